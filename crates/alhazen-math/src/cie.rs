//! Sampled spectra as colours (course, §"Colour space coordinates": a colour is the spectrum
//! weighed by the CIE 1931 matching functions, then taken to the display's primaries).
//!
//! * [`cie_xyz`]: the CIE 1931 2° matching functions (the multi-lobe fit of Wyman, Sloan and
//!   Shirley 2013, within a few per cent of the tables);
//! * [`d65`]: CIE standard illuminant D65 (its 5 nm table to 780 nm, 10 nm beyond);
//! * [`spectrum_to_linear_srgb`]: a spectrum given at some wavelengths as linear sRGB — a
//!   reflectance seen under D65 (white stays white), or an emitter's radiance as it is (a flat
//!   spectrum is a slightly purple sRGB, D65 being sRGB's white). Mitsuba's RGB modes take
//!   the spectra of their scene files so.

use crate::Vec3;

/// Shortest wavelength weighed, nm.
pub const LAMBDA_MIN: f64 = 360.0;
/// Longest wavelength weighed, nm.
pub const LAMBDA_MAX: f64 = 830.0;

fn lobe(lambda: f64, mu: f64, sigma_lo: f64, sigma_hi: f64) -> f64 {
    let t = (lambda - mu) / if lambda < mu { sigma_lo } else { sigma_hi };
    (-0.5 * t * t).exp()
}

/// The CIE 1931 2° colour matching functions `(x̄, ȳ, z̄)` at `lambda` nm (multi-lobe fit).
pub fn cie_xyz(lambda: f64) -> Vec3 {
    let x = 1.056 * lobe(lambda, 599.8, 37.9, 31.0) + 0.362 * lobe(lambda, 442.0, 16.0, 26.7)
        - 0.065 * lobe(lambda, 501.1, 20.4, 26.2);
    let y = 0.821 * lobe(lambda, 568.8, 46.9, 40.5) + 0.286 * lobe(lambda, 530.9, 16.3, 31.1);
    let z = 1.217 * lobe(lambda, 437.0, 11.8, 36.0) + 0.681 * lobe(lambda, 459.0, 26.0, 13.8);
    Vec3::new(x, y, z)
}

/// D65's relative power from 360 to 780 nm in 5 nm steps (100 at 560 nm).
const D65: [f64; 85] = [
    46.6383, 49.3637, 52.0891, 51.0323, 49.9755, 52.3118, 54.6482, 68.7015, 82.7549, 87.1204, 91.486, 92.4589, 93.4318,
    90.057, 86.6823, 95.7736, 104.865, 110.936, 117.008, 117.41, 117.812, 116.336, 114.861, 115.392, 115.923, 112.367,
    108.811, 109.082, 109.354, 108.578, 107.802, 106.296, 104.79, 106.239, 107.689, 106.047, 104.405, 104.225, 104.046,
    102.023, 100.0, 98.1671, 96.3342, 96.0611, 95.788, 92.2368, 88.6856, 89.3459, 90.0062, 89.8026, 89.5991, 88.6489,
    87.6987, 85.4936, 83.2886, 83.4939, 83.6992, 81.863, 80.0268, 80.1207, 80.2146, 81.2462, 82.2778, 80.281, 78.2842,
    74.0027, 69.7213, 70.6652, 71.6091, 72.979, 74.349, 67.9765, 61.604, 65.7448, 69.8856, 72.4863, 75.087, 69.3398,
    63.5927, 55.0054, 46.4182, 56.6118, 66.8054, 65.0941, 63.3828,
];
/// D65 from 780 to 830 nm in 10 nm steps.
const D65_TAIL: [f64; 6] = [63.3828, 64.304, 59.4519, 51.959, 57.4406, 60.3125];

/// CIE illuminant D65's relative spectral power at `lambda` nm (100 at 560 nm), linear between
/// its table's entries; 0 outside 360–830 nm.
pub fn d65(lambda: f64) -> f64 {
    let (table, start, step): (&[f64], f64, f64) =
        if lambda < 780.0 { (&D65, LAMBDA_MIN, 5.0) } else { (&D65_TAIL, 780.0, 10.0) };
    if !(LAMBDA_MIN..=LAMBDA_MAX).contains(&lambda) {
        return 0.0;
    }
    let x = (lambda - start) / step;
    let i = (x as usize).min(table.len() - 2);
    let t = x - i as f64;
    table[i] * (1.0 - t) + table[i + 1] * t
}

/// Steps of the integrals over 360–830 nm.
const STEPS: usize = 1000;

