//! What the importers share: reading files with a size limit, located errors and warnings, mesh
//! files read together on all threads (`PendingFiles`: meshes and images), and
//! the mapping of the common material models (metallic–roughness, named IORs) to alhazen's
//! BSDFs (course, §"Physically based models").

use crate::Warning;
use alhazen_math::Transform;
use alhazen_math::Vec3;
use alhazen_scene::bsdf::{BsdfDesc, Ior, MetalRoughness};
pub(crate) use alhazen_scene::bsdf::{eta_from_f0, ggx};
use alhazen_scene::{Diagnostic, FresnelMode, Material, MaterialId, Rgb, Scene, SceneError, Shape, Texture};
use std::collections::HashSet;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The largest scene or buffer file an importer reads (2 GiB): larger ones are refused before
/// anything is allocated.
pub const MAX_SCENE_FILE_BYTES: u64 = 2 << 30;

/// Reads a whole file, refusing one over [`MAX_SCENE_FILE_BYTES`] (and anything that is not a
/// regular file, such as `/dev/zero`) before reading.
pub(crate) fn read_bytes(path: &Path) -> Result<Vec<u8>, SceneError> {
    let io = |source| SceneError::Io { path: path.to_path_buf(), source };
    let meta = std::fs::metadata(path).map_err(io)?;
    if !meta.is_file() {
        return Err(io(std::io::Error::other("not a regular file")));
    }
    if meta.len() > MAX_SCENE_FILE_BYTES {
        return Err(io(std::io::Error::other(format!(
            "{} bytes is more than the {MAX_SCENE_FILE_BYTES} an imported file may have",
            meta.len()
        ))));
    }
    std::fs::read(path).map_err(io)
}

/// Reads a text file (see [`read_bytes`]); invalid UTF-8 is an error at its position.
pub(crate) fn read_text(path: &Path) -> Result<String, SceneError> {
    String::from_utf8(read_bytes(path)?).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        let text = String::from_utf8_lossy(e.as_bytes()).into_owned();
        located(path, &text, at..at + 1, "the file is not valid UTF-8")
    })
}

/// An error at byte range `span` of `text`.
pub(crate) fn located(file: &Path, text: &str, span: Range<usize>, message: impl Into<String>) -> SceneError {
    SceneError::Syntax(Box::new(Diagnostic::at(file, text, span, message)))
}

/// The 1-based line of byte `at` of `text`.
pub(crate) fn line_of(text: &str, at: usize) -> usize {
    text.as_bytes()[..at.min(text.len())].iter().filter(|&&b| b == b'\n').count() + 1
}

/// Warnings, each said once.
#[derive(Default)]
pub(crate) struct Warnings {
    list: Vec<Warning>,
    seen: HashSet<Warning>,
}

impl Warnings {
    /// Records a warning at `file:line` unless the same was said there already.
    pub(crate) fn add(&mut self, file: &Path, line: usize, message: impl Into<String>) {
        let w = Warning { file: file.to_path_buf(), line, message: message.into() };
        if self.seen.insert(w.clone()) {
            self.list.push(w);
        }
    }

    pub(crate) fn into_vec(self) -> Vec<Warning> {
        self.list
    }
}

/// Joins a file name found in a scene with the scene's directory.
pub(crate) fn relative_to(scene_file: &Path, name: &str) -> PathBuf {
    scene_file.parent().unwrap_or(Path::new(".")).join(name)
}

/// Adds a material and returns its id.
pub(crate) fn add_material(scene: &mut Scene, m: Material) -> MaterialId {
    scene.materials.push(m);
    (scene.materials.len() - 1) as MaterialId
}

/// `base` with `emission` added, its `texture` where it varies (a new material; `base` is
/// shared by other objects).
pub(crate) fn emissive(scene: &mut Scene, base: MaterialId, emission: Rgb, texture: Option<Texture>) -> MaterialId {
    let mut m = scene.materials[base as usize].clone();
    m.name = format!("{} (emitting)", m.name);
    (m.emission, m.emission_texture) = (emission, texture);
    add_material(scene, m)
}

