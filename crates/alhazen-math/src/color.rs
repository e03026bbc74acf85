//! Colour space coordinates (course, §"Colour space coordinates"): linear radiance inside,
//! sRGB only at the output; the HSV and HSL models for specifying colours; colours outside the
//! display's gamut brought into it by desaturation, not clamping (the course: clamping is
//! "usually a bad idea"); tone mapping of high dynamic range radiance for display.

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

/// The RGB of hue `h` (degrees, any finite value: taken modulo 360), saturation `s` and
/// value `v` (both in `[0, 1]`): Smith's hexcone model (1978), as the course presents it.
pub fn hsv_to_rgb(h: f64, s: f64, v: f64) -> Vec3 {
    let c = v * s;
    v - c + hue_chroma(h, c)
}

/// The RGB of hue `h` (degrees), saturation `s` and lightness `l` (both in `[0, 1]`): the
/// double hexcone model.
pub fn hsl_to_rgb(h: f64, s: f64, l: f64) -> Vec3 {
    let c = (1.0 - (2.0 * l - 1.0).abs()) * s;
    l - c / 2.0 + hue_chroma(h, c)
}

/// The fully saturated colour of hue `h` with chroma `c`, its smallest component zero.
fn hue_chroma(h: f64, c: f64) -> Vec3 {
    let h6 = h.rem_euclid(360.0) / 60.0;
    let x = c * (1.0 - (h6 % 2.0 - 1.0).abs());
    match h6 as u32 {
        0 => Vec3::new(c, x, 0.0),
        1 => Vec3::new(x, c, 0.0),
        2 => Vec3::new(0.0, c, x),
        3 => Vec3::new(0.0, x, c),
        4 => Vec3::new(x, 0.0, c),
        _ => Vec3::new(c, 0.0, x),
    }
}

/// Hue (degrees in `[0, 360)`), saturation and value of `rgb` (components in `[0, 1]`).
pub fn rgb_to_hsv(rgb: Vec3) -> (f64, f64, f64) {
    let (max, min) = (rgb.max_element(), rgb.min_element());
    let c = max - min;
    let h = if c == 0.0 {
        0.0
    } else if max == rgb.x {
        60.0 * ((rgb.y - rgb.z) / c).rem_euclid(6.0)
    } else if max == rgb.y {
        60.0 * ((rgb.z - rgb.x) / c + 2.0)
    } else {
        60.0 * ((rgb.x - rgb.y) / c + 4.0)
    };
    (h, if max == 0.0 { 0.0 } else { c / max }, max)
}

/// `c` moved towards the grey of its own luminance just far enough that no component is
/// negative and, with `ceiling`, none exceeds it: hue and luminance are kept where clamping
/// would shift both. A negative luminance gives black; one at or above the ceiling, white.
/// NaN components count as zero.
pub fn desaturate_into_gamut(c: Vec3, ceiling: Option<f64>) -> Vec3 {
    let c = Vec3::from_array(c.to_array().map(|x| if x.is_nan() { 0.0 } else { x }));
    let y = luminance(c);
    if y <= 0.0 {
        return Vec3::ZERO;
    }
    if let Some(top) = ceiling
        && y >= top
    {
        return Vec3::splat(top);
    }
    let mut t: f64 = 1.0;
    if c.min_element() < 0.0 {
        t = t.min(y / (y - c.min_element()));
    }
    if let Some(top) = ceiling
        && c.max_element() > top
    {
        t = t.min((top - y) / (c.max_element() - y));
    }
    if t >= 1.0 {
        return c;
    }
    let out = Vec3::splat(y) + (c - Vec3::splat(y)) * t;
    // Rounding may leave a component a hair outside.
    let out = out.max(Vec3::ZERO);
    ceiling.map_or(out, |top| out.min(Vec3::splat(top)))
}

/// How high dynamic range radiance is mapped to the display's `[0, 1]`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Tonemap {
    /// Unchanged (what exceeds the display is desaturated into it).
    #[default]
    None,
    /// Reinhard et al. (2002), the global operator `L / (1 + L)` on luminance, hue kept.
    Reinhard,
    /// Hable's filmic curve (2010, "Uncharted 2"), per channel, white point 11.2.
    Filmic,
}

impl Tonemap {
    /// `c` mapped for display.
    pub fn apply(self, c: Vec3) -> Vec3 {
        match self {
            Tonemap::None => c,
            Tonemap::Reinhard => {
                let y = luminance(c);
                if y > 0.0 { c * (1.0 / (1.0 + y)) } else { c }
            }
            Tonemap::Filmic => {
                let white = hable(HABLE_WHITE);
                Vec3::from_array(c.to_array().map(|x| hable(x.max(0.0)) / white))
            }
        }
    }
}

/// Hable's white point: radiance mapped to 1.
const HABLE_WHITE: f64 = 11.2;

