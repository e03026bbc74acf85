//! The path tracer end to end: white furnaces (nothing absorbs, so every pixel sees the
//! environment), an environment map read from an EXR file, thread-count independence, and the
//! dispersive prism showing a spectrum.

use alhazen_math::Vec3;
use alhazen_render::output::{Format, write_image};
use alhazen_render::{Image, render};
use alhazen_scene::parse_scene;
use std::path::Path;

fn mean(img: &Image) -> Vec3 {
    let n = (img.width * img.height) as f64;
    (0..img.height).flat_map(|y| (0..img.width).map(move |x| (x, y))).map(|(x, y)| img.get(x, y)).sum::<Vec3>() / n
}

fn furnace(material: &str, spp: u32) -> Image {
    let text = format!(
        r#"
background = [1, 1, 1]
[render]
width = 48
height = 48
spp = {spp}
max_depth = 64
integrator = "path"
[camera]
eye = [0, 0, 4]
fov = 35
[materials.m]
{material}
[[object]]
shape = "sphere"
radius = 1
material = "m"
"#
    );
    render(&parse_scene("furnace.toml".as_ref(), &text).unwrap(), &|_, _| {})
}

#[test]
fn white_lambert_sphere_vanishes_in_a_white_furnace() {
    let img = furnace(r#"bsdf = { type = "lambert", color = [1, 1, 1] }"#, 64);
    let m = mean(&img);
    assert!((m - Vec3::ONE).abs().max_element() < 2e-3, "mean {m}");
    // The centre pixel lies on the sphere: still the environment's radiance.
    let c = img.get(24, 24);
    assert!((c - Vec3::ONE).abs().max_element() < 0.05, "centre {c}");
}

/// A blend of a mirror (a delta lobe) and a rough coat is the blend of their images: a convex
/// object in a furnace sees only the environment, so its image is linear in its BSDF. (Mitsuba
/// 3's `blendbsdf` divides the delta lobe's weight by the coat's density at the mirror
/// direction, and renders this blend 30 % dark.)
#[test]
fn a_blend_of_a_mirror_and_a_rough_coat_is_the_blend_of_their_images() {
    let mirror = r#"{ type = "conductor", metal = "gold" }"#;
    let coat = r#"{ type = "plastic", color = [0, 0, 0], ior = 1.5, roughness = 0.3 }"#;
    let [a, b] = [mirror, coat].map(|m| mean(&furnace(&format!("bsdf = {m}"), 64)));
    let blend = mean(&furnace(&format!("bsdf = {{ type = \"mix\", a = {mirror}, b = {coat}, weight = 0.3 }}"), 64));
    let want = a * 0.3 + b * 0.7;
    assert!(((blend - want) / want).abs().max_element() < 0.01, "blend {blend}, the images' blend {want}");
}

/// A closed sphere of a thin translucent sheet (a paper lantern) whose reflected and transmitted
/// parts sum to white vanishes in a white furnace: the light that passes in bounces about inside
/// and leaves again. Plain Lambert on both faces, and under a layered glossy lobe, whose specular
/// bounces inside keep their angle (at grazing angles, many of them): each within 0.4 % at 256 spp;
/// 1.04 before the lobe's samples that leave below the surface were counted in the density.
#[test]
fn translucent_spheres_vanish_in_a_white_furnace() {
    let lantern = mean(&furnace(
        r#"bsdf = { type = "cook-torrance", color = [1, 1, 1], kd = 0.5, ks = 0, transmittance = [0.5, 0.5, 0.5] }"#,
        64,
    ));
    assert!((lantern - Vec3::ONE).abs().max_element() < 5e-3, "lambert on both faces: {lantern}");
    let glossy = mean(&furnace(
        r#"bsdf = { type = "cook-torrance", color = [1, 1, 1], kd = 0.6, ks = 1, layered = true, roughness = 0.2, transmittance = [0.4, 0.4, 0.4] }"#,
        64,
    ));
    assert!((glossy - Vec3::ONE).abs().max_element() < 0.01, "layered: {glossy}");
}

#[test]
fn smooth_and_rough_glass_conserve_energy_in_a_white_furnace() {
    let smooth = mean(&furnace(r#"bsdf = { type = "dielectric", ior = 1.5 }"#, 64));
    assert!((smooth - Vec3::ONE).abs().max_element() < 5e-3, "smooth glass: {smooth}");
    // Single-scattering microfacets lose the energy of multiple bounces between facets (at
    // every crossing, and light crosses a sphere at least twice): darker, never brighter, and
    // the less the rougher.
    let rough =
        |a: f64| mean(&furnace(&format!(r#"bsdf = {{ type = "dielectric", ior = 1.5, roughness = {a} }}"#), 64));
    let (slightly, very) = (rough(0.05), rough(0.3));
    assert!(slightly.max_element() < 1.0 + 5e-3 && slightly.min_element() > 0.97, "α = 0.05: {slightly}");
    assert!(very.max_element() < slightly.min_element() && very.min_element() > 0.8, "α = 0.3: {very}");
}

#[test]
fn environment_map_from_an_exr_file_lights_the_scene() {
    let dir = tempfile::tempdir().unwrap();
    // A uniform map of radiance 0.5 (scaled ×2 in the scene): a furnace of radiance 1.
    let (w, h) = (32, 16);
    let env = Image { width: w, height: h, pixels: vec![[0.5, 0.5, 0.5]; (w * h) as usize] };
    write_image(&env, &dir.path().join("sky.exr"), Format::from_path(Path::new("x.exr"), false).unwrap()).unwrap();
    let text = r#"
[render]
width = 32
height = 32
spp = 64
integrator = "path"
[camera]
eye = [0, 0, 4]
fov = 35
[[light]]
type = "environment"
file = "sky.exr"
scale = 2
[materials.white]
bsdf = { type = "lambert", color = [1, 1, 1] }
[[object]]
shape = "sphere"
radius = 1
material = "white"
"#;
    let scene = parse_scene(&dir.path().join("env.toml"), text).unwrap();
    let m = mean(&render(&scene, &|_, _| {}));
    assert!((m - Vec3::ONE).abs().max_element() < 3e-3, "mean {m}");
}

/// The per-path tracer (cornell-rough) and the lanes (the Lambertian Cornell box, where the
/// processor has AVX2 or AVX-512).
#[test]
fn path_traced_images_do_not_depend_on_the_thread_count() {
    for name in ["cornell-rough", "cornell-box"] {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../../scenes/{name}.toml"));
        let mut scene = alhazen_scene::load_scene(&path).unwrap();
        scene.render.width = 48;
        scene.render.height = 48;
        scene.render.spp = 8;
        let at = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| render(&scene, &|_, _| {}))
        };
        let one = at(1);
        assert_eq!(one, at(2), "{name}");
        assert_eq!(one, at(3), "{name}");
    }
}

#[test]
fn the_prism_spreads_white_light_into_a_spectrum() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/prism.toml");
    let mut scene = alhazen_scene::load_scene(&path).unwrap();
    scene.render.width = 160;
    scene.render.height = 120;
    scene.render.spp = 16;
    let img = render(&scene, &|_, _| {});
    // Bright pixels whose colour is dominated by red, by green and by blue all appear, and
    // along the band's rows red lies to the left of blue (the deviation grows with the index).
    let (mut red, mut green, mut blue) = (vec![], vec![], vec![]);
    for y in 0..img.height {
        for x in 0..img.width {
            let c = img.get(x, y);
            if c.max_element() < 0.3 {
                continue;
            }
            let s = c / c.element_sum();
            if s.x > 0.6 {
                red.push(x);
            } else if s.y > 0.5 {
                green.push(x);
            } else if s.z > 0.6 {
                blue.push(x);
            }
        }
    }
    assert!(red.len() > 20 && green.len() > 20 && blue.len() > 20, "{} {} {}", red.len(), green.len(), blue.len());
    let avg = |v: &[u32]| v.iter().map(|&x| x as f64).sum::<f64>() / v.len() as f64;
    assert!(avg(&red) < avg(&green) && avg(&green) < avg(&blue), "{} {} {}", avg(&red), avg(&green), avg(&blue));
}

#[test]
fn a_mirrored_emitter_keeps_shining_from_its_front() {
    // The Cornell box's lamp mirrored in x (a transform of negative determinant, as imported
    // scenes often have) is the same lamp: the box must be lit the same, not from the ceiling.
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-box.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let lamp = "[[0.23, 0, 0, 0], [0, 0, -0.19, 0.99]";
    assert!(text.contains(lamp));
    let mirrored = text.replace(lamp, "[[-0.23, 0, 0, 0], [0, 0, -0.19, 0.99]");
    let image = |t: &str| {
        let mut s = parse_scene(&path, t).unwrap();
        (s.render.width, s.render.height, s.render.spp) = (64, 64, 16);
        mean(&render(&s, &|_, _| {}))
    };
    let (a, b) = (image(&text), image(&mirrored));
    assert!(((a - b) / a).abs().max_element() < 0.03, "{a} vs {b}");
}

/// A disk lamp scaled by its transform is the disk of the scaled radius: the floor is lit the
/// same. (Its normal, mapped by the transform's inverse transpose, was left at the inverse
/// scale's length: a lamp at half scale sampled points beyond its rim, 59 % too bright
/// against Mitsuba 3.)
#[test]
fn a_scaled_disk_lamp_lights_as_its_own_radius() {
    let scene = |disk: &str| {
        format!(
            r#"
background = [0, 0, 0]
[render]
width = 48
height = 36
spp = 64
integrator = "path"
[camera]
eye = [0, 2.5, 5]
target = [0, 0.3, 0]
fov = 45
[[object]]
shape = "rectangle"
transform = [{{ scale = 4 }}, {{ rotate_x = -90 }}]
material = {{ color = [0.7, 0.6, 0.5] }}
[[object]]
shape = "disk"
material = {{ emission = [6, 6, 6] }}
{disk}
"#
        )
    };
    let image = |disk: &str| mean(&render(&parse_scene("disk.toml".as_ref(), &scene(disk)).unwrap(), &|_, _| {}));
    let plain = image("center = [-0.3, 1.8, -0.2]\nnormal = [0.3, -1, 0]\nradius = 0.4");
    let scaled =
        image("normal = [0.3, -1, 0]\nradius = 1.6\ntransform = [{ scale = 0.25 }, { translate = [-0.3, 1.8, -0.2] }]");
    assert!(plain.x > 0.01, "the floor is lit: {plain}");
    assert!(((plain - scaled) / plain).abs().max_element() < 0.03, "{plain} vs {scaled}");
}

/// A one-sided material is black from behind and ends the paths that reach its back; two-sided
/// (the default), both faces are shaded alike. A disk lit and seen from below, facing down
/// (its front) or up (its back).
#[test]
fn one_sided_surfaces_are_black_from_behind() {
    let scene = |one_sided: bool, normal_y: f64| {
        let text = format!(
            r#"
[render]
width = 4
height = 4
spp = 16
max_depth = 3
integrator = "path"
[camera]
type = "orthographic"
eye = [0, -2, 0]
target = [0, 0, 0]
up = [0, 0, 1]
width = 0.5
[[light]]
type = "point"
position = [0, -3, 0]
intensity = 10
[materials.card]
color = 0.8
one_sided = {one_sided}
[[object]]
shape = "disk"
center = [0, 0, 0]
normal = [0, {normal_y}, 0]
radius = 1
material = "card"
"#
        );
        let scene = parse_scene("card.toml".as_ref(), &text).unwrap();
        mean(&render(&scene, &|_, _| {})).x
    };
    let front = scene(true, -1.0);
    assert!(front > 0.1, "the front is lit: {front}");
    assert_eq!(scene(true, 1.0), 0.0, "one-sided, the back is black");
    assert_eq!(scene(false, -1.0), front, "the front does not depend on the flag");
    assert_eq!(scene(false, 1.0), front, "two-sided, the back is shaded as the front");
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(64))]
    /// A point that sees an area light's front, however grazing (down to a cosine of 0.02 at
    /// the light), finds every light point it samples unshadowed by the light itself: its shadow
    /// segment is aimed from its moved origin at the point (aimed along the sampled direction,
    /// it cut the light's plane short of the point: a floor beside a tilted lamp went dark).
    #[test]
    fn shadow_segments_reach_their_light_at_grazing_angles(
        tilt in -80.0..80.0f64, turn in 0.0..360.0f64, (sx, sy) in (0.2..3.0f64, 0.2..3.0f64),
        along in -6.0..6.0f64, across in -6.0..6.0f64, cos_light in 0.02..0.3f64, far in 0.5..8.0f64,
        (nx, ny, nz) in (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64), u in (0.0..1.0f64, 0.0..1.0f64),
    ) {
        let text = format!(
            r#"
[materials.lamp]
emission = [1, 1, 1]
[[object]]
shape = "rectangle"
material = "lamp"
transform = [{{ scale = [{sx}, {sy}, 1] }}, {{ rotate_x = {tilt} }}, {{ rotate_y = {turn} }}, {{ translate = [0.3, 1.2, -0.7] }}]
"#
        );
        let scene = parse_scene("lamp.toml".as_ref(), &text).unwrap();
        let (world, lights) = (alhazen_render::world::World::build(&scene), alhazen_render::lights::Lights::build(&scene));
        let o = &scene.objects[0].transform;
        let (centre, normal) = (o.point(Vec3::ZERO), o.normal(Vec3::Z).normalize());
        let (s, t) = alhazen_math::orthonormal_basis(normal);
        // A point seen from the light's centre at `cos_light` off its plane, `far` away.
        let side = (s * along + t * across).normalize_or(s);
        let sin = (1.0 - cos_light * cos_light).sqrt();
        let p = centre + (side * sin + normal * cos_light) * (far + sx.max(sy));
        let ls = lights.sample(p, 0.5, alhazen_math::Vec2::new(u.0, u.1));
        proptest::prop_assume!(ls.is_some());
        let ls = ls.unwrap();
        // A receiving surface whose normal faces the light point.
        let ng = Vec3::new(nx, ny, nz).normalize_or(ls.dir);
        let ng = if ng.dot(ls.dir) < 0.0 { -ng } else { ng };
        let (origin, dir, dist) = alhazen_render::path::shadow_segment(p, ng, ls.dir, ls.dist, p);
        proptest::prop_assert!(world.unoccluded(origin, dir, dist), "p {p}, dir {}, cos at the light {}", ls.dir, -normal.dot(ls.dir));
    }
}

/// A floor seen from low down under a lamp of material `lamp` (black, emitting), with `more`
/// objects (TOML).
fn under_a_lamp(lamp: &str, more: &str) -> alhazen_scene::Scene {
    let text = format!(
        r#"
[render]
width = 32
height = 32
spp = 64
max_depth = 3
integrator = "path"
[camera]
eye = [0, 0.6, 3.5]
target = [0, 0, 0]
fov = 50
[materials.floor]
color = 0.8
[materials.lamp]
color = 0
{lamp}
[[object]]
shape = "plane"
material = "floor"
{more}"#
    );
    parse_scene("lamp.toml".as_ref(), &text).unwrap()
}

/// A lamp half cut out (a coverage of 0.5, each ray's passage decided by its hash) lights a
/// floor as a lamp of half the radiance does: light samples drawn on it send half its radiance,
/// as rays that hit it see on average; the path and Whitted tracers alike. (Sent whole, the
/// image came out 1.41 times too bright.) The lamp is black: a half-present lamp reflects half.
#[test]
fn a_cut_out_lamp_sends_the_light_of_what_is_left() {
    let rectangle = "[[object]]\nshape = \"rectangle\"\nmaterial = \"lamp\"\n\
                     transform = [{ rotate_x = 90 }, { translate = [0, 1, 0] }]\n";
    let (mut cut, mut half) =
        (under_a_lamp("emission = 4\nalpha = 0.5", rectangle), under_a_lamp("emission = 2", rectangle));
    for integrator in [alhazen_scene::IntegratorKind::Path, alhazen_scene::IntegratorKind::Whitted] {
        (cut.render.integrator, half.render.integrator) = (integrator, integrator);
        let (a, b) = (mean(&render(&cut, &|_, _| {})), mean(&render(&half, &|_, _| {})));
        assert!(b.x > 0.05, "{integrator:?}: lit {b}");
        assert!(((a - b) / b).abs().max_element() < 0.03, "{integrator:?}: cut {a} against half {b}");
    }
}

/// A lamp without texture coordinates, cut out by a fine checker (half of it holes, by a
/// cutoff), lights a floor as a whole lamp of half the radiance: its light samples read the
/// coverage at the triangles' barycentrics, where its ray tests read it. (They read (0, 0),
/// a present square, everywhere: 1.5 times too bright.)
#[test]
fn a_cut_out_lamp_without_texture_coordinates_reads_its_barycentrics() {
    let positions = vec![Vec3::new(-0.5, 1.0, -0.5), Vec3::new(0.5, 1.0, -0.5), Vec3::new(0.0, 1.0, 0.5)];
    let lamp = alhazen_geom::TriangleMesh::new(positions, vec![[0, 1, 2]]).unwrap();
    let mut cut = under_a_lamp("emission = 4", "");
    cut.meshes.push(std::sync::Arc::new(lamp));
    let lamp_material = cut.materials.iter().position(|m| m.name == "lamp").unwrap() as u32;
    cut.objects.push(alhazen_scene::Object {
        name: None,
        shape: alhazen_scene::Shape::Mesh { mesh: cut.meshes.len() - 1, smooth: false },
        transform: alhazen_math::Transform::IDENTITY,
        material: lamp_material,
        mesh_materials: vec![],
    });
    let mut half = cut.clone();
    half.materials[lamp_material as usize].emission = Vec3::splat(2.0);
    let coverage = alhazen_scene::Texture::Checker { even: Vec3::ONE, odd: Vec3::ZERO, size: 0.02 };
    cut.materials[lamp_material as usize].alpha = Some(alhazen_scene::Alpha { coverage, cutoff: Some(0.5) });
    let (a, b) = (mean(&render(&cut, &|_, _| {})), mean(&render(&half, &|_, _| {})));
    assert!(b.x > 0.01, "lit {b}");
    assert!(((a - b) / b).abs().max_element() < 0.03, "cut {a} against half {b}");
}
