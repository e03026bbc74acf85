//! `exp`, `ln`, `pow`, `atan2` and `acos` without branches or library calls, so that loops calling
//! them vectorise (the path tracer's material kernels evaluate Beckmann's `D = e^{−tan²ϑ/m²}…`
//! and sample it by `tan²ϑ = −m² ln(1 − u)` for eight paths at once, and the environment map is
//! looked up for eight rays at once; the C library's functions are calls the compiler cannot
//! vectorise).
//!
//! They follow the classical scheme (Cody and Waite 1980; Muller, "Elementary Functions",
//! ch. 11): an exact or nearly exact reduction, then a polynomial on a small interval.
//!
//! * `exp(x) = 2^k · e^r`, `k = round(x / ln 2)`, `r = x − k ln 2` with `ln 2` split in two
//!   parts (the first with trailing zero bits, so `k · ln2_hi` is exact), `|r| ≤ ln 2 / 2`;
//!   `e^r` by its Taylor polynomial of degree 13 (truncation below 5·10⁻¹⁸), `2^k` built from
//!   its bits in two halves (results down to the subnormals).
//! * `ln(x) = e ln 2 + ln m`, `x = m · 2^e`, `m ∈ [√½, √2)`; `ln m = 2 atanh s`,
//!   `s = (m − 1)/(m + 1)`, `|s| ≤ 0.1716`, by its series to `s²³` (truncation below 10⁻¹⁸).
//!
//! The polynomials are evaluated by Estrin's scheme (terms paired, pairs paired with the
//! square, …): a few short chains of operations instead of Horner's one long one, which each
//! lane of a material kernel would wait on.
//!
//! * `atan2(y, x)`: `t = min/max` of `|x|, |y|` moved by the addition formula next to the
//!   nearest of `tan(kπ/8)`, `k ∈ {0, 1, 2}` (`|s| ≤ tan(π/16)`), the series of `atan s` to
//!   `s²¹`, then the octant by reflections; `acos x = atan2(√((1 − x)(1 + x)), x)`.
//!
//! Within a few units in the last place of the library's results (property tests); special
//! values as the library's: `exp(−∞) = 0`, `exp(∞) = ∞`, overflow to `∞`, underflow to 0,
//! `ln(0) = −∞`, `ln(∞) = ∞`, `ln` of a negative number or NaN is NaN.

/// `ln 2` in two parts: the first with its low 21 bits zero (`k · LN2_HI` is exact for
/// `|k| < 2²¹`), the second the next 53 bits of `ln 2` (Cody and Waite's split: the sum
/// carries `ln 2` to about 85 bits, where `LN_2` alone has 53).
const LN2_HI: f64 = f64::from_bits(0x3fe6_2e42_fee0_0000);
const LN2_LO: f64 = f64::from_bits(0x3dea_39ef_3579_3c76);

/// `1.5 · 2⁵²`: adding it rounds a number of magnitude below 2⁵¹ to an integer (to nearest,
/// ties to even), which the sum's low bits then hold.
const ROUNDER: f64 = 6_755_399_441_055_744.0;

/// `2^k` for integral `k` in `[−1022, 1023]`, from its bits.
#[inline(always)]
fn pow2(k: i64) -> f64 {
    f64::from_bits(((k + 1023) as u64) << 52)
}

/// `e^x`.
#[inline(always)]
pub fn exp(x: f64) -> f64 {
    // Beyond these the result is ∞ or 0 (and NaN stays NaN through the arithmetic).
    let xc = x.clamp(-746.0, 710.0);
    let t = xc * std::f64::consts::LOG2_E + ROUNDER;
    let k = t - ROUNDER;
    let r = (xc - k * LN2_HI) - k * LN2_LO;
    // e^r − 1 − r = r² Σ rⁿ/(n + 2)!, n in 0..12, by Estrin's scheme (short dependency chains;
    // no fused multiply–adds: the same bits everywhere), added to 1 + r last.
    let a = |n: u32| 1.0 / factorial(n + 2);
    let (r2, r4) = (r * r, r * r * (r * r));
    let pair = |n: u32| a(n) + a(n + 1) * r;
    let quad = |n: u32| pair(n) + pair(n + 2) * r2;
    let p = quad(0) + quad(4) * r4 + quad(8) * (r4 * r4);
    let er = 1.0 + (r + r2 * p);
    // 2^k in two factors, each a normal number, so subnormal results round once at the end.
    let k = (t.to_bits() as i64).wrapping_sub(ROUNDER.to_bits() as i64);
    let half = k >> 1;
    let value = er * pow2(half) * pow2(k - half);
    if x.is_nan() { x } else { value }
}

