//! Contact, determinism, growth-sample, PDLA, checkpoint and far-field-jump tests of whole
//! runs.

mod common;

use common::check_contacts;
use dla_pdla::sim::{OVERLAP_DISTANCE, SimError};
use dla_pdla::{Dim, FarField, Params, Simulation, Space};

fn grow<const D: usize>(n: u64, seed: u64, threads: usize) -> Simulation<D>
where
    Dim<D>: Space<D>,
{
    grow_with(
        Params {
            dim: D,
            particles: n,
            threads,
            ..Params::default()
        },
        seed,
    )
}

fn grow_with<const D: usize>(params: Params, seed: u64) -> Simulation<D>
where
    Dim<D>: Space<D>,
{
    let params = Params {
        keep_positions: true,
        ..params
    };
    let mut sim = Simulation::<D>::new(params, seed).unwrap();
    sim.run().unwrap();
    sim
}

fn contacts<const D: usize>(threads: usize)
where
    Dim<D>: Space<D>,
{
    contacts_with::<D>(threads, true);
}

fn contacts_with<const D: usize>(threads: usize, distance_map: bool)
where
    Dim<D>: Space<D>,
{
    contacts_sized::<D>(threads, distance_map, 20_000);
}

fn contacts_sized<const D: usize>(threads: usize, distance_map: bool, n: u64)
where
    Dim<D>: Space<D>,
{
    let sim = grow_with::<D>(
        Params {
            dim: D,
            particles: n,
            threads,
            distance_map,
            ..Params::default()
        },
        11,
    );
    let pos = sim.positions().unwrap();
    assert_eq!(pos.len() as u64, n);
    let (min_pair, max_contact) = check_contacts(pos);
    assert!(
        min_pair >= 1.0 - 1e-6,
        "{D}D, {threads} threads: two particles at {min_pair}"
    );
    assert!(
        max_contact <= 1.0 + 1e-6,
        "{D}D, {threads} threads: a particle at {max_contact} from every earlier one"
    );
    assert!(pos.iter().flatten().all(|x| x.is_finite()));
    if threads == 1 {
        assert_eq!(sim.discarded_walkers(), 0);
    }
}

#[test]
fn contacts_2d_one_thread() {
    contacts::<2>(1);
}

#[test]
fn contacts_without_the_distance_map() {
    contacts_with::<2>(1, false);
    contacts_with::<3>(2, false);
}

#[test]
fn contacts_3d_one_thread() {
    contacts::<3>(1);
}

#[test]
fn contacts_2d_two_threads() {
    contacts::<2>(2);
}

#[test]
fn contacts_3d_two_threads() {
    contacts::<3>(2);
}

/// 4D and 5D, serial and PDLA, with and without the distance map (smaller clusters: a 5D
/// particle costs 50 to 100 2D ones).
#[test]
fn contacts_4d_and_5d() {
    for threads in [1, 2] {
        contacts_sized::<4>(threads, true, 3000);
        contacts_sized::<5>(threads, true, 1200);
    }
    contacts_sized::<4>(1, false, 1500);
    contacts_sized::<5>(1, false, 600);
}

/// The walker's near cache answers exactly as the tree does, so it changes nothing but speed:
/// the same positions with it on and off, for the default walk, the tree-only walk (where the
/// cache answers most moves), the exact search, and a precision too coarse for the cache to
/// be used (kappa 0.8: the tree is exact only within 0.3 leaf diagonals, under the cache's
/// 5 diameters in 2D and 3D).
fn near_cache_is_invisible<const D: usize>(n: u64)
where
    Dim<D>: Space<D>,
{
    for (precision, distance_map) in [
        (2.0, true),
        (2.0, false),
        (f64::INFINITY, true),
        (0.8, true),
    ] {
        let run = |near_cache| {
            grow_with::<D>(
                Params {
                    dim: D,
                    particles: n,
                    precision,
                    distance_map,
                    near_cache,
                    ..Params::default()
                },
                3,
            )
        };
        let (on, off) = (run(true), run(false));
        assert_eq!(
            on.positions(),
            off.positions(),
            "{D}D, precision {precision}, distance map {distance_map}"
        );
        assert_eq!(on.state_hash(), off.state_hash());
    }
}

