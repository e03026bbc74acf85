//! Up to eight spheres tested against one ray at once: the top-level BVH's leaves keep their
//! untransformed spheres in such packets, structure of arrays (mirror and glass balls are what
//! Glaeser's scenes are made of).
//!
//! Each lane does exactly [`Sphere::hit`]'s arithmetic in the same order (Haines et al.'s
//! discriminant, no fused multiply–add; `sqrt` and division are exact in IEEE arithmetic), so
//! the AVX-512 kernel and the portable loop give the same bits as the one-sphere test. For
//! eight rays at once ([`RayPacket`], the path tracer's lanes) the kernel turns round, as the
//! flat packets' does: the rays are the lanes and each sphere in turn is broadcast against them,
//! so a packet of four balls costs four tests of eight useful lanes, not eight half-empty ones.

use super::{RayPacket, Sphere, VectorUnit};
use alhazen_math::Ray;

/// Per ray of a [`RayPacket`], its nearest sphere hit: `(packet, lane, t)`.
pub type RaysSphereHits = [Option<(usize, usize, f64)>; SPHERE_LANES];

/// Spheres per packet.
pub const SPHERE_LANES: usize = 8;

/// Up to eight spheres, lane by lane; unused lanes never report a hit.
#[derive(Clone, Debug)]
#[repr(C, align(64))]
pub struct SpherePacket {
    center: [[f64; SPHERE_LANES]; 3],
    radius: [f64; SPHERE_LANES],
    /// Lanes in use (the first ones).
    used: usize,
}

impl SpherePacket {
    /// The packet of `spheres` (at most [`SPHERE_LANES`]); lane `i` is `spheres[i]`.
    pub fn new(spheres: &[Sphere]) -> Self {
        assert!(spheres.len() <= SPHERE_LANES, "a packet holds at most {SPHERE_LANES} spheres");
        // An unused lane has radius NaN: its discriminant is NaN, which is no hit.
        let mut p = Self { center: [[0.0; SPHERE_LANES]; 3], radius: [f64::NAN; SPHERE_LANES], used: spheres.len() };
        for (lane, s) in spheres.iter().enumerate() {
            for axis in 0..3 {
                p.center[axis][lane] = s.center[axis];
            }
            p.radius[lane] = s.radius;
        }
        p
    }

    fn lane(&self, lane: usize) -> Sphere {
        let c = &self.center;
        Sphere::new(alhazen_math::Vec3::new(c[0][lane], c[1][lane], c[2][lane]), self.radius[lane])
    }

    /// The nearest hit with `0 < t < t_max` among `packets`: the packet, its lane and `t` (on a
    /// tie, the first packet, then the first lane). Same bits from every `unit`.
    #[inline]
    #[allow(unsafe_code)]
    pub fn nearest_of(packets: &[Self], ray: &Ray, t_max: f64, unit: VectorUnit) -> Option<(usize, usize, f64)> {
        #[cfg(target_arch = "x86_64")]
        if unit.is_avx512() {
            // SAFETY: a `VectorUnit` says AVX-512F only where the processor has it.
            return unsafe { avx512::nearest(packets, ray, t_max) };
        }
        #[cfg(target_arch = "x86_64")]
        if unit.is_avx2() {
            // SAFETY: a `VectorUnit` says AVX2 only where the processor has it.
            return unsafe { nearest_avx2(packets, ray, t_max) };
        }
        let _ = unit;
        Self::nearest_portable(packets, ray, t_max)
    }

    fn nearest_portable(packets: &[Self], ray: &Ray, t_max: f64) -> Option<(usize, usize, f64)> {
        let (mut best, mut t_max) = (None, t_max);
        for (k, p) in packets.iter().enumerate() {
            for lane in 0..p.used {
                if let Some(c) = p.lane(lane).hit(ray, t_max) {
                    (t_max, best) = (c.t, Some((k, lane, c.t)));
                }
            }
        }
        best
    }

