//! glTF 2.0.
use crate::Imported;
use alhazen_scene::SceneError;
use std::path::Path;
/// Reads a glTF file.
pub fn load(path: &Path) -> Result<Imported, SceneError> {
    Err(SceneError::Io { path: path.into(), source: std::io::Error::other("todo") })
}
