//! Up to eight planar primitives ([`Flat`]s) tested against one ray at once: the top-level
//! BVH's leaves keep their triangles and parallelograms in such packets, structure of arrays
//! (Wald et al. 2008, "Getting Rid of Packets", multi-primitive leaves; Embree's `Triangle4`).
//!
//! Each lane does exactly [`Flat::hit`]'s arithmetic in the same order (no fused multiply–add),
//! so the AVX-512 and AVX2 kernels, used where the processor has them, and the portable loop
//! give the same bits as each other and as the one-primitive test. Packets hold eight flats for
//! the AVX-512 kernel and four elsewhere ([`VectorUnit::lanes`]). The ray is tested against
//! all lanes without branches, which is what makes the packet pay: a scalar test's early exits
//! are unpredictable for rays in all directions. With AVX-512, a leaf's packets are tested in
//! one call that keeps each lane's nearest hit in registers and compares lanes once at the end.
//! For eight rays at once ([`RayPacket`], the path tracer's lanes) the AVX-512 kernel turns
//! round: the rays are the lanes and each flat in turn is broadcast against them.

use super::Flat;
use alhazen_math::{Ray, Vec3};

/// Primitives per packet.
pub const LANES: usize = 8;
/// Lanes per AVX2 register.
const HALF: usize = 4;

/// Up to eight flats, lane by lane; unused lanes never report a hit.
#[derive(Clone, Debug)]
#[repr(C, align(32))]
pub struct FlatPacket {
    origin: [[f64; LANES]; 3],
    normal: [[f64; LANES]; 3],
    u: [[f64; LANES]; 3],
    v: [[f64; LANES]; 3],
    /// 1 for a triangle (`b1 + b2 ≤ 1`), 0 for a parallelogram (`b2 ≤ 1`).
    triangle: [f64; LANES],
    /// Lanes in use (the first ones).
    used: usize,
}

/// Eight rays, coordinate by coordinate: ray `r` starts at `origin[axis][r]` and goes along
/// `dir[axis][r]`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
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

impl FlatPacket {
    /// The packet of `flats` (at most [`LANES`]); lane `i` is `flats[i]`.
    pub fn new(flats: &[Flat]) -> Self {
        assert!(flats.len() <= LANES, "a packet holds at most {LANES} flats");
        // An unused lane has a zero normal: its t is 0/0, which fails every comparison.
        let mut p = Self {
            origin: [[0.0; LANES]; 3],
            normal: [[0.0; LANES]; 3],
            u: [[0.0; LANES]; 3],
            v: [[0.0; LANES]; 3],
            triangle: [0.0; LANES],
            used: flats.len(),
        };
        for (lane, f) in flats.iter().enumerate() {
            for axis in 0..3 {
                p.origin[axis][lane] = f.origin[axis];
                p.normal[axis][lane] = f.normal[axis];
                p.u[axis][lane] = f.u[axis];
                p.v[axis][lane] = f.v[axis];
            }
            p.triangle[lane] = if f.is_parallelogram() { 0.0 } else { 1.0 };
        }
        p
    }

    /// The nearest hit with `0 < t < t_max` among the lanes (the first lane on a tie), by the
    /// kernel of `unit`.
    #[inline]
    #[allow(unsafe_code)]
    pub fn hit(&self, ray: &Ray, t_max: f64, unit: VectorUnit) -> Option<LaneHit> {
        match unit.0 {
            Unit::Portable => self.hit_portable(ray, t_max),
            #[cfg(target_arch = "x86_64")]
            // SAFETY: a `VectorUnit` says AVX2 only where the processor has it (`available`).
            Unit::Avx2 => unsafe { avx2::hit(self, ray, t_max) },
            #[cfg(target_arch = "x86_64")]
            // SAFETY: a `VectorUnit` says AVX-512F only where the processor has it.
            Unit::Avx512 => unsafe { avx512::nearest(std::slice::from_ref(self), ray, t_max) }.map(|(_, h)| h),
        }
    }

