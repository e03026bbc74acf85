//! The path tracer's common case in lanes: eight samples traced side by side, so their rays
//! and their shading run in the processor's vector units (a small wavefront: Laine, Karras and
//! Aila 2013, "Megakernels Considered Harmful", split a path tracer into stages over many
//! paths). It applies when every material is an untextured Lambert BSDF in RGB and the
//! processor has AVX2 or AVX-512 ([`PathTracer::lanes_apply`]).
//!
//! One bounce is a round of stages over the eight lanes: the rays' nearest hits in one call
//! ([`crate::World::intersect_rays`]: with AVX-512, in a world of flats, each flat against the
//! eight rays at once); per path, emission and the vertex ([`PathTracer::prepare_vertex`]);
//! the vertices' random numbers ([`StreamLanes`]) and light points ([`sample_lights`]) for all
//! lanes; the shading frame, next-event weights, cosine-weighted continuation and Russian
//! roulette ([`shade`]); the shadow rays in one call; per path, the step to the next vertex.
//! The all-lane stages are loops without branches the compiler turns into AVX-512 or AVX2
//! code. A lane whose path ends starts the next sample of the tile row it was given, so lanes
//! stay busy until the row's samples run out.
//!
//! Every lane performs exactly the floating-point operations of [`PathTracer::radiance`], in
//! the same order (no fused multiply–adds, no reassociation), and draws the same numbers, so
//! every sample is bit-identical to the per-path tracer's on every processor (test
//! `lanes_match_the_per_path_tracer`).

use super::{PathTracer, Previous, RR_DEPTH, epsilon, offset, power_heuristic};
use crate::bsdf::{Bsdf, ColorMode, Frame, cosine_hemisphere, cosine_pdf, same_side};
use crate::lights::{Emitter, Lights};
use crate::sampler::{PixelSeeds, StreamLanes};
use crate::shape::{RayPacket, VectorUnit};
use crate::world::HitPoint;
use alhazen_math::{Ray, Vec2, Vec3};
use std::f64::consts::FRAC_1_PI;

/// Paths traced side by side: one AVX-512 register of `f64` (two AVX2 ones).
const LANES: usize = 8;

/// One number per lane.
type Lanes = [f64; LANES];

/// One vector per lane, component by component (a [`RayPacket`]'s layout).
type Lanes3 = [Lanes; 3];

#[inline(always)]
fn get(v: &Lanes3, i: usize) -> Vec3 {
    Vec3::new(v[0][i], v[1][i], v[2][i])
}

#[inline(always)]
fn set(v: &mut Lanes3, i: usize, x: Vec3) {
    (v[0][i], v[1][i], v[2][i]) = (x.x, x.y, x.z);
}

/// What the per-path stage leaves for [`shade`], lane by lane.
#[derive(Clone, Debug, Default)]
struct Vertices {
    /// Towards the viewer (`−ray.dir`).
    wo: Lanes3,
    p: Lanes3,
    /// Geometric and shading normals as the surface reports them.
    ng: Lanes3,
    ns: Lanes3,
    albedo: Lanes3,
    beta: Lanes3,
    /// The light sample, valid where `light` is set (it exists, has radiance and density).
    light: [bool; LANES],
    light_dir: Lanes3,
    light_dist: Lanes,
    light_radiance: Lanes3,
    light_pdf: Lanes,
    light_delta: [bool; LANES],
    /// The continuation's two numbers, and roulette's where `roulette` is set.
    u_bsdf: [Lanes; 2],
    roulette: [bool; LANES],
    u_roulette: Lanes,
}

/// A parallelogram light as the lanes sample it ([`crate::lights`]' `sample_area`).
#[derive(Clone, Copy, Debug)]
pub(super) struct LaneLight {
    corner: Vec3,
    e1: Vec3,
    e2: Vec3,
    normal: Vec3,
    /// `1 / area`.
    pdf_area: f64,
    radiance: Vec3,
}

