//! Lines reflected in spherical and cylindrical mirrors, exactly (Glaeser §3–4): every point of
//! a line is reflected by the mirror library's solver of Alhazen's problem, with knots spaced
//! as the paper's Fig. 16 recommends — equal steps of the reflex's polar angle on the circle `k`
//! of the two-dimensional problem, carried back to the line along the reflected rays — then
//! refined until the drawn curve is within tolerance. A reflected point is drawn where the eye
//! sees the mirror point and the reflected ray reaches the line unblocked; the ends of the
//! forbidden region (§2.2) and of blocked stretches are found by bisection.

use crate::curves::{Curve, SceneLine};
use crate::view::{Leeway, View, clear_path};
use alhazen_math::{Ray, Vec2, Vec3};
use alhazen_mirror::{Cylinder, Site, Sphere};
use alhazen_render::World;
use alhazen_scene::{Scene, Shape};

/// A mirror of the scene.
#[derive(Clone, Debug)]
pub enum Mirror {
    /// A plane mirror (Glaeser's Fig. 3): a disk or a flat mesh such as a `rectangle`.
    Plane {
        /// A point of the plane.
        point: Vec3,
        /// Unit normal on the mirroring side.
        normal: Vec3,
        /// Its outline.
        extent: Extent,
        /// Scene object index.
        object: u32,
    },
    /// A spherical mirror.
    Sphere {
        /// The sphere.
        sphere: Sphere,
        /// Scene object index.
        object: u32,
    },
    /// A finite cylindrical mirror from `center` along `axis` (its length).
    Cylinder {
        /// The infinite cylinder (axis not unit: its length is the mirror's height).
        cylinder: Cylinder,
        /// Scene object index.
        object: u32,
    },
}

/// The outline of a plane mirror.
#[derive(Clone, Debug)]
pub enum Extent {
    /// A disk of this radius about the plane's point.
    Disk(f64),
    /// Triangles (in the plane).
    Triangles(std::sync::Arc<Vec<[Vec3; 3]>>),
}

impl Extent {
    fn contains(&self, center: Vec3, normal: Vec3, p: Vec3) -> bool {
        match self {
            Extent::Disk(r) => (p - center).length_squared() <= r * r,
            Extent::Triangles(tris) => tris.iter().any(|t| {
                let side = |a: Vec3, b: Vec3| (b - a).cross(p - a).dot(normal) >= 0.0;
                side(t[0], t[1]) && side(t[1], t[2]) && side(t[2], t[0])
            }),
        }
    }
}

/// A flat mesh as a plane mirror: all its triangles in one plane, wound alike.
fn flat_mirror(tris: &[[Vec3; 3]], object: u32) -> Option<Mirror> {
    let first = tris.first()?;
    let normal = (first[1] - first[0]).cross(first[2] - first[0]).try_normalize()?;
    let point = first[0];
    let size = tris.iter().flatten().map(|p| (*p - point).length()).fold(0.0, f64::max);
    let flat = tris.iter().flatten().all(|p| (*p - point).dot(normal).abs() <= 1e-9 * size.max(1.0));
    let alike = tris.iter().all(|t| (t[1] - t[0]).cross(t[2] - t[0]).dot(normal) > 0.0);
    (flat && alike).then(|| Mirror::Plane {
        point,
        normal,
        extent: Extent::Triangles(std::sync::Arc::new(tris.to_vec())),
        object,
    })
}

