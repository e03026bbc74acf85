//! Colour space coordinates (course, §"Colour space coordinates"): linear radiance inside,
//! sRGB only at the output.

use crate::{Mat3, Vec3};

/// The course's sRGB transfer function `R(x)`: `12.92 x` for `x < 0.0031308`, otherwise
/// `1.055 x^{1/2.4} − 0.055`, after clamping to `[0, 1]` (the course's second step). NaN → 0.
pub fn srgb_encode(x: f64) -> f64 {
    let x = if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) };
    if x < 0.0031308 { 12.92 * x } else { 1.055 * x.powf(1.0 / 2.4) - 0.055 }
}

/// The inverse of [`srgb_encode`] on `[0, 1]`.
pub fn srgb_to_linear(x: f64) -> f64 {
    if x <= 0.04045 { x / 12.92 } else { ((x + 0.055) / 1.055).powf(2.4) }
}

/// The course's CIE XYZ → linear sRGB matrix.
pub fn xyz_to_linear_srgb() -> Mat3 {
    Mat3::from_cols(
        Vec3::new(3.2406, -0.9689, 0.0557),
        Vec3::new(-1.5372, 1.8758, -0.2040),
        Vec3::new(-0.4986, 0.0415, 1.0570),
    )
}

/// Relative luminance (Rec. 709 / sRGB primaries) of linear RGB.
pub fn luminance(c: Vec3) -> f64 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transfer_function_matches_course_and_round_trips() {
        assert_eq!(srgb_encode(0.002), 12.92 * 0.002);
        assert!((srgb_encode(0.5) - (1.055 * 0.5f64.powf(1.0 / 2.4) - 0.055)).abs() < 1e-15);
        assert!((srgb_encode(2.0) - 1.0).abs() < 1e-15);
        assert_eq!(srgb_encode(f64::NAN), 0.0);
        for i in 0..=20 {
            let x = i as f64 / 20.0;
            assert!((srgb_encode(srgb_to_linear(x)) - x).abs() < 1e-12);
        }
    }

    #[test]
    fn d65_white_maps_to_rgb_one() {
        let white = xyz_to_linear_srgb() * Vec3::new(0.9505, 1.0, 1.089);
        assert!((white - Vec3::ONE).abs().max_element() < 2e-3, "{white}");
    }
}
