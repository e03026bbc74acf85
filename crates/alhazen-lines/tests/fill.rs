//! `lines --fill` (Glaeser §4, Theorems 6–9): a panel whose plane cuts a mirror cylinder has a
//! reflex that folds over itself; split along its plane's projecting lines, every piece's reflex
//! is a simple polygon, and the drawing's fills are all simple, farthest first.

use alhazen_lines::view::View;
use alhazen_lines::{Options, draw};
use alhazen_math::{Vec2, Vec3};
use alhazen_mirror::overlap::{Plane, split_polygon};
use alhazen_mirror::{Cylinder, Site};
use alhazen_render::World;
use std::path::Path;

fn scene() -> alhazen_scene::Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/lines/fig17-polygon-overlap.toml");
    alhazen_scene::load_scene(&path).unwrap()
}

/// True when two non-adjacent edges of the closed polygon cross.
fn self_intersects(p: &[Vec2]) -> bool {
    let n = p.len();
    let cross = |o: Vec2, a: Vec2, b: Vec2| (a - o).perp_dot(b - o);
    for i in 0..n {
        for j in i + 2..n {
            if i == 0 && j == n - 1 {
                continue;
            }
            let (a, b, c, d) = (p[i], p[(i + 1) % n], p[j], p[(j + 1) % n]);
            let (d1, d2) = (cross(c, d, a), cross(c, d, b));
            let (d3, d4) = (cross(a, b, c), cross(a, b, d));
            if d1 * d2 < -1e-18 && d3 * d4 < -1e-18 {
                return true;
            }
        }
    }
    false
}

/// The reflex outline of a polygon on paper (`None` if some outline point has no reflex).
fn reflex_outline(cyl: &Cylinder, eye: Vec3, view: &View, poly: &[Vec3]) -> Option<Vec<Vec2>> {
    let mut out = vec![];
    for (i, a) in poly.iter().enumerate() {
        let b = poly[(i + 1) % poly.len()];
        for k in 0..40 {
            let s = *a + (b - *a) * (k as f64 / 40.0);
            let r = cyl.visible_reflex(Site::At(eye), Site::At(s)).ok().flatten()?.point;
            out.push(view.to_paper(r));
        }
    }
    Some(out)
}

/// A convex polygon cut into the fan triangles of its centre.
fn quarters(p: &[Vec3]) -> Vec<Vec<Vec3>> {
    let c = p.iter().sum::<Vec3>() / p.len() as f64;
    (0..p.len()).map(|i| vec![c, p[i], p[(i + 1) % p.len()]]).collect()
}

#[test]
fn a_folding_reflex_is_split_into_simple_ones() {
    let scene = scene();
    let world = World::build(&scene);
    let view = View::new(&scene, &world, 200.0).unwrap();
    let Site::At(eye) = view.viewer() else { panic!("a perspective camera") };
    let cyl = Cylinder { center: Vec3::ZERO, axis: Vec3::new(0.0, 2.5, 0.0), radius: 0.7 };
    // The panel: the rectangle [-1, 1]² placed by its transform.
    let panel = scene.objects.iter().find(|o| o.name.as_deref() == Some("panel")).unwrap();
    let square =
        [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)].map(|(x, y)| panel.transform.point(Vec3::new(x, y, 0.0)));
    let plane = Plane::of_polygon(&square).unwrap();
    let lines = cyl.projecting_lines(eye, plane).unwrap();
    assert!(!lines.is_empty(), "the panel's plane cuts the cylinder where the eye sees it");
    // The part of the panel in front of the cylinder, as the eye sees it reflected: clipped to
    // the strip whose reflexes exist, it folds.
    let pieces = split_polygon(&square, &lines);
    assert!(pieces.len() >= 2);
    let (mut folded, mut checked) = (0, 0);
    for piece in &pieces {
        // Pieces reaching into the forbidden region (no reflex) are cut into smaller ones.
        for small in split_polygon(piece, &[]).iter().flat_map(|p| quarters(p)) {
            if let Some(outline) = reflex_outline(&cyl, eye, &view, &small) {
                assert!(!self_intersects(&outline), "a piece's reflex folds: {small:?}");
                checked += 1;
            }
        }
    }
    assert!(checked > 0);
    // Without the split, a narrow band of the panel across a projecting line folds over.
    for l in &lines {
        let across = plane.normal.cross(l.direction).normalize();
        let at = l.mirror_point + l.direction * 0.4;
        let band = [
            at - across * 0.15 - l.direction * 0.1,
            at + across * 0.15 - l.direction * 0.1,
            at + across * 0.15 + l.direction * 0.1,
            at - across * 0.15 + l.direction * 0.1,
        ];
        if let Some(outline) = reflex_outline(&cyl, eye, &view, &band) {
            folded += self_intersects(&outline) as usize;
        }
    }
    assert!(folded > 0, "a band across a projecting line has a folded reflex");
}

#[test]
fn the_drawings_fills_are_simple_and_lie_under_unchanged_lines() {
    let scene = scene();
    let (drawing, stats) = draw(&scene, &Options { fill: true, ..Options::default() }).unwrap();
    assert!(stats.fills > 10 && stats.fills == drawing.fills.len(), "{}", stats.fills);
    let complex = drawing.fills.iter().filter(|f| self_intersects(&f.points)).count();
    assert!(complex * 100 <= drawing.fills.len(), "{complex} of {} fills fold over", drawing.fills.len());
    let svg = drawing.to_svg(alhazen_lines::drawing::default_stroke);
    assert!(svg.contains("<g id=\"fills\"") && svg.matches("<polygon").count() == drawing.fills.len());
    let pdf = drawing.to_pdf(alhazen_lines::drawing::default_stroke);
    assert!(String::from_utf8_lossy(&pdf).contains(" rg "));
    // Without --fill nothing changes.
    let (plain, _) = draw(&scene, &Options::default()).unwrap();
    assert!(plain.fills.is_empty());
    assert_eq!(plain.lines, drawing.lines);
}
