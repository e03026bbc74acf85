//! The finite elements (course, §"The energetic balance method": "dividing the surfaces into
//! small enough finite elements"): every surface of the scene as the preview's world-space
//! triangles, each the root of a quadtree of triangles (the course's quadtree, on a triangle:
//! four children by the edge midpoints). The nodes at the *patch level* shoot light; the leaves
//! below them are the elements, refined while the solution is computed where the light changes
//! (near bright shooters, along shadow boundaries).
//!
//! Unbounded planes are cut to a square around the rest of the scene (an element needs an
//! area); the square's size is reported.

use alhazen_math::{Bounds3, Vec2, Vec3};
use alhazen_scene::{Scene, Shape};

/// A surface triangle of the scene: the root of one quadtree.
#[derive(Clone, Copy, Debug)]
pub struct InputTriangle {
    /// Corners, counter-clockwise seen from the front.
    pub p: [Vec3; 3],
    /// Shading normals at the corners.
    pub n: [Vec3; 3],
    /// Texture coordinates at the corners.
    pub uv: [Vec2; 3],
    /// Vertex colours at the corners (white where the mesh has none).
    pub color: [Vec3; 3],
    /// Unit geometric normal (the front).
    pub normal: Vec3,
    /// Area.
    pub area: f64,
    /// Material index.
    pub material: u32,
    /// Scene object.
    pub object: u32,
    /// Part of a closed surface: only its front (the outside) takes part.
    pub closed: bool,
}

impl InputTriangle {
    /// How many sides take part: the front, and the back of an open surface.
    #[inline]
    pub fn sides(&self) -> usize {
        if self.closed { 1 } else { 2 }
    }

    /// The point of barycentric coordinates `(b1, b2)` (weights of corners 1 and 2).
    #[inline]
    pub fn at(&self, b: [f64; 2]) -> Vec3 {
        self.p[0] + (self.p[1] - self.p[0]) * b[0] + (self.p[2] - self.p[0]) * b[1]
    }

    /// Texture coordinates at `(b1, b2)`.
    #[inline]
    pub fn uv_at(&self, b: [f64; 2]) -> Vec2 {
        self.uv[0] + (self.uv[1] - self.uv[0]) * b[0] + (self.uv[2] - self.uv[0]) * b[1]
    }

    /// Vertex colour at `(b1, b2)`.
    #[inline]
    pub fn color_at(&self, b: [f64; 2]) -> Vec3 {
        self.color[0] + (self.color[1] - self.color[0]) * b[0] + (self.color[2] - self.color[0]) * b[1]
    }

    /// Shading normal at `(b1, b2)`.
    #[inline]
    pub fn normal_at(&self, b: [f64; 2]) -> Vec3 {
        (self.n[0] + (self.n[1] - self.n[0]) * b[0] + (self.n[2] - self.n[0]) * b[1]).normalize_or(self.normal)
    }

    /// Barycentric coordinates `(b1, b2)` of `p` projected on the triangle's plane.
    pub fn barycentric(&self, p: Vec3) -> [f64; 2] {
        let (e1, e2, d) = (self.p[1] - self.p[0], self.p[2] - self.p[0], p - self.p[0]);
        let (a, b, c) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
        let (u, v) = (d.dot(e1), d.dot(e2));
        let det = a * c - b * b;
        [(c * u - b * v) / det, (a * v - b * u) / det]
    }

    /// The longest edge's length.
    pub fn longest_edge(&self) -> f64 {
        (0..3).map(|k| (self.p[(k + 1) % 3] - self.p[k]).length()).fold(0.0, f64::max)
    }
}

/// The scene's surfaces as triangles, with how many unbounded planes were cut to a square (and
/// its side) and how many CSG objects have no triangle form.
pub struct Surfaces {
    /// The triangles (degenerate ones left out).
    pub triangles: Vec<InputTriangle>,
    /// Planes cut to a square of side `plane_side`.
    pub planes: usize,
    /// The side of those squares.
    pub plane_side: f64,
    /// CSG objects left out.
    pub skipped: usize,
}

