//! Unidirectional path tracing of the rendering equation (course §"Global lighting models":
//! `L = L_e + ∫ ρ I dS`, Kajiya 1986).
//!
//! At each vertex: emitted radiance (weighted against light sampling by multiple importance
//! sampling, power heuristic), next-event estimation towards one light chosen uniformly (weighted
//! against BSDF sampling), then a BSDF-sampled continuation; Russian roulette from depth 5 on.
//! Delta lights and delta BSDF lobes skip the heuristic (their densities are not comparable).
//! As every light sample is weighed against a BSDF sample, which reaches every direction, the
//! lights sample only where BSDF samples do poorly (MIS compensation, Karlík et al. 2019;
//! [`LightSampling::AgainstBsdf`]): an environment map where it exceeds its mean, a sky of one
//! colour or a gradient not at all.
//!
//! Depth follows Mitsuba's `max_depth`: a path of `k` segments from the camera contributes when
//! `k ≤ max_depth` (1 = emitters seen directly, 2 = direct lighting). Emitters shine from the
//! side their normal points to. Scenes whose glass disperses (`cauchy`, `sellmeier`, `glass`)
//! are rendered spectrally ([`crate::spectrum`]); all others in RGB.
//!
//! Where the scene has sphere, cylinder or plane mirrors, each non-specular vertex also joins the
//! lights to itself through them exactly (`mirrors`, specular connections), MIS-weighted against
//! BSDF paths that reach an area light after the mirror.
//!
//! With a caustic estimate ([`CausticEstimate`], e.g. a photon map), light that reached a
//! non-specular vertex through specular (delta) surfaces is taken from it instead: the estimate
//! is added at every non-specular vertex, and emission reached from a non-specular vertex
//! through specular bounces only is left out (it is what the estimate holds). Mirror connections
//! are then off (the estimate holds their paths too), and so are the lanes' material kernels.
//!
//! Where the world tests eight rays at once faster than one by one (`World::traces_rays_together`),
//! samples are traced side by side in groups of eight (`lanes`), each with the same arithmetic (`PathTracer::vertex`),
//! so the same samples, whatever the materials.

use crate::bsdf::{Bsdf, ColorMode, Frame, bsdf_at, tangent_at};
use crate::camera::Camera;
use crate::film::PixelEstimator;
use crate::lights::{LightSampling, Lights};
use crate::sampler::{PixelSeeds, SampleStream, Sequence};
use crate::shape::ray_epsilon;
use crate::spectrum::{sample_wavelengths, spectrum_to_rgb};
use crate::world::{HitPoint, World, WorldHit};
use alhazen_math::{Ray, Vec2, Vec3};
use alhazen_scene::{SamplerKind, Scene};
use std::borrow::Cow;

mod lanes;
mod mirrors;
#[cfg(test)]
mod tests;

/// Depth from which Russian roulette may end paths (Mitsuba's `rr_depth`).
const RR_DEPTH: u32 = 5;

/// The path tracer over a built world and camera.
pub struct PathTracer<'a> {
    scene: &'a Scene,
    world: &'a World,
    camera: &'a Camera,
    lights: Lights,
    spectral: bool,
    sequence: Sequence,
    /// Each material's BSDF in RGB when it does not vary over the surface (no texture).
    uniform_bsdfs: Vec<Option<Bsdf>>,
    /// Samples are traced side by side in lanes (module `lanes`): the same samples.
    in_lanes: bool,
    /// The lights, when every one is a parallelogram, for the lanes' material kernels to sample.
    lane_lights: Option<Vec<lanes::LaneLight>>,
    /// Per material: the lanes' kernel for its vertices.
    material_kernels: Vec<lanes::Kernel>,
    /// Some material's inside absorbs (`Material::absorption`): paths leaving an object are
    /// weighed by what they kept inside it. (Without, no vertex asks.)
    absorbing: bool,
    /// Specular connections through the scene's sphere, cylinder and plane mirrors, if any.
    mirrors: Option<mirrors::MirrorConnections>,
    /// Light through specular surfaces onto non-specular ones, estimated elsewhere.
    caustics: Option<&'a dyn CausticEstimate>,
    /// Where the pixel filter places each sample, and its weight.
    film: crate::film::filter::FilmSampler,
}

