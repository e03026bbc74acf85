//! Finite cylinders and cones of revolution about the segment `base → top/apex`, open or capped
//! by disks. Both reduce to a quadratic in the ray parameter after splitting vectors into their
//! components along the axis and across it. The search ([`Cylinder::hit`]) finds only `t` and
//! which part was hit; the surface details are computed for the winning hit alone.

use super::{Candidate, Crossing, SurfaceHit};
use alhazen_math::poly::solve_quadratic;
use alhazen_math::{Bounds3, Ray, Vec2, Vec3, orthonormal_basis};
use std::f64::consts::{PI, TAU};

const SIDE: u32 = 0;
const BOTTOM: u32 = 1;
const TOP: u32 = 2;

/// The axis of a solid of revolution.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Axis {
    base: Vec3,
    dir: Vec3,
    height: f64,
    e1: Vec3,
    e2: Vec3,
}

/// Up to four `(t, part)` pairs, on the stack (this is on the hot path of every ray).
#[derive(Default)]
struct Parts {
    items: [Candidate; 4],
    len: usize,
}

impl Parts {
    fn push(&mut self, t: f64, aux: u32) {
        if self.len < self.items.len() {
            self.items[self.len] = Candidate { t, aux, bary: [0.0; 2] };
            self.len += 1;
        }
    }

    fn nearest(&self, t_max: f64) -> Option<Candidate> {
        self.items[..self.len].iter().filter(|c| c.t > 0.0 && c.t < t_max).min_by(|a, b| a.t.total_cmp(&b.t)).copied()
    }

    /// Entry and exit of a convex solid: the first and last of the whole line.
    fn crossings(&self, surface: impl Fn(Candidate) -> SurfaceHit, out: &mut Vec<Crossing>) {
        let items = &self.items[..self.len];
        let first = items.iter().min_by(|a, b| a.t.total_cmp(&b.t));
        let last = items.iter().max_by(|a, b| a.t.total_cmp(&b.t));
        if let (Some(f), Some(l), true) = (first, last, self.len >= 2) {
            out.push(Crossing { hit: surface(*f), entering: true });
            out.push(Crossing { hit: surface(*l), entering: false });
        }
    }
}

/// Axial and radial components of a ray relative to an axis.
struct Split {
    od: f64,
    dd: f64,
    op: Vec3,
    dp: Vec3,
}

impl Axis {
    fn new(base: Vec3, end: Vec3) -> Self {
        let height = (end - base).length();
        let dir = (end - base) / height;
        let (e1, e2) = orthonormal_basis(dir);
        Self { base, dir, height, e1, e2 }
    }

    fn split(&self, ray: &Ray) -> Split {
        let oc = ray.origin - self.base;
        let (od, dd) = (oc.dot(self.dir), ray.dir.dot(self.dir));
        Split { od, dd, op: oc - self.dir * od, dp: ray.dir - self.dir * dd }
    }

    fn angle_u(&self, radial: Vec3) -> f64 {
        (radial.dot(self.e2).atan2(radial.dot(self.e1)) + PI) / TAU
    }

    /// Texture coordinates on the side: the angle around the axis, the height along it.
    fn side_uv(&self, sp: &Split, radial: Vec3, t: f64) -> Vec2 {
        Vec2::new(self.angle_u(radial), (sp.od + t * sp.dd) / self.height)
    }

    /// Ray parameter of the cap disk at axial position `s` and radius `r`, if hit.
    fn cap_t(&self, sp: &Split, s: f64, r: f64) -> Option<f64> {
        if sp.dd == 0.0 {
            return None;
        }
        let t = (s - sp.od) / sp.dd;
        ((sp.op + sp.dp * t).length_squared() <= r * r).then_some(t)
    }

    fn cap_surface(&self, ray: &Ray, t: f64, r: f64, sign: f64) -> SurfaceHit {
        let p = ray.at(t);
        let d = p - self.base - self.dir * (self.dir.dot(p - self.base));
        let uv = Vec2::new(d.dot(self.e1), d.dot(self.e2)) / (2.0 * r) + 0.5;
        SurfaceHit::flat(t, p, self.dir * sign, uv)
    }

