//! `alhazen mirror …`: the exact reflex solver and the paper's figures from the command line.

use crate::Failure;
use alhazen_math::{Vec2, Vec3};
use alhazen_mirror::caustic::Side;
use alhazen_mirror::{Cylinder, MirrorError, Reflexes, Site, Sphere, figures};
use clap::{Args, Subcommand};
use serde::Deserialize;
use std::io::{BufRead, Write};
use std::path::{Path, PathBuf};

#[derive(Subcommand)]
pub enum MirrorCommand {
    /// Reflexes of points: reads JSON lines, writes one JSON line per query.
    #[command(after_help = r#"Input, one JSON object per line (from FILE or standard input):
  {"mirror":"sphere","center":[0,0,0],"radius":1,"eye":[0,0,5],"point":[3,0,4]}
  {"mirror":"cylinder","center":[0,0,0],"axis":[0,1,0],"radius":1,"eye":[0,1,6],"point":[2,3,1]}
  {"mirror":"sphere","center":[0,0,0],"radius":1,"eye_direction":[0,0,1],"point_direction":[1,1,0]}
"eye_direction" / "point_direction" instead of "eye" / "point" put them at infinity in that
direction (a parallel projection, the sun: the paper's equation (7)).
Output, one line per input line:
  {"reflexes":[[x,y,z]],"all":[{"point":[x,y,z],"kind":"outside"},…]}
"reflexes" holds the visible reflection on the outside (empty in the forbidden region); "all" every
real solution of the reflection condition ("outside", "inside", "virtual"), plus "circle" when a
point on a sphere's axis reflects in a whole circle (Theorem 2).
A "polygon" instead of a "point" asks whether its reflex overlaps itself (Theorems 7–9):
  {"mirror":"cylinder","center":[0,0,0],"axis":[0,1,0],"radius":1,"eye":[4,1,1],"polygon":[[…],…]}
gives {"projecting_lines":[{"point":[x,y,z],"direction":[x,y,z]}],"pieces":[[[x,y,z],…],…]}: the
lines of the polygon's plane that the eye sees as points in the mirror (its "contour"), and the
polygon split along those that cross it, whose reflexes do not overlap. A bad line gives
  {"line":N,"error":"…"}
and processing continues; the exit code is 2 if any line was bad."#)]
    Reflex {
        /// JSON-lines file (default: standard input).
        input: Option<PathBuf>,
    },
    /// Draws the catacaustic of a circle with its reflected rays (the paper's Fig. 5/9) as SVG.
    #[command(
        after_help = "Example:\n  alhazen mirror caustic --radius 1 --eye-distance 3 -o caustic.svg\n  alhazen mirror caustic --radius 1 --eye-distance inf -o nephroid.svg\n  alhazen mirror caustic --radius 1 --eye-distance 1 --inside -o cardioid.svg"
    )]
    Caustic(CausticArgs),
    /// Draws the confocal conics (foci eye and point) that touch the circle at the reflexes
    /// (the paper's Fig. 12) as SVG.
    #[command(after_help = "Example:\n  alhazen mirror conics --radius 1 --eye 3,0 --point 1.2,1.8 -o conics.svg")]
    Conics(ConicsArgs),
    /// The print to lay around a mirror cylinder so that a picture appears undistorted in it
    /// from the eye (the paper's anamorphoses, §2.4).
    #[command(
        after_help = "Examples:\n  alhazen mirror anamorph picture.png --radius 40 --height 150 --eye 0,300,400 --paper A3 --dpi 300 -o print.pdf\n  alhazen mirror anamorph drawing.svg --radius 40 --height 150 --eye 0,300,400 -o print.svg\n\nUnits are millimetres, y up, the cylinder stands on the paper with its axis on the y axis."
    )]
    Anamorph(crate::anamorph::AnamorphArgs),
}

#[derive(Args)]
pub struct CausticArgs {
    /// Radius of the mirror circle.
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    radius: f64,
    /// Distance of the eye from the centre; `inf` for parallel rays.
    #[arg(long, allow_negative_numbers = true)]
    eye_distance: f64,
    /// Reflection on the inside of the circle instead of the outside.
    #[arg(long)]
    inside: bool,
    /// Number of reflected rays drawn.
    #[arg(long, default_value_t = 48, value_parser = clap::value_parser!(u32).range(0..=100000))]
    rays: u32,
    /// Write the sphere's caustic surface instead (the curve turned about the axis through the
    /// eye and the centre, the x axis; the paper's Fig. 10) as a .ply mesh.
    #[arg(long)]
    surface: bool,
    /// Output file: .svg (the figure), or .ply with --surface.
    #[arg(short, long)]
    output: PathBuf,
}

