//! The renderable world: every object of the scene placed, with a top-level BVH over the bounded
//! ones (one leaf for a world of a few) and a plain list of unbounded ones (planes, which each ray
//! meets first). Small meshes, rectangles and untextured boxes are flattened into world-space
//! triangles and parallelograms, which the BVH's leaves test eight at a time in single precision
//! ([`FlatPacket`]); a leaf's untransformed spheres are [`SpherePacket`]s; other objects are tested
//! one by one, behind a test of their world box. Eight rays can be traced in one call
//! ([`World::intersect_rays`], [`World::unoccluded_rays`]: the path tracer's lanes); when the world
//! is one leaf, each flat and each packed sphere is tested against the eight at once, then each
//! ray's other objects.

use crate::bvh::Bvh;
use crate::shape::{
    AaBox, AlphaMask, Candidate, Cone, Csg, Cylinder, Disk, FLAT_LANES as LANES, Flat, FlatLane, FlatPacket, LaneHit,
    MeshAccel, MeshShape, PackedFlats, Placed, Plane, RayPacket, RaysSphereHits, SPHERE_LANES, Shape, Sphere,
    SpherePacket, SurfaceHit, VectorUnit, flat_primitives, on_triangle,
};
use alhazen_geom::TriangleMesh;
use alhazen_math::{Bounds3, Ray, Vec3};
use alhazen_scene as scene;
use std::sync::Arc;

/// `b` grown on every side by a millionth of its largest coordinate's magnitude: beyond any
/// rounding in an object's own ray tests, so a ray that misses it misses what it bounds.
fn padded(b: Bounds3) -> Bounds3 {
    let pad = Vec3::splat(b.min.abs().max(b.max.abs()).max_element() * 1e-6);
    Bounds3 { min: b.min - pad, max: b.max + pad }
}

/// What a ray's traversal found nearest: lane `h.lane` of flat packet `k`, or another
/// object's candidate (a sphere's, a plane's, a nested mesh's…).
enum Nearest {
    Flat(usize, LaneHit),
    Other(Candidate, u32),
}

/// The eight rays' reciprocal directions, axis by axis (one vector division per axis).
#[inline(always)]
fn inverse_dirs(rays: &RayPacket) -> [[f64; LANES]; 3] {
    rays.dir.map(|d| d.map(|x| 1.0 / x))
}

/// A world whose primitives cost at most this many tests (a packet of flats or spheres, or
/// another object, one each), its packets no more than a leaf holds, is one leaf: rays traced
/// eight at a time through it, each object behind its box, measured faster than through the
/// SAH's tree at 12 tests or fewer (even at 16, slower at 20; with more packets, slower:
/// `BENCHMARKS.md`, session 33).
const ONE_LEAF_TESTS: usize = 12;

/// The most flat packets whose hits' shading is kept ([`FlatShading`], ~1.7 KB a packet, so
/// at most ~14 MB): a world of more (over 65 K triangles in small meshes) finds its hits'
/// normals as a mesh does, rather than hold another 200 bytes a triangle.
const FLAT_SHADING_PACKETS: usize = 1 << 13;

/// One ray's reciprocal direction as lane 0 of [`inverse_dirs`]'s.
fn inverse_dir(ray: &Ray) -> [[f64; LANES]; 3] {
    let d = ray.dir.to_array();
    std::array::from_fn(|a| std::array::from_fn(|r| if r == 0 { 1.0 / d[a] } else { 0.0 }))
}

/// Whether the segment `(0, t_max)` of `ray` (reciprocal direction lane `r` of `inv`) may meet box
/// `b`: [`Bounds3::hit_interval`]'s slab test, the world's cull before an object's own.
#[inline(always)]
fn may_meet_box(b: &Bounds3, ray: &Ray, (inv, r): LaneInverse, t_max: f64) -> bool {
    b.hit_interval(ray, Vec3::new(inv[0][r], inv[1][r], inv[2][r]), t_max).is_some()
}

/// Lane `r` of rays' reciprocal directions ([`inverse_dirs`]), read where it is used: copied
/// out into an array of its own, its three stores stalled the wider load that read them back.
type LaneInverse<'a> = (&'a [[f64; LANES]; 3], usize);

/// An object ready to be intersected.
#[derive(Clone, Debug)]
pub struct WorldObject {
    /// Geometry in world space.
    pub placed: Placed,
    /// Its material.
    pub material: u32,
    /// Per-slot materials of a mesh (empty: `material` everywhere).
    pub slot_materials: Vec<u32>,
    /// Some material of the object has a bump map or anisotropic lobes: hits need `∂p/∂u`,
    /// `∂p/∂v`.
    pub tangents: bool,
}

/// A primitive of the top-level BVH: a whole object, or one triangle of a small mesh placed
/// in world space, or a parallelogram of two (flattened so their rays skip the nested mesh
/// BVH), or an untransformed sphere (the last two tested in packets).
#[derive(Clone, Copy, Debug)]
enum Primitive {
    Object(u32),
    Flat { object: u32, lane: FlatLane, flat: Flat },
    Sphere { object: u32, sphere: Sphere },
}

/// Whose triangle a lane of a [`FlatPacket`] is.
#[derive(Clone, Copy, Debug, Default)]
struct Lane {
    object: u32,
    flat: FlatLane,
}

/// What one leaf of the top-level BVH tests: its flats and spheres in packets, then its other
/// objects.
#[derive(Clone, Debug)]
struct Leaf {
    /// Range in `World::flats`.
    packets: std::ops::Range<usize>,
    /// Range in `World::spheres` (and `World::sphere_objects`).
    spheres: std::ops::Range<usize>,
    /// Range in `World::leaf_objects`.
    objects: std::ops::Range<usize>,
}

/// All objects with their acceleration structure.
#[derive(Debug, Default)]
pub struct World {
    objects: Vec<WorldObject>,
    /// Over the objects; its leaves are labelled with their index in `leaves`.
    bvh: Bvh,
    leaves: Vec<Leaf>,
    flats: PackedFlats<Lane>,
    spheres: Vec<SpherePacket>,
    /// Lane by lane, whose sphere packet `k`'s spheres are.
    sphere_objects: Vec<[u32; SPHERE_LANES]>,
    leaf_objects: Vec<u32>,
    /// Beside `leaf_objects`: each object's world box, padded by far more than the rounding of
    /// its own tests, so a ray that misses the box misses the object.
    leaf_boxes: Vec<Bounds3>,
    unbounded: Vec<u32>,
    /// The packets' kernel for this processor.
    vectors: VectorUnit,
    /// Everything bounded is in one leaf: its flats are tested against eight rays at once, ray
    /// by lane (after each ray's unbounded objects, before its spheres and other objects).
    one_leaf: bool,
    /// ... the leaf holds only flats, and nothing is unbounded.
    flats_only: bool,
    /// Beside `flats.lanes` (where they are at most [`FLAT_SHADING_PACKETS`]), for flats
    /// without smooth normals: each triangle's normal and material (empty: none kept).
    flat_shading: Vec<[Option<FlatShading>; LANES]>,
}

/// A flat's triangles' normals and materials (the first, then the second of a
/// parallelogram's pair), which a hit needs besides its point.
#[derive(Clone, Copy, Debug)]
struct FlatShading {
    normal: [Vec3; 2],
    material: [u32; 2],
    /// Each triangle's material slot, as the mesh reports it (the radiosity solution's mesh
    /// numbers its triangles by it).
    slot: [u32; 2],
    /// Each triangle's corners (the hit point is interpolated on them, as the mesh does).
    corners: [[Vec3; 3]; 2],
}

/// Where a ray meets the world, without texture coordinates or bump-map tangents (enough to
/// shade untextured materials).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HitPoint {
    /// The point.
    pub p: Vec3,
    /// Geometric normal (out of the solid or to the shape's front).
    pub n: Vec3,
    /// Shading normal, on the side of `n`.
    pub ns: Vec3,
    /// Material index.
    pub material: u32,
    /// Index of the scene object.
    pub object: u32,
}

