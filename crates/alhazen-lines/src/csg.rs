//! CSG bodies in line drawings (course, §"Constructive solid geometry": the boundary of a
//! regularised Boolean combination lies on its operands' surfaces). A body's lines are its
//! operands' own lines — edges, contours, rims — and the intersection curves of its operands'
//! surfaces (and of them with other objects), each kept where it lies on the body's boundary:
//! * a line on one operand's surface is kept where the body's membership is not constant
//!   around the point (on its boundary: the operand's surface is not swallowed by, or cut away
//!   with, another operand);
//! * an intersection curve of two operands of the same body is kept where the body has a
//!   crease: of the four quadrants the two surfaces make at the point, one or three inside (or
//!   two diagonal ones), not two side by side (the body's surface is then one of the two,
//!   smooth through the curve).
//!
//! The drawing finds the lines on a scene in which every CSG object is replaced by its leaf
//! operands placed in the world ([`Expansion`]), then [`Expansion::restrict`] cuts them to the
//! boundary (by bisection on the membership tests) and gives them back to the body's object, so
//! visibility is decided by the ray tracer's exact CSG intersection like any other line's.

use crate::curves::{Curve, LineKind, SceneLine};
use alhazen_math::{Transform, Vec3};
use alhazen_render::World;
use alhazen_render::shape::Placed;
use alhazen_scene::{Object, Scene, Shape};

/// Directions around a point at which membership is sampled (the axes and the diagonals).
const AROUND: [[f64; 3]; 14] = [
    [1.0, 0.0, 0.0],
    [-1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, -1.0, 0.0],
    [0.0, 0.0, 1.0],
    [0.0, 0.0, -1.0],
    [0.577, 0.577, 0.577],
    [0.577, 0.577, -0.577],
    [0.577, -0.577, 0.577],
    [0.577, -0.577, -0.577],
    [-0.577, 0.577, 0.577],
    [-0.577, 0.577, -0.577],
    [-0.577, -0.577, 0.577],
    [-0.577, -0.577, -0.577],
];

/// Bisection steps where membership changes along a curve (2⁻⁴⁰ of the curve).
const BISECTIONS: u32 = 40;

/// The scene with each CSG object replaced by its leaf operands in world space.
pub struct Expansion {
    /// The expanded scene.
    pub scene: Scene,
    /// The scene object each expanded object stands for.
    pub origin: Vec<u32>,
    /// Per expanded object: its index among the leaves (`leaf_world`'s objects) when it is
    /// a CSG operand.
    leaf: Vec<Option<u32>>,
    /// The leaves alone as a world: their surface normals.
    leaf_world: World,
}

/// The leaf operands of `shape` placed by `to_world`, each an object with the body's material.
fn leaves(shape: &Shape, to_world: Transform, body: &Object, out: &mut Vec<Object>) {
    match shape {
        Shape::Csg { a, b, .. } => {
            leaves(&a.shape, to_world * a.transform, body, out);
            leaves(&b.shape, to_world * b.transform, body, out);
        }
        leaf => out.push(Object { shape: leaf.clone(), transform: to_world, mesh_materials: vec![], ..body.clone() }),
    }
}

impl Expansion {
    /// `scene` expanded; `None` when it has no CSG object.
    pub fn of(scene: &Scene) -> Option<Expansion> {
        if !scene.objects.iter().any(|o| matches!(o.shape, Shape::Csg { .. })) {
            return None;
        }
        let (mut objects, mut origin, mut leaf) = (vec![], vec![], vec![]);
        let mut leaf_objects = vec![];
        for (i, o) in scene.objects.iter().enumerate() {
            if matches!(o.shape, Shape::Csg { .. }) {
                let mut parts = vec![];
                leaves(&o.shape, o.transform, o, &mut parts);
                for p in parts {
                    leaf.push(Some(leaf_objects.len() as u32));
                    leaf_objects.push(p.clone());
                    objects.push(p);
                    origin.push(i as u32);
                }
            } else {
                objects.push(o.clone());
                origin.push(i as u32);
                leaf.push(None);
            }
        }
        let leaf_world = World::build(&Scene { objects: leaf_objects, ..scene.clone() });
        Some(Expansion { scene: Scene { objects, ..scene.clone() }, origin, leaf, leaf_world })
    }

    /// The lines of the expanded scene as lines of `world`'s scene: those on operands cut to
    /// their body's boundary, every object index mapped back.
    pub fn restrict(&self, lines: Vec<SceneLine>, world: &World) -> Vec<SceneLine> {
        use rayon::prelude::*;
        lines
            .into_par_iter()
            .flat_map_iter(|line| {
                let pieces = self.boundary_pieces(&line, world);
                let object = self.origin[line.object as usize];
                let kind = match line.kind {
                    LineKind::Intersection { other } => LineKind::Intersection { other: self.origin[other as usize] },
                    k => k,
                };
                pieces.into_iter().map(move |curve| SceneLine { curve, object, kind })
            })
            .collect()
    }