/// Light that reached non-specular surfaces through specular (delta) ones only, from the lights
/// (paths `L S+ D` of Heckbert's notation): what a caustic photon map estimates.
pub trait CausticEstimate: Sync {
    /// Radiance leaving `p` (geometric normal `ng`, on the side the viewer is) towards the viewer:
    /// the sum over the light arriving near `p` from directions `wi` (unit, towards where it
    /// came from) of `f(wi)` times its power per area, `f` being the BSDF towards the viewer.
    fn radiance(&self, p: Vec3, ng: Vec3, f: &dyn Fn(Vec3) -> Vec3) -> Vec3;
}

/// A one-sided material's back, seen along `dir`: black, the path ends there (Mitsuba's BSDFs
/// without `twosided`; the side is the shading normal's, before any bump map).
#[inline(always)]
fn seen_from_behind(m: &alhazen_scene::Material, wh: &WorldHit, dir: Vec3) -> bool {
    m.one_sided && wh.hit.ns.dot(dir) >= 0.0
}

/// Power heuristic with β = 2.
#[inline]
fn power_heuristic(a: f64, b: f64) -> f64 {
    let (a2, b2) = (a * a, b * b);
    if a2 + b2 > 0.0 { a2 / (a2 + b2) } else { 0.0 }
}

/// A point moved off its surface towards the side of `dir`.
#[inline(always)]
fn offset(p: Vec3, ng: Vec3, dir: Vec3) -> Vec3 {
    let eps = ray_epsilon(p);
    p + ng * if ng.dot(dir) >= 0.0 { eps } else { -eps }
}

/// The shadow segment from `p` (geometric normal `ng`) to a light point `dist` away along unit
/// `dir` (`dist` infinite: a direction): its origin, direction and length. The origin moves off
/// the surface (`offset`); toward a point, the segment is aimed from there at the point (not
/// along `dir`, which seen from the moved origin would cut the light's own surface short of the
/// point where the light is met at a grazing angle) and stops short of it by more than the
/// origin moved (`4·ray_epsilon(scale)`), so that the light does not shadow itself. Written
/// without branches: the lanes' kernels compute it for eight lanes at once.
#[inline(always)]
pub fn shadow_segment(p: Vec3, ng: Vec3, dir: Vec3, dist: f64, scale: Vec3) -> (Vec3, Vec3, f64) {
    let origin = offset(p, ng, dir);
    let to = p + dir * dist - origin;
    let length = to.length();
    let aimed = dist.is_finite() && length > 0.0;
    let toward = if aimed { to / length } else { dir };
    let short = length * (1.0 - 1e-7) - 4.0 * ray_epsilon(scale);
    (
        origin,
        toward,
        if aimed {
            short
        } else if dist.is_finite() {
            0.0
        } else {
            f64::INFINITY
        },
    )
}

/// What the previous vertex left for the next one.
struct Previous {
    p: Vec3,
    pdf: f64,
    delta: bool,
}

impl Previous {
    /// The camera's vertex.
    fn camera(origin: Vec3) -> Self {
        Self { p: origin, pdf: 1.0, delta: true }
    }
}

/// One sample's path in flight: what its walk carries from vertex to vertex.
struct PathState {
    /// The ray to the next vertex, the `depth`-th segment from the camera.
    ray: Ray,
    depth: u32,
    /// Radiance gathered so far, and the throughput.
    l: Vec3,
    beta: Vec3,
    /// Product of the squared relative indices crossed (for Russian roulette).
    eta_scale: f64,
    /// A dispersive surface left only the hero wavelength.
    hero_only: bool,
    prev: Previous,
    /// Specular connections' bookkeeping: the object of the previous vertex, and the visit
    /// of a mirror reached from a non-specular vertex (for the next emission's MIS weight).
    prev_object: u32,
    visit: Option<mirrors::MirrorVisit>,
    /// A non-specular bounce was taken somewhere before; and every bounce since the last of
    /// them was specular (emission reached now is a caustic's, left to a caustic estimate).
    seen_diffuse: bool,
    caustic_chain: bool,
}

impl PathState {
    fn new(ray: Ray) -> Self {
        let prev = Previous::camera(ray.origin);
        Self {
            ray,
            depth: 1,
            l: Vec3::ZERO,
            beta: Vec3::ONE,
            eta_scale: 1.0,
            hero_only: false,
            prev,
            prev_object: u32::MAX,
            visit: None,
            seen_diffuse: false,
            caustic_chain: false,
        }
    }

