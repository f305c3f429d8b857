//! Memory checked before the work: the memory a run may take (`--max-memory`, else what the
//! machine has available), a model's peak-memory estimate compared with it, and the one line
//! that refuses a run that cannot fit, and the typed error of a large up-front allocation that
//! failed (so it is reported as a failed run, not an abort with a backtrace).
//!
//! Every binary takes `--max-memory BYTES` (suffixes K, M, G, T: [`parse_bytes`]); without it
//! the limit is the memory available: `MemAvailable` of `/proc/meminfo` where there is one,
//! else the total physical memory, lowered to the cgroup limit (`/sys/fs/cgroup/memory.max`,
//! or cgroup v1's `memory.limit_in_bytes`) when that is lower.

pub use crate::parse_bytes;
use crate::show_bytes;

/// The memory a run may take, and where that figure came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Limit {
    /// Bytes.
    pub bytes: u64,
    /// What set it.
    pub source: LimitSource,
}

/// Where a [`Limit`] came from; it decides how the refusal reads and what it suggests.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LimitSource {
    /// `--max-memory` on the command line (or in a config file).
    Flag,
    /// A default of the binary's `--max-memory` (animat's 4 GiB world cap), lower than the
    /// memory available.
    FlagDefault,
    /// `MemAvailable` of `/proc/meminfo`.
    MemAvailable,
    /// The cgroup's memory limit.
    Cgroup,
    /// Total physical memory (no `MemAvailable` on this system).
    Physical,
    /// Nothing could be read: no limit.
    Unknown,
}

impl Limit {
    /// `--max-memory` as given, else [`available`].
    pub fn from_flag(max_memory: Option<u64>) -> Limit {
        match max_memory {
            Some(bytes) => Limit {
                bytes,
                source: LimitSource::Flag,
            },
            None => available(),
        }
    }

    /// The lower of [`available`] and a binary's default cap (animat's world cap), when no
    /// `--max-memory` was given.
    pub fn with_default_cap(max_memory: Option<u64>, default_cap: u64) -> Limit {
        match max_memory {
            Some(_) => Limit::from_flag(max_memory),
            None => {
                let a = available();
                if default_cap < a.bytes {
                    Limit {
                        bytes: default_cap,
                        source: LimitSource::FlagDefault,
                    }
                } else {
                    a
                }
            }
        }
    }

    /// `Err(one line)` when `estimate` bytes do not fit: the estimate and `what` it is made
    /// of, the limit and where it came from, and the flag that overrides it; `smaller` names
    /// what to lower (`lower --particles`).
    ///
    /// # Errors
    /// The estimate exceeds the limit.
    pub fn check(&self, estimate: u64, what: &str, smaller: &str) -> Result<(), String> {
        if estimate <= self.bytes {
            return Ok(());
        }
        let need = format!("the run needs about {} ({what})", show_bytes(estimate));
        Err(match self.source {
            LimitSource::Flag | LimitSource::FlagDefault => format!(
                "{need}, over {}; {smaller}, or raise --max-memory",
                self.describe()
            ),
            _ => {
                let flag = show_bytes_flag(estimate);
                match total_memory() {
                    Some(total) if estimate > total => format!(
                        "{need}, more than {} and more than the machine's {} in all; {smaller}, \
                         or use a larger machine (--max-memory {flag} would start the run, to \
                         checkpoint and stop when memory runs out)",
                        self.describe(),
                        show_bytes(total)
                    ),
                    Some(total) => format!(
                        "{need}, more than {} (other processes hold the rest of the machine's \
                         {}); {smaller}, or give --max-memory {flag} to run anyway, at the risk \
                         of running out (the run then checkpoints and stops)",
                        self.describe(),
                        show_bytes(total)
                    ),
                    None => format!(
                        "{need}, more than {}; {smaller}, or give --max-memory {flag} to run \
                         anyway, at the risk of running out (the run then checkpoints and stops)",
                        self.describe()
                    ),
                }
            }
        })
    }
}

impl Limit {
    /// The limit as a message names it: `--max-memory 1.0 MiB`, or `the 22.1 GiB of memory
    /// available (MemAvailable in /proc/meminfo)`.
    pub fn describe(&self) -> String {
        match self.source {
            LimitSource::Flag | LimitSource::FlagDefault => {
                format!("--max-memory {}", show_bytes(self.bytes))
            }
            source => format!(
                "the {} of memory available ({})",
                show_bytes(self.bytes),
                source.describe()
            ),
        }
    }
}

