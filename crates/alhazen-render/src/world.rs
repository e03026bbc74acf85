//! The renderable world: every object of the scene placed, with a top-level BVH over the
//! bounded ones and a plain list of unbounded ones (planes).

use crate::bvh::Bvh;
use crate::shape::{
    AaBox, Candidate, Cone, Csg, Cylinder, Disk, MeshAccel, MeshShape, Placed, Plane, Shape, Sphere, SurfaceHit,
};
use alhazen_math::{Bounds3, Ray, Vec3};
use alhazen_scene as scene;
use std::sync::Arc;

/// An object ready to be intersected.
#[derive(Clone, Debug)]
pub struct WorldObject {
    /// Geometry in world space.
    pub placed: Placed,
    /// Its material.
    pub material: u32,
    /// Per-slot materials of a mesh (empty: `material` everywhere).
    pub slot_materials: Vec<u32>,
}

/// All objects with their acceleration structure.
#[derive(Debug, Default)]
pub struct World {
    objects: Vec<WorldObject>,
    bvh: Bvh,
    bounded: Vec<u32>,
    unbounded: Vec<u32>,
}

/// The first thing a shadow ray meets.
#[derive(Clone, Copy, Debug)]
pub enum ShadowHit {
    /// Nothing before the light.
    Clear,
    /// An opaque surface: no light passes.
    Opaque,
    /// A transparent surface that light may pass.
    Transparent(WorldHit),
}

/// A hit with the material to shade it with.
#[derive(Clone, Copy, Debug)]
pub struct WorldHit {
    /// The surface point.
    pub hit: SurfaceHit,
    /// Material index.
    pub material: u32,
    /// Index of the scene object.
    pub object: u32,
}

fn build_shape(s: &scene::Shape, meshes: &[Arc<MeshAccel>]) -> Shape {
    match s {
        scene::Shape::Sphere { center, radius } => Shape::Sphere(Sphere { center: *center, radius: *radius }),
        scene::Shape::Cylinder { base, top, radius, capped } => {
            Shape::Cylinder(Cylinder::new(*base, *top, *radius, *capped))
        }
        scene::Shape::Cone { base, apex, radius, capped } => Shape::Cone(Cone::new(*base, *apex, *radius, *capped)),
        scene::Shape::Disk { center, normal, radius } => {
            Shape::Disk(Disk { center: *center, normal: *normal, radius: *radius })
        }
        scene::Shape::Plane { point, normal } => Shape::Plane(Plane { point: *point, normal: *normal }),
        scene::Shape::Box { min, max } => Shape::Box(AaBox { min: *min, max: *max }),
        scene::Shape::Mesh { mesh, smooth } => Shape::Mesh(MeshShape { accel: meshes[*mesh].clone(), smooth: *smooth }),
        scene::Shape::Csg { op, a, b } => Shape::Csg(Box::new(Csg {
            op: *op,
            a: Placed::new(build_shape(&a.shape, meshes), a.transform),
            b: Placed::new(build_shape(&b.shape, meshes), b.transform),
        })),
    }
}

/// Meshes up to this size are copied into world space when placed, so their rays need no
/// transform; larger ones are shared between instances.
const BAKE_TRIANGLES: usize = 256;

/// A small mesh with `tf` applied to its positions and normals.
fn baked(mesh: &alhazen_geom::TriangleMesh, tf: &alhazen_math::Transform) -> alhazen_geom::TriangleMesh {
    let mut m = mesh.clone();
    m.positions.iter_mut().for_each(|p| *p = tf.point(*p));
    m.normals.iter_mut().for_each(|n| *n = tf.normal(*n).normalize_or_zero());
    // A mirroring transform reverses the winding; keep the outside outside.
    if tf.vector(Vec3::X).cross(tf.vector(Vec3::Y)).dot(tf.vector(Vec3::Z)) < 0.0 {
        m.triangles.iter_mut().for_each(|t| t.swap(1, 2));
    }
    m
}