#[derive(Args)]
pub struct ConicsArgs {
    /// Radius of the mirror circle (centred at the origin).
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    radius: f64,
    /// Eye position `x,y`.
    #[arg(long, value_parser = parse_vec2, allow_hyphen_values = true)]
    eye: Vec2,
    /// Point position `x,y`.
    #[arg(long, value_parser = parse_vec2, allow_hyphen_values = true)]
    point: Vec2,
    /// Output SVG file.
    #[arg(short, long)]
    output: PathBuf,
}

fn parse_vec2(s: &str) -> Result<Vec2, String> {
    parse_numbers::<2>(s).map(|[x, y]| Vec2::new(x, y))
}

/// `N` finite numbers separated by commas (`x,y` or `x,y,z` arguments).
pub(crate) fn parse_numbers<const N: usize>(s: &str) -> Result<[f64; N], String> {
    let parts: Vec<f64> =
        s.split(',').map(|p| p.trim().parse::<f64>().map_err(|e| format!("`{p}`: {e}"))).collect::<Result<_, _>>()?;
    match <[f64; N]>::try_from(parts) {
        Ok(v) if v.iter().all(|x| x.is_finite()) => Ok(v),
        _ => Err(format!("expected {N} finite numbers separated by commas")),
    }
}

pub fn run(cmd: &MirrorCommand) -> Result<(), Failure> {
    match cmd {
        MirrorCommand::Reflex { input } => run_reflex(input.as_deref()),
        MirrorCommand::Caustic(a) => {
            if a.surface {
                check_extension(&a.output, "ply", "--surface writes a .ply mesh")?;
            } else {
                check_svg(&a.output)?;
            }
            let radius_ok = a.radius > 0.0 && a.radius.is_finite();
            if !radius_ok || a.eye_distance.is_nan() || a.eye_distance <= 0.0 {
                return Err(Failure::input("--radius must be positive and finite, --eye-distance positive (or inf)"));
            }
            if !a.inside && a.eye_distance <= a.radius {
                return Err(Failure::input(
                    "an eye inside the circle sees only reflections on the inside: add --inside",
                ));
            }
            let side = if a.inside { Side::Inside } else { Side::Outside };
            if a.surface {
                return write_caustic_surface(a.radius, a.eye_distance, side, &a.output);
            }
            write_text(&a.output, &figures::caustic_svg(a.radius, a.eye_distance, side, a.rays as usize))
        }
        MirrorCommand::Conics(a) => {
            check_svg(&a.output)?;
            let svg = figures::conics_svg(a.radius, a.eye, a.point).map_err(|e| Failure::input(e.to_string()))?;
            write_text(&a.output, &svg)
        }
        MirrorCommand::Anamorph(a) => crate::anamorph::run(a),
    }
}

/// The caustic surface of a sphere of radius `r` at the origin, the eye at `e` on the x axis
/// (`inf`: parallel rays along it), as a PLY mesh; cut 4 radii (or twice the eye's distance)
/// from the centre where it runs off to infinity.
fn write_caustic_surface(r: f64, e: f64, side: Side, path: &Path) -> Result<(), Failure> {
    use alhazen_mirror::caustic::{Eye, sphere_surface};
    let eye = if e.is_finite() { Eye::At(e) } else { Eye::AtInfinity };
    let clip = if e.is_finite() { (2.0 * e).max(4.0 * r) } else { 4.0 * r };
    let mesh = sphere_surface(Vec3::ZERO, Vec3::X, r, eye, side, 720, 96, clip);
    if mesh.triangles.is_empty() {
        return Err(Failure::input("this eye sees no caustic on that side of the sphere"));
    }
    let bytes = alhazen_scene::write::ply_bytes(&mesh);
    alhazen_render::output::write_atomically(path, |f| f.write_all(&bytes))
        .map_err(|e| Failure::work(format!("cannot write {}: {e}", path.display())))
}

/// Refuses an output whose extension is not `ext`, saying `why`, before any work.
fn check_extension(path: &Path, ext: &str, why: &str) -> Result<(), Failure> {
    let ok = path.extension().and_then(|e| e.to_str()).is_some_and(|e| e.eq_ignore_ascii_case(ext));
    if ok { Ok(()) } else { Err(Failure::input(format!("{}: {why}", path.display()))) }
}

/// Refuses an output that is not an `.svg` file (the figures are SVG text), before any work.
fn check_svg(path: &Path) -> Result<(), Failure> {
    if path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() != Some("svg") {
        return Err(Failure::input(format!("{}: this figure is written as SVG; name the output .svg", path.display())));
    }
    crate::check_output_dir(path)
}

