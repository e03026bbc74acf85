//! Metals: Fresnel reflection with a complex index of refraction `η + iκ` per RGB channel
//! (course: "F_λ depends … on its refraction index, which depends on the wavelength"), as a
//! perfect mirror or as the microfacet `ρ = D G F / (4⟨l,n⟩⟨v,n⟩)`; Schlick's approximation from
//! the exact normal-incidence reflectance as an option.
//!
//! Parameters: `eta`, `k` (per channel), roughness/distribution/shadowing or none (smooth),
//! `tint` (a multiplier, 1 is physical), Fresnel mode. `η = κ = 0` is an ideal mirror (`F = tint`).

use super::microfacet::Microfacet;
use super::{BsdfSample, MicrofacetLobes, ThinFilm, reflect, same_side};
use alhazen_math::{Vec2, Vec3};

/// A conductor.
#[derive(Clone, Copy, Debug)]
pub struct Conductor {
    /// Rough, or smooth when `None`.
    pub facets: Option<Microfacet>,
    /// Real part of the index.
    pub eta: Vec3,
    /// Imaginary part.
    pub k: Vec3,
    /// Multiplier.
    pub tint: Vec3,
    /// Schlick instead of the exact formula.
    pub schlick: bool,
    /// A rough conductor adds the light that meets several facets (Kulla and Conty's lobe,
    /// `super::multiscatter`), as Cycles' multiple-scattering GGX gives it back: the lobe's
    /// terms that do not depend on the directions ([`Self::with_several_facets`]); `None`:
    /// single scattering.
    pub multiscatter: Option<super::SeveralFacets>,
    /// A thin film over the metal ([`ThinFilm`]): its interference blended into `F`.
    pub film: Option<ThinFilm>,
}

/// Unpolarised reflectance of a conductor `η + iκ` at incidence cosine `cos_i`:
/// `½(|r_∥|² + |r_⊥|²)`, the complex cosine of the transmitted angle written through its real
/// quantities (Born and Wolf §14.2): with `s² = 1 − c²`, `t₀ = η² − κ² − s²`,
/// `a² + b² = √(t₀² + 4η²κ²)` and `a = √((a² + b² + t₀)/2)`,
/// `R_⊥ = (a² + b² + c² − 2ac)/(a² + b² + c² + 2ac)` and
/// `R_∥ = R_⊥ (c²(a² + b²) + s⁴ − 2acs²)/(c²(a² + b²) + s⁴ + 2acs²)` — two square roots and one
/// division (their mean is `R_⊥ t₃/(t₃ + t₄)` for `t₃ ± t₄` the last fraction's terms) where
/// complex arithmetic takes three complex divisions (test: the same values).
#[cfg(test)]
fn fresnel_conductor(cos_i: f64, eta: f64, k: f64) -> f64 {
    fresnel_conductor_channels(cos_i, [eta; 4], [k; 4])[0]
}

/// `fresnel_conductor` for four channels at once, each with the same operations in the same
/// order (so the same bits): written lane by lane, the square roots and divisions of all
/// channels go through the vector unit together instead of one after another.
#[inline(always)]
fn fresnel_conductor_channels(cos_i: f64, eta: [f64; 4], k: [f64; 4]) -> [f64; 4] {
    let c = cos_i.abs().min(1.0);
    let (c2, s2) = (c * c, 1.0 - c * c);
    let mut out = [0.0; 4];
    for i in 0..4 {
        let t0 = eta[i] * eta[i] - k[i] * k[i] - s2;
        let ab2 = (t0 * t0 + 4.0 * eta[i] * eta[i] * k[i] * k[i]).sqrt();
        let a = (0.5 * (ab2 + t0)).max(0.0).sqrt();
        let (t1, t2) = (ab2 + c2, 2.0 * c * a);
        let (t3, t4) = (c2 * ab2 + s2 * s2, t2 * s2);
        // `(R_⊥ + R_∥)/2 = R_⊥ (1 + (t₃ − t₄)/(t₃ + t₄))/2 = R_⊥ t₃/(t₃ + t₄)`: one division.
        out[i] = ((t1 - t2) * t3 / ((t1 + t2) * (t3 + t4))).clamp(0.0, 1.0);
    }
    out
}

