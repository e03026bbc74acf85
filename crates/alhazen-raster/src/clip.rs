//! Clipping (course, §"Line clipping", §"Liang-Barsky algorithm", §"Clipping polygons").

use alhazen_math::{Vec2, Vec4};

/// An axis-aligned clipping window `[xmin, xmax] × [ymin, ymax]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Window {
    /// Left.
    pub xmin: f64,
    /// Right.
    pub xmax: f64,
    /// Bottom.
    pub ymin: f64,
    /// Top.
    pub ymax: f64,
}

const LEFT: u8 = 1;
const RIGHT: u8 = 2;
const BOTTOM: u8 = 4;
const TOP: u8 = 8;

impl Window {
    /// The Cohen–Sutherland outcode of `p`.
    pub fn outcode(&self, p: Vec2) -> u8 {
        let mut c = 0;
        if p.x < self.xmin {
            c |= LEFT;
        } else if p.x > self.xmax {
            c |= RIGHT;
        }
        if p.y < self.ymin {
            c |= BOTTOM;
        } else if p.y > self.ymax {
            c |= TOP;
        }
        c
    }

    /// True when `p` is inside or on the border.
    pub fn contains(&self, p: Vec2) -> bool {
        self.outcode(p) == 0
    }
}

/// Cohen–Sutherland: trivially accept (both codes 0), trivially reject (common bit), otherwise cut
/// at one border the outside end point crosses and repeat.
pub fn cohen_sutherland(w: &Window, mut a: Vec2, mut b: Vec2) -> Option<(Vec2, Vec2)> {
    for _ in 0..8 {
        let (ca, cb) = (w.outcode(a), w.outcode(b));
        if ca | cb == 0 {
            return Some((a, b));
        }
        if ca & cb != 0 {
            return None;
        }
        let (out, p, q) = if ca != 0 { (ca, a, b) } else { (cb, b, a) };
        let d = q - p;
        let cut = if out & TOP != 0 {
            Vec2::new(p.x + d.x * (w.ymax - p.y) / d.y, w.ymax)
        } else if out & BOTTOM != 0 {
            Vec2::new(p.x + d.x * (w.ymin - p.y) / d.y, w.ymin)
        } else if out & RIGHT != 0 {
            Vec2::new(w.xmax, p.y + d.y * (w.xmax - p.x) / d.x)
        } else {
            Vec2::new(w.xmin, p.y + d.y * (w.xmin - p.x) / d.x)
        };
        if ca != 0 { a = cut } else { b = cut }
    }
    None
}

/// Liang–Barsky: the parameter interval `[t0, t1] ⊂ [0, 1]` of `a + t (b − a)` inside the window,
/// from the four inequalities `t·p_k ≤ q_k`.
pub fn liang_barsky(w: &Window, a: Vec2, b: Vec2) -> Option<(Vec2, Vec2)> {
    let d = b - a;
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [(-d.x, a.x - w.xmin), (d.x, w.xmax - a.x), (-d.y, a.y - w.ymin), (d.y, w.ymax - a.y)] {
        if !lb_test(p, q, &mut t0, &mut t1) {
            return None;
        }
    }
    (t0 <= t1).then(|| (a + d * t0, a + d * t1))
}

/// The course's `LBTest` for one inequality `t·p ≤ q`: narrows `[t0, t1]`; false when the
/// segment lies wholly outside (parallel to the boundary and beyond it).
#[inline]
fn lb_test(p: f64, q: f64, t0: &mut f64, t1: &mut f64) -> bool {
    if p == 0.0 {
        return q >= 0.0;
    }
    let r = q / p;
    if p < 0.0 {
        *t0 = t0.max(r)
    } else {
        *t1 = t1.min(r)
    }
    true
}

