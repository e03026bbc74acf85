//! Stencil shadow volumes (course, §"Shadows"): for each light, the silhouette edges of every
//! closed object (edges between a triangle facing the light and one facing away) are extruded
//! to infinity (homogeneous points with `w = 0`), and the volume is closed by caps — the
//! light-facing triangles in front, the same projected to infinity behind. A visible point is in
//! shadow when the volume faces between it and the eye do not cancel:
//! * **depth pass** counts the faces in front of the point (+1 entering, −1 leaving) — simple,
//!   but wrong when the eye itself is inside a volume;
//! * **depth fail** (Carmack's reverse) counts the faces behind the point with the opposite
//!   signs, using the caps — right wherever the eye is.
//!
//! The far plane of the projection is at infinity, so the back caps are not clipped away.
//! Only perspective cameras can see points at infinity this way; meshes that are not watertight
//! cast no volume.

use super::clip::{ClipVertex, clip_polygon};
use super::geometry::Triangle;
use super::raster::{ScreenTriangle, rasterize, to_screen};
use alhazen_math::{Mat4, Vec3, Vec4};
use alhazen_scene::{Light, Scene};
use std::collections::HashMap;

/// Which counting rule.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StencilMode {
    /// Count volume faces in front of the visible surface.
    DepthPass,
    /// Count volume faces behind it (Carmack's reverse).
    DepthFail,
}

/// A volume polygon in screen space and whether it faces the eye.
pub struct VolumeTriangle {
    /// Screen triangle (depth `z/w` per corner).
    pub tri: ScreenTriangle,
    /// Facing the eye.
    pub front: bool,
}

/// Where a light is for extrusion: a position, or a direction of travel.
#[derive(Clone, Copy)]
enum Source {
    At(Vec3),
    Along(Vec3),
}

impl Source {
    /// Direction from the light to `p` (unnormalised).
    fn away(&self, p: Vec3) -> Vec3 {
        match *self {
            Source::At(l) => p - l,
            Source::Along(d) => d,
        }
    }
}

fn key(p: Vec3, scale: f64) -> [i64; 3] {
    let q = p / scale * 1e9;
    [q.x.round() as i64, q.y.round() as i64, q.z.round() as i64]
}

/// The volume of the closed triangles `tris` (one object) for a light, as world-space
/// homogeneous polygons with outward winding.
fn volume(tris: &[&Triangle], src: Source, scale: f64) -> Vec<[Vec4; 4]> {
    let facing: Vec<bool> = tris
        .iter()
        .map(|t| {
            let n = (t.v[1].p - t.v[0].p).cross(t.v[2].p - t.v[0].p);
            n.dot(src.away(t.v[0].p)) < 0.0
        })
        .collect();
    // Directed edges of light-facing triangles; an edge is on the silhouette when its reverse is
    // not also a light-facing triangle's edge.
    let mut edges: HashMap<([i64; 3], [i64; 3]), (Vec3, Vec3)> = HashMap::new();
    let mut count: HashMap<([i64; 3], [i64; 3]), u32> = HashMap::new();
    for t in tris {
        for k in 0..3 {
            let (a, b) = (key(t.v[k].p, scale), key(t.v[(k + 1) % 3].p, scale));
            let e = if a < b { (a, b) } else { (b, a) };
            *count.entry(e).or_default() += 1;
        }
    }
    if count.values().any(|&c| c != 2) {
        return vec![]; // not watertight
    }
    for (t, lit) in tris.iter().zip(&facing) {
        if *lit {
            for k in 0..3 {
                let (a, b) = (t.v[k].p, t.v[(k + 1) % 3].p);
                edges.insert((key(a, scale), key(b, scale)), (a, b));
            }
        }
    }
    let inf = |p: Vec3| src.away(p).extend(0.0);
    let mut polys = vec![];
    for (&(ka, kb), &(a, b)) in &edges {
        if !edges.contains_key(&(kb, ka)) {
            // Side quad, outward: along b → a, then out to infinity.
            polys.push([b.extend(1.0), a.extend(1.0), inf(a), inf(b)]);
        }
    }
    for (t, lit) in tris.iter().zip(&facing) {
        if *lit {
            let [a, b, c] = t.v.map(|v| v.p);
            polys.push([a.extend(1.0), b.extend(1.0), c.extend(1.0), c.extend(1.0)]);
            polys.push([inf(a), inf(c), inf(b), inf(b)]);
        }
    }
    polys
}

