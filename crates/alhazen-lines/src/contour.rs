//! Reflex contours of curved surfaces (Glaeser §5, Theorem 10): in a mirror, a sphere, cylinder
//! or cone is outlined not by its contour seen from the eye but by the points `S` where the
//! reflected ray `R → S` touches it, `R` the reflex of `S`: the zero set of
//! `F(a, b) = n(a, b) · (S(a, b) − R(S(a, b)))` over the surface's parameters. For each of a
//! run of values of `a` the roots in `b` are bracketed on a fine scan and bisected; roots of
//! neighbouring `a` are linked into curves.

use crate::reflect::Mirror;
use crate::view::View;
use alhazen_math::{Transform, Vec3, orthonormal_basis};
use alhazen_scene::Shape;
use std::f64::consts::{PI, TAU};

/// A surface as `(a, b) ↦ (point, outward normal)` on `[0, 1]²`, periodic in `b`.
pub struct Surface {
    eval: Box<dyn Fn(f64, f64) -> (Vec3, Vec3) + Sync>,
}

impl Surface {
    /// The surface of a sphere, cylinder or cone placed by a similarity: for a sphere `a` is
    /// the longitude about the axis towards `toward` and `b` the latitude from it (so every
    /// meridian crosses the contour); for a cylinder or cone `a` runs along the axis, `b` around.
    pub fn of(shape: &Shape, t: &Transform, toward: Vec3) -> Option<Surface> {
        let scale = t.vector(Vec3::X).length();
        let eval: Box<dyn Fn(f64, f64) -> (Vec3, Vec3) + Sync> = match *shape {
            Shape::Sphere { center, radius } => {
                let (c, r) = (t.point(center), radius * scale);
                let w = (toward - c).try_normalize().unwrap_or(Vec3::Y);
                let (u, v) = orthonormal_basis(w);
                Box::new(move |a, b| {
                    let (th, ph) = (PI * b, TAU * a);
                    let n = w * th.cos() + (u * ph.cos() + v * ph.sin()) * th.sin();
                    (c + n * r, n)
                })
            }
            Shape::Cylinder { base, top, radius, .. } => {
                let (b0, b1, r) = (t.point(base), t.point(top), radius * scale);
                let axis = b1 - b0;
                let (u, v) = orthonormal_basis(axis.normalize());
                Box::new(move |a, b| {
                    let ph = TAU * b;
                    let n = u * ph.cos() + v * ph.sin();
                    (b0 + axis * a + n * r, n)
                })
            }
            Shape::Cone { base, apex, radius, .. } => {
                let (b0, ap, r) = (t.point(base), t.point(apex), radius * scale);
                let axis = ap - b0;
                let h = axis.length();
                let w = axis / h;
                let (u, v) = orthonormal_basis(w);
                Box::new(move |a, b| {
                    let ph = TAU * b;
                    let radial = u * ph.cos() + v * ph.sin();
                    // Up the generator; the normal leans out by the half-angle.
                    let n = (radial * h + w * r).normalize();
                    (b0 + axis * a + radial * (r * (1.0 - a)), n)
                })
            }
            _ => return None,
        };
        Some(Surface { eval })
    }
}

/// Rows of `a`, scan steps of `b`, root-refinement steps at most.
const ROWS: usize = 96;
const SCAN: usize = 128;
const REFINE: usize = 60;

