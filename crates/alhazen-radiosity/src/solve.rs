//! The solution of the discretised energetic balance `(I − DF) L = L_e` (course, §"The
//! energetic balance method") by progressive refinement (Cohen, Chen, Wallace and Greenberg
//! 1988): instead of the Neumann series' sweeps `L_k = L_e + K L_{k−1}` over all elements at
//! once, the patch holding the most *unshot* power shoots it to every element, one patch at a
//! time, until what is left is a small fraction of what was emitted. Each shot is one column of
//! `K`; after all shots the elements hold a partial sum of the same series.
//!
//! A shot reaches an element through `G/π` of the element's centre towards the shooting patch,
//! exact for the unoccluded patch ([`form_factor::point_to_polygon`]), times the fraction of
//! rays from the centre to fixed points of the patch that no surface blocks (the course's `v`).
//! Receivers are visited down their quadtrees: a node takes the shot whole when the radiosity it
//! would receive is below the refinement threshold and its visibility is all-or-nothing, else
//! its children do (made on demand, to the deepest level allowed): the elements are refined
//! near bright shooters and along shadow boundaries, where the light changes.
//!
//! Point, spot and directional lights and the sky (background or environment map) shoot first,
//! once each, by the same descent (the course's `L_b`, "the product of ρ and the irradiance of
//! light coming from point light sources"); what they light is then shot on like the rest.

use crate::form_factor::{self, Polygon};
use crate::mesh::{InputTriangle, NO_PATCH, Node, Side, Tree, patch_level, surfaces};
use alhazen_math::Vec3;
use alhazen_math::color::luminance;
use alhazen_render::World;
use alhazen_scene::{Light, Scene};
use rayon::prelude::*;
use std::f64::consts::PI;
use std::sync::Arc;

/// How the solution is computed.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    /// Longest edge of a shooting patch, in scene units; `None` chooses it so that the scene
    /// has about [`TARGET_PATCHES`] patches.
    pub patch_size: Option<f64>,
    /// Levels of refinement allowed below the patches (each splits an element in four): the
    /// smallest element's edge is the patch size over `2^levels`, for small surface triangles
    /// too.
    pub levels: u8,
    /// Stop when the unshot power is at most this fraction of the power first to be shot.
    pub tolerance: f64,
    /// Refine a node where the radiosity a shot gives it exceeds this fraction of the
    /// brightest radiosity of the scene (a tenth of it along shadow boundaries).
    pub refine: f64,
    /// Visibility rays per node and shot: 1, 4 or 16.
    pub rays: u32,
    /// Most shots; `None` for 50 per patch.
    pub max_shots: Option<u64>,
    /// Shoot through the course's hemicube of this many pixels across instead of Lambert's
    /// closed form: the elements are then the patches split `levels` times, fixed in advance
    /// (the item buffer cannot ask for finer ones).
    pub hemicube: Option<u32>,
}

/// Patches aimed at when no patch size is given.
pub const TARGET_PATCHES: usize = 1024;

/// Most patches a scene may have (a larger count is met by larger patches).
pub const MAX_PATCHES: usize = 1 << 20;

/// About how many nodes the quadtrees may hold in all (each tree its share by area, at least
/// 64 per patch; a node and its display values take about [`NODE_BYTES`]); refinement stops
/// there.
pub const MAX_NODES: usize = 1 << 21;

/// Bytes per node, with its corners' display values.
pub const NODE_BYTES: u64 = 320;

/// An upper bound of the bytes a solve of `scene` may take with `settings`: the quadtrees at
/// their caps (the scene's budget of [`MAX_NODES`] plus 64 elements under every patch, a
/// third more for the nodes above them) and each surface triangle twice (elements and the
/// ray-cast world). Tessellates the scene to count its patches, allocating nothing big.
pub fn memory_estimate(scene: &Scene, settings: &Settings) -> u64 {
    let tris = surfaces(scene).triangles;
    let size = patch_size_for(&tris, settings);
    let patches: u64 = tris.iter().map(|t| 1u64 << (2 * patch_level(t.longest_edge(), size, 10))).sum();
    (MAX_NODES as u64 + patches * 86) * NODE_BYTES + tris.len() as u64 * 1000
}

impl Default for Settings {
    fn default() -> Self {
        Self { patch_size: None, levels: 3, tolerance: 0.002, refine: 0.002, rays: 4, max_shots: None, hemicube: None }
    }
}

