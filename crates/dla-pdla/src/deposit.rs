//! The observables of a deposit grown on a substrate (`--substrate-width`), computed after the
//! run from the positions and parents in arrival order (one pass, [`Deposit::push`]):
//!
//! - the density profile: particles per unit volume in layers of one diameter, against the
//!   height above the substrate. In diffusion-limited deposition it falls as `h^(D - d)`
//!   (`D` the fractal dimension of the trees, `d` the space dimension) up to heights of about
//!   the width, above which one or a few trees remain and it levels off (Meakin, "Diffusion-
//!   controlled deposition on fibers and surfaces", 1983); [`Deposit::density_dimension`] fits
//!   `D` over the range where the power law holds;
//! - the surviving trees: how many trees (particles that touched the substrate and everything
//!   grown on them) reach each height;
//! - the active zone: in each block of `W^(d-1)` particles in arrival order (a monolayer's
//!   worth), the mean and standard deviation of the heights at which they stuck, and the
//!   deposit's height at the block's end; the trees that grew in the block.
//!
//! Memory: 4 bytes a particle (each particle's tree) while the analysis runs, plus a few
//! numbers per layer and per tree.

use run_io::schema::{Column, Dtype, Form, Output};
use serde::Serialize;

/// `deposit.csv`: one row per layer of one diameter.
pub const DEPOSIT: Output = Output {
    file: "deposit.csv",
    form: Form::Csv,
    python: "deposit",
    when: Some("--substrate-width"),
    columns: &[
        Column::new(
            "height",
            Dtype::Float64,
            "diameters (the layer's lower edge: centres at heights in [height, height + 1))",
        ),
        Column::new("particles", Dtype::Uint64, "particles in the layer"),
        Column::new(
            "density",
            Dtype::Float64,
            "particles per unit volume (the layer's particles over W^(d-1))",
        ),
        Column::new(
            "trees",
            Dtype::Uint64,
            "trees (each grown from a particle on the substrate) reaching the layer",
        ),
    ],
};

/// `deposit_growth.csv`: one row per block of `W^(d-1)` particles in arrival order.
pub const DEPOSIT_GROWTH: Output = Output {
    file: "deposit_growth.csv",
    form: Form::Csv,
    python: "deposit_growth",
    when: Some("--substrate-width"),
    columns: &[
        Column::new("n", Dtype::Uint64, "particles at the block's end"),
        Column::new(
            "height",
            Dtype::Float64,
            "diameters (the deposit's largest centre height)",
        ),
        Column::new(
            "mean_height",
            Dtype::Float64,
            "diameters (mean sticking height of the block's particles)",
        ),
        Column::new(
            "active_zone_width",
            Dtype::Float64,
            "diameters (standard deviation of the block's sticking heights)",
        ),
        Column::new(
            "growing_trees",
            Dtype::Uint64,
            "trees that received a particle in the block",
        ),
    ],
};

/// Lowest height of the density fit, in diameters: below it the first layers (the particles
/// on the substrate and just above) are denser than the power law.
pub const DENSITY_FIT_FROM: f64 = 8.0;

/// The density fit stops at this fraction of the width (above about the width the trees
/// compete at the scale of the strip and the profile levels off) and of the deposit's height
/// (the top layers are still filling).
pub const DENSITY_FIT_TO: f64 = 0.25;

/// One block of `deposit_growth.csv`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Block {
    /// Particles at the block's end.
    pub n: u64,
    /// The deposit's height at the block's end.
    pub height: f64,
    /// Mean sticking height of the block's particles.
    pub mean_height: f64,
    /// Standard deviation of their sticking heights.
    pub active_zone_width: f64,
    /// Trees that received a particle in the block.
    pub growing_trees: u64,
}

/// The analysis of a deposit (see the module documentation).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Deposit {
    /// Space dimension.
    pub dim: usize,
    /// Substrate width.
    pub width: f64,
    /// Particles per layer of one diameter, from the substrate up.
    pub layers: Vec<u64>,
    /// The tree of every particle (an index into `tops`).
    tree_of: Vec<u32>,
    /// Each tree's highest centre.
    tops: Vec<f64>,
    /// Each tree's particles.
    masses: Vec<u64>,
    /// The last block each tree grew in (`u64::MAX`: none yet).
    grew_in: Vec<u64>,
    /// Finished blocks.
    pub blocks: Vec<Block>,
    block_size: u64,
    /// The current block's sums: count, heights, squared heights, trees grown.
    block: (u64, f64, f64, u64),
    /// Particles analysed.
    pub particles: u64,
    /// Largest centre height.
    pub height: f64,
}

