//! pbrt-v4 scene descriptions (`.pbrt`), from the file-format documentation: a hand-written
//! tokenizer (strings, numbers, brackets, `#` comments, each token with its byte span) and the
//! directives `LookAt`, `Translate`, `Scale`, `Rotate`, `Transform`, `ConcatTransform`,
//! `Identity`, `CoordinateSystem`/`CoordSysTransform`, `Camera`, `Film`, `Sampler`,
//! `Integrator`, `WorldBegin`, `AttributeBegin/End`, `TransformBegin/End`,
//! `ObjectBegin/End/Instance`, `Shape` (`trianglemesh`, `plymesh`, `sphere`, `disk`,
//! `cylinder`, `bilinearmesh`), `Material`, `MakeNamedMaterial`/`NamedMaterial` (`diffuse`,
//! `conductor`, `dielectric`, `thindielectric`, `coateddiffuse`, `coatedconductor`,
//! `diffusetransmission`, `mix`), `Texture` (`imagemap`, `checkerboard`, `scale`, `constant`),
//! `LightSource` (`point`, `spot`, `distant`, `infinite`), `AreaLightSource "diffuse"`,
//! `ReverseOrientation`, `Include`/`Import`, `MakeNamedMedium "homogeneous"` with
//! `MediumInterface` (a dielectric's or `interface`'s absorbing inside). Everything else is a
//! located warning.
//!
//! **Handedness.** pbrt's camera space has `+x` to the right of the image, `+y` up, `+z` ahead,
//! so a plain `LookAt` shows the mirror image of what a right-handed camera with the same eye,
//! target and up shows (alhazen's right is `ahead × up`). Such scenes are imported mirrored in
//! `x` as a whole — objects, lights, camera and environment — which gives pbrt's image exactly;
//! scenes whose camera transform already mirrors (`Scale -1 1 1` before `LookAt`, as exporters
//! write) are taken as they are.

use crate::Imported;
use crate::common::{self, PendingFiles, TexelMap, Warnings, flip_mesh, located};
use alhazen_math::{Mat3, Mat4, Transform, Vec2, Vec3};
use alhazen_scene::bsdf::{BsdfDesc, Ior};
use alhazen_scene::{
    Background, Bump, BumpPattern, CameraDesc, FresnelMode, ImageData, IntegratorKind, Light, LookAt, MaterialId,
    Object, PerspectiveOpening, PixelFilter, Scene, SceneError, Shape, Texture, Wrap,
};
use std::collections::HashMap;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::Arc;

type R<T> = Result<T, SceneError>;

/// Reads a pbrt-v4 scene.
pub fn load(path: &Path) -> Result<Imported, SceneError> {
    let mut imp = Importer::new();
    let walked = imp.file(path, 0);
    // The mesh files met before any error of the walk are loaded (an error in one of them came
    // first, so it is the one reported).
    imp.pending.load(&mut imp.scene, |_| {})?;
    walked?;
    imp.finish()
}

// ---- tokens -------------------------------------------------------------------------------

#[derive(Clone, Debug, PartialEq)]
enum Tok {
    Word(String),
    Str(String),
    Num(f64),
    Open,
    Close,
}

#[derive(Clone, Debug)]
struct Token {
    tok: Tok,
    span: Range<usize>,
}

fn tokenize(path: &Path, text: &str) -> R<Vec<Token>> {
    let b = text.as_bytes();
    let mut out = vec![];
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        let start = i;
        match c {
            b' ' | b'\t' | b'\r' | b'\n' => i += 1,
            b'#' => {
                while i < b.len() && b[i] != b'\n' {
                    i += 1;
                }
            }
            b'[' | b']' => {
                i += 1;
                out.push(Token { tok: if c == b'[' { Tok::Open } else { Tok::Close }, span: start..i });
            }
            b'"' => {
                i += 1;
                let mut s = String::new();
                loop {
                    match b.get(i) {
                        None | Some(b'\n') => return Err(located(path, text, start..i, "unterminated string")),
                        Some(b'"') => break,
                        Some(b'\\') => {
                            i += 1;
                            s.push(match b.get(i) {
                                Some(b'n') => '\n',
                                Some(b't') => '\t',
                                Some(&e) => e as char,
                                None => return Err(located(path, text, start..i, "unterminated string")),
                            });
                            i += 1;
                        }
                        Some(_) => {
                            let ch = text[i..].chars().next().expect("in bounds");
                            s.push(ch);
                            i += ch.len_utf8();
                        }
                    }
                }
                i += 1;
                out.push(Token { tok: Tok::Str(s), span: start..i });
            }
            b'0'..=b'9' | b'-' | b'+' | b'.' => {
                while i < b.len() && matches!(b[i], b'0'..=b'9' | b'-' | b'+' | b'.' | b'e' | b'E') {
                    i += 1;
                }
                let s = &text[start..i];
                let v = s.parse::<f64>().ok().filter(|v| v.is_finite());
                let v = v.ok_or_else(|| located(path, text, start..i, format!("`{s}` is not a finite number")))?;
                out.push(Token { tok: Tok::Num(v), span: start..i });
            }
            c if c.is_ascii_alphabetic() => {
                while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
                    i += 1;
                }
                out.push(Token { tok: Tok::Word(text[start..i].to_string()), span: start..i });
            }
            _ => {
                let ch = text[i..].chars().next().expect("in bounds");
                return Err(located(path, text, start..start + ch.len_utf8(), format!("unexpected character `{ch}`")));
            }
        }
    }
    Ok(out)
}

// ---- parameter lists ----------------------------------------------------------------------

#[derive(Clone, Debug)]
enum Value {
    Num(f64),
    Str(String),
    Bool(bool),
}

#[derive(Clone, Debug)]
struct Param {
    ty: String,
    name: String,
    values: Vec<Value>,
    span: Range<usize>,
}

/// A directive's parameter list, with what has been read.
struct Params {
    list: Vec<Param>,
    used: Vec<bool>,
}

// ---- graphics state -----------------------------------------------------------------------

#[derive(Clone)]
struct AreaLight {
    radiance: Vec3,
}

#[derive(Clone)]
struct State {
    ctm: Mat4,
    reverse: bool,
    material: Option<MaterialId>,
    area: Option<AreaLight>,
    /// The inside medium of the shapes that follow (`MediumInterface`), by name.
    interior: Option<String>,
}

struct Importer {
    /// Materials given a shape's cut-out: by the material and the coverage (its `Debug` text).
    cut_materials: HashMap<(MaterialId, String), MaterialId>,
    scene: Scene,
    warnings: Warnings,
    state: State,
    stack: Vec<(State, bool)>,
    named_coords: HashMap<String, Mat4>,
    named_materials: HashMap<String, MaterialId>,
    /// Named media: their absorption per unit length (`None`: a medium alhazen does not
    /// render, warned where it was made).
    media: HashMap<String, Option<Vec3>>,
    /// Named textures, each with the change its image map's `scale` and `invert`, or a `scale`
    /// or `mix` texture over it, makes to its image's values (none elsewhere): the image is
    /// copied changed where the texture is a colour, and read as it is, the change's gain its
    /// height, where it is a displacement.
    textures: HashMap<String, (Texture, TexelMap)>,
    /// The changed copies of images made so far: (image, the change's bits) → the copy.
    mapped_copies: HashMap<(usize, [u64; 6], bool), usize>,
    objects: HashMap<String, Vec<Object>>,
    defining: Option<(String, Vec<Object>)>,
    meshes: HashMap<(PathBuf, bool), usize>,
    default_material: Option<MaterialId>,
    /// pbrt's world-from-camera, kept until the end (mirroring is decided then).
    camera: Option<(Mat4, CameraKind)>,
    /// The screen's aspect once `Film` is read.
    environment: Option<(Arc<ImageData>, Mat4, f64)>,
    /// Mesh files met, loaded together once the walk is done.
    pending: PendingFiles,
}

#[derive(Clone, Copy)]
enum CameraKind {
    Perspective { fov_degrees: f64, lens: Option<alhazen_scene::ThinLens> },
    Orthographic { scale: f64 },
}

/// One file being read.
struct Ctx<'a> {
    path: &'a Path,
    text: &'a str,
    /// Its text, shared: kept for the locations of mesh files' errors found after the walk.
    shared: &'a Arc<str>,
}

impl Ctx<'_> {
    fn err(&self, span: Range<usize>, msg: impl Into<String>) -> SceneError {
        located(self.path, self.text, span, msg)
    }
    fn line(&self, span: &Range<usize>) -> usize {
        common::line_of(self.text, span.start)
    }
}

impl Importer {
    fn new() -> Self {
        let mut scene = alhazen_scene::empty_scene();
        scene.render.integrator = IntegratorKind::Path;
        scene.render.width = 1280;
        scene.render.height = 720;
        scene.render.spp = 16;
        scene.render.max_depth = 5;
        // pbrt-v4's default pixel filter.
        scene.render.filter = PixelFilter::Gaussian { sigma: 0.5, radius: [1.5; 2] };
        Self {
            scene,
            warnings: Warnings::default(),
            state: State { ctm: Mat4::IDENTITY, reverse: false, material: None, area: None, interior: None },
            media: HashMap::new(),
            stack: vec![],
            named_coords: HashMap::new(),
            named_materials: HashMap::new(),
            textures: HashMap::new(),
            mapped_copies: HashMap::new(),
            cut_materials: HashMap::new(),
            objects: HashMap::new(),
            defining: None,
            meshes: HashMap::new(),
            default_material: None,
            camera: None,
            environment: None,
            pending: PendingFiles::default(),
        }
    }

    fn warn(&mut self, ctx: &Ctx, span: &Range<usize>, msg: impl Into<String>) {
        let line = ctx.line(span);
        self.warnings.add(ctx.path, line, msg);
    }

    fn file(&mut self, path: &Path, depth: usize) -> R<()> {
        let text: Arc<str> = common::read_text(path)?.into();
        let ctx = Ctx { path, text: &text, shared: &text };
        let tokens = tokenize(path, &text)?;
        let mut i = 0;
        while i < tokens.len() {
            let t = &tokens[i];
            let Tok::Word(word) = &t.tok else {
                return Err(ctx.err(t.span.clone(), "expected a directive (such as Shape, Material or LookAt)"));
            };
            i += 1;
            i = self.directive(&ctx, word, t.span.clone(), &tokens, i, depth)?;
        }
        Ok(())
    }

    fn finish(mut self) -> R<Imported> {
        if self.defining.is_some() {
            self.warnings.add(Path::new("scene"), 0, "ObjectBegin without ObjectEnd: the object's shapes are left out");
        }
        self.place_camera();
        Ok(Imported { scene: self.scene, warnings: self.warnings.into_vec() })
    }

