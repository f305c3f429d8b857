//! Tests of the cell index: prefetched lines, rectangle scans against a brute-force scan, updates and windows across tiles.

use super::*;

/// The kind byte of the test items: [`KIND_B`] for `second`, else [`KIND_A`].
fn kind_byte(second: bool) -> u8 {
    if second { KIND_B } else { KIND_A }
}

#[test]
fn prefetched_lines_cover_the_rows_lines_in_the_tile() {
    // Every 8-byte row word `Window::rows` reads around p, where it lies in p's tile, is
    // in one of the prefetched lines, and every prefetched line holds a cell of the rows
    // in the tile; also at the limits of i64, where the rows cannot be formed.
    let mut pts = vec![
        [i64::MIN, i64::MIN],
        [i64::MAX, i64::MAX],
        [i64::MIN, i64::MAX],
    ];
    for x in -70..70 {
        for y in [
            -66, -65, -64, -63, -9, -8, -7, -1, 0, 1, 6, 7, 8, 62, 63, 64, 65,
        ] {
            pts.push([x, y]);
        }
    }
    for p in pts {
        let lines = near_line_offsets(p);
        // The cells of the rows in p's tile, by the offset of their line.
        let mut cells = Vec::new();
        for dy in -2..=2i64 {
            for dx in -2..=5i64 {
                let (Some(x), Some(y)) = (p[0].checked_add(dx), p[1].checked_add(dy)) else {
                    continue;
                };
                if x >> SHIFT == p[0] >> SHIFT && y >> SHIFT == p[1] >> SHIFT {
                    cells.push(offset(x, y) & !63);
                }
            }
        }
        for o in lines {
            assert_eq!(o % 64, 0, "{p:?}: {o} is not a line's start");
            assert!(
                cells.contains(&o),
                "{p:?}: line {o} holds no cell of the rows"
            );
        }
        for c in cells {
            assert!(lines.contains(&c), "{p:?}: line {c} not prefetched");
        }
    }
}

#[test]
fn scan_rect_visits_exactly_the_occupied_cells_of_the_kinds_in_the_rectangle() {
    use core_lattice::rng::{RngExt, stream};
    let mut rng = stream(5, 0);
    let mut c = CellIndex::default();
    let mut occ = std::collections::BTreeMap::new();
    // Clustered and scattered items across tile and block edges, some far away.
    for i in 0..3000u64 {
        let p = if i % 10 == 0 {
            [rng.random_range(-5000..5000), rng.random_range(-5000..5000)]
        } else {
            [rng.random_range(-100..100), rng.random_range(-70..90)]
        };
        if occ.contains_key(&p) {
            continue;
        }
        let k = kind_byte(i % 3 == 0);
        c.set(p, k, i);
        occ.insert(p, k);
    }
    // Moves within and across blocks and tiles, and removals, keep the masks right.
    let keys: Vec<[i64; 2]> = occ.keys().copied().collect();
    for (n, p) in keys.into_iter().enumerate() {
        if n % 4 == 0 {
            c.clear(p);
            occ.remove(&p);
        } else if n % 4 == 1 {
            let to = [
                p[0] + rng.random_range(-9..10),
                p[1] + rng.random_range(-9..10),
            ];
            if !occ.contains_key(&to) {
                c.relocate(p, to);
                let k = occ.remove(&p).unwrap();
                occ.insert(to, k);
            }
        }
    }
    for _ in 0..300 {
        let x0 = rng.random_range(-150..150);
        let y0 = rng.random_range(-150..150);
        let (w, h) = if rng.random_range(0..10) == 0 {
            (20000, 20000)
        } else {
            (rng.random_range(0..140), rng.random_range(0..140))
        };
        let kinds = rng.random_range(1..4u8);
        let mut seen = Vec::new();
        let _ = c.scan_rect([x0, x0 + w], [y0, y0 + h], kinds, |x, y, b| {
            assert_eq!(
                b,
                c.kinds[c.slot([x >> SHIFT, y >> SHIFT]).unwrap() as usize][offset(x, y)]
            );
            seen.push([x, y]);
            ControlFlow::Continue(())
        });
        seen.sort_unstable();
        let want: Vec<[i64; 2]> = occ
            .iter()
            .filter(|&(p, &k)| {
                (x0..=x0 + w).contains(&p[0]) && (y0..=y0 + h).contains(&p[1]) && k & kinds != 0
            })
            .map(|(p, _)| *p)
            .collect();
        let mut want = want;
        want.sort_unstable();
        assert_eq!(seen, want, "rect {x0} {y0} {w} {h} kinds {kinds}");
    }
    // A break stops the scan at once; the extremes of the plane are reachable.
    let mut n = 0;
    let r = c.scan_rect([i64::MIN, i64::MAX], [i64::MIN, i64::MAX], 3, |_, _, _| {
        n += 1;
        ControlFlow::Break(())
    });
    assert!(r.is_break() && n == 1);
    c.set([i64::MAX, i64::MIN], kind_byte(true), 1 << 40);
    let mut got = Vec::new();
    let _ = c.scan_rect(
        [i64::MAX - 3, i64::MAX],
        [i64::MIN, i64::MIN + 3],
        2,
        |x, y, _| {
            got.push([x, y]);
            ControlFlow::Continue(())
        },
    );
    assert_eq!(got, vec![[i64::MAX, i64::MIN]]);
}

