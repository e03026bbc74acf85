//! Deterministic randomness: every sample's generator is seeded by hashing
//! `(seed, pixel x, pixel y, sample index)`, so an image does not depend on thread count or
//! tile order. Never seeded from entropy.
//!
//! Two samplers feed the path tracer through [`SampleStream`]: independent numbers, and a
//! padded Sobol sequence with Owen scrambling (Burley 2020, "Practical Hash-based Owen
//! Scrambling"): each pair of dimensions uses the first two Sobol dimensions (a (0,2)-sequence),
//! with the sample index shuffled and the digits scrambled by hashes of
//! `(seed, pixel, dimension)`, so strata stay intact at power-of-two sample counts. Only the
//! first [`SOBOL_PAIRS`] pairs are Sobol points; later ones are independent numbers (as
//! Mitsuba 0.5's low-discrepancy sampler does past its `dimension`): deep in a path the
//! stratification no longer shows in the image. A sample's Sobol pairs are hashed together,
//! one pair per lane of one vector loop, when its stream starts.

use crate::shape::VectorUnit;
use alhazen_math::Vec2;

/// Dimension pairs drawn from the Sobol sequence: the pixel position and the first vertices'
/// light, lobe and BSDF samples. All are computed in one vector loop of eight lanes when a
/// sample starts, so eight cost what five did; past five, only the environment-map scene of the
/// suite gained (mean relative error −6 % at 32 spp, six seeds; the others within ±0.5 %), and
/// sixteen gained nothing more (BENCHMARKS.md, session 27).
pub const SOBOL_PAIRS: u32 = 8;

/// A small, fast generator (SplitMix64 sequence), adequate for jitter and stratification.
#[derive(Clone, Debug)]
pub struct Rng(u64);

#[inline]
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The hash of `(seed, pixel)` that [`Rng::for_sample`] finishes with the sample index.
#[inline]
fn rng_pixel_hash(seed: u64, x: u32, y: u32) -> u64 {
    mix(mix(seed ^ 0x9e37_79b9_7f4a_7c15) ^ ((x as u64) << 32 | y as u64))
}

impl Rng {
    /// The generator for one sample.
    #[inline]
    pub fn for_sample(seed: u64, x: u32, y: u32, sample: u32) -> Self {
        Self(mix(rng_pixel_hash(seed, x, y) ^ sample as u64))
    }

    /// A generator seeded by a point's coordinates, where no pixel sample is at hand
    /// (Whitted's area lights): the same point always draws the same numbers.
    #[inline]
    pub fn for_point(p: alhazen_math::Vec3) -> Self {
        Self(mix(mix(mix(p.x.to_bits()) ^ p.y.to_bits()) ^ p.z.to_bits()))
    }

    /// Next 64 random bits.
    #[inline]
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        mix(self.0)
    }

    /// Uniform in `[0, 1)`.
    #[inline]
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

/// Which sequence a [`SampleStream`] draws from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sequence {
    /// Independent uniform numbers.
    Independent,
    /// Owen-scrambled Sobol points.
    Sobol,
}

/// What every sample of one pixel shares: the hash of `(seed, pixel)` and the scrambling seeds
/// of each Sobol dimension pair, computed once for all the pixel's [`SampleStream`]s.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelSeeds {
    sequence: Sequence,
    /// Per Sobol pair (lanes past [`SOBOL_PAIRS`] unused): the seeds that shuffle the index and
    /// scramble the pair's first and second coordinate, from `mix(pixel seed ⊕ d)`.
    scrambles: Scrambles,
    rng: u64,
    /// The vector unit that runs [`sobol_points`]'s loop (the render's kernel).
    unit: VectorUnit,
}

/// Lanes of the vector loop that computes a sample's Sobol pairs all at once.
const SOBOL_LANES: usize = 8;
const _: () = assert!(SOBOL_PAIRS as usize <= SOBOL_LANES);

/// The three 32-bit scrambling seeds of each Sobol dimension pair, one array per seed.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Scrambles {
    shuffle: [u32; SOBOL_LANES],
    first: [u32; SOBOL_LANES],
    second: [u32; SOBOL_LANES],
}

