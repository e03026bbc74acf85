//! Image files: PNG (8-bit sRGB through the course's transfer function), OpenEXR (linear, half
//! or float) and PFM (linear float). On the way out colours are brought into the file's gamut by
//! desaturation, never clipped ([`alhazen_math::color::desaturate_into_gamut`]): negative
//! components (spectral colours beyond sRGB) in every format, components above 1 in PNG, after
//! the [`Display`]'s exposure and tone mapping. Every file is written to a temporary file in the target
//! directory and renamed into place, so a reader never sees half an image and an existing file
//! is only replaced by a complete one.

use crate::film::Image;
use alhazen_math::Vec3;
use alhazen_math::color::{Tonemap, desaturate_into_gamut, srgb_encode};
use std::io::{self, BufWriter, Write};
use std::path::Path;

/// Output file formats.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// 8-bit sRGB PNG.
    Png,
    /// OpenEXR with 16-bit half floats.
    ExrHalf,
    /// OpenEXR with 32-bit floats.
    ExrFloat,
    /// Portable float map.
    Pfm,
}

impl Format {
    /// The format for a file name's extension (`.exr` means float unless `half`).
    pub fn from_path(path: &Path, half: bool) -> Option<Self> {
        match path.extension()?.to_str()?.to_ascii_lowercase().as_str() {
            "png" => Some(Self::Png),
            "exr" if half => Some(Self::ExrHalf),
            "exr" => Some(Self::ExrFloat),
            "pfm" => Some(Self::Pfm),
            _ => None,
        }
    }
}

/// How radiance becomes a picture: an exposure in stops (all formats) and a tone mapping (8-bit
/// formats only; EXR and PFM stay linear radiance).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Display {
    /// Radiance is scaled by `2^exposure`.
    pub exposure: f64,
    /// Tone mapping, for 8-bit formats.
    pub tonemap: Tonemap,
}

impl Display {
    /// Pixel `p` of a linear (EXR, PFM) file: exposed, negatives desaturated away.
    pub fn linear(&self, p: [f32; 3]) -> [f32; 3] {
        let c = desaturate_into_gamut(self.exposed(p), None);
        [c.x as f32, c.y as f32, c.z as f32]
    }

    /// Pixel `p` on a display, in `[0, 1]`: exposed, tone mapped, desaturated into the gamut.
    pub fn shown(&self, p: [f32; 3]) -> Vec3 {
        desaturate_into_gamut(self.tonemap.apply(self.exposed(p)), Some(1.0))
    }

    fn exposed(&self, p: [f32; 3]) -> Vec3 {
        let c = Vec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
        if self.exposure == 0.0 { c } else { c * self.exposure.exp2() }
    }

    /// 8-bit sRGB bytes of `img`, row-major RGB.
    pub fn srgb8(&self, img: &Image) -> Vec<u8> {
        let byte = |x: f64| (srgb_encode(x) * 255.0 + 0.5) as u8;
        img.pixels.iter().flat_map(|&p| self.shown(p).to_array().map(byte)).collect()
    }
}

/// Writes `img` to `path` atomically, as the default [`Display`] shows it.
pub fn write_image(img: &Image, path: &Path, format: Format) -> io::Result<()> {
    PendingFile::create(path)?.write_image(img, format, Display::default())
}

/// Creates `path` through a temporary file in the same directory, filled by `fill`, synced and
/// renamed into place: readers see the old file or the complete new one, never a part.
pub fn write_atomically(path: &Path, fill: impl FnOnce(&mut std::fs::File) -> io::Result<()>) -> io::Result<()> {
    PendingFile::create(path)?.finish(fill)
}

/// An output file opened before the work that fills it: its temporary file already exists
/// beside `path`, so an unwritable place is found before a render, not after. Dropped
/// unfinished, it leaves nothing behind (and `path` untouched).
pub struct PendingFile {
    tmp: tempfile::NamedTempFile,
    path: std::path::PathBuf,
}

/// An I/O error without the temporary file's name (messages name the user's path): tempfile
/// appends ` at path "…"` to the system's message.
fn plain(e: io::Error) -> io::Error {
    if let Some(code) = e.raw_os_error() {
        return io::Error::from_raw_os_error(code);
    }
    let text = e.to_string();
    let system = text.split(" at path ").next().unwrap_or(&text).to_string();
    io::Error::new(e.kind(), system)
}

impl PendingFile {
    /// Creates the temporary file for `path`.
    pub fn create(path: &Path) -> io::Result<Self> {
        let dir = match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        let tmp = tempfile::Builder::new().prefix(".alhazen-").suffix(".part").tempfile_in(dir).map_err(plain)?;
        Ok(Self { tmp, path: path.to_path_buf() })
    }

    /// Encodes `img` as `format`, as `display` shows it, and renames it into place.
    pub fn write_image(self, img: &Image, format: Format, display: Display) -> io::Result<()> {
        // Pixels are mapped as they are encoded: no second copy of a large image.
        self.finish(|file| match format {
            Format::Png => encode_png(img, file, &display),
            Format::ExrHalf | Format::ExrFloat => encode_exr(img, file, format == Format::ExrHalf, &display),
            Format::Pfm => encode_pfm(img, &mut BufWriter::new(file), &display),
        })
    }

