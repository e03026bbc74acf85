//! The path tracer's light sources: point, spot and directional lights (delta), area lights
//! (any object whose material emits: spheres sampled by solid angle, rectangles, triangles —
//! meshes, boxes — and disks by area), the environment map and a coloured background
//! (uniformly over the sphere). Lights are chosen uniformly, by their power, or as a pilot pass
//! measures them ([`alhazen_scene::LightChoice`], [`crate::light_choice`]); every density here
//! includes that choice. Emitters of other shapes still shine when paths hit them, without
//! light sampling.
//! For the path tracer, whose light samples are weighed against BSDF samples, the sky is
//! sampled only where BSDF samples do poorly ([`LightSampling::AgainstBsdf`], MIS
//! compensation: Karlík et al. 2019).
//! A textured emission ([`AreaTexture`]) is read per point on meshes, by the texture
//! coordinates of the point a light sample lands on and of the point a ray hits alike.

use crate::distribution::Distribution1D;
use crate::envmap::{EnvMap, MapSampling, TexelSample};
use crate::shape::VectorUnit;
use alhazen_math::{Vec2, Vec3, orthonormal_basis};
use alhazen_scene::{Background, ImageData, Light, LightChoice, Scene, Shape, Texture};
use std::f64::consts::PI;
use std::sync::Arc;

/// Geometry of an area light, in world space.
#[derive(Clone, Debug)]
pub enum Emitter {
    /// A sphere.
    Sphere {
        /// Centre.
        center: Vec3,
        /// Radius.
        radius: f64,
    },
    /// Triangles, chosen by area.
    Triangles {
        /// Corners.
        triangles: Vec<[Vec3; 3]>,
        /// Choice by area.
        by_area: Distribution1D,
        /// Total area.
        area: f64,
    },
    /// A parallelogram `origin + s·e1 + t·e2`, `s, t ∈ [0, 1]` (rectangles), sampled without
    /// choosing a triangle.
    Parallelogram {
        /// A corner.
        origin: Vec3,
        /// First edge.
        e1: Vec3,
        /// Second edge.
        e2: Vec3,
        /// Unit normal `e1 × e2 / |e1 × e2|`.
        normal: Vec3,
        /// `|e1 × e2|`.
        area: f64,
    },
    /// A disk.
    Disk {
        /// Centre.
        center: Vec3,
        /// Unit normal (the emitting side).
        normal: Vec3,
        /// Radius.
        radius: f64,
    },
}

impl Emitter {
    /// A point at the middle of the emitter: a sphere's or disk's centre, a parallelogram's,
    /// the mean of the triangles' corners.
    pub fn centre(&self) -> Vec3 {
        match self {
            Emitter::Sphere { center, .. } | Emitter::Disk { center, .. } => *center,
            Emitter::Parallelogram { origin, e1, e2, .. } => *origin + (*e1 + *e2) * 0.5,
            Emitter::Triangles { triangles, .. } => {
                let sum: Vec3 = triangles.iter().flatten().copied().sum();
                sum / (3 * triangles.len()).max(1) as f64
            }
        }
    }
}

/// One light of the path tracer.
#[derive(Clone, Debug)]
pub enum PathLight {
    /// Point light, intensity falling off as `1/d²`.
    Point {
        /// Position.
        position: Vec3,
        /// Intensity (W/sr per channel).
        intensity: Vec3,
    },
    /// Spot light: a point light times `cos^e` inside its cone.
    Spot {
        /// Position.
        position: Vec3,
        /// Axis.
        direction: Vec3,
        /// Cosine of the half-angle.
        cos_cutoff: f64,
        /// Falloff exponent.
        falloff: f64,
        /// Cosine of the beam of full intensity ([`alhazen_scene::spot_profile`]).
        beam: Option<alhazen_scene::SpotBeam>,
        /// Intensity on the axis.
        intensity: Vec3,
    },
    /// Parallel light.
    Directional {
        /// Direction of travel.
        direction: Vec3,
        /// Irradiance on a perpendicular surface.
        irradiance: Vec3,
    },
    /// An emitting object.
    Area {
        /// Geometry.
        emitter: Emitter,
        /// Radiance from the front side (with a `texture`, its mean).
        radiance: Vec3,
        /// The radiance point by point, where it varies (on triangles only).
        texture: Option<Box<AreaTexture>>,
    },
    /// An environment map.
    Environment(Box<EnvMap>),
    /// A solid or gradient background.
    Background(Background),
}

/// An area light's radiance point by point: its texture, its cut-out, the scene's images, and
/// each triangle's texture coordinates (in the order of [`Emitter::Triangles`]' corners).
#[derive(Clone, Debug)]
pub struct AreaTexture {
    texture: Texture,
    /// Where the emitting surface is not: a point drawn in a hole sends nothing, and where a
    /// coverage `a` lets rays through, `a` of the radiance — what rays that hit the light
    /// there see on average.
    cut_out: Option<alhazen_scene::Alpha>,
    images: Vec<Arc<ImageData>>,
    uvs: Vec<[Vec2; 3]>,
}

