//! glTF 2.0 (`.gltf` with embedded, data-URI or external buffers and images; `.glb`), read with
//! the `gltf` crate.
//!
//! The default scene's node hierarchy is walked with each node's TRS or matrix composed onto
//! its parent's (the course's scene graph); every mesh primitive becomes one shared mesh
//! (positions, normals, first texture coordinates — `v` flipped, glTF's origin being the image's
//! top — indices; strips and fans unrolled; Draco-compressed ones decoded first, `draco`, as are meshopt-compressed buffer views, `meshopt`),
//! instanced by every node that uses it — except
//! where a node poses it (a skin, by linear blend skinning with its joints' world transforms;
//! morph targets of non-zero weight): that node's mesh is its own, its vertices moved; a node's
//! `EXT_mesh_gpu_instancing` instances are objects of its one mesh. Materials map
//! through the metallic–roughness model (`common::metal_rough`): the base-colour texture and
//! factor exactly, `KHR_materials_transmission` and `_ior`, emission with
//! `KHR_materials_emissive_strength`, a transmitting material's absorbing inside with
//! `KHR_materials_volume` (and its index by wavelength with `KHR_materials_dispersion`), a
//! clear coat with `KHR_materials_clearcoat`, cloth's sheen with `KHR_materials_sheen`, brushed
//! facets with `KHR_materials_anisotropy`, a thin film's interference colours with
//! `KHR_materials_iridescence`, a thin sheet's light passed through diffusely (leaves, paper)
//! with `KHR_materials_diffuse_transmission`; an unlit material (`KHR_materials_unlit`) is a black emitter
//! of its base colour; a `KHR_materials_variants` variant is chosen by the `variant` parameter
//! (`-D variant=NAME`); a metallic–roughness texture, a textured metal's
//! colour, stretched facets and a thin film are read per point (`BsdfDesc::MetallicRoughness`, the model at
//! each point), by their means under transmission; so is an emission texture (its factor and strength
//! multiplied in).
//! `KHR_lights_punctual` lights convert from photometric units (candela, lux) by the 683 lm/W
//! that Blender's exporter uses. The first camera met is the camera; without one the
//! scene's bounds are framed from `+z`.

use crate::common::{self, Warnings};
use crate::{Imported, draco, meshopt};
use alhazen_geom::TriangleMesh;
use alhazen_math::{Bounds3, Mat4, Quat, Transform, Vec2, Vec3};
use alhazen_scene::bsdf::{Anisotropy, AnisotropyModel, BsdfDesc, Ior, Iridescence, MetalRoughness, Translucency};
use alhazen_scene::{
    Bump, BumpPattern, CameraDesc, Diagnostic, ImageData, IntegratorKind, Light, LookAt, MaterialId, Object,
    PerspectiveOpening, Scene, SceneError, Shape, Texture, Wrap,
};
use gltf::accessor::DataType;
use gltf::material::AlphaMode;
use gltf::mesh::Mode;
use rayon::prelude::*;
use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

type R<T> = Result<T, SceneError>;

/// Luminous efficacy used to turn glTF's photometric light units into radiometric ones (lm/W).
pub const LUMENS_PER_WATT: f64 = 683.0;

/// Extensions whose absence from the model changes the picture but leaves it meaningful.
const KNOWN: &[&str] = &[
    "KHR_lights_punctual",
    "KHR_materials_transmission",
    "KHR_materials_ior",
    "KHR_materials_emissive_strength",
    "KHR_texture_transform",
    "KHR_mesh_quantization",
    "KHR_materials_specular",
    "KHR_materials_volume",
    "KHR_materials_clearcoat",
    "KHR_materials_anisotropy",
    "EXT_texture_webp",
    "KHR_materials_dispersion",
    "EXT_mesh_gpu_instancing",
    "KHR_materials_sheen",
    "KHR_materials_iridescence",
    "KHR_materials_unlit",
    "KHR_materials_variants",
    "KHR_materials_diffuse_transmission",
    draco::EXTENSION,
    meshopt::EXTENSIONS[0],
    meshopt::EXTENSIONS[1],
];

/// Reads a glTF 2.0 file, refusing compressed meshes that would decode to more than
/// `memory_budget` bytes before decoding them.
pub fn load(path: &Path, memory_budget: u64, parameters: &[(String, String)]) -> Result<Imported, SceneError> {
    let bytes = common::read_bytes(path)?;
    // The gltf crate's validation panics on some inconsistent files (an index out of bounds in
    // gltf-json 1.4, found by fuzzing): such a panic is caught, kept off the terminal, and
    // reported as a bad file. (The hook is the process's: a panic elsewhere at this moment
    // would be silent too, and still fail.)
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let result =
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| load_bytes(path, &bytes, memory_budget, parameters)));
    std::panic::set_hook(hook);
    result.unwrap_or_else(|_| {
        Err(error(path, &bytes, "not a valid glTF 2.0 file: its parts are inconsistent (the glTF reader failed on it)"))
    })
}

fn load_bytes(
    path: &Path,
    bytes: &[u8],
    memory_budget: u64,
    parameters: &[(String, String)],
) -> Result<Imported, SceneError> {
    let invalid = |e: gltf::Error| error(path, bytes, format!("not a valid glTF 2.0 file: {e}"));
    let (mut json, blob) = parse(bytes).map_err(invalid)?;
    // A required extension alhazen cannot read is said before the reader's validation (which
    // would name the textures a required image format leaves without a source); the rest
    // alhazen reads, some without the reader's support, whose validation would refuse them.
    if let Some(e) = json.extensions_required.iter().find(|e| !KNOWN.contains(&e.as_str())) {
        return Err(error(path, bytes, format!("the file requires extension {e}, which alhazen cannot read")));
    }
    json.extensions_required.clear();
    // A texture's `EXT_texture_webp` image, which glTF prefers to its fallback (and which may
    // be its only image), becomes its source.
    for texture in &mut json.textures {
        let webp = texture.extensions.as_ref().and_then(|e| e.others.get("EXT_texture_webp"));
        if let Some(i) = webp.and_then(|w| w.get("source")).and_then(|i| i.as_u64()) {
            texture.source = gltf::json::Index::new(i.min(u32::MAX as u64 - 1) as u32);
        }
    }
    // The buffers are read before validation: compressed buffer views and Draco-compressed
    // primitives are decoded from them into views and accessors of their own, which the
    // validation then sees.
    meshopt::empty_placeholders(&mut json, blob.is_some());
    let base = path.parent().unwrap_or(Path::new("."));
    let unvalidated = gltf::Document::from_json_without_validation(json);
    let mut buffers = gltf::import_buffers(&unvalidated, Some(base), blob)
        .map_err(|e| error(path, bytes, format!("cannot read its buffers: {e}")))?;
    let mut json = unvalidated.into_json();
    meshopt::decompress(&mut json, &mut buffers, memory_budget).map_err(|e| error(path, bytes, e))?;
    draco::decompress(&mut json, &mut buffers, memory_budget).map_err(|e| error(path, bytes, e))?;
    let document = gltf::Document::from_json(json).map_err(invalid)?;
    let mut imp = Importer {
        path,
        worlds: HashMap::new(),
        textures: document.textures().collect(),
        accessors: document.accessors().collect(),
        bytes,
        buffers,
        base,
        scene: alhazen_scene::empty_scene(),
        warnings: Warnings::default(),
        materials: HashMap::new(),
        meshes: HashMap::new(),
        images: HashMap::new(),
        decoded: HashMap::new(),
        camera: None,
        bounds: Bounds3::EMPTY,
        unlit: Default::default(),
        all_materials: document.materials().collect(),
        variant: None,
    };
    imp.scene.render.integrator = IntegratorKind::Path;
    imp.extensions(&document);
    imp.variant = imp.chosen_variant(&document, parameters)?;
    let scene = document.default_scene().or_else(|| document.scenes().next());
    let Some(scene) = scene else { return Err(error(path, bytes, "the file has no scene")) };
    imp.worlds = node_worlds(&scene);
    imp.decode_ahead(&document, &scene);
    for node in scene.nodes() {
        imp.node(&node, Mat4::IDENTITY, 0)?;
    }
    imp.finish()
}

/// Appends decoded data `out` (if any) to the file as a buffer named `name`, its bytes the
/// last of `buffers`.
pub(crate) fn append_buffer(
    json: &mut gltf::json::Root,
    buffers: &mut Vec<gltf::buffer::Data>,
    out: Vec<u8>,
    name: &str,
) {
    if out.is_empty() {
        return;
    }
    json.buffers.push(gltf::json::buffer::Buffer {
        byte_length: gltf::json::validation::USize64(out.len() as u64),
        name: Some(name.into()),
        uri: None,
        extensions: None,
        extras: Default::default(),
    });
    buffers.push(gltf::buffer::Data(out));
}

/// The file's JSON (not validated) and its binary chunk. Animations are not read: a file whose
/// animations the reader cannot parse (`KHR_animation_pointer`'s channels, which target no
/// node) is read without them; any other fault is the reader's error.
fn parse(bytes: &[u8]) -> Result<(gltf::json::Root, Option<Vec<u8>>), gltf::Error> {
    let error = match gltf::Gltf::from_slice_without_validation(bytes) {
        Ok(g) => return Ok((g.document.into_json(), g.blob)),
        Err(e) => e,
    };
    let (json, blob) = if bytes.starts_with(b"glTF") {
        let Ok(glb) = gltf::binary::Glb::from_slice(bytes) else { return Err(error) };
        (glb.json.into_owned(), glb.bin.map(|b| b.into_owned()))
    } else {
        (bytes.to_vec(), None)
    };
    let Ok(mut value) = serde_json::from_slice::<serde_json::Value>(&json) else { return Err(error) };
    if value.as_object_mut().and_then(|o| o.remove("animations")).is_none() {
        return Err(error);
    }
    serde_json::from_value(value).map(|root| (root, blob)).map_err(|_| error)
}

/// An error in a glTF file: JSON files are located by the first line naming the problem when
/// the message carries a position, binary files by the file alone.
fn error(path: &Path, bytes: &[u8], message: impl Into<String>) -> SceneError {
    let text = std::str::from_utf8(bytes).unwrap_or("");
    let message = message.into();
    // serde_json reports "line L column C"; point there when it does.
    let at = (|| {
        let rest = message.split("line ").nth(1)?;
        let mut it = rest.split(|c: char| !c.is_ascii_digit()).filter(|s| !s.is_empty());
        let (line, col) = (it.next()?.parse::<usize>().ok()?, it.next()?.parse::<usize>().ok()?);
        let start = text.split_inclusive('\n').take(line.saturating_sub(1)).map(str::len).sum::<usize>();
        Some(start + col.saturating_sub(1))
    })();
    SceneError::Syntax(Box::new(Diagnostic::at(path, text, at.unwrap_or(0)..at.unwrap_or(0) + 1, message)))
}

