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

use alhazen_math::viewing::{Frustum, ViewFrame, stereo_frusta};
use alhazen_math::{Mat3, Ray, Vec2, Vec3, Vec4};
use alhazen_scene::CameraDesc;

/// A camera ready to generate rays for a film of `film_width × film_height` pixels.
#[derive(Clone, Debug)]
pub struct Camera {
    kind: Kind,
    /// A perspective camera's thin lens.
    lens: Option<Lens>,
    /// Film width in pixels (twice the per-eye width for stereo).
    pub film_width: u32,
    /// Film height in pixels.
    pub film_height: u32,
}

// Built once per render, so the size of the largest variant does not matter.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug)]
enum Kind {
    Perspective(Pinhole),
    Parallel { corner: Vec3, dx: Vec3, dy: Vec3, dir: Vec3 },
    Panorama { frame: ViewFrame, angle: f64 },
    Stereo { left: Pinhole, right: Pinhole },
}

/// A perspective camera as frame + `P⁻¹`, composed once with the film's pixel scale: the
/// homogeneous point `P⁻¹ (x, y, −1, 1)` behind a pixel is affine in the pixel's coordinates,
/// and the ray's direction is its world part, normalised (no division by `w`, only its sign).
#[derive(Clone, Debug)]
struct Pinhole {
    eye: Vec3,
    /// The world part and `w` at pixel (0, 0), and their steps per pixel along x and y.
    at_origin: (Vec3, f64),
    per_x: (Vec3, f64),
    per_y: (Vec3, f64),
    /// Straight ahead, where `w` is zero.
    ahead: Vec3,
}

impl Pinhole {
    /// The camera for a film of `width × height` pixels (`y` down) spanning the standard
    /// square `[−1, 1]²` (`y` up).
    fn new(frame: ViewFrame, frustum: Frustum, width: f64, height: f64) -> Self {
        let p_inv = frustum.perspective_inverse();
        let world = |q: Vec4| (frame.to_world_dir(q.truncate()), q.w);
        // x = 2 fx / width − 1, y = 1 − 2 fy / height.
        let at_origin = world(p_inv * Vec4::new(-1.0, 1.0, -1.0, 1.0));
        let per_x = world(p_inv * Vec4::new(2.0 / width, 0.0, 0.0, 0.0));
        let per_y = world(p_inv * Vec4::new(0.0, -2.0 / height, 0.0, 0.0));
        Self { eye: frame.eye, at_origin, per_x, per_y, ahead: frame.to_world_dir(Vec3::NEG_Z) }
    }

    /// The ray through film position `(fx, fy)` in pixels.
    #[inline]
    fn ray(&self, fx: f64, fy: f64) -> Ray {
        let (d, w) = (
            self.at_origin.0 + self.per_x.0 * fx + self.per_y.0 * fy,
            self.at_origin.1 + self.per_x.1 * fx + self.per_y.1 * fy,
        );
        let dir = if w == 0.0 || !w.is_finite() {
            self.ahead
        } else if w < 0.0 {
            -d
        } else {
            d
        };
        Ray::new(self.eye, dir.normalize())
    }
}

/// A thin lens in world space: its disk's axes (the view frame's `u`, `v` times the radius),
/// the eye at its centre, and the plane in focus, `focus` along `ahead`.
#[derive(Clone, Copy, Debug)]
struct Lens {
    u: Vec3,
    v: Vec3,
    ahead: Vec3,
    focus: f64,
}

impl Lens {
    /// The ray from the lens point of `sample` (in the unit square) towards where the pinhole
    /// ray `through` meets the plane in focus.
    fn ray(&self, through: &Ray, sample: Vec2) -> Ray {
        let along = through.dir.dot(self.ahead);
        if along <= 0.0 {
            return *through;
        }
        let focus = through.at(self.focus / along);
        let (x, y) = concentric_disk(sample);
        let origin = through.origin + self.u * x + self.v * y;
        Ray::new(origin, (focus - origin).normalize())
    }
}

