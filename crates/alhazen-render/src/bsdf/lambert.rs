//! Lambert's perfectly matt surface (course, "In the Lambertian model…"): `ρ = albedo/π` when
//! `l` and `v` are on the same side, else 0. Energy is conserved for albedo ≤ 1 (`ρ < 1/π`).
//!
//! Parameters: `albedo` — the fraction of light reflected, per channel.

use super::{BsdfSample, cosine_pdf, same_side, sample_cosine};
use alhazen_math::{Vec2, Vec3};
use std::f64::consts::FRAC_1_PI;

/// Lambertian reflection.
#[derive(Clone, Copy, Debug)]
pub struct Lambert {
    /// Albedo.
    pub albedo: Vec3,
}

impl Lambert {
    /// `ρ`.
    pub fn eval(&self, v: Vec3, l: Vec3) -> Vec3 {
        if same_side(v, l) { self.albedo * FRAC_1_PI } else { Vec3::ZERO }
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
