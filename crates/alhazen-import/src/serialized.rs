//! Mitsuba's `serialized` meshes (the format of Mitsuba 0.4–3's `serialized` shape plugin,
//! versions 3 and 4, as its documentation lays it out): after a header of two little-endian
//! `u16`s (`0x041C` and the version), a zlib stream holding a flag word, the shape's name
//! (version 4), the vertex and triangle counts (`u64`), per-vertex positions, normals, texture
//! coordinates and colours (`f32`, or `f64` with flag `0x2000`; each present by its flag) and
//! three `u32` indices a triangle. A file holds several meshes one after the other; a table at
//! its end gives where each begins (`u32` offsets in version 3, `u64` in version 4) and then
//! their count (`u32`).

use alhazen_geom::TriangleMesh;
use alhazen_math::{Vec2, Vec3};
use std::io::Read;
use std::path::Path;

const MAGIC: u16 = 0x041C;
const HAS_NORMALS: u32 = 0x0001;
const HAS_TEXCOORDS: u32 = 0x0002;
const HAS_COLORS: u32 = 0x0008;
const DOUBLE_PRECISION: u32 = 0x2000;
/// DEFLATE's greatest expansion: 258 bytes out of a 2-bit code, so no stream holds more
/// than ~1032 times its size.
const MAX_INFLATION: u64 = 1032;

/// Mesh `shape` (0 for the first) of the serialized file at `path`; the error names the file.
pub(crate) fn load(path: &Path, shape: usize) -> Result<TriangleMesh, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("cannot load mesh {}: {e}", path.display()))?;
    let mesh = parse(&bytes, shape).map_err(|e| format!("cannot load mesh {}: {e}", path.display()))?;
    mesh.validate().map_err(|e| format!("mesh {} is invalid: {e}", path.display()))?;
    Ok(mesh)
}

/// Mesh `shape` of a serialized file's bytes.
pub(crate) fn parse(bytes: &[u8], shape: usize) -> Result<TriangleMesh, String> {
    let version = header(bytes, 0)?;
    let start = if shape == 0 { 0 } else { offset(bytes, version, shape)? };
    if header(bytes, start)? != version {
        return Err(format!("mesh {shape} has a header unlike the first mesh's"));
    }
    let compressed = &bytes[start + 4..];
    let mut z = flate2::read::ZlibDecoder::new(compressed);
    let flags = u32::from_le_bytes(take(&mut z)?);
    if version == 4 {
        skip_name(&mut z)?;
    }
    let (vertices, triangles) = (u64::from_le_bytes(take(&mut z)?), u64::from_le_bytes(take(&mut z)?));
    let has = |flag: u32| flags & flag != 0;
    let width: u64 = if has(DOUBLE_PRECISION) { 8 } else { 4 };
    let per_vertex = 3 + 3 * has(HAS_NORMALS) as u64 + 2 * has(HAS_TEXCOORDS) as u64 + 3 * has(HAS_COLORS) as u64;
    let size = vertices
        .checked_mul(per_vertex * width)
        .and_then(|v| triangles.checked_mul(12).and_then(|t| v.checked_add(t)))
        .filter(|&s| vertices <= u32::MAX as u64 && s <= MAX_INFLATION * compressed.len() as u64 + 64)
        .ok_or_else(|| {
            format!(
                "mesh {shape} claims {vertices} vertices and {triangles} triangles, more than its {} bytes can hold (a truncated or corrupt file)",
                compressed.len()
            )
        })?;
    // Grown as the stream inflates: a file that claims more than it holds allocates only what
    // it holds before it is refused.
    let mut data = Vec::new();
    (&mut z).take(size).read_to_end(&mut data).map_err(|e| format!("mesh {shape} is corrupt ({e})"))?;
    if data.len() as u64 != size {
        return Err(format!("mesh {shape} ends early: {} of its {size} bytes", data.len()));
    }
    // The stream ends with the triangles, and its checksum holds.
    if !matches!(z.read(&mut [0]), Ok(0)) {
        return Err(format!("mesh {shape} is corrupt: its stream does not end after its triangles"));
    }
    let mut at = 0;
    let mut reals = |n: u64| -> Vec<f64> {
        let len = (n * width) as usize;
        let chunk = &data[at..at + len];
        at += len;
        if width == 8 {
            chunk.chunks_exact(8).map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes"))).collect()
        } else {
            chunk.chunks_exact(4).map(|c| f32::from_le_bytes(c.try_into().expect("4 bytes")) as f64).collect()
        }
    };
    let triples = |v: Vec<f64>| v.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect::<Vec<_>>();
    let mut mesh = TriangleMesh { positions: triples(reals(3 * vertices)), ..TriangleMesh::default() };
    if has(HAS_NORMALS) {
        mesh.normals = triples(reals(3 * vertices));
    }
    if has(HAS_TEXCOORDS) {
        mesh.uvs = reals(2 * vertices).chunks_exact(2).map(|c| Vec2::new(c[0], c[1])).collect();
    }
    if has(HAS_COLORS) {
        reals(3 * vertices);
    }
    let indices = &data[at..];
    let index = |c: &[u8]| u32::from_le_bytes(c.try_into().expect("4 bytes"));
    mesh.triangles = indices.chunks_exact(12).map(|t| [index(&t[0..4]), index(&t[4..8]), index(&t[8..12])]).collect();
    Ok(mesh)
}

