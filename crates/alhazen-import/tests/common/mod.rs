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

/// `Σ|alhazen − reference| / Σ reference` over alhazen's image of `s` at the reference's size.
pub fn difference_from_reference(s: &alhazen_scene::Scene, reference: &alhazen_scene::ImageData) -> f64 {
    let mut s = s.clone();
    (s.render.width, s.render.height) = (reference.width, reference.height);
    let img = alhazen_render::render(&s, &|_, _| {});
    let (mut diff, mut sum) = (0.0, 0.0);
    for (i, r) in reference.texels().enumerate() {
        let r = alhazen_math::Vec3::new(r[0] as f64, r[1] as f64, r[2] as f64);
        diff += (img.get(i as u32 % reference.width, i as u32 / reference.width) - r).abs().element_sum();
        sum += r.element_sum();
    }
    diff / sum
}
