//! Intersection curves where objects meet: plane sections of spheres (circles) and of cylinders
//! (ellipses, or generating lines when the plane is parallel to the axis), two spheres (the
//! circle in their radical plane), and flat faces against flat faces (segments) — exact curves,
//! cut to the faces and the finite cylinder by exact angular intervals (`A cos θ + B sin θ + C ≥
//! 0` per bounding half-plane). Cylinders and cones against spheres, cylinders, cones and
//! planes (quartics and conics) are traced generator by generator: each generator meets the
//! other surface exactly (a quadratic), 720 generators around, linked into polylines. Lines a
//! face shares with the other object's own edges (a box standing on the floor, a cylinder's
//! base on it) are not repeated.

use crate::curves::{Curve, LineKind, SceneLine};
use alhazen_math::{Vec3, orthonormal_basis};
use alhazen_scene::{Scene, Shape};
use std::f64::consts::TAU;

/// A flat piece of a surface: the plane and the convex outline it is cut to.
#[derive(Clone, Debug)]
struct Flat {
    point: Vec3,
    normal: Vec3,
    outline: Outline,
}

#[derive(Clone, Debug)]
enum Outline {
    /// The whole plane.
    Unbounded,
    /// A convex polygon, counter-clockwise about the normal.
    Polygon(Vec<Vec3>),
    /// A disk about the point.
    Disk(f64),
}

/// The pieces of an object's surface that intersections are computed on.
#[derive(Clone, Debug)]
enum Piece {
    Flat(Flat),
    Sphere {
        center: Vec3,
        radius: f64,
    },
    /// The side of a finite cylinder from `base` along `axis` (its length).
    Side {
        base: Vec3,
        axis: Vec3,
        radius: f64,
    },
    /// The side of a finite cone from its base circle to `apex`.
    ConeSide {
        base: Vec3,
        apex: Vec3,
        radius: f64,
    },
}

/// Meshes with more triangles are left out of intersections (their pairs grow as the product).
const MAX_TRIANGLES: usize = 4096;

fn pieces(o: &alhazen_scene::Object, polyhedron: Option<&[[Vec3; 3]]>) -> Vec<Piece> {
    let t = &o.transform;
    let flat_disk = |c: Vec3, n: Vec3, r: f64| Piece::Flat(Flat { point: c, normal: n, outline: Outline::Disk(r) });
    match (&o.shape, crate::curves::similarity(t)) {
        (Shape::Plane { point, normal }, _) => {
            vec![Piece::Flat(Flat {
                point: t.point(*point),
                normal: t.normal(*normal).normalize(),
                outline: Outline::Unbounded,
            })]
        }
        (Shape::Sphere { center, radius }, Some(s)) => {
            vec![Piece::Sphere { center: t.point(*center), radius: radius * s }]
        }
        (Shape::Cylinder { base, top, radius, capped }, Some(s)) => {
            let (b, tp) = (t.point(*base), t.point(*top));
            let mut v = vec![Piece::Side { base: b, axis: tp - b, radius: radius * s }];
            if *capped {
                let a = (tp - b).normalize();
                v.push(flat_disk(b, -a, radius * s));
                v.push(flat_disk(tp, a, radius * s));
            }
            v
        }
        (Shape::Cone { base, apex, radius, capped }, Some(s)) => {
            let (b, ap) = (t.point(*base), t.point(*apex));
            let mut v = vec![Piece::ConeSide { base: b, apex: ap, radius: radius * s }];
            if *capped {
                v.push(flat_disk(b, (b - ap).normalize(), radius * s));
            }
            v
        }
        (Shape::Disk { center, normal, radius }, Some(s)) => {
            vec![flat_disk(t.point(*center), t.normal(*normal).normalize(), radius * s)]
        }
        (Shape::Box { .. } | Shape::Mesh { .. }, _) => {
            let Some(tris) = polyhedron else { return vec![] };
            if tris.len() > MAX_TRIANGLES {
                return vec![];
            }
            tris.iter()
                .filter_map(|&p| {
                    let n = (p[1] - p[0]).cross(p[2] - p[0]).try_normalize()?;
                    Some(Piece::Flat(Flat { point: p[0], normal: n, outline: Outline::Polygon(p.to_vec()) }))
                })
                .collect()
        }
        _ => vec![],
    }
}

