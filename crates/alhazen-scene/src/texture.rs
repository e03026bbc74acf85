//! Evaluation of surface colour textures: solid, checker, image (bilinear, repeating).

use crate::{ImageData, Texture, Wrap};
use alhazen_math::{Mat3, Vec2, Vec3, elementary};

/// The colour of `tex` at texture coordinates `uv`.
pub fn eval(tex: &Texture, uv: Vec2, images: &[std::sync::Arc<ImageData>]) -> Vec3 {
    match tex {
        Texture::Solid(c) => *c,
        Texture::Checker { even, odd, size } => {
            // The squares' parity in doubles: a tiny `size` makes indices beyond any integer type.
            let parity = |t: f64| (t / size).floor().rem_euclid(2.0);
            if parity(uv.x) == parity(uv.y) { *even } else { *odd }
        }
        Texture::Image { image, scale, offset, rotation: 0.0 } if *offset == Vec2::ZERO => {
            bilinear(&images[*image], uv * *scale)
        }
        Texture::Image { image, scale, offset, rotation: 0.0 } => bilinear(&images[*image], uv * *scale + *offset),
        Texture::Image { image, scale, offset, rotation } => {
            let (sin, cos) = alhazen_math::sin_cos_turns(rotation / 360.0);
            let p = uv * *scale;
            bilinear(&images[*image], Vec2::new(cos * p.x - sin * p.y, sin * p.x + cos * p.y) + *offset)
        }
    }
}

/// The fraction of a cut-out surface ([`crate::Alpha`]) present at texture coordinates `uv`:
/// its coverage texture's first channel.
pub fn coverage(alpha: &crate::Alpha, uv: Vec2, images: &[std::sync::Arc<ImageData>]) -> f64 {
    eval(&alpha.coverage, uv, images).x
}

/// The mean colour of `tex` over its texture space: an image's pixels' mean, a checker's two
/// colours' mean.
pub fn mean(tex: &Texture, images: &[std::sync::Arc<ImageData>]) -> Vec3 {
    match tex {
        Texture::Solid(c) => *c,
        Texture::Checker { even, odd, .. } => (*even + *odd) * 0.5,
        Texture::Image { image, .. } => image_mean(&images[*image]),
    }
}

/// The mean of an image's pixels.
pub fn image_mean(img: &ImageData) -> Vec3 {
    let sum = img.texels().fold(Vec3::ZERO, |s, p| s + Vec3::new(p[0] as f64, p[1] as f64, p[2] as f64));
    sum / img.texel_count().max(1) as f64
}

/// Equirectangular coordinates of direction `dir` (unit), by our own `atan2` and `acos`
/// (calls the compiler can inline and vectorise): `u` the azimuth from `−z` towards
/// `+x` plus `rotation`, over 2π; `v` the angle from straight up (`+y`), over π.
#[inline(always)]
pub fn equirect_uv(dir: Vec3, rotation: f64) -> Vec2 {
    use std::f64::consts::PI;
    let phi = elementary::atan2(dir.x, -dir.z) + rotation;
    let u = wrap_unit(phi / (2.0 * PI));
    let v = elementary::acos(dir.y.clamp(-1.0, 1.0)) / PI;
    Vec2::new(u.min(1.0 - 1e-16), v.min(1.0 - 1e-16))
}

/// The rotation taking `+y` to unit vector `up` by the least turn (about their common normal;
/// a half turn about `+x` for `−y`): the frame of an environment map whose up axis is `up`.
/// `None` for `+y` itself, where the map's directions are the world's.
pub fn up_frame(up: Vec3) -> Option<Mat3> {
    let axis = Vec3::Y.cross(up);
    let sin = axis.length();
    match (up == Vec3::Y, sin > 0.0) {
        (true, _) => None,
        (false, true) => Some(Mat3::from_axis_angle(axis / sin, sin.atan2(up.y))),
        (false, false) => Some(Mat3::from_rotation_x(std::f64::consts::PI)),
    }
}

/// World direction `dir` in the axes of a map of frame `frame` ([`up_frame`]).
#[inline(always)]
pub fn into_map(frame: Option<Mat3>, dir: Vec3) -> Vec3 {
    frame.map_or(dir, |f| f.transpose() * dir)
}

