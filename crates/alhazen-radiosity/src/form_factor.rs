//! Form factors (course, §"The energetic balance method": `F_ij`, `G_ij` and Nusselt's
//! analogy).
//!
//! The solver needs the collocation factor `G_ij/π` of an element's point `p_i` towards a
//! polygon `A_j` seen whole: by Nusselt's analogy it is the area of `A_j` projected on the unit
//! hemisphere over `p_i` and then on its base, divided by the base's area `π`. That area has a
//! closed form (Lambert's), a sum over the polygon's edges,
//!
//! `G/π = 1/(2π) Σ_k γ_k n·(r_k × r_{k+1}) / |r_k × r_{k+1}|`,
//!
//! with `r_k = v_k − p` and `γ_k` the angle the edge subtends at `p` — exact for any planar
//! polygon above the tangent plane of `p`; parts below it are clipped off first. The course
//! measures the same projected area on the five faces of a [`Hemicube`]; the solver uses the
//! closed form by default (no aliasing, one polygon clip) and the hemicube when asked.
//!
//! [`analytic`] holds the textbook closed forms between whole patches (parallel and
//! perpendicular rectangles, coaxial disks) the tests check the integrated point factors against.

use alhazen_math::Vec3;

/// Most corners a clipped polygon can have (a triangle cut by one plane has four).
pub const MAX_CORNERS: usize = 8;

/// A small convex polygon (corners in order).
#[derive(Clone, Copy, Debug)]
pub struct Polygon {
    /// Corners; only the first `len` count.
    pub v: [Vec3; MAX_CORNERS],
    /// Number of corners.
    pub len: usize,
}

impl Polygon {
    /// The triangle `t`.
    pub fn triangle(t: [Vec3; 3]) -> Self {
        let mut v = [Vec3::ZERO; MAX_CORNERS];
        v[..3].copy_from_slice(&t);
        Self { v, len: 3 }
    }

    /// The polygon of the given corners (at most [`MAX_CORNERS`]).
    pub fn of(corners: &[Vec3]) -> Self {
        let mut v = [Vec3::ZERO; MAX_CORNERS];
        let len = corners.len().min(MAX_CORNERS);
        v[..len].copy_from_slice(&corners[..len]);
        Self { v, len }
    }

    /// The corners.
    pub fn corners(&self) -> &[Vec3] {
        &self.v[..self.len]
    }

    /// The part where `(q − p)·n ≥ 0` (Sutherland–Hodgman against one plane).
    pub fn above(&self, p: Vec3, n: Vec3) -> Self {
        let mut out = Self { v: [Vec3::ZERO; MAX_CORNERS], len: 0 };
        let side = |q: Vec3| (q - p).dot(n);
        let mut push = |q: Vec3| {
            if out.len < MAX_CORNERS {
                out.v[out.len] = q;
                out.len += 1;
            }
        };
        for k in 0..self.len {
            let (a, b) = (self.v[k], self.v[(k + 1) % self.len]);
            let (sa, sb) = (side(a), side(b));
            if sa >= 0.0 {
                push(a);
            }
            if (sa >= 0.0) != (sb >= 0.0) {
                push(a + (b - a) * (sa / (sa - sb)));
            }
        }
        out
    }
}

/// `G/π` of the point `p` with unit normal `n` towards `poly`, ignoring occlusion: the fraction
/// of the light leaving `poly` uniformly (a Lambertian emitter) per unit of `poly`'s radiosity
/// that arrives at `p` as irradiance. The part of `poly` below `p`'s tangent plane is clipped off.
pub fn point_to_polygon(p: Vec3, n: Vec3, poly: &Polygon) -> f64 {
    lambert(p, n, poly.above(p, n).corners())
}

/// Lambert's edge sum for a planar polygon wholly above the tangent plane of `p` (any number
/// of corners, in order).
pub fn lambert(p: Vec3, n: Vec3, corners: &[Vec3]) -> f64 {
    let mut sum = 0.0;
    for k in 0..corners.len() {
        let (a, b) = (corners[k] - p, corners[(k + 1) % corners.len()] - p);
        let c = a.cross(b);
        let s = c.length();
        if s > 0.0 {
            sum += s.atan2(a.dot(b)) * n.dot(c) / s;
        }
    }
    (sum.abs() / (2.0 * std::f64::consts::PI)).min(1.0)
}

