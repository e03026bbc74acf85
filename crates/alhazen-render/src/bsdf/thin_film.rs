//! Thin-film interference (iridescence: soap films, oil on water, tempered steel), after Belcour
//! and Barla 2017, "A Practical Extension to Microfacet Theory for the Modeling of Varying
//! Iridescence", in the form glTF's `KHR_materials_iridescence` gives it: a dielectric film of
//! index `η₂` and thickness `d` between the outside (index `η₁`) and a base of normal-incidence
//! reflectance `F₀`, whose Fresnel factor becomes the Airy sum of the light bouncing inside
//! the film, `R₁₂ + T₁₂₁² R₂₃ / (1 − R₁₂R₂₃) + Σ_m C_m S_m`.
//!
//! The interfaces' reflectances are Schlick's (`R₁₂` at the incidence cosine, `R₂₃` at the
//! film's, from `F₀`'s index `(1 + √F₀)/(1 − √F₀)`); the phase of the light that crossed the
//! film twice is `2π·OPD/λ + φ` with the optical path difference `OPD = 2η₂d·cos θ₂` and the
//! interfaces' phase flips `φ` (π where light meets a lower index). In RGB the terms `m = 1, 2`
//! are integrated over the visible spectrum analytically, `S_m` the colour-matching functions'
//! Fourier transforms (Gaussian fits) taken to linear sRGB; rendering spectrally, each channel
//! is its own wavelength and `S_m = 2 cos(m(2π·OPD/λ + φ))`.

use alhazen_math::elementary::exp;
use alhazen_math::{Vec3, sin_cos_turns};
use std::f64::consts::PI;

/// A thin dielectric film over a surface: how much of it, its index and thickness.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThinFilm {
    /// Its weight `w ∈ [0, 1]`: the Fresnel factor is `(1 − w)·F + w·F_film`.
    pub weight: f32,
    /// The film's index of refraction.
    pub ior: f32,
    /// The film's thickness in nanometres.
    pub thickness: f32,
    /// The index outside the film (1 in air; a clear coat's over it).
    pub outside: f32,
    /// The channels' wavelengths (nm) when rendering spectrally; RGB when `None`.
    pub wavelengths: Option<[f32; 3]>,
}

/// Schlick's `F₀ + (1 − F₀)(1 − c)⁵`.
#[inline]
fn schlick(f0: f64, cos: f64) -> f64 {
    f0 + (1.0 - f0) * (1.0 - cos).powi(5)
}

/// The normal-incidence reflectance `((a − b)/(a + b))²` between indices `a` and `b`.
#[inline]
fn normal_reflectance(a: f64, b: f64) -> f64 {
    ((a - b) / (a + b)).powi(2)
}

