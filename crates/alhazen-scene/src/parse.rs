//! The native scene format (TOML), documented field by field in `docs/scene-format.md`.

use crate::diagnostic::did_you_mean;
use crate::model::*;
use crate::reader::{Node, R, Src, Table};
use crate::{SceneError, import};
use alhazen_math::{Mat4, Transform, Vec2, Vec3};
use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;
use toml::de::DeTable;

/// Largest image side accepted, and largest pixel count: beyond these the film cannot be
/// allocated on an ordinary machine, so we refuse before trying.
pub const MAX_SIDE: u64 = 1 << 16;
/// See [`MAX_SIDE`].
pub const MAX_PIXELS: u64 = 1 << 28;

pub(crate) const TOP_KEYS: &[&str] =
    &["render", "camera", "background", "ambient", "light", "materials", "meshes", "groups", "object"];

/// Parses scene text; `file` names it in messages and anchors relative paths. Geometry the
/// scene generates (subdivision) may take [`DEFAULT_MEMORY_BUDGET`](crate::DEFAULT_MEMORY_BUDGET).
pub fn parse_scene(file: &Path, text: &str) -> Result<Scene, SceneError> {
    parse_scene_within(file, text, crate::DEFAULT_MEMORY_BUDGET)
}

/// [`parse_scene`], refusing (with the location) generated geometry that would take more than
/// `memory_budget` bytes, before allocating it.
pub fn parse_scene_within(file: &Path, text: &str, memory_budget: u64) -> Result<Scene, SceneError> {
    parse_scene_reporting(file, text, memory_budget).map(|(scene, _)| scene)
}

/// [`parse_scene_within`] with the warnings: what was read only in part (an OBJ file's missing
/// material library), each naming its file.
pub fn parse_scene_reporting(file: &Path, text: &str, memory_budget: u64) -> Result<(Scene, Vec<String>), SceneError> {
    let src = Src { file, text };
    let root = DeTable::parse(text).map_err(|e| {
        let span = e.span().unwrap_or(0..0);
        let mut msg = e.message().lines().next().unwrap_or("invalid TOML").trim_end_matches('.').to_string();
        if msg.contains("recurs") {
            msg =
                "tables nested too deeply for the TOML reader (CSG operands and groups nest at most 64 levels)".into();
        }
        if let Some(c) =
            text.get(span.start..).and_then(|t| t.chars().next()).filter(|c| c.is_control() && !c.is_whitespace())
        {
            msg += &format!(
                " (the file has a control character here, U+{:04X}{})",
                c as u32,
                if c == '\0' { ", a NUL byte" } else { "" }
            );
        }
        SceneError::Syntax(Box::new(crate::Diagnostic::at(file, text, span, format!("TOML syntax error: {msg}"))))
    })?;
    let top = Table { src, t: root.get_ref(), span: root.span(), name: "scene", scope: None };
    let dir = file.parent().unwrap_or(Path::new("."));
    let mut p = Parser {
        dir,
        preloaded: preload_meshes(dir, root.get_ref()),
        scene: empty_scene(),
        material_names: HashMap::new(),
        mesh_names: HashMap::new(),
        mesh_files: HashMap::new(),
        memory_budget,
        warnings: Vec::new(),
    };
    p.scene_from(&top).map_err(SceneError::Syntax)?;
    Ok((p.scene, p.warnings))
}

/// Every mesh file the scene's tables name (`file = "….obj"`, `.ply` or `.bpt`, relative to
/// `dir`), read together on all threads before the walk, which takes each where it meets it:
/// a scene of many meshes (as `alhazen convert` writes) loads in a fraction of the time. What
/// cannot be read is kept as its error, reported where the walk meets the file, so errors come
/// in document order as when each file was read in turn.
fn preload_meshes(
    dir: &Path,
    root: &toml::de::DeTable,
) -> HashMap<std::path::PathBuf, Result<import::LoadedMesh, String>> {
    use rayon::prelude::*;
    fn walk(v: &toml::de::DeValue, dir: &Path, out: &mut Vec<std::path::PathBuf>) {
        match v {
            toml::de::DeValue::Table(t) => {
                for (key, value) in t.iter() {
                    if let (true, toml::de::DeValue::String(name)) = (key.get_ref() == "file", value.get_ref()) {
                        let ext =
                            Path::new(name.as_ref()).extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
                        if matches!(ext.as_deref(), Some("obj" | "ply" | "bpt")) {
                            out.push(dir.join(name.as_ref()));
                        }
                    }
                    walk(value.get_ref(), dir, out);
                }
            }
            toml::de::DeValue::Array(a) => a.iter().for_each(|v| walk(v.get_ref(), dir, out)),
            _ => {}
        }
    }
    let mut paths = Vec::new();
    for (_, value) in root.iter() {
        walk(value.get_ref(), dir, &mut paths);
    }
    let mut seen = std::collections::HashSet::new();
    paths.retain(|p| seen.insert(p.clone()));
    // One file gains nothing from the threads: the walk reads it.
    if paths.len() < 2 {
        return HashMap::new();
    }
    paths
        .into_par_iter()
        .map(|p| {
            let loaded = import::load_mesh(&p);
            (p, loaded)
        })
        .collect()
}

/// The scene an empty file describes: default render settings, a camera at `(0, 0, 5)` looking
/// at the origin, a black background, the default material and nothing else.
pub fn empty_scene() -> Scene {
    Scene {
        render: RenderSettings::default(),
        camera: CameraDesc::Perspective {
            look: LookAt { eye: Vec3::new(0.0, 0.0, 5.0), target: Vec3::ZERO, up: Vec3::Y },
            opening: PerspectiveOpening::Fov { angle: 45f64.to_radians(), horizontal: true },
            lens: None,
        },
        background: Background::Solid(Vec3::ZERO),
        ambient: Vec3::ZERO,
        lights: vec![],
        materials: vec![Material::default()],
        objects: vec![],
        meshes: vec![],
        images: vec![],
    }
}

