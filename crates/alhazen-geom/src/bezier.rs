//! Bézier curves (course, §"Elements of geometric design"): evaluation by de Casteljau and by the
//! course's Horner scheme, the Bernstein form, the hodograph, division at `t`, degree elevation,
//! and adaptive flattening to a polyline with the course's convex-hull stopping rule.
//!
//! Seed typos, corrected here and pinned by tests:
//! * the recursion is printed `Bⁿᵢ = (1−t)Bⁿ⁻¹ᵢ₋₁ + tBⁿ⁻¹ᵢ₋₁`; it is `(1−t)Bⁿ⁻¹ᵢ + tBⁿ⁻¹ᵢ₋₁`;
//! * the Horner loop updates the binomial as `b = b(n−1)/(i+1)`; it must be `b = b(n−i)/(i+1)`;
//! * the elevation identity is printed `Bⁿᵢ = (n−i)/(n+1−i)Bⁿ⁺¹ᵢ + (i−1)/(n+1)Bⁿ⁺¹ᵢ₊₁`; it is
//!   `Bⁿᵢ = (n+1−i)/(n+1)Bⁿ⁺¹ᵢ + (i+1)/(n+1)Bⁿ⁺¹ᵢ₊₁` (the point formula that follows is right).
//!
//! ```
//! use alhazen_geom::bezier::Bezier;
//! use alhazen_math::Vec2;
//! let c = Bezier::new(vec![Vec2::ZERO, Vec2::new(1.0, 2.0), Vec2::new(2.0, 0.0)]).unwrap();
//! assert_eq!(c.eval(0.5), Vec2::new(1.0, 1.0));
//! let line = c.flatten(1e-3);
//! assert!(line.len() > 4);
//! ```

use alhazen_math::{Vec2, Vec3, Vec4};
use std::ops::{Add, Mul, Sub};

/// What a control point must support: affine combinations and a distance.
pub trait ControlPoint: Copy + Add<Output = Self> + Sub<Output = Self> + Mul<f64, Output = Self> {
    /// Euclidean length of the point as a vector.
    fn norm(self) -> f64;
    /// Dot product.
    fn dot_with(self, o: Self) -> f64;
}

macro_rules! control_point {
    ($t:ty) => {
        impl ControlPoint for $t {
            fn norm(self) -> f64 {
                self.length()
            }
            fn dot_with(self, o: Self) -> f64 {
                self.dot(o)
            }
        }
    };
}
control_point!(Vec2);
control_point!(Vec3);
control_point!(Vec4);

/// A Bézier curve of degree `n` on `[0, 1]`, given by `n + 1` control points.
#[derive(Clone, Debug, PartialEq)]
pub struct Bezier<P> {
    points: Vec<P>,
}

/// The de Casteljau algorithm on `p` (overwritten): the point at `t` of the Bézier curve with
/// control points `p`, which must not be empty.
pub fn de_casteljau<P: ControlPoint>(p: &mut [P], t: f64) -> P {
    for j in 1..p.len() {
        for i in 0..p.len() - j {
            p[i] = p[i] * (1.0 - t) + p[i + 1] * t;
        }
    }
    p[0]
}

/// The Bernstein polynomial `Bⁿᵢ(t) = C(n, i) tⁱ (1−t)ⁿ⁻ⁱ`.
pub fn bernstein(n: usize, i: usize, t: f64) -> f64 {
    if i > n {
        return 0.0;
    }
    let mut c = 1.0;
    for k in 0..i {
        c = c * (n - k) as f64 / (k + 1) as f64;
    }
    c * t.powi(i as i32) * (1.0 - t).powi((n - i) as i32)
}

impl<P: ControlPoint> Bezier<P> {
    /// A curve from its control points; `None` without any.
    pub fn new(points: Vec<P>) -> Option<Self> {
        (!points.is_empty()).then_some(Self { points })
    }

    /// The control points.
    pub fn points(&self) -> &[P] {
        &self.points
    }

    /// The degree `n`.
    pub fn degree(&self) -> usize {
        self.points.len() - 1
    }

    /// `p(t)` by the de Casteljau algorithm (O(n²), numerically the most stable).
    pub fn eval(&self, t: f64) -> P {
        de_casteljau(&mut self.points.clone(), t)
    }

    /// `p(t)` by the course's Horner scheme in `s = 1 − t` (O(n)), with its binomial update
    /// corrected to `b ← b(n − i)/(i + 1)`.
    pub fn eval_horner(&self, t: f64) -> P {
        let n = self.degree();
        let s = 1.0 - t;
        let mut p = self.points[0];
        let (mut d, mut b) = (t, n as f64);
        for i in 1..=n {
            p = p * s + self.points[i] * (b * d);
            d *= t;
            b = b * (n - i) as f64 / (i + 1) as f64;
        }
        p
    }

