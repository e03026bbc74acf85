//! `alhazen-scene`: what a scene is, and how it is read.
//!
//! * [`model`] — the scene as plain data: camera, lights, materials (the course's local
//!   lighting models plus the lecture's mirror and transparency coefficients), shapes, CSG;
//! * the native TOML format ([`parse_scene`], [`load_scene`]), documented field by field in
//!   `docs/scene-format.md`; every error is a [`Diagnostic`] with `file:line:col`, a caret
//!   under the offending text, what was expected and, for typos, a "did you mean";
//! * [`import`] — OBJ/MTL and PLY meshes, PNG textures;
//! * [`write`](mod@write) — a scene written back as TOML (with its meshes as PLY, images as EXR).
//!
//! ```
//! let text = "[[object]]\nshape = \"sphere\"\nradius = 1.0\n";
//! let scene = alhazen_scene::parse_scene("inline.toml".as_ref(), text).unwrap();
//! assert_eq!(scene.objects.len(), 1);
//! let bad = "[[object]]\nshape = \"sphere\"\nradus = 1.0\n";
//! let err = alhazen_scene::parse_scene("inline.toml".as_ref(), bad).unwrap_err();
//! assert!(err.to_string().contains("inline.toml:3:1: unknown key `radus`"));
//! ```

pub mod bsdf;
mod diagnostic;
mod graph;
pub mod import;
pub mod model;
mod parse;
mod parse_bsdf;
mod parse_freeform;
mod reader;
pub mod texture;
pub mod write;

pub use diagnostic::{Diagnostic, did_you_mean};
pub use model::*;
pub use parse::{
    MAX_PIXELS, MAX_SIDE, empty_scene, parse_scene, parse_scene_reporting, parse_scene_within,
    rectangle as rectangle_mesh,
};
use std::path::{Path, PathBuf};

/// Why a scene could not be loaded.
#[derive(Debug)]
pub enum SceneError {
    /// The file could not be read.
    Io {
        /// The path.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// The file was read but is not a valid scene.
    Syntax(Box<Diagnostic>),
}

impl std::fmt::Display for SceneError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Io { path, source } => write!(f, "cannot read {}: {source}", path.display()),
            Self::Syntax(d) => d.fmt(f),
        }
    }
}

impl std::error::Error for SceneError {}

/// The largest scene file read (256 MiB): larger ones, and anything that is not a regular file
/// (such as `/dev/zero`), are refused before reading.
pub const MAX_SCENE_BYTES: u64 = 256 << 20;

/// What geometry a scene generates (subdivision) may take when the caller does not say: 8 GiB.
pub const DEFAULT_MEMORY_BUDGET: u64 = 8 << 30;

/// `bytes` for people: "3.2 GB", "512 MB", "12 kB".
pub fn format_bytes(bytes: u64) -> String {
    let b = bytes as f64;
    match bytes {
        0..1_000_000 => format!("{:.0} kB", b / 1e3),
        1_000_000..1_000_000_000 => format!("{:.0} MB", b / 1e6),
        _ => format!("{:.1} GB", b / 1e9),
    }
}

/// Reads and parses a scene file.
pub fn load_scene(path: &Path) -> Result<Scene, SceneError> {
    load_scene_within(path, DEFAULT_MEMORY_BUDGET)
}

/// [`load_scene`] within a memory budget for generated geometry ([`parse_scene_within`]).
pub fn load_scene_within(path: &Path, memory_budget: u64) -> Result<Scene, SceneError> {
    load_scene_reporting(path, memory_budget).map(|(scene, _)| scene)
}

/// [`load_scene_within`] with the warnings ([`parse_scene_reporting`]).
pub fn load_scene_reporting(path: &Path, memory_budget: u64) -> Result<(Scene, Vec<String>), SceneError> {
    let io = |source| SceneError::Io { path: path.to_path_buf(), source };
    let meta = std::fs::metadata(path).map_err(io)?;
    if !meta.is_file() {
        return Err(io(std::io::Error::other("not a regular file")));
    }
    if meta.len() > MAX_SCENE_BYTES {
        let message = format!("{} bytes is more than the {MAX_SCENE_BYTES} a scene file may have", meta.len());
        return Err(io(std::io::Error::other(message)));
    }
    let bytes = std::fs::read(path).map_err(io)?;
    if bytes.iter().all(u8::is_ascii_whitespace) {
        return Err(SceneError::Syntax(Box::new(Diagnostic::at(path, "", 0..0, "the scene file is empty"))));
    }
    let text = String::from_utf8(bytes).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        let text = String::from_utf8_lossy(e.as_bytes()).into_owned();
        SceneError::Syntax(Box::new(Diagnostic::at(path, &text, at..at + 1, "the scene file is not valid UTF-8")))
    })?;
    parse_scene_reporting(path, &text, memory_budget)
}
