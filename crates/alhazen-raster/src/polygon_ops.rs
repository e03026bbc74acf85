//! Boolean operations on polygons with holes by the Weiler–Atherton method (course, §"Clipping
//! polygons"): intersection, union, difference and symmetric difference.
//!
//! A polygon is a set of closed rings; the interior lies on the **left** of every edge (outer
//! boundaries counter-clockwise, holes clockwise, `y` up). The course states the mirror
//! convention (interior on the right), which is the same thing seen with `y` down, as on a
//! raster. Reversing every ring gives the complement, so one procedure serves all operations.
//!
//! Method: every edge of each polygon is cut at its crossings with the other polygon's edges
//! (the graph of the course with the new vertices); each piece is classified as inside or
//! outside the other polygon by the parity rule at its midpoint; the pieces that bound the result
//! are kept (for `A ∩ B`: pieces of `A` inside `B` and of `B` inside `A`), and the result's rings
//! are traced by following, at every vertex, the kept piece that starts there — at a crossing
//! that is always the other polygon's edge, as the course prescribes. Input in general position
//! (no vertex of one polygon on an edge of the other, no overlapping edges) is assumed;
//! degenerate contacts may produce slivers of zero area.

use alhazen_math::Vec2;

/// A polygon: closed rings (first vertex not repeated), interior on the left.
pub type Polygon = Vec<Vec<Vec2>>;

/// Which Boolean operation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BoolOp {
    /// `A ∩ B`.
    Intersection,
    /// `A ∪ B`.
    Union,
    /// `A − B`.
    Difference,
}

/// A piece of an edge between two graph vertices (ids), with its end points.
#[derive(Clone, Copy, Debug)]
struct Piece {
    from: usize,
    to: usize,
    a: Vec2,
    b: Vec2,
}

/// The crossing parameters `(s, t)` of segments `p0p1` and `q0q1`, strictly inside both.
fn crossing(p0: Vec2, p1: Vec2, q0: Vec2, q1: Vec2) -> Option<(f64, f64)> {
    let (r, s) = (p1 - p0, q1 - q0);
    let denom = r.perp_dot(s);
    if denom == 0.0 {
        return None;
    }
    let d = q0 - p0;
    let (t, u) = (d.perp_dot(s) / denom, d.perp_dot(r) / denom);
    (t > 0.0 && t < 1.0 && u > 0.0 && u < 1.0).then_some((t, u))
}

/// The parity rule: is `p` inside `poly`?
pub fn contains(poly: &Polygon, p: Vec2) -> bool {
    let mut inside = false;
    for ring in poly {
        for i in 0..ring.len() {
            let (a, b) = (ring[i], ring[(i + 1) % ring.len()]);
            if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x) {
                inside = !inside;
            }
        }
    }
    inside
}

/// The edges of a polygon as `(start, end)`, ring after ring.
fn edges(poly: &Polygon) -> Vec<(Vec2, Vec2)> {
    poly.iter().flat_map(|r| (0..r.len()).map(move |i| (r[i], r[(i + 1) % r.len()]))).collect()
}

/// The pieces of `poly`'s edges cut at all crossings with `other`; crossing `k` has vertex id
/// `crossing_base + k` in both polygons, other vertices get fresh ids from `next_id`.
fn pieces(poly: &Polygon, cuts: &[Vec<(f64, usize)>], next_id: &mut usize) -> Vec<Piece> {
    let mut out = Vec::new();
    let mut edge = 0;
    for ring in poly {
        let first_id = *next_id;
        *next_id += ring.len();
        for i in 0..ring.len() {
            let (a, b) = (ring[i], ring[(i + 1) % ring.len()]);
            let (start, end) = (first_id + i, first_id + (i + 1) % ring.len());
            let mut from = (start, a);
            for &(t, id) in &cuts[edge] {
                let p = a + (b - a) * t;
                out.push(Piece { from: from.0, to: id, a: from.1, b: p });
                from = (id, p);
            }
            out.push(Piece { from: from.0, to: end, a: from.1, b });
            edge += 1;
        }
    }
    out
}

/// Links kept pieces into closed rings by following each piece's end to the piece starting there.
fn trace(kept: Vec<Piece>) -> Polygon {
    let mut by_start: std::collections::HashMap<usize, usize> = std::collections::HashMap::new();
    for (k, p) in kept.iter().enumerate() {
        by_start.insert(p.from, k);
    }
    let mut used = vec![false; kept.len()];
    let mut rings = Vec::new();
    for start in 0..kept.len() {
        if used[start] {
            continue;
        }
        let mut ring = Vec::new();
        let mut k = start;
        while !used[k] {
            used[k] = true;
            ring.push(kept[k].a);
            match by_start.get(&kept[k].to) {
                Some(&next) => k = next,
                None => break, // degenerate input: an open chain is dropped below
            }
        }
        if k == start && ring.len() >= 3 {
            rings.push(ring);
        }
    }
    rings
}

fn reversed(poly: &Polygon) -> Polygon {
    poly.iter().map(|r| r.iter().rev().copied().collect()).collect()
}

