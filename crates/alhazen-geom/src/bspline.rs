//! B-spline and NURBS curves (course, §"B-spline curves", §"Rational Bézier and B-spline
//! patches"): degree `n`, knots `u₀ ≤ … ≤ u_N`, control points `d₀ … d_{N−n−1}`, domain
//! `[u_n, u_{N−n}]`. Evaluation by de Boor's algorithm, the basis by the Mansfield–de Boor–Cox
//! formula, the hodograph, Boehm's knot insertion, conversion to Bézier arcs, Lane–Riesenfeld
//! refinement of uniform splines, and rational curves in homogeneous coordinates (`Vec4`),
//! including the course's circle of three arcs with middle weights `cos 60° = ½`.
//!
//! ```
//! use alhazen_geom::bspline::{BSpline, nurbs_circle, rational_point};
//! use alhazen_math::Vec3;
//! let circle = nurbs_circle(Vec3::ZERO, 2.0);
//! let p = rational_point(&circle, 0.7);
//! assert!((p.length() - 2.0).abs() < 1e-12);
//! ```

use crate::bezier::{Bezier, ControlPoint};
use alhazen_math::{Vec3, Vec4};

/// Why knots and control points do not make a B-spline.
#[derive(Clone, Debug, PartialEq)]
pub enum SplineError {
    /// `points.len()` must equal `knots.len() − degree − 1`.
    Count,
    /// The knots decrease somewhere or are not finite.
    Knots,
    /// The domain `[u_n, u_{N−n}]` is empty.
    EmptyDomain,
}

impl std::fmt::Display for SplineError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::Count => "a B-spline of degree n with N+1 knots needs N−n control points",
            Self::Knots => "knots must be finite and non-decreasing",
            Self::EmptyDomain => "the domain [u_n, u_(N−n)] is empty",
        })
    }
}

impl std::error::Error for SplineError {}

/// A B-spline curve.
#[derive(Clone, Debug, PartialEq)]
pub struct BSpline<P> {
    degree: usize,
    knots: Vec<f64>,
    points: Vec<P>,
}

impl<P: ControlPoint> BSpline<P> {
    /// Checks the course's counting rule and the knot order.
    pub fn new(degree: usize, knots: Vec<f64>, points: Vec<P>) -> Result<Self, SplineError> {
        if knots.len() < degree + 2 || points.len() + degree + 1 != knots.len() {
            return Err(SplineError::Count);
        }
        if knots.iter().any(|u| !u.is_finite()) || knots.windows(2).any(|w| w[1] < w[0]) {
            return Err(SplineError::Knots);
        }
        let s = Self { degree, knots, points };
        let (a, b) = s.domain();
        if a >= b {
            return Err(SplineError::EmptyDomain);
        }
        Ok(s)
    }

    /// A clamped uniform spline: end knots of multiplicity `n + 1`, so the curve starts at the
    /// first and ends at the last control point.
    pub fn clamped_uniform(degree: usize, points: Vec<P>) -> Result<Self, SplineError> {
        let inner = points.len().saturating_sub(degree + 1);
        let mut knots = vec![0.0; degree + 1];
        knots.extend((1..=inner).map(|i| i as f64));
        knots.extend(std::iter::repeat_n((inner + 1) as f64, degree + 1));
        Self::new(degree, knots, points)
    }

    /// Degree `n`.
    pub fn degree(&self) -> usize {
        self.degree
    }

    /// Knots.
    pub fn knots(&self) -> &[f64] {
        &self.knots
    }

    /// Control points.
    pub fn points(&self) -> &[P] {
        &self.points
    }

    /// `[u_n, u_{N−n}]`.
    pub fn domain(&self) -> (f64, f64) {
        (self.knots[self.degree], self.knots[self.knots.len() - 1 - self.degree])
    }

    fn span(&self, t: f64) -> usize {
        span(&self.knots, self.degree, t)
    }

    /// `s(t)` by de Boor's algorithm (`t` is clamped to the domain).
    pub fn eval(&self, t: f64) -> P {
        de_boor(&self.knots, self.degree, &self.points, t, &mut Vec::new())
    }

