//! Subdivision of irregular meshes (course, §"Mesh methods"): the generalised Lane–Riesenfeld
//! refinement with `n = 3` (Catmull–Clark) and `n = 2` (Doo–Sabin). After one step of
//! Catmull–Clark all facets are quadrilaterals and extraordinary elements are vertices; after
//! Doo–Sabin they are facets.

use crate::halfedge::HalfedgeMesh;
use alhazen_math::Vec3;
use std::collections::HashMap;

/// One Catmull–Clark step: a face point per facet, an edge point per edge, and every vertex
/// moved to `(Q + 2R + (n − 3)S)/n` (interior) or `(S_prev + 6S + S_next)/8` (boundary, the
/// cubic B-spline rule). Boundary edges get their midpoints.
pub fn catmull_clark(m: &HalfedgeMesh) -> HalfedgeMesh {
    let nv = m.positions.len();
    let face_pts: Vec<Vec3> = (0..m.faces.len()).map(|f| m.face_centroid(f)).collect();
    // Edge points, keyed by the smaller halfedge of the pair.
    let mut edge_index: HashMap<usize, usize> = HashMap::new();
    let mut positions: Vec<Vec3> = Vec::with_capacity(nv + m.faces.len() + m.halfedges.len() / 2);
    positions.extend(std::iter::repeat_n(Vec3::ZERO, nv));
    positions.extend(face_pts.iter().copied());
    let key = |h: usize| m.halfedges[h].twin.map_or(h, |t| t.min(h));
    for h in 0..m.halfedges.len() {
        let k = key(h);
        if edge_index.contains_key(&k) {
            continue;
        }
        let (a, b) = (m.positions[m.halfedges[h].origin], m.positions[m.target(h)]);
        let p = match m.halfedges[h].twin {
            Some(t) => (a + b + face_pts[m.halfedges[h].face] + face_pts[m.halfedges[t].face]) / 4.0,
            None => (a + b) / 2.0,
        };
        edge_index.insert(k, positions.len());
        positions.push(p);
    }
    for v in 0..nv {
        positions[v] = moved_vertex(m, v, &face_pts);
    }
    let mut quads = Vec::with_capacity(m.halfedges.len());
    for f in 0..m.faces.len() {
        for h in m.face_halfedges(f) {
            let prev = m.prev(h);
            quads.push(vec![m.halfedges[h].origin, edge_index[&key(h)], nv + f, edge_index[&key(prev)]]);
        }
    }
    HalfedgeMesh::from_polygons(positions, &quads).expect("refinement of a manifold is a manifold")
}

fn moved_vertex(m: &HalfedgeMesh, v: usize, face_pts: &[Vec3]) -> Vec3 {
    let s = m.positions[v];
    let out = m.outgoing(v);
    if out.is_empty() {
        return s;
    }
    if m.is_boundary_vertex(v) {
        // Neighbours along the boundary.
        let next = out.iter().find(|&&h| m.halfedges[h].twin.is_none()).map(|&h| m.positions[m.target(h)]);
        let prev = out
            .iter()
            .map(|&h| m.prev(h))
            .find(|&p| m.halfedges[p].twin.is_none())
            .map(|p| m.positions[m.halfedges[p].origin]);
        return match (prev, next) {
            (Some(a), Some(b)) => (a + s * 6.0 + b) / 8.0,
            _ => s,
        };
    }
    let n = out.len() as f64;
    let q = out.iter().map(|&h| face_pts[m.halfedges[h].face]).sum::<Vec3>() / n;
    let r = out.iter().map(|&h| (s + m.positions[m.target(h)]) / 2.0).sum::<Vec3>() / n;
    (q + r * 2.0 + s * (n - 3.0)) / n
}

/// The limit position of an interior vertex under Catmull–Clark, from its 1-ring:
/// `(n² S + 4 Σ eᵢ + Σ fᵢ) / (n(n + 5))` with the edge neighbours `eᵢ` and the face points `fᵢ`
/// (valid on a mesh of quadrilaterals, i.e. after one step).
pub fn catmull_clark_limit(m: &HalfedgeMesh, v: usize) -> Vec3 {
    let out = m.outgoing(v);
    let n = out.len() as f64;
    let e: Vec3 = out.iter().map(|&h| m.positions[m.target(h)]).sum();
    // The vertex diagonally opposite in each quad.
    let f: Vec3 = out.iter().map(|&h| m.positions[m.target(m.halfedges[h].next)]).sum();
    (m.positions[v] * (n * n) + e * 4.0 + f) / (n * (n + 5.0))
}