    /// `p(t) = Σ pᵢ Bⁿᵢ(t)`, straight from the definition (for tests and teaching).
    pub fn eval_bernstein(&self, t: f64) -> P {
        let n = self.degree();
        let mut p = self.points[0] * bernstein(n, 0, t);
        for i in 1..=n {
            p = p + self.points[i] * bernstein(n, i, t);
        }
        p
    }

    /// The hodograph: the derivative is the Bézier curve of degree `n − 1` with control points
    /// `n(pᵢ₊₁ − pᵢ)`. `None` for degree 0.
    pub fn derivative(&self) -> Option<Bezier<P>> {
        let n = self.degree() as f64;
        Bezier::new(self.points.windows(2).map(|w| (w[1] - w[0]) * n).collect())
    }

    /// The arcs on `[0, t]` and `[t, 1]`, each reparametrised to `[0, 1]` (the course's
    /// `Divide`).
    pub fn divide(&self, t: f64) -> (Bezier<P>, Bezier<P>) {
        let mut p = self.points.clone();
        let n = self.degree();
        let mut q = Vec::with_capacity(n + 1);
        q.push(p[0]);
        let mut back = vec![p[n]];
        for j in 1..=n {
            for i in 0..=n - j {
                p[i] = p[i] * (1.0 - t) + p[i + 1] * t;
            }
            q.push(p[0]);
            back.push(p[n - j]);
        }
        back.reverse();
        (Bezier { points: q }, Bezier { points: back })
    }

    /// The same curve one degree higher: `p̂ᵢ = (n+1−i)/(n+1) pᵢ + i/(n+1) pᵢ₋₁`.
    pub fn elevate(&self) -> Bezier<P> {
        let n = self.degree();
        let m = (n + 1) as f64;
        let mut q = Vec::with_capacity(n + 2);
        q.push(self.points[0]);
        for i in 1..=n {
            q.push(self.points[i] * ((m - i as f64) / m) + self.points[i - 1] * (i as f64 / m));
        }
        q.push(self.points[n]);
        Bezier { points: q }
    }

    /// The largest distance of the inner control points from the chord `p₀pₙ`: by the
    /// convex-hull property, no point of the arc is farther from the chord.
    pub fn flatness(&self) -> f64 {
        if self.points.len() <= 2 {
            return 0.0;
        }
        let (a, b) = (self.points[0], *self.points.last().expect("non-empty"));
        let ab = b - a;
        let len2 = ab.dot_with(ab);
        self.points[1..self.points.len() - 1]
            .iter()
            .map(|&p| {
                let ap = p - a;
                let s = if len2 > 0.0 { (ap.dot_with(ab) / len2).clamp(0.0, 1.0) } else { 0.0 };
                (ap - ab * s).norm()
            })
            .fold(0.0, f64::max)
    }

    /// A polyline within `tolerance` of the curve: recursive halving until the course's
    /// convex-hull criterion holds (depth-limited to 40 halvings; a non-positive or NaN
    /// tolerance is treated as 1e-9 of the control polygon's size).
    pub fn flatten(&self, tolerance: f64) -> Vec<P> {
        let size = self.points.windows(2).map(|w| (w[1] - w[0]).norm()).sum::<f64>();
        let tol = if tolerance > 0.0 { tolerance } else { 1e-9 * size.max(1e-300) };
        let mut out = vec![self.points[0]];
        self.flatten_into(tol, 0, &mut out);
        out
    }

