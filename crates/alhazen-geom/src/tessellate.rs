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

/// The chordal errors of a `ku × kv` grid: the largest distance between the surface and the
/// grid's segments at the midpoints of `u`-edges, of `v`-edges, and between the surface and the
/// diagonals at cell centres.
fn chordal_errors<S: Surface>(s: &S, ku: usize, kv: usize) -> [f64; 3] {
    let (hu, hv) = (1.0 / ku as f64, 1.0 / kv as f64);
    let corners: Vec<Vec3> = (0..=ku)
        .flat_map(|i| (0..=kv).map(move |j| (i, j)))
        .map(|(i, j)| s.point(i as f64 * hu, j as f64 * hv))
        .collect();
    let corner = |i: usize, j: usize| corners[i * (kv + 1) + j];
    let mut worst = [0.0f64; 3];
    for i in 0..=ku {
        for j in 0..=kv {
            let (u, v) = (i as f64 * hu, j as f64 * hv);
            let p00 = corner(i, j);
            if i < ku {
                let e = (s.point(u + 0.5 * hu, v) - (p00 + corner(i + 1, j)) * 0.5).length();
                worst[0] = worst[0].max(e);
            }
            if j < kv {
                let e = (s.point(u, v + 0.5 * hv) - (p00 + corner(i, j + 1)) * 0.5).length();
                worst[1] = worst[1].max(e);
            }
            if i < ku && j < kv {
                let e = (s.point(u + 0.5 * hu, v + 0.5 * hv) - (p00 + corner(i + 1, j + 1)) * 0.5).length();
                worst[2] = worst[2].max(e);
            }
        }
    }
    worst
}

/// Cells per direction beyond which [`tessellate`] stops refining.
pub const MAX_CELLS_PER_SIDE: usize = 1024;

/// The grid `(ku, kv)` [`tessellate`] uses for `s` at `tolerance`, and its chordal error: each
/// direction doubled on its own while the chordal error along it (or across the cells'
/// diagonals) exceeds the tolerance, up to [`MAX_CELLS_PER_SIDE`] (where the error may stay
/// above the tolerance). A long thin tube gets many cells along and few around.
pub fn grid_for<S: Surface>(s: &S, tolerance: f64) -> (usize, usize, f64) {
    let (mut ku, mut kv) = (2, 2);
    loop {
        let [eu, ev, diagonal] = chordal_errors(s, ku, kv);
        let (mut refine_u, mut refine_v) = (eu > tolerance, ev > tolerance);
        if diagonal > tolerance && !refine_u && !refine_v {
            (refine_u, refine_v) = (true, true);
        }
        let (nu, nv) = (
            if refine_u { (ku * 2).min(MAX_CELLS_PER_SIDE) } else { ku },
            if refine_v { (kv * 2).min(MAX_CELLS_PER_SIDE) } else { kv },
        );
        if (nu, nv) == (ku, kv) {
            return (ku, kv, eu.max(ev).max(diagonal));
        }
        (ku, kv) = (nu, nv);
    }
}

/// A triangle mesh of `s` on the grid of [`grid_for`]: within `tolerance` of the surface at the
/// edges' midpoints and the cells' centres. Texture coordinates are the parameters.
pub fn tessellate<S: Surface>(s: &S, tolerance: f64) -> TriangleMesh {
    let (ku, kv, _) = grid_for(s, tolerance);
    tessellate_grid(s, ku, kv)
}

/// A triangle mesh of `s` on a `ku × kv` grid of the unit square (two triangles a cell).
pub fn tessellate_grid<S: Surface>(s: &S, ku: usize, kv: usize) -> TriangleMesh {
    let (ku, kv) = (ku.max(1), kv.max(1));
    let mut m = TriangleMesh::default();
    for i in 0..=ku {
        for j in 0..=kv {
            let (u, v) = (i as f64 / ku as f64, j as f64 / kv as f64);
            let (p, n) = s.sample(u, v);
            m.positions.push(p);
            m.normals.push(n);
            m.uvs.push(Vec2::new(u, v));
        }
    }
    let at = |i: usize, j: usize| (i * (kv + 1) + j) as u32;
    for i in 0..ku {
        for j in 0..kv {
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
            let (ku, kv, error) = grid_for(&p, tol);
            assert!(error <= tol);
            assert_eq!(m.positions.len(), (ku + 1) * (kv + 1));
            assert!(chordal_errors(&p, ku, kv).iter().all(|e| *e <= tol), "{ku} × {kv}");
            // Independent check: the surface at random parameters against the mesh's triangle there.
            for k in 0..200 {
                let (u, v) = ((k as f64 * 0.618_034).fract(), (k as f64 * 0.414_214).fract());
                let (i, j) = (((u * ku as f64) as usize).min(ku - 1), ((v * kv as f64) as usize).min(kv - 1));
                let (fu, fv) = (u * ku as f64 - i as f64, v * kv as f64 - j as f64);
                let at = |i: usize, j: usize| m.positions[i * (kv + 1) + j];
                let flat = if fu >= fv {
                    at(i, j) + (at(i + 1, j) - at(i, j)) * fu + (at(i + 1, j + 1) - at(i + 1, j)) * fv
                } else {
                    at(i, j) + (at(i, j + 1) - at(i, j)) * fv + (at(i + 1, j + 1) - at(i, j + 1)) * fu
                };
                assert!((p.point(u, v) - flat).length() <= 2.0 * tol, "{u} {v}");
            }
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
