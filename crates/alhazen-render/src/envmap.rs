//! Environment light from an equirectangular radiance map (course §"Image-based lighting for
//! physical models"), importance-sampled by texel power (luminance × sin ϑ).
//!
//! Mapping: `u = φ/2π` with `φ` the azimuth from `−z` towards `+x` (plus the map's rotation),
//! `v = ϑ/π` from straight up (`+y`) to straight down; texels are constant (nearest lookup), so
//! the sampling density matches the radiance exactly.

use crate::distribution::Distribution2D;
use alhazen_math::{Vec2, Vec3, color::luminance};
use alhazen_scene::ImageData;
use std::f64::consts::PI;
use std::sync::Arc;

/// An environment map ready for lookup and sampling.
#[derive(Clone, Debug)]
pub struct EnvMap {
    image: Arc<ImageData>,
    scale: f64,
    rotation: f64,
    /// The rotation in turns.
    turns: f64,
    distribution: Distribution2D,
}

impl EnvMap {
    /// From a linear radiance image.
    pub fn new(image: Arc<ImageData>, scale: f64, rotation: f64) -> Self {
        let (w, h) = (image.width as usize, image.height as usize);
        let mut weights = vec![0.0; w * h];
        for y in 0..h {
            let sin = (PI * (y as f64 + 0.5) / h as f64).sin();
            for x in 0..w {
                let p = image.pixels[y * w + x];
                weights[y * w + x] = luminance(Vec3::new(p[0] as f64, p[1] as f64, p[2] as f64)).max(0.0) * sin;
            }
        }
        let distribution = Distribution2D::new(&weights, w, h);
        Self { image, scale, rotation, turns: rotation / (2.0 * PI), distribution }
    }

    fn to_uv(&self, dir: Vec3) -> Vec2 {
        alhazen_scene::texture::equirect_uv(dir, self.rotation)
    }

    /// The direction of `uv` and its polar angle's sine.
    fn to_dir(&self, uv: Vec2) -> (Vec3, f64) {
        let (st, ct) = alhazen_math::sin_cos_turns(uv.y / 2.0);
        let (sp, cp) = alhazen_math::sin_cos_turns(uv.x - self.turns);
        (Vec3::new(st * sp, ct, -st * cp), st)
    }

    /// Radiance arriving from direction `dir` (unit, pointing away from the scene).
    pub fn radiance(&self, dir: Vec3) -> Vec3 {
        alhazen_scene::texture::equirect_texel(&self.image, dir, self.rotation) * self.scale
    }

    /// A direction with density ∝ power, its radiance and solid-angle density.
    pub fn sample(&self, u: Vec2) -> Option<(Vec3, Vec3, f64)> {
        let (uv, pdf_uv) = self.distribution.sample(u);
        let (dir, sin) = self.to_dir(uv);
        if pdf_uv <= 0.0 || sin <= 0.0 {
            return None;
        }
        // The radiance of the texel sampled (not looked up again from the direction: the same
        // texel but for rounding on its edges, without the inverse trigonometry).
        let radiance = alhazen_scene::texture::equirect_texel_at(&self.image, uv) * self.scale;
        Some((dir, radiance, pdf_uv / (2.0 * PI * PI * sin)))
    }

    /// Solid-angle density of [`Self::sample`] choosing `dir`.
    pub fn pdf(&self, dir: Vec3) -> f64 {
        self.pdf_at(self.to_uv(dir), polar_sine(dir))
    }

    /// [`Self::radiance`] and [`Self::pdf`] of `dir`, mapped to the image once.
    pub fn radiance_and_pdf(&self, dir: Vec3) -> (Vec3, f64) {
        let uv = self.to_uv(dir);
        (alhazen_scene::texture::equirect_texel_at(&self.image, uv) * self.scale, self.pdf_at(uv, polar_sine(dir)))
    }

    /// The density at `uv`, whose polar angle has sine `sin`.
    fn pdf_at(&self, uv: Vec2, sin: f64) -> f64 {
        if sin <= 0.0 { 0.0 } else { self.distribution.pdf(uv) / (2.0 * PI * PI * sin) }
    }
}

/// The sine of unit direction `dir`'s angle from +y, without trigonometry.
fn polar_sine(dir: Vec3) -> f64 {
    (dir.x * dir.x + dir.z * dir.z).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn test_map() -> EnvMap {
        let (w, h) = (16u32, 8u32);
        let pixels = (0..w * h).map(|i| [(i % 7) as f32 + 0.5, 1.0, (i % 3) as f32]).collect();
        EnvMap::new(Arc::new(ImageData { width: w, height: h, pixels }), 2.0, 0.4)
    }

    #[test]
    fn directions_round_trip_and_density_integrates_to_one() {
        let m = test_map();
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
        let m = test_map();
        for k in 0..200 {
            let u = Vec2::new((k as f64 * 0.618).fract(), (k as f64 * 0.377 + 0.1).fract());
            let (d, l, pdf) = m.sample(u).unwrap();
            assert!((m.pdf(d) - pdf).abs() < 1e-9 * pdf.max(1.0), "{k}");
            assert_eq!(m.radiance(d), l);
            assert_eq!(m.radiance_and_pdf(d), (l, m.pdf(d)));
        }
    }
}
