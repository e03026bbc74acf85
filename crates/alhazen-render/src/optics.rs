//! Reflection, refraction and Fresnel factors (lecture: "Computing R", "Computing T", Snell's
//! law, total internal reflection; course: the unpolarised Fresnel formula and Schlick).
//!
//! Conventions: `i` is the unit direction *towards* the viewer/incoming side (the lecture's `I`,
//! and `V` in `R = 2(V·N)N − V`), `n` the unit normal on the same side as `i`.

use alhazen_math::Vec3;

/// Mirror direction `R = 2(V·N)N − V` (lecture).
#[inline]
pub fn reflect(v: Vec3, n: Vec3) -> Vec3 {
    2.0 * v.dot(n) * n - v
}

/// The lecture's transmitted direction for relative index `eta = η_I/η_T`:
/// `T = −(cos θ_T − (η_I/η_T) cos θ_I) N − (η_I/η_T) I`, with
/// `cos θ_T = √(1 − (η_I/η_T)² (1 − (N·I)²))`; `None` under total internal reflection.
#[inline]
pub fn refract(i: Vec3, n: Vec3, eta: f64) -> Option<Vec3> {
    let cos_i = n.dot(i);
    let k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
    if k < 0.0 {
        return None;
    }
    let cos_t = k.sqrt();
    Some(-(cos_t - eta * cos_i) * n - eta * i)
}

/// The course's Fresnel factor for unpolarised light,
/// Beer–Lambert: the share of light kept over a distance `d` through a medium absorbing
/// `sigma` per unit length (per channel; the lecture's coloured glass).
#[inline]
pub fn beer(sigma: Vec3, d: f64) -> Vec3 {
    if sigma == Vec3::ZERO { Vec3::ONE } else { (-sigma * d).exp() }
}

/// What a ray keeps of its light after crossing the inside of `m` to meet its surface at `hit`
/// from behind (the geometric normal's back: the ray leaves the object there, having travelled
/// `hit.t` — a unit direction's length — inside): Beer–Lambert's transmittance of `m`'s
/// absorption in `mode`'s channels. `None` where `m` absorbs nothing or the ray arrives from
/// outside. (The path and photon tracers apply it at every vertex; Whitted on its own.)
#[inline(always)]
pub fn absorbed_inside(
    m: &alhazen_scene::Material,
    hit: &crate::shape::SurfaceHit,
    dir: Vec3,
    mode: crate::bsdf::ColorMode,
) -> Option<Vec3> {
    (m.absorption != Vec3::ZERO && hit.n.dot(dir) >= 0.0).then(|| beer(mode.color(m.absorption), hit.t))
}

/// `F = ½ (g−c)²/(g+c)² (1 + (c(g+c)−1)²/(c(g−c)+1)²)` with `c = cos θ` and
/// `g = √(η² + c² − 1)`, `η = η₂/η₁`. The seed prints `g = √(η² + c²) − 1`, which gives
/// `F(0°) ≠ ((η−1)/(η+1))²`; the `−1` belongs under the root (see the tests). Returns 1 under
/// total internal reflection (`g² < 0`).
/// Computed whole and then chosen (no early return: the path tracer's lanes run it for eight
/// rays at once).
#[inline(always)]
pub fn fresnel_dielectric(cos_theta: f64, eta: f64) -> f64 {
    let c = cos_theta.abs().min(1.0);
    let g2 = eta * eta + c * c - 1.0;
    let g = g2.sqrt();
    // `½ a² (1 + b²)` with `a = (g − c)/(g + c)`, `b = n/m`, over one denominator.
    let (n, m) = (c * (g + c) - 1.0, c * (g - c) + 1.0);
    let f = (0.5 * (g - c) * (g - c) * (m * m + n * n) / ((g + c) * (g + c) * (m * m))).min(1.0);
    if g2 < 0.0 || g + c == 0.0 { 1.0 } else { f }
}