    /// The nearest hit with `0 < t < t_max` in `packets`: the packet's index and its lane's hit
    /// (on a tie, the first packet, then the first lane). Same bits from every `unit`.
    #[inline]
    #[allow(unsafe_code)]
    pub fn nearest_of(packets: &[Self], ray: &Ray, t_max: f64, unit: VectorUnit) -> Option<(usize, LaneHit)> {
        #[cfg(target_arch = "x86_64")]
        if unit.is_avx512() {
            // SAFETY: a `VectorUnit` says AVX-512F only where the processor has it.
            return unsafe { avx512::nearest(packets, ray, t_max) };
        }
        let mut best = None;
        let mut t_max = t_max;
        for (k, p) in packets.iter().enumerate() {
            if let Some(h) = p.hit(ray, t_max, unit) {
                (t_max, best) = (h.t, Some((k, h)));
            }
        }
        best
    }

    /// True when some lane of `packets` is hit with `0 < t < t_max`.
    #[inline]
    #[allow(unsafe_code)]
    pub fn any_of(packets: &[Self], ray: &Ray, t_max: f64, unit: VectorUnit) -> bool {
        #[cfg(target_arch = "x86_64")]
        if unit.is_avx512() {
            // SAFETY: a `VectorUnit` says AVX-512F only where the processor has it.
            return unsafe { avx512::any(packets, ray, t_max) };
        }
        packets.iter().any(|p| p.hit(ray, t_max, unit).is_some())
    }

