//! Microfacet normal distributions `D` and shadowing `G` (course §"Physically based models").
//!
//! * Beckmann–Spizzichino: `D = exp(−tan²ϑ (c²/m_u² + s²/m_v²)) / (π m_u m_v cos⁴ϑ)`.
//! * Trowbridge–Reitz: `D = 1 / (π m_u m_v cos⁴ϑ (1 + tan²ϑ (c²/m_u² + s²/m_v²))²)`. **Seed
//!   typos**: the course prints the isotropic form as `m²/(π(1 + (m²−1)² cos⁴ϑ))` — the square
//!   belongs outside, `m²/(π(1 + (m²−1) cos²ϑ)²)` — and the anisotropic one with `sin²ϑ` where
//!   `tan²ϑ` is needed for `∫ D cos ϑ dω = 1` (both pinned by the normalisation test).
//! * Torrance–Sparrow Gaussian: `D = a·exp(−(ϑ/m)²)` on `[0, π/2)`, `a` found by quadrature so
//!   that `∫ D cos ϑ dω = 1` (the "rather troublesome" constant of the course).
//!
//! `G` is the course's V-groove term or Smith's separable `G₁(l) G₁(v)` (Walter et al. 2007).
//! Normals are sampled as seen from the viewer: Trowbridge–Reitz's visible normals
//! (`G₁(v) ⟨v,h⟩⁺ D(h) / ⟨v,n⟩`, Heitz 2018, "Sampling the GGX Distribution of Visible
//! Normals", as pbrt-v4 and Mitsuba 3 do: each sample's weight is at most `G₁(l)`; drawn by
//! Dupuy and Benyoub's spherical caps), the other
//! distributions with density `D(h) cos ϑ_h`.

use alhazen_math::elementary::{exp, ln};
use alhazen_math::{Vec2, Vec3};
use alhazen_scene::bsdf::{Distribution, Microfacets, Shadowing};
use std::f64::consts::PI;

/// A microfacet distribution ready for evaluation.
#[derive(Clone, Copy, Debug)]
pub struct Microfacet {
    /// `D`.
    pub distribution: Distribution,
    /// `m_u`.
    pub alpha_u: f64,
    /// `m_v`.
    pub alpha_v: f64,
    /// `G`.
    pub shadowing: Shadowing,
    /// The Gaussian's normalisation `a` (1 for the others).
    gaussian_a: f64,
}

/// `∫₀^{π/2} exp(−(ϑ/m)²) cos ϑ sin ϑ dϑ` by composite Simpson.
fn gaussian_integral(m: f64) -> f64 {
    let n = 256;
    let h = (PI / 2.0) / n as f64;
    let f = |t: f64| (-(t / m).powi(2)).exp() * t.cos() * t.sin();
    let inner: f64 = (1..n).map(|i| f(i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 }).sum();
    h / 3.0 * (f(0.0) + inner + f(PI / 2.0))
}

impl Microfacet {
    /// From the scene description.
    pub fn new(m: &Microfacets) -> Self {
        let gaussian_a = match m.distribution {
            Distribution::Gaussian => 1.0 / (2.0 * PI * gaussian_integral(m.alpha_u)),
            _ => 1.0,
        };
        Self {
            distribution: m.distribution,
            alpha_u: m.alpha_u,
            alpha_v: m.alpha_v,
            shadowing: m.shadowing,
            gaussian_a,
        }
    }

    /// `m_u² m_v² cos²ϑ + m_v² x² + m_u² y²` for the normal `h = (x, y, cos ϑ)`: the
    /// ellipse's stretch with no division. `tan²ϑ (c²/m_u² + s²/m_v²)` is `1/(m_u² m_v² cos²ϑ)`
    /// times its last two terms, and Trowbridge–Reitz's `cos⁴ϑ (1 + tan²ϑ(…))²` is its square
    /// over `m_u⁴ m_v⁴`.
    #[inline(always)]
    fn stretch(&self, h: Vec3) -> (f64, f64) {
        let (au2, av2) = (self.alpha_u * self.alpha_u, self.alpha_v * self.alpha_v);
        let across = h.x * h.x * av2 + h.y * h.y * au2;
        (au2 * av2 * (h.z * h.z), across)
    }

