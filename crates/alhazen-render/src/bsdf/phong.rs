//! Energy-normalised Phong (Lafortune–Willems 1994) built on the course's Phong model:
//! `ρ = kd·albedo/π + ks·(m+2)/(2π)·max(0, ⟨r, v⟩)^m` with `r` the mirror of `l`, times the
//! same-side factor. The `(m+2)/(2π)` factor makes the lobe reflect exactly `ks` at normal
//! incidence and less elsewhere, so `kd + ks ≤ 1` conserves energy. The course's Phong is not
//! reciprocal ("does not satisfy the Helmholtz principle"): its term is added to radiance, i.e.
//! divided by `⟨n,l⟩` as a BRDF. This normalised lobe is a BRDF itself and is symmetric.
//!
//! Parameters: `albedo`, weights `kd`, `ks`, exponent `m`.

use super::{BsdfSample, Frame, cosine_hemisphere, cosine_pdf, lobe_probability, reflect, same_side};
use alhazen_math::{Vec2, Vec3, color::luminance};
use std::f64::consts::{FRAC_1_PI, PI};

/// Normalised Phong.
#[derive(Clone, Copy, Debug)]
pub struct Phong {
    /// Diffuse colour times `kd`.
    pub diffuse: Vec3,
    /// `ks`.
    pub ks: f64,
    /// `m`.
    pub exponent: f64,
}

impl Phong {
    fn lobe(&self, v: Vec3, l: Vec3) -> f64 {
        let r = reflect(v, Vec3::new(0.0, 0.0, v.z.signum()));
        r.dot(l).max(0.0).powf(self.exponent)
    }

    fn p_diffuse(&self) -> f64 {
        lobe_probability(luminance(self.diffuse), self.ks)
    }

    /// `ρ`.
    pub fn eval(&self, v: Vec3, l: Vec3) -> Vec3 {
        if !same_side(v, l) {
            return Vec3::ZERO;
        }
        let m = self.exponent;
        self.diffuse * FRAC_1_PI + Vec3::splat(self.ks * (m + 2.0) / (2.0 * PI) * self.lobe(v, l))
    }

    /// Mixture of the cosine density and the `cos^m` lobe around the mirror direction.
    pub fn pdf(&self, v: Vec3, l: Vec3) -> f64 {
        if !same_side(v, l) {
            return 0.0;
        }
        let pd = self.p_diffuse();
        let m = self.exponent;
        pd * cosine_pdf(v, l) + (1.0 - pd) * (m + 1.0) / (2.0 * PI) * self.lobe(v, l)
    }

    /// Picks the diffuse or the specular lobe by `uc`.
    pub fn sample(&self, v: Vec3, uc: f64, u: Vec2) -> Option<BsdfSample> {
        let l = if uc < self.p_diffuse() {
            cosine_hemisphere(u, v)
        } else {
            let r = reflect(v, Vec3::new(0.0, 0.0, v.z.signum()));
            let cos = u.x.powf(1.0 / (self.exponent + 1.0));
            let sin = (1.0 - cos * cos).max(0.0).sqrt();
            let phi = 2.0 * PI * u.y;
            Frame::new(r, Vec3::X).to_world(Vec3::new(sin * phi.cos(), sin * phi.sin(), cos))
        };
        let pdf = self.pdf(v, l);
        (pdf > 0.0).then(|| BsdfSample { l, f: self.eval(v, l), pdf, delta: false, eta: 1.0, dispersive: false })
    }
}