/// The radiance of an equirectangular image seen in direction `dir`: interpolated bilinearly
/// between the centres of the four texels around it ([`equirect_taps`]), as Mitsuba and Cycles
/// read a map.
pub fn equirect_radiance(img: &ImageData, dir: Vec3, rotation: f64) -> Vec3 {
    let taps = equirect_taps(equirect_uv(dir, rotation), img.width as usize, img.height as usize);
    taps.iter().fold(Vec3::ZERO, |sum, &(i, w)| {
        let p = img.texel(i);
        sum + Vec3::new(p[0] as f64, p[1] as f64, p[2] as f64) * w
    })
}

/// The four texels (indices into a `width × height` image, rows from the top) whose centres
/// surround `uv` ([`equirect_uv`]'s coordinates) and their bilinear weights: wrapping round in
/// `u`, the first and last rows' centres standing for the poles. The weights sum to 1.
#[inline(always)]
pub fn equirect_taps(uv: Vec2, width: usize, height: usize) -> [(usize, f64); 4] {
    let x = uv.x * width as f64 - 0.5;
    let y = (uv.y * height as f64 - 0.5).clamp(0.0, (height - 1) as f64);
    // `x` lies in [−½, width − ½): its floor is −1 at least.
    let left = if x < 0.0 { width - 1 } else { (x as usize).min(width - 1) };
    let fx = if x < 0.0 { x + 1.0 } else { x - left as f64 };
    let right = if left + 1 == width { 0 } else { left + 1 };
    let top = (y as usize).min(height - 1);
    let fy = y - top as f64;
    let bottom = (top + 1).min(height - 1);
    [
        (top * width + left, (1.0 - fx) * (1.0 - fy)),
        (top * width + right, fx * (1.0 - fy)),
        (bottom * width + left, (1.0 - fx) * fy),
        (bottom * width + right, fx * fy),
    ]
}

/// `x.rem_euclid(1.0)`, bit for bit, without the call to `fmod` it makes where `x` lies in
/// `(−1, 2)` — where texture coordinates and azimuths almost always do. There the remainder is
/// `x`, `x + 1` (the one rounding `rem_euclid` makes too) or `x − 1` (exact).
#[inline(always)]
fn wrap_unit(x: f64) -> f64 {
    if (0.0..1.0).contains(&x) {
        x
    } else if x > -1.0 && x < 0.0 {
        x + 1.0
    } else if (1.0..2.0).contains(&x) {
        x - 1.0
    } else {
        // `x − ⌊x⌋` is `rem_euclid`'s value (exact but for the one rounding of `x % 1 + 1`
        // below zero, which this makes too; zero keeps `x`'s sign) without its call to `fmod`,
        // so loops vectorise.
        let r = x - x.floor();
        if r == 0.0 { r.copysign(x) } else { r }
    }
}

/// `x.floor()` for `|x| < 2⁶³` (NaN gives ±0), without the call to `floor` that baseline
/// x86-64 makes of it: truncated, one less where that went up, the sign `x`'s (for −0).
#[inline(always)]
fn floor_small(x: f64) -> f64 {
    let t = x as i64 as f64;
    (if t > x { t - 1.0 } else { t }).copysign(x)
}

fn bilinear(img: &ImageData, uv: Vec2) -> Vec3 {
    if img.wrap != [Wrap::Repeat; 2] {
        return bilinear_wrapped(img, uv);
    }
    let (w, h) = (img.width as i64, img.height as i64);
    // v = 0 is the bottom row of the image.
    let x = wrap_unit(uv.x) * w as f64 - 0.5;
    let y = (1.0 - wrap_unit(uv.y)) * h as f64 - 0.5;
    let (x0, y0) = (floor_small(x), floor_small(y));
    let (fx, fy) = (x - x0, y - y0);
    // The coordinates lie in [−1, size]: wrapped by a comparison, not an integer division.
    let wrap = |k: i64, size: i64| {
        if k < 0 {
            k + size
        } else if k >= size {
            k - size
        } else {
            k
        }
    };
    let (i, j) = (x0 as i64, y0 as i64);
    let (left, right) = (wrap(i, w), wrap(i + 1, w));
    let (upper, lower) = (wrap(j, h) * w, wrap(j + 1, h) * w);
    let [a, b, c, d] = img.texels_at([upper + left, upper + right, lower + left, lower + right].map(|k| k as usize));
    let v = |p: [f32; 3]| Vec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
    let top = v(a) * (1.0 - fx) + v(b) * fx;
    let bottom = v(c) * (1.0 - fx) + v(d) * fx;
    top * (1.0 - fy) + bottom * fy
}

