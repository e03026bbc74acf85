//! Shapes and their ray intersection. Each shape lives in its own file; [`Shape`] dispatches
//! over the closed set without virtual calls. All work happens in object space; [`Placed`]
//! carries the object→world transform (normals by the inverse transpose).
//!
//! Rays need not have unit directions here: transformed rays keep the world parameter `t`.

mod aabox;
mod alpha;
#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
mod avx512;
mod csg;
mod cylinder;
mod flat;
mod flat_packet;
mod mesh;
mod plane;
mod sphere;
mod sphere_packet;

pub use aabox::AaBox;
pub use alpha::{AlphaMask, ray_hash};
pub use csg::Csg;
pub use cylinder::{Cone, Cylinder};
pub use flat::{Flat, FlatLane, flat_primitives, parallelogram_of, parallelogram_to_triangle};
pub use flat_packet::{FlatPacket, LANES as FLAT_LANES, LaneHit, PackedFlats, RayPacket, VectorUnit, ray_epsilon};
#[cfg(target_arch = "x86_64")]
pub(crate) use flat_packet::{RayLanes, ray_in_lanes};
pub use mesh::{MeshAccel, MeshShape, on_triangle, triangle_hit};
pub use plane::{Disk, Plane};
pub use sphere::Sphere;
pub use sphere_packet::{RaysSphereHits, SPHERE_LANES, SpherePacket};

use alhazen_math::{Bounds3, Ray, Transform, Vec2, Vec3};

/// A ray–surface intersection.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceHit {
    /// Ray parameter.
    pub t: f64,
    /// Point.
    pub p: Vec3,
    /// Geometric normal, unit, pointing out of the solid (or to the shape's front side).
    pub n: Vec3,
    /// Shading normal, unit, on the same side as `n`.
    pub ns: Vec3,
    /// Texture coordinates.
    pub uv: Vec2,
    /// Material slot of a mesh triangle (0 elsewhere).
    pub slot: u32,
    /// `∂p/∂u` and `∂p/∂v` of the texture parametrisation, for bump mapping and anisotropic
    /// lobes: filled in by [`crate::World`] for objects whose material has a bump map or
    /// anisotropic microfacets (zero otherwise, and for shapes without them).
    pub dpduv: [Vec3; 2],
    /// The vertex colour of a mesh with colours, interpolated; white elsewhere.
    pub color: Vec3,
}

impl SurfaceHit {
    /// A hit whose shading normal is its geometric normal.
    pub fn flat(t: f64, p: Vec3, n: Vec3, uv: Vec2) -> Self {
        Self { t, p, n, ns: n, uv, slot: 0, dpduv: [Vec3::ZERO; 2], color: Vec3::ONE }
    }
}

/// The result of the hit search: the ray parameter and a shape-specific tag (a triangle
/// index, a face, a part) from which [`Shape::surface`] computes the full [`SurfaceHit`] for
/// the winning hit only.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Candidate {
    /// Ray parameter.
    pub t: f64,
    /// Shape-specific tag.
    pub aux: u32,
    /// Barycentric coordinates `(b1, b2)` of a triangle hit (unused by other shapes).
    pub bary: [f64; 2],
}

/// A point where a line enters or leaves a closed shape; used by CSG.
#[derive(Clone, Copy, Debug)]
pub struct Crossing {
    /// The surface point (its `t` may be negative: crossings cover the whole line).
    pub hit: SurfaceHit,
    /// True where the line goes from outside to inside.
    pub entering: bool,
}

/// Every kind of shape.
#[derive(Clone, Debug)]
pub enum Shape {
    /// Sphere.
    Sphere(Sphere),
    /// Finite cylinder.
    Cylinder(Cylinder),
    /// Finite cone.
    Cone(Cone),
    /// Disk.
    Disk(Disk),
    /// Infinite plane.
    Plane(Plane),
    /// Axis-aligned box.
    Box(AaBox),
    /// Triangle mesh.
    Mesh(MeshShape),
    /// Constructive solid geometry.
    Csg(Box<Csg>),
}

impl Shape {
    /// The nearest hit with `0 < t < t_max`, without surface details.
    #[inline]
    pub fn hit(&self, ray: &Ray, t_max: f64) -> Option<Candidate> {
        match self {
            Shape::Sphere(s) => s.hit(ray, t_max),
            Shape::Cylinder(s) => s.hit(ray, t_max),
            Shape::Cone(s) => s.hit(ray, t_max),
            Shape::Disk(s) => s.hit(ray, t_max),
            Shape::Plane(s) => s.hit(ray, t_max),
            Shape::Box(s) => s.hit(ray, t_max),
            Shape::Mesh(s) => s.hit(ray, t_max),
            Shape::Csg(s) => s.hit(ray, t_max),
        }
    }

