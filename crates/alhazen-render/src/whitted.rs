//! Recursive ray tracing as in the lecture (`RT_trace`, `RT_shade`): at the closest hit, the
//! ambient term plus, for each light on the viewer's side, the course's Lambert + Phong (or
//! Blinn–Phong) terms scaled by how much light transparent and opaque occluders let through;
//! then reflection and refraction rays up to the maximum depth. Transparent surfaces split their
//! transmission coefficient by a Fresnel factor; light travelling inside an absorbing medium
//! decays by Beer's law `exp(−σ d)`.
//!
//! Scenes with dispersive glass (the lecture's wavelength-dependent index) are traced
//! spectrally, as the path tracer does: each sample carries radiance at three wavelengths (a
//! hero and two rotations, [`crate::spectrum`]), every colour upsampled to them; at dispersive
//! glass the reflected ray keeps all three (Fresnel per wavelength) and the refracted one the
//! hero alone, bent by its own index (weighted ×3 once, which keeps the estimate unbiased).

use crate::bsdf::ColorMode;
use crate::camera::Camera;
use crate::connect::{MirrorPath, MirrorShape, Source};
use crate::film::PixelEstimator;
use crate::lights::{Lights, PathLight};
use crate::optics::{fresnel_dielectric, fresnel_schlick, reflect, refract};
use crate::sampler::Rng;
use crate::shape::ray_epsilon;
use crate::spectrum::{sample_wavelengths, spectrum_to_rgb};
use crate::texture;
use crate::world::{ShadowHit, World, WorldHit};
use alhazen_math::{Ray, Vec3};
use alhazen_scene::bsdf::{BsdfDesc, Ior};
use alhazen_scene::{FresnelMode, Light, Material, Scene};

/// Rays whose contribution to the pixel would fall below this are not traced (like POV-Ray's
/// `adc_bailout` of 1/255, but finer).
const MIN_WEIGHT: f64 = 1.0 / 1024.0;
/// How many transparent surfaces a shadow ray may pass before it counts as blocked.
const MAX_SHADOW_SURFACES: usize = 64;
/// Points taken on each emitting object per shading point: a 4 × 4 stratified grid.
const EMITTER_STRATA: u32 = 4;

/// The Whitted integrator over a built world.
pub struct Whitted<'a> {
    scene: &'a Scene,
    world: &'a World,
    max_depth: u32,
    /// Sphere, cylinder and plane mirrors that lights shine through onto other surfaces.
    mirrors: Vec<Mirror>,
    /// The scene's lights as the path tracer samples them, for its emitting objects.
    lights: Lights,
    /// The emitting objects that light others: `(light index in lights, object)`.
    emitters: Vec<(usize, u32)>,
    /// Per material, its index when it disperses (the scene is then traced spectrally).
    dispersion: Vec<Option<Ior>>,
}

/// The channels a ray carries: RGB, or radiance at three wavelengths; `hero_only` once a
/// refraction at dispersive glass has left only the first.
#[derive(Clone, Copy, Debug)]
pub struct Channels {
    mode: ColorMode,
    hero_only: bool,
}

impl Channels {
    /// Linear RGB.
    pub const RGB: Self = Self { mode: ColorMode::Rgb, hero_only: false };

    /// A colour in these channels.
    #[inline]
    fn c(&self, rgb: Vec3) -> Vec3 {
        self.mode.color(rgb)
    }
}

/// A mirror surface of the scene for specular connections ([`crate::connect`]).
struct Mirror {
    object: u32,
    shape: MirrorShape,
    reflectance: Vec3,
}

/// Fresnel reflectance for `cos` at a boundary with relative index `eta = η_T/η_I`.
fn fresnel(m: &Material, cos: f64, eta: f64) -> f64 {
    match m.fresnel {
        FresnelMode::Exact => fresnel_dielectric(cos, eta),
        FresnelMode::Schlick => fresnel_schlick(cos, eta),
        FresnelMode::Off => 0.0,
    }
}

