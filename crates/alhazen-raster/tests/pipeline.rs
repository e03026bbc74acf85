//! The raster pipeline against the ray tracer: same scene, same camera, same local lighting
//! model, no reflections and no shadows in view — the images must agree up to tessellation.

use alhazen_math::Vec3;
use alhazen_raster::pipeline::{RasterOptions, Shading, render_scene};
use alhazen_scene::parse_scene;

const SCENE: &str = r#"
background = [0.1, 0.12, 0.2]
ambient = 0.1
[render]
width = 160
height = 120
spp = 1
[camera]
eye = [0, 1.5, 6]
target = [0, 0.5, 0]
fov = 50
[[light]]
type = "point"
position = [2, 6, 8]
intensity = 0.9
[[light]]
type = "directional"
direction = [-0.3, -0.4, -1]
intensity = 0.3
[materials.red]
color = [0.8, 0.2, 0.15]
specular = 0.5
shininess = 40
[materials.blue]
color = [0.2, 0.3, 0.8]
specular = 0.3
shininess = 20
highlight = "blinn-phong"
[materials.checks]
color = { checker = { even = 0.8, odd = 0.3, size = 0.5 } }
[[object]]
shape = "sphere"
center = [-1.2, 0.8, 0]
radius = 0.8
material = "red"
[[object]]
shape = "box"
min = [0.4, 0, -0.6]
max = [1.8, 1.2, 0.6]
material = "blue"
transform = [{ rotate_y = 20 }]
[[object]]
shape = "disk"
center = [0, 0, 0]
normal = [0, 1, 0]
radius = 3
material = "checks"
"#;

fn mean_abs(a: &[[f32; 3]], b: &[[f32; 3]]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (0..3).map(|k| (x[k] - y[k]).abs() as f64).sum::<f64>() / 3.0).sum::<f64>()
        / a.len() as f64
}

/// Mean absolute difference per channel, relative to the ray tracer's mean brightness.
fn relative_error(fb: &alhazen_raster::pipeline::Framebuffer, traced: &alhazen_render::Image) -> f64 {
    let mean: f64 =
        traced.pixels.iter().map(|p| (p[0] + p[1] + p[2]) as f64 / 3.0).sum::<f64>() / traced.pixels.len() as f64;
    mean_abs(&fb.color, &traced.pixels) / mean
}

#[test]
fn raster_preview_agrees_with_the_ray_tracer_with_shadow_maps() {
    // Both lights cast shadows on the disk: shadow maps against shadow rays.
    let scene = parse_scene("agree.toml".as_ref(), SCENE).unwrap();
    let traced = alhazen_render::render(&scene, &|_, _| {});
    for shading in [Shading::Phong, Shading::Gouraud, Shading::Flat] {
        let (fb, stats) = render_scene(&scene, &RasterOptions { shading, ..Default::default() }).unwrap();
        assert!(stats.culled > 0 && stats.drawn > 0);
        let err = relative_error(&fb, &traced);
        eprintln!("{shading:?}: mean absolute difference {:.2} % of the mean brightness", err * 100.0);
        let limit = match shading {
            Shading::Phong => 0.01,
            Shading::Gouraud => 0.03,
            Shading::Flat => 0.05,
        };
        assert!(err < limit, "{shading:?}: mean error {:.2} % of the mean brightness", err * 100.0);
    }
}

#[test]
fn depth_buffer_keeps_the_nearest_surface() {
    let scene = parse_scene("agree.toml".as_ref(), SCENE).unwrap();
    let (fb, _) = render_scene(&scene, &RasterOptions::default()).unwrap();
    // Through the sphere's centre the disk lies behind the sphere: the sphere (red) must win,
    // whatever order the triangles were drawn in.
    let (x, y) = (50u32, 56u32);
    let c = fb.color[(y * 160 + x) as usize];
    assert!(c[0] > 2.0 * c[1] && c[0] > 2.0 * c[2], "{c:?}");
    assert!(fb.depth[(y * 160 + x) as usize].is_finite());
    // Background pixels keep an infinite depth and the background colour.
    assert!(fb.depth[0].is_infinite());
    assert!((fb.color[0][2] - 0.2).abs() < 1e-6);
}

#[test]
fn stereo_and_panorama_previews_agree_with_the_ray_tracer() {
    // The same scene through a stereo pair (side by side) and a 200° panorama: the preview's
    // two views and its cube map resampled against the ray tracer's cameras.
    let cameras = [
        "[camera]\ntype = \"stereo\"\neye = [0, 1.5, 6]\ntarget = [0, 0.5, 0]\neye_distance = 0.3\nscreen_distance = 6\nscreen_width = 7",
        "[camera]\ntype = \"panorama\"\neye = [0, 1.5, 6]\ntarget = [0, 0.5, 0]\nfov = 200",
    ];
    for camera in cameras {
        let text = SCENE.replace("[camera]\neye = [0, 1.5, 6]\ntarget = [0, 0.5, 0]\nfov = 50", camera);
        let scene = parse_scene("cameras.toml".as_ref(), &text).unwrap();
        let traced = alhazen_render::render(&scene, &|_, _| {});
        let (fb, _) = render_scene(&scene, &RasterOptions::default()).unwrap();
        assert_eq!((fb.width, fb.height), (traced.width, traced.height), "{camera}");
        let err = relative_error(&fb, &traced);
        eprintln!("{camera}: mean absolute difference {:.2} % of the mean brightness", err * 100.0);
        assert!(err < 0.03, "{camera}: mean error {:.2} % of the mean brightness", err * 100.0);
    }
    // The anaglyph: red from the left view, green and blue from the right.
    let text = SCENE.replace("[camera]\neye = [0, 1.5, 6]\ntarget = [0, 0.5, 0]\nfov = 50", cameras[0]);
    let scene = parse_scene("cameras.toml".as_ref(), &text).unwrap();
    let (pair, _) = render_scene(&scene, &RasterOptions::default()).unwrap();
    let (ana, _) = render_scene(&scene, &RasterOptions { anaglyph: true, ..Default::default() }).unwrap();
    assert_eq!((ana.width, ana.height), (pair.width / 2, pair.height));
    let (x, y) = (40, 70);
    let k = (y * ana.width + x) as usize;
    assert_eq!(ana.color[k][0], pair.color[(y * pair.width + x) as usize][0]);
    assert_eq!(ana.color[k][1], pair.color[(y * pair.width + x + ana.width) as usize][1]);
}

