//! A drawing on paper — polylines in millimetres on layers — and its three outputs: SVG (a
//! group per layer), PDF (an optional-content layer per layer, written by hand: the format's
//! few objects need no library) and an antialiased PNG preview (coverage from the exact
//! distance of each pixel centre to each segment).

use alhazen_math::Vec2;
use std::fmt::Write;

/// The layers of a line drawing.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Layer {
    /// Lines seen directly.
    Visible,
    /// Lines hidden by surfaces (drawn dashed when asked for).
    Hidden,
    /// Lines seen in a mirror.
    Reflected,
    /// The left eye's lines of a red–cyan anaglyph (visible and reflected).
    Left,
    /// The right eye's lines of a red–cyan anaglyph.
    Right,
}

impl Layer {
    /// All layers, bottom to top.
    pub const ALL: [Layer; 5] = [Layer::Hidden, Layer::Reflected, Layer::Visible, Layer::Left, Layer::Right];

    /// All layers in the order of their pens.
    pub const BY_PEN: [Layer; 5] = [Layer::Visible, Layer::Reflected, Layer::Hidden, Layer::Left, Layer::Right];

    /// The layer's number: its pen on a plotter, its layer in vpype and Inkscape (visible 1,
    /// reflected 2, hidden 3; an anaglyph's left eye 4, right eye 5).
    pub fn pen(self) -> u32 {
        match self {
            Layer::Visible => 1,
            Layer::Reflected => 2,
            Layer::Hidden => 3,
            Layer::Left => 4,
            Layer::Right => 5,
        }
    }

    /// The layer's name in SVG ids and PDF layer lists.
    pub fn name(self) -> &'static str {
        match self {
            Layer::Visible => "visible",
            Layer::Hidden => "hidden",
            Layer::Reflected => "reflected",
            Layer::Left => "left",
            Layer::Right => "right",
        }
    }
}

/// Stroke of a layer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stroke {
    /// Width in millimetres.
    pub width: f64,
    /// Colour, display RGB in `[0, 1]` (black `[0, 0, 0]`).
    pub rgb: [f64; 3],
    /// Dash length in millimetres (0: solid).
    pub dash: f64,
}

/// Polylines on paper, in millimetres, origin top left, `y` down.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Drawing {
    /// Paper size in millimetres.
    pub size: Vec2,
    /// `(layer, points)` in drawing order.
    pub lines: Vec<(Layer, Vec<Vec2>)>,
    /// Filled polygons under the lines, in painter's order (the first is covered by the later).
    pub fills: Vec<Fill>,
}

/// A filled polygon on paper (its outline closes itself).
#[derive(Clone, Debug, PartialEq)]
pub struct Fill {
    /// Corners in millimetres.
    pub points: Vec<Vec2>,
    /// Linear-free display RGB in `[0, 1]`.
    pub rgb: [f64; 3],
}

/// Default strokes: visible 0.35 mm black, hidden 0.18 mm grey dashed, reflected 0.25 mm; an
/// anaglyph's eyes 0.35 mm red (left) and cyan (right).
pub fn default_stroke(layer: Layer) -> Stroke {
    match layer {
        Layer::Visible => Stroke { width: 0.35, rgb: [0.0; 3], dash: 0.0 },
        Layer::Hidden => Stroke { width: 0.18, rgb: [0.45; 3], dash: 1.0 },
        Layer::Reflected => Stroke { width: 0.25, rgb: [0.1; 3], dash: 0.0 },
        Layer::Left => Stroke { width: 0.35, rgb: [1.0, 0.0, 0.0], dash: 0.0 },
        Layer::Right => Stroke { width: 0.35, rgb: [0.0, 1.0, 1.0], dash: 0.0 },
    }
}

impl Drawing {
    /// Number of polylines on a layer.
    pub fn count(&self, layer: Layer) -> usize {
        self.lines.iter().filter(|(l, _)| *l == layer).count()
    }

