//! The three mirrors: a circle in the plane, a sphere, a cylinder of revolution. Each maps its
//! problem to the canonical circle problem of [`crate::circle`] and back.

use crate::circle::{Canonical, ReflexKind, Site2, angle_diff};
use crate::{MirrorError, Reflex, ReflexCircle, Reflexes, Site};
use alhazen_math::{Vec2, Vec3, orthonormal_basis};

/// A circle in the plane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Circle {
    /// Centre `M`.
    pub center: Vec2,
    /// Radius `r`.
    pub radius: f64,
}

/// A spherical mirror.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Centre `M`.
    pub center: Vec3,
    /// Radius `r`.
    pub radius: f64,
}

/// An infinite cylinder of revolution.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cylinder {
    /// A point on the axis.
    pub center: Vec3,
    /// Axis direction (need not be unit).
    pub axis: Vec3,
    /// Radius `r`.
    pub radius: f64,
}

/// A plane frame `(origin, x̂, ŷ)` in 3D whose `x̂` points to the eye, and the canonical problem.
struct Frame {
    origin: Vec3,
    x: Vec3,
    y: Vec3,
    problem: Canonical,
}

impl Frame {
    fn to_3d(&self, phi: f64) -> (Vec3, Vec3) {
        self.normal_to_3d(Vec2::from_angle(phi))
    }

    /// The mirror point and normal for the canonical unit normal `(cos φ, sin φ)`.
    fn normal_to_3d(&self, n2: Vec2) -> (Vec3, Vec3) {
        let n = self.x * n2.x + self.y * n2.y;
        (self.origin + n * self.problem.r, n)
    }
}

fn check_radius(r: f64) -> Result<(), MirrorError> {
    if r > 0.0 && r.is_finite() { Ok(()) } else { Err(MirrorError::InvalidRadius) }
}

fn finite_site(s: Site) -> Result<Site, MirrorError> {
    match s {
        Site::At(p) if p.is_finite() => Ok(s),
        Site::Toward(d) if d.is_finite() && d.length_squared() > 0.0 => Ok(Site::Toward(d.normalize())),
        _ => Err(MirrorError::NonFinite),
    }
}

/// Builds the canonical problem in the plane through `origin` with eye and source given relative
/// to it (already projected for a cylinder). `None` for `ŷ` means the source is on the axis.
#[inline(always)]
fn frame(
    origin: Vec3,
    r: f64,
    eye: Site,
    source: Site,
    plane_normal: Option<Vec3>,
) -> Result<(Frame, bool), MirrorError> {
    let scale = r.max(1e-300);
    let (x, e_dist) = match eye {
        Site::At(p) => {
            let d = p - origin;
            let e = d.length();
            if e <= 1e-12 * scale {
                return Err(MirrorError::EyeOnAxis);
            }
            if (e - r).abs() <= 1e-12 * scale {
                return Err(MirrorError::EyeOnMirror);
            }
            (d * (1.0 / e), Some(e))
        }
        Site::Toward(d) => (d, None),
    };
    let (rel, rel_len, finite_source) = match source {
        Site::At(p) => {
            if let Site::At(e) = eye {
                let near = 1e-12 * scale.max(e.abs().max_element());
                if (p - e).length_squared() <= near * near {
                    return Err(MirrorError::SourceAtEye);
                }
            }
            let rel = p - origin;
            let rel_len = rel.length();
            if (rel_len - r).abs() <= 1e-12 * scale {
                return Err(MirrorError::SourceOnMirror);
            }
            (rel, rel_len, true)
        }
        Site::Toward(d) => (d, 1.0, false),
    };
    let sx = rel.dot(x);
    let perp = rel - x * sx;
    let perp_len = perp.length();
    let on_axis = perp_len <= 1e-12 * rel_len.max(scale);
    let (y, sy) = match plane_normal {
        // A cylinder's plane is known exactly: ŷ = a × x̂, turned towards the source.
        Some(a) => {
            let y = a.cross(x).normalize();
            let y = if perp.dot(y) < 0.0 { -y } else { y };
            (y, rel.dot(y).max(0.0))
        }
        None if on_axis => (orthonormal_basis(x).0, 0.0),
        // |perp|, not rel·ŷ: the rounding of ŷ along x̂ (ε|rel|/|perp|) times rel's large
        // component along x̂ would cost 10 ulps of the source's distance from the axis.
        None => (perp * (1.0 / perp_len), perp_len),
    };
    let s2 = Vec2::new(sx, if on_axis { 0.0 } else { sy });
    let problem = Canonical {
        r,
        eye: match e_dist {
            Some(e) => Site2::At(Vec2::new(e, 0.0)),
            None => Site2::Toward(Vec2::X),
        },
        w: e_dist.map_or(0.0, |e| 1.0 / e),
        source: if finite_source { Site2::At(s2) } else { Site2::Toward(s2.normalize()) },
    };
    Ok((Frame { origin, x, y, problem }, on_axis))
}