/// Shirley and Chiu's map of the unit square onto the unit disk, preserving areas.
fn concentric_disk(s: Vec2) -> (f64, f64) {
    let (a, b) = (2.0 * s.x - 1.0, 2.0 * s.y - 1.0);
    if a == 0.0 && b == 0.0 {
        return (0.0, 0.0);
    }
    let quarter = std::f64::consts::FRAC_PI_4;
    let (r, phi) = if a.abs() > b.abs() { (a, quarter * (b / a)) } else { (b, 2.0 * quarter - quarter * (a / b)) };
    let (sin, cos) = phi.sin_cos();
    (r * cos, r * sin)
}

fn frame(look: &alhazen_scene::LookAt) -> ViewFrame {
    // The scene reader has checked the frame is well defined; fall back to a fixed one anyway.
    ViewFrame::look_at(look.eye, look.target, look.up).unwrap_or(ViewFrame {
        eye: look.eye,
        u: Vec3::X,
        v: Vec3::Y,
        w: Vec3::Z,
    })
}

impl Camera {
    /// Builds the camera for an image of `width × height` pixels (per eye).
    pub fn new(desc: &CameraDesc, width: u32, height: u32) -> Self {
        let aspect = width as f64 / height as f64;
        let lens = match desc {
            CameraDesc::Perspective { look, lens: Some(l), .. } => {
                let f = frame(look);
                Some(Lens { u: f.u * l.aperture, v: f.v * l.aperture, ahead: -f.w, focus: l.focus_distance })
            }
            _ => None,
        };
        let (kind, film_width) = match desc {
            CameraDesc::Perspective { look, opening, .. } => {
                let frustum = opening.frustum(aspect, None);
                (Kind::Perspective(Pinhole::new(frame(look), frustum, width as f64, height as f64)), width)
            }
            CameraDesc::Orthographic { look, width: w } => {
                let f = frame(look);
                (parallel(f.u, f.v, -f.w, look.eye, *w, (width, height), 0.0), width)
            }
            CameraDesc::Axonometric { style, target, width: w, azimuth } => {
                let (a, b) = style.axes(*azimuth);
                let dir = alhazen_scene::Axonometry::direction(a, b);
                (parallel(a, b, dir, *target, *w, (width, height), 1e4), width)
            }
            CameraDesc::Stereo { look, eye_distance, screen_distance, screen_width } => {
                let f = frame(look);
                let (l, r) =
                    stereo_frusta(*eye_distance, *screen_distance, *screen_width, screen_width / aspect, 1.0, 1000.0);
                let eye = |s: f64| ViewFrame { eye: f.eye + f.u * (s * eye_distance / 2.0), ..f };
                (
                    Kind::Stereo {
                        left: Pinhole::new(eye(-1.0), l, width as f64, height as f64),
                        right: Pinhole::new(eye(1.0), r, width as f64, height as f64),
                    },
                    width * 2,
                )
            }
            CameraDesc::Panorama { look, angle } => (Kind::Panorama { frame: frame(look), angle: *angle }, width),
        };
        Self { kind, lens, film_width, film_height: height }
    }

    /// True when rays start on a lens: [`Self::lens_ray`] needs a second pair of numbers.
    #[inline(always)]
    pub fn has_lens(&self) -> bool {
        self.lens.is_some()
    }

    /// The ray through film position `(fx, fy)` from the lens point of `sample` (in the unit
    /// square): [`Self::ray`] without a lens.
    #[inline]
    pub fn lens_ray(&self, fx: f64, fy: f64, sample: Vec2) -> Ray {
        let pinhole = self.ray(fx, fy);
        self.lens.map_or(pinhole, |l| l.ray(&pinhole, sample))
    }

