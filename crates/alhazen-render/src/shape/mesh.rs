//! Triangle meshes: Möller–Trumbore intersection over a per-mesh BVH. One [`MeshAccel`] is
//! shared by every instance of the mesh (instancing = one mesh, many transforms).

use super::{Candidate, Crossing, SurfaceHit};
use crate::bvh::Bvh;
use alhazen_geom::TriangleMesh;
use alhazen_math::{Bounds3, Ray, Vec2, Vec3};
use std::sync::Arc;

/// A mesh with its acceleration structure.
#[derive(Debug)]
pub struct MeshAccel {
    /// The mesh.
    pub mesh: Arc<TriangleMesh>,
    bvh: Bvh,
    /// Unit geometric normal per triangle (zero for triangles without area).
    face_normals: Vec<Vec3>,
    /// Per triangle: its vertex normals all equal its face normal (smooth shading would only
    /// interpolate it back).
    flat: Vec<bool>,
}

impl MeshAccel {
    /// Builds the triangle BVH.
    pub fn new(mesh: Arc<TriangleMesh>) -> Self {
        let bounds: Vec<Bounds3> = (0..mesh.triangle_count()).map(|i| Bounds3::from_points(mesh.corners(i))).collect();
        let face_normals: Vec<Vec3> = (0..mesh.triangle_count())
            .map(|i| {
                let [a, b, c] = mesh.corners(i);
                (b - a).cross(c - a).normalize_or_zero()
            })
            .collect();
        let flat = mesh
            .triangles
            .iter()
            .zip(&face_normals)
            .map(|(t, n): (&[u32; 3], &Vec3)| {
                mesh.normals.is_empty() || t.iter().all(|&i| (mesh.normals[i as usize] - *n).length() < 1e-12)
            })
            .collect();
        Self { bvh: Bvh::build(&bounds), mesh, face_normals, flat }
    }
}

/// An instance of a mesh.
#[derive(Clone, Debug)]
pub struct MeshShape {
    /// Shared geometry.
    pub accel: Arc<MeshAccel>,
    /// Interpolate vertex normals when the mesh has them.
    pub smooth: bool,
}

/// Barycentric hit `(t, b1, b2)` of Möller–Trumbore, for any `t`.
#[inline]
pub fn triangle_hit(ray: &Ray, [p0, p1, p2]: [Vec3; 3]) -> Option<(f64, f64, f64)> {
    let (e1, e2) = (p1 - p0, p2 - p0);
    let pv = ray.dir.cross(e2);
    let det = e1.dot(pv);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let inv = 1.0 / det;
    let tv = ray.origin - p0;
    let b1 = tv.dot(pv) * inv;
    if !(0.0..=1.0).contains(&b1) {
        return None;
    }
    let qv = tv.cross(e1);
    let b2 = ray.dir.dot(qv) * inv;
    if b2 < 0.0 || b1 + b2 > 1.0 {
        return None;
    }
    Some((e2.dot(qv) * inv, b1, b2))
}

impl MeshShape {
    fn surface(&self, ray: &Ray, tri: usize, (t, b1, b2): (f64, f64, f64)) -> SurfaceHit {
        let m = &self.accel.mesh;
        let idx = m.triangles[tri].map(|i| i as usize);
        let n = self.accel.face_normals[tri];
        let b0 = 1.0 - b1 - b2;
        let ns = if self.smooth && !self.accel.flat[tri] {
            let s = m.normals[idx[0]] * b0 + m.normals[idx[1]] * b1 + m.normals[idx[2]] * b2;
            // Keep the shading normal on the geometric normal's side.
            s.try_normalize().map_or(n, |s| if s.dot(n) < 0.0 { -s } else { s })
        } else {
            n
        };
        let uv = if m.uvs.is_empty() {
            Vec2::new(b1, b2)
        } else {
            m.uvs[idx[0]] * b0 + m.uvs[idx[1]] * b1 + m.uvs[idx[2]] * b2
        };
        let slot = m.material_slots.get(tri).copied().unwrap_or(0);
        SurfaceHit { t, p: ray.at(t), n, ns, uv, slot, dpduv: [Vec3::ZERO; 2] }
    }

    /// `∂p/∂u`, `∂p/∂v` of triangle `tri` from its texture coordinates (its barycentric
    /// parametrisation when the mesh has none).
    pub fn tangents(&self, tri: usize) -> [Vec3; 2] {
        let m = &self.accel.mesh;
        let idx = m.triangles[tri].map(|i| i as usize);
        let [p0, p1, p2] = idx.map(|i| m.positions[i]);
        if m.uvs.is_empty() {
            return [p1 - p0, p2 - p0];
        }
        alhazen_scene::texture::uv_tangents([p0, p1, p2], idx.map(|i| m.uvs[i]))
    }

    /// Nearest hit in `(0, t_max)`; `aux` is the triangle.
    pub fn hit(&self, ray: &Ray, t_max: f64) -> Option<Candidate> {
        let m = &self.accel.mesh;
        let mut best = None;
        self.accel.bvh.traverse(ray, t_max, |i, t_max| {
            let h = triangle_hit(ray, m.corners(i as usize)).filter(|h| h.0 > 0.0 && h.0 < t_max)?;
            best = Some(Candidate { t: h.0, aux: i, bary: [h.1, h.2] });
            Some(h.0)
        });
        best
    }

    /// The surface at a hit found by [`MeshShape::hit`].
    pub fn surface_at(&self, ray: &Ray, c: Candidate) -> SurfaceHit {
        self.surface(ray, c.aux as usize, (c.t, c.bary[0], c.bary[1]))
    }

    /// Every triangle crossing of the whole line; entering where the ray meets the front.
    pub fn crossings(&self, ray: &Ray, out: &mut Vec<Crossing>) {
        // Move the origin behind the mesh so the whole line lies at t > 0 for the BVH.
        let b = self.bounds();
        let back = (b.centroid() - ray.origin).dot(ray.dir) / ray.dir.length_squared()
            - b.extent().length() / ray.dir.length()
            - 1.0;
        let back = back.min(0.0);
        let shifted = Ray::new(ray.at(back), ray.dir);
        let m = &self.accel.mesh;
        self.accel.bvh.traverse(&shifted, f64::INFINITY, |i, _| {
            if let Some((t, b1, b2)) = triangle_hit(&shifted, m.corners(i as usize)).filter(|h| h.0 > 0.0) {
                let hit = self.surface(ray, i as usize, (t + back, b1, b2));
                out.push(Crossing { hit, entering: hit.n.dot(ray.dir) < 0.0 });
            }
            None
        });
    }

    /// Bounding box.
    pub fn bounds(&self) -> Bounds3 {
        self.accel.bvh.bounds()
    }
}