    fn bounds(&self, r_base: f64, r_end: f64) -> Bounds3 {
        let d = self.dir;
        let e = Vec3::new(
            (1.0 - d.x * d.x).max(0.0).sqrt(),
            (1.0 - d.y * d.y).max(0.0).sqrt(),
            (1.0 - d.z * d.z).max(0.0).sqrt(),
        );
        let end = self.base + d * self.height;
        Bounds3::new(self.base - e * r_base, self.base + e * r_base)
            .union(Bounds3::new(end - e * r_end, end + e * r_end))
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

    fn parts(&self, ray: &Ray) -> Parts {
        let ax = &self.axis;
        let sp = ax.split(ray);
        let mut parts = Parts::default();
        // From the ray's closest approach to the axis, as for the sphere: |op + t dp|² = r²
        // solved about t_c, so origins far away (axonometric views start 10⁴ back) keep the
        // roots' precision instead of losing it to c = |op|² − r².
        let dp2 = sp.dp.length_squared();
        if dp2 > 0.0 {
            let tc = -sp.op.dot(sp.dp) / dp2;
            let q = sp.op + sp.dp * tc;
            let disc = self.radius * self.radius - q.length_squared();
            if disc >= 0.0 {
                let half = (disc / dp2).sqrt();
                for t in [tc - half, tc + half] {
                    if (0.0..=ax.height).contains(&(sp.od + t * sp.dd)) {
                        parts.push(t, SIDE);
                    }
                }
            }
        }
        if self.capped {
            for (s, part) in [(0.0, BOTTOM), (ax.height, TOP)] {
                if let Some(t) = ax.cap_t(&sp, s, self.radius) {
                    parts.push(t, part);
                }
            }
        }
        parts
    }

    /// Nearest hit in `(0, t_max)`: its `t` and part.
    #[inline]
    pub fn hit(&self, ray: &Ray, t_max: f64) -> Option<Candidate> {
        self.parts(ray).nearest(t_max)
    }

    /// The surface at a hit found by [`Cylinder::hit`].
    pub fn surface(&self, ray: &Ray, c: Candidate) -> SurfaceHit {
        self.surface_with(ray, c, true)
    }

    /// [`Self::surface`], its side's texture coordinates left at zero unless `uv` (their angle
    /// costs an inverse tangent).
    pub fn surface_with(&self, ray: &Ray, c: Candidate, uv: bool) -> SurfaceHit {
        let ax = &self.axis;
        match c.aux {
            BOTTOM => ax.cap_surface(ray, c.t, self.radius, -1.0),
            TOP => ax.cap_surface(ray, c.t, self.radius, 1.0),
            _ => {
                let sp = ax.split(ray);
                let radial = (sp.op + sp.dp * c.t) / self.radius;
                let uv = if uv { ax.side_uv(&sp, radial, c.t) } else { Vec2::ZERO };
                SurfaceHit::flat(c.t, ray.at(c.t), radial.normalize(), uv)
            }
        }
    }

    /// Entry and exit of the (capped, hence convex) solid.
    pub fn crossings(&self, ray: &Ray, out: &mut Vec<Crossing>) {
        if self.capped {
            self.parts(ray).crossings(|c| self.surface(ray, c), out);
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

    fn parts(&self, ray: &Ray) -> Parts {
        let ax = &self.axis;
        // The side's quadratic is solved from the ray's point nearest the base centre, so that
        // far origins (axonometric views start 10⁴ back) do not cancel its constant term.
        let shift = (ax.base - ray.origin).dot(ray.dir) / ray.dir.length_squared();
        let near = ax.split(&Ray::new(ray.origin + ray.dir * shift, ray.dir));
        let k2 = (self.radius / ax.height).powi(2);
        let h0 = ax.height - near.od;
        // |op + t dp|² = k² (h − s)², s = od + t dd.
        let a = near.dp.length_squared() - k2 * near.dd * near.dd;
        let b = 2.0 * (near.op.dot(near.dp) + k2 * h0 * near.dd);
        let c = near.op.length_squared() - k2 * h0 * h0;
        let mut parts = Parts::default();
        for &t in solve_quadratic(a, b, c).as_slice() {
            if (0.0..ax.height).contains(&(near.od + t * near.dd)) {
                parts.push(t + shift, SIDE);
            }
        }
        let sp = ax.split(ray);
        if self.capped
            && let Some(t) = ax.cap_t(&sp, 0.0, self.radius)
        {
            parts.push(t, BOTTOM);
        }
        parts
    }

    /// Nearest hit in `(0, t_max)`: its `t` and part.
    #[inline]
    pub fn hit(&self, ray: &Ray, t_max: f64) -> Option<Candidate> {
        self.parts(ray).nearest(t_max)
    }

    /// The surface at a hit found by [`Cone::hit`].
    pub fn surface(&self, ray: &Ray, c: Candidate) -> SurfaceHit {
        self.surface_with(ray, c, true)
    }

    /// [`Self::surface`], its side's texture coordinates left at zero unless `uv`.
    pub fn surface_with(&self, ray: &Ray, c: Candidate, uv: bool) -> SurfaceHit {
        let ax = &self.axis;
        if c.aux == BOTTOM {
            return ax.cap_surface(ray, c.t, self.radius, -1.0);
        }
        let sp = ax.split(ray);
        let radial = (sp.op + sp.dp * c.t).try_normalize().unwrap_or(ax.e1);
        let n = (radial * ax.height + ax.dir * self.radius).normalize();
        let uv = if uv { ax.side_uv(&sp, radial, c.t) } else { Vec2::ZERO };
        SurfaceHit::flat(c.t, ray.at(c.t), n, uv)
    }

    /// Entry and exit of the (capped, hence convex) solid.
    pub fn crossings(&self, ray: &Ray, out: &mut Vec<Crossing>) {
        if self.capped {
            self.parts(ray).crossings(|c| self.surface(ray, c), out);
        }
    }

    /// Bounding box.
    pub fn bounds(&self) -> Bounds3 {
        self.axis.bounds(self.radius, 0.0)
    }
}