/// The spheres, cylinders and plane mirrors (disks, flat meshes) of the scene with a mirror
/// reflectance; round ones placed by a similarity.
pub fn mirrors(scene: &Scene, polyhedra: &[Option<Vec<[Vec3; 3]>>]) -> Vec<Mirror> {
    let mut out = vec![];
    for (i, o) in scene.objects.iter().enumerate() {
        let m = &scene.materials[o.material as usize];
        if m.mirror.max_element() <= 0.0 {
            continue;
        }
        let t = &o.transform;
        let object = i as u32;
        if let Shape::Mesh { .. } = o.shape {
            out.extend(polyhedra[i].as_deref().and_then(|t| flat_mirror(t, object)));
            continue;
        }
        if let Shape::Disk { center, normal, radius } = o.shape {
            let (c, n) = (t.point(center), t.normal(normal).normalize());
            // A disk stays round only under a similarity; its rim's radius is measured.
            let (u, _) = alhazen_math::orthonormal_basis(normal);
            let r = (t.point(center + u * radius) - c).length();
            out.push(Mirror::Plane { point: c, normal: n, extent: Extent::Disk(r), object });
            continue;
        }
        let Some(scale) = crate::curves::similarity(t) else { continue };
        match o.shape {
            Shape::Sphere { center, radius } => {
                out.push(Mirror::Sphere { sphere: Sphere { center: t.point(center), radius: radius * scale }, object })
            }
            Shape::Cylinder { base, top, radius, .. } => {
                let (b, tp) = (t.point(base), t.point(top));
                out.push(Mirror::Cylinder {
                    cylinder: Cylinder { center: b, axis: tp - b, radius: radius * scale },
                    object,
                })
            }
            _ => {}
        }
    }
    out
}

/// What the eye sees of one point of a line in the mirror.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Seen {
    /// No reflex (forbidden region, off the finite mirror, behind the eye).
    Nothing,
    /// The reflex, seen.
    Visible(Vec3),
    /// The reflex exists but the mirror point is hidden or the reflected ray is blocked.
    Hidden(Vec3),
}

impl Seen {
    fn class(&self) -> u8 {
        match self {
            Seen::Nothing => 0,
            Seen::Visible(_) => 1,
            Seen::Hidden(_) => 2,
        }
    }

    fn point(&self) -> Option<Vec3> {
        match *self {
            Seen::Visible(p) | Seen::Hidden(p) => Some(p),
            Seen::Nothing => None,
        }
    }
}

impl Mirror {
    /// Scene object index.
    pub fn object(&self) -> u32 {
        match *self {
            Mirror::Sphere { object, .. } | Mirror::Cylinder { object, .. } | Mirror::Plane { object, .. } => object,
        }
    }

    /// A point inside the mirror (the sphere's centre, the cylinder's axis midpoint).
    pub fn center(&self) -> Vec3 {
        match self {
            Mirror::Sphere { sphere, .. } => sphere.center,
            Mirror::Cylinder { cylinder, .. } => cylinder.center + cylinder.axis * 0.5,
            Mirror::Plane { point, .. } => *point,
        }
    }

    /// The visible reflex of `s` on the mirror seen from `viewer`.
    pub fn reflex(&self, viewer: Site, s: Vec3) -> Option<Vec3> {
        match self {
            Mirror::Plane { point, normal, extent, .. } => {
                let ds = (s - *point).dot(*normal);
                let r = match viewer {
                    Site::At(e) => {
                        let de = (e - *point).dot(*normal);
                        if ds <= 0.0 || de <= 0.0 {
                            return None;
                        }
                        // The eye's ray to the mirror image of s meets the plane at R.
                        let image = s - *normal * (2.0 * ds);
                        e + (image - e) * (de / (de + ds))
                    }
                    Site::Toward(d) => {
                        let dn = d.dot(*normal);
                        if ds <= 0.0 || dn <= 0.0 {
                            return None;
                        }
                        s + (d - *normal * (2.0 * dn)) * (ds / dn)
                    }
                };
                extent.contains(*point, *normal, r).then_some(r)
            }
            Mirror::Sphere { sphere, .. } => sphere.visible_reflex(viewer, Site::At(s)).ok().flatten().map(|r| r.point),
            Mirror::Cylinder { cylinder, .. } => {
                let r = cylinder.visible_reflex(viewer, Site::At(s)).ok().flatten()?.point;
                let h = (r - cylinder.center).dot(cylinder.axis) / cylinder.axis.length_squared();
                (0.0..=1.0).contains(&h).then_some(r)
            }
        }
    }

