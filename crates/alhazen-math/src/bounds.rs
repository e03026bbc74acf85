//! Axis-aligned bounding boxes, used by the BVH.

use crate::{Ray, Vec3};

/// An axis-aligned box; `EMPTY` has `min > max` so that `union` works from it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds3 {
    /// Lower corner.
    pub min: Vec3,
    /// Upper corner.
    pub max: Vec3,
}

impl Bounds3 {
    /// The empty box, neutral element of [`Bounds3::union`].
    pub const EMPTY: Self = Self { min: Vec3::INFINITY, max: Vec3::NEG_INFINITY };

    /// The box spanned by two corners in any order.
    pub fn new(a: Vec3, b: Vec3) -> Self {
        Self { min: a.min(b), max: a.max(b) }
    }

    /// The box containing a set of points.
    pub fn from_points(points: impl IntoIterator<Item = Vec3>) -> Self {
        points.into_iter().fold(Self::EMPTY, |b, p| b.grow(p))
    }

    /// The smallest box containing both.
    pub fn union(self, o: Self) -> Self {
        Self { min: self.min.min(o.min), max: self.max.max(o.max) }
    }

    /// The smallest box containing `self` and `p`.
    pub fn grow(self, p: Vec3) -> Self {
        Self { min: self.min.min(p), max: self.max.max(p) }
    }

    /// True when no point lies inside.
    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x || self.min.y > self.max.y || self.min.z > self.max.z
    }

    /// True when every coordinate is finite.
    pub fn is_finite(&self) -> bool {
        self.min.is_finite() && self.max.is_finite()
    }

    /// Centre point.
    pub fn centroid(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }

    /// Edge lengths.
    pub fn extent(&self) -> Vec3 {
        self.max - self.min
    }

    /// Surface area (0 for an empty box), the cost measure of the SAH.
    pub fn surface_area(&self) -> f64 {
        if self.is_empty() {
            return 0.0;
        }
        let d = self.extent();
        2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
    }

    /// Slab test: the parameter interval where `ray` is inside, clipped to `[0, t_max]`.
    /// `inv_dir` is `1 / ray.dir` componentwise.
    #[inline]
    pub fn hit_interval(&self, ray: &Ray, inv_dir: Vec3, t_max: f64) -> Option<(f64, f64)> {
        let t0 = (self.min - ray.origin) * inv_dir;
        let t1 = (self.max - ray.origin) * inv_dir;
        let near = t0.min(t1).max_element().max(0.0);
        // The factor guards against rounding (pbrt's gamma(3)).
        let far = t0.max(t1).min_element().min(t_max) * (1.0 + 2.0 * f64::EPSILON * 3.0);
        (near <= far).then_some((near, far))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slab_test_hits_and_misses() {
        let b = Bounds3::new(Vec3::splat(-1.0), Vec3::splat(1.0));
        let r = Ray::new(Vec3::new(-5.0, 0.0, 0.0), Vec3::X);
        let (n, f) = b.hit_interval(&r, 1.0 / r.dir, f64::INFINITY).unwrap();
        assert!((n - 4.0).abs() < 1e-12 && (f - 6.0).abs() < 1e-9);
        let miss = Ray::new(Vec3::new(-5.0, 2.0, 0.0), Vec3::X);
        assert!(b.hit_interval(&miss, 1.0 / miss.dir, f64::INFINITY).is_none());
        assert!(b.hit_interval(&r, 1.0 / r.dir, 3.0).is_none());
    }

    #[test]
    fn union_and_area() {
        let b = Bounds3::EMPTY.grow(Vec3::ZERO).grow(Vec3::new(1.0, 2.0, 3.0));
        assert_eq!(b.surface_area(), 2.0 * (2.0 + 6.0 + 3.0));
        assert_eq!(Bounds3::EMPTY.surface_area(), 0.0);
        assert!(Bounds3::EMPTY.is_empty());
    }
}
