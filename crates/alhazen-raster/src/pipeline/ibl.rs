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
