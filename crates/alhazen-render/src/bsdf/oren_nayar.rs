//! Oren–Nayar rough diffuse reflection, exactly as the course writes it: the single-bounce term
//! `ρ_d,1 = c/π (C₁ + cos Δφ · C₂ tan β + (1 − |cos Δφ|) C₃ tan((α+β)/2))` and the
//! interreflection term `ρ_d,2 = c²/π · 0.17σ²/(σ²+0.13) · (1 − cos Δφ (2β/π)²)`.
//!
//! Parameters: `albedo` (`c_λ`), `sigma` (roughness σ, radians), `interreflection` (add `ρ_d,2`).
//! σ = 0 reproduces Lambert.
//!
//! Note on the seed: the course prints `(1 − c β²/π²)` in `ρ_d,2`; Oren and Nayar's paper has
//! `(2β/π)²`, which we use (the two differ by the factor 4 on β²).

use super::{BsdfSample, cosine_pdf, same_side, sample_cosine};
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
    /// `ρ_d,1 + ρ_d,2`.
    pub fn eval(&self, v: Vec3, l: Vec3) -> Vec3 {
        if !same_side(v, l) {
            return Vec3::ZERO;
        }
        let (theta_l, theta_v) = (l.z.abs().min(1.0).acos(), v.z.abs().min(1.0).acos());
        let (alpha, beta) = (theta_l.max(theta_v), theta_l.min(theta_v));
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
            let d = if c >= 0.0 { alpha.sin() } else { alpha.sin() - (2.0 * beta / PI).powi(3) };
            let c2 = 0.45 * s2 / (s2 + 0.09) * d;
            let c3 = 0.125 * s2 / (s2 + 0.09) * (4.0 * alpha * beta / (PI * PI)).powi(2);
            c1 + c * c2 * beta.tan() + (1.0 - c.abs()) * c3 * ((alpha + beta) / 2.0).tan()
        };
        let mut rho = self.albedo * (FRAC_1_PI * single);
        if self.interreflection {
            let k = 0.17 * s2 / (s2 + 0.13) * (1.0 - c * (2.0 * beta / PI).powi(2));
            rho += self.albedo * self.albedo * (FRAC_1_PI * k);
        }
        rho.max(Vec3::ZERO)
    }

    /// Cosine-weighted density.
    pub fn pdf(&self, v: Vec3, l: Vec3) -> f64 {
        cosine_pdf(v, l)
    }

    /// Cosine-weighted sampling.
    pub fn sample(&self, v: Vec3, _uc: f64, u: Vec2) -> Option<BsdfSample> {
        sample_cosine(v, u, |l| self.eval(v, l))
    }
}