    /// [`Self::nearest_of`] for eight rays at once: `found(r, k, hit)` for each `live` ray `r`
    /// that hits, with the same hit. With AVX-512 the rays are the lanes and each flat is
    /// broadcast against all eight, which needs no reduction across lanes and keeps eight
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
        if unit.is_avx512() {
            // SAFETY: a `VectorUnit` says AVX-512F only where the processor has it.
            let hits = unsafe { avx512::nearest_rays(packets, rays) };
            for r in (0..LANES).filter(|&r| live[r] && hits.hit & (1 << r) != 0) {
                let at = hits.at[r] as usize;
                found(r, at / LANES, LaneHit { lane: at % LANES, t: hits.t[r], b1: hits.b1[r], b2: hits.b2[r] });
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
        if unit.is_avx512() {
            // SAFETY: a `VectorUnit` says AVX-512F only where the processor has it.
            let hit = unsafe { avx512::any_rays(packets, rays, t_max) };
            return std::array::from_fn(|r| live[r] && hit & (1 << r) != 0);
        }
        std::array::from_fn(|r| live[r] && Self::any_of(packets, &rays.ray(r), t_max[r], unit))
    }

    /// Lane `lane` as a [`Flat`] (an unused lane: one with a zero normal, which no ray hits).
    fn lane(&self, lane: usize) -> Flat {
        let at = |a: &[[f64; LANES]; 3]| Vec3::new(a[0][lane], a[1][lane], a[2][lane]);
        let (origin, normal, u, v) = (at(&self.origin), at(&self.normal), at(&self.u), at(&self.v));
        Flat { origin, normal, u, v, parallelogram: self.triangle[lane] == 0.0 }
    }

    /// [`Self::hit`] one lane after the other, each by [`Flat::hit`].
    fn hit_portable(&self, ray: &Ray, mut t_max: f64) -> Option<LaneHit> {
        let mut best = None;
        for lane in 0..self.used {
            if let Some((t, b1, b2)) = self.lane(lane).hit(ray, t_max) {
                t_max = t;
                best = Some(LaneHit { lane, t, b1, b2 });
            }
        }
        best
    }
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
    /// Room for `packets` more packets, reserved at once: a big mesh's packets are the largest
    /// thing it builds, and a vector doubling as it grows holds both copies for a moment.
    pub fn reserve(&mut self, packets: usize) {
        self.packets.reserve_exact(packets);
        self.lanes.reserve_exact(packets);
    }

    /// Asks the processor to start loading packet `k` and what its lanes stand for.
    #[inline(always)]
    #[allow(unsafe_code)]
    pub fn prefetch(&self, k: usize) {
        #[cfg(target_arch = "x86_64")]
        if let (Some(p), Some(l)) = (self.packets.get(k), self.lanes.get(k)) {
            // SAFETY: prefetching never faults; SSE is part of x86-64.
            unsafe {
                use std::arch::x86_64::*;
                let p: *const i8 = (p as *const FlatPacket).cast();
                for line in (0..std::mem::size_of::<FlatPacket>().min(256)).step_by(64) {
                    _mm_prefetch(p.add(line), _MM_HINT_T0);
                }
                _mm_prefetch((l as *const [L; LANES]).cast(), _MM_HINT_T0);
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        let _ = k;
    }

    /// What the flats of packets `range` stand for, in order (the lanes in use).
    pub fn lanes_of(&self, range: std::ops::Range<usize>) -> impl Iterator<Item = L> + '_ {
        range.flat_map(move |k| self.lanes[k][..self.packets[k].used].iter().copied())
    }

    /// Appends `flats`, in order, as packets of `width` ([`VectorUnit::lanes`]); returns the
    /// range of their packets.
    pub fn push_leaf(&mut self, flats: &[(L, Flat)], width: usize) -> std::ops::Range<usize> {
        let first = self.packets.len();
        for chunk in flats.chunks(width) {
            let packet: Vec<Flat> = chunk.iter().map(|(_, f)| *f).collect();
            self.packets.push(FlatPacket::new(&packet));
            let mut lanes = [L::default(); LANES];
            chunk.iter().zip(&mut lanes).for_each(|((lane, _), slot)| *slot = *lane);
            self.lanes.push(lanes);
        }
        first..self.packets.len()
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
        let first = range.start;
        let (k, h) = FlatPacket::nearest_of(&self.packets[range], ray, t_max, unit)?;
        Some((self.lanes[first + k][h.lane], h))
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
    /// Two halves of four lanes in AVX2 registers.
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

    /// Flats per packet for this kernel: eight fill an AVX-512 register; four an AVX2 one, and
    /// a packet of eight would mostly test empty lanes there.
    pub fn lanes(self) -> usize {
        if self.is_avx512() { LANES } else { HALF }
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

#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
mod avx2 {
    use super::{FlatPacket, HALF, LANES, LaneHit};
    use alhazen_math::Ray;
    use std::arch::x86_64::*;

    /// Lanes `half·4 ..` of `a`, lane `i` of the register being lane `half·4 + i`.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn load(a: &[f64; LANES], half: usize) -> __m256d {
        // SAFETY: `half` is 0 or 1, so four f64s from `half·4` are in `a`; `loadu` needs no
        // alignment.
        unsafe { _mm256_loadu_pd(a[half * HALF..].as_ptr()) }
    }

    /// `(a·b)` lane by lane, summed as glam's `dot`: `(x·x + y·y) + z·z`.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn dot(a: [__m256d; 3], b: [__m256d; 3]) -> __m256d {
        _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(a[0], b[0]), _mm256_mul_pd(a[1], b[1])), _mm256_mul_pd(a[2], b[2]))
    }

    #[inline]
    #[target_feature(enable = "avx2")]
    fn load3(a: &[[f64; LANES]; 3], half: usize) -> [__m256d; 3] {
        [load(&a[0], half), load(&a[1], half), load(&a[2], half)]
    }

    /// [`FlatPacket::hit_portable`] in AVX2 registers, four lanes at a time.
    #[target_feature(enable = "avx2")]
    pub(super) fn hit(p: &FlatPacket, ray: &Ray, t_max: f64) -> Option<LaneHit> {
        let first = hit_half(p, ray, t_max, 0);
        if p.used <= HALF {
            return first;
        }
        hit_half(p, ray, first.map_or(t_max, |h| h.t), 1).or(first)
    }

    /// [`super::Flat::hit`]'s operations on four lanes, in its order, combined without its
    /// early exits.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn hit_half(p: &FlatPacket, ray: &Ray, t_max: f64, half: usize) -> Option<LaneHit> {
        let ro = [_mm256_set1_pd(ray.origin.x), _mm256_set1_pd(ray.origin.y), _mm256_set1_pd(ray.origin.z)];
        let rd = [_mm256_set1_pd(ray.dir.x), _mm256_set1_pd(ray.dir.y), _mm256_set1_pd(ray.dir.z)];
        let o = load3(&p.origin, half);
        let to_flat = [_mm256_sub_pd(o[0], ro[0]), _mm256_sub_pd(o[1], ro[1]), _mm256_sub_pd(o[2], ro[2])];
        let n = load3(&p.normal, half);
        let t = _mm256_div_pd(dot(n, to_flat), dot(n, rd));
        // As `Flat::hit`: `t·(d·u) − (o − r)·u`, the dot products independent of the division.
        let (u, v) = (load3(&p.u, half), load3(&p.v, half));
        let b1 = _mm256_sub_pd(_mm256_mul_pd(t, dot(rd, u)), dot(to_flat, u));
        let b2 = _mm256_sub_pd(_mm256_mul_pd(t, dot(rd, v)), dot(to_flat, v));
        let far = _mm256_add_pd(b2, _mm256_mul_pd(load(&p.triangle, half), b1));
        let (zero, one) = (_mm256_setzero_pd(), _mm256_set1_pd(1.0));
        let in_t =
            _mm256_and_pd(_mm256_cmp_pd::<_CMP_GT_OQ>(t, zero), _mm256_cmp_pd::<_CMP_LT_OQ>(t, _mm256_set1_pd(t_max)));
        let in_b1 = _mm256_and_pd(_mm256_cmp_pd::<_CMP_GE_OQ>(b1, zero), _mm256_cmp_pd::<_CMP_LE_OQ>(b1, one));
        let in_b2 = _mm256_and_pd(_mm256_cmp_pd::<_CMP_GE_OQ>(b2, zero), _mm256_cmp_pd::<_CMP_LE_OQ>(far, one));
        let inside = _mm256_and_pd(in_t, _mm256_and_pd(in_b1, in_b2));
        if _mm256_movemask_pd(inside) == 0 {
            return None;
        }
        // The smallest t of the lanes inside, then the first lane that has it.
        let t = _mm256_blendv_pd(_mm256_set1_pd(f64::INFINITY), t, inside);
        let min = _mm256_min_pd(t, _mm256_permute4x64_pd::<0b01_00_11_10>(t));
        let min = _mm256_min_pd(min, _mm256_permute_pd::<0b0101>(min));
        let lane = _mm256_movemask_pd(_mm256_cmp_pd::<_CMP_EQ_OQ>(t, min)).trailing_zeros() as usize;
        let mut lanes = [[0.0; HALF]; 3];
        for (dst, src) in lanes.iter_mut().zip([t, b1, b2]) {
            // SAFETY: `dst` is four writable f64s; `storeu` needs no alignment.
            unsafe { _mm256_storeu_pd(dst.as_mut_ptr(), src) };
        }
        Some(LaneHit { lane: half * HALF + lane, t: lanes[0][lane], b1: lanes[1][lane], b2: lanes[2][lane] })
    }
}

