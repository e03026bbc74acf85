//! `alhazen-render`: the photoreal path of alhazen — a Whitted ray tracer (lecture
//! "Viewing and recursive ray tracing"; course §"Lighting models") over an SAH BVH.
//!
//! Both integrators join lights to surfaces through sphere, cylinder and plane mirrors exactly
//! ([`connect`]: every solution of Alhazen's problem by `alhazen-mirror`, Glaeser §1–2).
//!
//! Data flow: [`alhazen_scene::Scene`] → [`World`] (shapes placed, BVH built) and [`Camera`] →
//! [`Whitted`] traces stratified samples per pixel in parallel tiles → [`Image`] (linear RGB) →
//! [`output::write_image`] (PNG / EXR / PFM, atomically).
//!
//! ```
//! let text = r#"
//! [render]
//! width = 8
//! height = 6
//! spp = 1
//! [camera]
//! eye = [0, 0, 5]
//! [[light]]
//! type = "point"
//! position = [5, 5, 5]
//! [[object]]
//! shape = "sphere"
//! radius = 1
//! "#;
//! let scene = alhazen_scene::parse_scene("doc.toml".as_ref(), text).unwrap();
//! let img = alhazen_render::render(&scene, &|_, _| {});
//! assert_eq!((img.width, img.height), (8, 6));
//! assert!(img.get(4, 3).x > 0.0, "the sphere is lit in the middle");
//! assert_eq!(img.get(0, 0).x, 0.0, "black background in the corner");
//! ```

pub mod bsdf;
pub mod bvh;
pub mod camera;
pub mod connect;
pub mod distribution;
pub mod envmap;
pub mod film;
pub mod light_choice;
pub mod lights;
pub mod optics;
pub mod output;
pub mod path;
mod prefetch;
pub mod sampler;
pub mod shape;
pub mod spectrum;
pub use alhazen_scene::texture;
pub mod whitted;
pub mod world;

pub use camera::Camera;
pub use film::Image;
pub use whitted::Whitted;
pub use world::World;

use alhazen_scene::{IntegratorKind, Scene};
use path::PathTracer;
use whitted::WhittedEstimator;

/// Renders `scene` with its own settings (`scene.render`); `progress(done, total)` reports
/// finished tiles. Runs on the current rayon pool.
pub fn render(scene: &Scene, progress: &(dyn Fn(usize, usize) + Sync)) -> Image {
    render_with(scene, shape::VectorUnit::detect(), progress)
}

/// [`render`] with the packets tested by `unit`'s kernel (one of [`shape::VectorUnit::available`]):
/// the same image from every kernel.
pub fn render_with(scene: &Scene, unit: shape::VectorUnit, progress: &(dyn Fn(usize, usize) + Sync)) -> Image {
    let (w, h) = film_size(scene);
    with_estimator(scene, unit, bvh::BuildMethod::Sah, &|estimator| {
        film::render_image(w, h, estimator, scene.render.spp, progress)
    })
}

/// About how many bytes rendering `scene` takes beyond the scene itself: the film (its
/// finished tiles, then the image, then the encoded file: 28 bytes a pixel at most) and the
/// world (per mesh triangle its precomputed flat and share of the BVH, ~450 bytes measured on
/// a million triangles; per object its shape and BVH node). Computed before building anything,
/// so a render that would not fit is refused at once.
pub fn memory_estimate(scene: &Scene) -> u64 {
    let (w, h) = film_size(scene);
    let film = w as u64 * h as u64 * 28;
    let triangles: u64 = scene.meshes.iter().map(|m| m.triangles.len() as u64).sum();
    film + triangles * 450 + scene.objects.len() as u64 * 300 + envmap::EnvMap::memory_estimate(scene)
}

/// The film's size for `scene`: its image size, or twice its width for a side-by-side stereo
/// camera.
pub fn film_size(scene: &Scene) -> (u32, u32) {
    let camera = Camera::new(&scene.camera, scene.render.width, scene.render.height);
    (camera.film_width, camera.film_height)
}

/// Renders part of `scene`'s film (a [`film::Job`]: some tiles, some samples), handing each
/// tile to `done` as it finishes; tiles not begun when `stop` is set are skipped. The tiles
/// of any set of jobs covering the film merge to the bits of [`render_with`] ([`film::part`]).
pub fn render_tiles_with(
    scene: &Scene,
    unit: shape::VectorUnit,
    job: &film::Job,
    stop: &std::sync::atomic::AtomicBool,
    done: &(dyn Fn(film::TileResult) + Sync),
) {
    render_tiles_by(scene, unit, bvh::BuildMethod::Sah, job, stop, done)
}

/// [`render_tiles_with`], the meshes' hierarchies built by `method` (Morton order builds
/// faster, the surface area heuristic traces faster; the hits are the same but for exact
/// ties).
pub fn render_tiles_by(
    scene: &Scene,
    unit: shape::VectorUnit,
    method: bvh::BuildMethod,
    job: &film::Job,
    stop: &std::sync::atomic::AtomicBool,
    done: &(dyn Fn(film::TileResult) + Sync),
) {
    render_tiles_in(scene, &World::build_by(scene, unit, method), job, stop, done)
}

/// [`render_tiles_by`] over `world`, built beforehand from `scene` by [`World::build_by`]
/// (so that a caller can tell the build's time from the render's).
pub fn render_tiles_in(
    scene: &Scene,
    world: &World,
    job: &film::Job,
    stop: &std::sync::atomic::AtomicBool,
    done: &(dyn Fn(film::TileResult) + Sync),
) {
    let (w, h) = film_size(scene);
    with_estimator_in(scene, world, &|estimator| film::render_tiles(w, h, estimator, job, stop, done))
}

/// Calls `work` with the scene's integrator over its world.
fn with_estimator<T>(
    scene: &Scene,
    unit: shape::VectorUnit,
    method: bvh::BuildMethod,
    work: &dyn Fn(&dyn film::PixelEstimator) -> T,
) -> T {
    with_estimator_in(scene, &World::build_by(scene, unit, method), work)
}

/// Calls `work` with the scene's integrator over `world`, the scene's.
fn with_estimator_in<T>(scene: &Scene, world: &World, work: &dyn Fn(&dyn film::PixelEstimator) -> T) -> T {
    let s = &scene.render;
    let camera = Camera::new(&scene.camera, s.width, s.height);
    match s.integrator {
        IntegratorKind::Whitted => work(&WhittedEstimator {
            whitted: Whitted::new(scene, world),
            camera: &camera,
            spp: s.spp,
            seed: s.seed,
            film: film::filter::FilmSampler::new(&s.filter),
        }),
        // Photon mapping and radiosity live in crates above this one (`alhazen render` runs
        // them); here the path tracer renders what the photon map converges to and radiosity
        // approximates.
        IntegratorKind::Path | IntegratorKind::Photon | IntegratorKind::Radiosity => {
            work(&PathTracer::new(scene, world, &camera))
        }
    }
}