struct Importer<'a> {
    path: &'a Path,
    /// Every node's transform to the world (a skin's joints are placed by theirs).
    worlds: HashMap<usize, Mat4>,
    /// The file's textures and accessors, for those named by extensions the reader does not
    /// know.
    textures: Vec<gltf::Texture<'a>>,
    accessors: Vec<gltf::Accessor<'a>>,
    bytes: &'a [u8],
    buffers: Vec<gltf::buffer::Data>,
    base: &'a Path,
    scene: Scene,
    warnings: Warnings,
    materials: HashMap<Option<usize>, MaterialId>,
    meshes: HashMap<(usize, usize), Option<usize>>,
    images: HashMap<(usize, Decoding), Arc<ImageData>>,
    /// Images decoded ahead of the walk, on all threads, or why they could not be
    /// ([`Importer::decode_ahead`]): taken by [`Importer::image`] when the walk asks.
    decoded: HashMap<(usize, Decoding), Result<ImageData, String>>,
    camera: Option<CameraDesc>,
    bounds: Bounds3,
    /// The materials made of `KHR_materials_unlit` ones, whose emission vertex colours do not
    /// tint.
    unlit: std::collections::HashSet<MaterialId>,
    /// The file's materials, for `KHR_materials_variants`' mappings, which name them by index.
    all_materials: Vec<gltf::Material<'a>>,
    /// The `KHR_materials_variants` variant chosen (`-D variant=NAME`), by index.
    variant: Option<usize>,
}

impl<'a> Importer<'a> {
    fn warn(&mut self, message: impl Into<String>) {
        self.warnings.add(self.path, 0, message);
    }

    fn err(&self, message: impl Into<String>) -> SceneError {
        error(self.path, self.bytes, message)
    }

    /// Warns about the extensions the file uses that alhazen ignores (those it requires are
    /// read or refused before).
    fn extensions(&mut self, doc: &gltf::Document) {
        for e in doc.extensions_used() {
            if !KNOWN.contains(&e) {
                self.warn(format!("extension {e} is not supported; ignored"));
            }
        }
    }

    /// The `KHR_materials_variants` variant `-D variant=NAME` names (its index), or none; any
    /// other parameter, or a name the file does not have, is an error that lists the names.
    /// A file with variants rendered without one says which it has.
    fn chosen_variant(&mut self, doc: &gltf::Document, parameters: &[(String, String)]) -> R<Option<usize>> {
        let names: Vec<String> = doc
            .extension_value("KHR_materials_variants")
            .and_then(|v| v.get("variants"))
            .and_then(|v| v.as_array())
            .map(|all| {
                let name = |(i, v): (usize, &serde_json::Value)| match v.get("name").and_then(|n| n.as_str()) {
                    Some(n) => n.to_string(),
                    None => format!("variant {i}"),
                };
                all.iter().enumerate().map(name).collect()
            })
            .unwrap_or_default();
        let listed = || match names.is_empty() {
            true => "the file has no material variants".to_string(),
            false => format!(
                "its material variants are {}",
                names.iter().map(|n| format!("`{n}`")).collect::<Vec<_>>().join(", ")
            ),
        };
        let mut chosen = None;
        for (key, value) in parameters {
            if key != "variant" {
                return Err(self.err(format!(
                    "-D {key}=…: a glTF file takes one parameter, -D variant=NAME (KHR_materials_variants); {}",
                    listed()
                )));
            }
            let Some(i) = names.iter().position(|n| n == value) else {
                return Err(self.err(format!("-D variant={value}: no such material variant; {}", listed())));
            };
            chosen = Some(i);
        }
        if chosen.is_none() && !names.is_empty() {
            self.warn(format!("{}: its default materials are used (-D variant=NAME picks one)", listed()));
        }
        Ok(chosen)
    }

