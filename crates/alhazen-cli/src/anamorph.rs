//! `alhazen mirror anamorph`: the drawing to lay around a mirror cylinder so that a picture
//! appears undistorted in it from the eye (Glaeser §2.4). A PNG picture gives a raster print
//! (PNG, or PDF with the raster embedded); an SVG line drawing (polylines and lines, e.g. from
//! `alhazen lines`) gives a vector print (SVG or PDF). Every print marks the cylinder's
//! footprint and axis.

use crate::Failure;
use alhazen_lines::drawing::{Backdrop, Drawing, Layer, Stroke, default_stroke};
use alhazen_math::{Vec2, Vec3};
use alhazen_mirror::anamorph::{Anamorphosis, Placement, paper_size};
use clap::Args;
use std::f64::consts::TAU;
use std::path::{Path, PathBuf};

#[derive(Args)]
pub struct AnamorphArgs {
    /// The picture: a PNG image, or an SVG line drawing (its polylines and lines).
    image: PathBuf,
    /// Radius of the mirror cylinder in millimetres.
    #[arg(long, allow_negative_numbers = true)]
    radius: f64,
    /// Height of the mirror cylinder in millimetres.
    #[arg(long, allow_negative_numbers = true)]
    height: f64,
    /// Eye position `x,y,z` in millimetres, `y` up, the cylinder's axis the `y` axis.
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    eye: Vec3,
    /// Paper: A0–A5, letter, or `WxH` in millimetres; turned to landscape if that fits better.
    #[arg(long, default_value = "A3")]
    paper: String,
    /// Resolution of a raster print.
    #[arg(long, default_value_t = 300.0)]
    dpi: f64,
    /// Samples per pixel along each axis of a raster print, averaged (the print squeezes parts
    /// of the picture hard: without them they alias).
    #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u32).range(1..=8))]
    supersample: u32,
    /// Output: .png or .pdf (raster picture); .svg or .pdf (line drawing); .png too.
    #[arg(short, long)]
    output: PathBuf,
}

fn parse_vec3(s: &str) -> Result<Vec3, String> {
    crate::mirror::parse_numbers::<3>(s).map(Vec3::from_array)
}

fn ext(p: &Path) -> String {
    p.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase()
}

pub fn run(a: &AnamorphArgs) -> Result<(), Failure> {
    let paper = paper_size(&a.paper)
        .ok_or_else(|| Failure::input(format!("--paper {:?}: use A0–A5, letter or WxH (mm)", a.paper)))?;
    if !(a.dpi.is_finite() && (10.0..=2400.0).contains(&a.dpi)) {
        return Err(Failure::input("--dpi must be between 10 and 2400"));
    }
    let out_ext = ext(&a.output);
    crate::check_output_dir(&a.output)?;
    let fits = match ext(&a.image).as_str() {
        "png" => ["png", "pdf"].contains(&out_ext.as_str()),
        _ => ["svg", "pdf", "png"].contains(&out_ext.as_str()),
    };
    if !fits {
        return Err(Failure::input(format!(
            "{}: a raster picture prints to .png or .pdf, a line drawing to .svg, .pdf or .png",
            a.output.display()
        )));
    }
    let bytes = match ext(&a.image).as_str() {
        "png" => raster_print(a, paper, &out_ext)?,
        "svg" => vector_print(a, paper, &out_ext)?,
        _ => {
            return Err(Failure::input(format!(
                "{}: the picture must be a .png image or an .svg drawing",
                a.image.display()
            )));
        }
    };
    alhazen_render::output::write_atomically(&a.output, |f| std::io::Write::write_all(f, &bytes))
        .map_err(|e| Failure::work(format!("cannot write {}: {e}", a.output.display())))?;
    eprintln!(
        "anamorphosis of {} for a cylinder r = {} mm, h = {} mm → {}",
        a.image.display(),
        a.radius,
        a.height,
        a.output.display()
    );
    Ok(())
}

fn setup(a: &AnamorphArgs, aspect: f64, paper: Vec2) -> Result<(Anamorphosis, Placement), Failure> {
    let an = Anamorphosis::new(a.radius, a.height, a.eye, aspect).map_err(|e| Failure::input(e.to_string()))?;
    let at = an.place(paper).map_err(|need| {
        Failure::input(format!(
            "the print needs {:.0} × {:.0} mm, more than the {:.0} × {:.0} mm paper: use larger paper, a smaller cylinder or a higher eye",
            need.x, need.y, paper.x, paper.y
        ))
    })?;
    Ok((an, at))
}