#[test]
fn near_cache_changes_nothing_but_speed() {
    near_cache_is_invisible::<2>(4000);
    near_cache_is_invisible::<3>(3000);
    near_cache_is_invisible::<4>(1000);
    near_cache_is_invisible::<5>(400);
}

#[test]
fn same_seed_same_hash_different_seed_different_hash() {
    let a = grow::<2>(3000, 5, 1);
    let b = grow::<2>(3000, 5, 1);
    let c = grow::<2>(3000, 6, 1);
    assert_eq!(a.state_hash(), b.state_hash());
    assert_eq!(a.positions(), b.positions());
    assert_ne!(a.state_hash(), c.state_hash());
    let a3 = grow::<3>(2000, 5, 1);
    let b3 = grow::<3>(2000, 5, 1);
    let c3 = grow::<3>(2000, 6, 1);
    assert_eq!(a3.state_hash(), b3.state_hash());
    assert_ne!(a3.state_hash(), c3.state_hash());
    // The hash does not depend on keeping positions.
    let mut p = a.params().clone();
    p.keep_positions = false;
    let mut d = Simulation::<2>::new(p, 5).unwrap();
    d.run().unwrap();
    assert_eq!(d.state_hash(), a.state_hash());
}

/// A far-field-jump run with a death radius so large that walkers wander far before dying:
/// every coordinate finite and every contact exact.
fn jump_with_huge_death_radius<const D: usize>()
where
    Dim<D>: Space<D>,
{
    let sim = grow_with::<D>(
        Params {
            dim: D,
            particles: 1500,
            far_field: FarField::Jump,
            death_ratio: 1e20,
            ..Params::default()
        },
        3,
    );
    let pos = sim.positions().unwrap();
    assert!(pos.iter().flatten().all(|x| x.is_finite()));
    let (mn, mx) = check_contacts(pos);
    assert!(mn >= 1.0 - 1e-6 && mx <= 1.0 + 1e-6, "{D}D: {mn} {mx}");
}

#[test]
fn far_field_jump_with_huge_death_radius_finishes_finite() {
    jump_with_huge_death_radius::<2>();
    jump_with_huge_death_radius::<3>();
}

#[test]
fn growth_samples_are_log_spaced_and_end_at_n() {
    let n = 20_000;
    let sim = grow::<2>(n, 1, 1);
    let s = sim.samples();
    // 200 per decade: every N up to about 87, then log-spaced.
    assert!(s.len() > 450 && s.len() < 650, "{}", s.len());
    assert_eq!(s[0].n, 1);
    assert_eq!(s.last().unwrap().n, n);
    // Each sample is taken at the next log-spaced size, `ceil(N ratio)` (at least one more
    // particle), with `ratio^SAMPLES_PER_DECADE = 10` whatever the target; the last one at `n`.
    let ratio = 10f64.powf(1.0 / dla_pdla::sim::SAMPLES_PER_DECADE);
    for w in s.windows(2) {
        let next = (w[0].n + 1).max((w[0].n as f64 * ratio).ceil() as u64);
        assert!(
            w[1].n == next || (w[1].n == n && n < next),
            "sample at {} after {}, expected {next}",
            w[1].n,
            w[0].n
        );
        assert!(w[1].r_ext >= w[0].r_ext && w[1].seconds >= w[0].seconds);
    }
    // Log-spaced: past the sizes where the one-particle minimum rules, successive sizes
    // differ by the ratio (up to the rounding up to whole particles).
    for w in s
        .windows(2)
        .filter(|w| w[1].n < n && w[0].n as f64 * (ratio - 1.0) > 1.0)
    {
        let r = w[1].n as f64 / w[0].n as f64;
        assert!(
            r >= ratio && r <= ratio + 1.0 / w[0].n as f64,
            "{r} vs {ratio}"
        );
    }
}

