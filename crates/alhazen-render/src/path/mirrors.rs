//! Specular connections in the path tracer (issue 19; Glaeser §1–2 through [`crate::connect`]):
//! at every non-specular vertex `x`, a point, spot, directional or area light is joined to `x`
//! through a sphere, cylinder or plane mirror by all the exact solutions of Alhazen's problem,
//! each weighted by the mirror's reflectance and the generalised geometry term.
//!
//! One (light, mirror) pair is connected per vertex, drawn at random — the light uniformly, the
//! mirror in proportion to how large its bounding sphere looks from `x` and from the light —
//! and its light divided by the probability of that draw: unbiased, as next-event estimation
//! is with one light, and a vertex costs one solve however many mirrors and lights the scene
//! has (connecting every pair made a scene of 49 objects, 8 of them chrome, 35× slower than
//! without connections).
//!
//! Delta lights seen through a delta mirror are reached by nothing else. For area lights the
//! same path can also be found by sampling the BSDF at `x` and hitting the light after the
//! mirror; both strategies are weighted by the power heuristic, the connection's density
//! expressed as a solid angle at `x`: `p_A / (G cos θ_y)`.

use super::{PathTracer, Terminator, power_heuristic, shadow_segment};
use crate::bsdf::{Bsdf, ColorMode, Frame, bsdf_at};
use crate::connect::{MirrorPath, MirrorShape, Source};
use crate::lights::{AreaPoint, Lights, PathLight};
use crate::sampler::SampleStream;
use crate::world::HitPoint;
use alhazen_math::{Vec2, Vec3};
use alhazen_scene::Scene;

/// A vertex connects with probability `ROULETTE_GAIN · Σ s_k(x)` (at most 1; `s_k` how large
/// piece `k`'s bounding sphere looks): `1` within `√8 ≈ 2.8` radii of a lone sphere, `1/8` at
/// eight radii. Measured on a scene of one small chrome ball among glossy spheres and on 49
/// objects with 8 chrome ones (BENCHMARKS.md, session 39).
const ROULETTE_GAIN: f64 = 8.0;

/// A mirror surface the connections go through.
#[derive(Clone, Debug)]
pub(super) struct MirrorPiece {
    object: u32,
    material: u32,
    shape: MirrorShape,
    /// The shape's bounding sphere (`None`: an unbounded plane), for choosing pieces.
    bound: Option<(Vec3, f64)>,
    /// Its material is one-sided: only its front reflects.
    front_only: bool,
}

/// A light the connections join through the mirrors.
#[derive(Clone, Debug)]
struct ConnectedLight {
    /// Its index among the scene's lights, and its emitting object.
    light: usize,
    object: Option<u32>,
    /// How large each piece looks from the light ([`apparent_size`] from a point light's
    /// position, an area light's centre; 1 from a light at infinity), for choosing pieces;
    /// zero for the light's own object, which no connection goes through.
    seen_from_light: Vec<f64>,
}

/// What the connections need from the scene: its mirrors and the lights to join through them.
#[derive(Clone, Debug)]
pub(super) struct MirrorConnections {
    pieces: Vec<MirrorPiece>,
    /// The pieces' bounding spheres side by side, for [`Self::draw_totals_keeping`].
    bounds: PieceBounds,
    /// The point, spot, directional and area lights.
    lights: Vec<ConnectedLight>,
    /// Some light is an area light: each vertex draws a point on them.
    any_area: bool,
}

/// A vertex's shading frame, its geometric normal on the viewer's side, its bump shadowing
/// and the direction to the viewer in the frame.
pub(super) struct VertexShading {
    pub(super) frame: Frame,
    pub(super) ng: Vec3,
    pub(super) terminator: Option<Terminator>,
    pub(super) v: Vec3,
}

/// A path that left a non-specular vertex `x` by sampling its BSDF and reflected on a mirror:
/// what the emission it meets next needs to weigh itself against the connection.
#[derive(Clone, Copy, Debug)]
pub(super) struct MirrorVisit {
    x: Vec3,
    x_object: u32,
    /// The BSDF's density at `x` of the direction taken.
    pdf_x: f64,
    piece: u32,
    m: Vec3,
}

