//! Each particle's parent (`connectivity`): the parents form one tree rooted at the seed, in
//! arrival order, every particle at its contact distance from its parent (1, or `f` with
//! noise reduction), serially and in PDLA, in 2D to 5D; recording them leaves the walk
//! unchanged; checkpoints keep them; the branch analysis of a real cluster matches a naive
//! one; and the binary writes them in every positions format.

mod common;

use common::tolerance;
use dla_pdla::branches::{Branches, Order};
use dla_pdla::sim::PARENTS_FILE;
use dla_pdla::{Dim, Params, Simulation, Space};
use std::process::Command;

/// A finished run of `params` with its parents recorded (positions kept).
fn grow<const D: usize>(params: Params, seed: u64) -> Simulation<D>
where
    Dim<D>: Space<D>,
{
    common::grow(
        Params {
            connectivity: true,
            ..params
        },
        seed,
    )
}

/// Parents form one tree in arrival order and each particle lies at the contact distance
/// from its parent, the nearest of the earlier particles (brute force).
fn assert_tree<const D: usize>(sim: &Simulation<D>) {
    let pos = sim.positions().unwrap();
    let parents = sim.parents().unwrap();
    assert_eq!(parents.len(), pos.len());
    assert_eq!(parents[0], -1);
    let f = sim.params().noise_reduction;
    let tol = tolerance::<D>(sim.params());
    let dist =
        |a: &[f64; D], b: &[f64; D]| (0..D).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt();
    for i in 1..pos.len() {
        let p = parents[i];
        assert!(
            p >= 0 && (p as usize) < i,
            "{D}D: particle {i} has parent {p}"
        );
        let d = dist(&pos[i], &pos[p as usize]);
        assert!(
            (d - f).abs() <= tol,
            "{D}D: particle {i} is {d} from its parent"
        );
        let nearest = pos[..i]
            .iter()
            .map(|q| dist(&pos[i], q))
            .fold(f64::INFINITY, f64::min);
        assert!(
            d <= nearest + tol,
            "{D}D: particle {i}: parent at {d}, nearest {nearest}"
        );
    }
}

#[test]
fn parents_form_a_tree_at_contact_distance_in_every_dimension() {
    let plain = Params {
        particles: 600,
        ..Params::default()
    };
    assert_tree(&grow::<2>(plain.clone(), 1));
    assert_tree(&grow::<3>(plain.clone(), 2));
    assert_tree(&grow::<4>(plain.clone(), 3));
    assert_tree(&grow::<5>(plain.clone(), 4));
    // The variants: refusals at contact, and storage at distance f.
    let variant = Params {
        particles: 500,
        sticking_probability: 0.3,
        noise_reduction: 0.5,
        ..Params::default()
    };
    assert_tree(&grow::<2>(variant.clone(), 5));
    assert_tree(&grow::<3>(variant, 6));
}

#[test]
fn pdla_parents_form_a_tree() {
    for (threads, seed) in [(2, 7), (3, 8)] {
        let params = Params {
            particles: 3000,
            threads,
            serial_until: 200,
            ..Params::default()
        };
        let sim = grow::<2>(params.clone(), seed);
        assert_tree(&sim);
        let sim = grow::<3>(
            Params {
                noise_reduction: 0.5,
                ..params
            },
            seed,
        );
        assert_tree(&sim);
    }
}

/// Recording the parents changes nothing the walk does.
#[test]
fn recording_parents_keeps_the_state_hash() {
    for seed in [1, 2] {
        let params = Params {
            particles: 2000,
            ..Params::default()
        };
        let mut plain = Simulation::<2>::new(params.clone(), seed).unwrap();
        plain.run().unwrap();
        let linked = grow::<2>(params, seed);
        assert_eq!(plain.state_hash(), linked.state_hash());
        assert!(plain.parents().is_none());
    }
}

/// A run checkpointed, dropped and resumed (in memory and from `positions_parent.npy`) ends with the
/// uninterrupted run's parents.
#[test]
fn checkpoints_keep_the_parents() {
    let params = Params {
        particles: 1500,
        connectivity: true,
        ..Params::default()
    };
    let whole = grow::<2>(params.clone(), 9);
    let dir = tempfile::tempdir().unwrap();
    let mut sim = Simulation::<2>::new(params.clone(), 9).unwrap();
    sim.stream_into(dir.path(), true).unwrap();
    for _ in 0..700 {
        sim.add_one().unwrap();
    }
    sim.write_checkpoint().unwrap();
    // Particles grown after the checkpoint are cut back on resume.
    for _ in 0..50 {
        sim.add_one().unwrap();
    }
    sim.sync_streams().unwrap();
    drop(sim);
    let mut resumed = Simulation::<2>::resume(dir.path(), None).unwrap();
    assert!(resumed.params().connectivity);
    resumed.stream_into(dir.path(), true).unwrap();
    resumed.run().unwrap();
    resumed.sync_streams().unwrap();
    assert_eq!(resumed.state_hash(), whole.state_hash());
    let b = Branches::from_npy(&dir.path().join(PARENTS_FILE), 1500).unwrap();
    assert_eq!(b, Branches::from_parents(whole.parents().unwrap()).unwrap());
    let mut read = Vec::new();
    dla_pdla::sim::each_particle(&resumed, dir.path(), |_, _, parent| {
        read.push(parent.unwrap());
        Ok(())
    })
    .unwrap();
    assert_eq!(read, whole.parents().unwrap());
    // A damaged parents file is refused on resume.
    let path = dir.path().join(PARENTS_FILE);
    let mut bytes = std::fs::read(&path).unwrap();
    bytes[128 + 8 * 10..128 + 8 * 11].copy_from_slice(&20i64.to_le_bytes());
    std::fs::write(&path, bytes).unwrap();
    let e = Simulation::<2>::resume(dir.path(), None)
        .unwrap_err()
        .to_string();
    assert!(e.contains("row 10 names parent 20"), "{e}");
}

