//! Light that bounces between microfacets before it leaves (Kulla and Conty 2017, "Revisiting
//! Physically Based Shading at Imageworks"): a single-scattering microfacet lobe loses the
//! energy `1 − E(μ)` of the paths that meet a second facet, up to half of it on rough metals.
//! An added lobe
//!
//! `f_ms(v, l) = F_ms (1 − E(μ_v)) (1 − E(μ_l)) / (π (1 − E_avg))`,
//! `F_ms = F_avg² E_avg / (1 − F_avg (1 − E_avg))`
//!
//! gives it back: with `F = 1` the sum reflects all the light at every angle (a white furnace
//! test), with a coloured `F` the bounces saturate the colour, as Cycles' multiple-scattering
//! GGX (Heitz et al. 2016's random walk, Blender's default) does on average. `E(μ, α)`, the
//! single-scattering albedo of Trowbridge–Reitz facets with Smith shadowing and `F = 1`, and
//! its cosine-weighted mean `E_avg(α)` are tabulated once per process.

use super::microfacet::Microfacet;
use alhazen_math::{Vec2, Vec3};
use std::f64::consts::PI;
use std::sync::OnceLock;

/// Table size along `μ = cos ϑ` and along `r = √α`.
const N: usize = 32;
/// Stratified directions per table cell (`STRATA²`).
const STRATA: usize = 16;

/// `E(μ, α)` on the grid `μ_j = j/(N−1)` (columns), `r_i = i/(N−1)` (rows, `α = r²`): the
/// values `single_scattering_albedo` gives (test `the_albedo_table_is_the_computed_one`),
/// written out so that a lookup reads a fixed address — the lanes' loops gather from it
/// without first asking whether a table has been made.
static ALBEDO: [[f64; N]; N] = include!("multiscatter_albedo.rs");

/// `E_avg` per `r_i`: `2 ∫ E(μ) μ dμ` by the trapezoid rule on the grid.
fn averages() -> &'static [f64; N] {
    static AVERAGES: OnceLock<[f64; N]> = OnceLock::new();
    AVERAGES.get_or_init(|| {
        std::array::from_fn(|i| {
            let h = 1.0 / (N - 1) as f64;
            let f = |j: usize| ALBEDO[i][j] * (j as f64 * h);
            2.0 * h * ((1..N - 1).map(f).sum::<f64>() + 0.5 * (f(0) + f(N - 1)))
        })
    })
}

#[cfg(test)]
/// The `α` of table row `i` (at least the facets' least, 10⁻³).
fn alpha_at(i: usize) -> f64 {
    let r = i as f64 / (N - 1) as f64;
    (r * r).max(1e-3)
}

/// `∫ D G / (4 μ_v μ_l) μ_l dω_l` for `F = 1` at `μ_v = mu`.
#[cfg(test)]
fn single_scattering_albedo(mu: f64, alpha: f64) -> f64 {
    stratified_albedo(&Microfacet::smith::<false>(alpha, alpha), mu, |_| 1.0)
}

/// `∫ D G F / (4 μ_v μ_l) μ_l dω_l` at `μ_v = mu`, `F` of the cosine between facet and light
/// given by `fresnel`, by the facets' visible-normal sampling over a stratified grid (a fixed
/// set of numbers: a table of it is the same every run).
pub(super) fn stratified_albedo(facets: &Microfacet, mu: f64, fresnel: impl Fn(f64) -> f64) -> f64 {
    let mu = mu.max(1e-3);
    let v = Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
    let mut sum = 0.0;
    for a in 0..STRATA {
        for b in 0..STRATA {
            let u = Vec2::new((a as f64 + 0.5) / STRATA as f64, (b as f64 + 0.5) / STRATA as f64);
            let Some(h) = facets.sample_h_from(v, u) else { continue };
            let l = 2.0 * v.dot(h) * h - v;
            if l.z <= 0.0 {
                continue;
            }
            let d = facets.d(h);
            let pdf = facets.pdf_h_from(v, h, d) / (4.0 * h.dot(v));
            if pdf > 0.0 {
                sum += d * facets.g(v, l, h) * fresnel(h.dot(l)) / (4.0 * v.z * l.z) * l.z / pdf;
            }
        }
    }
    (sum / (STRATA * STRATA) as f64).clamp(0.0, 1.0)
}

/// Bilinear lookup of the table at `(mu, alpha)`.
#[cfg(test)]
fn lookup(mu: f64, alpha: f64) -> f64 {
    lookup_in(mu, Row::at(alpha))
}

/// Where a roughness falls between the table's rows: the lower row and the weight of the next.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Row {
    i: usize,
    fy: f64,
}

impl Row {
    pub(crate) fn at(alpha: f64) -> Row {
        let y = alpha.max(0.0).sqrt().min(1.0) * (N - 1) as f64;
        let i = (y as usize).min(N - 2);
        Row { i, fy: y - i as f64 }
    }
}

/// Bilinear lookup of the table at `mu` between the rows of `row`.
#[inline(always)]
pub(crate) fn lookup_in(mu: f64, Row { i, fy }: Row) -> f64 {
    let x = mu.clamp(0.0, 1.0) * (N - 1) as f64;
    let j = (x as usize).min(N - 2);
    let fx = x - j as f64;
    // (A row's index is at most N − 2 already: said again, so that no bound is checked.)
    let i = i.min(N - 2);
    let row = |i: usize| ALBEDO[i][j] * (1.0 - fx) + ALBEDO[i][j + 1] * fx;
    row(i) * (1.0 - fy) + row(i + 1) * fy
}

