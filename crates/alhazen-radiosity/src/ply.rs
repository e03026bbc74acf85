//! The solution as a mesh (`alhazen render --integrator radiosity --export solution.ply`):
//! binary little-endian PLY, one triangle per element and lit side (wound so that its front is
//! that side; a side no light reached is left out), three vertices each with
//!
//! * `x y z`, `nx ny nz` (the side's shading normal), `s t` (texture coordinates),
//! * `irradiance_r irradiance_g irradiance_b`: the vertex-averaged irradiance over π, what the
//!   preview multiplies by the material's `ρ(uv)` per pixel,
//! * `color_r color_g color_b`: the mesh's vertex colour there (linear; white where it has
//!   none), which tints `ρ` of a material with vertex colours,
//! * `red green blue`: the radiance shown at the vertex, 8-bit sRGB, for other programs;
//!
//! and per face `material` and `object` (indices of the scene's) and `front` (1 when the face
//! is the surface's front, where emission shows). A comment carries the scene's fingerprint so
//! that `alhazen raster --radiosity` notices a solution of another scene.

use crate::solve::Solution;
use alhazen_math::color::{luminance, srgb_encode};
use alhazen_math::{Vec2, Vec3};
use std::f64::consts::PI;
use std::io::{self, Write};

/// A triangle of a solution mesh, as the preview draws it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LitTriangle {
    /// Corners (front counter-clockwise).
    pub p: [Vec3; 3],
    /// Shading normals.
    pub n: [Vec3; 3],
    /// Texture coordinates.
    pub uv: [Vec2; 3],
    /// Irradiance over π at the corners.
    pub irradiance: [Vec3; 3],
    /// Vertex colours at the corners.
    pub color: [Vec3; 3],
    /// Scene material.
    pub material: u32,
    /// Scene object.
    pub object: u32,
    /// The surface's front side (emission shows).
    pub front: bool,
}

/// A solution read back.
#[derive(Clone, Debug, PartialEq)]
pub struct LitMesh {
    /// Triangles.
    pub triangles: Vec<LitTriangle>,
    /// The fingerprint of the scene it was solved for.
    pub scene: Option<u64>,
}

const MAGIC: &str = "alhazen radiosity solution";
const VERTEX_PROPERTIES: [&str; 17] = [
    "float x",
    "float y",
    "float z",
    "float nx",
    "float ny",
    "float nz",
    "float s",
    "float t",
    "float irradiance_r",
    "float irradiance_g",
    "float irradiance_b",
    "float color_r",
    "float color_g",
    "float color_b",
    "uchar red",
    "uchar green",
    "uchar blue",
    // (the face properties follow in the header)
];
const VERTEX_BYTES: usize = 14 * 4 + 3;
const FACE_BYTES: usize = 1 + 12 + 4 + 4 + 1;

/// A hash of what a solution depends on in `scene`: its surfaces, materials, lights and
/// background (not the camera or the image settings).
pub fn scene_fingerprint(scene: &alhazen_scene::Scene) -> u64 {
    alhazen_render::film::part::hash_debug(&(
        &scene.objects,
        &scene.meshes,
        &scene.materials,
        &scene.lights,
        &scene.background,
    ))
}

/// The triangles of `solution` (see the module doc).
pub fn lit_triangles(solution: &Solution) -> Vec<LitTriangle> {
    let mut out = vec![];
    for (t, (tri, tree)) in solution.triangles.iter().zip(&solution.trees).enumerate() {
        let emits = solution.scene.materials[tri.material as usize].emission != Vec3::ZERO;
        for (i, node) in tree.nodes.iter().enumerate().filter(|(_, n)| n.is_leaf()) {
            for side in 0..2 {
                let e = solution.corners[t][i][side].map(|h| h.max(Vec3::ZERO) / PI);
                if e.iter().all(|h| luminance(*h) <= 0.0) && !(side == 0 && emits) {
                    continue;
                }
                let sign = if side == 0 { 1.0 } else { -1.0 };
                let mut lit = LitTriangle {
                    p: node.bary.map(|b| tri.at(b)),
                    n: node.bary.map(|b| tri.normal_at(b) * sign),
                    uv: node.bary.map(|b| tri.uv_at(b)),
                    irradiance: e,
                    color: node.bary.map(|b| tri.color_at(b)),
                    material: tri.material,
                    object: tri.object,
                    front: side == 0,
                };
                if side == 1 {
                    lit.p.swap(1, 2);
                    lit.n.swap(1, 2);
                    lit.uv.swap(1, 2);
                    lit.irradiance.swap(1, 2);
                    lit.color.swap(1, 2);
                }
                out.push(lit);
            }
        }
    }
    out
}