/// What was solved.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Stats {
    /// Shooting patches.
    pub patches: usize,
    /// Elements (quadtree leaves) at the end.
    pub elements: usize,
    /// Patch shots (light sources and the sky not counted).
    pub shots: u64,
    /// Unshot power left over the power first to be shot.
    pub unshot: f64,
    /// Power first to be shot (area × luminance of radiosity); zero when nothing lights the
    /// scene.
    pub initial_power: f64,
    /// The patch size used.
    pub patch_size: f64,
    /// Unbounded planes cut to squares, and the squares' side.
    pub planes: (usize, f64),
    /// CSG objects left out.
    pub skipped: usize,
}

/// A solved scene: its surfaces as element trees with what each element received, and the
/// world of those triangles the final image is ray cast in.
pub struct Solution {
    /// The scene the solution is of.
    pub scene: Arc<Scene>,
    /// The surface triangles (roots of the trees).
    pub triangles: Vec<InputTriangle>,
    /// One tree per triangle.
    pub trees: Vec<Tree>,
    /// The triangles as a world: mesh triangle `i` (slot `i`) is `triangles[i]`.
    pub world: World,
    /// The irradiance averaged at the elements' corners ([`crate::display`]).
    pub corners: crate::display::CornerIrradiance,
    /// Statistics.
    pub stats: Stats,
}

/// Why a solve cannot start.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum RadiosityError {
    /// No surface has a triangle form.
    #[error("the scene has no surface for radiosity (CSG objects have no elements)")]
    NoSurfaces,
    /// A setting is out of range.
    #[error("{0}")]
    Setting(String),
}

impl Settings {
    /// Checks the ranges.
    pub fn check(&self) -> Result<(), RadiosityError> {
        let bad = |s: String| Err(RadiosityError::Setting(s));
        if let Some(p) = self.patch_size.filter(|p| !(p.is_finite() && *p > 0.0)) {
            return bad(format!("patch size {p}: expected a positive length"));
        }
        if !(self.tolerance > 0.0 && self.tolerance < 1.0) {
            return bad(format!("tolerance {}: expected a fraction between 0 and 1", self.tolerance));
        }
        if !(self.refine > 0.0 && self.refine.is_finite()) {
            return bad(format!("refinement threshold {}: expected a positive fraction", self.refine));
        }
        if ![1, 4, 16].contains(&self.rays) {
            return bad(format!("{} visibility rays: expected 1, 4 or 16", self.rays));
        }
        if let Some(r) = self.hemicube.filter(|r| !(8..=4096).contains(r)) {
            return bad(format!("a hemicube of {r} pixels across: expected 8 to 4096"));
        }
        if self.levels > 8 {
            return bad(format!("{} refinement levels: at most 8 (each multiplies elements by 4)", self.levels));
        }
        Ok(())
    }
}

/// Solves `scene`'s radiosity; `progress(shots, unshot fraction)` reports each shot.
pub fn solve(
    scene: &Scene,
    settings: &Settings,
    progress: &(dyn Fn(u64, f64) + Sync),
) -> Result<Solution, RadiosityError> {
    settings.check()?;
    let surf = surfaces(scene);
    if surf.triangles.is_empty() {
        return Err(RadiosityError::NoSurfaces);
    }
    let triangles = surf.triangles;
    let scene = Arc::new(scene.clone());
    let world = World::build(&triangle_scene(&scene, &triangles));
    let patch_size = patch_size_for(&triangles, settings);
    let area: f64 = triangles.iter().map(|t| t.area).sum();
    let trees: Vec<Tree> = triangles
        .par_iter()
        .map(|t| {
            let cap = (MAX_NODES as f64 * t.area / area) as usize;
            tree_of(&scene, t, patch_size, settings.levels, cap)
        })
        .collect();
    let mut trees = trees;
    if settings.hemicube.is_some() {
        trees.par_iter_mut().zip(&triangles).for_each(|(t, tri)| split_all(&scene, tri, t));
    }
    let hemicube = settings.hemicube.map(form_factor::Hemicube::new);
    let mut solver =
        Solver { scene: &scene, world: &world, triangles: &triangles, trees, settings, eps: 0.0, hemicube };
    solver.eps = settings.refine * solver.brightest();
    solver.eps = solver.eps.max(f64::MIN_POSITIVE);
    for source in sources(&scene) {
        solver.shoot_all(&source);
    }
    let initial = solver.unshot_power();
    let patches: usize = solver.trees.iter().map(|t| t.patches.len()).sum();
    let max_shots = settings.max_shots.unwrap_or(50 * patches as u64);
    let mut shots = 0u64;
    let mut left = initial;
    while left > settings.tolerance * initial && shots < max_shots {
        let Some((t, p, side)) = solver.brightest_patch() else { break };
        solver.shoot_patch(t, p, side);
        shots += 1;
        left = solver.unshot_power();
        progress(shots, left / initial);
    }
    let mut trees = solver.trees;
    trees.par_iter_mut().for_each(|t| t.push_down(0));
    let elements = trees.iter().map(Tree::elements).sum();
    let unshot = if initial > 0.0 { left / initial } else { 0.0 };
    let stats = Stats {
        patches,
        elements,
        shots,
        unshot,
        initial_power: initial,
        patch_size,
        planes: (surf.planes, surf.plane_side),
        skipped: surf.skipped,
    };
    let corners = crate::display::average_at_vertices(&triangles, &trees);
    Ok(Solution { scene, triangles, trees, world, corners, stats })
}

