//! Search structures for the aggregation and animat models.
//!
//! - [`orthtree`]: quadtree (D = 2), octree (D = 3), 2^D children in general, with an exact
//!   nearest-distance query and the variable-precision distance search `vpdist` of
//!   Sosa-Herrera & Rodriguez-Romo (section 3.1, Listing 1).
//! - [`distmap`]: a coarse distance map (Ball & Brady) in front of the orthtree: one byte per
//!   cell bounding the distance to a growing point set, so DLA walkers far from the cluster
//!   jump without a tree query.
//! - [`lattice`]: contact search for items made of lattice sites (the DLCA clusters of Hawick,
//!   James & Scogings 2006, sections II.A, III, IV.A): the all-pairs baseline, grid boxes
//!   over a periodic or walled lattice, and an occupancy lattice, all exact and interchangeable.
//! - [`plane`]: grid boxes hashed over the unbounded integer plane, for the animat model of
//!   Hawick, James & Scogings (2006, sections II.B and IV.B).

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
