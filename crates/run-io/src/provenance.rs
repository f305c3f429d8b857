//! Where a result came from: date, version, git commit, command line, host and CPU (with its
//! family, caches and the kernel's speculative-execution mitigations, which a speed figure
//! depends on). Every `run.json` carries it (`provenance`), as do the reports of `cargo xtask
//! scaling` and `cargo xtask bench`, so a number in a paper can be traced to the build and
//! machine that produced it.

use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;
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
    /// What the kernel says of the processor: vendor, family and model numbers, caches and
    /// mitigations ([`Host::now`]); absent in a `run.json` written before it was recorded.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub host_cpu: Option<Host>,
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
            host_cpu: Some(Host::now()),
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
        .and_then(|s| cpuinfo_field(&s, "model name"))
        .unwrap_or_else(|| std::env::consts::ARCH.to_string())
}

/// The value of `name` in the first processor's block of a `/proc/cpuinfo` text.
fn cpuinfo_field(info: &str, name: &str) -> Option<String> {
    info.lines()
        .take_while(|l| !l.trim().is_empty())
        .find_map(|l| {
            let (k, v) = l.split_once(':')?;
            (k.trim() == name).then(|| v.trim().to_string())
        })
}

/// The processor a run ran on as the kernel describes it (Linux's `/proc/cpuinfo` and
/// `/sys/devices/system/cpu`; empty fields elsewhere): what makes a timing comparable, or not,
/// with one from another machine.
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Host {
    /// `vendor_id`: `GenuineIntel`, `AuthenticAMD`, ... (empty where unknown).
    pub vendor: String,
    /// `cpu family` (x86: 6 for most Intel cores, 25 for AMD Zen 3 and 4).
    pub family: Option<u32>,
    /// `model` within the family.
    pub model: Option<u32>,
    /// `stepping`.
    pub stepping: Option<u32>,
    /// The caches of CPU 0, innermost first.
    pub caches: Vec<Cache>,
    /// Each speculative-execution vulnerability the kernel knows of and its state
    /// (`/sys/devices/system/cpu/vulnerabilities`): `Not affected`, `Mitigation: ...` or
    /// `Vulnerable`. Mitigations cost time on some hosts (page-table isolation, retpolines).
    pub mitigations: BTreeMap<String, String>,
    /// Whether the kernel runs under a hypervisor (the `hypervisor` flag).
    pub virtualised: bool,
}

/// One cache of a CPU.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Cache {
    /// 1, 2, 3.
    pub level: u32,
    /// `Data`, `Instruction` or `Unified`.
    pub kind: String,
    /// Size in bytes.
    pub bytes: u64,
    /// Logical CPUs that share it.
    pub shared_by: u32,
}

impl Host {
    /// The processor this process runs on.
    pub fn now() -> Self {
        Self::read(
            Path::new("/proc/cpuinfo"),
            Path::new("/sys/devices/system/cpu"),
        )
    }

    /// The processor as `cpuinfo` (a `/proc/cpuinfo`) and `sys` (a
    /// `/sys/devices/system/cpu`) describe it; what cannot be read is left empty.
    pub fn read(cpuinfo: &Path, sys: &Path) -> Self {
        let info = std::fs::read_to_string(cpuinfo).unwrap_or_default();
        let field = |name: &str| cpuinfo_field(&info, name);
        let number = |name: &str| field(name).and_then(|v| v.parse().ok());
        let mut caches: Vec<Cache> = std::fs::read_dir(sys.join("cpu0/cache"))
            .into_iter()
            .flatten()
            .flatten()
            .filter(|e| e.file_name().to_string_lossy().starts_with("index"))
            .filter_map(|e| cache(&e.path()))
            .collect();
        caches.sort_by(|a, b| (a.level, &a.kind).cmp(&(b.level, &b.kind)));
        let mitigations = std::fs::read_dir(sys.join("vulnerabilities"))
            .into_iter()
            .flatten()
            .flatten()
            .filter_map(|e| {
                let state = std::fs::read_to_string(e.path()).ok()?;
                Some((
                    e.file_name().to_string_lossy().into_owned(),
                    state.trim().to_string(),
                ))
            })
            .collect();
        Host {
            vendor: field("vendor_id").unwrap_or_default(),
            family: number("cpu family"),
            model: number("model"),
            stepping: number("stepping"),
            caches,
            mitigations,
            virtualised: field("flags").is_some_and(|f| f.split(' ').any(|x| x == "hypervisor")),
        }
    }

