//! The BVH must return the same nearest hit as testing every object (and the world's planar
//! primitives, tested four at a time, the same hits as the mesh triangles they stand for);
//! shadow rays must be blocked exactly when a hit is nearer than the light.

use alhazen_math::{Ray, Vec3};
use alhazen_render::World;
use alhazen_render::shape::RayPacket;
use alhazen_render::world::HitPoint;
use alhazen_scene::parse_scene;
use proptest::prelude::*;

fn random_scene(spheres: &[(f64, f64, f64, f64)], boxes: &[(f64, f64, f64)]) -> String {
    let mut s = String::from("[[object]]\nshape = \"plane\"\npoint = [0, -3, 0]\n");
    // Rectangles: small meshes the world flattens into parallelograms.
    for (k, (x, y, z, r)) in spheres.iter().enumerate().filter(|(k, _)| k % 3 == 0) {
        s += &format!(
            "[[object]]\nshape = \"rectangle\"\ntransform = [{{ scale = [{}, {r}, 1] }}, {{ rotate_x = {} }}, \
             {{ rotate_y = {} }}, {{ translate = [{x}, {y}, {z}] }}]\n",
            2.0 * r,
            17 * k,
            40 + 29 * k
        );
    }
    for (x, y, z, r) in spheres {
        s += &format!("[[object]]\nshape = \"sphere\"\ncenter = [{x}, {y}, {z}]\nradius = {r}\n");
    }
    for (x, y, z) in boxes {
        s += &format!(
            "[[object]]\nshape = \"box\"\nmin = [{x}, {y}, {z}]\nmax = [{}, {}, {}]\ntransform = [{{ rotate_y = 30 }}]\n",
            x + 0.5,
            y + 0.8,
            z + 0.3
        );
        s += &format!(
            "[[object]]\nshape = \"cylinder\"\nbase = [{x}, {y}, {z}]\ntop = [{}, {}, {}]\nradius = 0.2\n",
            x + 0.1,
            y + 1.0,
            z
        );
    }
    s
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(40))]
    #[test]
    fn bvh_equals_brute_force(
        spheres in prop::collection::vec((-5.0..5.0f64, -2.0..5.0f64, -5.0..5.0f64, 0.1..1.0f64), 1..40),
        boxes in prop::collection::vec((-5.0..5.0f64, -2.0..5.0f64, -5.0..5.0f64), 0..20),
        rays in prop::collection::vec(((-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64), (-6.0..6.0f64, -6.0..6.0f64, -6.0..6.0f64)), 50),
    ) {
        let scene = parse_scene("random.toml".as_ref(), &random_scene(&spheres, &boxes)).unwrap();
        let world = World::build(&scene);
        for ((dx, dy, dz), (ox, oy, oz)) in rays {
            let Some(d) = Vec3::new(dx, dy, dz).try_normalize() else { continue };
            let ray = Ray::new(Vec3::new(ox, oy, oz), d);
            let fast = world.intersect(&ray, f64::INFINITY).map(|h| (h.hit.t, h.hit.n));
            let slow = world.intersect_brute_force(&ray, f64::INFINITY).map(|h| (h.t, h.n));
            // A shadow ray of length 4 is blocked exactly when something is nearer.
            let dist = 4.0;
            if slow.is_none_or(|(t, _)| (t - dist).abs() > 1e-6) {
                let blocked = slow.is_some_and(|(t, _)| t < dist);
                prop_assert_eq!(world.unoccluded(ray.origin, d, dist), !blocked);
            }
            match (fast, slow) {
                (Some((t1, n1)), Some((t2, n2))) => {
                    prop_assert!((t1 - t2).abs() <= 1e-9 * (1.0 + t2), "t {} vs {}", t1, t2);
                    prop_assert!((n1 - n2).length() < 1e-9, "n {} vs {}", n1, n2);
                }
                (a, b) => prop_assert_eq!(a.is_some(), b.is_some(), "{:?} vs {:?}", a, b),
            }
        }
    }
}

