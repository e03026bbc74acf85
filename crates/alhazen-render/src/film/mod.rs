//! The film: linear radiance per pixel, rendered in parallel tiles. The tile order and the
//! thread count do not affect any pixel (each sample's randomness is seeded from its pixel and
//! index), and a pixel's samples are summed exactly ([`alhazen_math::exact_sum`]), so the sum
//! does not depend on how the samples were grouped either: a render made in parts — tiles on
//! different machines, shares of the samples ([`part`]), or resumed from a checkpoint — merges
//! to the bits of the render made at once.

pub mod filter;
pub mod part;

use alhazen_math::Vec3;
use alhazen_math::exact_sum::{Digits, ExactSum, MAX_TERM};
use rayon::prelude::*;
use std::ops::Range;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// The side of the film's square tiles, in pixels.
pub const TILE: u32 = 32;

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

    /// Consecutive samples of pixel `(x, y)`: `out[i] = self.sample(x, y, first + i)`, in
    /// whatever order the estimator computes them fastest.
    fn samples(&self, x: u32, y: u32, first: u32, out: &mut [Vec3]) {
        out.iter_mut().enumerate().for_each(|(i, c)| *c = self.sample(x, y, first + i as u32));
    }

    /// [`Self::samples`] of several pixels: `out` holds each pixel's in turn (`out.len()` is a
    /// multiple of `pixels.len()`, the sample count).
    fn pixels_samples(&self, pixels: &[(u32, u32)], first: u32, out: &mut [Vec3]) {
        pixel_by_pixel(pixels, out, |x, y, samples| self.samples(x, y, first, samples));
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

/// One of the film's tiles: a rectangle of pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Tile {
    /// Left column.
    pub x0: u32,
    /// Top row.
    pub y0: u32,
    /// Width in pixels (`TILE` but at the right edge).
    pub width: u32,
    /// Height in pixels (`TILE` but at the bottom edge).
    pub height: u32,
}

impl Tile {
    /// Its pixel count.
    pub fn len(&self) -> usize {
        (self.width * self.height) as usize
    }

    /// Whether it has no pixel (never, for a film's tiles).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// The tiles of a `w × h` film, row by row: the unit of parallel work, of progress, of
/// checkpoints and of distributed renders.
pub fn tiles(w: u32, h: u32) -> Vec<Tile> {
    (0..h.div_ceil(TILE))
        .flat_map(|ty| (0..w.div_ceil(TILE)).map(move |tx| (tx * TILE, ty * TILE)))
        .map(|(x0, y0)| Tile { x0, y0, width: TILE.min(w - x0), height: TILE.min(h - y0) })
        .collect()
}

/// What part of a render to make: some of the film's tiles, and a range of each pixel's
/// sample indices (all of `0..spp` for a whole render).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Job {
    /// Indices into [`tiles`] to render, in increasing order.
    pub tiles: Vec<usize>,
    /// Sample indices of every pixel: to merge with other jobs' bit for bit, from and to
    /// multiples of [`SAMPLE_BLOCK`] (or `spp`), as [`part::share_samples`] splits them.
    pub samples: Range<u32>,
    /// Whether each tile's exact sums are kept (for parts that are merged later).
    pub keep_sums: bool,
}

impl Job {
    /// Every tile of a `w × h` film with every sample of `spp`.
    pub fn whole(w: u32, h: u32, spp: u32) -> Self {
        Self { tiles: (0..tiles(w, h).len()).collect(), samples: 0..spp, keep_sums: false }
    }
}

/// A rendered tile: its pixels over the job's samples and, when asked, their exact sums.
#[derive(Clone, Debug, PartialEq)]
pub struct TileResult {
    /// Index into [`tiles`].
    pub index: usize,
    /// The tile's pixels, row by row: each the mean of the job's samples.
    pub pixels: Vec<[f32; 3]>,
    /// Each pixel's exact channel sums, when the job keeps them.
    pub sums: Option<PixelSums>,
    /// Samples left out because they were not finite (NaN or infinite radiance from a
    /// degenerate input), or clamped to ±[`MAX_TERM`]: for the render's summary. Not saved in
    /// parts.
    pub unusable_samples: u64,
    /// Pixels whose value is beyond the float range and kept the largest float.
    pub clamped_pixels: u64,
}

