//! Many points against one mirror and one eye (structure of arrays): the visible reflex of each.
//!
//! The kernel works in the canonical frame of [`crate::circle`]: Newton's method on the balance
//! of tangential components `t·(â + b̂) = 0` (angle in = angle out), started at the bisector of
//! the polar directions of `E` and `S` — exact when `|ME| = |MS|`, (8) — and stepping the unit
//! normal instead of the angle, so the loop has no trigonometry and no branches and the compiler
//! can vectorise it. A fixed number of steps is taken; every result is then checked (residual,
//! both rays on the outside), and the rare point that fails goes through the scalar bracketed
//! solver, which also decides the forbidden region. The answers are therefore the scalar
//! solver's, only faster.

use crate::circle::{Canonical, Site2};
use crate::{Cylinder, MirrorError, Sphere};
use alhazen_math::{Vec2, Vec3};

/// Points as three coordinate slices of equal length.
#[derive(Clone, Copy, Debug)]
pub struct PointsSoA<'a> {
    /// x coordinates.
    pub x: &'a [f64],
    /// y coordinates.
    pub y: &'a [f64],
    /// z coordinates.
    pub z: &'a [f64],
}

impl PointsSoA<'_> {
    fn len(&self) -> usize {
        self.x.len().min(self.y.len()).min(self.z.len())
    }

    fn get(&self, i: usize) -> Vec3 {
        Vec3::new(self.x[i], self.y[i], self.z[i])
    }
}

/// The visible reflexes of a batch: coordinates, and whether each point has one (points in the
/// forbidden region, or degenerate ones, have `visible[i] = false` and NaN coordinates).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ReflexesSoA {
    /// x coordinates.
    pub x: Vec<f64>,
    /// y coordinates.
    pub y: Vec<f64>,
    /// z coordinates.
    pub z: Vec<f64>,
    /// Whether the point has a visible reflex.
    pub visible: Vec<bool>,
}

impl ReflexesSoA {
    fn reset(&mut self, n: usize) {
        for v in [&mut self.x, &mut self.y, &mut self.z] {
            v.clear();
            v.resize(n, f64::NAN);
        }
        self.visible.clear();
        self.visible.resize(n, false);
    }

    /// Stores the scalar solver's answer for a point the fast kernel left undecided.
    fn set_from_scalar(&mut self, i: usize, answer: Result<Option<crate::Reflex>, MirrorError>) {
        if let Ok(Some(v)) = answer {
            self.set(i, v.point);
        }
    }

    fn set(&mut self, i: usize, p: Vec3) {
        (self.x[i], self.y[i], self.z[i]) = (p.x, p.y, p.z);
        self.visible[i] = true;
    }
}

/// The §2.2 forbidden region in the canonical frame: the source inside the circle, or the
/// segment from the eye to it passing through the disk.
#[inline(always)]
fn forbidden(r: f64, e: f64, sx: f64, sy: f64) -> bool {
    let r2 = r * r;
    if sx * sx + sy * sy <= r2 {
        return true;
    }
    // Closest approach of E + t (S − E), t ∈ [0, 1], to the centre.
    let (dx, dy) = (sx - e, sy);
    let t = (-e * dx / (dx * dx + dy * dy)).clamp(0.0, 1.0);
    let (qx, qy) = (e + t * dx, t * dy);
    qx * qx + qy * qy < r2
}

/// The starting point of the fast kernel: `t = tan(φ₀/2)` for `φ₀ = σ/2`, the bisector of the
/// polar directions of `E` (angle 0) and `S` (angle `σ`) — exact when `|ME| = |MS|`, (8).
#[inline(always)]
fn start(sx: f64, sy: f64) -> f64 {
    let sl = (sx * sx + sy * sy).sqrt();
    // tan(σ/2), then tan(σ/4) by the half-angle formula.
    let half = if sl + sx > 0.0 { sy / (sl + sx) } else { 1e150 };
    half / (1.0 + (1.0 + half * half).sqrt())
}

