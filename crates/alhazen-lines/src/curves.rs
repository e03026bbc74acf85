//! The lines of a scene in space, exactly: edges of polyhedra and meshes (boundary edges,
//! feature edges by dihedral angle, silhouettes seen from the eye), the contours of spheres,
//! cylinders and cones (the course's and Glaeser's §1: a sphere's contour from `E` is a small
//! circle; a cylinder's and a cone's are generating lines through the tangents from the eye's
//! projection), and the rims of cylinders, cones and disks.

use crate::view::View;
use alhazen_math::{Transform, Vec3, orthonormal_basis};
use alhazen_raster::pipeline::geometry::world_triangles;
use alhazen_scene::{Scene, Shape};
use std::collections::HashMap;
use std::f64::consts::TAU;

/// A curve in space: a segment or an arc of a circle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Curve {
    /// The segment from `a` to `b`.
    Segment {
        /// Start.
        a: Vec3,
        /// End.
        b: Vec3,
    },
    /// `center + radius (u cos θ + v sin θ)` for θ from `start` to `end` (`u`, `v` orthonormal).
    Arc {
        /// Centre.
        center: Vec3,
        /// First axis of the circle's plane (unit).
        u: Vec3,
        /// Second axis (unit, ⟂ `u`).
        v: Vec3,
        /// Radius.
        radius: f64,
        /// Start angle.
        start: f64,
        /// End angle.
        end: f64,
    },
    /// `center + u cos θ + v sin θ` for θ from `start` to `end` (`u`, `v` conjugate
    /// semi-diameters): a cylinder's plane section.
    Ellipse {
        /// Centre.
        center: Vec3,
        /// Semi-diameter at θ = 0.
        u: Vec3,
        /// Conjugate semi-diameter at θ = π/2.
        v: Vec3,
        /// Start angle.
        start: f64,
        /// End angle.
        end: f64,
    },
}

impl Curve {
    /// The point at parameter `s ∈ [0, 1]`.
    pub fn point(&self, s: f64) -> Vec3 {
        match *self {
            Curve::Segment { a, b } => a + (b - a) * s,
            Curve::Arc { center, u, v, radius, start, end } => {
                let th = start + (end - start) * s;
                center + (u * th.cos() + v * th.sin()) * radius
            }
            Curve::Ellipse { center, u, v, start, end } => {
                let th = start + (end - start) * s;
                center + u * th.cos() + v * th.sin()
            }
        }
    }

    /// The part of the curve from parameter `s0` to `s1`, parametrised over `[0, 1]` again.
    pub fn sub(&self, s0: f64, s1: f64) -> Curve {
        let angle = |start: f64, end: f64| (start + (end - start) * s0, start + (end - start) * s1);
        match *self {
            Curve::Segment { .. } => Curve::Segment { a: self.point(s0), b: self.point(s1) },
            Curve::Arc { center, u, v, radius, start, end } => {
                let (start, end) = angle(start, end);
                Curve::Arc { center, u, v, radius, start, end }
            }
            Curve::Ellipse { center, u, v, start, end } => {
                let (start, end) = angle(start, end);
                Curve::Ellipse { center, u, v, start, end }
            }
        }
    }

    /// A full circle.
    pub fn circle(center: Vec3, axis: Vec3, radius: f64) -> Curve {
        let (u, v) = orthonormal_basis(axis.normalize());
        Curve::Arc { center, u, v, radius, start: 0.0, end: TAU }
    }

    /// Parameters of the chords that approximate the curve on paper within `tol_mm`.
    pub fn knots(&self, view: &View, tol_mm: f64) -> Vec<f64> {
        let knots = match *self {
            Curve::Segment { .. } => vec![0.0, 1.0],
            Curve::Arc { radius, start, end, .. } => round_knots(view, tol_mm, self, radius, end - start),
            Curve::Ellipse { u, v, start, end, .. } => {
                round_knots(view, tol_mm, self, u.length().max(v.length()), end - start)
            }
        };
        if view.is_projective() { knots } else { follow_film(self, &knots, view, tol_mm / view.mm_per_px) }
    }
}