/// Writes a text file atomically.
pub fn write_text(path: &Path, text: &str) -> Result<(), Failure> {
    alhazen_render::output::write_atomically(path, |f| f.write_all(text.as_bytes()))
        .map_err(|e| Failure::work(format!("cannot write {}: {e}", path.display())))
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Query {
    mirror: String,
    center: [f64; 3],
    radius: f64,
    eye: Option<[f64; 3]>,
    eye_direction: Option<[f64; 3]>,
    point: Option<[f64; 3]>,
    point_direction: Option<[f64; 3]>,
    axis: Option<[f64; 3]>,
    polygon: Option<Vec<[f64; 3]>>,
}

/// The site a query names by `at` (a point) or `toward` (a direction to infinity): exactly one.
fn site(name: &str, at: Option<[f64; 3]>, toward: Option<[f64; 3]>) -> Result<Site, String> {
    match (at, toward) {
        (Some(p), None) => Ok(Site::At(Vec3::from_array(p))),
        (None, Some(d)) => {
            let d = Vec3::from_array(d);
            if !(d.is_finite() && d != Vec3::ZERO) {
                return Err(format!("\"{name}_direction\" must be a non-zero finite vector"));
            }
            Ok(Site::Toward(d))
        }
        (None, None) => Err(format!("missing \"{name}\" (a point) or \"{name}_direction\" (a point at infinity)")),
        (Some(_), Some(_)) => Err(format!("give \"{name}\" or \"{name}_direction\", not both")),
    }
}

/// The reflexes `q` asks for, solved for the mirror scaled to unit radius at the origin (the
/// solver's tolerances are absolute, so a mirror of radius 1e-300 or a scene at 1e150 would
/// otherwise find nothing), with the map back to the query's coordinates.
fn solve(q: &Query) -> Result<(Reflexes, Unscale), String> {
    let center = Vec3::from_array(q.center);
    if !(q.radius.is_finite() && q.radius > 0.0) {
        return Err(format!("\"radius\" must be positive, not {}", q.radius));
    }
    let unscale = Unscale { center, scale: q.radius };
    // Points into the unit mirror's frame; directions need no change.
    let local = |s: Site| match s {
        Site::At(p) => Site::At((p - center) / q.radius),
        toward => toward,
    };
    let eye = local(site("eye", q.eye, q.eye_direction)?);
    let point = local(site("point", q.point, q.point_direction)?);
    // Beyond 1e100 radii squares overflow: such an eye or point is at infinity for the solver.
    let near = |s: Site| match s {
        Site::At(p) => p.length() <= 1e100,
        Site::Toward(_) => true,
    };
    if !(near(eye) && near(point)) {
        return Err("the eye or the point is more than 1e100 radii from the mirror: too far to solve (give a direction instead)".into());
    }
    let result: Result<Reflexes, MirrorError> = match (q.mirror.as_str(), q.axis) {
        ("sphere", None) => Sphere { center: Vec3::ZERO, radius: 1.0 }.reflexes(eye, point),
        ("sphere", Some(_)) => return Err("a sphere takes no \"axis\"".into()),
        ("cylinder", Some(axis)) => {
            Cylinder { center: Vec3::ZERO, axis: Vec3::from_array(axis), radius: 1.0 }.reflexes(eye, point)
        }
        ("cylinder", None) => return Err("a cylinder needs \"axis\"".into()),
        (other, _) => return Err(format!("unknown mirror \"{other}\": expected \"sphere\" or \"cylinder\"")),
    };
    result.map(|r| (r, unscale)).map_err(|e| e.to_string())
}

/// From the unit mirror's coordinates back to the query's.
struct Unscale {
    center: Vec3,
    scale: f64,
}

impl Unscale {
    fn point(&self, v: Vec3) -> Vec3 {
        self.center + v * self.scale
    }
}

fn answer((r, back): &(Reflexes, Unscale)) -> serde_json::Value {
    let p = |v: Vec3| serde_json::json!([v.x, v.y, v.z]);
    let kind = |k: alhazen_mirror::ReflexKind| format!("{k:?}").to_lowercase();
    let mut all: Vec<serde_json::Value> =
        r.all().map(|x| serde_json::json!({"point": p(back.point(x.point)), "kind": kind(x.kind)})).collect();
    if let Some(c) = r.circle {
        all.push(serde_json::json!({"circle": {"center": p(back.point(c.center)), "axis": p(c.axis), "radius": c.radius * back.scale}, "kind": kind(c.kind)}));
    }
    serde_json::json!({"reflexes": r.visible().map(|v| vec![p(back.point(v.point))]).unwrap_or_default(), "all": all})
}

/// A polygon's overlap test (Glaeser §4, Theorems 7–9): its plane's projecting lines on the
/// mirror seen from the eye, and the pieces it splits into along them.
fn overlap(q: &Query) -> Result<serde_json::Value, String> {
    use alhazen_mirror::overlap::{Plane, split_polygon};
    if q.point.is_some() || q.point_direction.is_some() {
        return Err("give \"point\" (a reflex) or \"polygon\" (an overlap test), not both".into());
    }
    let Some(eye) = q.eye.map(Vec3::from_array) else {
        return Err("a polygon's overlap test needs a finite \"eye\" (the paper's (22) and (27))".into());
    };
    let poly: Vec<Vec3> = q.polygon.iter().flatten().map(|p| Vec3::from_array(*p)).collect();
    if poly.len() < 3 || !poly.iter().all(|p| p.is_finite()) || !eye.is_finite() {
        return Err("\"polygon\" needs at least 3 finite points".into());
    }
    let plane = Plane::of_polygon(&poly).ok_or("the polygon has no area (its points are collinear)")?;
    if poly.iter().any(|p| (plane.normal.dot(*p) - plane.offset).abs() > 1e-9 * (1.0 + p.length())) {
        return Err("the polygon's points do not lie in one plane".into());
    }
    let center = Vec3::from_array(q.center);
    if !(q.radius.is_finite() && q.radius > 0.0) {
        return Err(format!("\"radius\" must be positive, not {}", q.radius));
    }
    let lines = match (q.mirror.as_str(), q.axis) {
        ("sphere", None) => Sphere { center, radius: q.radius }.projecting_lines(eye, plane),
        ("cylinder", Some(axis)) => {
            Cylinder { center, axis: Vec3::from_array(axis), radius: q.radius }.projecting_lines(eye, plane)
        }
        ("sphere", Some(_)) => return Err("a sphere takes no \"axis\"".into()),
        ("cylinder", None) => return Err("a cylinder needs \"axis\"".into()),
        (other, _) => return Err(format!("unknown mirror \"{other}\": expected \"sphere\" or \"cylinder\"")),
    }
    .map_err(|e| e.to_string())?;
    let p = |v: Vec3| serde_json::json!([v.x, v.y, v.z]);
    let pieces: Vec<serde_json::Value> = split_polygon(&poly, &lines)
        .iter()
        .map(|piece| serde_json::Value::Array(piece.iter().map(|v| p(*v)).collect()))
        .collect();
    let lines: Vec<serde_json::Value> =
        lines.iter().map(|l| serde_json::json!({"point": p(l.mirror_point), "direction": p(l.direction)})).collect();
    Ok(serde_json::json!({"projecting_lines": lines, "pieces": pieces}))
}

/// serde's message without its position inside the one line (the reply's `line` field says
/// which line), with the column kept: `column 2: expected ident`.
fn json_error(e: serde_json::Error) -> String {
    let text = e.to_string();
    let message = text.split(" at line ").next().unwrap_or(&text);
    if e.column() > 0 { format!("column {}: {message}", e.column()) } else { message.to_string() }
}

fn run_reflex(input: Option<&Path>) -> Result<(), Failure> {
    let reader: Box<dyn BufRead> = match input {
        Some(path) => Box::new(std::io::BufReader::new(
            std::fs::File::open(path).map_err(|e| Failure::input(format!("cannot read {}: {e}", path.display())))?,
        )),
        None => Box::new(std::io::stdin().lock()),
    };
    let stdout = std::io::stdout();
    let mut out = std::io::BufWriter::new(stdout.lock());
    let mut bad = 0usize;
    for (no, line) in reader.lines().enumerate() {
        let line = line.map_err(|e| Failure::input(format!("cannot read input: {e}")))?;
        if line.trim().is_empty() {
            continue;
        }
        let reply = serde_json::from_str::<Query>(&line).map_err(json_error).and_then(|q| match q.polygon {
            Some(_) => overlap(&q),
            None => solve(&q).map(|r| answer(&r)),
        });
        let value = reply.unwrap_or_else(|e| {
            bad += 1;
            serde_json::json!({"line": no + 1, "error": e})
        });
        writeln!(out, "{value}").map_err(|e| Failure::work(format!("cannot write output: {e}")))?;
    }
    out.flush().map_err(|e| Failure::work(format!("cannot write output: {e}")))?;
    if bad > 0 { Err(Failure::input(format!("{bad} input line(s) could not be answered"))) } else { Ok(()) }
}