/// `n!` for the small `n` of [`exp`]'s polynomial (folded to constants).
#[inline(always)]
const fn factorial(n: u32) -> f64 {
    let mut f = 1.0;
    let mut i = 2;
    while i <= n {
        f *= i as f64;
        i += 1;
    }
    f
}

/// The natural logarithm.
#[inline(always)]
pub fn ln(x: f64) -> f64 {
    // Subnormals scaled into the normal range first (by 2⁵⁴, taken back in the exponent).
    let subnormal = x < f64::MIN_POSITIVE;
    let (y, shift) = if subnormal { (x * 18_014_398_509_481_984.0, 54) } else { (x, 0) };
    let bits = y.to_bits();
    // The exponent `e` with `m = y / 2^e ∈ [√½, √2)`: the high word moved so that √½'s
    // (0x3fe6a09e) becomes 1's, then read as an exponent.
    let e = (((bits >> 32) as i64 + (0x3ff0_0000 - 0x3fe6_a09e)) >> 20) - 0x3ff;
    let m = f64::from_bits(bits.wrapping_sub((e as u64) << 52));
    let s = (m - 1.0) / (m + 1.0);
    let s2 = s * s;
    // 2 atanh s = 2s + 2s (s²/3 + s⁴/5 + … + s²²/23): the sum's s²ⁿ⁻²/(2n + 1), n in 1..=11,
    // by Estrin's scheme on s² (short chains), the largest term added last.
    let b = |n: i32| 1.0 / (2 * n + 1) as f64;
    let (z2, z4) = (s2 * s2, s2 * s2 * (s2 * s2));
    let pair = |n: i32| b(n) + b(n + 1) * s2;
    let quad = |n: i32| pair(n) + pair(n + 2) * z2;
    let p = quad(1) + quad(5) * z4 + (b(9) + b(10) * s2 + b(11) * z2) * (z4 * z4);
    let ln_m = 2.0 * s + 2.0 * s * (s2 * p);
    let e = (e - shift) as f64;
    let value = e * LN2_HI + (e * LN2_LO + ln_m);
    let special = if x == f64::INFINITY { x } else { f64::NAN };
    if x == 0.0 {
        f64::NEG_INFINITY
    } else if x > 0.0 && x < f64::INFINITY {
        value
    } else {
        special
    }
}

/// `atan2(y, x)`: the angle of `(x, y)` from the positive `x` axis, in `[−π, π]`.
///
/// With `t = min(|x|, |y|) / max(|x|, |y|) ∈ [0, 1]` and `c` the nearest of `tan(kπ/8)`,
/// `k ∈ {0, 1, 2}`, `atan t = kπ/8 + atan s` with `s = (t − c)/(1 + tc)`, `|s| ≤ tan(π/16)`
/// (formed from `|x|, |y|` with one division), where the series `s − s³/3 + … − s²¹/21` is
/// exact to 2⁻⁵⁵; the octant then by reflections.
#[inline(always)]
pub fn atan2(y: f64, x: f64) -> f64 {
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, FRAC_PI_8, PI};
    let (ax, ay) = (x.abs(), y.abs());
    let (lo, hi) = (ax.min(ay), ax.max(ay));
    // An infinite side: the diagonal or the axis; both zero: the axis. Magnitudes scaled by a
    // power of two (exactly) away from overflow and the subnormals.
    let (lo, hi) = if hi == f64::INFINITY {
        (if lo == f64::INFINITY { 1.0 } else { 0.0 }, 1.0)
    } else if hi == 0.0 {
        (0.0, 1.0)
    } else {
        (lo, hi)
    };
    let scale = if hi > 1e300 {
        0.25
    } else if hi < 1e-280 {
        f64::from_bits((1023 + 600) << 52)
    } else {
        1.0
    };
    let (lo, hi) = (lo * scale, hi * scale);
    // `tan(3π/16)` and `tan(π/16)` part the three intervals; `tan(π/8) = √2 − 1`.
    let (c, base) = if lo > 0.668_178_637_919_298_9 * hi {
        (1.0, FRAC_PI_4)
    } else if lo > 0.198_912_367_379_658 * hi {
        (0.414_213_562_373_095_05, FRAC_PI_8)
    } else {
        (0.0, 0.0)
    };
    let s = (lo - c * hi) / (hi + c * lo);
    let z = s * s;
    // Σ (−1)ⁿ zⁿ⁻¹/(2n + 1) for n in 1..=10, by Estrin's scheme (short chains; no fused
    // multiply–adds: the same bits everywhere).
    let a = |n: i32| if n % 2 == 0 { 1.0 } else { -1.0 } / (2 * n + 1) as f64;
    let (z2, z4) = (z * z, z * z * (z * z));
    let p01 = a(1) + a(2) * z;
    let p23 = a(3) + a(4) * z;
    let p45 = a(5) + a(6) * z;
    let p67 = a(7) + a(8) * z;
    let p89 = a(9) + a(10) * z;
    let p03 = p01 + p23 * z2;
    let p47 = p45 + p67 * z2;
    let p = p03 + (p47 + p89 * z4) * z4;
    let r = base + (s + s * (z * p));
    let r = if ay > ax { FRAC_PI_2 - r } else { r };
    let r = if x.is_sign_negative() { PI - r } else { r };
    let value = r.copysign(y);
    if x.is_nan() || y.is_nan() { f64::NAN } else { value }
}

