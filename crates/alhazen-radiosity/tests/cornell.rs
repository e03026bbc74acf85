//! The radiosity solution against the path tracer and against the energy balance.

use alhazen_math::Vec3;
use alhazen_radiosity::{FinalGather, Settings, solve};
use alhazen_render::film::{PixelEstimator, render_image};
use alhazen_render::{Camera, World};
use std::path::Path;

fn cornell(size: u32, spp: u32) -> alhazen_scene::Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-box.toml");
    let mut scene = alhazen_scene::load_scene(&path).unwrap();
    scene.render.width = size;
    scene.render.height = size;
    scene.render.spp = spp;
    scene
}

/// Mean radiance per scene object over the pixels whose centre and four neighbours' centres
/// all see that object (edges left out), from `image`.
fn per_object(scene: &alhazen_scene::Scene, image: &alhazen_render::Image) -> Vec<(Vec3, usize)> {
    let world = World::build(scene);
    let (w, h) = (scene.render.width, scene.render.height);
    let camera = Camera::new(&scene.camera, w, h);
    let id = |x: i64, y: i64| -> Option<u32> {
        if x < 0 || y < 0 || x >= w as i64 || y >= h as i64 {
            return None;
        }
        world.intersect(&camera.ray(x as f64 + 0.5, y as f64 + 0.5), f64::INFINITY).map(|hit| hit.object)
    };
    let mut sums = vec![(Vec3::ZERO, 0usize); scene.objects.len()];
    for y in 0..h as i64 {
        for x in 0..w as i64 {
            let Some(o) = id(x, y) else { continue };
            if [(1, 0), (-1, 0), (0, 1), (0, -1)].iter().all(|(dx, dy)| id(x + dx, y + dy) == Some(o)) {
                sums[o as usize].0 += image.get(x as u32, y as u32);
                sums[o as usize].1 += 1;
            }
        }
    }
    sums.iter().map(|(s, n)| (*s / (*n).max(1) as f64, *n)).collect()
}

/// Per wall, the mean of the pixels that see only that wall (edges left out), radiosity's
/// final image against the path tracer's at 1024 samples: within 6 % in every channel. (The
/// path tracer's noise there is below 1 %; what is left is the discretisation: constant
/// irradiance per element, centre visibility, vertex averaging.)
#[test]
fn cornell_box_walls_agree_with_the_path_tracer() {
    let size = 64;
    let scene = cornell(size, 1024);
    let path = alhazen_render::render(&scene, &|_, _| {});
    let settings = Settings { tolerance: 0.001, ..Default::default() };
    let solution = solve(&cornell(size, 4), &settings, &|_, _| {}).unwrap();
    let gather = FinalGather::new(&solution);
    let image = render_image(size, size, &gather as &dyn PixelEstimator, 4, &|_, _| {});
    let (want, got) = (per_object(&scene, &path), per_object(&scene, &image));
    let mut walls = 0;
    for (k, o) in scene.objects.iter().enumerate() {
        let ((a, n), (b, _)) = (want[k], got[k]);
        if n < 100 {
            continue; // the lamp, seen edge-on
        }
        walls += 1;
        let rel = ((b - a).abs() / a.max(Vec3::splat(1e-3))).max_element();
        assert!(rel < 0.06, "{:?}: path tracer {a:.4}, radiosity {b:.4} ({n} pixels): {:.1} %", o.name, 100.0 * rel);
    }
    assert_eq!(walls, 7, "floor, ceiling, back, two side walls, two boxes");
}

/// A closed box of six inward-facing walls of reflectance ρ, one emitting: in steady state the
/// walls reflect `Φ ρ/(1 − ρ)` of the emitted power Φ whatever the geometry — the Neumann
/// series summed. The solution holds it within 2 % (less the unshot remainder).
#[test]
fn a_closed_box_conserves_energy() {
    let rho = 0.5;
    let mut text = format!(
        "[render]\nwidth = 8\nheight = 8\n[camera]\neye = [0, 0, 0.9]\ntarget = [0, 0, 0]\n\
         [materials.wall]\ncolor = [{rho}, {rho}, {rho}]\n\
         [materials.lamp]\ncolor = [{rho}, {rho}, {rho}]\nemission = [1, 1, 1]\n"
    );
    // Unit rectangles in z = 0 facing +z, rotated and moved to face the inside of [-1, 1]³.
    let faces = [
        ("lamp", "{ rotate = { axis = [1, 0, 0], angle = 90 } }, { translate = [0, 1, 0] }"),
        ("wall", "{ rotate = { axis = [1, 0, 0], angle = -90 } }, { translate = [0, -1, 0] }"),
        ("wall", "{ rotate = { axis = [0, 1, 0], angle = 90 } }, { translate = [-1, 0, 0] }"),
        ("wall", "{ rotate = { axis = [0, 1, 0], angle = -90 } }, { translate = [1, 0, 0] }"),
        ("wall", "{ translate = [0, 0, -1] }"),
        ("wall", "{ rotate = { axis = [0, 1, 0], angle = 180 } }, { translate = [0, 0, 1] }"),
    ];
    for (m, tf) in faces {
        text += &format!("[[object]]\nshape = \"rectangle\"\nmaterial = \"{m}\"\ntransform = [{tf}]\n");
    }
    let scene = alhazen_scene::parse_scene("box.toml".as_ref(), &text).unwrap();
    let settings = Settings { tolerance: 1e-4, ..Default::default() };
    let s = solve(&scene, &settings, &|_, _| {}).unwrap();
    let mut reflected = 0.0;
    for (tri, tree) in s.triangles.iter().zip(&s.trees) {
        for n in tree.nodes.iter().filter(|n| n.is_leaf()) {
            let area = tri.area / 4f64.powi(n.level as i32);
            reflected += area * (n.rho * (n.side[0].h + n.side[1].h)).x;
        }
    }
    let emitted = std::f64::consts::PI * 4.0; // π L_e over the lamp's 2 × 2
    let want = emitted * rho / (1.0 - rho);
    assert!((reflected / want - 1.0).abs() < 0.02, "reflected {reflected}, expected {want} ({:?})", s.stats);
    // Every wall faces the inside: the outsides received nothing.
    assert!(s.trees.iter().flat_map(|t| &t.nodes).all(|n| n.side[1].h == Vec3::ZERO));
}

