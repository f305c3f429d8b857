//! Where a result came from: date, version, git commit, command line, host and CPU. Every
//! `run.json` carries it (`provenance`), as do the reports of `cargo xtask scaling`, so a number
//! in a paper can be traced to the build and machine that produced it.

use serde::{Deserialize, Serialize};
use std::time::{SystemTime, UNIX_EPOCH};

/// The git commit this crate was built from (`git rev-parse HEAD` at build time, by
/// `build.rs`), or `None` for a build outside a git checkout (a crates.io package, a tarball).
pub const GIT_COMMIT: Option<&str> = option_env!("AGGSIM_GIT_COMMIT");

/// The `provenance` object of `run.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Provenance {
    /// When the run finished, `YYYY-MM-DDTHH:MM:SSZ` (UTC, ISO 8601).
    pub date_utc: String,
    /// Version of the crate that ran it.
    pub version: String,
    /// The git commit of the build ([`GIT_COMMIT`]); `null` outside a checkout.
    pub git_commit: Option<String>,
    /// The process's command line, program first (for a library caller, such as Python, its
    /// own command line).
    pub command_line: Vec<String>,
    /// The host name.
    pub host: String,
    /// The CPU model (`/proc/cpuinfo`'s `model name`; the architecture elsewhere).
    pub cpu: String,
    /// Worker threads the run used.
    pub threads: usize,
    /// Logical CPUs available to the process (its CPU affinity: under an MPI launcher, the
    /// CPUs its rank gave it).
    pub cpus: usize,
    /// For a member of an ensemble over MPI ranks: the rank that ran it (the host is
    /// [`host`](Self::host)); absent otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mpi: Option<MpiPlace>,
}

/// Where an ensemble member ran in an MPI job (`provenance.mpi` of its `run.json`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MpiPlace {
    /// The MPI rank (in `MPI_COMM_WORLD`) that ran the member.
    pub rank: u64,
    /// The ranks of the job.
    pub ranks: u64,
    /// The CPUs of the rank's share of its node, which its members were sized by (`--jobs`
    /// defaults to this divided by `--threads`).
    pub cpus: u64,
}

/// Environment variable a rank sets for each member it runs, `RANK,RANKS,CPUS`
/// ([`MpiPlace`]), read by the member's [`Provenance::now`].
pub const MPI_PLACE_VAR: &str = "AGGSIM_MPI_PLACE";

impl MpiPlace {
    /// The placement a rank gave this process ([`MPI_PLACE_VAR`]), if any.
    pub fn from_env() -> Option<Self> {
        Self::parse(&std::env::var(MPI_PLACE_VAR).ok()?)
    }

    /// `RANK,RANKS,CPUS`, as [`MpiPlace::env_value`] writes it.
    pub fn parse(text: &str) -> Option<Self> {
        let v: Vec<u64> = text
            .split(',')
            .map(|s| s.trim().parse().ok())
            .collect::<Option<_>>()?;
        match v[..] {
            [rank, ranks, cpus] => Some(MpiPlace { rank, ranks, cpus }),
            _ => None,
        }
    }

    /// The value of [`MPI_PLACE_VAR`] for this placement.
    pub fn env_value(&self) -> String {
        format!("{},{},{}", self.rank, self.ranks, self.cpus)
    }
}

impl Provenance {
    /// The provenance of a run of `version` with `threads` workers, taken now.
    pub fn now(version: &str, threads: usize) -> Self {
        Provenance {
            date_utc: utc_iso8601(SystemTime::now()),
            version: version.to_string(),
            git_commit: GIT_COMMIT.map(str::to_string),
            command_line: std::env::args_os()
                .map(|a| a.to_string_lossy().into_owned())
                .collect(),
            host: host_name(),
            cpu: cpu_model(),
            threads,
            cpus: std::thread::available_parallelism().map_or(1, |n| n.get()),
            mpi: MpiPlace::from_env(),
        }
    }
}

