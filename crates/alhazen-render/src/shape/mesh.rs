//! Triangle meshes over a per-mesh BVH whose leaves hold the triangles (and the parallelograms
//! pairs of them form) as packets of [`super::Flat`]s, tested several at once; CSG's crossings
//! use Möller–Trumbore. One [`MeshAccel`] is shared by every instance of the mesh (instancing =
//! one mesh, many transforms).

use super::{
    AlphaMask, Candidate, Crossing, FlatLane, FlatPacket, LaneHit, PackedFlats, SurfaceHit, VectorUnit, flat_primitives,
};
use crate::bvh::Bvh;
use alhazen_geom::TriangleMesh;
use alhazen_math::{Bounds3, Ray, Vec2, Vec3};
use rayon::prelude::*;
use std::sync::Arc;

/// A mesh with its acceleration structure.
#[derive(Debug)]
pub struct MeshAccel {
    /// The mesh.
    pub mesh: Arc<TriangleMesh>,
    /// Over the flats of the mesh; its leaves are labelled with their packets' range.
    bvh: Bvh,
    /// Each leaf's flats, tested in packets.
    packets: PackedFlats<FlatLane>,
    vectors: VectorUnit,
    /// Per triangle: its vertex normals all equal its face normal (smooth shading would only
    /// interpolate it back); empty when the mesh has no vertex normals (every triangle flat).
    flat: Vec<bool>,
}

impl MeshAccel {
    /// Builds the BVH over the mesh's flats and packs its leaves for this processor's widest
    /// kernel.
    pub fn new(mesh: Arc<TriangleMesh>) -> Self {
        Self::with_unit(mesh, VectorUnit::detect())
    }

    /// [`Self::new`] for `vectors`' kernel.
    pub fn with_unit(mesh: Arc<TriangleMesh>, vectors: VectorUnit) -> Self {
        Self::with_build(mesh, vectors, crate::bvh::BuildMethod::Sah)
    }

    /// [`Self::with_unit`] with the hierarchy built by `method`.
    pub fn with_build(mesh: Arc<TriangleMesh>, vectors: VectorUnit, method: crate::bvh::BuildMethod) -> Self {
        let prims = flat_primitives(&mesh);
        let mut bvh = Bvh::build_with(prims.len(), |k| prims[k].bounds(&mesh), |_| true, method);
        // Each leaf is relabelled with the packets it will have, then all are packed at once.
        let (mut leaves, mut packed) = (vec![], 0);
        bvh.relabel_leaf_ranges(|leaf| {
            let first = packed;
            packed += leaf.len().div_ceil(crate::shape::FLAT_LANES);
            leaves.push(leaf);
            first..packed
        });
        let packets = PackedFlats::of_leaves(bvh.leaf_order(), &leaves, |k| {
            let lane = prims[k as usize];
            (lane, lane.flat(&mesh))
        });
        drop((prims, leaves));
        let mut flat = Vec::new();
        if !mesh.normals.is_empty() {
            let shades_flat = |(i, t): (usize, &[u32; 3])| {
                let n = face_normal(mesh.corners(i));
                t.iter().all(|&v| (mesh.normals[v as usize] - n).length() < 1e-12)
            };
            mesh.triangles.par_iter().enumerate().map(shades_flat).collect_into_vec(&mut flat);
        }
        Self { mesh, bvh, packets, vectors, flat }
    }
}

/// The unit geometric normal of the triangle with these corners (zero when it has no area):
/// computed where it is needed from the corners the hit reads anyway, rather than stored (24
/// bytes a triangle, a cache miss a hit).
#[inline]
fn face_normal([a, b, c]: [Vec3; 3]) -> Vec3 {
    (b - a).cross(c - a).normalize_or_zero()
}

/// Whether `alpha` keeps hit `h` of flat `lane` of `a`'s mesh on `ray`.
fn covered<'a>(a: &'a MeshAccel, alpha: &'a AlphaMask, ray: &'a Ray) -> impl Fn(FlatLane, LaneHit) -> bool + 'a {
    move |lane, h| alpha.covers(&a.mesh, &lane.candidate(h.t, h.b1, h.b2), ray)
}

