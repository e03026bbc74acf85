//! A convex combination `w·ρ_a + (1 − w)·ρ_b` of two scattering functions (the course's "convex
//! combination of the distributions" for surfaces with several families of microfacets).
//!
//! Parameters: the two BSDFs and the weight `w ∈ [0, 1]` of the first.

use super::{Bsdf, BsdfSample};
use alhazen_math::{Vec2, Vec3};

/// A blend of two BSDFs.
#[derive(Clone, Debug)]
pub struct Mix {
    /// First.
    pub a: Bsdf,
    /// Second.
    pub b: Bsdf,
    /// Weight of `a`.
    pub weight: f64,
}

/// `w·ρ_a + (1 − w)·ρ_b`: [`Mix::eval`] from its components' values (the path tracer's lanes
/// blend a mirror and Lambert through it too).
#[inline(always)]
pub(crate) fn blend(w: f64, a: Vec3, b: Vec3) -> Vec3 {
    a * w + b * (1.0 - w)
}

/// `w·p_a + (1 − w)·p_b`: [`Mix::pdf`] from its components' densities.
#[inline(always)]
pub(crate) fn blend_density(w: f64, a: f64, b: f64) -> f64 {
    a * w + b * (1.0 - w)
}

impl Mix {
    /// Weighted sum.
    pub fn eval(&self, v: Vec3, l: Vec3) -> Vec3 {
        self.eval_pdf(v, l).0
    }

    /// Weighted sum of the densities.
    pub fn pdf(&self, v: Vec3, l: Vec3) -> f64 {
        self.eval_pdf(v, l).1
    }

    /// Both sums, from the components' own `eval_pdf` (the path tracer's lanes blend the
    /// components they evaluate the same way).
    pub fn eval_pdf(&self, v: Vec3, l: Vec3) -> (Vec3, f64) {
        let ((fa, pa), (fb, pb)) = (self.a.eval_pdf(v, l), self.b.eval_pdf(v, l));
        (blend(self.weight, fa, fb), blend_density(self.weight, pa, pb))
    }

    /// The number a component is drawn with, `uc` rescaled to `[0, 1)` within the chosen
    /// component's share, and whether it is the first.
    #[inline(always)]
    pub(crate) fn component_choice(weight: f64, uc: f64) -> (bool, f64) {
        let (first, uc2) = if uc < weight { (true, uc / weight) } else { (false, (uc - weight) / (1.0 - weight)) };
        (first, uc2.min(1.0 - 1e-16))
    }

    /// Picks a component by `uc` (rescaled for the component's own use). A delta sample keeps its
    /// own weight times the choice probability; a smooth one is re-evaluated as the full mixture.
    pub fn sample(&self, v: Vec3, uc: f64, u: Vec2) -> Option<BsdfSample> {
        let (first, uc2) = Self::component_choice(self.weight, uc);
        let (chosen, p) = if first { (&self.a, self.weight) } else { (&self.b, 1.0 - self.weight) };
        let mut s = chosen.sample(v, uc2, u)?;
        if s.delta {
            s.f *= p;
            s.pdf *= p;
            return Some(s);
        }
        (s.f, s.pdf) = self.eval_pdf(v, s.l);
        (s.pdf > 0.0).then_some(s)
    }
}
