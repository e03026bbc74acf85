//! Specular connections through curved mirrors: light that reaches a non-specular point `x`
//! after one reflection on a sphere, cylinder or plane mirror, found exactly by solving
//! Alhazen's problem with `x` as the eye and the light as the source (G. Glaeser, *Reflections
//! on spheres and cylinders of revolution*, §1: the reflexes `R[Φ; x](S)`, all real roots of the
//! quartic of Theorem 1; a source at infinity as in (7)), each weighted by the **generalised
//! geometry term** — the ray-tube divergence through the curved mirror — derived in
//! `docs/specular-connections.md`.
//!
//! For a point source `y` the term is `G = dω_x / dA⊥_y`: the solid angle of directions at `x`
//! per unit cross-section of the reflected pencil at `y` (for a plane mirror `1/(t₁ + t₂)²`).
//! For a source at infinity it is `dω_x / dω_out`: solid angle at `x` per solid angle of the
//! reflected directions. Both follow from first-order ray differentials (Igehy 1999) through
//! the mirror's shape operator (sphere `I/r`, cylinder the projection across the axis over `r`,
//! plane 0), and by the invariance of étendue they are also the source's solid angle per unit
//! area at `x`, so `E⊥(x) = I·F·G` for a point light of intensity `I`.

use alhazen_math::{Transform, Vec3, orthonormal_basis};
use alhazen_mirror::{ReflexKind, Reflexes, Site};

/// A mirror's surface in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MirrorShape {
    /// A whole sphere.
    Sphere {
        /// Centre.
        center: Vec3,
        /// Radius.
        radius: f64,
    },
    /// The side of a finite cylinder of revolution.
    Cylinder {
        /// Centre of the bottom.
        base: Vec3,
        /// Unit axis from the bottom to the top.
        axis: Vec3,
        /// Length along the axis.
        height: f64,
        /// Radius.
        radius: f64,
        /// Closed by caps: nothing outside reaches the inside of its wall.
        closed: bool,
    },
    /// A flat disk (disk objects, cylinder caps).
    Disk {
        /// Centre.
        center: Vec3,
        /// Unit normal.
        normal: Vec3,
        /// Radius.
        radius: f64,
    },
    /// An infinite plane.
    Plane {
        /// A point on it.
        point: Vec3,
        /// Unit normal.
        normal: Vec3,
    },
}

/// A light source as the mirror solver sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Source {
    /// A point.
    At(Vec3),
    /// The point at infinity in this unit direction (from the scene towards the light).
    Toward(Vec3),
}

/// One light path `x → m → source` with a single mirror reflection.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MirrorPath {
    /// The mirror point `m`.
    pub point: Vec3,
    /// Unit normal at `m`, on the side facing `x` (and the source).
    pub normal: Vec3,
    /// Unit direction from `x` to `m`.
    pub to_mirror: Vec3,
    /// `|m − x|`.
    pub dist_to_mirror: f64,
    /// Unit direction from `m` to the source.
    pub to_source: Vec3,
    /// `|source − m|`; infinite for a source at infinity.
    pub dist_to_source: f64,
    /// The generalised geometry term (see the module documentation).
    pub geometry: f64,
}

impl MirrorShape {
    /// The mirror surfaces of a scene shape placed by `t`: a sphere, a cylinder's side (and its
    /// caps), a disk or a plane; empty for other shapes and for spheres, cylinders and disks
    /// under transforms that are not similarities (they would be ellipsoids).
    pub fn pieces(shape: &alhazen_scene::Shape, t: &Transform) -> Vec<MirrorShape> {
        use alhazen_scene::Shape;
        let s = t.similarity_scale();
        match (shape, s) {
            (Shape::Sphere { center, radius }, Some(s)) => {
                vec![MirrorShape::Sphere { center: t.point(*center), radius: radius * s }]
            }
            (Shape::Cylinder { base, top, radius, capped }, Some(s)) => {
                let (b, e) = (t.point(*base), t.point(*top));
                let Some(axis) = (e - b).try_normalize() else { return Vec::new() };
                let radius = radius * s;
                let height = (e - b).length();
                let mut v = vec![MirrorShape::Cylinder { base: b, axis, height, radius, closed: *capped }];
                if *capped {
                    v.push(MirrorShape::Disk { center: b, normal: -axis, radius });
                    v.push(MirrorShape::Disk { center: e, normal: axis, radius });
                }
                v
            }
            (Shape::Disk { center, normal, radius }, Some(s)) => {
                vec![MirrorShape::Disk { center: t.point(*center), normal: t.normal(*normal), radius: radius * s }]
            }
            (Shape::Plane { point, normal }, _) => {
                vec![MirrorShape::Plane { point: t.point(*point), normal: t.normal(*normal) }]
            }
            _ => Vec::new(),
        }
    }

