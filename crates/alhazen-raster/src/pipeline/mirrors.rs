//! Spherical and cylindrical mirrors in the preview by Glaeser's own method (*Reflections on spheres and
//! cylinders of revolution*, §3): every vertex of the scene is mapped to its reflex — the point
//! of the sphere or cylinder where the eye sees it — by the batch solver of `alhazen-mirror`, and each
//! triangle is rasterised as its reflex: the triangle of its corners' reflexes, subdivided where
//! the reflex of an edge's midpoint strays from the chord by more than half a pixel (the
//! paper's adaptive knots; a triangle whose reflex folds over the contour, Theorem 10, keeps
//! splitting and its pieces that still disagree at the finest level are left out). Depth is the
//! length of the reflected path `|E R| + |R P|`, tested in the mirror's own buffer; each pixel is
//! lit at the reflected point as seen from the mirror. Pixels of the mirror that no reflex
//! covers show the sky in the exactly reflected direction. Perspective cameras only (the batch
//! solver's eye is finite).
//!
//! Plane mirrors (flat emitters of `mirror > 0`: rectangles, disks, flat meshes) are drawn as
//! the course draws them: the scene rendered once more through the projection composed with the
//! reflection in the mirror's plane, clipped to the half-space in front of it, and shown on the
//! mirror's pixels.

use super::geometry::{Triangle, Vertex};
use super::raster::{Bary, ScreenTriangle, rasterize};
use super::{Projection, RasterOptions, shade};
use alhazen_math::{Vec2, Vec3, Vec4};
use alhazen_mirror::batch::{PointsSoA, ReflexesSoA};
use alhazen_mirror::overlap::{Plane, split_polygon};
use alhazen_mirror::{Cylinder, Site, Sphere};
use alhazen_scene::{Scene, Shape};
use rayon::prelude::*;

/// Finest subdivision of a triangle's reflex: splits are adaptive, so only pieces along a
/// curving reflex go this deep (an unbounded floor's towards its horizon).
const MAX_LEVEL: u32 = 12;
/// At the finest level a piece whose reflex still strays is drawn when it covers at most this
/// many pixels across, and left out when larger (it folds over the contour).
const FINEST_PX: f64 = 4.0;
/// Largest distance on screen, in pixels, between the reflex of an edge's midpoint and the
/// chord's midpoint before the triangle is split.
const TOLERANCE_PX: f64 = 0.5;
/// Levels a piece whose reflex crosses the eye's plane is split before it is left out.
const ACROSS_EYE_LEVELS: u32 = 6;

/// A curved mirror's surface: a sphere, or the side of a finite cylinder.
#[derive(Clone, Copy, Debug)]
pub enum Curved {
    /// A sphere.
    Sphere(Sphere),
    /// The side of a cylinder from `base` to `base + axis` (its caps are not this mirror).
    Cylinder {
        /// The infinite cylinder.
        cylinder: Cylinder,
        /// Centre of the bottom.
        base: Vec3,
        /// From the bottom's centre to the top's.
        axis: Vec3,
    },
}

/// A spherical or cylindrical mirror of the scene: its object and surface.
#[derive(Clone, Copy, Debug)]
pub struct SphereMirror {
    /// The scene object.
    pub object: u32,
    /// The surface in world space.
    pub surface: Curved,
}

/// The spheres and cylinders of `scene` whose material reflects (`mirror > 0`) under a
/// transform that keeps them what they are (a similarity).
pub fn sphere_mirrors(scene: &Scene) -> Vec<SphereMirror> {
    scene
        .objects
        .iter()
        .enumerate()
        .filter(|(_, o)| scene.materials[o.material as usize].mirror != Vec3::ZERO)
        .filter_map(|(i, o)| {
            let axes = [Vec3::X, Vec3::Y, Vec3::Z].map(|a| o.transform.vector(a));
            let s = axes[0].length();
            let similar = axes.iter().all(|a| (a.length() - s).abs() <= 1e-9 * s)
                && axes[0].dot(axes[1]).abs() + axes[1].dot(axes[2]).abs() + axes[0].dot(axes[2]).abs() <= 1e-9 * s * s;
            if !similar || s <= 0.0 {
                return None;
            }
            let t = &o.transform;
            let surface = match o.shape {
                Shape::Sphere { center, radius } => {
                    Curved::Sphere(Sphere { center: t.point(center), radius: radius * s })
                }
                Shape::Cylinder { base, top, radius, .. } => {
                    let (base, top) = (t.point(base), t.point(top));
                    let cylinder = Cylinder { center: base, axis: top - base, radius: radius * s };
                    Curved::Cylinder { cylinder, base, axis: top - base }
                }
                _ => return None,
            };
            Some(SphereMirror { object: i as u32, surface })
        })
        .collect()
}

