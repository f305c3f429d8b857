//! Tables (markdown and CSV), number formatting with error bars, and the provenance every result
//! file carries: date, machine, command.

use anyhow::{Context, Result};
use core_lattice::Welford;
use run_io::{CsvField, CsvWriter, write_atomic};
use std::fmt::Write as _;
use std::path::Path;
use std::time::SystemTime;

/// A table written both as markdown (for the report) and as CSV (the data behind it).
#[derive(Debug, Clone, Default)]
pub struct Table {
    /// Column names.
    pub header: Vec<String>,
    /// Rows of already formatted cells.
    pub rows: Vec<Vec<String>>,
}

impl Table {
    /// An empty table with these columns.
    pub fn new(header: &[&str]) -> Self {
        Table {
            header: header.iter().map(|s| s.to_string()).collect(),
            rows: Vec::new(),
        }
    }

    /// Append a row; it must have one cell per column.
    pub fn row(&mut self, cells: Vec<String>) {
        assert_eq!(
            cells.len(),
            self.header.len(),
            "a row of {} cells in a table of {} columns",
            cells.len(),
            self.header.len()
        );
        self.rows.push(cells);
    }

    /// The table as GitHub markdown.
    pub fn markdown(&self) -> String {
        let mut s = String::new();
        let line = |cells: &[String]| format!("| {} |\n", cells.join(" | "));
        s.push_str(&line(&self.header));
        s.push_str(&format!("|{}\n", "---|".repeat(self.header.len())));
        for r in &self.rows {
            s.push_str(&line(r));
        }
        s
    }

    /// Write the table as CSV, atomically, through run-io's [`CsvWriter`] (which quotes
    /// cells that need it).
    pub fn write_csv(&self, path: &Path) -> Result<()> {
        let header: Vec<&str> = self.header.iter().map(String::as_str).collect();
        let mut w = CsvWriter::create(path, &header)
            .with_context(|| format!("writing {}", path.display()))?;
        for r in &self.rows {
            let fields: Vec<&dyn CsvField> = r.iter().map(|c| c as &dyn CsvField).collect();
            w.row(&fields)
                .with_context(|| format!("writing {}", path.display()))?;
        }
        w.finish()
            .with_context(|| format!("writing {}", path.display()))
    }
}

/// Decimal places that show an uncertainty `err` with two significant digits.
fn decimals_for(err: f64) -> usize {
    if !(err.is_finite() && err > 0.0) {
        return 3;
    }
    (1 - err.log10().floor() as i64).clamp(0, 9) as usize
}

/// `value ± err`, rounded to the error's second significant digit (`1.428 ± 0.023`).
pub fn pm(value: f64, err: f64) -> String {
    if !value.is_finite() {
        return "n/a".to_string();
    }
    if !(err.is_finite() && err > 0.0) {
        return sig(value, 4);
    }
    let d = decimals_for(err);
    format!("{value:.d$} ± {err:.d$}")
}

/// A number with `digits` significant digits, in plain or scientific notation by magnitude.
pub fn sig(v: f64, digits: usize) -> String {
    if !v.is_finite() {
        return "n/a".to_string();
    }
    if v == 0.0 {
        return "0".to_string();
    }
    let mag = v.abs().log10().floor() as i32;
    if !(-3..6).contains(&mag) {
        return format!("{:.*e}", digits.saturating_sub(1), v);
    }
    let d = (digits as i32 - 1 - mag).max(0) as usize;
    format!("{v:.d$}")
}

fn welford(xs: &[f64]) -> Welford {
    let mut w = Welford::new();
    xs.iter().for_each(|&x| w.push(x));
    w
}

/// Mean and standard error of the mean (0 for a single value, NaN for none), from
/// `core_lattice`'s Welford accumulator.
pub fn mean_stderr(xs: &[f64]) -> (f64, f64) {
    let w = welford(xs);
    (w.mean(), if xs.len() == 1 { 0.0 } else { w.std_error() })
}

/// Sample standard deviation (0 for a single value).
pub fn std_dev(xs: &[f64]) -> f64 {
    if xs.len() == 1 {
        0.0
    } else {
        welford(xs).std_dev()
    }
}

/// Today's date and time in UTC, `YYYY-MM-DD HH:MM UTC`, from the system clock.
pub fn utc_now() -> String {
    run_io::provenance::utc_minutes(SystemTime::now())
}

/// The build: `aggsim 0.1.0 at commit <hash>`. The commands that report it build the binaries
/// they measure from the checkout, so the commit is the checkout's when they run (`git
/// rev-parse HEAD`), with a note when tracked files differ from it; xtask's own build may be
/// older (its binary run directly, without `cargo xtask`). Outside a checkout, the commit xtask
/// was built at, if any.
pub fn build_id() -> String {
    let version = env!("CARGO_PKG_VERSION");
    if let Some(commit) = git(&["rev-parse", "HEAD"]).filter(|c| !c.is_empty()) {
        let dirty =
            git(&["status", "--porcelain", "--untracked-files=no"]).is_some_and(|s| !s.is_empty());
        let note = if dirty {
            " with uncommitted changes"
        } else {
            ""
        };
        return format!("aggsim {version} at commit {commit}{note}");
    }
    match run_io::provenance::GIT_COMMIT {
        Some(c) => format!("aggsim {version} at commit {c}"),
        None => format!("aggsim {version} (not built from a git checkout)"),
    }
}