/// The reflex contour of `surface` in `mirror`, as curves of points on the surface (closed
/// curves repeat their first point).
pub fn reflex_contour(surface: &Surface, mirror: &Mirror, view: &View) -> Vec<Vec<Vec3>> {
    let viewer = view.viewer();
    let f = |a: f64, b: f64| -> Option<f64> {
        let (s, n) = (surface.eval)(a, b);
        let r = mirror.reflex(viewer, s)?;
        Some(n.dot((s - r).normalize_or_zero()))
    };
    let mut rows: Vec<Vec<f64>> = vec![];
    for k in 0..=ROWS {
        // Keep off the poles of a sphere and the apex of a cone.
        let a = 1e-4 + (1.0 - 2e-4) * k as f64 / ROWS as f64;
        // The scan of a row goes through the batch solver.
        let bs: Vec<f64> = (0..=SCAN).map(|j| j as f64 / SCAN as f64).collect();
        let (pts, normals): (Vec<Vec3>, Vec<Vec3>) = bs.iter().map(|&b| (surface.eval)(a, b)).unzip();
        let values: Vec<Option<f64>> = mirror
            .reflexes(viewer, &pts)
            .iter()
            .zip(pts.iter().zip(&normals))
            .map(|(r, (s, n))| r.map(|r| n.dot((*s - r).normalize_or_zero())))
            .collect();
        let mut roots = vec![];
        for j in 0..SCAN {
            if let (Some(f0), Some(f1)) = (values[j], values[j + 1])
                && (f0 > 0.0) != (f1 > 0.0)
            {
                roots.push(refine_root(&f, a, (bs[j], f0), (bs[j + 1], f1)));
            }
        }
        rows.push(roots);
    }
    link(&rows, surface)
}

/// A sign change of `f(a, ·)` between `lo` and `hi` narrowed by the Illinois variant of false
/// position (superlinear, and never leaves the bracket) until the bracket is below 1e-13.
fn refine_root(f: &impl Fn(f64, f64) -> Option<f64>, a: f64, mut lo: (f64, f64), mut hi: (f64, f64)) -> f64 {
    let mut side = 0;
    for _ in 0..REFINE {
        if hi.0 - lo.0 < 1e-13 {
            break;
        }
        let x = (lo.0 * hi.1 - hi.0 * lo.1) / (hi.1 - lo.1);
        let x = if x > lo.0 && x < hi.0 { x } else { 0.5 * (lo.0 + hi.0) };
        let Some(fx) = f(a, x) else { break };
        if fx == 0.0 {
            return x;
        }
        if (fx > 0.0) == (lo.1 > 0.0) {
            lo = (x, fx);
            if side == -1 {
                hi.1 *= 0.5;
            }
            side = -1;
        } else {
            hi = (x, fx);
            if side == 1 {
                lo.1 *= 0.5;
            }
            side = 1;
        }
    }
    let (x0, x1) = (lo.0, hi.0);
    if x1 - x0 < 1e-9 { 0.5 * (x0 + x1) } else { (lo.0 * hi.1 - hi.0 * lo.1) / (hi.1 - lo.1) }
}

/// Links the roots of consecutive rows by nearest `b` (periodic) into polylines.
fn link(rows: &[Vec<f64>], surface: &Surface) -> Vec<Vec<Vec3>> {
    let a_of = |k: usize| 1e-4 + (1.0 - 2e-4) * k as f64 / ROWS as f64;
    let dist = |x: f64, y: f64| {
        let d = (x - y).rem_euclid(1.0);
        d.min(1.0 - d)
    };
    let mut open: Vec<(f64, Vec<Vec3>)> = vec![];
    let mut done = vec![];
    for (k, roots) in rows.iter().enumerate() {
        let mut next: Vec<(f64, Vec<Vec3>)> = vec![];
        let mut taken = vec![false; open.len()];
        for &b in roots {
            let p = (surface.eval)(a_of(k), b).0;
            let best = (0..open.len())
                .filter(|&i| !taken[i])
                .min_by(|&i, &j| dist(open[i].0, b).total_cmp(&dist(open[j].0, b)));
            match best {
                Some(i) if dist(open[i].0, b) < 0.08 => {
                    taken[i] = true;
                    let mut pts = std::mem::take(&mut open[i].1);
                    pts.push(p);
                    next.push((b, pts));
                }
                _ => next.push((b, vec![p])),
            }
        }
        for (i, o) in open.into_iter().enumerate() {
            if !taken[i] && o.1.len() > 1 {
                done.push(o.1);
            }
        }
        open = next;
    }
    done.extend(open.into_iter().map(|o| o.1).filter(|p| p.len() > 1));
    // A curve that ends where another (or itself) starts, across the seam a = 1 → 0, closes up.
    for c in done.iter_mut() {
        let (first, last) = (c[0], c[c.len() - 1]);
        let step = (c[1] - first).length();
        if c.len() > 2 && (last - first).length() < 3.0 * step {
            c.push(first);
        }
    }
    done
}
