//! Specular connections in the path tracer (issue 19; Glaeser §1–2 through [`crate::connect`]):
//! at every non-specular vertex `x`, each point, spot, directional and area light is joined to
//! `x` through every sphere, cylinder and plane mirror by all the exact solutions of Alhazen's
//! problem, each weighted by the mirror's reflectance and the generalised geometry term.
//!
//! Delta lights seen through a delta mirror are reached by nothing else. For area lights the
//! same path can also be found by sampling the BSDF at `x` and hitting the light after the
//! mirror; both strategies are weighted by the power heuristic, the connection's density
//! expressed as a solid angle at `x`: `p_A / (G cos θ_y)`.

use super::{PathTracer, Terminator, offset, power_heuristic};
use crate::bsdf::{Bsdf, ColorMode, Frame, bsdf_at};
use crate::connect::{MirrorPath, MirrorShape, Source};
use crate::lights::{Lights, PathLight};
use crate::sampler::SampleStream;
use crate::shape::ray_epsilon;
use crate::world::HitPoint;
use alhazen_math::{Vec2, Vec3};
use alhazen_scene::Scene;

/// A mirror surface the connections go through.
#[derive(Clone, Debug)]
pub(super) struct MirrorPiece {
    object: u32,
    material: u32,
    shape: MirrorShape,
}

/// What the connections need from the scene: its mirrors and the lights to join through them.
#[derive(Clone, Debug)]
pub(super) struct MirrorConnections {
    pieces: Vec<MirrorPiece>,
    /// Indices of the point, spot, directional and area lights, with each one's object.
    lights: Vec<(usize, Option<u32>)>,
    /// Some light is an area light: each vertex draws a point on them.
    any_area: bool,
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
                    shape,
                })
            })
            .collect();
        let objects = lights.objects();
        let connected: Vec<(usize, Option<u32>)> = lights
            .all()
            .iter()
            .enumerate()
            .filter(|(_, l)| {
                matches!(
                    l,
                    PathLight::Point { .. }
                        | PathLight::Spot { .. }
                        | PathLight::Directional { .. }
                        | PathLight::Area { .. }
                )
            })
            .map(|(i, _)| (i, objects[i]))
            .collect();
        let any_area = connected.iter().any(|(_, o)| o.is_some());
        (!pieces.is_empty() && !connected.is_empty()).then_some(Self { pieces, lights: connected, any_area })
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

    /// The piece of mirror object `object` that `p` lies on.
    fn piece_at(&self, object: u32, p: Vec3) -> Option<u32> {
        let of_object = self.pieces.iter().enumerate().filter(|(_, piece)| piece.object == object);
        of_object.min_by(|(_, a), (_, b)| a.shape.distance(p).total_cmp(&b.shape.distance(p))).map(|(i, _)| i as u32)
    }
}

