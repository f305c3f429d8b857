//! Search structures for the aggregation and animat models, each usable on its own and tested
//! against a brute-force reference.
//!
//! The models' hot paths:
//!
//! - [`orthtree`]: quadtree (D = 2), octree (D = 3), 2^D children in general, with an exact
//!   nearest-distance query and the variable-precision distance search `vpdist` of
//!   Sosa-Herrera & Rodriguez-Romo (section 3.1, Listing 1). DLA and PDLA.
//! - [`distmap`]: a coarse distance map (Ball & Brady) in front of the orthtree: one byte per
//!   cell bounding the distance to a growing point set, so DLA walkers far from the cluster
//!   jump without a tree query.
//! - [`lattice::halo`]: rigid lattice shapes listed in small grid boxes by their halos, with a
//!   box side tuned as the shapes grow; exact face-contact search. DLCA's default `grid`
//!   strategy.
//! - [`cells`]: a dense per-cell index over the unbounded integer plane in tiles, with window
//!   and row-word reads of a neighbourhood ([`cells::near`]) and grid-box ring queries over it
//!   ([`cells::wide`]). The animat model's default search.
//!
//! The grid-boxing paper's own structures (Hawick, James & Scogings 2006, "Grid-Boxing for
//! Spatial Simulation Performance Optimisation"), kept as its **baseline settings** for
//! reproducing its measurements:
//!
//! - [`lattice`]: contact search for items made of lattice sites (the DLCA clusters, sections
//!   II.A, III, IV.A): the all-pairs baseline, the paper's grid boxes over a periodic or walled
//!   lattice (`LatticeGridBoxes`, DLCA's `grid-doubling`), and an occupancy lattice, all exact
//!   and interchangeable.
//! - [`plane`]: the paper's grid boxes hashed over the unbounded integer plane (`PlaneGrid`),
//!   for the animat model (sections II.B and IV.B): the animats' path with the cell search off
//!   (`World::set_cell_search`, the grid-box study) and with `--grid-box none`.
//!
//! ```
//! use spatial::orthtree::Orthtree;
//!
//! // A quadtree of unit-diameter particles, as DLA stores its cluster.
//! let mut tree = Orthtree::<2>::new();
//! for p in [[0.0, 0.0], [1.0, 0.0], [1.5, 0.8660254]] {
//!     tree.insert(p).unwrap();
//! }
//! let walker = [30.0, 40.0];
//! let exact = tree.nearest_distance(&walker).unwrap();
//! // vpdist with the paper's precision kappa = 2: never above the exact distance, so a walker
//! // may jump that far without touching the cluster, and cheaper to compute far away.
//! let bound = tree.vpdist(&walker, 2.0).unwrap();
//! assert!(bound <= exact && bound > 0.5 * exact);
//! ```

pub mod cells;
pub mod distmap;
pub mod lattice;
pub mod orthtree;
pub mod plane;
mod round;
pub mod testdata;

/// The README's examples, compiled and run as doctests so that they stay true.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
