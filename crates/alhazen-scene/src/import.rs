//! Importers for data a scene file refers to: OBJ/MTL meshes (via `tobj`), PLY meshes (ASCII and
//! binary, hand-written), and images for textures (PNG, decoded from sRGB to linear).

use crate::model::{ImageData, Material, Texture};
use alhazen_geom::TriangleMesh;
use alhazen_math::color::srgb_to_linear;
use alhazen_math::{Vec2, Vec3};
use std::path::Path;

/// A mesh and the materials its file defines, in slot order.
#[derive(Debug)]
pub struct LoadedMesh {
    /// The geometry.
    pub mesh: TriangleMesh,
    /// Materials referenced by `mesh.material_slots`.
    pub materials: Vec<Material>,
    /// What could not be read but did not stop the loading (a missing material library).
    pub warnings: Vec<String>,
}

/// Loads an `.obj` or `.ply` file; the error message names the file.
pub fn load_mesh(path: &Path) -> Result<LoadedMesh, String> {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    let result = match ext.as_deref() {
        Some("obj") => load_obj(path),
        Some("bpt") => std::fs::read_to_string(path)
            .map_err(|e| e.to_string())
            .and_then(|t| parse_bpt(&t))
            .map(|mesh| LoadedMesh { mesh, materials: vec![], warnings: vec![] }),
        Some("ply") => std::fs::read(path)
            .map_err(|e| e.to_string())
            .and_then(|b| parse_ply(&b))
            .map(|mesh| LoadedMesh { mesh, materials: vec![], warnings: vec![] }),
        _ => Err("unsupported mesh format (expected .obj, .ply or .bpt)".into()),
    };
    let loaded = result.map_err(|e| format!("cannot load mesh {}: {e}", path.display()))?;
    loaded.mesh.validate().map_err(|e| format!("mesh {} is invalid: {e}", path.display()))?;
    Ok(loaded)
}

fn load_obj(path: &Path) -> Result<LoadedMesh, String> {
    check_obj_faces(path)?;
    let opts = tobj::LoadOptions { triangulate: true, single_index: true, ..Default::default() };
    let (models, mtl) = tobj::load_obj(path, &opts).map_err(|e| e.to_string())?;
    // A missing .mtl file is not fatal: the object's own material is used, and the user told.
    let mut warnings = Vec::new();
    let mtl = mtl.unwrap_or_else(|e| {
        let has_library =
            std::fs::read_to_string(path).is_ok_and(|t| t.lines().any(|l| l.trim_start().starts_with("mtllib")));
        if has_library {
            warnings.push(format!(
                "{}: its material library could not be read ({e}); the object's own material is used instead",
                path.display()
            ));
        }
        Vec::new()
    });
    let mut mesh = TriangleMesh::default();
    let mut any_normals = true;
    let mut any_uvs = true;
    let mut any_colors = true;
    for m in &models {
        let mm = &m.mesh;
        let base = mesh.positions.len() as u32;
        let n = mm.positions.len() / 3;
        mesh.positions.extend(mm.positions.chunks_exact(3).map(|p| Vec3::new(p[0] as f64, p[1] as f64, p[2] as f64)));
        any_normals &= mm.normals.len() == mm.positions.len();
        any_uvs &= mm.texcoords.len() / 2 == n;
        if any_normals {
            mesh.normals.extend(mm.normals.chunks_exact(3).map(|v| Vec3::new(v[0] as f64, v[1] as f64, v[2] as f64)));
        }
        if any_uvs {
            mesh.uvs.extend(mm.texcoords.chunks_exact(2).map(|v| Vec2::new(v[0] as f64, v[1] as f64)));
        }
        // `v x y z r g b`: sRGB fractions, as Blender's OBJ reader takes them.
        any_colors &= mm.vertex_color.len() == mm.positions.len();
        if any_colors {
            let linear = |c: &[f32]| Vec3::new(c[0] as f64, c[1] as f64, c[2] as f64).map(srgb_to_linear);
            mesh.colors.extend(mm.vertex_color.chunks_exact(3).map(linear));
        }
        let slot = mm.material_id.map_or(u32::MAX, |i| i as u32);
        for tri in mm.indices.chunks_exact(3) {
            mesh.triangles.push([base + tri[0], base + tri[1], base + tri[2]]);
            mesh.material_slots.push(slot);
        }
    }
    if !any_normals {
        mesh.normals.clear();
    }
    if !any_uvs {
        mesh.uvs.clear();
    }
    if !any_colors {
        mesh.colors.clear();
    }
    // A mesh's colours show through its own materials, as OBJ viewers show them.
    let colored = |m: Material| Material { vertex_colors: !mesh.colors.is_empty(), ..m };
    let materials: Vec<Material> = mtl.iter().map(mtl_material).map(colored).collect();
    if materials.is_empty() || mesh.material_slots.iter().all(|s| *s == u32::MAX) {
        mesh.material_slots.clear();
    } else {
        // Faces without a material use slot 0's material rather than failing.
        for s in &mut mesh.material_slots {
            if *s as usize >= materials.len() {
                *s = 0;
            }
        }
    }
    mesh.material_names = materials.iter().map(|m| m.name.clone()).collect();
    Ok(LoadedMesh { mesh, materials, warnings })
}

