//! glTF's `EXT_meshopt_compression` and `KHR_meshopt_compression` (gltfpack's `-c`, many web
//! stores' files): buffer views whose bytes are stored compressed by meshoptimizer's codecs,
//! decoded here by hand from the extensions' bitstream specifications (Appendix A: attributes
//! — versions 0 and 1 —, triangles and indices; Appendix B: the octahedral, quaternion,
//! exponential and colour filters).
//!
//! Every compressed view is decoded into one new buffer and pointed at it before the glTF is
//! validated; the uncompressed placeholder ("fallback") buffers the extension allows, which
//! hold no data, are read as empty. The rest of the importer reads the views as any other.

use gltf::json::validation::USize64;
use gltf::json::{Index, Root, buffer};

/// The two extensions' names (the same bitstreams; KHR adds attribute version 1 and the colour
/// filter).
pub const EXTENSIONS: [&str; 2] = ["EXT_meshopt_compression", "KHR_meshopt_compression"];

/// A compressed view's parameters, as its extension object gives them.
struct Compressed {
    buffer: usize,
    offset: u64,
    length: u64,
    stride: usize,
    count: usize,
    mode: String,
    filter: String,
    khr: bool,
}

fn extension_of(view: &buffer::View) -> Option<(&serde_json::Value, bool)> {
    let others = &view.extensions.as_ref()?.others;
    others.get(EXTENSIONS[1]).map(|e| (e, true)).or_else(|| others.get(EXTENSIONS[0]).map(|e| (e, false)))
}

/// Gives the placeholder buffers of compressed views — buffers without a `uri` that are not a
/// binary glTF's own chunk (`has_blob`), whose data the views' extensions hold — an empty data
/// URI, so that the buffers can be read.
pub fn empty_placeholders(json: &mut Root, has_blob: bool) {
    let parents: Vec<usize> =
        json.buffer_views.iter().filter(|v| extension_of(v).is_some()).map(|v| v.buffer.value()).collect();
    for (i, b) in json.buffers.iter_mut().enumerate() {
        let blob = i == 0 && has_blob;
        if b.uri.is_none() && !blob && parents.contains(&i) {
            b.uri = Some("data:application/octet-stream;base64,".into());
            b.byte_length = USize64(0);
        }
    }
}

/// Decodes every compressed view of `json` into a buffer appended to `buffers`, refusing views
/// that would decode to more than `memory_budget` bytes in all before decoding any. Errors name
/// the view.
pub fn decompress(json: &mut Root, buffers: &mut Vec<gltf::buffer::Data>, memory_budget: u64) -> Result<(), String> {
    let mut jobs = Vec::new();
    for (i, view) in json.buffer_views.iter().enumerate() {
        if let Some((ext, khr)) = extension_of(view) {
            let c = parameters(ext, khr).map_err(|e| format!("buffer view {i}: its {} {e}", name(khr)))?;
            jobs.push((i, c));
        }
    }
    let total: u64 = jobs.iter().map(|(_, c)| (c.count as u64).saturating_mul(c.stride as u64)).sum();
    if total > memory_budget {
        return Err(format!(
            "its compressed buffer views decode to {total} bytes, more than the memory budget of {memory_budget}"
        ));
    }
    let mut out = Vec::with_capacity(total as usize);
    let new_buffer = json.buffers.len();
    for (i, c) in jobs {
        let name = name(c.khr);
        let view = &json.buffer_views[i];
        if view.byte_length.0 != (c.count * c.stride) as u64 {
            return Err(format!(
                "buffer view {i}: its {name} decodes {} elements of {} bytes, not its {} bytes",
                c.count, c.stride, view.byte_length.0
            ));
        }
        let data = compressed_bytes(buffers, &c).map_err(|e| format!("buffer view {i}: its {name} data {e}"))?;
        let start = out.len();
        out.resize(start + c.count * c.stride, 0);
        decode(&mut out[start..], data, &c).map_err(|e| format!("buffer view {i}: its {name} data {e}"))?;
        out.resize(out.len().next_multiple_of(4), 0);
        let view = &mut json.buffer_views[i];
        view.buffer = Index::new(new_buffer as u32);
        view.byte_offset = Some(USize64(start as u64));
    }
    crate::gltf::append_buffer(json, buffers, out, "decoded meshopt data");
    Ok(())
}