/// The patch size `settings` ask for (or the automatic one), grown to keep the patch count
/// within [`MAX_PATCHES`].
fn patch_size_for(tris: &[InputTriangle], settings: &Settings) -> f64 {
    fit_patch_size(tris, settings.patch_size.unwrap_or_else(|| auto_patch_size(tris)))
}

/// The patch size giving about [`TARGET_PATCHES`] patches.
fn auto_patch_size(tris: &[InputTriangle]) -> f64 {
    let area: f64 = tris.iter().map(|t| t.area).sum();
    // An equilateral triangle of edge e has area e²√3/4.
    (4.0 * area / (TARGET_PATCHES as f64 * 3f64.sqrt())).sqrt() * 2.0
}

/// `size`, grown until the scene has at most [`MAX_PATCHES`] patches.
fn fit_patch_size(tris: &[InputTriangle], mut size: f64) -> f64 {
    let count =
        |s: f64| -> usize { tris.iter().map(|t| 1usize << (2 * patch_level(t.longest_edge(), s, 10) as usize)).sum() };
    while count(size) > MAX_PATCHES {
        size *= 2.0;
    }
    size
}

/// The reflectance of the part of `tri` with corners `bary`: the material's `k_d · a` at four
/// points (the centre and halfway to each corner).
fn reflectance(scene: &Scene, tri: &InputTriangle, bary: [[f64; 2]; 3]) -> Vec3 {
    let m = &scene.materials[tri.material as usize];
    let c = [0, 1].map(|k| (bary[0][k] + bary[1][k] + bary[2][k]) / 3.0);
    let at = |b: [f64; 2]| {
        alhazen_scene::texture::eval(&m.color, tri.uv_at(b), &scene.images) * m.vertex_tint(tri.color_at(b))
    };
    let halfway = |i: usize| [0, 1].map(|k| 0.5 * (c[k] + bary[i][k]));
    let sum = at(c) + at(halfway(0)) + at(halfway(1)) + at(halfway(2));
    (sum * 0.25 * m.diffuse).clamp(Vec3::ZERO, Vec3::ONE)
}

fn tree_of(scene: &Scene, tri: &InputTriangle, patch_size: f64, levels: u8, cap: usize) -> Tree {
    let m = &scene.materials[tri.material as usize];
    let emission = m.emission * PI;
    let bary = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
    let root = Node {
        bary,
        children: 0,
        level: 0,
        rho: reflectance(scene, tri, bary),
        side: [Side::default(); 2],
        emission_unshot: emission != Vec3::ZERO,
        patch: NO_PATCH,
        pending: [Vec3::ZERO; 2],
        rho_area: Vec3::ZERO,
        parent: 0,
    };
    let level = patch_level(tri.longest_edge(), patch_size, 10);
    let mut root = root;
    root.rho_area = root.rho * tri.area;
    let mut tree = Tree {
        nodes: vec![root],
        patches: vec![],
        power: vec![],
        emission,
        // Elements no smaller than a patch split `levels` times, however small the triangle.
        max_level: patch_level(tri.longest_edge(), patch_size / f64::from(1u32 << levels), 10 + levels).max(level),
        max_nodes: 0,
        area: tri.area,
    };
    let mut frontier = vec![0u32];
    for _ in 0..level {
        let mut next = Vec::with_capacity(frontier.len() * 4);
        for i in frontier {
            tree.subdivide(i, |b| reflectance(scene, tri, b));
            let first = tree.nodes[i as usize].children;
            next.extend(first..first + 4);
        }
        frontier = next;
    }
    tree.max_nodes = cap.max(tree.nodes.len() + 64 * frontier.len());
    for (k, &p) in frontier.iter().enumerate() {
        tree.nodes[p as usize].patch = k as u32;
    }
    tree.power = vec![[0.0; 2]; frontier.len()];
    tree.patches = frontier;
    let area = tri.area / 4f64.powi(level as i32);
    for (k, &p) in tree.patches.iter().enumerate() {
        tree.power[k][0] = area * luminance(tree.nodes[p as usize].unshot(0, emission));
    }
    tree
}