    /// The material the chosen variant maps `prim` to, if it maps it; a mapping that names no
    /// material of the file is warned about and the default kept.
    fn variant_material(&mut self, prim: &gltf::Primitive) -> Option<gltf::Material<'a>> {
        let variant = self.variant?;
        let mappings = prim.extension_value("KHR_materials_variants")?.get("mappings")?.as_array()?;
        let maps_it = |m: &&serde_json::Value| {
            let variants = m.get("variants").and_then(|v| v.as_array());
            variants.is_some_and(|v| v.iter().any(|x| x.as_u64() == Some(variant as u64)))
        };
        let named = mappings.iter().find(maps_it)?.get("material");
        let found =
            named.and_then(|m| m.as_u64()).and_then(|m| self.all_materials.get(usize::try_from(m).ok()?)).cloned();
        if found.is_none() {
            let named = named.map_or("nothing".to_string(), |m| m.to_string());
            self.warn(format!(
                "a KHR_materials_variants mapping names material {named}, which the file does not have: the default material is kept"
            ));
        }
        found
    }

    fn finish(mut self) -> R<Imported> {
        self.scene.camera = match self.camera.take() {
            Some(c) => c,
            None => {
                if self.bounds.is_empty() {
                    self.warn("the scene has no camera and no geometry: alhazen's default camera is used");
                } else {
                    self.warn("the scene has no camera: its bounds are framed from +z");
                }
                framing(self.bounds, self.scene.render.width as f64 / self.scene.render.height as f64)
                    .unwrap_or(self.scene.camera.clone())
            }
        };
        Ok(Imported { scene: self.scene, warnings: self.warnings.into_vec() })
    }

    fn node(&mut self, node: &gltf::Node, parent: Mat4, depth: usize) -> R<()> {
        if depth > 256 {
            return Err(self.err("nodes nested deeper than 256 levels (a cycle?)"));
        }
        let local = Mat4::from_cols_array_2d(&node.transform().matrix().map(|c| c.map(f64::from)));
        let world = parent * local;
        if let Some(mesh) = node.mesh() {
            let weights: Vec<f64> =
                node.weights().or(mesh.weights()).map_or(vec![], |w| w.iter().map(|&x| x as f64).collect());
            // A skinned mesh is placed by its joints alone (glTF ignores its node's transform).
            let skin = node.skin().map(|skin| self.joint_matrices(&skin)).transpose()?;
            let placed = if skin.is_some() { Mat4::IDENTITY } else { world };
            let posed = skin.is_some() || weights.iter().any(|w| *w != 0.0);
            let instances = match node.extension_value("EXT_mesh_gpu_instancing") {
                Some(_) if posed => {
                    self.warn(format!(
                        "node {}: instances of a posed mesh are not supported; one is drawn",
                        node.index()
                    ));
                    vec![placed]
                }
                Some(ext) => self.instances(ext, placed, node.index())?,
                None => vec![placed],
            };
            for placed in instances {
                match Transform::from_matrix(placed) {
                    Ok(t) if posed => self.posed_mesh(&mesh, t, &weights, skin.as_deref())?,
                    Ok(t) => self.mesh(&mesh, t)?,
                    Err(e) => self.warn(format!("node {} is left out: its transform {e}", node.index())),
                }
            }
        }
        if let Some(camera) = node.camera()
            && self.camera.is_none()
        {
            self.camera = Some(self.camera_of(&camera, world));
        }
        if let Some(light) = node.light() {
            self.light(&light, world);
        }
        for child in node.children() {
            self.node(&child, world, depth + 1)?;
        }
        Ok(())
    }

    // ---- geometry ----------------------------------------------------------------------------

    fn mesh(&mut self, mesh: &gltf::Mesh, t: Transform) -> R<()> {
        for prim in mesh.primitives() {
            let key = (mesh.index(), prim.index());
            let index = match self.meshes.get(&key) {
                Some(i) => *i,
                None => {
                    let i = self.primitive(mesh, &prim)?.map(|m| {
                        self.scene.meshes.push(Arc::new(m));
                        self.scene.meshes.len() - 1
                    });
                    self.meshes.insert(key, i);
                    i
                }
            };
            let Some(index) = index else { continue };
            self.place_mesh(mesh, &prim, index, t)?;
        }
        Ok(())
    }

    /// An object of scene mesh `index` (the primitive's) with its material, placed by `t`.
    fn place_mesh(&mut self, mesh: &gltf::Mesh, prim: &gltf::Primitive, index: usize, t: Transform) -> R<()> {
        let material = match self.variant_material(prim) {
            Some(m) => self.material(m)?,
            None => self.material(prim.material())?,
        };
        // glTF multiplies every base colour by COLOR_0 where a primitive has it.
        if !self.scene.meshes[index].colors.is_empty() {
            self.scene.materials[material as usize].vertex_colors = true;
            if self.unlit.contains(&material) {
                let name = &self.scene.materials[material as usize].name;
                let message =
                    format!("{name}: the vertex colours (COLOR_0) of an unlit material are not supported; ignored");
                self.warn(message);
            }
        }
        self.bounds = self.bounds.union(t.bounds(&self.scene.meshes[index].bounds()));
        self.scene.objects.push(Object {
            name: mesh.name().map(str::to_string),
            shape: Shape::Mesh { mesh: index, smooth: true },
            transform: t,
            material,
            mesh_materials: vec![],
        });
        Ok(())
    }

    /// `EXT_mesh_gpu_instancing`'s instances of a node placed by `world`: each
    /// `world · T · R · S` of its `TRANSLATION`, `ROTATION` (a unit quaternion) and `SCALE`
    /// (any of them absent: none).
    fn instances(&mut self, ext: &serde_json::Value, world: Mat4, node: usize) -> R<Vec<Mat4>> {
        let name = format!("node {node}");
        let attributes = ext.get("attributes");
        let accessor = |key: &str| -> R<Option<gltf::Accessor<'_>>> {
            match attributes.and_then(|a| a.get(key)) {
                None => Ok(None),
                Some(i) => {
                    i.as_u64().and_then(|i| self.accessors.get(i as usize)).cloned().map(Some).ok_or_else(|| {
                        self.err(format!(
                            "{name}: EXT_mesh_gpu_instancing's {key} must name one of the file's accessors"
                        ))
                    })
                }
            }
        };
        let (t, r, sc) = (accessor("TRANSLATION")?, accessor("ROTATION")?, accessor("SCALE")?);
        let translations = t.map(|a| self.integers::<3>(&a, &name, "TRANSLATION")).transpose()?;
        let rotations = r.map(|a| self.integers::<4>(&a, &name, "ROTATION")).transpose()?;
        let scales = sc.map(|a| self.integers::<3>(&a, &name, "SCALE")).transpose()?;
        let counts: Vec<usize> =
            [translations.as_ref().map(Vec::len), rotations.as_ref().map(Vec::len), scales.as_ref().map(Vec::len)]
                .into_iter()
                .flatten()
                .collect();
        let Some(&n) = counts.first() else {
            return Err(self.err(format!("{name}: EXT_mesh_gpu_instancing has no TRANSLATION, ROTATION or SCALE")));
        };
        if counts.iter().any(|&c| c != n) {
            return Err(
                self.err(format!("{name}: EXT_mesh_gpu_instancing's attributes must have as many elements each"))
            );
        }
        (0..n)
            .map(|i| {
                let t = translations.as_ref().map_or(Vec3::ZERO, |v| Vec3::from_array(v[i]));
                let q = rotations.as_ref().map_or(Quat::IDENTITY, |v| Quat::from_array(v[i]));
                let s = scales.as_ref().map_or(Vec3::ONE, |v| Vec3::from_array(v[i]));
                if !(t.is_finite() && s.is_finite() && q.is_finite() && (q.length() - 1.0).abs() < 1e-3) {
                    return Err(self.err(format!(
                        "{name}: instance {i} has a non-finite place or a rotation that is not a unit quaternion"
                    )));
                }
                Ok(world * Mat4::from_scale_rotation_translation(s, q.normalize(), t))
            })
            .collect()
    }

    /// A mesh as its node shows it: each primitive's vertices moved by its morph targets
    /// (`weights`) and then by its skin (`joints`: each joint's world transform times its
    /// inverse bind matrix), a mesh of its own placed by `t`.
    fn posed_mesh(&mut self, mesh: &gltf::Mesh, t: Transform, weights: &[f64], joints: Option<&[Mat4]>) -> R<()> {
        for prim in mesh.primitives() {
            let Some(mut m) = self.primitive(mesh, &prim)? else { continue };
            let name = format!("mesh {} primitive {}", mesh.index(), prim.index());
            self.morph(&prim, &mut m, weights, &name)?;
            if let Some(joints) = joints {
                self.skin(&prim, &mut m, joints, &name)?;
            }
            m.validate().map_err(|e| self.err(format!("{name} as posed: {e}")))?;
            self.scene.meshes.push(Arc::new(m));
            let index = self.scene.meshes.len() - 1;
            self.place_mesh(mesh, &prim, index, t)?;
        }
        Ok(())
    }

    /// Moves `m`'s positions and normals by the primitive's morph targets times `weights`
    /// (glTF's `p + Σ wᵢ·Δpᵢ`).
    fn morph(&mut self, prim: &gltf::Primitive, m: &mut TriangleMesh, weights: &[f64], name: &str) -> R<()> {
        let targets: Vec<_> = prim.morph_targets().collect();
        if weights.iter().all(|w| *w == 0.0) {
            return Ok(());
        }
        if weights.len() > targets.len() {
            return Err(self.err(format!("{name}: {} morph weights for {} targets", weights.len(), targets.len())));
        }
        for (target, &w) in targets.iter().zip(weights).filter(|(_, w)| **w != 0.0) {
            for (accessor, values) in [(target.positions(), &mut m.positions), (target.normals(), &mut m.normals)] {
                let (Some(a), false) = (accessor, values.is_empty()) else { continue };
                let deltas = self.vec3s(&a, name, "morph target")?;
                if deltas.len() != values.len() {
                    return Err(self.err(format!(
                        "{name}: a morph target moves {} of its {} vertices",
                        deltas.len(),
                        values.len()
                    )));
                }
                values.iter_mut().zip(&deltas).for_each(|(v, d)| *v += *d * w);
            }
        }
        m.normals.iter_mut().for_each(|n| *n = n.normalize_or_zero());
        Ok(())
    }

    /// Moves `m`'s vertices by linear blend skinning: each by its joints' matrices
    /// (`JOINTS_n`, `WEIGHTS_n`, sets 0 and 1) weighted, normals by the blend's inverse
    /// transpose.
    fn skin(&mut self, prim: &gltf::Primitive, m: &mut TriangleMesh, joints: &[Mat4], name: &str) -> R<()> {
        let mut blends = vec![Mat4::ZERO; m.positions.len()];
        let mut any = false;
        for set in 0..2 {
            let (Some(j), Some(w)) = (prim.get(&gltf::Semantic::Joints(set)), prim.get(&gltf::Semantic::Weights(set)))
            else {
                continue;
            };
            let (j, w) = (self.integers::<4>(&j, name, "JOINTS")?, self.integers::<4>(&w, name, "WEIGHTS")?);
            if j.len() != blends.len() || w.len() != blends.len() {
                return Err(
                    self.err(format!("{name}: its JOINTS_{set} and WEIGHTS_{set} must have one element per vertex"))
                );
            }
            for ((blend, j), w) in blends.iter_mut().zip(&j).zip(&w) {
                for k in 0..4 {
                    let joint = joints.get(j[k] as usize).ok_or_else(|| {
                        self.err(format!("{name}: joint {} is not one of its skin's {}", j[k], joints.len()))
                    })?;
                    if !(w[k].is_finite() && w[k] >= 0.0) {
                        return Err(self.err(format!("{name}: its skin weights must be finite and ≥ 0")));
                    }
                    *blend += *joint * w[k];
                }
            }
            any = true;
        }
        if !any {
            return Err(self.err(format!("{name}: its node has a skin but the primitive no JOINTS_0 and WEIGHTS_0")));
        }
        for (i, blend) in blends.iter().enumerate() {
            // Weights that do not sum to 1 are normalised; none leaves the vertex where it is.
            let total = blend.row(3).w;
            let blend = if total > 0.0 { *blend * (1.0 / total) } else { Mat4::IDENTITY };
            m.positions[i] = blend.transform_point3(m.positions[i]);
            if let Some(n) = m.normals.get_mut(i) {
                let linear = alhazen_math::Mat3::from_mat4(blend);
                let normals = if linear.determinant() != 0.0 { linear.inverse().transpose() } else { linear };
                *n = (normals * *n).normalize_or_zero();
            }
        }
        Ok(())
    }

    /// A skin's joint matrices: each joint node's world transform times its inverse bind
    /// matrix (identity where the skin has none).
    fn joint_matrices(&mut self, skin: &gltf::Skin) -> R<Vec<Mat4>> {
        let name = format!("skin {}", skin.index());
        let inverse_binds = match skin.inverse_bind_matrices() {
            Some(a) => self.integers::<16>(&a, &name, "inverseBindMatrices")?,
            None => vec![Mat4::IDENTITY.to_cols_array(); skin.joints().count()],
        };
        if inverse_binds.len() < skin.joints().count() {
            return Err(self.err(format!("{name}: fewer inverse bind matrices than joints")));
        }
        skin.joints()
            .zip(inverse_binds)
            .map(|(joint, ib)| match self.worlds.get(&joint.index()) {
                Some(world) => Ok(*world * Mat4::from_cols_array(&ib)),
                None => Err(self.err(format!("{name}: joint node {} is not in the scene", joint.index()))),
            })
            .collect()
    }

    /// The `VEC3` elements of accessor `a`, floats or quantized integers.
    fn vec3s(&self, a: &gltf::Accessor, name: &str, what: &str) -> R<Vec<Vec3>> {
        if a.data_type() != DataType::F32 || a.sparse().is_none() {
            return Ok(self.integers::<3>(a, name, what)?.into_iter().map(Vec3::from_array).collect());
        }
        let buffers = &self.buffers;
        let iter = gltf::accessor::Iter::<[f32; 3]>::new(a.clone(), |b| buffers.get(b.index()).map(|d| &d.0[..]));
        let values = iter.ok_or_else(|| self.err(format!("{name}: its {what} accessor cannot be read")))?;
        Ok(values.map(|v| Vec3::new(v[0] as f64, v[1] as f64, v[2] as f64)).collect())
    }

    /// A primitive's triangles; `None` (with a warning) for points and lines.
    fn primitive(&mut self, mesh: &gltf::Mesh, prim: &gltf::Primitive) -> R<Option<TriangleMesh>> {
        let name = format!(
            "mesh {} primitive {}",
            mesh.name().map_or(mesh.index().to_string(), |n| format!("\"{n}\"")),
            prim.index()
        );
        if matches!(prim.mode(), Mode::Points | Mode::Lines | Mode::LineLoop | Mode::LineStrip) {
            self.warn(format!("{name}: points and lines are not rendered; left out"));
            return Ok(None);
        }
        let buffers = &self.buffers;
        let reader = prim.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
        // Integer attributes (KHR_mesh_quantization) are decoded here: the reader would take
        // their bytes for floats.
        let quantized = |sem: gltf::Semantic| prim.get(&sem).filter(|a| a.data_type() != DataType::F32);
        let positions: Vec<Vec3> = match quantized(gltf::Semantic::Positions) {
            Some(a) => self.integers::<3>(&a, &name, "POSITION")?.into_iter().map(Vec3::from_array).collect(),
            None => reader
                .read_positions()
                .ok_or_else(|| self.err(format!("{name} has no POSITION attribute")))?
                .map(|p| Vec3::new(p[0] as f64, p[1] as f64, p[2] as f64))
                .collect(),
        };
        let normals: Vec<Vec3> = match quantized(gltf::Semantic::Normals) {
            Some(a) => self.integers::<3>(&a, &name, "NORMAL")?.into_iter().map(Vec3::from_array).collect(),
            None => reader
                .read_normals()
                .map(|n| n.map(|v| Vec3::new(v[0] as f64, v[1] as f64, v[2] as f64)).collect())
                .unwrap_or_default(),
        };
        let uvs: Vec<Vec2> = match quantized(gltf::Semantic::TexCoords(0)) {
            Some(a) => {
                self.integers::<2>(&a, &name, "TEXCOORD_0")?.into_iter().map(|[u, v]| Vec2::new(u, 1.0 - v)).collect()
            }
            None => reader
                .read_tex_coords(0)
                .map(|t| t.into_f32().map(|v| Vec2::new(v[0] as f64, 1.0 - v[1] as f64)).collect())
                .unwrap_or_default(),
        };
        let rgba: Option<Vec<[f32; 4]>> = reader.read_colors(0).map(|c| c.into_rgba_f32().collect());
        let indices: Vec<u32> = match reader.read_indices() {
            Some(i) => i.into_u32().collect(),
            None => (0..positions.len() as u32).collect(),
        };
        // The reader stops silently at the end of a too-short buffer view: refuse such files.
        let expected = |sem: &gltf::Semantic| prim.get(sem).map_or(0, |a| a.count());
        let counts = [
            ("POSITION", positions.len(), expected(&gltf::Semantic::Positions)),
            ("NORMAL", normals.len(), expected(&gltf::Semantic::Normals)),
            ("TEXCOORD_0", uvs.len(), expected(&gltf::Semantic::TexCoords(0))),
            ("indices", indices.len(), prim.indices().map_or(indices.len(), |a| a.count())),
        ];
        for (what, got, want) in counts {
            if got != want {
                return Err(
                    self.err(format!("{name}: its {what} accessor has {want} elements but its buffer holds {got}"))
                );
            }
        }
        if let Some(&bad) = indices.iter().find(|&&i| i as usize >= positions.len()) {
            return Err(self.err(format!("{name}: index {bad} is not one of its {} vertices", positions.len())));
        }
        let triangles: Vec<[u32; 3]> = match prim.mode() {
            Mode::TriangleStrip => (2..indices.len())
                .map(|k| {
                    if k % 2 == 0 {
                        [indices[k - 2], indices[k - 1], indices[k]]
                    } else {
                        [indices[k - 1], indices[k - 2], indices[k]]
                    }
                })
                .collect(),
            Mode::TriangleFan => (2..indices.len()).map(|k| [indices[0], indices[k - 1], indices[k]]).collect(),
            _ => indices.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
        };
        let colors = self.vertex_colors(rgba, prim, &name)?;
        let mut m = TriangleMesh { positions, normals, uvs, colors, triangles, ..Default::default() };
        if m.normals.iter().any(|n| !n.is_finite()) {
            self.warn(format!("{name} has non-finite normals; they are recomputed from the faces"));
            m.normals.clear();
        }
        // Degenerate triangles (repeated indices) carry nothing; glTF allows them.
        m.triangles.retain(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2]);
        if m.triangles.is_empty() {
            self.warn(format!("{name} has no triangles; left out"));
            return Ok(None);
        }
        m.validate().map_err(|e| self.err(format!("{name}: {e}")))?;
        Ok(Some(m))
    }

    /// The `N`-component elements of accessor `a` of integer components (KHR_mesh_quantization:
    /// bytes and shorts, signed or not, normalised to [0, 1] or [−1, 1] where the accessor says,
    /// else their values), read through its buffer view's stride. Sparse ones, and views that
    /// stop short, are refused.
    fn integers<const N: usize>(&self, a: &gltf::Accessor, name: &str, what: &str) -> R<Vec<[f64; N]>> {
        let bad = |why: &str| self.err(format!("{name}: its {what} accessor {why}"));
        if a.dimensions().multiplicity() != N {
            return Err(bad(&format!("must have {N} components")));
        }
        if a.sparse().is_some() {
            return Err(bad("is sparse and quantized, which alhazen cannot read"));
        }
        let view = a.view().ok_or_else(|| bad("has no buffer view"))?;
        let data = self.buffers.get(view.buffer().index()).map(|d| &d.0[..]).unwrap_or_default();
        let size = a.data_type().size();
        let stride = view.stride().unwrap_or(size * N);
        let start = view.offset() + a.offset();
        let end = match a.count() {
            0 => start,
            n => start + stride * (n - 1) + size * N,
        };
        if end > view.offset() + view.length() || end > data.len() {
            return Err(bad(&format!("has {} elements but its buffer holds fewer", a.count())));
        }
        let normalized = a.normalized();
        let component = |at: usize| -> f64 {
            let b = &data[at..at + size];
            match (a.data_type(), normalized) {
                (DataType::I8, false) => b[0] as i8 as f64,
                (DataType::I8, true) => (b[0] as i8 as f64 / 127.0).max(-1.0),
                (DataType::U8, false) => b[0] as f64,
                (DataType::U8, true) => b[0] as f64 / 255.0,
                (DataType::I16, false) => i16::from_le_bytes([b[0], b[1]]) as f64,
                (DataType::I16, true) => (i16::from_le_bytes([b[0], b[1]]) as f64 / 32767.0).max(-1.0),
                (DataType::U16, false) => u16::from_le_bytes([b[0], b[1]]) as f64,
                (DataType::U16, true) => u16::from_le_bytes([b[0], b[1]]) as f64 / 65535.0,
                (DataType::U32, _) => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
                (DataType::F32, _) => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            }
        };
        Ok((0..a.count()).map(|i| std::array::from_fn(|k| component(start + i * stride + k * size))).collect())
    }

    /// `COLOR_0` (read as RGBA, integers normalised as the accessor says) as linear RGB, which
    /// multiplies the base colour; empty without it. Its alpha is left out, with a warning
    /// where it is not 1.
    fn vertex_colors(&mut self, rgba: Option<Vec<[f32; 4]>>, prim: &gltf::Primitive, name: &str) -> R<Vec<Vec3>> {
        let Some(rgba) = rgba else { return Ok(vec![]) };
        let want = prim.get(&gltf::Semantic::Colors(0)).map_or(0, |a| a.count());
        if rgba.len() != want {
            return Err(self
                .err(format!("{name}: its COLOR_0 accessor has {want} elements but its buffer holds {}", rgba.len())));
        }
        if rgba.iter().any(|c| c[3] != 1.0) {
            self.warn(format!("{name}: the alpha of its vertex colours (COLOR_0) is not supported; ignored"));
        }
        let colors: Vec<Vec3> = rgba.iter().map(|c| Vec3::new(c[0] as f64, c[1] as f64, c[2] as f64)).collect();
        if colors.iter().any(|c| !(c.is_finite() && c.min_element() >= 0.0)) {
            return Err(self.err(format!("{name}: its vertex colours (COLOR_0) must be finite and ≥ 0")));
        }
        Ok(colors)
    }

    // ---- materials -----------------------------------------------------------------------------

    fn material(&mut self, material: gltf::Material) -> R<MaterialId> {
        if let Some(&id) = self.materials.get(&material.index()) {
            return Ok(id);
        }
        let name = material
            .name()
            .map_or_else(|| format!("material {}", material.index().map_or(-1, |i| i as i64)), str::to_string);
        let pbr = material.pbr_metallic_roughness();
        let c = pbr.base_color_factor();
        let factor = rgb([c[0], c[1], c[2]]);
        let (base, base_mean) = match pbr.base_color_texture() {
            Some(info) => {
                let (scale, offset, rotation) = self.texture_placement(&info, &name)?;
                let img = self.image(&info.texture(), Decoding::Srgb)?;
                let img = wrapped(scaled(img, factor), &info.texture());
                let mean = alhazen_scene::texture::image_mean(&img);
                self.scene.images.push(img);
                (Texture::Image { image: self.scene.images.len() - 1, scale, offset, rotation }, mean)
            }
            None => (Texture::Solid(factor), factor),
        };
        if material.extension_value("KHR_materials_unlit").is_some() {
            return self.unlit(&material, &name, base, base_mean, c[3] as f64);
        }
        // The emissive texture is read per point, its factor and strength multiplied in.
        let strength = material.emissive_strength().unwrap_or(1.0) as f64;
        let mut emission = rgb(material.emissive_factor()) * strength;
        if !(emission.is_finite() && emission.min_element() >= 0.0) {
            return Err(self.err(format!("{name}: the emissive factor and strength must be finite and ≥ 0")));
        }
        let mut emission_texture = None;
        if let Some(info) = material.emissive_texture()
            && emission != Vec3::ZERO
        {
            let (scale, offset, rotation) = self.texture_placement(&info, &name)?;
            let img = wrapped(scaled(self.image(&info.texture(), Decoding::Srgb)?, emission), &info.texture());
            emission = alhazen_scene::texture::image_mean(&img);
            self.scene.images.push(img);
            emission_texture = Some(Texture::Image { image: self.scene.images.len() - 1, scale, offset, rotation });
        }
        let transmission = material.transmission().map_or(0.0, |t| t.transmission_factor() as f64);
        // Where the glass is: the factor times the texture's red channel, per point.
        let transmission_map = match material.transmission().and_then(|t| t.transmission_texture()) {
            Some(info) if transmission > 0.0 => {
                let (scale, offset, rotation) = self.texture_placement(&info, &name)?;
                let image = wrapped(self.image(&info.texture(), Decoding::Red)?, &info.texture());
                self.scene.images.push(image);
                Some(Texture::Image { image: self.scene.images.len() - 1, scale, offset, rotation })
            }
            _ => None,
        };
        // What the glass keeps at each crossing: the base colour's square root (Cycles', Disney's).
        let glass_tint = match &base {
            Texture::Image { image, scale, offset, rotation } if transmission > 0.0 => {
                let root = self.scene.images[*image].channels_mapped(|_, v| v.max(0.0).sqrt());
                self.scene.images.push(Arc::new(root));
                Texture::Image {
                    image: self.scene.images.len() - 1,
                    scale: *scale,
                    offset: *offset,
                    rotation: *rotation,
                }
            }
            _ => Texture::Solid(base_mean.max(Vec3::ZERO).powf(0.5)),
        };
        let ior = material.ior().unwrap_or(1.5) as f64;
        let (mut metallic, mut roughness) = (pbr.metallic_factor() as f64, pbr.roughness_factor() as f64);
        // The metallic-roughness texture is read per point (roughness in green, metalness in
        // blue), except under transmission, whose glass the model mixes in by one weight.
        let mut map = None;
        if let Some(info) = pbr.metallic_roughness_texture() {
            let image = self.image(&info.texture(), Decoding::Linear)?;
            if transmission > 0.0 {
                let mean = alhazen_scene::texture::image_mean(&image);
                (roughness, metallic) = (roughness * mean.y, metallic * mean.z);
                self.warn(format!(
                    "{name}: with transmission, the metallic-roughness texture is replaced by its mean (metallic {metallic:.3}, roughness {roughness:.3})"
                ));
            } else {
                let (scale, offset, rotation) = self.texture_placement(&info, &name)?;
                self.scene.images.push(wrapped(image, &info.texture()));
                map = Some(Texture::Image { image: self.scene.images.len() - 1, scale, offset, rotation });
            }
        }
        let bump = match material.normal_texture() {
            Some(nt) => {
                // The normal texture's info has no typed transform: read from its JSON.
                let transform = nt.extension_value("KHR_texture_transform").map(json_transform);
                let (scale, offset, rotation) = self.placement(nt.tex_coord(), transform, &name)?;
                let image = wrapped(self.image(&nt.texture(), Decoding::Linear)?, &nt.texture());
                self.scene.images.push(image);
                let map = Texture::Image { image: self.scene.images.len() - 1, scale, offset, rotation };
                Some(Bump { height: nt.scale() as f64, pattern: BumpPattern::NormalMap { map } })
            }
            None => None,
        };
        let placement = match base {
            Texture::Image { scale, offset, rotation, .. } => (scale, offset, rotation),
            _ => (Vec2::ONE, Vec2::ZERO, 0.0),
        };
        let alpha = self.cut_out(&material, c[3] as f64, placement)?;
        let iridescence = self.iridescence(&material, &name)?;
        // Under transmission the film is the glass's (on its outside face).
        let (iridescence, glass_film) = if transmission > 0.0 { (None, iridescence) } else { (iridescence, None) };
        if glass_film.is_some() && transmission < 1.0 {
            self.warn(format!(
                "{name}: KHR_materials_iridescence under partial transmission is rendered on the glass only"
            ));
        }
        let (metallic, roughness) = (metallic.clamp(0.0, 1.0), roughness.clamp(0.0, 1.0));
        // Per point where the map or a textured metal's colour varies (glTF's metal takes each
        // texel's base colour), else the constant mix (and its glass under transmission).
        let textured_metal = metallic > 0.0 && transmission <= 0.0 && !matches!(base, Texture::Solid(_));
        let mut lobes = self.lobes(&material, ior, &name);
        let translucency_map;
        let translucency_color_map;
        (lobes.translucency, translucency_map, translucency_color_map) = self.translucency(&material, &name)?;
        let mut anisotropy_map;
        (lobes.anisotropy, anisotropy_map) = self.anisotropy(&material, &name)?;
        if lobes.anisotropy.is_anisotropic() && transmission > 0.0 {
            self.warn(format!("{name}: KHR_materials_anisotropy under transmission is not supported; ignored"));
            (lobes.anisotropy, anisotropy_map) = (Anisotropy::default(), None);
        }
        // Stretched facets turn with the surface's tangent: read per point.
        let (specular_map, specular_color_map) = self.specular_maps(&material, transmission, &name)?;
        let per_point = map.is_some()
            || textured_metal
            || lobes.anisotropy.is_anisotropic()
            || iridescence.is_some()
            || specular_map.is_some()
            || specular_color_map.is_some()
            || translucency_map.is_some()
            || translucency_color_map.is_some();
        let bsdf = if per_point {
            let MetalRoughness { ior, specular, multiscatter, anisotropy, translucency } = lobes;
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
            }
        } else {
            let bsdf = common::metal_rough(
                base,
                base_mean,
                metallic,
                roughness,
                (ior, lobes),
                common::Glass {
                    weight: transmission.clamp(0.0, 1.0),
                    map: transmission_map,
                    tint: glass_tint,
                    film: glass_film,
                },
            );
            match self.dispersion(&material, ior, &name)? {
                Some(cauchy) => glass_of_index(bsdf, cauchy),
                None => bsdf,
            }
        };
        let bsdf = self.sheen(&material, bsdf, &name)?;
        let bsdf = self.clearcoat(&material, bsdf, &name)?;
        let refracts = bsdf.refracts();
        let mut m = alhazen_scene::Material::from_bsdf(&name, bsdf);
        (m.emission, m.emission_texture) = (emission, emission_texture);
        if refracts {
            m.absorption = self.volume(&material, &name)?;
        }
        m.bump = bump;
        m.alpha = alpha;
        let id = common::add_material(&mut self.scene, m);
        self.materials.insert(material.index(), id);
        Ok(id)
    }

    /// `KHR_materials_unlit`: the base colour shown as it is. A path tracer has no surface
    /// that lighting leaves alone, so the material is an emitter of radiance equal to its base
    /// colour (factor times texture, read per point) that reflects nothing: a camera ray that
    /// meets it sees exactly the base colour, as glTF's unlit shading says, and a scene of unlit
    /// materials (baked lighting) renders as it was baked. Blender's importer makes the same
    /// emitter visible to camera rays only; here it also lights its neighbours and casts shadows.
    /// Its other properties are ignored, as the extension says; its alpha cuts out as any
    /// material's.
    fn unlit(&mut self, material: &gltf::Material, name: &str, base: Texture, mean: Vec3, alpha: f64) -> R<MaterialId> {
        let placement = match base {
            Texture::Image { scale, offset, rotation, .. } => (scale, offset, rotation),
            _ => (Vec2::ONE, Vec2::ZERO, 0.0),
        };
        let alpha = self.cut_out(material, alpha, placement)?;
        let black = BsdfDesc::Lambert { albedo: Texture::Solid(Vec3::ZERO) };
        let mut m = alhazen_scene::Material::from_bsdf(name, black);
        m.emission = mean;
        m.emission_texture = matches!(base, Texture::Image { .. }).then_some(base);
        m.alpha = alpha;
        let id = common::add_material(&mut self.scene, m);
        self.materials.insert(material.index(), id);
        self.unlit.insert(id);
        Ok(id)
    }

    /// `KHR_materials_anisotropy`'s facets stretched along a direction of brushing:
    /// `anisotropyStrength` `s` stretches them to `α_t = α + (1 − α)s²` along the tangent turned
    /// by `anisotropyRotation` (radians, towards the bitangent), `α_b = α` across it; its
    /// texture (linear, placed by its own `KHR_texture_transform` and sampler) turns the
    /// direction further and scales the strength per point.
    fn anisotropy(&mut self, material: &gltf::Material, name: &str) -> R<(Anisotropy, Option<Texture>)> {
        let Some(a) = material.extension_value("KHR_materials_anisotropy") else {
            return Ok((Anisotropy::default(), None));
        };
        let number = |key: &str, range: std::ops::RangeInclusive<f64>| match a.get(key) {
            None => Some(0.0),
            Some(x) => x.as_f64().filter(|x| range.contains(x)),
        };
        let turn = std::f64::consts::TAU;
        let (Some(strength), Some(rotation)) =
            (number("anisotropyStrength", 0.0..=1.0), number("anisotropyRotation", -1e6..=1e6))
        else {
            return Err(self.err(format!(
                "{name}: KHR_materials_anisotropy's anisotropyStrength must be a number within [0, 1] and anisotropyRotation a number of radians"
            )));
        };
        // Within (−π, π]: a turn's worth more is the same direction.
        let rotation = rotation - turn * (rotation / turn).round();
        let anisotropy = Anisotropy { strength, rotation, model: AnisotropyModel::Gltf };
        let map = match a.get("anisotropyTexture") {
            Some(info) if strength > 0.0 => {
                Some(self.texture_of_info(info, name, "anisotropyTexture", Decoding::Linear)?)
            }
            _ => None,
        };
        Ok((anisotropy, map))
    }

    /// `KHR_materials_iridescence`'s thin film: weight `iridescenceFactor` (times
    /// `iridescenceTexture`'s red), index `iridescenceIOR`, thickness
    /// `iridescenceThicknessMaximum` nm, or from the minimum to it by
    /// `iridescenceThicknessTexture`'s green (both read linearly); under a clear coat the film's
    /// outside is the coat's index, 1.5. None without it and at a factor of 0.
    fn iridescence(&mut self, material: &gltf::Material, name: &str) -> R<Option<Box<Iridescence>>> {
        let Some(e) = material.extension_value("KHR_materials_iridescence") else { return Ok(None) };
        let number = |key: &str, default: f64, range: std::ops::RangeInclusive<f64>| match e.get(key) {
            None => Some(default),
            Some(x) => x.as_f64().filter(|x| range.contains(x)),
        };
        let (Some(factor), Some(ior), Some(thin), Some(thick)) = (
            number("iridescenceFactor", 0.0, 0.0..=1.0),
            number("iridescenceIOR", 1.3, 1.0..=10.0),
            number("iridescenceThicknessMinimum", 100.0, 0.0..=1e5),
            number("iridescenceThicknessMaximum", 400.0, 0.0..=1e5),
        ) else {
            return Err(self.err(format!(
                "{name}: KHR_materials_iridescence needs an iridescenceFactor within [0, 1], an iridescenceIOR within [1, 10] and thicknesses within [0, 100000] nm"
            )));
        };
        if factor == 0.0 {
            return Ok(None);
        }
        let map = |s: &mut Self, key: &str| match e.get(key) {
            Some(info) => s.texture_of_info(info, name, key, Decoding::Linear).map(Some),
            None => Ok(None),
        };
        let factor_map = map(self, "iridescenceTexture")?;
        let thickness_map = map(self, "iridescenceThicknessTexture")?;
        let coated = material
            .extension_value("KHR_materials_clearcoat")
            .and_then(|c| c.get("clearcoatFactor").and_then(|f| f.as_f64()))
            .is_some_and(|f| f > 0.0);
        let outside = if coated { 1.5 } else { 1.0 };
        Ok(Some(Box::new(Iridescence { factor, ior, thickness: [thin, thick], outside, factor_map, thickness_map })))
    }

    /// The image texture a JSON `textureInfo` of an extension names (`index`, `texCoord`,
    /// `KHR_texture_transform`), decoded as `decoding` says, placed and wrapped as glTF says.
    fn texture_of_info(&mut self, info: &serde_json::Value, name: &str, what: &str, decoding: Decoding) -> R<Texture> {
        let index = info.get("index").and_then(|i| i.as_u64());
        let tex_coord = info.get("texCoord").map_or(Some(0), |t| t.as_u64());
        let (Some(texture), Some(tex_coord)) =
            (index.and_then(|i| self.textures.get(i as usize)).cloned(), tex_coord.and_then(|t| u32::try_from(t).ok()))
        else {
            return Err(self.err(format!("{name}: {what} must name one of the file's textures")));
        };
        let transform = info.get("extensions").and_then(|e| e.get("KHR_texture_transform")).map(json_transform);
        let (scale, offset, rotation) = self.placement(tex_coord, transform, name)?;
        let image = wrapped(self.image(&texture, decoding)?, &texture);
        self.scene.images.push(image);
        Ok(Texture::Image { image: self.scene.images.len() - 1, scale, offset, rotation })
    }

    /// `KHR_materials_dispersion`'s index of refraction by wavelength, Cauchy's two terms
    /// through `n_d` = `ior` at 587.6 nm with the Abbe number `V_d = 20/dispersion`:
    /// `n(λ) = n_d + (n_d − 1)/V_d · (523 655/λ² − 1.5168)` (λ in nm). None without it or at 0
    /// (no dispersion). A dispersion so strong that the index would fall below 1 within the
    /// visible range (360–830 nm; glTF clamps it at 1 there) is lowered to the strongest that
    /// keeps it above, with a warning.
    fn dispersion(&mut self, material: &gltf::Material, ior: f64, name: &str) -> R<Option<Ior>> {
        let Some(d) = material.extension_value("KHR_materials_dispersion") else { return Ok(None) };
        let dispersion = match d.get("dispersion") {
            None => 0.0,
            Some(x) => x.as_f64().filter(|x| (0.0..=1e6).contains(x)).ok_or_else(|| {
                self.err(format!("{name}: KHR_materials_dispersion's dispersion must be a number ≥ 0"))
            })?,
        };
        if dispersion == 0.0 || ior <= 1.0 {
            return Ok(None);
        }
        // n(λ) falls with λ: its least is at the longest wavelength.
        let reach = 1.5168 - 523_655.0 / (alhazen_math::cie::LAMBDA_MAX * alhazen_math::cie::LAMBDA_MAX);
        let strongest = 20.0 * 0.999 / reach;
        let dispersion = if dispersion > strongest {
            self.warn(format!(
                "{name}: KHR_materials_dispersion's dispersion {dispersion} would take the index below 1; {strongest:.3} is used"
            ));
            strongest
        } else {
            dispersion
        };
        let k = (ior - 1.0) * dispersion / 20.0;
        // Cauchy's `A + B/λ²` with λ in micrometres.
        Ok(Some(Ior::Cauchy { a: ior - 1.5168 * k, b: 0.523655 * k }))
    }

    /// `bsdf` under `KHR_materials_sheen`'s fibres: of colour `sheenColorFactor` (times
    /// `sheenColorTexture`, sRGB), roughness `sheenRoughnessFactor` (times
    /// `sheenRoughnessTexture`'s alpha; `α = r²`); none where the colour factor is black.
    fn sheen(&mut self, material: &gltf::Material, bsdf: BsdfDesc, name: &str) -> R<BsdfDesc> {
        let Some(e) = material.extension_value("KHR_materials_sheen") else { return Ok(bsdf) };
        let color = unit_rgb(e.get("sheenColorFactor"), Vec3::ZERO);
        let roughness = e.get("sheenRoughnessFactor").map_or(Some(0.0), unit);
        let (Some(color), Some(roughness)) = (color, roughness) else {
            return Err(self.err(format!(
                "{name}: KHR_materials_sheen needs a sheenColorFactor of three numbers and a sheenRoughnessFactor, within [0, 1]"
            )));
        };
        if color == Vec3::ZERO {
            return Ok(bsdf);
        }
        // The colour texture is sRGB, times the factor; the roughness is the texture's alpha.
        let color = match e.get("sheenColorTexture") {
            None => Texture::Solid(color),
            Some(info) => match self.texture_of_info(info, name, "sheenColorTexture", Decoding::Srgb)? {
                Texture::Image { image, scale, offset, rotation } => {
                    let factored = scaled(self.scene.images[image].clone(), color);
                    self.scene.images[image] = factored;
                    Texture::Image { image, scale, offset, rotation }
                }
                other => other,
            },
        };
        let roughness_map = match e.get("sheenRoughnessTexture") {
            None => None,
            Some(info) => Some(self.texture_of_info(info, name, "sheenRoughnessTexture", Decoding::Alpha)?),
        };
        Ok(BsdfDesc::Sheened { base: Box::new(bsdf), color, roughness, roughness_map })
    }

    /// `bsdf` under `KHR_materials_clearcoat`'s coat: of weight `clearcoatFactor`, GGX facets
    /// of `α = clearcoatRoughnessFactor²` (at least 0.01, a clear coat), index 1.5 (glTF's);
    /// none where the factor is 0. `clearcoatTexture`'s red channel multiplies the weight and
    /// `clearcoatRoughnessTexture`'s green the roughness, per point (read linearly); its normal
    /// map is left out (warning).
    fn clearcoat(&mut self, material: &gltf::Material, bsdf: BsdfDesc, name: &str) -> R<BsdfDesc> {
        let Some(c) = material.extension_value("KHR_materials_clearcoat") else { return Ok(bsdf) };
        let number = |key: &str| match c.get(key) {
            None => Some(0.0),
            Some(x) => x.as_f64().filter(|x| (0.0..=1.0).contains(x)),
        };
        let (Some(weight), Some(roughness)) = (number("clearcoatFactor"), number("clearcoatRoughnessFactor")) else {
            return Err(self.err(format!(
                "{name}: KHR_materials_clearcoat's clearcoatFactor and clearcoatRoughnessFactor must be numbers within [0, 1]"
            )));
        };
        if c.get("clearcoatNormalTexture").is_some() {
            self.warn(format!(
                "{name}: KHR_materials_clearcoat's normal texture is not supported; the surface's normal is used"
            ));
        }
        if weight == 0.0 {
            return Ok(bsdf);
        }
        let mut map = |key: &str| match c.get(key) {
            Some(info) => self.texture_of_info(info, name, key, Decoding::Linear).map(Some),
            None => Ok(None),
        };
        let weight_map = map("clearcoatTexture")?;
        let roughness_map = map("clearcoatRoughnessTexture")?;
        let alpha = (roughness * roughness).max(0.01);
        let facets = alhazen_scene::bsdf::ggx(alpha, alpha);
        Ok(BsdfDesc::Coated { base: Box::new(bsdf), weight, facets, ior: 1.5, weight_map, roughness_map })
    }

    /// The absorption per unit length of a transmitting material's inside under
    /// `KHR_materials_volume`: `σ = −ln(attenuationColor) / attenuationDistance` (Beer–Lambert:
    /// light keeps the colour after that distance). None (zero) without the extension, for a
    /// thin-walled material (`thicknessFactor` 0: no inside) or an infinite distance. The
    /// thickness itself (a rasteriser's stand-in for the path length) is not needed: the
    /// tracers follow the light through the mesh.
    fn volume(&mut self, material: &gltf::Material, name: &str) -> R<Vec3> {
        let Some(v) = material.extension_value("KHR_materials_volume") else { return Ok(Vec3::ZERO) };
        let number = |key: &str, default: f64| match v.get(key) {
            None => Some(default),
            Some(x) => x.as_f64().filter(|x| x.is_finite()),
        };
        let thickness = number("thicknessFactor", 0.0).filter(|t| *t >= 0.0);
        let distance = number("attenuationDistance", f64::INFINITY).filter(|d| *d > 0.0);
        let color = match v.get("attenuationColor") {
            None => Some([1.0; 3]),
            Some(c) => c.as_array().filter(|c| c.len() == 3).and_then(|c| {
                let channels: Option<Vec<f64>> =
                    c.iter().map(|x| x.as_f64().filter(|x| (0.0..=1.0).contains(x))).collect();
                channels.map(|k| [k[0], k[1], k[2]])
            }),
        };
        let (Some(thickness), Some(distance), Some(color)) = (thickness, distance, color) else {
            return Err(self.err(format!(
                "{name}: KHR_materials_volume needs thicknessFactor ≥ 0, attenuationDistance > 0 and an attenuationColor of three numbers within [0, 1]"
            )));
        };
        if thickness == 0.0 || distance == f64::INFINITY {
            return Ok(Vec3::ZERO);
        }
        // A channel of colour 0, or a vanishing distance, keeps nothing: at most 10¹² per unit
        // length (as a Mitsuba or pbrt medium), finite.
        Ok(Vec3::from_array(color.map(|c| (-c.max(1e-30).ln() / distance).min(1e12))))
    }

    /// The metallic–roughness lobes: the metal gives back the light of several facets, as
    /// Blender's Principled BSDF (multiple-scattering GGX by default) does; the opaque coating
    /// under `KHR_materials_specular`: `specularFactor` the specular lobe's strength,
    /// `specularColorFactor` (its mean, with a warning where it is coloured) scaling the
    /// normal-incidence reflectance `((ior − 1)/(ior + 1))²`, at most 1 — read as the coating of
    /// the index with that reflectance. Its textures are left out (warning).
    fn lobes(&mut self, material: &gltf::Material, ior: f64, name: &str) -> MetalRoughness {
        let plain = MetalRoughness { multiscatter: true, ..common::plain_lobes(ior) };
        let Some(s) = material.specular() else { return plain };
        let color = s.specular_color_factor().map(f64::from);
        if color.iter().any(|&c| (c - color[0]).abs() > 1e-6) {
            self.warn(format!("{name}: a coloured specularColorFactor is read as its mean"));
        }
        let ior = alhazen_scene::bsdf::ior_scaled(ior, color.iter().sum::<f64>() / 3.0);
        MetalRoughness { ior: ior.max(1.0), specular: (s.specular_factor() as f64).clamp(0.0, 1.0), ..plain }
    }

    /// `KHR_materials_diffuse_transmission`: the share of the coating's diffuse light that passes
    /// through to the other side (`diffuseTransmissionFactor`, 0 without it) and its colour
    /// (`diffuseTransmissionColorFactor`, white): `(1 − share)·base` reflected, `share·colour`
    /// transmitted; and their textures, read per point (the share's alpha, the colour's sRGB).
    fn translucency(
        &mut self,
        material: &gltf::Material,
        name: &str,
    ) -> R<(Translucency, Option<Texture>, Option<Texture>)> {
        let Some(e) = material.extension_value("KHR_materials_diffuse_transmission") else {
            return Ok((Translucency::default(), None, None));
        };
        let factor = e.get("diffuseTransmissionFactor").map_or(Some(0.0), unit);
        let color = unit_rgb(e.get("diffuseTransmissionColorFactor"), Vec3::ONE);
        let (Some(factor), Some(color)) = (factor, color) else {
            return Err(self.err(format!(
                "{name}: KHR_materials_diffuse_transmission needs a diffuseTransmissionFactor and a diffuseTransmissionColorFactor of three numbers, within [0, 1]"
            )));
        };
        let mut map = |key: &str, decoding| match e.get(key) {
            Some(info) => self.texture_of_info(info, name, key, decoding).map(Some),
            None => Ok(None),
        };
        let factor_map = map("diffuseTransmissionTexture", Decoding::Alpha)?;
        let color_map = map("diffuseTransmissionColorTexture", Decoding::Srgb)?;
        let translucency = Translucency { factor: factor.clamp(0.0, 1.0), color: color.clamp(Vec3::ZERO, Vec3::ONE) };
        Ok((translucency, factor_map, color_map))
    }

    /// `KHR_materials_specular`'s textures, per point: `specularTexture` the coating's specular
    /// strength (its factor times the texture's alpha, in all three channels),
    /// `specularColorTexture` its normal-incidence reflectance (times the texture's mean colour,
    /// sRGB decoded). None without them, and under transmission (warning: the factors are used
    /// there).
    fn specular_maps(
        &mut self,
        material: &gltf::Material,
        transmission: f64,
        name: &str,
    ) -> R<(Option<Texture>, Option<Texture>)> {
        let Some(s) = material.specular() else { return Ok((None, None)) };
        let (strength, color) = (s.specular_texture(), s.specular_color_texture());
        if transmission > 0.0 && (strength.is_some() || color.is_some()) {
            self.warn(format!(
                "{name}: KHR_materials_specular's textures under transmission are not supported; its factors are used"
            ));
            return Ok((None, None));
        }
        let mut read = |info: Option<gltf::texture::Info>, decoding| -> R<Option<Texture>> {
            let Some(info) = info else { return Ok(None) };
            let (scale, offset, rotation) = self.texture_placement(&info, name)?;
            let image = wrapped(self.image(&info.texture(), decoding)?, &info.texture());
            self.scene.images.push(image);
            Ok(Some(Texture::Image { image: self.scene.images.len() - 1, scale, offset, rotation }))
        };
        Ok((read(strength, Decoding::Alpha)?, read(color, Decoding::Srgb)?))
    }

    /// `KHR_texture_transform`'s scale, offset and rotation in alhazen's texture coordinates, and
    /// the sampler's wrapping. glTF reads its image at `o + R·(s ⊙ uv)` with `v` down, `R` the
    /// matrix `[[cos ϑ, sin ϑ], [−sin ϑ, cos ϑ]]` of a `rotation` ϑ — as Blender's exporter
    /// writes it and three.js reads it (the extension's GLSL sample reads the transpose; Cycles'
    /// images of exported scenes agree with this reading, test
    /// `blender_texture_transform_agrees_with_cycles`); alhazen's `v = 1 − v_glTF` is up, and
    /// flipping `v` on both sides makes `R` a counter-clockwise turn by ϑ: the same texel is at
    /// `R(ϑ)·(s ⊙ uv) + (o_u + s_v sin ϑ, 1 − o_v − s_v cos ϑ)` (the shift kept in [0, 1): the
    /// images repeat) — a Blender Mapping node's own scale, rotation and location.
    fn texture_placement(&mut self, info: &gltf::texture::Info, name: &str) -> R<(Vec2, Vec2, f64)> {
        let transform = info
            .texture_transform()
            .map(|t| (t.scale().map(f64::from), t.offset().map(f64::from), t.rotation() as f64));
        self.placement(info.tex_coord(), transform, name)
    }

    /// [`Self::texture_placement`] from a texture's coordinate set and its transform's scale,
    /// offset and rotation.
    fn placement(
        &mut self,
        tex_coord: u32,
        transform: Option<([f64; 2], [f64; 2], f64)>,
        name: &str,
    ) -> R<(Vec2, Vec2, f64)> {
        if tex_coord != 0 {
            self.warn(format!("{name}: texture coordinate set {tex_coord} is read as set 0"));
        }
        match transform {
            Some(([su, sv], [ou, ov], turn)) => {
                // Texture coordinates times the scale stay far inside single precision's range.
                if ![su, sv, ou, ov, turn].iter().all(|x| x.is_finite() && x.abs() <= 1e6) {
                    return Err(self.err(format!(
                        "{name}: KHR_texture_transform's scale, offset and rotation must be numbers within ±10⁶"
                    )));
                }
                if turn == 0.0 {
                    return Ok((Vec2::new(su, sv), Vec2::new(ou, 1.0 - sv - ov).map(|x| x.rem_euclid(1.0)), 0.0));
                }
                let (sin, cos) = turn.sin_cos();
                let offset = Vec2::new(ou + sv * sin, 1.0 - ov - sv * cos).map(|x| x.rem_euclid(1.0));
                Ok((Vec2::new(su, sv), offset, turn.to_degrees()))
            }
            None => Ok((Vec2::ONE, Vec2::ZERO, 0.0)),
        }
    }

    /// The material's cut-out: `MASK` present where the base colour's alpha (its factor
    /// `factor` times its texture's alpha channel) reaches `alphaCutoff`; `BLEND` that alpha as
    /// a coverage, a ray let through with probability `1 − alpha` (Cycles' and Blender's
    /// reading of a blended surface in a path tracer); `None` when opaque.
    /// The base colour texture's `(scale, offset)` are the coverage's.
    fn cut_out(
        &mut self,
        material: &gltf::Material,
        factor: f64,
        (scale, offset, rotation): (Vec2, Vec2, f64),
    ) -> R<Option<alhazen_scene::Alpha>> {
        let cutoff = match material.alpha_mode() {
            AlphaMode::Opaque => return Ok(None),
            AlphaMode::Mask => {
                let cutoff = material.alpha_cutoff().unwrap_or(0.5) as f64;
                if !(cutoff >= 0.0 && cutoff.is_finite()) {
                    let name = material.name().unwrap_or("a material");
                    return Err(self.err(format!("{name}: alphaCutoff {cutoff} must be a number ≥ 0")));
                }
                Some(cutoff)
            }
            AlphaMode::Blend => None,
        };
        let factor = if factor.is_finite() { factor.clamp(0.0, 1.0) } else { 1.0 };
        let texture = match material.pbr_metallic_roughness().base_color_texture() {
            Some(info) => {
                let img = self.image(&info.texture(), Decoding::Alpha)?;
                // An image without an alpha channel is present everywhere.
                (alhazen_scene::texture::image_mean(&img).x < 1.0).then(|| {
                    self.scene.images.push(wrapped(scaled(img, Vec3::splat(factor)), &info.texture()));
                    Texture::Image { image: self.scene.images.len() - 1, scale, offset, rotation }
                })
            }
            None => None,
        };
        let coverage = match texture {
            Some(t) => t,
            // A constant coverage with a cutoff is all there or not at all.
            None => Texture::Solid(Vec3::splat(cutoff.map_or(factor, |c| if factor >= c { 1.0 } else { 0.0 }))),
        };
        if coverage == Texture::Solid(Vec3::ONE) {
            return Ok(None);
        }
        Ok(Some(alhazen_scene::Alpha { coverage, cutoff }))
    }

    /// A texture's image in linear RGB (decoded as `decoding` says).
    fn image(&mut self, texture: &gltf::Texture, decoding: Decoding) -> R<Arc<ImageData>> {
        let source = texture.source();
        let key = (source.index(), decoding);
        if let Some(img) = self.images.get(&key) {
            return Ok(img.clone());
        }
        let decoded = match self.decoded.remove(&key) {
            Some(ahead) => ahead,
            None => decode_image(&source, decoding, self.base, &self.buffers),
        };
        let img = Arc::new(decoded.map_err(|e| self.err(e))?);
        self.images.insert(key, img.clone());
        Ok(img)
    }

    /// Decodes every image the materials of `scene`'s meshes will ask for, all at once on all
    /// threads (a Blender export's textures are its load time); each error is kept, and
    /// reported only where the walk asks for the image, as if it were decoded there.
    fn decode_ahead(&mut self, document: &gltf::Document, scene: &gltf::Scene) {
        let mut wanted = std::collections::BTreeSet::new();
        let mut seen = std::collections::HashSet::new();
        let mut todo: Vec<(gltf::Node, usize)> = scene.nodes().map(|n| (n, 0)).collect();
        while let Some((node, depth)) = todo.pop() {
            if depth > 256 || !seen.insert(node.index()) {
                continue;
            }
            for material in node.mesh().iter().flat_map(|m| m.primitives()).map(|p| p.material()) {
                let pbr = material.pbr_metallic_roughness();
                let srgb =
                    [pbr.base_color_texture().map(|t| t.texture()), material.emissive_texture().map(|t| t.texture())];
                let linear = [
                    pbr.metallic_roughness_texture().map(|t| t.texture()),
                    material.normal_texture().map(|t| t.texture()),
                ];
                let alpha = pbr.base_color_texture().filter(|_| material.alpha_mode() != AlphaMode::Opaque);
                wanted.extend(srgb.iter().flatten().map(|t| (t.source().index(), Decoding::Srgb)));
                wanted.extend(linear.iter().flatten().map(|t| (t.source().index(), Decoding::Linear)));
                wanted.extend(alpha.map(|t| (t.texture().source().index(), Decoding::Alpha)));
                let transmission = material.transmission().and_then(|t| t.transmission_texture());
                wanted.extend(transmission.map(|t| (t.texture().source().index(), Decoding::Red)));
            }
            todo.extend(node.children().map(|c| (c, depth + 1)));
        }
        let images: Vec<gltf::Image> = document.images().collect();
        let (base, buffers) = (self.base, &self.buffers);
        let decoded: Vec<_> = wanted
            .into_par_iter()
            .filter_map(|(i, how)| Some(((i, how), decode_image(images.get(i)?, how, base, buffers))))
            .collect();
        self.decoded = decoded.into_iter().collect();
    }

    // ---- camera and lights ---------------------------------------------------------------------

    fn camera_of(&mut self, camera: &gltf::Camera, world: Mat4) -> CameraDesc {
        let eye = world.transform_point3(Vec3::ZERO);
        let ahead = world.transform_vector3(-Vec3::Z).normalize_or_zero();
        let up = world.transform_vector3(Vec3::Y).normalize_or_zero();
        let look = LookAt { eye, target: eye + ahead, up };
        match camera.projection() {
            gltf::camera::Projection::Perspective(p) => {
                if let Some(aspect) = p.aspect_ratio().filter(|a| *a > 0.0 && a.is_finite()) {
                    let r = &mut self.scene.render;
                    r.width =
                        ((r.height as f64 * aspect as f64).round() as u32).clamp(1, alhazen_scene::MAX_SIDE as u32);
                }
                let angle = (p.yfov() as f64).clamp(1e-3, 3.1);
                CameraDesc::Perspective {
                    look,
                    opening: PerspectiveOpening::Fov { angle, horizontal: false },
                    lens: None,
                }
            }
            gltf::camera::Projection::Orthographic(o) => {
                let (x, y) = (o.xmag().abs() as f64, o.ymag().abs() as f64);
                if x > 0.0 && y > 0.0 {
                    let r = &mut self.scene.render;
                    r.width = ((r.height as f64 * x / y).round() as u32).clamp(1, alhazen_scene::MAX_SIDE as u32);
                }
                CameraDesc::Orthographic { look, width: 2.0 * x.max(1e-9) }
            }
        }
    }

    fn light(&mut self, light: &gltf::khr_lights_punctual::Light, world: Mat4) {
        use gltf::khr_lights_punctual::Kind;
        let color = rgb(light.color());
        let power = color * (light.intensity() as f64 / LUMENS_PER_WATT);
        let position = world.transform_point3(Vec3::ZERO);
        let direction = world.transform_vector3(-Vec3::Z).normalize_or_zero();
        if light.range().is_some() {
            self.warn("a light's range is ignored: light falls off with the inverse square everywhere");
        }
        let l = match light.kind() {
            Kind::Directional => Light::Directional { direction, intensity: power },
            Kind::Point => Light::Point { position, intensity: power, attenuation: [1.0, 0.0, 0.0] },
            Kind::Spot { inner_cone_angle, outer_cone_angle } => {
                let (inner, outer) =
                    (inner_cone_angle as f64, (outer_cone_angle as f64).clamp(1e-4, std::f64::consts::FRAC_PI_2));
                // glTF's fade between its cones: the square of one linear in the cosine.
                let fades = outer - inner > 1e-6;
                let fade = alhazen_scene::SpotFade::SquaredCosine;
                Light::Spot {
                    position,
                    direction,
                    cos_cutoff: outer.cos(),
                    falloff: 0.0,
                    beam: fades.then(|| alhazen_scene::SpotBeam { cos: inner.max(0.0).cos(), fade }),
                    intensity: power,
                    attenuation: [1.0, 0.0, 0.0],
                }
            }
        };
        if direction == Vec3::ZERO && !matches!(l, Light::Point { .. }) {
            self.warn("a light whose node transform is singular is left out");
            return;
        }
        self.scene.lights.push(l);
    }
}