impl PathTracer<'_> {
    /// Light reaching `x` through one mirror reflection from every connected light: `Σ f·cos·F·L`
    /// with the generalised geometry term, MIS-weighted for area lights.
    #[inline(never)]
    pub(super) fn mirror_connections(
        &self,
        c: &MirrorConnections,
        bsdf: &Bsdf,
        frame: &Frame,
        terminator: Option<Terminator>,
        x: Vec3,
        ng: Vec3,
        v: Vec3,
        x_object: u32,
        mode: ColorMode,
        s: &mut SampleStream,
    ) -> Vec3 {
        let u = if c.any_area { s.next_2d() } else { Vec2::ZERO };
        let mut sum = Vec3::ZERO;
        for &(light, light_object) in &c.lights {
            let Some((source, area_point)) = self.connection_source(light, u) else { continue };
            for piece in &c.pieces {
                let behind = !bsdf.transmits() && !piece.shape.in_front_of(x, ng);
                if behind || piece.object == x_object || Some(piece.object) == light_object {
                    continue;
                }
                piece.shape.reflections(x, source, |path| {
                    let at = (bsdf, frame, terminator);
                    sum += self.connected_path(piece, light, area_point, at, x, ng, v, mode, &path);
                });
            }
        }
        sum
    }

    /// The light as the mirror solver sees it; for an area light a point drawn by area with its
    /// normal and density.
    fn connection_source(&self, light: usize, u: Vec2) -> Option<(Source, Option<(Vec3, f64)>)> {
        Some(match &self.lights.all()[light] {
            PathLight::Point { position, .. } | PathLight::Spot { position, .. } => (Source::At(*position), None),
            PathLight::Directional { direction, .. } => (Source::Toward(-*direction), None),
            PathLight::Area { .. } => {
                let (y, n, pdf) = self.lights.point_by_area(light, u)?;
                (Source::At(y), Some((n, pdf)))
            }
            _ => return None,
        })
    }

    /// One path's contribution, zero when blocked, back-facing or outside a spot's cone.
    fn connected_path(
        &self,
        piece: &MirrorPiece,
        light: usize,
        area_point: Option<(Vec3, f64)>,
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
            (PathLight::Spot { direction, cos_cutoff, falloff, intensity, .. }, _) => {
                let cos = -path.to_source.dot(*direction);
                if cos < *cos_cutoff {
                    return Vec3::ZERO;
                }
                (*intensity * (cos.powf(*falloff) * g), 1.0)
            }
            (PathLight::Directional { irradiance, .. }, _) => (*irradiance * g, 1.0),
            (PathLight::Area { radiance, .. }, Some((n_y, pdf_area))) => {
                let cos_y = -n_y.dot(path.to_source);
                if cos_y <= 0.0 {
                    return Vec3::ZERO;
                }
                let pdf_connection = pdf_area / (g * cos_y);
                (*radiance * (cos_y * g / pdf_area), power_heuristic(pdf_connection, bsdf.pdf(v, l)))
            }
            _ => return Vec3::ZERO,
        };
        let reflectance = self.mirror_bsdf(piece.material, mode).mirror_reflectance(path.to_mirror.dot(path.normal));
        if reflectance == Vec3::ZERO || !self.legs_unoccluded(x, ng, path) {
            return Vec3::ZERO;
        }
        f * reflectance * mode.color(le) * weight
    }

    /// The mirror material's BSDF in the channels of `mode`.
    fn mirror_bsdf(&self, material: u32, mode: ColorMode) -> std::borrow::Cow<'_, Bsdf> {
        match (&self.uniform_bsdfs[material as usize], mode) {
            (Some(b), ColorMode::Rgb) => std::borrow::Cow::Borrowed(b),
            _ => {
                let m = &self.scene.materials[material as usize];
                std::borrow::Cow::Owned(bsdf_at(m, Vec2::ZERO, &self.scene.images, mode))
            }
        }
    }

    /// Both legs free: `x → m` short of the mirror, `m → source` short of the light.
    fn legs_unoccluded(&self, x: Vec3, ng: Vec3, path: &MirrorPath) -> bool {
        let short = |d: f64, p: Vec3| d * (1.0 - 1e-7) - 4.0 * ray_epsilon(p);
        let to_mirror = short(path.dist_to_mirror, x.abs().max(path.point.abs()));
        if !self.world.unoccluded(offset(x, ng, path.to_mirror), path.to_mirror, to_mirror) {
            return false;
        }
        let to_source =
            if path.dist_to_source.is_finite() { short(path.dist_to_source, path.point) } else { f64::INFINITY };
        let from = offset(path.point, path.normal, path.to_source);
        self.world.unoccluded(from, path.to_source, to_source)
    }

    /// The power-heuristic weight of emission at `hit`, reached through the mirror of `visit`
    /// by BSDF sampling, against the connection that finds the same path (1 when the
    /// connection would not).
    #[inline(never)]
    pub(super) fn mirror_visit_weight(&self, c: &MirrorConnections, visit: &MirrorVisit, hit: &HitPoint) -> f64 {
        let piece = &c.pieces[visit.piece as usize];
        let Some(light) = self.lights.of_object(hit.object) else { return 1.0 };
        if hit.object == piece.object || hit.object == visit.x_object {
            return 1.0;
        }
        let (to_mirror, to_light) = (visit.m - visit.x, hit.p - visit.m);
        let (t1, t2) = (to_mirror.length(), to_light.length());
        let g = piece.shape.geometry(to_mirror / t1, t1, visit.m, t2);
        let cos_y = hit.n.dot(to_light / t2).abs();
        let pdf_connection = self.lights.area_density(light) / (g * cos_y);
        if !pdf_connection.is_finite() {
            return 1.0;
        }
        power_heuristic(visit.pdf_x, pdf_connection)
    }
}
