//! The run manifest `run.json` every model writes into its `--out` directory
//! (`docs/architecture.md`, "How data flows through a run"), and the process measurements that
//! go into it.
//!
//! Its top-level keys are exactly: `model`, `version`, `seed`, `threads`, `params` (the full
//! validated parameters), `wall_seconds`, `cpu_seconds`, `peak_rss_bytes` (read from the
//! operating system with `getrusage(2)`, not estimated), `provenance` (date, version, git commit,
//! command line, host, CPU: [`Provenance`]) and `results` (a map each model fills).
//! `cpu_seconds` and `peak_rss_bytes` are `null` on a platform that cannot report them;
//! `provenance` is absent only from files written before it existed.

use super::atomic::write_atomic;
use super::provenance::Provenance;
use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};
use std::io;
use std::path::Path;
use std::time::Instant;

/// The record of one run, serialised as `run.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunManifest {
    /// Model name: `dlca`, `dla`, `animat`.
    pub model: String,
    /// Version of the crate that ran it.
    pub version: String,
    /// The run's seed.
    pub seed: u64,
    /// Worker threads used.
    pub threads: usize,
    /// The full validated parameters.
    pub params: Value,
    /// Wall-clock seconds of the run.
    pub wall_seconds: f64,
    /// CPU seconds (user + system) of the process during the run.
    pub cpu_seconds: Option<f64>,
    /// Peak resident set size of the process, in bytes, as the operating system reports it.
    pub peak_rss_bytes: Option<u64>,
    /// Where the run came from (absent from files written before it existed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub provenance: Option<Provenance>,
    /// Headline results, filled by the model.
    pub results: Map<String, Value>,
}

impl RunManifest {
    /// Set one result.
    pub fn set_result(&mut self, key: &str, value: impl Into<Value>) -> &mut Self {
        self.results.insert(key.to_string(), value.into());
        self
    }

    /// Write `dir/run.json` atomically (pretty-printed JSON, trailing newline).
    pub fn write(&self, dir: impl AsRef<Path>) -> io::Result<()> {
        let mut bytes = serde_json::to_vec_pretty(self).map_err(io::Error::other)?;
        bytes.push(b'\n');
        write_atomic(dir.as_ref().join("run.json"), &bytes)
    }

    /// Read a `run.json`.
    pub fn read(path: impl AsRef<Path>) -> io::Result<Self> {
        let bytes = std::fs::read(path)?;
        serde_json::from_slice(&bytes).map_err(|e| io::Error::new(io::ErrorKind::InvalidData, e))
    }
}

/// Resource usage of this process so far, from `getrusage(RUSAGE_SELF)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProcessUsage {
    /// User plus system CPU seconds.
    pub cpu_seconds: f64,
    /// Peak resident set size in bytes (the high-water mark over the process's life).
    pub peak_rss_bytes: u64,
}

impl ProcessUsage {
    /// Current usage, or `None` where the platform has no `getrusage`.
    #[cfg(unix)]
    pub fn now() -> Option<Self> {
        use nix::sys::resource::{UsageWho, getrusage};
        use nix::sys::time::TimeValLike;
        let u = getrusage(UsageWho::RUSAGE_SELF).ok()?;
        let cpu_us = u.user_time().num_microseconds() + u.system_time().num_microseconds();
        let max_rss = u64::try_from(u.max_rss()).ok()?;
        // Linux and the BSDs report kilobytes; macOS reports bytes.
        let peak_rss_bytes = if cfg!(target_os = "macos") {
            max_rss
        } else {
            max_rss * 1024
        };
        Some(ProcessUsage {
            cpu_seconds: cpu_us as f64 * 1e-6,
            peak_rss_bytes,
        })
    }

    /// Current usage, or `None` where the platform has no `getrusage`.
    #[cfg(not(unix))]
    pub fn now() -> Option<Self> {
        None
    }
}

