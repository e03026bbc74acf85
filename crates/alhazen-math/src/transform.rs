//! Affine transformations `f(p) = L p + t` as 4×4 homogeneous matrices (course, §"Affine
//! transformations"), stored with their inverse.
//!
//! Points map by `A p`, free vectors by `L v`, and normal vectors by `L^{-T} n` (course,
//! §"Transformations of the normal vector": `m = L^{-T} n` keeps `mᵀ(f(p) − f(p₀)) = 0`).
//! Composition `a * b` applies `b` first, as the matrix product `A_a A_b` does.

use crate::{Bounds3, Mat3, Mat4, Ray, Vec3};
use std::ops::Mul;

/// Why a matrix cannot be used as a transformation.
#[derive(Clone, Debug, PartialEq)]
pub enum TransformError {
    /// The linear part is singular or the matrix has non-finite entries.
    NotInvertible,
    /// The bottom row is not `(0, 0, 0, 1)`.
    NotAffine,
}

impl std::fmt::Display for TransformError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::NotInvertible => write!(f, "the transformation is singular (not invertible)"),
            Self::NotAffine => write!(f, "the matrix is not affine (last row must be 0 0 0 1)"),
        }
    }
}

impl std::error::Error for TransformError {}

/// An invertible affine map with its inverse cached.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    m: Mat4,
    inv: Mat4,
}

impl Default for Transform {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Transform {
    /// The identity map.
    pub const IDENTITY: Self = Self { m: Mat4::IDENTITY, inv: Mat4::IDENTITY };

    /// True when the map reverses orientation (negative determinant, a mirror image): a
    /// triangle's winding then reverses, so its outside is kept by swapping two corners.
    pub fn is_mirroring(&self) -> bool {
        Mat3::from_mat4(self.m).determinant() < 0.0
    }

    /// The uniform scale of a similarity (rotation, reflection, uniform scale and translation);
    /// `None` for shears and unequal scales.
    pub fn similarity_scale(&self) -> Option<f64> {
        let (a, b, c) = (self.vector(Vec3::X), self.vector(Vec3::Y), self.vector(Vec3::Z));
        let s = a.length();
        let same = |v: Vec3| (v.length() - s).abs() < 1e-9 * s;
        let orthogonal = a.dot(b).abs() + b.dot(c).abs() + a.dot(c).abs() < 1e-9 * s * s;
        (s > 0.0 && same(b) && same(c) && orthogonal).then_some(s)
    }

    /// Checks invertibility and affinity of a user matrix.
    pub fn from_matrix(m: Mat4) -> Result<Self, TransformError> {
        if m.row(3) != crate::Vec4::new(0.0, 0.0, 0.0, 1.0) {
            return Err(TransformError::NotAffine);
        }
        let l = Mat3::from_mat4(m);
        let det = l.determinant();
        let scale = l.x_axis.length() * l.y_axis.length() * l.z_axis.length();
        if !m.is_finite() || !det.is_finite() || det.abs() <= 1e-12 * scale || scale == 0.0 {
            return Err(TransformError::NotInvertible);
        }
        Ok(Self { m, inv: m.inverse() })
    }

    /// Translation by `t`.
    pub fn translate(t: Vec3) -> Self {
        Self { m: Mat4::from_translation(t), inv: Mat4::from_translation(-t) }
    }

    /// Axis-aligned scaling; a zero factor makes it singular.
    pub fn try_scale(s: Vec3) -> Result<Self, TransformError> {
        Self::from_matrix(Mat4::from_scale(s))
    }

    /// Axis-aligned scaling by non-zero factors.
    ///
    /// # Panics
    /// If a factor is zero or not finite; use [`Transform::try_scale`] for user input.
    pub fn scale(s: Vec3) -> Self {
        Self::try_scale(s).expect("scale factors must be non-zero")
    }

    /// Rotation by `angle` radians about the unit `axis` through the origin (right-hand rule).
    pub fn rotate(axis: Vec3, angle: f64) -> Self {
        let m = Mat4::from_axis_angle(axis.normalize(), angle);
        Self { m, inv: m.transpose() }
    }

    /// The matrix `A`.
    pub fn matrix(&self) -> Mat4 {
        self.m
    }

    /// The inverse map.
    pub fn inverse(&self) -> Self {
        Self { m: self.inv, inv: self.m }
    }

    /// True for the identity (exactly).
    pub fn is_identity(&self) -> bool {
        self.m == Mat4::IDENTITY
    }

    /// `f(p) = L p + t`.
    #[inline]
    pub fn point(&self, p: Vec3) -> Vec3 {
        self.m.transform_point3(p)
    }