/// `steps` Newton steps on the tangential balance `t·(â + b̂) = 0`, in the rational
/// parameter `t = tan(φ/2)` of (14) (no trigonometry, no normalisation): source `(sx, sy ≥ 0)`,
/// eye `(e, 0)`, radius `r`. Returns the new `t` and whether the balance before the last step
/// was already small enough for the last step to finish it, with both rays on the outside.
#[inline(always)]
fn kernel(r: f64, e: f64, sx: f64, sy: f64, mut t: f64, steps: usize) -> (f64, bool) {
    let mut ok = false;
    for _ in 0..steps {
        // Everything is scaled by u = 1 + t² (the denominator of (14)), which cancels in the
        // unit vectors: the mirror point is r(1 − t², 2t)/u, so u·(E − R) and u·(S − R) are
        // polynomial in t. Two square roots and two divisions a step.
        let t2 = t * t;
        let (u, ct, st) = (1.0 + t2, 1.0 - t2, 2.0 * t);
        let (dex, dey) = (e * u - r * ct, -r * st);
        let (dsx, dsy) = (sx * u - r * ct, sy * u - r * st);
        let (la, lb) = ((dex * dex + dey * dey).sqrt(), (dsx * dsx + dsy * dsy).sqrt());
        let inv = 1.0 / (la * lb);
        let (ie, is) = (lb * inv, la * inv);
        let (ax, ay, bx, by) = (dex * ie, dey * ie, dsx * is, dsy * is);
        // u·(tangential) and u·(normal) components of the unit rays.
        let (ta, tb) = (-st * ax + ct * ay, -st * bx + ct * by);
        let (na, nb) = (ct * ax + st * ay, ct * bx + st * by);
        let g = ta + tb;
        // u²·dg/dφ with the true distances |E − R| = la/u, |S − R| = lb/u.
        let dg = -u * (na + nb) - r * u * (ie * (u * u - ta * ta) + is * (u * u - tb * tb));
        // dφ = 2 dt / u: Newton in t.
        t -= g * u * u / (2.0 * dg);
        // Quadratic convergence: a balance below 1e-9 before this step is squared by it. Near
        // grazing (n·â < 1e-3) the balance's rounding alone is worth 1e-13 rad of angle: those
        // points go to the scalar solver, which finishes on the line condition instead.
        ok = g.abs() < 1e-9 * u && na > 1e-3 * u && nb > 1e-3 * u;
    }
    (t, ok)
}

/// The unit normal `(cos φ, sin φ)` for `t = tan(φ/2)`.
#[inline(always)]
fn normal_of(t: f64) -> (f64, f64) {
    let k = 1.0 / (1.0 + t * t);
    ((1.0 - t * t) * k, 2.0 * t * k)
}

/// Scratch arrays of the canonical problems of a batch.
#[derive(Default)]
struct Canon {
    sx: Vec<f64>,
    sy: Vec<f64>,
    t: Vec<f64>,
    ok: Vec<bool>,
}

/// Newton steps of the first pass; the few points not converged get more.
const FIRST: usize = 3;
const SECOND: usize = 3;

impl Canon {
    /// Runs the kernel over all problems, with AVX-512 or AVX2 where the processor has them (the same
    /// arithmetic in wider registers: results are bit-identical, see the test
    /// `batch_agrees_with_scalar`).
    #[allow(unsafe_code)]
    fn solve(&mut self, r: f64, e: f64) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx512f") {
            // SAFETY: the processor supports AVX-512F, checked just above.
            unsafe { self.solve_avx512(r, e) };
            return;
        }
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the processor supports AVX2, checked just above; `solve_avx2` only enables
            // that instruction set for the same safe code.
            unsafe { self.solve_avx2(r, e) };
            return;
        }
        self.solve_portable(r, e);
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn solve_avx2(&mut self, r: f64, e: f64) {
        self.solve_portable(r, e);
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f")]
    fn solve_avx512(&mut self, r: f64, e: f64) {
        self.solve_portable(r, e);
    }

    /// The kernel over all problems (a loop without calls or early exits, which the compiler
    /// vectorises), then again over the stragglers.
    #[inline(always)]
    fn solve_portable(&mut self, r: f64, e: f64) {
        let n = self.sx.len();
        self.t.resize(n, 0.0);
        self.ok.resize(n, false);
        for i in 0..n {
            let (t, ok) = kernel(r, e, self.sx[i], self.sy[i], start(self.sx[i], self.sy[i]), FIRST);
            self.t[i] = t;
            self.ok[i] = ok;
        }
        for i in 0..n {
            if !self.ok[i] {
                let (t, ok) = kernel(r, e, self.sx[i], self.sy[i], self.t[i], SECOND);
                self.t[i] = t;
                self.ok[i] = ok;
            }
        }
        for i in 0..n {
            self.ok[i] &= !forbidden(r, e, self.sx[i], self.sy[i]) && self.sy[i] > 1e-9 * r && self.t[i].is_finite();
        }
    }

    fn normal(&self, i: usize) -> (f64, f64) {
        normal_of(self.t[i])
    }
}

