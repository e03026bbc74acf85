//! Planar primitives of the top-level BVH: the triangles of small meshes and the parallelograms
//! that pairs of them form (rectangles, box faces), each with its plane and its two barycentric
//! axes precomputed. The test is a projection: one division for the plane, then two dot
//! products (Wald 2004, "Realtime Ray Tracing and Interactive Global Illumination", §7.1).

use super::Candidate;
use alhazen_geom::TriangleMesh;
use alhazen_math::{Bounds3, Vec3};

/// A triangle `origin + b1·e1 + b2·e2` (`b1, b2 ≥ 0`, `b1 + b2 ≤ 1`) or a parallelogram
/// (`b1, b2 ∈ [0, 1]`), ready for ray tests.
#[derive(Clone, Copy, Debug)]
pub struct Flat {
    pub(super) origin: Vec3,
    /// `e1 × e2`.
    pub(super) normal: Vec3,
    /// `(e2 × N) / |N|²`: `(p − origin)·u = b1`.
    pub(super) u: Vec3,
    /// `(N × e1) / |N|²`: `(p − origin)·v = b2`.
    pub(super) v: Vec3,
    pub(super) parallelogram: bool,
}

impl Flat {
    /// The primitive spanned by `e1`, `e2` from `origin`; `None` when they span no area.
    pub fn new(origin: Vec3, e1: Vec3, e2: Vec3, parallelogram: bool) -> Option<Self> {
        let normal = e1.cross(e2);
        let n2 = normal.length_squared();
        (n2 > 0.0 && n2.is_finite()).then(|| Self {
            origin,
            normal,
            u: e2.cross(normal) / n2,
            v: normal.cross(e1) / n2,
            parallelogram,
        })
    }

    /// The triangle with these corners.
    pub fn triangle([a, b, c]: [Vec3; 3]) -> Option<Self> {
        Self::new(a, b - a, c - a, false)
    }

    /// True for a parallelogram.
    pub fn is_parallelogram(&self) -> bool {
        self.parallelogram
    }
}

/// Triangles `[a, b, c]`, `[a, c, d]` of a mesh that form the parallelogram
/// `a + s·(b − a) + t·(d − a)`: its corner and edges.
pub fn parallelogram_of(first: [u32; 3], second: [u32; 3], [a, b, c]: [Vec3; 3], d: Vec3) -> Option<[Vec3; 3]> {
    if first[0] != second[0] || first[2] != second[1] {
        return None;
    }
    let (e1, e2) = (b - a, d - a);
    let flat = (b + d - a - c).length() <= 1e-12 * (e1.length() + e2.length());
    (flat && e1.cross(e2).length_squared() > 0.0).then_some([a, e1, e2])
}

/// The triangle of the pair and its barycentric coordinates at parallelogram coordinates
/// `(s, t)`: the first triangle `[a, b, c]` where `s ≥ t`, else the second `[a, c, d]`.
#[inline]
pub fn parallelogram_to_triangle(s: f64, t: f64) -> (u32, f64, f64) {
    if s >= t { (0, s - t, t) } else { (1, s, t - s) }
}

/// Which mesh triangle a flat is: the triangle, or the first of a parallelogram's pair.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FlatLane {
    /// The triangle (the first of the pair for a parallelogram).
    pub triangle: u32,
    /// The flat is the parallelogram of `triangle` and the next one.
    pub parallelogram: bool,
}

impl FlatLane {
    /// The mesh triangle hit and its barycentrics, for the flat's hit `(t, b1, b2)`.
    #[inline]
    pub fn candidate(self, t: f64, b1: f64, b2: f64) -> Candidate {
        let (second, b1, b2) = if self.parallelogram { parallelogram_to_triangle(b1, b2) } else { (0, b1, b2) };
        Candidate { t, aux: self.triangle + second, bary: [b1, b2] }
    }

    /// The mesh triangles the flat covers.
    pub fn triangles(self) -> std::ops::Range<usize> {
        let first = self.triangle as usize;
        first..first + 1 + usize::from(self.parallelogram)
    }
}

