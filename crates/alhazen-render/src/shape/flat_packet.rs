//! Up to eight planar primitives ([`Flat`]s) tested against one ray at once: the top-level
//! BVH's leaves and the meshes' keep their triangles and parallelograms in such packets,
//! structure of arrays (Wald et al. 2008, "Getting Rid of Packets", multi-primitive leaves;
//! Embree's `Triangle4`).
//!
//! **Single precision.** A packet holds each flat as three planes in `f32`: its unit normal
//! `n` and barycentric axes `u`, `v`, each with its offset (`n·origin`, `u·origin`,
//! `v·origin`, taken in `f64` and rounded once). A ray meets it at
//! `t = (n·origin − n·o) / (n·d)` with `b1 = (u·o − u·origin) + t·(u·d)` and `b2` alike, the
//! ray rounded to `f32`. Eight lanes of `f32` are one AVX2 register, an operation where eight
//! lanes of `f64` take two (or one AVX-512 operation that Zen 4 splits in two), and the packet
//! is half the bytes: the flat tests of a Cornell box cost half as much, a million-triangle
//! mesh's leaves read 52 bytes a flat instead of 104. The price is accuracy: a plane's
//! distance from the ray's origin is good to about `8·2⁻²⁴·|o|` (the offsets make it
//! independent of the flat's size), which the tracers' self-intersection guard
//! ([`ray_epsilon`], `10⁻⁵·(1 + |p|)`) covers twentyfold, and barycentrics to
//! `2⁻²⁴·|p|/edge`, the accuracy of Embree's and Mitsuba 3's tests. Spheres, cylinders and the
//! BVH build stay in `f64`.
//!
//! Each lane does exactly [`Flat::hit`]'s `f32` arithmetic in the same order (no fused
//! multiply–add), so the AVX2 kernel, which AVX-512 processors also run, and the portable loop
//! give the same bits as each other and as the one-primitive test. The ray is tested against
//! all lanes without branches, which is what makes the packet pay: a scalar test's early exits
//! are unpredictable for rays in all directions. A leaf's packets are tested in one call that
//! keeps each lane's nearest hit in registers and compares lanes once at the end. For eight
//! rays at once ([`RayPacket`], the path tracer's lanes) the kernel turns round: the rays are
//! the lanes and each flat in turn is broadcast against them.

use super::Flat;
use alhazen_math::{Ray, Vec3};

/// Primitives per packet.
pub const LANES: usize = 8;

/// How far a ray leaving a surface at `p` starts off it (along the geometric normal), scaled
/// to the magnitude of its coordinates: twenty times the error of a flat's single-precision
/// plane distance, a ninth of Mitsuba 3's `(1 + |p|)·1500·2⁻²⁴`. Every tracer spawns rays with
/// it and shortens shadow rays by it.
#[inline(always)]
pub fn ray_epsilon(p: Vec3) -> f64 {
    1e-5 * (1.0 + p.abs().max_element())
}

/// A ray in single precision, its origin and direction rounded to nearest.
#[derive(Clone, Copy, Debug)]
struct Ray32 {
    origin: [f32; 3],
    dir: [f32; 3],
}

impl Ray32 {
    fn new(ray: &Ray) -> Self {
        Self { origin: round32(ray.origin), dir: round32(ray.dir) }
    }
}

/// `v`'s coordinates rounded to nearest `f32`s.
#[inline(always)]
fn round32(v: Vec3) -> [f32; 3] {
    [v.x as f32, v.y as f32, v.z as f32]
}

/// `a·b` summed as glam's `dot`: `(x·x + y·y) + z·z`.
#[inline(always)]
fn dot32(a: [f32; 3], b: [f32; 3]) -> f32 {
    (a[0] * b[0] + a[1] * b[1]) + a[2] * b[2]
}

/// One flat as the packets test it: three planes in `f32` (see the module's note).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct FlatPlanes {
    /// Unit normal, `u`, `v`.
    axes: [[f32; 3]; 3],
    /// Each axis's dot product with the flat's origin.
    offsets: [f32; 3],
    /// 1 for a triangle (`b1 + b2 ≤ 1`), 0 for a parallelogram (`b2 ≤ 1`).
    triangle: f32,
}

impl FlatPlanes {
    /// `flat`'s planes: its axes rounded to `f32`, their offsets computed from those rounded
    /// axes in `f64` and rounded once.
    pub(super) fn of(flat: &Flat) -> Self {
        let axes = [round32(flat.normal.normalize()), round32(flat.u), round32(flat.v)];
        let offsets = axes.map(|a| Vec3::new(a[0] as f64, a[1] as f64, a[2] as f64).dot(flat.origin) as f32);
        Self { axes, offsets, triangle: if flat.parallelogram { 0.0 } else { 1.0 } }
    }

    /// The hit `(t, b1, b2)` with `0 < t < t_max`: the arithmetic every kernel repeats.
    #[inline(always)]
    fn hit(&self, r: &Ray32, t_max: f32) -> Option<(f32, f32, f32)> {
        let [n, u, v] = self.axes;
        let t = (self.offsets[0] - dot32(n, r.origin)) / dot32(n, r.dir);
        let b1 = (dot32(u, r.origin) - self.offsets[1]) + t * dot32(u, r.dir);
        let b2 = (dot32(v, r.origin) - self.offsets[2]) + t * dot32(v, r.dir);
        let far = b2 + self.triangle * b1;
        // Also rejects NaN (rays in or parallel to the plane, unused lanes).
        let inside = t > 0.0 && t < t_max && (0.0..=1.0).contains(&b1) && b2 >= 0.0 && far <= 1.0;
        inside.then_some((t, b1, b2))
    }
}

