//! `alhazen view`: a window on the raster preview (issue 6). The scene is tessellated once; every
//! camera move redraws it with the raster pipeline. Keys launch the ray tracer on the current
//! view. Works under any X11 server, including Xvfb (`--screenshot` saves a frame and exits, for
//! checks without a person at the keyboard).
//!
//! Controls: left drag or arrow keys orbit around the target; right drag pans; wheel or `+`/`-`
//! zooms; `1`/`2`/`3` flat/Gouraud/Phong shading; `S` shadows; `M` shadow maps / stencil depth pass / depth fail; `I` environment light; `H` hemispherical lighting; `B` z-buffer/BSP painter; `W` wireframe; `C` back-face culling; `R` ray
//! traces the current view (Whitted, the scene's samples) and writes it to `--output`; `Esc` or
//! `Q` quits.

use crate::{Failure, check_output, load, save};
use alhazen_raster::pipeline::stencil::StencilMode;
use alhazen_raster::pipeline::{RasterOptions, Shading, ShadowMethod, Visibility, prepare, render_prepared};
use alhazen_render::Image;
use alhazen_render::output::to_srgb8;
use alhazen_scene::{CameraDesc, LookAt};
use clap::Args;
use minifb::{Key, KeyRepeat, MouseButton, MouseMode, Window, WindowOptions};
use std::path::PathBuf;
use std::time::Instant;

#[derive(Args)]
pub(crate) struct ViewArgs {
    /// The scene file: alhazen TOML, glTF (.gltf/.glb), Mitsuba 3 XML (.xml) or pbrt-v4 (.pbrt).
    scene: PathBuf,
    #[command(flatten)]
    parameters: crate::SceneParameters,
    #[command(flatten)]
    environment: crate::EnvironmentArgs,
    /// Window width (overrides the scene's image width).
    #[arg(long, value_parser = clap::value_parser!(u32).range(16..=8192))]
    width: Option<u32>,
    /// Window height.
    #[arg(long, value_parser = clap::value_parser!(u32).range(16..=8192))]
    height: Option<u32>,
    /// Where `R` writes the ray-traced view.
    #[arg(short, long, default_value = "view.png")]
    output: PathBuf,
    /// Draw `--frames` frames, save the last one to this file and exit.
    #[arg(long)]
    screenshot: Option<PathBuf>,
    /// Frames to draw before `--screenshot` (each orbits the camera by one degree).
    #[arg(long, default_value_t = 10, value_parser = clap::value_parser!(u32).range(1..=100000))]
    frames: u32,
    /// Orbit a radiosity solution (`alhazen render --integrator radiosity --export FILE.ply`)
    /// of this scene instead of the lit scene: the solution does not depend on the view.
    #[arg(long, value_name = "FILE.ply")]
    radiosity: Option<PathBuf>,
}

/// The orbiting camera: the look-at frame of the scene, moved by the user.
struct Orbit {
    look: LookAt,
    ortho_width: Option<f64>,
}

impl Orbit {
    /// Turns the eye about the target: `yaw` around the up vector, `pitch` towards it (radians).
    fn rotate(&mut self, yaw: f64, pitch: f64) {
        let up = self.look.up.normalize();
        let offset = self.look.eye - self.look.target;
        let r = alhazen_math::Transform::rotate(up, yaw);
        let mut o = r.vector(offset);
        let side = up.cross(o).normalize_or_zero();
        let tilted = alhazen_math::Transform::rotate(side, pitch).vector(o);
        // Stop short of the poles, where the frame would flip.
        if tilted.normalize().dot(up).abs() < 0.995 {
            o = tilted;
        }
        self.look.eye = self.look.target + o;
    }

    /// Moves eye and target together in the image plane (fractions of the distance).
    fn pan(&mut self, dx: f64, dy: f64) {
        let g = self.look.target - self.look.eye;
        let d = g.length();
        let u = g.cross(self.look.up).normalize_or_zero();
        let v = u.cross(g).normalize_or_zero();
        let shift = (u * -dx + v * dy) * d;
        self.look.eye += shift;
        self.look.target += shift;
    }

    /// Moves the eye towards the target by `factor` of the distance (orthographic: shrinks the view).
    fn zoom(&mut self, factor: f64) {
        if let Some(w) = &mut self.ortho_width {
            *w *= 1.0 - factor;
            return;
        }
        let g = self.look.target - self.look.eye;
        self.look.eye += g * factor.min(0.9);
    }

