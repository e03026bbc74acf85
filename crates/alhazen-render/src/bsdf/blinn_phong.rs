//! Energy-normalised, reciprocal Blinn–Phong with the course's anisotropy.
//!
//! The course's lobe is `⟨ĥ, n⟩^{2m}` with `ĥ ∝ P₀w + P₁w + a·P₂w`, `w = l + v`: in the frame
//! (scratch direction, cross direction, normal), `ĥ ∝ (h_s, a·h_t, h_n)`. We normalise it as a
//! density of half vectors, `D_a(h) = (2m+1)/(2π) ⟨ĥ,n⟩^{2m} · a/‖(h_s, a h_t, h_n)‖³` (the
//! isotropic `cos^{2m}` density carried through the stretch `h ↦ ĥ`, so `∫ D_a dω = 1`), and use
//! the Ashikhmin–Shirley denominator: `ρ_s = D_a(h) / (4 ⟨h,l⟩ max(⟨n,l⟩, ⟨n,v⟩))`. It is
//! symmetric in `l, v` (Helmholtz) and `∫ ρ_s cos ≤ 1`. `a = 1` is plain Blinn–Phong.
//!
//! Parameters: `albedo`, `kd`, `ks`, exponent `m`, anisotropy `a ∈ (0, 1]`; the tangent frame's
//! `s` axis is the scratch direction.

use super::{BsdfSample, cosine_hemisphere, cosine_pdf, lobe_probability, reflect, same_side};
use alhazen_math::{Vec2, Vec3, color::luminance};
use std::f64::consts::{FRAC_1_PI, PI};

/// Normalised anisotropic Blinn–Phong.
#[derive(Clone, Copy, Debug)]
pub struct BlinnPhong {
    /// Diffuse colour times `kd`.
    pub diffuse: Vec3,
    /// `ks`.
    pub ks: f64,
    /// `m`.
    pub exponent: f64,
    /// `a`.
    pub anisotropy: f64,
}

impl BlinnPhong {
    /// The half-vector density `D_a(h)`, `h` in the upper hemisphere.
    fn density(&self, h: Vec3) -> f64 {
        if h.z <= 0.0 {
            return 0.0;
        }
        let a = self.anisotropy;
        let stretched = Vec3::new(h.x, a * h.y, h.z);
        let len = stretched.length();
        let cos = h.z / len;
        (2.0 * self.exponent + 1.0) / (2.0 * PI) * cos.powf(2.0 * self.exponent) * a / (len * len * len)
    }

    fn half(v: Vec3, l: Vec3) -> Option<Vec3> {
        let h = (v + l).normalize_or_zero();
        (h != Vec3::ZERO).then(|| h * h.z.signum())
    }

    fn p_diffuse(&self) -> f64 {
        lobe_probability(luminance(self.diffuse), self.ks)
    }

    /// `ρ`.
    pub fn eval(&self, v: Vec3, l: Vec3) -> Vec3 {
        if !same_side(v, l) {
            return Vec3::ZERO;
        }
        let Some(h) = Self::half(v, l) else { return Vec3::ZERO };
        let spec = self.density(h) / (4.0 * h.dot(l).abs() * l.z.abs().max(v.z.abs()));
        self.diffuse * FRAC_1_PI + Vec3::splat(self.ks * spec)
    }

    /// Cosine density mixed with the half-vector density mapped to `l` (Jacobian `1/(4⟨h,l⟩)`).
    pub fn pdf(&self, v: Vec3, l: Vec3) -> f64 {
        if !same_side(v, l) {
            return 0.0;
        }
        let Some(h) = Self::half(v, l) else { return 0.0 };
        let pd = self.p_diffuse();
        pd * cosine_pdf(v, l) + (1.0 - pd) * self.density(h) / (4.0 * h.dot(l).abs())
    }

    /// Diffuse, or a half vector from the stretched `cos^{2m}` lobe reflected about.
    pub fn sample(&self, v: Vec3, uc: f64, u: Vec2) -> Option<BsdfSample> {
        let l = if uc < self.p_diffuse() {
            cosine_hemisphere(u, v)
        } else {
            let cos = u.x.powf(1.0 / (2.0 * self.exponent + 1.0));
            let sin = (1.0 - cos * cos).max(0.0).sqrt();
            let phi = 2.0 * PI * u.y;
            let hs = Vec3::new(sin * phi.cos(), sin * phi.sin(), cos);
            let h = Vec3::new(hs.x, hs.y / self.anisotropy, hs.z).normalize();
            reflect(v, h * v.z.signum())
        };
        let pdf = self.pdf(v, l);
        (pdf > 0.0).then(|| BsdfSample { l, f: self.eval(v, l), pdf, delta: false, eta: 1.0, dispersive: false })
    }
}
