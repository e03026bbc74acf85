//! Warnock's area subdivision: a region of the screen is decided at once when nothing falls in
//! it (background), when one triangle alone meets it (that triangle is drawn there), or when
//! one triangle covers the whole region and lies in front of every other one meeting it over
//! the whole region (it is drawn there); otherwise the region is split in four, down to single
//! pixels, where the nearest fragment wins.
//!
//! The tests are made on pixel centres, the rasteriser's samples: a triangle covers a
//! rectangle of pixels when it holds the centres of its four corner pixels (it is convex), and
//! it is in front over the rectangle when its depth plane is nearer than each other's at those
//! four centres (depth `z/w` is affine on the screen, so the corners bound it). The frame is the
//! z-buffer's exactly.

use super::raster::{Fragment, ScreenTriangle, rasterize};

/// A triangle's depth plane `z = a x + b y + c` on the screen, `None` seen edge-on.
fn depth_plane(t: &ScreenTriangle) -> Option<[f64; 3]> {
    let (dx1, dy1, dz1) = (t.x[1] - t.x[0], t.y[1] - t.y[0], t.z[1] - t.z[0]);
    let (dx2, dy2, dz2) = (t.x[2] - t.x[0], t.y[2] - t.y[0], t.z[2] - t.z[0]);
    let det = dx1 * dy2 - dx2 * dy1;
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let a = (dz1 * dy2 - dz2 * dy1) / det;
    let b = (dx1 * dz2 - dx2 * dz1) / det;
    Some([a, b, t.z[0] - a * t.x[0] - b * t.y[0]])
}

/// A rectangle of pixels `[x0, x1) × [y0, y1)`.
#[derive(Clone, Copy)]
struct Region {
    x0: u32,
    x1: u32,
    y0: u32,
    y1: u32,
}

impl Region {
    /// The centres of its corner pixels.
    fn corners(&self) -> [(f64, f64); 4] {
        let (l, r) = (self.x0 as f64 + 0.5, self.x1 as f64 - 0.5);
        let (t, b) = (self.y0 as f64 + 0.5, self.y1 as f64 - 0.5);
        [(l, t), (r, t), (l, b), (r, b)]
    }

    /// True when the triangle's bounding box reaches the region.
    fn meets(&self, t: &ScreenTriangle) -> bool {
        let min = |v: [f64; 3]| v.iter().copied().fold(f64::INFINITY, f64::min);
        let max = |v: [f64; 3]| v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        max(t.x) >= self.x0 as f64
            && min(t.x) <= self.x1 as f64
            && max(t.y) >= self.y0 as f64
            && min(t.y) <= self.y1 as f64
    }
}

/// The rasteriser's own fragments of `t` inside `r`.
fn fragments(t: &ScreenTriangle, width: u32, r: Region, mut emit: impl FnMut(Fragment)) {
    rasterize(t, width, r.y0, r.y1, |f| {
        if f.x >= r.x0 && f.x < r.x1 {
            emit(f);
        }
    });
}

/// True when every corner pixel centre of `r` lies strictly inside `t`.
fn covers(t: &ScreenTriangle, r: Region) -> bool {
    let area = (t.x[1] - t.x[0]) * (t.y[2] - t.y[0]) - (t.y[1] - t.y[0]) * (t.x[2] - t.x[0]);
    r.corners().iter().all(|&(x, y)| {
        (0..3).all(|k| {
            let (a, b) = ((k + 1) % 3, (k + 2) % 3);
            let e = (t.x[b] - t.x[a]) * (y - t.y[a]) - (t.y[b] - t.y[a]) * (x - t.x[a]);
            e * area.signum() > 0.0
        })
    })
}

/// Resolves the rows `y0..y1` of a frame `width` wide among the triangles `bin` (indices into
/// `screen`, in drawing order): `visible(k, triangle, fragment)` sets row-major index `k`
/// within the band, once per pixel.
pub fn band(
    screen: &[ScreenTriangle],
    bin: &[u32],
    width: u32,
    (y0, y1): (u32, u32),
    mut visible: impl FnMut(usize, &ScreenTriangle, Fragment),
) {
    let region = Region { x0: 0, x1: width, y0, y1 };
    let list: Vec<u32> = bin.iter().copied().filter(|&i| region.meets(&screen[i as usize])).collect();
    subdivide(screen, &list, width, region, y0, &mut visible);
}

fn subdivide(
    screen: &[ScreenTriangle],
    list: &[u32],
    width: u32,
    r: Region,
    band_y0: u32,
    visible: &mut impl FnMut(usize, &ScreenTriangle, Fragment),
) {
    if r.x0 >= r.x1 || r.y0 >= r.y1 || list.is_empty() {
        return; // background
    }
    let index = |f: &Fragment| ((f.y - band_y0) * width + f.x) as usize;
    if r.x1 - r.x0 == 1 && r.y1 - r.y0 == 1 {
        // One pixel: the nearest fragment, the first of equals.
        let mut best: Option<(f64, u32, Fragment)> = None;
        for &i in list {
            fragments(&screen[i as usize], width, r, |f| {
                if f.depth >= -1.0 && best.as_ref().is_none_or(|b| f.depth < b.0) {
                    best = Some((f.depth, i, f));
                }
            });
        }
        if let Some((_, i, f)) = best {
            visible(index(&f), &screen[i as usize], f);
        }
        return;
    }
    let winner = match list {
        [only] => Some(*only),
        _ => in_front_of_all(screen, list, r),
    };
    if let Some(i) = winner {
        let t = &screen[i as usize];
        fragments(t, width, r, |f| {
            if f.depth >= -1.0 {
                visible(index(&f), t, f);
            }
        });
        return;
    }
    let (mx, my) = ((r.x0 + r.x1) / 2, (r.y0 + r.y1) / 2);
    let quads = [
        Region { x0: r.x0, x1: mx, y0: r.y0, y1: my },
        Region { x0: mx, x1: r.x1, y0: r.y0, y1: my },
        Region { x0: r.x0, x1: mx, y0: my, y1: r.y1 },
        Region { x0: mx, x1: r.x1, y0: my, y1: r.y1 },
    ];
    for q in quads {
        let inside: Vec<u32> = list.iter().copied().filter(|&i| q.meets(&screen[i as usize])).collect();
        subdivide(screen, &inside, width, q, band_y0, visible);
    }
}

/// A triangle of `list` that covers `r` and is nearer than every other one's plane at each
/// corner pixel centre (and not in front of the near plane there), if there is one.
fn in_front_of_all(screen: &[ScreenTriangle], list: &[u32], r: Region) -> Option<u32> {
    let depth = |p: [f64; 3], (x, y): (f64, f64)| p[0] * x + p[1] * y + p[2];
    list.iter().copied().find(|&i| {
        let t = &screen[i as usize];
        let Some(p) = depth_plane(t) else { return false };
        if !covers(t, r) || r.corners().iter().any(|&c| depth(p, c) < -1.0) {
            return false;
        }
        list.iter().filter(|&&j| j != i).all(|&j| match depth_plane(&screen[j as usize]) {
            None => true,
            // Strictly nearer: the z-buffer keeps the first of equal depths.
            Some(q) => r.corners().iter().all(|&c| depth(p, c) < depth(q, c)),
        })
    })
}