/// The surfaces of `scene`, tessellated as the preview tessellates them.
pub fn surfaces(scene: &Scene) -> Surfaces {
    let tess = alhazen_raster::pipeline::geometry::scene_triangles(scene);
    let bounded = tess.triangles.iter().filter(|t| !t.unbounded);
    let bounds = bounded.fold(Bounds3::EMPTY, |b, t| t.v.iter().fold(b, |b, v| b.grow(v.p)));
    let (center, size) = if bounds.is_empty() {
        (Vec3::ZERO, 10.0)
    } else {
        (bounds.centroid(), (4.0 * bounds.extent().length()).max(1e-6))
    };
    let mut out = Vec::with_capacity(tess.triangles.len());
    let mut planes = 0;
    for t in tess.triangles.iter().filter(|t| !t.unbounded) {
        push(&mut out, t.v.map(|v| (v.p, v.n, v.uv, v.color)), (t.material, t.object, t.closed));
    }
    for (i, o) in scene.objects.iter().enumerate() {
        if let Shape::Plane { point, normal } = o.shape {
            let material = o.material;
            let (point, normal) = (o.transform.point(point), o.transform.normal(normal).normalize());
            planes += 1;
            for corners in plane_square(point, normal, center, size) {
                push(&mut out, corners.map(|(p, n, uv)| (p, n, uv, Vec3::ONE)), (material, i as u32, false));
            }
        }
    }
    Surfaces { triangles: out, planes, plane_side: size, skipped: tess.skipped }
}

/// A corner: position, shading normal, texture coordinates, vertex colour.
type Corner = (Vec3, Vec3, Vec2, Vec3);

fn push(out: &mut Vec<InputTriangle>, v: [Corner; 3], (material, object, closed): (u32, u32, bool)) {
    let p = v.map(|c| c.0);
    let cross = (p[1] - p[0]).cross(p[2] - p[0]);
    let area = 0.5 * cross.length();
    if area.is_nan() || area <= 0.0 || !area.is_finite() {
        return;
    }
    let normal = cross.normalize();
    let n = v.map(|c| if c.1.dot(normal) > 0.0 { c.1.normalize() } else { normal });
    let (uv, color) = (v.map(|c| c.2), v.map(|c| c.3));
    out.push(InputTriangle { p, n, uv, color, normal, area, material, object, closed });
}

/// The square of side `size` of the plane `(point, normal)` centred where `center` projects,
/// as eight triangles (a 2 × 2 grid), texture coordinates as the ray tracer's plane has them.
fn plane_square(point: Vec3, normal: Vec3, center: Vec3, size: f64) -> Vec<[(Vec3, Vec3, Vec2); 3]> {
    let (tu, tv) = alhazen_math::orthonormal_basis(normal);
    let mid = center - normal * (center - point).dot(normal);
    let at = |i: usize, j: usize| {
        let p = mid + tu * ((j as f64 - 1.0) * 0.5 * size) + tv * ((i as f64 - 1.0) * 0.5 * size);
        let d = p - point;
        (p, normal, Vec2::new(d.dot(tu), d.dot(tv)))
    };
    let mut out = vec![];
    let flip = tu.cross(tv).dot(normal) < 0.0;
    for i in 0..2 {
        for j in 0..2 {
            let (a, b, c, d) = (at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i + 1, j));
            if flip {
                out.push([a, c, b]);
                out.push([a, d, c]);
            } else {
                out.push([a, b, c]);
                out.push([a, c, d]);
            }
        }
    }
    out
}

/// What one side of a node has received.
#[derive(Clone, Copy, Debug, Default)]
pub struct Side {
    /// Irradiance received in all (`Σ_j G_ij/π · B_j`, W/m² per unit of the scene's radiance
    /// units).
    pub h: Vec3,
    /// The part of `h` whose reflection has not been shot yet.
    pub unshot: Vec3,
}

/// A node of an element quadtree.
#[derive(Clone, Copy, Debug)]
pub struct Node {
    /// Corners as barycentric coordinates `(b1, b2)` in the input triangle.
    pub bary: [[f64; 2]; 3],
    /// Index of the first of four children, 0 for a leaf.
    pub children: u32,
    /// Depth below the input triangle.
    pub level: u8,
    /// Diffuse reflectance (albedo, `π ρ` of the course) averaged over the node.
    pub rho: Vec3,
    /// Front and back.
    pub side: [Side; 2],
    /// The front's emission is still to be shot.
    pub emission_unshot: bool,
    /// Index of the patch (in [`Tree::patches`]) the node belongs to; [`NO_PATCH`] above the
    /// patch level.
    pub patch: u32,
    /// Irradiance received by the whole node and not yet handed down to its leaves (front,
    /// back): the hierarchy's push, done when the leaves' values are needed.
    pub pending: [Vec3; 2],
    /// `Σ area · ρ` over the leaves below (the node's own when a leaf).
    pub rho_area: Vec3,
    /// The parent (the root's is itself).
    pub parent: u32,
}

