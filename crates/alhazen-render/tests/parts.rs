//! A render made in parts — bands of tiles, shares of the samples, both, or stopped and
//! resumed — merges to the bits of the render made at once; damaged or mismatched parts are
//! refused with a reason, never a panic.

use alhazen_render::film::part::{self, Part, fingerprint, merge, share, share_samples};
use alhazen_render::film::{Job, TileResult, tiles};
use alhazen_render::shape::VectorUnit;
use alhazen_render::{Image, film_size, render_tiles_with, render_with};
use alhazen_scene::{Scene, parse_scene};
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

const SCENE: &str = r#"
[render]
width = 75
height = 41
spp = 37
max_depth = 4
integrator = "path"
[camera]
eye = [0, 1, 5]
target = [0, 0.5, 0]
fov = 45
[[light]]
type = "point"
position = [2, 4, 3]
intensity = 20
[materials.gold]
color = [0.9, 0.7, 0.3]
bsdf = { type = "conductor", metal = "gold", roughness = 0.3 }
[materials.glass]
transparency = 1
ior = 1.5
[[object]]
shape = "sphere"
center = [-0.8, 0.6, 0]
radius = 0.6
material = "gold"
[[object]]
shape = "sphere"
center = [0.8, 0.6, 0]
radius = 0.6
material = "glass"
[[object]]
shape = "plane"
point = [0, 0, 0]
normal = [0, 1, 0]
"#;

fn scenes() -> Vec<(&'static str, Scene)> {
    let path = parse_scene("parts.toml".as_ref(), SCENE).unwrap();
    let mut whitted = path.clone();
    whitted.render.integrator = alhazen_scene::IntegratorKind::Whitted;
    // Lambertian only: the path tracer's vector lanes.
    let lambert = SCENE
        .replace("bsdf = { type = \"conductor\", metal = \"gold\", roughness = 0.3 }\n", "")
        .replace("transparency = 1\nior = 1.5\n", "");
    vec![("path", path), ("whitted", whitted), ("lambert", parse_scene("l.toml".as_ref(), &lambert).unwrap())]
}

/// Renders `job` of `scene` into a part.
fn part_of(scene: &Scene, job: &Job) -> Part {
    let (w, h) = film_size(scene);
    let part = Mutex::new(Part::new(fingerprint(scene), w, h, scene.render.spp));
    let done = |t: TileResult| part.lock().unwrap().push(job.samples.clone(), t);
    render_tiles_with(scene, VectorUnit::detect(), job, &AtomicBool::new(false), &done);
    part.into_inner().unwrap()
}

/// Tile band `i/n` and sample pass `j/m`.
fn job(scene: &Scene, (i, n): (u32, u32), (j, m): (u32, u32)) -> Job {
    let (w, h) = film_size(scene);
    let t = share(tiles(w, h).len() as u64, i, n);
    let samples = share_samples(scene.render.spp, j, m);
    Job { tiles: (t.start as usize..t.end as usize).collect(), samples, keep_sums: true }
}

fn round_trip(p: &Part) -> Part {
    Part::decode(&p.encode()).unwrap()
}

fn assert_same(a: &Image, b: &Image, what: &str) {
    assert_eq!((a.width, a.height), (b.width, b.height));
    let differing = a.pixels.iter().zip(&b.pixels).filter(|(x, y)| x.map(f32::to_bits) != y.map(f32::to_bits)).count();
    assert_eq!(differing, 0, "{what}: {differing} pixels differ");
}

#[test]
fn parts_merge_to_the_bits_of_one_render() {
    for (name, scene) in scenes() {
        let whole = render_with(&scene, VectorUnit::detect(), &|_, _| {});
        for (n, m) in [(1, 1), (3, 1), (1, 3), (2, 5), (4, 2)] {
            let parts: Vec<Part> = (0..n)
                .flat_map(|i| (0..m).map(move |j| (i, j)))
                .map(|(i, j)| round_trip(&part_of(&scene, &job(&scene, (i, n), (j, m)))))
                .collect();
            assert_same(&merge(&parts).unwrap(), &whole, &format!("{name}: {n} bands × {m} passes"));
            if (n, m) == (1, 1) {
                assert_same(&parts[0].clone().into_image().unwrap(), &whole, "into_image");
            }
        }
    }
}

