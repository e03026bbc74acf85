//! Constructions of curves and surfaces (course, §"Some constructions of surfaces"): cubic
//! B-spline interpolation, lofting through curves, swept surfaces with auxiliary guides, and
//! spherical products (surfaces of revolution) of rational curves.

use crate::bezier::ControlPoint;
use crate::bspline::BSpline;
use crate::patch::{BSplinePatch, Net};
use alhazen_math::{Vec3, Vec4};

/// The clamped cubic B-spline through `q_0 … q_K` at parameters `t_0 < … < t_K`, with end
/// tangents estimated from the neighbouring points (Bessel), so that the system for the remaining
/// control points is the tridiagonal collocation system `N³_{k−1}(t) d_{k−1} + N³_k(t) d_k +
/// N³_{k+1}(t) d_{k+1} = q` of the course (the course leaves `d₁` and `d_{N−5}` free: they are
/// fixed here by the end tangents). `None` for fewer than 2 points or non-increasing parameters.
pub fn interpolate_cubic<P: ControlPoint>(q: &[P], t: &[f64]) -> Option<BSpline<P>> {
    let k = q.len().checked_sub(1)?;
    if k == 0 || t.len() != q.len() || t.windows(2).any(|w| w[1] <= w[0] || !w[1].is_finite()) {
        return None;
    }
    let mut knots = vec![t[0]; 4];
    knots.extend_from_slice(&t[1..k]);
    knots.extend(std::iter::repeat_n(t[k], 4));
    // End tangents by finite differences (a parabola through three points where available).
    let tangent = |i0: usize, i1: usize| (q[i1] - q[i0]) * (1.0 / (t[i1] - t[i0]));
    let (d_start, d_end) = (tangent(0, 1.min(k)), tangent(k - 1, k));
    let n = k + 3;
    let mut d = vec![q[0]; n];
    d[0] = q[0];
    d[n - 1] = q[k];
    d[1] = q[0] + d_start * ((t[1] - t[0]) / 3.0);
    d[n - 2] = q[k] - d_end * ((t[k] - t[k - 1]) / 3.0);
    if k >= 2 {
        // Unknowns d_2 … d_{n−3}; equation i (1 ≤ i ≤ k−1): s(t_i) = q_i involves d_i, d_{i+1}, d_{i+2}.
        // The basis alone, from a spline with dummy control points.
        let shape = BSpline::new(3, knots.clone(), vec![Vec3::ZERO; n]).ok()?;
        let basis = |j: usize, x: f64| Some(shape.basis(j, x));
        let m = k - 1;
        let (mut lo, mut di, mut up, mut rhs) = (vec![0.0; m], vec![0.0; m], vec![0.0; m], vec![q[0] * 0.0; m]);
        for e in 0..m {
            let i = e + 1;
            let (a, b, c) = (basis(i, t[i])?, basis(i + 1, t[i])?, basis(i + 2, t[i])?);
            let mut r = q[i];
            // Move the known neighbours to the right-hand side.
            if e == 0 {
                r = r - d[1] * a;
            } else {
                lo[e] = a;
            }
            if e == m - 1 {
                r = r - d[n - 2] * c;
            } else {
                up[e] = c;
            }
            di[e] = b;
            rhs[e] = r;
        }
        // Thomas algorithm (the collocation matrix is totally positive: no pivoting needed).
        for e in 1..m {
            let w = lo[e] / di[e - 1];
            di[e] -= w * up[e - 1];
            rhs[e] = rhs[e] - rhs[e - 1] * w;
        }
        let mut x = vec![q[0] * 0.0; m];
        x[m - 1] = rhs[m - 1] * (1.0 / di[m - 1]);
        for e in (0..m - 1).rev() {
            x[e] = (rhs[e] - x[e + 1] * up[e]) * (1.0 / di[e]);
        }
        d[2..2 + m].copy_from_slice(&x);
    }
    BSpline::new(3, knots, d).ok()
}

/// Chord-length parameters for points (0 at the first, the cumulative distance after).
pub fn chord_lengths<P: ControlPoint>(q: &[P]) -> Vec<f64> {
    let mut t = vec![0.0];
    for w in q.windows(2) {
        t.push(t.last().copied().unwrap_or(0.0) + (w[1] - w[0]).norm().max(1e-12));
    }
    t
}

/// Lofting (skinning): the bicubic-by-`m` B-spline patch through the curves `curves[i]` at
/// `u = t[i]`. All curves must share degree and knots (the course's assumption); each column of
/// the control net is interpolated like a point.
pub fn loft(curves: &[BSpline<Vec3>], t: &[f64]) -> Option<BSplinePatch<Vec3>> {
    let first = curves.first()?;
    if curves.iter().any(|c| c.degree() != first.degree() || c.knots() != first.knots()) {
        return None;
    }
    let cols = first.points().len();
    let columns: Vec<BSpline<Vec3>> = (0..cols)
        .map(|j| interpolate_cubic(&curves.iter().map(|c| c.points()[j]).collect::<Vec<_>>(), t))
        .collect::<Option<_>>()?;
    let rows = columns[0].points().len();
    let points = (0..rows).flat_map(|i| columns.iter().map(move |c| c.points()[i])).collect();
    BSplinePatch::new(
        3,
        first.degree(),
        columns[0].knots().to_vec(),
        first.knots().to_vec(),
        Net::new(rows, cols, points)?,
    )
    .ok()
}

