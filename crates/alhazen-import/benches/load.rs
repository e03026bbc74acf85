//! Time to import scene files, apart from building the renderer's world (BVHs):
//! `cargo bench -p alhazen-import --bench load -- FILE...` prints, per file, the best of five
//! `alhazen_import::load` and of five `alhazen_render::World::build` on its scene.
//! `bench/import/load_time.py` writes a million-triangle mesh in every format and runs this.

use std::time::Instant;

fn best_of<T>(runs: usize, mut f: impl FnMut() -> T) -> f64 {
    (0..runs)
        .map(|_| {
            let t = Instant::now();
            std::hint::black_box(f());
            t.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

fn main() {
    let files: Vec<String> = std::env::args().skip(1).filter(|a| !a.starts_with("--")).collect();
    if files.is_empty() {
        eprintln!("usage: cargo bench -p alhazen-import --bench load -- FILE...");
        return;
    }
    for f in files {
        let path = std::path::Path::new(&f);
        let scene = match alhazen_import::load(path) {
            Ok(s) => s.scene,
            Err(e) => {
                eprintln!("{f}: {e}");
                continue;
            }
        };
        let triangles: usize = scene.meshes.iter().map(|m| m.triangle_count()).sum();
        let load = best_of(5, || alhazen_import::load(path).map(|s| s.scene.objects.len()));
        let build = best_of(5, || alhazen_render::World::build(&scene).bounds());
        println!("{f}: {triangles} triangles: import {load:.3} s, world (BVH) {build:.3} s");
    }
}
