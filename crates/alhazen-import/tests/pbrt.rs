//! The pbrt-v4 importer: a Cornell box written from the file-format documentation renders the
//! bits of its native twin; pbrt's left-handed camera; features and malformed files.

mod common;
use common::*;

use alhazen_math::Vec3;
use alhazen_render::Image;
use alhazen_scene::bsdf::BsdfDesc;
use alhazen_scene::{Light, Scene, Shape, Texture};

fn small(mut s: Scene, spp: u32) -> Image {
    (s.render.width, s.render.height, s.render.spp) = (64, 64, spp);
    alhazen_render::render(&s, &|_, _| {})
}

fn bits(img: &Image) -> Vec<u64> {
    (0..img.height)
        .flat_map(|y| (0..img.width).map(move |x| (x, y)))
        .flat_map(|(x, y)| img.get(x, y).to_array())
        .map(f64::to_bits)
        .collect()
}

fn same_bits_as_twin(name: &str) {
    let pbrt = alhazen_import::load(&repo(&format!("scenes/pbrt/{name}.pbrt"))).unwrap();
    assert!(pbrt.warnings.is_empty(), "{:?}", pbrt.warnings);
    let toml = alhazen_scene::load_scene(&repo(&format!("scenes/{name}.toml"))).unwrap();
    assert_eq!(pbrt.scene.render, toml.render);
    assert_eq!(bits(&small(pbrt.scene, 4)), bits(&small(toml, 4)));
}

#[test]
fn pbrt_cornell_box_renders_the_bits_of_its_toml_twin() {
    same_bits_as_twin("cornell-box");
}

#[test]
fn pbrt_cornell_rough_renders_the_bits_of_its_toml_twin() {
    // Spheres, a rough conductor and rough glass; pbrt's spheres are placed by Translate.
    same_bits_as_twin("cornell-rough");
}

/// Mean red minus green of the left and right quarters of an image.
fn red_left_and_right(img: &Image) -> (f64, f64) {
    let quarter = |x0: u32| {
        let mut s = 0.0;
        for y in 0..img.height {
            for x in x0..x0 + img.width / 4 {
                let c = img.get(x, y);
                s += c.x - c.y;
            }
        }
        s
    };
    (quarter(0), quarter(3 * img.width / 4))
}

#[test]
fn a_plain_look_at_shows_pbrt_s_mirror_image() {
    // Without `Scale -1 1 1`, pbrt's camera (right = up × ahead) sees the red wall (at x = −1)
    // on the right of the image; the importer mirrors the scene so alhazen shows the same.
    let text = std::fs::read_to_string(repo("scenes/pbrt/cornell-box.pbrt")).unwrap();
    let plain = text.replace("Scale -1 1 1\n", "");
    assert_ne!(plain, text);
    let as_exported = small(alhazen_import::load(&repo("scenes/pbrt/cornell-box.pbrt")).unwrap().scene, 4);
    let plain = small(import(&[("plain.pbrt", &plain)]).unwrap().scene, 4);
    let (l, r) = red_left_and_right(&as_exported);
    assert!(l > r, "the red wall is on the left as exported: {l} {r}");
    let (l, r) = red_left_and_right(&plain);
    assert!(r > l, "and on the right under a plain LookAt: {l} {r}");
}

#[test]
fn instances_textures_lights_and_includes() {
    let main = r#"
LookAt 0 2 8  0 0 0  0 1 0
Camera "perspective" "float fov" 40
Film "rgb" "integer xresolution" 32 "integer yresolution" 16
WorldBegin
Include "lights.pbrt"
Texture "checks" "spectrum" "checkerboard" "float uscale" 4 "float vscale" 4 "rgb tex1" [1 1 1] "rgb tex2" [0 0 0]
Material "diffuse" "texture reflectance" "checks"
Shape "bilinearmesh" "point3 P" [-5 0 -5  5 0 -5  -5 0 5  5 0 5]
ObjectBegin "ball"
  MakeNamedMaterial "gold" "string type" "conductor" "spectrum eta" "metal-Au-eta" "spectrum k" "metal-Au-k" "float roughness" 0.04
  NamedMaterial "gold"
  Shape "sphere" "float radius" 0.5
ObjectEnd
AttributeBegin
  Translate 1 0.5 0
  ObjectInstance "ball"
AttributeEnd
Translate -1 0.5 0
ObjectInstance "ball"
"#;
    let lights = r#"LightSource "point" "point3 from" [0 4 0] "rgb I" [2 2 2]
LightSource "distant" "point3 from" [0 1 0] "point3 to" [0 0 0] "blackbody L" 5500
LightSource "spot" "point3 from" [0 3 0] "point3 to" [0 0 0] "float coneangle" 30 "float conedelta" 10"#;
    let s = import(&[("main.pbrt", main), ("lights.pbrt", lights)]).unwrap();
    let sc = &s.scene;
    assert_eq!((sc.render.width, sc.render.height), (32, 16));
    assert_eq!(sc.objects.len(), 3);
    // The scene is mirrored in x (plain LookAt): the first instance stands at x = −1.
    assert!((sc.objects[1].transform.point(Vec3::ZERO) - Vec3::new(-1.0, 0.5, 0.0)).length() < 1e-12);
    assert!((sc.objects[2].transform.point(Vec3::ZERO) - Vec3::new(1.0, 0.5, 0.0)).length() < 1e-12);
    assert!(matches!(sc.objects[1].shape, Shape::Sphere { radius: 0.5, .. }));
    let Some(BsdfDesc::Conductor { facets: Some(f), eta, .. }) = &sc.materials[sc.objects[1].material as usize].bsdf
    else {
        panic!("not a rough conductor")
    };
    assert!((f.alpha_u - 0.2).abs() < 1e-12, "pbrt remaps roughness 0.04 to α = 0.2");
    assert_eq!(*eta, alhazen_scene::bsdf::metal("gold").unwrap().0);
    assert!(matches!(
        sc.materials[sc.objects[0].material as usize].bsdf,
        Some(BsdfDesc::Lambert { albedo: Texture::Checker { size, .. } }) if size == 0.25
    ));
    assert_eq!(
        sc.lights[0],
        Light::Point { position: Vec3::new(-0.0, 4.0, 0.0), intensity: Vec3::splat(2.0), attenuation: [1.0, 0.0, 0.0] }
    );
    assert!(matches!(sc.lights[1], Light::Directional { direction, .. } if direction == -Vec3::Y));
    // pbrt's spot fades smoothly in the cosine over conedelta.
    let Light::Spot { cos_cutoff, beam: Some(beam), .. } = sc.lights[2] else { panic!("{:?}", sc.lights[2]) };
    assert_eq!((cos_cutoff, beam.cos), (30f64.to_radians().cos(), 20f64.to_radians().cos()));
    assert_eq!(beam.fade, alhazen_scene::SpotFade::SmoothCosine);
    let said: Vec<String> = s.warnings.iter().map(|w| w.to_string()).collect();
    assert!(said.iter().any(|w| w.contains("lights.pbrt:2: a blackbody spectrum")), "{said:?}");
    assert!(said.iter().any(|w| w.contains("main.pbrt:9: bilinear patches")), "{said:?}");
}

