//! An octree over the scene's triangles for view-frustum culling (course, §"Spatial data
//! structures": the octree divides a cube into eight at its centre, recursively, where there is
//! much in it). Each triangle lives in the smallest node whose cube holds it whole; a frame
//! tests nodes against the view volume `−w ≤ x, y, z ≤ w` in clip space and skips the
//! triangles of nodes entirely outside one of its planes — triangles the clipper would have
//! dropped anyway, so the image is the same, only sooner.

use super::geometry::Triangle;
use alhazen_math::{Bounds3, Mat4, Vec3, Vec4};

/// Triangles a node keeps before it is divided.
const LEAF: usize = 32;
/// Levels below the root at most.
const MAX_DEPTH: u32 = 12;

/// A node: its cube, its first child (eight consecutive nodes), and the range of `items` of its
/// own triangles and of its whole subtree.
#[derive(Clone, Debug)]
struct Node {
    bounds: Bounds3,
    children: Option<u32>,
    own: std::ops::Range<u32>,
    subtree: std::ops::Range<u32>,
}

/// The octree.
#[derive(Clone, Debug, Default)]
pub struct Octree {
    nodes: Vec<Node>,
    /// Triangle indices, each subtree's contiguous.
    items: Vec<u32>,
    /// Triangles not in the tree (unbounded: an infinite plane's), always drawn.
    unbounded: Vec<u32>,
}

/// Where a box lies against the view volume.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    /// Entirely outside one plane.
    Outside,
    /// Entirely inside all six.
    Inside,
    /// Across some plane.
    Across,
}

impl Octree {
    /// The octree of `triangles` (by their corners' bounds).
    pub fn build(triangles: &[Triangle]) -> Self {
        let mut tree = Octree::default();
        let mut boxed: Vec<(u32, Bounds3)> = Vec::with_capacity(triangles.len());
        for (i, t) in triangles.iter().enumerate() {
            let b = t.v.iter().fold(Bounds3::EMPTY, |b, v| b.grow(v.p));
            if t.unbounded || !b.is_finite() {
                tree.unbounded.push(i as u32);
            } else {
                boxed.push((i as u32, b));
            }
        }
        if boxed.is_empty() {
            return tree;
        }
        let all = boxed.iter().fold(Bounds3::EMPTY, |a, (_, b)| a.union(*b));
        // A cube around everything, so children are cubes.
        let half = all.extent().max_element() * 0.5 * (1.0 + 1e-9) + 1e-300;
        let c = all.centroid();
        tree.nodes.push(Node {
            bounds: Bounds3::new(c - Vec3::splat(half), c + Vec3::splat(half)),
            children: None,
            own: 0..0,
            subtree: 0..0,
        });
        tree.fill(0, boxed, 0);
        tree
    }

    /// Places `boxed` in node `n` and below, appending to `items` in depth-first order.
    fn fill(&mut self, n: usize, boxed: Vec<(u32, Bounds3)>, depth: u32) {
        let start = self.items.len() as u32;
        let bounds = self.nodes[n].bounds;
        let centre = bounds.centroid();
        let mut below: [Vec<(u32, Bounds3)>; 8] = Default::default();
        let mut own = vec![];
        if boxed.len() <= LEAF || depth >= MAX_DEPTH {
            own = boxed;
        } else {
            for (i, b) in boxed {
                // The octant holding the box whole, if one does.
                let lo = b.min.cmpge(centre);
                let hi = b.max.cmpge(centre);
                if lo == hi {
                    let k = (hi.x as usize) | (hi.y as usize) << 1 | (hi.z as usize) << 2;
                    below[k].push((i, b));
                } else {
                    own.push((i, b));
                }
            }
        }
        self.items.extend(own.iter().map(|(i, _)| *i));
        self.nodes[n].own = start..self.items.len() as u32;
        if below.iter().any(|b| !b.is_empty()) {
            let first = self.nodes.len();
            self.nodes[n].children = Some(first as u32);
            for k in 0..8 {
                let pick =
                    |bit: usize, lo: f64, mid: f64, hi: f64| if k >> bit & 1 == 1 { (mid, hi) } else { (lo, mid) };
                let (x0, x1) = pick(0, bounds.min.x, centre.x, bounds.max.x);
                let (y0, y1) = pick(1, bounds.min.y, centre.y, bounds.max.y);
                let (z0, z1) = pick(2, bounds.min.z, centre.z, bounds.max.z);
                self.nodes.push(Node {
                    bounds: Bounds3::new(Vec3::new(x0, y0, z0), Vec3::new(x1, y1, z1)),
                    children: None,
                    own: 0..0,
                    subtree: 0..0,
                });
            }
            for (k, b) in below.into_iter().enumerate() {
                self.fill(first + k, b, depth + 1);
            }
        }
        self.nodes[n].subtree = start..self.items.len() as u32;
    }