impl AreaTexture {
    /// The radiance at barycentric weights `b` of triangle `i`.
    #[inline]
    fn radiance(&self, (i, b): (usize, [f64; 3])) -> Vec3 {
        let [a, c, d] = self.uvs[i];
        let uv = a * b[0] + c * b[1] + d * b[2];
        let radiance = alhazen_scene::texture::eval(&self.texture, uv, &self.images);
        let Some(cut) = &self.cut_out else { return radiance };
        let coverage = alhazen_scene::texture::coverage(cut, uv, &self.images);
        radiance * cut.cutoff.map_or(coverage.clamp(0.0, 1.0), |c| if coverage >= c { 1.0 } else { 0.0 })
    }
}

/// The radiance a scene object's material emits at texture coordinates `uv`, as the lights
/// see it: a textured emission is read per point on meshes, other shapes shine its mean.
#[inline]
pub fn emission_at(scene: &Scene, material: u32, object: u32, uv: Vec2) -> Vec3 {
    let m = &scene.materials[material as usize];
    match &m.emission_texture {
        Some(t) if matches!(scene.objects[object as usize].shape, Shape::Mesh { .. }) => {
            alhazen_scene::texture::eval(t, uv, &scene.images)
        }
        _ => m.emission,
    }
}

/// A point drawn on an area light by area: where, its emitting side's unit normal, the area
/// density, and the radiance it sends.
#[derive(Clone, Copy, Debug)]
pub struct AreaPoint {
    /// The point.
    pub p: Vec3,
    /// Unit normal of the emitting side.
    pub n: Vec3,
    /// Density per unit area.
    pub pdf_area: f64,
    /// Radiance emitted there.
    pub radiance: Vec3,
}

/// An environment map's sample ([`EnvMap::sample`]) as a light sample.
#[inline]
fn env_sample(sample: Option<(Vec3, Vec3, f64)>) -> Option<LightSample> {
    let (dir, radiance, pdf) = sample?;
    Some(LightSample { dir, dist: f64::INFINITY, radiance, pdf, delta: false })
}

/// A light sample asked for ahead ([`Lights::ask`]): where from, its numbers, and an
/// environment map's row.
#[derive(Clone, Copy, Debug)]
pub struct LightAsk {
    p: Vec3,
    u_choice: f64,
    u: Vec2,
    row: Option<(f64, usize)>,
}

/// A point on a light seen from a shading point.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// Unit direction from the shading point to the light.
    pub dir: Vec3,
    /// Distance to the light point (infinite for distant lights).
    pub dist: f64,
    /// Radiance arriving (for delta lights: irradiance-like `I/d²`).
    pub radiance: Vec3,
    /// Solid-angle density including the light choice (the choice probability for delta lights).
    pub pdf: f64,
    /// True for point, spot and directional lights.
    pub delta: bool,
}

/// All lights of a scene.
#[derive(Clone, Debug, Default)]
pub struct Lights {
    lights: Vec<PathLight>,
    /// Light index of each scene object that can be sampled.
    by_object: Vec<Option<u32>>,
    /// The light that rays leaving the scene see.
    sky: Option<u32>,
    /// Some light is an environment map.
    has_environment: bool,
    /// The lights a sample chooses among: the first `choices` of `lights` (all but a sky of
    /// one colour or a gradient, last, under [`LightSampling::AgainstBsdf`]).
    choices: usize,
    /// How often each of the first `choices` lights is chosen, where that is not equally
    /// often.
    choice: Option<ChoiceTable>,
}

/// How often a light sample chooses each of `n` lights: everywhere alike, or cell by cell of a
/// grid over the scene, by the cell of the point the light is sampled from (a light that
/// lights one corner of a room is chosen there). Any such table gives every image the same
/// expectation, as long as the choice at a point and its density there are read from the same
/// cell.
#[derive(Clone, Debug)]
pub struct ChoiceTable {
    /// The probabilities, `n` for each cell in turn, and their running sums within each cell.
    pmf: Vec<f64>,
    cdf: Vec<f64>,
    n: usize,
    cells: Cells,
}

/// A grid of boxes: its lower corner, its cells per unit length along each axis and its cells
/// along each axis; a point beyond the grid (or NaN) takes the nearest cell.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cells {
    /// Lower corner.
    pub min: Vec3,
    /// Cells per unit length along each axis.
    pub scale: Vec3,
    /// Cells along each axis (at least one).
    pub res: [u32; 3],
}

impl Cells {
    /// One cell holding everything.
    pub const ONE: Cells = Cells { min: Vec3::ZERO, scale: Vec3::ZERO, res: [1, 1, 1] };

    /// How many cells.
    pub fn count(&self) -> usize {
        self.res.iter().map(|&r| r as usize).product()
    }

    /// The cell of point `at` (`x` fastest).
    #[inline]
    pub fn index(&self, at: Vec3) -> usize {
        if self.res == [1, 1, 1] {
            return 0;
        }
        let f = (at - self.min) * self.scale;
        // `max` takes NaN to 0; the conversion saturates.
        let c = |x: f64, r: u32| (x.max(0.0) as u32).min(r - 1) as usize;
        let [rx, ry, _] = self.res.map(|r| r as usize);
        (c(f.z, self.res[2]) * ry + c(f.y, self.res[1])) * rx + c(f.x, self.res[0])
    }
}

impl ChoiceTable {
    /// `pmf` (summing to 1) everywhere.
    pub fn everywhere(pmf: Vec<f64>) -> Self {
        Self::in_cells(pmf, Cells::ONE)
    }

