//! Cylinder anamorphoses (Glaeser §2.4, Theorem 4): a picture drawn on the base plane so that,
//! seen from the eye `E` in a mirror cylinder standing on it, it appears undistorted.
//!
//! The undistorted picture lives on the *picture plane*: the vertical plane through the
//! cylinder's axis facing the eye. A picture point `P` is seen along `E → P`; that ray meets the
//! cylinder at `R′`, is reflected there and meets the base plane at `S`: the picture's colour at
//! `P` is printed at `S` ([`Anamorphosis::floor_of_picture`]). Printing a raster goes the other
//! way, pixel by pixel on the paper: `S`'s visible reflex `R′` on the cylinder seen from `E`
//! is exactly Alhazen's problem ([`crate::Cylinder::visible_reflex`]), and `E → R′` continued
//! meets the picture plane at `P` ([`Anamorphosis::picture_of_floor`]).
//!
//! Coordinates are the scene files': `y` up, the base plane `y = 0`, the cylinder's axis the
//! `y` axis.

use crate::{Cylinder, Site};
use alhazen_math::{Vec2, Vec3};

/// Why an anamorphosis cannot be set up.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AnamorphError {
    /// Radius or height not positive and finite.
    BadCylinder,
    /// The eye must be outside the cylinder and above the base plane.
    BadEye,
    /// The picture's aspect ratio (width / height) must be positive and finite.
    BadAspect,
}

impl std::fmt::Display for AnamorphError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            AnamorphError::BadCylinder => "the cylinder's radius and height must be positive",
            AnamorphError::BadEye => "the eye must be outside the cylinder and above the base plane",
            AnamorphError::BadAspect => "the picture's aspect ratio must be positive",
        })
    }
}

impl std::error::Error for AnamorphError {}

/// A mirror cylinder of radius `r` and height `h` on the base plane, an eye, and where the
/// picture sits on the picture plane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Anamorphosis {
    cylinder: Cylinder,
    height: f64,
    eye: Vec3,
    /// Horizontal unit vector of the picture plane (the picture's `u` direction).
    across: Vec3,
    /// The picture's top-left corner, width and height on the picture plane.
    corner: Vec3,
    size: Vec2,
}

impl Anamorphosis {
    /// The picture, of aspect `width / height`, as large as the mirror shows it: the front of
    /// the cylinder, seen from the eye, covers on the picture plane a window `2r·e/√(e² − r²)`
    /// wide and about `h·e/(e − r)` high (`e` the eye's distance from the axis); the picture
    /// fills 90 % of its width or 85 % of its height, centred in it.
    pub fn new(radius: f64, height: f64, eye: Vec3, aspect: f64) -> Result<Self, AnamorphError> {
        let finite = |v: f64| v.is_finite() && v > 0.0;
        if !finite(radius) || !finite(height) {
            return Err(AnamorphError::BadCylinder);
        }
        if !finite(aspect) {
            return Err(AnamorphError::BadAspect);
        }
        let flat = Vec3::new(eye.x, 0.0, eye.z);
        let e = flat.length();
        if !eye.is_finite() || eye.y <= 0.0 || e <= radius * (1.0 + 1e-9) {
            return Err(AnamorphError::BadEye);
        }
        let toward = flat / e;
        let across = Vec3::Y.cross(toward);
        // The front line of the cylinder seen from the eye, carried on to the picture plane.
        let k = e / (e - radius);
        let (y_lo, y_hi) = (eye.y - eye.y * k, eye.y + (height - eye.y) * k);
        let half_width = radius * e / (e * e - radius * radius).sqrt();
        let (mut w, mut h) = (1.8 * half_width, 0.85 * (y_hi - y_lo));
        if w / h > aspect {
            w = h * aspect
        } else {
            h = w / aspect
        }
        let corner = -across * (0.5 * w) + Vec3::Y * (0.5 * (y_lo + y_hi) + 0.5 * h);
        Ok(Anamorphosis {
            cylinder: Cylinder { center: Vec3::ZERO, axis: Vec3::Y, radius },
            height,
            eye,
            across,
            corner,
            size: Vec2::new(w, h),
        })
    }

