//! The free-form shapes of scene files (issue 23, item 5): NURBS curves with knots and weights,
//! sweeps with the exact circle, a given section or given auxiliary guides, surfaces of
//! revolution of NURBS profiles, lofts through unlike curves — and a `tolerance` that refines.

use alhazen_geom::TriangleMesh;
use alhazen_geom::bspline::BSpline;
use alhazen_geom::construct::{chord_lengths, interpolate_cubic};
use alhazen_math::Vec3;
use alhazen_scene::{Shape, parse_scene, parse_scene_reporting};

fn mesh_of(text: &str) -> TriangleMesh {
    let scene = parse_scene("s.toml".as_ref(), text).unwrap_or_else(|e| panic!("{e}"));
    let Shape::Mesh { mesh, .. } = scene.objects[0].shape else { panic!("not a mesh") };
    let m = scene.meshes[mesh].as_ref().clone();
    m.validate().unwrap();
    m
}

fn err(text: &str) -> String {
    match parse_scene("s.toml".as_ref(), text) {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e) => e.to_string(),
    }
}

/// The distance from `p` to the curve `c`: the nearest of 2000 samples, then refined by
/// ternary search on the parameter between its neighbours.
fn distance_to(p: Vec3, c: &BSpline<Vec3>) -> f64 {
    let (a, b) = c.domain();
    let at = |k: usize| a + (b - a) * k as f64 / 2000.0;
    let d = |t: f64| (c.eval(t) - p).length();
    let k = (0..=2000).min_by(|i, j| d(at(*i)).total_cmp(&d(at(*j)))).unwrap();
    let (mut lo, mut hi) = (at(k.saturating_sub(1)), at((k + 1).min(2000)));
    for _ in 0..80 {
        let (m1, m2) = (lo + (hi - lo) / 3.0, hi - (hi - lo) / 3.0);
        if d(m1) < d(m2) { hi = m2 } else { lo = m1 }
    }
    d(0.5 * (lo + hi))
}

/// At most about 3000 of the mesh's vertices, spread over it.
fn some_vertices(m: &TriangleMesh) -> impl Iterator<Item = Vec3> + '_ {
    m.positions.iter().step_by(m.positions.len().div_ceil(3000)).copied()
}

#[test]
fn a_swept_tube_is_round_to_its_tolerance() {
    // Curvature radii stay above the tube's radius, so the nearest guide point of a surface
    // point is the one it was swept from.
    let guide =
        [Vec3::new(-2.0, 0.0, 0.0), Vec3::new(-1.0, 0.6, 0.3), Vec3::new(0.5, 0.2, -0.3), Vec3::new(2.0, 0.8, 0.0)];
    let c = interpolate_cubic(&guide, &chord_lengths(&guide)).unwrap();
    let mut errors = vec![];
    for tol in ["1e-2", "1e-3", "1e-4"] {
        let m = mesh_of(&format!(
            "[[object]]\nshape = \"sweep\"\nguide = [[-2, 0, 0], [-1, 0.6, 0.3], [0.5, 0.2, -0.3], [2, 0.8, 0]]\nradius = 0.25\ntolerance = {tol}\n"
        ));
        // Vertices lie on the surface: their distance from the guide is the radius.
        let worst = some_vertices(&m).map(|p| (distance_to(p, &c) - 0.25).abs()).fold(0.0, f64::max);
        errors.push((tol.parse::<f64>().unwrap(), worst, m.triangle_count()));
    }
    for (tol, worst, _) in &errors {
        assert!(worst <= tol, "{errors:?}");
    }
    assert!(errors[0].2 < errors[1].2 && errors[1].2 < errors[2].2, "a finer tolerance, a finer mesh: {errors:?}");
    // The old 16-gon was 1.9 % off whatever the tolerance; now 1e-4 of a 0.25 radius is 0.04 %.
    assert!(errors[2].1 / 0.25 < 4e-4, "{errors:?}");
}

