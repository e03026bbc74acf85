//! Rays `o + t d` (lecture: "determine ray from the cp through the pixel").

use crate::Vec3;

/// A half-line with origin `origin` and direction `dir` (not necessarily unit length).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Start point.
    pub origin: Vec3,
    /// Direction; unit length for rays made by cameras and the integrator.
    pub dir: Vec3,
}

impl Ray {
    /// A ray from `origin` along `dir`.
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        Self { origin, dir }
    }

    /// The point at parameter `t`.
    #[inline]
    pub fn at(&self, t: f64) -> Vec3 {
        self.origin + self.dir * t
    }
}
