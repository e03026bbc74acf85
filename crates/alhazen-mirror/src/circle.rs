//! Reflexes of a point on a circle (Glaeser §2.1): `R[k; E](S)`.
//!
//! Canonical frame: the circle's centre `M` is the origin, the eye `E` lies on the positive
//! `x`-axis at distance `e` (or at infinity in that direction). Writing `w = 1/e` (0 for an eye at
//! infinity) and `t = 1` for a finite source `S = (s_x, s_y)` or `t = 0` with `(s_x, s_y) =
//! (cos σ, sin σ)` for a source at infinity, every case of the paper is the one quartic
//!
//! `g(x) = (x² − r²)(2 s_x x − r²(w s_x + t))² + s_y²(2x² − r² w x − r²)²`,
//!
//! which is `e²·f(x)` of the paper's Theorem 1 for finite points, and whose normalised
//! coefficients are (5), (6) and (7) (tested). Seed typo: (7) prints `c₃ = −2uw s_x`; with `S` at
//! infinity the term is `−2uw` (the `s_x` cannot stay: it is infinite).
//!
//! Robustness (§2.2): the roots `x` of `g` are isolated on `[−r, r]` (near-double roots
//! included); the magnitude of `y` comes from the circle, both signs are tried (the hyperbola (3)
//! degenerates near the double points (11), so it cannot be trusted to pick the sign there), and
//! each candidate is polished by Newton's method in the polar angle `φ` on the exact condition
//! "the mirror image of the ray `R→E` about the normal lies on the line `RS`". Candidates whose
//! residual does not vanish are dropped, duplicates merged.

use crate::poly::{Poly, real_roots_in};
use alhazen_math::Vec2;

/// How a solution of the reflection condition reflects.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum ReflexKind {
    /// The light reflects on the outside of the mirror: the visible reflex.
    Outside,
    /// The light reflects on the inside (eye and source on the inner side of the tangent).
    Inside,
    /// `S` lies on the reflected *line* but behind the mirror point: no real light path.
    Virtual,
}

/// A point of the canonical frame, finite or at infinity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Site2 {
    /// A finite point.
    At(Vec2),
    /// A point at infinity in this (unit) direction.
    Toward(Vec2),
}

impl Site2 {
    /// Unit direction from `p` towards the site.
    #[inline]
    fn dir_from(&self, p: Vec2) -> Vec2 {
        match *self {
            Site2::At(q) => (q - p).normalize_or_zero(),
            Site2::Toward(d) => d,
        }
    }
}

/// One solution in the canonical frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Reflex2 {
    /// Polar angle of the mirror point.
    pub phi: f64,
    /// Classification.
    pub kind: ReflexKind,
}

/// Up to four solutions.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Reflexes2 {
    items: [Option<Reflex2>; 4],
    len: usize,
}

impl Reflexes2 {
    fn push(&mut self, r: Reflex2) {
        let dup = self.iter().any(|q| angle_diff(q.phi, r.phi) < 1e-9);
        if !dup && self.len < 4 {
            self.items[self.len] = Some(r);
            self.len += 1;
        }
    }

    pub fn iter(&self) -> impl Iterator<Item = Reflex2> + '_ {
        self.items[..self.len].iter().flatten().copied()
    }
}

pub(crate) fn angle_diff(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(std::f64::consts::TAU);
    d.min(std::f64::consts::TAU - d)
}

/// The canonical problem: radius `r`, eye at `(e, 0)` (`w = 1/e`) or at infinity (`w = 0`),
/// source `s`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Canonical {
    pub r: f64,
    pub eye: Site2,
    pub w: f64,
    pub source: Site2,
}

impl Canonical {
    /// The paper's quartic `g(x)` (see the module doc), ascending coefficients.
    pub fn quartic(&self) -> Poly {
        let (sx, sy, t) = match self.source {
            Site2::At(s) => (s.x, s.y, 1.0),
            Site2::Toward(d) => (d.x, d.y, 0.0),
        };
        let (r2, w) = (self.r * self.r, self.w);
        let p = [-r2, 0.0, 1.0];
        let q = [-r2 * (w * sx + t), 2.0 * sx];
        let h = [-r2, -r2 * w, 2.0];
        let q2 = [q[0] * q[0], 2.0 * q[0] * q[1], q[1] * q[1]];
        let mut g = [0.0; 5];
        for i in 0..3 {
            for j in 0..3 {
                g[i + j] += p[i] * q2[j] + sy * sy * h[i] * h[j];
            }
        }
        g
    }

