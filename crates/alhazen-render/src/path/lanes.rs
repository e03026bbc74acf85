//! The path tracer in lanes: paths traced side by side, whatever their materials, lights and
//! colours, so that their rays are tested together and their vertices shaded by material
//! kernels (a small wavefront: Laine, Karras and Aila 2013, "Megakernels Considered Harmful",
//! split a path tracer into stages over many paths, and queue each material's vertices apart).
//!
//! A thread keeps [`POOL`] paths in flight, in [`GROUPS`] groups of eight lanes. One bounce is
//! a round of stages over them all: each group's rays' nearest hits in one call
//! ([`crate::World::intersect_rays`]: in a world of one leaf, each ray's planes, each flat
//! against the eight rays at once, in AVX-512 or AVX2, then each ray's spheres and other
//! objects; elsewhere ray by ray); the sky seen by the rays that leave the scene
//! ([`Lights::sky_ahead`]; such a path, half of all in open scenes, ends there:
//! [`Kernel::Escaped`]); per path, the vertex, written into a batch of eight of its material
//! kernel ([`Batches`]); each batch's light samples and shading; each group's shadow rays in one call
//! ([`crate::World::unoccluded_rays`]), after which each path gathers its light and steps on. A
//! lane whose path ends starts the next sample of the pixels it was given, in place (its record
//! is not moved: a path's start costs what its hashing and camera ray cost), so lanes stay busy
//! until their samples run out; then the paths left move to the first groups.
//!
//! A vertex is shaded by its material's kernel. The general kernel is the per-path tracer's
//! own [`PathTracer::vertex`], lane by lane: every BSDF, texture, bump map, light and colour
//! mode. In RGB scenes, vertices on Lambert surfaces, on conductors (exact or Schlick's
//! Fresnel term), glass and plastic (smooth, or rough of Trowbridge–Reitz or Beckmann facets)
//! and Cook–Torrance, and two mixes (Lambert plus an ideal mirror; the glTF metallic–roughness
//! model of a partly metallic surface) — textured, bump-mapped or plain — take a material
//! kernel ([`Kernel`]) instead: their random numbers, emission, material, bent normal and specular connections
//! through the scene's mirrors per lane ([`PathTracer::kernel_vertex`]), then light points
//! (on parallelogram and point lights in lanes, [`sample_lights`]; on other lights for all
//! lanes at once, [`Lights::sample_lanes`], an
//! environment map's memory asked for every lane before any lane waits for it) and the shading
//! frame, next-event weights, bump shadowing, sampled continuation and Russian roulette
//! ([`shade`]) for all lanes at once, loops without branches the compiler turns into AVX-512 or
//! AVX2 code (`bench/vectorised.sh` checks). The kernels evaluate and sample the BSDFs through
//! the per-path tracer's own functions ([`LaneBsdf`]), written to compute whole and then
//! choose, so the two tracers share one implementation of each.
//!
//! Every lane performs exactly the floating-point operations of [`PathTracer::radiance`], in
//! the same order (no fused multiply–adds, no reassociation), draws the same numbers from its
//! own stream, and the batched ray tests find the hits the rays find alone, so every sample is
//! bit-identical to the per-path tracer's on every processor (test
//! `lanes_match_the_per_path_tracer`).

use super::{PathState, PathTracer, RR_DEPTH, Terminator, Vertex, offset, power_heuristic, shadow_segment};
use crate::bsdf::coated::{coat_albedo, coat_choice, sample_under_layer, under_coat};
use crate::bsdf::layered::{DiffuseSpecular, SpecularLobe};
use crate::bsdf::multiscatter::{MultipleScattering, Row, SeveralFacets};
use crate::bsdf::{
    BlinnPhongLobe, Bsdf, BsdfSample, Coat, ColorMode, Conductor, CookTorrance, CookTorranceLobe, Dielectric, Frame,
    Microfacet, MicrofacetLobes, OrenNayar, PhongLobe, Plastic, cosine_hemisphere, cosine_pdf, same_side,
};
use crate::lights::{Emitter, LightAsk, LightSample, Lights, PathLight};
use crate::sampler::{PixelSeeds, SampleStream, StreamStart};
use crate::shape::{RayPacket, VectorUnit};
use crate::spectrum::{sample_wavelengths, spectrum_to_rgb};
use crate::world::{HitPoint, WorldHit};
use alhazen_math::{Ray, Vec2, Vec3};
use std::f64::consts::FRAC_1_PI;
use std::ops::Range;

/// Paths traced side by side: one AVX-512 register of `f64` (two AVX2 ones).
const LANES: usize = 8;

/// One number per lane.
type Lanes = [f64; LANES];

/// One vector per lane, component by component (a [`RayPacket`]'s layout).
type Lanes3 = [Lanes; 3];

/// One flag per lane, 0 or 1, in words as wide as [`Lanes`]' numbers: the kernels' loads and
/// stores then all step by the same stride, and their masks are as wide as their numbers, which
/// the compiler needs to vectorise their loops for AVX2.
#[derive(Clone, Copy, Debug, Default)]
struct Flags([u64; LANES]);

impl Flags {
    #[inline(always)]
    fn at(&self, i: usize) -> bool {
        self.0[i] != 0
    }

    #[inline(always)]
    fn put(&mut self, i: usize, on: bool) {
        self.0[i] = u64::from(on);
    }

    /// Some lane's flag is set.
    fn any(&self) -> bool {
        self.0.iter().any(|&f| f != 0)
    }
}

#[inline(always)]
fn get(v: &Lanes3, i: usize) -> Vec3 {
    Vec3::new(v[0][i], v[1][i], v[2][i])
}

#[inline(always)]
fn set(v: &mut Lanes3, i: usize, x: Vec3) {
    (v[0][i], v[1][i], v[2][i]) = (x.x, x.y, x.z);
}

/// What the per-path stage leaves for [`shade`], lane by lane.
#[derive(Clone, Debug, Default)]
#[repr(C, align(64))]
struct Vertices {
    /// Towards the viewer (`−ray.dir`).
    wo: Lanes3,
    p: Lanes3,
    /// Geometric and shading normals as the surface reports them, the shading normal bent by
    /// the bump or normal map where there is one (`bumped`), and the unbent one.
    ng: Lanes3,
    ns: Lanes3,
    n0: Lanes3,
    bumped: Flags,
    /// A Lambert surface's or a plastic's albedo; a Cook–Torrance surface's diffuse colour
    /// (times `k_d`) and its `k_s`.
    albedo: Lanes3,
    ks: Lanes,
    /// A Cook–Torrance surface's specular weight its diffuse term is layered under (0 for
    /// none: [`CookTorranceLobe::layer`]), and the weight of that term seen from the viewer
    /// ([`weigh_layers`]).
    layer: Lanes,
    diffuse_weight: Lanes,
    /// A mix's weight of its first component ([`crate::bsdf::Mix`]).
    mix_weight: Lanes,
    /// A rough dielectric's relative index `η_inside/η_outside`, or a plastic coat's;
    /// Blinn–Phong's anisotropy `a`.
    ior: Lanes,
    /// A plastic's colouring of its inner reflection (its coat is its batch's: [`Batch::coat`]);
    /// whether an Oren–Nayar surface adds its interreflection term.
    nonlinear: Flags,
    /// A rough conductor's index `η + iκ` and tint (a glass's tint: what its refracted light
    /// keeps, white where clear); the roughnesses `m_u, m_v` of a rough
    /// conductor or dielectric, and its tangent where it is anisotropic (`tangent_given`).
    /// The kernels of other materials keep their numbers in these lanes too (four more
    /// fields cost the Cornell boxes 2 %): an Oren–Nayar surface's roughness `σ` in `alpha[0]`,
    /// a Phong or Blinn–Phong lobe's exponent in `alpha[1]`, Blinn–Phong's scratches in
    /// `tangent`.
    eta: Lanes3,
    k: Lanes3,
    tint: Lanes3,
    alpha: [Lanes; 2],
    tangent: Lanes3,
    tangent_given: Flags,
    beta: Lanes3,
    /// The path's product of squared relative indices so far (for roulette).
    eta_scale: Lanes,
    /// The light sample, valid where `light` is set (it exists, has radiance and density).
    light: Flags,
    light_dir: Lanes3,
    light_dist: Lanes,
    light_radiance: Lanes3,
    light_pdf: Lanes,
    light_delta: Flags,
    /// The continuation's lobe choice (where the BSDF has lobes to choose) and two numbers,
    /// and roulette's where `roulette` is set.
    u_lobe: Lanes,
    u_bsdf: [Lanes; 2],
    roulette: Flags,
    u_roulette: Lanes,
    /// A coated kernel's coats, made when its batch first needs them (in the batch's own
    /// lanes, their fields cost every kernel: see `alpha`).
    coats: Option<Box<CoatLanes>>,
    /// The metals' light of several facets ([`Conductor::multiscatter`]) of a kernel whose
    /// metals give it back, made when its batch first needs it (as `coats`); the lobe seen
    /// from the viewer is the batch's [`Batch::several_seen`].
    several: Option<Box<[SeveralFacets; LANES]>>,
}

/// Each lane's clear coat ([`crate::bsdf::Coated`]) over the base the other lanes describe: its
/// weight, its facets' roughness (isotropic Trowbridge–Reitz, Smith's shadowing), its index and
/// where that roughness falls in the albedo table, and its albedo towards the viewer
/// (`weigh_layers`).
#[derive(Clone, Debug, Default)]
#[repr(C, align(64))]
struct CoatLanes {
    weight: Lanes,
    alpha: Lanes,
    ior: Lanes,
    albedo: Lanes,
    row: [Row; LANES],
}

/// The coats of a batch without any.
static NO_COATS: std::sync::LazyLock<CoatLanes> = std::sync::LazyLock::new(CoatLanes::default);

/// The metals' facets of a batch without any.
static NO_FACETS: std::sync::LazyLock<[SeveralFacets; LANES]> = std::sync::LazyLock::new(Default::default);

// Every eight-lane field of the lanes' records lies on a cache line of its own: each record is
// aligned to 64 bytes and its lane fields (multiples of 64 bytes) come before its others.
const _: () = {
    use std::mem::offset_of;
    assert!(offset_of!(Vertices, coats) % 64 == 0);
    assert!(offset_of!(CoatLanes, row) % 64 == 0);
    assert!(offset_of!(LightLanes, point) % 64 == 0);
};

/// A parallelogram light as the lanes sample it ([`crate::lights`]' `sample_area`) or a point
/// light (`point`: at `corner`, `radiance` its intensity, as `Lights::sample` takes it).
#[derive(Clone, Copy, Debug)]
pub(super) struct LaneLight {
    corner: Vec3,
    e1: Vec3,
    e2: Vec3,
    normal: Vec3,
    /// `1 / area`.
    pdf_area: f64,
    radiance: Vec3,
    point: bool,
}

/// The lights samples choose among in lane form when every one is a parallelogram or a point
/// (the lanes then sample them too; a sky of one colour is not among them for the path tracer,
/// [`crate::lights::LightSampling::AgainstBsdf`], and where it is, `Lights::sample` samples it).
pub(super) fn lane_lights(lights: &Lights) -> Option<Vec<LaneLight>> {
    let none = LaneLight {
        corner: Vec3::ZERO,
        e1: Vec3::ZERO,
        e2: Vec3::ZERO,
        normal: Vec3::ZERO,
        pdf_area: 0.0,
        radiance: Vec3::ZERO,
        point: false,
    };
    let lane = |light: &PathLight| match *light {
        PathLight::Area {
            emitter: Emitter::Parallelogram { origin, e1, e2, normal, area },
            radiance,
            texture: None,
        } => Some(LaneLight { corner: origin, e1, e2, normal, pdf_area: 1.0 / area, radiance, ..none }),
        PathLight::Point { position, intensity } => {
            Some(LaneLight { corner: position, radiance: intensity, point: true, ..none })
        }
        _ => None,
    };
    lights.all()[..lights.choices()].iter().map(lane).collect::<Option<Vec<_>>>().filter(|all| !all.is_empty())
}

/// Where the lanes sample parallelogram and point lights: each lane's light and its two
/// numbers.
#[derive(Clone, Debug, Default)]
#[repr(C, align(64))]
struct LightLanes {
    corner: Lanes3,
    e1: Lanes3,
    e2: Lanes3,
    normal: Lanes3,
    pdf_area: Lanes,
    /// The probability of the lane's light's choice among the lights.
    choice_pdf: Lanes,
    u: [Lanes; 2],
    /// The lane samples a point light; `any_point`: some light is a point.
    point: [bool; LANES],
    any_point: bool,
    /// When some light is an environment map: what each lane asks of [`Lights::sample_lanes`]
    /// ([`Lights::ask`]), `None` where it asks nothing.
    asks: [Option<LightAsk>; LANES],
}

/// What [`shade`] returns, lane by lane.
#[derive(Clone, Debug, Default)]
#[repr(C, align(64))]
struct Shaded {
    /// Next-event contribution (before `beta`) if the shadow ray is clear; zero when there is
    /// no light to test (`shadow` unset).
    light: Lanes3,
    shadow: Flags,
    shadow_origin: Lanes3,
    shadow_dir: Lanes3,
    shadow_dist: Lanes,
    /// The path goes on (`alive`) from `origin` along `dir`, sampled with density `pdf` (a
    /// delta distribution's where `delta` is set), carrying `beta` and `eta_scale`.
    alive: Flags,
    delta: Flags,
    origin: Lanes3,
    dir: Lanes3,
    pdf: Lanes,
    beta: Lanes3,
    eta_scale: Lanes,
}

/// Paths in flight per thread: `GROUPS` packets of [`LANES`] rays, each traced together. Their
/// vertices are shaded in batches of [`LANES`] by material kernel ([`Batches`]), so that a
/// kernel's loop runs on vertices of its own material (a small wavefront's queues, sorted by
/// material), not on every lane of a bounce whatever its material. Sixty-four paths: more
/// vertices of each material fill the batches, and a lane's start and its hashing overlap more
/// of the others' work (with lanes restarted in place, 2–3.5 % faster than 32 on four of the
/// suite's scenes; 128 gained nothing more).
const GROUPS: usize = 8;
const POOL: usize = GROUPS * LANES;

/// Up to [`LANES`] vertices of one material kernel in a bounce (slots `..len`; the rest hold
/// stale values the kernel computes and no path reads), their light samples and shading.
#[derive(Clone, Debug)]
struct Batch {
    kernel: Kernel,
    /// A plastic kernel's coat, the same for every vertex of the batch: the kernel reads its
    /// numbers through one pointer, its function's argument, which the compiler can tell from
    /// the records it writes (through a pointer per lane it cannot, and the loop stays scalar).
    coat: Option<&'static Coat>,
    len: usize,
    vertices: Vertices,
    /// The lobe of several facets of each vertex's metal seen from its viewer, with the
    /// probability of sampling it (`weigh_layers`): found once for the vertex's light sample,
    /// its continuation and their evaluations, where the per-path tracer finds it for each.
    /// Handed to the kernel beside the vertices ([`Tables`]): read through a pointer kept in
    /// the vertices' records, the kernel's loop stayed scalar.
    several_seen: Box<[(MultipleScattering, f64); LANES]>,
    lights: LightLanes,
    shaded: Shaded,
}

/// What a batch's kernel reads besides its vertices, each table through a pointer of its own
/// (function arguments, which the compiler can tell from the records the kernel writes, and
/// may read ahead of a branch): the plastics' coat, the metals' lobes seen from the viewer.
#[derive(Clone, Copy)]
struct Tables<'a> {
    coat: &'static Coat,
    several_seen: &'a [(MultipleScattering, f64); LANES],
}

/// A bounce's batches (`all[..used]`); each kernel's newest one (`open`) takes its next vertex.
struct Batches {
    all: Vec<Batch>,
    used: usize,
    open: [Option<usize>; MATERIAL_KERNELS.len()],
    /// Whether some light is a point (see [`LightLanes::any_point`]).
    any_point: bool,
}

impl Batches {
    /// Batches in the storage `all` (a thread's, kept from its last call: see [`SPARE_BATCHES`]).
    fn reusing(all: Vec<Batch>, any_point: bool) -> Self {
        Batches { all, used: 0, open: [None; MATERIAL_KERNELS.len()], any_point }
    }

    /// Empties every batch for the next bounce (their storage kept).
    fn clear(&mut self) {
        self.used = 0;
        self.open = [None; MATERIAL_KERNELS.len()];
    }

    /// A free slot for a vertex of material kernel `kernel` (a plastic's of coat `coat`): its
    /// batch and slot.
    fn slot(&mut self, kernel: Kernel, coat: Option<&'static Coat>) -> (usize, usize) {
        let k = kernel.shaded();
        let takes = |b: &Batch| b.len < LANES && same_coat(b.coat, coat);
        // The kernel's newest batch, or (plastics of several coats) an older one of this coat.
        let open = self.open[k].filter(|&b| takes(&self.all[b])).or_else(|| {
            coat.and_then(|_| (0..self.used).find(|&b| self.all[b].kernel == kernel && takes(&self.all[b])))
        });
        if let Some(b) = open {
            self.all[b].len += 1;
            return (b, self.all[b].len - 1);
        }
        if self.used == self.all.len() {
            let lights = LightLanes { any_point: self.any_point, ..LightLanes::default() };
            let (vertices, shaded) = (Vertices::default(), Shaded::default());
            let several_seen = Box::new([(MultipleScattering::default(), 0.0); LANES]);
            self.all.push(Batch { kernel, coat, len: 0, vertices, several_seen, lights, shaded });
        }
        let b = self.used;
        self.used += 1;
        self.open[k] = Some(b);
        let batch = &mut self.all[b];
        (batch.kernel, batch.coat, batch.len) = (kernel, coat, 1);
        batch.lights.any_point = self.any_point;
        // What a slot is not sure to overwrite: a stale bent normal would only cost the bump
        // kernel's work, a stale ask a light sample.
        batch.vertices.bumped = Flags::default();
        batch.lights.asks = [None; LANES];
        (b, 0)
    }
}