impl MirrorConnections {
    /// The mirrors of `scene` (objects whose material is a smooth metal or mixes one in, without
    /// texture or bump map, on a sphere, cylinder, disk or plane) and its lights; `None` when
    /// there is no mirror or no light to connect.
    pub(super) fn build(scene: &Scene, lights: &Lights, uniform_bsdfs: &[Option<Bsdf>]) -> Option<Self> {
        let mirror_material = |id: u32| {
            let b = uniform_bsdfs[id as usize].as_ref();
            scene.materials[id as usize].bump.is_none()
                && b.is_some_and(|b| !b.transmits() && b.mirror_reflectance(1.0) != Vec3::ZERO)
        };
        let pieces: Vec<MirrorPiece> = scene
            .objects
            .iter()
            .enumerate()
            .filter(|(_, o)| o.mesh_materials.is_empty() && mirror_material(o.material))
            .flat_map(|(i, o)| {
                MirrorShape::pieces(&o.shape, &o.transform).into_iter().map(move |shape| MirrorPiece {
                    object: i as u32,
                    material: o.material,
                    bound: shape.bounding_sphere(),
                    front_only: scene.materials[o.material as usize].one_sided,
                    shape,
                })
            })
            .collect();
        let objects = lights.objects();
        let connected: Vec<_> = lights
            .all()
            .iter()
            .enumerate()
            .filter_map(|(i, l)| {
                let anchor = match l {
                    PathLight::Point { position, .. } | PathLight::Spot { position, .. } => Some(*position),
                    PathLight::Area { emitter, .. } => Some(emitter.centre()),
                    PathLight::Directional { .. } => None,
                    _ => return None,
                };
                Some((i, objects[i], anchor))
            })
            .collect();
        (!pieces.is_empty() && !connected.is_empty()).then(|| Self::new(pieces, &connected))
    }

    /// The connections through `pieces` of the lights `(index, emitting object, anchor)`.
    fn new(pieces: Vec<MirrorPiece>, lights: &[(usize, Option<u32>, Option<Vec3>)]) -> Self {
        let lights: Vec<ConnectedLight> = lights
            .iter()
            .map(|&(light, object, anchor)| {
                let seen = |p: &MirrorPiece| {
                    if Some(p.object) == object { 0.0 } else { apparent_size(p.bound, anchor) }
                };
                ConnectedLight { light, object, seen_from_light: pieces.iter().map(seen).collect() }
            })
            .collect();
        let any_area = lights.iter().any(|l| l.object.is_some());
        Self { bounds: PieceBounds::of(&pieces), pieces, lights, any_area }
    }

    /// The visit to record when the path sampled a delta lobe at `hit` after sampling a
    /// non-delta one at the previous vertex `x`.
    #[inline(never)]
    pub(super) fn visit(&self, x: Vec3, x_object: u32, pdf_x: f64, hit: &HitPoint) -> Option<MirrorVisit> {
        if hit.object == x_object {
            return None;
        }
        let piece = self.piece_at(hit.object, hit.p)?;
        Some(MirrorVisit { x, x_object, pdf_x, piece, m: hit.p })
    }

    /// How large piece `k` looks from `x` (on `x_object`): zero from its own object.
    fn seen_from(&self, k: usize, x: Vec3, x_object: u32) -> f64 {
        let piece = &self.pieces[k];
        if piece.object == x_object { 0.0 } else { apparent_size(piece.bound, Some(x)) }
    }

    /// The probability `q` that a vertex at `x` (on `x_object`) connects at all,
    /// `min(1, K · Σ s_k(x))` over the pieces (how large each looks) — a Russian roulette on
    /// what mirrors far away and small can bring, decided before any solve; near a mirror (a
    /// sphere within `√K` radii) a vertex always connects — and the sum of the pieces' weights
    /// in the draw for light `l` ([`Self::piece_weight`]). One pass, one division per piece.
    fn draw_totals(&self, l: &ConnectedLight, x: Vec3, x_object: u32) -> (f64, f64) {
        self.draw_totals_keeping(l, x, x_object, &mut [])
    }

    /// [`Self::draw_totals`], keeping the first pieces' sizes seen from `x` in `sizes`.
    #[inline(always)]
    fn draw_totals_keeping(&self, l: &ConnectedLight, x: Vec3, x_object: u32, sizes: &mut [f64]) -> (f64, f64) {
        let kept = sizes.len().min(self.pieces.len());
        self.bounds.seen_from(x, x_object, &mut sizes[..kept]);
        let (mut seen, mut total) = (0.0, 0.0);
        for k in 0..self.pieces.len() {
            let s = if k < kept { sizes[k] } else { self.seen_from(k, x, x_object) };
            seen += s;
            total += s * l.seen_from_light[k];
        }
        ((ROULETTE_GAIN * seen).min(1.0), total)
    }

