//! The paper's figures as SVG documents (strings; writing them is the caller's business):
//! the catacaustic with its generating rays (Fig. 5/9) and the confocal conics through the
//! reflexes (Fig. 12).

use crate::caustic::{self, Eye, Side};
use crate::{Circle, ReflexKind, Site};
use alhazen_math::Vec2;
use std::fmt::Write;

/// An SVG canvas mapping a square of the plane (centre, half-width) to `size × size` pixels.
struct Canvas {
    out: String,
    center: Vec2,
    half: f64,
    size: f64,
}

impl Canvas {
    fn new(center: Vec2, half: f64, size: f64, title: &str) -> Self {
        let mut out = String::new();
        let _ = writeln!(
            out,
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="{size}" height="{size}" viewBox="0 0 {size} {size}">"#
        );
        let _ = writeln!(out, "<title>{title}</title>");
        let _ = writeln!(out, r#"<rect width="100%" height="100%" fill="white"/>"#);
        Self { out, center, half, size }
    }

    fn map(&self, p: Vec2) -> (f64, f64) {
        let k = self.size / (2.0 * self.half);
        ((p.x - self.center.x) * k + self.size / 2.0, (self.center.y - p.y) * k + self.size / 2.0)
    }

    fn polyline(&mut self, pts: &[Vec2], stroke: &str, width: f64) {
        let mut d = String::new();
        for (i, p) in pts.iter().enumerate() {
            let (x, y) = self.map(*p);
            let _ = write!(d, "{}{x:.2},{y:.2}", if i == 0 { "M" } else { " L" });
        }
        let _ = writeln!(self.out, r#"<path d="{d}" fill="none" stroke="{stroke}" stroke-width="{width}"/>"#);
    }

    fn circle(&mut self, c: Vec2, r: f64, stroke: &str, fill: &str) {
        let (x, y) = self.map(c);
        let rr = r * self.size / (2.0 * self.half);
        let _ = writeln!(
            self.out,
            r#"<circle cx="{x:.2}" cy="{y:.2}" r="{rr:.2}" fill="{fill}" stroke="{stroke}" stroke-width="1.5"/>"#
        );
    }

    fn dot(&mut self, c: Vec2, color: &str, label: &str) {
        let (x, y) = self.map(c);
        let _ = writeln!(self.out, r#"<circle cx="{x:.2}" cy="{y:.2}" r="3.5" fill="{color}"/>"#);
        if !label.is_empty() {
            let _ = writeln!(
                self.out,
                r#"<text x="{:.2}" y="{:.2}" font-family="sans-serif" font-size="14">{label}</text>"#,
                x + 6.0,
                y - 6.0
            );
        }
    }

    fn finish(mut self) -> String {
        self.out.push_str("</svg>\n");
        self.out
    }
}

/// Fig. 5/9: the circle of radius `r` centred at the origin, the eye at `(e, 0)` (`e = ∞`
/// for parallel rays), `rays` reflected rays and the catacaustic of the chosen side.
pub fn caustic_svg(r: f64, e: f64, side: Side, rays: usize) -> String {
    let eye = if e.is_finite() { Eye::At(e) } else { Eye::AtInfinity };
    let half = if e.is_finite() { (e * 1.15).max(2.2 * r) } else { 2.2 * r };
    let mut c = Canvas::new(Vec2::ZERO, half, 800.0, &format!("catacaustic, r = {r}, e = {e}"));
    let extent = 4.0 * half;
    let (lo, hi) = match (eye, side) {
        (Eye::At(e), Side::Outside) if e > r => (-(r / e).acos(), (r / e).acos()),
        (Eye::AtInfinity, Side::Outside) => (-std::f64::consts::FRAC_PI_2, std::f64::consts::FRAC_PI_2),
        (Eye::At(e), Side::Inside) if e > r => ((r / e).acos(), 2.0 * std::f64::consts::PI - (r / e).acos()),
        _ => (0.0, 2.0 * std::f64::consts::PI),
    };
    for k in 0..rays {
        let phi = lo + (hi - lo) * (k as f64 + 0.5) / rays as f64;
        let (start, dir) = caustic::reflected_ray(r, eye, phi);
        let from = match eye {
            Eye::At(e) => Vec2::new(e, 0.0),
            Eye::AtInfinity => Vec2::new(extent, start.y),
        };
        c.polyline(&[from, start], "#c8c8c8", 0.6);
        // Inside reflections are drawn up to the next wall, outside ones far out.
        let len = if side == Side::Inside { -2.0 * start.dot(dir) } else { extent };
        c.polyline(&[start, start + dir * len], "#7fa7d9", 0.6);
    }
    c.circle(Vec2::ZERO, r, "black", "none");
    for piece in caustic::curve(r, eye, side, 2000, extent) {
        c.polyline(&piece, "#c0392b", 2.0);
    }
    if let Eye::At(e) = eye {
        c.dot(Vec2::new(e, 0.0), "black", "E");
    }
    c.dot(Vec2::ZERO, "black", "M");
    c.finish()
}

/// Fig. 12: the confocal conics with foci `E` and `S` that touch the circle (centre origin,
/// radius `r`) — at the reflexes of `S`: ellipses for real reflections, hyperbolas for virtual
/// ones.
pub fn conics_svg(r: f64, eye: Vec2, source: Vec2) -> Result<String, crate::MirrorError> {
    let circle = Circle { center: Vec2::ZERO, radius: r };
    let res = circle.reflexes(Site::At(eye.extend(0.0)), Site::At(source.extend(0.0)))?;
    let half = eye.length().max(source.length()).max(r) * 1.3;
    let mut c = Canvas::new(Vec2::ZERO, half, 800.0, "confocal conics touching the mirror at the reflexes");
    let (mid, focal) = ((eye + source) / 2.0, (eye - source).length() / 2.0);
    let ax = (eye - source).normalize_or(Vec2::X);
    let ay = ax.perp();
    for rf in res.all() {
        let p = Vec2::new(rf.point.x, rf.point.y);
        let (de, ds) = ((p - eye).length(), (p - source).length());
        let color = match rf.kind {
            ReflexKind::Outside => "#c0392b",
            ReflexKind::Inside => "#2e86c1",
            ReflexKind::Virtual => "#27ae60",
        };
        let pts: Vec<Vec2> = if rf.kind == ReflexKind::Virtual {
            // Hyperbola |de − ds| = 2a, the branch through p.
            let a = (de - ds).abs() / 2.0;
            let b = (focal * focal - a * a).max(0.0).sqrt();
            let sign = if de > ds { -1.0 } else { 1.0 };
            (0..=200)
                .map(|k| {
                    let u = -3.0 + 6.0 * k as f64 / 200.0;
                    mid + ax * (sign * a * u.cosh()) + ay * (b * u.sinh())
                })
                .collect()
        } else {
            let a = (de + ds) / 2.0;
            let b = (a * a - focal * focal).max(0.0).sqrt();
            (0..=200)
                .map(|k| {
                    let th = std::f64::consts::TAU * k as f64 / 200.0;
                    mid + ax * (a * th.cos()) + ay * (b * th.sin())
                })
                .collect()
        };
        c.polyline(&pts, color, 1.2);
        c.dot(p, color, "");
    }
    c.circle(Vec2::ZERO, r, "black", "none");
    c.dot(eye, "black", "E");
    c.dot(source, "black", "S");
    Ok(c.finish())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn figures_are_svg_with_the_expected_parts() {
        let s = caustic_svg(1.0, 3.0, Side::Outside, 24);
        assert!(s.starts_with("<svg") && s.trim_end().ends_with("</svg>"));
        assert!(s.matches("<path").count() > 48, "rays and caustic drawn");
        let s = caustic_svg(1.0, f64::INFINITY, Side::Outside, 24);
        assert!(s.contains("#c0392b"));
        let s = conics_svg(1.0, Vec2::new(3.0, 0.0), Vec2::new(1.5, 2.0)).unwrap();
        assert!(s.contains("#c0392b"), "the ellipse of the visible reflex");
        assert!(conics_svg(1.0, Vec2::new(1.0, 0.0), Vec2::new(1.5, 2.0)).is_err());
    }
}