    /// `pmfs`, one probability per light for each of `cells` in turn (each summing to 1).
    pub fn in_cells(pmfs: Vec<f64>, cells: Cells) -> Self {
        assert!(pmfs.len().is_multiple_of(cells.count()), "one probability per light in each cell");
        let n = pmfs.len() / cells.count();
        let cdf = pmfs
            .chunks(n)
            .flat_map(|cell| {
                cell.iter().scan(0.0, |sum, p| {
                    *sum += p;
                    Some(*sum)
                })
            })
            .collect();
        Self { pmf: pmfs, cdf, n, cells }
    }

    /// The first of the `n` entries of the cell of point `at`.
    #[inline]
    fn cell(&self, at: Vec3) -> usize {
        self.cells.index(at) * self.n
    }

    /// The light `u_choice` chooses in the cell whose entries start at `cell`: the first whose
    /// cumulative probability exceeds it. Among a few lights, by counting the entries at or
    /// below it (the same light: the cumulative probabilities never decrease) with every entry
    /// read at once — a binary search's reads wait on each other, and on a table that is not
    /// in the nearest cache each waits for memory (the search was a tenth of the corridor's
    /// render).
    #[inline]
    fn choose_in(&self, cell: usize, u_choice: f64) -> usize {
        let cdf = &self.cdf[cell..cell + self.n];
        let i = if self.n <= COUNTED_CHOICES {
            cdf.iter().map(|&c| usize::from(c <= u_choice)).sum()
        } else {
            cdf.partition_point(|&c| c <= u_choice)
        };
        i.min(self.n - 1)
    }
}

/// Lights up to this many are chosen by counting ([`ChoiceTable::choose_in`]).
const COUNTED_CHOICES: usize = 32;

/// The share of a choice among lights by power or by measure that goes to every light
/// equally (a defensive mixture: a dim lamp that lights what the camera sees still gets a
/// tenth of its uniform share of samples beside a bright one that lights little of it).
pub(crate) const UNIFORM_SHARE: f64 = 0.1;

/// How often each of `lights` is chosen under [`LightChoice::Power`] (`None` where that is
/// equally often): lights in the scene by their power mixed with a uniform share
/// ([`UNIFORM_SHARE`]); each light at infinity (directional, environment, sky), whose power
/// grows with the scene's size, as often as all lights in the scene together (pbrt-v4's
/// `BVHLightSampler` places them so).
fn power_pmf(lights: &[PathLight]) -> Option<Vec<f64>> {
    let powers: Vec<Option<f64>> = lights.iter().map(power).collect();
    let local = powers.iter().flatten().count();
    let total: f64 = powers.iter().flatten().sum();
    if local == 0 || !(total > 0.0 && total.is_finite()) {
        return None;
    }
    let group = 1.0 / (lights.len() - local + 1) as f64;
    let pmf: Vec<f64> = powers
        .iter()
        .map(|p| match p {
            Some(p) => group * ((1.0 - UNIFORM_SHARE) * p / total + UNIFORM_SHARE / local as f64),
            None => group,
        })
        .collect();
    unless_uniform(pmf)
}

/// `pmf`, or `None` where it chooses every light equally often (so that the choice keeps its
/// uniform arithmetic and its images their bits).
pub(crate) fn unless_uniform(pmf: Vec<f64>) -> Option<Vec<f64>> {
    let uniform = 1.0 / pmf.len() as f64;
    (!pmf.iter().all(|p| (p - uniform).abs() <= 1e-12 * uniform)).then_some(pmf)
}

/// A light's power, its channels' mean (the flux it emits), for the choice among lights;
/// `None` for a light at infinity.
fn power(light: &PathLight) -> Option<f64> {
    let mean = |c: Vec3| c.element_sum().max(0.0) / 3.0;
    match light {
        PathLight::Point { intensity, .. } => Some(4.0 * PI * mean(*intensity)),
        // Its cone's solid angle: an upper bound on a profile that falls off inside it.
        PathLight::Spot { cos_cutoff, intensity, .. } => Some(2.0 * PI * (1.0 - cos_cutoff) * mean(*intensity)),
        PathLight::Area { radiance, .. } => Some(PI * mean(*radiance) / area_density(light)),
        PathLight::Directional { .. } | PathLight::Environment(_) | PathLight::Background(_) => None,
    }
}

/// What a scene's light samples are for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightSampling {
    /// Estimates by light samples alone (Whitted's soft shadows, photon emission): every
    /// light is sampled wherever it shines.
    Whole,
    /// The path tracer's, each light sample weighed against a BSDF sample by multiple
    /// importance sampling: the BSDF samples cover every direction, so the lights sample only
    /// where the BSDF's do poorly (Karlík et al. 2019, "MIS compensation"; pbrt-v4's
    /// `allowIncompletePDF`). An environment map draws its samples where it exceeds its mean
    /// ([`MapSampling::AboveMean`]): a sun's, not the dim sky's. A sky of one colour or a
    /// gradient is left to the BSDF samples alone (sampled uniformly, it would only add noise
    /// and shadow rays), and the choice among the other lights.
    AgainstBsdf,
}

