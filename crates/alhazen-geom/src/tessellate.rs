//! Turning curves' and surfaces' exact descriptions into triangle meshes for the renderers:
//! polygon meshes by fan triangulation, patches on a grid refined until the chordal error is
//! within a tolerance, with shading normals from the exact surface.

use crate::TriangleMesh;
use crate::bezier::ControlPoint;
use crate::halfedge::HalfedgeMesh;
use crate::patch::{BSplinePatch, BezierPatch, rational_normal};
use alhazen_math::{Vec2, Vec3, Vec4};

/// Fan-triangulates every facet; vertex normals are area-weighted.
pub fn polygons_to_triangles(m: &HalfedgeMesh) -> TriangleMesh {
    let mut t = TriangleMesh { positions: m.positions.clone(), ..TriangleMesh::default() };
    for poly in m.polygons() {
        for k in 1..poly.len() - 1 {
            t.triangles.push([poly[0] as u32, poly[k] as u32, poly[k + 1] as u32]);
        }
    }
    t.compute_smooth_normals();
    t
}

/// A surface `(u, v) ∈ [0, 1]² ↦ (point, unit normal)`.
pub trait Surface {
    /// Point and unit normal at `(u, v)` in the unit square.
    fn sample(&self, u: f64, v: f64) -> (Vec3, Vec3);

    /// The point alone (the same as `sample(u, v).0`, possibly cheaper).
    fn point(&self, u: f64, v: f64) -> Vec3 {
        self.sample(u, v).0
    }

    /// Where the surface's polynomial pieces meet, in the unit square, per direction: `0` and
    /// `1` and the inner knots of a B-spline patch (where it may crease).
    fn breaks(&self) -> [Vec<f64>; 2] {
        [vec![0.0, 1.0], vec![0.0, 1.0]]
    }
}

impl Surface for BezierPatch<Vec3> {
    fn sample(&self, u: f64, v: f64) -> (Vec3, Vec3) {
        let (p, pu, pv) = self.partials(u, v);
        (p, pu.cross(pv).try_normalize().unwrap_or(Vec3::Z))
    }

    fn point(&self, u: f64, v: f64) -> Vec3 {
        self.eval(u, v)
    }
}

impl Surface for BezierPatch<Vec4> {
    fn sample(&self, u: f64, v: f64) -> (Vec3, Vec3) {
        let (h, hu, hv) = self.partials(u, v);
        (h.truncate() / h.w, rational_normal(h, hu, hv).unwrap_or(Vec3::Z))
    }

    fn point(&self, u: f64, v: f64) -> Vec3 {
        let h = self.eval(u, v);
        h.truncate() / h.w
    }
}

/// A B-spline patch's distinct domain knots in each direction, mapped to `[0, 1]`.
fn knot_breaks<P: ControlPoint>(s: &BSplinePatch<P>) -> [Vec<f64>; 2] {
    let ((u0, u1), (v0, v1)) = s.domain();
    let unit = |knots: &[f64], a: f64, b: f64| {
        let mut k: Vec<f64> = knots.iter().filter(|x| **x >= a && **x <= b).map(|x| (x - a) / (b - a)).collect();
        k.dedup();
        k
    };
    [unit(&s.u_knots, u0, u1), unit(&s.v_knots, v0, v1)]
}

/// The parameters of `s` at `(u, v)` in the unit square.
fn in_domain<P: ControlPoint>(s: &BSplinePatch<P>, u: f64, v: f64) -> (f64, f64) {
    let ((u0, u1), (v0, v1)) = s.domain();
    (u0 + (u1 - u0) * u, v0 + (v1 - v0) * v)
}

impl Surface for BSplinePatch<Vec3> {
    fn sample(&self, u: f64, v: f64) -> (Vec3, Vec3) {
        let (uu, vv) = in_domain(self, u, v);
        let (p, pu, pv) = self.partials(uu, vv);
        (p, pu.cross(pv).try_normalize().unwrap_or(Vec3::Z))
    }

    fn point(&self, u: f64, v: f64) -> Vec3 {
        let (uu, vv) = in_domain(self, u, v);
        self.eval(uu, vv)
    }

    fn breaks(&self) -> [Vec<f64>; 2] {
        knot_breaks(self)
    }
}