/// One Doo–Sabin step (the simple rule: each corner moves to the average of itself, its facet's
/// centroid and the midpoints of its two edges). New facets: one per facet, one quad per interior
/// edge, one polygon per interior vertex.
pub fn doo_sabin(m: &HalfedgeMesh) -> HalfedgeMesh {
    // A new point for every halfedge = every (facet, corner) pair: corner = origin of h.
    let mut positions = Vec::with_capacity(m.halfedges.len());
    for h in 0..m.halfedges.len() {
        let f = m.halfedges[h].face;
        let v = m.positions[m.halfedges[h].origin];
        let next = m.positions[m.target(h)];
        let prev = m.positions[m.halfedges[m.prev(h)].origin];
        positions.push((v + m.face_centroid(f) + (v + next) / 2.0 + (v + prev) / 2.0) / 4.0);
    }
    let mut polys: Vec<Vec<usize>> = (0..m.faces.len()).map(|f| m.face_halfedges(f)).collect();
    for h in 0..m.halfedges.len() {
        if let Some(t) = m.halfedges[h].twin
            && h < t
        {
            // The quad between the two facets along the edge h = (a → b), t = (b → a).
            polys.push(vec![h, m.halfedges[t].next, t, m.halfedges[h].next]);
        }
    }
    for v in 0..m.positions.len() {
        if m.is_boundary_vertex(v) {
            continue;
        }
        let ring: Vec<usize> = m.outgoing(v);
        if ring.len() >= 3 {
            // Corners of v in the facets around it; the rotation order of `outgoing` runs against
            // the edge quads' sides, so the polygon faces outward as it is.
            polys.push(ring);
        }
    }
    HalfedgeMesh::from_polygons(positions, &polys).expect("refinement of a manifold is a manifold")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn catmull_clark_keeps_the_cube_a_closed_quad_manifold() {
        let mut m = HalfedgeMesh::cube();
        for k in 1..=3 {
            m = catmull_clark(&m);
            assert!(m.is_closed());
            assert_eq!(m.euler_characteristic(), 2);
            assert_eq!(m.faces.len(), 6 * 4usize.pow(k));
            assert!(m.polygons().iter().all(|p| p.len() == 4));
        }
    }

    #[test]
    fn catmull_clark_converges_to_the_limit_points() {
        // The limit point of a vertex is invariant under refinement, and the vertex approaches it.
        let m1 = catmull_clark(&HalfedgeMesh::cube());
        let corner = 0; // vertices keep their indices: old vertices come first
        let limit = catmull_clark_limit(&m1, corner);
        let mut m = m1;
        let mut dist = vec![];
        for _ in 0..5 {
            assert!((catmull_clark_limit(&m, corner) - limit).length() < 1e-12);
            dist.push((m.positions[corner] - limit).length());
            m = catmull_clark(&m);
        }
        assert!(dist.windows(2).all(|w| w[1] < 0.5 * w[0]), "{dist:?}");
        // The limit surface of the cube is inside it and symmetric: the corner limit lies on the
        // diagonal.
        assert!((limit.x - limit.y).abs() < 1e-12 && (limit.y - limit.z).abs() < 1e-12 && limit.x.abs() < 1.0);
    }

    #[test]
    fn catmull_clark_on_an_irregular_open_mesh() {
        // A pyramid without its base: a boundary square and a valence-4 apex; plus a triangle fan.
        let p = vec![
            Vec3::new(-1.0, 0.0, -1.0),
            Vec3::new(1.0, 0.0, -1.0),
            Vec3::new(1.0, 0.0, 1.0),
            Vec3::new(-1.0, 0.0, 1.0),
            Vec3::Y,
        ];
        let m = HalfedgeMesh::from_polygons(p, &[vec![0, 4, 1], vec![1, 4, 2], vec![2, 4, 3], vec![3, 4, 0]]).unwrap();
        let r = catmull_clark(&m);
        assert!(!r.is_closed());
        assert_eq!(r.euler_characteristic(), m.euler_characteristic());
        assert_eq!(r.faces.len(), 12);
    }

    #[test]
    fn doo_sabin_on_the_cube() {
        let mut m = HalfedgeMesh::cube();
        for _ in 0..3 {
            let r = doo_sabin(&m);
            assert!(r.is_closed());
            assert_eq!(r.euler_characteristic(), 2);
            assert_eq!(r.faces.len(), m.faces.len() + m.edge_count() + m.positions.len());
            m = r;
        }
        // Extraordinary elements are facets: every vertex has valence 4 after one step.
        assert!((0..m.positions.len()).all(|v| m.outgoing(v).len() == 4));
        // Doo–Sabin of the cube stays inside it (flat faces stay in their planes) and cuts the
        // corners off.
        assert!(m.positions.iter().all(|p| p.abs().max_element() <= 1.0 + 1e-12));
        assert!(m.positions.iter().all(|p| p.abs().element_sum() < 2.9));
    }

    #[test]
    fn non_manifold_input_is_refused() {
        let p = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
        assert!(HalfedgeMesh::from_polygons(p.clone(), &[vec![0, 1, 2], vec![0, 1, 3]]).is_err());
        assert!(HalfedgeMesh::from_polygons(p.clone(), &[vec![0, 1]]).is_err());
        assert!(HalfedgeMesh::from_polygons(p, &[vec![0, 1, 9]]).is_err());
    }
}
