//! The raster pipeline of `alhazen raster` (course, §"Projections", §"Rasterisation",
//! §"Clipping", §"Visibility", §"Shading methods"): scene objects become world-space triangles;
//! vertices go model → world → view → clip by the course's matrices (`ViewFrame`, the
//! perspective `P` or orthographic projection); triangles facing away are culled (closed surfaces
//! only); polygons are clipped in homogeneous coordinates; the perspective division and the
//! viewport transform give screen triangles, which are rasterised with a z-buffer (or painted
//! back to front over a BSP tree), in parallel horizontal bands. Visibility fills a G-buffer —
//! per pixel the winning triangle and the weights of its corners there — and a deferred pass
//! interpolates the triangle's position, normal, texture coordinates (and Gouraud's corner
//! light) for each visible pixel and shades it once. Shading is
//! flat (one colour per triangle), Gouraud (light at the vertices, interpolated) or Phong
//! (normals interpolated, lighting per pixel) with the course's local models, shadows (maps or
//! stencil volumes), image-based and hemispherical light. The camera and the sample position (pixel centres) match `alhazen render`'s.

pub mod bsp;
pub mod cameras;
pub mod clip;
pub mod csg;
pub mod depth_sort;
pub mod emitters;
pub mod geometry;
pub mod ibl;
pub mod mirrors;
pub mod octree;
pub mod raster;
pub mod scanline;
pub mod shade;
pub mod shadow;
pub mod stencil;
pub mod warnock;

use alhazen_math::viewing::{Frustum, ViewFrame};
use alhazen_math::{Mat4, Vec2, Vec3, Vec4};
use alhazen_scene::{CameraDesc, Scene};
use clip::{ClipVertex, clip_polygon};
use geometry::{Triangle, scene_triangles};
use raster::{Bary, ScreenTriangle, interpolate, rasterize};
use rayon::prelude::*;

/// How colours are computed over a triangle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shading {
    /// One colour per triangle, from its face normal at its centroid.
    Flat,
    /// Lighting at the vertices, colours interpolated.
    Gouraud,
    /// Normals interpolated, lighting at every pixel.
    Phong,
}

/// How hidden surfaces are removed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Visibility {
    /// A depth buffer.
    ZBuffer,
    /// The painter's algorithm over a BSP tree (built once by [`prepare`]).
    Bsp,
    /// The scan-line algorithm: one row at a time, a depth buffer of one row and the triangles
    /// crossing it ([`scanline`]).
    Scanline,
    /// The depth-sort painter's algorithm with Newell's overlap tests, splitting where no order
    /// exists ([`depth_sort`]).
    DepthSort,
    /// Warnock's area subdivision ([`warnock`]).
    Warnock,
}

/// Options of a raster render.
#[derive(Clone, Debug)]
pub struct RasterOptions {
    /// Shading method.
    pub shading: Shading,
    /// Cull triangles of closed surfaces that face away.
    pub cull: bool,
    /// Draw triangle edges on top (Bresenham).
    pub wireframe: bool,
    /// Shadows from shadow maps (built once by [`prepare`]).
    pub shadows: bool,
    /// Light from the environment (map or background): diffuse by its nine-coefficient
    /// irradiance, glossy by the prefiltered environment and the split sum ([`ibl`]).
    pub ibl: bool,
    /// User clip planes `(n, d)` in world space: only `n·p + d ≥ 0` is drawn (the course's
    /// clip distances).
    pub clip_planes: Vec<Vec4>,
    /// User culling planes: a triangle entirely on the negative side of one is dropped whole
    /// (the course's culling distances).
    pub cull_planes: Vec<Vec4>,
    /// Hidden-surface removal.
    pub visibility: Visibility,
    /// How shadows are found when `shadows` is on: shadow maps, or stencil shadow volumes
    /// (perspective cameras; Flat and Phong shading).
    pub shadow_method: ShadowMethod,
    /// Replace the ambient constant by the course's hemispherical lighting (sky and ground
    /// colours from the background).
    pub hemispherical: bool,
    /// A stereo camera's eyes as one red–cyan anaglyph instead of side by side.
    pub anaglyph: bool,
    /// Skip the triangles of octree nodes outside the view volume ([`octree`]) before they are
    /// transformed; the image is the same either way (off only to measure it).
    pub frustum_culling: bool,
}

/// Shadow algorithm.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShadowMethod {
    /// Depth images from the lights ([`shadow`]).
    Maps,
    /// Stencil shadow volumes ([`stencil`]) with the given counting rule.
    Volumes(stencil::StencilMode),
}

impl Default for RasterOptions {
    fn default() -> Self {
        Self {
            shading: Shading::Phong,
            cull: true,
            wireframe: false,
            shadows: true,
            ibl: false,
            clip_planes: vec![],
            cull_planes: vec![],
            visibility: Visibility::ZBuffer,
            shadow_method: ShadowMethod::Maps,
            hemispherical: false,
            anaglyph: false,
            frustum_culling: true,
        }
    }
}

/// Texels a side of each shadow map.
pub const SHADOW_MAP_SIZE: u32 = 1024;