#[test]
fn orthographic_camera_and_wireframe_render() {
    let text = SCENE
        .replace("eye = [0, 1.5, 6]", "type = \"orthographic\"\nwidth = 6\neye = [0, 1.5, 6]")
        .replace("fov = 50", "");
    let scene = parse_scene("o.toml".as_ref(), &text).unwrap();
    let (fb, _) = render_scene(&scene, &RasterOptions { wireframe: true, ..Default::default() }).unwrap();
    let white = fb.color.iter().filter(|c| **c == [1.0, 1.0, 1.0]).count();
    assert!(white > 100, "edges drawn: {white}");
    let lit = fb.color.iter().filter(|c| Vec3::new(c[0] as f64, c[1] as f64, c[2] as f64).length() > 0.3).count();
    assert!(lit > 1000);
}

#[test]
fn image_based_light_agrees_with_the_path_tracer_on_a_convex_object() {
    // A Lambertian sphere under a sky with a dark ground: nothing occludes a convex object from
    // its environment, so the path tracer's answer is exactly ρ/π times the irradiance, which the
    // preview approximates by nine coefficients.
    let text = r#"
background = { zenith = [0.3, 0.5, 1.0], horizon = [1, 0.95, 0.9], ground = [0.15, 0.1, 0.05] }
[render]
width = 64
height = 64
spp = 64
max_depth = 2
integrator = "path"
[camera]
eye = [0, 1, 4]
target = [0, 0, 0]
fov = 35
[materials.white]
color = 0.8
bsdf = { type = "lambert" }
[[object]]
shape = "sphere"
radius = 1
material = "white"
"#;
    let scene = parse_scene("ibl.toml".as_ref(), text).unwrap();
    let traced = alhazen_render::render(&scene, &|_, _| {});
    let opts = RasterOptions { ibl: true, shadows: false, ..Default::default() };
    let (fb, _) = render_scene(&scene, &opts).unwrap();
    // Compare on the sphere only (the background is the same function in both).
    let (mut diff, mut sum, mut n) = (0.0, 0.0, 0);
    for (k, d) in fb.depth.iter().enumerate() {
        if d.is_finite() {
            let (a, b) = (fb.color[k], traced.pixels[k]);
            diff += (0..3).map(|c| (a[c] - b[c]).abs() as f64).sum::<f64>();
            sum += (0..3).map(|c| b[c] as f64).sum::<f64>();
            n += 1;
        }
    }
    assert!(n > 500);
    let err = diff / sum;
    eprintln!("IBL: mean absolute difference {:.2} % on the sphere", err * 100.0);
    assert!(err < 0.04, "{:.2} %", err * 100.0);
}

#[test]
fn cull_planes_drop_whole_triangles_and_clip_planes_cut_them() {
    let scene = parse_scene("agree.toml".as_ref(), SCENE).unwrap();
    let (_, plain) = render_scene(&scene, &RasterOptions::default()).unwrap();
    // Everything with x < 0 (the red sphere) culled whole.
    let cull = RasterOptions { cull_planes: vec![alhazen_math::Vec4::new(1.0, 0.0, 0.0, 0.0)], ..Default::default() };
    let (fb, stats) = render_scene(&scene, &cull).unwrap();
    assert!(stats.culled > plain.culled + 500, "{} vs {}", stats.culled, plain.culled);
    let red = |fb: &alhazen_raster::pipeline::Framebuffer| {
        fb.color.iter().filter(|c| c[0] > 2.0 * c[1] && c[0] > 0.2).count()
    };
    assert!(red(&fb) == 0, "the red sphere is gone");
    // A clip plane through the sphere's centre keeps part of it.
    let clip = RasterOptions { clip_planes: vec![alhazen_math::Vec4::new(0.0, 1.0, 0.0, -0.8)], ..Default::default() };
    let (half, _) = render_scene(&scene, &clip).unwrap();
    let (all, cut) = (red(&render_scene(&scene, &RasterOptions::default()).unwrap().0), red(&half));
    assert!(cut > 0 && cut < all, "{cut} of {all}");
}

#[test]
fn bsp_painter_draws_what_the_z_buffer_draws() {
    use alhazen_raster::pipeline::Visibility;
    let scene = parse_scene("agree.toml".as_ref(), SCENE).unwrap();
    let z = render_scene(&scene, &RasterOptions::default()).unwrap().0;
    let opts = RasterOptions { visibility: Visibility::Bsp, ..Default::default() };
    let (painted, _) = render_scene(&scene, &opts).unwrap();
    let differ = z.color.iter().zip(&painted.color).filter(|(a, b)| (0..3).any(|k| (a[k] - b[k]).abs() > 1e-3)).count();
    // Only pixels on silhouettes may differ (a split triangle's pieces cover them slightly
    // differently from the whole).
    assert!(differ * 200 < z.color.len(), "{differ} of {} pixels differ", z.color.len());
}