/// The intensity arriving along a mirror path: `I·G` (`I^dir·G` for a directional light),
/// with a spot's cone and fall-off seen along the leaving direction and the attenuation
/// `[a, b, c]` at the unfolded length `d` applied as `d²/(a d² + b d + c)`; `None` outside a
/// spot's cone.
fn intensity_through(light: &Light, path: &MirrorPath) -> Option<Vec3> {
    let unfolded = |attenuation: &[f64; 3]| {
        let d = path.dist_to_mirror + path.dist_to_source;
        d * d / (attenuation[0] * d * d + attenuation[1] * d + attenuation[2])
    };
    match light {
        Light::Point { intensity, attenuation, .. } => Some(*intensity * (path.geometry * unfolded(attenuation))),
        Light::Spot { direction, cos_cutoff, falloff, beam, intensity, attenuation, .. } => {
            let cos = -path.to_source.dot(*direction);
            let shaped = alhazen_scene::spot_profile(cos, *cos_cutoff, *falloff, *beam);
            (cos >= *cos_cutoff).then(|| *intensity * (shaped * path.geometry * unfolded(attenuation)))
        }
        Light::Directional { intensity, .. } => Some(*intensity * path.geometry),
        Light::Environment { .. } => None,
    }
}

/// A point being shaded: its material, diffuse colour `a`, position, shading and geometric
/// normals on the viewer's side, direction to the viewer, and the channels of its ray.
struct Shading<'m> {
    m: &'m Material,
    a: Vec3,
    p: Vec3,
    n: Vec3,
    ng: Vec3,
    v: Vec3,
    ch: Channels,
}

impl Shading<'_> {
    /// The cosine of light arriving from `l`, if it arrives on the viewer's side of both normals.
    fn facing(&self, l: Vec3) -> Option<f64> {
        let cos = self.n.dot(l);
        (cos > 0.0 && self.ng.dot(l) > 0.0).then_some(cos)
    }

    /// The course's local model for light from `l` at cosine `cos`: `a cos + s·highlight`.
    fn local(&self, l: Vec3, cos: f64) -> Vec3 {
        let mut local = self.a * cos;
        if self.m.specular != Vec3::ZERO {
            local += self.ch.c(self.m.specular) * self.m.highlight(self.n, l, self.v);
        }
        local
    }

    /// Where shadow rays leave from.
    fn origin(&self) -> Vec3 {
        self.p + self.ng * ray_epsilon(self.p)
    }
}

/// Whitted over a camera with stratified pixel samples.
pub struct WhittedEstimator<'a> {
    /// The integrator.
    pub whitted: Whitted<'a>,
    /// The camera.
    pub camera: &'a Camera,
    /// Samples per pixel (for stratification).
    pub spp: u32,
    /// Seed.
    pub seed: u64,
    /// Where the pixel filter places each sample, and its weight.
    pub film: crate::film::filter::FilmSampler,
}

impl PixelEstimator for WhittedEstimator<'_> {
    fn sample(&self, x: u32, y: u32, index: u32) -> Vec3 {
        let (fx, fy, weight) = self.film.stratified(self.seed, (x, y), index, self.spp);
        let ray = match self.camera.has_lens() {
            // The lens point from the sample's own numbers, apart from the pixel's strata.
            true => {
                let mut rng = Rng::for_sample(self.seed ^ 0x1e45_a9e7_7b1d_0c35, x, y, index);
                let lens = alhazen_math::Vec2::new(rng.uniform(), rng.uniform());
                self.camera.pixel_lens_ray(x, fx, fy, lens)
            }
            false => self.camera.pixel_ray(x, fx, fy),
        };
        if !self.whitted.is_spectral() {
            return self.whitted.trace(&ray, 1, 1.0) * weight;
        }
        // The wavelengths stratified over the pixel's samples, jittered per sample.
        let jitter = Rng::for_sample(self.seed ^ 0x5eed_1a4b_da00, x, y, index).uniform();
        let lambdas = sample_wavelengths((index as f64 + jitter) / self.spp as f64);
        let channels = Channels { mode: ColorMode::Spectral(lambdas), hero_only: false };
        spectrum_to_rgb(self.whitted.trace_in(&ray, 1, 1.0, channels), &lambdas) * weight
    }
}

