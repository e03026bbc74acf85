//! Exact sums of doubles: the result depends only on the numbers summed, never on their order
//! or grouping. The film sums a pixel's samples this way, so a render split into sample passes
//! and merged has the bits of the render made at once.
//!
//! A *superaccumulator* (after Neal, "Fast exact summation using small and large
//! superaccumulators", 2015): every finite double is an integer multiple of 2^−1074, so the
//! sum is kept as an integer in base 2^32, one `i64` digit ("chunk") per 32 bits, with 31
//! bits of headroom for carries. Adding a double adds its 53-bit significand, shifted, into
//! three chunks — a few integer operations, no branch on the data. Carries are propagated
//! only when a result is read (or after 2^30 additions), which gives the canonical digits;
//! [`ExactSum::value`] rounds those once, to nearest with ties to even.

/// Digits: the significand of the largest double ends in chunk 65; two more take carries.
const CHUNKS: usize = 68;
/// Additions before the digits must be normalised (each adds less than 2^32 to a digit).
const ADDS_BEFORE_CARRY: u32 = 1 << 30;

/// Magnitudes beyond which callers should clamp terms: then even 2^20 of them and their
/// merged sums stay far inside the double range.
pub const MAX_TERM: f64 = 1e300;

/// The exact sum of the doubles added so far.
#[derive(Clone, Debug)]
pub struct ExactSum {
    /// `Σ chunks[k] · 2^(32k − 1074)`.
    chunks: [i64; CHUNKS],
    /// The digits that may be nonzero: `touched.0 ..= touched.1` (empty when `0 > 1`).
    touched: (usize, usize),
    adds: u32,
}

impl Default for ExactSum {
    fn default() -> Self {
        Self { chunks: [0; CHUNKS], touched: (CHUNKS, 0), adds: 0 }
    }
}

impl PartialEq for ExactSum {
    /// Equal exact values.
    fn eq(&self, other: &Self) -> bool {
        self.digits() == other.digits()
    }
}

impl ExactSum {
    /// The empty sum.
    pub fn new() -> Self {
        Self::default()
    }

    /// Forgets everything added.
    pub fn clear(&mut self) {
        let (lo, hi) = self.touched;
        if lo <= hi {
            self.chunks[lo..=hi].fill(0);
        }
        self.touched = (CHUNKS, 0);
        self.adds = 0;
    }

    /// Adds `x` exactly. `x` must be finite (callers drop or clamp the others).
    #[inline]
    pub fn add(&mut self, x: f64) {
        debug_assert!(x.is_finite(), "{x}");
        if x == 0.0 {
            return; // common (black), and it would widen the digits to carry
        }
        let bits = x.to_bits();
        let exponent = ((bits >> 52) & 0x7ff) as u32;
        let fraction = bits & ((1 << 52) - 1);
        let significand = if exponent == 0 { fraction } else { fraction | 1 << 52 };
        // |x| = significand · 2^(p − 1074), p = 0 for subnormals.
        let p = exponent.max(1) - 1;
        let (k, shift) = ((p >> 5) as usize, p & 31);
        let shifted = (significand as u128) << shift;
        let negate = (bits as i64) >> 63; // 0 or −1
        let signed = |d: i64| (d ^ negate) - negate;
        self.chunks[k] += signed((shifted as u32) as i64);
        self.chunks[k + 1] += signed(((shifted >> 32) as u32) as i64);
        self.chunks[k + 2] += signed((shifted >> 64) as i64);
        self.touched = (self.touched.0.min(k), self.touched.1.max(k + 2));
        self.adds += 1;
        if self.adds == ADDS_BEFORE_CARRY {
            self.carry();
        }
    }

    /// Adds the sum whose [`Digits`] are given, exactly.
    pub fn add_digits(&mut self, d: &Digits) {
        let end = d.first + d.digits.len();
        if d.digits.is_empty() {
            return;
        }
        let sign = if d.negative { -1 } else { 1 };
        self.chunks[d.first..end].iter_mut().zip(&d.digits).for_each(|(c, &v)| *c += sign * v as i64);
        self.touched = (self.touched.0.min(d.first), self.touched.1.max(end - 1));
        self.adds += 1;
        if self.adds == ADDS_BEFORE_CARRY {
            self.carry();
        }
    }

    /// Propagates carries upward (every digit but the top one then in `0..2^32`).
    fn carry(&mut self) {
        let (lo, hi) = self.touched;
        if lo <= hi {
            self.touched.1 = carry(&mut self.chunks, lo, hi);
        }
        self.adds = 0;
    }

    /// The sum's canonical digits: two sums of the same value have the same digits.
    pub fn digits(&self) -> Digits {
        let (lo, hi) = self.touched;
        if lo > hi {
            return Digits::default();
        }
        let mut c = self.chunks;
        let mut top = carry(&mut c, lo, hi);
        let negative = c[top] < 0;
        if negative {
            c[lo..=top].iter_mut().for_each(|d| *d = -*d);
            top = carry(&mut c, lo, top);
        }
        let Some(first) = (lo..=top).find(|&k| c[k] != 0) else { return Digits::default() };
        let last = (first..=top).rev().find(|&k| c[k] != 0).unwrap_or(first);
        Digits { negative, first, digits: c[first..=last].iter().map(|&d| d as u32).collect() }
    }

