//! Image-based lighting for the preview (course, §"Integrating radiance in the Lambertian
//! model"): the irradiance `I(n) = ∫ L(l) ⟨l, n⟩ dS` of the environment, computed by the course's
//! quadrature (2) — `N` points spread evenly over the unit disk by the golden angle, lifted to the
//! hemisphere (which weights them by the cosine) and turned to `n` by a Householder reflection —
//! into an irradiance cube map, then approximated by the nine harmonic quadratic polynomials of
//! Ramamoorthi and Hanrahan with the course's basis `1, x, y, z, xy, yz, zx, x² − y²,
//! 2z² − x² − y²` and norms `‖p_i‖²` (texels weighted by their solid angle
//! `4/size² · (a² + b² + 1)^{−3/2}`).

use alhazen_math::Vec3;
use std::f64::consts::PI;

/// The golden angle `2πτ²`, `τ = (√5 − 1)/2` (the course's `DPHI`).
const GOLDEN_ANGLE: f64 = 2.399_963_229_728_653;

/// The course's quadrature (2) of the irradiance at normal `n` (unit): `π/N Σ L(l_i)`.
pub fn irradiance(radiance: &dyn Fn(Vec3) -> Vec3, n: Vec3, samples: usize) -> Vec3 {
    // Householder reflection taking e₃ to ∓n (then the sign is fixed), as in the course's shader.
    let sign = if n.z > 0.0 { 1.0 } else { -1.0 };
    let w = n + Vec3::Z * sign;
    let gamma = 2.0 / w.dot(w);
    let mut sum = Vec3::ZERO;
    for i in 0..samples {
        let r2 = (2 * i + 1) as f64 / (2 * samples) as f64;
        let (r, phi) = (r2.sqrt(), (i as f64 + 0.5) * GOLDEN_ANGLE);
        let l = Vec3::new(r * phi.cos(), r * phi.sin(), (1.0 - r2).sqrt());
        let l = l - w * (gamma * w.dot(l));
        sum += radiance(if n.z > 0.0 { -l } else { l });
    }
    sum * (PI / samples as f64)
}

/// The nine harmonic quadratic polynomials `p₀ … p₈` at `w`.
pub fn basis(w: Vec3) -> [f64; 9] {
    let (x, y, z) = (w.x, w.y, w.z);
    [1.0, x, y, z, x * y, y * z, z * x, x * x - y * y, 2.0 * z * z - x * x - y * y]
}

/// `‖p_i‖² = ∫_S p_i² dS` (the course's values).
pub const NORMS: [f64; 9] = [
    4.0 * PI,
    4.0 * PI / 3.0,
    4.0 * PI / 3.0,
    4.0 * PI / 3.0,
    4.0 * PI / 15.0,
    4.0 * PI / 15.0,
    4.0 * PI / 15.0,
    16.0 * PI / 15.0,
    16.0 * PI / 5.0,
];

/// The direction through texel `(i, j)` of face `face` (`±x, ±y, ±z`) of a `size²` cube map, and
/// the texel's solid angle.
fn texel(face: usize, i: usize, j: usize, size: usize) -> (Vec3, f64) {
    let a = 2.0 * (i as f64 + 0.5) / size as f64 - 1.0;
    let b = 2.0 * (j as f64 + 0.5) / size as f64 - 1.0;
    let s = a * a + b * b + 1.0;
    let weight = 4.0 / (size * size) as f64 / (s * s.sqrt());
    let w = match face {
        0 => Vec3::new(1.0, a, b),
        1 => Vec3::new(-1.0, a, b),
        2 => Vec3::new(a, 1.0, b),
        3 => Vec3::new(a, -1.0, b),
        4 => Vec3::new(a, b, 1.0),
        _ => Vec3::new(a, b, -1.0),
    };
    (w.normalize(), weight)
}

/// A function on the sphere as its projection on the nine polynomials (one coefficient vector
/// per colour channel).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sh9 {
    /// `a_i = (p_i, f) / ‖p_i‖²`.
    pub coefficients: [Vec3; 9],
}

