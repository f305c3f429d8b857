//! Writing a finished run into its output directory (see `docs/dla.md`, "Outputs"). The run
//! streamed `growth.csv` and, when positions are needed, `positions.npy` as it grew (see
//! [`Simulation::stream_into`]); the other files are written here, atomically, so each is
//! either complete or absent. Positions files other than `positions.npy` are made by reading
//! it back row by row, so no output needs the positions in memory.
//!
//! | file | content |
//! |---|---|
//! | `run.json` | manifest: parameters, seed, timings, peak memory, results |
//! | `growth.csv` | `n,radius_of_gyration,r_ext,seconds`, 200 log-spaced sizes per decade |
//! | `positions.npy` | every position, arrival order, float64 `(N, D)` (NumPy `.npy`) |
//! | `positions.csv` | `--positions csv`: `x,y`, `x,y,z`, `x,y,z,w` or `x,y,z,w,v`, arrival order |
//! | `positions.bin` | `--positions bin`: see [`write_positions_bin`] |
//! | `positions.xyz` | `--positions xyz`: extended XYZ point cloud (OVITO, VMD, ASE), element `C`; 2D and 3D only |
//! | `positions.vtk` | `--positions vtk`: legacy VTK points with the arrival index as a scalar (ParaView); 2D and 3D only |
//! | `dla.png` | `--png`: the figure of the cluster, coloured by arrival order or, when a pixel spans more than a diameter, by particles per pixel (feature `figures`, see [`crate::figure`]) |
//! | `dla.gif` | `--animate`: the growth of the cluster, one frame every `--animate-every` particles |
//! | `branches.csv`, `branches.png` | the Horton-Strahler analysis (whenever the parents are recorded; the chart with `--png`) |
//! | `deposit.csv`, `deposit_growth.csv`, `deposit.png` | a deposit's profile, surviving trees and active zone (`--substrate-width`; the chart with `--png`; see [`crate::deposit`]) |

use crate::sim::{GROWTH, GROWTH_COLUMNS, Simulation};
use crate::space::{Dim, Space};
use run_io::{
    AtomicFile, Attribute, Coords, CsvWriter, PointFormat, PointSet, ProcessUsage, RunClock,
    RunManifest, write_points,
};
use serde_json::json;
use std::io::Write;
use std::path::Path;

pub use crate::sim::{each_particle, each_position};
pub use run_io::OutputError;
use run_io::schema::{Axes, Column, Dtype, Form, Output};

/// Every output of `dla` with its columns, names, dtypes and units (`docs/outputs.md`; see
/// [`run_io::schema`]).
pub const SCHEMA: &[Output] = &[
    GROWTH,
    crate::branches::BRANCHES,
    crate::deposit::DEPOSIT,
    crate::deposit::DEPOSIT_GROWTH,
    Output {
        file: "positions",
        form: Form::Points {
            axes: Axes::Letters,
            dtype: Dtype::Float64,
            unit: "diameters",
        },
        python: "positions",
        when: Some("--positions"),
        columns: &[Column::new(
            "parent",
            Dtype::Int64,
            "arrival index of the particle it stuck to (-1: the seed)",
        )],
    },
];

/// Format of the optional positions file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum PositionsFormat {
    /// No positions file (positions are not kept in memory).
    None,
    /// `positions.npy` only (written as the cluster grows).
    Npy,
    /// `positions.csv`.
    Csv,
    /// `positions.bin`.
    Bin,
    /// `positions.xyz` (extended XYZ).
    Xyz,
    /// `positions.vtk` (legacy VTK, the arrival index as a point scalar).
    Vtk,
}

impl PositionsFormat {
    /// The name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            PositionsFormat::None => "none",
            PositionsFormat::Npy => "npy",
            PositionsFormat::Csv => "csv",
            PositionsFormat::Bin => "bin",
            PositionsFormat::Xyz => "xyz",
            PositionsFormat::Vtk => "vtk",
        }
    }
}