/// Measures a run: start it before the work, then [`RunClock::finish`] builds the manifest.
#[derive(Debug, Clone)]
pub struct RunClock {
    start: Instant,
    cpu_at_start: Option<f64>,
}

impl Default for RunClock {
    fn default() -> Self {
        Self::start()
    }
}

impl RunClock {
    /// Start measuring now.
    pub fn start() -> Self {
        RunClock {
            start: Instant::now(),
            cpu_at_start: ProcessUsage::now().map(|u| u.cpu_seconds),
        }
    }

    /// Wall seconds since the start.
    pub fn wall_seconds(&self) -> f64 {
        self.start.elapsed().as_secs_f64()
    }

    /// CPU seconds since the start.
    pub fn cpu_seconds(&self) -> Option<f64> {
        Some(ProcessUsage::now()?.cpu_seconds - self.cpu_at_start?)
    }

    /// A manifest with the measurements taken now and empty `results`.
    pub fn finish(
        &self,
        model: &str,
        version: &str,
        seed: u64,
        threads: usize,
        params: &impl Serialize,
    ) -> Result<RunManifest, serde_json::Error> {
        let usage = ProcessUsage::now();
        Ok(RunManifest {
            model: model.to_string(),
            version: version.to_string(),
            seed,
            threads,
            params: serde_json::to_value(params)?,
            wall_seconds: self.wall_seconds(),
            cpu_seconds: self.cpu_seconds(),
            peak_rss_bytes: usage.map(|u| u.peak_rss_bytes),
            provenance: Some(Provenance::now(version, threads)),
            results: Map::new(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Serialize)]
    struct P {
        dim: usize,
        fill: f64,
    }

    #[test]
    fn manifest_has_exactly_the_documented_keys() {
        let clock = RunClock::start();
        // Touch 64 MiB so the peak RSS must exceed it.
        let v = vec![1u8; 64 << 20];
        let busy: u64 = v.iter().map(|&b| u64::from(b)).sum();
        assert_eq!(busy, 64 << 20);
        let mut m = clock
            .finish("dlca", "0.1.0", 42, 1, &P { dim: 2, fill: 0.01 })
            .unwrap();
        m.set_result("clusters", 100);
        let dir = tempfile::tempdir().unwrap();
        m.write(dir.path()).unwrap();
        let text = std::fs::read_to_string(dir.path().join("run.json")).unwrap();
        let json: Value = serde_json::from_str(&text).unwrap();
        let mut keys: Vec<&str> = json
            .as_object()
            .unwrap()
            .keys()
            .map(|s| s.as_str())
            .collect();
        keys.sort();
        assert_eq!(
            keys,
            [
                "cpu_seconds",
                "model",
                "params",
                "peak_rss_bytes",
                "provenance",
                "results",
                "seed",
                "threads",
                "version",
                "wall_seconds"
            ]
        );
        assert_eq!(json["params"]["dim"], 2);
        assert_eq!(json["results"]["clusters"], 100);
        if cfg!(unix) {
            assert!(json["peak_rss_bytes"].as_u64().unwrap() >= 64 << 20);
            assert!(json["cpu_seconds"].as_f64().unwrap() >= 0.0);
        }
        assert_eq!(RunManifest::read(dir.path().join("run.json")).unwrap(), m);
    }

    /// Floats written to run.json read back bit-exact (serde_json's `float_roundtrip`); this
    /// CPU-seconds value (102595 us times 1e-6) came back one ulp off with the default parser.
    #[test]
    fn floats_round_trip_exactly() {
        for x in [
            102_595.0f64 * 1e-6,
            0.1 + 0.2,
            1e-300,
            123456.789e10,
            f64::MIN_POSITIVE,
        ] {
            let text = serde_json::to_string(&x).unwrap();
            assert_eq!(
                serde_json::from_str::<f64>(&text).unwrap().to_bits(),
                x.to_bits(),
                "{text}"
            );
        }
    }
}
