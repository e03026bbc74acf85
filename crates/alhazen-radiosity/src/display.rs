//! Showing the solution (course, end of §"The energetic balance method"): constant values per
//! element would show their boundaries, so each common vertex of coplanar elements takes the
//! area-weighted average of the elements around it and the values are interpolated between the
//! vertices. What is averaged is the irradiance an element received, not its colour: a point
//! `p` is shown as `L_e(p) + ρ(p) Ẽ(p)/π`, the course's `(L̃_b(p) + L̃(p)) ρ(p)/ρ_i` with the
//! texture's own `ρ(p)` at every pixel.
//!
//! [`FinalGather`] renders the camera's image from the solution: one ray per sample into the
//! element triangles, mirrors and glass followed as in the lecture's ray tracer (reflected and
//! refracted rays, Fresnel), the sky where rays leave.

use crate::mesh::{InputTriangle, Tree};
use crate::solve::Solution;
use alhazen_math::{Ray, Vec2, Vec3};
use alhazen_render::Camera;
use alhazen_render::film::PixelEstimator;
use alhazen_render::film::filter::FilmSampler;
use alhazen_render::optics::{fresnel_dielectric, reflect, refract};
use std::collections::HashMap;
use std::f64::consts::PI;

/// Irradiance averaged at each leaf's corners, front and back (`[side][corner]`), per tree
/// and node (interior nodes keep zeros).
pub type CornerIrradiance = Vec<Vec<[[Vec3; 3]; 2]>>;

/// A vertex's identity for averaging: its position and its (side's) shading normal, both
/// rounded, so coplanar elements and the facets of one smooth surface share vertices and a
/// sharp edge splits them.
type VertexKey = ([i64; 3], [i32; 3]);

/// The course's vertex averaging over all leaves of `trees`.
pub fn average_at_vertices(triangles: &[InputTriangle], trees: &[Tree]) -> CornerIrradiance {
    let extent = triangles.iter().flat_map(|t| t.p).fold(0.0f64, |m, p| m.max(p.abs().max_element()));
    let unit = 1e-9 * extent.max(1e-300);
    let key = |p: Vec3, n: Vec3| -> VertexKey {
        ((p / unit).round().to_array().map(|x| x as i64), (n * 1e4).round().to_array().map(|x| x as i32))
    };
    let mut sums: HashMap<VertexKey, (Vec3, f64)> = HashMap::new();
    let corners = |tri: &InputTriangle, b: [f64; 2], side: usize| {
        let n = tri.normal_at(b);
        key(tri.at(b), if side == 0 { n } else { -n })
    };
    for (tri, tree) in triangles.iter().zip(trees) {
        for node in tree.nodes.iter().filter(|n| n.is_leaf()) {
            let area = tri.area / 4f64.powi(node.level as i32);
            for side in 0..2 {
                for b in node.bary {
                    let e = sums.entry(corners(tri, b, side)).or_default();
                    e.0 += node.side[side].h * area;
                    e.1 += area;
                }
            }
        }
    }
    triangles
        .iter()
        .zip(trees)
        .map(|(tri, tree)| {
            tree.nodes
                .iter()
                .map(|node| {
                    if !node.is_leaf() {
                        return [[Vec3::ZERO; 3]; 2];
                    }
                    std::array::from_fn(|side| {
                        node.bary.map(|b| {
                            let (sum, area) = sums[&corners(tri, b, side)];
                            sum / area
                        })
                    })
                })
                .collect()
        })
        .collect()
}

impl Solution {
    /// The averaged irradiance at barycentric coordinates `b` of surface triangle `t`, on its
    /// front (`side` 0) or back.
    pub fn irradiance(&self, t: usize, b: [f64; 2], side: usize) -> Vec3 {
        let (leaf, w) = self.trees[t].locate(b);
        let c = &self.corners[t][leaf as usize][side];
        (c[0] * w[0] + c[1] * w[1] + c[2] * w[2]).max(Vec3::ZERO)
    }

