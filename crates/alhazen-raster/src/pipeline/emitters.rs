//! Emitting objects as the preview's lights (issue 21): the z-buffer has no area lights, so each
//! emitting object lends the preview a few point lights in the path tracer's units (emission is
//! radiance; the course's `a·I cos θ/d²` is divided by π, the Lambert normalisation), each with
//! a shadow map that leaves out the object's own triangles:
//! * a sphere: one light at its centre of intensity `L r²` (a sphere of radiance `L` shows the
//!   area `π r²` from every direction);
//! * a flat emitter (rectangle, disk, flat mesh): its area split in equal shares, each a spot of
//!   cosine fall-off over the hemisphere in front (`I(θ) = L A_k cos θ / π`) at the share's
//!   centroid;
//! * any other (boxes, closed meshes): shares radiating `L A_k / 4π` every way, a convex body's
//!   mean projected area being a quarter of its area (Cauchy).

use super::geometry::Triangle;
use alhazen_math::Vec3;
use alhazen_scene::{Light, Scene, Shape};
use std::collections::BTreeMap;
use std::f64::consts::PI;

/// Lights lent to the preview at most (shadow maps cost memory): four per emitter for up to
/// four emitters, else one each.
pub const SHARES_PER_EMITTER: usize = 4;

/// A light standing for (part of) an emitting object.
#[derive(Clone, Debug)]
pub struct EmitterLight {
    /// The light.
    pub light: Light,
    /// The emitting object (left out of its shadow map).
    pub object: u32,
}

/// The lights that stand for the emitting objects of `scene`, from its triangles.
pub fn emitter_lights(scene: &Scene, tris: &[Triangle]) -> Vec<EmitterLight> {
    let mut by_object: BTreeMap<u32, Vec<&Triangle>> = BTreeMap::new();
    for t in tris.iter().filter(|t| scene.materials[t.material as usize].emission != Vec3::ZERO) {
        by_object.entry(t.object).or_default().push(t);
    }
    let shares = if by_object.len() <= 4 { SHARES_PER_EMITTER } else { 1 };
    let mut out = vec![];
    for (object, tris) in by_object {
        let radiance = scene.materials[tris[0].material as usize].emission;
        let o = &scene.objects[object as usize];
        let lights = match o.shape {
            Shape::Sphere { center, .. } if !tris.is_empty() => {
                let c = o.transform.point(center);
                let r = (tris[0].v[0].p - c).length();
                vec![point(c, radiance * r * r)]
            }
            _ => area_shares(&tris, radiance, shares),
        };
        out.extend(lights.into_iter().map(|light| EmitterLight { light, object }));
    }
    out
}

fn point(position: Vec3, intensity: Vec3) -> Light {
    Light::Point { position, intensity, attenuation: [1.0, 0.0, 0.0] }
}

/// `shares` lights over equal shares of the triangles' area, in their order.
fn area_shares(tris: &[&Triangle], radiance: Vec3, shares: usize) -> Vec<Light> {
    let area = |t: &Triangle| 0.5 * (t.v[1].p - t.v[0].p).cross(t.v[2].p - t.v[0].p);
    let total: f64 = tris.iter().map(|t| area(t).length()).sum();
    if total <= 0.0 {
        return vec![];
    }
    let span = total / shares as f64;
    let mut acc = vec![(0.0, Vec3::ZERO, Vec3::ZERO); shares];
    let mut before = 0.0;
    for t in tris {
        let (a, centroid) = (area(t), (t.v[0].p + t.v[1].p + t.v[2].p) / 3.0);
        let len = a.length();
        // The triangle's area split between the shares its stretch of the total overlaps.
        for (k, share) in acc.iter_mut().enumerate() {
            let (lo, hi) = (k as f64 * span, (k + 1) as f64 * span);
            let part = (before + len).min(hi) - before.max(lo);
            if part > 0.0 && len > 0.0 {
                share.0 += part;
                share.1 += centroid * part;
                share.2 += a * (part / len);
            }
        }
        before += len;
    }
    let flat = tris.iter().map(|t| area(t)).sum::<Vec3>().length() > 0.9 * total;
    let offset = 1e-4 * total.sqrt();
    acc.into_iter()
        .filter(|s| s.0 > 0.0)
        .map(|(a, weighted, normal)| {
            let centroid = weighted / a;
            match normal.try_normalize().filter(|_| flat) {
                Some(n) => Light::Spot {
                    position: centroid + n * offset,
                    direction: n,
                    cos_cutoff: 0.0,
                    falloff: 1.0,
                    beam: None,
                    intensity: radiance * (a / PI),
                    attenuation: [1.0, 0.0, 0.0],
                },
                None => point(centroid, radiance * (a / (4.0 * PI))),
            }
        })
        .collect()
}