    /// `L v`, for free vectors (differences of points).
    #[inline]
    pub fn vector(&self, v: Vec3) -> Vec3 {
        self.m.transform_vector3(v)
    }

    /// `L^{-T} n`, for normal vectors; the result is not normalised.
    #[inline]
    pub fn normal(&self, n: Vec3) -> Vec3 {
        let i = &self.inv;
        // (L^{-1})^T n: dot n with the columns of L^{-1}.
        Vec3::new(i.x_axis.truncate().dot(n), i.y_axis.truncate().dot(n), i.z_axis.truncate().dot(n))
    }

    /// The ray with both origin and direction mapped (the direction is not renormalised, so
    /// ray parameters `t` are preserved).
    #[inline]
    pub fn ray(&self, r: &Ray) -> Ray {
        Ray::new(self.point(r.origin), self.vector(r.dir))
    }

    /// `self.inverse().ray(r)` without copying the matrices.
    #[inline]
    pub fn inverse_ray(&self, r: &Ray) -> Ray {
        Ray::new(self.inv.transform_point3(r.origin), self.inv.transform_vector3(r.dir))
    }

    /// A box containing the image of `b` (the eight corners transformed).
    pub fn bounds(&self, b: &Bounds3) -> Bounds3 {
        if b.is_empty() {
            return *b;
        }
        Bounds3::from_points((0..8).map(|i| {
            let c = Vec3::new(
                if i & 1 == 0 { b.min.x } else { b.max.x },
                if i & 2 == 0 { b.min.y } else { b.max.y },
                if i & 4 == 0 { b.min.z } else { b.max.z },
            );
            self.point(c)
        }))
    }
}

impl Mul for Transform {
    type Output = Transform;
    /// `(a * b)(p) = a(b(p))`: the course's `A₂A₁` for `f₂ ∘ f₁`.
    fn mul(self, rhs: Transform) -> Transform {
        Transform { m: self.m * rhs.m, inv: rhs.inv * self.inv }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn arb_vec() -> impl Strategy<Value = Vec3> {
        (-10.0..10.0f64, -10.0..10.0f64, -10.0..10.0f64).prop_map(|(x, y, z)| Vec3::new(x, y, z))
    }

    fn arb_transform() -> impl Strategy<Value = Transform> {
        (arb_vec(), arb_vec(), 0.0..6.3f64, (0.2..3.0f64, 0.2..3.0f64, 0.2..3.0f64)).prop_map(
            |(t, axis, angle, (sx, sy, sz))| {
                let axis = if axis.length() < 1e-3 { Vec3::Y } else { axis };
                Transform::translate(t) * Transform::rotate(axis, angle) * Transform::scale(Vec3::new(sx, sy, sz))
            },
        )
    }

    proptest! {
        #[test]
        fn transformed_normals_stay_perpendicular(t in arb_transform(), p0 in arb_vec(), a in arb_vec(), b in arb_vec()) {
            // A plane through p0 spanned by a, b; its normal a×b.
            let n = a.cross(b);
            prop_assume!(n.length() > 1e-3);
            let m = t.normal(n).normalize();
            for tangent in [a, b, a + b] {
                let image = t.point(p0 + tangent) - t.point(p0);
                prop_assert!(m.dot(image).abs() <= 1e-9 * image.length().max(1.0));
            }
        }

        #[test]
        fn inverse_undoes(t in arb_transform(), p in arb_vec()) {
            let q = t.inverse().point(t.point(p));
            prop_assert!((q - p).length() < 1e-9);
        }

        #[test]
        fn composition_applies_right_first(a in arb_transform(), b in arb_transform(), p in arb_vec()) {
            let q1 = (a * b).point(p);
            let q2 = a.point(b.point(p));
            prop_assert!((q1 - q2).length() < 1e-8 * q2.length().max(1.0));
        }
    }

    #[test]
    fn similarity_maps_normals_like_vectors() {
        // Course: L may transform normals when f is a similarity.
        let t = Transform::rotate(Vec3::new(1.0, 2.0, 3.0), 0.7) * Transform::scale(Vec3::splat(3.0));
        let n = Vec3::new(0.3, -0.2, 0.9);
        assert!((t.normal(n).normalize() - t.vector(n).normalize()).length() < 1e-12);
    }

    #[test]
    fn singular_and_projective_matrices_are_refused() {
        assert_eq!(Transform::try_scale(Vec3::new(1.0, 0.0, 1.0)), Err(TransformError::NotInvertible));
        let mut m = Mat4::IDENTITY;
        m.w_axis.x = 0.0;
        m.x_axis.w = 1.0;
        assert_eq!(Transform::from_matrix(m), Err(TransformError::NotAffine));
    }
}
