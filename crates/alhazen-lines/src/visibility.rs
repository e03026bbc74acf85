//! Exact hidden-line removal. Along a line, visibility can change only where its image crosses
//! the image of another line (an edge, a silhouette, a contour — Appel's observation behind
//! quantitative invisibility) or where the line itself pierces a surface. Those points are found
//! exactly (segment against segment on paper with orientation tests; the line as a ray against
//! the scene), and each piece between two of them gets one exact ray test from the eye at its
//! midpoint on the true curve. No step size enters the answer: chords of circles are only used
//! to find crossings, within the drawing tolerance.

use crate::Progress;
use crate::curves::SceneLine;
use crate::view::{Leeway, View};
use alhazen_math::{Ray, Vec2, Vec3};
use alhazen_render::World;
use alhazen_render::shape::ray_epsilon;
use rayon::prelude::*;

/// A chord of a line between two curve parameters, with its image on paper (film pixels).
#[derive(Clone, Copy, Debug)]
pub struct Chord {
    /// Index of the line.
    pub line: usize,
    /// Curve parameters of its ends.
    pub s: (f64, f64),
    /// Ends in space.
    pub p: (Vec3, Vec3),
    /// Ends on the film.
    pub q: (Vec2, Vec2),
}

/// A piece of a line with constant visibility.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Piece {
    /// Index of the line.
    pub line: usize,
    /// Curve parameters of its ends.
    pub s: (f64, f64),
    /// Seen from the eye.
    pub visible: bool,
}

/// The chords of every line, cut to the part in front of the eye.
pub fn chords(lines: &[SceneLine], view: &View, tol_mm: f64) -> Vec<Chord> {
    let mut out = vec![];
    for (i, l) in lines.iter().enumerate() {
        let knots = l.curve.knots(view, tol_mm);
        for w in knots.windows(2) {
            let (mut s0, mut s1) = (w[0], w[1]);
            let (mut a, mut b) = (l.curve.point(s0), l.curve.point(s1));
            // Near clipping: w is affine along the chord.
            let (ia, ib) = (view.in_front(a), view.in_front(b));
            if !ia && !ib {
                continue;
            }
            if !ia || !ib {
                let (wa, wb) = (view.depth(a), view.depth(b));
                let lim = 2e-6 * view.scale;
                let sm = s0 + (s1 - s0) * ((lim - wa) / (wb - wa)).clamp(0.0, 1.0);
                if ia {
                    (s1, b) = (sm, l.curve.point(sm));
                } else {
                    (s0, a) = (sm, l.curve.point(sm));
                }
                if !view.in_front(a) || !view.in_front(b) {
                    continue;
                }
            }
            // Only what lies on the film (and a margin) is drawn, and only crossings there can
            // change it: cut the chord to that window on paper (projective on the chord).
            let (qa, qb) = (view.to_film(a), view.to_film(b));
            // A chord across a panorama's seam: its ends are on either side of the film.
            if !view.is_projective() && (qa.x - qb.x).abs() > view.film.0 as f64 / 2.0 {
                continue;
            }
            let margin = 2.0;
            let window = alhazen_raster::clip::Window {
                xmin: -margin,
                ymin: -margin,
                xmax: view.film.0 as f64 + margin,
                ymax: view.film.1 as f64 + margin,
            };
            let Some((ca, cb)) = alhazen_raster::clip::liang_barsky(&window, qa, qb) else { continue };
            let d = qb - qa;
            let l2 = d.length_squared();
            let film_t = |q: Vec2| if l2 > 0.0 { ((q - qa).dot(d) / l2).clamp(0.0, 1.0) } else { 0.0 };
            let (t0, t1) = (view.chord_param(a, b, film_t(ca)), view.chord_param(a, b, film_t(cb)));
            let s_at = |t: f64| s0 + (s1 - s0) * t;
            let (p0, p1) = (a + (b - a) * t0, a + (b - a) * t1);
            out.push(Chord { line: i, s: (s_at(t0), s_at(t1)), p: (p0, p1), q: (ca, cb) });
        }
    }
    out
}

/// A uniform grid of chords on the film, for crossing queries.
struct Grid {
    origin: Vec2,
    cell: f64,
    dims: (usize, usize),
    cells: Vec<Vec<u32>>,
}