/// [`fresnel_conductor_channels`] at normal incidence, where it is
/// `((η − 1)² + κ²) / ((η + 1)² + κ²)`: no square root (Schlick's term starts from it at every
/// evaluation).
#[inline(always)]
fn normal_reflectance_channels(eta: [f64; 4], k: [f64; 4]) -> [f64; 4] {
    std::array::from_fn(|i| {
        let (below, above, k2) = (eta[i] - 1.0, eta[i] + 1.0, k[i] * k[i]);
        ((below * below + k2) / (above * above + k2)).clamp(0.0, 1.0)
    })
}

impl Conductor {
    /// `F` per channel at `cos`; `η = κ = 0` stands for an ideal mirror of reflectance `tint`.
    /// Computed whole, then chosen (no early return: the path tracer's lanes run it for eight
    /// conductors at once).
    #[inline(always)]
    pub fn fresnel(&self, cos: f64) -> Vec3 {
        let mirror = self.eta == Vec3::ZERO && self.k == Vec3::ZERO;
        let channels = |v: Vec3| [v.x, v.y, v.z, 0.0];
        let f = if self.schlick {
            let f0 = normal_reflectance_channels(channels(self.eta), channels(self.k));
            let f = |i: usize| f0[i] + (1.0 - f0[i]) * (1.0 - cos.abs().min(1.0)).powi(5);
            Vec3::new(f(0), f(1), f(2))
        } else {
            let f = fresnel_conductor_channels(cos, channels(self.eta), channels(self.k));
            Vec3::new(f[0], f[1], f[2])
        };
        let f = match &self.film {
            Some(film) => {
                let f0 = normal_reflectance_channels(channels(self.eta), channels(self.k));
                film.blend(f, cos, Vec3::new(f0[0], f0[1], f0[2]))
            }
            None => f,
        };
        if mirror { self.tint } else { f * self.tint }
    }

    /// `D G F / (4⟨l,n⟩⟨v,n⟩)` (plus the light of several facets with
    /// [`Self::multiscatter`]); 0 for a smooth metal.
    pub fn eval(&self, v: Vec3, l: Vec3) -> Vec3 {
        self.eval_pdf(v, l).0
    }

    /// The facet's density over `4⟨h,v⟩` (mixed with the cosine density of the light of
    /// several facets, in proportion to the two lobes' albedos, with [`Self::multiscatter`]).
    pub fn pdf(&self, v: Vec3, l: Vec3) -> f64 {
        self.eval_pdf(v, l).1
    }

    /// [`Self::eval`] and [`Self::pdf`] with the half vector and `D` found once (the same numbers).
    pub fn eval_pdf(&self, v: Vec3, l: Vec3) -> (Vec3, f64) {
        let Some(f) = &self.facets else { return (Vec3::ZERO, 0.0) };
        let lobe = self.lobe_seen_from(v);
        self.eval_pdf_with(f, lobe.as_ref().map(|(ms, p)| (ms, *p)), v, l)
    }

    /// [`Self::eval_pdf`] on `facets` with the lobe of several facets `ms` seen from `v` and
    /// the probability of sampling it.
    #[inline(always)]
    pub(crate) fn eval_pdf_with(
        &self,
        facets: &Microfacet,
        ms: Option<(&super::multiscatter::MultipleScattering, f64)>,
        v: Vec3,
        l: Vec3,
    ) -> (Vec3, f64) {
        let (value, pdf) = self.rough_eval_pdf(facets, v, l);
        let Some((ms, p)) = ms else { return (value, pdf) };
        if !same_side(v, l) {
            return (Vec3::ZERO, 0.0);
        }
        (value + ms.eval(l), (1.0 - p) * pdf + p * super::cosine_pdf(v, l))
    }

    /// The lobe of several facets seen from `v` and the probability of sampling it.
    #[inline(always)]
    pub(crate) fn lobe_seen_from(&self, v: Vec3) -> Option<(super::multiscatter::MultipleScattering, f64)> {
        let ms = self.multiple_scattering(v)?;
        Some((ms, ms.choice(self.fresnel(v.z))))
    }