/// `∫ w(λ)·(x̄, ȳ, z̄)(λ) dλ` over 360–830 nm where `w` is given, by the rectangle rule.
fn weighed(w: impl Fn(f64) -> Option<f64>) -> Vec3 {
    let dl = (LAMBDA_MAX - LAMBDA_MIN) / STEPS as f64;
    (0..STEPS).fold(Vec3::ZERO, |sum, i| {
        let lambda = LAMBDA_MIN + (i as f64 + 0.5) * dl;
        w(lambda).map_or(sum, |v| sum + cie_xyz(lambda) * (v * dl))
    })
}

/// The linear sRGB colour of the spectrum of `values` at increasing `wavelengths` (nm; linear
/// between them, nothing outside them). An `emitted` spectrum is radiance: the flat spectrum
/// of value 1 has luminance 1. Otherwise it is a reflectance seen under D65: the flat spectrum
/// of value 1 is white (1, 1, 1). Negative components are clamped to 0, and a reflectance's
/// to at most 1 (`bounded`). Fewer than two wavelengths (or a value short) are black.
pub fn spectrum_to_linear_srgb(wavelengths: &[f64], values: &[f64], emitted: bool, bounded: bool) -> Vec3 {
    if wavelengths.len() < 2 || values.len() != wavelengths.len() {
        return Vec3::ZERO;
    }
    let at = |lambda: f64| {
        let k = wavelengths.partition_point(|&w| w <= lambda);
        if k == 0 || lambda > *wavelengths.last()? {
            return None;
        }
        let k = k.min(wavelengths.len() - 1).max(1);
        let (w0, w1, v0, v1) = (wavelengths[k - 1], wavelengths[k], values[k - 1], values[k]);
        let v = if w1 > w0 { v0 + (v1 - v0) * (lambda - w0) / (w1 - w0) } else { v0 };
        Some(if emitted { v } else { v * d65(lambda) })
    };
    let xyz = weighed(at) / white_y(emitted);
    let rgb = crate::color::xyz_to_linear_srgb() * xyz;
    let rgb = rgb.max(Vec3::ZERO);
    if bounded { rgb.min(Vec3::ONE) } else { rgb }
}

/// The `Y` of the flat spectrum of value 1 (under D65 unless `emitted`), which the colours
/// are divided by.
fn white_y(emitted: bool) -> f64 {
    weighed(|lambda| Some(if emitted { 1.0 } else { d65(lambda) })).y
}

/// The linear sRGB of the flat spectrum of value 1 as radiance (luminance 1).
pub fn flat_emission_srgb() -> Vec3 {
    crate::color::xyz_to_linear_srgb() * (weighed(|_| Some(1.0)) / white_y(true))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_flat_reflectance_is_white_and_a_flat_emission_purple_of_luminance_one() {
        let white = spectrum_to_linear_srgb(&[300.0, 900.0], &[1.0, 1.0], false, true);
        assert!((white - Vec3::ONE).abs().max_element() < 0.02, "{white}");
        let e = spectrum_to_linear_srgb(&[300.0, 900.0], &[1.0, 1.0], true, false);
        assert!((e - flat_emission_srgb()).abs().max_element() < 1e-12);
        assert!((crate::color::luminance(e) - 1.0).abs() < 0.01 && e.x > 1.1 && e.z < 0.95, "{e}");
    }

    #[test]
    fn narrow_bands_have_their_hue_and_outside_the_table_nothing() {
        let band = |lo: f64| {
            spectrum_to_linear_srgb(&[lo, lo + 1.0, lo + 49.0, lo + 50.0], &[0.0, 1.0, 1.0, 0.0], false, false)
        };
        let (red, green, blue) = (band(600.0), band(510.0), band(430.0));
        assert!(
            red.x > red.y && red.x > red.z && green.y > green.x && green.y > green.z && blue.z > blue.y,
            "{red} {green} {blue}"
        );
        assert_eq!(spectrum_to_linear_srgb(&[850.0, 900.0], &[5.0, 5.0], true, false), Vec3::ZERO);
        assert_eq!(spectrum_to_linear_srgb(&[550.0], &[5.0], true, false), Vec3::ZERO);
        assert_eq!(spectrum_to_linear_srgb(&[450.0, 550.0], &[5.0], true, false), Vec3::ZERO);
        assert_eq!(d65(560.0), 100.0);
        assert!((d65(562.5) - 99.08355).abs() < 1e-9 && d65(100.0) == 0.0 && d65(830.0) == 60.3125);
    }
}
