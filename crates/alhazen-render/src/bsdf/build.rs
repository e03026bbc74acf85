//! From a scene material to the [`Bsdf`] at one surface point: textures looked up, colours
//! converted to the path's wavelengths when rendering spectrally, the index of a dispersive
//! glass taken at the hero wavelength.

use super::*;
use crate::texture;
use alhazen_scene::bsdf::{BsdfDesc, Ior};
use alhazen_scene::{FresnelMode, ImageData, Material};
use std::sync::Arc;

/// What the path knows about colour: RGB, or three wavelengths (hero first).
#[derive(Clone, Copy, Debug)]
pub enum ColorMode {
    /// Channels are linear RGB.
    Rgb,
    /// Channels are radiance at these wavelengths (nm).
    Spectral([f64; 3]),
}

impl ColorMode {
    /// An RGB reflectance or radiance in this mode's channels.
    pub fn color(&self, rgb: Vec3) -> Vec3 {
        match self {
            ColorMode::Rgb => rgb,
            ColorMode::Spectral(l) => crate::spectrum::rgb_to_spectrum(rgb, l),
        }
    }

    fn ior(&self, ior: &Ior) -> f64 {
        match self {
            ColorMode::Spectral(l) if ior.is_dispersive() => ior.at(l[0]),
            _ => ior.nominal(),
        }
    }
}

/// The BSDF of `m` at texture coordinates `uv` where the vertex colour is `color` (white
/// where the surface has none). A material with `vertex_colors` multiplies by it every colour
/// that is its base colour: albedos, diffuse colours, a metal's tint, a metallic-roughness
/// base (glTF's reading of `COLOR_0`).
pub fn bsdf_at(m: &Material, uv: Vec2, color: Vec3, images: &[Arc<ImageData>], mode: ColorMode) -> Bsdf {
    let tint = m.vertex_tint(color);
    let rgb = |t: &alhazen_scene::Texture| texture::eval(t, uv, images);
    let tex = |t: &alhazen_scene::Texture| mode.color(rgb(t) * tint);
    match &m.bsdf {
        Some(desc) => from_desc(desc, &Lookups { tex: &tex, rgb: &rgb, tint }, mode),
        None => whitted_equivalent(m, &tex, mode),
    }
}

/// The path tracer's reading of a Whitted material: glass when transparent, else Lambert plus
/// an ideal mirror of weight `max(mirror)`.
fn whitted_equivalent(m: &Material, tex: &dyn Fn(&alhazen_scene::Texture) -> Vec3, mode: ColorMode) -> Bsdf {
    if m.transparency != Vec3::ZERO {
        return Bsdf::Dielectric(Dielectric {
            facets: None,
            eta: m.ior,
            schlick: m.fresnel == FresnelMode::Schlick,
            dispersive: false,
            thin: false,
            tint: Vec3::ONE,
            film: None,
        });
    }
    let lambert = Bsdf::Lambert(Lambert { albedo: tex(&m.color) * m.diffuse });
    let w = m.mirror.max_element().min(1.0);
    if w <= 0.0 {
        return lambert;
    }
    let mirror = Bsdf::Conductor(Conductor {
        facets: None,
        eta: Vec3::ZERO,
        k: Vec3::ZERO,
        tint: mode.color(m.mirror / w),
        schlick: false,
        multiscatter: None,
        film: None,
    });
    Bsdf::Mix(Box::new(Mix { a: mirror, b: lambert, weight: w }))
}

/// A point's texture lookups: base colours in the path's channels (times the vertex colour),
/// and textures as stored (linear RGB); the vertex colour that tints base colours.
struct Lookups<'a> {
    tex: &'a dyn Fn(&alhazen_scene::Texture) -> Vec3,
    rgb: &'a dyn Fn(&alhazen_scene::Texture) -> Vec3,
    tint: Vec3,
}

