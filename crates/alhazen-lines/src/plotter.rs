//! Line art for pen plotters: the polylines of each layer joined where they meet and ordered
//! so the pen travels little while it is up (a greedy nearest-end tour over a grid of the
//! ends, improved by 2-opt moves that reverse runs of polylines and or-opt moves that carry
//! one polyline elsewhere, either way round), and HP-GL output, one pen
//! per layer. The course draws with `moveto`/`lineto`; a plotter pays for every `moveto`.

use crate::drawing::{Drawing, Layer};
use alhazen_math::Vec2;
use std::fmt::Write;

/// HP-GL plotter units per millimetre (0.025 mm a unit).
pub const HPGL_UNITS_PER_MM: f64 = 40.0;

/// What a plotter does to draw a drawing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Travel {
    /// Distance the pen moves while up, millimetres: per layer (one pen each) from the origin
    /// through the polylines in their order.
    pub pen_up_mm: f64,
    /// Polylines, each a pen-down stroke.
    pub polylines: usize,
}

/// A drawing ordered for a plotter and what it saved.
#[derive(Clone, Debug, PartialEq)]
pub struct Optimized {
    /// The drawing, layer by layer in pen order.
    pub drawing: Drawing,
    /// The plotter's travel over the drawing as given.
    pub before: Travel,
    /// And as optimised.
    pub after: Travel,
}

/// The pen-up travel and stroke count of `d` as it stands.
pub fn travel(d: &Drawing) -> Travel {
    let mut pen_up = 0.0;
    for layer in Layer::ALL {
        let mut at = Vec2::ZERO;
        for (_, pts) in d.lines.iter().filter(|(l, p)| *l == layer && !p.is_empty()) {
            pen_up += (pts[0] - at).length();
            at = pts[pts.len() - 1];
        }
    }
    Travel { pen_up_mm: pen_up, polylines: d.lines.iter().filter(|(_, p)| !p.is_empty()).count() }
}

/// `d` joined and ordered for a plotter: polylines that meet end to end are chained, each
/// layer's polylines are toured nearest end first and improved by 2-opt, and consecutive
/// polylines whose ends lie within `join_mm` are drawn as one stroke.
pub fn optimize(d: Drawing, join_mm: f64) -> Optimized {
    let before = travel(&d);
    let joined = d.joined();
    let mut lines = vec![];
    for layer in Layer::BY_PEN {
        let strokes: Vec<Vec<Vec2>> =
            joined.lines.iter().filter(|(l, _)| *l == layer).map(|(_, p)| p.clone()).collect();
        let mut order = nearest_end_tour(&strokes);
        improve(&strokes, &mut order);
        lines.extend(chain(&strokes, &order, join_mm).into_iter().map(|p| (layer, p)));
    }
    let drawing = Drawing { size: joined.size, lines, fills: vec![] };
    let after = travel(&drawing);
    Optimized { drawing, before, after }
}

/// A polyline in a tour: its index and whether it is drawn from its last point.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Step {
    line: usize,
    reversed: bool,
}

fn start(strokes: &[Vec<Vec2>], s: Step) -> Vec2 {
    let p = &strokes[s.line];
    if s.reversed { p[p.len() - 1] } else { p[0] }
}

fn end(strokes: &[Vec<Vec2>], s: Step) -> Vec2 {
    let p = &strokes[s.line];
    if s.reversed { p[0] } else { p[p.len() - 1] }
}

/// From the origin, always to the nearest free end (ties by index), over a uniform grid of ends.
fn nearest_end_tour(strokes: &[Vec<Vec2>]) -> Vec<Step> {
    let mut free = vec![true; strokes.len()];
    let mut grid = EndGrid::new(strokes, &free);
    let mut at = Vec2::ZERO;
    let mut order = Vec::with_capacity(strokes.len());
    while let Some(step) = grid.take_nearest(at) {
        order.push(step);
        free[step.line] = false;
        at = end(strokes, step);
        // Sparse grids are slow to search: coarsen as they empty.
        let left = strokes.len() - order.len();
        if left >= 32 && left * 4 < grid.built {
            grid = EndGrid::new(strokes, &free);
        }
    }
    order
}

/// The ends of every polyline in square cells, removed as polylines are drawn.
struct EndGrid {
    origin: Vec2,
    cell: f64,
    nx: usize,
    ny: usize,
    /// Per cell: `(point, id)`, the id `line × 2`, plus 1 for the line's last point.
    cells: Vec<Vec<(Vec2, usize)>>,
    /// Every end's point by id.
    ends: Vec<Vec2>,
    /// Polylines in the grid when it was built.
    built: usize,
}