pub(crate) struct Parser<'a> {
    pub(crate) dir: &'a Path,
    pub(crate) scene: Scene,
    material_names: HashMap<String, MaterialId>,
    mesh_names: HashMap<String, (usize, Vec<MaterialId>)>,
    /// Mesh files already loaded (a group instanced many times shares its meshes).
    mesh_files: HashMap<std::path::PathBuf, (usize, Vec<MaterialId>)>,
    /// Mesh files read before the walk ([`preload_meshes`]), each taken when the walk meets it.
    preloaded: HashMap<std::path::PathBuf, Result<import::LoadedMesh, String>>,
    /// Bytes that generated geometry may take.
    pub(crate) memory_budget: u64,
    /// What was read only in part.
    pub(crate) warnings: Vec<String>,
}

impl Parser<'_> {
    fn scene_from(&mut self, top: &Table) -> R<()> {
        top.check_keys(TOP_KEYS)?;
        if let Some(n) = top.get("render") {
            self.scene.render = render_settings(&n)?;
        }
        if let Some(n) = top.get("camera") {
            self.scene.camera = camera(&n)?;
        }
        if let Some(n) = top.get("background") {
            self.scene.background = background(&n)?;
        }
        self.scene.ambient = top.opt_rgb("ambient", Vec3::ZERO)?;
        if let Some(n) = top.get("materials") {
            let t = n.table_any()?;
            for (name, _) in t.keys() {
                let m = t.get(name).expect("key listed");
                let mat = self.material(&m, name)?;
                self.add_material(name, mat);
            }
        }
        if let Some(n) = top.get("meshes") {
            let t = n.table_any()?;
            for (name, _) in t.keys() {
                let m = t.get(name).expect("key listed");
                let mesh = self.mesh_decl(&m)?;
                self.mesh_names.insert(name.to_string(), mesh);
            }
        }
        for n in top.get("light").map(|n| n.array()).transpose()?.unwrap_or_default() {
            let l = match n.table_any()?.get("type") {
                Some(k) if k.str()? == "environment" => self.environment_light(&n)?,
                _ => light(&n)?,
            };
            self.scene.lights.push(l);
        }
        let groups = crate::graph::Groups::of(top)?;
        for n in top.get("object").map(|n| n.array()).transpose()?.unwrap_or_default() {
            let objects = self.objects_of(&n, &groups, &mut vec![], Transform::IDENTITY)?;
            self.scene.objects.extend(objects);
        }
        Ok(())
    }

    fn add_material(&mut self, name: &str, mat: Material) -> MaterialId {
        let id = self.scene.materials.len() as MaterialId;
        self.scene.materials.push(mat);
        self.material_names.insert(name.to_string(), id);
        id
    }

    fn material(&mut self, n: &Node, name: &str) -> R<Material> {
        const KEYS: &[&str] = &[
            "color",
            "diffuse",
            "specular",
            "shininess",
            "highlight",
            "mirror",
            "transparency",
            "ior",
            "absorption",
            "fresnel",
            "emission",
            "bsdf",
            "bump",
            "anisotropy",
            "scratches",
            "one_sided",
            "alpha",
            "vertex_colors",
        ];
        let t = n.table(KEYS)?;
        let plain = Material::default();
        let given = t.get("color").map(|c| self.texture(&c)).transpose()?;
        let bsdf = t.get("bsdf").map(|b| self.bsdf(&b, given.as_ref().unwrap_or(&plain.color))).transpose()?;
        // The Whitted and preview coefficients not given follow the BSDF.
        let d = bsdf.clone().map_or(plain, |b| Material::from_bsdf(name, b));
        let color = given.unwrap_or_else(|| d.color.clone());
        let (emission, emission_texture) = match t.get("emission") {
            Some(e) => self.emission(&e)?,
            None => (d.emission, None),
        };
        Ok(Material {
            name: name.to_string(),
            color,
            diffuse: t.get("diffuse").map_or(Ok(d.diffuse), |n| n.non_negative())?,
            specular: t.opt_rgb("specular", d.specular)?,
            shininess: t.get("shininess").map_or(Ok(d.shininess), |n| n.non_negative())?,
            highlight: match t.get("highlight") {
                Some(h) => match h.choice(&["phong", "blinn-phong"])? {
                    "phong" => Highlight::Phong,
                    _ => Highlight::BlinnPhong,
                },
                None => d.highlight,
            },
            mirror: t.opt_rgb("mirror", d.mirror)?,
            transparency: unit_rgb(&t, "transparency", d.transparency)?,
            ior: t.get("ior").map_or(Ok(d.ior), |n| n.positive())?,
            absorption: t.opt_rgb("absorption", d.absorption)?,
            fresnel: match t.get("fresnel") {
                Some(f) => match f.choice(&["exact", "schlick", "off"])? {
                    "exact" => FresnelMode::Exact,
                    "schlick" => FresnelMode::Schlick,
                    _ => FresnelMode::Off,
                },
                None => d.fresnel,
            },
            anisotropy: t.get("anisotropy").map_or(Ok(d.anisotropy), |n| n.in_range(1e-3, 1.0))?,
            scratches: t.get("scratches").map_or(Ok(d.scratches), |n| n.unit_vec3())?,
            emission,
            emission_texture,
            bsdf,
            bump: t.get("bump").map(|b| self.bump(&b)).transpose()?,
            one_sided: t.opt_bool("one_sided", false)?,
            vertex_colors: t.opt_bool("vertex_colors", false)?,
            alpha: t.get("alpha").map(|a| self.alpha(&a)).transpose()?,
        })
    }

    /// `alpha = a` (a coverage in `[0, 1]`, stochastic) or `alpha = { image = { file, scale },
    /// cutoff = c }` (the image's alpha channel, or its first where it has none; with `cutoff`,
    /// present where the coverage is at least `c`, else stochastic).
    fn alpha(&mut self, n: &Node) -> R<Alpha> {
        if !n.is_table() {
            return Ok(Alpha { coverage: Texture::Solid(Vec3::splat(n.in_range(0.0, 1.0)?)), cutoff: None });
        }
        let t = n.table(&["image", "cutoff"])?;
        // The cutoff is checked before the image is read.
        let cutoff = t.get("cutoff").map(|c| c.in_range(0.0, 1.0)).transpose()?;
        let Some(i) = t.get("image") else {
            return Err(n.err("`alpha`: expected a coverage in [0, 1] or { image = { file = … }, cutoff = c }"));
        };
        let (image, scale, offset, rotation) = self.image_file(&i, true, import::load_coverage)?;
        Ok(Alpha { coverage: Texture::Image { image, scale, offset, rotation }, cutoff })
    }

    /// `{ file = "x.png", scale = s or [u, v] }`: a repeated image (its index and scale); PNG and
    /// JPEG are sRGB unless `linear` (normal maps), EXR and HDR always linear.
    pub(crate) fn image_texture(&mut self, i: &Node, linear: bool) -> R<(usize, Vec2)> {
        self.image_of(i, linear, false).map(|(image, scale, ..)| (image, scale))
    }

    /// [`Self::image_texture`] of a colour, which may be turned and shifted too: `{ file, scale,
    /// rotation = degrees, offset = [u, v] }` (the image read at `R(rotation) · (uv · scale) +
    /// offset`).
    fn placed_image(&mut self, i: &Node) -> R<Texture> {
        let (image, scale, offset, rotation) = self.image_of(i, false, true)?;
        Ok(Texture::Image { image, scale, offset, rotation })
    }

    /// [`Self::placed_image`] read linearly (metallic–roughness maps, normal maps).
    pub(crate) fn linear_placed_image(&mut self, i: &Node) -> R<Texture> {
        let (image, scale, offset, rotation) = self.image_of(i, true, true)?;
        Ok(Texture::Image { image, scale, offset, rotation })
    }

    /// An image table (with an `offset` and a `rotation` where `placed` allows), read linearly
    /// or as sRGB.
    fn image_of(&mut self, i: &Node, linear: bool, placed: bool) -> R<(usize, Vec2, Vec2, f64)> {
        self.image_file(i, placed, |path| {
            let linear = linear
                || matches!(
                    path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref(),
                    Some("exr" | "hdr" | "pfm")
                );
            if linear { import::load_hdr_image(path) } else { import::load_image(path) }
        })
    }

    /// `{ file = "x.png", scale = s or [u, v] }` (and `offset = [u, v]`, `rotation = degrees`,
    /// `wrap = mode or [u, v]` where `placed` allows) read by `load`: the image's index (read
    /// with its wrap), scale, offset and rotation.
    fn image_file(
        &mut self,
        i: &Node,
        placed: bool,
        load: impl FnOnce(&std::path::Path) -> Result<crate::ImageData, String>,
    ) -> R<(usize, Vec2, Vec2, f64)> {
        let i = i.table(if placed { &["file", "scale", "offset", "rotation", "wrap"] } else { &["file", "scale"] })?;
        let file = i.req("file")?;
        let path = self.dir.join(file.str()?);
        // The scale is checked before the image is read.
        let scale = match i.get("scale") {
            Some(s) if s.is_table() => return Err(s.err("`scale`: expected a number or [u, v]")),
            Some(s) => match s.v {
                toml::de::DeValue::Array(_) => Vec2::from_array(s.numbers::<2>()?),
                _ => Vec2::splat(s.positive()?),
            },
            None => Vec2::ONE,
        };
        let offset = i.get("offset").map_or(Ok(Vec2::ZERO), |o| o.numbers::<2>().map(Vec2::from_array))?;
        let rotation = i.get("rotation").map_or(Ok(0.0), |r| r.in_range(-36000.0, 36000.0))?;
        let wrap = match i.get("wrap") {
            None => [crate::Wrap::Repeat; 2],
            Some(w) if w.is_array() => {
                let items = w.array()?;
                if items.len() != 2 {
                    return Err(w.err("`wrap`: expected a mode or [u, v] modes"));
                }
                [wrap_mode(&items[0])?, wrap_mode(&items[1])?]
            }
            Some(w) => [wrap_mode(&w)?; 2],
        };
        let data = load(&path).map_err(|e| file.err(e))?.with_wrap(wrap);
        self.scene.images.push(Arc::new(data));
        Ok((self.scene.images.len() - 1, scale, offset, rotation))
    }

    /// `bump = { height = h, waves = size }` or `bump = { height = h, image = { file, scale } }`.
    fn bump(&mut self, n: &Node) -> R<Bump> {
        let t = n.table(&["height", "waves", "image", "normal_map"])?;
        let height = t.req("height")?.f64()?;
        let pattern = match (t.get("waves"), t.get("image"), t.get("normal_map")) {
            (Some(w), None, None) => BumpPattern::Waves { size: w.positive()? },
            (None, Some(i), None) => {
                let (image, scale) = self.image_texture(&i, false)?;
                BumpPattern::Image { image, scale }
            }
            (None, None, Some(i)) => BumpPattern::NormalMap { map: self.linear_placed_image(&i)? },
            _ => {
                return Err(n.err(
                    "a bump needs exactly one of `waves = size`, `image = { file = … }` or `normal_map = { file = … }`",
                ));
            }
        };
        Ok(Bump { height, pattern })
    }

    pub(crate) fn texture(&mut self, n: &Node) -> R<Texture> {
        if !n.is_table() {
            return Ok(Texture::Solid(n.rgb()?));
        }
        let t = n.table(&["hsv", "hsl", "checker", "image"])?;
        if t.get("hsv").is_some() || t.get("hsl").is_some() {
            return Ok(Texture::Solid(n.rgb()?));
        }
        if let Some(c) = t.get("checker") {
            let c = c.table(&["even", "odd", "size"])?;
            return Ok(Texture::Checker {
                even: c.opt_rgb("even", Vec3::splat(0.9))?,
                odd: c.opt_rgb("odd", Vec3::splat(0.1))?,
                size: c.get("size").map_or(Ok(1.0), |n| n.positive())?,
            });
        }
        if let Some(i) = t.get("image") {
            return self.placed_image(&i);
        }
        Err(n.err("`color`: expected a colour, { hsv = [h, s, v] }, { hsl = [h, s, l] }, { checker = {...} } or { image = {...} }"))
    }

    /// `emission = [r, g, b]`, or a texture whose colours are multiplied by `strength` (a
    /// number or a colour, 1 by default): `{ image = {...}, strength = s }` or
    /// `{ checker = {...}, strength = s }`. The mean radiance, and the texture where it varies.
    fn emission(&mut self, n: &Node) -> R<(Vec3, Option<Texture>)> {
        let t = match n.is_table() {
            true => n.table(&["hsv", "hsl", "checker", "image", "strength"])?,
            false => return Ok((n.rgb()?, None)),
        };
        if t.get("hsv").is_some() || t.get("hsl").is_some() {
            return Ok((n.rgb()?, None));
        }
        let strength = t.opt_rgb("strength", Vec3::ONE)?;
        let texture = match (t.get("checker"), t.get("image")) {
            (Some(c), None) => {
                let c = c.table(&["even", "odd", "size"])?;
                Texture::Checker {
                    even: c.opt_rgb("even", Vec3::splat(0.9))? * strength,
                    odd: c.opt_rgb("odd", Vec3::splat(0.1))? * strength,
                    size: c.get("size").map_or(Ok(1.0), |n| n.positive())?,
                }
            }
            (None, Some(i)) => {
                let placed = self.placed_image(&i)?;
                if let (Texture::Image { image, .. }, true) = (&placed, strength != Vec3::ONE) {
                    let factor = strength.as_vec3().to_array();
                    self.scene.images[*image] = Arc::new(self.scene.images[*image].channels_scaled(factor));
                }
                placed
            }
            _ => {
                return Err(n.err(
                    "`emission`: expected a colour, { image = {...}, strength = s } or { checker = {...}, strength = s }",
                ));
            }
        };
        // An image's texels are single precision: a strength may take them past its range.
        let mean = crate::texture::mean(&texture, &self.scene.images);
        if !mean.is_finite() {
            return Err(n.err("`emission`: the image's values times `strength` overflow single precision"));
        }
        Ok((mean, Some(texture)))
    }

    fn material_ref(&mut self, n: &Node, object_name: &str) -> R<MaterialId> {
        if n.is_table() {
            let name = format!("{object_name} (inline)");
            let m = self.material(n, &name)?;
            return Ok(self.add_material(&name, m));
        }
        let name = n.str()?;
        self.material_names.get(name).copied().ok_or_else(|| {
            let mut d = n.err(format!("unknown material \"{name}\"; define it under [materials.{name}]"));
            if let Some(m) = did_you_mean(name, self.material_names.keys().map(String::as_str)) {
                *d = d.with_help(format!("did you mean \"{m}\"?"));
            }
            d
        })
    }

    fn mesh_decl(&mut self, n: &Node) -> R<(usize, Vec<MaterialId>)> {
        let t = n.table(&["file"])?;
        self.load_mesh(&t.req("file")?)
    }

    fn load_mesh(&mut self, file: &Node) -> R<(usize, Vec<MaterialId>)> {
        let path = self.dir.join(file.str()?);
        if let Some(m) = self.mesh_files.get(&path) {
            return Ok(m.clone());
        }
        let loaded = self.load_mesh_file(file, &path)?;
        self.mesh_files.insert(path, loaded.clone());
        Ok(loaded)
    }

    fn load_mesh_file(&mut self, file: &Node, path: &Path) -> R<(usize, Vec<MaterialId>)> {
        let path = path.to_path_buf();
        let read = self.preloaded.remove(&path).unwrap_or_else(|| import::load_mesh(&path));
        let mut loaded = read.map_err(|e| file.err(e))?;
        self.warnings.append(&mut loaded.warnings);
        let slots = loaded
            .materials
            .into_iter()
            .map(|m| {
                let name = format!("{}:{}", path.display(), m.name);
                self.add_material(&name, m)
            })
            .collect();
        self.scene.meshes.push(Arc::new(loaded.mesh));
        Ok((self.scene.meshes.len() - 1, slots))
    }

    /// `shape = "subdivision"`: a polygon mesh (`base = "cube"`, or a mesh `file`/`mesh`)
    /// refined `levels` times by Catmull–Clark or Doo–Sabin.
    fn subdivision(&mut self, t: &Table) -> R<alhazen_geom::TriangleMesh> {
        use alhazen_geom::halfedge::HalfedgeMesh;
        let base = match (t.get("base"), t.get("file"), t.get("mesh")) {
            (Some(b), None, None) => {
                b.choice(&["cube"])?;
                HalfedgeMesh::cube()
            }
            (None, Some(_), None) | (None, None, Some(_)) => {
                let (index, _) = match t.get("mesh") {
                    Some(m) => {
                        let name = m.str()?;
                        self.mesh_names.get(name).cloned().ok_or_else(|| m.err(format!("unknown mesh \"{name}\"")))?
                    }
                    None => self.load_mesh(&t.req("file")?)?,
                };
                let tm = self.scene.meshes[index].clone();
                let polys: Vec<Vec<usize>> =
                    tm.triangles.iter().map(|t| t.iter().map(|&v| v as usize).collect()).collect();
                let node = t.get("mesh").or(t.get("file")).expect("one is present");
                HalfedgeMesh::from_polygons(tm.positions.clone(), &polys)
                    .map_err(|e| node.err(format!("cannot subdivide: {e}")))?
            }
            _ => {
                return Err(t.req("shape")?.err("a subdivision surface needs exactly one of `base`, `file` or `mesh`"));
            }
        };
        let doo_sabin = match t.get("scheme") {
            Some(s) => s.choice(&["catmull-clark", "doo-sabin"])? == "doo-sabin",
            None => false,
        };
        let levels = t.get("levels").map_or(Ok(3), |n| n.integer(0, 6))?;
        // Each level quadruples the halfedges; the meshes of two levels and the triangles
        // take about this much per halfedge of the last.
        const BYTES_PER_HALFEDGE: u64 = 96;
        let needed = base.halfedges.len() as u64 * 4u64.pow(levels as u32) * BYTES_PER_HALFEDGE;
        if needed > self.memory_budget {
            let at = t.get("levels").unwrap_or(t.req("shape")?);
            return Err(at.err(format!(
                "subdividing this {}-face mesh {levels} times needs about {}, more than the memory budget of {} (lower `levels`, or raise the budget: alhazen --max-memory)",
                base.faces.len(),
                crate::format_bytes(needed),
                crate::format_bytes(self.memory_budget)
            )));
        }
        let mut m = base;
        for _ in 0..levels {
            m = if doo_sabin {
                alhazen_geom::subdivision::doo_sabin(&m)
            } else {
                alhazen_geom::subdivision::catmull_clark(&m)
            };
        }
        Ok(alhazen_geom::tessellate::polygons_to_triangles(&m))
    }

    pub(crate) fn object(&mut self, n: &Node, depth: usize) -> R<Object> {
        const COMMON: &[&str] = &["shape", "name", "material", "transform"];
        let t = n.table_any()?;
        let shape_node = t.req("shape")?;
        let kind = shape_node.choice(&[
            "sphere",
            "cylinder",
            "cone",
            "disk",
            "plane",
            "box",
            "mesh",
            "csg",
            "subdivision",
            "patch",
            "curve",
            "revolution",
            "sweep",
            "loft",
            "rectangle",
        ])?;
        let specific: &[&str] = match kind {
            "sphere" => &["center", "radius"],
            "cylinder" => &["base", "top", "radius", "capped"],
            "cone" => &["base", "apex", "radius", "capped"],
            "disk" => &["center", "normal", "radius"],
            "plane" => &["point", "normal"],
            "box" => &["min", "max"],
            "mesh" => &["file", "mesh", "smooth"],
            "subdivision" => &["base", "file", "mesh", "scheme", "levels", "smooth"],
            "patch" => &["rows", "points", "weights", "tolerance", "degree", "knots_u", "knots_v"],
            "loft" => &["curves", "tolerance", "smooth"],
            "curve" => &["kind", "degree", "points", "weights", "knots", "radius", "tolerance", "smooth"],
            "revolution" => &["profile", "tolerance", "smooth"],
            "sweep" => &["guide", "radius", "section", "guides", "tolerance", "smooth"],
            "rectangle" => &[],
            _ => &["op", "a", "b"],
        };
        let keys: Vec<&str> = COMMON.iter().chain(specific).copied().collect();
        t.check_keys(&keys)?;
        let name = t.get("name").map(|n| n.str().map(str::to_string)).transpose()?;
        let label = name.clone().unwrap_or_else(|| format!("{kind} object"));
        let transform = match t.get("transform") {
            Some(tr) => transform(&tr)?,
            None => Transform::IDENTITY,
        };
        let mut mesh_materials = vec![];
        let shape = match kind {
            "sphere" => {
                Shape::Sphere { center: t.opt_vec3("center", Vec3::ZERO)?, radius: t.req("radius")?.positive()? }
            }
            "cylinder" => {
                let (base, top) = (t.opt_vec3("base", Vec3::ZERO)?, t.opt_vec3("top", Vec3::Y)?);
                distinct(&t, "top", base, top)?;
                Shape::Cylinder { base, top, radius: t.req("radius")?.positive()?, capped: t.opt_bool("capped", true)? }
            }
            "cone" => {
                let (base, apex) = (t.opt_vec3("base", Vec3::ZERO)?, t.opt_vec3("apex", Vec3::Y)?);
                distinct(&t, "apex", base, apex)?;
                Shape::Cone { base, apex, radius: t.req("radius")?.positive()?, capped: t.opt_bool("capped", true)? }
            }
            "disk" => Shape::Disk {
                center: t.opt_vec3("center", Vec3::ZERO)?,
                normal: t.get("normal").map_or(Ok(Vec3::Y), |n| n.unit_vec3())?,
                radius: t.req("radius")?.positive()?,
            },
            "plane" => Shape::Plane {
                point: t.opt_vec3("point", Vec3::ZERO)?,
                normal: t.get("normal").map_or(Ok(Vec3::Y), |n| n.unit_vec3())?,
            },
            "box" => {
                let (min, max) = (t.opt_vec3("min", Vec3::splat(-1.0))?, t.opt_vec3("max", Vec3::ONE)?);
                if min.cmpge(max).any() {
                    return Err(t.req("max")?.err("`max` must exceed `min` in every coordinate"));
                }
                Shape::Box { min, max }
            }
            "subdivision" | "patch" | "curve" | "revolution" | "sweep" | "loft" | "rectangle" => {
                let mesh = match kind {
                    "rectangle" => rectangle(),
                    "subdivision" => self.subdivision(&t)?,
                    "patch" => self.patch(&t)?,
                    "revolution" => self.revolution(&t)?,
                    "sweep" => self.sweep(&t)?,
                    "loft" => self.loft(&t)?,
                    _ => self.curve(&t)?,
                };
                self.scene.meshes.push(Arc::new(mesh));
                Shape::Mesh { mesh: self.scene.meshes.len() - 1, smooth: t.opt_bool("smooth", true)? }
            }
            "mesh" => {
                let (mesh, slots) = match (t.get("mesh"), t.get("file")) {
                    (Some(m), None) => {
                        let name = m.str()?;
                        self.mesh_names.get(name).cloned().ok_or_else(|| {
                            let mut d = m.err(format!("unknown mesh \"{name}\"; declare it under [meshes.{name}]"));
                            if let Some(s) = did_you_mean(name, self.mesh_names.keys().map(String::as_str)) {
                                *d = d.with_help(format!("did you mean \"{s}\"?"));
                            }
                            d
                        })?
                    }
                    (None, Some(f)) => self.load_mesh(&f)?,
                    _ => return Err(shape_node.err("a mesh object needs exactly one of `file` or `mesh`")),
                };
                mesh_materials = slots;
                Shape::Mesh { mesh, smooth: t.opt_bool("smooth", true)? }
            }
            _ => {
                if depth > 64 {
                    return Err(shape_node.err("CSG nested deeper than 64 levels"));
                }
                let op = match t.req("op")?.choice(&["union", "intersection", "difference"])? {
                    "union" => CsgOp::Union,
                    "intersection" => CsgOp::Intersection,
                    _ => CsgOp::Difference,
                };
                let mut operand = |key: &str| -> R<Box<Object>> {
                    let node = t.req(key)?;
                    let o = self.object(&node, depth + 1)?;
                    if !o.shape.is_closed(&self.scene.meshes) {
                        return Err(node.err(format!("CSG operand `{key}` must be a closed shape (sphere, box, capped cylinder or cone, closed mesh, csg)")));
                    }
                    Ok(Box::new(o))
                };
                let a = operand("a")?;
                let b = operand("b")?;
                Shape::Csg { op, a, b }
            }
        };
        let material = match t.get("material") {
            Some(m) => {
                mesh_materials.clear();
                self.material_ref(&m, &label)?
            }
            None => 0,
        };
        Ok(Object { name, shape, transform, material, mesh_materials })
    }
}