/// What does not change when the camera moves: the triangles, the lights' shadow maps, the
/// environment's lighting and the BSP tree — each, but the triangles, only when asked for.
pub struct Prepared {
    /// World-space triangles.
    pub geometry: geometry::SceneTriangles,
    /// Shadow maps, when asked for.
    pub shadows: Option<shadow::Shadows>,
    /// The environment's irradiance and its prefiltered radiance, when image-based light is
    /// asked for.
    pub ibl: Option<Ibl>,
    /// The BSP tree, when the painter's algorithm is asked for.
    pub bsp: Option<bsp::BspTree>,
    /// The lights standing for emitting objects ([`emitters`]).
    pub emitters: Vec<emitters::EmitterLight>,
    /// The CSG bodies, ray cast per pixel ([`csg`]).
    pub csg: Option<csg::CsgBodies>,
    /// Light computed elsewhere (a radiosity solution), one per triangle: the triangles are
    /// drawn with it alone ([`prepare_lit`]).
    pub prelit: Option<Vec<Prelit>>,
    /// The triangles' octree, for frustum culling and the drawing order.
    pub octree: octree::Octree,
    /// The flat mirrors among the triangles.
    pub plane_mirrors: Vec<mirrors::PlaneMirror>,
    /// Some triangle is transparent (glass needs a second pass).
    pub transparent: bool,
    /// What vertex processing reads of each triangle.
    pub corners: Vec<Corners>,
    /// The same of the BSP tree's triangles (empty without the tree).
    pub bsp_corners: Vec<Corners>,
}

/// What vertex processing reads of a triangle: its corners and whether its surface is closed
/// (80 bytes of the triangle's 208 — a frame of a big mesh is bound by memory traffic).
#[derive(Clone, Copy, Debug)]
pub struct Corners {
    /// Corner positions.
    pub p: [Vec3; 3],
    /// Part of a closed surface.
    pub closed: bool,
}

impl Corners {
    /// The corners of each triangle.
    pub fn of(triangles: &[Triangle]) -> Vec<Corners> {
        triangles.iter().map(|t| Corners { p: t.v.map(|v| v.p), closed: t.closed }).collect()
    }
}

/// The light of one triangle of a solved scene: the irradiance over π at its corners, which
/// the material's `ρ(uv)` multiplies per pixel, and whether the triangle is its surface's front
/// (where emission shows).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Prelit {
    /// Irradiance over π at the corners.
    pub irradiance: [Vec3; 3],
    /// The surface's front side.
    pub front: bool,
}

/// Image-based light: the environment's irradiance, and the environment prefiltered for glossy
/// reflection with the split-sum table.
pub struct Ibl {
    /// Nine spherical-harmonic coefficients of the irradiance.
    pub irradiance: ibl::Sh9,
    /// The prefiltered environment.
    pub specular: ibl::SpecularIbl,
}

impl RasterOptions {
    /// Widens these options (as given to [`prepare`]) so that what `also` needs is prepared
    /// too: shadow maps, image-based light, the BSP tree.
    pub fn prepare_also(&mut self, also: &RasterOptions) {
        if also.shadows && also.shadow_method == ShadowMethod::Maps {
            (self.shadows, self.shadow_method) = (true, ShadowMethod::Maps);
        }
        self.ibl |= also.ibl;
        if also.visibility == Visibility::Bsp {
            self.visibility = Visibility::Bsp;
        }
    }
}

impl Prepared {
    /// True when everything `opts` asks for was prepared (a lit scene needs nothing more).
    pub fn serves(&self, opts: &RasterOptions) -> bool {
        if self.prelit.is_some() {
            return true;
        }
        let maps = opts.shadows && opts.shadow_method == ShadowMethod::Maps;
        (!maps || self.shadows.is_some())
            && (!opts.ibl || self.ibl.is_some())
            && (opts.visibility != Visibility::Bsp || self.bsp.is_some())
    }
}

/// Tessellates `scene` and, as `opts` ask, renders its shadow maps, computes its environment's
/// lighting and builds its BSP tree.
pub fn prepare(scene: &Scene, opts: &RasterOptions) -> Prepared {
    let mut geometry = scene_triangles(scene);
    let (octree, _) = in_tree_order(&mut geometry.triangles);
    let emitters = emitters::emitter_lights(scene, &geometry.triangles);
    let maps = opts.shadows && opts.shadow_method == ShadowMethod::Maps;
    let shadows = maps.then(|| shadow::Shadows::build(scene, &geometry.triangles, &emitters, SHADOW_MAP_SIZE));
    let ibl = opts.ibl.then(|| Ibl {
        irradiance: ibl::Sh9::irradiance_of(&|d| scene.sky(d), 8, 400),
        specular: ibl::SpecularIbl::build(&|d| scene.sky(d), 32),
    });
    let bsp = (opts.visibility == Visibility::Bsp).then(|| {
        let b =
            geometry.triangles.iter().fold(alhazen_math::Bounds3::EMPTY, |b, t| t.v.iter().fold(b, |b, v| b.grow(v.p)));
        bsp::BspTree::build(&geometry.triangles, 1e-9 * (1.0 + b.extent().length()))
    });
    let csg = csg::CsgBodies::of(scene);
    let plane_mirrors = mirrors::plane_mirrors(scene, &geometry.triangles);
    let transparent =
        geometry.triangles.iter().any(|t| scene.materials[t.material as usize].transparency != Vec3::ZERO);
    let corners = Corners::of(&geometry.triangles);
    let bsp_corners = bsp.as_ref().map_or(vec![], |tree| Corners::of(&tree.triangles));
    Prepared {
        geometry,
        shadows,
        ibl,
        bsp,
        emitters,
        csg,
        prelit: None,
        octree,
        plane_mirrors,
        transparent,
        corners,
        bsp_corners,
    }
}