    /// Fills the file by `fill`, syncs it and renames it into place.
    pub fn finish(mut self, fill: impl FnOnce(&mut std::fs::File) -> io::Result<()>) -> io::Result<()> {
        fill(self.tmp.as_file_mut())?;
        self.tmp.as_file().sync_all().map_err(plain)?;
        set_readable_permissions(self.tmp.path(), &self.path).map_err(plain)?;
        self.tmp.persist(&self.path).map_err(|e| plain(e.error))?;
        Ok(())
    }
}

/// Temporary files are private (0600); give the image the permissions of the file it
/// replaces, or the usual 0644 for a new one.
#[cfg(unix)]
fn set_readable_permissions(tmp: &Path, target: &Path) -> io::Result<()> {
    use std::os::unix::fs::PermissionsExt;
    let perms =
        std::fs::metadata(target).map(|m| m.permissions()).unwrap_or_else(|_| std::fs::Permissions::from_mode(0o644));
    std::fs::set_permissions(tmp, perms)
}

#[cfg(not(unix))]
fn set_readable_permissions(_tmp: &Path, _target: &Path) -> io::Result<()> {
    Ok(())
}

/// 8-bit sRGB bytes, row-major RGB, as the default [`Display`] shows `img`.
pub fn to_srgb8(img: &Image) -> Vec<u8> {
    Display::default().srgb8(img)
}

fn encode_png(img: &Image, out: &mut std::fs::File, display: &Display) -> io::Result<()> {
    use image::ImageEncoder;
    use image::codecs::png::{CompressionType, FilterType, PngEncoder};
    // Fast deflate: a render's PNG is written once and read by people, not shipped.
    let enc = PngEncoder::new_with_quality(BufWriter::new(out), CompressionType::Fast, FilterType::Adaptive);
    enc.write_image(&display.srgb8(img), img.width, img.height, image::ExtendedColorType::Rgb8)
        .map_err(io::Error::other)
}

fn encode_exr(img: &Image, out: &mut std::fs::File, half: bool, display: &Display) -> io::Result<()> {
    use exr::prelude::*;
    let (w, h) = (img.width as usize, img.height as usize);
    let px = |x: usize, y: usize| display.linear(img.pixels[y * w + x]);
    let result = if half {
        let channels = SpecificChannels::rgb(|p: Vec2<usize>| {
            let c = px(p.x(), p.y());
            (f16::from_f32(c[0]), f16::from_f32(c[1]), f16::from_f32(c[2]))
        });
        Image::from_channels((w, h), channels).write().non_parallel().to_buffered(BufWriter::new(out))
    } else {
        let channels = SpecificChannels::rgb(|p: Vec2<usize>| {
            let c = px(p.x(), p.y());
            (c[0], c[1], c[2])
        });
        Image::from_channels((w, h), channels).write().non_parallel().to_buffered(BufWriter::new(out))
    };
    result.map_err(io::Error::other)
}

/// PFM: `PF`, size, a negative scale for little-endian, then rows bottom to top.
fn encode_pfm(img: &Image, out: &mut impl Write, display: &Display) -> io::Result<()> {
    write!(out, "PF\n{} {}\n-1.0\n", img.width, img.height)?;
    for y in (0..img.height as usize).rev() {
        let row = &img.pixels[y * img.width as usize..(y + 1) * img.width as usize];
        for &p in row {
            for c in display.linear(p) {
                out.write_all(&c.to_le_bytes())?;
            }
        }
    }
    out.flush()
}

/// Reads a PFM written by [`write_image`] (for tests and image comparison tools).
pub fn read_pfm(bytes: &[u8]) -> Option<Image> {
    let mut fields = Vec::new();
    let mut pos = 0;
    while fields.len() < 4 {
        while pos < bytes.len() && bytes[pos].is_ascii_whitespace() {
            pos += 1;
        }
        let start = pos;
        while pos < bytes.len() && !bytes[pos].is_ascii_whitespace() {
            pos += 1;
        }
        fields.push(std::str::from_utf8(&bytes[start..pos]).ok()?.to_string());
    }
    pos += 1;
    let (w, h): (u32, u32) = (fields[1].parse().ok()?, fields[2].parse().ok()?);
    if fields[0] != "PF" || fields[3].parse::<f32>().ok()? >= 0.0 {
        return None;
    }
    let data = bytes.get(pos..pos + (w * h * 12) as usize)?;
    let mut pixels = vec![[0f32; 3]; (w * h) as usize];
    for (i, c) in data.chunks_exact(12).enumerate() {
        let (x, y) = (i as u32 % w, h - 1 - i as u32 / w);
        let f = |k: usize| f32::from_le_bytes([c[k], c[k + 1], c[k + 2], c[k + 3]]);
        pixels[(y * w + x) as usize] = [f(0), f(4), f(8)];
    }
    Some(Image { width: w, height: h, pixels })
}