#[test]
fn an_area_light_makes_its_shapes_emit() {
    let s = import(&[(
        "a.pbrt",
        r#"WorldBegin
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [1 2 3] "float scale" 2
  Shape "disk" "float radius" 0.5
AttributeEnd
Shape "sphere""#,
    )])
    .unwrap()
    .scene;
    assert_eq!(s.materials[s.objects[0].material as usize].emission, Vec3::new(2.0, 4.0, 6.0));
    assert_eq!(s.materials[s.objects[1].material as usize].emission, Vec3::ZERO);
}

/// `MakeNamedMedium "homogeneous"` inside a dielectric or an `interface` (`MediumInterface`,
/// part of the attributes) absorbs `scale·σ_a`; its scattering (pbrt's default `sigma_s` 1) is
/// warned about; other media, outside media and media in opaque shapes are warned and left
/// out; an unknown medium and bad values are located errors.
#[test]
fn homogeneous_media_absorb_inside_glass() {
    let imported = import(&[(
        "m.pbrt",
        r#"WorldBegin
MakeNamedMedium "tea" "string type" "homogeneous" "rgb sigma_a" [0.5 1 2] "rgb sigma_s" [0 0 0] "float scale" 2
MakeNamedMedium "smoke" "string type" "homogeneous"
MakeNamedMedium "cloud" "string type" "nanovdb" "string filename" "cloud.nvdb"
AttributeBegin
  MediumInterface "tea" ""
  Material "dielectric"
  Shape "sphere"
  Material "interface"
  Shape "sphere"
  Material "diffuse"
  Shape "sphere"
AttributeEnd
Material "dielectric"
Shape "sphere"
MediumInterface "smoke"
Shape "sphere"
MediumInterface "cloud" ""
Shape "sphere""#,
    )])
    .unwrap();
    let s = &imported.scene;
    let absorption: Vec<Vec3> = s.objects.iter().map(|o| s.materials[o.material as usize].absorption).collect();
    let tea = Vec3::new(1.0, 2.0, 4.0);
    assert_eq!(absorption, vec![tea, tea, Vec3::ZERO, Vec3::ZERO, Vec3::splat(1.0), Vec3::ZERO]);
    let said: Vec<String> = imported.warnings.iter().map(|w| w.to_string()).collect();
    for (line, says) in [
        (3, "the medium scatters"),
        (4, "medium \"nanovdb\" is not supported"),
        (12, "the medium \"tea\" inside this shape is not rendered"),
        (16, "the outside medium \"smoke\" is not rendered"),
    ] {
        assert!(said.iter().any(|w| w.contains(&format!("m.pbrt:{line}")) && w.contains(says)), "{says}: {said:?}");
    }
    for (text, expected) in [
        (
            "WorldBegin\nMediumInterface \"ink\" \"\"\nMaterial \"dielectric\"\nShape \"sphere\"",
            "a.pbrt:4:7: MediumInterface names the medium \"ink\"",
        ),
        (
            "WorldBegin\nMakeNamedMedium \"m\" \"rgb sigma_a\" [1 1 1]",
            "a.pbrt:2:1: MakeNamedMedium needs \"string type\"",
        ),
        (
            "WorldBegin\nMakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [-1 1 1]",
            "needs sigma_a ≥ 0",
        ),
        ("WorldBegin\nMakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"float scale\" -2", "scale ≥ 0"),
    ] {
        let err = import(&[("a.pbrt", text)]).expect_err(expected);
        assert!(err.contains(expected), "expected {expected:?} in:\n{err}");
    }
}