/// The octree of `triangles`, which are put in its order (see [`octree::Octree::renumber`]),
/// and the permutation: new triangle `k` was `order[k]`.
fn in_tree_order(triangles: &mut Vec<Triangle>) -> (octree::Octree, Vec<u32>) {
    let mut octree = octree::Octree::build(triangles);
    let order = octree.renumber();
    *triangles = order.iter().map(|&i| triangles[i as usize]).collect();
    (octree, order)
}

/// Triangles whose light is already known (a radiosity solution: `lit[i]` for
/// `triangles[i]`), drawn with it alone: no lights, shadows, mirrors, glass or CSG passes, and
/// always by the depth buffer.
pub fn prepare_lit(mut triangles: Vec<Triangle>, lit: Vec<Prelit>) -> Prepared {
    let (octree, order) = in_tree_order(&mut triangles);
    let lit = order.iter().map(|&i| lit[i as usize]).collect();
    Prepared {
        corners: Corners::of(&triangles),
        bsp_corners: vec![],
        octree,
        geometry: geometry::SceneTriangles { triangles, skipped: 0 },
        shadows: None,
        ibl: None,
        bsp: None,
        emitters: vec![],
        csg: None,
        prelit: Some(lit),
        plane_mirrors: vec![],
        transparent: false,
    }
}

/// What the pipeline did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RasterStats {
    /// Triangles in the scene.
    pub triangles: usize,
    /// Triangles culled as back faces.
    pub culled: usize,
    /// Triangles left out whole by the octree's frustum test.
    pub outside: usize,
    /// Triangles (after clipping and fan triangulation) rasterised.
    pub drawn: usize,
    /// Triangles not rasterised because they were clipped away or cover no pixel centre
    /// (most of a mesh finer than the pixels).
    pub missed: usize,
    /// Objects without a triangle form (CSG).
    pub skipped_objects: usize,
    /// Triangles (pieces of them in spherical mirrors) drawn as mirrors show them.
    pub reflexes: usize,
}

/// A rendered frame: linear RGB and depth (`z/w`), rows top to bottom.
#[derive(Clone, Debug)]
pub struct Framebuffer {
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
    /// Colours.
    pub color: Vec<[f32; 3]>,
    /// Depth per pixel (`+∞` where nothing was drawn).
    pub depth: Vec<f64>,
}

/// Why a scene cannot be rasterised.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum RasterError {
    /// The camera type has no projection matrix here.
    UnsupportedCamera(&'static str),
}

impl std::fmt::Display for RasterError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::UnsupportedCamera(k) => {
                write!(f, "this view supports perspective, orthographic and axonometric cameras, not {k}")
            }
        }
    }
}

impl std::error::Error for RasterError {}

/// The camera as matrices: world → clip, and what is needed to find the viewer direction.
#[derive(Clone, Copy, Debug)]
pub struct Projection {
    /// The course's viewing transformation followed by its projection matrix.
    pub world_to_clip: Mat4,
    /// Its inverse.
    pub clip_to_world: Mat4,
    /// The view frame (for parallel views: an eye 10⁴ units before the target).
    pub frame: ViewFrame,
    /// Central (true) or parallel projection.
    pub perspective: bool,
}

/// The camera of a scene as a [`Projection`] for a film of `width × height` pixels; stereo and
/// panorama cameras have none.
pub fn projection(desc: &CameraDesc, width: u32, height: u32) -> Result<Projection, RasterError> {
    let aspect = width as f64 / height as f64;
    let frame_of = |l: &alhazen_scene::LookAt| {
        ViewFrame::look_at(l.eye, l.target, l.up).unwrap_or(ViewFrame {
            eye: l.eye,
            u: Vec3::X,
            v: Vec3::Y,
            w: Vec3::Z,
        })
    };
    let (frame, p, perspective) = match desc {
        CameraDesc::Perspective { look, opening, .. } => {
            // A near plane close enough that nothing near the eye is clipped away.
            let frustum = opening.frustum(aspect, Some(1e-3));
            // The limit f → ∞ of the course's P: points at infinity (shadow volumes' far ends)
            // land on the far plane instead of beyond it.
            let mut p = frustum.perspective();
            p.z_axis.z = -1.0;
            p.w_axis.z = -2.0 * frustum.n;
            (frame_of(look), p, true)
        }
        CameraDesc::Orthographic { look, width: w } => {
            let (hw, hh) = (w / 2.0, w / aspect / 2.0);
            let frustum = Frustum { l: -hw, r: hw, b: -hh, t: hh, n: 0.0, f: 1e6 };
            (frame_of(look), frustum.orthographic(), false)
        }
        CameraDesc::Axonometric { style, target, width, azimuth } => {
            // The course's parallel projection p ↦ (a·p, b·p), depth along the kernel direction,
            // scaled to the standard cube; the view starts 10⁴ units before the target, as the
            // ray tracer's rays do.
            let (a, b) = style.axes(*azimuth);
            let dir = alhazen_scene::Axonometry::direction(a, b);
            let (hw, hh) = (width / 2.0, width / aspect / 2.0);
            let (near, far) = (-1e4, 1e6);
            let row = |v: Vec3, scale: f64, shift: f64| (v * scale).extend(-v.dot(*target) * scale + shift);
            let depth = 2.0 / (far - near);
            let m = Mat4::from_cols_array_2d(&[
                row(a, 1.0 / hw, 0.0).to_array(),
                row(b, 1.0 / hh, 0.0).to_array(),
                row(dir, depth, -near * depth - 1.0).to_array(),
                [0.0, 0.0, 0.0, 1.0],
            ])
            .transpose();
            let w = -dir;
            let u = b.cross(w).normalize_or_zero();
            let frame = ViewFrame { eye: *target - dir * 1e4, u, v: w.cross(u), w };
            return Ok(Projection { world_to_clip: m, clip_to_world: m.inverse(), frame, perspective: false });
        }
        // Drawn by `render_prepared` as two perspective views and as a cube map.
        CameraDesc::Stereo { .. } => return Err(RasterError::UnsupportedCamera("stereo")),
        CameraDesc::Panorama { .. } => return Err(RasterError::UnsupportedCamera("panorama")),
    };
    let world_to_clip = p * frame.world_to_view();
    Ok(Projection { world_to_clip, clip_to_world: world_to_clip.inverse(), frame, perspective })
}