impl<'a> Whitted<'a> {
    /// The integrator for `scene` over `world`.
    pub fn new(scene: &'a Scene, world: &'a World) -> Self {
        let mirrors = scene
            .objects
            .iter()
            .enumerate()
            .filter(|(_, o)| scene.render.mirror_connections && o.mesh_materials.is_empty())
            .flat_map(|(i, o)| {
                let m = &scene.materials[o.material as usize];
                let shapes = if m.mirror != Vec3::ZERO && m.bump.is_none() {
                    MirrorShape::pieces(&o.shape, &o.transform)
                } else {
                    Vec::new()
                };
                shapes.into_iter().map(move |shape| Mirror { object: i as u32, shape, reflectance: m.mirror })
            })
            .collect();
        let emits = scene.objects.iter().any(|o| scene.materials[o.material as usize].emission != Vec3::ZERO);
        let lights = if emits { Lights::build(scene) } else { Lights::default() };
        let emitters = (lights.objects().into_iter().enumerate())
            .filter(|(i, _)| matches!(lights.all()[*i], PathLight::Area { .. }))
            .filter_map(|(i, o)| Some((i, o?)))
            .collect();
        let dispersion = scene
            .materials
            .iter()
            .map(|m| match &m.bsdf {
                Some(BsdfDesc::Dielectric { ior, .. }) if ior.is_dispersive() && m.transparency != Vec3::ZERO => {
                    Some(*ior)
                }
                _ => None,
            })
            .collect();
        Self { scene, world, max_depth: scene.render.max_depth.max(1), mirrors, lights, emitters, dispersion }
    }

    /// Some glass of the scene disperses: samples are traced at sampled wavelengths.
    pub fn is_spectral(&self) -> bool {
        self.dispersion.iter().any(Option::is_some)
    }

    /// `RT_trace`: radiance along `ray` (unit direction) in RGB; `depth` starts at 1 for camera
    /// rays, `weight` is the ray's share of the pixel.
    pub fn trace(&self, ray: &Ray, depth: u32, weight: f64) -> Vec3 {
        self.trace_in(ray, depth, weight, Channels::RGB)
    }

    /// [`Self::trace`] in the channels `ch`.
    pub fn trace_in(&self, ray: &Ray, depth: u32, weight: f64, ch: Channels) -> Vec3 {
        match self.world.intersect(ray, f64::INFINITY) {
            Some(hit) => self.shade(&hit, ray, depth, weight, ch),
            None => ch.c(self.scene.sky(ray.dir)),
        }
    }

    /// `RT_shade`.
    fn shade(&self, wh: &WorldHit, ray: &Ray, depth: u32, weight: f64, ch: Channels) -> Vec3 {
        let m = &self.scene.materials[wh.material as usize];
        let h = &wh.hit;
        let v = -ray.dir;
        let front = h.n.dot(v) > 0.0;
        let ns = crate::world::shading_normal(h, m, &self.scene.images);
        let (ng, mut n) = if front { (h.n, ns) } else { (-h.n, -ns) };
        if n.dot(v) <= 0.0 {
            n = ng;
        }
        let a = ch.c(texture::eval(&m.color, h.uv, &self.scene.images) * m.vertex_tint(h.color)) * m.diffuse;
        let at = Shading { m, a, p: h.p, n, ng, v, ch };
        let mut color = a * ch.c(self.scene.ambient) + self.direct(&at);
        if !self.emitters.is_empty() {
            color += self.lit_by_emitters(&at, wh.object);
        }
        if !self.mirrors.is_empty() {
            color += self.through_mirrors(&at, wh.object);
        }
        if front {
            color += ch.c(crate::lights::emission_at(self.scene, wh.material, wh.object, h.uv));
        }
        if depth < self.max_depth {
            let dispersion = self.dispersion[wh.material as usize].as_ref();
            color += self.secondary(m, dispersion, (h.p, n, ng, v), front, (depth, weight), ch);
        }
        if !front {
            // The ray travelled h.t inside this object's medium.
            color *= crate::optics::beer(ch.c(m.absorption), h.t);
        }
        color
    }