    /// How far `p` is from the surface (to tell a capped cylinder's pieces apart).
    pub fn distance(&self, p: Vec3) -> f64 {
        match *self {
            MirrorShape::Sphere { center, radius } => ((p - center).length() - radius).abs(),
            MirrorShape::Cylinder { base, axis, height, radius, .. } => {
                let h = (p - base).dot(axis);
                let radial = (p - base - axis * h).length();
                (radial - radius).abs() + (-h).max(h - height).max(0.0)
            }
            MirrorShape::Disk { center, normal, radius } => {
                let h = (p - center).dot(normal);
                h.abs() + ((p - center - normal * h).length() - radius).max(0.0)
            }
            MirrorShape::Plane { point, normal } => (p - point).dot(normal).abs(),
        }
    }

    /// A sphere holding the piece — its centre and radius —, or `None` for an unbounded plane.
    pub fn bounding_sphere(&self) -> Option<(Vec3, f64)> {
        Some(match *self {
            MirrorShape::Sphere { center, radius } => (center, radius),
            MirrorShape::Cylinder { base, axis, height, radius, .. } => {
                (base + axis * (0.5 * height), (radius * radius + 0.25 * height * height).sqrt())
            }
            MirrorShape::Disk { center, radius, .. } => (center, radius),
            MirrorShape::Plane { .. } => return None,
        })
    }

    /// False when the whole mirror lies behind the plane through `x` with normal `n` (no light
    /// can come from it to a surface that only reflects).
    pub fn in_front_of(&self, x: Vec3, n: Vec3) -> bool {
        let Some((center, reach)) = self.bounding_sphere() else { return true };
        (center - x).dot(n) > -reach
    }

    /// True when no reflection on the inside can join `p` to the mirror: `p` outside a sphere
    /// or a closed cylinder, or beside an open one (radially outside, between its ends: a
    /// straight leg to the inner wall would have to pass over an end, but both of its ends lie
    /// between them). A point at infinity is beside an open cylinder unless it lies along the axis.
    ///
    /// A point radially outside an open cylinder, a distance `d` beyond one end's plane, sees
    /// the inner wall through that end only within `2r·d/(ρ − r)` of its rim (`ρ` its distance
    /// from the axis: the leg must cross the end's plane inside the rim). Where that band is
    /// thinner than 10⁻⁹ of the height — a floor the cylinder stands on, its plane rounded to
    /// either side — it counts as beside.
    fn outside_only(&self, p: Site) -> bool {
        match (*self, p) {
            (MirrorShape::Sphere { center, radius }, Site::At(p)) => (p - center).length_squared() > radius * radius,
            (MirrorShape::Cylinder { base, axis, height, radius, closed }, Site::At(p)) => {
                let h = (p - base).dot(axis);
                let rho = (p - base - axis * h).length();
                let beyond = (-h).max(h - height).max(0.0);
                let band = 2.0 * radius * beyond / (rho - radius);
                let outside = rho > radius;
                outside && (closed || band <= 1e-9 * height) || closed && !(0.0..=height).contains(&h)
            }
            (MirrorShape::Sphere { .. }, Site::Toward(_)) => true,
            (MirrorShape::Cylinder { closed, .. }, Site::Toward(_)) => closed,
            _ => false,
        }
    }

    /// The outward unit normal at `m` on the surface (a flat piece's own normal).
    fn outward_normal(&self, m: Vec3) -> Vec3 {
        match *self {
            MirrorShape::Sphere { center, .. } => (m - center).normalize(),
            MirrorShape::Cylinder { base, axis, .. } => (m - base - axis * (m - base).dot(axis)).normalize(),
            MirrorShape::Disk { normal, .. } | MirrorShape::Plane { normal, .. } => normal,
        }
    }

    /// The derivative of the outward unit normal along the tangent `v` (the shape operator).
    fn curvature(&self, v: Vec3) -> Vec3 {
        match *self {
            MirrorShape::Sphere { radius, .. } => v / radius,
            MirrorShape::Cylinder { axis, radius, .. } => (v - axis * axis.dot(v)) / radius,
            MirrorShape::Disk { .. } | MirrorShape::Plane { .. } => Vec3::ZERO,
        }
    }

    /// Every light path from `source` to `x` with one reflection on this mirror, each handed to
    /// `found`. Occlusion is not tested: the caller traces both legs.
    pub fn reflections(&self, x: Vec3, source: Source, found: impl FnMut(MirrorPath)) {
        self.reflections_on(x, source, false, found);
    }

