//! `alhazen-geom`: geometric data that the scene, the renderer and the line drawer share.
//!
//! * [`TriangleMesh`], an indexed triangle list (course, §"Representations of 3D scenes": a
//!   boundary representation reduced to the list of triangles needed to draw a solid);
//! * [`bezier`], Bézier curves (course, §"Elements of geometric design");
//! * [`bspline`], B-spline and NURBS curves (course, §"B-spline curves", rational curves);
//! * [`construct`]: cubic interpolation, lofting, sweeps, spherical products;
//! * [`patch`], tensor-product Bézier and B-spline patches, rational normals by the 4D wedge;
//! * [`halfedge`] polygon meshes and their [`subdivision`] (Catmull–Clark, Doo–Sabin);
//! * [`tessellate`]: patches, polygon meshes and tubes around curves as triangle meshes.
//!
//! ```
//! use alhazen_geom::TriangleMesh;
//! use alhazen_math::Vec3;
//! let m = TriangleMesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]]).unwrap();
//! assert_eq!(m.triangle_count(), 1);
//! ```

pub mod bezier;
pub mod bspline;
pub mod construct;
pub mod halfedge;
pub mod patch;
pub mod subdivision;
pub mod tessellate;

use alhazen_math::{Bounds3, Vec2, Vec3};

/// Why a mesh is unusable.
#[derive(Clone, Debug, PartialEq)]
pub enum MeshError {
    /// A triangle names a vertex that does not exist.
    IndexOutOfRange {
        /// Triangle number.
        triangle: usize,
        /// The bad index.
        index: u32,
    },
    /// A vertex position is NaN or infinite.
    NonFiniteVertex(usize),
    /// Per-vertex attribute arrays differ in length from the positions.
    AttributeLength(&'static str),
    /// A vertex colour is negative, NaN or infinite.
    BadColor(usize),
    /// No triangles.
    Empty,
}

impl std::fmt::Display for MeshError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::IndexOutOfRange { triangle, index } => {
                write!(f, "triangle {triangle} uses vertex {index}, which does not exist")
            }
            Self::NonFiniteVertex(i) => write!(f, "vertex {i} has a non-finite coordinate"),
            Self::AttributeLength(a) => write!(f, "the {a} array does not match the vertex count"),
            Self::BadColor(i) => write!(f, "vertex {i}'s colour is not finite and ≥ 0"),
            Self::Empty => write!(f, "the mesh has no triangles"),
        }
    }
}

impl std::error::Error for MeshError {}

/// An indexed triangle mesh with optional per-vertex normals, texture coordinates and colours,
/// and an optional per-triangle material slot.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriangleMesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Per-vertex shading normals (same length as `positions`) or empty.
    pub normals: Vec<Vec3>,
    /// Per-vertex texture coordinates (same length as `positions`) or empty.
    pub uvs: Vec<Vec2>,
    /// Per-vertex linear RGB colours (same length as `positions`) or empty: what a material
    /// with `vertex_colors` multiplies its base colour by (glTF's `COLOR_0`, a PLY's `red`,
    /// `green`, `blue`).
    pub colors: Vec<Vec3>,
    /// Vertex indices, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
    /// Per-triangle material slot (index into `material_names`) or empty.
    pub material_slots: Vec<u32>,
    /// Names of the materials the slots refer to.
    pub material_names: Vec<String>,
}

