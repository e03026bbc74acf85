//! How often the path tracer's light samples choose each light, measured
//! ([`alhazen_scene::LightChoice::Measured`]): a pilot pass follows camera rays through a grid
//! over the film to the surfaces they meet and there draws one point of every light, shadow ray
//! and all, so each light's share of the direct light on what the camera sees is known before
//! the first sample. The measures are summed cell by cell of a grid over those surfaces, and a
//! light sample drawn from a point chooses lights in proportion to its cell's sums (blended
//! with the whole image's where the cell holds few points), so the lamp overhead is chosen in
//! its stretch of a corridor and the next lamp in the next — in spirit the spatial light
//! choice of Cycles' and pbrt-v4's light trees, measured rather than bounded, shadows
//! included —, mixed with a uniform share. Choosing lights by an estimate of their
//! contribution is Shirley, Wang and Zimmerman's (1996, "Monte Carlo techniques for direct
//! lighting calculations", §4); the uniform share is Hesterberg's defensive mixture, so a
//! light the pilot saw little of (one that lights only what mirrors or later bounces show)
//! keeps samples; with thousands of lights the pilot's points per light are fewer and that
//! share grows. A lamp behind a wall, which power alone would choose most, is chosen least.
//!
//! The pass is a pure function of the scene and camera (its own fixed numbers, not the
//! render's seed): every band, pass and checkpoint of one image chooses alike.

use crate::bsdf::{ColorMode, bsdf_at};
use crate::camera::Camera;
use crate::lights::{Cells, ChoiceTable, Lights, UNIFORM_SHARE, unless_uniform};
use crate::path::shadow_segment;
use crate::sampler::Rng;
use crate::world::World;
use alhazen_math::{Vec2, Vec3};
use alhazen_scene::Scene;
use rayon::prelude::*;

/// The pilot's measures weigh all the choice but [`UNIFORM_SHARE`] where it has at least this
/// many points; with fewer (thousands of lights), each light's measure is noisier and their
/// weight shrinks in proportion, to none at none.
const TRUSTED_POINTS: u32 = 256;
/// A cell's measures are blended with this many points' worth of the mean point's, so that a
/// cell of few points keeps near the whole image's choice.
const PRIOR: f64 = 4.0;
/// At most this many cells along the longest extent of the surfaces the pilot met…
const CELLS_ALONG: u32 = 8;
/// …and, on average, at least this many points per cell…
const POINTS_PER_CELL: f64 = 8.0;
/// …and at most this many probabilities in the table (cells × lights).
const TABLE_ENTRIES: usize = 1 << 20;
/// The grid spans the points but this share of the outermost at each end of each axis.
const OUTLIERS: f64 = 0.02;
/// The pilot's grid is at most this many points along each side of the film…
const GRID: u32 = 64;
/// …and its shadow rays at most this many in all (fewer points for many lights).
const SHADOW_RAYS: u64 = 1 << 18;
/// The pilot's numbers (any fixed seed).
const PILOT_SEED: u64 = 0x6c69_6768_7473;

