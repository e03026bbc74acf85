//! `alhazen raster`: the software raster pipeline (issue 6) as an offline renderer — the quick
//! preview of a scene before a long ray-traced render.

use crate::{Failure, ImageArgs, check_output, load_sized};
use alhazen_raster::pipeline::stencil::StencilMode;
use alhazen_raster::pipeline::{RasterOptions, Shading, ShadowMethod, Visibility, prepare, render_prepared};
use alhazen_render::Image;
use clap::Args;
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

/// `--shadow-method`.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub(crate) enum ShadowMethodArg {
    /// Shadow maps.
    Maps,
    /// Stencil shadow volumes, depth pass.
    DepthPass,
    /// Stencil shadow volumes, depth fail (Carmack's reverse).
    DepthFail,
}

/// `--visibility`.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub(crate) enum VisibilityArg {
    /// A depth buffer.
    Zbuffer,
    /// The BSP-tree painter's algorithm.
    Bsp,
    /// The scan-line algorithm (a depth buffer of one row, an active triangle list).
    Scanline,
    /// The depth-sort painter's algorithm (Newell's overlap tests, splitting cycles).
    DepthSort,
    /// Warnock's area subdivision.
    Warnock,
}

#[derive(Args)]
pub(crate) struct RasterArgs {
    #[command(flatten)]
    image: ImageArgs,
    /// Shading method.
    #[arg(long, value_enum, default_value = "phong")]
    shading: ShadingArg,
    /// Keep back faces of closed surfaces.
    #[arg(long)]
    no_cull: bool,
    /// Draw triangle edges on top.
    #[arg(long)]
    wireframe: bool,
    /// No shadows.
    #[arg(long)]
    no_shadows: bool,
    /// Shadow algorithm: shadow maps, or stencil shadow volumes counted in front of the surface
    /// (depth pass) or behind it (depth fail).
    #[arg(long, value_enum, default_value = "maps")]
    shadow_method: ShadowMethodArg,
    /// Light from the environment map or background: diffuse (nine-coefficient irradiance)
    /// and glossy (prefiltered environment, split sum).
    #[arg(long)]
    ibl: bool,
    /// The course's hemispherical lighting (background up and down) instead of the ambient term.
    #[arg(long)]
    hemispherical: bool,
    /// With a stereo camera: one red–cyan anaglyph instead of the two views side by side.
    #[arg(long)]
    anaglyph: bool,
    /// Draw every triangle, without the octree's view-frustum culling (the same image; for
    /// measuring what the culling saves).
    #[arg(long)]
    no_frustum_culling: bool,
    /// Hidden-surface removal: depth buffer, or the painter's algorithm over a BSP tree.
    #[arg(long, value_enum, default_value = "zbuffer")]
    visibility: VisibilityArg,
    /// Keep only the world-space half-space `a x + b y + c z + d ≥ 0` (repeatable).
    #[arg(long, value_name = "A,B,C,D", value_parser = parse_plane)]
    clip_plane: Vec<alhazen_math::Vec4>,
    /// Drop triangles wholly outside this half-space (repeatable).
    #[arg(long, value_name = "A,B,C,D", value_parser = parse_plane)]
    cull_plane: Vec<alhazen_math::Vec4>,
    /// Render this many frames and report frames per second (the last one is written).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=10000))]
    frames: u32,
    /// Show a radiosity solution written by `alhazen render --integrator radiosity --export
    /// FILE.ply` (of this scene) instead of lighting the scene: its elements, Gouraud-shaded
    /// by their vertex-averaged light, textures per pixel. No solving again.
    #[arg(long, value_name = "FILE.ply")]
    radiosity: Option<std::path::PathBuf>,
}

/// `a,b,c,d` with a non-zero normal `(a, b, c)`.
fn parse_plane(s: &str) -> Result<alhazen_math::Vec4, String> {
    let v: Vec<f64> =
        s.split(',').map(|x| x.trim().parse::<f64>().map_err(|e| format!("{x:?}: {e}"))).collect::<Result<_, _>>()?;
    let [a, b, c, d] = v[..] else { return Err(format!("expected 4 numbers a,b,c,d, found {}", v.len())) };
    if !(a.is_finite() && b.is_finite() && c.is_finite() && d.is_finite()) || a * a + b * b + c * c == 0.0 {
        return Err("the plane needs finite numbers and a non-zero normal (a, b, c)".into());
    }
    Ok(alhazen_math::Vec4::new(a, b, c, d))
}

/// True when an environment map is the scene's only light (no lamps, no emitters): the
/// preview's objects are then dark without image-based lighting.
fn lit_by_environment_only(scene: &alhazen_scene::Scene) -> bool {
    use alhazen_scene::Light;
    let map = scene.lights.iter().any(|l| matches!(l, Light::Environment { .. }));
    let others = scene.lights.iter().any(|l| !matches!(l, Light::Environment { .. }));
    map && !others && scene.materials.iter().all(|m| m.emission == alhazen_math::Vec3::ZERO)
}