/// Why the particles cannot be analysed as a deposit.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DepositError {
    /// A particle whose parent is not an earlier particle or -1.
    #[error("particle {index} names parent {parent}: not an earlier particle or -1")]
    Parent {
        /// The particle.
        index: u64,
        /// What it names.
        parent: i64,
    },
    /// More trees than 32-bit indices.
    #[error("more than 2^32 - 1 trees")]
    TooManyTrees,
}

impl Deposit {
    /// An empty analysis of a deposit in `dim` dimensions on a substrate of width `width`.
    pub fn new(dim: usize, width: f64) -> Self {
        let area = width.powi(dim as i32 - 1);
        Deposit {
            dim,
            width,
            block_size: (area.ceil() as u64).max(1),
            ..Deposit::default()
        }
    }

    /// Adds the next particle in arrival order: its position `p` (height last) and parent
    /// (`-1`: it starts a tree, on the substrate or a seed of a seed set).
    ///
    /// # Errors
    /// A parent that is not an earlier particle.
    pub fn push(&mut self, p: &[f64], parent: i64) -> Result<(), DepositError> {
        let index = self.particles;
        let z = p[p.len() - 1];
        let tree = if parent < 0 {
            let t = u32::try_from(self.tops.len()).map_err(|_| DepositError::TooManyTrees)?;
            self.tops.push(z);
            self.masses.push(0);
            self.grew_in.push(u64::MAX);
            t
        } else {
            match self.tree_of.get(parent as usize) {
                Some(&t) if (parent as u64) < index => t,
                _ => return Err(DepositError::Parent { index, parent }),
            }
        };
        self.tree_of.push(tree);
        let t = tree as usize;
        self.tops[t] = self.tops[t].max(z);
        self.masses[t] += 1;
        self.height = self.height.max(z);
        let layer = z.max(0.0).floor() as usize;
        if self.layers.len() <= layer {
            self.layers.resize(layer + 1, 0);
        }
        self.layers[layer] += 1;
        let block = index / self.block_size;
        if self.grew_in[t] != block {
            self.grew_in[t] = block;
            self.block.3 += 1;
        }
        self.block.0 += 1;
        self.block.1 += z;
        self.block.2 += z * z;
        self.particles += 1;
        if self.particles % self.block_size == 0 {
            self.close_block();
        }
        Ok(())
    }

    /// Ends the analysis: the last, partial block is closed, and the per-particle memory
    /// freed.
    pub fn finish(&mut self) {
        if self.block.0 > 0 {
            self.close_block();
        }
        self.tree_of = Vec::new();
        self.grew_in = Vec::new();
    }

    fn close_block(&mut self) {
        let (k, s, s2, grown) = self.block;
        let kf = k as f64;
        let mean = s / kf;
        let var = (s2 / kf - mean * mean).max(0.0);
        self.blocks.push(Block {
            n: self.particles,
            height: self.height,
            mean_height: mean,
            active_zone_width: var.sqrt(),
            growing_trees: grown,
        });
        self.block = (0, 0.0, 0.0, 0);
    }

    /// Trees (particles without a parent: on the substrate, or seeds).
    pub fn trees(&self) -> u64 {
        self.tops.len() as u64
    }

    /// Particles per unit volume in layer `k` (heights `[k, k + 1)`).
    pub fn density(&self, k: usize) -> f64 {
        self.layers[k] as f64 / self.width.powi(self.dim as i32 - 1)
    }

    /// The trees reaching each layer (a tree reaches layer `k` if its highest centre is at
    /// least `k`).
    pub fn surviving_trees(&self) -> Vec<u64> {
        let mut tops: Vec<f64> = self.tops.clone();
        tops.sort_by(f64::total_cmp);
        (0..self.layers.len())
            .map(|k| {
                let below = tops.partition_point(|&t| t < k as f64);
                (tops.len() - below) as u64
            })
            .collect()
    }

    /// The layers of the density fit: from [`DENSITY_FIT_FROM`] up to [`DENSITY_FIT_TO`] of
    /// the width and of the height; `None` when that range spans less than a factor 4.
    pub fn fit_layers(&self) -> Option<std::ops::Range<usize>> {
        let lo = DENSITY_FIT_FROM as usize;
        let hi = (DENSITY_FIT_TO * self.width.min(self.height)).floor() as usize;
        (hi >= 4 * lo && hi <= self.layers.len()).then_some(lo..hi)
    }