/// `G/π` towards a point source of unit power density: `cos θ / d²` at `p` (normal `n`) of light
/// from `q`; zero behind `p`'s tangent plane.
pub fn point_to_point(p: Vec3, n: Vec3, q: Vec3) -> f64 {
    let d = q - p;
    let d2 = d.length_squared();
    if d2 == 0.0 {
        return 0.0;
    }
    (n.dot(d) / d2.sqrt()).max(0.0) / d2
}

/// Closed forms of patch-to-patch form factors `F_12` (the fraction of the light leaving patch 1
/// uniformly that reaches patch 2), from the heat-transfer literature; the references of the
/// tests.
pub mod analytic {
    use std::f64::consts::PI;

    /// Two directly opposed parallel `a × b` rectangles at distance `c`.
    pub fn parallel_rectangles(a: f64, b: f64, c: f64) -> f64 {
        let (x, y) = (a / c, b / c);
        let (x1, y1) = (1.0 + x * x, 1.0 + y * y);
        2.0 / (PI * x * y)
            * ((x1 * y1 / (1.0 + x * x + y * y)).sqrt().ln()
                + x * y1.sqrt() * (x / y1.sqrt()).atan()
                + y * x1.sqrt() * (y / x1.sqrt()).atan()
                - x * x.atan()
                - y * y.atan())
    }

    /// From a `w × l` rectangle to an `h × l` rectangle at right angles, sharing the edge `l`.
    pub fn perpendicular_rectangles(w: f64, h: f64, l: f64) -> f64 {
        let (w, h) = (w / l, h / l);
        let (w2, h2) = (w * w, h * h);
        let s = w2 + h2;
        let log = ((1.0 + w2) * (1.0 + h2) / (1.0 + s)).ln()
            + w2 * (w2 * (1.0 + s) / ((1.0 + w2) * s)).ln()
            + h2 * (h2 * (1.0 + s) / ((1.0 + h2) * s)).ln();
        (w * (1.0 / w).atan() + h * (1.0 / h).atan() - s.sqrt() * (1.0 / s.sqrt()).atan() + 0.25 * log) / (PI * w)
    }