#[test]
fn set_get_clear_relocate_and_windows_across_tiles() {
    let mut c = CellIndex::default();
    let pts = [[0, 0], [-1, -1], [63, 64], [64, 63], [-65, 130], [5, -200]];
    for (i, &p) in pts.iter().enumerate() {
        c.set(p, kind_byte(i % 2 == 1), 10 + i as u64);
    }
    for (i, &p) in pts.iter().enumerate() {
        assert_eq!(c.kind(p), kind_byte(i % 2 == 1));
        assert_eq!(c.id(p), 10 + i as u64);
    }
    assert_eq!(c.len(), pts.len());
    // Windows agree with kind/id everywhere in their square, across tile corners.
    for &q in &[[0i64, 0], [63, 63], [-32, 100], [64, 64], [-1, -1], [7, -9]] {
        let k = WINDOW_MAX;
        let w = c.window(q, k).unwrap();
        for x in q[0] - k..=q[0] + k {
            for y in q[1] - k..=q[1] + k {
                assert_eq!(w.at(x, y), c.kind([x, y]), "{q:?} {x} {y}");
                if w.at(x, y) != FREE {
                    assert_eq!(w.id(x, y), c.id([x, y]));
                }
            }
        }
    }
    // Distinct cells of a tile have distinct offsets.
    let mut offs: Vec<usize> = (0..TILE)
        .flat_map(|x| (0..TILE).map(move |y| offset(x, y)))
        .collect();
    offs.sort_unstable();
    offs.dedup();
    assert_eq!(offs.len(), CELLS);
    c.relocate([63, 64], [64, 64]);
    assert!(!c.occupied([63, 64]));
    assert_eq!(c.id([64, 64]), 12);
    c.relocate([0, 0], [1, 0]);
    assert_eq!(c.id([1, 0]), 10);
    assert_eq!(c.kind([1, 0]), kind_byte(false));
    for p in [[1, 0], [-1, -1], [64, 64], [64, 63], [-65, 130], [5, -200]] {
        c.clear(p);
    }
    assert!(c.is_empty());
    assert_eq!(c.len(), 0);
    assert!(c.window([i64::MAX, 0], 1).is_none());
    // Tiles far apart: the directory covers some, the map the rest; all are found, and
    // a tile that empties is gone from both.
    let far = [
        [3, 3],
        [1 << 40, 0],
        [-(1 << 40), 7],
        [5000, -9000],
        [i64::MAX - 5, i64::MIN + 3],
        [i64::MIN, i64::MAX],
    ];
    for (i, &p) in far.iter().enumerate() {
        c.set(p, kind_byte(i % 2 == 0), 100 + i as u64);
    }
    for (i, &p) in far.iter().enumerate() {
        assert_eq!(c.kind(p), kind_byte(i % 2 == 0), "{p:?}");
        assert_eq!(c.id(p), 100 + i as u64);
    }
    let w = c.window([5001, -9001], WINDOW_MAX).unwrap();
    assert_eq!(w.at(5000, -9000), kind_byte(false));
    assert_eq!(
        w.rows::<1>(4998, -9000)[0],
        u64::from(kind_byte(false) | c.bucket(103) << 2) << 16
    );
    for &p in &far {
        c.clear(p);
        assert!(!c.occupied(p));
    }
    assert!(c.is_empty());
    assert!(c.dir.iter().all(|&t| t == 0));
    assert_eq!(c.kind([i64::MAX, i64::MIN]), FREE);
}