    /// The visible reflexes of many points at once: spheres and cylinders seen from a finite
    /// eye go through the batch kernel of `alhazen-mirror` (33 M/s on one core).
    pub fn reflexes(&self, viewer: Site, pts: &[Vec3]) -> Vec<Option<Vec3>> {
        let eye = match viewer {
            Site::At(e) => e,
            Site::Toward(_) => return pts.iter().map(|p| self.reflex(viewer, *p)).collect(),
        };
        let (x, y, z): (Vec<f64>, Vec<f64>, Vec<f64>) =
            (pts.iter().map(|p| p.x).collect(), pts.iter().map(|p| p.y).collect(), pts.iter().map(|p| p.z).collect());
        let soa = alhazen_mirror::batch::PointsSoA { x: &x, y: &y, z: &z };
        let mut out = alhazen_mirror::batch::ReflexesSoA::default();
        let ok = match self {
            Mirror::Sphere { sphere, .. } => sphere.visible_reflexes_batch(eye, soa, &mut out),
            Mirror::Cylinder { cylinder, .. } => cylinder.visible_reflexes_batch(eye, soa, &mut out),
            Mirror::Plane { .. } => return pts.iter().map(|p| self.reflex(viewer, *p)).collect(),
        };
        if ok.is_err() {
            return vec![None; pts.len()];
        }
        (0..pts.len())
            .map(|i| {
                let r = Vec3::new(out.x[i], out.y[i], out.z[i]);
                let on_mirror = match self {
                    Mirror::Cylinder { cylinder, .. } => {
                        let h = (r - cylinder.center).dot(cylinder.axis) / cylinder.axis.length_squared();
                        (0.0..=1.0).contains(&h)
                    }
                    _ => true,
                };
                (out.visible[i] && on_mirror).then_some(r)
            })
            .collect()
    }

    /// What the eye sees of `s` in the mirror; the reflected ray may pass near the objects `s`
    /// lies on as `own` allows.
    fn seen(&self, view: &View, world: &World, s: Vec3, own: &Leeway) -> Seen {
        let Some(r) = self.reflex(view.viewer(), s) else { return Seen::Nothing };
        if !view.in_front(r) {
            return Seen::Nothing;
        }
        if view.sees(world, r) && reaches(world, r, s, own) { Seen::Visible(r) } else { Seen::Hidden(r) }
    }

    /// The two-dimensional problem of a point: its coordinates in the plane `MES` (sphere) or
    /// the normal projection along the axis (cylinder), `x̂` towards the eye, with the eye's own
    /// (finite `e`, or `None` at infinity).
    fn plane(&self, view: &View) -> Option<Plane> {
        Plane::new(self, view.eye, view.dir)
    }
}

impl Plane {
    /// The frame of `mirror` for an eye at `eye` (or at infinity opposite `dir`).
    fn new(mirror: &Mirror, eye: Option<Vec3>, dir: Vec3) -> Option<Plane> {
        let (m, r, axis) = match *mirror {
            Mirror::Sphere { sphere, .. } => (sphere.center, sphere.radius, None),
            Mirror::Cylinder { cylinder, .. } => (cylinder.center, cylinder.radius, Some(cylinder.axis.normalize())),
            // The reflex of a line in a plane is a line: uniform knots do.
            Mirror::Plane { .. } => return None,
        };
        let flat = |v: Vec3| axis.map_or(v, |a| v - a * v.dot(a));
        let (x, e) = match eye {
            Some(eye) => {
                let d = flat(eye - m);
                let e = d.length();
                (d / e, Some(e))
            }
            None => (flat(-dir).normalize(), None),
        };
        x.is_finite().then(|| Plane { m, r, x, y: axis.map(|a| a.cross(x)), e })
    }
}

