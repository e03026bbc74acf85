//! Pixel reconstruction filters by importance sampling (Ernst, Stamminger and Greiner 2006,
//! "Filter importance sampling"; pbrt-v4's `FilterSampler`): a sample of a pixel is placed at
//! an offset from the pixel's centre drawn in proportion to the filter's magnitude, and weighs
//! `±∫|f| / ∫f` by the sign of the filter there — 1 for filters without negative lobes — so
//! the mean of a pixel's weighted samples is the filtered image, every sample stays in its own
//! pixel (the film's exact sums and its parts are unchanged), and the filter costs a table
//! lookup a sample.
//!
//! Each axis's profile is tabulated as a staircase of `STEPS` steps, each holding the same
//! share of `∫|f|` (narrow where the filter is high, wide in its tails), each as high as the
//! profile's mean magnitude over it: the offset is drawn from the staircase exactly — step
//! `⌊u · STEPS⌋`, uniformly within it, no search — so the filter applied is the staircase, which
//! differs from the profile by less than one step's share anywhere (Mitsuba 3 splats through a
//! table of 31 steps). The samples' two numbers map monotonically onto the two offsets, so
//! strata and low-discrepancy points keep their structure.

use crate::sampler::stratified_offset;
use alhazen_math::Vec2;
use alhazen_scene::PixelFilter;

/// Steps of a tabulated profile, each an equal share of `∫|f|`.
const STEPS: usize = 2048;
/// Cells of the fine grid over `[−r, r]` on which a profile is summed to place the steps.
const FINE_CELLS: usize = 1 << 17;

/// Where a pixel's samples fall and what each weighs.
#[derive(Clone, Debug)]
pub struct FilmSampler {
    /// The profiles along `x` and `y`; `None` for the box of one pixel, whose samples keep the
    /// film positions they always had (`x + u`, weight 1).
    axes: Option<[Staircase; 2]>,
}

impl FilmSampler {
    /// The sampler of `filter` (which [`PixelFilter::problem`] accepts).
    pub fn new(filter: &PixelFilter) -> Self {
        if *filter == PixelFilter::PIXEL {
            return Self { axes: None };
        }
        Self { axes: Some([0, 1].map(|axis| Staircase::new(filter, axis))) }
    }

    /// Film position and weight of sample `index` of `spp` of pixel `(x, y)` placed by the
    /// pixel's strata ([`stratified_offset`]); a lone sample is the pixel's centre, weight 1 (a
    /// point sample, not a draw from the filter).
    pub fn stratified(&self, seed: u64, (x, y): (u32, u32), index: u32, spp: u32) -> (f64, f64, f64) {
        let (dx, dy) = stratified_offset(seed, x, y, index, spp);
        if spp == 1 {
            return (x as f64 + dx, y as f64 + dy, 1.0);
        }
        self.place(x, y, Vec2::new(dx, dy))
    }

    /// Film position of the sample of pixel `(x, y)` that the numbers `u ∈ [0, 1)²` place, and
    /// its weight.
    #[inline]
    pub fn place(&self, x: u32, y: u32, u: Vec2) -> (f64, f64, f64) {
        match &self.axes {
            None => (x as f64 + u.x, y as f64 + u.y, 1.0),
            Some([sx, sy]) => {
                let ((dx, wx), (dy, wy)) = (sx.sample(u.x), sy.sample(u.y));
                (x as f64 + 0.5 + dx, y as f64 + 0.5 + dy, wx * wy)
            }
        }
    }
}

/// One axis's profile as [`STEPS`] steps of equal share of `∫|f|` over `[−r, r]`.
#[derive(Clone, Debug)]
struct Staircase {
    /// The steps' edges, from `−r` to `r`.
    edges: Vec<f64>,
    /// Per step: its weight, `±∫|f| / ∫f` by its sign.
    weight: Vec<f64>,
}