/// The version of the mesh header at byte `at`: 3 or 4.
fn header(bytes: &[u8], at: usize) -> Result<u16, String> {
    let field = |k: usize| bytes.get(at + k..at + k + 2).map(|b| u16::from_le_bytes([b[0], b[1]]));
    let (Some(magic), Some(version)) = (field(0), field(2)) else {
        return Err("the file ends inside a mesh header".into());
    };
    match (magic, version) {
        (MAGIC, 3 | 4) => Ok(version),
        (MAGIC, v) => Err(format!("serialized version {v} is not supported (versions 3 and 4 are)")),
        _ => Err("not a Mitsuba serialized mesh (its first bytes are not 0x041C)".into()),
    }
}

/// Where mesh `shape` begins, from the table at the end of the file.
fn offset(bytes: &[u8], version: u16, shape: usize) -> Result<usize, String> {
    let tail = |from_end: usize, len: usize| {
        let start = bytes.len().checked_sub(from_end)?;
        Some(&bytes[start..start + len])
    };
    let count = tail(4, 4).map(|b| u32::from_le_bytes(b.try_into().expect("4 bytes"))).ok_or("no mesh table")?;
    if shape >= count as usize {
        return Err(format!("shape_index {shape} is out of range: the file holds {count} meshes"));
    }
    let width = if version == 4 { 8 } else { 4 };
    let entry = tail(4 + width * (count as usize - shape), width).ok_or("the mesh table is truncated")?;
    let at = if width == 8 {
        u64::from_le_bytes(entry.try_into().expect("8 bytes"))
    } else {
        u32::from_le_bytes(entry.try_into().expect("4 bytes")) as u64
    };
    usize::try_from(at)
        .ok()
        .filter(|&a| a.checked_add(4).is_some_and(|end| end <= bytes.len()))
        .ok_or_else(|| format!("mesh {shape} begins past the file's end"))
}

fn take<const N: usize>(z: &mut impl Read) -> Result<[u8; N], String> {
    let mut b = [0; N];
    z.read_exact(&mut b).map_err(|e| format!("the mesh's header is truncated or corrupt ({e})"))?;
    Ok(b)
}

