//! `alhazen-import`: scenes written for other programs, read into alhazen's scene model
//! (`alhazen_scene::Scene`), so that `render`, `raster` and `lines` take them as they are.
//!
//! * [`gltf`](mod@gltf) — glTF 2.0 (`.gltf`, `.glb`): the node hierarchy, meshes, the
//!   metallic–roughness materials, `KHR_lights_punctual`, cameras;
//! * [`mitsuba`] — Mitsuba 3 XML scenes (`.xml`), with their `serialized` meshes;
//! * [`pbrt`] — pbrt-v4 scene descriptions (`.pbrt`);
//! * anything else is alhazen's own TOML (`alhazen_scene::load_scene`).
//!
//! The course describes a scene as a hierarchy of nodes with transforms (course, §"Scene
//! graphs"); each importer walks its format's hierarchy and emits the flat object list of the
//! model, every object with its composed object → world transform, meshes shared between
//! instances. What the model cannot represent is never dropped silently: it becomes a
//! [`Warning`] at `file:line` saying what was approximated and how; what makes the scene
//! meaningless is an error with its location (`alhazen_scene::SceneError`).
//!
//! ```
//! use alhazen_import::SceneFormat;
//! assert_eq!(SceneFormat::from_path("cornell.xml".as_ref()), SceneFormat::Mitsuba);
//! assert_eq!(SceneFormat::from_path("kitchen.pbrt".as_ref()), SceneFormat::Pbrt);
//! assert_eq!(SceneFormat::from_path("scene.toml".as_ref()), SceneFormat::Alhazen);
//! ```

mod common;
mod draco;
pub mod gltf;
mod meshopt;
pub mod mitsuba;
pub mod pbrt;
mod serialized;

use alhazen_scene::{OutsideEnvironment, Scene, SceneError};
use std::path::{Path, PathBuf};

pub use common::MAX_SCENE_FILE_BYTES;

/// Something in an imported file that alhazen approximated or left out.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Warning {
    /// The file it is in.
    pub file: PathBuf,
    /// 1-based line, or 0 when the format has no lines (binary glTF).
    pub line: usize,
    /// What was approximated, and how.
    pub message: String,
}

impl std::fmt::Display for Warning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.line {
            0 => write!(f, "{}: {}", self.file.display(), self.message),
            line => write!(f, "{}:{line}: {}", self.file.display(), self.message),
        }
    }
}

/// A scene and what importing it had to approximate.
#[derive(Debug)]
pub struct Imported {
    /// The scene.
    pub scene: Scene,
    /// Approximations, in the order they were met (each said once).
    pub warnings: Vec<Warning>,
}

/// The formats a scene file can be in, by extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SceneFormat {
    /// alhazen's TOML (any extension not listed below).
    Alhazen,
    /// glTF 2.0, `.gltf` (JSON) or `.glb` (binary).
    Gltf,
    /// Mitsuba 3 XML, `.xml`.
    Mitsuba,
    /// pbrt-v4, `.pbrt`.
    Pbrt,
}

impl SceneFormat {
    /// The format a path's extension names (case-insensitive).
    pub fn from_path(path: &Path) -> Self {
        match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
            Some("gltf" | "glb") => Self::Gltf,
            Some("xml") => Self::Mitsuba,
            Some("pbrt") => Self::Pbrt,
            _ => Self::Alhazen,
        }
    }

    /// A name for messages.
    pub fn name(self) -> &'static str {
        match self {
            Self::Alhazen => "alhazen TOML",
            Self::Gltf => "glTF 2.0",
            Self::Mitsuba => "Mitsuba 3 XML",
            Self::Pbrt => "pbrt-v4",
        }
    }
}

/// Reads a scene file in any supported format (chosen by [`SceneFormat::from_path`]).
pub fn load(path: &Path) -> Result<Imported, SceneError> {
    load_within(path, alhazen_scene::DEFAULT_MEMORY_BUDGET)
}

/// [`load`], refusing geometry the scene generates beyond `memory_budget` bytes (before
/// allocating it).
pub fn load_within(path: &Path, memory_budget: u64) -> Result<Imported, SceneError> {
    load_with_parameters(path, memory_budget, &[])
}

/// [`load_within`], a Mitsuba scene's `$name` parameters given `parameters`' values over its
/// `<default>`s (Mitsuba's `-D name=value`), or a glTF file's material variant chosen by
/// `variant` (`KHR_materials_variants`; another name is an error); the other formats have no
/// parameters and ignore them.
pub fn load_with_parameters(
    path: &Path,
    memory_budget: u64,
    parameters: &[(String, String)],
) -> Result<Imported, SceneError> {
    load_with(path, &LoadOptions { memory_budget, parameters, environment: None })
}

/// How to read a scene file: [`load_with`]'s options.
#[derive(Clone, Copy, Debug)]
pub struct LoadOptions<'a> {
    /// The most bytes the geometry the scene generates may take ([`load_within`]).
    pub memory_budget: u64,
    /// Values of its parameters ([`load_with_parameters`]).
    pub parameters: &'a [(String, String)],
    /// An environment map to light it by in place of its own
    /// ([`alhazen_scene::Scene::light_by`]).
    pub environment: Option<&'a OutsideEnvironment>,
}

/// Reads a scene file as `options` say. A glTF file, which has no sky of its own, is lit by
/// a uniform white sky (with a warning) when it has no light and no environment is given.
pub fn load_with(path: &Path, options: &LoadOptions) -> Result<Imported, SceneError> {
    Ok(light(read_unlit(path, options.memory_budget, options.parameters)?, path, options.environment))
}

/// [`load_with`]'s second step, after [`read_unlit`]: the scene read from `path` lit by
/// `environment` (or a glTF file without lights by a white sky), its cut-outs checked. Apart,
/// so that a front end may read a large map only once the scene has proved readable.
pub fn light(mut imported: Imported, path: &Path, environment: Option<&OutsideEnvironment>) -> Imported {
    let scene = &mut imported.scene;
    let warn = |message: &str| Warning { file: path.to_path_buf(), line: 0, message: message.to_string() };
    match environment {
        Some(env) => scene.light_by(env),
        None if SceneFormat::from_path(path) == SceneFormat::Gltf
            && scene.lights.is_empty()
            && scene.materials.iter().all(|m| m.emission == alhazen_scene::Rgb::ZERO) =>
        {
            imported.warnings.push(warn("the scene has no lights: a uniform white sky lights it"));
            scene.background = alhazen_scene::Background::Solid(alhazen_scene::Rgb::ONE);
        }
        None => {}
    }
    let cut_outs = imported.scene.opaque_cut_outs();
    imported.warnings.extend(cut_outs.iter().map(|message| warn(message)));
    imported
}

/// [`load_with`]'s first step: the scene file read, with its `parameters`, no environment
/// applied yet (then [`light`]).
pub fn read_unlit(path: &Path, memory_budget: u64, parameters: &[(String, String)]) -> Result<Imported, SceneError> {
    match SceneFormat::from_path(path) {
        SceneFormat::Alhazen => {
            let (scene, warnings) = alhazen_scene::load_scene_reporting(path, memory_budget)?;
            let warnings =
                warnings.into_iter().map(|message| Warning { file: path.to_path_buf(), line: 0, message }).collect();
            Ok(Imported { scene, warnings })
        }
        SceneFormat::Gltf => gltf::load(path, memory_budget, parameters),
        SceneFormat::Mitsuba => mitsuba::load_with_parameters(path, parameters),
        SceneFormat::Pbrt => pbrt::load(path),
    }
}