impl Surface for BSplinePatch<Vec4> {
    fn sample(&self, u: f64, v: f64) -> (Vec3, Vec3) {
        let (uu, vv) = in_domain(self, u, v);
        let (h, hu, hv) = self.partials(uu, vv);
        (h.truncate() / h.w, rational_normal(h, hu, hv).unwrap_or(Vec3::Z))
    }

    fn point(&self, u: f64, v: f64) -> Vec3 {
        let (uu, vv) = in_domain(self, u, v);
        let h = self.eval(uu, vv);
        h.truncate() / h.w
    }

    fn breaks(&self) -> [Vec<f64>; 2] {
        knot_breaks(self)
    }
}

/// The chordal errors of the grid on parameters `us × vs`: the largest distance between the
/// surface and the grid's segments at the midpoints of `u`-edges, of `v`-edges, and between the
/// surface and the diagonals at cell centres.
fn chordal_errors<S: Surface>(s: &S, us: &[f64], vs: &[f64]) -> [f64; 3] {
    let corners: Vec<Vec3> =
        us.iter().flat_map(|&u| vs.iter().map(move |&v| (u, v))).map(|(u, v)| s.point(u, v)).collect();
    let kv = vs.len() - 1;
    let corner = |i: usize, j: usize| corners[i * (kv + 1) + j];
    let mut worst = [0.0f64; 3];
    for (i, &u) in us.iter().enumerate() {
        for (j, &v) in vs.iter().enumerate() {
            let p00 = corner(i, j);
            let (next_u, next_v) = (us.get(i + 1), vs.get(j + 1));
            if let Some(&u1) = next_u {
                let e = (s.point(0.5 * (u + u1), v) - (p00 + corner(i + 1, j)) * 0.5).length();
                worst[0] = worst[0].max(e);
            }
            if let Some(&v1) = next_v {
                let e = (s.point(u, 0.5 * (v + v1)) - (p00 + corner(i, j + 1)) * 0.5).length();
                worst[1] = worst[1].max(e);
            }
            if let (Some(&u1), Some(&v1)) = (next_u, next_v) {
                let e = (s.point(0.5 * (u + u1), 0.5 * (v + v1)) - (p00 + corner(i + 1, j + 1)) * 0.5).length();
                worst[2] = worst[2].max(e);
            }
        }
    }
    worst
}

/// Parameters dividing each piece between consecutive `breaks` into `per_piece` equal steps.
fn divided(breaks: &[f64], per_piece: usize) -> Vec<f64> {
    let mut out = vec![breaks[0]];
    for w in breaks.windows(2) {
        out.extend((1..=per_piece).map(|k| w[0] + (w[1] - w[0]) * k as f64 / per_piece as f64));
    }
    out
}

/// Cells per direction beyond which [`tessellate`] stops refining.
pub const MAX_CELLS_PER_SIDE: usize = 1024;

/// A tessellation grid: the parameters of its lines in each direction, in the unit square.
#[derive(Clone, Debug, PartialEq)]
pub struct Grid {
    /// Parameters of the lines across `u`.
    pub us: Vec<f64>,
    /// Parameters of the lines across `v`.
    pub vs: Vec<f64>,
    /// Its chordal error.
    pub error: f64,
}

impl Grid {
    /// Cells along `u` and `v`.
    pub fn cells(&self) -> (usize, usize) {
        (self.us.len() - 1, self.vs.len() - 1)
    }
}

/// The grid [`tessellate`] uses for `s` at `tolerance`. The patch is first subdivided where its
/// polynomial pieces meet (its knots, as inserting them to full multiplicity would split it
/// into Bézier patches) so that creases lie on grid lines; then each piece is divided into
/// equal steps, their number doubled in each direction on its own while the chordal error along
/// it (or across the cells' diagonals) exceeds the tolerance, up to [`MAX_CELLS_PER_SIDE`] cells
/// a side (where the error may stay above the tolerance; a direction with more pieces than that
/// is divided evenly, without regard to its knots). A long thin tube gets many cells along and
/// few around.
pub fn grid_for<S: Surface>(s: &S, tolerance: f64) -> Grid {
    let breaks =
        s.breaks().map(|b| if b.len() >= 2 && b.len() - 1 <= MAX_CELLS_PER_SIDE / 2 { b } else { vec![0.0, 1.0] });
    let pieces = [breaks[0].len() - 1, breaks[1].len() - 1];
    let most = pieces.map(|p| (MAX_CELLS_PER_SIDE / p).max(1));
    // At least two cells a side.
    let mut per = pieces.map(|p| if p >= 2 { 1 } else { 2 });
    loop {
        let (us, vs) = (divided(&breaks[0], per[0]), divided(&breaks[1], per[1]));
        let [eu, ev, diagonal] = chordal_errors(s, &us, &vs);
        let (mut refine_u, mut refine_v) = (eu > tolerance, ev > tolerance);
        if diagonal > tolerance && !refine_u && !refine_v {
            (refine_u, refine_v) = (true, true);
        }
        let next = [
            if refine_u { (per[0] * 2).min(most[0]) } else { per[0] },
            if refine_v { (per[1] * 2).min(most[1]) } else { per[1] },
        ];
        if next == per {
            return Grid { us, vs, error: eu.max(ev).max(diagonal) };
        }
        per = next;
    }
}