impl Projection {
    /// Unit direction from `p` towards the viewer.
    pub fn to_viewer(&self, p: Vec3) -> Vec3 {
        if self.perspective { (self.frame.eye - p).normalize_or_zero() } else { self.frame.w }
    }

    /// The eye ray through NDC `(x, y)`: from the near plane, along the line through the
    /// depth-0 point (both stay finite under the infinite far plane, unlike `Self::ray_dir`'s).
    pub fn near_ray(&self, x: f64, y: f64) -> alhazen_math::Ray {
        let at = |z: f64| {
            let q = self.clip_to_world * Vec4::new(x, y, z, 1.0);
            q.truncate() / q.w
        };
        let origin = at(-1.0);
        alhazen_math::Ray::new(origin, (at(0.0) - origin).normalize_or_zero())
    }

    /// The world direction of the ray through NDC `(x, y)` ([`Self::near_ray`]'s: from the
    /// near plane to the depth halfway in NDC, which a projection without a far plane — a
    /// glTF camera's without `zfar` — maps to a finite point where the far plane's is at
    /// infinity).
    fn ray_dir(&self, x: f64, y: f64) -> Vec3 {
        self.near_ray(x, y).dir
    }
}

/// What a triangle looks like at corner weights `b`: position, unit normal (interpolated) and
/// texture coordinates.
pub(crate) fn surface_at(t: &Triangle, b: Bary) -> (Vec3, Vec3, Vec2) {
    let p = interpolate(t.v.map(|v| v.p), b);
    let n = interpolate(t.v.map(|v| v.n), b).normalize_or_zero();
    (p, n, interpolate(t.v.map(|v| v.uv), b))
}

/// A triangle's vertex colour at corner weights `b`.
pub(crate) fn color_at(t: &Triangle, b: Bary) -> Vec3 {
    interpolate(t.v.map(|v| v.color), b)
}

/// False where a cut-out ([`alhazen_scene::Alpha`]) leaves mesh triangle `t` out at corner
/// weights `b`: below its cutoff, or, for a coverage without one, below the threshold of a 4×4
/// ordered dither at `pixel` (the preview's screen door for the tracers' per-ray passage).
/// Other shapes are opaque, as in the tracers.
pub(crate) fn present(scene: &alhazen_scene::Scene, t: &Triangle, b: Bary, (x, y): (u32, u32)) -> bool {
    const BAYER: [[u8; 4]; 4] = [[0, 8, 2, 10], [12, 4, 14, 6], [3, 11, 1, 9], [15, 7, 13, 5]];
    let Some(alpha) = &scene.materials[t.material as usize].alpha else { return true };
    let on_mesh =
        scene.objects.get(t.object as usize).is_some_and(|o| matches!(o.shape, alhazen_scene::Shape::Mesh { .. }));
    if !on_mesh {
        return true;
    }
    let coverage = alhazen_scene::texture::coverage(alpha, interpolate(t.v.map(|v| v.uv), b), &scene.images);
    match alpha.cutoff {
        Some(cutoff) => coverage >= cutoff,
        None => coverage >= 1.0 || coverage > (BAYER[(y % 4) as usize][(x % 4) as usize] as f64 + 0.5) / 16.0,
    }
}

/// What became of a triangle in vertex processing.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Fate {
    /// Culled (back face or user culling plane).
    Culled,
    /// On screen as one or more screen triangles.
    Kept,
    /// Clipped away, or on screen without covering a pixel centre.
    Missed,
}

/// Vertex processing of one triangle: culling, clipping, division, viewport. Screen
/// triangles that cannot cover a pixel centre are not kept (but for wireframes).
fn process(
    proj: &Projection,
    t: &Corners,
    index: u32,
    opts: &RasterOptions,
    (w, h): (u32, u32),
    out: &mut Vec<ScreenTriangle>,
) -> Fate {
    let [a, b, c] = t.p;
    let face = (b - a).cross(c - a);
    let centroid = (a + b + c) / 3.0;
    if opts.cull && t.closed && face.dot(proj.to_viewer(centroid)) < 0.0 {
        return Fate::Culled;
    }
    let below = |pl: &Vec4, p: Vec3| pl.truncate().dot(p) + pl.w < 0.0;
    if opts.cull_planes.iter().any(|pl| t.p.iter().all(|&p| below(pl, p))) {
        return Fate::Culled;
    }
    let corners: [ClipVertex; 3] = std::array::from_fn(|k| {
        let p = t.p[k];
        ClipVertex::corner(proj.world_to_clip * p.extend(1.0), p, k)
    });
    let keep = |s: &ScreenTriangle| opts.wireframe || raster::may_cover_a_pixel(s, (w, h));
    // Inside the view volume and no user planes: clipping would return the corners as they are.
    let inside = |c: &ClipVertex| {
        let q = c.pos;
        q.w > 0.0 && q.x.abs() <= q.w && q.y.abs() <= q.w && q.z.abs() <= q.w
    };
    if opts.clip_planes.is_empty() && corners.iter().all(inside) {
        let s = raster::triangle_to_screen(&corners, (w, h), index);
        if !keep(&s) {
            return Fate::Missed;
        }
        out.push(s);
        return Fate::Kept;
    }
    let clipped = clip::clip_user_planes(clip_polygon(&corners), &opts.clip_planes);
    let before = out.len();
    out.extend(raster::to_screen(&clipped, (w, h), index).into_iter().filter(keep));
    if out.len() > before { Fate::Kept } else { Fate::Missed }
}

