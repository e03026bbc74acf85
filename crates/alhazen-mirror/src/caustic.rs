//! The catacaustic of the reflection on a circle (Glaeser §2.3, §3): the envelope `k*` of the
//! rays of the pencil through `E` reflected on `k`.
//!
//! * [`point`]: (12) with the parameter (13), `λ = (r² − e r cos φ)/(2e² + r² − 3 e r cos φ)`,
//!   for a finite eye; for an eye at infinity the limit `R − (r cos φ / 2)(cos 2φ, sin 2φ)`, the
//!   nephroid. With `E` on the circle (`e = r`) `λ = 1/3`: the cardioid.
//! * [`point_rational`]: the rational form (15) in `t = tan(φ/2)`.
//! * [`kernel_point`] (16) and [`double_points`] (17): where reflected rays meet the axis `ME`,
//!   and the two mirror points whose reflected rays are perpendicular to it (the double tangents
//!   of `k*`, where the hyperbola (3) degenerates).
//! * [`curve`] samples the caustic by the polar angle (the paper's footnote 3: (15) distributes
//!   points badly), split where it runs off to infinity; [`sphere_surface`] and
//!   [`cylinder_surface`] sweep it into the catacaustic surfaces of Fig. 10 (rotation about `ME`
//!   for a sphere, translation along the axis for a cylinder) as triangle meshes.
//!
//! Frame: `M` at the origin, `E` at `(e, 0)`.

use alhazen_geom::TriangleMesh;
use alhazen_math::{Vec2, Vec3};
use std::f64::consts::PI;

/// Where the eye is, in the canonical frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Eye {
    /// At `(e, 0)`, `e > 0`.
    At(f64),
    /// At infinity in direction `+x` (parallel rays).
    AtInfinity,
}

/// Which reflections to draw.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    /// Reflection on the outside: mirror points the eye sees directly, `cos φ > r/e`.
    Outside,
    /// Reflection on the inside: the remaining mirror points (for an eye inside the circle, all).
    Inside,
}

/// The point of `k*` on the reflected ray of the mirror point at polar angle `phi`; `None` where
/// the ray is an asymptote (the caustic point is at infinity).
pub fn point(r: f64, eye: Eye, phi: f64) -> Option<Vec2> {
    let (s, c) = phi.sin_cos();
    let rr = Vec2::new(r * c, r * s);
    let p = match eye {
        Eye::At(e) => {
            let denom = 2.0 * e * e + r * r - 3.0 * e * r * c;
            if denom.abs() < 1e-14 * (e * e + r * r) {
                return None;
            }
            let lambda = (r * r - e * r * c) / denom;
            let e_star = Vec2::new(e * (2.0 * phi).cos(), e * (2.0 * phi).sin());
            rr + (e_star - rr) * lambda
        }
        Eye::AtInfinity => rr - Vec2::new((2.0 * phi).cos(), (2.0 * phi).sin()) * (r * c / 2.0),
    };
    p.is_finite().then_some(p)
}

/// The rational parametrisation (15) for `t = tan(φ/2)`, finite eye.
///
/// Seed typo: (15) prints `μ = (e/r)(t²+1)³ + 3(t²−1)(t²+1)² + 2(r/e)(t²+1)³`; inserting (13)
/// and (14) into (12) gives `μ = 2(e/r)(t²+1)³ + 3(t²−1)(t²+1)² + (r/e)(t²+1)³` (the factors
/// 2 and 1 are swapped). The numerators of `x` and `y` are as printed. The test
/// `rational_form_agrees_with_the_polar_one` shows both.
pub fn point_rational(r: f64, e: f64, t: f64) -> Option<Vec2> {
    let (t2, u) = (t * t, t * t + 1.0);
    let mu = 2.0 * e / r * u.powi(3) + 3.0 * (t2 - 1.0) * u * u + r / e * u.powi(3);
    if mu.abs() < 1e-300 {
        return None;
    }
    let x = (-r * u.powi(3) - e * (t2 - 1.0) * (t2 * t2 + 10.0 * t2 + 1.0)) / mu;
    let y = 16.0 * e * t * t2 / mu;
    Some(Vec2::new(x, y))
}

/// The kernel point (16): where the reflected ray of the mirror point with abscissa `x` meets
/// the axis `ME`, `x_k = e r² / (2 e x − r²)`; `None` when the ray is parallel to the axis.
pub fn kernel_point(r: f64, e: f64, x: f64) -> Option<f64> {
    let d = 2.0 * e * x - r * r;
    (d != 0.0).then(|| e * r * r / d)
}

/// The double points (17) of the projectivity of kernel points, `x = r/(4e)(r ± √(r² + 8e²))`:
/// mirror points whose reflected rays are perpendicular to `ME`.
pub fn double_points(r: f64, e: f64) -> [f64; 2] {
    let root = (r * r + 8.0 * e * e).sqrt();
    [r / (4.0 * e) * (r + root), r / (4.0 * e) * (r - root)]
}