/// The texture coordinates of `mesh`'s triangle `tri` at barycentric `[b1, b2]` (those
/// barycentrics where the mesh has none).
#[inline]
pub(super) fn uv_at(mesh: &TriangleMesh, tri: usize, [b1, b2]: [f64; 2]) -> Vec2 {
    if mesh.uvs.is_empty() {
        return Vec2::new(b1, b2);
    }
    let [i0, i1, i2] = mesh.triangles[tri].map(|i| i as usize);
    mesh.uvs[i0] * (1.0 - b1 - b2) + mesh.uvs[i1] * b1 + mesh.uvs[i2] * b2
}

/// The vertex colour of `mesh`'s triangle `tri` at barycentric `[b1, b2]` (white where the
/// mesh has none).
#[inline]
fn color_at(mesh: &TriangleMesh, tri: usize, [b1, b2]: [f64; 2]) -> Vec3 {
    if mesh.colors.is_empty() {
        return Vec3::ONE;
    }
    let [i0, i1, i2] = mesh.triangles[tri].map(|i| i as usize);
    mesh.colors[i0] * (1.0 - b1 - b2) + mesh.colors[i1] * b1 + mesh.colors[i2] * b2
}

/// An instance of a mesh.
#[derive(Clone, Debug)]
pub struct MeshShape {
    /// Shared geometry.
    pub accel: Arc<MeshAccel>,
    /// Interpolate vertex normals when the mesh has them.
    pub smooth: bool,
    /// Where its materials cut holes in it (`None`: opaque everywhere).
    pub alpha: Option<Arc<AlphaMask>>,
}