/// The normal bent by the material's bump map, with the triangle's `∂p/∂u`, `∂p/∂v` from its
/// texture coordinates (Flat and Phong shading; Gouraud lights the vertices only).
fn bumped(scene: &Scene, m: &alhazen_scene::Material, t: &Triangle, uv: Vec2, n: Vec3) -> Vec3 {
    let Some(b) = &m.bump else { return n };
    let [pu, pv] = alhazen_scene::texture::uv_tangents(t.v.map(|v| v.p), t.v.map(|v| v.uv));
    alhazen_scene::texture::bumped_normal(b, uv, n, pu, pv, &scene.images)
}

/// The colour of a fragment of a lit triangle: its emission on the front, and the material's
/// `ρ(uv)` times the irradiance over π interpolated from the corners (the course's display of a
/// radiosity solution, with the texture per pixel).
fn lit_color(scene: &Scene, t: &Triangle, lit: &Prelit, b: Bary) -> Vec3 {
    let m = &scene.materials[t.material as usize];
    let rho = shade::base_color(scene, m, interpolate(t.v.map(|v| v.uv), b), color_at(t, b)) * m.diffuse;
    let e = interpolate(lit.irradiance, b).max(Vec3::ZERO);
    let emitted = if lit.front { m.emission } else { Vec3::ZERO };
    emitted + rho.clamp(Vec3::ZERO, Vec3::ONE) * e
}

/// Gouraud's light at the corners of the last triangle asked for: neighbouring pixels mostly
/// show the same triangle, whose corners are lit once.
#[derive(Default)]
struct CornerLight {
    last: Option<(u32, [(Vec3, Vec3); 3])>,
}

impl CornerLight {
    fn of(&mut self, src: u32, light: impl FnOnce() -> [(Vec3, Vec3); 3]) -> [(Vec3, Vec3); 3] {
        match self.last {
            Some((s, l)) if s == src => l,
            _ => {
                let l = light();
                self.last = Some((src, l));
                l
            }
        }
    }
}

/// The colour of a fragment of triangle `src` at its corner weights `b`.
#[allow(clippy::too_many_arguments)]
fn fragment_color(
    scene: &Scene,
    proj: &Projection,
    tris: &[Triangle],
    (src, b): (u32, Bary),
    opts: &RasterOptions,
    shadows: &shade::Lighting,
    corner_light: &mut CornerLight,
) -> Vec3 {
    let t = &tris[src as usize];
    let m = &scene.materials[t.material as usize];
    // An unbounded plane's triangles reach far beyond the view: their corners and centroid
    // say nothing about the pixels, so they are lit per pixel whatever the shading (for a
    // plane the interpolated normal is the face normal: flat, Gouraud and Phong agree but for
    // where the light is evaluated). Without this the floor went black (flat) or lost its
    // shadows (Gouraud).
    let shading = if t.unbounded { Shading::Phong } else { opts.shading };
    match shading {
        Shading::Gouraud => {
            // The corners are lit without the pixel's stencil mask, as vertices are.
            let frame = shade::Lighting { blocked: 0, ..*shadows };
            let corners =
                corner_light.of(src, || t.v.map(|v| shade::lighting(scene, m, v.p, v.n, proj.to_viewer(v.p), &frame)));
            let (p, n, uv) = surface_at(t, b);
            let light = (interpolate(corners.map(|c| c.0), b), interpolate(corners.map(|c| c.1), b));
            let base = shade::base_color(scene, m, uv, color_at(t, b));
            shade::combine(scene, m, light, n, proj.to_viewer(p), base, shadows)
        }
        Shading::Flat => {
            let [a, b, c] = t.v;
            let centroid = (a.p + b.p + c.p) / 3.0;
            let n = (b.p - a.p).cross(c.p - a.p).normalize_or_zero();
            let uv = (a.uv + b.uv + c.uv) / 3.0;
            let n = bumped(scene, m, t, uv, n);
            let base = shade::base_color(scene, m, uv, (a.color + b.color + c.color) / 3.0);
            shade::shade(scene, m, centroid, n, proj.to_viewer(centroid), base, shadows)
        }
        Shading::Phong => {
            let (p, n, uv) = surface_at(t, b);
            let n = bumped(scene, m, t, uv, n);
            let base = shade::base_color(scene, m, uv, color_at(t, b));
            shade::shade(scene, m, p, n, proj.to_viewer(p), base, shadows)
        }
    }
}

const BAND: u32 = 16;

