//! Overlapping reflexes of polygons (Glaeser §4, Theorems 6–9, equations (18)–(28)).
//!
//! A polygon's carrier plane `β` meets the mirror in a curve `c` (an ellipse on a cylinder of
//! revolution, a small circle on a sphere). Where the eye's ray reflected at a point `C` of `c`
//! lies in `β` — equivalently, where the point `E*` of the reflected ray with `CE* = CE` lies in
//! `β` — every point of `β` on the line `CE*` reflects to `C`: the line is "projecting", and a
//! polygon crossing it folds over in the mirror (its reflex overlaps itself). These lines are the
//! "contour" of the plane (Theorem 9: at most four on a cylinder, two on a sphere). A polygon is
//! split along those that cross it; its pieces' reflexes then do not overlap (Theorems 6–8).
//!
//! The cylinder's points come from the quartic (22) in `u = r cos φ` (Theorem 7), the sphere's
//! from the linear equation (27) under condition (28) (Theorem 8), each in the paper's frame:
//! the eye on the `x` axis, the cylinder's axis the `z` axis, the sphere's centre the origin.
//! Only points `C` the eye sees (the reflection on the outside) count. Where the paper's
//! formulas divide by zero (a sphere's plane through its centre or normal to the axis `ME`), the
//! curve `c` is searched numerically for sign changes of `E*`'s side of `β`.

use crate::poly::real_roots_in;
use crate::{Cylinder, MirrorError, Sphere};
use alhazen_math::Vec3;

/// A plane `normal · x = offset` (unit normal).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    /// Unit normal.
    pub normal: Vec3,
    /// `normal · x` on the plane.
    pub offset: f64,
}

impl Plane {
    /// The plane through `point` with normal `normal` (normalised); `None` for a zero normal.
    pub fn through(point: Vec3, normal: Vec3) -> Option<Self> {
        let n = normal.try_normalize()?;
        Some(Plane { normal: n, offset: n.dot(point) })
    }

    /// The carrier plane of a polygon (Newell's normal); `None` when it has no area.
    pub fn of_polygon(poly: &[Vec3]) -> Option<Self> {
        let mut n = Vec3::ZERO;
        for (i, a) in poly.iter().enumerate() {
            let b = poly[(i + 1) % poly.len()];
            n += Vec3::new((a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y));
        }
        let centroid = poly.iter().sum::<Vec3>() / poly.len().max(1) as f64;
        Plane::through(centroid, n)
    }

    fn side(&self, p: Vec3) -> f64 {
        self.normal.dot(p) - self.offset
    }
}

/// A projecting line of a plane: the mirror point `C` and the unit direction of the eye's ray
/// reflected there, which lies in the plane. Every point `C + t·direction` (`t > 0`) of the
/// plane reflects to `C`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProjectingLine {
    /// The mirror point `C` (on the plane).
    pub mirror_point: Vec3,
    /// Unit direction of the reflected ray `CE*`.
    pub direction: Vec3,
}

/// The eye's ray reflected at mirror point `c` with outward normal `n`: unit direction.
fn reflected(eye: Vec3, c: Vec3, n: Vec3) -> Vec3 {
    let d = (c - eye).normalize();
    (d - n * (2.0 * d.dot(n))).normalize()
}

