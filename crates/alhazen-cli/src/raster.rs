//! `alhazen raster`: the software raster pipeline (issue 6) as an offline renderer — the quick
//! preview of a scene before a long ray-traced render.

use crate::{Failure, check_output};
use alhazen_raster::pipeline::geometry::scene_triangles;
use alhazen_raster::pipeline::{RasterOptions, Shading, render_triangles};
use alhazen_render::Image;
use alhazen_render::output::write_image;
use alhazen_scene::{MAX_PIXELS, SceneError, load_scene};
use clap::Args;
use std::path::PathBuf;
use std::time::Instant;

/// `--shading`.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub(crate) enum ShadingArg {
    /// One colour per triangle.
    Flat,
    /// Colours at the vertices, interpolated.
    Gouraud,
    /// Normals interpolated, lighting per pixel.
    Phong,
}

#[derive(Args)]
pub(crate) struct RasterArgs {
    /// The scene file (TOML).
    scene: PathBuf,
    /// Output image: .png, .exr or .pfm.
    #[arg(short, long)]
    output: PathBuf,
    /// Image width in pixels (overrides the scene).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=65536))]
    width: Option<u32>,
    /// Image height in pixels (overrides the scene).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=65536))]
    height: Option<u32>,
    /// Shading method.
    #[arg(long, value_enum, default_value = "phong")]
    shading: ShadingArg,
    /// Keep back faces of closed surfaces.
    #[arg(long)]
    no_cull: bool,
    /// Draw triangle edges on top.
    #[arg(long)]
    wireframe: bool,
    /// Render this many frames and report frames per second (the last one is written).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=10000))]
    frames: u32,
    /// Worker threads (default: all cores).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    threads: Option<u32>,
    /// Write EXR as 16-bit half floats.
    #[arg(long)]
    half: bool,
    /// No summary.
    #[arg(short, long)]
    quiet: bool,
}

pub(crate) fn run(a: &RasterArgs) -> Result<(), Failure> {
    let format = check_output(&a.output, a.half)?;
    let mut scene = load_scene(&a.scene).map_err(|e| match e {
        SceneError::Io { .. } => Failure::input(e.to_string()),
        SceneError::Syntax(d) => Failure::input(d.to_string()),
    })?;
    scene.render.width = a.width.unwrap_or(scene.render.width);
    scene.render.height = a.height.unwrap_or(scene.render.height);
    if scene.render.width as u64 * scene.render.height as u64 > MAX_PIXELS {
        return Err(Failure::input(format!("{}×{} pixels is too many", scene.render.width, scene.render.height)));
    }
    let opts = RasterOptions {
        shading: match a.shading {
            ShadingArg::Flat => Shading::Flat,
            ShadingArg::Gouraud => Shading::Gouraud,
            ShadingArg::Phong => Shading::Phong,
        },
        cull: !a.no_cull,
        wireframe: a.wireframe,
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(a.threads.map_or(0, |t| t as usize))
        .build()
        .map_err(|e| Failure::work(e.to_string()))?;
    let start = Instant::now();
    let geometry = scene_triangles(&scene);
    let tessellation = start.elapsed().as_secs_f64();
    let start = Instant::now();
    let mut last = None;
    for _ in 0..a.frames {
        last = Some(
            pool.install(|| render_triangles(&scene, &geometry, &opts)).map_err(|e| Failure::input(e.to_string()))?,
        );
    }
    let elapsed = start.elapsed().as_secs_f64();
    let (fb, stats) = last.expect("at least one frame");
    let image = Image { width: fb.width, height: fb.height, pixels: fb.color };
    write_image(&image, &a.output, format)
        .map_err(|e| Failure::work(format!("cannot write {}: {e}", a.output.display())))?;
    if !a.quiet {
        let per_frame = elapsed / a.frames as f64;
        eprintln!(
            "rasterised {} ({}×{}, {} triangles tessellated in {:.3} s, {} culled, {} drawn{}) in {:.4} s per frame ({:.1} fps, {:.2} M triangles/s) on {} threads → {}",
            a.scene.display(),
            image.width,
            image.height,
            stats.triangles,
            tessellation,
            stats.culled,
            stats.drawn,
            if stats.skipped_objects > 0 {
                format!(", {} CSG objects skipped", stats.skipped_objects)
            } else {
                String::new()
            },
            per_frame,
            1.0 / per_frame,
            stats.triangles as f64 / per_frame / 1e6,
            pool.current_num_threads(),
            a.output.display()
        );
    }
    Ok(())
}
