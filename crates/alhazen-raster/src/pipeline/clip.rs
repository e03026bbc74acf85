//! Clipping of polygons in homogeneous coordinates against the view volume
//! `−w ≤ x, y, z ≤ w` (course, §"Clipping polygons": Sutherland–Hodgman once per bounding
//! plane, in 4D so that nothing is divided by `w` before it is known to be positive).

use alhazen_math::Vec4;

/// Attributes per vertex: world position (3, for user clip planes) and the weights of the
/// source triangle's corners 1 and 2 (from [`BARY`]; everything else is interpolated from the
/// source triangle for the visible pixel alone).
pub const ATTRIBUTES: usize = 5;

/// Where the corner weights start among the attributes.
pub const BARY: usize = 3;

/// A clip-space vertex with its attributes (linear in clip space, so they interpolate with the
/// same parameter as the position).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClipVertex {
    /// Homogeneous position.
    pub pos: Vec4,
    /// Attributes, see [`ATTRIBUTES`].
    pub attr: [f64; ATTRIBUTES],
}

impl ClipVertex {
    /// Corner `k` of a source triangle: world position `p`, projected to `pos`, with the
    /// corner's weights (1 for itself).
    pub fn corner(pos: Vec4, p: alhazen_math::Vec3, k: usize) -> Self {
        let b = [(k == 1) as u8 as f64, (k == 2) as u8 as f64];
        ClipVertex { pos, attr: [p.x, p.y, p.z, b[0], b[1]] }
    }
}

fn lerp(a: &ClipVertex, b: &ClipVertex, t: f64) -> ClipVertex {
    let mut attr = [0.0; ATTRIBUTES];
    for k in 0..ATTRIBUTES {
        attr[k] = a.attr[k] + (b.attr[k] - a.attr[k]) * t;
    }
    ClipVertex { pos: a.pos + (b.pos - a.pos) * t, attr }
}

/// Signed distance-like value of the six planes `w ± x`, `w ± y`, `w ± z` (inside ≥ 0).
#[inline]
fn plane(p: Vec4, k: usize) -> f64 {
    let c = p[k / 2];
    if k.is_multiple_of(2) { p.w + c } else { p.w - c }
}

/// Sutherland–Hodgman against one half-space `f ≥ 0`, `f` affine along edges.
fn clip_against(poly: &[ClipVertex], f: impl Fn(&ClipVertex) -> f64) -> Vec<ClipVertex> {
    let Some(last) = poly.last() else { return vec![] };
    let mut next = Vec::with_capacity(poly.len() + 2);
    let (mut s, mut ds) = (*last, f(last));
    for &p in poly {
        let dp = f(&p);
        if dp >= 0.0 {
            if ds < 0.0 {
                next.push(lerp(&s, &p, ds / (ds - dp)));
            }
            next.push(p);
        } else if ds >= 0.0 {
            next.push(lerp(&s, &p, ds / (ds - dp)));
        }
        (s, ds) = (p, dp);
    }
    next
}

/// The part of a convex polygon inside the view volume (empty when none).
pub fn clip_polygon(poly: &[ClipVertex]) -> Vec<ClipVertex> {
    // Trivial accept: every vertex inside every plane.
    if poly.iter().all(|v| (0..6).all(|k| plane(v.pos, k) >= 0.0)) {
        return poly.to_vec();
    }
    let mut cur = poly.to_vec();
    for k in 0..6 {
        cur = clip_against(&cur, |v| plane(v.pos, k));
    }
    cur
}

/// The course's user clip distances: the part of the polygon where every world-space plane
/// `(n, d)` has `n·p + d ≥ 0` (`p` is the world position carried in the first attributes).
pub fn clip_user_planes(poly: Vec<ClipVertex>, planes: &[Vec4]) -> Vec<ClipVertex> {
    planes
        .iter()
        .fold(poly, |cur, pl| clip_against(&cur, |v| pl.x * v.attr[0] + pl.y * v.attr[1] + pl.z * v.attr[2] + pl.w))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn v(x: f64, y: f64, z: f64, w: f64) -> ClipVertex {
        ClipVertex { pos: Vec4::new(x, y, z, w), attr: [x; ATTRIBUTES] }
    }

    proptest! {
        #[test]
        fn user_clip_planes_keep_exactly_the_positive_side(
            c in prop::collection::vec((-3.0..3.0f64, -3.0..3.0f64, -3.0..3.0f64), 3),
            n in (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64), d in -1.0..1.0f64
        ) {
            prop_assume!(n.0 * n.0 + n.1 * n.1 + n.2 * n.2 > 0.01);
            let plane = Vec4::new(n.0, n.1, n.2, d);
            let f = |p: [f64; 3]| plane.x * p[0] + plane.y * p[1] + plane.z * p[2] + plane.w;
            let tri: Vec<ClipVertex> = c
                .iter()
                .map(|&(x, y, z)| {
                    let mut attr = [0.0; ATTRIBUTES];
                    attr[..3].copy_from_slice(&[x, y, z]);
                    ClipVertex { pos: Vec4::new(x, y, z, 1.0), attr }
                })
                .collect();
            let out = clip_user_planes(tri.clone(), &[plane]);
            for v in &out {
                prop_assert!(f([v.attr[0], v.attr[1], v.attr[2]]) >= -1e-9);
            }
            let kept = tri.iter().filter(|v| f([v.attr[0], v.attr[1], v.attr[2]]) >= 0.0).count();
            if kept == 3 {
                prop_assert_eq!(out.len(), 3);
            }
            if kept == 0 {
                prop_assert!(out.is_empty());
            }
        }

        #[test]
        fn clipped_triangles_stay_inside_and_keep_inside_points(
            c in prop::collection::vec((-3.0..3.0f64, -3.0..3.0f64, -3.0..3.0f64, -0.5..2.5f64), 3)
        ) {
            let tri: Vec<ClipVertex> = c.iter().map(|&(x, y, z, w)| v(x, y, z, w)).collect();
            let out = clip_polygon(&tri);
            for p in &out {
                for k in 0..6 {
                    prop_assert!(plane(p.pos, k) >= -1e-9, "vertex outside plane {k}: {:?}", p.pos);
                }
                prop_assert!((p.attr[0] - p.pos.x).abs() < 1e-9, "attributes follow the position");
            }
            // Brute force: points of the triangle inside the volume lie in the clipped polygon's
            // convex hull, checked through barycentric sampling and the plane tests.
            let inside = |p: Vec4| (0..6).all(|k| plane(p, k) >= 1e-9);
            let mut any_inside = false;
            for i in 0..=20 {
                for j in 0..=(20 - i) {
                    let (a, b) = (i as f64 / 20.0, j as f64 / 20.0);
                    let p = tri[0].pos * (1.0 - a - b) + tri[1].pos * a + tri[2].pos * b;
                    any_inside |= inside(p);
                }
            }
            prop_assert!(!any_inside || out.len() >= 3, "inside points but nothing kept");
        }
    }
}