impl From<WorldHit> for HitPoint {
    #[inline]
    fn from(h: WorldHit) -> Self {
        Self::from(&h)
    }
}

impl From<&WorldHit> for HitPoint {
    #[inline]
    fn from(h: &WorldHit) -> Self {
        Self { p: h.hit.p, n: h.hit.n, ns: h.hit.ns, material: h.material, object: h.object }
    }
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
        scene::Shape::Sphere { center, radius } => Shape::Sphere(Sphere::new(*center, *radius)),
        scene::Shape::Cylinder { base, top, radius, capped } => {
            Shape::Cylinder(Cylinder::new(*base, *top, *radius, *capped))
        }
        scene::Shape::Cone { base, apex, radius, capped } => Shape::Cone(Cone::new(*base, *apex, *radius, *capped)),
        scene::Shape::Disk { center, normal, radius } => {
            Shape::Disk(Disk { center: *center, normal: *normal, radius: *radius })
        }
        scene::Shape::Plane { point, normal } => Shape::Plane(Plane { point: *point, normal: *normal }),
        scene::Shape::Box { min, max } => Shape::Box(AaBox { min: *min, max: *max }),
        scene::Shape::Mesh { mesh, smooth } => {
            Shape::Mesh(MeshShape { accel: meshes[*mesh].clone(), smooth: *smooth, alpha: None })
        }
        scene::Shape::Csg { op, a, b } => Shape::Csg(Box::new(Csg {
            op: *op,
            a: Placed::new(build_shape(&a.shape, meshes), a.transform),
            b: Placed::new(build_shape(&b.shape, meshes), b.transform),
        })),
    }
}

/// True when some material of the object looks at texture coordinates (a texture, a bump map,
/// a textured emission or BSDF).
fn uses_uv(o: &scene::Object, s: &scene::Scene) -> bool {
    std::iter::once(&o.material).chain(&o.mesh_materials).any(|&m| {
        let m = &s.materials[m as usize];
        !matches!(m.color, scene::Texture::Solid(_))
            || m.bump.is_some()
            || m.emission_texture.is_some()
            || m.bsdf.as_ref().is_some_and(|b| b.is_textured())
            // A box with a cut-out stays a box (opaque: cut-outs are meshes'), not six faces.
            || m.alpha.is_some()
    })
}

/// Meshes up to this size are copied into world space when placed, so their rays need no
/// transform; larger ones are shared between instances.
const BAKE_TRIANGLES: usize = 256;

/// `mesh` with `tf` applied to its positions and normals (on all threads: the mesh may be
/// large, see [`placed_once`]).
fn baked(mesh: &TriangleMesh, tf: &alhazen_math::Transform) -> TriangleMesh {
    use rayon::prelude::*;
    let (mut positions, mut normals) = (Vec::new(), Vec::new());
    mesh.positions.par_iter().map(|p| tf.point(*p)).collect_into_vec(&mut positions);
    mesh.normals.par_iter().map(|n| tf.normal(*n).normalize_or_zero()).collect_into_vec(&mut normals);
    let mut triangles = mesh.triangles.clone();
    // A mirroring transform reverses the winding; keep the outside outside.
    if tf.is_mirroring() {
        triangles.par_iter_mut().for_each(|t| t.swap(1, 2));
    }
    TriangleMesh {
        positions,
        normals,
        triangles,
        uvs: mesh.uvs.clone(),
        colors: mesh.colors.clone(),
        material_slots: mesh.material_slots.clone(),
        material_names: mesh.material_names.clone(),
    }
}

/// The world-space mesh of a small mesh object without a transform, whose triangles go
/// straight into the top-level BVH.
fn flattenable(p: &Placed) -> Option<&alhazen_geom::TriangleMesh> {
    match (&p.shape, &p.to_world) {
        (Shape::Mesh(m), None) if m.accel.mesh.triangle_count() <= BAKE_TRIANGLES && m.alpha.is_none() => {
            Some(&m.accel.mesh)
        }
        _ => None,
    }
}

/// `placed` (object `o`'s shape), a mesh given its materials' cut-outs ([`AlphaMask`]), whose
/// coverages name `images`.
fn with_cut_outs(
    mut placed: Placed,
    o: &scene::Object,
    scene: &scene::Scene,
    images: &Arc<Vec<Arc<alhazen_scene::ImageData>>>,
) -> Placed {
    if let Shape::Mesh(m) = &mut placed.shape {
        m.alpha = AlphaMask::of(o, scene, images);
    }
    placed
}

fn turned_sphere(shape: &scene::Shape, t: &alhazen_math::Transform) -> Option<Sphere> {
    let scene::Shape::Sphere { center, radius } = shape else { return None };
    Sphere::placed(*center, *radius, t)
}

/// Per mesh of `scene`, the transform of the one object that places it, when no other object
/// (nor a CSG operand) uses it, the transform is not the identity and the mesh is too large to
/// be baked per object: such a mesh is built in world space, as Mitsuba and pbrt do with every
/// mesh, so its rays and hits need no transform. Meshes placed several times stay shared
/// (instancing), in their own space.
fn placed_once(scene: &scene::Scene) -> Vec<Option<alhazen_math::Transform>> {
    let mut uses = vec![0usize; scene.meshes.len()];
    let mut placer = vec![None; scene.meshes.len()];
    fn operands(s: &scene::Shape, uses: &mut [usize]) {
        if let scene::Shape::Csg { a, b, .. } = s {
            for o in [a, b] {
                match &o.shape {
                    // Never baked: counted as shared.
                    scene::Shape::Mesh { mesh, .. } => uses[*mesh] += 2,
                    other => operands(other, uses),
                }
            }
        }
    }
    for o in &scene.objects {
        match &o.shape {
            scene::Shape::Mesh { mesh, .. } => {
                uses[*mesh] += 1;
                placer[*mesh] = Some(o.transform);
            }
            other => operands(other, &mut uses),
        }
    }
    let large = |m: &TriangleMesh| m.triangle_count() > BAKE_TRIANGLES;
    placer
        .into_iter()
        .zip(uses)
        .zip(&scene.meshes)
        // A mirror reverses the baked triangles' winding, and with it the barycentric
        // parametrisation that stands in for missing texture coordinates.
        .map(|((tf, n), m)| {
            tf.filter(|tf| n == 1 && !tf.is_identity() && large(m) && (!tf.is_mirroring() || !m.uvs.is_empty()))
        })
        .collect()
}

fn place(
    o: &scene::Object,
    meshes: &[Arc<MeshAccel>],
    world_space: &[Option<alhazen_math::Transform>],
    scene: &scene::Scene,
    unit: VectorUnit,
) -> Placed {
    if let scene::Shape::Mesh { mesh, .. } = &o.shape
        && world_space[*mesh].is_some()
    {
        // Its mesh was built with this object's transform applied.
        return Placed::new(build_shape(&o.shape, meshes), alhazen_math::Transform::IDENTITY);
    }
    let small = match &o.shape {
        scene::Shape::Mesh { mesh, smooth } if !o.transform.is_identity() => {
            let m = &scene.meshes[*mesh];
            (m.triangle_count() <= BAKE_TRIANGLES).then(|| (m.clone(), *smooth))
        }
        // A box without texture coordinates becomes its six faces, tested in packets.
        scene::Shape::Box { min, max } if !uses_uv(o, scene) => {
            Some((Arc::new(TriangleMesh::cuboid(*min, *max)), false))
        }
        _ => None,
    };
    if let Some((m, smooth)) = small {
        let accel = Arc::new(MeshAccel::with_unit(Arc::new(baked(&m, &o.transform)), unit));
        return Placed::new(Shape::Mesh(MeshShape { accel, smooth, alpha: None }), alhazen_math::Transform::IDENTITY);
    }
    if let Some(sphere) = turned_sphere(&o.shape, &o.transform) {
        // Tested in packets like any other sphere; only its parametrisation keeps the turn.
        return Placed::new(Shape::Sphere(sphere), alhazen_math::Transform::IDENTITY);
    }
    Placed::new(build_shape(&o.shape, meshes), o.transform)
}

