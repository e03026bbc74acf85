//! `alhazen-math`: the numeric foundation of alhazen.
//!
//! All geometry is `f64` (exactness matters more than raw width here: the mirror solver needs
//! 1e-12 rad, and a double-precision ray tracer needs almost no self-intersection epsilon).
//! Coordinates are right-handed, angles are radians, `y` is up by convention of the scene files.
//!
//! * [`ray`] — rays and their parametric points;
//! * [`bounds`] — axis-aligned boxes and the slab test;
//! * [`transform`] — affine maps with cached inverse; normals go through the inverse
//!   transpose (course, §"Transformations of the normal vector");
//! * [`viewing`] — the lecture's and course's viewing pipeline: the look-at frame `(u, v, w)`,
//!   orthographic and perspective frustum matrices `(l, r, b, t, n, f)` and their inverses,
//!   window→viewport, homogenisation, stereo frusta;
//! * [`color`] — the course's sRGB transfer function and the XYZ→sRGB matrix;
//! * [`poly`] — numerically careful real roots of low-degree polynomials.
//!
//! ```
//! use alhazen_math::{Ray, Vec3, Transform};
//! let to_world = Transform::translate(Vec3::new(0.0, 1.0, 0.0)) * Transform::scale(Vec3::splat(2.0));
//! let r = Ray::new(Vec3::ZERO, Vec3::X);
//! assert_eq!(to_world.point(r.at(1.0)), Vec3::new(2.0, 1.0, 0.0));
//! ```

pub mod bounds;
pub mod color;
pub mod poly;
pub mod ray;
pub mod transform;
pub mod viewing;

pub use bounds::Bounds3;
pub use glam::{DMat3 as Mat3, DMat4 as Mat4, DVec2 as Vec2, DVec3 as Vec3, DVec4 as Vec4};
pub use ray::Ray;
pub use transform::{Transform, TransformError};

/// Builds an orthonormal basis `(t, b)` completing the unit vector `n` (Duff et al. 2017).
pub fn orthonormal_basis(n: Vec3) -> (Vec3, Vec3) {
    let sign = 1f64.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x), Vec3::new(b, sign + n.y * n.y * a, -n.y))
}