    /// Adds what `vertex` gathered, its light sample only if its shadow segment is `clear`.
    #[inline]
    fn gather(&mut self, vertex: &Vertex, clear: bool) {
        if let Some(light) = vertex.light {
            self.l += vertex.beta * if clear { light } else { Vec3::ZERO };
        }
        if let Some(mirrored) = vertex.mirrored {
            self.l += vertex.beta * mirrored;
        }
    }
}

/// What [`PathTracer::vertex`] leaves to be added once its shadow ray has been traced.
#[derive(Default)]
struct Vertex {
    /// The throughput at the vertex.
    beta: Vec3,
    /// The light sample's contribution if its shadow segment is clear (`None` at specular
    /// vertices, which sample no light).
    light: Option<Vec3>,
    /// The shadow segment to trace: a ray and its length.
    shadow: Option<(Ray, f64)>,
    /// Light through the scene's mirrors (specular connections).
    mirrored: Option<Vec3>,
    /// The path goes on along its new ray.
    goes_on: bool,
}

impl<'a> PathTracer<'a> {
    /// Prepares the lights of `scene`, each light sample weighed against a BSDF sample
    /// ([`LightSampling::AgainstBsdf`]).
    pub fn new(scene: &'a Scene, world: &'a World, camera: &'a Camera) -> Self {
        Self::with_light_sampling(scene, world, camera, LightSampling::AgainstBsdf)
    }

    /// [`Self::new`] with the lights sampled as `sampling` says (either gives every image the
    /// same expectation; [`LightSampling::Whole`] is there to show it).
    pub fn with_light_sampling(
        scene: &'a Scene,
        world: &'a World,
        camera: &'a Camera,
        sampling: LightSampling,
    ) -> Self {
        let spectral = scene.materials.iter().any(|m| m.bsdf.as_ref().is_some_and(|b| b.is_dispersive()));
        let sequence = match scene.render.sampler {
            SamplerKind::Sobol => Sequence::Sobol,
            SamplerKind::Independent => Sequence::Independent,
        };
        let uniform_bsdfs: Vec<Option<Bsdf>> = scene
            .materials
            .iter()
            .map(|m| {
                let untextured = matches!(m.color, alhazen_scene::Texture::Solid(_))
                    && m.bsdf.as_ref().is_none_or(|b| !b.is_textured())
                    && !m.vertex_colors;
                untextured.then(|| bsdf_at(m, Vec2::ZERO, Vec3::ONE, &scene.images, ColorMode::Rgb))
            })
            .collect();
        let mut lights = Lights::build_for(scene, sampling);
        if scene.render.light_choice == alhazen_scene::LightChoice::Measured {
            lights.choose_by(crate::light_choice::measured_choice(scene, world, camera, &lights));
        }
        let mirrors = scene
            .render
            .mirror_connections
            .then(|| mirrors::MirrorConnections::build(scene, &lights, &uniform_bsdfs))
            .flatten();
        let mut tracer = Self {
            scene,
            world,
            camera,
            lights,
            spectral,
            sequence,
            uniform_bsdfs,
            in_lanes: false,
            lane_lights: None,
            material_kernels: vec![],
            absorbing: scene.materials.iter().any(|m| m.absorption != Vec3::ZERO),
            mirrors,
            caustics: None,
            film: crate::film::filter::FilmSampler::new(&scene.render.filter),
        };
        tracer.lane_lights = lanes::lane_lights(&tracer.lights);
        tracer.material_kernels = lanes::material_kernels(&tracer);
        tracer.in_lanes = tracer.lanes_apply();
        tracer
    }

    /// The tracer taking caustics (light through specular surfaces onto non-specular ones) from
    /// `caustics`: mirror connections off; in lanes every vertex takes the general kernel
    /// (`vertex`, which gathers the estimate).
    pub fn with_caustics(mut self, caustics: &'a dyn CausticEstimate) -> Self {
        self.caustics = Some(caustics);
        self.mirrors = None;
        self.material_kernels.iter_mut().for_each(|k| *k = lanes::Kernel::General);
        self
    }

    /// Whether the scene's glass disperses (rendered spectrally).
    pub fn is_spectral(&self) -> bool {
        self.spectral
    }