/// About how many bytes [`render_scene`] takes for `scene` at its size with `opts`: the world's
/// triangles (twice while they are put in the octree's order), their corner records and screen
/// copies (one and a half per triangle, for clipping), the BSP
/// tree's when asked for, the frame and depth buffers, and room for shadow maps. Computed
/// without tessellating, so a scene that would not fit is refused before allocating.
pub fn memory_estimate(scene: &Scene, opts: &RasterOptions) -> u64 {
    let triangles: u64 = scene.objects.iter().map(|o| geometry::triangle_count(scene, &o.shape)).sum();
    let world = std::mem::size_of::<Triangle>() as u64;
    let screen = std::mem::size_of::<ScreenTriangle>() as u64;
    // The triangles are copied once into the octree's order while preparing (two copies at
    // that moment), and the frame's screen triangles come after.
    let per_triangle = world
        + (screen * 3 / 2).max(world)
        + std::mem::size_of::<Corners>() as u64
        + 16
        + if opts.visibility == Visibility::Bsp { 2 * world } else { 0 };
    let pixels = scene.render.width as u64 * scene.render.height as u64;
    const SHADOW_MAPS: u64 = 64 << 20;
    triangles * per_triangle + pixels * 32 + SHADOW_MAPS * scene.lights.len().min(16) as u64
}

/// Renders `scene` at its `[render]` size with the camera of the scene file.
pub fn render_scene(scene: &Scene, opts: &RasterOptions) -> Result<(Framebuffer, RasterStats), RasterError> {
    render_prepared(scene, &prepare(scene, opts), opts)
}

/// Renders prepared geometry (built once by [`prepare`], then drawn as often as the camera or
/// the options change). What `opts` asks for but was not prepared (see [`Prepared::serves`])
/// is left out: no shadow maps, no image-based light, the z-buffer instead of the BSP tree.
///
/// A stereo camera gives both eyes side by side (`2 × width`), or as a red–cyan anaglyph when
/// `opts.anaglyph`; a panorama is resampled from the six faces of a cube map rendered from its
/// eye.
pub fn render_prepared(
    scene: &Scene,
    prepared: &Prepared,
    opts: &RasterOptions,
) -> Result<(Framebuffer, RasterStats), RasterError> {
    let (w, h) = (scene.render.width, scene.render.height);
    if let Some([left, right]) = scene.camera.stereo_eyes(w as f64 / h as f64) {
        let (l, ls) = render_view(scene, prepared, opts, &projection(&left, w, h)?, (w, h))?;
        let (r, rs) = render_view(scene, prepared, opts, &projection(&right, w, h)?, (w, h))?;
        let fb = if opts.anaglyph { cameras::anaglyph(&l, &r) } else { cameras::side_by_side(&l, &r) };
        return Ok((fb, cameras::sum(ls, rs)));
    }
    if let CameraDesc::Panorama { look, angle } = scene.camera {
        return cameras::panorama(look, angle, (w, h), |desc, size| {
            render_view(scene, prepared, opts, &projection(desc, size, size)?, (size, size))
        });
    }
    render_view(scene, prepared, opts, &projection(&scene.camera, w, h)?, (w, h))
}

/// One view through `proj` at `w × h`, with what its mirrors show.
fn render_view(
    scene: &Scene,
    prepared: &Prepared,
    opts: &RasterOptions,
    proj: &Projection,
    size: (u32, u32),
) -> Result<(Framebuffer, RasterStats), RasterError> {
    render_view_in(scene, prepared, opts, proj, size, Pass::Main)
}

/// Which view a frame is: the camera's, a plane mirror's (whose own mirrors and glass show the
/// sky: one reflection deep), or what lies behind glass (drawn without transparent objects).
#[derive(Clone, Copy, PartialEq, Eq)]
enum Pass {
    Main,
    InMirror,
    BehindGlass,
}

