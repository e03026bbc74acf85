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
use alhazen_math::{Vec2, Vec3};
use std::f64::consts::PI;

/// The `cos^m` lobe around the mirror direction.
#[derive(Clone, Copy, Debug)]
pub struct PhongLobe {
    /// `m`.
    pub exponent: f64,
}

/// Normalised Phong.
pub type Phong = DiffuseSpecular<PhongLobe>;

fn mirror(v: Vec3) -> Vec3 {
    reflect(v, Vec3::new(0.0, 0.0, v.z.signum()))
}

impl SpecularLobe for PhongLobe {
    fn value(&self, v: Vec3, l: Vec3) -> f64 {
        (self.exponent + 2.0) / (2.0 * PI) * mirror(v).dot(l).max(0.0).powf(self.exponent)
    }

    fn pdf(&self, v: Vec3, l: Vec3) -> f64 {
        (self.exponent + 1.0) / (2.0 * PI) * mirror(v).dot(l).max(0.0).powf(self.exponent)
    }

    fn sample(&self, v: Vec3, u: Vec2) -> Option<Vec3> {
        let cos = u.x.powf(1.0 / (self.exponent + 1.0));
        let sin = (1.0 - cos * cos).max(0.0).sqrt();
        let phi = 2.0 * PI * u.y;
        Some(Frame::around(mirror(v)).to_world(Vec3::new(sin * phi.cos(), sin * phi.sin(), cos)))
    }
}
