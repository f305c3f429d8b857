//! Checkpoints of runs without a second copy of the cluster (serial runs between two walkers,
//! PDLA at a quiescent point between two parallel phases). The positions already
//! stream, in arrival order, to `positions.npy` in the run's directory; a checkpoint
//! (`checkpoint.bin`, beside it) holds only what is not in that file: the parameters, the seed,
//! the walk's random stream, the number of parallel phases run, the particle count `n` and the state hash after the first `n`
//! rows, the growth samples and the seconds grown. It is a few kilobytes at any size, written
//! atomically in `run_cli`'s checksummed `AGGSIMCK` envelope (model
//! [`CHECKPOINT_MODEL`]) after `positions.npy` has been flushed and synced.
//!
//! The payload is bincode, which is positional and not self-describing: a field added to a
//! struct moves every later byte, and serde's field defaults do not apply. So the parameters are
//! kept as `(name, text)` pairs ([`TextParams`]), which read with a new parameter at its
//! default, and the payload opens with a layout number ([`LAYOUT`], bumped with every change of
//! the snapshot's other fields);
//! the checkpoints written before it (before `sticking_probability` and `noise_reduction`),
//! which open with `dim` (2 to 5) instead, are read in their own layout and resume with both
//! parameters at 1, the model they were grown with.
//!
//! Invariant: restoring stores the first `n` rows of `positions.npy` again in arrival order,
//! which rebuilds the tree, `R_g`, `R_ext` and the state hash bit-identically; the rebuilt
//! hash must equal the recorded one, so a log that does not belong to the checkpoint is
//! refused. A resumed run ends with the state hash of an uninterrupted one, and one resumed
//! with a larger target with that of a run made to the larger target directly.

use super::growth::{Growth, Sample};
use crate::cluster::Cluster;
use crate::error::SimError;
use crate::params::{FarField, Params};
use crate::space::{DIMENSIONS, Dim, Space};
use core_lattice::rng::SimRng;
use run_io::{CheckpointError, NpyReader, StateHasher};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Model name in the checkpoint envelope.
pub const CHECKPOINT_MODEL: &str = "dla";
/// File name of a checkpoint in a run's directory.
pub const CHECKPOINT_FILE: &str = "checkpoint.bin";
/// File name of the streamed positions (the arrival log) in a run's directory.
pub const POSITIONS_FILE: &str = "positions.npy";
/// File name of the streamed parents (with `connectivity`), beside the positions: row `i`
/// is the arrival index of the particle particle `i` stuck to, `-1` for the seed.
pub const PARENTS_FILE: &str = "positions_parent.npy";

/// The layout of the payload this version writes: the number that opens it, before the
/// [`Snapshot`]. Never 2 to 5 (the `dim` that opens the checkpoints written before it).
const LAYOUT: u32 = 1001;

/// What `checkpoint.bin` holds: the layout number, then the snapshot.
#[derive(Serialize, Deserialize)]
struct Payload {
    layout: u32,
    snapshot: Snapshot,
}