    /// [`Self::nearest_of`] for each of eight rays, `rays[r]` before `t_max[r]` (`None` where
    /// not `live`): the same hits, the same bits.
    #[inline]
    #[allow(unsafe_code)]
    pub fn nearest_of_rays(
        packets: &[Self],
        rays: &RayPacket,
        t_max: &[f64; SPHERE_LANES],
        live: [bool; SPHERE_LANES],
        unit: VectorUnit,
    ) -> RaysSphereHits {
        #[cfg(target_arch = "x86_64")]
        if unit.is_avx512() {
            // SAFETY: a `VectorUnit` says AVX-512F only where the processor has it.
            return unsafe { avx512::nearest_rays(packets, rays, t_max, live) };
        }
        #[cfg(target_arch = "x86_64")]
        if unit.is_avx2() {
            // SAFETY: a `VectorUnit` says AVX2 only where the processor has it.
            // (The kernels drop the rays not live themselves: filtered here, their 256 bytes of
            // hits were copied once more, 2.6 % of the glossy scene.)
            return unsafe { nearest_rays_avx2(packets, rays, t_max, live) };
        }
        let _ = unit;
        std::array::from_fn(|r| if live[r] { Self::nearest_portable(packets, &rays.ray(r), t_max[r]) } else { None })
    }

    /// Whether each of eight rays meets a sphere of `packets` at `0 < t < t_max[r]` (false
    /// where not `live`): `nearest_of_rays(…)[r].is_some()`, a shadow ray's question, answered
    /// without keeping the nearest — each sphere's test waits on no earlier one's limit, and
    /// the tests stop once every live ray is blocked.
    #[inline]
    #[allow(unsafe_code)]
    pub fn any_of_rays(
        packets: &[Self],
        rays: &RayPacket,
        t_max: &[f64; SPHERE_LANES],
        live: [bool; SPHERE_LANES],
        unit: VectorUnit,
    ) -> [bool; SPHERE_LANES] {
        #[cfg(target_arch = "x86_64")]
        if unit.is_avx512() {
            // SAFETY: a `VectorUnit` says AVX-512F only where the processor has it.
            return unsafe { avx512::any_rays(packets, rays, t_max, live) };
        }
        #[cfg(target_arch = "x86_64")]
        if unit.is_avx2() {
            // SAFETY: a `VectorUnit` says AVX2 only where the processor has it.
            return unsafe { any_rays_avx2(packets, rays, t_max, live) };
        }
        let _ = unit;
        std::array::from_fn(|r| live[r] && Self::nearest_portable(packets, &rays.ray(r), t_max[r]).is_some())
    }
}

/// `a·b` summed as glam's `dot` (and `Sphere::roots`): `(x·x + y·y) + z·z`.
#[inline(always)]
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The first half of [`sphere_t`]: `f = o − c`, `β = −f·d` and the discriminant, and whether
/// the roots are real (the line meets the sphere).
#[inline(always)]
fn sphere_disc(
    center: [f64; 3],
    radius: f64,
    origin: [f64; 3],
    dir: [f64; 3],
    a: f64,
    inv_a: f64,
) -> ([f64; 3], f64, f64, bool) {
    let f = [origin[0] - center[0], origin[1] - center[1], origin[2] - center[2]];
    let beta = -dot(f, dir);
    let s = beta * inv_a;
    let perp = [f[0] + dir[0] * s, f[1] + dir[1] * s, f[2] + dir[2] * s];
    let disc = a * (radius * radius - dot(perp, perp));
    (f, beta, disc, !(disc < 0.0 || disc.is_nan() || a == 0.0))
}

/// [`Sphere::hit`]'s distance of `ray` to `center`, `radius` (`a = d·d`, its reciprocal given):
/// NaN where it misses, in `Sphere::roots`' operations and order, its early return a select.
#[inline(always)]
fn sphere_t(center: [f64; 3], radius: f64, origin: [f64; 3], dir: [f64; 3], a: f64, inv_a: f64) -> f64 {
    let (f, beta, disc, real) = sphere_disc(center, radius, origin, dir, a, inv_a);
    let r2 = radius * radius;
    let c = dot(f, f) - r2;
    let q = beta + disc.sqrt().copysign(beta);
    let (t0, t1) = if q == 0.0 { (0.0, 0.0) } else { (c / q, q * inv_a) };
    let (lo, hi) = (t0.min(t1), t0.max(t1));
    let t = if lo > 0.0 { lo } else { hi };
    if real { t } else { f64::NAN }
}

