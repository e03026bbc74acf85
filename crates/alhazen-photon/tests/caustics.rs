//! Photon mapping on real scenes (issue 23, item 3): a glass ball's caustic under an area light
//! agrees with the path tracer's converged estimate; under a point light, where no path from
//! the eye finds it, it appears; the map and image are the same at any thread count.

use alhazen_photon::{CausticMap, Settings, render};
use alhazen_render::World;
use alhazen_scene::{IntegratorKind, Scene, parse_scene};

/// A glass ball on a grey floor, lit by `light` from the upper left; black sky.
fn glass_ball(light: &str, size: (u32, u32), spp: u32) -> Scene {
    let text = format!(
        "background = 0\n[render]\nwidth = {}\nheight = {}\nspp = {spp}\nmax_depth = 8\nintegrator = \"path\"\n\
         [camera]\neye = [0, 4, -5]\ntarget = [0, 0.5, 0]\nfov = 45\n{light}\n\
         [[object]]\nshape = \"plane\"\nmaterial = {{ color = 0.8 }}\n\
         [[object]]\nshape = \"sphere\"\ncenter = [0, 1, 0]\nradius = 1\nmaterial = {{ color = 0, diffuse = 0, transparency = 1, ior = 1.5 }}\n",
        size.0, size.1
    );
    parse_scene("glass-ball.toml".as_ref(), &text).unwrap_or_else(|e| panic!("{e}"))
}

/// Mean luminance-ish (channel mean) over pixels `x0..x1`, `y0..y1`.
fn mean(img: &alhazen_render::Image, (x0, x1): (u32, u32), (y0, y1): (u32, u32)) -> f64 {
    let mut sum = 0.0;
    for y in y0..y1 {
        for x in x0..x1 {
            sum += img.get(x, y).element_sum() / 3.0;
        }
    }
    sum / ((x1 - x0) * (y1 - y0)) as f64
}

/// The caustic's box in the 64 × 48 image of [`glass_ball`] (inside the ball's shadow, right of
/// its foot), found from the photon image's brightest region.
const CAUSTIC: ((u32, u32), (u32, u32)) = ((15, 26), (26, 34));

#[test]
fn an_area_lights_caustic_agrees_with_the_converged_path_tracer() {
    let light =
        "[[object]]\nshape = \"sphere\"\ncenter = [-4, 5, 1]\nradius = 0.4\nmaterial = { color = 0, emission = 40 }";
    let reference = alhazen_render::render(&glass_ball(light, (64, 48), 4096), &|_, _| {});
    let settings = Settings { photons: 400_000, ..Settings::default() };
    let photons = render(&glass_ball(light, (64, 48), 64), &settings).unwrap();
    let (a, b) = (mean(&reference, CAUSTIC.0, CAUSTIC.1), mean(&photons, CAUSTIC.0, CAUSTIC.1));
    // The lit floor beside it, for scale: the caustic is brighter than direct light.
    let floor = mean(&reference, (52, 60), (36, 44));
    eprintln!("caustic box: path tracer {a:.4}, photon map {b:.4}; floor {floor:.4}");
    assert!(a > 1.5 * floor, "the box must hold a caustic: {a} vs floor {floor}");
    assert!((b / a - 1.0).abs() < 0.05, "caustic: photon map {b:.4}, path tracer {a:.4}");
    let (fa, fb) = (floor, mean(&photons, (52, 60), (36, 44)));
    assert!((fb / fa - 1.0).abs() < 0.03, "direct light unchanged: {fb:.4} vs {fa:.4}");
}

#[test]
fn a_point_lights_caustic_appears_where_paths_from_the_eye_find_none() {
    let light = "[[light]]\ntype = \"point\"\nposition = [-4, 5, 1]\nintensity = 20";
    let scene = glass_ball(light, (64, 48), 16);
    let path = alhazen_render::render(&scene, &|_, _| {});
    let photons = render(&scene, &Settings { photons: 200_000, ..Settings::default() }).unwrap();
    let (a, b) = (mean(&path, CAUSTIC.0, CAUSTIC.1), mean(&photons, CAUSTIC.0, CAUSTIC.1));
    let floor = mean(&path, (52, 60), (36, 44));
    assert!(a < 0.05 * floor, "the path tracer sees the shadow only: {a} vs floor {floor}");
    assert!(b > floor, "the photon map focuses light into the shadow: {b} vs floor {floor}");
}

#[test]
fn the_map_and_the_image_are_the_same_at_any_thread_count() {
    let light = "[[light]]\ntype = \"point\"\nposition = [-4, 5, 1]\nintensity = 20";
    let scene = glass_ball(light, (32, 24), 4);
    let settings = Settings { photons: 50_000, ..Settings::default() };
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let world = World::build(&scene);
            let map = CausticMap::build(&scene, &world, &settings, &|_, _| {}).unwrap();
            (map.photons().to_vec(), render(&scene, &settings).unwrap())
        })
    };
    let (one, two) = (run(1), run(2));
    assert!(!one.0.is_empty());
    assert_eq!(one.0, two.0);
    assert_eq!(one.1.pixels, two.1.pixels);
}

#[test]
fn dispersive_glass_is_refused_with_a_reason() {
    let text = "[render]\nintegrator = \"path\"\n[[light]]\ntype = \"point\"\nposition = [-4, 5, 1]\n[materials.flint]\nbsdf = { type = \"dielectric\", glass = \"sf11\" }\n[[object]]\nshape = \"sphere\"\nradius = 1\nmaterial = \"flint\"\n";
    let scene = parse_scene("f.toml".as_ref(), text).unwrap_or_else(|e| panic!("{e}"));
    let e = render(&scene, &Settings::default()).unwrap_err().to_string();
    assert!(e.contains("disperses") && e.contains("--integrator path"), "{e}");
    assert_eq!(scene.render.integrator, IntegratorKind::Path);
}
