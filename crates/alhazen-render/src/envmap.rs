//! Environment light from an equirectangular radiance map (course §"Image-based lighting for
//! physical models"), importance-sampled by texel power (luminance × sin ϑ): a row by the
//! marginal distribution, then a texel by the row's conditional one.
//!
//! Mapping: `u = φ/2π` with `φ` the azimuth from `−z` towards `+x` (plus the map's rotation),
//! `v = ϑ/π` from straight up (`+y`) to straight down. The radiance is interpolated bilinearly
//! between texel centres, as Mitsuba and Cycles read a map (a map of 1024 texels round, seen
//! behind a picture 50° wide, would otherwise show blocks 13 pixels across); the sampling
//! density is constant over each texel, in proportion to the mean of the interpolated radiance
//! over it (a 1-6-1 stencil across and down, over 64), which is positive wherever the radiance
//! is, so next-event estimates stay unbiased and a lit texel's dark neighbours, which its light
//! spills into, are sampled too.
//!
//! Layout: the caches, not the arithmetic, bound the map's cost (a 512 × 256 map in double
//! precision with guide tables is 3.5 MB, past what a core of this machine keeps close). Each
//! texel is one 16-byte record, its radiance and its row's CDF at its start in single
//! precision, and each row has a 16-bit guide table: a sample reads the row's guide and a
//! record or two, a lookup a record and its neighbour (2.25 MB in all where it was 3.5; the
//! CDF apart from the radiance was no faster). Densities come from the same single-precision
//! CDF as the sampling, so samples and lookups agree exactly. Paths traced side by side take
//! their samples and lookups in steps ([`EnvMap::sample_row`], [`EnvMap::touch_texels`],
//! [`EnvMap::sample_texel`], [`EnvMap::sample_at`]; [`EnvMap::texels_ahead`],
//! [`EnvMap::radiance_and_pdf_at`]), each asking memory for what the next will read, so that
//! the paths' cache misses overlap.
//!
//! Where every light sample is weighed against a BSDF sample (the path tracer), the map is
//! sampled by each texel's excess over its mean instead ([`MapSampling::AboveMean`], MIS
//! compensation: Karlík et al. 2019): the BSDF samples find the dim sky well.

use crate::distribution::{Distribution1D, Slices, guide_table, search_cdf};
use crate::prefetch::prefetch;
use crate::shape::VectorUnit;
use alhazen_math::{Mat3, Vec2, Vec3, color::luminance};
use alhazen_scene::ImageData;
use std::f64::consts::PI;

/// Rows at most this wide are searched without a guide table (and rows too wide for 16-bit
/// guide entries).
const GUIDED_FROM: usize = 16;

/// A texel: its radiance (unscaled) and its row's CDF at its start (the row's end, 1, is
/// implicit).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(16))]
struct Texel {
    radiance: [f32; 3],
    cdf: f32,
}

/// Directions [`EnvMap::texels_ahead`] maps to texels in one vector loop.
const AHEAD: usize = 8;

/// A point of the map [`EnvMap::sample_texel`] chose: its place and its texel.
#[derive(Clone, Copy, Debug)]
pub struct TexelSample {
    uv: Vec2,
    texel: (usize, usize),
}

/// An environment map ready for lookup and sampling.
#[derive(Clone, Debug)]
pub struct EnvMap {
    width: usize,
    height: usize,
    texels: Vec<Texel>,
    /// Per row, `width + 1` guide entries ([`guide_table`]); empty for narrow maps.
    guides: Vec<u16>,
    /// The guide entries' slices of a row.
    slices: Slices,
    scale: f64,
    rotation: f64,
    /// The rotation in turns.
    turns: f64,
    /// The map's axes in the world ([`alhazen_scene::texture::up_frame`]).
    frame: Option<Mat3>,
    /// Over rows, by their power.
    rows: Distribution1D,
}

impl EnvMap {
    /// From a linear radiance image, turned by `rotation` (radians) about its up axis `up`,
    /// sampled in proportion to its power everywhere.
    pub fn new(image: &ImageData, scale: f64, turn: (f64, Vec3)) -> Self {
        Self::sampled(image, scale, turn, MapSampling::Whole)
    }