/// Material `base` with an inside that absorbs `absorption` per unit length (a dielectric's:
/// tinted glass, a coloured liquid), a copy of it where it absorbed otherwise.
pub(crate) fn absorbing(scene: &mut Scene, base: MaterialId, absorption: Rgb) -> MaterialId {
    if scene.materials[base as usize].absorption == absorption {
        return base;
    }
    let mut m = scene.materials[base as usize].clone();
    m.name = format!("{} (absorbing)", m.name);
    m.absorption = absorption;
    add_material(scene, m)
}

/// The glTF 2.0 metallic–roughness model (also Mitsuba's `principled` reduced to it): a metal whose normal-incidence reflectance is the base
/// colour (Schlick), mixed by `metallic` with a dielectric coating over a Lambertian base (the
/// coating's index and strength and the metal's multiple scattering: `lobes`), both with GGX roughness `α = roughness²`; `transmission` mixes in rough glass of index
/// `ior`, times the map's luminance at each point where there is one (glTF's
/// `transmissionTexture`, whose red channel the importer gives all three), the light it lets
/// through keeping `glass_tint` at each crossing (Disney's, Cycles' and Mitsuba's `√base`, so
/// that a closed object passes its base colour).
pub(crate) fn metal_rough(
    base: Texture,
    base_mean: Rgb,
    metallic: f64,
    roughness: f64,
    (ior, lobes): (f64, MetalRoughness),
    glass: Glass,
) -> BsdfDesc {
    let Glass { weight: transmission, map: transmission_map, tint: glass_tint, film } = glass;
    // The model at a point of colour `base_mean`, its coating given the texture itself, its
    // metal smooth where the roughness is below the facets' least `α` (a material with a
    // single value need not keep the same lobes everywhere).
    let (mut metal, mut plastic, _) = BsdfDesc::metallic_roughness_at(base_mean, metallic, roughness, lobes);
    let alpha = (roughness * roughness).clamp(0.0, 1.0);
    let facets = (alpha > 1e-3).then(|| ggx(alpha, alpha));
    if let BsdfDesc::Conductor { facets: f, .. } = &mut metal {
        *f = facets;
    }
    if let BsdfDesc::CookTorrance { albedo, .. } = &mut plastic {
        *albedo = base;
    }
    let opaque = mix(metal, plastic, metallic);
    let glass = BsdfDesc::Dielectric {
        facets,
        ior: Ior::Constant(ior),
        fresnel: FresnelMode::Exact,
        transmittance: glass_tint,
        film,
    };
    let weight = transmission * (1.0 - metallic);
    match transmission_map {
        // Glass only where the map says: the mix kept even at full weight.
        Some(map) if weight > 0.0 => {
            BsdfDesc::Mix { a: Box::new(glass), b: Box::new(opaque), weight, weight_map: Some(map) }
        }
        _ => mix(glass, opaque, weight),
    }
}

/// The glass a metallic–roughness material mixes in ([`metal_rough`]).
pub(crate) struct Glass {
    /// Its weight (glTF's `transmissionFactor`).
    pub weight: f64,
    /// Where it is: the weight times the map's luminance, per point.
    pub map: Option<Texture>,
    /// What the light it lets through keeps at each crossing.
    pub tint: Texture,
    /// A thin film on its outside face.
    pub film: Option<Box<alhazen_scene::bsdf::Iridescence>>,
}

impl Glass {
    /// Clear glass of weight `weight` everywhere.
    pub fn clear(weight: f64, tint: Texture) -> Self {
        Glass { weight, map: None, tint, film: None }
    }
}

/// The plain lobes of the metallic–roughness model: a coating of index `ior` at full
/// strength, a metal of single scattering (as Mitsuba's and pbrt's).
pub(crate) fn plain_lobes(ior: f64) -> MetalRoughness {
    MetalRoughness {
        ior,
        specular: 1.0,
        multiscatter: false,
        anisotropy: Default::default(),
        translucency: Default::default(),
    }
}

/// `w·a + (1 − w)·b`, or the one that has all the weight.
pub(crate) fn mix(a: BsdfDesc, b: BsdfDesc, w: f64) -> BsdfDesc {
    if w >= 1.0 {
        a
    } else if w <= 0.0 {
        b
    } else {
        BsdfDesc::Mix { a: Box::new(a), b: Box::new(b), weight: w, weight_map: None }
    }
}