/// One view through `proj`.
fn render_view_in(
    scene: &Scene,
    prepared: &Prepared,
    opts: &RasterOptions,
    proj: &Projection,
    (w, h): (u32, u32),
    pass: Pass,
) -> Result<(Framebuffer, RasterStats), RasterError> {
    let in_mirror = pass != Pass::Main;
    let proj = *proj;
    let geometry = &prepared.geometry;
    let prelit = prepared.prelit.as_deref();
    let stencil_mode = match (opts.shadows, opts.shadow_method, proj.perspective) {
        (true, ShadowMethod::Volumes(mode), true) if prelit.is_none() => Some(mode),
        _ => None,
    };
    let light = shade::Lighting {
        shadows: if opts.shadows && stencil_mode.is_none() { prepared.shadows.as_ref() } else { None },
        irradiance: prepared.ibl.as_ref().filter(|_| opts.ibl).map(|i| &i.irradiance),
        specular: prepared.ibl.as_ref().filter(|_| opts.ibl).map(|i| &i.specular),
        blocked: 0,
        reflected: None,
        behind: None,
        emitters: &prepared.emitters,
        hemisphere: opts
            .hemispherical
            .then(|| (scene.background.radiance(Vec3::Y), scene.background.radiance(Vec3::NEG_Y))),
    };
    let shadows = &light;
    // The painter's algorithm draws the BSP tree's triangles back to front; the z-buffer any order.
    let (tris, corners, order): (&[Triangle], &[Corners], Vec<u32>) = match (&prepared.bsp, opts.visibility) {
        (Some(tree), Visibility::Bsp) => {
            let viewer =
                if proj.perspective { bsp::Viewer::At(proj.frame.eye) } else { bsp::Viewer::Towards(proj.frame.w) };
            (&tree.triangles, &prepared.bsp_corners, tree.back_to_front(viewer))
        }
        _ => {
            let mut order = Vec::with_capacity(geometry.triangles.len());
            prepared.octree.visible_items(opts.frustum_culling.then_some(&proj.world_to_clip), &mut order);
            (&geometry.triangles, &prepared.corners, order)
        }
    };
    let outside = tris.len() - order.len();
    let cut_outs = scene.materials.iter().any(|m| m.alpha.is_some());
    let painter = opts.visibility == Visibility::Bsp && prepared.bsp.is_some();
    // A lit scene's light is all in its triangles: no second passes.
    let in_mirror = in_mirror || prelit.is_some();
    let pass = if prelit.is_some() { Pass::InMirror } else { pass };
    let volumes = stencil_mode.map(|_| stencil::volumes(scene, tris, proj.world_to_clip, (w, h))).unwrap_or_default();
    // Spherical mirrors by Glaeser's method: what each shows, before the frame is shaded.
    let mut mirror_images: Vec<mirrors::MirrorImage> = vec![];
    if proj.perspective && !in_mirror {
        let plain = *shadows;
        let found = mirrors::sphere_mirrors(scene);
        mirror_images.extend(
            found.iter().map(|m| mirrors::mirror_image(scene, &geometry.triangles, m, &proj, (w, h), opts, &plain)),
        );
    }
    // Plane mirrors: the scene once more through the reflected projection, clipped to the
    // mirror's front.
    for plane in prepared.plane_mirrors.iter().filter(|_| !in_mirror) {
        let Some((reflected, front)) = plane.reflected(&proj) else { continue };
        let mut seen = opts.clone();
        seen.clip_planes.push(front);
        let (fb, s) = render_view_in(scene, prepared, &seen, &reflected, (w, h), Pass::InMirror)?;
        let color = fb.color.iter().map(|c| Some(Vec3::new(c[0] as f64, c[1] as f64, c[2] as f64))).collect();
        mirror_images.push(mirrors::MirrorImage { object: plane.object, color, drawn: s.drawn });
    }
    // Glass: the frame once more without transparent objects, what they let through.
    let clear = |t: &Triangle| scene.materials[t.material as usize].transparency == Vec3::ZERO;
    let behind_glass = if pass == Pass::Main && prepared.transparent {
        Some(render_view_in(scene, prepared, opts, &proj, (w, h), Pass::BehindGlass)?.0)
    } else {
        None
    };
    let processed: Vec<([usize; 2], Vec<ScreenTriangle>)> = order
        .par_chunks(4096)
        .map(|chunk| {
            let mut out = Vec::with_capacity(chunk.len());
            let mut count = [0; 2];
            for &i in chunk.iter().filter(|&&i| pass != Pass::BehindGlass || clear(&tris[i as usize])) {
                match process(&proj, &corners[i as usize], i, opts, (w, h), &mut out) {
                    Fate::Culled => count[0] += 1,
                    Fate::Missed => count[1] += 1,
                    Fate::Kept => {}
                }
            }
            (count, out)
        })
        .collect();
    let culled = processed.iter().map(|p| p.0[0]).sum();
    let missed = processed.iter().map(|p| p.0[1]).sum();
    // The frame's screen triangles go into the last frame's buffer: a big mesh's hundreds of MB
    // are not mapped afresh (and page-faulted) every frame.
    let mut screen = SCREEN_BUFFER.with(|b| std::mem::take(&mut *b.borrow_mut()));
    gather(processed.iter().map(|p| &p.1[..]).collect(), &mut screen);
    let painter = painter || opts.visibility == Visibility::DepthSort;
    if opts.visibility == Visibility::DepthSort {
        screen = depth_sort::depth_sort(screen).0;
    }
    // Each band's triangles, in drawing order.
    let band_count = h.div_ceil(BAND) as usize;
    let mut bins: Vec<Vec<u32>> = vec![vec![]; band_count];
    for (i, t) in screen.iter().enumerate() {
        let lo = t.y.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = t.y.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        if !(hi >= 0.0 && lo <= h as f64) {
            continue;
        }
        let first = ((lo.max(0.0) / BAND as f64) as usize).min(band_count - 1);
        let last = ((hi.min(h as f64) / BAND as f64) as usize).min(band_count - 1);
        for bin in &mut bins[first..=last] {
            bin.push(i as u32);
        }
    }
    let bands: Vec<(Vec<[f32; 3]>, Vec<f64>)> = (0..h.div_ceil(BAND))
        .into_par_iter()
        .map(|band| {
            let (y0, y1) = (band * BAND, ((band + 1) * BAND).min(h));
            let n = ((y1 - y0) * w) as usize;
            let (mut depth, mut owner) = (vec![f64::INFINITY; n], vec![(u32::MAX, [0.0; 2]); n]);
            let bin = &bins[band as usize];
            let set = |k: usize, t: &ScreenTriangle, f: raster::Fragment| {
                depth[k] = f.depth;
                owner[k] = (t.source, f.bary);
            };
            if opts.visibility == Visibility::Scanline {
                scanline::band(&screen, bin, w, (y0, y1), set);
            } else if opts.visibility == Visibility::Warnock {
                warnock::band(&screen, bin, w, (y0, y1), set);
            } else {
                for t in bin.iter().map(|&i| &screen[i as usize]) {
                    let source = &tris[t.source as usize];
                    rasterize(t, w, y0, y1, |f| {
                        let k = ((f.y - y0) * w + f.x) as usize;
                        if (painter || f.depth < depth[k])
                            && f.depth >= -1.0
                            && (!cut_outs || present(scene, source, f.bary, (f.x, f.y)))
                        {
                            depth[k] = f.depth;
                            owner[k] = (t.source, f.bary);
                        }
                    });
                }
            }
            // Stencil shadow volumes: per light, a count per pixel of this band.
            let mut blocked = vec![0u64; n];
            if let Some(mode) = stencil_mode {
                for (light, vol) in volumes.iter().enumerate().take(64) {
                    let counts = stencil::count(vol, &depth, w, (y0, y1), mode);
                    for (b, c) in blocked.iter_mut().zip(&counts) {
                        if *c != 0 {
                            *b |= 1 << light;
                        }
                    }
                }
            }
            // CSG bodies: a ray per pixel, kept where nearer than the z-buffer.
            let ndc = |k: usize| {
                let (x, y) = ((k as u32 % w) as f64 + 0.5, (y0 + k as u32 / w) as f64 + 0.5);
                (2.0 * x / w as f64 - 1.0, 1.0 - 2.0 * y / h as f64)
            };
            let bodies: Vec<Option<(f64, Vec3)>> = match &prepared.csg {
                Some(b) => (0..n)
                    .map(|k| {
                        b.cast(scene, &proj, ndc(k), depth[k], &shade::Lighting { blocked: blocked[k], ..*shadows })
                    })
                    .collect(),
                None => vec![],
            };
            // Deferred: each visible pixel is shaded once.
            let mut corner_light = CornerLight::default();
            let color = (0..n)
                .map(|k| {
                    if let Some(Some((_, c))) = bodies.get(k) {
                        return [c.x as f32, c.y as f32, c.z as f32];
                    }
                    let (src, b) = owner[k];
                    let src = &src;
                    let global = (y0 * w) as usize + k;
                    let reflected = (*src != u32::MAX)
                        .then(|| tris[*src as usize].object)
                        .and_then(|o| mirror_images.iter().find(|i| i.object == o))
                        .and_then(|i| i.color[global]);
                    let behind = behind_glass.as_ref().map(|b| {
                        let c = b.color[global];
                        Vec3::new(c[0] as f64, c[1] as f64, c[2] as f64)
                    });
                    let shadows = &shade::Lighting { blocked: blocked[k], reflected, behind, ..*shadows };
                    let c = if *src == u32::MAX {
                        let (x, y) = ((k as u32 % w) as f64 + 0.5, (y0 + k as u32 / w) as f64 + 0.5);
                        scene.sky(proj.ray_dir(2.0 * x / w as f64 - 1.0, 1.0 - 2.0 * y / h as f64))
                    } else {
                        match prelit {
                            Some(lit) => lit_color(scene, &tris[*src as usize], &lit[*src as usize], b),
                            None => fragment_color(scene, &proj, tris, (*src, b), opts, shadows, &mut corner_light),
                        }
                    };
                    [c.x as f32, c.y as f32, c.z as f32]
                })
                .collect();
            for (d, body) in depth.iter_mut().zip(&bodies) {
                if let Some((z, _)) = body {
                    *d = *z;
                }
            }
            (color, depth)
        })
        .collect();
    let mut fb = Framebuffer {
        width: w,
        height: h,
        color: Vec::with_capacity((w * h) as usize),
        depth: Vec::with_capacity((w * h) as usize),
    };
    for (c, d) in bands {
        fb.color.extend(c);
        fb.depth.extend(d);
    }
    if opts.wireframe {
        draw_wireframe(&mut fb, &screen);
    }
    let reflexes = mirror_images.iter().map(|i| i.drawn).sum();
    let stats = RasterStats {
        triangles: tris.len(),
        culled,
        outside,
        drawn: screen.len(),
        missed,
        skipped_objects: if prepared.csg.is_some() { 0 } else { geometry.skipped },
        reflexes,
    };
    SCREEN_BUFFER.with(|b| *b.borrow_mut() = screen);
    Ok((fb, stats))
}

