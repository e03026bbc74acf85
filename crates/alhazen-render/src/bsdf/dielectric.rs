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
use super::{BsdfSample, MicrofacetLobes, ThinFilm, reflect, refract_whole};
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
    /// A thin sheet (smooth): light passes straight through, or is reflected by both faces
    /// and the bounces between them (`Self::thin_sample`).
    pub thin: bool,
    /// What the refracted (or passing) light keeps, per channel (1: clear; glTF tints
    /// transmission by the base colour, Mitsuba by `specular_transmittance`).
    pub tint: Vec3,
    /// A thin film on the outside face ([`ThinFilm`]): light arriving from outside is
    /// reflected by `(1 − w)F + w·F_film` per channel and transmitted by one minus that.
    pub film: Option<ThinFilm>,
}

impl Dielectric {
    /// Clear glass of relative index `eta`, smooth when `facets` is `None`: exact Fresnel
    /// factor, one index for every colour, no tint, no film.
    #[inline(always)]
    pub fn clear(facets: Option<Microfacet>, eta: f64) -> Self {
        Dielectric { facets, eta, schlick: false, dispersive: false, thin: false, tint: Vec3::ONE, film: None }
    }

    /// Reflectance for the cosine between `v` and the (micro)normal; `v` inside when negative.
    #[inline(always)]
    fn fresnel(&self, cos_v: f64) -> f64 {
        let eta = if cos_v >= 0.0 { self.eta } else { 1.0 / self.eta };
        if self.schlick { fresnel_schlick(cos_v, eta) } else { fresnel_dielectric(cos_v, eta) }
    }

    /// With a film, what the reflected and the refracted light at cosine `cos_v` are scaled by
    /// beyond the boundary's own `F` and `1 − F` (`fr`): the film's factors over them. The
    /// reflection is still chosen with probability `F`, so the samples keep their densities.
    /// `None` without a film, or from inside (the film is on the outside face).
    #[inline(always)]
    fn film_scales(&self, cos_v: f64, fr: f64) -> Option<(Vec3, Vec3)> {
        let film = self.film.as_ref().filter(|_| cos_v > 0.0)?;
        let f0 = ((self.eta - 1.0) / (self.eta + 1.0)).powi(2);
        let f = film.blend(Vec3::splat(fr), cos_v, Vec3::splat(f0)).clamp(Vec3::ZERO, Vec3::ONE);
        let over = |x: Vec3, by: f64| if by > 0.0 { x / by } else { Vec3::ZERO };
        Some((over(f, fr), over(Vec3::ONE - f, 1.0 - fr)))
    }

    /// The generalised half vector of `v, l` facing `+z`, and `η' = η_l/η_v`.
    fn half(&self, v: Vec3, l: Vec3) -> Option<(Vec3, f64)> {
        let (valid, h, etap) = self.half_whole(v, l);
        valid.then_some((h, etap))
    }

    /// [`Self::half`] computed whole and then chosen: whether there is one (both directions see
    /// the facet from their own side), the half vector and `η'`.
    #[inline(always)]
    fn half_whole(&self, v: Vec3, l: Vec3) -> (bool, Vec3, f64) {
        let reflection = v.z * l.z > 0.0;
        let etap = if reflection {
            1.0
        } else if v.z > 0.0 {
            self.eta
        } else {
            1.0 / self.eta
        };
        let h = (v + l * etap).normalize_or_zero();
        let defined = !(h == Vec3::ZERO || v.z == 0.0 || l.z == 0.0);
        let h = h * h.z.signum();
        let facing = !(h.dot(l) * l.z <= 0.0 || h.dot(v) * v.z <= 0.0);
        (defined && facing, h, etap)
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
        let value = Vec3::splat(value) * if etap == 1.0 { Vec3::ONE } else { self.tint };
        match self.film_scales(v.dot(h), fr) {
            Some((r, t)) => value * if etap == 1.0 { r } else { t },
            None => value,
        }
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
        self.rough_eval_pdf(f, v, l)
    }

    /// Reflects with probability `F`, else refracts (about the normal or a sampled facet).
    pub fn sample(&self, v: Vec3, uc: f64, u: Vec2) -> Option<BsdfSample> {
        if self.thin {
            return self.thin_sample(v, uc);
        }
        if let Some(facets) = &self.facets {
            let (sampled, sample) = self.rough_sample(facets, v, uc, u);
            return sampled.then_some(sample);
        }
        let (sampled, sample) = self.smooth_sample(v, uc);
        sampled.then_some(sample)
    }

    /// A thin sheet's mirror direction, with the probability `R' = 2R/(1 + R)` that light is
    /// reflected by its faces and the bounces between them (`R` a face's reflectance, the same
    /// from either side), or `−v` straight through the sheet.
    pub(crate) fn thin_sample(&self, v: Vec3, uc: f64) -> Option<BsdfSample> {
        let (sampled, sample) = self.thin_sample_whole(v, uc);
        sampled.then_some(sample)
    }