impl Curved {
    /// The visible reflex of `p` seen from `eye` on the mirror (on a cylinder's side between
    /// its rims).
    fn reflex(&self, eye: Vec3, p: Vec3) -> Option<Vec3> {
        match self {
            Curved::Sphere(s) => s.visible_reflex(Site::At(eye), Site::At(p)).ok().flatten().map(|r| r.point),
            Curved::Cylinder { cylinder, .. } => {
                let r = cylinder.visible_reflex(Site::At(eye), Site::At(p)).ok().flatten()?.point;
                self.on_side(r).then_some(r)
            }
        }
    }

    /// The offset of `p` from the mirror's axis (sphere: from its centre) and the radius.
    fn radial(&self, p: Vec3) -> (Vec3, f64) {
        match self {
            Curved::Sphere(s) => (p - s.center, s.radius),
            Curved::Cylinder { cylinder, .. } => {
                let a = cylinder.axis.normalize();
                let d = p - cylinder.center;
                (d - a * d.dot(a), cylinder.radius)
            }
        }
    }

    /// Whether `p` lies inside the mirror's solid (a cylinder's between its rims): such points
    /// have no reflex.
    fn inside(&self, p: Vec3) -> bool {
        let (d, r) = self.radial(p);
        d.length_squared() < r * r && self.on_side(p)
    }

    /// Where the segment `a → b`, one end inside the solid and one outside, crosses the
    /// mirror's surface, as a parameter in `[0, 1]`.
    fn crossing(&self, a: Vec3, b: Vec3) -> Option<f64> {
        let ((da, r), (db, _)) = (self.radial(a), self.radial(b));
        // |da + t (db − da)|² = r²: the root in [0, 1].
        let e = db - da;
        let (qa, qb, qc) = (e.length_squared(), 2.0 * da.dot(e), da.length_squared() - r * r);
        let disc = qb * qb - 4.0 * qa * qc;
        if qa <= 0.0 || disc < 0.0 {
            return None;
        }
        let s = disc.sqrt();
        [(-qb - s) / (2.0 * qa), (-qb + s) / (2.0 * qa)].into_iter().find(|t| (0.0..=1.0).contains(t))
    }

    /// A point of the mirror's surface is its own reflex where the eye sees it.
    fn shows_itself(&self, eye: Vec3, q: Vec3) -> bool {
        let (n, _) = self.radial(q);
        n.dot(eye - q) > 0.0 && self.on_side(q)
    }

    /// Whether a point of the infinite cylinder lies between the rims.
    fn on_side(&self, r: Vec3) -> bool {
        match self {
            Curved::Sphere(_) => true,
            Curved::Cylinder { base, axis, .. } => {
                (0.0..=1.0).contains(&((r - *base).dot(*axis) / axis.length_squared()))
            }
        }
    }

    /// The visible reflexes of a batch of points, by the batch solver.
    fn batch(&self, eye: Vec3, points: PointsSoA, out: &mut ReflexesSoA) -> bool {
        let ok = match self {
            Curved::Sphere(s) => s.visible_reflexes_batch(eye, points, out).is_ok(),
            Curved::Cylinder { cylinder, .. } => cylinder.visible_reflexes_batch(eye, points, out).is_ok(),
        };
        if ok && matches!(self, Curved::Cylinder { .. }) {
            for i in 0..out.visible.len() {
                out.visible[i] = out.visible[i] && self.on_side(Vec3::new(out.x[i], out.y[i], out.z[i]));
            }
        }
        ok
    }

    /// Where a ray from `eye` along unit `d` first meets the mirror, and the normal there.
    fn hit(&self, eye: Vec3, d: Vec3) -> Option<(Vec3, Vec3)> {
        match self {
            Curved::Sphere(s) => {
                let oc = eye - s.center;
                let b = oc.dot(d);
                let disc = b * b - (oc.length_squared() - s.radius * s.radius);
                let t = -b - disc.max(0.0).sqrt();
                (disc >= 0.0 && t > 0.0).then(|| (eye + d * t, (eye + d * t - s.center) / s.radius))
            }
            Curved::Cylinder { cylinder, base, axis } => {
                // Components across the axis: |(o + t d)⊥|² = r².
                let a = *axis / axis.length();
                let (o, dp) = (eye - *base - a * (eye - *base).dot(a), d - a * d.dot(a));
                let (qa, qb, qc) =
                    (dp.length_squared(), o.dot(dp), o.length_squared() - cylinder.radius * cylinder.radius);
                let disc = qb * qb - qa * qc;
                if qa == 0.0 || disc < 0.0 {
                    return None;
                }
                let t = (-qb - disc.sqrt()) / qa;
                let p = eye + d * t;
                let foot = *base + a * (p - *base).dot(a);
                (t > 0.0 && self.on_side(p)).then(|| (p, (p - foot) / cylinder.radius))
            }
        }
    }

