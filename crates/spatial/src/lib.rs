//! Search structures for the aggregation and animat models.
//!
//! - [`orthtree`]: quadtree (D = 2), octree (D = 3), 2^D children in general, with an exact
//!   nearest-distance query and the variable-precision distance search `vpdist` of
//!   Sosa-Herrera & Rodriguez-Romo (seed 002, section 3.1, Listing 1).
//! - [`plane`]: grid boxes hashed over the unbounded integer plane, for the animat model of
//!   Hawick, James & Scogings (seed 000, sections II.B and IV.B).

pub mod orthtree;
pub mod plane;