impl Staircase {
    fn new(filter: &PixelFilter, axis: usize) -> Self {
        let r = filter.radius()[axis];
        // `|f|` summed over a fine grid (the midpoint rule), then cut into steps of equal sums.
        let (fine, h) = (FINE_CELLS, 2.0 * r / FINE_CELLS as f64);
        let mut running = Vec::with_capacity(fine + 1);
        running.push(0.0);
        for j in 0..fine {
            let m = filter.profile(axis, -r + (j as f64 + 0.5) * h).abs() * h;
            running.push(running[j] + m);
        }
        let total = running[fine];
        let mut edges = Vec::with_capacity(STEPS + 1);
        edges.push(-r);
        let mut j = 0;
        for k in 1..STEPS {
            let target = total * k as f64 / STEPS as f64;
            while running[j + 1] <= target {
                j += 1;
            }
            // Within fine cell `j`, whose sum is positive (it passes the target).
            let within = (target - running[j]) / (running[j + 1] - running[j]);
            edges.push(-r + (j as f64 + within) * h);
        }
        edges.push(r);
        let sign = |k: usize| filter.profile(axis, 0.5 * (edges[k] + edges[k + 1])) < 0.0;
        let negative = (0..STEPS).filter(|&k| sign(k)).count();
        // The staircase's `∫|f| / ∫f`: every step holds the same share (the filters accepted
        // have `∫f ≥ ∫|f| / 100`, so over twenty steps more positive than negative).
        let ratio = STEPS as f64 / STEPS.saturating_sub(2 * negative).max(1) as f64;
        let weight = (0..STEPS).map(|k| if sign(k) { -ratio } else { ratio }).collect();
        Self { edges, weight }
    }

