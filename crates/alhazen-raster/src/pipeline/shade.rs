//! The course's local lighting models for the preview (§"Lighting models"): ambient, Lambert and
//! the Phong or Blinn–Phong highlight (`⟨h, n⟩^{2m}`), for every light on the viewer's side of
//! the surface (the factor ν), with the course's distance attenuation, and the lights that
//! stand for emitting objects ([`super::emitters`]).

use super::ibl::{Sh9, SpecularIbl};
use super::shadow::Shadows;
use std::f64::consts::FRAC_1_PI;

/// What lights a point besides the scene's lights: shadow maps and the environment's irradiance.
#[derive(Clone, Copy, Default)]
pub struct Lighting<'a> {
    /// Shadow maps (no shadows when `None`).
    pub shadows: Option<&'a Shadows>,
    /// The environment's irradiance (no image-based light when `None`).
    pub irradiance: Option<&'a Sh9>,
    /// The prefiltered environment and split-sum table (no specular image-based light when `None`).
    pub specular: Option<&'a SpecularIbl>,
    /// Lights (bit `k` for light `k`) that a stencil shadow volume hides at this pixel.
    pub blocked: u64,
    /// What a mirror shows at this pixel ([`super::mirrors`]), instead of the sky.
    pub reflected: Option<Vec3>,
    /// What lies behind a transparent surface at this pixel (the frame drawn without
    /// transparent objects), instead of the sky.
    pub behind: Option<Vec3>,
    /// Lights standing for emitting objects, after the scene's (their shadow maps follow).
    pub emitters: &'a [super::emitters::EmitterLight],
    /// The course's hemispherical lighting instead of the ambient constant: sky and ground
    /// intensities (the background straight up and straight down).
    pub hemisphere: Option<(Vec3, Vec3)>,
}
use alhazen_math::{Vec2, Vec3};
use alhazen_scene::{Material, Scene};

/// The light arriving at `p` (unit normal `n`, viewer direction `v`), split as the course's
/// model is: the factor of the surface colour (`I^amb + Σ I^dir ⟨l, n⟩`) and the highlight
/// (`Σ I^dir s W`). Gouraud shading interpolates these two, so textures stay per pixel.
pub fn lighting(scene: &Scene, m: &Material, p: Vec3, n: Vec3, v: Vec3, extra: &Lighting) -> (Vec3, Vec3) {
    // Two-sided: light the side the viewer sees.
    let n = if n.dot(v) < 0.0 { -n } else { n };
    // The course's hemispherical lighting: sky and ground blended by t = (1 − ⟨z, n⟩)/2 (z = up),
    // the share of the ground in the projected hemisphere the surface sees.
    let ambient = match extra.hemisphere {
        Some((sky, ground)) => {
            let t = (1.0 - n.y) / 2.0;
            sky * (1.0 - t) + ground * t
        }
        None => scene.ambient,
    };
    let (mut diffuse, mut specular) = (ambient, Vec3::ZERO);
    // Lambertian reflection of the environment: ρ/π times its irradiance.
    if let Some(sh) = extra.irradiance {
        diffuse += sh.eval(n).max(Vec3::ZERO) * FRAC_1_PI;
    }
    let shadows = extra.shadows;
    let lights = scene.lights.iter().chain(extra.emitters.iter().map(|e| &e.light));
    for (k, light) in lights.enumerate() {
        let Some((l, _, i)) = light.arriving(p) else { continue };
        let cos = n.dot(l);
        let stenciled = k < 64 && extra.blocked >> k & 1 == 1;
        if cos <= 0.0 || stenciled || shadows.is_some_and(|s| !s.lit(k, p, n)) {
            continue;
        }
        diffuse += i * cos;
        if m.specular != Vec3::ZERO {
            specular += i * m.specular * m.highlight(n, l, v);
        }
    }
    (diffuse, specular)
}

/// Radiance towards the viewer from the light factors of [`lighting`] at texture coordinates
/// `uv`: `a·diffuse + specular`, plus emission; for mirrors what they show (or the sky — the
/// environment map, else the background — in the reflected direction); for glass a
/// Fresnel-weighted blend of what lies behind it (unrefracted) and the reflected sky.
pub fn combine(
    scene: &Scene,
    m: &Material,
    (diffuse, specular): (Vec3, Vec3),
    n: Vec3,
    v: Vec3,
    base: Vec3,
    extra: &Lighting,
) -> Vec3 {
    let a = base * m.diffuse;
    let mut c = a * diffuse + specular + m.emission;
    let n = if n.dot(v) < 0.0 { -n } else { n };
    // Glossy reflection of the environment by the split sum, with the Beckmann roughness that
    // matches the Phong exponent (m² = 2/(shininess + 2)) and a dielectric F₀ = 0.04.
    if let (Some(ibl), true) = (extra.specular, m.specular != Vec3::ZERO) {
        let r = 2.0 * v.dot(n) * n - v;
        let rough = (2.0 / (m.shininess + 2.0)).sqrt();
        c += m.specular * ibl.filtered(r, rough) * ibl.split_factor(v.dot(n), 0.04);
    }
    if m.mirror != Vec3::ZERO {
        c += m.mirror * extra.reflected.unwrap_or_else(|| scene.sky(2.0 * v.dot(n) * n - v));
    }
    if m.transparency != Vec3::ZERO {
        // A Fresnel-weighted blend of what lies behind (not refracted) and the reflected sky.
        let f = alhazen_render::optics::fresnel_dielectric(v.dot(n), m.ior);
        let behind = extra.behind.unwrap_or_else(|| scene.sky(-v));
        let mirrored = scene.sky(2.0 * v.dot(n) * n - v);
        c += m.transparency * (behind * (1.0 - f) + mirrored * f);
    }
    c
}

/// Radiance towards the viewer at `p`, lit per point; `base` is the material's colour there
/// ([`base_color`]).
pub fn shade(scene: &Scene, m: &Material, p: Vec3, n: Vec3, v: Vec3, base: Vec3, extra: &Lighting) -> Vec3 {
    combine(scene, m, lighting(scene, m, p, n, v, extra), n, v, base, extra)
}

/// The colour `a` of `m` at texture coordinates `uv` where the vertex colour is `color`.
pub fn base_color(scene: &Scene, m: &Material, uv: Vec2, color: Vec3) -> Vec3 {
    alhazen_scene::texture::eval(&m.color, uv, &scene.images) * m.vertex_tint(color)
}