#[test]
fn discard_guard_fails_loudly_instead_of_spinning() {
    use dla_pdla::SimError;
    use dla_pdla::sim::{DiscardGuard, MAX_CONSECUTIVE_DISCARDS};
    let mut g = DiscardGuard::default();
    for _ in 0..10 {
        g.record(true).unwrap();
    }
    g.record(false).unwrap();
    assert_eq!((g.total, g.consecutive), (10, 0));
    for _ in 1..MAX_CONSECUTIVE_DISCARDS {
        g.record(true).unwrap();
    }
    let e = g.record(true).unwrap_err();
    assert!(
        matches!(e, SimError::DiscardLivelock { consecutive, .. } if consecutive == MAX_CONSECUTIVE_DISCARDS)
    );
    assert!(e.to_string().contains("livelock"), "{e}");
}

/// No two particles of `positions` overlap, and every particle but the first touches an
/// earlier one (it stuck at contact, to rounding); `tree` holds exactly these positions.
fn assert_valid_cluster<const D: usize>(
    tree: &spatial::orthtree::Orthtree<D>,
    positions: &[[f64; D]],
) {
    assert_eq!(tree.len(), positions.len());
    let mut a: Vec<[f64; D]> = tree.iter().collect();
    let mut b = positions.to_vec();
    a.sort_by(|x, y| x.partial_cmp(y).unwrap());
    b.sort_by(|x, y| x.partial_cmp(y).unwrap());
    assert_eq!(a, b);
    for (i, p) in positions.iter().enumerate() {
        let mut within_overlap = 0;
        tree.for_each_within(p, OVERLAP_DISTANCE, |_| within_overlap += 1);
        assert_eq!(within_overlap, 1, "particle {i} at {p:?} overlaps another");
        if i > 0 {
            let touches = positions[..i]
                .iter()
                .any(|q| spatial::orthtree::dist_sq(p, q).sqrt() <= 1.0 + 1e-6);
            assert!(touches, "particle {i} at {p:?} touches no earlier particle");
        }
    }
}

#[test]
fn pdla_tree_holds_exactly_the_recorded_positions_touching_and_without_overlap() {
    let params = Params {
        particles: 5000,
        threads: 2,
        serial_until: 100,
        keep_positions: true,
        ..Params::default()
    };
    let mut sim = Simulation::<2>::new(params, 9).unwrap();
    sim.run().unwrap();
    assert_eq!(sim.particles(), 5000);
    assert_eq!(sim.positions().unwrap().len(), 5000);
    // Threads stick walkers concurrently, yet no two particles overlap, and every particle
    // but the seed touches an earlier one.
    assert_valid_cluster(sim.tree(), sim.positions().unwrap());
}

/// More threads than cores (threads preempted mid-walk, catching up on many particles at
/// once), in 3D with its own distance maps: still overlap-free and touching.
#[test]
fn pdla_with_more_threads_than_cores_in_3d_is_a_valid_cluster() {
    let params = Params {
        dim: 3,
        particles: 4000,
        threads: 4,
        serial_until: 100,
        keep_positions: true,
        ..Params::default()
    };
    let mut sim = Simulation::<3>::new(params, 11).unwrap();
    sim.run().unwrap();
    assert_eq!(sim.particles(), 4000);
    assert_valid_cluster(sim.tree(), sim.positions().unwrap());
}