    /// Radiance along `ray` in the channels of `mode`.
    pub fn radiance(&self, ray: Ray, mode: ColorMode, s: &mut SampleStream) -> Vec3 {
        let mut path = PathState::new(ray);
        let mut vertex = Vertex::default();
        loop {
            let hit = self.world.intersect(&path.ray, f64::INFINITY);
            self.vertex(&mut path, hit.as_ref(), mode, s, &mut vertex);
            let clear = vertex.shadow.is_none_or(|(ray, dist)| self.world.unoccluded(ray.origin, ray.dir, dist));
            path.gather(&vertex, clear);
            if !vertex.goes_on {
                return path.l;
            }
        }
    }

    /// One vertex of `path` where its ray meets `hit` (or leaves the scene): emission added,
    /// the light sample and the mirror connections left in the result (the light sample's
    /// shadow ray untraced), the path moved on to its next ray. Both tracers run it: the per-path
    /// one ([`Self::radiance`]) and the lanes, which trace eight paths' rays together.
    #[inline(always)]
    fn vertex(
        &self,
        path: &mut PathState,
        hit: Option<&WorldHit>,
        mode: ColorMode,
        s: &mut SampleStream,
        out: &mut Vertex,
    ) {
        let max_depth = self.scene.render.max_depth;
        *out = Vertex { beta: path.beta, ..Vertex::default() };
        if path.depth > max_depth {
            return;
        }
        let Some(wh) = hit else {
            if let Some(sky) = self.escaped(&path.ray, &path.prev, path.beta, mode) {
                path.l += sky;
            }
            return;
        };
        let m = &self.scene.materials[wh.material as usize];
        if self.absorbing
            && let Some(kept) = crate::optics::absorbed_inside(m, &wh.hit, path.ray.dir, mode)
        {
            path.beta *= kept;
        }
        if !(path.caustic_chain && self.caustics.is_some()) {
            let h = HitPoint::from(wh);
            path.l += path.beta * self.emitted(&h, wh.hit.uv, &path.ray, &path.prev, path.visit.as_ref(), mode);
        }
        if path.depth == max_depth || seen_from_behind(m, wh, path.ray.dir) {
            return;
        }
        let bsdf = match (&self.uniform_bsdfs[wh.material as usize], mode) {
            (Some(b), ColorMode::Rgb) => Cow::Borrowed(b),
            _ => Cow::Owned(bsdf_at(m, wh.hit.uv, wh.hit.color, &self.scene.images, mode)),
        };
        if self.spectral && !path.hero_only && is_dispersive(&bsdf) {
            // Wavelength-dependent paths: only the hero survives (×3 keeps it unbiased).
            path.beta *= Vec3::new(3.0, 0.0, 0.0);
            path.hero_only = true;
        }
        out.beta = path.beta;
        let wo = -path.ray.dir;
        let (frame, ng, terminator) = self.shading_frame(wh, &bsdf, wo, tangent_at(m, &wh.hit, &self.scene.images));
        let v = frame.to_local(wo);
        // One pair picks the light and the BSDF lobe, drawn only when there is a choice;
        // one pair each places the points.
        let choices = if self.lights.choices() > 1 || bsdf.chooses_lobe() { s.next_2d() } else { Vec2::ZERO };
        if !bsdf.is_delta() {
            let (light, shadow) = self.next_event(&bsdf, &frame, terminator, wh.hit.p, ng, v, mode, choices.x, s);
            (out.light, out.shadow) = (Some(light), shadow);
            if let Some(c) = self.mirrors.as_ref().filter(|_| path.depth + 2 <= max_depth) {
                let shading = || mirrors::VertexShading { frame, ng, terminator, v };
                out.mirrored = Some(self.mirror_connections(c, &bsdf, shading, wh.hit.p, wh.object, mode, s));
            }
            if let Some(c) = self.caustics {
                // RGB only: photon mapping refuses dispersive scenes.
                let f = |wi: Vec3| bsdf.eval(v, frame.to_local(wi)) * Terminator::shadowing(terminator, wi);
                path.l += path.beta * c.radiance(wh.hit.p, ng, &f);
            }
        }
        let Some(bs) = bsdf.sample(v, choices.y, s.next_2d()) else { return };
        let dir = frame.to_world(bs.l);
        // One division, not one per channel (the lanes' vector unit is slowest at dividing).
        let weight = bs.f * (bs.l.z.abs() / bs.pdf) * Terminator::shadowing(terminator, dir);
        if !weight.is_finite() || weight == Vec3::ZERO {
            return;
        }
        path.beta *= weight;
        path.eta_scale *= bs.eta * bs.eta;
        if path.depth >= RR_DEPTH {
            let q = (path.beta.max_element() * path.eta_scale).min(0.95);
            if s.next_1d() >= q {
                return;
            }
            path.beta *= 1.0 / q;
        }
        if let Some(c) = &self.mirrors {
            let reflected = bs.delta && !path.prev.delta;
            path.visit =
                reflected.then(|| c.visit(path.prev.p, path.prev_object, path.prev.pdf, &HitPoint::from(wh))).flatten();
            path.prev_object = wh.object;
        }
        path.caustic_chain = bs.delta && path.seen_diffuse;
        path.seen_diffuse |= !bs.delta;
        path.prev = Previous { p: wh.hit.p, pdf: bs.pdf, delta: bs.delta };
        path.ray = Ray::new(offset(wh.hit.p, ng, dir), dir);
        path.depth += 1;
        out.goes_on = true;
    }

