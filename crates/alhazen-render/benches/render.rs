//! Criterion benchmarks: the glass-balls scene at reduced size (whole pipeline), rays per
//! second against the BVH, and the Cornell box's world with rays like a path tracer's (from
//! inside the room, in every direction), each world once per packet kernel the processor runs
//! (`portable`, `avx2`, `avx512`: the same hits, so only the speed differs), one ray at a time
//! and eight at a time (as the path tracer's lanes trace them). The full-size
//! comparisons are
//! `bench/povray-compare.sh` and `bench/mitsuba/compare.py`.

use alhazen_math::{Ray, Vec3};
use alhazen_render::World;
use alhazen_render::shape::{RayPacket, VectorUnit};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;
use std::path::Path;

fn example(name: &str) -> alhazen_scene::Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes").join(name);
    alhazen_scene::load_scene(&path).expect("scene loads")
}

fn glass_balls() -> alhazen_scene::Scene {
    example("glass-balls.toml")
}

fn bench_render(c: &mut Criterion) {
    let mut scene = glass_balls();
    scene.render.width = 200;
    scene.render.height = 150;
    let mut g = c.benchmark_group("glass-balls");
    g.sample_size(10);
    g.throughput(Throughput::Elements(200 * 150 * 4));
    g.bench_function("200x150 4spp (camera samples/s)", |b| {
        b.iter(|| alhazen_render::render(black_box(&scene), &|_, _| {}))
    });
    g.finish();
}

fn bench_intersect(c: &mut Criterion) {
    let scene = glass_balls();
    let rays: Vec<Ray> = (0..1024)
        .map(|i| {
            let (x, y) = ((i % 32) as f64 / 32.0 - 0.5, (i / 32) as f64 / 32.0 - 0.3);
            Ray::new(Vec3::new(0.0, 2.2, -7.0), Vec3::new(x, y - 0.2, 1.0).normalize())
        })
        .collect();
    let mut g = c.benchmark_group("intersect");
    g.throughput(Throughput::Elements(rays.len() as u64));
    for unit in VectorUnit::available() {
        let world = World::build_with(&scene, unit);
        g.bench_function(format!("glass-balls world, {} (rays/s)", unit.name()), |b| {
            b.iter(|| rays.iter().filter(|r| world.intersect(black_box(r), f64::INFINITY).is_some()).count())
        });
    }
    g.finish();
}

fn bench_cornell_rays(c: &mut Criterion) {
    let scene = example("cornell-box.toml");
    let mut state = 12345u64;
    let mut uniform = || {
        state = state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let rays: Vec<Ray> = (0..4096)
        .map(|_| {
            let o = Vec3::new(uniform() * 1.8 - 0.9, uniform() * 1.8 - 0.9, uniform() * 1.8 - 0.9);
            Ray::new(o, Vec3::new(uniform() - 0.5, uniform() - 0.5, uniform() - 0.5).normalize())
        })
        .collect();
    let mut g = c.benchmark_group("cornell-box world");
    g.throughput(Throughput::Elements(rays.len() as u64));
    for unit in VectorUnit::available() {
        let world = World::build_with(&scene, unit);
        g.bench_function(format!("nearest hit, {} (rays/s)", unit.name()), |b| {
            b.iter(|| rays.iter().filter(|r| world.intersect(black_box(r), f64::INFINITY).is_some()).count())
        });
        g.bench_function(format!("shadow rays of length 0.5, {} (rays/s)", unit.name()), |b| {
            b.iter(|| rays.iter().filter(|r| world.unoccluded(black_box(r.origin), r.dir, 0.5)).count())
        });
        // The path tracer's lanes: eight rays per call (ray by lane with AVX-512).
        let packets: Vec<RayPacket> = rays
            .chunks_exact(8)
            .map(|chunk| {
                let mut p = RayPacket::default();
                chunk.iter().enumerate().for_each(|(i, r)| p.set(i, r));
                p
            })
            .collect();
        g.bench_function(format!("nearest hit, eight at a time, {} (rays/s)", unit.name()), |b| {
            let mut hits = [None; 8];
            b.iter(|| {
                let mut n = 0;
                for p in &packets {
                    world.intersect_rays(black_box(p), [true; 8], &mut hits);
                    n += hits.iter().flatten().count();
                }
                n
            })
        });
        g.bench_function(format!("shadow rays of length 0.5, eight at a time, {} (rays/s)", unit.name()), |b| {
            let dist = [0.5; 8];
            b.iter(|| packets.iter().flat_map(|p| world.unoccluded_rays(black_box(p), &dist, [true; 8])).count())
        });
    }
    g.finish();
}

criterion_group!(benches, bench_render, bench_intersect, bench_cornell_rays);
criterion_main!(benches);