    // ---- reading arguments ---------------------------------------------------------------

    fn numbers(
        &self,
        ctx: &Ctx,
        tokens: &[Token],
        i: &mut usize,
        n: usize,
        what: &str,
        at: &Range<usize>,
    ) -> R<Vec<f64>> {
        let mut out = vec![];
        let bracket = matches!(tokens.get(*i).map(|t| &t.tok), Some(Tok::Open));
        if bracket {
            *i += 1;
        }
        while out.len() < n {
            match tokens.get(*i) {
                Some(Token { tok: Tok::Num(v), .. }) => {
                    out.push(*v);
                    *i += 1;
                }
                other => {
                    let span = other.map_or(at.clone(), |t| t.span.clone());
                    return Err(ctx.err(span, format!("{what} takes {n} numbers")));
                }
            }
        }
        if bracket {
            match tokens.get(*i) {
                Some(Token { tok: Tok::Close, .. }) => *i += 1,
                other => {
                    return Err(ctx.err(
                        other.map_or(at.clone(), |t| t.span.clone()),
                        format!("{what}: expected `]` after {n} numbers"),
                    ));
                }
            }
        }
        Ok(out)
    }

    fn string_arg(
        &self,
        ctx: &Ctx,
        tokens: &[Token],
        i: &mut usize,
        what: &str,
        at: &Range<usize>,
    ) -> R<(String, Range<usize>)> {
        match tokens.get(*i) {
            Some(Token { tok: Tok::Str(s), span }) => {
                *i += 1;
                Ok((s.clone(), span.clone()))
            }
            other => Err(ctx.err(other.map_or(at.clone(), |t| t.span.clone()), format!("{what} needs a quoted name"))),
        }
    }

    fn params(&self, ctx: &Ctx, tokens: &[Token], i: &mut usize) -> R<Params> {
        let mut list = vec![];
        while let Some(Token { tok: Tok::Str(decl), span }) = tokens.get(*i) {
            let mut words = decl.split_whitespace();
            let (Some(ty), Some(name), None) = (words.next(), words.next(), words.next()) else {
                return Err(ctx.err(span.clone(), format!("\"{decl}\" is not a parameter declaration (\"type name\")")));
            };
            *i += 1;
            let one = |t: &Token| -> R<Value> {
                match &t.tok {
                    Tok::Num(v) => Ok(Value::Num(*v)),
                    Tok::Str(s) if ty == "bool" => match s.as_str() {
                        "true" => Ok(Value::Bool(true)),
                        "false" => Ok(Value::Bool(false)),
                        _ => Err(ctx.err(t.span.clone(), format!("\"{s}\" is not true or false"))),
                    },
                    Tok::Str(s) => Ok(Value::Str(s.clone())),
                    Tok::Word(w) if w == "true" || w == "false" => Ok(Value::Bool(w == "true")),
                    _ => Err(ctx.err(t.span.clone(), format!("expected a value for \"{decl}\""))),
                }
            };
            let mut values = vec![];
            match tokens.get(*i) {
                Some(Token { tok: Tok::Open, span: open }) => {
                    *i += 1;
                    loop {
                        match tokens.get(*i) {
                            Some(Token { tok: Tok::Close, .. }) => {
                                *i += 1;
                                break;
                            }
                            Some(t) => {
                                values.push(one(t)?);
                                *i += 1;
                            }
                            None => return Err(ctx.err(open.clone(), "`[` without `]`")),
                        }
                    }
                }
                Some(t) => {
                    values.push(one(t)?);
                    *i += 1;
                }
                None => return Err(ctx.err(span.clone(), format!("\"{decl}\" has no value"))),
            }
            let end = tokens.get(*i - 1).map_or(span.end, |t| t.span.end);
            list.push(Param { ty: ty.to_string(), name: name.to_string(), values, span: span.start..end });
        }
        let used = vec![false; list.len()];
        Ok(Params { list, used })
    }

    // ---- directives ----------------------------------------------------------------------

