//! Times `DistanceMap::insert` on the positions of a DLA run (`dla --positions bin`), arrival
//! order: `cargo run --release -p spatial --example distmap_insert -- OUT/positions.bin [cell:cap
//! ...]`.
use spatial::distmap::{DistanceMap, PointMap};
use std::time::Instant;

fn main() {
    let mut args = std::env::args().skip(1);
    let path = args.next().expect("positions.bin");
    let bytes = std::fs::read(&path).expect("read");
    // DLAPOS02 has the parents after the coordinates, which this reads past.
    assert!(matches!(&bytes[..8], b"DLAPOS01" | b"DLAPOS02"));
    let dim = u32::from_le_bytes(bytes[8..12].try_into().unwrap());
    assert_eq!(dim, 2, "2D positions only");
    let n = u64::from_le_bytes(bytes[12..20].try_into().unwrap()) as usize;
    let pts: Vec<[f64; 2]> = (0..n)
        .map(|i| {
            let o = 20 + 16 * i;
            [
                f64::from_le_bytes(bytes[o..o + 8].try_into().unwrap()),
                f64::from_le_bytes(bytes[o + 8..o + 16].try_into().unwrap()),
            ]
        })
        .collect();
    let levels: Vec<(f64, f64)> = {
        let v: Vec<String> = args.collect();
        if v.is_empty() {
            vec![(8.0, 64.0), (64.0, 512.0)]
        } else {
            v.iter()
                .map(|s| {
                    let (a, b) = s.split_once(':').expect("cell:cap");
                    (a.parse().unwrap(), b.parse().unwrap())
                })
                .collect()
        }
    };
    for (cell, cap) in levels {
        let mut map = DistanceMap::<2>::new(cell, cap).unwrap();
        let t = Instant::now();
        for p in &pts {
            map.insert(p).unwrap();
        }
        let s = t.elapsed().as_secs_f64();
        println!(
            "cell {cell} cap {cap}: {n} inserts in {s:.3} s, {:.0} ns per insert, {} bytes",
            s * 1e9 / n as f64,
            map.memory_bytes()
        );
    }
}