/// Mesh files are read together after the walk, yet each lands where its shape is, a file
/// shared by two shapes is read once, and an unreadable one is the error, at its shape, even
/// when a later directive is wrong too.
#[test]
fn mesh_files_load_together_in_order() {
    let shape = |file: &str| format!("Shape \"plymesh\" \"string filename\" \"{file}\"");
    let body = ["WorldBegin".into(), shape("three.ply"), shape("one.ply"), shape("three.ply"), shape("two.ply")];
    let (one, two, three) = (strip_ply(1), strip_ply(2), strip_ply(3));
    let files = [("a.pbrt", body.join("\n")), ("one.ply", one.clone()), ("two.ply", two), ("three.ply", three)];
    let s = import(&files.each_ref().map(|(n, t)| (*n, t.as_str()))).unwrap().scene;
    assert_eq!(mesh_triangle_counts(&s), [3, 1, 3, 2]);
    assert_eq!(s.meshes.len(), 3, "three.ply read once");
    let later = "NamedMaterial \"glod\"";
    let text = format!("WorldBegin\n{}\n{}\n{later}", shape("one.ply"), shape("missing.ply"));
    let err = import(&[("a.pbrt", &text), ("one.ply", &one)]).unwrap_err();
    assert!(err.contains("a.pbrt:3:") && err.contains("cannot load mesh"), "{err}");
    let text = format!("WorldBegin\n{}\n{later}", shape("one.ply"));
    let err = import(&[("a.pbrt", &text), ("one.ply", &one)]).unwrap_err();
    assert!(err.contains("a.pbrt:3:") && err.contains("no material named"), "{err}");
}

#[test]
fn malformed_files_are_located_errors() {
    let cases: &[(&str, &str)] = &[
        ("WorldBegin\nShape \"sphere\" \"float radius\" [ 1", "a.pbrt:2:31: `[` without `]`"),
        ("Shpe \"sphere\"", "a.pbrt:1:1: unknown directive `Shpe`"),
        ("LookAt 0 0 1 0 0", "LookAt takes 9 numbers"),
        ("WorldBegin\nNamedMaterial \"glod\"", "a.pbrt:2:15: no material named \"glod\""),
        ("WorldBegin\nObjectInstance \"x\"", "no object named \"x\""),
        (
            "WorldBegin\nShape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"integer indices\" [0 1 5]",
            "index 5 is not a vertex",
        ),
        ("WorldBegin\nShape \"plymesh\" \"string filename\" \"missing.ply\"", "cannot load mesh"),
        ("WorldBegin\nAttributeEnd", "AttributeEnd without a matching begin"),
        ("WorldBegin\nScale 0 1 1\nShape \"sphere\"", "singular"),
        ("Scale 0 1 1\nCamera \"perspective\"", "camera transform is singular"),
        ("WorldBegin\nShape \"sphere\" \"float radius\" \"big\"", "must hold numbers"),
        ("Include \"a.pbrt\"", "nested deeper than 16"),
        ("WorldBegin\nShape \"sphere\" \"radius\" 1", "is not a parameter declaration"),
        ("Film \"rgb\" \"integer xresolution\" 100000", "xresolution must be"),
        ("WorldBegin\n\"oops\"", "a.pbrt:2:1: expected a directive"),
        ("WorldBegin\nShape \"sphere\" \"float radius\" 1e999", "not a finite number"),
        ("Integrator \"path\" \"string lightsampler\" \"tree\"", "a.pbrt:1:1: unknown \"lightsampler\" \"tree\""),
    ];
    for (text, expected) in cases {
        let err = import(&[("a.pbrt", text)]).expect_err(expected);
        assert!(err.contains(expected), "expected {expected:?} in:\n{err}");
    }
}

/// pbrt's light samplers: its light tree (the default) as alhazen's measured choice, power and
/// uniform as they are.
#[test]
fn light_samplers_choose_lights_as_pbrt_names_them() {
    use alhazen_scene::LightChoice;
    for (sampler, choice) in [
        ("", LightChoice::Measured),
        (" \"string lightsampler\" \"bvh\"", LightChoice::Measured),
        (" \"string lightsampler\" \"power\"", LightChoice::Power),
        (" \"string lightsampler\" \"uniform\"", LightChoice::Uniform),
    ] {
        let s = import(&[("a.pbrt", &format!("Integrator \"path\"{sampler}\nWorldBegin\nShape \"sphere\""))]).unwrap();
        assert_eq!(s.scene.render.light_choice, choice, "{sampler}");
        assert!(!s.warnings.iter().any(|w| w.to_string().contains("lightsampler")), "{:?}", s.warnings);
    }
}

#[test]
fn unsupported_parameters_are_warned_about_where_they_are() {
    let s = import(&[("w.pbrt", "WorldBegin\nShape \"sphere\"\n  \"float wobble\" 3\nLightSource \"goniometric\"")])
        .unwrap();
    let said: Vec<String> = s.warnings.iter().map(|w| w.to_string()).collect();
    assert!(
        said.iter().any(|w| w.contains("w.pbrt:3: parameter \"wobble\" of shape \"sphere\" is not supported")),
        "{said:?}"
    );
    assert!(said.iter().any(|w| w.contains("w.pbrt:4: light \"goniometric\" is not supported")), "{said:?}");
    assert!(said.iter().any(|w| w.contains("no Camera")), "{said:?}");
}