pub(crate) fn run(a: &RasterArgs) -> Result<(), Failure> {
    let format = check_output(&a.image.output, a.image.half)?;
    let output = crate::open_output(&a.image.output)?;
    let scene = load_sized(&a.image)?;
    if !a.ibl && lit_by_environment_only(&scene) {
        eprintln!("warning: the scene is lit by its environment map alone: --ibl lights the preview by it");
    }
    if a.anaglyph && !matches!(scene.camera, alhazen_scene::CameraDesc::Stereo { .. }) {
        return Err(Failure::input(format!(
            "{}: --anaglyph needs a stereo camera (`type = \"stereo\"`)",
            a.image.scene.display()
        )));
    }
    let opts = RasterOptions {
        shading: match a.shading {
            ShadingArg::Flat => Shading::Flat,
            ShadingArg::Gouraud => Shading::Gouraud,
            ShadingArg::Phong => Shading::Phong,
        },
        cull: !a.no_cull,
        wireframe: a.wireframe,
        shadows: !a.no_shadows,
        ibl: a.ibl,
        hemispherical: a.hemispherical,
        anaglyph: a.anaglyph,
        frustum_culling: !a.no_frustum_culling,
        clip_planes: a.clip_plane.clone(),
        cull_planes: a.cull_plane.clone(),
        shadow_method: match a.shadow_method {
            ShadowMethodArg::Maps => ShadowMethod::Maps,
            ShadowMethodArg::DepthPass => ShadowMethod::Volumes(StencilMode::DepthPass),
            ShadowMethodArg::DepthFail => ShadowMethod::Volumes(StencilMode::DepthFail),
        },
        visibility: match a.visibility {
            VisibilityArg::Zbuffer => Visibility::ZBuffer,
            VisibilityArg::Bsp => Visibility::Bsp,
            VisibilityArg::Scanline => Visibility::Scanline,
            VisibilityArg::DepthSort => Visibility::DepthSort,
            VisibilityArg::Warnock => Visibility::Warnock,
        },
    };
    crate::check_memory(alhazen_raster::pipeline::memory_estimate(&scene, &opts), "previewing this scene")?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(a.image.threads.map_or(0, |t| t as usize))
        .build()
        .map_err(|e| Failure::work(e.to_string()))?;
    let start = Instant::now();
    let prepared = match &a.radiosity {
        Some(path) => pool.install(|| crate::radiosity::prepare_solution(path, &scene))?,
        None => pool.install(|| prepare(&scene, &opts)),
    };
    let tessellation = start.elapsed().as_secs_f64();
    let start = Instant::now();
    let mut last = None;
    for _ in 0..a.frames {
        last = Some(
            pool.install(|| render_prepared(&scene, &prepared, &opts)).map_err(|e| Failure::input(e.to_string()))?,
        );
    }
    let elapsed = start.elapsed().as_secs_f64();
    let (fb, stats) = last.expect("at least one frame");
    let image = Image { width: fb.width, height: fb.height, pixels: fb.color };
    output
        .write_image(&image, format, a.image.display.display())
        .map_err(|e| Failure::work(format!("cannot write {}: {e}", a.image.output.display())))?;
    if !a.image.quiet {
        let per_frame = elapsed / a.frames as f64;
        eprintln!(
            "rasterised {} ({}×{}, {} triangles tessellated{} in {:.3} s, {} culled, {} drawn, {} between pixel centres or clipped away{}) in {:.4} s per frame ({:.1} fps, {:.2} M triangles/s) on {} threads → {}",
            a.image.scene.display(),
            image.width,
            image.height,
            stats.triangles,
            match (opts.shadows, opts.visibility, &a.radiosity) {
                (_, _, Some(_)) => " from the radiosity solution",
                (true, Visibility::Bsp, None) => ", shadow maps and BSP tree built",
                (true, _, None) => " and shadow maps rendered",
                (false, Visibility::Bsp, None) => " and BSP tree built",
                (false, _, None) => "",
            },
            tessellation,
            stats.culled,
            stats.drawn,
            stats.missed,
            if stats.skipped_objects > 0 {
                format!(", {} CSG objects skipped", stats.skipped_objects)
            } else {
                String::new()
            } + &if stats.reflexes > 0 {
                format!(", {} pieces drawn in mirrors", stats.reflexes)
            } else {
                String::new()
            },
            per_frame,
            1.0 / per_frame,
            stats.triangles as f64 / per_frame / 1e6,
            pool.current_num_threads(),
            a.image.output.display()
        );
    }
    Ok(())
}