impl Flat {
    /// The hit `(t, b1, b2)` with `0 < t < t_max`, in single precision as the packets test
    /// it (see [`crate::shape::FlatPacket`]).
    pub fn hit(&self, ray: &Ray, t_max: f64) -> Option<(f64, f64, f64)> {
        let (t, b1, b2) = FlatPlanes::of(self).hit(&Ray32::new(ray), t_max as f32)?;
        Some((t as f64, b1 as f64, b2 as f64))
    }
}

/// Up to eight flats, lane by lane; unused lanes (all zero) never report a hit.
#[derive(Clone, Debug)]
#[repr(C, align(64))]
pub struct FlatPacket {
    /// Axis `a`'s coordinate `c` in `axes[a][c]`, lane by lane (normal, `u`, `v`).
    axes: [[[f32; LANES]; 3]; 3],
    offsets: [[f32; LANES]; 3],
    triangle: [f32; LANES],
    /// Lanes in use (the first ones).
    used: usize,
}

/// Eight rays, coordinate by coordinate: ray `r` starts at `origin[axis][r]` and goes along
/// `dir[axis][r]`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C, align(64))]
pub struct RayPacket {
    /// Origins.
    pub origin: [[f64; LANES]; 3],
    /// Directions.
    pub dir: [[f64; LANES]; 3],
}

impl RayPacket {
    /// Ray `r`.
    #[inline]
    pub fn ray(&self, r: usize) -> Ray {
        let at = |a: &[[f64; LANES]; 3]| Vec3::new(a[0][r], a[1][r], a[2][r]);
        Ray::new(at(&self.origin), at(&self.dir))
    }

    /// Makes ray `r` `ray`.
    #[inline]
    pub fn set(&mut self, r: usize, ray: &Ray) {
        for axis in 0..3 {
            (self.origin[axis][r], self.dir[axis][r]) = (ray.origin[axis], ray.dir[axis]);
        }
    }
}

/// A packet's nearest hit: its lane and [`Flat::hit`]'s `(t, b1, b2)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LaneHit {
    /// Which flat of the packet.
    pub lane: usize,
    /// Ray parameter.
    pub t: f64,
    /// Coordinate along the first edge.
    pub b1: f64,
    /// Coordinate along the second edge.
    pub b2: f64,
}

impl LaneHit {
    fn new(lane: usize, (t, b1, b2): (f32, f32, f32)) -> Self {
        Self { lane, t: t as f64, b1: b1 as f64, b2: b2 as f64 }
    }
}

impl FlatPacket {
    /// The packet of `flats` (at most [`LANES`]); lane `i` is `flats[i]`.
    pub fn new(flats: &[Flat]) -> Self {
        assert!(flats.len() <= LANES, "a packet holds at most {LANES} flats");
        Self::of(flats.iter().copied())
    }

    /// The packet of the first [`LANES`] of `flats`, lane by lane.
    fn of(flats: impl Iterator<Item = Flat>) -> Self {
        // An unused lane is all zero: its t is 0/0, which fails every comparison.
        let mut p = Self { axes: [[[0.0; LANES]; 3]; 3], offsets: [[0.0; LANES]; 3], triangle: [0.0; LANES], used: 0 };
        for (lane, f) in flats.take(LANES).enumerate() {
            p.used = lane + 1;
            let planes = FlatPlanes::of(&f);
            for a in 0..3 {
                for c in 0..3 {
                    p.axes[a][c][lane] = planes.axes[a][c];
                }
                p.offsets[a][lane] = planes.offsets[a];
            }
            p.triangle[lane] = planes.triangle;
        }
        p
    }

    /// Lane `lane`'s planes.
    fn planes(&self, lane: usize) -> FlatPlanes {
        FlatPlanes {
            axes: self.axes.map(|a| a.map(|c| c[lane])),
            offsets: self.offsets.map(|o| o[lane]),
            triangle: self.triangle[lane],
        }
    }

    /// The nearest hit with `0 < t < t_max` among the lanes (the first lane on a tie), by the
    /// kernel of `unit`.
    #[inline]
    pub fn hit(&self, ray: &Ray, t_max: f64, unit: VectorUnit) -> Option<LaneHit> {
        Self::nearest_of(std::slice::from_ref(self), ray, t_max, unit).map(|(_, h)| h)
    }

    /// The nearest hit with `0 < t < t_max` in `packets`: the packet's index and its lane's hit
    /// (on a tie, the first packet, then the first lane). Same bits from every `unit`.
    #[inline]
    #[allow(unsafe_code)]
    pub fn nearest_of(packets: &[Self], ray: &Ray, t_max: f64, unit: VectorUnit) -> Option<(usize, LaneHit)> {
        let (r, t_max) = (Ray32::new(ray), t_max as f32);
        #[cfg(target_arch = "x86_64")]
        if unit.is_simd() {
            // SAFETY: a `VectorUnit` says AVX2 or AVX-512 (which includes AVX2) only where the
            // processor has it.
            return unsafe {
                if unit.is_avx512() {
                    simd::nearest_avx512(packets, &r, t_max)
                } else {
                    simd::nearest(packets, &r, t_max)
                }
            };
        }
        let _ = unit;
        let mut best = None;
        let mut limit = t_max;
        for (k, p) in packets.iter().enumerate() {
            for lane in 0..p.used {
                if let Some(h) = p.planes(lane).hit(&r, limit) {
                    (limit, best) = (h.0, Some((k, LaneHit::new(lane, h))));
                }
            }
        }
        best
    }

    /// True when some lane of `packets` is hit with `0 < t < t_max`.
    #[inline]
    #[allow(unsafe_code)]
    pub fn any_of(packets: &[Self], ray: &Ray, t_max: f64, unit: VectorUnit) -> bool {
        let (r, t_max) = (Ray32::new(ray), t_max as f32);
        #[cfg(target_arch = "x86_64")]
        if unit.is_simd() {
            // SAFETY: as in `nearest_of`.
            return unsafe {
                if unit.is_avx512() { simd::any_avx512(packets, &r, t_max) } else { simd::any(packets, &r, t_max) }
            };
        }
        let _ = unit;
        packets.iter().any(|p| (0..p.used).any(|lane| p.planes(lane).hit(&r, t_max).is_some()))
    }