/// Write every output of `sim` into `dir` (which must exist) and return the manifest; `png` is
/// the side of `dla.png` in pixels, if one is wanted (feature `figures`: without it, asking for
/// one is an error and nothing is written). When the fractal dimension cannot be
/// fitted, its results are null and `fit_error` says why. Call [`Simulation::sync_streams`]
/// first when the run streams into `dir`.
pub fn write_outputs<const D: usize>(
    sim: &Simulation<D>,
    clock: &RunClock,
    dir: &Path,
    positions: PositionsFormat,
    png: Option<u32>,
) -> Result<RunManifest, OutputError>
where
    Dim<D>: Space<D>,
{
    // Without feature `figures` the library cannot draw: refused before any file is written.
    if png.is_some() && !cfg!(feature = "figures") {
        let e = std::io::Error::new(
            std::io::ErrorKind::Unsupported,
            "dla.png needs feature `figures`",
        );
        return Err(e.into());
    }
    // The simulation's peak, before the output stage (the PNG's pixels, a positions file
    // converted from positions.npy) can raise the process's high-water mark.
    let simulation_peak = ProcessUsage::now().map(|u| u.peak_rss_bytes);
    if !sim.streams_growth() {
        let mut w = CsvWriter::create(dir.join("growth.csv"), &GROWTH_COLUMNS)?;
        for s in sim.samples() {
            w.row(&[&s.n, &s.radius_of_gyration, &s.r_ext, &s.seconds])?;
        }
        w.finish()?;
    }
    match positions {
        PositionsFormat::None | PositionsFormat::Npy => {}
        PositionsFormat::Bin => write_positions_bin(sim, dir)?,
        PositionsFormat::Xyz | PositionsFormat::Vtk if D > 3 => {
            // Both hold three coordinates; writing a projection under the full file's name
            // would lose data silently.
            return Err(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                format!(
                    "--positions {} holds three coordinates, not {D}; use npy, csv or bin",
                    positions.name()
                ),
            )
            .into());
        }
        PositionsFormat::Csv | PositionsFormat::Xyz | PositionsFormat::Vtk => {
            let format = match positions {
                PositionsFormat::Csv => PointFormat::Csv,
                PositionsFormat::Xyz => PointFormat::Xyz,
                _ => PointFormat::Vtk,
            };
            let title = format!(
                "DLA cluster, {D}D, {} particles, seed {}, arrival order",
                sim.particles(),
                sim.seed()
            );
            let links = sim.params().connectivity;
            let parent = [Attribute {
                name: "parent",
                labels: None,
            }];
            let set = PointSet {
                n: sim.particles(),
                axes: &Dim::<D>::AXES,
                integer_coordinates: false,
                attributes: if links { &parent } else { &[] },
                index: Some("arrival"),
                title: &title,
                parent: links.then_some(0),
            };
            write_points(dir, "positions", format, &set, &mut |f| {
                each_particle(sim, dir, |_, p: &[f64; D], parent| match parent {
                    Some(k) => Ok(f(Coords::Float(p), &[k])?),
                    None => Ok(f(Coords::Float(p), &[])?),
                })
            })?;
        }
    }
    #[cfg(feature = "figures")]
    if let Some(side) = png {
        crate::figure::write_png(sim, dir, &dir.join("dla.png"), side)?;
    }
    let branches = branches_of(sim, dir)?;
    if let Some(b) = &branches {
        crate::branches::write_csv(b, dir)?;
        #[cfg(feature = "figures")]
        if png.is_some() {
            crate::branches::write_png(b, sim.particles(), sim.seed(), &dir.join("branches.png"))?;
        }
    }

    let deposit = deposit_of(sim, dir)?;
    if let Some(d) = &deposit {
        crate::deposit::write_csv(d, dir)?;
        #[cfg(feature = "figures")]
        if png.is_some() {
            crate::deposit::write_png(d, sim.seed(), &dir.join("deposit.png"))?;
        }
    }

    let mut m = manifest_with_peak(sim, clock, simulation_peak)?;
    if let Some(b) = &branches {
        set_branch_results(&mut m, b);
    }
    if let Some(d) = &deposit {
        crate::deposit::set_results(&mut m, d);
    }
    // The high-water mark now covers the output stage too.
    m.set_result("output_peak_rss_bytes", m.peak_rss_bytes);
    m.write(dir)?;
    Ok(m)
}

/// The run's manifest, `run.json` as [`write_outputs`] writes it: parameters, seed, the
/// measurements of `clock` taken now, and every result (`particles`, `radius_of_gyration`,
/// `r_ext`, `state_hash`, the fractal dimension or `fit_error`, the PDLA and memory figures).
/// The one place these results are assembled, for the `dla` binary and the Python bindings.
/// Called right after the simulation (as the Python bindings do), the process's peak memory is
/// the simulation's: `simulation_peak_rss_bytes` and `bytes_per_particle` measure it, and
/// `output_peak_rss_bytes` is null (no output stage ran; [`write_outputs`] sets it). A
/// deposit's results are added by the caller, which analyses the particles once for both its
/// arrays and [`crate::deposit::set_results`] (the Python bindings).
pub fn manifest<const D: usize>(
    sim: &Simulation<D>,
    clock: &RunClock,
) -> Result<RunManifest, OutputError>
where
    Dim<D>: Space<D>,
{
    let peak = ProcessUsage::now().map(|u| u.peak_rss_bytes);
    let mut m = manifest_with_peak(sim, clock, peak)?;
    // No output stage ran.
    m.set_result("output_peak_rss_bytes", serde_json::Value::Null);
    if let Some(parents) = sim.parents() {
        let b = crate::branches::Branches::from_parents(parents)
            .map_err(|e| std::io::Error::other(e.to_string()))?;
        set_branch_results(&mut m, &b);
    }
    Ok(m)
}

