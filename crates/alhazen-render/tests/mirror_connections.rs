//! Specular connections through mirrors in both ray tracers (issue 19): exact values through a
//! plane mirror (the mirror image of the light), the caustic of a cup on the catacaustic of the
//! mirror crate, unbiased multiple importance sampling for area lights, determinism.

use alhazen_math::Vec3;
use alhazen_mirror::caustic::{Eye, Side, curve};
use alhazen_render::Image;
use alhazen_scene::parse_scene;
use std::path::Path;

fn render(text: &str) -> Image {
    let scene = parse_scene("test.toml".as_ref(), text).unwrap();
    alhazen_render::render(&scene, &|_, _| {})
}

fn mean(img: &Image) -> Vec3 {
    let n = (img.width * img.height) as f64;
    (0..img.height).flat_map(|y| (0..img.width).map(move |x| (x, y))).map(|(x, y)| img.get(x, y)).sum::<Vec3>() / n
}

/// A Lambert floor seen from above (a tiny patch around the origin), a vertical plane mirror at
/// `x = 1` and a point light 2 above the floor.
fn floor_and_plane_mirror(integrator: &str, connections: bool) -> String {
    format!(
        r#"
[render]
width = 3
height = 3
spp = 4
max_depth = 3
integrator = "{integrator}"
mirror_connections = {connections}
[camera]
type = "orthographic"
eye = [0, 0, 5]
target = [0, 0, 0]
width = 0.001
[[light]]
type = "point"
position = [0, 0, 2]
intensity = 1
attenuation = [1, 0, 0]
[materials.floor]
color = 0.5
specular = 0
[materials.mirror]
color = 0
diffuse = 0
specular = 0
mirror = 0.5
[[object]]
shape = "plane"
normal = [0, 0, 1]
material = "floor"
[[object]]
shape = "plane"
point = [1, 0, 0]
normal = [-1, 0, 0]
material = "mirror"
"#
    )
}

#[test]
fn through_a_plane_mirror_the_light_shines_from_its_image() {
    // Direct: I cos/d² = 1/4. The image light at (2, 0, 2): d² = 8, cos = 1/√2, times R = 0.5.
    let direct = 0.25;
    let image = 0.5 * std::f64::consts::FRAC_1_SQRT_2 / 8.0;
    for (integrator, albedo_factor) in [("whitted", 0.5), ("path", 0.5 / std::f64::consts::PI)] {
        let with = render(&floor_and_plane_mirror(integrator, true)).get(1, 1).x;
        let without = render(&floor_and_plane_mirror(integrator, false)).get(1, 1).x;
        let (want_with, want_without) = (albedo_factor * (direct + image), albedo_factor * direct);
        assert!((with - want_with).abs() < 1e-5 * want_with, "{integrator}: {with} vs {want_with}");
        assert!((without - want_without).abs() < 1e-5 * want_without, "{integrator}: {without} vs {want_without}");
    }
}

/// The coffee cup seen straight from above at 1 sample per pixel under Whitted: along columns
/// that cross the nephroid, the brightest pixel lies on the catacaustic that the mirror crate
/// computes for a source at infinity (Glaeser §2.3), within a pixel or two. (Every column that
/// crosses the lit part of the arc is measured; the cusp, where the arc runs along the columns,
/// is left out.)
#[test]
fn the_cup_caustic_lies_on_the_catacaustic() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/coffee-cup.toml");
    let text = std::fs::read_to_string(&root).unwrap();
    let (head, rest) = text.split_once("[camera]").unwrap();
    let (_, tail) = rest.split_once("[[light]]").unwrap();
    let side = 400u32;
    let span = 2.2;
    let camera = format!(
        "[camera]\ntype = \"orthographic\"\neye = [0, 5, 0]\ntarget = [0, 0, 0]\nup = [0, 0, 1]\nwidth = {span}\n\n"
    );
    let head = head.replace("width = 640\nheight = 480\nspp = 4", &format!("width = {side}\nheight = {side}\nspp = 1"));
    // The sun at 50° (the scene's 30° lights only the arcs' first third: the rim shadows the
    // rest), so that most of the nephroid is lit.
    let tail = tail.replace("direction = [0, -0.5, -0.866]", "direction = [0, -0.766, -0.643]");
    let img = render(&format!("{head}{camera}[[light]]{tail}"));
    let pixel = span / side as f64;
    // The nephroid for parallel light from +z on the unit circle: canonical x is world z,
    // canonical y is world ±x.
    let arcs = curve(1.0, Eye::AtInfinity, Side::Inside, 20000, 2.0);
    let arc_z_at = |s: f64| -> f64 {
        let mut best = f64::NAN;
        for piece in &arcs {
            for w in piece.windows(2) {
                let (a, b) = (w[0], w[1]);
                if (a.y - s) * (b.y - s) <= 0.0 && a.y != b.y && a.y >= 0.0 && b.y >= 0.0 {
                    best = a.x + (b.x - a.x) * (s - a.y) / (b.y - a.y);
                }
            }
        }
        best
    };
    let mut errors = Vec::new();
    for column in 0..side {
        let x_world = span / 2.0 - (column as f64 + 0.5) * pixel;
        let s = x_world.abs();
        if !(0.3..=0.85).contains(&s) {
            continue;
        }
        let z = arc_z_at(s);
        // Search the shaded part of the floor between the centre and the sunlit strip.
        let row_of = |z: f64| ((span / 2.0 - z) / pixel - 0.5).round() as u32;
        let (top, bottom) = (row_of(-0.2), row_of(-0.72));
        let brightest = (top..=bottom).max_by(|&a, &b| img.get(column, a).x.total_cmp(&img.get(column, b).x)).unwrap();
        let want = (span / 2.0 - z) / pixel - 0.5;
        errors.push((brightest as f64 - want).abs());
    }
    errors.sort_by(f64::total_cmp);
    let (median, max) = (errors[errors.len() / 2], errors[errors.len() - 1]);
    assert!(errors.len() > 100, "{} columns", errors.len());
    eprintln!("distance to the catacaustic over {} columns: median {median:.2} px, max {max:.2} px", errors.len());
    assert!(median <= 1.0 && max <= 2.0, "distance to the catacaustic: median {median:.2} px, max {max:.2} px");
}