/// A mirror's two-dimensional frame.
struct Plane {
    m: Vec3,
    r: f64,
    x: Vec3,
    /// `ŷ` for a cylinder; a sphere's plane turns with each point (`y ≥ 0`).
    y: Option<Vec3>,
    e: Option<f64>,
}

impl Plane {
    fn coords(&self, p: Vec3) -> Vec2 {
        let rel = p - self.m;
        let x = rel.dot(self.x);
        match self.y {
            Some(y) => Vec2::new(x, rel.dot(y)),
            None => Vec2::new(x, (rel - self.x * x).length()),
        }
    }

    /// Parameters along `a → b` whose reflexes divide the arc between the ends' reflexes into
    /// `n` equal angles (Fig. 16): the eye's ray to the circle point at each angle, reflected,
    /// meets the line's image `b₀` (a line for a cylinder, a hyperbola for a sphere).
    fn knots(&self, ra: Vec3, rb: Vec3, a: Vec3, b: Vec3, n: usize) -> Vec<f64> {
        let (pa, pb) = (self.coords(ra), self.coords(rb));
        let (fa, fb) = (pa.y.atan2(pa.x), pb.y.atan2(pb.x));
        let (sa, sb) = (self.coords(a), self.coords(b));
        let rel = (a - self.m, b - a);
        let mut out = vec![0.0, 1.0];
        for k in 1..n {
            let phi = fa + (fb - fa) * k as f64 / n as f64;
            let nrm = Vec2::new(phi.cos(), phi.sin());
            let r2 = nrm * self.r;
            let inc = match self.e {
                Some(e) => r2 - Vec2::new(e, 0.0),
                None => Vec2::new(-1.0, 0.0),
            };
            let d = inc - nrm * (2.0 * inc.dot(nrm));
            let guess = k as f64 / n as f64;
            let roots = match self.y {
                // Cylinder: d × (S(λ) − R) = 0 is linear in λ.
                Some(_) => {
                    let f = |s: Vec2| d.x * (s.y - r2.y) - d.y * (s.x - r2.x);
                    let (f0, f1) = (f(sa), f(sb));
                    if (f1 - f0).abs() > 0.0 { vec![f0 / (f0 - f1)] } else { vec![] }
                }
                // Sphere: d.x·y = c(λ) with y = √(|S − M|² − x²), squared: a quadratic.
                None => {
                    let (x0, x1) = (sa.x, sb.x - sa.x);
                    let (q0, q1, q2) = (rel.0.length_squared(), 2.0 * rel.0.dot(rel.1), rel.1.length_squared());
                    let (c0, c1) = (d.y * (x0 - r2.x) + d.x * r2.y, d.y * x1);
                    let dx2 = d.x * d.x;
                    let qa = dx2 * (q2 - x1 * x1) - c1 * c1;
                    let qb = dx2 * (q1 - 2.0 * x0 * x1) - 2.0 * c0 * c1;
                    let qc = dx2 * (q0 - x0 * x0) - c0 * c0;
                    quadratic(qa, qb, qc).into_iter().filter(|l| (c0 + c1 * l) * d.x >= 0.0).collect()
                }
            };
            let on_ray = |l: f64| {
                let s = self.coords(a + (b - a) * l);
                (s - r2).dot(d) > 0.0
            };
            if let Some(l) = roots
                .into_iter()
                .filter(|l| (0.0..=1.0).contains(l) && on_ray(*l))
                .min_by(|p, q| (p - guess).abs().total_cmp(&(q - guess).abs()))
            {
                out.push(l);
            }
        }
        out.sort_by(f64::total_cmp);
        out.dedup_by(|p, q| (*p - *q).abs() < 1e-12);
        out
    }
}