fn name(khr: bool) -> &'static str {
    EXTENSIONS[khr as usize]
}

/// The extension object's parameters, checked as the specification requires.
fn parameters(ext: &serde_json::Value, khr: bool) -> Result<Compressed, String> {
    let int = |key: &str| ext.get(key).and_then(|v| v.as_u64());
    let need = |key: &str| int(key).ok_or(format!("has no {key}"));
    let text = |key: &str, default: &str| ext.get(key).and_then(|v| v.as_str()).unwrap_or(default).to_string();
    let c = Compressed {
        buffer: need("buffer")? as usize,
        offset: int("byteOffset").unwrap_or(0),
        length: need("byteLength")?,
        stride: need("byteStride")?.min(1 << 16) as usize,
        count: need("count")?.min(u32::MAX as u64) as usize,
        mode: text("mode", ""),
        filter: text("filter", "NONE"),
        khr,
    };
    let ok = match (c.mode.as_str(), c.filter.as_str()) {
        ("ATTRIBUTES", "NONE") => c.stride.is_multiple_of(4) && (4..=256).contains(&c.stride),
        ("ATTRIBUTES", "OCTAHEDRAL") => c.stride == 4 || c.stride == 8,
        ("ATTRIBUTES", "COLOR") if khr => c.stride == 4 || c.stride == 8,
        ("ATTRIBUTES", "QUATERNION") => c.stride == 8,
        ("ATTRIBUTES", "EXPONENTIAL") => c.stride.is_multiple_of(4) && (4..=256).contains(&c.stride),
        ("TRIANGLES", "NONE") => (c.stride == 2 || c.stride == 4) && c.count.is_multiple_of(3),
        ("INDICES", "NONE") => c.stride == 2 || c.stride == 4,
        _ => return Err(format!("has mode {:?} and filter {:?}, which are not one of its codecs", c.mode, c.filter)),
    };
    if !ok {
        return Err(format!(
            "{} {} cannot have a byteStride of {} (and count {})",
            c.mode, c.filter, c.stride, c.count
        ));
    }
    Ok(c)
}

/// The compressed bytes, or why they cannot be had.
fn compressed_bytes<'a>(buffers: &'a [gltf::buffer::Data], c: &Compressed) -> Result<&'a [u8], String> {
    let data = buffers.get(c.buffer).ok_or(format!("is in buffer {}, which is not in the file", c.buffer))?;
    let end = c.offset.checked_add(c.length).filter(|&e| e <= data.0.len() as u64);
    let end = end.ok_or(format!("runs past the end of buffer {}", c.buffer))?;
    Ok(&data.0[c.offset as usize..end as usize])
}

fn decode(out: &mut [u8], data: &[u8], c: &Compressed) -> Result<(), String> {
    match c.mode.as_str() {
        "ATTRIBUTES" => {
            attributes(out, c.count, c.stride, data, c.khr)?;
            filter(out, c.stride, &c.filter);
            Ok(())
        }
        "TRIANGLES" => triangles(out, c.count, c.stride, data),
        _ => indices(out, c.count, c.stride, data),
    }
}