/// [`bilinear`] for an image that does not repeat along some axis: each axis's two texels and
/// the weight of the second, by its [`Wrap`] (`None`: a black texel beyond the image).
fn bilinear_wrapped(img: &ImageData, uv: Vec2) -> Vec3 {
    // Along `v` the image's rows run down from `v = 1`.
    let ([left, right], fx) = taps(uv.x, img.width as i64, img.wrap[0]);
    let ([upper, lower], fy) = taps(1.0 - uv.y, img.height as i64, img.wrap[1]);
    let texel = |i: Option<i64>, j: Option<i64>| match (i, j) {
        (Some(i), Some(j)) => {
            let p = img.texel((j * img.width as i64 + i) as usize);
            Vec3::new(p[0] as f64, p[1] as f64, p[2] as f64)
        }
        _ => Vec3::ZERO,
    };
    let top = texel(left, upper) * (1.0 - fx) + texel(right, upper) * fx;
    let bottom = texel(left, lower) * (1.0 - fx) + texel(right, lower) * fx;
    top * (1.0 - fy) + bottom * fy
}

/// The two texels (of `size`) a coordinate `t` (the image spanning `[0, 1]`, texel centres at
/// `(k + ½) / size`) falls between, and the weight of the second.
fn taps(t: f64, size: i64, wrap: Wrap) -> ([Option<i64>; 2], f64) {
    let t = match wrap {
        Wrap::Repeat => wrap_unit(t),
        Wrap::Mirror => {
            let r = t.rem_euclid(2.0);
            if r > 1.0 { 2.0 - r } else { r }
        }
        // Beyond the image by more than a texel, everything is the edge's (or black): kept
        // small, so the texel index is a small integer.
        Wrap::Clamp | Wrap::Black => t.clamp(-1.0, 2.0),
    };
    let x = t * size as f64 - 0.5;
    let x0 = floor_small(x);
    let k = x0 as i64;
    let index = |k: i64| match wrap {
        Wrap::Repeat => Some(k.rem_euclid(size)),
        // Mirrored, the texel beyond an edge is the edge's own.
        Wrap::Clamp | Wrap::Mirror => Some(k.clamp(0, size - 1)),
        Wrap::Black => (0..size).contains(&k).then_some(k),
    };
    ([index(k), index(k + 1)], x - x0)
}

#[cfg(test)]
mod tests {
    use super::*;

