//! The scene model: plain data, independent of any file format and of the renderer.
//!
//! Colours are linear RGB ([`Rgb`]); angles are stored in radians (the file uses degrees).

use alhazen_geom::TriangleMesh;
use alhazen_math::{Transform, Vec2, Vec3};
use std::sync::Arc;

/// A linear RGB triple.
pub type Rgb = Vec3;

/// Index into [`Scene::materials`].
pub type MaterialId = u32;

/// A whole scene, as read from a scene file.
#[derive(Clone, Debug)]
pub struct Scene {
    /// Image size, sampling and recursion settings.
    pub render: RenderSettings,
    /// The camera.
    pub camera: CameraDesc,
    /// What rays that leave the scene see.
    pub background: Background,
    /// Ambient light `I^amb` (course, Lambert/Phong models).
    pub ambient: Rgb,
    /// Light sources.
    pub lights: Vec<Light>,
    /// Materials; objects refer to them by index. Index 0 is the default material.
    pub materials: Vec<Material>,
    /// Geometry.
    pub objects: Vec<Object>,
    /// Meshes shared between instances.
    pub meshes: Vec<Arc<TriangleMesh>>,
    /// Decoded image textures (linear RGB).
    pub images: Vec<Arc<ImageData>>,
}

/// The integrator that computes the image.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IntegratorKind {
    /// Recursive ray tracing (the lecture's `RT_trace`/`RT_shade`).
    Whitted,
    /// Unidirectional path tracing of the rendering equation (course, §"Global lighting models").
    Path,
    /// Path tracing with caustics from a photon map (the `alhazen-photon` crate; `alhazen
    /// render` builds the map). Without it, the path tracer renders what it converges to.
    Photon,
    /// The course's radiosity method (the `alhazen-radiosity` crate; `alhazen render` solves
    /// it). Without it, the path tracer renders the scene.
    Radiosity,
}

/// Where the path tracer's random numbers come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SamplerKind {
    /// Independent uniform numbers per sample.
    Independent,
    /// Sobol points, Owen-scrambled per pixel and dimension (low discrepancy).
    Sobol,
}

/// How the path tracer's light samples choose among the scene's lights (pbrt-v4's
/// `lightsampler`). Any choice gives every image the same expectation; they differ in noise.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightChoice {
    /// Every light equally often (Mitsuba 3's choice without sampling weights).
    Uniform,
    /// Lights in the scene by their power, mixed with a uniform share; lights at infinity
    /// (directional, environment, a sampled sky) each as often as all the others together,
    /// as pbrt-v4 places them beside its light tree.
    Power,
    /// Lights by the direct light a pilot pass measures each sending to the surfaces the
    /// camera sees (shadows included: a lamp behind a wall is seldom chosen), mixed with a
    /// uniform share.
    Measured,
}

/// Image size and sampling.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    /// Width in pixels (per eye for a stereo camera).
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Samples per pixel.
    pub spp: u32,
    /// Maximum depth of the ray tree.
    pub max_depth: u32,
    /// Seed of every random decision.
    pub seed: u64,
    /// The integrator.
    pub integrator: IntegratorKind,
    /// The path tracer's sampler.
    pub sampler: SamplerKind,
    /// How the path tracer's light samples choose a light.
    pub light_choice: LightChoice,
    /// Join lights to non-specular points through sphere, cylinder and plane mirrors exactly
    /// (specular connections, both ray tracers).
    pub mirror_connections: bool,
    /// How each pixel weighs the film positions of its samples.
    pub filter: PixelFilter,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            width: 640,
            height: 480,
            spp: 4,
            max_depth: 8,
            seed: 0,
            integrator: IntegratorKind::Whitted,
            sampler: SamplerKind::Sobol,
            light_choice: LightChoice::Measured,
            mirror_connections: true,
            filter: PixelFilter::PIXEL,
        }
    }
}

/// The pixel reconstruction filter: the weight a pixel gives a sample at offset `(x, y)` from
/// its centre, in pixels — separable, the product of one profile along `x` and one along `y`,
/// each zero beyond its radius (Mitchell and Netravali 1988, "Reconstruction filters in
/// computer graphics"; the filters of pbrt-v4 and Mitsuba 3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PixelFilter {
    /// Equal weight out to `radius` (0.5: the pixel's own square).
    Box {
        /// Along `x` and `y`, in pixels.
        radius: [f64; 2],
    },
    /// `1 − |x|/r`.
    Tent {
        /// `r` along `x` and `y`.
        radius: [f64; 2],
    },
    /// `exp(−x²/2σ²) − exp(−r²/2σ²)`.
    Gaussian {
        /// `σ`, in pixels.
        sigma: f64,
        /// `r` along `x` and `y`.
        radius: [f64; 2],
    },
    /// Mitchell and Netravali's cubic of parameters `B, C` over `|2x/r| ≤ 2` (`B = 0, C = ½`:
    /// Catmull–Rom); negative lobes.
    Mitchell {
        /// `B`.
        b: f64,
        /// `C`.
        c: f64,
        /// `r` along `x` and `y`.
        radius: [f64; 2],
    },
    /// The Blackman–Harris window over `[−r, r]`, `a₀ − a₁ cos θ + a₂ cos 2θ − a₃ cos 3θ` with
    /// `θ = π(x/r + 1)` (Harris 1978; Blender Cycles' default filter, `r` its "width").
    BlackmanHarris {
        /// `r` along `x` and `y`.
        radius: [f64; 2],
    },
    /// Lanczos' windowed sinc, `sinc(x) · sinc(x/τ)` with `sinc(x) = sin(πx)/(πx)`; negative lobes.
    Lanczos {
        /// `τ`, the window's width.
        tau: f64,
        /// Where the profile is cut, along `x` and `y`.
        radius: [f64; 2],
    },
}

/// The largest filter radius, in pixels: a sample then lands at most this far from its pixel.
pub const MAX_FILTER_RADIUS: f64 = 16.0;

impl PixelFilter {
    /// The box of one pixel: each sample anywhere in its own pixel, all weighed alike.
    pub const PIXEL: Self = Self::Box { radius: [0.5; 2] };

    /// The names of the filters, for [`Self::named`].
    pub const NAMES: [&str; 7] = ["box", "tent", "gaussian", "blackman-harris", "mitchell", "catmull-rom", "lanczos"];

