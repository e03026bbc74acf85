//! Real roots of polynomials of degree ≤ 4 on an interval, by isolation: the roots of the
//! derivative split the interval into monotone pieces, each holding at most one root, found by
//! safeguarded Newton (bisection when Newton leaves the bracket). Critical points where the
//! polynomial nearly vanishes are reported too: they are (near-)double roots, which bracketing
//! cannot see and which the caller polishes or rejects.

/// Coefficients in ascending order: `c[k]` multiplies `x^k`.
pub type Poly = [f64; 5];

/// Up to four roots, ascending.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Roots {
    vals: [f64; 4],
    len: usize,
}

impl Roots {
    fn push(&mut self, x: f64) {
        if self.len < 4 && (self.len == 0 || (x - self.vals[self.len - 1]).abs() > 1e-14) {
            self.vals[self.len] = x;
            self.len += 1;
        }
    }

    /// The roots found.
    pub fn as_slice(&self) -> &[f64] {
        &self.vals[..self.len]
    }
}

/// `p(x)` by Horner's scheme.
#[inline]
pub fn eval(p: &Poly, x: f64) -> f64 {
    (((p[4] * x + p[3]) * x + p[2]) * x + p[1]) * x + p[0]
}

/// The derivative.
pub fn derivative(p: &Poly) -> Poly {
    [p[1], 2.0 * p[2], 3.0 * p[3], 4.0 * p[4], 0.0]
}

/// `Σ |c_k| |x|^k`, the scale against which `p(x)` counts as zero.
fn magnitude(p: &Poly, x: f64) -> f64 {
    let ax = x.abs();
    (((p[4].abs() * ax + p[3].abs()) * ax + p[2].abs()) * ax + p[1].abs()) * ax + p[0].abs()
}

/// Real roots of `p` in `[lo, hi]`, ascending. A polynomial that is identically zero has none.
pub fn real_roots_in(p: &Poly, lo: f64, hi: f64) -> Roots {
    let mut out = Roots::default();
    let degree = (0..5).rev().find(|&k| p[k] != 0.0).unwrap_or(0);
    if degree == 0 {
        return out;
    }
    let mut breaks = [lo; 6];
    let mut nb = 1;
    if degree > 1 {
        for &c in real_roots_in(&derivative(p), lo, hi).as_slice() {
            if c > breaks[nb - 1] && c < hi {
                breaks[nb] = c;
                nb += 1;
            }
        }
    }
    breaks[nb] = hi;
    nb += 1;
    for w in 0..nb - 1 {
        let (a, b) = (breaks[w], breaks[w + 1]);
        let (fa, fb) = (eval(p, a), eval(p, b));
        // A critical point where p nearly vanishes without crossing zero on either side: a
        // (near-)double root, which bracketing cannot see. Two close simple roots around it are
        // bracketed instead (p changes sign in both neighbouring pieces).
        if w > 0 && fa.abs() <= 1e-9 * magnitude(p, a) {
            let before = eval(p, breaks[w - 1]);
            let crossing = fa != 0.0 && (before.signum() != fa.signum() || fb.signum() != fa.signum());
            if !crossing {
                out.push(a);
            }
        }
        if fa == 0.0 && w == 0 {
            out.push(a);
        } else if fa.signum() != fb.signum() && fb != 0.0 {
            out.push(bracketed_root(p, a, b, fa));
        }
        if fb == 0.0 && w == nb - 2 {
            out.push(b);
        }
    }
    out
}

/// The root of `p` in `[a, b]` where `p(a)` has sign `fa` and `p(b)` the other.
fn bracketed_root(p: &Poly, mut a: f64, mut b: f64, fa: f64) -> f64 {
    let dp = derivative(p);
    let mut x = 0.5 * (a + b);
    for _ in 0..100 {
        let fx = eval(p, x);
        if fx == 0.0 {
            return x;
        }
        if fx.signum() == fa.signum() {
            a = x
        } else {
            b = x
        }
        let d = eval(&dp, x);
        let newton = x - fx / d;
        x = if d != 0.0 && newton > a && newton < b { newton } else { 0.5 * (a + b) };
        if (b - a).abs() <= 4.0 * f64::EPSILON * x.abs().max(1e-300) {
            break;
        }
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn from_roots(r: &[f64]) -> Poly {
        let mut p = [1.0, 0.0, 0.0, 0.0, 0.0];
        for (k, &x) in r.iter().enumerate() {
            for i in (0..=k + 1).rev() {
                p[i] = if i > 0 { p[i - 1] } else { 0.0 } - x * p[i];
            }
        }
        p
    }

    #[test]
    fn double_roots_are_found() {
        let p = from_roots(&[0.3, 0.3, -0.5, 0.9]);
        let r = real_roots_in(&p, -1.0, 1.0);
        assert_eq!(r.as_slice().len(), 3, "{r:?}");
        assert!((r.as_slice()[1] - 0.3).abs() < 1e-7);
    }

    proptest! {
        #[test]
        fn simple_roots_are_found(mut rs in prop::collection::vec(-0.99..0.99f64, 4), scale in 0.1..100.0f64) {
            rs.sort_by(f64::total_cmp);
            prop_assume!(rs.windows(2).all(|w| w[1] - w[0] > 1e-3));
            let p = from_roots(&rs).map(|c| c * scale);
            let r = real_roots_in(&p, -1.0, 1.0);
            prop_assert_eq!(r.as_slice().len(), 4);
            for (a, b) in r.as_slice().iter().zip(&rs) {
                prop_assert!((a - b).abs() < 1e-9, "{} vs {}", a, b);
            }
        }
    }
}