/// Skips a version 4 mesh's name, a string ending in a zero byte.
fn skip_name(z: &mut impl Read) -> Result<(), String> {
    for _ in 0..1 << 16 {
        if take::<1>(z)? == [0] {
            return Ok(());
        }
    }
    Err("the mesh's name does not end within 64 KiB".into())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    /// A mesh to write: flags, positions, normals, texture coordinates, triangles.
    type Part = (u32, Vec<Vec3>, Vec<Vec3>, Vec<Vec2>, Vec<[u32; 3]>);

    /// A serialized file of `meshes` in `version` 3 or 4, written as the format's
    /// documentation lays it out.
    fn write(version: u16, meshes: &[Part]) -> Vec<u8> {
        let mut out = Vec::new();
        let mut starts = Vec::new();
        for (flags, p, n, uv, t) in meshes {
            starts.push(out.len() as u64);
            out.extend(MAGIC.to_le_bytes());
            out.extend(version.to_le_bytes());
            let mut body = flags.to_le_bytes().to_vec();
            if version == 4 {
                body.extend(b"part\0");
            }
            body.extend((p.len() as u64).to_le_bytes());
            body.extend((t.len() as u64).to_le_bytes());
            let double = flags & DOUBLE_PRECISION != 0;
            let mut real =
                |x: f64| if double { body.extend(x.to_le_bytes()) } else { body.extend((x as f32).to_le_bytes()) };
            p.iter().chain(n).for_each(|v| v.to_array().map(&mut real).into_iter().for_each(drop));
            uv.iter().for_each(|v| v.to_array().map(&mut real).into_iter().for_each(drop));
            if flags & HAS_COLORS != 0 {
                (0..3 * p.len()).for_each(|_| real(0.5));
            }
            t.iter().flatten().for_each(|i| body.extend(i.to_le_bytes()));
            let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
            z.write_all(&body).unwrap();
            out.extend(z.finish().unwrap());
        }
        for s in &starts {
            if version == 4 { out.extend(s.to_le_bytes()) } else { out.extend((*s as u32).to_le_bytes()) }
        }
        out.extend((meshes.len() as u32).to_le_bytes());
        out
    }

    fn quad() -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let p = vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
        (p, vec![[0, 1, 2], [0, 2, 3]])
    }

    #[test]
    fn every_mesh_of_a_file_reads_back_in_both_versions_and_precisions() {
        let (p, t) = quad();
        let n = vec![Vec3::Z; 4];
        let uv: Vec<Vec2> = p.iter().map(|q| Vec2::new(q.x, q.y)).collect();
        let tri = (vec![Vec3::ONE, Vec3::new(2.0, 1.0, 1.0), Vec3::new(1.0, 2.0, 1.5)], vec![[0, 1, 2]]);
        for version in [3, 4] {
            for double in [0, DOUBLE_PRECISION] {
                let file = write(
                    version,
                    &[
                        (0x1000 | double | HAS_NORMALS | HAS_TEXCOORDS, p.clone(), n.clone(), uv.clone(), t.clone()),
                        (0x1000 | double | HAS_COLORS, tri.0.clone(), vec![], vec![], tri.1.clone()),
                    ],
                );
                let first = parse(&file, 0).unwrap();
                assert_eq!(
                    (first.positions.clone(), first.normals, first.uvs, first.triangles),
                    (p.clone(), n.clone(), uv.clone(), t.clone())
                );
                let second = parse(&file, 1).unwrap();
                assert_eq!((second.positions, second.triangles), tri.clone(), "version {version}");
                assert!(second.normals.is_empty() && second.uvs.is_empty());
                assert!(parse(&file, 2).unwrap_err().contains("holds 2 meshes"));
            }
        }
    }

    #[test]
    fn damaged_files_are_errors_not_panics_or_huge_allocations() {
        let (p, t) = quad();
        let file = write(4, &[(0x1000, p, vec![], vec![], t)]);
        assert!(parse(&file[..3], 0).unwrap_err().contains("ends inside"));
        assert!(parse(b"PK\x03\x04zzzz", 0).unwrap_err().contains("not a Mitsuba serialized"));
        let mut v5 = file.clone();
        v5[2] = 5;
        assert!(parse(&v5, 0).unwrap_err().contains("version 5"));
        // Every truncation of the mesh's stream is refused (the table of 12 bytes after it is
        // not needed to read the first mesh).
        for len in 4..file.len() - 12 {
            assert!(parse(&file[..len], 0).is_err(), "{len} bytes");
        }
        // Counts claiming more than the stream could inflate to are refused before allocating.
        let body = [
            0x1000u32.to_le_bytes().to_vec(),
            b"x\0".to_vec(),
            u64::MAX.to_le_bytes().to_vec(),
            4u64.to_le_bytes().to_vec(),
        ]
        .concat();
        let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
        z.write_all(&body).unwrap();
        let huge = [MAGIC.to_le_bytes().to_vec(), 4u16.to_le_bytes().to_vec(), z.finish().unwrap()].concat();
        assert!(parse(&huge, 0).unwrap_err().contains("more than its"));
    }

    /// A Mitsuba scene's `serialized` shapes: each `shape_index` its mesh, placed, shared by
    /// the shapes that name it; an index past the file's meshes is a located error.
    #[test]
    fn scenes_read_each_mesh_of_a_serialized_file() {
        let dir = tempfile::tempdir().unwrap();
        let (p, t) = quad();
        let tri = (vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]]);
        let file = write(3, &[(0x1000, p, vec![], vec![], t), (0x1000, tri.0, vec![], vec![], tri.1)]);
        std::fs::write(dir.path().join("m.serialized"), file).unwrap();
        let shape = |index: u32| {
            format!(
                r#"<shape type="serialized"><string name="filename" value="m.serialized"/>
                   <integer name="shape_index" value="{index}"/><transform name="to_world"><translate x="{index}"/></transform></shape>"#
            )
        };
        let xml = format!("<scene version=\"3.0.0\">{}{}{}</scene>", shape(1), shape(0), shape(1));
        std::fs::write(dir.path().join("s.xml"), xml).unwrap();
        let s = crate::mitsuba::load(&dir.path().join("s.xml")).unwrap().scene;
        let meshes: Vec<usize> = s
            .objects
            .iter()
            .map(|o| match o.shape {
                alhazen_scene::Shape::Mesh { mesh, .. } => mesh,
                _ => panic!("not a mesh"),
            })
            .collect();
        assert_eq!(meshes[0], meshes[2], "one mesh for two shapes");
        assert_eq!([1, 2, 1].map(|i| s.meshes[meshes[i - 1]].triangles.len()), [1, 2, 1]);
        assert_eq!(s.objects[2].transform.point(Vec3::ZERO), Vec3::X);
        let xml = format!("<scene version=\"3.0.0\">\n{}</scene>", shape(2));
        std::fs::write(dir.path().join("s.xml"), xml).unwrap();
        let err = crate::mitsuba::load(&dir.path().join("s.xml")).unwrap_err().to_string();
        assert!(err.contains("s.xml:2:1") && err.contains("holds 2 meshes"), "{err}");
    }

    proptest::proptest! {
        /// Any bytes after a valid header give a mesh or an error, never a panic.
        #[test]
        fn arbitrary_bytes_never_panic(tail in proptest::collection::vec(proptest::prelude::any::<u8>(), 0..400), v in 3u16..5, shape in 0usize..3) {
            let bytes = [MAGIC.to_le_bytes().to_vec(), v.to_le_bytes().to_vec(), tail].concat();
            let _ = parse(&bytes, shape);
        }
    }
}
