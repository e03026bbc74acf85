//! The BSP-tree painter's algorithm (course, §"Visibility"): the triangles are sorted once into a
//! binary space partition — each node's plane is one of its triangles' planes, triangles that
//! straddle it are split — and for every view the tree is walked back to front (the subtree on
//! the viewer's far side of the plane first, then the node's own triangles, then the near side),
//! so painting in that order needs no depth buffer.
//!
//! Where no triangle's plane divides a large set (the faces of a convex mesh all lie behind one
//! another's planes, which would make the tree a chain and its construction quadratic), the
//! node takes a free plane instead: axis-aligned through the median of the triangles' centroids.

use super::geometry::{Triangle, Vertex};
use alhazen_math::Vec3;

/// A node: its plane `n·p = d`, its triangles (coplanar with the plane), and its subtrees.
#[derive(Clone, Debug)]
struct Node {
    n: Vec3,
    d: f64,
    triangles: Vec<u32>,
    front: Option<u32>,
    back: Option<u32>,
}

/// A parent node and whether a child hangs on its front side.
type Attach = Option<(u32, bool)>;
/// A half-space constraint `(n, d, front)` inherited from an ancestor.
type Side = (Vec3, f64, bool);

/// A BSP tree over triangles (split where needed).
#[derive(Clone, Debug)]
pub struct BspTree {
    /// The input triangles followed by the pieces of those that were split; the tree refers to
    /// them by index (a split triangle itself is no longer in the tree).
    pub triangles: Vec<Triangle>,
    nodes: Vec<Node>,
}

/// Where the viewer is: a point (perspective) or a direction towards it (parallel projection).
#[derive(Clone, Copy, Debug)]
pub enum Viewer {
    /// The eye.
    At(Vec3),
    /// Unit direction pointing to the viewer at infinity.
    Towards(Vec3),
}

fn lerp(a: &Vertex, b: &Vertex, t: f64) -> Vertex {
    Vertex {
        p: a.p.lerp(b.p, t),
        n: a.n.lerp(b.n, t).normalize_or_zero(),
        uv: a.uv.lerp(b.uv, t),
        color: a.color.lerp(b.color, t),
    }
}

/// Splits a triangle by the plane into the polygons in front and behind.
fn split(t: &Triangle, dist: [f64; 3]) -> (Vec<Vertex>, Vec<Vertex>) {
    let (mut front, mut back) = (vec![], vec![]);
    for i in 0..3 {
        let j = (i + 1) % 3;
        let (a, b, da, db) = (&t.v[i], &t.v[j], dist[i], dist[j]);
        if da >= 0.0 {
            front.push(*a);
        }
        if da <= 0.0 {
            back.push(*a);
        }
        if (da > 0.0 && db < 0.0) || (da < 0.0 && db > 0.0) {
            let m = lerp(a, b, da / (da - db));
            front.push(m);
            back.push(m);
        }
    }
    (front, back)
}

fn fan<'a>(poly: &'a [Vertex], like: &Triangle) -> impl Iterator<Item = Triangle> + 'a {
    let like = *like;
    (1..poly.len().saturating_sub(1)).map(move |k| Triangle { v: [poly[0], poly[k], poly[k + 1]], ..like })
}

