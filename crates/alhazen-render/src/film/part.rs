//! Film parts: rendered tiles saved to a file, to be merged into the image later — a render
//! spread over machines (`--tile i/N` renders a band of tiles, `--pass i/N` a share of every
//! pixel's samples), or a checkpoint of a render in progress.
//!
//! A tile that has all `spp` samples keeps its final pixels; a share of the samples keeps
//! each pixel's exact sums ([`super::PixelSums`]), which merge exactly — so the merged image
//! has the bits of the render made at once, however it was split.
//!
//! The file (`.film`), little-endian: `ALHZFILM`, format version (u32), the scene's
//! [`fingerprint`] (u64), film width, height and spp (u32 each), the tile count (u32); per
//! tile its index, first and end sample (u32 each), whether sums follow (u8), the pixels (f32
//! RGB) and, if so, each channel sum's sign, lowest place and digit count (three u8, three sums
//! per pixel), the digits' total (u32) and the digits (u32); last, an FNV-1a hash of all that, so a truncated or damaged file is refused.

use super::{PixelSums, TileResult, tiles};
use crate::Image;
use alhazen_math::exact_sum::ExactSum;
use std::fmt;
use std::ops::Range;

/// The file extension of film parts.
pub const EXTENSION: &str = "film";
const MAGIC: &[u8; 8] = b"ALHZFILM";
const VERSION: u32 = 1;

/// Rendered tiles of one scene's film.
#[derive(Clone, Debug, PartialEq)]
pub struct Part {
    /// [`fingerprint`] of the scene and the options it was rendered with.
    pub fingerprint: u64,
    /// Film width in pixels.
    pub width: u32,
    /// Film height in pixels.
    pub height: u32,
    /// Samples per pixel of the whole render.
    pub spp: u32,
    /// The tiles, each with the sample indices it holds.
    pub tiles: Vec<(Range<u32>, TileResult)>,
}

/// A hash of everything that decides a render's pixels: the scene as loaded, with the
/// options applied (size, spp, seed, integrator…). Parts of different renders have different
/// fingerprints (FNV-1a over the scene's `Debug` text, streamed: nothing is allocated).
pub fn fingerprint(scene: &alhazen_scene::Scene) -> u64 {
    hash_debug(scene)
}

/// The FNV-1a hash of `value`'s `Debug` form, streamed (no string is built): a fingerprint of
/// plain data.
pub fn hash_debug(value: &impl fmt::Debug) -> u64 {
    let mut h = Fnv::default();
    fmt::write(&mut h, format_args!("{value:?}")).expect("hashing never fails");
    h.0
}

struct Fnv(u64);

impl Default for Fnv {
    fn default() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }
}

impl Fnv {
    fn bytes(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ b as u64).wrapping_mul(0x0100_0000_01b3);
        }
    }
}

impl fmt::Write for Fnv {
    fn write_str(&mut self, s: &str) -> fmt::Result {
        self.bytes(s.as_bytes());
        Ok(())
    }
}

/// Share `i` of `n` of `0..total`: the `n` shares are contiguous, disjoint and cover it.
pub fn share(total: u64, i: u32, n: u32) -> Range<u64> {
    let at = |k: u32| (total as u128 * k as u128 / n.max(1) as u128) as u64;
    at(i)..at(i + 1)
}

/// Pass `i` of `n` of the sample indices `0..spp`: the shares split at multiples of
/// [`SAMPLE_BLOCK`](super::SAMPLE_BLOCK) (so that they merge exactly), and are empty when there
/// are more passes than blocks.
pub fn share_samples(spp: u32, i: u32, n: u32) -> Range<u32> {
    let block = super::SAMPLE_BLOCK;
    let r = share(spp.div_ceil(block) as u64, i, n);
    (r.start as u32 * block).min(spp)..(r.end as u32 * block).min(spp)
}

/// Whether `samples` of `0..spp` starts and ends where sample blocks do (or at `spp`).
fn block_aligned(samples: &Range<u32>, spp: u32) -> bool {
    let at_boundary = |k: u32| k.is_multiple_of(super::SAMPLE_BLOCK) || k == spp;
    at_boundary(samples.start) && at_boundary(samples.end)
}

impl Part {
    /// A part of the film `width × height × spp` holding nothing yet.
    pub fn new(fingerprint: u64, width: u32, height: u32, spp: u32) -> Self {
        Self { fingerprint, width, height, spp, tiles: Vec::new() }
    }

    /// Adds a rendered tile holding samples `samples`; its exact sums are dropped when it holds
    /// every sample (its pixels are then final).
    pub fn push(&mut self, samples: Range<u32>, mut tile: TileResult) {
        if samples == (0..self.spp) {
            tile.sums = None;
        }
        self.tiles.push((samples, tile));
    }