#[test]
fn a_nurbs_curve_with_knots_and_weights_is_a_full_circle() {
    // The course's circle of three 120° arcs, written out: the tube is a torus.
    let m = mesh_of(
        "[[object]]\nshape = \"curve\"\ndegree = 2\nradius = 0.1\ntolerance = 1e-4\n\
         points = [[1, 0, 0], [1, 1.7320508075688772, 0], [-0.5, 0.8660254037844386, 0], [-2, 0, 0], [-0.5, -0.8660254037844386, 0], [1, -1.7320508075688772, 0], [1, 0, 0]]\n\
         weights = [1, 0.5, 1, 0.5, 1, 0.5, 1]\nknots = [0, 0, 0, 1, 1, 2, 2, 3, 3, 3]\n",
    );
    for p in &m.positions {
        let ring = Vec3::new(p.x, p.y, 0.0).normalize();
        assert!(((*p - ring).length() - 0.1).abs() <= 1e-4, "{p}");
    }
}

#[test]
fn a_revolved_nurbs_circle_is_a_torus() {
    // Profile: the circle of radius 0.5 about (r, h) = (2, 0), as four 90° arcs.
    let w = std::f64::consts::FRAC_1_SQRT_2;
    let m = mesh_of(&format!(
        "[[object]]\nshape = \"revolution\"\ntolerance = 1e-4\nprofile = {{ degree = 2, \
         points = [[2.5, 0], [2.5, 0.5], [2, 0.5], [1.5, 0.5], [1.5, 0], [1.5, -0.5], [2, -0.5], [2.5, -0.5], [2.5, 0]], \
         weights = [1, {w}, 1, {w}, 1, {w}, 1, {w}, 1], knots = [0, 0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 4] }}\n"
    ));
    // y is the axis: every vertex is 0.5 from the circle of radius 2 in the xz plane.
    for p in &m.positions {
        let ring = Vec3::new(p.x, 0.0, p.z).normalize() * 2.0;
        assert!(((*p - ring).length() - 0.5).abs() <= 1e-9, "{p}");
    }
}

#[test]
fn a_given_section_and_given_guides_are_the_courses_formula() {
    // A square section swept along a straight guide with a constant frame: a square prism.
    let m = mesh_of(
        "[[object]]\nshape = \"sweep\"\nguide = { degree = 1, points = [[0, 0, 0], [0, 0, 3]] }\n\
         guides = [[[1, 0, 0], [1, 0, 0]], [[0, 1, 0], [0, 1, 0]], { degree = 2, points = [[0, 0, 1], [0, 0, 1], [0, 0, 1]] }]\n\
         section = { degree = 1, points = [[1, 1], [-1, 1], [-1, -1], [1, -1], [1, 1]] }\n",
    );
    for p in &m.positions {
        assert!((p.x.abs().max(p.y.abs()) - 1.0).abs() < 1e-12 && (-1e-12..=3.0 + 1e-12).contains(&p.z), "{p}");
    }
    // With a computed frame, a square section keeps its size along a curved guide.
    let m = mesh_of(
        "[[object]]\nshape = \"sweep\"\nguide = [[0, 0, 0], [1, 1, 0], [2, 0, 1]]\ntolerance = 1e-4\n\
         section = { degree = 1, points = [[0.2, 0.2], [-0.2, 0.2], [-0.2, -0.2], [0.2, -0.2], [0.2, 0.2]] }\n",
    );
    let guide = [Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0), Vec3::new(2.0, 0.0, 1.0)];
    let c = interpolate_cubic(&guide, &chord_lengths(&guide)).unwrap();
    for p in some_vertices(&m) {
        let d = distance_to(p, &c);
        assert!((0.2 - 1e-3..=0.2 * 2f64.sqrt() + 1e-3).contains(&d), "{p}: {d}");
    }
}

#[test]
fn unlike_curves_are_lofted_through() {
    let m = mesh_of(
        "[[object]]\nshape = \"loft\"\ntolerance = 1e-4\ncurves = [\n\
         [[0, 0, 0], [3, 0, 0]],\n\
         { degree = 3, points = [[0, 1, 0], [0.6, 1, 0.8], [1.2, 1, 0.9], [1.8, 1, 0.1], [2.4, 1, -0.7], [3, 1, -1]], knots = [0, 0, 0, 0, 0.3, 1.7, 2, 2, 2, 2] },\n\
         { degree = 2, points = [[0, 2, 0], [1.5, 2, 1.5], [3, 2, 0]], weights = [1, 0.7, 1] },\n]\n",
    );
    // The first curve is the straight edge u = 0 of the mesh.
    let on_edge = m.positions.iter().filter(|p| p.y.abs() < 1e-12 && p.z.abs() < 1e-12).count();
    assert!(on_edge >= 3, "{on_edge}");
    let (lo, hi) = m.positions.iter().fold((f64::MAX, f64::MIN), |(l, h), p| (l.min(p.y), h.max(p.y)));
    assert!(lo.abs() < 1e-9 && (hi - 2.0).abs() < 0.05, "{lo} {hi}");
}

