//! The course's physically based model `ρ_r = v(k_d ρ_d + k_s ρ_s)` with Lambert `ρ_d` and the
//! Cook–Torrance microfacet term `ρ_s = D G F / (4⟨l,n⟩⟨v,n⟩)`, `F` the dielectric Fresnel factor
//! at `c = ⟨h, l⟩` (exact unpolarised formula or Schlick) — plastic, varnish, clay with a sheen.
//!
//! Parameters: `albedo`, `kd`, `ks` (`k_d + k_s ≤ 1`), the microfacet distribution, roughness and
//! shadowing, the coating's index `ior`, the Fresnel mode.

use super::microfacet::Microfacet;
use super::{BsdfSample, cosine_hemisphere, cosine_pdf, lobe_probability, reflect, same_side};
use crate::optics::{fresnel_dielectric, fresnel_schlick};
use alhazen_math::{Vec2, Vec3, color::luminance};
use std::f64::consts::FRAC_1_PI;

/// Cook–Torrance.
#[derive(Clone, Copy, Debug)]
pub struct CookTorrance {
    /// `k_d` times the albedo.
    pub diffuse: Vec3,
    /// `k_s`.
    pub ks: f64,
    /// `D`, `G`.
    pub facets: Microfacet,
    /// Coating index.
    pub ior: f64,
    /// Use Schlick's `F`.
    pub schlick: bool,
}

impl CookTorrance {
    fn fresnel(&self, c: f64) -> f64 {
        if self.schlick { fresnel_schlick(c, self.ior) } else { fresnel_dielectric(c, self.ior) }
    }

    fn half(v: Vec3, l: Vec3) -> Option<Vec3> {
        let h = (v + l).normalize_or_zero();
        (h != Vec3::ZERO).then(|| h * h.z.signum())
    }

    fn p_diffuse(&self) -> f64 {
        lobe_probability(luminance(self.diffuse), self.ks)
    }

    /// `k_d ρ_d + k_s ρ_s`.
    pub fn eval(&self, v: Vec3, l: Vec3) -> Vec3 {
        if !same_side(v, l) {
            return Vec3::ZERO;
        }
        let Some(h) = Self::half(v, l) else { return Vec3::ZERO };
        let f = &self.facets;
        let spec = f.d(h) * f.g(v, l, h) * self.fresnel(h.dot(l)) / (4.0 * l.z.abs() * v.z.abs());
        self.diffuse * FRAC_1_PI + Vec3::splat(self.ks * spec)
    }

    /// Cosine density mixed with `D(h) cos ϑ_h / (4⟨h,v⟩)`.
    pub fn pdf(&self, v: Vec3, l: Vec3) -> f64 {
        if !same_side(v, l) {
            return 0.0;
        }
        let Some(h) = Self::half(v, l) else { return 0.0 };
        let pd = self.p_diffuse();
        pd * cosine_pdf(v, l) + (1.0 - pd) * self.facets.pdf_h(h) / (4.0 * h.dot(v).abs())
    }

    /// Diffuse by cosine, specular by reflecting `v` about a sampled facet normal.
    pub fn sample(&self, v: Vec3, uc: f64, u: Vec2) -> Option<BsdfSample> {
        let l = if uc < self.p_diffuse() {
            cosine_hemisphere(u, v)
        } else {
            let h = self.facets.sample_h(u)?;
            reflect(v, h * v.z.signum())
        };
        let pdf = self.pdf(v, l);
        (pdf > 0.0).then(|| BsdfSample { l, f: self.eval(v, l), pdf, delta: false, eta: 1.0, dispersive: false })
    }
}
