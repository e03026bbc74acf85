//! CSG bodies in line drawings: their operands' lines and intersection curves, cut to the body's
//! boundary, measured against the closed forms of a box with a corner cut away by a ball and a
//! ball threaded on a rod; then drawn end to end.

use alhazen_lines::curves::{Curve, EdgeOptions, LineKind, SceneLine};
use alhazen_lines::view::View;
use alhazen_lines::{Options, draw, lines_in_space};
use alhazen_math::Vec3;
use alhazen_render::World;
use std::f64::consts::FRAC_PI_2;

const CAMERA: &str =
    "[render]\nwidth = 400\nheight = 300\n[camera]\neye = [3.0, 2.5, 4.0]\ntarget = [0, 0, 0]\nfov = 60\n";

fn lines_of(text: &str) -> Vec<SceneLine> {
    let scene = alhazen_scene::parse_scene("csg.toml".as_ref(), &format!("{CAMERA}{text}")).unwrap();
    let world = World::build(&scene);
    let view = View::new(&scene, &world, 200.0).unwrap();
    let polyhedra = alhazen_lines::curves::polyhedra(&scene);
    lines_in_space(&scene, &polyhedra, &world, &view, &EdgeOptions { feature_angle: 30f64.to_radians() }).0
}

/// Length of a curve by fine chords.
fn length(c: &Curve) -> f64 {
    (0..1000).map(|k| (c.point((k + 1) as f64 / 1000.0) - c.point(k as f64 / 1000.0)).length()).sum()
}

fn points(c: &Curve) -> impl Iterator<Item = Vec3> + '_ {
    (0..=20).map(|k| c.point(k as f64 / 20.0))
}

#[test]
fn a_box_with_a_corner_cut_away_by_a_ball() {
    let lines = lines_of(
        "[[object]]\nshape = \"csg\"\nop = \"difference\"\n\
         a = { shape = \"box\", min = [-1, -1, -1], max = [1, 1, 1] }\n\
         b = { shape = \"sphere\", center = [1, 1, 1], radius = 1.2 }\n",
    );
    let centre = Vec3::ONE;
    let edges: Vec<&SceneLine> = lines.iter().filter(|l| l.kind == LineKind::Edge).collect();
    let arcs: Vec<&SceneLine> = lines.iter().filter(|l| matches!(l.kind, LineKind::Intersection { .. })).collect();
    assert!(lines.iter().all(|l| l.object == 0), "every line given back to the body");
    // The ball's contour is all inside the box or outside it: never on the body's boundary
    // where the eye could see it, but what is kept must lie outside the ball.
    for l in &lines {
        for p in points(&l.curve) {
            assert!((p - centre).length() >= 1.2 - 1e-3, "{:?} inside the ball", l.kind);
            assert!(p.abs().max_element() <= 1.0 + 1e-3, "{:?} outside the box", l.kind);
        }
    }
    // Twelve edges of 2, the three at the cut corner shortened by 1.2 each.
    let edge_length: f64 = edges.iter().map(|l| length(&l.curve)).sum();
    assert!((edge_length - (24.0 - 3.0 * 1.2)).abs() < 1e-6, "edges {edge_length}");
    // Three quarter circles of radius 1.2 where the ball leaves the faces it cuts.
    let arc_length: f64 = arcs.iter().map(|l| length(&l.curve)).sum();
    assert!((arc_length - 3.0 * 1.2 * FRAC_PI_2).abs() < 1e-3, "arcs {arc_length}");
}

