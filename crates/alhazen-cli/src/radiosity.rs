//! `alhazen render --integrator radiosity` (solve, export, then the final image through the
//! same tiles, bands and checkpoints as the other integrators) and the solution read back by
//! `raster --radiosity` and `view --radiosity`.

use crate::{Failure, check_output_dir, open_output};
use alhazen_radiosity::{Settings, Solution, ply};
use alhazen_scene::Scene;
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use std::io::BufWriter;
use std::path::{Path, PathBuf};

/// Surface triangles beyond which the solve is slow.
const MANY_TRIANGLES: usize = 20_000;

/// The radiosity integrator's settings.
#[derive(Args, Clone, Debug)]
pub(crate) struct RadiosityArgs {
    /// Radiosity: longest edge of a shooting patch, in scene units (default: about 1024
    /// patches over the scene).
    #[arg(long, value_name = "LENGTH", value_parser = parse_length)]
    patch_size: Option<f64>,
    /// Radiosity: levels of refinement below the patches (each splits an element in four).
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u8).range(0..=8))]
    levels: u8,
    /// Radiosity: stop when at most this fraction of the light is left unshot.
    #[arg(long, default_value_t = 0.002, value_name = "FRACTION", value_parser = parse_fraction)]
    radiosity_tolerance: f64,
    /// Radiosity: shoot through the course's hemicube of N pixels across (the item buffer
    /// filled by ray casting) instead of Lambert's exact form factors; the elements are then
    /// fixed in advance (every patch split --levels times).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(8..=4096))]
    hemicube: Option<u32>,
    /// Radiosity: also write the solution as a PLY mesh (per-vertex irradiance and sRGB
    /// colour), which `alhazen raster --radiosity` and `alhazen view --radiosity` show without
    /// solving again.
    #[arg(long, value_name = "FILE.ply")]
    export: Option<PathBuf>,
}

pub(crate) fn parse_length(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(x) if x.is_finite() && x > 0.0 => Ok(x),
        _ => Err(format!("`{s}` is not a positive length")),
    }
}

fn parse_fraction(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(x) if x > 0.0 && x < 1.0 => Ok(x),
        _ => Err(format!("`{s}` is not a fraction between 0 and 1")),
    }
}

impl RadiosityArgs {
    /// The solver's settings.
    pub(crate) fn settings(&self) -> Settings {
        Settings {
            patch_size: self.patch_size,
            levels: self.levels,
            tolerance: self.radiosity_tolerance,
            hemicube: self.hemicube,
            ..Settings::default()
        }
    }

    /// Refuses an export path that cannot be written, before any work.
    pub(crate) fn check(&self, radiosity: bool) -> Result<(), Failure> {
        let Some(path) = &self.export else { return Ok(()) };
        if !radiosity {
            return Err(Failure::input(
                "--export writes a radiosity solution: add --integrator radiosity (or `integrator = \"radiosity\"` in the scene's [render])",
            ));
        }
        if path.extension().and_then(|e| e.to_str()) != Some("ply") {
            return Err(Failure::input(format!("{}: the solution is written as a .ply mesh", path.display())));
        }
        check_output_dir(path)
    }
}