    fn directive(
        &mut self,
        ctx: &Ctx,
        word: &str,
        at: Range<usize>,
        tokens: &[Token],
        mut i: usize,
        depth: usize,
    ) -> R<usize> {
        let i = &mut i;
        match word {
            "LookAt" => {
                let v = self.numbers(ctx, tokens, i, 9, "LookAt", &at)?;
                let (eye, target, up) =
                    (Vec3::new(v[0], v[1], v[2]), Vec3::new(v[3], v[4], v[5]), Vec3::new(v[6], v[7], v[8]));
                let dir = (target - eye).normalize_or_zero();
                let right = up.normalize_or_zero().cross(dir).normalize_or_zero();
                if dir == Vec3::ZERO || right == Vec3::ZERO {
                    return Err(ctx.err(at, "LookAt: eye and target coincide, or up is parallel to the view"));
                }
                let new_up = dir.cross(right);
                let camera_to_world =
                    Mat4::from_cols(right.extend(0.0), new_up.extend(0.0), dir.extend(0.0), eye.extend(1.0));
                self.state.ctm *= camera_to_world.inverse();
            }
            "Translate" => {
                let v = self.numbers(ctx, tokens, i, 3, "Translate", &at)?;
                self.state.ctm *= Mat4::from_translation(Vec3::new(v[0], v[1], v[2]));
            }
            "Scale" => {
                let v = self.numbers(ctx, tokens, i, 3, "Scale", &at)?;
                self.state.ctm *= Mat4::from_scale(Vec3::new(v[0], v[1], v[2]));
            }
            "Rotate" => {
                let v = self.numbers(ctx, tokens, i, 4, "Rotate", &at)?;
                let axis = Vec3::new(v[1], v[2], v[3]);
                if axis.length() == 0.0 {
                    return Err(ctx.err(at, "Rotate: the axis is zero"));
                }
                self.state.ctm *= Mat4::from_axis_angle(axis.normalize(), v[0].to_radians());
            }
            "Transform" | "ConcatTransform" => {
                let v = self.numbers(ctx, tokens, i, 16, word, &at)?;
                // The file lists the matrix column by column.
                let m = Mat4::from_cols_array(&v.try_into().expect("16 numbers"));
                self.state.ctm = if word == "Transform" { m } else { self.state.ctm * m };
            }
            "Identity" => self.state.ctm = Mat4::IDENTITY,
            "CoordinateSystem" => {
                let (name, _) = self.string_arg(ctx, tokens, i, word, &at)?;
                self.named_coords.insert(name, self.state.ctm);
            }
            "CoordSysTransform" => {
                let (name, span) = self.string_arg(ctx, tokens, i, word, &at)?;
                self.state.ctm = *self
                    .named_coords
                    .get(&name)
                    .ok_or_else(|| ctx.err(span, format!("no coordinate system \"{name}\"")))?;
            }
            "ReverseOrientation" => self.state.reverse = !self.state.reverse,
            "WorldBegin" => {
                self.state.ctm = Mat4::IDENTITY;
                self.named_coords.insert("world".into(), Mat4::IDENTITY);
            }
            "WorldEnd" => {}
            "AttributeBegin" | "TransformBegin" => self.stack.push((self.state.clone(), word == "TransformBegin")),
            "AttributeEnd" | "TransformEnd" => {
                let (saved, transform_only) =
                    self.stack.pop().ok_or_else(|| ctx.err(at.clone(), format!("{word} without a matching begin")))?;
                if transform_only {
                    self.state.ctm = saved.ctm;
                } else {
                    self.state = saved;
                }
            }
            "Attribute" => {
                let _ = self.string_arg(ctx, tokens, i, word, &at)?;
                let p = self.params(ctx, tokens, i)?;
                self.warn(ctx, &at, "Attribute defaults are not supported; ignored");
                drop(p);
            }
            "PixelFilter" => {
                let (kind, _) = self.string_arg(ctx, tokens, i, word, &at)?;
                let mut p = self.params(ctx, tokens, i)?;
                self.scene.render.filter = self.pixel_filter(ctx, &at, &kind, &mut p)?;
                self.unused(ctx, &p, "PixelFilter");
            }
            "MakeNamedMedium" => {
                let (name, _) = self.string_arg(ctx, tokens, i, word, &at)?;
                let mut p = self.params(ctx, tokens, i)?;
                let medium = self.medium(ctx, &at, &mut p)?;
                self.media.insert(name, medium);
            }
            "MediumInterface" => {
                let (inside, _) = self.string_arg(ctx, tokens, i, word, &at)?;
                // One name: the same medium on both sides.
                let outside = match tokens.get(*i) {
                    Some(Token { tok: Tok::Str(s), .. }) => {
                        *i += 1;
                        s.clone()
                    }
                    _ => inside.clone(),
                };
                if !outside.is_empty() {
                    let why = "alhazen renders absorption inside dielectrics only";
                    self.warn(
                        ctx,
                        &at,
                        format!("MediumInterface: the outside medium \"{outside}\" is not rendered ({why}); ignored"),
                    );
                }
                self.state.interior = (!inside.is_empty()).then_some(inside);
            }
            "Option" | "ColorSpace" | "Accelerator" => {
                let _ = self.string_arg(ctx, tokens, i, word, &at)?;
                if word != "ColorSpace" {
                    self.params(ctx, tokens, i)?;
                }
                self.warn(ctx, &at, format!("{word}: not supported; ignored"));
            }
            "Camera" => {
                let (kind, _) = self.string_arg(ctx, tokens, i, word, &at)?;
                let mut p = self.params(ctx, tokens, i)?;
                let world_from_camera = self.state.ctm.inverse();
                if !world_from_camera.is_finite() {
                    return Err(ctx.err(at, "the camera transform is singular"));
                }
                self.named_coords.insert("camera".into(), world_from_camera);
                // pbrt's thin lens: `lensradius` (0: a pinhole), in focus at `focaldistance`.
                let aperture = self.float(ctx, &mut p, "lensradius", 0.0)?;
                let focus_distance = self.float(ctx, &mut p, "focaldistance", 1e6)?;
                if aperture < 0.0 || !aperture.is_finite() || !(focus_distance > 0.0 && focus_distance.is_finite()) {
                    return Err(ctx.err(at, "a camera needs `lensradius` ≥ 0 and a positive `focaldistance`"));
                }
                let lens = (aperture > 0.0).then_some(alhazen_scene::ThinLens { aperture, focus_distance });
                let kind = match kind.as_str() {
                    "perspective" => {
                        let fov = self.float(ctx, &mut p, "fov", 90.0)?;
                        if !(fov > 0.0 && fov < 180.0) {
                            return Err(ctx.err(at, "fov must be in (0, 180) degrees"));
                        }
                        CameraKind::Perspective { fov_degrees: fov, lens }
                    }
                    "orthographic" => {
                        if lens.is_some() {
                            self.warn(ctx, &at, "an orthographic camera's lens is not supported: everything is sharp");
                        }
                        CameraKind::Orthographic { scale: 1.0 }
                    }
                    other => {
                        self.warn(
                            ctx,
                            &at,
                            format!("camera \"{other}\" is not supported; a 90° perspective camera stands in"),
                        );
                        CameraKind::Perspective { fov_degrees: 90.0, lens }
                    }
                };
                self.unused(ctx, &p, "camera");
                self.camera = Some((world_from_camera, kind));
            }
            "Film" => {
                let _ = self.string_arg(ctx, tokens, i, word, &at)?;
                let mut p = self.params(ctx, tokens, i)?;
                let w = self.float(ctx, &mut p, "xresolution", 1280.0)?;
                let h = self.float(ctx, &mut p, "yresolution", 720.0)?;
                for (v, key) in [(w, "xresolution"), (h, "yresolution")] {
                    if !(v >= 1.0 && v <= alhazen_scene::MAX_SIDE as f64 && v.fract() == 0.0) {
                        return Err(ctx.err(
                            at,
                            format!("{key} must be a whole number of pixels in 1–{}", alhazen_scene::MAX_SIDE),
                        ));
                    }
                }
                if w * h > alhazen_scene::MAX_PIXELS as f64 {
                    return Err(ctx.err(at, "the film has more pixels than alhazen can allocate"));
                }
                (self.scene.render.width, self.scene.render.height) = (w as u32, h as u32);
                self.string(ctx, &mut p, "filename")?;
                self.unused(ctx, &p, "film");
            }
            "Sampler" => {
                let (kind, _) = self.string_arg(ctx, tokens, i, word, &at)?;
                let mut p = self.params(ctx, tokens, i)?;
                let spp = self.float(ctx, &mut p, "pixelsamples", 16.0)?;
                if !(1.0..=1048576.0).contains(&spp) {
                    return Err(ctx.err(at, "pixelsamples must be 1–1048576"));
                }
                self.scene.render.spp = spp as u32;
                self.scene.render.seed = self.float(ctx, &mut p, "seed", 0.0)?.max(0.0) as u64;
                self.scene.render.sampler = if kind == "independent" {
                    alhazen_scene::SamplerKind::Independent
                } else {
                    alhazen_scene::SamplerKind::Sobol
                };
                self.unused(ctx, &p, "sampler");
            }
            "Integrator" => {
                let (kind, _) = self.string_arg(ctx, tokens, i, word, &at)?;
                let mut p = self.params(ctx, tokens, i)?;
                let depth = self.float(ctx, &mut p, "maxdepth", 5.0)?;
                self.scene.render.max_depth = (depth.max(0.0) as u32).saturating_add(1).min(1000);
                // pbrt's light tree chooses lights by what they may send to each point; the
                // measured choice is alhazen's nearest.
                self.scene.render.light_choice = match self.string(ctx, &mut p, "lightsampler")?.as_deref() {
                    None | Some("bvh") => alhazen_scene::LightChoice::Measured,
                    Some("power") => alhazen_scene::LightChoice::Power,
                    Some("uniform") => alhazen_scene::LightChoice::Uniform,
                    Some(other) => {
                        return Err(ctx.err(
                            at,
                            format!("unknown \"lightsampler\" \"{other}\": expected \"bvh\", \"power\" or \"uniform\""),
                        ));
                    }
                };
                if !matches!(kind.as_str(), "path" | "volpath") {
                    self.warn(ctx, &at, format!("integrator \"{kind}\" is rendered by alhazen's path tracer"));
                }
                self.unused(ctx, &p, "integrator");
            }
            "Include" | "Import" => {
                let (name, span) = self.string_arg(ctx, tokens, i, word, &at)?;
                if depth >= 16 {
                    return Err(ctx.err(span, "includes nested deeper than 16 files (an include cycle?)"));
                }
                let path = common::relative_to(ctx.path, &name);
                self.file(&path, depth + 1).map_err(|e| match e {
                    SceneError::Io { source, .. } => {
                        ctx.err(span.clone(), format!("cannot read {}: {source}", path.display()))
                    }
                    e => e,
                })?;
            }
            "ObjectBegin" => {
                let (name, span) = self.string_arg(ctx, tokens, i, word, &at)?;
                if self.defining.is_some() {
                    return Err(ctx.err(span, "ObjectBegin inside another object definition"));
                }
                self.stack.push((self.state.clone(), false));
                self.defining = Some((name, vec![]));
            }
            "ObjectEnd" => {
                let (name, objects) =
                    self.defining.take().ok_or_else(|| ctx.err(at.clone(), "ObjectEnd without ObjectBegin"))?;
                self.objects.insert(name, objects);
                if let Some((saved, _)) = self.stack.pop() {
                    self.state = saved;
                }
            }
            "ObjectInstance" => {
                let (name, span) = self.string_arg(ctx, tokens, i, word, &at)?;
                let objects = self.objects.get(&name).cloned().ok_or_else(|| {
                    let mut e =
                        ctx.err(span.clone(), format!("no object named \"{name}\" (define it with ObjectBegin first)"));
                    if let (SceneError::Syntax(d), Some(s)) =
                        (&mut e, alhazen_scene::did_you_mean(&name, self.objects.keys().map(String::as_str)))
                    {
                        **d = d.clone().with_help(format!("did you mean \"{s}\"?"));
                    }
                    e
                })?;
                let t = self.transform(ctx, &at, self.state.ctm)?;
                for o in objects {
                    self.emit(Object { transform: t * o.transform, ..o });
                }
            }
            "Material" => {
                let (kind, span) = self.string_arg(ctx, tokens, i, word, &at)?;
                let mut p = self.params(ctx, tokens, i)?;
                let id = self.material(ctx, &kind, &span, &mut p, &format!("material at line {}", ctx.line(&at)))?;
                self.state.material = Some(id);
            }
            "MakeNamedMaterial" => {
                let (name, span) = self.string_arg(ctx, tokens, i, word, &at)?;
                let mut p = self.params(ctx, tokens, i)?;
                let kind = self
                    .string(ctx, &mut p, "type")?
                    .ok_or_else(|| ctx.err(span.clone(), "MakeNamedMaterial needs \"string type\""))?;
                let id = self.material(ctx, &kind, &span, &mut p, &name)?;
                self.named_materials.insert(name, id);
            }
            "NamedMaterial" => {
                let (name, span) = self.string_arg(ctx, tokens, i, word, &at)?;
                let id = self.named_material(ctx, &name, span)?;
                self.state.material = Some(id);
            }
            "Texture" => {
                let (name, _) = self.string_arg(ctx, tokens, i, word, &at)?;
                let (_class, _) = self.string_arg(ctx, tokens, i, word, &at)?;
                let (kind, kspan) = self.string_arg(ctx, tokens, i, word, &at)?;
                let mut p = self.params(ctx, tokens, i)?;
                let t = self.texture(ctx, &kind, &kspan, &mut p)?;
                self.textures.insert(name, t);
            }
            "LightSource" => {
                let (kind, span) = self.string_arg(ctx, tokens, i, word, &at)?;
                let mut p = self.params(ctx, tokens, i)?;
                self.light(ctx, &kind, &span, &mut p)?;
            }
            "AreaLightSource" => {
                let (kind, span) = self.string_arg(ctx, tokens, i, word, &at)?;
                let mut p = self.params(ctx, tokens, i)?;
                if kind != "diffuse" {
                    return Err(ctx.err(span, format!("area light \"{kind}\" is not pbrt's (only \"diffuse\")")));
                }
                let radiance = self.color(ctx, &mut p, "L", Vec3::ONE)? * self.float(ctx, &mut p, "scale", 1.0)?;
                if self.boolean(ctx, &mut p, "twosided", false)? {
                    self.warn(ctx, &at, "a two-sided area light emits from its front side only in alhazen");
                }
                self.unused(ctx, &p, "area light");
                self.state.area = Some(AreaLight { radiance });
            }
            "Shape" => {
                let (kind, span) = self.string_arg(ctx, tokens, i, word, &at)?;
                let mut p = self.params(ctx, tokens, i)?;
                self.shape(ctx, &kind, &span, &mut p)?;
            }
            other => {
                let known = [
                    "LookAt",
                    "Translate",
                    "Scale",
                    "Rotate",
                    "Transform",
                    "ConcatTransform",
                    "Camera",
                    "Film",
                    "Sampler",
                    "Integrator",
                    "WorldBegin",
                    "AttributeBegin",
                    "AttributeEnd",
                    "Shape",
                    "Material",
                    "Texture",
                    "LightSource",
                    "AreaLightSource",
                    "ObjectBegin",
                    "ObjectEnd",
                    "ObjectInstance",
                    "Include",
                    "Import",
                    "NamedMaterial",
                    "MakeNamedMaterial",
                ];
                let mut e = ctx.err(at.clone(), format!("unknown directive `{other}`"));
                if let (SceneError::Syntax(d), Some(s)) = (&mut e, alhazen_scene::did_you_mean(other, known)) {
                    **d = d.clone().with_help(format!("did you mean `{s}`?"));
                }
                return Err(e);
            }
        }
        Ok(*i)
    }

    // ---- parameters by type ------------------------------------------------------------

    fn find(&self, p: &mut Params, name: &str) -> Option<Param> {
        let k = p.list.iter().position(|q| q.name == name)?;
        p.used[k] = true;
        Some(p.list[k].clone())
    }

    fn nums(&self, ctx: &Ctx, q: &Param) -> R<Vec<f64>> {
        q.values
            .iter()
            .map(|v| match v {
                Value::Num(x) => Ok(*x),
                _ => Err(ctx.err(q.span.clone(), format!("\"{}\" must hold numbers", q.name))),
            })
            .collect()
    }

    fn float(&self, ctx: &Ctx, p: &mut Params, name: &str, default: f64) -> R<f64> {
        let Some(q) = self.find(p, name) else { return Ok(default) };
        match self.nums(ctx, &q)?[..] {
            [x] => Ok(x),
            _ => Err(ctx.err(q.span, format!("\"{name}\" must be one number"))),
        }
    }

    fn string(&self, ctx: &Ctx, p: &mut Params, name: &str) -> R<Option<String>> {
        let Some(q) = self.find(p, name) else { return Ok(None) };
        match &q.values[..] {
            [Value::Str(s)] => Ok(Some(s.clone())),
            _ => Err(ctx.err(q.span, format!("\"{name}\" must be one string"))),
        }
    }