/// Image maps are read with the mesh files once the walk is done; an unreadable one is the
/// error, at its texture, even when a later directive is wrong too.
#[test]
fn image_maps_load_after_the_walk_and_an_unreadable_one_is_located() {
    let dir = tempfile::tempdir().unwrap();
    image::RgbImage::from_pixel(2, 1, image::Rgb([0, 255, 0])).save(dir.path().join("green.png")).unwrap();
    let texture = |file: &str| format!("Texture \"t\" \"spectrum\" \"imagemap\" \"string filename\" \"{file}\"");
    let load = |text: &str| {
        std::fs::write(dir.path().join("a.pbrt"), text).unwrap();
        alhazen_import::load(&dir.path().join("a.pbrt")).map_err(|e| e.to_string())
    };
    let body = format!(
        "WorldBegin\n{}\nMaterial \"diffuse\" \"texture reflectance\" \"t\"\nShape \"sphere\"",
        texture("green.png")
    );
    let s = load(&body).unwrap().scene;
    assert_eq!(s.images.len(), 1);
    assert_eq!((s.images[0].width, s.images[0].texel(1)), (2, [0.0, 1.0, 0.0]));
    // pbrt's (u, v) mapping: scaled, then shifted by `udelta`, `vdelta`; and its wrap.
    let placed = load(&body.replace(
        "green.png\"",
        "green.png\" \"float uscale\" 2 \"float vscale\" 3 \"float udelta\" 0.25 \"float vdelta\" -0.5 \"string wrap\" \"black\"",
    ))
    .unwrap();
    assert!(!placed.warnings.iter().any(|w| w.to_string().contains("delta")), "{:?}", placed.warnings);
    let albedo = placed.scene.materials.iter().find_map(|m| match &m.bsdf {
        Some(BsdfDesc::Lambert { albedo: Texture::Image { scale, offset, .. } }) => Some((scale, offset)),
        _ => None,
    });
    let Some((scale, offset)) = albedo else { panic!("{:?}", placed.scene.materials) };
    assert_eq!((*scale, *offset), (alhazen_math::Vec2::new(2.0, 3.0), alhazen_math::Vec2::new(0.25, -0.5)));
    assert_eq!(placed.scene.images[0].wrap, [alhazen_scene::Wrap::Black; 2], "pbrt's wrap");
    let octahedral = load(&body.replace("green.png\"", "green.png\" \"string wrap\" \"octahedralsphere\"")).unwrap();
    assert_eq!(octahedral.scene.images[0].wrap, [alhazen_scene::Wrap::Repeat; 2]);
    assert!(octahedral.warnings.iter().any(|w| w.to_string().contains("\"octahedralsphere\" is read as repeat")));
    let err = load(&format!("WorldBegin\n{}\nNamedMaterial \"glod\"", texture("missing.png"))).unwrap_err();
    assert!(err.contains("a.pbrt:2:") && err.contains("cannot load image"), "{err}");
}

/// A texture the model holds constant (a checkerboard's squares) is replaced by the mean of its
/// image's pixels, read before the walk ends (not the placeholder that waits for the file,
/// which is black).
#[test]
fn a_texture_replaced_by_its_mean_is_read_first() {
    let dir = tempfile::tempdir().unwrap();
    let png = image::RgbImage::from_fn(2, 1, |x, _| image::Rgb(if x == 0 { [255, 0, 0] } else { [255, 255, 0] }));
    png.save(dir.path().join("rg.png")).unwrap();
    let body = "WorldBegin\nTexture \"t\" \"spectrum\" \"imagemap\" \"string filename\" \"rg.png\"\n\
                Texture \"c\" \"spectrum\" \"checkerboard\" \"texture tex1\" \"t\" \"rgb tex2\" [0 0 0]\n\
                Material \"diffuse\" \"texture reflectance\" \"c\"\n\
                Shape \"sphere\"";
    std::fs::write(dir.path().join("a.pbrt"), body).unwrap();
    let imported = alhazen_import::load(&dir.path().join("a.pbrt")).unwrap();
    let s = &imported.scene;
    let m = &s.materials[s.objects[0].material as usize];
    let Some(BsdfDesc::Lambert { albedo: Texture::Checker { even, odd, .. } }) = m.bsdf else { panic!("{:?}", m.bsdf) };
    assert_eq!((even, odd), (Vec3::new(1.0, 0.5, 0.0), Vec3::ZERO));
    assert!(imported.warnings.iter().any(|w| w.to_string().contains("replaced by its mean")));
}

/// A shape's `alpha`, a number or a float texture, cuts it out (pbrt's stochastic alpha: no
/// cutoff); shapes sharing a material and an alpha share one cut material.
#[test]
fn alpha_cuts_shapes_out() {
    let quad = r#"Shape "bilinearmesh" "point3 P" [0 0 0 1 0 0 0 1 0 1 1 0]"#;
    let text = format!(
        "WorldBegin\nTexture \"dots\" \"float\" \"checkerboard\" \"float tex1\" 1 \"float tex2\" 0\n\
         {quad} \"float alpha\" 0.25\n{quad} \"float alpha\" 0.25\n{quad} \"texture alpha\" \"dots\"\n{quad}\n"
    );
    let s = import(&[("a.pbrt", &text)]).unwrap().scene;
    let alpha = |o: usize| s.materials[s.objects[o].material as usize].alpha.clone();
    let quarter = alpha(0).expect("a cut-out");
    assert_eq!((quarter.coverage, quarter.cutoff), (Texture::Solid(Vec3::splat(0.25)), None));
    assert_eq!(s.objects[0].material, s.objects[1].material);
    assert!(matches!(alpha(2).map(|a| a.coverage), Some(Texture::Checker { .. })), "{:?}", alpha(2));
    assert_eq!(alpha(3), None);
}

