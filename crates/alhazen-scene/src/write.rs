//! Writing a scene as alhazen TOML (docs/scene-format.md), so that a scene imported from
//! another format can be edited: `alhazen convert IN -o OUT.toml`.
//!
//! Meshes go to binary PLY files (double precision, with normals and texture coordinates when
//! they have them) and images to OpenEXR files (linear, 32-bit float) in a folder beside the
//! TOML file; numbers are written in Rust's shortest round-trip form and angles in the degrees
//! whose conversion gives back the same radians where one exists, so reading the file again
//! gives the same scene (tested: `tests/write.rs`).

use crate::bsdf::{Anisotropy, AnisotropyModel, BsdfDesc, Distribution, Ior, Iridescence, Microfacets, Shadowing};
use crate::model::*;
use alhazen_math::{Vec2, Vec3};
use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Why a scene could not be written.
#[derive(Debug)]
pub enum WriteError {
    /// A file could not be written.
    Io(PathBuf, std::io::Error),
    /// The scene holds something the TOML format cannot say.
    Unsupported(String),
}

impl std::fmt::Display for WriteError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Io(p, e) => write!(f, "cannot write {}: {e}", p.display()),
            Self::Unsupported(s) => write!(f, "{s}"),
        }
    }
}

impl std::error::Error for WriteError {}

/// Writes `scene` to `path` as TOML, its meshes and images into the folder `assets` (created;
/// it should be beside `path`, whose file names it records relative to `path`'s folder).
/// `header` is written as comment lines at the top.
pub fn write_scene(scene: &Scene, path: &Path, assets: &Path, header: &str) -> Result<(), WriteError> {
    let base = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    std::fs::create_dir_all(assets).map_err(|e| WriteError::Io(assets.to_path_buf(), e))?;
    let rel = |p: &Path| -> String {
        let r = p.strip_prefix(base).unwrap_or(p);
        r.to_string_lossy().replace('\\', "/")
    };
    let mut images = vec![];
    for (i, img) in scene.images.iter().enumerate() {
        let file = assets.join(format!("image-{i}.exr"));
        write_exr(img, &file)?;
        images.push(rel(&file));
    }
    let mut meshes = vec![];
    for (i, m) in scene.meshes.iter().enumerate() {
        let file = assets.join(format!("mesh-{i}.ply"));
        std::fs::write(&file, ply_bytes(m)).map_err(|e| WriteError::Io(file.clone(), e))?;
        meshes.push(rel(&file));
    }
    let text = to_toml(scene, &images, &meshes, header)?;
    std::fs::write(path, text).map_err(|e| WriteError::Io(path.to_path_buf(), e))
}

/// The TOML text of `scene`, naming image `i` by `images[i]` and mesh `i` by `meshes[i]`.
pub fn to_toml(scene: &Scene, images: &[String], meshes: &[String], header: &str) -> Result<String, WriteError> {
    let wraps = scene.images.iter().map(|i| i.wrap).collect();
    let mut w = Writer { out: String::new(), images, wraps, material_names: vec![] };
    for line in header.lines() {
        let _ = writeln!(w.out, "# {line}");
    }
    w.top(scene);
    w.render(&scene.render);
    w.camera(&scene.camera);
    for l in &scene.lights {
        w.light(l);
    }
    w.materials(scene);
    for (i, name) in meshes.iter().enumerate() {
        let _ = write!(w.out, "\n[meshes.\"mesh-{i}\"]\nfile = {}\n", string(name));
    }
    for o in &scene.objects {
        if !o.mesh_materials.is_empty() {
            return Err(WriteError::Unsupported(format!(
                "object {}: per-face materials of an OBJ file cannot be written as TOML yet",
                o.name.as_deref().unwrap_or("(unnamed)")
            )));
        }
        w.out.push_str("\n[[object]]\n");
        w.object(o, true)?;
    }
    Ok(w.out)
}

