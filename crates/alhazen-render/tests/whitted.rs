//! Whitted ray tracing lit by emitting objects: where nothing reflects or refracts, its image
//! is the path tracer's direct light (paths of two segments), block by block; through
//! dispersive glass it spreads white light into the path tracer's spectrum.

use alhazen_math::Vec3;
use alhazen_render::{Image, render};
use alhazen_scene::{IntegratorKind, Scene, load_scene, parse_scene};
use std::path::Path;

fn with(mut scene: Scene, integrator: IntegratorKind, spp: u32) -> Image {
    scene.render.width = 32;
    scene.render.height = 32;
    scene.render.spp = spp;
    scene.render.max_depth = 2;
    scene.render.integrator = integrator;
    render(&scene, &|_, _| {})
}

/// Each 8 × 8 block's mean over the pixels that do not see a lamp (both values below 1; a
/// lamp's edge pixels differ by the sampling of the pixel's area, not of the light): within
/// `rel` of the path tracer's or `abs` of it.
fn blocks_agree(whitted: &Image, path: &Image, rel: f64, abs: f64) {
    for (bx, by) in (0..4).flat_map(|y| (0..4).map(move |x| (x, y))) {
        let (mut w, mut p, mut n) = (Vec3::ZERO, Vec3::ZERO, 0.0f64);
        for (x, y) in (0..8).flat_map(|y| (0..8).map(move |x| (8 * bx + x, 8 * by + y))) {
            let (a, b) = (whitted.get(x, y), path.get(x, y));
            if a.max_element() < 1.0 && b.max_element() < 1.0 {
                (w, p, n) = (w + a, p + b, n + 1.0);
            }
        }
        let (w, p) = (w / n.max(1.0), p / n.max(1.0));
        let ok = (w - p).abs().max_element() <= (rel * p.max_element()).max(abs);
        assert!(ok, "block ({bx}, {by}): Whitted {w:?}, path tracer {p:?}");
    }
}

#[test]
fn whitted_lit_by_the_cornell_lamp_is_the_path_tracers_direct_light() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-box.toml");
    let scene = load_scene(&path).unwrap();
    let whitted = with(scene.clone(), IntegratorKind::Whitted, 32);
    let traced = with(scene, IntegratorKind::Path, 1024);
    blocks_agree(&whitted, &traced, 0.04, 2e-3);
}

#[test]
fn sphere_and_disk_lamps_light_whitted_as_they_light_the_path_tracer() {
    let text = r#"
background = [0, 0, 0]
[camera]
eye = [0, 2.5, 5]
target = [0, 0.3, 0]
fov = 45
[materials.floor]
bsdf = { type = "lambert", color = [0.7, 0.6, 0.5] }
[[object]]
shape = "rectangle"
transform = [{ scale = 4 }, { rotate_x = -90 }]
material = "floor"
[[object]]
shape = "box"
min = [-0.4, 0, -0.4]
max = [0.4, 0.8, 0.4]
material = { color = [0.3, 0.5, 0.8] }
[[object]]
shape = "sphere"
center = [0.8, 2.9, 3.2]
radius = 0.3
material = { emission = [6, 5, 4] }
[[object]]
shape = "disk"
center = [-1.3, 1.8, -0.2]
normal = [0.3, -1, 0]
radius = 0.4
material = { emission = [2, 3, 4] }
"#;
    let scene = parse_scene("lamps.toml".as_ref(), text).unwrap();
    let whitted = with(scene.clone(), IntegratorKind::Whitted, 32);
    let traced = with(scene, IntegratorKind::Path, 1024);
    blocks_agree(&whitted, &traced, 0.04, 2e-3);
}

/// Where each channel of the lamp seen through the prism lies: its x centroid and sum over the
/// window of the image that holds it.
fn channel_centroids(img: &Image) -> [(f64, f64); 3] {
    std::array::from_fn(|c| {
        let (mut sum, mut moment) = (0.0, 0.0);
        for (x, y) in (10..55).flat_map(|y| (40..70).map(move |x| (x, y))) {
            let v = img.get(x, y)[c];
            (sum, moment) = (sum + v, moment + v * x as f64);
        }
        (moment / sum, sum)
    })
}

