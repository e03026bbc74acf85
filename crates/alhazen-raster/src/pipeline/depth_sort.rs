//! The depth-sort painter's algorithm (course, §"Image space algorithms": "sorting all facets
//! according to the distance from the viewer … if the intervals overlap, then the mutual
//! ordering of the objects cannot be determined without additional tests … a remedy is to
//! split some objects into pieces"), in the form of Newell, Newell and Sancha.
//!
//! Triangles are sorted farthest first by their farthest point. The farthest, `P`, is drawn
//! unless a triangle `Q` whose depth interval overlaps `P`'s may be hidden by it; `Q` is cleared
//! by the first test that holds: (1) their screen `x` extents or (2) `y` extents are disjoint,
//! (3) `P` lies wholly behind `Q`'s plane, (4) `Q` wholly in front of `P`'s plane, (5) their
//! projections do not overlap. If none holds, `Q` goes first when the reversed tests allow it
//! (`Q` behind `P`'s plane, or `P` in front of `Q`'s); a triangle that must move a second time
//! is in a cycle, and triangles that pierce each other cannot be ordered at all: then `P` is
//! split by `Q`'s plane (or `Q` by `P`'s) and the pieces sorted in again.
//!
//! All of it happens in screen space `(x, y, z/w)`, where the perspective division keeps planes
//! planar, and a split point interpolates `z/w`, `1/w` and the attributes over `w` linearly —
//! exactly as the rasteriser interpolates them — so the pieces are drawn as the whole was.

use super::raster::ScreenTriangle;
use alhazen_math::Vec3;
use std::collections::VecDeque;

/// A triangle's points `(x, y, z/w)`.
fn points(t: &ScreenTriangle) -> [Vec3; 3] {
    std::array::from_fn(|k| Vec3::new(t.x[k], t.y[k], t.z[k]))
}

/// The triangle's plane as `(n, p)` with `n` pointing away from the viewer (`n.z > 0`), or
/// `None` when it is seen edge-on (it covers no pixel).
fn plane(t: &ScreenTriangle) -> Option<(Vec3, Vec3)> {
    let p = points(t);
    let n = (p[1] - p[0]).cross(p[2] - p[0]);
    let scale = (p[1] - p[0]).length() * (p[2] - p[0]).length();
    if n.z.is_nan() || n.z.abs() <= 1e-12 * scale {
        return None;
    }
    Some((if n.z > 0.0 { n } else { -n }.normalize(), p[0]))
}

/// The farthest and nearest depth.
fn depth_range(t: &ScreenTriangle) -> (f64, f64) {
    let lo = t.z.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = t.z.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    (hi, lo)
}

/// Tolerance of the plane tests (depth units scaled by the screen).
const EPS: f64 = 1e-9;

/// True when every point of `a` lies behind (or on) the plane of `b`.
fn behind(a: &ScreenTriangle, b: &ScreenTriangle) -> bool {
    plane(b).is_none_or(|(n, o)| points(a).iter().all(|&v| n.dot(v - o) >= -EPS * (1.0 + v.abs().max_element())))
}

/// True when every point of `a` lies in front of (or on) the plane of `b`.
fn in_front(a: &ScreenTriangle, b: &ScreenTriangle) -> bool {
    plane(b).is_none_or(|(n, o)| points(a).iter().all(|&v| n.dot(v - o) <= EPS * (1.0 + v.abs().max_element())))
}

/// True when the screen extents along `x` (`axis` 0) or `y` (1) are disjoint.
fn apart(a: &ScreenTriangle, b: &ScreenTriangle, axis: usize) -> bool {
    let c = |t: &ScreenTriangle| if axis == 0 { t.x } else { t.y };
    let (ca, cb) = (c(a), c(b));
    let max = |v: [f64; 3]| v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let min = |v: [f64; 3]| v.iter().copied().fold(f64::INFINITY, f64::min);
    max(ca) <= min(cb) || max(cb) <= min(ca)
}

/// True when the projections have no interior point in common (separating axes: the six edge
/// normals).
fn projections_disjoint(a: &ScreenTriangle, b: &ScreenTriangle) -> bool {
    let edges = |t: &ScreenTriangle| {
        std::array::from_fn::<(f64, f64), 3, _>(|k| {
            let j = (k + 1) % 3;
            (-(t.y[j] - t.y[k]), t.x[j] - t.x[k])
        })
    };
    let project = |t: &ScreenTriangle, (nx, ny): (f64, f64)| {
        let v: [f64; 3] = std::array::from_fn(|k| nx * t.x[k] + ny * t.y[k]);
        (v.iter().copied().fold(f64::INFINITY, f64::min), v.iter().copied().fold(f64::NEG_INFINITY, f64::max))
    };
    edges(a).into_iter().chain(edges(b)).any(|axis| {
        let ((a0, a1), (b0, b1)) = (project(a, axis), project(b, axis));
        a1 <= b0 || b1 <= a0
    })
}

/// True when nothing of `q` can be hidden by `p` drawn first (tests 1–5).
fn p_may_go_first(p: &ScreenTriangle, q: &ScreenTriangle) -> bool {
    apart(p, q, 0) || apart(p, q, 1) || behind(p, q) || in_front(q, p) || projections_disjoint(p, q)
}