    /// Total length of the lines of a layer in millimetres.
    pub fn length(&self, layer: Layer) -> f64 {
        self.lines
            .iter()
            .filter(|(l, _)| *l == layer)
            .map(|(_, p)| p.windows(2).map(|w| (w[1] - w[0]).length()).sum::<f64>())
            .fold(0.0, |a, b| a + b)
    }

    /// Polylines of a layer that meet end to end (within 1 µm) chained into one, so a plotter
    /// lifts its pen less and files shrink; order otherwise kept.
    pub fn joined(mut self) -> Drawing {
        use std::collections::HashMap;
        self.lines.retain(|(_, p)| !p.is_empty());
        let key = |p: Vec2| ((p.x * 1e3).round() as i64, (p.y * 1e3).round() as i64);
        let n = self.lines.len();
        let mut ends: HashMap<(Layer, (i64, i64)), Vec<usize>> = HashMap::new();
        for (i, (layer, pts)) in self.lines.iter().enumerate() {
            ends.entry((*layer, key(pts[0]))).or_default().push(i);
            ends.entry((*layer, key(pts[pts.len() - 1]))).or_default().push(i);
        }
        let mut used = vec![false; n];
        let mut take = |layer: Layer, at: Vec2, used: &mut Vec<bool>| -> Option<usize> {
            let list = ends.get_mut(&(layer, key(at)))?;
            let pos = list.iter().position(|&j| !used[j])?;
            let j = list.swap_remove(pos);
            used[j] = true;
            Some(j)
        };
        let mut lines = vec![];
        for i in 0..n {
            if used[i] {
                continue;
            }
            used[i] = true;
            let layer = self.lines[i].0;
            let mut chain = self.lines[i].1.clone();
            // Forward from the end, then backward from the start.
            for forward in [true, false] {
                loop {
                    let at = if forward { chain[chain.len() - 1] } else { chain[0] };
                    let Some(j) = take(layer, at, &mut used) else { break };
                    let mut next = self.lines[j].1.clone();
                    if forward {
                        if key(next[0]) != key(at) {
                            next.reverse();
                        }
                        chain.extend_from_slice(&next[1..]);
                    } else {
                        if key(next[next.len() - 1]) != key(at) {
                            next.reverse();
                        }
                        next.pop();
                        next.extend_from_slice(&chain);
                        chain = next;
                    }
                }
            }
            lines.push((layer, chain));
        }
        Drawing { size: self.size, lines, fills: self.fills }
    }

    /// The drawing cut to its paper by the course's Liang–Barsky clipping: polylines leaving
    /// the paper are split.
    pub fn clipped(self) -> Drawing {
        let win = alhazen_raster::clip::Window { xmin: 0.0, ymin: 0.0, xmax: self.size.x, ymax: self.size.y };
        let mut lines = vec![];
        for (layer, pts) in self.lines {
            let mut cur: Vec<Vec2> = vec![];
            for s in pts.windows(2) {
                match alhazen_raster::clip::liang_barsky(&win, s[0], s[1]) {
                    Some((a, b)) => {
                        if cur.last().is_none_or(|l| (*l - a).length() > 1e-12) {
                            if cur.len() > 1 {
                                lines.push((layer, std::mem::take(&mut cur)));
                            }
                            cur = vec![a];
                        }
                        cur.push(b);
                    }
                    None => {
                        if cur.len() > 1 {
                            lines.push((layer, std::mem::take(&mut cur)));
                        }
                        cur.clear();
                    }
                }
            }
            if cur.len() > 1 {
                lines.push((layer, cur));
            }
        }
        Drawing { size: self.size, lines, fills: self.fills }
    }