#[test]
fn bsp_tree_partitions_the_scene() {
    use alhazen_raster::pipeline::bsp::{BspTree, Viewer};
    use alhazen_raster::pipeline::geometry::scene_triangles;
    let scene = parse_scene("agree.toml".as_ref(), SCENE).unwrap();
    let tris = scene_triangles(&scene).triangles;
    let tree = BspTree::build(&tris, 1e-9);
    assert!(tree.is_consistent(1e-7));
    assert!(tree.len() >= tris.len() - tris.len() / 10, "{} of {}", tree.len(), tris.len());
    // Every triangle is painted exactly once, from any viewpoint.
    for eye in [Vec3::new(0.0, 1.5, 6.0), Vec3::new(-5.0, 0.2, -3.0), Vec3::new(0.0, 10.0, 0.1)] {
        let mut order = tree.back_to_front(Viewer::At(eye));
        assert_eq!(order.len(), tree.len());
        order.sort();
        order.dedup();
        assert_eq!(order.len(), tree.len());
    }
}

#[test]
fn bsp_tree_of_a_convex_mesh_is_not_a_chain() {
    use alhazen_raster::pipeline::bsp::{BspTree, Viewer};
    use alhazen_raster::pipeline::geometry::scene_triangles;
    // Every face of a tessellated sphere lies behind every other face's plane: with triangle
    // planes alone the tree is a chain as deep as the mesh (and quadratic to build).
    let text = "[camera]\neye = [0, 0, 5]\ntarget = [0, 0, 0]\n[[object]]\nshape = \"sphere\"\nradius = 1\n";
    let scene = parse_scene("sphere.toml".as_ref(), text).unwrap();
    let tris = scene_triangles(&scene).triangles;
    assert!(tris.len() > 2000);
    let tree = BspTree::build(&tris, 1e-9);
    assert!(tree.is_consistent(1e-7));
    assert!(tree.depth() < tris.len() / 4, "depth {} for {} triangles", tree.depth(), tris.len());
    assert!(tree.len() < tris.len() * 3 / 2, "{} pieces of {} triangles", tree.len(), tris.len());
    let mut order = tree.back_to_front(Viewer::At(Vec3::new(0.3, 0.2, 5.0)));
    order.sort();
    order.dedup();
    assert_eq!(order.len(), tree.len());
}

#[test]
fn stencil_shadow_volumes_agree_with_the_ray_tracer() {
    use alhazen_raster::pipeline::ShadowMethod;
    use alhazen_raster::pipeline::stencil::StencilMode;
    let scene = parse_scene("agree.toml".as_ref(), SCENE).unwrap();
    let traced = alhazen_render::render(&scene, &|_, _| {});
    for mode in [StencilMode::DepthPass, StencilMode::DepthFail] {
        let opts = RasterOptions { shadow_method: ShadowMethod::Volumes(mode), ..Default::default() };
        let err = relative_error(&render_scene(&scene, &opts).unwrap().0, &traced);
        eprintln!("{mode:?}: {:.2} %", err * 100.0);
        assert!(err < 0.01, "{mode:?}: {:.2} %", err * 100.0);
    }
}

#[test]
fn depth_fail_stays_right_when_the_eye_is_in_a_shadow() {
    use alhazen_raster::pipeline::ShadowMethod;
    use alhazen_raster::pipeline::stencil::StencilMode;
    // The eye sits under a lit slab, inside its shadow volume, looking at the shadowed floor.
    let text = r#"
ambient = 0.1
[render]
width = 64
height = 48
spp = 1
[camera]
eye = [0, 1, 0.5]
target = [0, 0, -1.5]
fov = 60
[[light]]
type = "point"
position = [0, 8, 0]
[[object]]
shape = "box"
min = [-3, 2, -3]
max = [3, 2.3, 3]
[[object]]
shape = "disk"
radius = 20
"#;
    let scene = parse_scene("inside.toml".as_ref(), text).unwrap();
    let traced = alhazen_render::render(&scene, &|_, _| {});
    let err = |mode| {
        let opts = RasterOptions { shadow_method: ShadowMethod::Volumes(mode), ..Default::default() };
        relative_error(&render_scene(&scene, &opts).unwrap().0, &traced)
    };
    let (pass, fail) = (err(StencilMode::DepthPass), err(StencilMode::DepthFail));
    eprintln!("eye in shadow: depth pass {:.1} %, depth fail {:.1} %", pass * 100.0, fail * 100.0);
    assert!(fail < 0.01, "depth fail: {:.2} %", fail * 100.0);
    assert!(pass > 10.0 * fail.max(1e-3), "depth pass should break here: {:.2} %", pass * 100.0);
}

#[test]
fn bump_mapping_agrees_with_the_ray_tracer() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/bumps.toml");
    let mut scene = alhazen_scene::load_scene(&path).unwrap();
    scene.render.width = 160;
    scene.render.height = 108;
    scene.render.spp = 1;
    let traced = alhazen_render::render(&scene, &|_, _| {});
    let err = relative_error(&render_scene(&scene, &RasterOptions::default()).unwrap().0, &traced);
    // Without the bumps, the difference is far larger: the pattern is really there.
    let mut flat = scene.clone();
    flat.materials.iter_mut().for_each(|m| m.bump = None);
    let flat_err = relative_error(&render_scene(&flat, &RasterOptions::default()).unwrap().0, &traced);
    eprintln!("bumps: {:.2} % (against flat: {:.2} %)", err * 100.0, flat_err * 100.0);
    assert!(err < 0.03 && flat_err > 2.0 * err, "{:.2} % vs {:.2} %", err * 100.0, flat_err * 100.0);
}