impl Cylinder {
    /// The projecting lines of `plane` seen from `eye` (Theorems 7 and 9): at most four. None
    /// when the plane is parallel to the axis (it then meets the cylinder in generating lines,
    /// or not at all).
    pub fn projecting_lines(&self, eye: Vec3, plane: Plane) -> Result<Vec<ProjectingLine>, MirrorError> {
        self.check_eye(eye)?;
        let z = self.axis.normalize();
        let foot = self.center + z * (eye - self.center).dot(z);
        let e = (eye - foot).length();
        let x = (eye - foot) / e;
        let y = z.cross(x);
        let r = self.radius;
        // β in the frame: n_x x + n_y y + n_z z = c, i.e. z = a x + b y + d (18).
        let (nx, ny, nz) = (plane.normal.dot(x), plane.normal.dot(y), plane.normal.dot(z));
        if nz.abs() <= 1e-12 {
            return Ok(vec![]);
        }
        let (a, b, d) = (-nx / nz, -ny / nz, plane.side(foot) / -nz);
        let v = a * a + b * b;
        // The quartic (22) in u = r cos φ.
        let g = [
            r.powi(4) / 4.0 * (a * a * e * e + d * d + 2.0 * a * d * e - 4.0 * b * b * r * r),
            r.powi(4) * (a * d + a * a * e + 2.0 * b * b * e),
            r * r * (r * r * v - e * e * v - a * d * e),
            -2.0 * e * r * r * v,
            e * e * v,
        ];
        let to_world = |p: Vec3| foot + x * p.x + y * p.y + z * p.z;
        let mut lines = vec![];
        for &u in real_roots_in(&g, -r, r).as_slice() {
            // Only the eye's side of the cylinder: the reflection on the outside.
            if u <= r * r / e {
                continue;
            }
            let s_abs = (r * r - u * u).max(0.0).sqrt();
            // Undo the squaring: the sign of r sin φ the unsquared condition asks for.
            for s in [s_abs, -s_abs] {
                if s_abs == 0.0 && s < 0.0 {
                    continue;
                }
                let c = Vec3::new(u, s, a * u + b * s + d);
                let (cos2, sin2) = ((2.0 * u * u - r * r) / (r * r), 2.0 * u * s / (r * r));
                let e_star = Vec3::new(e * cos2, e * sin2, 2.0 * c.z);
                let scale = r.max(e).max(c.z.abs()).max(d.abs());
                if (e_star.z - (a * e_star.x + b * e_star.y + d)).abs() > 1e-7 * scale {
                    continue;
                }
                let (cw, ew) = (to_world(c), to_world(e_star));
                lines.push(ProjectingLine { mirror_point: cw, direction: (ew - cw).normalize() });
            }
        }
        Ok(lines)
    }
}

impl Sphere {
    /// The projecting lines of `plane` seen from `eye` (Theorems 8 and 9): at most two,
    /// symmetric about the plane through the eye, the centre and the plane's normal.
    pub fn projecting_lines(&self, eye: Vec3, plane: Plane) -> Result<Vec<ProjectingLine>, MirrorError> {
        let r = self.radius;
        if !(r > 0.0 && r.is_finite()) {
            return Err(MirrorError::InvalidRadius);
        }
        let to_eye = eye - self.center;
        let e = to_eye.length();
        if !e.is_finite() || e <= r * (1.0 + 1e-12) {
            return Err(if e < 1e-300 { MirrorError::EyeOnAxis } else { MirrorError::EyeOnMirror });
        }
        let x = to_eye / e;
        // Rotate about the x axis so that β is parallel to z (23): its normal in the xy plane.
        let side = plane.normal - x * plane.normal.dot(x);
        let b = side.length();
        let d = -plane.side(self.center);
        if d.abs() > r {
            return Ok(vec![]); // β misses the sphere: no overlapping (Theorem 6)
        }
        let r0 = (r * r - d * d).sqrt();
        let a = plane.normal.dot(x);
        if b <= 1e-9 || d.abs() <= 1e-9 * r {
            return Ok(self.projecting_lines_searched(eye, plane));
        }
        let y = side / b;
        let z = x.cross(y);
        // (27), under condition (28).
        let u = (2.0 * a * d * d * e - r * r * (a * e + d)) / (2.0 * b * d * e);
        if u.abs() >= r0 {
            return Ok(vec![]);
        }
        let h = (r0 * r0 - u * u).sqrt();
        let mut lines = vec![];
        for zc in [h, -h] {
            // (25): the point of c₀; (26): E* by reflecting E on the normal through it.
            let c = Vec3::new(a * d - b * u, b * d + a * u, zc);
            if c.x <= r * r / e {
                continue; // not seen from the eye
            }
            let lambda = 2.0 * e * c.x / (r * r);
            let e_star = c * lambda - Vec3::new(e, 0.0, 0.0);
            let to_world = |p: Vec3| self.center + x * p.x + y * p.y + z * p.z;
            let (cw, ew) = (to_world(c), to_world(e_star));
            lines.push(ProjectingLine { mirror_point: cw, direction: (ew - cw).normalize() });
            if h == 0.0 {
                break;
            }
        }
        Ok(lines)
    }