    fn boolean(&self, ctx: &Ctx, p: &mut Params, name: &str, default: bool) -> R<bool> {
        let Some(q) = self.find(p, name) else { return Ok(default) };
        match &q.values[..] {
            [Value::Bool(b)] => Ok(*b),
            _ => Err(ctx.err(q.span, format!("\"{name}\" must be true or false"))),
        }
    }

    fn vec3s(&self, ctx: &Ctx, q: &Param) -> R<Vec<Vec3>> {
        let v = self.nums(ctx, q)?;
        if !v.len().is_multiple_of(3) {
            return Err(ctx.err(q.span.clone(), format!("\"{}\" must hold triples of numbers", q.name)));
        }
        Ok(v.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect())
    }

    fn point(&self, ctx: &Ctx, p: &mut Params, name: &str, default: Vec3) -> R<Vec3> {
        let Some(q) = self.find(p, name) else { return Ok(default) };
        match self.vec3s(ctx, &q)?[..] {
            [v] => Ok(v),
            _ => Err(ctx.err(q.span, format!("\"{name}\" must be one point"))),
        }
    }

    /// A colour parameter or texture reference.
    fn texture_param(&mut self, ctx: &Ctx, p: &mut Params, name: &str, default: Vec3) -> R<Texture> {
        let (t, map) = self.texture_ref(ctx, p, name, default)?;
        Ok(self.mapped(t, map))
    }

    /// Parameter `name` as a texture and the change to its image's values (see `textures`).
    fn texture_ref(&mut self, ctx: &Ctx, p: &mut Params, name: &str, default: Vec3) -> R<(Texture, TexelMap)> {
        let Some(q) = self.find(p, name) else { return Ok((Texture::Solid(default), TexelMap::IDENTITY)) };
        if q.ty == "texture" {
            let [Value::Str(t)] = &q.values[..] else {
                return Err(ctx.err(q.span, "a texture parameter names one texture"));
            };
            return self
                .textures
                .get(t)
                .cloned()
                .ok_or_else(|| ctx.err(q.span.clone(), format!("no texture named \"{t}\"")));
        }
        self.color_of(ctx, &q).map(|c| (Texture::Solid(c), TexelMap::IDENTITY))
    }

    /// `t` with `map` changing its image: a changed copy of the image (one per image and
    /// change).
    fn mapped(&mut self, t: Texture, map: TexelMap) -> Texture {
        let Texture::Image { image, scale, offset, rotation } = t else { return t };
        if map == TexelMap::IDENTITY {
            return t;
        }
        let bits: Vec<u64> = map.gain.iter().chain(&map.offset).map(|x| x.to_bits()).collect();
        let key = (image, std::array::from_fn(|i| bits[i]), map.floor);
        let copy = match self.mapped_copies.get(&key) {
            Some(&copy) => copy,
            None => {
                let copy = self.pending.mapped_image(&mut self.scene.images, image, map);
                self.mapped_copies.insert(key, copy);
                copy
            }
        };
        Texture::Image { image: copy, scale, offset, rotation }
    }

    fn color(&mut self, ctx: &Ctx, p: &mut Params, name: &str, default: Vec3) -> R<Vec3> {
        let t = self.texture_param(ctx, p, name, default)?;
        if !matches!(t, Texture::Solid(_)) {
            let span = p.list.iter().find(|q| q.name == name).map_or(0..0, |q| q.span.clone());
            self.warn(ctx, &span, format!("a textured \"{name}\" is replaced by its mean colour"));
        }
        self.pending.texture_mean(&t, &mut self.scene)
    }

    fn color_of(&mut self, ctx: &Ctx, q: &Param) -> R<Vec3> {
        match q.ty.as_str() {
            "rgb" | "color" => match self.nums(ctx, q)?[..] {
                [r, g, b] => Ok(Vec3::new(r, g, b)),
                _ => Err(ctx.err(q.span.clone(), format!("\"{}\" must be three numbers", q.name))),
            },
            "float" => match self.nums(ctx, q)?[..] {
                [x] => Ok(Vec3::splat(x)),
                _ => Err(ctx.err(q.span.clone(), format!("\"{}\" must be one number", q.name))),
            },
            "blackbody" => {
                self.warn(ctx, &q.span, "a blackbody spectrum is approximated by white of the same luminance");
                Ok(Vec3::ONE)
            }
            "spectrum" => match &q.values[..] {
                [Value::Str(s)] => {
                    if s.starts_with("stdillum") {
                        return Ok(Vec3::ONE);
                    }
                    self.warn(ctx, &q.span, format!("named spectrum \"{s}\" is approximated by grey 0.5"));
                    Ok(Vec3::splat(0.5))
                }
                [Value::Num(x)] => Ok(Vec3::splat(*x)),
                _ => {
                    let v = self.nums(ctx, q)?;
                    let mut bands = [(0.0, 0.0); 3];
                    for pair in v.chunks_exact(2) {
                        let band = if pair[0] >= 600.0 {
                            0
                        } else if pair[0] >= 500.0 {
                            1
                        } else {
                            2
                        };
                        bands[band].0 += pair[1];
                        bands[band].1 += 1.0;
                    }
                    self.warn(
                        ctx,
                        &q.span,
                        "a sampled spectrum is approximated by RGB: its mean over 600–700, 500–600 and 400–500 nm",
                    );
                    let mean = |b: (f64, f64)| if b.1 > 0.0 { b.0 / b.1 } else { 0.0 };
                    Ok(Vec3::new(mean(bands[0]), mean(bands[1]), mean(bands[2])))
                }
            },
            other => Err(ctx.err(q.span.clone(), format!("\"{}\" cannot be a colour of type {other}", q.name))),
        }
    }

    /// pbrt-v4's `PixelFilter`: box, gaussian, mitchell, sinc (Lanczos) and triangle, with
    /// their radii along `x` and `y`.
    fn pixel_filter(&self, ctx: &Ctx, at: &Range<usize>, kind: &str, p: &mut Params) -> R<PixelFilter> {
        let default_radius = match kind {
            "box" => 0.5,
            "gaussian" => 1.5,
            "sinc" => 4.0,
            _ => 2.0,
        };
        let radius = [self.float(ctx, p, "xradius", default_radius)?, self.float(ctx, p, "yradius", default_radius)?];
        let filter = match kind {
            "box" => PixelFilter::Box { radius },
            "gaussian" => PixelFilter::Gaussian { sigma: self.float(ctx, p, "sigma", 0.5)?, radius },
            "mitchell" => PixelFilter::Mitchell {
                b: self.float(ctx, p, "B", 1.0 / 3.0)?,
                c: self.float(ctx, p, "C", 1.0 / 3.0)?,
                radius,
            },
            "sinc" => PixelFilter::Lanczos { tau: self.float(ctx, p, "tau", 3.0)?, radius },
            "triangle" => PixelFilter::Tent { radius },
            other => {
                return Err(ctx.err(
                    at.clone(),
                    format!("unknown PixelFilter \"{other}\"; expected one of box, gaussian, mitchell, sinc, triangle"),
                ));
            }
        };
        match filter.problem() {
            Some(why) => Err(ctx.err(at.clone(), why)),
            None => Ok(filter),
        }
    }

    fn unused(&mut self, ctx: &Ctx, p: &Params, what: &str) {
        for (q, used) in p.list.iter().zip(&p.used) {
            if !used {
                self.warn(ctx, &q.span, format!("parameter \"{}\" of {what} is not supported; ignored", q.name));
            }
        }
    }

    fn transform(&self, ctx: &Ctx, at: &Range<usize>, m: Mat4) -> R<Transform> {
        Transform::from_matrix(m).map_err(|e| ctx.err(at.clone(), format!("the current transformation: {e}")))
    }

    // ---- materials and textures ----------------------------------------------------------

    fn named_material(&self, ctx: &Ctx, name: &str, span: Range<usize>) -> R<MaterialId> {
        self.named_materials.get(name).copied().ok_or_else(|| {
            let mut e =
                ctx.err(span.clone(), format!("no material named \"{name}\" (define it with MakeNamedMaterial first)"));
            if let (SceneError::Syntax(d), Some(s)) =
                (&mut e, alhazen_scene::did_you_mean(name, self.named_materials.keys().map(String::as_str)))
            {
                **d = d.clone().with_help(format!("did you mean \"{s}\"?"));
            }
            e
        })
    }

    /// pbrt's roughness (`roughness` or `uroughness`/`vroughness`), remapped to α as pbrt
    /// does unless `remaproughness` is false; `None` when smooth.
    /// pbrt's `coateddiffuse`: a diffuse base under a dielectric interface, the light that enters
    /// bouncing between them — what alhazen's plastic sums in closed form (`nonlinear`: each
    /// bounce coloured by the base), but for pbrt's thin absorbing layer (`thickness`; its
    /// `albedo` 0 by default), left out. Stretched facets, which a plastic's coat cannot take, or
    /// an index of at most 1 give Cook–Torrance with its diffuse term layered under the lobe.
    fn coated_diffuse(
        &mut self,
        ctx: &Ctx,
        at: &Range<usize>,
        albedo: Texture,
        rough: Option<(f64, f64)>,
        ior: f64,
    ) -> BsdfDesc {
        match rough {
            Some((u, v)) if u != v || ior <= 1.0 => {
                self.warn(ctx, at, "coateddiffuse with stretched facets or an index of at most 1 is approximated by Cook–Torrance over Lambert, the diffuse term weighed by what the coat reflects");
                BsdfDesc::CookTorrance {
                    albedo,
                    kd: 1.0,
                    ks: 1.0,
                    facets: common::ggx(u, v),
                    ior,
                    fresnel: FresnelMode::Exact,
                    layered: true,
                    transmittance: Texture::Solid(Vec3::ZERO),
                }
            }
            None if ior <= 1.0 => {
                self.warn(ctx, at, "coateddiffuse with an index of at most 1 is read as its diffuse base");
                BsdfDesc::Lambert { albedo }
            }
            _ => {
                self.warn(
                    ctx,
                    at,
                    "coateddiffuse is read as a plastic: its thin absorbing layer (thickness, albedo) is left out",
                );
                BsdfDesc::Plastic { albedo, ior, facets: rough.map(|(u, v)| common::ggx(u, v)), nonlinear: true }
            }
        }
    }

    fn roughness(&mut self, ctx: &Ctx, p: &mut Params) -> R<Option<(f64, f64)>> {
        self.roughness_of(ctx, p, "")
    }

    /// [`Self::roughness`] of a layer's parameters, named with `prefix` (`"interface."`,
    /// `"conductor."`).
    fn roughness_of(&mut self, ctx: &Ctx, p: &mut Params, prefix: &str) -> R<Option<(f64, f64)>> {
        let r = self.float(ctx, p, &format!("{prefix}roughness"), 0.0)?;
        let u = self.float(ctx, p, &format!("{prefix}uroughness"), r)?;
        let v = self.float(ctx, p, &format!("{prefix}vroughness"), r)?;
        let remap = self.boolean(ctx, p, "remaproughness", true)?;
        let alpha = |x: f64| if remap { x.max(0.0).sqrt() } else { x.max(0.0) };
        Ok((u > 0.0 || v > 0.0).then(|| (alpha(u), alpha(v))))
    }