#[test]
fn pdla_checkpointed_stopped_and_resumed_is_a_valid_cluster() {
    let params = Params {
        particles: 12_000,
        threads: 2,
        serial_until: 500,
        ..Params::default()
    };
    let dir = tempfile::tempdir().unwrap();
    let halt = std::sync::atomic::AtomicBool::new(false);
    let mut sim = Simulation::<2>::new(params, 4).unwrap();
    sim.stream_into(dir.path(), true).unwrap();
    // Stopped (as by a signal) once past 5000 particles, in the parallel phase.
    let finished = sim
        .run_checkpointed(3000, &halt, &|n| {
            if n > 5000 {
                halt.store(true, std::sync::atomic::Ordering::Relaxed);
            }
        })
        .unwrap();
    assert!(!finished);
    let stopped_at = sim.particles();
    assert!(stopped_at > 5000 && stopped_at < 12_000, "{stopped_at}");
    drop(sim);
    let mut resumed = Simulation::<2>::resume(dir.path(), None).unwrap();
    assert_eq!(resumed.particles(), stopped_at);
    resumed.stream_into(dir.path(), true).unwrap();
    let go_on = std::sync::atomic::AtomicBool::new(false);
    assert!(resumed.run_checkpointed(3000, &go_on, &|_| {}).unwrap());
    assert_eq!(resumed.particles(), 12_000);
    let mut positions = Vec::new();
    dla_pdla::output::each_position(&resumed, dir.path(), |_, p: &[f64; 2]| {
        positions.push(*p);
        Ok(())
    })
    .unwrap();
    assert_eq!(positions.len(), 12_000);
    assert_valid_cluster(resumed.tree(), &positions);
}

/// Checkpoints a 3000-particle run after `stop` walkers, resumes it and grows it to the end:
/// the same state hash, `R_g` and growth samples as the uninterrupted run, and a
/// `positions.npy` holding its positions; `run_checkpointed` also ends with that hash and
/// leaves a final checkpoint that resumes to it. Returns the directory holding that final
/// checkpoint.
fn checkpoint_and_resume<const D: usize>(stop: u64) -> tempfile::TempDir
where
    Dim<D>: Space<D>,
{
    let params = Params {
        dim: D,
        particles: 3000,
        keep_positions: true,
        ..Params::default()
    };
    let streamed = Params {
        keep_positions: false,
        ..params.clone()
    };
    let dir = tempfile::tempdir().unwrap();
    let mut a = Simulation::<D>::new(params.clone(), 21).unwrap();
    a.run().unwrap();
    let mut b = Simulation::<D>::new(streamed.clone(), 21).unwrap();
    b.stream_into(dir.path(), true).unwrap();
    for _ in 0..stop {
        b.add_one().unwrap();
    }
    b.write_checkpoint().unwrap();
    // More particles after the checkpoint, never checkpointed: a killed run's extra rows.
    for _ in 0..50 {
        b.add_one().unwrap();
    }
    b.sync_streams().unwrap();
    drop(b);
    let mut c = Simulation::<D>::resume(dir.path(), None).unwrap();
    assert_eq!(c.particles(), stop + 1);
    c.stream_into(dir.path(), true).unwrap();
    c.run().unwrap();
    c.sync_streams().unwrap();
    assert_eq!(c.state_hash(), a.state_hash());
    assert_eq!(c.radius_of_gyration(), a.radius_of_gyration());
    let n: Vec<u64> = c.samples().iter().map(|s| s.n).collect();
    assert_eq!(n, a.samples().iter().map(|s| s.n).collect::<Vec<_>>());
    let mut from_file = Vec::new();
    dla_pdla::output::each_position(&c, dir.path(), |_, p: &[f64; D]| {
        from_file.push(*p);
        Ok(())
    })
    .unwrap();
    assert_eq!(Some(from_file.as_slice()), a.positions());
    let growth = std::fs::read_to_string(dir.path().join("growth.csv")).unwrap();
    assert_eq!(growth.lines().count(), a.samples().len() + 1);
    let fresh = tempfile::tempdir().unwrap();
    let mut d = Simulation::<D>::new(streamed, 21).unwrap();
    d.stream_into(fresh.path(), true).unwrap();
    let stop_flag = std::sync::atomic::AtomicBool::new(false);
    assert!(d.run_checkpointed(1000, &stop_flag, &|_| {}).unwrap());
    assert_eq!(d.state_hash(), a.state_hash());
    assert_eq!(
        Simulation::<D>::resume(fresh.path(), None)
            .unwrap()
            .state_hash(),
        a.state_hash()
    );
    fresh
}

