//! The cluster as a tree: Horton-Strahler orders of its branches from each particle's parent
//! (the particle it stuck to), after Horton (1945) and Strahler (1957), as Ossadnik applied
//! them to DLA ("Branch order and ramification analysis of large diffusion-limited-aggregation
//! clusters", 1992).
//!
//! - A particle no other particle stuck to (a tip) has order 1.
//! - A particle whose children's highest order `k` is held by one child has order `k`; by two
//!   or more, order `k + 1`.
//! - A *branch* of order `k` is a maximal chain of particles of order `k`, each the parent of
//!   the next: it starts at a tip (`k = 1`) or where two branches of order `k - 1` meet, and
//!   goes down to the particle where it joins a branch of higher order (or to a seed).
//!
//! `N_k` counts the branches of order `k` and `L_k` is their mean length in particles (the
//! particles of order `k` over `N_k`; with every particle a diameter from its parent, also
//! their length in diameters, `noise_reduction` times that with noise reduction). The
//! bifurcation ratio `R_B = N_k / N_{k+1}` and the length ratio `R_L = L_{k+1} / L_k` are near
//! constant over the orders a cluster holds many branches of (Horton's laws), and
//! [`Branches::bifurcation_ratio`] fits them there.
//!
//! Parents come before their children in arrival order, so one pass from the last particle to
//! the first sees every particle's children before the particle itself: 2 bytes a particle
//! beside the parents.

use serde::Serialize;

/// Branches of one Horton-Strahler order.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Order {
    /// The order `k` (1 for the tips' branches).
    pub order: u32,
    /// `N_k`: branches of this order.
    pub branches: u64,
    /// Particles of this order.
    pub particles: u64,
}

impl Order {
    /// `L_k`: the mean length of a branch of this order, in particles.
    pub fn mean_length(&self) -> f64 {
        self.particles as f64 / self.branches as f64
    }
}

/// The Horton-Strahler analysis of a forest of particles (one tree per seed).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Branches {
    /// Particles analysed.
    pub particles: u64,
    /// Trees (particles without a parent: the seeds).
    pub trees: u64,
    /// Every order from 1 to the highest, in order.
    pub orders: Vec<Order>,
}

/// Why parents do not form a forest in arrival order.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("particle {index} names parent {parent}: not an earlier particle or -1")]
pub struct NotAForest {
    /// The particle.
    pub index: u64,
    /// What it names.
    pub parent: i64,
}

/// The fewest branches an order must hold to enter the fitted ratios: the counting noise of
/// a ratio `N_k / N_(k+1)` is then about `1 / sqrt(50)`, 14 %, at most. The highest orders of
/// a finite cluster hold a handful of branches (one of the highest), shaped by the cluster's
/// outline rather than by branching, and fall short of it.
pub const FIT_MIN_BRANCHES: u64 = 50;

impl Branches {
    /// Analyses `parents` (`parents[i]`: the index of the particle particle `i` stuck to, `-1`
    /// for a seed).
    ///
    /// # Errors
    /// A parent that is not an earlier particle or `-1`.
    pub fn from_parents(parents: &[i64]) -> Result<Self, NotAForest> {
        let n = parents.len() as u64;
        let values = parents
            .iter()
            .rev()
            .map(|&p| Ok::<i64, std::convert::Infallible>(p));
        Self::from_last(n, values).map_err(|e| match e {
            Ok(e) => e,
            Err(never) => match never {},
        })
    }

