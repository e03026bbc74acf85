//! Turning curves' and surfaces' exact descriptions into triangle meshes for the renderers:
//! polygon meshes by fan triangulation, patches on a grid refined until the chordal error is
//! within a tolerance, with shading normals from the exact surface.

use crate::TriangleMesh;
use crate::bezier::ControlPoint;
use crate::halfedge::HalfedgeMesh;
use crate::patch::{BSplinePatch, BezierPatch, rational_normal};
use alhazen_math::{Vec2, Vec3, Vec4};

/// Fan-triangulates every facet; vertex normals are area-weighted.
pub fn polygons_to_triangles(m: &HalfedgeMesh) -> TriangleMesh {
    let mut t = TriangleMesh { positions: m.positions.clone(), ..TriangleMesh::default() };
    for poly in m.polygons() {
        for k in 1..poly.len() - 1 {
            t.triangles.push([poly[0] as u32, poly[k] as u32, poly[k + 1] as u32]);
        }
    }
    t.compute_smooth_normals();
    t
}

/// A surface `(u, v) ∈ [0, 1]² ↦ (point, unit normal)`.
pub trait Surface {
    /// Point and unit normal at `(u, v)` in the unit square.
    fn sample(&self, u: f64, v: f64) -> (Vec3, Vec3);

    /// The point alone (the same as `sample(u, v).0`, possibly cheaper).
    fn point(&self, u: f64, v: f64) -> Vec3 {
        self.sample(u, v).0
    }
}

impl Surface for BezierPatch<Vec3> {
    fn sample(&self, u: f64, v: f64) -> (Vec3, Vec3) {
        let (p, pu, pv) = self.partials(u, v);
        (p, pu.cross(pv).try_normalize().unwrap_or(Vec3::Z))
    }

    fn point(&self, u: f64, v: f64) -> Vec3 {
        self.eval(u, v)
    }
}

impl Surface for BezierPatch<Vec4> {
    fn sample(&self, u: f64, v: f64) -> (Vec3, Vec3) {
        let (h, hu, hv) = self.partials(u, v);
        (h.truncate() / h.w, rational_normal(h, hu, hv).unwrap_or(Vec3::Z))
    }

    fn point(&self, u: f64, v: f64) -> Vec3 {
        let h = self.eval(u, v);
        h.truncate() / h.w
    }
}

/// The parameters of `s` at `(u, v)` in the unit square.
fn in_domain<P: ControlPoint>(s: &BSplinePatch<P>, u: f64, v: f64) -> (f64, f64) {
    let ((u0, u1), (v0, v1)) = s.domain();
    (u0 + (u1 - u0) * u, v0 + (v1 - v0) * v)
}

impl Surface for BSplinePatch<Vec3> {
    fn sample(&self, u: f64, v: f64) -> (Vec3, Vec3) {
        let (uu, vv) = in_domain(self, u, v);
        let (p, pu, pv) = self.partials(uu, vv);
        (p, pu.cross(pv).try_normalize().unwrap_or(Vec3::Z))
    }

    fn point(&self, u: f64, v: f64) -> Vec3 {
        let (uu, vv) = in_domain(self, u, v);
        self.eval(uu, vv)
    }
}

impl Surface for BSplinePatch<Vec4> {
    fn sample(&self, u: f64, v: f64) -> (Vec3, Vec3) {
        let (uu, vv) = in_domain(self, u, v);
        let (h, hu, hv) = self.partials(uu, vv);
        (h.truncate() / h.w, rational_normal(h, hu, hv).unwrap_or(Vec3::Z))
    }

    fn point(&self, u: f64, v: f64) -> Vec3 {
        let (uu, vv) = in_domain(self, u, v);
        let h = self.eval(uu, vv);
        h.truncate() / h.w
    }
}

/// The largest distance between the surface at cell centres and edge midpoints and the
/// triangles of a `k × k` grid.
fn chordal_error<S: Surface>(s: &S, k: usize) -> f64 {
    let h = 1.0 / k as f64;
    let corners: Vec<Vec3> =
        (0..=k).flat_map(|i| (0..=k).map(move |j| (i, j))).map(|(i, j)| s.point(i as f64 * h, j as f64 * h)).collect();
    let corner = |i: usize, j: usize| corners[i * (k + 1) + j];
    let mut worst = 0.0f64;
    for i in 0..k {
        for j in 0..k {
            let (u, v) = (i as f64 * h, j as f64 * h);
            let (p00, p10, p01, p11) = (corner(i, j), corner(i + 1, j), corner(i, j + 1), corner(i + 1, j + 1));
            for (su, sv, approx) in
                [(0.5, 0.5, (p00 + p11) * 0.5), (0.5, 0.0, (p00 + p10) * 0.5), (0.0, 0.5, (p00 + p01) * 0.5)]
            {
                worst = worst.max((s.point(u + su * h, v + sv * h) - approx).length());
            }
        }
    }
    worst
}

