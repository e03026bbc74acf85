//! Property tests of the shapes: hits lie on the surface, normals are unit and outward, CSG
//! keeps only the boundary of the combined set, transformed shapes agree with direct ones.

use super::*;
use alhazen_scene::CsgOp;
use proptest::prelude::*;
use std::sync::Arc;

fn arb_dir() -> impl Strategy<Value = Vec3> {
    (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64)
        .prop_filter_map("non-zero", |(x, y, z)| Vec3::new(x, y, z).try_normalize())
}

fn arb_point(r: f64) -> impl Strategy<Value = Vec3> {
    (-r..r, -r..r, -r..r).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

/// A ray from far away aimed near the origin.
fn arb_ray() -> impl Strategy<Value = Ray> {
    (arb_dir(), arb_point(0.8)).prop_map(|(d, aim)| Ray::new(aim - d * 6.0, d))
}

fn unit_box_mesh() -> Arc<MeshAccel> {
    let cube = alhazen_geom::halfedge::HalfedgeMesh::cube();
    Arc::new(MeshAccel::new(Arc::new(alhazen_geom::tessellate::polygons_to_triangles(&cube))))
}

/// Signed distance-like implicit functions: zero on the surface.
/// A function that vanishes on a shape's surface.
type Implicit = Box<dyn Fn(Vec3) -> f64>;

fn shapes_with_implicit() -> Vec<(Shape, Implicit)> {
    let cyl_axis = |p: Vec3| Vec2::new(p.x, p.z).length();
    vec![
        (
            Shape::Sphere(Sphere::new(Vec3::new(0.1, 0.2, 0.0), 1.0)),
            Box::new(|p: Vec3| (p - Vec3::new(0.1, 0.2, 0.0)).length() - 1.0),
        ),
        (
            Shape::Cylinder(Cylinder::new(Vec3::new(0.0, -1.0, 0.0), Vec3::new(0.0, 1.0, 0.0), 0.7, true)),
            Box::new(move |p: Vec3| {
                let side = (cyl_axis(p) - 0.7).abs().max(if p.y.abs() <= 1.0 + 1e-9 { 0.0 } else { 1.0 });
                let cap = (p.y.abs() - 1.0).abs().max(if cyl_axis(p) <= 0.7 + 1e-9 { 0.0 } else { 1.0 });
                side.min(cap)
            }),
        ),
        (
            Shape::Cone(Cone::new(Vec3::new(0.0, -1.0, 0.0), Vec3::new(0.0, 1.0, 0.0), 1.0, true)),
            Box::new(move |p: Vec3| {
                let r = (1.0 - p.y) / 2.0;
                let side = (cyl_axis(p) - r).abs().max(if (-1.0 - 1e-9..=1.0).contains(&p.y) { 0.0 } else { 1.0 });
                let cap = (p.y + 1.0).abs().max(if cyl_axis(p) <= 1.0 + 1e-9 { 0.0 } else { 1.0 });
                side.min(cap)
            }),
        ),
        (
            Shape::Box(AaBox { min: Vec3::splat(-0.9), max: Vec3::new(0.9, 0.5, 0.7) }),
            Box::new(|p: Vec3| {
                let q = (p - Vec3::new(0.0, -0.2, -0.1)).abs() - Vec3::new(0.9, 0.7, 0.8);
                q.max_element()
            }),
        ),
        (
            Shape::Mesh(MeshShape { accel: unit_box_mesh(), smooth: false, alpha: None }),
            Box::new(|p: Vec3| p.abs().max_element() - 1.0),
        ),
        (
            Shape::Disk(Disk { center: Vec3::ZERO, normal: Vec3::Y, radius: 1.0 }),
            Box::new(|p: Vec3| p.y.abs().max((p.length() - 1.0).max(0.0))),
        ),
        (
            Shape::Plane(Plane { point: Vec3::ZERO, normal: Vec3::new(0.0, 0.6, 0.8) }),
            Box::new(|p: Vec3| p.dot(Vec3::new(0.0, 0.6, 0.8))),
        ),
    ]
}

/// A soup of `n` triangles in the unit cube; every third pair of triangles a parallelogram.
fn arb_soup(n: usize) -> impl Strategy<Value = alhazen_geom::TriangleMesh> {
    prop::collection::vec(arb_point(1.0), 3 * n).prop_map(|mut positions| {
        let mut triangles = vec![];
        for k in (0..positions.len()).step_by(6) {
            let k = k as u32;
            if k.is_multiple_of(18) {
                // Corners a, b, d and c = b + d − a: triangles [a, b, c], [a, c, d] tile a parallelogram.
                let (a, b, d) = (positions[k as usize], positions[k as usize + 1], positions[k as usize + 2]);
                positions[k as usize + 3] = b + d - a;
                triangles.extend([[k, k + 1, k + 3], [k, k + 3, k + 2]]);
            } else {
                triangles.extend([[k, k + 1, k + 2], [k + 3, k + 4, k + 5]]);
            }
        }
        alhazen_geom::TriangleMesh { positions, triangles, ..Default::default() }
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn hits_lie_on_the_surface_with_unit_normals(ray in arb_ray()) {
        for (shape, f) in shapes_with_implicit() {
            // Meshes' flats are tested in single precision (`FlatPacket`): their hits are good
            // to a few units of 2⁻²⁴ of the ray's length.
            let tolerance = if matches!(shape, Shape::Mesh(_)) { 1e-6 } else { 1e-9 };
            if let Some(h) = shape.intersect(&ray, f64::INFINITY) {
                prop_assert!(f(h.p).abs() < tolerance, "{shape:?}: f = {}", f(h.p));
                let along = if tolerance > 1e-9 { tolerance } else { 1e-12 };
                prop_assert!((h.p - ray.at(h.t)).length() < along);
                prop_assert!((h.n.length() - 1.0).abs() < 1e-9);
                prop_assert!(h.t > 0.0);
            }
        }
    }

    #[test]
    fn closed_shapes_enter_against_and_leave_along_the_normal(ray in arb_ray()) {
        for (shape, _) in shapes_with_implicit() {
            let mut cs = Vec::new();
            shape.crossings(&ray, &mut cs);
            prop_assert!(cs.len() % 2 == 0);
            for c in &cs {
                prop_assert_eq!(c.entering, c.hit.n.dot(ray.dir) < 0.0, "{:?}", shape);
            }
        }
    }

    #[test]
    fn transforms_preserve_hits(ray in arb_ray(), t in arb_point(2.0), angle in 0.0..6.0f64, axis in arb_dir(), s in 0.5..2.0f64) {
        // A unit sphere transformed equals the sphere with transformed centre and radius.
        let tf = Transform::translate(t) * Transform::rotate(axis, angle) * Transform::scale(Vec3::splat(s));
        let placed = Placed::new(Shape::Sphere(Sphere::new(Vec3::ZERO, 1.0)), tf);
        let direct = Sphere::new(t, s);
        let a = placed.intersect(&ray, f64::INFINITY);
        let b = Shape::Sphere(direct).intersect(&ray, f64::INFINITY);
        prop_assert_eq!(a.is_some(), b.is_some());
        if let (Some(a), Some(b)) = (a, b) {
            prop_assert!((a.t - b.t).abs() < 1e-9);
            prop_assert!((a.n - b.n).length() < 1e-9);
        }
    }

    /// A sphere placed by a similarity in world space (`Sphere::placed`, packed like any other)
    /// has the transformed sphere's hits, texture coordinates and tangents.
    #[test]
    fn placed_spheres_keep_their_parametrisation(
        ray in arb_ray(), t in arb_point(2.0), angle in 0.0..6.0f64, axis in arb_dir(), s in 0.5..2.0f64, c in arb_point(0.5),
    ) {
        let tf = Transform::translate(t) * Transform::rotate(axis, angle) * Transform::scale(Vec3::splat(s));
        let transformed = Placed::new(Shape::Sphere(Sphere::new(c, 0.7)), tf);
        let world = Placed::new(Shape::Sphere(Sphere::placed(c, 0.7, &tf).unwrap()), Transform::IDENTITY);
        prop_assert!(world.to_world.is_none());
        let (Some(a), Some(b)) = (transformed.hit(&ray, f64::INFINITY), world.hit(&ray, f64::INFINITY)) else {
            prop_assert_eq!(transformed.hit(&ray, f64::INFINITY).is_some(), world.hit(&ray, f64::INFINITY).is_some());
            return Ok(());
        };
        let (sa, sb) = (transformed.surface(&ray, a), world.surface(&ray, b));
        prop_assert!((sa.p - sb.p).length() < 1e-9 && (sa.n - sb.n).length() < 1e-9);
        // u wraps at the seam; away from the poles, where it is defined.
        let du = (sa.uv.x - sb.uv.x).abs();
        prop_assume!(sa.n.dot(tf.vector(Vec3::Y)).abs() < 0.99 * s);
        prop_assert!(du.min(1.0 - du) < 1e-7 && (sa.uv.y - sb.uv.y).abs() < 1e-7, "{:?} vs {:?}", sa.uv, sb.uv);
        for (da, db) in transformed.tangents(&ray, a).into_iter().zip(world.tangents(&ray, b)) {
            prop_assert!((da - db).length() < 1e-7 * (1.0 + da.length()), "{da} vs {db}");
        }
    }

    /// A mesh blocks a segment exactly when its nearest hit lies on it, whatever the segment's
    /// length (the any-hit traversal stops early but must not decide differently).
    #[test]
    fn mesh_blocks_where_it_is_hit(mesh in arb_soup(150), ray in arb_ray(), reach in 0.0..1.5f64) {
        let shape = MeshShape { accel: Arc::new(MeshAccel::new(Arc::new(mesh))), smooth: false, alpha: None };
        let t_max = shape.hit(&ray, f64::INFINITY).map_or(10.0, |c| c.t * 2.0 * reach);
        prop_assert_eq!(shape.blocks(&ray, t_max), shape.hit(&ray, t_max).is_some(), "t_max {}", t_max);
    }

    /// The mesh's packets of flats find what Möller–Trumbore over every triangle finds.
    #[test]
    fn mesh_packets_agree_with_every_triangle(mesh in arb_soup(150), ray in arb_ray()) {
        let mesh = Arc::new(mesh);
        let shape = MeshShape { accel: Arc::new(MeshAccel::new(mesh.clone())), smooth: false, alpha: None };
        let brute = (0..mesh.triangle_count())
            .filter_map(|i| mesh::triangle_hit(&ray, mesh.corners(i)).filter(|h| h.0 > 0.0).map(|h| (h.0, i)))
            .min_by(|a, b| a.0.total_cmp(&b.0));
        let hit = shape.hit(&ray, f64::INFINITY);
        // The packets test in single precision: they may differ from the double-precision test
        // only where the ray passes within 2⁻¹⁶ of an edge (in barycentric units).
        let near_edge = |i: usize| {
            let [p0, p1, p2] = mesh.corners(i);
            let (e1, e2, to) = (p1 - p0, p2 - p0, ray.origin - p0);
            let det = e1.dot(ray.dir.cross(e2));
            let (b1, b2) = (to.dot(ray.dir.cross(e2)) / det, ray.dir.dot(to.cross(e1)) / det);
            b1.min(b2).min(1.0 - b1 - b2).abs() < 1.5e-5
        };
        if hit.is_some() != brute.is_some() {
            let missed = brute.map_or_else(|| hit.unwrap().aux as usize, |(_, i)| i);
            prop_assert!(near_edge(missed), "{:?} vs {:?}", hit, brute);
            return Ok(());
        }
        if let (Some(c), Some((t, i))) = (hit, brute) {
            if c.aux as usize != i && near_edge(i) {
                return Ok(());
            }
            prop_assert!((c.t - t).abs() <= 1e-5 * (1.0 + t), "t {} vs {}", c.t, t);
            let s = shape.surface_at(c);
            prop_assert!((s.p - ray.at(t)).length() < 1e-5);
            // The same triangle unless another lies (almost) as near.
            let near: Vec<usize> = (0..mesh.triangle_count())
                .filter(|&j| mesh::triangle_hit(&ray, mesh.corners(j)).is_some_and(|h| (h.0 - t).abs() < 1e-5 * (1.0 + t)))
                .collect();
            prop_assert!(c.aux as usize == i || near.contains(&(c.aux as usize)));
        }
    }

    #[test]
    fn csg_difference_is_a_minus_b(ray in arb_ray()) {
        // Unit sphere minus a sphere of radius 0.6 centred at (0.7, 0, 0): a hit belongs to the
        // boundary of A − B: on A's surface outside B, or on B's surface inside A.
        let a = Placed::new(Shape::Sphere(Sphere::new(Vec3::ZERO, 1.0)), Transform::IDENTITY);
        let b = Placed::new(Shape::Sphere(Sphere::new(Vec3::new(0.7, 0.0, 0.0), 0.6)), Transform::IDENTITY);
        let csg = Csg { op: CsgOp::Difference, a, b };
        if let Some(h) = csg.intersect(&ray, f64::INFINITY) {
            let (da, db) = (h.p.length(), (h.p - Vec3::new(0.7, 0.0, 0.0)).length());
            let on_a = (da - 1.0).abs() < 1e-9 && db >= 0.6 - 1e-9;
            let on_b = (db - 0.6).abs() < 1e-9 && da <= 1.0 + 1e-9;
            prop_assert!(on_a || on_b);
            // The normal points out of A − B: into B on B's surface.
            if on_b && !on_a {
                prop_assert!(h.n.dot(h.p - Vec3::new(0.7, 0.0, 0.0)) < 0.0);
            }
            // Nothing of A − B lies before the hit: sample the segment.
            for k in 1..50 {
                let q = ray.at(h.t * k as f64 / 50.0);
                let inside = q.length() < 1.0 && (q - Vec3::new(0.7, 0.0, 0.0)).length() > 0.6;
                prop_assert!(!inside || h.t < 1e-9);
            }
        }
    }
}

#[test]
fn csg_union_and_intersection_of_overlapping_balls() {
    let ball = |x: f64| Placed::new(Shape::Sphere(Sphere::new(Vec3::new(x, 0.0, 0.0), 1.0)), Transform::IDENTITY);
    let ray = Ray::new(Vec3::new(-5.0, 0.0, 0.0), Vec3::X);
    let union = Csg { op: CsgOp::Union, a: ball(-0.5), b: ball(0.5) };
    let inter = Csg { op: CsgOp::Intersection, a: ball(-0.5), b: ball(0.5) };
    let (mut cu, mut ci) = (vec![], vec![]);
    union.crossings(&ray, &mut cu);
    inter.crossings(&ray, &mut ci);
    // Regularised union: the inner surfaces vanish; only x = −1.5 and x = 1.5 remain.
    assert_eq!(cu.iter().map(|c| c.hit.p.x).collect::<Vec<_>>(), vec![-1.5, 1.5]);
    assert_eq!(ci.iter().map(|c| c.hit.p.x).collect::<Vec<_>>(), vec![-0.5, 0.5]);
    // A ray starting inside the union leaves at 1.5.
    let inside = Ray::new(Vec3::ZERO, Vec3::X);
    assert_eq!(union.intersect(&inside, f64::INFINITY).unwrap().p.x, 1.5);
}

#[test]
fn open_cylinder_is_seen_from_inside() {
    let c = Shape::Cylinder(Cylinder::new(Vec3::ZERO, Vec3::Y, 1.0, false));
    let ray = Ray::new(Vec3::new(0.0, 2.0, 0.0), Vec3::new(0.1, -1.0, 0.0).normalize());
    let h = c.intersect(&ray, f64::INFINITY);
    assert!(h.is_none(), "the ray goes down the open tube and misses both walls above y=0");
    let ray = Ray::new(Vec3::new(0.0, 0.5, 0.0), Vec3::X);
    let h = c.intersect(&ray, f64::INFINITY).unwrap();
    assert!((h.p.x - 1.0).abs() < 1e-12 && h.n.x > 0.0, "outward normal even when hit from inside");
}

#[test]
fn tangents_are_the_derivatives_of_the_texture_parametrisation() {
    // Two nearby hits: p₂ − p₁ ≈ ∂p/∂u Δu + ∂p/∂v Δv.
    let sphere = Shape::Sphere(Sphere::new(Vec3::new(0.1, 0.2, -0.3), 1.3));
    let plane = Shape::Plane(Plane { point: Vec3::new(0.0, -1.0, 0.0), normal: Vec3::new(0.2, 1.0, 0.1).normalize() });
    let mesh = Shape::Mesh(MeshShape { accel: unit_box_mesh(), smooth: false, alpha: None });
    for shape in [sphere, plane, mesh] {
        let origin = Vec3::new(0.3, 4.0, 3.0);
        let target = Vec3::new(0.2, -0.1, 0.15);
        // A step the mesh's single-precision hits resolve (its parametrisation is linear).
        let d = if matches!(shape, Shape::Mesh(_)) { 1e-3 } else { 1e-5 };
        let ray = Ray::new(origin, (target - origin).normalize());
        let c = shape.hit(&ray, f64::INFINITY).unwrap();
        let a = shape.surface(&ray, c);
        let [dpdu, dpdv] = shape.tangents(&ray, c);
        let b = shape
            .intersect(&Ray::new(origin, (target + Vec3::new(d, 0.0, d) - origin).normalize()), f64::INFINITY)
            .unwrap();
        let predicted = dpdu * (b.uv.x - a.uv.x) + dpdv * (b.uv.y - a.uv.y);
        let moved = b.p - a.p;
        assert!((predicted - moved).length() < 1e-3 * moved.length(), "{shape:?}: {predicted} vs {moved}");
    }
}

#[test]
fn spheres_seen_from_far_away_are_hit_on_their_surface() {
    // β² − ac would cancel: rays from 10⁴–10⁶ away used to land 10⁻⁸ off the surface (shadow
    // acne in axonometric views, whose rays start 10⁴ units back).
    let s = Sphere::new(Vec3::new(0.3, 0.8, -0.2), 0.8);
    for dist in [1e4, 1e5, 1e6] {
        for k in 0..50 {
            let off = Vec3::new((k as f64 * 0.37).sin(), (k as f64 * 0.71).cos(), (k as f64 * 0.13).sin()) * 0.5;
            let origin = s.center + Vec3::new(1.0, 0.7, 0.4).normalize() * dist;
            let ray = Ray::new(origin, (s.center + off - origin).normalize());
            let h = Shape::Sphere(s).intersect(&ray, f64::INFINITY).unwrap();
            let miss = ((h.p - s.center).length() - s.radius).abs();
            assert!(miss < 1e-14 * dist, "{dist}: {miss}");
        }
    }
}

#[test]
fn cylinders_and_cones_seen_from_far_away_are_hit_on_their_surface() {
    // As for spheres: |op|² − r² cancelled for far origins (noisy self-shadowing of cylinders in
    // a military axonometry before session 3).
    let (base, top, r) = (Vec3::new(0.2, 0.0, -0.1), Vec3::new(0.2, 2.0, -0.1), 0.6);
    let cyl = Shape::Cylinder(Cylinder::new(base, top, r, false));
    let cone = Shape::Cone(Cone::new(base, top, r, false));
    let on_cylinder = |p: Vec3| (Vec2::new(p.x - base.x, p.z - base.z).length() - r).abs();
    let on_cone = |p: Vec3| (Vec2::new(p.x - base.x, p.z - base.z).length() - r * (1.0 - (p.y - base.y) / 2.0)).abs();
    for dist in [1e4, 1e5] {
        for k in 0..50 {
            let aim =
                base + Vec3::new(0.25 * (k as f64 * 0.37).sin(), 0.2 + 0.02 * k as f64, 0.1 * (k as f64 * 0.13).cos());
            let origin = aim + Vec3::new(1.0, 0.7, 0.4).normalize() * dist;
            let ray = Ray::new(origin, (aim - origin).normalize());
            for (shape, miss) in [(&cyl, &on_cylinder as &dyn Fn(Vec3) -> f64), (&cone, &on_cone)] {
                if let Some(h) = shape.intersect(&ray, f64::INFINITY) {
                    assert!(miss(h.p) < 1e-14 * dist, "{shape:?} {dist}: {}", miss(h.p));
                }
            }
        }
    }
}

/// A mesh's tree and packets, built on several threads, are those one thread builds.
#[test]
fn mesh_packs_the_same_on_any_number_of_threads() {
    let mut rng = crate::sampler::Rng::for_sample(23, 0, 0, 0);
    let mut next = || rng.uniform();
    // Small triangles scattered in a cube, with parallelograms among them.
    let mut positions = vec![];
    for _ in 0..20_000 {
        let a = alhazen_math::Vec3::new(next(), next(), next()) * 50.0;
        let (b, d) =
            (a + alhazen_math::Vec3::new(next(), next(), 0.1), a + alhazen_math::Vec3::new(0.1, next(), next()));
        let c = if next() < 0.3 { b + d - a } else { a + alhazen_math::Vec3::new(next(), 0.2, next()) };
        positions.extend([a, b, c, d]);
    }
    let triangles =
        (0..20_000u32).flat_map(|k| [[4 * k, 4 * k + 1, 4 * k + 2], [4 * k, 4 * k + 2, 4 * k + 3]]).collect();
    let mesh = Arc::new(alhazen_geom::TriangleMesh { positions, triangles, ..Default::default() });
    let build = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        let accel =
            pool.install(|| crate::shape::MeshAccel::with_unit(mesh.clone(), crate::shape::VectorUnit::PORTABLE));
        format!("{accel:?}")
    };
    let one = build(1);
    assert!(one.len() > 1_000_000, "a mesh big enough to be built in parallel");
    assert_eq!(one, build(3));
}