/// The shadow volumes of every light (index into `scene.lights`) in screen space.
pub fn volumes(scene: &Scene, tris: &[Triangle], world_to_clip: Mat4, (w, h): (u32, u32)) -> Vec<Vec<VolumeTriangle>> {
    let bounds = tris
        .iter()
        .filter(|t| !t.unbounded)
        .fold(alhazen_math::Bounds3::EMPTY, |b, t| t.v.iter().fold(b, |b, v| b.grow(v.p)));
    let scale = if bounds.is_empty() { 1.0 } else { bounds.extent().length().max(1e-9) };
    let objects = closed_objects(tris);
    scene
        .lights
        .iter()
        .map(|light| {
            let src = match *light {
                Light::Point { position, .. } | Light::Spot { position, .. } => Source::At(position),
                Light::Directional { direction, .. } => Source::Along(direction),
                Light::Environment { .. } => return vec![],
            };
            objects
                .iter()
                .flat_map(|o| volume(o, src, scale))
                .flat_map(|q| project(&q, world_to_clip, (w, h)))
                .collect()
        })
        .collect()
}

/// The closed triangles of each object, objects in index order.
fn closed_objects(tris: &[Triangle]) -> Vec<Vec<&Triangle>> {
    let mut by_object: std::collections::BTreeMap<u32, Vec<&Triangle>> = Default::default();
    for t in tris.iter().filter(|t| t.closed) {
        by_object.entry(t.object).or_default().push(t);
    }
    by_object.into_values().collect()
}

fn project(q: &[Vec4; 4], world_to_clip: Mat4, (w, h): (u32, u32)) -> Vec<VolumeTriangle> {
    let poly: Vec<ClipVertex> =
        q.iter().map(|p| ClipVertex { pos: world_to_clip * *p, attr: [0.0; super::clip::ATTRIBUTES] }).collect();
    to_screen(&clip_polygon(&poly), (w, h), 0)
        .into_iter()
        .filter_map(|tri| {
            // Counter-clockwise seen from outside = clockwise on a y-down screen when facing the eye.
            let area = (tri.x[1] - tri.x[0]) * (tri.y[2] - tri.y[0]) - (tri.y[1] - tri.y[0]) * (tri.x[2] - tri.x[0]);
            (area != 0.0).then_some(VolumeTriangle { tri, front: area < 0.0 })
        })
        .collect()
}

/// The stencil counts of rows `[y0, y1)`: non-zero where the surface at `depth` is in shadow.
pub fn count(
    volume: &[VolumeTriangle],
    depth: &[f64],
    width: u32,
    (y0, y1): (u32, u32),
    mode: StencilMode,
) -> Vec<i32> {
    let mut stencil = vec![0i32; depth.len()];
    for v in volume {
        rasterize(&v.tri, width, y0, y1, |f| {
            let k = ((f.y - y0) * width + f.x) as usize;
            let d = depth[k];
            if !d.is_finite() {
                return;
            }
            let eps = 1e-9;
            match mode {
                StencilMode::DepthPass if f.depth < d - eps => stencil[k] += if v.front { 1 } else { -1 },
                // Faces at the surface's own depth (the lit surface is the volume's front cap)
                // count as behind it, as a failed `LESS` depth test does.
                StencilMode::DepthFail if f.depth >= d - eps => stencil[k] += if v.front { -1 } else { 1 },
                _ => {}
            }
        });
    }
    stencil
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tessellated_solids_are_watertight_and_cast_volumes() {
        let text = r#"
[[light]]
type = "point"
position = [3, 6, 2]
[[object]]
shape = "sphere"
radius = 1
[[object]]
shape = "box"
transform = [{ translate = [3, 0, 0] }]
[[object]]
shape = "cylinder"
radius = 0.5
transform = [{ translate = [-3, 0, 0] }]
[[object]]
shape = "cone"
radius = 0.5
transform = [{ translate = [0, 0, -3] }]
"#;
        let scene = alhazen_scene::parse_scene("s.toml".as_ref(), text).unwrap();
        let tris = super::super::geometry::scene_triangles(&scene).triangles;
        let objects = closed_objects(&tris);
        assert_eq!(objects.len(), 4);
        for (k, o) in objects.iter().enumerate() {
            let v = volume(o, Source::At(Vec3::new(3.0, 6.0, 2.0)), 10.0);
            assert!(!v.is_empty(), "object {k} casts no volume");
        }
    }
}