    /// Analyses the parents of `positions_parent.npy` at `path` (as `dla` writes it, `n`
    /// rows), read from the last to the first in blocks: 1 byte a particle beside the file.
    ///
    /// # Errors
    /// The file does not read or is not `n` parents forming a forest.
    #[cfg(feature = "files")]
    pub fn from_npy(path: &std::path::Path, n: u64) -> Result<Self, String> {
        use std::io::{Read, Seek, SeekFrom};
        let what = |e: &dyn std::fmt::Display| format!("{}: {e}", path.display());
        let header = run_io::NpyReader::open_ints(path).map_err(|e| what(&e))?;
        if header.rows() != n {
            return Err(what(&format!("{} parents, not {n}", header.rows())));
        }
        let mut file = std::fs::File::open(path).map_err(|e| what(&e))?;
        const BLOCK: u64 = 1 << 16;
        let mut end = n;
        let mut block: Vec<i64> = Vec::new();
        let mut buf = vec![0u8; (BLOCK * 8) as usize];
        let mut failed = None;
        let values = std::iter::from_fn(|| {
            if block.is_empty() {
                if end == 0 || failed.is_some() {
                    return None;
                }
                let start = end.saturating_sub(BLOCK);
                let bytes = &mut buf[..((end - start) * 8) as usize];
                let read = file
                    .seek(SeekFrom::Start(run_io::npy::HEADER_BYTES + start * 8))
                    .and_then(|_| file.read_exact(bytes));
                if let Err(e) = read {
                    failed = Some(what(&e));
                    return None;
                }
                block.extend(
                    bytes
                        .chunks_exact(8)
                        .map(|c| i64::from_le_bytes(c.try_into().expect("8 bytes"))),
                );
                end = start;
            }
            block.pop().map(Ok::<i64, String>)
        });
        let b =
            Self::from_last(n, values).map_err(|e| e.map_or_else(|io| io, |e| e.to_string()))?;
        match failed {
            Some(e) => Err(e),
            None => Ok(b),
        }
    }

    /// The analysis of `n` particles from their parents given last first.
    fn from_last<E>(
        n: u64,
        parents: impl Iterator<Item = Result<i64, E>>,
    ) -> Result<Self, Result<NotAForest, E>> {
        // Per particle: the highest order among its children so far, and whether two or more
        // children hold it (bit 7). Orders stay far below 128: each order needs at least twice
        // the particles of the one below.
        let mut top = vec![0u8; usize::try_from(n).unwrap_or(usize::MAX)];
        const TWICE: u8 = 0x80;
        let mut orders: Vec<Order> = Vec::new();
        let mut trees = 0u64;
        let mut seen = 0u64;
        for (i, parent) in (0..n).rev().zip(parents) {
            let parent = parent.map_err(Err)?;
            seen += 1;
            let t = top[i as usize];
            let (order, head) = match (t & !TWICE, t & TWICE != 0) {
                (0, _) => (1u8, true),
                (k, true) => (k + 1, true),
                (k, false) => (k, false),
            };
            let k = usize::from(order);
            if orders.len() < k {
                orders.extend((orders.len() as u32 + 1..=k as u32).map(|order| Order {
                    order,
                    branches: 0,
                    particles: 0,
                }));
            }
            orders[k - 1].particles += 1;
            orders[k - 1].branches += u64::from(head);
            match parent {
                -1 => trees += 1,
                p if p >= 0 && (p as u64) < i => {
                    let slot = &mut top[p as usize];
                    let have = *slot & !TWICE;
                    if order > have {
                        *slot = order;
                    } else if order == have {
                        *slot |= TWICE;
                    }
                }
                p => {
                    return Err(Ok(NotAForest {
                        index: i,
                        parent: p,
                    }));
                }
            }
        }
        debug_assert!(seen <= n);
        Ok(Branches {
            particles: seen,
            trees,
            orders,
        })
    }

    /// `N_k / N_(k+1)` and `L_(k+1) / L_k` of each order, `None` at the highest.
    pub fn ratios(&self) -> Vec<(Option<f64>, Option<f64>)> {
        (0..self.orders.len())
            .map(|k| match (self.orders[k], self.orders.get(k + 1)) {
                (o, Some(n)) => (
                    Some(o.branches as f64 / n.branches as f64),
                    Some(n.mean_length() / o.mean_length()),
                ),
                _ => (None, None),
            })
            .collect()
    }

    /// The highest order (0 for no particle).
    pub fn max_order(&self) -> u32 {
        self.orders.len() as u32
    }

    /// The orders the ratios are fitted over: from 1 to the highest holding at least
    /// [`FIT_MIN_BRANCHES`] branches, when that spans at least three orders.
    pub fn fit_orders(&self) -> Option<std::ops::RangeInclusive<u32>> {
        let hi = self
            .orders
            .iter()
            .take_while(|o| o.branches >= FIT_MIN_BRANCHES)
            .count() as u32;
        (hi >= 3).then_some(1..=hi)
    }