/// The point with barycentrics `(b1, b2)` on the triangle with these corners: on its plane to
/// double precision, where `ray.at(t)` from a single-precision `t` is off it by up to
/// `2⁻²⁴·t·|d|` (far from a distant camera, more than the tracers' guard).
#[inline]
pub fn on_triangle([p0, p1, p2]: [Vec3; 3], b1: f64, b2: f64) -> Vec3 {
    p0 * (1.0 - b1 - b2) + p1 * b1 + p2 * b2
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
    /// True when triangle `tri` is shaded with its face normal (no vertex normals to blend).
    #[inline]
    pub fn shades_flat(&self, tri: usize) -> bool {
        !self.smooth || self.accel.flat.get(tri).is_none_or(|&f| f)
    }

    /// Triangle `tri`'s geometric and shading normals and material slot at barycentric
    /// `(b1, b2)`: what [`Self::surface_at`] reports, without the rest.
    #[inline]
    pub fn normals_and_slot(&self, tri: usize, b1: f64, b2: f64) -> (Vec3, Vec3, u32) {
        let m = &self.accel.mesh;
        let n = face_normal(m.corners(tri));
        let ns = if !self.shades_flat(tri) {
            let idx = m.triangles[tri].map(|i| i as usize);
            let b0 = 1.0 - b1 - b2;
            let s = m.normals[idx[0]] * b0 + m.normals[idx[1]] * b1 + m.normals[idx[2]] * b2;
            // Keep the shading normal on the geometric normal's side.
            s.try_normalize().map_or(n, |s| if s.dot(n) < 0.0 { -s } else { s })
        } else {
            n
        };
        (n, ns, m.material_slots.get(tri).copied().unwrap_or(0))
    }

    fn surface(&self, tri: usize, (t, b1, b2): (f64, f64, f64)) -> SurfaceHit {
        let m = &self.accel.mesh;
        let idx = m.triangles[tri].map(|i| i as usize);
        let (n, ns, slot) = self.normals_and_slot(tri, b1, b2);
        let uv = uv_at(m, tri, [b1, b2]);
        let p = on_triangle(idx.map(|i| m.positions[i]), b1, b2);
        SurfaceHit { t, p, n, ns, uv, slot, dpduv: [Vec3::ZERO; 2], color: color_at(m, tri, [b1, b2]) }
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

    /// The tree's leaves `ray` may meet, nearest first ([`Bvh::traverse_leaves_prefetching`]),
    /// or in the tree's order for an any-hit visit (without `NEAREST`):
    /// `visit(packets, t_max)`, each leaf's packets prefetched as soon as its box is met; the
    /// nodes tested in AVX2 registers with `AVX2`.
    ///
    /// # Safety
    /// `AVX2` only on a processor with AVX2.
    #[inline(always)]
    #[allow(unsafe_code)]
    unsafe fn traverse<const AVX2: bool, const NEAREST: bool>(
        &self,
        ray: &Ray,
        t_max: f64,
        visit: impl crate::bvh::LeafVisit,
    ) {
        let a = &*self.accel;
        let prefetch = |packets: std::ops::Range<usize>| a.packets.prefetch(packets.start);
        // SAFETY: the caller's contract.
        unsafe { a.bvh.traverse_leaves_prefetching_with::<AVX2, NEAREST>(ray, t_max, prefetch, visit) };
    }

    /// Nearest hit in `(0, t_max)`; `aux` is the triangle.
    #[allow(unsafe_code)]
    pub fn hit(&self, ray: &Ray, t_max: f64) -> Option<Candidate> {
        #[cfg(target_arch = "x86_64")]
        if self.accel.vectors.is_simd() {
            // SAFETY: a `VectorUnit` says AVX2 or AVX-512 (which includes it) only where the
            // processor has it.
            return unsafe {
                if self.accel.vectors.is_avx512() { self.hit_avx512(ray, t_max) } else { self.hit_avx2(ray, t_max) }
            };
        }
        self.hit_portable(ray, t_max)
    }

    /// [`Self::hit`] compiled for AVX2: its nodes tested in AVX2 registers, its leaves by the
    /// packets' AVX2 kernel inlined.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[allow(unsafe_code)]
    fn hit_avx2(&self, ray: &Ray, t_max: f64) -> Option<Candidate> {
        // SAFETY: this function runs only where AVX2 is.
        unsafe { self.hit_in_lanes(ray, t_max) }
    }

    /// [`Self::hit_avx2`] compiled for AVX-512 processors: the same instructions, the same
    /// bits, with 32 vector registers, so the ray's lanes stay in registers across the leaves.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,avx512f,avx512vl")]
    #[allow(unsafe_code)]
    fn hit_avx512(&self, ray: &Ray, t_max: f64) -> Option<Candidate> {
        // SAFETY: this function runs only where AVX-512 (and so AVX2) is.
        unsafe { self.hit_in_lanes(ray, t_max) }
    }

    /// [`Self::hit`] with AVX2: the ray prepared in lanes once, each leaf's packets tested by
    /// the AVX2 kernel (the bits of [`FlatPacket::nearest_of`]).
    ///
    /// # Safety
    /// Only on a processor with AVX2.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    #[allow(unsafe_code)]
    unsafe fn hit_in_lanes(&self, ray: &Ray, t_max: f64) -> Option<Candidate> {
        let a = &*self.accel;
        if let Some(alpha) = &self.alpha {
            // SAFETY: the caller's contract.
            return unsafe { self.hit_kept::<true>(ray, t_max, alpha) };
        }
        // SAFETY: the caller's contract.
        let mut visit =
            NearestInLanes { packets: &a.packets, ray: unsafe { super::flat_packet::ray_in_lanes(ray) }, best: None };
        // SAFETY: the caller's contract.
        unsafe { self.traverse::<true, true>(ray, t_max, &mut visit) };
        visit.best.map(|(lane, h)| lane.candidate(h.t, h.b1, h.b2))
    }

    /// [`Self::hit`] without AVX2: nodes in SSE halves, leaves by the portable kernel.
    #[allow(unsafe_code)]
    fn hit_portable(&self, ray: &Ray, t_max: f64) -> Option<Candidate> {
        let a = &*self.accel;
        if let Some(alpha) = &self.alpha {
            // SAFETY: without AVX2.
            return unsafe { self.hit_kept::<false>(ray, t_max, alpha) };
        }
        let mut best = None;
        let visit = |packets, t_max| {
            let (lane, h) = a.packets.nearest(packets, ray, t_max, a.vectors)?;
            best = Some((lane, h));
            Some(h.t)
        };
        // SAFETY: without AVX2.
        unsafe { self.traverse::<false, true>(ray, t_max, visit) };
        best.map(|(lane, h)| lane.candidate(h.t, h.b1, h.b2))
    }

    /// [`Self::hit`] on a mesh with cut-outs: the nearest hit where `alpha` says the
    /// surface is.
    ///
    /// # Safety
    /// `AVX2` only on a processor with AVX2.
    #[inline(always)]
    #[allow(unsafe_code)]
    unsafe fn hit_kept<const AVX2: bool>(&self, ray: &Ray, t_max: f64, alpha: &AlphaMask) -> Option<Candidate> {
        let a = &*self.accel;
        let mut best = None;
        let visit = |packets: std::ops::Range<usize>, t_max| {
            // The leaf's nearest hit in vector lanes first: when the mask keeps it, it is the
            // nearest kept (the same bits and tie rule); else flat by flat.
            let (lane, h) = a.packets.nearest(packets.clone(), ray, t_max, a.vectors)?;
            let nearest = lane.candidate(h.t, h.b1, h.b2);
            if alpha.covers(&a.mesh, &nearest, ray) {
                best = Some(nearest);
                return Some(h.t);
            }
            let (lane, h) = a.packets.nearest_kept(packets, ray, t_max, covered(a, alpha, ray))?;
            best = Some(lane.candidate(h.t, h.b1, h.b2));
            Some(h.t)
        };
        // SAFETY: the caller's contract.
        unsafe { self.traverse::<AVX2, true>(ray, t_max, visit) };
        best
    }

    /// True when some triangle lies on `ray` in `(0, t_max)`: [`MeshShape::hit`]`.is_some()`,
    /// stopping at the first leaf that holds one (shadow rays need no nearest hit).
    #[allow(unsafe_code)]
    pub fn blocks(&self, ray: &Ray, t_max: f64) -> bool {
        #[cfg(target_arch = "x86_64")]
        if self.accel.vectors.is_simd() {
            // SAFETY: as in `hit`.
            return unsafe {
                if self.accel.vectors.is_avx512() {
                    self.blocks_avx512(ray, t_max)
                } else {
                    self.blocks_avx2(ray, t_max)
                }
            };
        }
        self.blocks_portable(ray, t_max)
    }

    /// [`Self::blocks`] compiled for AVX2, as [`Self::hit_avx2`].
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[allow(unsafe_code)]
    fn blocks_avx2(&self, ray: &Ray, t_max: f64) -> bool {
        // SAFETY: this function runs only where AVX2 is.
        unsafe { self.blocks_in_lanes(ray, t_max) }
    }

    /// [`Self::blocks`] compiled for AVX-512 processors, as [`Self::hit_avx512`].
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,avx512f,avx512vl")]
    #[allow(unsafe_code)]
    fn blocks_avx512(&self, ray: &Ray, t_max: f64) -> bool {
        // SAFETY: this function runs only where AVX-512 (and so AVX2) is.
        unsafe { self.blocks_in_lanes(ray, t_max) }
    }

    /// [`Self::blocks`] with AVX2, the ray prepared in lanes once, as [`Self::hit_in_lanes`].
    ///
    /// # Safety
    /// Only on a processor with AVX2.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    #[allow(unsafe_code)]
    unsafe fn blocks_in_lanes(&self, ray: &Ray, t_max: f64) -> bool {
        let a = &*self.accel;
        if let Some(alpha) = &self.alpha {
            // SAFETY: the caller's contract.
            return unsafe { self.blocks_kept::<true>(ray, t_max, alpha) };
        }
        // SAFETY: the caller's contract.
        let mut visit =
            AnyInLanes { packets: &a.packets, ray: unsafe { super::flat_packet::ray_in_lanes(ray) }, blocked: false };
        // SAFETY: the caller's contract.
        unsafe { self.traverse::<true, false>(ray, t_max, &mut visit) };
        visit.blocked
    }

    /// [`Self::blocks`] without AVX2, as [`Self::hit_portable`].
    #[allow(unsafe_code)]
    fn blocks_portable(&self, ray: &Ray, t_max: f64) -> bool {
        let a = &*self.accel;
        if let Some(alpha) = &self.alpha {
            // SAFETY: without AVX2.
            return unsafe { self.blocks_kept::<false>(ray, t_max, alpha) };
        }
        let mut blocked = false;
        let visit = |packets: std::ops::Range<usize>, t_max| {
            blocked = FlatPacket::any_of(&a.packets.packets[packets], ray, t_max, a.vectors);
            blocked.then_some(0.0)
        };
        // SAFETY: without AVX2.
        unsafe { self.traverse::<false, false>(ray, t_max, visit) };
        blocked
    }

    /// [`Self::blocks`] on a mesh with cut-outs: some hit in `(0, t_max)` where `alpha`
    /// says the surface is.
    ///
    /// # Safety
    /// `AVX2` only on a processor with AVX2.
    #[inline(always)]
    #[allow(unsafe_code)]
    unsafe fn blocks_kept<const AVX2: bool>(&self, ray: &Ray, t_max: f64, alpha: &AlphaMask) -> bool {
        let a = &*self.accel;
        let mut blocked = false;
        let visit = |packets: std::ops::Range<usize>, t_max| {
            // Most leaves a shadow ray meets hold nothing on it: asked in vector lanes.
            if !FlatPacket::any_of(&a.packets.packets[packets.clone()], ray, t_max, a.vectors) {
                return None;
            }
            blocked = a.packets.nearest_kept(packets, ray, t_max, covered(a, alpha, ray)).is_some();
            blocked.then_some(0.0)
        };
        // SAFETY: the caller's contract.
        unsafe { self.traverse::<AVX2, false>(ray, t_max, visit) };
        blocked
    }

    /// The surface at a hit found by [`MeshShape::hit`].
    pub fn surface_at(&self, c: Candidate) -> SurfaceHit {
        self.surface(c.aux as usize, (c.t, c.bary[0], c.bary[1]))
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
        self.accel.bvh.traverse_leaves(&shifted, f64::INFINITY, |packets, _| {
            for i in self.accel.packets.lanes_of(packets).flat_map(|lane| lane.triangles()) {
                if let Some((t, b1, b2)) = triangle_hit(&shifted, m.corners(i)).filter(|h| h.0 > 0.0) {
                    let hit = self.surface(i, (t + back, b1, b2));
                    out.push(Crossing { hit, entering: hit.n.dot(ray.dir) < 0.0 });
                }
            }
            None
        });
    }

    /// Bounding box.
    pub fn bounds(&self) -> Bounds3 {
        self.accel.bvh.bounds()
    }
}

/// A leaf visit of [`MeshShape::hit_in_lanes`]: the nearest hit in the leaf's packets by the AVX2
/// kernel, inlined into the traversal. Made only where AVX2 is (its ray comes from the `unsafe`
/// [`super::flat_packet::ray_in_lanes`]).
#[cfg(target_arch = "x86_64")]
struct NearestInLanes<'a> {
    packets: &'a PackedFlats<FlatLane>,
    ray: super::flat_packet::RayLanes,
    best: Option<(FlatLane, LaneHit)>,
}

