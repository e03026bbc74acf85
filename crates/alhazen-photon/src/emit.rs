//! Where photons start: a light chosen by its power, a point on it, and a direction aimed at
//! the scene's specular objects (Jensen's projection maps, here cones to the objects' bounding
//! spheres): only photons that can meet a mirror or glass are shot, each carrying the power its
//! density gives it, so the caustic map fills without wasted rays.

use alhazen_math::{Vec2, Vec3, orthonormal_basis};
use alhazen_render::lights::{Lights, PathLight};
use alhazen_render::sampler::Rng;
use std::f64::consts::PI;

/// A sphere around a specular object.
#[derive(Clone, Copy, Debug)]
pub struct Target {
    /// Centre.
    pub center: Vec3,
    /// Radius.
    pub radius: f64,
}

/// A photon leaving a light: origin, unit direction and power (divided by the photon count by
/// the caller).
#[derive(Clone, Copy, Debug)]
pub struct Emission {
    /// Where it starts.
    pub origin: Vec3,
    /// Where it goes.
    pub dir: Vec3,
    /// Its power (W per channel), for one photon of one shot.
    pub power: Vec3,
}

/// Chooses lights and emits photons towards `targets` (or everywhere when there are none to aim
/// at: an unbounded specular object).
pub struct Emitter<'a> {
    lights: &'a Lights,
    targets: Vec<Target>,
    aim: bool,
    /// The scene's bounding sphere, for directional lights.
    scene: Target,
    /// Choice probability per light (zero for lights that shoot no photons: the sky).
    choice: Vec<f64>,
}

impl<'a> Emitter<'a> {
    /// An emitter over `lights`; `targets` are the specular objects' spheres, `None` when one is
    /// unbounded; `scene` the bounding sphere of everything.
    pub fn new(lights: &'a Lights, targets: Option<Vec<Target>>, scene: Target) -> Self {
        let aim = targets.is_some();
        let targets = targets.unwrap_or_default();
        let mut e = Self { lights, targets, aim, scene, choice: vec![] };
        let power: Vec<f64> = (0..lights.len()).map(|i| e.power_estimate(i)).collect();
        let total: f64 = power.iter().sum();
        e.choice = power.iter().map(|p| if total > 0.0 { p / total } else { 0.0 }).collect();
        e
    }

    /// True when some light shoots photons.
    pub fn shoots(&self) -> bool {
        self.choice.iter().any(|p| *p > 0.0)
    }

    /// A rough power towards the targets per light: only its share of the light choice.
    fn power_estimate(&self, i: usize) -> f64 {
        let mean = |c: Vec3| c.element_sum() / 3.0;
        match &self.lights.all()[i] {
            PathLight::Point { position, intensity } => mean(*intensity) * self.solid_angle(*position),
            PathLight::Spot { position, intensity, .. } => mean(*intensity) * self.solid_angle(*position),
            PathLight::Directional { irradiance, .. } => mean(*irradiance) * self.cross_section(),
            PathLight::Area { radiance, .. } => mean(*radiance) * PI / self.lights.area_density(i).max(1e-300),
            PathLight::Environment(_) | PathLight::Background(_) => 0.0,
        }
    }

    /// The solid angle of the targets' cones from `x` (their sum; 4π without targets).
    fn solid_angle(&self, x: Vec3) -> f64 {
        if !self.aim {
            return 4.0 * PI;
        }
        self.targets.iter().map(|t| cone(x, t).1).sum()
    }

    /// The targets' cross-section `Σ π r²` (the scene's without targets).
    fn cross_section(&self) -> f64 {
        if !self.aim {
            return PI * self.scene.radius * self.scene.radius;
        }
        self.targets.iter().map(|t| PI * t.radius * t.radius).sum()
    }