    /// `R_B`: `exp(-slope)` of the least-squares line through `(k, ln N_k)` over
    /// [`fit_orders`](Self::fit_orders); `None` when they are too few.
    pub fn bifurcation_ratio(&self) -> Option<f64> {
        self.fit(|o| o.branches as f64).map(|slope| (-slope).exp())
    }

    /// `R_L`: `exp(slope)` of the line through `(k, ln L_k)` over the same orders.
    pub fn length_ratio(&self) -> Option<f64> {
        self.fit(Order::mean_length).map(f64::exp)
    }

    fn fit(&self, y: impl Fn(&Order) -> f64) -> Option<f64> {
        let range = self.fit_orders()?;
        let pts: Vec<(f64, f64)> = self
            .orders
            .iter()
            .filter(|o| range.contains(&o.order))
            .map(|o| (f64::from(o.order), y(o).ln()))
            .collect();
        let m = pts.len() as f64;
        let (sx, sy) = pts.iter().fold((0.0, 0.0), |(a, b), (x, y)| (a + x, b + y));
        let (mx, my) = (sx / m, sy / m);
        let sxx: f64 = pts.iter().map(|(x, _)| (x - mx) * (x - mx)).sum();
        let sxy: f64 = pts.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
        Some(sxy / sxx)
    }
}

/// `branches.csv` in the schema: a row per Horton-Strahler order.
pub const BRANCHES: run_io::schema::Output = run_io::schema::Output {
    file: "branches.csv",
    form: run_io::schema::Form::Csv,
    python: "branches",
    // Whenever the parents are recorded: a run that streams its positions (the default, for
    // its checkpoints, or `--positions`).
    when: None,
    columns: &[
        run_io::schema::Column::new(
            "order",
            run_io::schema::Dtype::Uint64,
            "Horton-Strahler order k",
        ),
        run_io::schema::Column::new(
            "branches",
            run_io::schema::Dtype::Uint64,
            "N_k, branches of order k",
        ),
        run_io::schema::Column::new(
            "particles",
            run_io::schema::Dtype::Uint64,
            "particles of order k",
        ),
        run_io::schema::Column::new(
            "mean_length",
            run_io::schema::Dtype::Float64,
            "L_k, particles per branch",
        ),
        run_io::schema::Column::new(
            "bifurcation_ratio",
            run_io::schema::Dtype::Float64,
            "N_k / N_(k+1) (empty at the highest order)",
        ),
        run_io::schema::Column::new(
            "length_ratio",
            run_io::schema::Dtype::Float64,
            "L_(k+1) / L_k (empty at the highest order)",
        ),
    ],
};

/// Writes `branches.csv` (see [`BRANCHES`]) into `dir`.
#[cfg(feature = "files")]
pub fn write_csv(b: &Branches, dir: &std::path::Path) -> Result<(), run_io::OutputError> {
    let names: Vec<&str> = BRANCHES.columns.iter().map(|c| c.name).collect();
    let mut w = run_io::CsvWriter::create(dir.join(BRANCHES.file), &names)?;
    for (o, (rb, rl)) in b.orders.iter().zip(b.ratios()) {
        let text = |v: Option<f64>| v.map_or(String::new(), |v| v.to_string());
        w.row(&[
            &o.order,
            &o.branches,
            &o.particles,
            &o.mean_length(),
            &text(rb),
            &text(rl),
        ])?;
    }
    w.finish()?;
    Ok(())
}