impl Sh9 {
    /// Projects `f` sampled at the texel centres of a `size²` cube map.
    pub fn project(f: &dyn Fn(Vec3) -> Vec3, size: usize) -> Self {
        let mut c = [Vec3::ZERO; 9];
        for face in 0..6 {
            for j in 0..size {
                for i in 0..size {
                    let (w, weight) = texel(face, i, j, size);
                    let v = f(w) * weight;
                    for (k, p) in basis(w).iter().enumerate() {
                        c[k] += v * *p;
                    }
                }
            }
        }
        for (k, ck) in c.iter_mut().enumerate() {
            *ck /= NORMS[k];
        }
        Self { coefficients: c }
    }

    /// The irradiance of an environment given by its radiance: an irradiance cube map of
    /// `size²` texels a face by the quadrature with `samples` points, then projected.
    pub fn irradiance_of(radiance: &dyn Fn(Vec3) -> Vec3, size: usize, samples: usize) -> Self {
        Self::project(&|n| irradiance(radiance, n, samples), size)
    }

    /// The polynomial at `w`.
    pub fn eval(&self, w: Vec3) -> Vec3 {
        basis(w).iter().zip(&self.coefficients).map(|(p, c)| *c * *p).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_basis_is_orthogonal_with_the_course_norms() {
        // Project each basis polynomial: it must come back as itself.
        for k in 0..9 {
            let sh = Sh9::project(&|w| Vec3::splat(basis(w)[k]), 48);
            for (i, c) in sh.coefficients.iter().enumerate() {
                let want = if i == k { 1.0 } else { 0.0 };
                assert!((c.x - want).abs() < 2e-3, "p{k} → a{i} = {}", c.x);
            }
        }
    }

    #[test]
    fn quadrature_gives_the_irradiance_of_known_skies() {
        // A uniform sky of radiance 1 gives π; a sky L = max(0, l·z) gives 2π/3 facing up.
        let n = Vec3::new(0.2, -0.3, 0.9).normalize();
        assert!((irradiance(&|_| Vec3::ONE, n, 1500).x - PI).abs() < 1e-12);
        let up = irradiance(&|l| Vec3::splat(l.z.max(0.0)), Vec3::Z, 1500).x;
        assert!((up - 2.0 * PI / 3.0).abs() < 2e-3, "{up}");
        // Facing down into the dark half it sees nothing; sideways, half of the lobe.
        let down = irradiance(&|l| Vec3::splat(l.z.max(0.0)), -Vec3::Z, 1500).x;
        assert!(down.abs() < 1e-3, "{down}");
    }

    #[test]
    fn nine_coefficients_carry_the_irradiance_of_a_sky() {
        // Sky above the horizon, dark ground: the irradiance is smooth, and nine coefficients
        // reproduce it within a few percent of its maximum (Ramamoorthi and Hanrahan: ~1 %).
        let sky = |l: Vec3| if l.y > 0.0 { Vec3::new(0.4, 0.6, 1.0) } else { Vec3::new(0.1, 0.08, 0.05) };
        let sh = Sh9::irradiance_of(&sky, 16, 800);
        for n in [Vec3::Y, -Vec3::Y, Vec3::X, Vec3::new(0.3, 0.5, -0.8).normalize()] {
            let (exact, approx) = (irradiance(&sky, n, 4000), sh.eval(n));
            assert!((exact - approx).abs().max_element() < 0.04 * PI, "{n}: {exact} vs {approx}");
        }
    }
}

/// The course's roughness levels of the prefiltered environment.
pub const ROUGHNESS_LEVELS: [f64; 6] = [0.02, 0.04, 0.08, 0.12, 0.25, 0.4];

/// Beckmann–Spizzichino `D` at `cos²ϑ_h` for roughness `m` (course: `e^{−tan²ϑ/m²}/(πm²cos⁴ϑ)`).
fn beckmann(c2: f64, m: f64) -> f64 {
    let t2 = (1.0 - c2) / c2;
    (-t2 / (m * m)).exp() / (PI * m * m * c2 * c2)
}

/// A vector of the hemisphere around `n` from its polar angles about `e₃` (the course's
/// Householder reflection).
fn around(n: Vec3, l: Vec3) -> Vec3 {
    let sign = if n.z > 0.0 { 1.0 } else { -1.0 };
    let w = n + Vec3::Z * sign;
    let l = l - w * (2.0 / w.dot(w) * w.dot(l));
    if n.z > 0.0 { -l } else { l }
}

/// The filtered radiance `L_i(n) = 1/(2π) ∫ D L dS` with `v = n` (so `ϑ_h = ϑ_l/2`), by the
/// course's midpoint quadrature with `N × M` knots in `(λ, ϑ)`.
pub fn filtered_radiance(radiance: &dyn Fn(Vec3) -> Vec3, n: Vec3, m: f64, (nl, mt): (usize, usize)) -> Vec3 {
    let mut sum = Vec3::ZERO;
    for j in 0..mt {
        let theta = PI * (2 * j + 1) as f64 / (4 * mt) as f64;
        let (st, ct) = theta.sin_cos();
        let d = beckmann(0.5 * (1.0 + ct), m);
        let mut ring = Vec3::ZERO;
        for i in 0..nl {
            let lambda = PI * (2 * i + 1) as f64 / nl as f64;
            let l = Vec3::new(lambda.cos() * st, lambda.sin() * st, ct);
            ring += radiance(around(n, l));
        }
        sum += ring * (d * st);
    }
    sum * (PI / (2 * nl * mt) as f64)
}

/// The split-sum factors `M₀(ϑ_v)` and `M₁(ϑ_v)` of `∫ G F / (4⟨v,n⟩) dS ≈ M₀ + F₀ M₁` (Schlick's
/// `F = F₀ + (1 − F₀)(1 − ⟨l,h⟩)⁵`): `M₀ = ∫ G (1 − ⟨l,h⟩)⁵ / (4⟨v,n⟩)`,
/// `M₁ = ∫ G (1 − (1 − ⟨l,h⟩)⁵) / (4⟨v,n⟩)`, with the course's V-groove `G`. **Seed typo**: the
/// course prints `M₁` with the same integrand as `M₀`; Schlick's formula gives the one above
/// (checked: `M₀ + M₁ = ∫ G / (4⟨v,n⟩)`).
pub fn split_sum(cos_v: f64, (nl, mt): (usize, usize)) -> (f64, f64) {
    let v = Vec3::new((1.0 - cos_v * cos_v).max(0.0).sqrt(), 0.0, cos_v);
    let (mut m0, mut m1) = (0.0, 0.0);
    for j in 0..mt {
        let theta = PI * (2 * j + 1) as f64 / (4 * mt) as f64;
        let (st, ct) = theta.sin_cos();
        for i in 0..nl {
            let lambda = PI * (2 * i + 1) as f64 / nl as f64;
            let l = Vec3::new(lambda.cos() * st, lambda.sin() * st, ct);
            let h = (l + v).normalize();
            let (hn, vn, ln) = (h.z, v.z, l.z);
            let g = (2.0 * hn * vn / v.dot(h)).min(2.0 * hn * ln / l.dot(h)).min(1.0);
            let c5 = (1.0 - l.dot(h)).max(0.0).powi(5);
            let w = g / (4.0 * vn) * st;
            m0 += w * c5;
            m1 += w * (1.0 - c5);
        }
    }
    let k = PI * PI / (nl * mt) as f64;
    (m0 * k, m1 * k)
}

/// Prefiltered environment levels and the `M₀, M₁` table: specular image-based light for the
/// course's simplified Cook–Torrance model, `L_rs ≈ L_i(r) (M₀(ϑ_v) + F₀ M₁(ϑ_v))`.
#[derive(Clone, Debug)]
pub struct SpecularIbl {
    /// Per roughness level: a cube map (6 faces of `size²` texels), `size` halving per level.
    levels: Vec<(usize, Vec<Vec3>)>,
    /// `(M₀, M₁)` at `cos ϑ_v = (k + ½)/len`.
    table: Vec<(f64, f64)>,
}

fn cube_index(w: Vec3, size: usize) -> usize {
    let a = w.abs();
    let (face, u, v) = if a.x >= a.y && a.x >= a.z {
        (if w.x > 0.0 { 0 } else { 1 }, w.y / a.x, w.z / a.x)
    } else if a.y >= a.z {
        (if w.y > 0.0 { 2 } else { 3 }, w.x / a.y, w.z / a.y)
    } else {
        (if w.z > 0.0 { 4 } else { 5 }, w.x / a.z, w.y / a.z)
    };
    let t = |s: f64| (((s + 1.0) / 2.0 * size as f64) as usize).min(size - 1);
    (face * size + t(v)) * size + t(u)
}

impl SpecularIbl {
    /// Prefilters `radiance` at the course's roughness levels (cube maps from `base` texels a
    /// side, halving, at least 4) and tabulates the split sum.
    pub fn build(radiance: &(dyn Fn(Vec3) -> Vec3 + Sync), base: usize) -> Self {
        use rayon::prelude::*;
        let levels = ROUGHNESS_LEVELS
            .iter()
            .enumerate()
            .map(|(k, m)| {
                let size = (base >> k).max(4);
                let texels: Vec<Vec3> = (0..6 * size * size)
                    .into_par_iter()
                    .map(|idx| {
                        let (face, j, i) = (idx / (size * size), idx / size % size, idx % size);
                        filtered_radiance(radiance, texel(face, i, j, size).0, *m, (48, 12))
                    })
                    .collect();
                (size, texels)
            })
            .collect();
        let table = (0..32).map(|k| split_sum((k as f64 + 0.5) / 32.0, (64, 32))).collect();
        Self { levels, table }
    }