/// Splits every leaf of `tree` down to its deepest level (within its node budget).
fn split_all(scene: &Scene, tri: &InputTriangle, tree: &mut Tree) {
    let mut i = 0;
    while i < tree.nodes.len() {
        let node = tree.nodes[i];
        if node.is_leaf() && node.level < tree.max_level && tree.nodes.len() + 4 <= tree.max_nodes {
            tree.subdivide(i as u32, |b| reflectance(scene, tri, b));
        }
        i += 1;
    }
}

/// The scene of the surface triangles, one mesh whose triangle `i` has slot `i`, for ray casts.
fn triangle_scene(scene: &Scene, tris: &[InputTriangle]) -> Scene {
    let mut mesh = alhazen_geom::TriangleMesh::default();
    for (i, t) in tris.iter().enumerate() {
        let base = mesh.positions.len() as u32;
        mesh.positions.extend(t.p);
        mesh.normals.extend(t.n);
        mesh.uvs.extend(t.uv);
        mesh.triangles.push([base, base + 1, base + 2]);
        mesh.material_slots.push(i as u32);
    }
    let object = alhazen_scene::Object {
        name: Some("radiosity elements".into()),
        shape: alhazen_scene::Shape::Mesh { mesh: 0, smooth: true },
        transform: alhazen_math::Transform::IDENTITY,
        material: 0,
        mesh_materials: tris.iter().map(|t| t.material).collect(),
    };
    Scene {
        render: scene.render.clone(),
        camera: scene.camera.clone(),
        background: scene.background,
        ambient: scene.ambient,
        lights: scene.lights.clone(),
        materials: scene.materials.clone(),
        objects: vec![object],
        meshes: vec![Arc::new(mesh)],
        images: scene.images.clone(),
    }
}

/// What shoots light.
#[allow(clippy::large_enum_variant)] // one per shot, never stored in bulk
enum Source {
    /// A patch: its polygon, centre, the normal of the side it shoots from, its unshot
    /// radiosity and the points visibility rays aim at.
    Patch { poly: Polygon, centre: Vec3, normal: Vec3, radiosity: Vec3, aims: Vec<Vec3>, area: f64 },
    /// A point or spot light: intensity, and a spot's (axis, cosine of the cut-off, exponent,
    /// cosine of its beam).
    Point { position: Vec3, intensity: Vec3, spot: Option<(Vec3, f64, f64, Option<alhazen_scene::SpotBeam>)> },
    /// Parallel light from direction `towards` (unit, towards the light).
    Directional { towards: Vec3, irradiance: Vec3 },
    /// The background or environment map.
    Sky,
}

fn sources(scene: &Scene) -> Vec<Source> {
    let mut out: Vec<Source> = scene
        .lights
        .iter()
        .filter_map(|l| match *l {
            Light::Point { position, intensity, .. } => Some(Source::Point { position, intensity, spot: None }),
            Light::Spot { position, direction, cos_cutoff, falloff, beam, intensity, .. } => {
                Some(Source::Point { position, intensity, spot: Some((direction, cos_cutoff, falloff, beam)) })
            }
            Light::Directional { direction, intensity } => {
                Some(Source::Directional { towards: -direction.normalize(), irradiance: intensity })
            }
            Light::Environment { .. } => None,
        })
        .collect();
    if SKY_DIRECTIONS.iter().any(|d| scene.sky(*d) != Vec3::ZERO || scene.sky(-*d) != Vec3::ZERO) {
        out.push(Source::Sky);
    }
    out
}

/// Directions the sky is probed in to see whether it is black.
const SKY_DIRECTIONS: [Vec3; 7] = [
    Vec3::X,
    Vec3::Y,
    Vec3::Z,
    Vec3::new(0.577, 0.577, 0.577),
    Vec3::new(-0.577, 0.577, 0.577),
    Vec3::new(0.577, 0.577, -0.577),
    Vec3::new(-0.577, 0.577, -0.577),
];

/// The share of a shot above which a node must have an even form factor.
const UNEVEN: f64 = 0.01;

/// The share of a shot a node above the patch level may take whole.
const NEGLIGIBLE: f64 = 1e-4;

/// Directions per node for the sky's irradiance.
const SKY_RAYS: usize = 64;

/// What one node side receives from a source.
#[derive(Clone, Copy, Default)]
struct Transfer {
    /// Irradiance.
    h: Vec3,
    /// Radiosity it would give the node unoccluded (luminance), for refinement.
    potential: f64,
    /// Some visibility rays were blocked and some not.
    partial: bool,
    /// The form factor varies too much across the node for one value.
    uneven: bool,
    /// The factor times visibility (`G/π v`) from a patch, for the energy bound.
    factor: f64,
    /// The fraction of a patch's shot the node takes (unoccluded).
    share: f64,
}

