//! Energy-normalised Phong (Lafortune–Willems 1994) built on the course's Phong model:
//! `ρ = kd·albedo/π + ks·(m+2)/(2π)·max(0, ⟨r, v⟩)^m` with `r` the mirror of `l`, times the
//! same-side factor. The `(m+2)/(2π)` factor makes the lobe reflect exactly `ks` at normal
//! incidence and less elsewhere, so `kd + ks ≤ 1` conserves energy. The course's Phong is not
//! reciprocal ("does not satisfy the Helmholtz principle"): its term is added to radiance, i.e.
//! divided by `⟨n,l⟩` as a BRDF. This normalised lobe is a BRDF itself and is symmetric.
//!
//! Parameters: `albedo`, weights `kd`, `ks`, exponent `m`. Sampling: `cos^m` around the mirror
//! direction.

use super::layered::{DiffuseSpecular, SpecularLobe};
use super::{Frame, reflect};
use alhazen_math::elementary::pow;
use alhazen_math::{Vec2, Vec3, sin_cos_turns};
use std::f64::consts::PI;

/// The `cos^m` lobe around the mirror direction.
#[derive(Clone, Copy, Debug)]
pub struct PhongLobe {
    /// `m`.
    pub exponent: f64,
}

/// Normalised Phong.
pub type Phong = DiffuseSpecular<PhongLobe>;

#[inline(always)]
fn mirror(v: Vec3) -> Vec3 {
    reflect(v, Vec3::new(0.0, 0.0, v.z.signum()))
}

impl SpecularLobe for PhongLobe {
    #[inline(always)]
    fn value(&self, v: Vec3, l: Vec3) -> f64 {
        self.value_pdf(v, l).0
    }

    #[inline(always)]
    fn pdf(&self, v: Vec3, l: Vec3) -> f64 {
        self.value_pdf(v, l).1
    }

    /// `max(0, ⟨r, l⟩)^m` once, by our own [`pow`] (no library call: the same bits on every
    /// processor).
    #[inline(always)]
    fn value_pdf(&self, v: Vec3, l: Vec3) -> (f64, f64) {
        let power = pow(mirror(v).dot(l).max(0.0), self.exponent);
        ((self.exponent + 2.0) / (2.0 * PI) * power, (self.exponent + 1.0) / (2.0 * PI) * power)
    }

    #[inline(always)]
    fn sample(&self, v: Vec3, u: Vec2) -> Option<Vec3> {
        let cos = pow(u.x, 1.0 / (self.exponent + 1.0));
        let sin = (1.0 - cos * cos).max(0.0).sqrt();
        let (sin_phi, cos_phi) = sin_cos_turns(u.y);
        Some(Frame::around(mirror(v)).to_world(Vec3::new(sin * cos_phi, sin * sin_phi, cos)))
    }
}