/// The chunks' screen triangles one after another in `screen` (whose old contents are
/// overwritten, not cleared first), copied in parallel.
fn gather(chunks: Vec<&[ScreenTriangle]>, screen: &mut Vec<ScreenTriangle>) {
    let total = chunks.iter().map(|c| c.len()).sum();
    screen.truncate(total);
    let filler =
        ScreenTriangle { x: [0.0; 3], y: [0.0; 3], z: [0.0; 3], inv_w: [0.0; 3], bary_w: [[0.0; 2]; 3], source: 0 };
    screen.resize(total, filler);
    let mut rest = &mut screen[..];
    let mut parts = Vec::with_capacity(chunks.len());
    for c in &chunks {
        let (part, tail) = rest.split_at_mut(c.len());
        parts.push(part);
        rest = tail;
    }
    parts.into_par_iter().zip(chunks).for_each(|(part, c)| part.copy_from_slice(c));
}

thread_local! {
    /// The screen-triangle buffer of the last frame drawn on this thread, for the next.
    static SCREEN_BUFFER: std::cell::RefCell<Vec<ScreenTriangle>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// Triangle edges by Bresenham, in white, over the image.
fn draw_wireframe(fb: &mut Framebuffer, screen: &[ScreenTriangle]) {
    for t in screen {
        for k in 0..3 {
            let (a, b) = (k, (k + 1) % 3);
            let pa = (t.x[a].floor() as i64, t.y[a].floor() as i64);
            let pb = (t.x[b].floor() as i64, t.y[b].floor() as i64);
            for (x, y) in crate::bresenham_line(pa, pb) {
                if x >= 0 && y >= 0 && (x as u32) < fb.width && (y as u32) < fb.height {
                    fb.color[(y as u32 * fb.width + x as u32) as usize] = [1.0, 1.0, 1.0];
                }
            }
        }
    }
}