/// `shape = "rectangle"`: the square `[−1, 1]²` in the plane `z = 0`, facing `+z` (as Mitsuba's
/// `rectangle`); place and size it with `transform`.
pub fn rectangle() -> alhazen_geom::TriangleMesh {
    let positions = vec![
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(1.0, 1.0, 0.0),
        Vec3::new(-1.0, 1.0, 0.0),
    ];
    alhazen_geom::TriangleMesh {
        positions,
        normals: vec![Vec3::Z; 4],
        uvs: vec![Vec2::new(0.0, 0.0), Vec2::new(1.0, 0.0), Vec2::new(1.0, 1.0), Vec2::new(0.0, 1.0)],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        ..Default::default()
    }
}

fn distinct(t: &Table, key: &str, a: Vec3, b: Vec3) -> R<()> {
    if (a - b).length() > 0.0 {
        return Ok(());
    }
    let n = t.get(key).unwrap_or_else(|| t.req("shape").expect("shape was read"));
    Err(n.err(format!("`{key}` must differ from `base`")))
}

impl<'a, 'i> Node<'a, 'i> {
    /// A table whose keys the caller checks itself.
    pub(crate) fn table_any(&self) -> R<Table<'a, 'i>> {
        let toml::de::DeValue::Table(t) = self.v else {
            return Err(self.err(format!("`{}`: expected a table", self.key)));
        };
        Ok(Table { src: self.src, t, span: self.span.clone(), name: self.key, scope: self.scope.clone() })
    }
}