/// The area light of scene object `o`: where it emits and is a shape lights sample.
fn area_light_of(scene: &Scene, o: &alhazen_scene::Object) -> Option<PathLight> {
    let m = &scene.materials[o.material as usize];
    let radiance = m.emission;
    if radiance == Vec3::ZERO {
        return None;
    }
    // Read per point where the emission varies or a cut-out takes parts of it away.
    let textured = match (&m.emission_texture, &m.alpha) {
        (None, None) => None,
        (texture, cut_out) => {
            let texture = texture.clone().unwrap_or(Texture::Solid(radiance));
            textured_emitter_of(scene, o, &texture, cut_out.as_ref())
        }
    };
    match textured {
        Some((emitter, t)) => Some(PathLight::Area { emitter, radiance, texture: Some(Box::new(t)) }),
        None => emitter_of(scene, o).map(|emitter| PathLight::Area { emitter, radiance, texture: None }),
    }
}

/// The world-space triangles of an emitting mesh object whose radiance is `texture`, cut out by
/// `cut_out`, with their texture coordinates (never a parallelogram: its two triangles'
/// coordinates may differ).
fn textured_emitter_of(
    scene: &Scene,
    o: &alhazen_scene::Object,
    texture: &Texture,
    cut_out: Option<&alhazen_scene::Alpha>,
) -> Option<(Emitter, AreaTexture)> {
    let Shape::Mesh { mesh, .. } = &o.shape else { return None };
    let m = &scene.meshes[*mesh];
    let mirroring = o.transform.is_mirroring();
    let indices: Vec<[u32; 3]> = m.triangles.iter().map(|&tri| outside_first(tri, mirroring)).collect();
    // A mesh without texture coordinates is parametrised by each triangle's barycentrics, as
    // its ray tests report them: its corners at (0, 0), (1, 0), (0, 1), in the same order.
    let uvs = match m.uvs.is_empty() {
        true => vec![outside_first([Vec2::ZERO, Vec2::X, Vec2::Y], mirroring); indices.len()],
        false => indices.iter().map(|tri| tri.map(|i| m.uvs[i as usize])).collect(),
    };
    let tris: Vec<[Vec3; 3]> =
        indices.iter().map(|tri| tri.map(|i| o.transform.point(m.positions[i as usize]))).collect();
    let emitter = triangles_emitter(tris)?;
    let cut_out = cut_out.cloned();
    Some((emitter, AreaTexture { texture: texture.clone(), cut_out, images: scene.images.clone(), uvs }))
}

/// Triangles chosen by area, when they have any.
fn triangles_emitter(tris: Vec<[Vec3; 3]>) -> Option<Emitter> {
    let areas: Vec<f64> = tris.iter().map(|[a, b, c]| 0.5 * (*b - *a).cross(*c - *a).length()).collect();
    let area: f64 = areas.iter().sum();
    (area > 0.0).then(|| Emitter::Triangles { triangles: tris, by_area: Distribution1D::new(&areas), area })
}

/// The world-space geometry of an emitting object, when it can be sampled.
fn emitter_of(scene: &Scene, o: &alhazen_scene::Object) -> Option<Emitter> {
    let t = &o.transform;
    let similarity = || t.similarity_scale();
    let mirroring = t.is_mirroring();
    let triangles = triangles_emitter;
    match &o.shape {
        Shape::Sphere { center, radius } => {
            similarity().map(|s| Emitter::Sphere { center: t.point(*center), radius: radius * s })
        }
        Shape::Disk { center, normal, radius } => similarity().map(|s| Emitter::Disk {
            center: t.point(*center),
            normal: t.normal(*normal).normalize(),
            radius: radius * s,
        }),
        Shape::Mesh { mesh, .. } => {
            let m = &scene.meshes[*mesh];
            let indices: Vec<[u32; 3]> = m.triangles.iter().map(|&tri| outside_first(tri, mirroring)).collect();
            let tris: Vec<[Vec3; 3]> =
                indices.iter().map(|tri| tri.map(|i| t.point(m.positions[i as usize]))).collect();
            parallelogram(&indices, &tris).or_else(|| triangles(tris))
        }
        Shape::Box { min, max } => {
            let m = alhazen_geom::TriangleMesh::cuboid(*min, *max);
            triangles(
                (0..m.triangle_count()).map(|i| outside_first(m.corners(i).map(|p| t.point(p)), mirroring)).collect(),
            )
        }
        _ => None,
    }
}

/// A triangle's corners in the order that keeps its emitting side after a transform that
/// mirrors (which reverses the winding) or not.
fn outside_first<T>(mut tri: [T; 3], mirroring: bool) -> [T; 3] {
    if mirroring {
        tri.swap(1, 2);
    }
    tri
}

/// A mesh of two triangles forming a parallelogram.
fn parallelogram(indices: &[[u32; 3]], corners: &[[Vec3; 3]]) -> Option<Emitter> {
    let ([i, j], [first, [_, _, d]]) = (indices, corners) else { return None };
    let [origin, e1, e2] = crate::shape::parallelogram_of(*i, *j, *first, *d)?;
    let n = e1.cross(e2);
    Some(Emitter::Parallelogram { origin, e1, e2, normal: n / n.length(), area: n.length() })
}

