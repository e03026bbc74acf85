//! `alhazen-radiosity`: the course's energetic balance method (§"The energetic balance
//! method", "Global lighting models") for the diffuse surfaces of any scene.
//!
//! * [`form_factor`] — `G_ij/π` of a point towards a polygon in closed form (Nusselt's analogy,
//!   Lambert's edge sum), the course's hemicube with its delta form factors, the textbook
//!   patch-to-patch closed forms;
//! * [`mesh`] — the surfaces as quadtrees of triangular elements below shooting patches;
//! * [`solve`](mod@solve) — progressive refinement: the brightest unshot patch shoots, receivers refine
//!   where the light changes, point lights and the sky shoot first;
//! * [`display`] — vertex averaging for display and the final image by ray casting;
//! * [`ply`] — the solution as a PLY mesh with per-vertex values, read back by the preview.
//!
//! ```
//! let text = r#"
//! [render]
//! width = 8
//! height = 6
//! [camera]
//! eye = [0, 1, 4]
//! target = [0, 1, 0]
//! [materials.lamp]
//! emission = [5, 5, 5]
//! [[object]]
//! shape = "plane"
//! point = [0, 0, 0]
//! normal = [0, 1, 0]
//! [[object]]
//! shape = "disk"
//! center = [0, 2, 0]
//! normal = [0, -1, 0]
//! radius = 0.5
//! material = "lamp"
//! "#;
//! let scene = alhazen_scene::parse_scene("doc.toml".as_ref(), text).unwrap();
//! let solution = alhazen_radiosity::solve(&scene, &Default::default(), &|_, _| {}).unwrap();
//! // The floor below the lamp receives light; its back side none.
//! let t = solution.triangles.iter().position(|t| t.normal.y > 0.9).unwrap();
//! let b = solution.triangles[t].barycentric(alhazen_math::Vec3::ZERO);
//! assert!(solution.irradiance(t, b, 0).x > 0.0);
//! assert_eq!(solution.irradiance(t, b, 1).x, 0.0);
//! ```

pub mod display;
pub mod form_factor;
pub mod mesh;
pub mod ply;
pub mod solve;

pub use display::FinalGather;
pub use solve::{RadiosityError, Settings, Solution, Stats, memory_estimate, solve};