/// The analysis of a deposit ([`crate::deposit`]) from the particles and parents kept in
/// memory or streamed to `dir`; `None` for radial growth or a run without `connectivity`.
pub fn deposit_of<const D: usize>(
    sim: &Simulation<D>,
    dir: &Path,
) -> Result<Option<crate::deposit::Deposit>, OutputError> {
    let Some(substrate) = sim.params().substrate() else {
        return Ok(None);
    };
    if !sim.params().connectivity {
        return Ok(None);
    }
    let mut d = crate::deposit::Deposit::new(D, substrate.width);
    each_particle(sim, dir, |_, p: &[f64; D], parent| {
        d.push(p, parent.unwrap_or(-1))
            .map_err(|e| std::io::Error::other(e.to_string()).into())
    })?;
    d.finish();
    Ok(Some(d))
}

/// The one-line summary the `dla` binary prints at the end of a run, from its manifest `m`.
pub fn summary<const D: usize>(sim: &Simulation<D>, m: &RunManifest, dir: &Path) -> String {
    let number = |key: &str, digits: usize| {
        m.results
            .get(key)
            .and_then(|v| v.as_f64())
            .map_or_else(|| "n/a".to_string(), |d| format!("{d:.digits$}"))
    };
    let head = match sim.params().substrate() {
        Some(s) => format!(
            "dla: {} particles in {D}D on a substrate of width {}, height {:.2}, trees {} ({} still growing), density dimension {}",
            sim.particles(),
            s.width,
            sim.r_ext(),
            number("deposit_trees", 0),
            number("deposit_growing_trees", 0),
            number("density_dimension", 4),
        ),
        None => format!(
            "dla: {} particles in {D}D, R_g {:.2}, R_ext {:.2}, D_f {}",
            sim.particles(),
            sim.radius_of_gyration(),
            sim.r_ext(),
            number("fractal_dimension", 4),
        ),
    };
    format!(
        "{head} in {:.2} s; outputs in {}",
        m.wall_seconds,
        dir.display()
    )
}

/// The Horton-Strahler analysis of a run with `connectivity`, from the parents kept in memory
/// or in `positions_parent.npy` in `dir` (read from its end in blocks: 1 byte a particle);
/// `None` without connectivity.
pub fn branches_of<const D: usize>(
    sim: &Simulation<D>,
    dir: &Path,
) -> Result<Option<crate::branches::Branches>, OutputError> {
    if !sim.params().connectivity {
        return Ok(None);
    }
    let b = match sim.parents() {
        Some(parents) => {
            crate::branches::Branches::from_parents(parents).map_err(|e| e.to_string())
        }
        None => crate::branches::Branches::from_npy(
            &dir.join(crate::sim::PARENTS_FILE),
            sim.particles(),
        ),
    };
    b.map(Some)
        .map_err(|e| OutputError::from(std::io::Error::other(e)))
}

/// The branch analysis's results in `run.json`: the highest Horton-Strahler order, the trees,
/// and the fitted bifurcation and length ratios (null when the cluster has too few orders).
pub fn set_branch_results(m: &mut RunManifest, b: &crate::branches::Branches) {
    let range = b.fit_orders().map(|r| json!([r.start(), r.end()]));
    m.set_result("strahler_order", b.max_order())
        .set_result("trees", b.trees)
        .set_result("bifurcation_ratio", b.bifurcation_ratio())
        .set_result("length_ratio", b.length_ratio())
        .set_result("ratio_fit_orders", range);
}