impl PixelSeeds {
    /// The seeds of pixel `(x, y)`; its streams hash their Sobol pairs on `unit` (the same
    /// numbers on every unit).
    pub fn new(sequence: Sequence, seed: u64, x: u32, y: u32, unit: VectorUnit) -> Self {
        let pixel_seed = mix(mix(seed ^ 0x5851_f42d_4c95_7f2d) ^ ((x as u64) << 32 | y as u64));
        let mut scrambles = Scrambles::default();
        for d in 0..SOBOL_PAIRS as usize {
            let h = mix(pixel_seed ^ d as u64);
            scrambles.shuffle[d] = h as u32;
            scrambles.first[d] = (h >> 32) as u32;
            scrambles.second[d] = (h.wrapping_mul(0x9e37_79b9_7f4a_7c15) >> 32) as u32;
        }
        Self { sequence, scrambles, rng: rng_pixel_hash(seed, x, y), unit }
    }

    /// The stream of sample `index` of this pixel.
    #[inline]
    pub fn stream(&self, index: u32) -> SampleStream {
        let mut s = SampleStream::default();
        self.restart(&mut s, index);
        s
    }

    /// Makes `s` the stream of sample `index` of this pixel, written in place (a stream is
    /// ~100 bytes: the lanes restart theirs where they keep them rather than copy new ones in).
    #[inline]
    pub fn restart(&self, s: &mut SampleStream, index: u32) {
        s.sequence = self.sequence;
        s.rng = Rng(mix(self.rng ^ index as u64));
        if self.sequence == Sequence::Sobol {
            sobol_points(&self.scrambles, index.reverse_bits(), self.unit, &mut s.sobol);
        }
        s.dimension = 0;
        s.ahead = s.pair();
    }
}

/// Where a sample's [`SampleStream`] starts, computed ahead of it by [`PixelSeeds::starts`]:
/// its Sobol pairs and its generator's state.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StreamStart {
    sobol: [[u32; SOBOL_LANES]; 2],
    rng: u64,
}

impl PixelSeeds {
    /// The starts of samples `indices` of this pixel, into `out` (as many): for
    /// [`SampleStream::restart_from`]. With AVX-512, two samples' eight pairs are hashed in
    /// each register's sixteen lanes (and with GFNI a byte's bits reversed in one instruction):
    /// the hashing was a quarter of a sample that only starts and leaves (session 62).
    pub fn starts(&self, indices: std::ops::Range<u32>, out: &mut [StreamStart]) {
        let n = out.len().min(indices.len());
        for (index, start) in indices.clone().zip(out.iter_mut()) {
            start.rng = mix(self.rng ^ index as u64);
        }
        if self.sequence != Sequence::Sobol {
            return;
        }
        let mut done = 0;
        #[cfg(target_arch = "x86_64")]
        if self.unit.is_avx512() {
            // Two samples per loop in the sixteen lanes of AVX-512 registers.
            let twice = TwiceScrambles::of(&self.scrambles);
            let gfni = std::arch::is_x86_feature_detected!("gfni");
            for pair in out[..n - n % 2].chunks_exact_mut(2) {
                let index = indices.start + done as u32;
                let [a, b] = pair else { unreachable!() };
                let reversed = [index.reverse_bits(), (index + 1).reverse_bits()];
                // SAFETY: an AVX-512 `VectorUnit` is one whose processor has AVX-512 F, VL
                // and BW; GFNI is asked of it.
                #[allow(unsafe_code)]
                unsafe {
                    if gfni {
                        sobol_points_twice_gfni(&twice, reversed, [&mut a.sobol, &mut b.sobol])
                    } else {
                        sobol_points_twice_avx512(&twice, reversed, [&mut a.sobol, &mut b.sobol])
                    }
                }
                done += 2;
            }
        }
        for (k, start) in out[..n].iter_mut().enumerate().skip(done) {
            let index = indices.start + k as u32;
            sobol_points(&self.scrambles, index.reverse_bits(), self.unit, &mut start.sobol);
        }
    }
}