    /// The filter of this name with its default parameters (the scene format's).
    pub fn named(name: &str) -> Option<Self> {
        Some(match name {
            "box" => Self::PIXEL,
            "tent" => Self::Tent { radius: [1.0; 2] },
            "gaussian" => Self::Gaussian { sigma: 0.5, radius: [1.5; 2] },
            "blackman-harris" => Self::BlackmanHarris { radius: [1.5; 2] },
            "mitchell" => Self::Mitchell { b: 1.0 / 3.0, c: 1.0 / 3.0, radius: [2.0; 2] },
            "catmull-rom" => Self::Mitchell { b: 0.0, c: 0.5, radius: [2.0; 2] },
            "lanczos" => Self::Lanczos { tau: 3.0, radius: [3.0; 2] },
            _ => return None,
        })
    }

    /// The radii along `x` and `y`.
    pub fn radius(&self) -> [f64; 2] {
        match *self {
            Self::Box { radius }
            | Self::Tent { radius }
            | Self::BlackmanHarris { radius }
            | Self::Gaussian { radius, .. }
            | Self::Mitchell { radius, .. }
            | Self::Lanczos { radius, .. } => radius,
        }
    }

    /// The profile along `axis` (0: `x`, 1: `y`) at offset `x` from the centre.
    pub fn profile(&self, axis: usize, x: f64) -> f64 {
        let r = self.radius()[axis];
        let x = x.abs();
        if x > r {
            return 0.0;
        }
        match *self {
            Self::Box { .. } => 1.0,
            Self::Tent { .. } => 1.0 - x / r,
            Self::Gaussian { sigma, .. } => {
                let g = |x: f64| (-x * x / (2.0 * sigma * sigma)).exp();
                (g(x) - g(r)).max(0.0)
            }
            Self::BlackmanHarris { .. } => {
                let t = std::f64::consts::PI * (x / r + 1.0);
                0.35875 - 0.48829 * t.cos() + 0.14128 * (2.0 * t).cos() - 0.01168 * (3.0 * t).cos()
            }
            Self::Mitchell { b, c, .. } => mitchell(b, c, 2.0 * x / r),
            Self::Lanczos { tau, .. } => sinc(x) * sinc(x / tau),
        }
    }

    /// Why the filter cannot be used, if it cannot: a radius outside `(0, MAX_FILTER_RADIUS]`,
    /// a parameter not finite or out of range, or a profile whose integral is not at least a
    /// hundredth of its magnitude's (its samples' weights would be huge and of both signs).
    pub fn problem(&self) -> Option<String> {
        match *self {
            Self::Gaussian { sigma, .. } if !(sigma > 0.0 && sigma <= MAX_FILTER_RADIUS) => {
                return Some(format!("a Gaussian filter's sigma must lie in (0, {MAX_FILTER_RADIUS}], found {sigma}"));
            }
            Self::Mitchell { b, c, .. } if !(b.abs() <= 100.0 && c.abs() <= 100.0) => {
                return Some(format!("a Mitchell filter's B and C must be finite numbers within ±100, found {b}, {c}"));
            }
            Self::Lanczos { tau, .. } if !(0.01..=MAX_FILTER_RADIUS).contains(&tau) => {
                return Some(format!("a Lanczos filter's tau must lie in [0.01, {MAX_FILTER_RADIUS}], found {tau}"));
            }
            _ => {}
        }
        let radius = self.radius();
        if !radius.iter().all(|r| *r > 0.0 && *r <= MAX_FILTER_RADIUS) {
            return Some(format!(
                "a pixel filter's radius must lie in (0, {MAX_FILTER_RADIUS}] pixels, found {} × {}",
                radius[0], radius[1]
            ));
        }
        for axis in 0..2 {
            // The midpoint rule over a fine grid.
            let (r, n) = (radius[axis], 4096);
            let h = 2.0 * r / n as f64;
            let values = (0..n).map(|i| self.profile(axis, -r + (i as f64 + 0.5) * h));
            let (signed, magnitude) = values.fold((0.0, 0.0), |(s, m), v| (s + v * h, m + v.abs() * h));
            if signed.is_nan() || signed < 0.01 * magnitude || magnitude <= 0.0 {
                return Some(format!(
                    "this pixel filter's weights along {} sum to {signed:.3e} against {magnitude:.3e} in magnitude: \
                     its negative lobes would cancel its positive ones (a pixel divides by the sum)",
                    ["x", "y"][axis]
                ));
            }
        }
        None
    }
}

/// Mitchell and Netravali's cubic at `x` (zero beyond `|x| = 2`).
fn mitchell(b: f64, c: f64, x: f64) -> f64 {
    let x = x.abs();
    let v = if x < 1.0 {
        (12.0 - 9.0 * b - 6.0 * c) * x * x * x + (-18.0 + 12.0 * b + 6.0 * c) * x * x + (6.0 - 2.0 * b)
    } else if x < 2.0 {
        (-b - 6.0 * c) * x * x * x + (6.0 * b + 30.0 * c) * x * x + (-12.0 * b - 48.0 * c) * x + (8.0 * b + 24.0 * c)
    } else {
        0.0
    };
    v / 6.0
}

/// `sin(πx)/(πx)`, 1 at 0.
fn sinc(x: f64) -> f64 {
    let px = std::f64::consts::PI * x;
    if px.abs() < 1e-8 { 1.0 } else { px.sin() / px }
}

/// Where the camera stands.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LookAt {
    /// Eye point.
    pub eye: Vec3,
    /// Point looked at.
    pub target: Vec3,
    /// View-up vector.
    pub up: Vec3,
}

/// How a perspective camera's opening is given.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PerspectiveOpening {
    /// Field of view in radians across the image's width (`horizontal`) or height.
    Fov {
        /// Angle in radians.
        angle: f64,
        /// True when `angle` spans the width.
        horizontal: bool,
    },
    /// The course's frustum `l, r, b, t` on the near plane at distance `n`.
    Frustum {
        /// Left, right, bottom, top, near.
        lrbtn: [f64; 5],
    },
}

/// Parallel projections of technical drawing (course, §"Projections").
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Axonometry {
    /// Orthographic along `(1, 1, 1)`: the three axes equally foreshortened.
    Isometric,
    /// Oblique: the front plane undistorted, depth at 45° and full length.
    Cavalier,
    /// Oblique: like cavalier with depth at half length.
    Cabinet,
    /// Oblique: the ground plan undistorted (rotated), verticals vertical at full length.
    Military,
}

