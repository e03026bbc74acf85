//! Many points against one mirror and one eye (structure of arrays): the visible reflex of each.
//!
//! The kernel works in the canonical frame of [`crate::circle`], in the rational parameter
//! `t = tan(φ/2)` of (14), with no trigonometry and no branches so the compiler vectorises it:
//! 1. start at the bisector of the polar directions of `E` and `S` — exact when `|ME| = |MS|`,
//!    (8) — corrected to first order in `r/|ME|`, `r/|MS|`;
//! 2. Newton steps on the squared balance `Ta²·B − Tb²·A`, a polynomial in `t` (no square roots);
//! 3. one Newton step on the balance of tangential components `t·(â + b̂) = 0` (angle in = angle
//!    out) itself, which also decides convergence from the size of the balance and the angles of
//!    incidence (`converged`).
//!
//! Points not converged get more checked steps one by one; the rare point that still fails goes
//! through the scalar bracketed solver, which also decides the forbidden region. The answers are
//! therefore the scalar solver's to 1e-13 rad, only faster.

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

    #[inline(always)]
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

    fn set_none(&mut self, i: usize) {
        (self.x[i], self.y[i], self.z[i]) = (f64::NAN, f64::NAN, f64::NAN);
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

/// The starting point of the fast kernel, as `t = tan(φ₀/2)`: the bisector `σ/2` of the polar
/// directions of `E` (angle 0) and `S` (angle `σ`) — exact when `|ME| = |MS|`, (8) — moved by
/// one Newton step of the reflection condition linearised in `r/|ME|` and `r/|MS|`:
/// `φ₀ = σ/2 + δ`, `δ = −r sin(σ/2) (1/e − 1/s) / (2 + r cos(σ/2) (1/e + 1/s))`. Saves about
/// one step; two square roots and one division.
#[inline(always)]
fn start(r: f64, e: f64, sx: f64, sy: f64) -> f64 {
    let s = (sx * sx + sy * sy).sqrt();
    // The bisector direction (s + sx, sy) = |b|·(cos σ/2, sin σ/2); tan(σ/4) = sy/(|b| + s + sx).
    let bx = s + sx;
    let b = (bx * bx + sy * sy).sqrt();
    let (t0_num, t0_den) = (sy, b + bx);
    // tan(δ/2) ≈ δ/2 with both terms of δ multiplied by |b|·s·e.
    let (tau_num, tau_den) = (r * sy * (e - s), 2.0 * (2.0 * b * s * e + r * bx * (s + e)));
    // tan(σ/4 + δ/2) by the addition formula, as one fraction.
    (t0_num * tau_den + tau_num * t0_den) / (t0_den * tau_den - t0_num * tau_num)
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
        // polynomial in t.
        let t2 = t * t;
        let (u, ct, st) = (1.0 + t2, 1.0 - t2, 2.0 * t);
        let (dex, dey) = (e * u - r * ct, -r * st);
        let (dsx, dsy) = (sx * u - r * ct, sy * u - r * st);
        let (aa, bb) = (dex * dex + dey * dey, dsx * dsx + dsy * dsy);
        let (la, lb) = (aa.sqrt(), bb.sqrt());
        // Tangential and normal components (times u·la, u·lb): with â = (E − R)/|E − R|, the
        // balance is g = ta/la + tb/lb and, since ta² + na² = u²·aa, its derivative is
        // u²·dg/dφ = −u (na/la + nb/lb) − r u (na²/(aa la) + nb²/(bb lb)).
        let (ta, tb) = (-st * dex + ct * dey, -st * dsx + ct * dsy);
        let (na, nb) = (ct * dex + st * dey, ct * dsx + st * dsy);
        // Both multiplied by la·lb·aa·bb: one division a step, two square roots.
        let g_ab = ta * lb + tb * la;
        let ab = aa * bb;
        let slope = (na * lb + nb * la) * ab + r * (na * na * lb * bb + nb * nb * la * aa);
        // dφ = 2 dt / u: Newton in t.
        t += u * g_ab * ab / (2.0 * slope);
        ok = converged(g_ab, (na, la, aa), (nb, lb, bb), u);
    }
    (t, ok)
}