/// An `f32` colour of the file as the model's.
fn rgb(c: [f32; 3]) -> Vec3 {
    Vec3::new(c[0] as f64, c[1] as f64, c[2] as f64)
}

/// A camera that frames `bounds`: from `+z` and a little above, 45° vertical field of view.
fn framing(bounds: Bounds3, aspect: f64) -> Option<CameraDesc> {
    if bounds.is_empty() || !bounds.is_finite() {
        return None;
    }
    let center = (bounds.min + bounds.max) * 0.5;
    let radius = ((bounds.max - bounds.min).length() * 0.5).max(1e-9);
    let fov = 45f64.to_radians();
    let half = (fov / 2.0).min(((fov / 2.0).tan() * aspect).atan());
    let distance = radius / half.sin() * 1.05;
    let eye = center + Vec3::new(0.0, 0.35, 1.0).normalize() * distance;
    Some(CameraDesc::Perspective {
        look: LookAt { eye, target: center, up: Vec3::Y },
        opening: PerspectiveOpening::Fov { angle: fov, horizontal: false },
        lens: None,
    })
}

/// An image multiplied by `factor` (the base-colour factor glTF applies to its texture).
/// `img` read beyond `[0, 1]` as `texture`'s sampler says (glTF's `wrapS`, `wrapT`; a copy
/// only where that is not the image's own, repeat).
fn wrapped(mut img: Arc<ImageData>, texture: &gltf::Texture) -> Arc<ImageData> {
    use gltf::texture::WrappingMode;
    let wrap = |m: WrappingMode| match m {
        WrappingMode::Repeat => Wrap::Repeat,
        WrappingMode::ClampToEdge => Wrap::Clamp,
        WrappingMode::MirroredRepeat => Wrap::Mirror,
    };
    let sampler = texture.sampler();
    let wanted = [wrap(sampler.wrap_s()), wrap(sampler.wrap_t())];
    if img.wrap != wanted {
        Arc::make_mut(&mut img).wrap = wanted;
    }
    img
}