impl Transfer {
    /// What a light or the sky gives: irradiance `h`, the radiosity `potential` it would give
    /// unoccluded, and `seen` of `tried` shadow probes lit.
    fn of_light(h: Vec3, potential: f64, seen: usize, tried: usize) -> Self {
        Self { h, potential, partial: seen > 0 && seen < tried, uneven: false, factor: 0.0, share: 1.0 }
    }
}

struct Solver<'a> {
    scene: &'a Scene,
    world: &'a World,
    triangles: &'a [InputTriangle],
    trees: Vec<Tree>,
    settings: &'a Settings,
    eps: f64,
    /// The hemicube patches shoot through, when asked for.
    hemicube: Option<form_factor::Hemicube>,
}

impl Solver<'_> {
    /// The brightest radiosity any source gives a patch centre unoccluded: the refinement
    /// threshold's unit.
    fn brightest(&self) -> f64 {
        let emitted = self.trees.iter().map(|t| luminance(t.emission)).fold(0.0, f64::max);
        let sources = sources(self.scene);
        let direct = self
            .trees
            .par_iter()
            .zip(self.triangles)
            .map(|(tree, tri)| {
                let mut best = 0.0f64;
                for &p in &tree.patches {
                    let node = &tree.nodes[p as usize];
                    let (x, corners) = centre(tri, node);
                    for s in &sources {
                        for n in [tri.normal, -tri.normal] {
                            let t = self.transfer(s, x, n, corners, node.rho, false);
                            best = best.max(t.potential);
                        }
                    }
                }
                best
            })
            .reduce(|| 0.0, f64::max);
        emitted.max(direct)
    }

    /// The total unshot power.
    fn unshot_power(&self) -> f64 {
        self.trees.iter().flat_map(|t| &t.power).map(|p| p[0] + p[1]).sum()
    }

    /// The patch side with the most unshot power (the first of equals).
    fn brightest_patch(&self) -> Option<(usize, usize, usize)> {
        let mut best: Option<(f64, (usize, usize, usize))> = None;
        for (t, tree) in self.trees.iter().enumerate() {
            for (p, power) in tree.power.iter().enumerate() {
                for (s, &w) in power.iter().enumerate() {
                    if w > 0.0 && best.is_none_or(|b| w > b.0) {
                        best = Some((w, (t, p, s)));
                    }
                }
            }
        }
        best.map(|b| b.1)
    }

    /// Patch `p` of tree `t` shoots its side `side`'s unshot radiosity.
    fn shoot_patch(&mut self, t: usize, p: usize, side: usize) {
        let tri = &self.triangles[t];
        let node_index = self.trees[t].patches[p];
        self.trees[t].push_down(node_index);
        let tree = &self.trees[t];
        let node = tree.nodes[node_index as usize];
        let mut leaves = vec![];
        tree.leaves_below(node_index, &mut leaves);
        let mut flux = Vec3::ZERO;
        for &l in &leaves {
            let leaf = &tree.nodes[l as usize];
            flux += leaf.unshot(side, tree.emission) * leaf_area(tri, leaf);
        }
        let area = leaf_area(tri, &node);
        let corners = node.bary.map(|b| tri.at(b));
        let normal = if side == 0 { tri.normal } else { -tri.normal };
        let source = Source::Patch {
            poly: Polygon::triangle(corners),
            centre: (corners[0] + corners[1] + corners[2]) / 3.0,
            normal,
            radiosity: flux / area,
            aims: aims(corners, self.settings.rays),
            area,
        };
        match self.hemicube.take() {
            Some(cube) => {
                self.shoot_hemicube(&cube, &source);
                self.hemicube = Some(cube);
            }
            None => self.shoot_all(&source),
        }
        // What was shot is no longer unshot.
        let tree = &mut self.trees[t];
        for &l in &leaves {
            let leaf = &mut tree.nodes[l as usize];
            leaf.side[side].unshot = Vec3::ZERO;
            if side == 0 {
                leaf.emission_unshot = false;
            }
        }
        update_power(tri, tree, p);
    }

    /// Cohen's shot through a hemicube at the patch's centre: each pixel's ray finds the element
    /// it sees, which receives `ΔF · A_patch / A_element` of the patch's radiosity as irradiance
    /// (reciprocity). The delta form factors add up to at most 1: no energy is made.
    fn shoot_hemicube(&mut self, cube: &form_factor::Hemicube, source: &Source) {
        let Source::Patch { centre, normal, radiosity, area, .. } = source else { return };
        let eps = alhazen_render::shape::ray_epsilon(*centre);
        let this = &*self;
        let seen = |o: Vec3, d: Vec3| -> Option<Seen> {
            let hit = this.world.intersect(&alhazen_math::Ray::new(o + *normal * eps, d), f64::INFINITY)?;
            let t = hit.hit.slot;
            let tri = &this.triangles[t as usize];
            let side = usize::from(d.dot(tri.normal) > 0.0);
            (side < tri.sides()).then(|| (t, this.trees[t as usize].locate(tri.barycentric(hit.hit.p)).0, side))
        };
        let chunks: Vec<Vec<(Seen, f64)>> = cube
            .pixels
            .par_chunks(1024)
            .map(|pixels| {
                let part = form_factor::Hemicube { pixels: pixels.to_vec() };
                let mut out = vec![];
                part.gather(*centre, *normal, seen, |k, df| out.push((k, df)));
                out
            })
            .collect();
        let mut factors: std::collections::BTreeMap<Seen, f64> = Default::default();
        for (k, df) in chunks.into_iter().flatten() {
            *factors.entry(k).or_default() += df;
        }
        for ((t, leaf, side), f) in factors {
            let tree = &mut self.trees[t as usize];
            let h = *radiosity * (f * *area / tree.node_area(leaf));
            let node = &mut tree.nodes[leaf as usize];
            node.pending[side] += h;
            tree.power[node.patch as usize][side] += luminance(node.rho_area * h);
        }
    }

    /// Every tree receives from `source` (a shooter's own tree too: its other patches lie in the
    /// shooter's plane and receive nothing, which the descent finds at once). A patch never
    /// gives away more than it shoots: where the factors estimated at the receivers' points add
    /// up to more than the patch's whole light (`Σ_j A_j G_ji/π > A_i`, which reciprocity and
    /// Nusselt forbid; it happens between nearby surfaces at the deepest level), they are scaled
    /// down to it, so the iteration cannot gain energy.
    fn shoot_all(&mut self, source: &Source) {
        let trees = std::mem::take(&mut self.trees);
        let this = &*self;
        let received: Vec<(Tree, Vec<Received>, f64)> = trees
            .into_par_iter()
            .zip(this.triangles)
            .map(|(mut tree, tri)| {
                let (mut got, mut share) = (vec![], 0.0);
                if this.reaches(source, tri) {
                    share = this.receive(source, tri, &mut tree, 0, &mut got);
                }
                (tree, got, share)
            })
            .collect();
        let share: f64 = received.iter().map(|r| r.2).sum();
        let scale = match source {
            Source::Patch { area, .. } if share > *area => *area / share,
            _ => 1.0,
        };
        self.trees = received
            .into_par_iter()
            .map(|(mut tree, got, _)| {
                apply(&mut tree, &got, scale);
                tree
            })
            .collect();
    }

    /// False when `source` cannot light any of `tri` (it lies behind a shooting patch).
    fn reaches(&self, source: &Source, tri: &InputTriangle) -> bool {
        match source {
            Source::Patch { centre, normal, .. } => tri.p.iter().any(|&q| (q - *centre).dot(*normal) > 0.0),
            _ => true,
        }
    }

    /// Node `i` of `tree` (over `tri`) receives from `source`, whole or through its children:
    /// what it receives is pushed on `got`. Returns the area-weighted factor received (`Σ A G/π
    /// v`, for [`Self::shoot_all`]'s bound).
    fn receive(&self, source: &Source, tri: &InputTriangle, tree: &mut Tree, i: u32, got: &mut Vec<Received>) -> f64 {
        let node = tree.nodes[i as usize];
        let (x, corners) = centre(tri, &node);
        let sides = tri.sides();
        let t = [0, 1].map(|s| {
            let n = if s == 0 { tri.normal } else { -tri.normal };
            if s < sides { self.transfer(source, x, n, corners, node.rho, true) } else { Transfer::default() }
        });
        if t.iter().all(|t| t.h == Vec3::ZERO && t.potential == 0.0 && !t.uneven) {
            return 0.0;
        }
        // Above the patch level a node takes a shot whole only where its share is negligible
        // and nothing stands between part of it and the patch.
        let coarse = node.patch == NO_PATCH;
        let wants = |t: &Transfer| {
            t.uneven
                || t.potential > self.eps
                || (t.partial && t.potential > 0.1 * self.eps)
                || (coarse && (t.share > NEGLIGIBLE || t.partial))
        };
        let room = !node.is_leaf() || tree.nodes.len() + 4 <= tree.max_nodes;
        // With a hemicube the elements are fixed: go down to them, split nothing.
        let split = match self.hemicube {
            Some(_) => !node.is_leaf(),
            None => node.level < tree.max_level && room && t.iter().any(wants),
        };
        if split {
            if node.is_leaf() {
                tree.subdivide(i, |b| reflectance(self.scene, tri, b));
            }
            let first = tree.nodes[i as usize].children;
            return (first..first + 4).map(|k| self.receive(source, tri, tree, k, got)).sum();
        }
        got.push((i, [t[0].h, t[1].h]));
        leaf_area(tri, &node) * (t[0].factor + t[1].factor)
    }

    /// What the side with normal `n` of a node centred at `x` (corners `corners`, reflectance
    /// `rho`) receives from `source`; without visibility rays when `occlusion` is false.
    fn transfer(&self, source: &Source, x: Vec3, n: Vec3, corners: [Vec3; 3], rho: Vec3, occlusion: bool) -> Transfer {
        let eps = alhazen_render::shape::ray_epsilon(x);
        let from = x + n * eps;
        let sees = |to: Vec3, dist: f64| !occlusion || self.world.unoccluded(from, to, dist);
        match source {
            Source::Patch { poly, centre, normal, radiosity, aims, area } => {
                // A node across the patch's plane is refined (only its children can tell); one
                // that touches it counts as in front.
                let height = corners.map(|c| (c - *centre).dot(*normal));
                let across = height.iter().any(|&h| h < -eps);
                if height.iter().all(|&h| h <= eps) {
                    return Transfer::default();
                }
                if (x - *centre).dot(*normal) <= 0.0 {
                    return Transfer { uneven: true, share: 1.0, ..Transfer::default() };
                }
                let node_area = 0.5 * (corners[1] - corners[0]).cross(corners[2] - corners[0]).length();
                // Near the patch: the factor at the centres of the node's four children, whose
                // mean is the node's and whose spread says whether one value will do. Far from
                // it (both sizes under a quarter of the distance), the centre's.
                let near = (node_area.sqrt() + area.sqrt()) > 0.25 * (x - *centre).length();
                let (ff, spread) = if near {
                    let quarters = crate::mesh::split([[1.0, 0.0], [0.0, 1.0], [0.0, 0.0]]).map(|q| {
                        let w = [0, 1].map(|k| (q[0][k] + q[1][k] + q[2][k]) / 3.0);
                        let p = corners[0] * w[0] + corners[1] * w[1] + corners[2] * (1.0 - w[0] - w[1]);
                        form_factor::point_to_polygon(p, n, poly)
                    });
                    let ff = quarters.iter().sum::<f64>() / 4.0;
                    (ff, quarters.iter().fold(0.0f64, |m, q| m.max((q - ff).abs())))
                } else {
                    (form_factor::point_to_polygon(x, n, poly), 0.0)
                };
                if ff <= 0.0 {
                    return Transfer::default();
                }
                // Rays from points spread over the node (its centre and corners drawn in) to
                // points spread over the patch, in pairs: a shadow edge across either shows.
                let probes = probes(x, corners);
                let (mut seen, mut tried) = (0, 0);
                for (k, &q) in aims.iter().enumerate() {
                    let o = probes[k % 4] + n * eps;
                    let d = q - o;
                    if d.dot(n) <= 0.0 || d.dot(*normal) >= 0.0 {
                        continue;
                    }
                    tried += 1;
                    let dist = d.length();
                    seen += (!occlusion || self.world.unoccluded(o, d / dist, dist * (1.0 - 1e-9) - eps)) as usize;
                }
                let v = if tried == 0 { 0.0 } else { seen as f64 / tried as f64 };
                Transfer {
                    h: *radiosity * (ff * v),
                    potential: luminance(rho * *radiosity) * ff,
                    partial: seen > 0 && seen < tried,
                    // More than 1 % of the shot lands on a node whose factor varies by more
                    // than a quarter across it.
                    uneven: across || (spread > 0.25 * ff && ff * node_area > UNEVEN * *area),
                    factor: ff * v,
                    share: ff * node_area / *area,
                }
            }
            Source::Point { position, intensity, spot } => {
                let cone = |p: Vec3| match spot {
                    None => 1.0,
                    Some((axis, cutoff, falloff, beam)) => {
                        let c = -(p - *position).normalize_or_zero().dot(*axis);
                        alhazen_scene::spot_profile(c, *cutoff, *falloff, *beam)
                    }
                };
                let g = form_factor::point_to_point(x, n, *position) * cone(x);
                let probes = probes(x, corners);
                let mut seen = 0;
                for p in probes {
                    let d = *position - (p + n * eps);
                    let dist = d.length();
                    let lit = d.dot(n) > 0.0 && cone(p) > 0.0;
                    seen += (lit && (!occlusion || self.world.unoccluded(p + n * eps, d / dist, dist))) as usize;
                }
                let v = seen as f64 / probes.len() as f64;
                Transfer::of_light(*intensity * (g * v), luminance(rho * *intensity) * g, seen, probes.len())
            }
            Source::Directional { towards, irradiance } => {
                let cos = n.dot(*towards);
                if cos <= 0.0 {
                    return Transfer::default();
                }
                let probes = probes(x, corners);
                let seen = probes
                    .iter()
                    .filter(|p| !occlusion || self.world.unoccluded(**p + n * eps, *towards, f64::INFINITY))
                    .count();
                let v = seen as f64 / probes.len() as f64;
                Transfer::of_light(*irradiance * (cos * v), luminance(rho * *irradiance) * cos, seen, probes.len())
            }
            Source::Sky => {
                let (s, t) = alhazen_math::orthonormal_basis(n);
                let (mut sum, mut open) = (Vec3::ZERO, Vec3::ZERO);
                let mut seen = 0;
                for k in 0..SKY_RAYS {
                    let d = cosine_direction(k, SKY_RAYS, s, t, n);
                    let l = self.scene.sky(d);
                    open += l;
                    if sees(d, f64::INFINITY) {
                        sum += l;
                        seen += 1;
                    }
                }
                let w = PI / SKY_RAYS as f64;
                Transfer::of_light(sum * w, luminance(rho * open) * w, seen, SKY_RAYS)
            }
        }
    }
}