/// Indices of refraction that Mitsuba and pbrt accept by name (values from standard tables at
/// the sodium D line).
pub(crate) const NAMED_IORS: &[(&str, f64)] = &[
    ("vacuum", 1.0),
    ("helium", 1.000036),
    ("hydrogen", 1.000132),
    ("air", 1.000277),
    ("carbon dioxide", 1.00045),
    ("water", 1.333),
    ("acetone", 1.36),
    ("ethanol", 1.361),
    ("carbon tetrachloride", 1.461),
    ("glycerol", 1.4729),
    ("benzene", 1.501),
    ("silicone oil", 1.52045),
    ("bromine", 1.661),
    ("water ice", 1.31),
    ("fused quartz", 1.458),
    ("pyrex", 1.47),
    ("acrylic glass", 1.49),
    ("polypropylene", 1.49),
    ("bk7", 1.5046),
    ("sodium chloride", 1.544),
    ("amber", 1.55),
    ("pet", 1.575),
    ("diamond", 2.419),
];

/// The index of refraction a name stands for.
pub(crate) fn named_ior(name: &str) -> Option<f64> {
    let n = name.trim().to_ascii_lowercase();
    NAMED_IORS.iter().find(|e| e.0 == n).map(|e| e.1)
}

/// Checks that every number of a value is finite.
pub(crate) fn finite(v: &[f64]) -> bool {
    v.iter().all(|x| x.is_finite())
}

/// A sphere whose transform only moves and uniformly scales it, stated in world space with no
/// transform (the renderer tests such spheres several at a time); anything else as it is.
pub(crate) fn placed_sphere(shape: Shape, transform: Transform) -> (Shape, Transform) {
    let Shape::Sphere { center, radius } = shape else { return (shape, transform) };
    let m = transform.matrix();
    let l = alhazen_math::Mat3::from_mat4(m);
    let s = l.x_axis.x;
    let uniform = s > 0.0 && l == alhazen_math::Mat3::from_diagonal(Vec3::splat(s));
    if !uniform {
        return (shape, transform);
    }
    (Shape::Sphere { center: transform.point(center), radius: radius * s }, Transform::IDENTITY)
}

/// Turns a mesh inside out: each triangle's winding reversed, its normals negated.
pub(crate) fn flip_mesh(mesh: &mut alhazen_geom::TriangleMesh) {
    for t in &mut mesh.triangles {
        t.swap(1, 2);
    }
    for n in &mut mesh.normals {
        *n = -*n;
    }
}

/// Mesh and image files met while scene files are walked, each with its place in
/// `scene.meshes` or `scene.images` (a placeholder until loaded), read together on all threads
/// when the walk is done ([`Self::load`]): a scene of many meshes or textures loads in a
/// fraction of the time.
#[derive(Default)]
pub(crate) struct PendingFiles {
    /// The scene files that name such files, and their texts, for the locations of errors
    /// found after the walk.
    files: Vec<(PathBuf, Arc<str>)>,
    reads: Vec<PendingRead>,
}

struct PendingRead {
    path: PathBuf,
    what: Read,
    /// Where the scene names it: `files[file]`, bytes `span`.
    file: usize,
    span: Range<usize>,
}

/// An affine change of an image's channels, `offset + gain·v`, then `max(0, ·)` where `floor`
/// (pbrt's image maps' `scale` and `invert`, its `scale` and `mix` textures over one image).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TexelMap {
    /// Each channel's factor.
    pub gain: [f64; 3],
    /// Each channel's term.
    pub offset: [f64; 3],
    /// Whether negative values become 0.
    pub floor: bool,
}

impl TexelMap {
    /// No change.
    pub const IDENTITY: Self = Self { gain: [1.0; 3], offset: [0.0; 3], floor: false };

    /// This change, then `outer`.
    pub fn then(self, outer: Self) -> Self {
        Self {
            gain: std::array::from_fn(|c| outer.gain[c] * self.gain[c]),
            offset: std::array::from_fn(|c| outer.offset[c] + outer.gain[c] * self.offset[c]),
            floor: self.floor || outer.floor,
        }
    }