fn scaled(img: Arc<ImageData>, factor: Vec3) -> Arc<ImageData> {
    if factor == Vec3::ONE {
        // The decoded image itself, not a copy of its pixels.
        return img;
    }
    Arc::new(img.channels_scaled(factor.to_array().map(|x| x as f32)))
}

/// Every node of `scene` with its transform to the world (its ancestors' times its own);
/// nodes nested deeper than 256 levels are left out (the walk refuses them).
fn node_worlds(scene: &gltf::Scene) -> HashMap<usize, Mat4> {
    let mut worlds = HashMap::new();
    let mut todo: Vec<(gltf::Node, Mat4, usize)> = scene.nodes().map(|n| (n, Mat4::IDENTITY, 0)).collect();
    while let Some((node, parent, depth)) = todo.pop() {
        if depth > 256 || worlds.contains_key(&node.index()) {
            continue;
        }
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix().map(|c| c.map(f64::from)));
        worlds.insert(node.index(), world);
        todo.extend(node.children().map(|c| (c, world, depth + 1)));
    }
    worlds
}

/// `bsdf` with its glass (the dielectric that transmission mixes in) of index `ior`.
fn glass_of_index(bsdf: BsdfDesc, ior: Ior) -> BsdfDesc {
    match bsdf {
        BsdfDesc::Dielectric { facets, fresnel, transmittance, film, .. } => {
            BsdfDesc::Dielectric { facets, ior, fresnel, transmittance, film }
        }
        BsdfDesc::Mix { a, b, weight, weight_map } => BsdfDesc::Mix {
            a: Box::new(glass_of_index(*a, ior)),
            b: Box::new(glass_of_index(*b, ior)),
            weight,
            weight_map,
        },
        other => other,
    }
}