impl Grid {
    fn new(chords: &[Chord]) -> Grid {
        let (mut lo, mut hi) = (Vec2::splat(f64::INFINITY), Vec2::splat(f64::NEG_INFINITY));
        for c in chords {
            lo = lo.min(c.q.0.min(c.q.1));
            hi = hi.max(c.q.0.max(c.q.1));
        }
        if chords.is_empty() {
            (lo, hi) = (Vec2::ZERO, Vec2::ONE);
        }
        let size = (hi - lo).max(Vec2::splat(1e-9));
        let n = (chords.len() as f64).sqrt().clamp(1.0, 1024.0);
        let cell = (size.x.max(size.y) / n).max(1e-9);
        let dims = ((size.x / cell) as usize + 1, (size.y / cell) as usize + 1);
        let mut g = Grid { origin: lo, cell, dims, cells: vec![vec![]; dims.0 * dims.1] };
        for (k, c) in chords.iter().enumerate() {
            g.for_cells(c.q, |cell| cell.push(k as u32));
        }
        g
    }

    fn range(&self, q: (Vec2, Vec2)) -> ((usize, usize), (usize, usize)) {
        let f = |v: f64, o: f64, n: usize| (((v - o) / self.cell).floor().max(0.0) as usize).min(n - 1);
        let (lo, hi) = (q.0.min(q.1), q.0.max(q.1));
        (
            (f(lo.x, self.origin.x, self.dims.0), f(hi.x, self.origin.x, self.dims.0)),
            (f(lo.y, self.origin.y, self.dims.1), f(hi.y, self.origin.y, self.dims.1)),
        )
    }

    fn for_cells(&mut self, q: (Vec2, Vec2), mut f: impl FnMut(&mut Vec<u32>)) {
        let ((x0, x1), (y0, y1)) = self.range(q);
        for y in y0..=y1 {
            for x in x0..=x1 {
                f(&mut self.cells[y * self.dims.0 + x]);
            }
        }
    }

    fn candidates(&self, q: (Vec2, Vec2), out: &mut Vec<u32>) {
        out.clear();
        let ((x0, x1), (y0, y1)) = self.range(q);
        for y in y0..=y1 {
            for x in x0..=x1 {
                out.extend_from_slice(&self.cells[y * self.dims.0 + x]);
            }
        }
        out.sort_unstable();
        out.dedup();
    }
}

/// Twice the signed area of `(a, b, c)`, with a flag for "too close to call" in f64.
fn orient(a: Vec2, b: Vec2, c: Vec2) -> (f64, bool) {
    let (l, r) = ((b.x - a.x) * (c.y - a.y), (b.y - a.y) * (c.x - a.x));
    let det = l - r;
    // Shewchuk's error bound for orient2d's first stage.
    let bound = 3.3306690738754716e-16 * (l.abs() + r.abs());
    (det, det.abs() <= bound)
}

/// Parameters along chord `a` (on paper) where chord `b` crosses or touches it.
fn crossings(a: (Vec2, Vec2), b: (Vec2, Vec2), out: &mut Vec<f64>) {
    let (d1, z1) = orient(a.0, a.1, b.0);
    let (d2, z2) = orient(a.0, a.1, b.1);
    let (d3, z3) = orient(b.0, b.1, a.0);
    let (d4, z4) = orient(b.0, b.1, a.1);
    let along = |p: Vec2| {
        let d = a.1 - a.0;
        let l2 = d.length_squared();
        if l2 > 0.0 { (p - a.0).dot(d) / l2 } else { 0.0 }
    };
    if !(z1 || z2 || z3 || z4) {
        if (d1 > 0.0) != (d2 > 0.0) && (d3 > 0.0) != (d4 > 0.0) {
            out.push(d3 / (d3 - d4));
        }
        return;
    }
    // Touching or collinear: the other chord's ends lying on this one may start or end cover.
    for (p, z) in [(b.0, z1), (b.1, z2)] {
        if z {
            out.push(along(p));
        }
    }
}