impl World {
    /// Places every object of `scene` and builds the BVH, for this processor's widest kernel.
    pub fn build(scene: &scene::Scene) -> Self {
        Self::build_with(scene, VectorUnit::detect())
    }

    /// [`Self::build`] testing packets with `unit`'s kernel (one this processor runs: see
    /// [`VectorUnit::available`]). Every kernel gives the same hits.
    pub fn build_with(scene: &scene::Scene, unit: VectorUnit) -> Self {
        Self::build_by(scene, unit, crate::bvh::BuildMethod::Sah)
    }

    /// [`Self::build_with`], the meshes' own hierarchies built by `method` (the same hits by
    /// either; Morton order builds faster, the surface area heuristic traces faster).
    pub fn build_by(scene: &scene::Scene, unit: VectorUnit, method: crate::bvh::BuildMethod) -> Self {
        // Each mesh's tree on whichever thread is free (a scene of many meshes, each too small
        // for its own build to split across threads, keeps every thread busy); the same trees.
        let world_space = placed_once(scene);
        let meshes: Vec<Arc<MeshAccel>> = {
            use rayon::prelude::*;
            let accel = |(m, tf): (&Arc<TriangleMesh>, &Option<alhazen_math::Transform>)| {
                let m = tf.as_ref().map_or_else(|| m.clone(), |tf| Arc::new(baked(m, tf)));
                Arc::new(MeshAccel::with_build(m, unit, method))
            };
            scene.meshes.par_iter().zip(&world_space).map(accel).collect()
        };
        let images = Arc::new(scene.images.clone());
        let objects: Vec<WorldObject> = scene
            .objects
            .iter()
            .map(|o| WorldObject {
                placed: Placed {
                    uv: uses_uv(o, scene),
                    ..with_cut_outs(place(o, &meshes, &world_space, scene, unit), o, scene, &images)
                },
                material: o.material,
                slot_materials: o.mesh_materials.clone(),
                tangents: std::iter::once(&o.material).chain(&o.mesh_materials).any(|&m| {
                    let m = &scene.materials[m as usize];
                    m.bump.is_some() || crate::bsdf::is_anisotropic(m)
                }),
            })
            .collect();
        let (mut primitives, mut prim_bounds, mut unbounded) = (vec![], vec![], vec![]);
        for (i, o) in objects.iter().enumerate() {
            let object = i as u32;
            if let Some(mesh) = flattenable(&o.placed) {
                for lane in flat_primitives(mesh) {
                    let flat = lane.flat(mesh);
                    primitives.push(Primitive::Flat { object, lane, flat });
                    prim_bounds.push(lane.bounds(mesh));
                }
                continue;
            }
            let b = o.placed.bounds();
            if let (Shape::Sphere(sphere), None) = (&o.placed.shape, &o.placed.to_world) {
                primitives.push(Primitive::Sphere { object, sphere: *sphere });
                prim_bounds.push(b);
            } else if b.is_finite() {
                primitives.push(Primitive::Object(object));
                prim_bounds.push(b);
            } else {
                unbounded.push(object);
            }
        }
        // The tree does not depend on the processor (its SAH charges packets of four), so
        // neither do the order of tests nor the hit chosen on a tie. Flats and untransformed
        // spheres are both tested in packets: a few spheres on a floor make one leaf, whose
        // rays the lanes trace together (the glossy suite scene 1.29 → 1.06 s).
        // A world of a few objects stays one leaf even where the SAH would split it: its rays
        // are then traced eight at a time ([`Self::intersect_rays`]), each object behind its box.
        let mut bvh = Bvh::build_packed_within(
            &prim_bounds,
            |k| matches!(primitives[k], Primitive::Flat { .. } | Primitive::Sphere { .. }),
            ONE_LEAF_TESTS,
        );
        let mut world = Self { objects, unbounded, vectors: unit, ..Self::default() };
        world.fill_leaves(&mut bvh, &primitives);
        world.one_leaf = world.leaves.len() == 1;
        world.flats_only = world.one_leaf
            && world.unbounded.is_empty()
            && matches!(world.leaves.as_slice(), [leaf] if leaf.spheres.is_empty() && leaf.objects.is_empty());
        world.bvh = bvh;
        if world.flats.lanes.len() <= FLAT_SHADING_PACKETS {
            world.flat_shading = world.flats.lanes.iter().map(|lanes| lanes.map(|l| world.flat_shading(l))).collect();
        }
        world
    }

    /// What [`FlatShading`] a hit on `lane` needs; `None` where normals vary over it.
    fn flat_shading(&self, lane: Lane) -> Option<FlatShading> {
        let o = &self.objects[lane.object as usize];
        let Shape::Mesh(mesh) = &o.placed.shape else { return None };
        if o.placed.uv || o.tangents || !mesh.accel.mesh.colors.is_empty() {
            return None;
        }
        let first = lane.flat.triangle as usize;
        let triangles = [first, first + usize::from(lane.flat.parallelogram)];
        if !triangles.iter().all(|&t| mesh.shades_flat(t)) {
            return None;
        }
        let [a, b] = triangles.map(|t| {
            let (n, _, slot) = mesh.normals_and_slot(t, 0.0, 0.0);
            (n, o.slot_materials.get(slot as usize).copied().unwrap_or(o.material), slot)
        });
        let corners = triangles.map(|t| mesh.accel.mesh.corners(t));
        Some(FlatShading { normal: [a.0, b.0], material: [a.1, b.1], slot: [a.2, b.2], corners })
    }

    /// Sorts each leaf's primitives into packets of flats, packets of spheres and a list of
    /// objects; the tree's leaves are relabelled with their index in `leaves`.
    fn fill_leaves(&mut self, bvh: &mut Bvh, primitives: &[Primitive]) {
        bvh.relabel_leaves(|leaf| {
            let first_object = self.leaf_objects.len();
            let mut flats: Vec<(Lane, Flat)> = vec![];
            let mut spheres: Vec<(u32, Sphere)> = vec![];
            for &k in leaf {
                match primitives[k as usize] {
                    Primitive::Object(i) => {
                        self.leaf_objects.push(i);
                        self.leaf_boxes.push(padded(self.objects[i as usize].placed.bounds()));
                    }
                    Primitive::Flat { object, lane, flat } => flats.push((Lane { object, flat: lane }, flat)),
                    Primitive::Sphere { object, sphere } => spheres.push((object, sphere)),
                }
            }
            let packets = self.flats.push_leaf(&flats);
            let first_sphere = self.spheres.len();
            for chunk in spheres.chunks(SPHERE_LANES) {
                self.spheres.push(SpherePacket::new(&chunk.iter().map(|s| s.1).collect::<Vec<_>>()));
                let mut objects = [0; SPHERE_LANES];
                chunk.iter().zip(&mut objects).for_each(|(s, slot)| *slot = s.0);
                self.sphere_objects.push(objects);
            }
            let (spheres, objects) = (first_sphere..self.spheres.len(), first_object..self.leaf_objects.len());
            self.leaves.push(Leaf { packets, spheres, objects });
            self.leaves.len() - 1..self.leaves.len()
        });
    }

    /// Eight rays are traced at once faster than one by one ([`Self::intersect_rays`]): the
    /// world is one leaf (its flats tested against the eight rays at once) and the processor
    /// has AVX2 or AVX-512.
    pub fn traces_rays_together(&self) -> bool {
        self.one_leaf && (self.vectors.is_avx512() || self.vectors.is_avx2())
    }

    /// The kernel its packets are tested with.
    pub fn vector_unit(&self) -> VectorUnit {
        self.vectors
    }

    /// The objects, in the scene's order.
    pub fn objects(&self) -> &[WorldObject] {
        &self.objects
    }

    /// Bounds of the bounded objects.
    pub fn bounds(&self) -> Bounds3 {
        self.bvh.bounds()
    }

    /// The nearest hit in `(0, t_max)`: the object and its candidate, no surface details.
    #[inline]
    fn nearest(&self, ray: &Ray, t_max: f64) -> Option<(Candidate, u32)> {
        self.nearest_found(ray, t_max).map(|found| match found {
            Nearest::Flat(k, h) => self.flat_candidate(k, h),
            Nearest::Other(c, i) => (c, i),
        })
    }