/// How often to choose each of `lights`' [`Lights::choices`], by the direct light each sends to
/// the surfaces `camera` sees in `world` (of `scene`), cell by cell of a grid over those
/// surfaces; `None` where that is equally often, where there is no choice to make, or where
/// the pilot saw no light at all.
pub fn measured_choice(scene: &Scene, world: &World, camera: &Camera, lights: &Lights) -> Option<ChoiceTable> {
    let n = lights.choices();
    if n < 2 {
        return None;
    }
    let (columns, rows) = grid(camera, n);
    // Light reaches a surface that lets it through (glass, a translucent sheet) from either side.
    let through: Vec<bool> = (scene.materials.iter())
        .map(|m| bsdf_at(m, Vec2::ZERO, Vec3::ONE, &scene.images, ColorMode::Rgb).transmits())
        .collect();
    let pilot = Pilot { world, camera, lights, through: &through, grid: (columns, rows) };
    let per_row: Vec<Vec<Measure>> = (0..rows).into_par_iter().map(|y| pilot.row(y)).collect();
    let measures: Vec<Measure> = per_row.into_iter().flatten().collect();
    let mut sent = vec![0.0; n];
    for m in &measures {
        sent.iter_mut().zip(&m.sent).for_each(|(s, r)| *s += r);
    }
    let total: f64 = sent.iter().sum();
    if !(total > 0.0 && total.is_finite()) {
        return None;
    }
    let trust = (1.0 - UNIFORM_SHARE) * (columns * rows).min(TRUSTED_POINTS) as f64 / TRUSTED_POINTS as f64;
    let mix = |sent: &[f64]| -> Vec<f64> {
        let total: f64 = sent.iter().sum();
        sent.iter().map(|s| trust * s / total + (1.0 - trust) / n as f64).collect()
    };
    let cells = cells_of(&measures, n);
    if cells == Cells::ONE {
        return unless_uniform(mix(&sent)).map(ChoiceTable::everywhere);
    }
    // Each cell's sums, and a prior of `PRIOR` points of the mean point's.
    let prior: Vec<f64> = sent.iter().map(|s| s * PRIOR / measures.len() as f64).collect();
    let mut sums: Vec<f64> = (0..cells.count()).flat_map(|_| prior.iter().copied()).collect();
    for m in &measures {
        let cell = cells.index(m.p) * n;
        sums[cell..cell + n].iter_mut().zip(&m.sent).for_each(|(s, r)| *s += r);
    }
    Some(ChoiceTable::in_cells(sums.chunks(n).flat_map(mix).collect(), cells))
}

/// A grid over the points the pilot measured: up to [`CELLS_ALONG`] cells along their longest
/// extent (fewer for fewer points: [`POINTS_PER_CELL`] or more on average, were they filling
/// it), as many along the others as keeps cells near cubes, and at most [`TABLE_ENTRIES`]
/// probabilities in all for `n` lights; one cell where the points are few or all in one place.
fn cells_of(measures: &[Measure], n: usize) -> Cells {
    // The box of all but the outermost points along each axis: a ground plane met near the
    // horizon would stretch the whole box and coarsen the cells near the camera (points
    // beyond the box take the nearest cell).
    // Each axis's coordinates sorted once, both ends read off them.
    let ends: [(f64, f64); 3] = std::array::from_fn(|axis| {
        let mut at: Vec<f64> = measures.iter().map(|m| m.p[axis]).collect();
        at.sort_by(f64::total_cmp);
        let quantile = |q: f64| at.get(((at.len().max(1) - 1) as f64 * q).round() as usize).copied().unwrap_or(0.0);
        (quantile(OUTLIERS), quantile(1.0 - OUTLIERS))
    });
    let (lo, hi) = (Vec3::from_array(ends.map(|e| e.0)), Vec3::from_array(ends.map(|e| e.1)));
    let extent = hi - lo;
    let longest = extent.max_element();
    let by_points = (measures.len() as f64 / POINTS_PER_CELL).cbrt();
    let by_table = (TABLE_ENTRIES as f64 / n as f64).cbrt();
    let along = by_points.min(by_table).min(CELLS_ALONG as f64).floor().max(1.0) as u32;
    if along == 1 || !(longest > 0.0 && longest.is_finite()) {
        return Cells::ONE;
    }
    let res = extent.to_array().map(|e| ((e / longest * along as f64).ceil() as u32).clamp(1, along));
    let scale =
        Vec3::from_array(std::array::from_fn(|a| if extent[a] > 0.0 { res[a] as f64 / extent[a] } else { 0.0 }));
    Cells { min: lo, scale, res }
}

/// What the pilot measured at one point: where, and the irradiance each light sends there.
struct Measure {
    p: Vec3,
    sent: Vec<f64>,
}

/// The pilot grid's columns and rows for `lights` lights: at most [`GRID`] a side, no more
/// than the film's pixels, and within [`SHADOW_RAYS`].
fn grid(camera: &Camera, lights: usize) -> (u32, u32) {
    let points = (SHADOW_RAYS / lights as u64).clamp(16, (GRID * GRID) as u64);
    let side = (points as f64).sqrt() as u32;
    (side.min(camera.film_width).max(1), side.min(camera.film_height).max(1))
}