/// A cursor over a stream's bytes that fails rather than reading past its end.
struct Reader<'a> {
    data: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    fn byte(&mut self) -> Result<u8, String> {
        let b = *self.data.get(self.at).ok_or("ends early")?;
        self.at += 1;
        Ok(b)
    }

    fn take(&mut self, n: usize) -> Result<&'a [u8], String> {
        let s = self.data.get(self.at..self.at + n).ok_or("ends early")?;
        self.at += n;
        Ok(s)
    }

    /// An unsigned LEB128 integer of at most five bytes, wrapping to 32 bits.
    fn varint(&mut self) -> Result<u32, String> {
        let mut v = 0u32;
        for k in 0..5 {
            let b = self.byte()?;
            v |= ((b & 0x7f) as u32).wrapping_shl(7 * k);
            if b & 0x80 == 0 {
                return Ok(v);
            }
        }
        Err("has an index of more than five bytes".into())
    }

    fn finished(&self) -> Result<(), String> {
        if self.at == self.data.len() { Ok(()) } else { Err("has bytes left over after its last element".into()) }
    }
}

/// Mode 0: `count` elements of `stride` bytes from byte deltas in blocks (Appendix A).
fn attributes(out: &mut [u8], count: usize, stride: usize, data: &[u8], khr: bool) -> Result<(), String> {
    let header = *data.first().ok_or("is empty")?;
    let version = match header {
        0xa0 => 0,
        0xa1 if khr => 1,
        _ => return Err(format!("has header {header:#04x}, not an attribute stream's")),
    };
    let tail = stride + if version == 0 { 0 } else { stride / 4 };
    let padded = tail.max(if version == 0 { 32 } else { 24 });
    if data.len() < 1 + padded {
        return Err("ends early".into());
    }
    let mut last = data[data.len() - tail..][..stride].to_vec();
    let channels = &data[data.len() - tail + stride..];
    let mut body = Reader { data: &data[..data.len() - padded], at: 1 };
    let block = ((8192 / stride) & !15).min(256);
    let mut deltas = vec![0u8; block.next_multiple_of(16) * 4];
    let mut first = 0;
    while first < count {
        let n = block.min(count - first);
        let control = if version == 0 { &[][..] } else { body.take(stride / 4)? };
        for k in (0..stride).step_by(4) {
            let ctrl_byte = control.get(k / 4).copied().unwrap_or(0);
            for j in 0..4 {
                let lane = &mut deltas[j * n.next_multiple_of(16)..(j + 1) * n.next_multiple_of(16)];
                match (version, (ctrl_byte >> (2 * j)) & 3) {
                    (0, _) => byte_groups(&mut body, lane, [0, 2, 4, 8])?,
                    (_, 0) => byte_groups(&mut body, lane, [0, 1, 2, 4])?,
                    (_, 1) => byte_groups(&mut body, lane, [1, 2, 4, 8])?,
                    (_, 2) => lane.fill(0),
                    _ => lane[..n].copy_from_slice(body.take(n)?),
                }
            }
            let channel = if version == 0 { 0 } else { channels[k / 4] };
            let lanes = n.next_multiple_of(16);
            let elements = &mut out[first * stride..(first + n) * stride];
            undelta(elements, &deltas, lanes, n, stride, k, &mut last[k..k + 4], channel)?;
        }
        first += n;
    }
    body.finished()
}

/// One byte position's deltas of a block: 2-bit headers for its groups of 16, then each group's
/// deltas at the header's bit width out of `bits` (0: all zero; 8: bytes; else sentinel
/// coding, the sentinel's byte after the group's packed deltas).
fn byte_groups(body: &mut Reader, lane: &mut [u8], bits: [u32; 4]) -> Result<(), String> {
    let groups = lane.len() / 16;
    let header = body.take(groups.div_ceil(4))?;
    for g in 0..groups {
        let width = bits[((header[g / 4] >> (2 * (g % 4))) & 3) as usize];
        let group = &mut lane[16 * g..16 * g + 16];
        match width {
            0 => group.fill(0),
            8 => group.copy_from_slice(body.take(16)?),
            w => {
                let packed = body.take(2 * w as usize)?;
                let sentinel = (1u8 << w) - 1;
                for (i, d) in group.iter_mut().enumerate() {
                    let bit = i * w as usize;
                    let byte = packed[bit / 8];
                    // 1-bit deltas run from the least significant bit, wider ones from the most.
                    let v = if w == 1 { byte >> (bit % 8) } else { byte >> (8 - w as usize - bit % 8) } & sentinel;
                    *d = if v == sentinel { body.byte()? } else { v };
                }
            }
        }
    }
    Ok(())
}