    /// The reflection condition at polar angle `phi`: the cross product of the mirror image of
    /// the unit ray towards `E` with the unit ray towards `S` (zero on the line), and the dot
    /// product deciding real (> 0) or virtual (< 0), and `n·(towards E)`.
    #[inline]
    pub fn condition(&self, phi: f64) -> (f64, f64, f64) {
        let n = Vec2::new(phi.cos(), phi.sin());
        let p = n * self.r;
        let a = self.eye.dir_from(p);
        let b = self.source.dir_from(p);
        let m = 2.0 * a.dot(n) * n - a;
        (m.perp_dot(b), m.dot(b), a.dot(n))
    }

    /// The line condition `F = m × b̂` at `phi` and its exact derivative `dF/dφ`.
    #[inline]
    fn condition_slope(&self, phi: f64) -> (f64, f64) {
        let (s, c) = phi.sin_cos();
        let (n, t) = (Vec2::new(c, s), Vec2::new(-s, c));
        let p = n * self.r;
        // Unit direction towards a site and its derivative along the circle.
        let dir = |site: Site2| match site {
            Site2::At(q) => {
                let d = q - p;
                let len = d.length();
                let u = d / len;
                (u, -(t - u * u.dot(t)) * (self.r / len))
            }
            Site2::Toward(u) => (u, Vec2::ZERO),
        };
        let ((a, da), (b, db)) = (dir(self.eye), dir(self.source));
        let an = a.dot(n);
        let m = 2.0 * an * n - a;
        let dm = 2.0 * (da.dot(n) + a.dot(t)) * n + 2.0 * an * t - da;
        (m.perp_dot(b), dm.perp_dot(b) + m.perp_dot(db))
    }

    /// Newton's method (9), in the angle, on the line condition; `None` if it does not reach a
    /// zero. Converges linearly at double roots, quadratically elsewhere.
    fn polish(&self, mut phi: f64) -> Option<f64> {
        for _ in 0..80 {
            let (f, d) = self.condition_slope(phi);
            if f == 0.0 || d == 0.0 || !d.is_finite() {
                break;
            }
            let step = (f / d).clamp(-0.2, 0.2);
            phi -= step;
            if step.abs() <= 1e-16 * (1.0 + phi.abs()) {
                break;
            }
        }
        (self.condition(phi).0.abs() <= self.noise(phi)).then_some(phi)
    }

    /// How far from zero rounding alone can push the condition at `phi`: the directions towards
    /// `E` and `S` carry an error of about ε·(coordinate scale)/(distance).
    fn noise(&self, phi: f64) -> f64 {
        let p = Vec2::from_angle(phi) * self.r;
        let (mut scale, mut dmin) = (self.r, f64::INFINITY);
        for site in [self.eye, self.source] {
            if let Site2::At(q) = site {
                scale = scale.max(q.abs().max_element());
                dmin = dmin.min((q - p).length());
            }
        }
        1e-11 + 64.0 * f64::EPSILON * scale / dmin
    }

    /// The tangential balance `t·(â + b̂)` at `phi` (zero where the angles in and out are
    /// equal) and its derivative, for the bracketed search of the visible reflex.
    #[inline]
    fn balance(&self, phi: f64) -> (f64, f64) {
        let (s, c) = phi.sin_cos();
        let (n, t) = (Vec2::new(c, s), Vec2::new(-s, c));
        let p = n * self.r;
        let mut g = 0.0;
        let mut dg = 0.0;
        for site in [self.eye, self.source] {
            match site {
                Site2::At(q) => {
                    let d = q - p;
                    let len = d.length();
                    let u = d / len;
                    let tu = t.dot(u);
                    g += tu;
                    // d/dφ (t·u) = −n·u − (r/|d|)(1 − (t·u)²).
                    dg += -n.dot(u) - self.r / len * (1.0 - tu * tu);
                }
                Site2::Toward(u) => {
                    g += t.dot(u);
                    dg -= n.dot(u);
                }
            }
        }
        (g, dg)
    }

    /// Polar angle and visible half-width `acos(r/|q|)` of a site (π/2 at infinity).
    fn polar(&self, site: Site2) -> (f64, f64) {
        match site {
            Site2::At(q) => (q.y.atan2(q.x), (self.r / q.length()).clamp(-1.0, 1.0).acos()),
            Site2::Toward(d) => (d.y.atan2(d.x), std::f64::consts::FRAC_PI_2),
        }
    }

