//! Cut-outs: a mesh whose materials say where the surface is not ([`alhazen_scene::Alpha`]:
//! glTF's `alphaMode`, pbrt's shape `alpha`, Mitsuba's `mask`). Its ray tests look at every
//! hit's coverage before taking it, so a ray (a shadow ray too) goes on through the holes as
//! if nothing were there, in every tracer alike (pbrt-v4 tests alpha in its intersection
//! routines in the same way). A coverage between 0 and 1 without a cutoff lets that fraction
//! of the rays stop: which ones is decided by a hash of the ray and of the hit's distance,
//! never by a random stream, so that a render stays a function of its inputs and a ray's fate
//! is the same wherever it is traced.

use super::Candidate;
use alhazen_geom::TriangleMesh;
use alhazen_math::Ray;
use alhazen_scene::{self as scene, Alpha, ImageData};
use std::sync::Arc;

/// The cut-outs of one placed mesh: per material slot, its material's coverage.
#[derive(Debug)]
pub struct AlphaMask {
    /// Slot by slot, the material's cut-out (`None`: opaque).
    slots: Vec<Option<Alpha>>,
    /// The cut-out of slots past `slots` (the object's own material).
    others: Option<Alpha>,
    /// The scene's images, which the coverages name (one list shared by every mask).
    images: Arc<Vec<Arc<ImageData>>>,
}

impl AlphaMask {
    /// The cut-outs of `object` (a mesh) in `scene`, whose `images` they name; `None` when
    /// all its materials are opaque.
    pub fn of(object: &scene::Object, scene: &scene::Scene, images: &Arc<Vec<Arc<ImageData>>>) -> Option<Arc<Self>> {
        let alpha = |m: u32| scene.materials.get(m as usize).and_then(|m| m.alpha.clone());
        let slots: Vec<Option<Alpha>> = object.mesh_materials.iter().map(|&m| alpha(m)).collect();
        let others = alpha(object.material);
        if others.is_none() && slots.iter().all(Option::is_none) {
            return None;
        }
        Some(Arc::new(Self { slots, others, images: images.clone() }))
    }

    /// One cut-out for every slot (`alpha`'s coverage naming `images`).
    pub fn uniform(alpha: Alpha, images: Vec<Arc<ImageData>>) -> Self {
        Self { slots: vec![], others: Some(alpha), images: Arc::new(images) }
    }

    /// True when the surface is present at hit `c` of `ray` on `mesh` (`c.aux` its triangle).
    pub fn covers(&self, mesh: &TriangleMesh, c: &Candidate, ray: &Ray) -> bool {
        let tri = c.aux as usize;
        let slot = mesh.material_slots.get(tri).copied().unwrap_or(0) as usize;
        let Some(alpha) = self.slots.get(slot).unwrap_or(&self.others) else { return true };
        let coverage =
            alhazen_scene::texture::coverage(alpha, super::mesh::uv_at(mesh, c.aux as usize, c.bary), &self.images);
        match alpha.cutoff {
            Some(cutoff) => coverage >= cutoff,
            None => coverage >= 1.0 || (coverage > 0.0 && ray_hash(ray, c.t) < coverage),
        }
    }
}

/// A number in `[0, 1)` from the bits of `ray` and of the distance `t` of one of its hits
/// (SplitMix64's finaliser over each word in turn).
pub fn ray_hash(ray: &Ray, t: f64) -> f64 {
    let words = [ray.origin.x, ray.origin.y, ray.origin.z, ray.dir.x, ray.dir.y, ray.dir.z, t];
    let h = words.iter().fold(0x9e37_79b9_7f4a_7c15_u64, |h, w| mix(h ^ w.to_bits()));
    (h >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}