#[test]
fn hemispherical_lighting_blends_sky_and_ground_by_the_normal() {
    use alhazen_raster::pipeline::shade::{Lighting, lighting};
    let text = "background = { zenith = [0.2, 0.4, 1.0], horizon = [0.5, 0.5, 0.5], ground = [0.3, 0.2, 0.1] }\n";
    let scene = parse_scene("h.toml".as_ref(), text).unwrap();
    let (sky, ground) = (Vec3::new(0.2, 0.4, 1.0), Vec3::new(0.3, 0.2, 0.1));
    let extra = Lighting { hemisphere: Some((sky, ground)), ..Default::default() };
    let m = &scene.materials[0];
    let at = |n: Vec3| lighting(&scene, m, Vec3::ZERO, n, n, &extra).0;
    assert!((at(Vec3::Y) - sky).length() < 1e-12);
    assert!((at(-Vec3::Y) - ground).length() < 1e-12);
    assert!((at(Vec3::X) - (sky + ground) / 2.0).length() < 1e-12);
}

#[test]
fn the_course_anisotropic_highlight() {
    let scene = parse_scene("a.toml".as_ref(), "[materials.brushed]\nspecular = 1\nshininess = 20\nhighlight = \"blinn-phong\"\nanisotropy = 0.2\nscratches = [1, 0, 0]\n").unwrap();
    let m = scene.materials.iter().find(|m| m.name == "brushed").unwrap();
    let iso = alhazen_scene::Material { anisotropy: 1.0, ..m.clone() };
    let (n, l) = (Vec3::Z, Vec3::new(0.0, 0.0, 1.0));
    // With a = 1 the formula is Blinn–Phong's ⟨h, n⟩^{2m}.
    let v = Vec3::new(0.3, 0.2, 1.0).normalize();
    let h = (l + v).normalize();
    assert!((iso.highlight(n, l, v) - h.z.powf(40.0)).abs() < 1e-12);
    // a scales the half vector's component across the scratches: tilting v across them moves the
    // highlight less than tilting it along them (the highlight is stretched across).
    let along = m.highlight(n, l, Vec3::new(0.3, 0.0, 1.0).normalize());
    let across = m.highlight(n, l, Vec3::new(0.0, 0.3, 1.0).normalize());
    assert!(across > 1.3 * along, "{along} {across}");
    assert!(
        (iso.highlight(n, l, Vec3::new(0.3, 0.0, 1.0).normalize())
            - iso.highlight(n, l, Vec3::new(0.0, 0.3, 1.0).normalize()))
        .abs()
            < 1e-12
    );
}

#[test]
fn axonometric_views_agree_with_the_ray_tracer() {
    for style in ["isometric", "cavalier", "cabinet", "military"] {
        let camera =
            format!("[camera]\ntype = \"axonometric\"\nstyle = \"{style}\"\ntarget = [0, 0.5, 0]\nwidth = 7\n");
        let start = SCENE.find("[camera]").unwrap();
        let end = SCENE.find("[[light]]").unwrap();
        let text = format!("{}{}{}", &SCENE[..start], camera, &SCENE[end..]);
        let scene = parse_scene("axo.toml".as_ref(), &text).unwrap();
        let traced = alhazen_render::render(&scene, &|_, _| {});
        let err = relative_error(&render_scene(&scene, &RasterOptions::default()).unwrap().0, &traced);
        assert!(err < 0.01, "{style}: {:.2} %", err * 100.0);
    }
}

#[test]
fn preparation_builds_only_what_is_asked_and_widens_to_serve_more() {
    use alhazen_raster::pipeline::{ShadowMethod, Visibility, prepare, render_prepared, stencil::StencilMode};
    let scene = parse_scene("s.toml".as_ref(), SCENE).unwrap();
    let plain = RasterOptions { shadows: false, ..Default::default() };
    let prepared = prepare(&scene, &plain);
    assert!(prepared.shadows.is_none() && prepared.ibl.is_none() && prepared.bsp.is_none());
    let ibl = RasterOptions { ibl: true, ..Default::default() };
    let bsp = RasterOptions { visibility: Visibility::Bsp, ..plain.clone() };
    let volumes = RasterOptions { shadow_method: ShadowMethod::Volumes(StencilMode::DepthPass), ..Default::default() };
    assert!(!prepared.serves(&ibl) && !prepared.serves(&bsp) && prepared.serves(&volumes));
    let mut wide = plain.clone();
    for o in [&ibl, &bsp, &volumes] {
        wide.prepare_also(o);
    }
    let widened = prepare(&scene, &wide);
    for o in [&plain, &ibl, &bsp, &volumes] {
        assert!(widened.serves(o));
        // What was prepared beyond the options does not change the frame.
        let (a, _) = render_prepared(&scene, &widened, o).unwrap();
        let (b, _) = render_scene(&scene, o).unwrap();
        assert_eq!(a.color, b.color);
    }
}

/// An open mesh is seen from both sides (issue 21: every mesh was taken as closed and its faces
/// turned away were culled, so a sail vanished): closedness is measured from the edges.
#[test]
fn open_meshes_are_seen_from_behind() {
    let dir = tempfile::tempdir().unwrap();
    // One triangle whose front faces away from the camera (it looks down −z, the camera is at +z).
    std::fs::write(dir.path().join("sail.obj"), "v -1 -1 0\nv 0 1 0\nv 1 -1 0\nf 1 2 3\n").unwrap();
    let text = "ambient = 0.5\nbackground = [0, 0, 0]\n[render]\nwidth = 16\nheight = 16\n\
        [camera]\ntype = \"orthographic\"\neye = [0, 0, 5]\nwidth = 3\n\
        [[object]]\nshape = \"mesh\"\nfile = \"sail.obj\"\nmaterial = { color = 1 }\n";
    let path = dir.path().join("sail.toml");
    std::fs::write(&path, text).unwrap();
    let scene = alhazen_scene::load_scene(&path).unwrap();
    assert!(!scene.meshes[0].is_closed());
    let (fb, _) = render_scene(&scene, &RasterOptions::default()).unwrap();
    let centre = fb.color[(8 * 16 + 8) as usize];
    assert!(centre[0] > 0.1, "the back of an open mesh is drawn: {centre:?}");
}