    /// The file's bytes.
    pub fn encode(&self) -> Vec<u8> {
        let mut out = Vec::new();
        out.extend_from_slice(MAGIC);
        for v in [VERSION, 0, 0, self.width, self.height, self.spp, self.tiles.len() as u32] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out[12..20].copy_from_slice(&self.fingerprint.to_le_bytes());
        for (samples, t) in &self.tiles {
            for v in [t.index as u32, samples.start, samples.end] {
                out.extend_from_slice(&v.to_le_bytes());
            }
            out.push(t.sums.is_some() as u8);
            t.pixels.iter().flatten().for_each(|c| out.extend_from_slice(&c.to_le_bytes()));
            if let Some(s) = &t.sums {
                out.extend(s.heads.iter().flatten());
                out.extend_from_slice(&(s.digits.len() as u32).to_le_bytes());
                s.digits.iter().for_each(|d| out.extend_from_slice(&d.to_le_bytes()));
            }
        }
        let mut h = Fnv::default();
        h.bytes(&out);
        out.extend_from_slice(&h.0.to_le_bytes());
        out
    }

    /// Reads a part from its file's bytes, or says what is wrong with them.
    pub fn decode(bytes: &[u8]) -> Result<Self, String> {
        if bytes.len() < 8 || &bytes[..8] != MAGIC {
            return Err("not a film part (it does not begin with ALHZFILM)".into());
        }
        let (body, hash) = bytes.split_at(bytes.len().saturating_sub(8).max(8));
        let mut h = Fnv::default();
        h.bytes(body);
        if hash.len() != 8 || h.0.to_le_bytes() != hash {
            return Err("the file is truncated or damaged (its checksum does not match)".into());
        }
        let mut r = Reader { bytes: body, at: 8 };
        let version = r.u32()?;
        if version != VERSION {
            return Err(format!("film part format version {version}; this alhazen reads version {VERSION}"));
        }
        let fingerprint = r.u64()?;
        let (width, height, spp, count) = (r.u32()?, r.u32()?, r.u32()?, r.u32()?);
        if width == 0 || height == 0 || spp == 0 || width as u64 * height as u64 > alhazen_scene::MAX_PIXELS {
            return Err(format!("a film of {width}×{height} pixels and {spp} spp is not one alhazen renders"));
        }
        let all = tiles(width, height);
        let mut part = Part::new(fingerprint, width, height, spp);
        for _ in 0..count {
            let (index, start, end) = (r.u32()? as usize, r.u32()?, r.u32()?);
            let Some(tile) = all.get(index) else {
                return Err(format!("tile {index} does not exist in a {width}×{height} film"));
            };
            if start >= end || end > spp || !block_aligned(&(start..end), spp) {
                return Err(format!("tile {index} holds samples {start}..{end} of {spp}"));
            }
            let with_sums = r.u8()? != 0;
            let pixels: Vec<[f32; 3]> =
                (0..tile.len()).map(|_| Ok([r.f32()?, r.f32()?, r.f32()?])).collect::<Result<_, String>>()?;
            if pixels.iter().flatten().any(|c: &f32| !c.is_finite()) {
                return Err(format!("tile {index} has a pixel that is not finite"));
            }
            let sums = if with_sums { Some(read_sums(&mut r, tile.len())?) } else { None };
            if sums.is_none() && (start..end) != (0..spp) {
                return Err(format!("tile {index} holds samples {start}..{end} of {spp} without their sums"));
            }
            part.tiles.push((start..end, TileResult { index, pixels, sums, unusable_samples: 0, clamped_pixels: 0 }));
        }
        if r.at != body.len() {
            return Err(format!("{} bytes follow the last tile", body.len() - r.at));
        }
        Ok(part)
    }
}

fn read_sums(r: &mut Reader, pixels: usize) -> Result<PixelSums, String> {
    let heads: Vec<[u8; 3]> = r.take(9 * pixels)?.chunks_exact(3).map(|h| [h[0], h[1], h[2]]).collect();
    let count = r.u32()? as usize;
    if heads.iter().map(|h| h[2] as usize).sum::<usize>() != count {
        return Err("the exact sums' digit counts disagree".into());
    }
    let digits = r.take(count.checked_mul(4).ok_or("too many digits")?)?;
    let sums = PixelSums {
        heads,
        digits: digits.chunks_exact(4).map(|b| u32::from_le_bytes(b.try_into().expect("four bytes"))).collect(),
    };
    for (channel, head) in sums.channels().zip(&sums.heads) {
        if head[0] > 1 {
            return Err("an exact sum's sign is neither 0 nor 1".into());
        }
        channel.check()?;
    }
    Ok(sums)
}

struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], String> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.bytes.len()).ok_or("the file ends too soon")?;
        let s = &self.bytes[self.at..end];
        self.at = end;
        Ok(s)
    }
    fn u8(&mut self) -> Result<u8, String> {
        Ok(self.take(1)?[0])
    }
    fn u32(&mut self) -> Result<u32, String> {
        Ok(u32::from_le_bytes(self.take(4)?.try_into().expect("four bytes")))
    }
    fn u64(&mut self) -> Result<u64, String> {
        Ok(u64::from_le_bytes(self.take(8)?.try_into().expect("eight bytes")))
    }
    fn f32(&mut self) -> Result<f32, String> {
        Ok(f32::from_le_bytes(self.take(4)?.try_into().expect("four bytes")))
    }
}