/// The numbers of one sample of one pixel, dimension after dimension (by default, independent
/// numbers of a zero seed: a stream to [`PixelSeeds::restart`]).
#[derive(Clone, Debug)]
pub struct SampleStream {
    sequence: Sequence,
    /// The sample's Sobol pairs, computed together when the stream starts: first coordinates
    /// then second ones, as 32-bit fractions.
    sobol: [[u32; SOBOL_LANES]; 2],
    dimension: u32,
    rng: Rng,
    /// The pair of dimension `dimension`, computed one call ahead.
    ahead: Vec2,
}

/// Laine–Karras style hash of bit-reversed values: every output bit depends only on the same
/// and lower input bits, so applied to a reversed value it is a nested uniform (Owen) scramble.
#[inline]
fn scramble_reversed(mut x: u32, seed: u32) -> u32 {
    x ^= x.wrapping_mul(0x3d20adea);
    x = x.wrapping_add(seed);
    x = x.wrapping_mul((seed >> 16) | 1);
    x ^= x.wrapping_mul(0x05526c56);
    x ^= x.wrapping_mul(0x53a22864);
    x
}

/// Owen scrambling of `x` (the stream does the first reversal once per sample).
#[cfg(test)]
fn owen_scramble(x: u32, seed: u32) -> u32 {
    scramble_reversed(x.reverse_bits(), seed).reverse_bits()
}

/// Column `k` of the generator matrix of the second Sobol dimension (primitive polynomial
/// `x + 1`, all direction numbers 1): `v_k = v_{k−1} ⊕ (v_{k−1} ≫ 1)`, `v_0 = 2³¹`.
#[cfg(test)]
const fn sobol1_columns() -> [u32; 32] {
    let mut c = [0u32; 32];
    let mut v = 1u32 << 31;
    let mut k = 0;
    while k < 32 {
        c[k] = v;
        v ^= v >> 1;
        k += 1;
    }
    c
}

/// The second Sobol dimension of point `i`, bits reversed. Its generator columns reversed are
/// the binomials `(1 + t)^k` over GF(2) (bit `j` the coefficient of `t^j`), so the point is the
/// index read as a polynomial `I(t)` and evaluated at `1 + t`: splitting `I = A + t^h·B` gives
/// `I(1 + t) = (A + B)(1 + t) + t^h·B(1 + t)`, one shift and XOR per halving.
#[inline(always)]
fn sobol1_reversed(mut i: u32) -> u32 {
    i ^= i >> 16 & 0x0000_ffff;
    i ^= i >> 8 & 0x00ff_00ff;
    i ^= i >> 4 & 0x0f0f_0f0f;
    i ^= i >> 2 & 0x3333_3333;
    i ^ (i >> 1 & 0x5555_5555)
}

#[inline]
fn to_unit(x: u32) -> f64 {
    x as f64 * (1.0 / 4_294_967_296.0)
}

impl Default for SampleStream {
    fn default() -> Self {
        Self {
            sequence: Sequence::Independent,
            sobol: [[0; SOBOL_LANES]; 2],
            dimension: 0,
            rng: Rng(0),
            ahead: Vec2::ZERO,
        }
    }
}

impl SampleStream {
    /// Makes this the stream that `start` (of [`PixelSeeds::starts`], whose sequence is
    /// `sequence`) begins: [`PixelSeeds::restart`] with its hashing done ahead.
    #[inline]
    pub fn restart_from(&mut self, sequence: Sequence, start: &StreamStart) {
        self.sequence = sequence;
        self.rng = Rng(start.rng);
        self.sobol = start.sobol;
        self.dimension = 0;
        self.ahead = self.pair();
    }

    /// The stream of sample `index` of pixel `(x, y)` (for many samples of one pixel,
    /// [`PixelSeeds::stream`] hashes the pixel once).
    pub fn new(sequence: Sequence, seed: u64, x: u32, y: u32, index: u32, unit: VectorUnit) -> Self {
        PixelSeeds::new(sequence, seed, x, y, unit).stream(index)
    }

    /// The next pair of numbers in `[0, 1)²`.
    #[inline]
    pub fn next_2d(&mut self) -> Vec2 {
        let current = self.ahead;
        self.dimension += 1;
        // Computed now, used at the next call: the hashing runs while the caller works on
        // `current` instead of stalling it (a path is one long chain of dependent operations).
        self.ahead = self.pair();
        current
    }