/// Turns four byte positions' deltas (`deltas`, one lane of `lanes` per byte) of `n` elements
/// into their values at bytes `k..k + 4` of each element, from `last` (the previous element's,
/// updated), by the channel's mode: byte deltas, 2-byte deltas, or 4-byte XOR deltas rotated.
fn undelta(
    elements: &mut [u8],
    deltas: &[u8],
    lanes: usize,
    n: usize,
    stride: usize,
    k: usize,
    last: &mut [u8],
    channel: u8,
) -> Result<(), String> {
    let width = match channel & 0x0f {
        0 => 1,
        1 => 2,
        2 => 4,
        c => return Err(format!("has channel mode {c}, not one of its codecs'")),
    };
    if width < 4 && channel >> 4 != 0 {
        return Err(format!("has channel byte {channel:#04x}, not one of its codecs'"));
    }
    let rotation = (32 - (channel >> 4) as u32) & 31;
    for part in (0..4).step_by(width) {
        let mut prev = (0..width).fold(0u32, |v, j| v | (last[part + j] as u32) << (8 * j));
        for i in 0..n {
            let d = (0..width).fold(0u32, |v, j| v | (deltas[(part + j) * lanes + i] as u32) << (8 * j));
            let v = match width {
                1 => prev.wrapping_add(unzigzag(d, 8)) & 0xff,
                2 => prev.wrapping_add(unzigzag(d, 16)) & 0xffff,
                _ => d.rotate_left(rotation) ^ prev,
            };
            for j in 0..width {
                elements[i * stride + k + part + j] = (v >> (8 * j)) as u8;
            }
            prev = v;
        }
        for j in 0..width {
            last[part + j] = (prev >> (8 * j)) as u8;
        }
    }
    Ok(())
}

/// A zigzag code of `bits` bits as the signed difference it codes (two's complement, 32 bits).
fn unzigzag(v: u32, bits: u32) -> u32 {
    let mask = if bits == 32 { u32::MAX } else { (1 << bits) - 1 };
    if v & 1 == 1 { !(v >> 1) & mask } else { v >> 1 }
}

/// A FIFO of the 16 most recent edges or vertices of a triangle stream (Appendix A, mode 1).
struct Recent<T: Copy> {
    items: [T; 16],
    at: usize,
}

impl<T: Copy> Recent<T> {
    fn push(&mut self, v: T) {
        self.items[self.at] = v;
        self.at = (self.at + 1) % 16;
    }

    /// The `back`-th most recent item (0: the last pushed).
    fn get(&self, back: usize) -> T {
        self.items[(self.at + 31 - back) % 16]
    }
}

/// The decoder's state over a triangle stream: the next new vertex, the last explicit index.
struct Counters {
    next: u32,
    last: u32,
}

impl Counters {
    fn new_vertex(&mut self) -> u32 {
        self.next = self.next.wrapping_add(1);
        self.next.wrapping_sub(1)
    }

    /// An explicit index: a zigzag delta from the last one.
    fn explicit(&mut self, extra: &mut Reader) -> Result<u32, String> {
        self.last = self.last.wrapping_add(unzigzag(extra.varint()?, 32));
        Ok(self.last)
    }
}

