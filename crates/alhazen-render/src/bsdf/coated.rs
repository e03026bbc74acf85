//! A clear coat over another scattering function: car paint, varnished wood, lacquered metal
//! (glTF's `KHR_materials_clearcoat`, Blender's Principled Coat). A dielectric microfacet layer
//! of weight `w` reflects `w·ρ_c` (Cook–Torrance's `D G F / (4⟨l,n⟩⟨v,n⟩)`, exact Fresnel
//! factor of the coat's index); the base below receives what the coat lets through towards the
//! viewer, `1 − w·E_c(μ_v)`, where `E_c` is the coat's directional albedo — the facets'
//! single-scattering albedo (tabulated in [`super::multiscatter`]) times the Fresnel factor at
//! the viewing angle:
//!
//! `ρ(v, l) = w·ρ_c(v, l) + (1 − w·E_c(μ_v))·ρ_base(v, l)`.
//!
//! This is the glTF specification's layering (its `fresnel_coat`, with the albedo in place of
//! Schlick's factor) and Cycles' (its base weighted by one minus the coat's albedo towards the
//! viewer); the light the coat reflects back down onto the base is left out, as both do.
//!
//! Parameters: the base BSDF, the coat's weight `w ∈ [0, 1]`, its facets and index.

use super::cook_torrance::CookTorranceLobe;
use super::layered::SpecularLobe;
use super::multiscatter::{Row, lookup_in};
use super::{Bsdf, BsdfSample, same_side};
use crate::optics::fresnel_dielectric;
use alhazen_math::{Vec2, Vec3};

/// A base under a clear coat.
#[derive(Clone, Debug)]
pub struct Coated {
    /// What lies under the coat.
    pub base: Bsdf,
    /// The coat's microfacet lobe (its Fresnel factor exact).
    pub coat: CookTorranceLobe,
    /// The coat's weight `w ∈ [0, 1]`.
    pub weight: f64,
    /// Where the coat's roughness (for two, their geometric mean) falls in the albedo table:
    /// found once, not at every evaluation.
    row: Row,
}

impl Coated {
    /// `base` under `coat` of weight `weight`.
    pub fn new(base: Bsdf, coat: CookTorranceLobe, weight: f64) -> Self {
        let row = Row::at((coat.facets.alpha_u * coat.facets.alpha_v).sqrt());
        Coated { base, coat, weight, row }
    }

    /// `w·E_c(μ)`: the share of the light leaving along a direction of cosine `cos` with the
    /// normal that the coat reflects.
    pub(crate) fn coat_albedo(&self, cos: f64) -> f64 {
        coat_albedo(self.weight, self.row, self.coat.ior, cos)
    }

    /// Where the coat's roughness falls in the albedo table.
    pub(crate) fn row(&self) -> Row {
        self.row
    }

    /// `ρ(v, l)`.
    pub fn eval(&self, v: Vec3, l: Vec3) -> Vec3 {
        self.eval_pdf(v, l).0
    }

    /// The mixture of the coat's and the base's densities.
    pub fn pdf(&self, v: Vec3, l: Vec3) -> f64 {
        self.eval_pdf(v, l).1
    }

    /// [`Self::eval`] and [`Self::pdf`] at once.
    pub fn eval_pdf(&self, v: Vec3, l: Vec3) -> (Vec3, f64) {
        under_coat(&self.coat, self.weight, self.coat_albedo(v.z), self.base.eval_pdf(v, l), v, l)
    }

    /// The coat's facet reflection by `uc` below its share, else the base's sample (`uc`
    /// rescaled for it); a delta sample of the base keeps its own weight under the coat.
    pub fn sample(&self, v: Vec3, uc: f64, u: Vec2) -> Option<BsdfSample> {
        let albedo = self.coat_albedo(v.z);
        let q = coat_choice(albedo, self.weight);
        let base = |uc| self.base.sample(v, uc, u);
        sample_under_layer(base, uc, (q, albedo), || self.coat.sample(v, u), |l| self.eval_pdf(v, l))
    }
}

/// `w·E_c(μ)` of a coat of weight `weight`, roughness `row` and index `ior`, seen at cosine
/// `cos` ([`Coated::coat_albedo`]).
#[inline(always)]
pub(crate) fn coat_albedo(weight: f64, row: Row, ior: f64, cos: f64) -> f64 {
    let mu = cos.abs().min(1.0);
    weight * lookup_in(mu, row) * fresnel_dielectric(mu, ior)
}

/// The probability of sampling the coat rather than the base: its albedo's share, at least a
/// fifth of its weight (a glossy coat over a bright base still gets its reflections sampled).
#[inline(always)]
pub(crate) fn coat_choice(albedo: f64, weight: f64) -> f64 {
    albedo.max(0.2 * weight).min(0.9)
}

/// `(ρ, pdf)` of the coat `coat` of weight `weight` and albedo `albedo` towards the viewer over
/// a base whose `(ρ, pdf)` is `base` ([`Coated::eval_pdf`]; the lanes' coated kernels too).
#[inline(always)]
pub(crate) fn under_coat(
    coat: &CookTorranceLobe,
    weight: f64,
    albedo: f64,
    (fb, pb): (Vec3, f64),
    v: Vec3,
    l: Vec3,
) -> (Vec3, f64) {
    let q = coat_choice(albedo, weight);
    let (fc, pc) = if same_side(v, l) { coat.value_pdf(v, l) } else { (0.0, 0.0) };
    (fb * (1.0 - albedo) + Vec3::splat(weight * fc), q * pc + (1.0 - q) * pb)
}

/// A sample of a layer over a base (a coat, a sheen): the layer's own direction (`top`) where
/// `uc` falls below its share `q`, else the base's sample (`base`, drawn with
/// [`base_choice`]`(uc, q)`) — a delta sample of the base keeping its own weight times what the
/// layer of albedo `albedo` lets through —, a direction not a delta valued by the whole
/// (`eval_pdf`). Only the sample chosen is drawn.
#[inline(always)]
pub(crate) fn sample_under_layer(
    base: impl FnOnce(f64) -> Option<BsdfSample>,
    uc: f64,
    (q, albedo): (f64, f64),
    top: impl FnOnce() -> Option<Vec3>,
    eval_pdf: impl FnOnce(Vec3) -> (Vec3, f64),
) -> Option<BsdfSample> {
    let l = if uc < q {
        top()?
    } else {
        let mut s = base(base_choice(uc, q))?;
        if s.delta {
            s.f *= 1.0 - albedo;
            s.pdf *= 1.0 - q;
            return Some(s);
        }
        s.l
    };
    let (f, pdf) = eval_pdf(l);
    (pdf > 0.0).then_some(BsdfSample { l, f, pdf, delta: false, eta: 1.0, dispersive: false })
}

/// The base's lobe choice when the layer's share `q` is not chosen by `uc`: `uc` rescaled.
#[inline(always)]
fn base_choice(uc: f64, q: f64) -> f64 {
    ((uc - q) / (1.0 - q)).min(1.0 - 1e-16)
}