    /// The next number in `[0, 1)`: the first of the pair [`Self::next_2d`] would give.
    #[inline]
    pub fn next_1d(&mut self) -> f64 {
        self.next_2d().x
    }

    /// The pair of the current dimension (for independent numbers: the generator's next two).
    /// Always inlined: out of line, a path's every number pays a call (the lanes' per-path
    /// stage lost it to its own growth once, 7 % of the Cornell box).
    #[inline(always)]
    fn pair(&mut self) -> Vec2 {
        match self.sequence {
            Sequence::Sobol if self.dimension < SOBOL_PAIRS => {
                let d = self.dimension as usize;
                Vec2::new(to_unit(self.sobol[0][d]), to_unit(self.sobol[1][d]))
            }
            _ => Vec2::new(self.rng.uniform(), self.rng.uniform()),
        }
    }
}

/// Every Owen-scrambled Sobol pair of the sample whose index reversed is `index_reversed`,
/// one dimension pair per lane of one vector loop (in AVX2 registers where `unit` has them; the
/// same integers on every unit), into `out`: first coordinates, then second ones. Written in
/// place: returned, the pairs went through a copy whose loads waited on the loop's stores.
#[inline]
fn sobol_points(scrambles: &Scrambles, index_reversed: u32, unit: VectorUnit, out: &mut [[u32; SOBOL_LANES]; 2]) {
    #[cfg(target_arch = "x86_64")]
    if unit.is_simd() {
        // SAFETY: a `VectorUnit` says AVX2 or AVX-512 (which includes AVX2) only where the
        // processor has it.
        #[allow(unsafe_code)]
        return unsafe { sobol_points_avx2(scrambles, index_reversed, out) };
    }
    let _ = unit;
    sobol_points_in(scrambles, index_reversed, out)
}

#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
#[target_feature(enable = "avx2")]
unsafe fn sobol_points_avx2(scrambles: &Scrambles, index_reversed: u32, out: &mut [[u32; SOBOL_LANES]; 2]) {
    sobol_points_in(scrambles, index_reversed, out)
}

#[inline(always)]
fn sobol_points_in(scrambles: &Scrambles, index_reversed: u32, out: &mut [[u32; SOBOL_LANES]; 2]) {
    for d in 0..SOBOL_LANES {
        // The index shuffled by Owen scrambling (`owen_scramble`, its first reversal done once).
        let shuffled = scramble_reversed(index_reversed, scrambles.shuffle[d]).reverse_bits();
        // Dimension 0 is the van der Corput sequence, whose reversed bits are the index.
        out[0][d] = scramble_reversed(shuffled, scrambles.first[d]).reverse_bits();
        out[1][d] = scramble_reversed(sobol1_reversed(shuffled), scrambles.second[d]).reverse_bits();
    }
}

/// [`Scrambles`] twice over, for two samples in sixteen lanes.
#[cfg(target_arch = "x86_64")]
struct TwiceScrambles {
    shuffle: [u32; 2 * SOBOL_LANES],
    first: [u32; 2 * SOBOL_LANES],
    second: [u32; 2 * SOBOL_LANES],
}

#[cfg(target_arch = "x86_64")]
impl TwiceScrambles {
    fn of(s: &Scrambles) -> Self {
        let twice = |a: &[u32; SOBOL_LANES]| std::array::from_fn(|l| a[l % SOBOL_LANES]);
        Self { shuffle: twice(&s.shuffle), first: twice(&s.first), second: twice(&s.second) }
    }
}