/// The cylinder's footprint and a cross at its axis, on paper.
fn footprint(an: &Anamorphosis, at: &Placement) -> Vec<Vec<Vec2>> {
    let r = an.cylinder().radius;
    let circle = (0..=256).map(|k| at.paper_point(Vec2::from_angle(TAU * k as f64 / 256.0) * r)).collect();
    let c = at.axis;
    let arm = 0.15 * r;
    vec![circle, vec![c - Vec2::X * arm, c + Vec2::X * arm], vec![c - Vec2::Y * arm, c + Vec2::Y * arm]]
}

fn guide_stroke(l: Layer) -> Stroke {
    match l {
        Layer::Hidden => Stroke { width: 0.2, rgb: [0.6; 3], dash: 0.0 },
        _ => default_stroke(l),
    }
}

fn raster_print(a: &AnamorphArgs, paper: Vec2, out: &str) -> Result<Vec<u8>, Failure> {
    let img = alhazen_scene::import::load_image(&a.image)
        .map_err(|e| Failure::input(format!("{}: {e}", a.image.display())))?;
    let (an, at) = setup(a, img.width as f64 / img.height as f64, paper)?;
    let srgb = |v: f32| (255.0 * alhazen_math::color::srgb_encode(v.clamp(0.0, 1.0) as f64)).round() as u8;
    // The print at `n`× the resolution, averaged over n × n blocks in linear light.
    let n = a.supersample as usize;
    let fine_rows = (at.paper.y / 25.4 * a.dpi * n as f64).round().max(1.0) as u64;
    // The print (sRGB bytes, then its encoding) and one fine row of texture coordinates.
    let pixels = (at.paper.x / 25.4 * a.dpi).round() * (at.paper.y / 25.4 * a.dpi).round();
    let row = at.paper.x / 25.4 * a.dpi * n as f64 * 32.0;
    let needed = (pixels * 6.0 + row).min(u64::MAX as f64) as u64;
    let what = format!("a {:.0} × {:.0} mm print at {} dpi", at.paper.x, at.paper.y, a.dpi);
    crate::check_memory(needed, &what)?;
    let (mut rgb, mut sums, mut w) = (vec![], vec![], 0usize);
    let bar = crate::progress_bar(false);
    bar.set_length(fine_rows);
    let (_, fine_h) = an.print_raster(&at, a.dpi * n as f64, |y, row| {
        w = row.len() / n;
        sums.resize(w * 3, 0.0f32);
        for (x, uv) in row.iter().take(w * n).enumerate() {
            let c = uv.map_or([1.0f32; 3], |uv| bilinear(&img, uv));
            for k in 0..3 {
                sums[(x / n) * 3 + k] += c[k];
            }
        }
        if (y as usize + 1).is_multiple_of(n) {
            let scale = 1.0 / (n * n) as f32;
            rgb.extend(sums.iter().map(|v| srgb(v * scale)));
            sums.iter_mut().for_each(|v| *v = 0.0);
        }
        bar.set_position(y as u64 + 1);
    });
    bar.finish_and_clear();
    let (w, h) = (w as u32, fine_h / n as u32);
    let guides = Drawing {
        size: at.paper,
        lines: footprint(&an, &at).into_iter().map(|p| (Layer::Hidden, p)).collect(),
        fills: vec![],
    };
    match out {
        "pdf" => Ok(guides.to_pdf_over(guide_stroke, Some(&Backdrop { width: w, height: h, rgb }))),
        "png" => {
            // The guides darken the print where they pass.
            let (gw, gh, ink) = guides.to_pixels(w, guide_stroke);
            for (i, k) in ink.iter().enumerate().take((3 * gw * gh).min(3 * w * h) as usize) {
                rgb[i] = rgb[i].min(*k);
            }
            encode_png(w, h, &rgb)
        }
        _ => Err(Failure::input(format!("{}: a raster picture prints to .png or .pdf", a.output.display()))),
    }
}

fn encode_png(w: u32, h: u32, rgb: &[u8]) -> Result<Vec<u8>, Failure> {
    use image::ImageEncoder;
    let mut out = vec![];
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(rgb, w, h, image::ExtendedColorType::Rgb8)
        .map_err(|e| Failure::work(e.to_string()))?;
    Ok(out)
}

/// Bilinear lookup of a linear-RGB image at `(u, v) ∈ [0, 1]²`, `v` down.
fn bilinear(img: &alhazen_scene::ImageData, uv: Vec2) -> [f32; 3] {
    let (w, h) = (img.width as usize, img.height as usize);
    let x = (uv.x * w as f64 - 0.5).clamp(0.0, (w - 1) as f64);
    let y = (uv.y * h as f64 - 0.5).clamp(0.0, (h - 1) as f64);
    let (x0, y0) = (x.floor() as usize, y.floor() as usize);
    let (x1, y1) = ((x0 + 1).min(w - 1), (y0 + 1).min(h - 1));
    let (fx, fy) = ((x - x0 as f64) as f32, (y - y0 as f64) as f32);
    let p = |x: usize, y: usize| img.texel(y * w + x);
    let mut c = [0.0f32; 3];
    for k in 0..3 {
        let top = p(x0, y0)[k] * (1.0 - fx) + p(x1, y0)[k] * fx;
        let bottom = p(x0, y1)[k] * (1.0 - fx) + p(x1, y1)[k] * fx;
        c[k] = top * (1.0 - fy) + bottom * fy;
    }
    c
}