    /// [`Self::nearest_of`] for eight rays at once: `found(r, k, hit)` for each `live` ray `r`
    /// that hits, with the same hit. With AVX2 or AVX-512 the rays are the lanes and each flat
    /// is broadcast against all eight, which needs no reduction across lanes and keeps eight
    /// independent tests in flight.
    #[allow(unsafe_code)]
    pub fn nearest_of_rays(
        packets: &[Self],
        rays: &RayPacket,
        live: [bool; LANES],
        unit: VectorUnit,
        mut found: impl FnMut(usize, usize, LaneHit),
    ) {
        #[cfg(target_arch = "x86_64")]
        if unit.is_simd() {
            // SAFETY: as in `nearest_of`.
            let hits = unsafe {
                if unit.is_avx512() {
                    simd::nearest_rays_avx512(packets, rays)
                } else {
                    simd::nearest_rays(packets, rays)
                }
            };
            for r in (0..LANES).filter(|&r| live[r] && hits.hit & (1 << r) != 0) {
                let at = hits.at[r] as usize;
                found(r, at / LANES, LaneHit::new(at % LANES, (hits.t[r], hits.b1[r], hits.b2[r])));
            }
            return;
        }
        for r in (0..LANES).filter(|&r| live[r]) {
            if let Some((k, h)) = Self::nearest_of(packets, &rays.ray(r), f64::INFINITY, unit) {
                found(r, k, h);
            }
        }
    }

    /// [`Self::any_of`] for eight rays at once, each with its own `t_max` (false where not
    /// `live`).
    #[allow(unsafe_code)]
    pub fn any_of_rays(
        packets: &[Self],
        rays: &RayPacket,
        t_max: &[f64; LANES],
        live: [bool; LANES],
        unit: VectorUnit,
    ) -> [bool; LANES] {
        #[cfg(target_arch = "x86_64")]
        if unit.is_simd() {
            // SAFETY: as in `nearest_of`.
            let hit = unsafe {
                if unit.is_avx512() {
                    simd::any_rays_avx512(packets, rays, t_max)
                } else {
                    simd::any_rays(packets, rays, t_max)
                }
            };
            return std::array::from_fn(|r| live[r] && hit & (1 << r) != 0);
        }
        std::array::from_fn(|r| live[r] && Self::any_of(packets, &rays.ray(r), t_max[r], unit))
    }
}

/// One packet of up to [`LANES`] flats and what each stands for.
fn pack<L: Copy + Default>(flats: impl Iterator<Item = (L, Flat)>) -> (FlatPacket, [L; LANES]) {
    let mut lanes = [L::default(); LANES];
    // Straight into the packet, no vector between (a million-triangle mesh makes a hundred
    // thousand packets).
    let flats = flats.zip(&mut lanes).map(|((lane, f), slot)| {
        *slot = lane;
        f
    });
    let packet = FlatPacket::of(flats);
    (packet, lanes)
}

/// Packets of flats with what each lane stands for (`L`), filled leaf by leaf.
#[derive(Clone, Debug, Default)]
pub struct PackedFlats<L> {
    /// The packets, the leaves' one after the other.
    pub packets: Vec<FlatPacket>,
    /// Lane by lane, what packet `k`'s flats are.
    pub lanes: Vec<[L; LANES]>,
}

impl<L: Copy + Default> PackedFlats<L> {
    /// Asks the processor to start loading packet `k` and what its lanes stand for.
    #[inline(always)]
    pub fn prefetch(&self, k: usize) {
        if let (Some(p), Some(l)) = (self.packets.get(k), self.lanes.get(k)) {
            crate::prefetch::prefetch_all(p);
            crate::prefetch::prefetch(l);
        }
    }