/// A node's centre and corners in the scene.
fn centre(tri: &InputTriangle, node: &Node) -> (Vec3, [Vec3; 3]) {
    let corners = node.bary.map(|b| tri.at(b));
    ((corners[0] + corners[1] + corners[2]) / 3.0, corners)
}

fn leaf_area(tri: &InputTriangle, node: &Node) -> f64 {
    tri.area / 4f64.powi(node.level as i32)
}

/// What a hemicube pixel sees: surface triangle, element, side.
type Seen = (u32, u32, usize);

/// What a node received from a shot, front and back.
type Received = (u32, [Vec3; 2]);

/// Adds what nodes received (times `scale`) to them, pending for their leaves, and the power
/// it gives to their patches'. A node above the patch level hands it to its patches.
fn apply(tree: &mut Tree, got: &[Received], scale: f64) {
    let mut stack = vec![];
    for &(i, h) in got {
        let h = h.map(|h| h * scale);
        stack.push(i);
        while let Some(n) = stack.pop() {
            let node = &mut tree.nodes[n as usize];
            if node.patch == NO_PATCH {
                stack.extend(node.children..node.children + 4);
                continue;
            }
            for s in 0..2 {
                node.pending[s] += h[s];
                tree.power[node.patch as usize][s] += luminance(node.rho_area * h[s]);
            }
        }
    }
}