    /// True when the shape lies on `ray` in `(0, t_max)`: `self.hit(ray, t_max).is_some()`,
    /// found without looking for the nearest hit where that is cheaper (meshes).
    pub fn blocks(&self, ray: &Ray, t_max: f64) -> bool {
        match self {
            Shape::Mesh(s) => s.blocks(ray, t_max),
            _ => self.hit(ray, t_max).is_some(),
        }
    }

    /// The surface at a hit found by [`Shape::hit`] on the same ray.
    pub fn surface(&self, ray: &Ray, c: Candidate) -> SurfaceHit {
        self.surface_with(ray, c, true)
    }

    /// [`Shape::surface`], leaving a sphere's, a cylinder's or a cone's texture coordinates at
    /// zero unless `uv` (their angles cost inverse trigonometric functions).
    #[inline]
    pub fn surface_with(&self, ray: &Ray, c: Candidate, uv: bool) -> SurfaceHit {
        match self {
            Shape::Sphere(s) if !uv => s.hit_at_without_uv(ray, c.t),
            Shape::Sphere(s) => s.hit_at(ray, c.t),
            Shape::Cylinder(s) => s.surface_with(ray, c, uv),
            Shape::Cone(s) => s.surface_with(ray, c, uv),
            Shape::Disk(s) => s.surface(ray, c),
            Shape::Plane(s) => s.surface(ray, c),
            Shape::Box(s) => s.surface(ray, c),
            Shape::Mesh(s) => s.surface_at(c),
            Shape::Csg(s) => s.surface(ray, c),
        }
    }

    /// The nearest hit with `0 < t < t_max`, with its surface.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<SurfaceHit> {
        self.hit(ray, t_max).map(|c| self.surface(ray, c))
    }

    /// Object-space bounds (infinite for a plane).
    pub fn bounds(&self) -> Bounds3 {
        match self {
            Shape::Sphere(s) => s.bounds(),
            Shape::Cylinder(s) => s.bounds(),
            Shape::Cone(s) => s.bounds(),
            Shape::Disk(s) => s.bounds(),
            Shape::Plane(_) => Bounds3 { min: Vec3::NEG_INFINITY, max: Vec3::INFINITY },
            Shape::Box(s) => s.bounds(),
            Shape::Mesh(s) => s.bounds(),
            Shape::Csg(s) => s.bounds(),
        }
    }

    /// All crossings of the whole line through `ray`, sorted by `t`; only for closed shapes
    /// (open ones contribute nothing).
    pub fn crossings(&self, ray: &Ray, out: &mut Vec<Crossing>) {
        let start = out.len();
        match self {
            Shape::Sphere(s) => s.crossings(ray, out),
            Shape::Cylinder(s) => s.crossings(ray, out),
            Shape::Cone(s) => s.crossings(ray, out),
            Shape::Box(s) => s.crossings(ray, out),
            Shape::Mesh(s) => s.crossings(ray, out),
            Shape::Csg(s) => s.crossings(ray, out),
            Shape::Disk(_) | Shape::Plane(_) => {}
        }
        out[start..].sort_by(|a, b| a.hit.t.total_cmp(&b.hit.t));
    }
}

/// Crossings of a convex closed shape from its hits along the whole line: alternately entering
/// and leaving in order of `t`.
pub(crate) fn convex_crossings(mut hits: Vec<SurfaceHit>, out: &mut Vec<Crossing>) {
    hits.sort_by(|a, b| a.t.total_cmp(&b.t));
    if hits.len() >= 2 {
        let (first, last) = (hits[0], hits[hits.len() - 1]);
        out.push(Crossing { hit: first, entering: true });
        out.push(Crossing { hit: last, entering: false });
    }
}

/// A shape with an optional object→world transform.
#[derive(Clone, Debug)]
pub struct Placed {
    /// The shape in object space.
    pub shape: Shape,
    /// Object → world; `None` for the identity (saves two matrix products per ray).
    pub to_world: Option<Transform>,
    /// Compute texture coordinates at hits (a sphere's cost two inverse trigonometric functions;
    /// the world turns them off for objects whose materials use none).
    pub uv: bool,
}

impl Shape {
    /// `∂p/∂u`, `∂p/∂v` at the hit of `ray` found by `c` (object space); zero where the shape
    /// has none. Only what they need of the surface is computed: a sphere's normal (not its
    /// texture coordinates' inverse trigonometry), nothing of a mesh's or a plane's.
    pub fn tangents(&self, ray: &Ray, c: Candidate) -> [Vec3; 2] {
        match self {
            Shape::Sphere(s) => s.tangents(&s.hit_at_without_uv(ray, c.t)),
            Shape::Plane(p) => p.tangents(),
            Shape::Mesh(m) => m.tangents(c.aux as usize),
            _ => [Vec3::ZERO; 2],
        }
    }
}

