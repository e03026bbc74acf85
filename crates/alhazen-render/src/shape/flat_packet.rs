//! Four planar primitives ([`Flat`]s) tested against one ray at once: the top-level BVH's
//! leaves keep their triangles and parallelograms in such packets, structure of arrays
//! (Wald et al. 2008, "Getting Rid of Packets", multi-primitive leaves; Embree's `Triangle4`).
//!
//! Each lane does exactly [`Flat::hit`]'s arithmetic in the same order (no fused multiply–add),
//! so the AVX2 kernel, used where the processor has it, and the portable loop give the same
//! bits as each other and as the one-primitive test: images do not depend on the machine.
//! The ray is tested against all four lanes without branches, which is what makes the packet
//! pay: a scalar test's early exits are unpredictable for rays in all directions.

use super::Flat;
use alhazen_math::{Ray, Vec3};

/// Primitives per packet.
pub const LANES: usize = 4;

/// Up to four flats, lane by lane; unused lanes never report a hit.
#[derive(Clone, Debug)]
#[repr(C, align(32))]
pub struct FlatPacket {
    origin: [[f64; LANES]; 3],
    normal: [[f64; LANES]; 3],
    u: [[f64; LANES]; 3],
    v: [[f64; LANES]; 3],
    /// 1 for a triangle (`b1 + b2 ≤ 1`), 0 for a parallelogram (`b2 ≤ 1`).
    triangle: [f64; LANES],
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

    /// The nearest hit with `0 < t < t_max` among the lanes (the first lane on a tie).
    /// `vectors` says whether the processor has AVX2 ([`has_vector_unit`]).
    #[inline]
    pub fn hit(&self, ray: &Ray, t_max: f64, vectors: bool) -> Option<LaneHit> {
        if vectors { self.hit_vector(ray, t_max) } else { self.hit_portable(ray, t_max) }
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
        for lane in 0..LANES {
            if let Some((t, b1, b2)) = self.lane(lane).hit(ray, t_max) {
                t_max = t;
                best = Some(LaneHit { lane, t, b1, b2 });
            }
        }
        best
    }

    #[cfg(target_arch = "x86_64")]
    #[allow(unsafe_code)]
    #[inline]
    fn hit_vector(&self, ray: &Ray, t_max: f64) -> Option<LaneHit> {
        // SAFETY: `vectors` is true only when `has_vector_unit` found AVX2 on this processor.
        unsafe { avx2::hit(self, ray, t_max) }
    }

    #[cfg(not(target_arch = "x86_64"))]
    #[inline]
    fn hit_vector(&self, ray: &Ray, t_max: f64) -> Option<LaneHit> {
        self.hit_portable(ray, t_max)
    }
}

/// True when [`FlatPacket::hit`] may use its AVX2 kernel on this processor.
pub fn has_vector_unit() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
mod avx2 {
    use super::{FlatPacket, LANES, LaneHit};
    use alhazen_math::Ray;
    use std::arch::x86_64::*;