    fn eta(&mut self, ctx: &Ctx, p: &mut Params) -> R<f64> {
        self.eta_of(ctx, p, "eta")
    }

    /// [`Self::eta`] of the parameter `name`.
    fn eta_of(&mut self, ctx: &Ctx, p: &mut Params, name: &str) -> R<f64> {
        let Some(q) = self.find(p, name) else { return Ok(1.5) };
        match &q.values[..] {
            [Value::Num(x)] if *x > 0.0 => Ok(*x),
            [Value::Str(name)] => {
                let glass = name.strip_prefix("glass-").map(str::to_ascii_lowercase);
                let found = glass.and_then(|g| alhazen_scene::bsdf::GLASSES.iter().find(|e| e.0 == g));
                match found {
                    Some((_, b, c)) => Ok(Ior::Sellmeier { b: *b, c: *c }.nominal()),
                    None => {
                        self.warn(
                            ctx,
                            &q.span,
                            format!("named spectrum \"{name}\" is approximated by an index of 1.5"),
                        );
                        Ok(1.5)
                    }
                }
            }
            _ => Err(ctx.err(q.span, format!("\"{name}\" must be a positive number or a named spectrum"))),
        }
    }

    /// A material's `displacement`, pbrt-v4's bump mapping (the shading normal that of the
    /// surface moved along its normal by a float texture): a bump of an image map's luminance
    /// (pbrt averages the channels: the same on grey maps), its height the gain its `scale`,
    /// a `scale` or `mix` texture puts on the image; a constant moves nothing. A normal map, which pbrt prefers,
    /// replaces it (warning).
    fn displacement(&mut self, ctx: &Ctx, at: &Range<usize>, p: &mut Params) -> R<Option<Bump>> {
        let (t, map) = self.texture_ref(ctx, p, "displacement", Vec3::ZERO)?;
        // A constant added to the height moves no normal.
        let gain = Vec3::from_array(map.gain);
        let bump = match t {
            Texture::Solid(_) => None,
            Texture::Image { image, scale, offset, rotation } => {
                if offset != Vec2::ZERO || rotation != 0.0 {
                    self.warn(ctx, at, "a displacement map's udelta and vdelta are not supported; ignored");
                }
                // A float texture's gain is the same on every channel.
                let height = if gain == Vec3::splat(gain.x) { gain.x } else { gain.element_sum() / 3.0 };
                Some(Bump { height, pattern: BumpPattern::Image { image, scale } })
            }
            _ => {
                self.warn(ctx, at, "only image maps (scaled or not) can displace; the displacement is ignored");
                None
            }
        };
        if bump.is_some() && p.list.iter().any(|q| q.name == "normalmap") {
            self.warn(ctx, at, "a material with a normal map and a displacement takes the normal map, as pbrt");
            return Ok(None);
        }
        Ok(bump)
    }

    fn material(&mut self, ctx: &Ctx, kind: &str, at: &Range<usize>, p: &mut Params, name: &str) -> R<MaterialId> {
        let bsdf = self.bsdf(ctx, kind, at, p, 0)?;
        let displacement = self.displacement(ctx, at, p)?;
        let bump = match self.string(ctx, p, "normalmap")? {
            Some(file) => {
                let path = common::relative_to(ctx.path, &file);
                // Normal maps hold vectors: read linearly, not as sRGB colours.
                let img = alhazen_scene::import::load_hdr_image(&path).map_err(|e| ctx.err(at.clone(), e))?;
                self.scene.images.push(Arc::new(img));
                let image = self.scene.images.len() - 1;
                Some(Bump {
                    height: 1.0,
                    pattern: BumpPattern::NormalMap {
                        map: alhazen_scene::Texture::Image {
                            image,
                            scale: Vec2::ONE,
                            offset: Vec2::ZERO,
                            rotation: 0.0,
                        },
                    },
                })
            }
            None => displacement,
        };
        self.unused(ctx, p, &format!("material \"{kind}\""));
        let mut m = alhazen_scene::Material::from_bsdf(name, bsdf);
        m.bump = bump;
        Ok(common::add_material(&mut self.scene, m))
    }

    fn bsdf(&mut self, ctx: &Ctx, kind: &str, at: &Range<usize>, p: &mut Params, depth: usize) -> R<BsdfDesc> {
        let facets = |r: Option<(f64, f64)>| r.map(|(u, v)| common::ggx(u, v));
        Ok(match kind {
            "diffuse" => BsdfDesc::Lambert { albedo: self.texture_param(ctx, p, "reflectance", Vec3::splat(0.5))? },
            "conductor" | "coatedconductor" => {
                // A coated conductor's metal parameters are named `conductor.*`.
                let metal = if kind == "coatedconductor" { "conductor." } else { "" };
                let rough = self.roughness_of(ctx, p, metal)?;
                let (eta, k) = if let Some(q) = self.find(p, "reflectance") {
                    (common::eta_from_f0(self.color_of(ctx, &q)?), Vec3::ZERO)
                } else {
                    let (eta, k) = (format!("{metal}eta"), format!("{metal}k"));
                    (self.metal_spectrum(ctx, p, &eta, 0)?, self.metal_spectrum(ctx, p, &k, 1)?)
                };
                let fresnel =
                    if self.find(p, "reflectance").is_some() { FresnelMode::Schlick } else { FresnelMode::Exact };
                let conductor = BsdfDesc::Conductor {
                    facets: facets(rough),
                    eta,
                    k,
                    tint: Vec3::ONE,
                    fresnel,
                    multiscatter: false,
                };
                if kind == "conductor" {
                    return Ok(conductor);
                }
                // The interface as a clear coat (at least α = 0.01: pbrt's default is smooth).
                let (u, v) = self.roughness_of(ctx, p, "interface.")?.unwrap_or((0.01, 0.01));
                let ior = self.eta_of(ctx, p, "interface.eta")?;
                for k in ["thickness", "albedo", "g", "maxdepth", "nsamples"] {
                    self.find(p, k);
                }
                self.warn(ctx, at, "coatedconductor is approximated by a clear coat over its conductor: its interface's reflection, and the conductor under what the interface lets through (not pbrt's light bouncing between the layers)");
                BsdfDesc::Coated {
                    base: Box::new(conductor),
                    weight: 1.0,
                    facets: common::ggx(u.max(0.01), v.max(0.01)),
                    ior,
                    weight_map: None,
                    roughness_map: None,
                }
            }
            "dielectric" => {
                let rough = self.roughness(ctx, p)?;
                BsdfDesc::Dielectric {
                    facets: facets(rough),
                    ior: Ior::Constant(self.eta(ctx, p)?),
                    fresnel: FresnelMode::Exact,
                    transmittance: Texture::Solid(Vec3::ONE),
                    film: None,
                }
            }
            "thindielectric" => {
                let ior = self.eta(ctx, p)?;
                if ior < 1.0 {
                    self.warn(ctx, at, format!("a thin dielectric's eta {ior} below 1 is taken as 1 (no reflection)"));
                }
                BsdfDesc::ThinDielectric { ior: ior.max(1.0) }
            }
            "coateddiffuse" => {
                let albedo = self.texture_param(ctx, p, "reflectance", Vec3::splat(0.5))?;
                let rough = self.roughness(ctx, p)?;
                let ior = self.eta(ctx, p)?;
                for k in ["thickness", "albedo", "g", "maxdepth", "nsamples"] {
                    self.find(p, k);
                }
                self.coated_diffuse(ctx, at, albedo, rough, ior)
            }
            "diffusetransmission" => {
                let scale = self.float(ctx, p, "scale", 1.0)?.max(0.0);
                let mut part = |name: &str| -> R<Texture> {
                    Ok(match self.texture_param(ctx, p, name, Vec3::splat(0.25))? {
                        Texture::Solid(c) => Texture::Solid(c * scale),
                        image if scale == 1.0 => image,
                        image => {
                            self.warn(
                                ctx,
                                at,
                                format!("diffusetransmission's scale {scale} is left out of its {name} image"),
                            );
                            image
                        }
                    })
                };
                let (albedo, transmittance) = (part("reflectance")?, part("transmittance")?);
                // Lambert on both sides: Cook–Torrance without its specular lobe.
                BsdfDesc::CookTorrance {
                    albedo,
                    kd: 1.0,
                    ks: 0.0,
                    facets: common::ggx(1.0, 1.0),
                    ior: 1.5,
                    fresnel: FresnelMode::Exact,
                    layered: false,
                    transmittance,
                }
            }
            "mix" => {
                let q = self
                    .find(p, "materials")
                    .ok_or_else(|| ctx.err(at.clone(), "a mix material needs \"string materials\" [two names]"))?;
                let [Value::Str(a), Value::Str(b)] = &q.values[..] else {
                    return Err(ctx.err(q.span, "\"materials\" names two materials"));
                };
                let amount = self.color(ctx, p, "amount", Vec3::splat(0.5))?.x;
                let get = |imp: &Self, n: &str| -> R<BsdfDesc> {
                    let id = imp.named_material(ctx, n, q.span.clone())?;
                    Ok(imp.scene.materials[id as usize].bsdf.clone().expect("imported materials have a BSDF"))
                };
                let _ = depth;
                // pbrt picks the second material with probability `amount`.
                common::mix(get(self, b)?, get(self, a)?, amount.clamp(0.0, 1.0))
            }
            "interface" => {
                self.warn(ctx, at, "an interface material (a medium boundary) is rendered as clear glass of index 1");
                BsdfDesc::Dielectric {
                    facets: None,
                    ior: Ior::Constant(1.0),
                    fresnel: FresnelMode::Exact,
                    transmittance: Texture::Solid(Vec3::ONE),
                    film: None,
                }
            }
            other => {
                self.warn(
                    ctx,
                    at,
                    format!("material \"{other}\" is not supported; approximated by diffuse reflectance 0.5"),
                );
                p.used.iter_mut().for_each(|u| *u = true);
                BsdfDesc::Lambert { albedo: Texture::Solid(Vec3::splat(0.5)) }
            }
        })
    }

