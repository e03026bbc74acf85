//! Finite cylinders and cones of revolution about the segment `base → top/apex`, open or capped
//! by disks. Both reduce to a quadratic in the ray parameter after splitting vectors into their
//! components along the axis and across it.

use super::{Crossing, SurfaceHit, convex_crossings};
use alhazen_math::poly::solve_quadratic;
use alhazen_math::{Bounds3, Ray, Vec2, Vec3, orthonormal_basis};
use std::f64::consts::{PI, TAU};

/// The axis of a solid of revolution.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Axis {
    base: Vec3,
    dir: Vec3,
    height: f64,
    e1: Vec3,
    e2: Vec3,
}

impl Axis {
    fn new(base: Vec3, end: Vec3) -> Self {
        let height = (end - base).length();
        let dir = (end - base) / height;
        let (e1, e2) = orthonormal_basis(dir);
        Self { base, dir, height, e1, e2 }
    }

    fn angle_u(&self, radial: Vec3) -> f64 {
        (radial.dot(self.e2).atan2(radial.dot(self.e1)) + PI) / TAU
    }

    /// Hits of the cap disk at axial position `s` with radius `r` (normal `sign · dir`).
    fn cap(&self, ray: &Ray, s: f64, r: f64, sign: f64, hits: &mut Hits) {
        let denom = ray.dir.dot(self.dir);
        if denom == 0.0 {
            return;
        }
        let center = self.base + self.dir * s;
        let t = (center - ray.origin).dot(self.dir) / denom;
        let p = ray.at(t);
        let d = p - center;
        if d.length_squared() <= r * r {
            let uv = Vec2::new(d.dot(self.e1), d.dot(self.e2)) / (2.0 * r) + 0.5;
            hits.push(SurfaceHit::flat(t, p, self.dir * sign, uv));
        }
    }

    fn bounds(&self, r_base: f64, r_end: f64) -> Bounds3 {
        let d = self.dir;
        let e = Vec3::new((1.0 - d.x * d.x).max(0.0).sqrt(), (1.0 - d.y * d.y).max(0.0).sqrt(), (1.0 - d.z * d.z).max(0.0).sqrt());
        let end = self.base + d * self.height;
        Bounds3::new(self.base - e * r_base, self.base + e * r_base).union(Bounds3::new(end - e * r_end, end + e * r_end))
    }
}

/// Up to four hits, on the stack (this is on the hot path of every ray).
#[derive(Default)]
struct Hits {
    items: [Option<SurfaceHit>; 4],
    len: usize,
}

impl Hits {
    fn push(&mut self, h: SurfaceHit) {
        if self.len < self.items.len() {
            self.items[self.len] = Some(h);
            self.len += 1;
        }
    }

    fn iter(&self) -> impl Iterator<Item = SurfaceHit> + '_ {
        self.items[..self.len].iter().flatten().copied()
    }

    fn nearest(&self, t_max: f64) -> Option<SurfaceHit> {
        self.iter().filter(|h| h.t > 0.0 && h.t < t_max).min_by(|a, b| a.t.total_cmp(&b.t))
    }
}

/// A finite circular cylinder.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cylinder {
    axis: Axis,
    radius: f64,
    capped: bool,
}

impl Cylinder {
    /// The cylinder of `radius` around `base → top`.
    pub fn new(base: Vec3, top: Vec3, radius: f64, capped: bool) -> Self {
        Self { axis: Axis::new(base, top), radius, capped }
    }

    /// All hits of the whole line, unsorted.
    fn hits(&self, ray: &Ray, hits: &mut Hits) {
        let ax = &self.axis;
        let oc = ray.origin - ax.base;
        let (od, dd) = (oc.dot(ax.dir), ray.dir.dot(ax.dir));
        let (op, dp) = (oc - ax.dir * od, ray.dir - ax.dir * dd);
        let roots = solve_quadratic(dp.length_squared(), 2.0 * op.dot(dp), op.length_squared() - self.radius * self.radius);
        for &t in roots.as_slice() {
            let s = od + t * dd;
            if (0.0..=ax.height).contains(&s) {
                let radial = (op + dp * t) / self.radius;
                let uv = Vec2::new(ax.angle_u(radial), s / ax.height);
                hits.push(SurfaceHit::flat(t, ray.at(t), radial.normalize(), uv));
            }
        }
        if self.capped {
            ax.cap(ray, 0.0, self.radius, -1.0, hits);
            ax.cap(ray, ax.height, self.radius, 1.0, hits);
        }
    }

    /// Nearest hit in `(0, t_max)`.
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<SurfaceHit> {
        let mut hits = Hits::default();
        self.hits(ray, &mut hits);
        hits.nearest(t_max)
    }

    /// Entry and exit of the (capped, hence convex) solid.
    pub fn crossings(&self, ray: &Ray, out: &mut Vec<Crossing>) {
        if self.capped {
            let mut hits = Hits::default();
            self.hits(ray, &mut hits);
            convex_crossings(hits.iter().collect(), out);
        }
    }

    /// Bounding box.
    pub fn bounds(&self) -> Bounds3 {
        self.axis.bounds(self.radius, self.radius)
    }
}

/// A finite circular cone with its apex at the end of the axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cone {
    axis: Axis,
    radius: f64,
    capped: bool,
}

impl Cone {
    /// The cone with base disk of `radius` at `base` and apex at `apex`.
    pub fn new(base: Vec3, apex: Vec3, radius: f64, capped: bool) -> Self {
        Self { axis: Axis::new(base, apex), radius, capped }
    }

    fn hits(&self, ray: &Ray, hits: &mut Hits) {
        let ax = &self.axis;
        let k = self.radius / ax.height;
        let oc = ray.origin - ax.base;
        let (od, dd) = (oc.dot(ax.dir), ray.dir.dot(ax.dir));
        let (op, dp) = (oc - ax.dir * od, ray.dir - ax.dir * dd);
        let (k2, h0) = (k * k, ax.height - od);
        // |op + t dp|² = k² (h − s)², s = od + t dd.
        let a = dp.length_squared() - k2 * dd * dd;
        let b = 2.0 * (op.dot(dp) + k2 * h0 * dd);
        let c = op.length_squared() - k2 * h0 * h0;
        for &t in solve_quadratic(a, b, c).as_slice() {
            let s = od + t * dd;
            if (0.0..ax.height).contains(&s) {
                let q = op + dp * t;
                let radial = q.try_normalize().unwrap_or(ax.e1);
                let n = (radial * ax.height + ax.dir * self.radius).normalize();
                let uv = Vec2::new(ax.angle_u(radial), s / ax.height);
                hits.push(SurfaceHit::flat(t, ray.at(t), n, uv));
            }
        }
        if self.capped {
            ax.cap(ray, 0.0, self.radius, -1.0, hits);
        }
    }

    /// Nearest hit in `(0, t_max)`.
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<SurfaceHit> {
        let mut hits = Hits::default();
        self.hits(ray, &mut hits);
        hits.nearest(t_max)
    }

    /// Entry and exit of the (capped, hence convex) solid.
    pub fn crossings(&self, ray: &Ray, out: &mut Vec<Crossing>) {
        if self.capped {
            let mut hits = Hits::default();
            self.hits(ray, &mut hits);
            convex_crossings(hits.iter().collect(), out);
        }
    }

    /// Bounding box.
    pub fn bounds(&self) -> Bounds3 {
        self.axis.bounds(self.radius, 0.0)
    }
}