/// MTL → Whitted material: `Kd` colour, `Ks`/`Ns` highlight, `d`/`Tr` transparency, `Ni` ior;
/// illumination models 3–7 add a mirror term of `Ks`.
/// Refuses faces of fewer than three vertices (tobj would drop them silently), naming the line.
fn check_obj_faces(path: &Path) -> Result<(), String> {
    let text = std::fs::read(path).map_err(|e| e.to_string())?;
    for (no, line) in text.split(|&b| b == b'\n').enumerate() {
        let mut words = line.split(|b| b.is_ascii_whitespace()).filter(|w| !w.is_empty());
        if words.next() == Some(b"f".as_slice()) {
            let corners = words.take_while(|w| w[0] != b'#').count();
            if corners < 3 {
                return Err(format!("line {}: a face needs at least 3 vertices, this one has {corners}", no + 1));
            }
        }
    }
    Ok(())
}

fn mtl_material(m: &tobj::Material) -> Material {
    let rgb = |c: Option<[f32; 3]>, d: Vec3| c.map_or(d, |c| Vec3::new(c[0] as f64, c[1] as f64, c[2] as f64));
    let d = Material::default();
    let specular = rgb(m.specular, Vec3::ZERO);
    let opacity = m.dissolve.map_or(1.0, |x| x.clamp(0.0, 1.0) as f64);
    let illum = m.illumination_model.unwrap_or(2);
    Material {
        name: m.name.clone(),
        color: Texture::Solid(rgb(m.diffuse, Vec3::splat(0.8))),
        specular,
        shininess: m.shininess.map_or(d.shininess, |s| s.max(0.0) as f64),
        mirror: if (3..=7).contains(&illum) { specular } else { Vec3::ZERO },
        transparency: Vec3::splat(1.0 - opacity),
        ior: m.optical_density.filter(|n| *n > 0.0).map_or(d.ior, |n| n as f64),
        ..d
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum PlyFormat {
    Ascii,
    BinaryLe,
    BinaryBe,
}

#[derive(Clone, Copy, Debug)]
enum PlyType {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl PlyType {
    /// The largest code of an unsigned integer type (a colour channel's full scale); `None`
    /// for the others.
    fn full_scale(self) -> Option<f64> {
        match self {
            Self::U8 => Some(255.0),
            Self::U16 => Some(65535.0),
            Self::U32 => Some(u32::MAX as f64),
            _ => None,
        }
    }

    fn parse(s: &str) -> Option<Self> {
        Some(match s {
            "char" | "int8" => Self::I8,
            "uchar" | "uint8" => Self::U8,
            "short" | "int16" => Self::I16,
            "ushort" | "uint16" => Self::U16,
            "int" | "int32" => Self::I32,
            "uint" | "uint32" => Self::U32,
            "float" | "float32" => Self::F32,
            "double" | "float64" => Self::F64,
            _ => return None,
        })
    }
}

#[derive(Debug)]
struct PlyProperty {
    name: String,
    ty: PlyType,
    /// Count type for list properties.
    list: Option<PlyType>,
}

#[derive(Debug)]
struct PlyElement {
    name: String,
    count: usize,
    props: Vec<PlyProperty>,
}

/// A cursor over PLY body data in one of the three encodings.
struct PlyReader<'a> {
    format: PlyFormat,
    bytes: &'a [u8],
    pos: usize,
}

impl PlyReader<'_> {
    /// Inlined: a call per value costs 2 % of the instructions of loading a million faces.
    #[inline(always)]
    fn read(&mut self, ty: PlyType) -> Result<f64, String> {
        if self.format == PlyFormat::Ascii {
            return self.read_ascii();
        }
        let be = self.format == PlyFormat::BinaryBe;
        // Each type reads a fixed number of bytes: a copy of a run-time length would be a call
        // to `memcpy` per value.
        Ok(match ty {
            PlyType::I8 => self.take::<1>(be)?[0] as i8 as f64,
            PlyType::U8 => self.take::<1>(be)?[0] as f64,
            PlyType::I16 => i16::from_le_bytes(self.take(be)?) as f64,
            PlyType::U16 => u16::from_le_bytes(self.take(be)?) as f64,
            PlyType::I32 => i32::from_le_bytes(self.take(be)?) as f64,
            PlyType::U32 => u32::from_le_bytes(self.take(be)?) as f64,
            PlyType::F32 => f32::from_le_bytes(self.take(be)?) as f64,
            PlyType::F64 => f64::from_le_bytes(self.take(be)?),
        })
    }

    /// The next `N` bytes, in little-endian order (reversed when the file is big-endian).
    #[inline(always)]
    fn take<const N: usize>(&mut self, big_endian: bool) -> Result<[u8; N], String> {
        let mut b: [u8; N] = self
            .bytes
            .get(self.pos..self.pos + N)
            .and_then(|b| b.try_into().ok())
            .ok_or("unexpected end of binary data")?;
        self.pos += N;
        if big_endian {
            b.reverse();
        }
        Ok(b)
    }

    fn read_ascii(&mut self) -> Result<f64, String> {
        let rest = &self.bytes[self.pos..];
        let start = rest.iter().position(|c| !c.is_ascii_whitespace()).ok_or("unexpected end of ASCII data")?;
        let len = rest[start..].iter().position(|c| c.is_ascii_whitespace()).unwrap_or(rest.len() - start);
        let tok = std::str::from_utf8(&rest[start..start + len]).map_err(|_| "non-UTF-8 number")?;
        self.pos += start + len;
        tok.parse::<f64>().map_err(|_| format!("bad number `{tok}` in ASCII data"))
    }
}

/// Parses a PLY file: `vertex` (x, y, z, optional nx ny nz, u v / s t, red green blue / r g b)
/// and `face` (`vertex_indices` or `vertex_index` lists, fan-triangulated); other elements are
/// skipped. Colours in unsigned integers are sRGB codes (as scanners, MeshLab and Blender
/// write them), decoded to linear; in floating point they are linear (as Mitsuba reads them).
pub fn parse_ply(bytes: &[u8]) -> Result<TriangleMesh, String> {
    let (format, elements, body) = parse_ply_header(bytes)?;
    let mut rd = PlyReader { format, bytes: body, pos: 0 };
    let mut mesh = TriangleMesh::default();
    for el in &elements {
        let idx = |n: &str| el.props.iter().position(|p| p.name == n);
        let (xyz, nrm) = ([idx("x"), idx("y"), idx("z")], [idx("nx"), idx("ny"), idx("nz")]);
        let uv = [idx("u").or(idx("s")).or(idx("texture_u")), idx("v").or(idx("t")).or(idx("texture_v"))];
        let rgb = [idx("red").or(idx("r")), idx("green").or(idx("g")), idx("blue").or(idx("b"))];
        let decode = rgb.map(|c| c.map(|i| el.props[i].ty.full_scale()));
        let face_list = idx("vertex_indices").or(idx("vertex_index"));
        if el.name == "vertex" && xyz.iter().any(Option::is_none) {
            return Err("the vertex element lacks x, y or z".into());
        }
        if el.name == "face" && face_list.is_some_and(|i| el.props[i].list.is_none()) {
            return Err("the face element's vertex_indices is a number, not a list".into());
        }
        let mut vals = vec![0.0; el.props.len()];
        let (vertex, face) = (el.name == "vertex", el.name == "face");
        // One buffer reused by every face (a million faces would otherwise make a million
        // small allocations); the vectors grow at most to one item per byte of the body.
        let mut corners: Vec<u32> = Vec::new();
        let at_most = el.count.min(body.len());
        if vertex {
            mesh.positions.reserve(at_most);
        } else if face {
            mesh.triangles.reserve(at_most);
        }
        for _ in 0..el.count {
            corners.clear();
            for (i, p) in el.props.iter().enumerate() {
                match p.list {
                    None => vals[i] = rd.read(p.ty)?,
                    Some(ct) => {
                        let n = rd.read(ct)?;
                        if !(0.0..=1e6).contains(&n) {
                            return Err(format!("list length {n} out of range"));
                        }
                        let keep = face && Some(i) == face_list;
                        for _ in 0..n as usize {
                            let x = rd.read(p.ty)?;
                            if keep {
                                if !(x >= 0.0 && x < u32::MAX as f64) {
                                    return Err(format!("bad vertex index {x}"));
                                }
                                corners.push(x as u32);
                            }
                        }
                        if keep && corners.len() < 3 {
                            return Err("a face has fewer than 3 vertices".into());
                        }
                    }
                }
            }
            if vertex {
                let g = |o: Option<usize>| o.map(|i| vals[i]);
                mesh.positions.push(Vec3::new(vals[xyz[0].unwrap()], vals[xyz[1].unwrap()], vals[xyz[2].unwrap()]));
                if let [Some(x), Some(y), Some(z)] = nrm.map(g) {
                    mesh.normals.push(Vec3::new(x, y, z));
                }
                if let [Some(u), Some(v)] = uv.map(g) {
                    mesh.uvs.push(Vec2::new(u, v));
                }
                if let [Some(r), Some(g), Some(b)] = rgb.map(g) {
                    let linear = |x: f64, k: usize| match decode[k].flatten() {
                        Some(full) => srgb_to_linear(x / full),
                        None => x,
                    };
                    mesh.colors.push(Vec3::new(linear(r, 0), linear(g, 1), linear(b, 2)));
                }
            } else if face {
                if face_list.is_none() {
                    return Err("a face has fewer than 3 vertices".into());
                }
                for k in 1..corners.len() - 1 {
                    mesh.triangles.push([corners[0], corners[k], corners[k + 1]]);
                }
            }
        }
    }
    Ok(mesh)
}

fn parse_ply_header(bytes: &[u8]) -> Result<(PlyFormat, Vec<PlyElement>, &[u8]), String> {
    const END: &[u8] = b"end_header";
    let end = bytes.windows(END.len()).position(|w| w == END).ok_or("not a PLY file (no end_header)")?;
    let mut body_start = end + END.len();
    while body_start < bytes.len() && bytes[body_start] != b'\n' {
        body_start += 1;
    }
    let header = std::str::from_utf8(&bytes[..end]).map_err(|_| "PLY header is not text")?;
    let mut lines = header.lines().enumerate();
    if lines.next().map(|(_, l)| l.trim()) != Some("ply") {
        return Err("not a PLY file (first line is not `ply`)".into());
    }
    let mut format = None;
    let mut elements: Vec<PlyElement> = vec![];
    for (no, line) in lines {
        let w: Vec<&str> = line.split_whitespace().collect();
        let bad = || format!("PLY header line {}: cannot read `{}`", no + 1, line.trim());
        match w.as_slice() {
            ["format", f, _] => {
                format = Some(match *f {
                    "ascii" => PlyFormat::Ascii,
                    "binary_little_endian" => PlyFormat::BinaryLe,
                    "binary_big_endian" => PlyFormat::BinaryBe,
                    _ => return Err(bad()),
                })
            }
            ["element", name, count] => {
                let count = count.parse::<usize>().map_err(|_| bad())?;
                if count > 1 << 28 {
                    return Err(format!("PLY element `{name}` has {count} items, too many to load"));
                }
                elements.push(PlyElement { name: name.to_string(), count, props: vec![] });
            }
            ["property", "list", ct, ty, name] => {
                let el = elements.last_mut().ok_or_else(bad)?;
                el.props.push(PlyProperty {
                    name: name.to_string(),
                    ty: PlyType::parse(ty).ok_or_else(bad)?,
                    list: Some(PlyType::parse(ct).ok_or_else(bad)?),
                });
            }
            ["property", ty, name] => {
                let el = elements.last_mut().ok_or_else(bad)?;
                el.props.push(PlyProperty {
                    name: name.to_string(),
                    ty: PlyType::parse(ty).ok_or_else(bad)?,
                    list: None,
                });
            }
            ["comment", ..] | ["obj_info", ..] | [] => {}
            _ => return Err(bad()),
        }
    }
    let format = format.ok_or("PLY header has no format line")?;
    Ok((format, elements, &bytes[(body_start + 1).min(bytes.len())..]))
}

/// Parses bicubic Bézier patches in the classic Newell text format (`.bpt`: the number of
/// patches, one line of 16 one-based control point indices per patch, the number of points, one
/// `x,y,z` line per point; `#` comments) and tessellates them to a chordal tolerance of 0.002.
pub fn parse_bpt(text: &str) -> Result<TriangleMesh, String> {
    use alhazen_geom::patch::{BezierPatch, Net};
    let mut lines = text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
    let mut next = |what: &str| lines.next().ok_or_else(|| format!("unexpected end of file, expected {what}"));
    let count = |(no, l): (usize, &str), what: &str| {
        l.trim().parse::<usize>().map_err(|_| format!("line {}: expected the number of {what}", no + 1))
    };
    let numbers = |(no, l): (usize, &str), n: usize| -> Result<Vec<f64>, String> {
        let v: Vec<f64> = l
            .split(',')
            .map(|x| x.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|_| format!("line {}: expected {n} comma-separated numbers", no + 1))?;
        if v.len() == n && v.iter().all(|x| x.is_finite()) {
            Ok(v)
        } else {
            Err(format!("line {}: expected {n} numbers, found {}", no + 1, v.len()))
        }
    };
    let np = count(next("the patch count")?, "patches")?;
    if np > 100_000 {
        return Err(format!("{np} patches is too many"));
    }
    let patches: Vec<(usize, Vec<f64>)> =
        (0..np).map(|_| next("patch indices").and_then(|l| Ok((l.0, numbers(l, 16)?)))).collect::<Result<_, _>>()?;
    let nv = count(next("the point count")?, "points")?;
    if nv > 1_000_000 {
        return Err(format!("{nv} points is too many"));
    }
    let points: Vec<Vec3> = (0..nv)
        .map(|_| next("a point").and_then(|l| numbers(l, 3)).map(|v| Vec3::new(v[0], v[1], v[2])))
        .collect::<Result<_, _>>()?;
    let mut mesh = TriangleMesh::default();
    for (no, idx) in patches {
        let net: Vec<Vec3> = idx
            .iter()
            .map(|&i| {
                if i >= 1.0 && i <= nv as f64 && i.fract() == 0.0 {
                    Ok(points[i as usize - 1])
                } else {
                    Err(format!("line {}: index {i} is not a point", no + 1))
                }
            })
            .collect::<Result<_, _>>()?;
        let part =
            alhazen_geom::tessellate::tessellate(&BezierPatch { net: Net::new(4, 4, net).expect("16 points") }, 0.002);
        let base = mesh.positions.len() as u32;
        mesh.positions.extend(part.positions);
        mesh.normals.extend(part.normals);
        mesh.uvs.extend(part.uvs);
        mesh.triangles.extend(part.triangles.iter().map(|t| t.map(|v| v + base)));
    }
    Ok(mesh)
}

/// Loads an image and converts it from sRGB to linear RGB.
pub fn load_image(path: &Path) -> Result<ImageData, String> {
    let img = image::open(path).map_err(|e| format!("cannot load image {}: {e}", path.display()))?.to_rgb8();
    has_pixels(path, img.width(), img.height())?;
    let table = std::array::from_fn(|i| srgb_to_linear(i as f64 / 255.0) as f32);
    Ok(ImageData::from_codes(img.width(), img.height(), table, img.pixels().map(|p| p.0).collect()))
}

/// Loads a cut-out's coverage ([`crate::Alpha`]): the image's alpha channel, or its first
/// channel where it has none, as the linear fractions the file holds (an 8-bit code `k` is
/// `k/255`, never decoded from sRGB), in all three channels.
pub fn load_coverage(path: &Path) -> Result<ImageData, String> {
    let img = image::open(path).map_err(|e| format!("cannot load image {}: {e}", path.display()))?;
    has_pixels(path, img.width(), img.height())?;
    let channel = if img.color().has_alpha() { 3 } else { 0 };
    let (w, h) = (img.width(), img.height());
    if img.color().bytes_per_pixel() == img.color().channel_count() {
        let table = std::array::from_fn(|k| k as f32 / 255.0);
        let codes = img.to_rgba8().pixels().map(|p| [p.0[channel]; 3]).collect();
        return Ok(ImageData::from_codes(w, h, table, codes));
    }
    let pixels: Vec<[f32; 3]> = img.to_rgba32f().pixels().map(|p| [p.0[channel]; 3]).collect();
    if pixels.iter().any(|p| !(0.0..=1.0).contains(&p[0])) {
        return Err(format!("{}: a coverage must lie in [0, 1]; the image has other values", path.display()));
    }
    Ok(ImageData::new(w, h, pixels))
}

/// Refuses an image of no pixels (a header saying 0 × 2: found by fuzzing, it made texture
/// lookups divide by zero).
fn has_pixels(path: &Path, w: u32, h: u32) -> Result<(), String> {
    if w == 0 || h == 0 {
        return Err(format!("{}: the image is {w} × {h} pixels: it has none", path.display()));
    }
    Ok(())
}

/// Loads an environment map's radiance: a floating-point image (Radiance `.hdr`, OpenEXR) as
/// its values, an image of integers (8- or 16-bit PNG, JPEG) decoded from sRGB, as Blender,
/// Mitsuba and pbrt read such a map.
pub fn load_radiance_image(path: &Path) -> Result<ImageData, String> {
    let img = open_image(path)?;
    let srgb = !matches!(img.color(), image::ColorType::Rgb32F | image::ColorType::Rgba32F);
    linear_pixels(path, img, srgb)
}

/// Loads a high-dynamic-range image (Radiance `.hdr` or OpenEXR), whose values are linear
/// radiance already, or any image's values read linearly (normal maps).
pub fn load_hdr_image(path: &Path) -> Result<ImageData, String> {
    linear_pixels(path, open_image(path)?, false)
}

fn open_image(path: &Path) -> Result<image::DynamicImage, String> {
    image::open(path).map_err(|e| format!("cannot load image {}: {e}", path.display()))
}

/// An image's values as floats, decoded from sRGB when `srgb`; refused when some are negative,
/// infinite or NaN.
fn linear_pixels(path: &Path, img: image::DynamicImage, srgb: bool) -> Result<ImageData, String> {
    let img = img.to_rgb32f();
    has_pixels(path, img.width(), img.height())?;
    let decode = |c: f32| if srgb { srgb_to_linear(c as f64) as f32 } else { c };
    let pixels: Vec<[f32; 3]> = img.pixels().map(|p| p.0.map(decode)).collect();
    if pixels.iter().flatten().any(|v| !v.is_finite() || *v < 0.0) {
        return Err(format!("{}: the image has negative, infinite or NaN values", path.display()));
    }
    Ok(ImageData::new(img.width(), img.height(), pixels))
}

#[cfg(test)]
mod tests {
    use super::*;

    const ASCII_QUAD: &str = "ply\nformat ascii 1.0\ncomment a unit square\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n";

    #[test]
    fn ascii_ply_quad_is_fan_triangulated() {
        let m = parse_ply(ASCII_QUAD.as_bytes()).unwrap();
        assert_eq!(m.positions.len(), 4);
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    }

    #[test]
    fn binary_ply_matches_ascii() {
        for big in [false, true] {
            let fmt = if big { "binary_big_endian" } else { "binary_little_endian" };
            let mut b = format!("ply\nformat {fmt} 1.0\nelement vertex 3\nproperty double x\nproperty double y\nproperty double z\nelement face 1\nproperty list uchar uint vertex_indices\nend_header\n").into_bytes();
            for v in [[0.0f64, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 2.0, 0.5]] {
                for x in v {
                    b.extend(if big { x.to_be_bytes() } else { x.to_le_bytes() });
                }
            }
            b.push(3);
            for i in [0u32, 1, 2] {
                b.extend(if big { i.to_be_bytes() } else { i.to_le_bytes() });
            }
            let m = parse_ply(&b).unwrap();
            assert_eq!(m.positions[2], Vec3::new(0.0, 2.0, 0.5));
            assert_eq!(m.triangles, vec![[0, 1, 2]]);
        }
    }

    /// Every binary type in both byte orders reads back the value written: the vertex's
    /// coordinates in each type, the face's list count and indices in each integer type.
    #[test]
    fn binary_ply_reads_every_type_in_both_orders() {
        type Encode = fn(f64, bool) -> Vec<u8>;
        fn bytes<const N: usize>(le: [u8; N], big: bool) -> Vec<u8> {
            let mut b = le.to_vec();
            if big {
                b.reverse();
            }
            b
        }
        // Name, encoding, integer, signed.
        let types: [(&str, Encode, bool, bool); 8] = [
            ("char", |x, big| bytes((x as i8).to_le_bytes(), big), true, true),
            ("uchar", |x, big| bytes((x as u8).to_le_bytes(), big), true, false),
            ("short", |x, big| bytes((x as i16).to_le_bytes(), big), true, true),
            ("ushort", |x, big| bytes((x as u16).to_le_bytes(), big), true, false),
            ("int", |x, big| bytes((x as i32).to_le_bytes(), big), true, true),
            ("uint", |x, big| bytes((x as u32).to_le_bytes(), big), true, false),
            ("float", |x, big| bytes((x as f32).to_le_bytes(), big), false, true),
            ("double", |x, big| bytes(x.to_le_bytes(), big), false, true),
        ];
        for big in [false, true] {
            let order = if big { "binary_big_endian" } else { "binary_little_endian" };
            for (name, encode, integer, signed) in types {
                // A negative coordinate where the type has a sign.
                let corners = [[0.0, 0.0, 0.0], [3.0, 0.0, 0.0], [0.0, 2.0, if signed { -1.0 } else { 1.0 }]];
                let list = if integer { name } else { "uchar" };
                let mut b = format!(
                    "ply\nformat {order} 1.0\nelement vertex 3\nproperty {name} x\nproperty {name} y\n\
                     property {name} z\nelement face 1\nproperty list {list} {list} vertex_indices\nend_header\n"
                )
                .into_bytes();
                let index = if integer { encode } else { types[1].1 };
                corners.iter().flatten().for_each(|&x| b.extend(encode(x, big)));
                [3.0, 2.0, 0.0, 1.0].iter().for_each(|&i| b.extend(index(i, big)));
                let m = parse_ply(&b).unwrap_or_else(|e| panic!("{order} {name}: {e}"));
                assert_eq!(m.positions, corners.map(Vec3::from_array).to_vec(), "{order} {name}");
                assert_eq!(m.triangles, vec![[2, 0, 1]], "{order} {name}");
                // One byte short: an error, not a panic.
                assert!(parse_ply(&b[..b.len() - 1]).is_err(), "{order} {name}");
            }
        }
    }

    /// One mesh written as ASCII and in either binary order: vertices of floats, colour codes
    /// and doubles interleaved, polygons of three to five corners, and maybe a face property
    /// after the index list.
    fn ply_in(format: &str, vertices: &[[f32; 5]], faces: &[Vec<u32>], face_flag: bool) -> Vec<u8> {
        let flag = if face_flag { "property uchar flags\n" } else { "" };
        let mut b = format!(
            "ply\nformat {format} 1.0\nelement vertex {}\nproperty float x\nproperty uchar red\nproperty float y\n\
             property float z\nproperty uchar green\nproperty uchar blue\nproperty double u\nproperty double v\n\
             element face {}\nproperty list uchar int vertex_indices\n{flag}end_header\n",
            vertices.len(),
            faces.len()
        )
        .into_bytes();
        let big = format == "binary_big_endian";
        let put = |b: &mut Vec<u8>, le: &[u8], text: String| match format {
            "ascii" => b.extend(format!("{text} ").bytes()),
            _ if big => b.extend(le.iter().rev()),
            _ => b.extend(le),
        };
        for v in vertices {
            put(&mut b, &v[0].to_le_bytes(), f64::from(v[0]).to_string());
            put(&mut b, &[v[3] as u8], (v[3] as u8).to_string());
            put(&mut b, &v[1].to_le_bytes(), f64::from(v[1]).to_string());
            put(&mut b, &v[2].to_le_bytes(), f64::from(v[2]).to_string());
            put(&mut b, &[v[4] as u8], (v[4] as u8).to_string());
            put(&mut b, &[7], "7".into());
            put(&mut b, &f64::from(v[0]).to_le_bytes(), f64::from(v[0]).to_string());
            put(&mut b, &f64::from(v[1]).to_le_bytes(), f64::from(v[1]).to_string());
        }
        for f in faces {
            put(&mut b, &[f.len() as u8], f.len().to_string());
            f.iter().for_each(|&i| put(&mut b, &(i as i32).to_le_bytes(), i.to_string()));
            if face_flag {
                put(&mut b, &[1], "1".into());
            }
        }
        b
    }

    proptest::proptest! {
        /// Both binary orders read as ASCII does, and ASCII reads what was written.
        #[test]
        fn binary_ply_reads_as_ascii_does(
            vertices in proptest::collection::vec(proptest::array::uniform5(-100.0f32..255.0), 3..12),
            faces in proptest::collection::vec(proptest::collection::vec(0u32..12, 3..6), 0..6),
            face_flag: bool,
            cut in 0usize..40,
        ) {
            let faces: Vec<Vec<u32>> = faces.iter().map(|f| f.iter().map(|&i| i % vertices.len() as u32).collect()).collect();
            let vertices: Vec<[f32; 5]> = vertices.iter().map(|v| [v[0], v[1], v[2], v[3].abs(), v[4].abs()]).collect();
            let ascii = parse_ply(&ply_in("ascii", &vertices, &faces, face_flag)).unwrap();
            let fan: usize = faces.iter().map(|f| f.len() - 2).sum();
            let written: Vec<Vec3> = vertices.iter().map(|v| Vec3::new(v[0].into(), v[1].into(), v[2].into())).collect();
            proptest::prop_assert_eq!(&ascii.positions, &written);
            proptest::prop_assert_eq!(ascii.triangles.len(), fan);
            proptest::prop_assert_eq!(ascii.uvs.len(), vertices.len());
            for format in ["binary_little_endian", "binary_big_endian"] {
                let b = ply_in(format, &vertices, &faces, face_flag);
                let m = parse_ply(&b).unwrap();
                proptest::prop_assert_eq!(&m.positions, &ascii.positions);
                proptest::prop_assert_eq!(&m.colors, &ascii.colors);
                proptest::prop_assert_eq!(&m.uvs, &ascii.uvs);
                proptest::prop_assert_eq!(&m.triangles, &ascii.triangles);
                // Cut anywhere in the body: an error, not a panic or a shorter mesh.
                let body = b.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
                let at = body + cut * (b.len() - body) / 40;
                proptest::prop_assert!(at == b.len() || parse_ply(&b[..at]).is_err());
            }
        }
    }

    #[test]
    fn the_teapot_data_set_tessellates() {
        let text =
            std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/data/teapot.bpt")).unwrap();
        let m = parse_bpt(&text).unwrap();
        m.validate().unwrap();
        let b = m.bounds();
        // The classic teapot: 3.15 high, about 6.4 from spout to handle.
        assert!((b.max.z - 3.15).abs() < 1e-9 && b.min.z.abs() < 1e-9, "{b:?}");
        assert!((b.max.x - b.min.x) > 6.0 && (b.max.x - b.min.x) < 6.6);
        assert!(parse_bpt("1\n1,2,3\n").unwrap_err().contains("line 2"));
        assert!(parse_bpt("1\n1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,9\n1\n0,0,0\n").unwrap_err().contains("index 9"));
    }

    #[test]
    fn truncated_ply_is_an_error_not_a_panic() {
        let cut = &ASCII_QUAD.as_bytes()[..ASCII_QUAD.len() - 6];
        assert!(parse_ply(cut).is_err());
        assert!(parse_ply(b"hello").is_err());
        // Found by fuzzing (it indexed an empty list): a face's indices that are no list.
        let scalar = ASCII_QUAD.replace("property list uchar int vertex_indices", "property int vertex_indices");
        assert_ne!(scalar, ASCII_QUAD, "the fixture names its list as this test expects");
        assert!(parse_ply(scalar.as_bytes()).unwrap_err().contains("not a list"));
    }
}
