//! Mitsuba 3 XML scenes (`.xml`), read with a real XML parser (roxmltree), every element located
//! by line for messages.
//!
//! Supported: `default` parameters and `$name` substitution, `include`, `path` (folders searched
//! for the files named), `ref`/`id`; the
//! `perspective` and `orthographic` sensors (`fov`, `fov_axis`, `focal_length`, `to_world` with
//! `lookat`/`translate`/`rotate`/`scale`/`matrix`), `hdrfilm` size, the sampler's
//! `sample_count` and `seed`, the integrator's `max_depth`; shapes `obj`, `ply`, `serialized`, `rectangle`,
//! `cube`, `sphere`, `disk`, `cylinder`, `shapegroup`/`instance`; BSDFs `diffuse`,
//! `conductor`/`roughconductor` (named materials or `eta`/`k`), `dielectric`/`roughdielectric`,
//! `thindielectric`, `plastic`/`roughplastic`, `principled`, `blendbsdf`, `twosided`,
//! `bumpmap`, `normalmap` (a tangent-space normal map), `mask`; textures `bitmap` and `checkerboard`; emitters `area`,
//! `point`, `spot`, `directional`, `constant`, `envmap`. Textures are read per point where the
//! model can (colours, principled's roughness and metallic, an area light's radiance on a
//! mesh), by their means elsewhere (with a warning). Scenes of version 0.x have their
//! camelCase names upgraded as Mitsuba 3 does. Everything else is a located warning.
//!
//! Mitsuba's camera looks along its local `+z` with `+x` to the left of the image, which is
//! alhazen's right-handed camera seen through `lookat`, so scenes map without mirroring.

use crate::Imported;
use crate::common::{self, PendingFiles, Warnings, flip_mesh, located};
use alhazen_math::{Mat3, Mat4, Transform, Vec2, Vec3};
use alhazen_scene::bsdf::{Anisotropy, AnisotropyModel, BsdfDesc, Distribution, Ior, Microfacets, Shadowing};
use alhazen_scene::{
    Background, Bump, BumpPattern, CameraDesc, FresnelMode, IntegratorKind, Light, LookAt, MaterialId, Object,
    PerspectiveOpening, PixelFilter, SamplerKind, Scene, SceneError, Shape, Texture, Wrap,
};
use roxmltree::Node;
use std::cell::RefCell;
use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::sync::Arc;

type R<T> = Result<T, SceneError>;

/// Reads a Mitsuba 3 XML scene.
pub fn load(path: &Path) -> Result<Imported, SceneError> {
    load_with_parameters(path, &[])
}

/// Reads a Mitsuba 3 XML scene, its `$name` parameters given `parameters`' values over its
/// `<default>`s (as Mitsuba's `-D name=value`); a parameter the scene never uses is a warning.
pub fn load_with_parameters(path: &Path, parameters: &[(String, String)]) -> Result<Imported, SceneError> {
    let mut imp = Importer {
        scene: alhazen_scene::empty_scene(),
        warnings: Warnings::default(),
        defaults: parameters.iter().cloned().collect(),
        used: RefCell::default(),
        ids: HashMap::new(),
        meshes: HashMap::new(),
        default_material: None,
        black_material: None,
        camera_seen: false,
        version_major: 3,
        pending: PendingFiles::default(),
        search: vec![],
        scene_dir: path.parent().unwrap_or(Path::new(".")).to_path_buf(),
        cut_out: None,
        vertex_colored: false,
        integrator_kind: None,
        absorbing: false,
    };
    imp.scene.render.integrator = IntegratorKind::Path;
    imp.scene.render.width = 768;
    imp.scene.render.height = 576;
    imp.scene.render.max_depth = 1000;
    let walked = imp.file(path, 0);
    // The mesh and image files met before any error of the walk are loaded (an error in one of
    // them came first in the document, so it is the one reported).
    // Mitsuba ignores OBJ material libraries: the shape's BSDF applies to every face; it
    // smooths a mesh without normals by the angles of its faces at each vertex.
    imp.pending.load(&mut imp.scene, |m| {
        m.material_slots.clear();
        m.material_names.clear();
        if m.normals.is_empty() {
            m.compute_angle_weighted_normals();
        }
    })?;
    walked?;
    for (name, _) in parameters {
        if !imp.used.borrow().contains(name) {
            imp.warnings.add(path, 0, format!("parameter `{name}` is given a value but the scene never uses ${name}"));
        }
    }
    imp.finish()
}

/// Mitsuba's conductor names that alhazen has measured indices for.
const METAL_NAMES: &[(&str, &str)] = &[("Au", "gold"), ("Ag", "silver"), ("Cu", "copper"), ("Al", "aluminium")];

/// Mitsuba's other named conductors: `(η, κ)` at red, green and blue — the measured spectra
/// Mitsuba 3 ships (Palik's handbook and others), weighed into linear sRGB as its RGB modes
/// weigh them (values read from `mi.traverse` of Mitsuba 3.9.1's `conductor` in `scalar_rgb`).
/// A name `X_palik` not listed is `X`'s data (Palik's, as Mitsuba's unsuffixed names mostly are).
const MITSUBA_METALS: &[(&str, [f64; 3], [f64; 3])] = &[
    ("a-C", [2.94405, 2.22714, 1.96816], [0.887465, 0.799299, 0.81529]),
    ("AlAs", [3.6053, 3.23294, 2.21632], [0.000679437, 0.0, 0.00751271]),
    ("AlSb", [0.0, 4.13937, 4.66925], [0.0, 0.0940091, 1.30057]),
    ("Be", [4.18501, 3.18503, 2.78406], [3.83547, 3.01012, 2.86899]),
    ("Cr", [4.36967, 2.91651, 1.6549], [5.20655, 4.23131, 3.7547]),
    ("CsI", [2.1449, 1.70232, 1.66243], [0.0, 0.0, 0.0]),
    ("Cu2O", [3.55177, 2.94987, 2.75188], [0.114207, 0.193897, 0.606134]),
    ("Cu_palik", [0.213229, 0.919715, 1.10241], [3.92187, 2.45733, 2.13658]),
    ("CuO", [3.24754, 2.44781, 2.21022], [0.52109, 0.570031, 0.722179]),
    ("d-C", [2.70872, 2.31883, 2.2289], [0.0, 0.0, 0.0]),
    ("Hg", [2.39894, 1.44003, 0.90957], [6.32759, 4.37192, 3.42176]),
    ("HgTe", [4.77904, 3.2312, 2.6599], [1.63161, 1.58081, 1.72929]),
    ("Ir", [3.0863, 2.08219, 1.61791], [5.59215, 4.06709, 3.26731]),
    ("K", [0.0640432, 0.0464098, 0.0381849], [2.1042, 1.34894, 0.913126]),
    ("Li", [0.265791, 0.195618, 0.220949], [3.54015, 2.31112, 1.66861]),
    ("MgO", [2.08958, 1.65072, 1.59488], [4.3327e-12, 0.0, 2.49865e-11]),
    ("Mo", [4.48397, 3.52513, 2.77631], [4.11144, 3.42083, 3.15061]),
    ("Na_palik", [0.0602694, 0.0561409, 0.0619884], [3.17927, 2.11249, 1.57904]),
    ("Nb", [3.42007, 2.79009, 2.39563], [3.44139, 2.73767, 2.57975]),
    ("Ni_palik", [2.3673, 1.66337, 1.46708], [4.49881, 3.05015, 2.34544]),
    ("Rh", [2.58579, 1.86022, 1.55426], [6.78226, 4.70299, 3.97607]),
    ("Se", [4.05831, 2.84294, 2.82085], [0.75405, 0.638444, 0.521808]),
    ("SiC", [3.17234, 2.52597, 2.47937], [7.53766e-07, 0.0, 1.01925e-05]),
    ("SnTe", [4.52425, 1.98164, 1.28159], [0.0, 0.0, 0.0]),
    ("Ta", [2.06272, 2.39294, 2.62793], [2.40836, 1.74149, 1.94703]),
    ("Te", [7.39023, 4.4821, 2.63711], [3.25602, 3.52706, 3.29205]),
    ("ThF4", [1.83071, 1.44223, 1.38765], [0.0, 0.0, 0.0]),
    ("TiC", [3.70053, 2.83742, 2.58229], [3.26564, 2.35159, 2.17279]),
    ("TiN", [1.64845, 1.15052, 1.37982], [3.36833, 1.9435, 1.10207]),
    ("TiO2", [3.45661, 2.80174, 2.90517], [0.000105265, 0.0, 0.000652887]),
    ("V_palik", [4.27758, 3.51295, 2.76107], [3.4913, 2.88945, 3.11152]),
    ("VC", [3.65757, 2.75274, 2.53267], [3.0683, 2.19869, 1.96319]),
    ("VN", [2.8656, 2.11919, 1.94009], [3.03224, 2.05612, 1.61631]),
    ("W", [4.37082, 3.30025, 2.99841], [3.50064, 2.60487, 2.27323]),
];

/// Properties that change nothing in an image alhazen makes.
const HARMLESS: &[&str] =
    &["pixel_format", "component_format", "file_format", "banner", "high_quality_edges", "near_clip", "far_clip", "id"];

/// How many elements one element's references may read ahead of their place, one through
/// another (a bound on the recursion, far beyond any scene's).
const FORWARD_CHAIN: usize = 256;

/// What an `id` names.
#[derive(Clone)]
enum Named {
    Bsdf(MaterialId),
    Texture(Texture),
    Group(Vec<Object>),
    /// An `area` emitter declared apart, with its radiance, for the shapes that refer to it.
    AreaEmitter(Texture),
    /// A medium declared apart: its absorption per unit length (`None`: a medium alhazen does
    /// not render, warned where it was declared).
    Medium(Option<Vec3>),
    Other,
}

struct Importer {
    scene: Scene,
    warnings: Warnings,
    defaults: HashMap<String, String>,
    /// The parameters substituted somewhere.
    used: RefCell<HashSet<String>>,
    ids: HashMap<String, Named>,
    /// Mesh files (a `serialized` file's mesh) and orientations, and their places.
    meshes: HashMap<MeshKey, usize>,
    default_material: Option<MaterialId>,
    /// The black BSDF of emitting shapes without one, once made.
    black_material: Option<MaterialId>,
    camera_seen: bool,
    version_major: u32,
    /// Mesh files met, loaded together once the walk is done.
    pending: PendingFiles,
    /// The folders of `<path>` elements, the latest first.
    search: Vec<PathBuf>,
    /// The folder of the scene file.
    scene_dir: PathBuf,
    /// The cut-out of the `mask` met in the BSDF being read, for its material.
    cut_out: Option<alhazen_scene::Alpha>,
    /// The BSDF being read takes a colour from its mesh's `vertex_color` attribute.
    vertex_colored: bool,
    /// The integrator's plugin, and whether some shape's inside absorbs (told apart at the
    /// end: Mitsuba's integrators other than `volpath` ignore media).
    integrator_kind: Option<String>,
    absorbing: bool,
}

/// A mesh file as placed: its path, its part of a `serialized` file, and whether it is turned
/// inside out and its texture coordinates' `v` flipped.
type MeshKey = (PathBuf, Option<usize>, (bool, bool));

/// One file being read.
struct Ctx<'a> {
    path: &'a Path,
    text: &'a str,
    /// Its text, shared: kept for the locations of mesh files' errors found after the walk.
    shared: &'a Arc<str>,
}

/// A plugin element with the names of the properties read so far.
struct Plugin<'a, 'i> {
    node: Node<'a, 'i>,
    kind: String,
    used: RefCell<HashSet<String>>,
}

impl Ctx<'_> {
    fn err(&self, node: Node, msg: impl Into<String>) -> SceneError {
        located(self.path, self.text, node.range(), msg)
    }

    fn line(&self, node: Node) -> usize {
        common::line_of(self.text, node.range().start)
    }
}