    /// [`Self::new`] with its samples drawn as `sampling` says.
    pub fn sampled(image: &ImageData, scale: f64, (rotation, up): (f64, Vec3), sampling: MapSampling) -> Self {
        let (width, height) = (image.width as usize, image.height as usize);
        // The records over `floor`, and the greatest texel mean.
        let records = |floor: f64| {
            let (mut texels, mut row_power) = (Vec::with_capacity(width * height), Vec::with_capacity(height));
            let mut greatest = 0.0f64;
            for (y, means) in texel_means(image) {
                greatest = means.iter().fold(greatest, |g, &l| g.max(l));
                let sin = (PI * (y as f64 + 0.5) / height as f64).sin();
                let powers: Vec<f64> = means.iter().map(|&l| (l - floor).max(0.0) * sin).collect();
                let total: f64 = powers.iter().sum();
                let mut before = 0.0;
                for (x, w) in powers.iter().enumerate() {
                    let cdf = if total > 0.0 { before / total } else { x as f64 / width as f64 };
                    texels.push(Texel { radiance: image.texel(y * width + x), cdf: cdf as f32 });
                    before += w;
                }
                row_power.push(total);
            }
            (texels, row_power, greatest)
        };
        let (texels, row_power, _) = match sampling {
            MapSampling::Whole => records(0.0),
            MapSampling::AboveMean => {
                let mean = mean_luminance(image);
                let (texels, row_power, greatest) = records(mean);
                // Nothing above the mean but by rounding (a map of one colour): sampled whole.
                if greatest > mean * (1.0 + 1e-6) { (texels, row_power, greatest) } else { records(0.0) }
            }
        };
        let guided = (GUIDED_FROM..u16::MAX as usize).contains(&width);
        let mut m = Self {
            width,
            height,
            texels,
            guides: vec![],
            slices: Slices::new(width),
            scale,
            rotation,
            turns: rotation / (2.0 * PI),
            frame: alhazen_scene::texture::up_frame(up),
            rows: Distribution1D::new(&row_power),
        };
        if guided {
            let map = &m;
            let guides =
                (0..height).flat_map(|y| guide_table(width, move |i| map.cdf(y, i)).map(|g| g as u16)).collect();
            m.guides = guides;
        }
        m
    }

    /// The bytes the environment maps of `scene`'s lights will take (records, guide tables
    /// and the marginal over rows), for refusing a render before anything is allocated.
    pub fn memory_estimate(scene: &alhazen_scene::Scene) -> u64 {
        let maps = scene.lights.iter().filter_map(|l| match l {
            alhazen_scene::Light::Environment { image, .. } => scene.images.get(*image),
            _ => None,
        });
        maps.map(|i| {
            let (w, h) = (i.width as u64, i.height as u64);
            h * (w + 1) * (std::mem::size_of::<Texel>() as u64 + 2) + h * 24
        })
        .sum()
    }

    /// Row `y`'s CDF entry `i` (`0..=width`).
    #[inline]
    fn cdf(&self, y: usize, i: usize) -> f64 {
        if i < self.width { self.texels[y * self.width + i].cdf as f64 } else { 1.0 }
    }

    /// The texel `(x, y)` holding `uv`.
    #[inline(always)]
    fn texel_at(&self, uv: Vec2) -> (usize, usize) {
        let x = ((uv.x * self.width as f64) as usize).min(self.width - 1);
        let y = ((uv.y * self.height as f64) as usize).min(self.height - 1);
        (x, y)
    }

    /// The radiance at `uv`, interpolated bilinearly between the texel centres around it.
    fn radiance_at(&self, uv: Vec2) -> Vec3 {
        let taps = alhazen_scene::texture::equirect_taps(uv, self.width, self.height);
        let sum = taps.iter().fold(Vec3::ZERO, |sum, &(i, w)| {
            let p = self.texels[i].radiance;
            sum + Vec3::new(p[0] as f64, p[1] as f64, p[2] as f64) * w
        });
        sum * self.scale
    }