    /// The visible reflex (reflection on the outside), by a bracketed search: with the eye at
    /// polar angle 0 and the source at `σ ∈ [0, π]`, the reflex lies in
    /// `[max(0, σ − α_S), min(σ, α_E)]` (between the two directions and on the arcs both can
    /// see), where the balance changes sign from + to −. Returns the unit normal
    /// `(cos φ, sin φ)`; `None` in the forbidden region.
    #[inline]
    pub fn visible(&self) -> Option<Vec2> {
        if let (Site2::At(e), Site2::At(s)) = (self.eye, self.source)
            && let Some(n) = crate::batch::fast_visible(self.r, e.x, s.x, s.y)
        {
            return Some(n);
        }
        self.visible_bracketed().map(|phi| Vec2::from_angle(self.refine_line(phi)))
    }

    /// Finishes a solution with Newton steps on the line condition `m × b̂`, which measures the
    /// angle error directly (the balance does not, near grazing incidence); a step is kept only
    /// if it lowers the residual.
    fn refine_line(&self, mut phi: f64) -> f64 {
        for _ in 0..4 {
            let (f, d) = self.condition_slope(phi);
            if f == 0.0 || d == 0.0 || !d.is_finite() {
                break;
            }
            let next = phi - f / d;
            if self.condition(next).0.abs() >= f.abs() {
                break;
            }
            phi = next;
        }
        phi
    }

    fn visible_bracketed(&self) -> Option<f64> {
        if matches!(self.eye, Site2::At(e) if e.length() <= self.r)
            || matches!(self.source, Site2::At(s) if s.length() <= self.r)
        {
            return None;
        }
        let (_, alpha_e) = self.polar(self.eye);
        let (sigma, alpha_s) = self.polar(self.source);
        let (mut lo, mut hi) = ((sigma - alpha_s).max(0.0), sigma.min(alpha_e));
        if lo > hi {
            return None;
        }
        let (g_lo, g_hi) = (self.balance(lo).0, self.balance(hi).0);
        if g_lo < 0.0 || g_hi > 0.0 {
            return None;
        }
        let mut phi = 0.5 * (lo + hi);
        for _ in 0..100 {
            let (g, dg) = self.balance(phi);
            if g == 0.0 {
                break;
            }
            if g > 0.0 {
                lo = phi
            } else {
                hi = phi
            }
            let newton = phi - g / dg;
            let next = if newton > lo && newton < hi { newton } else { 0.5 * (lo + hi) };
            if (next - phi).abs() <= 1e-16 * (1.0 + phi.abs()) || hi - lo <= 1e-16 {
                phi = next;
                break;
            }
            phi = next;
        }
        Some(phi)
    }

