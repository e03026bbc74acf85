//! `alhazen`: the command-line front end (`render`, `raster`, `view`, `mirror`, `lines`). The only crate that reads argv and the environment,
//! writes to stdout/stderr and chooses exit codes:
//! 0 success, 1 a failure while working (e.g. the output cannot be written), 2 bad input (usage,
//! an unreadable or invalid scene file, impossible sizes).

use alhazen_render::output::{Format, write_image};
use alhazen_scene::{MAX_PIXELS, Scene, SceneError};
use clap::{Args, Parser, Subcommand, ValueEnum};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

mod anamorph;
mod lines;
mod mirror;
mod photon;
mod radiosity;
mod raster;
mod render;
mod view;

#[derive(Parser)]
#[command(name = "alhazen", version, about = "Mirrors, glass and line art: one scene, exact reflections.")]
struct Cli {
    /// The memory alhazen may use, e.g. 12G or 512M (K, M, G, T: powers of 1024). A scene or
    /// an output that would need more is refused before anything is allocated. Default: three
    /// quarters of this machine's memory, or of the process's limit (ulimit -v, cgroup) if lower.
    #[arg(long, global = true, value_name = "SIZE", value_parser = parse_size)]
    max_memory: Option<u64>,
    #[command(subcommand)]
    command: Command,
}

/// The memory budget of this run (`--max-memory` or the machine's share), set once in `main`.
static MEMORY_BUDGET: std::sync::OnceLock<u64> = std::sync::OnceLock::new();

/// The memory budget of this run.
pub(crate) fn memory_budget() -> u64 {
    *MEMORY_BUDGET.get_or_init(default_memory_budget)
}

/// Refuses work that needs more than the memory budget (bad input: exit 2), naming the need.
pub(crate) fn check_memory(needed: u64, what: &str) -> Result<(), Failure> {
    let budget = memory_budget();
    if needed <= budget {
        return Ok(());
    }
    Err(Failure::input(format!(
        "{what} needs about {}, more than the memory budget of {} (--max-memory raises it)",
        alhazen_scene::format_bytes(needed),
        alhazen_scene::format_bytes(budget)
    )))
}

/// Three quarters of the least of: the machine's memory, the process's address-space limit,
/// its cgroup's memory limit (8 GiB where none can be read).
fn default_memory_budget() -> u64 {
    let read = |p: &str| std::fs::read_to_string(p).ok();
    let total = read("/proc/meminfo").and_then(|m| {
        let line = m.lines().find(|l| l.starts_with("MemTotal:"))?.to_string();
        Some(line.split_whitespace().nth(1)?.parse::<u64>().ok()? * 1024)
    });
    let address_space = read("/proc/self/limits").and_then(|l| {
        let line = l.lines().find(|l| l.starts_with("Max address space"))?.to_string();
        line.split_whitespace().nth(3)?.parse::<u64>().ok()
    });
    let cgroup = read("/sys/fs/cgroup/memory.max").and_then(|v| v.trim().parse::<u64>().ok());
    let least = [total, address_space, cgroup].into_iter().flatten().min().unwrap_or(8 << 30);
    least / 4 * 3
}

