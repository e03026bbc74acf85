//! Renders made in parts (`--tile`, `--pass`, `alhazen merge`) and interrupted renders
//! (`--checkpoint`, `--resume`, killed by a signal) write the bytes of one uninterrupted render.

use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

const SCENE: &str = r#"
[render]
width = 128
height = 64
spp = 24
integrator = "path"
[camera]
eye = [0, 1, 5]
target = [0, 0.5, 0]
fov = 45
[[light]]
type = "point"
position = [2, 4, 3]
intensity = 20
[materials.glass]
transparency = 1
ior = 1.5
[materials.lamp]
emission = [4, 4, 3]
[[object]]
shape = "sphere"
center = [0.5, 0.6, 0]
radius = 0.6
material = "glass"
[[object]]
shape = "sphere"
center = [-1.2, 1.5, -1]
radius = 0.3
material = "lamp"
[[object]]
shape = "plane"
point = [0, 0, 0]
normal = [0, 1, 0]
"#;

fn alhazen(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_alhazen")).current_dir(dir).args(args).output().expect("the binary runs")
}

fn ok(o: Output) -> Output {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    o
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn setup() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("s.toml"), SCENE).unwrap();
    ok(alhazen(dir.path(), &["render", "s.toml", "-o", "whole.exr", "-q"]));
    dir
}

fn same_file(dir: &Path, a: &str, b: &str) -> bool {
    std::fs::read(dir.join(a)).unwrap() == std::fs::read(dir.join(b)).unwrap()
}

#[test]
fn tiles_and_passes_merge_to_the_bytes_of_one_render() {
    let dir = setup();
    let d = dir.path();
    for (flag, n) in [("--tile", 3), ("--pass", 3)] {
        let names: Vec<String> = (0..n).map(|i| format!("{}-{i}.film", &flag[2..])).collect();
        for (i, name) in names.iter().enumerate() {
            ok(alhazen(d, &["render", "s.toml", flag, &format!("{i}/{n}"), "-o", name, "-q", "--threads", "1"]));
        }
        let mut args = vec!["merge"];
        args.extend(names.iter().rev().map(String::as_str));
        args.extend(["-o", "merged.exr"]);
        let o = ok(alhazen(d, &args));
        assert!(stderr(&o).contains(&format!("merged {n} parts")), "{}", stderr(&o));
        assert!(same_file(d, "whole.exr", "merged.exr"), "{flag}: the merged image differs");
        // One part short: refused, nothing written.
        std::fs::remove_file(d.join("merged.exr")).unwrap();
        let o = alhazen(d, &["merge", &names[0], &names[1], "-o", "merged.exr"]);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        assert!(stderr(&o).contains("do not make a whole image"), "{}", stderr(&o));
        assert!(!d.join("merged.exr").exists());
    }
}

