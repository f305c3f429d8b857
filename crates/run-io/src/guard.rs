//! What keeps a long run from being lost: a [`Guard`] that the run's loop polls through one
//! flag, and that asks it to checkpoint (every few minutes of wall time, by default) or to
//! checkpoint and stop (a signal, or memory about to run out).
//!
//! A model's loop reads [`Guard::flag`] once per unit of work (a particle, a sweep, a step): a
//! relaxed load of one byte, which costs nothing measurable. When it is set, [`Guard::take`]
//! says what is wanted: [`Request::Checkpoint`] (write one and go on) or [`Request::Stop`]
//! (write one and stop, with the [`StopReason`] to report). PDLA passes the flag to its
//! threads as the "halt" of a parallel phase, so a timed checkpoint ends the phase at a
//! quiescent point and the next phase starts after it.
//!
//! Three things set it:
//! - **the clock** ([`Guard::watch`] with an interval): a checkpoint every `interval` of wall
//!   time;
//! - **signals** (`run_cli::cli::guard_signals`, feature `cli`): SIGINT, SIGTERM, SIGUSR1 and
//!   SIGXCPU, what batch systems send before they kill a job, and Ctrl-C;
//! - **memory** ([`MemoryWatch`]): the resident memory of the process against what the machine
//!   (or the cgroup, or `--max-memory`) has left, polled every [`POLL`]; when the headroom falls
//!   below [`MemoryWatch::margin`], the run is asked to checkpoint and stop before the kernel's
//!   OOM killer would end it with nothing saved.
//!
//! The watch thread sleeps between polls and ends when the [`Watch`] it returns is dropped.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU8, AtomicU64, AtomicUsize, Ordering};
use std::time::{Duration, Instant};

/// How often the watch thread wakes to read the memory figures (and the clock).
pub const POLL: Duration = Duration::from_millis(250);

/// Default wall time between timed checkpoints: short enough that a crash or a `SIGKILL`
/// costs a few minutes, long enough that a checkpoint's cost is negligible (see the models'
/// docs, "Stopping and resuming").
pub const DEFAULT_INTERVAL: Duration = Duration::from_secs(5 * 60);

/// Environment variable that fakes the machine's memory for tests: `BYTES` (suffixes as
/// `--max-memory`) is taken as a cgroup limit, with this process's resident memory as the
/// cgroup's use, instead of what `/proc/meminfo` and the cgroup files say.
pub const FAKE_MEMORY_ENV: &str = "AGGSIM_TEST_MEMORY_LIMIT";

const CHECKPOINT: u8 = 1;
const STOP_MEMORY: u8 = 4;

/// The "signal" of a stop the program asks for itself ([`Guard::request_stop`] with 0).
pub const PROGRAM_STOP: usize = usize::MAX;

/// Why a run was asked to stop.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum StopReason {
    /// A signal (its number; [`PROGRAM_STOP`] for a stop asked by the program itself).
    Signal(usize),
    /// Memory about to run out: the one-line account of the figures.
    Memory(String),
}

/// The name of a signal number (SIGTERM ...), or `a stop request`.
pub fn signal_name(sig: usize) -> &'static str {
    match sig {
        2 => "SIGINT",
        15 => "SIGTERM",
        10 => "SIGUSR1",
        24 => "SIGXCPU",
        1 => "SIGHUP",
        _ => "a stop request",
    }
}

/// What the run is asked to do when [`Guard::flag`] is set.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Request {
    /// Nothing (the flag was set by a request already taken).
    None,
    /// Write a checkpoint and go on.
    Checkpoint,
    /// Write a checkpoint and stop.
    Stop(StopReason),
}