/// The angles θ of `[0, 2π)` where every `A cos θ + B sin θ + C ≥ 0` holds, as intervals.
fn angular_intervals(constraints: &[(f64, f64, f64)]) -> Vec<(f64, f64)> {
    let mut cuts = vec![0.0, TAU];
    for &(a, b, c) in constraints {
        let r = (a * a + b * b).sqrt();
        if r <= 1e-300 {
            if c < 0.0 {
                return vec![];
            }
            continue;
        }
        let x = -c / r;
        if x >= 1.0 {
            return vec![];
        }
        if x > -1.0 {
            let (phi, alpha) = (b.atan2(a), x.acos());
            cuts.push((phi - alpha).rem_euclid(TAU));
            cuts.push((phi + alpha).rem_euclid(TAU));
        }
    }
    cuts.sort_by(f64::total_cmp);
    let holds = |th: f64| constraints.iter().all(|&(a, b, c)| a * th.cos() + b * th.sin() + c >= 0.0);
    let mut out: Vec<(f64, f64)> = vec![];
    for w in cuts.windows(2) {
        if w[1] - w[0] > 1e-12 && holds(0.5 * (w[0] + w[1])) {
            match out.last_mut() {
                Some(last) if (last.1 - w[0]).abs() < 1e-12 => last.1 = w[1],
                _ => out.push((w[0], w[1])),
            }
        }
    }
    // Join across θ = 0.
    if out.len() > 1 && out[0].0 < 1e-12 && (out[out.len() - 1].1 - TAU).abs() < 1e-12 {
        let first = out.remove(0);
        let last = out.len() - 1;
        out[last].1 = TAU + first.1;
    }
    out
}

/// Half-plane constraints of a flat outline on the curve `c + u cos θ + v sin θ` lying in its
/// plane: each edge's inward side. A disk outline gives no linear constraints (handled apart).
fn outline_constraints(f: &Flat, c: Vec3, u: Vec3, v: Vec3) -> Vec<(f64, f64, f64)> {
    match &f.outline {
        Outline::Polygon(p) => (0..p.len())
            .map(|k| {
                let (a, b) = (p[k], p[(k + 1) % p.len()]);
                let inward = f.normal.cross(b - a);
                (inward.dot(u), inward.dot(v), inward.dot(c - a))
            })
            .collect(),
        _ => vec![],
    }
}

/// Where a plane section `c + u cos θ + v sin θ` (a circle or an ellipse in `f`'s plane) lies
/// inside a disk outline: `|x − p|² ≤ r²` is quadratic in cos/sin, so it is decided on fine
/// intervals by bisection between the linear cuts.
fn inside_disk(f: &Flat, c: Vec3, u: Vec3, v: Vec3, iv: Vec<(f64, f64)>) -> Vec<(f64, f64)> {
    let Outline::Disk(r) = f.outline else { return iv };
    let inside = |th: f64| (c + u * th.cos() + v * th.sin() - f.point).length_squared() <= r * r;
    let mut out = vec![];
    for (a, b) in iv {
        let n = 256;
        let mut start: Option<f64> = None;
        let mut prev = (a, inside(a));
        if prev.1 {
            start = Some(a);
        }
        for k in 1..=n {
            let th = a + (b - a) * k as f64 / n as f64;
            let cur = (th, inside(th));
            if cur.1 != prev.1 {
                let (mut lo, mut hi) = (prev.0, cur.0);
                for _ in 0..60 {
                    let m = 0.5 * (lo + hi);
                    if inside(m) == prev.1 { lo = m } else { hi = m }
                }
                let edge = 0.5 * (lo + hi);
                match start.take() {
                    Some(s) => out.push((s, edge)),
                    None => start = Some(edge),
                }
            }
            prev = cur;
        }
        if let Some(s) = start {
            out.push((s, b));
        }
    }
    out
}

fn sphere_flat(center: Vec3, radius: f64, f: &Flat) -> Vec<Curve> {
    let d = (center - f.point).dot(f.normal);
    if d.abs() >= radius * (1.0 - 1e-9) {
        return vec![];
    }
    let c = center - f.normal * d;
    let rho = (radius * radius - d * d).sqrt();
    let (u, v) = orthonormal_basis(f.normal);
    let iv = angular_intervals(&outline_constraints(f, c, u * rho, v * rho));
    inside_disk(f, c, u * rho, v * rho, iv)
        .into_iter()
        .map(|(a, b)| Curve::Arc { center: c, u, v, radius: rho, start: a, end: b })
        .collect()
}