    proptest::proptest! {
        /// Lookups read the pixels' own bits whether the image keeps codes (at most 256
        /// distinct values in each channel, in any order, NaN and −0 included) or not (more),
        /// and so do its scaled channels.
        #[test]
        fn texels_are_the_pixels(
            values in proptest::collection::vec(proptest::prelude::any::<f32>(), 1..600),
            picks in proptest::collection::vec(proptest::prelude::any::<proptest::sample::Index>(), 3..1800),
            factor in proptest::array::uniform3(-4.0..4.0f32),
        ) {
            let n = picks.len() / 3;
            let pixels: Vec<[f32; 3]> =
                (0..n).map(|i| std::array::from_fn(|c| values[picks[3 * i + c].index(values.len())])).collect();
            let distinct = |c: usize| pixels.iter().map(|p| p[c].to_bits()).collect::<std::collections::HashSet<_>>().len();
            let img = ImageData::new(n as u32, 1, pixels.clone());
            proptest::prop_assert_eq!(img.has_codes(), (0..3).all(|c| distinct(c) <= 256));
            let scaled = img.channels_scaled(factor);
            for (i, p) in pixels.iter().enumerate() {
                proptest::prop_assert_eq!(img.texel(i).map(f32::to_bits), p.map(f32::to_bits));
                let want: [f32; 3] = std::array::from_fn(|c| p[c] * factor[c]);
                proptest::prop_assert_eq!(scaled.texel(i).map(f32::to_bits), want.map(f32::to_bits));
            }
            proptest::prop_assert_eq!(img.texels().count(), n);
        }

        /// An image turned upside down keeps its codes and reads, texel by texel, as the image
        /// of its reversed rows made afresh.
        #[test]
        fn rows_reversed_is_the_image_of_the_reversed_rows(
            codes in proptest::collection::vec(proptest::prelude::any::<[u8; 3]>(), 1..60),
            width in 1u32..7,
            coded in proptest::prelude::any::<bool>(),
        ) {
            let rows = codes.len() / width as usize;
            proptest::prop_assume!(rows > 0);
            let codes = &codes[..rows * width as usize];
            let table: [f32; 256] = std::array::from_fn(|k| k as f32 * 0.25 - 3.0);
            let img = if coded {
                ImageData::from_codes(width, rows as u32, table, codes.to_vec())
            } else {
                ImageData::new(width, rows as u32, codes.iter().map(|c| c.map(|k| table[k as usize] + 0.5)).collect())
            };
            let pixels: Vec<[f32; 3]> = img.texels().collect();
            let reversed: Vec<[f32; 3]> = pixels.chunks_exact(width as usize).rev().flatten().copied().collect();
            let fresh = ImageData::new(width, rows as u32, reversed);
            let turned = img.clone().rows_reversed();
            proptest::prop_assert_eq!(&turned, &fresh);
            proptest::prop_assert_eq!(turned.has_codes(), img.has_codes());
            for i in 0..codes.len() {
                proptest::prop_assert_eq!(turned.texel(i).map(f32::to_bits), fresh.texel(i).map(f32::to_bits));
            }
        }

        /// `wrap_unit` is `rem_euclid(1.0)` to the bit, near the unit interval and far from it.
        #[test]
        fn wrap_unit_is_rem_euclid(x in -3.0..3.0f64, far in -1e300..1e300f64, tiny in -1e-300..1e-300f64) {
            let edges = [-2.0, -1.0, -0.0, 0.0, 1.0, 2.0, f64::EPSILON / 4.0, -f64::EPSILON / 4.0, 1.0 - f64::EPSILON];
            for x in [x, far, tiny, f64::NAN, f64::INFINITY].into_iter().chain(edges) {
                let (a, b) = (wrap_unit(x), x.rem_euclid(1.0));
                proptest::prop_assert!(a.to_bits() == b.to_bits() || a.is_nan() && b.is_nan(), "{x}: {a} vs {b}");
            }
        }

        /// The floor without a call is the floor, on the texture coordinates' range and its
        /// edges (integers, just below and above them, ±0).
        #[test]
        fn floor_small_is_floor(x in -1e15..1e15f64, k in -5000i64..5000) {
            let k = k as f64;
            for x in [x, k, k.next_down(), k.next_up(), k + 0.5, -0.0, 0.0] {
                proptest::prop_assert_eq!(floor_small(x).to_bits(), x.floor().to_bits(), "{}", x);
            }
        }

        /// Wrapping by comparison reads the texels wrapping by `rem_euclid` reads, anywhere:
        /// negative, on the edges, far away.
        #[test]
        fn bilinear_wraps_like_rem_euclid(u in -1e6..1e6f64, v in -1e6..1e6f64, edge in 0usize..4) {
            let img = ImageData::new(5, 3, (0..15).map(|i| [i as f32, (i * i) as f32, 1.0]).collect());
            let uv = match edge { 0 => Vec2::new(u, v), 1 => Vec2::new(-1e-20, v), 2 => Vec2::new(u, 1.0), _ => Vec2::new(u.fract(), v.fract()) };
            let (w, h) = (5i64, 3i64);
            let x = uv.x.rem_euclid(1.0) * w as f64 - 0.5;
            let y = (1.0 - uv.y.rem_euclid(1.0)) * h as f64 - 0.5;
            let (x0, y0) = (x.floor(), y.floor());
            let (fx, fy) = (x - x0, y - y0);
            let px = |i: i64, j: i64| {
                let p = img.texel((j.rem_euclid(h) * w + i.rem_euclid(w)) as usize);
                Vec3::new(p[0] as f64, p[1] as f64, p[2] as f64)
            };
            let (i, j) = (x0 as i64, y0 as i64);
            let top = px(i, j) * (1.0 - fx) + px(i + 1, j) * fx;
            let bottom = px(i, j + 1) * (1.0 - fx) + px(i + 1, j + 1) * fx;
            proptest::prop_assert_eq!(bilinear(&img, uv), top * (1.0 - fy) + bottom * fy);
        }
    }