impl EndGrid {
    /// The ends of the polylines marked free.
    fn new(strokes: &[Vec<Vec2>], free: &[bool]) -> EndGrid {
        let ends: Vec<(Vec2, usize)> = strokes
            .iter()
            .enumerate()
            .filter(|(i, _)| free[*i])
            .flat_map(|(i, p)| [(p[0], 2 * i), (p[p.len() - 1], 2 * i + 1)])
            .collect();
        let (mut lo, mut hi) = (Vec2::splat(f64::INFINITY), Vec2::splat(f64::NEG_INFINITY));
        for (p, _) in &ends {
            (lo, hi) = (lo.min(*p), hi.max(*p));
        }
        if ends.is_empty() {
            (lo, hi) = (Vec2::ZERO, Vec2::ONE);
        }
        let span = (hi - lo).max(Vec2::splat(1e-9));
        // About two ends a cell, at most 4096 cells a side.
        let cell = ((span.x * span.y / (ends.len().max(1) as f64 / 2.0)).sqrt()).max(span.max_element() / 4096.0);
        let nx = ((span.x / cell) as usize + 1).min(4097);
        let ny = ((span.y / cell) as usize + 1).min(4097);
        let mut points = vec![Vec2::ZERO; 2 * strokes.len()];
        for &(p, id) in &ends {
            points[id] = p;
        }
        let built = ends.len() / 2;
        let mut grid = EndGrid { origin: lo, cell, nx, ny, cells: vec![vec![]; nx * ny], ends: points, built };
        for e in ends {
            let (cx, cy) = grid.cell_of(e.0);
            grid.cells[cy * nx + cx].push(e);
        }
        grid
    }

    fn cell_of(&self, p: Vec2) -> (usize, usize) {
        let c = (p - self.origin) / self.cell;
        let clamp = |v: f64, n: usize| (v.max(0.0) as usize).min(n - 1);
        (clamp(c.x, self.nx), clamp(c.y, self.ny))
    }

    /// The free end nearest `p`, its polyline taken out of the grid.
    fn take_nearest(&mut self, p: Vec2) -> Option<Step> {
        let (cx, cy) = self.cell_of(p);
        let mut best: Option<(f64, usize)> = None;
        for r in 0..self.nx.max(self.ny) {
            for (x, y) in ring(cx, cy, r, self.nx, self.ny) {
                for &(q, id) in &self.cells[y * self.nx + x] {
                    let d = (q - p).length();
                    if best.is_none_or(|(bd, bid)| (d, id) < (bd, bid)) {
                        best = Some((d, id));
                    }
                }
            }
            // Ends beyond ring r are at least r cells away.
            if best.is_some_and(|(d, _)| d <= r as f64 * self.cell) {
                break;
            }
        }
        let (_, id) = best?;
        let line = id / 2;
        self.remove(2 * line);
        self.remove(2 * line + 1);
        Some(Step { line, reversed: id % 2 == 1 })
    }

    fn remove(&mut self, id: usize) {
        let (cx, cy) = self.cell_of(self.ends[id]);
        let cell = &mut self.cells[cy * self.nx + cx];
        if let Some(i) = cell.iter().position(|e| e.1 == id) {
            cell.swap_remove(i);
        }
    }
}

/// The cells at Chebyshev distance `r` from `(cx, cy)` inside the grid, in rows: only the
/// ring's clipped border is visited.
fn ring(cx: usize, cy: usize, r: usize, nx: usize, ny: usize) -> impl Iterator<Item = (usize, usize)> {
    let (cx, cy, r) = (cx as i64, cy as i64, r as i64);
    let (x0, x1) = ((cx - r).max(0), (cx + r).min(nx as i64 - 1));
    let (y0, y1) = ((cy - r).max(0), (cy + r).min(ny as i64 - 1));
    (y0..=y1).flat_map(move |y| {
        let whole_row = y == cy - r || y == cy + r;
        let sides = [cx - r, cx + r].into_iter().filter(move |&x| !whole_row && x >= x0 && x <= x1);
        let row = (x0..=x1).filter(move |_| whole_row);
        row.chain(sides).map(move |x| (x as usize, y as usize))
    })
}

/// Moves tried around each polyline of a tour of `n`: up to 2000, fewer on long tours so a
/// round stays near 10⁸ distance evaluations.
fn window(n: usize) -> usize {
    (40_000_000 / n.max(1)).clamp(32, 2000)
}