/// Solves `scene` with a progress bar, warns about what radiosity leaves out, and writes the
/// export if asked.
pub(crate) fn solve(scene: &Scene, a: &RadiosityArgs, quiet: bool) -> Result<Solution, Failure> {
    let settings = a.settings();
    crate::check_memory(alhazen_radiosity::memory_estimate(scene, &settings), "solving this scene's radiosity")?;
    let export = a.export.as_deref().map(open_output).transpose()?;
    let triangles = alhazen_raster::pipeline::geometry::scene_triangles(scene).triangles.len();
    if triangles > MANY_TRIANGLES && !quiet {
        eprintln!(
            "warning: {triangles} surface triangles: every triangle shoots and receives on its own (no clusters), so radiosity's time grows with their square; expect minutes"
        );
    }
    let bar = if quiet { ProgressBar::hidden() } else { ProgressBar::new(1000) };
    bar.set_style(
        ProgressStyle::with_template("{spinner} radiosity [{bar:40}] {msg} elapsed {elapsed}")
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    let tolerance = settings.tolerance;
    // Progress on a log scale from everything unshot to the tolerance.
    let solution = alhazen_radiosity::solve(scene, &settings, &|shots, unshot| {
        let done = (unshot.max(tolerance).ln() / tolerance.ln()).clamp(0.0, 1.0);
        bar.set_position((done * 1000.0) as u64);
        bar.set_message(format!("shot {shots}, {:.2} % unshot", 100.0 * unshot));
    })
    .map_err(|e| Failure::input(e.to_string()))?;
    bar.finish_and_clear();
    warn(scene, &solution, tolerance);
    if let (Some(file), Some(path)) = (export, &a.export) {
        write_solution(&solution, file, path)?;
    }
    Ok(solution)
}

/// What radiosity leaves out, said once.
fn warn(scene: &Scene, s: &Solution, tolerance: f64) {
    let st = &s.stats;
    if st.initial_power == 0.0 {
        eprintln!(
            "warning: nothing lights this scene for radiosity (no emitting surface, point, spot or directional light, and a black background): the image is black"
        );
    }
    if st.skipped > 0 {
        eprintln!("warning: {} CSG objects have no elements and are left out of the radiosity solution", st.skipped);
    }
    if st.planes.0 > 0 {
        eprintln!(
            "note: {} unbounded planes are cut to squares of side {:.4} around the scene (elements need an area)",
            st.planes.0, st.planes.1
        );
    }
    let zero = alhazen_math::Vec3::ZERO;
    let specular = scene.materials.iter().any(|m| m.mirror != zero || m.transparency != zero);
    if specular {
        eprintln!(
            "note: radiosity solves diffuse reflection only: mirrors and glass show what they reflect and let through in the image, but pass no light between surfaces"
        );
    }
    if st.unshot > 2.0 * tolerance {
        eprintln!("warning: {:.1} % of the light was left unshot after {} shots", 100.0 * st.unshot, st.shots);
    }
}

/// Writes the solution mesh atomically.
fn write_solution(s: &Solution, file: alhazen_render::output::PendingFile, path: &Path) -> Result<(), Failure> {
    let triangles = ply::lit_triangles(s);
    let fingerprint = ply::scene_fingerprint(&s.scene);
    let shown = |t: &ply::LitTriangle, k: usize| {
        alhazen_radiosity::display::shown(&s.scene, t.material, (t.uv[k], t.color[k]), t.irradiance[k], t.front)
    };
    file.finish(|f| ply::write(&mut BufWriter::new(f), &triangles, fingerprint, shown))
        .map_err(|e| Failure::work(format!("cannot write {}: {e}", path.display())))
}

/// A solution written by `--export`, checked against `scene`.
pub(crate) fn read_solution(path: &Path, scene: &Scene) -> Result<ply::LitMesh, Failure> {
    let bytes = std::fs::read(path).map_err(|e| Failure::input(format!("cannot read {}: {e}", path.display())))?;
    let mesh = ply::read(&bytes).map_err(|e| Failure::input(format!("{}: {e}", path.display())))?;
    let materials = scene.materials.len() as u32;
    if let Some(t) = mesh.triangles.iter().find(|t| t.material >= materials) {
        return Err(Failure::input(format!(
            "{}: a triangle has material {} but the scene has {materials}: this solution is of another scene",
            path.display(),
            t.material
        )));
    }
    if mesh.scene != Some(ply::scene_fingerprint(scene)) {
        eprintln!(
            "warning: {} was solved for another version of this scene (or another scene): showing it as it is",
            path.display()
        );
    }
    Ok(mesh)
}

/// The preview's geometry and light from a solution file: its triangles (culled from behind,
/// each side of a surface being its own triangle) and their light.
pub(crate) fn prepare_solution(path: &Path, scene: &Scene) -> Result<alhazen_raster::pipeline::Prepared, Failure> {
    use alhazen_raster::pipeline::geometry::{Triangle, Vertex};
    use alhazen_raster::pipeline::{Prelit, prepare_lit};
    let mesh = read_solution(path, scene)?;
    let (triangles, lit) = mesh
        .triangles
        .iter()
        .map(|t| {
            let v = std::array::from_fn(|k| Vertex { p: t.p[k], n: t.n[k], uv: t.uv[k], color: t.color[k] });
            let tri = Triangle { v, material: t.material, closed: true, unbounded: false, object: t.object };
            (tri, Prelit { irradiance: t.irradiance, front: t.front })
        })
        .unzip();
    Ok(prepare_lit(triangles, lit))
}