impl Importer {
    fn finish(mut self) -> R<Imported> {
        if !self.camera_seen {
            self.warnings.add(Path::new("scene"), 0, "the scene has no sensor: alhazen's default camera is used");
        }
        let volumetric = self.integrator_kind.as_deref().is_some_and(|k| k.starts_with("volpath"));
        if self.absorbing && !volumetric {
            let kind = self.integrator_kind.as_deref().unwrap_or("path");
            self.warnings.add(
                Path::new("scene"),
                0,
                format!("alhazen renders the absorption of the scene's interior media, which Mitsuba's `{kind}` integrator ignores (its `volpath` renders them)"),
            );
        }
        Ok(Imported { scene: self.scene, warnings: self.warnings.into_vec() })
    }

    fn warn(&mut self, ctx: &Ctx, node: Node, msg: impl Into<String>) {
        let line = ctx.line(node);
        self.warnings.add(ctx.path, line, msg);
    }

    /// Reads one file (the scene or an `include`d one) into the scene.
    fn file(&mut self, path: &Path, depth: usize) -> R<()> {
        let text: Arc<str> = common::read_text(path)?.into();
        let doc = roxmltree::Document::parse(&text).map_err(|e| {
            let p = e.pos();
            let at = text.lines().take(p.row as usize - 1).map(|l| l.len() + 1).sum::<usize>() + p.col as usize - 1;
            located(path, &text, at..at + 1, format!("XML syntax error: {e}"))
        })?;
        let ctx = Ctx { path, text: &text, shared: &text };
        let root = doc.root_element();
        if root.tag_name().name() != "scene" {
            return Err(ctx.err(root, format!("expected a <scene> element, found <{}>", root.tag_name().name())));
        }
        if let Some(v) = root.attribute("version") {
            let major = v.split('.').next().and_then(|m| m.trim().parse::<u32>().ok());
            self.version_major =
                major.ok_or_else(|| ctx.err(root, format!("version \"{v}\" is not a version number")))?;
        } else if depth == 0 {
            self.version_major = 3;
        }
        // Mitsuba reads the whole tree before it makes anything, so an element may refer to
        // one declared after it: such an element is read first.
        let declared: HashMap<&str, Node> =
            root.children().filter(Node::is_element).filter_map(|c| Some((c.attribute("id")?, c))).collect();
        let mut done = HashSet::new();
        for child in root.children().filter(Node::is_element) {
            self.declared_first(&ctx, child, (&declared, &mut done), (depth, 0))?;
        }
        Ok(())
    }

    /// Reads top-level element `node` once, after the later elements of this file it refers to
    /// (a cycle of references, or a chain of more than [`FORWARD_CHAIN`], is left to report the
    /// element not yet declared). `depth` counts includes, `chain` elements read ahead.
    fn declared_first(
        &mut self,
        ctx: &Ctx,
        node: Node,
        (declared, done): (&HashMap<&str, Node>, &mut HashSet<roxmltree::NodeId>),
        (depth, chain): (usize, usize),
    ) -> R<()> {
        if !done.insert(node.id()) {
            return Ok(());
        }
        for r in node.descendants().filter(|d| d.tag_name().name() == "ref" && chain < FORWARD_CHAIN) {
            let later = r.attribute("id").filter(|id| !self.ids.contains_key(*id)).and_then(|id| declared.get(id));
            if let Some(&target) = later {
                self.declared_first(ctx, target, (declared, done), (depth, chain + 1))?;
            }
        }
        self.top_level(ctx, node, depth)
    }

    fn top_level(&mut self, ctx: &Ctx, node: Node, depth: usize) -> R<()> {
        match node.tag_name().name() {
            "default" => {
                let name = self.req_attr(ctx, node, "name")?;
                let value = self.req_attr(ctx, node, "value")?;
                self.defaults.entry(name).or_insert(value);
            }
            "include" => {
                if depth >= 16 {
                    return Err(ctx.err(node, "includes nested deeper than 16 files (an include cycle?)"));
                }
                let name = self.req_attr(ctx, node, "filename")?;
                let path = self.resolve(ctx, &name, true);
                self.file(&path, depth + 1).map_err(|e| match e {
                    SceneError::Io { source, .. } => {
                        ctx.err(node, format!("cannot read included file {}: {source}", path.display()))
                    }
                    e => e,
                })?;
            }
            "path" => self.search_path(ctx, node)?,
            "integrator" => self.integrator(ctx, node)?,
            "sensor" => self.sensor(ctx, node)?,
            "bsdf" => {
                let id = self.bsdf_material(ctx, node)?;
                self.register(ctx, node, Named::Bsdf(id))?;
            }
            "texture" => {
                let t = self.texture(ctx, node, false)?;
                self.register(ctx, node, Named::Texture(t))?;
            }
            "shape" => {
                let objects = self.shape(ctx, node)?;
                if self.attr(ctx, node, "type")?.as_deref() == Some("shapegroup") {
                    self.register(ctx, node, Named::Group(objects))?;
                } else {
                    self.scene.objects.extend(objects);
                }
            }
            "emitter" => self.emitter(ctx, node)?,
            "medium" => {
                let m = self.medium(ctx, node)?;
                self.register(ctx, node, Named::Medium(m))?;
            }
            other => {
                self.warn(ctx, node, format!("<{other}> is not supported (alhazen renders no scattering media, phase functions or volumes); ignored"));
                if node.attribute("id").is_some() {
                    self.register(ctx, node, Named::Other)?;
                }
            }
        }
        Ok(())
    }

    /// A `<path>` element: a folder searched for the files the scene names, before those
    /// searched already (Mitsuba's file resolver). A relative folder is taken from this file's
    /// folder, else from those searched.
    fn search_path(&mut self, ctx: &Ctx, node: Node) -> R<()> {
        let value = self.req_attr(ctx, node, "value")?;
        let own = common::relative_to(ctx.path, &value);
        let folder = if own.is_dir() { own.clone() } else { self.resolve(ctx, &value, false) };
        if !folder.is_dir() {
            return Err(ctx.err(node, format!("<path>: folder {} not found", own.display())));
        }
        self.search.insert(0, folder);
        Ok(())
    }

    /// Where a file named `name` in the file being read is: the first folder holding it of the
    /// `<path>` folders (the latest first), this file's folder, the scene file's folder and the
    /// working directory (an `include` looks in its file's folder first, as Mitsuba's does);
    /// when none holds it, the name taken from this file's folder, for the message.
    fn resolve(&self, ctx: &Ctx, name: &str, own_first: bool) -> PathBuf {
        let own = common::relative_to(ctx.path, name);
        if Path::new(name).is_absolute() {
            return own;
        }
        let own_dir = ctx.path.parent().unwrap_or(Path::new("."));
        let folders = own_first.then_some(own_dir).into_iter().chain(self.search.iter().map(PathBuf::as_path));
        let folders = folders.chain([own_dir, self.scene_dir.as_path(), Path::new(".")]);
        folders.map(|f| f.join(name)).find(|p| p.exists()).unwrap_or(own)
    }

    fn register(&mut self, ctx: &Ctx, node: Node, what: Named) -> R<()> {
        if let Some(id) = self.attr(ctx, node, "id")? {
            self.ids.insert(id, what);
        }
        Ok(())
    }

    // ---- attributes and properties -------------------------------------------------------

    /// An attribute with `$name` parameters substituted.
    fn attr(&self, ctx: &Ctx, node: Node, name: &str) -> R<Option<String>> {
        let Some(raw) = node.attribute(name) else { return Ok(None) };
        if !raw.contains('$') {
            return Ok(Some(raw.to_string()));
        }
        let mut out = String::new();
        let mut rest = raw;
        while let Some(i) = rest.find('$') {
            out.push_str(&rest[..i]);
            let tail = &rest[i + 1..];
            let len = tail.find(|c: char| !(c.is_alphanumeric() || c == '_')).unwrap_or(tail.len());
            let key = &tail[..len];
            let value = self.defaults.get(key).ok_or_else(|| {
                ctx.err(node, format!("${key} has no value: declare it with <default name=\"{key}\" value=\"…\"/>"))
            })?;
            out.push_str(value);
            self.used.borrow_mut().insert(key.to_string());
            rest = &tail[len..];
        }
        out.push_str(rest);
        Ok(Some(out))
    }

    fn req_attr(&self, ctx: &Ctx, node: Node, name: &str) -> R<String> {
        self.attr(ctx, node, name)?
            .ok_or_else(|| ctx.err(node, format!("<{}> needs a `{name}` attribute", node.tag_name().name())))
    }

    /// A property's name as Mitsuba 3 spells it (0.x scenes used camelCase).
    fn prop_name(&self, raw: &str) -> String {
        if self.version_major >= 2 {
            return raw.to_string();
        }
        let mut out = String::new();
        let chars: Vec<char> = raw.chars().collect();
        for (i, &c) in chars.iter().enumerate() {
            let prev_lower = i > 0 && (chars[i - 1].is_lowercase() || chars[i - 1].is_ascii_digit());
            if c.is_uppercase() && prev_lower {
                out.push('_');
            }
            out.extend(c.to_lowercase());
        }
        out
    }

    fn plugin<'a, 'i>(&self, ctx: &Ctx, node: Node<'a, 'i>) -> R<Plugin<'a, 'i>> {
        Ok(Plugin { node, kind: self.req_attr(ctx, node, "type")?, used: RefCell::new(HashSet::new()) })
    }

    /// The child element holding property `name`, marking it read.
    fn prop<'a, 'i>(&self, p: &Plugin<'a, 'i>, name: &str) -> Option<Node<'a, 'i>> {
        let found = p.node.children().filter(Node::is_element).find(|c| {
            c.attribute("name").is_some_and(|n| self.prop_name(n) == name)
                && !matches!(c.tag_name().name(), "bsdf" | "emitter" | "shape" | "sensor")
                || (c.tag_name().name() == "ref" && c.attribute("name").is_some_and(|n| self.prop_name(n) == name))
        });
        if found.is_some() {
            p.used.borrow_mut().insert(name.to_string());
        }
        found
    }

    /// Warns about every property of `p` not read.
    fn unused(&mut self, ctx: &Ctx, p: &Plugin, what: &str) {
        let used = p.used.borrow().clone();
        for c in p.node.children().filter(Node::is_element) {
            let Some(name) = c.attribute("name").map(|n| self.prop_name(n)) else { continue };
            if used.contains(&name) || HARMLESS.contains(&name.as_str()) {
                continue;
            }
            if matches!(
                c.tag_name().name(),
                "bsdf" | "texture" | "ref" | "emitter" | "rfilter" | "sampler" | "film" | "medium"
            ) {
                continue;
            }
            self.warn(ctx, c, format!("property `{name}` of {what} `{}` is not supported; ignored", p.kind));
        }
    }