/// A floor lit by a disk lamp facing away from it, through a mirror ball only, seen from above
/// where the lamp's reflection falls, and `extra` objects.
fn lamp_and_mirror_ball(connections: bool, spp: u32, seed: u32, extra: &str) -> String {
    format!(
        r#"
[render]
width = 16
height = 16
spp = {spp}
max_depth = 4
seed = {seed}
integrator = "path"
mirror_connections = {connections}
[camera]
type = "orthographic"
eye = [-2.0, 6, -0.6]
target = [-2.0, 0, -0.6]
up = [0, 0, 1]
width = 1.6
[materials.floor]
color = 0.8
[materials.chrome]
color = 0
diffuse = 0
mirror = 0.9
[materials.lamp]
color = 0
emission = 10
[[object]]
shape = "plane"
normal = [0, 1, 0]
material = "floor"
[[object]]
shape = "sphere"
center = [0, 1, 0]
radius = 1
material = "chrome"
[[object]]
shape = "disk"
center = [-1.7, 0.5, 0.7]
normal = [0.5, 1, 0]
radius = 0.4
material = "lamp"
{extra}"#
    )
}

/// A small lamp that faces away from the floor lights it only through a mirror ball. With
/// connections, paths that reach the lamp after the ball are weighted against them (MIS);
/// without, only BSDF sampling finds them. Both estimate the same image (means within 3 %, the
/// BSDF-only estimate at 64× the samples), and the connected one is much less noisy at equal
/// samples.
#[test]
fn area_light_through_a_mirror_ball_is_unbiased_with_and_without_connections() {
    let scene = |connections: bool, spp: u32, seed: u32| lamp_and_mirror_ball(connections, spp, seed, "");
    let noise = |connections: bool| {
        let (a, b) = (render(&scene(connections, 256, 0)), render(&scene(connections, 256, 1)));
        let n = (a.width * a.height) as f64;
        let pixels = (0..a.height).flat_map(|y| (0..a.width).map(move |x| (x, y)));
        pixels.map(|(x, y)| (a.get(x, y) - b.get(x, y)).x.abs()).sum::<f64>() / n / mean(&a).x
    };
    let connected = mean(&render(&scene(true, 256, 0))).x;
    let sampled = mean(&render(&scene(false, 16384, 2))).x;
    let rel = (connected - sampled).abs() / sampled;
    let (n_with, n_without) = (noise(true), noise(false));
    eprintln!("means {connected:.5} / {sampled:.5} ({:.2} %), noise {n_with:.4} / {n_without:.4}", rel * 100.0);
    assert!(rel < 0.03, "means {connected} with connections, {sampled} without ({:.2} %)", rel * 100.0);
    assert!(n_with * 4.0 < n_without, "relative noise {n_with} with connections, {n_without} without");
}

#[test]
fn connected_images_do_not_depend_on_the_thread_count() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    for (name, integrator) in
        [("coffee-cup", alhazen_scene::IntegratorKind::Path), ("glass-balls", alhazen_scene::IntegratorKind::Whitted)]
    {
        let mut scene = alhazen_scene::load_scene(&root.join(format!("{name}.toml"))).unwrap();
        (scene.render.width, scene.render.height, scene.render.spp) = (40, 30, 2);
        scene.render.integrator = integrator;
        let at = |threads| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| alhazen_render::render(&scene, &|_, _| {}))
        };
        assert!(at(1) == at(2), "{name}");
    }
}

/// Several lamps and several mirrors: each vertex connects through one (lamp, mirror) pair drawn
/// at random, and the emission found by sampling weighs itself with that draw's probability.
/// The floor in view is lit only through the mirrors (both lamps face away from it); its mean
/// is the one sampling alone converges to.
#[test]
fn one_drawn_lamp_and_mirror_per_vertex_is_unbiased() {
    let more = r#"
[[object]]
shape = "sphere"
center = [-3.5, 0.5, 1.5]
radius = 0.5
material = "chrome"
[[object]]
shape = "cylinder"
base = [-1.0, 0, -2.5]
top = [-1.0, 1.2, -2.5]
radius = 0.4
material = "chrome"
[[object]]
shape = "disk"
center = [-2.6, 0.4, 2.2]
normal = [0, 1, 0.4]
radius = 0.3
material = "lamp"
"#;
    let scene = |connections: bool, spp: u32, seed: u32| lamp_and_mirror_ball(connections, spp, seed, more);
    let connected = mean(&render(&scene(true, 256, 0))).x;
    let sampled = mean(&render(&scene(false, 16384, 2))).x;
    let rel = (connected - sampled).abs() / sampled;
    eprintln!("means {connected:.5} / {sampled:.5} ({:.2} %)", rel * 100.0);
    assert!(rel < 0.03, "means {connected} with connections, {sampled} without ({:.2} %)", rel * 100.0);
}
