//! Measurement entry points for the scaling study of Hawick, James & Scogings (2006),
//! "Grid-Boxing for Spatial Simulation Performance Optimisation", section IV.B (Fig. 9,
//! Table I), and for the whole-step throughput (`docs/benchmarks.md`): library functions so
//! that `xtask`, examples and benches all measure the same thing the same way.
//!
//! - [`search_scaling_point`]: neighbour-search time and distance evaluations per step for one
//!   population at a fixed start density and one grid setting (one point of Fig. 9);
//!   [`search_scaling_point_with`] also picks whether the cell-index search is used.
//! - [`step_throughput`]: whole-step wall time with timing off, as animat-steps per second.
//! - [`scaling_params`]: the parameters both use (defaults, with the population split between
//!   the species in the default ratio and the start radius set by the density).
//!
//! None of these assert anything about time; they measure and report. Wall-clock figures depend
//! on the machine and its load. Invariants: the world is built before any clock starts, and
//! measuring never changes the trajectory (the reported state hashes are the untimed run's).
//!
//! ```
//! use animat::GridBox;
//! use animat::bench::search_scaling_point;
//! let c = search_scaling_point(500, 0.2, GridBox::Side(60), 3, 1).unwrap();
//! assert_eq!(c.animats, 500);
//! assert_eq!(c.steps, 3);
//! assert!(c.search_seconds_per_step >= 0.0);
//! ```

use crate::params::{GridBox, Params};
use crate::world::{StepStats, World, WorldError};
use serde::Serialize;
use std::time::Instant;

/// Animats per cell of the start disc in the scaling study, the same for every population of
/// its ladder: about the default start's density (2300 animats on a disc of radius 60).
pub const SCALING_DENSITY: f64 = 0.2;

/// Parameters of a scaling point: [`Params::default`] with `population` animats split between
/// foxes and rabbits in the default ratio (foxes rounded, at least one of each when
/// `population >= 2`), the start radius giving `density` animats per cell
/// ([`Params::radius_for_density`]), and the grid setting `grid`.
pub fn scaling_params(population: u64, density: f64, grid: GridBox) -> Params {
    let d = Params::default();
    let total = d.foxes + d.rabbits;
    let mut foxes = ((population as f64) * (d.foxes as f64) / (total as f64)).round() as u64;
    if population >= 2 {
        foxes = foxes.clamp(1, population - 1);
    } else {
        foxes = 0;
    }
    Params {
        foxes,
        rabbits: population - foxes,
        start_radius: Params::radius_for_density(population, density),
        grid_box: grid,
        ..d
    }
}

/// Cost of the neighbour search for one population (one point of the paper's Fig. 9).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SearchCost {
    /// Animats at the start.
    pub animats: u64,
    /// Start density (animats per cell).
    pub density: f64,
    /// Grid setting, as given to `--grid-box`.
    #[serde(serialize_with = "ser_display")]
    pub grid: GridBox,
    /// Whether the cell-index search was on ([`World::set_cell_search`]).
    pub cell_search: bool,
    /// Steps measured.
    pub steps: u64,
    /// Animat turns taken over the measured steps (the population at the start of each step,
    /// summed).
    pub animat_steps: u64,
    /// Mean seconds per step spent in perception queries (clock read around each animat's
    /// decision), without the time the thread waited for a CPU (on Linux: each step's search
    /// time scaled by the step's share of time on the CPU, from
    /// `/proc/thread-self/schedstat`), so that other processes on the machine do not inflate
    /// it.
    pub search_seconds_per_step: f64,
    /// Mean distance evaluations per step ([`spatial::plane::PlaneGrid::distance_evals`]).
    pub distance_evals_per_step: f64,
    /// Mean wall seconds per whole step, with the timing clock reads included.
    pub step_seconds: f64,
    /// Live foxes and rabbits after the last step.
    pub final_foxes: u64,
    /// Live rabbits after the last step.
    pub final_rabbits: u64,
    /// State hash after the last step (equal across grid settings).
    pub state_hash: u64,
}

