//! Real roots of quadratics, robust against cancellation (the "citardauq" form).

/// Up to two real roots in ascending order.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QuadraticRoots {
    roots: [f64; 2],
    count: usize,
}

impl QuadraticRoots {
    /// The roots found, ascending.
    pub fn as_slice(&self) -> &[f64] {
        &self.roots[..self.count]
    }
}

/// Real roots of `a x² + b x + c = 0`. A double root is reported twice; `a = 0` degrades to
/// the linear equation. No roots for a negative discriminant or all-zero coefficients.
#[inline]
pub fn solve_quadratic(a: f64, b: f64, c: f64) -> QuadraticRoots {
    let none = QuadraticRoots { roots: [0.0; 2], count: 0 };
    if a == 0.0 {
        if b == 0.0 {
            return none;
        }
        return QuadraticRoots { roots: [-c / b, 0.0], count: 1 };
    }
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 || disc.is_nan() {
        return none;
    }
    let q = -0.5 * (b + disc.sqrt().copysign(b));
    let (x0, x1) = if q == 0.0 { (0.0, 0.0) } else { (q / a, c / q) };
    QuadraticRoots { roots: [x0.min(x1), x0.max(x1)], count: 2 }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn cancellation_is_avoided() {
        // Roots 1e-8 and 1e8: the naive formula loses the small one.
        let r = solve_quadratic(1.0, -(1e8 + 1e-8), 1.0);
        let s = r.as_slice();
        assert!((s[0] - 1e-8).abs() < 1e-22);
        assert!((s[1] - 1e8).abs() < 1e-6);
        assert!(solve_quadratic(1.0, 0.0, 1.0).as_slice().is_empty());
        assert_eq!(solve_quadratic(0.0, 2.0, -4.0).as_slice(), &[2.0]);
    }

    proptest! {
        #[test]
        fn roots_satisfy_the_equation(r0 in -100.0..100.0f64, r1 in -100.0..100.0f64, a in 0.1..10.0f64) {
            let r = solve_quadratic(a, -a * (r0 + r1), a * r0 * r1);
            let s = r.as_slice();
            prop_assert_eq!(s.len(), 2);
            prop_assert!((s[0] - r0.min(r1)).abs() < 1e-9 * (1.0 + r0.abs().max(r1.abs())));
            prop_assert!((s[1] - r0.max(r1)).abs() < 1e-9 * (1.0 + r0.abs().max(r1.abs())));
        }
    }
}