/// Real roots of `a λ² + b λ + c`.
fn quadratic(a: f64, b: f64, c: f64) -> Vec<f64> {
    if a.abs() <= 1e-14 * (b.abs() + c.abs()) {
        return if b != 0.0 { vec![-c / b] } else { vec![] };
    }
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        return vec![];
    }
    let q = -0.5 * (b + disc.sqrt().copysign(b));
    let mut v = vec![q / a];
    if q != 0.0 {
        v.push(c / q);
    }
    v
}

/// True when the reflected ray from the mirror point `r` reaches `s` unblocked (but for what
/// `own` allows near `s`).
fn reaches(world: &World, r: Vec3, s: Vec3, own: &Leeway) -> bool {
    let d = s - r;
    let dist = d.length();
    if dist <= 0.0 {
        return false;
    }
    let dir = d / dist;
    let start = 1e-6 * dist;
    clear_path(world, Ray::new(r + dir * start, dir), dist - start, own)
}

/// How finely reflected curves are followed.
#[derive(Clone, Copy, Debug)]
pub struct ReflectOptions {
    /// Largest distance on the film (pixels) between the drawn chord and the true reflex curve.
    pub tol_px: f64,
    /// Knots of the paper's distribution per line before refinement.
    pub knots: usize,
}

/// The visible reflexes of `line` in `mirror`, as polylines of world points on the mirror.
pub fn reflect_line(
    mirror: &Mirror,
    line: &SceneLine,
    view: &View,
    world: &World,
    opts: &ReflectOptions,
) -> Vec<Vec<Vec3>> {
    // Contours seen from the eye are not contours seen in the mirror: curved surfaces get
    // their reflex contours instead (crate::contour).
    if line.object == mirror.object() || line.kind == crate::curves::LineKind::Contour {
        return vec![];
    }
    let curve = line.curve;
    let knots = match (curve, mirror.plane(view)) {
        (Curve::Segment { a, b }, Some(plane)) => {
            match (mirror.reflex(view.viewer(), a), mirror.reflex(view.viewer(), b)) {
                (Some(ra), Some(rb)) => plane.knots(ra, rb, a, b, opts.knots),
                _ => uniform(opts.knots),
            }
        }
        _ => uniform(opts.knots * 4),
    };
    let (own, near) = line.leeway();
    reflect_path(mirror, |s| curve.point(s), &knots, &Leeway { objects: &own, near }, view, world, opts.tol_px)
}

/// The visible reflexes of the path `s ↦ point(s)`, `s ∈ [0, 1]`, starting from `knots`
/// (sorted, from 0 to 1); `own`: the objects the path lies on and how near to it their hits
/// are ignored.
pub fn reflect_path(
    mirror: &Mirror,
    point: impl Fn(f64) -> Vec3,
    knots: &[f64],
    own: &Leeway,
    view: &View,
    world: &World,
    tol_px: f64,
) -> Vec<Vec<Vec3>> {
    let seen = |s: f64| mirror.seen(view, world, point(s), own);
    let states: Vec<(f64, Seen)> = knots.iter().map(|&s| (s, seen(s))).collect();
    let Some(&first) = states.first() else { return vec![] };
    let mut pts = vec![first];
    for w in states.windows(2) {
        refine(w[0], w[1], 0, &seen, view, tol_px, &mut pts);
    }
    runs(&pts)
}

/// The polyline through `pts` as a path over `[0, 1]` (equal parameter per segment).
pub fn polyline_path(pts: &[Vec3]) -> impl Fn(f64) -> Vec3 + '_ {
    move |s: f64| {
        let n = pts.len() - 1;
        let x = (s * n as f64).clamp(0.0, n as f64);
        let i = (x.floor() as usize).min(n.saturating_sub(1));
        pts[i] + (pts[(i + 1).min(n)] - pts[i]) * (x - i as f64)
    }
}

pub(crate) fn uniform(n: usize) -> Vec<f64> {
    (0..=n).map(|k| k as f64 / n as f64).collect()
}