/// One Newton step on the squared balance `h = Ta²·B − Tb²·A` (the kernel's tangential
/// components `Ta`, `Tb` and squared lengths `A`, `B` of `u·(E − R)`, `u·(S − R)`): a polynomial
/// in `t` whose factor `Ta·√B + Tb·√A` is the kernel's balance, so near the visible reflex it
/// has the same root — without square roots. The kernel's own step finishes and checks.
#[inline(always)]
fn squared_balance_step(r: f64, e: f64, sx: f64, sy: f64, t: f64) -> f64 {
    let t2 = t * t;
    let (u, ct, st) = (1.0 + t2, 1.0 - t2, 2.0 * t);
    // The vectors and their derivatives in t.
    let (dex, dey, dex_t, dey_t) = (e * u - r * ct, -r * st, 2.0 * t * (e + r), -2.0 * r);
    let (dsx, dsy, dsx_t, dsy_t) = (sx * u - r * ct, sy * u - r * st, 2.0 * t * (sx + r), 2.0 * (t * sy - r));
    let tangential =
        |x: f64, y: f64, x_t: f64, y_t: f64| (-st * x + ct * y, -2.0 * x - st * x_t - 2.0 * t * y + ct * y_t);
    let (ta, ta_t) = tangential(dex, dey, dex_t, dey_t);
    let (tb, tb_t) = tangential(dsx, dsy, dsx_t, dsy_t);
    let (aa, aa_t) = (dex * dex + dey * dey, 2.0 * (dex * dex_t + dey * dey_t));
    let (bb, bb_t) = (dsx * dsx + dsy * dsy, 2.0 * (dsx * dsx_t + dsy * dsy_t));
    let h = ta * ta * bb - tb * tb * aa;
    let h_t = 2.0 * ta * ta_t * bb + ta * ta * bb_t - 2.0 * tb * tb_t * aa - tb * tb * aa_t;
    t - h / h_t
}