    /// The basis function `Nⁿᵢ(t)` by the Mansfield–de Boor–Cox recursion (0/0 taken as 0).
    pub fn basis(&self, i: usize, t: f64) -> f64 {
        fn rec(u: &[f64], i: usize, n: usize, t: f64, last: bool) -> f64 {
            if n == 0 {
                let inside = t >= u[i] && t < u[i + 1];
                // The right end of the domain belongs to the last non-empty span.
                return if inside || (last && t == u[i + 1] && u[i] < u[i + 1]) { 1.0 } else { 0.0 };
            }
            let left = if u[i + n] > u[i] { (t - u[i]) / (u[i + n] - u[i]) * rec(u, i, n - 1, t, last) } else { 0.0 };
            let right = if u[i + n + 1] > u[i + 1] {
                (u[i + n + 1] - t) / (u[i + n + 1] - u[i + 1]) * rec(u, i + 1, n - 1, t, last)
            } else {
                0.0
            };
            left + right
        }
        let last = t >= self.domain().1;
        rec(&self.knots, i, self.degree, t, last)
    }

    /// The hodograph: `s'(t) = Σ n/(u_{i+n+1} − u_{i+1}) (d_{i+1} − d_i) N^{n−1}_{i+1}(t)` on the
    /// knots without the first and last one. `None` for degree 0.
    pub fn derivative(&self) -> Option<BSpline<P>> {
        let n = self.degree;
        if n == 0 {
            return None;
        }
        let u = &self.knots;
        let mut pts = Vec::with_capacity(self.points.len() - 1);
        hodograph(u, n, &self.points, &mut pts);
        BSpline::new(n - 1, u[1..u.len() - 1].to_vec(), pts).ok()
    }

    /// Boehm's knot insertion (the course's in-place procedure): the same curve on one more
    /// knot. `t` must lie in the domain.
    pub fn insert_knot(&self, t: f64) -> BSpline<P> {
        let n = self.degree;
        let (a, b) = self.domain();
        let t = t.clamp(a, b);
        let k = self.span(t);
        let u = &self.knots;
        let mut pts = Vec::with_capacity(self.points.len() + 1);
        for i in 0..=self.points.len() {
            let p = if i + n <= k {
                self.points[i]
            } else if i > k {
                self.points[i - 1]
            } else {
                let alpha = (t - u[i]) / (u[i + n] - u[i]);
                self.points[i - 1] * (1.0 - alpha) + self.points[i] * alpha
            };
            pts.push(p);
        }
        let mut knots = u.clone();
        knots.insert(k + 1, t);
        BSpline { degree: n, knots, points: pts }
    }

    /// The polynomial arcs as Bézier curves, one per non-empty knot span of the domain: knots are
    /// inserted until every domain knot has multiplicity `n` (course: "then the control polygon
    /// consists of control polygons of Bézier curves").
    pub fn to_bezier(&self) -> Vec<Bezier<P>> {
        let n = self.degree;
        let (a, b) = self.domain();
        let mut s = self.clone();
        let mut distinct: Vec<f64> = self.knots.iter().copied().filter(|u| *u >= a && *u <= b).collect();
        distinct.dedup();
        for &u in &distinct {
            let mult = s.knots.iter().filter(|k| **k == u).count();
            for _ in mult..n.max(1) {
                s = s.insert_knot(u);
            }
        }
        distinct
            .windows(2)
            .map(|w| {
                let k = s.knots.iter().rposition(|u| *u == w[0]).expect("knot present");
                Bezier::new(s.points[k - n..=k].to_vec()).expect("n + 1 points")
            })
            .collect()
    }
}

impl<P: ControlPoint> BSpline<P> {
    /// The clamped spline joining Bézier arcs `arcs[i]` (all of one degree `n`) on
    /// `[breaks[i], breaks[i + 1]]`: end knots of multiplicity `n + 1`, interior knots of
    /// multiplicity `n` (the arcs' shared end points are the joints).
    pub fn from_bezier(arcs: &[Bezier<P>], breaks: &[f64]) -> Result<Self, SplineError> {
        let n = arcs.first().map_or(0, |a| a.degree());
        if arcs.is_empty() || breaks.len() != arcs.len() + 1 || arcs.iter().any(|a| a.degree() != n) {
            return Err(SplineError::Count);
        }
        let mut knots = vec![breaks[0]; n + 1];
        let mut points = arcs[0].points().to_vec();
        for (arc, &u) in arcs[1..].iter().zip(&breaks[1..]) {
            knots.extend(std::iter::repeat_n(u, n));
            points.extend_from_slice(&arc.points()[1..]);
        }
        knots.extend(std::iter::repeat_n(breaks[breaks.len() - 1], n + 1));
        Self::new(n, knots, points)
    }