    /// The radiance shown at barycentric coordinates `b` (texture coordinates `uv`) of
    /// surface triangle `t` from its front or back: emission (front only) plus the diffuse
    /// reflection `ρ(uv) Ẽ/π`.
    pub fn radiance(&self, t: usize, b: [f64; 2], uv: Vec2, side: usize) -> Vec3 {
        let tri = &self.triangles[t];
        shown(&self.scene, tri.material, (uv, tri.color_at(b)), self.irradiance(t, b, side) / PI, side == 0)
    }
}

/// The radiance shown where material `material` (texture coordinates `uv`, vertex colour
/// `color`) receives the irradiance `e_over_pi · π`: its emission on the front, and
/// `ρ(uv) · e_over_pi`.
pub fn shown(
    scene: &alhazen_scene::Scene,
    material: u32,
    (uv, color): (Vec2, Vec3),
    e_over_pi: Vec3,
    front: bool,
) -> Vec3 {
    let m = &scene.materials[material as usize];
    let rho = alhazen_scene::texture::eval(&m.color, uv, &scene.images) * m.vertex_tint(color) * m.diffuse;
    let emitted = if front { m.emission } else { Vec3::ZERO };
    emitted + rho.clamp(Vec3::ZERO, Vec3::ONE) * e_over_pi
}

/// The image of a solution through the scene's camera.
pub struct FinalGather<'a> {
    /// The solution.
    pub solution: &'a Solution,
    /// The camera.
    pub camera: Camera,
    /// Where the pixel filter places each sample, and its weight.
    pub film: FilmSampler,
}

impl<'a> FinalGather<'a> {
    /// The scene's camera at its image size.
    pub fn new(solution: &'a Solution) -> Self {
        let r = &solution.scene.render;
        Self {
            solution,
            camera: Camera::new(&solution.scene.camera, r.width, r.height),
            film: FilmSampler::new(&r.filter),
        }
    }

    /// The radiance along `ray`, following mirrors and glass `depth` more times.
    pub fn trace(&self, ray: &Ray, depth: u32) -> Vec3 {
        let s = self.solution;
        let Some(hit) = s.world.intersect(ray, f64::INFINITY) else { return s.scene.sky(ray.dir) };
        let t = hit.hit.slot as usize;
        let tri = &s.triangles[t];
        let front = ray.dir.dot(tri.normal) < 0.0;
        let mut l = s.radiance(t, tri.barycentric(hit.hit.p), hit.hit.uv, usize::from(!front));
        let m = &s.scene.materials[hit.material as usize];
        if depth == 0 || (m.mirror == Vec3::ZERO && m.transparency == Vec3::ZERO) {
            return l;
        }
        let v = -ray.dir;
        let n = if hit.hit.ns.dot(v) < 0.0 { -hit.hit.ns } else { hit.hit.ns };
        let ng = if front { tri.normal } else { -tri.normal };
        let eps = alhazen_render::shape::ray_epsilon(hit.hit.p);
        let bounce = |d: Vec3, out: bool| {
            let o = hit.hit.p + ng * if out { eps } else { -eps };
            self.trace(&Ray::new(o, d), depth - 1)
        };
        let mirrored = bounce(reflect(v, n), true);
        l += m.mirror * mirrored;
        if m.transparency != Vec3::ZERO {
            // Relative index of the far side over this side.
            let eta = if front { m.ior } else { 1.0 / m.ior };
            let f = fresnel_dielectric(v.dot(n), eta);
            l += m.transparency
                * match refract(v, n, 1.0 / eta) {
                    Some(d) => bounce(d, false) * (1.0 - f) + mirrored * f,
                    None => mirrored,
                };
        }
        l
    }
}

impl PixelEstimator for FinalGather<'_> {
    fn sample(&self, x: u32, y: u32, index: u32) -> Vec3 {
        let r = &self.solution.scene.render;
        let (fx, fy, weight) = self.film.stratified(r.seed, (x, y), index, r.spp);
        let ray = match self.camera.has_lens() {
            true => {
                let mut rng = alhazen_render::sampler::Rng::for_sample(r.seed ^ 0x1e45_a9e7_7b1d_0c35, x, y, index);
                self.camera.pixel_lens_ray(x, fx, fy, alhazen_math::Vec2::new(rng.uniform(), rng.uniform()))
            }
            false => self.camera.pixel_ray(x, fx, fy),
        };
        self.trace(&ray, r.max_depth) * weight
    }
}