    /// The density of sampling a point of texel `(x, y)` in the unit square of `uv`.
    fn density_uv(&self, (x, y): (usize, usize)) -> f64 {
        let width = self.cdf(y, x + 1) - self.cdf(y, x);
        self.rows.cell_density(y) * width * self.width as f64
    }

    /// A point in row `y` (`u` in `[0, 1)`) by the row's CDF, and its texel's column.
    fn sample_in_row(&self, y: usize, u: f64) -> (f64, usize) {
        let w = self.width;
        let guide =
            (!self.guides.is_empty()).then_some((&self.slices, |j: usize| self.guides[y * (w + 1) + j] as usize));
        let x = search_cdf(u, w, guide, |i| self.cdf(y, i));
        let (lo, hi) = (self.cdf(y, x), self.cdf(y, x + 1));
        let du = if hi > lo { (u - lo) / (hi - lo) } else { 0.5 };
        (((x as f64 + du.clamp(0.0, 1.0)) / w as f64).min(1.0 - 1e-16), x)
    }

    /// The guide slice `u` falls in.
    fn slice(&self, u: f64) -> usize {
        self.slices.of(u)
    }

    /// World direction `dir` in the map's axes.
    #[inline(always)]
    fn in_map_axes(&self, dir: Vec3) -> Vec3 {
        alhazen_scene::texture::into_map(self.frame, dir)
    }

    #[inline(always)]
    fn to_uv(&self, dir: Vec3) -> Vec2 {
        alhazen_scene::texture::equirect_uv(self.in_map_axes(dir), self.rotation)
    }

    /// The direction of `uv` and its polar angle's sine.
    fn to_dir(&self, uv: Vec2) -> (Vec3, f64) {
        let (st, ct) = alhazen_math::sin_cos_turns(uv.y / 2.0);
        let (sp, cp) = alhazen_math::sin_cos_turns(uv.x - self.turns);
        let dir = Vec3::new(st * sp, ct, -st * cp);
        (self.frame.map_or(dir, |f| f * dir), st)
    }

    /// Radiance arriving from direction `dir` (unit, pointing away from the scene).
    pub fn radiance(&self, dir: Vec3) -> Vec3 {
        self.radiance_at(self.to_uv(dir))
    }

    /// A direction with density ∝ power, its radiance and solid-angle density.
    pub fn sample(&self, u: Vec2) -> Option<(Vec3, Vec3, f64)> {
        self.sample_in(self.sample_row(u), u)
    }

    /// The first step of [`Self::sample`]: the row `u` falls in, its `v` and index, and the
    /// row's guide entries for `u.x` asked of memory (`prefetch`), so that paths sampling
    /// side by side wait for their rows together rather than one after another.
    pub fn sample_row(&self, u: Vec2) -> (f64, usize) {
        let (v, y) = self.rows.sample_point(u.y);
        if !self.guides.is_empty() {
            prefetch(&self.guides[y * (self.width + 1) + self.slice(u.x)]);
        }
        (v, y)
    }

    /// The second step: the texels the search of row `y` for `u.x` will read, asked of memory
    /// (their slice's guide entries read, which [`Self::sample_row`] asked for).
    pub fn touch_texels(&self, (_, y): (f64, usize), u: Vec2) {
        let (w, row) = (self.width, &self.texels[y * self.width..(y + 1) * self.width]);
        let (lo, hi) = if self.guides.is_empty() {
            (0, w)
        } else {
            let (j, guides) = (self.slice(u.x), &self.guides[y * (w + 1)..]);
            (guides[j] as usize, guides[j + 1] as usize)
        };
        prefetch(&row[lo.saturating_sub(1).min(w - 1)]);
        prefetch(&row[hi.min(w) - 1]);
    }

    /// [`Self::sample`] in row `row` ([`Self::sample_row`]`(u)`).
    pub fn sample_in(&self, row: (f64, usize), u: Vec2) -> Option<(Vec3, Vec3, f64)> {
        self.sample_at(self.sample_texel(row, u))
    }