#[test]
fn an_unbounded_plane_is_lit_per_pixel_whatever_the_shading() {
    // A plane's triangles reach far past the view, so flat shading (lit at the centroid) made
    // the floor black and Gouraud (lit at the corners) lost its shadows. The floor must agree
    // with the ray tracer under every shading, shadows included.
    let text = SCENE.replace(
        "shape = \"disk\"\ncenter = [0, 0, 0]\nnormal = [0, 1, 0]\nradius = 3",
        "shape = \"plane\"\npoint = [0, 0, 0]\nnormal = [0, 1, 0]",
    );
    assert_ne!(text, SCENE);
    let scene = parse_scene("plane.toml".as_ref(), &text).unwrap();
    let traced = alhazen_render::render(&scene, &|_, _| {});
    // Floor pixels only: the bottom rows, below every object.
    let rows = 100..120usize;
    let floor =
        |c: &[[f32; 3]]| -> Vec<[f32; 3]> { rows.clone().flat_map(|y| c[y * 160..(y + 1) * 160].to_vec()).collect() };
    let reference = floor(&traced.pixels);
    let brightness = reference.iter().map(|p| (p[0] + p[1] + p[2]) as f64 / 3.0).sum::<f64>() / reference.len() as f64;
    assert!(brightness > 0.1, "the traced floor is lit: {brightness}");
    for shading in [Shading::Phong, Shading::Gouraud, Shading::Flat] {
        let (fb, _) = render_scene(&scene, &RasterOptions { shading, ..Default::default() }).unwrap();
        let err = mean_abs(&floor(&fb.color), &reference) / brightness;
        eprintln!("{shading:?}: floor differs by {:.2} % of its brightness", err * 100.0);
        assert!(err < 0.02, "{shading:?}: floor differs by {:.2} %", err * 100.0);
    }
}

#[test]
fn the_memory_estimate_counts_every_triangle_drawn() {
    // The estimate counts triangles without tessellating; it must not count fewer than are made.
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let mut checked = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().and_then(|e| e.to_str()) != Some("toml") {
            continue;
        }
        let scene = alhazen_scene::load_scene(&path).unwrap();
        let made = alhazen_raster::pipeline::geometry::scene_triangles(&scene).triangles.len() as u64;
        let counted: u64 =
            scene.objects.iter().map(|o| alhazen_raster::pipeline::geometry::triangle_count(&scene, &o.shape)).sum();
        assert!(counted >= made, "{}: {counted} counted, {made} made", path.display());
        assert!(alhazen_raster::pipeline::memory_estimate(&scene, &RasterOptions::default()) > made * 200);
        checked += 1;
    }
    assert!(checked > 20);
}

#[test]
fn the_preview_is_lit_by_the_cornell_lamp_as_whitted_is() {
    // The lamp is an emitting rectangle: four shadow-mapped lights in the preview, 4 × 4 shadow
    // rays in Whitted; the walls' brightness must agree, the shadows' edges may not (hard vs soft).
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-box.toml");
    let mut scene = alhazen_scene::load_scene(&path).unwrap();
    (scene.render.width, scene.render.height, scene.render.spp) = (64, 64, 16);
    scene.render.integrator = alhazen_scene::IntegratorKind::Whitted;
    let traced = alhazen_render::render(&scene, &|_, _| {});
    let (fb, _) = render_scene(&scene, &RasterOptions::default()).unwrap();
    let err = relative_error(&fb, &traced);
    assert!(err < 0.2, "mean absolute difference {:.1} % of the mean brightness", err * 100.0);
    // Means over the pixels that do not see the lamp (the lamp's edge is sampled differently).
    let lit = |p: &[f32; 3]| p.iter().all(|c| *c < 1.0);
    let (mut r, mut t, mut n) = (0.0, 0.0, 0.0);
    for (a, b) in fb.color.iter().zip(&traced.pixels).filter(|(a, b)| lit(a) && lit(b)) {
        r += (a[0] + a[1] + a[2]) as f64;
        t += (b[0] + b[1] + b[2]) as f64;
        n += 1.0;
    }
    let (r, t) = (r / n, t / n);
    assert!((r - t).abs() < 0.05 * t, "preview mean {r}, Whitted mean {t}");
}

/// The pixels whose four corners all see `object` first (inside its outline, off its edge).
fn inside_outline(scene: &alhazen_scene::Scene, object: u32) -> Vec<(u32, u32)> {
    let (w, h) = (scene.render.width, scene.render.height);
    let world = alhazen_render::World::build(scene);
    let camera = alhazen_render::Camera::new(&scene.camera, w, h);
    let sees =
        |fx: f64, fy: f64| world.intersect(&camera.ray(fx, fy), f64::INFINITY).is_some_and(|h| h.object == object);
    (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            let (fx, fy) = (x as f64, y as f64);
            sees(fx, fy) && sees(fx + 1.0, fy) && sees(fx, fy + 1.0) && sees(fx + 1.0, fy + 1.0)
        })
        .collect()
}

