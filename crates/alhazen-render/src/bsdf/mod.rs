//! Physically based scattering functions (course §"Physically based models"), one file each.
//!
//! Conventions (the course's): `v` is the unit direction towards the viewer (where the path came
//! from), `l` towards the light (where it goes next); both point away from the surface and are
//! given in the local shading frame, whose `z` axis is the normal. `eval` returns `ρ(l, v)`
//! without the cosine; `pdf` is the solid-angle density of `sample` choosing `l`; delta lobes
//! (mirrors, smooth glass) are reached only through `sample`. Reflection lobes carry the
//! course's same-side factor `v`: zero unless `l` and `v` are on the same side of the surface.

mod blinn_phong;
mod build;
pub(crate) mod coated;
mod conductor;
mod cook_torrance;
mod dielectric;
mod lambert;
pub mod layered;
mod layering;
pub mod microfacet;
mod mix;
pub(crate) mod multiscatter;
mod oren_nayar;
mod phong;
mod plastic;
mod sheen;
mod thin_film;

pub use blinn_phong::{BlinnPhong, BlinnPhongLobe};
pub use build::{ColorMode, bsdf_at, is_anisotropic, tangent_at};
pub use coated::Coated;
pub use conductor::Conductor;
pub use cook_torrance::{CookTorrance, CookTorranceLobe};
pub use dielectric::Dielectric;
pub use lambert::Lambert;
pub use microfacet::Microfacet;
pub use mix::Mix;
pub(crate) use mix::{blend, blend_density};
pub use multiscatter::SeveralFacets;
pub use oren_nayar::OrenNayar;
pub use phong::{Phong, PhongLobe};
pub use plastic::{Coat, Plastic};
pub use sheen::Sheened;
pub use thin_film::ThinFilm;

use alhazen_math::{Vec2, Vec3};
use std::f64::consts::PI;

/// What `sample` chose.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfSample {
    /// Direction towards the light, local frame.
    pub l: Vec3,
    /// `ρ(l, v)` (for delta lobes: the weight divided by `|cos|`).
    pub f: Vec3,
    /// Density of choosing `l` (for delta lobes: the discrete probability).
    pub pdf: f64,
    /// True for a mirror or smooth refraction.
    pub delta: bool,
    /// Relative index `η_l/η_v` crossed (1 for reflection).
    pub eta: f64,
    /// True when the index that bent this ray depends on wavelength.
    pub dispersive: bool,
}

/// One scattering function at one surface point, colours resolved.
#[derive(Clone, Debug)]
pub enum Bsdf {
    /// Lambert.
    Lambert(Lambert),
    /// Oren–Nayar.
    OrenNayar(OrenNayar),
    /// Normalised Phong.
    Phong(Phong),
    /// Normalised (anisotropic) Blinn–Phong.
    BlinnPhong(BlinnPhong),
    /// Cook–Torrance.
    CookTorrance(CookTorrance),
    /// A diffuse base under a dielectric coat.
    Plastic(Plastic),
    /// Metal.
    Conductor(Conductor),
    /// Glass.
    Dielectric(Dielectric),
    /// Blend of two.
    Mix(Box<Mix>),
    /// A base under a clear coat.
    Coated(Box<Coated>),
    /// A base under a sheen.
    Sheened(Box<Sheened>),
}

macro_rules! dispatch {
    ($self:ident, $b:ident => $e:expr) => {
        match $self {
            Bsdf::Lambert($b) => $e,
            Bsdf::OrenNayar($b) => $e,
            Bsdf::Phong($b) => $e,
            Bsdf::BlinnPhong($b) => $e,
            Bsdf::CookTorrance($b) => $e,
            Bsdf::Plastic($b) => $e,
            Bsdf::Conductor($b) => $e,
            Bsdf::Dielectric($b) => $e,
            Bsdf::Mix($b) => $e,
            Bsdf::Coated($b) => $e,
            Bsdf::Sheened($b) => $e,
        }
    };
}

impl Bsdf {
    /// `ρ(l, v)`; zero for delta lobes.
    pub fn eval(&self, v: Vec3, l: Vec3) -> Vec3 {
        dispatch!(self, b => b.eval(v, l))
    }

    /// Density of `sample` returning `l` (non-delta part).
    pub fn pdf(&self, v: Vec3, l: Vec3) -> f64 {
        dispatch!(self, b => b.pdf(v, l))
    }