/// True when the segment from the eye to the point meets the disk of radius `r` around the
/// origin, or the point is inside it: the §2.2 forbidden region (no reflection on the outside).
fn forbidden_2d(p: &Canonical) -> bool {
    let r2 = p.r * p.r;
    let (origin, dir, t_end) = match (p.eye, p.source) {
        (_, Site2::Toward(_)) => return false_if_outside_light(p),
        (Site2::At(e), Site2::At(s)) => (e, s - e, 1.0),
        (Site2::Toward(d), Site2::At(s)) => (s, d, f64::INFINITY),
    };
    if let Site2::At(s) = p.source
        && s.length_squared() <= r2
    {
        return true;
    }
    // Does origin + t dir, 0 < t < t_end, pass through the disk?
    let (a, b, c) = (dir.length_squared(), origin.dot(dir), origin.length_squared() - r2);
    let disc = b * b - a * c;
    if disc <= 0.0 {
        return false;
    }
    let (t0, t1) = ((-b - disc.sqrt()) / a, (-b + disc.sqrt()) / a);
    t1 > 0.0 && t0 < t_end
}

/// A point at infinity is seen in the mirror unless it lies straight behind it, i.e. its
/// direction is inside the cone of directions hidden by the mirror from the eye.
fn false_if_outside_light(p: &Canonical) -> bool {
    let Site2::Toward(d) = p.source else { return false };
    match p.eye {
        // Parallel view and light: hidden only when the light comes from exactly behind.
        Site2::Toward(v) => (d + v).length() < 1e-15,
        Site2::At(e) => {
            let to_mirror = -e.normalize();
            let half = (p.r / e.length()).asin();
            d.angle_to(to_mirror).abs() < half
        }
    }
}

fn solve(fr: &Frame, on_axis: bool) -> Reflexes {
    let mut out = Reflexes::default();
    for s in fr.problem.solve().iter() {
        let is_axis_point = angle_diff(s.phi, 0.0) < 1e-9 || angle_diff(s.phi, std::f64::consts::PI) < 1e-9;
        if on_axis && !is_axis_point {
            // Theorem 2: the solutions at ±φ sweep a small circle about the axis.
            if out.circle.is_none() {
                out.circle = Some(ReflexCircle {
                    center: fr.origin + fr.x * (fr.problem.r * s.phi.cos()),
                    axis: fr.x,
                    radius: fr.problem.r * s.phi.sin().abs(),
                    kind: s.kind,
                });
            }
            continue;
        }
        let (point, normal) = fr.to_3d(s.phi);
        out.push(Reflex { point, normal, kind: s.kind });
    }
    out
}

/// A site projected along a cylinder's axis, with its height (or, at infinity, its slope).
type Projected = (Site, f64);

/// The height of a cylinder's reflex above the projection plane, from (10): the unfolded path
/// `E → R → S` is straight. For a site at infinity the "height" slot holds its slope.
fn height(
    foot: Vec3,
    kind: ReflexKind,
    (pe, he): (Site, f64),
    (ps, hs): (Site, f64),
) -> Result<Option<f64>, MirrorError> {
    let dist = |site: Site| match site {
        Site::At(p) => Some((p - foot).length()),
        Site::Toward(_) => None,
    };
    let virtual_sign = if kind == ReflexKind::Virtual { -1.0 } else { 1.0 };
    Ok(match (dist(pe), dist(ps)) {
        (Some(le), Some(ls)) => {
            let denom = le + virtual_sign * ls;
            (denom.abs() >= 1e-300).then(|| he + (hs - he) * le / denom)
        }
        // Eye at infinity: reflection keeps the axial slope `he` of the eye ray, so the light
        // climbs by `he` per unit of horizontal length from S to R.
        (None, Some(ls)) => Some(hs + virtual_sign * he * ls),
        // Light at infinity with slope `hs` towards it: symmetric.
        (Some(le), None) => Some(he + virtual_sign * hs * le),
        (None, None) => return Err(MirrorError::Indeterminate),
    })
}

impl Circle {
    /// All reflexes of `source` seen from `eye`, in the plane (z = 0 of the results).
    pub fn reflexes(&self, eye: Site, source: Site) -> Result<Reflexes, MirrorError> {
        self.as_sphere().reflexes(eye, source)
    }

    fn as_sphere(&self) -> Sphere {
        Sphere { center: self.center.extend(0.0), radius: self.radius }
    }
}

impl Sphere {
    #[inline(always)]
    fn frame(&self, eye: Site, source: Site) -> Result<(Frame, bool), MirrorError> {
        check_radius(self.radius)?;
        if !self.center.is_finite() {
            return Err(MirrorError::NonFinite);
        }
        frame(self.center, self.radius, finite_site(eye)?, finite_site(source)?, None)
    }