/// The lights in lane form when every one is a parallelogram (the lanes then sample them too).
pub(super) fn lane_lights(lights: &Lights) -> Option<Vec<LaneLight>> {
    let lights = lights.parallelograms()?.into_iter().map(|(e, radiance)| match e {
        Emitter::Parallelogram { origin, e1, e2, normal, area } => {
            Some(LaneLight { corner: origin, e1, e2, normal, pdf_area: 1.0 / area, radiance })
        }
        _ => None,
    });
    lights.collect()
}

/// Where the lanes sample parallelogram lights: each lane's light and its two numbers.
#[derive(Clone, Debug, Default)]
struct LightLanes {
    corner: Lanes3,
    e1: Lanes3,
    e2: Lanes3,
    normal: Lanes3,
    pdf_area: Lanes,
    u: [Lanes; 2],
}

/// What [`shade`] returns, lane by lane.
#[derive(Clone, Debug, Default)]
struct Shaded {
    /// Next-event contribution (before `beta`) if the shadow ray is clear; zero when there is
    /// no light to test (`shadow` unset).
    light: Lanes3,
    shadow: [bool; LANES],
    shadow_origin: Lanes3,
    shadow_dist: Lanes,
    /// The path goes on (`alive`) from `origin` along `dir`, sampled with density `pdf`,
    /// carrying `beta`.
    alive: [bool; LANES],
    origin: Lanes3,
    dir: Lanes3,
    pdf: Lanes,
    beta: Lanes3,
}

/// One sample's path in flight.
struct Path {
    /// Where its result goes.
    job: usize,
    ray: Ray,
    depth: u32,
    l: Vec3,
    beta: Vec3,
    prev: Previous,
}

