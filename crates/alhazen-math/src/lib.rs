//! `alhazen-math`: the numeric foundation of alhazen.
//!
//! All geometry is `f64` (exactness matters more than raw width here: the mirror solver needs
//! 1e-12 rad, and a double-precision ray tracer needs almost no self-intersection epsilon).
//! Coordinates are right-handed, angles are radians, `y` is up by convention of the scene files.
//!
//! * [`ray`] — rays and their parametric points;
//! * [`bounds`] — axis-aligned boxes and the slab test;
//! * [`transform`] — affine maps with cached inverse; normals go through the inverse
//!   transpose (course, §"Transformations of the normal vector");
//! * [`viewing`] — the lecture's and course's viewing pipeline: the look-at frame `(u, v, w)`,
//!   orthographic and perspective frustum matrices `(l, r, b, t, n, f)` and their inverses,
//!   window→viewport, homogenisation, stereo frusta;
//! * [`color`] — the course's sRGB transfer function and the XYZ→sRGB matrix;
//! * [`cie`] — the CIE 1931 matching functions, illuminant D65, sampled spectra as sRGB;
//! * [`poly`] — numerically careful real roots of low-degree polynomials;
//! * [`exact_sum`] — order-independent exact sums of doubles (the film's pixel sums);
//! * [`elementary`] — `exp` and `ln` that vectorise (the material kernels' Beckmann facets).
//!
//! ```
//! use alhazen_math::{Ray, Vec3, Transform};
//! let to_world = Transform::translate(Vec3::new(0.0, 1.0, 0.0)) * Transform::scale(Vec3::splat(2.0));
//! let r = Ray::new(Vec3::ZERO, Vec3::X);
//! assert_eq!(to_world.point(r.at(1.0)), Vec3::new(2.0, 1.0, 0.0));
//! ```

pub mod bounds;
pub mod cie;
pub mod color;
pub mod elementary;
pub mod exact_sum;
pub mod poly;
pub mod ray;
pub mod transform;
pub mod viewing;

pub use bounds::Bounds3;
pub use glam::{DMat3 as Mat3, DMat4 as Mat4, DQuat as Quat, DVec2 as Vec2, DVec3 as Vec3, DVec4 as Vec4};
pub use ray::Ray;
pub use transform::{Transform, TransformError};

/// `(sin 2πt, cos 2πt)` for a fraction of a turn `t` (sampling's azimuths), within 1e-15 of
/// `(2πt).sin_cos()`: `t` is reduced to the nearest quarter turn exactly, then Taylor
/// polynomials of degree 17 and 16 on `|θ| ≤ π/4` (truncation below 1e-16). A shorter chain
/// of dependent operations than `sin_cos`, which must reduce arbitrary arguments.
#[inline]
pub fn sin_cos_turns(t: f64) -> (f64, f64) {
    let quarters = 4.0 * t;
    // Round to nearest by the 1.5·2⁵² trick (exact for |t| < 2⁴⁹; `round` is a libm call on
    // baseline x86-64).
    const MAGIC: f64 = 6_755_399_441_055_744.0;
    let shifted = quarters + MAGIC;
    let q = shifted - MAGIC;
    let x = (quarters - q) * std::f64::consts::FRAC_PI_2;
    let x2 = x * x;
    // Taylor coefficients in x², evaluated by Estrin's scheme: the next ray waits on this, so
    // a short dependency chain matters more than the operation count.
    const SIN: [f64; 9] = taylor(1);
    const COS: [f64; 9] = taylor(0);
    let (x4, x8) = (x2 * x2, x2 * x2 * (x2 * x2));
    let estrin = |k: &[f64; 9]| {
        let (a, b) = (k[0] + k[1] * x2 + x4 * (k[2] + k[3] * x2), k[4] + k[5] * x2 + x4 * (k[6] + k[7] * x2));
        a + x4 * x4 * b + x8 * x8 * k[8]
    };
    let (s, c) = (estrin(&SIN), estrin(&COS));
    let (sin, cos) = (x * s, c);
    // The quadrant without branches (its value is random in sampling): odd quadrants swap,
    // and bit 1 of q (of q + 1) flips the sign of the sine (cosine). `shifted`'s mantissa
    // counts in units of 1, so its low bits are q's (two's complement below zero): read from
    // its bits, which vectorise, where converting q to an integer does not under AVX2.
    let q = shifted.to_bits();
    let (sin, cos) = if q & 1 == 0 { (sin, cos) } else { (cos, sin) };
    let flip = |v: f64, bit: u64| f64::from_bits(v.to_bits() ^ ((bit & 2) << 62));
    (flip(sin, q), flip(cos, q.wrapping_add(1)))
}

