//! Shadow maps (course, §"Shadows"): the scene's depth as seen from each light, rendered with
//! the same clipping and rasterisation as the image; a point is lit when nothing recorded in its
//! texel is nearer to the light. Point lights use six 90° faces (a cube map), spot lights one
//! perspective map through their cone, directional lights one orthographic map over the scene's
//! bounded objects. Depths are distances to the light (along the light for directional light),
//! compared after moving the point a texel and a half along its normal and with a one-texel
//! tolerance, against self-shadowing ("shadow acne").

use super::clip::{ClipVertex, clip_polygon};
use super::emitters::EmitterLight;
use super::geometry::Triangle;
use super::raster::{rasterize, to_screen};
use alhazen_math::viewing::{Frustum, ViewFrame};
use alhazen_math::{Bounds3, Mat4, Vec3};
use alhazen_scene::{Light, Scene};
use rayon::prelude::*;

/// One depth image from a light.
#[derive(Clone, Debug)]
struct Face {
    world_to_clip: Mat4,
    size: u32,
    /// World size of a texel at unit distance (perspective) or absolute (orthographic).
    texel: f64,
    depth: Vec<f64>,
}

/// How depth is measured for a light.
#[derive(Clone, Copy, Debug)]
enum Metric {
    /// Distance to a point light.
    From(Vec3),
    /// Distance along a direction from a plane through `origin`.
    Along { origin: Vec3, dir: Vec3 },
}

impl Metric {
    fn of(&self, p: Vec3) -> f64 {
        match *self {
            Metric::From(l) => (p - l).length(),
            Metric::Along { origin, dir } => (p - origin).dot(dir),
        }
    }
}

/// The shadow maps of one light.
#[derive(Clone, Debug)]
pub struct LightShadow {
    faces: Vec<Face>,
    metric: Metric,
    perspective: bool,
}

/// Shadow maps of every light of a scene (`None` for lights that cast none, e.g. environments).
#[derive(Clone, Debug)]
pub struct Shadows {
    lights: Vec<Option<LightShadow>>,
}

/// One shadow map: the depths of `tris` but those of object `skip` (a light's own emitter).
fn face(
    scene: &Scene,
    tris: &[Triangle],
    skip: Option<u32>,
    frame: ViewFrame,
    projection: Mat4,
    size: u32,
    texel: f64,
    metric: Metric,
) -> Face {
    let world_to_clip = projection * frame.world_to_view();
    let mut depth = vec![f64::INFINITY; (size * size) as usize];
    let cut_outs = scene.materials.iter().any(|m| m.alpha.is_some());
    for t in tris.iter().filter(|t| Some(t.object) != skip) {
        let poly: Vec<ClipVertex> =
            t.v.iter().enumerate().map(|(k, v)| ClipVertex::corner(world_to_clip * v.p.extend(1.0), v.p, k)).collect();
        for st in to_screen(&clip_polygon(&poly), (size, size), 0) {
            rasterize(&st, size, 0, size, |f| {
                let d = metric.of(super::raster::interpolate(t.v.map(|v| v.p), f.bary));
                let k = (f.y * size + f.x) as usize;
                if d < depth[k] && (!cut_outs || super::present(scene, t, f.bary, (f.x, f.y))) {
                    depth[k] = d;
                }
            });
        }
    }
    Face { world_to_clip, size, texel, depth }
}

fn frame_towards(eye: Vec3, dir: Vec3) -> ViewFrame {
    let up = if dir.y.abs() > 0.9 { Vec3::X } else { Vec3::Y };
    ViewFrame::look_at(eye, eye + dir, up).expect("dir is a unit vector not parallel to up")
}

/// Bounds of the finite part of the scene (the huge quads of infinite planes left out).
pub(super) fn finite_bounds(tris: &[Triangle]) -> Bounds3 {
    tris.iter().filter(|t| !t.unbounded).fold(Bounds3::EMPTY, |b, t| t.v.iter().fold(b, |b, v| b.grow(v.p)))
}