    /// The probability that a vertex at `x` (on `x_object`) connects at all
    /// ([`Self::draw_totals`]).
    #[cfg(test)]
    fn connect_probability(&self, x: Vec3, x_object: u32) -> f64 {
        self.draw_totals(&self.lights[0], x, x_object).0
    }

    /// The weight of piece `k` in the draw for light `l` at `x` (an object on `x_object`):
    /// how large the piece's bounding sphere looks from `x` times from the light (its radius²
    /// over the squared distance, at most 1; an unbounded plane 1); zero for the object `x`
    /// lies on and for the light's own object, which no connection goes through.
    fn piece_weight(&self, l: &ConnectedLight, k: usize, x: Vec3, x_object: u32) -> f64 {
        self.seen_from(k, x, x_object) * l.seen_from_light[k]
    }

    /// The (light, piece) pair a vertex at `x` connects through, drawn by `u` — whether it
    /// connects at all by [`Self::draw_totals`]' `q` (`u.y < q`), then the light uniformly and
    /// the piece by [`Self::piece_weight`] (`u.y / q`, uniform again) — with the probability
    /// of the draw; `None` when it does not connect.
    fn choose(&self, x: Vec3, x_object: u32, u: Vec2) -> Option<(usize, usize, f64)> {
        let slot = ((u.x * self.lights.len() as f64) as usize).min(self.lights.len() - 1);
        let l = &self.lights[slot];
        // The pieces' sizes from `x` (up to `KEPT` of them), kept for the draw's running sum.
        const KEPT: usize = 32;
        let mut sizes = [0.0; KEPT];
        let (q, total) = self.draw_totals_keeping(l, x, x_object, &mut sizes);
        if u.y >= q || total <= 0.0 {
            return None;
        }
        // The first piece whose running sum passes `(u.y / q) · total` (the last one weighed,
        // should rounding keep the sum below it).
        let (target, mut below, mut chosen) = (u.y / q * total, 0.0, None);
        for k in 0..self.pieces.len() {
            // `piece_weight`, its first factor kept.
            let w = sizes.get(k).map_or_else(|| self.piece_weight(l, k, x, x_object), |s| s * l.seen_from_light[k]);
            if w > 0.0 {
                (below, chosen) = (below + w, Some((k, w)));
                if target < below {
                    break;
                }
            }
        }
        let (k, w) = chosen?;
        Some((slot, k, q * (w / total / self.lights.len() as f64)))
    }

    /// The probability that [`Self::choose`] draws light `slot` and piece `k` at `x`.
    fn choice_probability(&self, slot: usize, k: usize, x: Vec3, x_object: u32) -> f64 {
        let l = &self.lights[slot];
        let (q, total) = self.draw_totals(l, x, x_object);
        if total <= 0.0 {
            return 0.0;
        }
        q * (self.piece_weight(l, k, x, x_object) / total / self.lights.len() as f64)
    }

    /// The piece of mirror object `object` that `p` lies on.
    fn piece_at(&self, object: u32, p: Vec3) -> Option<u32> {
        let of_object = self.pieces.iter().enumerate().filter(|(_, piece)| piece.object == object);
        of_object.min_by(|(_, a), (_, b)| a.shape.distance(p).total_cmp(&b.shape.distance(p))).map(|(i, _)| i as u32)
    }
}

/// The mirror pieces' bounding spheres, one array per quantity: how large the first pieces look
/// from a vertex is then one loop of independent divisions, in vector lanes, where one piece's
/// record after another made each wait for the last (the draw was 7 % of a scene of nine
/// mirror balls).
#[derive(Clone, Debug, Default)]
struct PieceBounds {
    centre: [Vec<f64>; 3],
    /// The squared radius; infinite for an unbounded plane, which then looks as large as
    /// anything can (`∞/d²` at most 1 is 1, as is `∞/∞`, NaN, at most 1 by `f64::min`).
    radius_squared: Vec<f64>,
    object: Vec<u32>,
}

impl PieceBounds {
    fn of(pieces: &[MirrorPiece]) -> Self {
        let mut b = PieceBounds::default();
        for p in pieces {
            let (centre, r2) = p.bound.map_or((Vec3::ZERO, f64::INFINITY), |(c, r)| (c, r * r));
            (0..3).for_each(|a| b.centre[a].push(centre[a]));
            b.radius_squared.push(r2);
            b.object.push(p.object);
        }
        b
    }