/// The direction `u` picks uniformly on the unit sphere (a sky's light sample).
#[inline(always)]
fn uniform_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (sin, cos) = alhazen_math::sin_cos_turns(u.y);
    Vec3::new(r * cos, r * sin, z)
}

impl Lights {
    /// The lights of `scene`: its light list, then one area light per emitting object.
    pub fn build(scene: &Scene) -> Self {
        Self::build_for(scene, LightSampling::Whole)
    }

    /// [`Self::build`] for estimates of the kind `purpose` says.
    pub fn build_for(scene: &Scene, purpose: LightSampling) -> Self {
        let mut lights = Vec::new();
        let mut sky = None;
        for l in &scene.lights {
            lights.push(match *l {
                Light::Point { position, intensity, .. } => PathLight::Point { position, intensity },
                Light::Spot { position, direction, cos_cutoff, falloff, beam, intensity, .. } => {
                    PathLight::Spot { position, direction, cos_cutoff, falloff, beam, intensity }
                }
                Light::Directional { direction, intensity } => {
                    PathLight::Directional { direction, irradiance: intensity }
                }
                Light::Environment { image, scale, rotation, up } => {
                    sky = Some(lights.len() as u32);
                    let sampling = match purpose {
                        LightSampling::Whole => MapSampling::Whole,
                        LightSampling::AgainstBsdf => MapSampling::AboveMean,
                    };
                    PathLight::Environment(Box::new(EnvMap::sampled(
                        &scene.images[image],
                        scale,
                        (rotation, up),
                        sampling,
                    )))
                }
            });
        }
        let black = matches!(scene.background, Background::Solid(c) if c == Vec3::ZERO);
        if sky.is_none() && !black {
            sky = Some(lights.len() as u32);
            lights.push(PathLight::Background(scene.background));
        }
        let mut by_object = vec![None; scene.objects.len()];
        for (i, o) in scene.objects.iter().enumerate() {
            if let Some(light) = area_light_of(scene, o) {
                by_object[i] = Some(lights.len() as u32);
                lights.push(light);
            }
        }
        let mut choices = lights.len();
        if let (LightSampling::AgainstBsdf, Some(i)) = (purpose, sky)
            && matches!(lights[i as usize], PathLight::Background(_))
        {
            // The sky last, out of the choice.
            let background = lights.remove(i as usize);
            for light in by_object.iter_mut().flatten().filter(|l| **l > i) {
                *light -= 1;
            }
            sky = Some(lights.len() as u32);
            lights.push(background);
            choices -= 1;
        }
        let has_environment = lights.iter().any(|l| matches!(l, PathLight::Environment(_)));
        let by_power = scene.render.light_choice == LightChoice::Power;
        let choice = by_power.then(|| power_pmf(&lights[..choices])).flatten().map(ChoiceTable::everywhere);
        Self { lights, by_object, sky, has_environment, choices, choice }
    }

    /// Chooses lights as `table` says (one probability per light of [`Self::choices`] in each
    /// of its cells), or every light equally often (`None`).
    pub fn choose_by(&mut self, table: Option<ChoiceTable>) {
        assert!(table.as_ref().is_none_or(|t| t.n == self.choices), "one probability per light chosen among");
        self.choice = table;
    }

    /// Whether scene object `object` emits and is sampled as an area light ([`Self::of_object`]
    /// of the lights [`Self::build`] makes, without building the others: environment maps).
    pub fn samples_object(scene: &Scene, object: usize) -> bool {
        scene.objects.get(object).and_then(|o| area_light_of(scene, o)).is_some()
    }

    /// Number of lights.
    pub fn len(&self) -> usize {
        self.lights.len()
    }

    /// True when there is no light.
    pub fn is_empty(&self) -> bool {
        self.lights.is_empty()
    }

    /// Number of lights a sample chooses among ([`Self::choose`]; all of them but a sky left to
    /// BSDF samples, [`LightSampling::AgainstBsdf`]).
    pub fn choices(&self) -> usize {
        self.choices
    }

    /// Probability of choosing light `light` (one of the first [`Self::choices`]) for a
    /// sample drawn from point `at`.
    #[inline(always)]
    pub fn choice_pdf(&self, light: usize, at: Vec3) -> f64 {
        match &self.choice {
            Some(t) => t.pmf[t.cell(at) + light],
            None => 1.0 / self.choices as f64,
        }
    }

    /// The light `u_choice` chooses (by [`Self::choice_pdf`]) for a sample drawn from point
    /// `at`; there must be one ([`Self::choices`]). Always inlined: a call per vertex cost a
    /// scene of one light 1.5 % (cornell-rough).
    #[inline(always)]
    pub fn choose(&self, u_choice: f64, at: Vec3) -> usize {
        // In `u32`: x86-64 converts between `f64` and 32-bit integers in one instruction each,
        // and `usize` (unsigned 64-bit) in several; the light is the same (far fewer than 2³²).
        let n = u32::try_from(self.choices).unwrap_or(u32::MAX);
        match &self.choice {
            None => ((u_choice * f64::from(n)) as u32).min(n - 1) as usize,
            Some(t) => t.choose_in(t.cell(at), u_choice),
        }
    }