/// Improves the tour until no move shortens it (at most 64 rounds): 2-opt, then or-opt.
fn improve(strokes: &[Vec<Vec2>], order: &mut Vec<Step>) {
    for _ in 0..64 {
        let reversed = two_opt(strokes, order);
        let moved = or_opt(strokes, order);
        if !reversed && !moved {
            break;
        }
    }
}

/// One round of 2-opt: reversing the run `i..=j` (each polyline then drawn backwards) when
/// it shortens the pen-up moves into and out of the run. Whether anything changed.
fn two_opt(strokes: &[Vec<Vec2>], order: &mut [Step]) -> bool {
    let n = order.len();
    let w = window(n);
    let mut improved = false;
    for i in 0..n {
        let before_run = if i == 0 { Vec2::ZERO } else { end(strokes, order[i - 1]) };
        for j in i..n.min(i + w) {
            let after_run = order.get(j + 1).map(|&s| start(strokes, s));
            let (si, ej) = (start(strokes, order[i]), end(strokes, order[j]));
            let out_now = after_run.map_or(0.0, |a| (a - ej).length());
            let out_then = after_run.map_or(0.0, |a| (a - si).length());
            let gain = (si - before_run).length() + out_now - (ej - before_run).length() - out_then;
            if gain > 1e-9 {
                order[i..=j].reverse();
                for s in &mut order[i..=j] {
                    s.reversed = !s.reversed;
                }
                improved = true;
            }
        }
    }
    improved
}

/// One round of or-opt: each polyline moved, either way round, to the gap within the window
/// where it lengthens the tour least, when that beats where it is. Whether anything changed.
fn or_opt(strokes: &[Vec<Vec2>], order: &mut Vec<Step>) -> bool {
    let dist = |a: Vec2, b: Option<Vec2>| b.map_or(0.0, |b| (a - b).length());
    let w = window(order.len());
    let mut improved = false;
    for i in 0..order.len() {
        let step = order[i];
        let prev = if i == 0 { Vec2::ZERO } else { end(strokes, order[i - 1]) };
        let next = order.get(i + 1).map(|&s| start(strokes, s));
        let (s, e) = (start(strokes, step), end(strokes, step));
        let saved = (s - prev).length() + dist(e, next) - dist(prev, next);
        // Gap g of the tour without polyline i: between its polylines g − 1 and g.
        let without = |g: usize| if g < i { order[g] } else { order[g + 1] };
        let mut best: Option<(f64, usize, bool)> = None;
        for g in i.saturating_sub(w)..=(i + w).min(order.len() - 1) {
            let a = if g == 0 { Vec2::ZERO } else { end(strokes, without(g - 1)) };
            let b = (g + 1 < order.len()).then(|| start(strokes, without(g)));
            for (reversed, (s, e)) in [(false, (s, e)), (true, (e, s))] {
                let cost = (s - a).length() + dist(e, b) - dist(a, b);
                if saved - cost > best.map_or(1e-9, |b| b.0) {
                    best = Some((saved - cost, g, reversed));
                }
            }
        }
        if let Some((_, g, reversed)) = best {
            order.remove(i);
            order.insert(g, Step { line: step.line, reversed: step.reversed != reversed });
            improved = true;
        }
    }
    improved
}

/// The tour as polylines, consecutive ones within `join_mm` drawn as one stroke.
fn chain(strokes: &[Vec<Vec2>], order: &[Step], join_mm: f64) -> Vec<Vec<Vec2>> {
    let mut out: Vec<Vec<Vec2>> = vec![];
    for &s in order {
        let mut pts = strokes[s.line].clone();
        if s.reversed {
            pts.reverse();
        }
        match out.last_mut() {
            Some(last) if (pts[0] - last[last.len() - 1]).length() <= join_mm => {
                let skip = usize::from(pts[0] == last[last.len() - 1]);
                last.extend_from_slice(&pts[skip..]);
            }
            _ => out.push(pts),
        }
    }
    out
}