/// [`SpherePacket::nearest_of`] with each packet's lanes tested in a loop without branches
/// (AVX2 code), then the nearest taken: the lane of least `t` below the limit, the first on a
/// tie, as testing them in turn against a shrinking limit finds.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn nearest_avx2(packets: &[SpherePacket], ray: &Ray, t_max: f64) -> Option<(usize, usize, f64)> {
    let (origin, dir) = (ray.origin.to_array(), ray.dir.to_array());
    let a = ray.dir.length_squared();
    let inv_a = 1.0 / a;
    let (mut best, mut limit) = (None, t_max);
    for (k, p) in packets.iter().enumerate() {
        let meets = (0..SPHERE_LANES).fold(false, |any, l| {
            let center = [p.center[0][l], p.center[1][l], p.center[2][l]];
            any | sphere_disc(center, p.radius[l], origin, dir, a, inv_a).3
        });
        if !meets {
            continue;
        }
        let t: [f64; SPHERE_LANES] = std::array::from_fn(|l| {
            let center = [p.center[0][l], p.center[1][l], p.center[2][l]];
            sphere_t(center, p.radius[l], origin, dir, a, inv_a)
        });
        for (lane, &t) in t.iter().enumerate().take(p.used) {
            if t > 0.0 && t < limit {
                (limit, best) = (t, Some((k, lane, t)));
            }
        }
    }
    best
}

/// [`SpherePacket::nearest_of_rays`] in loops over the eight rays without branches, which the
/// compiler turns into AVX2 code: each sphere in turn against all rays, [`Sphere::hit`]'s
/// operations in its order (its early return a mask), strictly nearer replacing.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn nearest_rays_avx2(
    packets: &[SpherePacket],
    rays: &RayPacket,
    t_max: &[f64; SPHERE_LANES],
    live: [bool; SPHERE_LANES],
) -> RaysSphereHits {
    const R: usize = SPHERE_LANES;
    let (o, d) = (&rays.origin, &rays.dir);
    let a: [f64; R] = std::array::from_fn(|r| dot([d[0][r], d[1][r], d[2][r]], [d[0][r], d[1][r], d[2][r]]));
    let inv_a = a.map(|a| 1.0 / a);
    let (mut best, mut which, mut hit) = (*t_max, [0u64; R], [false; R]);
    for (k, p) in packets.iter().enumerate() {
        for lane in 0..p.used {
            let (center, radius) = ([p.center[0][lane], p.center[1][lane], p.center[2][lane]], p.radius[lane]);
            let id = (k * SPHERE_LANES + lane) as u64;
            // Most spheres are missed by all eight rays: their square roots and divisions
            // (slow on every processor, slowest where AVX2 runs in halves) are skipped.
            let meets = (0..R).fold(false, |any, r| {
                let (origin, dir) = ([o[0][r], o[1][r], o[2][r]], [d[0][r], d[1][r], d[2][r]]);
                any | sphere_disc(center, radius, origin, dir, a[r], inv_a[r]).3
            });
            if !meets {
                continue;
            }
            for r in 0..R {
                let (origin, dir) = ([o[0][r], o[1][r], o[2][r]], [d[0][r], d[1][r], d[2][r]]);
                let t = sphere_t(center, radius, origin, dir, a[r], inv_a[r]);
                let closer = t > 0.0 && t < best[r];
                best[r] = if closer { t } else { best[r] };
                which[r] = if closer { id } else { which[r] };
                hit[r] |= closer;
            }
        }
    }
    std::array::from_fn(|r| {
        let id = which[r] as usize;
        (hit[r] && live[r]).then(|| (id / SPHERE_LANES, id % SPHERE_LANES, best[r]))
    })
}