    /// From a disk of radius `r1` to a coaxial parallel disk of radius `r2` at distance `h`.
    pub fn coaxial_disks(r1: f64, r2: f64, h: f64) -> f64 {
        let (a, b) = (r1 / h, r2 / h);
        let x = 1.0 + (1.0 + b * b) / (a * a);
        0.5 * (x - (x * x - 4.0 * (b / a).powi(2)).sqrt())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `F_12` by integrating the point factor over patch 1 (`origin + u·e1 + v·e2`, `u, v ∈ [0, 1]`)
    /// by the midpoint rule on an `n × n` grid.
    fn integrate(origin: Vec3, e1: Vec3, e2: Vec3, to: &Polygon, n: usize) -> f64 {
        let normal = e1.cross(e2).normalize();
        // Midpoints of a grid graded towards both ends (t = ½ − ½cos): the factor of two patches
        // sharing an edge has a logarithmic singularity along it.
        let knots: Vec<f64> = (0..=n).map(|i| 0.5 - 0.5 * (std::f64::consts::PI * i as f64 / n as f64).cos()).collect();
        let mut sum = 0.0;
        for i in 0..n {
            for j in 0..n {
                let (u, du) = (0.5 * (knots[i] + knots[i + 1]), knots[i + 1] - knots[i]);
                let (v, dv) = (0.5 * (knots[j] + knots[j + 1]), knots[j + 1] - knots[j]);
                sum += point_to_polygon(origin + e1 * u + e2 * v, normal, to) * du * dv;
            }
        }
        sum
    }

    fn rectangle(origin: Vec3, e1: Vec3, e2: Vec3) -> Polygon {
        Polygon::of(&[origin, origin + e1, origin + e1 + e2, origin + e2])
    }

    #[test]
    fn parallel_rectangles_match_the_closed_form() {
        for (a, b, c) in [(1.0, 1.0, 1.0), (2.0, 0.5, 1.0), (1.0, 3.0, 0.25), (0.2, 0.3, 2.0)] {
            let to = rectangle(Vec3::new(0.0, 0.0, c), Vec3::new(a, 0.0, 0.0), Vec3::new(0.0, b, 0.0));
            let f = integrate(Vec3::ZERO, Vec3::new(a, 0.0, 0.0), Vec3::new(0.0, b, 0.0), &to, 96);
            let want = analytic::parallel_rectangles(a, b, c);
            assert!((f - want).abs() < 1e-4 * want.max(0.01), "{a}×{b} at {c}: {f} vs {want}");
        }
        // The textbook's value for unit squares a unit apart.
        assert!((analytic::parallel_rectangles(1.0, 1.0, 1.0) - 0.19982).abs() < 1e-5);
    }

    #[test]
    fn perpendicular_rectangles_match_the_closed_form() {
        for (w, h, l) in [(1.0, 1.0, 1.0), (2.0, 1.0, 1.0), (0.5, 2.0, 3.0)] {
            // Patch 1 in the floor (x: 0..w, z: 0..l), patch 2 in the wall x = 0 (y: 0..h).
            let to = rectangle(Vec3::ZERO, Vec3::new(0.0, 0.0, l), Vec3::new(0.0, h, 0.0));
            let f = integrate(Vec3::ZERO, Vec3::new(0.0, 0.0, l), Vec3::new(w, 0.0, 0.0), &to, 160);
            let want = analytic::perpendicular_rectangles(w, h, l);
            assert!((f - want).abs() < 1e-3 * want, "{w}, {h}, {l}: {f} vs {want}");
        }
        assert!((analytic::perpendicular_rectangles(1.0, 1.0, 1.0) - 0.20004).abs() < 1e-5);
    }

    #[test]
    fn coaxial_disks_match_the_closed_form() {
        let disk = |r: f64, z: f64| -> Vec<Vec3> {
            let k = 256;
            (0..k)
                .map(|i| {
                    let a = 2.0 * std::f64::consts::PI * i as f64 / k as f64;
                    Vec3::new(r * a.cos(), r * a.sin(), z)
                })
                .collect()
        };
        for (r1, r2, h) in [(1.0, 1.0, 1.0), (0.5, 2.0, 1.0), (1.0, 0.3, 0.5)] {
            let rim = disk(r2, h);
            let at = |p: Vec3| lambert(p, Vec3::Z, &rim);
            // Over disk 1 in rings (the factor depends on the radius only).
            let rings = 400;
            let mut f = 0.0;
            for i in 0..rings {
                let r = r1 * (i as f64 + 0.5) / rings as f64;
                f += at(Vec3::new(r, 0.0, 0.0)) * 2.0 * r * (r1 / rings as f64) / (r1 * r1);
            }
            // The 256-gon's area is short of the circle's by 2π²/(3·256²) (relative).
            let want = analytic::coaxial_disks(r1, r2, h);
            assert!((f - want).abs() < 2e-4 * want.max(0.05), "{r1}, {r2}, {h}: {f} vs {want}");
        }
    }

    #[test]
    fn the_inside_of_a_box_sees_all_of_its_other_faces() {
        // Nusselt: from any point of one face the five others cover the whole hemisphere.
        let faces = [
            rectangle(Vec3::new(0.0, 0.0, 1.0), Vec3::X, Vec3::Y),
            rectangle(Vec3::ZERO, Vec3::Y, Vec3::Z),
            rectangle(Vec3::X, Vec3::Y, Vec3::Z),
            rectangle(Vec3::ZERO, Vec3::X, Vec3::Z),
            rectangle(Vec3::Y, Vec3::X, Vec3::Z),
        ];
        for p in [Vec3::new(0.5, 0.5, 0.0), Vec3::new(0.01, 0.9, 0.0), Vec3::new(0.99, 0.01, 0.0)] {
            let sum: f64 = faces.iter().map(|f| point_to_polygon(p, Vec3::Z, f)).sum();
            assert!((sum - 1.0).abs() < 1e-12, "{p}: {sum}");
        }
    }

    #[test]
    fn clipping_keeps_what_lies_above_the_tangent_plane() {
        // A square standing across the plane of p: only its upper half counts.
        let sq = rectangle(Vec3::new(-1.0, 2.0, -1.0), Vec3::new(2.0, 0.0, 0.0), Vec3::new(0.0, 0.0, 2.0));
        let upper = rectangle(Vec3::new(-1.0, 2.0, 0.0), Vec3::new(2.0, 0.0, 0.0), Vec3::new(0.0, 0.0, 1.0));
        let (a, b) = (point_to_polygon(Vec3::ZERO, Vec3::Z, &sq), point_to_polygon(Vec3::ZERO, Vec3::Z, &upper));
        assert!(a > 0.0 && (a - b).abs() < 1e-15, "{a} vs {b}");
        assert_eq!(point_to_polygon(Vec3::ZERO, Vec3::NEG_Z, &upper), 0.0);
    }
}

/// The course's hemicube: the five faces (the top `z = 1` and the four half sides) of the cube
/// `[−1, 1]² × [0, 1]` over a point, each face `resolution` pixels across (the sides half as
/// high). Each pixel has its *delta form factor*, the area its image takes under Nusselt's
/// double projection over `π`: `ΔA / (π (x² + y² + 1)²)` on the top, `z ΔA / (π (y² + z² + 1)²)`
/// on a side; they add up to 1 less the discretisation error.
#[derive(Clone, Debug)]
pub struct Hemicube {
    /// Per pixel: its direction in the frame `(s, t, n)` (not unit) and delta form factor.
    pub pixels: Vec<(Vec3, f64)>,
}

impl Hemicube {
    /// The hemicube of `resolution` pixels across the top (even, at least 2).
    pub fn new(resolution: u32) -> Self {
        let r = resolution.max(2) & !1;
        let step = 2.0 / r as f64;
        let area = step * step;
        let mut pixels = Vec::with_capacity((3 * r * r) as usize);
        let at = |i: u32| -1.0 + (i as f64 + 0.5) * step;
        for i in 0..r {
            for j in 0..r {
                let (x, y) = (at(i), at(j));
                pixels.push((Vec3::new(x, y, 1.0), area / (std::f64::consts::PI * (x * x + y * y + 1.0).powi(2))));
            }
        }
        // The four sides: u across the side, z up it.
        for side in 0..4 {
            for i in 0..r {
                for k in 0..r / 2 {
                    let (u, z) = (at(i), (k as f64 + 0.5) * step);
                    let d = match side {
                        0 => Vec3::new(1.0, u, z),
                        1 => Vec3::new(-1.0, u, z),
                        2 => Vec3::new(u, 1.0, z),
                        _ => Vec3::new(u, -1.0, z),
                    };
                    pixels.push((d, z * area / (std::f64::consts::PI * (u * u + z * z + 1.0).powi(2))));
                }
            }
        }
        Self { pixels }
    }

