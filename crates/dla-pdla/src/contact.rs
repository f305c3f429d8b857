//! Exact first contact along a straight move (Sosa-Herrera & Rodriguez-Romo, section 3.2,
//! Fig. 6): the smallest time at which a walker stepping from `p` along `u` comes within centre
//! distance 1 of a stored particle, or (a deposit) touches the substrate. The walker
//! ([`crate::walker`]) asks it for every step of `step_min`, from the tree or its near cache.

use spatial::orthtree::Orthtree;

/// The time `t` in `[0, len]` at which a deposit's walker at height `z`, stepping with vertical
/// component `uz`, touches the substrate (its centre at `z = 0`), if it does. At `z <= 0` the
/// walker already touches it: `t = 0`, with `REFUSE` only if the step points into it (as for
/// a particle, see [`contact`]).
#[inline(always)]
pub(crate) fn wall_contact<const REFUSE: bool>(z: f64, uz: f64, len: f64) -> Option<f64> {
    if z <= 0.0 {
        return (!REFUSE || uz < 0.0).then_some(0.0);
    }
    if uz >= 0.0 {
        return None;
    }
    let t = z / -uz;
    (t <= len).then_some(t)
}

/// Smallest `t` in `[0, len]` with `|p + t u - q| = 1` over every stored centre `q` (`u` a unit
/// vector): the first contact along the step (Sosa-Herrera & Rodriguez-Romo, section 3.2, Fig. 6).
/// A centre already at distance <= 1 gives `t = 0`.
pub fn first_contact<const D: usize>(
    tree: &Orthtree<D>,
    p: &[f64; D],
    u: &[f64; D],
    len: f64,
) -> Option<f64> {
    first_contact_with::<D, false>(tree, p, u, len).map(|(t, _)| t)
}

/// [`first_contact`] and the centre touched; with `REFUSE`, a centre at distance <= 1 only if
/// `u` points into it (see [`contact`]).
pub(crate) fn first_contact_with<const D: usize, const REFUSE: bool>(
    tree: &Orthtree<D>,
    p: &[f64; D],
    u: &[f64; D],
    len: f64,
) -> Option<(f64, [f64; D])> {
    let mut best = (f64::INFINITY, [0.0; D]);
    tree.for_each_within(p, len + 1.0, |q| contact::<D, REFUSE>(p, u, &q, &mut best));
    (best.0 <= len).then_some(best)
}

/// Lowers `best` (a time and the centre touched then) to the contact time with centre `q`
/// along `p + t u`, if there is one. A centre at distance <= 1 is touched at `t = 0`; with
/// `REFUSE` (sticking probability below 1) only if the step points into it (`b < 0`), so that
/// a walker left in contact by a refused sticking moves freely away from the particle
/// (`REFUSE = false` compiles to the plain test).
#[inline(always)]
pub(crate) fn contact<const D: usize, const REFUSE: bool>(
    p: &[f64; D],
    u: &[f64; D],
    q: &[f64; D],
    best: &mut (f64, [f64; D]),
) {
    let mut b = 0.0;
    let mut w2 = 0.0;
    for i in 0..D {
        let w = p[i] - q[i];
        b += w * u[i];
        w2 += w * w;
    }
    let c = w2 - 1.0;
    let t = if c <= 0.0 {
        if REFUSE && b >= 0.0 {
            return;
        }
        0.0
    } else {
        let disc = b * b - c;
        if disc < 0.0 || b >= 0.0 {
            return;
        }
        // Stable form of -b - sqrt(disc) (b < 0): c / (-b + sqrt(disc)).
        c / (-b + disc.sqrt())
    };
    if t < best.0 {
        *best = (t, *q);
    }
}