    /// SVG in millimetres, a group per layer, coordinates to 0.001 mm.
    pub fn to_svg(&self, stroke: impl Fn(Layer) -> Stroke) -> String {
        let mut s = String::new();
        let (w, h) = (self.size.x, self.size.y);
        // No background rectangle: a plotter would draw it. Each layer is an Inkscape layer
        // whose label starts with its pen number, as vpype reads layers.
        let _ = writeln!(
            s,
            "<svg xmlns=\"http://www.w3.org/2000/svg\" xmlns:inkscape=\"http://www.inkscape.org/namespaces/inkscape\" width=\"{w:.3}mm\" height=\"{h:.3}mm\" viewBox=\"0 0 {w:.3} {h:.3}\" style=\"background-color:white\">"
        );
        if !self.fills.is_empty() {
            s.push_str("<g id=\"fills\" inkscape:groupmode=\"layer\" inkscape:label=\"fills\" stroke=\"none\">\n");
            for f in &self.fills {
                let [r, g, b] = f.rgb.map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8);
                s.push_str("<polygon points=\"");
                for (i, p) in f.points.iter().enumerate() {
                    let _ = write!(s, "{}{:.3},{:.3}", if i > 0 { " " } else { "" }, p.x, p.y);
                }
                let _ = writeln!(s, "\" fill=\"rgb({r},{g},{b})\"/>");
            }
            s.push_str("</g>\n");
        }
        for layer in Layer::ALL {
            if layer >= Layer::Left && !self.lines.iter().any(|(l, _)| *l == layer) {
                continue; // the eyes' layers only in anaglyphs
            }
            let st = stroke(layer);
            let [r, g, b] = st.rgb.map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8);
            let dash = if st.dash > 0.0 {
                format!(" stroke-dasharray=\"{:.3} {:.3}\"", st.dash, st.dash)
            } else {
                String::new()
            };
            let _ = writeln!(
                s,
                "<g id=\"{0}\" inkscape:groupmode=\"layer\" inkscape:label=\"{1} {0}\" fill=\"none\" stroke=\"rgb({r},{g},{b})\" stroke-width=\"{2:.3}\" stroke-linecap=\"round\" stroke-linejoin=\"round\"{dash}>",
                layer.name(),
                layer.pen(),
                st.width
            );
            for (_, pts) in self.lines.iter().filter(|(l, _)| *l == layer) {
                s.push_str("<polyline points=\"");
                for (i, p) in pts.iter().enumerate() {
                    let _ = write!(s, "{}{:.3},{:.3}", if i > 0 { " " } else { "" }, p.x, p.y);
                }
                s.push_str("\"/>\n");
            }
            s.push_str("</g>\n");
        }
        s.push_str("</svg>\n");
        s
    }

    /// A one-page PDF of the paper's size with one optional-content layer per layer.
    pub fn to_pdf(&self, stroke: impl Fn(Layer) -> Stroke) -> Vec<u8> {
        self.to_pdf_over(stroke, None)
    }

    /// The PDF with an RGB raster (`width × height`, 8 bits, row-major) filling the page under
    /// the lines, compressed with Flate.
    pub fn to_pdf_over(&self, stroke: impl Fn(Layer) -> Stroke, backdrop: Option<&Backdrop>) -> Vec<u8> {
        const PT: f64 = 72.0 / 25.4;
        let (w, h) = (self.size.x * PT, self.size.y * PT);
        let mut content = String::new();
        if backdrop.is_some() {
            let _ = writeln!(content, "q {w:.3} 0 0 {h:.3} 0 0 cm /Im0 Do Q");
        }
        for f in &self.fills {
            let [r, g, b] = f.rgb.map(|c| c.clamp(0.0, 1.0));
            let _ = write!(content, "{r:.4} {g:.4} {b:.4} rg ");
            for (i, p) in f.points.iter().enumerate() {
                let _ = write!(content, "{:.3} {:.3} {} ", p.x * PT, h - p.y * PT, if i == 0 { "m" } else { "l" });
            }
            content.push_str("h f\n");
        }
        for (k, layer) in Layer::ALL.iter().enumerate() {
            let st = stroke(*layer);
            let _ = writeln!(content, "/OC /L{k} BDC");
            let dash =
                if st.dash > 0.0 { format!("[{:.3} {:.3}] 0 d", st.dash * PT, st.dash * PT) } else { "[] 0 d".into() };
            let [r, g, b] = st.rgb.map(|c| c.clamp(0.0, 1.0));
            let _ = writeln!(content, "{r:.3} {g:.3} {b:.3} RG {:.3} w 1 J 1 j {dash}", st.width * PT);
            for (_, pts) in self.lines.iter().filter(|(l, _)| l == layer) {
                for (i, p) in pts.iter().enumerate() {
                    let _ = write!(content, "{:.3} {:.3} {} ", p.x * PT, h - p.y * PT, if i == 0 { "m" } else { "l" });
                }
                content.push_str("S\n");
            }
            content.push_str("EMC\n");
        }
        let n = Layer::ALL.len();
        let image_obj = 6 + n;
        let xobject = if backdrop.is_some() { format!(" /XObject << /Im0 {image_obj} 0 R >>") } else { String::new() };
        let ocgs: Vec<String> = (0..n).map(|k| format!("{} 0 R", 6 + k)).collect();
        let props: Vec<String> = (0..n).map(|k| format!("/L{k} {} 0 R", 6 + k)).collect();
        let mut objects = vec![
            format!(
                "<< /Type /Catalog /Pages 2 0 R /OCProperties << /OCGs [{0}] /D << /Order [{0}] >> >> >>",
                ocgs.join(" ")
            ),
            "<< /Type /Pages /Kids [3 0 R] /Count 1 >>".to_string(),
            format!(
                "<< /Type /Page /Parent 2 0 R /MediaBox [0 0 {w:.3} {h:.3}] /Contents 4 0 R /Resources << /Properties << {} >>{xobject} >> >>",
                props.join(" ")
            ),
            format!("<< /Length {} >>\nstream\n{content}endstream", content.len()),
            "<< /Producer (alhazen lines) >>".to_string(),
        ];
        for layer in Layer::ALL {
            objects.push(format!("<< /Type /OCG /Name ({}) >>", layer.name()));
        }
        let mut out = b"%PDF-1.5\n%\xe2\xe3\xcf\xd3\n".to_vec();
        let mut offsets = vec![];
        for (i, o) in objects.iter().enumerate() {
            offsets.push(out.len());
            out.extend_from_slice(format!("{} 0 obj\n{o}\nendobj\n", i + 1).as_bytes());
        }
        if let Some(b) = backdrop {
            use std::io::Write as _;
            let mut z = flate2::write::ZlibEncoder::new(vec![], flate2::Compression::default());
            let _ = z.write_all(&b.rgb);
            let data = z.finish().unwrap_or_default();
            offsets.push(out.len());
            out.extend_from_slice(
                format!(
                    "{image_obj} 0 obj\n<< /Type /XObject /Subtype /Image /Width {} /Height {} /ColorSpace /DeviceRGB /BitsPerComponent 8 /Filter /FlateDecode /Length {} >>\nstream\n",
                    b.width,
                    b.height,
                    data.len()
                )
                .as_bytes(),
            );
            out.extend_from_slice(&data);
            out.extend_from_slice(b"\nendstream\nendobj\n");
        }
        let count = offsets.len();
        let xref = out.len();
        let mut tail = format!("xref\n0 {}\n0000000000 65535 f \n", count + 1);
        for off in offsets {
            let _ = writeln!(tail, "{off:010} 00000 n ");
        }
        let _ = write!(
            tail,
            "trailer\n<< /Size {} /Root 1 0 R /Info 5 0 R >>\nstartxref\n{xref}\n%%EOF\n",
            objects.len() + 1
        );
        out.extend_from_slice(tail.as_bytes());
        out
    }

    /// An antialiased RGB preview `px` pixels wide (three bytes a pixel): each pixel's coverage
    /// by each stroke from the exact distance of its centre to the segment (round caps); inks
    /// absorb per channel as on paper (a red and a cyan stroke crossing make black), the
    /// darkest wins.
    pub fn to_pixels(&self, px: u32, stroke: impl Fn(Layer) -> Stroke) -> (u32, u32, Vec<u8>) {
        let scale = px as f64 / self.size.x.max(1e-9);
        let (w, h) = (px, ((self.size.y * scale).round() as u32).max(1));
        let mut ink = vec![[0.0f32; 3]; (w * h) as usize];
        let absorbed = |rgb: [f64; 3]| rgb.map(|c| (1.0 - c.clamp(0.0, 1.0)) as f32);
        for f in &self.fills {
            let pts: Vec<Vec2> = f.points.iter().map(|p| *p * scale).collect();
            fill_polygon(&mut ink, (w, h), &pts, absorbed(f.rgb));
        }
        for (layer, pts) in &self.lines {
            let st = stroke(*layer);
            let half = (0.5 * st.width * scale).max(0.5);
            let darkness = absorbed(st.rgb);
            let mut walked = 0.0;
            for seg in pts.windows(2) {
                let (a, b) = (seg[0] * scale, seg[1] * scale);
                let len = (b - a).length();
                if st.dash > 0.0 {
                    let period = 2.0 * st.dash * scale;
                    // Draw the dashes of this segment as sub-segments.
                    let mut t = 0.0;
                    while t < len {
                        let phase = (walked + t) % period;
                        let run = if phase < period / 2.0 { period / 2.0 - phase } else { period - phase };
                        let end = (t + run).min(len);
                        if phase < period / 2.0 {
                            let d = (b - a) / len.max(1e-12);
                            stamp(&mut ink, (w, h), a + d * t, a + d * end, half, darkness);
                        }
                        t = end;
                    }
                } else {
                    stamp(&mut ink, (w, h), a, b, half, darkness);
                }
                walked += len;
            }
        }
        let pixels = ink.iter().flatten().map(|&k| (255.0 * (1.0 - k.clamp(0.0, 1.0))).round() as u8).collect();
        (w, h, pixels)
    }
}