    /// The third step: the point in row `row` (its texel searched for, whose records
    /// [`Self::touch_texels`] asked for), and the texels its radiance is interpolated from
    /// asked of memory — in the row above or below too, which no earlier step could know.
    pub fn sample_texel(&self, (v, y): (f64, usize), u: Vec2) -> TexelSample {
        let (u, x) = self.sample_in_row(y, u.x);
        let taps = alhazen_scene::texture::equirect_taps(Vec2::new(u, v), self.width, self.height);
        prefetch(&self.texels[taps[0].0]);
        prefetch(&self.texels[taps[3].0]);
        TexelSample { uv: Vec2::new(u, v), texel: (x, y) }
    }

    /// The last step: the direction of a point [`Self::sample_texel`] found, its radiance and
    /// solid-angle density.
    pub fn sample_at(&self, TexelSample { uv, texel }: TexelSample) -> Option<(Vec3, Vec3, f64)> {
        let (dir, sin) = self.to_dir(uv);
        // The texel sampled (not looked up again from the direction: the same texel but for
        // rounding on its edges, without the inverse trigonometry).
        let density = self.density_uv(texel);
        if density <= 0.0 || sin <= 0.0 {
            return None;
        }
        Some((dir, self.radiance_at(uv), density / (2.0 * PI * PI * sin)))
    }

    /// Solid-angle density of [`Self::sample`] choosing `dir`.
    pub fn pdf(&self, dir: Vec3) -> f64 {
        self.solid_angle_density(self.texel_at(self.to_uv(dir)), polar_sine(self.in_map_axes(dir)))
    }

    /// [`Self::radiance`] and [`Self::pdf`] of `dir`, mapped to the image once.
    pub fn radiance_and_pdf(&self, dir: Vec3) -> (Vec3, f64) {
        self.radiance_and_pdf_at(dir, self.to_uv(dir))
    }

    /// The first half of [`Self::radiance_and_pdf`] for many directions (`None` where a lane
    /// has none): every lane's place in the map, found in one loop of arithmetic (vectorised),
    /// and the texels around it asked of memory. [`Self::radiance_and_pdf_at`] reads them
    /// later, when they have arrived.
    pub fn texels_ahead<const N: usize>(&self, dirs: &[Option<Vec3>; N], unit: VectorUnit) -> [Vec2; N] {
        // The directions given, side by side, [`AHEAD`] at a time: lanes without one (often
        // half of them) cost no inverse trigonometry.
        let (mut dense, mut from, mut n) = ([Vec3::Y; N], [0; N], 0);
        for (i, dir) in dirs.iter().enumerate() {
            if let Some(dir) = *dir {
                (dense[n], from[n]) = (dir, i);
                n += 1;
            }
        }
        let mut uvs = [Vec2::ZERO; N];
        for start in (0..n).step_by(AHEAD) {
            let mut some = [Vec3::Y; AHEAD];
            let len = AHEAD.min(n - start);
            some[..len].copy_from_slice(&dense[start..start + len]);
            for (k, &uv) in self.uvs_in_lanes(&some, unit)[..len].iter().enumerate() {
                uvs[from[start + k]] = uv;
                // The two rows the interpolation reads (a row's pair is one line or two).
                let taps = alhazen_scene::texture::equirect_taps(uv, self.width, self.height);
                prefetch(&self.texels[taps[0].0]);
                prefetch(&self.texels[taps[3].0]);
            }
        }
        uvs
    }

    /// [`Self::radiance_and_pdf`] of `dir`, at its place `uv` in the map ([`Self::texels_ahead`]).
    pub fn radiance_and_pdf_at(&self, dir: Vec3, uv: Vec2) -> (Vec3, f64) {
        (self.radiance_at(uv), self.solid_angle_density(self.texel_at(uv), polar_sine(self.in_map_axes(dir))))
    }

