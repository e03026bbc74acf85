//! `alhazen lines` on `scenes/lines/bench-many-objects.toml` (62 spheres, cylinders, cones and
//! cubes, two mirrors): exact visibility with and without reflections, against the sampled
//! visibility of fogleman/ln's approach at two step sizes.

use alhazen_lines::drawing::Layer;
use alhazen_lines::{Options, draw};
use criterion::{Criterion, criterion_group, criterion_main};
use std::path::Path;

fn bench(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/lines/bench-many-objects.toml");
    let scene = alhazen_scene::load_scene(&path).unwrap();
    let runs = [
        ("exact, no reflections", Options { reflections: false, ..Options::default() }),
        ("exact, with reflections", Options::default()),
        (
            "sampled every 1 px, no reflections",
            Options { reflections: false, sampled: Some(1.0), ..Options::default() },
        ),
        (
            "sampled every 0.25 px, no reflections",
            Options { reflections: false, sampled: Some(0.25), ..Options::default() },
        ),
    ];
    let mut g = c.benchmark_group("lines (2 threads)");
    g.sample_size(10);
    for (name, opts) in &runs {
        let (d, s) = draw(&scene, opts).unwrap();
        eprintln!(
            "{name}: {} visible polylines, {:.1} mm visible, {} reflected polylines, {:.1} mm reflected",
            s.visible,
            d.length(Layer::Visible),
            s.reflected,
            d.length(Layer::Reflected)
        );
        g.bench_function(*name, |b| b.iter(|| draw(&scene, opts).unwrap()));
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