/// Liang–Barsky in homogeneous coordinates (course: "the algorithms may easily be modified to
/// work using homogeneous coordinates"): the parameter interval `[t0, t1] ⊂ [0, 1]` of
/// `a + t (b − a)` inside the clip volume `−w ≤ x, y, z ≤ w`, i.e. the six half-spaces
/// `w ± x ≥ 0`, `w ± y ≥ 0`, `w ± z ≥ 0` — linear in `t`, so each is one Liang–Barsky test and no
/// division by `w` happens before clipping. Points in the volume have `w ≥ 0`.
pub fn liang_barsky_homogeneous(a: Vec4, b: Vec4) -> Option<(f64, f64)> {
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for axis in 0..3 {
        for sign in [1.0, -1.0] {
            // d(t) = d0 + t (d1 − d0) ≥ 0 with d = w + sign·coordinate.
            let (d0, d1) = (a.w + sign * a[axis], b.w + sign * b[axis]);
            if !lb_test(d0 - d1, d0, &mut t0, &mut t1) {
                return None;
            }
        }
    }
    (t0 <= t1).then_some((t0, t1))
}

/// Sutherland–Hodgman: the polygon clipped by each half-plane of a convex, counter-clockwise
/// `clipper` in turn. The result may have zero-length edges where the polygon touches a border;
/// an empty result means no overlap.
pub fn sutherland_hodgman(polygon: &[Vec2], clipper: &[Vec2]) -> Vec<Vec2> {
    let mut out = polygon.to_vec();
    for k in 0..clipper.len() {
        if out.is_empty() {
            break;
        }
        let (e0, e1) = (clipper[k], clipper[(k + 1) % clipper.len()]);
        let inside = |p: Vec2| (e1 - e0).perp_dot(p - e0) >= 0.0;
        let cross = |p: Vec2, q: Vec2| {
            let (dp, dq) = ((e1 - e0).perp_dot(p - e0), (e1 - e0).perp_dot(q - e0));
            p + (q - p) * (dp / (dp - dq))
        };
        let input = std::mem::take(&mut out);
        for i in 0..input.len() {
            let (p, q) = (input[i], input[(i + 1) % input.len()]);
            match (inside(p), inside(q)) {
                (true, true) => out.push(q),
                (true, false) => out.push(cross(p, q)),
                (false, true) => {
                    out.push(cross(p, q));
                    out.push(q);
                }
                (false, false) => {}
            }
        }
    }
    out
}

