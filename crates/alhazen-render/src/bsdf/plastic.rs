//! Plastic: a diffuse base under a clear dielectric coat, the model of Mitsuba 3's `plastic`
//! and `roughplastic` (after Weidlich and Wilkie 2007, "Arbitrarily layered micro-facet
//! surfaces"). Light either reflects off the coat — a mirror weighted by Fresnel's `F`, or the
//! Cook–Torrance microfacet lobe `D G F / (4⟨l,n⟩⟨v,n⟩)` of the course when rough — or enters,
//! scatters diffusely off the base and bounces between base and coat until it leaves; the
//! bounces sum to a geometric series:
//!
//! `ρ_d(l, v) = albedo / (1 − R_in) · t(v) t(l) / (π η²)`,
//!
//! `t(μ)` the coat's transmittance at incidence cosine `μ` (`1 − F(μ)` when smooth; for a rough
//! coat the microfacet transmission lobe's albedo, found by quadrature), `R_in`
//! the coat's reflectance seen from inside averaged over the cosine-weighted hemisphere (the
//! base's light comes back diffusely), `1/η²` the radiance's dilution across the interface.
//! With `nonlinear`, `R_in` is weighted by the albedo (`albedo / (1 − albedo·R_in)`).
//! Sampling picks the coat or the base by their shares of the light, as Mitsuba does.
//!
//! `R_in = 2∫₀¹ R(μ) μ dμ` is integrated by Gauss–Legendre quadrature. Mitsuba's
//! `roughplastic` takes it as the plain mean of `2 R(μ) μ` over its 64 table cosines
//! `0, 1/63, …, 1`, which for η = 1.49 gives 0.579 where the integral is 0.590: its diffuse
//! term is 2.7 % darker than the model's, and rough plastics here render 0.5–1.4 % brighter
//! than Mitsuba's (its `plastic` uses a fit within 0.1 % of the integral; BENCHMARKS.md).
//!
//! `t(μ)` is kept as its interpolating polynomial at [`TERMS`] Chebyshev nodes of `[0, 1]`
//! (Trefethen, "Approximation Theory and Approximation Practice", ch. 3–8: for a function
//! analytic on the interval the error falls geometrically with the degree), in monomial form
//! in `x = 2μ − 1` and evaluated by Estrin's scheme (two operations a term in five rounds of
//! independent ones; the coefficients' rounding moves the values on `[−1, 1]` by less than
//! 1e-9): within 2e-5 of `1 − F` for
//! indices 1.05–2.4, where linear interpolation in a 64-entry table erred by 1e-3–5e-3, and as
//! close to the rough quadrature as such a table or closer (`tests`). It is also arithmetic
//! alone: the path tracer's plastic kernels have no table to read per lane — a gather, which
//! kept them scalar on AVX2 processors.

use super::microfacet::Microfacet;
use super::{
    BsdfSample, MicrofacetLobes, cosine_hemisphere, cosine_pdf, lobe_probability, reflect, refract, same_side,
};
use crate::optics::fresnel_dielectric;
use alhazen_math::{Vec2, Vec3};
use std::cell::RefCell;
use std::f64::consts::FRAC_1_PI;
use std::sync::Mutex;

/// Coefficients of the transmittance's polynomial (its degree plus one; `Coat::transmittance`
/// pairs them in rounds written for 24).
const TERMS: usize = 24;
/// Gauss–Legendre nodes per dimension of the quadratures over microfacet normals.
const NODES: usize = 48;

/// A coat's transmittance and inner reflectance.
#[derive(Debug, PartialEq)]
pub struct Coat {
    /// `t(μ)`'s polynomial in `x = 2μ − 1`, constant term first.
    transmittance: [f64; TERMS],
    inner_reflectance: f64,
}

/// Plastic at one surface point.
#[derive(Clone, Copy, Debug)]
pub struct Plastic {
    /// The base's albedo.
    pub albedo: Vec3,
    /// The coat's index relative to the outside.
    pub eta: f64,
    /// The coat's microfacets, or a smooth coat.
    pub facets: Option<Microfacet>,
    /// Albedo-weighted inner bounces.
    pub nonlinear: bool,
    /// The coat's transmittance and inner reflectance.
    pub coat: &'static Coat,
}

impl Plastic {
    /// Plastic of `albedo` under a coat of index `eta` and roughness `facets`.
    pub fn new(albedo: Vec3, eta: f64, facets: Option<Microfacet>, nonlinear: bool) -> Self {
        Self { albedo, eta, facets, nonlinear, coat: Coat::of(eta, facets.as_ref()) }
    }