/// Inside a mirror's outline (pixels whose corners all see the mirror first): the mean absolute
/// difference from the ray tracer relative to its mean brightness there, and the same for the
/// preview's old stand-in, the sky in the reflected direction.
fn mirror_error(scene: &alhazen_scene::Scene, mirror: &str) -> (f64, f64) {
    let (w, h) = (scene.render.width, scene.render.height);
    let traced = alhazen_render::render(scene, &|_, _| {});
    let (fb, stats) = render_scene(scene, &RasterOptions::default()).unwrap();
    assert!(stats.reflexes > 0);
    let object = scene.objects.iter().position(|o| o.name.as_deref() == Some(mirror)).unwrap() as u32;
    let world = alhazen_render::World::build(scene);
    let camera = alhazen_render::Camera::new(&scene.camera, w, h);
    let (mut diff, mut sky, mut sum, mut n) = (0.0, 0.0, 0.0, 0.0);
    for (x, y) in inside_outline(scene, object) {
        let ray = camera.ray(x as f64 + 0.5, y as f64 + 0.5);
        let Some(hit) = world.intersect(&ray, f64::INFINITY) else { continue };
        let k = (y * w + x) as usize;
        let (a, b) = (fb.color[k], traced.pixels[k]);
        let nrm = hit.hit.n;
        let r = ray.dir - nrm * (2.0 * ray.dir.dot(nrm));
        let s = scene.sky(r) * 0.9;
        diff += (0..3).map(|c| (a[c] - b[c]).abs() as f64).sum::<f64>() / 3.0;
        sky += (0..3).map(|c| (s[c] - b[c] as f64).abs()).sum::<f64>() / 3.0;
        sum += (b[0] + b[1] + b[2]) as f64 / 3.0;
        n += 1.0;
    }
    assert!(n > 100.0, "the mirror covers {n} pixels");
    (diff / sum, sky / sum)
}

#[test]
fn mirrors_show_in_the_preview_what_the_ray_tracer_shows() {
    // Glaeser's method (every vertex to its reflex, triangles rasterised as their reflexes)
    // against Whitted's reflected rays, inside the ball's outline: the teapot beside it and the
    // checker floor to the horizon.
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/teapot.toml");
    let mut scene = alhazen_scene::load_scene(&path).unwrap();
    (scene.render.width, scene.render.height, scene.render.spp, scene.render.max_depth) = (320, 240, 4, 2);
    scene.render.integrator = alhazen_scene::IntegratorKind::Whitted;
    let (err, sky) = mirror_error(&scene, "mirror ball");
    eprintln!("teapot: mean absolute difference in the mirror {:.2} % (sky only: {:.2} %)", err * 100.0, sky * 100.0);
    assert!(err < 0.09 && err < sky / 4.0, "{err} vs the sky's {sky}");
    // The benchmark scene: the mirror ball shows the glass balls, which the preview draws as
    // flat as it draws them directly; the floor, the red ball and the sky must agree.
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/glass-balls.toml");
    let mut scene = alhazen_scene::load_scene(&path).unwrap();
    (scene.render.width, scene.render.height, scene.render.spp, scene.render.max_depth) = (320, 240, 4, 2);
    scene.render.integrator = alhazen_scene::IntegratorKind::Whitted;
    let (err, sky) = mirror_error(&scene, "mirror ball");
    eprintln!(
        "glass balls: mean absolute difference in the mirror {:.2} % (sky only: {:.2} %)",
        err * 100.0,
        sky * 100.0
    );
    assert!(err < 0.6 * sky, "{err} vs the sky's {sky}");
    let (err, sky) = mirror_error(&scene, "mirror cylinder");
    eprintln!(
        "glass balls' cylinder: mean absolute difference in the mirror {:.2} % (sky only: {:.2} %)",
        err * 100.0,
        sky * 100.0
    );
    assert!(err < 0.6 * sky, "{err} vs the sky's {sky}");
    // A plane mirror (Glaeser's Fig. 3): the scene through the reflected projection.
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/lines/fig3-plane-mirror.toml");
    let mut scene = alhazen_scene::load_scene(&path).unwrap();
    (scene.render.width, scene.render.height, scene.render.spp, scene.render.max_depth) = (320, 240, 4, 2);
    scene.render.integrator = alhazen_scene::IntegratorKind::Whitted;
    let (err, sky) = mirror_error(&scene, "mirror");
    eprintln!(
        "plane mirror: mean absolute difference in the mirror {:.2} % (sky only: {:.2} %)",
        err * 100.0,
        sky * 100.0
    );
    assert!(err < 0.05 && err < sky / 4.0, "{err} vs the sky's {sky}");
}

#[test]
fn a_card_through_a_mirror_ball_shows_without_gaps() {
    // A checkered strip passes through the ball: triangles whose corners lie inside the ball
    // have no reflex there; the pieces along the curve where the strip leaves the ball are
    // drawn up to the surface (each surface point is its own reflex), not left out.
    let text = r#"
background = [0.6, 0.7, 0.9]
ambient = 0.3
[render]
width = 320
height = 240
spp = 4
max_depth = 2
integrator = "whitted"
[camera]
eye = [-0.8, 0.6, 5]
target = [0, 0, 0]
fov = 30
[[light]]
type = "directional"
direction = [-0.3, -1, -0.5]
[[object]]
name = "mirror ball"
shape = "sphere"
radius = 1
material = { color = 0, diffuse = 0, mirror = 0.9 }
[[object]]
shape = "rectangle"
transform = [{ scale = [3, 0.25, 1] }, { rotate_y = 80 }, { translate = [0.4, 0, 0] }]
material = { color = { checker = { even = 0.9, odd = 0.1, size = 0.1 } } }
"#;
    let scene = alhazen_scene::parse_scene("card.toml".as_ref(), text).unwrap();
    let (err, sky) = mirror_error(&scene, "mirror ball");
    eprintln!(
        "card through the ball: mean absolute difference in the mirror {:.2} % (sky only: {:.2} %)",
        err * 100.0,
        sky * 100.0
    );
    assert!(err < 0.005, "{err} (0.86 % with the pieces along the curve left out)");
}

