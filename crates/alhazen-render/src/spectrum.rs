//! Spectral rendering for dispersion (lecture, "Refraction and wavelength": `η_λ` varies with λ).
//!
//! * Hero-wavelength sampling (Wilkie et al. 2014): each path carries three wavelengths
//!   `λ₀ + k·Λ/3` (mod Λ) over the visible range of width Λ; a dispersive refraction keeps only
//!   the hero `λ₀`, scaled by 3, so the estimate stays unbiased.
//! * RGB → spectrum: `s(λ) = r·b_r(λ) + g'·b_g(λ) + b'·b_b(λ)` over three smooth bands that sum to 1
//!   everywhere, with coefficients solved so the spectrum's colour is the given RGB. White is the
//!   flat spectrum (energy conserving for albedos); out-of-gamut values are clamped at 0.
//! * Spectrum → colour: the CIE 1931 matching functions (Wyman, Sloan & Shirley 2013 analytic
//!   fit) → XYZ → linear sRGB with the course's matrix, white-balanced so the equal-energy
//!   spectrum is RGB white (the course: "The computer screen emits light with a specific power").

use alhazen_math::{Mat3, Vec3, color::xyz_to_linear_srgb};
use std::sync::OnceLock;

pub use alhazen_math::cie::{LAMBDA_MAX, LAMBDA_MIN, cie_xyz};

fn smoothstep(x: f64) -> f64 {
    let t = x.clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// The three bands (red, green, blue) at `lambda`; they sum to 1.
fn bands(lambda: f64) -> Vec3 {
    let blue = 1.0 - smoothstep((lambda - 470.0) / 40.0);
    let red = smoothstep((lambda - 570.0) / 40.0);
    Vec3::new(red, 1.0 - red - blue, blue)
}

struct Tables {
    /// Spectrum → balanced linear sRGB per unit of `x̄ȳz̄`-weighted radiance.
    xyz_to_rgb: Mat3,
    /// Band coefficients from RGB.
    rgb_to_bands: Mat3,
}

fn tables() -> &'static Tables {
    static T: OnceLock<Tables> = OnceLock::new();
    T.get_or_init(|| {
        let m = xyz_to_linear_srgb();
        let n = 4700;
        let dl = (LAMBDA_MAX - LAMBDA_MIN) / n as f64;
        let (mut white, mut band_xyz) = (Vec3::ZERO, [Vec3::ZERO; 3]);
        for i in 0..n {
            let l = LAMBDA_MIN + (i as f64 + 0.5) * dl;
            let c = cie_xyz(l) * dl;
            white += c;
            let b = bands(l);
            for k in 0..3 {
                band_xyz[k] += c * b[k];
            }
        }
        // Balance: the flat spectrum maps to (1, 1, 1).
        let rgb_white = m * white;
        let balance = Mat3::from_diagonal(Vec3::ONE / rgb_white);
        let xyz_to_rgb = balance * m;
        let band_rgb = Mat3::from_cols(xyz_to_rgb * band_xyz[0], xyz_to_rgb * band_xyz[1], xyz_to_rgb * band_xyz[2]);
        Tables { xyz_to_rgb, rgb_to_bands: band_rgb.inverse() }
    })
}

/// The wavelengths a path carries: the hero `λ₀` from `u ∈ [0, 1)` and two rotations.
pub fn sample_wavelengths(u: f64) -> [f64; 3] {
    let span = LAMBDA_MAX - LAMBDA_MIN;
    [0.0, 1.0, 2.0].map(|k| LAMBDA_MIN + (u + k / 3.0).fract() * span)
}

/// The value at each of `lambdas` of the spectrum upsampled from linear RGB.
pub fn rgb_to_spectrum(rgb: Vec3, lambdas: &[f64; 3]) -> Vec3 {
    let c = tables().rgb_to_bands * rgb;
    Vec3::from_array(lambdas.map(|l| bands(l).dot(c).max(0.0)))
}

/// The balanced linear sRGB of radiance values `values` at `lambdas` (an unbiased estimate of the
/// colour of the spectrum when the wavelengths are sampled by [`sample_wavelengths`]).
pub fn spectrum_to_rgb(values: Vec3, lambdas: &[f64; 3]) -> Vec3 {
    let span = LAMBDA_MAX - LAMBDA_MIN;
    let xyz: Vec3 = (0..3).map(|k| cie_xyz(lambdas[k]) * values[k]).sum::<Vec3>() * (span / 3.0);
    tables().xyz_to_rgb * xyz
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matching_functions_integrate_like_cie_1931() {
        // CIE 1931 tables: ∫x̄ = 106.865, ∫ȳ = 106.857, ∫z̄ = 106.892 (1 nm sums), peak ȳ(555) ≈ 1.
        let s: Vec3 = (360..=830).map(|l| cie_xyz(l as f64)).sum();
        for (got, want) in [(s.x, 106.865), (s.y, 106.857), (s.z, 106.892)] {
            assert!((got - want).abs() / want < 0.01, "{got} vs {want}");
        }
        assert!((cie_xyz(555.0).y - 1.0).abs() < 0.02);
    }

    #[test]
    fn flat_spectrum_is_white_and_colours_round_trip() {
        let lambdas = sample_wavelengths(0.3);
        assert!((rgb_to_spectrum(Vec3::ONE, &lambdas) - Vec3::ONE).abs().max_element() < 1e-9);
        for rgb in [Vec3::ONE, Vec3::new(0.8, 0.5, 0.3), Vec3::new(0.2, 0.6, 0.4), Vec3::new(0.4, 0.4, 0.7)] {
            // Average many wavelength triples: the colour of the upsampled spectrum.
            let n = 6000;
            let mut sum = Vec3::ZERO;
            for i in 0..n {
                let l = sample_wavelengths((i as f64 + 0.5) / n as f64);
                sum += spectrum_to_rgb(rgb_to_spectrum(rgb, &l), &l);
            }
            let back = sum / n as f64;
            assert!((back - rgb).abs().max_element() < 2e-3, "{rgb} → {back}");
        }
    }
}