struct Writer<'a> {
    out: String,
    images: &'a [String],
    /// Each image's wrap modes (written with the textures that place it).
    wraps: Vec<[Wrap; 2]>,
    material_names: Vec<String>,
}

/// A number as TOML: Rust's shortest representation that reads back to the same bits.
fn num(x: f64) -> String {
    let s = format!("{x:?}");
    if s.contains('.') || s.contains('e') || s.contains("inf") || s.contains("NaN") { s } else { format!("{s}.0") }
}

fn vec3(v: Vec3) -> String {
    format!("[{}, {}, {}]", num(v.x), num(v.y), num(v.z))
}

fn string(s: &str) -> String {
    let mut out = String::from("\"");
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if (c as u32) < 0x20 || c == '\u{7f}' => {
                let _ = write!(out, "\\u{:04X}", c as u32);
            }
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// The degrees that `to_radians` (then `f`) maps back to exactly `f(radians)`, when a few ulps
/// around the conversion find them; else the nearest degrees.
fn degrees(radians: f64, f: impl Fn(f64) -> f64) -> f64 {
    let target = f(radians);
    let mut d = radians.to_degrees();
    if f(d.to_radians()) == target {
        return d;
    }
    for step in 1..=16 {
        for sign in [1.0, -1.0] {
            let mut c = d;
            for _ in 0..step {
                c = if sign > 0.0 { c.next_up() } else { c.next_down() };
            }
            if f(c.to_radians()) == target {
                return c;
            }
        }
    }
    d = radians.to_degrees();
    d
}

impl Writer<'_> {
    fn line(&mut self, key: &str, value: String) {
        let _ = writeln!(self.out, "{key} = {value}");
    }

    fn top(&mut self, s: &Scene) {
        match s.background {
            Background::Solid(c) => self.line("background", vec3(c)),
            Background::Gradient { zenith, horizon, ground } => self.line(
                "background",
                format!("{{ zenith = {}, horizon = {}, ground = {} }}", vec3(zenith), vec3(horizon), vec3(ground)),
            ),
        }
        self.line("ambient", vec3(s.ambient));
    }

    fn render(&mut self, r: &RenderSettings) {
        self.out.push_str("\n[render]\n");
        self.line("width", r.width.to_string());
        self.line("height", r.height.to_string());
        self.line("spp", r.spp.to_string());
        self.line("max_depth", r.max_depth.to_string());
        self.line("seed", r.seed.to_string());
        let integrator = match r.integrator {
            IntegratorKind::Whitted => "whitted",
            IntegratorKind::Path => "path",
            IntegratorKind::Photon => "photon",
            IntegratorKind::Radiosity => "radiosity",
        };
        self.line("integrator", string(integrator));
        let sampler = match r.sampler {
            SamplerKind::Sobol => "sobol",
            SamplerKind::Independent => "independent",
        };
        self.line("sampler", string(sampler));
        match r.light_choice {
            LightChoice::Measured => {}
            LightChoice::Power => self.line("light_choice", string("power")),
            LightChoice::Uniform => self.line("light_choice", string("uniform")),
        }
        if !r.mirror_connections {
            self.line("mirror_connections", "false".to_string());
        }
        if r.filter != PixelFilter::PIXEL {
            self.line("filter", pixel_filter(&r.filter));
        }
    }

    fn look(&mut self, l: &LookAt) {
        self.line("eye", vec3(l.eye));
        self.line("target", vec3(l.target));
        self.line("up", vec3(l.up));
    }

    fn camera(&mut self, c: &CameraDesc) {
        self.out.push_str("\n[camera]\n");
        match c {
            CameraDesc::Perspective { look, opening, lens } => {
                self.line("type", string("perspective"));
                self.look(look);
                if let Some(l) = lens {
                    self.line("aperture", num(l.aperture));
                    self.line("focus_distance", num(l.focus_distance));
                }
                match *opening {
                    PerspectiveOpening::Fov { angle, horizontal } => {
                        self.line("fov", num(degrees(angle, |x| x)));
                        self.line("fov_axis", string(if horizontal { "horizontal" } else { "vertical" }));
                    }
                    PerspectiveOpening::Frustum { lrbtn: [l, r, b, t, n] } => self.line(
                        "frustum",
                        format!(
                            "{{ left = {}, right = {}, bottom = {}, top = {}, near = {} }}",
                            num(l),
                            num(r),
                            num(b),
                            num(t),
                            num(n)
                        ),
                    ),
                }
            }
            CameraDesc::Orthographic { look, width } => {
                self.line("type", string("orthographic"));
                self.look(look);
                self.line("width", num(*width));
            }
            CameraDesc::Axonometric { style, target, width, azimuth } => {
                self.line("type", string("axonometric"));
                let s = match style {
                    Axonometry::Isometric => "isometric",
                    Axonometry::Cavalier => "cavalier",
                    Axonometry::Cabinet => "cabinet",
                    Axonometry::Military => "military",
                };
                self.line("style", string(s));
                self.line("target", vec3(*target));
                self.line("width", num(*width));
                self.line("azimuth", num(degrees(*azimuth, |x| x)));
            }
            CameraDesc::Stereo { look, eye_distance, screen_distance, screen_width } => {
                self.line("type", string("stereo"));
                self.look(look);
                self.line("eye_distance", num(*eye_distance));
                self.line("screen_distance", num(*screen_distance));
                self.line("screen_width", num(*screen_width));
            }
            CameraDesc::Panorama { look, angle } => {
                self.line("type", string("panorama"));
                self.look(look);
                self.line("fov", num(degrees(*angle, |x| x)));
            }
        }
    }

    fn light(&mut self, l: &Light) {
        self.out.push_str("\n[[light]]\n");
        let att = |a: &[f64; 3]| format!("[{}, {}, {}]", num(a[0]), num(a[1]), num(a[2]));
        match l {
            Light::Point { position, intensity, attenuation } => {
                self.line("type", string("point"));
                self.line("position", vec3(*position));
                self.line("intensity", vec3(*intensity));
                self.line("attenuation", att(attenuation));
            }
            Light::Directional { direction, intensity } => {
                self.line("type", string("directional"));
                self.line("direction", vec3(*direction));
                self.line("intensity", vec3(*intensity));
            }
            Light::Spot { position, direction, cos_cutoff, falloff, beam, intensity, attenuation } => {
                self.line("type", string("spot"));
                self.line("position", vec3(*position));
                self.line("direction", vec3(*direction));
                self.line("angle", num(degrees(cos_cutoff.acos(), f64::cos)));
                if let Some(beam) = beam {
                    self.line("beam", num(degrees(beam.cos.acos(), f64::cos)));
                    let fade = match beam.fade {
                        crate::SpotFade::LinearAngle => "angle",
                        crate::SpotFade::SmoothCosine => "smooth",
                        crate::SpotFade::SquaredCosine => "squared",
                    };
                    self.line("fade", string(fade));
                }
                self.line("falloff", num(*falloff));
                self.line("intensity", vec3(*intensity));
                self.line("attenuation", att(attenuation));
            }
            Light::Environment { image, scale, rotation, up } => {
                self.line("type", string("environment"));
                self.line("file", string(&self.images[*image].clone()));
                self.line("scale", num(*scale));
                self.line("rotate_y", num(degrees(*rotation, |x| x)));
                if *up != Vec3::Y {
                    self.line("up", vec3(*up));
                }
            }
        }
    }

    fn materials(&mut self, s: &Scene) {
        let mut used: HashMap<String, usize> = HashMap::new();
        for (i, m) in s.materials.iter().enumerate() {
            let base = if i == 0 && *m == Material::default() { "default".to_string() } else { m.name.clone() };
            let n = used.entry(base.clone()).or_insert(0);
            *n += 1;
            let name = if *n == 1 { base } else { format!("{base} {n}") };
            self.material_names.push(name.clone());
            if i == 0 && *m == Material::default() {
                continue;
            }
            let _ = write!(self.out, "\n[materials.{}]\n", string(&name));
            self.material(m);
        }
    }

    fn texture(&self, t: &Texture) -> String {
        match t {
            Texture::Solid(c) => vec3(*c),
            Texture::Checker { even, odd, size } => {
                format!("{{ checker = {{ even = {}, odd = {}, size = {} }} }}", vec3(*even), vec3(*odd), num(*size))
            }
            Texture::Image { image, scale, offset, rotation } => {
                format!("{{ image = {} }}", self.placed_image(*image, *scale, *offset, *rotation))
            }
        }
    }

    /// [`Self::image`] turned by `rotation` and shifted by `offset` (each written only where it
    /// is not zero).
    fn placed_image(&self, image: usize, scale: Vec2, offset: Vec2, rotation: f64) -> String {
        let mut table = self.image(image, scale).trim_end_matches(" }").to_string();
        if rotation != 0.0 {
            table += &format!(", rotation = {}", num(rotation));
        }
        if offset != Vec2::ZERO {
            table += &format!(", offset = [{}, {}]", num(offset.x), num(offset.y));
        }
        match self.wraps.get(image).copied().unwrap_or_default() {
            [Wrap::Repeat, Wrap::Repeat] => {}
            [u, v] if u == v => table += &format!(", wrap = {}", string(u.name())),
            [u, v] => table += &format!(", wrap = [{}, {}]", string(u.name()), string(v.name())),
        }
        table + " }"
    }

    /// A map's image table (`{ file, scale, … }`: metallic–roughness and normal maps are
    /// images).
    /// A metallic–roughness surface's `anisotropy` entry (after a comma), empty when isotropic
    /// and unmapped.
    fn anisotropy_entry(&self, a: &Anisotropy, map: Option<&Texture>) -> String {
        if *a == Anisotropy::default() && map.is_none() {
            return String::new();
        }
        let model = match a.model {
            AnisotropyModel::Gltf => "gltf",
            AnisotropyModel::Disney => "disney",
        };
        format!(
            ", anisotropy = {{ strength = {}, rotation = {}, model = \"{model}\"{} }}",
            num(a.strength),
            num(degrees(a.rotation, |x| x)),
            map.map_or(String::new(), |m| format!(", map = {}", self.map_image(m)))
        )
    }

    fn iridescence_entry(&self, i: &Iridescence) -> String {
        let map = |key: &str, m: &Option<Texture>| {
            m.as_ref().map_or(String::new(), |m| format!(", {key} = {}", self.map_image(m)))
        };
        format!(
            ", iridescence = {{ factor = {}, ior = {}, thickness = [{}, {}], outside = {}{}{} }}",
            num(i.factor),
            num(i.ior),
            num(i.thickness[0]),
            num(i.thickness[1]),
            num(i.outside),
            map("factor_map", &i.factor_map),
            map("thickness_map", &i.thickness_map)
        )
    }

    fn map_image(&self, map: &Texture) -> String {
        match map {
            Texture::Image { image, scale, offset, rotation } => self.placed_image(*image, *scale, *offset, *rotation),
            // (The readers make images only; another texture is written as a texture.)
            other => self.texture(other),
        }
    }

    fn image(&self, image: usize, scale: Vec2) -> String {
        format!("{{ file = {}, scale = [{}, {}] }}", string(&self.images[image]), num(scale.x), num(scale.y))
    }

    fn material(&mut self, m: &Material) {
        let color = self.texture(&m.color);
        self.line("color", color);
        self.line("diffuse", num(m.diffuse));
        self.line("specular", vec3(m.specular));
        self.line("shininess", num(m.shininess));
        self.line("highlight", string(if m.highlight == Highlight::Phong { "phong" } else { "blinn-phong" }));
        self.line("anisotropy", num(m.anisotropy));
        self.line("scratches", vec3(m.scratches));
        self.line("mirror", vec3(m.mirror));
        self.line("transparency", vec3(m.transparency));
        self.line("ior", num(m.ior));
        self.line("absorption", vec3(m.absorption));
        self.line("fresnel", string(fresnel(m.fresnel)));
        match &m.emission_texture {
            Some(t) => {
                let t = self.texture(t);
                self.line("emission", t);
            }
            None => self.line("emission", vec3(m.emission)),
        }
        if let Some(b) = &m.bump {
            let pattern = match &b.pattern {
                BumpPattern::Waves { size } => format!("waves = {}", num(*size)),
                BumpPattern::Image { image, scale } => format!("image = {}", self.image(*image, *scale)),
                BumpPattern::NormalMap { map } => format!("normal_map = {}", self.map_image(map)),
            };
            self.line("bump", format!("{{ height = {}, {pattern} }}", num(b.height)));
        }
        if let Some(b) = &m.bsdf {
            let t = self.bsdf(b);
            self.line("bsdf", t);
        }
        if m.one_sided {
            self.line("one_sided", "true".to_string());
        }
        if m.vertex_colors {
            self.line("vertex_colors", "true".to_string());
        }
        if let Some(a) = &m.alpha {
            let cutoff = a.cutoff.map_or(String::new(), |c| format!(", cutoff = {}", num(c)));
            let text = match &a.coverage {
                Texture::Image { image, scale, offset, rotation } => {
                    format!("{{ image = {}{cutoff} }}", self.placed_image(*image, *scale, *offset, *rotation))
                }
                // A constant coverage with a cutoff is all there or not at all.
                other => {
                    let a0 = crate::texture::mean(other, &[]).x;
                    num(a.cutoff.map_or(a0, |c| if a0 >= c { 1.0 } else { 0.0 }))
                }
            };
            self.line("alpha", text);
        }
    }

    fn bsdf(&self, b: &BsdfDesc) -> String {
        let facets = |f: &Option<Microfacets>| match f {
            None => "roughness = 0.0".to_string(),
            Some(f) => {
                let d = match f.distribution {
                    Distribution::Beckmann => "beckmann",
                    Distribution::TrowbridgeReitz => "trowbridge-reitz",
                    Distribution::Gaussian => "gaussian",
                };
                let s = if f.shadowing == Shadowing::Smith { "smith" } else { "cook-torrance" };
                format!(
                    "roughness = [{}, {}], distribution = \"{d}\", shadowing = \"{s}\"",
                    num(f.alpha_u),
                    num(f.alpha_v)
                )
            }
        };
        match b {
            BsdfDesc::Lambert { albedo } => format!("{{ type = \"lambert\", color = {} }}", self.texture(albedo)),
            BsdfDesc::OrenNayar { albedo, sigma, interreflection } => format!(
                "{{ type = \"oren-nayar\", color = {}, sigma = {}, interreflection = {interreflection} }}",
                self.texture(albedo),
                num(degrees(*sigma, |x| x))
            ),
            BsdfDesc::Phong { albedo, kd, ks, exponent } => format!(
                "{{ type = \"phong\", color = {}, kd = {}, ks = {}, exponent = {} }}",
                self.texture(albedo),
                num(*kd),
                num(*ks),
                num(*exponent)
            ),
            BsdfDesc::BlinnPhong { albedo, kd, ks, exponent, anisotropy, scratches } => format!(
                "{{ type = \"blinn-phong\", color = {}, kd = {}, ks = {}, exponent = {}, anisotropy = {}, scratches = {} }}",
                self.texture(albedo),
                num(*kd),
                num(*ks),
                num(*exponent),
                num(*anisotropy),
                vec3(*scratches)
            ),
            BsdfDesc::CookTorrance { albedo, kd, ks, facets: f, ior, fresnel: fr, layered, transmittance } => {
                let through = match transmittance {
                    Texture::Solid(c) if *c == Vec3::ZERO => String::new(),
                    other => format!(", transmittance = {}", self.texture(other)),
                };
                format!(
                    "{{ type = \"cook-torrance\", color = {}, kd = {}, ks = {}, ior = {}, fresnel = \"{}\", layered = {layered}, {}{through} }}",
                    self.texture(albedo),
                    num(*kd),
                    num(*ks),
                    num(*ior),
                    fresnel(*fr),
                    facets(&Some(*f))
                )
            }
            BsdfDesc::Plastic { albedo, ior, facets: f, nonlinear } => format!(
                "{{ type = \"plastic\", color = {}, ior = {}, nonlinear = {nonlinear}, {} }}",
                self.texture(albedo),
                num(*ior),
                facets(f)
            ),
            BsdfDesc::Conductor { facets: f, eta, k, tint, fresnel: fr, multiscatter } => format!(
                "{{ type = \"conductor\", eta = {}, k = {}, tint = {}, fresnel = \"{}\", {}{} }}",
                vec3(*eta),
                vec3(*k),
                vec3(*tint),
                fresnel(*fr),
                facets(f),
                if *multiscatter { ", multiscatter = true" } else { "" }
            ),
            BsdfDesc::ThinDielectric { ior } => format!("{{ type = \"thin-dielectric\", ior = {} }}", num(*ior)),
            BsdfDesc::Dielectric { facets: f, ior, fresnel: fr, transmittance, film } => {
                let ior = match ior {
                    Ior::Constant(x) => format!("ior = {}", num(*x)),
                    Ior::Cauchy { a, b } => format!("cauchy = [{}, {}]", num(*a), num(*b)),
                    Ior::Sellmeier { b, c } => format!(
                        "sellmeier = {{ b = [{}, {}, {}], c = [{}, {}, {}] }}",
                        num(b[0]),
                        num(b[1]),
                        num(b[2]),
                        num(c[0]),
                        num(c[1]),
                        num(c[2])
                    ),
                };
                let tint = match transmittance {
                    Texture::Solid(c) if *c == Vec3::ONE => String::new(),
                    other => format!(", transmittance = {}", self.texture(other)),
                };
                let film = film.as_ref().map_or(String::new(), |i| self.iridescence_entry(i));
                format!("{{ type = \"dielectric\", {ior}, fresnel = \"{}\", {}{tint}{film} }}", fresnel(*fr), facets(f))
            }
            BsdfDesc::Mix { a, b, weight, weight_map } => {
                let map = weight_map.as_ref().map_or(String::new(), |t| format!(", weight_map = {}", self.texture(t)));
                format!(
                    "{{ type = \"mix\", a = {}, b = {}, weight = {}{map} }}",
                    self.bsdf(a),
                    self.bsdf(b),
                    num(*weight)
                )
            }
            BsdfDesc::Sheened { base, color, roughness, roughness_map } => format!(
                "{{ type = \"sheen\", base = {}, sheen_color = {}, roughness = {}{} }}",
                self.bsdf(base),
                self.texture(color),
                num(*roughness),
                roughness_map.as_ref().map_or(String::new(), |m| format!(", roughness_map = {}", self.map_image(m)))
            ),
            BsdfDesc::Coated { base, weight, facets: f, ior, weight_map, roughness_map } => {
                let map = |key: &str, m: &Option<Texture>| {
                    m.as_ref().map_or(String::new(), |m| format!(", {key} = {}", self.map_image(m)))
                };
                format!(
                    "{{ type = \"coated\", base = {}, weight = {}, ior = {}, {}{}{} }}",
                    self.bsdf(base),
                    num(*weight),
                    num(*ior),
                    facets(&Some(*f)),
                    map("weight_map", weight_map),
                    map("roughness_map", roughness_map)
                )
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
                let through = if translucency.factor == 0.0 {
                    String::new()
                } else {
                    format!(
                        ", diffuse_transmission = {{ factor = {}, color = {}{}{} }}",
                        num(translucency.factor),
                        vec3(translucency.color),
                        translucency_map
                            .as_ref()
                            .map_or(String::new(), |m| format!(", factor_map = {}", self.map_image(m))),
                        translucency_color_map
                            .as_ref()
                            .map_or(String::new(), |m| format!(", color_map = {}", self.texture(m)))
                    )
                };
                format!(
                    "{{ type = \"metallic-roughness\", color = {}, metallic = {}, roughness = {}, ior = {}{}{}{}{}{}{}{}{through} }}",
                    self.texture(base),
                    num(*metallic),
                    num(*roughness),
                    num(*ior),
                    if *specular == 1.0 { String::new() } else { format!(", specular = {}", num(*specular)) },
                    if *multiscatter { ", multiscatter = true" } else { "" },
                    map.as_ref().map_or(String::new(), |m| format!(", map = {}", self.map_image(m))),
                    self.anisotropy_entry(anisotropy, anisotropy_map.as_ref()),
                    iridescence.as_ref().map_or(String::new(), |i| self.iridescence_entry(i)),
                    specular_map.as_ref().map_or(String::new(), |m| format!(", specular_map = {}", self.map_image(m))),
                    specular_color_map
                        .as_ref()
                        .map_or(String::new(), |m| format!(", specular_color_map = {}", self.texture(m)))
                )
            }
        }
    }

    /// An object's keys (the table header is written by the caller).
    fn object(&mut self, o: &Object, with_material: bool) -> Result<(), WriteError> {
        if let Some(n) = &o.name {
            self.line("name", string(n));
        }
        match &o.shape {
            Shape::Sphere { center, radius } => {
                self.line("shape", string("sphere"));
                self.line("center", vec3(*center));
                self.line("radius", num(*radius));
            }
            Shape::Cylinder { base, top, radius, capped } => {
                self.line("shape", string("cylinder"));
                self.line("base", vec3(*base));
                self.line("top", vec3(*top));
                self.line("radius", num(*radius));
                self.line("capped", capped.to_string());
            }
            Shape::Cone { base, apex, radius, capped } => {
                self.line("shape", string("cone"));
                self.line("base", vec3(*base));
                self.line("apex", vec3(*apex));
                self.line("radius", num(*radius));
                self.line("capped", capped.to_string());
            }
            Shape::Disk { center, normal, radius } => {
                self.line("shape", string("disk"));
                self.line("center", vec3(*center));
                self.line("normal", vec3(*normal));
                self.line("radius", num(*radius));
            }
            Shape::Plane { point, normal } => {
                self.line("shape", string("plane"));
                self.line("point", vec3(*point));
                self.line("normal", vec3(*normal));
            }
            Shape::Box { min, max } => {
                self.line("shape", string("box"));
                self.line("min", vec3(*min));
                self.line("max", vec3(*max));
            }
            Shape::Mesh { mesh, smooth } => {
                self.line("shape", string("mesh"));
                self.line("mesh", string(&format!("mesh-{mesh}")));
                self.line("smooth", smooth.to_string());
            }
            Shape::Csg { op, a, b } => {
                self.line("shape", string("csg"));
                let op = match op {
                    CsgOp::Union => "union",
                    CsgOp::Intersection => "intersection",
                    CsgOp::Difference => "difference",
                };
                self.line("op", string(op));
                let (a, b) = (self.inline_object(a)?, self.inline_object(b)?);
                self.line("a", a);
                self.line("b", b);
            }
        }
        if !o.transform.is_identity() {
            let m = o.transform.matrix();
            let rows: Vec<String> = (0..4)
                .map(|r| {
                    let row = m.row(r);
                    format!("[{}, {}, {}, {}]", num(row.x), num(row.y), num(row.z), num(row.w))
                })
                .collect();
            self.line("transform", format!("[{{ matrix = [{}] }}]", rows.join(", ")));
        }
        if with_material && o.material != 0 {
            let name = self.material_names[o.material as usize].clone();
            self.line("material", string(&name));
        }
        Ok(())
    }

    /// A CSG operand as an inline table (its material is the CSG's).
    fn inline_object(&mut self, o: &Object) -> Result<String, WriteError> {
        let saved = std::mem::take(&mut self.out);
        self.object(o, false)?;
        let body = std::mem::replace(&mut self.out, saved);
        Ok(format!("{{ {} }}", body.lines().collect::<Vec<_>>().join(", ")))
    }
}