/// [`sobol_points_in`] for two samples (their indices reversed) at once: lane `l` computes
/// pair `l mod 8` of sample `l div 8`, the same integers.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn sobol_points_twice_in(s: &TwiceScrambles, reversed: [u32; 2], out: [&mut [[u32; SOBOL_LANES]; 2]; 2]) {
    let index: [u32; 2 * SOBOL_LANES] = std::array::from_fn(|l| reversed[l / SOBOL_LANES]);
    let (mut first, mut second) = ([0u32; 2 * SOBOL_LANES], [0u32; 2 * SOBOL_LANES]);
    for l in 0..2 * SOBOL_LANES {
        let shuffled = scramble_reversed(index[l], s.shuffle[l]).reverse_bits();
        first[l] = scramble_reversed(shuffled, s.first[l]).reverse_bits();
        second[l] = scramble_reversed(sobol1_reversed(shuffled), s.second[l]).reverse_bits();
    }
    for (k, points) in out.into_iter().enumerate() {
        points[0].copy_from_slice(&first[k * SOBOL_LANES..][..SOBOL_LANES]);
        points[1].copy_from_slice(&second[k * SOBOL_LANES..][..SOBOL_LANES]);
    }
}

#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
#[target_feature(enable = "avx512f,avx512vl,avx512bw")]
unsafe fn sobol_points_twice_avx512(s: &TwiceScrambles, reversed: [u32; 2], out: [&mut [[u32; SOBOL_LANES]; 2]; 2]) {
    sobol_points_twice_in(s, reversed, out)
}

/// [`sobol_points_twice_avx512`] where GFNI reverses each byte's bits in one instruction.
#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
#[target_feature(enable = "avx512f,avx512vl,avx512bw,gfni")]
unsafe fn sobol_points_twice_gfni(s: &TwiceScrambles, reversed: [u32; 2], out: [&mut [[u32; SOBOL_LANES]; 2]; 2]) {
    sobol_points_twice_in(s, reversed, out)
}

/// The position in `[0, 1)²` of sample `i` of `n` in a pixel: jittered on a `k × k` grid when
/// `n = k²`, otherwise N-rooks (one sample per row and per column stratum); the pixel centre
/// for `n = 1`.
pub fn stratified_offset(seed: u64, x: u32, y: u32, i: u32, n: u32) -> (f64, f64) {
    if n == 1 {
        return (0.5, 0.5);
    }
    let mut rng = Rng::for_sample(seed, x, y, i);
    let (jx, jy) = (rng.uniform(), rng.uniform());
    let k = (n as f64).sqrt().round() as u32;
    if k * k == n {
        return (((i % k) as f64 + jx) / k as f64, ((i / k) as f64 + jy) / k as f64);
    }
    // N-rooks: column i, row π(i) for a pixel-seeded permutation π.
    let row = permute(i, n, mix(seed ^ mix((x as u64) << 32 | y as u64)) as u32);
    ((i as f64 + jx) / n as f64, (row as f64 + jy) / n as f64)
}