    /// Checks the mirror and a finite eye: errors as [`Sphere::reflexes`] would give them.
    pub(crate) fn check_eye(&self, eye: Vec3) -> Result<(), MirrorError> {
        self.frame(Site::At(eye), Site::Toward(Vec3::ONE)).map(|_| ())
    }

    /// All reflexes of `source` seen from `eye`: solved in the plane `MES` (§1).
    pub fn reflexes(&self, eye: Site, source: Site) -> Result<Reflexes, MirrorError> {
        let (fr, on_axis) = self.frame(eye, source)?;
        Ok(solve(&fr, on_axis))
    }

    /// Only the visible reflex (the bracketed search of [`crate::circle`], no quartic).
    pub fn visible_reflex(&self, eye: Site, source: Site) -> Result<Option<Reflex>, MirrorError> {
        let (fr, _) = self.frame(eye, source)?;
        Ok(fr.problem.visible().map(|n| {
            let (point, normal) = fr.normal_to_3d(n);
            Reflex { point, normal, kind: ReflexKind::Outside }
        }))
    }

    /// True when `source` has no visible reflex from `eye` (inside the sphere, or hidden behind
    /// it as seen from the eye).
    pub fn is_forbidden(&self, eye: Site, source: Site) -> Result<bool, MirrorError> {
        let (fr, _) = self.frame(eye, source)?;
        Ok(forbidden_2d(&fr.problem))
    }
}

impl Cylinder {
    /// Unit axis, or an error.
    fn unit_axis(&self) -> Result<Vec3, MirrorError> {
        check_radius(self.radius)?;
        if !self.center.is_finite() || !self.axis.is_finite() {
            return Err(MirrorError::NonFinite);
        }
        self.axis.try_normalize().ok_or(MirrorError::NonFinite)
    }

    /// Projects along the axis onto the plane through `center`; returns the site and its height.
    fn project(&self, a: Vec3, s: Site) -> Result<Projected, MirrorError> {
        Ok(match finite_site(s)? {
            Site::At(p) => {
                let h = (p - self.center).dot(a);
                (Site::At(p - a * h), h)
            }
            Site::Toward(d) => {
                let flat = d - a * d.dot(a);
                let len = flat.length();
                if len <= 1e-12 {
                    return Err(MirrorError::Indeterminate);
                }
                // The slope (height per unit of horizontal length) travels in the height slot.
                (Site::Toward(flat / len), d.dot(a) / len)
            }
        })
    }

    fn frame(&self, eye: Site, source: Site) -> Result<(Frame, Vec3, Projected, Projected), MirrorError> {
        let a = self.unit_axis()?;
        let pe = self.project(a, eye)?;
        let ps = self.project(a, source)?;
        let (fr, _) = frame(self.center, self.radius, pe.0, ps.0, Some(a))?;
        Ok((fr, a, pe, ps))
    }

    /// Checks the mirror and a finite eye: errors as [`Cylinder::reflexes`] would give them.
    pub(crate) fn check_eye(&self, eye: Vec3) -> Result<(), MirrorError> {
        let a = self.unit_axis()?;
        let (pe, _) = self.project(a, Site::At(eye))?;
        frame(self.center, self.radius, pe, Site::Toward(a.any_orthonormal_vector()), Some(a)).map(|_| ())
    }

    /// All reflexes of `source` seen from `eye`: solved in the projection along the axis, the
    /// height from (10).
    pub fn reflexes(&self, eye: Site, source: Site) -> Result<Reflexes, MirrorError> {
        let (fr, a, pe, ps) = self.frame(eye, source)?;
        let mut out = Reflexes::default();
        for s in fr.problem.solve().iter() {
            let (foot, normal) = fr.to_3d(s.phi);
            if let Some(h) = height(foot, s.kind, pe, ps)? {
                out.push(Reflex { point: foot + a * h, normal, kind: s.kind });
            }
        }
        Ok(out)
    }

    /// Only the visible reflex (the bracketed search of [`crate::circle`], no quartic).
    pub fn visible_reflex(&self, eye: Site, source: Site) -> Result<Option<Reflex>, MirrorError> {
        let (fr, a, pe, ps) = self.frame(eye, source)?;
        let Some(n) = fr.problem.visible() else { return Ok(None) };
        let (foot, normal) = fr.normal_to_3d(n);
        Ok(height(foot, ReflexKind::Outside, pe, ps)?.map(|h| Reflex {
            point: foot + a * h,
            normal,
            kind: ReflexKind::Outside,
        }))
    }

    /// True when `source` has no visible reflex from `eye`.
    pub fn is_forbidden(&self, eye: Site, source: Site) -> Result<bool, MirrorError> {
        let (fr, ..) = self.frame(eye, source)?;
        Ok(forbidden_2d(&fr.problem))
    }
}