    /// The projecting lines by searching the circle `β ∩ Φ` for sign changes of the reflected
    /// ray's side of `β` (where (27) divides by zero).
    fn projecting_lines_searched(&self, eye: Vec3, plane: Plane) -> Vec<ProjectingLine> {
        let d = -plane.side(self.center);
        let r0 = (self.radius * self.radius - d * d).max(0.0).sqrt();
        let centre = self.center + plane.normal * d;
        let (s, t) = alhazen_math::orthonormal_basis(plane.normal);
        let at = |phi: f64| centre + (s * phi.cos() + t * phi.sin()) * r0;
        let side = |phi: f64| {
            let c = at(phi);
            let n = (c - self.center) / self.radius;
            if n.dot(eye - c) <= 0.0 { None } else { Some(plane.normal.dot(reflected(eye, c, n))) }
        };
        search_circle(side)
            .into_iter()
            .map(|phi| {
                let c = at(phi);
                ProjectingLine { mirror_point: c, direction: reflected(eye, c, (c - self.center) / self.radius) }
            })
            .collect()
    }
}

/// Parameters in `[0, 2π)` where `f` (defined on the visible part) changes sign, refined by
/// bisection: 4096 steps, then 60 halvings.
fn search_circle(f: impl Fn(f64) -> Option<f64>) -> Vec<f64> {
    const STEPS: usize = 4096;
    let tau = std::f64::consts::TAU;
    let mut out = vec![];
    for k in 0..STEPS {
        let (mut lo, mut hi) = (tau * k as f64 / STEPS as f64, tau * (k + 1) as f64 / STEPS as f64);
        let (Some(mut flo), Some(fhi)) = (f(lo), f(hi)) else { continue };
        if flo == 0.0 {
            out.push(lo);
            continue;
        }
        if flo * fhi > 0.0 || fhi == 0.0 {
            continue;
        }
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            match f(mid) {
                Some(fm) if fm * flo > 0.0 => (lo, flo) = (mid, fm),
                Some(_) => hi = mid,
                None => break,
            }
        }
        out.push(0.5 * (lo + hi));
    }
    out
}

/// Splits the planar polygon `poly` along those of `lines` (in its plane) that cross it: the
/// pieces whose reflexes do not fold over. Lines that miss it leave it whole.
pub fn split_polygon(poly: &[Vec3], lines: &[ProjectingLine]) -> Vec<Vec<Vec3>> {
    let Some(plane) = Plane::of_polygon(poly) else { return vec![poly.to_vec()] };
    let mut pieces = vec![poly.to_vec()];
    for line in lines {
        // The half-planes either side of the line within β.
        let across = plane.normal.cross(line.direction).normalize();
        let offset = across.dot(line.mirror_point);
        let mut next = vec![];
        for piece in pieces {
            let f = |p: Vec3| across.dot(p) - offset;
            let (front, back) = (cut(&piece, &f, 1.0), cut(&piece, &f, -1.0));
            if front.len() >= 3 && back.len() >= 3 {
                next.push(front);
                next.push(back);
            } else {
                next.push(piece);
            }
        }
        pieces = next;
    }
    pieces
}