    /// How large each of the first `sizes.len()` pieces looks from `x` (on `x_object`), as
    /// [`MirrorConnections::seen_from`] computes it, to the bit.
    #[inline(always)]
    fn seen_from(&self, x: Vec3, x_object: u32, sizes: &mut [f64]) {
        let n = sizes.len();
        let (cx, cy, cz) = (&self.centre[0][..n], &self.centre[1][..n], &self.centre[2][..n]);
        let (r2, object) = (&self.radius_squared[..n], &self.object[..n]);
        for k in 0..n {
            let (dx, dy, dz) = (cx[k] - x.x, cy[k] - x.y, cz[k] - x.z);
            // `apparent_size`: `DVec3::length_squared` sums in this order.
            let size = (r2[k] / (dx * dx + dy * dy + dz * dz)).min(1.0);
            sizes[k] = if object[k] == x_object { 0.0 } else { size };
        }
    }
}

/// How large a bounding sphere looks from `p`: its radius² over the squared distance, at most
/// 1; 1 for an unbounded plane or a point at infinity.
fn apparent_size(bound: Option<(Vec3, f64)>, p: Option<Vec3>) -> f64 {
    match (bound, p) {
        (Some((centre, r)), Some(p)) => (r * r / (centre - p).length_squared()).min(1.0),
        _ => 1.0,
    }
}