    #[test]
    fn checker_alternates_with_unit_squares() {
        let t = Texture::Checker { even: Vec3::ONE, odd: Vec3::ZERO, size: 1.0 };
        assert_eq!(eval(&t, Vec2::new(0.5, 0.5), &[]), Vec3::ONE);
        assert_eq!(eval(&t, Vec2::new(1.5, 0.5), &[]), Vec3::ZERO);
        assert_eq!(eval(&t, Vec2::new(-0.5, 0.5), &[]), Vec3::ZERO);
        assert_eq!(eval(&t, Vec2::new(-0.5, -0.5), &[]), Vec3::ONE);
    }

    #[test]
    fn tiny_squares_and_far_coordinates_do_not_overflow() {
        // Found by the fuzzer: `size = 1e-320` overflowed the integer square index.
        let t = Texture::Checker { even: Vec3::ONE, odd: Vec3::ZERO, size: 1e-320 };
        for uv in [Vec2::new(3.0, -7.0), Vec2::new(1e300, 2.5), Vec2::new(-1e300, -1e300)] {
            let c = eval(&t, uv, &[]);
            assert!(c == Vec3::ONE || c == Vec3::ZERO);
        }
        // Where indices fit an integer, the parity is the sum's.
        let t = Texture::Checker { even: Vec3::ONE, odd: Vec3::ZERO, size: 0.3 };
        for (x, y) in [(0.1, 0.7), (-2.9, 4.4), (100.05, -33.3), (7.0, 7.0)] {
            let k = (x / 0.3f64).floor() as i64 + (y / 0.3f64).floor() as i64;
            let want = if k.rem_euclid(2) == 0 { Vec3::ONE } else { Vec3::ZERO };
            assert_eq!(eval(&t, Vec2::new(x, y), &[]), want, "({x}, {y})");
        }
    }