/// Writes `triangles` of the scene of fingerprint `scene` as PLY; `shown(t, k)` is the radiance
/// shown at corner `k` of triangle `t` (for the 8-bit colours).
pub fn write(
    out: &mut impl Write,
    triangles: &[LitTriangle],
    scene: u64,
    shown: impl Fn(&LitTriangle, usize) -> Vec3,
) -> io::Result<()> {
    let mut header = format!(
        "ply\nformat binary_little_endian 1.0\ncomment {MAGIC}\ncomment scene {scene:016x}\nelement vertex {}\n",
        triangles.len() * 3
    );
    for p in VERTEX_PROPERTIES {
        header += &format!("property {p}\n");
    }
    header += &format!(
        "element face {}\nproperty uchar int vertex_indices\nproperty int material\nproperty int object\nproperty uchar front\nend_header\n",
        triangles.len()
    );
    out.write_all(header.as_bytes())?;
    let mut buf = Vec::with_capacity(triangles.len() * 3 * VERTEX_BYTES);
    for t in triangles {
        for k in 0..3 {
            let floats = [t.p[k].to_array(), t.n[k].to_array()].concat();
            let lit = [t.irradiance[k].to_array(), t.color[k].to_array()].concat();
            for x in floats.iter().chain(&[t.uv[k].x, t.uv[k].y]).chain(&lit) {
                buf.extend((*x as f32).to_le_bytes());
            }
            let c = shown(t, k);
            buf.extend(c.to_array().map(|x| (srgb_encode(x.clamp(0.0, 1.0)) * 255.0).round() as u8));
        }
    }
    out.write_all(&buf)?;
    buf.clear();
    for (i, t) in triangles.iter().enumerate() {
        buf.push(3);
        for k in 0..3 {
            buf.extend(((3 * i + k) as i32).to_le_bytes());
        }
        buf.extend((t.material as i32).to_le_bytes());
        buf.extend((t.object as i32).to_le_bytes());
        buf.push(t.front as u8);
    }
    out.write_all(&buf)
}

