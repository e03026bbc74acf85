//! Sphere `|p − c| = r`: the quadratic `|o + t d − c|² = r²`.

use super::{Candidate, Crossing, SurfaceHit, convex_crossings};
use alhazen_math::{Bounds3, Mat3, Ray, Transform, Vec2, Vec3};
use std::f64::consts::{PI, TAU};

/// A sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Centre.
    pub center: Vec3,
    /// Radius (> 0).
    pub radius: f64,
    /// The rotation from world directions to the sphere's own frame (pole +y, `u = 0` towards
    /// −x), when it was placed turned: only its texture coordinates and tangents see it.
    pub turn: Option<Mat3>,
}

impl Sphere {
    /// The sphere of `center` and `radius`, its pole along +y.
    pub const fn new(center: Vec3, radius: f64) -> Self {
        Self { center, radius, turn: None }
    }

    /// The sphere of `center` and `radius` placed by `t`, when `t` is a similarity (rotation,
    /// uniform scale, translation, perhaps a reflection): a sphere in world space, whose
    /// parametrisation alone keeps the rotation.
    pub fn placed(center: Vec3, radius: f64, t: &Transform) -> Option<Self> {
        let scale = t.similarity_scale()?;
        let rotation = Mat3::from_mat4(t.matrix()) / scale;
        let turn = (rotation != Mat3::IDENTITY).then(|| rotation.transpose());
        Some(Self { center: t.point(center), radius: radius * scale, turn })
    }

    /// A unit direction from the centre in the sphere's own frame.
    #[inline]
    fn own(&self, n: Vec3) -> Vec3 {
        self.turn.map_or(n, |r| r * n)
    }

    /// Both roots of `a t² − 2βt + c = 0` (`f = o − c`, `β = −f·d`), ascending. The
    /// discriminant is taken as `a (r² − |f − (f·d/a) d|²)` — from the ray's closest approach to
    /// the centre — instead of `β² − ac`, which cancels catastrophically for rays from far away
    /// (Haines et al., "Precision Improvements for Ray/Sphere Intersection", 2019). `1/a` is
    /// the ray's alone: packets compute it once for all their spheres.
    fn roots(&self, ray: &Ray) -> [f64; 2] {
        let (d, f) = (ray.dir, ray.origin - self.center);
        let a = d.length_squared();
        let inv_a = 1.0 / a;
        let beta = -f.dot(d);
        let perp = f + d * (beta * inv_a);
        let disc = a * (self.radius * self.radius - perp.length_squared());
        if disc < 0.0 || disc.is_nan() || a == 0.0 {
            return [f64::NAN; 2];
        }
        let c = f.length_squared() - self.radius * self.radius;
        let q = beta + disc.sqrt().copysign(beta);
        let (t0, t1) = if q == 0.0 { (0.0, 0.0) } else { (c / q, q * inv_a) };
        [t0.min(t1), t0.max(t1)]
    }

    /// The surface at parameter `t`.
    pub fn hit_at(&self, ray: &Ray, t: f64) -> SurfaceHit {
        let p = ray.at(t);
        let n = (p - self.center) / self.radius;
        // Texture coordinates: longitude around the pole, latitude from the north pole.
        let n_own = self.own(n);
        let u = (n_own.z.atan2(-n_own.x) + PI) / TAU;
        let v = n_own.y.clamp(-1.0, 1.0).acos() / PI;
        SurfaceHit::flat(t, p, n.normalize(), Vec2::new(u, v))
    }

    /// The surface at parameter `t` without texture coordinates.
    #[inline]
    pub fn hit_at_without_uv(&self, ray: &Ray, t: f64) -> SurfaceHit {
        let p = ray.at(t);
        SurfaceHit::flat(t, p, ((p - self.center) / self.radius).normalize(), Vec2::ZERO)
    }

    /// `∂p/∂u` around the pole (longitude) and `∂p/∂v` towards the south (latitude) at a hit.
    pub fn tangents(&self, hit: &SurfaceHit) -> [Vec3; 2] {
        let (n, r) = (self.own(hit.n), self.radius);
        let dpdu = Vec3::new(n.z, 0.0, -n.x) * (TAU * r);
        let rho = (n.x * n.x + n.z * n.z).sqrt();
        let dpdv = if rho > 0.0 { Vec3::new(n.x * n.y / rho, -rho, n.z * n.y / rho) * (PI * r) } else { Vec3::ZERO };
        // The inverse of a rotation is its transpose.
        self.turn.map_or([dpdu, dpdv], |r| [dpdu, dpdv].map(|d| r.transpose() * d))
    }

    /// Nearest hit in `(0, t_max)`.
    #[inline]
    pub fn hit(&self, ray: &Ray, t_max: f64) -> Option<Candidate> {
        let [t0, t1] = self.roots(ray);
        let t = if t0 > 0.0 { t0 } else { t1 };
        (t > 0.0 && t < t_max).then_some(Candidate { t, aux: 0, bary: [0.0; 2] })
    }

    /// Both crossings of the line.
    pub fn crossings(&self, ray: &Ray, out: &mut Vec<Crossing>) {
        let [t0, t1] = self.roots(ray);
        if t0.is_finite() {
            convex_crossings(vec![self.hit_at(ray, t0), self.hit_at(ray, t1)], out);
        }
    }

    /// Bounding box.
    pub fn bounds(&self) -> Bounds3 {
        Bounds3::new(self.center - Vec3::splat(self.radius), self.center + Vec3::splat(self.radius))
    }
}
