//! Cameras: turn a film position into a world ray.
//!
//! * perspective — through the course's `P⁻¹`: a point of the standard cube's near face
//!   `(x, y, −1)` is taken back to the near plane of the frustum `(l, r, b, t, n)` in view space and
//!   the view frame `(u, v, w)` carries it to the world;
//! * parallel projections — orthographic, and the axonometries of the course (isometric,
//!   cavalier, cabinet, military) as one linear map `p ↦ (a·p, b·p)` whose kernel is the ray
//!   direction;
//! * stereo — two skewed frusta sharing `b, t, n, f` (course, §"Stereoscopic vision"), left eye
//!   on the left half of a double-width film;
//! * panorama — central projection on a cylinder around the view's vertical axis (course,
//!   §"Nonlinear projections"), developed flat.

use alhazen_math::viewing::{Frustum, ViewFrame, homogenize, stereo_frusta};
use alhazen_math::{Mat3, Mat4, Ray, Vec3, Vec4};
use alhazen_scene::{Axonometry, CameraDesc, PerspectiveOpening};

/// A camera ready to generate rays for a film of `film_width × film_height` pixels.
#[derive(Clone, Debug)]
pub struct Camera {
    kind: Kind,
    /// Film width in pixels (twice the per-eye width for stereo).
    pub film_width: u32,
    /// Film height in pixels.
    pub film_height: u32,
}

#[derive(Clone, Debug)]
enum Kind {
    Perspective(Pinhole),
    Parallel { corner: Vec3, dx: Vec3, dy: Vec3, dir: Vec3 },
    Panorama { frame: ViewFrame, angle: f64 },
    Stereo { left: Pinhole, right: Pinhole },
}

/// A perspective camera as frame + `P⁻¹`.
#[derive(Clone, Debug)]
struct Pinhole {
    frame: ViewFrame,
    p_inv: Mat4,
}

impl Pinhole {
    fn new(frame: ViewFrame, frustum: Frustum) -> Self {
        Self { frame, p_inv: frustum.perspective_inverse() }
    }

    /// `(x, y)` in the standard square `[−1, 1]²`, `y` up.
    #[inline]
    fn ray(&self, x: f64, y: f64) -> Ray {
        let p = homogenize(self.p_inv * Vec4::new(x, y, -1.0, 1.0)).unwrap_or(Vec3::NEG_Z);
        Ray::new(self.frame.eye, self.frame.to_world_dir(p).normalize())
    }
}

fn frame(look: &alhazen_scene::LookAt) -> ViewFrame {
    // The scene reader has checked the frame is well defined; fall back to a fixed one anyway.
    ViewFrame::look_at(look.eye, look.target, look.up).unwrap_or(ViewFrame { eye: look.eye, u: Vec3::X, v: Vec3::Y, w: Vec3::Z })
}

impl Camera {
    /// Builds the camera for an image of `width × height` pixels (per eye).
    pub fn new(desc: &CameraDesc, width: u32, height: u32) -> Self {
        let aspect = width as f64 / height as f64;
        let (kind, film_width) = match desc {
            CameraDesc::Perspective { look, opening } => {
                let frustum = match *opening {
                    PerspectiveOpening::Fov { angle, horizontal } => {
                        let fovy = if horizontal { 2.0 * ((angle / 2.0).tan() / aspect).atan() } else { angle };
                        Frustum::symmetric(fovy, aspect, 1.0, 1000.0)
                    }
                    PerspectiveOpening::Frustum { lrbtn: [l, r, b, t, n] } => Frustum { l, r, b, t, n, f: n * 1000.0 },
                };
                (Kind::Perspective(Pinhole::new(frame(look), frustum)), width)
            }
            CameraDesc::Orthographic { look, width: w } => {
                let f = frame(look);
                (parallel(f.u, f.v, -f.w, look.eye, *w, (width, height), 0.0), width)
            }
            CameraDesc::Axonometric { style, target, width: w, azimuth } => {
                let (a, b) = axonometric_axes(*style, *azimuth);
                let dir = kernel_direction(a, b);
                (parallel(a, b, dir, *target, *w, (width, height), 1e4), width)
            }
            CameraDesc::Stereo { look, eye_distance, screen_distance, screen_width } => {
                let f = frame(look);
                let (l, r) = stereo_frusta(*eye_distance, *screen_distance, *screen_width, screen_width / aspect, 1.0, 1000.0);
                let eye = |s: f64| ViewFrame { eye: f.eye + f.u * (s * eye_distance / 2.0), ..f };
                (Kind::Stereo { left: Pinhole::new(eye(-1.0), l), right: Pinhole::new(eye(1.0), r) }, width * 2)
            }
            CameraDesc::Panorama { look, angle } => (Kind::Panorama { frame: frame(look), angle: *angle }, width),
        };
        Self { kind, film_width, film_height: height }
    }