impl Axonometry {
    /// The image axes `a`, `b` of the projection `p ↦ (a·p, b·p)` for the scene turned by
    /// `azimuth` about the vertical.
    pub fn axes(self, azimuth: f64) -> (Vec3, Vec3) {
        let (s, c) = azimuth.sin_cos();
        // Rotated ground axes: x' (right) and the receding direction r' (away from the viewer).
        let (x, away) = (Vec3::new(c, 0.0, -s), Vec3::new(-s, 0.0, -c));
        match self {
            Axonometry::Isometric => {
                let w = Vec3::new(1.0, 1.0, 1.0).normalize();
                let w = Vec3::new(c * w.x + s * w.z, w.y, -s * w.x + c * w.z);
                let u = Vec3::Y.cross(w).normalize();
                (u, w.cross(u))
            }
            Axonometry::Cavalier | Axonometry::Cabinet => {
                let k = if self == Axonometry::Cavalier { 1.0 } else { 0.5 };
                let q = std::f64::consts::FRAC_PI_4;
                // Depth along `away` is drawn up and to the right at 45°, length k.
                (x + away * (k * q.cos()), Vec3::Y + away * (k * q.sin()))
            }
            // The rotated ground plan is undistorted; verticals keep their length.
            Axonometry::Military => (x, away + Vec3::Y),
        }
    }

    /// The projection direction: the kernel of `p ↦ (a·p, b·p)`, pointing down or away.
    pub fn direction(a: Vec3, b: Vec3) -> Vec3 {
        let d = a.cross(b).normalize();
        if d.y < 0.0 || (d.y == 0.0 && d.z < 0.0) { d } else { -d }
    }
}

/// A camera description.
#[derive(Clone, Debug, PartialEq)]
pub enum CameraDesc {
    /// Perspective: a pinhole, or a thin lens with depth of field.
    Perspective {
        /// Placement.
        look: LookAt,
        /// Field of view or frustum.
        opening: PerspectiveOpening,
        /// A thin lens (`None`: a pinhole, everything sharp).
        lens: Option<ThinLens>,
    },
    /// Orthographic, `width` world units across the image.
    Orthographic {
        /// Placement.
        look: LookAt,
        /// Visible width in world units.
        width: f64,
    },
    /// An axonometric (parallel, possibly oblique) view centred on `target`.
    Axonometric {
        /// The axonometry.
        style: Axonometry,
        /// The point at the image centre.
        target: Vec3,
        /// Visible width in world units.
        width: f64,
        /// Rotation of the scene about the vertical axis before projecting, radians.
        azimuth: f64,
    },
    /// Two perspective views side by side (left eye on the left).
    Stereo {
        /// Placement of the point between the eyes.
        look: LookAt,
        /// Distance between the eyes.
        eye_distance: f64,
        /// Distance from the eyes to the screen.
        screen_distance: f64,
        /// Screen width (the height follows from the image aspect).
        screen_width: f64,
    },
    /// Central projection on a cylinder around the vertical axis of the view, developed flat.
    Panorama {
        /// Placement.
        look: LookAt,
        /// Horizontal angle covered, radians (up to 2π).
        angle: f64,
    },
}

impl CameraDesc {
    /// A stereo camera's two eyes as perspective cameras (left, right) for images of aspect
    /// `aspect` (per eye): each eye `∓eye_distance/2` along the view's horizontal axis, looking
    /// parallel, with the skewed frusta of the course's §"Stereoscopic vision" (near plane at 1)
    /// that show both the same screen rectangle. `None` for other cameras.
    pub fn stereo_eyes(&self, aspect: f64) -> Option<[CameraDesc; 2]> {
        let CameraDesc::Stereo { look, eye_distance, screen_distance, screen_width } = *self else { return None };
        let u = alhazen_math::viewing::ViewFrame::look_at(look.eye, look.target, look.up).map_or(Vec3::X, |f| f.u);
        let (l, r) = alhazen_math::viewing::stereo_frusta(
            eye_distance,
            screen_distance,
            screen_width,
            screen_width / aspect,
            1.0,
            1000.0,
        );
        let eye = |side: f64, f: alhazen_math::viewing::Frustum| {
            let shift = u * (side * eye_distance / 2.0);
            CameraDesc::Perspective {
                look: LookAt { eye: look.eye + shift, target: look.target + shift, up: look.up },
                opening: PerspectiveOpening::Frustum { lrbtn: [f.l, f.r, f.b, f.t, f.n] },
                lens: None,
            }
        };
        Some([eye(-1.0, l), eye(1.0, r)])
    }
}

/// A thin lens (pbrt's and Mitsuba's `thinlens`): rays start on a disk of radius `aperture`
/// about the eye, across the view axis, and meet where the pinhole's ray through the same film
/// point meets the plane `focus_distance` ahead of the eye; what lies off that plane blurs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThinLens {
    /// The lens's radius, in world units (> 0).
    pub aperture: f64,
    /// The distance along the view axis to the plane in focus (> 0).
    pub focus_distance: f64,
}

/// What a ray that hits nothing sees.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Background {
    /// A constant colour.
    Solid(Rgb),
    /// Blend from `horizon` (direction y = 0) to `zenith` (y = 1); `ground` below the horizon.
    Gradient {
        /// Colour straight up.
        zenith: Rgb,
        /// Colour at the horizon.
        horizon: Rgb,
        /// Colour below the horizon.
        ground: Rgb,
    },
}

impl Material {
    /// What the base colour is multiplied by at a point whose (interpolated) vertex colour is
    /// `color`: `color` with [`Self::vertex_colors`], else white.
    #[inline]
    pub fn vertex_tint(&self, color: Rgb) -> Rgb {
        if self.vertex_colors { color } else { Vec3::ONE }
    }