fn side_flat(base: Vec3, axis: Vec3, radius: f64, f: &Flat) -> Vec<Curve> {
    let len = axis.length();
    let a = axis / len;
    let (x, y) = orthonormal_basis(a);
    let an = a.dot(f.normal);
    if an.abs() < 1e-9 {
        return side_flat_parallel(base, axis, radius, f, (x, y));
    }
    // Height along the axis where the generator at θ meets the plane: affine in cos θ, sin θ.
    let h0 = (f.point - base).dot(f.normal) / an;
    let (hc, hs) = (-radius * x.dot(f.normal) / an, -radius * y.dot(f.normal) / an);
    // The section is the rim itself (the plane ⟂ axis through an end): already an edge.
    if hc.abs() + hs.abs() < 1e-9 * len && (h0.abs() < 1e-9 * len || (h0 - len).abs() < 1e-9 * len) {
        return vec![];
    }
    let c = base + a * h0;
    let (u, v) = (x * radius + a * hc, y * radius + a * hs);
    let mut cons = vec![(hc, hs, h0), (-hc, -hs, len - h0)];
    cons.extend(outline_constraints(f, c, u, v));
    let iv = angular_intervals(&cons);
    inside_disk(f, c, u, v, iv).into_iter().map(|(s, e)| Curve::Ellipse { center: c, u, v, start: s, end: e }).collect()
}

/// A plane parallel to the axis cuts the side in up to two generating lines.
fn side_flat_parallel(base: Vec3, axis: Vec3, radius: f64, f: &Flat, (x, y): (Vec3, Vec3)) -> Vec<Curve> {
    let (a, b, c) = (radius * x.dot(f.normal), radius * y.dot(f.normal), (base - f.point).dot(f.normal));
    let r = (a * a + b * b).sqrt();
    if r <= 0.0 || (c / r).abs() >= 1.0 {
        return vec![];
    }
    let (phi, alpha) = (b.atan2(a), (-c / r).acos());
    [phi - alpha, phi + alpha]
        .into_iter()
        .flat_map(|th| {
            let p = base + (x * th.cos() + y * th.sin()) * radius;
            clip_segment(p, p + axis, f)
        })
        .collect()
}

/// The part of segment `a b` (in `f`'s plane) inside its outline (Cyrus–Beck).
fn clip_segment(a: Vec3, b: Vec3, f: &Flat) -> Vec<Curve> {
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    let d = b - a;
    match &f.outline {
        Outline::Unbounded => {}
        Outline::Polygon(p) => {
            for k in 0..p.len() {
                let (e0, e1) = (p[k], p[(k + 1) % p.len()]);
                let inward = f.normal.cross(e1 - e0);
                let (num, den) = (inward.dot(a - e0), inward.dot(d));
                if den.abs() < 1e-300 {
                    if num < 0.0 {
                        return vec![];
                    }
                } else if den > 0.0 {
                    t0 = t0.max(-num / den);
                } else {
                    t1 = t1.min(-num / den);
                }
            }
        }
        Outline::Disk(r) => {
            let m = a - f.point;
            let (qa, qb, qc) = (d.length_squared(), 2.0 * m.dot(d), m.length_squared() - r * r);
            let disc = qb * qb - 4.0 * qa * qc;
            if qa <= 0.0 || disc < 0.0 {
                return vec![];
            }
            let sq = disc.sqrt();
            t0 = t0.max((-qb - sq) / (2.0 * qa));
            t1 = t1.min((-qb + sq) / (2.0 * qa));
        }
    }
    if t1 - t0 <= 1e-12 {
        return vec![];
    }
    vec![Curve::Segment { a: a + d * t0, b: a + d * t1 }]
}