    /// The mirror direction, or reflection about a sampled facet (or, with
    /// [`Self::multiscatter`], by `uc`, a cosine-weighted direction for the light of several
    /// facets), valued as the whole BSDF.
    pub fn sample(&self, v: Vec3, uc: f64, u: Vec2) -> Option<BsdfSample> {
        let Some(facets) = &self.facets else { return Some(self.smooth_sample(v)) };
        let Some((ms, p)) = self.lobe_seen_from(v) else {
            let (sampled, sample) = self.rough_sample(facets, v, 0.0, u);
            return sampled.then_some(sample);
        };
        let (sampled, sample) = self.several_sample_whole(facets, (&ms, p), v, uc, u);
        sampled.then_some(sample)
    }

    /// [`Self::sample`] on `facets` with the lobe of several facets `ms` seen from `v` and the
    /// probability `p` of sampling it, computed whole and then chosen, for the lanes as for
    /// it: the lobe chosen by `uc` — its cosine-weighted direction and the facet's both
    /// computed, one taken —, kept where the density is not 0; whether there is one, and the
    /// sample.
    #[inline(always)]
    pub(crate) fn several_sample_whole(
        &self,
        facets: &Microfacet,
        (ms, p): (&super::multiscatter::MultipleScattering, f64),
        v: Vec3,
        uc: f64,
        u: Vec2,
    ) -> (bool, BsdfSample) {
        let (facet_ok, facet) = self.rough_sample(facets, v, 0.0, u);
        let several = uc < p;
        let l = if several { super::cosine_hemisphere(u, v) } else { facet.l };
        let (f, pdf) = self.eval_pdf_with(facets, Some((ms, p)), v, l);
        ((several || facet_ok) && pdf > 0.0, BsdfSample { l, f, pdf, delta: false, eta: 1.0, dispersive: false })
    }

    /// The lobe of the light of several facets seen from `v`, with [`Self::multiscatter`].
    #[inline(always)]
    pub(crate) fn multiple_scattering(&self, v: Vec3) -> Option<super::multiscatter::MultipleScattering> {
        Some(self.multiscatter?.seen_from(v))
    }

    /// This conductor giving back the light of several facets: the lobe's terms found, where
    /// its facets are Trowbridge–Reitz (GGX) with Smith's shadowing, whose albedo is tabulated
    /// (else single scattering: `None`).
    pub fn with_several_facets(self) -> Self {
        use alhazen_scene::bsdf::{Distribution, Shadowing};
        let ggx =
            |f: &&super::Microfacet| f.distribution == Distribution::TrowbridgeReitz && f.shadowing == Shadowing::Smith;
        let lobe = self.facets.as_ref().filter(ggx).map(|f| {
            let alpha = (f.alpha_u * f.alpha_v).sqrt();
            super::SeveralFacets::new(alpha, self.fresnel_average())
        });
        Conductor { multiscatter: lobe, ..self }
    }

    /// The cosine-weighted mean of [`Self::fresnel`]: `F0 + (1 − F0)/21` for Schlick's term,
    /// the tint for an ideal mirror, by quadrature for the exact formula.
    fn fresnel_average(&self) -> Vec3 {
        if self.eta == Vec3::ZERO && self.k == Vec3::ZERO {
            return self.tint;
        }
        if self.schlick && self.film.is_none() {
            let channels = |v: Vec3| [v.x, v.y, v.z, 0.0];
            let f0 = normal_reflectance_channels(channels(self.eta), channels(self.k));
            let avg = |i: usize| f0[i] + (1.0 - f0[i]) / 21.0;
            return Vec3::new(avg(0), avg(1), avg(2)) * self.tint;
        }
        super::multiscatter::fresnel_average(|c| self.fresnel(c))
    }

    /// The smooth conductor's mirror direction, weighted by the Fresnel term.
    #[inline(always)]
    pub(crate) fn smooth_sample(&self, v: Vec3) -> BsdfSample {
        let l = Vec3::new(-v.x, -v.y, v.z);
        let f = self.fresnel(v.z) / v.z.abs();
        BsdfSample { l, f, pdf: 1.0, delta: true, eta: 1.0, dispersive: false }
    }
}