fn render_settings(n: &Node) -> R<RenderSettings> {
    let t = n.table(&[
        "width",
        "height",
        "spp",
        "max_depth",
        "seed",
        "integrator",
        "sampler",
        "light_choice",
        "mirror_connections",
        "filter",
    ])?;
    let d = RenderSettings::default();
    let r = RenderSettings {
        width: t.get("width").map_or(Ok(d.width as u64), |n| n.integer(1, MAX_SIDE))? as u32,
        height: t.get("height").map_or(Ok(d.height as u64), |n| n.integer(1, MAX_SIDE))? as u32,
        spp: t.get("spp").map_or(Ok(d.spp as u64), |n| n.integer(1, 1 << 20))? as u32,
        max_depth: t.get("max_depth").map_or(Ok(d.max_depth as u64), |n| n.integer(0, 1000))? as u32,
        seed: t.get("seed").map_or(Ok(0), |n| n.integer(0, i64::MAX as u64))?,
        integrator: match t.get("integrator") {
            Some(i) => match i.choice(&["whitted", "path", "photon", "radiosity"])? {
                "whitted" => IntegratorKind::Whitted,
                "photon" => IntegratorKind::Photon,
                "radiosity" => IntegratorKind::Radiosity,
                _ => IntegratorKind::Path,
            },
            None => d.integrator,
        },
        sampler: match t.get("sampler") {
            Some(i) => match i.choice(&["sobol", "independent"])? {
                "sobol" => SamplerKind::Sobol,
                _ => SamplerKind::Independent,
            },
            None => d.sampler,
        },
        light_choice: match t.get("light_choice") {
            Some(i) => match i.choice(&["measured", "power", "uniform"])? {
                "uniform" => LightChoice::Uniform,
                "power" => LightChoice::Power,
                _ => LightChoice::Measured,
            },
            None => d.light_choice,
        },
        mirror_connections: t.opt_bool("mirror_connections", d.mirror_connections)?,
        filter: t.get("filter").map_or(Ok(d.filter), |n| pixel_filter(&n))?,
    };
    if r.width as u64 * r.height as u64 > MAX_PIXELS {
        return Err(t
            .req("width")?
            .err(format!("{}×{} pixels is more than the {MAX_PIXELS} this renderer can allocate", r.width, r.height)));
    }
    Ok(r)
}