#[test]
fn checkpoint_and_resume_give_the_uninterrupted_state_hash() {
    checkpoint_and_resume::<2>(1234);
    checkpoint_and_resume::<4>(777);
    let dir = checkpoint_and_resume::<3>(999);
    // A checkpoint of the wrong dimension is refused.
    assert!(Simulation::<2>::resume(dir.path(), None).is_err());
}

#[test]
fn a_run_extended_from_its_checkpoint_ends_as_a_run_made_to_the_larger_size() {
    let params = |particles| Params {
        particles,
        ..Params::default()
    };
    let dir = tempfile::tempdir().unwrap();
    let stop = std::sync::atomic::AtomicBool::new(false);
    let mut short = Simulation::<2>::new(params(2000), 5).unwrap();
    short.stream_into(dir.path(), true).unwrap();
    assert!(short.run_checkpointed(700, &stop, &|_| {}).unwrap());
    let mut long = Simulation::<2>::resume(dir.path(), Some(3500)).unwrap();
    assert_eq!(long.params().particles, 3500);
    let elsewhere = tempfile::tempdir().unwrap();
    long.stream_into(elsewhere.path(), true).unwrap();
    long.run().unwrap();
    long.sync_streams().unwrap();
    let mut direct = Simulation::<2>::new(params(3500), 5).unwrap();
    direct.run().unwrap();
    assert_eq!(long.state_hash(), direct.state_hash());
    assert_eq!(long.samples().len(), direct.samples().len());
    for (a, b) in long.samples().iter().zip(direct.samples()) {
        assert_eq!(
            (a.n, a.radius_of_gyration, a.r_ext),
            (b.n, b.radius_of_gyration, b.r_ext)
        );
    }
    // Below the particles stored: refused.
    assert!(matches!(
        Simulation::<2>::resume(dir.path(), Some(1999)),
        Err(SimError::CheckpointUsage(_))
    ));
}

#[test]
fn a_positions_log_that_is_not_the_checkpoints_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let mut s = Simulation::<2>::new(
        Params {
            particles: 500,
            ..Params::default()
        },
        1,
    )
    .unwrap();
    s.stream_into(dir.path(), true).unwrap();
    s.run().unwrap();
    s.write_checkpoint().unwrap();
    let log = dir.path().join("positions.npy");
    let mut bytes = std::fs::read(&log).unwrap();
    // One coordinate of the 100th particle moved by about 2e-6 of itself (a last-bit change
    // would vanish: the tree stores positions on its own grid, and the log holds the stored
    // positions).
    let at = 128 + 99 * 16 + 4;
    bytes[at] ^= 0x10;
    std::fs::write(&log, &bytes).unwrap();
    let e = Simulation::<2>::resume(dir.path(), None).unwrap_err();
    assert!(
        e.to_string().contains("does not belong to the checkpoint"),
        "{e}"
    );
    // Cut short: refused too.
    bytes[at] ^= 0x10;
    bytes.truncate(128 + 300 * 16);
    std::fs::write(&log, &bytes).unwrap();
    let e = Simulation::<2>::resume(dir.path(), None).unwrap_err();
    assert!(e.to_string().contains("positions.npy"), "{e}");
}

#[test]
fn checkpoints_need_the_positions_streamed() {
    let stop = std::sync::atomic::AtomicBool::new(false);
    for threads in [1, 2] {
        let mut s = Simulation::<2>::new(
            Params {
                particles: 100,
                threads,
                ..Params::default()
            },
            1,
        )
        .unwrap();
        assert!(matches!(
            s.run_checkpointed(10, &stop, &|_| {}),
            Err(SimError::CheckpointUsage(_))
        ));
        assert!(matches!(
            s.write_checkpoint(),
            Err(SimError::CheckpointUsage(_))
        ));
        let dir = tempfile::tempdir().unwrap();
        s.stream_into(dir.path(), false).unwrap();
        assert!(s.run_checkpointed(10, &stop, &|_| {}).is_err());
        assert!(!dir.path().join("checkpoint.bin").exists());
    }
}

