//! `alhazen render` and `alhazen merge`: a render made at once, in parts to be merged (bands
//! of tiles, shares of the samples: `alhazen_render::film::part`), or saved to a checkpoint and
//! resumed after an interruption. Every way gives the same bits.

use crate::{DisplayArgs, Failure, ImageArgs, check_output, check_output_dir, load_sized, open_output, progress_bar};
use alhazen_render::film::part::{self, Part, fingerprint, merge, share, share_samples};
use alhazen_render::film::{Job, SAMPLE_BLOCK, TileResult, tiles};
use alhazen_render::shape::VectorUnit;
use alhazen_scene::Scene;
use clap::Args;
use indicatif::ProgressBar;
use std::io::Write;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Set by Ctrl-C or SIGTERM while a checkpointed render runs: no new tile is begun.
static STOP: AtomicBool = AtomicBool::new(false);

/// The exit code of a render interrupted by a signal (128 + SIGINT, as shells report it).
const INTERRUPTED: u8 = 130;

#[derive(Args)]
pub(crate) struct RenderArgs {
    #[command(flatten)]
    image: ImageArgs,
    /// Samples per pixel (overrides the scene).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1048576))]
    spp: Option<u32>,
    /// Maximum ray depth (overrides the scene).
    #[arg(long, value_parser = clap::value_parser!(u32).range(0..=1000))]
    depth: Option<u32>,
    /// Random seed (overrides the scene): a whole number from 0 to 2^64 − 1.
    #[arg(long, allow_negative_numbers = true, value_parser = parse_seed)]
    seed: Option<u64>,
    /// Integrator (overrides the scene): recursive ray tracing or path tracing.
    #[arg(long, value_enum)]
    integrator: Option<IntegratorArg>,
    /// The path tracer's sampler (overrides the scene).
    #[arg(long, value_enum)]
    sampler: Option<SamplerArg>,
    /// How the path tracer's light samples choose among several lights (overrides the scene):
    /// by the direct light a pilot pass measures each sending to what the camera sees, by
    /// power, or uniformly. Every choice converges to the same image.
    #[arg(long, value_enum)]
    light_choice: Option<LightChoiceArg>,
    /// The pixel reconstruction filter, with its default parameters (overrides the scene's,
    /// e.g. the Gaussian an imported Mitsuba or pbrt scene gets when it names none): `box` is
    /// each sample anywhere in its own pixel.
    #[arg(long, value_parser = clap::builder::PossibleValuesParser::new(alhazen_scene::PixelFilter::NAMES))]
    filter: Option<String>,
    /// Do not join lights to surfaces through sphere, cylinder and plane mirrors exactly (for
    /// comparison: caustics are then left to sampled paths, and lost under Whitted).
    #[arg(long)]
    no_mirror_connections: bool,
    /// The vector kernels to use (default: the widest this processor has). Every kernel renders
    /// the same image; this is for measuring their speed.
    #[arg(long, value_enum)]
    kernel: Option<KernelArg>,
    /// How meshes' bounding volume hierarchies are built: the surface area heuristic (traces
    /// faster) or Morton order (builds faster). The hits are the same but for exact ties.
    #[arg(long, value_enum, default_value = "sah")]
    bvh: BvhArg,
    /// Render band I of N of the film's tiles (0 ≤ I < N) into a film part (-o NAME.film), to
    /// be joined with `alhazen merge`: e.g. one band per machine or per job of an array.
    #[arg(long, value_name = "I/N", value_parser = parse_split)]
    tile: Option<(u32, u32)>,
    /// Render share I of N of every pixel's samples (0 ≤ I < N; shares are whole blocks of 8
    /// samples) into a film part (-o NAME.film); merged, the shares give the bits of one render.
    #[arg(long, value_name = "I/N", value_parser = parse_split)]
    pass: Option<(u32, u32)>,
    /// Save progress to FILE (a film part, .film) every --checkpoint-every seconds and when
    /// interrupted (Ctrl-C, SIGTERM); finish later with --resume. Removed once the output is written.
    #[arg(long, value_name = "FILE")]
    checkpoint: Option<PathBuf>,
    /// Seconds between checkpoints.
    #[arg(long, default_value_t = 60.0, value_name = "SECONDS", value_parser = parse_seconds)]
    checkpoint_every: f64,
    /// Continue from the --checkpoint file (when it exists): its tiles are not rendered again,
    /// and the image has the bits of an uninterrupted render.
    #[arg(long, requires = "checkpoint")]
    resume: bool,
    #[command(flatten)]
    radiosity: crate::radiosity::RadiosityArgs,
    #[command(flatten)]
    photon: crate::photon::PhotonArgs,
}

