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

/// An ASCII PLY file of a strip of `n` triangles.
#[allow(dead_code)]
pub fn strip_ply(n: usize) -> String {
    let mut t = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
         element face {n}\nproperty list uchar int vertex_indices\nend_header\n",
        n + 2
    );
    (0..n + 2).for_each(|i| t += &format!("{i} {} 0\n", i % 2));
    (0..n).for_each(|i| t += &format!("3 {i} {} {}\n", i + 1, i + 2));
    t
}

/// Each object's mesh's triangle count (every object a mesh).
#[allow(dead_code)]
pub fn mesh_triangle_counts(s: &alhazen_scene::Scene) -> Vec<usize> {
    let count = |o: &alhazen_scene::Object| match o.shape {
        alhazen_scene::Shape::Mesh { mesh, .. } => s.meshes[mesh].triangles.len(),
        _ => panic!("not a mesh"),
    };
    s.objects.iter().map(count).collect()
}