/// `(−1)ᵏ / (2k + odd)!` for `k = 0..9`: the Taylor coefficients of cos (`odd = 0`) or of
/// sin / x (`odd = 1`) in powers of `x²`.
const fn taylor(odd: usize) -> [f64; 9] {
    let mut r = [0.0; 9];
    let (mut k, mut term) = (0, 1.0);
    while k < 9 {
        r[k] = term;
        let n = (2 * k + odd + 1) as f64;
        term = -term / (n * (n + 1.0));
        k += 1;
    }
    r
}

/// Builds an orthonormal basis `(t, b)` completing the unit vector `n` (Duff et al. 2017).
pub fn orthonormal_basis(n: Vec3) -> (Vec3, Vec3) {
    let sign = 1f64.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x), Vec3::new(b, sign + n.y * n.y * a, -n.y))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn sin_cos_turns_matches_the_library(t in 0.0..1.0f64) {
            let (s, c) = sin_cos_turns(t);
            let (s0, c0) = (2.0 * std::f64::consts::PI * t).sin_cos();
            // The library's argument 2πt is itself rounded (≈ 4e-16 at a full turn).
            prop_assert!((s - s0).abs() <= 1e-15 && (c - c0).abs() <= 1e-15, "{t}: {s} {c} vs {s0} {c0}");
            prop_assert!((s * s + c * c - 1.0).abs() <= 1e-15);
        }

        /// Whole turns do not change the result, nor do negative ones: the quadrant read from
        /// the shifted bits is right on both sides of zero and far from it.
        #[test]
        fn sin_cos_turns_repeats_every_turn(t in 0.0..1.0f64, turns in -100_000i32..100_000) {
            let (s, c) = sin_cos_turns(t);
            let (s1, c1) = sin_cos_turns(t + turns as f64);
            // `t + turns` is rounded to the turns' magnitude: within it, the result agrees.
            let tolerance = 1e-15 + 8.0 * f64::EPSILON * turns.unsigned_abs() as f64;
            prop_assert!((s - s1).abs() <= tolerance && (c - c1).abs() <= tolerance, "{t} + {turns}: {s1} {c1} vs {s} {c}");
        }
    }

    #[test]
    fn sin_cos_turns_is_exact_at_quarter_turns() {
        assert_eq!(sin_cos_turns(0.0), (0.0, 1.0));
        assert_eq!(sin_cos_turns(0.25), (1.0, -0.0));
        assert_eq!(sin_cos_turns(0.5), (-0.0, -1.0));
        assert_eq!(sin_cos_turns(0.75), (-1.0, 0.0));
        let (s, c) = sin_cos_turns(0.125);
        assert!((s - std::f64::consts::FRAC_1_SQRT_2).abs() < 2e-16 && (c - s).abs() < 2e-16);
        let (s, c) = sin_cos_turns(-1.0 / 3.0);
        assert!((s + 0.75f64.sqrt()).abs() < 2e-16 && (c + 0.5).abs() < 2e-16);
        let (s, c) = sin_cos_turns(1000.1);
        assert!((s - (0.2 * std::f64::consts::PI).sin()).abs() < 1e-12 && c > 0.8);
    }
}
