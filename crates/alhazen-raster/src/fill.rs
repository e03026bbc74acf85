//! Scanline polygon filling with an active edge table (course, §"Filling polygons"), with the
//! course's pixel ownership convention made exact: pixel `(x, y)` (centre at integer
//! coordinates) belongs to the polygon when the point `(x + ε, y − δ)`, `0 < δ ≪ ε`
//! infinitesimal, is inside — "points to the right of the centre are inside", and on a
//! horizontal edge "points below are inside". Every pixel of a plane tiled by polygons with
//! common edges then belongs to exactly one of them. Crossings are exact rationals.

/// The spans `(y, x_first, x_last)` (inclusive) of a polygon with integer vertices, by the
/// parity rule.
pub fn fill_polygon(vertices: &[(i64, i64)]) -> Vec<(i64, i64, i64)> {
    // Non-horizontal edges, lower end first, sorted by their lower end.
    let mut edges: Vec<((i64, i64), (i64, i64))> = (0..vertices.len())
        .map(|i| (vertices[i], vertices[(i + 1) % vertices.len()]))
        .filter(|(a, b)| a.1 != b.1)
        .map(|(a, b)| if a.1 < b.1 { (a, b) } else { (b, a) })
        .collect();
    edges.sort_by_key(|(a, _)| a.1);
    let (Some(y_min), Some(y_max)) = (edges.iter().map(|e| e.0.1).min(), edges.iter().map(|e| e.1.1).max()) else {
        return vec![];
    };
    let mut spans = vec![];
    let mut active: Vec<usize> = vec![];
    let mut next = 0;
    // Row y is sampled just below y: an edge is active when y0 < y ≤ y1 (the course rejects the
    // lower end point).
    for y in y_min + 1..=y_max {
        active.retain(|&e| edges[e].1.1 >= y);
        while next < edges.len() && edges[next].0.1 < y {
            if edges[next].1.1 >= y {
                active.push(next);
            }
            next += 1;
        }
        // Crossing x at height y as a rational (num, den), den > 0.
        let mut xs: Vec<(i64, i64)> = active
            .iter()
            .map(|&e| {
                let ((x0, y0), (x1, y1)) = edges[e];
                (x0 * (y1 - y0) + (y - y0) * (x1 - x0), y1 - y0)
            })
            .collect();
        xs.sort_by(|a, b| (a.0 as i128 * b.1 as i128).cmp(&(b.0 as i128 * a.1 as i128)));
        for pair in xs.chunks_exact(2) {
            // x + ε lies between the crossings ⇔ x_left ≤ x < x_right.
            let first = ceil_div(pair[0].0, pair[0].1);
            let last = ceil_div(pair[1].0, pair[1].1) - 1;
            if first <= last {
                spans.push((y, first, last));
            }
        }
    }
    spans
}

fn ceil_div(num: i64, den: i64) -> i64 {
    -((-num).div_euclid(den))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use std::collections::{HashMap, HashSet};

    fn pixels(poly: &[(i64, i64)]) -> Vec<(i64, i64)> {
        fill_polygon(poly).into_iter().flat_map(|(y, a, b)| (a..=b).map(move |x| (x, y))).collect()
    }

    #[test]
    fn a_square_owns_its_left_column_and_top_row() {
        // The square [0, 4]²: pixels x ∈ 0..4, y ∈ 1..=4.
        let px = pixels(&[(0, 0), (4, 0), (4, 4), (0, 4)]);
        assert_eq!(px.len(), 16);
        assert!(px.iter().all(|&(x, y)| (0..4).contains(&x) && (1..=4).contains(&y)));
    }

    proptest! {
        #[test]
        fn a_tessellated_plane_covers_every_pixel_exactly_once(jitter in prop::collection::vec((-2i64..=2, -2i64..=2), 49)) {
            // A 6×6 grid of cells 12 pixels wide, interior vertices jittered by up to 2 (too little
            // to fold a cell), each cell split along alternating diagonals: shared edges of every
            // slope, vertices on pixel centres.
            let v = |i: usize, j: usize| {
                let (dx, dy) = if i > 0 && i < 6 && j > 0 && j < 6 { jitter[i * 7 + j] } else { (0, 0) };
                (12 * i as i64 + dx, 12 * j as i64 + dy)
            };
            let mut count: HashMap<(i64, i64), u32> = HashMap::new();
            for i in 0..6 {
                for j in 0..6 {
                    let (a, b, c, d) = (v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1));
                    let tris = if (i + j) % 2 == 0 { [[a, b, c], [a, c, d]] } else { [[a, b, d], [b, c, d]] };
                    for t in tris {
                        for p in pixels(&t) {
                            *count.entry(p).or_default() += 1;
                        }
                    }
                }
            }
            prop_assert!(count.values().all(|&c| c == 1), "a pixel was drawn twice");
            let outer: HashSet<_> = pixels(&[(0, 0), (72, 0), (72, 72), (0, 72)]).into_iter().collect();
            prop_assert_eq!(count.len(), outer.len(), "no pixel left out");
            prop_assert!(count.keys().all(|p| outer.contains(p)));
        }
    }
}