/// One of [`crate::Wrap::NAMES`].
fn wrap_mode(n: &Node) -> R<crate::Wrap> {
    let name = n.choice(&crate::Wrap::NAMES)?;
    crate::Wrap::named(name).ok_or_else(|| n.err(format!("`wrap`: unknown mode \"{name}\"")))
}

/// `filter = "NAME"` (its defaults) or `{ type = "NAME", radius = r or [rx, ry], … }`.
fn pixel_filter(n: &Node) -> R<PixelFilter> {
    if !n.is_table() {
        let name = n.choice(&PixelFilter::NAMES)?;
        return PixelFilter::named(name).ok_or_else(|| n.err(format!("`filter`: unknown filter \"{name}\"")));
    }
    let t = n.table(&["type", "radius", "sigma", "b", "c", "tau"])?;
    let kind = t.req("type")?.choice(&PixelFilter::NAMES)?;
    t.check_keys(match kind {
        "gaussian" => &["type", "radius", "sigma"],
        "mitchell" => &["type", "radius", "b", "c"],
        "lanczos" => &["type", "radius", "tau"],
        _ => &["type", "radius"],
    })?;
    let sigma = t.opt_f64("sigma", 0.5)?;
    let tau = t.opt_f64("tau", 3.0)?;
    let radius = match t.get("radius") {
        Some(r) if r.is_array() => Some(r.numbers::<2>()?),
        Some(r) => Some([r.f64()?; 2]),
        None => None,
    };
    let default = PixelFilter::named(kind).map_or([2.0; 2], |f| f.radius());
    let filter = match kind {
        "gaussian" => PixelFilter::Gaussian { sigma, radius: radius.unwrap_or([3.0 * sigma; 2]) },
        "mitchell" => PixelFilter::Mitchell {
            b: t.opt_f64("b", 1.0 / 3.0)?,
            c: t.opt_f64("c", 1.0 / 3.0)?,
            radius: radius.unwrap_or(default),
        },
        "lanczos" => PixelFilter::Lanczos { tau, radius: radius.unwrap_or([tau; 2]) },
        "catmull-rom" => PixelFilter::Mitchell { b: 0.0, c: 0.5, radius: radius.unwrap_or(default) },
        "tent" => PixelFilter::Tent { radius: radius.unwrap_or(default) },
        "blackman-harris" => PixelFilter::BlackmanHarris { radius: radius.unwrap_or(default) },
        _ => PixelFilter::Box { radius: radius.unwrap_or(default) },
    };
    match filter.problem() {
        Some(why) => Err(n.err(format!("`filter`: {why}"))),
        None => Ok(filter),
    }
}

