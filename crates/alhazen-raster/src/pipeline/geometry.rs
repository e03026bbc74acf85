//! The scene as world-space triangles for the raster pipeline: meshes transformed, analytic
//! shapes (spheres, cylinders, cones, disks, boxes, planes) tessellated finely enough for a
//! preview. CSG objects have no triangle form here and are skipped (counted).

use alhazen_math::{Transform, Vec2, Vec3};
use alhazen_scene::{Scene, Shape};
use std::f64::consts::PI;

/// A vertex in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vertex {
    /// Position.
    pub p: Vec3,
    /// Unit normal (interpolated for smooth shading).
    pub n: Vec3,
    /// Texture coordinates.
    pub uv: Vec2,
    /// Vertex colour (white where the mesh has none).
    pub color: Vec3,
}

/// A world-space triangle with its material and whether it belongs to a closed surface (only
/// those are back-face culled).
#[derive(Clone, Copy, Debug)]
pub struct Triangle {
    /// Corners, counter-clockwise seen from the outside.
    pub v: [Vertex; 3],
    /// Material index.
    pub material: u32,
    /// Part of a closed surface.
    pub closed: bool,
    /// Part of an infinite plane (left out of shadow-map bounds).
    pub unbounded: bool,
    /// Index of the scene object.
    pub object: u32,
}

/// The triangles of a whole scene and the number of objects that could not be tessellated.
pub struct SceneTriangles {
    /// Triangles.
    pub triangles: Vec<Triangle>,
    /// CSG objects skipped.
    pub skipped: usize,
}

/// Segments around a full turn of a round shape.
const SEGMENTS: usize = 48;

/// A grid of `rows × cols` quads from `f(u, v) → (point, normal, texture coordinates)` on
/// `[0, 1]²`, object space.
fn grid(rows: usize, cols: usize, f: impl Fn(f64, f64) -> (Vec3, Vec3, Vec2)) -> Vec<[Vertex; 3]> {
    let at = |i: usize, j: usize| {
        let (u, v) = (j as f64 / cols as f64, i as f64 / rows as f64);
        let (p, n, uv) = f(u, v);
        Vertex { p, n, uv, color: Vec3::ONE }
    };
    let mut out = Vec::with_capacity(rows * cols * 2);
    for i in 0..rows {
        for j in 0..cols {
            let (a, b, c, d) = (at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i + 1, j));
            out.push([a, b, c]);
            out.push([a, c, d]);
        }
    }
    out
}

/// An orthonormal pair `(s, t)` completing `axis` with `s × t = axis`.
fn basis(axis: Vec3) -> (Vec3, Vec3) {
    let s = alhazen_math::orthonormal_basis(axis).0;
    (s, axis.cross(s))
}

/// A disk of `radius` around `center` facing `normal`, as a fan.
fn disk(center: Vec3, normal: Vec3, radius: f64) -> Vec<[Vertex; 3]> {
    let (s, t) = basis(normal);
    disk_in(center, (s, t), normal, radius)
}

/// A disk in the plane of `s, t` facing `normal` (`±s × t`): the rim points are those of the
/// side of a cylinder built on the same `s, t`, so caps and side share their edges exactly.
fn disk_in(center: Vec3, (s, t): (Vec3, Vec3), normal: Vec3, radius: f64) -> Vec<[Vertex; 3]> {
    let c = Vertex { p: center, n: normal, uv: Vec2::splat(0.5), color: Vec3::ONE };
    let facing_st = s.cross(t).dot(normal) > 0.0;
    (0..SEGMENTS)
        .map(|k| {
            let at = |k: usize| {
                let a = 2.0 * PI * (k % SEGMENTS) as f64 / SEGMENTS as f64;
                let d = s * a.cos() + t * a.sin();
                let uv = Vec2::new(0.5 + 0.5 * a.cos(), 0.5 + 0.5 * a.sin());
                Vertex { p: center + d * radius, n: normal, uv, color: Vec3::ONE }
            };
            if facing_st { [c, at(k), at(k + 1)] } else { [c, at(k + 1), at(k)] }
        })
        .collect()
}