/// `--kernel`.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
enum KernelArg {
    /// Scalar loops, on any processor.
    Portable,
    /// AVX2 (x86-64).
    Avx2,
    /// AVX-512 F, DQ, VL and BW (x86-64).
    Avx512,
}

/// `--bvh`.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
enum BvhArg {
    /// The surface area heuristic.
    Sah,
    /// Morton order (a linear BVH).
    Morton,
}

/// `--integrator`.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
enum IntegratorArg {
    /// The lecture's recursive ray tracer.
    Whitted,
    /// Path tracing with next-event estimation and MIS.
    Path,
    /// The course's radiosity (diffuse interreflection, solved once), then an image by ray
    /// casting the solution (mirrors and glass followed).
    Radiosity,
    /// Path tracing with caustics (light through mirrors and glass onto diffuse surfaces) from
    /// a photon map: point lights' caustics appear, area lights' converge.
    Photon,
}

/// `--sampler`.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
enum SamplerArg {
    /// Owen-scrambled Sobol points.
    Sobol,
    /// Independent uniform numbers.
    Independent,
}

/// `--light-choice`.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
enum LightChoiceArg {
    /// By the direct light each sends to what the camera sees (a pilot pass; the default).
    Measured,
    /// By power.
    Power,
    /// Every light equally often.
    Uniform,
}

fn apply_overrides(scene: &mut Scene, a: &RenderArgs) {
    let r = &mut scene.render;
    r.spp = a.spp.unwrap_or(r.spp);
    r.max_depth = a.depth.unwrap_or(r.max_depth);
    r.seed = a.seed.unwrap_or(r.seed);
    if let Some(i) = a.integrator {
        r.integrator = match i {
            IntegratorArg::Whitted => alhazen_scene::IntegratorKind::Whitted,
            IntegratorArg::Path => alhazen_scene::IntegratorKind::Path,
            IntegratorArg::Radiosity => alhazen_scene::IntegratorKind::Radiosity,
            IntegratorArg::Photon => alhazen_scene::IntegratorKind::Photon,
        };
    }
    if a.no_mirror_connections {
        r.mirror_connections = false;
    }
    if let Some(f) = a.filter.as_deref().and_then(alhazen_scene::PixelFilter::named) {
        r.filter = f;
    }
    if let Some(s) = a.sampler {
        r.sampler = match s {
            SamplerArg::Sobol => alhazen_scene::SamplerKind::Sobol,
            SamplerArg::Independent => alhazen_scene::SamplerKind::Independent,
        };
    }
    if let Some(c) = a.light_choice {
        r.light_choice = match c {
            LightChoiceArg::Measured => alhazen_scene::LightChoice::Measured,
            LightChoiceArg::Power => alhazen_scene::LightChoice::Power,
            LightChoiceArg::Uniform => alhazen_scene::LightChoice::Uniform,
        };
    }
}

/// Whitted lights with emitting spheres, disks, boxes and meshes; says which others it only
/// shows.
fn warn_unsampled_emitters(scene: &Scene) {
    let emits = |o: &alhazen_scene::Object| scene.materials[o.material as usize].emission != alhazen_math::Vec3::ZERO;
    let sampled = |i: usize| alhazen_render::lights::Lights::samples_object(scene, i);
    let unsampled = scene.objects.iter().enumerate().filter(|(i, o)| emits(o) && !sampled(*i)).count();
    if unsampled > 0 {
        eprintln!(
            "warning: {unsampled} emitting object(s) light nothing under Whitted ray tracing (only spheres, disks, rectangles, boxes and meshes do; not cylinders, cones, patches, CSG or distorted spheres): they are shown, not sampled; use --integrator path"
        );
    }
}