    fn numbers(&self, ctx: &Ctx, node: Node, text: &str) -> R<Vec<f64>> {
        text.split(|c: char| c == ',' || c.is_whitespace())
            .filter(|s| !s.is_empty())
            .map(|s| {
                s.parse::<f64>()
                    .ok()
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| ctx.err(node, format!("`{s}` is not a finite number")))
            })
            .collect()
    }

    fn float(&self, ctx: &Ctx, p: &Plugin, name: &str, default: f64) -> R<f64> {
        let Some(n) = self.prop(p, name) else { return Ok(default) };
        if !matches!(n.tag_name().name(), "float" | "integer") {
            return Err(ctx.err(n, format!("`{name}` must be a <float>")));
        }
        let v = self.numbers(ctx, n, &self.req_attr(ctx, n, "value")?)?;
        match v[..] {
            [x] => Ok(x),
            _ => Err(ctx.err(n, format!("`{name}` must be one number"))),
        }
    }

    /// A float parameter that Mitsuba also takes as a texture (`<texture>` or a `<ref>` to
    /// one): the number, or the texture (a bitmap read as its luminance where it has colour).
    fn float_or_texture(&mut self, ctx: &Ctx, p: &Plugin, name: &str, default: f64) -> R<Result<f64, Texture>> {
        let Some(n) = self.prop(p, name) else { return Ok(Ok(default)) };
        if matches!(n.tag_name().name(), "texture" | "ref") {
            return self.color_node(ctx, n).map(Err);
        }
        self.float(ctx, p, name, default).map(Ok)
    }

    /// [`Self::float_or_texture`] for a parameter the model holds constant: a texture is
    /// replaced by its mean luminance, with a warning.
    fn float_or_mean(&mut self, ctx: &Ctx, p: &Plugin, name: &str, default: f64) -> R<f64> {
        let v = self.float_or_texture(ctx, p, name, default)?;
        self.textured_mean(ctx, p, name, v)
    }

    fn string(&self, ctx: &Ctx, p: &Plugin, name: &str) -> R<Option<String>> {
        match self.prop(p, name) {
            Some(n) => self.attr(ctx, n, "value").and_then(|v| v.map(Some).ok_or_else(|| ctx.err(n, "needs `value`"))),
            None => Ok(None),
        }
    }

    fn boolean(&self, ctx: &Ctx, p: &Plugin, name: &str, default: bool) -> R<bool> {
        let Some(n) = self.prop(p, name) else { return Ok(default) };
        match self.req_attr(ctx, n, "value")?.as_str() {
            "true" | "1" => Ok(true),
            "false" | "0" => Ok(false),
            other => Err(ctx.err(n, format!("`{other}` is not a boolean (true or false)"))),
        }
    }

    /// A `<point>`/`<vector>` with `x, y, z` attributes or a `value`.
    fn point_of(&self, ctx: &Ctx, n: Node, default: Vec3) -> R<Vec3> {
        if let Some(v) = self.attr(ctx, n, "value")? {
            return match self.numbers(ctx, n, &v)?[..] {
                [x] => Ok(Vec3::splat(x)),
                [x, y, z] => Ok(Vec3::new(x, y, z)),
                _ => Err(ctx.err(n, "expected three numbers")),
            };
        }
        let mut out = default;
        for (i, axis) in ["x", "y", "z"].iter().enumerate() {
            if let Some(v) = self.attr(ctx, n, axis)? {
                out[i] = match self.numbers(ctx, n, &v)?[..] {
                    [x] => x,
                    _ => return Err(ctx.err(n, format!("`{axis}` must be one number"))),
                };
            }
        }
        Ok(out)
    }

    fn point(&self, ctx: &Ctx, p: &Plugin, name: &str, default: Vec3) -> R<Vec3> {
        match self.prop(p, name) {
            Some(n) => self.point_of(ctx, n, Vec3::ZERO),
            None => Ok(default),
        }
    }

    /// A colour: `<rgb>`, `<spectrum>`, `<float>`, or (where `textures` allows) a texture.
    fn color(&mut self, ctx: &Ctx, p: &Plugin, name: &str, default: Vec3) -> R<Texture> {
        let Some(n) = self.prop(p, name) else { return Ok(Texture::Solid(default)) };
        self.color_node(ctx, n)
    }

    fn color_node(&mut self, ctx: &Ctx, n: Node) -> R<Texture> {
        match n.tag_name().name() {
            "rgb" | "srgb" | "color" => {
                let v = self.req_attr(ctx, n, "value")?;
                let c = match self.numbers(ctx, n, &v)?[..] {
                    [x] => Vec3::splat(x),
                    [r, g, b] => Vec3::new(r, g, b),
                    _ => return Err(ctx.err(n, "an rgb value is one or three numbers")),
                };
                let c = if n.tag_name().name() == "srgb" {
                    Vec3::new(
                        alhazen_math::color::srgb_to_linear(c.x),
                        alhazen_math::color::srgb_to_linear(c.y),
                        alhazen_math::color::srgb_to_linear(c.z),
                    )
                } else {
                    c
                };
                Ok(Texture::Solid(c))
            }
            "float" | "integer" => {
                let v = self.numbers(ctx, n, &self.req_attr(ctx, n, "value")?)?;
                match v[..] {
                    [x] => Ok(Texture::Solid(Vec3::splat(x))),
                    _ => Err(ctx.err(n, "expected one number")),
                }
            }
            "spectrum" => self.spectrum(ctx, n).map(Texture::Solid),
            "texture" => self.texture(ctx, n, false),
            "ref" => {
                let id = self.req_attr(ctx, n, "id")?;
                match self.ids.get(&id) {
                    Some(Named::Texture(t)) => Ok(t.clone()),
                    Some(_) => Err(ctx.err(n, format!("\"{id}\" is not a texture"))),
                    None => Err(self.unknown_id(ctx, n, &id)),
                }
            }
            other => {
                Err(ctx.err(n, format!("<{other}> is not a colour (expected <rgb>, <spectrum>, <float> or <texture>)")))
            }
        }
    }

    /// A spectrum as Mitsuba's RGB modes take it: `λ:value` pairs weighed by the CIE matching
    /// functions (a reflectance under D65, so that a flat one is grey; an emitter's radiance as
    /// it is), one value (grey; for an emitter, that much of the flat spectrum, slightly purple
    /// in sRGB), or a file (not read: grey 0.5).
    fn spectrum(&mut self, ctx: &Ctx, n: Node) -> R<Vec3> {
        if self.attr(ctx, n, "filename")?.is_some() {
            self.warn(ctx, n, "spectra from files are not read; approximated by grey 0.5");
            return Ok(Vec3::splat(0.5));
        }
        let emitted = n.parent_element().is_some_and(|p| p.tag_name().name() == "emitter");
        let v = self.req_attr(ctx, n, "value")?;
        if !v.contains(':') {
            return match self.numbers(ctx, n, &v)?[..] {
                [x] if emitted => Ok(alhazen_math::cie::flat_emission_srgb() * x),
                [x] => Ok(Vec3::splat(x)),
                _ => Err(ctx.err(n, "a spectrum value is one number or `wavelength:value` pairs")),
            };
        }
        let (mut wavelengths, mut values) = (vec![], vec![]);
        for pair in v.split(',') {
            let (l, x) =
                pair.split_once(':').ok_or_else(|| ctx.err(n, format!("`{pair}` is not `wavelength:value`")))?;
            let [l, x] = [l, x].map(|t| self.numbers(ctx, n, t).map(|v| v.first().copied().unwrap_or(0.0)));
            let (l, x) = (l?, x?);
            if wavelengths.last().is_some_and(|&last| l <= last) {
                return Err(ctx.err(n, "a spectrum's wavelengths must increase"));
            }
            wavelengths.push(l);
            values.push(x);
        }
        if wavelengths.len() < 2 {
            return Err(ctx.err(n, "a sampled spectrum needs two `wavelength:value` pairs or more"));
        }
        let name = n.attribute("name").unwrap_or("");
        let bounded = !emitted && !matches!(name, "eta" | "k" | "int_ior" | "ext_ior");
        Ok(alhazen_math::cie::spectrum_to_linear_srgb(&wavelengths, &values, emitted, bounded))
    }

    fn unknown_id(&self, ctx: &Ctx, n: Node, id: &str) -> SceneError {
        let mut d = match ctx.err(n, format!("no object has id \"{id}\"")) {
            SceneError::Syntax(d) => d,
            e => return e,
        };
        if let Some(s) = alhazen_scene::did_you_mean(id, self.ids.keys().map(String::as_str)) {
            *d = d.clone().with_help(format!("did you mean \"{s}\"?"));
        }
        SceneError::Syntax(d)
    }

    /// The `<transform name=…>` property as a matrix (identity when absent).
    fn matrix(&self, ctx: &Ctx, p: &Plugin, name: &str) -> R<Mat4> {
        match self.prop(p, name) {
            Some(n) => self.transform_node(ctx, n),
            None => Ok(Mat4::IDENTITY),
        }
    }

    fn transform_node(&self, ctx: &Ctx, n: Node) -> R<Mat4> {
        if n.tag_name().name() != "transform" {
            return Err(ctx.err(n, "expected a <transform>"));
        }
        let mut m = Mat4::IDENTITY;
        for op in n.children().filter(Node::is_element) {
            let step = match op.tag_name().name() {
                "translate" => Mat4::from_translation(self.point_of(ctx, op, Vec3::ZERO)?),
                "scale" => Mat4::from_scale(self.point_of(ctx, op, Vec3::ONE)?),
                "rotate" => {
                    let axis = self.point_of(ctx, op, Vec3::ZERO)?;
                    let angle = self.numbers(ctx, op, &self.req_attr(ctx, op, "angle")?)?;
                    let (Some(&angle), true) = (angle.first(), axis.length() > 0.0) else {
                        return Err(ctx.err(op, "<rotate> needs a non-zero axis and an `angle` in degrees"));
                    };
                    Mat4::from_axis_angle(axis.normalize(), angle.to_radians())
                }
                "matrix" => {
                    let v = self.numbers(ctx, op, &self.req_attr(ctx, op, "value")?)?;
                    match v.len() {
                        16 => Mat4::from_cols_array(&v.try_into().expect("16 numbers")).transpose(),
                        9 => Mat4::from_mat3(Mat3::from_cols_array(&v.try_into().expect("9 numbers")).transpose()),
                        _ => return Err(ctx.err(op, "a <matrix> value is 16 numbers (row by row)")),
                    }
                }
                "lookat" => {
                    let get = |k: &str| -> R<Vec3> {
                        let v = self.numbers(ctx, op, &self.req_attr(ctx, op, k)?)?;
                        match v[..] {
                            [x, y, z] => Ok(Vec3::new(x, y, z)),
                            _ => Err(ctx.err(op, format!("`{k}` must be three numbers"))),
                        }
                    };
                    let (origin, target) = (get("origin")?, get("target")?);
                    let dir = (target - origin).normalize_or_zero();
                    let up = match self.attr(ctx, op, "up")? {
                        Some(_) => get("up")?,
                        None => dir.any_orthonormal_vector(),
                    };
                    let left = up.cross(dir).normalize_or_zero();
                    if dir == Vec3::ZERO || left == Vec3::ZERO {
                        return Err(ctx.err(op, "<lookat>: origin and target coincide, or up is parallel to the view"));
                    }
                    let new_up = dir.cross(left);
                    Mat4::from_cols(left.extend(0.0), new_up.extend(0.0), dir.extend(0.0), origin.extend(1.0))
                }
                other => {
                    return Err(ctx.err(
                        op,
                        format!("<{other}> is not a transformation (translate, rotate, scale, matrix, lookat)"),
                    ));
                }
            };
            m = step * m;
        }
        Ok(m)
    }

    fn transform(&self, ctx: &Ctx, node: Node, m: Mat4) -> R<Transform> {
        Transform::from_matrix(m).map_err(|e| ctx.err(node, format!("to_world: {e}")))
    }

    // ---- integrator, sensor --------------------------------------------------------------

    fn integrator(&mut self, ctx: &Ctx, node: Node) -> R<()> {
        let p = self.plugin(ctx, node)?;
        // A wrapping integrator (`aov`, `moment`) reads its inner one next: the last is the one.
        self.integrator_kind = Some(p.kind.clone());
        let depth = self.float(ctx, &p, "max_depth", -1.0)?;
        let r = &mut self.scene.render;
        r.integrator = IntegratorKind::Path;
        r.max_depth = if depth < 0.0 { 1000 } else { (depth as u32).min(1000) };
        match p.kind.as_str() {
            "path" | "volpath" | "volpathmis" | "prb" | "prb_basic" => {}
            "direct" => self.scene.render.max_depth = 2,
            other => {
                self.warn(ctx, node, format!("integrator `{other}` is rendered by alhazen's path tracer"));
                if let Some(inner) = node.children().find(|c| c.tag_name().name() == "integrator") {
                    return self.integrator(ctx, inner);
                }
            }
        }
        self.float(ctx, &p, "rr_depth", 5.0)?;
        self.unused(ctx, &p, "integrator");
        Ok(())
    }

    fn sensor(&mut self, ctx: &Ctx, node: Node) -> R<()> {
        if self.camera_seen {
            self.warn(ctx, node, "more than one sensor: the first is used");
            return Ok(());
        }
        self.camera_seen = true;
        let p = self.plugin(ctx, node)?;
        // Mitsuba's default pixel filter (a film's `rfilter` replaces it): its Gaussian of
        // standard deviation ½ pixel, cut at four.
        self.scene.render.filter = PixelFilter::Gaussian { sigma: 0.5, radius: [2.0; 2] };
        for child in node.children().filter(Node::is_element) {
            match child.tag_name().name() {
                "film" => self.film(ctx, child)?,
                "sampler" => self.sampler(ctx, child)?,
                _ => {}
            }
        }
        let m = self.matrix(ctx, &p, "to_world")?;
        let l = Mat3::from_mat4(m);
        let eye = m.transform_point3(Vec3::ZERO);
        let (fwd, up) = ((l * Vec3::Z).normalize_or_zero(), (l * Vec3::Y).normalize_or_zero());
        if fwd == Vec3::ZERO || up == Vec3::ZERO || !common::finite(&[eye.x, eye.y, eye.z]) {
            return Err(ctx.err(node, "the sensor's to_world is singular"));
        }
        if l.determinant() < 0.0 {
            self.warn(ctx, node, "the sensor's to_world mirrors the image; alhazen renders it unmirrored");
        }
        let look = LookAt { eye, target: eye + fwd, up };
        let (w, h) = (self.scene.render.width as f64, self.scene.render.height as f64);
        self.scene.camera = match p.kind.as_str() {
            "perspective" | "thinlens" => {
                // Mitsuba's thin lens: in focus at its far clip (10⁴) unless told otherwise.
                let lens = if p.kind == "thinlens" {
                    let aperture = self.float(ctx, &p, "aperture_radius", f64::NAN)?;
                    let far = self.float(ctx, &p, "far_clip", 1e4)?;
                    let focus_distance = self.float(ctx, &p, "focus_distance", far)?;
                    if !(aperture > 0.0 && aperture.is_finite() && focus_distance > 0.0 && focus_distance.is_finite()) {
                        return Err(ctx.err(node, "a thinlens needs a positive `aperture_radius` and `focus_distance`"));
                    }
                    Some(alhazen_scene::ThinLens { aperture, focus_distance })
                } else {
                    None
                };
                let axis = self.string(ctx, &p, "fov_axis")?.unwrap_or_else(|| "x".into());
                // Without `fov`, Mitsuba's focal length, 50 mm unless given.
                let focal_length = self.string(ctx, &p, "focal_length")?.unwrap_or_else(|| "50mm".into());
                let (fov, axis) = if self.prop(&p, "fov").is_none() {
                    let mm = focal_length.trim_end_matches("mm").trim().parse::<f64>().ok().filter(|f| *f > 0.0);
                    let mm = mm.ok_or_else(|| {
                        ctx.err(node, format!("focal_length \"{focal_length}\" is not a length in mm"))
                    })?;
                    // Mitsuba measures the focal length against a 36 × 24 mm film's diagonal.
                    (2.0 * (0.5 * 36f64.hypot(24.0) / mm).atan().to_degrees(), "diagonal".to_string())
                } else {
                    (self.float(ctx, &p, "fov", 0.0)?, axis)
                };
                if !(fov > 0.0 && fov < 180.0) {
                    return Err(ctx.err(node, "a perspective sensor needs `fov` in (0, 180) degrees"));
                }
                let half = (fov.to_radians() / 2.0).tan();
                let (angle, horizontal) = match axis.as_str() {
                    "x" => (fov.to_radians(), true),
                    "y" => (fov.to_radians(), false),
                    "diagonal" => (2.0 * (half * w / w.hypot(h)).atan(), true),
                    "smaller" => (fov.to_radians(), w <= h),
                    "larger" => (fov.to_radians(), w >= h),
                    other => {
                        return Err(
                            ctx.err(node, format!("fov_axis \"{other}\" is not x, y, diagonal, smaller or larger"))
                        );
                    }
                };
                CameraDesc::Perspective { look, opening: PerspectiveOpening::Fov { angle, horizontal }, lens }
            }
            "orthographic" => {
                // The sensor sees [-1, 1] along its shorter axis, scaled by to_world.
                let sx = (l * Vec3::X).length();
                CameraDesc::Orthographic { look, width: 2.0 * sx * (w / h).max(1.0) }
            }
            other => {
                self.warn(ctx, node, format!("sensor `{other}` is not supported; a 45° perspective camera stands in"));
                CameraDesc::Perspective {
                    look,
                    opening: PerspectiveOpening::Fov { angle: 45f64.to_radians(), horizontal: true },
                    lens: None,
                }
            }
        };
        self.unused(ctx, &p, "sensor");
        Ok(())
    }

    fn film(&mut self, ctx: &Ctx, node: Node) -> R<()> {
        let p = self.plugin(ctx, node)?;
        let size = |x: f64, n: Node| -> R<u32> {
            (x >= 1.0 && x <= alhazen_scene::MAX_SIDE as f64 && x.fract() == 0.0).then_some(x as u32).ok_or_else(|| {
                ctx.err(n, format!("film size {x} is not a whole number of pixels in 1–{}", alhazen_scene::MAX_SIDE))
            })
        };
        self.scene.render.width = size(self.float(ctx, &p, "width", 768.0)?, node)?;
        self.scene.render.height = size(self.float(ctx, &p, "height", 576.0)?, node)?;
        if (self.scene.render.width as u64) * (self.scene.render.height as u64) > alhazen_scene::MAX_PIXELS {
            return Err(ctx.err(node, "the film has more pixels than alhazen can allocate"));
        }
        if let Some(f) = node.children().find(|c| c.tag_name().name() == "rfilter") {
            self.scene.render.filter = self.rfilter(ctx, f)?;
        }
        for crop in ["crop_width", "crop_height", "crop_offset_x", "crop_offset_y"] {
            if let Some(n) = self.prop(&p, crop) {
                self.warn(ctx, n, format!("`{crop}` is ignored: the whole film is rendered"));
            }
        }
        self.unused(ctx, &p, "film");
        Ok(())
    }

    /// A film's `rfilter`: Mitsuba's box (its own pixel), tent, Gaussian (cut at four standard
    /// deviations), Mitchell–Netravali, Catmull–Rom and Lanczos filters.
    fn rfilter(&mut self, ctx: &Ctx, node: Node) -> R<PixelFilter> {
        let p = self.plugin(ctx, node)?;
        let filter = match p.kind.as_str() {
            "box" => PixelFilter::PIXEL,
            "tent" => PixelFilter::Tent { radius: [self.float(ctx, &p, "radius", 1.0)?; 2] },
            "gaussian" => {
                let sigma = self.float(ctx, &p, "stddev", 0.5)?;
                PixelFilter::Gaussian { sigma, radius: [4.0 * sigma; 2] }
            }
            "mitchell" => PixelFilter::Mitchell {
                b: self.float(ctx, &p, "B", 1.0 / 3.0)?,
                c: self.float(ctx, &p, "C", 1.0 / 3.0)?,
                radius: [2.0; 2],
            },
            "catmullrom" => PixelFilter::Mitchell { b: 0.0, c: 0.5, radius: [2.0; 2] },
            "lanczos" => {
                let lobes = self.float(ctx, &p, "lobes", 3.0)?;
                PixelFilter::Lanczos { tau: lobes, radius: [lobes; 2] }
            }
            other => {
                return Err(ctx.err(
                    node,
                    format!(
                        "unknown pixel filter `{other}`; expected one of box, tent, gaussian, mitchell, catmullrom, lanczos"
                    ),
                ));
            }
        };
        if let Some(why) = filter.problem() {
            return Err(ctx.err(node, why));
        }
        self.unused(ctx, &p, "rfilter");
        Ok(filter)
    }

    fn sampler(&mut self, ctx: &Ctx, node: Node) -> R<()> {
        let p = self.plugin(ctx, node)?;
        let spp = self.float(ctx, &p, "sample_count", 4.0)?;
        if !(1.0..=1048576.0).contains(&spp) {
            return Err(ctx.err(node, "sample_count must be 1–1048576"));
        }
        self.scene.render.spp = spp as u32;
        let seed = self.float(ctx, &p, "seed", 0.0)?;
        self.scene.render.seed = seed.max(0.0) as u64;
        self.scene.render.sampler = if p.kind == "independent" { SamplerKind::Independent } else { SamplerKind::Sobol };
        self.unused(ctx, &p, "sampler");
        Ok(())
    }

    // ---- materials -----------------------------------------------------------------------

    /// The black diffuse BSDF Mitsuba gives an emitting shape without one.
    fn black_material(&mut self) -> MaterialId {
        if let Some(id) = self.black_material {
            return id;
        }
        let m = alhazen_scene::Material::from_bsdf(
            "mitsuba emitter default",
            BsdfDesc::Lambert { albedo: Texture::Solid(Vec3::ZERO) },
        );
        let id = common::add_material(&mut self.scene, m);
        self.black_material = Some(id);
        id
    }

    fn default_material(&mut self) -> MaterialId {
        if let Some(id) = self.default_material {
            return id;
        }
        let mut m = alhazen_scene::Material::from_bsdf(
            "mitsuba default",
            BsdfDesc::Lambert { albedo: Texture::Solid(Vec3::splat(0.5)) },
        );
        m.one_sided = true;
        let id = common::add_material(&mut self.scene, m);
        self.default_material = Some(id);
        id
    }

    /// A `<bsdf>` element as a new material: one-sided, as Mitsuba's are, unless wrapped in
    /// `twosided` or letting light through.
    fn bsdf_material(&mut self, ctx: &Ctx, node: Node) -> R<MaterialId> {
        (self.cut_out, self.vertex_colored) = (None, false);
        let (desc, bump) = self.bsdf(ctx, node, 0)?;
        let name = self.attr(ctx, node, "id")?.unwrap_or_else(|| format!("bsdf at line {}", ctx.line(node)));
        let one_sided = !self.is_twosided(node, 0) && reflects_only(&desc);
        let mut m = alhazen_scene::Material::from_bsdf(&name, desc);
        (m.bump, m.one_sided, m.alpha) = (bump, one_sided, self.cut_out.take());
        m.vertex_colors = std::mem::take(&mut self.vertex_colored);
        Ok(common::add_material(&mut self.scene, m))
    }

    /// True when the BSDF `node` shades both sides: a `twosided`, or a wrapper of one (a bump
    /// or normal map, a mask), or a reference to a two-sided material.
    fn is_twosided(&self, node: Node, depth: usize) -> bool {
        if depth > 32 {
            return false;
        }
        match (node.tag_name().name(), node.attribute("type")) {
            ("ref", _) => node.attribute("id").is_some_and(
                |id| matches!(self.ids.get(id), Some(Named::Bsdf(m)) if !self.scene.materials[*m as usize].one_sided),
            ),
            (_, Some("twosided")) => true,
            (_, Some("bumpmap" | "normalmap" | "mask")) => node
                .children()
                .find(|c| c.tag_name().name() == "bsdf" || c.tag_name().name() == "ref")
                .is_some_and(|inner| self.is_twosided(inner, depth + 1)),
            _ => false,
        }
    }

    /// The nested BSDF of a wrapper (`twosided`, `bumpmap`, …).
    fn inner_bsdf(&mut self, ctx: &Ctx, node: Node, depth: usize) -> R<(BsdfDesc, Option<Bump>)> {
        let children: Vec<Node> = node
            .children()
            .filter(|c| {
                c.tag_name().name() == "bsdf"
                    || (c.tag_name().name() == "ref" && c.attribute("name").is_none_or(|n| n.starts_with("bsdf")))
            })
            .collect();
        let Some(first) = children.first() else {
            return Err(ctx.err(node, "this BSDF needs a nested <bsdf> (or <ref> to one)"));
        };
        if children.len() > 1 && node.attribute("type") == Some("twosided") {
            self.warn(ctx, node, "twosided with a different back BSDF: the front BSDF is used on both sides");
        }
        self.bsdf_ref(ctx, *first, depth + 1)
    }

    fn bsdf_ref(&mut self, ctx: &Ctx, n: Node, depth: usize) -> R<(BsdfDesc, Option<Bump>)> {
        if n.tag_name().name() == "bsdf" {
            return self.bsdf(ctx, n, depth);
        }
        let id = self.req_attr(ctx, n, "id")?;
        match self.ids.get(&id) {
            Some(Named::Bsdf(m)) => {
                let m = &self.scene.materials[*m as usize];
                if m.alpha.is_some() {
                    self.cut_out = m.alpha.clone();
                }
                Ok((m.bsdf.clone().expect("imported materials have a BSDF"), m.bump.clone()))
            }
            Some(_) => Err(ctx.err(n, format!("\"{id}\" is not a BSDF"))),
            None => Err(self.unknown_id(ctx, n, &id)),
        }
    }

    /// A `<bsdf>` element as a BSDF description and an optional bump map.
    fn bsdf(&mut self, ctx: &Ctx, node: Node, depth: usize) -> R<(BsdfDesc, Option<Bump>)> {
        if depth > 32 {
            return Err(ctx.err(node, "BSDFs nested deeper than 32 levels"));
        }
        let p = self.plugin(ctx, node)?;
        let kind = p.kind.clone();
        let mut bump = None;
        let desc = match kind.as_str() {
            "twosided" => return self.inner_bsdf(ctx, node, depth),
            "diffuse" => BsdfDesc::Lambert { albedo: self.color(ctx, &p, "reflectance", Vec3::splat(0.5))? },
            "conductor" | "roughconductor" => {
                let facets = self.facets(ctx, &p, kind == "roughconductor")?;
                let tint = self.constant_color(ctx, &p, "specular_reflectance", Vec3::ONE)?;
                let (eta, k) = match self.string(ctx, &p, "material")? {
                    Some(name) => self.named_metal(ctx, node, &name),
                    None if self.prop(&p, "eta").is_some() || self.prop(&p, "k").is_some() => (
                        self.constant_color(ctx, &p, "eta", Vec3::ZERO)?,
                        self.constant_color(ctx, &p, "k", Vec3::ONE)?,
                    ),
                    None => (Vec3::ZERO, Vec3::ZERO),
                };
                BsdfDesc::Conductor { facets, eta, k, tint, fresnel: FresnelMode::Exact, multiscatter: false }
            }
            "dielectric" | "roughdielectric" | "thindielectric" => {
                let ior = self.ior(ctx, &p, 1.5046)?;
                // A dielectric's transmission may be tinted; its reflection, and a thin one's, not.
                let unread: &[&str] = if kind == "thindielectric" {
                    &["specular_reflectance", "specular_transmittance"]
                } else {
                    &["specular_reflectance"]
                };
                for key in unread {
                    if let Some(n) = self.prop(&p, key) {
                        self.warn(ctx, n, format!("`{key}` of a {kind} is not supported: taken as 1"));
                    }
                }
                if kind == "thindielectric" {
                    if ior < 1.0 {
                        self.warn(
                            ctx,
                            node,
                            format!("a thin dielectric's index {ior} below 1 is taken as 1 (no reflection)"),
                        );
                    }
                    BsdfDesc::ThinDielectric { ior: ior.max(1.0) }
                } else {
                    let facets = self.facets(ctx, &p, kind == "roughdielectric")?;
                    let transmittance = self.color(ctx, &p, "specular_transmittance", Vec3::ONE)?;
                    BsdfDesc::Dielectric {
                        facets,
                        ior: Ior::Constant(ior),
                        fresnel: FresnelMode::Exact,
                        transmittance,
                        film: None,
                    }
                }
            }
            "plastic" | "roughplastic" => {
                let albedo = self.color(ctx, &p, "diffuse_reflectance", Vec3::splat(0.5))?;
                // Mitsuba's default coat is polypropylene.
                let ior = self.ior(ctx, &p, 1.49)?;
                if !(ior > 1.0 && ior.is_finite()) {
                    return Err(
                        ctx.err(node, format!("{kind}: the coat's index must exceed the outside's (got {ior})"))
                    );
                }
                let facets = self.facets(ctx, &p, kind == "roughplastic")?;
                if facets.is_some_and(|f| f.alpha_u != f.alpha_v) {
                    return Err(ctx.err(node, "roughplastic takes one alpha, not alpha_u and alpha_v (as Mitsuba)"));
                }
                if self.prop(&p, "specular_reflectance").is_some() {
                    self.warn(ctx, node, "specular_reflectance is not supported: the coat is clear (1)");
                }
                let nonlinear = self.boolean(ctx, &p, "nonlinear", false)?;
                BsdfDesc::Plastic { albedo, ior, facets, nonlinear }
            }
            "principled" => {
                let base = self.color(ctx, &p, "base_color", Vec3::splat(0.8))?;
                let mean = self.pending.texture_mean(&base, &mut self.scene)?;
                let ior = self.float(ctx, &p, "eta", 1.5)?;
                let trans = self.float_or_mean(ctx, &p, "spec_trans", 0.0)?;
                self.warn(ctx, node, "principled is approximated by the glTF metallic–roughness model (base colour, metallic, roughness, anisotropic, eta, spec_trans; a clear coat for clearcoat)");
                let anisotropic = self.float_or_mean(ctx, &p, "anisotropic", 0.0)?;
                if !(0.0..=1.0).contains(&anisotropic) {
                    return Err(
                        ctx.err(node, format!("principled: `anisotropic` must lie within [0, 1] (got {anisotropic})"))
                    );
                }
                let anisotropy = Anisotropy { strength: anisotropic, rotation: 0.0, model: AnisotropyModel::Disney };
                let bsdf = self.principled(ctx, &p, (base, mean), (ior, anisotropy), trans)?;
                // Its clear coat: GTR1 facets of α from 0.1 to 0.001 with `clearcoat_gloss`, a
                // quarter of `clearcoat` strong, read as a coat of GGX facets (α at least 0.01).
                let clearcoat = self.float_or_mean(ctx, &p, "clearcoat", 0.0)?;
                let gloss = self.float_or_mean(ctx, &p, "clearcoat_gloss", 0.0)?;
                self.float(ctx, &p, "clearcoat_sampling_rate", 1.0)?;
                if clearcoat > 0.0 {
                    let alpha = (0.1 + (0.001 - 0.1) * gloss.clamp(0.0, 1.0)).max(0.01);
                    let (weight, facets) = ((0.25 * clearcoat).min(1.0), common::ggx(alpha, alpha));
                    BsdfDesc::Coated {
                        base: Box::new(bsdf),
                        weight,
                        facets,
                        ior: 1.5,
                        weight_map: None,
                        roughness_map: None,
                    }
                } else {
                    bsdf
                }
            }
            "blendbsdf" => {
                let w = match self.prop(&p, "weight") {
                    Some(n) => self.color_node(ctx, n)?,
                    None => Texture::Solid(Vec3::splat(0.5)),
                };
                let kids: Vec<Node> = node
                    .children()
                    .filter(|c| matches!(c.tag_name().name(), "bsdf" | "ref") && c.attribute("name") != Some("weight"))
                    .collect();
                let [a, b] = kids[..] else { return Err(ctx.err(node, "blendbsdf needs two nested BSDFs")) };
                let (a, _) = self.bsdf_ref(ctx, a, depth + 1)?;
                let (b, _) = self.bsdf_ref(ctx, b, depth + 1)?;
                // Weight 0 is the first BSDF, 1 the second; a textured weight is read per point
                // (its luminance, as Mitsuba reads a colour bitmap where it wants a number).
                match w {
                    Texture::Solid(w) => common::mix(b, a, luminance(w).clamp(0.0, 1.0)),
                    map => BsdfDesc::Mix { a: Box::new(b), b: Box::new(a), weight: 1.0, weight_map: Some(map) },
                }
            }
            "bumpmap" => {
                let tex = node.children().find(|c| {
                    matches!(c.tag_name().name(), "texture")
                        || (c.tag_name().name() == "ref"
                            && c.attribute("name").is_none_or(|n| !n.starts_with("bsdf"))
                            && self.is_texture_ref(c))
                });
                let Some(tex) = tex else { return Err(ctx.err(node, "bumpmap needs a nested height <texture>")) };
                let tex = self.color_node(ctx, tex)?;
                let scale = self.float(ctx, &p, "scale", 1.0)?;
                let (inner, _) = self.inner_bsdf(ctx, node, depth)?;
                bump = match tex {
                    Texture::Image { image, scale: s, offset, rotation } => {
                        if offset != Vec2::ZERO || rotation != 0.0 {
                            self.warn(ctx, node, "a bump map's to_uv shift and rotation are not supported; ignored");
                        }
                        Some(Bump { height: scale, pattern: BumpPattern::Image { image, scale: s } })
                    }
                    _ => {
                        self.warn(ctx, node, "only bitmap textures can be bump maps; the bump map is ignored");
                        None
                    }
                };
                inner
            }
            "normalmap" => {
                let tex = node.children().find(|c| {
                    c.tag_name().name() == "texture" || (c.tag_name().name() == "ref" && self.is_texture_ref(c))
                });
                let Some(tex) = tex else { return Err(ctx.err(node, "normalmap needs a nested <texture>")) };
                // Normal maps hold vectors, not colours: read linearly whatever `raw` says.
                let tex = if tex.tag_name().name() == "texture" {
                    self.texture(ctx, tex, true)?
                } else {
                    self.color_node(ctx, tex)?
                };
                p.used.borrow_mut().insert("normalmap".to_string());
                let (inner, _) = self.inner_bsdf(ctx, node, depth)?;
                bump = match tex {
                    map @ Texture::Image { .. } => Some(Bump { height: 1.0, pattern: BumpPattern::NormalMap { map } }),
                    _ => {
                        self.warn(ctx, node, "only bitmap textures can be normal maps; the normal map is ignored");
                        None
                    }
                };
                inner
            }
            "mask" => {
                // Mitsuba's opacity (0.5 unless given) picks its nested BSDF or a passage
                // straight through, at random: a coverage without cutoff.
                let coverage = self.color(ctx, &p, "opacity", Vec3::splat(0.5))?;
                let inner = self.inner_bsdf(ctx, node, depth)?;
                self.unused(ctx, &p, "bsdf");
                self.cut_out = Some(alhazen_scene::Alpha { coverage, cutoff: None });
                return Ok(inner);
            }
            other => {
                self.warn(
                    ctx,
                    node,
                    format!("BSDF `{other}` is not supported; approximated by a diffuse reflectance of 0.5"),
                );
                return Ok((BsdfDesc::Lambert { albedo: Texture::Solid(Vec3::splat(0.5)) }, None));
            }
        };
        self.unused(ctx, &p, "bsdf");
        Ok((desc, bump))
    }

    /// An `area` emitter's radiance, as a texture.
    fn area_radiance(&mut self, ctx: &Ctx, node: Node) -> R<Texture> {
        let e = self.plugin(ctx, node)?;
        if e.kind != "area" {
            return Err(ctx.err(node, format!("a shape can only hold an `area` emitter, not `{}`", e.kind)));
        }
        let radiance = self.color(ctx, &e, "radiance", Vec3::ONE)?;
        self.unused(ctx, &e, "emitter");
        Ok(radiance)
    }

    fn is_area_emitter_ref(&self, n: &Node) -> bool {
        n.attribute("id").is_some_and(|id| matches!(self.ids.get(id), Some(Named::AreaEmitter(_))))
    }

    fn is_texture_ref(&self, n: &Node) -> bool {
        n.attribute("id").is_some_and(|id| matches!(self.ids.get(id), Some(Named::Texture(_))))
    }

    /// A colour that the model holds constant (a texture is replaced by its mean, with a warning).
    fn constant_color(&mut self, ctx: &Ctx, p: &Plugin, name: &str, default: Vec3) -> R<Vec3> {
        let t = self.color(ctx, p, name, default)?;
        if !matches!(t, Texture::Solid(_)) {
            let n = self.prop(p, name).expect("read above");
            self.warn(ctx, n, format!("a textured `{name}` is replaced by its mean colour"));
        }
        self.pending.texture_mean(&t, &mut self.scene)
    }

    fn named_metal(&mut self, ctx: &Ctx, node: Node, name: &str) -> (Vec3, Vec3) {
        if name == "none" {
            return (Vec3::ZERO, Vec3::ZERO);
        }
        let ours = METAL_NAMES.iter().find(|m| m.0 == name).map(|m| m.1);
        let listed = |name: &str| MITSUBA_METALS.iter().find(|m| m.0 == name);
        let theirs = || {
            let m = listed(name).or_else(|| name.strip_suffix("_palik").and_then(listed));
            m.map(|m| (Vec3::from_array(m.1), Vec3::from_array(m.2)))
        };
        match ours.and_then(alhazen_scene::bsdf::metal).or_else(theirs) {
            Some(ek) => ek,
            None => {
                self.warn(ctx, node, format!("conductor material \"{name}\" is not one of Mitsuba's named conductors; rendered as a perfect mirror"));
                (Vec3::ZERO, Vec3::ZERO)
            }
        }
    }

    /// `int_ior / ext_ior` (numbers or material names), or `eta`; `default_int` when neither
    /// is given.
    fn ior(&mut self, ctx: &Ctx, p: &Plugin, default_int: f64) -> R<f64> {
        let one = |imp: &mut Self, key: &str, default: f64| -> R<f64> {
            let Some(n) = imp.prop(p, key) else { return Ok(default) };
            let v = imp.req_attr(ctx, n, "value")?;
            if n.tag_name().name() == "string" {
                return common::named_ior(&v).ok_or_else(|| {
                    let names: Vec<&str> = common::NAMED_IORS.iter().map(|e| e.0).collect();
                    ctx.err(n, format!("\"{v}\" is not a known material (known: {})", names.join(", ")))
                });
            }
            match imp.numbers(ctx, n, &v)?[..] {
                [x] if x > 0.0 => Ok(x),
                _ => Err(ctx.err(n, format!("`{key}` must be a positive number or a material name"))),
            }
        };
        let int = one(self, "int_ior", default_int)?;
        let ext = one(self, "ext_ior", 1.000277)?;
        if self.prop(p, "eta").is_some() {
            return self.float(ctx, p, "eta", 1.5);
        }
        Ok(int / ext)
    }

    /// `distribution`, `alpha` / `alpha_u`, `alpha_v` of a rough BSDF; `None` for a smooth one.
    fn facets(&mut self, ctx: &Ctx, p: &Plugin, rough: bool) -> R<Option<Microfacets>> {
        if !rough {
            return Ok(None);
        }
        let distribution = match self.string(ctx, p, "distribution")?.as_deref() {
            None | Some("beckmann") => Distribution::Beckmann,
            Some("ggx") => Distribution::TrowbridgeReitz,
            Some(other) => {
                let n = self.prop(p, "distribution").expect("read above");
                return Err(ctx.err(n, format!("distribution \"{other}\" is not beckmann or ggx")));
            }
        };
        let alpha = self.float_or_mean(ctx, p, "alpha", 0.1)?;
        let au = self.float_or_mean(ctx, p, "alpha_u", alpha)?;
        let av = self.float_or_mean(ctx, p, "alpha_v", alpha)?;
        self.boolean(ctx, p, "sample_visible", true)?;
        if !(au > 0.0 && av > 0.0) {
            return Err(ctx.err(p.node, "roughness `alpha` must be positive"));
        }
        Ok(Some(Microfacets { distribution, alpha_u: au, alpha_v: av, shadowing: Shadowing::Smith }))
    }

    /// Principled's metallic–roughness part: read per point where roughness or metallic is a
    /// texture (both sampled into one map, roughness in green and metalness in blue, on the
    /// grid of the larger image; `BsdfDesc::MetallicRoughness`) or the base colour of a metal
    /// is; the constant mix otherwise, and under specular transmission (textures by their
    /// means, with a warning).
    fn principled(
        &mut self,
        ctx: &Ctx,
        p: &Plugin,
        (base, mean): (Texture, Vec3),
        (ior, anisotropy): (f64, Anisotropy),
        trans: f64,
    ) -> R<BsdfDesc> {
        let anisotropy = if anisotropy.is_anisotropic() && trans > 0.0 {
            let n = self.prop(p, "anisotropic").expect("read above");
            self.warn(ctx, n, "`anisotropic` under specular transmission is not supported; ignored");
            Anisotropy::default()
        } else {
            anisotropy
        };
        let metallic = self.float_or_texture(ctx, p, "metallic", 0.0)?;
        let roughness = self.float_or_texture(ctx, p, "roughness", 0.5)?;
        // The bitmaps' placements (scale, shift, turn): one map serves both where they agree.
        let placement_of = |t: &Result<f64, Texture>| match t {
            Err(Texture::Image { scale, offset, rotation, .. }) => Some((*scale, *offset, *rotation)),
            _ => None,
        };
        let placements: Vec<(Vec2, Vec2, f64)> =
            [placement_of(&metallic), placement_of(&roughness)].into_iter().flatten().collect();
        let mapped = metallic.is_err() || roughness.is_err();
        if mapped && trans <= 0.0 && placements.windows(2).all(|w| w[0] == w[1]) {
            for t in [&metallic, &roughness] {
                if let Err(Texture::Image { image, .. }) = t {
                    self.pending.load_image_now(&mut self.scene, *image)?;
                }
            }
            let image = metal_rough_map(&self.scene.images, &roughness, &metallic);
            self.scene.images.push(Arc::new(image));
            let (scale, offset, rotation) = placements.first().copied().unwrap_or((Vec2::ONE, Vec2::ZERO, 0.0));
            let map = Some(Texture::Image { image: self.scene.images.len() - 1, scale, offset, rotation });
            let (metallic, roughness) = (metallic.unwrap_or(1.0), roughness.unwrap_or(1.0));
            let (metallic, roughness) = (metallic.clamp(0.0, 1.0), roughness.clamp(0.0, 1.0));
            return Ok(BsdfDesc::MetallicRoughness {
                base,
                metallic,
                roughness,
                map,
                ior,
                specular: 1.0,
                multiscatter: false,
                anisotropy,
                anisotropy_map: None,
                iridescence: None,
                specular_map: None,
                specular_color_map: None,
                translucency: Default::default(),
                translucency_map: None,
                translucency_color_map: None,
            });
        }
        let metallic = self.textured_mean(ctx, p, "metallic", metallic)?;
        let roughness = self.textured_mean(ctx, p, "roughness", roughness)?;
        let textured_metal = metallic > 0.0 && trans <= 0.0 && !matches!(base, Texture::Solid(_));
        if textured_metal || anisotropy.is_anisotropic() {
            // A textured metal takes each point's base colour; stretched facets turn with the
            // surface's tangent.
            let (metallic, roughness) = (metallic.clamp(0.0, 1.0), roughness.clamp(0.0, 1.0));
            return Ok(BsdfDesc::MetallicRoughness {
                base,
                metallic,
                roughness,
                map: None,
                ior,
                specular: 1.0,
                multiscatter: false,
                anisotropy,
                anisotropy_map: None,
                iridescence: None,
                specular_map: None,
                specular_color_map: None,
                translucency: Default::default(),
                translucency_map: None,
                translucency_color_map: None,
            });
        }
        Ok(common::metal_rough(
            base,
            mean,
            metallic,
            roughness,
            (ior, common::plain_lobes(ior)),
            common::Glass::clear(trans, Texture::Solid(mean.powf(0.5))),
        ))
    }

    /// `v`, or the mean luminance of its texture (parameter `name`), with a warning.
    fn textured_mean(&mut self, ctx: &Ctx, p: &Plugin, name: &str, v: Result<f64, Texture>) -> R<f64> {
        match v {
            Ok(x) => Ok(x),
            Err(t) => {
                let n = self.prop(p, name).expect("read above");
                self.warn(ctx, n, format!("a textured `{name}` is replaced by its mean"));
                Ok(luminance(self.pending.texture_mean(&t, &mut self.scene)?))
            }
        }
    }

    /// A `<texture>`; `linear` reads a bitmap without sRGB decoding (normal maps).
    fn texture(&mut self, ctx: &Ctx, node: Node, linear: bool) -> R<Texture> {
        let p = self.plugin(ctx, node)?;
        let uv = self.matrix(ctx, &p, "to_uv")?;
        // A scale, a turn and a shift (Mitsuba reads its image at to_uv · uv, `v` down, as
        // alhazen reads the image turned upside down at `uv`): the same numbers.
        let (scale, offset, rotation) = match uv_placement(&uv) {
            Some(placement) => placement,
            None => {
                self.warn(ctx, node, "to_uv other than a scale, a rotation and a shift is not supported; ignored");
                (Vec2::ONE, Vec2::ZERO, 0.0)
            }
        };
        let t = match p.kind.as_str() {
            "bitmap" => {
                let name =
                    self.string(ctx, &p, "filename")?.ok_or_else(|| ctx.err(node, "bitmap needs a `filename`"))?;
                let path = self.resolve(ctx, &name, false);
                let raw = self.boolean(ctx, &p, "raw", false)? || linear;
                let hdr = matches!(
                    path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref(),
                    Some("exr" | "hdr" | "pfm")
                );
                // Read with the other files once the walk is done. Mitsuba reads texture
                // coordinate v = 0 at the image's top row, alhazen at its bottom (as OpenGL and
                // glTF's flipped convention do): turned upside down, the image shows each
                // coordinate the texel Mitsuba shows it.
                let (images, at) = (&mut self.scene.images, (ctx.path, ctx.shared));
                let index = self.pending.push_image(images, &path, (hdr || raw, true), at, node.range());
                let wrap = match self.string(ctx, &p, "wrap_mode")?.as_deref() {
                    None | Some("repeat") => Wrap::Repeat,
                    Some("mirror") => Wrap::Mirror,
                    Some("clamp") => Wrap::Clamp,
                    Some(other) => {
                        return Err(
                            ctx.err(node, format!("unknown wrap_mode \"{other}\"; expected repeat, mirror or clamp"))
                        );
                    }
                };
                std::sync::Arc::make_mut(&mut self.scene.images[index]).wrap = [wrap; 2];
                self.string(ctx, &p, "filter_type")?;
                Texture::Image { image: index, scale, offset, rotation }
            }
            "checkerboard" => {
                if offset != Vec2::ZERO || rotation != 0.0 {
                    self.warn(ctx, node, "a checkerboard's to_uv shift and rotation are not supported; ignored");
                }
                let even = self.constant_color(ctx, &p, "color0", Vec3::splat(0.4))?;
                let odd = self.constant_color(ctx, &p, "color1", Vec3::splat(0.2))?;
                if scale.x != scale.y {
                    self.warn(ctx, node, "a checkerboard scaled differently in u and v uses the mean scale");
                }
                Texture::Checker { even, odd, size: 1.0 / (scale.x + scale.y) }
            }
            "mesh_attribute" => {
                let name = self.string(ctx, &p, "name")?.unwrap_or_default();
                let scale = self.float(ctx, &p, "scale", 1.0)?;
                if !(scale.is_finite() && (0.0..=1e6).contains(&scale)) {
                    return Err(ctx.err(node, "a mesh_attribute's `scale` must be a number in [0, 10⁶]"));
                }
                if name != "vertex_color" {
                    self.warn(
                        ctx,
                        node,
                        format!(
                            "mesh attribute `{name}` is not supported (only vertex_color); approximated by grey 0.5"
                        ),
                    );
                    return Ok(Texture::Solid(Vec3::splat(0.5)));
                }
                // The material multiplies its base colour by the mesh's colours.
                self.vertex_colored = true;
                Texture::Solid(Vec3::splat(scale))
            }
            other => {
                self.warn(ctx, node, format!("texture `{other}` is not supported; approximated by grey 0.5"));
                return Ok(Texture::Solid(Vec3::splat(0.5)));
            }
        };
        self.unused(ctx, &p, "texture");
        Ok(t)
    }

    // ---- shapes ----------------------------------------------------------------------------

    /// A `<shape>` as objects (several for a shapegroup or an instance of one).
    fn shape(&mut self, ctx: &Ctx, node: Node) -> R<Vec<Object>> {
        let p = self.plugin(ctx, node)?;
        let kind = p.kind.clone();
        if kind == "shapegroup" {
            let mut objects = vec![];
            for c in node.children().filter(|c| c.tag_name().name() == "shape") {
                objects.extend(self.shape(ctx, c)?);
            }
            return Ok(objects);
        }
        let m = self.matrix(ctx, &p, "to_world")?;
        let transform = self.transform(ctx, node, m)?;
        if kind == "instance" {
            let r = node
                .children()
                .find(|c| c.tag_name().name() == "ref")
                .ok_or_else(|| ctx.err(node, "an instance needs a <ref> to a shapegroup"))?;
            let id = self.req_attr(ctx, r, "id")?;
            let group = match self.ids.get(&id) {
                Some(Named::Group(g)) => g.clone(),
                Some(_) => return Err(ctx.err(r, format!("\"{id}\" is not a shapegroup"))),
                None => return Err(self.unknown_id(ctx, r, &id)),
            };
            self.unused(ctx, &p, "shape");
            return Ok(group.into_iter().map(|o| Object { transform: transform * o.transform, ..o }).collect());
        }
        let flip = self.boolean(ctx, &p, "flip_normals", false)?;
        let shape = match kind.as_str() {
            "obj" | "ply" | "serialized" => {
                let name = self
                    .string(ctx, &p, "filename")?
                    .ok_or_else(|| ctx.err(node, format!("{kind} needs a `filename`")))?;
                let path = self.resolve(ctx, &name, false);
                let face_normals = self.boolean(ctx, &p, "face_normals", false)?;
                let part = if kind == "serialized" {
                    let index = self.float(ctx, &p, "shape_index", 0.0)?;
                    if !(0.0..=u32::MAX as f64).contains(&index) || index.fract() != 0.0 {
                        return Err(ctx.err(node, format!("shape_index {index} is not a mesh's index (0, 1, 2, …)")));
                    }
                    Some(index as usize)
                } else {
                    None
                };
                // Mitsuba's OBJ reader turns `v` to `1 − v` unless told not to; its PLY
                // reader only when told to.
                let flip_v = match kind.as_str() {
                    "serialized" => false,
                    _ => self.boolean(ctx, &p, "flip_tex_coords", kind == "obj")?,
                };
                let mesh = self.mesh(ctx, node, (&path, part), (flip, flip_v))?;
                Shape::Mesh { mesh, smooth: !face_normals }
            }
            "rectangle" => {
                let mut mesh = alhazen_scene::rectangle_mesh();
                if flip {
                    flip_mesh(&mut mesh);
                }
                self.scene.meshes.push(Arc::new(mesh));
                Shape::Mesh { mesh: self.scene.meshes.len() - 1, smooth: false }
            }
            "cube" => Shape::Box { min: Vec3::splat(-1.0), max: Vec3::ONE },
            "sphere" => {
                let radius = self.float(ctx, &p, "radius", 1.0)?;
                if radius <= 0.0 {
                    return Err(ctx.err(node, "a sphere's radius must be positive"));
                }
                Shape::Sphere { center: self.point(ctx, &p, "center", Vec3::ZERO)?, radius }
            }
            "disk" => Shape::Disk { center: Vec3::ZERO, normal: Vec3::Z, radius: 1.0 },
            "cylinder" => {
                let (base, top) = (self.point(ctx, &p, "p0", Vec3::ZERO)?, self.point(ctx, &p, "p1", Vec3::Z)?);
                let radius = self.float(ctx, &p, "radius", 1.0)?;
                if radius <= 0.0 || base == top {
                    return Err(ctx.err(node, "a cylinder needs a positive radius and p0 ≠ p1"));
                }
                Shape::Cylinder { base, top, radius, capped: false }
            }
            other => {
                self.warn(ctx, node, format!("shape `{other}` is not supported; left out"));
                return Ok(vec![]);
            }
        };
        if flip && !matches!(kind.as_str(), "obj" | "ply" | "serialized" | "rectangle") {
            self.warn(
                ctx,
                node,
                "flip_normals is applied to meshes only: this shape emits and is shaded from its outside",
            );
        }
        let mut material = None;
        let mut emission = None;
        let mut interior = None;
        for c in node.children().filter(Node::is_element) {
            let side = c.attribute("name").filter(|n| matches!(*n, "interior" | "exterior"));
            if let ("medium" | "ref", Some(side)) = (c.tag_name().name(), side) {
                let absorption = self.medium_of(ctx, c)?;
                if side == "interior" {
                    interior = absorption.map(|a| (a, c));
                } else if absorption.is_some() {
                    self.warn(ctx, c, "an exterior medium is not rendered (alhazen renders absorption inside dielectrics only); ignored");
                }
                continue;
            }
            match c.tag_name().name() {
                "bsdf" => material = Some(self.bsdf_material(ctx, c)?),
                "ref" if c.attribute("name") == Some("emitter") || self.is_area_emitter_ref(&c) => {
                    let id = self.req_attr(ctx, c, "id")?;
                    emission = Some(match self.ids.get(&id) {
                        Some(Named::AreaEmitter(radiance)) => (radiance.clone(), c),
                        Some(_) => return Err(ctx.err(c, format!("\"{id}\" is not an area emitter"))),
                        None => return Err(self.unknown_id(ctx, c, &id)),
                    });
                }
                "ref" if c.attribute("name").is_none_or(|n| n == "bsdf") => {
                    let id = self.req_attr(ctx, c, "id")?;
                    material = Some(match self.ids.get(&id) {
                        Some(Named::Bsdf(m)) => *m,
                        Some(_) => return Err(ctx.err(c, format!("\"{id}\" is not a BSDF"))),
                        None => return Err(self.unknown_id(ctx, c, &id)),
                    });
                }
                "emitter" => emission = Some((self.area_radiance(ctx, c)?, c)),
                _ => {}
            }
        }
        // A textured radiance is read per point on meshes; other shapes shine its mean.
        let emission = match emission {
            Some((Texture::Solid(c), _)) => Some((c, None)),
            Some((textured, _)) if matches!(shape, Shape::Mesh { .. }) => {
                Some((self.pending.texture_mean(&textured, &mut self.scene)?, Some(textured)))
            }
            Some((textured, c)) => {
                self.warn(ctx, c, "a textured `radiance` is replaced by its mean colour on shapes other than meshes");
                Some((self.pending.texture_mean(&textured, &mut self.scene)?, None))
            }
            None => None,
        };
        // Mitsuba gives a shape without a BSDF a diffuse one of reflectance 0.5, and an emitting
        // shape one of reflectance 0: a bare light does not reflect.
        let mut material = match (material, &emission) {
            (Some(m), _) => m,
            (None, None) => self.default_material(),
            (None, Some(_)) => self.black_material(),
        };
        if let Some((e, texture)) = emission {
            material = common::emissive(&mut self.scene, material, e, texture);
        }
        if let Some((absorption, c)) = interior {
            material = self.absorbing(ctx, c, material, absorption);
        }
        self.unused(ctx, &p, "shape");
        let name = self.attr(ctx, node, "id")?;
        let (shape, transform) = match shape {
            Shape::Sphere { center, radius } if self.parametrised(material) => {
                // Mitsuba's sphere has its pole along local +z and u = 0 along +x; alhazen's its
                // pole along +y and u = 0 along −x: turned a quarter about x (y → z, z → −y), the
                // sphere carries Mitsuba's texture coordinates and tangents.
                let quarter = Transform::rotate(Vec3::X, std::f64::consts::FRAC_PI_2);
                (Shape::Sphere { center: Vec3::ZERO, radius }, transform * Transform::translate(center) * quarter)
            }
            shape => common::placed_sphere(shape, transform),
        };
        Ok(vec![Object { name, shape, transform, material, mesh_materials: vec![] }])
    }

    /// A shape's `interior` or `exterior` medium (a `<medium>`, or a `<ref>` to one): its
    /// absorption, `None` where alhazen does not render it (warned).
    fn medium_of(&mut self, ctx: &Ctx, c: Node) -> R<Option<Vec3>> {
        if c.tag_name().name() == "medium" {
            return self.medium(ctx, c);
        }
        let id = self.req_attr(ctx, c, "id")?;
        match self.ids.get(&id) {
            Some(Named::Medium(m)) => Ok(*m),
            Some(_) => Err(ctx.err(c, format!("\"{id}\" is not a medium"))),
            None => Err(self.unknown_id(ctx, c, &id)),
        }
    }

    /// A `homogeneous` medium as alhazen renders it: the absorption `σ_a = scale·σ_t·(1 −
    /// albedo)` per unit length (Beer–Lambert) inside the dielectric it fills. Scattering is
    /// not rendered (a warning where the albedo is not 0); other media are left out (`None`).
    fn medium(&mut self, ctx: &Ctx, node: Node) -> R<Option<Vec3>> {
        let p = self.plugin(ctx, node)?;
        if p.kind != "homogeneous" {
            let why = "alhazen renders the absorption of homogeneous media only";
            self.warn(ctx, node, format!("medium `{}` is not supported ({why}); ignored", p.kind));
            return Ok(None);
        }
        let sigma_t = self.medium_value(ctx, &p, "sigma_t", 1.0)?;
        // Mitsuba's default albedo scatters three quarters of what meets the medium.
        let albedo = self.medium_value(ctx, &p, "albedo", 0.75)?;
        let scale = self.float(ctx, &p, "scale", 1.0)?;
        self.boolean(ctx, &p, "has_spectral_extinction", true)?;
        let valid =
            sigma_t.min_element() >= 0.0 && scale >= 0.0 && albedo.min_element() >= 0.0 && albedo.max_element() <= 1.0;
        let absorption = sigma_t * scale * (Vec3::ONE - albedo);
        if !(valid && absorption.is_finite() && absorption.max_element() <= 1e12) {
            return Err(ctx.err(node, "a homogeneous medium needs sigma_t ≥ 0, scale ≥ 0 and an albedo within [0, 1]"));
        }
        if albedo != Vec3::ZERO && sigma_t * scale != Vec3::ZERO {
            self.warn(ctx, node, format!(
                "the medium scatters (albedo {:.3} {:.3} {:.3}): alhazen renders its absorption σ_t·(1 − albedo) only, not its scattering",
                albedo.x, albedo.y, albedo.z
            ));
        }
        self.unused(ctx, &p, "medium");
        Ok(Some(absorption))
    }

    /// A medium's `sigma_t` or `albedo`: a number, a colour, or a `constvolume` of one.
    fn medium_value(&mut self, ctx: &Ctx, p: &Plugin, name: &str, default: f64) -> R<Vec3> {
        let Some(mut n) = self.prop(p, name) else { return Ok(Vec3::splat(default)) };
        if n.tag_name().name() == "volume" {
            let volume = self.plugin(ctx, n)?;
            if volume.kind != "constvolume" {
                let what = format!(
                    "volume `{}` is not supported: a medium's `{name}` must be a number, a colour or a constvolume",
                    volume.kind
                );
                return Err(ctx.err(n, what));
            }
            let Some(value) = self.prop(&volume, "value") else { return Ok(Vec3::ONE) };
            self.unused(ctx, &volume, "volume");
            n = value;
        }
        match self.color_node(ctx, n)? {
            Texture::Solid(c) => Ok(c),
            _ => Err(ctx.err(n, format!("a medium's `{name}` must be a number or a colour, not a texture"))),
        }
    }

    /// Material `m` with an inside absorbing `absorption` per unit length, where it is a
    /// dielectric's (elsewhere the medium is left out, warned at `c`).
    fn absorbing(&mut self, ctx: &Ctx, c: Node, m: MaterialId, absorption: Vec3) -> MaterialId {
        if absorption == Vec3::ZERO {
            return m;
        }
        if !self.scene.materials[m as usize].bsdf.as_ref().is_some_and(BsdfDesc::refracts) {
            self.warn(
                ctx,
                c,
                "an interior medium is rendered inside dielectrics only (this shape's BSDF does not refract); ignored",
            );
            return m;
        }
        self.absorbing = true;
        common::absorbing(&mut self.scene, m, absorption)
    }

    /// True when material `m` looks at its surface's parametrisation (textures, bump maps,
    /// anisotropic lobes), so a sphere must carry Mitsuba's.
    fn parametrised(&self, m: u32) -> bool {
        let m = &self.scene.materials[m as usize];
        m.bump.is_some() || m.bsdf.as_ref().is_some_and(|b| b.is_textured() || b.is_anisotropic())
    }

    /// A mesh file's place in the scene, once per file (and orientation); its triangles are
    /// read with the other files' once the walk is done.
    /// Mesh file `path` (its `part` of a `serialized` file), turned inside out when `flip`,
    /// its texture coordinates' `v` turned to `1 − v` when `flip_v`: its place in the scene.
    fn mesh(&mut self, ctx: &Ctx, node: Node, (path, part): (&Path, Option<usize>), flips: (bool, bool)) -> R<usize> {
        let key = (path.to_path_buf(), part, flips);
        if let Some(&i) = self.meshes.get(&key) {
            return Ok(i);
        }
        self.scene.meshes.push(Arc::new(alhazen_geom::TriangleMesh::default()));
        let index = self.scene.meshes.len() - 1;
        self.meshes.insert(key, index);
        self.pending.push_mesh((index, part), path, flips, (ctx.path, ctx.shared), node.range());
        Ok(index)
    }

    // ---- emitters --------------------------------------------------------------------------

    fn emitter(&mut self, ctx: &Ctx, node: Node) -> R<()> {
        let p = self.plugin(ctx, node)?;
        let m = self.matrix(ctx, &p, "to_world")?;
        let l = Mat3::from_mat4(m);
        let light = match p.kind.as_str() {
            "point" => {
                let position = match self.prop(&p, "position") {
                    Some(n) => self.point_of(ctx, n, Vec3::ZERO)?,
                    None => m.transform_point3(Vec3::ZERO),
                };
                let intensity = self.constant_color(ctx, &p, "intensity", Vec3::ONE)?;
                Light::Point { position, intensity, attenuation: [1.0, 0.0, 0.0] }
            }
            "spot" => {
                let intensity = self.constant_color(ctx, &p, "intensity", Vec3::ONE)?;
                let cutoff = self.float(ctx, &p, "cutoff_angle", 20.0)?;
                let beam = self.float(ctx, &p, "beam_width", cutoff * 0.75)?;
                if !(cutoff > 0.0 && cutoff < 180.0) {
                    return Err(ctx.err(node, "cutoff_angle must be in (0, 180) degrees"));
                }
                if beam.is_nan() || beam <= 0.0 {
                    return Err(ctx.err(node, "beam_width must be positive"));
                }
                self.prop(&p, "texture").inspect(|_| self.warn(ctx, node, "a projected spot texture is ignored"));
                Light::Spot {
                    position: m.transform_point3(Vec3::ZERO),
                    direction: (l * Vec3::Z).normalize(),
                    cos_cutoff: cutoff.to_radians().cos(),
                    // Mitsuba's fade: full intensity within `beam_width`, linear in angle to
                    // nothing at `cutoff_angle`.
                    falloff: 0.0,
                    beam: (beam < cutoff).then(|| alhazen_scene::SpotBeam {
                        cos: beam.to_radians().cos(),
                        fade: alhazen_scene::SpotFade::LinearAngle,
                    }),
                    intensity,
                    attenuation: [1.0, 0.0, 0.0],
                }
            }
            "directional" => {
                let direction = match self.prop(&p, "direction") {
                    Some(n) => self.point_of(ctx, n, Vec3::ZERO)?,
                    None => l * Vec3::Z,
                };
                if direction.length() == 0.0 {
                    return Err(ctx.err(node, "a directional emitter needs a non-zero direction"));
                }
                let intensity = self.constant_color(ctx, &p, "irradiance", Vec3::ONE)?;
                Light::Directional { direction: direction.normalize(), intensity }
            }
            "constant" => {
                let radiance = self.constant_color(ctx, &p, "radiance", Vec3::ONE)?;
                self.scene.background = Background::Solid(radiance);
                self.unused(ctx, &p, "emitter");
                return Ok(());
            }
            "envmap" => {
                let name =
                    self.string(ctx, &p, "filename")?.ok_or_else(|| ctx.err(node, "envmap needs a `filename`"))?;
                let path = self.resolve(ctx, &name, false);
                let img = alhazen_scene::import::load_radiance_image(&path).map_err(|e| ctx.err(node, e))?;
                let scale = self.float(ctx, &p, "scale", 1.0)?;
                let (rotation, up) = self.map_orientation(ctx, node, l);
                self.scene.images.push(Arc::new(img));
                Light::Environment { image: self.scene.images.len() - 1, scale, rotation, up }
            }
            "area" if node.attribute("id").is_some() => {
                let radiance = self.area_radiance(ctx, node)?;
                return self.register(ctx, node, Named::AreaEmitter(radiance));
            }
            "area" => return Err(ctx.err(node, "an area emitter must be nested in the <shape> it covers")),
            other => {
                self.warn(ctx, node, format!("emitter `{other}` is not supported; left out"));
                return Ok(());
            }
        };
        self.unused(ctx, &p, "emitter");
        self.scene.lights.push(light);
        Ok(())
    }

    /// The angle of a rotation about `+y` (Mitsuba's envmap and alhazen's share the
    /// equirectangular mapping, `u` from `−z` towards `+x`); other rotations are warned about.
    /// An environment map's `to_world` as alhazen's up axis and turn about it: the image of
    /// `+y`, and the turn that is left once the least rotation taking `+y` there is undone. A
    /// matrix that is not a rotation (scaled, sheared or mirrored) is taken by its columns made
    /// orthonormal, with a warning.
    fn map_orientation(&mut self, ctx: &Ctx, node: Node, l: Mat3) -> (f64, Vec3) {
        let up = l.y_axis.try_normalize().unwrap_or(Vec3::Y);
        let z = (l.z_axis - up * l.z_axis.dot(up)).try_normalize().unwrap_or_else(|| up.any_orthonormal_vector());
        let rotation = Mat3::from_cols(up.cross(z), up, z);
        if (l - rotation).to_cols_array().iter().any(|x| x.abs() > 1e-5) {
            self.warn(ctx, node, "an environment map's to_world that is not a rotation is taken by its rotation");
        }
        let frame = alhazen_scene::texture::up_frame(up).unwrap_or(Mat3::IDENTITY);
        let turn = frame.transpose() * rotation;
        (turn.z_axis.x.atan2(turn.z_axis.z), up)
    }
}

