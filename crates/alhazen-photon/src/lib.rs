//! Photon mapping (Jensen 1996, "Global illumination using photon maps"; the course's remark
//! that caustics — light focused by mirrors and lenses onto diffuse surfaces — are what a path
//! tracer from the eye finds hardest): photons leave the lights aimed at the mirrors and glass
//! ([`emit`]), follow their delta reflections and refractions, and are stored where they land on
//! a non-specular surface after at least one of them — the caustic map, a [`kdtree::KdTree`].
//! The path tracer then takes `L S+ D` light from the map's density estimate at its
//! non-specular vertices ([`alhazen_render::path::CausticEstimate`]) and everything else as
//! before. Point lights' caustics, which no path from the eye can find, appear; area lights'
//! converge without the path tracer's fireflies.
//!
//! Deterministic: photon `i` draws from its own generator, and photons are stored in their
//! order, so the map — and the image — are the same at any thread count.

pub mod emit;
pub mod kdtree;

use alhazen_math::{Ray, Vec2, Vec3};
use alhazen_render::bsdf::{ColorMode, Frame, bsdf_at, tangent_at};
use alhazen_render::lights::Lights;
use alhazen_render::path::CausticEstimate;
use alhazen_render::sampler::Rng;
use alhazen_render::world::{World, shading_normal};
use alhazen_scene::Scene;
use emit::{Emitter, Target};
use kdtree::{KdTree, Located, Neighbour};
use rayon::prelude::*;
use std::f64::consts::PI;

/// How the caustic map is made and read.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    /// Photons shot (each aimed at a specular object).
    pub photons: usize,
    /// Photons in one density estimate.
    pub nearest: usize,
    /// The largest gathering radius; `None`: 5 % of the bounding sphere of the scene's bounded objects.
    pub radius: Option<f64>,
    /// Seed of the photons' generators.
    pub seed: u64,
}

impl Default for Settings {
    fn default() -> Self {
        Self { photons: 500_000, nearest: 64, radius: None, seed: 0 }
    }
}

/// Bytes one stored photon takes (position, power, direction, normal).
pub const PHOTON_BYTES: u64 = std::mem::size_of::<Photon>() as u64;

/// Photons traced per batch (one generator seed range, one progress step).
const BATCH: usize = 4096;

/// A photon where it landed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Photon {
    /// Where.
    pub p: Vec3,
    /// Its power (W per channel).
    pub power: Vec3,
    /// Unit direction back towards where it came from.
    pub wi: Vec3,
    /// The surface's geometric normal on the side it arrived.
    pub n: Vec3,
}

impl Located for Photon {
    fn position(&self) -> Vec3 {
        self.p
    }
}

/// Why a scene gets no photon map.
#[derive(Clone, Debug, PartialEq)]
pub enum Refusal {
    /// Dispersive glass is traced spectrally; the map is RGB.
    Dispersive,
}

impl std::fmt::Display for Refusal {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Refusal::Dispersive => f.write_str(
                "photon mapping traces RGB photons, and this scene's glass disperses (cauchy, sellmeier or glass ior): use --integrator path",
            ),
        }
    }
}

/// The caustic photon map of a scene.
#[derive(Clone, Debug)]
pub struct CausticMap {
    tree: KdTree<Photon>,
    nearest: usize,
    radius: f64,
    /// Photons shot.
    pub shot: usize,
}