#[test]
fn free_form_mistakes_are_located_and_explained() {
    let base = "[[object]]\nshape = \"curve\"\npoints = [[0, 0, 0], [1, 0, 0], [2, 1, 0], [3, 0, 0]]\n";
    let e = err(&format!("{base}degree = 2\nknots = [0, 0, 0, 1, 1]\n"));
    assert!(e.contains("s.toml:5:") && e.contains("needs 7 knots (points + degree + 1), found 5"), "{e}");
    let e = err(&format!("{base}degree = 2\nknots = [0, 0, 0, 2, 1, 1, 1]\n"));
    assert!(e.contains("non-decreasing"), "{e}");
    let e = err(&format!("{base}degree = 1\nknots = [0, 0, 1, 1, 2, 2]\n"));
    assert!(e.contains("repeats more than 1 times"), "{e}");
    let e = err(&format!("{base}weights = [1, 0, 1, 1]\n"));
    assert!(e.contains("must be positive"), "{e}");
    let e = err(&format!("{base}weights = [1, 1]\n"));
    assert!(e.contains("2 weights for 4 control points"), "{e}");
    let e = err(&format!("{base}kind = \"bezier\"\nknots = [0, 0, 0, 0, 1, 1, 1, 1]\n"));
    assert!(e.contains("a Bézier curve has no `knots`"), "{e}");
    let e = err(&format!("{base}kind = \"nurbs\"\ndegree = 4\n"));
    assert!(e.contains("degree 4 needs at least 5 control points"), "{e}");
    let sweep = "[[object]]\nshape = \"sweep\"\nguide = [[0, 0, 0], [1, 0, 0]]\n";
    let e = err(&format!("{sweep}radius = 1\nsection = [[1, 0], [0, 1]]\n"));
    assert!(e.contains("`radius` and `section` exclude each other"), "{e}");
    let e = err(&format!("{sweep}guides = [[[1, 0, 0], [1, 0, 0]]]\n"));
    assert!(e.contains("expected the three auxiliary guides"), "{e}");
    let e = err("[[object]]\nshape = \"revolution\"\nprofile = { points = [[1, 0], [-1, 1]] }\n");
    assert!(e.contains("cannot be negative"), "{e}");
    let fine = "[[object]]\nshape = \"revolution\"\nprofile = [[1, 0], [2, 1], [1, 2]]\ntolerance = 1e-9\n";
    let e = parse_scene_reporting("s.toml".as_ref(), fine, 1 << 20).unwrap_err().to_string();
    assert!(e.contains("s.toml:4:13") && e.contains("more than the memory budget of 1 MB"), "{e}");
}

#[test]
fn tolerances_that_cannot_be_reached_are_reported() {
    // A hairpin turn: the frame refines to its limit of control points and says so.
    let hairpin = "[[object]]\nname = \"hairpin\"\nshape = \"sweep\"\nguide = [[0, 0, 0], [1, 0, 0], [0, 0.001, 0]]\nradius = 0.5\ntolerance = 1e-3\n";
    let (_, warnings) = parse_scene_reporting("s.toml".as_ref(), hairpin, 1 << 34).unwrap();
    assert!(
        warnings.iter().any(|w| w.contains("hairpin") && w.contains("frame") && w.contains("not the `tolerance`")),
        "{warnings:?}"
    );
    // A tessellation finer than 1024 cells a side is not made; the shape says how close it got.
    let tiny =
        "[[object]]\nname = \"tiny\"\nshape = \"revolution\"\nprofile = [[1, 0], [2, 1], [1, 2]]\ntolerance = 1e-12\n";
    let (_, warnings) = parse_scene_reporting("s.toml".as_ref(), tiny, 1 << 34).unwrap();
    assert!(warnings.iter().any(|w| w.contains("tiny: tessellated within")), "{warnings:?}");
}