    /// What a path carrying `beta` gathers from the sky when `ray` leaves the scene, weighted
    /// against light sampling; `None` where the sky is black. Out of line: inlined into
    /// `radiance`, it pushed `Lights::sample` out (cornell-rough 7 % slower).
    #[inline(never)]
    fn escaped(&self, ray: &Ray, prev: &Previous, beta: Vec3, mode: ColorMode) -> Option<Vec3> {
        self.escaped_inline(ray, prev, beta, mode)
    }

    /// [`Self::escaped`] inlined, for the lanes' loop, where its call and result cost 2 % of
    /// the glossy scene.
    #[inline(always)]
    fn escaped_inline(&self, ray: &Ray, prev: &Previous, beta: Vec3, mode: ColorMode) -> Option<Vec3> {
        self.escaped_from(self.lights.sky(ray.dir, prev.p), prev, beta, mode)
    }

    /// [`Self::escaped`] with the sky's radiance and density along the ray looked up
    /// ([`Lights::sky`]).
    fn escaped_from(&self, (le, pdf): (Vec3, f64), prev: &Previous, beta: Vec3, mode: ColorMode) -> Option<Vec3> {
        if le == Vec3::ZERO {
            return None;
        }
        let w = if prev.delta { 1.0 } else { power_heuristic(prev.pdf, pdf) };
        Some(beta * mode.color(le) * w)
    }

    /// Emission of the surface hit, weighted against light sampling (and against the specular
    /// connection when the path came through a mirror, `visit`).
    #[inline(always)]
    fn emitted(
        &self,
        h: &HitPoint,
        uv: Vec2,
        ray: &Ray,
        prev: &Previous,
        visit: Option<&mirrors::MirrorVisit>,
        mode: ColorMode,
    ) -> Vec3 {
        let m = &self.scene.materials[h.material as usize];
        if m.emission == Vec3::ZERO || h.n.dot(ray.dir) >= 0.0 {
            return Vec3::ZERO;
        }
        let le = crate::lights::emission_at(self.scene, h.material, h.object, uv);
        let w = match (visit, &self.mirrors) {
            (Some(visit), Some(c)) => self.mirror_visit_weight(c, visit, h),
            _ if prev.delta => 1.0,
            _ => power_heuristic(prev.pdf, self.lights.area_pdf(h.object, prev.p, h.p, h.n)),
        };
        mode.color(le) * w
    }

    /// The local frame (normal on the viewer's side for opaque surfaces — the course's two-sided
    /// reading of the same-side factor), the geometric normal on the same side, and the shadowing
    /// of a bump or normal map.
    #[inline(always)]
    fn shading_frame(
        &self,
        wh: &WorldHit,
        bsdf: &Bsdf,
        wo: Vec3,
        tangent: Option<Vec3>,
    ) -> (Frame, Vec3, Option<Terminator>) {
        let m = &self.scene.materials[wh.material as usize];
        let (mut ng, mut ns) = (wh.hit.n, crate::world::shading_normal(&wh.hit, m, &self.scene.images));
        let mut n0 = wh.hit.ns;
        if !bsdf.transmits() && ng.dot(wo) < 0.0 {
            (ng, ns, n0) = (-ng, -ns, -n0);
        }
        // A shading normal that puts the viewer on the other side than the geometry would leak.
        if ns.dot(wo) * ng.dot(wo) <= 0.0 {
            ns = ng;
        }
        let terminator = m.bump.as_ref().and_then(|_| Terminator::between(n0, ns));
        (tangent.map_or_else(|| Frame::around(ns), |t| Frame::new(ns, t)), ng, terminator)
    }