impl BspTree {
    /// Builds the tree (iteratively: a deep tree cannot overflow the stack). `eps` is the
    /// distance within which a vertex counts as on a plane.
    pub fn build(input: &[Triangle], eps: f64) -> Self {
        let mut tree = BspTree { triangles: input.to_vec(), nodes: vec![] };
        let all: Vec<u32> = (0..input.len() as u32).filter(|&i| plane_of(&input[i as usize]).is_some()).collect();
        if all.is_empty() {
            return tree;
        }
        // Work items: (set of triangles, parent node and side to attach to, depth).
        let mut work: Vec<(Vec<u32>, Attach, usize)> = vec![(all, None, 0)];
        while let Some((set, parent, depth)) = work.pop() {
            let (n, d) = tree.splitter(&set, eps, depth);
            let (mut on, mut front, mut back) = (vec![], vec![], vec![]);
            for &i in &set {
                let t = tree.triangles[i as usize];
                let dist = t.v.map(|v| n.dot(v.p) - d);
                let dist = dist.map(|x| if x.abs() <= eps { 0.0 } else { x });
                let (pos, neg) = (dist.iter().any(|x| *x > 0.0), dist.iter().any(|x| *x < 0.0));
                match (pos, neg) {
                    (false, false) => on.push(i),
                    (true, false) => front.push(i),
                    (false, true) => back.push(i),
                    (true, true) => {
                        let (f, b) = split(&t, dist);
                        for (poly, side) in [(f, &mut front), (b, &mut back)] {
                            for piece in fan(&poly, &t) {
                                if plane_of(&piece).is_some() {
                                    side.push(tree.triangles.len() as u32);
                                    tree.triangles.push(piece);
                                }
                            }
                        }
                    }
                }
            }
            let me = tree.nodes.len() as u32;
            tree.nodes.push(Node { n, d, triangles: on, front: None, back: None });
            if let Some((p, is_front)) = parent {
                let node = &mut tree.nodes[p as usize];
                if is_front { node.front = Some(me) } else { node.back = Some(me) }
            }
            if !front.is_empty() {
                work.push((front, Some((me, true)), depth + 1));
            }
            if !back.is_empty() {
                work.push((back, Some((me, false)), depth + 1));
            }
        }
        tree
    }

    /// The plane of a node over `set`: of eight candidate triangles' planes, the one that splits
    /// the fewest triangles of a sample and divides it most evenly (eight candidates against up
    /// to 64 triangles), so that the tree stays small and shallow; a free plane when the set is
    /// large and even the best leaves one side of the sample empty (a chain step) and a free
    /// plane divides it better.
    fn splitter(&self, set: &[u32], eps: f64, depth: usize) -> (Vec3, f64) {
        let plane = |i: usize| plane_of(&self.triangles[set[i] as usize]).expect("degenerate triangles filtered");
        if set.len() <= 8 {
            return plane(0);
        }
        let m = 64.min(set.len());
        let sample: Vec<&Triangle> = (0..m).map(|k| &self.triangles[set[k * set.len() / m] as usize]).collect();
        let (score, (n, d)) = (0..8)
            .map(|c| {
                let (n, d) = plane(c * set.len() / 8);
                (sides(&sample, n, d, eps), (n, d))
            })
            .min_by_key(|((splits, front, back), _)| 8 * splits + front.abs_diff(*back))
            .expect("eight candidates");
        let (_, front, back) = score;
        if front.min(back) > 0 || set.len() < FREE_PLANE_SET || depth >= FREE_PLANE_DEPTH {
            return (n, d);
        }
        self.median_plane(set)
            .filter(|&(n, d)| {
                // Both sides non-empty and few splits, so that the children are smaller.
                let (splits, f, b) = sides(&sample, n, d, eps);
                f > 0 && b > 0 && splits <= f.min(b)
            })
            .unwrap_or((n, d))
    }

    /// The plane across the longest extent of the centroids of `set`, through their median.
    fn median_plane(&self, set: &[u32]) -> Option<(Vec3, f64)> {
        let centroid = |i: &u32| {
            let v = &self.triangles[*i as usize].v;
            (v[0].p + v[1].p + v[2].p) / 3.0
        };
        let bounds = set.iter().map(centroid).fold(alhazen_math::Bounds3::EMPTY, |b, c| b.grow(c));
        let axis = bounds.extent().max_position();
        if bounds.extent()[axis] <= 0.0 {
            return None;
        }
        let mut coords: Vec<f64> = set.iter().map(|i| centroid(i)[axis]).collect();
        let mid = coords.len() / 2;
        let (_, median, _) = coords.select_nth_unstable_by(mid, f64::total_cmp);
        let mut n = Vec3::ZERO;
        n[axis] = 1.0;
        Some((n, *median))
    }

