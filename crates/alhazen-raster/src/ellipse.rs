//! Ellipses (course, §"Rasterisation algorithms"): the integer midpoint algorithm for ellipses
//! with axes along the raster, and the recursive subdivision of an ellipse given by its centre
//! and two conjugate half-axes (`r_Ellipse`).

use alhazen_math::Vec2;

/// The pixels of the ellipse `x²/a² + y²/b² = 1` centred at `(cx, cy)` by the midpoint method,
/// integers only. An ellipse has just two axes of symmetry, so — as the course says — two eighths
/// are traced separately: from `(0, b)` stepping `x` (one pixel per column) while the slope is
/// above −1, and from `(a, 0)` stepping `y` (one pixel per row); in each, the sign of
/// `4F = 4b²x² + a²(2y − 1)² − 4a²b²` at the midpoint between two candidates picks the nearer.
/// The quadrant is then mirrored four ways.
pub fn midpoint_ellipse((cx, cy): (i64, i64), a: i64, b: i64) -> Vec<(i64, i64)> {
    if a < 0 || b < 0 {
        return vec![];
    }
    // A flat ellipse is the segment between its vertices.
    if a == 0 || b == 0 {
        return if b == 0 {
            (-a..=a).map(|x| (cx + x, cy)).collect()
        } else {
            (-b..=b).map(|y| (cx, cy + y)).collect()
        };
    }
    let mut quadrant = eighth(a, b);
    quadrant.extend(eighth(b, a).into_iter().map(|(y, x)| (x, y)));
    let mut out = Vec::with_capacity(quadrant.len() * 4);
    let mut seen = std::collections::HashSet::new();
    for &(px, py) in &quadrant {
        for (sx, sy) in [(px, py), (-px, py), (px, -py), (-px, -py)] {
            if seen.insert((sx, sy)) {
                out.push((cx + sx, cy + sy));
            }
        }
    }
    out
}

/// Column by column from `(0, b)`: the pixel nearest the curve in each column, up to the column
/// of the point where the slope is −1 (`x² (a² + b²) ≤ a⁴`).
fn eighth(a: i64, b: i64) -> Vec<(i64, i64)> {
    let (a2, b2) = (a * a, b * b);
    // 4F at the midpoint (x, y − ½): positive when the midpoint is outside.
    let f = |x: i64, y: i64| 4 * b2 * x * x + a2 * (2 * y - 1) * (2 * y - 1) - 4 * a2 * b2;
    let (mut x, mut y) = (0i64, b);
    let mut out = vec![];
    while x * x * (a2 + b2) <= a2 * a2 {
        while y > 0 && f(x, y) > 0 {
            y -= 1;
        }
        out.push((x, y));
        x += 1;
    }
    out
}

/// A closed polyline through points of the ellipse `s + cos φ · v0 + sin φ · v1` (`v0`, `v1`
/// conjugate half-axes), by the course's `r_Ellipse`: each arc between `p0` and `p1` (as vectors
/// from the centre) is halved by `p2 = (p0 + p1) / (2 cos(α/2))`, `α` the arc's angle on the unit
/// circle, until the chord is shorter than `tolerance` or `max_depth` halvings are made. The
/// factors `1/(2 cos(α_k/2))` are computed once per level. (The seed lists `c_i = cos(π/2^{i+1})`
/// and divides by `c`; the midpoint of an arc of angle α needs `2 cos(α/2)`, checked by the test.)
pub fn conjugate_ellipse(s: Vec2, v0: Vec2, v1: Vec2, tolerance: f64, max_depth: usize) -> Vec<Vec2> {
    // Level k halves arcs of angle (π/2)/2^k.
    let factors: Vec<f64> =
        (0..max_depth).map(|k| 1.0 / (2.0 * (std::f64::consts::FRAC_PI_2 / (1u64 << (k + 1)) as f64).cos())).collect();
    let mut out = vec![];
    let quarter = [v0, v1, -v0, -v1, v0];
    for w in quarter.windows(2) {
        arc(w[0], w[1], 0, &factors, tolerance, &mut out);
    }
    out.iter().map(|p| s + *p).collect()
}