/// [`SpherePacket::any_of_rays`] in loops over the eight rays without branches (AVX2 code), as
/// [`nearest_rays_avx2`] tests them against a limit that does not shrink. (Its setup and
/// skipping test are written out again: through a shared helper indexing the rays, both loops
/// stopped being vector code and the glossy scene took 1.37× as long.)
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn any_rays_avx2(
    packets: &[SpherePacket],
    rays: &RayPacket,
    t_max: &[f64; SPHERE_LANES],
    live: [bool; SPHERE_LANES],
) -> [bool; SPHERE_LANES] {
    const R: usize = SPHERE_LANES;
    let (o, d) = (&rays.origin, &rays.dir);
    let a: [f64; R] = std::array::from_fn(|r| dot([d[0][r], d[1][r], d[2][r]], [d[0][r], d[1][r], d[2][r]]));
    let inv_a = a.map(|a| 1.0 / a);
    let mut blocked = live.map(|l| !l);
    for p in packets {
        for lane in 0..p.used {
            let (center, radius) = ([p.center[0][lane], p.center[1][lane], p.center[2][lane]], p.radius[lane]);
            let meets = (0..R).fold(false, |any, r| {
                let (origin, dir) = ([o[0][r], o[1][r], o[2][r]], [d[0][r], d[1][r], d[2][r]]);
                any | sphere_disc(center, radius, origin, dir, a[r], inv_a[r]).3
            });
            if !meets {
                continue;
            }
            for r in 0..R {
                let (origin, dir) = ([o[0][r], o[1][r], o[2][r]], [d[0][r], d[1][r], d[2][r]]);
                let t = sphere_t(center, radius, origin, dir, a[r], inv_a[r]);
                blocked[r] |= t > 0.0 && t < t_max[r];
            }
            if !blocked.contains(&false) {
                return live;
            }
        }
    }
    std::array::from_fn(|r| blocked[r] && live[r])
}

#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
mod avx512 {
    use super::super::avx512::{NearestLanes, RayLanes, dot, load, load3, ray_lanes};
    use super::{RayPacket, RaysSphereHits, SPHERE_LANES, SpherePacket};
    use alhazen_math::Ray;
    use std::arch::x86_64::*;

    /// [`super::Sphere::hit`]'s operations on all lanes, in its order, without its branches:
    /// the nearer root in front of the origin and the lanes hit before `t_max`.
    #[inline]
    #[target_feature(enable = "avx512f")]
    fn lanes(center: [__m512d; 3], r: __m512d, ray: &SphereRays, t_max: __m512d) -> (__m512d, __mmask8) {
        let (o, d, a, inv_a) = (ray.rays.origin, ray.rays.dir, ray.a, ray.inv_a);
        let f = [0, 1, 2].map(|i| _mm512_sub_pd(o[i], center[i]));
        let sign = _mm512_set1_pd(-0.0);
        // `−(f·d)` by flipping the sign bit (`0 − x` would turn −0 into +0).
        let beta = bits(dot(f, d), sign, _mm512_xor_si512);
        let s = _mm512_mul_pd(beta, inv_a);
        let perp = [0, 1, 2].map(|i| _mm512_add_pd(f[i], _mm512_mul_pd(d[i], s)));
        let r2 = _mm512_mul_pd(r, r);
        let disc = _mm512_mul_pd(a, _mm512_sub_pd(r2, dot(perp, perp)));
        let zero = _mm512_setzero_pd();
        // `!(disc < 0 || disc is NaN || a == 0)`.
        let real = _mm512_cmp_pd_mask::<_CMP_NLT_UQ>(disc, zero)
            & _mm512_cmp_pd_mask::<_CMP_ORD_Q>(disc, disc)
            & _mm512_cmp_pd_mask::<_CMP_NEQ_UQ>(a, zero);
        // Most rays pass every sphere of a packet: skip the square root and the division.
        if real == 0 {
            return (zero, 0);
        }
        let c = _mm512_sub_pd(dot(f, f), r2);
        // `sqrt(disc).copysign(beta)`.
        let magnitude = bits(sign, _mm512_sqrt_pd(disc), _mm512_andnot_si512);
        let root = bits(magnitude, bits(sign, beta, _mm512_and_si512), _mm512_or_si512);
        let q = _mm512_add_pd(beta, root);
        let q_zero = _mm512_cmp_pd_mask::<_CMP_EQ_OQ>(q, zero);
        let t0 = _mm512_mask_blend_pd(q_zero, _mm512_div_pd(c, q), zero);
        let t1 = _mm512_mask_blend_pd(q_zero, _mm512_mul_pd(q, inv_a), zero);
        let (lo, hi) = (min(t0, t1), max(t0, t1));
        let t = _mm512_mask_blend_pd(_mm512_cmp_pd_mask::<_CMP_GT_OQ>(lo, zero), hi, lo);
        let inside = _mm512_cmp_pd_mask::<_CMP_GT_OQ>(t, zero) & _mm512_cmp_pd_mask::<_CMP_LT_OQ>(t, t_max);
        (t, real & inside)
    }