/// The pilot pass over `grid` (columns, rows) of the film; `through[m]`: material `m` lets
/// light through.
struct Pilot<'a> {
    world: &'a World,
    camera: &'a Camera,
    lights: &'a Lights,
    through: &'a [bool],
    grid: (u32, u32),
}

impl Pilot<'_> {
    /// Row `y` of the grid: what each light sends to the points its cells' camera rays meet
    /// (irradiance on the side the camera sees — either side where the surface lets light
    /// through —, shadowed).
    fn row(&self, y: u32) -> Vec<Measure> {
        let Pilot { world, camera, lights, through, grid: (columns, rows) } = *self;
        let mut measures = Vec::new();
        let (w, h) = (camera.film_width as f64, camera.film_height as f64);
        for x in 0..columns {
            let mut rng = Rng::for_sample(PILOT_SEED, x, y, 0);
            let fx = (x as f64 + rng.uniform()) * w / columns as f64;
            let fy = (y as f64 + rng.uniform()) * h / rows as f64;
            let column = (fx as u32).min(camera.film_width - 1);
            let ray = camera.pixel_ray(column, fx, fy);
            let Some(hit) = world.intersect(&ray, f64::INFINITY) else { continue };
            let (p, n) = (hit.hit.p, hit.hit.n);
            let seen = if n.dot(ray.dir) < 0.0 { n } else { -n };
            let both_sides = through[hit.material as usize];
            let mut sent = vec![0.0; lights.choices()];
            for (light, s) in sent.iter_mut().enumerate() {
                let u = Vec2::new(rng.uniform(), rng.uniform());
                let Some(ls) = lights.sample_light(light, p, u) else { continue };
                let cos = if both_sides { seen.dot(ls.dir).abs() } else { seen.dot(ls.dir) };
                let irradiance = ls.radiance.element_sum() / 3.0 * cos / ls.pdf;
                if !(cos > 0.0 && irradiance > 0.0 && irradiance.is_finite()) {
                    continue;
                }
                let (origin, dir, dist) = shadow_segment(p, seen, ls.dir, ls.dist, p);
                if world.unoccluded(origin, dir, dist) {
                    *s += irradiance;
                }
            }
            measures.push(Measure { p, sent });
        }
        measures
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use alhazen_scene::{LightChoice, parse_scene};

    /// A floor seen from the front, a wall behind it, and `lights` (TOML): a lamp above the
    /// floor and whatever else.
    fn room(lights: &str) -> alhazen_scene::Scene {
        room_seen_from("eye = [0, 1.5, 5]\ntarget = [0, 0.5, 0]", lights)
    }

    /// [`room`] seen by the camera `camera` (TOML).
    fn room_seen_from(camera: &str, lights: &str) -> alhazen_scene::Scene {
        let text = format!(
            r#"
[render]
width = 64
height = 48
integrator = "path"
[camera]
{camera}
fov = 50
[[object]]
shape = "plane"
normal = [0, 1, 0]
material = {{ color = 0.5 }}
[[object]]
shape = "box"
min = [-50, -1, -2]
max = [50, 20, -1.5]
material = {{ color = 0.5 }}
[[object]]
shape = "rectangle"
transform = [{{ scale = [0.5, 0.5, 1] }}, {{ rotate_x = 90 }}, {{ translate = [0, 2.5, 0] }}]
material = {{ color = 0, emission = [4, 4, 4] }}
{lights}
"#
        );
        parse_scene("room.toml".as_ref(), &text).unwrap()
    }

    /// `scene`'s lights as the path tracer chooses them, and whether the measure chose.
    fn measured(scene: &alhazen_scene::Scene) -> (Lights, bool) {
        let world = World::build(scene);
        let camera = Camera::new(&scene.camera, scene.render.width, scene.render.height);
        let mut lights = Lights::build_for(scene, crate::lights::LightSampling::AgainstBsdf);
        let table = measured_choice(scene, &world, &camera, &lights);
        let chose = table.is_some();
        lights.choose_by(table);
        (lights, chose)
    }

    /// The probabilities of choosing each light from `at`.
    fn pmf(lights: &Lights, at: Vec3) -> Vec<f64> {
        (0..lights.choices()).map(|i| lights.choice_pdf(i, at)).collect()
    }

    /// Points of the floor the camera sees, and one beyond it.
    const FLOOR: [Vec3; 5] = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(-1.5, 0.0, 1.0),
        Vec3::new(1.5, 0.0, -1.0),
        Vec3::new(0.3, 0.0, 2.0),
        Vec3::new(40.0, -3.0, 90.0),
    ];

    /// A point light a thousand times the lamp's power behind the wall gets the uniform share
    /// alone, everywhere; the lamp, which lights the floor, the rest. Choosing by power, the
    /// hidden light takes nearly every sample.
    #[test]
    fn a_light_behind_a_wall_gets_the_uniform_share_alone() {
        let mut scene = room("[[light]]\ntype = \"point\"\nposition = [0, 3, -4]\nintensity = 4000");
        let (lights, _) = measured(&scene);
        let (lamp, hidden) = (lights.of_object(2).unwrap(), 0);
        assert_eq!(lights.choices(), 2);
        for at in FLOOR {
            let pmf = pmf(&lights, at);
            assert!((pmf[hidden] - UNIFORM_SHARE / 2.0).abs() < 1e-15, "{at}: {pmf:?}");
            assert!((pmf[lamp] - (1.0 - UNIFORM_SHARE / 2.0)).abs() < 1e-15, "{at}: {pmf:?}");
        }
        scene.render.light_choice = LightChoice::Power;
        let by_power = Lights::build_for(&scene, crate::lights::LightSampling::AgainstBsdf);
        assert!(by_power.choice_pdf(hidden, Vec3::ZERO) > 0.9, "{}", by_power.choice_pdf(hidden, Vec3::ZERO));
    }

    /// Two lights lighting the floor alike share the choice alike between them; a weaker one
    /// gets less; every cell's choice sums to 1.
    #[test]
    fn lights_are_chosen_as_often_as_they_light_what_the_camera_sees() {
        let point = |x: f64, i: f64| format!("[[light]]\ntype = \"point\"\nposition = [{x}, 2, 1]\nintensity = {i}\n");
        let (lights, chose) = measured(&room(&(point(-1.0, 3.0) + &point(1.0, 3.0) + &point(0.0, 0.3))));
        assert!(chose);
        assert_eq!(lights.choices(), 4);
        let between = pmf(&lights, Vec3::new(0.0, 0.0, 1.0));
        assert!((between[0] - between[1]).abs() < 0.15 * between[0], "{between:?}");
        for at in FLOOR {
            let pmf = pmf(&lights, at);
            assert!(pmf[2] < 0.5 * pmf[0].max(pmf[1]), "{at}: {pmf:?}");
            assert!((pmf.iter().sum::<f64>() - 1.0).abs() < 1e-12, "{at}: {pmf:?}");
        }
    }

    /// Two low lamps far apart, each lighting its own end of the floor: each is chosen most at
    /// its own end, and they share the middle.
    #[test]
    fn a_light_is_chosen_most_where_it_lights_most() {
        let point = |x: f64| format!("[[light]]\ntype = \"point\"\nposition = [{x}, 0.4, 0.5]\nintensity = 2\n");
        let scene = room_seen_from("eye = [0, 6, 6]\ntarget = [0, 0, 0]", &(point(-3.0) + &point(3.0)));
        let (lights, _) = measured(&scene);
        let (left, right) = (pmf(&lights, Vec3::new(-3.0, 0.0, 0.5)), pmf(&lights, Vec3::new(3.0, 0.0, 0.5)));
        assert!(left[0] > 0.6 && right[1] > 0.6, "{left:?} {right:?}");
        let middle = pmf(&lights, Vec3::new(0.0, 0.0, 0.5));
        assert!((middle[0] - middle[1]).abs() < 0.1, "{middle:?}");
    }

    /// The same seen low over a ground plane to its horizon, whose far points would stretch a
    /// grid over all points: near the camera each lamp is still chosen most at its own end.
    #[test]
    fn far_ground_does_not_coarsen_the_cells_near_the_camera() {
        let point = |x: f64| format!("[[light]]\ntype = \"point\"\nposition = [{x}, 0.4, 3]\nintensity = 2\n");
        let text = format!(
            "[render]\nwidth = 64\nheight = 48\nintegrator = \"path\"\n[camera]\neye = [0, 1, 6]\ntarget = [0, 0.8, 0]\nfov = 60\n\
             [[object]]\nshape = \"plane\"\nnormal = [0, 1, 0]\nmaterial = {{ color = 0.5 }}\n{}{}",
            point(-1.5),
            point(1.5)
        );
        let (lights, _) = measured(&parse_scene("far.toml".as_ref(), &text).unwrap());
        let (left, right) = (pmf(&lights, Vec3::new(-1.5, 0.0, 3.0)), pmf(&lights, Vec3::new(1.5, 0.0, 3.0)));
        assert!(left[0] > 0.6 && right[1] > 0.6, "{left:?} {right:?}");
    }

    /// With thousands of lights the pilot has fewer points, each light's measure is noisier,
    /// and more of the choice is shared equally: half the lights, behind the wall, still get
    /// more than half their uniform share.
    #[test]
    fn with_many_lights_the_uniform_share_grows() {
        let light = |k: usize| {
            let z = if k.is_multiple_of(2) { -4.0 } else { 1.0 };
            format!("[[light]]\ntype = \"point\"\nposition = [{}, 2, {z}]\nintensity = 0.01\n", k as f64 * 0.001)
        };
        let (lights, _) = measured(&room(&(0..2000).map(light).collect::<String>()));
        let n = lights.choices() as f64;
        assert_eq!(n, 2001.0);
        let pmf = pmf(&lights, Vec3::ZERO);
        let least = pmf.iter().cloned().fold(f64::INFINITY, f64::min);
        assert!(least * n > 0.5 && least * n < 0.7, "{}", least * n);
    }

    /// Nothing to choose: one light, or none seen (the camera looks at the sky).
    #[test]
    fn without_a_choice_or_a_light_seen_every_light_is_chosen_alike() {
        assert!(!measured(&room("")).1);
        let up = "eye = [0, 30, 0]\ntarget = [0, 60, 0]\nup = [0, 0, 1]";
        assert!(!measured(&room_seen_from(up, "[[light]]\ntype = \"point\"\nposition = [0, 3, -4]")).1);
    }

    proptest::proptest! {
        /// Where a light sample lands, a ray meeting that light reckons the density the sample
        /// was drawn with — the light's choice included — (the MIS weights' invariant), for
        /// lights chosen by power: two lamps and a lit sphere of different powers, a point light
        /// and a sky.
        #[test]
        fn a_light_sample_and_a_ray_reaching_it_agree_on_its_density(
            u_choice in 0.0..1.0f64, u in (0.0..1.0f64, 0.0..1.0f64), (x, z) in (-4.0..4.0f64, -1.0..6.0f64),
            by_measure in proptest::bool::ANY,
        ) {
            let mut scene = room(
                "[[object]]\nshape = \"rectangle\"\ntransform = [{ scale = [2, 1, 1] }, { rotate_x = 60 }, { translate = [1, 3, 1] }]\n\
                 material = { color = 0, emission = [0.3, 0.3, 0.3] }\n\
                 [[object]]\nshape = \"sphere\"\ncenter = [-1.5, 1.5, 0]\nradius = 0.2\nmaterial = { color = 0, emission = [40, 30, 20] }\n\
                 [[light]]\ntype = \"point\"\nposition = [0, 2, 1]\nintensity = 2\n",
            );
            scene.background = alhazen_scene::Background::Solid(alhazen_math::Vec3::splat(0.2));
            scene.render.light_choice = LightChoice::Power;
            let mut lights = Lights::build(&scene);
            if by_measure {
                let (world, camera) = (World::build(&scene), Camera::new(&scene.camera, 64, 48));
                lights.choose_by(measured_choice(&scene, &world, &camera, &lights));
            }
            let p = Vec3::new(x, 0.0, z);
            proptest::prop_assert_eq!(lights.choices(), 5);
            proptest::prop_assert!(pmf(&lights, p).iter().any(|p| (p - 0.2).abs() > 0.01));
            let ls = lights.sample(p, u_choice, Vec2::new(u.0, u.1));
            proptest::prop_assume!(ls.is_some());
            let ls = ls.unwrap();
            let light = lights.choose(u_choice, p);
            let objects = lights.objects();
            let reckoned = match (objects[light], &lights.all()[light]) {
                (Some(object), crate::lights::PathLight::Area { emitter, .. }) => {
                    let n = match emitter {
                        crate::lights::Emitter::Parallelogram { normal, .. } => *normal,
                        _ => (p + ls.dir * ls.dist - emitter.centre()).normalize(),
                    };
                    lights.area_pdf(object, p, p + ls.dir * ls.dist, n)
                }
                (_, crate::lights::PathLight::Background(_)) => lights.sky(ls.dir, p).1,
                _ => lights.choice_pdf(light, p),
            };
            proptest::prop_assert!((reckoned - ls.pdf).abs() <= 1e-9 * ls.pdf, "light {light}: sampled {}, reckoned {reckoned}", ls.pdf);
        }

        /// Counting the cumulative probabilities at or below a number picks the light a binary
        /// search picks, zero probabilities, numbers on the steps and the threshold between the
        /// two ways included.
        #[test]
        fn lights_are_chosen_by_counting_as_by_search(
            weights in proptest::collection::vec(proptest::prop_oneof![proptest::strategy::Just(0.0), 0.01..10.0f64], 2..40),
            numbers in proptest::collection::vec(0.0..1.0f64, 8),
        ) {
            proptest::prop_assume!(weights.iter().any(|&w| w > 0.0));
            let scene = room(&"[[light]]\ntype = \"point\"\nposition = [0, 2, 1]\n".repeat(weights.len() - 1));
            let mut lights = Lights::build(&scene);
            let total: f64 = weights.iter().sum();
            let pmf: Vec<f64> = weights.iter().map(|w| w / total).collect();
            let cdf: Vec<f64> = pmf.iter().scan(0.0, |sum, p| { *sum += p; Some(*sum) }).collect();
            lights.choose_by(Some(ChoiceTable::everywhere(pmf.clone())));
            for u in numbers.iter().chain(&cdf).copied() {
                let searched = cdf.partition_point(|&c| c <= u).min(pmf.len() - 1);
                proptest::prop_assert_eq!(lights.choose(u, Vec3::ZERO), searched, "u {}", u);
            }
        }

        /// A light is chosen as often as its probability says: over `n` evenly spread numbers,
        /// each light within one of `n · p` times.
        #[test]
        fn lights_are_chosen_by_their_probabilities(weights in proptest::collection::vec(0.01..10.0f64, 2..12)) {
            let scene = room(&"[[light]]\ntype = \"point\"\nposition = [0, 2, 1]\n".repeat(weights.len() - 1));
            let mut lights = Lights::build(&scene);
            let total: f64 = weights.iter().sum();
            let pmf: Vec<f64> = weights.iter().map(|w| w / total).collect();
            lights.choose_by(Some(ChoiceTable::everywhere(pmf.clone())));
            let n = 10_000;
            let mut counts = vec![0usize; pmf.len()];
            for k in 0..n {
                counts[lights.choose((k as f64 + 0.5) / n as f64, Vec3::ZERO)] += 1;
            }
            for (i, (c, p)) in counts.iter().zip(&pmf).enumerate() {
                proptest::prop_assert!((*c as f64 - n as f64 * p).abs() <= 1.0, "light {i}: {c} of {n}, p {p}");
                proptest::prop_assert_eq!(lights.choice_pdf(i, Vec3::ZERO), *p);
            }
        }
    }
}
