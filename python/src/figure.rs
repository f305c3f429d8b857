//! The binaries' figures from results: `dla.png`, `dla.gif`, `dlca.png` and the animat
//! snapshots, drawn by the libraries' own raster code (`dla_pdla::figure`,
//! `dlca::figure`, `animat::output::SnapshotFrame`, all framed by `figures`) from the
//! arrays and results a result object holds, so that a file equals the binary's for the same
//! run byte for byte.

use crate::convert::{Count, count, value_error};
use figures::animation::ANIMATION_MAX_SIDE;
use figures::{PNG_SIZE_MAX, PNG_SIZE_MIN};
use numpy::{PyReadonlyArray1, PyReadonlyArray2};
use pyo3::exceptions::PyOSError;
use pyo3::prelude::*;
use run_io::OutputError;
use std::path::PathBuf;

/// The side of a raster in pixels, as `--png-size` takes it: a count in
/// [`PNG_SIZE_MIN`]..=`max` (`name` is the keyword argument, for messages).
pub fn side(name: &str, v: Option<Count>, max: u32) -> PyResult<Option<u32>> {
    let Some(v) = v else { return Ok(None) };
    let range = format!("{PNG_SIZE_MIN}..={max}");
    let shown = v.to_string();
    let s: u32 = count(&[], name, v).map_err(|e| {
        // `count`'s own range is u32's; the message names the raster's.
        let m = e.to_string();
        if m.contains("outside the accepted range") {
            value_error(format!(
                "{name} = {shown} is outside the accepted range {range}"
            ))
        } else if m.contains("not a whole number") {
            value_error(format!(
                "{name} = {shown} is not a whole number; a size in pixels is, in the accepted \
                 range {range}"
            ))
        } else {
            e
        }
    })?;
    if !(PNG_SIZE_MIN..=max).contains(&s) {
        return Err(value_error(format!(
            "{name} = {s} is outside the accepted range {range}"
        )));
    }
    Ok(Some(s))
}

/// The side of a PNG's raster (`--png-size`).
pub fn png_side(v: Option<Count>) -> PyResult<Option<u32>> {
    side("size", v, PNG_SIZE_MAX)
}

/// The side of an animation's figures (`--png-size` with `--animate`).
pub fn gif_side(v: Option<Count>) -> PyResult<Option<u32>> {
    side("size", v, ANIMATION_MAX_SIDE)
}

/// `frame_radius` (the animat binary's `--frame-radius`): half a frame's side in cells, 1..
pub fn frame_radius(v: Option<Count>) -> PyResult<Option<i64>> {
    v.map(|v| count::<u64>(&[], "frame_radius", v))
        .transpose()?
        .map(|r| {
            i64::try_from(r).ok().filter(|&r| r >= 1).ok_or_else(|| {
                value_error(format!(
                    "frame_radius = {r} is outside the accepted range 1..={}",
                    i64::MAX
                ))
            })
        })
        .transpose()
}

/// An animation a run writes as it goes: the `animate`, `animate_every` and `animate_size`
/// keywords of `aggsim.dlca` and `aggsim.animat`, which are the binaries' `--animate`,
/// `--animate-every` and `--png-size` (the binary writes to `OUT/<model>.gif`, Python to
/// `path`).
#[derive(Debug)]
pub struct Animate {
    /// The GIF file, written atomically when the run ends.
    pub path: PathBuf,
    /// Steps or sweeps between frames (default: the binary's).
    pub every: Option<u64>,
    /// Side of the figures in pixels (default: the binary's).
    pub side: Option<u32>,
}

impl Animate {
    /// The `OSError` of a run whose animation `a` could not be written (a run without one
    /// writes no file, so cannot fail this way; its error names no path).
    pub fn error(a: Option<&Animate>, e: OutputError) -> PyErr {
        write_error(a.map_or(std::path::Path::new(""), |a| a.path.as_path()), e)
    }

    /// The keywords checked as the binaries check their flags: `animate_every` at least 1,
    /// `animate_size` in 16..=16384, and neither without `animate`. `model` names the file in
    /// the message.
    pub fn from_args(
        path: Option<PathBuf>,
        every: Option<Count>,
        size: Option<Count>,
        model: &str,
    ) -> PyResult<Option<Self>> {
        let side = side("animate_size", size, ANIMATION_MAX_SIDE)?;
        let every = every
            .map(|v| count::<u64>(&[], "animate_every", v))
            .transpose()?;
        if every == Some(0) {
            return Err(value_error(
                "animate_every = 0 is outside the accepted range 1..",
            ));
        }
        match path {
            Some(path) => Ok(Some(Animate { path, every, side })),
            None if every.is_some() || side.is_some() => Err(value_error(format!(
                "animate_every and animate_size set up the animation written to animate; give \
                 animate a path (for example animate=\"{model}.gif\")"
            ))),
            None => Ok(None),
        }
    }
}