/// Whether the Newton step taken from the balance `g = g_ab/(la·lb)` lands within 1e-13 rad.
/// With `m` the smaller of the two cosines of incidence, the step's error is about `C g²` with
/// `C` growing like `m⁻³` towards grazing incidence, so ask `g² < 10⁻¹⁴ m³` (measured on 400,000
/// configurations with radii over six decades and near-grazing rays: worst error 3e-14 rad).
/// Below `m = 10⁻³` the balance's rounding alone is worth 1e-13 rad: those points go to the
/// scalar solver, which finishes on the line condition instead. In the kernel's scaled
/// quantities (cosine `n/(u·l)`, `l² = ll`), without divisions.
#[inline(always)]
fn converged(g_ab: f64, (na, la, aa): (f64, f64, f64), (nb, lb, bb): (f64, f64, f64), u: f64) -> bool {
    let g2u = g_ab * g_ab * u;
    let c = 1e-14;
    na > 1e-3 * u * la && nb > 1e-3 * u * lb && g2u * la < c * na * na * na * bb && g2u * lb < c * nb * nb * nb * aa
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

/// Steps on the squared balance before the kernel's checked step (without square roots, they
/// bring 93 % of scene-like points close enough for one checked step to finish, 4 steps 99 %,
/// but the fourth costs more than the stragglers); the points not converged get up to `MORE`
/// checked steps one by one.
const SQUARED: usize = 3;
const MORE: usize = 4;

/// The kernel's start and the unchecked steps on the squared balance.
#[inline(always)]
fn approach(r: f64, e: f64, sx: f64, sy: f64, squared: usize) -> f64 {
    let mut t = start(r, e, sx, sy);
    for _ in 0..squared {
        t = squared_balance_step(r, e, sx, sy, t);
    }
    t
}

/// A loop to compile for the widest vector instructions the processor has.
trait VectorLoop {
    /// The work; implementations are `#[inline(always)]`, so they are compiled inside the
    /// callers below, with their instruction sets.
    fn run(self);
}

/// Runs `job` compiled for AVX-512 or AVX2 where the processor has them: the same arithmetic in
/// wider registers (no fused multiply–add is introduced), so results do not depend on it.
#[allow(unsafe_code)]
fn with_widest_vectors(job: impl VectorLoop) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx512f") {
        // SAFETY: the processor supports AVX-512F, checked just above.
        unsafe { on_avx512(job) };
        return;
    }
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the processor supports AVX2, checked just above; `on_avx2` only enables that
        // instruction set for the same safe code.
        unsafe { on_avx2(job) };
        return;
    }
    job.run();
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn on_avx2(job: impl VectorLoop) {
    job.run();
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn on_avx512(job: impl VectorLoop) {
    job.run();
}

impl Canon {
    fn with_len(n: usize) -> Canon {
        Canon { sx: vec![0.0; n], sy: vec![0.0; n], t: vec![0.0; n], ok: vec![false; n] }
    }

    /// The kernel over all problems (a loop without calls or early exits, which the compiler
    /// vectorises), then again over the stragglers.
    #[inline(always)]
    fn solve(&mut self, r: f64, e: f64) {
        let n = self.sx.len();
        let (sx, sy, ts, oks) = (&self.sx[..n], &self.sy[..n], &mut self.t[..n], &mut self.ok[..n]);
        for i in 0..n {
            (ts[i], oks[i]) = kernel(r, e, sx[i], sy[i], approach(r, e, sx[i], sy[i], SQUARED), 1);
        }
        for i in 0..n {
            if !oks[i] {
                (ts[i], oks[i]) = finish_straggler(r, e, sx[i], sy[i], ts[i]);
            }
        }
        for i in 0..n {
            oks[i] &= !forbidden(r, e, sx[i], sy[i]) && sy[i] > 1e-9 * r && ts[i].is_finite();
        }
    }
}

/// The visible reflex of the canonical problem by the fast kernel, as the unit normal
/// `(cos φ, sin φ)`, if it converges (`None` means: ask the bracketed solver).
pub(crate) fn fast_visible(r: f64, e: f64, sx: f64, sy: f64) -> Option<Vec2> {
    if sy <= 1e-9 * r || forbidden(r, e, sx, sy) {
        return None;
    }
    let (t, ok) = newton_until_converged(r, e, sx, sy, approach(r, e, sx, sy, SCALAR_SQUARED), 1 + MORE);
    (ok && t.is_finite()).then(|| {
        let (c, s) = normal_of(t);
        Vec2::new(c, s)
    })
}

/// More checked steps for a point the vector pass left unconverged. Not inlined: a call keeps
/// the compiler from running this loop masked over every point of the batch.
#[inline(never)]
fn finish_straggler(r: f64, e: f64, sx: f64, sy: f64, t: f64) -> (f64, bool) {
    newton_until_converged(r, e, sx, sy, t, MORE)
}

/// Steps on the squared balance in the scalar path, where each checked step costs its latency.
const SCALAR_SQUARED: usize = 1;

/// Newton steps one at a time until converged, at most `steps` (the scalar path: latency, not
/// width, is what costs there).
#[inline(always)]
fn newton_until_converged(r: f64, e: f64, sx: f64, sy: f64, mut t: f64, steps: usize) -> (f64, bool) {
    for _ in 0..steps {
        let (next, ok) = kernel(r, e, sx, sy, t, 1);
        t = next;
        if ok {
            return (t, true);
        }
    }
    (t, false)
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
        let (m, r) = (self.center, self.radius);
        let e = (eye - m).length();
        let frame = SphereFrame { m, r, xh: (eye - m) / e };
        run_batch(frame, r, e, points, out, |p| self.visible_reflex(crate::Site::At(eye), crate::Site::At(p)));
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
        let a = self.axis.normalize();
        let (m, r) = (self.center, self.radius);
        let he = (eye - m).dot(a);
        let d = (eye - m) - a * he;
        let e = d.length();
        let xh = d / e;
        let frame = CylinderFrame { m, a, xh, yh: a.cross(xh), he, r, e };
        run_batch(frame, r, e, points, out, |p| self.visible_reflex(crate::Site::At(eye), crate::Site::At(p)));
        Ok(())
    }
}

/// How a mirror turns a point into its canonical problem `(x, y ≥ 0)` and the solution `t` of
/// that problem back into the reflex in space.
trait CanonicalFrame: Copy {
    fn canonical(&self, p: Vec3) -> (f64, f64);
    fn lift(&self, p: Vec3, t: f64, sy: f64) -> Vec3;
}

/// The kernel over a batch with the widest vectors, then the scalar solver (which also decides
/// the forbidden region) for the points it left undecided.
fn run_batch<F: CanonicalFrame>(
    frame: F,
    r: f64,
    e: f64,
    points: PointsSoA,
    out: &mut ReflexesSoA,
    scalar: impl Fn(Vec3) -> Result<Option<crate::Reflex>, MirrorError>,
) {
    let n = points.len();
    out.reset(n);
    let mut cn = Canon::with_len(n);
    with_widest_vectors(BatchLoop { frame, r, e, points, cn: &mut cn, out: &mut *out });
    for i in 0..n {
        out.visible[i] = cn.ok[i];
        if !cn.ok[i] {
            out.set_none(i);
            if !forbidden(r, e, cn.sx[i], cn.sy[i]) {
                out.set_from_scalar(i, scalar(points.get(i)));
            }
        }
    }
}