/// Why parts do not merge into an image.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MergeError {
    /// The part at fault (an index into the parts given), when one is.
    pub part: Option<usize>,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for MergeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for MergeError {}

/// A tile's samples in one part.
type Piece<'a> = (Range<u32>, &'a TileResult);

/// The tiles that hold samples `0..spp` of every tile of the film, in order; each list is one
/// tile's parts sorted by first sample. The same tile and samples twice (a checkpoint beside
/// the part that finished it) counts once.
fn coverage(parts: &[Part]) -> Result<Vec<Vec<Piece<'_>>>, MergeError> {
    let Some(first) = parts.first() else {
        return Err(MergeError { part: None, message: "no parts to merge".into() });
    };
    let mut by_tile: Vec<Vec<Piece>> = vec![Vec::new(); tiles(first.width, first.height).len()];
    for (k, p) in parts.iter().enumerate() {
        let differs = if p.fingerprint != first.fingerprint {
            Some("another scene or other options (size, spp, seed, integrator…)")
        } else if (p.width, p.height, p.spp) != (first.width, first.height, first.spp) {
            Some("another film size or spp")
        } else {
            None
        };
        if let Some(what) = differs {
            return Err(MergeError {
                part: Some(k),
                message: format!("it was rendered with {what} than the first part"),
            });
        }
        p.tiles.iter().for_each(|(s, t)| by_tile[t.index].push((s.clone(), t)));
    }
    let absent: Vec<usize> = (0..by_tile.len()).filter(|&i| by_tile[i].is_empty()).collect();
    if !absent.is_empty() {
        let message = format!("{} of {} tiles are in no part: {}", absent.len(), by_tile.len(), spans(&absent));
        return Err(MergeError { part: None, message });
    }
    for (index, list) in by_tile.iter_mut().enumerate() {
        list.sort_by_key(|(s, _)| (s.start, s.end));
        list.dedup_by(|b, a| a.0 == b.0);
        let mut next = 0;
        for (s, _) in list.iter() {
            if s.start != next {
                let message = if s.start < next {
                    format!("tile {index} has samples {}..{} in two parts that split them differently", s.start, next)
                } else {
                    format!("tile {index} lacks samples {next}..{}", s.start)
                };
                return Err(MergeError { part: None, message });
            }
            next = s.end;
        }
        if next != first.spp {
            let message = format!("tile {index} lacks samples {next}..{}", first.spp);
            return Err(MergeError { part: None, message });
        }
    }
    Ok(by_tile)
}

/// Increasing indices as runs: "3, 5–9, 12".
fn spans(indices: &[usize]) -> String {
    let mut runs: Vec<(usize, usize)> = Vec::new();
    for &i in indices {
        match runs.last_mut() {
            Some((_, end)) if *end + 1 == i => *end = i,
            _ => runs.push((i, i)),
        }
    }
    let text: Vec<String> =
        runs.iter().map(|&(a, b)| if a == b { a.to_string() } else { format!("{a}–{b}") }).collect();
    text.join(", ")
}

/// The image the parts make together. They must come from one render (same fingerprint and
/// film) and hold every sample of every tile exactly once; the image is then bit for bit the
/// one rendered at once.
pub fn merge(parts: &[Part]) -> Result<Image, MergeError> {
    let by_tile = coverage(parts)?;
    let (w, h, spp) = (parts[0].width, parts[0].height, parts[0].spp);
    let merged: Vec<Vec<[f32; 3]>> = by_tile.iter().map(|list| merge_tile(list, spp)).collect();
    Ok(super::assemble(w, h, merged.iter().enumerate().map(|(i, p)| (i, p.as_slice()))))
}

impl Part {
    /// The image of a part that holds every sample of every tile (a whole render, or a
    /// resumed one), taking its tiles' pixels one by one: the peak memory is one image, not two.
    pub fn into_image(mut self) -> Result<Image, MergeError> {
        coverage(std::slice::from_ref(&self))?;
        let (w, h) = (self.width, self.height);
        let all = tiles(w, h);
        let mut image = Image { width: w, height: h, pixels: vec![[0f32; 3]; (w as usize) * (h as usize)] };
        while let Some((_, tile)) = self.tiles.pop() {
            super::place(&mut image, all[tile.index], &tile.pixels);
            if self.tiles.len() * 4 < self.tiles.capacity() {
                self.tiles.shrink_to_fit();
            }
        }
        Ok(image)
    }
}

/// One tile's pixels from its parts (which cover `0..spp`).
fn merge_tile(list: &[Piece], spp: u32) -> Vec<[f32; 3]> {
    if let [(_, whole)] = list {
        return whole.pixels.clone();
    }
    let mut channels: Vec<_> =
        list.iter().map(|(_, t)| t.sums.as_ref().expect("checked on reading").channels()).collect();
    let mut sums: [ExactSum; 3] = Default::default();
    (0..list[0].1.pixels.len())
        .map(|_| {
            sums.iter_mut().for_each(ExactSum::clear);
            for part in channels.iter_mut() {
                for s in sums.iter_mut() {
                    s.add_digits(&part.next().expect("three sums per pixel"));
                }
            }
            super::pixel_value(&mut sums, spp as u64)
        })
        .collect()
}