    /// A point to centre the rings of an unbounded plane on, and the mirror's size.
    fn centre_and_size(&self) -> (Vec3, f64) {
        match self {
            Curved::Sphere(s) => (s.center, s.radius),
            Curved::Cylinder { cylinder, base, axis } => {
                (*base + *axis * 0.5, cylinder.radius.max(axis.length() / 2.0))
            }
        }
    }
}

/// A plane mirror of the scene: its object and its plane `n·x = d` (`n` towards the side it
/// reflects).
#[derive(Clone, Copy, Debug)]
pub struct PlaneMirror {
    /// The scene object.
    pub object: u32,
    /// Unit normal.
    pub normal: Vec3,
    /// `n·x` on the plane.
    pub offset: f64,
}

/// The flat objects of `scene` whose material reflects, from their triangles (all corners on
/// the first triangle's plane).
pub fn plane_mirrors(scene: &Scene, tris: &[Triangle]) -> Vec<PlaneMirror> {
    let mut by_object: std::collections::BTreeMap<u32, Vec<&Triangle>> = Default::default();
    for t in tris.iter().filter(|t| scene.materials[t.material as usize].mirror != Vec3::ZERO) {
        if !matches!(scene.objects[t.object as usize].shape, Shape::Sphere { .. } | Shape::Cylinder { .. }) {
            by_object.entry(t.object).or_default().push(t);
        }
    }
    by_object
        .into_iter()
        .filter_map(|(object, ts)| {
            let [a, b, c] = ts[0].v.map(|v| v.p);
            let normal = (b - a).cross(c - a).try_normalize()?;
            let offset = normal.dot(a);
            let extent = ts.iter().flat_map(|t| t.v.iter()).map(|v| (v.p - a).length()).fold(0.0, f64::max);
            let flat =
                ts.iter().flat_map(|t| t.v.iter()).all(|v| (normal.dot(v.p) - offset).abs() <= 1e-9 * (1.0 + extent));
            flat.then_some(PlaneMirror { object, normal, offset })
        })
        .collect()
}

impl PlaneMirror {
    /// The reflection in the mirror's plane as a matrix.
    pub fn reflection(&self) -> alhazen_math::Mat4 {
        let n = self.normal;
        let col = |i: usize| {
            let e = Vec3::AXES[i];
            (e - n * (2.0 * n.dot(e))).extend(0.0)
        };
        alhazen_math::Mat4::from_cols(col(0), col(1), col(2), (n * (2.0 * self.offset)).extend(1.0))
    }

    /// `proj` seen in the mirror: the projection of reflected points, the eye reflected; `None`
    /// when the eye is behind the mirror (it sees the mirror's back).
    pub fn reflected(&self, proj: &Projection) -> Option<(Projection, Vec4)> {
        let side = self.normal.dot(proj.frame.eye) - self.offset;
        if side <= 0.0 {
            return None;
        }
        let m = self.reflection();
        let f = proj.frame;
        let dir = |v: Vec3| v - self.normal * (2.0 * self.normal.dot(v));
        let frame =
            alhazen_math::viewing::ViewFrame { eye: m.transform_point3(f.eye), u: dir(f.u), v: dir(f.v), w: dir(f.w) };
        let reflected = Projection {
            world_to_clip: proj.world_to_clip * m,
            clip_to_world: m * proj.clip_to_world,
            frame,
            perspective: proj.perspective,
        };
        // Keep what lies strictly in front of the mirror, n·x − d ≥ ε: the mirror itself (and
        // what lies on its plane) would cover its own reflection.
        let eps = 1e-7 * (1.0 + self.offset.abs() + side);
        Some((reflected, self.normal.extend(-self.offset - eps)))
    }
}

/// What a mirror shows, per pixel of the image: `None` off the sphere.
pub struct MirrorImage {
    /// The mirror's object.
    pub object: u32,
    /// The reflected radiance per pixel, rows top to bottom.
    pub color: Vec<Option<Vec3>>,
    /// Reflex triangles rasterised.
    pub drawn: usize,
}

/// False when the mirror lies wholly outside the view volume of `proj`: all eight corners of a
/// cube around its bounding sphere beyond one of the clip planes.
fn in_view(surface: &Curved, proj: &Projection) -> bool {
    let (centre, size) = surface.centre_and_size();
    // `size` is the larger of radius and half height: √2 times it bounds a cylinder.
    let r = size * std::f64::consts::SQRT_2;
    let corners: Vec<Vec4> = (0..8)
        .map(|i| {
            let pick = |bit: u32| if i & bit == 0 { -r } else { r };
            let p = centre + Vec3::new(pick(1), pick(2), pick(4));
            proj.world_to_clip * Vec4::new(p.x, p.y, p.z, 1.0)
        })
        .collect();
    let outside = |f: fn(&Vec4) -> bool| corners.iter().all(f);
    !(outside(|c| c.x > c.w)
        || outside(|c| c.x < -c.w)
        || outside(|c| c.y > c.w)
        || outside(|c| c.y < -c.w)
        || outside(|c| c.z < -c.w)
        || outside(|c| c.w <= 0.0))
}