    /// The candidate and object of lane `h.lane` of flat packet `k`'s hit `h`.
    #[inline(always)]
    fn flat_candidate(&self, k: usize, h: LaneHit) -> (Candidate, u32) {
        let lane = self.flats.lanes[k][h.lane];
        (lane.flat.candidate(h.t, h.b1, h.b2), lane.object)
    }

    /// The nearest hit in `(0, t_max)` as the traversal found it.
    #[inline]
    #[allow(unsafe_code)]
    fn nearest_found(&self, ray: &Ray, t_max: f64) -> Option<Nearest> {
        #[cfg(target_arch = "x86_64")]
        if self.vectors.is_simd() && !self.bvh.is_one_leaf() {
            // SAFETY: a `VectorUnit` says AVX2 or AVX-512 (which includes it) only where the
            // processor has it.
            return unsafe {
                if self.vectors.is_avx512() { self.nearest_avx512(ray, t_max) } else { self.nearest_avx2(ray, t_max) }
            };
        }
        self.nearest_portable(ray, t_max)
    }

    /// [`Self::nearest`] compiled for AVX2: the tree's nodes tested in AVX2 registers, the
    /// leaves' flats by the packets' AVX2 kernel inlined (as a mesh's, `MeshShape::hit`).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[allow(unsafe_code)]
    fn nearest_avx2(&self, ray: &Ray, t_max: f64) -> Option<Nearest> {
        // SAFETY: this function runs only where AVX2 is.
        unsafe { self.nearest_in_lanes(ray, t_max) }
    }

    /// [`Self::nearest_avx2`] compiled for AVX-512 processors: the same bits, 32 registers.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,avx512f,avx512vl")]
    #[allow(unsafe_code)]
    fn nearest_avx512(&self, ray: &Ray, t_max: f64) -> Option<Nearest> {
        // SAFETY: this function runs only where AVX-512 (and so AVX2) is.
        unsafe { self.nearest_in_lanes(ray, t_max) }
    }

    /// [`Self::nearest`] with AVX2, the ray prepared in lanes once for every leaf's flats.
    ///
    /// # Safety
    /// Only on a processor with AVX2.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    #[allow(unsafe_code)]
    unsafe fn nearest_in_lanes(&self, ray: &Ray, t_max: f64) -> Option<Nearest> {
        let best = self.nearest_unbounded(ray, t_max);
        let t_best = best.map_or(t_max, |(c, _)| c.t);
        // SAFETY: the caller's contract.
        let lanes = unsafe { crate::shape::ray_in_lanes(ray) };
        let mut visit = NearestInLanes { world: self, ray, lanes, best, best_flat: None };
        // SAFETY: the caller's contract.
        unsafe { self.bvh.traverse_leaves_prefetching_with::<true, true>(ray, t_best, |_| {}, &mut visit) };
        visit.best_flat.map(|(k, h)| Nearest::Flat(k, h)).or(visit.best.map(|(c, i)| Nearest::Other(c, i)))
    }

    /// [`Self::nearest`] without AVX2 ([`Bvh::traverse_leaves_prefetching_with`]).
    #[allow(unsafe_code)]
    fn nearest_portable(&self, ray: &Ray, t_max: f64) -> Option<Nearest> {
        let mut best = self.nearest_unbounded(ray, t_max);
        let t_best = best.map_or(t_max, |(c, _)| c.t);
        // The nearest flat's packet and lane; made a candidate once, after the traversal.
        let mut best_flat: Option<(usize, LaneHit)> = None;
        let visit = |range: std::ops::Range<usize>, t_max| {
            let leaf = &self.leaves[range.start];
            // Leaves of spheres and other objects only skip the flat kernel's call, as leaves
            // without spheres skip the sphere kernel's.
            let flats = match leaf.packets.is_empty() {
                true => None,
                false => self.flats.nearest_packet(leaf.packets.clone(), ray, t_max, self.vectors),
            };
            self.nearest_in_leaf(leaf, ray, t_max, flats, &mut best, &mut best_flat)
        };
        // SAFETY: without AVX2.
        unsafe { self.bvh.traverse_leaves_prefetching_with::<false, true>(ray, t_best, |_| {}, visit) };
        best_flat.map(|(k, h)| Nearest::Flat(k, h)).or(best.map(|(c, i)| Nearest::Other(c, i)))
    }

    /// A leaf's part of [`Self::nearest`] once its flats' nearest hit `flats` is known: that
    /// hit, unless one of its spheres or other objects is nearer; returns the closer hit
    /// distance if the leaf holds one.
    #[inline(always)]
    fn nearest_in_leaf(
        &self,
        leaf: &Leaf,
        ray: &Ray,
        mut t_max: f64,
        flats: Option<(usize, LaneHit)>,
        best: &mut Option<(Candidate, u32)>,
        best_flat: &mut Option<(usize, LaneHit)>,
    ) -> Option<f64> {
        let mut closer = None;
        if let Some((k, h)) = flats {
            *best_flat = Some((k, h));
            (t_max, closer) = (h.t, Some(h.t));
        }
        if let Some((c, i)) = self.nearest_solid(leaf, ray, t_max) {
            (*best, *best_flat) = (Some((c, i)), None);
            closer = Some(c.t);
        }
        closer
    }

    /// The nearest hit on an unbounded object (a plane) before `t_max`: the first of equally
    /// near ones.
    #[inline]
    fn nearest_unbounded(&self, ray: &Ray, t_max: f64) -> Option<(Candidate, u32)> {
        let mut best = None;
        let mut t_best = t_max;
        for &i in &self.unbounded {
            if let Some(c) = self.objects[i as usize].placed.hit(ray, t_best) {
                t_best = c.t;
                best = Some((c, i));
            }
        }
        best
    }

    /// True when an unbounded object lies on `ray` before `t_max`.
    #[inline]
    fn unbounded_blocks(&self, ray: &Ray, t_max: f64) -> bool {
        self.unbounded.iter().any(|&i| self.objects[i as usize].placed.blocks(ray, t_max))
    }

    /// The nearest of `leaf`'s spheres and other objects before `t_max` (its flats tested
    /// already): the candidate and its object.
    #[inline]
    fn nearest_solid(&self, leaf: &Leaf, ray: &Ray, t_max: f64) -> Option<(Candidate, u32)> {
        let spheres = &self.spheres[leaf.spheres.clone()];
        // Most leaves hold no sphere packet: skip the kernel's call.
        let sphere =
            if spheres.is_empty() { None } else { SpherePacket::nearest_of(spheres, ray, t_max, self.vectors) };
        let inv = self.culls_by_box(leaf).then(|| inverse_dir(ray));
        self.nearest_solid_after(leaf, ray, t_max, sphere, inv.as_ref().map(|inv| (inv, 0)))
    }

    /// A ray's objects in `leaf` are culled by their boxes first when it holds several: the
    /// leaf's box bounds them all, and a cylinder's or a mesh's own test costs more than a box
    /// (a scene of 49 spheres, boxes and cylinders: 9 % faster, the same hits).
    #[inline]
    fn culls_by_box(&self, leaf: &Leaf) -> bool {
        leaf.objects.len() > 1
    }

    /// The nearest sphere hit of each of eight rays in `leaf` ([`SpherePacket::nearest_of_rays`]),
    /// inlined so that the kernel writes its hits where the caller keeps them.
    #[inline(always)]
    fn spheres_of_rays(
        &self,
        leaf: &Leaf,
        rays: &RayPacket,
        t_max: &[f64; LANES],
        live: [bool; LANES],
    ) -> RaysSphereHits {
        let spheres = &self.spheres[leaf.spheres.clone()];
        if spheres.is_empty() {
            return [None; LANES];
        }
        SpherePacket::nearest_of_rays(spheres, rays, t_max, live, self.vectors)
    }

