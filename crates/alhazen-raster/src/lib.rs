//! `alhazen-raster`: the raster side of the course (§"Rasterisation algorithms", §"Line
//! clipping", §"Clipping polygons"), the base of the preview pipeline of `alhazen view`.
//!
//! * [`bresenham_line`] — integer-only lines in all octants;
//! * [`midpoint_circle`] — integer-only circles (eight-way symmetry);
//! * [`ellipse`] — integer midpoint ellipses and the recursive conjugate-half-axes ellipse;
//! * [`clip`] — Cohen–Sutherland and Liang–Barsky segment clipping (also in homogeneous
//!   coordinates against the clip volume), Sutherland–Hodgman polygon clipping against a convex
//!   window;
//! * [`polygon_ops`] — Weiler–Atherton intersection, union and difference of polygons with holes;
//! * [`pipeline`] — the 3D pipeline of `alhazen raster`: transforms, homogeneous clipping,
//!   perspective-correct rasterisation with a z-buffer, flat/Gouraud/Phong shading;
//! * [`fill`] — scanline filling with an active edge table and exact pixel ownership.
//!
//! ```
//! let px = alhazen_raster::bresenham_line((0, 0), (5, 2));
//! assert_eq!(px, vec![(0, 0), (1, 0), (2, 1), (3, 1), (4, 2), (5, 2)]);
//! ```

pub mod clip;
pub mod ellipse;
pub mod fill;
pub mod pipeline;
pub mod polygon_ops;

/// The pixels of the segment between two pixel centres, by the course's Bresenham algorithm
/// generalised to all octants (the roles of `x` and `y` swap when `|Δy| > |Δx|`; increments take
/// the signs of the deltas). Integers only; both end points are included.
pub fn bresenham_line((x0, y0): (i64, i64), (x1, y1): (i64, i64)) -> Vec<(i64, i64)> {
    // Walk the major axis `a` one step at a time; the minor axis `b` steps when the integer error
    // term `c` (the course's numerator over 2Δa) turns positive.
    let steep = (y1 - y0).abs() > (x1 - x0).abs();
    let (a0, b0, a1, b1) = if steep { (y0, x0, y1, x1) } else { (x0, y0, x1, y1) };
    let (da, db) = ((a1 - a0).abs(), (b1 - b0).abs());
    let (g, h) = ((a1 - a0).signum(), (b1 - b0).signum());
    let (mut a, mut b, mut c) = (a0, b0, -da);
    let mut out = Vec::with_capacity(da as usize + 1);
    for _ in 0..=da {
        out.push(if steep { (b, a) } else { (a, b) });
        c += 2 * db;
        if c > 0 {
            b += h;
            c -= 2 * da;
        }
        a += g;
    }
    out
}

/// The pixels of the circle of integer radius `r` centred at `(cx, cy)` by the midpoint algorithm:
/// one octant is traced with an integer decision variable (`f = x² + y² − r²` at the midpoint
/// between the two candidate pixels) and mirrored eight ways. Duplicates on the diagonals and axes
/// are removed; order is by octant.
pub fn midpoint_circle((cx, cy): (i64, i64), r: i64) -> Vec<(i64, i64)> {
    if r <= 0 {
        return if r == 0 { vec![(cx, cy)] } else { vec![] };
    }
    let mut octant = vec![];
    let (mut x, mut y) = (0i64, r);
    // Decision at the midpoint (x + 1, y − ½), scaled by 4 to stay integral.
    let mut d = 5 - 4 * r;
    while x <= y {
        octant.push((x, y));
        if d > 0 {
            d += 8 * (x - y) + 20;
            y -= 1;
        } else {
            d += 8 * x + 12;
        }
        x += 1;
    }
    let mut out = Vec::with_capacity(octant.len() * 8);
    let mut seen = std::collections::HashSet::new();
    for &(a, b) in &octant {
        for (px, py) in [(a, b), (b, a), (-a, b), (-b, a), (a, -b), (b, -a), (-a, -b), (-b, -a)] {
            if seen.insert((px, py)) {
                out.push((cx + px, cy + py));
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn bresenham_picks_the_nearest_pixel_of_each_column_or_row(x0 in -50i64..50, y0 in -50i64..50, x1 in -50i64..50, y1 in -50i64..50) {
            let px = bresenham_line((x0, y0), (x1, y1));
            let (dx, dy) = ((x1 - x0) as f64, (y1 - y0) as f64);
            prop_assert_eq!(px.first().copied(), Some((x0, y0)));
            prop_assert_eq!(px.last().copied(), Some((x1, y1)));
            prop_assert_eq!(px.len() as i64, (x1 - x0).abs().max((y1 - y0).abs()) + 1);
            for w in px.windows(2) {
                // 8-connected, one step along the major axis.
                prop_assert!((w[1].0 - w[0].0).abs() <= 1 && (w[1].1 - w[0].1).abs() <= 1);
            }
            for &(x, y) in &px {
                // Distance along the minor axis from the ideal line is at most ½.
                let off = if dx.abs() >= dy.abs() {
                    if dx == 0.0 { 0.0 } else { (y as f64) - (y0 as f64 + dy * (x - x0) as f64 / dx) }
                } else {
                    (x as f64) - (x0 as f64 + dx * (y - y0) as f64 / dy)
                };
                prop_assert!(off.abs() <= 0.5 + 1e-12, "({x},{y}) off by {off}");
            }
        }

        #[test]
        fn midpoint_circle_pixels_are_within_half_a_pixel(r in 0i64..200, cx in -20i64..20, cy in -20i64..20) {
            let px = midpoint_circle((cx, cy), r);
            for &(x, y) in &px {
                let d = (((x - cx) as f64).powi(2) + ((y - cy) as f64).powi(2)).sqrt();
                prop_assert!((d - r as f64).abs() <= 0.5 + 1e-9 || r == 0, "({x},{y}) at {d}");
            }
            // Every column crossing of the circle's upper half has a pixel at the right height.
            for x in -r / 2..=r / 2 {
                let ideal = ((r * r - x * x) as f64).sqrt();
                prop_assert!(px.iter().any(|&(a, b)| a - cx == x && ((b - cy) as f64 - ideal).abs() <= 0.5 + 1e-9));
            }
        }
    }
}
