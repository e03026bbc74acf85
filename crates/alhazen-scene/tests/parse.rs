//! The scene reader on real files and on the mistakes users make.

use alhazen_math::Vec3;
use alhazen_scene::{CameraDesc, Light, PerspectiveOpening, Shape, Texture, Wrap, load_scene, parse_scene};
use std::path::Path;

fn err(text: &str) -> String {
    parse_scene("s.toml".as_ref(), text).unwrap_err().to_string()
}

#[test]
fn obj_with_mtl_materials_and_instancing() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/instancing.toml");
    let scene = load_scene(&path).unwrap();
    assert_eq!(scene.meshes.len(), 2, "each mesh is loaded once however often it is used");
    let ico = &scene.meshes[0];
    // tobj splits the file by material, so shared corners are duplicated.
    assert_eq!(ico.triangle_count(), 20);
    assert!(ico.positions.iter().all(|p| (p.length() - 1.0).abs() < 1e-6));
    let objs: Vec<_> = scene.objects.iter().filter(|o| matches!(o.shape, Shape::Mesh { mesh: 0, .. })).collect();
    assert_eq!(objs.len(), 3);
    let gold = &scene.materials[objs[0].mesh_materials[0] as usize];
    assert_eq!(gold.color, Texture::Solid(Vec3::new(0.8f32 as f64, 0.6f32 as f64, 0.2f32 as f64)));
    assert_eq!(gold.shininess, 60.0);
    let octa = &scene.meshes[1];
    assert_eq!((octa.positions.len(), octa.triangle_count()), (6, 8));
}

#[test]
fn transforms_apply_in_the_order_written() {
    let s = parse_scene(
        "s.toml".as_ref(),
        "[[object]]\nshape = \"sphere\"\nradius = 1\ntransform = [{ translate = [1, 0, 0] }, { rotate_z = 90 }, { scale = 2 }]\n",
    )
    .unwrap();
    // (0,0,0) → (1,0,0) → (0,1,0) → (0,2,0).
    let p = s.objects[0].transform.point(Vec3::ZERO);
    assert!((p - Vec3::new(0.0, 2.0, 0.0)).length() < 1e-12, "{p}");
}

#[test]
fn image_texture_is_loaded_and_linearised() {
    let dir = tempfile::tempdir().unwrap();
    image::RgbImage::from_pixel(2, 2, image::Rgb([255, 128, 0])).save(dir.path().join("t.png")).unwrap();
    let file = dir.path().join("s.toml");
    std::fs::write(&file, "[[object]]\nshape = \"sphere\"\nradius = 1\nmaterial = { color = { image = { file = \"t.png\", scale = 2 } } }\n").unwrap();
    let s = load_scene(&file).unwrap();
    let px = s.images[0].texel(0);
    assert_eq!(px[0], 1.0);
    assert!((px[1] - 0.2158605).abs() < 1e-6, "sRGB 128 is linear 0.216");
    let missing =
        err("[[object]]\nshape = \"sphere\"\nradius = 1\nmaterial = { color = { image = { file = \"nope.png\" } } }\n");
    assert!(missing.contains("s.toml:4:41: cannot load image"), "{missing}");
}

#[test]
fn cameras_and_lights_are_read() {
    let s = parse_scene(
        "s.toml".as_ref(),
        "[camera]\neye = [0, 0, 5]\nfrustum = { left = -1, right = 1, bottom = -0.5, top = 0.5, near = 2 }\n[[light]]\ntype = \"spot\"\nposition = [0, 5, 0]\ndirection = [0, -1, 0]\nangle = 60\n",
    )
    .unwrap();
    assert!(matches!(s.camera, CameraDesc::Perspective { opening: PerspectiveOpening::Frustum { .. }, .. }));
    let Light::Spot { cos_cutoff, .. } = s.lights[0] else { panic!() };
    assert!((cos_cutoff - 0.5).abs() < 1e-12);
}

#[test]
fn mistakes_are_located_and_explained() {
    assert!(err("[[object]]\nradius = 1\n").contains("s.toml:1:1: `object` is missing the required key `shape`"));
    assert!(err("[render]\nwidth = \"big\"\n").contains("s.toml:2:9: `width`: expected an integer, found a string"));
    assert!(err("[render]\nspp = 0\n").contains("`spp` must be an integer in 1..=1048576, found 0"));
    assert!(err("[camera]\neye = [0, 0]\n").contains("s.toml:2:7: `eye`: expected 3 numbers, found 2"));
    assert!(err("[camera]\neye = [0, 0, 0]\n").contains("eye and target coincide"));
    assert!(err("[[object]]\nshape = \"box\"\nmin = [1, 1, 1]\nmax = [0, 2, 2]\n").contains("`max` must exceed `min`"));
    assert!(err("[[object]]\nshape = \"sphere\"\nradius = 1\ntransform = [{ scale = 0 }]\n").contains("singular"));
    assert!(err("[[object]]\nshape = \"csg\"\nop = \"union\"\na = { shape = \"plane\" }\nb = { shape = \"sphere\", radius = 1 }\n").contains("must be a closed shape"));
    assert!(
        err("[[light]]\ntype = \"point\"\nposition = [0, 1, 0]\nattenuation = [0, 0, 0]\n").contains("not all zero")
    );
    assert!(err("[[object]]\nshape = \"sphere\"\nradius = nan\n").contains("expected a finite number"));
    assert!(err("[[object]]\nshape = \"mesh\"\nfile = \"missing.obj\"\n").contains("cannot load mesh"));
    let typo = err("[materials.glass]\nior = 1.5\n[[object]]\nshape = \"sphere\"\nradius = 1\nmaterial = \"glas\"\n");
    assert!(typo.contains("unknown material \"glas\"") && typo.contains("did you mean \"glass\"?"), "{typo}");
    assert!(
        err("[[object]]\nshape = \"patch\"\nrows = 2\npoints = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]\n")
            .contains("do not form 2 rows")
    );
    assert!(err("[[object]]\nshape = \"curve\"\npoints = [[0, 0, 0]]\n").contains("at least 2 control points"));
    assert!(err("[[object]]\nshape = \"subdivision\"\nbase = \"cuboid\"\n").contains("did you mean \"cube\"?"));
    assert!(err("[render]\nlight_choice = \"measure\"\n").contains("did you mean \"measured\"?"));
    assert!(err("[render]\nlight_choice = 3\n").contains("s.toml:2:16: `light_choice`: expected a string"));
    assert!(
        err("[[object]]\nshape = \"subdivision\"\nbase = \"cube\"\nlevels = 9\n")
            .contains("`levels` must be an integer in 0..=6")
    );
    assert!(err("[[object]]\nshape = \"patch\"\nrows = 2\ndegree = [1, 1]\npoints = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]]\n").contains("needs all of `degree`, `knots_u` and `knots_v`"));
    assert!(err("[[object]]\nshape = \"loft\"\ncurves = [[[0, 0, 0], [1, 0, 0]]]\n").contains("at least 2 curves"));
    assert!(err("[[object]]\nshape = \"revolution\"\nprofile = [[1, 0]]\n").contains("at least 2 points"));
    let late = err("[render]\nwidth = 10\nbackground = 1\n");
    assert!(late.contains("must come before the first [table] header"), "{late}");
}

/// A scene's mesh files are read together before the walk; what cannot be read is still
/// reported where the walk meets it, the first in document order, and the files read are the
/// meshes a walk reading each in turn would give.
#[test]
fn mesh_files_read_together_report_errors_in_document_order() {
    let meshes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/meshes");
    let (ico, prism) = (meshes.join("icosahedron.obj"), meshes.join("prism.obj"));
    let object = |file: &Path| format!("[[object]]\nshape = \"mesh\"\nfile = {:?}\n", file.display().to_string());
    let dir = tempfile::tempdir().unwrap();
    let (first, second) = (dir.path().join("first-missing.ply"), dir.path().join("second-missing.obj"));
    let text = [object(&ico), object(&second), object(&prism), object(&first)].concat();
    let e = parse_scene(&dir.path().join("s.toml"), &text).unwrap_err().to_string();
    assert!(e.contains("s.toml:6:8") && e.contains("second-missing.obj"), "{e}");
    assert!(!e.contains("first-missing"), "{e}");
    // Read together (two files) or alone (one), the same meshes.
    let together = parse_scene(&dir.path().join("s.toml"), &[object(&ico), object(&prism)].concat()).unwrap();
    for (i, alone) in [&ico, &prism].into_iter().enumerate() {
        let alone = parse_scene(&dir.path().join("s.toml"), &object(alone)).unwrap();
        assert_eq!(together.meshes[i].positions, alone.meshes[0].positions);
        assert_eq!(together.meshes[i].triangles, alone.meshes[0].triangles);
    }
}

#[test]
fn invalid_utf8_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("bad.toml");
    std::fs::write(&file, b"ambient = 0.1\n# \xff\n").unwrap();
    let e = load_scene(&file).unwrap_err().to_string();
    assert!(e.contains("bad.toml:2:3: the scene file is not valid UTF-8"), "{e}");
}

mod no_panic {
    use proptest::prelude::*;

