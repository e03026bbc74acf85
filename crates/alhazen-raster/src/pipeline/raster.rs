//! Triangle rasterisation (course, §"Rasterisation algorithms" and the homogeneous formulas of
//! §"Projections"): edge functions over the pixel centres of the triangle's bounding box, a fill
//! rule that gives a pixel on a shared edge to exactly one of the two triangles, depth
//! interpolated linearly in screen space (`z/w` is affine there) and attributes perspective-
//! correctly (`a/w` and `1/w` interpolated, then divided).
//!
//! A screen triangle carries no shading attributes: only the weights of its source triangle's
//! corners at its own corners (barycentric coordinates, which clipping interpolates like any
//! attribute). The fragment that wins a pixel gives the weights there, and the attributes —
//! position, normal, texture coordinates, Gouraud light — are interpolated from the source
//! triangle for that pixel alone (deferred; a frame of a million triangles moves 150 bytes per
//! triangle instead of 440).

use super::clip::BARY;

/// Weights of a source triangle's corners 1 and 2 (corner 0's is the rest).
pub type Bary = [f64; 2];

/// A triangle after projection: screen `x, y` (pixels, `y` down), depth `z/w`, `1/w`, and the
/// weights of its source's corners divided by `w`.
#[derive(Clone, Copy, Debug)]
pub struct ScreenTriangle {
    /// Screen x of the corners.
    pub x: [f64; 3],
    /// Screen y of the corners.
    pub y: [f64; 3],
    /// `z/w`.
    pub z: [f64; 3],
    /// `1/w`.
    pub inv_w: [f64; 3],
    /// The source's corner weights times `1/w`.
    pub bary_w: [Bary; 3],
    /// Index of the source triangle.
    pub source: u32,
}

/// The value of per-corner quantities `a` of a triangle at weights `b` of corners 1 and 2.
#[inline]
pub fn interpolate<T>(a: [T; 3], b: Bary) -> T
where
    T: std::ops::Add<Output = T> + std::ops::Sub<Output = T> + std::ops::Mul<f64, Output = T> + Copy,
{
    a[0] + (a[1] - a[0]) * b[0] + (a[2] - a[0]) * b[1]
}

/// The perspective division and viewport transform of a clipped convex polygon (clip space,
/// `w > 0`), fanned into screen triangles of a `w × h` image tagged with `source`.
pub fn to_screen(clipped: &[super::clip::ClipVertex], (w, h): (u32, u32), source: u32) -> Vec<ScreenTriangle> {
    let pts: Vec<_> = clipped.iter().map(|cv| divide(cv, (w, h))).collect();
    (1..pts.len().saturating_sub(1))
        .map(|k| {
            let c = [&pts[0], &pts[k], &pts[k + 1]];
            ScreenTriangle {
                x: c.map(|p| p.0),
                y: c.map(|p| p.1),
                z: c.map(|p| p.2),
                inv_w: c.map(|p| p.3),
                bary_w: c.map(|p| p.4),
                source,
            }
        })
        .collect()
}

/// A corner after the perspective division and the viewport: `x, y, z/w, 1/w, weights/w`.
type ScreenCorner = (f64, f64, f64, f64, Bary);

#[inline]
fn divide(cv: &super::clip::ClipVertex, (w, h): (u32, u32)) -> ScreenCorner {
    let inv_w = 1.0 / cv.pos.w;
    let (x, y, z) = (cv.pos.x * inv_w, cv.pos.y * inv_w, cv.pos.z * inv_w);
    let b = [cv.attr[BARY] * inv_w, cv.attr[BARY + 1] * inv_w];
    ((x + 1.0) * 0.5 * w as f64, (1.0 - y) * 0.5 * h as f64, z, inv_w, b)
}

/// [`to_screen`] of a triangle that needs no clipping (inside the view volume): the same
/// numbers, without allocating.
pub fn triangle_to_screen(c: &[super::clip::ClipVertex; 3], size: (u32, u32), source: u32) -> ScreenTriangle {
    let p = c.each_ref().map(|cv| divide(cv, size));
    ScreenTriangle {
        x: p.each_ref().map(|q| q.0),
        y: p.each_ref().map(|q| q.1),
        z: p.each_ref().map(|q| q.2),
        inv_w: p.each_ref().map(|q| q.3),
        bary_w: p.each_ref().map(|q| q.4),
        source,
    }
}

/// `⌈v⌉` clamped to the integers `[lo, hi]` (`lo` for NaN), without a call to libm.
#[inline]
fn ceil_within(v: f64, lo: u32, hi: u32) -> u32 {
    let c = v.clamp(lo as f64, hi as f64);
    let t = c as u32;
    if (t as f64) < c { t + 1 } else { t }
}