/// [`manifest`] with the simulation's peak resident memory measured before the output stage
/// (`simulation_peak`), so that `bytes_per_particle` is the simulation's cost per particle and
/// not that of rendering `dla.png`.
fn manifest_with_peak<const D: usize>(
    sim: &Simulation<D>,
    clock: &RunClock,
    simulation_peak: Option<u64>,
) -> Result<RunManifest, OutputError>
where
    Dim<D>: Space<D>,
{
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
    let bpp = simulation_peak
        .map(|b| json!(b as f64 / n as f64))
        .unwrap_or(serde_json::Value::Null);
    m.set_result("particles", n)
        .set_result("radius_of_gyration", sim.radius_of_gyration())
        .set_result("r_ext", sim.r_ext())
        .set_result("discarded_walkers", sim.discarded_walkers())
        .set_result("pdla_parallel_seconds", sim.parallel_seconds())
        .set_result("pdla_lock_wait_seconds", sim.lock_wait_seconds())
        .set_result("pdla_phases", sim.pdla_phases())
        .set_result("walk_counts", json!(sim.walk_counts()))
        .set_result("state_hash", sim.state_hash())
        .set_result("tree_memory_bytes", sim.tree().memory_bytes() as u64)
        // Against the 2^32 - 2 the tree's 32-bit indices can number: the headroom left.
        .set_result("tree_point_slots", sim.tree().stats().point_slots as u64)
        .set_result(
            "distance_map_bytes",
            (sim.cluster().memory_bytes() - sim.tree().memory_bytes()) as u64,
        )
        .set_result("simulation_peak_rss_bytes", simulation_peak)
        .set_result("bytes_per_particle", bpp);
    match fit {
        _ if params.substrate().is_some() => {
            m.set_result("fractal_dimension", serde_json::Value::Null)
                .set_result("fractal_dimension_stderr", serde_json::Value::Null)
                .set_result(
                    "fit_error",
                    "a deposit has no radius-of-gyration fit: see density_dimension",
                );
        }
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
    Ok(m)
}

/// `positions.bin`: little-endian; the 8 bytes `DLAPOS01`, `u32` dimension `D`, `u64` count
/// `N`, then `N * D` `f64` coordinates, particle by particle in arrival order. With
/// `connectivity` the magic is `DLAPOS02` and `N` `i64` parents follow the coordinates.
pub fn write_positions_bin<const D: usize>(
    sim: &Simulation<D>,
    dir: &Path,
) -> Result<(), OutputError> {
    let mut f = AtomicFile::create(dir.join("positions.bin"))?;
    {
        let mut b = std::io::BufWriter::new(&mut f);
        let links = sim.params().connectivity;
        b.write_all(if links { b"DLAPOS02" } else { b"DLAPOS01" })?;
        b.write_all(&(D as u32).to_le_bytes())?;
        b.write_all(&sim.particles().to_le_bytes())?;
        each_position(sim, dir, |_, p: &[f64; D]| {
            for x in p {
                b.write_all(&x.to_le_bytes())?;
            }
            Ok(())
        })?;
        if links {
            each_particle(sim, dir, |_, _, parent| {
                b.write_all(&parent.unwrap_or(-1).to_le_bytes())?;
                Ok(())
            })?;
        }
        b.flush()?;
    }
    f.commit()?;
    Ok(())
}

/// Whether the outputs of a run of `params` read its positions back (a deposit's analysis,
/// [`deposit_of`]), so that a front end must sync them even where it was not asked to keep
/// them.
pub fn reads_positions(params: &crate::Params) -> bool {
    params.substrate().is_some()
}

/// [`default_png_side`] of a run's frame ([`Simulation::figure_half`]).
pub fn default_png_side_of<const D: usize>(sim: &Simulation<D>) -> u32 {
    default_png_side(sim.figure_half())
}

/// Side of `dla.png` in pixels when none is asked for: one pixel per diameter across the
/// cluster, at least [`PNG_MIN_SIDE`] and at most [`PNG_MAX_SIDE`].
pub fn default_png_side(r_ext: f64) -> u32 {
    ((2.0 * (r_ext + 1.0)).ceil() as u32).clamp(PNG_MIN_SIDE, PNG_MAX_SIDE)
}

/// Memory the buffers of a `side` x `side` `dla.png` take while it is drawn: per pixel of the
/// raster at most an arrival, a depth and a lighting value (16 bytes), its colour (3) and the
/// figure around it (axes and legend at most double the area: 6).
pub fn png_memory_bytes(side: u64) -> u64 {
    side.saturating_mul(side).saturating_mul(25)
}

/// Smallest default side of `dla.png`.
pub const PNG_MIN_SIDE: u32 = 512;
/// Largest default side of `dla.png` (any side up to 65536 may be asked for).
pub const PNG_MAX_SIDE: u32 = 4096;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_side_is_one_pixel_per_diameter_within_bounds() {
        assert_eq!(default_png_side(10.0), PNG_MIN_SIDE);
        assert_eq!(default_png_side(1000.0), 2002);
        assert_eq!(default_png_side(1e6), PNG_MAX_SIDE);
    }
}

#[cfg(test)]
mod schema_tests {
    use super::*;

    #[test]
    fn the_outputs_document_lists_the_schema() {
        let doc = include_str!("../../../docs/outputs.md");
        run_io::schema::check_doc(doc, "## `dla`", SCHEMA);
    }
}