/// Splits every chord where visibility may change and decides each piece by a ray test.
/// Each chord decided is a step of `progress`.
pub fn pieces(
    lines: &[SceneLine],
    chords: &[Chord],
    view: &View,
    world: &World,
    progress: &dyn Progress,
) -> Vec<Piece> {
    let grid = Grid::new(chords);
    let per_chord: Vec<Vec<Piece>> = chords
        .par_iter()
        .enumerate()
        .map_init(Vec::new, |cand, (k, c)| {
            grid.candidates(c.q, cand);
            let mut ts = vec![0.0, 1.0];
            for &j in cand.iter() {
                if j as usize != k {
                    crossings(c.q, chords[j as usize].q, &mut ts);
                }
            }
            // Film parameters → chord parameters in space.
            for t in ts.iter_mut() {
                *t = view.chord_param(c.p.0, c.p.1, t.clamp(0.0, 1.0));
            }
            piercings(c, lines[c.line].object, world, &mut ts);
            ts.sort_by(f64::total_cmp);
            ts.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
            let curve = lines[c.line].curve;
            let (own, near) = lines[c.line].leeway();
            let leeway = Leeway { objects: &own, near };
            ts.windows(2)
                .filter(|w| w[1] > w[0])
                .map(|w| {
                    let s = |t: f64| c.s.0 + (c.s.1 - c.s.0) * t;
                    let mid = curve.point(s(0.5 * (w[0] + w[1])));
                    Piece { line: c.line, s: (s(w[0]), s(w[1])), visible: view.sees_with(world, mid, &leeway) }
                })
                .collect::<Vec<_>>()
        })
        .inspect(|_| progress.advance(1))
        .collect();
    merge(per_chord.into_iter().flatten())
}

/// The baseline the exact method is measured against (fogleman/ln's approach): visibility
/// tested by a ray at sample points every `step_px` pixels along each chord, pieces cut halfway
/// between samples that disagree. Its answer depends on the step.
pub fn pieces_sampled(
    lines: &[SceneLine],
    chords: &[Chord],
    view: &View,
    world: &World,
    step_px: f64,
    progress: &dyn Progress,
) -> Vec<Piece> {
    let per_chord: Vec<Vec<Piece>> = chords
        .par_iter()
        .inspect(|_| progress.advance(1))
        .map(|c| {
            let n = ((c.q.1 - c.q.0).length() / step_px).ceil().max(1.0) as usize;
            let curve = lines[c.line].curve;
            let (own, near) = lines[c.line].leeway();
            let leeway = Leeway { objects: &own, near };
            let s = |t: f64| c.s.0 + (c.s.1 - c.s.0) * t;
            let vis: Vec<bool> =
                (0..n).map(|k| view.sees_with(world, curve.point(s((k as f64 + 0.5) / n as f64)), &leeway)).collect();
            vis.iter()
                .enumerate()
                .map(|(k, &v)| Piece {
                    line: c.line,
                    s: (s(k as f64 / n as f64), s((k + 1) as f64 / n as f64)),
                    visible: v,
                })
                .collect()
        })
        .collect();
    merge(per_chord.into_iter().flatten())
}

/// Where the chord, as a ray, passes through the surface of another object.
fn piercings(c: &Chord, own: u32, world: &World, ts: &mut Vec<f64>) {
    let d = c.p.1 - c.p.0;
    let len = d.length();
    if len <= 0.0 {
        return;
    }
    let dir = d / len;
    let mut t0 = 0.0;
    for _ in 0..64 {
        let ray = Ray::new(c.p.0 + dir * t0, dir);
        let Some(h) = world.intersect(&ray, len - t0) else { break };
        let t = t0 + h.hit.t;
        if h.object != own && t > 1e-9 * len && t < len * (1.0 - 1e-9) {
            ts.push(t / len);
        }
        // Past the hit by the tracers' own guard (flats are tested in single precision).
        t0 = t + ray_epsilon(h.hit.p);
        if t0 >= len {
            break;
        }
    }
}

/// Joins consecutive pieces of a line with the same visibility.
fn merge(pieces: impl Iterator<Item = Piece>) -> Vec<Piece> {
    let mut out: Vec<Piece> = vec![];
    for p in pieces {
        if let Some(last) = out.last_mut()
            && last.line == p.line
            && last.visible == p.visible
            && (last.s.1 - p.s.0).abs() < 1e-12
        {
            last.s.1 = p.s.1;
            continue;
        }
        out.push(p);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crossing_of_an_x_is_found_in_the_middle() {
        let mut ts = vec![];
        let a = (Vec2::new(0.0, 0.0), Vec2::new(2.0, 2.0));
        let b = (Vec2::new(0.0, 2.0), Vec2::new(2.0, 0.0));
        crossings(a, b, &mut ts);
        assert_eq!(ts.len(), 1);
        assert!((ts[0] - 0.5).abs() < 1e-15);
    }

    #[test]
    fn disjoint_segments_do_not_cross() {
        let mut ts = vec![];
        crossings((Vec2::ZERO, Vec2::X), (Vec2::new(0.0, 1.0), Vec2::new(1.0, 2.0)), &mut ts);
        assert!(ts.is_empty());
    }
}