    /// What the flats of packets `range` stand for, in order (the lanes in use).
    pub fn lanes_of(&self, range: std::ops::Range<usize>) -> impl Iterator<Item = L> + '_ {
        range.flat_map(move |k| self.lanes[k][..self.packets[k].used].iter().copied())
    }

    /// Appends `flats`, in order, as packets of [`LANES`]; returns the range of their packets.
    pub fn push_leaf(&mut self, flats: &[(L, Flat)]) -> std::ops::Range<usize> {
        let first = self.packets.len();
        for chunk in flats.chunks(LANES) {
            let (packet, lanes) = pack(chunk.iter().copied());
            self.packets.push(packet);
            self.lanes.push(lanes);
        }
        first..self.packets.len()
    }

    /// The packets [`Self::push_leaf`] makes of the leaves `leaves` one after the other (leaf
    /// `i`'s `⌈len / LANES⌉` packets after leaf `i − 1`'s), each leaf the flats `flat(k)` for
    /// the indices `k` of `order[leaf]`: built on all threads into vectors of exactly their
    /// size, the same packets as one thread makes.
    pub fn of_leaves(order: &[u32], leaves: &[std::ops::Range<usize>], flat: impl Fn(u32) -> (L, Flat) + Sync) -> Self
    where
        L: Send,
    {
        use rayon::prelude::*;
        let chunks: Vec<_> = leaves
            .iter()
            .flat_map(|leaf| leaf.clone().step_by(LANES).map(|at| at..(at + LANES).min(leaf.end)))
            .collect();
        let mut packed = Self::default();
        chunks
            .par_iter()
            .map(|chunk| pack(order[chunk.clone()].iter().map(|&k| flat(k))))
            .unzip_into_vecs(&mut packed.packets, &mut packed.lanes);
        packed
    }

    /// The nearest hit in packets `range` (see [`FlatPacket::nearest_of`]): what its lane
    /// stands for and its hit.
    #[inline]
    pub fn nearest(
        &self,
        range: std::ops::Range<usize>,
        ray: &Ray,
        t_max: f64,
        unit: VectorUnit,
    ) -> Option<(L, LaneHit)> {
        let (k, h) = self.nearest_packet(range, ray, t_max, unit)?;
        Some((self.lanes[k][h.lane], h))
    }

    /// The nearest hit in packets `range` with `0 < t < t_max` that `keep` takes (ties to the
    /// first, as [`Self::nearest`]), `keep` asked only of hits nearer than the nearest kept so
    /// far: flat by flat in the scalar test, whose hits are the vector kernels' bits.
    pub fn nearest_kept(
        &self,
        range: std::ops::Range<usize>,
        ray: &Ray,
        t_max: f64,
        mut keep: impl FnMut(L, LaneHit) -> bool,
    ) -> Option<(L, LaneHit)> {
        let r = Ray32::new(ray);
        let mut limit = t_max as f32;
        let mut best = None;
        for k in range {
            let p = &self.packets[k];
            for lane in 0..p.used {
                if let Some(h) = p.planes(lane).hit(&r, limit) {
                    let hit = (self.lanes[k][lane], LaneHit::new(lane, h));
                    if keep(hit.0, hit.1) {
                        (limit, best) = (h.0, Some(hit));
                    }
                }
            }
        }
        best
    }

    /// [`Self::nearest`] naming the packet (its index among all) rather than its lane's label.
    #[inline]
    pub fn nearest_packet(
        &self,
        range: std::ops::Range<usize>,
        ray: &Ray,
        t_max: f64,
        unit: VectorUnit,
    ) -> Option<(usize, LaneHit)> {
        let first = range.start;
        let (k, h) = FlatPacket::nearest_of(&self.packets[range], ray, t_max, unit)?;
        Some((first + k, h))
    }
}

#[cfg(target_arch = "x86_64")]
pub(crate) use simd::RayLanes;

/// `ray` prepared for [`PackedFlats::nearest_in_lanes`] and [`PackedFlats::any_in_lanes`]:
/// rounded to `f32` and broadcast, once per traversal.
///
/// # Safety
/// Only on a processor with AVX2; fast only inlined into a function compiled for it.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
#[allow(unsafe_code)]
pub(crate) unsafe fn ray_in_lanes(ray: &Ray) -> RayLanes {
    // SAFETY: the caller's contract.
    unsafe { simd::lanes_of(ray) }
}

#[cfg(target_arch = "x86_64")]
impl<L: Copy + Default> PackedFlats<L> {
    /// [`Self::nearest`] by the AVX2 kernel for a ray in lanes ([`ray_in_lanes`]): the same
    /// hit, inlined into a caller compiled for AVX2 (a mesh's traversal).
    ///
    /// # Safety
    /// As [`ray_in_lanes`].
    #[inline(always)]
    #[allow(unsafe_code)]
    pub(crate) unsafe fn nearest_in_lanes(
        &self,
        range: std::ops::Range<usize>,
        r: &RayLanes,
        t_max: f64,
    ) -> Option<(L, LaneHit)> {
        // SAFETY: the caller's contract.
        let (k, h) = unsafe { self.nearest_packet_in_lanes(range, r, t_max) }?;
        Some((self.lanes[k][h.lane], h))
    }

    /// [`Self::nearest_in_lanes`] naming the packet (its index among all), as
    /// [`Self::nearest_packet`] does.
    ///
    /// # Safety
    /// As [`ray_in_lanes`].
    #[inline(always)]
    #[allow(unsafe_code)]
    pub(crate) unsafe fn nearest_packet_in_lanes(
        &self,
        range: std::ops::Range<usize>,
        r: &RayLanes,
        t_max: f64,
    ) -> Option<(usize, LaneHit)> {
        let first = range.start;
        // SAFETY: the caller's contract.
        let (k, h) = unsafe { simd::nearest_in(&self.packets[range], r, t_max as f32) }?;
        Some((first + k, h))
    }

    /// [`FlatPacket::any_of`] on packets `range` by the AVX2 kernel for a ray in lanes, as
    /// [`Self::nearest_in_lanes`].
    ///
    /// # Safety
    /// As [`ray_in_lanes`].
    #[inline(always)]
    #[allow(unsafe_code)]
    pub(crate) unsafe fn any_in_lanes(&self, range: std::ops::Range<usize>, r: &RayLanes, t_max: f64) -> bool {
        // SAFETY: the caller's contract.
        unsafe { simd::any_in(&self.packets[range], r, t_max as f32) }
    }
}

/// Which of the packet kernels runs: all give the same bits. A value can only come from
/// [`VectorUnit::detect`], [`VectorUnit::available`] or [`VectorUnit::PORTABLE`], so it never
/// names an instruction set this processor lacks (the kernels rely on that).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct VectorUnit(Unit);

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
enum Unit {
    /// One lane after the other (any processor).
    #[default]
    Portable,
    /// AVX2 registers (eight `f32` flats or four `f64` path lanes at a time).
    #[cfg(target_arch = "x86_64")]
    Avx2,
    /// All eight lanes in one AVX-512 register (F, DQ, VL and BW present).
    #[cfg(target_arch = "x86_64")]
    Avx512,
}

impl VectorUnit {
    /// The portable loop, on any processor.
    pub const PORTABLE: Self = Self(Unit::Portable);

    /// The widest kernel this processor runs.
    pub fn detect() -> Self {
        Self::available().pop().unwrap_or(Self::PORTABLE)
    }

