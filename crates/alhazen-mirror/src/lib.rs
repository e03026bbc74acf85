//! `alhazen-mirror`: exact reflexes on spherical and cylindrical mirrors, after G. Glaeser,
//! *Reflections on spheres and cylinders of revolution* (sections 1–3).
//!
//! Given a mirror, an eye `E` and a point `S`, the **reflex** `R[Φ; E](S)` is the point `R` of the
//! mirror where light from `S` reflects into `E` — Alhazen's problem. On a sphere the problem
//! lives in the plane `MES`; on a cylinder of revolution in the normal projection along the axis
//! (§1, Fig. 4). Either way it becomes the reflection on a circle `k`, solved by the quartic of
//! Theorem 1 (equations (5)–(7); module [`circle`]), whose up to four real roots are classified as
//! the visible reflection on the outside, reflections on the inside, or virtual solutions.
//!
//! * The sphere's reflexes of a point are coplanar; when `S` lies on the axis `ME` the
//!   non-trivial ones form a small circle (Theorem 2, [`Reflexes::circle`]).
//! * On a cylinder the height follows from (10): the unfolded light path is straight.
//! * [`Sphere::is_forbidden`] / [`Cylinder::is_forbidden`] answer the §2.2 question "can the
//!   reflex be seen at all?".
//! * [`batch`] solves many points against one mirror and eye (structure of arrays), for the
//!   visible reflex only.
//! * [`caustic`] gives the catacaustic (12), (13), its rational form (15), kernel points (16),
//!   double points (17) and the catacaustic surfaces as triangle meshes.
//! * [`anamorph`] prints cylinder anamorphoses (§2.4, Theorem 4).
//! * [`overlap`] finds where a polygon's reflex folds over (§4, Theorems 6–9: the projecting
//!   lines of its plane, from the quartic (22) or the linear (27)) and splits it there.
//!
//! All solutions satisfy the law of reflection to about 1e-13 rad (tests check 1e-12 against a
//! brute-force search), and no input makes the solver panic: degenerate input is a
//! [`MirrorError`].
//!
//! ```
//! use alhazen_mirror::{Site, Sphere};
//! use alhazen_math::Vec3;
//! let ball = Sphere { center: Vec3::ZERO, radius: 1.0 };
//! let eye = Site::At(Vec3::new(0.0, 0.0, 5.0));
//! let light = Site::At(Vec3::new(3.0, 0.0, 4.0));
//! let r = ball.reflexes(eye, light).unwrap();
//! let visible = r.visible().unwrap();
//! assert!((visible.point.length() - 1.0).abs() < 1e-12);
//! // Angle in = angle out.
//! let n = visible.normal;
//! let to_eye = (Vec3::new(0.0, 0.0, 5.0) - visible.point).normalize();
//! let to_light = (Vec3::new(3.0, 0.0, 4.0) - visible.point).normalize();
//! assert!((to_eye.dot(n) - to_light.dot(n)).abs() < 1e-12);
//! ```

pub mod anamorph;
pub mod batch;
pub mod caustic;
pub mod circle;
pub mod figures;
pub mod overlap;
mod poly;
mod solids;

pub use circle::ReflexKind;
pub use solids::{Circle, Cylinder, Sphere};

use alhazen_math::Vec3;

/// A point that may lie at infinity (a parallel projection's eye, the sun).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Site {
    /// A finite point.
    At(Vec3),
    /// The point at infinity in this direction (need not be unit).
    Toward(Vec3),
}

/// Why a reflex problem has no well-defined answer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MirrorError {
    /// The radius is zero, negative or not finite.
    InvalidRadius,
    /// An input coordinate or direction is NaN or infinite, or a direction is zero.
    NonFinite,
    /// The eye lies on the mirror surface.
    EyeOnMirror,
    /// The eye lies on the axis of symmetry (sphere centre, cylinder axis): every normal passes
    /// through it.
    EyeOnAxis,
    /// The point coincides with the eye.
    SourceAtEye,
    /// The point lies on the mirror surface.
    SourceOnMirror,
    /// A cylinder seen exactly along its axis, or eye and point both at infinity on a cylinder
    /// (the height of the reflex is not determined).
    Indeterminate,
}

impl std::fmt::Display for MirrorError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::InvalidRadius => "the mirror's radius must be positive and finite",
            Self::NonFinite => "a coordinate is not finite, or a direction is zero",
            Self::EyeOnMirror => "the eye lies on the mirror",
            Self::EyeOnAxis => "the eye lies on the mirror's centre or axis",
            Self::SourceAtEye => "the point coincides with the eye",
            Self::SourceOnMirror => "the point lies on the mirror",
            Self::Indeterminate => "the reflex is not determined (view along the axis, or both points at infinity)",
        })
    }
}

impl std::error::Error for MirrorError {}

/// One reflex: the mirror point, its outward unit normal and how it reflects.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reflex {
    /// The point on the mirror.
    pub point: Vec3,
    /// Outward unit normal there.
    pub normal: Vec3,
    /// Outside (visible), inside or virtual.
    pub kind: ReflexKind,
}

/// The small circle of reflexes of a point on the sphere's axis `ME` (Theorem 2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReflexCircle {
    /// Centre (on the axis).
    pub center: Vec3,
    /// Unit axis direction (from the sphere's centre towards the eye).
    pub axis: Vec3,
    /// Radius.
    pub radius: f64,
    /// How its points reflect.
    pub kind: ReflexKind,
}

/// All reflexes of a point: up to four isolated ones (outside first, then inside, then
/// virtual), and for a sphere possibly a circle of them.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Reflexes {
    items: [Option<Reflex>; 4],
    len: usize,
    /// Theorem 2's small circle, when the point lies on the axis `ME` of a sphere.
    pub circle: Option<ReflexCircle>,
}

impl From<Option<Reflex>> for Reflexes {
    /// The set holding at most this one reflex (e.g. what a `visible_reflex` found).
    fn from(r: Option<Reflex>) -> Self {
        let mut out = Reflexes::default();
        if let Some(r) = r {
            out.push(r);
        }
        out
    }
}

impl Reflexes {
    fn push(&mut self, r: Reflex) {
        if self.len < 4 {
            self.items[self.len] = Some(r);
            self.len += 1;
        }
    }

    /// Every isolated solution of the reflection condition.
    pub fn all(&self) -> impl Iterator<Item = &Reflex> {
        self.items[..self.len].iter().flatten()
    }

    /// The visible reflex (reflection on the outside), if the point is not in the forbidden
    /// region.
    pub fn visible(&self) -> Option<&Reflex> {
        self.all().find(|r| r.kind == ReflexKind::Outside)
    }

    /// The solutions of one kind.
    pub fn of_kind(&self, kind: ReflexKind) -> impl Iterator<Item = &Reflex> {
        self.all().filter(move |r| r.kind == kind)
    }
}