/// The host name, or `unknown`.
pub fn host_name() -> String {
    #[cfg(unix)]
    if let Ok(h) = nix::unistd::gethostname() {
        return h.to_string_lossy().into_owned();
    }
    std::env::var("HOSTNAME")
        .or_else(|_| std::env::var("COMPUTERNAME"))
        .unwrap_or_else(|_| "unknown".to_string())
}

/// The CPU model from `/proc/cpuinfo`, or the architecture where there is none.
pub fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|m| m.trim().to_string())
        })
        .unwrap_or_else(|| std::env::consts::ARCH.to_string())
}

/// `t` as `YYYY-MM-DDTHH:MM:SSZ`.
pub fn utc_iso8601(t: SystemTime) -> String {
    let (y, mo, d, h, mi, s) = utc_fields(t);
    format!("{y:04}-{mo:02}-{d:02}T{h:02}:{mi:02}:{s:02}Z")
}

/// `t` as `YYYY-MM-DD HH:MM UTC`, for reports.
pub fn utc_minutes(t: SystemTime) -> String {
    let (y, mo, d, h, mi, _) = utc_fields(t);
    format!("{y:04}-{mo:02}-{d:02} {h:02}:{mi:02} UTC")
}

fn utc_fields(t: SystemTime) -> (i64, u32, u32, u64, u64, u64) {
    let secs = t.duration_since(UNIX_EPOCH).map_or(0, |d| d.as_secs());
    let (days, rem) = (secs / 86_400, secs % 86_400);
    let (y, m, d) = civil_from_days(days as i64);
    (y, m, d, rem / 3600, (rem % 3600) / 60, rem % 60)
}

/// Proleptic Gregorian date of a day count since 1970-01-01 (H. Hinnant's algorithm).
pub fn civil_from_days(z: i64) -> (i64, u32, u32) {
    let z = z + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let m = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    let y = yoe + era * 400 + i64::from(m <= 2);
    (y, m, d)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    #[test]
    fn dates() {
        assert_eq!(civil_from_days(0), (1970, 1, 1));
        assert_eq!(civil_from_days(20_414), (2025, 11, 22));
        assert_eq!(civil_from_days(11_016), (2000, 2, 29));
        let t = UNIX_EPOCH + Duration::from_secs(20_414 * 86_400 + 13 * 3600 + 5 * 60 + 9);
        assert_eq!(utc_iso8601(t), "2025-11-22T13:05:09Z");
        assert_eq!(utc_minutes(t), "2025-11-22 13:05 UTC");
    }

    #[test]
    fn an_mpi_placement_round_trips_through_its_variable_and_run_json() {
        let place = MpiPlace {
            rank: 3,
            ranks: 5,
            cpus: 16,
        };
        assert_eq!(MpiPlace::parse(&place.env_value()), Some(place));
        assert_eq!(MpiPlace::parse("3,5"), None);
        assert_eq!(MpiPlace::parse("3,x,1"), None);
        let mut p = Provenance::now("9.9.9", 1);
        let plain = serde_json::to_value(&p).unwrap();
        assert!(plain.get("mpi").is_none(), "{plain}");
        p.mpi = Some(place);
        let json = serde_json::to_value(&p).unwrap();
        assert_eq!(json["mpi"]["rank"], 3);
        assert_eq!(serde_json::from_value::<Provenance>(json).unwrap(), p);
        // A run.json written before the field existed still reads.
        assert_eq!(
            serde_json::from_value::<Provenance>(plain).unwrap().mpi,
            None
        );
    }

    #[test]
    fn provenance_describes_this_process() {
        let p = Provenance::now("9.9.9", 3);
        assert_eq!((p.version.as_str(), p.threads), ("9.9.9", 3));
        assert!(p.cpus >= 1 && !p.host.is_empty() && !p.cpu.is_empty());
        assert!(!p.command_line.is_empty());
        assert_eq!(p.mpi, None);
        assert_eq!(p.date_utc.len(), "2026-01-01T00:00:00Z".len());
        // Built from this checkout, the commit is a full hash.
        if let Some(c) = &p.git_commit {
            assert!(
                c.len() == 40 && c.chars().all(|c| c.is_ascii_hexdigit()),
                "{c}"
            );
        }
    }
}