fn from_desc(desc: &BsdfDesc, lookups: &Lookups, mode: ColorMode) -> Bsdf {
    let tex = lookups.tex;
    match desc {
        BsdfDesc::Lambert { albedo } => Bsdf::Lambert(Lambert { albedo: tex(albedo) }),
        BsdfDesc::OrenNayar { albedo, sigma, interreflection } => {
            Bsdf::OrenNayar(OrenNayar { albedo: tex(albedo), sigma: *sigma, interreflection: *interreflection })
        }
        BsdfDesc::Phong { albedo, kd, ks, exponent } => Bsdf::Phong(Phong {
            diffuse: tex(albedo) * *kd,
            ks: *ks,
            lobe: PhongLobe { exponent: *exponent },
            transmittance: Vec3::ZERO,
        }),
        BsdfDesc::BlinnPhong { albedo, kd, ks, exponent, anisotropy, .. } => Bsdf::BlinnPhong(BlinnPhong {
            diffuse: tex(albedo) * *kd,
            ks: *ks,
            lobe: BlinnPhongLobe { exponent: *exponent, anisotropy: *anisotropy },
            transmittance: Vec3::ZERO,
        }),
        BsdfDesc::CookTorrance { albedo, kd, ks, facets, ior, fresnel, layered, transmittance } => {
            Bsdf::CookTorrance(CookTorrance {
                diffuse: tex(albedo) * *kd,
                ks: *ks,
                lobe: CookTorranceLobe {
                    facets: Microfacet::new(facets),
                    ior: *ior,
                    schlick: *fresnel == FresnelMode::Schlick,
                    layer: if *layered { *ks } else { 0.0 },
                },
                transmittance: tex(transmittance),
            })
        }
        BsdfDesc::Plastic { albedo, ior, facets, nonlinear } => {
            Bsdf::Plastic(Plastic::new(tex(albedo), *ior, facets.as_ref().map(Microfacet::new), *nonlinear))
        }
        BsdfDesc::Conductor { facets, eta, k, tint, fresnel, multiscatter } => {
            let c = Conductor {
                facets: facets.as_ref().map(Microfacet::new),
                eta: mode.color(*eta),
                k: mode.color(*k),
                tint: mode.color(*tint * lookups.tint),
                schlick: *fresnel == FresnelMode::Schlick,
                multiscatter: None,
                film: None,
            };
            Bsdf::Conductor(if *multiscatter { c.with_several_facets() } else { c })
        }
        BsdfDesc::Dielectric { facets, ior, fresnel, transmittance, film } => Bsdf::Dielectric(Dielectric {
            facets: facets.as_ref().map(Microfacet::new),
            eta: mode.ior(ior),
            schlick: *fresnel == FresnelMode::Schlick,
            dispersive: ior.is_dispersive() && matches!(mode, ColorMode::Spectral(_)),
            thin: false,
            // Clear glass stays exactly clear (in every colour mode).
            tint: match transmittance {
                alhazen_scene::Texture::Solid(c) if *c == Vec3::ONE && lookups.tint == Vec3::ONE => Vec3::ONE,
                t => tex(t),
            },
            film: film.as_ref().map(|i| thin_film(i, lookups, mode)),
        }),
        BsdfDesc::ThinDielectric { ior } => Bsdf::Dielectric(Dielectric {
            facets: None,
            eta: *ior,
            schlick: false,
            dispersive: false,
            thin: true,
            tint: Vec3::ONE,
            film: None,
        }),
        BsdfDesc::Mix { a, b, weight, weight_map } => {
            let at = weight_map.as_ref().map_or(1.0, |t| alhazen_math::color::luminance((lookups.rgb)(t)));
            let weight = (weight * at).clamp(0.0, 1.0);
            Bsdf::Mix(Box::new(Mix { a: from_desc(a, lookups, mode), b: from_desc(b, lookups, mode), weight }))
        }
        BsdfDesc::Sheened { base, color, roughness, roughness_map } => {
            let r = roughness * roughness_map.as_ref().map_or(1.0, |m| (lookups.rgb)(m).x);
            Bsdf::Sheened(Box::new(super::Sheened::new(
                from_desc(base, lookups, mode),
                mode.color((lookups.rgb)(color)),
                r * r,
            )))
        }
        BsdfDesc::Coated { base, weight, facets, ior, weight_map, roughness_map } => {
            // glTF's maps: the weight in the red channel, the roughness in the green.
            let weight = weight * weight_map.as_ref().map_or(1.0, |m| (lookups.rgb)(m).x.clamp(0.0, 1.0));
            let mut facets = *facets;
            if let Some(m) = roughness_map {
                let g = (lookups.rgb)(m).y.clamp(0.0, 1.0);
                facets.alpha_u = (facets.alpha_u * g * g).max(0.01);
                facets.alpha_v = (facets.alpha_v * g * g).max(0.01);
            }
            Bsdf::Coated(Box::new(super::Coated::new(
                from_desc(base, lookups, mode),
                CookTorranceLobe { facets: Microfacet::new(&facets), ior: *ior, schlick: false, layer: 0.0 },
                weight,
            )))
        }
        BsdfDesc::MetallicRoughness {
            base,
            metallic,
            roughness,
            map,
            ior,
            specular,
            multiscatter,
            anisotropy,
            anisotropy_map,
            iridescence,
            specular_map,
            specular_color_map,
            translucency,
            translucency_map,
            translucency_color_map,
        } => {
            // glTF's map: roughness in its green channel, metalness in its blue.
            let texel = map.as_ref().map_or(Vec3::ONE, |m| (lookups.rgb)(m));
            let anisotropy = anisotropy_map.as_ref().map_or(*anisotropy, |m| anisotropy.at_texel((lookups.rgb)(m)));
            let (metal, coating, weight) = BsdfDesc::metallic_roughness_at(
                (lookups.rgb)(base) * lookups.tint,
                metallic * texel.z,
                roughness * texel.y,
                alhazen_scene::bsdf::MetalRoughness {
                    ior: specular_color_map.as_ref().map_or(*ior, |m| {
                        let c = (lookups.rgb)(m);
                        alhazen_scene::bsdf::ior_scaled(*ior, (c.x + c.y + c.z) / 3.0)
                    }),
                    specular: specular * specular_map.as_ref().map_or(1.0, |m| (lookups.rgb)(m).x.clamp(0.0, 1.0)),
                    multiscatter: *multiscatter,
                    anisotropy,
                    translucency: alhazen_scene::bsdf::Translucency {
                        factor: translucency.factor
                            * translucency_map.as_ref().map_or(1.0, |m| (lookups.rgb)(m).x.clamp(0.0, 1.0)),
                        color: translucency.color
                            * translucency_color_map
                                .as_ref()
                                .map_or(Vec3::ONE, |m| (lookups.rgb)(m).clamp(Vec3::ZERO, Vec3::ONE)),
                    },
                },
            );
            let (a, b) = (from_desc(&metal, lookups, mode), from_desc(&coating, lookups, mode));
            match iridescence {
                // (The general kernel shades filmed surfaces, whatever their lobes — a filmed
                // conductor is never a lane kernel's —: all metal or none is one lobe, the
                // film's Fresnel factor not found for the other.)
                Some(i) if weight >= 1.0 => filmed_metal(a, thin_film(i, lookups, mode)),
                Some(i) if weight <= 0.0 => filmed_coating(b, thin_film(i, lookups, mode)),
                Some(i) => {
                    let film = thin_film(i, lookups, mode);
                    let (a, b) = (filmed_metal(a, film), filmed_coating(b, film));
                    Bsdf::Mix(Box::new(Mix { a, b, weight }))
                }
                None => Bsdf::Mix(Box::new(Mix { a, b, weight })),
            }
        }
    }
}