/// `acos(x)` in `[0, π]`, as [`atan2`]`(√((1 − x)(1 + x)), x)`; NaN outside `[−1, 1]`.
#[inline(always)]
pub fn acos(x: f64) -> f64 {
    atan2(((1.0 - x) * (1.0 + x)).sqrt(), x)
}

/// `x^y` for `x ≥ 0` (Phong's `cos^m`, its sampling's `u^{1/(m+1)}`), as `e^{y ln x}`: the
/// exponent's absolute error `|y ln x|·2⁻⁵³` is the result's relative error (below 10⁻¹³
/// wherever the result is a normal number). `x^0 = 1`, `0^y` is 0 for `y > 0` and `∞` for
/// `y < 0`, as the library's; a negative `x` gives NaN.
#[inline(always)]
pub fn pow(x: f64, y: f64) -> f64 {
    if y == 0.0 { 1.0 } else { exp(y * ln(x)) }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The split is `ln 2`: its parts sum to the library's constant.
    #[test]
    fn ln2_split_sums_to_ln2() {
        assert_eq!(LN2_HI + LN2_LO, std::f64::consts::LN_2);
        assert_eq!(LN2_HI.to_bits() & 0x1f_ffff, 0);
    }

    /// Units in the last place between `a` and the library's `b`.
    fn ulps(a: f64, b: f64) -> u64 {
        if a == b {
            return 0;
        }
        (a.to_bits() as i64 - b.to_bits() as i64).unsigned_abs()
    }

    #[test]
    fn special_values_are_the_library_s() {
        assert_eq!(exp(0.0), 1.0);
        assert_eq!(exp(f64::NEG_INFINITY), 0.0);
        assert_eq!(exp(f64::INFINITY), f64::INFINITY);
        assert_eq!(exp(800.0), f64::INFINITY);
        assert_eq!(exp(-800.0), 0.0);
        assert!(exp(f64::NAN).is_nan());
        assert_eq!(ln(1.0), 0.0);
        assert_eq!(ln(0.0), f64::NEG_INFINITY);
        assert_eq!(ln(f64::INFINITY), f64::INFINITY);
        assert!(ln(-1.0).is_nan() && ln(f64::NAN).is_nan() && ln(f64::NEG_INFINITY).is_nan());
        assert!(ulps(ln(f64::MIN_POSITIVE / 1024.0), (f64::MIN_POSITIVE / 1024.0).ln()) <= 2);
        assert!(ulps(exp(-740.0), (-740.0f64).exp()) <= 1, "subnormal results");
    }

    #[test]
    fn atan2_and_acos_special_values_are_the_library_s() {
        use std::f64::consts::{FRAC_PI_2, PI};
        let (inf, zero) = (f64::INFINITY, 0.0f64);
        let pairs = [
            (zero, zero),
            (-zero, zero),
            (zero, -zero),
            (-zero, -zero),
            (zero, -2.0),
            (-zero, -2.0),
            (zero, 3.0),
            (2.0, zero),
            (-2.0, -zero),
            (inf, inf),
            (-inf, inf),
            (inf, -inf),
            (-inf, -inf),
            (1.0, inf),
            (-1.0, -inf),
            (inf, 5.0),
            (1.0, 1.0),
            (-1.0, -1.0),
            (f64::MAX, f64::MIN_POSITIVE),
            (f64::MIN_POSITIVE, -f64::MAX),
            (f64::MAX, f64::MAX * 0.7),
            (-f64::MAX * 0.9, f64::MAX),
            (5e-324, 1.5e-323),
            (-2.2e-308, 1e-310),
        ];
        for (y, x) in pairs {
            let (ours, theirs) = (atan2(y, x), y.atan2(x));
            assert!(ulps(ours, theirs) <= 1, "atan2({y}, {x}): {ours} vs {theirs}");
            assert_eq!(ours.is_sign_negative(), theirs.is_sign_negative(), "atan2({y}, {x})");
        }
        assert!(atan2(f64::NAN, 1.0).is_nan() && atan2(1.0, f64::NAN).is_nan());
        assert_eq!((acos(1.0), acos(-1.0), acos(0.0)), (0.0, PI, FRAC_PI_2));
        assert!(acos(1.5).is_nan() && acos(-1.0 - 1e-15).is_nan() && acos(f64::NAN).is_nan());
    }

    proptest! {
        /// Within four units in the last place of the library, in every direction, at
        /// magnitudes from 2⁻²⁰⁰ to 2²⁰⁰ and across each of the reduction's interval edges.
        #[test]
        fn atan2_matches_the_library(
            y in -1.0..1.0f64, x in -1.0..1.0f64, ey in -200..200i32, ex in -200..200i32, edge in 0..2usize,
            nudge in -64..64i64,
        ) {
            let t = f64::from_bits(([0.668_178_637_919_298_9f64, 0.198_912_367_379_658][edge].to_bits() as i64 + nudge) as u64);
            for (y, x) in [(y, x), (y * 2f64.powi(ey), x * 2f64.powi(ex)), (t, 1.0), (-1.0, -t)] {
                prop_assert!(ulps(atan2(y, x), y.atan2(x)) <= 4, "atan2({}, {}): {} vs {}", y, x, atan2(y, x), y.atan2(x));
            }
        }

        /// Within four units in the last place of the library on `[−1, 1]`, its ends included.
        #[test]
        fn acos_matches_the_library(x in -1.0..=1.0f64) {
            prop_assert!(ulps(acos(x), x.acos()) <= 4, "acos({}): {} vs {}", x, acos(x), x.acos());
        }

        /// Within 10⁻¹³ of the library's, relatively, where a material raises a cosine or a
        /// number of `[0, 1)` to a power: exponents from 10⁻⁴ to 10⁴ (results below the normal
        /// range excepted), and the special values.
        #[test]
        fn pow_matches_the_library(x in 0.0..=1.0f64, e in -4.0..4.0f64) {
            let y = 10f64.powf(e);
            for (x, y) in [(x, y), (x, 1.0 / y), (1.0 - x * 1e-9, y)] {
                let (ours, theirs) = (pow(x, y), x.powf(y));
                if theirs >= f64::MIN_POSITIVE {
                    prop_assert!((ours - theirs).abs() <= 1e-13 * theirs, "pow({}, {}): {} vs {}", x, y, ours, theirs);
                } else {
                    prop_assert!(ours < 1e-300, "pow({}, {}): {} vs {}", x, y, ours, theirs);
                }
            }
            prop_assert_eq!((pow(x, 0.0), pow(0.0, y), pow(0.0, -y), pow(1.0, y)), (1.0, 0.0, f64::INFINITY, 1.0));
            prop_assert!(pow(-0.5, y).is_nan());
        }

        /// Within two units in the last place of the library, over the whole normal range.
        #[test]
        fn exp_matches_the_library(x in -708.0..709.0f64) {
            prop_assert!(ulps(exp(x), x.exp()) <= 2, "{}: {} vs {}", x, exp(x), x.exp());
        }

        #[test]
        fn exp_matches_the_library_near_zero(x in -1.0..1.0f64) {
            prop_assert!(ulps(exp(x), x.exp()) <= 2, "{}: {} vs {}", x, exp(x), x.exp());
        }

        #[test]
        fn ln_matches_the_library(x in 1e-300..1e300f64, u in 1e-17..1.0f64) {
            prop_assert!(ulps(ln(x), x.ln()) <= 2, "{}: {} vs {}", x, ln(x), x.ln());
            prop_assert!(ulps(ln(u), u.ln()) <= 2, "{}: {} vs {}", u, ln(u), u.ln());
            // Near 1, where the result is small.
            let near = 1.0 + (u - 0.5) * 1e-3;
            prop_assert!(ulps(ln(near), near.ln()) <= 2, "{}: {} vs {}", near, ln(near), near.ln());
        }
    }
}