#[test]
fn a_tree_out_of_indices_stops_the_run_with_a_typed_error() {
    for threads in [1, 2] {
        let mut sim = Simulation::<2>::new(
            Params {
                particles: 100_000,
                threads,
                ..Params::default()
            },
            3,
        )
        .unwrap();
        sim.set_tree_index_limit(2000);
        let e = sim.run().unwrap_err();
        assert!(
            matches!(
                e,
                SimError::Tree(spatial::orthtree::OrthtreeError::CapacityExceeded(_))
            ),
            "{e}"
        );
        assert!(
            sim.particles() > 100 && sim.particles() < 2000,
            "{}",
            sim.particles()
        );
    }
}

/// `run_until` stops where it is told (here from the progress report, as a front end's
/// Ctrl-C would) and a later call continues: stopped twice and continued, one thread ends as
/// the uninterrupted run, with the same samples and positions; two threads stop at a
/// quiescent point and end as a valid cluster of the target size.
#[test]
fn run_until_stops_and_continues_to_the_uninterrupted_run() {
    use std::sync::atomic::{AtomicBool, Ordering};
    let whole = grow::<2>(5000, 3, 1);
    let mut sim = Simulation::<2>::new(
        Params {
            particles: 5000,
            keep_positions: true,
            ..Params::default()
        },
        3,
    )
    .unwrap();
    for at in [1024, 3072] {
        let stop = AtomicBool::new(false);
        let done = sim
            .run_until(&stop, &|n| {
                if n >= at {
                    stop.store(true, Ordering::Relaxed);
                }
            })
            .unwrap();
        assert!(!done);
        // Stopped right after the particle whose report set the flag.
        assert_eq!(sim.particles(), at);
    }
    assert!(sim.run_until(&AtomicBool::new(false), &|_| {}).unwrap());
    assert_eq!(sim.state_hash(), whole.state_hash());
    let n = |s: &Simulation<2>| s.samples().iter().map(|s| s.n).collect::<Vec<_>>();
    assert_eq!(n(&sim), n(&whole));
    assert_eq!(
        sim.into_positions().unwrap(),
        whole.into_positions().unwrap()
    );

    let mut pdla = Simulation::<2>::new(
        Params {
            particles: 3000,
            threads: 2,
            keep_positions: true,
            ..Params::default()
        },
        5,
    )
    .unwrap();
    let stop = AtomicBool::new(false);
    let done = pdla
        .run_until(&stop, &|n| {
            if n >= 1000 {
                stop.store(true, Ordering::Relaxed);
            }
        })
        .unwrap();
    assert!(!done && pdla.particles() < 3000);
    assert!(pdla.run_until(&AtomicBool::new(false), &|_| {}).unwrap());
    assert_eq!(pdla.particles(), 3000);
    assert_valid_cluster(pdla.tree(), pdla.positions().unwrap());
}

/// PDLA towards a very large target reserves the tree's room phase by phase, not for the whole
/// target at once from a tree of one particle (which asked for 30 GB at 1e8 and aborted).
#[test]
fn pdla_towards_a_huge_target_starts_without_reserving_it_all() {
    use std::sync::atomic::{AtomicBool, Ordering};
    let mut pdla = Simulation::<2>::new(
        Params {
            particles: 100_000_000,
            threads: 2,
            ..Params::default()
        },
        7,
    )
    .unwrap();
    let stop = AtomicBool::new(false);
    let done = pdla
        .run_until(&stop, &|n| {
            if n >= 2000 {
                stop.store(true, Ordering::Relaxed);
            }
        })
        .unwrap();
    assert!(!done && pdla.particles() >= 2000);
    assert!(
        pdla.tree().memory_bytes() < 1 << 30,
        "{} bytes",
        pdla.tree().memory_bytes()
    );
}
