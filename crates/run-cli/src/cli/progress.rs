//! Progress of a run: an indicatif bar on a terminal, or a one-line heartbeat on stderr every
//! so many seconds when there is no bar (a redirected log, `--quiet`), or nothing (`-qq`).
//! [`Progress`] is `Sync`, so the walkers of a parallel run can report through one reference.

use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// Progress of a run; see [`LogArgs::progress`](super::LogArgs::progress).
pub struct Progress {
    kind: Kind,
    /// Last position reported through [`Progress::set_position`].
    position: AtomicU64,
    /// Text after the counts (`sweep 120, 4000 clusters`).
    message: Mutex<String>,
}

enum Kind {
    Silent,
    Bar(indicatif::ProgressBar),
    Heartbeat(Heartbeat),
}

struct Heartbeat {
    program: String,
    unit: String,
    len: u64,
    every: Duration,
    start: Instant,
    /// Milliseconds since `start` at which the next line is due.
    next_ms: AtomicU64,
}

impl Progress {
    /// No reports.
    pub fn silent() -> Self {
        Progress::with(Kind::Silent)
    }

    /// An indicatif bar of `len` steps with `template`.
    pub fn bar(len: u64, template: &str) -> Self {
        let bar = indicatif::ProgressBar::new(len);
        bar.set_style(
            indicatif::ProgressStyle::with_template(template)
                .expect("the binaries' progress templates are valid"),
        );
        Progress::with(Kind::Bar(bar))
    }

    /// A line `program: pos/len unit (p%) after T, R unit/s, eta E[, message]` on stderr every
    /// `every_seconds` (> 0).
    pub fn heartbeat(program: &str, len: u64, unit: &str, every_seconds: f64) -> Self {
        let every = Duration::from_secs_f64(every_seconds.clamp(1e-3, 1e9));
        Progress::with(Kind::Heartbeat(Heartbeat {
            program: program.to_string(),
            unit: unit.to_string(),
            len,
            every,
            start: Instant::now(),
            next_ms: AtomicU64::new(every.as_millis() as u64),
        }))
    }

    fn with(kind: Kind) -> Self {
        Progress {
            kind,
            position: AtomicU64::new(0),
            message: Mutex::new(String::new()),
        }
    }

    /// The run has reached `pos` of its `len` steps. Cheap: a heartbeat reads the clock and
    /// prints only when a line is due.
    pub fn set_position(&self, pos: u64) {
        self.position.store(pos, Ordering::Relaxed);
        match &self.kind {
            Kind::Silent => {}
            Kind::Bar(bar) => bar.set_position(pos),
            Kind::Heartbeat(h) => {
                let now = h.start.elapsed();
                let now_ms = now.as_millis() as u64;
                let due = h.next_ms.load(Ordering::Relaxed);
                // One thread wins the line when several report at once.
                if now_ms >= due
                    && h.next_ms
                        .compare_exchange(
                            due,
                            now_ms + h.every.as_millis().max(1) as u64,
                            Ordering::Relaxed,
                            Ordering::Relaxed,
                        )
                        .is_ok()
                {
                    super::say(&self.line(h, pos, now));
                }
            }
        }
    }

    /// Text shown after the counts (the bar's `{msg}`, the end of a heartbeat line).
    pub fn set_message(&self, message: String) {
        match &self.kind {
            Kind::Silent => {}
            Kind::Bar(bar) => bar.set_message(message),
            Kind::Heartbeat(_) => {
                if let Ok(mut m) = self.message.lock() {
                    *m = message;
                }
            }
        }
    }

    /// Advance by `n` steps.
    pub fn inc(&self, n: u64) {
        self.set_position(self.position.load(Ordering::Relaxed).saturating_add(n));
    }

    /// Remove the bar (heartbeats print nothing more).
    pub fn finish(&self) {
        if let Kind::Bar(bar) = &self.kind {
            bar.finish_and_clear();
        }
    }

    fn line(&self, h: &Heartbeat, pos: u64, elapsed: Duration) -> String {
        let secs = elapsed.as_secs_f64().max(1e-9);
        let rate = pos as f64 / secs;
        let pct = if h.len == 0 {
            100.0
        } else {
            100.0 * pos as f64 / h.len as f64
        };
        let eta = if rate > 0.0 && pos <= h.len {
            duration_text((h.len - pos) as f64 / rate)
        } else {
            "?".to_string()
        };
        let mut line = format!(
            "{}: {pos}/{} {} ({pct:.1}%) after {}, {} {}/s, eta {eta}",
            h.program,
            h.len,
            h.unit,
            duration_text(secs),
            rate_text(rate),
            h.unit
        );
        if let Ok(m) = self.message.lock()
            && !m.is_empty()
        {
            line.push_str(", ");
            line.push_str(&m);
        }
        line
    }
}

/// `1h 02m 03s`, `2m 03s` or `3.0s`.
fn duration_text(seconds: f64) -> String {
    let s = seconds.max(0.0);
    if s < 60.0 {
        return format!("{s:.1}s");
    }
    let whole = s.round() as u64;
    let (h, m, sec) = (whole / 3600, whole / 60 % 60, whole % 60);
    if h > 0 {
        format!("{h}h {m:02}m {sec:02}s")
    } else {
        format!("{m}m {sec:02}s")
    }
}

/// A rate with three significant digits.
fn rate_text(rate: f64) -> String {
    if rate >= 100.0 {
        format!("{rate:.0}")
    } else if rate >= 1.0 {
        format!("{rate:.1}")
    } else {
        format!("{rate:.3}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn heartbeat_lines_give_counts_rate_and_eta() {
        let p = Progress::heartbeat("dla", 1000, "particles", 60.0);
        p.set_message("R_g 12.5".into());
        let Kind::Heartbeat(h) = &p.kind else {
            unreachable!()
        };
        let line = p.line(h, 250, Duration::from_secs(90));
        assert_eq!(
            line,
            "dla: 250/1000 particles (25.0%) after 1m 30s, 2.8 particles/s, eta 4m 30s, R_g 12.5"
        );
    }

    #[test]
    fn durations_read_as_clock_text() {
        assert_eq!(duration_text(3.04), "3.0s");
        assert_eq!(duration_text(123.0), "2m 03s");
        assert_eq!(duration_text(3723.0), "1h 02m 03s");
    }

    #[test]
    fn silent_and_heartbeat_accept_reports_from_threads() {
        let p = Progress::heartbeat("x", 10, "steps", 1e-3);
        std::thread::scope(|s| {
            for _ in 0..2 {
                s.spawn(|| (0..10).for_each(|i| p.set_position(i)));
            }
        });
        Progress::silent().inc(3);
    }
}