    /// The course's local model summed over the lights (ν: light and viewer on one side).
    fn direct(&self, at: &Shading) -> Vec3 {
        let mut sum = Vec3::ZERO;
        for light in &self.scene.lights {
            let Some((l, dist, i_dir)) = light.arriving(at.p) else { continue };
            let Some(cos) = at.facing(l) else { continue };
            let through = self.transmittance(at.origin(), l, dist, at.ch);
            if through == Vec3::ZERO {
                continue;
            }
            sum += through * at.ch.c(i_dir) * at.local(l, cos);
        }
        sum
    }

    /// The course's local model lit by emitting objects, in the path tracer's units: each patch
    /// `dA` of an emitter of radiance `L` is a point light of intensity `L cos θ_y dA`, and the
    /// model's `a cos θ_x + k_s·highlight` is divided by π, the Lambert BRDF's normalisation
    /// (emission is radiance, not the course's light intensity), so the term is
    /// `∫ L (a cos θ_x + k_s·highlight)/π dω` — for Lambert the path tracer's direct light. Estimated with 4 × 4
    /// stratified points per emitter (spheres by the cone they show), jittered by a generator
    /// seeded with `p`, each tested by a shadow ray.
    #[inline(never)]
    fn lit_by_emitters(&self, at: &Shading, object: u32) -> Vec3 {
        let p = at.p;
        let mut rng = Rng::for_point(p);
        let strata = EMITTER_STRATA as f64;
        let mut sum = Vec3::ZERO;
        for &(light, _) in self.emitters.iter().filter(|e| e.1 != object) {
            for k in 0..EMITTER_STRATA * EMITTER_STRATA {
                let (i, j) = ((k % EMITTER_STRATA) as f64, (k / EMITTER_STRATA) as f64);
                let u = alhazen_math::Vec2::new((i + rng.uniform()) / strata, (j + rng.uniform()) / strata);
                let Some(s) = self.lights.sample_light(light, p, u) else { continue };
                let Some(cos) = at.facing(s.dir) else { continue };
                if s.pdf.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                    continue;
                }
                let (from, toward, reach) = crate::path::shadow_segment(p, at.ng, s.dir, s.dist, p + s.dir * s.dist);
                let through = self.transmittance(from, toward, reach, at.ch);
                if through == Vec3::ZERO {
                    continue;
                }
                sum += through * at.ch.c(s.radiance) * at.local(s.dir, cos) / s.pdf;
            }
        }
        sum / (strata * strata * std::f64::consts::PI)
    }

    /// The course's local model for light that reaches `p` after one reflection on a sphere,
    /// cylinder or plane mirror (every exact solution of Alhazen's problem, [`crate::connect`]):
    /// the light's intensity focused by the generalised geometry term (its attenuation taken at
    /// the unfolded length), times the mirror's reflectance and both legs' transmittance.
    /// Out of line: `shade` stays as small as it was for scenes without mirrors.
    #[inline(never)]
    fn through_mirrors(&self, at: &Shading, object: u32) -> Vec3 {
        let (p, ng, ch) = (at.p, at.ng, at.ch);
        let mut sum = Vec3::ZERO;
        for light in &self.scene.lights {
            let source = match *light {
                Light::Point { position, .. } | Light::Spot { position, .. } => Source::At(position),
                Light::Directional { direction, .. } => Source::Toward(-direction),
                Light::Environment { .. } => continue,
            };
            let facing = |mirror: &&Mirror| mirror.object != object && mirror.shape.in_front_of(p, ng);
            for mirror in self.mirrors.iter().filter(facing) {
                mirror.shape.reflections(p, source, |path| {
                    let l = path.to_mirror;
                    let Some(cos) = at.facing(l) else { return };
                    let Some(i) = intensity_through(light, &path) else { return };
                    let through = self.legs_transmittance(p, ng, &path, ch);
                    if through == Vec3::ZERO {
                        return;
                    }
                    sum += through * ch.c(mirror.reflectance) * ch.c(i) * at.local(l, cos);
                });
            }
        }
        sum
    }

    /// What passes both legs of a mirror path: `p → m` short of the mirror, `m → light`.
    fn legs_transmittance(&self, p: Vec3, ng: Vec3, path: &MirrorPath, ch: Channels) -> Vec3 {
        let m = path.point;
        let (from, toward, reach) = crate::path::shadow_segment(p, ng, path.to_mirror, path.dist_to_mirror, m);
        let first = self.transmittance(from, toward, reach, ch);
        if first == Vec3::ZERO {
            return first;
        }
        let (from, toward, reach) = crate::path::shadow_segment(m, path.normal, path.to_source, path.dist_to_source, m);
        first * self.transmittance(from, toward, reach, ch)
    }

    /// How much light passes from `origin` along `l` over `dist`: 0 at an opaque surface; at a
    /// transparent one its transmission times `1 − F`, and Beer's law inside absorbing media.
    fn transmittance(&self, mut origin: Vec3, l: Vec3, mut dist: f64, ch: Channels) -> Vec3 {
        let mut through = Vec3::ONE;
        for _ in 0..MAX_SHADOW_SURFACES {
            let materials = &self.scene.materials;
            let opaque = |id: u32| materials[id as usize].transparency == Vec3::ZERO;
            let wh = match self.world.shadow_hit(&Ray::new(origin, l), dist, opaque) {
                ShadowHit::Clear => return through,
                ShadowHit::Opaque => return Vec3::ZERO,
                ShadowHit::Transparent(wh) => wh,
            };
            let m = &materials[wh.material as usize];
            let cos_n = wh.hit.n.dot(l);
            let entering = cos_n < 0.0;
            let eta = if entering { m.ior } else { 1.0 / m.ior };
            through *= ch.c(m.transparency) * (1.0 - fresnel(m, cos_n, eta));
            if !entering {
                through *= crate::optics::beer(ch.c(m.absorption), wh.hit.t);
            }
            if through.max_element() < 1e-6 {
                return Vec3::ZERO;
            }
            origin = wh.hit.p + wh.hit.n * (cos_n.signum() * ray_epsilon(wh.hit.p));
            dist -= wh.hit.t;
        }
        Vec3::ZERO
    }

    /// Reflected and refracted rays; at dispersive glass (`dispersion`) in spectral channels,
    /// Fresnel per wavelength and the refracted ray for the hero wavelength alone.
    fn secondary(
        &self,
        m: &Material,
        dispersion: Option<&Ior>,
        (p, n, ng, v): (Vec3, Vec3, Vec3, Vec3),
        front: bool,
        (depth, weight): (u32, f64),
        ch: Channels,
    ) -> Vec3 {
        let mut color = Vec3::ZERO;
        let mut reflect_w = ch.c(m.mirror);
        if m.transparency != Vec3::ZERO {
            let transparency = ch.c(m.transparency);
            // eta = η_I/η_T for the lecture's T; the Fresnel formula takes η_T/η_I.
            let (eta, f, trans_w, refracted) = match (dispersion, ch.mode) {
                (Some(ior), ColorMode::Spectral(lambdas)) => {
                    let etas = lambdas.map(|l| if front { 1.0 / ior.at(l) } else { ior.at(l) });
                    let f = Vec3::from_array(etas.map(|eta| fresnel(m, n.dot(v), 1.0 / eta)));
                    // Only the hero goes on; ×3 the first time keeps the estimate unbiased.
                    let share = if ch.hero_only { 1.0 } else { 3.0 };
                    let trans_w = Vec3::new(transparency.x * (1.0 - f.x) * share, 0.0, 0.0);
                    (etas[0], f, trans_w, Channels { hero_only: true, ..ch })
                }
                _ => {
                    let eta = if front { 1.0 / m.ior } else { m.ior };
                    let f = fresnel(m, n.dot(v), 1.0 / eta);
                    (eta, Vec3::splat(f), transparency * (1.0 - f), ch)
                }
            };
            reflect_w += transparency * f;
            if let Some(t) = refract(v, n, eta) {
                let w = weight * trans_w.max_element();
                if w > MIN_WEIGHT {
                    let origin = p - ng * ray_epsilon(p);
                    color += trans_w * self.trace_in(&Ray::new(origin, t.normalize()), depth + 1, w, refracted);
                }
            }
        }
        let w = weight * reflect_w.max_element();
        if w > MIN_WEIGHT {
            let r = reflect(v, n).normalize();
            color += reflect_w * self.trace_in(&Ray::new(p + ng * ray_epsilon(p), r), depth + 1, w, ch);
        }
        color
    }
}