/// Deepest halving of a chord whose image strays from the curve's (2⁻³⁰ of the curve).
const FILM_DEPTH: u32 = 30;

/// `knots` refined for a film on which the curve's image is not its chords' (a panorama's):
/// each chord halved until its image's midpoint is within `tol_px` of the curve's image there,
/// and, where the film wraps around (the panorama's seam behind the eye), until the chord across
/// it is as short as the depth allows (its image spans the film: [`crate::visibility::chords`]
/// leaves it out).
fn follow_film(curve: &Curve, knots: &[f64], view: &View, tol_px: f64) -> Vec<f64> {
    let half_width = view.film.0 as f64 / 2.0;
    let film = |s: f64| view.to_film(curve.point(s));
    let mut out = vec![knots[0]];
    let mut stack = vec![];
    for w in knots.windows(2) {
        stack.push((w[1], w[0], 0));
        while let Some((s1, s0, depth)) = stack.pop() {
            let (a, b) = (curve.point(s0), curve.point(s1));
            let mid = 0.5 * (s0 + s1);
            let split = depth < FILM_DEPTH && view.in_front(a) && view.in_front(b) && {
                let (fa, fb) = (film(s0), film(s1));
                (fa.x - fb.x).abs() > half_width || (film(mid) - (fa + fb) * 0.5).length() > tol_px
            };
            if split {
                // Right half below the left: the left comes off the stack first.
                stack.push((s1, mid, depth + 1));
                stack.push((mid, s0, depth + 1));
            } else {
                out.push(s1);
            }
        }
    }
    out
}

/// Knots of an arc of radius (at most) `radius` spanning `angle`, chords within `tol_mm`: the
/// chord error `r(1 − cos(Δ/2))` on paper, with the projection's scale taken at the largest of
/// eight points of the arc (not at its centre: a horizon's centre is under the eye).
fn round_knots(view: &View, tol_mm: f64, curve: &Curve, radius: f64, angle: f64) -> Vec<f64> {
    let px_per_unit = (0..8).map(|k| view_px_per_unit(view, curve.point(k as f64 / 8.0))).fold(0.0, f64::max);
    let mm = radius * view.mm_per_px * px_per_unit;
    let step = if mm > 0.0 { (8.0 * tol_mm / mm).sqrt().min(0.5) } else { 0.5 };
    let n = ((angle.abs() / step).ceil() as usize).clamp(8, 20_000);
    (0..=n).map(|k| k as f64 / n as f64).collect()
}

/// Film pixels per world unit near `p` (the projection's local scale).
fn view_px_per_unit(view: &View, p: Vec3) -> f64 {
    let (ray, _) = view.eye_ray(p);
    let (u, _) = orthonormal_basis(ray.dir);
    let h = 1e-3 * view.scale;
    let (a, b) = (p - u * h, p + u * h);
    if !view.in_front(a) || !view.in_front(b) {
        return 1.0;
    }
    (view.to_film(b) - view.to_film(a)).length() / (2.0 * h)
}

/// What a line is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LineKind {
    /// Edge between faces meeting at an angle, or a face's free boundary.
    Edge,
    /// Silhouette of a mesh or contour of a curved surface.
    Contour,
    /// Rim of a cylinder, cone or disk.
    Rim,
    /// The horizon of an infinite plane: its line at infinity (a circle far away).
    Horizon,
    /// Where the object meets `other`.
    Intersection {
        /// The other object.
        other: u32,
    },
}

impl SceneLine {
    /// How close to the line's own objects a visibility ray may pass: chords of intersection
    /// curves run just inside both objects (1e-3 of the distance is ample and far below any
    /// real occlusion by them).
    pub fn leeway(&self) -> (Vec<u32>, f64) {
        match self.kind {
            LineKind::Intersection { other } => (vec![self.object, other], 1e-3),
            _ => (vec![], 0.0),
        }
    }
}