    /// A Trowbridge–Reitz (or, with `BECKMANN`, Beckmann) distribution with Smith's
    /// shadowing: the ones the path tracer's lanes evaluate (their kind known to the compiler,
    /// the matches below fold away; Beckmann's `exp` and `ln` are [`alhazen_math::elementary`]'s,
    /// which vectorise).
    #[inline(always)]
    pub fn smith<const BECKMANN: bool>(alpha_u: f64, alpha_v: f64) -> Self {
        let distribution = if BECKMANN { Distribution::Beckmann } else { Distribution::TrowbridgeReitz };
        Self { distribution, alpha_u, alpha_v, shadowing: Shadowing::Smith, gaussian_a: 1.0 }
    }

    /// `Some(BECKMANN)` for the distributions [`Self::smith`] makes.
    pub fn smith_kind(&self) -> Option<bool> {
        let beckmann = match self.distribution {
            Distribution::TrowbridgeReitz => false,
            Distribution::Beckmann => true,
            Distribution::Gaussian => return None,
        };
        (self.shadowing == Shadowing::Smith).then_some(beckmann)
    }

    /// `D(h)` for `h` in the upper hemisphere (0 below). Here and below, values are computed
    /// whole and then chosen, without early returns, so that the path tracer's lanes evaluate
    /// the same function for eight normals at once.
    #[inline(always)]
    pub fn d(&self, h: Vec3) -> f64 {
        // One division each (the vector unit's slowest operation, which the lanes run for
        // every evaluation): `e = tan²ϑ(…)` over the stretch, and the whole of `D`.
        let (along, across) = self.stretch(h);
        let area = self.alpha_u * self.alpha_v;
        let d = match self.distribution {
            Distribution::Beckmann => {
                let cos4 = h.z.powi(4);
                exp(-(across / along)) / (PI * area * cos4)
            }
            // `(m_u m_v)³ / (π (m_u² m_v² cos²ϑ + m_v² x² + m_u² y²)²)`.
            Distribution::TrowbridgeReitz => area * area * area / (PI * (along + across).powi(2)),
            Distribution::Gaussian => {
                let theta = h.z.min(1.0).acos();
                self.gaussian_a * (-(theta / self.alpha_u).powi(2)).exp()
            }
        };
        if h.z > 0.0 && d.is_finite() { d } else { 0.0 }
    }

    /// A normal `h` with density `D(h) cos ϑ_h`; `None` only on rejection failure.
    #[inline(always)]
    pub fn sample_h(&self, u: Vec2) -> Option<Vec3> {
        if self.distribution == Distribution::Gaussian {
            return self.sample_gaussian_h(u);
        }
        // The azimuth of an elliptically stretched uniform direction: (m_u cos φ₀, m_v sin φ₀)
        // has the azimuth φ, and its squared length r² is 1/(cos²φ/m_u² + sin²φ/m_v²), the
        // factor tan²ϑ takes — no inverse trigonometry needed.
        let (s0, c0) = alhazen_math::sin_cos_turns(u.y);
        let (x, y) = (self.alpha_u * c0, self.alpha_v * s0);
        let r2 = x * x + y * y;
        let r = r2.sqrt();
        let (cos_phi, sin_phi) = if r > 0.0 { (x / r, y / r) } else { (1.0, 0.0) };
        let u0 = u.x.min(1.0 - 1e-16);
        let tan2 = match self.distribution {
            Distribution::Beckmann => -ln(1.0 - u0) * r2,
            _ => u0 / (1.0 - u0) * r2,
        };
        let ct = 1.0 / (1.0 + tan2).sqrt();
        let st = (tan2 / (1.0 + tan2)).sqrt();
        Some(Vec3::new(st * cos_phi, st * sin_phi, ct))
    }

    /// [`Self::sample_h`] for the Gaussian (out of line: a rejection loop).
    #[inline(never)]
    fn sample_gaussian_h(&self, u: Vec2) -> Option<Vec3> {
        let (theta, phi) = (self.sample_gaussian_theta(u.x)?, 2.0 * PI * u.y);
        let (st, ct) = theta.sin_cos();
        Some(Vec3::new(st * phi.cos(), st * phi.sin(), ct))
    }

    /// ϑ with density ∝ `exp(−(ϑ/m)²) cos ϑ sin ϑ` by rejection from the Rayleigh density
    /// `ϑ exp(−(ϑ/m)²)` (acceptance `cos ϑ sin ϑ / ϑ ≤ 1`); the extra numbers come from a hash
    /// of `u`, so the result stays a function of `u`.
    fn sample_gaussian_theta(&self, u: f64) -> Option<f64> {
        let mut rng = crate::sampler::Rng::for_sample(u.to_bits(), 0x6a, 0x75, 0x73);
        let mut x = u;
        for _ in 0..256 {
            let theta = self.alpha_u * (-(1.0 - x.min(1.0 - 1e-16)).ln()).sqrt();
            if theta < PI / 2.0 && rng.uniform() * theta <= theta.cos() * theta.sin() {
                return Some(theta);
            }
            x = rng.uniform();
        }
        None
    }