    /// The exact sum rounded to the nearest double, ties to even (in the subnormal range
    /// within one unit of the last place, still a function of the exact sum alone). Carries
    /// in place, without allocating: this runs once per pixel and channel.
    pub fn value(&mut self) -> f64 {
        let (lo, hi) = self.touched;
        if lo > hi {
            return 0.0;
        }
        let mut top = carry(&mut self.chunks, lo, hi);
        self.touched.1 = top;
        self.adds = 0;
        if self.chunks[top] < 0 {
            return self.digits().value(); // negative sums are rare: through a copy
        }
        let c = &self.chunks;
        while top > lo && c[top] == 0 {
            top -= 1;
        }
        let base = top.saturating_sub(2);
        let window = c[base..=top].iter().rev().fold(0u128, |v, &d| (v << 32) | d as u128);
        let sticky = c[lo.min(base)..base].iter().any(|&d| d != 0);
        round(window, sticky, base, false)
    }
}

/// `±(window + sticky/2) · 2^(32·place − 1074)` rounded to the nearest double, ties to even,
/// where `sticky` says whether anything below the window is nonzero. With a window of at least
/// 55 significant bits, rounding it with the sticky bit is rounding the whole sum.
fn round(window: u128, sticky: bool, place: usize, negative: bool) -> f64 {
    let magnitude = ((window << 1) | sticky as u128) as f64;
    let v = scale_by_power_of_two(magnitude, 32 * place as i32 - 1075);
    if negative { -v } else { v }
}

/// Carries `c[lo..]` upward until nothing is left to carry past `hi` (digits above `hi` are
/// zero); returns the top digit's index. Every digit below it is then in `0..2^32`; the top one
/// is negative for a negative sum (and the carrying stops there, not at the last digit).
fn carry(c: &mut [i64; CHUNKS], lo: usize, hi: usize) -> usize {
    let mut top = hi;
    for k in lo..CHUNKS - 1 {
        let carry = c[k] >> 32;
        if k >= hi && carry == 0 {
            break;
        }
        c[k] -= carry << 32;
        c[k + 1] += carry;
        top = top.max(k + 1);
        if k >= hi && (-(1 << 32)..0).contains(&c[k + 1]) {
            break;
        }
    }
    top
}

/// An exact sum in canonical form, sign and magnitude: `±Σ digits[i] · 2^(32(first + i) − 1074)`,
/// no zero digit at either end (what a partial render stores per pixel and channel).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Digits {
    /// Whether the sum is negative.
    pub negative: bool,
    /// The place of the lowest digit.
    pub first: usize,
    /// Base-2^32 digits of the magnitude, lowest first.
    pub digits: Vec<u32>,
}

impl Digits {
    /// Checks digits read from outside: they must be the canonical digits of some sum.
    pub fn check(&self) -> Result<(), String> {
        let canonical = self.digits.first().is_none_or(|&d| d != 0) && self.digits.last().is_none_or(|&d| d != 0);
        if self.first + self.digits.len() > CHUNKS || !canonical || (self.digits.is_empty() && self.negative) {
            return Err("not the digits of an exact sum".into());
        }
        Ok(())
    }

    /// The value rounded to the nearest double, ties to even.
    pub fn value(&self) -> f64 {
        let d = &self.digits;
        if d.is_empty() {
            return 0.0;
        }
        // The top three digits (at least 65 significant bits when there are three) and a sticky
        // bit for anything below: rounding them is rounding the whole.
        let base = (d.len() - 1).saturating_sub(2);
        let window = d[base..].iter().rev().fold(0u128, |v, &c| (v << 32) | c as u128);
        let sticky = d[..base].iter().any(|&c| c != 0);
        round(window, sticky, self.first + base, self.negative)
    }
}