#[cfg(target_arch = "x86_64")]
impl crate::bvh::LeafVisit for &mut NearestInLanes<'_> {
    #[inline(always)]
    #[allow(unsafe_code)]
    fn visit(&mut self, packets: std::ops::Range<usize>, t_max: f64) -> Option<f64> {
        // SAFETY: a visit is made only where AVX2 is (see the type).
        let (lane, h) = unsafe { self.packets.nearest_in_lanes(packets, &self.ray, t_max) }?;
        self.best = Some((lane, h));
        Some(h.t)
    }
}

/// A leaf visit of [`MeshShape::blocks_in_lanes`]: whether the leaf's packets hold a hit, as
/// [`NearestInLanes`].
#[cfg(target_arch = "x86_64")]
struct AnyInLanes<'a> {
    packets: &'a PackedFlats<FlatLane>,
    ray: super::flat_packet::RayLanes,
    blocked: bool,
}

#[cfg(target_arch = "x86_64")]
impl crate::bvh::LeafVisit for &mut AnyInLanes<'_> {
    #[inline(always)]
    #[allow(unsafe_code)]
    fn visit(&mut self, packets: std::ops::Range<usize>, t_max: f64) -> Option<f64> {
        // SAFETY: a visit is made only where AVX2 is (see the type).
        self.blocked = unsafe { self.packets.any_in_lanes(packets, &self.ray, t_max) };
        self.blocked.then_some(0.0)
    }
}