    /// The course's highlight factor for light from `l` seen from `v` at normal `n` (all unit,
    /// `n` on the viewer's side): Phong `max(0, ⟨r, v⟩)^m`, or Blinn–Phong `⟨ĥ, n⟩^{2m}` with the
    /// course's anisotropic `ĥ ∝ P₀w + P₁w + a·P₂w`, `w = l + v` (projections on `n`, on the
    /// scratch direction and across it; `a = 1` is plain Blinn–Phong).
    pub fn highlight(&self, n: Vec3, l: Vec3, v: Vec3) -> f64 {
        match self.highlight {
            Highlight::Phong => (2.0 * l.dot(n) * n - l).dot(v).max(0.0).powf(self.shininess),
            Highlight::BlinnPhong => {
                let w = l + v;
                let h = if self.anisotropy < 1.0 {
                    let r = (self.scratches - n * n.dot(self.scratches)).normalize_or_zero();
                    let b = n.cross(r);
                    n * w.dot(n) + r * w.dot(r) + b * (self.anisotropy * w.dot(b))
                } else {
                    w
                };
                h.normalize_or_zero().dot(n).max(0.0).powf(2.0 * self.shininess)
            }
        }
    }
}

impl Background {
    /// What a ray leaving the scene in direction `dir` sees.
    pub fn radiance(&self, dir: Vec3) -> Rgb {
        match *self {
            Background::Solid(c) => c,
            Background::Gradient { zenith, horizon, ground } => {
                if dir.y >= 0.0 {
                    horizon.lerp(zenith, dir.y.min(1.0))
                } else {
                    ground
                }
            }
        }
    }
}

/// A light source with the course's distance attenuation `1/(a d² + b d + c)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// Emits equally in all directions from a point.
    Point {
        /// Position.
        position: Vec3,
        /// Emitted intensity `I^em`.
        intensity: Rgb,
        /// `[a, b, c]`.
        attenuation: [f64; 3],
    },
    /// Parallel light from infinitely far away.
    Directional {
        /// Direction the light travels (unit).
        direction: Vec3,
        /// Intensity `I^dir`.
        intensity: Rgb,
    },
    /// A point light restricted to a cone, with falloff `cos^e` inside it ([`spot_profile`]).
    Spot {
        /// Position.
        position: Vec3,
        /// Axis direction (unit).
        direction: Vec3,
        /// Cosine of the half-angle of the cone.
        cos_cutoff: f64,
        /// Exponent of the cosine falloff.
        falloff: f64,
        /// A beam of full intensity, from whose edge the light fades to nothing at the cone's;
        /// `None`: no fade.
        beam: Option<SpotBeam>,
        /// Emitted intensity.
        intensity: Rgb,
        /// `[a, b, c]`.
        attenuation: [f64; 3],
    },
    /// Light from infinitely far away in every direction, given by an equirectangular image.
    Environment {
        /// Index into [`Scene::images`] (linear radiance).
        image: usize,
        /// Multiplier of the image's values.
        scale: f64,
        /// Rotation of the map about its up axis, radians.
        rotation: f64,
        /// The map's up axis (unit): `+y` for a map upright in the scene, `+z` for one upright
        /// in a z-up world (Blender's).
        up: Vec3,
    },
}

impl Light {
    /// The course's local-model view of the light at `p`: the unit direction towards it, its
    /// distance (infinite for directional light) and the intensity `I^dir = I^em/(a d² + b d + c)`
    /// arriving there (times `cos^e` inside a spot's cone); `None` outside a spot's cone, at the
    /// light itself, and for the environment (which rays see when they leave the scene).
    pub fn arriving(&self, p: Vec3) -> Option<(Vec3, f64, Rgb)> {
        let falloff = |abc: &[f64; 3], d: f64| abc[0] * d * d + abc[1] * d + abc[2];
        match self {
            Light::Point { position, intensity, attenuation } => {
                let to = *position - p;
                let d = to.length();
                (d > 0.0).then(|| (to / d, d, *intensity / falloff(attenuation, d)))
            }
            Light::Directional { direction, intensity } => Some((-*direction, f64::INFINITY, *intensity)),
            Light::Spot { position, direction, cos_cutoff, falloff: e, beam, intensity, attenuation } => {
                let to = *position - p;
                let d = to.length();
                let l = to / d;
                let cos = -l.dot(*direction);
                let shaped = spot_profile(cos, *cos_cutoff, *e, *beam);
                (d > 0.0 && cos >= *cos_cutoff).then(|| (l, d, *intensity * shaped / falloff(attenuation, d)))
            }
            Light::Environment { .. } => None,
        }
    }
}

/// The share of a spot light's axial intensity it sends at cosine `cos` from its axis: 0
/// outside its cone (`cos < cos_cutoff`), `cos^falloff` inside, fading where it has a beam
/// (`beam`) linearly in angle from 1 at the beam's edge to 0 at the cone's.
#[inline]
pub fn spot_profile(cos: f64, cos_cutoff: f64, falloff: f64, beam: Option<SpotBeam>) -> f64 {
    let inside = cos >= cos_cutoff;
    if !inside {
        return 0.0;
    }
    // pow(x, 1) is x: the cosine spots that stand for emitters skip libm.
    let shaped = if falloff == 1.0 { cos } else { cos.powf(falloff) };
    match beam {
        Some(SpotBeam { cos: inner, fade }) if cos < inner => shaped * fade.at(cos, cos_cutoff, inner.min(1.0)),
        _ => shaped,
    }
}

/// A spot's beam of full intensity: the cosine of its half-angle and how the light fades from
/// its edge to the cone's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpotBeam {
    /// Cosine of the beam's half-angle.
    pub cos: f64,
    /// The fade between the beam's edge and the cone's.
    pub fade: SpotFade,
}

/// How a spot fades between its beam and its cone: each renderer's own.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum SpotFade {
    /// Linear in angle (Mitsuba's spot; alhazen's TOML).
    #[default]
    LinearAngle,
    /// Smooth in the cosine, `t²(3 − 2t)` with `t` linear in the cosine (pbrt-v4's spotlight).
    SmoothCosine,
    /// The square of a fade linear in the cosine (glTF's `KHR_lights_punctual`).
    SquaredCosine,
}

impl SpotFade {
    /// The share of the light at cosine `cos` between the cone's `cos_cutoff` and the beam's
    /// `cos_beam`.
    pub fn at(self, cos: f64, cos_cutoff: f64, cos_beam: f64) -> f64 {
        let linear = |x: f64, edge: f64, inner: f64| ((x - edge) / (inner - edge)).clamp(0.0, 1.0);
        match self {
            SpotFade::LinearAngle => linear(cos.clamp(-1.0, 1.0).acos(), cos_cutoff.acos(), cos_beam.acos()),
            SpotFade::SmoothCosine => {
                let t = linear(cos, cos_cutoff, cos_beam);
                t * t * (3.0 - 2.0 * t)
            }
            SpotFade::SquaredCosine => linear(cos, cos_cutoff, cos_beam).powi(2),
        }
    }
}

