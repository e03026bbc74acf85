//! Traces a file of rays against a mesh with alhazen's world (top-level BVH over objects, SAH
//! BVH over the mesh's triangles): the BVH side of `bench/embree/bvh.py`, which traces the same
//! rays with Embree 4.
//!
//! ```sh
//! cargo run --release -p alhazen-render --example trace_rays -- MESH.ply RAYS.bin HITS.bin [THREADS] [sah|morton]
//! ```
//!
//! `RAYS.bin`: little-endian `f32` records `ox oy oz dx dy dz` (directions need not be unit).
//! `HITS.bin`: one `f32` per ray, the hit distance along the ray's unit direction (infinity
//! for a miss). Prints the world's build time (the mesh already loaded) and rays per second,
//! best of three passes, for the nearest hits alone (`World::nearest_hit`, the query Embree's
//! `rtcIntersect1` answers) and with their surfaces (`World::intersect`), on `THREADS` threads (default: all; 0 for all), the mesh's BVH built by
//! the surface area heuristic (default) or in Morton order.

use alhazen_math::{Ray, Vec3};
use alhazen_render::World;
use rayon::prelude::*;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [mesh, rays, hits, rest @ ..] = args.as_slice() else {
        return Err("usage: trace_rays MESH.ply RAYS.bin HITS.bin [THREADS] [sah|morton]".into());
    };
    let threads = rest.first().map(|t| t.parse()).transpose()?.unwrap_or(0);
    let method = match rest.get(1).map(String::as_str) {
        None | Some("sah") => alhazen_render::bvh::BuildMethod::Sah,
        Some("morton") => alhazen_render::bvh::BuildMethod::Morton,
        Some(other) => return Err(format!("unknown BVH build {other:?}: sah or morton").into()),
    };
    rayon::ThreadPoolBuilder::new().num_threads(threads).build_global()?;
    let mesh = std::path::absolute(mesh)?;
    let text = format!(
        "[meshes.m]\nfile = {:?}\n[[object]]\nshape = \"mesh\"\nmesh = \"m\"\nsmooth = false\n",
        mesh.display().to_string()
    );
    let scene = alhazen_scene::parse_scene("trace_rays.toml".as_ref(), &text)?;
    let bytes = std::fs::read(rays)?;
    let floats: Vec<f32> = bytes.chunks_exact(4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect();
    let rays: Vec<Ray> = floats
        .chunks_exact(6)
        .map(|r| {
            let v = |i: usize| Vec3::new(r[i] as f64, r[i + 1] as f64, r[i + 2] as f64);
            Ray::new(v(0), v(3).normalize())
        })
        .collect();
    let t0 = Instant::now();
    let world = World::build_by(&scene, alhazen_render::shape::VectorUnit::detect(), method);
    let build = t0.elapsed().as_secs_f64();
    // The nearest hits alone (Embree's query), then with each hit's surface (what a renderer
    // shades: normals, texture coordinates, material).
    let nearest = |ray: &Ray| world.nearest_hit(ray, f64::INFINITY).map_or(f32::INFINITY, |h| h.0.t as f32);
    let surface = |ray: &Ray| world.intersect(ray, f64::INFINITY).map_or(f32::INFINITY, |h| h.hit.t as f32);
    let (t, best) = best_of_three(&rays, nearest);
    let (t_surface, best_surface) = best_of_three(&rays, surface);
    assert_eq!(t, t_surface, "both queries find the same hits");
    std::fs::write(hits, t.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>())?;
    let hit_count = t.iter().filter(|x| x.is_finite()).count();
    println!(
        "alhazen: {} triangles, build {:.3} s, {} rays ({} hit) in {:.3} s: {:.2} Mrays/s on {} threads \
         ({:.2} Mrays/s with the hits' surfaces)",
        scene.meshes.iter().map(|m| m.triangle_count()).sum::<usize>(),
        build,
        rays.len(),
        hit_count,
        best,
        rays.len() as f64 / best / 1e6,
        rayon::current_num_threads(),
        rays.len() as f64 / best_surface / 1e6,
    );
    Ok(())
}

/// Each ray's hit distance by `trace`, and the best time of three passes over all of them.
fn best_of_three(rays: &[Ray], trace: impl Fn(&Ray) -> f32 + Sync) -> (Vec<f32>, f64) {
    let (mut t, mut best) = (vec![], f64::INFINITY);
    for _ in 0..3 {
        let t0 = Instant::now();
        t = rays.par_chunks(4096).flat_map_iter(|chunk| chunk.iter().map(&trace)).collect();
        best = best.min(t0.elapsed().as_secs_f64());
    }
    (t, best)
}