    /// The light `u_choice` chooses from `at` ([`Self::choose`]) and the probability of that
    /// choice ([`Self::choice_pdf`]), the cell found once.
    #[inline(always)]
    pub fn choose_with_pdf(&self, u_choice: f64, at: Vec3) -> (usize, f64) {
        match &self.choice {
            None => (self.choose(u_choice, at), 1.0 / self.choices as f64),
            Some(t) => {
                let cell = t.cell(at);
                let i = t.choose_in(cell, u_choice);
                (i, t.pmf[cell + i])
            }
        }
    }

    /// The light `u_choice` picks from `at` and the probability of that choice.
    #[inline]
    fn chosen(&self, u_choice: f64, at: Vec3) -> (&PathLight, f64) {
        let (i, pdf) = self.choose_with_pdf(u_choice, at);
        (&self.lights[i], pdf)
    }

    /// The probability that a light sample drawn from `at` chooses the sky (0 where it is left
    /// out of the choice, [`Self::choices`]).
    fn sky_choice_pdf(&self, at: Vec3) -> f64 {
        match self.sky {
            Some(i) if (i as usize) < self.choices => self.choice_pdf(i as usize, at),
            _ => 0.0,
        }
    }

    /// Radiance arriving from the sky along `-dir` (`dir` pointing away from the scene) and the
    /// density of sampling `dir` among the lights from point `from` (an environment map's
    /// direction is mapped to its image once).
    pub fn sky(&self, dir: Vec3, from: Vec3) -> (Vec3, f64) {
        match self.sky.map(|i| &self.lights[i as usize]) {
            Some(PathLight::Environment(m)) => {
                let (radiance, pdf) = m.radiance_and_pdf(dir);
                (radiance, pdf * self.sky_choice_pdf(from))
            }
            Some(PathLight::Background(b)) => (b.radiance(dir), self.sky_choice_pdf(from) / (4.0 * PI)),
            _ => (Vec3::ZERO, 0.0),
        }
    }

    /// The sky is an environment map.
    pub fn sky_is_environment(&self) -> bool {
        matches!(self.sky.map(|i| &self.lights[i as usize]), Some(PathLight::Environment(_)))
    }

    /// The first half of [`Self::sky`] for many directions (`None` where a lane has none): an
    /// environment map's texels found for all lanes at once and asked of memory;
    /// [`Self::sky_at`] reads them, as late as the caller can wait.
    pub fn sky_ahead<const N: usize>(&self, dirs: &[Option<Vec3>; N], unit: VectorUnit) -> [Vec2; N] {
        match self.sky.map(|i| &self.lights[i as usize]) {
            Some(PathLight::Environment(m)) => m.texels_ahead(dirs, unit),
            _ => [Vec2::ZERO; N],
        }
    }

    /// [`Self::sky`] of `dir`, whose place in the map [`Self::sky_ahead`] found.
    pub fn sky_at(&self, dir: Vec3, uv: Vec2, from: Vec3) -> (Vec3, f64) {
        match self.sky.map(|i| &self.lights[i as usize]) {
            Some(PathLight::Environment(m)) => {
                let (radiance, pdf) = m.radiance_and_pdf_at(dir, uv);
                (radiance, pdf * self.sky_choice_pdf(from))
            }
            _ => self.sky(dir, from),
        }
    }

    /// Density of sampling the point `q` (normal `n`) of scene object `object` from `p`; 0 when
    /// the object is not a sampled light.
    pub fn area_pdf(&self, object: u32, p: Vec3, q: Vec3, n: Vec3) -> f64 {
        let Some(Some(i)) = self.by_object.get(object as usize) else { return 0.0 };
        let PathLight::Area { emitter, .. } = &self.lights[*i as usize] else { return 0.0 };
        let to = q - p;
        let d2 = to.length_squared();
        let cos = n.dot(to).abs() / d2.sqrt();
        let area_to_solid = |pdf_area: f64| if cos > 0.0 { pdf_area * d2 / cos } else { 0.0 };
        let pdf = match emitter {
            Emitter::Sphere { center, radius } => match cone(p, *center, *radius) {
                Some((_, one_minus_cos)) => 1.0 / (2.0 * PI * one_minus_cos),
                None => area_to_solid(1.0 / (4.0 * PI * radius * radius)),
            },
            Emitter::Triangles { area, .. } => area_to_solid(1.0 / area),
            Emitter::Parallelogram { area, .. } => area_to_solid(1.0 / area),
            Emitter::Disk { radius, .. } => area_to_solid(1.0 / (PI * radius * radius)),
        };
        pdf * self.choice_pdf(*i as usize, p)
    }

    /// Every light, in the order of their indices.
    pub fn all(&self) -> &[PathLight] {
        &self.lights
    }

    /// The light index of scene object `object`, when it is a sampled area light.
    pub fn of_object(&self, object: u32) -> Option<usize> {
        self.by_object.get(object as usize).copied().flatten().map(|i| i as usize)
    }

    /// The scene object of each light (area lights only).
    pub fn objects(&self) -> Vec<Option<u32>> {
        let mut of_light = vec![None; self.lights.len()];
        for (object, light) in self.by_object.iter().enumerate() {
            if let Some(i) = light {
                of_light[*i as usize] = Some(object as u32);
            }
        }
        of_light
    }