/// A figure that could not be written: `OSError` with the library's message.
pub fn write_error(path: &std::path::Path, e: OutputError) -> PyErr {
    PyOSError::new_err(format!("writing {}: {e}", path.display()))
}

/// The `(N, D)` float64 positions of a DLA result, C-contiguous as the result holds them.
pub fn dla_positions<'py>(obj: &Bound<'py, PyAny>) -> PyResult<PyReadonlyArray2<'py, f64>> {
    let a: PyReadonlyArray2<'py, f64> = obj
        .getattr("positions")?
        .extract()
        .map_err(|_| value_error("positions is not a float64 array of shape (N, D)"))?;
    if a.as_slice().is_err() {
        return Err(value_error("positions is not a C-contiguous array"));
    }
    Ok(a)
}

/// The particles of a DLCA result as (x1, x2, cluster id) rows in the order of its arrays,
/// checked against the lattice's `sizes`.
pub fn dlca_rows(obj: &Bound<'_, PyAny>, sizes: &[u64]) -> PyResult<Vec<(u64, u64, u32)>> {
    let x: PyReadonlyArray2<'_, i64> = obj
        .getattr("positions")?
        .extract()
        .map_err(|_| value_error("positions is not an int64 array of shape (N, D)"))?;
    let cluster: PyReadonlyArray1<'_, i64> = obj
        .getattr("cluster")?
        .extract()
        .map_err(|_| value_error("cluster is not an int64 array of shape (N,)"))?;
    let (x, cluster) = (x.as_array(), cluster.as_array());
    let d = sizes.len();
    if x.ncols() != d || x.nrows() != cluster.len() {
        return Err(value_error(format!(
            "positions of shape ({}, {}) and cluster of shape ({},) do not fit a {d}D lattice",
            x.nrows(),
            x.ncols(),
            cluster.len()
        )));
    }
    let mut rows = Vec::with_capacity(cluster.len());
    for (row, &id) in x.rows().into_iter().zip(cluster.iter()) {
        let coord = |a: usize| {
            u64::try_from(row[a])
                .ok()
                .filter(|&c| c < sizes[a])
                .ok_or_else(|| {
                    value_error(format!(
                        "site {row} is outside the lattice of sides {sizes:?}"
                    ))
                })
        };
        let id = u32::try_from(id)
            .ok()
            .filter(|&i| i != u32::MAX)
            .ok_or_else(|| value_error(format!("cluster id {id} is not a cluster id")))?;
        rows.push((coord(0)?, if d >= 2 { coord(1)? } else { 0 }, id));
    }
    Ok(rows)
}

/// The animats of an animat result as (cell, species) rows.
pub fn animat_rows(obj: &Bound<'_, PyAny>) -> PyResult<Vec<([i64; 2], ::animat::Species)>> {
    let x: PyReadonlyArray2<'_, i64> = obj
        .getattr("positions")?
        .extract()
        .map_err(|_| value_error("positions is not an int64 array of shape (M, 2)"))?;
    let species: PyReadonlyArray1<'_, i64> = obj
        .getattr("species")?
        .extract()
        .map_err(|_| value_error("species is not an int64 array of shape (M,)"))?;
    let (x, species) = (x.as_array(), species.as_array());
    if x.ncols() != 2 || x.nrows() != species.len() {
        return Err(value_error(format!(
            "positions of shape ({}, {}) and species of shape ({},) do not fit",
            x.nrows(),
            x.ncols(),
            species.len()
        )));
    }
    x.rows()
        .into_iter()
        .zip(species.iter())
        .map(|(row, &code)| {
            let s = u64::try_from(code)
                .ok()
                .and_then(::animat::Species::from_code)
                .ok_or_else(|| {
                    value_error(format!(
                        "species code {code}: aggsim.FOX (0) or aggsim.RABBIT (1)"
                    ))
                })?;
            Ok(([row[0], row[1]], s))
        })
        .collect()
}