impl LimitSource {
    fn describe(self) -> &'static str {
        match self {
            LimitSource::Flag => "--max-memory",
            LimitSource::FlagDefault => "the default --max-memory",
            LimitSource::MemAvailable => "MemAvailable in /proc/meminfo",
            LimitSource::Cgroup => "the cgroup's memory.max",
            LimitSource::Physical => "physical memory",
            LimitSource::Unknown => "unknown",
        }
    }
}

/// The memory this process may use now: `MemAvailable` (else `MemTotal`) of `/proc/meminfo`,
/// or the cgroup limit if lower; [`LimitSource::Unknown`] with `u64::MAX` where neither can
/// be read (the check then passes).
pub fn available() -> Limit {
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok();
    let from_meminfo = meminfo.as_deref().and_then(|t| {
        meminfo_field(t, "MemAvailable")
            .map(|b| (b, LimitSource::MemAvailable))
            .or_else(|| meminfo_field(t, "MemTotal").map(|b| (b, LimitSource::Physical)))
    });
    let cgroup = [
        "/sys/fs/cgroup/memory.max",
        "/sys/fs/cgroup/memory/memory.limit_in_bytes",
    ]
    .iter()
    .find_map(|p| cgroup_limit(&std::fs::read_to_string(p).ok()?));
    let (bytes, source) = match (from_meminfo, cgroup) {
        (Some((m, _)), Some(c)) if c < m => (c, LimitSource::Cgroup),
        (Some((m, s)), _) => (m, s),
        (None, Some(c)) => (c, LimitSource::Cgroup),
        (None, None) => (u64::MAX, LimitSource::Unknown),
    };
    Limit { bytes, source }
}

/// `MemTotal` of `/proc/meminfo`, or the cgroup limit if lower.
pub fn total_memory() -> Option<u64> {
    let total = std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|t| meminfo_field(&t, "MemTotal"));
    let cgroup = [
        "/sys/fs/cgroup/memory.max",
        "/sys/fs/cgroup/memory/memory.limit_in_bytes",
    ]
    .iter()
    .find_map(|p| cgroup_limit(&std::fs::read_to_string(p).ok()?));
    match (total, cgroup) {
        (Some(t), Some(c)) => Some(t.min(c)),
        (t, c) => t.or(c),
    }
}

/// `bytes` rounded up to a value of `--max-memory` that covers it: `23G`, `512M`.
fn show_bytes_flag(bytes: u64) -> String {
    const UNITS: [(u64, &str); 4] = [
        (1 << 40, "T"),
        (1 << 30, "G"),
        (1 << 20, "M"),
        (1 << 10, "K"),
    ];
    for (scale, unit) in UNITS {
        if bytes >= scale {
            return format!("{}{unit}", bytes.div_ceil(scale));
        }
    }
    bytes.to_string()
}

/// A `Name:  1234 kB` line of `/proc/meminfo`, in bytes.
pub(crate) fn meminfo_field(text: &str, name: &str) -> Option<u64> {
    let line = text.lines().find(|l| l.split(':').next() == Some(name))?;
    let mut words = line.split(':').nth(1)?.split_whitespace();
    let value: u64 = words.next()?.parse().ok()?;
    match words.next() {
        Some("kB") => value.checked_mul(1024),
        None => Some(value),
        Some(_) => None,
    }
}

/// The content of a cgroup memory limit file: a byte count, `max` (no limit) or, in cgroup
/// v1, a huge number meaning none.
pub(crate) fn cgroup_limit(text: &str) -> Option<u64> {
    let v: u64 = text.trim().parse().ok()?;
    (v < 1 << 60).then_some(v)
}

/// An allocation made up front (a lattice, a reservation of the tree) that the system refused:
/// the run reports it as a failed run, `cannot allocate N bytes for WHAT`.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("cannot allocate {} for {what}", show_allocation(*.bytes))]
pub struct AllocError {
    /// Bytes asked for.
    pub bytes: u64,
    /// What they were for.
    pub what: String,
}

fn show_allocation(bytes: u64) -> String {
    format!("{bytes} bytes ({})", show_bytes(bytes))
}

/// A vector of `len` copies of `value`, or an [`AllocError`] naming `what` if the memory
/// cannot be had (instead of the abort of `vec![value; len]`).
///
/// # Errors
/// The allocation failed, or its size overflows.
pub fn try_vec<T: Clone>(len: usize, value: T, what: &str) -> Result<Vec<T>, AllocError> {
    let mut v = try_vec_capacity(len, what)?;
    v.resize(len, value);
    Ok(v)
}

