//! Sheen over another scattering function: the soft rim of velvet, satin and other cloth
//! (glTF's `KHR_materials_sheen`, Blender's Principled Sheen). Fibres standing up from the
//! surface are a microfacet distribution of their own, Estevez and Kulla's "Charlie" sheen
//! (2017, "Production Friendly Microfacet Sheen BRDF"):
//!
//! `D(h) = (2 + 1/α) sin(ϑ_h)^{1/α} / (2π)`,
//!
//! with their fitted shadowing `Λ(μ)` in `ρ_s = D / ((1 + Λ(μ_v) + Λ(μ_l)) · 4 μ_v μ_l)`. The
//! sheen of colour `c` lies over the base, which receives what the sheen lets through towards
//! the viewer (the glTF specification's albedo scaling, as [`super::Coated`] layers a coat):
//!
//! `ρ(v, l) = c·ρ_s(v, l) + (1 − max(c)·E_s(μ_v))·ρ_base(v, l)`,
//!
//! `E_s(μ, α)` the sheen's directional albedo, tabulated once per process. The sheen is sampled
//! cosine-weighted (its lobe is broad).
//!
//! Parameters: the base BSDF, the sheen's colour and roughness `α = r²` (glTF's
//! `sheenRoughnessFactor` is `r`).

use super::{Bsdf, BsdfSample, cosine_hemisphere, cosine_pdf, same_side};
use alhazen_math::{Vec2, Vec3};
use std::f64::consts::PI;
use std::sync::OnceLock;

/// A base under a sheen.
#[derive(Clone, Debug)]
pub struct Sheened {
    /// What lies under the sheen.
    pub base: Bsdf,
    /// The sheen's colour.
    pub color: Vec3,
    /// The fibres' roughness `α ∈ [10⁻³, 1]`.
    pub alpha: f64,
}

/// The least roughness: below it `sin^{1/α}` underflows everywhere but at grazing facets.
const LEAST_ALPHA: f64 = 1e-3;

impl Sheened {
    /// `base` under a sheen of `color` and roughness `alpha` (clamped to `[10⁻³, 1]`).
    pub fn new(base: Bsdf, color: Vec3, alpha: f64) -> Self {
        Sheened { base, color, alpha: alpha.clamp(LEAST_ALPHA, 1.0) }
    }

    /// `max(c)·E_s(μ)`: the share of the light leaving along a direction of cosine `cos` that
    /// the sheen reflects.
    pub(crate) fn sheen_albedo(&self, cos: f64) -> f64 {
        (self.color.max_element() * albedo(cos.abs().min(1.0), self.alpha)).clamp(0.0, 1.0)
    }

    /// The probability of sampling the sheen rather than the base: its albedo's share, within
    /// `[0.1, 0.9]` where there is a sheen.
    fn sheen_choice(&self, albedo: f64) -> f64 {
        if self.color.max_element() <= 0.0 { 0.0 } else { albedo.clamp(0.1, 0.9) }
    }

    /// `ρ(v, l)`.
    pub fn eval(&self, v: Vec3, l: Vec3) -> Vec3 {
        self.eval_pdf(v, l).0
    }

    /// The mixture of the sheen's and the base's densities.
    pub fn pdf(&self, v: Vec3, l: Vec3) -> f64 {
        self.eval_pdf(v, l).1
    }

    /// [`Self::eval`] and [`Self::pdf`] at once.
    pub fn eval_pdf(&self, v: Vec3, l: Vec3) -> (Vec3, f64) {
        let albedo = self.sheen_albedo(v.z);
        let q = self.sheen_choice(albedo);
        let (fb, pb) = self.base.eval_pdf(v, l);
        let fs = if same_side(v, l) { sheen(v, l, self.alpha) } else { 0.0 };
        (fb * (1.0 - albedo) + self.color * fs, q * cosine_pdf(v, l) + (1.0 - q) * pb)
    }

    /// The sheen's cosine-weighted direction by `uc` below its share, else the base's sample
    /// (`uc` rescaled for it); a delta sample of the base keeps its own weight under the
    /// sheen.
    pub fn sample(&self, v: Vec3, uc: f64, u: Vec2) -> Option<BsdfSample> {
        let albedo = self.sheen_albedo(v.z);
        let q = self.sheen_choice(albedo);
        let (top, base) = (|| Some(cosine_hemisphere(u, v)), |uc| self.base.sample(v, uc, u));
        super::coated::sample_under_layer(base, uc, (q, albedo), top, |l| self.eval_pdf(v, l))
    }
}

/// The sheen lobe `ρ_s(v, l)` (colour 1) for `v`, `l` on one side of the surface.
pub(crate) fn sheen(v: Vec3, l: Vec3, alpha: f64) -> f64 {
    let (mu_v, mu_l) = (v.z.abs(), l.z.abs());
    let h = (v + l).normalize_or_zero();
    if mu_v == 0.0 || mu_l == 0.0 || h == Vec3::ZERO {
        return 0.0;
    }
    let sin2 = (1.0 - h.z * h.z).max(0.0);
    let d = (2.0 + 1.0 / alpha) * sin2.powf(0.5 / alpha) / (2.0 * PI);
    d / ((1.0 + lambda(mu_v, alpha) + lambda(mu_l, alpha)) * 4.0 * mu_v * mu_l)
}