/// The corner and edges of the flat of triangle `t` of `mesh`: with `pair`, of the
/// parallelogram of `t` and `t + 1` (`None` when they do not form one); else of the triangle.
fn flat_edges(mesh: &TriangleMesh, t: usize, pair: bool) -> Option<[Vec3; 3]> {
    let corners @ [a, b, c] = mesh.corners(t);
    if !pair {
        return Some([a, b - a, c - a]);
    }
    if t + 1 >= mesh.triangle_count() {
        return None;
    }
    let (first, second) = (mesh.triangles[t], mesh.triangles[t + 1]);
    parallelogram_of(first, second, corners, mesh.positions[second[2] as usize])
}

/// True when [`flat_edges`] span an area (the test of [`Flat::new`], without computing the
/// flat).
fn spans_area(mesh: &TriangleMesh, t: usize, pair: bool) -> bool {
    flat_edges(mesh, t, pair).is_some_and(|[_, e1, e2]| {
        let n2 = e1.cross(e2).length_squared();
        n2 > 0.0 && n2.is_finite()
    })
}

impl FlatLane {
    /// The flat this lane stands for in `mesh` (computed again: the same numbers as when the
    /// lane was made by [`flat_primitives`]).
    pub fn flat(self, mesh: &TriangleMesh) -> Flat {
        let [o, e1, e2] = flat_edges(mesh, self.triangle as usize, self.parallelogram).expect("a lane of this mesh");
        Flat::new(o, e1, e2, self.parallelogram).expect("a flat with area")
    }

    /// The bounds of the flat this lane stands for in `mesh`.
    pub fn bounds(self, mesh: &TriangleMesh) -> Bounds3 {
        let t = self.triangle as usize;
        let [o, e1, e2] = flat_edges(mesh, t, self.parallelogram).expect("a lane of this mesh");
        if self.parallelogram {
            Bounds3::from_points([o, o + e1, o + e2, o + e1 + e2])
        } else {
            Bounds3::from_points(mesh.corners(t))
        }
    }
}

/// The triangles of `mesh` as flats (their lanes: [`FlatLane::flat`] gives each flat again
/// where it is needed, and [`FlatLane::bounds`] its bounds, so a million-triangle mesh does not
/// hold a hundred megabytes of them while it packs them): consecutive pairs that form a
/// parallelogram become one; triangles without area are dropped.
pub fn flat_primitives(mesh: &TriangleMesh) -> Vec<FlatLane> {
    use rayon::prelude::*;
    // What each triangle would start, found on all threads: a parallelogram with the next, a
    // triangle, or nothing (no area). Then the pairs are taken greedily in triangle order.
    const NOTHING: u8 = 0;
    const TRIANGLE: u8 = 1;
    const PARALLELOGRAM: u8 = 2;
    let start = |t: usize| {
        if spans_area(mesh, t, true) {
            PARALLELOGRAM
        } else if spans_area(mesh, t, false) {
            TRIANGLE
        } else {
            NOTHING
        }
    };
    let mut starts = Vec::new();
    (0..mesh.triangle_count()).into_par_iter().map(start).collect_into_vec(&mut starts);
    // At most one flat per triangle: reserved once, so the vector is not copied as it grows
    // (pages reserved and never written cost no memory).
    let mut lanes = Vec::with_capacity(mesh.triangle_count());
    let mut t = 0;
    while t < starts.len() {
        let lane = FlatLane { triangle: t as u32, parallelogram: starts[t] == PARALLELOGRAM };
        if starts[t] != NOTHING {
            lanes.push(lane);
        }
        t += if lane.parallelogram { 2 } else { 1 };
    }
    lanes
}

#[cfg(test)]
mod tests {
    use super::*;
    use alhazen_math::Ray;