    /// One light sample, weighted by the power heuristic against the BSDF's density: what it
    /// brings if the shadow segment it returns (a ray and its length) is clear; zero, and no
    /// segment, when it brings nothing anyway.
    #[inline(always)]
    fn next_event(
        &self,
        bsdf: &Bsdf,
        frame: &Frame,
        terminator: Option<Terminator>,
        p: Vec3,
        ng: Vec3,
        v: Vec3,
        mode: ColorMode,
        u_choice: f64,
        s: &mut SampleStream,
    ) -> (Vec3, Option<(Ray, f64)>) {
        let Some(ls) = self.lights.sample(p, u_choice, s.next_2d()) else { return (Vec3::ZERO, None) };
        if ls.radiance == Vec3::ZERO || ls.pdf <= 0.0 {
            return (Vec3::ZERO, None);
        }
        let l = frame.to_local(ls.dir);
        // The density is needed only against a light that could also be hit.
        let (f, bsdf_pdf) = if ls.delta { (bsdf.eval(v, l), 0.0) } else { bsdf.eval_pdf(v, l) };
        let f = f * l.z.abs() * Terminator::shadowing(terminator, ls.dir);
        // Light must leave from the side of the geometry the BSDF sends it to.
        if f == Vec3::ZERO || (ng.dot(ls.dir) > 0.0) != (l.z > 0.0) && !bsdf.transmits() {
            return (Vec3::ZERO, None);
        }
        let (origin, toward, dist) = shadow_segment(p, ng, ls.dir, ls.dist, p);
        let w = if ls.delta { 1.0 } else { power_heuristic(ls.pdf, bsdf_pdf) };
        (f * mode.color(ls.radiance) * (w / ls.pdf), Some((Ray::new(origin, toward), dist)))
    }
}

fn is_dispersive(b: &Bsdf) -> bool {
    match b {
        Bsdf::Dielectric(d) => d.dispersive,
        Bsdf::Mix(m) => is_dispersive(&m.a) || is_dispersive(&m.b),
        _ => false,
    }
}

impl PixelEstimator for PathTracer<'_> {
    fn samples(&self, x: u32, y: u32, first: u32, out: &mut [Vec3]) {
        if self.in_lanes {
            self.pixels_in_lanes(&[(x, y)], first, out);
        } else {
            let seeds = PixelSeeds::new(self.sequence, self.scene.render.seed, x, y, self.world.vector_unit());
            out.iter_mut().enumerate().for_each(|(i, c)| *c = self.sample_of(seeds.stream(first + i as u32), x, y));
        }
    }

    fn pixels_samples(&self, pixels: &[(u32, u32)], first: u32, out: &mut [Vec3]) {
        if self.in_lanes {
            self.pixels_in_lanes(pixels, first, out);
        } else {
            crate::film::pixel_by_pixel(pixels, out, |x, y, samples| self.samples(x, y, first, samples));
        }
    }

    fn sample(&self, x: u32, y: u32, index: u32) -> Vec3 {
        self.sample_of(
            SampleStream::new(self.sequence, self.scene.render.seed, x, y, index, self.world.vector_unit()),
            x,
            y,
        )
    }
}

