//! `alhazen-lines`: exact line drawings of a scene with its reflections in spherical and
//! cylindrical mirrors — Glaeser, *Reflections on spheres and cylinders of revolution*, §3–4,
//! and the course's visibility algorithms for line drawings.
//!
//! The pipeline, one module each:
//! * [`curves`] — the lines in space: mesh edges (boundary, feature by dihedral angle,
//!   silhouettes), exact contours of spheres, cylinders and cones, rims;
//! * [`visibility`] — hidden-line removal: lines are cut where their images cross (segment
//!   against segment with robust orientation tests) or where they pierce a surface, and each
//!   piece is decided by one exact ray test;
//! * [`intersect`] — intersection curves where objects meet (plane sections of spheres and
//!   cylinders, sphere pairs, face pairs), exactly;
//! * [`csg`] — CSG bodies: their operands' lines and intersection curves cut to the body's
//!   boundary;
//! * [`reflect`] — every line reflected in every mirror by the exact reflex solver, knots as in
//!   the paper's Fig. 16, drawn where the eye sees the mirror point and the reflected ray
//!   reaches the line;
//! * [`drawing`] — millimetres on paper: SVG, PDF (layers), antialiased PNG preview;
//! * [`plotter`] — pen plotters: joined, ordered strokes and HP-GL;
//! * [`horizon`] — the floating-horizon algorithm for graphs `z = f(x, y)`.
//!
//! ```no_run
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let scene = alhazen_scene::load_scene(std::path::Path::new("scenes/lines/fig21-cylinder-in-sphere.toml"))?;
//! let (drawing, stats) = alhazen_lines::draw(&scene, &alhazen_lines::Options::default())?;
//! std::fs::write("fig21.svg", drawing.to_svg(alhazen_lines::drawing::default_stroke))?;
//! println!("{} visible polylines", stats.visible);
//! # Ok(()) }
//! ```

pub mod contour;
pub mod csg;
pub mod curves;
pub mod drawing;
pub mod fill;
pub mod horizon;
pub mod intersect;
pub mod plotter;
pub mod reflect;
pub mod view;
pub mod visibility;

use alhazen_math::Vec3;
use alhazen_raster::pipeline::RasterError;
use alhazen_render::World;
use alhazen_scene::Scene;
use drawing::{Drawing, Layer};
use rayon::prelude::*;

/// What to draw and how finely.
#[derive(Clone, Copy, Debug)]
pub struct Options {
    /// Paper width in millimetres (the height follows the scene's aspect ratio).
    pub width_mm: f64,
    /// Largest distance on paper between a drawn chord and the true curve, millimetres.
    pub tol_mm: f64,
    /// Mesh edges whose faces meet at more than this angle (degrees) are drawn.
    pub feature_angle_deg: f64,
    /// Keep hidden lines (on their own layer).
    pub hidden: bool,
    /// Draw reflections in spherical, cylindrical and plane mirrors.
    pub reflections: bool,
    /// Decide visibility by sampling every this many film pixels instead of exactly (the
    /// baseline of the benchmark, as fogleman/ln does).
    pub sampled: Option<f64>,
    /// Fill the reflexes of the scene's polygons in the mirrors, in painter's order ([`fill`]).
    pub fill: bool,
    /// A stereo camera's eyes as one red–cyan anaglyph (left eye red, right eye cyan, on one
    /// paper, hidden lines left out) instead of side by side.
    pub anaglyph: bool,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            width_mm: 200.0,
            tol_mm: 0.005,
            feature_angle_deg: 30.0,
            hidden: false,
            reflections: true,
            sampled: None,
            fill: false,
            anaglyph: false,
        }
    }
}

/// What a drawing holds.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Stats {
    /// Lines found in the scene (edges, contours, rims).
    pub scene_lines: usize,
    /// Visible polylines.
    pub visible: usize,
    /// Hidden polylines.
    pub hidden: usize,
    /// Reflected polylines.
    pub reflected: usize,
    /// Mirrors found.
    pub mirrors: usize,
    /// Filled reflex polygons.
    pub fills: usize,
    /// Round objects drawn from their tessellation (their transform is not a similarity).
    pub tessellated: usize,
    /// Objects without lines (planes in parallel views).
    pub skipped: usize,
}