impl CausticMap {
    /// Shoots `settings.photons` photons through `world` (built from `scene`) and keeps those
    /// that reach a non-specular surface through specular ones; `progress(done, total)` after
    /// each batch.
    pub fn build(
        scene: &Scene,
        world: &World,
        settings: &Settings,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Result<Self, Refusal> {
        check(scene)?;
        let lights = Lights::build(scene);
        let bounds = world.bounds();
        let scene_sphere = if bounds.is_finite() && !bounds.is_empty() {
            Target { center: bounds.centroid(), radius: (bounds.extent().length() * 0.5).max(1e-9) }
        } else {
            Target { center: Vec3::ZERO, radius: 1.0 }
        };
        let emitter = Emitter::new(&lights, specular_targets(scene, world), scene_sphere);
        let radius = settings.radius.unwrap_or(0.05 * scene_sphere.radius);
        let mut photons = Vec::new();
        if emitter.shoots() && settings.photons > 0 {
            let batches = settings.photons.div_ceil(BATCH);
            let done = std::sync::atomic::AtomicUsize::new(0);
            let tracer = Tracer { scene, world, max_depth: scene.render.max_depth.max(2) };
            let per_batch: Vec<Vec<Photon>> = (0..batches)
                .into_par_iter()
                .map(|b| {
                    let range = b * BATCH..((b + 1) * BATCH).min(settings.photons);
                    let mut out = Vec::new();
                    for i in range {
                        let mut rng = Rng::for_sample(settings.seed ^ 0x7068_6f74_6f6e, i as u32, (i >> 32) as u32, 0);
                        if let Some(e) = emitter.emit(&mut rng) {
                            tracer.trace(
                                Ray::new(e.origin, e.dir),
                                e.power / settings.photons as f64,
                                &mut rng,
                                &mut out,
                            );
                        }
                    }
                    progress(done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1, batches);
                    out
                })
                .collect();
            photons = per_batch.into_iter().flatten().collect();
        }
        Ok(Self { tree: KdTree::build(photons), nearest: settings.nearest.max(1), radius, shot: settings.photons })
    }

    /// The stored photons, in tree order.
    pub fn photons(&self) -> &[Photon] {
        self.tree.items()
    }

    /// The largest gathering radius.
    pub fn radius(&self) -> f64 {
        self.radius
    }
}

impl CausticEstimate for CausticMap {
    /// Jensen's estimate with the cone filter (`k = 1`): `Σ f(wᵢ) ΔΦᵢ wᵢ / ((1 − 2/3) π r²)`,
    /// `r` the distance of the farthest photon gathered (at most the radius), photons on the
    /// viewer's side of the surface only.
    fn radiance(&self, p: Vec3, ng: Vec3, f: &dyn Fn(Vec3) -> Vec3) -> Vec3 {
        if self.tree.is_empty() {
            return Vec3::ZERO;
        }
        NEIGHBOURS.with(|cell| {
            let mut found = cell.borrow_mut();
            self.tree.nearest(p, self.nearest, self.radius, |ph| ph.n.dot(ng) > 0.5, &mut found);
            let r2 = found.iter().map(|n| n.dist2).fold(0.0, f64::max);
            if found.is_empty() || r2 <= 0.0 {
                return Vec3::ZERO;
            }
            let r = r2.sqrt();
            let sum = found.iter().fold(Vec3::ZERO, |acc, n: &Neighbour| {
                let ph = &self.tree.items()[n.index as usize];
                acc + f(ph.wi) * ph.power * (1.0 - n.dist2.sqrt() / r)
            });
            sum / ((1.0 - 2.0 / 3.0) * PI * r2)
        })
    }
}

thread_local! {
    static NEIGHBOURS: std::cell::RefCell<Vec<Neighbour>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// Bounding spheres of the objects whose materials have a delta lobe (mirrors, smooth glass);
/// `None` when one of them is unbounded (a plane mirror), so photons cannot be aimed.
fn specular_targets(scene: &Scene, world: &World) -> Option<Vec<Target>> {
    let specular = |m: u32| {
        bsdf_at(&scene.materials[m as usize], Vec2::ZERO, Vec3::ONE, &scene.images, ColorMode::Rgb).has_delta_lobe()
    };
    let mut targets = vec![];
    for o in world.objects() {
        let materials = std::iter::once(o.material).chain(o.slot_materials.iter().copied());
        if !materials.into_iter().any(specular) {
            continue;
        }
        let b = o.placed.bounds();
        if !b.is_finite() {
            return None;
        }
        targets.push(Target { center: b.centroid(), radius: (b.extent().length() * 0.5).max(1e-9) });
    }
    Some(targets)
}

/// Follows photons through delta bounces.
struct Tracer<'a> {
    scene: &'a Scene,
    world: &'a World,
    max_depth: u32,
}

impl Tracer<'_> {
    /// Traces one photon of `power` along `ray`, storing it in `out` where it meets a
    /// non-specular surface after one or more specular bounces; it goes on only along delta
    /// lobes (a caustic path), with Russian roulette after a few bounces.
    fn trace(&self, mut ray: Ray, mut power: Vec3, rng: &mut Rng, out: &mut Vec<Photon>) {
        // A photon goes on only along delta lobes: after `bounce` bounces, all were specular.
        for bounce in 0..self.max_depth {
            let Some(wh) = self.world.intersect(&ray, f64::INFINITY) else { return };
            let m = &self.scene.materials[wh.material as usize];
            if let Some(kept) = alhazen_render::optics::absorbed_inside(m, &wh.hit, ray.dir, ColorMode::Rgb) {
                power *= kept;
            }
            let bsdf = bsdf_at(m, wh.hit.uv, wh.hit.color, &self.scene.images, ColorMode::Rgb);
            let wi = -ray.dir;
            let (mut ng, mut ns) = (wh.hit.n, shading_normal(&wh.hit, m, &self.scene.images));
            if !bsdf.transmits() && ng.dot(wi) < 0.0 {
                (ng, ns) = (-ng, -ns);
            }
            if ns.dot(wi) * ng.dot(wi) <= 0.0 {
                ns = ng;
            }
            if !bsdf.is_delta() && bounce > 0 {
                let side = if ng.dot(wi) >= 0.0 { ng } else { -ng };
                out.push(Photon { p: wh.hit.p, power, wi, n: side });
            }
            if !bsdf.has_delta_lobe() {
                return;
            }
            let frame =
                tangent_at(m, &wh.hit, &self.scene.images).map_or_else(|| Frame::around(ns), |t| Frame::new(ns, t));
            let Some(bs) = bsdf.sample(frame.to_local(wi), rng.uniform(), Vec2::new(rng.uniform(), rng.uniform()))
            else {
                return;
            };
            if !bs.delta {
                return;
            }
            // Power, not radiance, crosses a refraction: undo the radiance's 1/η².
            let weight = bs.f * bs.l.z.abs() / bs.pdf * (bs.eta * bs.eta);
            if !weight.is_finite() || weight == Vec3::ZERO {
                return;
            }
            power *= weight;
            if bounce >= 3 {
                let q = weight.max_element().min(0.95);
                if rng.uniform() >= q {
                    return;
                }
                power /= q;
            }
            let dir = frame.to_world(bs.l);
            let eps = alhazen_render::shape::ray_epsilon(wh.hit.p);
            ray = Ray::new(wh.hit.p + ng * if ng.dot(dir) >= 0.0 { eps } else { -eps }, dir);
        }
    }
}

/// Refuses what the photon map cannot hold: dispersive glass (traced spectrally; photons are RGB).
pub fn check(scene: &Scene) -> Result<(), Refusal> {
    match scene.materials.iter().any(|m| m.bsdf.as_ref().is_some_and(|b| b.is_dispersive())) {
        true => Err(Refusal::Dispersive),
        false => Ok(()),
    }
}

/// Renders `scene` by path tracing with caustics from a photon map made with `settings` (the
/// default vector kernel and BVH). For tools and tests; the CLI renders in tiles and parts.
pub fn render(scene: &Scene, settings: &Settings) -> Result<alhazen_render::Image, Refusal> {
    let world = World::build(scene);
    let map = CausticMap::build(scene, &world, settings, &|_, _| {})?;
    let r = &scene.render;
    let camera = alhazen_render::Camera::new(&scene.camera, r.width, r.height);
    let tracer = alhazen_render::path::PathTracer::new(scene, &world, &camera).with_caustics(&map);
    let (w, h) = alhazen_render::film_size(scene);
    Ok(alhazen_render::film::render_image(w, h, &tracer, r.spp, &|_, _| {}))
}
