//! `exp` and `ln` without branches or library calls, so that loops calling them vectorise (the
//! path tracer's material kernels evaluate Beckmann's `D = e^{−tan²ϑ/m²}…` and sample it by
//! `tan²ϑ = −m² ln(1 − u)` for eight paths at once; the C library's functions are calls the
//! compiler cannot vectorise).
//!
//! Both follow the classical scheme (Cody and Waite 1980; Muller, "Elementary Functions",
//! ch. 11): an exact reduction by powers of two, then a polynomial on a small interval.
//!
//! * `exp(x) = 2^k · e^r`, `k = round(x / ln 2)`, `r = x − k ln 2` with `ln 2` split in two
//!   parts (the first with trailing zero bits, so `k · ln2_hi` is exact), `|r| ≤ ln 2 / 2`;
//!   `e^r` by its Taylor polynomial of degree 13 (truncation below 5·10⁻¹⁸), `2^k` built from
//!   its bits in two halves (results down to the subnormals).
//! * `ln(x) = e ln 2 + ln m`, `x = m · 2^e`, `m ∈ [√½, √2)`; `ln m = 2 atanh s`,
//!   `s = (m − 1)/(m + 1)`, `|s| ≤ 0.1716`, by its series to `s²³` (truncation below 10⁻¹⁸).
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
    // Horner's scheme on 1/n! (no fused multiply–adds: the same bits everywhere).
    let mut p = 1.0 / 6_227_020_800.0;
    for n in (1..13).rev() {
        p = p * r + 1.0 / factorial(n);
    }
    let er = p * r + 1.0;
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
    // 2 atanh s = 2 (s + s³/3 + … + s²³/23), Horner on s².
    let mut p = 1.0 / 23.0;
    for n in (0..11).rev() {
        p = p * s2 + 1.0 / (2 * n + 1) as f64;
    }
    let ln_m = 2.0 * s * p;
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

    proptest! {
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