impl PathTracer<'_> {
    /// True when every material is an untextured Lambert BSDF, colours are RGB and the
    /// processor has AVX2 or AVX-512: the case [`Self::pixels_in_lanes`] traces faster. (Its
    /// portable loops, exact but scalar, are 7 % slower than the per-path tracer.)
    pub(super) fn lanes_apply(&self) -> bool {
        let unit = self.world.vector_unit();
        (unit.is_avx512() || unit.is_avx2()) && self.lanes_could_apply()
    }

    /// [`Self::lanes_apply`] whatever the processor.
    pub(super) fn lanes_could_apply(&self) -> bool {
        !self.spectral
            && self.scene.materials.iter().zip(&self.uniform_bsdfs).all(|(m, b)| {
                matches!(b, Some(Bsdf::Lambert(_))) && m.bump.is_none() && crate::bsdf::tangent_hint(m).is_none()
            })
    }

    /// Samples `first..` of `pixels`, traced in lanes: `out` holds each pixel's samples in
    /// turn, sample `first + i` of pixel `p` at `out[p × n + i]` (`n` samples per pixel).
    pub(super) fn pixels_in_lanes(&self, pixels: &[(u32, u32)], first: u32, out: &mut [Vec3]) {
        let mut paths: [Option<Path>; LANES] = Default::default();
        let spp = out.len() / pixels.len().max(1);
        let mut next = 0..out.len();
        let mut seeds = PixelSeeds::new(self.sequence, self.scene.render.seed, 0, 0);
        let (mut vertices, mut shaded) = (Vertices::default(), Shaded::default());
        let mut lights = LightLanes::default();
        let unit = self.world.vector_unit();
        let mut rays = RayPacket::default();
        let mut hits: [Option<HitPoint>; LANES] = [None; LANES];
        let mut streams = StreamLanes::new(self.sequence);
        loop {
            // Idle lanes start the pixel's next samples; all lanes' rays are traced together.
            for (i, slot) in paths.iter_mut().enumerate().filter(|(_, p)| p.is_none()) {
                *slot = next.next().map(|job| {
                    let ((x, y), index) = (pixels[job / spp], first + (job % spp) as u32);
                    if job % spp == 0 {
                        seeds = PixelSeeds::new(self.sequence, self.scene.render.seed, x, y);
                    }
                    streams.start(i, &seeds, index);
                    let path = self.start_path(streams.next_2d_of(i), (x, y), job);
                    rays.set(i, &path.ray);
                    path
                });
            }
            if paths.iter().all(Option::is_none) {
                return;
            }
            self.world.intersect_rays(&rays, paths.each_ref().map(|p| p.is_some()), &mut hits);
            let mut shading = [false; LANES];
            for (i, (slot, hit)) in paths.iter_mut().zip(&hits).enumerate() {
                let Some(path) = slot else { continue };
                shading[i] = self.prepare_vertex(path, hit, &mut vertices, i);
                if !shading[i] {
                    out[path.job] = path.l;
                    *slot = None;
                }
            }
            self.draw_vertex_numbers(&mut streams, shading, (&mut vertices, &mut lights));
            if self.lane_lights.is_some() {
                sample_lights(&lights, &mut vertices, self.lights.choice_pdf(), unit);
            }
            shade(&vertices, &mut shaded, unit);
            let shadow_rays = RayPacket { origin: shaded.shadow_origin, dir: vertices.light_dir };
            let tested = std::array::from_fn(|i| shading[i] && shaded.shadow[i]);
            let clear = self.world.unoccluded_rays(&shadow_rays, &shaded.shadow_dist, tested);
            for (i, slot) in paths.iter_mut().enumerate() {
                let Some(path) = slot.as_mut().filter(|_| shading[i]) else { continue };
                self.finish_vertex(path, &shaded, clear[i], i);
                if shaded.alive[i] {
                    rays.set(i, &path.ray);
                } else {
                    out[path.job] = path.l;
                    *slot = None;
                }
            }
        }
    }

    /// The path through `film` (the pixel's first pair) of pixel `(x, y)`, whose result goes to
    /// `out[job]`.
    fn start_path(&self, film: Vec2, (x, y): (u32, u32), job: usize) -> Path {
        let ray = self.camera.ray(x as f64 + film.x, y as f64 + film.y);
        let prev = Previous::camera(ray.origin);
        Path { job, ray, depth: 1, l: Vec3::ZERO, beta: Vec3::ONE, prev }
    }

    /// The per-path half of a vertex, as in [`Self::radiance`]: the ray's `hit`, its emission
    /// and the vertex, written to lane `i`; false when the path ends.
    fn prepare_vertex(&self, path: &mut Path, hit: &Option<HitPoint>, v: &mut Vertices, i: usize) -> bool {
        let max_depth = self.scene.render.max_depth;
        if path.depth > max_depth {
            return false;
        }
        let Some(wh) = hit else {
            if let Some(sky) = self.escaped(&path.ray, &path.prev, path.beta, ColorMode::Rgb) {
                path.l += sky;
            }
            return false;
        };
        path.l += path.beta * self.emitted(wh, &path.ray, &path.prev, None, ColorMode::Rgb);
        if path.depth == max_depth {
            return false;
        }
        let Some(Bsdf::Lambert(lambert)) = &self.uniform_bsdfs[wh.material as usize] else {
            unreachable!("lanes apply only when every material is Lambert (`lanes_apply`)")
        };
        v.roulette[i] = path.depth >= RR_DEPTH;
        set(&mut v.wo, i, -path.ray.dir);
        set(&mut v.p, i, wh.p);
        set(&mut v.ng, i, wh.n);
        set(&mut v.ns, i, wh.ns);
        set(&mut v.albedo, i, lambert.albedo);
        set(&mut v.beta, i, path.beta);
        path.prev.p = wh.p;
        true
    }

    /// The random numbers of the vertices of the lanes `shading`, in the per-path tracer's
    /// order (light choice when there is one, light point, continuation, roulette from
    /// [`RR_DEPTH`] on), and each lane's light sample.
    fn draw_vertex_numbers(
        &self,
        streams: &mut StreamLanes,
        shading: [bool; LANES],
        (v, lights): (&mut Vertices, &mut LightLanes),
    ) {
        let unit = self.world.vector_unit();
        let mut choice = [[0.0; LANES]; 2];
        if self.lights.len() > 1 {
            streams.next_2d(shading, &mut choice, unit);
        }
        let mut u_light = [[0.0; LANES]; 2];
        streams.next_2d(shading, &mut u_light, unit);
        streams.next_2d(shading, &mut v.u_bsdf, unit);
        // Drawn before it is known whether the path survives the continuation; a path that
        // does not never draws again, so the streams stay the per-path tracer's.
        let mut u_roulette = [[0.0; LANES]; 2];
        streams.next_2d(std::array::from_fn(|i| shading[i] && v.roulette[i]), &mut u_roulette, unit);
        v.u_roulette = u_roulette[0];
        for i in (0..LANES).filter(|&i| shading[i]) {
            match &self.lane_lights {
                Some(all) => {
                    let k = &all[self.lights.choose(choice[0][i])];
                    set(&mut lights.corner, i, k.corner);
                    set(&mut lights.e1, i, k.e1);
                    set(&mut lights.e2, i, k.e2);
                    set(&mut lights.normal, i, k.normal);
                    lights.pdf_area[i] = k.pdf_area;
                    set(&mut v.light_radiance, i, k.radiance);
                    (v.light[i], v.light_delta[i]) = (k.radiance != Vec3::ZERO, false);
                }
                None => {
                    let u = Vec2::new(u_light[0][i], u_light[1][i]);
                    let light = self.lights.sample(get(&v.p, i), choice[0][i], u);
                    let light = light.filter(|ls| ls.radiance != Vec3::ZERO && not_at_most_zero(ls.pdf));
                    v.light[i] = light.is_some();
                    if let Some(ls) = light {
                        set(&mut v.light_dir, i, ls.dir);
                        set(&mut v.light_radiance, i, ls.radiance);
                        (v.light_dist[i], v.light_pdf[i], v.light_delta[i]) = (ls.dist, ls.pdf, ls.delta);
                    }
                }
            }
        }
        lights.u = u_light;
    }

    /// The per-path half after [`shade`] and the shadow ray (`unoccluded` when it was traced and
    /// met nothing): the light gathered, then the step to the next vertex.
    fn finish_vertex(&self, path: &mut Path, s: &Shaded, unoccluded: bool, i: usize) {
        let clear = !s.shadow[i] || unoccluded;
        let light = if clear { get(&s.light, i) } else { Vec3::ZERO };
        path.l += path.beta * light;
        if s.alive[i] {
            path.beta = get(&s.beta, i);
            path.prev.pdf = s.pdf[i];
            path.prev.delta = false;
            path.ray = Ray::new(get(&s.origin, i), get(&s.dir, i));
            path.depth += 1;
        }
    }
}