/// Sutherland–Hodgman: the part of `poly` where `sign · f ≥ 0`.
fn cut(poly: &[Vec3], f: &impl Fn(Vec3) -> f64, sign: f64) -> Vec<Vec3> {
    let mut out = vec![];
    for (i, &a) in poly.iter().enumerate() {
        let b = poly[(i + 1) % poly.len()];
        let (fa, fb) = (sign * f(a), sign * f(b));
        if fa >= 0.0 {
            out.push(a);
        }
        if (fa > 0.0 && fb < 0.0) || (fa < 0.0 && fb > 0.0) {
            out.push(a + (b - a) * (fa / (fa - fb)));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Site;
    use proptest::prelude::*;

    /// The curve `β ∩ Φ` searched numerically (the test's independent oracle): parameters of
    /// `c(φ)` where the reflected ray crosses `β`, mapped to points.
    fn searched(points: impl Fn(f64) -> Option<(Vec3, Vec3)>, eye: Vec3, plane: Plane) -> Vec<Vec3> {
        let side = |phi: f64| {
            let (c, n) = points(phi)?;
            (n.dot(eye - c) > 0.0).then(|| plane.normal.dot(reflected(eye, c, n)))
        };
        search_circle(side).into_iter().filter_map(|phi| points(phi).map(|(c, _)| c)).collect()
    }

    fn check_line(
        line: &ProjectingLine,
        plane: Plane,
        eye: Vec3,
        on_mirror: impl Fn(Vec3) -> f64,
        reflex: impl Fn(Vec3) -> Option<Vec3>,
    ) -> Result<(), TestCaseError> {
        let c = line.mirror_point;
        prop_assert!(on_mirror(c).abs() < 1e-8, "C on the mirror: {}", on_mirror(c));
        prop_assert!(plane.side(c).abs() < 1e-8, "C in β: {}", plane.side(c));
        prop_assert!(line.direction.dot(plane.normal).abs() < 1e-7, "the ray lies in β");
        // Points of β along the line reflect to C (where they are not hidden behind the mirror).
        for t in [0.5, 1.5, 4.0] {
            let p = c + line.direction * t;
            if let Some(r) = reflex(p) {
                prop_assert!((r - c).length() < 1e-6, "{p} reflects to {r}, not {c}");
            }
        }
        let _ = eye;
        Ok(())
    }

    proptest! {
        #[test]
        fn a_spheres_projecting_lines_are_those_of_a_search_and_project(
            eye in (2.0..6.0f64, -3.0..3.0f64, -3.0..3.0f64),
            n in (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64),
            offset in -0.95..0.95f64,
        ) {
            let sphere = Sphere { center: Vec3::new(0.3, -0.2, 0.1), radius: 1.0 };
            let eye = Vec3::new(eye.0, eye.1, eye.2);
            let Some(plane) = Plane::through(sphere.center + Vec3::new(n.0, n.1, n.2).normalize_or(Vec3::X) * offset, Vec3::new(n.0, n.1, n.2)) else { return Ok(()) };
            let lines = sphere.projecting_lines(eye, plane).unwrap();
            prop_assert!(lines.len() <= 2);
            for l in &lines {
                check_line(l, plane, eye, |p| (p - sphere.center).length() - 1.0, |p| {
                    sphere.visible_reflex(Site::At(eye), Site::At(p)).ok().flatten().map(|r| r.point)
                })?;
            }
            let d = -plane.side(sphere.center);
            let r0 = (1.0 - d * d).sqrt();
            let (s, t) = alhazen_math::orthonormal_basis(plane.normal);
            let found = searched(|phi| {
                let c = sphere.center + plane.normal * d + (s * phi.cos() + t * phi.sin()) * r0;
                Some((c, c - sphere.center))
            }, eye, plane);
            prop_assert_eq!(lines.len(), found.len(), "closed form {:?} vs search {:?}", lines, found);
            for f in &found {
                prop_assert!(lines.iter().any(|l| (l.mirror_point - *f).length() < 1e-6));
            }
        }

        #[test]
        fn a_cylinders_projecting_lines_are_those_of_a_search_and_project(
            eye in (2.0..6.0f64, -3.0..3.0f64, -3.0..3.0f64),
            n in (-1.0..1.0f64, -1.0..1.0f64, 0.2..1.0f64),
            height in -2.0..2.0f64,
        ) {
            let cyl = Cylinder { center: Vec3::new(0.2, 0.0, -0.1), axis: Vec3::new(0.1, 1.0, 0.2), radius: 1.0 };
            let axis = cyl.axis.normalize();
            let eye = Vec3::new(eye.0, eye.1, eye.2);
            // Planes not parallel to the axis: the normal has a component along it.
            let normal = Vec3::new(n.0, n.1, n.2).normalize() + axis * 0.3;
            let Some(plane) = Plane::through(cyl.center + axis * height, normal) else { return Ok(()) };
            prop_assume!(plane.normal.dot(axis).abs() > 0.05);
            let lines = cyl.projecting_lines(eye, plane).unwrap();
            prop_assert!(lines.len() <= 4);
            let dist = |p: Vec3| { let q = p - cyl.center; (q - axis * q.dot(axis)).length() - 1.0 };
            for l in &lines {
                check_line(l, plane, eye, dist, |p| cyl.visible_reflex(Site::At(eye), Site::At(p)).ok().flatten().map(|r| r.point))?;
            }
            let (s, t) = alhazen_math::orthonormal_basis(axis);
            let found = searched(|phi| {
                let radial = s * phi.cos() + t * phi.sin();
                let base = cyl.center + radial;
                // The point of the generating line through `base` in β.
                let k = -plane.side(base) / plane.normal.dot(axis);
                Some((base + axis * k, radial))
            }, eye, plane);
            prop_assert_eq!(lines.len(), found.len(), "closed form {:?} vs search {:?}", lines, found);
            for f in &found {
                prop_assert!(lines.iter().any(|l| (l.mirror_point - *f).length() < 1e-6));
            }
        }
    }

    #[test]
    fn planes_through_a_mirror_often_have_projecting_lines_and_the_fallback_finds_them_too() {
        let sphere = Sphere { center: Vec3::ZERO, radius: 1.0 };
        let cyl = Cylinder { center: Vec3::ZERO, axis: Vec3::Y, radius: 1.0 };
        let eye = Vec3::new(4.0, 0.5, 0.3);
        let (mut on_sphere, mut on_cylinder) = (0, 0);
        for k in 0..200 {
            let f = k as f64;
            let n = Vec3::new((f * 0.37).sin(), (f * 0.71).cos(), (f * 1.13).sin() + 0.2);
            let plane = Plane::through(Vec3::new(0.0, (f * 0.53).sin() * 0.9, 0.0), n).unwrap();
            on_sphere += sphere.projecting_lines(eye, plane).unwrap().len().min(1);
            on_cylinder += cyl.projecting_lines(eye, plane).unwrap().len().min(1);
        }
        assert!(on_sphere > 20 && on_cylinder > 20, "{on_sphere} {on_cylinder} of 200 planes");
        // A plane through the sphere's centre: (27) divides by zero; the search answers.
        let plane = Plane::through(Vec3::ZERO, Vec3::new(0.2, 1.0, -0.4)).unwrap();
        for l in sphere.projecting_lines(eye, plane).unwrap() {
            let p = l.mirror_point + l.direction * 2.0;
            let r = sphere.visible_reflex(Site::At(eye), Site::At(p)).unwrap().unwrap().point;
            assert!((r - l.mirror_point).length() < 1e-6);
        }
    }

    #[test]
    fn a_polygon_across_a_projecting_line_is_split_there_and_keeps_its_area() {
        // Fig. 18's situation: a large square in a plane cutting the sphere near the eye's side.
        let sphere = Sphere { center: Vec3::ZERO, radius: 1.0 };
        let eye = Vec3::new(5.0, 0.0, 0.0);
        let plane = Plane::through(Vec3::new(0.0, 0.6, 0.0), Vec3::new(0.3, 1.0, 0.2)).unwrap();
        let lines = sphere.projecting_lines(eye, plane).unwrap();
        assert_eq!(lines.len(), 2, "{lines:?}");
        let (s, t) = alhazen_math::orthonormal_basis(plane.normal);
        let centre = lines[0].mirror_point + lines[0].direction * 1.5;
        let square: Vec<Vec3> = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
            .iter()
            .map(|&(a, b)| centre + (s * a + t * b) * 2.0)
            .collect();
        let pieces = split_polygon(&square, &lines);
        assert!(pieces.len() >= 2, "{}", pieces.len());
        let area = |p: &[Vec3]| {
            let n = (1..p.len() - 1).fold(Vec3::ZERO, |acc, k| acc + (p[k] - p[0]).cross(p[k + 1] - p[0]));
            n.length() / 2.0
        };
        let total: f64 = pieces.iter().map(|p| area(p)).sum();
        assert!((total - 16.0).abs() < 1e-9, "{total}");
        // No piece crosses a line.
        for piece in &pieces {
            for l in &lines {
                let across = plane.normal.cross(l.direction);
                let sides: Vec<f64> = piece.iter().map(|p| across.dot(*p - l.mirror_point)).collect();
                assert!(sides.iter().all(|x| *x >= -1e-9) || sides.iter().all(|x| *x <= 1e-9));
            }
        }
        // A plane that misses the sphere has no projecting lines (Theorem 6).
        let far = Plane::through(Vec3::new(0.0, 2.0, 0.0), Vec3::Y).unwrap();
        assert!(sphere.projecting_lines(eye, far).unwrap().is_empty());
    }
}