    /// `t(μ)`.
    #[inline(always)]
    fn transmittance(&self, mu: f64) -> f64 {
        self.coat.transmittance(mu)
    }

    /// The probability of sampling the coat rather than the base, seen from `v`: their shares
    /// of the light (`1 − t(v)` and `t(v)`), weighted by the coat's (white) and the base's mean
    /// colours.
    #[inline(always)]
    fn p_coat(&self, v: Vec3) -> f64 {
        let t = self.transmittance(v.z);
        // Both shares over `1 + base`, which the ratio cancels.
        let base = (self.albedo.x + self.albedo.y + self.albedo.z) * (1.0 / 3.0);
        lobe_probability(1.0 - t, t * base)
    }

    #[inline(always)]
    fn base(&self, v: Vec3, l: Vec3) -> Vec3 {
        let inner = if self.nonlinear {
            self.albedo * self.coat.inner_reflectance
        } else {
            Vec3::splat(self.coat.inner_reflectance)
        };
        let t = self.transmittance(v.z) * self.transmittance(l.z);
        self.albedo / (Vec3::ONE - inner) * (t * FRAC_1_PI / (self.eta * self.eta))
    }

    /// The rough coat's lobe `D G F / (4⟨l,n⟩⟨v,n⟩)` and its sampling density.
    #[inline(always)]
    fn coat_lobe(&self, facets: &Microfacet, v: Vec3, l: Vec3) -> (f64, f64) {
        // `half_vector`, computed whole and then chosen (for the path tracer's lanes).
        let h = (v + l).normalize_or_zero();
        let defined = h != Vec3::ZERO;
        let h = h * h.z.signum();
        let f = fresnel_dielectric(h.dot(v), self.eta);
        let value = facets.d(h) * facets.g(v, l, h) * f / (4.0 * l.z.abs() * v.z.abs());
        let pdf = facets.pdf_h_from(v, h, facets.d(h)) / (4.0 * h.dot(v).abs());
        if defined { (value, pdf) } else { (0.0, 0.0) }
    }

    /// `ρ(l, v)` (the smooth coat's mirror only through `sample`).
    pub fn eval(&self, v: Vec3, l: Vec3) -> Vec3 {
        if !same_side(v, l) {
            return Vec3::ZERO;
        }
        let coat = self.facets.map_or(0.0, |f| self.coat_lobe(&f, v, l).0);
        self.base(v, l) + Vec3::splat(coat)
    }

    /// The mixture of the coat's and the base's densities (the smooth coat's mirror excluded).
    pub fn pdf(&self, v: Vec3, l: Vec3) -> f64 {
        if !same_side(v, l) {
            return 0.0;
        }
        let p = self.p_coat(v);
        let coat = self.facets.map_or(0.0, |f| self.coat_lobe(&f, v, l).1);
        p * coat + (1.0 - p) * cosine_pdf(v, l)
    }

    /// [`Self::eval`] and [`Self::pdf`] with the coat's lobe evaluated once (the same numbers).
    pub fn eval_pdf(&self, v: Vec3, l: Vec3) -> (Vec3, f64) {
        match &self.facets {
            Some(facets) => self.rough_eval_pdf(facets, v, l),
            None => self.smooth_eval_pdf(v, l),
        }
    }

    /// [`Self::eval_pdf`] of the smooth coat (the base alone: the coat is a delta lobe),
    /// computed whole and then chosen.
    #[inline(always)]
    pub(crate) fn smooth_eval_pdf(&self, v: Vec3, l: Vec3) -> (Vec3, f64) {
        let p = self.p_coat(v);
        let value = (self.base(v, l) + Vec3::splat(0.0), p * 0.0 + (1.0 - p) * cosine_pdf(v, l));
        if same_side(v, l) { value } else { (Vec3::ZERO, 0.0) }
    }

    /// The coat or the base by `uc`, then a direction from it.
    pub fn sample(&self, v: Vec3, uc: f64, u: Vec2) -> Option<BsdfSample> {
        if let Some(facets) = &self.facets {
            let (sampled, sample) = self.rough_sample(facets, v, uc, u);
            return sampled.then_some(sample);
        }
        let (sampled, sample) = self.smooth_sample(v, uc, u);
        sampled.then_some(sample)
    }