/// An environment map given apart from the scene file (`alhazen render --environment`), as a
/// [`Light::Environment`] gives one: it lights the scene in place of the file's own.
#[derive(Clone, Debug)]
pub struct OutsideEnvironment {
    /// The equirectangular map (linear radiance).
    pub image: Arc<ImageData>,
    /// Multiplier of the map's values.
    pub scale: f64,
    /// Rotation of the map about its up axis, radians.
    pub rotation: f64,
    /// The map's up axis (unit).
    pub up: Vec3,
}

impl Scene {
    /// Lights the scene by `env` instead of its own environment map (its image is kept: it
    /// was read already); rays that leave the scene then see `env`, not the background.
    pub fn light_by(&mut self, env: &OutsideEnvironment) {
        self.lights.retain(|l| !matches!(l, Light::Environment { .. }));
        self.images.push(env.image.clone());
        let image = self.images.len() - 1;
        self.lights.push(Light::Environment { image, scale: env.scale, rotation: env.rotation, up: env.up });
    }

    /// What a ray leaving the scene in direction `dir` sees: the environment map if the scene
    /// has one (interpolated bilinearly), else the background.
    pub fn sky(&self, dir: Vec3) -> Rgb {
        for l in &self.lights {
            if let Light::Environment { image, scale, rotation, up } = *l {
                let dir = crate::texture::into_map(crate::texture::up_frame(up), dir);
                return crate::texture::equirect_radiance(&self.images[image], dir, rotation) * scale;
            }
        }
        self.background.radiance(dir)
    }
}

impl PerspectiveOpening {
    /// The frustum for an image of aspect `width/height` with its near plane at `near` (the
    /// file's own `near` for an explicit frustum when `None`, else 1), far at 1000 × near. A
    /// horizontal field of view is converted to the vertical one of the course's `P`.
    pub fn frustum(&self, aspect: f64, near: Option<f64>) -> alhazen_math::viewing::Frustum {
        use alhazen_math::viewing::Frustum;
        match *self {
            PerspectiveOpening::Fov { angle, horizontal } => {
                let fovy = if horizontal { 2.0 * ((angle / 2.0).tan() / aspect).atan() } else { angle };
                let n = near.unwrap_or(1.0);
                Frustum::symmetric(fovy, aspect, n, 1000.0 * n)
            }
            PerspectiveOpening::Frustum { lrbtn: [l, r, b, t, n0] } => {
                let n = near.unwrap_or(n0);
                let k = n / n0;
                Frustum { l: l * k, r: r * k, b: b * k, t: t * k, n, f: 1000.0 * n }
            }
        }
    }
}

/// A colour that may vary over a surface.
#[derive(Clone, Debug, PartialEq)]
pub enum Texture {
    /// One colour.
    Solid(Rgb),
    /// Alternating squares of `size` in texture space.
    Checker {
        /// Colour of squares with even `⌊u/size⌋+⌊v/size⌋`.
        even: Rgb,
        /// The other colour.
        odd: Rgb,
        /// Edge of a square in texture units.
        size: f64,
    },
    /// An image (index into [`Scene::images`]) repeated with `scale` images per texture unit.
    Image {
        /// Which image.
        image: usize,
        /// Repeats per texture unit in u and v.
        scale: Vec2,
        /// Shift of the image in its own units (a fraction of it per unit), after `scale` and
        /// `rotation`: the image is read at `R(rotation) · (uv · scale) + offset`.
        offset: Vec2,
        /// Turn of the scaled coordinates in degrees, counter-clockwise (u right, v up) about
        /// the origin, before `offset`.
        rotation: f64,
    },
}

/// Which specular highlight formula.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Highlight {
    /// `max(0, ⟨r, v⟩)^m`.
    Phong,
    /// `⟨h, n⟩^{2m}` (course: exponent `2m` so highlights match Phong's size).
    BlinnPhong,
}

/// How reflectance at a dielectric boundary depends on the angle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FresnelMode {
    /// The course's exact unpolarised formula.
    Exact,
    /// Schlick's approximation.
    Schlick,
    /// No Fresnel: `mirror` and `transparency` are used as given.
    Off,
}

/// A Whitted material: the course's local model plus mirror and transparency coefficients.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// Name in the scene file.
    pub name: String,
    /// Surface colour `a` (before `diffuse`).
    pub color: Texture,
    /// Diffuse weight multiplied into `a`.
    pub diffuse: f64,
    /// Specular colour `s`.
    pub specular: Rgb,
    /// Exponent `m`.
    pub shininess: f64,
    /// Highlight formula.
    pub highlight: Highlight,
    /// The course's anisotropy `a ∈ (0, 1]` of the Blinn–Phong highlight (1: isotropic).
    pub anisotropy: f64,
    /// Direction of the scratches for an anisotropic highlight (projected on the tangent plane).
    pub scratches: Vec3,
    /// Mirror reflectance.
    pub mirror: Rgb,
    /// Transmission coefficient.
    pub transparency: Rgb,
    /// Index of refraction of the inside relative to the outside.
    pub ior: f64,
    /// Beer absorption coefficient per unit length inside (linear RGB).
    pub absorption: Rgb,
    /// Fresnel treatment of transparent surfaces.
    pub fresnel: FresnelMode,
    /// Radiance emitted from the front side: a non-zero value makes the object an area light.
    /// With an [`Self::emission_texture`], its mean over the texture (what the preview, the
    /// radiosity solver and the choice of photons' lights use).
    pub emission: Rgb,
    /// Radiance emitted point by point, where it varies (an image or a checker, already scaled
    /// by its strength); `None`: `emission` everywhere. The path and Whitted tracers read it per
    /// point on meshes; other shapes shine `emission`.
    pub emission_texture: Option<Texture>,
    /// The scattering function for the path tracer; `None` derives one from the Whitted
    /// coefficients (see [`crate::bsdf`]).
    pub bsdf: Option<crate::bsdf::BsdfDesc>,
    /// Bump mapping: small displacements along the normal, seen through the perturbed normal.
    pub bump: Option<Bump>,
    /// The path tracer shades the front side only (that of the shading normal): seen from
    /// behind, an opaque surface is black and ends paths, as Mitsuba's BSDFs not wrapped in
    /// `twosided` are. `false` (the default): both sides alike, the course's reading.
    pub one_sided: bool,
    /// The base colour (`color`, a BSDF's albedo or diffuse colour, a conductor's tint, a
    /// metallic-roughness base) is multiplied by the mesh's vertex colours where it has them
    /// (glTF's `COLOR_0`, Mitsuba's `mesh_attribute` `vertex_color`), white elsewhere.
    pub vertex_colors: bool,
    /// A cut-out: where the surface is not (leaves and lace drawn on a card). `None`: opaque
    /// everywhere.
    pub alpha: Option<Alpha>,
}