    /// The pieces of `line` on the boundaries of the bodies it lies on (the whole line when
    /// it lies on none).
    fn boundary_pieces(&self, line: &SceneLine, world: &World) -> Vec<Curve> {
        let own = line.object as usize;
        let other = match line.kind {
            LineKind::Intersection { other } => Some(other as usize),
            _ => None,
        };
        let body = |k: usize| self.leaf[k].map(|_| &world.objects()[self.origin[k] as usize].placed);
        if body(own).is_none() && other.and_then(body).is_none() {
            return vec![line.curve];
        }
        let same_body = other.is_some_and(|o| body(o).is_some() && self.origin[o] == self.origin[own]);
        // A curve on a surface is exact: its points are sampled closely. Intersection curves
        // may be traced chords, off the true curve by up to a ten-thousandth of the body.
        let near = if other.is_some() { TRACED } else { EXACT };
        let keep = |p: Vec3| -> bool {
            if same_body {
                let o = other.expect("an intersection");
                return self.creased(body(own).expect("a body"), [own, o], p);
            }
            [Some(own), other].into_iter().flatten().filter_map(&body).all(|b| on_boundary(b, p, near * size(b)))
        };
        split(&line.curve, keep)
    }

    /// True when the body has a crease at `p` on the intersection of its leaves `pair`.
    fn creased(&self, body: &Placed, pair: [usize; 2], p: Vec3) -> bool {
        let leaf_world = &self.leaf_world;
        let e = TRACED * size(body);
        let normal = |k: usize| leaf_world.objects()[self.leaf[k]? as usize].placed.normal_near(p, 100.0 * e);
        let (Some(n1), Some(n2)) = (normal(pair[0]), normal(pair[1])) else {
            return on_boundary(body, p, e);
        };
        let quadrant = |a: f64, b: f64| {
            let d = (n1 * a + n2 * b).try_normalize();
            d.is_some_and(|d| body.contains(p + d * e))
        };
        let q = [quadrant(1.0, 1.0), quadrant(1.0, -1.0), quadrant(-1.0, -1.0), quadrant(-1.0, 1.0)];
        match q.iter().filter(|&&x| x).count() {
            1 | 3 => true,
            // Two opposite quadrants: the body touches itself along the curve.
            2 => q[0] == q[2],
            _ => false,
        }
    }
}

/// How far around a point of an exact curve membership is sampled, relative to the body's size.
const EXACT: f64 = 1e-8;
/// The same around a point of an intersection curve (traced curves' chords stray from the true
/// curve by less).
const TRACED: f64 = 1e-4;

/// The diagonal of a body's bounds.
fn size(body: &Placed) -> f64 {
    let b = body.bounds();
    let size = if b.is_finite() && !b.is_empty() { (b.max - b.min).length() } else { 1.0 };
    size.max(1e-12)
}

/// True when membership of `body` is not the same all around `p` at distance `eps`.
fn on_boundary(body: &Placed, p: Vec3, eps: f64) -> bool {
    let at = |d: &[f64; 3]| body.contains(p + Vec3::from_array(*d) * eps);
    let first = at(&AROUND[0]);
    AROUND[1..].iter().any(|d| at(d) != first)
}

/// The pieces of `curve` where `keep` holds: sampled, then each change located by bisection.
fn split(curve: &Curve, keep: impl Fn(Vec3) -> bool) -> Vec<Curve> {
    let samples = match curve {
        Curve::Segment { .. } => 16,
        _ => 256,
    };
    let at = |s: f64| keep(curve.point(s));
    let mut pieces = vec![];
    let (mut prev_s, mut prev) = (0.0, at(0.0));
    let mut start = prev.then_some(0.0);
    for k in 1..=samples {
        let s = k as f64 / samples as f64;
        let now = at(s);
        if now != prev {
            let (mut lo, mut hi) = (prev_s, s);
            for _ in 0..BISECTIONS {
                let mid = 0.5 * (lo + hi);
                if at(mid) == prev { lo = mid } else { hi = mid }
            }
            let cut = 0.5 * (lo + hi);
            match start.take() {
                Some(s0) => pieces.push((s0, cut)),
                None => start = Some(cut),
            }
        }
        (prev_s, prev) = (s, now);
    }
    if let Some(s0) = start {
        pieces.push((s0, 1.0));
    }
    pieces.into_iter().filter(|(a, b)| b > a).map(|(a, b)| curve.sub(a, b)).collect()
}