/// The requests a run polls; shared by the run's loop, the watch thread and signal handlers
/// (which store the signal's number in [`signal`](Self::signal_slot) and set the
/// [`flag`](Self::flag): two atomic stores, async-signal-safe).
#[derive(Debug, Default)]
pub struct Guard {
    attention: Arc<AtomicBool>,
    requests: AtomicU8,
    /// The signal that asked for a stop (0: none; [`PROGRAM_STOP`]: the program's own).
    signal: Arc<AtomicUsize>,
    memory: std::sync::Mutex<Option<String>>,
}

impl Guard {
    /// A guard with nothing requested, shared.
    pub fn new() -> Arc<Guard> {
        Arc::new(Guard::default())
    }

    /// The one flag a run's loop polls (relaxed): set while a request waits. PDLA's threads
    /// take it as the halt of their phase.
    pub fn flag(&self) -> &AtomicBool {
        &self.attention
    }

    /// The flag, shared, for a signal handler to set (`signal_hook::flag::register`) after
    /// storing its number in [`signal_slot`](Self::signal_slot).
    pub fn flag_arc(&self) -> Arc<AtomicBool> {
        Arc::clone(&self.attention)
    }

    /// Where a signal handler stores its signal's number (`signal_hook::flag::register_usize`):
    /// any number but 0 is a stop request.
    pub fn signal_slot(&self) -> Arc<AtomicUsize> {
        Arc::clone(&self.signal)
    }

    /// Whether a request waits (a relaxed load of [`flag`](Self::flag)).
    #[inline]
    pub fn is_set(&self) -> bool {
        self.attention.load(Ordering::Relaxed)
    }

    /// Asks for a checkpoint.
    pub fn request_checkpoint(&self) {
        self.requests.fetch_or(CHECKPOINT, Ordering::SeqCst);
        self.attention.store(true, Ordering::SeqCst);
    }

    /// Asks the run to checkpoint and stop for signal `sig` ([`PROGRAM_STOP`]: the program's
    /// own request, such as Python's Ctrl-C).
    pub fn request_stop(&self, sig: usize) {
        let sig = if sig == 0 { PROGRAM_STOP } else { sig };
        let _ = self
            .signal
            .compare_exchange(0, sig, Ordering::SeqCst, Ordering::SeqCst);
        self.attention.store(true, Ordering::SeqCst);
    }

    /// Asks the run to checkpoint and stop because memory is about to run out (`why`: the
    /// figures, one line).
    pub fn request_memory_stop(&self, why: String) {
        let mut m = self.memory.lock().unwrap_or_else(|e| e.into_inner());
        if m.is_none() {
            *m = Some(why);
        }
        drop(m);
        self.requests.fetch_or(STOP_MEMORY, Ordering::SeqCst);
        self.attention.store(true, Ordering::SeqCst);
    }

    /// What is requested, clearing a checkpoint request; a stop stays requested (every later
    /// call returns it again).
    pub fn take(&self) -> Request {
        // Clear the flag before reading the requests: a request made meanwhile sets it again.
        self.attention.store(false, Ordering::SeqCst);
        let r = self.requests.fetch_and(STOP_MEMORY, Ordering::SeqCst);
        if let Some(stop) = self.stop_reason() {
            self.attention.store(true, Ordering::SeqCst);
            return Request::Stop(stop);
        }
        if r & CHECKPOINT != 0 {
            Request::Checkpoint
        } else {
            Request::None
        }
    }

    /// The stop requested, if any, without clearing anything.
    pub fn stop_reason(&self) -> Option<StopReason> {
        let r = self.requests.load(Ordering::SeqCst);
        let sig = self.signal.load(Ordering::SeqCst);
        if r & STOP_MEMORY != 0 {
            let why = self.memory.lock().unwrap_or_else(|e| e.into_inner());
            Some(StopReason::Memory(why.clone().unwrap_or_default()))
        } else if sig != 0 {
            Some(StopReason::Signal(sig))
        } else {
            None
        }
    }

