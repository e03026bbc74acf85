//! A halfedge polygon mesh (course, §"Representations of 3D scenes": each edge is a pair of
//! oppositely oriented halfedges; a halfedge knows its origin, its twin, the next halfedge of its
//! facet and its facet). Facets are arbitrary simple polygons without holes.

use alhazen_math::Vec3;
use std::collections::HashMap;

/// Index of a halfedge.
pub type HalfedgeId = usize;

/// One oriented side of an edge.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Halfedge {
    /// The vertex it starts at.
    pub origin: usize,
    /// The opposite halfedge, `None` on the boundary.
    pub twin: Option<HalfedgeId>,
    /// The next halfedge around the same facet.
    pub next: HalfedgeId,
    /// The facet it bounds.
    pub face: usize,
}

/// Why polygons do not form a manifold mesh.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum MeshBuildError {
    /// A facet has fewer than 3 vertices, repeats a vertex or names a missing one.
    BadFacet(usize),
    /// The same directed edge occurs twice (inconsistent orientation or a non-manifold edge).
    NonManifoldEdge(usize, usize),
}

impl std::fmt::Display for MeshBuildError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::BadFacet(i) => write!(f, "facet {i} needs at least 3 distinct existing vertices"),
            Self::NonManifoldEdge(a, b) => write!(f, "the edge {a}→{b} is used twice (orientation or manifoldness)"),
        }
    }
}

impl std::error::Error for MeshBuildError {}

/// A polygon mesh with halfedge connectivity.
#[derive(Clone, Debug, PartialEq)]
pub struct HalfedgeMesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// All halfedges; those of facet `f` are consecutive.
    pub halfedges: Vec<Halfedge>,
    /// For each facet, its first halfedge.
    pub faces: Vec<HalfedgeId>,
    /// For each vertex, one outgoing halfedge (`None` for an isolated vertex).
    pub vertex_out: Vec<Option<HalfedgeId>>,
}

impl HalfedgeMesh {
    /// Builds the connectivity from counter-clockwise polygons.
    pub fn from_polygons(positions: Vec<Vec3>, polygons: &[Vec<usize>]) -> Result<Self, MeshBuildError> {
        let mut halfedges = Vec::new();
        let mut faces = Vec::with_capacity(polygons.len());
        let mut directed: HashMap<(usize, usize), HalfedgeId> = HashMap::new();
        let mut vertex_out = vec![None; positions.len()];
        for (f, poly) in polygons.iter().enumerate() {
            let distinct = poly.iter().collect::<std::collections::HashSet<_>>().len() == poly.len();
            if poly.len() < 3 || !distinct || poly.iter().any(|&v| v >= positions.len()) {
                return Err(MeshBuildError::BadFacet(f));
            }
            let base = halfedges.len();
            faces.push(base);
            for (k, &v) in poly.iter().enumerate() {
                let w = poly[(k + 1) % poly.len()];
                if directed.insert((v, w), base + k).is_some() {
                    return Err(MeshBuildError::NonManifoldEdge(v, w));
                }
                halfedges.push(Halfedge { origin: v, twin: None, next: base + (k + 1) % poly.len(), face: f });
                vertex_out[v].get_or_insert(base + k);
            }
        }
        for (&(v, w), &h) in &directed {
            halfedges[h].twin = directed.get(&(w, v)).copied();
        }
        // Boundary vertices start at their boundary halfedge, so that walks around them are
        // complete.
        for h in 0..halfedges.len() {
            if halfedges[h].twin.is_none() {
                vertex_out[halfedges[h].origin] = Some(h);
            }
        }
        Ok(Self { positions, halfedges, faces, vertex_out })
    }

    /// The vertex a halfedge points to.
    pub fn target(&self, h: HalfedgeId) -> usize {
        self.halfedges[self.halfedges[h].next].origin
    }

    /// The halfedges of a facet, in order.
    pub fn face_halfedges(&self, f: usize) -> Vec<HalfedgeId> {
        let start = self.faces[f];
        let mut out = vec![start];
        let mut h = self.halfedges[start].next;
        while h != start {
            out.push(h);
            h = self.halfedges[h].next;
        }
        out
    }

    /// The vertices of a facet, in order.
    pub fn face_vertices(&self, f: usize) -> Vec<usize> {
        self.face_halfedges(f).into_iter().map(|h| self.halfedges[h].origin).collect()
    }

    /// The previous halfedge around the facet.
    pub fn prev(&self, h: HalfedgeId) -> HalfedgeId {
        let mut p = h;
        while self.halfedges[p].next != h {
            p = self.halfedges[p].next;
        }
        p
    }

    /// Outgoing halfedges of a vertex, walking across twins; for boundary vertices the walk
    /// starts at the boundary and covers the fan.
    pub fn outgoing(&self, v: usize) -> Vec<HalfedgeId> {
        let Some(start) = self.vertex_out[v] else { return vec![] };
        let mut out = vec![start];
        let mut h = start;
        // Rotate: previous halfedge's twin is the next outgoing one (clockwise around v).
        while let Some(t) = self.halfedges[self.prev(h)].twin {
            if t == start {
                break;
            }
            out.push(t);
            h = t;
        }
        out
    }

    /// True when the vertex lies on the boundary.
    pub fn is_boundary_vertex(&self, v: usize) -> bool {
        self.outgoing(v)
            .iter()
            .any(|&h| self.halfedges[h].twin.is_none() || self.halfedges[self.prev(h)].twin.is_none())
    }

    /// Number of undirected edges.
    pub fn edge_count(&self) -> usize {
        self.halfedges.iter().enumerate().filter(|(i, h)| h.twin.is_none_or(|t| *i < t)).count()
    }

    /// Euler characteristic `V − E + F`.
    pub fn euler_characteristic(&self) -> i64 {
        self.positions.len() as i64 - self.edge_count() as i64 + self.faces.len() as i64
    }

    /// True when every edge has two facets.
    pub fn is_closed(&self) -> bool {
        self.halfedges.iter().all(|h| h.twin.is_some())
    }

    /// The centroid of a facet.
    pub fn face_centroid(&self, f: usize) -> Vec3 {
        let vs = self.face_vertices(f);
        vs.iter().map(|&v| self.positions[v]).sum::<Vec3>() / vs.len() as f64
    }

    /// The polygons (vertex lists), e.g. to triangulate for rendering.
    pub fn polygons(&self) -> Vec<Vec<usize>> {
        (0..self.faces.len()).map(|f| self.face_vertices(f)).collect()
    }

    /// A unit cube `[-1, 1]³` with outward-facing quads.
    pub fn cube() -> Self {
        let p = |x: f64, y: f64, z: f64| Vec3::new(x, y, z);
        let positions = vec![
            p(-1., -1., -1.),
            p(1., -1., -1.),
            p(1., 1., -1.),
            p(-1., 1., -1.),
            p(-1., -1., 1.),
            p(1., -1., 1.),
            p(1., 1., 1.),
            p(-1., 1., 1.),
        ];
        let quads = vec![
            vec![0, 3, 2, 1],
            vec![4, 5, 6, 7],
            vec![0, 1, 5, 4],
            vec![2, 3, 7, 6],
            vec![0, 4, 7, 3],
            vec![1, 2, 6, 5],
        ];
        Self::from_polygons(positions, &quads).expect("the cube is a closed manifold")
    }
}