/// Hable's curve with his published constants (shoulder 0.15, linear 0.50, angle 0.10, toe
/// 0.20, toe numerator 0.02, toe denominator 0.30).
fn hable(x: f64) -> f64 {
    let (a, b, c, d, e, f) = (0.15, 0.50, 0.10, 0.20, 0.02, 0.30);
    (x * (a * x + c * b) + d * e) / (x * (a * x + b) + d * f) - e / f
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

    /// The published examples of the HSV/HSL models (the primaries, greys, and the
    /// olive `#A0A424` = (0.628, 0.643, 0.142): H 61.8°, HSV (0.779, 0.643), HSL (0.638, 0.393)).
    #[test]
    fn hsv_and_hsl_give_the_published_colours() {
        let close = |a: Vec3, b: Vec3| (a - b).abs().max_element() < 2e-3;
        assert_eq!(hsv_to_rgb(0.0, 1.0, 1.0), Vec3::new(1.0, 0.0, 0.0));
        assert_eq!(hsv_to_rgb(120.0, 1.0, 1.0), Vec3::new(0.0, 1.0, 0.0));
        assert_eq!(hsv_to_rgb(240.0, 1.0, 0.5), Vec3::new(0.0, 0.0, 0.5));
        assert_eq!(hsv_to_rgb(-120.0, 1.0, 1.0), Vec3::new(0.0, 0.0, 1.0));
        assert_eq!(hsv_to_rgb(77.0, 0.0, 0.25), Vec3::splat(0.25));
        assert_eq!(hsl_to_rgb(0.0, 1.0, 0.5), Vec3::new(1.0, 0.0, 0.0));
        assert_eq!(hsl_to_rgb(60.0, 1.0, 0.25), Vec3::new(0.5, 0.5, 0.0));
        assert_eq!(hsl_to_rgb(200.0, 0.7, 1.0), Vec3::ONE);
        let olive = Vec3::new(0.628, 0.643, 0.142);
        assert!(close(hsv_to_rgb(61.8, 0.779, 0.643), olive));
        assert!(close(hsl_to_rgb(61.8, 0.638, 0.393), olive));
        let (h, s, v) = rgb_to_hsv(olive);
        assert!((h - 61.8).abs() < 0.1 && (s - 0.779).abs() < 1e-3 && (v - 0.643).abs() < 1e-3);
        for i in 0..360 {
            let c = hsv_to_rgb(i as f64, 0.6, 0.8);
            let (h, s, v) = rgb_to_hsv(c);
            assert!((h - i as f64).abs() < 1e-9 && (s - 0.6).abs() < 1e-12 && (v - 0.8).abs() < 1e-12, "{i}");
        }
    }

    /// Desaturation keeps luminance and hue direction, and lands in the gamut.
    #[test]
    fn out_of_gamut_colours_are_desaturated_not_clamped() {
        let red = Vec3::new(2.0, 0.1, 0.1);
        let shown = desaturate_into_gamut(red, Some(1.0));
        assert!((luminance(shown) - luminance(red)).abs() < 1e-12, "{shown}");
        assert!(shown.max_element() <= 1.0 && shown.min_element() >= 0.0);
        assert!(shown.x == 1.0 && shown.y > 0.1 && (shown.y - shown.z).abs() < 1e-12);
        let spectral = Vec3::new(-0.05, 0.3, 0.6);
        let lifted = desaturate_into_gamut(spectral, None);
        assert!((luminance(lifted) - luminance(spectral)).abs() < 1e-12 && lifted.x.abs() < 1e-12);
        assert!(lifted.z > lifted.y && lifted.y > 0.0);
        assert_eq!(desaturate_into_gamut(Vec3::new(0.2, 0.5, 0.9), Some(1.0)), Vec3::new(0.2, 0.5, 0.9));
        assert_eq!(desaturate_into_gamut(Vec3::new(5.0, 4.0, 3.0), Some(1.0)), Vec3::ONE);
        assert_eq!(desaturate_into_gamut(Vec3::new(-1.0, 0.1, 0.0), None), Vec3::ZERO);
        assert_eq!(desaturate_into_gamut(Vec3::new(f64::NAN, 0.5, 0.5), None), Vec3::new(0.0, 0.5, 0.5));
    }

    /// Reinhard maps luminance 1 to 1/2 and keeps hue; Hable's curve maps 0 to 0 and its white
    /// point to 1, and is increasing; none changes `Tonemap::None`'s colours.
    #[test]
    fn tone_mapping_curves_have_their_published_values() {
        let grey = Tonemap::Reinhard.apply(Vec3::ONE);
        assert!((grey - Vec3::splat(0.5)).abs().max_element() < 1e-15);
        let c = Tonemap::Reinhard.apply(Vec3::new(3.0, 1.5, 0.3));
        assert!((c.x / c.y - 2.0).abs() < 1e-12 && (c.y / c.z - 5.0).abs() < 1e-12);
        assert_eq!(Tonemap::Filmic.apply(Vec3::ZERO), Vec3::ZERO);
        assert!((Tonemap::Filmic.apply(Vec3::splat(HABLE_WHITE)) - Vec3::ONE).abs().max_element() < 1e-15);
        // Hable's curve at 1: (0.15 + 0.05 + 0.004) / (0.15 + 0.5 + 0.06) − 0.02/0.3, over f(11.2).
        let at_one = (0.204 / 0.71 - 0.02 / 0.3) / hable(11.2);
        assert!((Tonemap::Filmic.apply(Vec3::ONE).x - at_one).abs() < 1e-15);
        let mut last = -1.0;
        for i in 0..100 {
            let y = Tonemap::Filmic.apply(Vec3::splat(i as f64 * 0.2)).x;
            assert!(y > last);
            last = y;
        }
        assert_eq!(Tonemap::None.apply(Vec3::new(7.0, 0.5, 0.0)), Vec3::new(7.0, 0.5, 0.0));
    }
}
