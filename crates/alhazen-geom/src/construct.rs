//! Constructions of curves and surfaces (course, §"Some constructions of surfaces"): cubic
//! B-spline interpolation, lofting through curves, swept surfaces with auxiliary guides, and
//! spherical products (surfaces of revolution) of rational curves.

use crate::bezier::ControlPoint;
use crate::bspline::{BSpline, make_compatible};
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

/// Lofting (skinning): the cubic-by-`m` B-spline patch through the curves `curves[i]` at
/// `u = t[i]`. The course assumes all curves share degree and knots; curves that do not are made
/// so first ([`make_compatible`]: degree elevation and knot insertion, domains mapped to
/// `[0, 1]`). Each column of the control net is then interpolated like a point.
pub fn loft<P: ControlPoint>(curves: &[BSpline<P>], t: &[f64]) -> Option<BSplinePatch<P>> {
    let curves = make_compatible(curves);
    let first = curves.first()?;
    let cols = first.points().len();
    let columns: Vec<BSpline<P>> = (0..cols)
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

/// The swept surface (course, §"Swept surfaces") with guide `p(u)`, auxiliary guides
/// `x1, x2, x3` (the frame, of `p`'s degree and knots) and cross-section `q(v)`:
/// `s(u, v) = p(u) + x1(u) q_x(v) + x2(u) q_y(v) + x3(u) q_z(v)`, so the control points are the
/// course's `d_ij = x1_i x_q_j + x2_i y_q_j + x3_i z_q_j + p_i`. Guide and section may be rational
/// (homogeneous control points); the frame then shares the guide's weights, which keeps the
/// surface a tensor product: `D_ij = (W_j P_i + w_i Σ_k x_k,i Q_j,k, w_i W_j)`.
pub fn sweep(p: &BSpline<Vec4>, x: [&BSpline<Vec3>; 3], q: &BSpline<Vec4>) -> Option<BSplinePatch<Vec4>> {
    if x.iter().any(|g| g.knots() != p.knots() || g.degree() != p.degree()) {
        return None;
    }
    let (rows, cols) = (p.points().len(), q.points().len());
    let mut pts = Vec::with_capacity(rows * cols);
    for (i, gp) in p.points().iter().enumerate() {
        let frame = [x[0].points()[i], x[1].points()[i], x[2].points()[i]];
        for qj in q.points() {
            let offset = frame[0] * qj.x + frame[1] * qj.y + frame[2] * qj.z;
            pts.push((gp.truncate() * qj.w + offset * gp.w).extend(gp.w * qj.w));
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
    revolution_of(&homogeneous)
}

/// The surface of revolution about the `z` axis of a rational profile `(r w, h w, 0, w)` (radius
/// `r`, height `h`): the spherical product with the exact NURBS circle.
pub fn revolution_of(profile: &BSpline<Vec4>) -> Option<BSplinePatch<Vec4>> {
    spherical_product(&crate::bspline::nurbs_circle(Vec3::ZERO, 1.0), profile)
}

/// A swept surface whose frame follows its guide, and how far it is from the ideal one.
#[derive(Clone, Debug)]
pub struct FramedSweep {
    /// The rational B-spline surface.
    pub surface: BSplinePatch<Vec4>,
    /// The largest deviation measured (in the section's units) of the placed section from a
    /// rigid copy in the guide's normal plane: `R · max(|‖x₁‖ − 1|, |‖x₂‖ − 1|, |x₁·x₂|, |x₁·t|,
    /// |x₂·t|)` with `R` the section's extent, over samples of every span.
    pub error: f64,
    /// How many times the guide was subdivided to reach it.
    pub subdivisions: usize,
}

/// Control points beyond which [`framed_sweep`] stops subdividing the guide.
pub const MAX_GUIDE_POINTS: usize = 1 << 14;

/// The course's swept surface with the auxiliary guides computed: a rotation-minimising frame
/// (double reflection, Wang et al. 2008) at the Greville abscissae of the guide, from its exact
/// tangents, is the frame's control points. Between them the frame is a spline, slightly
/// stretched and skewed; the guide is subdivided ([`BSpline::subdivided`]: Lane–Riesenfeld or
/// Boehm's knot insertion) until that deviation is within `tolerance`, so the section —
/// by default the exact rational circle — is placed as precisely as asked. `section` is a planar
/// rational curve in the frame's `(normal, binormal)` plane.
pub fn framed_sweep(guide: &BSpline<Vec4>, section: &BSpline<Vec4>, tolerance: f64) -> Option<FramedSweep> {
    let extent = section.points().iter().map(|q| (q.truncate() / q.w).length()).fold(0.0, f64::max);
    let mut guide = guide.clone();
    let mut subdivisions = 0;
    loop {
        let frame = rotation_minimising_frame(&guide)?;
        let error = extent * frame_deviation(&guide, &frame)?;
        let [n, b, t] = frame.map(|f| BSpline::new(guide.degree(), guide.knots().to_vec(), f).expect("guide's knots"));
        let surface = sweep(&guide, [&n, &b, &t], section)?;
        if error <= tolerance || guide.points().len() * 2 > MAX_GUIDE_POINTS || !error.is_finite() {
            return Some(FramedSweep { surface, error, subdivisions });
        }
        guide = guide.subdivided();
        subdivisions += 1;
    }
}

/// A tube of `radius` around `guide`: [`framed_sweep`] of the exact NURBS circle.
pub fn swept_tube(guide: &BSpline<Vec4>, radius: f64, tolerance: f64) -> Option<FramedSweep> {
    framed_sweep(guide, &crate::bspline::nurbs_circle(Vec3::ZERO, radius), tolerance)
}

/// The point and unit tangent of a rational curve at `t` (`None` where the derivative vanishes).
fn point_and_tangent(c: &BSpline<Vec4>, dc: &BSpline<Vec4>, t: f64) -> (Vec3, Option<Vec3>) {
    let (h, dh) = (c.eval(t), dc.eval(t));
    let p = h.truncate() / h.w;
    (p, ((dh.truncate() - p * dh.w) / h.w).try_normalize())
}

/// The Greville abscissae `ξ_i = (u_{i+1} + … + u_{i+n}) / n` (the parameters the control
/// points belong to).
fn greville(c: &BSpline<Vec4>) -> Vec<f64> {
    let (n, u) = (c.degree().max(1), c.knots());
    (0..c.points().len()).map(|i| u[i + 1..=i + n].iter().sum::<f64>() / n as f64).collect()
}

/// Normal, binormal and tangent at the Greville abscissae, transported by double reflection.
fn rotation_minimising_frame(c: &BSpline<Vec4>) -> Option<[Vec<Vec3>; 3]> {
    let dc = c.derivative()?;
    let samples: Vec<(Vec3, Option<Vec3>)> = greville(c).iter().map(|&t| point_and_tangent(c, &dc, t)).collect();
    let first = samples.iter().find_map(|s| s.1)?;
    let (mut x, mut t) = (samples[0].0, first);
    let mut r = alhazen_math::orthonormal_basis(t).0;
    let mut frame = [vec![], vec![], vec![]];
    for &(xn, tn) in &samples {
        let tn = tn.unwrap_or(t);
        let v1 = xn - x;
        let c1 = v1.dot(v1);
        let (rl, tl) =
            if c1 > 0.0 { (r - v1 * (2.0 / c1 * v1.dot(r)), t - v1 * (2.0 / c1 * v1.dot(t))) } else { (r, t) };
        let v2 = tn - tl;
        let c2 = v2.dot(v2);
        let rn = if c2 > 0.0 { rl - v2 * (2.0 / c2 * v2.dot(rl)) } else { rl };
        r = (rn - tn * rn.dot(tn)).normalize_or(alhazen_math::orthonormal_basis(tn).0);
        (x, t) = (xn, tn);
        frame[0].push(r);
        frame[1].push(t.cross(r));
        frame[2].push(t);
    }
    Some(frame)
}

/// The largest deviation of the spline frame from an orthonormal frame perpendicular to the
/// guide, over eight samples in every span.
fn frame_deviation(c: &BSpline<Vec4>, frame: &[Vec<Vec3>; 3]) -> Option<f64> {
    let dc = c.derivative()?;
    // The frame's splines carry the guide's weights: x(u) = Σ N_i w_i x_i / w(u).
    let weighted = |f: &Vec<Vec3>| {
        let pts = f.iter().zip(c.points()).map(|(x, h)| (*x * h.w).extend(h.w)).collect();
        BSpline::new(c.degree(), c.knots().to_vec(), pts).expect("guide's knots")
    };
    let (xn, xb) = (weighted(&frame[0]), weighted(&frame[1]));
    let at = |s: &BSpline<Vec4>, u: f64| {
        let h = s.eval(u);
        h.truncate() / h.w
    };
    let mut worst = 0.0f64;
    for w in c.breakpoints().windows(2) {
        for k in 0..=8 {
            let u = w[0] + (w[1] - w[0]) * k as f64 / 8.0;
            let Some(t) = point_and_tangent(c, &dc, u).1 else { continue };
            let (n, b) = (at(&xn, u), at(&xb, u));
            let dev =
                [(n.length() - 1.0).abs(), (b.length() - 1.0).abs(), n.dot(b).abs(), n.dot(t).abs(), b.dot(t).abs()];
            worst = dev.into_iter().fold(worst, f64::max);
        }
    }
    Some(worst)
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

    fn homogeneous(c: &BSpline<Vec3>) -> BSpline<Vec4> {
        BSpline::new(c.degree(), c.knots().to_vec(), c.points().iter().map(|p| p.extend(1.0)).collect()).unwrap()
    }

    fn point(h: Vec4) -> Vec3 {
        h.truncate() / h.w
    }

    #[test]
    fn sweeping_a_circle_along_a_line_gives_a_cylinder() {
        let line = |a: Vec3, b: Vec3| BSpline::clamped_uniform(1, vec![a, b]).unwrap();
        let guide = homogeneous(&line(Vec3::ZERO, Vec3::new(0.0, 0.0, 3.0)));
        let (x1, x2, x3) = (line(Vec3::X, Vec3::X), line(Vec3::Y, Vec3::Y), line(Vec3::Z, Vec3::Z));
        let s = sweep(&guide, [&x1, &x2, &x3], &nurbs_circle(Vec3::ZERO, 1.0)).unwrap();
        let ((u0, u1), (v0, v1)) = s.domain();
        for i in 0..=10 {
            for j in 0..=60 {
                let p = point(s.eval(u0 + (u1 - u0) * i as f64 / 10.0, v0 + (v1 - v0) * j as f64 / 60.0));
                assert!((p.truncate().length() - 1.0).abs() < 1e-12 && (p.z - 0.3 * i as f64).abs() < 1e-12, "{p}");
            }
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

    /// The largest `| |s(u, v) − c(u)| − r |` over a fine sampling of a tube around `c`.
    fn radial_error(tube: &FramedSweep, c: &BSpline<Vec4>, r: f64) -> f64 {
        let ((u0, u1), (v0, v1)) = tube.surface.domain();
        let (a, b) = c.domain();
        let mut worst = 0.0f64;
        for i in 0..=200 {
            let f = i as f64 / 200.0;
            let centre = point(c.eval(a + (b - a) * f));
            for j in 0..=24 {
                let p = point(tube.surface.eval(u0 + (u1 - u0) * f, v0 + (v1 - v0) * j as f64 / 24.0));
                worst = worst.max(((p - centre).length() - r).abs());
            }
        }
        worst
    }

    #[test]
    fn a_swept_tube_is_as_round_as_its_tolerance_asks() {
        let guide = [Vec3::ZERO, Vec3::new(1.0, 0.5, 0.0), Vec3::new(2.0, 0.0, 1.0), Vec3::new(3.0, 1.0, 1.0)];
        let c = homogeneous(&interpolate_cubic(&guide, &chord_lengths(&guide)).unwrap());
        let mut last = f64::INFINITY;
        for tol in [1e-2, 1e-3, 1e-4, 1e-5] {
            let tube = swept_tube(&c, 0.2, tol).unwrap();
            assert!(tube.error <= tol, "{tol}: {}", tube.error);
            let measured = radial_error(&tube, &c, 0.2);
            assert!(measured <= 2.0 * tol, "tolerance {tol}: measured radial error {measured}");
            assert!(measured <= last);
            last = measured;
        }
        assert!(swept_tube(&c, 0.2, 1e-5).unwrap().subdivisions >= 2);
    }

    #[test]
    fn a_tube_around_a_rational_guide_follows_it() {
        // A quarter of a circle of radius 2 as guide: the tube is a piece of a torus.
        let guide = crate::bspline::conic_arc(
            Vec3::X * 2.0,
            Vec3::new(2.0, 2.0, 0.0),
            Vec3::Y * 2.0,
            std::f64::consts::FRAC_1_SQRT_2,
        );
        let tube = swept_tube(&guide, 0.5, 1e-4).unwrap();
        assert!(radial_error(&tube, &guide, 0.5) <= 2e-4);
        // Every point lies on the torus: distance from the guide circle is the tube radius.
        let ((u0, u1), (v0, v1)) = tube.surface.domain();
        for i in 0..=20 {
            for j in 0..=20 {
                let p = point(tube.surface.eval(u0 + (u1 - u0) * i as f64 / 20.0, v0 + (v1 - v0) * j as f64 / 20.0));
                let ring = Vec3::new(p.x, p.y, 0.0).normalize() * 2.0;
                assert!(((p - ring).length() - 0.5).abs() <= 2e-4, "{p}");
            }
        }
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
                let f = j as f64 / 10.0;
                assert!((s.eval(ti, f) - c.eval(v0 + (v1 - v0) * f)).length() < 1e-9);
            }
        }
    }

    #[test]
    fn curves_of_different_degrees_and_knots_are_lofted_exactly() {
        // A line (degree 1, 2 points), a cubic on uneven knots and a rational circle arc.
        let line = homogeneous(&BSpline::clamped_uniform(1, vec![Vec3::ZERO, Vec3::new(3.0, 0.0, 0.0)]).unwrap());
        let cubic = homogeneous(
            &BSpline::new(
                3,
                vec![0.0, 0.0, 0.0, 0.0, 0.3, 1.7, 2.0, 2.0, 2.0, 2.0],
                (0..6).map(|k| Vec3::new(k as f64 * 0.6, 1.0, (k as f64).sin())).collect(),
            )
            .unwrap(),
        );
        let arc = crate::bspline::conic_arc(
            Vec3::new(0.0, 2.0, 0.0),
            Vec3::new(1.5, 2.0, 1.5),
            Vec3::new(3.0, 2.0, 0.0),
            0.7,
        );
        let curves = [line, cubic, arc];
        let t = [0.0, 1.0, 2.0];
        let s = loft(&curves, &t).unwrap();
        for (c, ti) in curves.iter().zip(t) {
            let (a, b) = c.domain();
            for j in 0..=40 {
                let f = j as f64 / 40.0;
                let (on_surface, on_curve) = (point(s.eval(ti, f)), point(c.eval(a + (b - a) * f)));
                assert!((on_surface - on_curve).length() < 1e-9, "{ti} {f}: {on_surface} vs {on_curve}");
            }
        }
    }
}