    #[test]
    fn image_lookup_hits_pixel_centres() {
        let img = ImageData::new(2, 1, vec![[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]);
        let t = Texture::Image { image: 0, scale: Vec2::ONE, offset: Vec2::ZERO, rotation: 0.0 };
        let imgs = [std::sync::Arc::new(img)];
        assert_eq!(eval(&t, Vec2::new(0.25, 0.5), &imgs), Vec3::X);
        assert_eq!(eval(&t, Vec2::new(0.75, 0.5), &imgs), Vec3::Z);
    }

    /// Beyond `[0, 1]`, a clamped image keeps its edge texels, a mirrored one turns over, a
    /// black one fades to black within half a texel; inside, every mode reads what the
    /// repeating image reads.
    #[test]
    fn wrap_modes_read_beyond_the_image_as_named() {
        let img = ImageData::new(4, 1, (0..4).map(|i| [i as f32 + 1.0, 0.0, 0.0]).collect());
        let read = |wrap: Wrap, u: f64| {
            let imgs = [std::sync::Arc::new(img.clone().with_wrap([wrap, Wrap::Repeat]))];
            eval(
                &Texture::Image { image: 0, scale: Vec2::ONE, offset: Vec2::ZERO, rotation: 0.0 },
                Vec2::new(u, 0.5),
                &imgs,
            )
            .x
        };
        for u in [0.125, 0.3, 0.5, 0.6, 0.875] {
            for wrap in [Wrap::Clamp, Wrap::Mirror, Wrap::Black] {
                assert_eq!(read(wrap, u), read(Wrap::Repeat, u), "{wrap:?} at {u}");
            }
        }
        // Texel centres at 1/8, 3/8, 5/8, 7/8 hold 1, 2, 3, 4.
        assert_eq!((read(Wrap::Clamp, 1.6), read(Wrap::Clamp, -3.0), read(Wrap::Clamp, 1e300)), (4.0, 1.0, 4.0));
        assert_eq!((read(Wrap::Mirror, 1.125), read(Wrap::Mirror, 1.875), read(Wrap::Mirror, -0.125)), (4.0, 1.0, 1.0));
        assert_eq!((read(Wrap::Black, 1.5), read(Wrap::Black, -0.5)), (0.0, 0.0));
        assert_eq!(read(Wrap::Black, 0.0), 0.5, "half the edge texel, half black");
        assert_eq!(read(Wrap::Repeat, 0.0), 2.5, "half the edge texel, half the other edge's");
    }

    /// A turned image is read where the scaled coordinates turn to, counter-clockwise (a
    /// quarter turn takes `u` to `v`), then shifted.
    #[test]
    fn a_turned_image_is_read_at_the_turned_coordinates() {
        let img = ImageData::new(4, 4, (0..16).map(|i| [i as f32, 0.0, 0.0]).collect());
        let imgs = [std::sync::Arc::new(img)];
        let at = |rotation: f64, uv: Vec2| {
            let t = Texture::Image { image: 0, scale: Vec2::new(0.5, 0.25), offset: Vec2::new(0.1, 0.2), rotation };
            eval(&t, uv, &imgs)
        };
        let plain = |uv: Vec2| {
            eval(&Texture::Image { image: 0, scale: Vec2::ONE, offset: Vec2::ZERO, rotation: 0.0 }, uv, &imgs)
        };
        for uv in [Vec2::new(0.3, 0.7), Vec2::new(1.4, -0.2), Vec2::new(0.05, 0.9)] {
            let p = uv * Vec2::new(0.5, 0.25);
            assert!((at(90.0, uv) - plain(Vec2::new(-p.y, p.x) + Vec2::new(0.1, 0.2))).length() < 1e-9);
            assert!((at(180.0, uv) - plain(-p + Vec2::new(0.1, 0.2))).length() < 1e-9);
            let (s, c) = (30f64.to_radians().sin(), 30f64.to_radians().cos());
            assert!(
                (at(30.0, uv) - plain(Vec2::new(c * p.x - s * p.y, s * p.x + c * p.y) + Vec2::new(0.1, 0.2))).length()
                    < 1e-9
            );
            assert_eq!(at(0.0, uv), plain(p + Vec2::new(0.1, 0.2)));
        }
    }
}

/// `∂p/∂u`, `∂p/∂v` of the linear map taking a triangle's texture coordinates `uv` to its
/// corners `p`; zero when the texture coordinates are degenerate.
pub fn uv_tangents(p: [Vec3; 3], uv: [Vec2; 3]) -> [Vec3; 2] {
    let (d1, d2) = (uv[1] - uv[0], uv[2] - uv[0]);
    let det = d1.x * d2.y - d1.y * d2.x;
    if det == 0.0 {
        return [Vec3::ZERO; 2];
    }
    let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
    [(e1 * d2.y - e2 * d1.y) / det, (e2 * d1.x - e1 * d2.x) / det]
}

/// The bump pattern's value in `[0, 1]` at `uv`.
fn bump_value(b: &crate::BumpPattern, uv: Vec2, images: &[std::sync::Arc<ImageData>]) -> f64 {
    match b {
        crate::BumpPattern::Waves { size } => {
            let k = 2.0 * std::f64::consts::PI / size;
            0.5 + 0.5 * (k * uv.x).sin() * (k * uv.y).sin()
        }
        crate::BumpPattern::Image { image, scale } => {
            alhazen_math::color::luminance(bilinear(&images[*image], uv * *scale)).clamp(0.0, 1.0)
        }
        crate::BumpPattern::NormalMap { .. } => 0.0,
    }
}

/// The normal a tangent-space normal map gives: the texel `2c − 1` in the frame `T` (∂p/∂u
/// made orthogonal to `n`), `B = ±n × T` (on ∂p/∂v's side), `n`; the tangential part scaled by
/// `strength`.
fn mapped_normal(c: Vec3, strength: f64, n: Vec3, pu: Vec3, pv: Vec3) -> Vec3 {
    let t = (pu - n * n.dot(pu)).try_normalize().unwrap_or_else(|| alhazen_math::orthonormal_basis(n).0);
    let b = n.cross(t);
    let b = if b.dot(pv) < 0.0 { -b } else { b };
    let local = c * 2.0 - Vec3::ONE;
    let m = t * (local.x * strength) + b * (local.y * strength) + n * local.z.max(0.0);
    m.try_normalize().unwrap_or(n)
}

/// The normal of the bumped surface `p̂ = p + d(u, v) n` by the course's approximation
/// `Dp̂ ≈ Dp + (Dd) n` (the term `d Dn` neglected): `n̂ ∝ (p_u + d_u n) × (p_v + d_v n)`, turned
/// to `n`'s side. `dpdu`, `dpdv` are the surface's partial derivatives (zero when unknown: then
/// an orthonormal tangent frame of `n` stands in). The gradient of `d` is taken by central
/// differences over a step that follows the pattern's detail. The caller keeps `n` where the
/// viewer would see `n̂` from behind, as the course prescribes.
pub fn bumped_normal(
    bump: &crate::Bump,
    uv: Vec2,
    n: Vec3,
    dpdu: Vec3,
    dpdv: Vec3,
    images: &[std::sync::Arc<ImageData>],
) -> Vec3 {
    let (pu, pv) = if dpdu.cross(dpdv).length_squared() > 0.0 {
        (dpdu, dpdv)
    } else {
        let (s, t) = alhazen_math::orthonormal_basis(n);
        if s.cross(t).dot(n) > 0.0 { (s, t) } else { (t, s) }
    };
    let step = match &bump.pattern {
        crate::BumpPattern::Waves { size } => size * 1e-4,
        crate::BumpPattern::Image { image, scale } => {
            0.5 / (images[*image].width.max(images[*image].height) as f64 * scale.max_element())
        }
        crate::BumpPattern::NormalMap { map } => {
            return mapped_normal(eval(map, uv, images), bump.height, n, pu, pv);
        }
    };
    let d = |du: f64, dv: f64| bump.height * bump_value(&bump.pattern, uv + Vec2::new(du, dv), images);
    let (du, dv) = ((d(step, 0.0) - d(-step, 0.0)) / (2.0 * step), (d(0.0, step) - d(0.0, -step)) / (2.0 * step));
    let m = (pu + n * du).cross(pv + n * dv);
    let m = if m.dot(n) < 0.0 { -m } else { m };
    m.try_normalize().unwrap_or(n)
}

#[cfg(test)]
mod bump_tests {
    use super::*;
    use crate::{Bump, BumpPattern};