    /// [`Self::thin_sample`] computed whole and then chosen, for the lanes as for it: whether
    /// there is one (`v` off the sheet's plane, finite) and the sample.
    #[inline(always)]
    pub(crate) fn thin_sample_whole(&self, v: Vec3, uc: f64) -> (bool, BsdfSample) {
        let r = self.fresnel(v.z.abs());
        let reflectance = 2.0 * r / (1.0 + r);
        let reflects = uc < reflectance;
        let (l, p, tint) =
            if reflects { (reflect(v, Vec3::Z), reflectance, Vec3::ONE) } else { (-v, 1.0 - reflectance, self.tint) };
        let sample =
            BsdfSample { l, f: Vec3::splat(p / l.z.abs()) * tint, pdf: p, delta: true, eta: 1.0, dispersive: false };
        (v.z != 0.0 && v.z.is_finite(), sample)
    }

    /// The smooth boundary's mirror direction (with probability `F`, when `uc < F`) or
    /// refracted one: whether there is one (the normal seen from the front, the direction on
    /// the right side) and the sample. Computed whole and then chosen, for the lanes as for
    /// [`Self::sample`].
    #[inline(always)]
    pub(crate) fn smooth_sample(&self, v: Vec3, uc: f64) -> (bool, BsdfSample) {
        let h = Vec3::Z;
        let front = v.dot(h) * v.z > 0.0 || (v.dot(h) * v.z).is_nan();
        let fr = self.fresnel(v.dot(h));
        let reflects = uc < fr;
        let mirrored = reflect(v, h);
        let (refracts, refracted, etap) = refract_whole(v, h, self.eta);
        let mut sample = if reflects {
            let (l, f) = (mirrored, Vec3::splat(fr / mirrored.z.abs()));
            BsdfSample { l, f, pdf: fr, delta: true, eta: 1.0, dispersive: false }
        } else {
            let (l, f) = (refracted, Vec3::splat((1.0 - fr) / refracted.z.abs() / (etap * etap)) * self.tint);
            BsdfSample { l, f, pdf: 1.0 - fr, delta: true, eta: etap, dispersive: self.dispersive }
        };
        if let Some((r, t)) = self.film_scales(v.dot(h), fr) {
            sample.f *= if reflects { r } else { t };
        }
        let side_ok = if reflects {
            mirrored.z * v.z > 0.0 || (mirrored.z * v.z).is_nan()
        } else {
            refracts && (refracted.z * v.z < 0.0 || (refracted.z * v.z).is_nan())
        };
        (front && side_ok, sample)
    }
}

impl MicrofacetLobes for Dielectric {
    /// [`Self::eval_pdf`] of the rough boundary of `facets` (this one's), computed whole and
    /// then chosen, for the path tracer's lanes as much as for [`Self::eval_pdf`].
    #[inline(always)]
    fn rough_eval_pdf(&self, facets: &Microfacet, v: Vec3, l: Vec3) -> (Vec3, f64) {
        let (valid, h, etap) = self.half_whole(v, l);
        let fr = self.fresnel(v.dot(h));
        let d = facets.d(h);
        let (dg, pdf_h) = (d * facets.g(v, l, h), facets.pdf_h_from(v, h, d));
        let reflected = (Vec3::splat(dg * fr / (4.0 * (l.z * v.z).abs())), pdf_h / (4.0 * v.dot(h).abs()) * fr);
        let denom = (l.dot(h) + v.dot(h) / etap).powi(2) * (l.z * v.z).abs();
        let value = dg * (1.0 - fr) * (l.dot(h) * v.dot(h)).abs() / denom / (etap * etap);
        let jacobian = l.dot(h).abs() / (l.dot(h) + v.dot(h) / etap).powi(2);
        let refracted = (Vec3::splat(value) * self.tint, pdf_h * jacobian * (1.0 - fr));
        let (value, pdf) = if etap == 1.0 { reflected } else { refracted };
        let value = match self.film_scales(v.dot(h), fr) {
            Some((r, t)) => value * if etap == 1.0 { r } else { t },
            None => value,
        };
        if valid { (value, pdf) } else { (Vec3::ZERO, 0.0) }
    }

    /// Reflection (with probability `F`, when `uc < F`) or refraction of `v` about a facet of
    /// `facets` (this boundary's) drawn with the numbers `u`: whether there is one (a facet
    /// seen from the front, a direction on the right side, a positive density) and the sample.
    /// Computed whole and then chosen, for the lanes as for [`Self::sample`].
    #[inline(always)]
    fn rough_sample(&self, facets: &Microfacet, v: Vec3, uc: f64, u: Vec2) -> (bool, BsdfSample) {
        let h = facets.sample_h_from(v, u);
        let (found, h) = (h.is_some(), h.unwrap_or(Vec3::Z));
        // A facet seen from behind: `pdf` gives such `l` no density. (NaNs pass every test
        // here, as in the early returns these tests replace.)
        let front = v.dot(h) * v.z > 0.0 || (v.dot(h) * v.z).is_nan();
        let fr = self.fresnel(v.dot(h));
        let reflects = uc < fr;
        let mirrored = reflect(v, h);
        let (refracts, refracted, etap) = refract_whole(v, h, self.eta);
        let (l, side_ok, eta) = if reflects {
            (mirrored, mirrored.z * v.z > 0.0 || (mirrored.z * v.z).is_nan(), 1.0)
        } else {
            (refracted, refracts && (refracted.z * v.z < 0.0 || (refracted.z * v.z).is_nan()), etap)
        };
        let (f, pdf) = self.rough_eval_pdf(facets, v, l);
        let dispersive = self.dispersive && !reflects;
        (found && front && side_ok && pdf > 0.0, BsdfSample { l, f, pdf, delta: false, eta, dispersive })
    }
}