/// A `KHR_texture_transform` read from its JSON (for texture infos the reader does not type):
/// scale, offset and rotation, glTF's defaults where absent.
fn json_transform(t: &serde_json::Value) -> ([f64; 2], [f64; 2], f64) {
    let pair = |key: &str, default: f64| {
        let at = |k: usize| t.get(key).and_then(|v| v.get(k)).and_then(|x| x.as_f64());
        [at(0).unwrap_or(default), at(1).unwrap_or(default)]
    };
    (pair("scale", 1.0), pair("offset", 0.0), t.get("rotation").and_then(|r| r.as_f64()).unwrap_or(0.0))
}

/// Image `source` read (from its file, data URI or buffer view) and decoded to linear RGB, or
/// why it could not be.
fn decode_image(
    source: &gltf::Image,
    decoding: Decoding,
    base: &Path,
    buffers: &[gltf::buffer::Data],
) -> Result<ImageData, String> {
    let data = match webp_bytes(source, base, buffers) {
        Some(bytes) => decode_webp(&bytes?),
        None => gltf::image::Data::from_source(source.source(), Some(base), buffers).map_err(|e| e.to_string()),
    }
    .map_err(|e| format!("image {}: {e}", source.index()))?;
    decode(&data, decoding).ok_or_else(|| format!("image {}: unsupported pixel format", source.index()))
}

