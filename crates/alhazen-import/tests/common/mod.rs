//! Helpers shared by the importer tests.
#![allow(dead_code)]

use alhazen_import::Imported;
use std::path::{Path, PathBuf};

/// A path in the repository.
pub fn repo(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(rel)
}

/// Writes `files` (name, text) to a fresh directory and imports the first.
pub fn import(files: &[(&str, &str)]) -> Result<Imported, String> {
    let dir = tempfile::tempdir().unwrap();
    for (name, text) in files {
        std::fs::write(dir.path().join(name), text).unwrap();
    }
    alhazen_import::load(&dir.path().join(files[0].0)).map_err(|e| e.to_string())
}