fn parse_seed(s: &str) -> Result<u64, String> {
    s.parse::<u64>().map_err(|_| format!("a seed is a whole number from 0 to 18446744073709551615, not {s:?}"))
}

/// The kernel `--kernel` names, if this processor has it.
fn vector_unit(kernel: Option<KernelArg>) -> Result<VectorUnit, Failure> {
    let Some(kernel) = kernel else { return Ok(VectorUnit::detect()) };
    let name = match kernel {
        KernelArg::Portable => "portable",
        KernelArg::Avx2 => "avx2",
        KernelArg::Avx512 => "avx512",
    };
    let available = VectorUnit::available();
    available.iter().copied().find(|u| u.name() == name).ok_or_else(|| {
        let names: Vec<&str> = available.iter().map(|u| u.name()).collect();
        Failure::input(format!("--kernel {name}: this processor lacks it (it has: {})", names.join(", ")))
    })
}

fn parse_split(s: &str) -> Result<(u32, u32), String> {
    let bad = || format!("expected I/N with 0 ≤ I < N (e.g. 0/4 for the first of four), not {s:?}");
    let (i, n) = s.split_once('/').ok_or_else(bad)?;
    let (i, n): (u32, u32) = (i.trim().parse().map_err(|_| bad())?, n.trim().parse().map_err(|_| bad())?);
    if i >= n {
        return Err(bad());
    }
    Ok((i, n))
}

fn parse_seconds(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        _ => Err(format!("a number of seconds, 0 or more, not {s:?}")),
    }
}

fn is_part(path: &Path) -> bool {
    path.extension().and_then(|e| e.to_str()) == Some(part::EXTENSION)
}

/// What this command renders: tiles and samples of the film.
struct Plan {
    width: u32,
    height: u32,
    spp: u32,
    fingerprint: u64,
    band: Range<usize>,
    samples: Range<u32>,
}

impl Plan {
    fn new(scene: &Scene, a: &RenderArgs) -> Result<Self, Failure> {
        let (width, height) = alhazen_render::film_size(scene);
        let spp = scene.render.spp;
        let count = tiles(width, height).len();
        let band = a.tile.map_or(0..count as u64, |(i, n)| share(count as u64, i, n));
        let samples = a.pass.map_or(0..spp, |(i, n)| share_samples(spp, i, n));
        if band.is_empty() {
            let n = a.tile.map_or(1, |t| t.1);
            return Err(Failure::input(format!(
                "--tile …/{n}: a {width}×{height} film has only {count} tiles; use at most {count} bands"
            )));
        }
        if samples.is_empty() {
            let n = a.pass.map_or(1, |p| p.1);
            let most = spp.div_ceil(SAMPLE_BLOCK);
            return Err(Failure::input(format!(
                "--pass …/{n}: passes split the samples in blocks of {SAMPLE_BLOCK}, so {spp} samples per pixel make at most {most} passes"
            )));
        }
        let band = band.start as usize..band.end as usize;
        // Only what is saved to be merged or resumed needs the fingerprint (hashing a big
        // scene's meshes takes a moment).
        let saved = is_part(&a.image.output) || a.checkpoint.is_some();
        let fingerprint = if saved { fingerprint(scene) } else { 0 };
        Ok(Self { width, height, spp, fingerprint, band, samples })
    }

    fn empty_part(&self) -> Part {
        Part::new(self.fingerprint, self.width, self.height, self.spp)
    }
}