    /// `(eval(v, l), pdf(v, l))` — the same numbers, with the terms they share (half vector,
    /// `D`, Fresnel) computed once where the model has them.
    pub fn eval_pdf(&self, v: Vec3, l: Vec3) -> (Vec3, f64) {
        match self {
            Bsdf::Conductor(c) => c.eval_pdf(v, l),
            Bsdf::Dielectric(d) => d.eval_pdf(v, l),
            Bsdf::Plastic(p) => p.eval_pdf(v, l),
            Bsdf::CookTorrance(c) => c.rough_eval_pdf(&c.lobe.facets, v, l),
            Bsdf::Phong(p) => p.eval_pdf(v, l),
            Bsdf::BlinnPhong(b) => b.eval_pdf(v, l),
            Bsdf::Mix(m) => m.eval_pdf(v, l),
            Bsdf::Coated(c) => c.eval_pdf(v, l),
            Bsdf::Sheened(c) => c.eval_pdf(v, l),
            _ => (self.eval(v, l), self.pdf(v, l)),
        }
    }

    /// Chooses `l` from `v`; `uc` picks a lobe, `u` places the direction.
    pub fn sample(&self, v: Vec3, uc: f64, u: Vec2) -> Option<BsdfSample> {
        if let Bsdf::CookTorrance(c) = self {
            // The lanes' form (the same sample, computed whole and then chosen).
            let (sampled, s) = c.rough_sample(&c.lobe.facets, v, uc, u);
            return sampled.then_some(s);
        }
        dispatch!(self, b => b.sample(v, uc, u))
    }

    /// True when `sample` uses its lobe choice `uc` (several lobes to pick from).
    pub fn chooses_lobe(&self) -> bool {
        match self {
            Bsdf::Conductor(c) => c.multiple_scattering(Vec3::Z).is_some(),
            _ => !matches!(self, Bsdf::Lambert(_) | Bsdf::OrenNayar(_)),
        }
    }

    /// True when every lobe is a delta (no light sampling helps).
    pub fn is_delta(&self) -> bool {
        match self {
            Bsdf::Conductor(c) => c.facets.is_none(),
            Bsdf::Dielectric(d) => d.facets.is_none(),
            Bsdf::Mix(m) => m.a.is_delta() && m.b.is_delta(),
            _ => false,
        }
    }

    /// True when some lobe is a delta (a smooth metal's or glass's): light can leave along one
    /// direction only.
    pub fn has_delta_lobe(&self) -> bool {
        match self {
            Bsdf::Conductor(c) => c.facets.is_none(),
            Bsdf::Plastic(p) => p.has_mirror(),
            Bsdf::Dielectric(d) => d.facets.is_none(),
            Bsdf::Mix(m) => m.a.has_delta_lobe() || m.b.has_delta_lobe(),
            Bsdf::Coated(c) => c.base.has_delta_lobe(),
            Bsdf::Sheened(c) => c.base.has_delta_lobe(),
            _ => false,
        }
    }

    /// The weight of the mirror lobe (a smooth metal's delta reflection) at incidence cosine
    /// `cos`: what a specular connection through this surface carries; zero without one.
    pub fn mirror_reflectance(&self, cos: f64) -> Vec3 {
        match self {
            Bsdf::Conductor(c) if c.facets.is_none() => c.fresnel(cos),
            Bsdf::Mix(m) => m.a.mirror_reflectance(cos) * m.weight + m.b.mirror_reflectance(cos) * (1.0 - m.weight),
            Bsdf::Coated(c) => c.base.mirror_reflectance(cos) * (1.0 - c.coat_albedo(cos)),
            Bsdf::Sheened(c) => c.base.mirror_reflectance(cos) * (1.0 - c.sheen_albedo(cos)),
            _ => Vec3::ZERO,
        }
    }

    /// True when light passes through (the surface has an inside).
    pub fn transmits(&self) -> bool {
        match self {
            Bsdf::Dielectric(_) => true,
            Bsdf::CookTorrance(c) => c.transmittance != Vec3::ZERO,
            Bsdf::Mix(m) => m.a.transmits() || m.b.transmits(),
            Bsdf::Coated(c) => c.base.transmits(),
            Bsdf::Sheened(c) => c.base.transmits(),
            _ => false,
        }
    }
}

/// A right-handed frame `(s, t, n)`.
#[derive(Clone, Copy, Debug)]
pub struct Frame {
    /// Tangent.
    pub s: Vec3,
    /// Bitangent.
    pub t: Vec3,
    /// Normal.
    pub n: Vec3,
}

impl Frame {
    /// A frame around `n` with `s` along the projection of `tangent` on the tangent plane (any
    /// tangent when that is degenerate).
    pub fn new(n: Vec3, tangent: Vec3) -> Self {
        let s = tangent - n * n.dot(tangent);
        let s = if s.length_squared() > 1e-12 { s.normalize() } else { alhazen_math::orthonormal_basis(n).0 };
        Self { s, t: n.cross(s), n }
    }

    /// Any frame around unit `n` (Duff et al. 2017, "Building an Orthonormal Basis, Revisited"):
    /// for isotropic BSDFs, which do not care how the tangent turns about the normal.
    pub fn around(n: Vec3) -> Self {
        let (s, t) = alhazen_math::orthonormal_basis(n);
        Self { s, t, n }
    }

