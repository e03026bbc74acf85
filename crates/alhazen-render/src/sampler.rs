//! Deterministic randomness: every sample's generator is seeded by hashing
//! `(seed, pixel x, pixel y, sample index)`, so an image does not depend on thread count or
//! tile order. Never seeded from entropy.

/// A small, fast generator (SplitMix64 sequence), adequate for jitter and stratification.
#[derive(Clone, Debug)]
pub struct Rng(u64);

#[inline]
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

impl Rng {
    /// The generator for one sample.
    #[inline]
    pub fn for_sample(seed: u64, x: u32, y: u32, sample: u32) -> Self {
        let h = mix(seed ^ 0x9e37_79b9_7f4a_7c15);
        let h = mix(h ^ ((x as u64) << 32 | y as u64));
        Self(mix(h ^ sample as u64))
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