/// `x · 2^e`, exact while the result is a normal double.
fn scale_by_power_of_two(x: f64, e: i32) -> f64 {
    let pow = |e: i32| f64::from_bits(((e + 1023) as u64) << 52);
    match e {
        -1022..=1023 => x * pow(e),
        e if e > 1023 => x * pow(1023) * pow((e - 1023).min(1023)),
        e => x * pow((e + 600).max(-1022)) * pow(-600),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Doubles that are multiples of 2^-40 below 2^50 in magnitude: their exact sum fits an
    /// i128, and `i128 as f64` rounds to nearest, ties to even — an independent reference.
    fn fixed_point() -> impl Strategy<Value = i128> {
        prop_oneof![
            (-(1i128 << 90)..(1i128 << 90)),
            (-(1i128 << 20)..(1i128 << 20)),
            (-(1i128 << 53)..(1i128 << 53)).prop_map(|m| m << 37),
        ]
    }

    fn as_double(units: i128) -> f64 {
        let d = units as f64;
        assert_eq!(d as i128, units, "a term is a double exactly");
        d * 2f64.powi(-40)
    }

    fn exact(terms: &[i128]) -> f64 {
        terms.iter().sum::<i128>() as f64 * 2f64.powi(-40)
    }

    /// A term representable exactly: the top 53 bits of `units`.
    fn representable(units: i128) -> i128 {
        (units as f64) as i128
    }

    fn sum(terms: &[f64]) -> ExactSum {
        let mut s = ExactSum::new();
        terms.iter().for_each(|&t| s.add(t));
        s
    }

    proptest! {
        #[test]
        fn the_sum_is_the_exact_sum_correctly_rounded(raw in prop::collection::vec(fixed_point(), 0..60)) {
            let terms: Vec<i128> = raw.into_iter().map(representable).collect();
            let doubles: Vec<f64> = terms.iter().map(|&t| as_double(t)).collect();
            prop_assert_eq!(sum(&doubles).value().to_bits(), exact(&terms).to_bits());
        }

        #[test]
        fn order_and_grouping_do_not_matter(raw in prop::collection::vec(fixed_point(), 1..60), cut in 0usize..60, seed in any::<u64>()) {
            let terms: Vec<f64> = raw.into_iter().map(|u| as_double(representable(u))).collect();
            let mut whole = sum(&terms);
            // Two passes summed apart, then merged by their digits.
            let cut = cut.min(terms.len());
            let (a, mut b) = (sum(&terms[..cut]), sum(&terms[cut..]));
            b.add_digits(&a.digits());
            prop_assert_eq!(b.digits(), whole.digits());
            prop_assert_eq!(b.value().to_bits(), whole.value().to_bits());
            prop_assert_eq!(whole.digits().value().to_bits(), whole.value().to_bits());
            // Any permutation.
            let mut shuffled = terms.clone();
            let mut state = seed | 1;
            for i in (1..shuffled.len()).rev() {
                state ^= state << 13; state ^= state >> 7; state ^= state << 17;
                shuffled.swap(i, (state % (i as u64 + 1)) as usize);
            }
            prop_assert_eq!(sum(&shuffled).value().to_bits(), whole.value().to_bits());
        }

        #[test]
        fn any_doubles_sum_exactly_at_every_scale(mantissas in prop::collection::vec(-(1i64 << 53)..(1i64 << 53), 1..30), scale in -1070i32..900) {
            // Terms sharing one exponent: their sum is an i64-sized integer times 2^scale.
            let unit = scale_by_power_of_two(1.0, scale);
            let terms: Vec<f64> = mantissas.iter().map(|&m| m as f64 * unit).collect();
            let reference = scale_by_power_of_two(mantissas.iter().map(|&m| m as i128).sum::<i128>() as f64, scale);
            prop_assert_eq!(sum(&terms).value().to_bits(), reference.to_bits());
        }
    }

    #[test]
    fn where_naive_summation_fails() {
        assert_eq!(sum(&[1e100, 1.0, -1e100, 1e-30]).value(), 1.0 + 1e-30);
        // Ties to even, decided by a digit far below.
        assert_eq!(sum(&[1.0, f64::EPSILON / 2.0, f64::EPSILON * 1e-10]).value(), 1.0 + f64::EPSILON);
        assert_eq!(sum(&[1.0, -f64::EPSILON / 4.0]).value(), 1.0);
        assert_eq!(sum(&[1.0, -f64::EPSILON / 4.0, -f64::EPSILON * 1e-10]).value(), 1.0 - f64::EPSILON / 2.0);
        assert_eq!(sum(&[-3.5, -1e-300]).value(), -3.5);
        assert_eq!(sum(&[f64::MIN_POSITIVE / 8.0, f64::MIN_POSITIVE]).value(), f64::MIN_POSITIVE * 1.125);
        assert_eq!(sum(&[MAX_TERM; 1024]).value(), MAX_TERM * 1024.0);
        assert_eq!(ExactSum::new().value(), 0.0);
        assert_eq!(sum(&[2.5, -2.5]).value(), 0.0);
        let mut s = sum(&[7.0, 1e-200]);
        s.clear();
        assert_eq!((s.value(), s.digits()), (0.0, Digits::default()));
        assert_eq!(sum(&[-1.0, 0.25]).digits(), Digits { negative: true, first: 33, digits: vec![3 << 16] });
    }

    #[test]
    fn foreign_digits_are_refused() {
        let d = |negative, first, digits: &[u32]| Digits { negative, first, digits: digits.to_vec() };
        assert!(d(false, CHUNKS - 1, &[1, 1]).check().is_err());
        assert!(d(false, 3, &[0, 1]).check().is_err());
        assert!(d(true, 3, &[]).check().is_err());
        assert!(d(true, 3, &[5, 7]).check().is_ok());
    }
}