    /// `L_i(r)` at roughness `m` (linear between the two nearest levels, clamped to the range).
    pub fn filtered(&self, r: Vec3, m: f64) -> Vec3 {
        let at = |k: usize| {
            let (size, texels) = &self.levels[k];
            texels[cube_index(r, *size)]
        };
        let k = ROUGHNESS_LEVELS.iter().position(|x| *x >= m).unwrap_or(ROUGHNESS_LEVELS.len() - 1);
        if k == 0 || ROUGHNESS_LEVELS[k] <= m {
            return at(k);
        }
        let (a, b) = (ROUGHNESS_LEVELS[k - 1], ROUGHNESS_LEVELS[k]);
        let t = (m - a) / (b - a);
        at(k - 1) * (1.0 - t) + at(k) * t
    }

    /// `M₀ + F₀ M₁` at `cos ϑ_v`.
    pub fn split_factor(&self, cos_v: f64, f0: f64) -> f64 {
        let k = ((cos_v.clamp(0.0, 1.0) * self.table.len() as f64) as usize).min(self.table.len() - 1);
        let (m0, m1) = self.table[k];
        m0 + f0 * m1
    }
}

#[cfg(test)]
mod specular_tests {
    use super::*;

    #[test]
    fn split_sum_parts_add_up_and_stay_in_range() {
        for cos_v in [0.1, 0.5, 0.9, 1.0] {
            let (m0, m1) = split_sum(cos_v, (128, 64));
            // M₀ + M₁ = ∫ G/(4⟨v,n⟩) dS, checked by a finer independent midpoint rule in (cos ϑ, φ).
            let v = Vec3::new((1.0 - cos_v * cos_v).sqrt(), 0.0, cos_v);
            let (mut total, k) = (0.0, 600);
            for a in 0..k {
                let z = (a as f64 + 0.5) / k as f64;
                let r = (1.0 - z * z).sqrt();
                for b in 0..k {
                    let phi = 2.0 * PI * (b as f64 + 0.5) / k as f64;
                    let l = Vec3::new(r * phi.cos(), r * phi.sin(), z);
                    let h = (l + v).normalize();
                    let g = (2.0 * h.z * v.z / v.dot(h)).min(2.0 * h.z * l.z / l.dot(h)).min(1.0);
                    total += g / (4.0 * v.z);
                }
            }
            total *= 2.0 * PI / (k * k) as f64;
            assert!(((m0 + m1) - total).abs() < 2e-3 * total, "cos {cos_v}: {} vs {total}", m0 + m1);
            assert!(m0 >= 0.0 && m1 > m0, "{m0} {m1}");
        }
    }

    #[test]
    fn filtered_radiance_of_a_uniform_sky_is_uniform_and_sharper_levels_follow_the_sky() {
        let uniform = filtered_radiance(&|_| Vec3::ONE, Vec3::new(0.3, 0.4, 0.866).normalize(), 0.25, (96, 48));
        let up = filtered_radiance(&|_| Vec3::ONE, Vec3::Z, 0.25, (96, 48));
        assert!((uniform - up).abs().max_element() < 1e-9, "independent of n");
        // With little roughness the filter is narrow: it sees the colour straight along n.
        let sky = |l: Vec3| if l.y > 0.0 { Vec3::X } else { Vec3::Y };
        let ibl = SpecularIbl::build(&sky, 16);
        let (a, b) = (ibl.filtered(Vec3::Y, 0.02), ibl.filtered(-Vec3::Y, 0.02));
        assert!(a.x > 5.0 * a.y && b.y > 5.0 * b.x, "{a} {b}");
    }
}