/// Two flat pieces: the line of their planes, cut to both outlines; nothing if it runs along
/// an edge of either (the objects only touch there).
fn flat_flat(f: &Flat, g: &Flat) -> Vec<Curve> {
    let dir = f.normal.cross(g.normal);
    let s2 = dir.length_squared();
    if s2 < 1e-18 {
        return vec![];
    }
    // A point on both planes: least-norm solution of n_f·x = d_f, n_g·x = d_g.
    let (df, dg) = (f.normal.dot(f.point), g.normal.dot(g.point));
    let p = (g.normal.cross(dir) * df + dir.cross(f.normal) * dg) / s2;
    let dir = dir / s2.sqrt();
    let on_edge = |h: &Flat| match &h.outline {
        Outline::Polygon(poly) => (0..poly.len()).any(|k| {
            let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
            let off = |q: Vec3| (q - p - dir * (q - p).dot(dir)).length();
            off(a) < 1e-9 * (1.0 + (b - a).length()) && off(b) < 1e-9 * (1.0 + (b - a).length())
        }),
        _ => false,
    };
    if on_edge(f) || on_edge(g) {
        return vec![];
    }
    // A long enough segment of the line, then both outlines.
    let reach = |h: &Flat| match &h.outline {
        Outline::Polygon(poly) => poly.iter().map(|q| (*q - p).length()).fold(0.0, f64::max),
        Outline::Disk(r) => (h.point - p).length() + r,
        Outline::Unbounded => 0.0,
    };
    let half = reach(f).max(reach(g));
    if half == 0.0 {
        return vec![];
    }
    let mut out = vec![];
    for c in clip_segment(p - dir * half, p + dir * half, f) {
        if let Curve::Segment { a, b } = c {
            out.extend(clip_segment(a, b, g));
        }
    }
    out
}

fn sphere_sphere(c1: Vec3, r1: f64, c2: Vec3, r2: f64) -> Vec<Curve> {
    let d = c2 - c1;
    let dd = d.length_squared();
    let dist = dd.sqrt();
    if dist >= r1 + r2 || dist <= (r1 - r2).abs() || dd == 0.0 {
        return vec![];
    }
    let k = (dd + r1 * r1 - r2 * r2) / (2.0 * dd);
    let c = c1 + d * k;
    let rho = (r1 * r1 - (d * k).length_squared()).max(0.0).sqrt();
    vec![Curve::circle(c, d, rho)]
}

fn pair(p: &Piece, q: &Piece) -> Vec<Curve> {
    match (p, q) {
        (Piece::Flat(f), Piece::Flat(g)) => flat_flat(f, g),
        (Piece::Sphere { center, radius }, Piece::Flat(f)) | (Piece::Flat(f), Piece::Sphere { center, radius }) => {
            sphere_flat(*center, *radius, f)
        }
        (Piece::Side { base, axis, radius }, Piece::Flat(f)) | (Piece::Flat(f), Piece::Side { base, axis, radius }) => {
            side_flat(*base, *axis, *radius, f)
        }
        (Piece::Sphere { center: c1, radius: r1 }, Piece::Sphere { center: c2, radius: r2 }) => {
            sphere_sphere(*c1, *r1, *c2, *r2)
        }
        // The rest meet in quartics (or conics on a cone): traced generator by generator.
        (Piece::Side { .. } | Piece::ConeSide { .. }, _) => ruled_section(p, q),
        (_, Piece::Side { .. } | Piece::ConeSide { .. }) => ruled_section(q, p),
    }
}

/// Generators traced around a cylinder's or cone's side.
const GENERATORS: usize = 720;

/// The intersection of a ruled side (cylinder or cone) with another piece, exact on every one
/// of `GENERATORS` generators — each meets a quadric in at most two points (a quadratic in
/// the height) and a plane in one — and linked from generator to generator into polylines.
fn ruled_section(ruled: &Piece, other: &Piece) -> Vec<Curve> {
    let (base, axis, r, cone) = match *ruled {
        Piece::Side { base, axis, radius } => (base, axis, radius, false),
        Piece::ConeSide { base, apex, radius } => (base, apex - base, radius, true),
        _ => return vec![],
    };
    let (x, y) = orthonormal_basis(axis.normalize());
    let generator = |th: f64| {
        let foot = base + (x * th.cos() + y * th.sin()) * r;
        // h ∈ [0, 1] from the base circle to the top circle (or the apex).
        (foot, if cone { base + axis - foot } else { axis })
    };
    let mut rows = vec![];
    for k in 0..GENERATORS {
        let th = TAU * k as f64 / GENERATORS as f64;
        let (o, d) = generator(th);
        // Hits on the rims (or the apex) are rims, drawn already: a cone standing on the floor.
        let hs: Vec<f64> = line_hits(other, o, d).into_iter().filter(|h| *h > 1e-9 && *h < 1.0 - 1e-9).collect();
        rows.push(hs.into_iter().map(|h| o + d * h).collect::<Vec<Vec3>>());
    }
    link_rows(&rows, (axis.length() + r) * 0.05)
}