#[test]
fn csg_bodies_show_in_the_preview_as_the_ray_tracer_shows_them() {
    // A box minus a sphere, lit from the eye's side: the per-pixel ray cast against Whitted on
    // the pixels that see the body (its self-shadows are the ray tracer's only).
    let text = r#"
background = [0.2, 0.3, 0.5]
ambient = 0.1
[render]
width = 160
height = 120
spp = 4
max_depth = 1
[camera]
eye = [2.5, 2.5, 4]
target = [0, 0.4, 0]
fov = 40
[[light]]
type = "point"
position = [3, 4, 5]
[[object]]
shape = "disk"
center = [0, 0, 0]
normal = [0, 1, 0]
radius = 4
material = { color = 0.7 }
[[object]]
name = "body"
shape = "csg"
op = "difference"
material = { color = [0.85, 0.3, 0.25], specular = 0.4, shininess = 50 }
transform = [{ rotate_y = 25 }, { translate = [0, 0.7, 0] }]
a = { shape = "box", min = [-0.7, -0.7, -0.7], max = [0.7, 0.7, 0.7] }
b = { shape = "sphere", radius = 0.9 }
"#;
    let mut scene = parse_scene("csg.toml".as_ref(), text).unwrap();
    scene.render.integrator = alhazen_scene::IntegratorKind::Whitted;
    let traced = alhazen_render::render(&scene, &|_, _| {});
    let (fb, stats) = render_scene(&scene, &RasterOptions::default()).unwrap();
    assert_eq!(stats.skipped_objects, 0);
    let (mut diff, mut sum, mut n) = (0.0, 0.0, 0);
    for (x, y) in inside_outline(&scene, 1) {
        let k = (y * 160 + x) as usize;
        diff += (0..3).map(|c| (fb.color[k][c] - traced.pixels[k][c]).abs() as f64).sum::<f64>() / 3.0;
        sum += (0..3).map(|c| traced.pixels[k][c] as f64).sum::<f64>() / 3.0;
        n += 1;
    }
    assert!(n > 300, "the body covers {n} pixels");
    eprintln!("CSG body: mean absolute difference {:.2} % over {n} pixels", 100.0 * diff / sum);
    assert!(diff / sum < 0.05, "{}", diff / sum);
}

#[test]
fn glass_shows_what_lies_behind_it_blended_by_fresnel() {
    // A glass ball before a red wall: its centre shows the wall (transmitted, 1 − F ≈ 0.96 at
    // normal incidence), its rim more of the reflected sky.
    let text = r#"
background = [0.2, 0.3, 0.9]
ambient = 1
[render]
width = 64
height = 64
[camera]
eye = [0, 0, 5]
fov = 30
[[object]]
shape = "sphere"
radius = 0.8
material = { color = 0, diffuse = 0, transparency = 1, ior = 1.5 }
[[object]]
shape = "rectangle"
transform = [{ scale = 3 }, { translate = [0, 0, -2] }]
material = { color = [0.9, 0.1, 0.1] }
"#;
    let scene = parse_scene("glass.toml".as_ref(), text).unwrap();
    let (fb, _) = render_scene(&scene, &RasterOptions::default()).unwrap();
    // At normal incidence F = ((1.5 − 1)/(1.5 + 1))² = 0.04: 0.96 of the wall, 0.04 of the sky.
    let centre = fb.color[32 * 64 + 32];
    let want = [0.96 * 0.9 + 0.04 * 0.2, 0.96 * 0.1 + 0.04 * 0.3, 0.96 * 0.1 + 0.04 * 0.9];
    assert!((0..3).all(|c| (centre[c] as f64 - want[c]).abs() < 2e-3), "{centre:?} vs {want:?}");
}

/// The course's other visibility algorithms against the z-buffer on every scene of `scenes/`
/// and `scenes/cameras/`, with their cameras: the scan-line
/// algorithm and Warnock's area subdivision give its frame and depth bit for bit, the
/// depth-sort painter its frame but on at most one pixel in a thousand.
#[test]
fn the_scanline_warnock_and_depth_sort_algorithms_draw_every_scene_as_the_z_buffer_does() {
    use alhazen_raster::pipeline::Visibility;
    let files = scene_files();
    for path in files {
        let mut scene = alhazen_scene::load_scene(&path).unwrap();
        // A quarter of the size keeps the test short; odd sizes exercise partial bands.
        scene.render.width = (scene.render.width / 4).max(9) | 1;
        scene.render.height = (scene.render.height / 4).max(9) | 1;
        let z = RasterOptions::default();
        let scan = RasterOptions { visibility: Visibility::Scanline, ..Default::default() };
        let prepared = alhazen_raster::pipeline::prepare(&scene, &z);
        let (a, _) = alhazen_raster::pipeline::render_prepared(&scene, &prepared, &z).unwrap();
        let (b, _) = alhazen_raster::pipeline::render_prepared(&scene, &prepared, &scan).unwrap();
        assert!(a.color == b.color && a.depth == b.depth, "{}", path.display());
        let warnock = RasterOptions { visibility: Visibility::Warnock, ..Default::default() };
        let (d, _) = alhazen_raster::pipeline::render_prepared(&scene, &prepared, &warnock).unwrap();
        assert!(a.color == d.color && a.depth == d.depth, "Warnock: {}", path.display());
        let sorted = RasterOptions { visibility: Visibility::DepthSort, ..Default::default() };
        let (c, _) = alhazen_raster::pipeline::render_prepared(&scene, &prepared, &sorted).unwrap();
        let differ = a.color.iter().zip(&c.color).filter(|(p, q)| (0..3).any(|k| (p[k] - q[k]).abs() > 1e-3)).count();
        // Where triangles pierce each other the pieces meet on the exact intersection line,
        // the depth buffer per pixel centre: a pixel may go either way (1 of 16,261 on the
        // swept tube, none elsewhere).
        assert!(differ * 1000 <= a.color.len(), "{}: depth sort differs on {differ} pixels", path.display());
    }
}