fn parse_size(s: &str) -> Result<u64, String> {
    let t = s.trim().trim_end_matches(['B', 'b']).trim_end_matches('i');
    let (digits, unit) = match t.char_indices().find(|(_, c)| c.is_ascii_alphabetic()) {
        Some((i, _)) => (&t[..i], &t[i..]),
        None => (t, ""),
    };
    let shift = match unit.to_ascii_uppercase().as_str() {
        "" => 0,
        "K" => 10,
        "M" => 20,
        "G" => 30,
        "T" => 40,
        _ => return Err(format!("a size such as 12G, 512M or 4096K, not {s:?}")),
    };
    match digits.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 && v * (1u64 << shift) as f64 <= u64::MAX as f64 => {
            Ok((v * (1u64 << shift) as f64) as u64)
        }
        _ => Err(format!("a size such as 12G, 512M or 4096K, not {s:?}")),
    }
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene to an image (PNG, EXR or PFM) by recursive (Whitted) ray tracing or path tracing.
    #[command(
        after_help = "Example:\n  alhazen render scenes/glass-balls.toml -o glass-balls.png --spp 16\n\nThe scene format is described in docs/scene-format.md."
    )]
    Render(render::RenderArgs),
    /// Rasterise a scene (the fast preview): z-buffer, shadow maps, flat/Gouraud/Phong shading.
    #[command(after_help = "Example:\n  alhazen raster scenes/glass-balls.toml -o preview.png --shading gouraud")]
    Raster(raster::RasterArgs),
    /// An interactive window on the raster preview: orbit, pan, zoom; R ray traces the view.
    #[command(
        after_help = "Controls: left drag or arrows orbit, right drag pans, wheel or +/- zooms,\n1/2/3 flat/Gouraud/Phong, S shadows, M maps/stencil, I environment light, H hemispherical, B z-buffer/BSP,\nW wireframe, C culling, R ray trace, Esc/Q quit.\n\nExample:\n  alhazen view scenes/glass-balls.toml"
    )]
    View(view::ViewArgs),
    /// Exact reflexes on spheres and cylinders (Glaeser), catacaustics and their figures.
    #[command(subcommand)]
    Mirror(mirror::MirrorCommand),
    /// Exact hidden-line drawing (SVG, PDF, PNG) with the reflections in spherical and
    /// cylindrical mirrors.
    #[command(
        after_help = "Examples:\n  alhazen lines scenes/lines/fig21-cylinder-in-sphere.toml -o fig21.svg\n  alhazen lines scenes/lines/fig1-town-in-cylinder.toml -o fig1.pdf --hidden\n  alhazen lines --graph ripple -o ripple.svg"
    )]
    Lines(lines::LinesArgs),
    /// Write any scene alhazen reads (glTF, Mitsuba XML, pbrt, TOML) as alhazen TOML, to edit it.
    #[command(
        after_help = "The meshes go to binary PLY and the images to OpenEXR files in OUT-assets/ beside OUT.toml.\n\nExample:\n  alhazen convert model.glb -o model.toml"
    )]
    Convert(ConvertArgs),
    /// Join film parts rendered with `render --tile/--pass` (e.g. on a cluster) into the image:
    /// bit for bit the one a single render makes.
    #[command(
        after_help = "Example:\n  for i in 0 1 2 3; do alhazen render scene.toml --tile $i/4 -o part$i.film; done\n  alhazen merge part*.film -o scene.exr"
    )]
    Merge(render::MergeArgs),
}

#[derive(Args)]
struct ConvertArgs {
    /// The scene to convert: alhazen TOML, glTF 2.0 (.gltf/.glb), Mitsuba 3 XML (.xml) or pbrt-v4 (.pbrt).
    scene: PathBuf,
    #[command(flatten)]
    parameters: SceneParameters,
    #[command(flatten)]
    environment: EnvironmentArgs,
    /// The TOML file to write (its meshes and images go to a folder beside it, named after it).
    #[arg(short, long)]
    output: PathBuf,
}

/// Values of a Mitsuba scene's `$name` parameters, as Mitsuba's own `-D name=value`.
#[derive(Args, Default)]
pub(crate) struct SceneParameters {
    /// A Mitsuba scene's parameter: `-D spp=64` gives `$spp` that value, over the scene's
    /// `<default>` (repeat for more); for a glTF file, `-D variant=NAME` picks a material
    /// variant (`KHR_materials_variants`).
    #[arg(short = 'D', long = "define", value_name = "NAME=VALUE", value_parser = parse_define)]
    pub(crate) defines: Vec<(String, String)>,
}