    /// [`Self::sample`] with the smooth coat: its mirror (weight `F`, chosen with probability
    /// `p`), or the base. Whether there is a sample and the sample, computed whole and then
    /// chosen, for the lanes as for [`Self::sample`].
    #[inline(always)]
    pub(crate) fn smooth_sample(&self, v: Vec3, uc: f64, u: Vec2) -> (bool, BsdfSample) {
        let p = self.p_coat(v);
        let mirrored = Vec3::new(-v.x, -v.y, v.z);
        let f_mirror = Vec3::splat(fresnel_dielectric(v.z, self.eta) / mirrored.z.abs());
        let l = cosine_hemisphere(u, v);
        let (f, pdf) = self.smooth_eval_pdf(v, l);
        if uc < p {
            (true, BsdfSample { l: mirrored, f: f_mirror, pdf: p, delta: true, eta: 1.0, dispersive: false })
        } else {
            (pdf > 0.0, BsdfSample { l, f, pdf, delta: false, eta: 1.0, dispersive: false })
        }
    }

    /// True for a smooth coat (a mirror lobe).
    pub fn has_mirror(&self) -> bool {
        self.facets.is_none()
    }
}

impl MicrofacetLobes for Plastic {
    /// [`Self::eval_pdf`] of the rough coat of `facets` (this plastic's), computed whole and
    /// then chosen, for the path tracer's lanes as much as for [`Self::eval_pdf`].
    #[inline(always)]
    fn rough_eval_pdf(&self, facets: &Microfacet, v: Vec3, l: Vec3) -> (Vec3, f64) {
        let (coat, coat_pdf) = self.coat_lobe(facets, v, l);
        let p = self.p_coat(v);
        let value = (self.base(v, l) + Vec3::splat(coat), p * coat_pdf + (1.0 - p) * cosine_pdf(v, l));
        if same_side(v, l) { value } else { (Vec3::ZERO, 0.0) }
    }

    /// [`Self::sample`] with the rough coat of `facets` (this plastic's): whether there is a
    /// sample (a facet where the coat is chosen, a positive density) and the sample. Computed
    /// whole and then chosen, for the lanes as for [`Self::sample`].
    #[inline(always)]
    fn rough_sample(&self, facets: &Microfacet, v: Vec3, uc: f64, u: Vec2) -> (bool, BsdfSample) {
        let coat = uc < self.p_coat(v);
        let h = facets.sample_h_from(v, u);
        let mirrored = reflect(v, h.unwrap_or(Vec3::Z) * v.z.signum());
        let l = if coat { mirrored } else { cosine_hemisphere(u, v) };
        let (f, pdf) = self.rough_eval_pdf(facets, v, l);
        ((!coat || h.is_some()) && pdf > 0.0, BsdfSample { l, f, pdf, delta: false, eta: 1.0, dispersive: false })
    }
}

/// A coat's identity for the cache: index, and distribution, roughness and shadowing.
type CoatKey = (u64, Option<(u8, u64, u8)>);

fn key(eta: f64, facets: Option<&Microfacet>) -> CoatKey {
    (eta.to_bits(), facets.map(|f| (f.distribution as u8, f.alpha_u.to_bits(), f.shadowing as u8)))
}