    /// Starts the watch thread: a checkpoint request every `interval` (none if `None`) and,
    /// with `memory`, a stop request when memory is about to run out. The thread ends when the
    /// returned [`Watch`] is dropped.
    ///
    /// # Errors
    /// The thread could not be started.
    pub fn watch(
        self: &Arc<Self>,
        interval: Option<Duration>,
        memory: Option<MemoryWatch>,
    ) -> std::io::Result<Watch> {
        let done = Arc::new((std::sync::Mutex::new(false), std::sync::Condvar::new()));
        if interval.is_none() && memory.is_none() {
            return Ok(Watch { done, thread: None });
        }
        let guard = Arc::clone(self);
        let shared = Arc::clone(&done);
        let thread = std::thread::Builder::new()
            .name("aggsim-watch".into())
            .spawn(move || watch_loop(&guard, interval, memory, &shared))?;
        Ok(Watch {
            done,
            thread: Some(thread),
        })
    }
}

/// The watch thread of a [`Guard`]; dropping it stops the thread.
#[derive(Debug)]
pub struct Watch {
    done: Arc<(std::sync::Mutex<bool>, std::sync::Condvar)>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl Drop for Watch {
    fn drop(&mut self) {
        *self.done.0.lock().unwrap_or_else(|e| e.into_inner()) = true;
        self.done.1.notify_all();
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

fn watch_loop(
    guard: &Guard,
    interval: Option<Duration>,
    memory: Option<MemoryWatch>,
    done: &(std::sync::Mutex<bool>, std::sync::Condvar),
) {
    let mut next = interval.map(|i| Instant::now() + i);
    let mut stopped = done.0.lock().unwrap_or_else(|e| e.into_inner());
    loop {
        let now = Instant::now();
        if let (Some(at), Some(i)) = (next, interval)
            && now >= at
        {
            guard.request_checkpoint();
            next = Some(now + i);
        }
        if let Some(m) = &memory
            && let Some(why) = m.exhausted()
        {
            guard.request_memory_stop(why);
        }
        let mut wait = if memory.is_some() {
            POLL
        } else {
            Duration::from_secs(3600)
        };
        if let Some(at) = next {
            wait = wait.min(at.saturating_duration_since(now));
        }
        let (s, _) = done
            .1
            .wait_timeout_while(stopped, wait, |d| !*d)
            .unwrap_or_else(|e| e.into_inner());
        stopped = s;
        if *stopped {
            return;
        }
    }
}

/// The memory figures a [`MemoryWatch`] compares: this process's resident memory and the
/// headroom left to it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MemoryFigures {
    /// Resident memory of this process (`VmRSS`), bytes.
    pub resident: u64,
    /// What the process may still add before the OOM killer would strike: the lower of the
    /// machine's `MemAvailable` and the cgroup's `memory.max - memory.current`.
    pub headroom: u64,
    /// The total that headroom is taken from (the machine's memory or the cgroup limit), for
    /// the message.
    pub total: u64,
    /// What sets the headroom.
    pub source: &'static str,
}

/// Watches the process's memory against what the machine (or its cgroup) has left; see
/// [`Guard::watch`]. `--max-memory` is not watched: it decides whether a run may start (its
/// estimate against the limit), and a run allowed past the machine's memory with it is the
/// one this watch is for.
#[derive(Debug, Clone)]
pub struct MemoryWatch {
    /// Bytes the final checkpoint needs on top of the state (its serialized copy, buffers):
    /// kept free besides the [`margin`](Self::margin).
    pub reserve: Arc<AtomicU64>,
    /// A test hook ([`FAKE_MEMORY_ENV`]): a fixed limit in place of the machine's figures.
    fake_limit: Option<u64>,
}

impl Default for MemoryWatch {
    fn default() -> Self {
        MemoryWatch::new()
    }
}

impl MemoryWatch {
    /// A watch of the machine's figures, or of the test hook's [`FAKE_MEMORY_ENV`] if set.
    pub fn new() -> MemoryWatch {
        let fake_limit = std::env::var(FAKE_MEMORY_ENV)
            .ok()
            .and_then(|v| crate::parse_bytes(&v).ok());
        MemoryWatch {
            reserve: Arc::new(AtomicU64::new(0)),
            fake_limit,
        }
    }

    /// The headroom under which the run is stopped: 1 % of the total, at least 64 MiB (what
    /// the allocator and the kernel take in one step of a run while the watch sleeps), plus
    /// the [`reserve`](Self::reserve).
    pub fn margin(&self, total: u64) -> u64 {
        (total / 100)
            .max(64 << 20)
            .saturating_add(self.reserve.load(Ordering::Relaxed))
    }

    /// The figures now; `None` where they cannot be read (no `/proc`).
    pub fn figures(&self) -> Option<MemoryFigures> {
        let resident = resident_bytes()?;
        let mut best: Option<MemoryFigures> = None;
        let mut consider = |headroom: u64, total: u64, source: &'static str| {
            if best.is_none_or(|b| headroom < b.headroom) {
                best = Some(MemoryFigures {
                    resident,
                    headroom,
                    total,
                    source,
                });
            }
        };
        if let Some(limit) = self.fake_limit {
            consider(limit.saturating_sub(resident), limit, "the test limit");
        } else {
            let meminfo = std::fs::read_to_string("/proc/meminfo").ok();
            if let Some(t) = meminfo.as_deref()
                && let (Some(avail), Some(total)) = (
                    crate::memory::meminfo_field(t, "MemAvailable"),
                    crate::memory::meminfo_field(t, "MemTotal"),
                )
            {
                consider(avail, total, "the machine");
            }
            if let Some((max, current)) = cgroup_figures() {
                consider(max.saturating_sub(current), max, "the cgroup");
            }
        }
        best
    }

    /// `Some(one line)` when the headroom is below the margin.
    pub fn exhausted(&self) -> Option<String> {
        let f = self.figures()?;
        let margin = self.margin(f.total);
        (f.headroom < margin).then(|| {
            use crate::show_bytes;
            format!(
                "memory nearly exhausted: the run holds {} resident and {} has {} of {} left, \
                 under the {} kept for the checkpoint",
                show_bytes(f.resident),
                f.source,
                show_bytes(f.headroom),
                show_bytes(f.total),
                show_bytes(margin)
            )
        })
    }
}

/// `VmRSS` of `/proc/self/status`, bytes.
pub fn resident_bytes() -> Option<u64> {
    let t = std::fs::read_to_string("/proc/self/status").ok()?;
    crate::memory::meminfo_field(&t, "VmRSS")
}

/// `(memory.max, memory.current)` of this process's cgroup (v2), or v1's limit and usage;
/// `None` without a limit.
fn cgroup_figures() -> Option<(u64, u64)> {
    let read = |p: &str| std::fs::read_to_string(p).ok();
    let pairs = [
        ("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory.current"),
        (
            "/sys/fs/cgroup/memory/memory.limit_in_bytes",
            "/sys/fs/cgroup/memory/memory.usage_in_bytes",
        ),
    ];
    pairs.iter().find_map(|(max, cur)| {
        let max = crate::memory::cgroup_limit(&read(max)?)?;
        let cur: u64 = read(cur)?.trim().parse().ok()?;
        Some((max, cur))
    })
}

/// A checkpoint interval as written on the command line: `off` (or `0`), seconds (`90`), or a
/// number with a unit `s`, `m`, `h` (`30s`, `5m`, `1.5h`). `Ok(None)` is off.
///
/// # Errors
/// Anything else, or an interval under one second, as one line.
pub fn parse_interval(s: &str) -> Result<Option<Duration>, String> {
    let t = s.trim();
    if t.eq_ignore_ascii_case("off") || t == "0" {
        return Ok(None);
    }
    let (num, scale) = match t.char_indices().last() {
        Some((i, 's')) => (&t[..i], 1.0),
        Some((i, 'm')) => (&t[..i], 60.0),
        Some((i, 'h')) => (&t[..i], 3600.0),
        _ => (t, 1.0),
    };
    let v: f64 = num
        .trim()
        .parse()
        .map_err(|_| format!("{s:?} is not a duration (such as 90, 30s, 5m, 2h, or off)"))?;
    let secs = v * scale;
    if !secs.is_finite() || !(1.0..=1e9).contains(&secs) {
        return Err(format!(
            "{s:?} is outside the accepted range 1s..=1e9s (or off)"
        ));
    }
    Ok(Some(Duration::from_secs_f64(secs)))
}

/// An interval as [`parse_interval`] reads it back: `off`, `300s`.
pub fn show_interval(i: Option<Duration>) -> String {
    match i {
        None => "off".into(),
        Some(d) if d.as_secs() % 3600 == 0 && d.subsec_nanos() == 0 => {
            format!("{}h", d.as_secs() / 3600)
        }
        Some(d) if d.as_secs() % 60 == 0 && d.subsec_nanos() == 0 => {
            format!("{}m", d.as_secs() / 60)
        }
        Some(d) => format!("{}s", d.as_secs_f64()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn intervals_parse_and_show() {
        assert_eq!(parse_interval("off"), Ok(None));
        assert_eq!(parse_interval("0"), Ok(None));
        assert_eq!(parse_interval("90"), Ok(Some(Duration::from_secs(90))));
        assert_eq!(parse_interval("30s"), Ok(Some(Duration::from_secs(30))));
        assert_eq!(parse_interval("5m"), Ok(Some(Duration::from_secs(300))));
        assert_eq!(parse_interval("1.5h"), Ok(Some(Duration::from_secs(5400))));
        for bad in ["", "m", "-5m", "0.5", "5x", "nan", "inf"] {
            assert!(parse_interval(bad).is_err(), "{bad:?}");
        }
        for i in ["off", "5m", "2h", "90s", "1.5s"] {
            assert_eq!(show_interval(parse_interval(i).unwrap()), i);
        }
    }

    #[test]
    fn requests_are_taken_once_and_stops_stay() {
        let g = Guard::new();
        assert!(!g.is_set());
        assert_eq!(g.take(), Request::None);
        g.request_checkpoint();
        assert!(g.is_set());
        assert_eq!(g.take(), Request::Checkpoint);
        assert!(!g.is_set());
        assert_eq!(g.take(), Request::None);
        g.request_stop(15);
        g.request_stop(2);
        g.request_checkpoint();
        assert_eq!(g.take(), Request::Stop(StopReason::Signal(15)));
        assert!(g.is_set(), "a stop stays requested");
        assert_eq!(g.take(), Request::Stop(StopReason::Signal(15)));
        g.request_memory_stop("low".into());
        assert_eq!(g.take(), Request::Stop(StopReason::Memory("low".into())));
    }

    #[test]
    fn the_clock_requests_checkpoints_and_the_watch_ends_when_dropped() {
        let g = Guard::new();
        let w = g.watch(Some(Duration::from_millis(20)), None).unwrap();
        let start = Instant::now();
        while !g.is_set() {
            assert!(start.elapsed() < Duration::from_secs(10), "no request");
            std::thread::sleep(Duration::from_millis(1));
        }
        assert_eq!(g.take(), Request::Checkpoint);
        drop(w);
    }

    #[test]
    fn memory_below_the_margin_is_a_stop() {
        let Some(resident) = resident_bytes() else {
            return;
        };
        let mut m = MemoryWatch::new();
        // Room for the resident memory and twice the margin: nothing to report.
        m.fake_limit = Some(resident + 3 * (64 << 20));
        assert_eq!(m.exhausted(), None);
        // The resident memory and half the margin: a stop, with the figures.
        m.fake_limit = Some(resident + (32 << 20));
        let why = m.exhausted().expect("a stop");
        assert!(
            why.contains("the test limit") && !why.contains('\n'),
            "{why}"
        );
    }
}