/// The prism under Whitted: sampled wavelengths, each refracted by its own index, spread the
/// white lamp into the colours the path tracer shows at the same places (red to blue centroids
/// within half a pixel, each channel's light within 15 %); with a constant index, no spread.
#[test]
fn whitted_disperses_white_light_through_the_prism_as_the_path_tracer_does() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/prism.toml");
    let scene = load_scene(&path).unwrap();
    let sized = |mut s: Scene, integrator| {
        (s.render.width, s.render.height, s.render.spp, s.render.integrator) = (100, 75, 64, integrator);
        render(&s, &|_, _| {})
    };
    let whitted = channel_centroids(&sized(scene.clone(), IntegratorKind::Whitted));
    let traced = channel_centroids(&sized(scene.clone(), IntegratorKind::Path));
    assert!(whitted[2].0 - whitted[0].0 > 3.0, "blue lies beyond red: {whitted:?}");
    for c in 0..3 {
        assert!((whitted[c].0 - traced[c].0).abs() < 0.5, "channel {c}: {whitted:?} vs {traced:?}");
        assert!((whitted[c].1 / traced[c].1 - 1.0).abs() < 0.15, "channel {c}: {whitted:?} vs {traced:?}");
    }
    let mut constant = scene;
    for m in &mut constant.materials {
        if let Some(alhazen_scene::bsdf::BsdfDesc::Dielectric { ior, .. }) = &mut m.bsdf {
            *ior = alhazen_scene::bsdf::Ior::Constant(m.ior);
        }
    }
    let flat = channel_centroids(&sized(constant, IntegratorKind::Whitted));
    assert!((flat[2].0 - flat[0].0).abs() < 0.5, "no spread without dispersion: {flat:?}");
}

/// A lamp seen against black through a Gaussian pixel filter: Whitted's stratified samples and
/// the path tracer's draw the same filtered edges (pixel by pixel, within 3 % of the brightest
/// pixel, where the box of one pixel differs by 15 %); a lone Whitted sample is still
/// the pixel's centre (the box's bits).
#[test]
fn whitted_and_the_path_tracer_filter_pixels_alike() {
    let text = "[render]\nwidth = 24\nheight = 24\n[camera]\neye = [0, 0, 4]\nfov = 25\n\
                [materials.lamp]\ncolor = 0\nemission = [4, 3, 2]\n\
                [[object]]\nshape = \"rectangle\"\nmaterial = \"lamp\"\ntransform = [{ scale = 0.45 }, { rotate_z = 20 }]\n";
    let mut scene = parse_scene("lamp.toml".as_ref(), text).unwrap();
    let box_whitted = with(scene.clone(), IntegratorKind::Whitted, 64);
    scene.render.filter = alhazen_scene::PixelFilter::Gaussian { sigma: 0.5, radius: [1.5; 2] };
    let (whitted, path) =
        (with(scene.clone(), IntegratorKind::Whitted, 256), with(scene.clone(), IntegratorKind::Path, 1024));
    let worst = |a: &Image, b: &Image| {
        (0..24 * 24).map(|i| (a.get(i % 24, i / 24) - b.get(i % 24, i / 24)).abs().max_element()).fold(0.0, f64::max)
            / 4.0
    };
    assert!(worst(&whitted, &path) < 0.03, "{}", worst(&whitted, &path));
    assert!(worst(&box_whitted, &path) > 0.1, "{}", worst(&box_whitted, &path));
    let one = |s: &Scene| with(s.clone(), IntegratorKind::Whitted, 1).pixels;
    let mut boxed = scene.clone();
    boxed.render.filter = alhazen_scene::PixelFilter::PIXEL;
    assert_eq!(one(&scene), one(&boxed));
}