    /// Every kernel this processor runs, narrowest first.
    pub fn available() -> Vec<Self> {
        let mut units = vec![Self::PORTABLE];
        #[cfg(target_arch = "x86_64")]
        {
            if std::arch::is_x86_feature_detected!("avx2") {
                units.push(Self(Unit::Avx2));
            }
            // F for the packets; DQ, VL and BW for the path tracer's lanes (64-bit integer
            // multiplies and conversions): every AVX-512 processor since Skylake-SP has all four.
            if std::arch::is_x86_feature_detected!("avx512f")
                && std::arch::is_x86_feature_detected!("avx512dq")
                && std::arch::is_x86_feature_detected!("avx512vl")
                && std::arch::is_x86_feature_detected!("avx512bw")
            {
                units.push(Self(Unit::Avx512));
            }
        }
        units
    }

    /// The AVX2 kernels run, on an AVX2 or an AVX-512 processor (flats are tested eight
    /// `f32` lanes at a time in AVX2 registers on both).
    #[inline]
    pub fn is_simd(self) -> bool {
        self.is_avx2() || self.is_avx512()
    }

    /// `portable`, `avx2` or `avx512`.
    pub fn name(self) -> &'static str {
        match self.0 {
            Unit::Portable => "portable",
            #[cfg(target_arch = "x86_64")]
            Unit::Avx2 => "avx2",
            #[cfg(target_arch = "x86_64")]
            Unit::Avx512 => "avx512",
        }
    }

    /// The AVX2 kernels run.
    #[inline]
    pub fn is_avx2(self) -> bool {
        #[cfg(target_arch = "x86_64")]
        {
            self.0 == Unit::Avx2
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            false
        }
    }

    /// The AVX-512 kernels run.
    #[inline]
    pub fn is_avx512(self) -> bool {
        #[cfg(target_arch = "x86_64")]
        {
            self.0 == Unit::Avx512
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            false
        }
    }
}

/// The kernels in AVX2 registers of eight `f32` lanes, run on AVX2 and AVX-512 processors
/// alike: [`FlatPlanes::hit`]'s operations, in its order, without its early exits.
#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
mod simd {
    use super::{FlatPacket, LANES, Ray32, RayPacket};
    use std::arch::x86_64::*;