/// The screen position of world point `p`.
fn to_screen(proj: &Projection, p: Vec3, (w, h): (u32, u32)) -> Vec2 {
    let c = proj.world_to_clip * Vec4::new(p.x, p.y, p.z, 1.0);
    Vec2::new((c.x / c.w + 1.0) * 0.5 * w as f64, (1.0 - c.y / c.w) * 0.5 * h as f64)
}

/// Renders what `mirror` reflects of `tris` as seen through `proj` (perspective) at `w × h`.
pub fn mirror_image(
    scene: &Scene,
    tris: &[Triangle],
    mirror: &SphereMirror,
    proj: &Projection,
    (w, h): (u32, u32),
    opts: &RasterOptions,
    light: &shade::Lighting,
) -> MirrorImage {
    let eye = proj.frame.eye;
    let surface = mirror.surface;
    if !in_view(&surface, proj) {
        // Nothing of the mirror is in this view (a cube face of a panorama looking away).
        return MirrorImage { object: mirror.object, color: vec![None; (w * h) as usize], drawn: 0 };
    }
    // Unbounded planes are re-meshed in rings around the mirror (their large squares would
    // need splitting twenty times over to resolve what lies near it).
    let planes = plane_rings(tris, surface.centre_and_size());
    let all: Vec<&Triangle> = tris.iter().filter(|t| !t.unbounded).chain(planes.iter().map(|p| &p.0)).collect();
    let others: Vec<u32> = (0..all.len() as u32).filter(|&i| all[i as usize].object != mirror.object).collect();
    let reflexes = corner_reflexes(&all, &others, &surface, eye);
    let pieces: Vec<ScreenTriangle> = others
        .par_iter()
        .enumerate()
        .flat_map_iter(|(k, &i)| {
            let t = all[i as usize];
            let mut out = vec![];
            let job = Reflexes { surface: &surface, eye, proj, size: (w, h) };
            let face = (t.v[1].p - t.v[0].p).cross(t.v[2].p - t.v[0].p);
            for (v, b, corners) in job.unfolded(t, reflexes[k]) {
                // Back faces seen from the mirror are culled as they are from the eye.
                let facing = corners
                    .iter()
                    .flatten()
                    .next()
                    .is_none_or(|r| !(opts.cull && t.closed) || face.dot(*r - v[0].p) >= 0.0);
                if facing {
                    job.split(v, b, corners, i, 0, &mut out);
                }
            }
            out
        })
        .collect();
    let drawn = pieces.len();
    let band = super::BAND;
    let color: Vec<Option<Vec3>> = (0..h.div_ceil(band))
        .into_par_iter()
        .flat_map_iter(|b| {
            let (y0, y1) = (b * band, ((b + 1) * band).min(h));
            let n = ((y1 - y0) * w) as usize;
            let (mut depth, mut owner) = (vec![f64::INFINITY; n], vec![(u32::MAX, [0.0; 2]); n]);
            for t in pieces.iter().filter(|t| {
                let (lo, hi) = (
                    t.y.iter().copied().fold(f64::INFINITY, f64::min),
                    t.y.iter().copied().fold(f64::NEG_INFINITY, f64::max),
                );
                hi >= y0 as f64 && lo <= y1 as f64
            }) {
                rasterize(t, w, y0, y1, |f| {
                    let k = ((f.y - y0) * w + f.x) as usize;
                    if f.depth < depth[k] {
                        depth[k] = f.depth;
                        owner[k] = (t.source, f.bary);
                    }
                });
            }
            (0..n)
                .map(|k| {
                    let (x, y) = ((k as u32 % w) as f64 + 0.5, (y0 + k as u32 / w) as f64 + 0.5);
                    let d = proj.near_ray(2.0 * x / w as f64 - 1.0, 1.0 - 2.0 * y / h as f64).dir;
                    let (at, n) = surface.hit(eye, d)?;
                    let (src, b) = owner[k];
                    Some(if src == u32::MAX {
                        scene.sky(d - 2.0 * d.dot(n) * n)
                    } else {
                        reflected_color(scene, all[src as usize], b, at, light)
                    })
                })
                .collect::<Vec<_>>()
        })
        .collect();
    MirrorImage { object: mirror.object, color, drawn }
}