    /// [`Self::nearest_solid`] with the leaf's nearest sphere hit already found (`sphere`: its
    /// packet, lane and distance). Inlined: out of line, its call and result cost what its box
    /// tests cost.
    #[inline(always)]
    fn nearest_solid_after(
        &self,
        leaf: &Leaf,
        ray: &Ray,
        mut t_max: f64,
        sphere: Option<(usize, usize, f64)>,
        inv_dir: Option<LaneInverse>,
    ) -> Option<(Candidate, u32)> {
        let mut best = self.sphere_candidate(leaf, sphere);
        if let Some((c, _)) = best {
            t_max = c.t;
        }
        let boxes = &self.leaf_boxes[leaf.objects.clone()];
        for (&i, b) in self.leaf_objects[leaf.objects.clone()].iter().zip(boxes) {
            if inv_dir.is_some_and(|inv| !may_meet_box(b, ray, inv, t_max)) {
                continue;
            }
            if let Some(c) = self.objects[i as usize].placed.hit(ray, t_max) {
                best = Some((c, i));
                t_max = c.t;
            }
        }
        best
    }

    /// The candidate and object of `leaf`'s sphere hit `sphere` (its packet, lane and distance).
    #[inline(always)]
    fn sphere_candidate(&self, leaf: &Leaf, sphere: Option<(usize, usize, f64)>) -> Option<(Candidate, u32)> {
        let (k, lane, t) = sphere?;
        Some((Candidate { t, aux: 0, bary: [0.0; 2] }, self.sphere_objects[leaf.spheres.start + k][lane]))
    }

    /// True when one of `leaf`'s spheres or other objects lies on `ray` before `t_max`.
    #[inline]
    fn solid_blocks(&self, leaf: &Leaf, ray: &Ray, t_max: f64) -> bool {
        !leaf.spheres.is_empty()
            && SpherePacket::nearest_of(&self.spheres[leaf.spheres.clone()], ray, t_max, self.vectors).is_some()
            || self.objects_block(
                leaf,
                ray,
                t_max,
                self.culls_by_box(leaf).then(|| inverse_dir(ray)).as_ref().map(|inv| (inv, 0)),
            )
    }

    /// True when one of `leaf`'s other objects (not flats, not packed spheres) lies on `ray`
    /// before `t_max`.
    #[inline]
    fn objects_block(&self, leaf: &Leaf, ray: &Ray, t_max: f64, inv_dir: Option<LaneInverse>) -> bool {
        let boxes = &self.leaf_boxes[leaf.objects.clone()];
        self.leaf_objects[leaf.objects.clone()].iter().zip(boxes).any(|(&i, b)| {
            inv_dir.is_none_or(|inv| may_meet_box(b, ray, inv, t_max))
                && self.objects[i as usize].placed.blocks(ray, t_max)
        })
    }

    /// The nearest hit in `(0, t_max)` without its surface: the distance, the triangle and its
    /// barycentric coordinates for a mesh (see [`Candidate`]) and the object's index — what a
    /// ray query of Embree (`rtcIntersect1`) reports. [`Self::intersect`] adds the surface.
    #[inline]
    pub fn nearest_hit(&self, ray: &Ray, t_max: f64) -> Option<(Candidate, u32)> {
        self.nearest(ray, t_max)
    }