impl Drawing {
    /// The preview encoded as an 8-bit RGB PNG.
    pub fn to_png(&self, px: u32, stroke: impl Fn(Layer) -> Stroke) -> Result<Vec<u8>, image::ImageError> {
        use image::ImageEncoder;
        let (w, h, pixels) = self.to_pixels(px, stroke);
        let mut out = vec![];
        image::codecs::png::PngEncoder::new(&mut out).write_image(&pixels, w, h, image::ExtendedColorType::Rgb8)?;
        Ok(out)
    }
}

/// Paints `ink` (darkness per channel) inside polygon `pts` (pixels; even–odd rule at pixel
/// centres), over what was there.
fn fill_polygon(ink: &mut [[f32; 3]], (w, h): (u32, u32), pts: &[Vec2], darkness: [f32; 3]) {
    if pts.len() < 3 {
        return;
    }
    let (lo, hi) = pts.iter().fold((f64::MAX, f64::MIN), |(lo, hi), p| (lo.min(p.y), hi.max(p.y)));
    let (y0, y1) = ((lo - 0.5).ceil().max(0.0) as u32, ((hi - 0.5).floor().min(h as f64 - 1.0)).max(-1.0) as i64);
    let mut xs = vec![];
    for y in y0 as i64..=y1 {
        let yc = y as f64 + 0.5;
        xs.clear();
        for (i, a) in pts.iter().enumerate() {
            let b = pts[(i + 1) % pts.len()];
            if (a.y <= yc) != (b.y <= yc) {
                xs.push(a.x + (yc - a.y) / (b.y - a.y) * (b.x - a.x));
            }
        }
        xs.sort_by(f64::total_cmp);
        for pair in xs.chunks_exact(2) {
            let (x0, x1) =
                ((pair[0] - 0.5).ceil().max(0.0) as i64, ((pair[1] - 0.5).floor()).min(w as f64 - 1.0) as i64);
            for x in x0..=x1 {
                ink[(y as u32 * w + x as u32) as usize] = darkness;
            }
        }
    }
}