impl MicrofacetLobes for Conductor {
    /// [`Self::eval_pdf`] of the rough conductor of `facets` (this conductor's), computed whole
    /// and then chosen, for the path tracer's lanes as much as for [`Self::eval_pdf`].
    #[inline(always)]
    fn rough_eval_pdf(&self, facets: &Microfacet, v: Vec3, l: Vec3) -> (Vec3, f64) {
        let h = (v + l).normalize_or_zero();
        let valid = same_side(v, l) && h != Vec3::ZERO;
        // `half_vector`'s normal, turned to the upper hemisphere.
        let h = h * h.z.signum();
        let d = facets.d(h);
        let value = self.fresnel(h.dot(l)) * (d * facets.g(v, l, h) / (4.0 * l.z.abs() * v.z.abs()));
        let pdf = facets.pdf_h_from(v, h, d) / (4.0 * h.dot(v).abs());
        if valid { (value, pdf) } else { (Vec3::ZERO, 0.0) }
    }

    /// Reflection of `v` about a facet of `facets` (this conductor's) drawn with the numbers
    /// `u` (one lobe: `uc` is not needed): whether there is one (a facet, and a positive density) and the sample. Computed
    /// whole and then chosen, for the lanes as for [`Self::sample`].
    #[inline(always)]
    fn rough_sample(&self, facets: &Microfacet, v: Vec3, _uc: f64, u: Vec2) -> (bool, BsdfSample) {
        let h = facets.sample_h_from(v, u);
        let l = reflect(v, h.unwrap_or(Vec3::Z) * v.z.signum());
        let (f, pdf) = self.rough_eval_pdf(facets, v, l);
        (h.is_some() && pdf > 0.0, BsdfSample { l, f, pdf, delta: false, eta: 1.0, dispersive: false })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Complex arithmetic, for the reference form of the equations.
    #[derive(Clone, Copy)]
    struct C(f64, f64);

    impl C {
        fn add(self, o: C) -> C {
            C(self.0 + o.0, self.1 + o.1)
        }
        fn sub(self, o: C) -> C {
            C(self.0 - o.0, self.1 - o.1)
        }
        fn mul(self, o: C) -> C {
            C(self.0 * o.0 - self.1 * o.1, self.0 * o.1 + self.1 * o.0)
        }
        fn div(self, o: C) -> C {
            let d = o.0 * o.0 + o.1 * o.1;
            C((self.0 * o.0 + self.1 * o.1) / d, (self.1 * o.0 - self.0 * o.1) / d)
        }
        fn norm2(self) -> f64 {
            self.0 * self.0 + self.1 * self.1
        }
        fn sqrt(self) -> C {
            let r = self.norm2().sqrt();
            let re = ((r + self.0) / 2.0).max(0.0).sqrt();
            let im = ((r - self.0) / 2.0).max(0.0).sqrt();
            C(re, if self.1 < 0.0 { -im } else { im })
        }
    }

    /// `½(|r_∥|² + |r_⊥|²)` with the complex transmitted cosine, term by term.
    fn complex_form(c: f64, eta: f64, k: f64) -> f64 {
        let n = C(eta, k);
        let sin2_t = C(1.0 - c * c, 0.0).div(n.mul(n));
        let cos_t = C(1.0, 0.0).sub(sin2_t).sqrt();
        let ci = C(c, 0.0);
        let r_par = n.mul(ci).sub(cos_t).div(n.mul(ci).add(cos_t));
        let r_perp = ci.sub(n.mul(cos_t)).div(ci.add(n.mul(cos_t)));
        ((r_par.norm2() + r_perp.norm2()) / 2.0).min(1.0)
    }

    proptest::proptest! {
        /// The real form gives the complex form's reflectance for metals, dielectrics and
        /// everything between, at every angle.
        #[test]
        fn real_form_is_the_complex_form(c in 0.0..=1.0f64, eta in 0.05..5.0f64, k in 0.0..10.0f64) {
            let (a, b) = (fresnel_conductor(c, eta, k), complex_form(c, eta, k));
            proptest::prop_assert!((a - b).abs() <= 1e-12 + 1e-9 * b, "c {} η {} κ {}: {} vs {}", c, eta, k, a, b);
        }

        /// At normal incidence the square-root-free form is the general one.
        #[test]
        fn normal_reflectance_is_the_reflectance_at_normal_incidence(eta in 0.0..20.0f64, k in 0.0..20.0f64) {
            let (a, b) = (normal_reflectance_channels([eta; 4], [k; 4])[0], fresnel_conductor_channels(1.0, [eta; 4], [k; 4])[0]);
            proptest::prop_assert!((a - b).abs() <= 1e-14 + 1e-12 * b, "η {} κ {}: {} vs {}", eta, k, a, b);
        }
    }
}