/// The swept surface with guide `p` and auxiliary guides `x1, x2, x3` (same degree and knots) and
/// cross-section `q`: control points `d_ij = x1_i x_q_j + x2_i y_q_j + x3_i z_q_j + p_i`.
pub fn sweep(p: &BSpline<Vec3>, x: [&BSpline<Vec3>; 3], q: &BSpline<Vec3>) -> Option<BSplinePatch<Vec3>> {
    if x.iter().any(|g| g.knots() != p.knots() || g.degree() != p.degree()) {
        return None;
    }
    let (rows, cols) = (p.points().len(), q.points().len());
    let mut pts = Vec::with_capacity(rows * cols);
    for i in 0..rows {
        for qj in q.points() {
            pts.push(x[0].points()[i] * qj.x + x[1].points()[i] * qj.y + x[2].points()[i] * qj.z + p.points()[i]);
        }
    }
    BSplinePatch::new(p.degree(), q.degree(), p.knots().to_vec(), q.knots().to_vec(), Net::new(rows, cols, pts)?).ok()
}

/// The spherical product of a rational equator `e(u)` and meridian `m(v)`, planar curves given
/// homogeneously as `(X, Y, 0, W)`: the rational patch with control points
/// `(X_e X_m, Y_e X_m, W_e Y_m, W_e W_m)` (the course's formula, lifted to homogeneous
/// coordinates). A circle and a half circle give a sphere; a circle and any profile a surface of
/// revolution about the `z` axis.
pub fn spherical_product(e: &BSpline<Vec4>, m: &BSpline<Vec4>) -> Option<BSplinePatch<Vec4>> {
    let mut pts = Vec::with_capacity(e.points().len() * m.points().len());
    for a in e.points() {
        for b in m.points() {
            pts.push(Vec4::new(a.x * b.x, a.y * b.x, a.w * b.y, a.w * b.w));
        }
    }
    let net = Net::new(e.points().len(), m.points().len(), pts)?;
    BSplinePatch::new(e.degree(), m.degree(), e.knots().to_vec(), m.knots().to_vec(), net).ok()
}

/// The half circle of radius `r` in the `xy` plane from `(0, −r)` to `(0, r)` through `(r, 0)`,
/// as a rational quadratic B-spline (two 90° arcs, middle weights `cos 45°`).
pub fn half_circle(r: f64) -> BSpline<Vec4> {
    let w = std::f64::consts::FRAC_1_SQRT_2;
    let h = |x: f64, y: f64, wt: f64| Vec4::new(x * wt, y * wt, 0.0, wt);
    let pts = vec![h(0.0, -r, 1.0), h(r, -r, w), h(r, 0.0, 1.0), h(r, r, w), h(0.0, r, 1.0)];
    BSpline::new(2, vec![0.0, 0.0, 0.0, 1.0, 1.0, 2.0, 2.0, 2.0], pts).expect("valid by construction")
}

/// A surface of revolution about the `z` axis: the spherical product of the unit circle and the
/// cubic interpolant of the profile points `(radius, height)`.
pub fn revolution(profile: &[(f64, f64)]) -> Option<BSplinePatch<Vec4>> {
    let q: Vec<Vec3> = profile.iter().map(|&(r, h)| Vec3::new(r, h, 0.0)).collect();
    let meridian = interpolate_cubic(&q, &chord_lengths(&q))?;
    let homogeneous =
        BSpline::new(3, meridian.knots().to_vec(), meridian.points().iter().map(|p| p.extend(1.0)).collect()).ok()?;
    spherical_product(&crate::bspline::nurbs_circle(Vec3::ZERO, 1.0), &homogeneous)
}