/// Where a surface is, point by point (glTF's `alphaMode`, pbrt's shape `alpha`, Mitsuba's
/// `mask`): rays pass through it where it is not, in every tracer, shadow rays too. Taken by
/// the ray tests of meshes (the renderers test every hit of a mesh with a cut-out material
/// before taking it); other shapes are opaque.
#[derive(Clone, Debug, PartialEq)]
pub struct Alpha {
    /// The fraction of the surface present, in `[0, 1]`: the texture's first (red) channel.
    pub coverage: Texture,
    /// `Some(c)`: present where the coverage is at least `c`, absent elsewhere (glTF's
    /// `MASK`). `None`: a coverage `a` between 0 and 1 lets a fraction `1 − a` of the rays
    /// through, each ray's passage decided by a hash of the ray (pbrt's stochastic alpha).
    pub cutoff: Option<f64>,
}

/// A displacement `d(q(u, v))` of a surface along its normal (course, §"Shading methods":
/// bump mapping), applied to the normal only.
#[derive(Clone, Debug, PartialEq)]
pub struct Bump {
    /// Displacement at the top of the pattern (world units).
    pub height: f64,
    /// The pattern, values in `[0, 1]`.
    pub pattern: BumpPattern,
}

/// Where the displacement comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum BumpPattern {
    /// `½ + ½ sin(2πu/size) sin(2πv/size)`: an egg-crate of period `size` in texture units.
    Waves {
        /// Period.
        size: f64,
    },
    /// The luminance of an image (bilinear), repeated `scale` times per texture unit.
    Image {
        /// Index into [`Scene::images`].
        image: usize,
        /// Repeats per texture unit.
        scale: Vec2,
    },
    /// A tangent-space normal map (glTF, Mitsuba `normalmap`, pbrt `normalmap`): each texel's
    /// linear RGB `c` is the normal `2c − 1` in the frame of `∂p/∂u`, the bitangent and `n`;
    /// the bump's `height` scales its tangential part (glTF's `normalTexture.scale`). The frame
    /// is the surface's own: a turned map's texels are read turned, its vectors are not (as
    /// Blender's Normal Map node, which takes the UV map's tangent, reads them).
    NormalMap {
        /// The map: an image texture ([`Texture::Image`], linear values, not sRGB) with its
        /// placement (scale, turn, shift).
        map: Texture,
    },
}

impl Default for Material {
    fn default() -> Self {
        Self {
            name: "default".into(),
            color: Texture::Solid(Vec3::splat(0.8)),
            diffuse: 1.0,
            specular: Vec3::ZERO,
            shininess: 32.0,
            highlight: Highlight::Phong,
            anisotropy: 1.0,
            scratches: Vec3::X,
            mirror: Vec3::ZERO,
            transparency: Vec3::ZERO,
            ior: 1.5,
            absorption: Vec3::ZERO,
            fresnel: FresnelMode::Exact,
            emission: Vec3::ZERO,
            emission_texture: None,
            bsdf: None,
            bump: None,
            one_sided: false,
            vertex_colors: false,
            alpha: None,
        }
    }
}

/// A boolean operation of constructive solid geometry.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CsgOp {
    /// A ∪ B.
    Union,
    /// A ∩ B.
    Intersection,
    /// A − B.
    Difference,
}

/// A primitive or compound shape, in its own (object) coordinates.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// A ball's surface.
    Sphere {
        /// Centre.
        center: Vec3,
        /// Radius.
        radius: f64,
    },
    /// A finite circular cylinder from `base` to `top`.
    Cylinder {
        /// Centre of the bottom.
        base: Vec3,
        /// Centre of the top.
        top: Vec3,
        /// Radius.
        radius: f64,
        /// Closed by two disks.
        capped: bool,
    },
    /// A finite circular cone from a base disk to an apex.
    Cone {
        /// Centre of the base.
        base: Vec3,
        /// Apex.
        apex: Vec3,
        /// Base radius.
        radius: f64,
        /// Closed by the base disk.
        capped: bool,
    },
    /// A flat disk.
    Disk {
        /// Centre.
        center: Vec3,
        /// Normal (unit).
        normal: Vec3,
        /// Radius.
        radius: f64,
    },
    /// An infinite plane.
    Plane {
        /// A point on it.
        point: Vec3,
        /// Normal (unit).
        normal: Vec3,
    },
    /// An axis-aligned box (before the object's transform).
    Box {
        /// Lower corner.
        min: Vec3,
        /// Upper corner.
        max: Vec3,
    },
    /// A triangle mesh, index into [`Scene::meshes`].
    Mesh {
        /// Which mesh.
        mesh: usize,
        /// Interpolate vertex normals.
        smooth: bool,
    },
    /// Constructive solid geometry of two closed shapes.
    Csg {
        /// The operation.
        op: CsgOp,
        /// Left operand.
        a: Box<Object>,
        /// Right operand.
        b: Box<Object>,
    },
}

impl Shape {
    /// True when the shape bounds a volume, as CSG needs.
    pub fn is_closed(&self, meshes: &[std::sync::Arc<alhazen_geom::TriangleMesh>]) -> bool {
        match self {
            Shape::Mesh { mesh, .. } => meshes.get(*mesh).is_some_and(|m| m.is_closed()),
            Shape::Sphere { .. } | Shape::Box { .. } | Shape::Csg { .. } => true,
            Shape::Cylinder { capped, .. } | Shape::Cone { capped, .. } => *capped,
            Shape::Disk { .. } | Shape::Plane { .. } => false,
        }
    }
}

