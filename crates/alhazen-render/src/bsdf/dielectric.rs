//! Glass, water, diamond: reflection and refraction at a boundary between two dielectrics.
//!
//! Smooth: a delta mirror with weight `F` and a delta refraction (Snell) with weight
//! `(1 − F)/η²` — the course's η² factor: radiance is compressed into the smaller solid angle
//! on the denser side (`η₁²ρ(l,v) = η₂²ρ(v,l)`).
//!
//! Rough: the course's microfacet BRDF `DGF/(4|⟨l,n⟩⟨v,n⟩|)` and its transmission term (1),
//! `ρ_t = D G (1−F)/|⟨l,n⟩⟨v,n⟩| · η₂²/η₁²`-type, with the half vector `h ∝ v + η l` of the course.
//! The course's (1) omits the Jacobian of the half-vector map; we use the complete form of
//! Walter et al. (2007), `|⟨l,h⟩⟨v,h⟩| / |⟨l,n⟩⟨v,n⟩| · D G (1−F) / (⟨l,h⟩ + ⟨v,h⟩/η')² / η'²`,
//! `η' = η_l/η_v`, without which energy is not conserved.
//!
//! Parameters: `eta` (inside over outside, already evaluated at the path's wavelength when
//! dispersive), optional microfacets, Fresnel mode, `dispersive` (marks refracted samples).

use super::microfacet::Microfacet;
use super::{BsdfSample, reflect, refract};
use crate::optics::{fresnel_dielectric, fresnel_schlick};
use alhazen_math::{Vec2, Vec3};

/// A dielectric boundary; the local `+z` side is outside.
#[derive(Clone, Copy, Debug)]
pub struct Dielectric {
    /// Rough, or smooth when `None`.
    pub facets: Option<Microfacet>,
    /// `η_inside / η_outside`.
    pub eta: f64,
    /// Schlick instead of the exact formula.
    pub schlick: bool,
    /// The index depends on wavelength.
    pub dispersive: bool,
}

impl Dielectric {
    /// Reflectance for the cosine between `v` and the (micro)normal; `v` inside when negative.
    fn fresnel(&self, cos_v: f64) -> f64 {
        let eta = if cos_v >= 0.0 { self.eta } else { 1.0 / self.eta };
        if self.schlick { fresnel_schlick(cos_v, eta) } else { fresnel_dielectric(cos_v, eta) }
    }

    /// The generalised half vector of `v, l` facing `+z`, and `η' = η_l/η_v`.
    fn half(&self, v: Vec3, l: Vec3) -> Option<(Vec3, f64)> {
        let reflection = v.z * l.z > 0.0;
        let etap = if reflection {
            1.0
        } else if v.z > 0.0 {
            self.eta
        } else {
            1.0 / self.eta
        };
        let h = (v + l * etap).normalize_or_zero();
        if h == Vec3::ZERO || v.z == 0.0 || l.z == 0.0 {
            return None;
        }
        let h = h * h.z.signum();
        // Both directions must see the facet from their own side.
        if h.dot(l) * l.z <= 0.0 || h.dot(v) * v.z <= 0.0 {
            return None;
        }
        Some((h, etap))
    }

    /// `ρ_r + ρ_t` (0 when smooth).
    pub fn eval(&self, v: Vec3, l: Vec3) -> Vec3 {
        let Some(f) = &self.facets else { return Vec3::ZERO };
        let Some((h, etap)) = self.half(v, l) else { return Vec3::ZERO };
        let fr = self.fresnel(v.dot(h));
        let dg = f.d(h) * f.g(v, l, h);
        let value = if etap == 1.0 {
            dg * fr / (4.0 * (l.z * v.z).abs())
        } else {
            let denom = (l.dot(h) + v.dot(h) / etap).powi(2) * (l.z * v.z).abs();
            dg * (1.0 - fr) * (l.dot(h) * v.dot(h)).abs() / denom / (etap * etap)
        };
        Vec3::splat(value)
    }

    /// Density of `sample`: facet density times the reflect/refract Jacobian and choice.
    pub fn pdf(&self, v: Vec3, l: Vec3) -> f64 {
        let Some(f) = &self.facets else { return 0.0 };
        let Some((h, etap)) = self.half(v, l) else { return 0.0 };
        let fr = self.fresnel(v.dot(h));
        let pdf_h = f.pdf_h_from(v, h, f.d(h));
        if etap == 1.0 {
            pdf_h / (4.0 * v.dot(h).abs()) * fr
        } else {
            let jacobian = l.dot(h).abs() / (l.dot(h) + v.dot(h) / etap).powi(2);
            pdf_h * jacobian * (1.0 - fr)
        }
    }

    /// [`Self::eval`] and [`Self::pdf`] with the half vector, `F` and `D` found once (the same
    /// numbers).
    pub fn eval_pdf(&self, v: Vec3, l: Vec3) -> (Vec3, f64) {
        let Some(f) = &self.facets else { return (Vec3::ZERO, 0.0) };
        let Some((h, etap)) = self.half(v, l) else { return (Vec3::ZERO, 0.0) };
        let fr = self.fresnel(v.dot(h));
        let d = f.d(h);
        let (dg, pdf_h) = (d * f.g(v, l, h), f.pdf_h_from(v, h, d));
        if etap == 1.0 {
            (Vec3::splat(dg * fr / (4.0 * (l.z * v.z).abs())), pdf_h / (4.0 * v.dot(h).abs()) * fr)
        } else {
            let denom = (l.dot(h) + v.dot(h) / etap).powi(2) * (l.z * v.z).abs();
            let value = dg * (1.0 - fr) * (l.dot(h) * v.dot(h)).abs() / denom / (etap * etap);
            let jacobian = l.dot(h).abs() / (l.dot(h) + v.dot(h) / etap).powi(2);
            (Vec3::splat(value), pdf_h * jacobian * (1.0 - fr))
        }
    }

    /// Reflects with probability `F`, else refracts (about the normal or a sampled facet).
    pub fn sample(&self, v: Vec3, uc: f64, u: Vec2) -> Option<BsdfSample> {
        let h = match &self.facets {
            None => Vec3::Z,
            Some(f) => f.sample_h_from(v, u)?,
        };
        if v.dot(h) * v.z <= 0.0 {
            return None; // the facet is seen from behind: `pdf` gives such `l` no density
        }
        let fr = self.fresnel(v.dot(h));
        let smooth = self.facets.is_none();
        if uc < fr {
            let l = reflect(v, h);
            if l.z * v.z <= 0.0 {
                return None;
            }
            if smooth {
                let f = Vec3::splat(fr / l.z.abs());
                return Some(BsdfSample { l, f, pdf: fr, delta: true, eta: 1.0, dispersive: false });
            }
            let (f, pdf) = self.eval_pdf(v, l);
            return (pdf > 0.0).then_some(BsdfSample { l, f, pdf, delta: false, eta: 1.0, dispersive: false });
        }
        let (l, etap) = refract(v, h, self.eta)?;
        if l.z * v.z >= 0.0 {
            return None;
        }
        if smooth {
            let f = Vec3::splat((1.0 - fr) / l.z.abs() / (etap * etap));
            return Some(BsdfSample { l, f, pdf: 1.0 - fr, delta: true, eta: etap, dispersive: self.dispersive });
        }
        let (f, pdf) = self.eval_pdf(v, l);
        (pdf > 0.0).then_some(BsdfSample { l, f, pdf, delta: false, eta: etap, dispersive: self.dispersive })
    }
}
