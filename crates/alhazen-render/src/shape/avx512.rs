//! AVX-512 building blocks of the sphere packets' kernels ([`super::SpherePacket`]): eight f64
//! lanes, glam's summation order, and the choice of the nearest lane with the packets' tie rule
//! (first packet, then first lane).

use alhazen_math::Ray;
use std::arch::x86_64::*;

/// Lanes in a register.
pub const LANES: usize = 8;

/// Eight f64s into a register, lane `i` from `a[i]`.
#[inline]
#[target_feature(enable = "avx512f")]
pub fn load(a: &[f64; LANES]) -> __m512d {
    // SAFETY: `a` is eight readable f64s; `loadu` needs no alignment.
    unsafe { _mm512_loadu_pd(a.as_ptr()) }
}

/// The three coordinates' rows.
#[inline]
#[target_feature(enable = "avx512f")]
pub fn load3(a: &[[f64; LANES]; 3]) -> [__m512d; 3] {
    [load(&a[0]), load(&a[1]), load(&a[2])]
}

/// `(a·b)` lane by lane, summed as glam's `dot`: `(x·x + y·y) + z·z`.
#[inline]
#[target_feature(enable = "avx512f")]
pub fn dot(a: [__m512d; 3], b: [__m512d; 3]) -> __m512d {
    _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(a[0], b[0]), _mm512_mul_pd(a[1], b[1])), _mm512_mul_pd(a[2], b[2]))
}

/// The ray's origin and direction, each coordinate in all lanes.
pub struct RayLanes {
    /// Origin.
    pub origin: [__m512d; 3],
    /// Direction.
    pub dir: [__m512d; 3],
}

/// `ray` broadcast to every lane.
#[inline]
#[target_feature(enable = "avx512f")]
pub fn ray_lanes(ray: &Ray) -> RayLanes {
    let (o, d) = (ray.origin, ray.dir);
    RayLanes {
        origin: [_mm512_set1_pd(o.x), _mm512_set1_pd(o.y), _mm512_set1_pd(o.z)],
        dir: [_mm512_set1_pd(d.x), _mm512_set1_pd(d.y), _mm512_set1_pd(d.z)],
    }
}

/// Each lane's nearest hit so far over a leaf's packets: strictly nearer replaces, so an
/// earlier packet keeps a tie.
pub struct NearestLanes {
    t: __m512d,
    /// The packet of each lane's hit.
    k: __m512i,
    hit: __mmask8,
}

impl NearestLanes {
    /// No hit yet; hits must come before `t_max` (in every lane).
    #[inline]
    #[target_feature(enable = "avx512f")]
    pub fn new(t_max: __m512d) -> Self {
        Self { t: t_max, k: _mm512_setzero_si512(), hit: 0 }
    }

    /// Takes packet `k`'s lanes `inside` at `t` where they are nearer; returns the lanes taken.
    #[inline]
    #[target_feature(enable = "avx512f")]
    pub fn update(&mut self, k: usize, t: __m512d, inside: __mmask8) -> __mmask8 {
        let closer = inside & _mm512_cmp_pd_mask::<_CMP_LT_OQ>(t, self.t);
        self.t = _mm512_mask_blend_pd(closer, self.t, t);
        self.k = _mm512_mask_blend_epi64(closer, self.k, _mm512_set1_epi64(k as i64));
        self.hit |= closer;
        closer
    }

    /// The lane with the smallest `t`; on a tie, the one whose packet came first, then the
    /// first lane: `(lane, its packet, its t)`.
    #[inline]
    #[target_feature(enable = "avx512f")]
    pub fn nearest(&self) -> Option<(usize, usize, f64)> {
        if self.hit == 0 {
            return None;
        }
        let min = _mm512_reduce_min_pd(_mm512_mask_blend_pd(self.hit, _mm512_set1_pd(f64::INFINITY), self.t));
        let ties = self.hit & _mm512_cmp_pd_mask::<_CMP_EQ_OQ>(self.t, _mm512_set1_pd(min));
        let lane = if ties.is_power_of_two() { ties.trailing_zeros() as usize } else { first_packet(ties, self.k) };
        let k = _mm512_permutexvar_epi64(_mm512_set1_epi64(lane as i64), self.k);
        Some((lane, _mm_cvtsi128_si64(_mm512_castsi512_si128(k)) as usize, min))
    }
}

/// Of the lanes in `ties`, the one whose packet (`k`) came first, then the first lane.
#[cold]
#[target_feature(enable = "avx512f")]
fn first_packet(ties: __mmask8, k: __m512i) -> usize {
    let mut ks = [0i64; LANES];
    // SAFETY: `ks` is eight writable i64s; `storeu` needs no alignment.
    unsafe { _mm512_storeu_si512(ks.as_mut_ptr().cast(), k) };
    (0..LANES).filter(|&l| ties & (1 << l) != 0).min_by_key(|&l| ks[l]).unwrap_or(0)
}