/// `E_avg` at `alpha`, interpolated.
fn average(alpha: f64) -> f64 {
    let t = averages();
    let y = alpha.max(0.0).sqrt().min(1.0) * (N - 1) as f64;
    let i = (y as usize).min(N - 2);
    let fy = y - i as f64;
    t[i] * (1.0 - fy) + t[i + 1] * fy
}

/// What the compensating lobe of a material keeps whatever the directions: where the facets'
/// roughness `alpha` (for two roughnesses, their geometric mean) falls in the table, `E_avg(α)`, and
/// `F_ms / (π (1 − E_avg))` for its Fresnel term's mean. Found once per material (or per
/// point of a textured one), not at every evaluation.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SeveralFacets {
    row: Row,
    e_avg: f64,
    scale: Vec3,
}

impl SeveralFacets {
    /// The lobe of facets of roughness `alpha` under a Fresnel term of cosine-weighted mean
    /// `f_avg` ([`fresnel_average`]).
    pub(crate) fn new(alpha: f64, f_avg: Vec3) -> Self {
        let e_avg = average(alpha);
        let f_ms = f_avg * f_avg * e_avg / (Vec3::ONE - f_avg * (1.0 - e_avg));
        let scale = if e_avg < 1.0 { f_ms / (PI * (1.0 - e_avg)) } else { Vec3::ZERO };
        SeveralFacets { row: Row::at(alpha), e_avg, scale }
    }

    /// The lobe seen from `v` (local frame).
    #[inline(always)]
    pub(crate) fn seen_from(&self, v: Vec3) -> MultipleScattering {
        MultipleScattering { lost_v: 1.0 - lookup_in(v.z.abs(), self.row), lobe: *self }
    }
}

/// The compensating lobe seen from one direction.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct MultipleScattering {
    /// `1 − E(μ_v)`: the energy the single-scattering lobe loses towards `v`.
    lost_v: f64,
    lobe: SeveralFacets,
}

impl MultipleScattering {
    /// `f_ms(v, l)` for `l` on `v`'s side.
    #[inline(always)]
    pub(crate) fn eval(&self, l: Vec3) -> Vec3 {
        self.lobe.scale * (self.lost_v * (1.0 - lookup_in(l.z.abs(), self.lobe.row)))
    }

    /// The probability of sampling this lobe rather than the single-scattering one, whose
    /// Fresnel term towards `v` is `f_v`: their albedos' shares (`F_ms (1 − E(μ_v))` against
    /// about `F(μ_v) E(μ_v)`, mean channels).
    #[inline(always)]
    pub(crate) fn choice(&self, f_v: Vec3) -> f64 {
        let multiple = (self.lobe.scale * (PI * (1.0 - self.lobe.e_avg) * self.lost_v)).element_sum() / 3.0;
        let single = f_v.element_sum() / 3.0 * (1.0 - self.lost_v);
        super::lobe_probability(multiple, single)
    }
}

/// `F_avg = 2 ∫ F(μ) μ dμ`, by 8-point Gauss–Legendre on [0, 1].
pub(crate) fn fresnel_average(fresnel: impl Fn(f64) -> Vec3) -> Vec3 {
    const NODES: [(f64, f64); 4] = [
        (0.183_434_642_495_649_8, 0.362_683_783_378_362),
        (0.525_532_409_916_329, 0.313_706_645_877_887_3),
        (0.796_666_477_413_626_7, 0.222_381_034_453_374_5),
        (0.960_289_856_497_536_3, 0.101_228_536_290_376_3),
    ];
    NODES.iter().fold(Vec3::ZERO, |s, &(x, w)| {
        let (a, b) = (0.5 * (1.0 - x), 0.5 * (1.0 + x));
        s + (fresnel(a) * a + fresnel(b) * b) * (w * 0.5)
    }) * 2.0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The written-out table is what the albedo's quadrature gives (to 10⁻¹²: another C
    /// library's square roots or sines could move a last bit).
    #[test]
    fn the_albedo_table_is_the_computed_one() {
        for (i, row) in ALBEDO.iter().enumerate() {
            for (j, &e) in row.iter().enumerate() {
                let computed = single_scattering_albedo(j as f64 / (N - 1) as f64, alpha_at(i));
                assert!((e - computed).abs() <= 1e-12, "row {i}, column {j}: {e} written, {computed} computed");
            }
        }
    }

    /// The single-scattering albedo falls with roughness; smooth facets lose nothing.
    #[test]
    fn single_scattering_loses_energy_with_roughness() {
        assert!((lookup(0.8, 1e-3) - 1.0).abs() < 0.01, "{}", lookup(0.8, 1e-3));
        assert!(lookup(0.8, 0.25) > lookup(0.8, 0.5) && lookup(0.8, 0.5) > lookup(0.8, 1.0));
        assert!(average(0.1) > 0.95 && average(0.5) < average(0.1));
        // Schlick's term averages to F0 + (1 − F0)/21.
        let f0 = 0.3;
        let avg = fresnel_average(|c| Vec3::splat(f0 + (1.0 - f0) * (1.0 - c).powi(5)));
        assert!((avg.x - (f0 + (1.0 - f0) / 21.0)).abs() < 1e-9, "{avg}");
        // Up to about 60 % lost on the roughest facets (Kulla and Conty's figure 3).
        assert!((0.3..0.6).contains(&average(1.0)), "{}", average(1.0));
    }
}
