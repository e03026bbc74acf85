//! Light samples left to BSDF samples where those do well ([`LightSampling::AgainstBsdf`]) give
//! every image the expectation light samples everywhere ([`LightSampling::Whole`]) give: every
//! kind of BSDF, under a gradient sky (left to BSDF samples alone) and under an environment map
//! with a sun (sampled only above its mean), beside a lamp (and a point light). So does every
//! choice among several lights ([`LightChoice`]).

use super::{LightSampling, PathTracer};
use crate::{Camera, World};
use alhazen_math::Vec3;
use alhazen_scene::{ImageData, Light, LightChoice, Scene};

/// Twelve spheres in a 4 × 3 grid, one per kind of BSDF, on a grey ground, and a lamp.
const SPHERES: &str = r#"
background = { zenith = [0.3, 0.45, 0.9], horizon = [0.9, 0.85, 0.7], ground = [0.2, 0.15, 0.1] }
[render]
width = 48
height = 36
spp = 384
max_depth = 5
integrator = "path"
[camera]
eye = [0, 2.2, 7]
target = [0, 0.9, 0]
fov = 42
[[object]]
shape = "plane"
normal = [0, 1, 0]
material = { color = [0.5, 0.5, 0.5] }
[[object]]
shape = "sphere"
center = [1.5, 4.5, 1.5]
radius = 0.3
material = { color = [0.5, 0.5, 0.5], emission = [12, 11, 9] }
[[object]]
shape = "sphere"
center = [-2.4, 2.9, -1]
radius = 0.5
material = { bsdf = { type = "lambert", color = [0.8, 0.6, 0.4] } }
[[object]]
shape = "sphere"
center = [-0.8, 2.9, -1]
radius = 0.5
material = { bsdf = { type = "oren-nayar", sigma = 25, color = [0.6, 0.7, 0.3] } }
[[object]]
shape = "sphere"
center = [0.8, 2.9, -1]
radius = 0.5
material = { bsdf = { type = "phong", color = [0.5, 0.2, 0.2], kd = 0.6, ks = 0.4, exponent = 30 } }
[[object]]
shape = "sphere"
center = [2.4, 2.9, -1]
radius = 0.5
material = { bsdf = { type = "blinn-phong", color = [0.2, 0.3, 0.6], kd = 0.5, ks = 0.5, exponent = 40, anisotropy = 0.3 } }
[[object]]
shape = "sphere"
center = [-2.4, 1.7, -1]
radius = 0.5
material = { bsdf = { type = "conductor", roughness = [0.08, 0.3], distribution = "ggx", eta = [0.2, 0.4, 1.4], k = [3.9, 2.4, 1.6] } }
[[object]]
shape = "sphere"
center = [-0.8, 1.7, -1]
radius = 0.5
material = { bsdf = { type = "conductor", roughness = 0.2, distribution = "beckmann", metal = "copper", multiscatter = true } }
[[object]]
shape = "sphere"
center = [0.8, 1.7, -1]
radius = 0.5
material = { bsdf = { type = "dielectric", roughness = 0.15, distribution = "ggx", ior = 1.5 } }
[[object]]
shape = "sphere"
center = [2.4, 1.7, -1]
radius = 0.5
material = { bsdf = { type = "plastic", roughness = 0.2, distribution = "beckmann", ior = 1.5, color = [0.7, 0.2, 0.3] } }
[[object]]
shape = "sphere"
center = [-2.4, 0.5, -1]
radius = 0.5
material = { bsdf = { type = "cook-torrance", roughness = 0.25, distribution = "ggx", color = [0.3, 0.6, 0.8], ks = 1.0, layered = true } }
[[object]]
shape = "sphere"
center = [-0.8, 0.5, -1]
radius = 0.5
material = { bsdf = { type = "metallic-roughness", color = [0.9, 0.6, 0.2], metallic = 0.5, roughness = 0.35, diffuse_transmission = { factor = 0.4 } } }
[[object]]
shape = "sphere"
center = [0.8, 0.5, -1]
radius = 0.5
material = { bsdf = { type = "coated", base = { type = "conductor", roughness = 0.3, metal = "gold" }, roughness = 0.05, ior = 1.5 } }
[[object]]
shape = "sphere"
center = [2.4, 0.5, -1]
radius = 0.5
material = { bsdf = { type = "sheen", base = { type = "lambert", color = [0.3, 0.3, 0.7] }, sheen_color = [0.9, 0.9, 0.9], roughness = 0.4 } }
"#;

/// An equirectangular sky: a dim gradient and a sun 40° above the horizon, bright enough to
/// carry most of the map's power in a few texels.
fn sun_map() -> ImageData {
    let (w, h) = (64, 32);
    let pixels = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| {
            let sky = 0.3 + 0.5 * (1.0 - y as f32 / h as f32);
            let sun = (x as i32 - 20).abs() <= 1 && (y as i32 - 7).abs() <= 1;
            if sun { [400.0, 380.0, 330.0] } else { [sky * 0.8, sky * 0.9, sky] }
        })
        .collect();
    ImageData::new(w, h, pixels)
}