/// Every lane's point on its parallelogram light, as `Lights::sample` computes it.
#[allow(unsafe_code)]
fn sample_lights(k: &LightLanes, v: &mut Vertices, choice_pdf: f64, unit: VectorUnit) {
    #[cfg(target_arch = "x86_64")]
    if unit.is_avx512() {
        // SAFETY: a `VectorUnit` says AVX-512 (F, DQ, VL, BW) only where the processor has them.
        return unsafe { sample_lights_avx512(k, v, choice_pdf) };
    }
    #[cfg(target_arch = "x86_64")]
    if unit.is_avx2() {
        // SAFETY: a `VectorUnit` says AVX2 only where the processor has it.
        return unsafe { sample_lights_avx2(k, v, choice_pdf) };
    }
    let _ = unit;
    (0..LANES).for_each(|i| sample_light(k, v, choice_pdf, i));
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512dq,avx512vl,avx512bw")]
#[allow(unsafe_code)]
unsafe fn sample_lights_avx512(k: &LightLanes, v: &mut Vertices, choice_pdf: f64) {
    (0..LANES).for_each(|i| sample_light(k, v, choice_pdf, i));
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[allow(unsafe_code)]
unsafe fn sample_lights_avx2(k: &LightLanes, v: &mut Vertices, choice_pdf: f64) {
    (0..LANES).for_each(|i| sample_light(k, v, choice_pdf, i));
}

/// Lane `i`'s point on its parallelogram, as `lights::sample_area` computes it.
#[inline(always)]
fn sample_light(k: &LightLanes, v: &mut Vertices, choice_pdf: f64, i: usize) {
    let q = get(&k.corner, i) + get(&k.e1, i) * k.u[0][i] + get(&k.e2, i) * k.u[1][i];
    let to = q - get(&v.p, i);
    let d2 = to.length_squared();
    let dist = d2.sqrt();
    let dir = to / dist;
    let cos = -get(&k.normal, i).dot(dir);
    let pdf = k.pdf_area[i] * d2 / cos * choice_pdf;
    v.light[i] &= dist != 0.0 && not_at_most_zero(cos) && not_at_most_zero(pdf);
    set(&mut v.light_dir, i, dir);
    (v.light_dist[i], v.light_pdf[i]) = (dist, pdf);
}

/// The Lambertian vertex of every lane at once, with the per-path tracer's arithmetic.
#[allow(unsafe_code)]
fn shade(v: &Vertices, out: &mut Shaded, unit: VectorUnit) {
    #[cfg(target_arch = "x86_64")]
    if unit.is_avx512() {
        // SAFETY: a `VectorUnit` says AVX-512 (F, DQ, VL, BW) only where the processor has them.
        return unsafe { shade_avx512(v, out) };
    }
    #[cfg(target_arch = "x86_64")]
    if unit.is_avx2() {
        // SAFETY: a `VectorUnit` says AVX2 only where the processor has it.
        return unsafe { shade_avx2(v, out) };
    }
    let _ = unit;
    shade_lanes(v, out)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512dq,avx512vl,avx512bw")]
#[allow(unsafe_code)]
unsafe fn shade_avx512(v: &Vertices, out: &mut Shaded) {
    shade_lanes(v, out)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[allow(unsafe_code)]
unsafe fn shade_avx2(v: &Vertices, out: &mut Shaded) {
    shade_lanes(v, out)
}

#[inline(always)]
fn shade_lanes(v: &Vertices, out: &mut Shaded) {
    for i in 0..LANES {
        shade_lane(v, out, i);
    }
}

/// Lane `i` of the Lambertian vertices: the per-path tracer's own functions (`shading_frame`'s
/// rule, [`Frame`], [`cosine_hemisphere`], [`offset`], [`epsilon`], [`power_heuristic`]) on one
/// lane, inlined into the all-lane loop.
#[inline(always)]
fn shade_lane(v: &Vertices, out: &mut Shaded, i: usize) {
    let (wo, p) = (get(&v.wo, i), get(&v.p, i));
    // The shading frame (`PathTracer::shading_frame`; Lambert does not transmit).
    let (mut ng, mut ns) = (get(&v.ng, i), get(&v.ns, i));
    if ng.dot(wo) < 0.0 {
        (ng, ns) = (-ng, -ns);
    }
    if ns.dot(wo) * ng.dot(wo) <= 0.0 {
        ns = ng;
    }
    let frame = Frame::around(ns);
    let wv = frame.to_local(wo);
    let rho = get(&v.albedo, i) * FRAC_1_PI;
    // Next event (`PathTracer::next_event`).
    let dir = get(&v.light_dir, i);
    let l = frame.to_local(dir);
    let f = if same_side(wv, l) { rho } else { Vec3::ZERO } * l.z.abs();
    let shadow = v.light[i] && !(f == Vec3::ZERO || (ng.dot(dir) > 0.0) != (l.z > 0.0));
    let pdf_light = v.light_pdf[i];
    let w = if v.light_delta[i] { 1.0 } else { power_heuristic(pdf_light, cosine_pdf(wv, l)) };
    let c = if shadow { f * get(&v.light_radiance, i) * (w / pdf_light) } else { Vec3::ZERO };
    set(&mut out.light, i, c);
    out.shadow[i] = shadow;
    set(&mut out.shadow_origin, i, offset(p, ng, dir));
    let d = v.light_dist[i];
    out.shadow_dist[i] = if d.is_finite() { d * (1.0 - 1e-7) - 4.0 * epsilon(p) } else { f64::INFINITY };
    // The continuation (`sample_cosine`).
    let l = cosine_hemisphere(Vec2::new(v.u_bsdf[0][i], v.u_bsdf[1][i]), wv);
    let pdf = cosine_pdf(wv, l);
    let dir = frame.to_world(l);
    let weight = rho * l.z.abs() / pdf;
    let mut beta = get(&v.beta, i) * weight;
    let mut alive = pdf > 0.0 && weight.is_finite() && weight != Vec3::ZERO;
    if v.roulette[i] {
        // `eta_scale` is 1 on Lambertian paths.
        let q = (beta.max_element() * 1.0).min(0.95);
        // `u ≥ q` ends the path (u is never NaN; a NaN q does not end it).
        alive &= v.u_roulette[i] < q || q.is_nan();
        beta /= q;
    }
    out.alive[i] = alive;
    out.pdf[i] = pdf;
    set(&mut out.beta, i, beta);
    set(&mut out.dir, i, dir);
    set(&mut out.origin, i, offset(p, ng, dir));
}

/// `!(x <= 0)`, as the per-path tracer's rejections read (NaN passes).
#[inline(always)]
fn not_at_most_zero(x: f64) -> bool {
    x > 0.0 || x.is_nan()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::film::PixelEstimator;
    use crate::{Camera, World};

    /// A Lambertian scene the lanes trace with per-path light sampling: spheres, a box and a
    /// plane, an emitting box (triangles) and sphere, point and spot lights, a gradient sky.
    const MIXED: &str = r#"
background = { zenith = [0.3, 0.4, 0.9], horizon = [0.8, 0.8, 0.7], ground = [0.2, 0.15, 0.1] }
[render]
width = 24
height = 18
spp = 13
max_depth = 6
integrator = "path"
[camera]
eye = [0, 1.5, 6]
target = [0, 0.5, 0]
[[light]]
type = "point"
position = [2, 4, 3]
intensity = 6
[[light]]
type = "spot"
position = [-3, 4, 2]
direction = [0.5, -1, -0.3]
angle = 30
intensity = 8
[materials.glow]
color = [0.5, 0.5, 0.5]
emission = [4, 3, 2]
[[object]]
shape = "plane"
normal = [0, 1, 0]
material = { color = [0.6, 0.6, 0.5] }
[[object]]
shape = "sphere"
center = [-1, 1, 0]
radius = 1
material = { color = [0.8, 0.2, 0.2] }
[[object]]
shape = "box"
min = [0.5, 0, -1]
max = [1.5, 1.2, 0]
material = { color = [0.2, 0.7, 0.3] }
[[object]]
shape = "box"
min = [-0.3, 2.5, -0.3]
max = [0.3, 2.7, 0.3]
material = "glow"
[[object]]
shape = "sphere"
center = [2, 0.4, 1]
radius = 0.4
material = "glow"
"#;

    /// Every sample of every pixel, `(in lanes, per path)`, in full precision, with `unit`'s
    /// kernels.
    fn samples(scene: &alhazen_scene::Scene, unit: VectorUnit) -> (Vec<Vec3>, Vec<Vec3>) {
        let world = World::build_with(scene, unit);
        let camera = Camera::new(&scene.camera, scene.render.width, scene.render.height);
        let mut tracer = PathTracer::new(scene, &world, &camera);
        assert!(tracer.lanes_could_apply(), "the scene is Lambertian: lanes apply");
        let mut all = [vec![], vec![]];
        for (in_lanes, out) in [true, false].into_iter().zip(&mut all) {
            tracer.in_lanes = in_lanes;
            // Rows of pixels traced together, and single pixels.
            let (w, h, spp) = (camera.film_width, camera.film_height, scene.render.spp as usize);
            for y in 0..h {
                let row: Vec<(u32, u32)> = (0..w).map(|x| (x, y)).collect();
                let mut samples = vec![Vec3::NAN; spp * row.len()];
                if y % 2 == 0 {
                    tracer.pixels_samples(&row, 0, &mut samples);
                } else {
                    samples.chunks_mut(spp).zip(&row).for_each(|(s, &(x, y))| tracer.samples(x, y, 0, s));
                }
                out.extend(samples);
            }
        }
        let [lanes, per_path] = all;
        (lanes, per_path)
    }

    /// The lanes trace the same bits as the per-path tracer: lights sampled in lanes (the
    /// Cornell box's parallelogram, and two of them) and per path (everything else), every depth
    /// from 0, a sky, sample counts that leave lanes idle; with every vector unit this processor
    /// has.
    #[test]
    fn lanes_match_the_per_path_tracer() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
        let mut cornell = alhazen_scene::load_scene(&root.join("cornell-box.toml")).unwrap();
        (cornell.render.width, cornell.render.height, cornell.render.spp) = (20, 20, 11);
        let mixed = alhazen_scene::parse_scene("mixed.toml".as_ref(), MIXED).unwrap();
        // Two parallelogram lights: the lanes draw the light choice too.
        let text = std::fs::read_to_string(root.join("cornell-box.toml")).unwrap()
            + "[[object]]\nshape = \"rectangle\"\nmaterial = \"light\"\n\
               transform = [{ scale = 0.2 }, { rotate_y = 90 }, { translate = [0.9, 0.2, 0] }]\n";
        let mut two_lights = alhazen_scene::parse_scene("two-lights.toml".as_ref(), &text).unwrap();
        (two_lights.render.width, two_lights.render.height, two_lights.render.spp) = (16, 16, 9);
        for (name, base) in [("cornell-box", cornell), ("mixed", mixed), ("two lights", two_lights)] {
            for depth in [0, 1, 2, 3, 8] {
                let mut scene = base.clone();
                scene.render.max_depth = depth;
                for unit in VectorUnit::available() {
                    let (lanes, per_path) = samples(&scene, unit);
                    let same = lanes
                        .iter()
                        .zip(&per_path)
                        .all(|(a, b)| a.to_array().map(f64::to_bits) == b.to_array().map(f64::to_bits));
                    assert!(same, "{name}, max_depth {depth}, {}: the lanes' samples differ", unit.name());
                    if depth > 2 {
                        assert!(lanes.iter().filter(|c| c.x > 0.0).count() > lanes.len() / 4, "{name}: lit");
                    }
                }
            }
        }
    }

    #[test]
    fn lanes_apply_only_to_lambertian_rgb_scenes_with_vector_units() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
        for (name, lambertian) in [("cornell-box", true), ("cornell-rough", false), ("prism", false)] {
            let scene = alhazen_scene::load_scene(&root.join(format!("{name}.toml"))).unwrap();
            for unit in VectorUnit::available() {
                let world = World::build_with(&scene, unit);
                let camera = Camera::new(&scene.camera, 8, 8);
                let tracer = PathTracer::new(&scene, &world, &camera);
                assert_eq!(tracer.lanes_could_apply(), lambertian, "{name}");
                let vectors = unit.is_avx512() || unit.is_avx2();
                assert_eq!(tracer.in_lanes, lambertian && vectors, "{name}, {}", unit.name());
            }
        }
    }
}