pub(crate) fn run(a: &RenderArgs) -> Result<(), Failure> {
    let unit = vector_unit(a.kernel)?;
    let out = &a.image.output;
    let format = if is_part(out) {
        check_output_dir(out)?;
        None
    } else if a.tile.is_some() || a.pass.is_some() {
        return Err(Failure::input(format!(
            "{}: --tile and --pass write a film part; name the output NAME.{} and join the parts with `alhazen merge`",
            out.display(),
            part::EXTENSION
        )));
    } else {
        Some(check_output(out, a.image.half)?)
    };
    if let Some(c) = &a.checkpoint {
        if !is_part(c) {
            return Err(Failure::input(format!(
                "{}: a checkpoint is a film part, NAME.{}",
                c.display(),
                part::EXTENSION
            )));
        }
        check_output_dir(c)?;
    }
    let output = open_output(out)?;
    let mut scene = load_sized(&a.image)?;
    apply_overrides(&mut scene, a);
    // `--integrator`, or the scene's `[render] integrator`.
    let radiosity = scene.render.integrator == alhazen_scene::IntegratorKind::Radiosity;
    a.radiosity.check(radiosity)?;
    let photon = scene.render.integrator == alhazen_scene::IntegratorKind::Photon;
    a.photon.check(photon, &scene)?;
    if scene.render.integrator == alhazen_scene::IntegratorKind::Whitted && !radiosity {
        warn_unsampled_emitters(&scene);
    }
    let mut plan = Plan::new(&scene, a)?;
    if radiosity && plan.fingerprint != 0 {
        // Parts of renders with other radiosity settings must not merge.
        plan.fingerprint ^= part::hash_debug(&("radiosity", a.radiosity.settings()));
    }
    if photon && plan.fingerprint != 0 {
        plan.fingerprint ^= part::hash_debug(&("photon", a.photon.settings(scene.render.seed)));
    }
    let what = format!("rendering this {}×{} film", plan.width, plan.height);
    let photons = if photon { a.photon.memory_estimate() } else { 0 };
    crate::check_memory(alhazen_render::memory_estimate(&scene) + photons, &what)?;
    let resumed = match &a.checkpoint {
        Some(c) => open_checkpoint(c, a.resume, &plan)?,
        None => plan.empty_part(),
    };
    let threads = a.image.threads.map_or(0, |t| t as usize);
    let pool =
        rayon::ThreadPoolBuilder::new().num_threads(threads).build().map_err(|e| Failure::work(e.to_string()))?;
    if a.checkpoint.is_some() {
        ctrlc::set_handler(|| {
            if STOP.swap(true, Ordering::SeqCst) {
                std::process::exit(INTERRUPTED.into()); // a second interrupt: leave now
            }
        })
        .map_err(|e| Failure::work(format!("cannot catch interrupts for the checkpoint: {e}")))?;
    }
    let start = Instant::now();
    let solution = match radiosity {
        true => Some(pool.install(|| crate::radiosity::solve(&scene, &a.radiosity, a.image.quiet))?),
        false => None,
    };
    // The world the tracers trace, built apart so that the summary tells its time.
    let (world, map);
    let mut world_time = None;
    let source = match &solution {
        Some(s) => Source::Radiosity(s),
        None => {
            let building = Instant::now();
            world = pool.install(|| alhazen_render::World::build_by(&scene, unit, bvh_method(a.bvh)));
            world_time = Some(building.elapsed());
            match photon {
                true => {
                    map = pool.install(|| crate::photon::build(&scene, &world, &a.photon, a.image.quiet))?;
                    Source::Photons(&world, &map)
                }
                false => Source::Scene(&world),
            }
        }
    };
    let (part, stopped) = pool.install(|| render_plan(&scene, &plan, resumed, a, &source));
    let elapsed = start.elapsed();
    let total = plan.band.len();
    if stopped {
        let c = a.checkpoint.as_ref().expect("only a checkpointed render stops");
        save_checkpoint(c, &part)?;
        return Err(Failure {
            code: INTERRUPTED,
            message: format!(
                "interrupted after {} of {total} tiles; progress is saved in {}: run the same command with --resume to finish",
                part.tiles.len(),
                c.display()
            ),
        });
    }
    let written = match format {
        None => output.finish(|f| f.write_all(&part.encode())),
        Some(format) => {
            let image = part.into_image().map_err(|e| Failure::work(e.to_string()))?;
            output.write_image(&image, format, a.image.display.display())
        }
    };
    written.map_err(|e| Failure::work(format!("cannot write {}: {e}", out.display())))?;
    if let Some(c) = &a.checkpoint {
        let _ = std::fs::remove_file(c); // its work is in the output now
    }
    if !a.image.quiet {
        summary(&scene, a, &plan, (elapsed, world_time), pool.current_num_threads(), &source);
    }
    Ok(())
}

