//! The scan-line algorithm (course, §"Image space algorithms": "rasterise all polygons at the
//! same time, one horizontal line of the image after another … reduce the depth buffer to a
//! one-dimensional array"): an edge table holds each triangle under the first row it covers; the
//! active list gains a row's new triangles and loses those that ended above it; visibility along
//! the row is resolved in a depth buffer of one row. Triangles stay in drawing order in the
//! active list and a nearer fragment must be strictly nearer, so the frame is the z-buffer's
//! pixel for pixel.

use super::raster::{Fragment, ScreenTriangle, rasterize};

/// The rows `[first, last]` whose pixel centres a triangle's vertical extent reaches.
fn rows(t: &ScreenTriangle) -> (f64, f64) {
    let lo = t.y.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = t.y.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    ((lo - 0.5).ceil(), (hi - 0.5).floor())
}

/// Resolves the rows `y0..y1` of a frame `width` wide among the triangles `bin` (indices into
/// `screen`, in drawing order): `visible(k, triangle, fragment)` is called each time a fragment
/// is nearer than what row-local index `k` (row-major within the band) held before.
pub fn band(
    screen: &[ScreenTriangle],
    bin: &[u32],
    width: u32,
    (y0, y1): (u32, u32),
    mut visible: impl FnMut(usize, &ScreenTriangle, Fragment),
) {
    // The edge table: each triangle under the first row of the band it covers.
    let mut table: Vec<Vec<u32>> = vec![vec![]; (y1 - y0) as usize];
    for &i in bin {
        let (first, last) = rows(&screen[i as usize]);
        if last >= y0 as f64 && first < y1 as f64 && first <= last {
            table[(first.max(y0 as f64) as u32 - y0) as usize].push(i);
        }
    }
    let mut active: Vec<u32> = vec![];
    let mut depth = vec![f64::INFINITY; width as usize];
    for y in y0..y1 {
        let new = std::mem::take(&mut table[(y - y0) as usize]);
        if !new.is_empty() {
            active.extend(new);
            active.sort_unstable();
        }
        active.retain(|&i| rows(&screen[i as usize]).1 >= y as f64);
        depth.fill(f64::INFINITY);
        for &i in &active {
            let t = &screen[i as usize];
            rasterize(t, width, y, y + 1, |f| {
                let x = f.x as usize;
                if f.depth < depth[x] && f.depth >= -1.0 {
                    depth[x] = f.depth;
                    visible(((y - y0) * width) as usize + x, t, f);
                }
            });
        }
    }
}
