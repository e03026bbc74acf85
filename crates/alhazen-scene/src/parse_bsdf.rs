//! The `bsdf` table of a material and the environment light (docs/scene-format.md,
//! "Physically based materials").

use crate::bsdf::*;
use crate::import;
use crate::model::{FresnelMode, Light, Texture};
use crate::parse::Parser;
use crate::reader::{Node, R, Table};
use alhazen_math::Vec3;
use std::sync::Arc;

const MICROFACET_KEYS: &[&str] = &["roughness", "distribution", "shadowing"];

fn names<T>(list: &[(&'static str, T, T)]) -> Vec<&'static str> {
    list.iter().map(|e| e.0).collect()
}

impl Parser<'_> {
    /// A metallic–roughness surface's `anisotropy`: its strength, or `{ strength, rotation =
    /// degrees, model = "gltf" | "disney", map = image }` (the map read linearly).
    fn anisotropy(&mut self, n: &Node) -> R<(Anisotropy, Option<Texture>)> {
        if !n.is_table() {
            return Ok((Anisotropy { strength: n.in_range(0.0, 1.0)?, ..Anisotropy::default() }, None));
        }
        let t = n.table(&["strength", "rotation", "model", "map"])?;
        let model = match t.get("model").map_or(Ok("gltf"), |m| m.choice(&["gltf", "disney"]))? {
            "gltf" => AnisotropyModel::Gltf,
            _ => AnisotropyModel::Disney,
        };
        let anisotropy = Anisotropy {
            strength: t.req("strength")?.in_range(0.0, 1.0)?,
            rotation: t.get("rotation").map_or(Ok(0.0), |r| r.in_range(-360.0, 360.0))?.to_radians(),
            model,
        };
        Ok((anisotropy, t.get("map").map(|m| self.linear_placed_image(&m)).transpose()?))
    }

    /// A Cook–Torrance surface's `transmittance` (black when absent): a colour or texture; a
    /// colour within `[0, 1]` that with the diffuse weight `kd` sends on at most what arrives.
    fn diffuse_transmittance(&mut self, t: &Table, kd: f64) -> R<Texture> {
        let Some(c) = t.get("transmittance") else { return Ok(Texture::Solid(Vec3::ZERO)) };
        match self.texture(&c)? {
            Texture::Solid(k) if !(k.min_element() >= 0.0 && k.max_element() <= 1.0) => {
                Err(c.err("`transmittance` is a colour within [0, 1]: what passes through"))
            }
            Texture::Solid(k) if kd + k.max_element() > 1.0 + 1e-9 => Err(c.err(format!(
                "kd + transmittance = {} exceeds 1: the surface would create energy",
                kd + k.max_element()
            ))),
            texture => Ok(texture),
        }
    }

    /// A metallic–roughness surface's `iridescence = { factor, ior, thickness, outside,
    /// factor_map, thickness_map }`: `thickness` one number (nm) or the two the thickness map's
    /// green channel runs between.
    fn iridescence(&mut self, n: &Node) -> R<Iridescence> {
        let t = n.table(&["factor", "ior", "thickness", "outside", "factor_map", "thickness_map"])?;
        let thickness = match t.get("thickness") {
            None => [100.0, 400.0],
            Some(x) if x.is_array() => {
                let ends = x.numbers::<2>()?;
                if !ends.iter().all(|d| (0.0..=1e5).contains(d)) {
                    return Err(x.err(
                        "a film's `thickness` is [at the map's 0, at its 1] in nanometres, each within [0, 100000]",
                    ));
                }
                ends
            }
            Some(x) => {
                let d = x.in_range(0.0, 1e5)?;
                [d, d]
            }
        };
        Ok(Iridescence {
            factor: t.get("factor").map_or(Ok(1.0), |n| n.in_range(0.0, 1.0))?,
            ior: t.get("ior").map_or(Ok(1.3), |n| n.in_range(1.0, 10.0))?,
            thickness,
            outside: t.get("outside").map_or(Ok(1.0), |n| n.in_range(1.0, 10.0))?,
            factor_map: t.get("factor_map").map(|m| self.linear_placed_image(&m)).transpose()?,
            thickness_map: t.get("thickness_map").map(|m| self.linear_placed_image(&m)).transpose()?,
        })
    }

    /// A `bsdf` table; `albedo` is the material's `color`, the default albedo.
    pub(crate) fn bsdf(&mut self, n: &Node, albedo: &Texture) -> R<BsdfDesc> {
        let t = n.table_any()?;
        let kind = t.req("type")?.choice(&[
            "lambert",
            "oren-nayar",
            "phong",
            "blinn-phong",
            "cook-torrance",
            "plastic",
            "conductor",
            "dielectric",
            "thin-dielectric",
            "mix",
            "metallic-roughness",
            "coated",
            "sheen",
        ])?;
        let keys: Vec<&str> = match kind {
            "lambert" => vec!["color"],
            "oren-nayar" => vec!["color", "sigma", "interreflection"],
            "phong" => vec!["color", "kd", "ks", "exponent"],
            "blinn-phong" => vec!["color", "kd", "ks", "exponent", "anisotropy", "scratches"],
            "cook-torrance" => {
                [&["color", "kd", "ks", "ior", "fresnel", "layered", "transmittance"][..], MICROFACET_KEYS].concat()
            }
            "plastic" => [&["color", "ior", "nonlinear"][..], MICROFACET_KEYS].concat(),
            "conductor" => [&["metal", "eta", "k", "tint", "fresnel", "multiscatter"][..], MICROFACET_KEYS].concat(),
            "dielectric" => [
                &["ior", "cauchy", "sellmeier", "glass", "fresnel", "transmittance", "iridescence"][..],
                MICROFACET_KEYS,
            ]
            .concat(),
            "metallic-roughness" => {
                vec![
                    "color",
                    "metallic",
                    "roughness",
                    "map",
                    "ior",
                    "specular",
                    "multiscatter",
                    "anisotropy",
                    "iridescence",
                    "specular_map",
                    "specular_color_map",
                    "diffuse_transmission",
                ]
            }
            "thin-dielectric" => vec!["ior"],
            "coated" => [&["base", "weight", "ior", "weight_map", "roughness_map"][..], MICROFACET_KEYS].concat(),
            "sheen" => vec!["base", "sheen_color", "roughness", "roughness_map"],
            _ => vec!["a", "b", "weight", "weight_map"],
        };
        t.check_keys(&[&["type"][..], &keys].concat())?;
        let albedo = match t.get("color") {
            Some(c) => self.texture(&c)?,
            None => albedo.clone(),
        };
        Ok(match kind {
            "lambert" => BsdfDesc::Lambert { albedo },
            "oren-nayar" => BsdfDesc::OrenNayar {
                albedo,
                sigma: t.get("sigma").map_or(Ok(20.0), |n| n.in_range(0.0, 90.0))?.to_radians(),
                interreflection: t.opt_bool("interreflection", true)?,
            },
            "phong" | "blinn-phong" => {
                let (kd, ks) = weights(&t, 0.2)?;
                let exponent = t.get("exponent").map_or(Ok(32.0), |n| n.in_range(0.0, 1e6))?;
                if kind == "phong" {
                    BsdfDesc::Phong { albedo, kd, ks, exponent }
                } else {
                    BsdfDesc::BlinnPhong {
                        albedo,
                        kd,
                        ks,
                        exponent,
                        anisotropy: t.get("anisotropy").map_or(Ok(1.0), |n| n.in_range(1e-3, 1.0))?,
                        scratches: t.opt_vec3("scratches", Vec3::X)?,
                    }
                }
            }
            "cook-torrance" => {
                let layered = t.opt_bool("layered", false)?;
                let (kd, ks) = if layered { layered_weights(&t, 0.5)? } else { fresnel_weights(&t, 0.5)? };
                let facets = microfacets(&t)?.unwrap_or(default_facets(0.3));
                BsdfDesc::CookTorrance {
                    albedo,
                    kd,
                    ks,
                    facets,
                    ior: t.opt_positive("ior", 1.5)?,
                    fresnel: fresnel(&t)?,
                    layered,
                    transmittance: self.diffuse_transmittance(&t, kd)?,
                }
            }
            "conductor" => {
                let (eta, k) = match t.get("metal") {
                    Some(m) => {
                        if let Some(e) = t.get("eta").or(t.get("k")) {
                            return Err(e.err("give either `metal` or `eta` and `k`, not both"));
                        }
                        let name = m.choice(&names(METALS))?;
                        let (_, eta, k) = METALS.iter().find(|e| e.0 == name).expect("a listed metal");
                        (Vec3::from_array(*eta), Vec3::from_array(*k))
                    }
                    None => (
                        t.opt_rgb("eta", Vec3::from_array(METALS[2].1))?,
                        t.opt_rgb("k", Vec3::from_array(METALS[2].2))?,
                    ),
                };
                let facets = microfacets(&t)?;
                let (tint, fresnel, multiscatter) =
                    (t.opt_rgb("tint", Vec3::ONE)?, fresnel(&t)?, t.opt_bool("multiscatter", false)?);
                BsdfDesc::Conductor { facets, eta, k, tint, fresnel, multiscatter }
            }
            "plastic" => {
                let facets = microfacets(&t)?;
                if facets.is_some_and(|f| f.alpha_u != f.alpha_v) {
                    return Err(t.req("roughness")?.err("a plastic's coat takes one roughness, not two"));
                }
                BsdfDesc::Plastic {
                    albedo,
                    ior: t.get("ior").map_or(Ok(1.49), |n| n.in_range(1.0 + 1e-6, 10.0))?,
                    facets,
                    nonlinear: t.opt_bool("nonlinear", false)?,
                }
            }
            "dielectric" => BsdfDesc::Dielectric {
                facets: microfacets(&t)?,
                ior: ior(&t)?,
                fresnel: fresnel(&t)?,
                transmittance: match t.get("transmittance") {
                    Some(c) => match self.texture(&c)? {
                        Texture::Solid(k) if !(k.min_element() >= 0.0 && k.max_element() <= 1.0) => {
                            return Err(
                                c.err("a dielectric's `transmittance` is a colour within [0, 1]: what light keeps")
                            );
                        }
                        tint => tint,
                    },
                    None => Texture::Solid(Vec3::ONE),
                },
                film: t.get("iridescence").map(|n| self.iridescence(&n).map(Box::new)).transpose()?,
            },
            "thin-dielectric" => {
                BsdfDesc::ThinDielectric { ior: t.get("ior").map_or(Ok(1.5), |n| n.in_range(1.0, 10.0))? }
            }
            "metallic-roughness" => {
                let (anisotropy, anisotropy_map) = match t.get("anisotropy") {
                    Some(n) => self.anisotropy(&n)?,
                    None => (Anisotropy::default(), None),
                };
                let (translucency, translucency_map, translucency_color_map) = match t.get("diffuse_transmission") {
                    Some(n) => self.translucency(&n)?,
                    None => (Translucency::default(), None, None),
                };
                BsdfDesc::MetallicRoughness {
                    base: albedo,
                    metallic: t.get("metallic").map_or(Ok(0.0), |n| n.in_range(0.0, 1.0))?,
                    roughness: t.get("roughness").map_or(Ok(0.5), |n| n.in_range(0.0, 1.0))?,
                    // Read linearly, as glTF's metallic-roughness textures are.
                    map: t.get("map").map(|m| self.linear_placed_image(&m)).transpose()?,
                    ior: t.get("ior").map_or(Ok(1.5), |n| n.in_range(1.0, 10.0))?,
                    specular: t.get("specular").map_or(Ok(1.0), |n| n.in_range(0.0, 1.0))?,
                    multiscatter: t.opt_bool("multiscatter", false)?,
                    anisotropy,
                    anisotropy_map,
                    iridescence: t.get("iridescence").map(|n| self.iridescence(&n).map(Box::new)).transpose()?,
                    specular_map: t.get("specular_map").map(|m| self.linear_placed_image(&m)).transpose()?,
                    specular_color_map: t.get("specular_color_map").map(|m| self.texture(&m)).transpose()?,
                    translucency,
                    translucency_map,
                    translucency_color_map,
                }
            }
            "coated" => {
                // The coat is rough (a near-mirror at its least roughness): its albedo and
                // sampling are those of microfacets.
                let facets = microfacets(&t)?.unwrap_or(default_facets(0.01));
                if facets.alpha_u.min(facets.alpha_v) < 0.01 {
                    return Err(t
                        .req("roughness")?
                        .err("a coat's `roughness` is at least 0.01 (0.01: a clear, glossy coat)"));
                }
                BsdfDesc::Coated {
                    base: Box::new(self.bsdf(&t.req("base")?, &albedo)?),
                    weight: t.get("weight").map_or(Ok(1.0), |n| n.in_range(0.0, 1.0))?,
                    facets,
                    ior: t.get("ior").map_or(Ok(1.5), |n| n.in_range(1.0, 10.0))?,
                    weight_map: t.get("weight_map").map(|m| self.linear_placed_image(&m)).transpose()?,
                    roughness_map: t.get("roughness_map").map(|m| self.linear_placed_image(&m)).transpose()?,
                }
            }
            "sheen" => BsdfDesc::Sheened {
                base: Box::new(self.bsdf(&t.req("base")?, &albedo)?),
                color: t
                    .get("sheen_color")
                    .map_or(Ok(crate::model::Texture::Solid(Vec3::ONE)), |c| self.texture(&c))?,
                roughness: t.get("roughness").map_or(Ok(0.5), |n| n.in_range(0.0, 1.0))?,
                roughness_map: t.get("roughness_map").map(|m| self.linear_placed_image(&m)).transpose()?,
            },
            _ => BsdfDesc::Mix {
                a: Box::new(self.bsdf(&t.req("a")?, &albedo)?),
                b: Box::new(self.bsdf(&t.req("b")?, &albedo)?),
                weight: t.get("weight").map_or(Ok(0.5), |n| n.in_range(0.0, 1.0))?,
                weight_map: t.get("weight_map").map(|n| self.texture(&n)).transpose()?,
            },
        })
    }

    /// `[[light]] type = "environment"`: an equirectangular `.hdr` or `.exr` map, turned by
    /// `rotate_y` degrees about its up axis, `up` (`+y` unless given).
    pub(crate) fn environment_light(&mut self, n: &Node) -> R<Light> {
        let t = n.table(&["type", "file", "scale", "rotate_y", "up"])?;
        let file = t.req("file")?;
        // The numbers first: a mistake in them is said before the image is read.
        let scale = t.get("scale").map_or(Ok(1.0), |n| n.non_negative())?;
        let rotation = t.opt_f64("rotate_y", 0.0)?.to_radians();
        let up = t.get("up").map_or(Ok(Vec3::Y), |n| n.unit_vec3())?;
        let path = self.dir.join(file.str()?);
        let data = import::load_radiance_image(&path).map_err(|e| file.err(e))?;
        self.scene.images.push(Arc::new(data));
        Ok(Light::Environment { image: self.scene.images.len() - 1, scale, rotation, up })
    }

    /// A metallic–roughness surface's `diffuse_transmission = { factor, color, factor_map,
    /// color_map }` (0 and white when absent; the factor's map read linearly, its first
    /// channel the share's multiplier; the colour's map a texture).
    fn translucency(&mut self, n: &Node) -> R<(Translucency, Option<Texture>, Option<Texture>)> {
        let t = n.table(&["factor", "color", "factor_map", "color_map"])?;
        let factor = t.get("factor").map_or(Ok(0.0), |f| f.in_range(0.0, 1.0))?;
        let color = t.opt_rgb("color", Vec3::ONE)?;
        if !(color.min_element() >= 0.0 && color.max_element() <= 1.0) {
            let node = t.get("color").expect("a colour out of range was given");
            return Err(node.err("`color` is what passing light keeps: a colour within [0, 1]"));
        }
        let factor_map = t.get("factor_map").map(|m| self.linear_placed_image(&m)).transpose()?;
        let color_map = t.get("color_map").map(|m| self.texture(&m)).transpose()?;
        Ok((Translucency { factor, color }, factor_map, color_map))
    }
}

/// Cook–Torrance's `kd` and `ks`: its specular term carries the Fresnel factor, so energy is
/// conserved when `k_d + k_s·F(0) ≤ 1` (at normal incidence; `F` grows towards grazing angles
/// where the microfacet term shrinks) — the course's `k_d + k_s = 1` is the special case of a
/// perfect reflector.
fn fresnel_weights(t: &Table, default_ks: f64) -> R<(f64, f64)> {
    let ks = t.get("ks").map_or(Ok(default_ks), |n| n.in_range(0.0, 1.0))?;
    let kd = t.get("kd").map_or(Ok(1.0 - ks), |n| n.in_range(0.0, 1.0))?;
    let ior = t.opt_positive("ior", 1.5)?;
    let f0 = ((ior - 1.0) / (ior + 1.0)).powi(2);
    if kd + ks * f0 > 1.0 + 1e-9 {
        let node = t.get("kd").or(t.get("ks")).expect("one was given");
        return Err(node.err(format!("kd + ks·F(0) = {} exceeds 1: the surface would create energy", kd + ks * f0)));
    }
    Ok((kd, ks))
}

/// `kd` (1) and `ks` of a layered surface, whose diffuse weight `k_d(1 − k_s·E)` keeps energy
/// whatever they are in `[0, 1]`.
fn layered_weights(t: &Table, default_ks: f64) -> R<(f64, f64)> {
    let ks = t.get("ks").map_or(Ok(default_ks), |n| n.in_range(0.0, 1.0))?;
    let kd = t.get("kd").map_or(Ok(1.0), |n| n.in_range(0.0, 1.0))?;
    Ok((kd, ks))
}

/// `kd` and `ks` with the course's `k_d + k_s ≤ 1`.
fn weights(t: &Table, default_ks: f64) -> R<(f64, f64)> {
    let ks = t.get("ks").map_or(Ok(default_ks), |n| n.in_range(0.0, 1.0))?;
    let kd = t.get("kd").map_or(Ok(1.0 - ks), |n| n.in_range(0.0, 1.0))?;
    if kd + ks > 1.0 + 1e-9 {
        let node = t.get("kd").or(t.get("ks")).expect("one was given");
        return Err(node.err(format!("kd + ks = {} exceeds 1: the surface would create energy", kd + ks)));
    }
    Ok((kd, ks))
}

fn default_facets(alpha: f64) -> Microfacets {
    Microfacets {
        distribution: Distribution::TrowbridgeReitz,
        alpha_u: alpha,
        alpha_v: alpha,
        shadowing: Shadowing::Smith,
    }
}

/// `roughness` (number or `[u, v]`), `distribution`, `shadowing`; `None` for a smooth surface.
fn microfacets(t: &Table) -> R<Option<Microfacets>> {
    let (alpha_u, alpha_v) = match t.get("roughness") {
        None => return Ok(None),
        Some(r) if matches!(r.v, toml::de::DeValue::Array(_)) => {
            let [u, v] = r.numbers::<2>()?;
            if !(0.0..=4.0).contains(&u) || !(0.0..=4.0).contains(&v) {
                return Err(r.err("`roughness`: expected values from 0 to 4"));
            }
            (u, v)
        }
        Some(r) => {
            let a = r.in_range(0.0, 4.0)?;
            (a, a)
        }
    };
    if alpha_u == 0.0 && alpha_v == 0.0 {
        return Ok(None);
    }
    if alpha_u < 1e-4 || alpha_v < 1e-4 {
        let r = t.req("roughness")?;
        return Err(r.err("`roughness` below 1e-4 is numerically a mirror: use 0 for a smooth surface"));
    }
    let distribution = match t.get("distribution") {
        Some(d) => match d.choice(&["beckmann", "trowbridge-reitz", "ggx", "gaussian"])? {
            "beckmann" => Distribution::Beckmann,
            "gaussian" => Distribution::Gaussian,
            _ => Distribution::TrowbridgeReitz,
        },
        None => Distribution::TrowbridgeReitz,
    };
    let shadowing = match t.get("shadowing") {
        Some(s) => match s.choice(&["smith", "cook-torrance"])? {
            "smith" => Shadowing::Smith,
            _ => Shadowing::CookTorrance,
        },
        None if distribution == Distribution::Gaussian => Shadowing::CookTorrance,
        None => Shadowing::Smith,
    };
    if distribution == Distribution::Gaussian {
        if shadowing == Shadowing::Smith {
            let s = t.req("shadowing")?;
            return Err(
                s.err("Smith shadowing has no closed form for the Gaussian distribution; use \"cook-torrance\"")
            );
        }
        if alpha_u != alpha_v {
            return Err(t.req("roughness")?.err("the Gaussian distribution is isotropic: give one roughness"));
        }
    }
    Ok(Some(Microfacets { distribution, alpha_u, alpha_v, shadowing }))
}

fn fresnel(t: &Table) -> R<FresnelMode> {
    Ok(match t.get("fresnel") {
        Some(f) => match f.choice(&["exact", "schlick"])? {
            "exact" => FresnelMode::Exact,
            _ => FresnelMode::Schlick,
        },
        None => FresnelMode::Exact,
    })
}

/// `ior`, `cauchy = [A, B]`, `sellmeier = { b = [..], c = [..] }` or `glass = "bk7"`.
fn ior(t: &Table) -> R<Ior> {
    let given: Vec<Node> = ["ior", "cauchy", "sellmeier", "glass"].iter().filter_map(|k| t.get(k)).collect();
    if given.len() > 1 {
        return Err(given[1].err("give one of `ior`, `cauchy`, `sellmeier` or `glass`"));
    }
    let Some(n) = given.first() else { return Ok(Ior::Constant(1.5)) };
    let ior = match n.key {
        "ior" => Ior::Constant(n.positive()?),
        "cauchy" => {
            let [a, b] = n.numbers::<2>()?;
            Ior::Cauchy { a, b }
        }
        "sellmeier" => {
            let s = n.table(&["b", "c"])?;
            Ior::Sellmeier { b: s.req("b")?.numbers::<3>()?, c: s.req("c")?.numbers::<3>()? }
        }
        _ => {
            let name = n.choice(&names(GLASSES))?;
            let (_, b, c) = GLASSES.iter().find(|e| e.0 == name).expect("a listed glass");
            Ior::Sellmeier { b: *b, c: *c }
        }
    };
    // The visible range must give a real index above zero.
    for lambda in [360.0, 589.3, 830.0] {
        let eta = ior.at(lambda);
        if !(eta.is_finite() && eta > 0.0) {
            return Err(n.err(format!("the index of refraction at {lambda} nm would be {eta}")));
        }
    }
    Ok(ior)
}