/// What `git args` prints in the workspace, trimmed; `None` without git or a checkout.
fn git(args: &[&str]) -> Option<String> {
    std::process::Command::new("git")
        .args(args)
        .current_dir(crate::workspace_root())
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
}

/// One line describing the machine: CPU model (vendor, family, model, caches, whether
/// virtualised, and how many of the kernel's known speculative-execution vulnerabilities it
/// mitigates), logical cores, memory, kernel, rustc.
pub fn machine() -> String {
    let host = run_io::provenance::Host::now();
    let mitigated = host
        .mitigations
        .values()
        .filter(|v| v.starts_with("Mitigation"))
        .count();
    let cpu = format!(
        "{} ({}; mitigations on for {mitigated} of {} known vulnerabilities)",
        run_io::provenance::cpu_model(),
        host.summary(),
        host.mitigations.len()
    );
    let cores = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1);
    let mem = std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("MemTotal"))
                .and_then(|l| l.split_whitespace().nth(1))
                .and_then(|kb| kb.parse::<f64>().ok())
        })
        .map(|kb| format!("{:.0} GiB", kb / 1024.0 / 1024.0))
        .unwrap_or_else(|| "unknown memory".to_string());
    let kernel = std::fs::read_to_string("/proc/sys/kernel/osrelease")
        .map(|s| format!("Linux {}", s.trim()))
        .unwrap_or_else(|_| std::env::consts::OS.to_string());
    let rustc = std::process::Command::new(std::env::var("RUSTC").unwrap_or("rustc".into()))
        .arg("-V")
        .output()
        .ok()
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .filter(|s| !s.is_empty())
        .unwrap_or_else(|| "rustc (version unknown)".to_string());
    format!("{cpu}, {cores} logical cores, {mem}, {kernel}, {rustc}")
}

/// A markdown document under construction.
#[derive(Debug, Default)]
pub struct Doc {
    text: String,
}

impl Doc {
    /// A document with a level-1 title.
    pub fn new(title: &str) -> Self {
        Doc {
            text: format!("# {title}\n\n"),
        }
    }

    /// A level-2 heading.
    pub fn h2(&mut self, title: &str) {
        let _ = write!(self.text, "## {title}\n\n");
    }

    /// A paragraph.
    pub fn p(&mut self, text: &str) {
        let _ = write!(self.text, "{}\n\n", text.trim());
    }

    /// A table.
    pub fn table(&mut self, t: &Table) {
        let _ = writeln!(self.text, "{}", t.markdown());
    }

    /// An image link.
    pub fn image(&mut self, alt: &str, file: &str) {
        let _ = write!(self.text, "![{alt}]({file})\n\n");
    }

    /// The markdown text.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// Write atomically.
    pub fn write(&self, path: &Path) -> Result<()> {
        write_atomic(path, self.text.as_bytes())
            .with_context(|| format!("writing {}", path.display()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn build_id_names_the_checkouts_commit() {
        let head = git(&["rev-parse", "HEAD"]);
        let id = build_id();
        assert!(
            id.starts_with(&format!("aggsim {} ", env!("CARGO_PKG_VERSION"))),
            "{id}"
        );
        match head {
            // The commit the checkout is at now, not the one xtask was compiled at.
            Some(head) => assert!(id.contains(&format!("at commit {head}")), "{id} vs {head}"),
            // An exported tree: whatever the build recorded.
            None => assert!(id.contains("commit") || id.contains("not built"), "{id}"),
        }
    }

    #[test]
    fn formats_error_bars() {
        assert_eq!(pm(1.42812, 0.0231), "1.428 ± 0.023");
        assert_eq!(pm(73.4, 4.2), "73.4 ± 4.2");
        assert_eq!(pm(1234.0, 150.0), "1234 ± 150");
        assert_eq!(pm(2.0, 0.0), "2.000");
        assert_eq!(sig(0.012345, 3), "0.0123");
        assert_eq!(sig(1.5e-7, 2), "1.5e-7");
    }

    #[test]
    fn tables() {
        let mut t = Table::new(&["a", "b"]);
        t.row(vec!["1".into(), "x, y".into()]);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.csv");
        t.write_csv(&path).unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "a,b\n1,\"x, y\"\n");
        assert_eq!(t.markdown(), "| a | b |\n|---|---|\n| 1 | x, y |\n");
        let (m, se) = mean_stderr(&[1.0, 2.0, 3.0]);
        assert_eq!(m, 2.0);
        assert!((se - (1.0f64 / 3.0).sqrt()).abs() < 1e-12);
    }
}
