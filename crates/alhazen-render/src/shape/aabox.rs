//! Axis-aligned boxes (the slab method, keeping the face of entry and exit).

use super::{Candidate, Crossing, SurfaceHit};
use alhazen_math::{Bounds3, Ray, Vec2, Vec3};

/// A solid axis-aligned box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AaBox {
    /// Lower corner.
    pub min: Vec3,
    /// Upper corner.
    pub max: Vec3,
}

impl AaBox {
    /// Per axis, the parameters where the line enters and leaves that axis's slab; `None` for
    /// a line parallel to a slab and in one of its planes (treated as outside).
    #[inline]
    fn slab_times(&self, ray: &Ray) -> Option<(Vec3, Vec3)> {
        let inv = 1.0 / ray.dir;
        let (t0, t1) = ((self.min - ray.origin) * inv, (self.max - ray.origin) * inv);
        (!t0.is_nan() && !t1.is_nan()).then(|| (t0.min(t1), t0.max(t1)))
    }

    /// Entry and exit parameters along the whole line with their face axes, if it meets the box.
    #[inline]
    fn slab(&self, ray: &Ray) -> Option<((f64, usize), (f64, usize))> {
        let (lo, hi) = self.slab_times(ray)?;
        // Ties go to the lowest axis.
        let near_axis = if lo.x >= lo.y && lo.x >= lo.z {
            0
        } else if lo.y >= lo.z {
            1
        } else {
            2
        };
        let far_axis = if hi.x <= hi.y && hi.x <= hi.z {
            0
        } else if hi.y <= hi.z {
            1
        } else {
            2
        };
        let (near, far) = (lo[near_axis], hi[far_axis]);
        (near <= far && near.is_finite() && far.is_finite()).then_some(((near, near_axis), (far, far_axis)))
    }

    fn hit_at(&self, ray: &Ray, t: f64, axis: usize) -> SurfaceHit {
        let p = ray.at(t);
        let mid = (self.min[axis] + self.max[axis]) * 0.5;
        let mut n = Vec3::ZERO;
        n[axis] = if p[axis] > mid { 1.0 } else { -1.0 };
        let (i, j) = ((axis + 1) % 3, (axis + 2) % 3);
        let size = self.max - self.min;
        let uv = Vec2::new((p[i] - self.min[i]) / size[i], (p[j] - self.min[j]) / size[j]);
        SurfaceHit::flat(t, p, n, uv)
    }

    /// Nearest hit in `(0, t_max)`. The face is found again by [`Self::surface`], so this
    /// test (also every shadow ray's) has no data-dependent branches.
    #[inline]
    pub fn hit(&self, ray: &Ray, t_max: f64) -> Option<Candidate> {
        let (lo, hi) = self.slab_times(ray)?;
        // The same values as `slab`'s entry and exit.
        let (near, far) = (lo.max_element(), hi.min_element());
        let t = if near > 0.0 { near } else { far };
        let inside = near <= far && near.is_finite() && far.is_finite();
        (inside && t > 0.0 && t < t_max).then_some(Candidate { t, aux: 0, bary: [0.0; 2] })
    }

    /// The surface at a hit.
    pub fn surface(&self, ray: &Ray, c: Candidate) -> SurfaceHit {
        let face = self.slab(ray).map_or(0, |((t0, a0), (_, a1))| if t0 == c.t { a0 } else { a1 });
        self.hit_at(ray, c.t, face)
    }

    /// Entry and exit of the line.
    pub fn crossings(&self, ray: &Ray, out: &mut Vec<Crossing>) {
        if let Some(((t0, a0), (t1, a1))) = self.slab(ray) {
            out.push(Crossing { hit: self.hit_at(ray, t0, a0), entering: true });
            out.push(Crossing { hit: self.hit_at(ray, t1, a1), entering: false });
        }
    }

    /// Bounding box.
    pub fn bounds(&self) -> Bounds3 {
        Bounds3::new(self.min, self.max)
    }
}