    /// The offset `u ∈ [0, 1)` picks and its weight: step `⌊u · STEPS⌋`, uniformly within it.
    #[inline]
    fn sample(&self, u: f64) -> (f64, f64) {
        let scaled = u * STEPS as f64;
        let k = (scaled as usize).min(STEPS - 1);
        let within = scaled - k as f64;
        let (a, b) = (self.edges[k], self.edges[k + 1]);
        (a + within * (b - a), self.weight[k])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const FILTERS: [PixelFilter; 7] = [
        PixelFilter::Box { radius: [1.5, 0.75] },
        PixelFilter::Tent { radius: [1.0, 2.0] },
        PixelFilter::Gaussian { sigma: 0.5, radius: [2.0, 1.5] },
        PixelFilter::BlackmanHarris { radius: [1.5, 1.0] },
        PixelFilter::Mitchell { b: 1.0 / 3.0, c: 1.0 / 3.0, radius: [2.0, 2.0] },
        PixelFilter::Mitchell { b: 0.0, c: 0.5, radius: [2.0, 3.0] },
        PixelFilter::Lanczos { tau: 3.0, radius: [3.0, 2.0] },
    ];

    /// The profile's integral over `[a, b]` (Simpson's rule, finely).
    fn integral(f: &PixelFilter, axis: usize, a: f64, b: f64) -> f64 {
        integral_of(|x| f.profile(axis, x), a, b)
    }

    fn integral_of(g: impl Fn(f64) -> f64, a: f64, b: f64) -> f64 {
        let n = 20_000;
        let h = (b - a) / n as f64;
        let v = |i: usize| g(a + i as f64 * h);
        (v(0) + v(n) + (1..n).map(|i| v(i) * if i % 2 == 1 { 4.0 } else { 2.0 }).sum::<f64>()) * h / 3.0
    }

    /// The share of the staircase's magnitude over `[a, b]`.
    fn staircase_share(stairs: &Staircase, a: f64, b: f64) -> f64 {
        let e = &stairs.edges;
        (0..STEPS).map(|k| (b.min(e[k + 1]) - a.max(e[k])).max(0.0) / (e[k + 1] - e[k]) / STEPS as f64).sum()
    }

    /// The offsets follow the staircase (χ² of 200,000 independent draws in 40 cells); the
    /// staircase is the profile's magnitude within two steps' share in every cell; weighted,
    /// the samples integrate as the normalised filter does.
    #[test]
    fn weighted_offsets_follow_the_filter() {
        for f in FILTERS {
            let s = FilmSampler::new(&f);
            for axis in 0..2 {
                let stairs = &s.axes.as_ref().unwrap()[axis];
                let r = f.radius()[axis];
                let total = integral(&f, axis, -r, r);
                let magnitude = integral_of(|x| f.profile(axis, x).abs(), -r, r);
                let (n, cells) = (200_000usize, 40usize);
                let width = 2.0 * r / cells as f64;
                let (mut counts, mut weighted) = (vec![0.0; cells], vec![0.0; cells]);
                let mut rng = crate::sampler::Rng::for_sample(7, axis as u32, 0, 0);
                for _ in 0..n {
                    let (d, w) = stairs.sample(rng.uniform());
                    assert!(d.abs() <= r, "{f:?}: offset {d} beyond {r}");
                    let c = (((d + r) / width) as usize).min(cells - 1);
                    counts[c] += 1.0;
                    weighted[c] += w;
                }
                let mut chi2 = 0.0;
                for c in 0..cells {
                    let a = -r + width * c as f64;
                    let share = staircase_share(stairs, a, a + width);
                    let true_share = integral_of(|x| f.profile(axis, x).abs(), a, a + width) / magnitude;
                    assert!(
                        (share - true_share).abs() <= 2.0 / STEPS as f64,
                        "{f:?} cell {c}: {share} vs {true_share}"
                    );
                    let expected = n as f64 * share;
                    if expected > 5.0 {
                        chi2 += (counts[c] - expected).powi(2) / expected;
                    }
                    // The weighted samples of a cell estimate its share of the signed integral.
                    let signed = integral(&f, axis, a, a + width) / total;
                    assert!((weighted[c] / n as f64 - signed).abs() < 3e-3, "{f:?} axis {axis} cell {c}");
                }
                // The 99.9 % point of χ² with 39 degrees of freedom.
                assert!(chi2 < 72.0, "{f:?} axis {axis}: χ² = {chi2}");
                // Stratified numbers: the weights' mean is the staircase's, 1.
                let mean_weight = (0..n).map(|k| stairs.sample((k as f64 + 0.5) / n as f64).1).sum::<f64>() / n as f64;
                assert!((mean_weight - 1.0).abs() < 1e-3, "{f:?}: mean weight {mean_weight}");
            }
        }
    }

    #[test]
    fn the_pixel_box_keeps_the_film_positions() {
        let s = FilmSampler::new(&PixelFilter::PIXEL);
        for u in [Vec2::new(0.0, 0.0), Vec2::new(0.3, 0.999), Vec2::new(0.123456789, 0.5)] {
            let (x, y, w) = s.place(7, 3, u);
            assert_eq!((x.to_bits(), y.to_bits(), w), ((7.0 + u.x).to_bits(), (3.0 + u.y).to_bits(), 1.0));
        }
    }

    #[test]
    fn filters_without_negative_lobes_weigh_every_sample_one() {
        for f in &FILTERS[..4] {
            let s = FilmSampler::new(f);
            for k in 0..1000 {
                let u = Vec2::new(k as f64 / 1000.0, (k * 7 % 1000) as f64 / 1000.0);
                assert_eq!(s.place(0, 0, u).2, 1.0);
            }
        }
    }

    #[test]
    fn the_centre_number_lands_near_the_centre() {
        for f in FILTERS {
            let (x, y, _) = FilmSampler::new(&f).place(4, 9, Vec2::splat(0.5));
            assert!((x - 4.5).abs() < 0.02 && (y - 9.5).abs() < 0.02, "{f:?}: {x}, {y}");
        }
    }
}