/// A line of the scene: a curve on an object.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneLine {
    /// The curve.
    pub curve: Curve,
    /// Index of the scene object it lies on.
    pub object: u32,
    /// What it is.
    pub kind: LineKind,
}

/// How lines are picked.
#[derive(Clone, Copy, Debug)]
pub struct EdgeOptions {
    /// Mesh edges whose faces meet at more than this angle (radians) are drawn.
    pub feature_angle: f64,
}

/// Corners of the world triangles of every box and mesh (`None` for other shapes), computed
/// once per drawing for the lines, the intersections, the plane mirrors and the silhouettes
/// seen in mirrors.
pub fn polyhedra(scene: &Scene) -> Vec<Option<Vec<[Vec3; 3]>>> {
    let corners = |o| world_triangles(scene, o).map(|t| t.iter().map(|t| t.map(|v| v.p)).collect());
    scene
        .objects
        .iter()
        .map(|o| if matches!(o.shape, Shape::Box { .. } | Shape::Mesh { .. }) { corners(o) } else { None })
        .collect()
}

/// Every line of the scene for this view (boxes and meshes from `polyhedra`); the count of
/// objects drawn from their tessellation because their transform distorts a round shape, and of
/// objects with no lines (CSG).
pub fn scene_lines(
    scene: &Scene,
    polyhedra: &[Option<Vec<[Vec3; 3]>>],
    view: &View,
    opts: &EdgeOptions,
) -> (Vec<SceneLine>, usize, usize) {
    let (mut lines, mut tessellated, mut skipped) = (vec![], 0, 0);
    for (i, o) in scene.objects.iter().enumerate() {
        let object = i as u32;
        let exact = similarity(&o.transform).and_then(|s| round_lines(&o.shape, &o.transform, s, view, object));
        match (exact, &o.shape) {
            (Some(l), _) => lines.extend(l),
            (None, Shape::Plane { point, normal }) => {
                lines.extend(horizon(o.transform.point(*point), o.transform.normal(*normal), view, object))
            }
            (None, Shape::Csg { .. }) => skipped += 1,
            (None, shape) => {
                if matches!(
                    shape,
                    Shape::Sphere { .. } | Shape::Cylinder { .. } | Shape::Cone { .. } | Shape::Disk { .. }
                ) {
                    tessellated += 1;
                }
                match &polyhedra[i] {
                    Some(tris) => lines.extend(mesh_lines(tris, view, opts, object)),
                    None => {
                        // A round object under a distorting transform: its tessellation.
                        if let Some(tris) = world_triangles(scene, o) {
                            let corners: Vec<[Vec3; 3]> = tris.iter().map(|t| t.map(|v| v.p)).collect();
                            lines.extend(mesh_lines(&corners, view, opts, object));
                        }
                    }
                }
            }
        }
    }
    (lines, tessellated, skipped)
}

/// Seen from an eye, an infinite plane ends at its horizon, the image of its line at infinity:
/// drawn as a circle in the plane a million scene sizes away (the image is off the true line by
/// less than 1e-6 of the eye's height over that distance). In parallel views it lies off the
/// paper, but mirrors still show it.
fn horizon(point: Vec3, normal: Vec3, view: &View, object: u32) -> Option<SceneLine> {
    let n = normal.try_normalize()?;
    let center = view.eye.unwrap_or(point);
    let foot = center - n * (center - point).dot(n);
    let curve = Curve::circle(foot, n, 1e6 * view.scale);
    Some(SceneLine { curve, object, kind: LineKind::Horizon })
}