/// `branches.png`: `N_k` and `L_k` against the order `k` on a log axis, with the fitted
/// Horton lines over [`Branches::fit_orders`] (feature `figures`).
#[cfg(feature = "figures")]
pub fn write_png(
    b: &Branches,
    particles: u64,
    seed: u64,
    path: &std::path::Path,
) -> Result<(), run_io::OutputError> {
    use figures::chart::{Chart, Series, Style};
    let pts = |y: &dyn Fn(&Order) -> f64| -> Vec<(f64, f64)> {
        b.orders
            .iter()
            .map(|o| (f64::from(o.order), y(o)))
            .collect()
    };
    let mut series = vec![
        Series::new(
            "N_k, branches of order k",
            pts(&|o| o.branches as f64),
            Style::Points,
        ),
        Series::new(
            "L_k, mean length (particles)",
            pts(&|o| o.mean_length()),
            Style::Points,
        ),
    ];
    // The fitted lines through the fitted orders, anchored at their geometric mean.
    if let (Some(range), Some(rb), Some(rl)) =
        (b.fit_orders(), b.bifurcation_ratio(), b.length_ratio())
    {
        let mid: Vec<&Order> = b
            .orders
            .iter()
            .filter(|o| range.contains(&o.order))
            .collect();
        let m = mid.len() as f64;
        let kx = mid.iter().map(|o| f64::from(o.order)).sum::<f64>() / m;
        let line = |ratio: f64, y: &dyn Fn(&Order) -> f64| -> Vec<(f64, f64)> {
            let ly = mid.iter().map(|o| y(o).ln()).sum::<f64>() / m;
            [*range.start(), *range.end()]
                .iter()
                .map(|&k| (f64::from(k), (ly + (f64::from(k) - kx) * ratio.ln()).exp()))
                .collect()
        };
        series.push(Series::new(
            format!("fit: R_B = {rb:.2}"),
            line(1.0 / rb, &|o| o.branches as f64),
            Style::Line,
        ));
        series.push(Series::new(
            format!("fit: R_L = {rl:.2}"),
            line(rl, &|o| o.mean_length()),
            Style::Line,
        ));
    }
    let chart = Chart {
        title: format!(
            "Horton-Strahler branches, {} particles, seed {seed}",
            figures::group_digits(particles)
        ),
        x_label: "order k".into(),
        y_label: "N_k and L_k".into(),
        log_x: false,
        log_y: true,
        series,
    };
    figures::chart::write_chart(&chart, path)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Orders by hand: a seed with two chains of two (a Y), then a third chain on one of them.
    #[test]
    fn orders_of_small_trees() {
        // 0 is the seed; 1-2 and 3-4 are two chains from it: both order 1, the seed order 2.
        let b = Branches::from_parents(&[-1, 0, 1, 0, 3]).unwrap();
        assert_eq!(b.trees, 1);
        assert_eq!(
            b.orders,
            vec![
                Order {
                    order: 1,
                    branches: 2,
                    particles: 4
                },
                Order {
                    order: 2,
                    branches: 1,
                    particles: 1
                },
            ]
        );
        // A chain is one branch of order 1, whatever its length.
        let b = Branches::from_parents(&[-1, 0, 1, 2, 3]).unwrap();
        assert_eq!(b.orders.len(), 1);
        assert_eq!((b.orders[0].branches, b.orders[0].particles), (1, 5));
        // A side twig of order 1 on an order-2 branch leaves it order 2: 0-1-2 with 2 forked
        // into 3 and 4 (order 2 from 2 down to 0), and 5 stuck to 1.
        let b = Branches::from_parents(&[-1, 0, 1, 2, 2, 1]).unwrap();
        assert_eq!(b.orders[1].branches, 1);
        assert_eq!(b.orders[1].particles, 3);
        assert_eq!(b.orders[0].branches, 3);
        // Two seeds, two trees.
        let b = Branches::from_parents(&[-1, -1, 0, 1]).unwrap();
        assert_eq!(b.trees, 2);
        assert!(Branches::from_parents(&[-1, 2, 0]).is_err());
        assert!(Branches::from_parents(&[-1, -2]).is_err());
    }

    /// A complete binary tree of depth `d` has `2^(d-k)` branches of order `k`: the
    /// bifurcation ratio is exactly 2 and every branch is one particle long.
    #[test]
    fn complete_binary_tree_has_ratio_two() {
        let depth = 10;
        let n = (1usize << (depth + 1)) - 1;
        let parents: Vec<i64> = (0..n)
            .map(|i| if i == 0 { -1 } else { ((i - 1) / 2) as i64 })
            .collect();
        let b = Branches::from_parents(&parents).unwrap();
        assert_eq!(b.max_order(), depth + 1);
        for o in &b.orders {
            assert_eq!(o.branches, 1 << (depth + 1 - o.order));
            assert_eq!(o.mean_length(), 1.0);
        }
        assert!((b.bifurcation_ratio().unwrap() - 2.0).abs() < 1e-12);
        assert!((b.length_ratio().unwrap() - 1.0).abs() < 1e-12);
    }
}