    /// One photon from `rng`; `None` when it carries nothing (outside a spot's cone, behind an
    /// area light).
    pub fn emit(&self, rng: &mut Rng) -> Option<Emission> {
        let light = choose(&self.choice, rng.uniform())?;
        let p_choice = self.choice[light];
        let e = match &self.lights.all()[light] {
            PathLight::Point { position, intensity } => {
                let (dir, pdf) = self.direction(*position, rng)?;
                Emission { origin: *position, dir, power: *intensity / pdf }
            }
            PathLight::Spot { position, direction, cos_cutoff, falloff, beam, intensity } => {
                let (dir, pdf) = self.direction(*position, rng)?;
                let c = dir.dot(*direction);
                if c < *cos_cutoff {
                    return None;
                }
                let shaped = alhazen_scene::spot_profile(c, *cos_cutoff, *falloff, *beam);
                Emission { origin: *position, dir, power: *intensity * shaped / pdf }
            }
            PathLight::Area { .. } => {
                let point = self.lights.point_by_area(light, Vec2::new(rng.uniform(), rng.uniform()))?;
                let (origin, n, pdf_area, radiance) = (point.p, point.n, point.pdf_area, point.radiance);
                let (dir, pdf) = self.direction(origin, rng)?;
                let cos = n.dot(dir);
                if cos <= 0.0 {
                    return None;
                }
                Emission {
                    origin: origin + n * 1e-9 * (1.0 + origin.abs().max_element()),
                    dir,
                    power: radiance * cos / (pdf_area * pdf),
                }
            }
            PathLight::Directional { direction, irradiance } => {
                let (point, pdf_area) = self.across(*direction, rng)?;
                let back = self.scene.radius * 4.0 + (point - self.scene.center).length();
                Emission { origin: point - *direction * back, dir: *direction, power: *irradiance / pdf_area }
            }
            PathLight::Environment(_) | PathLight::Background(_) => return None,
        };
        Some(Emission { power: e.power / p_choice, ..e })
    }

    /// A direction from `x` towards the targets and its solid-angle density (the mixture of
    /// their cones, each chosen by its solid angle).
    fn direction(&self, x: Vec3, rng: &mut Rng) -> Option<(Vec3, f64)> {
        let u = Vec2::new(rng.uniform(), rng.uniform());
        if !self.aim {
            return Some((uniform_sphere(u), 1.0 / (4.0 * PI)));
        }
        let cones: Vec<(f64, f64)> = self.targets.iter().map(|t| cone(x, t)).collect();
        let total: f64 = cones.iter().map(|c| c.1).sum();
        let weights: Vec<f64> = cones.iter().map(|c| c.1 / total).collect();
        let j = choose(&weights, rng.uniform())?;
        let axis = (self.targets[j].center - x).normalize_or(Vec3::Z);
        let dir = in_cone(axis, cones[j].0, u);
        // Every cone containing the direction could have produced it.
        let inside = self
            .targets
            .iter()
            .zip(&cones)
            .filter(|(t, c)| dir.dot((t.center - x).normalize_or(Vec3::Z)) >= c.0)
            .count()
            .max(1);
        Some((dir, inside as f64 / total))
    }

    /// A point on the plane across `d` (through the scene's centre) inside the targets' disks,
    /// and its area density.
    fn across(&self, d: Vec3, rng: &mut Rng) -> Option<(Vec3, f64)> {
        let disks: Vec<Target> = if self.aim { self.targets.clone() } else { vec![self.scene] };
        let total: f64 = disks.iter().map(|t| PI * t.radius * t.radius).sum();
        let weights: Vec<f64> = disks.iter().map(|t| PI * t.radius * t.radius / total).collect();
        let j = choose(&weights, rng.uniform())?;
        let (s, t) = orthonormal_basis(d);
        let u = Vec2::new(rng.uniform(), rng.uniform());
        let (r, phi) = (disks[j].radius * u.x.sqrt(), 2.0 * PI * u.y);
        // Project the disk's centre into the plane through the scene's centre.
        let c = disks[j].center - d * (disks[j].center - self.scene.center).dot(d);
        let point = c + (s * phi.cos() + t * phi.sin()) * r;
        let inside = disks
            .iter()
            .filter(|q| {
                let qc = q.center - d * (q.center - self.scene.center).dot(d);
                (point - qc).length_squared() <= q.radius * q.radius
            })
            .count()
            .max(1);
        Some((point, inside as f64 / total))
    }
}