    proptest::proptest! {
        /// The flats are what taking triangles in order gives: a parallelogram with the next
        /// where the two form one, else the triangle where it has area (a row of quads).
        #[test]
        fn flats_pair_triangles_greedily_in_order(
            quads in proptest::collection::vec((0u8..4, proptest::bool::ANY), 0..40),
        ) {
            let mut mesh = TriangleMesh::default();
            for (q, &(kind, flip)) in quads.iter().enumerate() {
                let x = q as f64;
                let base = mesh.positions.len() as u32;
                // Quad a, b, c, d counter-clockwise: [a, b, c], [a, c, d] form a parallelogram
                // unless d is moved off (kind 1), the first is rotated (flip), has no area
                // (kind 2) or stands alone (kind 3).
                let d_y = if kind == 1 { 0.5 } else { 1.0 };
                mesh.positions.extend([Vec3::new(x, 0.0, 0.0), Vec3::new(x + 1.0, 0.0, 0.0), Vec3::new(x + 1.0, 1.0, 0.0), Vec3::new(x, d_y, 0.0)]);
                let [a, b, c, d] = [base, base + 1, base + 2, base + 3];
                let first = if kind == 2 { [a, a, b] } else if flip { [b, c, a] } else { [a, b, c] };
                mesh.triangles.push(first);
                if kind != 3 {
                    mesh.triangles.push([a, c, d]);
                }
            }
            let mut want = vec![];
            let mut t = 0;
            while t < mesh.triangle_count() {
                if spans_area(&mesh, t, true) {
                    want.push((t as u32, true));
                    t += 2;
                    continue;
                }
                if spans_area(&mesh, t, false) {
                    want.push((t as u32, false));
                }
                t += 1;
            }
            let got: Vec<_> = flat_primitives(&mesh).iter().map(|l| (l.triangle, l.parallelogram)).collect();
            proptest::prop_assert_eq!(got, want);
        }
    }

    #[test]
    fn triangle_barycentrics_reproduce_the_hit_point() {
        let corners = [Vec3::new(0.0, 0.0, 1.0), Vec3::new(2.0, 0.1, 1.2), Vec3::new(0.3, 1.5, 0.9)];
        let f = Flat::triangle(corners).unwrap();
        let target = corners[0] * 0.2 + corners[1] * 0.5 + corners[2] * 0.3;
        let ray = Ray::new(Vec3::new(0.1, -0.2, -3.0), (target - Vec3::new(0.1, -0.2, -3.0)).normalize());
        let (t, b1, b2) = f.hit(&ray, f64::INFINITY).unwrap();
        // Single precision (see `FlatPacket`): good to a few units of 2⁻²⁴ of the distances.
        assert!((ray.at(t) - target).length() < 1e-6);
        assert!((b1 - 0.5).abs() < 1e-6 && (b2 - 0.3).abs() < 1e-6);
        assert!(f.hit(&ray, t * 0.999).is_none(), "beyond t_max");
        let away = Ray::new(ray.origin, -ray.dir);
        assert!(f.hit(&away, f64::INFINITY).is_none(), "behind the origin");
    }

    #[test]
    fn parallelogram_covers_both_triangles_and_maps_back() {
        let (a, b, d) = (Vec3::ZERO, Vec3::X * 2.0, Vec3::Y);
        let c = b + d - a;
        let [o, e1, e2] = parallelogram_of([0, 1, 2], [0, 2, 3], [a, b, c], d).unwrap();
        let quad = Flat::new(o, e1, e2, true).unwrap();
        let (tri1, tri2) = (Flat::triangle([a, b, c]).unwrap(), Flat::triangle([a, c, d]).unwrap());
        for (x, y) in [(0.3, 0.2), (1.5, 0.9), (0.2, 0.8), (1.9, 0.05), (2.1, 0.5), (0.5, -0.1)] {
            let ray = Ray::new(Vec3::new(x, y, 5.0), -Vec3::Z);
            let direct = tri1.hit(&ray, 10.0).map(|h| (0, h)).or(tri2.hit(&ray, 10.0).map(|h| (1, h)));
            match (quad.hit(&ray, 10.0), direct) {
                (Some((t, s, u)), Some((which, (t2, b1, b2)))) => {
                    let (k, c1, c2) = parallelogram_to_triangle(s, u);
                    assert!((t - t2).abs() < 1e-6 && k == which, "({x}, {y})");
                    assert!((c1 - b1).abs() < 1e-6 && (c2 - b2).abs() < 1e-6, "({x}, {y})");
                }
                (None, None) => {}
                (q, t) => panic!("({x}, {y}): parallelogram {q:?}, triangles {t:?}"),
            }
        }
        assert!(parallelogram_of([0, 1, 2], [0, 3, 2], [a, b, c], d).is_none(), "not a shared diagonal");
        assert!(parallelogram_of([0, 1, 2], [0, 2, 3], [a, b, c + Vec3::Z], d).is_none(), "not flat");
    }
}