    fn apply(&self, camera: &mut CameraDesc) {
        match camera {
            CameraDesc::Perspective { look, .. } => *look = self.look,
            CameraDesc::Orthographic { look, width } => {
                *look = self.look;
                *width = self.ortho_width.unwrap_or(*width);
            }
            _ => {}
        }
    }
}

/// What a redraw depends on.
#[allow(clippy::type_complexity)]
fn snapshot(o: &Orbit, p: &RasterOptions) -> (LookAt, Option<f64>, Shading, [bool; 5], Visibility, ShadowMethod) {
    (
        o.look,
        o.ortho_width,
        p.shading,
        [p.wireframe, p.cull, p.shadows, p.ibl, p.hemispherical],
        p.visibility,
        p.shadow_method,
    )
}

fn to_pixels(image: &Image) -> Vec<u32> {
    to_srgb8(image).chunks_exact(3).map(|c| (c[0] as u32) << 16 | (c[1] as u32) << 8 | c[2] as u32).collect()
}

pub(crate) fn run(a: &ViewArgs) -> Result<(), Failure> {
    let format = check_output(&a.output, false)?;
    if let Some(s) = &a.screenshot {
        check_output(s, false)?;
    }
    let mut scene = load(&a.scene, &a.parameters, &a.environment)?;
    scene.render.width = a.width.unwrap_or(scene.render.width).clamp(16, 8192);
    scene.render.height = a.height.unwrap_or(scene.render.height).clamp(16, 8192);
    let (w, h) = (scene.render.width as usize, scene.render.height as usize);
    let mut orbit = match &scene.camera {
        CameraDesc::Perspective { look, .. } => Orbit { look: *look, ortho_width: None },
        CameraDesc::Orthographic { look, width } => Orbit { look: *look, ortho_width: Some(*width) },
        _ => return Err(Failure::input("alhazen view needs a perspective or orthographic camera")),
    };
    let mut prepared_for = RasterOptions::default();
    let bsp = RasterOptions { visibility: alhazen_raster::pipeline::Visibility::Bsp, ..RasterOptions::default() };
    crate::check_memory(alhazen_raster::pipeline::memory_estimate(&scene, &bsp), "previewing this scene")?;
    let mut prepared = match &a.radiosity {
        Some(path) => crate::radiosity::prepare_solution(path, &scene)?,
        None => prepare(&scene, &prepared_for),
    };
    let mut window = Window::new("alhazen view", w, h, WindowOptions::default())
        .map_err(|e| Failure::work(format!("cannot open a window (is an X server running?): {e}")))?;
    window.set_target_fps(60);
    let mut opts = RasterOptions::default();
    let (mut dirty, mut frame) = (true, 0u32);
    let mut last_mouse: Option<(f32, f32)> = None;
    let mut traced: Option<Vec<u32>> = None;
    let mut buffer = vec![0u32; w * h];
    while window.is_open() && !window.is_key_down(Key::Escape) && !window.is_key_down(Key::Q) {
        let before = snapshot(&orbit, &opts);
        handle_input(&window, &mut orbit, &mut opts, &mut last_mouse);
        if a.screenshot.is_some() {
            orbit.rotate(1f64.to_radians(), 0.0);
        }
        dirty |= before != snapshot(&orbit, &opts);
        if window.is_key_pressed(Key::R, KeyRepeat::No) {
            window.set_title("alhazen view — ray tracing…");
            let image = alhazen_render::render(&scene, &|_, _| {});
            save(&image, &a.output, format)?;
            traced = Some(to_pixels(&image));
            eprintln!("ray traced the view → {}", a.output.display());
        }
        if dirty {
            traced = None;
            if !prepared.serves(&opts) {
                window.set_title("alhazen view — preparing…");
                prepared_for.prepare_also(&opts);
                prepared = prepare(&scene, &prepared_for);
            }
            orbit.apply(&mut scene.camera);
            let start = Instant::now();
            let (fb, stats) = render_prepared(&scene, &prepared, &opts).map_err(|e| Failure::input(e.to_string()))?;
            buffer = to_pixels(&Image { width: fb.width, height: fb.height, pixels: fb.color });
            let ms = start.elapsed().as_secs_f64() * 1e3;
            window.set_title(&format!(
                "alhazen view — {:?}, {:?}{}{}{} — {} triangles, {:.1} ms",
                opts.visibility,
                opts.shading,
                if opts.shadows { format!(", shadows by {:?}", opts.shadow_method) } else { String::new() },
                if opts.wireframe { ", wireframe" } else { "" },
                if opts.cull { "" } else { ", no culling" },
                stats.triangles,
                ms
            ));
            dirty = false;
        }
        window
            .update_with_buffer(traced.as_ref().unwrap_or(&buffer), w, h)
            .map_err(|e| Failure::work(format!("window update failed: {e}")))?;
        frame += 1;
        if let Some(path) = &a.screenshot
            && frame >= a.frames
        {
            let shown = traced.as_ref().unwrap_or(&buffer);
            let pixels = shown
                .iter()
                .map(|p| {
                    let c = |s: u32| alhazen_math::color::srgb_to_linear(((p >> s) & 0xff) as f64 / 255.0) as f32;
                    [c(16), c(8), c(0)]
                })
                .collect();
            save(&Image { width: w as u32, height: h as u32, pixels }, path, check_output(path, false)?)?;
            break;
        }
    }
    Ok(())
}