fn fresnel(f: FresnelMode) -> &'static str {
    match f {
        FresnelMode::Exact => "exact",
        FresnelMode::Schlick => "schlick",
        FresnelMode::Off => "off",
    }
}

/// A mesh as binary little-endian PLY in double precision.
pub fn ply_bytes(m: &alhazen_geom::TriangleMesh) -> Vec<u8> {
    let mut h = format!(
        "ply\nformat binary_little_endian 1.0\ncomment written by alhazen\nelement vertex {}\nproperty double x\nproperty double y\nproperty double z\n",
        m.positions.len()
    );
    if !m.normals.is_empty() {
        h.push_str("property double nx\nproperty double ny\nproperty double nz\n");
    }
    if !m.uvs.is_empty() {
        h.push_str("property double u\nproperty double v\n");
    }
    // Linear colours in floating point (read back as they are, not as sRGB codes).
    if !m.colors.is_empty() {
        h.push_str("property double red\nproperty double green\nproperty double blue\n");
    }
    let _ = write!(h, "element face {}\nproperty list uchar uint vertex_indices\nend_header\n", m.triangles.len());
    let mut out = h.into_bytes();
    for i in 0..m.positions.len() {
        let mut put = |x: f64| out.extend(x.to_le_bytes());
        m.positions[i].to_array().into_iter().for_each(&mut put);
        if !m.normals.is_empty() {
            m.normals[i].to_array().into_iter().for_each(&mut put);
        }
        if !m.uvs.is_empty() {
            m.uvs[i].to_array().into_iter().for_each(&mut put);
        }
        if !m.colors.is_empty() {
            m.colors[i].to_array().into_iter().for_each(&mut put);
        }
    }
    for t in &m.triangles {
        out.push(3);
        t.iter().for_each(|i| out.extend(i.to_le_bytes()));
    }
    out
}