/// Schlick's approximation `F₀ + (1 − F₀)(1 − cos θ)⁵`, `F₀ = ((η−1)/(η+1))²`. For light going to
/// the optically thinner side (`η < 1`) the transmitted angle's cosine is used, as Schlick
/// requires, and total internal reflection gives 1.
pub fn fresnel_schlick(cos_theta: f64, eta: f64) -> f64 {
    let f0 = ((eta - 1.0) / (eta + 1.0)).powi(2);
    let mut c = cos_theta.abs().min(1.0);
    if eta < 1.0 {
        let sin2_t = (1.0 - c * c) / (eta * eta);
        if sin2_t >= 1.0 {
            return 1.0;
        }
        c = (1.0 - sin2_t).sqrt();
    }
    f0 + (1.0 - f0) * (1.0 - c).powi(5)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn fresnel_limits() {
        for eta in [1.33f64, 1.5, 2.419] {
            let f0 = ((eta - 1.0) / (eta + 1.0)).powi(2);
            assert!((fresnel_dielectric(1.0, eta) - f0).abs() < 1e-12, "normal incidence");
            assert!((fresnel_dielectric(0.0, eta) - 1.0).abs() < 1e-12, "grazing incidence");
            assert!((fresnel_schlick(1.0, eta) - f0).abs() < 1e-12);
            assert!((fresnel_schlick(0.0, eta) - 1.0).abs() < 1e-12);
        }
        // Matched media reflect nothing.
        assert!(fresnel_dielectric(0.3, 1.0).abs() < 1e-12);
    }

    #[test]
    fn seed_fresnel_typo_is_really_wrong() {
        // The seed's g = √(η² + c²) − 1 at c = 1, η = 1.5 gives g = 0.803 instead of 1.5.
        let (eta, c) = (1.5f64, 1.0f64);
        let g_seed = (eta * eta + c * c).sqrt() - 1.0;
        let f_seed = 0.5 * ((g_seed - c) / (g_seed + c)).powi(2);
        assert!((f_seed - 0.04).abs() > 0.001);
    }

    #[test]
    fn fresnel_matches_the_s_and_p_average() {
        // Independent form: average of the squared s and p amplitude coefficients.
        let eta = 1.5f64;
        for k in 0..=9 {
            let ci = (k as f64 * 0.1).max(1e-3);
            let st = (1.0 - ci * ci).sqrt() / eta;
            let ct = (1.0 - st * st).sqrt();
            let rs = (ci - eta * ct) / (ci + eta * ct);
            let rp = (eta * ci - ct) / (eta * ci + ct);
            assert!((fresnel_dielectric(ci, eta) - 0.5 * (rs * rs + rp * rp)).abs() < 1e-12);
        }
    }

    #[test]
    fn total_internal_reflection() {
        // From glass (1.5) to air: critical angle asin(1/1.5) ≈ 41.8°.
        let n = Vec3::Z;
        let steep = Vec3::new(40f64.to_radians().sin(), 0.0, 40f64.to_radians().cos());
        let grazing = Vec3::new(43f64.to_radians().sin(), 0.0, 43f64.to_radians().cos());
        assert!(refract(steep, n, 1.5).is_some());
        assert!(refract(grazing, n, 1.5).is_none());
        assert_eq!(fresnel_dielectric(grazing.z, 1.0 / 1.5), 1.0);
        assert_eq!(fresnel_schlick(grazing.z, 1.0 / 1.5), 1.0);
    }

    proptest! {
        #[test]
        fn snell_law_holds(theta in 0.0..1.5f64, phi in 0.0..std::f64::consts::TAU, eta in 0.3..3.0f64) {
            let i = Vec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos());
            let n = Vec3::Z;
            match refract(i, n, eta) {
                Some(t) => {
                    prop_assert!((t.length() - 1.0).abs() < 1e-12);
                    let sin_t = (1.0 - t.z * t.z).max(0.0).sqrt();
                    // sin θ_I / sin θ_T = η_T / η_I = 1/eta.
                    prop_assert!((theta.sin() * eta - sin_t).abs() < 1e-12);
                    prop_assert!(t.z < 0.0, "transmitted ray crosses the surface");
                    // Coplanar with i and n.
                    prop_assert!(t.dot(i.cross(n)).abs() < 1e-12);
                }
                None => prop_assert!(eta * theta.sin() > 1.0 - 1e-12),
            }
            let r = reflect(i, n);
            prop_assert!((r.dot(n) - i.dot(n)).abs() < 1e-12 && (r + i - 2.0 * i.dot(n) * n).length() < 1e-12);
        }
    }
}
