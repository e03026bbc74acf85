//! Planes `n·(p − q) = 0` and disks (the part of a plane within a radius of a centre).

use alhazen_math::{Bounds3, Ray, Vec2, Vec3, orthonormal_basis};

use super::{Candidate, SurfaceHit};

/// An infinite plane; its texture coordinates are lengths along a tangent frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    /// A point on the plane.
    pub point: Vec3,
    /// Unit normal (the front side).
    pub normal: Vec3,
}

#[inline]
fn plane_t(point: Vec3, normal: Vec3, ray: &Ray) -> f64 {
    let denom = normal.dot(ray.dir);
    if denom == 0.0 { f64::NAN } else { normal.dot(point - ray.origin) / denom }
}

impl Plane {
    /// Nearest hit in `(0, t_max)`.
    #[inline]
    pub fn hit(&self, ray: &Ray, t_max: f64) -> Option<Candidate> {
        let t = plane_t(self.point, self.normal, ray);
        (t > 0.0 && t < t_max).then_some(Candidate { t, aux: 0, bary: [0.0; 2] })
    }

    /// The surface at a hit.
    pub fn surface(&self, ray: &Ray, c: Candidate) -> SurfaceHit {
        let (t, p) = (c.t, ray.at(c.t));
        let (tu, tv) = orthonormal_basis(self.normal);
        let d = p - self.point;
        SurfaceHit::flat(t, p, self.normal, Vec2::new(d.dot(tu), d.dot(tv)))
    }

    /// `∂p/∂u`, `∂p/∂v`: the tangent frame the texture coordinates are measured along.
    pub fn tangents(&self) -> [Vec3; 2] {
        let (tu, tv) = orthonormal_basis(self.normal);
        [tu, tv]
    }
}

/// A flat disk.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Disk {
    /// Centre.
    pub center: Vec3,
    /// Unit normal.
    pub normal: Vec3,
    /// Radius.
    pub radius: f64,
}

impl Disk {
    /// Nearest hit in `(0, t_max)`.
    #[inline]
    pub fn hit(&self, ray: &Ray, t_max: f64) -> Option<Candidate> {
        let t = plane_t(self.center, self.normal, ray);
        let inside = (ray.at(t) - self.center).length_squared() <= self.radius * self.radius;
        (t > 0.0 && t < t_max && inside).then_some(Candidate { t, aux: 0, bary: [0.0; 2] })
    }

    /// The surface at a hit.
    pub fn surface(&self, ray: &Ray, c: Candidate) -> SurfaceHit {
        let p = ray.at(c.t);
        let d = p - self.center;
        let (tu, tv) = orthonormal_basis(self.normal);
        let uv = Vec2::new(d.dot(tu), d.dot(tv)) / (2.0 * self.radius) + 0.5;
        SurfaceHit::flat(c.t, p, self.normal, uv)
    }

    /// Bounding box (tight per axis).
    pub fn bounds(&self) -> Bounds3 {
        let n = self.normal;
        let e = Vec3::new(
            (1.0 - n.x * n.x).max(0.0).sqrt(),
            (1.0 - n.y * n.y).max(0.0).sqrt(),
            (1.0 - n.z * n.z).max(0.0).sqrt(),
        ) * self.radius;
        Bounds3::new(self.center - e, self.center + e)
    }
}