    /// The fractal dimension of the trees from the density profile, `D = d + s` with `s` the
    /// slope of `ln density` against `ln height` (layer midpoints) over
    /// [`fit_layers`](Self::fit_layers), and its standard error; `None` when the deposit is
    /// too low for the fit, or a fitted layer is empty.
    pub fn density_dimension(&self) -> Option<(f64, f64)> {
        let range = self.fit_layers()?;
        let (h, rho): (Vec<f64>, Vec<f64>) = range
            .map(|k| (k as f64 + 0.5, self.density(k)))
            .filter(|&(_, r)| r > 0.0)
            .unzip();
        let fit = core_lattice::Fit::log_log(&h, &rho).ok()?;
        Some((self.dim as f64 + fit.slope, fit.slope_stderr))
    }

    /// The exponent `x` of the trees' mass against their height, `M ~ H^x`, across the trees
    /// whose height (the highest centre plus one diameter) lies from [`DENSITY_FIT_FROM`] to
    /// a quarter of the width (taller trees feel the strip's period): the slope of ln mass
    /// against ln height, and its standard error; `None` with fewer than 10 such trees. It is
    /// not the trees' fractal dimension: a tree stops growing when its neighbours screen it,
    /// while it is thinner than the ones that go on, so the short trees are not small copies
    /// of the tall ones (in 2D diffusion-limited deposition `x` is about 1.5 where `D` is
    /// 1.71; see `docs/results/deposit.md`).
    pub fn tree_mass_exponent(&self) -> Option<(f64, f64)> {
        let (h, m): (Vec<f64>, Vec<f64>) = self
            .tops
            .iter()
            .zip(&self.masses)
            .map(|(&t, &m)| (t + 1.0, m as f64))
            .filter(|&(h, _)| h >= DENSITY_FIT_FROM && h <= DENSITY_FIT_TO * self.width)
            .unzip();
        if h.len() < 10 {
            return None;
        }
        let fit = core_lattice::Fit::log_log(&h, &m).ok()?;
        Some((fit.slope, fit.slope_stderr))
    }

    /// The last block's active-zone width (the standard deviation of the heights at which
    /// the last `W^(d-1)` particles stuck).
    pub fn active_zone_width(&self) -> Option<f64> {
        self.blocks.last().map(|b| b.active_zone_width)
    }
}

/// Writes `deposit.csv` and `deposit_growth.csv` into `dir`.
#[cfg(feature = "files")]
pub fn write_csv(d: &Deposit, dir: &std::path::Path) -> Result<(), run_io::OutputError> {
    let names: Vec<&str> = DEPOSIT.columns.iter().map(|c| c.name).collect();
    let mut w = run_io::CsvWriter::create(dir.join(DEPOSIT.file), &names)?;
    for (k, trees) in d.surviving_trees().into_iter().enumerate() {
        w.row(&[&(k as f64), &d.layers[k], &d.density(k), &trees])?;
    }
    w.finish()?;
    let names: Vec<&str> = DEPOSIT_GROWTH.columns.iter().map(|c| c.name).collect();
    let mut w = run_io::CsvWriter::create(dir.join(DEPOSIT_GROWTH.file), &names)?;
    for b in &d.blocks {
        w.row(&[
            &b.n,
            &b.height,
            &b.mean_height,
            &b.active_zone_width,
            &b.growing_trees,
        ])?;
    }
    w.finish()?;
    Ok(())
}

/// The deposit's results in `run.json`.
#[cfg(feature = "files")]
pub fn set_results(m: &mut run_io::RunManifest, d: &Deposit) {
    let fit = d.density_dimension();
    let trees = d.tree_mass_exponent();
    let range = d
        .fit_layers()
        .map(|r| serde_json::json!([r.start as f64, r.end as f64]));
    m.set_result("deposit_height", d.height)
        .set_result("deposit_trees", d.trees())
        .set_result(
            "deposit_growing_trees",
            d.blocks.last().map(|b| b.growing_trees),
        )
        .set_result("density_dimension", fit.map(|f| f.0))
        .set_result("density_dimension_stderr", fit.map(|f| f.1))
        .set_result("density_fit_heights", range)
        .set_result("tree_mass_exponent", trees.map(|f| f.0))
        .set_result("tree_mass_exponent_stderr", trees.map(|f| f.1))
        .set_result("active_zone_width", d.active_zone_width());
}