/// The uniform scale of a similarity transform (rotation, uniform scale, translation): the
/// transforms under which spheres, cylinders and cones keep their exact form.
pub(crate) fn similarity(t: &Transform) -> Option<f64> {
    let (x, y, z) = (t.vector(Vec3::X), t.vector(Vec3::Y), t.vector(Vec3::Z));
    let s = x.length();
    let tol = 1e-9 * s;
    let ok = (y.length() - s).abs() < tol
        && (z.length() - s).abs() < tol
        && x.dot(y).abs() < tol * s
        && y.dot(z).abs() < tol * s
        && x.dot(z).abs() < tol * s;
    ok.then_some(s)
}

/// Exact lines of spheres, cylinders, cones and disks; `None` for other shapes.
fn round_lines(shape: &Shape, t: &Transform, scale: f64, view: &View, object: u32) -> Option<Vec<SceneLine>> {
    let line = |curve, kind| SceneLine { curve, object, kind };
    let mut out = vec![];
    match *shape {
        Shape::Sphere { center, radius } => {
            if let Some(c) = sphere_contour(t.point(center), radius * scale, view) {
                out.push(line(c, LineKind::Contour));
            }
        }
        Shape::Cylinder { base, top, radius, .. } => {
            let (b, tp, r) = (t.point(base), t.point(top), radius * scale);
            let axis = tp - b;
            out.push(line(Curve::circle(b, axis, r), LineKind::Rim));
            out.push(line(Curve::circle(tp, axis, r), LineKind::Rim));
            for p in cylinder_contour_feet(b, axis, r, view) {
                out.push(line(Curve::Segment { a: p, b: p + axis }, LineKind::Contour));
            }
        }
        Shape::Cone { base, apex, radius, .. } => {
            let (b, a, r) = (t.point(base), t.point(apex), radius * scale);
            out.push(line(Curve::circle(b, a - b, r), LineKind::Rim));
            for p in cone_contour_feet(b, a, r, view) {
                out.push(line(Curve::Segment { a: p, b: a }, LineKind::Contour));
            }
        }
        Shape::Disk { center, normal, radius } => {
            out.push(line(Curve::circle(t.point(center), t.normal(normal), radius * scale), LineKind::Rim));
        }
        _ => return None,
    }
    Some(out)
}

/// The contour of a sphere: from an eye at distance `d > r`, the small circle of the touching
/// cone (centre `M + (E − M) r²/d²`, radius `r √(1 − r²/d²)`); for parallel views the great
/// circle across the viewing direction.
fn sphere_contour(m: Vec3, r: f64, view: &View) -> Option<Curve> {
    match view.eye {
        Some(e) => {
            let d = e - m;
            let dd = d.length_squared();
            (dd > r * r * (1.0 + 1e-12)).then(|| Curve::circle(m + d * (r * r / dd), d, r * (1.0 - r * r / dd).sqrt()))
        }
        None => Some(Curve::circle(m, view.dir, r)),
    }
}

/// Feet on the base circle of the tangents from the eye's projection along the axis (the two
/// contour generators of a cylinder).
fn cylinder_contour_feet(base: Vec3, axis: Vec3, r: f64, view: &View) -> Vec<Vec3> {
    let a = axis.normalize();
    let toward = match view.eye {
        Some(e) => {
            let q = (e - base) - a * (e - base).dot(a);
            return tangent_feet(base, a, r, q);
        }
        None => a.cross(view.dir),
    };
    let Some(n) = toward.try_normalize() else { return vec![] };
    vec![base + n * r, base - n * r]
}

/// Points of contact of the tangents from `q` (relative to `center`, in the circle's plane ⟂
/// `a`) to the circle of radius `r`.
fn tangent_feet(center: Vec3, a: Vec3, r: f64, q: Vec3) -> Vec<Vec3> {
    let d = q.length();
    if d <= r * (1.0 + 1e-12) {
        return vec![];
    }
    let x = q / d;
    let y = a.cross(x);
    let (c, s) = (r / d, (1.0 - (r / d) * (r / d)).sqrt());
    vec![center + (x * c + y * s) * r, center + (x * c - y * s) * r]
}

