//! The `alhazen` binary as a user meets it: exit codes, messages pointing into the scene file,
//! and files written completely or not at all.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn alhazen(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_alhazen")).args(args).output().expect("the binary runs")
}

fn scene_file(dir: &Path, text: &str) -> PathBuf {
    let p = dir.join("scene.toml");
    std::fs::write(&p, text).unwrap();
    p
}

/// Renders `text` into a temp dir and returns (exit code, stderr, whether an output exists).
fn render(text: &str, extra: &[&str]) -> (i32, String, bool) {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene_file(dir.path(), text);
    let out = dir.path().join("out.png");
    let mut args = vec!["render", scene.to_str().unwrap(), "-o", out.to_str().unwrap(), "--quiet"];
    args.extend_from_slice(extra);
    let o = alhazen(&args);
    (o.status.code().unwrap_or(-1), String::from_utf8_lossy(&o.stderr).into_owned(), out.exists())
}

const OK: &str = "[render]\nwidth = 16\nheight = 12\nspp = 1\n[camera]\neye = [0, 0, 5]\n[[light]]\ntype = \"point\"\nposition = [3, 3, 3]\n[[object]]\nshape = \"sphere\"\nradius = 1\n";

#[test]
fn renders_a_png() {
    let (code, err, exists) = render(OK, &[]);
    assert_eq!(code, 0, "{err}");
    assert!(exists);
}