    /// The distinct knots of the domain, in order: the ends of the polynomial arcs.
    pub fn breakpoints(&self) -> Vec<f64> {
        let (a, b) = self.domain();
        let mut distinct: Vec<f64> = self.knots.iter().copied().filter(|u| *u >= a && *u <= b).collect();
        distinct.dedup();
        distinct
    }

    /// Degree elevation (course: "the same curve one degree higher"): every Bézier arc is
    /// elevated and the arcs are joined again ([`Self::from_bezier`]), so the result is the same
    /// curve, clamped, on the same domain.
    pub fn elevate(&self) -> BSpline<P> {
        let arcs: Vec<Bezier<P>> = self.to_bezier().iter().map(Bezier::elevate).collect();
        Self::from_bezier(&arcs, &self.breakpoints()).expect("arcs of one degree on the spline's own breakpoints")
    }

    /// Whether the end knots have multiplicity `n + 1` (the curve starts and ends at its end
    /// control points).
    pub fn is_clamped(&self) -> bool {
        let (n, u) = (self.degree, &self.knots);
        u[..=n].iter().all(|k| *k == u[0]) && u[u.len() - 1 - n..].iter().all(|k| *k == u[u.len() - 1])
    }

    /// The same curve, clamped, with its knots mapped affinely so that the domain is `[0, 1]`.
    pub fn normalized(&self) -> BSpline<P> {
        let c = self.clamped();
        let (a, b) = c.domain();
        let knots = c.knots.iter().map(|u| ((u - a) / (b - a)).clamp(0.0, 1.0)).collect();
        BSpline { knots, ..c }
    }

    /// The same curve on the same domain with clamped ends (joined from its Bézier arcs if it was
    /// not clamped).
    pub fn clamped(&self) -> BSpline<P> {
        if self.is_clamped() {
            return self.clone();
        }
        Self::from_bezier(&self.to_bezier(), &self.breakpoints()).expect("the spline's own arcs")
    }

    /// One step of subdivision: a knot at the middle of every span of the domain. On uniform
    /// knots this is the Lane–Riesenfeld step (doubling and `n` averagings, on knots of half the
    /// spacing); otherwise Boehm's insertion, one knot at a time. The control polygon converges
    /// to the curve as the steps repeat — the course's way to display a spline.
    pub fn subdivided(&self) -> BSpline<P> {
        let n = self.degree;
        let gaps: Vec<f64> = self.knots.windows(2).map(|w| w[1] - w[0]).collect();
        let uniform = gaps.iter().all(|g| (g - gaps[0]).abs() <= 1e-12 * gaps[0].abs().max(1e-300)) && gaps[0] > 0.0;
        if uniform && n > 0 {
            let points = lane_riesenfeld(&self.points, n);
            let h = gaps[0] / 2.0;
            let start = self.knots[n] - n as f64 * h;
            let knots = (0..points.len() + n + 1).map(|i| start + i as f64 * h).collect();
            return BSpline { degree: n, knots, points };
        }
        let mids: Vec<f64> = self.breakpoints().windows(2).map(|w| 0.5 * (w[0] + w[1])).collect();
        mids.iter().fold(self.clone(), |s, &t| s.insert_knot(t))
    }

    /// The same curve with every knot of `knots` (sorted, within the domain) present at least as
    /// often as there: the missing ones inserted by Boehm's algorithm.
    pub fn with_knots(&self, knots: &[f64]) -> BSpline<P> {
        let mut s = self.clone();
        let mut i = 0;
        while i < knots.len() {
            let u = knots[i];
            let want = knots[i..].iter().take_while(|k| **k == u).count();
            let have = s.knots.iter().filter(|k| **k == u).count();
            for _ in have..want {
                s = s.insert_knot(u);
            }
            i += want;
        }
        s
    }
}

