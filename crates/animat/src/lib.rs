//! # animat: predator-prey artificial life with rule priorities and grid boxes
//!
//! The foxes-and-rabbits animat model of Hawick, James & Scogings (2006), "Grid-Boxing for
//! Spatial Simulation Performance Optimisation" (section II.B; the scaling study of section
//! IV.B), stated precisely in `docs/animat.md`: animats on the unbounded integer plane, one
//! per cell, each running its species' rule list in priority order and executing the first
//! rule whose condition holds. Perception is lazy: a rule asks only the neighbour queries its
//! condition needs. Neighbour searches go through `spatial`: by default the dense per-cell
//! index [`spatial::cells::CellIndex`] (the hot path), else the paper's grid boxes
//! [`spatial::plane::PlaneGrid`] (the baseline setting); every path and every grid-box size,
//! and the exhaustive "no grid" search, gives a bit-identical trajectory.
//!
//! ```
//! use animat::{Params, World};
//! let params = Params { foxes: 20, rabbits: 200, start_radius: 30, ..Params::default() };
//! let mut world = World::new(params, 42).unwrap();
//! world.run(10);
//! assert_eq!(world.steps(), 10);
//! assert_eq!(world.state_hash().len(), 16);
//! ```

pub mod bench;
#[cfg(feature = "files")]
pub mod checkpoint;
#[cfg(feature = "files")]
pub mod output;
pub mod params;
pub mod world;

pub use params::{FoxRule, GridBox, Params, ParamsError, RabbitRule, Species};
pub use world::{Animat, QueryCounts, Snapshot, StepStats, World, WorldError};

/// The README's examples, compiled and run as doctests so that they stay true.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