impl PathTracer<'_> {
    /// The camera's ray through film position `(fx, fy)` of a sample of a pixel in column `x`:
    /// through a lens, the stream's next pair picks the lens point (the pinhole's draws nothing,
    /// so its images keep their bits).
    // Inlined: a ray returned through the stack and copied into a lane's record stalled the
    // copy's loads (store forwarding fails across two stores): envmap and glossy ~1 %.
    #[inline(always)]
    fn camera_ray(&self, x: u32, (fx, fy): (f64, f64), s: &mut SampleStream) -> Ray {
        match self.camera.has_lens() {
            true => self.camera.pixel_lens_ray(x, fx, fy, s.next_2d()),
            false => self.camera.pixel_ray(x, fx, fy),
        }
    }

    /// The sample of pixel `(x, y)` whose numbers `s` gives.
    fn sample_of(&self, mut s: SampleStream, x: u32, y: u32) -> Vec3 {
        let (fx, fy, weight) = self.film.place(x, y, s.next_2d());
        let ray = self.camera_ray(x, (fx, fy), &mut s);
        let value = if self.spectral {
            let lambdas = sample_wavelengths(s.next_1d());
            let values = self.radiance(ray, ColorMode::Spectral(lambdas), &mut s);
            spectrum_to_rgb(values, &lambdas)
        } else {
            self.radiance(ray, ColorMode::Rgb, &mut s)
        };
        value * weight
    }
}

/// The shadowing a bump or normal map casts on itself (Estevez et al. 2019, "A microfacet-based
/// shadowing function to solve the bump terminator problem", Ray Tracing Gems ch. 12; what
/// Mitsuba 3 applies to its `bumpmap` and `normalmap`): the bent normal read as the mean of a
/// microfacet distribution of roughness `α² = min(tan²ϑ_b / 8, 1)`, `ϑ_b` its angle to the
/// surface's own shading normal, whose Smith term `2 / (1 + √(1 + α² tan²ϑ))` dims light
/// arriving at grazing angles to the unbent surface, which the bent normal would otherwise light
/// too brightly, ending the shading abruptly at the terminator.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Terminator {
    /// The unbent shading normal.
    normal: Vec3,
    /// `α²`.
    alpha2: f64,
}

impl Terminator {
    /// The shadowing of a surface of shading normal `n0` bent to `ns`; `None` where it is not
    /// bent (or bent past the horizon, where the leak guard has replaced it).
    fn between(n0: Vec3, ns: Vec3) -> Option<Self> {
        let (bent, t) = Self::bent(n0, ns);
        bent.then_some(t)
    }

    /// [`Self::between`] without a branch (for vector lanes): whether the normal is bent, and
    /// the shadowing if it is.
    #[inline(always)]
    fn bent(n0: Vec3, ns: Vec3) -> (bool, Self) {
        let c = n0.dot(ns).clamp(-1.0, 1.0);
        (c < 1.0 && c > 0.0, Self { normal: n0, alpha2: (0.125 * (1.0 - c * c) / (c * c)).min(1.0) })
    }

    /// The factor for light arriving from (or leaving towards) world direction `dir`; 1 without
    /// a bent normal.
    #[inline]
    fn shadowing(t: Option<Self>, dir: Vec3) -> f64 {
        t.map_or(1.0, |t| t.factor(dir))
    }

    /// The factor of a bent normal, computed whole and then chosen (no branch, for the lanes).
    #[inline(always)]
    fn factor(self, dir: Vec3) -> f64 {
        let c2 = self.normal.dot(dir).powi(2);
        let g = 2.0 / (1.0 + (1.0 + self.alpha2 * (1.0 - c2).max(0.0) / c2).sqrt());
        if c2 <= 0.0 { 0.0 } else { g }
    }
}

#[cfg(test)]
mod terminator_tests {
    use super::*;

    /// No bend, no shadowing; a bent normal dims light the more grazing it arrives to the
    /// unbent surface, never at normal incidence, and light from below is dark.
    #[test]
    fn bump_shadowing_dims_grazing_light_only() {
        let n0 = Vec3::Z;
        assert!(Terminator::between(n0, n0).is_none());
        let t = Terminator::between(n0, Vec3::new(0.5, 0.0, 1.0).normalize());
        assert_eq!(Terminator::shadowing(t, Vec3::Z), 1.0);
        let grazing = |deg: f64| {
            let a = deg.to_radians();
            Terminator::shadowing(t, Vec3::new(a.sin(), 0.0, a.cos()))
        };
        assert!(1.0 > grazing(30.0) && grazing(30.0) > grazing(60.0) && grazing(60.0) > grazing(89.0));
        assert!(grazing(89.0) > 0.0 && grazing(60.0) > 0.9, "{} {}", grazing(60.0), grazing(89.0));
        assert_eq!(Terminator::shadowing(t, Vec3::X), 0.0);
        assert_eq!(Terminator::shadowing(None, Vec3::X), 1.0);
    }
}