fn vector_print(a: &AnamorphArgs, paper: Vec2, out: &str) -> Result<Vec<u8>, Failure> {
    let text = std::fs::read_to_string(&a.image).map_err(|e| Failure::input(format!("{}: {e}", a.image.display())))?;
    let (size, lines) = parse_svg_lines(&text).map_err(|e| Failure::input(format!("{}: {e}", a.image.display())))?;
    let (an, at) = setup(a, size.x / size.y, paper)?;
    let mut d = Drawing {
        size: at.paper,
        lines: footprint(&an, &at).into_iter().map(|p| (Layer::Hidden, p)).collect(),
        fills: vec![],
    };
    for l in &lines {
        let uv: Vec<Vec2> = l.iter().map(|p| *p / size).collect();
        for run in an.print_polyline(&uv, 0.25) {
            d.lines.push((Layer::Visible, run.into_iter().map(|f| at.paper_point(f)).collect()));
        }
    }
    let d = d.clipped();
    match out {
        "svg" => Ok(d.to_svg(guide_stroke).into_bytes()),
        "pdf" => Ok(d.to_pdf(guide_stroke)),
        "png" => {
            let px = (at.paper.x / 25.4 * a.dpi).round().max(16.0) as u32;
            d.to_png(px, guide_stroke).map_err(|e| Failure::work(e.to_string()))
        }
        _ => Err(Failure::input(format!("{}: a line drawing prints to .svg, .pdf or .png", a.output.display()))),
    }
}

/// The size (from `viewBox`, else `width`/`height`) and the polylines of a simple SVG:
/// `<polyline points>`, `<polygon points>` (closed) and `<line>` elements.
pub fn parse_svg_lines(svg: &str) -> Result<(Vec2, Vec<Vec<Vec2>>), String> {
    let attr = |tag: &str, name: &str| -> Option<String> {
        let key = format!(" {name}=\"");
        let i = tag.find(&key)? + key.len();
        Some(tag[i..].split('"').next()?.to_string())
    };
    let nums = |s: &str| -> Vec<f64> {
        s.split(|c: char| c == ',' || c.is_whitespace())
            .filter(|t| !t.is_empty())
            .filter_map(|t| t.parse().ok())
            .collect()
    };
    let root = svg.find("<svg").map(|i| &svg[i..]).ok_or("not an SVG file (no <svg> element)")?;
    let root_tag = &root[..root.find('>').ok_or("unterminated <svg> tag")?];
    let size = match attr(root_tag, "viewBox").map(|v| nums(&v)) {
        Some(v) if v.len() == 4 && v[2] > 0.0 && v[3] > 0.0 => Vec2::new(v[2], v[3]),
        _ => {
            let dim = |n| {
                attr(root_tag, n).and_then(|v| nums(v.trim_end_matches(|c: char| c.is_alphabetic())).first().copied())
            };
            match (dim("width"), dim("height")) {
                (Some(w), Some(h)) if w > 0.0 && h > 0.0 => Vec2::new(w, h),
                _ => return Err("the <svg> element has no usable viewBox or width/height".into()),
            }
        }
    };
    let mut lines = vec![];
    for (name, closed) in [("<polyline", false), ("<polygon", true), ("<line", false)] {
        for (i, _) in svg.match_indices(name) {
            let tag = &svg[i..i + svg[i..].find('>').unwrap_or(svg.len() - i)];
            let pts: Vec<Vec2> = if name == "<line" {
                let v: Vec<f64> = ["x1", "y1", "x2", "y2"].iter().filter_map(|k| attr(tag, k)?.parse().ok()).collect();
                if v.len() != 4 {
                    continue;
                }
                vec![Vec2::new(v[0], v[1]), Vec2::new(v[2], v[3])]
            } else {
                let v = nums(&attr(tag, "points").unwrap_or_default());
                let mut p: Vec<Vec2> = v.chunks_exact(2).map(|c| Vec2::new(c[0], c[1])).collect();
                if closed && p.len() > 2 {
                    p.push(p[0]);
                }
                p
            };
            if pts.len() > 1 {
                lines.push(pts);
            }
        }
    }
    if lines.is_empty() {
        return Err("no <polyline>, <polygon> or <line> elements".into());
    }
    Ok((size, lines))
}