    /// [`Self::ray`] for a sample of a pixel of column `column`, placed at `(fx, fy)` by a pixel
    /// filter (perhaps beyond the pixel): a stereo pair's eye is the pixel's, a sample beyond
    /// its image's edge seeing on through the same eye (as beyond any image's edge), never the
    /// other eye's view.
    #[inline(always)]
    pub fn pixel_ray(&self, column: u32, fx: f64, fy: f64) -> Ray {
        match &self.kind {
            Kind::Stereo { left, right } => {
                let half = self.film_width / 2;
                if column < half { left.ray(fx, fy) } else { right.ray(fx - half as f64, fy) }
            }
            _ => self.ray(fx, fy),
        }
    }

    /// [`Self::lens_ray`] for a sample of a pixel of column `column`, as [`Self::pixel_ray`].
    #[inline]
    pub fn pixel_lens_ray(&self, column: u32, fx: f64, fy: f64, sample: Vec2) -> Ray {
        let pinhole = self.pixel_ray(column, fx, fy);
        self.lens.map_or(pinhole, |l| l.ray(&pinhole, sample))
    }

    /// The ray through film position `(fx, fy)` in pixels, `y` down.
    #[inline(always)]
    pub fn ray(&self, fx: f64, fy: f64) -> Ray {
        let (w, h) = (self.film_width as f64, self.film_height as f64);
        match &self.kind {
            Kind::Perspective(p) => p.ray(fx, fy),
            Kind::Parallel { corner, dx, dy, dir } => Ray::new(*corner + *dx * fx + *dy * fy, *dir),
            Kind::Panorama { frame, angle } => {
                let phi = (fx / w - 0.5) * angle;
                let height = (0.5 - fy / h) * angle * h / w;
                Ray::new(frame.eye, frame.to_world_dir(Vec3::new(phi.sin(), height, -phi.cos())).normalize())
            }
            Kind::Stereo { left, right } => {
                let half = w / 2.0;
                let (cam, x) = if fx < half { (left, fx) } else { (right, fx - half) };
                cam.ray(x, fy)
            }
        }
    }
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

#[cfg(test)]
mod tests {
    use super::*;
    use alhazen_scene::{Axonometry, LookAt, PerspectiveOpening};

    const LOOK: LookAt = LookAt { eye: Vec3::new(0.0, 0.0, 5.0), target: Vec3::ZERO, up: Vec3::Y };

    #[test]
    fn perspective_edges_span_the_horizontal_fov() {
        let desc = CameraDesc::Perspective {
            look: LOOK,
            opening: PerspectiveOpening::Fov { angle: 60f64.to_radians(), horizontal: true },
            lens: None,
        };
        let cam = Camera::new(&desc, 400, 300);
        let (left, right) = (cam.ray(0.0, 150.0).dir, cam.ray(400.0, 150.0).dir);
        assert!((left.angle_between(right) - 60f64.to_radians()).abs() < 1e-12);
        let centre = cam.ray(200.0, 150.0).dir;
        assert!((centre - Vec3::NEG_Z).length() < 1e-12);
        // Right-handed: looking down −z, the image's right is +x and its top +y.
        assert!(right.x > 0.0 && cam.ray(200.0, 0.0).dir.y > 0.0);
    }

    #[test]
    fn frustum_camera_matches_the_course_frustum() {
        let desc = CameraDesc::Perspective {
            look: LOOK,
            opening: PerspectiveOpening::Frustum { lrbtn: [-0.2, 0.6, -0.3, 0.3, 1.0] },
            lens: None,
        };
        let cam = Camera::new(&desc, 80, 60);
        // The film's top-left corner looks through (l, t, −n).
        let d = cam.ray(0.0, 0.0).dir;
        assert!((d - Vec3::new(-0.2, 0.3, -1.0).normalize()).length() < 1e-12);
    }

    /// Where a parallel camera's film shows world point `p`, by intersecting its ray grid.
    fn film_position(cam: &Camera, p: Vec3) -> (f64, f64) {
        let Kind::Parallel { corner, dx, dy, dir } = &cam.kind else { panic!("parallel camera") };
        let m = Mat3::from_cols(*dx, *dy, *dir);
        let s = m.inverse() * (p - *corner);
        (s.x, s.y)
    }