    /// A conductor's `eta` (`which = 0`) or `k` (`which = 1`): numbers, a named metal spectrum
    /// (`metal-Au-eta`, …), a spectrum file (`spds/Au.eta.spd`: pairs of wavelength in nm and
    /// value) or the pairs themselves, a spectrum's RGB as pbrt-v3 made its metals' (the CIE
    /// integrals over the spectrum without an illuminant, divided by ȳ's); copper by default,
    /// as pbrt.
    fn metal_spectrum(&mut self, ctx: &Ctx, p: &mut Params, name: &str, which: usize) -> R<Vec3> {
        let named = |metal: &str| alhazen_scene::bsdf::metal(metal).map(|ek| if which == 0 { ek.0 } else { ek.1 });
        let Some(q) = self.find(p, name) else { return Ok(named("copper").expect("a listed metal")) };
        let rgb = |pairs: &[f64]| {
            let (wavelengths, values): (Vec<f64>, Vec<f64>) = pairs.chunks_exact(2).map(|p| (p[0], p[1])).unzip();
            alhazen_math::cie::spectrum_to_linear_srgb(&wavelengths, &values, true, false)
        };
        if let [Value::Str(s)] = &q.values[..] {
            let file = common::relative_to(ctx.path, s);
            if !s.starts_with("metal-") && file.is_file() {
                return Ok(rgb(&spectrum_file(&file).map_err(|e| ctx.err(q.span.clone(), e))?));
            }
            let metal = match s.split('-').nth(1) {
                Some("Au") => "gold",
                Some("Ag") => "silver",
                Some("Cu") => "copper",
                Some("Al") => "aluminium",
                _ => {
                    self.warn(
                        ctx,
                        &q.span,
                        format!(
                            "spectrum \"{s}\" is not among alhazen's measured metals (Au, Ag, Cu, Al); copper stands in"
                        ),
                    );
                    "copper"
                }
            };
            return Ok(named(metal).expect("a listed metal"));
        }
        if q.ty == "spectrum" && q.values.len() > 1 {
            let pairs = self.nums(ctx, &q)?;
            return match sampled(&pairs) {
                Ok(()) => Ok(rgb(&pairs)),
                Err(e) => Err(ctx.err(q.span.clone(), format!("\"{}\" {e}", q.name))),
            };
        }
        self.color_of(ctx, &q)
    }

    /// A `Texture` directive's texture, and the change it makes to its image's values.
    fn texture(&mut self, ctx: &Ctx, kind: &str, at: &Range<usize>, p: &mut Params) -> R<(Texture, TexelMap)> {
        let mut map = TexelMap::IDENTITY;
        let t = match kind {
            "imagemap" => {
                let name = self
                    .string(ctx, p, "filename")?
                    .ok_or_else(|| ctx.err(at.clone(), "imagemap needs \"string filename\""))?;
                let path = common::relative_to(ctx.path, &name);
                let encoding = self.string(ctx, p, "encoding")?;
                let hdr = matches!(
                    path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref(),
                    Some("exr" | "hdr" | "pfm")
                );
                let linear = hdr || encoding.as_deref() == Some("linear");
                if let Some(e) = encoding.as_deref().filter(|e| !matches!(*e, "sRGB" | "linear")) {
                    self.warn(ctx, at, format!("encoding \"{e}\" is read as sRGB"));
                }
                // Read with the other files once the walk is done.
                let (images, file) = (&mut self.scene.images, (ctx.path, ctx.shared));
                let index = self.pending.push_image(images, &path, (linear, false), file, at.clone());
                // pbrt's (u, v) mapping reads the image at (s·u + Δu, t·v + Δv), `v` up as here.
                let (us, vs) = (self.float(ctx, p, "uscale", 1.0)?, self.float(ctx, p, "vscale", 1.0)?);
                let offset = Vec2::new(self.float(ctx, p, "udelta", 0.0)?, self.float(ctx, p, "vdelta", 0.0)?);
                let wrap = match self.string(ctx, p, "wrap")?.as_deref() {
                    None | Some("repeat") => Wrap::Repeat,
                    Some("black") => Wrap::Black,
                    Some("clamp") => Wrap::Clamp,
                    Some(w) => {
                        self.warn(ctx, at, format!("wrap \"{w}\" is read as repeat"));
                        Wrap::Repeat
                    }
                };
                std::sync::Arc::make_mut(&mut self.scene.images[index]).wrap = [wrap; 2];
                self.string(ctx, p, "filter")?;
                // pbrt's `scale · texel`, then `max(0, 1 − ·)` where inverted.
                map = affine(Vec3::splat(self.float(ctx, p, "scale", 1.0)?), Vec3::ZERO);
                if self.boolean(ctx, p, "invert", false)? {
                    map = map.then(TexelMap { floor: true, ..affine(-Vec3::ONE, Vec3::ONE) });
                }
                Texture::Image { image: index, scale: Vec2::new(us, vs), offset, rotation: 0.0 }
            }
            "checkerboard" => {
                let (us, vs) = (self.float(ctx, p, "uscale", 1.0)?, self.float(ctx, p, "vscale", 1.0)?);
                if us != vs {
                    self.warn(ctx, at, "a checkerboard scaled differently in u and v uses the mean scale");
                }
                let even = self.color(ctx, p, "tex1", Vec3::ONE)?;
                let odd = self.color(ctx, p, "tex2", Vec3::ZERO)?;
                self.float(ctx, p, "dimension", 2.0)?;
                Texture::Checker { even, odd, size: 2.0 / (us + vs) }
            }
            "constant" => Texture::Solid(self.color(ctx, p, "value", Vec3::ONE)?),
            "scale" => {
                let (t, inner) = self.texture_ref(ctx, p, "tex", Vec3::ONE)?;
                let s = self.color(ctx, p, "scale", Vec3::ONE)?;
                match t {
                    Texture::Solid(c) => Texture::Solid(c * s),
                    Texture::Checker { even, odd, size } => Texture::Checker { even: even * s, odd: odd * s, size },
                    img => {
                        map = inner.then(affine(s, Vec3::ZERO));
                        img
                    }
                }
            }
            "mix" => {
                let (t, m) = self.mix(ctx, at, p)?;
                map = m;
                t
            }
            other => {
                self.warn(ctx, at, format!("texture \"{other}\" is not supported; approximated by grey 0.5"));
                p.used.iter_mut().for_each(|u| *u = true);
                Texture::Solid(Vec3::splat(0.5))
            }
        };
        self.unused(ctx, p, &format!("texture \"{kind}\""));
        Ok((t, map))
    }

    /// pbrt's `mix` texture, `(1 − amount)·tex1 + amount·tex2` (`tex1` 0, `tex2` 1 and
    /// `amount` ½ by default): exact where at most one of the three is an image (a change of
    /// its values), else the mix of their means (warning).
    fn mix(&mut self, ctx: &Ctx, at: &Range<usize>, p: &mut Params) -> R<(Texture, TexelMap)> {
        let (a, ma) = self.texture_ref(ctx, p, "amount", Vec3::splat(0.5))?;
        let (t1, m1) = self.texture_ref(ctx, p, "tex1", Vec3::ZERO)?;
        let (t2, m2) = self.texture_ref(ctx, p, "tex2", Vec3::ONE)?;
        Ok(match (a, t1, t2) {
            (Texture::Solid(a), Texture::Solid(c1), Texture::Solid(c2)) => {
                (Texture::Solid((Vec3::ONE - a) * c1 + a * c2), TexelMap::IDENTITY)
            }
            (img, Texture::Solid(c1), Texture::Solid(c2)) => (img, ma.then(affine(c2 - c1, c1))),
            (Texture::Solid(a), img, Texture::Solid(c2)) => (img, m1.then(affine(Vec3::ONE - a, a * c2))),
            (Texture::Solid(a), Texture::Solid(c1), img) => (img, m2.then(affine(a, (Vec3::ONE - a) * c1))),
            (a, t1, t2) => {
                self.warn(ctx, at, "a mix of two or three textures is replaced by the mix of their means");
                let mut mean = |t: Texture, m: TexelMap| {
                    let t = self.mapped(t, m);
                    self.pending.texture_mean(&t, &mut self.scene)
                };
                let (a, c1, c2) = (mean(a, ma)?, mean(t1, m1)?, mean(t2, m2)?);
                (Texture::Solid((Vec3::ONE - a) * c1 + a * c2), TexelMap::IDENTITY)
            }
        })
    }

    // ---- lights --------------------------------------------------------------------------

    fn light(&mut self, ctx: &Ctx, kind: &str, at: &Range<usize>, p: &mut Params) -> R<()> {
        let m = self.state.ctm;
        let scale = self.float(ctx, p, "scale", 1.0)?;
        if self.find(p, "power").is_some() || self.find(p, "illuminance").is_some() {
            self.warn(
                ctx,
                at,
                "\"power\"/\"illuminance\" normalisation is not supported; the given radiance or intensity is used",
            );
        }
        let light = match kind {
            "point" => {
                let from = self.point(ctx, p, "from", Vec3::ZERO)?;
                let intensity = self.color(ctx, p, "I", Vec3::ONE)? * scale;
                Light::Point { position: m.transform_point3(from), intensity, attenuation: [1.0, 0.0, 0.0] }
            }
            "spot" => {
                let from = self.point(ctx, p, "from", Vec3::ZERO)?;
                let to = self.point(ctx, p, "to", Vec3::Z)?;
                let cone = self.float(ctx, p, "coneangle", 30.0)?;
                let delta = self.float(ctx, p, "conedelta", 5.0)?;
                let intensity = self.color(ctx, p, "I", Vec3::ONE)? * scale;
                let dir = m.transform_vector3(to - from).normalize_or_zero();
                if dir == Vec3::ZERO || !(cone > 0.0 && cone < 180.0) {
                    return Err(ctx.err(at.clone(), "a spot light needs from ≠ to and coneangle in (0, 180)"));
                }
                // pbrt's fade over conedelta: smooth in the cosine.
                let beam = (cone - delta).max(0.0);
                let fade = alhazen_scene::SpotFade::SmoothCosine;
                Light::Spot {
                    position: m.transform_point3(from),
                    direction: dir,
                    cos_cutoff: cone.to_radians().cos(),
                    falloff: 0.0,
                    beam: (beam < cone).then(|| alhazen_scene::SpotBeam { cos: beam.to_radians().cos(), fade }),
                    intensity,
                    attenuation: [1.0, 0.0, 0.0],
                }
            }
            "distant" => {
                let from = self.point(ctx, p, "from", Vec3::ZERO)?;
                let to = self.point(ctx, p, "to", Vec3::Z)?;
                let dir = m.transform_vector3(to - from).normalize_or_zero();
                if dir == Vec3::ZERO {
                    return Err(ctx.err(at.clone(), "a distant light needs from ≠ to"));
                }
                Light::Directional { direction: dir, intensity: self.color(ctx, p, "L", Vec3::ONE)? * scale }
            }
            "infinite" => {
                if let Some(name) = self.string(ctx, p, "filename")? {
                    let path = common::relative_to(ctx.path, &name);
                    let img = alhazen_scene::import::load_radiance_image(&path).map_err(|e| ctx.err(at.clone(), e))?;
                    if img.width != img.height {
                        return Err(ctx.err(
                            at.clone(),
                            format!(
                                "{}: pbrt's environment maps are square (equal-area octahedral), this one is {}×{}",
                                path.display(),
                                img.width,
                                img.height
                            ),
                        ));
                    }
                    self.environment = Some((Arc::new(img), m, scale));
                } else {
                    let l = self.color(ctx, p, "L", Vec3::ONE)? * scale;
                    self.scene.background = Background::Solid(l);
                }
                for k in ["portal"] {
                    if self.find(p, k).is_some() {
                        self.warn(ctx, at, "portals are not needed by alhazen; ignored");
                    }
                }
                self.unused(ctx, p, "light \"infinite\"");
                return Ok(());
            }
            other => {
                self.warn(ctx, at, format!("light \"{other}\" is not supported; left out"));
                return Ok(());
            }
        };
        self.unused(ctx, p, &format!("light \"{kind}\""));
        self.scene.lights.push(light);
        Ok(())
    }