    /// Lane `i` of every register is lane `i` of the packet.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn load(a: &[f64; LANES]) -> __m256d {
        // SAFETY: `a` is four readable f64s; `loadu` needs no alignment.
        unsafe { _mm256_loadu_pd(a.as_ptr()) }
    }

    /// `(a·b)` lane by lane, summed as glam's `dot`: `(x·x + y·y) + z·z`.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn dot(a: [__m256d; 3], b: [__m256d; 3]) -> __m256d {
        _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(a[0], b[0]), _mm256_mul_pd(a[1], b[1])), _mm256_mul_pd(a[2], b[2]))
    }

    #[inline]
    #[target_feature(enable = "avx2")]
    fn load3(a: &[[f64; LANES]; 3]) -> [__m256d; 3] {
        [load(&a[0]), load(&a[1]), load(&a[2])]
    }

    /// [`FlatPacket::hit_portable`] in AVX2 registers: [`super::Flat::hit`]'s operations lane by
    /// lane, in its order, combined without its early exits.
    #[target_feature(enable = "avx2")]
    pub(super) fn hit(p: &FlatPacket, ray: &Ray, t_max: f64) -> Option<LaneHit> {
        let ro = [_mm256_set1_pd(ray.origin.x), _mm256_set1_pd(ray.origin.y), _mm256_set1_pd(ray.origin.z)];
        let rd = [_mm256_set1_pd(ray.dir.x), _mm256_set1_pd(ray.dir.y), _mm256_set1_pd(ray.dir.z)];
        let o = load3(&p.origin);
        let to_flat = [_mm256_sub_pd(o[0], ro[0]), _mm256_sub_pd(o[1], ro[1]), _mm256_sub_pd(o[2], ro[2])];
        let n = load3(&p.normal);
        let t = _mm256_div_pd(dot(n, to_flat), dot(n, rd));
        // As `Flat::hit`: `t·(d·u) − (o − r)·u`, the dot products independent of the division.
        let (u, v) = (load3(&p.u), load3(&p.v));
        let b1 = _mm256_sub_pd(_mm256_mul_pd(t, dot(rd, u)), dot(to_flat, u));
        let b2 = _mm256_sub_pd(_mm256_mul_pd(t, dot(rd, v)), dot(to_flat, v));
        let far = _mm256_add_pd(b2, _mm256_mul_pd(load(&p.triangle), b1));
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
        let mut lanes = [[0.0; LANES]; 3];
        for (dst, src) in lanes.iter_mut().zip([t, b1, b2]) {
            // SAFETY: `dst` is four writable f64s; `storeu` needs no alignment.
            unsafe { _mm256_storeu_pd(dst.as_mut_ptr(), src) };
        }
        Some(LaneHit { lane, t: lanes[0][lane], b1: lanes[1][lane], b2: lanes[2][lane] })
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
        /// Both kernels agree bit for bit with testing the flats one by one.
        #[test]
        fn packet_equals_flat_by_flat(
            flats in prop::collection::vec(flat(), 1..=LANES),
            origin in vec3(),
            dir in vec3(),
            t_max in prop_oneof![Just(f64::INFINITY), 0.1..5.0f64],
        ) {
            let flats: Vec<Flat> = flats.into_iter().flatten().collect();
            prop_assume!(!flats.is_empty() && dir.length() > 1e-3);
            let ray = Ray::new(origin, dir.normalize());
            let mut expected = None;
            let mut limit = t_max;
            for (lane, f) in flats.iter().enumerate() {
                if let Some((t, b1, b2)) = f.hit(&ray, limit) {
                    limit = t;
                    expected = Some(LaneHit { lane, t, b1, b2 });
                }
            }
            let packet = FlatPacket::new(&flats);
            prop_assert_eq!(packet.hit(&ray, t_max, false), expected);
            if has_vector_unit() {
                prop_assert_eq!(packet.hit(&ray, t_max, true), expected);
            }
        }
    }

    #[test]
    fn unused_lanes_and_rays_in_the_plane_never_hit() {
        let f = Flat::new(Vec3::ZERO, Vec3::X, Vec3::Y, true).unwrap();
        let packet = FlatPacket::new(&[f]);
        for vectors in [false, has_vector_unit()] {
            let down = Ray::new(Vec3::new(0.5, 0.5, 1.0), -Vec3::Z);
            assert_eq!(packet.hit(&down, f64::INFINITY, vectors).map(|h| (h.lane, h.t)), Some((0, 1.0)));
            let grazing = Ray::new(Vec3::new(-1.0, 0.5, 0.0), Vec3::X);
            assert_eq!(packet.hit(&grazing, f64::INFINITY, vectors), None);
            assert_eq!(FlatPacket::new(&[]).hit(&down, f64::INFINITY, vectors), None);
        }
    }
}