#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
mod avx512 {
    use super::super::avx512::{NearestLanes, RayLanes, dot, lane_of, load, load3, ray_lanes};
    use super::{FlatPacket, LANES, LaneHit, RayPacket};
    use alhazen_math::Ray;
    use std::arch::x86_64::*;

    /// [`super::Flat::hit`]'s operations on all eight lanes, in its order, without its early
    /// exits: `(t, b1, b2)` and the lanes hit with `0 < t < t_max`.
    #[inline]
    #[target_feature(enable = "avx512f")]
    fn lanes(p: &FlatPacket, r: &RayLanes, t_max: __m512d) -> (__m512d, __m512d, __m512d, __mmask8) {
        let flat = FlatLanes {
            origin: load3(&p.origin),
            normal: load3(&p.normal),
            u: load3(&p.u),
            v: load3(&p.v),
            triangle: load(&p.triangle),
        };
        flat_lanes(&flat, r, t_max)
    }

    /// A flat per lane (eight of a packet, or one in all lanes).
    struct FlatLanes {
        origin: [__m512d; 3],
        normal: [__m512d; 3],
        u: [__m512d; 3],
        v: [__m512d; 3],
        triangle: __m512d,
    }

    /// [`lanes`] for a flat and a ray per lane.
    #[inline]
    #[target_feature(enable = "avx512f")]
    fn flat_lanes(p: &FlatLanes, r: &RayLanes, t_max: __m512d) -> (__m512d, __m512d, __m512d, __mmask8) {
        let (ro, rd, o) = (&r.origin, r.dir, p.origin);
        let to_flat = [_mm512_sub_pd(o[0], ro[0]), _mm512_sub_pd(o[1], ro[1]), _mm512_sub_pd(o[2], ro[2])];
        let n = p.normal;
        let t = _mm512_div_pd(dot(n, to_flat), dot(n, rd));
        let (u, v) = (p.u, p.v);
        let b1 = _mm512_sub_pd(_mm512_mul_pd(t, dot(rd, u)), dot(to_flat, u));
        let b2 = _mm512_sub_pd(_mm512_mul_pd(t, dot(rd, v)), dot(to_flat, v));
        let far = _mm512_add_pd(b2, _mm512_mul_pd(p.triangle, b1));
        let (zero, one) = (_mm512_setzero_pd(), _mm512_set1_pd(1.0));
        let in_t = _mm512_cmp_pd_mask::<_CMP_GT_OQ>(t, zero) & _mm512_cmp_pd_mask::<_CMP_LT_OQ>(t, t_max);
        let in_b1 = _mm512_cmp_pd_mask::<_CMP_GE_OQ>(b1, zero) & _mm512_cmp_pd_mask::<_CMP_LE_OQ>(b1, one);
        let in_b2 = _mm512_cmp_pd_mask::<_CMP_GE_OQ>(b2, zero) & _mm512_cmp_pd_mask::<_CMP_LE_OQ>(far, one);
        (t, b1, b2, in_t & in_b1 & in_b2)
    }