fn handle_input(window: &Window, orbit: &mut Orbit, opts: &mut RasterOptions, last: &mut Option<(f32, f32)>) {
    let step = 3f64.to_radians();
    for (key, yaw, pitch) in
        [(Key::Left, -step, 0.0), (Key::Right, step, 0.0), (Key::Up, 0.0, step), (Key::Down, 0.0, -step)]
    {
        if window.is_key_down(key) {
            orbit.rotate(yaw, pitch);
        }
    }
    for (key, f) in [(Key::Equal, 0.05), (Key::NumPadPlus, 0.05), (Key::Minus, -0.05), (Key::NumPadMinus, -0.05)] {
        if window.is_key_down(key) {
            orbit.zoom(f);
        }
    }
    if let Some((_, dy)) = window.get_scroll_wheel() {
        orbit.zoom(dy as f64 * 0.02);
    }
    for (key, shading) in [(Key::Key1, Shading::Flat), (Key::Key2, Shading::Gouraud), (Key::Key3, Shading::Phong)] {
        if window.is_key_pressed(key, KeyRepeat::No) {
            opts.shading = shading;
        }
    }
    if window.is_key_pressed(Key::W, KeyRepeat::No) {
        opts.wireframe = !opts.wireframe;
    }
    if window.is_key_pressed(Key::C, KeyRepeat::No) {
        opts.cull = !opts.cull;
    }
    if window.is_key_pressed(Key::S, KeyRepeat::No) {
        opts.shadows = !opts.shadows;
    }
    if window.is_key_pressed(Key::I, KeyRepeat::No) {
        opts.ibl = !opts.ibl;
    }
    if window.is_key_pressed(Key::H, KeyRepeat::No) {
        opts.hemispherical = !opts.hemispherical;
    }
    if window.is_key_pressed(Key::M, KeyRepeat::No) {
        opts.shadow_method = match opts.shadow_method {
            ShadowMethod::Maps => ShadowMethod::Volumes(StencilMode::DepthPass),
            ShadowMethod::Volumes(StencilMode::DepthPass) => ShadowMethod::Volumes(StencilMode::DepthFail),
            ShadowMethod::Volumes(StencilMode::DepthFail) => ShadowMethod::Maps,
        };
    }
    if window.is_key_pressed(Key::B, KeyRepeat::No) {
        opts.visibility = match opts.visibility {
            Visibility::ZBuffer => Visibility::Bsp,
            Visibility::Bsp => Visibility::Scanline,
            Visibility::Scanline => Visibility::DepthSort,
            Visibility::DepthSort => Visibility::Warnock,
            Visibility::Warnock => Visibility::ZBuffer,
        };
    }
    let pos = window.get_mouse_pos(MouseMode::Pass);
    let (left, right) = (window.get_mouse_down(MouseButton::Left), window.get_mouse_down(MouseButton::Right));
    if let (Some((x, y)), Some((px, py))) = (pos, *last) {
        let (dx, dy) = ((x - px) as f64, (y - py) as f64);
        if left {
            orbit.rotate(-dx * 0.01, dy * 0.01);
        } else if right {
            let size = window.get_size();
            orbit.pan(dx / size.0 as f64, dy / size.1 as f64);
        }
    }
    *last = if left || right { pos } else { None };
}
