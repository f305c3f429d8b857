//! The charts of `cargo xtask`: the plotting module of `sim_run` (feature `plot`), which
//! the models' ensembles use too.

pub use sim_run::plot::*;