/// A triangle mesh of `s` on the grid of [`grid_for`]: within `tolerance` of the surface at the
/// edges' midpoints and the cells' centres. Texture coordinates are the parameters.
pub fn tessellate<S: Surface>(s: &S, tolerance: f64) -> TriangleMesh {
    tessellate_grid(s, &grid_for(s, tolerance))
}

/// A triangle mesh of `s` on `grid` (two triangles a cell).
pub fn tessellate_grid<S: Surface>(s: &S, grid: &Grid) -> TriangleMesh {
    let (ku, kv) = grid.cells();
    let mut m = TriangleMesh::default();
    for &u in &grid.us {
        for &v in &grid.vs {
            let (p, n) = s.sample(u, v);
            m.positions.push(p);
            m.normals.push(n);
            m.uvs.push(Vec2::new(u, v));
        }
    }
    let at = |i: usize, j: usize| (i * (kv + 1) + j) as u32;
    for i in 0..ku {
        for j in 0..kv {
            m.triangles.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            m.triangles.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    m
}

/// A tube of `radius` around a polyline (for drawing curves in images): a ring of `sides`
/// vertices per point, oriented by parallel transport.
pub fn tube<P: ControlPoint + Into<Vec3>>(points: &[P], radius: f64, sides: usize) -> TriangleMesh {
    let pts: Vec<Vec3> = points.iter().map(|&p| p.into()).collect();
    let mut m = TriangleMesh::default();
    if pts.len() < 2 {
        return m;
    }
    let sides = sides.max(3);
    let tangent = |i: usize| (pts[(i + 1).min(pts.len() - 1)] - pts[i.saturating_sub(1)]).normalize_or(Vec3::X);
    let mut normal = alhazen_math::orthonormal_basis(tangent(0)).0;
    for i in 0..pts.len() {
        let t = tangent(i);
        normal = (normal - t * normal.dot(t)).normalize_or(alhazen_math::orthonormal_basis(t).0);
        let binormal = t.cross(normal);
        for s in 0..sides {
            let a = std::f64::consts::TAU * s as f64 / sides as f64;
            let dir = normal * a.cos() + binormal * a.sin();
            m.positions.push(pts[i] + dir * radius);
            m.normals.push(dir);
        }
    }
    for i in 0..pts.len() - 1 {
        for s in 0..sides {
            let (a, b) = ((i * sides + s) as u32, (i * sides + (s + 1) % sides) as u32);
            let (c, d) = (a + sides as u32, b + sides as u32);
            m.triangles.push([a, b, d]);
            m.triangles.push([a, d, c]);
        }
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::patch::Net;

    #[test]
    fn tessellation_error_is_within_tolerance() {
        // A saddle-like bicubic patch.
        let pts: Vec<Vec3> = (0..16)
            .map(|k| Vec3::new((k / 4) as f64, (k % 4) as f64, (((k / 4) as f64 - 1.5) * ((k % 4) as f64 - 1.5)).sin()))
            .collect();
        let p = BezierPatch { net: Net::new(4, 4, pts).unwrap() };
        for tol in [0.1, 0.01, 0.001] {
            let m = tessellate(&p, tol);
            m.validate().unwrap();
            let grid = grid_for(&p, tol);
            let (ku, kv) = grid.cells();
            assert!(grid.error <= tol);
            assert_eq!(m.positions.len(), (ku + 1) * (kv + 1));
            assert!(chordal_errors(&p, &grid.us, &grid.vs).iter().all(|e| *e <= tol), "{ku} × {kv}");
            // Independent check: the surface at random parameters against the mesh's triangle there.
            for k in 0..200 {
                let (u, v) = ((k as f64 * 0.618_034).fract(), (k as f64 * 0.414_214).fract());
                let (i, j) = (((u * ku as f64) as usize).min(ku - 1), ((v * kv as f64) as usize).min(kv - 1));
                let (fu, fv) = (u * ku as f64 - i as f64, v * kv as f64 - j as f64);
                let at = |i: usize, j: usize| m.positions[i * (kv + 1) + j];
                let flat = if fu >= fv {
                    at(i, j) + (at(i + 1, j) - at(i, j)) * fu + (at(i + 1, j + 1) - at(i + 1, j)) * fv
                } else {
                    at(i, j) + (at(i, j + 1) - at(i, j)) * fv + (at(i + 1, j + 1) - at(i, j + 1)) * fu
                };
                assert!((p.point(u, v) - flat).length() <= 2.0 * tol, "{u} {v}");
            }
            assert!(m.normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-9));
        }
    }

    #[test]
    fn a_crease_at_a_knot_lies_on_a_grid_line() {
        // A linear-by-quadratic B-spline patch, folded along u = 0.3 (a double knot of the
        // quadratic direction): a roof with its ridge off the grid's even divisions.
        let u_knots = vec![0.0, 0.0, 0.0, 0.3, 0.3, 1.0, 1.0, 1.0];
        let ridge = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(0.15, 0.0, 0.5),
            Vec3::new(0.3, 0.0, 1.0),
            Vec3::new(0.65, 0.0, 0.5),
            Vec3::new(1.0, 0.0, 0.0),
        ];
        let points: Vec<Vec3> = ridge.iter().flat_map(|p| [*p, *p + Vec3::Y]).collect();
        let patch =
            BSplinePatch::new(2, 1, u_knots, vec![0.0, 0.0, 1.0, 1.0], Net::new(5, 2, points).unwrap()).unwrap();
        let grid = grid_for(&patch, 1e-3);
        assert!(grid.us.contains(&0.3), "{:?}", grid.us);
        // The roof is two planes: the first grid meets the tolerance exactly with its ridge line.
        assert_eq!(grid.cells().0, 2, "{:?}", grid.us);
        let m = tessellate(&patch, 1e-3);
        assert!(m.positions.iter().any(|p| (p.z - 1.0).abs() < 1e-12), "the ridge is in the mesh");
    }

    #[test]
    fn rational_patch_of_a_cylinder_is_exact() {
        // Quarter cylinder: a rational quadratic arc (weights 1, √2/2, 1) extruded.
        let w = std::f64::consts::FRAC_1_SQRT_2;
        let arc = [(Vec3::X, 1.0), (Vec3::new(1.0, 1.0, 0.0), w), (Vec3::Y, 1.0)];
        let pts: Vec<Vec4> =
            arc.iter().flat_map(|&(p, w)| [0.0, 2.0].map(|z| ((p + Vec3::Z * z) * w).extend(w))).collect();
        let patch = BezierPatch { net: Net::new(3, 2, pts).unwrap() };
        let m = tessellate(&patch, 1e-3);
        for (p, n) in m.positions.iter().zip(&m.normals) {
            assert!((p.truncate().length() - 1.0).abs() < 1e-12);
            assert!(
                (n.truncate().normalize() - p.truncate().normalize()).length() < 1e-9
                    || (n.truncate().normalize() + p.truncate().normalize()).length() < 1e-9
            );
        }
    }

    #[test]
    fn subdivided_cube_triangulates_to_a_closed_mesh() {
        let m = crate::subdivision::catmull_clark(&HalfedgeMesh::cube());
        let t = polygons_to_triangles(&m);
        t.validate().unwrap();
        assert_eq!(t.triangle_count(), 2 * m.faces.len());
    }

    #[test]
    fn tubes_have_the_radius() {
        let pts = [Vec3::ZERO, Vec3::X, Vec3::new(2.0, 1.0, 0.0)];
        let m = tube(&pts, 0.1, 8);
        m.validate().unwrap();
        for (k, p) in m.positions.iter().enumerate() {
            assert!(((*p - pts[k / 8]).length() - 0.1).abs() < 1e-12);
        }
    }
}