/// Curves made compatible for lofting and sweeping (course: "all curves must have the same
/// degree and the same knots"): each is clamped and mapped to the domain `[0, 1]`, raised to the
/// highest degree among them by degree elevation, and given the union of all knots (each with
/// its largest multiplicity) by knot insertion. Every curve stays the same point set with the
/// same parametrisation up to the affine map of its domain.
pub fn make_compatible<P: ControlPoint>(curves: &[BSpline<P>]) -> Vec<BSpline<P>> {
    let degree = curves.iter().map(|c| c.degree).max().unwrap_or(0);
    let raised: Vec<BSpline<P>> = curves
        .iter()
        .map(|c| {
            let mut c = c.normalized();
            while c.degree < degree {
                c = c.elevate();
            }
            c
        })
        .collect();
    // Knots closer than this are one knot (they differ only by the rounding of the domain map).
    const SAME_KNOT: f64 = 1e-12;
    let mut values: Vec<f64> = raised.iter().flat_map(|c| c.knots.iter().copied()).collect();
    values.sort_by(f64::total_cmp);
    values.dedup_by(|a, b| (*a - *b).abs() <= SAME_KNOT);
    let snap = |c: &BSpline<P>| -> BSpline<P> {
        let knots = c
            .knots
            .iter()
            .map(|u| *values.iter().find(|v| (*v - u).abs() <= SAME_KNOT).expect("every knot is among the values"))
            .collect();
        BSpline { knots, ..c.clone() }
    };
    let snapped: Vec<BSpline<P>> = raised.iter().map(snap).collect();
    let merged: Vec<f64> = values
        .iter()
        .flat_map(|&v| {
            let mult = snapped.iter().map(|c| c.knots.iter().filter(|k| **k == v).count()).max().unwrap_or(0);
            std::iter::repeat_n(v, mult)
        })
        .collect();
    snapped.iter().map(|c| c.with_knots(&merged)).collect()
}

/// The `k` with `t ∈ [u_k, u_{k+1})`, `n ≤ k < N − n` (the last span for the right end).
pub(crate) fn span(knots: &[f64], n: usize, t: f64) -> usize {
    let last = knots.len() - 2 - n;
    // Knots do not decrease: those ≤ t among u_{n+1} … u_last are a prefix.
    n + knots[n + 1..=last].partition_point(|u| *u <= t)
}

/// De Boor's algorithm: the point at `t` (clamped to the domain) of the B-spline of degree `n`
/// on valid `knots` (as [`BSpline::new`] checks them) with control points `points`. Only
/// `points[k − n ..= k]` of the span `k` of `t` are read; `scratch` is working space.
pub(crate) fn de_boor<P: ControlPoint>(knots: &[f64], n: usize, points: &[P], t: f64, scratch: &mut Vec<P>) -> P {
    let t = t.clamp(knots[n], knots[knots.len() - 1 - n]);
    let k = span(knots, n, t);
    scratch.clear();
    scratch.extend_from_slice(&points[k - n..=k]);
    let d = scratch;
    for j in 1..=n {
        for i in (j..=n).rev() {
            let idx = k - n + i;
            let denom = knots[idx + n + 1 - j] - knots[idx];
            let alpha = if denom > 0.0 { (t - knots[idx]) / denom } else { 0.0 };
            d[i] = d[i - 1] * (1.0 - alpha) + d[i] * alpha;
        }
    }
    d[n]
}

/// The control points of the hodograph of a spline of degree `n ≥ 1` (see
/// [`BSpline::derivative`]), written to `out`.
pub(crate) fn hodograph<P: ControlPoint>(knots: &[f64], n: usize, points: &[P], out: &mut Vec<P>) {
    out.clear();
    out.extend(points.windows(2).enumerate().map(|(i, w)| {
        let h = knots[i + n + 1] - knots[i + 1];
        if h > 0.0 { (w[1] - w[0]) * (n as f64 / h) } else { w[0] * 0.0 }
    }));
}

/// One Lane–Riesenfeld step for a uniform B-spline of degree `n` with control points `c`:
/// doubling, then `n` averagings; the result is the control polygon on the knots halved.
pub fn lane_riesenfeld<P: ControlPoint>(c: &[P], n: usize) -> Vec<P> {
    let mut d: Vec<P> = c.iter().flat_map(|&p| [p, p]).collect();
    for _ in 0..n {
        d = d.windows(2).map(|w| (w[0] + w[1]) * 0.5).collect();
    }
    d
}

/// A rational curve's point: the homogeneous B-spline `(w x, w y, w z, w)` evaluated and divided
/// by its weight.
pub fn rational_point(s: &BSpline<Vec4>, t: f64) -> Vec3 {
    let h = s.eval(t);
    h.truncate() / h.w
}