fn parse_define(s: &str) -> Result<(String, String), String> {
    let (name, value) = s.split_once('=').ok_or_else(|| format!("`{s}` is not NAME=VALUE"))?;
    let name = name.trim();
    if name.is_empty() || !name.chars().all(|c| c.is_alphanumeric() || c == '_') {
        return Err(format!("`{name}` is not a parameter name (letters, digits and _)"));
    }
    Ok((name.to_string(), value.to_string()))
}

/// An environment map to light a scene by, in place of its own (a glTF file has none: a
/// Blender export carries no world).
#[derive(Args, Default)]
pub(crate) struct EnvironmentArgs {
    /// Light the scene by this equirectangular map (Radiance .hdr or OpenEXR, linear radiance)
    /// instead of its own environment or sky: e.g. the HDRI a Blender scene exported to glTF
    /// was lit by (turned by --environment-rotate 90, it is where Blender shows it).
    #[arg(long, value_name = "FILE")]
    pub(crate) environment: Option<PathBuf>,
    /// The --environment map's values times this.
    #[arg(long, value_name = "SCALE", default_value_t = 1.0, allow_negative_numbers = true, value_parser = parse_environment_scale, requires = "environment")]
    pub(crate) environment_scale: f64,
    /// The --environment map turned about its up axis by this many degrees: its centre seen
    /// towards +z at 0, towards +x at 90 (as Blender's world behind the glTF files it writes).
    #[arg(long, value_name = "DEGREES", default_value_t = 0.0, allow_negative_numbers = true, value_parser = parse_degrees, requires = "environment")]
    pub(crate) environment_rotate: f64,
    /// The --environment map's up axis: y (glTF's, alhazen's) or z (a z-up scene's, as many
    /// pbrt and Mitsuba scenes are).
    #[arg(long, value_enum, default_value = "y", requires = "environment")]
    pub(crate) environment_up: UpAxis,
}

#[derive(Clone, Copy, Default, ValueEnum)]
pub(crate) enum UpAxis {
    #[default]
    Y,
    Z,
}

impl EnvironmentArgs {
    /// The map, read; `None` without `--environment`. A file that cannot be read as one is
    /// bad input.
    fn read(&self) -> Result<Option<alhazen_scene::OutsideEnvironment>, Failure> {
        let Some(file) = &self.environment else { return Ok(None) };
        let image = alhazen_scene::import::load_radiance_image(file)
            .map_err(|e| Failure::input(format!("--environment: {e}")))?;
        let up = match self.environment_up {
            UpAxis::Y => alhazen_math::Vec3::Y,
            UpAxis::Z => alhazen_math::Vec3::Z,
        };
        let rotation = self.environment_rotate.to_radians();
        Ok(Some(alhazen_scene::OutsideEnvironment { image: image.into(), scale: self.environment_scale, rotation, up }))
    }
}

fn parse_environment_scale(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(x) if x.is_finite() && x >= 0.0 => Ok(x),
        _ => Err(format!("a scale is a number of at least 0, not {s:?}")),
    }
}

fn parse_degrees(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(x) if x.is_finite() && x.abs() <= 1e6 => Ok(x),
        _ => Err(format!("an angle is a number of degrees from -1000000 to 1000000, not {s:?}")),
    }
}

/// What every image-producing command takes: the scene, the output and its size.
#[derive(Args)]
pub(crate) struct ImageArgs {
    /// The scene file: alhazen TOML, glTF 2.0 (.gltf/.glb), Mitsuba 3 XML (.xml) or pbrt-v4 (.pbrt).
    pub(crate) scene: PathBuf,
    #[command(flatten)]
    pub(crate) parameters: SceneParameters,
    #[command(flatten)]
    pub(crate) environment: EnvironmentArgs,
    /// Output image: .png (8-bit sRGB), .exr or .pfm (linear floats).
    #[arg(short, long)]
    pub(crate) output: PathBuf,
    /// Image width in pixels (overrides the scene).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub(crate) width: Option<u32>,
    /// Image height in pixels (overrides the scene).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub(crate) height: Option<u32>,
    /// Worker threads (default: all cores). The image does not depend on it.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub(crate) threads: Option<u32>,
    /// Write EXR as 16-bit half floats instead of 32-bit floats.
    #[arg(long)]
    pub(crate) half: bool,
    /// No progress bar or summary.
    #[arg(short, long)]
    pub(crate) quiet: bool,
    #[command(flatten)]
    pub(crate) display: DisplayArgs,
}