    /// The ray through film position `(fx, fy)` in pixels, `y` down.
    #[inline]
    pub fn ray(&self, fx: f64, fy: f64) -> Ray {
        let (w, h) = (self.film_width as f64, self.film_height as f64);
        match &self.kind {
            Kind::Perspective(p) => p.ray(2.0 * fx / w - 1.0, 1.0 - 2.0 * fy / h),
            Kind::Parallel { corner, dx, dy, dir } => Ray::new(*corner + *dx * fx + *dy * fy, *dir),
            Kind::Panorama { frame, angle } => {
                let phi = (fx / w - 0.5) * angle;
                let height = (0.5 - fy / h) * angle * h / w;
                Ray::new(frame.eye, frame.to_world_dir(Vec3::new(phi.sin(), height, -phi.cos())).normalize())
            }
            Kind::Stereo { left, right } => {
                let half = w / 2.0;
                let (cam, x) = if fx < half { (left, fx) } else { (right, fx - half) };
                cam.ray(2.0 * x / half - 1.0, 1.0 - 2.0 * fy / h)
            }
        }
    }
}

/// The image axes `a, b` of an axonometry: a point `p` lands at `(a·p, b·p)`.
fn axonometric_axes(style: Axonometry, azimuth: f64) -> (Vec3, Vec3) {
    let (s, c) = azimuth.sin_cos();
    // Rotated ground axes: x' (right) and the receding direction r' (away from the viewer).
    let (x, away) = (Vec3::new(c, 0.0, -s), Vec3::new(-s, 0.0, -c));
    match style {
        Axonometry::Isometric => {
            let w = (Vec3::new(1.0, 1.0, 1.0)).normalize();
            let w = Vec3::new(c * w.x + s * w.z, w.y, -s * w.x + c * w.z);
            let u = Vec3::Y.cross(w).normalize();
            (u, w.cross(u))
        }
        Axonometry::Cavalier | Axonometry::Cabinet => {
            let k = if style == Axonometry::Cavalier { 1.0 } else { 0.5 };
            let q = std::f64::consts::FRAC_PI_4;
            // Depth along `away` is drawn up and to the right at 45°, length k.
            (x + away * (k * q.cos()), Vec3::Y + away * (k * q.sin()))
        }
        // The rotated ground plan is undistorted; verticals keep their length.
        Axonometry::Military => (x, away + Vec3::Y),
    }
}

/// The projection direction: the kernel of `p ↦ (a·p, b·p)`, pointing down or away.
fn kernel_direction(a: Vec3, b: Vec3) -> Vec3 {
    let d = a.cross(b).normalize();
    if d.y < 0.0 || (d.y == 0.0 && d.z < 0.0) { d } else { -d }
}

/// A parallel projection with image axes `a, b` (their dual basis spans the film), rays along
/// `dir`, centred on `center`, `view_width` world units across a film of `px_w × px_h`;
/// origins backed off by `back`.
fn parallel(a: Vec3, b: Vec3, dir: Vec3, center: Vec3, view_width: f64, (px_w, px_h): (u32, u32), back: f64) -> Kind {
    // Rows a, b, dir; the columns of the inverse are the dual basis: ea·a = 1, ea·b = 0, ea·dir = 0.
    let m = Mat3::from_cols(a, b, dir).transpose();
    let inv = m.inverse();
    let (ea, eb) = (inv.x_axis, inv.y_axis);
    let view_height = view_width * px_h as f64 / px_w as f64;
    let origin = center - dir * back;
    let (dx, dy) = (ea * (view_width / px_w as f64), -eb * (view_height / px_h as f64));
    Kind::Parallel { corner: origin - ea * (view_width / 2.0) + eb * (view_height / 2.0), dx, dy, dir }
}