/// An 8-bit RGB raster to put under a PDF's lines.
#[derive(Clone, Debug, PartialEq)]
pub struct Backdrop {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width × height × 3` bytes, rows top to bottom.
    pub rgb: Vec<u8>,
}

/// Darkens the pixels near segment `a b` by their coverage (1 inside, a one-pixel ramp at
/// distance `half`).
fn stamp(ink: &mut [[f32; 3]], (w, h): (u32, u32), a: Vec2, b: Vec2, half: f64, darkness: [f32; 3]) {
    let lo = (a.min(b) - Vec2::splat(half + 1.0)).max(Vec2::ZERO);
    let hi = (a.max(b) + Vec2::splat(half + 1.0)).min(Vec2::new(w as f64 - 1.0, h as f64 - 1.0));
    if lo.x > hi.x || lo.y > hi.y {
        return;
    }
    let d = b - a;
    let l2 = d.length_squared();
    for y in lo.y as u32..=hi.y as u32 {
        for x in lo.x as u32..=hi.x as u32 {
            let p = Vec2::new(x as f64 + 0.5, y as f64 + 0.5);
            let t = if l2 > 0.0 { ((p - a).dot(d) / l2).clamp(0.0, 1.0) } else { 0.0 };
            let dist = (p - (a + d * t)).length();
            let cover = (half + 0.5 - dist).clamp(0.0, 1.0) as f32;
            let k = &mut ink[(y * w + x) as usize];
            for c in 0..3 {
                k[c] = k[c].max(cover * darkness[c]);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> Drawing {
        let p = |x, y| Vec2::new(x, y);
        Drawing {
            size: p(20.0, 10.0),
            lines: vec![(Layer::Visible, vec![p(2.0, 2.0), p(18.0, 2.0), p(18.0, 8.0)])],
            fills: vec![],
        }
    }

    #[test]
    fn svg_has_a_group_per_layer_and_exact_coordinates() {
        let s = square().to_svg(default_stroke);
        assert!(s.contains("width=\"20.000mm\""));
        assert!(s.contains("<g id=\"visible\"") && s.contains("<g id=\"hidden\"") && s.contains("<g id=\"reflected\""));
        assert!(s.contains("2.000,2.000 18.000,2.000 18.000,8.000"));
    }

    #[test]
    fn pdf_cross_reference_points_at_its_objects() {
        let pdf = square().to_pdf(default_stroke);
        let at = |off: usize, what: &str| pdf[off..].starts_with(what.as_bytes());
        let text = String::from_utf8_lossy(&pdf[20..]).into_owned();
        let xref: usize = text.rsplit("startxref\n").next().unwrap().lines().next().unwrap().parse().unwrap();
        assert!(at(xref, "xref"));
        let table = String::from_utf8_lossy(&pdf[xref..]).into_owned();
        for (k, line) in table.lines().skip(3).take(8).enumerate() {
            let off: usize = line[..10].parse().unwrap();
            assert!(at(off, &format!("{} 0 obj", k + 1)), "object {}", k + 1);
        }
        assert!(text.contains("/OCG /Name (visible)"));
    }

    #[test]
    fn touching_polylines_are_chained_and_nothing_is_lost() {
        let p = |x, y| Vec2::new(x, y);
        let d = Drawing {
            size: p(10.0, 10.0),
            lines: vec![
                (Layer::Visible, vec![p(0.0, 0.0), p(1.0, 0.0)]),
                (Layer::Visible, vec![p(2.0, 0.0), p(1.0, 0.0)]),
                (Layer::Visible, vec![p(3.0, 3.0), p(0.0, 0.0)]),
                (Layer::Reflected, vec![p(2.0, 0.0), p(5.0, 5.0)]),
            ],
            fills: vec![],
        };
        let length = d.length(Layer::Visible);
        let j = d.joined();
        assert_eq!(j.count(Layer::Visible), 1);
        assert_eq!(j.count(Layer::Reflected), 1, "layers are not mixed");
        assert!((j.length(Layer::Visible) - length).abs() < 1e-12);
        assert_eq!(j.lines[0].1.len(), 4);
    }

    #[test]
    fn preview_inks_the_line_and_nothing_far_from_it() {
        let (w, h, px) = square().to_pixels(200, default_stroke);
        assert_eq!((w, h), (200, 100));
        let at = |x: u32, y: u32| &px[3 * (y * w + x) as usize..][..3];
        assert!(at(100, 20).iter().all(|&c| c < 60), "on the line");
        assert_eq!(at(60, 60), [255; 3], "far from it");
    }
}
