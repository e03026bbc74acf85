//! Reflexes per second: the scalar solvers, the batch API, and a baseline that solves the same
//! quartic (5) with the generic `roots` crate and then classifies, side by side.

use alhazen_math::{Vec2, Vec3};
use alhazen_mirror::batch::{PointsSoA, ReflexesSoA};
use alhazen_mirror::{Cylinder, Site, Sphere};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;

const N: usize = 4096;

/// Scene-like points: a cloud in front of and around a unit mirror at the origin, eye at
/// (0, 1, 6); deterministic (a fixed linear congruential sequence).
fn points() -> Vec<Vec3> {
    let mut state = 0x2545F4914F6CDD1Du64;
    let mut next = || {
        state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..N).map(|_| Vec3::new(next() * 8.0 - 4.0, next() * 4.0 - 1.0, next() * 6.0 - 1.0)).collect()
}

/// The baseline: coefficients (5) in the canonical frame, `roots::find_roots_quartic`, y from
/// the hyperbola (3), then classification of every solution by the reflection condition.
fn baseline_visible(r: f64, e: f64, s: Vec2) -> Option<Vec2> {
    let (sx, sy) = (s.x, s.y);
    let (u, v, w) = (2.0 / (r * r), 1.0 / (sx * sx + sy * sy), 1.0 / e);
    let c4 = u * u;
    let c3 = -2.0 * u * (v * sx + w);
    let c2 = v * (1.0 + 2.0 * w * sx) + w * w - 2.0 * u;
    let c1 = 4.0 * sx * v + 2.0 * w * sx * sx * v + 2.0 * w;
    let c0 = v * sy * sy - v * r * r * (1.0 + 2.0 * w * sx + w * w * sx * sx);
    let roots = roots::find_roots_quartic(c4, c3, c2, c1, c0);
    let mut best = None;
    for &x in roots.as_ref() {
        let y = sy * (2.0 * e * x * x - r * r * (x + e)) / (2.0 * e * sx * x - r * r * (sx + e));
        let p = Vec2::new(x, y);
        let n = p / r;
        let (a, b) = ((Vec2::new(e, 0.0) - p).normalize(), (s - p).normalize());
        if a.dot(n) > 0.0 && b.dot(n) > 0.0 {
            best = Some(p);
        }
    }
    best
}

fn bench(c: &mut Criterion) {
    let pts = points();
    let sphere = Sphere { center: Vec3::ZERO, radius: 1.0 };
    let cyl = Cylinder { center: Vec3::ZERO, axis: Vec3::Y, radius: 1.0 };
    let eye = Vec3::new(0.0, 1.0, 6.0);
    let (xs, ys, zs): (Vec<f64>, Vec<f64>, Vec<f64>) =
        (pts.iter().map(|p| p.x).collect(), pts.iter().map(|p| p.y).collect(), pts.iter().map(|p| p.z).collect());
    let soa = PointsSoA { x: &xs, y: &ys, z: &zs };
    // The same problems in the canonical frame, for the 2D baseline.
    let d = eye.length();
    let xh = eye / d;
    let canon: Vec<Vec2> = pts.iter().map(|p| Vec2::new(p.dot(xh), (*p - xh * p.dot(xh)).length())).collect();

    let mut g = c.benchmark_group("reflexes per second (1 core)");
    g.throughput(Throughput::Elements(N as u64));
    g.bench_function("sphere batch (visible)", |b| {
        let mut out = ReflexesSoA::default();
        b.iter(|| sphere.visible_reflexes_batch(black_box(eye), soa, &mut out).unwrap())
    });
    g.bench_function("cylinder batch (visible)", |b| {
        let mut out = ReflexesSoA::default();
        b.iter(|| cyl.visible_reflexes_batch(black_box(eye), soa, &mut out).unwrap())
    });
    g.bench_function("sphere scalar visible_reflex", |b| {
        b.iter(|| {
            pts.iter()
                .filter(|p| sphere.visible_reflex(Site::At(eye), Site::At(black_box(**p))).unwrap().is_some())
                .count()
        })
    });
    g.bench_function("sphere scalar reflexes (all, classified)", |b| {
        b.iter(|| {
            pts.iter()
                .map(|p| sphere.reflexes(Site::At(eye), Site::At(black_box(*p))).map_or(0, |r| r.all().count()))
                .sum::<usize>()
        })
    });
    g.bench_function("baseline: roots crate quartic + classify (2D)", |b| {
        b.iter(|| canon.iter().filter(|s| baseline_visible(1.0, d, black_box(**s)).is_some()).count())
    });
    g.bench_function("ours: canonical 2D visible (same problems)", |b| {
        b.iter(|| {
            canon.iter().filter(|s| alhazen_mirror::batch::canonical_visible(1.0, d, black_box(**s)).is_some()).count()
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