    /// [`Self::reflections`] on the front only when `front_only` (a one-sided mirror: the
    /// outside of a sphere or cylinder, the side a disk's or plane's normal faces), whose
    /// back reflects nothing.
    pub fn reflections_on(&self, x: Vec3, source: Source, front_only: bool, mut found: impl FnMut(MirrorPath)) {
        let site = match source {
            Source::At(y) => Site::At(y),
            Source::Toward(d) => Site::Toward(d),
        };
        let mut visit = |m: Vec3, n: Vec3| {
            if let Some(path) = self.contains(m).then(|| self.path(x, m, n, source)).flatten()
                && !(front_only && path.normal.dot(self.outward_normal(m)) < 0.0)
            {
                found(path);
            }
        };
        // Inside reflections need both legs inside: either end beside or outside rules them out.
        let visible_only = front_only || self.outside_only(Site::At(x)) || self.outside_only(site);
        let reflexes = match *self {
            MirrorShape::Sphere { center, radius } if visible_only => {
                let sphere = alhazen_mirror::Sphere { center, radius };
                sphere.visible_reflex(Site::At(x), site).map(Reflexes::from)
            }
            MirrorShape::Sphere { center, radius } => {
                alhazen_mirror::Sphere { center, radius }.reflexes(Site::At(x), site)
            }
            MirrorShape::Cylinder { base, axis, radius, .. } if visible_only => {
                let cylinder = alhazen_mirror::Cylinder { center: base, axis, radius };
                cylinder.visible_reflex(Site::At(x), site).map(Reflexes::from)
            }
            MirrorShape::Cylinder { base, axis, radius, .. } => {
                alhazen_mirror::Cylinder { center: base, axis, radius }.reflexes(Site::At(x), site)
            }
            MirrorShape::Disk { center, normal, .. } | MirrorShape::Plane { point: center, normal } => {
                if let Some(m) = plane_reflex(center, normal, x, source) {
                    visit(m, normal);
                }
                return;
            }
        };
        for reflex in reflexes.iter().flat_map(|r| r.all()).filter(|r| r.kind != ReflexKind::Virtual) {
            visit(reflex.point, reflex.normal);
        }
    }

    /// True when the point of the unbounded surface lies on this finite piece.
    fn contains(&self, m: Vec3) -> bool {
        match *self {
            MirrorShape::Sphere { .. } | MirrorShape::Plane { .. } => true,
            MirrorShape::Cylinder { base, axis, height, .. } => (0.0..=height).contains(&(m - base).dot(axis)),
            MirrorShape::Disk { center, radius, .. } => (m - center).length_squared() <= radius * radius,
        }
    }

    /// The path through `m` (unit normal `n`, either side), when `x` and the source lie strictly
    /// on one side of the tangent plane, with its geometry term.
    fn path(&self, x: Vec3, m: Vec3, n: Vec3, source: Source) -> Option<MirrorPath> {
        let to_x = x - m;
        let (to_source, dist_to_source) = match source {
            Source::At(y) => {
                let d = (y - m).length();
                ((y - m) / d, d)
            }
            Source::Toward(d) => (d, f64::INFINITY),
        };
        let (side_x, side_s) = (to_x.dot(n), to_source.dot(n));
        if (side_x * side_s).partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return None;
        }
        let dist_to_mirror = to_x.length();
        let to_mirror = -to_x / dist_to_mirror;
        let geometry = self.geometry(to_mirror, dist_to_mirror, m, dist_to_source);
        let normal = if side_x > 0.0 { n } else { -n };
        (geometry.is_finite() && geometry > 0.0).then_some(MirrorPath {
            point: m,
            normal,
            to_mirror,
            dist_to_mirror,
            to_source,
            dist_to_source,
            geometry,
        })
    }

    /// The generalised geometry term of the path leaving `x` along unit `d` that meets the
    /// mirror at `m` after `t1` and goes on for `t2` (infinite: a source at infinity). Two
    /// orthonormal direction differentials at `x` are carried to the mirror (Igehy's transfer),
    /// reflected with the derivative of the outward normal, and carried on; the cross-section
    /// they span there is `1/G`.
    pub fn geometry(&self, d: Vec3, t1: f64, m: Vec3, t2: f64) -> f64 {
        let n = self.outward_normal(m);
        let (e1, e2) = orthonormal_basis(d);
        let dn = d.dot(n);
        let r = d - n * (2.0 * dn);
        let reflected = |e: Vec3| {
            let dp = e * t1 - d * (t1 * e.dot(n) / dn);
            let dndp = self.curvature(dp);
            let dr = e - (dndp * dn + n * (e.dot(n) + d.dot(dndp))) * 2.0;
            (dp, dr)
        };
        let ((p1, r1), (p2, r2)) = (reflected(e1), reflected(e2));
        let spread = if t2.is_finite() { (p1 + r1 * t2).cross(p2 + r2 * t2).dot(r) } else { r1.cross(r2).dot(r) };
        1.0 / spread.abs()
    }
}

/// Where light from `source` reflects on the plane through `p` with unit normal `n` into `x`:
/// the straight line from `x` to the source's mirror image, when both lie on the same side.
fn plane_reflex(p: Vec3, n: Vec3, x: Vec3, source: Source) -> Option<Vec3> {
    let hx = (x - p).dot(n);
    let (image, dir) = match source {
        Source::At(y) => {
            let hy = (y - p).dot(n);
            if (hx * hy).partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                return None;
            }
            let image = y - n * (2.0 * hy);
            (Some(image), image - x)
        }
        Source::Toward(d) => {
            if (hx * d.dot(n)).partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                return None;
            }
            (None, d - n * (2.0 * d.dot(n)))
        }
    };
    let along = dir.dot(n);
    if along == 0.0 {
        return None;
    }
    let t = -hx / along;
    let m = x + dir * t;
    let within = match image {
        Some(_) => (0.0..=1.0).contains(&t),
        None => t > 0.0,
    };
    within.then_some(m)
}

#[cfg(test)]
mod tests;