/// `deposit.png`: the density profile and the surviving trees against the height, log-log,
/// with the fitted power law (feature `figures`).
#[cfg(feature = "figures")]
pub fn write_png(
    d: &Deposit,
    seed: u64,
    path: &std::path::Path,
) -> Result<(), run_io::OutputError> {
    use figures::chart::{Chart, Series, Style};
    let mid = |k: usize| k as f64 + 0.5;
    let density: Vec<(f64, f64)> = (0..d.layers.len())
        .filter(|&k| d.layers[k] > 0)
        .map(|k| (mid(k), d.density(k)))
        .collect();
    let trees: Vec<(f64, f64)> = d
        .surviving_trees()
        .into_iter()
        .enumerate()
        .filter(|&(_, t)| t > 0)
        .map(|(k, t)| (mid(k), t as f64 / d.trees().max(1) as f64))
        .collect();
    let mut series = vec![
        Series::new("density (particles per unit volume)", density, Style::Line),
        Series::new(
            "surviving trees / trees on the substrate",
            trees,
            Style::Line,
        ),
    ];
    if let (Some(range), Some((dim, _))) = (d.fit_layers(), d.density_dimension()) {
        let (a, b) = (mid(range.start), mid(range.end - 1));
        // The fitted line through the geometric mean of the fitted densities.
        let ks: Vec<usize> = range.filter(|&k| d.layers[k] > 0).collect();
        let m = ks.len() as f64;
        let lx = ks.iter().map(|&k| mid(k).ln()).sum::<f64>() / m;
        let ly = ks.iter().map(|&k| d.density(k).ln()).sum::<f64>() / m;
        let s = dim - d.dim as f64;
        let at = |h: f64| (h, (ly + s * (h.ln() - lx)).exp());
        series.push(Series::new(
            format!("fit: h^(D - {}), D = {dim:.3}", d.dim),
            vec![at(a), at(b)],
            Style::Line,
        ));
    }
    let chart = Chart::log_log(
        format!(
            "Deposit, {}D, width {}, {} particles, seed {seed}",
            d.dim,
            d.width,
            figures::group_digits(d.particles)
        ),
        "height h (diameters)",
        "density; surviving trees (fraction)",
        series,
    );
    figures::chart::write_chart(&chart, path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_hand_made_deposit() {
        // Width 2 in 2D: blocks of 2 particles. Two trees: 0 (x 0) and 1 (x 1); 2 and 3 on
        // tree 0 at heights 0.9 and 1.8; 4 on tree 1 at 0.95.
        let mut d = Deposit::new(2, 2.0);
        for (p, parent) in [
            ([0.0, 0.0], -1),
            ([1.0, 0.0], -1),
            ([0.4, 0.9], 0),
            ([0.6, 1.8], 2),
            ([1.3, 0.95], 1),
        ] {
            d.push(&p, parent).unwrap();
        }
        d.finish();
        assert_eq!(d.trees(), 2);
        assert_eq!(d.layers, vec![4, 1]);
        assert_eq!(d.surviving_trees(), vec![2, 1]);
        assert_eq!(d.density(0), 2.0);
        assert_eq!(d.blocks.len(), 3);
        assert_eq!(d.blocks[0].growing_trees, 2);
        assert_eq!(d.blocks[1].growing_trees, 1);
        assert!((d.blocks[1].mean_height - 1.35).abs() < 1e-12);
        assert!((d.blocks[1].active_zone_width - 0.45).abs() < 1e-12);
        assert_eq!(d.blocks[2].n, 5);
        assert_eq!(d.height, 1.8);
        assert!(d.density_dimension().is_none());
        let mut bad = Deposit::new(2, 2.0);
        bad.push(&[0.0, 0.0], -1).unwrap();
        assert!(matches!(
            bad.push(&[0.0, 1.0], 1),
            Err(DepositError::Parent {
                index: 1,
                parent: 1
            })
        ));
    }

    /// A profile falling exactly as h^(-0.3) gives D = d - 0.3.
    #[test]
    fn the_density_fit_reads_the_power_law() {
        let mut d = Deposit::new(2, 400.0);
        d.height = 399.0;
        d.layers = (0..400)
            .map(|k| (1e6 * (k as f64 + 0.5).powf(-0.3)).round() as u64)
            .collect();
        let (dim, err) = d.density_dimension().unwrap();
        assert!((dim - 1.7).abs() < 1e-3, "{dim}");
        assert!(err < 1e-3);
        assert_eq!(d.fit_layers(), Some(8..99));
    }
}