/// Every coat computed in this process: a few per scene, kept for the process's life so a
/// surface point's BSDF can point at its numbers without counting references.
static COATS: Mutex<Vec<(CoatKey, &'static Coat)>> = Mutex::new(vec![]);

thread_local! {
    /// This thread's view of [`COATS`]: textured plastic builds its BSDF at every hit, and the
    /// lookup should not take a lock.
    static SEEN: RefCell<Vec<(CoatKey, &'static Coat)>> = const { RefCell::new(vec![]) };
}

impl Coat {
    /// A coat of no transmittance, where a coat is needed before one is known (the path
    /// tracer's lanes without plastic).
    pub(crate) const NONE: Coat = Coat { transmittance: [0.0; TERMS], inner_reflectance: 0.0 };

    /// `t(μ)` (of `|μ|`, at most 1) by Estrin's scheme, within `[0, 1]`: the terms paired,
    /// `a_{2k} + a_{2k+1}·x`, then the pairs paired with `x²`, and so on — five rounds of
    /// independent operations where Horner's rule is one chain of 23 (a lane's several
    /// evaluations wait on its latency).
    #[inline(always)]
    fn transmittance(&self, mu: f64) -> f64 {
        let x = 2.0 * mu.abs().min(1.0) - 1.0;
        let t = &self.transmittance;
        let pairs: [f64; TERMS / 2] = std::array::from_fn(|k| t[2 * k] + t[2 * k + 1] * x);
        let x2 = x * x;
        let quads: [f64; TERMS / 4] = std::array::from_fn(|k| pairs[2 * k] + pairs[2 * k + 1] * x2);
        let x4 = x2 * x2;
        let [q0, q1, q2, q3, q4, q5] = quads;
        let (o0, o1, o2) = (q0 + q1 * x4, q2 + q3 * x4, q4 + q5 * x4);
        let x8 = x4 * x4;
        let sum = (o0 + o1 * x8) + o2 * (x8 * x8);
        sum.clamp(0.0, 1.0)
    }

    /// The numbers of a coat of index `eta` and roughness `facets`, computed once per process.
    pub fn of(eta: f64, facets: Option<&Microfacet>) -> &'static Coat {
        let k = key(eta, facets);
        if let Some(c) = SEEN.with_borrow(|seen| seen.iter().find(|e| e.0 == k).map(|e| e.1)) {
            return c;
        }
        let coat = {
            let mut all = COATS.lock().unwrap_or_else(|e| e.into_inner());
            match all.iter().find(|e| e.0 == k) {
                Some(e) => e.1,
                None => {
                    let c: &'static Coat = Box::leak(Box::new(Coat::compute(eta, facets)));
                    all.push((k, c));
                    c
                }
            }
        };
        SEEN.with_borrow_mut(|seen| seen.push((k, coat)));
        coat
    }

    /// The coat's numbers, the transmittance at each node computed in parallel (each on its
    /// own, so the same bits on any number of threads; every sum is taken in order).
    fn compute(eta: f64, facets: Option<&Microfacet>) -> Coat {
        use rayon::prelude::*;
        let mut at_nodes = [0.0; TERMS];
        at_nodes.par_iter_mut().enumerate().for_each(|(k, t)| {
            let mu = ((chebyshev_node(k) + 1.0) / 2.0).max(1e-6);
            *t = match facets {
                None => 1.0 - fresnel_dielectric(mu, eta),
                Some(f) => rough_transmittance(f, mu, eta),
            };
        });
        let transmittance = monomial(&chebyshev_coefficients(&at_nodes));
        // R_in = 2 ∫₀¹ R(μ) μ dμ, R the reflectance from inside (index 1/η).
        let terms: Vec<f64> = RULE
            .par_iter()
            .map(|&(mu, w)| {
                let r = match facets {
                    None => fresnel_dielectric(mu, 1.0 / eta),
                    Some(f) => rough_reflectance(f, mu, 1.0 / eta),
                };
                2.0 * w * r * mu
            })
            .collect();
        let inner_reflectance = terms.iter().sum();
        Coat { transmittance, inner_reflectance }
    }
}

/// Node `k` of the [`TERMS`] Chebyshev nodes of `[−1, 1]`: `cos(π(k + ½)/n)`.
fn chebyshev_node(k: usize) -> f64 {
    (std::f64::consts::PI * (k as f64 + 0.5) / TERMS as f64).cos()
}

/// The Chebyshev coefficients `c_j` of the polynomial taking `values[k]` at node `k`
/// (the discrete cosine transform: `c_j = (2/n) Σ_k values[k] cos(πj(k + ½)/n)`, `c_0` halved).
fn chebyshev_coefficients(values: &[f64; TERMS]) -> [f64; TERMS] {
    let n = TERMS as f64;
    std::array::from_fn(|j| {
        let sum: f64 =
            (0..TERMS).map(|k| values[k] * (std::f64::consts::PI * j as f64 * (k as f64 + 0.5) / n).cos()).sum();
        if j == 0 { sum / n } else { 2.0 * sum / n }
    })
}

/// `Σ c_j T_j(x)` as a polynomial in `x`, constant term first (`T_{j+1} = 2x T_j − T_{j−1}`).
fn monomial(c: &[f64; TERMS]) -> [f64; TERMS] {
    let (mut previous, mut current) = ([0.0; TERMS], [0.0; TERMS]);
    (previous[0], current[1]) = (1.0, 1.0);
    let mut out = [0.0; TERMS];
    out[0] = c[0];
    for (k, &ck) in c.iter().enumerate().skip(1) {
        for (o, t) in out.iter_mut().zip(&current) {
            *o += ck * t;
        }
        if k + 1 < TERMS {
            let mut next = [0.0; TERMS];
            for m in 0..TERMS {
                let shifted = if m > 0 { 2.0 * current[m - 1] } else { 0.0 };
                next[m] = shifted - previous[m];
            }
            (previous, current) = (current, next);
        }
    }
    out
}

/// The incident direction at cosine `mu` in the `xz` plane.
fn incident(mu: f64) -> Vec3 {
    Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu)
}