/// Exact sums of a tile's pixels, three channels per pixel, as canonical digits
/// ([`Digits`]): `heads[3p + c]` is (negative, first, count) of pixel `p`'s channel `c`, whose
/// digits follow one another in `digits`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PixelSums {
    /// Sign, place of the lowest digit and number of digits of each channel sum.
    pub heads: Vec<[u8; 3]>,
    /// The digits, channel after channel.
    pub digits: Vec<u32>,
}

impl PixelSums {
    fn push(&mut self, sums: &[ExactSum; 3]) {
        for s in sums {
            let d = s.digits();
            self.heads.push([d.negative as u8, d.first as u8, d.digits.len() as u8]);
            self.digits.extend_from_slice(&d.digits);
        }
    }

    /// The channel sums one after the other.
    pub fn channels(&self) -> impl Iterator<Item = Digits> + '_ {
        self.heads.iter().scan(0usize, |at, &[negative, first, n]| {
            let range = *at..*at + n as usize;
            *at = range.end;
            Some(Digits { negative: negative != 0, first: first as usize, digits: self.digits[range].to_vec() })
        })
    }
}

/// Renders the job's tiles of a `w × h` film with the job's samples of `spp`, handing each
/// tile to `done` as it finishes (from worker threads, in any order). Tiles not yet begun
/// when `stop` is set are skipped: what `done` received is all that was rendered.
pub fn render_tiles(
    w: u32,
    h: u32,
    estimator: &dyn PixelEstimator,
    job: &Job,
    stop: &AtomicBool,
    done: &(dyn Fn(TileResult) + Sync),
) {
    let all = tiles(w, h);
    // Every tile a piece of work a thread may take (by default a thread runs a run of tiles
    // alone, and the other waited on its last ones: 4–8 % of a Cornell box's time on 2 threads).
    job.tiles.par_iter().with_max_len(1).for_each(|&index| {
        if !stop.load(Ordering::Relaxed) {
            done(render_tile(all[index], index, estimator, job));
        }
    });
}

fn render_tile(tile: Tile, index: usize, estimator: &dyn PixelEstimator, job: &Job) -> TileResult {
    // The tile's bands in parallel: the last tiles of a render then keep every thread busy.
    let bands: Vec<TileResult> = (tile.y0..tile.y0 + tile.height)
        .step_by(BAND_ROWS as usize)
        .collect::<Vec<u32>>()
        .into_par_iter()
        .map(|y0| {
            let band = Tile { y0, height: BAND_ROWS.min(tile.y0 + tile.height - y0), ..tile };
            render_band(band, estimator, job)
        })
        .collect();
    let mut result = TileResult {
        index,
        pixels: Vec::with_capacity(tile.len()),
        sums: job.keep_sums.then(PixelSums::default),
        unusable_samples: 0,
        clamped_pixels: 0,
    };
    for band in bands {
        result.pixels.extend(band.pixels);
        if let (Some(all), Some(b)) = (result.sums.as_mut(), band.sums) {
            all.heads.extend(b.heads);
            all.digits.extend(b.digits);
        }
        result.unusable_samples += band.unusable_samples;
        result.clamped_pixels += band.clamped_pixels;
    }
    result
}

/// Rows of a tile rendered as one piece of work (a tile holds several: the last tiles of a
/// render, shared among threads a band each, leave no thread idle for a tile's time).
const BAND_ROWS: u32 = 2;