/// Mode 1: a triangle list from one code per triangle over a FIFO of recent edges and one of
/// recent vertices.
fn triangles(out: &mut [u8], count: usize, stride: usize, data: &[u8]) -> Result<(), String> {
    let triangles = count / 3;
    if data.first() != Some(&0xe1) {
        return Err("does not start as a triangle stream".into());
    }
    if data.len() < 1 + triangles + 16 {
        return Err("ends early".into());
    }
    let codes = &data[1..1 + triangles];
    let aux = &data[data.len() - 16..];
    let mut extra = Reader { data: &data[1 + triangles..data.len() - 16], at: 0 };
    let mut n = Counters { next: 0, last: 0 };
    let mut edges = Recent { items: [(0u32, 0u32); 16], at: 0 };
    let mut vertices = Recent { items: [0u32; 16], at: 0 };
    for (t, &code) in codes.iter().enumerate() {
        let (hi, lo) = ((code >> 4) as usize, (code & 15) as usize);
        let tri = if hi < 15 {
            // A recent edge and a third vertex: new, recent, beside the last, or explicit.
            let (a, b) = edges.get(hi);
            let c = match lo {
                0 => n.new_vertex(),
                1..=12 => vertices.get(lo),
                13 | 14 => {
                    n.last = if lo == 13 { n.last.wrapping_sub(1) } else { n.last.wrapping_add(1) };
                    n.last
                }
                _ => n.explicit(&mut extra)?,
            };
            edges.push((c, b));
            edges.push((a, c));
            if lo == 0 || lo >= 13 {
                vertices.push(c);
            }
            [a, b, c]
        } else {
            // Three vertices: by the table (`0xfY`) or a byte of their own (`0xfe`, `0xff`).
            let explicit = lo >= 14;
            let zw = if explicit { extra.byte()? } else { aux[lo] };
            if explicit && zw == 0 {
                n.next = 0;
            }
            let a = if lo == 15 { n.explicit(&mut extra)? } else { n.new_vertex() };
            let (z, w) = ((zw >> 4) as usize, (zw & 15) as usize);
            let mut other = |sel: usize| match sel {
                0 => Ok(n.new_vertex()),
                15 if explicit => n.explicit(&mut extra),
                s => Ok(vertices.get(s - 1)),
            };
            let b = other(z)?;
            let c = other(w)?;
            edges.push((b, a));
            edges.push((c, b));
            edges.push((a, c));
            vertices.push(a);
            if z == 0 || (explicit && z == 15) {
                vertices.push(b);
            }
            if w == 0 || (explicit && w == 15) {
                vertices.push(c);
            }
            [a, b, c]
        };
        for (j, v) in tri.into_iter().enumerate() {
            put_index(out, stride, 3 * t + j, v);
        }
    }
    extra.finished()
}

/// Mode 2: indices as deltas from one of two baselines.
fn indices(out: &mut [u8], count: usize, stride: usize, data: &[u8]) -> Result<(), String> {
    if data.first() != Some(&0xd1) || data.len() < 5 {
        return Err("does not start as an index stream".into());
    }
    let mut body = Reader { data: &data[..data.len() - 4], at: 1 };
    let mut last = [0u32; 2];
    for i in 0..count {
        let v = body.varint()?;
        let baseline = (v & 1) as usize;
        last[baseline] = last[baseline].wrapping_add(unzigzag(v >> 1, 32));
        put_index(out, stride, i, last[baseline]);
    }
    body.finished()
}

fn put_index(out: &mut [u8], stride: usize, i: usize, v: u32) {
    if stride == 2 {
        out[2 * i..2 * i + 2].copy_from_slice(&(v as u16).to_le_bytes());
    } else {
        out[4 * i..4 * i + 4].copy_from_slice(&v.to_le_bytes());
    }
}