fn look_at(t: &Table) -> R<LookAt> {
    let look = LookAt {
        eye: t.req("eye")?.vec3()?,
        target: t.opt_vec3("target", Vec3::ZERO)?,
        up: t.opt_vec3("up", Vec3::Y)?,
    };
    if alhazen_math::viewing::ViewFrame::look_at(look.eye, look.target, look.up).is_none() {
        let n = t.get("target").unwrap_or(t.req("eye")?);
        return Err(n.err("the camera's eye and target coincide, or `up` is parallel to the view direction"));
    }
    Ok(look)
}

fn camera(n: &Node) -> R<CameraDesc> {
    let t = n.table_any()?;
    let kind = match t.get("type") {
        Some(k) => k.choice(&["perspective", "orthographic", "axonometric", "stereo", "panorama"])?,
        None => "perspective",
    };
    let keys: &[&str] = match kind {
        "perspective" => &["type", "eye", "target", "up", "fov", "fov_axis", "frustum", "aperture", "focus_distance"],
        "orthographic" => &["type", "eye", "target", "up", "width"],
        "axonometric" => &["type", "style", "target", "width", "azimuth"],
        "stereo" => &["type", "eye", "target", "up", "eye_distance", "screen_distance", "screen_width"],
        _ => &["type", "eye", "target", "up", "fov"],
    };
    t.check_keys(keys)?;
    Ok(match kind {
        "perspective" => {
            let look = look_at(&t)?;
            let opening = match (t.get("fov"), t.get("frustum")) {
                (Some(_), Some(f)) => return Err(f.err("give either `fov` or `frustum`, not both")),
                (_, Some(f)) => {
                    let ft = f.table(&["left", "right", "bottom", "top", "near"])?;
                    let v = ["left", "right", "bottom", "top"].map(|k| ft.req(k).and_then(|n| n.f64()));
                    let [l, r, b, tp] = [v[0].clone()?, v[1].clone()?, v[2].clone()?, v[3].clone()?];
                    let near = ft.req("near")?.positive()?;
                    if l >= r || b >= tp {
                        return Err(f.err("the frustum needs left < right and bottom < top"));
                    }
                    PerspectiveOpening::Frustum { lrbtn: [l, r, b, tp, near] }
                }
                (fov, None) => PerspectiveOpening::Fov {
                    angle: fov.map_or(Ok(45.0), |n| n.in_range(1e-3, 179.0))?.to_radians(),
                    horizontal: match t.get("fov_axis") {
                        Some(a) => a.choice(&["horizontal", "vertical"])? == "horizontal",
                        None => true,
                    },
                },
            };
            let lens = match (t.get("aperture"), t.get("focus_distance")) {
                (None, Some(f)) => return Err(f.err("`focus_distance` needs an `aperture` (the lens's radius)")),
                (None, None) => None,
                (Some(a), focus) => Some(ThinLens {
                    aperture: a.positive()?,
                    // In focus at the target unless told otherwise.
                    focus_distance: match focus {
                        Some(f) => f.positive()?,
                        None => (look.target - look.eye).length(),
                    },
                }),
            };
            CameraDesc::Perspective { look, opening, lens }
        }
        "orthographic" => CameraDesc::Orthographic { look: look_at(&t)?, width: t.req("width")?.positive()? },
        "axonometric" => {
            let style = match t.req("style")?.choice(&["isometric", "cavalier", "cabinet", "military"])? {
                "isometric" => Axonometry::Isometric,
                "cavalier" => Axonometry::Cavalier,
                "cabinet" => Axonometry::Cabinet,
                _ => Axonometry::Military,
            };
            // Military views are customarily drawn with the plan turned by 45°.
            let default_azimuth = if style == Axonometry::Military { 45.0 } else { 0.0 };
            CameraDesc::Axonometric {
                style,
                target: t.opt_vec3("target", Vec3::ZERO)?,
                width: t.req("width")?.positive()?,
                azimuth: t.opt_f64("azimuth", default_azimuth)?.to_radians(),
            }
        }
        "stereo" => CameraDesc::Stereo {
            look: look_at(&t)?,
            eye_distance: t.get("eye_distance").map_or(Ok(0.065), |n| n.positive())?,
            screen_distance: t.get("screen_distance").map_or(Ok(0.6), |n| n.positive())?,
            screen_width: t.get("screen_width").map_or(Ok(0.5), |n| n.positive())?,
        },
        _ => CameraDesc::Panorama {
            look: look_at(&t)?,
            angle: t.get("fov").map_or(Ok(360.0), |n| n.in_range(1e-3, 360.0))?.to_radians(),
        },
    })
}