    const VALID: &str = "background = [0.1, 0.2, 0.3]\n[render]\nwidth = 8\n[camera]\ntype = \"axonometric\"\nstyle = \"military\"\nwidth = 3\n[[light]]\ntype = \"spot\"\nposition = [0, 3, 0]\ndirection = [0, -1, 0]\n[materials.m]\ncolor = { checker = { size = 0.5 } }\n[[object]]\nshape = \"csg\"\nop = \"difference\"\nmaterial = \"m\"\na = { shape = \"box\" }\nb = { shape = \"cone\", radius = 0.5, transform = [{ matrix = [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]] }] }\n";

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2000))]
        /// Damaged scene files give errors, never panics.
        #[test]
        fn mutated_scenes_never_panic(at in 0usize..VALID.len(), len in 0usize..8, insert in "[\\[\\]{}=\"., 0-9a-z\\n\u{e9}-]{0,6}") {
            let mut s = VALID.to_string();
            let (a, b) = (at.min(s.len()), (at + len).min(s.len()));
            if s.is_char_boundary(a) && s.is_char_boundary(b) {
                s.replace_range(a..b, &insert);
            }
            let _ = alhazen_scene::parse_scene("m.toml".as_ref(), &s);
        }
    }

    #[test]
    fn the_unmutated_scene_is_valid() {
        alhazen_scene::parse_scene("m.toml".as_ref(), VALID).unwrap();
    }
}

#[test]
fn physically_based_materials_are_read() {
    use alhazen_scene::bsdf::{BsdfDesc, Distribution, Ior, Shadowing};
    let text = r#"
[render]
integrator = "path"
sampler = "independent"
light_choice = "power"
[materials.gold]
bsdf = { type = "conductor", metal = "gold", roughness = [0.1, 0.3], distribution = "beckmann" }
[materials.prism]
bsdf = { type = "dielectric", glass = "bk7" }
[materials.lamp]
emission = [5, 4, 3]
[materials.blend]
bsdf = { type = "mix", weight = 0.25, a = { type = "lambert" }, b = { type = "cook-torrance", distribution = "gaussian", roughness = 0.2, kd = 0.3, ks = 0.7 } }
[[object]]
shape = "rectangle"
material = "lamp"
"#;
    let s = parse_scene("pbr.toml".as_ref(), text).unwrap();
    assert_eq!(s.render.integrator, alhazen_scene::IntegratorKind::Path);
    assert_eq!(s.render.sampler, alhazen_scene::SamplerKind::Independent);
    assert_eq!(s.render.light_choice, alhazen_scene::LightChoice::Power);
    let mat = |name: &str| s.materials.iter().find(|m| m.name == name).unwrap();
    let Some(BsdfDesc::Conductor { facets: Some(f), .. }) = &mat("gold").bsdf else { panic!() };
    assert_eq!(
        (f.distribution, f.alpha_u, f.alpha_v, f.shadowing),
        (Distribution::Beckmann, 0.1, 0.3, Shadowing::Smith)
    );
    let Some(BsdfDesc::Dielectric { ior, facets: None, .. }) = &mat("prism").bsdf else { panic!() };
    // BK7: n_d = 1.5168 at the sodium line.
    assert!(matches!(ior, Ior::Sellmeier { .. }) && (ior.nominal() - 1.5168).abs() < 1e-4, "{}", ior.nominal());
    assert!(ior.at(450.0) > ior.at(650.0), "normal dispersion");
    assert_eq!(mat("lamp").emission, Vec3::new(5.0, 4.0, 3.0));
    let Some(BsdfDesc::Mix { weight, b, .. }) = &mat("blend").bsdf else { panic!() };
    assert_eq!(*weight, 0.25);
    assert!(matches!(**b, BsdfDesc::CookTorrance { kd: 0.3, ks: 0.7, .. }));
    let Shape::Mesh { mesh, .. } = s.objects[0].shape else { panic!() };
    assert_eq!(s.meshes[mesh].triangle_count(), 2);
}

/// glTF's metallic–roughness material: its defaults, its factors and map, and the same after
/// writing the scene back out.
#[test]
fn metallic_roughness_reads_and_writes_back() {
    use alhazen_scene::bsdf::BsdfDesc;
    let dir = tempfile::tempdir().unwrap();
    let png = image::RgbImage::from_fn(2, 2, |x, y| image::Rgb([0, (x * 200) as u8, (y * 255) as u8]));
    png.save(dir.path().join("mr.png")).unwrap();
    let text = r#"
[materials.plain]
bsdf = { type = "metallic-roughness" }
[materials.worn]
bsdf = { type = "metallic-roughness", color = [0.9, 0.6, 0.2], metallic = 1, roughness = 0.7, ior = 1.4, map = { file = "mr.png", scale = 2 } }
[materials.leaf]
bsdf = { type = "metallic-roughness", color = [0.2, 0.6, 0.1], diffuse_transmission = { factor = 0.4, color = [1, 0.5, 0] } }
[materials.veined]
bsdf = { type = "metallic-roughness", diffuse_transmission = { factor = 1, factor_map = { file = "mr.png" }, color_map = { image = { file = "mr.png" } } } }
"#;
    let path = dir.path().join("mr.toml");
    std::fs::write(&path, text).unwrap();
    let s = load_scene(&path).unwrap();
    let mat = |s: &alhazen_scene::Scene, name: &str| s.materials.iter().find(|m| m.name == name).unwrap().bsdf.clone();
    let Some(BsdfDesc::MetallicRoughness { metallic, roughness, ior, map: None, .. }) = mat(&s, "plain") else {
        panic!()
    };
    assert_eq!((metallic, roughness, ior), (0.0, 0.5, 1.5));
    let Some(BsdfDesc::MetallicRoughness {
        metallic, roughness, map: Some(Texture::Image { image, scale, .. }), ..
    }) = mat(&s, "worn")
    else {
        panic!()
    };
    assert_eq!((metallic, roughness, scale), (1.0, 0.7, alhazen_math::Vec2::splat(2.0)));
    // Read linearly: 200/255, not its sRGB decoding.
    assert_eq!(s.images[image].texel(1), [0.0, 200.0 / 255.0, 0.0]);
    let Some(BsdfDesc::MetallicRoughness { translucency, .. }) = mat(&s, "leaf") else { panic!() };
    let color = alhazen_math::Vec3::new(1.0, 0.5, 0.0);
    assert_eq!(translucency, alhazen_scene::bsdf::Translucency { factor: 0.4, color });
    let again_path = dir.path().join("again.toml");
    alhazen_scene::write::write_scene(&s, &again_path, &dir.path().join("assets"), "").unwrap();
    let again = load_scene(&again_path).unwrap();
    for name in ["plain", "worn", "leaf"] {
        assert_eq!(mat(&s, name), mat(&again, name));
    }
    // A leaf's share and colour read per point: the share's map linearly (200/255 in green),
    // the colour's decoded from sRGB; written back, the same texels.
    let maps = |s: &alhazen_scene::Scene| match mat(s, "veined") {
        Some(BsdfDesc::MetallicRoughness {
            translucency_map: Some(Texture::Image { image: a, .. }),
            translucency_color_map: Some(Texture::Image { image: b, .. }),
            ..
        }) => (s.images[a].texel(1), s.images[b].texel(1)),
        other => panic!("{other:?}"),
    };
    let (share, colour) = maps(&s);
    assert_eq!(share, [0.0, 200.0 / 255.0, 0.0]);
    assert!((colour[1] - 0.578).abs() < 1e-3, "{colour:?}");
    assert_eq!(maps(&again), (share, colour));
}