/// How radiance is shown: exposure and tone mapping.
#[derive(Args)]
pub(crate) struct DisplayArgs {
    /// Exposure in stops: radiance is scaled by 2^EV before it is written (every format).
    #[arg(long, value_name = "EV", default_value_t = 0.0, allow_negative_numbers = true, value_parser = parse_exposure)]
    pub(crate) exposure: f64,
    /// Tone mapping of .png output (EXR and PFM stay linear): none (colours beyond white are
    /// desaturated towards it), reinhard (L/(1+L) on luminance), filmic (Hable's curve).
    #[arg(long, value_enum, default_value = "none")]
    pub(crate) tonemap: TonemapArg,
}

#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum TonemapArg {
    None,
    Reinhard,
    Filmic,
}

impl DisplayArgs {
    pub(crate) fn display(&self) -> alhazen_render::output::Display {
        use alhazen_math::color::Tonemap;
        let tonemap = match self.tonemap {
            TonemapArg::None => Tonemap::None,
            TonemapArg::Reinhard => Tonemap::Reinhard,
            TonemapArg::Filmic => Tonemap::Filmic,
        };
        alhazen_render::output::Display { exposure: self.exposure, tonemap }
    }
}

fn parse_exposure(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(ev) if ev.is_finite() && ev.abs() <= 64.0 => Ok(ev),
        _ => Err(format!("an exposure is a number of stops from -64 to 64, not {s:?}")),
    }
}

/// An error and the exit code it deserves.
pub(crate) struct Failure {
    code: u8,
    message: String,
}