/// Estevez and Kulla's shadowing `Λ(μ)` of the Charlie sheen: their fit `L(x)` (five
/// coefficients interpolated in `(1 − α)²` between the ends of their table), mirrored about
/// `μ = ½` for the terminator's softening.
fn lambda(mu: f64, alpha: f64) -> f64 {
    let t = (1.0 - alpha) * (1.0 - alpha);
    let lerp = |a: f64, b: f64| a + (b - a) * t;
    let (a, b, c, d, e) = (
        lerp(21.5473, 25.3245),
        lerp(3.82987, 3.32435),
        lerp(0.19823, 0.16801),
        lerp(-1.97760, -1.27393),
        lerp(-4.32054, -4.85967),
    );
    let fit = |x: f64| a / (1.0 + b * x.powf(c)) + d * x + e;
    if mu < 0.5 { fit(mu).exp() } else { (2.0 * fit(0.5) - fit(1.0 - mu)).exp() }
}

/// Table size along `μ` and along `α`.
const N: usize = 32;
/// Stratified directions per table cell (`STRATA²`).
const STRATA: usize = 24;

/// `E_s(μ, α)` on the grid `μ_j = j/(N−1)`, `α_i = i/(N−1)` (the first row at the least `α`).
fn table() -> &'static [[f64; N]; N] {
    static TABLE: OnceLock<[[f64; N]; N]> = OnceLock::new();
    TABLE.get_or_init(|| {
        std::array::from_fn(|i| {
            let alpha = (i as f64 / (N - 1) as f64).max(LEAST_ALPHA);
            std::array::from_fn(|j| directional_albedo((j as f64 / (N - 1) as f64).max(1e-3), alpha))
        })
    })
}

/// `∫ ρ_s(v, l) μ_l dω_l` at `μ_v = mu`, by cosine-weighted directions on a stratified grid (a
/// fixed set of numbers: the table is the same every run).
fn directional_albedo(mu: f64, alpha: f64) -> f64 {
    let v = Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
    let mut sum = 0.0;
    for a in 0..STRATA {
        for b in 0..STRATA {
            let u = Vec2::new((a as f64 + 0.5) / STRATA as f64, (b as f64 + 0.5) / STRATA as f64);
            let l = cosine_hemisphere(u, v);
            // f·μ_l / (μ_l/π) = π·f.
            sum += PI * sheen(v, l, alpha);
        }
    }
    sum / (STRATA * STRATA) as f64
}

/// `E_s(μ, α)`, bilinear in the table.
fn albedo(mu: f64, alpha: f64) -> f64 {
    let t = table();
    let x = mu.clamp(0.0, 1.0) * (N - 1) as f64;
    let y = alpha.clamp(0.0, 1.0) * (N - 1) as f64;
    let (j, i) = ((x as usize).min(N - 2), (y as usize).min(N - 2));
    let (fx, fy) = (x - j as f64, y - i as f64);
    let row = |i: usize| t[i][j] * (1.0 - fx) + t[i][j + 1] * fx;
    row(i) * (1.0 - fy) + row(i + 1) * fy
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sheen alone reflects no more than it receives, at every roughness and angle, and
    /// reflects some at grazing views.
    #[test]
    fn the_sheen_albedo_stays_within_one() {
        for i in 0..N {
            for j in 1..N {
                let e = table()[i][j];
                assert!((0.0..=1.0).contains(&e), "α row {i}, μ column {j}: {e}");
            }
        }
        assert!(albedo(0.1, 0.5) > 0.05, "{}", albedo(0.1, 0.5));
    }

    /// The Charlie distribution is one over the projected facets, `∫ D(h) cos ϑ_h dω_h = 1`, at
    /// every roughness; the sheen lobe is reciprocal.
    #[test]
    fn the_fibres_are_a_distribution_and_reciprocal() {
        for alpha in [0.01, 0.09, 0.3, 0.64, 1.0] {
            let d = |theta: f64| (2.0 + 1.0 / alpha) * theta.sin().powf(1.0 / alpha) / (2.0 * PI);
            let n = 20_000;
            let h = 0.5 * PI / n as f64;
            // ∫ 2π D cos ϑ sin ϑ dϑ by the midpoint rule.
            let total: f64 =
                (0..n).map(|k| (k as f64 + 0.5) * h).map(|t| 2.0 * PI * d(t) * t.cos() * t.sin() * h).sum();
            assert!((total - 1.0).abs() < 1e-4, "α {alpha}: {total}");
            for (a, b) in [(0.2, 1.1), (0.7, 0.3), (1.4, 0.9)] {
                let v = Vec3::new(f64::sin(a), 0.0, f64::cos(a));
                let l = Vec3::new(-f64::sin(b) * 0.6, f64::sin(b) * 0.8, f64::cos(b));
                let (x, y) = (sheen(v, l, alpha), sheen(l, v, alpha));
                assert!((x - y).abs() <= 1e-12 * x.max(1.0), "α {alpha}: {x} {y}");
            }
        }
    }
}