fn arc(p0: Vec2, p1: Vec2, k: usize, factors: &[f64], tolerance: f64, out: &mut Vec<Vec2>) {
    if k == factors.len() || (p1 - p0).length() <= tolerance {
        out.push(p0);
        return;
    }
    let p2 = (p0 + p1) * factors[k];
    arc(p0, p2, k + 1, factors, tolerance, out);
    arc(p2, p1, k + 1, factors, tolerance, out);
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn midpoint_ellipse_pixels_lie_within_half_a_pixel(a in 0i64..60, b in 0i64..60, cx in -50i64..50, cy in -50i64..50) {
            let px = midpoint_ellipse((cx, cy), a, b);
            prop_assert!(!px.is_empty());
            for &(x, y) in &px {
                // Midpoint rule: in its column (where x steps) or row (where y steps) the curve
                // passes within half a pixel.
                let (dx, dy) = (((x - cx) as f64).abs(), ((y - cy) as f64).abs());
                let (af, bf) = (a as f64, b as f64);
                let in_column = (dy - bf * (1.0 - (dx / af).powi(2)).max(0.0).sqrt()).abs();
                let in_row = (dx - af * (1.0 - (dy / bf).powi(2)).max(0.0).sqrt()).abs();
                prop_assert!(in_column.min(in_row) <= 0.5 + 1e-9 || a == 0 || b == 0, "({x},{y}) off by {in_column}, {in_row}");
            }
            // The curve is closed: every pixel has an 8-neighbour in the set, and the four axis
            // extremes are drawn.
            let set: std::collections::HashSet<_> = px.iter().copied().collect();
            for &(x, y) in &px {
                let n = (-1..=1).flat_map(|i| (-1..=1).map(move |j| (i, j))).filter(|&(i, j)| (i, j) != (0, 0) && set.contains(&(x + i, y + j))).count();
                prop_assert!(n >= 1 || px.len() == 1);
            }
            for p in [(cx + a, cy), (cx - a, cy), (cx, cy + b), (cx, cy - b)] {
                prop_assert!(set.contains(&p), "{p:?} missing");
            }
        }

        #[test]
        fn conjugate_half_axes_give_points_of_the_ellipse(
            v0x in -3.0..3.0f64, v0y in -3.0..3.0f64, v1x in -3.0..3.0f64, v1y in -3.0..3.0f64, tol in 0.01..0.5f64
        ) {
            let (v0, v1) = (Vec2::new(v0x, v0y), Vec2::new(v1x, v1y));
            prop_assume!(v0.perp_dot(v1).abs() > 0.1);
            let s = Vec2::new(1.0, -2.0);
            let pts = conjugate_ellipse(s, v0, v1, tol, 20);
            // Each point is s + cos φ v0 + sin φ v1 with cos² + sin² = 1.
            let det = v0.perp_dot(v1);
            for p in &pts {
                let q = *p - s;
                let cs = Vec2::new(q.perp_dot(v1), v0.perp_dot(q)) / det;
                prop_assert!((cs.length() - 1.0).abs() < 1e-12, "{p} → {cs}");
            }
            for w in pts.windows(2) {
                prop_assert!((w[1] - w[0]).length() <= tol + 1e-12);
            }
        }
    }

    #[test]
    fn a_circle_is_an_ellipse_with_equal_axes() {
        let mut e = midpoint_ellipse((0, 0), 10, 10);
        let mut c = crate::midpoint_circle((0, 0), 10);
        e.sort();
        c.sort();
        // Both are within half a pixel; they may differ in a few diagonal pixels.
        let same = e.iter().filter(|p| c.contains(p)).count();
        assert!(same * 10 >= e.len() * 9, "{same} of {}", e.len());
    }
}