/// A metallic–roughness surface's `anisotropy`: a strength (glTF's stretch, no turn) or a
/// table of strength, rotation in degrees and model; the same after writing the scene back
/// out; mistakes located.
#[test]
fn metallic_roughness_anisotropy_reads_and_writes_back() {
    use alhazen_scene::bsdf::{Anisotropy, AnisotropyModel, BsdfDesc};
    let dir = tempfile::tempdir().unwrap();
    let text = r#"
[materials.brushed]
bsdf = { type = "metallic-roughness", metallic = 1, roughness = 0.3, anisotropy = 0.6 }
[materials.turned]
bsdf = { type = "metallic-roughness", metallic = 1, anisotropy = { strength = 0.9, rotation = 30, model = "disney" } }
[materials.mapped]
bsdf = { type = "metallic-roughness", metallic = 1, anisotropy = { strength = 0.5, map = { file = "dir.png", scale = 2 } } }
"#;
    image::RgbImage::from_pixel(2, 2, image::Rgb([255, 128, 200])).save(dir.path().join("dir.png")).unwrap();
    let path = dir.path().join("a.toml");
    std::fs::write(&path, text).unwrap();
    let s = load_scene(&path).unwrap();
    let anisotropy =
        |s: &alhazen_scene::Scene, name: &str| match &s.materials.iter().find(|m| m.name == name).unwrap().bsdf {
            Some(BsdfDesc::MetallicRoughness { anisotropy, .. }) => *anisotropy,
            other => panic!("{other:?}"),
        };
    assert_eq!(anisotropy(&s, "brushed"), Anisotropy { strength: 0.6, rotation: 0.0, model: AnisotropyModel::Gltf });
    let turned = anisotropy(&s, "turned");
    assert_eq!((turned.strength, turned.rotation, turned.model), (0.9, 30f64.to_radians(), AnisotropyModel::Disney));
    let map = |s: &alhazen_scene::Scene, name: &str| match &s.materials.iter().find(|m| m.name == name).unwrap().bsdf {
        Some(BsdfDesc::MetallicRoughness { anisotropy_map: Some(Texture::Image { image, scale, .. }), .. }) => {
            (s.images[*image].texel(0), *scale)
        }
        other => panic!("{other:?}"),
    };
    // Read linearly: 128/255, not its sRGB decoding.
    assert_eq!(map(&s, "mapped"), ([1.0, 128.0 / 255.0, 200.0 / 255.0], alhazen_math::Vec2::splat(2.0)));
    let again_path = dir.path().join("again.toml");
    alhazen_scene::write::write_scene(&s, &again_path, &dir.path().join("assets"), "").unwrap();
    let again = load_scene(&again_path).unwrap();
    for name in ["brushed", "turned", "mapped"] {
        assert_eq!(anisotropy(&s, name), anisotropy(&again, name));
    }
    assert_eq!(map(&s, "mapped"), map(&again, "mapped"));
    for (bad, says) in [
        ("anisotropy = 1.5", "1.5"),
        (r#"anisotropy = { strength = 0.5, model = "ward" }"#, "\"gltf\", \"disney\""),
        (r#"anisotropy = { rotation = 10 }"#, "strength"),
    ] {
        let text = format!("[materials.m]\nbsdf = {{ type = \"metallic-roughness\", {bad} }}\n");
        std::fs::write(&path, &text).unwrap();
        let e = load_scene(&path).unwrap_err().to_string();
        assert!(e.contains("a.toml:2:") && e.contains(says), "{bad}: {e}");
    }
}

/// A dielectric's `transmittance` (what refracted light keeps at each crossing): white by
/// default, a colour or an image; the same after writing the scene back out.
#[test]
fn dielectric_transmittance_reads_and_writes_back() {
    use alhazen_scene::bsdf::BsdfDesc;
    let dir = tempfile::tempdir().unwrap();
    let text = r#"
[materials.clear]
bsdf = { type = "dielectric", ior = 1.5 }
[materials.amber]
bsdf = { type = "dielectric", ior = 1.5, roughness = 0.1, transmittance = [0.9, 0.6, 0.2] }
[materials.mapped]
bsdf = { type = "dielectric", transmittance = { image = { file = "t.png" } } }
[materials.bubble]
bsdf = { type = "dielectric", iridescence = { ior = 1.33, thickness = 300 } }
"#;
    image::RgbImage::from_pixel(2, 2, image::Rgb([255, 128, 0])).save(dir.path().join("t.png")).unwrap();
    let path = dir.path().join("d.toml");
    std::fs::write(&path, text).unwrap();
    let s = load_scene(&path).unwrap();
    let tint = |s: &alhazen_scene::Scene, name: &str| match &s.materials.iter().find(|m| m.name == name).unwrap().bsdf {
        Some(BsdfDesc::Dielectric { transmittance, .. }) => transmittance.clone(),
        other => panic!("{other:?}"),
    };
    assert_eq!(tint(&s, "clear"), Texture::Solid(alhazen_math::Vec3::ONE));
    assert_eq!(tint(&s, "amber"), Texture::Solid(alhazen_math::Vec3::new(0.9, 0.6, 0.2)));
    assert!(matches!(tint(&s, "mapped"), Texture::Image { .. }));
    let again_path = dir.path().join("again.toml");
    alhazen_scene::write::write_scene(&s, &again_path, &dir.path().join("assets"), "").unwrap();
    let again = load_scene(&again_path).unwrap();
    for name in ["clear", "amber"] {
        assert_eq!(tint(&s, name), tint(&again, name));
    }
    assert!(matches!(tint(&again, "mapped"), Texture::Image { .. }));
    // A film on the outside face, written back.
    let film = |s: &alhazen_scene::Scene| match &s.materials.iter().find(|m| m.name == "bubble").unwrap().bsdf {
        Some(BsdfDesc::Dielectric { film: Some(i), .. }) => (i.ior, i.thickness),
        other => panic!("{other:?}"),
    };
    assert_eq!(film(&s), (1.33, [300.0, 300.0]));
    assert_eq!(film(&again), film(&s));
    for (bad, says) in [("[2, 0, 0]", "within [0, 1]"), ("[nan, 0, 0]", "finite"), ("[-1, 0, 0]", "must be ≥ 0")] {
        std::fs::write(&path, format!("[materials.m]\nbsdf = {{ type = \"dielectric\", transmittance = {bad} }}\n"))
            .unwrap();
        let e = load_scene(&path).unwrap_err().to_string();
        assert!(e.contains("d.toml:2:") && e.contains(says), "{bad}: {e}");
    }
}

/// A metallic–roughness surface's `iridescence` (a thin film): its defaults, one thickness or
/// the two a map runs between, maps read linearly; the same after writing the scene back out
/// (and its `specular_map` and `specular_color_map`); mistakes located.
#[test]
fn metallic_roughness_iridescence_reads_and_writes_back() {
    use alhazen_scene::bsdf::{BsdfDesc, Iridescence};
    let dir = tempfile::tempdir().unwrap();
    let text = r#"
[materials.soap]
bsdf = { type = "metallic-roughness", roughness = 0.1, iridescence = {} }
[materials.oil]
bsdf = { type = "metallic-roughness", metallic = 1, iridescence = { factor = 0.7, ior = 1.5, thickness = 550, outside = 1.5 } }
[materials.mapped]
bsdf = { type = "metallic-roughness", specular_map = { file = "f.png" }, specular_color_map = { image = { file = "f.png" } }, iridescence = { thickness = [800, 200], factor_map = { file = "f.png" }, thickness_map = { file = "f.png", scale = 3 } } }
"#;
    image::RgbImage::from_pixel(2, 2, image::Rgb([255, 128, 200])).save(dir.path().join("f.png")).unwrap();
    let path = dir.path().join("i.toml");
    std::fs::write(&path, text).unwrap();
    let s = load_scene(&path).unwrap();
    let film = |s: &alhazen_scene::Scene, name: &str| match &s.materials.iter().find(|m| m.name == name).unwrap().bsdf {
        Some(BsdfDesc::MetallicRoughness { iridescence: Some(i), .. }) => (**i).clone(),
        other => panic!("{other:?}"),
    };
    let plain = |factor, ior, thickness, outside| Iridescence {
        factor,
        ior,
        thickness,
        outside,
        factor_map: None,
        thickness_map: None,
    };
    assert_eq!(film(&s, "soap"), plain(1.0, 1.3, [100.0, 400.0], 1.0));
    assert_eq!(film(&s, "oil"), plain(0.7, 1.5, [550.0, 550.0], 1.5));
    let mapped = film(&s, "mapped");
    assert_eq!(mapped.thickness, [800.0, 200.0]);
    let Some(Texture::Image { image, .. }) = mapped.thickness_map else { panic!("{mapped:?}") };
    // Read linearly: 128/255, not its sRGB decoding; green 0.5 is halfway from 800 to 200 nm.
    assert_eq!(s.images[image].texel(0), [1.0, 128.0 / 255.0, 200.0 / 255.0]);
    assert_eq!(mapped.at(None, Some(alhazen_math::Vec3::new(0.0, 0.5, 0.0))), (1.0, 500.0));
    let again_path = dir.path().join("again.toml");
    alhazen_scene::write::write_scene(&s, &again_path, &dir.path().join("assets"), "").unwrap();
    let again = load_scene(&again_path).unwrap();
    for name in ["soap", "oil"] {
        assert_eq!(film(&s, name), film(&again, name));
    }
    let specular_map = |s: &alhazen_scene::Scene| match &s.materials.iter().find(|m| m.name == "mapped").unwrap().bsdf {
        Some(BsdfDesc::MetallicRoughness { specular_map: Some(Texture::Image { image, .. }), .. }) => {
            s.images[*image].texel(0)
        }
        other => panic!("{other:?}"),
    };
    assert_eq!(specular_map(&s), specular_map(&again));
    let colour_map = |s: &alhazen_scene::Scene| match &s.materials.iter().find(|m| m.name == "mapped").unwrap().bsdf {
        Some(BsdfDesc::MetallicRoughness { specular_color_map: Some(Texture::Image { image, .. }), .. }) => {
            s.images[*image].texel(0)
        }
        other => panic!("{other:?}"),
    };
    assert_eq!(colour_map(&s), colour_map(&again));
    let m = film(&again, "mapped");
    assert_eq!((m.thickness, m.factor_map.is_some(), m.thickness_map.is_some()), ([800.0, 200.0], true, true));
    for (bad, says) in [
        ("iridescence = { factor = 2 }", "2"),
        ("iridescence = { thickness = [100, -1] }", "each within [0, 100000]"),
        ("iridescence = { thickness = [100] }", "2"),
        ("iridescence = { ior = 0.5 }", "0.5"),
        ("iridescence = { colour = 1 }", "colour"),
        ("iridescence = { ior = nan }", "finite"),
        ("iridescence = { thickness = [nan, 100] }", "finite"),
        ("iridescence = { thickness = inf }", "finite"),
    ] {
        let text = format!("[materials.m]\nbsdf = {{ type = \"metallic-roughness\", {bad} }}\n");
        std::fs::write(&path, &text).unwrap();
        let e = load_scene(&path).unwrap_err().to_string();
        assert!(e.contains("i.toml:2:") && e.contains(says), "{bad}: {e}");
    }
}

/// glTF's stretch `α_t = α + (1 − α)s²`, `α_b = α`; Disney's `α/a`, `α·a` with
/// `a = √(1 − 0.9s)`; none at strength 0.
#[test]
fn anisotropy_stretches_the_roughness() {
    use alhazen_scene::bsdf::{Anisotropy, AnisotropyModel};
    let at = |strength: f64, model| Anisotropy { strength, rotation: 0.0, model };
    assert_eq!(at(0.0, AnisotropyModel::Gltf).alphas(0.2), (0.2, 0.2));
    assert_eq!(at(0.0, AnisotropyModel::Disney).alphas(0.2), (0.2, 0.2));
    assert_eq!(at(0.5, AnisotropyModel::Gltf).alphas(0.2), (0.2 + 0.8 * 0.25, 0.2));
    assert_eq!(at(1.0, AnisotropyModel::Gltf).alphas(0.2), (1.0, 0.2));
    let (along, across) = at(0.9, AnisotropyModel::Disney).alphas(0.16);
    let aspect = (1.0f64 - 0.81).sqrt();
    assert_eq!((along, across), (0.16 / aspect, 0.16 * aspect));
    assert!(!at(0.0, AnisotropyModel::Disney).is_anisotropic() && at(0.1, AnisotropyModel::Gltf).is_anisotropic());
    // A map's texel: red and green the direction `2c − 1` (turning the rotation further), blue
    // the strength's factor.
    let turned =
        Anisotropy { rotation: 0.5, ..at(0.8, AnisotropyModel::Gltf) }.at_texel(alhazen_math::Vec3::new(0.5, 1.0, 0.5));
    assert_eq!((turned.strength, turned.rotation), (0.4, 0.5 + std::f64::consts::FRAC_PI_2));
    let flat = at(0.8, AnisotropyModel::Gltf).at_texel(alhazen_math::Vec3::new(0.5, 0.5, 1.0));
    assert_eq!((flat.strength, flat.rotation), (0.8, 0.0));
}

/// Sheen over a base: its colour (white by default) and roughness (0.5), the base's albedo the
/// material's colour; the same after writing the scene back out.
#[test]
fn sheen_reads_and_writes_back() {
    use alhazen_scene::bsdf::BsdfDesc;
    let dir = tempfile::tempdir().unwrap();
    let text = r#"
[materials.velvet]
color = [0.3, 0.02, 0.05]
bsdf = { type = "sheen", base = { type = "lambert" }, sheen_color = [1, 0.9, 0.9], roughness = 0.4 }
[materials.plain]
bsdf = { type = "sheen", base = { type = "lambert" } }
[materials.mapped]
bsdf = { type = "sheen", base = { type = "lambert" }, sheen_color = { image = { file = "fibres.png" } }, roughness_map = { file = "fibres.png", scale = 2 } }
"#;
    image::RgbImage::from_pixel(2, 2, image::Rgb([200, 100, 50])).save(dir.path().join("fibres.png")).unwrap();
    let path = dir.path().join("s.toml");
    std::fs::write(&path, text).unwrap();
    let s = load_scene(&path).unwrap();
    let mat = |s: &alhazen_scene::Scene, name: &str| s.materials.iter().find(|m| m.name == name).unwrap().bsdf.clone();
    let Some(BsdfDesc::Sheened { base, color, roughness, .. }) = mat(&s, "velvet") else { panic!() };
    assert_eq!((color, roughness), (Texture::Solid(alhazen_math::Vec3::new(1.0, 0.9, 0.9)), 0.4));
    assert!(
        matches!(*base, BsdfDesc::Lambert { albedo: Texture::Solid(c) } if c == alhazen_math::Vec3::new(0.3, 0.02, 0.05))
    );
    assert!(matches!(mat(&s, "plain"), Some(BsdfDesc::Sheened { roughness: 0.5, .. })));
    let again_path = dir.path().join("again.toml");
    alhazen_scene::write::write_scene(&s, &again_path, &dir.path().join("assets"), "").unwrap();
    let again = load_scene(&again_path).unwrap();
    let texel = |s: &alhazen_scene::Scene, t: &Texture| match t {
        Texture::Image { image, .. } => s.images[*image].texel(0),
        other => panic!("{other:?}"),
    };
    let Some(BsdfDesc::Sheened { color, roughness_map: Some(map), .. }) = mat(&s, "mapped") else { panic!() };
    // The colour sRGB-decoded, the roughness map read linearly.
    assert!((texel(&s, &color)[0] - 0.5776).abs() < 1e-3 && texel(&s, &map)[0] == 200.0 / 255.0);
    for name in ["velvet", "plain"] {
        assert_eq!(mat(&s, name), mat(&again, name));
    }
    let Some(BsdfDesc::Sheened { color: c2, roughness_map: Some(m2), .. }) = mat(&again, "mapped") else { panic!() };
    assert_eq!((texel(&s, &color), texel(&s, &map)), (texel(&again, &c2), texel(&again, &m2)));
}

/// Plastic: smooth by default (Mitsuba's polypropylene coat), rough with a roughness, and the
/// same after writing the scene back out.
#[test]
fn plastic_reads_and_writes_back() {
    use alhazen_scene::bsdf::{BsdfDesc, Distribution};
    let text = r#"
[materials.smooth]
bsdf = { type = "plastic", color = [0.8, 0.1, 0.1] }
[materials.rough]
bsdf = { type = "plastic", color = [0.1, 0.3, 0.6], ior = 1.6, roughness = 0.15, distribution = "ggx", nonlinear = true }
"#;
    let s = parse_scene("plastic.toml".as_ref(), text).unwrap();
    let mat = |s: &alhazen_scene::Scene, name: &str| s.materials.iter().find(|m| m.name == name).unwrap().bsdf.clone();
    let Some(BsdfDesc::Plastic { ior, facets: None, nonlinear: false, .. }) = mat(&s, "smooth") else { panic!() };
    assert_eq!(ior, 1.49);
    let Some(BsdfDesc::Plastic { ior, facets: Some(f), nonlinear: true, .. }) = mat(&s, "rough") else { panic!() };
    assert_eq!((ior, f.distribution, f.alpha_u), (1.6, Distribution::TrowbridgeReitz, 0.15));
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("again.toml");
    alhazen_scene::write::write_scene(&s, &path, &dir.path().join("assets"), "").unwrap();
    let again = load_scene(&path).unwrap();
    for name in ["smooth", "rough"] {
        assert_eq!(format!("{:?}", mat(&s, name)), format!("{:?}", mat(&again, name)));
    }
}

/// A layered Cook–Torrance surface: `kd` 1 unless given, any `ks` in [0, 1] (its diffuse weight
/// `kd(1 − ks·E)` keeps energy), a translucent sheet's `transmittance`, and the same after
/// writing the scene back out.
#[test]
fn layered_cook_torrance_reads_and_writes_back() {
    use alhazen_scene::bsdf::BsdfDesc;
    let text = "[materials.glaze]\nbsdf = { type = \"cook-torrance\", color = [0.8, 0.2, 0.1], ks = 1, layered = true, roughness = 0.2, kd = 0.7, transmittance = [0.3, 0.2, 0.1] }\n\
                [materials.plain]\nbsdf = { type = \"cook-torrance\", color = [0.8, 0.2, 0.1] }\n\
                [[object]]\nshape = \"sphere\"\nradius = 1\nmaterial = \"glaze\"\n[[object]]\nshape = \"sphere\"\nradius = 1\nmaterial = \"plain\"\n";
    let s = alhazen_scene::parse_scene("s.toml".as_ref(), text).unwrap();
    let bsdf = |s: &alhazen_scene::Scene, name: &str| s.materials.iter().find(|m| m.name == name).unwrap().bsdf.clone();
    let Some(BsdfDesc::CookTorrance { kd, ks, layered: true, transmittance, .. }) = bsdf(&s, "glaze") else { panic!() };
    assert_eq!(
        (kd, ks, transmittance),
        (0.7, 1.0, alhazen_scene::Texture::Solid(alhazen_math::Vec3::new(0.3, 0.2, 0.1)))
    );
    assert!(matches!(bsdf(&s, "plain"), Some(BsdfDesc::CookTorrance { kd: 0.5, layered: false, .. })));
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("again.toml");
    alhazen_scene::write::write_scene(&s, &path, &dir.path().join("assets"), "").unwrap();
    let again = load_scene(&path).unwrap();
    for name in ["glaze", "plain"] {
        assert_eq!(format!("{:?}", bsdf(&s, name)), format!("{:?}", bsdf(&again, name)));
    }
}

#[test]
fn physically_based_mistakes_are_explained() {
    let m = |bsdf: &str| err(&format!("[materials.m]\nbsdf = {bsdf}\n"));
    assert!(m(r#"{ type = "lambart" }"#).contains("did you mean \"lambert\"?"));
    assert!(m(r#"{ type = "phong", kd = 0.8, ks = 0.5 }"#).contains("kd + ks = 1.3 exceeds 1"));
    assert!(m(r#"{ type = "cook-torrance", kd = 1, ks = 1 }"#).contains("kd + ks·F(0) = 1.04 exceeds 1"));
    assert!(m(r#"{ type = "cook-torrance", layered = "yes" }"#).contains("layered"));
    assert!(m(r#"{ type = "cook-torrance", layered = true, kd = 1.2 }"#).contains("kd"));
    assert!(
        m(r#"{ type = "cook-torrance", ks = 0, kd = 0.7, transmittance = 0.5 }"#).contains("kd + transmittance = 1.2")
    );
    assert!(m(r#"{ type = "cook-torrance", transmittance = [0.2, 1.5, 0] }"#).contains("within [0, 1]"));
    assert!(m(r#"{ type = "cook-torrance", transmittance = nan }"#).contains("expected a finite number"));
    assert!(m(r#"{ type = "cook-torrance", transmittance = 1e300 }"#).contains("beyond ±1e100"));
    assert!(
        m(r#"{ type = "conductor", roughness = 0.2, distribution = "gaussian", shadowing = "smith" }"#)
            .contains("Smith shadowing has no closed form")
    );
    assert!(m(r#"{ type = "dielectric", ior = 1.5, glass = "bk7" }"#).contains("give one of"));
    assert!(m(r#"{ type = "plastic", roughness = [0.1, 0.3] }"#).contains("takes one roughness"));
    assert!(m(r#"{ type = "plastic", ior = 1.0 }"#).contains("ior"));
    assert!(m(r#"{ type = "plastic", ior = nan }"#).contains("ior"));
    assert!(m(r#"{ type = "plastic", ior = 1e300 }"#).contains("ior"));
    assert!(m(r#"{ type = "plastic", nonlinear = 1 }"#).contains("nonlinear"));
    assert!(m(r#"{ type = "dielectric", glass = "bk8" }"#).contains("did you mean \"bk7\"?"));
    assert!(m(r#"{ type = "metallic-roughness", metallic = 1.5 }"#).contains("s.toml:2:"));
    assert!(m(r#"{ type = "metallic-roughness", diffuse_transmission = { factor = 2 } }"#).contains("factor"));
    assert!(
        m(r#"{ type = "metallic-roughness", diffuse_transmission = { color = [2, 0, 0] } }"#).contains("within [0, 1]")
    );
    assert!(m(r#"{ type = "metallic-roughness", diffuse_transmission = { factor = nan } }"#).contains("finite"));
    assert!(m(r#"{ type = "metallic-roughness", diffuse_transmission = { colour = [1, 0, 0] } }"#).contains("colour"));
    assert!(
        m(r#"{ type = "metallic-roughness", diffuse_transmission = { factor_map = { file = "nowhere.png" } } }"#)
            .contains("nowhere.png")
    );
    assert!(
        m(r#"{ type = "metallic-roughness", diffuse_transmission = { color_map = "leaf.png" } }"#)
            .contains("color_map")
    );
    assert!(m(r#"{ type = "metallic-roughness", roughness = -0.1 }"#).contains("roughness"));
    assert!(m(r#"{ type = "metallic-roughness", metallic = nan }"#).contains("expected a finite number"));
    assert!(m(r#"{ type = "metallic-roughness", roughness = 1e300 }"#).contains("roughness"));
    assert!(m(r#"{ type = "metallic-roughness", ior = 0.5 }"#).contains("must lie in [1, 10]"));
    assert!(m(r#"{ type = "metallic-roughness", map = 3 }"#).contains("`map`: expected a table"));
    assert!(m(r#"{ type = "metallic-roughness", map = { file = "mr.png", scale = 0 } }"#).contains("positive"));
    assert!(m(r#"{ type = "metallic-roughness", map = { file = "none.png" } }"#).contains("none.png"));
    assert!(m(r#"{ type = "metallic-roughness", metalic = 0.5 }"#).contains("did you mean `metallic`?"));
    assert!(m(r#"{ type = "dielectric", cauchy = [1.5, -1] }"#).contains("index of refraction at 360 nm"));
    assert!(m(r#"{ type = "conductor", metal = "gold", eta = [1, 1, 1] }"#).contains("either `metal` or `eta`"));
    assert!(m(r#"{ type = "lambert", roughness = 0.1 }"#).contains("unknown key `roughness`"));
    let env = err("[[light]]\ntype = \"environment\"\nfile = \"nowhere.hdr\"\n");
    assert!(env.contains("s.toml:3:8") && env.contains("cannot load image"), "{env}");
    assert!(err("[render]\nintegrator = \"bdpt\"\n").contains("expected one of"));
    for (name, kind) in
        [("photon", alhazen_scene::IntegratorKind::Photon), ("radiosity", alhazen_scene::IntegratorKind::Radiosity)]
    {
        let s = parse_scene("i.toml".as_ref(), &format!("[render]\nintegrator = \"{name}\"\n")).unwrap();
        assert_eq!(s.render.integrator, kind);
    }
    let bump = |b: &str| err(&format!("[materials.m]\nbump = {b}\n"));
    assert!(bump("{ height = 0.1 }").contains("exactly one of `waves = size`, `image = { file = … }` or `normal_map"));
    assert!(bump("{ waves = 0.5 }").contains("missing the required key `height`"));
    assert!(bump("{ height = 0.1, waves = -1 }").contains("waves"));
}

/// Colours in the course's HSV and HSL models, wherever a colour goes (a material, a checker's
/// squares, emission); bad ones are refused where they are written.
#[test]
fn colours_in_hsv_and_hsl() {
    let text = r#"
[materials.a]
color = { hsv = [120, 1, 0.5] }
emission = { hsl = [240, 1, 0.25] }
[materials.b]
color = { checker = { even = { hsl = [0, 1, 0.5] }, odd = { hsv = [60, 0.5, 1] } } }
[[object]]
shape = "sphere"
radius = 1
material = "a"
[[object]]
shape = "sphere"
radius = 1
material = "b"
"#;
    let scene = parse_scene("hsv.toml".as_ref(), text).unwrap();
    let a = &scene.materials[scene.objects[0].material as usize];
    assert_eq!(a.color, Texture::Solid(Vec3::new(0.0, 0.5, 0.0)));
    assert_eq!(a.emission, Vec3::new(0.0, 0.0, 0.5));
    let b = &scene.materials[scene.objects[1].material as usize];
    let Texture::Checker { even, odd, .. } = b.color else { panic!("a checker") };
    assert_eq!((even, odd), (Vec3::new(1.0, 0.0, 0.0), Vec3::new(1.0, 1.0, 0.5)));
    for (bad, expected) in [
        ("{ hsv = [120, 1.5, 0.5] }", "3:9"),
        ("{ hsl = [120, 1, -0.5] }", "3:9"),
        ("{ hsv = [120, 1] }", "3:9"),
        ("{ hsv = [nan, 1, 1] }", "3:9"),
        ("{ hsl = [inf, 1, 0.5] }", "3:9"),
        ("{ hsv = [1, 1, 1], hsl = [1, 1, 1] }", "3:9"),
        ("{ rgb = [1, 1, 1] }", "3:9"),
    ] {
        let e = err(&format!("[materials.a]\n# {bad}\ncolor = {bad}\n"));
        assert!(e.contains("hsv") || e.contains("hsl") || e.contains("saturation"), "{bad}: {e}");
        assert!(e.contains(expected) || e.contains("3:"), "{bad}: {e}");
    }
}

/// `one_sided`: false unless given, kept when the scene is written back, and refused with its
/// place when it is not a boolean.
#[test]
fn one_sided_reads_writes_back_and_refuses_non_booleans() {
    let text = "[materials.card]\ncolor = 0.8\none_sided = true\n[materials.plain]\ncolor = 0.5\n";
    let s = parse_scene("card.toml".as_ref(), text).unwrap();
    let flag = |s: &alhazen_scene::Scene, name: &str| s.materials.iter().find(|m| m.name == name).unwrap().one_sided;
    assert!(flag(&s, "card") && !flag(&s, "plain"));
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("again.toml");
    alhazen_scene::write::write_scene(&s, &path, &dir.path().join("assets"), "").unwrap();
    let again = load_scene(&path).unwrap();
    assert!(flag(&again, "card") && !flag(&again, "plain"));
    for bad in ["1", "\"yes\"", "nan", "[true]"] {
        let e = err(&format!("[materials.card]\none_sided = {bad}\n"));
        assert!(e.contains("one_sided") && e.contains(":2:"), "{bad}: {e}");
    }
}

/// An emission may be a texture times a strength: the image scaled once when read (sRGB
/// decoded), its mean the constant emission; a checker's colours scaled; the same after the
/// scene is written back out; mistakes explained.
#[test]
fn textured_emission_reads_and_writes_back() {
    let dir = tempfile::tempdir().unwrap();
    let png = image::RgbImage::from_fn(2, 1, |x, _| image::Rgb(if x == 0 { [255, 0, 0] } else { [0, 0, 255] }));
    png.save(dir.path().join("screen.png")).unwrap();
    let text = r#"
[materials.screen]
emission = { image = { file = "screen.png", scale = [2, 1] }, strength = 4 }
[materials.tiles]
emission = { checker = { even = [1, 1, 1], odd = [0, 0, 0], size = 0.5 }, strength = [1, 2, 3] }
[materials.plain]
emission = { hsv = [0, 0, 0.5] }
"#;
    let path = dir.path().join("e.toml");
    std::fs::write(&path, text).unwrap();
    let s = load_scene(&path).unwrap();
    let mat = |s: &alhazen_scene::Scene, name: &str| s.materials.iter().find(|m| m.name == name).unwrap().clone();
    let screen = mat(&s, "screen");
    assert_eq!(screen.emission, Vec3::new(2.0, 0.0, 2.0));
    let Some(Texture::Image { image, scale, .. }) = screen.emission_texture else {
        panic!("{:?}", screen.emission_texture)
    };
    assert_eq!(scale, alhazen_math::Vec2::new(2.0, 1.0));
    assert_eq!(s.images[image].texels().collect::<Vec<_>>(), vec![[4.0, 0.0, 0.0], [0.0, 0.0, 4.0]]);
    let tiles = mat(&s, "tiles");
    assert_eq!(tiles.emission, Vec3::new(0.5, 1.0, 1.5));
    assert_eq!(
        tiles.emission_texture,
        Some(Texture::Checker { even: Vec3::new(1.0, 2.0, 3.0), odd: Vec3::ZERO, size: 0.5 })
    );
    assert_eq!((mat(&s, "plain").emission, mat(&s, "plain").emission_texture), (Vec3::splat(0.5), None));
    let again_path = dir.path().join("again.toml");
    alhazen_scene::write::write_scene(&s, &again_path, &dir.path().join("assets"), "").unwrap();
    let again = load_scene(&again_path).unwrap();
    for name in ["screen", "tiles", "plain"] {
        let (a, b) = (mat(&s, name), mat(&again, name));
        assert_eq!((a.emission, a.emission_texture.is_some()), (b.emission, b.emission_texture.is_some()), "{name}");
    }
    let Some(Texture::Image { image, .. }) = mat(&again, "screen").emission_texture else { panic!() };
    assert_eq!(again.images[image].texels().collect::<Vec<_>>(), vec![[4.0, 0.0, 0.0], [0.0, 0.0, 4.0]]);
    let m = |emission: &str| err(&format!("[materials.m]\nemission = {emission}\n"));
    assert!(m("{ strength = 2 }").contains("expected a colour, { image"), "{}", m("{ strength = 2 }"));
    assert!(m(r#"{ checker = {}, strength = -1 }"#).contains("≥ 0"));
    assert!(m(r#"{ checker = {}, strenght = 2 }"#).contains("strenght"));
    assert!(m(r#"{ checker = {}, strength = 2, image = { file = "x.png" } }"#).contains("expected a colour"));
    assert!(m(r#"{ checker = {}, strength = 1e300 }"#).contains("beyond ±1e100"));
    assert!(m(r#"{ checker = {}, strength = nan }"#).contains("expected a finite number"));
    assert!(m(r#"{ image = { file = "none.png" } }"#).contains("none.png"));
    let huge = "[materials.m]\nemission = { image = { file = \"screen.png\" }, strength = 1e50 }\n";
    std::fs::write(&path, huge).unwrap();
    let e = load_scene(&path).unwrap_err().to_string();
    assert!(e.contains("overflow single precision") && e.contains("e.toml:2:"), "{e}");
}

/// A spot's `fade` from its beam to its cone: linear in angle by default, smooth in the
/// cosine (pbrt's) or the square of linear in the cosine (glTF's); the same after writing the
/// scene back out.
#[test]
fn spot_fades_read_and_write_back() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("f.toml");
    let spot = |fade: &str| {
        format!(
            "[[light]]\ntype = \"spot\"\nposition = [0, 1, 0]\ndirection = [0, -1, 0]\nangle = 30\nbeam = 20\n{fade}"
        )
    };
    let text = [spot(""), spot("fade = \"smooth\"\n"), spot("fade = \"squared\"\n")].concat();
    std::fs::write(&path, text).unwrap();
    let s = load_scene(&path).unwrap();
    let fades: Vec<_> = s
        .lights
        .iter()
        .map(|l| match l {
            alhazen_scene::Light::Spot { beam: Some(b), .. } => b.fade,
            other => panic!("{other:?}"),
        })
        .collect();
    use alhazen_scene::SpotFade::*;
    assert_eq!(fades, [LinearAngle, SmoothCosine, SquaredCosine]);
    let again_path = dir.path().join("again.toml");
    alhazen_scene::write::write_scene(&s, &again_path, &dir.path().join("assets"), "").unwrap();
    assert_eq!(load_scene(&again_path).unwrap().lights, s.lights);
}

/// This session's new keys refuse what they cannot mean, pointing at the value: a spot's
/// `beam` outside 0–180° or NaN, an environment's `up` of no length or not finite, a thin
/// sheet's `ior` below 1, a blend's `weight_map` that is not a texture.
#[test]
fn beams_up_axes_thin_sheets_and_weight_maps_refuse_nonsense() {
    let spot = |beam: &str| {
        err(&format!(
            "[[light]]\ntype = \"spot\"\nposition = [0, 1, 0]\ndirection = [0, -1, 0]\nangle = 30\nbeam = {beam}\n"
        ))
    };
    for beam in ["200", "-1", "nan"] {
        assert!(spot(beam).contains("s.toml:6"), "beam {beam}: {}", spot(beam));
    }
    // A fade needs a beam to fade from, and is one of three.
    let e = err("[[light]]\ntype = \"spot\"\nposition = [0, 1, 0]\ndirection = [0, -1, 0]\nfade = \"smooth\"\n");
    assert!(e.contains("s.toml:5") && e.contains("give a `beam`"), "{e}");
    let e = spot("20\nfade = \"cubic\"");
    assert!(e.contains("s.toml:7") && e.contains("\"squared\""), "{e}");
    let sky = |up: &str| err(&format!("[[light]]\ntype = \"environment\"\nfile = \"none.exr\"\nup = {up}\n"));
    for up in ["[0, 0, 0]", "[nan, 1, 0]", "[1, 2]"] {
        let e = sky(up);
        assert!(e.contains("s.toml:") && !e.contains("none.exr"), "up {up}: {e}");
    }
    let material = |bsdf: &str| {
        err(&format!("[materials.m]\nbsdf = {bsdf}\n[[object]]\nshape = \"sphere\"\nradius = 1\nmaterial = \"m\"\n"))
    };
    for bsdf in [
        r#"{ type = "thin-dielectric", ior = 0.5 }"#,
        r#"{ type = "thin-dielectric", ior = nan }"#,
        r#"{ type = "mix", a = { type = "lambert" }, b = { type = "lambert" }, weight_map = "noise" }"#,
    ] {
        assert!(material(bsdf).contains("s.toml:2"), "{bsdf}: {}", material(bsdf));
    }
}

/// `alpha`: a constant coverage, or an image's alpha channel (its first where it has none)
/// with an optional cutoff; written back the same; out-of-range values, an image missing or
/// a cutoff without image refused where they are written.
#[test]
fn alpha_cut_outs_read_write_back_and_refuse_nonsense() {
    let dir = tempfile::tempdir().unwrap();
    let rgba = image::RgbaImage::from_fn(2, 1, |x, _| image::Rgba([200, 100, 50, if x == 0 { 255 } else { 51 }]));
    rgba.save(dir.path().join("leaf.png")).unwrap();
    image::GrayImage::from_fn(2, 1, |x, _| image::Luma([if x == 0 { 0 } else { 255 }]))
        .save(dir.path().join("grey.png"))
        .unwrap();
    let text = r#"
[materials.leaf]
alpha = { image = { file = "leaf.png", scale = 2 }, cutoff = 0.5 }
[materials.lace]
alpha = { image = { file = "grey.png" } }
[materials.veil]
alpha = 0.25
[materials.plain]
color = 0.5
"#;
    let path = dir.path().join("a.toml");
    std::fs::write(&path, text).unwrap();
    let s = load_scene(&path).unwrap();
    let alpha =
        |s: &alhazen_scene::Scene, name: &str| s.materials.iter().find(|m| m.name == name).unwrap().alpha.clone();
    let coverage = |s: &alhazen_scene::Scene, name: &str| {
        let Some(alhazen_scene::Alpha { coverage: Texture::Image { image, .. }, cutoff }) = alpha(s, name) else {
            panic!("{name}: {:?}", alpha(s, name))
        };
        (s.images[image].texels().map(|t| t[0]).collect::<Vec<_>>(), cutoff)
    };
    // Alpha and grey values as fractions, never decoded from sRGB.
    assert_eq!(coverage(&s, "leaf"), (vec![1.0, 0.2], Some(0.5)));
    assert_eq!(coverage(&s, "lace"), (vec![0.0, 1.0], None));
    let veil = alhazen_scene::Alpha { coverage: Texture::Solid(Vec3::splat(0.25)), cutoff: None };
    assert_eq!(alpha(&s, "veil"), Some(veil.clone()));
    assert_eq!(alpha(&s, "plain"), None);
    let again_path = dir.path().join("again.toml");
    alhazen_scene::write::write_scene(&s, &again_path, &dir.path().join("assets"), "").unwrap();
    let again = load_scene(&again_path).unwrap();
    assert_eq!(coverage(&again, "leaf"), coverage(&s, "leaf"));
    assert_eq!(coverage(&again, "lace"), coverage(&s, "lace"));
    assert_eq!((alpha(&again, "veil"), alpha(&again, "plain")), (Some(veil), None));
    let m = |alpha: &str| err(&format!("[materials.m]\nalpha = {alpha}\n"));
    for bad in ["1.5", "-0.1", "nan", "\"half\"", "{ cutoff = 0.5 }", "{ image = { file = \"x.png\" }, cutoff = 2 }"] {
        assert!(m(bad).contains("s.toml:2"), "{bad}: {}", m(bad));
    }
    assert!(m("{ image = { file = \"none.png\" } }").contains("none.png"));
    assert!(m("{ image = { file = \"x.png\" }, cutof = 0.5 }").contains("cutof"));
}

/// A perspective camera's thin lens: `aperture` (its radius) and `focus_distance` (the
/// target's distance unless given), written back; nonsense refused where it is written.
#[test]
fn thin_lenses_read_write_back_and_refuse_nonsense() {
    let lens_of = |s: &alhazen_scene::Scene| match s.camera {
        alhazen_scene::CameraDesc::Perspective { lens, .. } => lens,
        ref other => panic!("{other:?}"),
    };
    let cam = |extra: &str| format!("[camera]\neye = [0, 0, 5]\ntarget = [0, 0, 1]\n{extra}");
    let s = parse_scene("l.toml".as_ref(), &cam("aperture = 0.1\n")).unwrap();
    assert_eq!(lens_of(&s), Some(alhazen_scene::ThinLens { aperture: 0.1, focus_distance: 4.0 }));
    let s = parse_scene("l.toml".as_ref(), &cam("aperture = 0.2\nfocus_distance = 7\n")).unwrap();
    let lens = Some(alhazen_scene::ThinLens { aperture: 0.2, focus_distance: 7.0 });
    assert_eq!(lens_of(&s), lens);
    assert_eq!(lens_of(&parse_scene("l.toml".as_ref(), &cam("")).unwrap()), None);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("again.toml");
    alhazen_scene::write::write_scene(&s, &path, &dir.path().join("assets"), "").unwrap();
    assert_eq!(lens_of(&load_scene(&path).unwrap()), lens);
    for bad in ["aperture = 0\n", "aperture = -1\n", "aperture = nan\n", "aperture = 0.1\nfocus_distance = 0\n"] {
        let e = err(&cam(bad));
        assert!(e.contains("s.toml:4") || e.contains("s.toml:5"), "{bad}: {e}");
    }
    assert!(err(&cam("focus_distance = 3\n")).contains("needs an `aperture`"));
    assert!(
        err("[camera]\ntype = \"orthographic\"\neye = [0, 0, 5]\nwidth = 2\naperture = 0.1\n").contains("aperture")
    );
}

/// A colour image may be turned and shifted (`rotation = degrees`, `offset = [u, v]`, after
/// `scale`), and is written back so; a bump or normal map may not (its table refuses the keys).
#[test]
fn image_offsets_read_write_back_and_are_refused_where_unsupported() {
    let dir = tempfile::tempdir().unwrap();
    image::RgbImage::from_fn(2, 1, |x, _| image::Rgb([x as u8 * 255, 0, 0])).save(dir.path().join("t.png")).unwrap();
    let text =
        "[materials.m]\ncolor = { image = { file = \"t.png\", scale = 2, offset = [0.25, 0.5], rotation = -30.5 } }\n";
    let path = dir.path().join("o.toml");
    std::fs::write(&path, text).unwrap();
    let placed = |s: &alhazen_scene::Scene| match &s.materials.iter().find(|m| m.name == "m").unwrap().color {
        Texture::Image { scale, offset, rotation, .. } => (*scale, *offset, *rotation),
        other => panic!("{other:?}"),
    };
    let s = load_scene(&path).unwrap();
    let expected = (alhazen_math::Vec2::splat(2.0), alhazen_math::Vec2::new(0.25, 0.5), -30.5);
    assert_eq!(placed(&s), expected);
    let again = dir.path().join("again.toml");
    alhazen_scene::write::write_scene(&s, &again, &dir.path().join("assets"), "").unwrap();
    assert_eq!(placed(&load_scene(&again).unwrap()), expected);
    for bad in ["[nan, 0]", "[0.5]", "[1e300, 0]", "0.5"] {
        let text = format!("[materials.m]\ncolor = {{ image = {{ file = \"t.png\", offset = {bad} }} }}\n");
        std::fs::write(&path, text).unwrap();
        let e = load_scene(&path).unwrap_err().to_string();
        assert!(e.contains("o.toml:2") && !e.contains("cannot load"), "{bad}: {e}");
    }
    // Wrap modes, one for both axes or one each, written back so.
    for (wrap, want) in [("\"clamp\"", [Wrap::Clamp; 2]), ("[\"mirror\", \"black\"]", [Wrap::Mirror, Wrap::Black])] {
        let text = format!("[materials.m]\ncolor = {{ image = {{ file = \"t.png\", wrap = {wrap} }} }}\n");
        std::fs::write(&path, text).unwrap();
        let s = load_scene(&path).unwrap();
        assert_eq!(s.images[0].wrap, want);
        alhazen_scene::write::write_scene(&s, &again, &dir.path().join("assets"), "").unwrap();
        assert_eq!(load_scene(&again).unwrap().images[0].wrap, want);
    }
    for bad in ["\"clmap\"", "[\"clamp\"]", "3"] {
        let text = format!("[materials.m]\ncolor = {{ image = {{ file = \"t.png\", wrap = {bad} }} }}\n");
        std::fs::write(&path, text).unwrap();
        let e = load_scene(&path).unwrap_err().to_string();
        assert!(e.contains("o.toml:2") && e.contains("wrap"), "{bad}: {e}");
    }
    for bad in ["nan", "\"30\"", "1e9"] {
        let text = format!("[materials.m]\ncolor = {{ image = {{ file = \"t.png\", rotation = {bad} }} }}\n");
        std::fs::write(&path, text).unwrap();
        let e = load_scene(&path).unwrap_err().to_string();
        assert!(e.contains("o.toml:2") && e.contains("rotation"), "{bad}: {e}");
    }
    for key in ["offset = [0.5, 0]", "rotation = 90"] {
        let bump = format!("[materials.m]\nbump = {{ height = 0.1, image = {{ file = \"t.png\", {key} }} }}\n");
        std::fs::write(&path, bump).unwrap();
        let e = load_scene(&path).unwrap_err().to_string();
        assert!(e.contains(key.split(' ').next().unwrap()) && e.contains("o.toml:2"), "{e}");
    }
}

/// A pixel filter by name (its defaults) or as a table; written back to the same numbers;
/// mistakes located and explained.
#[test]
fn pixel_filters_read_write_back_and_refuse_mistakes() {
    use alhazen_scene::PixelFilter;
    let filter = |v: &str| parse_scene("f.toml".as_ref(), &format!("[render]\nfilter = {v}\n")).unwrap().render.filter;
    assert_eq!(parse_scene("f.toml".as_ref(), "").unwrap().render.filter, PixelFilter::PIXEL);
    assert_eq!(filter("\"box\""), PixelFilter::PIXEL);
    assert_eq!(filter("\"gaussian\""), PixelFilter::Gaussian { sigma: 0.5, radius: [1.5; 2] });
    assert_eq!(
        filter("{ type = \"gaussian\", sigma = 0.25 }"),
        PixelFilter::Gaussian { sigma: 0.25, radius: [0.75; 2] }
    );
    assert_eq!(filter("\"tent\""), PixelFilter::Tent { radius: [1.0; 2] });
    assert_eq!(filter("{ type = \"blackman-harris\", radius = 2 }"), PixelFilter::BlackmanHarris { radius: [2.0; 2] });
    assert_eq!(filter("\"catmull-rom\""), PixelFilter::Mitchell { b: 0.0, c: 0.5, radius: [2.0; 2] });
    assert_eq!(filter("{ type = \"lanczos\", tau = 2 }"), PixelFilter::Lanczos { tau: 2.0, radius: [2.0; 2] });
    let written = [
        PixelFilter::Box { radius: [1.0, 0.5] },
        PixelFilter::BlackmanHarris { radius: [1.5; 2] },
        PixelFilter::Mitchell { b: 1.0 / 3.0, c: 1.0 / 3.0, radius: [2.0; 2] },
        PixelFilter::Gaussian { sigma: 0.3, radius: [1.1, 0.9] },
    ];
    let dir = tempfile::tempdir().unwrap();
    for f in written {
        let mut s = parse_scene("f.toml".as_ref(), "").unwrap();
        s.render.filter = f;
        let path = dir.path().join("again.toml");
        alhazen_scene::write::write_scene(&s, &path, &dir.path().join("assets"), "").unwrap();
        assert_eq!(load_scene(&path).unwrap().render.filter, f);
    }
    for (bad, says) in [
        ("\"gauss\"", "did you mean \"gaussian\""),
        ("{ type = \"box\", sigma = 1 }", "unknown key `sigma`"),
        ("{ radius = 1 }", "required key `type`"),
        ("{ type = \"tent\", radius = 0 }", "radius must lie in (0, 16]"),
        ("{ type = \"tent\", radius = [1, 40] }", "radius must lie in (0, 16]"),
        ("{ type = \"gaussian\", sigma = -1 }", "sigma must lie in"),
        ("{ type = \"lanczos\", tau = 0 }", "tau must lie in"),
        ("{ type = \"mitchell\", b = 1e300 }", "beyond ±1e100"),
        ("{ type = \"mitchell\", c = 1000 }", "B and C must be finite"),
        ("3", "expected a string"),
    ] {
        let e = err(&format!("[render]\nfilter = {bad}\n"));
        assert!(e.contains(says) && e.contains(":2:"), "{bad}: {e}");
    }
}

/// Vertex colours: a PLY's unsigned `red green blue` are sRGB codes and its float `r g b` linear,
/// an OBJ's `v x y z r g b` sRGB fractions (its MTL-less mesh takes the object's material, which
/// says whether it uses them); `vertex_colors` and the colours survive writing the scene back;
/// a negative colour and a flag that is not a boolean are refused with their place.
#[test]
fn vertex_colours_read_from_ply_and_obj_write_back_and_bad_ones_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let ply = |props: &str, rows: [&str; 3]| {
        format!(
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n{props}\
             element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0 {}\n1 0 0 {}\n0 1 0 {}\n3 0 1 2\n",
            rows[0], rows[1], rows[2]
        )
    };
    let bytes = "property uchar red\nproperty uchar green\nproperty uchar blue\n";
    std::fs::write(dir.path().join("codes.ply"), ply(bytes, ["255 128 0", "0 0 0", "10 20 30"])).unwrap();
    let floats = "property float r\nproperty float g\nproperty float b\n";
    std::fs::write(dir.path().join("linear.ply"), ply(floats, ["0.25 0.5 1", "2 0 0", "0 0 0"])).unwrap();
    std::fs::write(dir.path().join("painted.obj"), "v 0 0 0 1 0.5 0\nv 1 0 0 0 0 0\nv 0 1 0 1 1 1\nf 1 2 3\n").unwrap();
    let text = "[materials.painted]\ncolor = 0.8\nvertex_colors = true\n\
                [meshes.codes]\nfile = \"codes.ply\"\n[meshes.linear]\nfile = \"linear.ply\"\n\
                [meshes.obj]\nfile = \"painted.obj\"\n\
                [[object]]\nshape = \"mesh\"\nmesh = \"codes\"\nmaterial = \"painted\"\n\
                [[object]]\nshape = \"mesh\"\nmesh = \"linear\"\nmaterial = \"painted\"\n\
                [[object]]\nshape = \"mesh\"\nmesh = \"obj\"\nmaterial = \"painted\"\n";
    let path = dir.path().join("painted.toml");
    std::fs::write(&path, text).unwrap();
    let s = load_scene(&path).unwrap();
    let srgb = alhazen_math::color::srgb_to_linear;
    // The objects' meshes, in the order written.
    let mesh = |s: &alhazen_scene::Scene, name: &str| {
        let k = ["codes", "linear", "obj"].iter().position(|n| *n == name).unwrap();
        let Shape::Mesh { mesh, .. } = s.objects[k].shape else { panic!("not a mesh") };
        s.meshes[mesh].colors.clone()
    };
    assert_eq!(mesh(&s, "codes")[0], Vec3::new(1.0, srgb(128.0 / 255.0), 0.0));
    assert_eq!(mesh(&s, "codes")[2], Vec3::new(srgb(10.0 / 255.0), srgb(20.0 / 255.0), srgb(30.0 / 255.0)));
    assert_eq!(mesh(&s, "linear"), vec![Vec3::new(0.25, 0.5, 1.0), Vec3::new(2.0, 0.0, 0.0), Vec3::ZERO]);
    assert_eq!(mesh(&s, "obj")[0], Vec3::new(1.0, srgb(0.5f32 as f64), 0.0));
    assert!(s.materials.iter().find(|m| m.name == "painted").unwrap().vertex_colors);
    let again_path = dir.path().join("again.toml");
    alhazen_scene::write::write_scene(&s, &again_path, &dir.path().join("assets"), "").unwrap();
    let again = load_scene(&again_path).unwrap();
    assert!(again.materials.iter().find(|m| m.name == "painted").unwrap().vertex_colors);
    let colors = |s: &alhazen_scene::Scene| s.meshes.iter().map(|m| m.colors.clone()).collect::<Vec<_>>();
    assert_eq!(colors(&again), colors(&s));
    // A negative colour is refused, naming the file.
    std::fs::write(dir.path().join("linear.ply"), ply(floats, ["0.25 -0.5 1", "2 0 0", "0 0 0"])).unwrap();
    let e = load_scene(&path).unwrap_err().to_string();
    assert!(e.contains("linear.ply") && e.contains("colour"), "{e}");
    for bad in ["1", "\"yes\""] {
        let e = err(&format!("[materials.card]\nvertex_colors = {bad}\n"));
        assert!(e.contains("vertex_colors") && e.contains(":2:"), "{bad}: {e}");
    }
}

/// A metallic–roughness coating's `specular` strength: 1 unless given, written back when it is
/// not 1, refused outside [0, 1] with its place.
#[test]
fn metallic_roughness_specular_reads_writes_back_and_is_checked() {
    use alhazen_scene::bsdf::BsdfDesc;
    let text = "[materials.matte]\nbsdf = { type = \"metallic-roughness\", specular = 0.25 }\n\
                [materials.plain]\nbsdf = { type = \"metallic-roughness\" }\n";
    let s = parse_scene("s.toml".as_ref(), text).unwrap();
    let specular =
        |s: &alhazen_scene::Scene, name: &str| match &s.materials.iter().find(|m| m.name == name).unwrap().bsdf {
            Some(BsdfDesc::MetallicRoughness { specular, .. }) => *specular,
            other => panic!("{other:?}"),
        };
    assert_eq!((specular(&s, "matte"), specular(&s, "plain")), (0.25, 1.0));
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("again.toml");
    alhazen_scene::write::write_scene(&s, &path, &dir.path().join("assets"), "").unwrap();
    let again = load_scene(&path).unwrap();
    assert_eq!((specular(&again, "matte"), specular(&again, "plain")), (0.25, 1.0));
    let e = err("[materials.m]\nbsdf = { type = \"metallic-roughness\", specular = 1.5 }\n");
    assert!(e.contains(":2:") && e.contains("specular"), "{e}");
}

/// `multiscatter` on a conductor and on the metallic–roughness model: false unless given,
/// written back, refused when not a boolean.
#[test]
fn multiscatter_reads_writes_back_and_is_checked() {
    use alhazen_scene::bsdf::BsdfDesc;
    let text = "[materials.gold]\nbsdf = { type = \"conductor\", metal = \"gold\", roughness = 0.4, multiscatter = true }\n\
                [materials.mr]\nbsdf = { type = \"metallic-roughness\", metallic = 1, multiscatter = true }\n\
                [materials.plain]\nbsdf = { type = \"conductor\", roughness = 0.4 }\n";
    let flags = |s: &alhazen_scene::Scene| {
        s.materials
            .iter()
            .filter_map(|m| match &m.bsdf {
                Some(BsdfDesc::Conductor { multiscatter, .. } | BsdfDesc::MetallicRoughness { multiscatter, .. }) => {
                    Some((m.name.clone(), *multiscatter))
                }
                _ => None,
            })
            .collect::<Vec<_>>()
    };
    let s = parse_scene("s.toml".as_ref(), text).unwrap();
    let want = vec![("gold".to_string(), true), ("mr".to_string(), true), ("plain".to_string(), false)];
    assert_eq!(flags(&s), want);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("again.toml");
    alhazen_scene::write::write_scene(&s, &path, &dir.path().join("assets"), "").unwrap();
    assert_eq!(flags(&load_scene(&path).unwrap()), want);
    let e = err("[materials.m]\nbsdf = { type = \"conductor\", multiscatter = 1 }\n");
    assert!(e.contains(":2:") && e.contains("multiscatter"), "{e}");
}

/// `type = "coated"`: a clear coat over any BSDF (weight 1, roughness 0.01, index 1.5 unless
/// given), written back the same; a coat smoother than 0.01, a base missing or a weight
/// outside [0, 1] refused where they are written.
#[test]
fn coats_read_write_back_and_refuse_nonsense() {
    use alhazen_scene::bsdf::BsdfDesc;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("c.toml");
    let text = "[materials.paint]\nbsdf = { type = \"coated\", base = { type = \"lambert\", color = [0.6, 0.1, 0.1] }, roughness = 0.05 }\n";
    std::fs::write(&path, text).unwrap();
    let coat = |s: &alhazen_scene::Scene| s.materials.iter().find(|m| m.name == "paint").unwrap().bsdf.clone().unwrap();
    let s = load_scene(&path).unwrap();
    let read = coat(&s);
    let BsdfDesc::Coated { base, weight, facets, ior, .. } = &read else { panic!("{read:?}") };
    assert!(matches!(**base, BsdfDesc::Lambert { .. }), "{base:?}");
    assert_eq!((*weight, facets.alpha_u, *ior), (1.0, 0.05, 1.5));
    let again = dir.path().join("again.toml");
    alhazen_scene::write::write_scene(&s, &again, &dir.path().join("assets"), "").unwrap();
    assert_eq!(coat(&load_scene(&again).unwrap()), read);
    // The weight and roughness read per point from maps, written back as maps.
    image::RgbImage::from_pixel(2, 2, image::Rgb([255, 128, 0])).save(dir.path().join("coat.png")).unwrap();
    let text = "[materials.paint]\nbsdf = { type = \"coated\", base = { type = \"lambert\" }, roughness = 0.3, weight_map = { file = \"coat.png\" }, roughness_map = { file = \"coat.png\", scale = 2 } }\n";
    std::fs::write(&path, text).unwrap();
    let s = load_scene(&path).unwrap();
    let mapped = |s: &alhazen_scene::Scene| match coat(s) {
        BsdfDesc::Coated {
            weight_map: Some(Texture::Image { image: w, .. }),
            roughness_map: Some(Texture::Image { image: r, scale, .. }),
            ..
        } => (s.images[w].texel(0), s.images[r].texel(0), scale),
        other => panic!("{other:?}"),
    };
    assert_eq!(mapped(&s), ([1.0, 128.0 / 255.0, 0.0], [1.0, 128.0 / 255.0, 0.0], alhazen_math::Vec2::splat(2.0)));
    alhazen_scene::write::write_scene(&s, &again, &dir.path().join("assets"), "").unwrap();
    assert_eq!(mapped(&load_scene(&again).unwrap()), mapped(&s));
    let material = |bsdf: &str| {
        err(&format!("[materials.m]\nbsdf = {bsdf}\n[[object]]\nshape = \"sphere\"\nradius = 1\nmaterial = \"m\"\n"))
    };
    for (bsdf, says) in [
        (r#"{ type = "coated", base = { type = "lambert" }, roughness = 0.001 }"#, "at least 0.01"),
        (r#"{ type = "coated", roughness = 0.1 }"#, "base"),
        (r#"{ type = "coated", base = { type = "lambert" }, weight = 1.5 }"#, "weight"),
    ] {
        let e = material(bsdf);
        assert!(e.contains("s.toml:2") && e.contains(says), "{bsdf}: {e}");
    }
}

/// Every light choice survives being written back out (the default, `measured`, unwritten).
#[test]
fn light_choices_survive_the_round_trip() {
    use alhazen_scene::LightChoice;
    let dir = tempfile::tempdir().unwrap();
    for (name, choice) in
        [("measured", LightChoice::Measured), ("power", LightChoice::Power), ("uniform", LightChoice::Uniform)]
    {
        let s = parse_scene("c.toml".as_ref(), &format!("[render]\nlight_choice = \"{name}\"\n")).unwrap();
        assert_eq!(s.render.light_choice, choice);
        let path = dir.path().join("again.toml");
        alhazen_scene::write::write_scene(&s, &path, &dir.path().join("assets"), "").unwrap();
        assert_eq!(load_scene(&path).unwrap().render.light_choice, choice, "{name}");
    }
}
