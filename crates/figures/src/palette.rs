//! Colours of the figures, chosen to be read by everyone: the Okabe-Ito categorical palette
//! (Okabe & Ito, "Color Universal Design", 2002/2008; recommended by Wong, "Points of view:
//! Color blindness", Nature Methods 2011) for species, clusters and the series of charts
//! (`figures::chart` takes its colours from [`OKABE_ITO`]), perceptual sequential maps
//! (viridis, magma: van der Walt & Smith, 2015) for ordered quantities such as arrival order,
//! each restricted to the part that stands out from the figure's background, and a colouring of
//! touching regions that gives neighbours different colours.
//!
//! Legibility is measured by the WCAG 2.1 contrast ratio of relative luminances; 3:1 is its
//! threshold for graphical objects, and every colour drawn on a background here meets it.

use std::collections::HashMap;

/// An sRGB colour, 8 bits per channel.
pub type Rgb = [u8; 3];

/// The Okabe-Ito palette, in its published order: black, orange, sky blue, bluish green,
/// yellow, blue, vermillion, reddish purple.
pub const OKABE_ITO: [Rgb; 8] = [
    [0, 0, 0],
    [230, 159, 0],
    [86, 180, 233],
    [0, 158, 115],
    [240, 228, 66],
    [0, 114, 178],
    [213, 94, 0],
    [204, 121, 167],
];

/// Foxes, in every figure (snapshots, animations, population curves): Okabe-Ito vermillion.
pub const FOX: Rgb = OKABE_ITO[6];
/// Rabbits, in every figure: Okabe-Ito blue.
pub const RABBIT: Rgb = OKABE_ITO[5];

/// White: the background of figures whose data are dark or saturated (DLA, animats).
pub const WHITE: Rgb = [255, 255, 255];
/// Black: the background of the cluster figures, whose categorical colours are light.
pub const BLACK: Rgb = [0, 0, 0];

/// The smallest contrast ratio of a colour drawn on a background (WCAG 2.1, non-text contrast).
pub const MIN_CONTRAST: f64 = 3.0;

/// Colours for regions on [`BLACK`] (DLCA clusters): the seven Okabe-Ito colours other than
/// black, then a light grey, each at least 4:1 against black.
pub const ON_BLACK: [Rgb; 8] = [
    OKABE_ITO[1],
    OKABE_ITO[2],
    OKABE_ITO[3],
    OKABE_ITO[4],
    OKABE_ITO[5],
    OKABE_ITO[6],
    OKABE_ITO[7],
    [187, 187, 187],
];

/// WCAG 2.1 relative luminance of an sRGB colour, 0 (black) to 1 (white).
pub fn relative_luminance(c: Rgb) -> f64 {
    let lin = |v: u8| {
        let s = f64::from(v) / 255.0;
        if s <= 0.04045 {
            s / 12.92
        } else {
            ((s + 0.055) / 1.055).powf(2.4)
        }
    };
    0.2126 * lin(c[0]) + 0.7152 * lin(c[1]) + 0.0722 * lin(c[2])
}

/// WCAG 2.1 contrast ratio of two colours, 1 (equal luminance) to 21 (black on white).
pub fn contrast(a: Rgb, b: Rgb) -> f64 {
    let (la, lb) = (relative_luminance(a), relative_luminance(b));
    (la.max(lb) + 0.05) / (la.min(lb) + 0.05)
}

/// A sequential colour map, restricted to the sub-range `[lo, hi]` of the full map whose
/// colours all stand out from a background by at least [`MIN_CONTRAST`].
#[derive(Debug, Clone, Copy)]
pub struct Sequential {
    gradient: colorous::Gradient,
    name: &'static str,
    lo: f64,
    hi: f64,
}

impl Sequential {
    /// Magma restricted to the colours legible on white (from black through purple to red).
    pub fn magma_on_white() -> Self {
        Self::legible_on(colorous::MAGMA, "magma", WHITE)
    }

    /// Viridis restricted to the colours legible on black (from blue through green to yellow).
    pub fn viridis_on_black() -> Self {
        Self::legible_on(colorous::VIRIDIS, "viridis", BLACK)
    }

    /// The longest run of `gradient`'s colours (sampled at 1/1024 steps) whose contrast with
    /// `background` is at least [`MIN_CONTRAST`].
    pub fn legible_on(gradient: colorous::Gradient, name: &'static str, background: Rgb) -> Self {
        const STEPS: usize = 1024;
        let ok = |i: usize| {
            let c = gradient.eval_continuous(i as f64 / STEPS as f64);
            contrast([c.r, c.g, c.b], background) >= MIN_CONTRAST
        };
        let (mut best, mut start) = ((0, 0), None);
        for i in 0..=STEPS + 1 {
            match (i <= STEPS && ok(i), start) {
                (true, None) => start = Some(i),
                (false, Some(s)) => {
                    if i - s > best.1 - best.0 {
                        best = (s, i);
                    }
                    start = None;
                }
                _ => {}
            }
        }
        assert!(
            best.1 > best.0,
            "{name} has no colour legible on {background:?}"
        );
        Sequential {
            gradient,
            name,
            lo: best.0 as f64 / STEPS as f64,
            hi: (best.1 - 1) as f64 / STEPS as f64,
        }
    }

