//! The two model parameters beyond plain DLA, `sticking_probability` and `noise_reduction`:
//! at their defaults the run is the plain model bit for bit; below 1 the clusters keep their
//! geometric invariants (brute force over the stored positions), serially and in PDLA, and a
//! checkpointed run resumes to the uninterrupted one.

use dla_pdla::sim::OVERLAP_DISTANCE;
mod common;

use common::{grow, tolerance};
use dla_pdla::{Dim, Params, Simulation, Space};

/// Brute force over the stored positions: for every particle after the seed, the distance to
/// the nearest earlier one, as (smallest, largest) over the particles.
fn nearest_earlier<const D: usize>(pos: &[[f64; D]]) -> (f64, f64) {
    let mut lo = f64::INFINITY;
    let mut hi: f64 = 0.0;
    for i in 1..pos.len() {
        let d2 = pos[..i]
            .iter()
            .map(|q| (0..D).map(|a| (pos[i][a] - q[a]).powi(2)).sum::<f64>())
            .fold(f64::INFINITY, f64::min);
        lo = lo.min(d2.sqrt());
        hi = hi.max(d2.sqrt());
    }
    (lo, hi)
}

/// The invariants of a cluster grown with noise reduction `f` (1 included): every particle
/// after the seed at distance `f` from an earlier one (the one it touched) and no two closer
/// than `f`, both to within the stored positions' rounding `tol`, less `slack` (PDLA's re-check
/// tolerance, `1 - OVERLAP_DISTANCE`, for the smallest distance); `n` particles, all finite.
fn assert_cluster<const D: usize>(sim: &Simulation<D>, n: u64, slack: f64) {
    let params = sim.params();
    let (f, tol) = (params.noise_reduction, tolerance::<D>(params));
    let pos = sim.positions().unwrap();
    assert_eq!((pos.len() as u64, sim.particles()), (n, n));
    assert!(pos.iter().flatten().all(|x| x.is_finite()));
    let (lo, hi) = nearest_earlier(pos);
    let what = format!(
        "{D}D, p {}, f {f}, {} threads",
        params.sticking_probability, params.threads
    );
    // The nearest earlier particle is at distance f, within the rounding: none closer (so no
    // two particles closer than f), and none farther (each touched an earlier one).
    assert!(lo >= f - tol - slack, "{what}: two particles {lo} apart");
    assert!(
        hi <= f + tol,
        "{what}: a particle {hi} from every earlier one"
    );
}

/// With both parameters at 1 given explicitly, a run is the default one: the same state hash,
/// and the hash the plain model gave before the parameters existed (recorded with the code of
/// commit ce928da, serial 2D and 3D).
#[test]
fn both_at_one_is_the_plain_model_bit_for_bit() {
    for (dim, n, seed) in [(2usize, 1500u64, 7u64), (3, 800, 8)] {
        let plain = Params {
            dim,
            particles: n,
            ..Params::default()
        };
        let explicit = Params {
            sticking_probability: 1.0,
            noise_reduction: 1.0,
            ..plain.clone()
        };
        let hash = |p: &Params| {
            dla_pdla::with_dim!(dim, D => {
                let mut sim = Simulation::<D>::new(p.clone(), seed).unwrap();
                sim.run().unwrap();
                assert_eq!(sim.walk_counts().refused, 0);
                sim.state_hash()
            }, _ => unreachable!())
        };
        assert_eq!(hash(&explicit), hash(&plain), "{dim}D");
        let before = match dim {
            2 => PLAIN_2D_1500_SEED_7,
            _ => PLAIN_3D_800_SEED_8,
        };
        assert_eq!(
            hash(&plain),
            before,
            "{dim}D: the plain model's trajectory changed"
        );
    }
}

/// State hashes of the plain model (the same before `sticking_probability` and
/// `noise_reduction`; since walkers leave a map cell's empty ball rather than jump by their
/// own bound, which moves them differently, and in 2D since that exit point is computed
/// without a division by the ball's radius and with its scale's division and square root side
/// by side, each of which rounds it differently).
const PLAIN_2D_1500_SEED_7: &str = "ab06f4c52cdb41ae";
const PLAIN_3D_800_SEED_8: &str = "3f0949bb708b5c90";

/// Noise reduction 1/2 in 2D and 3D: every particle at distance 1/2 from an earlier one, none
/// closer than 1/2 to another; and with 1, the plain model's contacts (distance 1, none
/// closer), to the rounding of the stored positions.
#[test]
fn noise_reduction_stores_each_particle_at_f_from_the_one_it_touched() {
    for f in [0.5, 1.0] {
        let params = |particles| Params {
            particles,
            noise_reduction: f,
            ..Params::default()
        };
        assert_cluster(&grow::<2>(params(1500), 3), 1500, 0.0);
        assert_cluster(&grow::<3>(params(700), 4), 700, 0.0);
    }
    // Overlapping particles make a denser cluster: at the same N its radius of gyration is
    // smaller than the plain model's.
    let rg = |f| {
        grow::<2>(
            Params {
                particles: 1500,
                noise_reduction: f,
                ..Params::default()
            },
            3,
        )
        .radius_of_gyration()
    };
    assert!(rg(0.5) < 0.8 * rg(1.0), "{} against {}", rg(0.5), rg(1.0));
}