impl PathTracer<'_> {
    /// Light reaching `x` through one mirror reflection: `Σ f·cos·F·L` over the reflections
    /// of one (light, mirror) pair drawn at random ([`MirrorConnections::choose`]), divided by
    /// the probability of the draw, with the generalised geometry term; MIS-weighted for area
    /// lights. `shading` gives the vertex's frame, geometric normal, bump shadowing and
    /// direction to the viewer in the frame ([`PathTracer::shading_frame`]): asked only when
    /// the vertex connects.
    #[inline(never)]
    pub(super) fn mirror_connections(
        &self,
        c: &MirrorConnections,
        bsdf: &Bsdf,
        shading: impl FnOnce() -> VertexShading,
        x: Vec3,
        x_object: u32,
        mode: ColorMode,
        s: &mut SampleStream,
    ) -> Vec3 {
        let u = if c.any_area { s.next_2d() } else { Vec2::ZERO };
        let u_choice = s.next_2d();
        let Some((slot, k, p_choice)) = c.choose(x, x_object, u_choice) else { return Vec3::ZERO };
        let (light, piece) = (c.lights[slot].light, &c.pieces[k]);
        let Some((source, area_point)) = self.connection_source(light, u) else { return Vec3::ZERO };
        let VertexShading { frame, ng, terminator, v } = shading();
        if !bsdf.transmits() && !piece.shape.in_front_of(x, ng) {
            return Vec3::ZERO;
        }
        let mut sum = Vec3::ZERO;
        piece.shape.reflections_on(x, source, piece.front_only, |path| {
            let at = (bsdf, &frame, terminator);
            sum += self.connected_path(piece, (light, area_point, p_choice), at, x, ng, v, mode, &path);
        });
        sum
    }

    /// The light as the mirror solver sees it; for an area light a point drawn by area with its
    /// normal and density.
    fn connection_source(&self, light: usize, u: Vec2) -> Option<(Source, Option<AreaPoint>)> {
        Some(match &self.lights.all()[light] {
            PathLight::Point { position, .. } | PathLight::Spot { position, .. } => (Source::At(*position), None),
            PathLight::Directional { direction, .. } => (Source::Toward(-*direction), None),
            PathLight::Area { .. } => {
                let point = self.lights.point_by_area(light, u)?;
                (Source::At(point.p), Some(point))
            }
            _ => return None,
        })
    }

    /// One path's contribution through `piece` from `light` (an area light's point, its
    /// normal and density), drawn with probability `p_choice`; zero when blocked, back-facing
    /// or outside a spot's cone.
    fn connected_path(
        &self,
        piece: &MirrorPiece,
        (light, area_point, p_choice): (usize, Option<AreaPoint>, f64),
        (bsdf, frame, terminator): (&Bsdf, &Frame, Option<Terminator>),
        x: Vec3,
        ng: Vec3,
        v: Vec3,
        mode: ColorMode,
        path: &MirrorPath,
    ) -> Vec3 {
        let l = frame.to_local(path.to_mirror);
        let f = bsdf.eval(v, l) * l.z.abs() * Terminator::shadowing(terminator, path.to_mirror);
        if f == Vec3::ZERO || (ng.dot(path.to_mirror) > 0.0) != (l.z > 0.0) && !bsdf.transmits() {
            return Vec3::ZERO;
        }
        let g = path.geometry;
        let (le, weight) = match (&self.lights.all()[light], area_point) {
            (PathLight::Point { intensity, .. }, _) => (*intensity * g, 1.0),
            (PathLight::Spot { direction, cos_cutoff, falloff, beam, intensity, .. }, _) => {
                let cos = -path.to_source.dot(*direction);
                if cos < *cos_cutoff {
                    return Vec3::ZERO;
                }
                (*intensity * (alhazen_scene::spot_profile(cos, *cos_cutoff, *falloff, *beam) * g), 1.0)
            }
            (PathLight::Directional { irradiance, .. }, _) => (*irradiance * g, 1.0),
            (PathLight::Area { .. }, Some(AreaPoint { n: n_y, pdf_area, radiance, .. })) => {
                let cos_y = -n_y.dot(path.to_source);
                if cos_y <= 0.0 {
                    return Vec3::ZERO;
                }
                let pdf_connection = p_choice * pdf_area / (g * cos_y);
                (radiance * (cos_y * g / pdf_area), power_heuristic(pdf_connection, bsdf.pdf(v, l)))
            }
            _ => return Vec3::ZERO,
        };
        let reflectance = self.mirror_bsdf(piece.material, mode).mirror_reflectance(path.to_mirror.dot(path.normal));
        if reflectance == Vec3::ZERO || !self.legs_unoccluded(x, ng, path) {
            return Vec3::ZERO;
        }
        f * reflectance * mode.color(le) * (weight / p_choice)
    }

    /// The mirror material's BSDF in the channels of `mode`.
    fn mirror_bsdf(&self, material: u32, mode: ColorMode) -> std::borrow::Cow<'_, Bsdf> {
        match (&self.uniform_bsdfs[material as usize], mode) {
            (Some(b), ColorMode::Rgb) => std::borrow::Cow::Borrowed(b),
            _ => {
                let m = &self.scene.materials[material as usize];
                std::borrow::Cow::Owned(bsdf_at(m, Vec2::ZERO, Vec3::ONE, &self.scene.images, mode))
            }
        }
    }

    /// Both legs free: `x → m` short of the mirror, `m → source` short of the light.
    fn legs_unoccluded(&self, x: Vec3, ng: Vec3, path: &MirrorPath) -> bool {
        let scale = x.abs().max(path.point.abs());
        let (from, toward, dist) = shadow_segment(x, ng, path.to_mirror, path.dist_to_mirror, scale);
        if !self.world.unoccluded(from, toward, dist) {
            return false;
        }
        let (from, toward, dist) =
            shadow_segment(path.point, path.normal, path.to_source, path.dist_to_source, path.point);
        self.world.unoccluded(from, toward, dist)
    }

    /// The power-heuristic weight of emission at `hit`, reached through the mirror of `visit`
    /// by BSDF sampling, against the connection that finds the same path (1 when the
    /// connection would not).
    #[inline(never)]
    pub(super) fn mirror_visit_weight(&self, c: &MirrorConnections, visit: &MirrorVisit, hit: &HitPoint) -> f64 {
        let piece = &c.pieces[visit.piece as usize];
        let Some(light) = self.lights.of_object(hit.object) else { return 1.0 };
        let Some(slot) = c.lights.iter().position(|l| l.light == light) else { return 1.0 };
        let p_choice = c.choice_probability(slot, visit.piece as usize, visit.x, visit.x_object);
        if hit.object == piece.object || hit.object == visit.x_object || p_choice == 0.0 {
            return 1.0;
        }
        let (to_mirror, to_light) = (visit.m - visit.x, hit.p - visit.m);
        let (t1, t2) = (to_mirror.length(), to_light.length());
        let g = piece.shape.geometry(to_mirror / t1, t1, visit.m, t2);
        let cos_y = hit.n.dot(to_light / t2).abs();
        let pdf_connection = p_choice * self.lights.area_density(light) / (g * cos_y);
        if !pdf_connection.is_finite() {
            return 1.0;
        }
        power_heuristic(visit.pdf_x, pdf_connection)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Three spheres of different sizes and a plane, two lights (one on an object that is also
    /// a piece): pieces and lights a vertex may draw.
    fn connections() -> MirrorConnections {
        let sphere = |object, center: Vec3, radius| {
            let shape = MirrorShape::Sphere { center, radius };
            MirrorPiece { object, material: 0, bound: shape.bounding_sphere(), front_only: false, shape }
        };
        let plane = MirrorShape::Plane { point: Vec3::ZERO, normal: Vec3::Y };
        let pieces = vec![
            sphere(0, Vec3::new(1.0, 1.0, 0.0), 0.5),
            sphere(1, Vec3::new(-2.0, 0.5, 1.0), 0.2),
            sphere(2, Vec3::new(0.0, 3.0, -4.0), 1.5),
            MirrorPiece { object: 3, material: 0, bound: None, front_only: false, shape: plane },
        ];
        MirrorConnections::new(pieces, &LIGHTS)
    }

    /// How large the pieces look from a vertex, all in one loop over their bounds side by side,
    /// is what each piece's own record gives, to the bit: spheres near and far, the plane (no
    /// bound), the vertex's own object, a vertex at a sphere's centre and far away.
    #[test]
    fn the_pieces_side_by_side_look_as_large_as_each_alone() {
        let c = connections();
        let points = [
            (Vec3::new(0.3, 0.0, 0.2), 3),
            (Vec3::new(1.0, 1.5, 0.0), 0),
            (Vec3::new(1.0, 1.0, 0.0), 9),
            (Vec3::new(-5.0e200, 2.0, 7.0), 9),
            (Vec3::new(-2.0, 0.6, 1.1), 1),
        ];
        for (x, x_object) in points {
            let mut sizes = [f64::NAN; 4];
            c.bounds.seen_from(x, x_object, &mut sizes);
            for (k, size) in sizes.iter().enumerate() {
                let alone = c.seen_from(k, x, x_object);
                assert_eq!(size.to_bits(), alone.to_bits(), "piece {k} from {x}: {size} against {alone}");
            }
        }
    }

    /// A light at a point, and one on the largest sphere.
    const LIGHTS: [(usize, Option<u32>, Option<Vec3>); 2] =
        [(0, None, Some(Vec3::new(0.0, 5.0, 0.0))), (1, Some(2), Some(Vec3::new(0.0, 3.0, -4.0)))];

    /// The draw's frequencies over a fine grid of `u` are the probabilities it reports, and
    /// those [`MirrorConnections::choice_probability`] gives the emission's MIS weight, which
    /// sum to the probability of connecting at all; no piece is drawn through which nothing
    /// connects (its own object, the light's).
    #[test]
    fn the_drawn_pair_has_the_probability_the_weights_use() {
        let without_plane = MirrorConnections::new(connections().pieces[..3].to_vec(), &LIGHTS);
        let points = [(Vec3::new(0.3, 0.0, 0.2), 3), (Vec3::new(1.0, 1.5, 0.0), 0), (Vec3::new(-5.0, 2.0, 7.0), 9)];
        for (c, (x, x_object)) in
            [connections(), without_plane].into_iter().flat_map(|c| points.map(|p| (c.clone(), p)))
        {
            let q = c.connect_probability(x, x_object);
            assert!(q > 0.0 && q <= 1.0, "{q}");
            let n = 1000;
            let mut counts = [[0usize; 4]; 2];
            for i in 0..n {
                for j in 0..n {
                    let u = Vec2::new((i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64);
                    let Some((slot, k, p)) = c.choose(x, x_object, u) else { continue };
                    assert!((p - c.choice_probability(slot, k, x, x_object)).abs() <= 1e-15 * p);
                    assert!(c.pieces[k].object != x_object && Some(c.pieces[k].object) != c.lights[slot].object);
                    counts[slot][k] += 1;
                }
            }
            let mut total = 0.0;
            for (slot, row) in counts.iter().enumerate() {
                for (k, &count) in row.iter().enumerate().take(c.pieces.len()) {
                    let p = c.choice_probability(slot, k, x, x_object);
                    let frequency = count as f64 / (n * n) as f64;
                    assert!((frequency - p).abs() < 2e-3, "{x}: pair ({slot}, {k}) drawn {frequency}, probability {p}");
                    total += p;
                }
            }
            assert!((total - q).abs() < 1e-12, "{total} against {q}");
        }
    }
}
