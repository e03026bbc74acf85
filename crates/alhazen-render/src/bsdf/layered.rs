//! The course's form of a physically based reflection model, `ρ_r = v(k_d ρ_d + k_s ρ_s)`:
//! a Lambertian `ρ_d` plus a specular lobe `ρ_s`, zero unless `l` and `v` are on the same side
//! (the factor `v`). Phong, Blinn–Phong and Cook–Torrance differ only in `ρ_s`; sampling picks the
//! diffuse or the specular lobe in proportion to their weights and the density is the mixture.

use super::{BsdfSample, cosine_hemisphere, cosine_pdf, lobe_probability, same_side};
use alhazen_math::{Vec2, Vec3, color::luminance};
use std::f64::consts::FRAC_1_PI;

/// A specular lobe `ρ_s` with a way to sample it.
pub trait SpecularLobe {
    /// `ρ_s(l, v)` for `l`, `v` on the same side.
    fn value(&self, v: Vec3, l: Vec3) -> f64;
    /// Solid-angle density of [`SpecularLobe::sample`].
    fn pdf(&self, v: Vec3, l: Vec3) -> f64;
    /// `(value(v, l), pdf(v, l))`: the same numbers, with what they share computed once
    /// where the lobe has it.
    #[inline(always)]
    fn value_pdf(&self, v: Vec3, l: Vec3) -> (f64, f64) {
        (self.value(v, l), self.pdf(v, l))
    }
    /// A direction `l` from `u ∈ [0, 1)²`.
    fn sample(&self, v: Vec3, u: Vec2) -> Option<Vec3>;
    /// What the diffuse term is weighed by, seen at cosine `mu`: 1 unless the lobe layers it
    /// (`bsdf::layering`).
    #[inline(always)]
    fn diffuse_weight(&self, _mu: f64) -> f64 {
        1.0
    }
}

/// `k_d·albedo/π + k_s·ρ_s`, and `transmittance/π` on the other side (a thin translucent
/// sheet; black for none).
#[derive(Clone, Copy, Debug)]
pub struct DiffuseSpecular<S> {
    /// Diffuse colour times `k_d`.
    pub diffuse: Vec3,
    /// `k_s`.
    pub ks: f64,
    /// `ρ_s`.
    pub lobe: S,
    /// What passes diffusely through to the other side.
    pub transmittance: Vec3,
}

impl<S: SpecularLobe> DiffuseSpecular<S> {
    /// The probability of sampling a diffuse lobe (reflected or passed through) rather than
    /// the specular one.
    #[inline(always)]
    pub(super) fn p_diffuse(&self) -> f64 {
        lobe_probability(luminance(self.diffuse) + luminance(self.transmittance), self.ks)
    }

    /// Of a diffuse lobe, the probability that it is the reflected one (exactly 1 without
    /// transmittance).
    #[inline(always)]
    pub(super) fn p_reflected(&self) -> f64 {
        let through = luminance(self.transmittance);
        if through > 0.0 { luminance(self.diffuse) / (luminance(self.diffuse) + through) } else { 1.0 }
    }

    /// `ρ`.
    #[inline(always)]
    pub fn eval(&self, v: Vec3, l: Vec3) -> Vec3 {
        let diffuse = FRAC_1_PI * self.lobe.diffuse_weight(v.z);
        if !same_side(v, l) {
            return self.transmittance * diffuse;
        }
        self.diffuse * diffuse + Vec3::splat(self.ks * self.lobe.value(v, l))
    }

    /// The mixture of the cosine densities, reflected and passed through, and the lobe's.
    #[inline(always)]
    pub fn pdf(&self, v: Vec3, l: Vec3) -> f64 {
        let pd = self.p_diffuse();
        if !same_side(v, l) {
            // The specular lobe's facets send some of its samples through too.
            let lobe = if self.transmittance != Vec3::ZERO { (1.0 - pd) * self.lobe.pdf(v, l) } else { 0.0 };
            return pd * (1.0 - self.p_reflected()) * (l.z.abs() * FRAC_1_PI) + lobe;
        }
        pd * self.p_reflected() * cosine_pdf(v, l) + (1.0 - pd) * self.lobe.pdf(v, l)
    }

    /// `(eval(v, l), pdf(v, l))`, the lobe's value and density computed together.
    #[inline(always)]
    pub fn eval_pdf(&self, v: Vec3, l: Vec3) -> (Vec3, f64) {
        let pd = self.p_diffuse();
        let diffuse = FRAC_1_PI * self.lobe.diffuse_weight(v.z);
        if !same_side(v, l) {
            let lobe = if self.transmittance != Vec3::ZERO { (1.0 - pd) * self.lobe.pdf(v, l) } else { 0.0 };
            return (self.transmittance * diffuse, pd * (1.0 - self.p_reflected()) * (l.z.abs() * FRAC_1_PI) + lobe);
        }
        let (value, density) = self.lobe.value_pdf(v, l);
        let f = self.diffuse * diffuse + Vec3::splat(self.ks * value);
        (f, pd * self.p_reflected() * cosine_pdf(v, l) + (1.0 - pd) * density)
    }

    /// The diffuse reflection, the diffuse transmission or the specular lobe by `uc`, then a
    /// direction from it.
    #[inline(always)]
    pub fn sample(&self, v: Vec3, uc: f64, u: Vec2) -> Option<BsdfSample> {
        let pd = self.p_diffuse();
        let l = if uc < pd * self.p_reflected() {
            cosine_hemisphere(u, v)
        } else if uc < pd {
            cosine_hemisphere(u, -v)
        } else {
            self.lobe.sample(v, u)?
        };
        let (f, pdf) = self.eval_pdf(v, l);
        (pdf > 0.0).then_some(BsdfSample { l, f, pdf, delta: false, eta: 1.0, dispersive: false })
    }
}