/// Each unbounded plane as rings around the foot of the mirror's centre: radii growing by 1.4
/// from a fiftieth of the mirror's size out to the plane's squares (10⁴), 48 sectors; texture
/// coordinates continued from the plane's own triangle (they are affine in the position). Each
/// ring triangle comes with the index of the plane triangle that stands for its material.
fn plane_rings(tris: &[Triangle], (centre, size): (Vec3, f64)) -> Vec<(Triangle, u32)> {
    let mut out = vec![];
    let mut done: Vec<u32> = vec![];
    for (index, t) in tris.iter().enumerate().filter(|(_, t)| t.unbounded) {
        if done.contains(&t.object) {
            continue;
        }
        done.push(t.object);
        let [a, b, c] = t.v;
        let n = (b.p - a.p).cross(c.p - a.p).normalize_or_zero();
        let (e1, e2) = alhazen_math::orthonormal_basis(n);
        let foot = centre - n * n.dot(centre - a.p);
        // Texture coordinates are affine in the position on the plane.
        let weights = plane_weights(t.v.map(|v| v.p));
        let at = |r: f64, k: usize| {
            let phi = std::f64::consts::TAU * k as f64 / 48.0;
            let p = foot + (e1 * phi.cos() + e2 * phi.sin()) * r;
            let [al, be] = weights(p);
            let uv = a.uv + (b.uv - a.uv) * al + (c.uv - a.uv) * be;
            Vertex { p, n, uv, color: a.color + (b.color - a.color) * al + (c.color - a.color) * be }
        };
        let mut radii = vec![0.0];
        let mut r = size / 50.0;
        while r < 1e4 {
            radii.push(r);
            r *= 1.4;
        }
        let tri = |v: [Vertex; 3]| (Triangle { v, unbounded: false, closed: false, ..*t }, index as u32);
        for w in radii.windows(2) {
            for k in 0..48 {
                let (p, q, s, o) = (at(w[0], k), at(w[0], k + 1), at(w[1], k + 1), at(w[1], k));
                out.push(tri([p, o, s]));
                if w[0] > 0.0 {
                    out.push(tri([p, s, q]));
                }
            }
        }
    }
    out
}

/// The weights `(α, β)` of a point of the plane of triangle `p` with
/// `point − p₀ = α (p₁ − p₀) + β (p₂ − p₀)` (by the normal equations).
fn plane_weights(p: [Vec3; 3]) -> impl Fn(Vec3) -> Bary {
    let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
    let (d11, d12, d22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let det = d11 * d22 - d12 * d12;
    move |q: Vec3| {
        let d = q - p[0];
        let (a, b) = (d.dot(e1), d.dot(e2));
        [(d22 * a - d12 * b) / det, (d11 * b - d12 * a) / det]
    }
}

/// The visible reflex of every corner of the triangles `which`, by the batch solver.
fn corner_reflexes(tris: &[&Triangle], which: &[u32], surface: &Curved, eye: Vec3) -> Vec<[Option<Vec3>; 3]> {
    let corners: Vec<Vec3> = which.iter().flat_map(|&i| tris[i as usize].v.map(|v| v.p)).collect();
    let solved: Vec<Option<Vec3>> = corners
        .par_chunks(4096)
        .flat_map_iter(|chunk| {
            let (x, y, z): (Vec<f64>, Vec<f64>, Vec<f64>) = (
                chunk.iter().map(|p| p.x).collect(),
                chunk.iter().map(|p| p.y).collect(),
                chunk.iter().map(|p| p.z).collect(),
            );
            let mut out = ReflexesSoA::default();
            let ok = surface.batch(eye, PointsSoA { x: &x, y: &y, z: &z }, &mut out);

            (0..chunk.len())
                .map(|i| (ok && out.visible[i]).then(|| Vec3::new(out.x[i], out.y[i], out.z[i])))
                .collect::<Vec<_>>()
        })
        .collect();
    solved.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect()
}

/// The point of `t` at corner weights `b`, lit as the mirror sees it from mirror point `at`.
fn reflected_color(scene: &Scene, t: &Triangle, b: Bary, at: Vec3, light: &shade::Lighting) -> Vec3 {
    let m = &scene.materials[t.material as usize];
    let (p, n, uv) = super::surface_at(t, b);
    let base = shade::base_color(scene, m, uv, super::color_at(t, b));
    shade::shade(scene, m, p, n, (at - p).normalize_or_zero(), base, light)
}

/// The weights of a triangle's own corners.
const CORNER_WEIGHTS: [Bary; 3] = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];

/// The reflexes of one mirror seen from one eye, to split triangles into.
struct Reflexes<'a> {
    surface: &'a Curved,
    eye: Vec3,
    proj: &'a Projection,
    size: (u32, u32),
}

/// A piece of a triangle: corners, their weights in the triangle, their reflexes.
type Piece = ([Vertex; 3], [Bary; 3], [Option<Vec3>; 3]);