impl Shadows {
    /// Renders the shadow maps of every light of `scene`, then of the lights standing for its
    /// emitters, over `tris` (`size` texels a side).
    pub fn build(scene: &Scene, tris: &[Triangle], emitters: &[EmitterLight], size: u32) -> Self {
        let bounds = finite_bounds(tris);
        let extent = if bounds.is_empty() { 1.0 } else { bounds.extent().length().max(1e-6) };
        let (near, far) = (1e-4 * extent, 1e4 * extent);
        let all: Vec<(&Light, Option<u32>)> =
            scene.lights.iter().map(|l| (l, None)).chain(emitters.iter().map(|e| (&e.light, Some(e.object)))).collect();
        let cube = |position: Vec3, skip: Option<u32>| {
            let p = Frustum::symmetric(std::f64::consts::FRAC_PI_2, 1.0, near, far).perspective();
            let dirs = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
            let metric = Metric::From(position);
            let faces = dirs
                .iter()
                .map(|d| face(scene, tris, skip, frame_towards(position, *d), p, size, 2.0 / size as f64, metric))
                .collect();
            Some(LightShadow { faces, metric, perspective: true })
        };
        let lights = all
            .par_iter()
            .map(|&(light, skip)| match *light {
                Light::Point { position, .. } => cube(position, skip),
                // Cones wider than 120° are seen through the six faces of a point light.
                Light::Spot { position, cos_cutoff, .. } if cos_cutoff < 0.5 => cube(position, skip),
                Light::Spot { position, direction, cos_cutoff, .. } => {
                    let fov = (2.0 * cos_cutoff.clamp(-1.0, 1.0).acos()).clamp(1e-3, 170f64.to_radians());
                    let p = Frustum::symmetric(fov, 1.0, near, far).perspective();
                    let metric = Metric::From(position);
                    let texel = 2.0 * (fov / 2.0).tan() / size as f64;
                    Some(LightShadow {
                        faces: vec![face(
                            scene,
                            tris,
                            skip,
                            frame_towards(position, direction),
                            p,
                            size,
                            texel,
                            metric,
                        )],
                        metric,
                        perspective: true,
                    })
                }
                Light::Directional { direction, .. } => {
                    if bounds.is_empty() {
                        return None;
                    }
                    let r = extent / 2.0;
                    let origin = bounds.centroid() - direction * (2.0 * r);
                    let p = Frustum { l: -r, r, b: -r, t: r, n: 0.0, f: 4.0 * r }.orthographic();
                    let metric = Metric::Along { origin, dir: direction };
                    Some(LightShadow {
                        faces: vec![face(
                            scene,
                            tris,
                            skip,
                            frame_towards(origin, direction),
                            p,
                            size,
                            2.0 * r / size as f64,
                            metric,
                        )],
                        metric,
                        perspective: false,
                    })
                }
                Light::Environment { .. } => None,
            })
            .collect();
        Self { lights }
    }

    /// Whether light `index` reaches `p` on a surface with unit normal `n` facing the light (true
    /// for lights without a map, and outside every map). The point is first moved off the
    /// surface by a texel along `n` (normal-offset bias), which keeps grazing surfaces from
    /// shadowing themselves.
    pub fn lit(&self, index: usize, p: Vec3, n: Vec3) -> bool {
        let Some(Some(s)) = self.lights.get(index) else { return true };
        let texel_at = |d: f64, f: &Face| if s.perspective { f.texel * d } else { f.texel };
        let p = p + n * (1.5 * texel_at(s.metric.of(p).abs(), &s.faces[0]));
        let d = s.metric.of(p);
        for f in &s.faces {
            let c = f.world_to_clip * p.extend(1.0);
            if c.w <= 0.0 || c.x.abs() > c.w || c.y.abs() > c.w {
                continue;
            }
            let (x, y) = ((c.x / c.w + 1.0) * 0.5 * f.size as f64, (1.0 - c.y / c.w) * 0.5 * f.size as f64);
            let (i, j) = ((x as u32).min(f.size - 1), (y as u32).min(f.size - 1));
            let stored = f.depth[(j * f.size + i) as usize];
            return d <= stored + texel_at(d, f);
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_occluder_shadows_what_is_behind_it_only() {
        let text = r#"
[[light]]
type = "point"
position = [0, 5, 0]
[[light]]
type = "directional"
direction = [0, -1, 0]
[[object]]
shape = "box"
min = [-1, 2, -1]
max = [1, 2.2, 1]
[[object]]
shape = "plane"
"#;
        let scene = alhazen_scene::parse_scene("s.toml".as_ref(), text).unwrap();
        let tris = super::super::geometry::scene_triangles(&scene).triangles;
        let sh = Shadows::build(&scene, &tris, &[], 256);
        for light in 0..2 {
            assert!(!sh.lit(light, Vec3::new(0.0, 0.0, 0.0), Vec3::Y), "under the box (light {light})");
            assert!(sh.lit(light, Vec3::new(3.0, 0.0, 0.5), Vec3::Y), "beside it (light {light})");
            assert!(sh.lit(light, Vec3::new(0.0, 2.2, 0.0), Vec3::Y), "on top of the box (light {light})");
        }
    }
}
