//! The course's physically based model `ρ_r = v(k_d ρ_d + k_s ρ_s)` with Lambert `ρ_d` and the
//! Cook–Torrance microfacet term `ρ_s = D G F / (4⟨l,n⟩⟨v,n⟩)`, `F` the dielectric Fresnel factor
//! at `c = ⟨h, l⟩` (exact unpolarised formula or Schlick) — plastic, varnish, clay with a sheen.
//!
//! Parameters: `albedo`, `kd`, `ks` (`k_d + k_s ≤ 1`), the microfacet distribution, roughness and
//! shadowing, the coating's index `ior`, the Fresnel mode.

use super::half_vector;
use super::layered::{DiffuseSpecular, SpecularLobe};
use super::microfacet::Microfacet;
use super::reflect;
use crate::optics::{fresnel_dielectric, fresnel_schlick};
use alhazen_math::{Vec2, Vec3};

/// The microfacet lobe `D G F / (4⟨l,n⟩⟨v,n⟩)` of a dielectric coating.
#[derive(Clone, Copy, Debug)]
pub struct CookTorranceLobe {
    /// `D`, `G`.
    pub facets: Microfacet,
    /// Coating index.
    pub ior: f64,
    /// Use Schlick's `F`.
    pub schlick: bool,
}

/// Cook–Torrance.
pub type CookTorrance = DiffuseSpecular<CookTorranceLobe>;

impl SpecularLobe for CookTorranceLobe {
    fn value(&self, v: Vec3, l: Vec3) -> f64 {
        let Some(h) = half_vector(v, l) else { return 0.0 };
        let c = h.dot(l);
        let f = if self.schlick { fresnel_schlick(c, self.ior) } else { fresnel_dielectric(c, self.ior) };
        self.facets.d(h) * self.facets.g(v, l, h) * f / (4.0 * l.z.abs() * v.z.abs())
    }

    /// The facet's density over `4⟨h,v⟩`.
    fn pdf(&self, v: Vec3, l: Vec3) -> f64 {
        let Some(h) = half_vector(v, l) else { return 0.0 };
        self.facets.pdf_h_from(v, h, self.facets.d(h)) / (4.0 * h.dot(v).abs())
    }

    /// `v` reflected about a sampled facet normal.
    fn sample(&self, v: Vec3, u: Vec2) -> Option<Vec3> {
        let h = self.facets.sample_h_from(v, u)?;
        Some(reflect(v, h * v.z.signum()))
    }
}
