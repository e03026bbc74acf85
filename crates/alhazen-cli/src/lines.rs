//! `alhazen lines`: exact hidden-line drawings of a scene with its reflections in spherical and
//! cylindrical mirrors, as SVG, PDF or a PNG preview; `--graph` draws a function graph with
//! the floating-horizon algorithm instead; `--optimize` and HP-GL output for pen plotters.

use crate::{Failure, load};
use alhazen_lines::drawing::{Drawing, Layer, Stroke, default_stroke};
use alhazen_lines::horizon::{Graph, Layout, floating_horizon};
use alhazen_lines::{Options, Progress, draw_reporting};
use alhazen_math::Vec2;
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

#[derive(Args)]
pub struct LinesArgs {
    /// The scene file (TOML, glTF, Mitsuba 3 XML or pbrt-v4); not needed with --graph.
    #[arg(required_unless_present = "graph")]
    scene: Option<PathBuf>,
    #[command(flatten)]
    parameters: crate::SceneParameters,
    /// Output: .svg (a layer per kind of line, read as layers by Inkscape and vpype), .pdf,
    /// .hpgl or .plt (HP-GL for pen plotters: pen 1 visible, 2 reflected, 3 hidden; an
    /// anaglyph's eyes 4 and 5) or .png (an antialiased preview).
    #[arg(short, long)]
    output: PathBuf,
    /// Paper width in millimetres (the height follows the scene's image aspect).
    #[arg(long, default_value_t = 200.0, value_parser = paper_width)]
    width_mm: f64,
    /// Also draw hidden lines (dashed, on their own layer).
    #[arg(long)]
    hidden: bool,
    /// Leave out the reflections in mirrors.
    #[arg(long)]
    no_reflections: bool,
    /// Fill the reflexes of the scene's polygons in spherical, cylindrical and plane mirrors
    /// with their colours, farthest first, under the lines; polygons whose reflexes would fold
    /// over are split first (Glaeser's Theorems 7–9).
    #[arg(long, conflicts_with_all = ["no_reflections", "optimize"])]
    fill: bool,
    /// With a stereo camera: one red–cyan anaglyph (left eye red, right eye cyan, on the
    /// layers `4 left` and `5 right`) instead of the two drawings side by side.
    #[arg(long, conflicts_with_all = ["fill", "hidden"])]
    anaglyph: bool,
    /// Mesh edges whose faces meet at more than this angle (degrees) are drawn.
    #[arg(long, default_value_t = 30.0, value_parser = angle)]
    feature_angle: f64,
    /// Stroke width of visible lines in millimetres.
    #[arg(long, default_value_t = 0.35, value_parser = positive)]
    stroke: f64,
    /// Stroke width of hidden lines in millimetres.
    #[arg(long, default_value_t = 0.18, value_parser = positive)]
    stroke_hidden: f64,
    /// Stroke width of reflected lines in millimetres.
    #[arg(long, default_value_t = 0.25, value_parser = positive)]
    stroke_reflected: f64,
    /// Order the lines for a pen plotter: join strokes that meet, tour each layer nearest end
    /// first, improved by 2-opt, and report the pen-up travel saved.
    #[arg(long)]
    optimize: bool,
    /// With --optimize, strokes whose ends lie this close (millimetres) are drawn as one.
    #[arg(long, default_value_t = 0.05, value_parser = non_negative, requires = "optimize", allow_negative_numbers = true)]
    join_tolerance: f64,
    /// Width of a PNG preview in pixels.
    #[arg(long, default_value_t = 1000, value_parser = clap::value_parser!(u32).range(16..=20000))]
    png_width: u32,
    /// Decide visibility by ray tests every STEP film pixels instead of exactly (the
    /// benchmark's baseline, as fogleman/ln draws).
    #[arg(long, value_name = "STEP", value_parser = positive)]
    sampled: Option<f64>,
    /// Draw the graph of a built-in function with the floating-horizon algorithm.
    #[arg(long, value_enum)]
    graph: Option<GraphFunction>,
    /// Net lines per direction of a graph.
    #[arg(long, default_value_t = 41, value_parser = clap::value_parser!(u32).range(2..=2000))]
    net: u32,
    /// Worker threads (default: all cores). The drawing does not depend on it.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    threads: Option<u32>,
    /// No summary.
    #[arg(short, long)]
    quiet: bool,
}

/// Functions for `--graph`.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
enum GraphFunction {
    /// cos(r)·e^(−r/6) over [−10, 10]², r = √(x² + y²).
    Ripple,
    /// x² − y² over [−1, 1]².
    Saddle,
    /// The MATLAB "peaks" surface over [−3, 3]².
    Peaks,
}

