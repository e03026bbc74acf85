//! Filled reflexes in mirrors (Glaeser §4, "Reflexes of polygons"): every polygon of the scene
//! is reflected as a polygon and filled with its colour, farthest first (a painter's order by
//! the length of the light path `ER + RS`, which Theorem 5 makes the reflection on the outside
//! the shortest of). Where the polygon's plane meets a sphere or cylinder mirror, the projecting
//! lines of Theorems 7–9 ([`alhazen_mirror::overlap`]) split it first, so that no reflex folds
//! over itself and its fill is well defined; large pieces are subdivided so that those partly
//! in the forbidden region (no visible reflex, §2.2) keep their reflexible parts.
//!
//! The fills lie under the lines; what hides a mirror from the eye is not filled, only drawn.

use crate::drawing::Fill;
use crate::reflect::Mirror;
use crate::view::View;
use alhazen_math::{Vec2, Vec3};
use alhazen_mirror::Site;
use alhazen_mirror::overlap::{Plane, ProjectingLine, split_polygon};
use alhazen_raster::pipeline::geometry::{Vertex, world_triangles};
use alhazen_scene::Scene;
use rayon::prelude::*;

/// Points per polygon edge whose reflexes outline the filled reflex.
const EDGE_SAMPLES: usize = 6;
/// Halvings of a piece at most, where it is large against its distance from the mirror.
const MAX_SUBDIVISIONS: u32 = 4;

/// A reflex polygon on paper, the length of its light path and its colour.
struct Reflected {
    fill: Fill,
    path: f64,
}

/// The filled reflexes of every object's polygons in every mirror, in painter's order.
pub fn reflex_fills(scene: &Scene, mirrors: &[Mirror], view: &View) -> Vec<Fill> {
    let jobs: Vec<(usize, usize)> =
        (0..mirrors.len()).flat_map(|m| (0..scene.objects.len()).map(move |o| (m, o))).collect();
    let mut all: Vec<Reflected> = jobs
        .par_iter()
        .filter(|&&(m, o)| mirrors[m].object() != o as u32)
        .flat_map_iter(|&(m, o)| {
            let object = &scene.objects[o];
            let triangles = world_triangles(scene, object).unwrap_or_default();
            let material = &scene.materials[object.material as usize];
            triangles
                .into_iter()
                .flat_map(|t| reflect_triangle(scene, &mirrors[m], view, &t, material))
                .collect::<Vec<_>>()
        })
        .collect();
    // Farthest first; ties in a fixed order (the sort is stable over the jobs' order).
    all.sort_by(|a, b| b.path.total_cmp(&a.path));
    all.into_iter().map(|r| r.fill).collect()
}

/// One scene triangle's filled reflexes in `mirror`.
fn reflect_triangle(
    scene: &Scene,
    mirror: &Mirror,
    view: &View,
    t: &[Vertex; 3],
    material: &alhazen_scene::Material,
) -> Vec<Reflected> {
    let viewer = view.viewer();
    let corners = t.map(|v| v.p);
    // Nothing of it shows in the mirror: its corners and centre have no reflex.
    let centre = corners.iter().sum::<Vec3>() / 3.0;
    if corners.iter().chain([&centre]).all(|p| mirror.reflex(viewer, *p).is_none()) && !large(&corners, mirror) {
        return vec![];
    }
    let lines = projecting_lines(mirror, viewer, &corners);
    let mut out = vec![];
    for piece in split_polygon(&corners, &lines) {
        for small in subdivided(piece, mirror, 0) {
            if let Some(r) = reflect_polygon(scene, mirror, view, &small, t, material) {
                out.push(r);
            }
        }
    }
    out
}

/// True when the triangle is large against its distance from the mirror (its corners may all
/// be forbidden while its middle is seen).
fn large(corners: &[Vec3], mirror: &Mirror) -> bool {
    let size = (0..corners.len()).map(|i| (corners[(i + 1) % corners.len()] - corners[i]).length()).fold(0.0, f64::max);
    let centre = corners.iter().sum::<Vec3>() / corners.len() as f64;
    size > 0.5 * (centre - mirror.center()).length()
}