    /// A normal for reflecting or refracting `v` (either side: the normal is in the upper
    /// hemisphere, as seen from `v` mirrored to `+z`): visible normals for Trowbridge–Reitz,
    /// [`Self::sample_h`] otherwise. Density [`Self::pdf_h_from`].
    #[inline(always)]
    pub fn sample_h_from(&self, v: Vec3, u: Vec2) -> Option<Vec3> {
        if self.distribution != Distribution::TrowbridgeReitz {
            return self.sample_h(u);
        }
        let v = v * v.z.signum();
        // In the stretched configuration, where the distribution is the unit hemisphere's, the
        // visible normals are `v` plus a uniform point of the unit sphere's cap `z ≥ −v_z`
        // (Dupuy and Benyoub 2023, "Sampling Visible GGX Normals with Spherical Caps": the
        // density of Heitz 2018 in fewer operations). Nothing where `v` is at the horizon.
        let vs = Vec3::new(self.alpha_u * v.x, self.alpha_v * v.y, v.z).normalize_or_zero();
        let z = (1.0 - u.x) * (1.0 + vs.z) - vs.z;
        let r = (1.0 - z * z).max(0.0).sqrt();
        let (sin, cos) = alhazen_math::sin_cos_turns(u.y);
        let n = Vec3::new(r * cos, r * sin, z) + vs;
        let h = Vec3::new(self.alpha_u * n.x, self.alpha_v * n.y, n.z.max(0.0)).normalize_or_zero();
        (vs.z > 0.0 && h.z > 0.0).then_some(h)
    }

    /// Density of [`Self::sample_h_from`] choosing `h` (upper hemisphere) for `v`, where
    /// `d = D(h)`.
    #[inline(always)]
    pub fn pdf_h_from(&self, v: Vec3, h: Vec3, d: f64) -> f64 {
        if self.distribution != Distribution::TrowbridgeReitz {
            return d * h.z.max(0.0);
        }
        let v = v * v.z.signum();
        let vh = v.dot(h);
        let pdf = d * vh / (v.z * (1.0 + self.lambda(v)));
        if vh <= 0.0 || v.z <= 0.0 { 0.0 } else { pdf }
    }

    /// Density of [`Self::sample_h`].
    pub fn pdf_h(&self, h: Vec3) -> f64 {
        self.d(h) * h.z.max(0.0)
    }

    /// Smith's `Λ(w)` (Beckmann by Walter's rational fit, Trowbridge–Reitz exactly), of
    /// `α² tan²ϑ = (x² m_u² + y² m_v²)/cos²ϑ` (the projected roughness `α²` has `sin²ϑ` below,
    /// `tan²ϑ` above: they cancel).
    #[inline(always)]
    fn lambda(&self, w: Vec3) -> f64 {
        let sin2 = (1.0 - w.z * w.z).max(0.0);
        let spread = w.x * w.x * self.alpha_u * self.alpha_u + w.y * w.y * self.alpha_v * self.alpha_v;
        let lambda = match self.distribution {
            Distribution::Beckmann => {
                // `a = 1/(α tanϑ)`.
                let a = ((w.z * w.z) / spread).sqrt();
                if a >= 1.6 { 0.0 } else { (1.0 - 1.259 * a + 0.396 * a * a) / (3.535 * a + 2.181 * a * a) }
            }
            _ => ((1.0 + spread / (w.z * w.z)).sqrt() - 1.0) / 2.0,
        };
        if sin2 == 0.0 { 0.0 } else { lambda }
    }

    /// `1 + Λ(w)`, or ∞ where `w` sees the back of the facet `h` (Smith's `G₁(w)` is its
    /// reciprocal).
    #[inline(always)]
    fn g1_denominator(&self, w: Vec3, h: Vec3) -> f64 {
        let denominator = 1.0 + self.lambda(w);
        if w.dot(h) * w.z <= 0.0 { f64::INFINITY } else { denominator }
    }