fn ser_display<S: serde::Serializer>(g: &GridBox, s: S) -> Result<S::Ok, S::Error> {
    s.collect_str(g)
}

/// Measures the neighbour search of `steps` steps from the start of [`scaling_params`]
/// (`population` animats at `density` animats per cell, grid setting `grid`, run seed `seed`)
/// with [`World::set_timing`] on. The world is built before the clock starts.
///
/// # Errors
/// [`WorldError::Params`] if the parameters are invalid (for example `density > 0.5`).
pub fn search_scaling_point(
    population: u64,
    density: f64,
    grid: GridBox,
    steps: u64,
    seed: u64,
) -> Result<SearchCost, WorldError> {
    search_scaling_point_with(population, density, grid, steps, seed, true)
}

/// [`search_scaling_point`] with the cell-index search on or off
/// ([`World::set_cell_search`]): off measures the paper's structure, the grid boxes alone
/// (`none` is always the exhaustive scan).
///
/// # Errors
/// [`WorldError::Params`] if the parameters are invalid.
pub fn search_scaling_point_with(
    population: u64,
    density: f64,
    grid: GridBox,
    steps: u64,
    seed: u64,
    cell_search: bool,
) -> Result<SearchCost, WorldError> {
    let mut w = World::new(scaling_params(population, density, grid), seed)?;
    w.set_timing(true);
    w.set_cell_search(cell_search);
    let (mut search, mut evals) = (0.0, 0u64);
    let t = Instant::now();
    let (mut step_start, mut waited_before) = (Instant::now(), thread_run_delay());
    let (turns, done) = measured_steps(&mut w, steps, |s| {
        // The decisions are timed by the wall clock, so a step in which the thread waited for
        // a CPU (other processes on the machine) counts part of the wait as search. Waits
        // fall on the search in proportion to its share of the step, so the search's own
        // time is its wall time scaled by the step's share of time on the CPU.
        let wall = step_start.elapsed().as_secs_f64();
        let waited = thread_run_delay();
        let on_cpu = match (waited, waited_before) {
            (Some(b), Some(a)) if wall > 0.0 => (1.0 - (b - a) / wall).clamp(0.0, 1.0),
            _ => 1.0,
        };
        search += s.search_seconds * on_cpu;
        evals += s.distance_evals;
        (step_start, waited_before) = (Instant::now(), thread_run_delay());
    });
    let wall = t.elapsed().as_secs_f64();
    let per = |x: f64| if done > 0 { x / done as f64 } else { 0.0 };
    Ok(SearchCost {
        animats: population,
        density,
        grid,
        cell_search: w.cell_search(),
        steps: done,
        animat_steps: turns,
        search_seconds_per_step: per(search),
        distance_evals_per_step: per(evals as f64),
        step_seconds: per(wall),
        final_foxes: w.foxes(),
        final_rabbits: w.rabbits(),
        state_hash: state_hash_u64(&w),
    })
}

/// Whole-step throughput: animat-steps per second (the target and the figures are in
/// `docs/benchmarks.md`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Throughput {
    /// Animats at the start.
    pub animats: u64,
    /// Steps measured.
    pub steps: u64,
    /// Animat turns over the measured steps.
    pub animat_steps: u64,
    /// Wall seconds of the measured steps (timing off).
    pub seconds: f64,
    /// `animat_steps / seconds`.
    pub animat_steps_per_second: f64,
    /// CPU seconds of the measuring thread over the measured steps, where the platform says
    /// (Linux: `/proc/thread-self/schedstat`); on a loaded machine this is closer than
    /// `seconds` to what an idle core would give (cache sharing still counts).
    pub cpu_seconds: Option<f64>,
    /// State hash after the last step.
    pub state_hash: u64,
}