/// Kensler's hash-based permutation of `0..n` ("Correlated multi-jittered sampling", 2013).
fn permute(mut i: u32, l: u32, p: u32) -> u32 {
    let mut w = l - 1;
    w |= w >> 1;
    w |= w >> 2;
    w |= w >> 4;
    w |= w >> 8;
    w |= w >> 16;
    loop {
        i ^= p;
        i = i.wrapping_mul(0xe170893d);
        i ^= p >> 16;
        i ^= (i & w) >> 4;
        i ^= p >> 8;
        i = i.wrapping_mul(0x0929eb3f);
        i ^= p >> 23;
        i ^= (i & w) >> 1;
        i = i.wrapping_mul(1 | p >> 27);
        i = i.wrapping_mul(0x6935fa69);
        i ^= (i & w) >> 11;
        i = i.wrapping_mul(0x74dcb303);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0x9e501cc3);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0xc860a3df);
        i &= w;
        i ^= i >> 5;
        if i < l {
            return (i.wrapping_add(p)) % l;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_inputs_same_numbers() {
        let a: Vec<f64> = (0..4).map(|_| Rng::for_sample(7, 3, 4, 5).uniform()).collect();
        assert!(a.iter().all(|x| *x == a[0]));
        assert_ne!(Rng::for_sample(7, 3, 4, 5).uniform(), Rng::for_sample(7, 3, 4, 6).uniform());
    }

    #[test]
    fn uniform_chi_square() {
        // 10 bins, 100k draws: χ² with 9 dof stays below 27.9 (p = 0.001).
        let mut rng = Rng::for_sample(1, 2, 3, 4);
        let mut bins = [0u32; 10];
        for _ in 0..100_000 {
            bins[(rng.uniform() * 10.0) as usize] += 1;
        }
        let chi2: f64 = bins.iter().map(|&b| (b as f64 - 10_000.0).powi(2) / 10_000.0).sum();
        assert!(chi2 < 27.9, "χ² = {chi2}");
    }

    /// One Sobol pair by the definition: the index Owen-scrambled, its van der Corput and
    /// second-Sobol-dimension points, each Owen-scrambled (each reversal written out).
    fn sobol_pair_by_definition(index: u32, shuffle: u32, first: u32, second: u32) -> (u32, u32) {
        let shuffled = owen_scramble(index, shuffle);
        let sobol1 = sobol1_reversed(shuffled).reverse_bits();
        (owen_scramble(shuffled.reverse_bits(), first), owen_scramble(sobol1, second))
    }

    proptest::proptest! {
        /// The vector loop gives every lane the pair the definition gives, on every kernel.
        #[test]
        fn sobol_points_are_the_definition_on_every_kernel(
            index in proptest::prelude::any::<u32>(),
            seeds in proptest::collection::vec(proptest::prelude::any::<u32>(), 3 * SOBOL_LANES),
        ) {
            let scrambles = Scrambles {
                shuffle: std::array::from_fn(|d| seeds[d]),
                first: std::array::from_fn(|d| seeds[SOBOL_LANES + d]),
                second: std::array::from_fn(|d| seeds[2 * SOBOL_LANES + d]),
            };
            let points = |unit| {
                let mut out = [[0; SOBOL_LANES]; 2];
                sobol_points(&scrambles, index.reverse_bits(), unit, &mut out);
                out
            };
            let portable = points(VectorUnit::PORTABLE);
            for unit in VectorUnit::available() {
                proptest::prop_assert_eq!(portable, points(unit), "{:?}", unit);
            }
            for d in 0..SOBOL_LANES {
                let pair = sobol_pair_by_definition(index, seeds[d], seeds[SOBOL_LANES + d], seeds[2 * SOBOL_LANES + d]);
                proptest::prop_assert_eq!((portable[0][d], portable[1][d]), pair, "lane {}", d);
            }
        }
    }

    proptest::proptest! {
        /// Streams started from starts computed ahead, many at once on any kernel, draw the
        /// numbers of streams started one by one.
        #[test]
        fn streams_started_ahead_are_the_streams(
            seed in proptest::prelude::any::<u64>(),
            (x, y) in (0u32..4096, 0u32..4096),
            first in proptest::prelude::any::<u32>(),
            n in 0usize..9,
        ) {
            for sequence in [Sequence::Sobol, Sequence::Independent] {
                let alone = PixelSeeds::new(sequence, seed, x, y, VectorUnit::PORTABLE);
                for unit in VectorUnit::available() {
                    let seeds = PixelSeeds::new(sequence, seed, x, y, unit);
                    let mut starts = [StreamStart::default(); 9];
                    let indices = first..first.saturating_add(n as u32);
                    seeds.starts(indices.clone(), &mut starts[..n]);
                    for (k, index) in indices.enumerate() {
                        let (mut ahead, mut one) = (SampleStream::default(), alone.stream(index));
                        ahead.restart_from(sequence, &starts[k]);
                        for _ in 0..SOBOL_PAIRS + 2 {
                            proptest::prop_assert_eq!(ahead.next_2d(), one.next_2d(), "{:?} {:?} {}", sequence, unit, index);
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn sobol_dimension_one_matches_the_bitwise_definition() {
        let cols = sobol1_columns();
        let mut rng = Rng(7);
        let random = (0..1000).map(|_| rng.next_u64() as u32);
        for i in [0u32, 1, 2, 3, 77, 1 << 20, 0xdead_beef, u32::MAX].into_iter().chain(random) {
            let y = (0..32).filter(|k| i >> k & 1 == 1).fold(0, |acc, k| acc ^ cols[k]);
            assert_eq!(sobol1_reversed(i).reverse_bits(), y, "{i}");
        }
    }

    #[test]
    fn owen_scrambling_permutes_elementary_intervals() {
        // Values sharing their top k bits keep sharing them after scrambling.
        for seed in [1u32, 0xabcdef, 0x1234_5678] {
            for k in [1, 4, 9] {
                let (a, b) = (0xf000_0000u32 | 0x35, 0xf000_0000u32 | 0x9a00);
                assert_eq!(owen_scramble(a, seed) >> (32 - k), owen_scramble(b, seed) >> (32 - k));
            }
        }
    }

    #[test]
    fn sobol_points_are_stratified_in_every_dimension_pair() {
        // 64 scrambled (0,2)-points: one per cell of every elementary 2^a × 2^b interval grid.
        for dim in 0..SOBOL_PAIRS {
            let pts: Vec<_> = (0..64)
                .map(|i| {
                    let mut s = SampleStream::new(Sequence::Sobol, 9, 5, 7, i, VectorUnit::PORTABLE);
                    for _ in 0..dim {
                        s.next_2d();
                    }
                    s.next_2d()
                })
                .collect();
            for a in 0..=6 {
                let (nx, ny) = (1u32 << a, 1u32 << (6 - a));
                let mut cells: Vec<u32> =
                    pts.iter().map(|p| (p.y * ny as f64) as u32 * nx + (p.x * nx as f64) as u32).collect();
                cells.sort();
                assert_eq!(cells, (0..64).collect::<Vec<_>>(), "dimension pair {dim}, {nx}×{ny}");
            }
        }
    }

    #[test]
    fn next_1d_is_the_first_of_the_pair_and_advances_alike() {
        for sequence in [Sequence::Sobol, Sequence::Independent] {
            let (mut one, mut two) = (
                SampleStream::new(sequence, 2, 3, 4, 5, VectorUnit::PORTABLE),
                SampleStream::new(sequence, 2, 3, 4, 5, VectorUnit::PORTABLE),
            );
            for _ in 0..6 {
                assert_eq!(one.next_1d(), two.next_2d().x, "{sequence:?}");
            }
            assert_eq!(one.next_2d(), two.next_2d(), "{sequence:?}");
        }
    }

    #[test]
    fn sobol_differs_between_pixels_and_is_uniform() {
        let a = SampleStream::new(Sequence::Sobol, 1, 0, 0, 3, VectorUnit::PORTABLE).next_2d();
        let b = SampleStream::new(Sequence::Sobol, 1, 1, 0, 3, VectorUnit::PORTABLE).next_2d();
        assert_ne!(a, b);
        // The first pair, and one past the Sobol pairs (independent numbers there).
        for skip in [0, SOBOL_PAIRS + 2] {
            let mut bins = [0u32; 10];
            for px in 0..200 {
                for i in 0..50 {
                    let mut s = SampleStream::new(Sequence::Sobol, 4, px, 1, i, VectorUnit::PORTABLE);
                    for _ in 0..skip {
                        s.next_2d();
                    }
                    bins[(s.next_1d() * 10.0) as usize] += 1;
                }
            }
            let chi2: f64 = bins.iter().map(|&b| (b as f64 - 1000.0).powi(2) / 1000.0).sum();
            assert!(chi2 < 27.9, "pair {skip}: χ² = {chi2}");
        }
    }

    #[test]
    fn strata_are_each_hit_once() {
        for n in [4u32, 9, 6, 7] {
            let pts: Vec<_> = (0..n).map(|i| stratified_offset(3, 10, 20, i, n)).collect();
            let k = (n as f64).sqrt().round() as u32;
            if k * k == n {
                let mut cells: Vec<u32> =
                    pts.iter().map(|(x, y)| (y * k as f64) as u32 * k + (x * k as f64) as u32).collect();
                cells.sort();
                assert_eq!(cells, (0..n).collect::<Vec<_>>());
            } else {
                for coord in [0, 1] {
                    let mut rows: Vec<u32> =
                        pts.iter().map(|p| ((if coord == 0 { p.0 } else { p.1 }) * n as f64) as u32).collect();
                    rows.sort();
                    assert_eq!(rows, (0..n).collect::<Vec<_>>());
                }
            }
        }
    }
}