/// A tube swept along the cubic interpolant of `guide` with a circular cross-section of
/// `radius`: the auxiliary guides are a rotation-minimising frame carried along the guide's
/// control polygon, the cross-section a 16-gon (a linear B-spline), so the result is the
/// course's swept B-spline surface.
pub fn swept_tube(guide: &[Vec3], radius: f64) -> Option<BSplinePatch<Vec3>> {
    let p = interpolate_cubic(guide, &chord_lengths(guide))?;
    let cp = p.points();
    let tangent = |i: usize| (cp[(i + 1).min(cp.len() - 1)] - cp[i.saturating_sub(1)]).normalize_or(Vec3::Z);
    let mut n = alhazen_math::orthonormal_basis(tangent(0)).0;
    let (mut x1, mut x2, mut x3) = (vec![], vec![], vec![]);
    for i in 0..cp.len() {
        let t = tangent(i);
        n = (n - t * n.dot(t)).normalize_or(alhazen_math::orthonormal_basis(t).0);
        x1.push(n * radius);
        x2.push(t.cross(n) * radius);
        x3.push(t * 0.0);
    }
    let guide_of = |pts: Vec<Vec3>| BSpline::new(3, p.knots().to_vec(), pts).ok();
    let (g1, g2, g3) = (guide_of(x1)?, guide_of(x2)?, guide_of(x3)?);
    let ring: Vec<Vec3> = (0..=16)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / 16.0;
            Vec3::new(a.cos(), a.sin(), 0.0)
        })
        .collect();
    sweep(&p, [&g1, &g2, &g3], &BSpline::clamped_uniform(1, ring).ok()?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bspline::nurbs_circle;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn interpolation_passes_through_the_points(pts in prop::collection::vec((-5.0..5.0f64, -5.0..5.0f64, -5.0..5.0f64), 2..12)) {
            let q: Vec<Vec3> = pts.into_iter().map(|(x, y, z)| Vec3::new(x, y, z)).collect();
            let t = chord_lengths(&q);
            let s = interpolate_cubic(&q, &t).unwrap();
            for (p, ti) in q.iter().zip(&t) {
                prop_assert!((s.eval(*ti) - *p).length() < 1e-9 * (1.0 + p.length()), "{} vs {}", s.eval(*ti), p);
            }
        }
    }

    #[test]
    fn spherical_product_of_circle_and_half_circle_is_a_sphere() {
        let s = spherical_product(&nurbs_circle(Vec3::ZERO, 1.0), &half_circle(2.0)).unwrap();
        let ((u0, u1), (v0, v1)) = s.domain();
        for i in 0..=40 {
            for j in 0..=40 {
                let h = s.eval(u0 + (u1 - u0) * i as f64 / 40.0, v0 + (v1 - v0) * j as f64 / 40.0);
                let p = h.truncate() / h.w;
                assert!((p.length() - 2.0).abs() < 1e-12, "{p}");
            }
        }
    }

    #[test]
    fn sweeping_a_circle_along_a_line_gives_a_cylinder() {
        let line = |a: Vec3, b: Vec3| BSpline::clamped_uniform(1, vec![a, b]).unwrap();
        let guide = line(Vec3::ZERO, Vec3::new(0.0, 0.0, 3.0));
        let (x1, x2, x3) = (line(Vec3::X, Vec3::X), line(Vec3::Y, Vec3::Y), line(Vec3::Z, Vec3::Z));
        // The cross-section: a polygonal approximation of a circle is enough to check the frame.
        let ring: Vec<Vec3> = (0..=8)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / 8.0;
                Vec3::new(a.cos(), a.sin(), 0.0)
            })
            .collect();
        let section = BSpline::clamped_uniform(1, ring).unwrap();
        let s = sweep(&guide, [&x1, &x2, &x3], &section).unwrap();
        for k in 0..=8 {
            let p = s.net.points[s.net.cols + k];
            assert!(((p.x * p.x + p.y * p.y).sqrt() - 1.0).abs() < 1e-12 && (p.z - 3.0).abs() < 1e-12);
        }
    }

    #[test]
    fn revolution_keeps_the_profile_radius() {
        let s = revolution(&[(1.0, 0.0), (1.5, 1.0), (0.8, 2.0), (1.2, 3.0)]).unwrap();
        let ((u0, u1), (v0, v1)) = s.domain();
        for j in 0..=10 {
            let v = v0 + (v1 - v0) * j as f64 / 10.0;
            let radii: Vec<f64> = (0..=12)
                .map(|i| {
                    let h = s.eval(u0 + (u1 - u0) * i as f64 / 12.0, v);
                    (h.truncate() / h.w).truncate().length()
                })
                .collect();
            assert!(radii.iter().all(|r| (r - radii[0]).abs() < 1e-12), "{radii:?}");
        }
    }

    #[test]
    fn swept_tube_has_constant_radius_at_the_control_frames() {
        let guide = [Vec3::ZERO, Vec3::new(1.0, 0.5, 0.0), Vec3::new(2.0, 0.0, 1.0), Vec3::new(3.0, 1.0, 1.0)];
        let s = swept_tube(&guide, 0.2).unwrap();
        s.net.points.chunks(s.net.cols).for_each(|row| {
            let c = row[0] - (row[0] - row[8]) * 0.5;
            assert!(row[..16].iter().all(|p| ((*p - c).length() - 0.2).abs() < 1e-9));
        });
    }

    #[test]
    fn lofting_interpolates_the_curves() {
        let mk = |h: f64, r: f64| {
            BSpline::clamped_uniform(3, (0..6).map(|k| Vec3::new(k as f64, h, r * (k as f64).sin())).collect()).unwrap()
        };
        let curves = vec![mk(0.0, 1.0), mk(1.0, 0.3), mk(2.5, 1.5), mk(3.0, 0.2)];
        let t = [0.0, 1.0, 2.5, 3.0];
        let s = loft(&curves, &t).unwrap();
        let (v0, v1) = curves[0].domain();
        for (c, ti) in curves.iter().zip(t) {
            for j in 0..=10 {
                let v = v0 + (v1 - v0) * j as f64 / 10.0;
                assert!((s.eval(ti, v) - c.eval(v)).length() < 1e-9);
            }
        }
    }
}