/// Deviation refinement stops at this depth, locating a change of what is seen at this one.
const FLAT_DEPTH: u32 = 12;
const EDGE_DEPTH: u32 = 26;

/// Adds the points after `a` up to `b`, halving where the chord strays from the curve on the
/// film or where what is seen changes.
fn refine(
    a: (f64, Seen),
    b: (f64, Seen),
    depth: u32,
    seen: &impl Fn(f64) -> Seen,
    view: &View,
    tol: f64,
    out: &mut Vec<(f64, Seen)>,
) {
    let sm = 0.5 * (a.0 + b.0);
    let changes = a.1.class() != b.1.class();
    if depth >= EDGE_DEPTH || (!changes && depth >= FLAT_DEPTH) {
        out.push(b);
        return;
    }
    let m = (sm, seen(sm));
    let bent = match (a.1.point(), m.1.point(), b.1.point()) {
        (Some(p), Some(q), Some(r)) => {
            let (p, q, r) = (view.to_film(p), view.to_film(q), view.to_film(r));
            (q - (p + r) * 0.5).length() > tol
        }
        _ => false,
    };
    if !changes && m.1.class() == a.1.class() && !bent {
        out.push(b);
        return;
    }
    refine(a, m, depth + 1, seen, view, tol, out);
    refine(m, b, depth + 1, seen, view, tol, out);
}

/// Runs of consecutive visible points.
fn runs(pts: &[(f64, Seen)]) -> Vec<Vec<Vec3>> {
    let mut out = vec![];
    let mut cur: Vec<Vec3> = vec![];
    for (_, s) in pts {
        if let Seen::Visible(p) = s {
            cur.push(*p);
        } else if !cur.is_empty() {
            out.push(std::mem::take(&mut cur));
        }
    }
    if cur.len() > 1 {
        out.push(cur);
    }
    out.retain(|r| r.len() > 1);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Fig. 16: the knots' reflexes divide the arc between the ends' reflexes into equal polar
    /// angles about the axis ME (sphere) or in the projection along the axis (cylinder).
    #[test]
    fn knots_give_equal_steps_of_the_reflex_angle() {
        let eye = Vec3::new(0.3, 0.8, 6.0);
        let (a, b) = (Vec3::new(-2.5, 0.4, 1.0), Vec3::new(2.0, -0.3, 1.8));
        let mirrors = [
            Mirror::Sphere { sphere: Sphere { center: Vec3::ZERO, radius: 1.0 }, object: 0 },
            Mirror::Cylinder {
                cylinder: Cylinder { center: Vec3::new(0.0, -5.0, 0.0), axis: Vec3::Y * 10.0, radius: 1.0 },
                object: 0,
            },
        ];
        for mirror in mirrors {
            let plane = Plane::new(&mirror, Some(eye), Vec3::NEG_Z).unwrap();
            let reflex = |p: Vec3| mirror.reflex(Site::At(eye), p).unwrap();
            let knots = plane.knots(reflex(a), reflex(b), a, b, 8);
            assert_eq!(knots.len(), 9, "{mirror:?}");
            let angle = |l: f64| {
                let c = plane.coords(reflex(a + (b - a) * l));
                c.y.atan2(c.x)
            };
            let steps: Vec<f64> = knots.windows(2).map(|w| angle(w[1]) - angle(w[0])).collect();
            for s in &steps {
                assert!((s - steps[0]).abs() < 1e-9, "{mirror:?}: {steps:?}");
            }
        }
    }

    #[test]
    fn quadratic_roots_are_accurate() {
        let r = quadratic(1.0, -3.0, 2.0);
        assert!(r.iter().any(|x| (x - 1.0).abs() < 1e-15) && r.iter().any(|x| (x - 2.0).abs() < 1e-15));
        assert!(quadratic(1.0, 0.0, 1.0).is_empty());
    }
}