/// pbrt's `lensradius` and `focaldistance` make a thin lens; a radius of 0 is a pinhole.
#[test]
fn lens_radius_makes_a_thin_lens() {
    let lens_of = |camera: &str| {
        let text =
            format!("LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\" {camera}\nWorldBegin\nShape \"sphere\"\n");
        match import(&[("c.pbrt", &text)]).unwrap().scene.camera {
            alhazen_scene::CameraDesc::Perspective { lens, .. } => lens,
            other => panic!("{other:?}"),
        }
    };
    let lens = lens_of("\"float lensradius\" 0.1 \"float focaldistance\" 4");
    assert_eq!(lens, Some(alhazen_scene::ThinLens { aperture: 0.1, focus_distance: 4.0 }));
    assert_eq!(lens_of("\"float lensradius\" 0"), None);
    assert_eq!(lens_of(""), None);
}

/// A negative or non-finite lens radius, and a focal distance that is not positive, are
/// located errors.
#[test]
fn lens_nonsense_is_refused() {
    for camera in ["\"float lensradius\" -0.1", "\"float lensradius\" 0.1 \"float focaldistance\" 0"] {
        let text = format!("Camera \"perspective\" {camera}\nWorldBegin\nShape \"sphere\"\n");
        let e = import(&[("c.pbrt", &text)]).unwrap_err();
        assert!(e.contains("c.pbrt:1") && e.contains("lensradius"), "{camera}: {e}");
    }
}

/// pbrt-v4's pixel filters with their own defaults (a Gaussian when the file names none), and a
/// filter alhazen does not know is a located error.
#[test]
fn pixel_filters_are_pbrt_s() {
    use alhazen_scene::PixelFilter;
    let filter = |line: &str| {
        let text = format!("{line}\nCamera \"perspective\"\nWorldBegin\n");
        import(&[("f.pbrt", &text)]).map(|s| {
            assert!(s.warnings.is_empty(), "{:?}", s.warnings);
            s.scene.render.filter
        })
    };
    assert_eq!(filter(""), Ok(PixelFilter::Gaussian { sigma: 0.5, radius: [1.5; 2] }));
    assert_eq!(filter("PixelFilter \"box\""), Ok(PixelFilter::PIXEL));
    assert_eq!(filter("PixelFilter \"triangle\" \"float xradius\" 1"), Ok(PixelFilter::Tent { radius: [1.0, 2.0] }));
    assert_eq!(
        filter("PixelFilter \"gaussian\" \"float sigma\" 0.3 \"float yradius\" 1"),
        Ok(PixelFilter::Gaussian { sigma: 0.3, radius: [1.5, 1.0] })
    );
    assert_eq!(
        filter("PixelFilter \"mitchell\" \"float B\" 0 \"float C\" 0.5"),
        Ok(PixelFilter::Mitchell { b: 0.0, c: 0.5, radius: [2.0; 2] })
    );
    assert_eq!(filter("PixelFilter \"sinc\""), Ok(PixelFilter::Lanczos { tau: 3.0, radius: [4.0; 2] }));
    let e = filter("PixelFilter \"blackman\"").unwrap_err();
    assert!(e.contains("f.pbrt:1:") && e.contains("unknown PixelFilter \"blackman\""), "{e}");
    let e = filter("PixelFilter \"box\" \"float xradius\" 0").unwrap_err();
    assert!(e.contains("f.pbrt:1:") && e.contains("radius must lie in"), "{e}");
}

/// `coatedconductor`: its interface as a clear coat (`interface.roughness`, `interface.eta`)
/// over the conductor of its `conductor.*` parameters (they were read as a plain conductor's,
/// and the coat dropped), with a warning that pbrt's bouncing between the layers is left out.
#[test]
fn a_coated_conductor_is_its_conductor_under_a_clear_coat() {
    use alhazen_scene::bsdf::{BsdfDesc, METALS};
    let imported = import(&[(
        "c.pbrt",
        r#"WorldBegin
Material "coatedconductor" "spectrum conductor.eta" "metal-Au-eta" "spectrum conductor.k" "metal-Au-k"
  "float conductor.roughness" 0.04 "float interface.eta" 1.6 "float thickness" 0.02
Shape "sphere""#,
    )])
    .unwrap();
    let s = &imported.scene;
    let bsdf = s.materials[s.objects[0].material as usize].bsdf.clone().unwrap();
    let BsdfDesc::Coated { base, weight, facets, ior, .. } = bsdf else { panic!("{bsdf:?}") };
    assert_eq!((weight, facets.alpha_u, ior), (1.0, 0.01, 1.6));
    let BsdfDesc::Conductor { facets: Some(metal), eta, .. } = *base else { panic!("{base:?}") };
    assert!((metal.alpha_u - 0.2).abs() < 1e-12 && eta == Vec3::from_array(METALS[0].1), "{metal:?} {eta}");
    let said: Vec<String> = imported.warnings.iter().map(|w| w.to_string()).collect();
    assert!(said.iter().any(|w| w.contains("c.pbrt:2") && w.contains("clear coat over its conductor")), "{said:?}");
    assert!(!said.iter().any(|w| w.contains("is not supported")), "{said:?}");
}