/// `A op B` by the Weiler–Atherton method.
pub fn boolean(a: &Polygon, b: &Polygon, op: BoolOp) -> Polygon {
    // Union is the complement of the intersection of complements; difference is A ∩ ¬B.
    let (pa, pb, flip) = match op {
        BoolOp::Intersection => (a.clone(), b.clone(), false),
        BoolOp::Union => (reversed(a), reversed(b), true),
        BoolOp::Difference => (a.clone(), reversed(b), false),
    };
    let (ea, eb) = (edges(&pa), edges(&pb));
    let (mut cuts_a, mut cuts_b) = (vec![vec![]; ea.len()], vec![vec![]; eb.len()]);
    let mut next_id = 0;
    for (i, (p0, p1)) in ea.iter().enumerate() {
        for (j, (q0, q1)) in eb.iter().enumerate() {
            if let Some((s, t)) = crossing(*p0, *p1, *q0, *q1) {
                cuts_a[i].push((s, next_id));
                cuts_b[j].push((t, next_id));
                next_id += 1;
            }
        }
    }
    for c in cuts_a.iter_mut().chain(cuts_b.iter_mut()) {
        c.sort_by(|x, y| x.0.total_cmp(&y.0));
    }
    // Inside tests against the complemented polygons: a point is in ¬P when it is not in P.
    let inside = |poly: &Polygon, complemented: bool, p: Vec2| contains(poly, p) != complemented;
    let (ca, cb) = (op == BoolOp::Union, op != BoolOp::Intersection);
    let mut kept: Vec<Piece> =
        pieces(&pa, &cuts_a, &mut next_id).into_iter().filter(|p| inside(b, cb, (p.a + p.b) / 2.0)).collect();
    kept.extend(pieces(&pb, &cuts_b, &mut next_id).into_iter().filter(|p| inside(a, ca, (p.a + p.b) / 2.0)));
    let result = trace(kept);
    if flip { reversed(&result) } else { result }
}

/// The signed area of a polygon with holes (positive for the left-interior convention).
pub fn area(poly: &Polygon) -> f64 {
    poly.iter().map(|r| crate::clip::signed_area(r)).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use std::f64::consts::PI;

    /// A star-shaped ring around `c` (counter-clockwise), radii in `[r0, r1]`.
    fn star(c: Vec2, radii: &[f64], phase: f64) -> Vec<Vec2> {
        let n = radii.len();
        (0..n)
            .map(|i| {
                let a = phase + 2.0 * PI * i as f64 / n as f64;
                c + Vec2::new(a.cos(), a.sin()) * radii[i]
            })
            .collect()
    }

    /// The area where `test` holds, on a fine grid over `[-3, 3]²`.
    fn grid_area(test: impl Fn(Vec2) -> bool) -> f64 {
        let n = 400;
        let h = 6.0 / n as f64;
        let mut count = 0;
        for i in 0..n {
            for j in 0..n {
                if test(Vec2::new(-3.0 + (i as f64 + 0.5) * h, -3.0 + (j as f64 + 0.5) * h)) {
                    count += 1;
                }
            }
        }
        count as f64 * h * h
    }

    fn polygon_strategy() -> impl Strategy<Value = Polygon> {
        (
            -0.8..0.8f64,
            -0.8..0.8f64,
            prop::collection::vec(1.0..2.0f64, 5..12),
            0.0..6.3f64,
            prop::collection::vec(0.2..0.5f64, 3..7),
            any::<bool>(),
        )
            .prop_map(|(cx, cy, outer, phase, hole, with_hole)| {
                let c = Vec2::new(cx, cy);
                let mut poly = vec![star(c, &outer, phase)];
                if with_hole {
                    let mut h = star(c, &hole, phase + 0.1);
                    h.reverse();
                    poly.push(h);
                }
                poly
            })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(200))]

        #[test]
        fn boolean_areas_match_inclusion_exclusion_and_a_grid(a in polygon_strategy(), b in polygon_strategy()) {
            let i = boolean(&a, &b, BoolOp::Intersection);
            let u = boolean(&a, &b, BoolOp::Union);
            let d = boolean(&a, &b, BoolOp::Difference);
            let (aa, ab) = (area(&a), area(&b));
            let (ai, au, ad) = (area(&i), area(&u), area(&d));
            prop_assert!((au - (aa + ab - ai)).abs() < 1e-9, "union {au} vs {aa} + {ab} − {ai}");
            prop_assert!((ad - (aa - ai)).abs() < 1e-9, "difference {ad} vs {aa} − {ai}");
            let grid = grid_area(|p| contains(&a, p) && contains(&b, p));
            prop_assert!((ai - grid).abs() < 0.02, "intersection {ai} vs grid {grid}");
            // Every result point is where it should be.
            for ring in &i {
                for w in ring.windows(2) {
                    let m = (w[0] + w[1]) / 2.0;
                    let off = Vec2::new(-(w[1] - w[0]).y, (w[1] - w[0]).x).normalize() * 1e-7;
                    prop_assert!(contains(&a, m + off) && contains(&b, m + off), "interior left of {m}");
                }
            }
        }
    }

    #[test]
    fn disjoint_and_nested_polygons() {
        let sq = |c: Vec2, r: f64| {
            vec![vec![c + Vec2::new(-r, -r), c + Vec2::new(r, -r), c + Vec2::new(r, r), c + Vec2::new(-r, r)]]
        };
        let (big, small, far) = (sq(Vec2::ZERO, 1.0), sq(Vec2::new(0.1, 0.2), 0.3), sq(Vec2::new(5.0, 0.0), 1.0));
        assert!((area(&boolean(&big, &small, BoolOp::Intersection)) - 0.36).abs() < 1e-12);
        assert!((area(&boolean(&big, &small, BoolOp::Difference)) - (4.0 - 0.36)).abs() < 1e-12);
        assert_eq!(boolean(&big, &small, BoolOp::Difference).len(), 2, "a square with a hole");
        assert!(boolean(&big, &far, BoolOp::Intersection).is_empty());
        assert!((area(&boolean(&big, &far, BoolOp::Union)) - 8.0).abs() < 1e-12);
    }
}
