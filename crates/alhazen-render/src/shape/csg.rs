//! Constructive solid geometry for ray tracing (course, §"Constructive solid geometry"): the
//! crossings of the line with both operands are merged in order of `t`, and a boundary of the
//! result is kept exactly where membership of the combined set changes. Keeping only changes of
//! membership is the regularisation: surfaces where the set is inside on both sides (or outside
//! on both) are dropped.

use super::{Candidate, Crossing, Placed, SurfaceHit};
use alhazen_math::{Bounds3, Ray};
use alhazen_scene::CsgOp;

/// A boolean combination of two closed shapes.
#[derive(Clone, Debug)]
pub struct Csg {
    /// The operation.
    pub op: CsgOp,
    /// Left operand.
    pub a: Placed,
    /// Right operand.
    pub b: Placed,
}

impl Csg {
    fn inside(&self, in_a: bool, in_b: bool) -> bool {
        match self.op {
            CsgOp::Union => in_a || in_b,
            CsgOp::Intersection => in_a && in_b,
            CsgOp::Difference => in_a && !in_b,
        }
    }

    /// Crossings of the result along the whole line, sorted.
    pub fn crossings(&self, ray: &Ray, out: &mut Vec<Crossing>) {
        let (mut ca, mut cb) = (Vec::new(), Vec::new());
        self.a.crossings(ray, &mut ca);
        self.b.crossings(ray, &mut cb);
        let (mut i, mut j) = (0, 0);
        let (mut in_a, mut in_b) = (false, false);
        let mut inside = false;
        while i < ca.len() || j < cb.len() {
            let take_a = j >= cb.len() || (i < ca.len() && ca[i].hit.t <= cb[j].hit.t);
            let (c, from_b) = if take_a {
                i += 1;
                (ca[i - 1], false)
            } else {
                j += 1;
                (cb[j - 1], true)
            };
            if from_b {
                in_b = c.entering
            } else {
                in_a = c.entering
            }
            let now = self.inside(in_a, in_b);
            if now != inside {
                inside = now;
                let mut hit = c.hit;
                if from_b && self.op == CsgOp::Difference {
                    // B's surface bounds A − B from the other side.
                    hit.n = -hit.n;
                    hit.ns = -hit.ns;
                }
                out.push(Crossing { hit, entering: now });
            }
        }
    }

    /// Nearest boundary point of the result in `(0, t_max)` (only its `t` is kept).
    pub fn hit(&self, ray: &Ray, t_max: f64) -> Option<Candidate> {
        self.intersect(ray, t_max).map(|h| Candidate { t: h.t, aux: 0, bary: [0.0; 2] })
    }

    /// The surface at a hit found by [`Csg::hit`] (recomputed: CSG hits are rare enough).
    pub fn surface(&self, ray: &Ray, c: Candidate) -> SurfaceHit {
        self.intersect(ray, c.t * (1.0 + 1e-12) + f64::MIN_POSITIVE).unwrap_or(SurfaceHit::flat(
            c.t,
            ray.at(c.t),
            -ray.dir.normalize(),
            alhazen_math::Vec2::ZERO,
        ))
    }

    /// Nearest boundary point of the result in `(0, t_max)`.
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<SurfaceHit> {
        let mut all = Vec::new();
        self.crossings(ray, &mut all);
        all.into_iter().map(|c| c.hit).find(|h| h.t > 0.0 && h.t < t_max)
    }

    /// Bounding box (A's alone for intersection and difference).
    pub fn bounds(&self) -> Bounds3 {
        match self.op {
            CsgOp::Union => self.a.bounds().union(self.b.bounds()),
            CsgOp::Intersection | CsgOp::Difference => self.a.bounds(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{AaBox, Cylinder, Placed, Shape, Sphere};
    use super::*;
    use alhazen_math::{Transform, Vec3};
    use proptest::prelude::*;

    /// A box minus a sphere, turned and moved: membership by crossings against the formulas.
    fn body(op: CsgOp) -> (Placed, Transform) {
        let to_world =
            Transform::translate(Vec3::new(0.3, -0.2, 1.0)) * Transform::rotate(Vec3::new(1.0, 2.0, 0.5), 0.7);
        let csg = Csg {
            op,
            a: Placed::new(Shape::Box(AaBox { min: Vec3::splat(-1.0), max: Vec3::splat(1.0) }), Transform::IDENTITY),
            b: Placed::new(Shape::Sphere(Sphere::new(Vec3::ZERO, 1.0)), Transform::translate(Vec3::new(0.8, 0.0, 0.0))),
        };
        (Placed::new(Shape::Csg(Box::new(csg)), to_world), to_world)
    }

    proptest! {
        #[test]
        fn membership_follows_the_operation(x in -2.0..2.0f64, y in -2.0..2.0f64, z in -2.0..2.0f64) {
            let local = Vec3::new(x, y, z);
            let in_box = local.abs().max_element() < 1.0;
            let in_ball = (local - Vec3::new(0.8, 0.0, 0.0)).length() < 1.0;
            let margin = (local.abs().max_element() - 1.0).abs().min(((local - Vec3::new(0.8, 0.0, 0.0)).length() - 1.0).abs());
            prop_assume!(margin > 1e-9);
            for (op, want) in [
                (CsgOp::Union, in_box || in_ball),
                (CsgOp::Intersection, in_box && in_ball),
                (CsgOp::Difference, in_box && !in_ball),
            ] {
                let (placed, to_world) = body(op);
                prop_assert_eq!(placed.contains(to_world.point(local)), want, "{:?}", op);
            }
        }
    }

    #[test]
    fn the_normal_near_a_surface_point_is_the_surface_normal() {
        let c = Placed::new(Shape::Cylinder(Cylinder::new(Vec3::ZERO, Vec3::Y * 2.0, 0.5, true)), Transform::IDENTITY);
        let n = c.normal_near(Vec3::new(0.5, 1.0, 0.0), 1e-9).unwrap();
        assert!((n - Vec3::X).length() < 1e-9, "{n:?}");
        assert!(c.normal_near(Vec3::new(0.2, 1.0, 0.0), 1e-3).is_none());
    }
}