    /// A point of area light `light` chosen uniformly by area (not including the light choice):
    /// the point, its emitting normal, the area density and the radiance there; `None` for
    /// other lights.
    pub fn point_by_area(&self, light: usize, u: Vec2) -> Option<AreaPoint> {
        match &self.lights[light] {
            PathLight::Area { emitter, radiance, texture } => {
                let (p, n, pdf_area, at) = point_by_area(emitter, u);
                let radiance = texture.as_ref().map_or(*radiance, |t| t.radiance(at));
                Some(AreaPoint { p, n, pdf_area, radiance })
            }
            _ => None,
        }
    }

    /// The area density of [`Self::point_by_area`] for area light `light`.
    pub fn area_density(&self, light: usize) -> f64 {
        area_density(&self.lights[light])
    }

    /// Chooses a light by `u_choice` and a point on it by `u`, as seen from `p`.
    #[inline]
    pub fn sample(&self, p: Vec3, u_choice: f64, u: Vec2) -> Option<LightSample> {
        if self.choices == 0 {
            return None;
        }
        let (light, choice_pdf) = self.chosen(u_choice, p);
        let mut s = self.sample_one(light, p, u)?;
        s.pdf *= choice_pdf;
        Some(s)
    }

    /// Some light is an environment map: its samples and lookups wait for memory (its tables
    /// outgrow the caches), so paths side by side do better to take them together
    /// ([`Self::sample_lanes`], [`Self::sky_ahead`]).
    pub fn has_environment(&self) -> bool {
        self.has_environment
    }

    /// The first half of [`Self::sample`]`(p, u_choice, u)` for a path among others
    /// ([`Self::sample_lanes`] finishes it): an environment map's row found and its guide
    /// asked of memory, while the other paths are busy.
    #[inline]
    pub fn ask(&self, p: Vec3, u_choice: f64, u: Vec2) -> LightAsk {
        let chosen = (self.choices > 0).then(|| self.chosen(u_choice, p).0);
        let row = match chosen {
            Some(PathLight::Environment(m)) => Some(m.sample_row(u)),
            _ => None,
        };
        LightAsk { p, u_choice, u, row }
    }

    /// [`Self::sample`] for paths side by side, each lane's [`LightAsk`] or `None`, handing
    /// lane `i`'s sample to `found(i, sample)`: the same samples, but an environment map's
    /// texels are asked of memory for every lane before any lane reads them (those its search
    /// reads, then those its radiance is interpolated from), so that the lanes' cache misses
    /// overlap.
    #[inline]
    pub fn sample_lanes<const N: usize>(
        &self,
        asks: &[Option<LightAsk>; N],
        mut found: impl FnMut(usize, Option<LightSample>),
    ) {
        // (A lane has a row only where an environment map was chosen.)
        let map = |ask: &LightAsk| {
            let row = ask.row?;
            match self.chosen(ask.u_choice, ask.p) {
                (PathLight::Environment(m), choice_pdf) => Some((m.as_ref(), row, choice_pdf)),
                _ => None,
            }
        };
        // Each lane's map, the row its search found, and the map's choice probability.
        type Chosen<'a> = Option<(&'a EnvMap, (f64, usize), f64)>;
        let maps: [Chosen; N] = std::array::from_fn(|i| asks[i].as_ref().and_then(map));
        for (ask, (m, row, _)) in asks.iter().zip(&maps).filter_map(|(a, m)| Some((a.as_ref()?, (*m)?))) {
            m.touch_texels(row, ask.u);
        }
        let texels: [Option<(&EnvMap, TexelSample, f64)>; N] = std::array::from_fn(|i| {
            let ((m, row, choice_pdf), ask) = (maps[i]?, asks[i].as_ref()?);
            Some((m, m.sample_texel(row, ask.u), choice_pdf))
        });
        for (i, ask) in asks.iter().enumerate() {
            let Some(ask) = ask else { continue };
            let sample = match texels[i] {
                Some((m, texel, choice_pdf)) => env_sample(m.sample_at(texel)).map(|mut s| {
                    s.pdf *= choice_pdf;
                    s
                }),
                None => self.sample(ask.p, ask.u_choice, ask.u),
            };
            found(i, sample);
        }
    }

    /// A point of light `light` seen from `p`, chosen by `u`; its density leaves out the
    /// choice of the light.
    pub fn sample_light(&self, light: usize, p: Vec3, u: Vec2) -> Option<LightSample> {
        self.sample_one(&self.lights[light], p, u)
    }

    fn sample_one(&self, light: &PathLight, p: Vec3, u: Vec2) -> Option<LightSample> {
        let delta = |to: Vec3, radiance: Vec3| {
            let d = to.length();
            (d > 0.0).then(|| LightSample { dir: to / d, dist: d, radiance: radiance / (d * d), pdf: 1.0, delta: true })
        };
        match light {
            PathLight::Point { position, intensity } => delta(*position - p, *intensity),
            PathLight::Spot { position, direction, cos_cutoff, falloff, beam, intensity } => {
                let to = *position - p;
                let cos = -to.normalize_or_zero().dot(*direction);
                if cos < *cos_cutoff {
                    return None;
                }
                delta(to, *intensity * alhazen_scene::spot_profile(cos, *cos_cutoff, *falloff, *beam))
            }
            PathLight::Directional { direction, irradiance } => Some(LightSample {
                dir: -*direction,
                dist: f64::INFINITY,
                radiance: *irradiance,
                pdf: 1.0,
                delta: true,
            }),
            PathLight::Environment(m) => env_sample(m.sample(u)),
            PathLight::Background(b) => {
                let dir = uniform_sphere(u);
                let radiance = b.radiance(dir);
                Some(LightSample { dir, dist: f64::INFINITY, radiance, pdf: 1.0 / (4.0 * PI), delta: false })
            }
            PathLight::Area { emitter, radiance, texture } => sample_area(emitter, *radiance, texture.as_deref(), p, u),
        }
    }
}

