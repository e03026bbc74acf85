//! The scene graph of the TOML format: groups instanced with transforms and parameters, nested
//! (a DAG), level of detail by projected size, shared meshes, and the errors for cycles, unknown
//! groups and parameters.

use alhazen_math::Vec3;
use alhazen_scene::{Shape, Texture, load_scene, parse_scene};
use std::path::Path;

fn err(text: &str) -> String {
    parse_scene(Path::new("g.toml"), text).unwrap_err().to_string()
}

#[test]
fn the_example_expands_groups_parameters_and_levels_of_detail() {
    let s = load_scene(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/scene-graph.toml")).unwrap();
    // A plane, two tables of a top and four legs, two vases.
    assert_eq!(s.objects.len(), 1 + 2 * 5 + 2);
    let tops: Vec<_> = s.objects.iter().filter(|o| matches!(o.shape, Shape::Box { .. })).take(2).collect();
    let color = |o: &alhazen_scene::Object| s.materials[o.material as usize].color.clone();
    assert_eq!(color(tops[0]), Texture::Solid(Vec3::new(0.55, 0.35, 0.2)), "the default parameter");
    assert_eq!(color(tops[1]), Texture::Solid(Vec3::new(0.2, 0.3, 0.6)), "the instance's parameter");
    // The high table's legs: the leg group scaled by the table's height, passed on as `$height`.
    let legs: Vec<_> = s.objects.iter().filter(|o| matches!(o.shape, Shape::Cylinder { .. })).collect();
    assert_eq!(legs.len(), 8);
    let leg_top = |i: usize| legs[i].transform.point(Vec3::Y).y;
    assert!((leg_top(0) - 0.75).abs() < 1e-12 && (leg_top(7) - 1.05).abs() < 1e-12, "{} {}", leg_top(0), leg_top(7));
    // The near vase covers more than 30 pixels and is the fine sphere; the far one is a box.
    let (near, far) = (&s.objects[s.objects.len() - 2], &s.objects[s.objects.len() - 1]);
    assert!(matches!(near.shape, Shape::Sphere { .. }), "{:?}", near.shape);
    assert!(matches!(far.shape, Shape::Box { .. }), "{:?}", far.shape);
    assert_eq!(far.transform.point(Vec3::ZERO), Vec3::new(4.0, 0.0, -40.0));
}

#[test]
fn instances_of_a_mesh_file_share_one_mesh() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("t.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let mut text = String::from("[[groups.tri.object]]\nshape = \"mesh\"\nfile = \"t.obj\"\n");
    for x in 0..5 {
        text += &format!("[[object]]\ngroup = \"tri\"\ntransform = [{{ translate = [{x}, 0, 0] }}]\n");
    }
    let p = dir.path().join("s.toml");
    std::fs::write(&p, text).unwrap();
    let s = load_scene(&p).unwrap();
    assert_eq!((s.objects.len(), s.meshes.len()), (5, 1));
}

#[test]
fn a_cycle_is_refused_naming_its_path() {
    let e = err(
        "[[groups.a.object]]\ngroup = \"b\"\n[[groups.b.object]]\ngroup = \"c\"\n[[groups.c.object]]\ngroup = \"a\"\n[[object]]\ngroup = \"a\"\n",
    );
    assert!(e.contains("the groups form a cycle: a → b → c → a"), "{e}");
    assert!(e.contains("g.toml:6:9"), "{e}");
}

#[test]
fn unknown_groups_and_parameters_are_located() {
    let e = err("[[groups.table.object]]\nshape = \"sphere\"\nradius = 1\n[[object]]\ngroup = \"tabel\"\n");
    assert!(e.contains("g.toml:5:9: unknown group \"tabel\"") && e.contains("did you mean \"table\"?"), "{e}");
    let e = err(
        "[groups.g]\nparameters = { size = 1 }\n[[groups.g.object]]\nshape = \"sphere\"\nradius = \"$size\"\n[[object]]\ngroup = \"g\"\nparameters = { sise = 2 }\n",
    );
    assert!(e.contains("group \"g\" has no parameter `sise`") && e.contains("did you mean `size`?"), "{e}");
    let e = err("[[groups.g.object]]\nshape = \"sphere\"\nradius = \"$r\"\n[[object]]\ngroup = \"g\"\n");
    assert!(e.contains("g.toml:3:10: `radius`: parameter `$r` has no value here"), "{e}");
    let e = err("[[object]]\nshape = \"sphere\"\nradius = \"$r\"\n");
    assert!(e.contains("not inside a group"), "{e}");
}

#[test]
fn parameters_reach_nested_groups_and_materials() {
    let s = parse_scene(
        Path::new("g.toml"),
        r#"
[materials.red]
color = [1, 0, 0]
[materials.blue]
color = [0, 0, 1]
[groups.ball]
parameters = { r = 1, paint = "red" }
[[groups.ball.object]]
shape = "sphere"
radius = "$r"
material = "$paint"
[groups.pair]
parameters = { paint = "red" }
[[groups.pair.object]]
group = "ball"
parameters = { paint = "$paint", r = 0.5 }
[[groups.pair.object]]
group = "ball"
parameters = { paint = "$paint" }
transform = [{ translate = [3, 0, 0] }]
[[object]]
group = "pair"
parameters = { paint = "blue" }
"#,
    )
    .unwrap();
    assert_eq!(s.objects.len(), 2);
    assert!(matches!(s.objects[0].shape, Shape::Sphere { radius, .. } if radius == 0.5));
    assert!(matches!(s.objects[1].shape, Shape::Sphere { radius, .. } if radius == 1.0));
    for o in &s.objects {
        assert_eq!(s.materials[o.material as usize].name, "blue");
    }
}