    // ---- shapes --------------------------------------------------------------------------

    fn emit(&mut self, o: Object) {
        match &mut self.defining {
            Some((_, list)) => list.push(o),
            None => self.scene.objects.push(o),
        }
    }

    fn current_material(&mut self) -> MaterialId {
        if let Some(m) = self.state.material {
            return m;
        }
        if let Some(m) = self.default_material {
            return m;
        }
        let m = alhazen_scene::Material::from_bsdf(
            "pbrt default",
            BsdfDesc::Lambert { albedo: Texture::Solid(Vec3::splat(0.5)) },
        );
        let id = common::add_material(&mut self.scene, m);
        self.default_material = Some(id);
        id
    }

    fn shape(&mut self, ctx: &Ctx, kind: &str, at: &Range<usize>, p: &mut Params) -> R<()> {
        let transform = self.transform(ctx, at, self.state.ctm)?;
        let reverse = self.state.reverse;
        let partial = |imp: &mut Self, p: &mut Params, ctx: &Ctx| -> R<()> {
            let phimax = imp.float(ctx, p, "phimax", 360.0)?;
            if phimax < 360.0 {
                imp.warn(ctx, at, "partial shapes (phimax < 360) are rendered whole");
            }
            Ok(())
        };
        let shape = match kind {
            "sphere" => {
                let radius = self.float(ctx, p, "radius", 1.0)?;
                if radius <= 0.0 {
                    return Err(ctx.err(at.clone(), "a sphere's radius must be positive"));
                }
                let (zmin, zmax) = (self.float(ctx, p, "zmin", -radius)?, self.float(ctx, p, "zmax", radius)?);
                if zmin > -radius || zmax < radius {
                    self.warn(ctx, at, "a sphere cut by zmin/zmax is rendered whole");
                }
                partial(self, p, ctx)?;
                Shape::Sphere { center: Vec3::ZERO, radius }
            }
            "disk" => {
                let radius = self.float(ctx, p, "radius", 1.0)?;
                if radius <= 0.0 {
                    return Err(ctx.err(at.clone(), "a disk's radius must be positive"));
                }
                if self.float(ctx, p, "innerradius", 0.0)? > 0.0 {
                    self.warn(ctx, at, "a disk's inner radius is not supported: the disk is full");
                }
                partial(self, p, ctx)?;
                // A reversed disk faces −z: an emitting one shines that way.
                let normal = if reverse { -Vec3::Z } else { Vec3::Z };
                Shape::Disk { center: Vec3::new(0.0, 0.0, self.float(ctx, p, "height", 0.0)?), normal, radius }
            }
            "cylinder" => {
                let radius = self.float(ctx, p, "radius", 1.0)?;
                let (zmin, zmax) = (self.float(ctx, p, "zmin", -1.0)?, self.float(ctx, p, "zmax", 1.0)?);
                if radius <= 0.0 || zmin == zmax {
                    return Err(ctx.err(at.clone(), "a cylinder needs a positive radius and zmin ≠ zmax"));
                }
                partial(self, p, ctx)?;
                Shape::Cylinder {
                    base: Vec3::new(0.0, 0.0, zmin),
                    top: Vec3::new(0.0, 0.0, zmax),
                    radius,
                    capped: false,
                }
            }
            "trianglemesh" | "bilinearmesh" | "loopsubdiv" => {
                let mut mesh = self.inline_mesh(ctx, kind, at, p)?;
                if reverse {
                    flip_mesh(&mut mesh);
                }
                self.scene.meshes.push(Arc::new(mesh));
                Shape::Mesh { mesh: self.scene.meshes.len() - 1, smooth: true }
            }
            "plymesh" => {
                let name = self
                    .string(ctx, p, "filename")?
                    .ok_or_else(|| ctx.err(at.clone(), "plymesh needs \"string filename\""))?;
                let path = common::relative_to(ctx.path, &name);
                if self.find(p, "displacement").is_some() {
                    self.warn(ctx, at, "displacement is not supported; the mesh is used undisplaced");
                    self.find(p, "edgelength");
                }
                Shape::Mesh { mesh: self.ply(ctx, at, &path, reverse)?, smooth: true }
            }
            other => {
                self.warn(ctx, at, format!("shape \"{other}\" is not supported; left out"));
                return Ok(());
            }
        };
        if reverse && matches!(shape, Shape::Sphere { .. } | Shape::Cylinder { .. }) {
            self.warn(
                ctx,
                at,
                "ReverseOrientation applies to meshes and disks only: this shape emits from its outside",
            );
        }
        // pbrt's alpha: a coverage that lets a fraction of the rays through (no cutoff).
        let coverage = self.texture_param(ctx, p, "alpha", Vec3::ONE)?;
        self.unused(ctx, p, &format!("shape \"{kind}\""));
        let mut material = self.current_material();
        if let Some(area) = self.state.area.clone() {
            material = common::emissive(&mut self.scene, material, area.radiance, None);
        }
        if coverage != Texture::Solid(Vec3::ONE) {
            material = self.cut_material(material, coverage);
        }
        if let Some(name) = self.state.interior.clone() {
            material = self.absorbing(ctx, at, material, &name)?;
        }
        let (shape, transform) = common::placed_sphere(shape, transform);
        self.emit(Object { name: None, shape, transform, material, mesh_materials: vec![] });
        Ok(())
    }

    /// A `homogeneous` medium as alhazen renders it: its absorption `scale·σ_a` per unit length
    /// (Beer–Lambert) inside the dielectric (or `interface`) it fills. Scattering (`sigma_s`, 1
    /// by default as in pbrt) is not rendered: warned where it is not 0. Other media are left
    /// out (`None`, warned).
    fn medium(&mut self, ctx: &Ctx, at: &Range<usize>, p: &mut Params) -> R<Option<Vec3>> {
        let kind =
            self.string(ctx, p, "type")?.ok_or_else(|| ctx.err(at.clone(), "MakeNamedMedium needs \"string type\""))?;
        if kind != "homogeneous" {
            p.used.iter_mut().for_each(|u| *u = true);
            let why = "alhazen renders the absorption of homogeneous media only";
            self.warn(ctx, at, format!("medium \"{kind}\" is not supported ({why}); ignored"));
            return Ok(None);
        }
        if let Some(preset) = self.string(ctx, p, "preset")? {
            self.warn(ctx, at, format!("medium preset \"{preset}\" is not supported; sigma_a and sigma_s are used"));
        }
        let sigma_a = self.color(ctx, p, "sigma_a", Vec3::ONE)?;
        let sigma_s = self.color(ctx, p, "sigma_s", Vec3::ONE)?;
        let scale = self.float(ctx, p, "scale", 1.0)?;
        let absorption = sigma_a * scale;
        let valid = sigma_a.min_element() >= 0.0 && sigma_s.min_element() >= 0.0 && scale >= 0.0;
        if !(valid && absorption.is_finite() && absorption.max_element() <= 1e12) {
            return Err(ctx.err(at.clone(), "a homogeneous medium needs sigma_a ≥ 0, sigma_s ≥ 0 and scale ≥ 0"));
        }
        if sigma_s * scale != Vec3::ZERO {
            self.warn(
                ctx,
                at,
                "the medium scatters (sigma_s > 0; pbrt's default is 1): alhazen renders its absorption only",
            );
        }
        for k in ["g", "Lescale"] {
            self.float(ctx, p, k, 0.0)?;
        }
        if self.color(ctx, p, "Le", Vec3::ZERO)? != Vec3::ZERO {
            self.warn(ctx, at, "a medium's emission (Le) is not rendered");
        }
        self.unused(ctx, p, "medium \"homogeneous\"");
        Ok(Some(absorption))
    }

    /// `material` filled with the medium `name` (the shape's inside): its absorption, where the
    /// material refracts (elsewhere the medium is left out, warned).
    fn absorbing(&mut self, ctx: &Ctx, at: &Range<usize>, material: MaterialId, name: &str) -> R<MaterialId> {
        let absorption = *self.media.get(name).ok_or_else(|| {
            ctx.err(at.clone(), format!("MediumInterface names the medium \"{name}\", which no MakeNamedMedium made"))
        })?;
        let Some(absorption) = absorption.filter(|a| *a != Vec3::ZERO) else { return Ok(material) };
        if !self.scene.materials[material as usize].bsdf.as_ref().is_some_and(BsdfDesc::refracts) {
            let why = "rendered inside dielectrics and interface materials only";
            self.warn(ctx, at, format!("the medium \"{name}\" inside this shape is not rendered ({why})"));
            return Ok(material);
        }
        Ok(common::absorbing(&mut self.scene, material, absorption))
    }

    /// `material` with the cut-out `coverage` (made once per pair).
    fn cut_material(&mut self, material: MaterialId, coverage: Texture) -> MaterialId {
        let key = (material, format!("{coverage:?}"));
        if let Some(&m) = self.cut_materials.get(&key) {
            return m;
        }
        let mut m = self.scene.materials[material as usize].clone();
        m.alpha = Some(alhazen_scene::Alpha { coverage, cutoff: None });
        let id = common::add_material(&mut self.scene, m);
        self.cut_materials.insert(key, id);
        id
    }