/// The checkpoint to continue from: empty for a fresh render; refused when it exists and
/// --resume is not given (it is progress the user would lose) or when it is another render's.
fn open_checkpoint(path: &Path, resume: bool, plan: &Plan) -> Result<Part, Failure> {
    if !path.exists() {
        if resume {
            eprintln!("note: no checkpoint at {} yet; starting from the beginning", path.display());
        }
        return Ok(plan.empty_part());
    }
    if !resume {
        return Err(Failure::input(format!(
            "{} exists: add --resume to continue from it, or remove it to start again",
            path.display()
        )));
    }
    let part = read_part(path)?;
    let theirs = (part.fingerprint, part.width, part.height, part.spp);
    if theirs != (plan.fingerprint, plan.width, plan.height, plan.spp) {
        return Err(Failure::input(format!(
            "{} is the checkpoint of another render (the scene or the options differ); remove it or name another --checkpoint",
            path.display()
        )));
    }
    if part.tiles.iter().any(|(s, t)| *s != plan.samples || !plan.band.contains(&t.index)) {
        return Err(Failure::input(format!(
            "{} holds other tiles or samples than this command renders (--tile or --pass differ)",
            path.display()
        )));
    }
    Ok(part)
}

/// Reads a film part, or says what is wrong with it (bad input, exit 2).
pub(crate) fn read_part(path: &Path) -> Result<Part, Failure> {
    let bytes = std::fs::read(path).map_err(|e| Failure::input(format!("cannot read {}: {e}", path.display())))?;
    Part::decode(&bytes).map_err(|e| Failure::input(format!("{}: {e}", path.display())))
}

fn save_checkpoint(path: &Path, part: &Part) -> Result<(), Failure> {
    let bytes = part.encode();
    alhazen_render::output::write_atomically(path, |f| f.write_all(&bytes))
        .map_err(|e| Failure::work(format!("cannot write the checkpoint {}: {e}", path.display())))
}

/// Renders the plan's tiles that `resumed` lacks; returns them all, and whether an interrupt
/// stopped the render.
fn render_plan(scene: &Scene, plan: &Plan, resumed: Part, a: &RenderArgs, source: &Source) -> (Part, bool) {
    let done: Vec<bool> = {
        let mut d = vec![false; plan.band.end];
        resumed.tiles.iter().for_each(|(_, t)| d[t.index] = true);
        d
    };
    let job = Job {
        tiles: plan.band.clone().filter(|&i| !done[i]).collect(),
        samples: plan.samples.clone(),
        keep_sums: plan.samples != (0..plan.spp),
    };
    let bar = progress_bar(a.image.quiet);
    bar.set_length(plan.band.len() as u64);
    bar.set_position(resumed.tiles.len() as u64);
    let state = Mutex::new(Progress {
        part: resumed,
        saved: Instant::now(),
        started: Instant::now(),
        new: 0,
        warned: false,
        unusable: 0,
        clamped: 0,
    });
    let every = Duration::from_secs_f64(a.checkpoint_every);
    render_tiles(scene, source, &job, &|t| {
        let mut s = state.lock().unwrap_or_else(|e| e.into_inner());
        s.unusable += t.unusable_samples;
        s.clamped += t.clamped_pixels;
        s.part.push(job.samples.clone(), t);
        s.new += 1;
        bar.inc(1);
        s.warn_if_long(job.tiles.len(), &bar);
        if let Some(c) = a.checkpoint.as_ref().filter(|_| s.saved.elapsed() >= every) {
            if let Err(f) = save_checkpoint(c, &s.part) {
                bar.println(format!("warning: {}", f.message));
            }
            s.saved = Instant::now();
        }
    });
    bar.finish_and_clear();
    let progress = state.into_inner().unwrap_or_else(|e| e.into_inner());
    if progress.unusable > 0 {
        eprintln!(
            "warning: {} samples had a radiance that is not a finite number or is beyond ±1e300 (a degenerate value in the scene?): left out or clamped",
            progress.unusable
        );
    }
    if progress.clamped > 0 {
        eprintln!(
            "warning: {} pixels are brighter than a 32-bit float can hold and keep the largest one (3.4e38); is a light or an emission absurdly strong?",
            progress.clamped
        );
    }
    let part = progress.part;
    let stopped = STOP.load(Ordering::SeqCst) && part.tiles.len() < plan.band.len();
    (part, stopped)
}