/// The pieces of `t` on either side of the plane `(n, o)` as triangles (a fan of each piece).
fn split(t: &ScreenTriangle, (n, o): (Vec3, Vec3)) -> Vec<ScreenTriangle> {
    let p = points(t);
    let mut d: [f64; 3] = std::array::from_fn(|k| n.dot(p[k] - o));
    // Corners within rounding of the plane lie on it: only a real cut makes pieces.
    for (k, dk) in d.iter_mut().enumerate() {
        if dk.abs() <= EPS * (1.0 + p[k].abs().max_element()) {
            *dk = 0.0;
        }
    }
    if d.iter().all(|&x| x >= 0.0) || d.iter().all(|&x| x <= 0.0) {
        return vec![*t];
    }
    let vertex = |k: usize| (t.x[k], t.y[k], t.z[k], t.inv_w[k], t.bary_w[k]);
    type V = (f64, f64, f64, f64, [f64; 2]);
    let lerp = |a: V, b: V, s: f64| -> V {
        (
            a.0 + (b.0 - a.0) * s,
            a.1 + (b.1 - a.1) * s,
            a.2 + (b.2 - a.2) * s,
            a.3 + (b.3 - a.3) * s,
            std::array::from_fn(|i| a.4[i] + (b.4[i] - a.4[i]) * s),
        )
    };
    let (mut front, mut back): (Vec<V>, Vec<V>) = (vec![], vec![]);
    for k in 0..3 {
        let j = (k + 1) % 3;
        let (a, b) = (vertex(k), vertex(j));
        if d[k] >= 0.0 {
            back.push(a);
        }
        if d[k] <= 0.0 {
            front.push(a);
        }
        if (d[k] > 0.0 && d[j] < 0.0) || (d[k] < 0.0 && d[j] > 0.0) {
            let m = lerp(a, b, d[k] / (d[k] - d[j]));
            back.push(m);
            front.push(m);
        }
    }
    let mut out = vec![];
    for poly in [front, back] {
        for k in 1..poly.len().saturating_sub(1) {
            let c = [poly[0], poly[k], poly[k + 1]];
            out.push(ScreenTriangle {
                x: c.map(|v| v.0),
                y: c.map(|v| v.1),
                z: c.map(|v| v.2),
                inv_w: c.map(|v| v.3),
                bary_w: c.map(|v| v.4),
                source: t.source,
            });
        }
    }
    out
}

/// `tris` in an order to draw them back to front with no depth test, split where no order
/// exists. Returns the order and the number of splits made.
pub fn depth_sort(tris: Vec<ScreenTriangle>) -> (Vec<ScreenTriangle>, usize) {
    let mut list: Vec<(ScreenTriangle, bool)> = tris.into_iter().map(|t| (t, false)).collect();
    list.sort_by(|a, b| depth_range(&b.0).0.total_cmp(&depth_range(&a.0).0));
    let mut queue: VecDeque<(ScreenTriangle, bool)> = list.into();
    let budget = 4 * queue.len() + 1000;
    let (mut out, mut splits) = (Vec::with_capacity(queue.len()), 0);
    'next: while let Some((p, moved)) = queue.pop_front() {
        let near_p = depth_range(&p).1;
        for i in 0..queue.len() {
            let q = &queue[i].0;
            if depth_range(q).0 <= near_p {
                break; // this and every later triangle lies wholly behind P
            }
            if p_may_go_first(&p, q) {
                continue;
            }
            if splits < budget {
                let q_first = behind(q, &p) || in_front(&p, q);
                if q_first && !queue[i].1 {
                    // Q goes first: to the front, marked; P waits behind it.
                    let q = queue.remove(i).expect("in range");
                    queue.push_front((p, moved));
                    queue.push_front((q.0, true));
                    continue 'next;
                }
                // A cycle, or triangles that pierce each other: cut P by Q's plane, or else Q
                // by P's, and sort the pieces in.
                if let Some(pieces) = plane(q).map(|pl| split(&p, pl)).filter(|v| v.len() > 1) {
                    splits += 1;
                    insert_all(&mut queue, pieces);
                    continue 'next;
                }
                if let Some(pieces) = plane(&p).map(|pl| split(q, pl)).filter(|v| v.len() > 1) {
                    splits += 1;
                    queue.remove(i);
                    queue.push_front((p, moved));
                    insert_all(&mut queue, pieces);
                    continue 'next;
                }
            }
        }
        out.push(p);
    }
    (out, splits)
}

/// Puts `pieces` into the queue in its order (farthest first).
fn insert_all(queue: &mut VecDeque<(ScreenTriangle, bool)>, pieces: Vec<ScreenTriangle>) {
    for t in pieces {
        let far = depth_range(&t).0;
        let at = queue.iter().position(|(q, _)| depth_range(q).0 < far).unwrap_or(queue.len());
        queue.insert(at, (t, false));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(p: [(f64, f64, f64); 3], source: u32) -> ScreenTriangle {
        ScreenTriangle {
            x: p.map(|v| v.0),
            y: p.map(|v| v.1),
            z: p.map(|v| v.2),
            inv_w: [1.0; 3],
            bary_w: [[0.0; 2]; 3],
            source,
        }
    }

    #[test]
    fn disjoint_depths_keep_their_order_and_piercing_triangles_are_split() {
        let far = tri([(0.0, 0.0, 0.9), (10.0, 0.0, 0.9), (0.0, 10.0, 0.9)], 0);
        let near = tri([(0.0, 0.0, 0.1), (10.0, 0.0, 0.1), (0.0, 10.0, 0.1)], 1);
        let (order, splits) = depth_sort(vec![near, far]);
        assert_eq!((order.iter().map(|t| t.source).collect::<Vec<_>>(), splits), (vec![0, 1], 0));
        // Two triangles crossing each other along a line: no order exists without a cut.
        let a = tri([(0.0, 0.0, 0.2), (10.0, 0.0, 0.8), (0.0, 10.0, 0.2)], 0);
        let b = tri([(0.0, 0.0, 0.8), (10.0, 0.0, 0.2), (0.0, 10.0, 0.8)], 1);
        let (order, splits) = depth_sort(vec![a, b]);
        assert!(splits >= 1 && order.len() >= 3, "{splits} splits, {} pieces", order.len());
    }
}