    /// Every real solution, classified, ordered Outside, Inside, Virtual.
    pub fn solve(&self) -> Reflexes2 {
        let g = self.quartic();
        // Scale x = r ξ and normalise, so conditioning does not depend on units.
        let mut gs = [0.0; 5];
        let mut rk = 1.0;
        for k in 0..5 {
            gs[k] = g[k] * rk;
            rk *= self.r;
        }
        let big = gs.iter().fold(0.0f64, |m, c| m.max(c.abs()));
        if big == 0.0 || !big.is_finite() {
            return Reflexes2::default();
        }
        let gs = gs.map(|c| c / big);
        let mut found: Vec<Reflex2> = Vec::with_capacity(8);
        for &xi in real_roots_in(&gs, -1.0 - 1e-9, 1.0 + 1e-9).as_slice() {
            let base = xi.clamp(-1.0, 1.0).acos();
            for phi0 in [base, -base] {
                if let Some(phi) = self.polish(phi0) {
                    let (_, along, n_dot_a) = self.condition(phi);
                    let kind = if along < 0.0 {
                        ReflexKind::Virtual
                    } else if n_dot_a > 0.0 {
                        ReflexKind::Outside
                    } else {
                        ReflexKind::Inside
                    };
                    found.push(Reflex2 { phi: phi.rem_euclid(std::f64::consts::TAU), kind });
                }
            }
        }
        found.sort_by(|a, b| a.kind.cmp(&b.kind).then(a.phi.total_cmp(&b.phi)));
        let mut out = Reflexes2::default();
        // The bracketed search is authoritative for the visible reflex; the quartic's own
        // Outside candidates are duplicates of it (or spurious near the forbidden boundary).
        if let Some(n) = self.visible() {
            out.push(Reflex2 { phi: n.y.atan2(n.x).rem_euclid(std::f64::consts::TAU), kind: ReflexKind::Outside });
        }
        for r in found.into_iter().filter(|r| r.kind != ReflexKind::Outside) {
            out.push(r);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The paper's normalised coefficients (5), (6), (7).
    fn paper(r: f64, w: f64, source: Site2) -> Poly {
        let u = 2.0 / (r * r);
        match source {
            Site2::At(s) => {
                let v = 1.0 / s.length_squared();
                let (sx, sy) = (s.x, s.y);
                [
                    v * sy * sy - v * r * r * (1.0 + 2.0 * w * sx + w * w * sx * sx),
                    4.0 * sx * v + 2.0 * w * sx * sx * v + 2.0 * w,
                    v * (1.0 + 2.0 * w * sx) + w * w - 2.0 * u,
                    -2.0 * u * (v * sx + w),
                    u * u,
                ]
            }
            Site2::Toward(d) => {
                let (c, s) = (d.x, d.y);
                // (7) with c₃ = −2uw: the printed −2uw·s_x is a typo.
                [s * s - w * w * r * r * c * c, 2.0 * w * (1.0 + c * c), w * w - 2.0 * u, -2.0 * u * w, u * u]
            }
        }
    }

    fn same_up_to_scale(a: Poly, b: Poly) {
        let k = b[4] / a[4];
        for i in 0..5 {
            assert!((a[i] * k - b[i]).abs() < 1e-9 * b.iter().map(|x| x.abs()).fold(0.0, f64::max), "{a:?} ~ {b:?}");
        }
    }

    #[test]
    fn quartic_matches_the_papers_coefficients() {
        for (r, e, s) in
            [(1.0, 3.0, Vec2::new(2.0, 1.5)), (0.5, 7.0, Vec2::new(-3.0, 0.2)), (2.0, 2.5, Vec2::new(0.3, -0.4))]
        {
            let c = Canonical { r, eye: Site2::At(Vec2::new(e, 0.0)), w: 1.0 / e, source: Site2::At(s) };
            same_up_to_scale(c.quartic(), paper(r, 1.0 / e, Site2::At(s)));
            // (6): parallel projection.
            let c = Canonical { r, eye: Site2::Toward(Vec2::X), w: 0.0, source: Site2::At(s) };
            same_up_to_scale(c.quartic(), paper(r, 0.0, Site2::At(s)));
            // (7): source at infinity.
            let d = s.normalize();
            let c = Canonical { r, eye: Site2::At(Vec2::new(e, 0.0)), w: 1.0 / e, source: Site2::Toward(d) };
            same_up_to_scale(c.quartic(), paper(r, 1.0 / e, Site2::Toward(d)));
        }
    }

    #[test]
    fn equal_distances_give_the_half_angle_reflex() {
        // (8): |ME| = |MS| = 3, S at polar angle σ: the visible reflex is at σ/2.
        let sigma = 1.1f64;
        let c = Canonical {
            r: 1.0,
            eye: Site2::At(Vec2::new(3.0, 0.0)),
            w: 1.0 / 3.0,
            source: Site2::At(Vec2::from_angle(sigma) * 3.0),
        };
        let sols = c.solve();
        let outside: Vec<_> = sols.iter().filter(|s| s.kind == ReflexKind::Outside).collect();
        assert_eq!(outside.len(), 1);
        assert!((outside[0].phi - sigma / 2.0).abs() < 1e-13);
        assert!(sols.iter().any(|s| angle_diff(s.phi, sigma / 2.0 + std::f64::consts::PI) < 1e-12));
    }

    #[test]
    fn hyperbola_axis_points_match_equation_4() {
        // (4)/(17): the hyperbola meets the x-axis at x = r/(4e)(r ± √(r² + 8e²)), independent of S.
        let (r, e) = (1.0f64, 2.0f64);
        for sign in [1.0, -1.0] {
            let x = r / (4.0 * e) * (r + sign * (r * r + 8.0 * e * e).sqrt());
            for s in [Vec2::new(0.5, 2.0), Vec2::new(-3.0, 1.0)] {
                let num = 2.0 * e * x * x - r * r * (x + e);
                assert!(num.abs() < 1e-12, "the numerator of (3) vanishes: y = 0 for every S ({s})");
            }
        }
    }
}