    /// World → local.
    pub fn to_local(&self, w: Vec3) -> Vec3 {
        Vec3::new(w.dot(self.s), w.dot(self.t), w.dot(self.n))
    }

    /// Local → world.
    pub fn to_world(&self, w: Vec3) -> Vec3 {
        self.s * w.x + self.t * w.y + self.n * w.z
    }
}

/// The course's same-side factor `v` for a reflection lobe.
#[inline]
pub(crate) fn same_side(v: Vec3, l: Vec3) -> bool {
    v.z * l.z > 0.0
}

/// Cosine-weighted direction in the hemisphere of `v` (Malley's method), density `|cos|/π`.
#[inline(always)]
pub(crate) fn cosine_hemisphere(u: Vec2, v: Vec3) -> Vec3 {
    let r = u.x.sqrt();
    let (sin, cos) = alhazen_math::sin_cos_turns(u.y);
    let z = (1.0 - u.x).max(0.0).sqrt();
    Vec3::new(r * cos, r * sin, if v.z < 0.0 { -z } else { z })
}

/// Density of [`cosine_hemisphere`].
#[inline]
pub(crate) fn cosine_pdf(v: Vec3, l: Vec3) -> f64 {
    if same_side(v, l) { l.z.abs() / PI } else { 0.0 }
}

/// The lobes of a BSDF of microfacets (a rough conductor, dielectric or plastic) on given
/// facets, computed whole and then chosen: the per-path tracer evaluates its BSDF through them,
/// and the path tracer's lanes with the facets' kind a constant the compiler folds.
pub(crate) trait MicrofacetLobes {
    /// `eval_pdf` on `facets`.
    fn rough_eval_pdf(&self, facets: &Microfacet, v: Vec3, l: Vec3) -> (Vec3, f64);
    /// `sample` on `facets` with the numbers `uc` (a lobe, where there are several) and `u`:
    /// whether there is a sample, and the sample.
    fn rough_sample(&self, facets: &Microfacet, v: Vec3, uc: f64, u: Vec2) -> (bool, BsdfSample);
}

/// Mirror of `v` about `n` (both local).
#[inline]
pub(crate) fn reflect(v: Vec3, n: Vec3) -> Vec3 {
    2.0 * v.dot(n) * n - v
}

/// The direction `v` refracts into through a surface with normal `n` and relative index
/// `eta = η_inside/η_outside` (inside is `−n`); `None` under total internal reflection. Returns
/// the direction and the index ratio `η_l/η_v` crossed.
pub(crate) fn refract(v: Vec3, n: Vec3, eta: f64) -> Option<(Vec3, f64)> {
    let (refracts, l, eta) = refract_whole(v, n, eta);
    refracts.then_some((l, eta))
}

/// [`refract`] computed whole and then chosen, for the path tracer's lanes: whether `v`
/// refracts, the direction (meaningless where it does not) and the index ratio.
#[inline(always)]
pub(crate) fn refract_whole(v: Vec3, n: Vec3, eta: f64) -> (bool, Vec3, f64) {
    let cos_v = n.dot(v);
    let inside = cos_v < 0.0;
    let (eta, cos_i, n) = if inside { (1.0 / eta, -cos_v, -n) } else { (eta, cos_v, n) };
    let sin2_t = (1.0 - cos_i * cos_i).max(0.0) / (eta * eta);
    let cos_t = (1.0 - sin2_t).sqrt();
    (sin2_t < 1.0 || sin2_t.is_nan(), -v / eta + (cos_i / eta - cos_t) * n, eta)
}

/// The half vector of `v` and `l`, turned to the upper hemisphere; `None` when they are opposite.
#[inline]
pub(crate) fn half_vector(v: Vec3, l: Vec3) -> Option<Vec3> {
    let h = (v + l).normalize_or_zero();
    (h != Vec3::ZERO).then(|| h * h.z.signum())
}

/// A cosine-weighted sample of a diffuse lobe whose value is `eval(l)`.
#[inline(always)]
pub(crate) fn sample_cosine(v: Vec3, u: Vec2, eval: impl Fn(Vec3) -> Vec3) -> Option<BsdfSample> {
    let l = cosine_hemisphere(u, v);
    let pdf = cosine_pdf(v, l);
    (pdf > 0.0).then(|| BsdfSample { l, f: eval(l), pdf, delta: false, eta: 1.0, dispersive: false })
}

/// Lobe choice probability proportional to two non-negative weights (0.5 each when both vanish).
#[inline(always)]
pub(crate) fn lobe_probability(a: f64, b: f64) -> f64 {
    if a + b > 0.0 { a / (a + b) } else { 0.5 }
}
