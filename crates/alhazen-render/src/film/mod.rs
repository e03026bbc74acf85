//! The film: linear radiance per pixel, rendered in parallel tiles. The tile order and the
//! thread count do not affect any pixel (each sample's randomness is seeded from its pixel and
//! index), so images are identical at any thread count.

use alhazen_math::Vec3;
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};

const TILE: u32 = 32;

/// A rendered image: linear RGB, rows top to bottom.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width × height` pixels.
    pub pixels: Vec<[f32; 3]>,
}

impl Image {
    /// The pixel at `(x, y)`.
    pub fn get(&self, x: u32, y: u32) -> Vec3 {
        let p = self.pixels[(y * self.width + x) as usize];
        Vec3::new(p[0] as f64, p[1] as f64, p[2] as f64)
    }
}

/// Something that estimates the colour of one sample of one pixel.
pub trait PixelEstimator: Sync {
    /// Linear RGB of sample `index` of pixel `(x, y)`: a pure function of its arguments.
    fn sample(&self, x: u32, y: u32, index: u32) -> Vec3;

    /// Every sample of pixel `(x, y)`: `out[i] = self.sample(x, y, i)`, in whatever order
    /// the estimator computes them fastest.
    fn samples(&self, x: u32, y: u32, out: &mut [Vec3]) {
        out.iter_mut().enumerate().for_each(|(i, c)| *c = self.sample(x, y, i as u32));
    }

    /// [`Self::samples`] of several pixels: `out` holds each pixel's in turn (`out.len()` is a
    /// multiple of `pixels.len()`, the sample count).
    fn pixels_samples(&self, pixels: &[(u32, u32)], out: &mut [Vec3]) {
        pixel_by_pixel(pixels, out, |x, y, samples| self.samples(x, y, samples));
    }
}

/// [`PixelEstimator::pixels_samples`] one pixel after the other: `samples(x, y, out)` for each
/// pixel's share of `out`.
pub fn pixel_by_pixel(pixels: &[(u32, u32)], out: &mut [Vec3], mut samples: impl FnMut(u32, u32, &mut [Vec3])) {
    let spp = out.len() / pixels.len().max(1);
    for (&(x, y), chunk) in pixels.iter().zip(out.chunks_exact_mut(spp.max(1))) {
        samples(x, y, chunk);
    }
}

/// Renders a `w × h` image with `spp` samples per pixel, averaged with a box filter;
/// `progress(done, total)` is called as tiles finish (from worker threads).
pub fn render_image(
    w: u32,
    h: u32,
    estimator: &dyn PixelEstimator,
    spp: u32,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Image {
    let tiles: Vec<(u32, u32)> =
        (0..h.div_ceil(TILE)).flat_map(|ty| (0..w.div_ceil(TILE)).map(move |tx| (tx * TILE, ty * TILE))).collect();
    let done = AtomicUsize::new(0);
    let rendered: Vec<Vec<[f32; 3]>> = tiles
        .par_iter()
        .map(|&(x0, y0)| {
            let mut out = Vec::with_capacity((TILE * TILE) as usize);
            let row_end = (x0 + TILE).min(w);
            // A tile row at a time: the estimator may trace several pixels' samples together.
            let mut samples = vec![Vec3::ZERO; spp as usize * (row_end - x0) as usize];
            for y in y0..(y0 + TILE).min(h) {
                let row: Vec<(u32, u32)> = (x0..row_end).map(|x| (x, y)).collect();
                estimator.pixels_samples(&row, &mut samples);
                out.extend(row.iter().enumerate().map(|(i, _)| average(&samples[i * spp as usize..][..spp as usize])));
            }
            progress(done.fetch_add(1, Ordering::Relaxed) + 1, tiles.len());
            out
        })
        .collect();
    let mut pixels = vec![[0f32; 3]; (w * h) as usize];
    for (&(x0, y0), tile) in tiles.iter().zip(&rendered) {
        let tw = (x0 + TILE).min(w) - x0;
        for (k, px) in tile.iter().enumerate() {
            let (x, y) = (x0 + k as u32 % tw, y0 + k as u32 / tw);
            pixels[(y * w + x) as usize] = *px;
        }
    }
    Image { width: w, height: h, pixels }
}

/// The box-filtered pixel of its samples, summed in index order.
fn average(samples: &[Vec3]) -> [f32; 3] {
    let mut sum = Vec3::ZERO;
    for &c in samples {
        // A NaN or infinity from a degenerate input must not poison the pixel.
        sum += if c.is_finite() { c } else { Vec3::ZERO };
    }
    // Beyond the float range a pixel keeps the largest float, not an infinity.
    let c = (sum / samples.len() as f64).clamp(Vec3::splat(-f32::MAX as f64), Vec3::splat(f32::MAX as f64));
    [c.x as f32, c.y as f32, c.z as f32]
}