    /// `image` changed (itself where this is no change).
    pub fn apply(&self, image: alhazen_scene::ImageData) -> alhazen_scene::ImageData {
        if *self == Self::IDENTITY {
            return image;
        }
        image.channels_mapped(|c, v| {
            let x = (self.offset[c] + self.gain[c] * v as f64) as f32;
            if self.floor { x.max(0.0) } else { x }
        })
    }
}

/// What a pending file becomes.
#[derive(Clone, Copy)]
enum Read {
    /// `scene.meshes[index]`, turned inside out when `flip` and its texture coordinates'
    /// `v` turned to `1 − v` when `flip_v`; of a Mitsuba `serialized` file, its mesh `part`.
    Mesh { index: usize, flip: bool, flip_v: bool, part: Option<usize> },
    /// `scene.images[index]`: linear values (or sRGB decoded), upside down when `rows_reversed`,
    /// its channels changed by `map`.
    Image { index: usize, linear: bool, rows_reversed: bool, map: TexelMap },
}

/// A pending file as read, with where it goes.
enum Loaded {
    Mesh { index: usize, flip: bool, flip_v: bool, mesh: Result<alhazen_scene::import::LoadedMesh, String> },
    Image { index: usize, rows_reversed: bool, map: TexelMap, image: Result<alhazen_scene::ImageData, String> },
}

impl PendingFiles {
    /// Mesh file `path` (turned inside out when `flip`, its texture coordinates' `v` turned to
    /// `1 − v` when `flip_v`, as Mitsuba's OBJ reader does; of a Mitsuba `serialized` file, its
    /// mesh `part`) for `scene.meshes[index]`, its shape at bytes `span` of scene file `at` (its
    /// path and text, kept only for files that name mesh or image files: a scene's large files
    /// of inline geometry are not held to the end).
    pub fn push_mesh(
        &mut self,
        (index, part): (usize, Option<usize>),
        path: &Path,
        (flip, flip_v): (bool, bool),
        at: (&Path, &Arc<str>),
        span: Range<usize>,
    ) {
        self.push(path, Read::Mesh { index, flip, flip_v, part }, at, span);
    }

    /// Image file `path`, read as linear values (else decoded from sRGB), turned upside down
    /// when `rows_reversed`; named at bytes `span` of scene file `at`. (Its placeholder's `wrap`,
    /// set by the caller, is kept when the image is read.) Its place in `images` (a
    /// placeholder until [`Self::load`]) is returned.
    pub fn push_image(
        &mut self,
        images: &mut Vec<Arc<alhazen_scene::ImageData>>,
        path: &Path,
        (linear, rows_reversed): (bool, bool),
        at: (&Path, &Arc<str>),
        span: Range<usize>,
    ) -> usize {
        images.push(Arc::new(alhazen_scene::ImageData::new(1, 1, vec![[0.0; 3]])));
        let index = images.len() - 1;
        self.push(path, Read::Image { index, linear, rows_reversed, map: TexelMap::IDENTITY }, at, span);
        index
    }

    /// A copy of image `index` of `images` with its channels changed by `map` (a texture of
    /// a scene file that changes an image), added to `images`: read from the same file once it
    /// is read, if it is pending. Its place in `images` is returned.
    pub fn mapped_image(
        &mut self,
        images: &mut Vec<Arc<alhazen_scene::ImageData>>,
        index: usize,
        map: TexelMap,
    ) -> usize {
        let pending = self.reads.iter().find(|r| matches!(r.what, Read::Image { index: i, .. } if i == index));
        let copy = pending.map(|r| {
            let Read::Image { linear, rows_reversed, map: first, .. } = r.what else { unreachable!("an image") };
            let what = Read::Image { index: images.len(), linear, rows_reversed, map: first.then(map) };
            PendingRead { path: r.path.clone(), what, file: r.file, span: r.span.clone() }
        });
        let placeholder = images[index].clone();
        match copy {
            Some(read) => {
                self.reads.push(read);
                images.push(placeholder);
            }
            None => images.push(Arc::new(map.apply((*placeholder).clone()))),
        }
        images.len() - 1
    }