/// Reads a solution written by [`write()`]; errors say what is wrong.
pub fn read(bytes: &[u8]) -> Result<LitMesh, String> {
    let end = b"end_header\n";
    let at = bytes.windows(end.len()).position(|w| w == end).ok_or("not a PLY file (no end_header)")?;
    let header = std::str::from_utf8(&bytes[..at]).map_err(|_| "the PLY header is not text")?;
    let body = &bytes[at + end.len()..];
    let mut lines = header.lines();
    if lines.next() != Some("ply") || lines.next() != Some("format binary_little_endian 1.0") {
        return Err("not a binary little-endian PLY file".into());
    }
    if lines.next() != Some(&format!("comment {MAGIC}")) {
        return Err(format!("not an {MAGIC} (written by `alhazen render --integrator radiosity --export`)"));
    }
    let scene =
        lines.next().and_then(|l| l.strip_prefix("comment scene ")).and_then(|h| u64::from_str_radix(h, 16).ok());
    let count = |line: Option<&str>, what: &str| -> Result<usize, String> {
        line.and_then(|l| l.strip_prefix(&format!("element {what} ")))
            .and_then(|n| n.parse().ok())
            .ok_or(format!("the PLY header lacks its {what} count"))
    };
    let vertices = count(lines.next(), "vertex")?;
    for p in VERTEX_PROPERTIES {
        if lines.next() != Some(&format!("property {p}")) {
            return Err(format!("the PLY header lacks `property {p}` where a solution has it"));
        }
    }
    let faces = count(lines.next(), "face")?;
    let want = vertices.checked_mul(VERTEX_BYTES).zip(faces.checked_mul(FACE_BYTES)).map(|(a, b)| a + b);
    if vertices != faces.saturating_mul(3) || want != Some(body.len()) {
        return Err(format!(
            "the PLY body holds {} bytes; {vertices} vertices and {faces} triangles need {}",
            body.len(),
            want.map_or("more".into(), |w| w.to_string())
        ));
    }
    let f32_at = |b: &[u8], k: usize| f32::from_le_bytes(b[4 * k..4 * k + 4].try_into().expect("4 bytes")) as f64;
    let i32_at = |b: &[u8], o: usize| i32::from_le_bytes(b[o..o + 4].try_into().expect("4 bytes"));
    let (vbytes, fbytes) = body.split_at(vertices * VERTEX_BYTES);
    let mut triangles = Vec::with_capacity(faces);
    for (i, f) in fbytes.chunks_exact(FACE_BYTES).enumerate() {
        let ids = [i32_at(f, 1), i32_at(f, 5), i32_at(f, 9)];
        if f[0] != 3 || ids.iter().any(|&v| v < 0 || v as usize >= vertices) {
            return Err(format!("triangle {i}: bad vertex indices"));
        }
        let (material, object) = (i32_at(f, 13), i32_at(f, 17));
        if material < 0 || object < 0 {
            return Err(format!("triangle {i}: negative material or object"));
        }
        let v = ids.map(|k| &vbytes[k as usize * VERTEX_BYTES..(k as usize + 1) * VERTEX_BYTES]);
        let vec = |b: &[u8], k: usize| Vec3::new(f32_at(b, k), f32_at(b, k + 1), f32_at(b, k + 2));
        let t = LitTriangle {
            p: v.map(|b| vec(b, 0)),
            n: v.map(|b| vec(b, 3)),
            uv: v.map(|b| Vec2::new(f32_at(b, 6), f32_at(b, 7))),
            irradiance: v.map(|b| vec(b, 8)),
            color: v.map(|b| vec(b, 11)),
            material: material as u32,
            object: object as u32,
            front: f[21] != 0,
        };
        let finite = t.p.iter().chain(&t.n).chain(&t.irradiance).chain(&t.color).all(|x| x.is_finite());
        if !finite || t.uv.iter().any(|x| !x.is_finite()) {
            return Err(format!("triangle {i}: a value is not a finite number"));
        }
        triangles.push(t);
    }
    Ok(LitMesh { triangles, scene })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Vec<LitTriangle> {
        vec![LitTriangle {
            p: [Vec3::ZERO, Vec3::X, Vec3::Y],
            n: [Vec3::Z; 3],
            uv: [Vec2::ZERO, Vec2::X, Vec2::Y],
            irradiance: [Vec3::new(0.5, 0.25, 0.125), Vec3::ONE, Vec3::ZERO],
            color: [Vec3::ONE, Vec3::new(0.25, 0.5, 1.0), Vec3::ONE],
            material: 2,
            object: 7,
            front: false,
        }]
    }

    #[test]
    fn a_solution_mesh_reads_back_as_written() {
        let mut bytes = vec![];
        write(&mut bytes, &sample(), 0xabc, |t, k| t.irradiance[k]).unwrap();
        let back = read(&bytes).unwrap();
        assert_eq!(back.triangles, sample());
        assert_eq!(back.scene, Some(0xabc));
    }

    #[test]
    fn damaged_files_are_refused_with_a_reason() {
        let mut bytes = vec![];
        write(&mut bytes, &sample(), 1, |t, k| t.irradiance[k]).unwrap();
        assert!(read(&bytes[..bytes.len() - 1]).unwrap_err().contains("bytes"));
        assert!(read(b"ply\nformat ascii 1.0\nend_header\n").unwrap_err().contains("binary"));
        let other = String::from_utf8_lossy(&bytes).replace(MAGIC, "something else");
        assert!(read(other.as_bytes()).is_err());
        assert!(read(b"hello").unwrap_err().contains("end_header"));
    }
}