    /// The colour of `t` in `[0, 1]` (clamped): the map's `lo` at 0, its `hi` at 1.
    pub fn at(&self, t: f64) -> Rgb {
        let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
        let c = self
            .gradient
            .eval_continuous(self.lo + t * (self.hi - self.lo));
        [c.r, c.g, c.b]
    }

    /// The map's name (`magma`) and the part of it used, for captions and documents.
    pub fn describe(&self) -> String {
        format!("{} {:.2} to {:.2}", self.name, self.lo, self.hi)
    }

    /// A table of `n` colours (at least 2) from 0 to 1, for drawing many pixels quickly.
    pub fn table(&self, n: usize) -> Vec<Rgb> {
        let n = n.max(2);
        (0..n).map(|i| self.at(i as f64 / (n - 1) as f64)).collect()
    }
}

/// Colours of the regions of a label image (row-major, `width` pixels a row, `empty` where
/// there is none) such that neighbouring regions get different colours from a palette of
/// `colours` entries. Regions are neighbours when, each grown by up to `reach` pixels into the
/// empty pixels around it (breadth first, so an empty pixel goes to the nearest region), they
/// meet: regions that touch, and regions less than about `2 reach` pixels apart with no other
/// region between them. (Regions that never touch, such as DLCA clusters, which merge on
/// contact, need a `reach` of several pixels to be told apart.)
///
/// Greedy colouring in smallest-last order (Matula & Beck, "Smallest-last ordering and
/// clustering and graph coloring algorithms", 1983): it needs at most one colour more than the
/// graph's degeneracy, which is at most 5 for a planar map (and the grown regions form one but
/// for pixel corners), so 7 colours suffice in practice. `prefer` names a colour a region
/// should keep if no neighbour has it (the colour it had in the previous frame of an
/// animation). Should every colour be taken by a neighbour, the region gets the one its
/// neighbours use least; the second value counts such regions.
pub fn colour_regions(
    labels: &[u32],
    width: usize,
    empty: u32,
    reach: usize,
    colours: usize,
    prefer: impl Fn(u32) -> Option<usize>,
) -> (HashMap<u32, usize>, usize) {
    assert!(colours > 0 && width > 0);
    let mut ids: Vec<u32> = labels.iter().copied().filter(|&l| l != empty).collect();
    ids.sort_unstable();
    ids.dedup();
    let index: HashMap<u32, usize> = ids.iter().enumerate().map(|(i, &id)| (id, i)).collect();
    let height = labels.len() / width;
    // Grow every region into the empty pixels, breadth first, `reach` steps at most.
    let mut owner = labels.to_vec();
    let mut queue: std::collections::VecDeque<(usize, usize)> = owner
        .iter()
        .enumerate()
        .filter(|(_, l)| **l != empty)
        .map(|(at, _)| (at, 0))
        .collect();
    while let Some((at, d)) = queue.pop_front() {
        if d >= reach {
            continue;
        }
        let (x, y) = (at % width, at / width);
        for (dx, dy) in [
            (-1i64, -1i64),
            (0, -1),
            (1, -1),
            (-1, 0),
            (1, 0),
            (-1, 1),
            (0, 1),
            (1, 1),
        ] {
            let (nx, ny) = (x as i64 + dx, y as i64 + dy);
            if nx < 0 || ny < 0 || nx >= width as i64 || ny >= height as i64 {
                continue;
            }
            let n = ny as usize * width + nx as usize;
            if owner[n] == empty {
                owner[n] = owner[at];
                queue.push_back((n, d + 1));
            }
        }
    }
    let labels = &owner;
    let mut edges: Vec<(usize, usize)> = Vec::new();
    let mut link = |a: u32, b: u32| {
        if a != b && a != empty && b != empty {
            let (i, j) = (index[&a], index[&b]);
            edges.push((i.min(j), i.max(j)));
        }
    };
    for y in 0..height {
        for x in 0..width {
            let a = labels[y * width + x];
            if a == empty {
                continue;
            }
            if x + 1 < width {
                link(a, labels[y * width + x + 1]);
            }
            if y + 1 < height {
                link(a, labels[(y + 1) * width + x]);
                if x + 1 < width {
                    link(a, labels[(y + 1) * width + x + 1]);
                }
                if x > 0 {
                    link(a, labels[(y + 1) * width + x - 1]);
                }
            }
        }
    }
    edges.sort_unstable();
    edges.dedup();
    let n = ids.len();
    let mut adj: Vec<Vec<usize>> = vec![Vec::new(); n];
    for &(i, j) in &edges {
        adj[i].push(j);
        adj[j].push(i);
    }
    // Smallest-last order: repeatedly remove a vertex of least remaining degree (ties by index,
    // so the colouring is deterministic); colour in the reverse order of removal.
    let mut degree: Vec<usize> = adj.iter().map(Vec::len).collect();
    let mut removed = vec![false; n];
    let mut heap: std::collections::BinaryHeap<std::cmp::Reverse<(usize, usize)>> =
        (0..n).map(|i| std::cmp::Reverse((degree[i], i))).collect();
    let mut order = Vec::with_capacity(n);
    while let Some(std::cmp::Reverse((d, i))) = heap.pop() {
        if removed[i] || d != degree[i] {
            continue;
        }
        removed[i] = true;
        order.push(i);
        for &j in &adj[i] {
            if !removed[j] {
                degree[j] -= 1;
                heap.push(std::cmp::Reverse((degree[j], j)));
            }
        }
    }
    let mut colour = vec![usize::MAX; n];
    let mut clashes = 0;
    let mut used = vec![0usize; colours];
    for &i in order.iter().rev() {
        used.iter_mut().for_each(|u| *u = 0);
        for &j in &adj[i] {
            if colour[j] != usize::MAX {
                used[colour[j]] += 1;
            }
        }
        colour[i] = match prefer(ids[i]).filter(|&c| c < colours && used[c] == 0) {
            Some(c) => c,
            None => match used.iter().position(|&u| u == 0) {
                Some(c) => c,
                None => {
                    clashes += 1;
                    (0..colours).min_by_key(|&c| (used[c], c)).unwrap_or(0)
                }
            },
        };
    }
    (
        ids.iter().zip(colour).map(|(&id, c)| (id, c)).collect(),
        clashes,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn okabe_ito_is_the_published_palette() {
        // Okabe & Ito (2008), as hex: 000000 E69F00 56B4E9 009E73 F0E442 0072B2 D55E00 CC79A7.
        let hex: Vec<String> = OKABE_ITO
            .iter()
            .map(|c| format!("{:02X}{:02X}{:02X}", c[0], c[1], c[2]))
            .collect();
        assert_eq!(
            hex,
            [
                "000000", "E69F00", "56B4E9", "009E73", "F0E442", "0072B2", "D55E00", "CC79A7"
            ]
        );
        assert_ne!(FOX, RABBIT);
    }

    #[test]
    fn contrast_matches_the_wcag_definition() {
        assert!((contrast(BLACK, WHITE) - 21.0).abs() < 1e-9);
        assert!((contrast(WHITE, WHITE) - 1.0).abs() < 1e-12);
        // #777777 on white is the classic just-below-4.5 example (4.48).
        assert!((contrast([119, 119, 119], WHITE) - 4.48).abs() < 0.01);
    }

    #[test]
    fn every_colour_stands_out_from_its_background() {
        for c in ON_BLACK {
            assert!(contrast(c, BLACK) >= 4.0, "{c:?}");
        }
        for c in [FOX, RABBIT] {
            assert!(contrast(c, WHITE) >= MIN_CONTRAST, "{c:?}");
        }
        for (map, bg) in [
            (Sequential::magma_on_white(), WHITE),
            (Sequential::viridis_on_black(), BLACK),
        ] {
            for c in map.table(256) {
                assert!(contrast(c, bg) >= MIN_CONTRAST, "{} {c:?}", map.describe());
            }
            // Most of the map is kept, and its two ends differ clearly.
            assert!(map.hi - map.lo > 0.5, "{}", map.describe());
            assert!(
                contrast(map.at(0.0), map.at(1.0)) > 2.0,
                "{}",
                map.describe()
            );
        }
    }

    #[test]
    fn touching_regions_get_different_colours() {
        // A 3 x 3 checkerboard of 9 regions: every region touches its 8-neighbours.
        let w = 9;
        let labels: Vec<u32> = (0..w * w)
            .map(|i| ((i / w) / 3 * 3 + (i % w) / 3) as u32)
            .collect();
        let (c, clashes) = colour_regions(&labels, w, u32::MAX, 0, 8, |_| None);
        assert_eq!(clashes, 0);
        for y in 0..w {
            for x in 0..w {
                let a = labels[y * w + x];
                for (dx, dy) in [(1, 0), (0, 1), (1, 1)] {
                    if x + dx < w && y + dy < w {
                        let b = labels[(y + dy) * w + x + dx];
                        if a != b {
                            assert_ne!(c[&a], c[&b], "{a} {b}");
                        }
                    }
                }
            }
        }
        // A preferred colour is kept when free.
        let (c2, _) = colour_regions(&labels, w, u32::MAX, 0, 8, |id| (id == 4).then_some(7));
        assert_eq!(c2[&4], 7);
        // Too few colours: the clash is counted, never hidden.
        let (_, clashes) = colour_regions(&labels, w, u32::MAX, 0, 2, |_| None);
        assert!(clashes > 0);
        // Two dots 5 pixels apart are neighbours when grown by 2 pixels (they meet in the
        // middle of the 4 empty pixels), not by 1.
        let mut dots = vec![u32::MAX; 20];
        dots[2] = 1;
        dots[7] = 2;
        for (reach, apart) in [(1, false), (2, true)] {
            let (c, _) = colour_regions(&dots, 20, u32::MAX, reach, 8, |_| Some(0));
            assert_eq!(c[&1] != c[&2], apart, "reach {reach}");
        }
    }
}
