//! A diffuse base under a dielectric specular lobe, weighed by what the lobe leaves: the
//! directional albedo `E(μ) = ∫ D G F / (4 μ μ_l) μ_l dω_l` of the lobe seen at cosine `μ`, so
//! that a layered Cook–Torrance surface `k_d(1 − k_s·E(μ_o))·ρ/π + k_s·ρ_s` reflects no more
//! than arrives at any angle (the course's physically based model, chapter "Reflection models";
//! Cycles' Principled BSDF weighs its base so, "albedo scaling"; glTF's layering by the Fresnel
//! term aims at the same). A constant `k_d = 1 − k_s·F(0)` gives back 9 % more than a white
//! base receives at 85°.
//!
//! `E` depends on the cosine, the roughness and the index. It is tabulated over `μ` and
//! `r = √α` (as [`super::multiscatter`]'s table) in slices of `t = |η − 1|/(η + 1)` (`√F(0)`),
//! each slice computed when a surface of an index near it is first met (a glTF's default 1.5
//! falls on one), for Trowbridge–Reitz and for Beckmann facets with Smith's shadowing and the
//! exact Fresnel term; lookups interpolate linearly along all three.

use super::microfacet::Microfacet;
use crate::optics::fresnel_dielectric;
use alhazen_scene::bsdf::Distribution;
use std::sync::OnceLock;

/// Table size along `μ` and along `r = √α`.
const N: usize = 32;
/// Slices along `t`, `t_k = k·T_STEP` up to 0.9 (an index of 19).
const SLICES: usize = 19;
const T_STEP: f64 = 0.05;

/// `E` at `μ_j = j/(N−1)` (column `j`) for `α = r_i²` (row `i`, `r_i = i/(N−1)`).
type Slice = [[f64; N]; N];

/// The slices of each distribution (Trowbridge–Reitz first), each made on first use.
static TABLES: [[OnceLock<Box<Slice>>; SLICES]; 2] = [const { [const { OnceLock::new() }; SLICES] }; 2];

/// The slice `k` of `E` for Beckmann facets or Trowbridge–Reitz ones.
fn slice(beckmann: bool, k: usize) -> &'static Slice {
    TABLES[usize::from(beckmann)][k].get_or_init(|| Box::new(compute(beckmann, index_at(k as f64 * T_STEP))))
}

/// The index whose `t` is `t`.
fn index_at(t: f64) -> f64 {
    (1.0 + t) / (1.0 - t)
}

/// A slice: each row on its own thread, every sum in a fixed order (the same bits on any
/// number of threads).
fn compute(beckmann: bool, eta: f64) -> Slice {
    use rayon::prelude::*;
    let mut rows = [[0.0; N]; N];
    rows.par_iter_mut().enumerate().for_each(|(i, row)| {
        let r = i as f64 / (N - 1) as f64;
        let alpha = (r * r).max(1e-3);
        let facets =
            if beckmann { Microfacet::smith::<true>(alpha, alpha) } else { Microfacet::smith::<false>(alpha, alpha) };
        for (j, e) in row.iter_mut().enumerate() {
            *e = directional_albedo(&facets, j as f64 / (N - 1) as f64, eta);
        }
    });
    rows
}

/// `E(μ)` of the lobe of `facets` and index `eta` (the quadrature of [`super::multiscatter`]'s
/// table, with the Fresnel factor).
pub(super) fn directional_albedo(facets: &Microfacet, mu: f64, eta: f64) -> f64 {
    super::multiscatter::stratified_albedo(facets, mu, |cos| fresnel_dielectric(cos, eta))
}

/// `E(μ)` of a dielectric lobe of index `eta` on `facets` (Beckmann's or, for every other
/// distribution, Trowbridge–Reitz's; two roughnesses by their geometric mean), interpolated.
#[inline]
pub(crate) fn albedo(facets: &Microfacet, mu: f64, eta: f64) -> f64 {
    let beckmann = facets.distribution == Distribution::Beckmann;
    let t = ((eta - 1.0) / (eta + 1.0)).abs().min((SLICES - 1) as f64 * T_STEP);
    let z = t / T_STEP;
    let k = (z as usize).min(SLICES - 2);
    let fz = z - k as f64;
    let r = (facets.alpha_u * facets.alpha_v).max(0.0).sqrt().sqrt().min(1.0) * (N - 1) as f64;
    let i = (r as usize).min(N - 2);
    let fr = r - i as f64;
    let x = mu.abs().min(1.0) * (N - 1) as f64;
    let j = (x as usize).min(N - 2);
    let fx = x - j as f64;
    let bilinear = |s: &Slice| {
        let row = |i: usize| s[i][j] * (1.0 - fx) + s[i][j + 1] * fx;
        row(i) * (1.0 - fr) + row(i + 1) * fr
    };
    let near = bilinear(slice(beckmann, k));
    // An index on a slice (a glTF's 1.5) needs no second one.
    if fz == 0.0 { near } else { near * (1.0 - fz) + bilinear(slice(beckmann, k + 1)) * fz }
}

#[cfg(test)]
mod tests {
    use super::*;

    proptest::proptest! {
        /// The table's `E` is the lobe's own albedo within 0.01 between its nodes, for indices
        /// from water's to diamond's and beyond, rough and nearly smooth.
        #[test]
        fn interpolated_albedo_is_the_lobes(
            mu in 0.02..1.0f64,
            r in 0.05..1.0f64,
            eta in 1.0..3.0f64,
            beckmann in proptest::bool::ANY,
        ) {
            let alpha = r * r;
            let facets = if beckmann { Microfacet::smith::<true>(alpha, alpha) } else { Microfacet::smith::<false>(alpha, alpha) };
            let exact = directional_albedo(&facets, mu, eta);
            let table = albedo(&facets, mu, eta);
            proptest::prop_assert!((table - exact).abs() < 0.01, "E({mu}, α {alpha}, η {eta}) = {exact}, table {table}");
        }
    }

    /// `E` is `F(0)` head-on on nearly smooth facets and grows towards grazing angles; rough
    /// facets lose some of it to shadowing.
    #[test]
    fn albedo_follows_the_fresnel_term() {
        let smooth = Microfacet::smith::<false>(1e-3, 1e-3);
        let f0 = 0.04;
        assert!((albedo(&smooth, 1.0, 1.5) - f0).abs() < 2e-3, "{}", albedo(&smooth, 1.0, 1.5));
        assert!(albedo(&smooth, 0.1, 1.5) > 0.3, "{}", albedo(&smooth, 0.1, 1.5));
        let rough = Microfacet::smith::<false>(0.6, 0.6);
        assert!(albedo(&rough, 0.1, 1.5) < albedo(&smooth, 0.1, 1.5));
    }
}
