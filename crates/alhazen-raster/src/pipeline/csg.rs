//! CSG bodies in the preview by a per-pixel ray-cast pass (issue 21): the z-buffer has no
//! triangles for a Boolean combination, so each pixel casts its eye ray at the scene's CSG
//! objects alone (the ray tracer's exact intersection, `alhazen-render`), and where the body is
//! nearer than what the z-buffer holds it is lit by the course's local model there. Their
//! shadows on others are not drawn (shadow maps hold triangles).

use super::{Projection, shade};
use alhazen_math::{Vec2, Vec3};
use alhazen_render::World;
use alhazen_scene::{Scene, Shape};

/// The CSG objects of a scene, ready to be ray cast.
pub struct CsgBodies {
    world: World,
}

impl CsgBodies {
    /// The CSG objects of `scene`, or `None` when it has none.
    pub fn of(scene: &Scene) -> Option<CsgBodies> {
        let mut only = scene.clone();
        only.objects.retain(|o| matches!(o.shape, Shape::Csg { .. }));
        (!only.objects.is_empty()).then(|| CsgBodies { world: World::build(&only) })
    }

    /// Casts the ray through NDC `(x, y)`: when a body is nearer than `depth` (the z-buffer's
    /// `z/w`), its depth and colour.
    pub fn cast(
        &self,
        scene: &Scene,
        proj: &Projection,
        (x, y): (f64, f64),
        depth: f64,
        light: &shade::Lighting,
    ) -> Option<(f64, Vec3)> {
        let hit = self.world.intersect(&proj.near_ray(x, y), f64::INFINITY)?;
        let p = hit.hit.p;
        let c = proj.world_to_clip * p.extend(1.0);
        let z = c.z / c.w;
        if z.partial_cmp(&depth) != Some(std::cmp::Ordering::Less) {
            return None;
        }
        let m = &scene.materials[hit.material as usize];
        let color = shade::shade(
            scene,
            m,
            p,
            hit.hit.ns,
            proj.to_viewer(p),
            shade::base_color(scene, m, Vec2::new(hit.hit.uv.x, hit.hit.uv.y), hit.hit.color),
            light,
        );
        Some((z, color))
    }
}