    fn push(&mut self, path: &Path, what: Read, at: (&Path, &Arc<str>), span: Range<usize>) {
        if !self.files.last().is_some_and(|(_, text)| Arc::ptr_eq(text, at.1)) {
            self.files.push((at.0.to_path_buf(), at.1.clone()));
        }
        let file = self.files.len() - 1;
        self.reads.push(PendingRead { path: path.to_path_buf(), what, file, span });
    }

    /// Reads image `index` into `scene` now, if it is still pending (a texture replaced by its
    /// mean needs its pixels before the walk ends); an error is located where the scene names
    /// the file.
    pub fn load_image_now(&mut self, scene: &mut Scene, index: usize) -> Result<(), SceneError> {
        let Some(at) = self.reads.iter().position(|r| matches!(r.what, Read::Image { index: i, .. } if i == index))
        else {
            return Ok(());
        };
        let r = self.reads.remove(at);
        let Read::Image { linear, rows_reversed, map, .. } = r.what else { unreachable!("found as an image") };
        let image = if linear {
            alhazen_scene::import::load_hdr_image(&r.path)
        } else {
            alhazen_scene::import::load_image(&r.path)
        };
        let image = image.map_err(|e| {
            let (path, text) = &self.files[r.file];
            located(path, text, r.span.clone(), e)
        })?;
        let image = if rows_reversed { image.rows_reversed() } else { image };
        let image = map.apply(image);
        // The placeholder holds the wrap the texture asked for.
        scene.images[index] = Arc::new(image.with_wrap(scene.images[index].wrap));
        Ok(())
    }

    /// The mean colour of `t` (`texture::mean`), its image read first if it is pending.
    pub fn texture_mean(&mut self, t: &Texture, scene: &mut Scene) -> Result<Rgb, SceneError> {
        if let Texture::Image { image, .. } = t {
            self.load_image_now(scene, *image)?;
        }
        Ok(alhazen_scene::texture::mean(t, &scene.images))
    }

    /// Reads the files pushed, on all threads, into `scene`, each mesh given to `adjust` first;
    /// the first that cannot be read, in the order they were pushed, is the error, where the
    /// scene names it.
    pub fn load(
        &mut self,
        scene: &mut Scene,
        adjust: impl Fn(&mut alhazen_geom::TriangleMesh),
    ) -> Result<(), SceneError> {
        use rayon::prelude::*;
        let pending = std::mem::take(&mut self.reads);
        let read = |r: &PendingRead| match r.what {
            Read::Mesh { index, flip, flip_v, part } => {
                let mesh = match part {
                    None => alhazen_scene::import::load_mesh(&r.path),
                    Some(part) => crate::serialized::load(&r.path, part)
                        .map(|mesh| alhazen_scene::import::LoadedMesh { mesh, materials: vec![], warnings: vec![] }),
                };
                Loaded::Mesh { index, flip, flip_v, mesh }
            }
            Read::Image { index, linear, rows_reversed, map } => {
                let image = if linear {
                    alhazen_scene::import::load_hdr_image(&r.path)
                } else {
                    alhazen_scene::import::load_image(&r.path)
                };
                Loaded::Image { index, rows_reversed, map, image }
            }
        };
        let loaded: Vec<_> = pending.par_iter().map(read).collect();
        for (r, loaded) in pending.into_iter().zip(loaded) {
            let at = |e: String| {
                let (path, text) = &self.files[r.file];
                located(path, text, r.span.clone(), e)
            };
            match loaded {
                Loaded::Mesh { index, flip, flip_v, mesh } => {
                    let mut mesh = mesh.map_err(at)?.mesh;
                    adjust(&mut mesh);
                    if flip_v {
                        mesh.uvs.iter_mut().for_each(|uv| uv.y = 1.0 - uv.y);
                    }
                    if flip {
                        flip_mesh(&mut mesh);
                    }
                    scene.meshes[index] = Arc::new(mesh);
                }
                Loaded::Image { index, rows_reversed, map, image } => {
                    let image = image.map_err(at)?;
                    let image = if rows_reversed { image.rows_reversed() } else { image };
                    let image = map.apply(image);
                    scene.images[index] = Arc::new(image.with_wrap(scene.images[index].wrap));
                }
            }
        }
        Ok(())
    }
}