impl Placed {
    /// `∂p/∂u`, `∂p/∂v` in world space at the hit of `ray` found by `c`.
    pub fn tangents(&self, ray: &Ray, c: Candidate) -> [Vec3; 2] {
        match &self.to_world {
            None => self.shape.tangents(ray, c),
            Some(tf) => self.shape.tangents(&tf.inverse_ray(ray), c).map(|d| tf.vector(d)),
        }
    }

    /// Places `shape` with `to_world` (dropped when it is the identity).
    pub fn new(shape: Shape, to_world: Transform) -> Self {
        Self { shape, to_world: (!to_world.is_identity()).then_some(to_world), uv: true }
    }

    /// The nearest hit of a world-space ray, without surface details.
    #[inline]
    pub fn hit(&self, ray: &Ray, t_max: f64) -> Option<Candidate> {
        match &self.to_world {
            None => self.shape.hit(ray, t_max),
            Some(tf) => self.shape.hit(&tf.inverse_ray(ray), t_max),
        }
    }

    /// [`Shape::blocks`] in world space.
    pub fn blocks(&self, ray: &Ray, t_max: f64) -> bool {
        match &self.to_world {
            None => self.shape.blocks(ray, t_max),
            Some(tf) => self.shape.blocks(&tf.inverse_ray(ray), t_max),
        }
    }

    /// The world-space surface at a hit found by [`Placed::hit`].
    pub fn surface(&self, ray: &Ray, c: Candidate) -> SurfaceHit {
        match &self.to_world {
            None => self.shape.surface_with(ray, c, self.uv),
            Some(tf) => to_world(tf, self.shape.surface_with(&tf.inverse_ray(ray), c, self.uv)),
        }
    }

    /// The nearest hit in world space.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<SurfaceHit> {
        self.hit(ray, t_max).map(|c| self.surface(ray, c))
    }

    /// True when `p` lies inside the closed shape: the line through `p` along a fixed direction
    /// (no axis, so that boxes are not met edge-on) is inside after its last crossing behind `p`.
    /// Points within rounding of the surface may go either way; open shapes contain nothing.
    pub fn contains(&self, p: Vec3) -> bool {
        let dir = Vec3::new(0.5773, 0.6201, 0.5312).normalize();
        let mut all = Vec::new();
        self.crossings(&Ray::new(p, dir), &mut all);
        all.iter().take_while(|c| c.hit.t < 0.0).last().is_some_and(|c| c.entering)
    }

    /// The unit normal of the surface at a point `p` on it (within `tol`), found as the
    /// crossing nearest `p` along a few fixed lines through it; `None` when no crossing is that
    /// near (not on the surface, or an open shape).
    pub fn normal_near(&self, p: Vec3, tol: f64) -> Option<Vec3> {
        let dirs = [Vec3::new(0.5773, 0.6201, 0.5312), Vec3::new(-0.7, 0.1, 0.71), Vec3::new(0.2, -0.9, 0.38)];
        let mut all = Vec::new();
        for d in dirs {
            all.clear();
            self.crossings(&Ray::new(p, d.normalize()), &mut all);
            let near = all.iter().min_by(|a, b| a.hit.t.abs().total_cmp(&b.hit.t.abs()));
            if let Some(c) = near.filter(|c| c.hit.t.abs() <= tol) {
                return c.hit.n.try_normalize();
            }
        }
        None
    }

    /// World-space crossings (see [`Shape::crossings`]).
    pub fn crossings(&self, ray: &Ray, out: &mut Vec<Crossing>) {
        match &self.to_world {
            None => self.shape.crossings(ray, out),
            Some(tf) => {
                let start = out.len();
                self.shape.crossings(&tf.inverse_ray(ray), out);
                for c in &mut out[start..] {
                    c.hit = to_world(tf, c.hit);
                }
            }
        }
    }

    /// World-space bounds.
    pub fn bounds(&self) -> Bounds3 {
        let b = self.shape.bounds();
        match &self.to_world {
            None => b,
            Some(_) if !b.is_finite() => b,
            Some(tf) => tf.bounds(&b),
        }
    }
}

#[inline]
fn to_world(tf: &Transform, h: SurfaceHit) -> SurfaceHit {
    let n = tf.normal(h.n).normalize();
    let ns = if h.ns == h.n { n } else { tf.normal(h.ns).normalize() };
    SurfaceHit { p: tf.point(h.p), n, ns, ..h }
}

#[cfg(test)]
mod tests;