#[test]
fn integrator_and_sampler_can_be_chosen_on_the_command_line() {
    for extra in [
        &["--integrator", "path"][..],
        &["--integrator", "path", "--sampler", "independent"],
        &["--integrator", "whitted"],
    ] {
        let (code, err, exists) = render(OK, extra);
        assert_eq!(code, 0, "{extra:?}: {err}");
        assert!(exists);
    }
    let (code, err, exists) = render(OK, &["--integrator", "bdpt"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("possible values: whitted, path"), "{err}");
    assert!(!exists);
}

/// The summary line tells the render's time and the part of it that built the world, in the
/// form the suite's script reads (bench/mitsuba/suite.py).
#[test]
fn summary_tells_the_time_that_built_the_world() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene_file(dir.path(), OK);
    let out = dir.path().join("out.png");
    let o = alhazen(&["render", scene.to_str().unwrap(), "-o", out.to_str().unwrap(), "--threads", "1"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{err}");
    let line = err.lines().find(|l| l.starts_with("rendered ")).unwrap_or_else(|| panic!("no summary: {err}"));
    let seconds = |before: &str| -> f64 {
        let at = line.find(before).unwrap_or_else(|| panic!("no {before:?} in {line}"));
        line[..at].rsplit(' ').next().unwrap().parse().unwrap()
    };
    let (total, building) = (seconds(" s on 1 thread,"), seconds(" s of it building the world"));
    assert!(building >= 0.0 && building <= total, "{line}");
}

/// `--kernel portable` runs on every processor and renders the bits the default kernel does
/// (the path tracer, whose Lambertian scenes the wider kernels trace in lanes).
#[test]
fn every_kernel_renders_the_same_image() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene_file(dir.path(), OK);
    let image = |kernel: &[&str]| {
        let out = dir.path().join("out.exr");
        let mut args = vec!["render", scene.to_str().unwrap(), "-o", out.to_str().unwrap(), "--quiet"];
        args.extend_from_slice(&["--integrator", "path", "--spp", "9"]);
        args.extend_from_slice(kernel);
        let o = alhazen(&args);
        assert_eq!(o.status.code(), Some(0), "{kernel:?}: {}", String::from_utf8_lossy(&o.stderr));
        std::fs::read(&out).unwrap()
    };
    assert_eq!(image(&[]), image(&["--kernel", "portable"]));
    let (code, err, exists) = render(OK, &["--kernel", "sse9"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("possible values: portable, avx2, avx512"), "{err}");
    assert!(!exists);
}

#[test]
fn raster_preview_writes_an_image_and_refuses_unsupported_cameras() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene_file(dir.path(), OK);
    let out = dir.path().join("preview.png");
    for shading in ["flat", "gouraud", "phong"] {
        let o = alhazen(&[
            "raster",
            scene.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--shading",
            shading,
            "--wireframe",
        ]);
        assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
        assert!(String::from_utf8_lossy(&o.stderr).contains("fps"));
    }
    assert!(out.exists());
    let pano = scene_file(dir.path(), "[camera]\ntype = \"panorama\"\neye = [0, 0, 5]\n[[object]]\nshape = \"box\"\n");
    let o = alhazen(&["raster", pano.to_str().unwrap(), "-o", dir.path().join("p.png").to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let stereo = scene_file(dir.path(), "[camera]\ntype = \"stereo\"\neye = [0, 0, 5]\n[[object]]\nshape = \"box\"\n");
    let o =
        alhazen(&["raster", stereo.to_str().unwrap(), "-o", dir.path().join("s.png").to_str().unwrap(), "--anaglyph"]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let mono = scene_file(dir.path(), "[camera]\neye = [0, 0, 5]\n[[object]]\nshape = \"box\"\n");
    let o =
        alhazen(&["raster", mono.to_str().unwrap(), "-o", dir.path().join("a.png").to_str().unwrap(), "--anaglyph"]);
    assert_eq!(o.status.code(), Some(2), "--anaglyph without a stereo camera");
    assert!(String::from_utf8_lossy(&o.stderr).contains("needs a stereo camera"));
    assert!(!dir.path().join("a.png").exists());
}

#[test]
fn view_needs_a_display_and_a_supported_camera() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene_file(dir.path(), OK);
    // Without an X server the window cannot open: a clear error, exit code 1.
    let o = Command::new(env!("CARGO_BIN_EXE_alhazen"))
        .args(["view", scene.to_str().unwrap(), "--screenshot", dir.path().join("s.png").to_str().unwrap()])
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stderr).contains("cannot open a window"));
    let pano = scene_file(dir.path(), "[camera]\ntype = \"panorama\"\neye = [0, 0, 5]\n");
    let o = alhazen(&["view", pano.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn view_draws_frames_under_xvfb_when_it_is_installed() {
    // `apt-get install xvfb` makes this run; the screenshot is the frame the window showed.
    if Command::new("xvfb-run").arg("--help").output().is_err() {
        eprintln!("xvfb-run not installed: the window test needs an X server");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let scene = scene_file(dir.path(), OK);
    let shot = dir.path().join("shot.png");
    let o = Command::new("xvfb-run")
        .args(["-a", env!("CARGO_BIN_EXE_alhazen"), "view", scene.to_str().unwrap(), "--screenshot"])
        .arg(&shot)
        .args(["--frames", "3"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(shot.exists());
}

#[test]
fn bad_toml_points_at_the_line() {
    let (code, err, exists) = render("[render]\nwidth = = 3\n", &[]);
    assert_eq!(code, 2);
    assert!(err.contains("scene.toml:2:"), "{err}");
    assert!(err.contains("TOML syntax error"), "{err}");
    assert!(!exists);
}

#[test]
fn unknown_key_suggests_the_right_one() {
    let (code, err, _) = render(&OK.replace("radius = 1", "radus = 1"), &[]);
    assert_eq!(code, 2);
    assert!(err.contains("scene.toml:12:1: unknown key `radus`"), "{err}");
    assert!(err.contains("did you mean `radius`?"), "{err}");
    assert!(err.contains("12 | radus = 1\n   | ^^^^^"), "caret under the key: {err}");
}

#[test]
fn negative_radius_is_refused() {
    let (code, err, _) = render(&OK.replace("radius = 1", "radius = -1"), &[]);
    assert_eq!(code, 2);
    assert!(err.contains("scene.toml:12:10: `radius` must be positive, found -1"), "{err}");
}

#[test]
fn absurd_resolution_is_refused_before_allocating() {
    let (code, err, _) =
        render(&OK.replace("width = 16", "width = 60000").replace("height = 12", "height = 60000"), &[]);
    assert_eq!(code, 2);
    assert!(err.contains("more than the"), "{err}");
    let (code, err, _) = render(OK, &["--width", "65536", "--height", "65536"]);
    assert_eq!(code, 2, "{err}");
    let (code, _, _) = render(OK, &["--width", "0"]);
    assert_eq!(code, 2);
}

#[test]
fn missing_scene_file() {
    let o = alhazen(&["render", "/nonexistent/scene.toml", "-o", "/tmp/x.png"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("cannot read /nonexistent/scene.toml"));
}

#[test]
fn unknown_material_and_enum_values_get_suggestions() {
    let (code, err, _) = render(&OK.replace("shape = \"sphere\"", "shape = \"spere\""), &[]);
    assert_eq!(code, 2);
    assert!(err.contains("did you mean \"sphere\"?"), "{err}");
    let (code, err, _) = render(&format!("{OK}material = \"glas\"\n[materials.glass]\nior = 1.5\n"), &[]);
    assert_eq!(code, 2, "{err}");
}

#[test]
fn unknown_output_format_fails_before_rendering() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene_file(dir.path(), OK);
    let o = alhazen(&["render", scene.to_str().unwrap(), "-o", dir.path().join("x.jpg").to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("unknown image format"));
}

#[test]
fn failed_write_keeps_the_old_file() {
    // The output path is a directory: the write fails, nothing is half-written.
    let dir = tempfile::tempdir().unwrap();
    let scene = scene_file(dir.path(), OK);
    let target = dir.path().join("taken.png");
    std::fs::create_dir(&target).unwrap();
    let o = alhazen(&["render", scene.to_str().unwrap(), "-o", target.to_str().unwrap(), "--quiet"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(target.is_dir());
    let leftovers: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().contains(".part"))
        .collect();
    assert!(leftovers.is_empty());
}

/// An output that cannot be created is refused before the work (exit 2), naming the user's
/// path, not the hidden temporary file (`/proc` takes no new files, even from root).
#[test]
fn unwritable_output_is_refused_before_rendering() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene_file(dir.path(), OK);
    for command in ["render", "raster"] {
        let o = alhazen(&[command, scene.to_str().unwrap(), "-o", "/proc/alhazen-out.png", "--quiet"]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{command}: {err}");
        assert!(err.contains("cannot write /proc/alhazen-out.png") && !err.contains(".alhazen-"), "{command}: {err}");
    }
}

/// Inputs that used to be accepted though meaningless (issue 22) are refused with exit 2 and a
/// message saying what is expected; `--depth 0` (emitters only) is accepted like `max_depth = 0`.
#[test]
fn meaningless_inputs_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let scene = scene_file(dir.path(), OK);
    let s = scene.to_str().unwrap();
    let empty = dir.path().join("empty.toml");
    std::fs::write(&empty, "\n  \n").unwrap();
    std::fs::write(dir.path().join("two.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\nf 1 2 3\n").unwrap();
    let lines_obj = dir.path().join("obj.toml");
    std::fs::write(&lines_obj, "[[object]]\nshape = \"mesh\"\nfile = \"two.obj\"\n").unwrap();
    std::fs::write(dir.path().join("sail.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let csg = dir.path().join("csg.toml");
    std::fs::write(&csg, "[[object]]\nshape = \"csg\"\nop = \"union\"\na = { shape = \"mesh\", file = \"sail.obj\" }\nb = { shape = \"sphere\" }\n").unwrap();
    let huge = dir.path().join("huge.toml");
    std::fs::write(&huge, "[[object]]\nshape = \"sphere\"\ncenter = [1e308, 0, 0]\n").unwrap();
    let profile = dir.path().join("profile.toml");
    std::fs::write(&profile, "[[object]]\nshape = \"revolution\"\nprofile = [[1, 0], [-0.5, 1], [1, 2]]\n").unwrap();
    let guide = dir.path().join("guide.toml");
    std::fs::write(&guide, "[[object]]\nshape = \"sweep\"\nguide = [[0, 0, 0], [1, 0, 0], [1, 0, 0], [2, 1, 0]]\n")
        .unwrap();
    let glass = dir.path().join("glass.toml");
    std::fs::write(&glass, "[materials.m]\ntransparency = [0.5, 2, 0.5]\n").unwrap();
    let cases: Vec<(Vec<String>, &str)> = vec![
        (
            vec!["mirror".into(), "caustic".into(), "--eye-distance".into(), "3".into(), "-o".into(), out("c.png")],
            "name the output .svg",
        ),
        (
            vec![
                "mirror".into(),
                "conics".into(),
                "--eye".into(),
                "3,0".into(),
                "--point".into(),
                "1,1".into(),
                "-o".into(),
                out("c.pdf"),
            ],
            "name the output .svg",
        ),
        (
            vec!["lines".into(), s.into(), "-o".into(), out("l.svg"), "--feature-angle".into(), "nan".into()],
            "angle from 0 to 180",
        ),
        (
            vec!["lines".into(), s.into(), "-o".into(), out("l.svg"), "--width-mm".into(), "1e308".into()],
            "1e308 mm is wider",
        ),
        (vec!["render".into(), "/dev/zero".into(), "-o".into(), out("z.png")], "not a regular file"),
        (vec!["render".into(), empty.to_str().unwrap().into(), "-o".into(), out("e.png")], "the scene file is empty"),
        (vec!["render".into(), glass.to_str().unwrap().into(), "-o".into(), out("g.png")], "must lie in [0, 1]"),
        (vec!["render".into(), profile.to_str().unwrap().into(), "-o".into(), out("p.png")], "cannot be negative"),
        (
            vec!["render".into(), lines_obj.to_str().unwrap().into(), "-o".into(), out("o.png")],
            "line 4: a face needs at least 3 vertices",
        ),
        (
            vec!["render".into(), guide.to_str().unwrap().into(), "-o".into(), out("s.png")],
            "guide points 2 and 3 coincide",
        ),
        (
            vec!["render".into(), s.into(), "-o".into(), out("n.png"), "--seed".into(), "-1".into()],
            "a seed is a whole number",
        ),
        (
            vec![
                "mirror".into(),
                "caustic".into(),
                "--radius".into(),
                "-40".into(),
                "--eye-distance".into(),
                "3".into(),
                "-o".into(),
                out("c.svg"),
            ],
            "--radius must be positive",
        ),
    ];
    for (args, expected) in cases {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let o = alhazen(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(expected), "{args:?}: {err}");
    }
    let o = alhazen(&["render", s, "-o", &out("d.png"), "--depth", "0", "--quiet"]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
}

/// A scene lit only by emitting objects, rendered by a renderer that ignores them, says so
/// (issue 21: the black Whitted Cornell box and preview); the path tracer does not warn.
#[test]
fn renderers_that_ignore_emitters_say_so() {
    let dir = tempfile::tempdir().unwrap();
    let cornell = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-box.toml");
    let c = cornell.to_str().unwrap();
    let out = dir.path().join("x.png");
    let o = out.to_str().unwrap();
    let small = ["--width", "16", "--height", "16", "-q"];
    let run = |args: &[&str]| String::from_utf8_lossy(&alhazen(&[args, &small[..]].concat()).stderr).into_owned();
    assert!(
        !run(&["render", c, "-o", o, "--integrator", "whitted"]).contains("warning"),
        "Whitted lights with the lamp"
    );
    let tube = scene_file(
        dir.path(),
        "[[object]]\nshape = \"cylinder\"\nradius = 0.2\nmaterial = { emission = [4, 4, 4] }\n[[object]]\nshape = \"box\"\n",
    );
    let said = run(&["render", tube.to_str().unwrap(), "-o", o, "--integrator", "whitted"]);
    assert!(said.contains("1 emitting object(s) light nothing") && said.contains("use --integrator path"), "{said}");
    assert!(!run(&["raster", c, "-o", o]).contains("warning"), "the preview lights with the lamp");
    assert!(!run(&["render", c, "-o", o, "--spp", "1"]).contains("warning"));
}

#[test]
fn help_shows_an_example() {
    let o = alhazen(&["render", "--help"]);
    assert!(String::from_utf8_lossy(&o.stdout).contains("alhazen render scenes/glass-balls.toml -o glass-balls.png"));
}

#[test]
fn every_example_scene_parses() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let mut n = 0;
    for entry in walk(&dir) {
        if entry.extension().is_some_and(|e| e == "toml") {
            alhazen_scene::load_scene(&entry).unwrap_or_else(|e| panic!("{e}"));
            n += 1;
        }
    }
    assert!(n >= 15, "found {n} scenes");
}

fn walk(dir: &Path) -> Vec<PathBuf> {
    let mut out = vec![];
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let p = e.path();
        if p.is_dir() { out.extend(walk(&p)) } else { out.push(p) }
    }
    out
}

mod mirror {
    use super::alhazen;
    use std::io::Write;
    use std::process::{Command, Stdio};

    fn reflex(input: &str) -> (i32, Vec<serde_json::Value>) {
        let mut child = Command::new(env!("CARGO_BIN_EXE_alhazen"))
            .args(["mirror", "reflex"])
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        child.stdin.take().unwrap().write_all(input.as_bytes()).unwrap();
        let out = child.wait_with_output().unwrap();
        let lines = String::from_utf8(out.stdout).unwrap().lines().map(|l| serde_json::from_str(l).unwrap()).collect();
        (out.status.code().unwrap(), lines)
    }

    #[test]
    fn json_lines_in_json_lines_out() {
        let (code, lines) = reflex(concat!(
            r#"{"mirror":"sphere","center":[0,0,0],"radius":1,"eye":[0,0,5],"point":[3,0,4]}"#,
            "\n",
            r#"{"mirror":"cylinder","center":[0,0,0],"axis":[0,1,0],"radius":1,"eye":[0,1,6],"point":[2,3,1]}"#,
            "\n"
        ));
        assert_eq!(code, 0);
        assert_eq!(lines.len(), 2);
        let v = &lines[0]["reflexes"][0];
        let p: Vec<f64> = v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
        // Eye and point at equal distance 5 from the centre, 36.87° apart: the reflex bisects.
        let half = (3f64.atan2(4.0) / 2.0).tan();
        assert!((p[0] / p[2] - half).abs() < 1e-12, "{p:?}");
        assert_eq!(lines[0]["all"].as_array().unwrap().len(), 4);
        assert_eq!(lines[1]["reflexes"].as_array().unwrap().len(), 1);
    }

    /// A polygon's overlap test (Theorems 7–9): a panel across a mirror cylinder splits along
    /// its plane's projecting lines; bad polygons and an eye at infinity are refused per line.
    #[test]
    fn a_polygon_across_a_mirror_is_split_along_its_projecting_lines() {
        let panel = r#""polygon":[[-2,0.6,-1],[2,0.6,-1],[2,1.6,1.5],[-2,1.6,1.5]]"#;
        let (code, lines) = reflex(&format!(
            "{{\"mirror\":\"cylinder\",\"center\":[0,0,0],\"axis\":[0,1,0],\"radius\":0.7,\"eye\":[1.5,3.5,7],{panel}}}\n\
             {{\"mirror\":\"sphere\",\"center\":[0,0,0],\"radius\":1,\"eye_direction\":[0,0,1],{panel}}}\n\
             {{\"mirror\":\"sphere\",\"center\":[0,0,0],\"radius\":1,\"eye\":[0,0,5],\"polygon\":[[0,0,0],[1,1,1],[2,2,2]]}}\n\
             {{\"mirror\":\"sphere\",\"center\":[0,0,0],\"radius\":1,\"eye\":[0,0,5],\"polygon\":[[0,0,0],[1,0,0],[0,1,0],[0,0,1]]}}\n"
        ));
        assert_eq!(code, 2);
        let projecting = lines[0]["projecting_lines"].as_array().unwrap();
        assert_eq!(projecting.len(), 2, "{}", lines[0]);
        assert!(lines[0]["pieces"].as_array().unwrap().len() >= 3, "{}", lines[0]);
        assert!(lines[1]["error"].as_str().unwrap().contains("finite \"eye\""));
        assert!(lines[2]["error"].as_str().unwrap().contains("no area"));
        assert!(lines[3]["error"].as_str().unwrap().contains("one plane"));
    }

    #[test]
    fn reflexes_do_not_depend_on_the_scale() {
        // The same configuration at radius 1, 1e-300 and 1e150: the answers scale with it
        // (the solver's tolerances are absolute; a tiny or huge mirror used to find nothing).
        let at = |s: f64| {
            let q = format!(
                r#"{{"mirror":"sphere","center":[{c},0,0],"radius":{s:e},"eye":[{c},0,{e:e}],"point":[{px:e},0,{pz:e}]}}"#,
                c = 7.0 * s,
                e = 5.0 * s,
                px = 10.0 * s,
                pz = 4.0 * s
            );
            let (code, lines) = reflex(&format!("{q}\n"));
            assert_eq!(code, 0, "{q}");
            let p: Vec<f64> = lines[0]["reflexes"][0].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
            [p[0] / s - 7.0, p[1] / s, p[2] / s]
        };
        let unit = at(1.0);
        for s in [1e-300, 1e150] {
            let scaled = at(s);
            assert!((0..3).all(|k| (scaled[k] - unit[k]).abs() < 1e-12), "{s}: {scaled:?} vs {unit:?}");
        }
        let (code, lines) = reflex(concat!(
            r#"{"mirror":"sphere","center":[0,0,0],"radius":1e-300,"eye":[0,0,5],"point":[3,0,4]}"#,
            "\n"
        ));
        assert_eq!(code, 2);
        assert!(lines[0]["error"].as_str().unwrap().contains("more than 1e100 radii"), "{lines:?}");
    }

    /// Eyes and points at infinity (the paper's equation (7)): the reflex of a direction seen
    /// from a direction bisects them, and matches a point far along that direction; a site is
    /// given once, as a point or as a non-zero direction.
    #[test]
    fn eyes_and_points_at_infinity() {
        let first = |line: &serde_json::Value| -> Vec<f64> {
            line["reflexes"][0].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
        };
        let (code, lines) = reflex(concat!(
            r#"{"mirror":"sphere","center":[1,2,3],"radius":2,"eye_direction":[0,0,1],"point_direction":[1,0,1]}"#,
            "\n",
            r#"{"mirror":"sphere","center":[0,0,0],"radius":1,"eye_direction":[0,0,1],"point":[3,0,4]}"#,
            "\n",
            r#"{"mirror":"sphere","center":[0,0,0],"radius":1,"eye":[0,0,1e9],"point":[3,0,4]}"#,
            "\n",
            r#"{"mirror":"cylinder","center":[0,0,0],"axis":[0,1,0],"radius":1,"eye_direction":[0,1,3],"point":[2,3,1]}"#,
            "\n",
            r#"{"mirror":"cylinder","center":[0,0,0],"axis":[0,1,0],"radius":1,"eye":[0,1e9,3e9],"point":[2,3,1]}"#,
            "\n",
        ));
        assert_eq!(code, 0, "{lines:?}");
        let p = first(&lines[0]);
        let bisector = std::f64::consts::FRAC_PI_8;
        let expected = [1.0 + 2.0 * bisector.sin(), 2.0, 3.0 + 2.0 * bisector.cos()];
        assert!((0..3).all(|k| (p[k] - expected[k]).abs() < 1e-12), "{p:?}");
        for (infinite, far) in [(1, 2), (3, 4)] {
            let (a, b) = (first(&lines[infinite]), first(&lines[far]));
            assert!((0..3).all(|k| (a[k] - b[k]).abs() < 1e-6), "{a:?} vs {b:?}");
        }
        let (code, lines) = reflex(concat!(
            r#"{"mirror":"sphere","center":[0,0,0],"radius":1,"eye":[0,0,5],"eye_direction":[0,0,1],"point":[3,0,4]}"#,
            "\n",
            r#"{"mirror":"sphere","center":[0,0,0],"radius":1,"point":[3,0,4]}"#,
            "\n",
            r#"{"mirror":"sphere","center":[0,0,0],"radius":1,"eye":[0,0,5],"point_direction":[0,0,0]}"#,
            "\n",
        ));
        assert_eq!(code, 2);
        assert!(lines[0]["error"].as_str().unwrap().contains("not both"), "{lines:?}");
        assert!(lines[1]["error"].as_str().unwrap().contains("eye_direction"), "{lines:?}");
        assert!(lines[2]["error"].as_str().unwrap().contains("non-zero"), "{lines:?}");
    }

    #[test]
    fn bad_lines_are_reported_and_skipped() {
        let (code, lines) = reflex(concat!(
            "not json\n",
            r#"{"mirror":"sphere","center":[0,0,0],"radius":-1,"eye":[0,0,5],"point":[3,0,4]}"#,
            "\n",
            r#"{"mirror":"sphere","center":[0,0,0],"radius":1,"eye":[0,0,5],"point":[0,0,-3]}"#,
            "\n"
        ));
        assert_eq!(code, 2);
        assert_eq!(lines[0]["line"], 1);
        assert!(lines[1]["error"].as_str().unwrap().contains("radius"));
        // The error names the column only: the line is the reply's `line` (a mixed file used to
        // say "line 1" in the text of an error on line 2).
        let (_, mixed) = reflex(concat!(
            r#"{"mirror":"sphere","center":[0,0,0],"radius":1,"eye":[0,0,5],"point":[3,0,4]}"#,
            "
not json
"
        ));
        assert_eq!(mixed[1]["line"], 2);
        assert_eq!(mixed[1]["error"], "column 2: expected ident");
        // Straight behind the ball: forbidden, no visible reflex, but other solutions.
        assert_eq!(lines[2]["reflexes"].as_array().unwrap().len(), 0);
        assert!(!lines[2]["all"].as_array().unwrap().is_empty());
    }

    /// `--surface` writes the sphere's caustic surface as a mesh: for parallel light inside the
    /// sphere the nephroid turned about the axis, whose cusp lies on the axis at r/2 from the
    /// centre (the paraxial focus); it refuses an output that is not .ply.
    #[test]
    fn caustic_surfaces_are_meshes() {
        let dir = tempfile::tempdir().unwrap();
        let ply = dir.path().join("nephroid.ply");
        let args = ["mirror", "caustic", "--radius", "2", "--eye-distance", "inf", "--inside", "--surface", "-o"];
        let o = alhazen(&[&args[..], &[ply.to_str().unwrap()]].concat());
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let mesh = alhazen_scene::import::load_mesh(&ply).unwrap().mesh;
        assert!(mesh.triangle_count() > 10_000);
        let near_axis: Vec<f64> = mesh.positions.iter().filter(|p| p.y.hypot(p.z) < 1e-3).map(|p| p.x.abs()).collect();
        assert!(!near_axis.is_empty() && near_axis.iter().all(|x| (x - 1.0).abs() < 1e-2), "{near_axis:?}");
        assert!(mesh.positions.iter().all(|p| p.is_finite() && p.length() <= 2.0 + 1e-9));
        let svg = dir.path().join("nephroid.svg");
        let o = alhazen(&[&args[..], &[svg.to_str().unwrap()]].concat());
        assert_eq!(o.status.code(), Some(2));
        assert!(String::from_utf8_lossy(&o.stderr).contains(".ply"));
        assert!(!svg.exists());
    }

    #[test]
    fn figures_are_written() {
        let dir = tempfile::tempdir().unwrap();
        let f = dir.path().join("c.svg");
        let o = alhazen(&["mirror", "caustic", "--radius", "1", "--eye-distance", "inf", "-o", f.to_str().unwrap()]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        assert!(std::fs::read_to_string(&f).unwrap().starts_with("<svg"));
        let o = alhazen(&["mirror", "caustic", "--radius", "1", "--eye-distance", "0.5", "-o", f.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(2), "an eye inside needs --inside");
        let g = dir.path().join("g.svg");
        let o = alhazen(&["mirror", "conics", "--eye", "3,0", "--point", "-1.2,1.8", "-o", g.to_str().unwrap()]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let o = alhazen(&["mirror", "conics", "--eye", "3", "--point", "1,1", "-o", g.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(2));
    }
}

#[test]
fn lines_writes_svg_pdf_and_png_and_refuses_bad_input() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene_file(
        dir.path(),
        "[render]\nwidth = 200\nheight = 150\n[camera]\neye = [4, 3, 5]\n[[object]]\nshape = \"box\"\n\
         [[object]]\nshape = \"sphere\"\ncenter = [2.2, 0, 0]\nradius = 0.8\nmaterial = { mirror = 1 }\n",
    );
    for ext in ["svg", "pdf", "png"] {
        let out = dir.path().join(format!("d.{ext}"));
        let o = alhazen(&["lines", scene.to_str().unwrap(), "-o", out.to_str().unwrap(), "--hidden"]);
        assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
        let bytes = std::fs::read(&out).unwrap();
        match ext {
            "svg" => {
                let s = String::from_utf8(bytes).unwrap();
                assert!(s.contains("<g id=\"visible\"") && s.matches("<polyline").count() >= 9, "{s}");
                assert!(s.contains("<g id=\"reflected\""));
            }
            "pdf" => assert!(bytes.starts_with(b"%PDF-1.5") && bytes.ends_with(b"%%EOF\n")),
            _ => assert!(bytes.starts_with(b"\x89PNG")),
        }
    }
    let bad_ext = alhazen(&["lines", scene.to_str().unwrap(), "-o", dir.path().join("d.jpg").to_str().unwrap()]);
    assert_eq!(bad_ext.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad_ext.stderr).contains(".svg, .pdf, .hpgl, .plt or .png"));
    let graph = alhazen(&["lines", "--graph", "saddle", "-o", dir.path().join("g.svg").to_str().unwrap(), "-q"]);
    assert_eq!(graph.status.code(), Some(0));
    let stereo = scene_file(dir.path(), "[camera]\ntype = \"stereo\"\neye = [0, 0, 5]\n[[object]]\nshape = \"box\"\n");
    let pair = dir.path().join("s.svg");
    let o = alhazen(&["lines", stereo.to_str().unwrap(), "-o", pair.to_str().unwrap(), "--width-mm", "100"]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(std::fs::read_to_string(&pair).unwrap().contains("width=\"200.000mm\""), "two 100 mm views side by side");
    let glyph = dir.path().join("a.svg");
    let o =
        alhazen(&["lines", stereo.to_str().unwrap(), "-o", glyph.to_str().unwrap(), "--width-mm", "100", "--anaglyph"]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let svg = std::fs::read_to_string(&glyph).unwrap();
    assert!(
        svg.contains("width=\"100.000mm\"")
            && svg.contains("inkscape:label=\"4 left\" fill=\"none\" stroke=\"rgb(255,0,0)\"")
    );
    let mono = scene_file(dir.path(), "[camera]\neye = [0, 0, 5]\n[[object]]\nshape = \"box\"\n");
    let o = alhazen(&["lines", mono.to_str().unwrap(), "-o", glyph.to_str().unwrap(), "--anaglyph"]);
    assert_eq!(o.status.code(), Some(2), "--anaglyph without a stereo camera");
    assert!(String::from_utf8_lossy(&o.stderr).contains("needs a stereo camera"));
    let pano = scene_file(dir.path(), "[camera]\ntype = \"panorama\"\neye = [0, 0, 5]\n[[object]]\nshape = \"box\"\n");
    let o = alhazen(&["lines", pano.to_str().unwrap(), "-o", dir.path().join("p.svg").to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "a panorama is drawn: {}", String::from_utf8_lossy(&o.stderr));
    assert!(std::fs::read_to_string(dir.path().join("p.svg")).unwrap().contains("<polyline"));
}

#[test]
fn lines_for_pen_plotters_are_optimized_layered_and_written_as_hpgl() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene_file(
        dir.path(),
        "[camera]\neye = [4, 3, 5]\n[[object]]\nshape = \"box\"\n\
         [[object]]\nshape = \"sphere\"\ncenter = [2.2, 0, 0]\nradius = 0.8\nmaterial = { mirror = 1 }\n",
    );
    let svg = dir.path().join("p.svg");
    let o = alhazen(&["lines", scene.to_str().unwrap(), "-o", svg.to_str().unwrap(), "--hidden", "--optimize"]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let said = String::from_utf8_lossy(&o.stderr);
    assert!(said.contains("pen-up travel") && said.contains("% saved"), "{said}");
    let s = std::fs::read_to_string(&svg).unwrap();
    for label in ["1 visible", "2 reflected", "3 hidden"] {
        assert!(s.contains(&format!("inkscape:groupmode=\"layer\" inkscape:label=\"{label}\"")), "{s}");
    }
    assert!(!s.contains("<rect"), "a plotter would draw a background rectangle");
    let hpgl = dir.path().join("p.hpgl");
    let o = alhazen(&["lines", scene.to_str().unwrap(), "-o", hpgl.to_str().unwrap(), "--optimize", "-q"]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let h = std::fs::read_to_string(&hpgl).unwrap();
    assert!(h.starts_with("IN;\nSP1;\nPU") && h.contains("SP2;") && h.ends_with("PU;SP0;\n"), "{h}");
    let o = alhazen(&["lines", scene.to_str().unwrap(), "-o", hpgl.to_str().unwrap(), "--join-tolerance", "0.1"]);
    assert_eq!(o.status.code(), Some(2), "--join-tolerance needs --optimize");
    for bad in ["nan", "inf", "-1", "x"] {
        let o = alhazen(&[
            "lines",
            scene.to_str().unwrap(),
            "-o",
            hpgl.to_str().unwrap(),
            "--optimize",
            "--join-tolerance",
            bad,
        ]);
        assert_eq!(o.status.code(), Some(2), "--join-tolerance {bad}");
        assert!(String::from_utf8_lossy(&o.stderr).contains("expected a number ≥ 0"), "--join-tolerance {bad}");
    }
    // vpype, when installed, reads the three layers as layers 1, 2, 3.
    if let Ok(v) = Command::new("vpype").args(["read", svg.to_str().unwrap(), "stat"]).output() {
        let stat = String::from_utf8_lossy(&v.stdout);
        assert!(v.status.success() && ["Layer 1", "Layer 2", "Layer 3"].iter().all(|l| stat.contains(l)), "{stat}");
    }
}

#[test]
fn anamorph_prints_and_says_when_the_paper_is_too_small() {
    let dir = tempfile::tempdir().unwrap();
    let svg = dir.path().join("pic.svg");
    std::fs::write(&svg, "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"0 0 40 30\"><polyline points=\"2,2 38,2 38,28 2,28 2,2\"/><line x1=\"2\" y1=\"2\" x2=\"38\" y2=\"28\"/></svg>").unwrap();
    let out = dir.path().join("print.svg");
    let args = ["--radius", "40", "--height", "120", "--eye", "0,500,350"];
    let mut ok = vec!["mirror", "anamorph", svg.to_str().unwrap()];
    ok.extend(args);
    ok.extend(["-o", out.to_str().unwrap()]);
    let o = alhazen(&ok);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(std::fs::read_to_string(&out).unwrap().matches("<polyline").count() >= 4);
    let mut small = ok.clone();
    small.extend(["--paper", "A5"]);
    let o = alhazen(&small);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("needs"), "{}", String::from_utf8_lossy(&o.stderr));
    let mut inside = vec!["mirror", "anamorph", svg.to_str().unwrap(), "--radius", "40", "--height", "120"];
    inside.extend(["--eye", "0,100,10", "-o", out.to_str().unwrap()]);
    let o = alhazen(&inside);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("outside the cylinder"));
}

#[test]
fn every_importable_format_renders_rasters_and_draws() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let files = [
        root.join("scenes/mitsuba/cornell-box.xml"),
        root.join("scenes/pbrt/cornell-box.pbrt"),
        root.join("crates/alhazen-import/tests/data/blender/materials.glb"),
    ];
    let dir = tempfile::tempdir().unwrap();
    for f in &files {
        let f = f.to_str().unwrap();
        for (cmd, out) in [("render", "a.png"), ("raster", "b.png"), ("lines", "c.svg")] {
            let out = dir.path().join(out);
            let mut args = vec![cmd, f, "-o", out.to_str().unwrap()];
            if cmd != "lines" {
                args.extend(["--width", "32", "--height", "24", "--quiet"]);
            }
            if cmd == "render" {
                args.extend(["--spp", "1"]);
            }
            let o = alhazen(&args);
            assert_eq!(o.status.code(), Some(0), "{cmd} {f}: {}", String::from_utf8_lossy(&o.stderr));
            assert!(out.exists(), "{cmd} {f}");
        }
    }
}

#[test]
fn importers_warn_on_stderr_and_refuse_bad_files_with_exit_code_2() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o.png");
    let xml = dir.path().join("s.xml");
    std::fs::write(
        &xml,
        "<scene version=\"3.0.0\">\n<shape type=\"sphere\"><float name=\"wobble\" value=\"1\"/></shape>\n</scene>",
    )
    .unwrap();
    let o = alhazen(&[
        "render",
        xml.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--width",
        "8",
        "--height",
        "8",
        "--spp",
        "1",
        "-q",
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{err}");
    assert!(err.contains("warning:") && err.contains("s.xml:2: property `wobble`"), "{err}");
    let pbrt = dir.path().join("s.pbrt");
    std::fs::write(&pbrt, "WorldBegin\nShape \"sphere\" \"float radius\" [ 1").unwrap();
    let o = alhazen(&["render", pbrt.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("s.pbrt:2:31"), "{}", String::from_utf8_lossy(&o.stderr));
    let glb = dir.path().join("s.glb");
    std::fs::write(&glb, b"not a glb").unwrap();
    let never = dir.path().join("never.png");
    let o = alhazen(&["render", glb.to_str().unwrap(), "-o", never.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(!never.exists());
}

#[test]
fn convert_writes_toml_that_renders_and_refuses_other_outputs() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("cornell.toml");
    let xml = root.join("scenes/mitsuba/cornell-box.xml");
    let o = alhazen(&["convert", xml.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(std::fs::read_to_string(&out).unwrap().starts_with("# Converted by alhazen"));
    assert!(dir.path().join("cornell-assets/mesh-0.ply").exists());
    let png = dir.path().join("c.png");
    let o = alhazen(&[
        "render",
        out.to_str().unwrap(),
        "-o",
        png.to_str().unwrap(),
        "--spp",
        "1",
        "--width",
        "16",
        "--height",
        "16",
        "-q",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let o = alhazen(&["convert", xml.to_str().unwrap(), "-o", dir.path().join("c.json").to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("is a .toml file"));
}

/// `--environment` lights any scene by a map in place of its own sky (a glTF file has none):
/// rays that leave see the map, not the scene's background, in the path tracer, Whitted's and
/// the preview;
/// `convert` writes it into the TOML. Its options without a map, and maps that cannot be read
/// or numbers that mean nothing, are refused with exit code 2.
#[test]
fn an_environment_map_given_on_the_command_line_lights_the_scene() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    // The map: a render of a uniform sky of (0.2, 0.4, 0.6), written as OpenEXR.
    std::fs::write(p("sky.toml"), "background = [0.2, 0.4, 0.6]\n[render]\nwidth = 8\nheight = 4\n").unwrap();
    let o = alhazen(&["render", &p("sky.toml"), "-o", &p("sky.exr"), "-q"]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let scene = scene_file(dir.path(), &format!("background = [1, 0, 0]\n{OK}"));
    let corner = |extra: &[&str]| {
        let out = p("o.pfm");
        let mut args = vec!["render", scene.to_str().unwrap(), "-o", &out, "-q"];
        args.extend_from_slice(extra);
        let o = alhazen(&args);
        assert_eq!(o.status.code(), Some(0), "{extra:?}: {}", String::from_utf8_lossy(&o.stderr));
        let bytes = std::fs::read(p("o.pfm")).unwrap();
        let floats = &bytes[bytes.len() - 16 * 12 * 12..];
        std::array::from_fn::<f32, 3, _>(|c| f32::from_le_bytes(floats[4 * c..4 * c + 4].try_into().unwrap()))
    };
    assert_eq!(corner(&[]), [1.0, 0.0, 0.0]);
    for integrator in ["whitted", "path"] {
        let seen = corner(&["--integrator", integrator, "--environment", &p("sky.exr"), "--environment-scale", "2"]);
        assert!(seen.iter().zip([0.4, 0.8, 1.2]).all(|(a, b)| (a - b).abs() < 1e-5), "{integrator}: {seen:?}");
    }
    // The preview shows the map behind its objects too, and says what lights it; a glTF
    // camera without a far plane (Blender's export) sees it as well.
    let glb = Path::new(env!("CARGO_MANIFEST_DIR")).join("../alhazen-import/tests/data/blender/environment.glb");
    for file in [scene.to_str().unwrap(), glb.to_str().unwrap()] {
        let o = alhazen(&[
            "raster",
            file,
            "-o",
            &p("r.pfm"),
            "--environment",
            &p("sky.exr"),
            "--width",
            "16",
            "--height",
            "12",
        ]);
        assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
        // (The TOML scene has a lamp; the glTF file no light but the map.)
        assert_eq!(
            String::from_utf8_lossy(&o.stderr).contains("--ibl lights the preview"),
            file == glb.to_str().unwrap()
        );
        let bytes = std::fs::read(p("r.pfm")).unwrap();
        let floats = &bytes[bytes.len() - 16 * 12 * 12..];
        let seen: [f32; 3] = std::array::from_fn(|c| f32::from_le_bytes(floats[4 * c..4 * c + 4].try_into().unwrap()));
        assert!(seen.iter().zip([0.2, 0.4, 0.6]).all(|(a, b)| (a - b).abs() < 1e-5), "{file}: {seen:?}");
    }
    // Under a map that varies, the preview's sky above the balls is Whitted's (but for where in
    // each pixel it is looked up: the sky changes fast towards the pole).
    let map = glb.with_file_name("environment-sky.exr");
    let top_row = |command: &str| {
        let (out, map) = (p("t.pfm"), map.to_str().unwrap());
        let mut args = vec![command, glb.to_str().unwrap(), "-o", &out, "--width", "16", "--height", "12", "-q"];
        args.extend(["--environment", map, "--environment-rotate", "90"]);
        if command == "render" {
            args.extend(["--integrator", "whitted"]);
        }
        let o = alhazen(&args);
        assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
        let bytes = std::fs::read(p("t.pfm")).unwrap();
        let floats: Vec<f32> =
            bytes[bytes.len() - 16 * 12 * 12..].chunks(4).map(|b| f32::from_le_bytes(b.try_into().unwrap())).collect();
        // PFM rows run bottom to top: the image's top row is the last.
        let top = &floats[11 * 16 * 3..];
        [0, 1, 2].map(|c| top.iter().skip(c).step_by(3).sum::<f32>() / 16.0)
    };
    let (preview, whitted) = (top_row("raster"), top_row("render"));
    assert!(preview.iter().zip(whitted).all(|(a, b)| (a - b).abs() < 0.1 * b), "{preview:?} {whitted:?}");
    assert!(preview[2] > 1.2 * preview[0], "a blue sky: {preview:?}");
    let o = alhazen(&["convert", scene.to_str().unwrap(), "-o", &p("lit.toml"), "--environment", &p("sky.exr")]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(std::fs::read_to_string(p("lit.toml")).unwrap().contains("type = \"environment\""));
    for (extra, says) in [
        (&["--environment-scale", "2"][..], "--environment <FILE>"),
        (&["--environment", "missing.hdr"], "--environment: cannot load image missing.hdr"),
        (&["--environment", scene.to_str().unwrap()], "--environment: cannot load image"),
        (&["--environment", &p("sky.exr"), "--environment-scale", "-1"], "a scale is a number of at least 0"),
        (&["--environment", &p("sky.exr"), "--environment-rotate", "nan"], "an angle is a number of degrees"),
        (&["--environment", &p("sky.exr"), "--environment-up", "x"], "possible values: y, z"),
    ] {
        let (code, err, exists) = render(OK, extra);
        assert_eq!(code, 2, "{extra:?}: {err}");
        assert!(err.contains(says), "{extra:?}: {err}");
        assert!(!exists);
    }
    // The scene is read before the map (which may be large): a scene's error is told first.
    let (code, err, _) = render("[render]\nwidth = \"wide\"\n", &["--environment", "missing.hdr"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("scene.toml:2") && !err.contains("--environment"), "{err}");
}

/// What the fuzz test (tests/fuzz.rs) found: each used to panic.
#[test]
fn inputs_found_by_fuzzing_are_refused_or_rendered() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let run = |args: &[&str]| {
        let o = Command::new(env!("CARGO_BIN_EXE_alhazen")).current_dir(d).args(args).output().unwrap();
        (o.status.code(), String::from_utf8_lossy(&o.stderr).into_owned())
    };
    // A Radiance HDR texture of 2 × 0 pixels (texture lookups divided by zero).
    let mut hdr = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 0 +X 2\n".to_vec();
    hdr.extend([0u8; 8]);
    std::fs::write(d.join("t.hdr"), hdr).unwrap();
    let textured = format!(
        "{OK}[materials.t]\ncolor = {{ image = {{ file = \"t.hdr\" }} }}\n[[object]]\nshape = \"sphere\"\nradius = 1\nmaterial = \"t\"\n"
    );
    std::fs::write(d.join("t.toml"), textured).unwrap();
    let (code, err) = run(&["render", "t.toml", "-o", "o.png", "-q"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("t.hdr: the image is 2 × 0 pixels"), "{err}");
    // A glTF mesh whose POSITION accessor does not exist (the gltf crate's validation panicked).
    std::fs::write(
        d.join("m.gltf"),
        r#"{"asset":{"version":"2.0"},"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}]}"#,
    )
    .unwrap();
    let (code, err) = run(&["render", "m.gltf", "-o", "o.png", "-q"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("not a valid glTF 2.0 file") && !err.contains("panicked"), "{err}");
    // A pbrt integrator with an absurd maxdepth (the depth + 1 overflowed).
    std::fs::write(
        d.join("i.pbrt"),
        "Integrator \"path\" \"integer maxdepth\" [ 1e30 ]\nWorldBegin\nShape \"sphere\"\n",
    )
    .unwrap();
    let (code, err) = run(&["render", "i.pbrt", "-o", "o.png", "-q", "--width", "8", "--height", "6", "--spp", "1"]);
    assert!(matches!(code, Some(0) | Some(2)) && !err.contains("panicked"), "{err}");
    // A checker of squares 1e-320 wide (the square index overflowed).
    let checker = OK.replace(
        "[[object]]",
        "[materials.c]\ncolor = { checker = { even = 1, odd = 0, size = 1e-320 } }\n[[object]]\nmaterial = \"c\"",
    );
    std::fs::write(d.join("c.toml"), checker).unwrap();
    let (code, err) = run(&["render", "c.toml", "-o", "o.png", "-q"]);
    assert_eq!(code, Some(0), "{err}");
}

#[test]
fn a_missing_material_library_is_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n";
    for (name, text, warned) in
        [("with.obj", format!("mtllib missing.mtl\n{obj}"), true), ("without.obj", obj.to_string(), false)]
    {
        std::fs::write(dir.path().join(name), text).unwrap();
        let scene = scene_file(dir.path(), &format!("{OK}[[object]]\nshape = \"mesh\"\nfile = \"{name}\"\n"));
        let out = dir.path().join("out.png");
        let o = alhazen(&["render", scene.to_str().unwrap(), "-o", out.to_str().unwrap(), "-q"]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(0), "{err}");
        assert_eq!(
            err.contains("warning:") && err.contains("material library could not be read"),
            warned,
            "{name}: {err}"
        );
    }
}

#[test]
fn clamped_pixels_are_reported() {
    let text =
        OK.replace("position = [3, 3, 3]", "position = [3, 3, 3]\nattenuation = [0, 0, 1e-100]\nintensity = 1e100");
    assert_ne!(text, OK);
    let dir = tempfile::tempdir().unwrap();
    let scene = scene_file(dir.path(), &text);
    let out = dir.path().join("out.exr");
    let o = alhazen(&["render", scene.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{err}");
    assert!(err.contains("pixels are brighter than a 32-bit float can hold"), "{err}");
    let (_, err, _) = render(OK, &[]);
    assert!(!err.contains("warning"), "{err}");
}

#[test]
fn deep_nesting_and_control_characters_are_named() {
    let deep = format!(
        "[[object]]\nshape = \"csg\"\nop = \"union\"\na = {}{{ shape = \"sphere\", radius = 1 }}{}\nb = {{ shape = \"sphere\", radius = 1 }}\n",
        "{ op = \"union\", a = ".repeat(90),
        ", b = { shape = \"sphere\", radius = 1 } }".repeat(90)
    );
    let (code, err, _) = render(&deep, &[]);
    assert_eq!(code, 2);
    assert!(err.contains("nested too deeply") && err.contains("64 levels"), "{err}");
    let (code, err, _) = render("[camera]\neye = [0, 0, 5]\0\n", &[]);
    assert_eq!(code, 2);
    assert!(err.contains("U+0000, a NUL byte") && err.contains("scene.toml:2:"), "{err}");
}

#[test]
fn work_beyond_the_memory_budget_is_refused_before_allocating() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let many: String =
        (0..2000).map(|i| format!("[[object]]\nshape = \"sphere\"\ncenter = [{i}, 0, 0]\nradius = 0.4\n")).collect();
    std::fs::write(d.join("many.toml"), format!("{OK}{many}")).unwrap();
    std::fs::write(d.join("sub.toml"), "[[object]]\nshape = \"subdivision\"\nbase = \"cube\"\nlevels = 6\n").unwrap();
    let run = |args: &[&str]| {
        let o = Command::new(env!("CARGO_BIN_EXE_alhazen")).current_dir(d).args(args).output().unwrap();
        (o.status.code(), String::from_utf8_lossy(&o.stderr).into_owned())
    };
    let cases: [(&[&str], &str); 3] = [
        (&["raster", "many.toml", "-o", "m.png", "--max-memory", "64M"], "previewing this scene needs about"),
        (
            &["render", "many.toml", "-o", "m.png", "--width", "8000", "--height", "8000", "--max-memory", "64M"],
            "rendering this 8000×8000 film needs",
        ),
        (
            &["render", "sub.toml", "-o", "s.png", "--max-memory", "4M"],
            "sub.toml:4:10: subdividing this 6-face mesh 6 times",
        ),
    ];
    for (args, what) in cases {
        let (code, err) = run(args);
        assert_eq!(code, Some(2), "{args:?}: {err}");
        assert!(err.contains(what) && err.contains("more than the memory budget of"), "{args:?}: {err}");
        assert!(!d.join("m.png").exists() && !d.join("s.png").exists());
    }
    let (code, err) = run(&["render", "sub.toml", "-o", "s.png", "--max-memory", "lots"]);
    assert_eq!(code, Some(2));
    assert!(err.contains("a size such as 12G"), "{err}");
    // Within the budget the same scene renders.
    let (code, err) =
        run(&["render", "sub.toml", "-o", "s.png", "--max-memory", "2G", "--width", "32", "--height", "24"]);
    assert_eq!(code, Some(0), "{err}");
}

/// Colours leave the program in gamut by desaturation: the prism's spectral colours (negative
/// components in RGB before) have none in the PFM; `--exposure` brightens every format,
/// `--tonemap` changes the PNG only; bad values are refused before rendering.
#[test]
fn exposure_tone_mapping_and_gamut() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let dir = tempfile::tempdir().unwrap();
    let prism = dir.path().join("prism.pfm");
    let o = alhazen(&[
        "render",
        root.join("prism.toml").to_str().unwrap(),
        "-o",
        prism.to_str().unwrap(),
        "--width",
        "80",
        "--height",
        "60",
        "--spp",
        "16",
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let img = alhazen_render::output::read_pfm(&std::fs::read(&prism).unwrap()).unwrap();
    assert!(img.pixels.iter().flatten().all(|&c| c >= 0.0 && c.is_finite()), "a negative or non-finite component");
    let scene = scene_file(dir.path(), OK);
    let mean = |extra: &[&str], name: &str| {
        let out = dir.path().join(name);
        let mut args = vec!["render", scene.to_str().unwrap(), "-o", out.to_str().unwrap(), "--quiet"];
        args.extend_from_slice(extra);
        let o = alhazen(&args);
        assert!(o.status.success(), "{extra:?}: {}", String::from_utf8_lossy(&o.stderr));
        if name.ends_with(".pfm") {
            let img = alhazen_render::output::read_pfm(&std::fs::read(&out).unwrap()).unwrap();
            return img.pixels.iter().flatten().map(|&c| c as f64).sum::<f64>();
        }
        image::open(&out).unwrap().to_rgb8().pixels().flat_map(|p| p.0).map(f64::from).sum::<f64>()
    };
    let plain = mean(&[], "plain.png");
    assert!(mean(&["--exposure", "1"], "bright.png") > plain);
    assert!(mean(&["--exposure", "-2"], "dark.png") < plain);
    assert_ne!(mean(&["--tonemap", "filmic"], "filmic.png"), plain);
    assert_ne!(mean(&["--tonemap", "reinhard"], "reinhard.png"), plain);
    let linear = mean(&[], "plain.pfm");
    assert!((mean(&["--exposure", "1"], "bright.pfm") - 2.0 * linear).abs() < 1e-6 * linear);
    assert_eq!(mean(&["--tonemap", "filmic"], "filmic.pfm"), linear);
    for bad in [
        &["--exposure", "nan"][..],
        &["--exposure", "inf"],
        &["--exposure", "100"],
        &["--exposure", "x"],
        &["--tonemap", "aces"],
    ] {
        let (code, err, exists) = render(OK, bad);
        assert_eq!(code, 2, "{bad:?}: {err}");
        assert!(err.contains("exposure") || err.contains("possible values"), "{bad:?}: {err}");
        assert!(!exists);
    }
}

/// `render --integrator radiosity --export` solves once; `raster --radiosity` shows the same
/// solution without solving: per pixel the two images agree to a few per cent of the mean
/// (the raster interpolates the same vertex values; edges are sampled differently).
#[test]
fn a_radiosity_solution_is_rendered_exported_and_shown_by_the_preview() {
    let dir = tempfile::tempdir().unwrap();
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-box.toml");
    let (image, ply, raster) = (dir.path().join("r.pfm"), dir.path().join("s.ply"), dir.path().join("p.pfm"));
    let size = ["--width", "48", "--height", "48"];
    let mut args = vec!["render", scene.to_str().unwrap(), "-o", image.to_str().unwrap(), "--quiet"];
    args.extend(["--integrator", "radiosity", "--spp", "1", "--export", ply.to_str().unwrap()]);
    args.extend(size);
    let o = alhazen(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // The scene file may ask for radiosity itself: the same image.
    let text = std::fs::read_to_string(&scene).unwrap();
    assert!(text.contains("integrator = \"path\""));
    let in_file = dir.path().join("radiosity.toml");
    std::fs::write(&in_file, text.replacen("integrator = \"path\"", "integrator = \"radiosity\"", 1)).unwrap();
    let by_file = dir.path().join("f.pfm");
    let mut args = vec!["render", in_file.to_str().unwrap(), "-o", by_file.to_str().unwrap(), "--quiet", "--spp", "1"];
    args.extend(size);
    let o = alhazen(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(std::fs::read(&image).unwrap(), std::fs::read(&by_file).unwrap());
    let mut args = vec!["raster", scene.to_str().unwrap(), "-o", raster.to_str().unwrap(), "--quiet"];
    args.extend(["--radiosity", ply.to_str().unwrap()]);
    args.extend(size);
    let o = alhazen(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(!String::from_utf8_lossy(&o.stderr).contains("another"), "the solution is this scene's");
    let read = |p: &Path| alhazen_render::output::read_pfm(&std::fs::read(p).unwrap()).unwrap();
    let (a, b) = (read(&image), read(&raster));
    let (mut diff, mut sum) = (0.0, 0.0);
    for (p, q) in a.pixels.iter().zip(&b.pixels) {
        diff += (0..3).map(|k| (p[k] - q[k]).abs() as f64).sum::<f64>();
        sum += (0..3).map(|k| p[k] as f64).sum::<f64>();
    }
    assert!(sum > 0.0 && diff / sum < 0.05, "mean difference {:.2} % of the mean", 100.0 * diff / sum);
}

#[test]
fn radiosity_options_and_solution_files_are_checked() {
    let dir = tempfile::tempdir().unwrap();
    let ply = dir.path().join("s.ply");
    let (code, err, _) = render(OK, &["--export", ply.to_str().unwrap()]);
    assert_eq!(code, 2, "--export without radiosity: {err}");
    assert!(err.contains("--integrator radiosity"), "{err}");
    let (code, err, exists) = render(OK, &["--integrator", "radiosity", "--export", "s.obj"]);
    assert_eq!((code, exists), (2, false), "{err}");
    assert!(err.contains(".ply"), "{err}");
    for bad in [
        ["--patch-size", "0"],
        ["--patch-size", "NaN"],
        ["--patch-size", "-1"],
        ["--radiosity-tolerance", "1.5"],
        ["--radiosity-tolerance", "nan"],
        ["--levels", "9"],
        ["--hemicube", "4"],
        ["--export", "/no/such/dir/s.ply"],
    ] {
        let (code, err, _) = render(OK, &[&["--integrator", "radiosity"][..], &bad[..]].concat());
        assert_eq!(code, 2, "{bad:?}: {err}");
    }
    // A point light on a sphere over an unbounded floor: solved, the floor cut and said so.
    let floor = format!("{OK}[[object]]\nshape = \"plane\"\npoint = [0, -1, 0]\nnormal = [0, 1, 0]\n");
    let (code, err, exists) = render(&floor, &["--integrator", "radiosity"]);
    assert_eq!((code, exists), (0, true), "{err}");
    assert!(err.contains("cut to squares"), "{err}");
    // A solve that would not fit the memory budget is refused before it starts.
    let (code, err, exists) = render(OK, &["--integrator", "radiosity", "--max-memory", "100M"]);
    assert_eq!((code, exists), (2, false), "{err}");
    assert!(err.contains("radiosity needs about"), "{err}");
    // Not a solution: refused with the reason, nothing written.
    let scene = scene_file(dir.path(), OK);
    std::fs::write(&ply, b"ply\nformat ascii 1.0\nend_header\n").unwrap();
    let out = dir.path().join("p.png");
    let o = alhazen(&[
        "raster",
        scene.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--radiosity",
        ply.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("binary"), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(!out.exists());
}

/// `--integrator photon`: a glass ball's caustic under a point light, rendered in two bands
/// merged to the bits of one render (the map is the same in every process); its options are
/// checked, and refused without the integrator.
#[test]
fn photon_mapping_renders_in_parts_and_checks_its_options() {
    let glass = format!(
        "{OK}[[object]]\nshape = \"plane\"\npoint = [0, -1, 0]\n[[object]]\nshape = \"sphere\"\ncenter = [1, 0, 2]\nradius = 0.5\nmaterial = {{ transparency = 1, diffuse = 0, color = 0 }}\n"
    );
    let dir = tempfile::tempdir().unwrap();
    let scene = scene_file(dir.path(), &glass);
    let photon = ["--integrator", "photon", "--photons", "20000", "--width", "64", "--height", "48", "--quiet"];
    let run = |out: &str, extra: &[&str]| {
        let out = dir.path().join(out);
        let mut args = vec!["render", scene.to_str().unwrap(), "-o", out.to_str().unwrap()];
        args.extend_from_slice(&photon);
        args.extend_from_slice(extra);
        let o = alhazen(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        out
    };
    let whole = run("whole.pfm", &[]);
    // The scene file may ask for the photon map itself (`[render] integrator = "photon"`),
    // with the options still on the command line: the same image.
    let in_file = dir.path().join("photon.toml");
    std::fs::write(&in_file, glass.replacen("[render]\n", "[render]\nintegrator = \"photon\"\n", 1)).unwrap();
    let out = dir.path().join("file.pfm");
    let mut args = vec!["render", in_file.to_str().unwrap(), "-o", out.to_str().unwrap()];
    args.extend_from_slice(&photon[2..]);
    let o = alhazen(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(std::fs::read(&whole).unwrap(), std::fs::read(&out).unwrap());
    // Paths traced eight at a time in lanes (the default kernel here) or one by one: the same.
    let portable = run("portable.pfm", &["--kernel", "portable"]);
    assert_eq!(std::fs::read(&whole).unwrap(), std::fs::read(&portable).unwrap());
    let (a, b) = (run("a.film", &["--tile", "0/2"]), run("b.film", &["--tile", "1/2"]));
    let merged = dir.path().join("merged.pfm");
    let o = alhazen(&["merge", a.to_str().unwrap(), b.to_str().unwrap(), "-o", merged.to_str().unwrap(), "--quiet"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(std::fs::read(&whole).unwrap(), std::fs::read(&merged).unwrap());
    for bad in [&["--photons", "10"][..], &["--photon-nearest", "8"], &["--photon-radius", "0.1"]] {
        let (code, err, exists) = render(OK, bad);
        assert_eq!((code, exists), (2, false), "{bad:?}: {err}");
        assert!(err.contains("add --integrator photon"), "{err}");
    }
    for bad in
        [&["--photons", "0"][..], &["--photon-radius", "-1"], &["--photon-radius", "nan"], &["--photon-nearest", "0"]]
    {
        let (code, err, _) = render(OK, &[&["--integrator", "photon"][..], bad].concat());
        assert_eq!(code, 2, "{bad:?}: {err}");
    }
    // A photon map that would not fit in memory is refused before it is shot.
    let (code, err, exists) = render(OK, &["--integrator", "photon", "--photons", "100000000", "--max-memory", "200M"]);
    assert_eq!((code, exists), (2, false), "{err}");
    let prism = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/prism.toml");
    let out = dir.path().join("prism.png");
    let o = alhazen(&["render", prism.to_str().unwrap(), "-o", out.to_str().unwrap(), "--integrator", "photon"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("disperses"), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(!out.exists());
}

/// `lines --fill`: the reflexes in the mirror are filled under the lines (SVG polygons, PDF
/// fills); with nothing to reflect in, the option is refused rather than ignored.
#[test]
fn lines_fill_the_reflexes_in_mirrors() {
    let dir = tempfile::tempdir().unwrap();
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/lines/fig17-polygon-overlap.toml");
    let svg = dir.path().join("f.svg");
    let o = alhazen(&["lines", scene.to_str().unwrap(), "--fill", "-o", svg.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stderr).contains("filled reflex polygons"));
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.contains("<g id=\"fills\"") && text.contains("<polygon"));
    let o = alhazen(&["lines", scene.to_str().unwrap(), "--fill", "--no-reflections", "-o", svg.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
}

/// `--bvh morton` builds meshes' hierarchies in Morton order: the same image as the surface
/// area heuristic's (a mesh of more than 256 triangles, so it keeps its own hierarchy).
#[test]
fn a_morton_bvh_renders_the_same_image() {
    let dir = tempfile::tempdir().unwrap();
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/teapot.toml");
    let image = |bvh: &str| {
        let out = dir.path().join(format!("{bvh}.pfm"));
        let o = alhazen(&[
            "render",
            scene.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--quiet",
            "--bvh",
            bvh,
            "--width",
            "40",
            "--height",
            "30",
            "--spp",
            "1",
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        std::fs::read(out).unwrap()
    };
    assert_eq!(image("sah"), image("morton"));
}

/// `-D` takes NAME=VALUE for a Mitsuba scene: a malformed one, or one given to a scene of
/// another format, is bad input (exit code 2) before anything is read or rendered.
#[test]
fn scene_parameters_are_refused_when_malformed_or_misplaced() {
    for bad in ["spp", "=4", "s p=4"] {
        let (code, err, written) = render(OK, &["-D", bad]);
        assert!(
            code == 2 && !written && (err.contains("NAME=VALUE") || err.contains("parameter name")),
            "{bad}: {err}"
        );
    }
    let (code, err, written) = render(OK, &["-D", "spp=4"]);
    assert!(code == 2 && !written && err.contains("Mitsuba"), "{err}");
}

/// Under Whitted an emitting cylinder is shown, not sampled, and the render says so; an
/// emitting sphere is sampled and adds nothing to the count (the environment map beside them
/// is not built for the warning).
#[test]
fn whitted_says_which_emitters_it_only_shows() {
    let dir = tempfile::tempdir().unwrap();
    let sky: Vec<u8> =
        "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 2\n".bytes().chain([128, 128, 128, 129].repeat(2)).collect();
    std::fs::write(dir.path().join("sky.hdr"), sky).unwrap();
    let text = "[render]\nwidth = 16\nheight = 12\nspp = 1\n[camera]\neye = [0, 0, 5]\n[[light]]\ntype = \"environment\"\nfile = \"sky.hdr\"\n[[object]]\nshape = \"sphere\"\nradius = 0.5\nmaterial = { emission = [2, 2, 2] }\n[[object]]\nshape = \"cylinder\"\nradius = 0.2\nmaterial = { emission = [2, 2, 2] }\n";
    let scene = scene_file(dir.path(), text);
    let out = dir.path().join("out.png");
    let o = alhazen(&["render", scene.to_str().unwrap(), "-o", out.to_str().unwrap(), "--quiet"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{err}");
    assert!(err.contains("warning: 1 emitting object(s) light nothing under Whitted"), "{err}");
}