/// [`render_tile`] of one band of rows (its index left 0).
fn render_band(band: Tile, estimator: &dyn PixelEstimator, job: &Job) -> TileResult {
    let count = job.samples.len();
    let mut pixels = Vec::with_capacity(band.len());
    let mut kept = job.keep_sums.then(PixelSums::default);
    // A row at a time: the estimator may trace several pixels' samples together.
    let mut samples = vec![Vec3::ZERO; count * band.width as usize];
    let mut sums: [ExactSum; 3] = Default::default();
    let (mut unusable_samples, mut clamped_pixels) = (0, 0);
    for y in band.y0..band.y0 + band.height {
        let row: Vec<(u32, u32)> = (band.x0..band.x0 + band.width).map(|x| (x, y)).collect();
        estimator.pixels_samples(&row, job.samples.start, &mut samples);
        for i in 0..row.len() {
            unusable_samples += sum_samples(&samples[i * count..(i + 1) * count], job.samples.start, &mut sums);
            let pixel = pixel_value(&mut sums, count as u64);
            clamped_pixels += pixel.iter().any(|c| c.abs() == f32::MAX) as u64;
            pixels.push(pixel);
            if let Some(k) = kept.as_mut() {
                k.push(&sums);
            }
        }
    }
    TileResult { index: 0, pixels, sums: kept, unusable_samples, clamped_pixels }
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
    let job = Job::whole(w, h, spp);
    let rendered = Mutex::new(vec![Vec::new(); job.tiles.len()]);
    let finished = AtomicUsize::new(0);
    render_tiles(w, h, estimator, &job, &AtomicBool::new(false), &|t| {
        rendered.lock().unwrap_or_else(|e| e.into_inner())[t.index] = t.pixels;
        progress(finished.fetch_add(1, Ordering::Relaxed) + 1, job.tiles.len());
    });
    let rendered = rendered.into_inner().unwrap_or_else(|e| e.into_inner());
    assemble(w, h, rendered.iter().enumerate().map(|(i, p)| (i, p.as_slice())))
}

/// The image whose tiles (index into [`tiles`], pixels) are given; missing ones stay black.
pub fn assemble<'a>(w: u32, h: u32, rendered: impl Iterator<Item = (usize, &'a [[f32; 3]])>) -> Image {
    let all = tiles(w, h);
    let mut image = Image { width: w, height: h, pixels: vec![[0f32; 3]; (w as usize) * (h as usize)] };
    for (index, tile_pixels) in rendered {
        place(&mut image, all[index], tile_pixels);
    }
    image
}

/// Copies a tile's pixels (row by row) into the image.
pub fn place(image: &mut Image, t: Tile, tile_pixels: &[[f32; 3]]) {
    for (row, line) in tile_pixels.chunks_exact(t.width as usize).enumerate() {
        let at = ((t.y0 + row as u32) * image.width + t.x0) as usize;
        image.pixels[at..at + line.len()].copy_from_slice(line);
    }
}

/// Samples are summed in blocks of this many consecutive indices (`[8j, 8j + 8)`), each block
/// in index order in doubles, and the blocks' sums exactly: the pixel then depends only on its
/// samples, whichever jobs made them, as long as jobs split the samples at block boundaries
/// ([`part::share_samples`]) — at an eighth of the cost of summing every sample exactly.
pub const SAMPLE_BLOCK: u32 = 8;

/// A pixel's samples (indices `first..`) summed by blocks, channel by channel. A NaN or
/// infinity from a degenerate input adds nothing (it must not poison the pixel); huge values
/// are clamped so no block sum overflows. Returns how many samples were left out or clamped.
fn sum_samples(samples: &[Vec3], first: u32, sums: &mut [ExactSum; 3]) -> u64 {
    let limit = Vec3::splat(MAX_TERM);
    let mut unusable = 0;
    sums.iter_mut().for_each(ExactSum::clear);
    let to_boundary = ((SAMPLE_BLOCK - first % SAMPLE_BLOCK) % SAMPLE_BLOCK) as usize;
    let (head, rest) = samples.split_at(to_boundary.min(samples.len()));
    for block in std::iter::once(head).filter(|h| !h.is_empty()).chain(rest.chunks(SAMPLE_BLOCK as usize)) {
        let mut block_sum = Vec3::ZERO;
        for c in block {
            if c.is_finite() && c.abs().cmple(limit).all() {
                block_sum += *c;
            } else {
                unusable += 1;
                if c.is_finite() {
                    block_sum += c.clamp(-limit, limit);
                }
            }
        }
        for (s, v) in sums.iter_mut().zip([block_sum.x, block_sum.y, block_sum.z]) {
            s.add(v);
        }
    }
    unusable
}

/// The box-filtered pixel: the exact sums of `count` samples divided by `count`. Beyond the
/// float range a pixel keeps the largest float, not an infinity.
pub fn pixel_value(sums: &mut [ExactSum; 3], count: u64) -> [f32; 3] {
    sums.each_mut().map(|s| (s.value() / count.max(1) as f64).clamp(-f32::MAX as f64, f32::MAX as f64) as f32)
}