#[test]
fn a_ball_threaded_on_a_rod() {
    let lines = lines_of(
        "[[object]]\nshape = \"csg\"\nop = \"union\"\n\
         a = { shape = \"sphere\", center = [0, 0, 0], radius = 0.6 }\n\
         b = { shape = \"cylinder\", base = [0, -0.9, 0], top = [0, 0.9, 0], radius = 0.3 }\n",
    );
    let y0 = (0.36f64 - 0.09).sqrt();
    // The rod's contour lines run from the rims to the ball only.
    let contours: Vec<&SceneLine> =
        lines.iter().filter(|l| l.kind == LineKind::Contour && matches!(l.curve, Curve::Segment { .. })).collect();
    let rod: f64 = contours.iter().map(|l| length(&l.curve)).sum();
    assert!((rod - 4.0 * (0.9 - y0)).abs() < 1e-6, "rod contours {rod}");
    for l in &contours {
        assert!(points(&l.curve).all(|p| p.y.abs() >= y0 - 1e-6), "a rod contour inside the ball");
    }
    // The two rims whole, and the two circles where the rod enters the ball (a crease).
    let rims: f64 = lines.iter().filter(|l| l.kind == LineKind::Rim).map(|l| length(&l.curve)).sum();
    assert!((rims - 2.0 * std::f64::consts::TAU * 0.3).abs() < 1e-3, "rims {rims}");
    let creases: f64 =
        lines.iter().filter(|l| matches!(l.kind, LineKind::Intersection { .. })).map(|l| length(&l.curve)).sum();
    assert!((creases - 2.0 * std::f64::consts::TAU * 0.3).abs() < 1e-2, "creases {creases}");
    // The ball's contour: a small circle, kept but where the rod passes through it.
    assert!(lines.iter().any(|l| l.kind == LineKind::Contour && matches!(l.curve, Curve::Arc { .. })));
}

#[test]
fn a_surface_that_does_not_change_the_body_leaves_no_crease() {
    // A ∪ (B ∩ C) with C inside A: the body is A. B's surface crosses A's, but across that
    // circle the body is A on both sides (two neighbouring quadrants inside): no line there.
    let lines = lines_of(
        "[[object]]\nshape = \"csg\"\nop = \"union\"\n\
         a = { shape = \"sphere\", center = [0, 0, 0], radius = 1 }\n\
         b = { shape = \"csg\", op = \"intersection\", \
               a = { shape = \"sphere\", center = [1, 0, 0], radius = 0.5 }, \
               b = { shape = \"sphere\", center = [0.5, 0, 0], radius = 0.3 } }\n",
    );
    assert_eq!(lines.len(), 1, "{lines:?}");
    assert!(matches!(lines[0].curve, Curve::Arc { radius, .. } if radius < 1.0 && radius > 0.9));
    // The same balls as A ∪ B: the circle where B leaves A is a crease now.
    let lines = lines_of(
        "[[object]]\nshape = \"csg\"\nop = \"union\"\n\
         a = { shape = \"sphere\", center = [0, 0, 0], radius = 1 }\n\
         b = { shape = \"sphere\", center = [1, 0, 0], radius = 0.5 }\n",
    );
    let circle: f64 =
        lines.iter().filter(|l| matches!(l.kind, LineKind::Intersection { .. })).map(|l| length(&l.curve)).sum();
    // Radius of the circle where |p| = 1 and |p − (1, 0, 0)| = 0.5: x = 0.875.
    let r = (1.0f64 - 0.875 * 0.875).sqrt();
    assert!((circle - std::f64::consts::TAU * r).abs() < 1e-4, "{circle}");
}

#[test]
fn csg_bodies_are_drawn_with_their_visibility() {
    let text = format!(
        "{CAMERA}[[object]]\nshape = \"csg\"\nop = \"difference\"\n\
         a = {{ shape = \"box\", min = [-1, -1, -1], max = [1, 1, 1] }}\n\
         b = {{ shape = \"sphere\", center = [1, 1, 1], radius = 1.2 }}\n"
    );
    let scene = alhazen_scene::parse_scene("csg.toml".as_ref(), &text).unwrap();
    let (drawing, stats) = draw(&scene, &Options { hidden: true, ..Options::default() }).unwrap();
    assert_eq!(stats.skipped, 0);
    assert!(stats.visible > 0 && stats.hidden > 0, "{stats:?}");
    // The box's far corner (-1, -1, -1) is hidden; its near corner was cut away, so no line of
    // the drawing reaches the corner's image.
    let view = View::new(&scene, &World::build(&scene), 200.0).unwrap();
    let cut = view.to_paper(Vec3::ONE);
    let nearest = drawing.lines.iter().flat_map(|(_, pts)| pts).map(|p| (*p - cut).length()).fold(f64::MAX, f64::min);
    assert!(nearest > 5.0, "a line {nearest} mm from the cut-away corner");
}
