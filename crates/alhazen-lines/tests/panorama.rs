//! Line drawings through the panorama camera (central projection on a cylinder, developed
//! flat): the drawing's film is the ray tracer's, straight lines are followed as the curves they
//! become within the tolerance, and nothing is drawn across the seam where the film wraps.

use alhazen_lines::curves::Curve;
use alhazen_lines::view::View;
use alhazen_lines::{Options, draw};
use alhazen_math::{Vec2, Vec3};
use alhazen_render::{Camera, World};
use proptest::prelude::*;

fn panorama(fov: f64, objects: &str) -> alhazen_scene::Scene {
    let text = format!(
        "[render]\nwidth = 720\nheight = 240\n[camera]\ntype = \"panorama\"\neye = [0.3, 1.1, -0.4]\n\
         target = [1, 1.3, 2]\nfov = {fov}\n{objects}"
    );
    alhazen_scene::parse_scene("pano.toml".as_ref(), &text).unwrap()
}

const BOXES: &str = "[[object]]\nshape = \"box\"\nmin = [1, 0, 2]\nmax = [2, 2, 3]\n\
     [[object]]\nshape = \"box\"\nmin = [-3, 0, -4]\nmax = [-1, 1, -3]\n\
     [[object]]\nshape = \"box\"\nmin = [2, 0, -3]\nmax = [3, 3, -2]\n";

proptest! {
    /// A point along the ray through a film position lands on that film position.
    #[test]
    fn the_film_is_the_ray_tracers(fx in 1.0..719.0f64, fy in 1.0..239.0f64, d in 0.1..50.0f64, fov in 90.0..360.0f64) {
        let scene = panorama(fov, BOXES);
        let view = View::new(&scene, &World::build(&scene), 720.0).unwrap();
        let ray = Camera::new(&scene.camera, 720, 240).ray(fx, fy);
        let q = view.to_film(ray.at(d));
        prop_assert!((q - Vec2::new(fx, fy)).length() < 1e-7, "{q:?}");
    }

    /// A segment's image is followed within the tolerance: the true image of points between
    /// its knots lies within `tol` of the chords.
    #[test]
    fn segments_become_curves_within_the_tolerance(
        a in prop::array::uniform3(-4.0..4.0f64), b in prop::array::uniform3(-4.0..4.0f64),
    ) {
        let scene = panorama(300.0, BOXES);
        let view = View::new(&scene, &World::build(&scene), 720.0).unwrap();
        let curve = Curve::Segment { a: Vec3::from_array(a), b: Vec3::from_array(b) };
        prop_assume!((0..=64).all(|k| view.depth(curve.point(k as f64 / 64.0)) > 0.3));
        let tol_mm = 0.05;
        let knots = curve.knots(&view, tol_mm);
        for w in knots.windows(2) {
            let (fa, fb) = (view.to_paper(curve.point(w[0])), view.to_paper(curve.point(w[1])));
            if (fa.x - fb.x).abs() > 360.0 {
                continue; // across the seam: left out of the drawing
            }
            for k in 1..8 {
                let p = view.to_paper(curve.point(w[0] + (w[1] - w[0]) * k as f64 / 8.0));
                let t = ((p - fa).dot(fb - fa) / (fb - fa).length_squared().max(1e-300)).clamp(0.0, 1.0);
                prop_assert!((fa + (fb - fa) * t - p).length() < 4.0 * tol_mm, "{}", (fa + (fb - fa) * t - p).length());
            }
        }
    }
}

#[test]
fn nothing_is_drawn_across_the_seam() {
    // A full turn: the box behind the eye straddles the seam; so does the horizon.
    let scene = panorama(360.0, &format!("{BOXES}[[object]]\nshape = \"plane\"\n"));
    let (drawing, stats) = draw(&scene, &Options { width_mm: 720.0, ..Options::default() }).unwrap();
    assert!(stats.visible >= 4, "{stats:?}");
    let longest =
        drawing.lines.iter().flat_map(|(_, p)| p.windows(2)).map(|s| (s[1].x - s[0].x).abs()).fold(0.0, f64::max);
    assert!(longest < 100.0, "a stroke {longest} mm across");
    // The box behind the eye shows at both ends of the film.
    let xs: Vec<f64> = drawing.lines.iter().flat_map(|(_, p)| p.iter().map(|q| q.x)).collect();
    assert!(xs.iter().any(|&x| x < 20.0) && xs.iter().any(|&x| x > 700.0));
}