    /// The eye.
    pub fn eye(&self) -> Vec3 {
        self.eye
    }

    /// The mirror.
    pub fn cylinder(&self) -> Cylinder {
        self.cylinder
    }

    /// The point of the picture plane at picture coordinates `(u, v) ∈ [0, 1]²` (`v` down).
    pub fn picture_point(&self, uv: Vec2) -> Vec3 {
        self.corner + self.across * (uv.x * self.size.x) - Vec3::Y * (uv.y * self.size.y)
    }

    /// Picture coordinates of the point of the picture plane the eye sees through `q`.
    fn picture_coords(&self, q: Vec3) -> Option<Vec2> {
        // The picture plane passes through the axis; its normal points to the eye.
        let n = self.across.cross(Vec3::Y);
        let d = q - self.eye;
        let den = d.dot(n);
        if den.abs() < 1e-300 {
            return None;
        }
        let p = self.eye + d * (-self.eye.dot(n) / den);
        let rel = p - self.corner;
        let uv = Vec2::new(rel.dot(self.across) / self.size.x, -rel.y / self.size.y);
        ((0.0..=1.0).contains(&uv.x) && (0.0..=1.0).contains(&uv.y)).then_some(uv)
    }

    /// The picture point printed at floor point `(x, z)`, as picture coordinates: `None` where
    /// the floor point has no visible reflex on the finite mirror, or shows outside the picture.
    pub fn picture_of_floor(&self, floor: Vec2) -> Option<Vec2> {
        let s = Vec3::new(floor.x, 0.0, floor.y);
        let r = self.cylinder.visible_reflex(Site::At(self.eye), Site::At(s)).ok().flatten()?.point;
        if !(0.0..=self.height).contains(&r.y) {
            return None;
        }
        self.picture_coords(r)
    }