/// The film of `i` at a point: its weight and thickness from its maps there.
fn thin_film(i: &alhazen_scene::bsdf::Iridescence, lookups: &Lookups, mode: ColorMode) -> ThinFilm {
    let texel = |m: &Option<alhazen_scene::Texture>| m.as_ref().map(|m| (lookups.rgb)(m));
    let (weight, thickness) = i.at(texel(&i.factor_map), texel(&i.thickness_map));
    let wavelengths = match mode {
        ColorMode::Rgb => None,
        ColorMode::Spectral(l) => Some(l.map(|x| x as f32)),
    };
    ThinFilm {
        weight: weight as f32,
        ior: i.ior as f32,
        thickness: thickness as f32,
        outside: i.outside as f32,
        wavelengths,
    }
}

/// The metallic–roughness model's metal under `film`: its Fresnel factor blended with the
/// film's (its light of several facets found again with it).
fn filmed_metal(metal: Bsdf, film: ThinFilm) -> Bsdf {
    match metal {
        Bsdf::Conductor(c) => {
            let several = c.multiscatter.is_some();
            let c = Conductor { film: Some(film), multiscatter: None, ..c };
            Bsdf::Conductor(if several { c.with_several_facets() } else { c })
        }
        other => other,
    }
}

/// The metallic–roughness model's coating under `film`: its specular lobe split into `1 − w` of
/// itself and `w` of the film's (glTF's `mix(F, F_film, w)`), the latter a lobe of the same
/// facets whose factor is the film's over the coating's index: `ρ_d + k_s(1 − w)ρ_s +
/// k_s·w·ρ_film`, written as a mix that samples the film's lobe with probability `k_s·w/2`.
/// The mix is kept where the film or the specular lobe is nothing (its film lobe then of weight
/// 0), so that every point of a filmed surface has the same kind of BSDF.
fn filmed_coating(coating: Bsdf, film: ThinFilm) -> Bsdf {
    let Bsdf::CookTorrance(ct) = &coating else { return coating };
    let w = f64::from(film.weight).clamp(0.0, 1.0);
    let film_share = ct.ks * w / 2.0;
    let keep = 1.0 - film_share;
    let own = CookTorrance {
        diffuse: ct.diffuse / keep,
        ks: ct.ks * (1.0 - w) / keep,
        lobe: ct.lobe,
        transmittance: ct.transmittance / keep,
    };
    let lobe = Conductor {
        facets: Some(ct.lobe.facets),
        eta: Vec3::splat(ct.lobe.ior),
        k: Vec3::ZERO,
        // `k_s·w / (k_s·w/2)`, where the film lobe is sampled at all.
        tint: Vec3::splat(if film_share > 0.0 { 2.0 } else { 0.0 }),
        schlick: true,
        multiscatter: None,
        film: Some(ThinFilm { weight: 1.0, ..film }),
    };
    Bsdf::Mix(Box::new(Mix { a: Bsdf::CookTorrance(own), b: Bsdf::Conductor(lobe), weight: keep }))
}

