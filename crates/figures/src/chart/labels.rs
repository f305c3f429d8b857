//! Placing the point labels of a chart: each beside its point or on rings around it, where it
//! overlaps no other label, no marker and no legend.

/// A rectangle of pixels: left, top, right, bottom (right and bottom exclusive).
pub type Rect = (i32, i32, i32, i32);

/// Whether the rectangles `a` and `b` share a pixel.
pub(super) fn overlaps(a: Rect, b: Rect) -> bool {
    a.0 < b.2 && b.0 < a.2 && a.1 < b.3 && b.1 < a.3
}

/// Places labels of `sizes` (width, height in pixels) near their `anchors` (the points they
/// name) inside `area`, so that no two labels overlap and no label overlaps an `obstacle` (the
/// markers, the legend). Each label takes the first free spot: beside its point (upper right,
/// lower right, upper left, lower left), then on rings of growing radius around it (16 spots a
/// ring, the last ring a quarter of the area's larger side away). A label with no free spot is
/// left out (`None`) rather than drawn over another.
pub fn place_labels(
    anchors: &[(i32, i32)],
    sizes: &[(i32, i32)],
    obstacles: &[Rect],
    area: Rect,
) -> Vec<Option<Rect>> {
    let mut placed: Vec<Rect> = Vec::new();
    let inside = |r: Rect| r.0 >= area.0 && r.1 >= area.1 && r.2 <= area.2 && r.3 <= area.3;
    let reach = (area.2 - area.0).max(area.3 - area.1) / 4;
    anchors
        .iter()
        .zip(sizes)
        .map(|(&(ax, ay), &(w, h))| {
            let beside = [
                (ax + 6, ay - h - 2),
                (ax + 6, ay + 2),
                (ax - 6 - w, ay - h - 2),
                (ax - 6 - w, ay + 2),
            ];
            let step = h + 6;
            let rings = (1..)
                .map(|k| k * step)
                .take_while(|&r| r <= reach.max(step));
            let around = rings.flat_map(|r| {
                (0..16).map(move |j| {
                    let t = f64::from(j) * std::f64::consts::PI / 8.0;
                    let (cx, cy) = (
                        ax + (1.6 * f64::from(r) * t.cos()) as i32,
                        ay - (f64::from(r) * t.sin()) as i32,
                    );
                    (cx - w / 2, cy - h / 2)
                })
            });
            let spot = beside
                .into_iter()
                .chain(around)
                .map(|(x, y)| (x, y, x + w, y + h))
                .find(|&r| {
                    let padded = (r.0 - 2, r.1 - 2, r.2 + 2, r.3 + 2);
                    inside(r)
                        && !obstacles.iter().any(|&o| overlaps(padded, o))
                        && !placed.iter().any(|&p| overlaps(padded, p))
                });
            if let Some(r) = spot {
                placed.push(r);
            }
            spot
        })
        .collect()
}