/// Horton-Strahler orders by the definition, recursively over explicit children lists.
fn naive_orders(parents: &[i64]) -> Vec<Order> {
    let n = parents.len();
    let mut children = vec![Vec::new(); n];
    for (i, &p) in parents.iter().enumerate() {
        if p >= 0 {
            children[p as usize].push(i);
        }
    }
    let mut order = vec![0u32; n];
    let mut head = vec![false; n];
    for i in (0..n).rev() {
        let ks: Vec<u32> = children[i].iter().map(|&c| order[c]).collect();
        let top = ks.iter().copied().max().unwrap_or(0);
        let at_top = ks.iter().filter(|&&k| k == top).count();
        (order[i], head[i]) = match (ks.is_empty(), at_top) {
            (true, _) => (1, true),
            (false, 1) => (top, false),
            _ => (top + 1, true),
        };
    }
    let max = order.iter().copied().max().unwrap_or(0);
    (1..=max)
        .map(|k| Order {
            order: k,
            branches: (0..n).filter(|&i| order[i] == k && head[i]).count() as u64,
            particles: order.iter().filter(|&&o| o == k).count() as u64,
        })
        .collect()
}

#[test]
fn branch_analysis_of_real_clusters_matches_the_definition() {
    for seed in [1, 2, 3] {
        let sim = grow::<2>(
            Params {
                particles: 20_000,
                ..Params::default()
            },
            seed,
        );
        let parents = sim.parents().unwrap();
        let b = Branches::from_parents(parents).unwrap();
        assert_eq!(b.orders, naive_orders(parents), "seed {seed}");
        assert_eq!((b.trees, b.particles), (1, 20_000));
        // Horton's law holds roughly even at this size: the ratio lies in the published
        // range of DLA (about 5), far from a random tree's or a chain's.
        let rb = b.bifurcation_ratio().unwrap();
        assert!((4.0..6.5).contains(&rb), "seed {seed}: R_B {rb}");
    }
}

fn dla() -> Command {
    Command::new(env!("CARGO_BIN_EXE_dla"))
}

/// The binary writes the parents with the positions in every format, the branch analysis in
/// `branches.csv` and `run.json`, and the same parents whatever the format.
#[test]
fn the_binary_writes_parents_in_every_format() {
    let dir = tempfile::tempdir().unwrap();
    let run = |fmt: &str| {
        let out = dir.path().join(fmt);
        let st = dla()
            .args([
                "--particles",
                "400",
                "--seed",
                "5",
                "--quiet",
                "--positions",
                fmt,
            ])
            .arg("--out")
            .arg(&out)
            .status()
            .unwrap();
        assert!(st.success(), "{fmt}");
        out
    };
    let npy = run("npy");
    let bytes = std::fs::read(npy.join(PARENTS_FILE)).unwrap();
    let parents: Vec<i64> = bytes[128..]
        .chunks(8)
        .map(|c| i64::from_le_bytes(c.try_into().unwrap()))
        .collect();
    assert_eq!(parents.len(), 400);
    assert_eq!(parents[0], -1);
    assert!((1..400).all(|i| (0..i as i64).contains(&parents[i])));
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(npy.join("run.json")).unwrap()).unwrap();
    assert_eq!(m["results"]["trees"], 1);
    assert!(m["results"]["strahler_order"].as_u64().unwrap() >= 3);
    let table = std::fs::read_to_string(npy.join("branches.csv")).unwrap();
    assert!(
        table
            .starts_with("order,branches,particles,mean_length,bifurcation_ratio,length_ratio\n1,")
    );

    let csv = std::fs::read_to_string(run("csv").join("positions.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("x,y,parent"));
    let from_csv: Vec<i64> = lines
        .map(|l| l.rsplit(',').next().unwrap().parse().unwrap())
        .collect();
    assert_eq!(from_csv, parents);

    let bin = std::fs::read(run("bin").join("positions.bin")).unwrap();
    assert_eq!(&bin[..8], b"DLAPOS02");
    assert_eq!(bin.len(), 20 + 400 * 16 + 400 * 8);
    let from_bin: Vec<i64> = bin[20 + 400 * 16..]
        .chunks(8)
        .map(|c| i64::from_le_bytes(c.try_into().unwrap()))
        .collect();
    assert_eq!(from_bin, parents);

    let vtk = std::fs::read(run("vtk").join("positions.vtk")).unwrap();
    let find = |s: &str| vtk.windows(s.len()).position(|w| w == s.as_bytes());
    // 399 lines of 3 integers and the seed's vertex of 2.
    assert!(find("CELLS 400 1199\n").is_some());
    assert!(find("SCALARS parent int 1\n").is_some());

    let xyz = std::fs::read_to_string(run("xyz").join("positions.xyz")).unwrap();
    assert!(xyz.lines().nth(1).unwrap().contains(":parent:I:1"));
    let last: i64 = xyz
        .lines()
        .nth(2)
        .unwrap()
        .rsplit(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert_eq!(last, -1);
}