/// HP-GL for a plotter: one pen per layer (`SP1` visible, `SP2` reflected, `SP3` hidden), in
/// plotter units of 0.025 mm with the origin at the paper's lower left; hidden lines are drawn
/// solid (put a fine pen in slot 3).
pub fn to_hpgl(d: &Drawing) -> String {
    let mut s = String::from("IN;\n");
    let units = |p: Vec2| {
        let x = (p.x * HPGL_UNITS_PER_MM).round() as i64;
        let y = ((d.size.y - p.y) * HPGL_UNITS_PER_MM).round() as i64;
        (x, y)
    };
    for layer in Layer::BY_PEN {
        let mut strokes = d.lines.iter().filter(|(l, p)| *l == layer && !p.is_empty()).peekable();
        if strokes.peek().is_none() {
            continue;
        }
        let _ = writeln!(s, "SP{};", layer.pen());
        for (_, pts) in strokes {
            let mut xy: Vec<(i64, i64)> = pts.iter().map(|p| units(*p)).collect();
            xy.dedup();
            let (x0, y0) = xy[0];
            let _ = write!(s, "PU{x0},{y0};PD");
            let rest = if xy.len() > 1 { &xy[1..] } else { &xy[..] };
            for (k, (x, y)) in rest.iter().enumerate() {
                let _ = write!(s, "{}{x},{y}", if k > 0 { "," } else { "" });
            }
            s.push_str(";\n");
        }
    }
    s.push_str("PU;SP0;\n");
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Undirected segments of a layer, to 1 nm.
    fn segments(d: &Drawing, layer: Layer) -> Vec<[(i64, i64); 2]> {
        let key = |p: Vec2| ((p.x * 1e6).round() as i64, (p.y * 1e6).round() as i64);
        let mut out: Vec<[(i64, i64); 2]> = d
            .lines
            .iter()
            .filter(|(l, _)| *l == layer)
            .flat_map(|(_, p)| p.windows(2).map(|w| [key(w[0]), key(w[1])]))
            .filter(|[a, b]| a != b)
            .map(|mut s| {
                s.sort();
                s
            })
            .collect();
        out.sort();
        out
    }

    fn drawing(strokes: Vec<(u8, Vec<(f64, f64)>)>) -> Drawing {
        let layer = |k: u8| Layer::ALL[k as usize % 3];
        let lines = strokes
            .into_iter()
            .map(|(k, pts)| (layer(k), pts.into_iter().map(|(x, y)| Vec2::new(x, y)).collect()))
            .collect();
        Drawing { size: Vec2::new(100.0, 80.0), lines, fills: vec![] }
    }

    fn strokes() -> impl Strategy<Value = Vec<(u8, Vec<(f64, f64)>)>> {
        // Coordinates on a coarse lattice so that ends often meet.
        let point = (0..40u32, 0..32u32).prop_map(|(x, y)| (x as f64 * 2.5, y as f64 * 2.5));
        prop::collection::vec((0..3u8, prop::collection::vec(point, 2..5)), 0..60)
    }

    proptest! {
        #[test]
        fn a_ring_is_the_cells_at_that_chebyshev_distance(nx in 1..9usize, ny in 1..9usize, c in (0..9usize, 0..9usize), r in 0..12usize) {
            let (cx, cy) = (c.0.min(nx - 1), c.1.min(ny - 1));
            let mut got: Vec<(usize, usize)> = ring(cx, cy, r, nx, ny).collect();
            got.sort();
            let mut want = vec![];
            for x in 0..nx {
                for y in 0..ny {
                    if x.abs_diff(cx).max(y.abs_diff(cy)) == r {
                        want.push((x, y));
                    }
                }
            }
            want.sort();
            prop_assert_eq!(got, want);
        }

        #[test]
        fn optimizing_keeps_every_segment_on_its_layer(s in strokes()) {
            let d = drawing(s);
            let o = optimize(d.clone(), 0.0);
            for layer in Layer::ALL {
                prop_assert_eq!(segments(&d, layer), segments(&o.drawing, layer));
            }
            prop_assert_eq!(o.before, travel(&d));
            prop_assert_eq!(o.after, travel(&o.drawing));
        }

        #[test]
        fn improving_never_lengthens_the_tour_nor_loses_a_stroke(s in strokes()) {
            let d = drawing(s);
            let strokes: Vec<Vec<Vec2>> = d.lines.iter().map(|(_, p)| p.clone()).collect();
            let tour_length = |order: &[Step]| {
                let mut at = Vec2::ZERO;
                order.iter().map(|&s| {
                    let d = (start(&strokes, s) - at).length();
                    at = end(&strokes, s);
                    d
                }).sum::<f64>()
            };
            let mut order = nearest_end_tour(&strokes);
            let mut seen: Vec<usize> = order.iter().map(|s| s.line).collect();
            seen.sort();
            prop_assert_eq!(seen, (0..strokes.len()).collect::<Vec<_>>());
            let greedy = tour_length(&order);
            improve(&strokes, &mut order);
            prop_assert!(tour_length(&order) <= greedy + 1e-9);
            let mut seen: Vec<usize> = order.iter().map(|s| s.line).collect();
            seen.sort();
            prop_assert_eq!(seen, (0..strokes.len()).collect::<Vec<_>>());
        }

        #[test]
        fn hpgl_holds_every_point_to_a_plotter_unit(s in strokes()) {
            let d = drawing(s);
            let back = read_hpgl(&to_hpgl(&d), d.size.y);
            for layer in Layer::ALL {
                let want: Vec<&Vec<Vec2>> = d.lines.iter().filter(|(l, _)| *l == layer).map(|(_, p)| p).collect();
                let got: Vec<&Vec<Vec2>> = back.iter().filter(|(l, _)| *l == layer).map(|(_, p)| p).collect();
                prop_assert_eq!(want.len(), got.len());
                for (w, g) in want.iter().zip(&got) {
                    let mut w: Vec<Vec2> = w.to_vec();
                    w.dedup();
                    prop_assert_eq!(w.len(), g.len());
                    for (a, b) in w.iter().zip(g.iter()) {
                        prop_assert!((*a - *b).length() <= 0.5 / HPGL_UNITS_PER_MM * 2f64.sqrt() + 1e-12);
                    }
                }
            }
        }
    }

    /// Reads back what `to_hpgl` writes: `SPn;`, `PUx,y;PDx,y,…;`.
    fn read_hpgl(s: &str, height: f64) -> Vec<(Layer, Vec<Vec2>)> {
        let mut out = vec![];
        let mut layer = Layer::Visible;
        for cmd in s.split(';').map(str::trim).filter(|c| !c.is_empty()) {
            let (op, args) = cmd.split_at(2);
            let nums: Vec<f64> = args.split(',').filter(|a| !a.is_empty()).map(|a| a.parse().unwrap()).collect();
            let pts = nums.chunks(2).map(|c| Vec2::new(c[0], height * HPGL_UNITS_PER_MM - c[1]) / HPGL_UNITS_PER_MM);
            match op {
                "SP" if nums == [0.0] => {}
                "SP" => layer = *Layer::ALL.iter().find(|l| l.pen() as f64 == nums[0]).unwrap(),
                "PU" => out.extend(pts.map(|p| (layer, vec![p]))),
                "PD" => {
                    let line: &mut Vec<Vec2> = &mut out.last_mut().unwrap().1;
                    let pts: Vec<Vec2> = pts.collect();
                    // A single point drawn is a dot: the point again.
                    if !(pts.len() == 1 && line.len() == 1 && pts[0] == line[0]) {
                        line.extend(pts);
                    }
                }
                _ => {}
            }
        }
        out
    }

    #[test]
    fn a_shuffled_hatching_is_toured_with_far_less_travel() {
        // 400 short strokes in a 20 × 20 lattice, listed in a scrambled order.
        let mut lines = vec![];
        for k in 0..400u64 {
            let m = (k * 263) % 400;
            let (x, y) = ((m % 20) as f64 * 4.0 + 5.0, (m / 20) as f64 * 3.0 + 5.0);
            lines.push((Layer::Visible, vec![Vec2::new(x, y), Vec2::new(x + 2.0, y)]));
        }
        let d = Drawing { size: Vec2::new(100.0, 80.0), lines, fills: vec![] };
        let o = optimize(d, 0.0);
        assert!(o.after.pen_up_mm < 0.15 * o.before.pen_up_mm, "{:?} → {:?}", o.before, o.after);
        // A tour of the lattice rows needs at least 400 moves of 2 mm.
        assert!(o.after.pen_up_mm >= 800.0 - 1e-9);
        assert_eq!(o.after.polylines, 400);
    }

    #[test]
    fn strokes_that_nearly_meet_become_one_within_the_tolerance() {
        let p = |x, y| Vec2::new(x, y);
        let lines =
            vec![(Layer::Visible, vec![p(1.0, 1.0), p(5.0, 1.0)]), (Layer::Visible, vec![p(5.03, 1.0), p(9.0, 1.0)])];
        let d = Drawing { size: p(10.0, 10.0), lines, fills: vec![] };
        assert_eq!(optimize(d.clone(), 0.05).after.polylines, 1);
        assert_eq!(optimize(d, 0.01).after.polylines, 2);
    }
}