/// `(1 − t)·a + t·b` for `t = 0 … 1` smoothed (Hermite's `3t² − 2t³`).
fn smoothstep(edge0: f64, edge1: f64, x: f64) -> f64 {
    let t = ((x - edge0) / (edge1 - edge0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// The colour-matching functions' Gaussian fits in frequency (`x̄`, `ȳ`, `z̄`, and `x̄`'s second
/// lobe): amplitude, mean and variance, as glTF's reference gives them.
const FITS: [(f64, f64, f64); 4] = [
    (5.4856e-13, 1.6810e6, 4.3278e9),
    (4.4201e-13, 1.7953e6, 9.3046e9),
    (5.2481e-13, 2.2084e6, 6.6121e9),
    (9.7470e-14, 2.2399e6, 4.5282e9),
];

/// The XYZ fits' normalisation: a zero path difference gives `(1, 1, 1)`.
const FIT_SUM: f64 = 1.0685e-7;

/// The colour-matching functions' response to the phases `cos(m·(2π·opd/λ + φ))` over the
/// visible spectrum for `m = 1, 2`, taken to linear sRGB: the fits' Fourier transforms,
/// Gaussians again, `a·√(2πσ²)·cos(μ·k + mφ)·exp(−k²σ²)` at `k = 2π·m·opd` (`opd` in nm),
/// each XYZ component shifted by its channel's phase as glTF's reference gives it. The phases
/// are multiples of π (`flip[c]` says an odd one), so `m = 2` follows from `m = 1` by the
/// double angle (`cos 2x = 2cos²x − 1`, `exp(−4k²σ²) = exp(−k²σ²)⁴`): four cosines and four
/// exponentials for both (branchless ones, `alhazen_math`'s).
fn sensitivities(opd: f64, flip: [bool; 3]) -> [Vec3; 2] {
    let phase = 2.0 * PI * opd * 1e-9;
    // The four fits side by side (one vector loop): `cos(μ·k)` as a fraction of a turn,
    // `μ·opd·10⁻⁹`, and the Gaussian envelope.
    let c: [f64; 4] = std::array::from_fn(|j| sin_cos_turns(FITS[j].1 * opd * 1e-9).1);
    let e: [f64; 4] = std::array::from_fn(|j| exp(-phase * phase * FITS[j].2));
    let amplitude = |j: usize| FITS[j].0 * (2.0 * PI * FITS[j].2).sqrt() / FIT_SUM;
    let mut xyz = [[0.0; 3]; 2];
    for j in 0..4 {
        let channel = j % 3;
        let sign = if flip[channel] { -1.0 } else { 1.0 };
        xyz[0][channel] += amplitude(j) * sign * c[j] * e[j];
        xyz[1][channel] += amplitude(j) * (2.0 * c[j] * c[j] - 1.0) * (e[j] * e[j]) * (e[j] * e[j]);
    }
    xyz.map(|[x, y, z]| {
        Vec3::new(
            3.2404542 * x - 1.5371385 * y - 0.4985314 * z,
            -0.9692660 * x + 1.8760108 * y + 0.0415560 * z,
            0.0556434 * x - 0.2040259 * y + 1.0572252 * z,
        )
    })
}

/// [`sensitivities`] at single wavelengths `λ` (rendering spectrally): `cos(m·(2π·opd/λ + φ))`
/// per channel, for `m = 1, 2`.
fn phases_at(opd: f64, flip: [bool; 3], wavelengths: [f32; 3]) -> [Vec3; 2] {
    let c: [f64; 3] = std::array::from_fn(|i| {
        let c = sin_cos_turns(opd / f64::from(wavelengths[i])).1;
        if flip[i] { -c } else { c }
    });
    [Vec3::new(c[0], c[1], c[2]), Vec3::new(2.0 * c[0] * c[0] - 1.0, 2.0 * c[1] * c[1] - 1.0, 2.0 * c[2] * c[2] - 1.0)]
}

impl ThinFilm {
    /// `(1 − w)·base + w·F_film` at incidence cosine `cos` over a base of normal-incidence
    /// reflectance `f0` (per channel), `base` the base's own Fresnel factor there.
    #[inline]
    pub fn blend(&self, base: Vec3, cos: f64, f0: Vec3) -> Vec3 {
        let w = f64::from(self.weight);
        if w <= 0.0 {
            return base;
        }
        base * (1.0 - w) + self.reflectance(cos, f0) * w
    }

    /// The Fresnel factor of the film over a base of normal-incidence reflectance `f0`, at
    /// incidence cosine `cos` (the module's formula); 1 where light cannot enter the film.
    pub fn reflectance(&self, cos: f64, f0: Vec3) -> Vec3 {
        let cos1 = cos.abs().min(1.0);
        let outside = f64::from(self.outside);
        let thickness = f64::from(self.thickness).max(0.0);
        // A film thinning to nothing takes the outside's index (no interface left).
        let eta2 = outside + (f64::from(self.ior) - outside) * smoothstep(0.0, 30.0, thickness);
        let sin2 = (outside / eta2).powi(2) * (1.0 - cos1 * cos1);
        if sin2 >= 1.0 {
            return Vec3::ONE;
        }
        let cos2 = (1.0 - sin2).sqrt();
        let r12 = schlick(normal_reflectance(eta2, outside), cos1);
        let t121 = 1.0 - r12;
        // The phases φ = φ₂₁ + φ₂₃ (π where light meets a lower index): odd multiples of π flip.
        let phi21_flips = eta2 >= outside;
        let f0 = [f0.x, f0.y, f0.z].map(|f| f.clamp(0.0, 0.9999));
        let base_ior = f0.map(|f| (1.0 + f.sqrt()) / (1.0 - f.sqrt()));
        let r23 = base_ior.map(|n| schlick(normal_reflectance(n, eta2), cos2));
        let flip = base_ior.map(|n| phi21_flips != (n < eta2));
        let opd = 2.0 * eta2 * thickness * cos2;
        let r123 = r23.map(|r| (r12 * r).clamp(1e-5, 0.9999));
        let rs: [f64; 3] = std::array::from_fn(|i| t121 * t121 * r23[i] / (1.0 - r123[i]));
        let mut total = Vec3::new(r12 + rs[0], r12 + rs[1], r12 + rs[2]);
        let mut cm = Vec3::new(rs[0] - t121, rs[1] - t121, rs[2] - t121);
        let r123 = Vec3::new(r123[0].sqrt(), r123[1].sqrt(), r123[2].sqrt());
        let terms = match self.wavelengths {
            None => sensitivities(opd, flip),
            Some(l) => phases_at(opd, flip, l),
        };
        for s in terms {
            cm *= r123;
            total += cm * s * 2.0;
        }
        total.max(Vec3::ZERO)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn film(thickness: f32, ior: f32) -> ThinFilm {
        ThinFilm { weight: 1.0, ior, thickness, outside: 1.0, wavelengths: None }
    }

    /// A film thinning to nothing takes the outside's index, whatever its own; at normal
    /// incidence such a film leaves the base's reflectance (up to the compound terms' clamp).
    #[test]
    fn a_vanishing_film_leaves_the_base() {
        let f0 = Vec3::new(0.04, 0.5, 0.9);
        for cos in [1.0, 0.7, 0.3, 0.05] {
            assert_eq!(film(0.0, 1.5).reflectance(cos, f0), film(0.0, 1.0).reflectance(cos, f0));
        }
        let f = film(0.0, 1.5).reflectance(1.0, f0);
        assert!((f - f0).abs().max_element() < 0.01, "{f} against {f0}");
    }

    /// The sensitivity at zero path difference and phase is the XYZ white `(1, 1, 1)` within the
    /// fits' normalisation, in sRGB.
    #[test]
    fn the_sensitivity_at_zero_difference_is_white_in_xyz() {
        let s = sensitivities(0.0, [false; 3])[0];
        let white = Vec3::new(
            3.2404542 - 1.5371385 - 0.4985314,
            -0.969266 + 1.8760108 + 0.041556,
            0.0556434 - 0.2040259 + 1.0572252,
        );
        assert!((s - white).abs().max_element() < 2e-3, "{s} against {white}");
    }

    /// Interference colours: a soap-like film (η 1.33, 300 nm) over glass tints the reflection,
    /// and the tint changes with the thickness and angle; the factor stays within [0, 1] for
    /// the films glTF allows.
    #[test]
    fn films_colour_the_reflection_and_stay_bounded() {
        let f0 = Vec3::splat(0.04);
        let a = film(300.0, 1.33).reflectance(1.0, f0);
        let b = film(500.0, 1.33).reflectance(1.0, f0);
        let spread = |c: Vec3| c.max_element() - c.min_element();
        assert!(spread(a) > 0.01 && spread(b) > 0.01, "{a} {b}");
        assert!((a - b).abs().max_element() > 0.01, "{a} {b}");
        for thickness in (0..=1200).step_by(37) {
            for ior in [1.0, 1.2, 1.5, 2.0, 3.0] {
                for cos in [1.0, 0.8, 0.5, 0.2, 0.01] {
                    for f0 in [0.0, 0.04, 0.5, 0.95, 1.0] {
                        let f = film(thickness as f32, ior).reflectance(cos, Vec3::splat(f0));
                        assert!(f.is_finite() && f.min_element() >= 0.0 && f.max_element() < 1.6, "{f}");
                    }
                }
            }
        }
    }

    /// Rendering spectrally, each wavelength sees its own phase: at normal incidence a quarter-
    /// wave film (η₂ between the outside and the base) cancels the reflection at its wavelength
    /// (anti-reflection coating) and not at another.
    #[test]
    fn a_quarter_wave_film_cancels_its_wavelength() {
        // MgF₂-like 1.38 on glass of index 1.9: η₂² ≈ 1.9, R₁₂ ≈ R₂₃.
        let (eta2, base): (f64, f64) = (1.38, 1.9);
        let lambda = 550.0;
        let thickness = lambda / (4.0 * eta2);
        let f0 = normal_reflectance(base, 1.0);
        let at = |l: f32| {
            let f = ThinFilm {
                weight: 1.0,
                ior: eta2 as f32,
                thickness: thickness as f32,
                outside: 1.0,
                wavelengths: Some([l; 3]),
            };
            f.reflectance(1.0, Vec3::splat(f0)).x
        };
        assert!(at(550.0) < 0.25 * f0, "{} against the bare {f0}", at(550.0));
        assert!(at(400.0) > at(550.0) + 0.005, "{} {}", at(400.0), at(550.0));
    }

    /// The weight blends the film in linearly; none keeps the base exactly.
    #[test]
    fn the_weight_blends_linearly() {
        let base = Vec3::new(0.2, 0.3, 0.4);
        let f0 = Vec3::splat(0.04);
        let mut f = film(400.0, 1.3);
        f.weight = 0.0;
        assert_eq!(f.blend(base, 0.6, f0), base);
        f.weight = 0.5;
        let full = film(400.0, 1.3).reflectance(0.6, f0);
        assert!((f.blend(base, 0.6, f0) - (base + full) * 0.5).abs().max_element() < 1e-12);
    }
}