#[test]
fn a_render_stopped_and_resumed_has_the_bits_of_one_render() {
    let (_, scene) = scenes().remove(0);
    let whole = render_with(&scene, VectorUnit::detect(), &|_, _| {});
    let (w, h) = film_size(&scene);
    let every = Job::whole(w, h, scene.render.spp);
    // Stop after a few tiles (as SIGINT does), keep what finished, resume with the rest.
    let stop = AtomicBool::new(false);
    let finished = AtomicUsize::new(0);
    let first = Mutex::new(Part::new(fingerprint(&scene), w, h, scene.render.spp));
    render_tiles_with(&scene, VectorUnit::detect(), &every, &stop, &|t| {
        first.lock().unwrap().push(every.samples.clone(), t);
        if finished.fetch_add(1, Ordering::SeqCst) == 2 {
            stop.store(true, Ordering::SeqCst);
        }
    });
    let first = round_trip(&first.into_inner().unwrap());
    let done: Vec<usize> = first.tiles.iter().map(|(_, t)| t.index).collect();
    assert!(done.len() >= 3 && done.len() < every.tiles.len(), "stopped part-way: {} tiles", done.len());
    assert!(merge(std::slice::from_ref(&first)).unwrap_err().message.contains("tiles are in no part"));
    let rest = Job { tiles: every.tiles.iter().copied().filter(|i| !done.contains(i)).collect(), ..every.clone() };
    let second = part_of(&scene, &rest);
    assert_same(&merge(&[first.clone(), second.clone()]).unwrap(), &whole, "resumed");
    // A checkpoint merged beside the part that finished it counts its tiles once.
    assert_same(&merge(&[first.clone(), first, second]).unwrap(), &whole, "tiles twice");
}

#[test]
fn mismatched_and_incomplete_parts_are_refused() {
    let (_, scene) = scenes().remove(0);
    let a = part_of(&scene, &job(&scene, (0, 2), (0, 1)));
    let b = part_of(&scene, &job(&scene, (1, 2), (0, 1)));
    assert!(merge(&[a.clone(), b.clone()]).is_ok());
    let mut other = scene.clone();
    other.render.seed += 1;
    let c = part_of(&other, &job(&other, (1, 2), (0, 1)));
    let err = merge(&[a.clone(), c]).unwrap_err();
    assert_eq!(err.part, Some(1));
    assert!(err.message.contains("another scene or other options"), "{err}");
    let err = merge(std::slice::from_ref(&a)).unwrap_err();
    assert!(err.message.contains("tiles are in no part"), "{err}");
    // Passes split differently overlap; a missing pass is named.
    let p = part_of(&scene, &job(&scene, (0, 1), (0, 2)));
    let q = part_of(&scene, &job(&scene, (0, 1), (1, 3)));
    assert!(merge(&[p.clone(), q]).unwrap_err().message.contains("split them differently"));
    let err = merge(&[p]).unwrap_err();
    assert!(err.message.contains("lacks samples 16..37"), "{err}");
    assert!(merge(&[]).is_err());
}

#[test]
fn damaged_files_are_refused_not_read() {
    let (_, scene) = scenes().remove(0);
    let p = part_of(&scene, &job(&scene, (0, 4), (0, 2)));
    let bytes = p.encode();
    assert_eq!(Part::decode(&bytes).unwrap(), p);
    for len in (0..bytes.len()).step_by(97) {
        assert!(Part::decode(&bytes[..len]).is_err(), "truncated to {len}");
    }
    for at in (0..bytes.len()).step_by(89) {
        let mut damaged = bytes.clone();
        damaged[at] ^= 0x20;
        assert!(Part::decode(&damaged).is_err(), "byte {at} flipped");
    }
    assert!(Part::decode(b"P6\n1 1\n255\n").unwrap_err().contains("not a film part"));
    assert_eq!(part::EXTENSION, "film");
}

#[test]
fn sample_passes_split_at_blocks() {
    assert_eq!(share_samples(37, 0, 2), 0..16);
    assert_eq!(share_samples(37, 1, 2), 16..37);
    assert!((0..6).any(|i| share_samples(37, i, 6).is_empty()), "five blocks make at most five passes");
    for n in 1..6 {
        let passes: Vec<_> = (0..n).map(|i| share_samples(37, i, n)).collect();
        assert!(passes.iter().all(|p| !p.is_empty() && p.start % 8 == 0 && (p.end % 8 == 0 || p.end == 37)));
        assert!(passes.windows(2).all(|w| w[0].end == w[1].start) && passes[n as usize - 1].end == 37);
    }
    // A part whose samples do not start at a block is not one alhazen writes: refused on reading.
    let (_, scene) = scenes().remove(0);
    let mut odd = job(&scene, (0, 4), (0, 1));
    odd.samples = 3..37;
    assert!(Part::decode(&part_of(&scene, &odd).encode()).unwrap_err().contains("holds samples 3..37"));
}

#[test]
fn shares_are_contiguous_disjoint_and_cover() {
    for total in [0u64, 1, 7, 64, 1000] {
        for n in 1..9 {
            let shares: Vec<_> = (0..n).map(|i| share(total, i, n)).collect();
            assert_eq!(shares[0].start, 0);
            assert_eq!(shares[n as usize - 1].end, total);
            assert!(shares.windows(2).all(|w| w[0].end == w[1].start));
        }
    }
}