    /// [`FlatPacket::nearest_of`] without a branch per packet: each lane keeps the nearest hit
    /// it has seen (strictly nearer replaces, so earlier packets win ties), and the lanes are
    /// compared once at the end.
    #[target_feature(enable = "avx512f")]
    pub(super) fn nearest(packets: &[FlatPacket], ray: &Ray, t_max: f64) -> Option<(usize, LaneHit)> {
        let r = ray_lanes(ray);
        let limit = _mm512_set1_pd(t_max);
        let (mut best, mut best_b1, mut best_b2) = (NearestLanes::new(limit), _mm512_setzero_pd(), _mm512_setzero_pd());
        for (k, p) in packets.iter().enumerate() {
            let (t, b1, b2, inside) = lanes(p, &r, limit);
            let closer = best.update(k, t, inside);
            best_b1 = _mm512_mask_blend_pd(closer, best_b1, b1);
            best_b2 = _mm512_mask_blend_pd(closer, best_b2, b2);
        }
        let (lane, k, t) = best.nearest()?;
        Some((k, LaneHit { lane, t, b1: lane_of(best_b1, lane), b2: lane_of(best_b2, lane) }))
    }

    /// Eight rays, one per lane.
    #[inline]
    #[target_feature(enable = "avx512f")]
    fn rays_in_lanes(rays: &RayPacket) -> RayLanes {
        RayLanes { origin: load3(&rays.origin), dir: load3(&rays.dir) }
    }