/// The solution is the same bits on one thread and on two.
#[test]
fn the_solution_does_not_depend_on_the_thread_count() {
    let solve_on = |threads| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| solve(&cornell(16, 1), &Settings::default(), &|_, _| {}).unwrap().corners)
    };
    let (a, b) = (solve_on(1), solve_on(2));
    assert!(a == b, "corner irradiance differs between 1 and 2 threads");
}

/// The course's hemicube (delta form factors, the item buffer filled by ray casting) gives the
/// Cornell box of Lambert's closed form: per wall within 7 % (the small box 5.7 %, the rest
/// within 2.5 %), the image's mean within 1 %.
#[test]
fn the_hemicube_agrees_with_the_closed_form() {
    let size = 48;
    let scene = cornell(size, 2);
    let image_of = |settings: &Settings| {
        let s = solve(&scene, settings, &|_, _| {}).unwrap();
        render_image(size, size, &FinalGather::new(&s) as &dyn PixelEstimator, 2, &|_, _| {})
    };
    let exact = image_of(&Settings::default());
    let cube = image_of(&Settings { hemicube: Some(48), levels: 2, ..Default::default() });
    let mean = |i: &alhazen_render::Image| i.pixels.iter().map(|p| (p[0] + p[1] + p[2]) as f64).sum::<f64>();
    assert!((mean(&cube) / mean(&exact) - 1.0).abs() < 0.01, "{} vs {}", mean(&cube), mean(&exact));
    let (a, b) = (per_object(&scene, &exact), per_object(&scene, &cube));
    for (k, o) in scene.objects.iter().enumerate() {
        let ((x, n), (y, _)) = (a[k], b[k]);
        if n >= 50 {
            let rel = ((y - x).abs() / x.max(Vec3::splat(1e-3))).max_element();
            assert!(rel < 0.07, "{:?}: closed form {x:.4}, hemicube {y:.4}: {:.1} %", o.name, 100.0 * rel);
        }
    }
}

/// A floor painted red by its vertex colours (a white material with `vertex_colors`) under a
/// lamp facing it bleeds red onto a white panel above the lamp, which only the floor lights;
/// the same floor without its colours bleeds grey. The floor itself shows red.
#[test]
fn vertex_colours_bleed_onto_their_neighbours() {
    let text = r#"
[camera]
eye = [0, 1, 4]
target = [0, 1, 0]
[materials.white]
color = 0.8
vertex_colors = true
[materials.lamp]
emission = [5, 5, 5]
[[object]]
shape = "rectangle"
material = "white"
transform = [{ scale = 2 }, { rotate_x = -90 }]
[[object]]
shape = "disk"
center = [0, 2, 0]
normal = [0, -1, 0]
radius = 0.5
material = "lamp"
[[object]]
shape = "rectangle"
material = "white"
transform = [{ rotate_x = 90 }, { translate = [0, 2.5, 0] }]
"#;
    let mut scene = alhazen_scene::parse_scene("painted.toml".as_ref(), text).unwrap();
    let alhazen_scene::Shape::Mesh { mesh, .. } = scene.objects[0].shape else { panic!("not a mesh") };
    // The floor and the panel share the rectangle: the panel is given its own white copy.
    let mut floor = (*scene.meshes[mesh]).clone();
    floor.colors = vec![Vec3::new(1.0, 0.1, 0.1); floor.positions.len()];
    scene.meshes.push(std::sync::Arc::new(floor));
    scene.objects[0].shape = alhazen_scene::Shape::Mesh { mesh: scene.meshes.len() - 1, smooth: true };
    let bled = |scene: &alhazen_scene::Scene| {
        let s = alhazen_radiosity::solve(scene, &Default::default(), &|_, _| {}).unwrap();
        let panel = s.triangles.iter().position(|t| t.normal.y < -0.9 && t.p[0].y > 2.4).unwrap();
        let floor = s.triangles.iter().position(|t| t.normal.y > 0.9 && t.p[0].y.abs() < 1e-9).unwrap();
        let b = [1.0 / 3.0; 2];
        let uv = alhazen_math::Vec2::ZERO;
        (s.irradiance(panel, s.triangles[panel].barycentric(s.triangles[panel].at(b)), 0), s.radiance(floor, b, uv, 0))
    };
    let (painted, red) = bled(&scene);
    assert!(painted.x > 5.0 * painted.y && red.x > 5.0 * red.y, "{painted} {red}");
    let last = scene.meshes.len() - 1;
    std::sync::Arc::make_mut(&mut scene.meshes[last]).colors.clear();
    let (plain, grey) = bled(&scene);
    assert!((plain.x - plain.y).abs() < 1e-9 * plain.x && (grey.x - grey.y).abs() < 1e-9 * grey.x, "{plain} {grey}");
}
