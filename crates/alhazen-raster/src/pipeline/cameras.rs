//! The cameras a projection matrix cannot give, made from ones it can: a stereo pair as two
//! perspective views (course, §"Stereoscopic vision"), side by side or as a red–cyan anaglyph,
//! and the cylindrical panorama resampled from a cube map — six 90° views from its eye — as
//! the ray tracer's panorama camera maps pixels to directions.

use super::{Framebuffer, RasterError, RasterStats, projection};
use alhazen_math::viewing::ViewFrame;
use alhazen_math::{Vec3, Vec4};
use alhazen_scene::{CameraDesc, LookAt, PerspectiveOpening};
use rayon::prelude::*;

/// Both views' statistics together.
pub fn sum(a: RasterStats, b: RasterStats) -> RasterStats {
    RasterStats {
        triangles: a.triangles,
        culled: a.culled + b.culled,
        outside: a.outside + b.outside,
        drawn: a.drawn + b.drawn,
        missed: a.missed + b.missed,
        skipped_objects: a.skipped_objects,
        reflexes: a.reflexes + b.reflexes,
    }
}

/// The left view on the left, the right view on the right.
pub fn side_by_side(l: &Framebuffer, r: &Framebuffer) -> Framebuffer {
    let (w, h) = (l.width, l.height);
    let mut fb =
        Framebuffer { width: 2 * w, height: h, color: Vec::with_capacity(l.color.len() * 2), depth: Vec::new() };
    fb.depth.reserve(l.depth.len() * 2);
    for y in 0..h as usize {
        let row = y * w as usize..(y + 1) * w as usize;
        for eye in [l, r] {
            fb.color.extend_from_slice(&eye.color[row.clone()]);
            fb.depth.extend_from_slice(&eye.depth[row.clone()]);
        }
    }
    fb
}

/// A colour anaglyph for red (left) – cyan (right) glasses: red from the left view, green and
/// blue from the right; the depth of the nearer.
pub fn anaglyph(l: &Framebuffer, r: &Framebuffer) -> Framebuffer {
    Framebuffer {
        width: l.width,
        height: l.height,
        color: l.color.iter().zip(&r.color).map(|(a, b)| [a[0], b[1], b[2]]).collect(),
        depth: l.depth.iter().zip(&r.depth).map(|(a, b)| a.min(*b)).collect(),
    }
}

/// The panorama of `angle` radians from `look` at `w × h`: the cube's faces (as fine as the
/// panorama's pixels, at most 4096 a side) are rendered by `view` and each pixel takes the
/// face texel its direction falls on.
pub fn panorama(
    look: LookAt,
    angle: f64,
    (w, h): (u32, u32),
    view: impl Fn(&CameraDesc, u32) -> Result<(Framebuffer, RasterStats), RasterError>,
) -> Result<(Framebuffer, RasterStats), RasterError> {
    let frame = ViewFrame::look_at(look.eye, look.target, look.up).unwrap_or(ViewFrame {
        eye: look.eye,
        u: Vec3::X,
        v: Vec3::Y,
        w: Vec3::Z,
    });
    let size = ((w as f64 * std::f64::consts::FRAC_PI_2 / angle).ceil() as u32).clamp(16, 4096);
    // Forward and up of each face, in the view's frame (−w is ahead).
    let faces = [
        (-frame.w, frame.v),
        (frame.w, frame.v),
        (frame.u, frame.v),
        (-frame.u, frame.v),
        (frame.v, frame.w),
        (-frame.v, -frame.w),
    ];
    let mut rendered = vec![];
    let mut stats: Option<RasterStats> = None;
    for (ahead, up) in faces {
        let desc = CameraDesc::Perspective {
            look: LookAt { eye: frame.eye, target: frame.eye + ahead, up },
            opening: PerspectiveOpening::Fov { angle: std::f64::consts::FRAC_PI_2, horizontal: true },
            lens: None,
        };
        let (fb, s) = view(&desc, size)?;
        stats = Some(stats.map_or(s, |t| sum(t, s)));
        rendered.push((projection(&desc, size, size)?, ahead, fb));
    }
    let pixel = |x: u32, y: u32| {
        // The ray tracer's panorama: azimuth across, height on the unit cylinder down.
        let phi = ((x as f64 + 0.5) / w as f64 - 0.5) * angle;
        let height = (0.5 - (y as f64 + 0.5) / h as f64) * angle * h as f64 / w as f64;
        let d = frame.to_world_dir(Vec3::new(phi.sin(), height, -phi.cos()));
        let (proj, _, fb) = rendered.iter().max_by(|a, b| a.1.dot(d).total_cmp(&b.1.dot(d))).expect("six faces");
        let c = proj.world_to_clip * Vec4::new(frame.eye.x + d.x, frame.eye.y + d.y, frame.eye.z + d.z, 1.0);
        let (nx, ny) = (c.x / c.w, c.y / c.w);
        let fx = (((nx + 1.0) * 0.5 * size as f64) as u32).min(size - 1);
        let fy = (((1.0 - ny) * 0.5 * size as f64) as u32).min(size - 1);
        let k = (fy * size + fx) as usize;
        (fb.color[k], fb.depth[k])
    };
    let texels: Vec<([f32; 3], f64)> =
        (0..h).into_par_iter().flat_map_iter(|y| (0..w).map(move |x| pixel(x, y))).collect();
    let fb = Framebuffer {
        width: w,
        height: h,
        color: texels.iter().map(|t| t.0).collect(),
        depth: texels.iter().map(|t| t.1).collect(),
    };
    Ok((fb, stats.expect("six faces")))
}