    /// Renumbers the triangles in the tree's order (the unbounded ones first) and returns the
    /// permutation: new triangle `k` is old triangle `order[k]`. A frame then reads the
    /// triangles it keeps front to back in memory (a million triangles drawn in the tree's order
    /// but stored in the file's took twice as long to transform).
    pub fn renumber(&mut self) -> Vec<u32> {
        let order: Vec<u32> = self.unbounded.iter().chain(&self.items).copied().collect();
        let first = self.unbounded.len() as u32;
        self.unbounded = (0..first).collect();
        self.items = (first..order.len() as u32).collect();
        order
    }

    /// Appends to `out` the triangles that may show through `world_to_clip` (all with `None`):
    /// the unbounded ones, then the tree's in its own order, leaving out those of nodes entirely
    /// outside the view volume. Culled or not, the triangles kept come in the same order, so
    /// the frame is the same; the order is the frame's drawing order.
    pub fn visible_items(&self, world_to_clip: Option<&Mat4>, out: &mut Vec<u32>) {
        out.extend_from_slice(&self.unbounded);
        match world_to_clip {
            None => out.extend_from_slice(&self.items),
            Some(m) if !self.nodes.is_empty() => self.append_visible(0, m, out),
            Some(_) => {}
        }
    }

    /// [`Self::visible_items`] below node `n`, depth first as `items` is laid out.
    fn append_visible(&self, n: usize, world_to_clip: &Mat4, out: &mut Vec<u32>) {
        let node = &self.nodes[n];
        let range = |r: &std::ops::Range<u32>| &self.items[r.start as usize..r.end as usize];
        match side(&node.bounds, world_to_clip) {
            Side::Outside => {}
            Side::Inside => out.extend_from_slice(range(&node.subtree)),
            Side::Across => {
                out.extend_from_slice(range(&node.own));
                if let Some(first) = node.children {
                    for child in first as usize..first as usize + 8 {
                        self.append_visible(child, world_to_clip, out);
                    }
                }
            }
        }
    }
}