/// The cone from `x` around sphere `t`: the cosine of its half-angle and its solid angle (the
/// whole sphere of directions when `x` is inside).
fn cone(x: Vec3, t: &Target) -> (f64, f64) {
    let d2 = (t.center - x).length_squared();
    if d2 <= t.radius * t.radius {
        return (-1.0, 4.0 * PI);
    }
    let cos_max = (1.0 - t.radius * t.radius / d2).max(0.0).sqrt();
    (cos_max, 2.0 * PI * (1.0 - cos_max))
}

/// A direction uniform in the cone around `axis` of half-angle cosine `cos_max`.
fn in_cone(axis: Vec3, cos_max: f64, u: Vec2) -> Vec3 {
    let cos = 1.0 - u.x * (1.0 - cos_max);
    let sin = (1.0 - cos * cos).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    let (s, t) = orthonormal_basis(axis);
    (s * (sin * phi.cos()) + t * (sin * phi.sin()) + axis * cos).normalize()
}

fn uniform_sphere(u: Vec2) -> Vec3 {
    in_cone(Vec3::Z, -1.0, u)
}

/// The index chosen by `u` from probabilities `p` (summing to 1); `None` if all are zero.
fn choose(p: &[f64], u: f64) -> Option<usize> {
    let mut acc = 0.0;
    let mut last = None;
    for (i, &pi) in p.iter().enumerate() {
        if pi <= 0.0 {
            continue;
        }
        acc += pi;
        last = Some(i);
        if u < acc {
            return Some(i);
        }
    }
    last
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cone_directions_stay_in_their_cone_and_cover_it() {
        let axis = Vec3::new(1.0, 2.0, -0.5).normalize();
        let mut rng = Rng::for_sample(1, 2, 3, 4);
        let (mut min_cos, mut mean) = (1.0f64, Vec3::ZERO);
        for _ in 0..20_000 {
            let d = in_cone(axis, 0.9, Vec2::new(rng.uniform(), rng.uniform()));
            min_cos = min_cos.min(d.dot(axis));
            mean += d / 20_000.0;
        }
        assert!((0.9 - 1e-12..0.901).contains(&min_cos), "{min_cos}");
        // The mean direction of a uniform cone is its axis times (1 + cos_max) / 2.
        assert!((mean - axis * 0.95).length() < 3e-3, "{mean}");
    }

    #[test]
    fn aimed_directions_cover_the_union_of_cones_with_their_density() {
        // E[1/pdf] over the emitter's own directions is the solid angle of the union of the
        // cones, also where two targets' cones overlap; counted independently over the sphere.
        let lights = Lights::default();
        let targets = vec![
            Target { center: Vec3::new(0.0, 0.0, 3.0), radius: 1.0 },
            Target { center: Vec3::new(0.8, 0.3, 2.5), radius: 1.2 },
        ];
        let e = Emitter::new(&lights, Some(targets.clone()), Target { center: Vec3::ZERO, radius: 10.0 });
        assert!(!e.shoots(), "no lights, nothing to shoot");
        let n = 400_000;
        let mut rng = Rng::for_sample(7, 0, 0, 0);
        let by_pdf: f64 = (0..n).map(|_| 1.0 / e.direction(Vec3::ZERO, &mut rng).unwrap().1).sum::<f64>() / n as f64;
        let hits = (0..n)
            .filter(|_| {
                let d = uniform_sphere(Vec2::new(rng.uniform(), rng.uniform()));
                targets.iter().any(|t| d.dot(t.center.normalize()) >= cone(Vec3::ZERO, t).0)
            })
            .count();
        let union = 4.0 * PI * hits as f64 / n as f64;
        assert!((by_pdf / union - 1.0).abs() < 0.01, "{by_pdf} vs {union}");
    }
}