/// The means of a 4 × 3 grid of blocks of the image `tracer` renders (each block holds one
/// sphere), pixel values from the box filter's samples.
fn block_means(scene: &Scene, sampling: LightSampling) -> Vec<Vec3> {
    let world = World::build(scene);
    let camera = Camera::new(&scene.camera, scene.render.width, scene.render.height);
    let tracer = PathTracer::with_light_sampling(scene, &world, &camera, sampling);
    let (w, h, spp) = (scene.render.width, scene.render.height, scene.render.spp as usize);
    let mut blocks = vec![Vec3::ZERO; 12];
    let mut samples = vec![Vec3::ZERO; spp];
    for y in 0..h {
        for x in 0..w {
            use crate::film::PixelEstimator;
            tracer.samples(x, y, 0, &mut samples);
            let block = (y * 3 / h) as usize * 4 + (x * 4 / w) as usize;
            blocks[block] += samples.iter().sum::<Vec3>() / (spp * (w * h) as usize / 12) as f64;
        }
    }
    blocks
}

/// Each block's mean under both samplings, within `tolerance` of each other (relative to the
/// brighter channel's value).
fn same_expectation(scene: &Scene, tolerance: f64) {
    let (whole, against) = (block_means(scene, LightSampling::Whole), block_means(scene, LightSampling::AgainstBsdf));
    for (i, (a, b)) in whole.iter().zip(&against).enumerate() {
        let difference = (*a - *b).abs().max_element() / a.max_element().max(1e-3);
        assert!(difference < tolerance, "block {i}: whole {a}, against BSDF samples {b} ({:.2} %)", 100.0 * difference);
    }
}

#[test]
fn a_gradient_sky_left_to_bsdf_samples_lights_every_bsdf_as_before() {
    let scene = alhazen_scene::parse_scene("spheres.toml".as_ref(), SPHERES).unwrap();
    same_expectation(&scene, 0.01);
}

#[test]
fn an_environment_map_sampled_above_its_mean_lights_every_bsdf_as_before() {
    let mut scene = alhazen_scene::parse_scene("spheres.toml".as_ref(), SPHERES).unwrap();
    scene.images.push(sun_map().into());
    let image = scene.images.len() - 1;
    scene.lights.push(Light::Environment { image, scale: 1.0, rotation: 0.3, up: Vec3::Y });
    scene.lights.push(Light::Point {
        position: Vec3::new(2.0, 4.0, 3.0),
        intensity: Vec3::splat(8.0),
        attenuation: [1.0, 0.0, 0.0],
    });
    same_expectation(&scene, 0.03);
}

/// Against BSDF samples, the gradient sky is out of the choice (its density zero), the lamp in
/// it, whatever the sky's place in the list was.
#[test]
fn against_bsdf_samples_a_gradient_sky_is_not_chosen() {
    use crate::lights::{Lights, PathLight};
    let scene = alhazen_scene::parse_scene("spheres.toml".as_ref(), SPHERES).unwrap();
    let (whole, against) = (Lights::build(&scene), Lights::build_for(&scene, LightSampling::AgainstBsdf));
    assert_eq!((whole.len(), whole.choices()), (2, 2));
    assert_eq!((against.len(), against.choices()), (2, 1));
    assert!(whole.sky(Vec3::Y, Vec3::ZERO).1 > 0.0);
    assert_eq!(against.sky(Vec3::Y, Vec3::ZERO), (whole.sky(Vec3::Y, Vec3::ZERO).0, 0.0));
    let lamp = against.of_object(1).unwrap();
    assert!(matches!(against.all()[lamp], PathLight::Area { .. }) && lamp < against.choices());
    for u in [0.0, 0.5, 0.999] {
        assert_eq!(against.choose(u, Vec3::ZERO), lamp);
    }
}

/// Lights chosen uniformly, by power and as a pilot pass measures them light every BSDF alike:
/// beside the lamp and a sun map, a bright point light, a spot, a directional light, and a
/// strong point light under the ground, which lights nothing the camera sees.
#[test]
fn every_light_choice_lights_every_bsdf_alike() {
    let mut scene = alhazen_scene::parse_scene("spheres.toml".as_ref(), SPHERES).unwrap();
    scene.images.push(sun_map().into());
    let image = scene.images.len() - 1;
    let point = |position: Vec3, intensity: f64| Light::Point {
        position,
        intensity: Vec3::splat(intensity),
        attenuation: [1.0, 0.0, 0.0],
    };
    scene.lights.extend([
        Light::Environment { image, scale: 0.2, rotation: 0.3, up: Vec3::Y },
        point(Vec3::new(2.0, 4.0, 3.0), 3.0),
        point(Vec3::new(0.0, -3.0, 0.0), 3000.0),
        Light::Spot {
            position: Vec3::new(-3.0, 4.0, 2.0),
            direction: Vec3::new(0.5, -0.6, -0.6).normalize(),
            cos_cutoff: 0.9,
            falloff: 1.0,
            beam: None,
            intensity: Vec3::splat(5.0),
            attenuation: [1.0, 0.0, 0.0],
        },
        Light::Directional { direction: Vec3::new(0.3, -1.0, -0.4).normalize(), intensity: Vec3::splat(0.2) },
    ]);
    let means = |choice| {
        let mut scene = scene.clone();
        scene.render.light_choice = choice;
        block_means(&scene, LightSampling::AgainstBsdf)
    };
    let uniform = means(LightChoice::Uniform);
    for choice in [LightChoice::Power, LightChoice::Measured] {
        for (i, (a, b)) in uniform.iter().zip(&means(choice)).enumerate() {
            let difference = (*a - *b).abs().max_element() / a.max_element().max(1e-3);
            assert!(difference < 0.03, "{choice:?}, block {i}: uniform {a}, {b} ({:.2} %)", 100.0 * difference);
        }
    }
}