    /// The places in the map of many directions, in AVX-512 or AVX2 where `unit` has them.
    #[allow(unsafe_code)]
    fn uvs_in_lanes<const N: usize>(&self, dirs: &[Vec3; N], unit: VectorUnit) -> [Vec2; N] {
        #[cfg(target_arch = "x86_64")]
        if unit.is_avx512() {
            // SAFETY: a `VectorUnit` says AVX-512 (F, DQ, VL, BW) only where the processor has them.
            return unsafe { self.uvs_avx512(dirs) };
        }
        #[cfg(target_arch = "x86_64")]
        if unit.is_avx2() {
            // SAFETY: a `VectorUnit` says AVX2 only where the processor has it.
            return unsafe { self.uvs_avx2(dirs) };
        }
        let _ = unit;
        self.uvs_of(dirs)
    }

    /// [`Self::uvs_in_lanes`]'s loop, inlined into each vector unit's function.
    #[inline(always)]
    fn uvs_of<const N: usize>(&self, dirs: &[Vec3; N]) -> [Vec2; N] {
        let mut uvs = [Vec2::ZERO; N];
        for (uv, &dir) in uvs.iter_mut().zip(dirs) {
            *uv = self.to_uv(dir);
        }
        uvs
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512dq,avx512vl,avx512bw")]
    #[allow(unsafe_code)]
    unsafe fn uvs_avx512<const N: usize>(&self, dirs: &[Vec3; N]) -> [Vec2; N] {
        self.uvs_of(dirs)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[allow(unsafe_code)]
    unsafe fn uvs_avx2<const N: usize>(&self, dirs: &[Vec3; N]) -> [Vec2; N] {
        self.uvs_of(dirs)
    }

    /// The density of a direction in `texel` whose polar angle has sine `sin`.
    fn solid_angle_density(&self, texel: (usize, usize), sin: f64) -> f64 {
        if sin <= 0.0 { 0.0 } else { self.density_uv(texel) / (2.0 * PI * PI * sin) }
    }
}

/// How an environment map's light samples are drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MapSampling {
    /// In proportion to the interpolated radiance's luminance over each texel: every direction
    /// the map lights can be drawn (what an estimate by light samples alone needs).
    Whole,
    /// In proportion to how far that luminance exceeds its mean over the sphere, nothing below
    /// it (Karlík et al. 2019, "MIS compensation"): for estimates that weigh light samples
    /// against BSDF samples, which cover the rest — the light samples go to the map's bright
    /// parts (a sun), where the BSDF samples are weak. Sampled whole where no texel exceeds
    /// the mean (a map of one colour). The mean is of the texels' own values, the excess of
    /// their interpolated means over it: any floor gives unbiased estimates, as long as the
    /// densities come from the same tables as the samples (they do).
    AboveMean,
}

/// Row by row, each texel's mean of the interpolated luminance over it (1-6-1 across and down,
/// over 64; three rows' luminance at a time: an image kept as codes is never expanded whole).
fn texel_means(image: &ImageData) -> impl Iterator<Item = (usize, Vec<f64>)> + '_ {
    let (width, height) = (image.width as usize, image.height as usize);
    let luminances =
        move |y: usize| -> Vec<f64> { (0..width).map(|x| texel_luminance(image.texel(y * width + x))).collect() };
    let mut rows = (luminances(0), luminances(0));
    (0..height).map(move |y| {
        let below = luminances((y + 1).min(height - 1));
        let across = |r: &[f64], x: usize| {
            let (left, right) = (if x == 0 { width - 1 } else { x - 1 }, if x + 1 == width { 0 } else { x + 1 });
            r[left] + 6.0 * r[x] + r[right]
        };
        let (above, here) = &rows;
        let means = (0..width).map(|x| (across(above, x) + 6.0 * across(here, x) + across(&below, x)) / 64.0).collect();
        rows = (std::mem::take(&mut rows.1), below);
        (y, means)
    })
}

/// The mean luminance of the map over the sphere (each texel weighed by its solid angle; the
/// texels' own values, which the interpolation averages to the same within rounding).
fn mean_luminance(image: &ImageData) -> f64 {
    let (width, height) = (image.width as usize, image.height as usize);
    let (mut sum, mut weight) = (0.0, 0.0);
    for y in 0..height {
        let sin = (PI * (y as f64 + 0.5) / height as f64).sin();
        let row: f64 = (0..width).map(|x| texel_luminance(image.texel(y * width + x))).sum();
        (sum, weight) = (sum + row * sin, weight + width as f64 * sin);
    }
    if weight > 0.0 { sum / weight } else { 0.0 }
}