/// The range of polar angles of `side`, as `(start, end)` with `start < end`.
fn angle_range(r: f64, eye: Eye, side: Side) -> (f64, f64) {
    let visible = match eye {
        Eye::At(e) if e <= r => 0.0,
        Eye::At(e) => (r / e).acos(),
        Eye::AtInfinity => PI / 2.0,
    };
    match side {
        Side::Outside => (-visible, visible),
        Side::Inside => (visible, 2.0 * PI - visible),
    }
}

/// The caustic of `side` as polylines, sampled at `samples` polar angles; pieces that run off
/// to infinity (or beyond `clip` from the centre) are cut.
pub fn curve(r: f64, eye: Eye, side: Side, samples: usize, clip: f64) -> Vec<Vec<Vec2>> {
    let (a, b) = angle_range(r, eye, side);
    let mut pieces: Vec<Vec<Vec2>> = vec![vec![]];
    for k in 0..=samples.max(2) {
        let phi = a + (b - a) * k as f64 / samples.max(2) as f64;
        match point(r, eye, phi).filter(|p| p.length() <= clip) {
            Some(p) => pieces.last_mut().expect("non-empty").push(p),
            None if !pieces.last().expect("non-empty").is_empty() => pieces.push(vec![]),
            None => {}
        }
    }
    pieces.retain(|p| p.len() >= 2);
    pieces
}

/// The ray reflected at the mirror point of polar angle `phi`: its start (on the circle) and unit
/// direction.
pub fn reflected_ray(r: f64, eye: Eye, phi: f64) -> (Vec2, Vec2) {
    let n = Vec2::from_angle(phi);
    let p = n * r;
    let incoming = match eye {
        Eye::At(e) => (p - Vec2::new(e, 0.0)).normalize(),
        Eye::AtInfinity => Vec2::NEG_X,
    };
    (p, incoming - 2.0 * incoming.dot(n) * n)
}

/// The catacaustic surface of a sphere of radius `r` centred at `center`, the eye at distance
/// `e` along `axis`: the curve of `side` rotated about the axis, `segments` steps around.
pub fn sphere_surface(
    center: Vec3,
    axis: Vec3,
    r: f64,
    eye: Eye,
    side: Side,
    samples: usize,
    segments: usize,
    clip: f64,
) -> TriangleMesh {
    let axis = axis.normalize();
    let (u, v) = alhazen_math::orthonormal_basis(axis);
    let mut mesh = TriangleMesh::default();
    // The curve is symmetric about the axis: rotating the half with y ≥ 0 covers the surface.
    for piece in curve(r, eye, side, samples, clip) {
        let half: Vec<Vec2> = piece.into_iter().filter(|p| p.y >= 0.0).collect();
        if half.len() < 2 {
            continue;
        }
        let rows = segments.max(3);
        let base = mesh.positions.len() as u32;
        for j in 0..rows {
            let a = 2.0 * PI * j as f64 / rows as f64;
            let radial = u * a.cos() + v * a.sin();
            mesh.positions.extend(half.iter().map(|p| center + axis * p.x + radial * p.y));
        }
        grid_triangles(&mut mesh, base, rows, half.len(), true);
    }
    mesh
}

/// The catacaustic surface of a cylinder (axis through `center` along `axis`, eye direction in
/// the normal projection `toward_eye`): the curve translated from height 0 to `height`.
pub fn cylinder_surface(
    center: Vec3,
    axis: Vec3,
    toward_eye: Vec3,
    r: f64,
    eye: Eye,
    side: Side,
    samples: usize,
    height: f64,
    clip: f64,
) -> TriangleMesh {
    let axis = axis.normalize();
    let x = (toward_eye - axis * toward_eye.dot(axis)).normalize();
    let y = axis.cross(x);
    let mut mesh = TriangleMesh::default();
    for piece in curve(r, eye, side, samples, clip) {
        let base = mesh.positions.len() as u32;
        for h in [0.0, height] {
            mesh.positions.extend(piece.iter().map(|p| center + x * p.x + y * p.y + axis * h));
        }
        grid_triangles(&mut mesh, base, 2, piece.len(), false);
    }
    mesh
}