/// `⌊v⌋` clamped to the integers `[lo, hi]` (`lo` for NaN).
#[inline]
fn floor_within(v: f64, lo: u32, hi: u32) -> u32 {
    v.clamp(lo as f64, hi as f64) as u32
}

/// The columns `[x0, x1)` and rows `[y0, y1)` of the pixel centres inside the bounding box of
/// corners `x, y`, within columns `[0, width)` and rows `rows` (empty ranges when none).
#[inline]
fn centre_box(x: &[f64; 3], y: &[f64; 3], width: u32, rows: (u32, u32)) -> (u32, u32, u32, u32) {
    let lo = |v: &[f64; 3]| v[0].min(v[1]).min(v[2]);
    let hi = |v: &[f64; 3]| v[0].max(v[1]).max(v[2]);
    // Centre c + ½ lies in [lo, hi] for c in [⌈lo − ½⌉, ⌊hi + ½⌋).
    let (x0, x1) = (ceil_within(lo(x) - 0.5, 0, width), floor_within(hi(x) + 0.5, 0, width));
    let (y0, y1) = (ceil_within(lo(y) - 0.5, rows.0, rows.1), floor_within(hi(y) + 0.5, rows.0, rows.1));
    if x0 < x1 && y0 < y1 { (x0, x1, y0, y1) } else { (0, 0, 0, 0) }
}

/// False when no pixel centre of a `width × height` image lies in the triangle's bounding box:
/// it cannot cover one (most triangles of a mesh finer than the pixels), and the frame need
/// not keep it.
#[inline]
pub fn may_cover_a_pixel(t: &ScreenTriangle, (width, height): (u32, u32)) -> bool {
    let (x0, x1, y0, y1) = centre_box(&t.x, &t.y, width, (0, height));
    x0 < x1 && y0 < y1
}

/// One covered pixel: position, depth and perspective-correct attributes.
pub struct Fragment {
    /// Column.
    pub x: u32,
    /// Row.
    pub y: u32,
    /// `z/w`.
    pub depth: f64,
    /// The source triangle's corner weights (perspective-correct).
    pub bary: Bary,
}

/// True when a pixel centre exactly on edge `a → b` belongs to the triangle on the edge's
/// positive side: the rule must flip with the edge's direction, so of the two triangles sharing
/// the edge (which run it in opposite directions) exactly one takes the pixel.
#[inline]
fn owns_edge(dx: f64, dy: f64) -> bool {
    dy > 0.0 || (dy == 0.0 && dx < 0.0)
}

/// Columns `[x0, x1)` of row centre `cy` that may be inside all edges: each edge not parallel
/// to the row bounds the centres `cx` where its function is non-negative; a pixel of margin
/// absorbs the rounding of the division, and the exact per-pixel test decides (thin triangles
/// such as shadow-volume sides no longer cost their whole bounding box).
#[inline]
fn row_span(edges: &[(f64, f64, f64, f64); 3], cy: f64, min_x: u32, max_x: u32) -> (u32, u32) {
    let (mut lo, mut hi) = (min_x as f64, max_x as f64);
    for &(ax, ay, dx, dy) in edges {
        // e = dx (cy − ay) − dy (cx − ax) ≥ 0.
        let cross = ax + dx * (cy - ay) / dy;
        if dy > 0.0 {
            hi = hi.min(cross + 1.0);
        } else if dy < 0.0 {
            lo = lo.max(cross - 1.5);
        }
    }
    if lo >= hi {
        return (0, 0);
    }
    (floor_within(lo, min_x, max_x), ceil_within(hi, min_x, max_x))
}