impl Failure {
    fn input(message: impl Into<String>) -> Self {
        Self { code: 2, message: message.into() }
    }
    fn work(message: impl Into<String>) -> Self {
        Self { code: 1, message: message.into() }
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    if let Some(bytes) = cli.max_memory {
        let _ = MEMORY_BUDGET.set(bytes);
    }
    let result = match cli.command {
        Command::Render(args) => render::run(&args),
        Command::Merge(args) => render::run_merge(&args),
        Command::Raster(args) => raster::run(&args),
        Command::View(args) => view::run(&args),
        Command::Mirror(cmd) => mirror::run(&cmd),
        Command::Lines(args) => lines::run(&args),
        Command::Convert(args) => run_convert(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(f) => {
            eprintln!("error: {}", f.message);
            ExitCode::from(f.code)
        }
    }
}

/// Reads a scene file in any format alhazen imports (TOML, glTF, Mitsuba XML, pbrt), printing
/// what the import approximated; every problem with it is bad input (exit code 2).
pub(crate) fn load(path: &Path, parameters: &SceneParameters, environment: &EnvironmentArgs) -> Result<Scene, Failure> {
    let format = alhazen_import::SceneFormat::from_path(path);
    let takes_parameters = matches!(format, alhazen_import::SceneFormat::Mitsuba | alhazen_import::SceneFormat::Gltf);
    if !parameters.defines.is_empty() && !takes_parameters {
        return Err(Failure::input(format!(
            "-D gives values to a Mitsuba scene's $parameters, or a glTF file's material variant; {} is a {} file",
            path.display(),
            format.name()
        )));
    }
    let unlit = alhazen_import::read_unlit(path, memory_budget(), &parameters.defines).map_err(|e| match e {
        SceneError::Io { .. } => Failure::input(e.to_string()),
        SceneError::Syntax(d) => Failure::input(d.to_string()),
    })?;
    // The --environment map (perhaps large) only once the scene has proved readable.
    let environment = environment.read()?;
    let imported = alhazen_import::light(unlit, path, environment.as_ref());
    for w in &imported.warnings {
        eprintln!("warning: {w}");
    }
    Ok(imported.scene)
}

/// Reads the scene and applies `--width`/`--height`, refusing sizes that cannot be allocated.
pub(crate) fn load_sized(a: &ImageArgs) -> Result<Scene, Failure> {
    let mut scene = load(&a.scene, &a.parameters, &a.environment)?;
    let r = &mut scene.render;
    r.width = a.width.unwrap_or(r.width);
    r.height = a.height.unwrap_or(r.height);
    if r.width as u64 * r.height as u64 > MAX_PIXELS {
        return Err(Failure::input(format!(
            "{}×{} pixels is more than the {MAX_PIXELS} this renderer can allocate",
            r.width, r.height
        )));
    }
    Ok(scene)
}

/// Writes `image` atomically, or says why not.
pub(crate) fn save(image: &alhazen_render::Image, path: &Path, format: Format) -> Result<(), Failure> {
    write_image(image, path, format).map_err(|e| Failure::work(format!("cannot write {}: {e}", path.display())))
}

pub(crate) fn check_output(path: &Path, half: bool) -> Result<Format, Failure> {
    let format = Format::from_path(path, half)
        .ok_or_else(|| Failure::input(format!("{}: unknown image format; use .png, .exr or .pfm", path.display())))?;
    check_output_dir(path)?;
    Ok(format)
}

/// Opens the output (its temporary file) before any work, so that a place where it cannot be
/// written is refused at once (exit 2) instead of after the render.
pub(crate) fn open_output(path: &Path) -> Result<alhazen_render::output::PendingFile, Failure> {
    alhazen_render::output::PendingFile::create(path)
        .map_err(|e| Failure::input(format!("cannot write {}: {e}", path.display())))
}

/// Refuses an output path whose directory does not exist, before any work is done.
pub(crate) fn check_output_dir(path: &Path) -> Result<(), Failure> {
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    if !dir.is_dir() {
        return Err(Failure::input(format!("{}: the directory {} does not exist", path.display(), dir.display())));
    }
    Ok(())
}

fn run_convert(a: &ConvertArgs) -> Result<(), Failure> {
    if a.output.extension().and_then(|e| e.to_str()) != Some("toml") {
        return Err(Failure::input(format!("{}: the output of convert is a .toml file", a.output.display())));
    }
    check_output_dir(&a.output)?;
    let scene = load(&a.scene, &a.parameters, &a.environment)?;
    let stem = a.output.file_stem().and_then(|s| s.to_str()).unwrap_or("scene");
    let assets = a.output.with_file_name(format!("{stem}-assets"));
    let header = format!(
        "Converted by alhazen {} from {} ({}).\nMeshes and images are in {}/.",
        env!("CARGO_PKG_VERSION"),
        a.scene.display(),
        alhazen_import::SceneFormat::from_path(&a.scene).name(),
        assets.file_name().and_then(|s| s.to_str()).unwrap_or("")
    );
    alhazen_scene::write::write_scene(&scene, &a.output, &assets, &header).map_err(|e| match e {
        alhazen_scene::write::WriteError::Unsupported(m) => Failure::input(m),
        e => Failure::work(e.to_string()),
    })?;
    eprintln!(
        "wrote {} ({} objects, {} meshes, {} images in {})",
        a.output.display(),
        scene.objects.len(),
        scene.meshes.len(),
        scene.images.len(),
        assets.display()
    );
    Ok(())
}

pub(crate) fn progress_bar(quiet: bool) -> ProgressBar {
    if quiet {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(1);
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} rendering [{bar:40}] {percent:>3}% tiles {pos}/{len} elapsed {elapsed} eta {eta}",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar())
        .progress_chars("=> "),
    );
    bar
}