    /// The nearest hit in `(0, t_max)` with its surface and material.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<WorldHit> {
        Some(match self.nearest_found(ray, t_max)? {
            Nearest::Flat(k, h) => self.flat_hit(ray, k, h),
            Nearest::Other(c, i) => self.surface_of(ray, c, i),
        })
    }

    /// [`Self::intersect`] for eight rays without a limit, into `out` (`None` where not
    /// `live`): the same hits, several rays' tests in flight at once.
    pub fn intersect_rays(&self, rays: &RayPacket, live: [bool; LANES], out: &mut [Option<WorldHit>; LANES]) {
        if self.flats_only {
            out.iter_mut().for_each(|slot| *slot = None);
            FlatPacket::nearest_of_rays(&self.flats.packets, rays, live, self.vectors, |r, k, h| {
                out[r] = Some(self.flat_hit(&rays.ray(r), k, h));
            });
        } else if self.one_leaf {
            self.intersect_rays_in_leaf(rays, live, out);
        } else {
            for (r, (slot, live)) in out.iter_mut().zip(live).enumerate() {
                *slot = if live { self.intersect(&rays.ray(r), f64::INFINITY) } else { None };
            }
        }
    }

    /// [`Self::intersect_rays`] in a one-leaf world: its flats against the eight rays at once,
    /// then each ray's spheres and other objects, as [`Self::nearest`] tests them.
    #[inline(never)]
    fn intersect_rays_in_leaf(&self, rays: &RayPacket, live: [bool; LANES], out: &mut [Option<WorldHit>; LANES]) {
        // Each ray is copied out of the packet first: the loads that read such a copy stall
        // when its stores have not yet been written to the cache.
        let each: [Ray; LANES] = std::array::from_fn(|r| rays.ray(r));
        let mut flat = [None; LANES];
        FlatPacket::nearest_of_rays(&self.flats.packets, rays, live, self.vectors, |r, k, h| {
            flat[r] = Some((k, h));
        });
        // The unbounded objects first, as `nearest` tests them: a flat is nearer only below
        // their hit, compared as `FlatPacket::nearest_of` compares with its limit.
        let mut unbounded: [Option<(Candidate, u32)>; LANES] = [None; LANES];
        // (Most worlds have none: their lanes' `None`s are not built and copied in.)
        if !self.unbounded.is_empty() {
            for (r, u) in unbounded.iter_mut().enumerate().filter(|&(r, _)| live[r]) {
                *u = self.nearest_unbounded(&each[r], f64::INFINITY);
            }
            for (f, u) in flat.iter_mut().zip(&unbounded) {
                if let (Some((_, h)), Some((c, _))) = (*f, u)
                    && h.t as f32 >= c.t as f32
                {
                    *f = None;
                }
            }
        }
        let leaf = &self.leaves[0];
        let t_max: [f64; LANES] = std::array::from_fn(|r| match (flat[r], unbounded[r]) {
            (Some((_, h)), _) => h.t,
            (None, Some((c, _))) => c.t,
            (None, None) => f64::INFINITY,
        });
        let spheres = self.spheres_of_rays(leaf, rays, &t_max, live);
        let inv = (!leaf.objects.is_empty()).then(|| inverse_dirs(rays));
        for (r, slot) in out.iter_mut().enumerate() {
            let ray = &each[r];
            let inv = inv.as_ref().map(|inv| (inv, r));
            // A leaf of flats and spheres only (most small scenes) has no other object to test.
            let solid = match live[r] {
                false => None,
                true if leaf.objects.is_empty() => self.sphere_candidate(leaf, spheres[r]),
                true => self.nearest_solid_after(leaf, ray, t_max[r], spheres[r], inv),
            };
            *slot = match (solid, flat[r], unbounded[r]) {
                (Some((c, i)), ..) => Some(self.surface_of(ray, c, i)),
                (None, Some((k, h)), _) => Some(self.flat_hit(ray, k, h)),
                (None, None, Some((c, i))) => Some(self.surface_of(ray, c, i)),
                (None, None, None) => None,
            };
        }
    }

    /// The hit of `ray` on lane `h.lane` of packet `k` as [`Self::intersect`] reports it (the
    /// flat is a triangle or parallelogram of a mesh placed in world space). Flats whose
    /// materials look at no texture coordinates and whose normals do not vary skip the
    /// surface's interpolation: their hits carry zero texture coordinates.
    #[inline(always)]
    fn flat_hit(&self, ray: &Ray, k: usize, h: LaneHit) -> WorldHit {
        let (c, object) = self.flat_candidate(k, h);
        if let Some(s) = self.flat_shading.get(k).and_then(|lanes| lanes[h.lane].as_ref()) {
            // The triangle of the pair the candidate picked.
            let second = (c.aux - self.flats.lanes[k][h.lane].flat.triangle) as usize;
            let (n, material) = (s.normal[second], s.material[second]);
            let p = on_triangle(s.corners[second], c.bary[0], c.bary[1]);
            let hit = SurfaceHit { slot: s.slot[second], ..SurfaceHit::flat(h.t, p, n, alhazen_math::Vec2::ZERO) };
            return WorldHit { hit, material, object };
        }
        self.surface_of(ray, c, object)
    }

    /// [`Self::unoccluded`] for eight segments, `rays[r]` over `dist[r]` (false where not `live`).
    pub fn unoccluded_rays(&self, rays: &RayPacket, dist: &[f64; LANES], live: [bool; LANES]) -> [bool; LANES] {
        if self.one_leaf {
            let blocked = FlatPacket::any_of_rays(&self.flats.packets, rays, dist, live, self.vectors);
            let leaf = &self.leaves[0];
            let open = std::array::from_fn(|r| {
                live[r] && !blocked[r] && (self.unbounded.is_empty() || !self.unbounded_blocks(&rays.ray(r), dist[r]))
            });
            let spheres = &self.spheres[leaf.spheres.clone()];
            let sphere_blocks = if self.flats_only || spheres.is_empty() {
                [false; LANES]
            } else {
                SpherePacket::any_of_rays(spheres, rays, dist, open, self.vectors)
            };
            let inv = (!leaf.objects.is_empty()).then(|| inverse_dirs(rays));
            return std::array::from_fn(|r| {
                let inv = inv.as_ref().map(|inv| (inv, r));
                open[r]
                    && (self.flats_only || !sphere_blocks[r] && !self.objects_block(leaf, &rays.ray(r), dist[r], inv))
            });
        }
        std::array::from_fn(|r| {
            let ray = rays.ray(r);
            live[r] && self.unoccluded(ray.origin, ray.dir, dist[r])
        })
    }

    /// The hit of object `i` whose candidate is `c`, with its surface and material.
    #[inline]
    fn surface_of(&self, ray: &Ray, c: Candidate, i: u32) -> WorldHit {
        let o = &self.objects[i as usize];
        let mut hit = o.placed.surface(ray, c);
        if o.tangents {
            hit.dpduv = o.placed.tangents(ray, c);
        }
        let material = o.slot_materials.get(hit.slot as usize).copied().unwrap_or(o.material);
        WorldHit { hit, material, object: i }
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

    /// True when nothing blocks the segment from `origin` along unit `dir` over `dist`; stops at
    /// the first blocker found.
    #[inline]
    #[allow(unsafe_code)]
    pub fn unoccluded(&self, origin: Vec3, dir: Vec3, dist: f64) -> bool {
        #[cfg(target_arch = "x86_64")]
        if self.vectors.is_simd() && !self.bvh.is_one_leaf() {
            // SAFETY: as in `nearest`.
            return unsafe {
                if self.vectors.is_avx512() {
                    self.unoccluded_avx512(origin, dir, dist)
                } else {
                    self.unoccluded_avx2(origin, dir, dist)
                }
            };
        }
        self.unoccluded_portable(origin, dir, dist)
    }

    /// [`Self::unoccluded`] compiled for AVX2, the leaves' flats by the AVX2 kernel inlined.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[allow(unsafe_code)]
    fn unoccluded_avx2(&self, origin: Vec3, dir: Vec3, dist: f64) -> bool {
        // SAFETY: this function runs only where AVX2 is.
        unsafe { self.unoccluded_in_lanes(origin, dir, dist) }
    }

    /// [`Self::unoccluded_avx2`] compiled for AVX-512 processors: the same bits, 32 registers.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,avx512f,avx512vl")]
    #[allow(unsafe_code)]
    fn unoccluded_avx512(&self, origin: Vec3, dir: Vec3, dist: f64) -> bool {
        // SAFETY: this function runs only where AVX-512 (and so AVX2) is.
        unsafe { self.unoccluded_in_lanes(origin, dir, dist) }
    }

    /// [`Self::unoccluded`] with AVX2, the ray prepared in lanes once for every leaf's flats.
    ///
    /// # Safety
    /// Only on a processor with AVX2.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    #[allow(unsafe_code)]
    unsafe fn unoccluded_in_lanes(&self, origin: Vec3, dir: Vec3, dist: f64) -> bool {
        let ray = Ray::new(origin, dir);
        if self.unbounded_blocks(&ray, dist) {
            return false;
        }
        // SAFETY: the caller's contract.
        let lanes = unsafe { crate::shape::ray_in_lanes(&ray) };
        let mut visit = AnyInLanes { world: self, ray: &ray, lanes, blocked: false };
        // SAFETY: the caller's contract.
        unsafe { self.bvh.traverse_leaves_prefetching_with::<true, false>(&ray, dist, |_| {}, &mut visit) };
        !visit.blocked
    }

    /// [`Self::unoccluded`] without AVX2.
    #[allow(unsafe_code)]
    fn unoccluded_portable(&self, origin: Vec3, dir: Vec3, dist: f64) -> bool {
        let ray = Ray::new(origin, dir);
        if self.unbounded_blocks(&ray, dist) {
            return false;
        }
        let mut blocked = false;
        let visit = |range: std::ops::Range<usize>, t_max| {
            let leaf = &self.leaves[range.start];
            let flats = &self.flats.packets[leaf.packets.clone()];
            blocked = !flats.is_empty() && FlatPacket::any_of(flats, &ray, t_max, self.vectors)
                || self.solid_blocks(leaf, &ray, t_max);
            blocked.then_some(0.0)
        };
        // SAFETY: without AVX2.
        unsafe { self.bvh.traverse_leaves_prefetching_with::<false, false>(&ray, dist, |_| {}, visit) };
        !blocked
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

/// A leaf visit of [`World::nearest_in_lanes`]: the leaf's flats by the AVX2 kernel for a ray in
/// lanes, inlined into the traversal (a type, not a closure, so that it is), then its other
/// objects. Made only where AVX2 is (its lanes come from the `unsafe` `ray_in_lanes`).
#[cfg(target_arch = "x86_64")]
struct NearestInLanes<'a> {
    world: &'a World,
    ray: &'a Ray,
    lanes: crate::shape::RayLanes,
    best: Option<(Candidate, u32)>,
    best_flat: Option<(usize, LaneHit)>,
}

#[cfg(target_arch = "x86_64")]
impl crate::bvh::LeafVisit for &mut NearestInLanes<'_> {
    #[inline(always)]
    #[allow(unsafe_code)]
    fn visit(&mut self, range: std::ops::Range<usize>, t_max: f64) -> Option<f64> {
        let leaf = &self.world.leaves[range.start];
        let flats = match leaf.packets.is_empty() {
            true => None,
            // SAFETY: a visit is made only where AVX2 is (see the type).
            false => unsafe { self.world.flats.nearest_packet_in_lanes(leaf.packets.clone(), &self.lanes, t_max) },
        };
        self.world.nearest_in_leaf(leaf, self.ray, t_max, flats, &mut self.best, &mut self.best_flat)
    }
}

/// A leaf visit of [`World::unoccluded_in_lanes`]: whether the leaf's flats (by the AVX2 kernel
/// for a ray in lanes) or other objects block the segment, as [`NearestInLanes`].
#[cfg(target_arch = "x86_64")]
struct AnyInLanes<'a> {
    world: &'a World,
    ray: &'a Ray,
    lanes: crate::shape::RayLanes,
    blocked: bool,
}

#[cfg(target_arch = "x86_64")]
impl crate::bvh::LeafVisit for &mut AnyInLanes<'_> {
    #[inline(always)]
    #[allow(unsafe_code)]
    fn visit(&mut self, range: std::ops::Range<usize>, t_max: f64) -> Option<f64> {
        let (world, leaf) = (self.world, &self.world.leaves[range.start]);
        // SAFETY: a visit is made only where AVX2 is (see the type).
        self.blocked = !leaf.packets.is_empty()
            && unsafe { world.flats.any_in_lanes(leaf.packets.clone(), &self.lanes, t_max) }
            || world.solid_blocks(leaf, self.ray, t_max);
        self.blocked.then_some(0.0)
    }
}