    /// Flat `lane` of `p` in every lane (against eight rays).
    #[inline]
    #[target_feature(enable = "avx512f")]
    fn broadcast(p: &FlatPacket, lane: usize) -> FlatLanes {
        let row = |a: &[[f64; LANES]; 3]| [0, 1, 2].map(|axis| _mm512_set1_pd(a[axis][lane]));
        FlatLanes {
            origin: row(&p.origin),
            normal: row(&p.normal),
            u: row(&p.u),
            v: row(&p.v),
            triangle: _mm512_set1_pd(p.triangle[lane]),
        }
    }

    /// Eight rays' nearest hits, ray by lane: `hit` has bit `r` set when ray `r` hits flat
    /// `at[r]` (packet × [`LANES`] + lane) at `t[r]`, `b1[r]`, `b2[r]`.
    pub(super) struct RaysHits {
        pub hit: u8,
        pub at: [i64; LANES],
        pub t: [f64; LANES],
        pub b1: [f64; LANES],
        pub b2: [f64; LANES],
    }

    /// [`FlatPacket::nearest_of_rays`]: every flat in order against the eight rays; strictly
    /// nearer replaces, so ties keep the first packet, then the first lane, as
    /// [`nearest`] does.
    #[target_feature(enable = "avx512f")]
    pub(super) fn nearest_rays(packets: &[FlatPacket], rays: &RayPacket) -> RaysHits {
        let r = rays_in_lanes(rays);
        let limit = _mm512_set1_pd(f64::INFINITY);
        let (mut best_t, mut best_at) = (limit, _mm512_setzero_si512());
        let (mut best_b1, mut best_b2, mut hit) = (_mm512_setzero_pd(), _mm512_setzero_pd(), 0u8);
        for (k, p) in packets.iter().enumerate() {
            for lane in 0..p.used {
                let (t, b1, b2, inside) = flat_lanes(&broadcast(p, lane), &r, limit);
                let closer = inside & _mm512_cmp_pd_mask::<_CMP_LT_OQ>(t, best_t);
                best_t = _mm512_mask_blend_pd(closer, best_t, t);
                best_at = _mm512_mask_blend_epi64(closer, best_at, _mm512_set1_epi64((k * LANES + lane) as i64));
                best_b1 = _mm512_mask_blend_pd(closer, best_b1, b1);
                best_b2 = _mm512_mask_blend_pd(closer, best_b2, b2);
                hit |= closer;
            }
        }
        let mut out = RaysHits { hit, at: [0; LANES], t: [0.0; LANES], b1: [0.0; LANES], b2: [0.0; LANES] };
        // SAFETY: each destination is eight writable f64s or i64s; `storeu` needs no alignment.
        unsafe {
            _mm512_storeu_pd(out.t.as_mut_ptr(), best_t);
            _mm512_storeu_pd(out.b1.as_mut_ptr(), best_b1);
            _mm512_storeu_pd(out.b2.as_mut_ptr(), best_b2);
            _mm512_storeu_si512(out.at.as_mut_ptr().cast(), best_at);
        }
        out
    }

    /// [`FlatPacket::any_of_rays`]: the rays blocked by some flat, one bit per ray.
    #[target_feature(enable = "avx512f")]
    pub(super) fn any_rays(packets: &[FlatPacket], rays: &RayPacket, t_max: &[f64; LANES]) -> u8 {
        let (r, limit) = (rays_in_lanes(rays), load(t_max));
        let mut blocked = 0u8;
        for p in packets {
            for lane in 0..p.used {
                blocked |= flat_lanes(&broadcast(p, lane), &r, limit).3;
            }
        }
        blocked
    }

    /// [`FlatPacket::any_of`]: the lanes hit, gathered over every packet.
    #[target_feature(enable = "avx512f")]
    pub(super) fn any(packets: &[FlatPacket], ray: &Ray, t_max: f64) -> bool {
        let r = ray_lanes(ray);
        let limit = _mm512_set1_pd(t_max);
        packets.iter().fold(0, |hit, p| hit | lanes(p, &r, limit).3) != 0
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