/// The same coat (or none), by address: a scene's coats are made once each.
fn same_coat(a: Option<&'static Coat>, b: Option<&'static Coat>) -> bool {
    a.map(std::ptr::from_ref) == b.map(std::ptr::from_ref)
}

thread_local! {
    /// Each thread's batches between calls of [`PathTracer::pixels_in_lanes`]: a call that made
    /// its own grew them anew, their 14 KB apiece cleared and copied for every row of pixels.
    static SPARE_BATCHES: std::cell::RefCell<Vec<Batch>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// Samples whose streams' starts [`PathTracer::starts_ahead`] computes together, two at a time
/// in AVX-512 registers (an empty scene −13 %, the suite's scenes −0.4 to −3 %; computed ahead
/// one at a time, nothing changed: the hashing's cost is its instructions, not its latency).
const STARTS_AHEAD: usize = 32;

/// The stream starts of the next jobs of a thread's lanes.
#[derive(Default)]
struct StartsAhead {
    /// The jobs whose starts `starts` holds, the first at `starts[0]`.
    jobs: Range<usize>,
    starts: [StreamStart; STARTS_AHEAD],
    /// The pixel whose seeds were last made, and its seeds.
    seeds: Option<((u32, u32), PixelSeeds)>,
}

/// One sample's path in a lane, or none: a lane's record stays in its place and is restarted
/// there (moved in whole, its ~350 bytes cost more than the start itself).
struct LanePath {
    /// A path is in the lane.
    live: bool,
    /// Where its result goes.
    job: usize,
    path: PathState,
    stream: SampleStream,
    /// RGB, or the wavelengths of a spectral sample.
    mode: ColorMode,
    /// The pixel filter's weight of the sample.
    weight: f64,
}

/// What a material kernel's vertex gathers through mirrors, from [`PathTracer::kernel_vertex`]
/// to [`finish_kernel`] within one bounce: the light its specular connections brought, and the
/// mirror visit its continuation records if it samples a delta lobe. Kept beside the pool, not
/// in its records: few scenes have mirrors, and every pass over the pool reads the records.
#[derive(Clone, Copy, Default)]
struct KernelMirrors {
    mirrored: Option<Vec3>,
    visit: Option<super::mirrors::MirrorVisit>,
}

impl LanePath {
    /// An idle lane.
    fn idle() -> Self {
        let path = PathState::new(Ray::new(Vec3::ZERO, Vec3::Z));
        let stream = SampleStream::default();
        Self { live: false, job: 0, path, stream, mode: ColorMode::Rgb, weight: 1.0 }
    }

    /// The sample's value: its radiance, in RGB, times its filter weight.
    fn value(&self) -> Vec3 {
        let l = match self.mode {
            ColorMode::Spectral(lambdas) => spectrum_to_rgb(self.path.l, &lambdas),
            ColorMode::Rgb => self.path.l,
        };
        l * self.weight
    }
}

/// How a vertex is shaded: per material, and per lane in each bounce.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Kernel {
    /// No path in the lane.
    Idle,
    /// [`PathTracer::vertex`]: its result in the lane's [`Vertex`].
    General,
    /// The path's ray left the scene: the sky it sees added as [`PathTracer::vertex`] adds
    /// it, the path ended (half of all vertices in the suite's open scenes).
    Escaped,
    /// Lambert: textured or not, bump-mapped or not.
    Lambert,
    /// The course's rough diffuse reflection ([`OrenNayar`]).
    OrenNayar,
    /// The course's Phong and (anisotropic) Blinn–Phong lobes over Lambert, normalised.
    Phong,
    BlinnPhong,
    /// A rough conductor of Trowbridge–Reitz facets with Smith's shadowing and the exact
    /// Fresnel term ([`conductor_facets`]): textured or not, bump-mapped or not, anisotropic
    /// or not.
    RoughConductor,
    /// A rough dielectric of Trowbridge–Reitz facets with Smith's shadowing, the exact
    /// Fresnel term and an index that does not disperse ([`dielectric_facets`]).
    RoughDielectric,
    /// Plastic under a rough coat of Trowbridge–Reitz facets with Smith's shadowing.
    RoughPlastic,
    /// A smooth conductor (a mirror, coloured by its Fresnel term), exact Fresnel term.
    SmoothConductor,
    /// Smooth glass of an index that does not disperse, exact Fresnel term.
    SmoothDielectric,
    /// Plastic under a smooth coat.
    SmoothPlastic,
    /// [`Kernel::RoughConductor`], [`Kernel::RoughDielectric`] and [`Kernel::RoughPlastic`]
    /// with Beckmann facets.
    BeckmannConductor,
    BeckmannDielectric,
    BeckmannPlastic,
    /// The course's Cook–Torrance model (Lambert plus a dielectric microfacet lobe, exact
    /// Fresnel term) on isotropic Trowbridge–Reitz or Beckmann facets with Smith's shadowing:
    /// what a glTF material's dielectric base becomes.
    CookTorrance,
    BeckmannCookTorrance,
    /// [`Kernel::RoughConductor`], [`Kernel::BeckmannConductor`] and
    /// [`Kernel::SmoothConductor`] with Schlick's Fresnel term: a glTF metal's.
    RoughSchlickConductor,
    BeckmannSchlickConductor,
    SmoothSchlickConductor,
    /// Lambert plus an ideal mirror ([`crate::bsdf::Mix`] of a smooth conductor, exact
    /// Fresnel term, and Lambert): the course's Whitted material as the path tracer reads it.
    LambertMirror,
    /// The glTF metallic–roughness model where it is partly metallic (a metallic factor, or a
    /// metallic texture's mean, between 0 and 1): a [`crate::bsdf::Mix`] of a rough conductor
    /// with Schlick's term and Cook–Torrance, both on isotropic Trowbridge–Reitz facets.
    MetallicRoughness,
    /// A clear coat ([`crate::bsdf::Coated`]: isotropic Trowbridge–Reitz facets, Smith's
    /// shadowing, exact Fresnel term) over Lambert, Cook–Torrance or the metallic–roughness mix
    /// (glTF's `KHR_materials_clearcoat` over its base).
    CoatedLambert,
    CoatedCookTorrance,
    CoatedMetallicRoughness,
    /// [`Kernel::MetallicRoughness`] and [`Kernel::CoatedMetallicRoughness`] whose metal gives
    /// back the light of several facets ([`Conductor::multiscatter`]), and rough conductors
    /// that do (Trowbridge–Reitz facets, Smith's shadowing; exact or Schlick's Fresnel term):
    /// every glTF material's, as Blender's Principled BSDF has it.
    SeveralMetallicRoughness,
    CoatedSeveralMetallicRoughness,
    SeveralConductor,
    SeveralSchlickConductor,
    /// A thin sheet of glass (a window: [`Dielectric::thin`]), exact Fresnel term, an index
    /// that does not disperse.
    ThinDielectric,
}

/// The material kernels, in the order of the lanes' [`Shaded`] they write (their order in
/// [`Kernel`]).
const MATERIAL_KERNELS: [Kernel; 28] = [
    Kernel::Lambert,
    Kernel::OrenNayar,
    Kernel::Phong,
    Kernel::BlinnPhong,
    Kernel::RoughConductor,
    Kernel::RoughDielectric,
    Kernel::RoughPlastic,
    Kernel::SmoothConductor,
    Kernel::SmoothDielectric,
    Kernel::SmoothPlastic,
    Kernel::BeckmannConductor,
    Kernel::BeckmannDielectric,
    Kernel::BeckmannPlastic,
    Kernel::CookTorrance,
    Kernel::BeckmannCookTorrance,
    Kernel::RoughSchlickConductor,
    Kernel::BeckmannSchlickConductor,
    Kernel::SmoothSchlickConductor,
    Kernel::LambertMirror,
    Kernel::MetallicRoughness,
    Kernel::CoatedLambert,
    Kernel::CoatedCookTorrance,
    Kernel::CoatedMetallicRoughness,
    Kernel::SeveralMetallicRoughness,
    Kernel::CoatedSeveralMetallicRoughness,
    Kernel::SeveralConductor,
    Kernel::SeveralSchlickConductor,
    Kernel::ThinDielectric,
];

impl Kernel {
    /// Which of the lanes' [`Shaded`] a material kernel writes.
    fn shaded(self) -> usize {
        (self as usize).saturating_sub(Kernel::Lambert as usize)
    }

    /// A material kernel (not idle, not the general one).
    fn is_material(self) -> bool {
        !matches!(self, Kernel::Idle | Kernel::General | Kernel::Escaped)
    }

    /// The kernel's BSDF has lobes to choose between (it draws a number for the choice).
    fn chooses_lobe(self) -> bool {
        matches!(
            self,
            Kernel::Phong
                | Kernel::BlinnPhong
                | Kernel::RoughDielectric
                | Kernel::RoughPlastic
                | Kernel::SmoothDielectric
                | Kernel::SmoothPlastic
                | Kernel::BeckmannDielectric
                | Kernel::BeckmannPlastic
                | Kernel::CookTorrance
                | Kernel::BeckmannCookTorrance
                | Kernel::LambertMirror
                | Kernel::MetallicRoughness
                | Kernel::CoatedLambert
                | Kernel::CoatedCookTorrance
                | Kernel::CoatedMetallicRoughness
                | Kernel::SeveralMetallicRoughness
                | Kernel::CoatedSeveralMetallicRoughness
                | Kernel::SeveralConductor
                | Kernel::SeveralSchlickConductor
                | Kernel::ThinDielectric
        )
    }

    /// The kernel's BSDF is a delta distribution: its vertices sample no light.
    fn is_delta(self) -> bool {
        matches!(
            self,
            Kernel::SmoothConductor
                | Kernel::SmoothSchlickConductor
                | Kernel::SmoothDielectric
                | Kernel::ThinDielectric
        )
    }

    /// The kernel's BSDF has a delta lobe (a path may leave its vertices specularly).
    fn samples_delta(self) -> bool {
        self.is_delta() || matches!(self, Kernel::SmoothPlastic | Kernel::LambertMirror)
    }
}

/// Per material: the kernel its vertices take, in a scene whose vertices may take material
/// kernels (RGB). A material's kind of BSDF does not vary over its
/// surface (textures vary colours only), so the BSDF at any point tells (checked at each hit in
/// debug builds).
pub(super) fn material_kernels(tracer: &PathTracer) -> Vec<Kernel> {
    let scene_allows = !tracer.spectral;
    let images = &tracer.scene.images;
    let kernel = |m| kernel_of(&crate::bsdf::bsdf_at(m, Vec2::ZERO, Vec3::ONE, images, ColorMode::Rgb), m);
    tracer.scene.materials.iter().map(|m| if scene_allows { kernel(m) } else { Kernel::General }).collect()
}

/// The kernel of `bsdf`, material `m`'s at some point.
fn kernel_of(bsdf: &Bsdf, m: &alhazen_scene::Material) -> Kernel {
    match bsdf {
        // So is a translucent sheet's (the kernels shade reflection only).
        _ if translucent(m) => Kernel::General,
        Bsdf::Lambert(_) if !crate::bsdf::is_anisotropic(m) => Kernel::Lambert,
        Bsdf::OrenNayar(_) => Kernel::OrenNayar,
        Bsdf::Phong(p) if p.transmittance == Vec3::ZERO => Kernel::Phong,
        Bsdf::BlinnPhong(b) if b.transmittance == Vec3::ZERO => Kernel::BlinnPhong,
        // A filmed metal is the general kernel's; one that gives back the light of several
        // facets takes its own kernel where its facets are Trowbridge–Reitz with Smith's
        // shadowing (the only ones whose albedo is tabulated).
        Bsdf::Conductor(c) if c.film.is_some() => Kernel::General,
        Bsdf::Conductor(c) if c.multiscatter.is_some() => match (conductor_facets(c), c.schlick) {
            (Some(false), false) => Kernel::SeveralConductor,
            (Some(false), true) => Kernel::SeveralSchlickConductor,
            _ => Kernel::General,
        },
        Bsdf::Conductor(c) => match (c.facets.map(|_| conductor_facets(c)), c.schlick) {
            (None, false) => Kernel::SmoothConductor,
            (None, true) => Kernel::SmoothSchlickConductor,
            (Some(Some(false)), false) => Kernel::RoughConductor,
            (Some(Some(true)), false) => Kernel::BeckmannConductor,
            (Some(Some(false)), true) => Kernel::RoughSchlickConductor,
            (Some(Some(true)), true) => Kernel::BeckmannSchlickConductor,
            (Some(None), _) => Kernel::General,
        },
        Bsdf::Dielectric(d) if d.thin && d.film.is_none() && d.facets.is_none() && !d.schlick && !d.dispersive => {
            Kernel::ThinDielectric
        }
        Bsdf::Dielectric(d) if d.thin || d.film.is_some() => Kernel::General,
        Bsdf::Dielectric(d) if d.facets.is_none() && !d.schlick && !d.dispersive => Kernel::SmoothDielectric,
        Bsdf::Dielectric(d) => match dielectric_facets(d) {
            Some(false) => Kernel::RoughDielectric,
            Some(true) => Kernel::BeckmannDielectric,
            None => Kernel::General,
        },
        Bsdf::Plastic(p) if p.facets.is_none() => Kernel::SmoothPlastic,
        Bsdf::Plastic(p) => match plastic_facets(p) {
            Some(false) => Kernel::RoughPlastic,
            Some(true) => Kernel::BeckmannPlastic,
            None => Kernel::General,
        },
        Bsdf::CookTorrance(c) => match cook_torrance_facets(c) {
            Some(false) => Kernel::CookTorrance,
            Some(true) => Kernel::BeckmannCookTorrance,
            None => Kernel::General,
        },
        Bsdf::Coated(c) if lane_coat(c) => match kernel_of(&c.base, m) {
            Kernel::Lambert => Kernel::CoatedLambert,
            Kernel::CookTorrance => Kernel::CoatedCookTorrance,
            Kernel::MetallicRoughness => Kernel::CoatedMetallicRoughness,
            Kernel::SeveralMetallicRoughness => Kernel::CoatedSeveralMetallicRoughness,
            _ => Kernel::General,
        },
        Bsdf::Mix(mix) if lambert_mirror(mix).is_some() && !crate::bsdf::is_anisotropic(m) => Kernel::LambertMirror,
        Bsdf::Mix(mix)
            if let Some((metal, ..)) = metallic_roughness(mix)
                && !crate::bsdf::is_anisotropic(m) =>
        {
            match metal.multiscatter {
                None => Kernel::MetallicRoughness,
                Some(_) => Kernel::SeveralMetallicRoughness,
            }
        }
        _ => Kernel::General,
    }
}

/// True where `m` passes light diffusely through somewhere (a Cook–Torrance `transmittance`
/// that is not black, a metallic–roughness coating's diffuse transmission).
fn translucent(m: &alhazen_scene::Material) -> bool {
    use alhazen_scene::bsdf::BsdfDesc;
    fn walk(d: &BsdfDesc) -> bool {
        match d {
            BsdfDesc::CookTorrance { transmittance, .. } => *transmittance != alhazen_scene::Texture::Solid(Vec3::ZERO),
            BsdfDesc::MetallicRoughness { translucency, .. } => translucency.factor > 0.0,
            BsdfDesc::Mix { a, b, .. } => walk(a) || walk(b),
            BsdfDesc::Coated { base, .. } | BsdfDesc::Sheened { base, .. } => walk(base),
            _ => false,
        }
    }
    m.bsdf.as_ref().is_some_and(walk)
}

/// For a conductor a rough kernel evaluates — Trowbridge–Reitz or Beckmann facets with Smith's
/// shadowing (the lanes' [`Microfacet::smith`]), the exact or Schlick's Fresnel term — whether
/// its facets are Beckmann's.
fn conductor_facets(c: &Conductor) -> Option<bool> {
    c.facets?.smith_kind()
}

/// A mix's mirror, Lambert and the mirror's weight, where it is an ideal mirror (a smooth
/// conductor, exact Fresnel term) mixed with Lambert.
fn lambert_mirror(mix: &crate::bsdf::Mix) -> Option<(&Conductor, &crate::bsdf::Lambert, f64)> {
    match (&mix.a, &mix.b) {
        (Bsdf::Conductor(c), Bsdf::Lambert(l)) if c.facets.is_none() && !c.schlick && c.film.is_none() => {
            Some((c, l, mix.weight))
        }
        _ => None,
    }
}

/// A mix's metal, its Cook–Torrance base and the metal's weight, where it is the glTF
/// metallic–roughness model's mix: a rough conductor with Schlick's term and Cook–Torrance (exact
/// term), both on isotropic Trowbridge–Reitz facets.
fn metallic_roughness(mix: &crate::bsdf::Mix) -> Option<(&Conductor, &CookTorrance, f64)> {
    match (&mix.a, &mix.b) {
        (Bsdf::Conductor(c), Bsdf::CookTorrance(base))
            if c.schlick
                && c.film.is_none()
                && conductor_facets(c) == Some(false)
                && c.facets.is_some_and(|f| f.alpha_u == f.alpha_v)
                && cook_torrance_facets(base) == Some(false) =>
        {
            Some((c, base, mix.weight))
        }
        _ => None,
    }
}

/// A coat the coated kernels take: isotropic Trowbridge–Reitz facets with Smith's shadowing,
/// the exact Fresnel term, not layered itself.
fn lane_coat(c: &crate::bsdf::Coated) -> bool {
    let f = &c.coat.facets;
    f.smith_kind() == Some(false) && f.alpha_u == f.alpha_v && !c.coat.schlick && c.coat.layer == 0.0
}

/// [`conductor_facets`] for a dielectric of one index for every colour.
fn dielectric_facets(d: &Dielectric) -> Option<bool> {
    d.facets.filter(|_| !d.schlick && !d.dispersive)?.smith_kind()
}