/// pbrt-v4's scenes give metals by spectrum files (`"spectrum eta" "spds/Au.eta.spd"`, pairs of
/// wavelength and value). Read as pbrt-v3 made its metals' RGB (the CIE integrals without an
/// illuminant, over ȳ's), pbrt's gold sampled every 25 nm gives the gold of alhazen's table
/// within 3 % — from a file and from the pairs written inline alike; an unreadable or
/// malformed file is a located error.
#[test]
fn spectrum_files_give_conductors_their_colour() {
    use alhazen_scene::bsdf::METALS;
    let eta = "350 1.7506 375 1.6972 400 1.6579 425 1.6202 450 1.5085 475 1.2635 500 0.8512 525 0.5192 550 0.3504 \
               575 0.2725 600 0.2203 625 0.1888 650 0.1678 675 0.1607 700 0.1605 725 0.1634 750 0.1691 775 0.1760 \
               800 0.1814 825 0.1876 850 0.1963";
    let k = "350 1.8457 375 1.9031 400 1.9560 425 1.9440 450 1.8788 475 1.7999 500 1.8868 525 2.2776 550 2.7141 \
             575 2.9329 600 3.0000 625 3.0632 650 3.1378 675 3.5374 700 3.9637 725 4.3012 750 4.5939 775 4.8611 \
             800 5.1268 825 5.3745 850 5.5884";
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("spds")).unwrap();
    std::fs::write(dir.path().join("spds/Au.eta.spd"), format!("# gold\n{}\n", eta.replace("  ", "\n"))).unwrap();
    std::fs::write(dir.path().join("spds/Au.k.spd"), k).unwrap();
    std::fs::write(dir.path().join("spds/bad.spd"), "400 1.0 500").unwrap();
    std::fs::write(dir.path().join("spds/nan.spd"), "400 1.0 500 NaN").unwrap();
    let load = |material: &str| {
        let text = format!("Camera \"perspective\"\nWorldBegin\nMaterial \"conductor\" {material}\nShape \"sphere\"");
        std::fs::write(dir.path().join("a.pbrt"), text).unwrap();
        alhazen_import::load(&dir.path().join("a.pbrt")).map_err(|e| e.to_string())
    };
    let from_files = load(r#""spectrum eta" "spds/Au.eta.spd" "spectrum k" "spds/Au.k.spd""#).unwrap();
    let inline = load(&format!("\"spectrum eta\" [ {eta} ] \"spectrum k\" [ {k} ]")).unwrap();
    for imported in [&from_files, &inline] {
        assert!(imported.warnings.is_empty(), "{:?}", imported.warnings);
        let s = &imported.scene;
        let Some(BsdfDesc::Conductor { eta, k, .. }) = s.materials[s.objects[0].material as usize].bsdf else {
            panic!("not a conductor")
        };
        let off = |a: Vec3, b: [f64; 3]| ((a - Vec3::from_array(b)) / Vec3::from_array(b)).abs().max_element();
        assert!(off(eta, METALS[0].1) < 0.03 && off(k, METALS[0].2) < 0.03, "{eta} {k}");
    }
    let err = load(r#""spectrum eta" "spds/bad.spd""#).unwrap_err();
    assert!(err.contains("a.pbrt:3:") && err.contains("must be two or more pairs"), "{err}");
    let err = load(r#""spectrum eta" "spds/nan.spd""#).unwrap_err();
    assert!(err.contains("a.pbrt:3:") && err.contains("must be two or more pairs"), "{err}");
    let err = load(r#""spectrum eta" [ 500 1 400 2 ]"#).unwrap_err();
    assert!(err.contains("a.pbrt:3:") && err.contains("increasing"), "{err}");
}

/// A `scale` texture of an image map (pbrt-v4's killeroo floors: `"float scale" 0.5` over
/// `textures/lines.png`) scales the image's texels; the image map itself, used elsewhere,
/// keeps its own.
#[test]
fn a_scaled_image_map_is_scaled() {
    let dir = tempfile::tempdir().unwrap();
    image::RgbImage::from_pixel(2, 1, image::Rgb([255, 255, 0])).save(dir.path().join("y.png")).unwrap();
    let body = "Camera \"perspective\"\nWorldBegin\nTexture \"grid\" \"spectrum\" \"imagemap\" \"string filename\" \"y.png\"\n\
                Texture \"half\" \"spectrum\" \"scale\" \"rgb scale\" [0.5 0.25 1] \"texture tex\" \"grid\"\n\
                Material \"diffuse\" \"texture reflectance\" \"half\"\nShape \"sphere\"\n\
                Material \"diffuse\" \"texture reflectance\" \"grid\"\nShape \"sphere\"";
    std::fs::write(dir.path().join("a.pbrt"), body).unwrap();
    let imported = alhazen_import::load(&dir.path().join("a.pbrt")).unwrap();
    assert!(imported.warnings.is_empty(), "{:?}", imported.warnings);
    let s = &imported.scene;
    let texel = |object: usize| match &s.materials[s.objects[object].material as usize].bsdf {
        Some(BsdfDesc::Lambert { albedo: Texture::Image { image, .. } }) => s.images[*image].texel(0),
        other => panic!("{other:?}"),
    };
    assert_eq!((texel(0), texel(1)), ([0.5, 0.25, 0.0], [1.0, 1.0, 0.0]));
}

/// `ReverseOrientation` turns a disk over: a disk light above the floor, reversed as pbrt-v4's
/// killeroo scenes reverse theirs, shines down on it; not reversed, it shines up and the floor
/// (the image's lowest rows, below the disk) stays dark.
#[test]
fn a_reversed_disk_light_shines_the_other_way() {
    let scene = |reverse: &str| {
        let text = format!(
            r#"LookAt 0 -4 3  0 0 0  0 0 1
Camera "perspective" "float fov" 50
WorldBegin
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [5 5 5]
  Translate 0 0 2
  {reverse}
  Shape "disk" "float radius" 1
AttributeEnd
Material "diffuse" "rgb reflectance" [0.5 0.5 0.5]
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3] "point3 P" [-3 -3 0 3 -3 0 3 3 0 -3 3 0]"#
        );
        let s = import(&[("a.pbrt", &text)]).unwrap();
        assert!(s.warnings.is_empty(), "{:?}", s.warnings);
        let img = small(s.scene, 4);
        (48..64).flat_map(|y| (0..64).map(move |x| (x, y))).map(|(x, y)| img.get(x, y).element_sum()).sum::<f64>()
    };
    let (down, up) = (scene("ReverseOrientation"), scene(""));
    assert!(down > 100.0 * up.max(1e-3), "{down} {up}");
}

/// A material's `displacement` (pbrt-v4's bump mapping; its contemporary-bathroom floors: a
/// `scale` of −0.05 over a float image map) bumps the shading normal by the image, the scale
/// its height: no scaled copy of the image is made for it. Where the same scaled texture is a
/// colour, one copy serves every material that uses it.
#[test]
fn displacement_maps_bump_and_scaled_textures_share_their_copy() {
    let dir = tempfile::tempdir().unwrap();
    image::RgbImage::from_fn(4, 4, |x, y| image::Rgb([(x * 60) as u8, (y * 60) as u8, 90]))
        .save(dir.path().join("b.png"))
        .unwrap();
    let head = "Camera \"perspective\"\nWorldBegin\nTexture \"base\" \"float\" \"imagemap\" \"string filename\" \"b.png\" \"float uscale\" 2\n\
                Texture \"bump\" \"float\" \"scale\" \"float scale\" -0.05 \"texture tex\" \"base\"\n";
    let load = |body: &str| {
        std::fs::write(dir.path().join("a.pbrt"), format!("{head}{body}")).unwrap();
        alhazen_import::load(&dir.path().join("a.pbrt")).unwrap()
    };
    let bumped = load("Material \"diffuse\" \"texture displacement\" \"bump\"\nShape \"sphere\"");
    assert!(bumped.warnings.is_empty(), "{:?}", bumped.warnings);
    let s = &bumped.scene;
    let bump = s.materials[s.objects[0].material as usize].bump.clone();
    let pattern = alhazen_scene::BumpPattern::Image { image: 0, scale: alhazen_math::Vec2::new(2.0, 1.0) };
    assert_eq!(bump, Some(alhazen_scene::Bump { height: -0.05, pattern }));
    assert_eq!(s.images.len(), 1, "no scaled copy for a displacement");
    let coloured = load(
        "Material \"diffuse\" \"texture reflectance\" \"bump\"\nShape \"sphere\"\n\
         Material \"coateddiffuse\" \"texture reflectance\" \"bump\"\nShape \"sphere\"",
    );
    assert_eq!(coloured.scene.images.len(), 2, "one copy for both materials");
    let (copy, image) = (coloured.scene.images[1].texel(5), coloured.scene.images[0].texel(5));
    assert!((0..3).all(|c| (copy[c] - -0.05 * image[c]).abs() < 1e-8), "{copy:?} {image:?}");
}

/// An image map's own `scale` and `invert` (`max(0, 1 − scale·v)`), and `mix` textures over
/// one image (pbrt-v4's kroken scene: an inverted float map mixing two colours, a wood image
/// half mixed with grey) change a copy of the image's values as pbrt evaluates them; a mix of
/// two images is the mix of their means (warning).
#[test]
fn image_map_scale_invert_and_mixes_change_the_image() {
    let dir = tempfile::tempdir().unwrap();
    image::RgbImage::from_fn(4, 1, |x, _| image::Rgb([(x * 80) as u8, 200, 30]))
        .save(dir.path().join("m.png"))
        .unwrap();
    let body = r#"Camera "perspective"
WorldBegin
Texture "plain" "spectrum" "imagemap" "string filename" "m.png"
Texture "bright" "spectrum" "imagemap" "string filename" "m.png" "float scale" 3
Texture "inv" "float" "imagemap" "string filename" "m.png" "bool invert" true "float scale" 0.5
Texture "blanket" "spectrum" "mix" "texture amount" "inv" "rgb tex2" [ .7 .7 .7 ] "rgb tex1" [ .85 .7 .6 ]
Texture "wood" "spectrum" "imagemap" "string filename" "m.png" "float scale" 1.1
Texture "wood-mixed" "spectrum" "mix" "texture tex1" "wood" "rgb tex2" [ .5 .5 .5 ] "float amount" .5
Texture "both" "spectrum" "mix" "texture tex1" "wood" "texture tex2" "plain"
"#;
    let shapes = ["plain", "bright", "blanket", "wood-mixed", "both"]
        .map(|t| format!("Material \"diffuse\" \"texture reflectance\" \"{t}\"\nShape \"sphere\"\n"))
        .concat();
    std::fs::write(dir.path().join("a.pbrt"), format!("{body}{shapes}")).unwrap();
    let imported = alhazen_import::load(&dir.path().join("a.pbrt")).unwrap();
    let said: Vec<String> = imported.warnings.iter().map(|w| w.to_string()).collect();
    assert!(said.len() == 1 && said[0].contains("a.pbrt:9") && said[0].contains("mix of their means"), "{said:?}");
    let s = &imported.scene;
    let albedo = |object: usize| match &s.materials[s.objects[object].material as usize].bsdf {
        Some(BsdfDesc::Lambert { albedo }) => albedo.clone(),
        other => panic!("{other:?}"),
    };
    let texels = |object: usize| match albedo(object) {
        Texture::Image { image, .. } => (0..4).map(|i| s.images[image].texel(i).map(f64::from)).collect::<Vec<_>>(),
        other => panic!("{other:?}"),
    };
    let plain = texels(0);
    let near = |a: &[[f64; 3]], f: &dyn Fn(usize, f64) -> f64| {
        a.iter().zip(&plain).all(|(a, p)| (0..3).all(|c| (a[c] - f(c, p[c])).abs() < 1e-6))
    };
    assert!(near(&texels(1), &|_, v| 3.0 * v), "{:?}", texels(1));
    let (c1, c2) = ([0.85, 0.7, 0.6], [0.7, 0.7, 0.7]);
    assert!(near(&texels(2), &|c, v| c1[c] + (c2[c] - c1[c]) * (1.0 - 0.5 * v).max(0.0)), "{:?}", texels(2));
    assert!(near(&texels(3), &|_, v| 0.5 * 1.1 * v + 0.25), "{:?}", texels(3));
    assert!(matches!(albedo(4), Texture::Solid(_)));
}

/// pbrt's `coateddiffuse` (a diffuse base under a dielectric interface, what pbrt-v4's converter
/// makes of pbrt-v3's `plastic`) is read as a plastic whose inner bounces are coloured by the
/// base: the layered physics a smooth or isotropic interface gives in closed form. A base of 0.5
/// under an interface of 1.5 then sends back `0.96 · 0.5 (1 − R_in)/(1 − 0.5 R_in)` ≈ 0.28 of
/// light arriving head-on; the Cook–Torrance it was read as before sent back 0.48. Stretched
/// facets give a layered Cook–Torrance, each with a warning.
#[test]
fn coated_diffuse_is_a_plastic() {
    let material = |params: &str| {
        let text = format!("WorldBegin\nMaterial \"coateddiffuse\" {params}\nShape \"sphere\"");
        let s = import(&[("c.pbrt", text.as_str())]).unwrap();
        let said: Vec<String> = s.warnings.iter().map(|w| w.to_string()).collect();
        (s.scene.materials[s.scene.objects[0].material as usize].bsdf.clone().unwrap(), said)
    };
    let (smooth, said) = material("\"rgb reflectance\" [0.5 0.5 0.5]");
    assert!(matches!(smooth, BsdfDesc::Plastic { ior: 1.5, facets: None, nonlinear: true, .. }), "{smooth:?}");
    assert!(said.iter().any(|w| w.contains("coateddiffuse is read as a plastic")), "{said:?}");
    let (rough, _) = material("\"float roughness\" 0.04 \"float eta\" 1.33");
    let BsdfDesc::Plastic { ior, facets: Some(f), .. } = rough else { panic!("{rough:?}") };
    assert_eq!((ior, f.alpha_u, f.alpha_v), (1.33, 0.2, 0.2));
    let (stretched, said) = material("\"float uroughness\" 0.01 \"float vroughness\" 0.09");
    assert!(matches!(stretched, BsdfDesc::CookTorrance { layered: true, .. }), "{stretched:?}");
    assert!(said.iter().any(|w| w.contains("stretched facets")), "{said:?}");
}

/// pbrt's `diffusetransmission` (leaves, paper): Lambert on the lit side and on the other, each
/// of its colour times `scale` — a sheet lit from behind shows its transmittance, where it was
/// read as Lambert reflection of the two summed and showed black.
#[test]
fn diffuse_transmission_passes_light_through() {
    let text = "LookAt 0 0 -3  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 20\n\
                Film \"rgb\" \"integer xresolution\" 16 \"integer yresolution\" 16\n\
                WorldBegin\nLightSource \"distant\" \"point3 from\" [0 0 5] \"point3 to\" [0 0 0] \"blackbody L\" 6500\n\
                Material \"diffusetransmission\" \"rgb reflectance\" [0.2 0.2 0.2] \"rgb transmittance\" [0.3 0.6 0.2] \"float scale\" 0.5\n\
                Shape \"bilinearmesh\" \"point3 P\" [-2 -2 0  2 -2 0  -2 2 0  2 2 0]";
    let s = import(&[("leaf.pbrt", text)]).unwrap();
    let Some(BsdfDesc::CookTorrance { albedo, ks, transmittance, .. }) =
        &s.scene.materials[s.scene.objects[0].material as usize].bsdf
    else {
        panic!()
    };
    assert_eq!((albedo, *ks), (&Texture::Solid(Vec3::splat(0.1)), 0.0));
    assert_eq!(transmittance, &Texture::Solid(Vec3::new(0.15, 0.3, 0.1)));
    // Lit from behind (the light at +z, the camera at −z): the sheet glows green.
    let mut scene = s.scene;
    scene.render.integrator = alhazen_scene::IntegratorKind::Path;
    let img = small(scene, 16);
    let c = img.get(8, 8);
    assert!(c.y > 0.05 && c.y > 1.5 * c.x && c.y > 2.0 * c.z, "{c}");
}