/// Sticking probability 0.05 in 2D and 3D: refused walkers never step inside a particle (none
/// closer than 1 to another, each at 1 from an earlier one), and a walker is refused about
/// `(1 - p) / p` times before it sticks.
#[test]
fn refused_walkers_walk_on_without_overlapping() {
    fn one<const D: usize>(n: u64)
    where
        Dim<D>: Space<D>,
    {
        let p = 0.05;
        let sim = grow::<D>(
            Params {
                particles: n,
                sticking_probability: p,
                ..Params::default()
            },
            5,
        );
        assert_cluster(&sim, n, 0.0);
        let refused = sim.walk_counts().refused as f64;
        // Geometric: (1 - p) / p refusals per walker on average, 19 here, with a relative
        // standard deviation of 1 / sqrt((1 - p) (n - 1)), 3 to 4 %.
        let expected = (1.0 - p) / p * (n - 1) as f64;
        assert!(
            refused > 0.8 * expected && refused < 1.25 * expected,
            "{D}D: {refused} refused contacts, about {expected} expected"
        );
    }
    one::<2>(1000);
    one::<3>(700);
}

/// Reaction-limited clusters are more compact: over 8 seeds of 1000 particles in 2D, the mean
/// radius of gyration with sticking probability 0.05 is clearly below that of DLA.
#[test]
fn a_small_sticking_probability_grows_more_compact_clusters() {
    let mean_rg = |p: f64| {
        let rg: f64 = (1..=8)
            .map(|seed| {
                let params = Params {
                    particles: 1000,
                    sticking_probability: p,
                    ..Params::default()
                };
                let mut sim = Simulation::<2>::new(params, seed).unwrap();
                sim.run().unwrap();
                sim.radius_of_gyration()
            })
            .sum();
        rg / 8.0
    };
    let (rla, dla) = (mean_rg(0.05), mean_rg(1.0));
    assert!(
        rla < 0.9 * dla,
        "mean R_g {rla} with p = 0.05, {dla} with 1"
    );
}

/// PDLA with two threads, sticking probability 0.3 and noise reduction 1/2: the requested size
/// and the geometric invariants (none closer than 1/2 less the re-check's tolerance).
#[test]
fn pdla_with_both_parameters_keeps_the_invariants() {
    let sim = grow::<2>(
        Params {
            particles: 2000,
            threads: 2,
            sticking_probability: 0.3,
            noise_reduction: 0.5,
            ..Params::default()
        },
        6,
    );
    assert_cluster(&sim, 2000, 1.0 - OVERLAP_DISTANCE);
    assert!(sim.walk_counts().refused > 0);
}

/// Both parameters in 3D to 5D, serially and in PDLA (small clusters).
#[test]
fn both_parameters_in_every_dimension() {
    fn one<const D: usize>(n: u64, threads: usize)
    where
        Dim<D>: Space<D>,
    {
        let sim = grow::<D>(
            Params {
                particles: n,
                threads,
                sticking_probability: 0.3,
                noise_reduction: 0.6,
                ..Params::default()
            },
            9,
        );
        let slack = if threads > 1 {
            1.0 - OVERLAP_DISTANCE
        } else {
            0.0
        };
        assert_cluster(&sim, n, slack);
    }
    one::<3>(500, 1);
    one::<3>(500, 2);
    one::<4>(250, 1);
    one::<4>(250, 2);
    one::<5>(150, 1);
    one::<5>(150, 2);
}

/// A serial run with both parameters below 1, checkpointed midway (with particles after the
/// checkpoint that a kill loses) and resumed, ends with the uninterrupted run's state hash.
#[test]
fn a_resumed_run_with_both_parameters_is_the_uninterrupted_run() {
    let params = Params {
        particles: 1200,
        sticking_probability: 0.3,
        noise_reduction: 0.5,
        ..Params::default()
    };
    let mut whole = Simulation::<2>::new(params.clone(), 12).unwrap();
    whole.run().unwrap();
    let dir = tempfile::tempdir().unwrap();
    let mut sim = Simulation::<2>::new(params, 12).unwrap();
    sim.stream_into(dir.path(), true).unwrap();
    for _ in 0..500 {
        sim.add_one().unwrap();
    }
    sim.write_checkpoint().unwrap();
    for _ in 0..40 {
        sim.add_one().unwrap();
    }
    sim.sync_streams().unwrap();
    drop(sim);
    let mut resumed = Simulation::<2>::resume(dir.path(), None).unwrap();
    assert_eq!(resumed.particles(), 501);
    assert_eq!(resumed.params(), whole.params());
    resumed.stream_into(dir.path(), true).unwrap();
    resumed.run().unwrap();
    assert_eq!(resumed.state_hash(), whole.state_hash());
    assert_eq!(resumed.radius_of_gyration(), whole.radius_of_gyration());
}
