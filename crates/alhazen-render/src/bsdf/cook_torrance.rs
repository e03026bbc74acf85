//! The course's physically based model `ρ_r = v(k_d ρ_d + k_s ρ_s)` with Lambert `ρ_d` and the
//! Cook–Torrance microfacet term `ρ_s = D G F / (4⟨l,n⟩⟨v,n⟩)`, `F` the dielectric Fresnel factor
//! at `c = ⟨h, l⟩` (exact unpolarised formula or Schlick) — plastic, varnish, clay with a sheen.
//!
//! Parameters: `albedo`, `kd`, `ks` (`k_d + k_s ≤ 1`), the microfacet distribution, roughness and
//! shadowing, the coating's index `ior`, the Fresnel mode.

use super::layered::{DiffuseSpecular, SpecularLobe};
use super::microfacet::Microfacet;
use super::reflect;
use super::{BsdfSample, MicrofacetLobes, cosine_hemisphere, cosine_pdf, same_side};
use crate::optics::{fresnel_dielectric, fresnel_schlick};
use alhazen_math::{Vec2, Vec3};
use std::f64::consts::FRAC_1_PI;

/// The microfacet lobe `D G F / (4⟨l,n⟩⟨v,n⟩)` of a dielectric coating.
#[derive(Clone, Copy, Debug)]
pub struct CookTorranceLobe {
    /// `D`, `G`.
    pub facets: Microfacet,
    /// Coating index.
    pub ior: f64,
    /// Use Schlick's `F`.
    pub schlick: bool,
    /// The specular weight the diffuse term is layered under (`k_d(1 − layer·E(μ_o))`,
    /// `bsdf::layering`); 0 for a diffuse weight that does not vary.
    pub layer: f64,
}

/// Cook–Torrance.
pub type CookTorrance = DiffuseSpecular<CookTorranceLobe>;

impl CookTorranceLobe {
    /// [`SpecularLobe::value`] and [`SpecularLobe::pdf`] at once (`D` computed once), computed
    /// whole and then chosen — no early return where `v` and `l` are opposite — so that the
    /// path tracer's lanes evaluate it for eight directions at once.
    #[inline(always)]
    pub(crate) fn value_pdf(&self, v: Vec3, l: Vec3) -> (f64, f64) {
        let h = (v + l).normalize_or_zero();
        let met = h != Vec3::ZERO;
        let h = h * h.z.signum();
        let c = h.dot(l);
        let f = if self.schlick { fresnel_schlick(c, self.ior) } else { fresnel_dielectric(c, self.ior) };
        let d = self.facets.d(h);
        let value = d * self.facets.g(v, l, h) * f / (4.0 * l.z.abs() * v.z.abs());
        let pdf = self.facets.pdf_h_from(v, h, d) / (4.0 * h.dot(v).abs());
        if met { (value, pdf) } else { (0.0, 0.0) }
    }
}

impl SpecularLobe for CookTorranceLobe {
    fn value(&self, v: Vec3, l: Vec3) -> f64 {
        self.value_pdf(v, l).0
    }

    /// `1 − layer·E(μ_o)`: exactly 1 where the lobe is not layered.
    #[inline(always)]
    fn diffuse_weight(&self, mu: f64) -> f64 {
        if self.layer == 0.0 { 1.0 } else { 1.0 - self.layer * super::layering::albedo(&self.facets, mu, self.ior) }
    }

    /// The facet's density over `4⟨h,v⟩`.
    fn pdf(&self, v: Vec3, l: Vec3) -> f64 {
        self.value_pdf(v, l).1
    }

    /// `v` reflected about a sampled facet normal.
    fn sample(&self, v: Vec3, u: Vec2) -> Option<Vec3> {
        let h = self.facets.sample_h_from(v, u)?;
        Some(reflect(v, h * v.z.signum()))
    }
}

impl CookTorrance {
    /// [`MicrofacetLobes::rough_eval_pdf`] with the diffuse term weighed by `weight`, the
    /// lobe's [`SpecularLobe::diffuse_weight`] seen from `v` (the path tracer's lanes find it
    /// before their vector loop: its table lookup would keep the loop scalar).
    #[inline(always)]
    pub(crate) fn eval_pdf_weighted(&self, weight: f64, v: Vec3, l: Vec3) -> (Vec3, f64) {
        let (value, lobe_pdf) = self.lobe.value_pdf(v, l);
        let (pd, reflected) = (self.p_diffuse(), self.p_reflected());
        let diffuse = FRAC_1_PI * weight;
        let f = self.diffuse * diffuse + Vec3::splat(self.ks * value);
        let pdf = pd * reflected * cosine_pdf(v, l) + (1.0 - pd) * lobe_pdf;
        // Through to the other side: the diffuse transmission alone, sampled by it and by the
        // specular lobe's facets that send the viewer below the surface.
        let lobe_through = if self.transmittance != Vec3::ZERO { (1.0 - pd) * lobe_pdf } else { 0.0 };
        let through = (self.transmittance * diffuse, pd * (1.0 - reflected) * (l.z.abs() * FRAC_1_PI) + lobe_through);
        if same_side(v, l) { (f, pdf) } else { through }
    }

    /// [`MicrofacetLobes::rough_sample`] with the diffuse term weighed by `weight`.
    #[inline(always)]
    pub(crate) fn sample_weighted(&self, weight: f64, v: Vec3, uc: f64, u: Vec2) -> (bool, BsdfSample) {
        let pd = self.p_diffuse();
        let (diffuse, reflected) = (uc < pd, uc < pd * self.p_reflected());
        let h = self.lobe.facets.sample_h_from(v, u);
        let mirrored = reflect(v, h.unwrap_or(Vec3::Z) * v.z.signum());
        let l = if reflected {
            cosine_hemisphere(u, v)
        } else if diffuse {
            cosine_hemisphere(u, -v)
        } else {
            mirrored
        };
        let (f, pdf) = self.eval_pdf_weighted(weight, v, l);
        ((diffuse || h.is_some()) && pdf > 0.0, BsdfSample { l, f, pdf, delta: false, eta: 1.0, dispersive: false })
    }
}

impl MicrofacetLobes for CookTorrance {
    /// `(eval, pdf)` of [`DiffuseSpecular`] on this lobe, computed whole and then chosen: the
    /// per-path tracer's ([`super::Bsdf::eval_pdf`]) and the lanes'. `facets` are the lobe's
    /// own (the lanes build it with them).
    #[inline(always)]
    fn rough_eval_pdf(&self, _: &Microfacet, v: Vec3, l: Vec3) -> (Vec3, f64) {
        self.eval_pdf_weighted(self.lobe.diffuse_weight(v.z), v, l)
    }

    /// [`DiffuseSpecular::sample`] on this lobe, computed whole and then chosen: whether there
    /// is a sample (a facet where the lobe is chosen, a positive density) and the sample.
    #[inline(always)]
    fn rough_sample(&self, _: &Microfacet, v: Vec3, uc: f64, u: Vec2) -> (bool, BsdfSample) {
        self.sample_weighted(self.lobe.diffuse_weight(v.z), v, uc, u)
    }
}
