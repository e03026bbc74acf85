//! Criterion benchmarks: the glass-balls scene at reduced size (whole pipeline) and rays per
//! second against the BVH. The full-size comparison with POV-Ray is `bench/povray-compare.sh`.

use alhazen_math::{Ray, Vec3};
use alhazen_render::World;
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;
use std::path::Path;

fn glass_balls() -> alhazen_scene::Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/glass-balls.toml");
    alhazen_scene::load_scene(&path).expect("scene loads")
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
    let world = World::build(&scene);
    let rays: Vec<Ray> = (0..1024)
        .map(|i| {
            let (x, y) = ((i % 32) as f64 / 32.0 - 0.5, (i / 32) as f64 / 32.0 - 0.3);
            Ray::new(Vec3::new(0.0, 2.2, -7.0), Vec3::new(x, y - 0.2, 1.0).normalize())
        })
        .collect();
    let mut g = c.benchmark_group("intersect");
    g.throughput(Throughput::Elements(rays.len() as u64));
    g.bench_function("glass-balls world (rays/s)", |b| {
        b.iter(|| rays.iter().filter(|r| world.intersect(black_box(r), f64::INFINITY).is_some()).count())
    });
    g.finish();
}

criterion_group!(benches, bench_render, bench_intersect);
criterion_main!(benches);
