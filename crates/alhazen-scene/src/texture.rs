//! Evaluation of surface colour textures: solid, checker, image (bilinear, repeating).

use crate::{ImageData, Texture};
use alhazen_math::{Vec2, Vec3};

/// The colour of `tex` at texture coordinates `uv`.
pub fn eval(tex: &Texture, uv: Vec2, images: &[std::sync::Arc<ImageData>]) -> Vec3 {
    match tex {
        Texture::Solid(c) => *c,
        Texture::Checker { even, odd, size } => {
            let k = (uv.x / size).floor() as i64 + (uv.y / size).floor() as i64;
            if k.rem_euclid(2) == 0 { *even } else { *odd }
        }
        Texture::Image { image, scale } => bilinear(&images[*image], uv * *scale),
    }
}

/// Equirectangular coordinates of direction `dir` (unit): `u` the azimuth from `−z` towards
/// `+x` plus `rotation`, over 2π; `v` the angle from straight up (`+y`), over π.
pub fn equirect_uv(dir: Vec3, rotation: f64) -> Vec2 {
    use std::f64::consts::PI;
    let phi = dir.x.atan2(-dir.z) + rotation;
    let u = (phi / (2.0 * PI)).rem_euclid(1.0);
    let v = dir.y.clamp(-1.0, 1.0).acos() / PI;
    Vec2::new(u.min(1.0 - 1e-16), v.min(1.0 - 1e-16))
}

/// The texel of an equirectangular image seen in direction `dir` (nearest lookup).
pub fn equirect_texel(img: &ImageData, dir: Vec3, rotation: f64) -> Vec3 {
    let uv = equirect_uv(dir, rotation);
    let (w, h) = (img.width as usize, img.height as usize);
    let (x, y) = (((uv.x * w as f64) as usize).min(w - 1), ((uv.y * h as f64) as usize).min(h - 1));
    let p = img.pixels[y * w + x];
    Vec3::new(p[0] as f64, p[1] as f64, p[2] as f64)
}

fn bilinear(img: &ImageData, uv: Vec2) -> Vec3 {
    let (w, h) = (img.width as i64, img.height as i64);
    // v = 0 is the bottom row of the image.
    let x = uv.x.rem_euclid(1.0) * w as f64 - 0.5;
    let y = (1.0 - uv.y.rem_euclid(1.0)) * h as f64 - 0.5;
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let px = |i: i64, j: i64| {
        let p = img.pixels[(j.rem_euclid(h) * w + i.rem_euclid(w)) as usize];
        Vec3::new(p[0] as f64, p[1] as f64, p[2] as f64)
    };
    let (i, j) = (x0 as i64, y0 as i64);
    let top = px(i, j) * (1.0 - fx) + px(i + 1, j) * fx;
    let bottom = px(i, j + 1) * (1.0 - fx) + px(i + 1, j + 1) * fx;
    top * (1.0 - fy) + bottom * fy
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checker_alternates_with_unit_squares() {
        let t = Texture::Checker { even: Vec3::ONE, odd: Vec3::ZERO, size: 1.0 };
        assert_eq!(eval(&t, Vec2::new(0.5, 0.5), &[]), Vec3::ONE);
        assert_eq!(eval(&t, Vec2::new(1.5, 0.5), &[]), Vec3::ZERO);
        assert_eq!(eval(&t, Vec2::new(-0.5, 0.5), &[]), Vec3::ZERO);
        assert_eq!(eval(&t, Vec2::new(-0.5, -0.5), &[]), Vec3::ONE);
    }

    #[test]
    fn image_lookup_hits_pixel_centres() {
        let img = ImageData { width: 2, height: 1, pixels: vec![[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]] };
        let t = Texture::Image { image: 0, scale: Vec2::ONE };
        let imgs = [std::sync::Arc::new(img)];
        assert_eq!(eval(&t, Vec2::new(0.25, 0.5), &imgs), Vec3::X);
        assert_eq!(eval(&t, Vec2::new(0.75, 0.5), &imgs), Vec3::Z);
    }
}