    /// The delta form factors gathered by what each pixel sees from `p` (unit normal `n`):
    /// `seen(origin, unit direction)` names the element a pixel's ray meets first (the course's
    /// item buffer, filled by ray casting instead of five projections), or `None`. Calls
    /// `add(element, ΔF)` pixel by pixel, in a fixed order.
    pub fn gather<K>(&self, p: Vec3, n: Vec3, seen: impl Fn(Vec3, Vec3) -> Option<K>, mut add: impl FnMut(K, f64)) {
        let (s, t) = alhazen_math::orthonormal_basis(n);
        for &(d, df) in &self.pixels {
            let dir = (s * d.x + t * d.y + n * d.z).normalize();
            if let Some(k) = seen(p, dir) {
                add(k, df);
            }
        }
    }
}

#[cfg(test)]
mod hemicube_tests {
    use super::*;

    #[test]
    fn the_delta_form_factors_add_up_to_one() {
        for r in [20, 100, 300] {
            let sum: f64 = Hemicube::new(r).pixels.iter().map(|p| p.1).sum();
            assert!((sum - 1.0).abs() < 2.0 / r as f64, "{r}: {sum}");
        }
    }

    #[test]
    fn the_hemicube_agrees_with_lambert_on_a_square() {
        // A unit square above the point, offset: what the hemicube's pixels see of it.
        let corner = Vec3::new(-0.2, 0.1, 0.7);
        let (e1, e2) = (Vec3::X, Vec3::Y);
        let square = Polygon::of(&[corner, corner + e1, corner + e1 + e2, corner + e2]);
        let seen = |o: Vec3, d: Vec3| {
            let t = (corner.z - o.z) / d.z;
            let q = o + d * t;
            (t > 0.0 && (0.0..=1.0).contains(&(q.x - corner.x)) && (0.0..=1.0).contains(&(q.y - corner.y)))
                .then_some(())
        };
        let mut f = 0.0;
        Hemicube::new(200).gather(Vec3::ZERO, Vec3::Z, seen, |_, df| f += df);
        let exact = point_to_polygon(Vec3::ZERO, Vec3::Z, &square);
        assert!((f - exact).abs() < 0.01 * exact, "hemicube {f}, Lambert {exact}");
    }
}