/// The visible reflex of the canonical problem by the fast kernel, as the unit normal
/// `(cos φ, sin φ)`, if it converges (`None` means: ask the bracketed solver).
pub(crate) fn fast_visible(r: f64, e: f64, sx: f64, sy: f64) -> Option<Vec2> {
    let (t, ok) = kernel(r, e, sx, sy, start(sx, sy), FIRST);
    let (t, ok) = if ok { (t, ok) } else { kernel(r, e, sx, sy, t, SECOND) };
    (ok && t.is_finite() && sy > 1e-9 * r && !forbidden(r, e, sx, sy)).then(|| {
        let (c, s) = normal_of(t);
        Vec2::new(c, s)
    })
}

impl Sphere {
    /// The visible reflex of every point seen from the finite `eye`.
    pub fn visible_reflexes_batch(
        &self,
        eye: Vec3,
        points: PointsSoA,
        out: &mut ReflexesSoA,
    ) -> Result<(), MirrorError> {
        self.check_eye(eye)?;
        let n = points.len();
        out.reset(n);
        let (m, r) = (self.center, self.radius);
        let d = eye - m;
        let e = d.length();
        let xh = d / e;
        let mut cn = Canon::default();
        for i in 0..n {
            let rel = points.get(i) - m;
            let sx = rel.dot(xh);
            cn.sx.push(sx);
            cn.sy.push((rel - xh * sx).length());
        }
        cn.solve(r, e);
        for i in 0..n {
            let (sx, sy) = (cn.sx[i], cn.sy[i]);
            if cn.ok[i] {
                let perp = (points.get(i) - m) - xh * sx;
                let (c, s) = cn.normal(i);
                out.set(i, m + (xh * c + perp * (s / sy)) * r);
            } else if !forbidden(r, e, sx, sy) {
                out.set_from_scalar(i, self.visible_reflex(crate::Site::At(eye), crate::Site::At(points.get(i))));
            }
        }
        Ok(())
    }
}

impl Cylinder {
    /// The visible reflex of every point seen from the finite `eye`.
    pub fn visible_reflexes_batch(
        &self,
        eye: Vec3,
        points: PointsSoA,
        out: &mut ReflexesSoA,
    ) -> Result<(), MirrorError> {
        self.check_eye(eye)?;
        let n = points.len();
        out.reset(n);
        let a = self.axis.normalize();
        let (m, r) = (self.center, self.radius);
        let he = (eye - m).dot(a);
        let d = (eye - m) - a * he;
        let e = d.length();
        let xh = d / e;
        let yh = a.cross(xh);
        let mut cn = Canon::default();
        for i in 0..n {
            let rel = points.get(i) - m;
            cn.sx.push(rel.dot(xh));
            cn.sy.push(rel.dot(yh).abs());
        }
        cn.solve(r, e);
        for i in 0..n {
            let (sx, sy) = (cn.sx[i], cn.sy[i]);
            if cn.ok[i] {
                let rel = points.get(i) - m;
                let (c, s) = cn.normal(i);
                let s = s.copysign(rel.dot(yh));
                let foot = Vec2::new(c, s) * r;
                let (le, ls) = ((Vec2::new(e, 0.0) - foot).length(), (Vec2::new(sx, rel.dot(yh)) - foot).length());
                let h = he + (rel.dot(a) - he) * le / (le + ls);
                out.set(i, m + (xh * c + yh * s) * r + a * h);
            } else if !forbidden(r, e, sx, sy) {
                out.set_from_scalar(i, self.visible_reflex(crate::Site::At(eye), crate::Site::At(points.get(i))));
            }
        }
        Ok(())
    }
}

/// The visible reflex on a circle in canonical position, by the scalar bracketed solver (for
/// benchmarks and tests of the kernel).
pub fn canonical_visible(r: f64, e: f64, s: Vec2) -> Option<f64> {
    Canonical { r, eye: Site2::At(Vec2::new(e, 0.0)), w: 1.0 / e, source: Site2::At(s) }
        .visible()
        .map(|n| n.y.atan2(n.x))
}