    /// Rays in lanes with `a = d·d` and `1/a`, which every sphere's test takes.
    struct SphereRays {
        rays: RayLanes,
        a: __m512d,
        inv_a: __m512d,
    }

    impl SphereRays {
        #[inline]
        #[target_feature(enable = "avx512f")]
        fn new(rays: RayLanes) -> Self {
            let a = dot(rays.dir, rays.dir);
            Self { rays, a, inv_a: _mm512_div_pd(_mm512_set1_pd(1.0), a) }
        }
    }

    /// A bitwise operation of AVX-512F on the lanes' bits.
    #[inline]
    #[target_feature(enable = "avx512f")]
    fn bits(a: __m512d, b: __m512d, op: unsafe fn(__m512i, __m512i) -> __m512i) -> __m512d {
        // SAFETY: `op` is one of AVX-512F's bitwise intrinsics, which this function enables.
        _mm512_castsi512_pd(unsafe { op(_mm512_castpd_si512(a), _mm512_castpd_si512(b)) })
    }

    /// `f64::min` lane by lane (the other operand where one is NaN).
    #[inline]
    #[target_feature(enable = "avx512f")]
    fn min(a: __m512d, b: __m512d) -> __m512d {
        _mm512_mask_blend_pd(_mm512_cmp_pd_mask::<_CMP_LT_OQ>(b, a) | _mm512_cmp_pd_mask::<_CMP_UNORD_Q>(a, a), a, b)
    }

    /// `f64::max` lane by lane (the other operand where one is NaN).
    #[inline]
    #[target_feature(enable = "avx512f")]
    fn max(a: __m512d, b: __m512d) -> __m512d {
        _mm512_mask_blend_pd(_mm512_cmp_pd_mask::<_CMP_GT_OQ>(b, a) | _mm512_cmp_pd_mask::<_CMP_UNORD_Q>(a, a), a, b)
    }

    /// [`SpherePacket::nearest_of`]: each lane keeps the nearest hit it has seen (strictly
    /// nearer replaces), compared once at the end.
    #[target_feature(enable = "avx512f")]
    pub(super) fn nearest(packets: &[SpherePacket], ray: &Ray, t_max: f64) -> Option<(usize, usize, f64)> {
        let r = SphereRays::new(ray_lanes(ray));
        let limit = _mm512_set1_pd(t_max);
        let mut best = NearestLanes::new(limit);
        for (k, p) in packets.iter().enumerate() {
            let center = [0, 1, 2].map(|i| load(&p.center[i]));
            let (t, inside) = lanes(center, load(&p.radius), &r, limit);
            best.update(k, t, inside);
        }
        let (lane, k, t) = best.nearest()?;
        Some((k, lane, t))
    }

    /// [`SpherePacket::nearest_of_rays`]: the rays in lanes, each sphere in order broadcast
    /// against them; strictly nearer replaces, so the first of equally near spheres is kept.
    #[target_feature(enable = "avx512f")]
    pub(super) fn nearest_rays(
        packets: &[SpherePacket],
        rays: &RayPacket,
        t_max: &[f64; SPHERE_LANES],
        live: [bool; SPHERE_LANES],
    ) -> RaysSphereHits {
        let ray = SphereRays::new(RayLanes { origin: load3(&rays.origin), dir: load3(&rays.dir) });
        let mut best = load(t_max);
        // Per ray, the sphere of its nearest hit as `packet × SPHERE_LANES + lane`, taken
        // without a branch: which rays a sphere is nearer for is data, not a pattern.
        let (mut which, mut hit) = (_mm512_setzero_si512(), 0u8);
        for (k, p) in packets.iter().enumerate() {
            for lane in 0..p.used {
                let center = [0, 1, 2].map(|i| _mm512_set1_pd(p.center[i][lane]));
                let (t, closer) = lanes(center, _mm512_set1_pd(p.radius[lane]), &ray, best);
                best = _mm512_mask_blend_pd(closer, best, t);
                which = _mm512_mask_blend_epi64(closer, which, _mm512_set1_epi64((k * SPHERE_LANES + lane) as i64));
                hit |= closer;
            }
        }
        let (mut t, mut id) = ([0.0; SPHERE_LANES], [0i64; SPHERE_LANES]);
        // SAFETY: `t` and `id` are eight writable f64s and i64s; `storeu` needs no alignment.
        unsafe {
            _mm512_storeu_pd(t.as_mut_ptr(), best);
            _mm512_storeu_si512(id.as_mut_ptr().cast(), which);
        }
        std::array::from_fn(|r| {
            let id = id[r] as usize;
            (hit >> r & 1 == 1 && live[r]).then(|| (id / SPHERE_LANES, id % SPHERE_LANES, t[r]))
        })
    }