fn background(n: &Node) -> R<Background> {
    if !n.is_table() {
        return Ok(Background::Solid(n.rgb()?));
    }
    let t = n.table(&["color", "zenith", "horizon", "ground"])?;
    if let Some(c) = t.get("color") {
        if let Some(other) = t.get("zenith").or(t.get("horizon")) {
            return Err(other.err("give either `color` or a gradient (`zenith`, `horizon`), not both"));
        }
        return Ok(Background::Solid(c.rgb()?));
    }
    let horizon = t.opt_rgb("horizon", Vec3::splat(1.0))?;
    Ok(Background::Gradient {
        zenith: t.opt_rgb("zenith", Vec3::new(0.3, 0.5, 0.9))?,
        horizon,
        ground: t.opt_rgb("ground", horizon)?,
    })
}

fn attenuation(t: &Table) -> R<[f64; 3]> {
    let Some(n) = t.get("attenuation") else { return Ok([0.0, 0.0, 1.0]) };
    let abc = n.numbers::<3>()?;
    if abc.iter().any(|x| *x < 0.0) || abc.iter().all(|x| *x == 0.0) {
        return Err(n.err("`attenuation` [a, b, c] needs a, b, c ≥ 0, not all zero (intensity / (a d² + b d + c))"));
    }
    Ok(abc)
}