/// A cone's contour generators touch the base circle where the tangents from `P` do, `P` the
/// point where the line from the apex through the eye (or along the view) meets the base plane.
fn cone_contour_feet(base: Vec3, apex: Vec3, r: f64, view: &View) -> Vec<Vec3> {
    let a = (apex - base).normalize();
    let through = match view.eye {
        Some(e) => e - apex,
        None => view.dir,
    };
    let den = through.dot(a);
    if den.abs() < 1e-12 * through.length() {
        // The line is parallel to the base plane: the feet are across its direction.
        let Some(x) = (through - a * den).try_normalize() else { return vec![] };
        let y = a.cross(x);
        return vec![base + y * r, base - y * r];
    }
    let p = apex + through * ((base - apex).dot(a) / den);
    tangent_feet(base, a, r, p - base)
}

/// An undirected edge by the bits of its corners.
type EdgeKey = ([u64; 3], [u64; 3]);

/// An edge of a triangle soup with the unit normals of the faces that share it.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshEdge {
    /// One end.
    pub a: Vec3,
    /// The other end.
    pub b: Vec3,
    /// Normals of the faces on it (one for a boundary edge).
    pub normals: Vec<Vec3>,
}

/// The edges of a triangle soup whose shared corners are equal, in first-seen order.
pub fn mesh_edges(tris: &[[Vec3; 3]]) -> Vec<MeshEdge> {
    let key = |p: Vec3| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
    let mut index: HashMap<EdgeKey, usize> = HashMap::new();
    let mut edges: Vec<MeshEdge> = vec![];
    for t in tris {
        let n = (t[1] - t[0]).cross(t[2] - t[0]);
        let Some(n) = n.try_normalize() else { continue };
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let (ka, kb) = (key(a), key(b));
            let id = if ka < kb { (ka, kb) } else { (kb, ka) };
            let i = *index.entry(id).or_insert_with(|| {
                edges.push(MeshEdge { a, b, normals: vec![] });
                edges.len() - 1
            });
            edges[i].normals.push(n);
        }
    }
    edges
}

/// Whether an edge is always drawn (a boundary, a crease beyond `cos_feature`, non-manifold).
pub fn is_feature(e: &MeshEdge, cos_feature: f64) -> bool {
    match e.normals.as_slice() {
        [n1, n2] => n1.dot(*n2) < cos_feature,
        _ => true,
    }
}

/// Whether a smooth edge is on the silhouette seen from `toward(mid)` (a direction from the
/// edge's midpoint to the viewer): one face turned to it, the other away.
pub fn is_silhouette(e: &MeshEdge, toward: impl Fn(Vec3) -> Option<Vec3>) -> bool {
    let Some(to) = toward((e.a + e.b) * 0.5) else { return false };
    match e.normals.as_slice() {
        [n1, n2] => (n1.dot(to) > 0.0) != (n2.dot(to) > 0.0),
        _ => false,
    }
}

/// Boundary, feature and silhouette edges of a triangle soup whose shared corners are equal.
pub fn mesh_lines(tris: &[[Vec3; 3]], view: &View, opts: &EdgeOptions, object: u32) -> Vec<SceneLine> {
    let cos_feature = opts.feature_angle.cos();
    let to_eye = |mid: Vec3| {
        Some(match view.eye {
            Some(e) => e - mid,
            None => -view.dir,
        })
    };
    mesh_edges(tris)
        .into_iter()
        .filter_map(|e| {
            let kind = if is_feature(&e, cos_feature) {
                LineKind::Edge
            } else if is_silhouette(&e, to_eye) {
                LineKind::Contour
            } else {
                return None;
            };
            Some(SceneLine { curve: Curve::Segment { a: e.a, b: e.b }, object, kind })
        })
        .collect()
}
