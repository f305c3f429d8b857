//! Serial DLA: one walker at a time, each released on the birth sphere and walked until it
//! sticks, on one random stream (`stream_id(PURPOSE_WALK, 0)`), then stored at its contact
//! point (or, with noise reduction `f < 1`, at distance `f` from the particle it touched).
//!
//! Invariant: a serial run is a pure function of `(Params, seed)`: the walker's moves depend
//! only on the stream and the stored particles, and nothing else draws from the stream.

use super::growth::{Growth, noise_reduced};
use crate::cluster::Cluster;
use crate::error::SimError;
use crate::params::Params;
use crate::space::{Dim, Space};
use crate::walker::{WalkState, Walker};
use core_lattice::rng::{SimRng, stream, stream_id};

/// Stream purpose of the serial walker (`stream_id(PURPOSE_WALK, 0)`).
pub const PURPOSE_WALK: u32 = 1;

/// The serial walker's random stream and memory.
#[derive(Debug)]
pub(crate) struct Serial<const D: usize> {
    /// The walk's random stream (saved in checkpoints).
    pub(crate) rng: SimRng,
    /// The current walker's memory (reset for each walker).
    pub(crate) walk: WalkState<D>,
}

impl<const D: usize> Serial<D> {
    /// The serial walk of run `seed`, from its first walker.
    pub(crate) fn new(params: &Params, seed: u64) -> Self {
        Serial::with_rng(params, stream(seed, stream_id(PURPOSE_WALK, 0)))
    }

    /// The serial walk continuing on `rng` (a resumed checkpoint).
    pub(crate) fn with_rng(params: &Params, rng: SimRng) -> Self {
        Serial {
            rng,
            walk: WalkState::new(params),
        }
    }

    /// Releases one walker and grows `cluster` by the particle it becomes; returns its stored
    /// position.
    pub(crate) fn add_one(
        &mut self,
        params: &Params,
        cluster: &mut Cluster<D>,
        growth: &mut Growth<D>,
    ) -> Result<[f64; D], SimError>
    where
        Dim<D>: Space<D>,
    {
        self.walk.reset();
        let r_b = growth.r_ext + params.birth_gap;
        // Each branch launches its own walker, so that the plain walk's position is never
        // written through a pointer the variant walk shares and stays in registers (see
        // `walker::detached`).
        if self.walk.variant() {
            let w = Walker::launch(r_b, &mut self.walk, &mut self.rng);
            self.walk_one::<true>(w, params, cluster, growth)
        } else {
            let w = Walker::launch(r_b, &mut self.walk, &mut self.rng);
            self.walk_one::<false>(w, params, cluster, growth)
        }
    }

    /// Walks `w` until it sticks and grows `cluster` by it ([`Walker::advance`]'s `VARIANT`).
    fn walk_one<const VARIANT: bool>(
        &mut self,
        mut w: Walker<D>,
        params: &Params,
        cluster: &mut Cluster<D>,
        growth: &mut Growth<D>,
    ) -> Result<[f64; D], SimError>
    where
        Dim<D>: Space<D>,
    {
        loop {
            if let Some(p) = w.advance::<VARIANT, _>(
                &mut self.walk,
                cluster,
                growth.r_ext,
                params,
                &mut self.rng,
            ) {
                let p = if self.walk.refuse {
                    match w.settle_detached(p, &mut self.walk, cluster, params, &mut self.rng) {
                        Some(p) => p,
                        None => continue,
                    }
                } else {
                    p
                };
                let touched = self.walk.touched();
                let p = noise_reduced(p, touched, params.noise_reduction);
                return growth.add(cluster, p, touched, params.particles);
            }
        }
    }
}