/// Appendix B's filters, applied to the decoded elements in place.
fn filter(out: &mut [u8], stride: usize, filter: &str) {
    match (filter, stride) {
        ("OCTAHEDRAL", 4) => out.chunks_exact_mut(4).for_each(|e| {
            let v = octahedral([e[0] as i8 as f32, e[1] as i8 as f32, e[2] as i8 as f32], 127.0);
            e[..3].copy_from_slice(&v.map(|x| x as i8 as u8));
        }),
        ("OCTAHEDRAL", _) => out.chunks_exact_mut(8).for_each(|e| {
            let v = octahedral([0, 1, 2].map(|i| i16::from_le_bytes([e[2 * i], e[2 * i + 1]]) as f32), 32767.0);
            for i in 0..3 {
                e[2 * i..2 * i + 2].copy_from_slice(&(v[i] as i16).to_le_bytes());
            }
        }),
        ("QUATERNION", _) => out.chunks_exact_mut(8).for_each(quaternion),
        ("EXPONENTIAL", _) => out.chunks_exact_mut(4).for_each(|e| {
            let input = i32::from_le_bytes([e[0], e[1], e[2], e[3]]);
            let (exponent, mantissa) = (input >> 24, (input << 8) >> 8);
            let v = (mantissa as f32) * 2f32.powi(exponent);
            e.copy_from_slice(&v.to_le_bytes());
        }),
        ("COLOR", 4) => out.chunks_exact_mut(4).for_each(|e| {
            let rgba = color([e[0] as i32, e[1] as i8 as i32, e[2] as i8 as i32, e[3] as i32], 255.0);
            e.copy_from_slice(&rgba.map(|x| x as u8));
        }),
        ("COLOR", _) => out.chunks_exact_mut(8).for_each(|e| {
            let c = |i: usize| [e[2 * i], e[2 * i + 1]];
            let input = [
                u16::from_le_bytes(c(0)) as i32,
                i16::from_le_bytes(c(1)) as i32,
                i16::from_le_bytes(c(2)) as i32,
                u16::from_le_bytes(c(3)) as i32,
            ];
            let rgba = color(input, 65535.0);
            for i in 0..4 {
                e[2 * i..2 * i + 2].copy_from_slice(&(rgba[i] as u16).to_le_bytes());
            }
        }),
        _ => {}
    }
}

/// An octahedrally coded unit vector (`x`, `y` and the code's 1.0) as normalised integers of
/// maximum `max`, rounded half away from zero.
fn octahedral([x, y, one]: [f32; 3], max: f32) -> [f32; 3] {
    let (mut x, mut y) = (x / one, y / one);
    let z = 1.0 - x.abs() - y.abs();
    let t = z.min(0.0);
    x -= t.copysign(x);
    y -= t.copysign(y);
    let len = (x * x + y * y + z * z).sqrt();
    [x, y, z].map(|c| (c / len * max).round())
}

/// A quaternion of three coded components and the index of the omitted largest one, as four
/// normalised 16-bit integers.
fn quaternion(e: &mut [u8]) {
    let input: [i16; 4] = [0, 1, 2, 3].map(|i| i16::from_le_bytes([e[2 * i], e[2 * i + 1]]));
    let range = std::f32::consts::FRAC_1_SQRT_2;
    let one = (input[3] | 3) as f32;
    let [x, y, z] = [0, 1, 2].map(|i| input[i] as f32 / one * range);
    let w = (1.0 - x * x - y * y - z * z).max(0.0).sqrt();
    let largest = (input[3] & 3) as usize;
    let mut q = [0i16; 4];
    for (k, v) in [w, x, y, z].into_iter().enumerate() {
        q[(largest + k) % 4] = (v * 32767.0).round() as i16;
    }
    for i in 0..4 {
        e[2 * i..2 * i + 2].copy_from_slice(&q[i].to_le_bytes());
    }
}

/// A YCoCg colour with its alpha's scale bit as RGBA normalised to `max`.
fn color([y, co, cg, alpha]: [i32; 4], max: f32) -> [f32; 4] {
    let msb = 31 - (alpha.max(1) as u32).leading_zeros();
    let scale = (1i32 << (msb + 1)) - 1;
    let a = alpha & (scale >> 1);
    let a = (a << 1) | (a & 1);
    let s = max / scale as f32;
    [y + co - cg, y + cg, y - co - cg, a].map(|v| (v as f32 * s).round().clamp(0.0, max))
}