    /// The triangles from the farthest to the nearest as seen by `viewer`.
    pub fn back_to_front(&self, viewer: Viewer) -> Vec<u32> {
        let mut out = Vec::with_capacity(self.triangles.len());
        if self.nodes.is_empty() {
            return out;
        }
        // Stack of (node, expanded): an expanded node emits its own triangles when popped.
        let mut stack = vec![(0u32, false)];
        while let Some((k, expanded)) = stack.pop() {
            let node = &self.nodes[k as usize];
            if expanded {
                out.extend(&node.triangles);
                continue;
            }
            let in_front = match viewer {
                Viewer::At(e) => node.n.dot(e) - node.d >= 0.0,
                Viewer::Towards(w) => node.n.dot(w) >= 0.0,
            };
            let (far, near) = if in_front { (node.back, node.front) } else { (node.front, node.back) };
            // Pushed in reverse: far subtree first, then the node, then the near subtree.
            if let Some(n) = near {
                stack.push((n, false));
            }
            stack.push((k, true));
            if let Some(f) = far {
                stack.push((f, false));
            }
        }
        out
    }

    /// Number of triangles in the tree (split pieces, not the triangles they replace).
    pub fn len(&self) -> usize {
        self.nodes.iter().map(|n| n.triangles.len()).sum()
    }

    /// The number of nodes on the longest path from the root.
    pub fn depth(&self) -> usize {
        let mut deepest = 0;
        let mut stack: Vec<(u32, usize)> = if self.nodes.is_empty() { vec![] } else { vec![(0, 1)] };
        while let Some((k, d)) = stack.pop() {
            deepest = deepest.max(d);
            let node = &self.nodes[k as usize];
            stack.extend([node.front, node.back].into_iter().flatten().map(|c| (c, d + 1)));
        }
        deepest
    }

    /// True when there is nothing to draw.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// Checks the partition: every triangle of a subtree lies on its side of each ancestor's
    /// plane (within `eps`). For tests.
    pub fn is_consistent(&self, eps: f64) -> bool {
        let mut stack: Vec<(u32, Vec<Side>)> = vec![(0, vec![])];
        while let Some((k, constraints)) = stack.pop() {
            let Some(node) = self.nodes.get(k as usize) else { return true };
            for &i in &node.triangles {
                for v in &self.triangles[i as usize].v {
                    for (n, d, front) in &constraints {
                        let s = n.dot(v.p) - d;
                        if (*front && s < -eps) || (!*front && s > eps) {
                            return false;
                        }
                    }
                }
            }
            for (child, front) in [(node.front, true), (node.back, false)] {
                if let Some(c) = child {
                    let mut next = constraints.clone();
                    next.push((node.n, node.d, front));
                    stack.push((c, next));
                }
            }
        }
        true
    }
}

/// Depth below which a node may take a free plane (bounds the splitting of long triangles).
const FREE_PLANE_DEPTH: usize = 48;
/// Sets smaller than this always take a triangle's plane: a chain over them costs less than the
/// triangles a free plane would split.
const FREE_PLANE_SET: usize = 1024;

/// How many triangles of `sample` the plane `n·p = d` splits, and how many lie wholly in front
/// and wholly behind.
fn sides(sample: &[&Triangle], n: Vec3, d: f64, eps: f64) -> (usize, usize, usize) {
    let (mut splits, mut front, mut back) = (0usize, 0usize, 0usize);
    for t in sample {
        let s = t.v.map(|v| n.dot(v.p) - d);
        match (s.iter().any(|x| *x > eps), s.iter().any(|x| *x < -eps)) {
            (true, true) => splits += 1,
            (true, false) => front += 1,
            (false, true) => back += 1,
            _ => {}
        }
    }
    (splits, front, back)
}

/// The plane `n·p = d` of a triangle (unit `n`), `None` when it is degenerate.
fn plane_of(t: &Triangle) -> Option<(Vec3, f64)> {
    let n = (t.v[1].p - t.v[0].p).cross(t.v[2].p - t.v[0].p).try_normalize()?;
    Some((n, n.dot(t.v[0].p)))
}