#[test]
fn bad_parts_and_options_are_refused() {
    let dir = setup();
    let d = dir.path();
    let code = |o: Output| (o.status.code(), stderr(&o));
    let (c, e) = code(alhazen(d, &["render", "s.toml", "--tile", "0/2", "-o", "x.png"]));
    assert_eq!(c, Some(2));
    assert!(e.contains("name the output NAME.film"), "{e}");
    let (c, e) = code(alhazen(d, &["render", "s.toml", "--pass", "2/2", "-o", "x.film"]));
    assert_eq!(c, Some(2));
    assert!(e.contains("expected I/N with 0 ≤ I < N"), "{e}");
    let (c, e) = code(alhazen(d, &["render", "s.toml", "--pass", "0/4", "-o", "x.film"]));
    assert_eq!(c, Some(2));
    assert!(e.contains("24 samples per pixel make at most 3 passes"), "{e}");
    // Parts of different renders, and a damaged part.
    ok(alhazen(d, &["render", "s.toml", "--tile", "0/2", "-o", "a.film", "-q"]));
    ok(alhazen(d, &["render", "s.toml", "--tile", "1/2", "-o", "b.film", "-q", "--seed", "9"]));
    let (c, e) = code(alhazen(d, &["merge", "a.film", "b.film", "-o", "m.png"]));
    assert_eq!(c, Some(2));
    assert!(e.contains("b.film: it was rendered with another scene or other options"), "{e}");
    let mut bytes = std::fs::read(d.join("a.film")).unwrap();
    bytes.truncate(bytes.len() / 2);
    std::fs::write(d.join("a.film"), bytes).unwrap();
    let (c, e) = code(alhazen(d, &["merge", "a.film", "-o", "m.png"]));
    assert_eq!(c, Some(2));
    assert!(e.contains("a.film: the file is truncated or damaged"), "{e}");
    let (c, e) = code(alhazen(d, &["merge", "s.toml", "-o", "m.png"]));
    assert_eq!(c, Some(2));
    assert!(e.contains("not a film part"), "{e}");
    // A checkpoint is not overwritten without --resume, nor resumed into another render.
    std::fs::write(d.join("c.film"), b"progress").unwrap();
    let (c, e) = code(alhazen(d, &["render", "s.toml", "-o", "x.png", "--checkpoint", "c.film"]));
    assert_eq!(c, Some(2));
    assert!(e.contains("c.film exists: add --resume"), "{e}");
    ok(alhazen(d, &["render", "s.toml", "--tile", "0/2", "-o", "c.film", "-q", "--spp", "3"]));
    let (c, e) = code(alhazen(d, &["render", "s.toml", "-o", "x.png", "--checkpoint", "c.film", "--resume"]));
    assert_eq!(c, Some(2));
    assert!(e.contains("the checkpoint of another render"), "{e}");
    assert!(!d.join("x.png").exists());
}

/// Starts a checkpointed render of `spp` samples, waits for its first checkpoint, sends
/// `signal`, and returns the exit status.
fn interrupt(d: &Path, signal: &str) -> Option<i32> {
    let _ = std::fs::remove_file(d.join("ck.film"));
    let mut child = Command::new(env!("CARGO_BIN_EXE_alhazen"))
        .current_dir(d)
        .args(["render", "s.toml", "-o", "slow.exr", "-q", "--threads", "2", "--spp", "600"])
        .args(["--checkpoint", "ck.film", "--checkpoint-every", "0"])
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while !d.join("ck.film").exists() {
        assert!(start.elapsed() < Duration::from_secs(120), "no checkpoint was written");
        std::thread::sleep(Duration::from_millis(5));
    }
    Command::new("kill").args(["-s", signal, &child.id().to_string()]).status().unwrap();
    child.wait().unwrap().code()
}

#[test]
fn an_interrupted_render_resumes_to_the_bytes_of_one_render() {
    let dir = setup();
    let d = dir.path();
    ok(alhazen(d, &["render", "s.toml", "-o", "slow-whole.exr", "-q", "--spp", "600"]));
    for signal in ["INT", "TERM", "KILL"] {
        let code = interrupt(d, signal);
        if signal == "KILL" {
            assert_eq!(code, None, "killed");
        } else {
            assert_eq!(code, Some(130), "{signal}: interrupted");
        }
        assert!(!d.join("slow.exr").exists(), "{signal}: no image from an interrupted render");
        assert!(d.join("ck.film").exists(), "{signal}: progress kept");
        let o = ok(alhazen(
            d,
            &["render", "s.toml", "-o", "slow.exr", "--spp", "600", "--checkpoint", "ck.film", "--resume"],
        ));
        assert!(same_file(d, "slow.exr", "slow-whole.exr"), "{signal}: the resumed image differs");
        assert!(!d.join("ck.film").exists(), "{signal}: the checkpoint is removed once the image is written");
        assert!(stderr(&o).contains("rendered"), "{}", stderr(&o));
        std::fs::remove_file(d.join("slow.exr")).unwrap();
    }
}