/// Calls `emit` for every pixel centre of rows `[y0, y1)` and columns `[0, width)` covered by `t`.
pub fn rasterize(t: &ScreenTriangle, width: u32, y0: u32, y1: u32, mut emit: impl FnMut(Fragment)) {
    let (mut x, mut y, mut idx) = (t.x, t.y, [0usize, 1, 2]);
    let area = (x[1] - x[0]) * (y[2] - y[0]) - (y[1] - y[0]) * (x[2] - x[0]);
    if area == 0.0 || !area.is_finite() {
        return;
    }
    if area < 0.0 {
        x.swap(1, 2);
        y.swap(1, 2);
        idx.swap(1, 2);
    }
    let area = area.abs();
    let (min_x, max_x, min_y, max_y) = centre_box(&x, &y, width, (y0, y1));
    if min_x >= max_x {
        return;
    }
    // Edge k runs from corner k+1 to corner k+2; its function is the weight of corner k.
    let edges: [(f64, f64, f64, f64); 3] = std::array::from_fn(|k| {
        let (a, b) = ((k + 1) % 3, (k + 2) % 3);
        (x[a], y[a], x[b] - x[a], y[b] - y[a])
    });
    for py in min_y..max_y {
        let cy = py as f64 + 0.5;
        let (x0, x1) = row_span(&edges, cy, min_x, max_x);
        for px in x0..x1 {
            let cx = px as f64 + 0.5;
            let mut w = [0.0; 3];
            let mut inside = true;
            for (k, &(ax, ay, dx, dy)) in edges.iter().enumerate() {
                // Positive inside: the corners were ordered for a positive area.
                let e = dx * (cy - ay) - dy * (cx - ax);
                if e < 0.0 || (e == 0.0 && !owns_edge(dx, dy)) {
                    inside = false;
                    break;
                }
                w[k] = e / area;
            }
            if !inside {
                continue;
            }
            let depth = (0..3).map(|k| w[k] * t.z[idx[k]]).sum();
            let inv_w: f64 = (0..3).map(|k| w[k] * t.inv_w[idx[k]]).sum();
            let bary = [0, 1].map(|j| (0..3).map(|k| w[k] * t.bary_w[idx[k]][j]).sum::<f64>() / inv_w);
            emit(Fragment { x: px, y: py, depth, bary });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn tri(p: [(f64, f64); 3]) -> ScreenTriangle {
        ScreenTriangle {
            x: p.map(|q| q.0),
            y: p.map(|q| q.1),
            z: [0.0; 3],
            inv_w: [1.0; 3],
            bary_w: [[0.0; 2]; 3],
            source: 0,
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(300))]

        /// A jittered grid of quads, each split in two triangles in both winding orders, covers
        /// every pixel of its interior exactly once.
        #[test]
        fn a_tessellated_plane_covers_every_pixel_exactly_once(
            jitter in prop::collection::vec((-1.9..1.9f64, -1.9..1.9f64), 81), flip in prop::collection::vec(any::<bool>(), 64)
        ) {
            let (n, cell, w) = (8usize, 8.0, 64u32);
            let grid = |i: usize, j: usize| {
                let (jx, jy) = if i == 0 || j == 0 || i == n || j == n { (0.0, 0.0) } else { jitter[i * 9 + j] };
                (j as f64 * cell + jx, i as f64 * cell + jy)
            };
            let mut count = vec![0u32; (w * w) as usize];
            for i in 0..n {
                for j in 0..n {
                    let (a, b, c, d) = (grid(i, j), grid(i, j + 1), grid(i + 1, j + 1), grid(i + 1, j));
                    let tris = if flip[i * n + j] { [[a, b, c], [a, c, d]] } else { [[a, c, b], [a, d, c]] };
                    for t in tris {
                        rasterize(&tri(t), w, 0, w, |f| count[(f.y * w + f.x) as usize] += 1);
                    }
                }
            }
            prop_assert!(count.iter().all(|&c| c == 1), "{:?}", count.iter().enumerate().find(|(_, c)| **c != 1));
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(500))]

        /// A triangle whose bounding box holds no pixel centre covers none, and the frame may
        /// drop it.
        #[test]
        fn triangles_kept_out_cover_no_pixel(p in prop::array::uniform3((-2.0..18.0f64, -2.0..18.0f64)), scale in 0.01..3.0f64) {
            let t = tri(p.map(|(x, y)| (x * scale, y * scale)));
            let mut covered = 0;
            rasterize(&t, 16, 0, 16, |_| covered += 1);
            if !may_cover_a_pixel(&t, (16, 16)) {
                prop_assert_eq!(covered, 0);
            }
        }
    }

    #[test]
    fn attributes_interpolate_perspective_correctly() {
        // Two corners at w = 1 and one at w = 4: the attribute a (= 0, 0, 1) at the centroid in
        // screen space is not 1/3 but (1/4 · 1/3) / (1/3 + 1/3 + 1/12).
        let mut t = tri([(0.0, 0.0), (30.0, 0.0), (0.0, 30.0)]);
        t.inv_w = [1.0, 1.0, 0.25];
        t.bary_w = [[0.0, 0.0], [1.0, 0.0], [0.0, 0.25]];
        let mut got = None;
        rasterize(&t, 64, 0, 64, |f| {
            if (f.x, f.y) == (9, 9) {
                got = Some(f.bary[1]);
            }
        });
        let (b1, b2) = (9.5 / 30.0, 9.5 / 30.0);
        let b0 = 1.0 - b1 - b2;
        let want = (b2 * 0.25) / (b0 + b1 + b2 * 0.25);
        assert!((got.unwrap() - want).abs() < 1e-12);
    }
}
