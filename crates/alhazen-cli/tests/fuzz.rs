//! Fuzzing every parser through the binary, as users' files reach it: scene TOML, OBJ, PLY,
//! PNG/HDR/EXR textures, glTF, Mitsuba XML, pbrt, film parts, `mirror reflex` JSON lines and
//! SVG pictures for anamorphoses. Seeds are the repository's files (and a few made here);
//! each input is one to three mutations of a seed — bit flips, cut, repeated or spliced
//! ranges, numbers replaced by extremes (1e308, NaN, -0, 2^32 + 1…), stray NUL and non-UTF-8
//! bytes — run under a 4 GiB address-space limit. Every run must end with exit code 0, 1 or 2
//! within the time limit, and print no NaN or infinity; anything else is saved under
//! `target/fuzz-findings/` and fails the test.
//!
//! CI runs a short, fixed-seed pass (`ALHAZEN_FUZZ_RUNS`, default 40 per target). Longer runs,
//! recorded in RELIABILITY.md:
//!
//! ```sh
//! ALHAZEN_FUZZ_SECONDS=600 ALHAZEN_FUZZ_TARGET=toml ALHAZEN_FUZZ_SEED=7 \
//!     cargo test --release -p alhazen-cli --test fuzz -- --nocapture
//! ```

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// One parser reached through one command.
struct Target {
    name: &'static str,
    /// The mutated file's name in the work folder.
    file: &'static str,
    /// Seeds: repository files (relative to the root) or bytes made by `made`.
    seeds: Vec<Vec<u8>>,
    /// The command line, given the work folder.
    args: fn() -> Vec<&'static str>,
    /// Scene files that reference the fuzzed file (mesh, texture), written beside it.
    wrapper: Option<&'static str>,
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn files(dir: &str, ext: &str) -> Vec<Vec<u8>> {
    let mut out: Vec<(PathBuf, Vec<u8>)> = walk(&root().join(dir))
        .into_iter()
        .filter(|p| p.extension().and_then(|e| e.to_str()) == Some(ext))
        .filter_map(|p| std::fs::read(&p).ok().map(|b| (p, b)))
        .filter(|(_, b)| b.len() < 4 << 20)
        .collect();
    out.sort();
    out.into_iter().map(|(_, b)| b).collect()
}

fn walk(dir: &Path) -> Vec<PathBuf> {
    let Ok(entries) = std::fs::read_dir(dir) else { return vec![] };
    entries.flatten().flat_map(|e| if e.path().is_dir() { walk(&e.path()) } else { vec![e.path()] }).collect()
}

const SMALL: [&str; 6] = ["--width", "12", "--height", "9", "--spp", "1"];

fn render_args(scene: &'static str) -> Vec<&'static str> {
    let mut a = vec!["render", scene, "-o", "out.png", "-q"];
    a.extend(SMALL);
    a
}

fn hdr_seed() -> Vec<u8> {
    let mut b = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 2\n".to_vec();
    b.extend([128, 64, 32, 129, 10, 200, 30, 130, 0, 0, 0, 0, 255, 255, 255, 128]);
    b
}

fn targets(made: &Path) -> Vec<Target> {
    let made_file = |n: &str| std::fs::read(made.join(n)).expect("made at start");
    vec![
        Target {
            name: "toml",
            file: "s.toml",
            seeds: files("scenes", "toml"),
            args: || render_args("s.toml"),
            wrapper: None,
        },
        Target {
            name: "obj",
            file: "m.obj",
            seeds: files("scenes", "obj"),
            args: || render_args("w.toml"),
            wrapper: Some("[[object]]\nshape = \"mesh\"\nfile = \"m.obj\"\n"),
        },
        Target {
            name: "ply",
            file: "m.ply",
            seeds: [files("scenes", "ply"), vec![made_file("grid.ply")]].concat(),
            args: || render_args("w.toml"),
            wrapper: Some("[[object]]\nshape = \"mesh\"\nfile = \"m.ply\"\n"),
        },
        Target {
            name: "png",
            file: "t.png",
            seeds: files("crates/alhazen-render/tests/data/golden", "png"),
            args: || render_args("w.toml"),
            wrapper: Some(
                "[materials.t]\ncolor = { image = { file = \"t.png\" } }\n[[object]]\nshape = \"sphere\"\nradius = 1\nmaterial = \"t\"\n",
            ),
        },
        Target {
            name: "hdr",
            file: "t.hdr",
            seeds: vec![hdr_seed()],
            args: || render_args("w.toml"),
            wrapper: Some(
                "[materials.t]\ncolor = { image = { file = \"t.hdr\" } }\n[[object]]\nshape = \"sphere\"\nradius = 1\nmaterial = \"t\"\n",
            ),
        },
        Target {
            name: "exr",
            file: "t.exr",
            seeds: vec![made_file("small.exr")],
            args: || render_args("w.toml"),
            wrapper: Some(
                "[materials.t]\ncolor = { image = { file = \"t.exr\" } }\n[[object]]\nshape = \"sphere\"\nradius = 1\nmaterial = \"t\"\n",
            ),
        },
        Target {
            name: "gltf",
            file: "s.glb",
            seeds: files("crates/alhazen-import/tests/data", "glb"),
            args: || render_args("s.glb"),
            wrapper: None,
        },
        Target {
            name: "mitsuba",
            file: "s.xml",
            seeds: files("scenes/mitsuba", "xml"),
            args: || render_args("s.xml"),
            wrapper: None,
        },
        Target {
            name: "pbrt",
            file: "s.pbrt",
            seeds: files("scenes/pbrt", "pbrt"),
            args: || render_args("s.pbrt"),
            wrapper: None,
        },
        Target {
            name: "film",
            file: "p.film",
            seeds: vec![made_file("whole.film"), made_file("band.film"), made_file("pass.film")],
            args: || vec!["merge", "p.film", "-o", "out.exr", "-q"],
            wrapper: None,
        },
        Target {
            name: "json",
            file: "q.jsonl",
            seeds: vec![
                br#"{"mirror":"sphere","center":[0,0,0],"radius":1,"eye":[0,0,5],"point":[3,0,4]}
{"mirror":"cylinder","center":[0,0,0],"axis":[0,1,0],"radius":1,"eye":[0,1,5],"point":[3,2,4]}"#
                    .to_vec(),
            ],
            args: || vec!["mirror", "reflex", "q.jsonl"],
            wrapper: None,
        },
        Target {
            name: "svg",
            file: "p.svg",
            seeds: vec![
                br#"<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="80mm" viewBox="0 0 100 80">
<polyline points="10,10 50,70 90,10" fill="none" stroke="black"/>
<polygon points="20,20 80,20 50,60"/>
<line x1="0" y1="40" x2="100" y2="40"/>
</svg>"#
                    .to_vec(),
                made_file("caustic.svg"),
            ],
            args: || {
                vec![
                    "mirror",
                    "anamorph",
                    "p.svg",
                    "--radius",
                    "40",
                    "--height",
                    "100",
                    "--eye",
                    "0,300,400",
                    "-o",
                    "out.svg",
                ]
            },
            wrapper: None,
        },
    ]
}

/// Seeds no repository file gives: made by the binary itself.
fn make_seeds(dir: &Path) {
    let scene = "[render]\nwidth = 40\nheight = 30\nspp = 16\n[camera]\neye = [0, 0, 5]\n[[light]]\ntype = \"point\"\nposition = [3, 3, 3]\n[[object]]\nshape = \"sphere\"\nradius = 1\n";
    std::fs::write(dir.join("small.toml"), scene).unwrap();
    let mut grid = String::from(
        "ply\nformat ascii 1.0\nelement vertex 9\nproperty float x\nproperty float y\nproperty float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n",
    );
    (0..9).for_each(|i| grid += &format!("{} {} {}\n", i % 3, i / 3, (i * 7 % 5) as f64 * 0.1));
    [[0, 1, 4, 3], [1, 2, 5, 4], [3, 4, 7, 6], [4, 5, 8, 7]]
        .iter()
        .for_each(|f| grid += &format!("4 {} {} {} {}\n", f[0], f[1], f[2], f[3]));
    std::fs::write(dir.join("grid.ply"), grid).unwrap();
    for args in [
        &["render", "small.toml", "-o", "small.exr", "-q"][..],
        &["render", "small.toml", "-o", "whole.film", "-q"],
        &["render", "small.toml", "--tile", "0/2", "-o", "band.film", "-q"],
        &["render", "small.toml", "--pass", "1/2", "-o", "pass.film", "-q"],
        &["mirror", "caustic", "--radius", "1", "--eye-distance", "3", "-o", "caustic.svg"],
    ] {
        let o = Command::new(env!("CARGO_BIN_EXE_alhazen")).current_dir(dir).args(args).output().unwrap();
        assert!(o.status.success(), "{args:?}: {}", String::from_utf8_lossy(&o.stderr));
    }
}

/// xorshift64*: deterministic, from the seed given.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

const EXTREMES: [&str; 12] =
    ["1e308", "-1e308", "0", "-0", "nan", "inf", "4294967297", "-1", "1e-320", "99999999", "2147483648", "0.5"];

fn mutate(seed: &[u8], other: &[u8], rng: &mut Rng) -> Vec<u8> {
    let mut b = seed.to_vec();
    for _ in 0..1 + rng.below(3) {
        let len = b.len().max(1);
        match rng.below(7) {
            0 => {
                for _ in 0..1 + rng.below(8) {
                    let i = rng.below(b.len());
                    if let Some(x) = b.get_mut(i) {
                        *x ^= 1 << rng.below(8);
                    }
                }
            }
            1 => {
                let at = rng.below(len);
                let end = (at + 1 + rng.below(64)).min(b.len());
                b.drain(at.min(end)..end);
            }
            2 => {
                let at = rng.below(len);
                let piece: Vec<u8> = b[at.min(b.len())..(at + 1 + rng.below(256)).min(b.len())].to_vec();
                let to = rng.below(b.len() + 1);
                let times = 1 + rng.below(4);
                (0..times).for_each(|_| b.splice(to..to, piece.iter().copied()).for_each(drop));
            }
            3 => {
                // A number replaced by an extreme.
                let starts: Vec<usize> = (0..b.len())
                    .filter(|&i| b[i].is_ascii_digit() && (i == 0 || !b[i - 1].is_ascii_alphanumeric()))
                    .collect();
                if !starts.is_empty() {
                    let s = starts[rng.below(starts.len())];
                    let e = (s..b.len())
                        .find(|&i| !(b[i].is_ascii_digit() || b[i] == b'.' || b[i] == b'e'))
                        .unwrap_or(b.len());
                    b.splice(s..e, EXTREMES[rng.below(EXTREMES.len())].bytes()).for_each(drop);
                }
            }
            4 => b.truncate(rng.below(len)),
            5 => {
                let at = rng.below(b.len() + 1);
                let junk = [0u8, 0xff, 0xc3, b'"', b'[', b'{', b'\n', b'=', b'<', b'-'];
                (0..1 + rng.below(4)).for_each(|_| b.insert(at.min(b.len()), junk[rng.below(junk.len())]));
            }
            _ => {
                // Spliced with another seed of the same kind.
                let cut = rng.below(len).min(b.len());
                let from = rng.below(other.len().max(1)).min(other.len());
                b.truncate(cut);
                b.extend_from_slice(&other[from..]);
            }
        }
    }
    b
}

/// What a run did wrong, if anything, and its exit code.
fn run_once(dir: &Path, t: &Target, limit: Duration) -> (Option<String>, Option<i32>) {
    let mut cmd = Command::new("sh");
    cmd.current_dir(dir)
        .arg("-c")
        .arg("ulimit -v 4194304; exec \"$0\" \"$@\"")
        .arg(env!("CARGO_BIN_EXE_alhazen"))
        .args((t.args)())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    let mut child = cmd.spawn().expect("sh runs");
    let start = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().expect("wait") {
            break s;
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            return (Some(format!("no answer within {} s", limit.as_secs())), None);
        }
        std::thread::sleep(Duration::from_millis(2));
    };
    let out = child.wait_with_output().expect("output");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    // Answers (not error lines, which quote the input) must hold finite numbers only: serde
    // writes a non-finite number as null.
    let non_finite = stdout
        .lines()
        .filter(|l| !l.starts_with("{\"error\""))
        .find(|l| l.contains("null") || l.contains("NaN") || l.contains("inf"));
    let finding = match status.code() {
        Some(0..=2) if non_finite.is_none() => None,
        Some(0..=2) => {
            Some(format!("non-finite output: {}", non_finite.unwrap_or("").chars().take(300).collect::<String>()))
        }
        code => Some(format!("exit {code:?}: {}", stderr.chars().take(600).collect::<String>())),
    };
    (finding, status.code())
}

#[test]
fn every_parser_survives_mutated_input() {
    let env = |k: &str| std::env::var(k).ok();
    let runs: usize = env("ALHAZEN_FUZZ_RUNS").and_then(|v| v.parse().ok()).unwrap_or(40);
    let seconds: Option<u64> = env("ALHAZEN_FUZZ_SECONDS").and_then(|v| v.parse().ok());
    let only = env("ALHAZEN_FUZZ_TARGET");
    let seed: u64 = env("ALHAZEN_FUZZ_SEED").and_then(|v| v.parse().ok()).unwrap_or(1);
    let limit = Duration::from_secs(env("ALHAZEN_FUZZ_TIMEOUT").and_then(|v| v.parse().ok()).unwrap_or(30));
    let made = tempfile::tempdir().unwrap();
    make_seeds(made.path());
    let findings_dir = root().join("target/fuzz-findings");
    let mut findings = Vec::new();
    for t in targets(made.path()).into_iter().filter(|t| only.as_deref().is_none_or(|o| o == t.name)) {
        assert!(!t.seeds.is_empty(), "{}: no seeds", t.name);
        let dir = tempfile::tempdir().unwrap();
        if let Some(w) = t.wrapper {
            std::fs::write(
                dir.path().join("w.toml"),
                format!("[camera]\neye = [0, 0, 5]\n[[light]]\ntype = \"point\"\nposition = [3, 3, 3]\n{w}"),
            )
            .unwrap();
        }
        // The harness reaches the parser: the first seed, unmutated, is read and used.
        std::fs::write(dir.path().join(t.file), &t.seeds[0]).unwrap();
        assert_eq!(run_once(dir.path(), &t, limit).1, Some(0), "{}: the first seed is not accepted", t.name);
        let mut rng = Rng(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ t.name.len() as u64 | 1);
        let (start, mut done, mut slowest) = (Instant::now(), 0usize, Duration::ZERO);
        // The slowest input of a long campaign is kept too, to see what made it slow.
        let slowest_file = findings_dir.join(format!("slowest-{}-{seed}-{}", t.name, t.file));
        while seconds.map_or(done < runs, |s| start.elapsed() < Duration::from_secs(s)) {
            let k = rng.below(t.seeds.len());
            let other = &t.seeds[rng.below(t.seeds.len())];
            let input = mutate(&t.seeds[k], other, &mut rng);
            std::fs::write(dir.path().join(t.file), &input).unwrap();
            let began = Instant::now();
            if let (Some(what), _) = run_once(dir.path(), &t, limit) {
                std::fs::create_dir_all(&findings_dir).unwrap();
                let saved = findings_dir.join(format!("{}-{seed}-{done}-{}", t.name, t.file));
                std::fs::write(&saved, &input).unwrap();
                findings.push(format!("{}: {what} (input saved as {})", t.name, saved.display()));
            }
            if began.elapsed() > slowest && seconds.is_some() {
                std::fs::create_dir_all(&findings_dir).unwrap();
                std::fs::write(&slowest_file, &input).unwrap();
            }
            slowest = slowest.max(began.elapsed());
            done += 1;
        }
        eprintln!(
            "fuzz {:>8}: {done} runs in {:.1} s ({:.0}/s), slowest {:.2} s, findings so far {}",
            t.name,
            start.elapsed().as_secs_f64(),
            done as f64 / start.elapsed().as_secs_f64(),
            slowest.as_secs_f64(),
            findings.len()
        );
    }
    assert!(findings.is_empty(), "{} findings:\n{}", findings.len(), findings.join("\n"));
}