/// [`conductor_facets`] for plastic: a coat of isotropic facets.
fn plastic_facets(p: &Plastic) -> Option<bool> {
    p.facets.filter(|f| f.alpha_u == f.alpha_v)?.smith_kind()
}

/// [`conductor_facets`] for Cook–Torrance: isotropic facets, the exact Fresnel term.
fn cook_torrance_facets(c: &CookTorrance) -> Option<bool> {
    Some(c.lobe.facets).filter(|f| !c.lobe.schlick && f.alpha_u == f.alpha_v)?.smith_kind()
}

impl PathTracer<'_> {
    /// True where the processor has a vector unit (AVX2 or AVX-512) for the kernels: the
    /// lanes are then faster than paths one by one. (Portably the material kernels' loops are
    /// exact but scalar, and slower than the per-path tracer.)
    pub(super) fn lanes_apply(&self) -> bool {
        let unit = self.world.vector_unit();
        unit.is_avx512() || unit.is_avx2()
    }

    /// Samples `first..` of `pixels`, traced in lanes: `out` holds each pixel's samples in
    /// turn, sample `first + i` of pixel `p` at `out[p × n + i]` (`n` samples per pixel).
    pub(super) fn pixels_in_lanes(&self, pixels: &[(u32, u32)], first: u32, out: &mut [Vec3]) {
        let any = |kind: fn(&LaneLight) -> bool| self.lane_lights.as_ref().is_some_and(|all| all.iter().any(kind));
        let mut batches = Batches::reusing(SPARE_BATCHES.take(), any(|k| k.point));
        self.trace_in_lanes(pixels, first, out, &mut batches);
        SPARE_BATCHES.set(batches.all);
    }

    /// [`Self::pixels_in_lanes`] with the vertices shaded in `batches`.
    fn trace_in_lanes(&self, pixels: &[(u32, u32)], first: u32, out: &mut [Vec3], batches: &mut Batches) {
        let mut lanes: [LanePath; POOL] = std::array::from_fn(|_| LanePath::idle());
        let spp = out.len() / pixels.len().max(1);
        let mut next = 0..out.len();
        let unit = self.world.vector_unit();
        let mut ahead = StartsAhead::default();
        let mut rays = [RayPacket::default(); GROUPS];
        let mut hits: [[Option<WorldHit>; LANES]; GROUPS] = [[None; LANES]; GROUPS];
        let mut general: [Vertex; POOL] = std::array::from_fn(|_| Vertex::default());
        let mut kernels = [Kernel::Idle; POOL];
        let mut mirrors = [KernelMirrors::default(); POOL];
        let mut at = [(0, 0); POOL];
        let (mut shadows, mut dist) = ([RayPacket::default(); GROUPS], [[0.0; LANES]; GROUPS]);
        let together = self.world.traces_rays_together();
        loop {
            // Idle lanes start the pixels' next samples: their streams, then their film positions
            // and camera rays (two short loops whose iterations the processor overlaps, where one
            // long one would wait on each lane's hashing and square root in turn). Each group's
            // rays are traced together.
            let mut starting: [Option<(u32, u32)>; POOL] = [None; POOL];
            for (p, lane) in lanes.iter_mut().enumerate().filter(|(_, l)| !l.live) {
                let Some(job) = next.next() else { break };
                if !ahead.jobs.contains(&job) {
                    self.starts_ahead(pixels, first, spp, job..(job + STARTS_AHEAD).min(out.len()), &mut ahead);
                }
                lane.stream.restart_from(self.sequence, &ahead.starts[job - ahead.jobs.start]);
                (lane.live, lane.job, starting[p]) = (true, job, Some(pixels[job / spp]));
            }
            for (p, lane) in lanes.iter_mut().enumerate() {
                let Some(pixel) = starting[p] else { continue };
                self.start(lane, pixel);
                rays[p / LANES].set(p % LANES, &lane.path.ray);
            }
            if next.is_empty() {
                // No samples left to start: the paths still going move to the first groups, so
                // that the last bounces trace as few packets as there are paths to fill.
                if !gather_paths(&mut lanes, &mut rays) {
                    return;
                }
            }
            let live: [[bool; LANES]; GROUPS] =
                std::array::from_fn(|g| std::array::from_fn(|i| lanes[g * LANES + i].live));
            // Under an environment map every lane's hit is needed before the vertices (for the
            // sky lookups below); otherwise rays not traced together are traced in the
            // per-path stage, where a local hit costs no copy into `hits`.
            let sky_map = self.lights.sky_is_environment();
            if together {
                for g in (0..GROUPS).filter(|&g| live[g].contains(&true)) {
                    self.world.intersect_rays(&rays[g], live[g], &mut hits[g]);
                }
            } else if sky_map {
                for (p, lane) in lanes.iter().enumerate().filter(|(_, l)| l.live) {
                    hits[p / LANES][p % LANES] = self.world.intersect(&lane.path.ray, f64::INFINITY);
                }
            }
            // Rays that leave the scene see an environment map, looked up for all lanes together
            // (other skies in `vertex`).
            let escaping: [Option<Vec3>; POOL] = if sky_map {
                std::array::from_fn(|p| {
                    let lane = &lanes[p];
                    let escapes =
                        hits[p / LANES][p % LANES].is_none() && lane.path.depth <= self.scene.render.max_depth;
                    (lane.live && escapes).then_some(lane.path.ray.dir)
                })
            } else {
                [None; POOL]
            };
            // Their texels are asked of memory now and read when the paths finish the bounce.
            let sky_texels = escaping.iter().any(Option::is_some).then(|| self.lights.sky_ahead(&escaping, unit));
            batches.clear();
            let mut tested = [[false; LANES]; GROUPS];
            for (p, lane) in lanes.iter_mut().enumerate() {
                let (g, i) = (p / LANES, p % LANES);
                kernels[p] = Kernel::Idle;
                if !lane.live {
                    continue;
                }
                if escaping[p].is_some() {
                    // As `vertex` ends a path whose ray leaves the scene (its sky added below).
                    kernels[p] = Kernel::Escaped;
                    continue;
                }
                let traced = together || sky_map;
                let alone = if traced { None } else { self.world.intersect(&lane.path.ray, f64::INFINITY) };
                let hit = if traced { hits[g][i].as_ref() } else { alone.as_ref() };
                if hit.is_none() {
                    // As `vertex` ends a path whose ray leaves the scene.
                    kernels[p] = Kernel::Escaped;
                    let path = &mut lane.path;
                    if path.depth <= self.scene.render.max_depth
                        && let Some(sky) = self.escaped_inline(&path.ray, &path.prev, path.beta, lane.mode)
                    {
                        path.l += sky;
                    }
                    continue;
                }
                if let Some((b, s)) = self.kernel_vertex(lane, hit, batches, &mut mirrors[p]) {
                    (kernels[p], at[p]) = (batches.all[b].kernel, (b, s));
                    continue;
                }
                kernels[p] = Kernel::General;
                self.general_vertex(&mut lane.path, hit, lane.mode, &mut lane.stream, &mut general[p]);
                if let Some((ray, d)) = general[p].shadow {
                    (tested[g][i], dist[g][i]) = (true, d);
                    shadows[g].set(i, &ray);
                }
            }
            // Each material kernel's batches: their lights sampled, their vertices shaded.
            for b in &mut batches.all[..batches.used] {
                if self.lane_lights.is_some() {
                    sample_lights(&b.lights, &mut b.vertices, unit);
                } else if self.lights.has_environment() {
                    let v = &mut b.vertices;
                    self.lights.sample_lanes(&b.lights.asks, |i, sample| set_light(v, i, sample));
                }
                weigh_layers(b.kernel, &mut b.vertices, &mut b.several_seen, b.len);
                let tables = Tables { coat: b.coat.unwrap_or(&Coat::NONE), several_seen: &b.several_seen };
                shade_with(b.kernel, &b.vertices, tables, &mut b.shaded, b.len, unit);
            }
            for (p, kernel) in kernels.iter().enumerate().filter(|(_, k)| k.is_material()) {
                let ((g, i), (b, s)) = ((p / LANES, p % LANES), at[p]);
                let sh = &batches.all[b].shaded;
                debug_assert_eq!(*kernel, batches.all[b].kernel);
                // Copied whether the lane tests a shadow ray or not (one not tested is not
                // traced): a branch on it, mispredicted, cost cornell-rough ~2 %.
                (tested[g][i], dist[g][i]) = (sh.shadow.at(s), sh.shadow_dist[s]);
                shadows[g].set(i, &Ray::new(get(&sh.shadow_origin, s), get(&sh.shadow_dir, s)));
            }
            let clear: [[bool; LANES]; GROUPS] = std::array::from_fn(|g| {
                if tested[g].contains(&true) {
                    self.world.unoccluded_rays(&shadows[g], &dist[g], tested[g])
                } else {
                    [false; LANES]
                }
            });
            for (p, lane) in lanes.iter_mut().enumerate().filter(|(_, l)| l.live) {
                let (g, i) = (p / LANES, p % LANES);
                if let (Some(dir), Some(texels)) = (escaping[p], &sky_texels) {
                    let sky = self.lights.sky_at(dir, texels[p], lane.path.prev.p);
                    let path = &mut lane.path;
                    path.l += self.escaped_from(sky, &path.prev, path.beta, lane.mode).unwrap_or(Vec3::ZERO);
                }
                let open = !tested[g][i] || clear[g][i];
                let goes_on = match kernels[p] {
                    Kernel::General | Kernel::Idle => {
                        lane.path.gather(&general[p], open);
                        general[p].goes_on
                    }
                    Kernel::Escaped => false,
                    _ => finish_kernel(lane, &mirrors[p], &batches.all[at[p].0].shaded, open, at[p].1),
                };
                if goes_on {
                    rays[g].set(i, &lane.path.ray);
                } else {
                    out[lane.job] = lane.value();
                    lane.live = false;
                }
            }
        }
    }

    /// The stream starts of `jobs` (of [`Self::trace_in_lanes`]'s numbering: sample
    /// `first + job % spp` of pixel `pixels[job / spp]`), computed together into `ahead`.
    fn starts_ahead(&self, pixels: &[(u32, u32)], first: u32, spp: usize, jobs: Range<usize>, ahead: &mut StartsAhead) {
        let unit = self.world.vector_unit();
        let mut job = jobs.start;
        while job < jobs.end {
            let pixel = pixels[job / spp];
            let end = ((job / spp + 1) * spp).min(jobs.end);
            let seeds = match ahead.seeds {
                Some((at, seeds)) if at == pixel => seeds,
                _ => PixelSeeds::new(self.sequence, self.scene.render.seed, pixel.0, pixel.1, unit),
            };
            ahead.seeds = Some((pixel, seeds));
            let index = first + (job % spp) as u32;
            seeds.starts(index..index + (end - job) as u32, &mut ahead.starts[job - jobs.start..end - jobs.start]);
            job = end;
        }
        ahead.jobs = jobs;
    }

    /// [`Self::vertex`] for a lane no material kernel shades, out of line: inlined, the
    /// general kernel's every BSDF grew the per-path stage the kernels' lanes run through
    /// (and cost the Lambert-only Cornell box 2–4 %).
    #[inline(never)]
    fn general_vertex(
        &self,
        path: &mut PathState,
        hit: Option<&WorldHit>,
        mode: ColorMode,
        stream: &mut SampleStream,
        out: &mut Vertex,
    ) {
        self.vertex(path, hit, mode, stream, out)
    }

    /// Starts `lane`'s path in pixel `(x, y)`, its stream restarted, as [`Self::sample_of`]
    /// starts it: its film position, its camera ray.
    fn start(&self, lane: &mut LanePath, (x, y): (u32, u32)) {
        let (fx, fy, weight) = self.film.place(x, y, lane.stream.next_2d());
        lane.weight = weight;
        lane.path = PathState::new(self.camera_ray(x, (fx, fy), &mut lane.stream));
        lane.mode =
            if self.spectral { ColorMode::Spectral(sample_wavelengths(lane.stream.next_1d())) } else { ColorMode::Rgb };
    }

    /// The per-path half of a material kernel's vertex, as in [`Self::vertex`]: emission, the
    /// vertex, its material and its random numbers and light sample, written to a slot of its
    /// kernel's batch: the batch and the slot. `None` (nothing done) when the vertex is no
    /// material kernel's: the ray missed, the path ends here, or the material takes the general
    /// kernel.
    fn kernel_vertex(
        &self,
        lane: &mut LanePath,
        hit: Option<&WorldHit>,
        batches: &mut Batches,
        mirrors: &mut KernelMirrors,
    ) -> Option<(usize, usize)> {
        let path = &mut lane.path;
        let wh = hit?;
        let material = self.material_kernels[wh.material as usize];
        let m = &self.scene.materials[wh.material as usize];
        if !material.is_material()
            || path.depth >= self.scene.render.max_depth
            || super::seen_from_behind(m, wh, path.ray.dir)
        {
            return None;
        }
        let at_hit;
        let bsdf = match &self.uniform_bsdfs[wh.material as usize] {
            Some(bsdf) => bsdf,
            None => {
                at_hit = crate::bsdf::bsdf_at(m, wh.hit.uv, wh.hit.color, &self.scene.images, ColorMode::Rgb);
                // Textures vary colours only: the kind of BSDF, and so its kernel, is the same
                // at every point of the surface (`bsdf::build` branches on none of them).
                debug_assert_eq!(kernel_of(&at_hit, m), material);
                &at_hit
            }
        };
        let kernel = material;
        let coat = if let Bsdf::Plastic(p) = bsdf { Some(p.coat) } else { None };
        let (b, i) = batches.slot(kernel, coat);
        let Batch { vertices: v, lights, .. } = &mut batches.all[b];
        match bsdf {
            Bsdf::Lambert(lambert) => set(&mut v.albedo, i, lambert.albedo),
            Bsdf::Coated(c) if set_coated_base(v, i, &c.base) => set_coat(v, i, c),
            Bsdf::OrenNayar(o) => {
                set(&mut v.albedo, i, o.albedo);
                v.alpha[0][i] = o.sigma;
                v.nonlinear.put(i, o.interreflection);
            }
            Bsdf::Phong(p) => {
                set(&mut v.albedo, i, p.diffuse);
                (v.ks[i], v.alpha[1][i]) = (p.ks, p.lobe.exponent);
            }
            Bsdf::BlinnPhong(b) => {
                set(&mut v.albedo, i, b.diffuse);
                (v.ks[i], v.alpha[1][i], v.ior[i]) = (b.ks, b.lobe.exponent, b.lobe.anisotropy);
                set_tangent(v, i, crate::bsdf::tangent_at(m, &wh.hit, &self.scene.images));
            }
            Bsdf::Conductor(c) => {
                set(&mut v.eta, i, c.eta);
                set(&mut v.k, i, c.k);
                set(&mut v.tint, i, c.tint);
                set_several(v, i, c);
                if let Some(facets) = &c.facets {
                    set_facets(v, i, facets, crate::bsdf::tangent_at(m, &wh.hit, &self.scene.images));
                }
            }
            Bsdf::Dielectric(d) => {
                v.ior[i] = d.eta;
                set(&mut v.tint, i, d.tint);
                if let Some(facets) = &d.facets {
                    set_facets(v, i, facets, crate::bsdf::tangent_at(m, &wh.hit, &self.scene.images));
                }
            }
            Bsdf::CookTorrance(c) => set_cook_torrance(v, i, c),
            Bsdf::Mix(mix) if let Some((c, lambert, weight)) = lambert_mirror(mix) => {
                set(&mut v.albedo, i, lambert.albedo);
                set(&mut v.eta, i, c.eta);
                set(&mut v.k, i, c.k);
                set(&mut v.tint, i, c.tint);
                v.mix_weight[i] = weight;
            }
            Bsdf::Mix(mix) if let Some(parts) = metallic_roughness(mix) => set_metallic_roughness(v, i, parts),
            Bsdf::Plastic(p) => {
                set(&mut v.albedo, i, p.albedo);
                v.ior[i] = p.eta;
                v.nonlinear.put(i, p.nonlinear);
                if let Some(facets) = &p.facets {
                    set_facets(v, i, facets, None);
                }
            }
            _ => {
                // No kernel's (`kernel_of` gives none to other BSDFs): the slot given back.
                batches.all[b].len -= 1;
                return None;
            }
        }
        // As `vertex` weighs a path that crossed an absorbing inside, before its emission.
        if self.absorbing
            && let Some(kept) = crate::optics::absorbed_inside(m, &wh.hit, path.ray.dir, ColorMode::Rgb)
        {
            path.beta *= kept;
        }
        let h = HitPoint::from(wh);
        path.l += path.beta * self.emitted(&h, wh.hit.uv, &path.ray, &path.prev, path.visit.as_ref(), ColorMode::Rgb);
        // As `vertex` records a mirror's visit, from the previous vertex as it was. (Without
        // mirrors the visit stays `None`, unwritten: a whole record's copy each vertex.)
        if let Some(c) = &self.mirrors {
            let reflected = !path.prev.delta && kernel.samples_delta();
            mirrors.visit = if reflected { c.visit(path.prev.p, path.prev_object, path.prev.pdf, &h) } else { None };
        }
        path.prev_object = wh.object;
        v.roulette.put(i, path.depth >= RR_DEPTH);
        set(&mut v.wo, i, -path.ray.dir);
        set(&mut v.p, i, h.p);
        set(&mut v.ng, i, h.n);
        v.bumped.put(i, m.bump.is_some());
        if v.bumped.at(i) {
            set(&mut v.ns, i, crate::world::shading_normal(&wh.hit, m, &self.scene.images));
            set(&mut v.n0, i, h.ns);
        } else {
            set(&mut v.ns, i, h.ns);
        }
        set(&mut v.beta, i, path.beta);
        v.eta_scale[i] = path.eta_scale;
        path.prev.p = h.p;
        // The vertex's numbers in the per-path tracer's order: light choice when there is one,
        // light point, continuation, roulette from `RR_DEPTH` on. Roulette's is drawn before it
        // is known whether the path survives the continuation; a path that does not never draws
        // again, so the stream stays the per-path tracer's.
        let s = &mut lane.stream;
        let path = &lane.path;
        // One pair picks the light and the lobe, drawn only when there is a choice; a delta
        // BSDF samples no light and draws no number for it.
        let chooses = self.lights.choices() > 1 || kernel.chooses_lobe();
        let (choice, u_lobe) = if chooses { s.next_2d().into() } else { (0.0, 0.0) };
        v.u_lobe[i] = u_lobe;
        let u_light = if kernel.is_delta() { Vec2::ZERO } else { s.next_2d() };
        mirrors.mirrored = self.kernel_mirror_connections(kernel, path, wh, bsdf, s);
        let u_bsdf = s.next_2d();
        (v.u_bsdf[0][i], v.u_bsdf[1][i]) = (u_bsdf.x, u_bsdf.y);
        if v.roulette.at(i) {
            v.u_roulette[i] = s.next_1d();
        }
        match &self.lane_lights {
            _ if kernel.is_delta() => v.light.put(i, false),
            Some(all) => {
                let (chosen, choice_pdf) = self.lights.choose_with_pdf(choice, h.p);
                let k = &all[chosen];
                lights.choice_pdf[i] = choice_pdf;
                set(&mut lights.corner, i, k.corner);
                set(&mut lights.e1, i, k.e1);
                set(&mut lights.e2, i, k.e2);
                set(&mut lights.normal, i, k.normal);
                lights.pdf_area[i] = k.pdf_area;
                lights.point[i] = k.point;
                (lights.u[0][i], lights.u[1][i]) = (u_light.x, u_light.y);
                set(&mut v.light_radiance, i, k.radiance);
                v.light.put(i, k.radiance != Vec3::ZERO);
                v.light_delta.put(i, k.point);
            }
            None if self.lights.has_environment() => lights.asks[i] = Some(self.lights.ask(h.p, choice, u_light)),
            None => {
                let light = self.lights.sample(h.p, choice, u_light);
                set_light(v, i, light);
            }
        }
        Some((b, i))
    }
}

