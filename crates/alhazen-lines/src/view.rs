//! The drawing's camera: the scene camera as the course's viewing and projection matrices
//! (shared with the raster preview) or as the ray tracer's panorama (central projection on a
//! cylinder around the view's vertical axis, developed flat: straight lines become curves,
//! which the curves' knots follow within the tolerance), film pixels → millimetres on paper, and
//! the one exact visibility question every line asks: does the ray from the eye reach this
//! point?

use alhazen_math::viewing::ViewFrame;
use alhazen_math::{Mat4, Ray, Vec2, Vec3, Vec4};
use alhazen_mirror::Site;
use alhazen_raster::pipeline::{Projection, RasterError, projection};
use alhazen_render::World;
use alhazen_render::shape::ray_epsilon;
use alhazen_scene::{CameraDesc, Scene};

/// Clip-space `w` below which a point counts as behind the eye (relative to the view's scale).
const NEAR_W: f64 = 1e-6;

/// How the camera maps space to the film.
#[derive(Clone, Copy, Debug)]
enum Mapping {
    /// World → clip by the course's matrices: central or parallel projection.
    Projective(Mat4),
    /// The panorama camera: azimuth across the film (`angle` radians over its width), height
    /// over horizontal distance up it, in the view frame.
    Panorama { frame: ViewFrame, angle: f64 },
}

/// A camera that maps world points to the paper and answers visibility by ray casting.
pub struct View {
    mapping: Mapping,
    /// Film size in pixels (the scene's image size).
    pub film: (u32, u32),
    /// Millimetres per film pixel.
    pub mm_per_px: f64,
    /// The eye, or `None` for parallel projections.
    pub eye: Option<Vec3>,
    /// Viewing direction (from the eye into the scene), unit.
    pub dir: Vec3,
    /// A length larger than the scene, for parallel rays' origins and tolerances.
    pub scale: f64,
    near_w: f64,
}

impl View {
    /// The scene camera on paper `width_mm` wide.
    pub fn new(scene: &Scene, world: &World, width_mm: f64) -> Result<View, RasterError> {
        let (w, h) = (scene.render.width, scene.render.height);
        let (mapping, frame, perspective) = match &scene.camera {
            CameraDesc::Panorama { look, angle } => {
                let frame = ViewFrame::look_at(look.eye, look.target, look.up)
                    .ok_or(RasterError::UnsupportedCamera("a panorama whose eye, target and up do not make a frame"))?;
                (Mapping::Panorama { frame, angle: *angle }, frame, true)
            }
            camera => {
                let Projection { world_to_clip, frame, perspective, .. } = projection(camera, w, h)?;
                (Mapping::Projective(world_to_clip), frame, perspective)
            }
        };
        let b = world.bounds();
        let scale = if b.is_empty() { 1.0 } else { (b.max - b.min).length().max(1e-9) + frame.eye.length() };
        let near_w = if perspective { NEAR_W * scale } else { f64::NEG_INFINITY };
        Ok(View {
            mapping,
            film: (w, h),
            mm_per_px: width_mm / w as f64,
            eye: perspective.then_some(frame.eye),
            dir: -frame.w,
            scale,
            near_w,
        })
    }

    /// Clip-space `w` of a point: positive in front of the eye (1 for parallel views); for a
    /// panorama the distance from the view's vertical axis through the eye (the projection
    /// blows up on that axis alone).
    pub fn depth(&self, p: Vec3) -> f64 {
        match self.mapping {
            Mapping::Projective(m) => (m * p.extend(1.0)).w,
            Mapping::Panorama { frame, .. } => {
                let d = p - frame.eye;
                d.dot(frame.u).hypot(d.dot(frame.w))
            }
        }
    }

    /// False for a panorama: straight lines in space are curves on its film.
    pub fn is_projective(&self) -> bool {
        matches!(self.mapping, Mapping::Projective(_))
    }

    /// True when `p` is in front of the eye (far enough not to blow up the projection).
    pub fn in_front(&self, p: Vec3) -> bool {
        self.depth(p) > self.near_w
    }

    /// Film position in pixels (`y` down) of a point in front of the eye.
    pub fn to_film(&self, p: Vec3) -> Vec2 {
        let (w, h) = (self.film.0 as f64, self.film.1 as f64);
        match self.mapping {
            Mapping::Projective(m) => {
                let c: Vec4 = m * p.extend(1.0);
                let (x, y) = (c.x / c.w, c.y / c.w);
                Vec2::new((x + 1.0) * 0.5 * w, (1.0 - y) * 0.5 * h)
            }
            Mapping::Panorama { frame, angle } => {
                // The ray tracer's panorama inverted: direction (sin φ, height, −cos φ).
                let d = p - frame.eye;
                let (x, y, z) = (d.dot(frame.u), d.dot(frame.v), d.dot(frame.w));
                let (phi, height) = (x.atan2(-z), y / x.hypot(z));
                Vec2::new((phi / angle + 0.5) * w, 0.5 * h - height * w / angle)
            }
        }
    }