    #[test]
    fn bumped_plane_normal_is_the_displaced_surface_normal() {
        // On a plane Dn = 0, so the course's approximation is exact: the normal of the surface
        // z = h·w(x, y) (plane z = 0, u = x, v = y).
        let (h, size) = (0.05, 0.7);
        let bump = Bump { height: h, pattern: BumpPattern::Waves { size } };
        for (x, y) in [(0.1, 0.2), (0.33, -0.4), (1.7, 0.05)] {
            let got = bumped_normal(&bump, Vec2::new(x, y), Vec3::Z, Vec3::X, Vec3::Y, &[]);
            let k = 2.0 * std::f64::consts::PI / size;
            let (gx, gy) = (h * 0.5 * k * (k * x).cos() * (k * y).sin(), h * 0.5 * k * (k * x).sin() * (k * y).cos());
            let want = Vec3::new(-gx, -gy, 1.0).normalize();
            assert!((got - want).length() < 1e-7, "{got} vs {want}");
        }
        // A flat normal map (texel (½, ½, 1)) leaves the normal alone; a tilted texel tilts it
        // towards ∂p/∂u, by its strength.
        let img = |c: [f32; 3]| std::sync::Arc::new(ImageData::new(1, 1, vec![c]));
        let image = Texture::Image { image: 0, scale: Vec2::ONE, offset: Vec2::ZERO, rotation: 0.0 };
        let map = Bump { height: 1.0, pattern: BumpPattern::NormalMap { map: image } };
        let flat = bumped_normal(&map, Vec2::new(0.3, 0.3), Vec3::Z, Vec3::X * 2.0, Vec3::Y, &[img([0.5, 0.5, 1.0])]);
        assert!((flat - Vec3::Z).length() < 1e-12, "{flat}");
        let tilted = bumped_normal(&map, Vec2::ZERO, Vec3::Z, Vec3::X, -Vec3::Y, &[img([1.0, 0.5, 0.5])]);
        assert!((tilted - Vec3::X).length() < 1e-12, "{tilted}");
        let half = Bump { height: 0.5, ..map.clone() };
        let mixed = bumped_normal(&half, Vec2::ZERO, Vec3::Z, Vec3::X, Vec3::Y, &[img([0.5, 1.0, 1.0])]);
        assert!((mixed - Vec3::new(0.0, 0.5, 1.0).normalize()).length() < 1e-12, "{mixed}");
        // Zero height leaves the normal alone.
        let flat = Bump { height: 0.0, pattern: BumpPattern::Waves { size } };
        assert_eq!(bumped_normal(&flat, Vec2::new(0.3, 0.3), Vec3::Z, Vec3::X, Vec3::Y, &[]), Vec3::Z);
    }
}
