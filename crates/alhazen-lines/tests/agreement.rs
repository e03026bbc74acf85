//! The drawing agrees with the ray tracer: an edge/ID render of the same scene and camera
//! (object and normal seen directly and, on a mirror, after one reflection) has its edges where
//! the drawing has lines — the horizon of the floor included — within about a pixel at 1000
//! pixels across.

use alhazen_lines::drawing::Layer;
use alhazen_lines::{Options, draw};
use alhazen_math::{Ray, Vec2, Vec3};
use alhazen_render::{Camera, World};
use alhazen_scene::{Scene, load_scene};
use std::path::Path;

const WIDTH: u32 = 1000;

/// What a pixel's primary ray sees: object and normal, and after a mirror the same again.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Id {
    direct: Option<(u32, Vec3)>,
    reflected: Option<(u32, Vec3)>,
}

fn scene_at(path: &str) -> Scene {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut scene = load_scene(&root.join(path)).unwrap();
    let aspect = scene.render.height as f64 / scene.render.width as f64;
    scene.render.width = WIDTH;
    scene.render.height = (WIDTH as f64 * aspect).round() as u32;
    scene
}

fn seen(scene: &Scene, world: &World, ray: &Ray) -> Option<(u32, Vec3, Vec3, Vec3)> {
    let h = world.intersect(ray, f64::INFINITY)?;
    Some((h.object, h.hit.n, h.hit.p, scene.materials[h.material as usize].mirror))
}

fn id_image(scene: &Scene) -> (Vec<Id>, u32, u32) {
    let world = World::build(scene);
    let (w, h) = (scene.render.width, scene.render.height);
    let cam = Camera::new(&scene.camera, w, h);
    let mut ids = Vec::with_capacity((w * h) as usize);
    for y in 0..h {
        for x in 0..w {
            let ray = cam.ray(x as f64 + 0.5, y as f64 + 0.5);
            let direct = seen(scene, &world, &ray);
            let reflected = direct.and_then(|(_, n, p, mirror)| {
                if mirror.max_element() <= 0.0 {
                    return None;
                }
                let d = ray.dir - n * (2.0 * ray.dir.dot(n));
                seen(scene, &world, &Ray::new(p + n * alhazen_render::shape::ray_epsilon(p), d))
            });
            ids.push(Id { direct: direct.map(|d| (d.0, d.1)), reflected: reflected.map(|r| (r.0, r.1)) });
        }
    }
    (ids, w, h)
}

fn differ(a: Option<(u32, Vec3)>, b: Option<(u32, Vec3)>) -> bool {
    match (a, b) {
        (Some((oa, na)), Some((ob, nb))) => oa != ob || na.dot(nb) < 30f64.to_radians().cos(),
        (None, None) => false,
        _ => true,
    }
}

/// Pixel centres between which the ID changes (the edge lies half a pixel from each).
fn id_edges(ids: &[Id], w: u32, h: u32) -> Vec<Vec2> {
    let at = |x: u32, y: u32| ids[(y * w + x) as usize];
    let mut out = vec![];
    for y in 0..h {
        for x in 0..w {
            let a = at(x, y);
            for (nx, ny) in [(x + 1, y), (x, y + 1)] {
                if nx < w && ny < h {
                    let b = at(nx, ny);
                    if differ(a.direct, b.direct) || differ(a.reflected, b.reflected) {
                        out.push(Vec2::new(0.5 * (x + nx) as f64 + 0.5, 0.5 * (y + ny) as f64 + 0.5));
                    }
                }
            }
        }
    }
    out
}

/// Points every half pixel along the drawing's visible and reflected lines (paper mm = px).
fn line_samples(scene: &Scene) -> Vec<Vec2> {
    let opts = Options { width_mm: WIDTH as f64, ..Options::default() };
    let (drawing, _) = draw(scene, &opts).unwrap();
    let mut out = vec![];
    for (layer, pts) in &drawing.lines {
        if *layer == Layer::Hidden {
            continue;
        }
        for s in pts.windows(2) {
            let n = ((s[1] - s[0]).length() * 2.0).ceil().max(1.0) as usize;
            out.extend((0..n).map(|k| s[0] + (s[1] - s[0]) * (k as f64 / n as f64)));
        }
    }
    out
}

/// Fraction of `from` within `tol` of some point of `to` (a grid of buckets).
fn within(from: &[Vec2], to: &[Vec2], tol: f64) -> f64 {
    let cell = 4.0;
    let mut grid = std::collections::HashMap::<(i64, i64), Vec<Vec2>>::new();
    for p in to {
        grid.entry(((p.x / cell).floor() as i64, (p.y / cell).floor() as i64)).or_default().push(*p);
    }
    let near = |p: Vec2| {
        let (cx, cy) = ((p.x / cell).floor() as i64, (p.y / cell).floor() as i64);
        (-1..=1).any(|dx| {
            (-1..=1).any(|dy| grid.get(&(cx + dx, cy + dy)).is_some_and(|v| v.iter().any(|q| (*q - p).length() <= tol)))
        })
    };
    from.iter().filter(|p| near(**p)).count() as f64 / from.len().max(1) as f64
}

fn agreement(path: &str) -> (f64, f64) {
    let scene = scene_at(path);
    let (ids, w, h) = id_image(&scene);
    let edges = id_edges(&ids, w, h);
    let lines = line_samples(&scene);
    // Both ways: lines lie on ID edges, ID edges are drawn.
    (within(&lines, &edges, 1.0), within(&edges, &lines, 1.0))
}

/// Asserts that 99 % of the drawn line samples lie on ID edges and 99 % of ID edges are drawn.
fn assert_agrees(path: &str) {
    let (on, drawn) = agreement(path);
    eprintln!("{path}: lines on ID edges {on:.4}, ID edges drawn {drawn:.4}");
    assert!(on > 0.99 && drawn > 0.99, "{path}: {on} {drawn}");
}

#[test]
fn fig21_drawing_agrees_with_the_ray_tracer() {
    assert_agrees("scenes/lines/fig21-cylinder-in-sphere.toml");
}

#[test]
fn fig3_plane_mirror_agrees_with_the_ray_tracer() {
    assert_agrees("scenes/lines/fig3-plane-mirror.toml");
}

#[test]
fn fig1_town_in_a_cylinder_agrees_with_the_ray_tracer() {
    assert_agrees("scenes/lines/fig1-town-in-cylinder.toml");
}

#[test]
fn fig16_reflexes_of_lines_agree_with_the_ray_tracer() {
    assert_agrees("scenes/lines/fig16-reflexes-of-lines.toml");
}

#[test]
fn fig17_polygon_through_a_cylinder_agrees_with_the_ray_tracer() {
    assert_agrees("scenes/lines/fig17-polygon-overlap.toml");
}

#[test]
fn a_military_axonometry_with_a_mirror_agrees_with_the_ray_tracer() {
    assert_agrees("scenes/lines/axonometric-mirror.toml");
}

#[test]
fn intersection_curves_agree_with_the_ray_tracer() {
    assert_agrees("scenes/lines/intersections.toml");
}

#[test]
fn csg_bodies_agree_with_the_ray_tracer() {
    assert_agrees("scenes/lines/csg-bodies.toml");
}

#[test]
fn a_panorama_with_a_mirror_agrees_with_the_ray_tracer() {
    // Straight edges are curves on the panorama's film, followed within the tolerance.
    assert_agrees("scenes/cameras/panorama.toml");
}