/// The side of a cone frustum from `(base, r0)` to `(top, r1)`, outward normals.
fn round_side(base: Vec3, top: Vec3, r0: f64, r1: f64) -> Vec<[Vertex; 3]> {
    let axis = top - base;
    let h = axis.length();
    let a = axis / h;
    let (s, t) = basis(a);
    // The normal tilts by the slope of the side.
    let slope = (r0 - r1) / h;
    grid(1, SEGMENTS, |u, v| {
        let ang = 2.0 * PI * (u % 1.0);
        let d = s * ang.cos() + t * ang.sin();
        // The rims are exactly `base + d r0` and `top + d r1`, as the caps' (watertight meshes).
        let p = if v == 1.0 { top + d * r1 } else { base + axis * v + d * (r0 + (r1 - r0) * v) };
        (p, (d + a * slope).normalize(), Vec2::new(u, v))
    })
}

fn object_triangles(scene: &Scene, shape: &Shape) -> Option<Vec<[Vertex; 3]>> {
    Some(match shape {
        Shape::Sphere { center, radius } => grid(SEGMENTS / 2, SEGMENTS, |u, v| {
            let (theta, phi) = (PI * (1.0 - v), 2.0 * PI * u);
            let n = Vec3::new(theta.sin() * phi.cos(), theta.cos(), -theta.sin() * phi.sin());
            // The ray tracer's (longitude, latitude from the north pole).
            (*center + n * *radius, n, Vec2::new(u, 1.0 - v))
        }),
        Shape::Cylinder { base, top, radius, capped } | Shape::Cone { base, apex: top, radius, capped } => {
            let r1 = if matches!(shape, Shape::Cone { .. }) { 0.0 } else { *radius };
            let mut t = round_side(*base, *top, *radius, r1);
            if *capped {
                let a = (*top - *base).normalize();
                let st = basis(a);
                t.extend(disk_in(*base, st, -a, *radius));
                if r1 > 0.0 {
                    t.extend(disk_in(*top, st, a, r1));
                }
            }
            t
        }
        Shape::Disk { center, normal, radius } => disk(*center, *normal, *radius),
        Shape::Plane { point, normal } => {
            // A large square: the pipeline clips it to the view volume. Texture coordinates are
            // the ray tracer's lengths along its tangent frame.
            let (s, t) = basis(*normal);
            let (tu, tv) = alhazen_math::orthonormal_basis(*normal);
            let size = 1e4;
            grid(8, 8, |u, v| {
                let d = s * (u - 0.5) * 2.0 * size + t * (v - 0.5) * 2.0 * size;
                (*point + d, *normal, Vec2::new(d.dot(tu), d.dot(tv)))
            })
        }
        Shape::Box { min, max } => {
            let mut out = vec![];
            for axis in 0..3 {
                let (i, j) = ((axis + 1) % 3, (axis + 2) % 3);
                for high in [false, true] {
                    let mut n = Vec3::ZERO;
                    n[axis] = if high { 1.0 } else { -1.0 };
                    let face = grid(1, 1, |u, v| {
                        let mut p = Vec3::ZERO;
                        p[axis] = if high { max[axis] } else { min[axis] };
                        p[i] = min[i] + u * (max[i] - min[i]);
                        p[j] = min[j] + v * (max[j] - min[j]);
                        (p, n, Vec2::new(u, v))
                    });
                    // (i, j, axis) is right-handed: the grid faces +axis.
                    out.extend(face.into_iter().map(|[a, b, c]| if high { [a, b, c] } else { [a, c, b] }));
                }
            }
            out
        }
        Shape::Mesh { mesh, smooth } => {
            let m = &scene.meshes[*mesh];
            m.triangles
                .iter()
                .map(|t| {
                    let [a, b, c] = t.map(|i| m.positions[i as usize]);
                    let flat = (b - a).cross(c - a).normalize_or_zero();
                    t.map(|i| {
                        let i = i as usize;
                        let n = if *smooth && !m.normals.is_empty() { m.normals[i] } else { flat };
                        let uv = m.uvs.get(i).copied().unwrap_or(Vec2::ZERO);
                        let color = m.colors.get(i).copied().unwrap_or(Vec3::ONE);
                        Vertex { p: m.positions[i], n, uv, color }
                    })
                })
                .collect()
        }
        Shape::Csg { .. } => return None,
    })
}

