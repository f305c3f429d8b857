//! Writing a finished run into its output directory (see `docs/dla.md`, "Outputs"); every file
//! is written atomically, so a file is either complete or absent.
//!
//! | file | content |
//! |---|---|
//! | `run.json` | manifest: parameters, seed, timings, peak memory, results |
//! | `growth.csv` | `n,radius_of_gyration,r_ext,seconds` at about 1000 log-spaced sizes |
//! | `positions.csv` | `--positions csv`: `x,y` or `x,y,z`, arrival order |
//! | `positions.bin` | `--positions bin`: see [`write_positions_bin`] |
//! | `positions.xyz` | `--positions xyz`: XYZ point cloud, element `C` |
//! | `dla.png` | `--png`: the cluster shaded by arrival order (3D: projection on x, y) |

use crate::sim::Simulation;
use crate::space::{Dim, Space};
use core_lattice::io::{AtomicFile, CsvField, CsvWriter, RunClock, RunManifest, write_png_gray};
use serde_json::json;
use std::io::Write;
use std::path::Path;

pub use core_lattice::io::OutputError;

/// Format of the optional positions file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum PositionsFormat {
    /// No positions file (positions are not kept in memory).
    None,
    /// `positions.csv`.
    Csv,
    /// `positions.bin`.
    Bin,
    /// `positions.xyz`.
    Xyz,
}

/// Write every output of `sim` into `dir` (which must exist) and return the manifest. When the
/// fractal dimension cannot be fitted, its results are null and `fit_error` says why.
pub fn write_outputs<const D: usize>(
    sim: &Simulation<D>,
    clock: &RunClock,
    dir: &Path,
    positions: PositionsFormat,
    png: bool,
) -> Result<RunManifest, OutputError>
where
    Dim<D>: Space<D>,
{
    let mut w = CsvWriter::create(
        dir.join("growth.csv"),
        &["n", "radius_of_gyration", "r_ext", "seconds"],
    )?;
    for s in sim.samples() {
        w.row(&[&s.n, &s.radius_of_gyration, &s.r_ext, &s.seconds])?;
    }
    w.finish()?;

    if let Some(pos) = sim.positions() {
        match positions {
            PositionsFormat::None => {}
            PositionsFormat::Csv => {
                let mut w = CsvWriter::create(dir.join("positions.csv"), &Dim::<D>::AXES)?;
                for p in pos {
                    let f: Vec<&dyn CsvField> = p.iter().map(|x| x as &dyn CsvField).collect();
                    w.row(&f)?;
                }
                w.finish()?;
            }
            PositionsFormat::Bin => write_positions_bin(&dir.join("positions.bin"), pos)?,
            PositionsFormat::Xyz => {
                let mut f = AtomicFile::create(dir.join("positions.xyz"))?;
                {
                    let mut b = std::io::BufWriter::new(&mut f);
                    writeln!(b, "{}", pos.len())?;
                    writeln!(b, "DLA cluster, seed {}, arrival order", sim.seed())?;
                    for p in pos {
                        // XYZ holds three coordinates: z = 0 in the plane.
                        let z = p.get(2).copied().unwrap_or(0.0);
                        writeln!(b, "C {} {} {}", p[0], p[1], z)?;
                    }
                    b.flush()?;
                }
                f.commit()?;
            }
        }
        if png {
            write_picture(pos, &dir.join("dla.png"))?;
        }
    }

    let fit = sim.fractal_dimension();
    let params = sim.params();
    let mut m = clock.finish(
        "dla",
        env!("CARGO_PKG_VERSION"),
        sim.seed(),
        params.threads,
        params,
    )?;
    let n = sim.particles();
    let bpp = m
        .peak_rss_bytes
        .map(|b| json!(b as f64 / n as f64))
        .unwrap_or(serde_json::Value::Null);
    m.set_result("particles", n)
        .set_result("radius_of_gyration", sim.radius_of_gyration())
        .set_result("r_ext", sim.r_ext())
        .set_result("discarded_walkers", sim.discarded_walkers())
        .set_result("pdla_parallel_seconds", sim.parallel_seconds())
        .set_result("pdla_lock_wait_seconds", sim.lock_wait_seconds())
        .set_result("state_hash", sim.state_hash())
        .set_result("tree_memory_bytes", sim.tree().memory_bytes() as u64)
        .set_result(
            "distance_map_bytes",
            (sim.cluster().memory_bytes() - sim.tree().memory_bytes()) as u64,
        )
        .set_result("bytes_per_particle", bpp);
    match fit {
        Ok(f) => {
            m.set_result("fractal_dimension", f.slope)
                .set_result("fractal_dimension_stderr", f.slope_stderr)
                .set_result("fit_points", f.n as u64);
        }
        Err(e) => {
            m.set_result("fractal_dimension", serde_json::Value::Null)
                .set_result("fractal_dimension_stderr", serde_json::Value::Null)
                .set_result("fit_error", e.to_string());
        }
    }
    m.write(dir)?;
    Ok(m)
}

/// `positions.bin`: little-endian; the 8 bytes `DLAPOS01`, `u32` dimension `D`, `u64` count
/// `N`, then `N * D` `f64` coordinates, particle by particle in arrival order.
pub fn write_positions_bin<const D: usize>(
    path: &Path,
    pos: &[[f64; D]],
) -> Result<(), OutputError> {
    let mut f = AtomicFile::create(path)?;
    {
        let mut b = std::io::BufWriter::new(&mut f);
        b.write_all(b"DLAPOS01")?;
        b.write_all(&(D as u32).to_le_bytes())?;
        b.write_all(&(pos.len() as u64).to_le_bytes())?;
        for p in pos {
            for x in p {
                b.write_all(&x.to_le_bytes())?;
            }
        }
        b.flush()?;
    }
    f.commit()?;
    Ok(())
}

/// The cluster as a grayscale picture on black, projected on (x, y), each particle a disc of
/// diameter 1 (at least one pixel) shaded from dark (first) to white (last) by arrival order.
fn write_picture<const D: usize>(pos: &[[f64; D]], path: &Path) -> Result<(), OutputError> {
    let extent = pos
        .iter()
        .map(|p| p[0].abs().max(p[1].abs()))
        .fold(0.0, f64::max)
        + 1.0;
    let side = ((2.0 * extent).ceil() as u32).clamp(64, 4096);
    let scale = f64::from(side) / (2.0 * extent);
    let mut px = vec![0u8; (side as usize) * (side as usize)];
    let n = pos.len().max(2) as f64;
    let rad = (0.5 * scale).max(0.5);
    for (i, p) in pos.iter().enumerate() {
        let shade = (55.0 + 200.0 * i as f64 / (n - 1.0)) as u8;
        let cx = (p[0] + extent) * scale;
        let cy = (extent - p[1]) * scale;
        let (x0, x1) = (
            (cx - rad).floor().max(0.0) as u32,
            ((cx + rad).ceil() as u32).min(side - 1),
        );
        let (y0, y1) = (
            (cy - rad).floor().max(0.0) as u32,
            ((cy + rad).ceil() as u32).min(side - 1),
        );
        for y in y0..=y1 {
            for x in x0..=x1 {
                let (dx, dy) = (f64::from(x) + 0.5 - cx, f64::from(y) + 0.5 - cy);
                if dx * dx + dy * dy <= rad * rad || (x1 == x0 && y1 == y0) {
                    let at = y as usize * side as usize + x as usize;
                    px[at] = px[at].max(shade);
                }
            }
        }
    }
    write_png_gray(path, side, side, &px)?;
    Ok(())
}