/// The encoded bytes of a WebP image (`EXT_texture_webp`: MIME type `image/webp`, or a file
/// named `.webp`) — from its buffer view, data URI or file —, or why they cannot be read;
/// `None` for other images, which the glTF reader decodes.
fn webp_bytes(source: &gltf::Image, base: &Path, buffers: &[gltf::buffer::Data]) -> Option<Result<Vec<u8>, String>> {
    use base64::Engine as _;
    match source.source() {
        gltf::image::Source::View { view, mime_type } => (mime_type == "image/webp").then(|| {
            let bytes = buffers.get(view.buffer().index()).map(|b| &b.0[..]).unwrap_or(&[]);
            bytes
                .get(view.offset()..view.offset() + view.length())
                .map(<[u8]>::to_vec)
                .ok_or_else(|| format!("its buffer view reaches beyond its buffer ({} bytes)", bytes.len()))
        }),
        gltf::image::Source::Uri { uri, mime_type } => {
            let data = uri.strip_prefix("data:");
            let webp = match data {
                Some(d) => d.starts_with("image/webp"),
                None => mime_type == Some("image/webp") || uri.to_ascii_lowercase().ends_with(".webp"),
            };
            webp.then(|| match data {
                Some(d) => {
                    let encoded = d.split_once(";base64,").map(|(_, b)| b).ok_or("a WebP data URI must be base64")?;
                    base64::engine::general_purpose::STANDARD.decode(encoded).map_err(|e| format!("its data URI: {e}"))
                }
                None => {
                    let name = urlencoding::decode(uri).map_err(|e| format!("its URI: {e}"))?;
                    let path = base.join(&*name);
                    std::fs::read(&path).map_err(|e| format!("cannot read {}: {e}", path.display()))
                }
            })
        }
    }
}