    /// Paper position in millimetres (`y` down, origin top left).
    pub fn to_paper(&self, p: Vec3) -> Vec2 {
        self.to_film(p) * self.mm_per_px
    }

    /// Paper size in millimetres.
    pub fn paper(&self) -> Vec2 {
        Vec2::new(self.film.0 as f64, self.film.1 as f64) * self.mm_per_px
    }

    /// The eye for the mirror solver: a point, or the direction towards the viewer.
    pub fn viewer(&self) -> Site {
        match self.eye {
            Some(e) => Site::At(e),
            None => Site::Toward(-self.dir),
        }
    }

    /// The parameter along a 3D chord `a → b` of the point at parameter `t` of its projection:
    /// central projection is projective on a line, so equal steps on paper are not equal steps
    /// in space.
    /// A panorama's chords are short enough (their knots follow the curved image within the
    /// tolerance) for the film parameter to stand for the chord's own.
    pub fn chord_param(&self, a: Vec3, b: Vec3, t: f64) -> f64 {
        if !self.is_projective() {
            return t;
        }
        let (wa, wb) = (self.depth(a), self.depth(b));
        let den = (1.0 - t) * wb + t * wa;
        if den.abs() < 1e-300 { t } else { t * wa / den }
    }

    /// The ray from the eye towards `p` and the distance to `p`.
    pub fn eye_ray(&self, p: Vec3) -> (Ray, f64) {
        match self.eye {
            Some(e) => {
                let d = p - e;
                let dist = d.length();
                (Ray::new(e, d / dist.max(1e-300)), dist)
            }
            None => {
                let back = 4.0 * self.scale;
                (Ray::new(p - self.dir * back, self.dir), back)
            }
        }
    }

    /// Exact visibility of a point on (or near) a surface: nothing is hit before it, allowing
    /// for the surface the point itself lies on (a relative 1e-6 of the distance).
    pub fn sees(&self, world: &World, p: Vec3) -> bool {
        self.sees_with(world, p, &Leeway::NONE)
    }

    /// Visibility of a point allowed `own`: hits on those objects closer to the point than
    /// its leeway (a fraction of the distance) do not count — for points on chords of curves
    /// that lie on those objects (an intersection curve's chords run just inside both).
    pub fn sees_with(&self, world: &World, p: Vec3, own: &Leeway) -> bool {
        let (ray, dist) = self.eye_ray(p);
        clear_path(world, ray, dist, own)
    }
}

/// Objects a visibility ray may pass near its end point: hits on them beyond `(1 − near)` of
/// the way are ignored (`near = 1` ignores them entirely: a convex object cannot hide its own
/// contour).
#[derive(Clone, Copy, Debug)]
pub struct Leeway<'a> {
    /// The objects.
    pub objects: &'a [u32],
    /// The fraction of the distance.
    pub near: f64,
}

impl Leeway<'_> {
    /// No leeway.
    pub const NONE: Leeway<'static> = Leeway { objects: &[], near: 0.0 };
}

/// True when hit `h` of `ray` is the point `dist` along it itself, as far as the hit's
/// precision tells: flats are tested in single precision ([`alhazen_render::shape::FlatPacket`]),
/// their plane distances good to the tracers' guard ([`ray_epsilon`]), which along a ray
/// meeting the surface at a cosine `c` is a distance `ε / c`.
fn reaches(ray: &Ray, h: &alhazen_render::world::WorldHit, dist: f64) -> bool {
    let cos = (h.hit.n.dot(ray.dir) / ray.dir.length()).abs().max(1e-3);
    (dist - h.hit.t) * ray.dir.length() < ray_epsilon(h.hit.p) / cos
}

/// True when the ray reaches `dist` with no hit except those `own` allows.
pub fn clear_path(world: &World, ray: Ray, dist: f64, own: &Leeway) -> bool {
    let end = dist * (1.0 - 1e-6);
    let mut t = 0.0;
    for _ in 0..16 {
        let from = Ray::new(ray.origin + ray.dir * t, ray.dir);
        match world.intersect(&from, end - t) {
            None => return true,
            Some(h) if own.objects.contains(&h.object) && t + h.hit.t >= dist * (1.0 - own.near) => {
                // Past the hit by the tracers' own guard (flats are tested in single precision).
                t += h.hit.t + ray_epsilon(h.hit.p) / ray.dir.length();
            }
            Some(h) if reaches(&from, &h, dist - t) => return true,
            Some(_) => return false,
        }
        if t >= end {
            return true;
        }
    }
    false
}