/// [`Params`] as `(name, text)` pairs ([`core_lattice::spec::as_text`]): adding a parameter
/// does not change the layout, and a checkpoint written before it reads with the parameter at
/// its default.
#[derive(Serialize, Deserialize)]
#[serde(transparent)]
struct TextParams(#[serde(with = "core_lattice::spec::as_text")] Params);

/// The state a checkpoint holds (`P`: the parameters' layout, [`TextParams`] but for the
/// checkpoints of earlier versions).
#[derive(Serialize, Deserialize)]
struct Snapshot<P = TextParams> {
    params: P,
    seed: u64,
    rng: SimRng,
    /// Parallel (PDLA) phases run so far: a resumed run's phases draw from new streams.
    pdla_rounds: u32,
    /// Particles stored: the first `n` rows of `positions.npy`.
    n: u64,
    /// The state hash after those `n` particles.
    state_hash: String,
    samples: Vec<Sample>,
    next_sample: u64,
    last_off_schedule: bool,
    /// Wall seconds of growth so far (the `seconds` column of `growth.csv` continues).
    seconds: f64,
}

/// [`Params`] as the checkpoints written before `sticking_probability` and `noise_reduction`
/// hold it (their payload is a bare `Snapshot<ParamsBeforeVariants>`, without a layout
/// number); they resume with both fields at 1, the model they were grown with.
#[derive(Deserialize)]
#[cfg_attr(test, derive(Serialize))]
struct ParamsBeforeVariants {
    dim: usize,
    particles: u64,
    birth_gap: f64,
    far_field: FarField,
    death_ratio: f64,
    step_min: f64,
    precision: f64,
    threads: usize,
    serial_until: u64,
    fit_from: u64,
    keep_positions: bool,
    leaf_side: f64,
    distance_map: bool,
    near_cache: bool,
}

/// A `$To` struct literal holding the fields [`Params`] and [`ParamsBeforeVariants`] share,
/// copied from `$p`, then the fields `$rest` (those only `$To` has): the one list of the
/// shared fields, for the conversions both ways.
macro_rules! shared_params {
    ($To:ident from $p:expr, $($rest:tt)*) => {{
        let p = $p;
        $To {
            dim: p.dim,
            particles: p.particles,
            birth_gap: p.birth_gap,
            far_field: p.far_field,
            death_ratio: p.death_ratio,
            step_min: p.step_min,
            precision: p.precision,
            threads: p.threads,
            serial_until: p.serial_until,
            fit_from: p.fit_from,
            keep_positions: p.keep_positions,
            leaf_side: p.leaf_side,
            distance_map: p.distance_map,
            near_cache: p.near_cache,
            $($rest)*
        }
    }};
}

impl<P> Snapshot<P> {
    /// The same snapshot with its parameters converted by `f`.
    fn map_params<Q>(self, f: impl FnOnce(P) -> Q) -> Snapshot<Q> {
        Snapshot {
            params: f(self.params),
            seed: self.seed,
            rng: self.rng,
            pdla_rounds: self.pdla_rounds,
            n: self.n,
            state_hash: self.state_hash,
            samples: self.samples,
            next_sample: self.next_sample,
            last_off_schedule: self.last_off_schedule,
            seconds: self.seconds,
        }
    }
}

impl From<Snapshot<ParamsBeforeVariants>> for Snapshot {
    fn from(s: Snapshot<ParamsBeforeVariants>) -> Self {
        s.map_params(|p| {
            TextParams(shared_params!(Params from p,
                sticking_probability: 1.0,
                substrate_width: 0.0,
                drift: 0.0,
                ballistic: false,
                seed_set: None,
                noise_reduction: 1.0,
                connectivity: false,
            ))
        })
    }
}

/// The snapshot in `path`: a payload of layout [`LAYOUT`] or, failing that, one written before
/// layout numbers ([`ParamsBeforeVariants`]). An old payload never passes for a new one: it
/// opens with its `dim`, 2 to 5, where a new one has its layout. A payload that is neither is
/// refused with the error of today's layout.
fn read_snapshot(path: &Path) -> Result<Snapshot, CheckpointError> {
    let error = match run_io::read_checkpoint::<Payload>(path, CHECKPOINT_MODEL) {
        Ok(p) if p.layout == LAYOUT => return Ok(p.snapshot),
        Ok(p) => CheckpointError::Decode(format!(
            "payload layout {} (this version reads {LAYOUT})",
            p.layout
        )),
        Err(CheckpointError::Decode(e)) => CheckpointError::Decode(e),
        Err(e) => return Err(e),
    };
    match run_io::read_checkpoint::<Snapshot<ParamsBeforeVariants>>(path, CHECKPOINT_MODEL) {
        Ok(old) if DIMENSIONS.contains(&old.params.dim) => Ok(Snapshot::from(old)),
        _ => Err(error),
    }
}

/// A run rebuilt from a checkpoint.
pub(crate) struct Restored<const D: usize> {
    pub(crate) params: Params,
    pub(crate) seed: u64,
    pub(crate) rng: SimRng,
    pub(crate) pdla_rounds: u32,
    pub(crate) cluster: Cluster<D>,
    pub(crate) growth: Growth<D>,
    /// The `positions.npy` the cluster was rebuilt from.
    pub(crate) log: PathBuf,
}

/// Writes the checkpoint of a serial run streaming its positions into `dir`: syncs the
/// streams, then writes `dir/checkpoint.bin` atomically.
pub(crate) fn write<const D: usize>(
    dir: &Path,
    params: &Params,
    seed: u64,
    rng: &SimRng,
    pdla_rounds: u32,
    growth: &mut Growth<D>,
) -> Result<(), SimError> {
    let streams = growth
        .streams
        .as_mut()
        .filter(|s| s.positions.is_some())
        .ok_or_else(|| {
            SimError::CheckpointUsage(
                "a checkpoint needs the positions streamed to positions.npy (Simulation::stream_into)"
                    .into(),
            )
        })?;
    streams.sync()?;
    let snap = Snapshot {
        params: TextParams(params.clone()),
        seed,
        rng: rng.clone(),
        pdla_rounds,
        n: growth.n,
        state_hash: growth.hasher.finish_hex(),
        samples: growth.samples.clone(),
        next_sample: growth.next_sample,
        last_off_schedule: growth.last_off_schedule,
        seconds: growth.started.elapsed().as_secs_f64(),
    };
    let payload = Payload {
        layout: LAYOUT,
        snapshot: snap,
    };
    run_io::write_checkpoint(dir.join(CHECKPOINT_FILE), CHECKPOINT_MODEL, &payload)?;
    Ok(())
}

/// Reads the checkpoint in `dir` and rebuilds its run in `D` dimensions from
/// `dir/positions.npy`, with the target raised to `particles` if given (at least the
/// particles stored).
pub(crate) fn read<const D: usize>(
    dir: &Path,
    particles: Option<u64>,
) -> Result<Restored<D>, SimError>
where
    Dim<D>: Space<D>,
{
    let snap = read_snapshot(&dir.join(CHECKPOINT_FILE))?;
    let mut params = snap.params.0;
    params.validate()?;
    if params.dim != D {
        return Err(SimError::CheckpointUsage(format!(
            "--dim {} in the checkpoint, {D} given",
            params.dim
        )));
    }
    let extended = particles.is_some_and(|m| m != params.particles);
    if let Some(m) = particles {
        if m < snap.n {
            return Err(SimError::CheckpointUsage(format!(
                "--particles {m} is below the {} particles the checkpoint holds",
                snap.n
            )));
        }
        params.particles = m;
        params.validate()?;
    }
    // A radial run holds its seed from the start; a deposit may be checkpointed empty.
    let first = u64::from(params.substrate().is_none());
    if snap.n < first || snap.n > params.particles {
        return Err(SimError::CheckpointUsage(format!(
            "the checkpoint holds {} particles, outside {first}..={}",
            snap.n, params.particles
        )));
    }
    let log = dir.join(POSITIONS_FILE);
    let bad_log = |why: String| SimError::CheckpointUsage(format!("{}: {why}", log.display()));
    // Two passes over the log: the first hashes its first `n` rows (the stored positions, so
    // their hash is the state hash) and refuses a log that is not the checkpoint's before
    // anything is built from it: a damaged or foreign row far from the origin (1e6 diameters)
    // would otherwise size the distance maps for it (tens of gigabytes) before the hash could
    // refuse it. The second stores them.
    let open = || -> Result<NpyReader, SimError> {
        let reader = NpyReader::open(&log).map_err(|e| SimError::CheckpointUsage(e.to_string()))?;
        if reader.cols() != D {
            return Err(bad_log(format!("{} columns, not {D}", reader.cols())));
        }
        Ok(reader)
    };
    let mut p = [0.0; D];
    let mut reader = open()?;
    let mut hasher = StateHasher::new();
    for i in 0..snap.n {
        let more = reader
            .read_beyond(&mut p)
            .map_err(|e| SimError::CheckpointUsage(e.to_string()))?;
        if !more {
            return Err(bad_log(format!(
                "holds {i} positions, the checkpoint needs {}",
                snap.n
            )));
        }
        hasher.f64s(&p);
    }
    if hasher.finish_hex() != snap.state_hash {
        return Err(bad_log(format!(
            "does not belong to the checkpoint: its first {} positions hash to {}, the checkpoint recorded {}",
            snap.n,
            hasher.finish_hex(),
            snap.state_hash
        )));
    }
    let mut reader = open()?;
    let mut cluster = Cluster::new(&params)?;
    let mut growth = Growth::new(&params);
    for _ in 0..snap.n {
        let more = reader
            .read_beyond(&mut p)
            .map_err(|e| SimError::CheckpointUsage(e.to_string()))?;
        if !more {
            return Err(bad_log("changed while it was read".into()));
        }
        growth.add(&mut cluster, p, None, params.particles)?;
    }
    // Storing a position returns it unchanged (the log holds stored positions), so the
    // rebuilt state has the hash just checked; anything else is a log that changed between
    // the passes.
    if growth.hasher.finish_hex() != snap.state_hash {
        return Err(bad_log("changed while it was read".into()));
    }
    if params.connectivity {
        // The rebuild stored each particle with its arrival index as its tag, which is all
        // the tree needs; the parents themselves are in their own log.
        let keep = growth.parents.is_some();
        if let Some(parents) = read_parents(&dir.join(PARENTS_FILE), snap.n, keep)? {
            growth.parents = Some(parents);
        }
    }
    growth.samples = snap.samples;
    growth.next_sample = snap.next_sample;
    growth.last_off_schedule = snap.last_off_schedule;
    // The sample taken only because the old target was reached is not one a run made to the
    // new target takes.
    if extended && growth.last_off_schedule {
        growth.samples.pop();
        growth.last_off_schedule = false;
    }
    // A NaN (a damaged checkpoint) counts as no time rather than a panic.
    let seconds = Duration::try_from_secs_f64(snap.seconds.clamp(0.0, 1e9)).unwrap_or_default();
    if let Some(t) = Instant::now().checked_sub(seconds) {
        growth.started = t;
    }
    Ok(Restored {
        params,
        seed: snap.seed,
        rng: snap.rng,
        pdla_rounds: snap.pdla_rounds,
        cluster,
        growth,
        log,
    })
}

/// The first `n` parents of the log at `path`, checked to form a forest in arrival order
/// (every row an earlier particle's index or `-1`), read row by row; returned only with
/// `keep` (a run that keeps them in memory), so that checking costs no memory.
pub(crate) fn read_parents(path: &Path, n: u64, keep: bool) -> Result<Option<Vec<i64>>, SimError> {
    let bad = |why: String| SimError::CheckpointUsage(format!("{}: {why}", path.display()));
    let mut r = NpyReader::open_ints(path).map_err(|e| bad(e.to_string()))?;
    let mut out = keep.then(|| Vec::with_capacity(usize::try_from(n).unwrap_or(0)));
    for i in 0..n {
        match r.next_int().map_err(|e| bad(e.to_string()))? {
            Some(p) if p >= -1 && p < i as i64 => out.iter_mut().for_each(|v| v.push(p)),
            Some(p) => {
                return Err(bad(format!(
                    "row {i} names parent {p}, not an earlier particle"
                )));
            }
            None => return Err(bad(format!("holds {i} parents, the checkpoint needs {n}"))),
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::Simulation;

    impl From<Snapshot> for Snapshot<ParamsBeforeVariants> {
        fn from(s: Snapshot) -> Self {
            s.map_params(|TextParams(p)| {
                assert_eq!((p.sticking_probability, p.noise_reduction), (1.0, 1.0));
                shared_params!(ParamsBeforeVariants from p,)
            })
        }
    }

    /// A checkpoint in the layout written before `sticking_probability` and `noise_reduction`
    /// resumes, with both at 1, to the uninterrupted run's state hash; a payload that is
    /// neither layout is refused with today's layout's error.
    #[test]
    fn checkpoints_from_before_the_variants_resume() {
        let params = Params {
            particles: 800,
            ..Params::default()
        };
        let mut whole = Simulation::<2>::new(params.clone(), 3).unwrap();
        whole.run().unwrap();
        let dir = tempfile::tempdir().unwrap();
        let mut sim = Simulation::<2>::new(params, 3).unwrap();
        sim.stream_into(dir.path(), true).unwrap();
        for _ in 0..400 {
            sim.add_one().unwrap();
        }
        sim.write_checkpoint().unwrap();
        drop(sim);
        let path = dir.path().join(CHECKPOINT_FILE);
        let old = Snapshot::<ParamsBeforeVariants>::from(read_snapshot(&path).unwrap());
        run_io::write_checkpoint(&path, CHECKPOINT_MODEL, &old).unwrap();
        // The old payload opens with its dim where today's has its layout.
        if let Ok(p) = run_io::read_checkpoint::<Payload>(&path, CHECKPOINT_MODEL) {
            assert_eq!(p.layout, 2);
        }
        let mut resumed = Simulation::<2>::resume(dir.path(), None).unwrap();
        assert_eq!(resumed.particles(), 401);
        assert_eq!(resumed.params(), whole.params());
        resumed.run().unwrap();
        assert_eq!(resumed.state_hash(), whole.state_hash());
        // A payload of a later layout, or of none, is refused, naming the layout.
        let later = Payload {
            layout: LAYOUT + 1,
            snapshot: Snapshot::from(old),
        };
        run_io::write_checkpoint(&path, CHECKPOINT_MODEL, &later).unwrap();
        let e = read_snapshot(&path).err().unwrap().to_string();
        assert!(
            e.contains("payload layout 1002 (this version reads 1001)"),
            "{e}"
        );
        run_io::write_checkpoint(&path, CHECKPOINT_MODEL, &(1u8, "x")).unwrap();
        assert!(matches!(
            read_snapshot(&path),
            Err(CheckpointError::Decode(_))
        ));
    }
}