/// Parameters `h` where the line `o + h d` meets a piece (within its extent).
fn line_hits(piece: &Piece, o: Vec3, d: Vec3) -> Vec<f64> {
    let roots = |a: f64, b: f64, c: f64| -> Vec<f64> {
        if a.abs() < 1e-300 {
            return if b != 0.0 { vec![-c / b] } else { vec![] };
        }
        let disc = b * b - 4.0 * a * c;
        if disc < 0.0 {
            return vec![];
        }
        let q = -0.5 * (b + disc.sqrt().copysign(b));
        if q == 0.0 { vec![0.0] } else { vec![q / a, c / q] }
    };
    match *piece {
        Piece::Sphere { center, radius } => {
            let m = o - center;
            roots(d.length_squared(), 2.0 * m.dot(d), m.length_squared() - radius * radius)
        }
        Piece::Side { base, axis, radius } => {
            let a = axis.normalize();
            let perp = |v: Vec3| v - a * v.dot(a);
            let (m, dp) = (perp(o - base), perp(d));
            roots(dp.length_squared(), 2.0 * m.dot(dp), m.length_squared() - radius * radius)
                .into_iter()
                .filter(|h| (0.0..=axis.length()).contains(&(o + d * *h - base).dot(a)))
                .collect()
        }
        Piece::ConeSide { base, apex, radius } => {
            let axis = apex - base;
            let height = axis.length();
            let a = axis / height;
            let k2 = (radius / height).powi(2);
            let (m, s0, ds) = (o - base, (o - base).dot(a), d.dot(a));
            let (mp, dp) = (m - a * s0, d - a * ds);
            // |mp + h dp|² = k² (H − s0 − h ds)²
            let h0 = height - s0;
            roots(
                dp.length_squared() - k2 * ds * ds,
                2.0 * (mp.dot(dp) + k2 * h0 * ds),
                mp.length_squared() - k2 * h0 * h0,
            )
            .into_iter()
            .filter(|h| (0.0..=height).contains(&(s0 + ds * *h)))
            .collect()
        }
        Piece::Flat(ref f) => {
            let den = d.dot(f.normal);
            if den.abs() < 1e-300 {
                return vec![];
            }
            let h = (f.point - o).dot(f.normal) / den;
            let p = o + d * h;
            let inside = match &f.outline {
                Outline::Unbounded => true,
                Outline::Disk(r) => (p - f.point).length_squared() <= r * r,
                Outline::Polygon(poly) => (0..poly.len()).all(|k| {
                    let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
                    f.normal.cross(b - a).dot(p - a) >= 0.0
                }),
            };
            if inside { vec![h] } else { vec![] }
        }
    }
}

/// Links points of consecutive (cyclic) rows by nearest distance, below `gap`, into segments.
fn link_rows(rows: &[Vec<Vec3>], gap: f64) -> Vec<Curve> {
    let mut out = vec![];
    let n = rows.len();
    for k in 0..n {
        let (cur, next) = (&rows[k], &rows[(k + 1) % n]);
        let mut taken = vec![false; next.len()];
        for p in cur {
            let best = (0..next.len())
                .filter(|&j| !taken[j])
                .min_by(|&i, &j| (next[i] - *p).length_squared().total_cmp(&(next[j] - *p).length_squared()));
            if let Some(j) = best
                && (next[j] - *p).length() < gap
            {
                taken[j] = true;
                out.push(Curve::Segment { a: *p, b: next[j] });
            }
        }
    }
    out
}

/// Lower and upper corners of a box.
type Aabb = (Vec3, Vec3);

/// A piece with its bounds (`None`: unbounded).
type Bounded = (Piece, Option<Aabb>);

/// Bounds of an object's pieces (`None`: unbounded), padded a little.
fn bounds(pieces: &[Piece]) -> Option<Aabb> {
    let (mut lo, mut hi) = (Vec3::splat(f64::INFINITY), Vec3::splat(f64::NEG_INFINITY));
    let mut grow = |p: Vec3, r: f64| {
        lo = lo.min(p - Vec3::splat(r));
        hi = hi.max(p + Vec3::splat(r));
    };
    for p in pieces {
        match p {
            Piece::Sphere { center, radius } => grow(*center, *radius),
            Piece::Side { base, axis, radius } => {
                grow(*base, *radius);
                grow(*base + *axis, *radius);
            }
            Piece::ConeSide { base, apex, radius } => {
                grow(*base, *radius);
                grow(*apex, 0.0);
            }
            Piece::Flat(f) => match &f.outline {
                Outline::Unbounded => return None,
                Outline::Disk(r) => grow(f.point, *r),
                Outline::Polygon(poly) => poly.iter().for_each(|q| grow(*q, 0.0)),
            },
        }
    }
    let pad = 1e-9 * (hi - lo).length();
    (lo.x <= hi.x).then(|| (lo - Vec3::splat(pad), hi + Vec3::splat(pad)))
}

