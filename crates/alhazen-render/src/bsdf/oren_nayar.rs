//! Oren–Nayar rough diffuse reflection, exactly as the course writes it: the single-bounce term
//! `ρ_d,1 = c/π (C₁ + cos Δφ · C₂ tan β + (1 − |cos Δφ|) C₃ tan((α+β)/2))` and the
//! interreflection term `ρ_d,2 = c²/π · 0.17σ²/(σ²+0.13) · (1 − cos Δφ (2β/π)²)`.
//!
//! Parameters: `albedo` (`c_λ`), `sigma` (roughness σ, radians), `interreflection` (add `ρ_d,2`).
//! σ = 0 reproduces Lambert.
//!
//! Note on the seed: the course prints `(1 − c β²/π²)` in `ρ_d,2`; Oren and Nayar's paper has
//! `(2β/π)²`, which we use (the two differ by the factor 4 on β²).

use super::{BsdfSample, cosine_hemisphere, cosine_pdf, same_side};
use alhazen_math::elementary::acos;
use alhazen_math::{Vec2, Vec3};
use std::f64::consts::{FRAC_1_PI, PI};

/// Oren–Nayar.
#[derive(Clone, Copy, Debug)]
pub struct OrenNayar {
    /// `c_λ`.
    pub albedo: Vec3,
    /// σ in radians.
    pub sigma: f64,
    /// Include `ρ_d,2`.
    pub interreflection: bool,
}

impl OrenNayar {
    /// `ρ_d,1 + ρ_d,2`. The angles by our own `acos` and the tangents from the cosines
    /// (`tan β = sin β / cos β`, `tan((α+β)/2) = (sin α + sin β)/(cos α + cos β)`): no library
    /// calls, so the same bits on every processor and a loop over lanes that vectorises.
    #[inline(always)]
    pub fn eval(&self, v: Vec3, l: Vec3) -> Vec3 {
        if !same_side(v, l) {
            return Vec3::ZERO;
        }
        // α is the larger angle of the two, β the smaller: their cosines the smaller and larger
        // (β < π/2: both directions lie off the tangent plane on the same side).
        let (cos_l, cos_v) = (l.z.abs().min(1.0), v.z.abs().min(1.0));
        let (cos_a, cos_b) = (cos_l.min(cos_v), cos_l.max(cos_v));
        let sine = |c: f64| ((1.0 - c) * (1.0 + c)).sqrt();
        let (sin_a, sin_b) = (sine(cos_a), sine(cos_b));
        let (alpha, beta) = (acos(cos_a), acos(cos_b));
        // cos Δφ between the projections on the tangent plane (irrelevant when one is normal).
        let (pl, pv) = (Vec2::new(l.x, l.y), Vec2::new(v.x, v.y));
        let denom = pl.length() * pv.length();
        let normal_one = denom < 1e-12;
        let c = if normal_one { 0.0 } else { (pl.dot(pv) / denom).clamp(-1.0, 1.0) };
        let s2 = self.sigma * self.sigma;
        let c1 = 1.0 - 0.5 * s2 / (s2 + 0.33);
        let single = if normal_one {
            c1
        } else {
            let d = if c >= 0.0 { sin_a } else { sin_a - (2.0 * beta / PI).powi(3) };
            let c2 = 0.45 * s2 / (s2 + 0.09) * d;
            let c3 = 0.125 * s2 / (s2 + 0.09) * (4.0 * alpha * beta / (PI * PI)).powi(2);
            c1 + c * c2 * (sin_b / cos_b) + (1.0 - c.abs()) * c3 * ((sin_a + sin_b) / (cos_a + cos_b))
        };
        let mut rho = self.albedo * (FRAC_1_PI * single);
        if self.interreflection {
            let k = 0.17 * s2 / (s2 + 0.13) * (1.0 - c * (2.0 * beta / PI).powi(2));
            rho += self.albedo * self.albedo * (FRAC_1_PI * k);
        }
        rho.max(Vec3::ZERO)
    }

    /// Cosine-weighted density.
    #[inline(always)]
    pub fn pdf(&self, v: Vec3, l: Vec3) -> f64 {
        cosine_pdf(v, l)
    }

    /// Cosine-weighted sampling (`sample_cosine`'s, written out: the path tracer's lanes
    /// then evaluate it inline, in vector registers).
    #[inline(always)]
    pub fn sample(&self, v: Vec3, _uc: f64, u: Vec2) -> Option<BsdfSample> {
        let l = cosine_hemisphere(u, v);
        let (f, pdf) = (self.eval(v, l), cosine_pdf(v, l));
        (pdf > 0.0).then_some(BsdfSample { l, f, pdf, delta: false, eta: 1.0, dispersive: false })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The course's formula with the library's `acos`, `sin` and `tan`, as written.
    fn by_the_book(b: &OrenNayar, v: Vec3, l: Vec3) -> Vec3 {
        let (theta_l, theta_v) = (l.z.abs().min(1.0).acos(), v.z.abs().min(1.0).acos());
        let (alpha, beta) = (theta_l.max(theta_v), theta_l.min(theta_v));
        let (pl, pv) = (Vec2::new(l.x, l.y), Vec2::new(v.x, v.y));
        let c = (pl.dot(pv) / (pl.length() * pv.length())).clamp(-1.0, 1.0);
        let s2 = b.sigma * b.sigma;
        let c1 = 1.0 - 0.5 * s2 / (s2 + 0.33);
        let d = if c >= 0.0 { alpha.sin() } else { alpha.sin() - (2.0 * beta / PI).powi(3) };
        let c2 = 0.45 * s2 / (s2 + 0.09) * d;
        let c3 = 0.125 * s2 / (s2 + 0.09) * (4.0 * alpha * beta / (PI * PI)).powi(2);
        let single = c1 + c * c2 * beta.tan() + (1.0 - c.abs()) * c3 * ((alpha + beta) / 2.0).tan();
        let k = 0.17 * s2 / (s2 + 0.13) * (1.0 - c * (2.0 * beta / PI).powi(2));
        (b.albedo * (FRAC_1_PI * single) + b.albedo * b.albedo * (FRAC_1_PI * k)).max(Vec3::ZERO)
    }

    proptest::proptest! {
        /// The tangents from the cosines give the formula's values (to rounding), at every
        /// pair of directions on one side, grazing ones included.
        #[test]
        fn eval_is_the_course_formula(
            sigma in 0.0..1.5f64,
            (zl, phil) in (1e-6..1.0f64, 0.0..std::f64::consts::TAU),
            (zv, phiv) in (1e-6..1.0f64, 0.0..std::f64::consts::TAU),
        ) {
            let dir = |z: f64, phi: f64| {
                let r = (1.0 - z * z).sqrt();
                Vec3::new(r * phi.cos(), r * phi.sin(), z)
            };
            let b = OrenNayar { albedo: Vec3::new(0.9, 0.5, 0.1), sigma, interreflection: true };
            let (v, l) = (dir(zv, phiv), dir(zl, phil));
            let (ours, theirs) = (b.eval(v, l), by_the_book(&b, v, l));
            proptest::prop_assert!((ours - theirs).abs().max_element() <= 1e-12 * theirs.max_element().max(1e-3), "{ours} vs {theirs}");
        }
    }
}