    /// [`SpherePacket::any_of_rays`]: each sphere in order broadcast against the rays, the
    /// limit fixed, until every live ray is blocked.
    #[target_feature(enable = "avx512f")]
    pub(super) fn any_rays(
        packets: &[SpherePacket],
        rays: &RayPacket,
        t_max: &[f64; SPHERE_LANES],
        live: [bool; SPHERE_LANES],
    ) -> [bool; SPHERE_LANES] {
        let ray = SphereRays::new(RayLanes { origin: load3(&rays.origin), dir: load3(&rays.dir) });
        let limit = load(t_max);
        let live_mask = (0..SPHERE_LANES).fold(0u8, |m, r| m | u8::from(live[r]) << r);
        let mut blocked = 0u8;
        'spheres: for p in packets {
            for lane in 0..p.used {
                let center = [0, 1, 2].map(|i| _mm512_set1_pd(p.center[i][lane]));
                blocked |= lanes(center, _mm512_set1_pd(p.radius[lane]), &ray, limit).1;
                if blocked & live_mask == live_mask {
                    break 'spheres;
                }
            }
        }
        std::array::from_fn(|r| (blocked & live_mask) >> r & 1 == 1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use alhazen_math::Vec3;
    use proptest::prelude::*;

    fn vec3(r: f64) -> impl Strategy<Value = Vec3> {
        (-r..r, -r..r, -r..r).prop_map(|(x, y, z)| Vec3::new(x, y, z))
    }

    fn sphere() -> impl Strategy<Value = Sphere> {
        (vec3(3.0), 0.05..1.5f64).prop_map(|(center, radius)| Sphere::new(center, radius))
    }

    proptest! {
        /// Every kernel agrees bit for bit with testing the spheres one by one, in order.
        #[test]
        fn packets_equal_sphere_by_sphere(
            spheres in prop::collection::vec(sphere(), 1..=2 * SPHERE_LANES + 3),
            fill in 1..=SPHERE_LANES,
            origin in vec3(4.0),
            dir in vec3(1.0),
            t_max in prop_oneof![Just(f64::INFINITY), 0.1..8.0f64],
        ) {
            prop_assume!(dir.length() > 1e-3);
            let ray = Ray::new(origin, dir.normalize());
            let mut expected = None;
            let mut limit = t_max;
            for (i, s) in spheres.iter().enumerate() {
                if let Some(c) = s.hit(&ray, limit) {
                    limit = c.t;
                    expected = Some((i / fill, i % fill, c.t));
                }
            }
            let packets: Vec<SpherePacket> = spheres.chunks(fill).map(SpherePacket::new).collect();
            for unit in VectorUnit::available() {
                prop_assert_eq!(SpherePacket::nearest_of(&packets, &ray, t_max, unit), expected, "{:?}", unit);
            }
        }
    }

    proptest! {
        /// Eight rays at once find, ray by ray, what each finds alone (ties included: the
        /// spheres repeat, so equally near hits occur).
        #[test]
        fn eight_rays_equal_one_by_one(
            spheres in prop::collection::vec(sphere(), 1..=2 * SPHERE_LANES + 3),
            fill in 1..=SPHERE_LANES,
            rays in prop::collection::vec((vec3(4.0), vec3(1.0), prop_oneof![Just(f64::INFINITY), 0.1..8.0f64]), SPHERE_LANES),
            live in prop::array::uniform8(prop::bool::ANY),
        ) {
            let mut spheres = spheres;
            spheres.push(spheres[0]);
            let packets: Vec<SpherePacket> = spheres.chunks(fill).map(SpherePacket::new).collect();
            let mut packet = RayPacket::default();
            let mut t_max = [0.0; SPHERE_LANES];
            for (r, (o, d, t)) in rays.iter().enumerate() {
                let d = if d.length() > 1e-3 { d.normalize() } else { Vec3::X };
                packet.set(r, &Ray::new(*o, d));
                t_max[r] = *t;
            }
            for unit in VectorUnit::available() {
                let together = SpherePacket::nearest_of_rays(&packets, &packet, &t_max, live, unit);
                let blocked = SpherePacket::any_of_rays(&packets, &packet, &t_max, live, unit);
                for r in 0..SPHERE_LANES {
                    let alone = SpherePacket::nearest_of(&packets, &packet.ray(r), t_max[r], unit).filter(|_| live[r]);
                    prop_assert_eq!(together[r], alone, "ray {} {:?}", r, unit);
                    prop_assert_eq!(blocked[r], alone.is_some(), "any hit of ray {} {:?}", r, unit);
                }
            }
        }
    }

    proptest! {
        /// A planet-sized sphere as the ground (POV-Ray scenes' habit): a ray from a little
        /// above it finds it where it is, to the rounding of `|o − c|² − r²`, which cancels to
        /// about the height times the diameter: a relative error of a few `ε·r/h`. In `f32`
        /// that is 2²⁹ times more — 0.06 % of the height for a 10⁴ radius seen from 1 unit
        /// above, a third of it for an Earth-sized one; a packet test in `f32` was tried and
        /// rejected for this (BENCHMARKS, session 22).
        #[test]
        fn huge_spheres_are_met_where_they_are(
            radius in 1e3..1e7f64,
            height in 1e-3..10.0f64,
            across in -1.0..1.0f64,
            slant in -0.5..0.5f64,
        ) {
            let top = Vec3::new(across, radius + height, -across);
            let ground = [SpherePacket::new(&[Sphere::new(Vec3::ZERO, radius)])];
            // Straight down, and slanted (the exact distance then from the f64 quadratic's
            // nearer root in its stable form, which has no cancellation here).
            for dir in [Vec3::NEG_Y, Vec3::new(slant, -1.0, 0.0).normalize()] {
                let ray = Ray::new(top, dir);
                let b = -top.dot(dir);
                let c = height * (2.0 * radius + height) + across * across * 2.0;
                let disc = b * b - c;
                let exact = c / (b + disc.sqrt());
                for unit in VectorUnit::available() {
                    let hit = SpherePacket::nearest_of(&ground, &ray, f64::INFINITY, unit);
                    let t = hit.map(|h| h.2);
                    let tolerance = 8.0 * f64::EPSILON * (radius / height + 1.0) * exact;
                    prop_assert!(t.is_some_and(|t| (t - exact).abs() <= tolerance), "{t:?} vs {exact} {unit:?}");
                }
            }
        }
    }

    /// Rays from inside, tangent rays and a sphere seen from far away take the same roots.
    #[test]
    fn inside_tangent_and_far_rays_agree() {
        let spheres = [
            Sphere::new(Vec3::ZERO, 1.0),
            Sphere::new(Vec3::new(0.0, 1.0, 5.0), 1.0),
            Sphere::new(Vec3::new(0.0, 0.0, -1e6), 2.0),
        ];
        let packet = [SpherePacket::new(&spheres)];
        let rays = [
            Ray::new(Vec3::new(0.1, 0.2, 0.0), Vec3::Z),
            Ray::new(Vec3::new(0.0, 0.0, 2.0), Vec3::Z),
            Ray::new(Vec3::new(0.5, 0.0, 1e3), -Vec3::Z),
        ];
        for ray in rays {
            let expected = spheres
                .iter()
                .enumerate()
                .fold((None, f64::INFINITY), |(best, lim), (i, s)| match s.hit(&ray, lim) {
                    Some(c) => (Some((0, i, c.t)), c.t),
                    None => (best, lim),
                })
                .0;
            assert!(expected.is_some());
            for unit in VectorUnit::available() {
                assert_eq!(SpherePacket::nearest_of(&packet, &ray, f64::INFINITY, unit), expected, "{unit:?}");
            }
        }
    }
}