/// How many triangles `object_triangles` makes of `shape`, without making them (for the
/// memory estimate).
pub fn triangle_count(scene: &Scene, shape: &Shape) -> u64 {
    let round = SEGMENTS as u64;
    match shape {
        Shape::Sphere { .. } => round * round,
        Shape::Cylinder { capped, .. } => 2 * round + if *capped { 2 * round } else { 0 },
        Shape::Cone { capped, .. } => 2 * round + if *capped { round } else { 0 },
        Shape::Disk { .. } => round,
        Shape::Plane { .. } => 128,
        Shape::Box { .. } => 12,
        Shape::Mesh { mesh, .. } => scene.meshes[*mesh].triangles.len() as u64,
        Shape::Csg { .. } => 0,
    }
}

fn place(tri: [Vertex; 3], tf: &Transform) -> [Vertex; 3] {
    let mut t = tri.map(|v| Vertex { p: tf.point(v.p), n: tf.normal(v.n).normalize_or_zero(), ..v });
    // A mirroring transform reverses the winding.
    if tf.vector(Vec3::X).cross(tf.vector(Vec3::Y)).dot(tf.vector(Vec3::Z)) < 0.0 {
        t.swap(1, 2);
    }
    t
}

/// One object's tessellation in world space (`None` for CSG), before material assignment.
pub fn world_triangles(scene: &Scene, object: &alhazen_scene::Object) -> Option<Vec<[Vertex; 3]>> {
    Some(object_triangles(scene, &object.shape)?.into_iter().map(|t| place(t, &object.transform)).collect())
}

/// Every object of `scene` as world-space triangles.
pub fn scene_triangles(scene: &Scene) -> SceneTriangles {
    let (mut triangles, mut skipped) = (vec![], 0);
    // Whether each mesh bounds a solid is measured once (back faces of open ones are seen).
    let closed_meshes: Vec<bool> = scene.meshes.iter().map(|m| m.is_closed()).collect();
    let is_closed = |s: &Shape| match s {
        Shape::Mesh { mesh, .. } => closed_meshes[*mesh],
        s => s.is_closed(&scene.meshes),
    };
    for (object, o) in scene.objects.iter().enumerate() {
        let object = object as u32;
        let Some(tris) = object_triangles(scene, &o.shape) else {
            skipped += 1;
            continue;
        };
        let slots = match &o.shape {
            Shape::Mesh { mesh, .. } => Some(&scene.meshes[*mesh].material_slots),
            _ => None,
        };
        for (k, t) in tris.into_iter().enumerate() {
            let material = match slots.and_then(|s| s.get(k)) {
                Some(&slot) => o.mesh_materials.get(slot as usize).copied().unwrap_or(o.material),
                None => o.material,
            };
            let unbounded = matches!(o.shape, Shape::Plane { .. });
            let t = place(t, &o.transform);
            // Degenerate triangles (sphere poles, cone apexes) draw nothing and would break the
            // edge pairing of closed meshes.
            let (e1, e2) = (t[1].p - t[0].p, t[2].p - t[0].p);
            let longest = e1.length_squared().max(e2.length_squared()).max((t[2].p - t[1].p).length_squared());
            if e1.cross(e2).length_squared() <= 1e-20 * longest * longest {
                continue;
            }
            triangles.push(Triangle { v: t, material, closed: is_closed(&o.shape), unbounded, object });
        }
    }
    SceneTriangles { triangles, skipped }
}