/// The albedo of a rough interface's lobe seen from `v`: `∫ w(h) G(v, l, h) ⟨v,h⟩/(⟨v,n⟩⟨h,n⟩)`
/// over facet normals `h` drawn with density `D(h)⟨h,n⟩`, by Gauss–Legendre quadrature over
/// the sampler's unit square; `lobe(h)` gives the outgoing direction and the facet's weight.
fn lobe_albedo(f: &Microfacet, v: Vec3, lobe: impl Fn(Vec3) -> Option<(Vec3, f64)>) -> f64 {
    let nodes = &*RULE;
    let mut sum = 0.0;
    for &(x, wx) in nodes {
        for &(y, wy) in nodes {
            let Some(h) = f.sample_h(Vec2::new(x, y)) else { continue };
            let Some((l, weight)) = lobe(h) else { continue };
            let vh = v.dot(h);
            if vh <= 0.0 || h.z <= 0.0 {
                continue;
            }
            sum += wx * wy * weight * f.g(v, l, h) * vh / (v.z * h.z);
        }
    }
    sum
}

/// A rough coat's transmittance at incidence cosine `mu`: the light refracted into it.
fn rough_transmittance(f: &Microfacet, mu: f64, eta: f64) -> f64 {
    let v = incident(mu);
    lobe_albedo(f, v, |h| {
        let (l, _) = refract(v, h, eta)?;
        (l.z < 0.0).then(|| (l, 1.0 - fresnel_dielectric(v.dot(h), eta)))
    })
}

/// A rough interface's reflectance at incidence cosine `mu` for the relative index `eta`.
fn rough_reflectance(f: &Microfacet, mu: f64, eta: f64) -> f64 {
    let v = incident(mu);
    lobe_albedo(f, v, |h| {
        let l = reflect(v, h);
        (l.z > 0.0).then(|| (l, fresnel_dielectric(v.dot(h), eta)))
    })
}

/// The `NODES`-point Gauss–Legendre rule, computed once.
static RULE: std::sync::LazyLock<Vec<(f64, f64)>> = std::sync::LazyLock::new(|| gauss_legendre(NODES));