impl Reflexes<'_> {
    fn reflex(&self, p: Vec3) -> Option<Vec3> {
        self.surface.reflex(self.eye, p)
    }

    /// Glaeser's Theorems 6–10: where the plane of a triangle meets the mirror, the reflected
    /// rays that lie in the plane (its projecting lines) may cross the triangle, and its reflex
    /// folds over there (the mirror sees the plane from both sides); the triangle is cut along
    /// them (`alhazen_mirror::overlap`) into pieces whose reflexes do not fold, each fanned
    /// into triangles. Other triangles are returned whole.
    fn unfolded(&self, t: &Triangle, corners: [Option<Vec3>; 3]) -> Vec<Piece> {
        let whole = vec![(t.v, CORNER_WEIGHTS, corners)];
        let p = t.v.map(|v| v.p);
        let Some(plane) = Plane::of_polygon(&p) else { return whole };
        // Projecting lines start on the curve where the plane meets the mirror.
        let distance = |c: Vec3| (plane.normal.dot(c) - plane.offset).abs();
        let lines = match self.surface {
            Curved::Sphere(s) if distance(s.center) < s.radius => s.projecting_lines(self.eye, plane),
            Curved::Cylinder { cylinder, .. }
                if plane.normal.dot(cylinder.axis).abs() > 1e-12 * cylinder.axis.length()
                    || distance(cylinder.center) < cylinder.radius =>
            {
                cylinder.projecting_lines(self.eye, plane)
            }
            _ => return whole,
        };
        let polygons = split_polygon(&p, &lines.unwrap_or_default());
        if polygons.len() < 2 {
            return whole;
        }
        let weights = plane_weights(p);
        let corner = |q: Vec3| {
            let b = weights(q);
            let (_, n, uv) = super::surface_at(t, b);
            let known = t.v.iter().position(|v| v.p == q).map(|k| corners[k]);
            (Vertex { p: q, n, uv, color: super::color_at(t, b) }, b, known.unwrap_or_else(|| self.reflex(q)))
        };
        let mut out = vec![];
        for poly in polygons {
            let c: Vec<_> = poly.iter().map(|&q| corner(q)).collect();
            for k in 1..c.len().saturating_sub(1) {
                let tri = [c[0], c[k], c[k + 1]];
                out.push((tri.map(|x| x.0), tri.map(|x| x.1), tri.map(|x| x.2)));
            }
        }
        out
    }

    /// Emits the reflex of triangle `v` (corner reflexes `r`), split until each piece's edges
    /// are within the tolerance.
    /// `b` are the corners' weights in the source triangle, which the pieces carry.
    #[allow(clippy::too_many_arguments)]
    fn split(
        &self,
        v: [Vertex; 3],
        b: [Bary; 3],
        r: [Option<Vec3>; 3],
        source: u32,
        level: u32,
        out: &mut Vec<ScreenTriangle>,
    ) {
        // Reflexes behind the eye are not in this view: a piece wholly behind is left out, one
        // across the eye's plane is split a few times and then left out too (screen positions
        // behind the eye mean nothing to the tolerance, which would split it to the last level).
        let behind = r.iter().flatten().filter(|p| (self.proj.world_to_clip * p.extend(1.0)).w <= 0.0).count();
        if behind > 0 && (behind == r.iter().flatten().count() || level >= ACROSS_EYE_LEVELS) {
            return;
        }
        // Pieces a pixel across are done: drawn when every corner has a reflex, else (deeper
        // down) left out: they lie on the border of the region without reflexes.
        let present: Vec<Vec2> = r.iter().flatten().map(|p| to_screen(self.proj, *p, self.size)).collect();
        let span = present.iter().map(|p| (*p - present[0]).length()).fold(0.0, f64::max);
        if behind == 0 && present.len() == 3 && span <= 1.0 {
            // Most triangles of a fine mesh: their reflex is smaller than a pixel (a convex
            // mirror shrinks), no midpoint needs solving.
            self.emit(v, b, r.map(|x| x.expect("three reflexes")), source, out);
            return;
        }
        if level >= 3 && present.len() == 2 && span <= 1.0 {
            self.rim(v, b, r, source, out);
            return;
        }
        let mid = |a: &Vertex, b: &Vertex| Vertex {
            p: (a.p + b.p) / 2.0,
            n: (a.n + b.n).normalize_or_zero(),
            uv: (a.uv + b.uv) / 2.0,
            color: (a.color + b.color) / 2.0,
        };
        let m = [mid(&v[1], &v[2]), mid(&v[2], &v[0]), mid(&v[0], &v[1])];
        let half = |x: Bary, y: Bary| [(x[0] + y[0]) / 2.0, (x[1] + y[1]) / 2.0];
        let mb = [half(b[1], b[2]), half(b[2], b[0]), half(b[0], b[1])];
        let rm = m.map(|x| self.reflex(x.p));
        // Without a reflex at any corner or midpoint the piece lies in the region the mirror
        // does not show; with one, deep down, on its border.
        let known = present.len() + rm.iter().flatten().count();
        if known == 0 || (level >= 4 && known <= 1) {
            if known == 1 && present.len() == 1 {
                self.rim(v, b, r, source, out);
            }
            return;
        }
        let screen = |p: Vec3| to_screen(self.proj, p, self.size);
        // A piece whose known reflexes all lie beyond one edge of the screen, farther than
        // they lie apart, is not in this view (a panorama's cube faces that do not look at the
        // mirror split such pieces to the pixel otherwise).
        let known: Vec<Vec2> = r.iter().chain(&rm).flatten().map(|p| screen(*p)).collect();
        if behind == 0 && self.off_screen(&known) {
            return;
        }
        let fits = match (r, rm) {
            _ if behind > 0 => false,
            ([Some(a), Some(b), Some(c)], [Some(ma), Some(mb), Some(mc)]) => {
                let (sa, sb, sc) = (screen(a), screen(b), screen(c));
                let off = [(ma, sb, sc), (mb, sc, sa), (mc, sa, sb)]
                    .iter()
                    .map(|&(mr, s0, s1)| (screen(mr) - (s0 + s1) / 2.0).length())
                    .fold(0.0, f64::max);
                off <= TOLERANCE_PX
            }
            _ => false,
        };
        let small = || {
            let s: Vec<Vec2> = r.iter().flatten().map(|p| screen(*p)).collect();
            s.len() == 3 && s.iter().all(|p| (*p - s[0]).length() <= FINEST_PX)
        };
        if fits || (level == MAX_LEVEL && behind == 0 && small()) {
            self.emit(v, b, r.map(|x| x.expect("three reflexes")), source, out);
        } else if level < MAX_LEVEL {
            for (tri, w, refl) in [
                ([v[0], m[2], m[1]], [b[0], mb[2], mb[1]], [r[0], rm[2], rm[1]]),
                ([m[2], v[1], m[0]], [mb[2], b[1], mb[0]], [rm[2], r[1], rm[0]]),
                ([m[1], m[0], v[2]], [mb[1], mb[0], b[2]], [rm[1], rm[0], r[2]]),
                ([m[0], m[1], m[2]], [mb[0], mb[1], mb[2]], [rm[0], rm[1], rm[2]]),
            ] {
                self.split(tri, w, refl, source, level + 1, out);
            }
        }
    }

    /// The last piece of a triangle that passes through the mirror: its corners inside the
    /// mirror's solid (which have no reflex) are replaced by the points where its edges leave
    /// the surface — a point of the surface is its own reflex — and the rest is drawn (without
    /// this, the pieces along the curve where a mesh pierces the mirror were left out, and the
    /// sky showed through there).
    fn rim(&self, v: [Vertex; 3], b: [Bary; 3], r: [Option<Vec3>; 3], source: u32, out: &mut Vec<ScreenTriangle>) {
        let missing = (0..3).filter(|&k| r[k].is_none());
        if !missing.clone().all(|k| self.surface.inside(v[k].p)) {
            return;
        }
        let mut poly: Vec<(Vertex, Bary, Vec3)> = vec![];
        for k in 0..3 {
            let j = (k + 1) % 3;
            if let Some(rk) = r[k] {
                poly.push((v[k], b[k], rk));
            }
            if r[k].is_some() != r[j].is_some() {
                let Some(t) = self.surface.crossing(v[k].p, v[j].p) else { return };
                let q = Vertex {
                    p: v[k].p + (v[j].p - v[k].p) * t,
                    n: (v[k].n + (v[j].n - v[k].n) * t).normalize_or_zero(),
                    uv: v[k].uv + (v[j].uv - v[k].uv) * t,
                    color: v[k].color + (v[j].color - v[k].color) * t,
                };
                if !self.surface.shows_itself(self.eye, q.p) {
                    return;
                }
                let w = [0, 1].map(|i| b[k][i] + (b[j][i] - b[k][i]) * t);
                poly.push((q, w, q.p));
            }
        }
        for k in 1..poly.len().saturating_sub(1) {
            let c = [poly[0], poly[k], poly[k + 1]];
            self.emit(c.map(|x| x.0), c.map(|x| x.1), c.map(|x| x.2), source, out);
        }
    }

    /// True when `pts` (screen positions) all lie beyond one edge of the screen by more than
    /// their own extent.
    fn off_screen(&self, pts: &[Vec2]) -> bool {
        let Some(&first) = pts.first() else { return false };
        let span = pts.iter().map(|p| (*p - first).length()).fold(0.0, f64::max);
        let (w, h) = (self.size.0 as f64, self.size.1 as f64);
        let all = |f: &dyn Fn(&Vec2) -> bool| pts.iter().all(f);
        all(&|p| p.x < -span) || all(&|p| p.x > w + span) || all(&|p| p.y < -span) || all(&|p| p.y > h + span)
    }

    fn emit(&self, v: [Vertex; 3], b: [Bary; 3], r: [Vec3; 3], source: u32, out: &mut Vec<ScreenTriangle>) {
        let s = r.map(|p| to_screen(self.proj, p, self.size));
        let (w, h) = (self.size.0 as f64, self.size.1 as f64);
        if s.iter().all(|p| p.x < 0.0)
            || s.iter().all(|p| p.x > w)
            || s.iter().all(|p| p.y < 0.0)
            || s.iter().all(|p| p.y > h)
        {
            return;
        }
        out.push(ScreenTriangle {
            x: s.map(|p| p.x),
            y: s.map(|p| p.y),
            z: std::array::from_fn(|k| (r[k] - self.eye).length() + (v[k].p - r[k]).length()),
            inv_w: [1.0; 3],
            bary_w: b,
            source,
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn vertex(p: Vec3) -> Vertex {
        Vertex { p, n: Vec3::Y, uv: Vec2::new(p.x, p.z), color: Vec3::ONE }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(300))]

        /// Glaeser's split: no piece of a triangle (clear of the mirror) is seen by the mirror
        /// from both sides of its plane, and the pieces cover the triangle.
        #[test]
        fn no_piece_is_seen_from_both_sides(
            c in prop::array::uniform3(prop::array::uniform3(-3.0..3.0f64)),
            eye in prop::array::uniform3(-6.0..6.0f64),
        ) {
            let eye = Vec3::from_array(eye);
            prop_assume!(eye.length() > 2.0);
            let p = c.map(Vec3::from_array);
            let area = |p: [Vec3; 3]| (p[1] - p[0]).cross(p[2] - p[0]).length() / 2.0;
            prop_assume!(area(p) > 0.05 && p.iter().all(|q| q.length() > 1.01));
            let surface = Curved::Sphere(Sphere { center: Vec3::ZERO, radius: 1.0 });
            let look = alhazen_scene::LookAt { eye, target: Vec3::ZERO, up: if eye.cross(Vec3::Y).length() > 0.1 { Vec3::Y } else { Vec3::X } };
            let desc = alhazen_scene::CameraDesc::Perspective {
                look,
                opening: alhazen_scene::PerspectiveOpening::Fov { angle: 1.0, horizontal: true }, lens: None };
            let proj = super::super::projection(&desc, 64, 64).unwrap();
            let job = Reflexes { surface: &surface, eye, proj: &proj, size: (64, 64) };
            let t = Triangle { v: p.map(vertex), material: 0, closed: false, unbounded: false, object: 0 };
            // Triangles that pass through the mirror are not the theorem's: a projecting ray
            // starts inside them.
            let grid = (0..=40).flat_map(|i| (0..=40 - i).map(move |j| [i as f64 / 40.0, j as f64 / 40.0]));
            prop_assume!(grid.clone().all(|b| super::super::surface_at(&t, b).0.length() > 1.05));
            let pieces = job.unfolded(&t, p.map(|q| job.reflex(q)));
            let covered: f64 = pieces.iter().map(|(v, _, _)| area(v.map(|x| x.p))).sum();
            prop_assert!((covered - area(p)).abs() < 1e-9 * (1.0 + area(p)), "{covered} of {}", area(p));
            let plane = Plane::of_polygon(&p).unwrap();
            for (v, b, r) in &pieces {
                // The corners' weights give back the corners.
                for k in 0..3 {
                    prop_assert!((super::super::surface_at(&t, b[k]).0 - v[k].p).length() < 1e-9);
                }
                // The corners' reflexes and those of points inside the piece, where the mirror
                // shows all of them (across a region it does not show, the side may change).
                let inside = (1..8).flat_map(|i| (1..8 - i).map(move |j| [i as f64 / 8.0, j as f64 / 8.0]));
                let at = |w: [f64; 2]| v[0].p + (v[1].p - v[0].p) * w[0] + (v[2].p - v[0].p) * w[1];
                let more: Option<Vec<Vec3>> = inside.map(|w| job.reflex(at(w))).collect();
                let (Some(more), true) = (more, r.iter().all(|x| x.is_some())) else { continue };
                let side: Vec<f64> =
                    r.iter().flatten().chain(&more).map(|r| plane.normal.dot(*r) - plane.offset).collect();
                let tol = 1e-9;
                prop_assert!(side.iter().all(|&s| s >= -tol) || side.iter().all(|&s| s <= tol), "{side:?}");
            }
        }
    }
}