    /// Eight f32s into a register, lane `i` from `a[i]`.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn load(a: &[f32; LANES]) -> __m256 {
        // SAFETY: `a` is eight readable f32s; `loadu` needs no alignment.
        unsafe { _mm256_loadu_ps(a.as_ptr()) }
    }

    #[inline]
    #[target_feature(enable = "avx2")]
    fn load3(a: &[[f32; LANES]; 3]) -> [__m256; 3] {
        [load(&a[0]), load(&a[1]), load(&a[2])]
    }

    /// `(a·b)` lane by lane, summed as glam's `dot`: `(x·x + y·y) + z·z`.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn dot(a: [__m256; 3], b: [__m256; 3]) -> __m256 {
        _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(a[0], b[0]), _mm256_mul_ps(a[1], b[1])), _mm256_mul_ps(a[2], b[2]))
    }

    /// A ray per lane (eight rays, or one in all lanes).
    pub(crate) struct RayLanes {
        origin: [__m256; 3],
        dir: [__m256; 3],
    }

    /// A flat per lane (a packet's eight, or one in all lanes).
    struct FlatLanes {
        axes: [[__m256; 3]; 3],
        offsets: [__m256; 3],
        triangle: __m256,
    }

    #[inline]
    #[target_feature(enable = "avx2")]
    fn ray_lanes(r: &Ray32) -> RayLanes {
        RayLanes { origin: r.origin.map(|x| _mm256_set1_ps(x)), dir: r.dir.map(|x| _mm256_set1_ps(x)) }
    }

    /// Eight rays, one per lane, rounded to `f32` as [`Ray32::new`] rounds them.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn rays_in_lanes(rays: &RayPacket) -> RayLanes {
        let row = |a: &[f64; LANES]| narrow(a);
        RayLanes { origin: rays.origin.each_ref().map(row), dir: rays.dir.each_ref().map(row) }
    }

    /// Eight f64s rounded to nearest f32s (as `as f32` rounds), lane `i` from `a[i]`.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn narrow(a: &[f64; LANES]) -> __m256 {
        // SAFETY: `a` is eight readable f64s; `loadu` needs no alignment.
        let (lo, hi) = unsafe { (_mm256_loadu_pd(a.as_ptr()), _mm256_loadu_pd(a[4..].as_ptr())) };
        _mm256_set_m128(_mm256_cvtpd_ps(hi), _mm256_cvtpd_ps(lo))
    }

    #[inline]
    #[target_feature(enable = "avx2")]
    fn packet_lanes(p: &FlatPacket) -> FlatLanes {
        FlatLanes { axes: p.axes.each_ref().map(|a| load3(a)), offsets: load3(&p.offsets), triangle: load(&p.triangle) }
    }

    /// Flat `lane` of `p` in every lane.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn broadcast(p: &FlatPacket, lane: usize) -> FlatLanes {
        let row = |a: &[[f32; LANES]; 3]| [0, 1, 2].map(|c| _mm256_set1_ps(a[c][lane]));
        FlatLanes {
            axes: p.axes.each_ref().map(row),
            offsets: row(&p.offsets),
            triangle: _mm256_set1_ps(p.triangle[lane]),
        }
    }

    /// `(t, b1, b2)` lane by lane and the lanes hit with `0 < t < t_max` (all ones there).
    #[inline]
    #[target_feature(enable = "avx2")]
    fn hits(f: &FlatLanes, r: &RayLanes, t_max: __m256) -> (__m256, __m256, __m256, __m256) {
        let [n, u, v] = f.axes;
        let t = _mm256_div_ps(_mm256_sub_ps(f.offsets[0], dot(n, r.origin)), dot(n, r.dir));
        let b1 = _mm256_add_ps(_mm256_sub_ps(dot(u, r.origin), f.offsets[1]), _mm256_mul_ps(t, dot(u, r.dir)));
        let b2 = _mm256_add_ps(_mm256_sub_ps(dot(v, r.origin), f.offsets[2]), _mm256_mul_ps(t, dot(v, r.dir)));
        let far = _mm256_add_ps(b2, _mm256_mul_ps(f.triangle, b1));
        let (zero, one) = (_mm256_setzero_ps(), _mm256_set1_ps(1.0));
        let in_t = _mm256_and_ps(_mm256_cmp_ps::<_CMP_GT_OQ>(t, zero), _mm256_cmp_ps::<_CMP_LT_OQ>(t, t_max));
        let in_b1 = _mm256_and_ps(_mm256_cmp_ps::<_CMP_GE_OQ>(b1, zero), _mm256_cmp_ps::<_CMP_LE_OQ>(b1, one));
        let in_b2 = _mm256_and_ps(_mm256_cmp_ps::<_CMP_GE_OQ>(b2, zero), _mm256_cmp_ps::<_CMP_LE_OQ>(far, one));
        (t, b1, b2, _mm256_and_ps(in_t, _mm256_and_ps(in_b1, in_b2)))
    }

    /// Each lane's nearest hit so far: strictly nearer replaces, so the earlier flat keeps a
    /// tie. `at` says which flat (`packet × LANES + lane`).
    struct Nearest {
        t: __m256,
        b1: __m256,
        b2: __m256,
        at: __m256i,
        /// All ones in the lanes with a hit.
        hit: __m256,
    }

    impl Nearest {
        #[inline]
        #[target_feature(enable = "avx2")]
        fn new(t_max: __m256) -> Self {
            let zero = _mm256_setzero_ps();
            Self { t: t_max, b1: zero, b2: zero, at: _mm256_setzero_si256(), hit: zero }
        }

        /// Takes the lanes of `hit` (from [`hits`]) nearer than what they hold, from flats `at`.
        #[inline]
        #[target_feature(enable = "avx2")]
        fn update(&mut self, (t, b1, b2, inside): (__m256, __m256, __m256, __m256), at: __m256i) {
            // Without a branch: which lanes are nearer is as good as random.
            let take = _mm256_and_ps(_mm256_cmp_ps::<_CMP_LT_OQ>(t, self.t), inside);
            self.t = _mm256_blendv_ps(self.t, t, take);
            self.b1 = _mm256_blendv_ps(self.b1, b1, take);
            self.b2 = _mm256_blendv_ps(self.b2, b2, take);
            self.at =
                _mm256_castps_si256(_mm256_blendv_ps(_mm256_castsi256_ps(self.at), _mm256_castsi256_ps(at), take));
            self.hit = _mm256_or_ps(self.hit, take);
        }

        #[inline]
        #[target_feature(enable = "avx2")]
        fn store(&self) -> Hits {
            let hit = _mm256_movemask_ps(self.hit) as u8;
            let mut out = Hits { hit, at: [0; LANES], t: [0.0; LANES], b1: [0.0; LANES], b2: [0.0; LANES] };
            // SAFETY: each destination is eight writable f32s or i32s; `storeu` needs no
            // alignment.
            unsafe {
                _mm256_storeu_ps(out.t.as_mut_ptr(), self.t);
                _mm256_storeu_ps(out.b1.as_mut_ptr(), self.b1);
                _mm256_storeu_ps(out.b2.as_mut_ptr(), self.b2);
                _mm256_storeu_si256(out.at.as_mut_ptr().cast(), self.at);
            }
            out
        }
    }

    /// Hits lane by lane: bit `i` of `hit` set where lane `i` hit flat `at[i]` (packet ×
    /// [`LANES`] + lane) at `t[i]`, `b1[i]`, `b2[i]`.
    pub(super) struct Hits {
        pub hit: u8,
        pub at: [i32; LANES],
        pub t: [f32; LANES],
        pub b1: [f32; LANES],
        pub b2: [f32; LANES],
    }

    /// [`FlatPacket::nearest_of`]'s kernel for a ray already in lanes: each lane keeps the
    /// nearest hit it has seen, and the lanes are compared once at the end (on a tie, the first
    /// flat). Inlined where the caller is compiled for AVX2 (a mesh's traversal, which prepares
    /// its ray once for all the leaves it visits): a leaf then costs no call and no registers
    /// saved around one.
    ///
    /// # Safety
    /// Only on a processor with AVX2, and fast only inlined into a function compiled for it.
    #[inline(always)]
    pub(crate) unsafe fn nearest_in(
        packets: &[FlatPacket],
        r: &RayLanes,
        t_max: f32,
    ) -> Option<(usize, super::LaneHit)> {
        // SAFETY: the caller's contract: every call below is to an AVX2 function.
        unsafe {
            let limit = _mm256_set1_ps(t_max);
            let mut best = Nearest::new(limit);
            let lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
            for (k, p) in packets.iter().enumerate() {
                let at = _mm256_add_epi32(_mm256_set1_epi32((k * LANES) as i32), lane);
                best.update(hits(&packet_lanes(p), r, limit), at);
            }
            // Most leaves a ray visits it misses, and most it hits it hits in one lane: neither
            // needs the lanes stored and compared (a loop whose branches follow random hits).
            let hit = _mm256_movemask_ps(best.hit) as u32;
            if hit == 0 {
                return None;
            }
            let h = best.store();
            let nearest = if hit & (hit - 1) == 0 {
                hit.trailing_zeros() as usize
            } else {
                (0..LANES)
                    .filter(|&l| h.hit & (1 << l) != 0)
                    .min_by(|&a, &b| h.t[a].total_cmp(&h.t[b]).then(h.at[a].cmp(&h.at[b])))?
            };
            let at = h.at[nearest] as usize;
            Some((at / LANES, super::LaneHit::new(at % LANES, (h.t[nearest], h.b1[nearest], h.b2[nearest]))))
        }
    }

    /// [`FlatPacket::any_of`]'s kernel for a ray already in lanes, as [`nearest_in`]: stops at
    /// the first packet with a lane hit.
    ///
    /// # Safety
    /// As [`nearest_in`].
    #[inline(always)]
    pub(crate) unsafe fn any_in(packets: &[FlatPacket], r: &RayLanes, t_max: f32) -> bool {
        // SAFETY: the caller's contract: every call below is to an AVX2 function.
        unsafe {
            let limit = _mm256_set1_ps(t_max);
            packets.iter().any(|p| _mm256_movemask_ps(hits(&packet_lanes(p), r, limit).3) != 0)
        }
    }

    /// `ray` rounded to `f32` as [`Ray32::new`] rounds it, in every lane: prepared once for all
    /// the leaves one traversal visits.
    ///
    /// # Safety
    /// As [`nearest_in`].
    #[inline(always)]
    pub(crate) unsafe fn lanes_of(ray: &alhazen_math::Ray) -> RayLanes {
        // SAFETY: the caller's contract.
        unsafe { ray_lanes(&Ray32::new(ray)) }
    }

    /// Defines each kernel twice from one body: for AVX2 processors (16 vector registers) and,
    /// named `…_avx512`, for AVX-512 ones, where the same AVX2 instructions (the same
    /// arithmetic, the same bits) get 32 registers: the rays, the flats and the nearest hits
    /// then stay in registers, where with 16 some spill to the stack — and where they spill
    /// was at the mercy of inlining elsewhere in the program (the eight-ray kernel's time moved
    /// by half with unrelated changes).
    macro_rules! kernels {
        ($($(#[$doc:meta])* fn $name:ident / $wide:ident ($($arg:ident: $ty:ty),*) -> $ret:ty $body:block)*) => {$(
            $(#[$doc])*
            #[target_feature(enable = "avx2")]
            pub(super) fn $name($($arg: $ty),*) -> $ret $body

            $(#[$doc])*
            #[target_feature(enable = "avx2,avx512f,avx512vl")]
            pub(super) fn $wide($($arg: $ty),*) -> $ret $body
        )*};
    }

    kernels! {
        /// [`FlatPacket::nearest_of`]: each lane keeps the nearest hit it has seen, and the
        /// lanes are compared once at the end (on a tie, the first flat).
        fn nearest / nearest_avx512(packets: &[FlatPacket], r: &Ray32, t_max: f32) -> Option<(usize, super::LaneHit)> {
            // SAFETY: this kernel runs only where AVX2 is.
            unsafe { nearest_in(packets, &ray_lanes(r), t_max) }
        }

        /// [`FlatPacket::any_of`]: stops at the first packet with a lane hit.
        fn any / any_avx512(packets: &[FlatPacket], r: &Ray32, t_max: f32) -> bool {
            // SAFETY: this kernel runs only where AVX2 is.
            unsafe { any_in(packets, &ray_lanes(r), t_max) }
        }

        /// Eight rays' nearest hits, ray by lane.
        fn nearest_rays / nearest_rays_avx512(packets: &[FlatPacket], rays: &RayPacket) -> Hits {
            let r = rays_in_lanes(rays);
            let limit = _mm256_set1_ps(f32::INFINITY);
            let mut best = Nearest::new(limit);
            for (k, p) in packets.iter().enumerate() {
                for lane in 0..p.used {
                    let at = _mm256_set1_epi32((k * LANES + lane) as i32);
                    best.update(hits(&broadcast(p, lane), &r, limit), at);
                }
            }
            best.store()
        }

        /// [`FlatPacket::any_of_rays`]: the rays blocked by some flat, one bit per ray.
        fn any_rays / any_rays_avx512(packets: &[FlatPacket], rays: &RayPacket, t_max: &[f64; LANES]) -> u8 {
            let r = rays_in_lanes(rays);
            let limit = narrow(t_max);
            let mut blocked = _mm256_setzero_ps();
            for p in packets {
                for lane in 0..p.used {
                    blocked = _mm256_or_ps(blocked, hits(&broadcast(p, lane), &r, limit).3);
                }
            }
            _mm256_movemask_ps(blocked) as u8
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn vec3() -> impl Strategy<Value = Vec3> {
        (-2.0..2.0f64, -2.0..2.0f64, -2.0..2.0f64).prop_map(|(x, y, z)| Vec3::new(x, y, z))
    }

    fn flat() -> impl Strategy<Value = Option<Flat>> {
        (vec3(), vec3(), vec3(), any::<bool>()).prop_map(|(o, e1, e2, par)| Flat::new(o, e1, e2, par))
    }

    proptest! {
        /// Every kernel agrees bit for bit with testing the flats one by one, in order, over
        /// packets of any fill.
        #[test]
        fn packets_equal_flat_by_flat(
            flats in prop::collection::vec(flat(), 1..=3 * LANES),
            fill in 1..=LANES,
            origin in vec3(),
            dir in vec3(),
            t_max in prop_oneof![Just(f64::INFINITY), 0.1..5.0f64],
        ) {
            let flats: Vec<Flat> = flats.into_iter().flatten().collect();
            prop_assume!(!flats.is_empty() && dir.length() > 1e-3);
            let ray = Ray::new(origin, dir.normalize());
            let mut expected = None;
            let mut limit = t_max;
            for (i, f) in flats.iter().enumerate() {
                if let Some((t, b1, b2)) = f.hit(&ray, limit) {
                    limit = t;
                    expected = Some((i / fill, LaneHit { lane: i % fill, t, b1, b2 }));
                }
            }
            let packets: Vec<FlatPacket> = flats.chunks(fill).map(FlatPacket::new).collect();
            for unit in VectorUnit::available() {
                prop_assert_eq!(FlatPacket::nearest_of(&packets, &ray, t_max, unit), expected, "{:?}", unit);
                prop_assert_eq!(FlatPacket::any_of(&packets, &ray, t_max, unit), expected.is_some(), "{:?}", unit);
            }
        }

        /// Eight rays at once find what each finds alone (nearest without a limit; any-hit
        /// with each ray's own), and nothing for rays not live.
        #[test]
        fn eight_rays_equal_one_by_one(
            flats in prop::collection::vec(flat(), 1..=3 * LANES),
            fill in 1..=LANES,
            rays in prop::collection::vec((vec3(), vec3(), 0.1..5.0f64, any::<bool>()), LANES),
        ) {
            let flats: Vec<Flat> = flats.into_iter().flatten().collect();
            prop_assume!(!flats.is_empty() && rays.iter().all(|r| r.1.length() > 1e-3));
            let packets: Vec<FlatPacket> = flats.chunks(fill).map(FlatPacket::new).collect();
            let ray_of = |r: &(Vec3, Vec3, f64, bool)| Ray::new(r.0, r.1.normalize());
            let mut all = RayPacket::default();
            rays.iter().enumerate().for_each(|(i, r)| all.set(i, &ray_of(r)));
            let t_max = std::array::from_fn(|i| rays[i].2);
            let live = std::array::from_fn(|i| rays[i].3);
            for unit in VectorUnit::available() {
                let mut found = [None; LANES];
                FlatPacket::nearest_of_rays(&packets, &all, live, unit, |r, k, h| found[r] = Some((k, h)));
                let blocked = FlatPacket::any_of_rays(&packets, &all, &t_max, live, unit);
                for r in 0..LANES {
                    let alone = FlatPacket::nearest_of(&packets, &all.ray(r), f64::INFINITY, unit);
                    prop_assert_eq!(found[r], alone.filter(|_| live[r]), "{:?}", unit);
                    let any = FlatPacket::any_of(&packets, &all.ray(r), t_max[r], unit);
                    prop_assert_eq!(blocked[r], any && live[r], "{:?}", unit);
                }
            }
        }
    }

    proptest! {
        /// The tracers' guard covers the single-precision test: a ray leaving a flat from
        /// `ray_epsilon` off it never meets that flat again, and one aimed back into it does,
        /// at coordinates up to 10⁴ (and flats up to that size).
        #[test]
        fn the_guard_covers_single_precision(
            corner in vec3(),
            e1 in vec3(),
            e2 in vec3(),
            parallelogram in any::<bool>(),
            at in (0.05..0.45f64, 0.05..0.45f64),
            dir in vec3(),
            scale in prop_oneof![Just(1.0), Just(100.0), Just(1e4)],
        ) {
            let Some(f) = Flat::new(corner * scale, e1 * scale, e2 * scale, parallelogram) else { return Ok(()) };
            prop_assume!(dir.length() > 1e-3);
            let n = f.normal.normalize();
            let p = corner * scale + e1 * scale * at.0 + e2 * scale * at.1;
            let origin = p + n * ray_epsilon(p);
            let dir = dir.normalize();
            // Away from the surface (not grazing it closer than 1 %), and back into it.
            prop_assume!(dir.dot(n).abs() > 0.01);
            let (away, into) = if dir.dot(n) > 0.0 { (dir, -dir) } else { (-dir, dir) };
            let packet = [FlatPacket::new(&[f])];
            for unit in VectorUnit::available() {
                prop_assert!(FlatPacket::nearest_of(&packet, &Ray::new(origin, away), f64::INFINITY, unit).is_none());
                prop_assert!(FlatPacket::nearest_of(&packet, &Ray::new(origin, into), f64::INFINITY, unit).is_some());
            }
        }
    }

    /// Two flats in one plane: the first packet's wins, whatever lane the other is in.
    #[test]
    fn ties_go_to_the_first_packet_then_the_first_lane() {
        let f = Flat::new(Vec3::ZERO, Vec3::X, Vec3::Y, true).unwrap();
        let g = Flat::new(Vec3::new(-1.0, -1.0, 0.0), Vec3::X * 3.0, Vec3::Y * 3.0, true).unwrap();
        let far = Flat::new(Vec3::new(0.0, 0.0, -1.0), Vec3::X, Vec3::Y, true).unwrap();
        let down = Ray::new(Vec3::new(0.5, 0.5, 1.0), -Vec3::Z);
        // (packets, the winner's packet and lane): a tie within a lane, then across lanes.
        let cases = [
            (vec![FlatPacket::new(&[f, far, far]), FlatPacket::new(&[g, f])], (0, 0)),
            (vec![FlatPacket::new(&[far, f]), FlatPacket::new(&[g])], (0, 1)),
        ];
        for (packets, winner) in cases {
            for unit in VectorUnit::available() {
                let (k, h) = FlatPacket::nearest_of(&packets, &down, f64::INFINITY, unit).unwrap();
                assert_eq!(((k, h.lane), h.t), (winner, 1.0), "{unit:?}");
            }
        }
    }

    #[test]
    fn unused_lanes_and_rays_in_the_plane_never_hit() {
        let f = Flat::new(Vec3::ZERO, Vec3::X, Vec3::Y, true).unwrap();
        let packet = FlatPacket::new(&[f]);
        for unit in VectorUnit::available() {
            let down = Ray::new(Vec3::new(0.5, 0.5, 1.0), -Vec3::Z);
            assert_eq!(packet.hit(&down, f64::INFINITY, unit).map(|h| (h.lane, h.t)), Some((0, 1.0)));
            let grazing = Ray::new(Vec3::new(-1.0, 0.5, 0.0), Vec3::X);
            assert_eq!(packet.hit(&grazing, f64::INFINITY, unit), None);
            assert_eq!(FlatPacket::new(&[]).hit(&down, f64::INFINITY, unit), None);
        }
    }
}