/// Where box `b` lies against the view volume of `world_to_clip`.
pub fn side(b: &Bounds3, world_to_clip: &Mat4) -> Side {
    let corners: [Vec4; 8] = std::array::from_fn(|k| {
        let p = Vec3::new(
            if k & 1 == 0 { b.min.x } else { b.max.x },
            if k & 2 == 0 { b.min.y } else { b.max.y },
            if k & 4 == 0 { b.min.z } else { b.max.z },
        );
        *world_to_clip * p.extend(1.0)
    });
    let mut inside_all = true;
    for axis in 0..3 {
        for sign in [1.0, -1.0] {
            let inside = corners.iter().filter(|c| c.w + sign * c[axis] >= 0.0).count();
            if inside == 0 {
                return Side::Outside;
            }
            inside_all &= inside == 8;
        }
    }
    if inside_all { Side::Inside } else { Side::Across }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipeline::clip::{ClipVertex, clip_polygon};
    use crate::pipeline::geometry::Vertex;
    use alhazen_math::Vec2;
    use proptest::prelude::*;

    /// The pipeline's own perspective projection of a 4 : 3 image.
    fn clip_of(eye: Vec3, target: Vec3, up: Vec3, fov_degrees: f64) -> Mat4 {
        use alhazen_scene::{CameraDesc, LookAt, PerspectiveOpening};
        let desc = CameraDesc::Perspective {
            look: LookAt { eye, target, up },
            opening: PerspectiveOpening::Fov { angle: fov_degrees.to_radians(), horizontal: true },
            lens: None,
        };
        crate::pipeline::projection(&desc, 64, 48).unwrap().world_to_clip
    }

    fn triangle(p: [Vec3; 3]) -> Triangle {
        let v = |p: Vec3| Vertex { p, n: Vec3::Z, uv: Vec2::ZERO, color: Vec3::ONE };
        Triangle { v: p.map(v), material: 0, closed: false, unbounded: false, object: 0 }
    }

    proptest! {
        /// A triangle left unmarked is one the clipper drops whole; the marked count is right.
        #[test]
        fn only_triangles_outside_the_view_volume_are_skipped(
            corners in prop::collection::vec((-20.0..20.0f64, -20.0..20.0f64, -20.0..20.0f64), 3..600),
            eye in (-15.0..15.0f64, -15.0..15.0f64, -15.0..15.0f64),
            look in (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64),
            fov in 20.0..120.0f64,
        ) {
            let pts: Vec<Vec3> = corners.iter().map(|&(x, y, z)| Vec3::new(x, y, z)).collect();
            // Triangles of all sizes: neighbours' corners, scaled down for some.
            let triangles: Vec<Triangle> = pts
                .chunks_exact(3)
                .enumerate()
                .map(|(i, c)| {
                    let s = [1.0, 0.1, 0.01][i % 3];
                    triangle([c[0], c[0] + (c[1] - c[0]) * s, c[0] + (c[2] - c[0]) * s])
                })
                .collect();
            prop_assume!(!triangles.is_empty());
            let eye = Vec3::new(eye.0, eye.1, eye.2);
            let dir = Vec3::new(look.0, look.1, look.2);
            prop_assume!(dir.length() > 0.1);
            let up = if dir.normalize().cross(Vec3::Y).length() > 1e-3 { Vec3::Y } else { Vec3::X };
            let world_to_clip = clip_of(eye, eye + dir, up, fov);
            let tree = Octree::build(&triangles);
            let (mut kept, mut all) = (vec![], vec![]);
            tree.visible_items(Some(&world_to_clip), &mut kept);
            tree.visible_items(None, &mut all);
            // Every triangle once without culling; with it, a subsequence in the same order.
            let mut sorted = all.clone();
            sorted.sort_unstable();
            prop_assert_eq!(sorted, (0..triangles.len() as u32).collect::<Vec<_>>());
            let mut rest = all.iter();
            prop_assert!(kept.iter().all(|k| rest.any(|a| a == k)), "not in the drawing order");
            let mut visible = vec![false; triangles.len()];
            kept.iter().for_each(|&i| visible[i as usize] = true);
            for (t, seen) in triangles.iter().zip(&visible) {
                if !seen {
                    let poly: Vec<ClipVertex> =
                        t.v.iter().enumerate().map(|(k, v)| ClipVertex::corner(world_to_clip * v.p.extend(1.0), v.p, k)).collect();
                    prop_assert!(clip_polygon(&poly).is_empty(), "{:?}", t.v.map(|v| v.p));
                }
            }
        }
    }

    #[test]
    fn renumbered_triangles_are_kept_in_their_order() {
        let triangles: Vec<Triangle> = (0..500)
            .map(|k| {
                let o = Vec3::new((k * 37 % 20) as f64, (k * 11 % 17) as f64, (k % 3) as f64);
                triangle([o, o + Vec3::X * (0.3 + (k % 5) as f64), o + Vec3::Y * 0.5])
            })
            .collect();
        let mut tree = Octree::build(&triangles);
        let world_to_clip = clip_of(Vec3::new(3.0, 3.0, 9.0), Vec3::new(2.0, 2.0, 0.0), Vec3::Y, 40.0);
        let mut before = vec![];
        tree.visible_items(Some(&world_to_clip), &mut before);
        let order = tree.renumber();
        let mut sorted = order.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..500).collect::<Vec<u32>>(), "a permutation");
        let renumbered: Vec<Triangle> = order.iter().map(|&i| triangles[i as usize]).collect();
        // The renumbered tree is the tree of the renumbered triangles, and keeps the same ones.
        let rebuilt = Octree::build(&renumbered);
        assert_eq!((rebuilt.items.clone(), rebuilt.unbounded.clone()), (tree.items.clone(), tree.unbounded.clone()));
        let mut after = vec![];
        tree.visible_items(Some(&world_to_clip), &mut after);
        assert_eq!(after.iter().map(|&k| order[k as usize]).collect::<Vec<_>>(), before);
        assert!(after.windows(2).all(|w| w[0] < w[1]), "kept in memory order");
    }

    #[test]
    fn a_view_of_one_corner_skips_the_rest() {
        // A 20 × 20 grid of small triangles; a narrow view of one corner.
        let triangles: Vec<Triangle> = (0..400)
            .map(|k| {
                let o = Vec3::new((k % 20) as f64, (k / 20) as f64, 0.0);
                triangle([o, o + Vec3::X * 0.5, o + Vec3::Y * 0.5])
            })
            .collect();
        let world_to_clip = clip_of(Vec3::new(0.5, 0.5, 3.0), Vec3::new(0.5, 0.5, 0.0), Vec3::Y, 30.0);
        let tree = Octree::build(&triangles);
        let mut kept = vec![];
        tree.visible_items(Some(&world_to_clip), &mut kept);
        assert!(kept.contains(&0) && kept.len() < 40, "{} of 400 kept", kept.len());
    }
}