/// [`Node::patch`] of nodes above the patch level.
pub const NO_PATCH: u32 = u32::MAX;

impl Node {
    /// True for an element.
    #[inline]
    pub fn is_leaf(&self) -> bool {
        self.children == 0
    }

    /// The radiosity side `s` still has to shoot: its emission (until shot) and its reflection
    /// of the unshot irradiance.
    #[inline]
    pub fn unshot(&self, s: usize, emission: Vec3) -> Vec3 {
        let e = if s == 0 && self.emission_unshot { emission } else { Vec3::ZERO };
        e + self.rho * self.side[s].unshot
    }
}

/// The quadtree of one input triangle.
#[derive(Clone, Debug)]
pub struct Tree {
    /// Node 0 is the whole triangle.
    pub nodes: Vec<Node>,
    /// The nodes that shoot (the patch level).
    pub patches: Vec<u32>,
    /// Unshot power (area × luminance) of each patch, front and back.
    pub power: Vec<[f64; 2]>,
    /// Emitted radiosity `π L_e` of the front.
    pub emission: Vec3,
    /// Deepest level refinement may reach.
    pub max_level: u8,
    /// Most nodes refinement may make (the tree's share of the scene's budget).
    pub max_nodes: usize,
    /// The input triangle's area.
    pub area: f64,
}

/// The four children of a triangle of corners `[a, b, c]`: three at the corners and the
/// middle one, whose corners are the midpoints `[bc, ca, ab]`.
pub fn split(c: [[f64; 2]; 3]) -> [[[f64; 2]; 3]; 4] {
    let mid = |i: usize, j: usize| [0.5 * (c[i][0] + c[j][0]), 0.5 * (c[i][1] + c[j][1])];
    let (ab, bc, ca) = (mid(0, 1), mid(1, 2), mid(2, 0));
    [[c[0], ab, ca], [ab, c[1], bc], [ca, bc, c[2]], [bc, ca, ab]]
}

/// Which child of [`split`] holds the point of local barycentric weights `l` (of corners a, b,
/// c), and its weights in that child.
#[inline]
pub fn child_of(l: [f64; 3]) -> (usize, [f64; 3]) {
    if l[0] >= 0.5 {
        (0, [2.0 * l[0] - 1.0, 2.0 * l[1], 2.0 * l[2]])
    } else if l[1] >= 0.5 {
        (1, [2.0 * l[0], 2.0 * l[1] - 1.0, 2.0 * l[2]])
    } else if l[2] >= 0.5 {
        (2, [2.0 * l[0], 2.0 * l[1], 2.0 * l[2] - 1.0])
    } else {
        (3, [1.0 - 2.0 * l[0], 1.0 - 2.0 * l[1], 1.0 - 2.0 * l[2]])
    }
}

impl Tree {
    /// The leaf holding the point of barycentric coordinates `b` in the input triangle, and the
    /// point's weights of that leaf's corners.
    pub fn locate(&self, b: [f64; 2]) -> (u32, [f64; 3]) {
        let mut l = [1.0 - b[0] - b[1], b[0], b[1]];
        let mut i = 0u32;
        while !self.nodes[i as usize].is_leaf() {
            let (k, inner) = child_of(l);
            i = self.nodes[i as usize].children + k as u32;
            l = inner;
        }
        (i, l)
    }

    /// The area of node `i`.
    #[inline]
    pub fn node_area(&self, i: u32) -> f64 {
        self.area / 4f64.powi(self.nodes[i as usize].level as i32)
    }

    /// Splits leaf `i` into four, each inheriting what it received; `rho` gives a child's
    /// reflectance from its corners. The sums `ρ · area` above it follow.
    pub fn subdivide(&mut self, i: u32, rho: impl Fn([[f64; 2]; 3]) -> Vec3) {
        let parent = self.nodes[i as usize];
        debug_assert!(parent.is_leaf());
        let first = self.nodes.len() as u32;
        let area = self.node_area(i) / 4.0;
        let mut sum = Vec3::ZERO;
        for bary in split(parent.bary) {
            let rho = rho(bary);
            sum += rho * area;
            let level = parent.level + 1;
            let pending = [Vec3::ZERO; 2];
            self.nodes.push(Node { bary, children: 0, level, rho, pending, rho_area: rho * area, parent: i, ..parent });
        }
        self.nodes[i as usize].children = first;
        let delta = sum - parent.rho_area;
        let mut k = i;
        loop {
            self.nodes[k as usize].rho_area += delta;
            if k == 0 {
                break;
            }
            k = self.nodes[k as usize].parent;
        }
    }