/// A texel's luminance, zero where it is not a finite positive number.
fn texel_luminance(p: [f32; 3]) -> f64 {
    let l = luminance(Vec3::new(p[0] as f64, p[1] as f64, p[2] as f64));
    if l.is_finite() { l.max(0.0) } else { 0.0 }
}

/// The sine of unit direction `dir`'s angle from +y, without trigonometry.
fn polar_sine(dir: Vec3) -> f64 {
    (dir.x * dir.x + dir.z * dir.z).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Upright, tilted towards `+z` (a z-up world's map) and upside down; sampled whole and
    /// above its mean.
    fn test_maps() -> Vec<EnvMap> {
        let (w, h) = (16u32, 8u32);
        let pixels: Vec<_> = (0..w * h).map(|i| [(i % 7) as f32 + 0.5, 1.0, (i % 3) as f32]).collect();
        let image = ImageData::new(w, h, pixels);
        let ups = [Vec3::Y, Vec3::new(0.0, 0.6, 0.8), -Vec3::Y];
        let samplings = [MapSampling::Whole, MapSampling::AboveMean];
        samplings.iter().flat_map(|&s| ups.map(|up| EnvMap::sampled(&image, 2.0, (0.4, up), s))).collect()
    }

    /// Sampled above its mean, a map draws no direction where its interpolated luminance is
    /// below the mean (its density there is zero), and its bright patch more often than sampled
    /// whole; a map of one colour is sampled whole.
    #[test]
    fn above_its_mean_a_map_samples_its_bright_parts_only() {
        let (w, h) = (32u32, 16u32);
        // A dim sky brightening upwards and a bright patch.
        let pixels: Vec<_> = (0..w * h)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                let sky = 1.0 + (h - y) as f32 / h as f32;
                if (10..13).contains(&x) && (4..6).contains(&y) { [90.0, 80.0, 70.0] } else { [sky; 3] }
            })
            .collect();
        let image = ImageData::new(w, h, pixels);
        let m = EnvMap::sampled(&image, 1.0, (0.0, Vec3::Y), MapSampling::AboveMean);
        let mean = mean_luminance(&image);
        let means: Vec<f64> = texel_means(&image).flat_map(|(_, row)| row).collect();
        for k in 0..300 {
            let u = Vec2::new((k as f64 * 0.618).fract(), (k as f64 * 0.377 + 0.1).fract());
            let (d, _, pdf) = m.sample(u).unwrap();
            let (x, y) = m.texel_at(m.to_uv(d));
            assert!(means[y * w as usize + x] > mean, "sample {k} in texel {x}, {y}");
            assert!((m.pdf(d) - pdf).abs() < 1e-9 * pdf);
        }
        // The dim sky far from the patch: no density; the patch: more than sampled whole.
        let whole = EnvMap::new(&image, 1.0, (0.0, Vec3::Y));
        let (dim, patch) = (whole.to_dir(Vec2::new(0.8, 0.9)).0, whole.to_dir(Vec2::new(11.5 / 32.0, 5.0 / 16.0)).0);
        assert_eq!(m.pdf(dim), 0.0);
        assert!(whole.pdf(dim) > 0.0 && m.pdf(patch) > whole.pdf(patch));
        // One colour: sampled whole (uniformly over the sphere, but for the rows' sines).
        let grey = ImageData::new(w, h, vec![[0.7; 3]; (w * h) as usize]);
        let (a, b) = (
            EnvMap::sampled(&grey, 1.0, (0.0, Vec3::Y), MapSampling::AboveMean),
            EnvMap::new(&grey, 1.0, (0.0, Vec3::Y)),
        );
        for dir in [Vec3::new(0.0, 0.8, 0.6), Vec3::new(0.6, 0.0, 0.8), Vec3::new(0.0, -0.8, 0.6)] {
            assert_eq!(a.pdf(dir), b.pdf(dir));
            assert!((a.pdf(dir) * 4.0 * PI - 1.0).abs() < 0.1, "{dir}: {}", a.pdf(dir));
        }
    }

    #[test]
    fn directions_round_trip_and_density_integrates_to_one() {
        for m in test_maps() {
            round_trip_and_unit_integral(&m);
        }
    }

    fn round_trip_and_unit_integral(m: &EnvMap) {
        let (n, mut sum) = (400, 0.0);
        for i in 0..n {
            let z = -1.0 + 2.0 * (i as f64 + 0.5) / n as f64;
            for j in 0..n {
                let phi = 2.0 * PI * (j as f64 + 0.5) / n as f64;
                let r = (1.0 - z * z).sqrt();
                let d = Vec3::new(r * phi.cos(), z, r * phi.sin());
                assert!((m.to_dir(m.to_uv(d)).0 - d).length() < 1e-9);
                sum += m.pdf(d);
            }
        }
        assert!((sum * 4.0 * PI / (n * n) as f64 - 1.0).abs() < 1e-2, "{sum}");
    }

    #[test]
    fn samples_report_their_own_density_and_radiance() {
        for m in test_maps() {
            own_density_and_radiance(&m);
        }
    }

    fn own_density_and_radiance(m: &EnvMap) {
        for k in 0..200 {
            let u = Vec2::new((k as f64 * 0.618).fract(), (k as f64 * 0.377 + 0.1).fract());
            let (d, l, pdf) = m.sample(u).unwrap();
            assert!((m.pdf(d) - pdf).abs() < 1e-9 * pdf.max(1.0), "{k}");
            // Looked up again from the direction, the place in the map moves by rounding.
            assert!((m.radiance(d) - l).abs().max_element() < 1e-6 * l.max_element().max(1.0), "{k}");
            assert_eq!(m.radiance_and_pdf(d), (m.radiance(d), m.pdf(d)));
        }
    }

    /// Between texel centres the radiance is interpolated bilinearly: a texel's own value at
    /// its centre, the mean of two at the edge between them, round the seam in `u`, held at
    /// the first and last rows' centres towards the poles.
    #[test]
    fn radiance_is_interpolated_between_texel_centres() {
        let (w, h) = (8usize, 4usize);
        let value = |x: usize, y: usize| (x + 10 * y) as f32;
        let pixels = (0..w * h).map(|i| [value(i % w, i / w), 1.0, 0.0]).collect();
        let m = EnvMap::new(&ImageData::new(w as u32, h as u32, pixels), 2.0, (0.0, Vec3::Y));
        let at = |x: f64, y: f64| m.radiance_at(Vec2::new(x / w as f64, y / h as f64)).x / 2.0;
        let close = |a: f64, b: f64| (a - b).abs() < 1e-12;
        assert!(close(at(3.5, 1.5), 13.0) && close(at(4.0, 1.5), 13.5) && close(at(3.5, 2.0), 18.0));
        assert!(close(at(4.0, 2.0), 18.5));
        // Round the seam: between the last column and the first.
        assert!(close(at(0.0, 1.5), 13.5) && close(at(7.75, 1.5), 0.25 * 10.0 + 0.75 * 17.0));
        // Towards the poles, the first and last rows' values.
        assert!(close(at(2.5, 0.1), 2.0) && close(at(2.5, 3.9), 32.0));
        assert!((m.radiance_at(Vec2::new(0.3, 0.6)).y - 2.0).abs() < 1e-12);
    }

    /// Next-event estimates of the light a map sends through a window of directions are
    /// unbiased: the mean of radiance over density of its samples that fall inside equals the
    /// integral of the interpolated radiance over the window (a fine midpoint sum), for a map
    /// with one lit texel among black ones (whose light spills into its neighbours) and a
    /// smooth one.
    #[test]
    fn light_sampling_integrates_the_interpolated_radiance() {
        let (w, h) = (16u32, 8u32);
        let one_lit = (0..w * h).map(|i| if i == 3 * w + 5 { [40.0, 30.0, 20.0] } else { [0.0; 3] }).collect();
        let smooth = (0..w * h).map(|i| [(i % w) as f32 * 0.3 + 0.1, (i / w) as f32, 1.0]).collect();
        for pixels in [one_lit, smooth] {
            let m = EnvMap::new(&ImageData::new(w, h, pixels), 1.0, (0.4, Vec3::Y));
            let inside = |d: Vec3| d.x > 0.2 && d.y > -0.3;
            let n = 1usize << 20;
            let mut estimate = Vec3::ZERO;
            for k in 0..n {
                let u = Vec2::new((k as f64 * 0.618_033_988_749_895).fract(), (k as f64 + 0.5) / n as f64);
                if let Some((_, l, pdf)) = m.sample(u).filter(|s| inside(s.0)) {
                    estimate += l / pdf;
                }
            }
            estimate /= n as f64;
            let (cells, mut integral) = (1024usize, Vec3::ZERO);
            for j in 0..cells {
                for i in 0..2 * cells {
                    let uv = Vec2::new((i as f64 + 0.5) / (2 * cells) as f64, (j as f64 + 0.5) / cells as f64);
                    let (d, sin) = m.to_dir(uv);
                    if inside(d) {
                        integral += m.radiance_at(uv) * sin * 2.0 * PI * PI / (2 * cells * cells) as f64;
                    }
                }
            }
            assert!((estimate - integral).abs().max_element() < 2e-3 * integral.max_element(), "{estimate} {integral}");
        }
    }

    /// A single lit texel and the neighbours its light spills into, among black rows (whose
    /// CDFs fall back to uniform), take every sample, with the density their lookups report; narrow maps (searched without guide
    /// tables) and black maps give finite densities.
    #[test]
    fn one_lit_texel_takes_every_sample() {
        for (w, h) in [(40u32, 20u32), (8, 4)] {
            let lit = (h / 3 * w + w / 4) as usize;
            let pixels = (0..(w * h) as usize).map(|i| if i == lit { [5.0, 4.0, 3.0] } else { [0.0; 3] }).collect();
            let m = EnvMap::new(&ImageData::new(w, h, pixels), 1.0, (0.0, Vec3::Y));
            for k in 0..100 {
                let u = Vec2::new((k as f64 * 0.618).fract(), (k as f64 * 0.377 + 0.1).fract());
                let (d, l, pdf) = m.sample(u).unwrap();
                // Within a texel of the lit one's centre, where its light spills.
                let uv = m.to_uv(d);
                let (dx, dy) = (uv.x * w as f64 - (w / 4) as f64 - 0.5, uv.y * h as f64 - (h / 3) as f64 - 0.5);
                assert!(dx.abs() <= 1.5 && dy.abs() <= 1.5, "{w}×{h} sample {k}: {dx}, {dy}");
                assert!(l.x >= 0.0 && (l - Vec3::new(5.0, 4.0, 3.0) * (l.x / 5.0)).length() < 1e-12);
                assert!((m.pdf(d) - pdf).abs() < 1e-9 * pdf, "{w}×{h} sample {k}");
            }
            let black = EnvMap::new(&ImageData::new(w, h, vec![[0.0; 3]; (w * h) as usize]), 1.0, (0.0, Vec3::Y));
            let (_, l, pdf) = black.sample(Vec2::new(0.3, 0.6)).unwrap();
            assert!(l == Vec3::ZERO && pdf.is_finite() && pdf > 0.0);
        }
    }

    /// A render is refused before its maps are built: the estimate grows by at least each
    /// map's records and guide tables.
    #[test]
    fn memory_estimate_counts_each_map() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
        let mut scene = alhazen_scene::load_scene(&root.join("cornell-box.toml")).unwrap();
        let before = crate::memory_estimate(&scene);
        scene.images.push(std::sync::Arc::new(ImageData::new(64, 32, vec![[1.0; 3]; 64 * 32])));
        let image = scene.images.len() - 1;
        scene.lights.push(alhazen_scene::Light::Environment { image, scale: 1.0, rotation: 0.0, up: Vec3::Y });
        assert!(crate::memory_estimate(&scene) >= before + 64 * 32 * 18);
    }
}
