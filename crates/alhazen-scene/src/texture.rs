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
