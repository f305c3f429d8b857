//! The charts of `cargo xtask`: the plotting module of `core_lattice` (feature `plot`), which
//! the models' ensembles use too.

pub use core_lattice::plot::*;