fn write_exr(img: &ImageData, path: &Path) -> Result<(), WriteError> {
    let flat: Vec<f32> = img.texels().flatten().collect();
    let buf = image::Rgb32FImage::from_raw(img.width, img.height, flat)
        .ok_or_else(|| WriteError::Unsupported(format!("image {}: size and pixels disagree", path.display())))?;
    buf.save_with_format(path, image::ImageFormat::OpenExr)
        .map_err(|e| WriteError::Io(path.to_path_buf(), std::io::Error::other(e)))
}

/// A pixel filter as an inline table that reads back to the same numbers.
fn pixel_filter(f: &PixelFilter) -> String {
    let radius = |[x, y]: [f64; 2]| if x == y { num(x) } else { format!("[{}, {}]", num(x), num(y)) };
    match *f {
        PixelFilter::Box { radius: r } => format!("{{ type = \"box\", radius = {} }}", radius(r)),
        PixelFilter::Tent { radius: r } => format!("{{ type = \"tent\", radius = {} }}", radius(r)),
        PixelFilter::BlackmanHarris { radius: r } => {
            format!("{{ type = \"blackman-harris\", radius = {} }}", radius(r))
        }
        PixelFilter::Gaussian { sigma, radius: r } => {
            format!("{{ type = \"gaussian\", sigma = {}, radius = {} }}", num(sigma), radius(r))
        }
        PixelFilter::Mitchell { b, c, radius: r } => {
            format!("{{ type = \"mitchell\", b = {}, c = {}, radius = {} }}", num(b), num(c), radius(r))
        }
        PixelFilter::Lanczos { tau, radius: r } => {
            format!("{{ type = \"lanczos\", tau = {}, radius = {} }}", num(tau), radius(r))
        }
    }
}