/// A shape placed in the world with a material.
#[derive(Clone, Debug, PartialEq)]
pub struct Object {
    /// Optional name (for messages).
    pub name: Option<String>,
    /// Geometry in object space.
    pub shape: Shape,
    /// Object → world.
    pub transform: Transform,
    /// Material; for meshes with per-triangle materials see [`Object::mesh_materials`].
    pub material: MaterialId,
    /// Per-slot materials of a mesh from its MTL file (empty when `material` applies to all).
    pub mesh_materials: Vec<MaterialId>,
}

impl Object {
    /// The object's materials: its own and its mesh's slots'.
    pub fn materials(&self) -> impl Iterator<Item = MaterialId> + '_ {
        std::iter::once(self.material).chain(self.mesh_materials.iter().copied())
    }
}

impl Scene {
    /// A warning per object that is not a mesh but has a material with a cut-out: renderers
    /// cut holes in meshes only ([`Alpha`]), so it is drawn opaque.
    pub fn opaque_cut_outs(&self) -> Vec<String> {
        let cut = |m: MaterialId| self.materials.get(m as usize).is_some_and(|m| m.alpha.is_some());
        let name = |i: usize, o: &Object| o.name.clone().unwrap_or_else(|| format!("object {}", i + 1));
        self.objects
            .iter()
            .enumerate()
            .filter(|(_, o)| !matches!(o.shape, Shape::Mesh { .. }) && o.materials().any(cut))
            .map(|(i, o)| format!("{}: a cut-out (alpha) applies to meshes only; this shape is opaque", name(i, o)))
            .collect()
    }
}

/// A decoded image in linear RGB, rows top to bottom. Made by [`ImageData::new`] (or
/// [`ImageData::from_codes`]), which keeps the pixels as one-byte codes when each channel takes
/// at most 256 values (every 8-bit image does), as `f32`s otherwise; the pixels are read-only.
/// Two images are equal when their sizes and pixels are (however they are kept).
#[derive(Clone)]
pub struct ImageData {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    texels: Texels,
    /// How a texture reads it beyond `[0, 1]` along `u` and along `v`.
    pub wrap: [Wrap; 2],
}

/// How an image texture is read beyond `[0, 1]` along one axis (glTF's and OpenGL's wrap
/// modes, Mitsuba's `wrap_mode`, pbrt's `wrap`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Wrap {
    /// The image repeats.
    #[default]
    Repeat,
    /// The edge texels stretch outwards.
    Clamp,
    /// The image repeats mirrored, every other copy turned over.
    Mirror,
    /// Black beyond the image.
    Black,
}

impl Wrap {
    /// The names the scene format gives the modes.
    pub const NAMES: [&str; 4] = ["repeat", "clamp", "mirror", "black"];

    /// The mode of one of [`Self::NAMES`].
    pub fn named(name: &str) -> Option<Self> {
        Some(match name {
            "repeat" => Self::Repeat,
            "clamp" => Self::Clamp,
            "mirror" => Self::Mirror,
            "black" => Self::Black,
            _ => return None,
        })
    }

    /// Its name in the scene format.
    pub fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }
}

/// How an image keeps its pixels: a texture's cost in a render is its cache footprint, and an
/// image's cost in loading the memory it fills, so an image that codes keeps only its codes
/// (3 bytes a pixel instead of 12: a 2048² texture 12 MB instead of 48).
#[derive(Clone)]
enum Texels {
    Floats(Vec<[f32; 3]>),
    Codes(PixelCodes),
}

/// An image's pixels as one byte per channel into a table of at most 256 values per channel:
/// what every 8-bit image decodes to, and what scaling its channels keeps.
#[derive(Clone)]
struct PixelCodes {
    tables: Box<[[f32; 256]; 3]>,
    codes: Vec<[u8; 3]>,
}

impl PartialEq for ImageData {
    fn eq(&self, other: &Self) -> bool {
        (self.width, self.height, self.wrap) == (other.width, other.height, other.wrap)
            && self.texels().eq(other.texels())
    }
}

impl std::fmt::Debug for ImageData {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ImageData")
            .field("width", &self.width)
            .field("height", &self.height)
            .field("pixels", &self.texels().collect::<Vec<_>>())
            .field("has_codes", &self.has_codes())
            .field("wrap", &self.wrap)
            .finish()
    }
}

impl ImageData {
    /// The image of `pixels` (`width × height`, rows top to bottom).
    pub fn new(width: u32, height: u32, pixels: Vec<[f32; 3]>) -> Self {
        let texels = PixelCodes::of(&pixels).map_or(Texels::Floats(pixels), Texels::Codes);
        Self { width, height, texels, wrap: [Wrap::Repeat; 2] }
    }

    /// The image read with `wrap` beyond `[0, 1]`.
    pub fn with_wrap(mut self, wrap: [Wrap; 2]) -> Self {
        self.wrap = wrap;
        self
    }

    /// The image whose pixel channels are `table[code]`: an 8-bit image and its decoding.
    pub fn from_codes(width: u32, height: u32, table: [f32; 256], codes: Vec<[u8; 3]>) -> Self {
        let texels = Texels::Codes(PixelCodes { tables: Box::new([table; 3]), codes });
        Self { width, height, texels, wrap: [Wrap::Repeat; 2] }
    }

    /// The number of pixels.
    pub fn texel_count(&self) -> usize {
        match &self.texels {
            Texels::Floats(p) => p.len(),
            Texels::Codes(c) => c.codes.len(),
        }
    }