/// True when no part of the BSDF lets light through (glass is two-sided in Mitsuba too).
fn reflects_only(desc: &BsdfDesc) -> bool {
    match desc {
        BsdfDesc::Dielectric { .. } | BsdfDesc::ThinDielectric { .. } => false,
        BsdfDesc::Mix { a, b, .. } => reflects_only(a) && reflects_only(b),
        _ => true,
    }
}

/// Rec. 709 luminance: what Mitsuba reads from a colour texture where it wants a number (a
/// grey's value exactly).
fn luminance(c: Vec3) -> f64 {
    if c.x == c.y && c.y == c.z { c.x } else { alhazen_math::color::luminance(c) }
}

/// The metallic–roughness map of principled's `roughness` and `metallic` (a number is 1 in
/// the map, the factor keeping it): each texture's luminance at the centres of the texels of
/// a grid as wide and as tall as the widest and tallest image among them (the larger image's
/// if that grid exceeds it fourfold; 256² for checkerboards alone), roughness in green, metalness
/// in blue, each texture sampled at its own scale's first repeat.
fn metal_rough_map(
    images: &[Arc<alhazen_scene::ImageData>],
    roughness: &Result<f64, Texture>,
    metallic: &Result<f64, Texture>,
) -> alhazen_scene::ImageData {
    let size = |t: &Result<f64, Texture>| match t {
        Err(Texture::Image { image, .. }) => (images[*image].width, images[*image].height),
        _ => (0, 0),
    };
    let ((rw, rh), (mw, mh)) = (size(roughness), size(metallic));
    let larger = if rw as u64 * rh as u64 >= mw as u64 * mh as u64 { (rw, rh) } else { (mw, mh) };
    let (w, h) = match (rw.max(mw), rh.max(mh)) {
        (0, _) | (_, 0) => (256, 256),
        // Images of crossed shapes (wide and tall) would make a grid far larger than either:
        // the larger image's own grid then (the map never outgrows 4× the larger image).
        (w, h) if w as u64 * h as u64 > 4 * larger.0 as u64 * larger.1 as u64 => larger,
        wh => wh,
    };
    let value = |t: &Result<f64, Texture>, uv: Vec2| match t {
        Ok(_) => 1.0,
        Err(Texture::Image { image, .. }) => luminance(alhazen_scene::texture::eval(
            &Texture::Image { image: *image, scale: Vec2::ONE, offset: Vec2::ZERO, rotation: 0.0 },
            uv,
            images,
        )),
        Err(other) => luminance(alhazen_scene::texture::eval(other, uv, images)),
    };
    let pixels = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| {
            // Row 0 is the image's top, texture coordinate v = 1.
            let uv = Vec2::new((x as f64 + 0.5) / w as f64, 1.0 - (y as f64 + 0.5) / h as f64);
            [0.0, value(roughness, uv) as f32, value(metallic, uv) as f32]
        })
        .collect();
    alhazen_scene::ImageData::new(w, h, pixels)
}
/// A `to_uv` matrix as a scale, then a turn (degrees, counter-clockwise), then a shift — what
/// `<scale>`, `<rotate>` and `<translate>` written in that order make —, or `None` for any
/// other (a shear, a turn before an unequal scale, a projection, a zero scale).
fn uv_placement(m: &Mat4) -> Option<(Vec2, Vec2, f64)> {
    let (a, b) = (Vec2::new(m.x_axis.x, m.x_axis.y), Vec2::new(m.y_axis.x, m.y_axis.y));
    let offset = Vec2::new(m.w_axis.x, m.w_axis.y);
    if !(offset.is_finite() && a.is_finite() && b.is_finite()) || a.length() == 0.0 || b.length() == 0.0 {
        return None;
    }
    if a.y == 0.0 && b.x == 0.0 {
        // A plain scale keeps its numbers exactly.
        return Some((Vec2::new(a.x, b.y), offset, 0.0));
    }
    // Columns `s_u (cos φ, sin φ)` and `s_v (−sin φ, cos φ)`: at right angles.
    if a.dot(b).abs() > 1e-9 * a.length() * b.length() {
        return None;
    }
    let angle = a.y.atan2(a.x);
    let (sin, cos) = angle.sin_cos();
    let scale = Vec2::new(a.length(), b.dot(Vec2::new(-sin, cos)));
    Some((scale, offset, angle.to_degrees()))
}