    /// `G(l, v)` for the microfacet normal `h`.
    #[inline(always)]
    pub fn g(&self, v: Vec3, l: Vec3, h: Vec3) -> f64 {
        match self.shadowing {
            // `G₁(v) G₁(l)` in one division.
            Shadowing::Smith => 1.0 / (self.g1_denominator(v, h) * self.g1_denominator(l, h)),
            Shadowing::CookTorrance => {
                let (hn, vn, ln) = (h.z, v.z.abs(), l.z.abs());
                let (vh, lh) = (v.dot(h).abs(), l.dot(h).abs());
                if vh == 0.0 || lh == 0.0 {
                    return 0.0;
                }
                (2.0 * hn * vn / vh).min(2.0 * hn * ln / lh).min(1.0)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn facets(distribution: Distribution, au: f64, av: f64) -> Microfacet {
        Microfacet::new(&Microfacets { distribution, alpha_u: au, alpha_v: av, shadowing: Shadowing::Smith })
    }

    /// `∫ f(h) dω` over the upper hemisphere by a midpoint rule in (cos ϑ, φ), `nt` steps in
    /// cos ϑ and 256 in φ.
    fn over_hemisphere(nt: usize, f: impl Fn(Vec3) -> f64) -> f64 {
        let np = 256;
        let mut sum = 0.0;
        for i in 0..nt {
            let z = (i as f64 + 0.5) / nt as f64;
            let r = (1.0 - z * z).sqrt();
            for j in 0..np {
                let phi = 2.0 * PI * (j as f64 + 0.5) / np as f64;
                sum += f(Vec3::new(r * phi.cos(), r * phi.sin(), z));
            }
        }
        sum * (1.0 / nt as f64) * (2.0 * PI / np as f64)
    }

    /// `∫ D(h) cos ϑ dω` over the hemisphere.
    fn projected_area(m: &Microfacet) -> f64 {
        over_hemisphere(4000, |h| m.d(h) * h.z)
    }

    /// The visible normals' density `G₁(v) ⟨v,h⟩⁺ D(h) / ⟨v,n⟩` integrates to one over the
    /// hemisphere for every view (it needs Smith's exact Λ), and its samples are all visible.
    #[test]
    fn visible_normals_have_unit_density_and_face_the_viewer() {
        let m = facets(Distribution::TrowbridgeReitz, 0.15, 0.5);
        for (theta, phi) in [(0.1f64, 0.3f64), (1.0, 2.0), (1.45, -0.7), (2.2, 1.0)] {
            let v = Vec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos());
            let total = over_hemisphere(3000, |h| m.pdf_h_from(v, h, m.d(h)));
            assert!((total - 1.0).abs() < 5e-3, "θ = {theta}: {total}");
            for k in 0..64 {
                let u = Vec2::new((k % 8) as f64 / 8.0 + 0.03, (k / 8) as f64 / 8.0 + 0.05);
                let h = m.sample_h_from(v, u).unwrap();
                assert!(h.z > 0.0 && h.dot(v) * v.z > 0.0, "{h} for {v}");
            }
        }
    }

    #[test]
    fn every_distribution_has_unit_projected_area() {
        for d in [Distribution::Beckmann, Distribution::TrowbridgeReitz] {
            for (au, av) in [(0.1, 0.1), (0.3, 0.3), (0.7, 0.7), (0.2, 0.5)] {
                let a = projected_area(&facets(d, au, av));
                assert!((a - 1.0).abs() < 5e-3, "{d:?} {au} {av}: {a}");
            }
        }
        for m in [0.1, 0.3, 0.8] {
            let a = projected_area(&facets(Distribution::Gaussian, m, m));
            assert!((a - 1.0).abs() < 5e-3, "gaussian {m}: {a}");
        }
    }

    #[test]
    fn the_course_printed_trowbridge_reitz_is_not_normalised() {
        // m²/(π(1 + (m²−1)² cos⁴ϑ)) as printed: its projected area is not 1.
        let m: f64 = 0.3;
        let (nt, mut sum) = (20000, 0.0);
        for i in 0..nt {
            let z = (i as f64 + 0.5) / nt as f64;
            sum += m * m / (PI * (1.0 + (m * m - 1.0).powi(2) * z.powi(4))) * z;
        }
        let printed = sum / nt as f64 * 2.0 * PI;
        assert!((printed - 1.0).abs() > 0.1, "{printed}");
        // And the corrected isotropic form equals our D.
        let f = facets(Distribution::TrowbridgeReitz, m, m);
        let h = Vec3::new(0.3, 0.1, 1.0).normalize();
        let corrected = m * m / (PI * (1.0 + (m * m - 1.0) * h.z * h.z).powi(2));
        assert!((f.d(h) - corrected).abs() < 1e-12 * corrected);
    }
}