/// The `n`-point Gauss–Legendre rule on `[0, 1]`: nodes and weights (Newton's iteration on the
/// Legendre polynomial from Chebyshev's guesses).
fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 1.0;
            for _ in 0..100 {
                // P_n(x) and P_n'(x) by the three-term recurrence.
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    (p0, p1) = (p1, ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64);
                }
                dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let step = p1 / dp;
                x -= step;
                if step.abs() < 1e-15 {
                    break;
                }
            }
            let w = 2.0 / ((1.0 - x * x) * dp * dp);
            ((1.0 - x) / 2.0, w / 2.0)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use alhazen_scene::bsdf::{Distribution, Microfacets, Shadowing};

    fn ggx(alpha: f64) -> Microfacet {
        Microfacet::new(&Microfacets {
            distribution: Distribution::TrowbridgeReitz,
            alpha_u: alpha,
            alpha_v: alpha,
            shadowing: Shadowing::Smith,
        })
    }

    #[test]
    fn gauss_legendre_integrates_polynomials_exactly() {
        let rule = gauss_legendre(8);
        assert!((rule.iter().map(|e| e.1).sum::<f64>() - 1.0).abs() < 1e-14);
        // ∫₀¹ x^15 = 1/16: exact for degree ≤ 2n − 1.
        assert!((rule.iter().map(|&(x, w)| w * x.powi(15)).sum::<f64>() - 1.0 / 16.0).abs() < 1e-14);
    }

    /// A nearly smooth rough coat has the smooth coat's numbers; a rough one lets more light in
    /// at grazing angles (its facets face the light) and conserves energy.
    #[test]
    fn rough_coats_tend_to_the_smooth_one() {
        let smooth = Coat::compute(1.5, None);
        let nearly = Coat::compute(1.5, Some(&ggx(0.002)));
        for mu in [0.13, 0.5, 1.0] {
            assert!((smooth.transmittance(mu) - nearly.transmittance(mu)).abs() < 2e-3, "{mu}");
        }
        assert!((smooth.inner_reflectance - nearly.inner_reflectance).abs() < 5e-3);
        // The smooth inner reflectance from 1.5 is about 0.596 (the diffuse Fresnel
        // reflectance of an index-1/1.5 interface).
        assert!((smooth.inner_reflectance - 0.596).abs() < 2e-3, "{}", smooth.inner_reflectance);
        let rough = Coat::compute(1.5, Some(&ggx(0.3)));
        assert!((0..=100).all(|i| (0.0..=1.0).contains(&rough.transmittance(i as f64 / 100.0))));
        assert!(rough.transmittance(0.06) > smooth.transmittance(0.06));
    }

    /// The polynomial is `t(μ)` between its nodes: within 2e-5 of `1 − F` for smooth coats, and
    /// of the quadrature for rough ones (GGX and Beckmann, nearly smooth to very rough) within
    /// 1e-3 (6e-4 at worst, at grazing incidence on a nearly smooth coat, where a 64-entry
    /// table's linear interpolation erred by 2e-3; elsewhere 1e-4 and less, as the table).
    #[test]
    fn transmittance_polynomials_follow_the_coat() {
        let beckmann = |alpha: f64| {
            Microfacet::new(&Microfacets {
                distribution: Distribution::Beckmann,
                alpha_u: alpha,
                alpha_v: alpha,
                shadowing: Shadowing::Smith,
            })
        };
        for eta in [1.05, 1.3, 1.5, 2.4] {
            let smooth = Coat::compute(eta, None);
            for i in 0..=400 {
                let mu = (i as f64 / 400.0).max(1e-6);
                let exact = 1.0 - fresnel_dielectric(mu, eta);
                assert!((smooth.transmittance(mu) - exact).abs() < 2e-5, "η {eta} μ {mu}");
            }
        }
        for (eta, f) in [(1.5, ggx(0.01)), (1.5, ggx(0.3)), (1.3, ggx(1.0)), (2.4, beckmann(0.1)), (1.5, beckmann(0.5))]
        {
            let rough = Coat::compute(eta, Some(&f));
            for i in 0..=40 {
                let mu = (i as f64 / 40.0).max(1e-6);
                let exact = rough_transmittance(&f, mu, eta);
                assert!((rough.transmittance(mu) - exact).abs() < 1e-3, "η {eta} μ {mu}: {}", rough.transmittance(mu));
            }
        }
    }

    /// The Chebyshev coefficients and their monomial form reproduce a polynomial of the degree.
    #[test]
    fn chebyshev_interpolation_is_exact_on_polynomials() {
        let p = |x: f64| 0.3 - 1.2 * x + 0.5 * x.powi(3) + 0.01 * x.powi(TERMS as i32 - 1);
        let coat = Coat {
            transmittance: monomial(&chebyshev_coefficients(&std::array::from_fn(|k| p(chebyshev_node(k))))),
            inner_reflectance: 0.0,
        };
        for i in 0..=100 {
            let mu = i as f64 / 100.0;
            let want = p(2.0 * mu - 1.0).clamp(0.0, 1.0);
            assert!((coat.transmittance(mu) - want).abs() < 1e-9, "μ {mu}: {} vs {want}", coat.transmittance(mu));
        }
    }

    /// A white base under a smooth coat reflects everything that arrives (`ρ = 1`): the
    /// albedo at every angle is 1, by quadrature over the hemisphere plus the coat's mirror.
    #[test]
    fn white_plastic_conserves_energy() {
        for facets in [None, Some(ggx(0.05))] {
            let p = Plastic::new(Vec3::ONE, 1.5, facets, false);
            for mu in [0.3, 0.7, 1.0] {
                let v = incident(mu);
                let (n, mut sum) = (400, 0.0);
                for i in 0..n {
                    let z = (i as f64 + 0.5) / n as f64;
                    for j in 0..n {
                        let phi = 2.0 * std::f64::consts::PI * (j as f64 + 0.5) / n as f64;
                        let r = (1.0 - z * z).sqrt();
                        let l = Vec3::new(r * phi.cos(), r * phi.sin(), z);
                        sum += p.eval(v, l).x * z;
                    }
                }
                let mut albedo = sum * 2.0 * std::f64::consts::PI / (n * n) as f64;
                if facets.is_none() {
                    albedo += fresnel_dielectric(mu, 1.5);
                }
                // The base conserves energy exactly; the single-scattering rough coat loses a little.
                assert!(albedo <= 1.0 + 5e-3 && albedo > 0.93, "{facets:?} μ {mu}: {albedo}");
            }
        }
    }
}