/// Told how far a drawing has come: the stages in order, each with its count of steps (0 when
/// it is not counted), then steps done. Called from worker threads.
pub trait Progress: Sync {
    /// A stage begins.
    fn stage(&self, name: &'static str, steps: u64);
    /// `n` more steps of the current stage are done.
    fn advance(&self, n: u64);
}

/// Progress nobody watches.
pub struct Unwatched;

impl Progress for Unwatched {
    fn stage(&self, _: &'static str, _: u64) {}
    fn advance(&self, _: u64) {}
}

/// Draws `scene` from its camera.
pub fn draw(scene: &Scene, opts: &Options) -> Result<(Drawing, Stats), RasterError> {
    draw_reporting(scene, opts, &Unwatched)
}

/// [`draw`], telling `progress` of each stage: long on scenes of millions of triangles. A
/// stereo camera gives both eyes' drawings side by side on paper twice as wide (left eye on
/// the left), as the ray tracer's stereo images are.
pub fn draw_reporting(scene: &Scene, opts: &Options, progress: &dyn Progress) -> Result<(Drawing, Stats), RasterError> {
    let aspect = scene.render.width as f64 / scene.render.height as f64;
    let Some(eyes) = scene.camera.stereo_eyes(aspect) else { return draw_view(scene, opts, progress) };
    let mut halves = vec![];
    for camera in eyes {
        let eye = Scene { camera, ..scene.clone() };
        halves.push(draw_view(&eye, opts, progress)?);
    }
    let (right, r) = halves.pop().expect("two eyes");
    let (mut left, l) = halves.pop().expect("two eyes");
    if opts.anaglyph {
        return Ok(anaglyph(left, right, l, r));
    }
    let shift = alhazen_math::Vec2::new(left.size.x, 0.0);
    left.lines
        .extend(right.lines.into_iter().map(|(layer, pts)| (layer, pts.into_iter().map(|p| p + shift).collect())));
    left.fills.extend(
        right
            .fills
            .into_iter()
            .map(|f| drawing::Fill { points: f.points.into_iter().map(|p| p + shift).collect(), ..f }),
    );
    left.size.x += right.size.x;
    let stats = Stats {
        visible: l.visible + r.visible,
        hidden: l.hidden + r.hidden,
        reflected: l.reflected + r.reflected,
        fills: l.fills + r.fills,
        ..l
    };
    Ok((left, stats))
}

/// Two eyes' drawings on one paper as a red–cyan anaglyph: each eye's visible and reflected
/// lines on its own layer ([`Layer::Left`], [`Layer::Right`]), hidden lines and fills left out.
fn anaglyph(left: Drawing, right: Drawing, l: Stats, r: Stats) -> (Drawing, Stats) {
    let eye = |d: Drawing, layer: Layer| {
        d.lines.into_iter().filter(|(k, _)| *k != Layer::Hidden).map(move |(_, pts)| (layer, pts))
    };
    let size = left.size;
    let lines = eye(left, Layer::Left).chain(eye(right, Layer::Right)).collect();
    let stats =
        Stats { visible: l.visible + r.visible, hidden: 0, reflected: l.reflected + r.reflected, fills: 0, ..l };
    (Drawing { size, lines, fills: vec![] }, stats)
}

/// The drawing from one camera.
fn draw_view(scene: &Scene, opts: &Options, progress: &dyn Progress) -> Result<(Drawing, Stats), RasterError> {
    progress.stage("building the scene's index", 0);
    let world = World::build(scene);
    let view = view::View::new(scene, &world, opts.width_mm)?;
    let edge_opts = curves::EdgeOptions { feature_angle: opts.feature_angle_deg.to_radians() };
    progress.stage("finding edges, contours and intersections", 0);
    let polyhedra = curves::polyhedra(scene);
    let (lines, tessellated, skipped) = lines_in_space(scene, &polyhedra, &world, &view, &edge_opts);
    let chords = visibility::chords(&lines, &view, opts.tol_mm);
    progress.stage("deciding visibility", chords.len() as u64);
    let pieces = match opts.sampled {
        Some(step) => visibility::pieces_sampled(&lines, &chords, &view, &world, step, progress),
        None => visibility::pieces(&lines, &chords, &view, &world, progress),
    };
    let mut drawing = Drawing { size: view.paper(), lines: vec![], fills: vec![] };
    for p in &pieces {
        if !p.visible && !opts.hidden {
            continue;
        }
        let layer = if p.visible { Layer::Visible } else { Layer::Hidden };
        drawing.lines.push((layer, polyline(&lines[p.line].curve, p.s, &view, opts.tol_mm)));
    }
    let mirrors = if opts.reflections { reflect::mirrors(scene, &polyhedra) } else { vec![] };
    let tol_px = opts.tol_mm / view.mm_per_px;
    let ropts = reflect::ReflectOptions { tol_px, knots: 16 };
    let jobs: Vec<(usize, usize)> = (0..mirrors.len()).flat_map(|m| (0..lines.len()).map(move |l| (m, l))).collect();
    progress.stage("reflecting lines in mirrors", jobs.len() as u64);
    let reflected: Vec<Vec<Vec<Vec3>>> = jobs
        .par_iter()
        .map(|&(m, l)| {
            let runs = reflect::reflect_line(&mirrors[m], &lines[l], &view, &world, &ropts);
            progress.advance(1);
            runs
        })
        .collect();
    let mut reflected = reflected;
    progress.stage("reflecting contours and silhouettes", 0);
    reflected.extend(reflex_contours(scene, &mirrors, &view, &world, tol_px));
    reflected.extend(mesh_reflex_silhouettes(scene, &polyhedra, &mirrors, &view, &world, &edge_opts, tol_px));
    for run in reflected.into_iter().flatten() {
        drawing.lines.push((Layer::Reflected, run.iter().map(|p| view.to_paper(*p)).collect()));
    }
    if opts.fill {
        progress.stage("filling reflexes", 0);
        drawing.fills = fill::reflex_fills(scene, &mirrors, &view);
    }
    progress.stage("joining lines", 0);
    let drawing = drawing.clipped().joined();
    let stats = Stats {
        scene_lines: lines.len(),
        visible: drawing.count(Layer::Visible),
        hidden: drawing.count(Layer::Hidden),
        reflected: drawing.count(Layer::Reflected),
        mirrors: mirrors.len(),
        fills: drawing.fills.len(),
        tessellated,
        skipped,
    };
    Ok((drawing, stats))
}

/// Every line of the scene in space for this view — edges, contours, rims, horizons and
/// intersection curves; CSG bodies' from their operands, cut to the body's boundary ([`csg`]) —
/// with the counts of objects drawn from their tessellation and of objects without lines.
pub fn lines_in_space(
    scene: &Scene,
    polyhedra: &[Option<Vec<[Vec3; 3]>>],
    world: &World,
    view: &view::View,
    edge_opts: &curves::EdgeOptions,
) -> (Vec<curves::SceneLine>, usize, usize) {
    let expansion = csg::Expansion::of(scene);
    let expanded_polyhedra;
    let (line_scene, line_polyhedra) = match &expansion {
        Some(x) => {
            expanded_polyhedra = curves::polyhedra(&x.scene);
            (&x.scene, &expanded_polyhedra[..])
        }
        None => (scene, polyhedra),
    };
    let (mut lines, tessellated, skipped) = curves::scene_lines(line_scene, line_polyhedra, view, edge_opts);
    lines.extend(intersect::intersection_lines(line_scene, line_polyhedra));
    let lines = match &expansion {
        Some(x) => x.restrict(lines, world),
        None => lines,
    };
    (lines, tessellated, skipped)
}

/// The reflex contours (Theorem 10) of every sphere, cylinder and cone in every mirror.
fn reflex_contours(
    scene: &Scene,
    mirrors: &[reflect::Mirror],
    view: &view::View,
    world: &World,
    tol_px: f64,
) -> Vec<Vec<Vec<Vec3>>> {
    let jobs: Vec<(usize, usize)> =
        (0..mirrors.len()).flat_map(|m| (0..scene.objects.len()).map(move |o| (m, o))).collect();
    jobs.par_iter()
        .filter(|&&(m, o)| mirrors[m].object() != o as u32)
        .filter_map(|&(m, o)| {
            let obj = &scene.objects[o];
            let surface = contour::Surface::of(&obj.shape, &obj.transform, mirrors[m].center())?;
            let curves = contour::reflex_contour(&surface, &mirrors[m], view);
            let own = [o as u32];
            let runs = curves.iter().flat_map(|c| {
                let knots = reflect::uniform(c.len() - 1);
                // A convex object cannot hide its own contour.
                let leeway = view::Leeway { objects: &own, near: 1.0 };
                reflect::reflect_path(&mirrors[m], reflect::polyline_path(c), &knots, &leeway, view, world, tol_px)
            });
            Some(runs.collect::<Vec<_>>())
        })
        .collect()
}

/// The silhouettes of meshes as seen in each mirror: smooth edges whose faces turn one to, one
/// away from the reflected ray at the edge's midpoint (the polyhedral reflex contour).
fn mesh_reflex_silhouettes(
    scene: &Scene,
    polyhedra: &[Option<Vec<[Vec3; 3]>>],
    mirrors: &[reflect::Mirror],
    view: &view::View,
    world: &World,
    opts: &curves::EdgeOptions,
    tol_px: f64,
) -> Vec<Vec<Vec<Vec3>>> {
    if mirrors.is_empty() {
        return vec![];
    }
    let cos_feature = opts.feature_angle.cos();
    let meshes: Vec<(u32, Vec<curves::MeshEdge>)> = scene
        .objects
        .iter()
        .enumerate()
        .filter(|(_, o)| matches!(o.shape, alhazen_scene::Shape::Mesh { .. }))
        .filter_map(|(i, _)| Some((i as u32, curves::mesh_edges(polyhedra[i].as_deref()?))))
        .collect();
    let jobs: Vec<(usize, usize)> = (0..mirrors.len()).flat_map(|m| (0..meshes.len()).map(move |k| (m, k))).collect();
    jobs.par_iter()
        .filter(|&&(m, k)| mirrors[m].object() != meshes[k].0)
        .map(|&(m, k)| {
            let mirror = &mirrors[m];
            let toward = |mid: Vec3| mirror.reflex(view.viewer(), mid).map(|r| r - mid);
            let knots = reflect::uniform(4);
            meshes[k]
                .1
                .iter()
                .filter(|e| !curves::is_feature(e, cos_feature) && curves::is_silhouette(e, toward))
                .flat_map(|e| {
                    let (a, b) = (e.a, e.b);
                    let own = view::Leeway::NONE;
                    reflect::reflect_path(mirror, move |s| a + (b - a) * s, &knots, &own, view, world, tol_px)
                })
                .collect()
        })
        .collect()
}

/// The piece `s` of a curve as a polyline on paper within `tol_mm`.
fn polyline(curve: &curves::Curve, s: (f64, f64), view: &view::View, tol_mm: f64) -> Vec<alhazen_math::Vec2> {
    let knots = curve.knots(view, tol_mm);
    let mut pts = vec![view.to_paper(curve.point(s.0))];
    for &k in knots.iter().filter(|&&k| k > s.0 && k < s.1) {
        pts.push(view.to_paper(curve.point(k)));
    }
    pts.push(view.to_paper(curve.point(s.1)));
    pts
}
