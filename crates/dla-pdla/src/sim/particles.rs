//! Reading a run's particles back in arrival order, with their parents: from memory
//! (`keep_positions`) or from the files the run streamed (`positions.npy`,
//! `positions_parent.npy`), row by row, so that no output needs them in memory.

use super::{PARENTS_FILE, POSITIONS_FILE, Simulation};
use std::path::Path;

/// Calls `f(i, p)` with every stored position `p` in arrival order (`i` from 0): from memory
/// (`keep_positions`) or from `positions.npy` in `dir`, read row by row.
///
/// # Errors
/// Neither source holds the positions, the file does not read, or `f` fails.
pub fn each_position<const D: usize>(
    sim: &Simulation<D>,
    dir: &Path,
    f: impl FnMut(u64, &[f64; D]) -> Result<(), run_io::OutputError>,
) -> Result<(), run_io::OutputError> {
    positions_from(sim, dir, f)
}

/// [`each_position`] with each particle's parent (`f(i, p, parent)`), from memory or from
/// `positions_parent.npy` in `dir`; the parent is `None` for a run without `connectivity`.
///
/// # Errors
/// As for [`each_position`], and for `positions_parent.npy`.
pub fn each_particle<const D: usize>(
    sim: &Simulation<D>,
    dir: &Path,
    mut f: impl FnMut(u64, &[f64; D], Option<i64>) -> Result<(), run_io::OutputError>,
) -> Result<(), run_io::OutputError> {
    if !sim.params().connectivity {
        return positions_from(sim, dir, |i, p| f(i, p, None));
    }
    let npy = |e: run_io::NpyError| std::io::Error::other(e.to_string());
    if let Some(parents) = sim.parents() {
        return positions_from(sim, dir, |i, p| f(i, p, parents.get(i as usize).copied()));
    }
    let path = dir.join(PARENTS_FILE);
    let mut r = run_io::NpyReader::open_ints(&path).map_err(npy)?;
    if r.rows() != sim.particles() {
        return Err(std::io::Error::other(format!(
            "{}: {} parents, not {}",
            path.display(),
            r.rows(),
            sim.particles()
        ))
        .into());
    }
    positions_from(sim, dir, |i, p| {
        let parent = r.next_int().map_err(npy)?;
        f(i, p, parent)
    })
}

fn positions_from<const D: usize>(
    sim: &Simulation<D>,
    dir: &Path,
    mut f: impl FnMut(u64, &[f64; D]) -> Result<(), run_io::OutputError>,
) -> Result<(), run_io::OutputError> {
    if let Some(pos) = sim.positions() {
        for (i, p) in pos.iter().enumerate() {
            f(i as u64, p)?;
        }
        return Ok(());
    }
    let npy = |e: run_io::NpyError| std::io::Error::other(e.to_string());
    let path = dir.join(POSITIONS_FILE);
    let mut r = run_io::NpyReader::open(&path).map_err(npy)?;
    if r.cols() != D || r.rows() != sim.particles() {
        return Err(std::io::Error::other(format!(
            "{}: shape ({}, {}), not ({}, {D})",
            path.display(),
            r.rows(),
            r.cols(),
            sim.particles()
        ))
        .into());
    }
    let mut p = [0.0; D];
    let mut i = 0;
    while r.next_row(&mut p).map_err(npy)? {
        f(i, &p)?;
        i += 1;
    }
    Ok(())
}