impl PathTracer<'_> {
    /// The light a kernel's vertex gathers through the scene's mirrors, drawn from `s` where
    /// [`Self::vertex`] draws it (after the light point, before the continuation); `None`
    /// where `vertex` connects nothing (no mirrors, a delta BSDF, too deep). The vertex's
    /// frame, which the kernels compute in lanes, is computed here only for a vertex the
    /// roulette lets connect.
    fn kernel_mirror_connections(
        &self,
        kernel: Kernel,
        path: &PathState,
        wh: &WorldHit,
        bsdf: &Bsdf,
        s: &mut SampleStream,
    ) -> Option<Vec3> {
        let c = self.mirrors.as_ref()?;
        if kernel.is_delta() || path.depth + 2 > self.scene.render.max_depth {
            return None;
        }
        let shading = || {
            let m = &self.scene.materials[wh.material as usize];
            let wo = -path.ray.dir;
            let (frame, ng, terminator) =
                self.shading_frame(wh, bsdf, wo, crate::bsdf::tangent_at(m, &wh.hit, &self.scene.images));
            super::mirrors::VertexShading { frame, ng, terminator, v: frame.to_local(wo) }
        };
        Some(self.mirror_connections(c, bsdf, shading, wh.hit.p, wh.object, ColorMode::Rgb, s))
    }
}

/// Lane `i`'s light sample, where it exists and has radiance and density.
#[inline(always)]
fn set_light(v: &mut Vertices, i: usize, sample: Option<LightSample>) {
    let light = sample.filter(|ls| ls.radiance != Vec3::ZERO && not_at_most_zero(ls.pdf));
    v.light.put(i, light.is_some());
    if let Some(ls) = light {
        set(&mut v.light_dir, i, ls.dir);
        set(&mut v.light_radiance, i, ls.radiance);
        (v.light_dist[i], v.light_pdf[i]) = (ls.dist, ls.pdf);
        v.light_delta.put(i, ls.delta);
    }
}

/// Lane `i`'s Cook–Torrance surface.
#[inline(always)]
fn set_cook_torrance(v: &mut Vertices, i: usize, c: &CookTorrance) {
    set(&mut v.albedo, i, c.diffuse);
    (v.ks[i], v.ior[i], v.layer[i]) = (c.ks, c.lobe.ior, c.lobe.layer);
    set_facets(v, i, &c.lobe.facets, None);
}

/// Lane `i`'s metallic–roughness mix: its metal, its Cook–Torrance base, the metal's weight.
#[inline(always)]
fn set_metallic_roughness(v: &mut Vertices, i: usize, (metal, base, weight): (&Conductor, &CookTorrance, f64)) {
    set(&mut v.eta, i, metal.eta);
    set(&mut v.k, i, metal.k);
    set(&mut v.tint, i, metal.tint);
    let metal_alpha = metal.facets.map_or(0.0, |f| f.alpha_u);
    (v.alpha[0][i], v.alpha[1][i]) = (metal_alpha, base.lobe.facets.alpha_u);
    set(&mut v.albedo, i, base.diffuse);
    (v.ks[i], v.ior[i], v.layer[i]) = (base.ks, base.lobe.ior, base.lobe.layer);
    v.mix_weight[i] = weight;
    set_several(v, i, metal);
}

/// Lane `i`'s metal's light of several facets, where it gives it back.
#[inline(always)]
fn set_several(v: &mut Vertices, i: usize, metal: &Conductor) {
    if let Some(several) = metal.multiscatter {
        v.several.get_or_insert_with(Box::default)[i] = several;
    }
}

/// Lane `i`'s base under a clear coat; false where no coated kernel has it (`kernel_of` gives
/// none to other bases: the slot is then given back, as for any BSDF without a kernel).
fn set_coated_base(v: &mut Vertices, i: usize, base: &Bsdf) -> bool {
    match base {
        Bsdf::Lambert(lambert) => set(&mut v.albedo, i, lambert.albedo),
        Bsdf::CookTorrance(base) => set_cook_torrance(v, i, base),
        Bsdf::Mix(mix) if let Some(parts) = metallic_roughness(mix) => set_metallic_roughness(v, i, parts),
        _ => return false,
    }
    true
}

/// Lane `i`'s clear coat (its albedo towards the viewer found later, `weigh_layers`).
fn set_coat(v: &mut Vertices, i: usize, c: &crate::bsdf::Coated) {
    let coats = v.coats.get_or_insert_with(Box::default);
    (coats.weight[i], coats.alpha[i], coats.ior[i]) = (c.weight, c.coat.facets.alpha_u, c.coat.ior);
    coats.row[i] = c.row();
}

/// Lane `i`'s microfacets and tangent.
fn set_facets(v: &mut Vertices, i: usize, facets: &Microfacet, tangent: Option<Vec3>) {
    (v.alpha[0][i], v.alpha[1][i]) = (facets.alpha_u, facets.alpha_v);
    set_tangent(v, i, tangent);
}

/// Lane `i`'s tangent, where its lobes turn with one.
fn set_tangent(v: &mut Vertices, i: usize, tangent: Option<Vec3>) {
    v.tangent_given.put(i, tangent.is_some());
    set(&mut v.tangent, i, tangent.unwrap_or(Vec3::X));
}

/// Moves the paths of the pool to its first slots, each with its ray, keeping their order;
/// false when there is none. (Where a path is traced changes none of its numbers.)
fn gather_paths(lanes: &mut [LanePath; POOL], rays: &mut [RayPacket; GROUPS]) -> bool {
    let mut to = 0;
    for from in 0..POOL {
        if !lanes[from].live {
            continue;
        }
        if from != to {
            // The idle record goes where the path was.
            lanes.swap(to, from);
            rays[to / LANES].set(to % LANES, &lanes[to].path.ray);
        }
        to += 1;
    }
    to > 0
}

/// The per-path half of a material kernel's vertex after [`shade`] and the shadow ray (`clear`
/// when it was not traced or met nothing): the light gathered, then the light through mirrors,
/// then the step to the next vertex (the mirror visit kept if the lobe taken was a delta one).
/// True when the path goes on.
fn finish_kernel(lane: &mut LanePath, mirrors: &KernelMirrors, s: &Shaded, clear: bool, i: usize) -> bool {
    let path = &mut lane.path;
    let light = if clear { get(&s.light, i) } else { Vec3::ZERO };
    path.l += path.beta * light;
    if let Some(mirrored) = mirrors.mirrored {
        path.l += path.beta * mirrored;
    }
    if s.alive.at(i) {
        path.beta = get(&s.beta, i);
        path.eta_scale = s.eta_scale[i];
        path.prev.pdf = s.pdf[i];
        path.prev.delta = s.delta.at(i);
        path.ray = Ray::new(get(&s.origin, i), get(&s.dir, i));
        path.depth += 1;
        if mirrors.visit.is_some() || path.visit.is_some() {
            path.visit = if path.prev.delta { mirrors.visit } else { None };
        }
    }
    s.alive.at(i)
}

/// Every lane's point on its parallelogram light or its point light's position, as
/// `Lights::sample` computes them.
fn sample_lights(k: &LightLanes, v: &mut Vertices, unit: VectorUnit) {
    match k.any_point {
        false => sample_lights_in::<false>(k, v, unit),
        true => sample_lights_in::<true>(k, v, unit),
    }
}

