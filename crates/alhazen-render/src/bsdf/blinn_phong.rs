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

use super::layered::{DiffuseSpecular, SpecularLobe};
use super::{half_vector, reflect};
use alhazen_math::elementary::pow;
use alhazen_math::{Vec2, Vec3, sin_cos_turns};
use std::f64::consts::PI;

/// The stretched `⟨ĥ, n⟩^{2m}` lobe.
#[derive(Clone, Copy, Debug)]
pub struct BlinnPhongLobe {
    /// `m` (the lobe is `cos^{2m}`).
    pub exponent: f64,
    /// `a`.
    pub anisotropy: f64,
}

/// Normalised anisotropic Blinn–Phong.
pub type BlinnPhong = DiffuseSpecular<BlinnPhongLobe>;

impl BlinnPhongLobe {
    /// The half-vector density `D_a(h)`, `h` in the upper hemisphere.
    #[inline(always)]
    fn density(&self, h: Vec3) -> f64 {
        if h.z <= 0.0 {
            return 0.0;
        }
        let a = self.anisotropy;
        let stretched = Vec3::new(h.x, a * h.y, h.z);
        let len = stretched.length();
        let cos = h.z / len;
        (2.0 * self.exponent + 1.0) / (2.0 * PI) * pow(cos, 2.0 * self.exponent) * a / (len * len * len)
    }
}

impl SpecularLobe for BlinnPhongLobe {
    #[inline(always)]
    fn value(&self, v: Vec3, l: Vec3) -> f64 {
        self.value_pdf(v, l).0
    }

    /// The half-vector density mapped to `l` (Jacobian `1/(4⟨h,l⟩)`).
    #[inline(always)]
    fn pdf(&self, v: Vec3, l: Vec3) -> f64 {
        self.value_pdf(v, l).1
    }

    #[inline(always)]
    fn value_pdf(&self, v: Vec3, l: Vec3) -> (f64, f64) {
        let Some(h) = half_vector(v, l) else { return (0.0, 0.0) };
        let (density, jacobian) = (self.density(h), 4.0 * h.dot(l).abs());
        (density / (jacobian * l.z.abs().max(v.z.abs())), density / jacobian)
    }

    /// A half vector from the stretched `cos^{2m}` lobe, `v` reflected about it.
    #[inline(always)]
    fn sample(&self, v: Vec3, u: Vec2) -> Option<Vec3> {
        let cos = pow(u.x, 1.0 / (2.0 * self.exponent + 1.0));
        let sin = (1.0 - cos * cos).max(0.0).sqrt();
        let (sin_phi, cos_phi) = sin_cos_turns(u.y);
        let hs = Vec3::new(sin * cos_phi, sin * sin_phi, cos);
        let h = Vec3::new(hs.x, hs.y / self.anisotropy, hs.z).normalize();
        Some(reflect(v, h * v.z.signum()))
    }
}