/// Recomputes patch `p`'s unshot power from its elements.
fn update_power(tri: &InputTriangle, tree: &mut Tree, p: usize) {
    let mut power = [0.0; 2];
    let mut stack = vec![tree.patches[p]];
    while let Some(i) = stack.pop() {
        let node = &tree.nodes[i as usize];
        if node.is_leaf() {
            for (s, w) in power.iter_mut().enumerate() {
                *w += leaf_area(tri, node) * luminance(node.unshot(s, tree.emission));
            }
        } else {
            stack.extend(node.children..node.children + 4);
        }
    }
    tree.power[p] = power;
}

/// Where point and directional lights are tested for shadow: the centre and the corners drawn
/// 5 % towards it.
fn probes(x: Vec3, corners: [Vec3; 3]) -> [Vec3; 4] {
    let pull = |c: Vec3| c + (x - c) * 0.05;
    [x, pull(corners[0]), pull(corners[1]), pull(corners[2])]
}

/// The points of a shooting triangle that visibility rays aim at: its centre (1), the centres
/// of its four children (4) or of its sixteen grandchildren (16).
fn aims(corners: [Vec3; 3], rays: u32) -> Vec<Vec3> {
    let mut tris = vec![[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]];
    let mut n = 1;
    while n < rays {
        tris = tris.iter().flat_map(|t| crate::mesh::split(*t)).collect();
        n *= 4;
    }
    let at = |b: [f64; 2]| corners[0] + (corners[1] - corners[0]) * b[0] + (corners[2] - corners[0]) * b[1];
    tris.iter().map(|t| at([0, 1].map(|k| (t[0][k] + t[1][k] + t[2][k]) / 3.0))).collect()
}

/// Direction `k` of `n` cosine-distributed about `z`: Fibonacci points on the unit disk lifted
/// to the hemisphere (Malley's method), deterministic and evenly spread.
fn cosine_direction(k: usize, n: usize, s: Vec3, t: Vec3, z: Vec3) -> Vec3 {
    let golden = PI * (3.0 - 5f64.sqrt());
    let r = ((k as f64 + 0.5) / n as f64).sqrt();
    let phi = golden * k as f64;
    let (x, y) = (r * phi.cos(), r * phi.sin());
    s * x + t * y + z * (1.0 - r * r).max(0.0).sqrt()
}