/// The intersection curves of every pair of objects whose bounds overlap.
pub fn intersection_lines(scene: &Scene, polyhedra: &[Option<Vec<[Vec3; 3]>>]) -> Vec<SceneLine> {
    // Each piece with its bounds (`None`: unbounded), and each object's.
    let objs: Vec<(Vec<Bounded>, Option<Aabb>)> = scene
        .objects
        .iter()
        .zip(polyhedra)
        .map(|(o, poly)| {
            let ps = pieces(o, poly.as_deref());
            let whole = bounds(&ps);
            (ps.into_iter().map(|p| (p.clone(), bounds(std::slice::from_ref(&p)))).collect(), whole)
        })
        .collect();
    let overlap = |a: Option<Aabb>, b: Option<Aabb>| match (a, b) {
        (Some((a0, a1)), Some((b0, b1))) => a0.cmple(b1).all() && b0.cmple(a1).all(),
        _ => true,
    };
    let mut out = vec![];
    for i in 0..objs.len() {
        for j in i + 1..objs.len() {
            if !overlap(objs[i].1, objs[j].1) {
                continue;
            }
            for (p, pb) in &objs[i].0 {
                for (q, qb) in &objs[j].0 {
                    if !overlap(*pb, *qb) {
                        continue;
                    }
                    for curve in pair(p, q) {
                        out.push(SceneLine {
                            curve,
                            object: i as u32,
                            kind: LineKind::Intersection { other: j as u32 },
                        });
                    }
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn flat(point: Vec3, normal: Vec3) -> Flat {
        Flat { point, normal, outline: Outline::Unbounded }
    }

    #[test]
    fn a_sphere_cut_by_a_plane_gives_its_circle() {
        let c = sphere_flat(Vec3::ZERO, 2.0, &flat(Vec3::new(0.0, 1.0, 0.0), Vec3::Y));
        assert_eq!(c.len(), 1);
        for k in 0..10 {
            let p = c[0].point(k as f64 / 10.0);
            assert!((p.length() - 2.0).abs() < 1e-12 && (p.y - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn a_tilted_plane_cuts_a_cylinder_in_an_ellipse_within_its_height() {
        let n = Vec3::new(0.0, 1.0, 0.5).normalize();
        let curves = side_flat(Vec3::ZERO, Vec3::Y * 2.0, 1.0, &flat(Vec3::Y, n));
        assert!(!curves.is_empty());
        for c in &curves {
            for k in 0..=20 {
                let p = c.point(k as f64 / 20.0);
                assert!((Vec3::new(p.x, 0.0, p.z).length() - 1.0).abs() < 1e-12, "{p:?}");
                assert!((p - Vec3::Y).dot(n).abs() < 1e-12);
                assert!((-1e-12..=2.0 + 1e-12).contains(&p.y));
            }
        }
    }

    #[test]
    fn a_plane_through_a_cylinders_base_repeats_no_rim() {
        assert!(side_flat(Vec3::ZERO, Vec3::Y, 1.0, &flat(Vec3::ZERO, Vec3::Y)).is_empty());
    }

    #[test]
    fn angular_intervals_of_a_half_plane_are_half_the_circle() {
        let iv = angular_intervals(&[(1.0, 0.0, 0.0)]);
        let total: f64 = iv.iter().map(|(a, b)| b - a).sum();
        assert!((total - std::f64::consts::PI).abs() < 1e-12, "{iv:?}");
    }

    #[test]
    fn two_spheres_meet_in_their_radical_circle() {
        let c = sphere_sphere(Vec3::ZERO, 1.0, Vec3::X, 1.0);
        let p = c[0].point(0.3);
        assert!((p.length() - 1.0).abs() < 1e-12 && ((p - Vec3::X).length() - 1.0).abs() < 1e-12);
    }
}