#[allow(unsafe_code)]
fn sample_lights_in<const POINT: bool>(k: &LightLanes, v: &mut Vertices, unit: VectorUnit) {
    #[cfg(target_arch = "x86_64")]
    if unit.is_avx512() {
        // SAFETY: a `VectorUnit` says AVX-512 (F, DQ, VL, BW) only where the processor has them.
        return unsafe { sample_lights_avx512::<POINT>(k, v) };
    }
    #[cfg(target_arch = "x86_64")]
    if unit.is_avx2() {
        // SAFETY: a `VectorUnit` says AVX2 only where the processor has it.
        return unsafe { sample_lights_avx2::<POINT>(k, v) };
    }
    let _ = unit;
    (0..LANES).for_each(|i| sample_light::<POINT>(k, v, i));
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512dq,avx512vl,avx512bw")]
#[allow(unsafe_code)]
unsafe fn sample_lights_avx512<const POINT: bool>(k: &LightLanes, v: &mut Vertices) {
    (0..LANES).for_each(|i| sample_light::<POINT>(k, v, i));
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[allow(unsafe_code)]
unsafe fn sample_lights_avx2<const POINT: bool>(k: &LightLanes, v: &mut Vertices) {
    (0..LANES).for_each(|i| sample_light::<POINT>(k, v, i));
}

/// Lane `i`'s point on its parallelogram, as `lights::sample_area` computes it, or (`POINT`:
/// some light is a point, and this lane's is) the point with its intensity over the squared
/// distance, as `Lights::sample` draws them. Both are computed and one kept, so the lanes do
/// not branch.
#[inline(always)]
fn sample_light<const POINT: bool>(k: &LightLanes, v: &mut Vertices, i: usize) {
    let choice_pdf = k.choice_pdf[i];
    let corner = get(&k.corner, i);
    let on_area = corner + get(&k.e1, i) * k.u[0][i] + get(&k.e2, i) * k.u[1][i];
    let q = if POINT && k.point[i] { corner } else { on_area };
    let to = q - get(&v.p, i);
    let d2 = to.length_squared();
    let dist = d2.sqrt();
    let dir = to / dist;
    let cos = -get(&k.normal, i).dot(dir);
    let pdf = k.pdf_area[i] * d2 / cos * choice_pdf;
    let area_ok = dist != 0.0 && not_at_most_zero(cos) && not_at_most_zero(pdf);
    if POINT && k.point[i] {
        // `Lights::sample`'s point: `dist` is `to.length()`, the radiance its intensity over
        // `dist · dist`, the density the choice's alone.
        let (radiance, pdf) = (get(&v.light_radiance, i) / (dist * dist), 1.0 * choice_pdf);
        v.light.put(i, v.light.at(i) && dist > 0.0 && radiance != Vec3::ZERO && not_at_most_zero(pdf));
        set(&mut v.light_dir, i, dir);
        set(&mut v.light_radiance, i, radiance);
        (v.light_dist[i], v.light_pdf[i]) = (dist, pdf);
    } else {
        v.light.put(i, v.light.at(i) && area_ok);
        set(&mut v.light_dir, i, dir);
        (v.light_dist[i], v.light_pdf[i]) = (dist, pdf);
    }
}

/// A BSDF a material kernel evaluates and samples in lane `i` of [`Vertices`], through the
/// per-path tracer's own functions (inlined into the all-lane loop, without branches).
trait LaneBsdf {
    /// The BSDF transmits: the shading frame is not turned to the viewer, and light may come
    /// from either side of the geometry.
    const TRANSMITS: bool = false;
    /// The local frame around the shading normal `ns` ([`PathTracer::shading_frame`]'s):
    /// around the normal unless the BSDF turns with a tangent.
    #[inline(always)]
    fn frame(_: &Vertices, _: usize, ns: Vec3) -> Frame {
        Frame::around(ns)
    }
    /// `ρ` and the sampling density towards `l`, seen from `wv` (local): `Bsdf::eval_pdf`;
    /// nothing for a delta distribution (the default).
    #[inline(always)]
    fn eval_pdf(_: &Vertices, _: Tables<'_>, _: usize, _: Vec3, _: Vec3) -> (Vec3, f64) {
        (Vec3::ZERO, 0.0)
    }
    /// The continuation drawn with the numbers `uc, u`, as `Bsdf::sample` draws it: whether
    /// there is one, and the sample.
    fn sample(v: &Vertices, tables: Tables<'_>, i: usize, wv: Vec3, uc: f64, u: Vec2) -> (bool, BsdfSample);
}

/// Lambert's BSDF ([`crate::bsdf::Lambert`]), cosine-weighted sampling (`sample_cosine`).
struct Lambertian;

impl LaneBsdf for Lambertian {
    #[inline(always)]
    fn eval_pdf(v: &Vertices, _: Tables<'_>, i: usize, wv: Vec3, l: Vec3) -> (Vec3, f64) {
        let rho = get(&v.albedo, i) * FRAC_1_PI;
        (if same_side(wv, l) { rho } else { Vec3::ZERO }, cosine_pdf(wv, l))
    }

    #[inline(always)]
    fn sample(v: &Vertices, _: Tables<'_>, i: usize, wv: Vec3, _: f64, u: Vec2) -> (bool, BsdfSample) {
        // `cosine_hemisphere` keeps `l` on the side of `wv`, where `ρ` is the albedo's.
        let l = cosine_hemisphere(u, wv);
        let (f, pdf) = (get(&v.albedo, i) * FRAC_1_PI, cosine_pdf(wv, l));
        (true, BsdfSample { l, f, pdf, delta: false, eta: 1.0, dispersive: false })
    }
}

/// The course's Oren–Nayar model ([`OrenNayar`]), cosine-weighted sampling.
struct LaneOrenNayar;

impl LaneOrenNayar {
    #[inline(always)]
    fn at(v: &Vertices, i: usize) -> OrenNayar {
        OrenNayar { albedo: get(&v.albedo, i), sigma: v.alpha[0][i], interreflection: v.nonlinear.at(i) }
    }
}

impl LaneBsdf for LaneOrenNayar {
    #[inline(always)]
    fn eval_pdf(v: &Vertices, _: Tables<'_>, i: usize, wv: Vec3, l: Vec3) -> (Vec3, f64) {
        let b = Self::at(v, i);
        (b.eval(wv, l), b.pdf(wv, l))
    }

    #[inline(always)]
    fn sample(v: &Vertices, _: Tables<'_>, i: usize, wv: Vec3, uc: f64, u: Vec2) -> (bool, BsdfSample) {
        lane_sample(Self::at(v, i).sample(wv, uc, u))
    }
}

/// The course's Lambert-plus-lobe BSDFs ([`DiffuseSpecular`]: normalised Phong, anisotropic
/// Blinn–Phong): a lobe chosen by `uc`, then a direction from it.
struct LaneDiffuseSpecular<S>(std::marker::PhantomData<S>);

/// A specular lobe the lanes build from a lane's numbers.
trait LaneLobe: SpecularLobe + Sized {
    /// The lobe turns with the lane's tangent (Blinn–Phong's scratches).
    const TANGENT: bool;
    fn at(v: &Vertices, i: usize) -> Self;
}

impl LaneLobe for PhongLobe {
    const TANGENT: bool = false;
    #[inline(always)]
    fn at(v: &Vertices, i: usize) -> Self {
        PhongLobe { exponent: v.alpha[1][i] }
    }
}

impl LaneLobe for BlinnPhongLobe {
    const TANGENT: bool = true;
    #[inline(always)]
    fn at(v: &Vertices, i: usize) -> Self {
        BlinnPhongLobe { exponent: v.alpha[1][i], anisotropy: v.ior[i] }
    }
}

impl<S: LaneLobe> LaneDiffuseSpecular<S> {
    #[inline(always)]
    fn at(v: &Vertices, i: usize) -> DiffuseSpecular<S> {
        DiffuseSpecular { diffuse: get(&v.albedo, i), ks: v.ks[i], lobe: S::at(v, i), transmittance: Vec3::ZERO }
    }
}

impl<S: LaneLobe> LaneBsdf for LaneDiffuseSpecular<S> {
    #[inline(always)]
    fn frame(v: &Vertices, i: usize, ns: Vec3) -> Frame {
        if S::TANGENT { tangent_frame(v, i, ns) } else { Frame::around(ns) }
    }

    #[inline(always)]
    fn eval_pdf(v: &Vertices, _: Tables<'_>, i: usize, wv: Vec3, l: Vec3) -> (Vec3, f64) {
        Self::at(v, i).eval_pdf(wv, l)
    }

    #[inline(always)]
    fn sample(v: &Vertices, _: Tables<'_>, i: usize, wv: Vec3, uc: f64, u: Vec2) -> (bool, BsdfSample) {
        lane_sample(Self::at(v, i).sample(wv, uc, u))
    }
}

/// The frame `PathTracer::shading_frame` turns with lane `i`'s tangent, or about `ns` alone
/// where it has none.
#[inline(always)]
fn tangent_frame(v: &Vertices, i: usize, ns: Vec3) -> Frame {
    let (around, along) = (Frame::around(ns), Frame::new(ns, get(&v.tangent, i)));
    if v.tangent_given.at(i) { along } else { around }
}

/// A sample as the kernels return it: whether there is one (none ends the path).
#[inline(always)]
fn lane_sample(sample: Option<BsdfSample>) -> (bool, BsdfSample) {
    let none = BsdfSample { l: Vec3::Z, f: Vec3::ZERO, pdf: 0.0, delta: false, eta: 1.0, dispersive: false };
    (sample.is_some(), sample.unwrap_or(none))
}

/// A clear coat over the base `B` ([`crate::bsdf::Coated`]), its albedo towards the viewer found
/// before the loop (`weigh_layers`: a table lookup would keep the loop scalar), the base
/// through `B`'s own lane functions.
struct LaneCoated<B>(std::marker::PhantomData<B>);

impl<B: LaneBsdf> LaneCoated<B> {
    /// Lane `i`'s coat: its lobe, weight and albedo towards the viewer.
    #[inline(always)]
    fn coat(v: &Vertices, i: usize) -> (CookTorranceLobe, f64, f64) {
        let c = v.coats.as_deref().unwrap_or(&NO_COATS);
        let facets = Microfacet::smith::<false>(c.alpha[i], c.alpha[i]);
        (CookTorranceLobe { facets, ior: c.ior[i], schlick: false, layer: 0.0 }, c.weight[i], c.albedo[i])
    }
}

impl<B: LaneBsdf> LaneBsdf for LaneCoated<B> {
    const TRANSMITS: bool = B::TRANSMITS;

    #[inline(always)]
    fn frame(v: &Vertices, i: usize, ns: Vec3) -> Frame {
        B::frame(v, i, ns)
    }

    #[inline(always)]
    fn eval_pdf(v: &Vertices, tables: Tables<'_>, i: usize, wv: Vec3, l: Vec3) -> (Vec3, f64) {
        let (lobe, weight, albedo) = Self::coat(v, i);
        under_coat(&lobe, weight, albedo, B::eval_pdf(v, tables, i, wv, l), wv, l)
    }

    #[inline(always)]
    fn sample(v: &Vertices, tables: Tables<'_>, i: usize, wv: Vec3, uc: f64, u: Vec2) -> (bool, BsdfSample) {
        let (lobe, weight, albedo) = Self::coat(v, i);
        let q = coat_choice(albedo, weight);
        let base = |uc| {
            let (sampled, s) = B::sample(v, tables, i, wv, uc, u);
            sampled.then_some(s)
        };
        let whole = |l| Self::eval_pdf(v, tables, i, wv, l);
        lane_sample(sample_under_layer(base, uc, (q, albedo), || lobe.sample(wv, u), whole))
    }
}

/// A BSDF of microfacets a rough kernel ([`Rough`]) evaluates: built for lane `i` with the
/// lane's facets, then evaluated and sampled through its own [`MicrofacetLobes`].
trait RoughBsdf: MicrofacetLobes {
    /// The BSDF transmits ([`LaneBsdf::TRANSMITS`]).
    const TRANSMITS: bool = false;
    /// The BSDF may be anisotropic: a tangent frame where the lane has a tangent.
    const TANGENT: bool = true;
    /// Lane `i`'s BSDF on `facets`, its Fresnel mode a constant the compiler folds.
    fn at(v: &Vertices, tables: Tables<'_>, i: usize, facets: Microfacet) -> Self;
}

impl RoughBsdf for Conductor {
    #[inline(always)]
    fn at(v: &Vertices, _: Tables<'_>, i: usize, facets: Microfacet) -> Self {
        let (eta, k, tint) = (get(&v.eta, i), get(&v.k, i), get(&v.tint, i));
        Conductor { facets: Some(facets), eta, k, tint, schlick: false, multiscatter: None, film: None }
    }
}

/// A conductor with Schlick's Fresnel term (a constant the compiler folds, as the exact one's).
struct SchlickConductor(Conductor);

impl MicrofacetLobes for SchlickConductor {
    #[inline(always)]
    fn rough_eval_pdf(&self, facets: &Microfacet, v: Vec3, l: Vec3) -> (Vec3, f64) {
        self.0.rough_eval_pdf(facets, v, l)
    }

    #[inline(always)]
    fn rough_sample(&self, facets: &Microfacet, v: Vec3, uc: f64, u: Vec2) -> (bool, BsdfSample) {
        self.0.rough_sample(facets, v, uc, u)
    }
}

impl RoughBsdf for SchlickConductor {
    #[inline(always)]
    fn at(v: &Vertices, _: Tables<'_>, i: usize, facets: Microfacet) -> Self {
        let (eta, k, tint) = (get(&v.eta, i), get(&v.k, i), get(&v.tint, i));
        SchlickConductor(Conductor {
            facets: Some(facets),
            eta,
            k,
            tint,
            schlick: true,
            multiscatter: None,
            film: None,
        })
    }
}

impl RoughBsdf for Dielectric {
    const TRANSMITS: bool = true;

    #[inline(always)]
    fn at(v: &Vertices, _: Tables<'_>, i: usize, facets: Microfacet) -> Self {
        Dielectric { tint: get(&v.tint, i), ..Dielectric::clear(Some(facets), v.ior[i]) }
    }
}

/// Cook–Torrance in the lanes: its diffuse weight found before the kernel's loop
/// ([`weigh_layers`]), the same number the per-path tracer's BSDF finds from the viewer.
struct LaneCookTorrance(CookTorrance, f64);

impl MicrofacetLobes for LaneCookTorrance {
    #[inline(always)]
    fn rough_eval_pdf(&self, _: &Microfacet, v: Vec3, l: Vec3) -> (Vec3, f64) {
        self.0.eval_pdf_weighted(self.1, v, l)
    }

    #[inline(always)]
    fn rough_sample(&self, _: &Microfacet, v: Vec3, uc: f64, u: Vec2) -> (bool, BsdfSample) {
        self.0.sample_weighted(self.1, v, uc, u)
    }
}

impl RoughBsdf for LaneCookTorrance {
    /// Isotropic facets only ([`cook_torrance_facets`]).
    const TANGENT: bool = false;

    #[inline(always)]
    fn at(v: &Vertices, _: Tables<'_>, i: usize, facets: Microfacet) -> Self {
        let lobe = CookTorranceLobe { facets, ior: v.ior[i], schlick: false, layer: v.layer[i] };
        let transmittance = Vec3::ZERO;
        LaneCookTorrance(
            CookTorrance { diffuse: get(&v.albedo, i), ks: v.ks[i], lobe, transmittance },
            v.diffuse_weight[i],
        )
    }
}

impl RoughBsdf for Plastic {
    /// A plastic's coat takes one roughness.
    const TANGENT: bool = false;

    #[inline(always)]
    fn at(v: &Vertices, tables: Tables<'_>, i: usize, facets: Microfacet) -> Self {
        plastic_at(v, tables, i, Some(facets))
    }
}

/// A rough conductor, dielectric or plastic (`B`) on Trowbridge–Reitz or, with `BECKMANN`,
/// Beckmann facets with Smith's shadowing (their kind a constant the compiler folds), in a
/// tangent frame where it is anisotropic.
struct Rough<B, const BECKMANN: bool>(std::marker::PhantomData<B>);

impl<B: RoughBsdf, const BECKMANN: bool> Rough<B, BECKMANN> {
    /// Lane `i`'s BSDF and its facets.
    #[inline(always)]
    fn at(v: &Vertices, tables: Tables<'_>, i: usize) -> (B, Microfacet) {
        let facets = Microfacet::smith::<BECKMANN>(v.alpha[0][i], v.alpha[1][i]);
        (B::at(v, tables, i, facets), facets)
    }
}

impl<B: RoughBsdf, const BECKMANN: bool> LaneBsdf for Rough<B, BECKMANN> {
    const TRANSMITS: bool = B::TRANSMITS;

    #[inline(always)]
    fn frame(v: &Vertices, i: usize, ns: Vec3) -> Frame {
        if !B::TANGENT {
            return Frame::around(ns);
        }
        tangent_frame(v, i, ns)
    }

    #[inline(always)]
    fn eval_pdf(v: &Vertices, tables: Tables<'_>, i: usize, wv: Vec3, l: Vec3) -> (Vec3, f64) {
        let (bsdf, facets) = Self::at(v, tables, i);
        bsdf.rough_eval_pdf(&facets, wv, l)
    }

    #[inline(always)]
    fn sample(v: &Vertices, tables: Tables<'_>, i: usize, wv: Vec3, uc: f64, u: Vec2) -> (bool, BsdfSample) {
        let (bsdf, facets) = Self::at(v, tables, i);
        bsdf.rough_sample(&facets, wv, uc, u)
    }
}

/// Smooth conductors: [`Conductor::smooth_sample`], with Schlick's Fresnel term where
/// `SCHLICK`; nothing to evaluate (a delta distribution).
struct SmoothConductor<const SCHLICK: bool>;

impl<const SCHLICK: bool> LaneBsdf for SmoothConductor<SCHLICK> {
    #[inline(always)]
    fn sample(v: &Vertices, _: Tables<'_>, i: usize, wv: Vec3, _: f64, _: Vec2) -> (bool, BsdfSample) {
        let (eta, k, tint) = (get(&v.eta, i), get(&v.k, i), get(&v.tint, i));
        (
            true,
            Conductor { facets: None, eta, k, tint, schlick: SCHLICK, multiscatter: None, film: None }
                .smooth_sample(wv),
        )
    }
}

/// Smooth glass: [`Dielectric::smooth_sample`]; nothing to evaluate (a delta distribution).
struct SmoothDielectric;

impl LaneBsdf for SmoothDielectric {
    const TRANSMITS: bool = true;

    #[inline(always)]
    fn sample(v: &Vertices, _: Tables<'_>, i: usize, wv: Vec3, uc: f64, _: Vec2) -> (bool, BsdfSample) {
        Dielectric { tint: get(&v.tint, i), ..Dielectric::clear(None, v.ior[i]) }.smooth_sample(wv, uc)
    }
}

/// A thin sheet of glass: [`Dielectric::thin_sample`]; nothing to evaluate (a delta
/// distribution).
struct ThinDielectric;

impl LaneBsdf for ThinDielectric {
    const TRANSMITS: bool = true;

    #[inline(always)]
    fn sample(v: &Vertices, _: Tables<'_>, i: usize, wv: Vec3, uc: f64, _: Vec2) -> (bool, BsdfSample) {
        Dielectric { tint: get(&v.tint, i), thin: true, ..Dielectric::clear(None, v.ior[i]) }.thin_sample_whole(wv, uc)
    }
}

/// Plastic under a smooth coat: [`Plastic::smooth_eval_pdf`] (its base) and
/// [`Plastic::smooth_sample`] (the coat's mirror or the base).
struct SmoothPlastic;

/// Lane `i`'s plastic, its coat on `facets` (smooth for `None`).
#[inline(always)]
fn plastic_at(v: &Vertices, tables: Tables<'_>, i: usize, facets: Option<Microfacet>) -> Plastic {
    let (albedo, eta, nonlinear) = (get(&v.albedo, i), v.ior[i], v.nonlinear.at(i));
    Plastic { albedo, eta, facets, nonlinear, coat: tables.coat }
}

impl LaneBsdf for SmoothPlastic {
    #[inline(always)]
    fn eval_pdf(v: &Vertices, tables: Tables<'_>, i: usize, wv: Vec3, l: Vec3) -> (Vec3, f64) {
        plastic_at(v, tables, i, None).smooth_eval_pdf(wv, l)
    }

    #[inline(always)]
    fn sample(v: &Vertices, tables: Tables<'_>, i: usize, wv: Vec3, uc: f64, u: Vec2) -> (bool, BsdfSample) {
        plastic_at(v, tables, i, None).smooth_sample(wv, uc, u)
    }
}

/// Lambert plus an ideal mirror of weight `w` (the lane's `mix_weight`): [`crate::bsdf::Mix`]'s
/// arithmetic on its two components, its sample computed for both and then chosen.
struct LambertMirror;

impl LambertMirror {
    /// Lane `i`'s mirror, Lambert and the mirror's weight.
    #[inline(always)]
    fn at(v: &Vertices, i: usize) -> (Conductor, crate::bsdf::Lambert, f64) {
        let (eta, k, tint) = (get(&v.eta, i), get(&v.k, i), get(&v.tint, i));
        let mirror = Conductor { facets: None, eta, k, tint, schlick: false, multiscatter: None, film: None };
        (mirror, crate::bsdf::Lambert { albedo: get(&v.albedo, i) }, v.mix_weight[i])
    }
}

impl LaneBsdf for LambertMirror {
    #[inline(always)]
    fn eval_pdf(v: &Vertices, _: Tables<'_>, i: usize, wv: Vec3, l: Vec3) -> (Vec3, f64) {
        let (mirror, lambert, w) = Self::at(v, i);
        let f = crate::bsdf::blend(w, mirror.eval(wv, l), lambert.eval(wv, l));
        (f, crate::bsdf::blend_density(w, mirror.pdf(wv, l), lambert.pdf(wv, l)))
    }

    /// `Mix::sample`: the mirror with probability `w` (its delta sample's value and density
    /// times `w`), else Lambert's cosine-weighted direction valued as the whole mix.
    #[inline(always)]
    fn sample(v: &Vertices, tables: Tables<'_>, i: usize, wv: Vec3, uc: f64, u: Vec2) -> (bool, BsdfSample) {
        let (mirror, _, w) = Self::at(v, i);
        let mut reflected = mirror.smooth_sample(wv);
        (reflected.f, reflected.pdf) = (reflected.f * w, reflected.pdf * w);
        let l = cosine_hemisphere(u, wv);
        let (f, pdf) = Self::eval_pdf(v, tables, i, wv, l);
        let diffuse = BsdfSample { l, f, pdf, delta: false, eta: 1.0, dispersive: false };
        // `sample_cosine`'s condition, then the mix's.
        let first = uc < w;
        (first || cosine_pdf(wv, l) > 0.0 && pdf > 0.0, if first { reflected } else { diffuse })
    }
}

/// The glTF metallic–roughness mix (lane `i`'s `mix_weight` the metal's share): a rough
/// conductor with Schlick's term on the lane's `alpha[0]` and Cook–Torrance on its `alpha[1]`,
/// both isotropic Trowbridge–Reitz facets, the metal giving back the light of several facets
/// with `SEVERAL` (the lanes' `several_seen`); [`crate::bsdf::Mix`]'s arithmetic, its sample
/// drawn from both components and then chosen.
struct MetallicRoughness<const SEVERAL: bool>;

impl<const SEVERAL: bool> MetallicRoughness<SEVERAL> {
    /// Lane `i`'s metal (its light of several facets, if any, apart: the lanes' `several_seen`)
    /// and its facets, its Cook–Torrance base, and the metal's weight.
    #[inline(always)]
    fn at(v: &Vertices, i: usize) -> ((Conductor, Microfacet), CookTorrance, f64) {
        let metal_facets = Microfacet::smith::<false>(v.alpha[0][i], v.alpha[0][i]);
        let (eta, k, tint) = (get(&v.eta, i), get(&v.k, i), get(&v.tint, i));
        let metal =
            Conductor { facets: Some(metal_facets), eta, k, tint, schlick: true, multiscatter: None, film: None };
        let base_facets = Microfacet::smith::<false>(v.alpha[1][i], v.alpha[1][i]);
        let lobe = CookTorranceLobe { facets: base_facets, ior: v.ior[i], schlick: false, layer: v.layer[i] };
        let base = CookTorrance { diffuse: get(&v.albedo, i), ks: v.ks[i], lobe, transmittance: Vec3::ZERO };
        ((metal, metal_facets), base, v.mix_weight[i])
    }
}

impl<const SEVERAL: bool> LaneBsdf for MetallicRoughness<SEVERAL> {
    #[inline(always)]
    fn eval_pdf(v: &Vertices, tables: Tables<'_>, i: usize, wv: Vec3, l: Vec3) -> (Vec3, f64) {
        let ((metal, metal_facets), base, w) = Self::at(v, i);
        let several = if SEVERAL { Some(tables.several_seen[i]) } else { None };
        let (fa, pa) = metal.eval_pdf_with(&metal_facets, several.as_ref().map(|(ms, p)| (ms, *p)), wv, l);
        let (fb, pb) = base.eval_pdf_weighted(v.diffuse_weight[i], wv, l);
        (crate::bsdf::blend(w, fa, fb), crate::bsdf::blend_density(w, pa, pb))
    }

    /// `Mix::sample`: the metal with probability `w`, else the base (each drawn as
    /// `Bsdf::sample` draws it: the metal's without its lobe number, or, with several facets,
    /// with it, rescaled: [`Conductor::several_sample_whole`]), valued as the whole mix; every candidate
    /// computed, then the chosen one taken.
    #[inline(always)]
    fn sample(v: &Vertices, tables: Tables<'_>, i: usize, wv: Vec3, uc: f64, u: Vec2) -> (bool, BsdfSample) {
        let ((metal, metal_facets), base, w) = Self::at(v, i);
        let (first, uc) = crate::bsdf::Mix::component_choice(w, uc);
        let (metal_ok, metal_sample) = match SEVERAL {
            true => {
                let (ms, p) = tables.several_seen[i];
                metal.several_sample_whole(&metal_facets, (&ms, p), wv, uc, u)
            }
            false => metal.rough_sample(&metal_facets, wv, 0.0, u),
        };
        let (base_ok, base_sample) = base.sample_weighted(v.diffuse_weight[i], wv, uc, u);
        let (sampled, l) = if first { (metal_ok, metal_sample.l) } else { (base_ok, base_sample.l) };
        let (f, pdf) = Self::eval_pdf(v, tables, i, wv, l);
        (sampled && pdf > 0.0, BsdfSample { l, f, pdf, delta: false, eta: 1.0, dispersive: false })
    }
}

/// A rough conductor (Trowbridge–Reitz facets, Smith's shadowing; Schlick's Fresnel term
/// where `SCHLICK`) giving back the light of several facets: [`Conductor::eval_pdf`] and
/// [`Conductor::sample`], its lobe seen from the viewer found before the loop
/// (`several_seen`).
struct SeveralConductor<const SCHLICK: bool>(Conductor, (MultipleScattering, f64));

impl<const SCHLICK: bool> SeveralConductor<SCHLICK> {
    /// Lane `i`'s metal without its lobe of several facets.
    #[inline(always)]
    fn metal(v: &Vertices, i: usize) -> Conductor {
        let facets = Microfacet::smith::<false>(v.alpha[0][i], v.alpha[1][i]);
        let (eta, k, tint) = (get(&v.eta, i), get(&v.k, i), get(&v.tint, i));
        Conductor { facets: Some(facets), eta, k, tint, schlick: SCHLICK, multiscatter: None, film: None }
    }
}

impl<const SCHLICK: bool> MicrofacetLobes for SeveralConductor<SCHLICK> {
    #[inline(always)]
    fn rough_eval_pdf(&self, facets: &Microfacet, v: Vec3, l: Vec3) -> (Vec3, f64) {
        let (ms, p) = self.1;
        self.0.eval_pdf_with(facets, Some((&ms, p)), v, l)
    }

    #[inline(always)]
    fn rough_sample(&self, facets: &Microfacet, v: Vec3, uc: f64, u: Vec2) -> (bool, BsdfSample) {
        let (ms, p) = self.1;
        self.0.several_sample_whole(facets, (&ms, p), v, uc, u)
    }
}

impl<const SCHLICK: bool> RoughBsdf for SeveralConductor<SCHLICK> {
    #[inline(always)]
    fn at(v: &Vertices, tables: Tables<'_>, i: usize, facets: Microfacet) -> Self {
        SeveralConductor(Conductor { facets: Some(facets), ..Self::metal(v, i) }, tables.several_seen[i])
    }
}

/// Every lane's vertex at once as `kernel` shades it (lanes from `len` on, unused, may be
/// left as they were).
fn shade_with(kernel: Kernel, v: &Vertices, tables: Tables<'_>, out: &mut Shaded, len: usize, unit: VectorUnit) {
    match kernel {
        Kernel::Lambert => shade::<Lambertian>(v, tables, out, len, unit),
        Kernel::OrenNayar => shade::<LaneOrenNayar>(v, tables, out, len, unit),
        Kernel::Phong => shade::<LaneDiffuseSpecular<PhongLobe>>(v, tables, out, len, unit),
        Kernel::BlinnPhong => shade::<LaneDiffuseSpecular<BlinnPhongLobe>>(v, tables, out, len, unit),
        Kernel::RoughConductor => shade::<Rough<Conductor, false>>(v, tables, out, len, unit),
        Kernel::RoughDielectric => shade::<Rough<Dielectric, false>>(v, tables, out, len, unit),
        Kernel::RoughPlastic => shade::<Rough<Plastic, false>>(v, tables, out, len, unit),
        Kernel::BeckmannConductor => shade::<Rough<Conductor, true>>(v, tables, out, len, unit),
        Kernel::BeckmannDielectric => shade::<Rough<Dielectric, true>>(v, tables, out, len, unit),
        Kernel::BeckmannPlastic => shade::<Rough<Plastic, true>>(v, tables, out, len, unit),
        Kernel::CookTorrance => shade::<Rough<LaneCookTorrance, false>>(v, tables, out, len, unit),
        Kernel::BeckmannCookTorrance => shade::<Rough<LaneCookTorrance, true>>(v, tables, out, len, unit),
        Kernel::SmoothConductor => shade::<SmoothConductor<false>>(v, tables, out, len, unit),
        Kernel::RoughSchlickConductor => shade::<Rough<SchlickConductor, false>>(v, tables, out, len, unit),
        Kernel::BeckmannSchlickConductor => shade::<Rough<SchlickConductor, true>>(v, tables, out, len, unit),
        Kernel::SmoothSchlickConductor => shade::<SmoothConductor<true>>(v, tables, out, len, unit),
        Kernel::LambertMirror => shade::<LambertMirror>(v, tables, out, len, unit),
        Kernel::MetallicRoughness => shade::<MetallicRoughness<false>>(v, tables, out, len, unit),
        Kernel::SeveralMetallicRoughness => shade::<MetallicRoughness<true>>(v, tables, out, len, unit),
        Kernel::SeveralConductor => shade::<Rough<SeveralConductor<false>, false>>(v, tables, out, len, unit),
        Kernel::SeveralSchlickConductor => shade::<Rough<SeveralConductor<true>, false>>(v, tables, out, len, unit),
        Kernel::CoatedLambert => shade::<LaneCoated<Lambertian>>(v, tables, out, len, unit),
        Kernel::CoatedCookTorrance => shade::<LaneCoated<Rough<LaneCookTorrance, false>>>(v, tables, out, len, unit),
        Kernel::CoatedMetallicRoughness => shade::<LaneCoated<MetallicRoughness<false>>>(v, tables, out, len, unit),
        Kernel::CoatedSeveralMetallicRoughness => {
            shade::<LaneCoated<MetallicRoughness<true>>>(v, tables, out, len, unit)
        }
        Kernel::SmoothDielectric => shade::<SmoothDielectric>(v, tables, out, len, unit),
        Kernel::ThinDielectric => shade::<ThinDielectric>(v, tables, out, len, unit),
        Kernel::SmoothPlastic => shade::<SmoothPlastic>(v, tables, out, len, unit),
        Kernel::Idle | Kernel::General | Kernel::Escaped => {}
    }
}

/// Every lane's vertex at once as material `M` shades it, with the per-path tracer's
/// arithmetic; with the bump terminator's arithmetic where some lane's normal may be bent (a
/// kernel apiece, the plain one as lean as before bump maps took it).
fn shade<M: LaneBsdf>(v: &Vertices, tables: Tables<'_>, out: &mut Shaded, len: usize, unit: VectorUnit) {
    if v.bumped.any() {
        shade_in::<M, true>(v, tables, out, len, unit)
    } else {
        shade_in::<M, false>(v, tables, out, len, unit)
    }
}

/// Half the lanes: a batch of at most this many vertices is shaded in half a vector loop
/// (up to a third of the suite's batches are, the last of their kernel in a bounce).
const HALF: usize = LANES / 2;

#[allow(unsafe_code)]
fn shade_in<M: LaneBsdf, const BUMPS: bool>(
    v: &Vertices,
    tables: Tables<'_>,
    out: &mut Shaded,
    len: usize,
    unit: VectorUnit,
) {
    #[cfg(target_arch = "x86_64")]
    if unit.is_avx512() {
        // SAFETY: a `VectorUnit` says AVX-512 (F, DQ, VL, BW) only where the processor has them.
        return unsafe { shade_avx512::<M, BUMPS>(v, tables, out, len) };
    }
    #[cfg(target_arch = "x86_64")]
    if unit.is_avx2() {
        // SAFETY: a `VectorUnit` says AVX2 only where the processor has it.
        return unsafe { shade_avx2::<M, BUMPS>(v, tables, out, len) };
    }
    let _ = unit;
    (0..len).for_each(|i| shade_lane::<M, BUMPS>(v, tables, out, i));
}

/// One loop over all lanes, or over the first half of them for a batch that fits.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512dq,avx512vl,avx512bw")]
#[allow(unsafe_code)]
unsafe fn shade_avx512<M: LaneBsdf, const BUMPS: bool>(v: &Vertices, tables: Tables<'_>, out: &mut Shaded, len: usize) {
    if len <= HALF {
        shade_lanes::<M, BUMPS, 0, HALF>(v, tables, out)
    } else {
        shade_lanes::<M, BUMPS, 0, LANES>(v, tables, out)
    }
}

/// A loop over each half of the lanes (an AVX2 register of `f64` each), the second only where
/// the batch reaches it.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[allow(unsafe_code)]
unsafe fn shade_avx2<M: LaneBsdf, const BUMPS: bool>(v: &Vertices, tables: Tables<'_>, out: &mut Shaded, len: usize) {
    shade_lanes::<M, BUMPS, 0, HALF>(v, tables, out);
    if len > HALF {
        shade_lanes::<M, BUMPS, HALF, LANES>(v, tables, out);
    }
}

/// Lanes `FROM..TO` in one loop without branches.
#[inline(always)]
fn shade_lanes<M: LaneBsdf, const BUMPS: bool, const FROM: usize, const TO: usize>(
    v: &Vertices,
    tables: Tables<'_>,
    out: &mut Shaded,
) {
    for i in FROM..TO {
        shade_lane::<M, BUMPS>(v, tables, out, i);
    }
}

/// Lane `i`'s vertex: the per-path tracer's own functions (`shading_frame`'s rule, `M`'s
/// frame, evaluation and sampling, [`offset`], `epsilon`, [`power_heuristic`]) on one lane,
/// inlined into the all-lane loop.
#[inline(always)]
fn shade_lane<M: LaneBsdf, const BUMPS: bool>(v: &Vertices, tables: Tables<'_>, out: &mut Shaded, i: usize) {
    let p = get(&v.p, i);
    let View { ng, ns, n0, frame, wv } = view::<M>(v, i);
    // The bump terminator's shadowing (`Terminator::shadowing`), chosen without branches.
    let (bent, terminator) = Terminator::bent(n0, ns);
    let bent = BUMPS && v.bumped.at(i) && bent;
    let shadowing = |dir: Vec3| if bent { terminator.factor(dir) } else { 1.0 };
    // Next event (`PathTracer::next_event`).
    let dir = get(&v.light_dir, i);
    let l = frame.to_local(dir);
    let (f, pdf_bsdf) = M::eval_pdf(v, tables, i, wv, l);
    let f = f * l.z.abs() * shadowing(dir);
    let shadow = v.light.at(i) && !(f == Vec3::ZERO || (ng.dot(dir) > 0.0) != (l.z > 0.0) && !M::TRANSMITS);
    let pdf_light = v.light_pdf[i];
    let w = if v.light_delta.at(i) { 1.0 } else { power_heuristic(pdf_light, pdf_bsdf) };
    let c = if shadow { f * get(&v.light_radiance, i) * (w / pdf_light) } else { Vec3::ZERO };
    set(&mut out.light, i, c);
    out.shadow.put(i, shadow);
    let (origin, toward, dist) = shadow_segment(p, ng, dir, v.light_dist[i], p);
    set(&mut out.shadow_origin, i, origin);
    set(&mut out.shadow_dir, i, toward);
    out.shadow_dist[i] = dist;
    // The continuation.
    let (sampled, bs) = M::sample(v, tables, i, wv, v.u_lobe[i], Vec2::new(v.u_bsdf[0][i], v.u_bsdf[1][i]));
    let (l, pdf) = (bs.l, bs.pdf);
    let dir = frame.to_world(l);
    let weight = bs.f * (l.z.abs() / pdf) * shadowing(dir);
    let mut beta = get(&v.beta, i) * weight;
    let eta_scale = v.eta_scale[i] * (bs.eta * bs.eta);
    let mut alive = sampled && pdf > 0.0 && weight.is_finite() && weight != Vec3::ZERO;
    if v.roulette.at(i) {
        let q = (beta.max_element() * eta_scale).min(0.95);
        // `u ≥ q` ends the path (u is never NaN; a NaN q does not end it).
        alive &= v.u_roulette[i] < q || q.is_nan();
        beta *= 1.0 / q;
    }
    out.alive.put(i, alive);
    out.pdf[i] = pdf;
    out.delta.put(i, bs.delta);
    out.eta_scale[i] = eta_scale;
    set(&mut out.beta, i, beta);
    set(&mut out.dir, i, dir);
    set(&mut out.origin, i, offset(p, ng, dir));
}

/// Lane `i`'s shading frame as `M` turns it (`PathTracer::shading_frame`): its geometric,
/// shading and unbent normals turned towards the viewer (unless `M` transmits), the frame, and
/// the viewer in it.
struct View {
    ng: Vec3,
    ns: Vec3,
    n0: Vec3,
    frame: Frame,
    wv: Vec3,
}

#[inline(always)]
fn view<M: LaneBsdf>(v: &Vertices, i: usize) -> View {
    let wo = get(&v.wo, i);
    let (mut ng, mut ns, mut n0) = (get(&v.ng, i), get(&v.ns, i), get(&v.n0, i));
    if !M::TRANSMITS && ng.dot(wo) < 0.0 {
        (ng, ns, n0) = (-ng, -ns, -n0);
    }
    if ns.dot(wo) * ng.dot(wo) <= 0.0 {
        ns = ng;
    }
    let frame = M::frame(v, i, ns);
    View { ng, ns, n0, frame, wv: frame.to_local(wo) }
}

/// Each Cook–Torrance vertex's diffuse weight seen from its viewer
/// ([`CookTorranceLobe::diffuse_weight`], 1 where it is not layered), for the kernels that have
/// one, found one lane after another before the kernel's vector loop: a table lookup inside it
/// would keep the loop scalar.
fn weigh_layers(kernel: Kernel, v: &mut Vertices, several_seen: &mut [(MultipleScattering, f64); LANES], len: usize) {
    match kernel {
        Kernel::CookTorrance => weigh_layers_of::<Rough<LaneCookTorrance, false>>(v, len, |v, i| {
            Microfacet::smith::<false>(v.alpha[0][i], v.alpha[1][i])
        }),
        Kernel::BeckmannCookTorrance => weigh_layers_of::<Rough<LaneCookTorrance, true>>(v, len, |v, i| {
            Microfacet::smith::<true>(v.alpha[0][i], v.alpha[1][i])
        }),
        Kernel::MetallicRoughness => weigh_layers_of::<MetallicRoughness<false>>(v, len, |v, i| {
            Microfacet::smith::<false>(v.alpha[1][i], v.alpha[1][i])
        }),
        Kernel::SeveralMetallicRoughness => {
            type M = MetallicRoughness<true>;
            weigh_layers_of::<M>(v, len, |v, i| Microfacet::smith::<false>(v.alpha[1][i], v.alpha[1][i]));
            weigh_several::<M>(v, several_seen, len, |v, i| M::at(v, i).0.0);
        }
        Kernel::SeveralConductor => {
            type M = Rough<SeveralConductor<false>, false>;
            weigh_several::<M>(v, several_seen, len, SeveralConductor::<false>::metal);
        }
        Kernel::SeveralSchlickConductor => {
            type M = Rough<SeveralConductor<true>, false>;
            weigh_several::<M>(v, several_seen, len, SeveralConductor::<true>::metal);
        }
        Kernel::CoatedLambert => weigh_coats::<LaneCoated<Lambertian>>(v, len),
        Kernel::CoatedCookTorrance => {
            type M = LaneCoated<Rough<LaneCookTorrance, false>>;
            weigh_layers_of::<M>(v, len, |v, i| Microfacet::smith::<false>(v.alpha[0][i], v.alpha[1][i]));
            weigh_coats::<M>(v, len);
        }
        Kernel::CoatedMetallicRoughness => {
            type M = LaneCoated<MetallicRoughness<false>>;
            weigh_layers_of::<M>(v, len, |v, i| Microfacet::smith::<false>(v.alpha[1][i], v.alpha[1][i]));
            weigh_coats::<M>(v, len);
        }
        Kernel::CoatedSeveralMetallicRoughness => {
            type M = LaneCoated<MetallicRoughness<true>>;
            weigh_layers_of::<M>(v, len, |v, i| Microfacet::smith::<false>(v.alpha[1][i], v.alpha[1][i]));
            weigh_coats::<M>(v, len);
            weigh_several::<M>(v, several_seen, len, |v, i| MetallicRoughness::<true>::at(v, i).0.0);
        }
        _ => {}
    }
}

/// Each coated vertex's coat albedo towards its viewer ([`crate::bsdf::Coated::coat_albedo`]),
/// for kernel `M`.
fn weigh_coats<M: LaneBsdf>(v: &mut Vertices, len: usize) {
    let mut coats = v.coats.take().unwrap_or_default();
    for i in 0..len {
        let cos = view::<M>(v, i).wv.z;
        coats.albedo[i] = coat_albedo(coats.weight[i], coats.row[i], coats.ior[i], cos);
    }
    v.coats = Some(coats);
}

/// Each vertex's metal's lobe of several facets seen from its viewer, with the probability of
/// sampling it ([`Conductor::lobe_seen_from`]), for kernel `M` whose lane `i`'s metal
/// (without that lobe) `metal` gives (a coat over the metal sees it from the same direction).
fn weigh_several<M: LaneBsdf>(
    v: &Vertices,
    seen: &mut [(MultipleScattering, f64); LANES],
    len: usize,
    metal: impl Fn(&Vertices, usize) -> Conductor,
) {
    let several = v.several.as_deref().unwrap_or(&NO_FACETS);
    for i in 0..len {
        let metal = Conductor { multiscatter: Some(several[i]), ..metal(v, i) };
        seen[i] = metal.lobe_seen_from(view::<M>(v, i).wv).unwrap_or_default();
    }
}

/// [`weigh_layers`] for kernel `M`, whose Cook–Torrance lobe has the facets `facets` gives.
fn weigh_layers_of<M: LaneBsdf>(v: &mut Vertices, len: usize, facets: impl Fn(&Vertices, usize) -> Microfacet) {
    for i in 0..len {
        v.diffuse_weight[i] = if v.layer[i] == 0.0 {
            1.0
        } else {
            let lobe = CookTorranceLobe { facets: facets(v, i), ior: v.ior[i], schlick: false, layer: v.layer[i] };
            lobe.diffuse_weight(view::<M>(v, i).wv.z)
        };
    }
}

/// `!(x <= 0)`, as the per-path tracer's rejections read (NaN passes).
#[inline(always)]
fn not_at_most_zero(x: f64) -> bool {
    x > 0.0 || x.is_nan()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::film::PixelEstimator;
    use crate::shape::VectorUnit;
    use crate::{Camera, World};

    /// A scene of every kind of material and light: Lambert, Oren–Nayar, Cook–Torrance and
    /// textured surfaces, bump maps, rough and smooth glass, rough conductors (one anisotropic
    /// and bump-mapped, one of Beckmann facets) and a smooth one, rough plastics (one textured,
    /// one of Beckmann facets) and a smooth one, Beckmann glass, glass that absorbs (rough
    /// and smooth), tinted glass (rough, and smooth under a checkered tint), Phong and
    /// anisotropic Blinn–Phong, a mirror
    /// (with specular connections) and a Lambert surface with a mirror's gloss (the course's
    /// Whitted material), a glTF metallic–roughness mix, Schlick conductors (a glTF metal's; rough and smooth),
    /// spheres, boxes and a plane, an emitting box (triangles)
    /// and sphere, point and spot lights, a gradient sky.
    const MIXED: &str = r#"
background = { zenith = [0.3, 0.4, 0.9], horizon = [0.8, 0.8, 0.7], ground = [0.2, 0.15, 0.1] }
[render]
width = 24
height = 18
spp = 13
max_depth = 6
integrator = "path"
mirror_connections = true
[camera]
eye = [0, 1.5, 6]
target = [0, 0.5, 0]
[[light]]
type = "point"
position = [2, 4, 3]
intensity = 6
[[light]]
type = "spot"
position = [-3, 4, 2]
direction = [0.5, -1, -0.3]
angle = 30
intensity = 8
[materials.glow]
color = [0.5, 0.5, 0.5]
emission = [4, 3, 2]
[materials.chrome]
color = 0
diffuse = 0
mirror = 0.9
[[object]]
shape = "plane"
normal = [0, 1, 0]
material = { color = { checker = { even = [0.7, 0.7, 0.6], odd = [0.2, 0.2, 0.2], size = 0.5 } }, bump = { height = 0.02, waves = 0.5 } }
[[object]]
shape = "sphere"
center = [-1, 1, 0]
radius = 1
material = { bsdf = { type = "conductor", roughness = 0.2, distribution = "ggx", eta = [0.2, 0.4, 1.4], k = [3.9, 2.4, 1.6] } }
[[object]]
shape = "sphere"
center = [-0.6, 0.35, 2.2]
radius = 0.35
material = { bsdf = { type = "plastic", roughness = 0.15, distribution = "ggx", ior = 1.5, color = { checker = { even = [0.8, 0.2, 0.1], odd = [0.1, 0.3, 0.8], size = 0.2 } } } }
[[object]]
shape = "sphere"
center = [-1.4, 0.3, 2.6]
radius = 0.3
material = { bsdf = { type = "plastic", roughness = 0.3, distribution = "ggx", ior = 1.6, nonlinear = true, color = [0.2, 0.6, 0.3] } }
[[object]]
shape = "box"
min = [1.8, 0, 1.6]
max = [2.3, 0.5, 2.1]
material = { bsdf = { type = "plastic", ior = 1.5, color = [0.7, 0.6, 0.2] } }
[[object]]
shape = "sphere"
center = [-2.6, 1.5, -0.5]
radius = 0.45
material = { bsdf = { type = "conductor", roughness = 0.12, distribution = "beckmann", eta = [0.2, 0.4, 1.4], k = [3.9, 2.4, 1.6] } }
[[object]]
shape = "sphere"
center = [0.0, 1.9, 1.0]
radius = 0.3
material = { bsdf = { type = "dielectric", roughness = 0.2, distribution = "beckmann", ior = 1.33 } }
[[object]]
shape = "sphere"
center = [1.3, 0.3, 3.0]
radius = 0.3
material = { bsdf = { type = "plastic", roughness = 0.25, distribution = "beckmann", ior = 1.5, color = [0.3, 0.3, 0.8] } }
[[object]]
shape = "sphere"
center = [0.9, 0.25, 2.4]
radius = 0.25
material = { bsdf = { type = "conductor", eta = [0.2, 0.9, 1.1], k = [3.9, 2.4, 2.2] } }
[[object]]
shape = "sphere"
center = [2.4, 1.6, -1.5]
radius = 0.7
material = { bsdf = { type = "conductor", roughness = [0.05, 0.35], distribution = "ggx", eta = [0.14, 0.37, 1.4], k = [3.98, 2.39, 1.6] }, bump = { height = 0.03, waves = 0.4 } }
[[object]]
shape = "sphere"
center = [0.3, 0.5, 1.2]
radius = 0.5
material = { bsdf = { type = "dielectric", roughness = 0.15, distribution = "ggx", ior = 1.5 }, absorption = [0.2, 0.9, 1.6] }
[[object]]
shape = "sphere"
center = [-2.2, 0.4, 1.5]
radius = 0.4
material = { bsdf = { type = "dielectric", ior = 1.5 }, absorption = [1.5, 0.4, 0.1] }
[[object]]
shape = "sphere"
center = [1.6, 0.6, -0.8]
radius = 0.6
material = "chrome"
[[object]]
shape = "box"
min = [0.5, 0, -1]
max = [1.5, 1.2, 0]
material = { bsdf = { type = "cook-torrance", roughness = 0.1, distribution = "beckmann", color = [0.2, 0.7, 0.3], kd = 0.7, ks = 0.3 } }
[[object]]
shape = "sphere"
center = [-1.3, 0.3, 2.9]
radius = 0.3
material = { bsdf = { type = "cook-torrance", roughness = 0.2, distribution = "ggx", color = { checker = { even = [0.8, 0.3, 0.1], odd = [0.1, 0.2, 0.7], size = 0.1 } }, ks = 1.0, layered = true } }
[[object]]
shape = "box"
min = [-2.5, 0, -2]
max = [-1.8, 0.6, -1.3]
material = { bsdf = { type = "oren-nayar", sigma = 20, color = [0.6, 0.5, 0.3] } }
[[object]]
shape = "box"
min = [-0.3, 2.5, -0.3]
max = [0.3, 2.7, 0.3]
material = "glow"
[[object]]
shape = "sphere"
center = [2, 0.4, 1]
radius = 0.4
material = "glow"
[[object]]
shape = "sphere"
center = [-0.2, 0.2, 3.2]
radius = 0.2
material = { bsdf = { type = "conductor", roughness = 0.25, distribution = "ggx", eta = [1.8, 1.2, 0.6], k = [0, 0, 0], fresnel = "schlick" } }
[[object]]
shape = "box"
min = [-3.2, 0, 0.4]
max = [-2.6, 0.9, 1.0]
material = { bsdf = { type = "conductor", eta = [2.1, 1.5, 0.9], k = [0, 0, 0], fresnel = "schlick" } }
[[object]]
shape = "sphere"
center = [2.8, 0.3, 0.2]
radius = 0.3
material = { bsdf = { type = "conductor", roughness = 0.3, distribution = "beckmann", eta = [0.3, 0.5, 1.2], k = [3, 2.5, 2], fresnel = "schlick" } }
[[object]]
shape = "box"
min = [2.6, 0, -0.6]
max = [3.4, 0.7, 0.0]
material = { color = [0.6, 0.3, 0.2], mirror = [0.5, 0.4, 0.3] }
[[object]]
shape = "sphere"
center = [0.9, 1.5, -1.2]
radius = 0.35
material = { bsdf = { type = "mix", weight = 0.6, a = { type = "conductor", roughness = 0.2, distribution = "ggx", eta = [2.0, 1.6, 1.2], k = [0, 0, 0], fresnel = "schlick" }, b = { type = "cook-torrance", roughness = 0.3, distribution = "ggx", color = [0.3, 0.5, 0.2], kd = 0.96, ks = 1.0, ior = 1.5 } } }
[[object]]
name = "metallic-roughness"
shape = "sphere"
center = [-1.9, 2.1, -2.0]
radius = 0.4
material = { bsdf = { type = "metallic-roughness", metallic = 0.9, roughness = 0.8, color = { checker = { even = [0.9, 0.6, 0.2], odd = [0.3, 0.3, 0.35], size = 0.15 } } } }
[[object]]
shape = "sphere"
center = [-0.9, 2.3, -1.4]
radius = 0.3
material = { bsdf = { type = "phong", ks = 0.4, exponent = 40, color = { checker = { even = [0.9, 0.2, 0.2], odd = [0.2, 0.2, 0.9], size = 0.1 } } } }
[[object]]
shape = "box"
min = [0.8, 2.0, -2.4]
max = [1.5, 2.6, -1.8]
material = { bsdf = { type = "blinn-phong", ks = 0.5, exponent = 25, anisotropy = 0.2, scratches = [1, 0, 1], color = [0.7, 0.7, 0.2] } }
[[object]]
shape = "sphere"
center = [0.4, 0.35, 2.6]
radius = 0.35
material = { bsdf = { type = "dielectric", ior = 1.45, transmittance = { checker = { even = [1, 1, 1], odd = [0.5, 0.8, 0.6], size = 0.15 } } } }
[[object]]
shape = "sphere"
center = [-0.5, 1.0, 0.6]
radius = 0.3
material = { bsdf = { type = "dielectric", roughness = 0.2, distribution = "ggx", ior = 1.5, transmittance = [0.6, 0.8, 0.9] } }
[[object]]
shape = "sphere"
center = [1.9, 0.35, 2.6]
radius = 0.35
material = { bsdf = { type = "coated", roughness = 0.05, weight = 0.8, base = { type = "lambert", color = { checker = { even = [0.8, 0.1, 0.1], odd = [0.9, 0.9, 0.8], size = 0.1 } } } } }
[[object]]
shape = "box"
min = [-1.2, 0, -2.8]
max = [-0.4, 0.8, -2.0]
material = { bsdf = { type = "coated", roughness = 0.15, ior = 1.6, base = { type = "cook-torrance", roughness = 0.3, distribution = "ggx", color = [0.2, 0.3, 0.7], ks = 1.0, layered = true } } }
[[object]]
shape = "sphere"
center = [2.9, 1.2, 1.2]
radius = 0.4
material = { bsdf = { type = "coated", roughness = 0.02, base = { type = "metallic-roughness", metallic = 0.6, roughness = 0.5, color = [0.7, 0.1, 0.1] } } }
[[object]]
shape = "sphere"
center = [-2.6, 0.45, 1.6]
radius = 0.45
material = { bsdf = { type = "metallic-roughness", metallic = 0.7, roughness = 0.45, multiscatter = true, color = { checker = { even = [0.95, 0.7, 0.3], odd = [0.2, 0.5, 0.3], size = 0.12 } } } }
[[object]]
shape = "box"
min = [2.2, 1.6, -2.8]
max = [2.9, 2.3, -2.1]
material = { bsdf = { type = "coated", roughness = 0.1, weight = 0.7, base = { type = "metallic-roughness", metallic = 0.4, roughness = 0.6, multiscatter = true, color = [0.3, 0.6, 0.9] } } }
[[object]]
shape = "sphere"
center = [-2.9, 1.5, 0.2]
radius = 0.4
material = { bsdf = { type = "conductor", roughness = 0.55, distribution = "ggx", eta = [3.0, 2.2, 1.5], k = [0, 0, 0], fresnel = "schlick", multiscatter = true, tint = [0.95, 0.9, 0.8] } }
[[object]]
shape = "sphere"
center = [1.6, 2.4, 0.8]
radius = 0.35
material = { bsdf = { type = "conductor", metal = "copper", roughness = 0.35, multiscatter = true } }
[[object]]
shape = "box"
min = [-2.2, 0.0, 2.0]
max = [-1.2, 1.1, 2.5]
material = { bsdf = { type = "thin-dielectric", ior = 1.5 } }
"#;

    /// [`MIXED`] with its metallic–roughness sphere given a map (4 × 4 texels: roughness from
    /// 0 to 1 along u in green, metalness 0, ½, 1 and 1 from the top row down in blue).
    fn mixed_scene() -> alhazen_scene::Scene {
        let mut scene = alhazen_scene::parse_scene("mixed.toml".as_ref(), MIXED).unwrap();
        let texels = (0..16).map(|i| [0.0, (i % 4) as f32 / 3.0, [0.0, 0.5, 1.0, 1.0][i / 4]]).collect();
        scene.images.push(std::sync::Arc::new(alhazen_scene::ImageData::new(4, 4, texels)));
        let image = scene.images.len() - 1;
        let material = mapped_material(&scene);
        let bsdf = scene.materials[material].bsdf.as_mut();
        let Some(alhazen_scene::bsdf::BsdfDesc::MetallicRoughness { map, .. }) = bsdf else { panic!("{bsdf:?}") };
        *map = Some(alhazen_scene::Texture::Image {
            image,
            scale: alhazen_math::Vec2::ONE,
            offset: alhazen_math::Vec2::ZERO,
            rotation: 0.0,
        });
        scene
    }

    /// The material of [`MIXED`]'s metallic–roughness sphere.
    fn mapped_material(scene: &alhazen_scene::Scene) -> usize {
        let object = scene.objects.iter().find(|o| o.name.as_deref() == Some("metallic-roughness")).unwrap();
        object.material as usize
    }

    /// Every sample of every pixel, `(in lanes, per path)`, in full precision, with `unit`'s
    /// kernels.
    fn samples(scene: &alhazen_scene::Scene, unit: VectorUnit) -> (Vec<Vec3>, Vec<Vec3>) {
        samples_with(scene, unit, crate::lights::LightSampling::AgainstBsdf)
    }

    /// Every sample the same, bit for bit.
    fn same_bits(a: &[Vec3], b: &[Vec3]) -> bool {
        a.len() == b.len()
            && a.iter().zip(b).all(|(a, b)| a.to_array().map(f64::to_bits) == b.to_array().map(f64::to_bits))
    }

    /// [`samples`] with the lights sampled as `sampling` says.
    fn samples_with(
        scene: &alhazen_scene::Scene,
        unit: VectorUnit,
        sampling: crate::lights::LightSampling,
    ) -> (Vec<Vec3>, Vec<Vec3>) {
        let world = World::build_with(scene, unit);
        let camera = Camera::new(&scene.camera, scene.render.width, scene.render.height);
        let mut tracer = PathTracer::with_light_sampling(scene, &world, &camera, sampling);
        let mut all = [vec![], vec![]];
        for (in_lanes, out) in [true, false].into_iter().zip(&mut all) {
            tracer.in_lanes = in_lanes;
            // Rows of pixels traced together, and single pixels.
            let (w, h, spp) = (camera.film_width, camera.film_height, scene.render.spp as usize);
            for y in 0..h {
                let row: Vec<(u32, u32)> = (0..w).map(|x| (x, y)).collect();
                let mut samples = vec![Vec3::NAN; spp * row.len()];
                if y % 2 == 0 {
                    tracer.pixels_samples(&row, 0, &mut samples);
                } else {
                    samples.chunks_mut(spp).zip(&row).for_each(|(s, &(x, y))| tracer.samples(x, y, 0, s));
                }
                out.extend(samples);
            }
        }
        let [lanes, per_path] = all;
        (lanes, per_path)
    }

    fn small(name: &str, (w, h, spp): (u32, u32, u32)) -> alhazen_scene::Scene {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
        let mut scene = alhazen_scene::load_scene(&root.join(format!("{name}.toml"))).unwrap();
        (scene.render.width, scene.render.height, scene.render.spp) = (w, h, spp);
        scene.render.integrator = alhazen_scene::IntegratorKind::Path;
        scene
    }

    /// The lanes trace the same bits as the per-path tracer, on every kind of scene: the
    /// Cornell box (flats in one leaf: rays tested eight at once), with two lights, its rough
    /// version (gold and glass spheres in the same leaf), the prism (spectral), textures, bump maps, mirrors with
    /// specular connections and every light type (`MIXED`); every depth from 0, sample counts
    /// that leave lanes idle; with every vector unit this processor has.
    #[test]
    fn lanes_match_the_per_path_tracer() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
        let mixed = mixed_scene();
        // Two parallelogram lights: the vertices choose one.
        let text = std::fs::read_to_string(root.join("cornell-box.toml")).unwrap()
            + "[[object]]\nshape = \"rectangle\"\nmaterial = \"light\"\n\
               transform = [{ scale = 0.2 }, { rotate_y = 90 }, { translate = [0.9, 0.2, 0] }]\n";
        let mut two_lights = alhazen_scene::parse_scene("two-lights.toml".as_ref(), &text).unwrap();
        (two_lights.render.width, two_lights.render.height, two_lights.render.spp) = (16, 16, 9);
        // Without specular connections its textured, bump-mapped plane takes the Lambert
        // kernel, its conductors, plastics and glass theirs.
        let mut unconnected = mixed.clone();
        unconnected.render.mirror_connections = false;
        // The same under an environment map (a bright spot on a gradient), sampled and looked
        // up for all lanes at once.
        let mut environment = unconnected.clone();
        let (w, h) = (64, 32);
        let texels = (0..w * h).map(|i| {
            let (x, y) = ((i % w) as f32, (i / w) as f32);
            if (x - 40.0).abs() < 2.0 && (y - 9.0).abs() < 2.0 {
                [60.0, 50.0, 40.0]
            } else {
                [0.2 + x / 90.0, 0.3, y / 40.0]
            }
        });
        environment.images.push(std::sync::Arc::new(alhazen_scene::ImageData::new(
            w as u32,
            h as u32,
            texels.collect(),
        )));
        let image = environment.images.len() - 1;
        environment.lights.push(alhazen_scene::Light::Environment { image, scale: 1.0, rotation: 0.3, up: Vec3::Y });
        // Glass whose index and its inverse do not square to exactly 1 (1.52² · (1/1.52)²):
        // Lambert vertices after it see a path's `eta_scale` off 1 in the last bit.
        let mut glass = small("cornell-rough", (16, 16, 9));
        for m in &mut glass.materials {
            if let Some(alhazen_scene::bsdf::BsdfDesc::Dielectric { ior, .. }) = &mut m.bsdf {
                *ior = alhazen_scene::bsdf::Ior::Constant(1.52);
            }
        }
        // A sky of one colour beside parallelogram lights: left to BSDF samples (and, below,
        // sampled among the lights, which the lanes leave to `Lights::sample`).
        let sky = alhazen_scene::Background::Solid(Vec3::new(0.3, 0.4, 0.5));
        let mut two_lights_and_sky = two_lights.clone();
        two_lights_and_sky.background = sky;
        let mut rough_under_sky = small("cornell-rough", (16, 16, 7));
        rough_under_sky.background = sky;
        // Point lights beside a parallelogram and a sky: the lanes sample them too (one on
        // the floor's plane, whose points there are at no distance from it).
        let mut points = small("cornell-rough", (16, 16, 9));
        points.background = sky;
        for (position, intensity) in [(Vec3::new(0.3, 0.6, 0.4), 0.5), (Vec3::new(-0.5, -1.0, 0.2), 0.2)] {
            let intensity = Vec3::splat(intensity);
            points.lights.push(alhazen_scene::Light::Point { position, intensity, attenuation: [1.0, 0.0, 0.0] });
        }
        // Cut-outs in every surface: squares present, squares three-fifths present (a ray's
        // passage decided by its hash); rays lost to the sky through the holes.
        let mut cut = small("cornell-box", (16, 16, 9));
        cut.background = sky;
        for m in &mut cut.materials {
            let (even, odd) = (Vec3::ONE, Vec3::splat(0.6));
            let coverage = alhazen_scene::Texture::Checker { even, odd, size: 0.25 };
            m.alpha = Some(alhazen_scene::Alpha { coverage, cutoff: None });
        }
        // Through a thin lens: each sample's lens point drawn from its stream.
        let mut through_lens = small("cornell-box", (16, 16, 9));
        if let alhazen_scene::CameraDesc::Perspective { lens, .. } = &mut through_lens.camera {
            *lens = Some(alhazen_scene::ThinLens { aperture: 0.1, focus_distance: 2.5 });
        }
        // Through a filter of negative lobes: the samples placed beyond their pixels, weighed ±.
        let mut filtered = small("cornell-box", (16, 16, 9));
        filtered.render.filter = alhazen_scene::PixelFilter::Mitchell { b: 0.0, c: 0.5, radius: [2.0, 1.5] };
        // Thin sheets lit from behind, metallic–roughness with a diffuse transmission, one of
        // them mapped (each point's share read from a checker): the general kernel's.
        let sheets = alhazen_scene::parse_scene(
            "sheets.toml".as_ref(),
            "[render]\nwidth = 16\nheight = 12\nspp = 9\nintegrator = \"path\"\n[camera]\neye = [0, 0, 4]\n\
             [[light]]\ntype = \"directional\"\ndirection = [0.2, 0, 1]\nintensity = 3\n\
             [materials.leaf]\nbsdf = { type = \"metallic-roughness\", color = [0.3, 0.6, 0.2], diffuse_transmission = { factor = 0.8, color = [1, 0.5, 0.2], color_map = { checker = { even = [1, 1, 1], odd = [0.2, 0.2, 0.2], size = 0.5 } } } }\n\
             [materials.paper]\nbsdf = { type = \"metallic-roughness\", metallic = 0.3, diffuse_transmission = { factor = 0.5 } }\n\
             [[object]]\nshape = \"rectangle\"\nmaterial = \"leaf\"\ntransform = [{ scale = [0.7, 1, 1] }, { translate = [-0.8, 0, 0] }]\n\
             [[object]]\nshape = \"rectangle\"\nmaterial = \"paper\"\ntransform = [{ scale = [0.7, 1, 1] }, { translate = [0.8, 0, 0] }]\n",
        )
        .unwrap();
        let scenes = [
            ("thin sheets lit from behind", sheets),
            ("cornell-box through a Catmull–Rom filter", filtered),
            ("cornell-box through a lens", through_lens),
            ("cornell-box, cut out", cut),
            ("point lights, a parallelogram and a sky", points),
            ("two lights and a sky", two_lights_and_sky.clone()),
            ("cornell-rough and a sky", rough_under_sky),
            ("cornell-box", small("cornell-box", (20, 20, 11))),
            ("cornell-rough, glass of index 1.52", glass),
            ("cornell-rough", small("cornell-rough", (16, 16, 7))),
            ("prism", small("prism", (16, 12, 5))),
            ("mixed", mixed),
            ("mixed, no specular connections", unconnected),
            ("mixed, under an environment map", environment),
            ("two lights", two_lights),
        ];
        for (name, base) in scenes {
            for depth in [0, 1, 2, 3, 8] {
                let mut scene = base.clone();
                scene.render.max_depth = depth;
                for unit in VectorUnit::available() {
                    let (lanes, per_path) = samples(&scene, unit);
                    assert!(
                        same_bits(&lanes, &per_path),
                        "{name}, max_depth {depth}, {}: the lanes' samples differ",
                        unit.name()
                    );
                    if depth > 2 {
                        assert!(lanes.iter().filter(|c| c.x > 0.0).count() > lanes.len() / 4, "{name}: lit");
                    }
                }
            }
        }
        for unit in VectorUnit::available() {
            let whole = crate::lights::LightSampling::Whole;
            let (lanes, per_path) = samples_with(&two_lights_and_sky, unit, whole);
            assert!(
                same_bits(&lanes, &per_path),
                "two lights and a sky sampled among them, {}: the lanes' samples differ",
                unit.name()
            );
        }
    }

    /// The course's BSDFs and the layered ones at the ends of their parameters — a Phong
    /// lobe of exponent 0 and 10⁵, Blinn–Phong of anisotropy 0.001 and exponent 0.01,
    /// Oren–Nayar of σ 90° and 0, coats of weight 0 and of index 3 over a smooth metal, black
    /// glass — give finite samples, the lanes' the per-path tracer's bits.
    #[test]
    fn extreme_parameters_give_finite_samples() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
        let text = std::fs::read_to_string(root.join("cornell-box.toml")).unwrap();
        let materials = [
            r#"{ type = "phong", color = [0.8, 0.8, 0.8], ks = 1.0, kd = 0, exponent = 0 }"#,
            r#"{ type = "phong", color = [0.8, 0.8, 0.8], ks = 0.5, exponent = 100000 }"#,
            r#"{ type = "blinn-phong", color = [0.8, 0.8, 0.8], ks = 0.9, exponent = 5000, anisotropy = 0.001 }"#,
            r#"{ type = "blinn-phong", color = [0.8, 0.8, 0.8], ks = 0.3, exponent = 0.01 }"#,
            r#"{ type = "oren-nayar", color = [0.8, 0.8, 0.8], sigma = 90 }"#,
            r#"{ type = "oren-nayar", color = [0.8, 0.8, 0.8], sigma = 0 }"#,
            r#"{ type = "coated", weight = 0, base = { type = "lambert", color = [0.8, 0.8, 0.8] } }"#,
            r#"{ type = "coated", roughness = 0.01, ior = 3, base = { type = "metallic-roughness", metallic = 1, roughness = 0 } }"#,
            r#"{ type = "dielectric", ior = 1.5, transmittance = [0, 0, 0] }"#,
        ];
        for bsdf in materials {
            let walls = text.replace(
                r#"bsdf = { type = "lambert", color = [0.885809, 0.698859, 0.666422] }"#,
                &format!("bsdf = {bsdf}"),
            );
            assert_ne!(walls, text, "the white walls take {bsdf}");
            let mut scene = alhazen_scene::parse_scene("extreme.toml".as_ref(), &walls).unwrap();
            (scene.render.width, scene.render.height, scene.render.spp, scene.render.max_depth) = (10, 10, 5, 5);
            let (lanes, per_path) = samples(&scene, VectorUnit::detect());
            assert!(lanes.iter().all(|c| c.is_finite()), "{bsdf}: not finite");
            assert!(same_bits(&lanes, &per_path), "{bsdf}: the lanes' samples differ");
        }
    }

    /// The mixed scene's materials take every material kernel, so that
    /// `lanes_match_the_per_path_tracer` checks each of them.
    #[test]
    fn the_mixed_scene_takes_every_kernel() {
        let scene = alhazen_scene::parse_scene("mixed.toml".as_ref(), MIXED).unwrap();
        let world = World::build(&scene);
        let camera = Camera::new(&scene.camera, 8, 8);
        let kernels = material_kernels(&PathTracer::new(&scene, &world, &camera));
        for k in MATERIAL_KERNELS {
            assert!(kernels.contains(&k), "{k:?}");
        }
    }

    /// Glass whose transmittance is an image, white at one texel: every point, that one
    /// included, takes the glass kernel (which carries each lane's tint), and so does clear
    /// glass under vertex colours and plain clear glass.
    #[test]
    fn glass_tinted_anywhere_takes_the_glass_kernel_everywhere() {
        use alhazen_scene::bsdf::{BsdfDesc, Ior};
        let images = [std::sync::Arc::new(alhazen_scene::ImageData::new(2, 1, vec![[1.0; 3], [0.9, 0.5, 0.2]]))];
        let map = alhazen_scene::Texture::Image { image: 0, scale: Vec2::ONE, offset: Vec2::ZERO, rotation: 0.0 };
        let glass = |transmittance| BsdfDesc::Dielectric {
            facets: None,
            ior: Ior::Constant(1.5),
            fresnel: alhazen_scene::FresnelMode::Exact,
            transmittance,
            film: None,
        };
        let kernels = |m: &alhazen_scene::Material| -> Vec<Kernel> {
            [0.25, 0.75]
                .map(|u| {
                    let bsdf = crate::bsdf::bsdf_at(m, Vec2::new(u, 0.5), Vec3::ONE, &images, ColorMode::Rgb);
                    kernel_of(&bsdf, m)
                })
                .to_vec()
        };
        let tinted = alhazen_scene::Material::from_bsdf("tinted", glass(map));
        assert_eq!(kernels(&tinted), [Kernel::SmoothDielectric, Kernel::SmoothDielectric]);
        let clear = alhazen_scene::Material::from_bsdf("clear", glass(alhazen_scene::Texture::Solid(Vec3::ONE)));
        assert_eq!(kernels(&clear), [Kernel::SmoothDielectric, Kernel::SmoothDielectric]);
        let painted = alhazen_scene::Material { vertex_colors: true, ..clear };
        assert_eq!(kernels(&painted), [Kernel::SmoothDielectric, Kernel::SmoothDielectric]);
    }

    /// A film whose map gives it no weight anywhere, over a metallic–roughness map whose
    /// metalness runs from 0 to 1: every point takes the general kernel (a filmed surface's
    /// kind of BSDF is the same everywhere), and its BSDF is finite.
    #[test]
    fn a_filmed_surface_takes_the_general_kernel_everywhere() {
        let mut scene = mixed_scene();
        let material = mapped_material(&scene);
        let image = scene.images.len() - 1;
        let map = alhazen_scene::Texture::Image {
            image,
            scale: alhazen_math::Vec2::ONE,
            offset: alhazen_math::Vec2::ZERO,
            rotation: 0.0,
        };
        let bsdf = scene.materials[material].bsdf.as_mut();
        let Some(alhazen_scene::bsdf::BsdfDesc::MetallicRoughness { iridescence, .. }) = bsdf else {
            panic!("{bsdf:?}")
        };
        *iridescence = Some(Box::new(alhazen_scene::bsdf::Iridescence {
            factor: 1.0,
            ior: 1.4,
            thickness: [100.0, 600.0],
            outside: 1.0,
            factor_map: Some(map.clone()),
            thickness_map: Some(map),
        }));
        let m = &scene.materials[material];
        let (v, l) = (Vec3::new(0.3, 0.1, 0.95).normalize(), Vec3::new(-0.2, 0.4, 0.89).normalize());
        for i in 0..64 {
            let uv = Vec2::new((i % 8 + 1) as f64 / 8.0, (i / 8 + 1) as f64 / 8.0);
            let bsdf = crate::bsdf::bsdf_at(m, uv, Vec3::ONE, &scene.images, ColorMode::Rgb);
            assert_eq!(kernel_of(&bsdf, m), Kernel::General, "{uv}: {bsdf:?}");
            let (f, pdf) = bsdf.eval_pdf(v, l);
            assert!(f.is_finite() && f.min_element() >= 0.0 && pdf.is_finite() && pdf > 0.0, "{uv}: {f} {pdf}");
        }
    }

    /// A metallic–roughness map varies the BSDF from point to point — its metal's weight and
    /// both lobes' roughness — and every point, the map's zeros and ones included, takes the
    /// metallic–roughness kernel.
    #[test]
    fn a_metallic_roughness_map_varies_the_bsdf_and_keeps_its_kernel() {
        let scene = mixed_scene();
        let m = &scene.materials[mapped_material(&scene)];
        let (mut weights, mut alphas) = (std::collections::BTreeSet::new(), std::collections::BTreeSet::new());
        // The texels' centres (read exactly), and points between them.
        for i in 0..64 {
            let uv = Vec2::new((i % 8 + 1) as f64 / 8.0, (i / 8 + 1) as f64 / 8.0);
            let bsdf = crate::bsdf::bsdf_at(m, uv, Vec3::ONE, &scene.images, ColorMode::Rgb);
            assert_eq!(kernel_of(&bsdf, m), Kernel::MetallicRoughness, "{uv}");
            let Bsdf::Mix(mix) = &bsdf else { panic!("{bsdf:?}") };
            let Bsdf::Conductor(Conductor { facets: Some(f), .. }) = &mix.a else { panic!("{bsdf:?}") };
            weights.insert(mix.weight.to_bits());
            alphas.insert(f.alpha_u.to_bits());
        }
        // Metalness in blue (0, ½ and 1 times the factor 0.9), not green (thirds).
        let metals = [0.0, 0.45, 0.9].map(|w: f64| weights.contains(&w.to_bits()));
        assert!(metals.iter().all(|&m| m), "{weights:?}");
        assert!(weights.len() >= 4 && alphas.len() >= 6 && alphas.contains(&1e-3f64.to_bits()), "{alphas:?}");
    }

    /// Each material kernel has a slot of its own among the batches' open ones.
    #[test]
    fn material_kernels_have_their_own_slots() {
        for (i, k) in MATERIAL_KERNELS.into_iter().enumerate() {
            assert!(k.is_material());
            assert_eq!(k.shaded(), i, "{k:?}");
        }
    }

    proptest::proptest! {
        /// A bounce's vertices, of kernels in any order, each get a slot of their own in a batch
        /// of their kernel, and the batches are as few as the kernels' counts allow; a cleared
        /// set of batches starts afresh with its storage kept.
        #[test]
        fn batches_hold_each_kernel_and_coat_apart(
            kinds in proptest::collection::vec((0..MATERIAL_KERNELS.len(), 0..2usize), 0..POOL),
        ) {
            // Plastics of two coats; other kernels have none.
            let coats = [Coat::of(1.5, None), Coat::of(1.3, None)];
            let plastic = |k: Kernel| matches!(k, Kernel::RoughPlastic | Kernel::BeckmannPlastic | Kernel::SmoothPlastic);
            let coat_of = |(k, c): (usize, usize)| plastic(MATERIAL_KERNELS[k]).then_some(coats[c]);
            let key = |(k, c): (usize, usize)| (k, if plastic(MATERIAL_KERNELS[k]) { c } else { 0 });
            let mut batches = Batches::reusing(vec![], false);
            for round in 0..2 {
                batches.clear();
                let mut taken = std::collections::HashSet::new();
                for &kind in &kinds {
                    let (b, s) = batches.slot(MATERIAL_KERNELS[kind.0], coat_of(kind));
                    proptest::prop_assert!(b < batches.used && s < batches.all[b].len && s < LANES);
                    proptest::prop_assert_eq!(batches.all[b].kernel, MATERIAL_KERNELS[kind.0]);
                    proptest::prop_assert!(same_coat(batches.all[b].coat, coat_of(kind)));
                    proptest::prop_assert!(taken.insert((b, s)), "slot {:?} given twice", (b, s));
                }
                let mut counts = std::collections::HashMap::new();
                for &kind in &kinds {
                    *counts.entry(key(kind)).or_insert(0usize) += 1;
                }
                let fewest: usize = counts.values().map(|n| n.div_ceil(LANES)).sum();
                proptest::prop_assert_eq!(batches.used, fewest, "round {}", round);
                let filled: usize = batches.all[..batches.used].iter().map(|b| b.len).sum();
                proptest::prop_assert_eq!(filled, kinds.len());
            }
        }
    }

    /// The lanes trace every scene where the processor has a vector unit for their kernels;
    /// the world tests their eight rays at once where it is one leaf (the Cornell boxes; the
    /// prism too, whose floor, an unbounded plane, each ray meets first; not the scene graph's
    /// tree of many objects).
    #[test]
    fn lanes_apply_with_vector_units() {
        for (name, together) in
            [("cornell-box", true), ("cornell-rough", true), ("prism", true), ("scene-graph", false)]
        {
            let scene = small(name, (8, 8, 1));
            for unit in VectorUnit::available() {
                let world = World::build_with(&scene, unit);
                let camera = Camera::new(&scene.camera, 8, 8);
                let tracer = PathTracer::new(&scene, &world, &camera);
                let vectors = unit.is_avx512() || unit.is_avx2();
                assert_eq!(tracer.in_lanes, vectors, "{name}, {}", unit.name());
                assert_eq!(world.traces_rays_together(), together && vectors, "{name}, {}", unit.name());
            }
        }
    }
}