    /// Where picture point `(u, v)` is printed on the floor: `E → P` meets the cylinder at `R′`
    /// (the first of its two intersections), is reflected and meets the floor. `None` if the
    /// ray misses the finite mirror or the reflected ray does not come down.
    pub fn floor_of_picture(&self, uv: Vec2) -> Option<Vec2> {
        let p = self.picture_point(uv);
        let d = (p - self.eye).normalize();
        // |flat(E + t d)|² = r²
        let (ex, ez, dx, dz) = (self.eye.x, self.eye.z, d.x, d.z);
        let a = dx * dx + dz * dz;
        let b = 2.0 * (ex * dx + ez * dz);
        let c = ex * ex + ez * ez - self.cylinder.radius * self.cylinder.radius;
        let disc = b * b - 4.0 * a * c;
        if a <= 0.0 || disc < 0.0 {
            return None;
        }
        let t = (-b - disc.sqrt()) / (2.0 * a);
        let r = self.eye + d * t;
        if t <= 0.0 || !(0.0..=self.height).contains(&r.y) {
            return None;
        }
        let n = Vec3::new(r.x, 0.0, r.z).normalize();
        let out = d - n * (2.0 * d.dot(n));
        if out.y >= 0.0 {
            return None;
        }
        let s = r + out * (-r.y / out.y);
        Some(Vec2::new(s.x, s.z))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn setup() -> Anamorphosis {
        Anamorphosis::new(1.0, 3.0, Vec3::new(0.0, 6.0, 8.0), 1.5).unwrap()
    }

    #[test]
    fn theorem_4_a_circle_of_radius_e_reflects_at_half_the_height() {
        // Eye at horizontal distance e = 8, height 6: floor points at distance 8 from the axis
        // reflect on the parallel circle at height 6/2.
        let a = setup();
        for k in 0..24 {
            let ang = 0.3 * (k as f64 / 23.0 - 0.5);
            let s = Vec3::new(8.0 * ang.sin(), 0.0, 8.0 * ang.cos());
            let r = a.cylinder.visible_reflex(Site::At(a.eye), Site::At(s)).unwrap().unwrap();
            assert!((r.point.y - 3.0).abs() < 1e-12, "{:?}", r.point);
        }
    }

    #[test]
    fn printing_and_seeing_are_inverse() {
        let a = setup();
        let mut checked = 0;
        for i in 0..=10 {
            for j in 0..=10 {
                let uv = Vec2::new(0.02 + 0.96 * i as f64 / 10.0, 0.02 + 0.96 * j as f64 / 10.0);
                if let Some(f) = a.floor_of_picture(uv) {
                    let back = a.picture_of_floor(f).expect("a printed point is seen");
                    assert!((back - uv).length() < 1e-9, "{uv:?} → {f:?} → {back:?}");
                    checked += 1;
                }
            }
        }
        assert!(checked > 100, "{checked}");
    }

    #[test]
    fn bad_setups_are_errors() {
        assert_eq!(Anamorphosis::new(0.0, 1.0, Vec3::new(0.0, 1.0, 5.0), 1.0), Err(AnamorphError::BadCylinder));
        assert_eq!(Anamorphosis::new(1.0, 1.0, Vec3::new(0.0, 1.0, 0.5), 1.0), Err(AnamorphError::BadEye));
        assert_eq!(Anamorphosis::new(1.0, 1.0, Vec3::new(0.0, -1.0, 5.0), 1.0), Err(AnamorphError::BadEye));
        assert_eq!(Anamorphosis::new(1.0, 1.0, Vec3::new(0.0, 1.0, 5.0), f64::NAN), Err(AnamorphError::BadAspect));
    }
}

/// Paper sizes in millimetres, portrait.
pub fn paper_size(name: &str) -> Option<Vec2> {
    let iso = |n: i32| {
        // A0 is 841 × 1189 mm; each next size halves the long side (ISO 216, rounded down).
        let (mut w, mut h) = (841.0f64, 1189.0f64);
        for _ in 0..n {
            (w, h) = ((h / 2.0).floor(), w);
        }
        Vec2::new(w, h)
    };
    match name.to_ascii_uppercase().as_str() {
        "A0" => Some(iso(0)),
        "A1" => Some(iso(1)),
        "A2" => Some(iso(2)),
        "A3" => Some(iso(3)),
        "A4" => Some(iso(4)),
        "A5" => Some(iso(5)),
        "LETTER" => Some(Vec2::new(215.9, 279.4)),
        _ => {
            let (w, h) = name.split_once(['x', 'X'])?;
            let (w, h) = (w.trim().parse::<f64>().ok()?, h.trim().parse::<f64>().ok()?);
            (w > 0.0 && h > 0.0 && w.is_finite() && h.is_finite()).then(|| Vec2::new(w, h))
        }
    }
}

/// Where the print goes on paper: the axis's position in millimetres from the top-left corner
/// (paper `x` along world `x`, paper `y` along world `z`; world units are millimetres).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    /// Paper size in millimetres.
    pub paper: Vec2,
    /// The cylinder's axis on the paper.
    pub axis: Vec2,
}

impl Placement {
    /// The floor point under a paper point.
    pub fn floor(&self, paper_mm: Vec2) -> Vec2 {
        paper_mm - self.axis
    }

    /// The paper point over a floor point.
    pub fn paper_point(&self, floor: Vec2) -> Vec2 {
        floor + self.axis
    }
}

