//! glTF's `KHR_draco_mesh_compression`: a primitive whose vertices and triangles are one Draco
//! bitstream in a buffer view, decoded with the `draco-core` crate (Google's Draco format, as
//! Blender's glTF exporter writes it under "Compression").
//!
//! The file's streams are decoded on all threads; the decoded attributes and triangles are
//! then written, in the file's order, into one new buffer, each behind a buffer
//! view and accessor of its own (of the component type and width the primitive's accessor
//! declares, so normalised integers stay normalised), and the primitive's attributes and
//! indices are pointed at them before the glTF is validated: the rest of the importer reads a
//! decompressed primitive as any other. Attributes the extension does not list keep their own
//! (uncompressed) accessors, as the extension specifies.

use draco_core::decode_limits::DecodeLimits;
use draco_core::decoder_buffer::DecoderBuffer;
use draco_core::draco_types::DataType as DracoType;
use draco_core::mesh::Mesh;
use draco_core::mesh_decoder::MeshDecoder;
use gltf::json::accessor::{ComponentType, GenericComponentType, Type};
use gltf::json::validation::{Checked, USize64};
use gltf::json::{Accessor, Index, Root, buffer};
use rayon::prelude::*;

/// The extension's name.
pub const EXTENSION: &str = "KHR_draco_mesh_compression";

/// Decompresses every Draco primitive of `json` into a buffer appended to `buffers` (whose
/// entries are the file's buffers, by index): the streams decoded on all threads, each refused
/// if it would decode to more than `memory_budget` bytes before it is decoded, and all of them
/// if their data come to more. Errors name the mesh and primitive (the first in the file's
/// order).
pub fn decompress(json: &mut Root, buffers: &mut Vec<gltf::buffer::Data>, memory_budget: u64) -> Result<(), String> {
    let mut jobs = Vec::new();
    for (m, mesh) in json.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            if let Some(ext) = prim.extensions.as_ref().and_then(|e| e.others.get(EXTENSION)) {
                jobs.push((m, p, ext.clone()));
            }
        }
    }
    let decoded: Vec<Result<Mesh, String>> =
        jobs.par_iter().map(|(_, _, ext)| decode(json, buffers, ext, memory_budget)).collect();
    let mut out = Vec::new();
    let new_buffer = Index::new(json.buffers.len() as u32);
    for ((m, p, ext), mesh) in jobs.iter().zip(decoded) {
        let name = match &json.meshes[*m].name {
            Some(n) => format!("mesh \"{n}\" primitive {p}"),
            None => format!("mesh {m} primitive {p}"),
        };
        let located = |e: String| format!("{name}: its {EXTENSION} data {e}");
        let mesh = mesh.map_err(located)?;
        decompress_primitive(json, (*m, *p), ext, &mesh, new_buffer, &mut out).map_err(located)?;
        if out.len() as u64 > memory_budget {
            return Err(located(format!(
                "and the primitives before it decode to more than the memory budget of {memory_budget} bytes"
            )));
        }
    }
    crate::gltf::append_buffer(json, buffers, out, "decoded Draco data");
    Ok(())
}

/// The mesh of the Draco stream `ext` names, decoded within `memory_budget` bytes.
fn decode(
    json: &Root,
    buffers: &[gltf::buffer::Data],
    ext: &serde_json::Value,
    memory_budget: u64,
) -> Result<Mesh, String> {
    let view = ext.get("bufferView").and_then(|v| v.as_u64()).ok_or("names no bufferView")?;
    let bytes = view_bytes(json, buffers, view)?;
    let limits = DecodeLimits::default().with_max_decoded_bytes(memory_budget);
    let mut stream = DecoderBuffer::new(bytes).with_limits(limits);
    let mut mesh = Mesh::new();
    MeshDecoder::new().decode(&mut stream, &mut mesh).map_err(|e| format!("cannot be decoded: {e}"))?;
    Ok(mesh)
}