    fn flatten_into(&self, tol: f64, depth: usize, out: &mut Vec<P>) {
        if depth >= 40 || self.flatness() <= tol {
            out.push(*self.points.last().expect("non-empty"));
            return;
        }
        let (a, b) = self.divide(0.5);
        a.flatten_into(tol, depth + 1, out);
        b.flatten_into(tol, depth + 1, out);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn arb_curve() -> impl Strategy<Value = Bezier<Vec3>> {
        prop::collection::vec((-10.0..10.0f64, -10.0..10.0f64, -10.0..10.0f64), 1..9)
            .prop_map(|v| Bezier::new(v.into_iter().map(|(x, y, z)| Vec3::new(x, y, z)).collect()).unwrap())
    }

    fn close(a: Vec3, b: Vec3) -> bool {
        (a - b).length() <= 1e-9 * (1.0 + a.length())
    }

    proptest! {
        #[test]
        fn de_casteljau_equals_bernstein_and_horner(c in arb_curve(), t in 0.0..1.0f64) {
            prop_assert!(close(c.eval(t), c.eval_bernstein(t)));
            prop_assert!(close(c.eval(t), c.eval_horner(t)));
        }

        #[test]
        fn division_leaves_the_curve_unchanged(c in arb_curve(), t in 0.05..0.95f64, u in 0.0..1.0f64) {
            let (a, b) = c.divide(t);
            prop_assert!(close(a.eval(u), c.eval(u * t)));
            prop_assert!(close(b.eval(u), c.eval(t + u * (1.0 - t))));
        }

        #[test]
        fn elevation_leaves_the_curve_unchanged(c in arb_curve(), u in 0.0..1.0f64) {
            let e = c.elevate();
            prop_assert_eq!(e.degree(), c.degree() + 1);
            prop_assert!(close(e.eval(u), c.eval(u)));
        }

        #[test]
        fn hodograph_matches_finite_differences(c in arb_curve(), t in 0.1..0.9f64) {
            if let Some(d) = c.derivative() {
                let h = 1e-6;
                let fd = (c.eval(t + h) - c.eval(t - h)) / (2.0 * h);
                prop_assert!((d.eval(t) - fd).length() <= 1e-5 * (1.0 + fd.length()));
            }
        }

        #[test]
        fn flattening_is_within_tolerance(c in arb_curve(), tol in 1e-4..1e-1f64) {
            let line = c.flatten(tol);
            // Every curve point is near the polyline: sample and measure.
            for k in 0..=200 {
                let p = c.eval(k as f64 / 200.0);
                let d = line.windows(2).map(|w| {
                    let ab = w[1] - w[0];
                    let s = if ab.length_squared() > 0.0 { ((p - w[0]).dot(ab) / ab.length_squared()).clamp(0.0, 1.0) } else { 0.0 };
                    (p - w[0] - ab * s).length()
                }).fold(f64::INFINITY, f64::min);
                prop_assert!(d <= tol * (1.0 + 1e-9) || line.len() == 1, "{d} > {tol}");
            }
        }

        #[test]
        fn the_curve_lies_in_the_convex_hull_of_a_planar_polygon(pts in prop::collection::vec((-5.0..5.0f64, -5.0..5.0f64), 2..7), t in 0.0..1.0f64) {
            // In the plane: every supporting line of the control points bounds the curve.
            let c = Bezier::new(pts.iter().map(|&(x, y)| Vec2::new(x, y)).collect()).unwrap();
            let p = c.eval(t);
            for k in 0..16 {
                let dir = Vec2::from_angle(k as f64 * std::f64::consts::TAU / 16.0);
                let max = c.points().iter().map(|q| q.dot(dir)).fold(f64::NEG_INFINITY, f64::max);
                prop_assert!(p.dot(dir) <= max + 1e-9);
            }
        }

        #[test]
        fn variation_diminishing(pts in prop::collection::vec((-5.0..5.0f64, -5.0..5.0f64), 2..7), angle in 0.0..std::f64::consts::PI, offset in -3.0..3.0f64) {
            // No line crosses the curve more often than the control polygon.
            let c = Bezier::new(pts.iter().map(|&(x, y)| Vec2::new(x, y)).collect()).unwrap();
            let n = Vec2::from_angle(angle);
            let side = |p: Vec2| (p.dot(n) - offset).signum();
            let count = |v: &[Vec2]| v.windows(2).filter(|w| side(w[0]) != side(w[1])).count();
            let samples: Vec<Vec2> = (0..=2000).map(|k| c.eval(k as f64 / 2000.0)).collect();
            prop_assert!(count(&samples) <= count(c.points()));
        }
    }

    #[test]
    fn seed_typos_are_really_typos() {
        // Horner with the printed update b = b(n−1)/(i+1) is wrong from degree 3 on.
        let c = Bezier::new(vec![Vec2::ZERO, Vec2::X, Vec2::Y, Vec2::ONE]).unwrap();
        let (n, t) = (3usize, 0.3f64);
        let s = 1.0 - t;
        let (mut p, mut d, mut b) = (c.points()[0], t, n as f64);
        for i in 1..=n {
            p = p * s + c.points()[i] * (b * d);
            d *= t;
            b = b * (n - 1) as f64 / (i + 1) as f64;
        }
        assert!((p - c.eval(t)).length() > 1e-3);
        assert!((c.eval_horner(t) - c.eval(t)).length() < 1e-15);
        // Elevation identity: the corrected weights reproduce Bⁿᵢ.
        for i in 0..=4usize {
            let lhs = bernstein(4, i, t);
            let rhs = (5 - i) as f64 / 5.0 * bernstein(5, i, t) + (i + 1) as f64 / 5.0 * bernstein(5, i + 1, t);
            assert!((lhs - rhs).abs() < 1e-15);
        }
    }
}