impl Anamorphosis {
    /// Centres the printed region (and the cylinder's footprint) on paper of size `paper`,
    /// turned to landscape if that fits better; `Err(needed size)` when it does not fit.
    pub fn place(&self, paper: Vec2) -> Result<Placement, Vec2> {
        let r = self.cylinder.radius;
        let (mut lo, mut hi) = (Vec2::splat(-r), Vec2::splat(r));
        let n = 64;
        for i in 0..=n {
            for j in 0..=n {
                if let Some(f) = self.floor_of_picture(Vec2::new(i as f64 / n as f64, j as f64 / n as f64)) {
                    (lo, hi) = (lo.min(f), hi.max(f));
                }
            }
        }
        let need = (hi - lo) * 1.04;
        for p in [paper, Vec2::new(paper.y, paper.x)] {
            if need.x <= p.x && need.y <= p.y {
                return Ok(Placement { paper: p, axis: p * 0.5 - (lo + hi) * 0.5 });
            }
        }
        Err(need)
    }

    /// The picture coordinates printed at each pixel of a `dpi` raster of the paper, handed to
    /// `row(y, coordinates)` a row at a time, top first (`None` where the paper stays blank),
    /// computed by the batch solver; returns the raster's size.
    pub fn print_raster(&self, at: &Placement, dpi: f64, mut row: impl FnMut(u32, &[Option<Vec2>])) -> (u32, u32) {
        let px_mm = 25.4 / dpi;
        let (w, h) = ((at.paper.x / px_mm).round().max(1.0) as u32, (at.paper.y / px_mm).round().max(1.0) as u32);
        let mut reflexes = crate::batch::ReflexesSoA::default();
        let ys = vec![0.0; w as usize];
        let fx: Vec<f64> = (0..w).map(|i| (i as f64 + 0.5) * px_mm - at.axis.x).collect();
        let mut uvs = Vec::with_capacity(w as usize);
        for y in 0..h {
            let fzs = vec![(y as f64 + 0.5) * px_mm - at.axis.y; w as usize];
            let pts = crate::batch::PointsSoA { x: &fx, y: &ys, z: &fzs };
            uvs.clear();
            if self.cylinder.visible_reflexes_batch(self.eye, pts, &mut reflexes).is_err() {
                uvs.resize(w as usize, None);
            } else {
                for i in 0..w as usize {
                    let r = Vec3::new(reflexes.x[i], reflexes.y[i], reflexes.z[i]);
                    let seen = reflexes.visible[i] && (0.0..=self.height).contains(&r.y);
                    uvs.push(if seen { self.picture_coords(r) } else { None });
                }
            }
            row(y, &uvs);
        }
        (w, h)
    }

    /// A polyline of the picture (picture coordinates) as printed: floor polylines in
    /// millimetres, subdivided until consecutive points are at most `step` apart, broken where
    /// the picture is not seen in the mirror.
    pub fn print_polyline(&self, pts: &[Vec2], step: f64) -> Vec<Vec<Vec2>> {
        let mut out = vec![];
        let mut cur: Vec<Vec2> = vec![];
        let mut flush = |cur: &mut Vec<Vec2>| {
            if cur.len() > 1 {
                out.push(std::mem::take(cur));
            }
            cur.clear();
        };
        for seg in pts.windows(2) {
            let mut stack = vec![(0.0, 1.0)];
            let at = |t: f64| self.floor_of_picture(seg[0] + (seg[1] - seg[0]) * t);
            let mut first = true;
            while let Some((t0, t1)) = stack.pop() {
                let (a, b) = (at(t0), at(t1));
                let long = matches!((a, b), (Some(a), Some(b)) if (a - b).length() > step);
                if (long || a.is_some() != b.is_some()) && t1 - t0 > 1e-6 {
                    let tm = 0.5 * (t0 + t1);
                    stack.push((tm, t1));
                    stack.push((t0, tm));
                    continue;
                }
                if first {
                    match a {
                        Some(a) if cur.last().is_none_or(|l| (*l - a).length() > 1e-9) => {
                            flush(&mut cur);
                            cur.push(a);
                        }
                        None => flush(&mut cur),
                        _ => {}
                    }
                    first = false;
                }
                match b {
                    Some(b) if a.is_some() => cur.push(b),
                    Some(b) => {
                        flush(&mut cur);
                        cur.push(b);
                    }
                    None => flush(&mut cur),
                }
            }
        }
        flush(&mut cur);
        out
    }
}