/// The world-space tangent that anisotropic lobes align with at `hit`: Blinn–Phong's
/// scratches, else `∂p/∂u` for anisotropic microfacets (as pbrt and Mitsuba orient them),
/// turned about the normal by a metallic–roughness surface's rotation and its map's direction
/// there (`turned_tangent`, [`alhazen_scene::bsdf::Anisotropy::at_texel`]); `None` for
/// isotropic BSDFs, whose frame may turn freely about the normal, and where `∂p/∂u` is
/// unknown (zero).
pub fn tangent_at(m: &Material, hit: &crate::shape::SurfaceHit, images: &[Arc<ImageData>]) -> Option<Vec3> {
    let dpdu = hit.dpduv[0];
    match &m.bsdf {
        Some(BsdfDesc::BlinnPhong { scratches, .. }) => Some(*scratches),
        Some(BsdfDesc::MetallicRoughness { anisotropy, anisotropy_map, .. })
            if dpdu != Vec3::ZERO && anisotropy.is_anisotropic() =>
        {
            let rotation = match anisotropy_map {
                Some(map) => anisotropy.at_texel(texture::eval(map, hit.uv, images)).rotation,
                None => anisotropy.rotation,
            };
            Some(turned_tangent(hit.dpduv, hit.n, rotation))
        }
        // `dpdu` first: it is zero wherever the world computed no tangents (no anisotropic
        // material), and the walk down the description costs more.
        Some(desc) if dpdu != Vec3::ZERO && desc.is_anisotropic() => Some(dpdu),
        _ => None,
    }
}

/// `∂p/∂u` turned about `n` by `angle` towards the bitangent, as glTF's
/// `KHR_materials_anisotropy` turns it: `t cos θ + b sin θ` with `t` the part of `∂p/∂u`
/// across `n` and `b = ±n × t`, on the side of `∂p/∂v` (texture coordinates mirrored turn
/// the other way).
pub fn turned_tangent([dpdu, dpdv]: [Vec3; 2], n: Vec3, angle: f64) -> Vec3 {
    if angle == 0.0 {
        return dpdu;
    }
    let t = (dpdu - n * n.dot(dpdu)).normalize_or_zero();
    let b = n.cross(t);
    let b = if b.dot(dpdv) < 0.0 { -b } else { b };
    let (sin, cos) = angle.sin_cos();
    let turned = t * cos + b * sin;
    if turned == Vec3::ZERO { dpdu } else { turned }
}

/// True when `m`'s lobes turn with the tangent (Blinn–Phong's scratches, microfacets of two
/// roughnesses): its hits need `∂p/∂u`.
pub fn is_anisotropic(m: &Material) -> bool {
    m.bsdf.as_ref().is_some_and(BsdfDesc::is_anisotropic)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit(v: [f64; 3]) -> Option<Vec3> {
        Vec3::from_array(v).try_normalize()
    }

    proptest::proptest! {
        /// The turned tangent lies across the normal, at `angle` from `∂p/∂u`'s part across it,
        /// turned towards `∂p/∂v`'s side; no turn leaves `∂p/∂u` as it is.
        #[test]
        fn the_tangent_turns_about_the_normal_towards_dpdv(
            n in proptest::array::uniform3(-1.0..1.0f64),
            dpdu in proptest::array::uniform3(-1.0..1.0f64),
            dpdv in proptest::array::uniform3(-1.0..1.0f64),
            angle in -3.1..3.1f64,
        ) {
            let (Some(n), dpdu, dpdv) = (unit(n), Vec3::from_array(dpdu), Vec3::from_array(dpdv)) else { return Ok(()) };
            let t = dpdu - n * n.dot(dpdu);
            let b = n.cross(t);
            proptest::prop_assume!(t.length() > 0.1 && b.dot(dpdv).abs() > 0.1);
            proptest::prop_assert_eq!(turned_tangent([dpdu, dpdv], n, 0.0), dpdu);
            let turned = turned_tangent([dpdu, dpdv], n, angle);
            proptest::prop_assert!((turned.length() - 1.0).abs() < 1e-9 && turned.dot(n).abs() < 1e-9);
            let (t, b) = (t.normalize(), b.normalize() * b.dot(dpdv).signum());
            proptest::prop_assert!((turned.dot(t) - angle.cos()).abs() < 1e-9);
            proptest::prop_assert!((turned.dot(b) - angle.sin()).abs() < 1e-9);
        }
    }
}