fn place(o: &scene::Object, meshes: &[Arc<MeshAccel>], scene: &scene::Scene) -> Placed {
    if let scene::Shape::Mesh { mesh, smooth } = o.shape {
        let m = &scene.meshes[mesh];
        if !o.transform.is_identity() && m.triangle_count() <= BAKE_TRIANGLES {
            let accel = Arc::new(MeshAccel::new(Arc::new(baked(m, &o.transform))));
            return Placed::new(Shape::Mesh(MeshShape { accel, smooth }), alhazen_math::Transform::IDENTITY);
        }
    }
    Placed::new(build_shape(&o.shape, meshes), o.transform)
}

impl World {
    /// Places every object of `scene` and builds the BVH.
    pub fn build(scene: &scene::Scene) -> Self {
        let meshes: Vec<Arc<MeshAccel>> = scene.meshes.iter().map(|m| Arc::new(MeshAccel::new(m.clone()))).collect();
        let objects: Vec<WorldObject> = scene
            .objects
            .iter()
            .map(|o| WorldObject {
                placed: place(o, &meshes, scene),
                material: o.material,
                slot_materials: o.mesh_materials.clone(),
            })
            .collect();
        let bounds: Vec<Bounds3> = objects.iter().map(|o| o.placed.bounds()).collect();
        let (bounded, unbounded): (Vec<u32>, Vec<u32>) =
            (0..objects.len() as u32).partition(|&i| bounds[i as usize].is_finite());
        let bvh = Bvh::build(&bounded.iter().map(|&i| bounds[i as usize]).collect::<Vec<_>>());
        Self { objects, bvh, bounded, unbounded }
    }

    /// Bounds of the bounded objects.
    pub fn bounds(&self) -> Bounds3 {
        self.bvh.bounds()
    }

    /// The nearest hit in `(0, t_max)`: the object and its candidate, no surface details.
    #[inline]
    fn nearest(&self, ray: &Ray, t_max: f64) -> Option<(Candidate, u32)> {
        let mut best: Option<(Candidate, u32)> = None;
        let mut t_best = t_max;
        for &i in &self.unbounded {
            if let Some(c) = self.objects[i as usize].placed.hit(ray, t_best) {
                t_best = c.t;
                best = Some((c, i));
            }
        }
        self.bvh.traverse(ray, t_best, |k, t_max| {
            let i = self.bounded[k as usize];
            let c = self.objects[i as usize].placed.hit(ray, t_max)?;
            best = Some((c, i));
            Some(c.t)
        });
        best
    }

    /// The nearest hit in `(0, t_max)` with its surface and material.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<WorldHit> {
        let (c, i) = self.nearest(ray, t_max)?;
        let o = &self.objects[i as usize];
        let hit = o.placed.surface(ray, c);
        let material = o.slot_materials.get(hit.slot as usize).copied().unwrap_or(o.material);
        Some(WorldHit { hit, material, object: i })
    }

    /// What a shadow ray meets first: asks `is_opaque(material)` before computing the
    /// surface, so an opaque blocker costs no shading work.
    #[inline]
    pub fn shadow_hit(&self, ray: &Ray, t_max: f64, is_opaque: impl Fn(u32) -> bool) -> ShadowHit {
        let Some((c, i)) = self.nearest(ray, t_max) else { return ShadowHit::Clear };
        let o = &self.objects[i as usize];
        if o.slot_materials.is_empty() && is_opaque(o.material) {
            return ShadowHit::Opaque;
        }
        let hit = o.placed.surface(ray, c);
        let material = o.slot_materials.get(hit.slot as usize).copied().unwrap_or(o.material);
        if is_opaque(material) {
            return ShadowHit::Opaque;
        }
        ShadowHit::Transparent(WorldHit { hit, material, object: i })
    }

    /// True when nothing blocks the segment from `origin` along unit `dir` over `dist`.
    #[inline]
    pub fn unoccluded(&self, origin: Vec3, dir: Vec3, dist: f64) -> bool {
        self.nearest(&Ray::new(origin, dir), dist).is_none()
    }

    /// The nearest hit by testing every object (the reference for BVH tests).
    pub fn intersect_brute_force(&self, ray: &Ray, t_max: f64) -> Option<SurfaceHit> {
        let mut best: Option<SurfaceHit> = None;
        for o in &self.objects {
            let limit = best.map_or(t_max, |b| b.t);
            if let Some(h) = o.placed.intersect(ray, limit) {
                best = Some(h);
            }
        }
        best
    }
}