fn positive(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v > 0.0 && v.is_finite() => Ok(v),
        _ => Err(format!("expected a positive number, got {s:?}")),
    }
}

fn non_negative(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v >= 0.0 && v.is_finite() => Ok(v),
        _ => Err(format!("expected a number ≥ 0, got {s:?}")),
    }
}

/// A paper width in millimetres: positive, at most 10 m.
fn paper_width(s: &str) -> Result<f64, String> {
    match positive(s)? {
        v if v <= 10_000.0 => Ok(v),
        _ => Err(format!("{s} mm is wider than the 10000 mm a drawing may be")),
    }
}

/// An angle in degrees from 0 to 180.
fn angle(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if (0.0..=180.0).contains(&v) => Ok(v),
        _ => Err(format!("expected an angle from 0 to 180 degrees, got {s:?}")),
    }
}

/// Output kinds by extension.
enum Kind {
    Svg,
    Pdf,
    Png,
    Hpgl,
}

fn output_kind(path: &Path) -> Result<Kind, Failure> {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    let kind = match ext.as_deref() {
        Some("svg") => Kind::Svg,
        Some("pdf") => Kind::Pdf,
        Some("png") => Kind::Png,
        Some("hpgl" | "plt") => Kind::Hpgl,
        _ => {
            return Err(Failure::input(format!(
                "{}: unknown drawing format; use .svg, .pdf, .hpgl, .plt or .png",
                path.display()
            )));
        }
    };
    crate::check_output_dir(path)?;
    Ok(kind)
}

pub fn run(a: &LinesArgs) -> Result<(), Failure> {
    let kind = output_kind(&a.output)?;
    let threads = a.threads.map_or(0, |t| t as usize);
    let pool =
        rayon::ThreadPoolBuilder::new().num_threads(threads).build().map_err(|e| Failure::work(e.to_string()))?;
    let start = Instant::now();
    let (drawing, summary) = match (a.graph, &a.scene) {
        (Some(g), _) => graph_drawing(g, a),
        (None, Some(path)) => {
            let scene = load(path, &a.parameters, &crate::EnvironmentArgs::default())?;
            let opts = Options {
                width_mm: a.width_mm,
                feature_angle_deg: a.feature_angle,
                hidden: a.hidden,
                reflections: !a.no_reflections,
                sampled: a.sampled,
                fill: a.fill,
                anaglyph: a.anaglyph,
                ..Options::default()
            };
            if a.anaglyph && !matches!(scene.camera, alhazen_scene::CameraDesc::Stereo { .. }) {
                return Err(Failure::input(format!(
                    "{}: --anaglyph needs a stereo camera (`type = \"stereo\"`)",
                    path.display()
                )));
            }
            let progress = StageBar::new(a.quiet);
            let drawn = pool.install(|| draw_reporting(&scene, &opts, &progress));
            progress.bar.finish_and_clear();
            let (d, s) = drawn.map_err(|e| Failure::input(format!("{}: {}", path.display(), camera_error(e))))?;
            let mut summary = format!(
                "{} scene lines → {} visible, {} hidden, {} reflected polylines ({} mirrors)",
                s.scene_lines, s.visible, s.hidden, s.reflected, s.mirrors
            );
            if s.tessellated > 0 {
                summary += &format!("; {} distorted round objects drawn from their tessellation", s.tessellated);
            }
            if s.skipped > 0 {
                summary += &format!("; {} CSG objects have no lines", s.skipped);
            }
            if a.fill {
                summary += &format!("; {} filled reflex polygons", s.fills);
            }
            (d, summary)
        }
        (None, None) => return Err(Failure::input("give a scene file or --graph")),
    };
    let (drawing, summary) = if a.optimize {
        let o = alhazen_lines::plotter::optimize(drawing, a.join_tolerance);
        let (b, f) = (o.before, o.after);
        let saved = if b.pen_up_mm > 0.0 { 100.0 * (1.0 - f.pen_up_mm / b.pen_up_mm) } else { 0.0 };
        let plot = format!(
            "; optimized for plotting: pen-up travel {:.0} mm → {:.0} mm ({saved:.0} % saved), {} → {} strokes",
            b.pen_up_mm, f.pen_up_mm, b.polylines, f.polylines
        );
        (o.drawing, summary + &plot)
    } else {
        (drawing, summary)
    };
    let stroke = |l: Layer| {
        let width = match l {
            Layer::Visible => a.stroke,
            Layer::Hidden => a.stroke_hidden,
            Layer::Reflected => a.stroke_reflected,
            Layer::Left | Layer::Right => a.stroke,
        };
        Stroke { width, ..default_stroke(l) }
    };
    let bytes = match kind {
        Kind::Svg => drawing.to_svg(stroke).into_bytes(),
        Kind::Pdf => drawing.to_pdf(stroke),
        Kind::Png => drawing.to_png(a.png_width, stroke).map_err(|e| Failure::work(e.to_string()))?,
        Kind::Hpgl => alhazen_lines::plotter::to_hpgl(&drawing).into_bytes(),
    };
    alhazen_render::output::write_atomically(&a.output, |f| std::io::Write::write_all(f, &bytes))
        .map_err(|e| Failure::work(format!("cannot write {}: {e}", a.output.display())))?;
    if !a.quiet {
        eprintln!("{summary} in {:.3} s → {}", start.elapsed().as_secs_f64(), a.output.display());
    }
    Ok(())
}