    #[test]
    fn isometric_foreshortens_the_three_axes_equally() {
        let desc =
            CameraDesc::Axonometric { style: Axonometry::Isometric, target: Vec3::ZERO, width: 10.0, azimuth: 0.0 };
        let cam = Camera::new(&desc, 100, 100);
        let o = film_position(&cam, Vec3::ZERO);
        let lens: Vec<f64> = [Vec3::X, Vec3::Y, Vec3::Z]
            .iter()
            .map(|a| {
                let q = film_position(&cam, *a);
                ((q.0 - o.0).powi(2) + (q.1 - o.1).powi(2)).sqrt()
            })
            .collect();
        assert!((lens[0] - lens[1]).abs() < 1e-9 && (lens[1] - lens[2]).abs() < 1e-9, "{lens:?}");
        // Vertical stays vertical.
        let up = film_position(&cam, Vec3::Y);
        assert!((up.0 - o.0).abs() < 1e-9 && up.1 < o.1);
    }

    #[test]
    fn cavalier_keeps_the_front_and_draws_depth_at_45_degrees() {
        let desc =
            CameraDesc::Axonometric { style: Axonometry::Cavalier, target: Vec3::ZERO, width: 10.0, azimuth: 0.0 };
        let cam = Camera::new(&desc, 100, 100);
        let o = film_position(&cam, Vec3::ZERO);
        let x = film_position(&cam, Vec3::X);
        let depth = film_position(&cam, Vec3::NEG_Z);
        assert!(((x.0 - o.0) - 10.0).abs() < 1e-9 && (x.1 - o.1).abs() < 1e-9, "x axis unscaled");
        let (ddx, ddy) = (depth.0 - o.0, o.1 - depth.1);
        assert!((ddx - ddy).abs() < 1e-9 && ((ddx * ddx + ddy * ddy).sqrt() - 10.0).abs() < 1e-9, "full length at 45°");
    }

    #[test]
    fn military_keeps_the_ground_plan() {
        let desc =
            CameraDesc::Axonometric { style: Axonometry::Military, target: Vec3::ZERO, width: 10.0, azimuth: 0.7 };
        let cam = Camera::new(&desc, 100, 100);
        // Distances and right angles in the ground plane are preserved.
        let (o, a, b) = (film_position(&cam, Vec3::ZERO), film_position(&cam, Vec3::X), film_position(&cam, Vec3::Z));
        let (va, vb) = ((a.0 - o.0, a.1 - o.1), (b.0 - o.0, b.1 - o.1));
        assert!((va.0 * vb.0 + va.1 * vb.1).abs() < 1e-9);
        assert!(((va.0.hypot(va.1)) - 10.0).abs() < 1e-9 && ((vb.0.hypot(vb.1)) - 10.0).abs() < 1e-9);
    }

    #[test]
    fn stereo_eyes_are_apart_and_converge_on_the_screen() {
        let desc = CameraDesc::Stereo { look: LOOK, eye_distance: 0.5, screen_distance: 5.0, screen_width: 4.0 };
        let cam = Camera::new(&desc, 100, 50);
        assert_eq!(cam.film_width, 200);
        let (l, r) = (cam.ray(50.0, 25.0), cam.ray(150.0, 25.0));
        assert!(((r.origin - l.origin).length() - 0.5).abs() < 1e-12);
        // Both centre rays meet at the screen centre, the target.
        let pl = l.at(5.0 / -l.dir.z);
        let pr = r.at(5.0 / -r.dir.z);
        assert!(pl.length() < 1e-9 && pr.length() < 1e-9, "{pl} {pr}");
    }