/// Every scene of `scenes/` and `scenes/cameras/`.
fn scene_files() -> Vec<std::path::PathBuf> {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let mut files: Vec<_> = std::fs::read_dir(&root)
        .unwrap()
        .chain(std::fs::read_dir(root.join("cameras")).unwrap())
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    assert!(files.len() > 30, "{} scenes", files.len());
    files
}

/// The octree's view-frustum culling leaves every frame as it was, bit for bit (it skips only
/// triangles the clipper drops), and skips some triangles where the view does not hold the
/// whole scene.
#[test]
fn frustum_culling_leaves_every_scene_unchanged() {
    let mut skipped_somewhere = false;
    for path in scene_files() {
        let mut scene = alhazen_scene::load_scene(&path).unwrap();
        scene.render.width = (scene.render.width / 4).max(9) | 1;
        scene.render.height = (scene.render.height / 4).max(9) | 1;
        let culling = RasterOptions::default();
        let all = RasterOptions { frustum_culling: false, ..Default::default() };
        let prepared = alhazen_raster::pipeline::prepare(&scene, &culling);
        let (a, sa) = alhazen_raster::pipeline::render_prepared(&scene, &prepared, &culling).unwrap();
        let (b, sb) = alhazen_raster::pipeline::render_prepared(&scene, &prepared, &all).unwrap();
        assert!(a.color == b.color && a.depth == b.depth, "{}", path.display());
        assert_eq!((sa.drawn, sb.outside), (sb.drawn, 0), "{}", path.display());
        skipped_somewhere |= sa.outside > 0;
    }
    assert!(skipped_somewhere);
}

/// A cut-out (a checker of holes by a cutoff) in a screen before the sphere: the preview
/// leaves out what the ray tracer sees through, in view and in its shadow maps alike.
#[test]
fn cut_outs_agree_with_the_ray_tracer() {
    let text = format!(
        "{SCENE}\n[materials.screen]\ncolor = 0.9\nalpha = 0.5\n[[object]]\nshape = \"rectangle\"\nmaterial = \"screen\"\n\
         transform = [{{ scale = 1.2 }}, {{ translate = [-0.6, 0.9, 1.2] }}]\n"
    );
    let mut scene = parse_scene("cut.toml".as_ref(), &text).unwrap();
    let screen = scene.materials.iter().position(|m| m.name == "screen").unwrap();
    let coverage = alhazen_scene::Texture::Checker { even: Vec3::ONE, odd: Vec3::ZERO, size: 0.25 };
    scene.materials[screen].alpha = Some(alhazen_scene::Alpha { coverage, cutoff: Some(0.5) });
    let traced = alhazen_render::render(&scene, &|_, _| {});
    let (fb, _) = render_scene(&scene, &RasterOptions::default()).unwrap();
    let err = relative_error(&fb, &traced);
    eprintln!("cut-outs: mean absolute difference {:.2} % of the mean brightness", err * 100.0);
    assert!(err < 0.02, "mean error {:.2} % of the mean brightness", err * 100.0);
    // Without the cut-out the screen hides what the holes show.
    scene.materials[screen].alpha = None;
    let (whole, _) = render_scene(&scene, &RasterOptions::default()).unwrap();
    let whole_err = relative_error(&whole, &traced);
    eprintln!("without them: {:.2} %", whole_err * 100.0);
    assert!(whole_err > 2.0 * err.max(0.01), "the holes show nothing");
}

/// A screen whose four corners are painted red, green, blue and white (vertex colours, which
/// its material multiplies its colour by): the preview interpolates them as the ray tracer
/// does; drawn without them it is off.
#[test]
fn vertex_colours_agree_with_the_ray_tracer() {
    let text = format!(
        "{SCENE}\n[materials.screen]\ncolor = 0.9\nvertex_colors = true\n[[object]]\nshape = \"rectangle\"\n\
         material = \"screen\"\ntransform = [{{ scale = 1.2 }}, {{ translate = [-0.6, 0.9, 1.2] }}]\n"
    );
    let mut scene = parse_scene("painted.toml".as_ref(), &text).unwrap();
    let screen = scene.objects.last().unwrap();
    let alhazen_scene::Shape::Mesh { mesh, .. } = screen.shape else { panic!("the rectangle is not a mesh") };
    let corners = [Vec3::X, Vec3::Y, Vec3::Z, Vec3::ONE];
    std::sync::Arc::make_mut(&mut scene.meshes[mesh]).colors = corners.to_vec();
    let traced = alhazen_render::render(&scene, &|_, _| {});
    let (fb, _) = render_scene(&scene, &RasterOptions::default()).unwrap();
    let err = relative_error(&fb, &traced);
    eprintln!("vertex colours: mean absolute difference {:.2} % of the mean brightness", err * 100.0);
    assert!(err < 0.02, "mean error {:.2} % of the mean brightness", err * 100.0);
    std::sync::Arc::make_mut(&mut scene.meshes[mesh]).colors.clear();
    let (plain, _) = render_scene(&scene, &RasterOptions::default()).unwrap();
    let plain_err = relative_error(&plain, &traced);
    eprintln!("without them: {:.2} %", plain_err * 100.0);
    assert!(plain_err > 2.0 * err.max(0.01), "the colours show nothing");
}