/// The projecting lines of the triangle's plane on a sphere or cylinder seen from a finite eye
/// (none for plane mirrors, which do not fold, and eyes at infinity, outside (22) and (27)).
fn projecting_lines(mirror: &Mirror, viewer: Site, corners: &[Vec3; 3]) -> Vec<ProjectingLine> {
    let (Site::At(eye), Some(plane)) = (viewer, Plane::of_polygon(corners)) else { return vec![] };
    let found = match mirror {
        Mirror::Sphere { sphere, .. } => sphere.projecting_lines(eye, plane),
        Mirror::Cylinder { cylinder, .. } => cylinder.projecting_lines(eye, plane),
        Mirror::Plane { .. } => Ok(vec![]),
    };
    found.unwrap_or_default()
}

/// `piece` halved (fan-split into triangles, then at their longest edges) while it is large
/// against its distance from the mirror.
fn subdivided(piece: Vec<Vec3>, mirror: &Mirror, depth: u32) -> Vec<Vec<Vec3>> {
    if depth >= MAX_SUBDIVISIONS || !large(&piece, mirror) {
        return vec![piece];
    }
    let triangles: Vec<[Vec3; 3]> = (1..piece.len() - 1).map(|k| [piece[0], piece[k], piece[k + 1]]).collect();
    triangles
        .into_iter()
        .flat_map(|[a, b, c]| {
            // Halve at the longest edge.
            let (a, b, c) = if (b - a).length() >= (c - b).length().max((a - c).length()) {
                (a, b, c)
            } else if (c - b).length() >= (a - c).length() {
                (b, c, a)
            } else {
                (c, a, b)
            };
            let m = (a + b) * 0.5;
            [vec![a, m, c], vec![m, b, c]]
        })
        .flat_map(|p| subdivided(p, mirror, depth + 1))
        .collect()
}

/// The filled reflex of a planar polygon whose every outline sample has a visible reflex.
fn reflect_polygon(
    scene: &Scene,
    mirror: &Mirror,
    view: &View,
    poly: &[Vec3],
    t: &[Vertex; 3],
    material: &alhazen_scene::Material,
) -> Option<Reflected> {
    let mut outline = vec![];
    for (i, a) in poly.iter().enumerate() {
        let b = poly[(i + 1) % poly.len()];
        outline.extend((0..EDGE_SAMPLES).map(|k| *a + (b - *a) * (k as f64 / EDGE_SAMPLES as f64)));
    }
    let reflexes = mirror.reflexes(view.viewer(), &outline);
    let mut path = 0.0;
    let mut points = Vec::with_capacity(outline.len());
    for (s, r) in outline.iter().zip(&reflexes) {
        let r = (*r)?;
        path += match view.viewer() {
            Site::At(e) => (r - e).length() + (*s - r).length(),
            Site::Toward(d) => -r.dot(d.normalize()) + (*s - r).length(),
        };
        points.push(view.to_paper(r));
    }
    let centre = poly.iter().sum::<Vec3>() / poly.len() as f64;
    let (uv, vertex_color) = at(t, centre);
    let rgb = alhazen_scene::texture::eval(&material.color, uv, &scene.images) * material.vertex_tint(vertex_color);
    let srgb = rgb.to_array().map(|c| alhazen_math::color::srgb_encode(c.clamp(0.0, 1.0)));
    Some(Reflected { fill: Fill { points, rgb: srgb }, path: path / outline.len() as f64 })
}

/// Texture coordinates and vertex colour at `p` in triangle `t` (barycentric).
fn at(t: &[Vertex; 3], p: Vec3) -> (Vec2, Vec3) {
    let (a, b, c) = (t[0].p, t[1].p, t[2].p);
    let n = (b - a).cross(c - a);
    let area = n.length_squared();
    if area <= 0.0 {
        return (t[0].uv, t[0].color);
    }
    let wa = (c - b).cross(p - b).dot(n) / area;
    let wb = (a - c).cross(p - c).dot(n) / area;
    let wc = 1.0 - wa - wb;
    (t[0].uv * wa + t[1].uv * wb + t[2].uv * wc, t[0].color * wa + t[1].color * wb + t[2].color * wc)
}