    /// A filtered sample of a stereo pixel beside the seam, placed across it, is still seen by
    /// its pixel's eye (the other eye's view must not bleed in).
    #[test]
    fn a_stereo_pixel_keeps_its_eye_beyond_the_seam() {
        let desc = CameraDesc::Stereo { look: LOOK, eye_distance: 0.5, screen_distance: 5.0, screen_width: 4.0 };
        let cam = Camera::new(&desc, 100, 50);
        let (left_eye, right_eye) = (cam.ray(10.0, 25.0).origin, cam.ray(110.0, 25.0).origin);
        assert_eq!(cam.pixel_ray(99, 100.7, 25.0).origin, left_eye);
        assert_eq!(cam.pixel_ray(100, 99.2, 25.0).origin, right_eye);
        assert_eq!(cam.ray(100.7, 25.0).origin, right_eye);
        // Within the pixel, the ray of `ray` itself.
        assert_eq!(cam.pixel_ray(99, 99.5, 25.0), cam.ray(99.5, 25.0));
        assert_eq!(cam.pixel_ray(100, 100.5, 25.0), cam.ray(100.5, 25.0));
    }

    proptest::proptest! {
        /// Through a thin lens every ray of a film point starts on the lens (a disk of the
        /// aperture's radius about the eye, across the view axis) and meets the pinhole ray
        /// of that point on the plane in focus; the lens's points fill the disk uniformly
        /// (Shirley–Chiu's map preserves area: a quarter of the square lands within half the
        /// radius).
        #[test]
        fn a_thin_lens_focuses_every_ray_of_a_film_point_on_the_plane_in_focus(
            fx in 0.0..400.0f64, fy in 0.0..300.0f64, u in 0.0..1.0f64, v in 0.0..1.0f64,
            aperture in 0.01..0.5f64, focus_distance in 0.5..20.0f64,
        ) {
            let lens = alhazen_scene::ThinLens { aperture, focus_distance };
            let look = LookAt { eye: Vec3::new(1.0, 2.0, 3.0), target: Vec3::new(-2.0, 0.5, -1.0), up: Vec3::Y };
            let opening = PerspectiveOpening::Fov { angle: 50f64.to_radians(), horizontal: true };
            let cam = Camera::new(&CameraDesc::Perspective { look, opening, lens: Some(lens) }, 400, 300);
            let (pinhole, ray) = (cam.ray(fx, fy), cam.lens_ray(fx, fy, alhazen_math::Vec2::new(u, v)));
            let ahead = (look.target - look.eye).normalize();
            let offset = ray.origin - look.eye;
            proptest::prop_assert!(offset.dot(ahead).abs() < 1e-12 && offset.length() <= aperture * (1.0 + 1e-12));
            let focus = pinhole.at(focus_distance / pinhole.dir.dot(ahead));
            let t = (focus - ray.origin).dot(ray.dir);
            proptest::prop_assert!((ray.at(t) - focus).length() < 1e-9 * (1.0 + focus_distance), "{} {}", ray.at(t), focus);
            let (x, y) = concentric_disk(alhazen_math::Vec2::new(u, v));
            let inner = (u - 0.5).abs() < 0.25 && (v - 0.5).abs() < 0.25;
            proptest::prop_assert!(!inner || x.hypot(y) <= 0.5 + 1e-12);
        }
    }

    #[test]
    fn without_a_lens_a_camera_draws_no_lens_point() {
        let opening = PerspectiveOpening::Fov { angle: 1.0, horizontal: true };
        let cam = Camera::new(&CameraDesc::Perspective { look: LOOK, opening, lens: None }, 40, 30);
        assert!(!cam.has_lens());
        assert_eq!(cam.lens_ray(3.5, 7.25, alhazen_math::Vec2::new(0.9, 0.1)), cam.ray(3.5, 7.25));
    }

    #[test]
    fn panorama_columns_are_equal_angles() {
        let desc = CameraDesc::Panorama { look: LOOK, angle: std::f64::consts::PI };
        let cam = Camera::new(&desc, 180, 60);
        let a = cam.ray(90.0, 30.0).dir;
        let b = cam.ray(135.0, 30.0).dir;
        let c = cam.ray(180.0, 30.0).dir;
        assert!((a.angle_between(b) - std::f64::consts::FRAC_PI_4).abs() < 1e-12);
        assert!((a.angle_between(c) - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    }
}