    /// `trianglemesh` (`P`, `indices`, `N`, `uv`), `bilinearmesh` (four corners a patch, split
    /// in two triangles) and `loopsubdiv` (its control mesh).
    fn inline_mesh(
        &mut self,
        ctx: &Ctx,
        kind: &str,
        at: &Range<usize>,
        p: &mut Params,
    ) -> R<alhazen_geom::TriangleMesh> {
        let pq = self.find(p, "P").ok_or_else(|| ctx.err(at.clone(), format!("{kind} needs \"point3 P\"")))?;
        let positions = self.vec3s(ctx, &pq)?;
        let indices: Vec<u32> = match self.find(p, "indices") {
            Some(q) => self
                .nums(ctx, &q)?
                .iter()
                .map(|&x| {
                    (x >= 0.0 && x.fract() == 0.0 && x < positions.len() as f64).then_some(x as u32).ok_or_else(|| {
                        ctx.err(
                            q.span.clone(),
                            format!("index {x} is not a vertex of the {} in \"P\"", positions.len()),
                        )
                    })
                })
                .collect::<R<_>>()?,
            None if kind == "trianglemesh" && positions.len() == 3 => vec![0, 1, 2],
            None if kind == "bilinearmesh" && positions.len() == 4 => vec![0, 1, 2, 3],
            None => return Err(ctx.err(at.clone(), format!("{kind} needs \"integer indices\""))),
        };
        let triangles: Vec<[u32; 3]> = if kind == "bilinearmesh" {
            if !indices.len().is_multiple_of(4) {
                return Err(ctx.err(at.clone(), "bilinearmesh indices come in fours"));
            }
            self.warn(ctx, at, "bilinear patches are rendered as two triangles each (exact for flat ones)");
            indices.chunks_exact(4).flat_map(|q| [[q[0], q[1], q[3]], [q[0], q[3], q[2]]]).collect()
        } else {
            if !indices.len().is_multiple_of(3) {
                return Err(ctx.err(at.clone(), "triangle indices come in threes"));
            }
            if kind == "loopsubdiv" {
                self.float(ctx, p, "levels", 3.0)?;
                self.warn(ctx, at, "Loop subdivision is not supported: the control mesh is rendered");
            }
            indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect()
        };
        let normals = match self.find(p, "N") {
            Some(q) => self.vec3s(ctx, &q)?,
            None => vec![],
        };
        let uvs = match self.find(p, "uv") {
            Some(q) => self.nums(ctx, &q)?.chunks_exact(2).map(|c| Vec2::new(c[0], c[1])).collect(),
            None => vec![],
        };
        for k in ["S", "faceIndices"] {
            self.find(p, k);
        }
        let mesh = alhazen_geom::TriangleMesh { positions, normals, uvs, triangles, ..Default::default() };
        mesh.validate().map_err(|e| ctx.err(at.clone(), format!("{kind}: {e}")))?;
        Ok(mesh)
    }

    /// A mesh file's place in the scene, once per file (and orientation); its triangles are
    /// read with the other files' once the walk is done.
    fn ply(&mut self, ctx: &Ctx, at: &Range<usize>, path: &Path, reverse: bool) -> R<usize> {
        if let Some(&i) = self.meshes.get(&(path.to_path_buf(), reverse)) {
            return Ok(i);
        }
        self.scene.meshes.push(Arc::new(alhazen_geom::TriangleMesh::default()));
        let index = self.scene.meshes.len() - 1;
        self.meshes.insert((path.to_path_buf(), reverse), index);
        self.pending.push_mesh((index, None), path, (reverse, false), (ctx.path, ctx.shared), at.clone());
        Ok(index)
    }

    // ---- the camera, and mirroring -------------------------------------------------------

    /// Places the camera and, when pbrt's camera shows the mirror image of alhazen's (a plain
    /// `LookAt`), mirrors the whole scene in `x` (see the module documentation).
    fn place_camera(&mut self) {
        let (w, h) = (self.scene.render.width as f64, self.scene.render.height as f64);
        let Some((c, kind)) = self.camera else {
            self.warnings.add(Path::new("scene"), 0, "the scene has no Camera: alhazen's default camera is used");
            self.finish_environment(false);
            return;
        };
        let l = Mat3::from_mat4(c);
        let eye = c.transform_point3(Vec3::ZERO);
        let (right, up, ahead) = (l * Vec3::X, (l * Vec3::Y).normalize(), (l * Vec3::Z).normalize());
        // alhazen's image right is ahead × up; pbrt's is the camera's +x.
        let mirror = right.dot(ahead.cross(up)) < 0.0;
        let f = if mirror { Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0)) } else { Mat4::IDENTITY };
        let look = LookAt {
            eye: f.transform_point3(eye),
            target: f.transform_point3(eye + ahead),
            up: f.transform_vector3(up),
        };
        let depth_scale = (l * Vec3::Z).length();
        self.scene.camera = match kind {
            CameraKind::Perspective { fov_degrees, lens } => CameraDesc::Perspective {
                look,
                // pbrt's fov spans the shorter side of the image.
                opening: PerspectiveOpening::Fov { angle: fov_degrees.to_radians(), horizontal: w < h },
                // The lens in world units: the camera's transform may scale.
                lens: lens.map(|lens| alhazen_scene::ThinLens {
                    aperture: lens.aperture * right.length(),
                    focus_distance: lens.focus_distance * depth_scale,
                }),
            },
            CameraKind::Orthographic { scale } => {
                CameraDesc::Orthographic { look, width: 2.0 * scale * (w / h).max(1.0) * right.length() }
            }
        };
        if mirror {
            let ft = Transform::from_matrix(f).expect("a reflection is invertible");
            for o in &mut self.scene.objects {
                o.transform = ft * o.transform;
            }
            for light in &mut self.scene.lights {
                match light {
                    Light::Point { position, .. } => *position = f.transform_point3(*position),
                    Light::Spot { position, direction, .. } => {
                        *position = f.transform_point3(*position);
                        *direction = f.transform_vector3(*direction);
                    }
                    Light::Directional { direction, .. } => *direction = f.transform_vector3(*direction),
                    Light::Environment { .. } => {}
                }
            }
        }
        self.finish_environment(mirror);
    }

    /// Resamples pbrt's equal-area octahedral environment map into alhazen's equirectangular
    /// one, through the light's transform (and the mirror), so any orientation maps exactly.
    fn finish_environment(&mut self, mirror: bool) {
        let Some((img, m, scale)) = self.environment.take() else { return };
        let light_from_world = Mat3::from_mat4(m).inverse();
        let n = img.width as usize;
        let (w, h) = (2 * n, n);
        let mut pixels = Vec::with_capacity(w * h);
        for y in 0..h {
            for x in 0..w {
                let u = (x as f64 + 0.5) / w as f64;
                let v = (y as f64 + 0.5) / h as f64;
                // alhazen's equirectangular direction: azimuth from −z towards +x, v from +y.
                let (phi, theta) = (u * 2.0 * std::f64::consts::PI, v * std::f64::consts::PI);
                let mut d = Vec3::new(theta.sin() * phi.sin(), theta.cos(), -theta.sin() * phi.cos());
                if mirror {
                    d.x = -d.x;
                }
                let local = (light_from_world * d).normalize_or_zero();
                let st = equal_area_sphere_to_square(local);
                let (i, j) = (((st.x * n as f64) as usize).min(n - 1), ((st.y * n as f64) as usize).min(n - 1));
                pixels.push(img.texel(j * n + i));
            }
        }
        self.scene.images.push(Arc::new(ImageData::new(w as u32, h as u32, pixels)));
        self.scene.lights.push(Light::Environment {
            image: self.scene.images.len() - 1,
            scale,
            rotation: 0.0,
            up: Vec3::Y,
        });
    }
}

/// Clarberg's equal-area map of the unit sphere onto `[0, 1]²` (octahedral), as pbrt-v4 uses
/// for its environment maps; `atan` computed exactly.
fn equal_area_sphere_to_square(d: Vec3) -> Vec2 {
    let (x, y, z) = (d.x.abs(), d.y.abs(), d.z.abs());
    let r = (1.0 - z).max(0.0).sqrt();
    let (a, b) = (x.max(y), x.min(y));
    let b = if a == 0.0 { 0.0 } else { b / a };
    let mut phi = b.atan() * 2.0 / std::f64::consts::PI;
    if x < y {
        phi = 1.0 - phi;
    }
    let mut v = phi * r;
    let mut u = r - v;
    if d.z < 0.0 {
        std::mem::swap(&mut u, &mut v);
        u = 1.0 - u;
        v = 1.0 - v;
    }
    Vec2::new(0.5 * (u.copysign(d.x) + 1.0), 0.5 * (v.copysign(d.y) + 1.0))
}

/// The change `offset + gain·v` of an image's values.
fn affine(gain: Vec3, offset: Vec3) -> TexelMap {
    TexelMap { gain: gain.to_array(), offset: offset.to_array(), floor: false }
}

/// The pairs of wavelength (nm) and value of a spectrum file (pbrt's `.spd`: numbers separated
/// by white space, `#` comments), or why they cannot be had.
fn spectrum_file(path: &Path) -> Result<Vec<f64>, String> {
    let text = common::read_text(path).map_err(|e| format!("cannot read spectrum file: {e}"))?;
    let mut pairs = Vec::new();
    for word in text.lines().flat_map(|l| l.split('#').next().unwrap_or("").split_whitespace()) {
        let v =
            word.parse::<f64>().map_err(|_| format!("spectrum file {}: \"{word}\" is not a number", path.display()))?;
        pairs.push(v);
    }
    sampled(&pairs).map_err(|e| format!("spectrum file {} {e}", path.display()))?;
    Ok(pairs)
}

/// Whether `pairs` is a sampled spectrum: two or more pairs of finite numbers, the wavelengths
/// increasing.
fn sampled(pairs: &[f64]) -> Result<(), String> {
    let ok = pairs.len() >= 4
        && pairs.len().is_multiple_of(2)
        && pairs.iter().all(|x| x.is_finite())
        && pairs.chunks_exact(2).zip(pairs.chunks_exact(2).skip(1)).all(|(a, b)| a[0] < b[0]);
    if ok { Ok(()) } else { Err("must be two or more pairs of wavelength (nm, increasing) and value".into()) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equal_area_map_sends_the_poles_and_axes_where_pbrt_does() {
        let close = |a: Vec2, b: Vec2| (a - b).length() < 1e-12;
        assert!(close(equal_area_sphere_to_square(Vec3::Z), Vec2::new(0.5, 0.5)));
        assert!(close(equal_area_sphere_to_square(Vec3::X), Vec2::new(1.0, 0.5)));
        assert!(close(equal_area_sphere_to_square(Vec3::Y), Vec2::new(0.5, 1.0)));
        assert!(
            close(equal_area_sphere_to_square(-Vec3::Z), Vec2::new(1.0, 1.0))
                || close(equal_area_sphere_to_square(-Vec3::Z), Vec2::new(0.0, 0.0))
        );
    }
}
