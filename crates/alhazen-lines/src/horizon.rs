//! The floating-horizon algorithm for graphs `z = f(x, y)` (course, §"Floating horizon
//! algorithm"): the net of lines `x = const`, `y = const` is drawn in a parallel projection
//! fixed by four corner images, from the front to the rear; the lines drawn so far bound a
//! forbidden band per pixel column between the upper horizon `ht` and the lower horizon `hb`.
//! Segments are drawn in groups that share end points (all segments at the same distance from
//! the front corner) and the horizons updated after each group, the course's "fully correct"
//! variant.

use alhazen_math::Vec2;

/// A graph to draw: the function, its domain and the net.
pub struct Graph<'a> {
    /// The function.
    pub f: &'a (dyn Fn(f64, f64) -> f64 + Sync),
    /// `[x_min, x_max]`.
    pub x: (f64, f64),
    /// `[y_min, y_max]`.
    pub y: (f64, f64),
    /// Net lines in `x` and in `y`.
    pub lines: (usize, usize),
}

/// The course's layout: picture `w × h` pixels; `(x_min, y_min, z_min) ↦ (w_x, h_z)`,
/// `(x_min, y_min, z_max) ↦ (w_x, 0)`, `(x_max, y_min, z_min) ↦ (0, h_x + h_z)`,
/// `(x_max, y_max, z_min) ↦ (w − w_x, h)`.
#[derive(Clone, Copy, Debug)]
pub struct Layout {
    /// Picture width in pixels.
    pub w: f64,
    /// Picture height in pixels.
    pub h: f64,
    /// `w_x`.
    pub wx: f64,
    /// `h_x`.
    pub hx: f64,
    /// `h_z`.
    pub hz: f64,
}

/// The visible parts of the net as polylines in pixels (`η` down).
pub fn floating_horizon(g: &Graph, l: &Layout) -> Vec<Vec<Vec2>> {
    let (nx, ny) = (g.lines.0.max(2), g.lines.1.max(2));
    let at = |i: usize, j: usize| {
        // i counts from x_max, j from y_max: (0, 0) is the front corner.
        let x = g.x.1 + (g.x.0 - g.x.1) * i as f64 / (nx - 1) as f64;
        let y = g.y.1 + (g.y.0 - g.y.1) * j as f64 / (ny - 1) as f64;
        (x, y, (g.f)(x, y))
    };
    let nodes: Vec<(f64, f64, f64)> =
        (0..nx).flat_map(|i| (0..ny).map(move |j| (i, j))).map(|(i, j)| at(i, j)).collect();
    let (z0, z1) = nodes.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), n| (a.min(n.2), b.max(n.2)));
    let dz = if z1 > z0 { z1 - z0 } else { 1.0 };
    let (dx, dy) = (g.x.1 - g.x.0, g.y.1 - g.y.0);
    let project = |(x, y, z): (f64, f64, f64)| {
        let xi = l.wx - l.wx * (x - g.x.0) / dx + (l.w - l.wx) * (y - g.y.0) / dy;
        let eta = l.hz - l.hz * (z - z0) / dz + l.hx * (x - g.x.0) / dx + (l.h - l.hx - l.hz) * (y - g.y.0) / dy;
        Vec2::new(xi, eta)
    };
    let node = |i: usize, j: usize| project(nodes[i * ny + j]);
    let cols = l.w.ceil() as usize + 1;
    let (mut ht, mut hb) = (vec![f64::INFINITY; cols], vec![f64::NEG_INFINITY; cols]);
    let mut out = vec![];
    for level in 0..(nx + ny - 2) {
        let mut group = vec![];
        for i in 0..nx {
            if level < i || level - i >= ny {
                continue;
            }
            let j = level - i;
            if i + 1 < nx {
                group.push((node(i, j), node(i + 1, j)));
            }
            if j + 1 < ny {
                group.push((node(i, j), node(i, j + 1)));
            }
        }
        let columns: Vec<Vec<(usize, f64)>> = group.iter().map(|s| columns_of(*s, cols)).collect();
        for c in &columns {
            let mut run: Vec<Vec2> = vec![];
            for &(x, y) in c {
                if y < ht[x] || y > hb[x] {
                    run.push(Vec2::new(x as f64, y));
                } else if run.len() > 1 {
                    out.push(std::mem::take(&mut run));
                } else {
                    run.clear();
                }
            }
            if run.len() > 1 {
                out.push(run);
            }
        }
        for &(x, y) in columns.iter().flatten() {
            ht[x] = ht[x].min(y);
            hb[x] = hb[x].max(y);
        }
    }
    out
}

/// The segment sampled at every pixel column it spans: `(column, η)`.
fn columns_of((a, b): (Vec2, Vec2), cols: usize) -> Vec<(usize, f64)> {
    let (a, b) = if a.x <= b.x { (a, b) } else { (b, a) };
    let (x0, x1) = (a.x.ceil().max(0.0) as usize, (b.x.floor().max(0.0) as usize).min(cols - 1));
    (x0..=x1)
        .filter(|&x| x as f64 >= a.x && x as f64 <= b.x)
        .map(|x| {
            let t = if b.x > a.x { (x as f64 - a.x) / (b.x - a.x) } else { 0.0 };
            (x, a.y + (b.y - a.y) * t)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    const LAYOUT: Layout = Layout { w: 400.0, h: 300.0, wx: 150.0, hx: 60.0, hz: 120.0 };

    #[test]
    fn a_flat_graph_is_all_visible() {
        let g = Graph { f: &|_, _| 0.0, x: (-1.0, 1.0), y: (-1.0, 1.0), lines: (5, 5) };
        let lines = floating_horizon(&g, &LAYOUT);
        // A plane seen from above: every net line shows (the plane is never folded over).
        let drawn: f64 = lines.iter().map(|l| l.len() as f64).sum();
        assert!(drawn > 0.0);
    }

    #[test]
    fn a_wall_hides_what_is_behind_it() {
        // A wall across the middle hides the low lines just behind it in the same columns.
        let g = Graph {
            f: &|x, _| if x.abs() < 0.05 { 1.0 } else { 0.0 },
            x: (-1.0, 1.0),
            y: (-1.0, 1.0),
            lines: (21, 21),
        };
        let lines = floating_horizon(&g, &LAYOUT);
        // (Heights are scaled to the layout's h_z, so the flat reference must be exactly flat.)
        let flat = Graph { f: &|_, _| 0.0, ..g };
        let all = floating_horizon(&flat, &LAYOUT);
        let count = |l: &Vec<Vec<Vec2>>| l.iter().map(|p| p.len()).sum::<usize>();
        assert!(count(&lines) < count(&all), "{} vs {}", count(&lines), count(&all));
    }
}