/// A batch: canonical coordinates, the kernel, and the reflexes back in space, in one loop
/// each that the compiler vectorises.
struct BatchLoop<'a, F> {
    frame: F,
    r: f64,
    e: f64,
    points: PointsSoA<'a>,
    cn: &'a mut Canon,
    out: &'a mut ReflexesSoA,
}

impl<F: CanonicalFrame> VectorLoop for BatchLoop<'_, F> {
    #[inline(always)]
    fn run(self) {
        let n = self.cn.sx.len();
        for i in 0..n {
            (self.cn.sx[i], self.cn.sy[i]) = self.frame.canonical(self.points.get(i));
        }
        self.cn.solve(self.r, self.e);
        for i in 0..n {
            let p = self.frame.lift(self.points.get(i), self.cn.t[i], self.cn.sy[i]);
            (self.out.x[i], self.out.y[i], self.out.z[i]) = (p.x, p.y, p.z);
        }
    }
}

/// The sphere's plane MES: x̂ towards the eye, the source at distance |perp| from the axis.
#[derive(Clone, Copy)]
struct SphereFrame {
    m: Vec3,
    r: f64,
    xh: Vec3,
}

impl SphereFrame {
    #[inline(always)]
    fn perp(&self, p: Vec3) -> (f64, Vec3) {
        let rel = p - self.m;
        let sx = rel.dot(self.xh);
        (sx, rel - self.xh * sx)
    }
}

impl CanonicalFrame for SphereFrame {
    #[inline(always)]
    fn canonical(&self, p: Vec3) -> (f64, f64) {
        let (sx, perp) = self.perp(p);
        (sx, perp.length())
    }

    #[inline(always)]
    fn lift(&self, p: Vec3, t: f64, sy: f64) -> Vec3 {
        // The normal (c, s) of (14) and ŷ = perp/|perp|, with one division.
        let inv = 1.0 / ((1.0 + t * t) * sy);
        let (c, s_over_sy) = ((1.0 - t * t) * sy * inv, 2.0 * t * inv);
        self.m + (self.xh * c + self.perp(p).1 * s_over_sy) * self.r
    }
}

/// A cylinder's frame: centre, unit axis, x̂ towards the eye's projection, ŷ = a × x̂, the
/// eye's height, the radius and the eye's distance from the axis.
#[derive(Clone, Copy)]
struct CylinderFrame {
    m: Vec3,
    a: Vec3,
    xh: Vec3,
    yh: Vec3,
    he: f64,
    r: f64,
    e: f64,
}

impl CylinderFrame {
    /// Canonical x, signed y and height of a point.
    #[inline(always)]
    fn project(&self, p: Vec3) -> (f64, f64, f64) {
        let rel = p - self.m;
        (rel.dot(self.xh), rel.dot(self.yh), rel.dot(self.a))
    }
}

impl CanonicalFrame for CylinderFrame {
    #[inline(always)]
    fn canonical(&self, p: Vec3) -> (f64, f64) {
        let (sx, sy, _) = self.project(p);
        (sx, sy.abs())
    }

    #[inline(always)]
    fn lift(&self, p: Vec3, t: f64, _: f64) -> Vec3 {
        let (sx, sy, hs) = self.project(p);
        let (c, s) = normal_of(t);
        let s = s.copysign(sy);
        // (10): the unfolded path E → R → S is straight.
        let (fx, fy) = (c * self.r, s * self.r);
        let le = ((self.e - fx) * (self.e - fx) + fy * fy).sqrt();
        let ls = ((sx - fx) * (sx - fx) + (sy - fy) * (sy - fy)).sqrt();
        let h = self.he + (hs - self.he) * le / (le + ls);
        self.m + (self.xh * c + self.yh * s) * self.r + self.a * h
    }
}

/// The visible reflex on a circle in canonical position, by the scalar bracketed solver (for
/// benchmarks and tests of the kernel).
pub fn canonical_visible(r: f64, e: f64, s: Vec2) -> Option<f64> {
    Canonical { r, eye: Site2::At(Vec2::new(e, 0.0)), w: 1.0 / e, source: Site2::At(s) }
        .visible()
        .map(|n| n.y.atan2(n.x))
}