    /// Hands the irradiance pending at node `i` and below down to the leaves.
    pub fn push_down(&mut self, i: u32) {
        let mut stack = vec![i];
        while let Some(n) = stack.pop() {
            let node = &mut self.nodes[n as usize];
            let pending = std::mem::take(&mut node.pending);
            if node.is_leaf() {
                for (side, p) in node.side.iter_mut().zip(pending) {
                    side.h += p;
                    side.unshot += p;
                }
                continue;
            }
            let first = node.children;
            for c in first..first + 4 {
                let child = &mut self.nodes[c as usize];
                child.pending[0] += pending[0];
                child.pending[1] += pending[1];
                stack.push(c);
            }
        }
    }

    /// The leaves below node `i` (itself when it is one).
    pub fn leaves_below(&self, i: u32, out: &mut Vec<u32>) {
        out.clear();
        let mut stack = vec![i];
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n as usize];
            if node.is_leaf() {
                out.push(n);
            } else {
                stack.extend((0..4).rev().map(|k| node.children + k));
            }
        }
    }

    /// The number of leaves.
    pub fn elements(&self) -> usize {
        self.nodes.iter().filter(|n| n.is_leaf()).count()
    }
}

/// Depth of the patch level for a triangle whose longest edge is `edge`: edges of at most
/// `patch_size` (the deepest allowed is `cap`).
pub fn patch_level(edge: f64, patch_size: f64, cap: u8) -> u8 {
    let mut level = 0u8;
    let mut e = edge;
    while e > patch_size && level < cap {
        e *= 0.5;
        level += 1;
    }
    level
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_point_is_found_in_the_leaf_that_holds_it() {
        let mut tree = Tree {
            nodes: vec![Node {
                bary: [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]],
                children: 0,
                level: 0,
                rho: Vec3::ONE,
                side: [Side::default(); 2],
                emission_unshot: false,
                patch: 0,
                pending: [Vec3::ZERO; 2],
                rho_area: Vec3::ONE,
                parent: 0,
            }],
            patches: vec![0],
            power: vec![[0.0; 2]],
            emission: Vec3::ZERO,
            max_level: 4,
            max_nodes: 1000,
            area: 1.0,
        };
        tree.subdivide(0, |_| Vec3::ONE);
        tree.subdivide(4, |_| Vec3::ONE); // the middle child
        tree.subdivide(1, |_| Vec3::ONE);
        let mut state = 12345u64;
        let mut next = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..2000 {
            let (mut b1, mut b2) = (next(), next());
            if b1 + b2 > 1.0 {
                (b1, b2) = (1.0 - b1, 1.0 - b2);
            }
            let (leaf, w) = tree.locate([b1, b2]);
            let c = tree.nodes[leaf as usize].bary;
            let back = [0, 1].map(|k| w[0] * c[0][k] + w[1] * c[1][k] + w[2] * c[2][k]);
            assert!((back[0] - b1).abs() < 1e-12 && (back[1] - b2).abs() < 1e-12, "{b1}, {b2} → {back:?}");
            assert!(w.iter().all(|&x| x > -1e-12), "weights inside the leaf: {w:?}");
        }
        assert_eq!(tree.elements(), 10);
        // The leaves' ρ · area add up at the root: 10 leaves of ρ = 1 over the area 1.
        assert!((tree.nodes[0].rho_area - Vec3::ONE).abs().max_element() < 1e-15);
    }

    #[test]
    fn barycentric_coordinates_invert_at() {
        let t = InputTriangle {
            p: [Vec3::new(1.0, 0.0, 0.0), Vec3::new(3.0, 1.0, 0.5), Vec3::new(0.0, 2.0, 1.0)],
            n: [Vec3::Z; 3],
            uv: [Vec2::ZERO; 3],
            color: [Vec3::ONE; 3],
            normal: Vec3::Z,
            area: 1.0,
            material: 0,
            object: 0,
            closed: false,
        };
        let b = t.barycentric(t.at([0.25, 0.6]));
        assert!((b[0] - 0.25).abs() < 1e-12 && (b[1] - 0.6).abs() < 1e-12);
    }
}