    /// One line for a report: `AuthenticAMD family 25 model 17; L1d 32 KiB, L2 1 MiB, L3 32
    /// MiB; virtualised`.
    pub fn summary(&self) -> String {
        let mut s = self.vendor.clone();
        if let (Some(f), Some(m)) = (self.family, self.model) {
            s += &format!(" family {f} model {m}");
        }
        let caches: Vec<String> = self
            .caches
            .iter()
            .filter(|c| c.kind != "Instruction")
            .map(|c| {
                let kind = if c.kind == "Data" { "d" } else { "" };
                format!("L{}{kind} {}", c.level, crate::show_bytes(c.bytes))
            })
            .collect();
        if !caches.is_empty() {
            s += &format!("; {}", caches.join(", "));
        }
        if self.virtualised {
            s += "; virtualised";
        }
        s
    }
}

/// The cache described by a `cpuN/cache/indexK` directory.
fn cache(dir: &Path) -> Option<Cache> {
    let read = |f: &str| {
        std::fs::read_to_string(dir.join(f))
            .ok()
            .map(|s| s.trim().to_string())
    };
    let size = read("size")?;
    let (digits, unit) = size.split_at(
        size.find(|c: char| !c.is_ascii_digit())
            .unwrap_or(size.len()),
    );
    let scale = match unit {
        "K" => 1 << 10,
        "M" => 1 << 20,
        "G" => 1 << 30,
        "" => 1,
        _ => return None,
    };
    let shared_by = read("shared_cpu_list").map_or(1, |l| cpu_list_len(&l));
    Some(Cache {
        level: read("level")?.parse().ok()?,
        kind: read("type")?,
        bytes: digits.parse::<u64>().ok()? * scale,
        shared_by,
    })
}

/// The CPUs a list such as `0-3,8-11` or `5` names.
fn cpu_list_len(list: &str) -> u32 {
    list.split(',')
        .filter(|r| !r.is_empty())
        .map(|r| match r.split_once('-') {
            Some((a, b)) => match (a.parse::<u32>(), b.parse::<u32>()) {
                (Ok(a), Ok(b)) if b >= a => b - a + 1,
                _ => 1,
            },
            None => 1,
        })
        .sum()
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
    fn the_host_is_read_from_the_kernel_files() {
        let dir = tempfile::tempdir().unwrap();
        let info = dir.path().join("cpuinfo");
        std::fs::write(
            &info,
            "processor\t: 0\nvendor_id\t: GenuineIntel\ncpu family\t: 6\nmodel\t\t: 106\n\
             model name\t: Intel(R) Xeon(R)\nstepping\t: 6\nflags\t\t: fpu sse hypervisor\n\n\
             processor\t: 1\nvendor_id\t: Other\n",
        )
        .unwrap();
        let sys = dir.path().join("cpu");
        for (i, level, kind, size, shared) in [
            (0, "1", "Data", "48K", "0-1"),
            (1, "1", "Instruction", "32K", "0-1"),
            (2, "2", "Unified", "2048K", "0-1"),
            (3, "3", "Unified", "300M", "0-1,4-7"),
        ] {
            let d = sys.join(format!("cpu0/cache/index{i}"));
            std::fs::create_dir_all(&d).unwrap();
            for (f, v) in [
                ("level", level),
                ("type", kind),
                ("size", size),
                ("shared_cpu_list", shared),
            ] {
                std::fs::write(d.join(f), format!("{v}\n")).unwrap();
            }
        }
        std::fs::create_dir_all(sys.join("vulnerabilities")).unwrap();
        std::fs::write(sys.join("vulnerabilities/meltdown"), "Not affected\n").unwrap();
        std::fs::write(
            sys.join("vulnerabilities/retbleed"),
            "Mitigation: Enhanced IBRS\n",
        )
        .unwrap();
        let h = Host::read(&info, &sys);
        assert_eq!(
            (h.vendor.as_str(), h.family, h.model, h.stepping),
            ("GenuineIntel", Some(6), Some(106), Some(6))
        );
        assert!(h.virtualised);
        assert_eq!(h.caches.len(), 4);
        assert_eq!(
            (
                h.caches[0].level,
                h.caches[0].kind.as_str(),
                h.caches[0].bytes
            ),
            (1, "Data", 48 << 10)
        );
        assert_eq!((h.caches[3].bytes, h.caches[3].shared_by), (300 << 20, 6));
        assert_eq!(h.mitigations["retbleed"], "Mitigation: Enhanced IBRS");
        assert_eq!(
            h.summary(),
            "GenuineIntel family 6 model 106; L1d 48.0 KiB, L2 2.0 MiB, L3 300.0 MiB; virtualised"
        );
        // Nothing to read: an empty description, not an error.
        let none = Host::read(&dir.path().join("missing"), &dir.path().join("missing"));
        assert_eq!(none, Host::default());
        // It round-trips through run.json.
        let json = serde_json::to_value(&h).unwrap();
        assert_eq!(serde_json::from_value::<Host>(json).unwrap(), h);
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