fn light(n: &Node) -> R<Light> {
    let t = n.table_any()?;
    let kind = t.req("type")?.choice(&["point", "directional", "spot", "environment"])?;
    let keys: &[&str] = match kind {
        "point" => &["type", "position", "intensity", "attenuation"],
        "directional" => &["type", "direction", "intensity"],
        _ => &["type", "position", "direction", "angle", "beam", "fade", "falloff", "intensity", "attenuation"],
    };
    t.check_keys(keys)?;
    let intensity = t.opt_rgb("intensity", Vec3::ONE)?;
    // How a spot fades from its beam to its cone: "angle" (linear in angle), "smooth" (smooth in
    // the cosine, pbrt's), "squared" (glTF's).
    let fade = match t.get("fade") {
        Some(f) => Some(match f.choice(&["angle", "smooth", "squared"])? {
            "angle" => crate::SpotFade::LinearAngle,
            "smooth" => crate::SpotFade::SmoothCosine,
            _ => crate::SpotFade::SquaredCosine,
        }),
        None => None,
    };
    if let (Some(f), None) = (t.get("fade"), t.get("beam")) {
        return Err(f.err("a spot's `fade` runs from its `beam` to its `angle`: give a `beam`"));
    }
    Ok(match kind {
        "point" => Light::Point { position: t.req("position")?.vec3()?, intensity, attenuation: attenuation(&t)? },
        "directional" => Light::Directional { direction: t.req("direction")?.unit_vec3()?, intensity },
        _ => Light::Spot {
            position: t.req("position")?.vec3()?,
            direction: t.req("direction")?.unit_vec3()?,
            cos_cutoff: t.get("angle").map_or(Ok(30.0), |n| n.in_range(0.0, 180.0))?.to_radians().cos(),
            falloff: t.get("falloff").map_or(Ok(1.0), |n| n.non_negative())?,
            beam: t
                .get("beam")
                .map(|n| n.in_range(0.0, 180.0).map(|b| b.to_radians().cos()))
                .transpose()?
                .map(|cos| crate::SpotBeam { cos, fade: fade.unwrap_or_default() }),
            intensity,
            attenuation: attenuation(&t)?,
        },
    })
}

/// `transform = [ { translate = [..] }, { rotate = { axis = [..], angle = deg } }, … ]`, applied
/// in the order listed.
pub(crate) fn transform(n: &Node) -> R<Transform> {
    let mut total = Transform::IDENTITY;
    for step in n.array()? {
        let t = step.table(&["translate", "scale", "rotate", "rotate_x", "rotate_y", "rotate_z", "matrix"])?;
        let mut keys = t.keys();
        let (Some((key, _)), None) = (keys.next(), keys.next()) else {
            return Err(step.err("each transform step is a table with exactly one key, e.g. { translate = [0, 1, 0] }"));
        };
        let v = t.get(key).expect("key listed");
        let m = match key {
            "translate" => Transform::translate(v.vec3()?),
            "scale" => {
                let s = if v.is_table() {
                    return Err(v.err("`scale`: expected a number or [x, y, z]"));
                } else if matches!(v.v, toml::de::DeValue::Array(_)) {
                    v.vec3()?
                } else {
                    Vec3::splat(v.f64()?)
                };
                Transform::try_scale(s).map_err(|e| v.err(format!("`scale`: {e}")))?
            }
            "rotate" => {
                let r = v.table(&["axis", "angle"])?;
                Transform::rotate(r.req("axis")?.unit_vec3()?, r.req("angle")?.f64()?.to_radians())
            }
            "rotate_x" => Transform::rotate(Vec3::X, v.f64()?.to_radians()),
            "rotate_y" => Transform::rotate(Vec3::Y, v.f64()?.to_radians()),
            "rotate_z" => Transform::rotate(Vec3::Z, v.f64()?.to_radians()),
            _ => {
                let rows = v.array()?;
                if rows.len() != 4 {
                    return Err(v.err("`matrix`: expected 4 rows of 4 numbers"));
                }
                let r: Vec<[f64; 4]> = rows.iter().map(|r| r.numbers::<4>()).collect::<R<_>>()?;
                let m = Mat4::from_cols_array_2d(&r.try_into().expect("4 rows")).transpose();
                Transform::from_matrix(m).map_err(|e| v.err(format!("`matrix`: {e}")))?
            }
        };
        total = m * total;
    }
    Ok(total)
}

/// An RGB coefficient in `[0, 1]` per channel (a surface cannot pass on more light than it gets).
fn unit_rgb(t: &Table, key: &str, default: Vec3) -> R<Vec3> {
    let v = t.opt_rgb(key, default)?;
    if v.max_element() > 1.0 {
        return Err(t.req(key)?.err(format!("`{key}` must lie in [0, 1] per channel (it scales the light passed on)")));
    }
    Ok(v)
}