/// A room of rectangles and untransformed boxes: all flats in one leaf, which the world tests
/// eight rays at a time, ray by lane.
fn flats_scene(boxes: &[(f64, f64, f64)]) -> String {
    let mut s = String::new();
    for (k, (x, y, z)) in boxes.iter().enumerate() {
        s += &format!(
            "[[object]]\nshape = \"box\"\nmin = [{x}, {y}, {z}]\nmax = [{}, {}, {}]\n",
            x + 0.7,
            y + 0.4,
            z + 0.9
        );
        s += &format!(
            "[[object]]\nshape = \"rectangle\"\ntransform = [{{ scale = 2 }}, {{ rotate_x = {} }}, {{ translate = [{z}, {x}, {y}] }}]\n",
            23 * k
        );
    }
    s
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(40))]
    /// Eight rays at once meet what each meets alone, in a world of flats in one leaf and in a
    /// general one; shadow rays likewise; rays not live meet nothing.
    #[test]
    fn eight_rays_meet_what_each_meets_alone(
        spheres in prop::collection::vec((-5.0..5.0f64, -2.0..5.0f64, -5.0..5.0f64, 0.1..1.0f64), 1..10),
        boxes in prop::collection::vec((-3.0..3.0f64, -3.0..3.0f64, -3.0..3.0f64), 1..4),
        rays in prop::collection::vec(((-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64), (-4.0..4.0f64, -4.0..4.0f64, -4.0..4.0f64), 0.5..8.0f64, any::<bool>()), 8),
    ) {
        for text in [flats_scene(&boxes), random_scene(&spheres, &boxes)] {
            let world = World::build(&parse_scene("rays.toml".as_ref(), &text).unwrap());
            let dir = |i: usize| Vec3::new(rays[i].0.0, rays[i].0.1, rays[i].0.2).try_normalize().unwrap_or(Vec3::Z);
            let mut all = RayPacket::default();
            (0..8).for_each(|i| all.set(i, &Ray::new(Vec3::new(rays[i].1.0, rays[i].1.1, rays[i].1.2), dir(i))));
            let (dist, live): ([f64; 8], [bool; 8]) = (std::array::from_fn(|i| rays[i].2), std::array::from_fn(|i| rays[i].3));
            let mut hits = [None; 8];
            world.intersect_rays(&all, live, &mut hits);
            let clear = world.unoccluded_rays(&all, &dist, live);
            for i in 0..8 {
                let ray = &all.ray(i);
                let alone = world.intersect(ray, f64::INFINITY).filter(|_| live[i]);
                prop_assert_eq!(hits[i].map(HitPoint::from), alone.map(HitPoint::from));
                prop_assert_eq!(clear[i], live[i] && world.unoccluded(ray.origin, ray.dir, dist[i]));
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    /// A mesh's hierarchy built in Morton order meets what the SAH-built one meets: the nearest
    /// hit's distance and triangle, ray by ray.
    #[test]
    fn a_morton_built_mesh_meets_what_the_sah_built_one_does(
        seed in 0u64..1_000_000,
        rays in prop::collection::vec(((-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64), (-3.0..3.0f64, -3.0..3.0f64, -3.0..3.0f64)), 32),
    ) {
        // A random soup of 600 small triangles (more than a mesh baked into the world).
        let mesh = triangle_soup(seed, 600);
        let unit = alhazen_render::shape::VectorUnit::detect();
        let shape = |method| alhazen_render::shape::MeshShape {
            accel: std::sync::Arc::new(alhazen_render::shape::MeshAccel::with_build(mesh.clone(), unit, method)),
            smooth: false,
            alpha: None,
        };
        let (sah, morton) = (shape(alhazen_render::bvh::BuildMethod::Sah), shape(alhazen_render::bvh::BuildMethod::Morton));
        for (d, o) in &rays {
            let dir = Vec3::new(d.0, d.1, d.2).try_normalize().unwrap_or(Vec3::Z);
            let ray = Ray::new(Vec3::new(o.0, o.1, o.2), dir);
            let (a, b) = (sah.hit(&ray, f64::INFINITY), morton.hit(&ray, f64::INFINITY));
            prop_assert_eq!(a.map(|c| (c.t, c.aux)), b.map(|c| (c.t, c.aux)));
        }
    }
}

/// A soup of small triangles, without texture coordinates (a hit's are its barycentrics).
fn triangle_soup(seed: u64, count: u32) -> std::sync::Arc<alhazen_geom::TriangleMesh> {
    let mut state = seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    let mut positions = vec![];
    for _ in 0..count {
        let c = Vec3::new(next(), next(), next()) * 2.0;
        positions.extend([c, c + Vec3::new(next(), next(), next()) * 0.3, c + Vec3::new(next(), next(), next()) * 0.3]);
    }
    let triangles = (0..count).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect();
    std::sync::Arc::new(alhazen_geom::TriangleMesh::new(positions, triangles).unwrap())
}

/// `mesh` with every triangle cut out by `alpha`, and without.
fn cut_and_whole(
    mesh: &std::sync::Arc<alhazen_geom::TriangleMesh>,
    alpha: alhazen_scene::Alpha,
) -> (alhazen_render::shape::MeshShape, alhazen_render::shape::MeshShape) {
    use alhazen_render::shape::{AlphaMask, MeshAccel, MeshShape};
    let accel = std::sync::Arc::new(MeshAccel::new(mesh.clone()));
    let mask = std::sync::Arc::new(AlphaMask::uniform(alpha, vec![]));
    let cut = MeshShape { accel: accel.clone(), smooth: false, alpha: Some(mask) };
    (cut, MeshShape { accel, smooth: false, alpha: None })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// A mesh with cut-outs: its hit is the nearest hit the mask keeps — the whole mesh's own
    /// when that one is kept, never nearer, always kept — and a shadow ray is blocked exactly
    /// when there is such a hit; with a cutoff and with a coverage decided ray by ray.
    #[test]
    fn cut_out_meshes_hit_the_nearest_covered_triangle(
        seed in 0u64..1_000_000,
        cutoff in prop::option::of(0.3..0.9f64),
        rays in prop::collection::vec(((-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64), (-3.0..3.0f64, -3.0..3.0f64, -3.0..3.0f64), 0.5..8.0f64), 32),
    ) {
        let mesh = triangle_soup(seed, 400);
        let (even, odd) = (Vec3::ONE, Vec3::splat(0.5));
        let coverage = alhazen_scene::Texture::Checker { even, odd, size: 0.2 };
        let (cut, whole) = cut_and_whole(&mesh, alhazen_scene::Alpha { coverage, cutoff });
        let mask = cut.alpha.clone().unwrap();
        for (d, o, t_max) in &rays {
            let dir = Vec3::new(d.0, d.1, d.2).try_normalize().unwrap_or(Vec3::Z);
            let ray = Ray::new(Vec3::new(o.0, o.1, o.2), dir);
            for t_max in [f64::INFINITY, *t_max] {
                let (kept, nearest) = (cut.hit(&ray, t_max), whole.hit(&ray, t_max));
                prop_assert_eq!(cut.blocks(&ray, t_max), kept.is_some());
                if let Some(k) = kept {
                    prop_assert!(mask.covers(&mesh, &k, &ray));
                    prop_assert!(k.t >= nearest.unwrap().t);
                }
                if let Some(n) = nearest.filter(|n| mask.covers(&mesh, n, &ray)) {
                    prop_assert_eq!(kept.map(|k| (k.t, k.aux)), Some((n.t, n.aux)));
                }
            }
        }
    }
}

/// A coverage of 0.3 without cutoff stops three rays in ten (the hash's decisions are
/// independent of the rays' layout): 20 000 rays through a square, within five standard
/// deviations of the binomial.
#[test]
fn a_partial_coverage_stops_its_fraction_of_the_rays() {
    let positions = vec![
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(1.0, 1.0, 0.0),
        Vec3::new(-1.0, 1.0, 0.0),
    ];
    let mesh = std::sync::Arc::new(alhazen_geom::TriangleMesh::new(positions, vec![[0, 1, 2], [0, 2, 3]]).unwrap());
    let coverage = alhazen_scene::Texture::Solid(Vec3::splat(0.3));
    let (cut, _) = cut_and_whole(&mesh, alhazen_scene::Alpha { coverage, cutoff: None });
    let n = 20_000;
    let stopped = (0..n)
        .filter(|&i| {
            let (x, y) = ((i % 200) as f64 / 200.0 - 0.5, (i / 200) as f64 / 100.0 - 0.5);
            let ray = Ray::new(Vec3::new(x, y, 2.0), Vec3::new(0.01 * x, 0.0, -1.0).normalize());
            cut.hit(&ray, f64::INFINITY).is_some()
        })
        .count();
    let (mean, sd) = (0.3 * n as f64, (n as f64 * 0.3 * 0.7).sqrt());
    assert!((stopped as f64 - mean).abs() < 5.0 * sd, "{stopped} of {n} stopped, expected {mean} ± {sd}");
}