/// Triangles of a `rows × cols` vertex grid starting at `base`; `wrap` closes the rows.
fn grid_triangles(mesh: &mut TriangleMesh, base: u32, rows: usize, cols: usize, wrap: bool) {
    let row_pairs = if wrap { rows } else { rows - 1 };
    for j in 0..row_pairs {
        let (r0, r1) = (j, (j + 1) % rows);
        for i in 0..cols - 1 {
            let at = |r: usize, c: usize| base + (r * cols + c) as u32;
            mesh.triangles.push([at(r0, i), at(r0, i + 1), at(r1, i + 1)]);
            mesh.triangles.push([at(r0, i), at(r1, i + 1), at(r1, i)]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eye_at_infinity_gives_the_nephroid() {
        let r = 2.0;
        for k in 0..50 {
            let phi = -1.5 + 3.0 * k as f64 / 50.0;
            let p = point(r, Eye::AtInfinity, phi).unwrap();
            let nephroid =
                Vec2::new(3.0 * phi.cos() - (3.0 * phi).cos(), 3.0 * phi.sin() - (3.0 * phi).sin()) * (r / 4.0);
            assert!((p - nephroid).length() < 1e-14);
            // And it is the limit of large e.
            let far = point(r, Eye::At(1e9), phi).unwrap();
            assert!((far - p).length() < 1e-7);
        }
    }

    #[test]
    fn eye_on_the_circle_gives_the_cardioid() {
        let r = 1.5;
        for k in 1..60 {
            let phi = 2.0 * PI * k as f64 / 60.0;
            let p = point(r, Eye::At(r), phi).unwrap();
            // A cardioid with cusp at (r/3, 0)·(−1): (r/3)(2cos φ + cos 2φ, 2 sin φ + sin 2φ).
            let t = phi + PI;
            let cardioid = -Vec2::new(2.0 * t.cos() - (2.0 * t).cos(), 2.0 * t.sin() - (2.0 * t).sin()) * (r / 3.0);
            assert!((p - cardioid).length() < 1e-13, "{p} {cardioid}");
        }
    }

    #[test]
    fn the_caustic_is_the_envelope_of_the_reflected_rays() {
        for eye in [Eye::At(3.0), Eye::At(0.6), Eye::AtInfinity] {
            for k in 1..40 {
                let phi = 0.05 + 0.07 * k as f64;
                let Some(p) = point(1.0, eye, phi) else { continue };
                let (start, dir) = reflected_ray(1.0, eye, phi);
                // On the ray's line…
                assert!(dir.perp_dot(p - start).abs() < 1e-12 * (1.0 + (p - start).length()));
                // …and tangent to it: the curve's derivative is parallel to the ray.
                let h = 1e-6;
                let (Some(a), Some(b)) = (point(1.0, eye, phi - h), point(1.0, eye, phi + h)) else { continue };
                let tangent = (b - a) / (2.0 * h);
                assert!(tangent.perp_dot(dir).abs() < 1e-6 * (1.0 + tangent.length()), "{eye:?} φ={phi}");
            }
        }
    }

    #[test]
    fn rational_form_agrees_with_the_polar_one() {
        let (r, e) = (1.0, 2.5);
        for k in 1..30 {
            let phi = -1.2 + 0.08 * k as f64;
            let t = (phi / 2.0).tan();
            let (Some(a), Some(b)) = (point(r, Eye::At(e), phi), point_rational(r, e, t)) else { continue };
            assert!((a - b).length() < 1e-12, "φ={phi}: {a} vs {b}");
            // The seed's printed μ misses the curve (except where e = r).
            let (t2, u) = (t * t, t * t + 1.0);
            let mu_seed = e / r * u.powi(3) + 3.0 * (t2 - 1.0) * u * u + 2.0 * r / e * u.powi(3);
            let y_seed = 16.0 * e * t * t2 / mu_seed;
            assert!(t.abs() < 0.05 || (y_seed - a.y).abs() > 1e-3);
        }
    }

    #[test]
    fn kernel_and_double_points() {
        let (r, e) = (1.0, 3.0);
        for k in 0..20 {
            let phi = -1.0 + 0.1 * k as f64;
            let (start, dir) = reflected_ray(r, Eye::At(e), phi);
            if let Some(xk) = kernel_point(r, e, start.x) {
                // The reflected line passes through (x_k, 0).
                assert!(dir.perp_dot(Vec2::new(xk, 0.0) - start).abs() < 1e-9 * (1.0 + xk.abs()));
            }
        }
        for x in double_points(r, e) {
            assert!((kernel_point(r, e, x).unwrap() - x).abs() < 1e-12);
            let phi = (x / r).acos();
            let (_, dir) = reflected_ray(r, Eye::At(e), phi);
            assert!(dir.x.abs() < 1e-12, "the reflected ray is perpendicular to ME");
        }
    }

    #[test]
    fn surfaces_are_valid_meshes() {
        let m = sphere_surface(Vec3::ZERO, Vec3::Z, 1.0, Eye::At(3.0), Side::Outside, 64, 32, 10.0);
        m.validate().unwrap();
        assert!(m.triangle_count() > 1000);
        let c = cylinder_surface(Vec3::ZERO, Vec3::Y, Vec3::X, 1.0, Eye::At(0.5), Side::Inside, 64, 2.0, 10.0);
        c.validate().unwrap();
        // Every vertex of the cylinder's surface projects onto the planar caustic.
        for p in &c.positions {
            let q = Vec2::new(p.x, -p.z);
            let near = curve(1.0, Eye::At(0.5), Side::Inside, 64, 10.0)
                .into_iter()
                .flatten()
                .any(|c| (c - q).length() < 1e-12);
            assert!(near);
        }
    }
}