/// A triangle mesh of `s` whose grid is doubled until the chordal error (measured at cell
/// centres and edge midpoints) is below `tolerance`, up to 256 × 256 cells. Texture coordinates
/// are the parameters.
pub fn tessellate<S: Surface>(s: &S, tolerance: f64) -> TriangleMesh {
    let mut k = 2;
    while k < 256 && chordal_error(s, k) > tolerance {
        k *= 2;
    }
    let mut m = TriangleMesh::default();
    for i in 0..=k {
        for j in 0..=k {
            let (u, v) = (i as f64 / k as f64, j as f64 / k as f64);
            let (p, n) = s.sample(u, v);
            m.positions.push(p);
            m.normals.push(n);
            m.uvs.push(Vec2::new(u, v));
        }
    }
    let at = |i: usize, j: usize| (i * (k + 1) + j) as u32;
    for i in 0..k {
        for j in 0..k {
            m.triangles.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            m.triangles.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    m
}

/// A tube of `radius` around a polyline (for drawing curves in images): a ring of `sides`
/// vertices per point, oriented by parallel transport.
pub fn tube<P: ControlPoint + Into<Vec3>>(points: &[P], radius: f64, sides: usize) -> TriangleMesh {
    let pts: Vec<Vec3> = points.iter().map(|&p| p.into()).collect();
    let mut m = TriangleMesh::default();
    if pts.len() < 2 {
        return m;
    }
    let sides = sides.max(3);
    let tangent = |i: usize| (pts[(i + 1).min(pts.len() - 1)] - pts[i.saturating_sub(1)]).normalize_or(Vec3::X);
    let mut normal = alhazen_math::orthonormal_basis(tangent(0)).0;
    for i in 0..pts.len() {
        let t = tangent(i);
        normal = (normal - t * normal.dot(t)).normalize_or(alhazen_math::orthonormal_basis(t).0);
        let binormal = t.cross(normal);
        for s in 0..sides {
            let a = std::f64::consts::TAU * s as f64 / sides as f64;
            let dir = normal * a.cos() + binormal * a.sin();
            m.positions.push(pts[i] + dir * radius);
            m.normals.push(dir);
        }
    }
    for i in 0..pts.len() - 1 {
        for s in 0..sides {
            let (a, b) = ((i * sides + s) as u32, (i * sides + (s + 1) % sides) as u32);
            let (c, d) = (a + sides as u32, b + sides as u32);
            m.triangles.push([a, b, d]);
            m.triangles.push([a, d, c]);
        }
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::patch::Net;

    #[test]
    fn tessellation_error_is_within_tolerance() {
        // A saddle-like bicubic patch.
        let pts: Vec<Vec3> = (0..16)
            .map(|k| Vec3::new((k / 4) as f64, (k % 4) as f64, (((k / 4) as f64 - 1.5) * ((k % 4) as f64 - 1.5)).sin()))
            .collect();
        let p = BezierPatch { net: Net::new(4, 4, pts).unwrap() };
        for tol in [0.1, 0.01, 0.001] {
            let m = tessellate(&p, tol);
            m.validate().unwrap();
            // Independent check on a finer sampling: distance to the nearest vertex plane is
            // bounded by the chordal error at random interior points of the triangles.
            let k = ((m.positions.len() as f64).sqrt() as usize) - 1;
            assert!(chordal_error(&p, k) <= tol, "k = {k}");
            assert!(m.normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-9));
        }
    }

    #[test]
    fn rational_patch_of_a_cylinder_is_exact() {
        // Quarter cylinder: a rational quadratic arc (weights 1, √2/2, 1) extruded.
        let w = std::f64::consts::FRAC_1_SQRT_2;
        let arc = [(Vec3::X, 1.0), (Vec3::new(1.0, 1.0, 0.0), w), (Vec3::Y, 1.0)];
        let pts: Vec<Vec4> =
            arc.iter().flat_map(|&(p, w)| [0.0, 2.0].map(|z| ((p + Vec3::Z * z) * w).extend(w))).collect();
        let patch = BezierPatch { net: Net::new(3, 2, pts).unwrap() };
        let m = tessellate(&patch, 1e-3);
        for (p, n) in m.positions.iter().zip(&m.normals) {
            assert!((p.truncate().length() - 1.0).abs() < 1e-12);
            assert!(
                (n.truncate().normalize() - p.truncate().normalize()).length() < 1e-9
                    || (n.truncate().normalize() + p.truncate().normalize()).length() < 1e-9
            );
        }
    }

    #[test]
    fn subdivided_cube_triangulates_to_a_closed_mesh() {
        let m = crate::subdivision::catmull_clark(&HalfedgeMesh::cube());
        let t = polygons_to_triangles(&m);
        t.validate().unwrap();
        assert_eq!(t.triangle_count(), 2 * m.faces.len());
    }

    #[test]
    fn tubes_have_the_radius() {
        let pts = [Vec3::ZERO, Vec3::X, Vec3::new(2.0, 1.0, 0.0)];
        let m = tube(&pts, 0.1, 8);
        m.validate().unwrap();
        for (k, p) in m.positions.iter().enumerate() {
            assert!(((*p - pts[k / 8]).length() - 0.1).abs() < 1e-12);
        }
    }
}