/// A vector of `len` zeros of an integer type (`T::default()`), or an [`AllocError`] naming `what`, whose pages
/// the operating system supplies on first touch (`vec![0; len]` allocates zeroed memory): the
/// elements a run never writes cost no memory. The allocation is first tried fallibly and
/// released, so that memory that cannot be had is an error rather than an abort.
///
/// # Errors
/// The allocation failed, or its size overflows.
pub fn try_zeros<T: Clone + Default>(len: usize, what: &str) -> Result<Vec<T>, AllocError> {
    drop(try_vec_capacity::<T>(len, what)?);
    Ok(vec![T::default(); len])
}

fn try_vec_capacity<T>(len: usize, what: &str) -> Result<Vec<T>, AllocError> {
    let mut v = Vec::new();
    try_reserve(&mut v, len, what)?;
    Ok(v)
}

/// Reserves room for `additional` more elements in `v` exactly, or an [`AllocError`] naming
/// `what`.
///
/// # Errors
/// The allocation failed, or its size overflows.
pub fn try_reserve<T>(v: &mut Vec<T>, additional: usize, what: &str) -> Result<(), AllocError> {
    v.try_reserve_exact(additional).map_err(|_| AllocError {
        bytes: (additional as u64).saturating_mul(size_of::<T>() as u64),
        what: what.to_string(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn meminfo_and_cgroup_files_parse() {
        let t = "MemTotal:       24684092 kB\nMemFree:  1 kB\nMemAvailable:   24076784 kB\n";
        assert_eq!(meminfo_field(t, "MemAvailable"), Some(24076784 * 1024));
        assert_eq!(meminfo_field(t, "MemTotal"), Some(24684092 * 1024));
        assert_eq!(meminfo_field(t, "Swap"), None);
        assert_eq!(cgroup_limit("max\n"), None);
        assert_eq!(cgroup_limit("1073741824\n"), Some(1 << 30));
        assert_eq!(cgroup_limit("9223372036854771712\n"), None);
    }

    #[test]
    fn available_memory_is_read_here() {
        let a = available();
        assert!(a.bytes > 0);
        if std::path::Path::new("/proc/meminfo").exists() {
            assert_ne!(a.source, LimitSource::Unknown);
        }
    }

    #[test]
    fn a_run_that_does_not_fit_is_one_line_naming_the_override() {
        let flag = Limit::from_flag(Some(1 << 20));
        assert!(flag.check(1 << 20, "x", "lower --n").is_ok());
        let e = flag
            .check(2 << 20, "2 bytes per thing", "lower --n")
            .unwrap_err();
        assert_eq!(
            e,
            "the run needs about 2.0 MiB (2 bytes per thing), over --max-memory 1.0 MiB; \
             lower --n, or raise --max-memory"
        );
        let avail = Limit {
            bytes: 1 << 30,
            source: LimitSource::MemAvailable,
        };
        let e = avail.check(31 << 30, "y", "lower --particles").unwrap_err();
        assert!(e.contains("31.0 GiB") && e.contains("1.0 GiB of memory available"));
        assert!(e.contains("--max-memory 31G") && !e.contains('\n'), "{e}");
        assert!(!e.contains("such as"), "{e}");
        if let Some(total) = total_memory() {
            assert!(e.contains(&show_bytes(total)), "{e}");
        }
        assert_eq!(show_bytes_flag(31 << 30), "31G");
        assert_eq!(show_bytes_flag((31 << 30) + 1), "32G");
        assert_eq!(show_bytes_flag(1500 << 20), "2G");
        assert_eq!(show_bytes_flag(100), "100");
        let capped = Limit::with_default_cap(None, 1 << 10);
        assert_eq!(capped.source, LimitSource::FlagDefault);
        assert_eq!(Limit::with_default_cap(Some(5), 1 << 10).bytes, 5);
    }

    #[test]
    fn a_refused_allocation_is_an_error_not_an_abort() {
        let e = try_vec(usize::MAX / 2, 0u64, "the lattice").unwrap_err();
        assert!(e.to_string().starts_with("cannot allocate "), "{e}");
        assert!(e.to_string().ends_with(" for the lattice"), "{e}");
        assert_eq!(try_vec(3, 7u8, "x").unwrap(), vec![7, 7, 7]);
        let e = try_zeros::<u32>(usize::MAX / 2, "the labels").unwrap_err();
        assert!(e.to_string().ends_with(" for the labels"), "{e}");
        assert_eq!(try_zeros::<u32>(3, "x").unwrap(), vec![0, 0, 0]);
    }
}