impl TriangleMesh {
    /// A validated mesh from positions and triangles.
    pub fn new(positions: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Result<Self, MeshError> {
        let m = Self { positions, triangles, ..Self::default() };
        m.validate()?;
        Ok(m)
    }

    /// Checks indices, finiteness and attribute lengths.
    pub fn validate(&self) -> Result<(), MeshError> {
        if self.triangles.is_empty() {
            return Err(MeshError::Empty);
        }
        if let Some(i) = self.positions.iter().position(|p| !p.is_finite()) {
            return Err(MeshError::NonFiniteVertex(i));
        }
        let n = self.positions.len() as u32;
        for (t, tri) in self.triangles.iter().enumerate() {
            if let Some(&index) = tri.iter().find(|&&i| i >= n) {
                return Err(MeshError::IndexOutOfRange { triangle: t, index });
            }
        }
        if !self.normals.is_empty() && self.normals.len() != self.positions.len() {
            return Err(MeshError::AttributeLength("normal"));
        }
        if !self.uvs.is_empty() && self.uvs.len() != self.positions.len() {
            return Err(MeshError::AttributeLength("texture coordinate"));
        }
        if !self.colors.is_empty() && self.colors.len() != self.positions.len() {
            return Err(MeshError::AttributeLength("colour"));
        }
        if let Some(i) = self.colors.iter().position(|c| !(c.is_finite() && c.min_element() >= 0.0)) {
            return Err(MeshError::BadColor(i));
        }
        if !self.material_slots.is_empty() && self.material_slots.len() != self.triangles.len() {
            return Err(MeshError::AttributeLength("material slot"));
        }
        Ok(())
    }

    /// The solid box `[min, max]` as twelve triangles, two per face, counter-clockwise seen
    /// from outside.
    pub fn cuboid(min: Vec3, max: Vec3) -> Self {
        let positions = (0..8)
            .map(|i| {
                let pick = |bit: usize, lo: f64, hi: f64| if i & bit == 0 { lo } else { hi };
                Vec3::new(pick(1, min.x, max.x), pick(2, min.y, max.y), pick(4, min.z, max.z))
            })
            .collect();
        // Faces as corner quads (bit 0: x, bit 1: y, bit 2: z high), outward winding.
        const FACES: [[u32; 4]; 6] =
            [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
        let triangles = FACES.iter().flat_map(|f| [[f[0], f[1], f[2]], [f[0], f[2], f[3]]]).collect();
        Self { positions, triangles, ..Self::default() }
    }

    /// True when the mesh bounds a solid: every edge, matched by its end points' positions (so
    /// vertices split at texture seams still join), is used exactly once in each direction.
    /// Degenerate triangles (two equal corners) are ignored. By sorting, not hashing: vertices
    /// get one id per distinct position, then the directed edges are sorted (stably) by their
    /// undirected key and each edge's uses are counted in triangle order.
    pub fn is_closed(&self) -> bool {
        let key = |i: u32| self.positions[i as usize].to_array().map(f64::to_bits);
        let mut by_position: Vec<u32> = (0..self.positions.len() as u32).collect();
        by_position.sort_unstable_by_key(|&i| key(i));
        let mut id = vec![0u32; self.positions.len()];
        let mut next = 0u32;
        for (k, &i) in by_position.iter().enumerate() {
            if k > 0 && key(by_position[k - 1]) != key(i) {
                next += 1;
            }
            id[i as usize] = next;
        }
        let mut edges: Vec<(u64, i8)> = Vec::with_capacity(3 * self.triangles.len());
        for t in &self.triangles {
            let k = t.map(|i| id[i as usize] as u64);
            if k[0] == k[1] || k[1] == k[2] || k[0] == k[2] {
                continue;
            }
            for (a, b) in [(k[0], k[1]), (k[1], k[2]), (k[2], k[0])] {
                // +1 for a → b, −1 for b → a, on the edge's canonical key.
                edges.push(if a < b { (a << 32 | b, 1) } else { (b << 32 | a, -1) });
            }
        }
        edges.sort_by_key(|e| e.0);
        let mut count = 0i32;
        for (k, e) in edges.iter().enumerate() {
            if k > 0 && edges[k - 1].0 != e.0 {
                if count != 0 {
                    return false;
                }
                count = 0;
            }
            count += e.1 as i32;
            // A second use in the same direction: not a solid's boundary.
            if count.abs() > 1 {
                return false;
            }
        }
        !edges.is_empty() && count == 0
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// The three corners of triangle `i`.
    #[inline]
    pub fn corners(&self, i: usize) -> [Vec3; 3] {
        self.triangles[i].map(|v| self.positions[v as usize])
    }

    /// Bounding box of all vertices.
    pub fn bounds(&self) -> Bounds3 {
        Bounds3::from_points(self.positions.iter().copied())
    }

    /// Area-weighted vertex normals, for smooth shading of meshes that have none.
    pub fn compute_smooth_normals(&mut self) {
        let mut acc = vec![Vec3::ZERO; self.positions.len()];
        for tri in &self.triangles {
            let [a, b, c] = tri.map(|v| self.positions[v as usize]);
            let n = (b - a).cross(c - a);
            for &v in tri {
                acc[v as usize] += n;
            }
        }
        self.normals = acc.into_iter().map(|n| n.try_normalize().unwrap_or(Vec3::Y)).collect();
    }

    /// Vertex normals weighted by the angle each triangle makes at the vertex (Thürmer and
    /// Wüthrich 1998, "Computing vertex normals from polygonal facets"): a vertex's normal does
    /// not change when a neighbouring face is split. Mitsuba smooths the meshes it is given
    /// without normals so; a vertex on no face of area gets +y.
    /// The corners' weighted normals are found on all threads a block of triangles at a time,
    /// and added to their vertices in triangle order: the same bits on any number of threads.
    pub fn compute_angle_weighted_normals(&mut self) {
        use rayon::prelude::*;
        const BLOCK: usize = 1 << 16;
        let corners = |tri: &[u32; 3]| corner_weights(tri.map(|v| self.positions[v as usize]));
        let mut acc = vec![Vec3::ZERO; self.positions.len()];
        let mut weighted: Vec<[Vec3; 3]> = Vec::with_capacity(BLOCK.min(self.triangles.len()));
        for block in self.triangles.chunks(BLOCK) {
            block.par_iter().map(corners).collect_into_vec(&mut weighted);
            for (tri, w) in block.iter().zip(&weighted) {
                for k in 0..3 {
                    acc[tri[k] as usize] += w[k];
                }
            }
        }
        self.normals = acc.into_par_iter().map(|n| n.try_normalize().unwrap_or(Vec3::Y)).collect();
    }
}

/// A triangle's unit normal weighted by its angle at each corner (zero for a triangle of no
/// area, whose angles may be undefined). Each angle is `atan2(|a × b|, a · b)` of the corner's
/// two edges: accurate at every angle, no edge normalised, our own `atan2` (the library's `acos`
/// was 6 % of loading a world of a million triangles); `|a × b|` is twice the area at every
/// corner, so one cross product serves all three (a third of the time of one per corner).
fn corner_weights(p: [Vec3; 3]) -> [Vec3; 3] {
    let edges = [p[1] - p[0], p[2] - p[1], p[0] - p[2]];
    let normal = edges[0].cross(-edges[2]);
    let twice_area = normal.length();
    if !(twice_area > 0.0 && twice_area.is_finite()) {
        return [Vec3::ZERO; 3];
    }
    let n = normal / twice_area;
    // Corner k's edges run to the next corner (`edges[k]`) and from the one before (`edges[k + 2]`).
    std::array::from_fn(|k| n * alhazen_math::elementary::atan2(twice_area, -edges[k].dot(edges[(k + 2) % 3])))
}

#[cfg(test)]
mod tests {

    /// The definition, by hashing directed edges in triangle order.
    fn closed_by_hashing(m: &TriangleMesh) -> bool {
        use std::collections::HashMap;
        let key = |i: u32| m.positions[i as usize].to_array().map(f64::to_bits);
        let mut edges: HashMap<([u64; 3], [u64; 3]), i32> = HashMap::new();
        for t in &m.triangles {
            let k = t.map(key);
            if k[0] == k[1] || k[1] == k[2] || k[0] == k[2] {
                continue;
            }
            for (a, b) in [(k[0], k[1]), (k[1], k[2]), (k[2], k[0])] {
                let (edge, sign) = if a < b { ((a, b), 1) } else { ((b, a), -1) };
                let count = edges.entry(edge).or_insert(0);
                *count += sign;
                if count.abs() > 1 {
                    return false;
                }
            }
        }
        !edges.is_empty() && edges.values().all(|&c| c == 0)
    }

    proptest::proptest! {
        #[test]
        fn closedness_by_sorting_is_the_definition(
            tris in proptest::collection::vec((0u32..6, 0u32..6, 0u32..6), 0..24),
            duplicate in 0usize..6,
        ) {
            // Six positions, one of them twice (a seam), and triangles over them.
            let mut positions: Vec<Vec3> = (0..6).map(|i| Vec3::new((i % 2) as f64, (i / 2 % 2) as f64, (i / 4) as f64)).collect();
            positions.push(positions[duplicate]);
            let triangles = tris.iter().map(|&(a, b, c)| [a, b, if c == 5 { 6 } else { c }]).collect();
            let m = TriangleMesh { positions, triangles, ..TriangleMesh::default() };
            proptest::prop_assert_eq!(m.is_closed(), closed_by_hashing(&m));
        }

        #[test]
        fn closedness_by_sorting_is_the_definition_near_closed_meshes(
            extra in proptest::collection::vec((0usize..12, proptest::bool::ANY, proptest::bool::ANY), 0..6),
        ) {
            // The cube, with some of its triangles added again, reversed or not, and in pairs.
            let mut m = TriangleMesh::cuboid(Vec3::ZERO, Vec3::ONE);
            for &(k, reversed, pair) in &extra {
                let t = m.triangles[k];
                let r = [t[0], t[2], t[1]];
                m.triangles.push(if reversed { r } else { t });
                if pair {
                    m.triangles.push(if reversed { t } else { r });
                }
            }
            proptest::prop_assert_eq!(m.is_closed(), closed_by_hashing(&m));
        }

        /// Angle-weighted normals are, bit for bit, each vertex's corner weights summed in
        /// triangle order, on one thread or several.
        #[test]
        fn angle_weighted_normals_are_the_sums_in_triangle_order(
            p in proptest::collection::vec(proptest::array::uniform3(-4i8..4), 1..40),
            tris in proptest::collection::vec(proptest::array::uniform3(0usize..64), 0..80),
            threads in 1usize..5,
        ) {
            let positions: Vec<Vec3> = p.iter().map(|c| Vec3::new(c[0] as f64, c[1] as f64 * 0.7, c[2] as f64 * 1.3)).collect();
            let triangles = tris.iter().map(|t| t.map(|v| (v % positions.len()) as u32)).collect();
            let mut m = TriangleMesh { positions, triangles, ..TriangleMesh::default() };
            let mut want = vec![Vec3::ZERO; m.positions.len()];
            for tri in &m.triangles {
                let w = corner_weights(tri.map(|v| m.positions[v as usize]));
                for k in 0..3 {
                    want[tri[k] as usize] += w[k];
                }
            }
            let want: Vec<Vec3> = want.iter().map(|n| n.try_normalize().unwrap_or(Vec3::Y)).collect();
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| m.compute_angle_weighted_normals());
            let bits = |v: &[Vec3]| v.iter().map(|n| n.to_array().map(f64::to_bits)).collect::<Vec<_>>();
            proptest::prop_assert_eq!(bits(&m.normals), bits(&want));
        }

        /// One cross product for a triangle's three corners gives each corner's weight as its
        /// own two edges' `atan2(|a × b|, a · b)` does (to 1e-12), down to slivers; the angles
        /// sum to π.
        #[test]
        fn corner_weights_are_each_corners_angle(
            p in proptest::array::uniform3(proptest::array::uniform3(-10.0..10.0f64)),
            sliver in 0.0..1.0f64,
            thin in 0u32..12,
        ) {
            let mut p = p.map(Vec3::from_array);
            // Now and then the third corner almost on the first two's line.
            if thin > 0 {
                p[2] = p[0].lerp(p[1], sliver * 3.0 - 1.0) + (p[2] - p[0]) * 10f64.powi(-(thin as i32));
            }
            let w = corner_weights(p);
            let Some(n) = (p[1] - p[0]).cross(p[2] - p[0]).try_normalize() else { return Ok(()) };
            let mut sum = 0.0;
            for k in 0..3 {
                let (a, b) = (p[(k + 1) % 3] - p[k], p[(k + 2) % 3] - p[k]);
                let angle = a.cross(b).length().atan2(a.dot(b));
                proptest::prop_assert!((w[k] - n * angle).length() <= 1e-12 * angle.max(1.0), "{k}: {} {angle}", w[k]);
                sum += w[k].dot(n);
            }
            proptest::prop_assert!((sum - std::f64::consts::PI).abs() < 1e-12);
        }
    }

    #[test]
    fn closedness_is_measured_from_the_edges() {
        let cube = TriangleMesh::cuboid(Vec3::ZERO, Vec3::ONE);
        assert!(cube.is_closed());
        // A face missing: open (the lofted sail, the teapot without its bottom).
        let mut open = cube.clone();
        open.triangles.truncate(10);
        assert!(!open.is_closed());
        // Vertices split per face (as at texture seams) still join by position.
        let mut split = TriangleMesh::default();
        for t in &cube.triangles {
            let base = split.positions.len() as u32;
            split.positions.extend(t.map(|i| cube.positions[i as usize]));
            split.triangles.push([base, base + 1, base + 2]);
        }
        assert!(split.is_closed());
        // One face turned inside out: an edge used twice in one direction.
        let mut flipped = cube.clone();
        flipped.triangles[0].swap(1, 2);
        assert!(!flipped.is_closed());
        assert!(!TriangleMesh::default().is_closed());
    }

    use super::*;

    #[test]
    fn cuboid_faces_point_outwards_and_cover_the_surface() {
        let (min, max) = (Vec3::new(-1.0, 0.0, 2.0), Vec3::new(3.0, 0.5, 4.0));
        let m = TriangleMesh::cuboid(min, max);
        let centre = (min + max) * 0.5;
        let mut area = 0.0;
        for i in 0..m.triangle_count() {
            let [a, b, c] = m.corners(i);
            let n = (b - a).cross(c - a);
            assert!(n.dot((a + b + c) / 3.0 - centre) > 0.0, "triangle {i} faces inwards");
            area += 0.5 * n.length();
        }
        let e = max - min;
        assert!((area - 2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)).abs() < 1e-12);
    }

    #[test]
    fn validation_catches_bad_indices_and_nan() {
        let e = TriangleMesh::new(vec![Vec3::ZERO, Vec3::X], vec![[0, 1, 2]]).unwrap_err();
        assert_eq!(e, MeshError::IndexOutOfRange { triangle: 0, index: 2 });
        let e = TriangleMesh::new(vec![Vec3::NAN, Vec3::X, Vec3::Y], vec![[0, 1, 2]]).unwrap_err();
        assert_eq!(e, MeshError::NonFiniteVertex(0));
        assert_eq!(TriangleMesh::new(vec![], vec![]).unwrap_err(), MeshError::Empty);
    }

    #[test]
    fn angle_weighted_normals_ignore_how_a_face_is_split() {
        // A vertex at a cube's corner: three faces of equal angle, one of them split in two; a
        // triangle of no area (a repeated corner) adds nothing.
        let p = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z, Vec3::new(1.0, 1.0, 0.0)];
        let faces = |split: bool| {
            let mut t = vec![[0, 3, 1], [0, 2, 3], [0, 0, 1]];
            t.extend(if split { vec![[0, 1, 4], [0, 4, 2]] } else { vec![[0, 1, 2]] });
            let mut m = TriangleMesh { positions: p.clone(), triangles: t, ..TriangleMesh::default() };
            m.compute_angle_weighted_normals();
            m.normals[0]
        };
        let want = Vec3::ONE.normalize();
        assert!((faces(false) - want).length() < 1e-12 && (faces(true) - want).length() < 1e-12);
    }

    #[test]
    fn smooth_normals_of_a_flat_fan_are_the_face_normal() {
        let mut m =
            TriangleMesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y], vec![[0, 1, 2], [0, 2, 3]])
                .unwrap();
        m.compute_smooth_normals();
        assert!(m.normals.iter().all(|n| (*n - Vec3::Z).length() < 1e-12));
    }
}