/// The drawing's stages on a terminal: a spinner while a stage is not counted, a bar with its
/// estimate when it is.
struct StageBar {
    bar: ProgressBar,
    done: AtomicU64,
}

impl StageBar {
    fn new(quiet: bool) -> StageBar {
        let bar = if quiet { ProgressBar::hidden() } else { ProgressBar::new_spinner() };
        bar.enable_steady_tick(std::time::Duration::from_millis(200));
        StageBar { bar, done: AtomicU64::new(0) }
    }
}

impl Progress for StageBar {
    fn stage(&self, name: &'static str, steps: u64) {
        let template = if steps == 0 {
            "{spinner} {msg} … elapsed {elapsed}"
        } else {
            "{spinner} {msg} [{bar:40}] {percent:>3}% {pos}/{len} elapsed {elapsed} eta {eta}"
        };
        let style = ProgressStyle::with_template(template).unwrap_or_else(|_| ProgressStyle::default_bar());
        self.done.store(0, Ordering::Relaxed);
        self.bar.set_message(name);
        self.bar.set_length(steps);
        self.bar.set_position(0);
        self.bar.set_style(style.progress_chars("=> "));
    }

    fn advance(&self, n: u64) {
        let done = self.done.fetch_add(n, Ordering::Relaxed) + n;
        // The bar takes a lock: tell it every 256 steps and at the end.
        if done % 256 < n || Some(done) == self.bar.length() {
            self.bar.set_position(done);
        }
    }
}

/// The drawing's own words for a camera it cannot use.
fn camera_error(e: alhazen_raster::pipeline::RasterError) -> String {
    let alhazen_raster::pipeline::RasterError::UnsupportedCamera(kind) = e;
    format!("cannot draw the camera: {kind}")
}

/// A floating-horizon drawing of a built-in function on paper `width_mm` wide.
fn graph_drawing(g: GraphFunction, a: &LinesArgs) -> (Drawing, String) {
    let (f, range): (&(dyn Fn(f64, f64) -> f64 + Sync), f64) = match g {
        GraphFunction::Ripple => (
            &|x: f64, y: f64| {
                let r = (x * x + y * y).sqrt();
                r.cos() * (-r / 6.0).exp()
            },
            10.0,
        ),
        GraphFunction::Saddle => (&|x: f64, y: f64| x * x - y * y, 1.0),
        GraphFunction::Peaks => (
            &|x: f64, y: f64| {
                3.0 * (1.0 - x).powi(2) * (-(x * x) - (y + 1.0).powi(2)).exp()
                    - 10.0 * (x / 5.0 - x.powi(3) - y.powi(5)) * (-x * x - y * y).exp()
                    - (-(x + 1.0).powi(2) - y * y).exp() / 3.0
            },
            3.0,
        ),
    };
    let n = a.net as usize;
    let graph = Graph { f, x: (-range, range), y: (-range, range), lines: (n, n) };
    // One pixel column per 0.05 mm.
    let w = a.width_mm / 0.05;
    let layout = Layout { w, h: 0.75 * w, wx: 0.4 * w, hx: 0.18 * w, hz: 0.3 * w };
    let lines = floating_horizon(&graph, &layout);
    let count = lines.len();
    let drawing = Drawing {
        size: Vec2::new(a.width_mm, 0.75 * a.width_mm),
        lines: lines.into_iter().map(|l| (Layer::Visible, l.into_iter().map(|p| p * 0.05).collect())).collect(),
        fills: vec![],
    };
    (drawing, format!("{g:?} graph, {n}×{n} net → {count} visible polylines"))
}