/// The signed area of a polygon (positive for counter-clockwise).
pub fn signed_area(p: &[Vec2]) -> f64 {
    (0..p.len()).map(|i| p[i].perp_dot(p[(i + 1) % p.len()])).sum::<f64>() / 2.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    const W: Window = Window { xmin: -1.0, xmax: 2.0, ymin: -0.5, ymax: 1.5 };

    fn arb_point() -> impl Strategy<Value = Vec2> {
        (-4.0..4.0f64, -4.0..4.0f64).prop_map(|(x, y)| Vec2::new(x, y))
    }

    fn arb_homogeneous() -> impl Strategy<Value = Vec4> {
        (-3.0..3.0f64, -3.0..3.0f64, -3.0..3.0f64, -0.5..2.5f64).prop_map(|(x, y, z, w)| Vec4::new(x, y, z, w))
    }

    proptest! {
        #[test]
        fn homogeneous_clipping_agrees_with_brute_force(a in arb_homogeneous(), b in arb_homogeneous()) {
            let inside = |t: f64| {
                let p = a + (b - a) * t;
                p.x.abs() <= p.w && p.y.abs() <= p.w && p.z.abs() <= p.w
            };
            let n = 4000;
            let samples: Vec<f64> = (0..=n).map(|i| i as f64 / n as f64).filter(|t| inside(*t)).collect();
            match liang_barsky_homogeneous(a, b) {
                None => prop_assert!(samples.len() <= 1, "{} samples inside", samples.len()),
                Some((t0, t1)) => {
                    // The volume is convex: inside samples form exactly the interval.
                    let h = 1.0 / n as f64;
                    if let (Some(first), Some(last)) = (samples.first(), samples.last()) {
                        prop_assert!((first - t0).abs() <= h + 1e-9 && (last - t1).abs() <= h + 1e-9, "[{t0}, {t1}] vs [{first}, {last}]");
                    } else {
                        prop_assert!(t1 - t0 <= h);
                    }
                    for t in [t0, (t0 + t1) / 2.0, t1] {
                        let p = a + (b - a) * t;
                        let tol = 1e-9 * (1.0 + p.abs().max_element());
                        prop_assert!(p.x.abs() <= p.w + tol && p.y.abs() <= p.w + tol && p.z.abs() <= p.w + tol);
                    }
                }
            }
        }

        #[test]
        fn segment_clipping_agrees_with_brute_force(a in arb_point(), b in arb_point()) {
            let cs = cohen_sutherland(&W, a, b);
            let lb = liang_barsky(&W, a, b);
            // Brute force: the inside part of densely sampled points.
            let inside: Vec<f64> = (0..=4000).map(|k| k as f64 / 4000.0).filter(|t| W.contains(a + (b - a) * *t)).collect();
            match (cs, lb) {
                (Some((p, q)), Some((r, s))) => {
                    prop_assert!(W.contains(p) && W.contains(q), "clipped ends lie in the window");
                    let len = (q - p).length();
                    prop_assert!((len - (s - r).length()).abs() < 1e-9);
                    if let (Some(&t0), Some(&t1)) = (inside.first(), inside.last()) {
                        prop_assert!((len - (t1 - t0) * (b - a).length()).abs() <= 2.0 * (b - a).length() / 4000.0 + 1e-9);
                    }
                }
                (None, None) => prop_assert!(inside.len() <= 1),
                (x, y) => prop_assert!(inside.len() <= 1, "{x:?} vs {y:?}"),
            }
        }

        #[test]
        fn polygon_clipping_area_matches_sampling(pts in prop::collection::vec(arb_point(), 3..8)) {
            // A convex polygon: the hull of random points, counter-clockwise.
            let hull = convex_hull(&pts);
            prop_assume!(hull.len() >= 3);
            let window = [Vec2::new(W.xmin, W.ymin), Vec2::new(W.xmax, W.ymin), Vec2::new(W.xmax, W.ymax), Vec2::new(W.xmin, W.ymax)];
            let clipped = sutherland_hodgman(&hull, &window);
            let area = if clipped.len() >= 3 { signed_area(&clipped) } else { 0.0 };
            // Sample the window on a grid and count points inside the hull.
            let n = 300;
            let mut count = 0;
            for i in 0..n {
                for j in 0..n {
                    let p = Vec2::new(W.xmin + (W.xmax - W.xmin) * (i as f64 + 0.5) / n as f64, W.ymin + (W.ymax - W.ymin) * (j as f64 + 0.5) / n as f64);
                    if (0..hull.len()).all(|k| (hull[(k + 1) % hull.len()] - hull[k]).perp_dot(p - hull[k]) >= 0.0) {
                        count += 1;
                    }
                }
            }
            let sampled = count as f64 / (n * n) as f64 * (W.xmax - W.xmin) * (W.ymax - W.ymin);
            prop_assert!((area - sampled).abs() < 0.05, "{area} vs {sampled}");
        }
    }

    fn convex_hull(pts: &[Vec2]) -> Vec<Vec2> {
        let mut p = pts.to_vec();
        p.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
        let mut lower: Vec<Vec2> = vec![];
        for &q in &p {
            while lower.len() >= 2
                && (lower[lower.len() - 1] - lower[lower.len() - 2]).perp_dot(q - lower[lower.len() - 2]) <= 0.0
            {
                lower.pop();
            }
            lower.push(q);
        }
        let mut upper: Vec<Vec2> = vec![];
        for &q in p.iter().rev() {
            while upper.len() >= 2
                && (upper[upper.len() - 1] - upper[upper.len() - 2]).perp_dot(q - upper[upper.len() - 2]) <= 0.0
            {
                upper.pop();
            }
            upper.push(q);
        }
        lower.pop();
        upper.pop();
        lower.extend(upper);
        lower
    }
}