/// Homogeneous control point `(w p, w)`.
pub fn weighted(p: Vec3, w: f64) -> Vec4 {
    (p * w).extend(w)
}

/// A conic arc as a rational quadratic Bézier curve (homogeneous control points): from `p0` to
/// `p2` with tangents meeting at `p1`, middle weight `w` — an ellipse for `w < 1`, a parabola for
/// `w = 1`, a hyperbola for `w > 1` (the course's circle arc is `w = cos φ` with equal legs).
pub fn conic_arc(p0: Vec3, p1: Vec3, p2: Vec3, w: f64) -> BSpline<Vec4> {
    BSpline::new(2, vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0], vec![weighted(p0, 1.0), weighted(p1, w), weighted(p2, 1.0)])
        .expect("valid by construction")
}

/// The course's full circle of three equal arcs in the plane `z = center.z`: quadratic rational
/// Bézier arcs of angle 2φ = 120°, end weights 1 and middle weights `cos φ = ½`, joined as one
/// NURBS with double interior knots.
pub fn nurbs_circle(center: Vec3, radius: f64) -> BSpline<Vec4> {
    let on =
        |k: f64| center + Vec3::new((k * 120f64).to_radians().cos(), (k * 120f64).to_radians().sin(), 0.0) * radius;
    // The middle control point of an arc: where the end tangents meet, at distance r / cos φ.
    let apex = |k: f64| {
        center
            + Vec3::new((k * 120.0 + 60.0f64).to_radians().cos(), (k * 120.0 + 60.0f64).to_radians().sin(), 0.0)
                * (radius / 0.5)
    };
    let points = vec![
        weighted(on(0.0), 1.0),
        weighted(apex(0.0), 0.5),
        weighted(on(1.0), 1.0),
        weighted(apex(1.0), 0.5),
        weighted(on(2.0), 1.0),
        weighted(apex(2.0), 0.5),
        weighted(on(0.0), 1.0),
    ];
    let knots = vec![0.0, 0.0, 0.0, 1.0, 1.0, 2.0, 2.0, 3.0, 3.0, 3.0];
    BSpline::new(2, knots, points).expect("valid by construction")
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn arb_spline() -> impl Strategy<Value = BSpline<Vec3>> {
        (
            1usize..5,
            prop::collection::vec((-5.0..5.0f64, -5.0..5.0f64, -5.0..5.0f64), 6..12),
            prop::collection::vec(0.1..2.0f64, 20),
        )
            .prop_map(|(n, pts, gaps)| {
                let pts: Vec<Vec3> = pts.into_iter().map(|(x, y, z)| Vec3::new(x, y, z)).collect();
                let mut knots = vec![0.0];
                for g in gaps.iter().take(pts.len() + n) {
                    knots.push(knots.last().unwrap() + g);
                }
                BSpline::new(n, knots, pts).unwrap()
            })
    }

    fn close(a: Vec3, b: Vec3) -> bool {
        (a - b).length() <= 1e-9 * (1.0 + a.length())
    }

    proptest! {
        #[test]
        fn de_boor_equals_the_basis_sum(s in arb_spline(), f in 0.0..1.0f64) {
            let (a, b) = s.domain();
            let t = a + (b - a) * f;
            let sum = s.points().iter().enumerate().fold(Vec3::ZERO, |acc, (i, p)| acc + *p * s.basis(i, t));
            prop_assert!(close(s.eval(t), sum));
            // Partition of unity on the domain.
            let total: f64 = (0..s.points().len()).map(|i| s.basis(i, t)).sum();
            prop_assert!((total - 1.0).abs() < 1e-12);
        }

        #[test]
        fn knot_insertion_leaves_the_curve_unchanged(s in arb_spline(), f in 0.0..1.0f64, g in 0.0..1.0f64) {
            let (a, b) = s.domain();
            let r = s.insert_knot(a + (b - a) * f);
            prop_assert_eq!(r.points().len(), s.points().len() + 1);
            let t = a + (b - a) * g;
            prop_assert!(close(r.eval(t), s.eval(t)));
        }

        #[test]
        fn hodograph_matches_finite_differences(s in arb_spline(), f in 0.05..0.95f64) {
            let (a, b) = s.domain();
            let t = a + (b - a) * f;
            // Avoid knots, where the derivative may jump for low degree.
            prop_assume!(s.knots().iter().all(|u| (u - t).abs() > 1e-3));
            if let Some(d) = s.derivative() {
                let h = 1e-6;
                let fd = (s.eval(t + h) - s.eval(t - h)) / (2.0 * h);
                prop_assert!((d.eval(t) - fd).length() <= 1e-4 * (1.0 + fd.length()));
            }
        }

        #[test]
        fn bezier_arcs_reproduce_the_spline(s in arb_spline(), g in 0.0..1.0f64) {
            let (a, b) = s.domain();
            let mut distinct: Vec<f64> = s.knots().iter().copied().filter(|u| *u >= a && *u <= b).collect();
            distinct.dedup();
            let arcs = s.to_bezier();
            prop_assert_eq!(arcs.len(), distinct.len() - 1);
            for (arc, w) in arcs.iter().zip(distinct.windows(2)) {
                let t = w[0] + (w[1] - w[0]) * g;
                prop_assert!(close(arc.eval(g), s.eval(t)));
            }
        }

        #[test]
        fn degree_elevation_keeps_the_curve(s in arb_spline(), g in 0.0..1.0f64) {
            let e = s.elevate();
            prop_assert_eq!(e.degree(), s.degree() + 1);
            prop_assert!(e.is_clamped());
            prop_assert_eq!(e.domain(), s.domain());
            let (a, b) = s.domain();
            let t = a + (b - a) * g;
            prop_assert!(close(e.eval(t), s.eval(t)), "{} vs {}", e.eval(t), s.eval(t));
        }

        #[test]
        fn subdivision_keeps_the_curve_and_halves_the_spans(s in arb_spline(), g in 0.0..1.0f64) {
            let r = s.subdivided();
            let (a, b) = s.domain();
            prop_assert_eq!(r.domain(), (a, b));
            prop_assert_eq!(r.breakpoints().len() - 1, 2 * (s.breakpoints().len() - 1));
            let t = a + (b - a) * g;
            prop_assert!(close(r.eval(t), s.eval(t)));
        }

        #[test]
        fn lane_riesenfeld_is_midpoint_knot_insertion_on_uniform_knots(n in 1usize..5, len in 6usize..10, g in 0.0..1.0f64) {
            let pts: Vec<Vec3> = (0..len).map(|k| Vec3::new(k as f64, ((k * 7) % 5) as f64, ((k * 3) % 4) as f64)).collect();
            let s = BSpline::new(n, (0..len + n + 1).map(|i| i as f64 * 0.5).collect(), pts).unwrap();
            let lr = s.subdivided();
            let boehm = s.breakpoints().windows(2).fold(s.clone(), |c, w| c.insert_knot(0.5 * (w[0] + w[1])));
            let (a, b) = s.domain();
            let t = a + (b - a) * g;
            prop_assert!(close(lr.eval(t), boehm.eval(t)) && close(lr.eval(t), s.eval(t)));
            // One new control point per span of the domain either way.
            prop_assert_eq!(lr.points().len(), boehm.points().len());
        }

        #[test]
        fn compatible_curves_share_degree_and_knots_and_keep_their_shape(a in arb_spline(), b in arb_spline(), g in 0.0..1.0f64) {
            let c = make_compatible(&[a.clone(), b.clone()]);
            prop_assert_eq!(c[0].degree(), a.degree().max(b.degree()));
            prop_assert_eq!(c[0].knots(), c[1].knots());
            prop_assert_eq!(c[0].domain(), (0.0, 1.0));
            for (orig, comp) in [a, b].iter().zip(&c) {
                let (lo, hi) = orig.domain();
                prop_assert!(close(comp.eval(g), orig.eval(lo + (hi - lo) * g)));
            }
        }

        #[test]
        fn unit_weight_nurbs_equals_the_b_spline(s in arb_spline(), g in 0.0..1.0f64) {
            let h = BSpline::new(s.degree(), s.knots().to_vec(), s.points().iter().map(|p| weighted(*p, 1.0)).collect()).unwrap();
            let (a, b) = s.domain();
            let t = a + (b - a) * g;
            prop_assert!(close(rational_point(&h, t), s.eval(t)));
        }

        #[test]
        fn nurbs_are_projectively_invariant(g in 0.0..1.0f64, w in 0.2..3.0f64) {
            // Scaling all weights changes nothing; applying a projective map to the homogeneous
            // control points maps the curve points.
            let c = nurbs_circle(Vec3::new(1.0, 2.0, 0.0), 1.5);
            let scaled = BSpline::new(2, c.knots().to_vec(), c.points().iter().map(|p| *p * w).collect()).unwrap();
            let t = 3.0 * g;
            prop_assert!(close(rational_point(&c, t), rational_point(&scaled, t)));
            let m = alhazen_math::Mat4::from_cols(Vec4::new(1.0, 0.2, 0.0, 0.1), Vec4::new(0.0, 1.0, 0.3, 0.05), Vec4::new(0.0, 0.0, 1.0, 0.0), Vec4::new(0.5, -0.3, 0.2, 1.0));
            let image = BSpline::new(2, c.knots().to_vec(), c.points().iter().map(|p| m * *p).collect()).unwrap();
            let expect = m * rational_point(&c, t).extend(1.0);
            prop_assert!(close(rational_point(&image, t), expect.truncate() / expect.w));
        }
    }

    #[test]
    fn the_nurbs_circle_has_constant_radius() {
        let c = nurbs_circle(Vec3::new(3.0, -1.0, 2.0), 2.5);
        for k in 0..=3000 {
            let p = rational_point(&c, 3.0 * k as f64 / 3000.0);
            assert!(((p - Vec3::new(3.0, -1.0, 2.0)).length() - 2.5).abs() < 1e-12, "{p}");
        }
    }

    #[test]
    fn conic_arcs_are_conics() {
        // Legs (1,0)→(1,1)→(0,1): w = √2/2 is the unit circle arc; w = 1 the polynomial
        // (parabolic) quadratic Bézier arc.
        let circle = conic_arc(Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y, std::f64::consts::FRAC_1_SQRT_2);
        let parabola = conic_arc(Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y, 1.0);
        for k in 0..=20 {
            let t = k as f64 / 20.0;
            assert!((rational_point(&circle, t).length() - 1.0).abs() < 1e-14);
            let p = rational_point(&parabola, t);
            let q = Vec3::X * (1.0 - t) * (1.0 - t) + Vec3::new(1.0, 1.0, 0.0) * 2.0 * t * (1.0 - t) + Vec3::Y * t * t;
            assert!((p - q).length() < 1e-14);
        }
        // A hyperbola arc leaves the triangle's incircle side: it bulges towards p1 more.
        let hyper = conic_arc(Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y, 3.0);
        assert!(rational_point(&hyper, 0.5).x > rational_point(&parabola, 0.5).x);
    }

    #[test]
    fn lane_riesenfeld_converges_to_the_uniform_spline() {
        // Uniform cubic on integer knots: after refinement the polygon approaches the curve.
        let c: Vec<Vec3> = [(0.0, 0.0), (1.0, 2.0), (3.0, 3.0), (4.0, 0.0), (6.0, 1.0), (7.0, 3.0)]
            .iter()
            .map(|&(x, y)| Vec3::new(x, y, 0.0))
            .collect();
        let knots: Vec<f64> = (0..c.len() + 4).map(|i| i as f64).collect();
        let s = BSpline::new(3, knots, c.clone()).unwrap();
        let mut poly = c.clone();
        let mut errors = vec![];
        for _ in 0..5 {
            poly = lane_riesenfeld(&poly, 3);
            let (a, b) = s.domain();
            let err = (0..=100)
                .map(|k| {
                    let p = s.eval(a + (b - a) * k as f64 / 100.0);
                    poly.iter().map(|q| (*q - p).length()).fold(f64::INFINITY, f64::min)
                })
                .fold(0.0, f64::max);
            errors.push(err);
        }
        assert!(errors.windows(2).all(|w| w[1] < w[0] * 0.7), "{errors:?}");
        assert!(*errors.last().unwrap() < 0.05);
    }

    #[test]
    fn bad_input_is_an_error() {
        assert_eq!(BSpline::new(2, vec![0.0, 1.0, 2.0], vec![Vec3::ZERO]), Err(SplineError::Count));
        assert_eq!(BSpline::new(1, vec![0.0, 2.0, 1.0], vec![Vec3::ZERO]), Err(SplineError::Knots));
        assert_eq!(BSpline::new(1, vec![0.0, 1.0, 1.0, 2.0], vec![Vec3::ZERO, Vec3::X]), Err(SplineError::EmptyDomain));
        assert!(BSpline::clamped_uniform(3, vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z, Vec3::ONE]).is_ok());
    }
}