/// An area light's density per unit area when its points are drawn by area (0 for other
/// lights).
fn area_density(light: &PathLight) -> f64 {
    match light {
        PathLight::Area { emitter, .. } => match emitter {
            Emitter::Sphere { radius, .. } => 1.0 / (4.0 * PI * radius * radius),
            Emitter::Triangles { area, .. } | Emitter::Parallelogram { area, .. } => 1.0 / area,
            Emitter::Disk { radius, .. } => 1.0 / (PI * radius * radius),
        },
        _ => 0.0,
    }
}

/// The cone of directions from `p` to a sphere: its axis and `1 − cos θ_max`; `None` inside.
fn cone(p: Vec3, center: Vec3, radius: f64) -> Option<(Vec3, f64)> {
    let to = center - p;
    let d2 = to.length_squared();
    if d2 <= radius * radius * (1.0 + 1e-9) {
        return None;
    }
    let sin2 = radius * radius / d2;
    let cos = (1.0 - sin2).max(0.0).sqrt();
    Some((to / d2.sqrt(), sin2 / (1.0 + cos)))
}

/// Which triangle of an emitter a point lies on, and its barycentric weights there.
type OnTriangle = (usize, [f64; 3]);

/// A point on an emitter chosen uniformly by area: the point, its unit normal (the emitting
/// side), the area density, and the triangle it lies on (triangles only; else the first,
/// unused). Always inlined: the connections call it too, and sampling a light for next-event
/// estimation must not pay a call for it.
#[inline(always)]
fn point_by_area(emitter: &Emitter, u: Vec2) -> (Vec3, Vec3, f64, OnTriangle) {
    let nowhere = (0, [1.0, 0.0, 0.0]);
    match emitter {
        Emitter::Sphere { center, radius } => {
            let n = uniform_sphere(u);
            (*center + n * *radius, n, 1.0 / (4.0 * PI * radius * radius), nowhere)
        }
        Emitter::Triangles { triangles, by_area, area } => {
            let (x, _, i) = by_area.sample_continuous(u.x);
            let ux = x * by_area.len() as f64 - i as f64;
            let [a, b, c] = triangles[i];
            let su = ux.clamp(0.0, 1.0).sqrt();
            let (b0, b1) = (1.0 - su, u.y * su);
            let b2 = 1.0 - b0 - b1;
            let q = a * b0 + b * b1 + c * b2;
            (q, (b - a).cross(c - a).normalize_or_zero(), 1.0 / area, (i, [b0, b1, b2]))
        }
        Emitter::Parallelogram { origin, e1, e2, normal, area } => {
            (*origin + *e1 * u.x + *e2 * u.y, *normal, 1.0 / area, nowhere)
        }
        Emitter::Disk { center, normal, radius } => {
            let (s, t) = orthonormal_basis(*normal);
            let r = radius * u.x.sqrt();
            let (sin, cos) = alhazen_math::sin_cos_turns(u.y);
            (*center + (s * cos + t * sin) * r, *normal, 1.0 / (PI * radius * radius), nowhere)
        }
    }
}

/// A point on an area light: the direction, distance, radiance (0 from its back) and density.
#[inline(always)]
fn sample_area(
    emitter: &Emitter,
    radiance: Vec3,
    texture: Option<&AreaTexture>,
    p: Vec3,
    u: Vec2,
) -> Option<LightSample> {
    if let Emitter::Sphere { center, radius } = emitter
        && let Some((axis, one_minus_cos)) = cone(p, *center, *radius)
    {
        // Uniform in the cone, then the near intersection with the sphere.
        let cos = 1.0 - u.x * one_minus_cos;
        let sin = (1.0 - cos * cos).max(0.0).sqrt();
        let (sin_phi, cos_phi) = alhazen_math::sin_cos_turns(u.y);
        let (s, t) = orthonormal_basis(axis);
        let dir = (s * cos_phi + t * sin_phi) * sin + axis * cos;
        let d = (*center - p).length();
        let disc = (radius * radius - d * d * sin * sin).max(0.0);
        let dist = d * cos - disc.sqrt();
        let pdf = 1.0 / (2.0 * PI * one_minus_cos);
        return Some(LightSample { dir, dist, radiance, pdf, delta: false });
    }
    let (q, n, pdf_area, at) = point_by_area(emitter, u);
    let to = q - p;
    let d2 = to.length_squared();
    let dist = d2.sqrt();
    if dist == 0.0 {
        return None;
    }
    let dir = to / dist;
    let cos = -n.dot(dir);
    if cos <= 0.0 {
        return None; // the back of a one-sided emitter
    }
    let radiance = texture.map_or(radiance, |t| t.radiance(at));
    Some(LightSample { dir, dist, radiance, pdf: pdf_area * d2 / cos, delta: false })
}