/// The shading normal at `hit` for material `m`: the surface's, bent by the material's bump map
/// (course, bump mapping) when it has one.
pub fn shading_normal(hit: &SurfaceHit, m: &scene::Material, images: &[Arc<scene::ImageData>]) -> Vec3 {
    match &m.bump {
        None => hit.ns,
        Some(b) => scene::texture::bumped_normal(b, hit.uv, hit.ns, hit.dpduv[0], hit.dpduv[1], images),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A large mesh placed by one object is built in world space (no transform left on the
    /// object); placed by two, it is shared and each ray transformed. Either way the same
    /// surfaces, to the flats' single precision (barycentrics to 10⁻⁴ of a small triangle),
    /// mirrored or not. A mirror is baked only when the mesh has texture coordinates (the
    /// winding turns, and with it the barycentric parametrisation that stands in for them).
    #[test]
    fn a_mesh_placed_once_is_built_in_world_space() {
        let scene_with = |scale: &str| {
            let text = format!(
                "[[object]]\nshape = \"subdivision\"\nbase = \"cube\"\nlevels = 3\nsmooth = true\n\
                 transform = [{{ scale = {scale} }}, {{ rotate_y = 30 }}, {{ translate = [0.4, -0.2, 1.0] }}]\n"
            );
            scene::parse_scene("once.toml".as_ref(), &text).unwrap()
        };
        assert!(World::build(&scene_with("[0.5, -0.8, 0.6]")).objects[0].placed.to_world.is_some(), "a mirror");
        // A turn and uniform scale; a mirror, baked once the mesh has texture coordinates.
        for (scale, uvs) in [("0.7", false), ("[0.7, -0.7, 0.7]", true)] {
            let mut once = scene_with(scale);
            if uvs {
                let mut m = (*once.meshes[0]).clone();
                m.uvs = m.positions.iter().map(|p| alhazen_math::Vec2::new(p.x + 0.3 * p.z, p.y - 0.2 * p.z)).collect();
                once.meshes[0] = std::sync::Arc::new(m);
            }
            let mut twice = once.clone();
            let far = scene::Object {
                transform: alhazen_math::Transform::translate(Vec3::new(100.0, 0.0, 0.0)) * once.objects[0].transform,
                ..once.objects[0].clone()
            };
            twice.objects.push(far);
            let (baked, shared) = (World::build(&once), World::build(&twice));
            assert!(once.meshes[0].triangle_count() > BAKE_TRIANGLES);
            assert!(baked.objects[0].placed.to_world.is_none(), "{scale}: built in world space");
            assert!(shared.objects[0].placed.to_world.is_some(), "{scale}: shared, placed by its transform");
            let mut hits = 0;
            for k in 0..400 {
                let a = k as f64 * 0.37;
                let origin = Vec3::new(3.0 * a.cos(), 1.5 * (1.3 * a).sin(), 1.0 + 3.0 * a.sin());
                let target = Vec3::new(0.4 + 0.5 * (2.1 * a).sin(), -0.2 + 0.6 * a.cos(), 1.0 + 0.4 * (0.7 * a).cos());
                let ray = Ray::new(origin, (target - origin).normalize());
                let (b, s) = (baked.intersect(&ray, f64::INFINITY), shared.intersect(&ray, f64::INFINITY));
                assert_eq!(b.is_some(), s.is_some(), "{scale}, ray {k}");
                let (Some(b), Some(s)) = (b, s) else { continue };
                hits += 1;
                let close = |x: Vec3, y: Vec3, tol: f64| (x - y).length() < tol;
                let (b, s) = (b.hit, s.hit);
                assert!((b.t - s.t).abs() < 1e-5 && close(b.p, s.p, 1e-5), "{scale}, ray {k}: {b:?} vs {s:?}");
                assert!(close(b.n, s.n, 1e-9) && close(b.ns, s.ns, 1e-5), "{scale}, ray {k}: normals {b:?} vs {s:?}");
                assert!((b.uv - s.uv).length() < 1e-4, "{scale}, ray {k}: uv {b:?} vs {s:?}");
            }
            assert!(hits > 200, "{scale}: {hits} hits");
        }
    }

    /// Anisotropic microfacets turn with the surface's `∂p/∂u` (a sphere's is the azimuth about
    /// +y), not with an arbitrary frame; isotropic ones need no tangent.
    #[test]
    fn anisotropic_lobes_follow_the_parametrisation() {
        let text = |roughness: &str| {
            format!(
                "[materials.m]\nbsdf = {{ type = \"conductor\", metal = \"silver\", roughness = {roughness} }}\n\
                 [[object]]\nshape = \"sphere\"\nradius = 1\nmaterial = \"m\"\n"
            )
        };
        for (roughness, anisotropic) in [("[0.05, 0.3]", true), ("0.2", false)] {
            let scene = scene::parse_scene("aniso.toml".as_ref(), &text(roughness)).unwrap();
            let world = World::build(&scene);
            let ray = Ray::new(Vec3::new(0.3, 0.4, -5.0), Vec3::Z);
            let hit = world.intersect(&ray, f64::INFINITY).unwrap().hit;
            let tangent =
                crate::bsdf::tangent_at(&scene.materials[scene.objects[0].material as usize], &hit, &scene.images);
            assert_eq!(tangent.is_some(), anisotropic, "{roughness}");
            if let Some(t) = tangent {
                assert!(t.dot(hit.n).abs() < 1e-12 && t.y.abs() < 1e-12 && t.length() > 0.0, "{t}");
            }
        }
    }

    /// Rays into one-leaf worlds of flats and solids (a packet of three spheres; a packet of two
    /// and a cylinder tested alone; a mesh; a plane and six cylinders beside them), eight at a
    /// time and one by one: the same hits and the same shadows.
    #[test]
    fn eight_rays_meet_a_leaf_of_flats_and_solids_as_one_does() {
        let rectangle = "[[object]]\nshape = \"rectangle\"\ntransform = [{ scale = 3 }, { rotate_x = -90 }, { translate = [0, -1, 0] }]\n";
        let sphere = |x: f64| format!("[[object]]\nshape = \"sphere\"\ncenter = [{x}, 0, 0]\nradius = 0.6\n");
        let packet = format!("{rectangle}{}{}{}", sphere(-1.5), sphere(0.0), sphere(1.5));
        let cylinder = "[[object]]\nshape = \"cylinder\"\nradius = 0.3\nbase = [0, -1, 0]\ntop = [0, 0.8, 0]\n";
        let singles = format!("{rectangle}{}{}{cylinder}", sphere(-1.5), sphere(1.5));
        // A mesh too big to flatten, placed by a transform: tested alone, behind its world box.
        let mesh = "[[object]]\nshape = \"subdivision\"\nbase = \"cube\"\nlevels = 3\nsmooth = true\n\
                    transform = [{ scale = 0.5 }, { rotate_y = 30 }, { translate = [0.4, -0.2, 1.0] }]\n";
        let meshes = format!("{rectangle}{}{}{mesh}", sphere(-1.5), sphere(1.5));
        // An unbounded plane, tested first (it crosses the rectangle and the spheres), and a
        // few cylinders, more than a tree's leaf holds.
        let plane = "[[object]]\nshape = \"plane\"\npoint = [0, -0.7, 0]\nnormal = [0.2, 1, 0.1]\n";
        let cylinders: String = (0..6)
            .map(|k| {
                format!(
                    "[[object]]\nshape = \"cylinder\"\nradius = 0.2\nbase = [{x}, -1, 1]\ntop = [{x}, 0.5, 1]\n",
                    x = k as f64 - 2.5
                )
            })
            .collect();
        let planar = format!("{packet}{plane}{cylinders}");
        for (text, packets) in [(packet, 1), (singles, 1), (meshes, 1), (planar, 1)] {
            let world = World::build(&scene::parse_scene("leaf.toml".as_ref(), &text).unwrap());
            assert!(world.one_leaf && !world.flats_only, "one leaf of flats and solids");
            assert_eq!(world.spheres.len(), packets);
            let mut n = 0;
            for k in 0..64 {
                let mut rays = RayPacket::default();
                for i in 0..LANES {
                    let a = (k * LANES + i) as f64 * 0.41;
                    let origin = Vec3::new(4.0 * a.cos(), 2.0 + (1.3 * a).sin(), 4.0 * a.sin());
                    let target = Vec3::new(1.8 * (2.1 * a).sin(), -0.8 + 0.5 * a.cos(), 0.5 * (0.7 * a).cos());
                    rays.set(i, &Ray::new(origin, (target - origin).normalize()));
                }
                let live: [bool; LANES] = std::array::from_fn(|i| (k + i) % 7 != 3);
                let mut hits = [None; LANES];
                world.intersect_rays(&rays, live, &mut hits);
                let dist: [f64; LANES] = std::array::from_fn(|i| 2.0 + i as f64);
                let clear = world.unoccluded_rays(&rays, &dist, live);
                for i in 0..LANES {
                    let ray = rays.ray(i);
                    let alone = world.intersect(&ray, f64::INFINITY).filter(|_| live[i]);
                    assert_eq!(hits[i].map(HitPoint::from), alone.map(HitPoint::from));
                    assert_eq!(clear[i], live[i] && world.unoccluded(ray.origin, ray.dir, dist[i]));
                    n += usize::from(alone.is_some_and(|h| h.object > 0));
                }
            }
            assert!(n > 100, "{n} rays meet solids");
        }
    }

    proptest::proptest! {
        /// The box test culls no ray whose segment reaches a point of the box (on its faces
        /// too), whatever the ray's length, direction (some along the axes) or distance.
        #[test]
        fn the_box_cull_keeps_every_ray_that_meets_the_box(
            lo in proptest::array::uniform3(-1e3..1e3f64),
            size in proptest::array::uniform3(0.0..1e2f64),
            scale in -8i32..8,
            u in proptest::array::uniform3(proptest::prop_oneof![0.0..1.0f64, proptest::strategy::Just(0.0), proptest::strategy::Just(1.0)]),
            from in proptest::array::uniform3(-1e4..1e4f64),
            zero in 0usize..5,
            length in 0.0..10.0f64,
        ) {
            let s = 10f64.powi(scale);
            let lo = Vec3::from_array(lo) * s;
            let b = padded(Bounds3 { min: lo, max: lo + Vec3::from_array(size) * s });
            let target = lo + Vec3::from_array(size) * s * Vec3::from_array(u);
            let origin = Vec3::from_array(from) * s;
            let mut dir = (target - origin) * length.max(1e-3);
            if zero < 3 {
                dir[zero] = 0.0;
            }
            proptest::prop_assume!(dir.length() > 0.0);
            let ray = Ray::new(origin, dir);
            // The parameter of the point nearest `target` on the line, and a bit beyond.
            let t = ((target - origin).dot(dir) / dir.length_squared()).max(0.0);
            // The reciprocal in lane 3 of a packet's.
            let mut lanes = [[f64::NAN; LANES]; 3];
            (0..3).for_each(|a| lanes[a][3] = 1.0 / dir[a]);
            let inv = (&lanes, 3);
            let on_ray = (ray.at(t) - target).length() <= 1e-9 * (lo.length() + size.iter().sum::<f64>() * s + 1.0);
            if on_ray {
                proptest::prop_assert!(may_meet_box(&b, &ray, inv, t * (1.0 + 1e-12) + f64::MIN_POSITIVE), "{b:?} {ray:?} {t}");
                proptest::prop_assert!(may_meet_box(&b, &ray, inv, f64::INFINITY));
            }
            // A ray pointing away from a box it starts outside never meets it.
            let away = Ray::new(b.max + Vec3::ONE, Vec3::ONE);
            proptest::prop_assert!(!may_meet_box(&b, &away, (&[[1.0; LANES]; 3], 0), f64::INFINITY));
        }
    }

    /// Rays into a one-leaf world of flats with smooth normals and a checker texture (a
    /// subdivided cube) and flat ones (a box): eight at a time, each hit is what the ray finds
    /// alone, with its texture coordinates where the material looks at them.
    #[test]
    fn eight_rays_meet_smooth_and_flat_flats_as_one_does() {
        let text = r#"
[[object]]
shape = "subdivision"
base = "cube"
levels = 0
smooth = true
material = { color = { checker = { even = [1, 1, 1], odd = [0, 0, 0], size = 0.1 } } }
[[object]]
shape = "box"
min = [1.5, -1, -1]
max = [2.5, 1, 1]
"#;
        let world = World::build(&scene::parse_scene("smooth.toml".as_ref(), text).unwrap());
        assert!(world.flats_only, "one leaf of flats");
        assert!(world.flat_shading.iter().flatten().any(Option::is_none), "some flats shade smoothly");
        let (mut n, mut uv) = (0, 0);
        for k in 0..64 {
            let mut rays = RayPacket::default();
            for i in 0..LANES {
                let a = (k * LANES + i) as f64 * 0.37;
                let origin = Vec3::new(4.0 * a.cos(), 1.5 * (1.3 * a).sin(), 4.0 * a.sin());
                rays.set(
                    i,
                    &Ray::new(origin, (Vec3::new(0.8 * (2.1 * a).sin(), 0.3 * a.cos(), 0.2) - origin).normalize()),
                );
            }
            let mut hits = [None; LANES];
            world.intersect_rays(&rays, [true; LANES], &mut hits);
            for (i, hit) in hits.into_iter().enumerate() {
                let alone = world.intersect(&rays.ray(i), f64::INFINITY);
                assert_eq!(hit.map(HitPoint::from), alone.map(HitPoint::from));
                if let (Some(h), Some(a)) = (hit, alone)
                    && world.objects[h.object as usize].placed.uv
                {
                    (n, uv) = (n + usize::from(h.hit.n != h.hit.ns), uv + 1);
                    assert_eq!(h.hit.uv, a.hit.uv);
                }
            }
        }
        assert!(n > 50 && uv == n, "{n} hits with smooth normals, {uv} with texture coordinates");
    }

    /// A flat's hit from its kept shading ([`FlatShading`]) is the mesh's own (its candidate's
    /// surface, [`World::surface_of`]), in a world of one leaf and in a tree of many.
    #[test]
    fn kept_flat_shading_is_the_meshes_own() {
        let mut text = String::new();
        for (i, j) in (0..6).flat_map(|i| (0..6).map(move |j| (i, j))) {
            let (x, z) = (i as f64 * 1.5 - 4.0, j as f64 * 1.5 - 4.0);
            text += &format!(
                "[[object]]\nshape = \"box\"\nmin = [{x}, 0, {z}]\nmax = [{}, {}, {}]\n",
                x + 1.0,
                0.5 + 0.1 * i as f64,
                z + 0.8
            );
        }
        let many = World::build(&scene::parse_scene("many.toml".as_ref(), &text).unwrap());
        let one = World::build(
            &scene::parse_scene(
                "one.toml".as_ref(),
                "[[object]]\nshape = \"box\"\nmin = [-1, 0, -1]\nmax = [1, 1, 1]\n",
            )
            .unwrap(),
        );
        assert!(!many.one_leaf && one.one_leaf);
        for world in [many, one] {
            assert!(world.flat_shading.iter().flatten().all(Option::is_some), "every box shades flat");
            let mut met = 0;
            for k in 0..2000 {
                let a = k as f64 * 0.61;
                let origin = Vec3::new(7.0 * a.cos(), 3.0 + 2.0 * (1.7 * a).sin(), 7.0 * a.sin());
                let ray = Ray::new(
                    origin,
                    (Vec3::new(2.0 * (2.3 * a).sin(), 0.2, 2.0 * (1.1 * a).cos()) - origin).normalize(),
                );
                let kept = world.intersect(&ray, f64::INFINITY);
                let own = world.nearest_hit(&ray, f64::INFINITY).map(|(c, i)| world.surface_of(&ray, c, i));
                let seen = |h: Option<WorldHit>| h.map(|h| (HitPoint::from(h), h.hit.slot));
                assert_eq!(seen(kept), seen(own), "ray {k}");
                met += usize::from(kept.is_some());
            }
            assert!(met > 500, "{met} hits");
        }
    }
}