/// Runs `warmup` unmeasured steps and then `steps` measured steps from the start of
/// [`scaling_params`], with timing off, and reports animat-steps per second.
///
/// # Errors
/// [`WorldError::Params`] if the parameters are invalid.
pub fn step_throughput(
    population: u64,
    density: f64,
    grid: GridBox,
    warmup: u64,
    steps: u64,
    seed: u64,
) -> Result<Throughput, WorldError> {
    let mut w = World::new(scaling_params(population, density, grid), seed)?;
    w.run(warmup);
    let cpu0 = thread_cpu_seconds();
    let t = Instant::now();
    let (turns, done) = measured_steps(&mut w, steps, |_| {});
    let seconds = t.elapsed().as_secs_f64();
    let cpu_seconds = thread_cpu_seconds().zip(cpu0).map(|(b, a)| b - a);
    Ok(Throughput {
        cpu_seconds,
        animats: population,
        steps: done,
        animat_steps: turns,
        seconds,
        animat_steps_per_second: if seconds > 0.0 {
            turns as f64 / seconds
        } else {
            0.0
        },
        state_hash: state_hash_u64(&w),
    })
}

/// Runs up to `steps` steps of `w`, stopping early when every animat has died, and hands each
/// step's counters to `each`. Returns the animat turns taken (the population at the start of
/// each step, summed) and the steps done.
fn measured_steps(w: &mut World, steps: u64, mut each: impl FnMut(StepStats)) -> (u64, u64) {
    let (mut turns, mut done) = (0u64, 0u64);
    for _ in 0..steps {
        let n = w.foxes() + w.rabbits();
        if n == 0 {
            break;
        }
        turns += n;
        each(w.step());
        done += 1;
    }
    (turns, done)
}

/// [`World::state_hash`] as a number.
fn state_hash_u64(w: &World) -> u64 {
    u64::from_str_radix(&w.state_hash(), 16).expect("a state hash is 16 hex digits")
}

/// CPU time of the calling thread in seconds (Linux `/proc/thread-self/schedstat`, whose
/// first field is nanoseconds on the CPU), or `None` where unavailable.
pub fn thread_cpu_seconds() -> Option<f64> {
    schedstat_field(0)
}

/// Seconds the calling thread has spent runnable but waiting for a CPU (the second field of
/// Linux `/proc/thread-self/schedstat`), or `None` where unavailable.
pub fn thread_run_delay() -> Option<f64> {
    schedstat_field(1)
}

fn schedstat_field(i: usize) -> Option<f64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    let ns: u64 = s.split_whitespace().nth(i)?.parse().ok()?;
    Some(ns as f64 * 1e-9)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scaling_params_split_and_density() {
        let p = scaling_params(2300, 0.2, GridBox::Side(60));
        assert_eq!((p.foxes, p.rabbits), (300, 2000));
        assert_eq!(p.start_radius, Params::radius_for_density(2300, 0.2));
        p.validate().unwrap();
        let p = scaling_params(1000, 0.2, GridBox::None);
        assert_eq!(p.foxes + p.rabbits, 1000);
        assert!(p.foxes >= 1 && p.rabbits >= 1);
    }

    #[test]
    fn grid_settings_measure_the_same_trajectory() {
        let a = search_scaling_point(800, 0.2, GridBox::Side(60), 4, 3).unwrap();
        let b = search_scaling_point(800, 0.2, GridBox::None, 4, 3).unwrap();
        let c = search_scaling_point_with(800, 0.2, GridBox::Side(60), 4, 3, false).unwrap();
        assert!(a.cell_search && !b.cell_search && !c.cell_search);
        assert_eq!(a.state_hash, b.state_hash);
        assert_eq!(a.state_hash, c.state_hash);
        assert_eq!(a.animat_steps, b.animat_steps);
        assert_eq!(a.steps, 4);
        let t = step_throughput(800, 0.2, GridBox::Side(60), 1, 3, 3).unwrap();
        assert_eq!(t.steps, 3);
        assert!(t.animat_steps > 0);
        assert!(search_scaling_point(100, 0.9, GridBox::Side(60), 1, 1).is_err());
    }
}