    /// The `width × height` linear RGB values, row by row.
    pub fn texels(&self) -> impl Iterator<Item = [f32; 3]> + '_ {
        (0..self.texel_count()).map(|i| self.texel(i))
    }

    /// The image upside down (its rows in reverse order), its codes kept: no pixel is looked
    /// at again, where [`Self::new`] on the reversed pixels would find their codes anew.
    pub fn rows_reversed(self) -> Self {
        let w = (self.width as usize).max(1);
        let texels = match self.texels {
            Texels::Floats(p) => Texels::Floats(rows_reversed(&p, w)),
            Texels::Codes(c) => Texels::Codes(PixelCodes { codes: rows_reversed(&c.codes, w), tables: c.tables }),
        };
        Self { width: self.width, height: self.height, texels, wrap: self.wrap }
    }

    /// The image with each pixel's channels multiplied by `factor`'s (`p[c] · factor[c]` in
    /// `f32`): an image that codes keeps its codes and scales its tables.
    pub fn channels_scaled(&self, factor: [f32; 3]) -> Self {
        self.channels_mapped(|c, v| v * factor[c])
    }

    /// The image with each pixel's channel `c` of value `v` replaced by `f(c, v)`: an image
    /// that codes keeps its codes and maps its tables.
    pub fn channels_mapped(&self, f: impl Fn(usize, f32) -> f32) -> Self {
        let (width, height) = (self.width, self.height);
        match &self.texels {
            Texels::Floats(p) => {
                Self::new(width, height, p.iter().map(|p| std::array::from_fn(|c| f(c, p[c]))).collect())
            }
            Texels::Codes(c) => {
                let tables = Box::new(std::array::from_fn(|k| c.tables[k].map(|v| f(k, v))));
                let texels = Texels::Codes(PixelCodes { tables, codes: c.codes.clone() });
                Self { width, height, texels, wrap: self.wrap }
            }
        }
    }

    /// True when lookups read the pixels as one-byte codes (at most 256 distinct values a
    /// channel).
    pub fn has_codes(&self) -> bool {
        matches!(self.texels, Texels::Codes(_))
    }

    /// Pixels `at` (row by row), as [`Self::texel`] reads each: a bilinear lookup's four,
    /// the kind of storage matched once.
    #[inline]
    pub fn texels_at<const N: usize>(&self, at: [usize; N]) -> [[f32; 3]; N] {
        match &self.texels {
            Texels::Codes(c) => at.map(|i| {
                let k = c.codes[i];
                [c.tables[0][k[0] as usize], c.tables[1][k[1] as usize], c.tables[2][k[2] as usize]]
            }),
            Texels::Floats(p) => at.map(|i| p[i]),
        }
    }

    /// Pixel `i` (row by row), as texture lookups read it.
    #[inline]
    pub fn texel(&self, i: usize) -> [f32; 3] {
        self.texels_at([i])[0]
    }
}

/// The rows of `width` items of `items` in reverse order.
fn rows_reversed<T: Copy>(items: &[T], width: usize) -> Vec<T> {
    items.chunks_exact(width).rev().flatten().copied().collect()
}

impl PixelCodes {
    /// The codes of `pixels` when each channel takes at most 256 distinct values (found by a
    /// small open-addressed table of the values' bits per channel; an image of more gives up
    /// early).
    fn of(pixels: &[[f32; 3]]) -> Option<Self> {
        const SLOTS: usize = 1024;
        let mut slots = [[(0u32, u16::MAX); SLOTS]; 3];
        let mut tables = Box::new([[0.0f32; 256]; 3]);
        let mut used = [0usize; 3];
        let mut code = |c: usize, v: f32| -> Option<u8> {
            let bits = v.to_bits();
            let mut at = (bits.wrapping_mul(0x9E37_79B1) >> 22) as usize;
            loop {
                let (b, k) = slots[c][at];
                if k == u16::MAX {
                    if used[c] == 256 {
                        return None;
                    }
                    slots[c][at] = (bits, used[c] as u16);
                    tables[c][used[c]] = v;
                    used[c] += 1;
                    return Some((used[c] - 1) as u8);
                }
                if b == bits {
                    return Some(k as u8);
                }
                at = (at + 1) % SLOTS;
            }
        };
        let codes = pixels
            .iter()
            .map(|p| Some([code(0, p[0])?, code(1, p[1])?, code(2, p[2])?]))
            .collect::<Option<Vec<_>>>()?;
        Some(Self { tables, codes })
    }
}

#[cfg(test)]
mod tests {
    use super::{SpotBeam, SpotFade, spot_profile};

    /// Mitsuba's spot: full intensity within the beam, a fade linear in angle to nothing at
    /// the cone's edge; without a beam, `cos^e` inside the cone.
    #[test]
    fn spot_profiles_fade_linearly_in_angle_from_the_beam_to_the_cone() {
        let (cone, beam) = (30f64.to_radians(), 20f64.to_radians());
        let linear = SpotBeam { cos: beam.cos(), fade: SpotFade::LinearAngle };
        let at = |deg: f64| spot_profile(deg.to_radians().cos(), cone.cos(), 0.0, Some(linear));
        assert_eq!((at(0.0), at(19.9), at(30.1)), (1.0, 1.0, 0.0));
        for (deg, want) in [(22.5, 0.75), (25.0, 0.5), (29.0, 0.1)] {
            assert!((at(deg) - want).abs() < 1e-9, "{deg}°: {}", at(deg));
        }
        let c = 10f64.to_radians().cos();
        assert_eq!(spot_profile(c, cone.cos(), 1.0, None), c);
        assert_eq!(spot_profile(c, cone.cos(), 3.0, None), c.powf(3.0));
        assert_eq!(spot_profile(f64::NAN, cone.cos(), 1.0, None), 0.0);
    }

    /// pbrt's fade is smooth in the cosine, glTF's the square of a fade linear in it: both 1
    /// at the beam's edge, 0 at the cone's, in between by their formulas.
    #[test]
    fn spot_fades_are_each_renderers_own() {
        let (cone, beam) = (30f64.to_radians().cos(), 20f64.to_radians().cos());
        let mid = 0.5 * (cone + beam);
        for fade in [SpotFade::SmoothCosine, SpotFade::SquaredCosine, SpotFade::LinearAngle] {
            let at = |cos: f64| spot_profile(cos, cone, 0.0, Some(SpotBeam { cos: beam, fade }));
            assert_eq!((at(beam), at(1.0), at(cone - 1e-9)), (1.0, 1.0, 0.0), "{fade:?}");
        }
        let at = |cos: f64, fade| spot_profile(cos, cone, 0.0, Some(SpotBeam { cos: beam, fade }));
        assert!((at(mid, SpotFade::SmoothCosine) - 0.5).abs() < 1e-12);
        assert!((at(mid, SpotFade::SquaredCosine) - 0.25).abs() < 1e-12);
        let quarter = cone + 0.25 * (beam - cone);
        assert!((at(quarter, SpotFade::SmoothCosine) - 0.15625).abs() < 1e-12);
        assert!((at(quarter, SpotFade::SquaredCosine) - 0.0625).abs() < 1e-12);
    }
}