/// Writes `mesh`'s attributes and triangles, as extension object `ext` of primitive `p` of
/// mesh `m` assigns them, into `out` (buffer `new_buffer`), and points the primitive at them.
fn decompress_primitive(
    json: &mut Root,
    (m, p): (usize, usize),
    ext: &serde_json::Value,
    mesh: &Mesh,
    new_buffer: Index<buffer::Buffer>,
    out: &mut Vec<u8>,
) -> Result<(), String> {
    let points = mesh.num_points();
    let attributes = ext.get("attributes").and_then(|a| a.as_object()).ok_or("names no attributes")?;
    for (semantic, id) in attributes {
        let id = id.as_u64().filter(|&i| i <= u32::MAX as u64).ok_or(format!("gives {semantic} no attribute id"))?;
        let attribute =
            mesh.attribute_by_unique_id(id as u32).ok_or(format!("has no attribute {id} (the file's {semantic})"))?;
        let prim = &json.meshes[m].primitives[p];
        let target = prim
            .attributes
            .iter()
            .find(|(s, _)| semantic_name(s).as_deref() == Some(semantic.as_str()))
            .map(|(_, a)| a.value())
            .ok_or(format!("compresses {semantic}, which the primitive does not have"))?;
        let template = json
            .accessors
            .get(target)
            .ok_or(format!("names {semantic}'s accessor {target}, which is not in the file"))?;
        let (kind, components) =
            element(template).ok_or(format!("compresses {semantic}, whose accessor has no valid type"))?;
        let floats = attribute.read_f32s(points, components);
        let from_floats = matches!(attribute.data_type(), DracoType::Float32 | DracoType::Float64);
        let start = out.len();
        for v in floats {
            write_component(out, kind, template.normalized && from_floats, v);
        }
        let accessor = Accessor { count: USize64(points as u64), ..accessor_like(template) };
        let index = push_accessor(json, accessor, new_buffer, start, out);
        // The placeholder (which has no data) reads the decoded values too, for validation.
        if json.accessors[target].buffer_view.is_none() {
            json.accessors[target] = json.accessors[index.value()].clone();
        }
        let prim = &mut json.meshes[m].primitives[p];
        let slot = prim.attributes.iter_mut().find(|(s, _)| semantic_name(s).as_deref() == Some(semantic.as_str()));
        if let Some((_, a)) = slot {
            *a = index;
        }
    }
    let start = out.len();
    for face in mesh.faces() {
        for corner in face {
            out.extend_from_slice(&corner.0.to_le_bytes());
        }
    }
    let indices = Accessor {
        buffer_view: None,
        byte_offset: None,
        count: USize64(3 * mesh.num_faces() as u64),
        component_type: Checked::Valid(GenericComponentType(ComponentType::U32)),
        extensions: None,
        extras: Default::default(),
        type_: Checked::Valid(Type::Scalar),
        min: None,
        max: None,
        name: None,
        normalized: false,
        sparse: None,
    };
    let index = push_accessor(json, indices, new_buffer, start, out);
    let prim = &mut json.meshes[m].primitives[p];
    if let Some(old) = prim.indices.replace(index).map(|i| i.value())
        && json.accessors.get(old).is_some_and(|a| a.buffer_view.is_none())
    {
        json.accessors[old] = json.accessors[index.value()].clone();
    }
    let prim = &mut json.meshes[m].primitives[p];
    // Draco's faces are triangles, whatever the primitive's mode said they were drawn as.
    prim.mode = Checked::Valid(gltf::json::mesh::Mode::Triangles);
    Ok(())
}

/// The bytes of buffer view `view` of `json`, or why they cannot be had.
fn view_bytes<'a>(json: &Root, buffers: &'a [gltf::buffer::Data], view: u64) -> Result<&'a [u8], String> {
    let v =
        json.buffer_views.get(view as usize).ok_or(format!("names buffer view {view}, which is not in the file"))?;
    let data =
        buffers.get(v.buffer.value()).ok_or(format!("is in buffer {}, which is not in the file", v.buffer.value()))?;
    let start = v.byte_offset.map_or(0, |o| o.0);
    let end = start.checked_add(v.byte_length.0).filter(|&e| e <= data.0.len() as u64);
    let end = end.ok_or(format!("runs past the end of buffer {}", v.buffer.value()))?;
    Ok(&data.0[start as usize..end as usize])
}

/// An accessor's component type and number of components, if both are valid.
fn element(a: &Accessor) -> Option<(ComponentType, usize)> {
    let Checked::Valid(GenericComponentType(kind)) = a.component_type else { return None };
    let Checked::Valid(t) = a.type_ else { return None };
    Some((kind, t.multiplicity()))
}

/// A new accessor of `template`'s type and bounds, without data of its own yet.
fn accessor_like(template: &Accessor) -> Accessor {
    Accessor {
        buffer_view: None,
        byte_offset: None,
        count: template.count,
        component_type: template.component_type,
        extensions: None,
        extras: Default::default(),
        type_: template.type_,
        min: template.min.clone(),
        max: template.max.clone(),
        name: template.name.clone(),
        normalized: template.normalized,
        sparse: None,
    }
}

/// Adds `accessor` to `json`, reading `out[start..]` through a view of its own in buffer
/// `new_buffer`; pads `out` to four bytes so that the next view starts aligned.
fn push_accessor(
    json: &mut Root,
    mut accessor: Accessor,
    new_buffer: Index<buffer::Buffer>,
    start: usize,
    out: &mut Vec<u8>,
) -> Index<Accessor> {
    json.buffer_views.push(buffer::View {
        buffer: new_buffer,
        byte_length: USize64((out.len() - start) as u64),
        byte_offset: Some(USize64(start as u64)),
        byte_stride: None,
        name: None,
        target: None,
        extensions: None,
        extras: Default::default(),
    });
    out.resize(out.len().next_multiple_of(4), 0);
    accessor.buffer_view = Some(Index::new(json.buffer_views.len() as u32 - 1));
    json.accessors.push(accessor);
    Index::new(json.accessors.len() as u32 - 1)
}

/// Writes decoded value `v` as one component of type `kind`: a float as it is; an integer
/// attribute's value as that integer; a float attribute into a normalised integer accessor
/// scaled to the type's range (`normalise`).
fn write_component(out: &mut Vec<u8>, kind: ComponentType, normalise: bool, v: f32) {
    let int = |max: f32| if normalise { (v.clamp(-1.0, 1.0) * max).round() } else { v.round() };
    match kind {
        ComponentType::F32 => out.extend_from_slice(&v.to_le_bytes()),
        ComponentType::U8 => out.push(int(255.0) as u8),
        ComponentType::I8 => out.push(int(127.0) as i8 as u8),
        ComponentType::U16 => out.extend_from_slice(&(int(65535.0) as u16).to_le_bytes()),
        ComponentType::I16 => out.extend_from_slice(&(int(32767.0) as i16).to_le_bytes()),
        ComponentType::U32 => out.extend_from_slice(&(v.round() as u32).to_le_bytes()),
    }
}

/// A glTF attribute semantic's name as the file spells it (`POSITION`, `TEXCOORD_0`, …).
fn semantic_name(s: &Checked<gltf::json::mesh::Semantic>) -> Option<String> {
    match s {
        Checked::Valid(s) => Some(s.to_string()),
        Checked::Invalid => None,
    }
}