/// What the image is made from besides the scene.
enum Source<'a> {
    /// The scene's integrator over its world.
    Scene(&'a alhazen_render::World),
    /// A radiosity solution.
    Radiosity(&'a alhazen_radiosity::Solution),
    /// The world and its caustic photon map (the path tracer takes caustics from it).
    Photons(&'a alhazen_render::World, &'a alhazen_photon::CausticMap),
}

fn bvh_method(bvh: BvhArg) -> alhazen_render::bvh::BuildMethod {
    match bvh {
        BvhArg::Sah => alhazen_render::bvh::BuildMethod::Sah,
        BvhArg::Morton => alhazen_render::bvh::BuildMethod::Morton,
    }
}

/// The job's tiles by the scene's integrator, from a radiosity solution, or with a photon map.
fn render_tiles(scene: &Scene, source: &Source, job: &Job, done: &(dyn Fn(TileResult) + Sync)) {
    let (w, h) = alhazen_render::film_size(scene);
    match source {
        Source::Radiosity(s) => {
            alhazen_render::film::render_tiles(w, h, &alhazen_radiosity::FinalGather::new(s), job, &STOP, done)
        }
        Source::Photons(world, map) => {
            let r = &scene.render;
            let camera = alhazen_render::Camera::new(&scene.camera, r.width, r.height);
            let tracer = alhazen_render::path::PathTracer::new(scene, world, &camera).with_caustics(*map);
            alhazen_render::film::render_tiles(w, h, &tracer, job, &STOP, done)
        }
        Source::Scene(world) => alhazen_render::render_tiles_in(scene, world, job, &STOP, done),
    }
}

struct Progress {
    part: Part,
    saved: Instant,
    started: Instant,
    new: usize,
    warned: bool,
    /// Samples the film left out or clamped.
    unusable: u64,
    /// Pixels beyond the float range.
    clamped: u64,
}

impl Progress {
    /// Once a few tiles are done, warns if the rest will take over an hour.
    fn warn_if_long(&mut self, of: usize, bar: &ProgressBar) {
        let elapsed = self.started.elapsed().as_secs_f64();
        if self.warned || self.new < 4.max(of / 50) || elapsed < 2.0 {
            return;
        }
        self.warned = true;
        let left = elapsed / self.new as f64 * (of - self.new) as f64;
        if left > 3600.0 {
            bar.println(format!(
                "warning: about {:.1} hours left at this pace (from the first {} tiles); --checkpoint FILE lets a render be stopped and resumed, --tile/--pass split it over machines",
                left / 3600.0,
                self.new
            ));
        }
    }
}

/// A pixel filter in a few words, e.g. `gaussian filter (σ 0.5, radius 2)`.
fn describe_filter(f: &alhazen_scene::PixelFilter) -> String {
    use alhazen_scene::PixelFilter as F;
    let r = f.radius();
    let radius = if r[0] == r[1] { format!("radius {}", r[0]) } else { format!("radius {} × {}", r[0], r[1]) };
    match *f {
        F::Box { .. } => format!("box filter ({radius})"),
        F::Tent { .. } => format!("tent filter ({radius})"),
        F::BlackmanHarris { .. } => format!("blackman-harris filter ({radius})"),
        F::Gaussian { sigma, .. } => format!("gaussian filter (σ {sigma}, {radius})"),
        F::Mitchell { b, c, .. } => format!("mitchell filter (B {b:.3}, C {c:.3}, {radius})"),
        F::Lanczos { tau, .. } => format!("lanczos filter (τ {tau}, {radius})"),
    }
}

/// The summary line on stderr: what was rendered, in how long (`elapsed` in all, the part of it
/// that built the world when one was built), on how many threads, to which file.
fn summary(
    scene: &Scene,
    a: &RenderArgs,
    plan: &Plan,
    (elapsed, world_time): (Duration, Option<Duration>),
    threads: usize,
    source: &Source,
) {
    let r = &scene.render;
    let integrator = match (r.integrator, source) {
        (_, Source::Photons(_, map)) => format!(
            "path tracing, {:?} sampler, caustics from {} photons shot ({} stored, gathered within {:.3})",
            r.sampler,
            map.shot,
            map.photons().len(),
            map.radius()
        )
        .replacen("Sobol", "sobol", 1)
        .replacen("Independent", "independent", 1),
        (_, Source::Radiosity(s)) => {
            let st = &s.stats;
            format!(
                "radiosity: {} patches of at most {:.3}, {} elements, {} shots, {:.2} % left unshot",
                st.patches,
                st.patch_size,
                st.elements,
                st.shots,
                100.0 * st.unshot
            )
        }
        (alhazen_scene::IntegratorKind::Whitted, Source::Scene(_)) => "Whitted ray tracing".to_string(),
        // Photon and radiosity renders have their own source.
        (_, Source::Scene(_)) => format!("path tracing, {:?} sampler", r.sampler).to_lowercase(),
    };
    let what = match (a.tile, a.pass) {
        (None, None) => String::new(),
        _ => format!(
            "; tiles {}..{} of {}, samples {}..{}",
            plan.band.start,
            plan.band.end,
            tiles(plan.width, plan.height).len(),
            plan.samples.start,
            plan.samples.end
        ),
    };
    let building = world_time.map_or(String::new(), |t| format!(", {:.3} s of it building the world", t.as_secs_f64()));
    let filter = match r.filter {
        alhazen_scene::PixelFilter::PIXEL => String::new(),
        f => format!(", {}", describe_filter(&f)),
    };
    eprintln!(
        "rendered {} ({}×{}, {} spp, depth {}, {integrator}{filter}{what}) in {:.3} s on {threads} thread{}{building} → {}",
        a.image.scene.display(),
        plan.width,
        plan.height,
        r.spp,
        r.max_depth,
        elapsed.as_secs_f64(),
        if threads == 1 { "" } else { "s" },
        a.image.output.display()
    );
}

/// `alhazen merge`.
#[derive(Args)]
pub(crate) struct MergeArgs {
    /// The film parts (.film) written by `alhazen render --tile/--pass`, in any order.
    #[arg(required = true)]
    parts: Vec<PathBuf>,
    /// Output image: .png (8-bit sRGB), .exr or .pfm (linear floats).
    #[arg(short, long)]
    output: PathBuf,
    /// Write EXR as 16-bit half floats instead of 32-bit floats.
    #[arg(long)]
    half: bool,
    /// No summary.
    #[arg(short, long)]
    quiet: bool,
    #[command(flatten)]
    display: DisplayArgs,
}

pub(crate) fn run_merge(a: &MergeArgs) -> Result<(), Failure> {
    let format = check_output(&a.output, a.half)?;
    let output = open_output(&a.output)?;
    let parts = a.parts.iter().map(|p| read_part(p)).collect::<Result<Vec<_>, _>>()?;
    let image = merge(&parts).map_err(|e| {
        let first = a.parts[0].display();
        match e.part {
            Some(k) => Failure::input(format!("{}: {e} ({first})", a.parts[k].display())),
            None => Failure::input(format!("the parts do not make a whole image: {e}")),
        }
    })?;
    output
        .write_image(&image, format, a.display.display())
        .map_err(|e| Failure::work(format!("cannot write {}: {e}", a.output.display())))?;
    if !a.quiet {
        eprintln!(
            "merged {} parts ({}×{}, {} spp) → {}",
            parts.len(),
            image.width,
            image.height,
            parts[0].spp,
            a.output.display()
        );
    }
    Ok(())
}