/// A WebP image's pixels, eight bits a channel (with alpha where it has one).
fn decode_webp(bytes: &[u8]) -> Result<gltf::image::Data, String> {
    let img = image::load_from_memory_with_format(bytes, image::ImageFormat::WebP)
        .map_err(|e| format!("not a readable WebP image: {e}"))?;
    let (width, height) = (img.width(), img.height());
    let (pixels, format) = if img.color().has_alpha() {
        (img.into_rgba8().into_raw(), gltf::image::Format::R8G8B8A8)
    } else {
        (img.into_rgb8().into_raw(), gltf::image::Format::R8G8B8)
    };
    Ok(gltf::image::Data { pixels, format, width, height })
}

/// A JSON number within `[0, 1]`, as extensions' factors are.
fn unit(x: &serde_json::Value) -> Option<f64> {
    x.as_f64().filter(|x| (0.0..=1.0).contains(x))
}

/// A JSON colour factor of three numbers within `[0, 1]`, `default` where it is absent; `None`
/// where it is malformed.
fn unit_rgb(value: Option<&serde_json::Value>, default: Vec3) -> Option<Vec3> {
    let Some(c) = value else { return Some(default) };
    let k: Vec<f64> = c.as_array().filter(|c| c.len() == 3)?.iter().map(unit).collect::<Option<_>>()?;
    Some(Vec3::new(k[0], k[1], k[2]))
}

/// How an image's channels are read.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
enum Decoding {
    /// Colours, decoded from sRGB (base colour, emission).
    Srgb,
    /// Values as they are (metallic–roughness, normals).
    Linear,
    /// The alpha channel, as it is, in all three (1 where the image has none).
    Alpha,
    /// The red channel, as it is, in all three (the first of a grey image).
    Red,
}

/// Decoded glTF image data as linear RGB.
fn decode(data: &gltf::image::Data, decoding: Decoding) -> Option<ImageData> {
    use gltf::image::Format::*;
    let (channels, bytes) = match data.format {
        R8 => (1, 1),
        R8G8 => (2, 1),
        R8G8B8 => (3, 1),
        R8G8B8A8 => (4, 1),
        R16 => (1, 2),
        R16G16 => (2, 2),
        R16G16B16 => (3, 2),
        R16G16B16A16 => (4, 2),
        R32G32B32FLOAT => (3, 4),
        R32G32B32A32FLOAT => (4, 4),
    };
    let n = data.width as usize * data.height as usize;
    if data.pixels.len() != n * channels * bytes || data.width == 0 || data.height == 0 {
        return None;
    }
    let srgb = decoding == Decoding::Srgb;
    // Channel `i` of a pixel: grey images repeat their first; alpha is the last of two or four.
    let has_alpha = channels % 2 == 0;
    let channel = |i: usize| match decoding {
        Decoding::Alpha if has_alpha => channels - 1,
        Decoding::Red => 0,
        _ if channels < 3 => 0,
        _ => i,
    };
    if decoding == Decoding::Alpha && !has_alpha {
        // Present everywhere: one texel says so (the material then has no cut-out).
        return Some(ImageData::from_codes(1, 1, [1.0; 256], vec![[0; 3]]));
    }
    if bytes == 1 {
        // Eight bits a channel: the 256 values decoded once, the pixels kept as their codes.
        let table = std::array::from_fn(|k| {
            let v = k as f32 / 255.0;
            if srgb { alhazen_math::color::srgb_to_linear(v as f64) as f32 } else { v }
        });
        let codes = data.pixels.chunks_exact(channels).map(|p| std::array::from_fn(|i| p[channel(i)])).collect();
        return Some(ImageData::from_codes(data.width, data.height, table, codes));
    }
    let value = |k: usize| -> f32 {
        let b = &data.pixels[k * bytes..(k + 1) * bytes];
        let v = match bytes {
            1 => b[0] as f32 / 255.0,
            2 => u16::from_le_bytes([b[0], b[1]]) as f32 / 65535.0,
            _ => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
        };
        if srgb && bytes < 4 { alhazen_math::color::srgb_to_linear(v as f64) as f32 } else { v }
    };
    let pixels = (0..n).map(|p| std::array::from_fn(|i| value(p * channels + channel(i)))).collect();
    Some(ImageData::new(data.width, data.height, pixels))
}
