//! `alhazen render --integrator photon`: the caustic photon map made once (with a progress
//! bar), then the path tracer taking caustics from it, through the same tiles, bands and
//! checkpoints as the other integrators.

use crate::Failure;
use alhazen_photon::{CausticMap, Settings};
use alhazen_render::World;
use alhazen_scene::Scene;
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};

/// The photon map's settings.
#[derive(Args, Clone, Debug)]
pub(crate) struct PhotonArgs {
    /// Photon mapping: photons shot from the lights towards the mirrors and glass [default: 500000].
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..=100_000_000))]
    photons: Option<u64>,
    /// Photon mapping: photons gathered in each density estimate [default: 64].
    #[arg(long, value_name = "K", value_parser = clap::value_parser!(u32).range(1..=4096))]
    photon_nearest: Option<u32>,
    /// Photon mapping: the largest gathering radius, in scene units (default: 5 % of the
    /// radius of the bounding sphere of the scene's bounded objects).
    #[arg(long, value_name = "LENGTH", value_parser = crate::radiosity::parse_length)]
    photon_radius: Option<f64>,
}

impl PhotonArgs {
    /// The map's settings for a render seeded by `seed`.
    pub(crate) fn settings(&self, seed: u64) -> Settings {
        let d = Settings::default();
        Settings {
            photons: self.photons.map_or(d.photons, |n| n as usize),
            nearest: self.photon_nearest.map_or(d.nearest, |k| k as usize),
            radius: self.photon_radius,
            seed,
        }
    }

    /// Refuses photon options without the photon integrator, and scenes it cannot render.
    pub(crate) fn check(&self, photon: bool, scene: &Scene) -> Result<(), Failure> {
        if !photon {
            let given = [
                ("--photons", self.photons.is_some()),
                ("--photon-nearest", self.photon_nearest.is_some()),
                ("--photon-radius", self.photon_radius.is_some()),
            ];
            if let Some((option, _)) = given.iter().find(|g| g.1) {
                return Err(Failure::input(format!(
                    "{option} sets the photon map: add --integrator photon (or `integrator = \"photon\"` in the scene's [render])"
                )));
            }
            return Ok(());
        }
        alhazen_photon::check(scene).map_err(|e| Failure::input(e.to_string()))
    }

    /// Bytes the map may take: every photon stored once, and its copy while the tree is built.
    pub(crate) fn memory_estimate(&self) -> u64 {
        self.settings(0).photons as u64 * alhazen_photon::PHOTON_BYTES * 2
    }
}

/// The world and its caustic map, made with a progress bar.
pub(crate) fn build(scene: &Scene, world: &World, args: &PhotonArgs, quiet: bool) -> Result<CausticMap, Failure> {
    let bar = if quiet { ProgressBar::hidden() } else { ProgressBar::new(1) };
    bar.set_style(
        ProgressStyle::with_template("{spinner} photons [{bar:40}] {percent:>3}% elapsed {elapsed} eta {eta}")
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    let map = CausticMap::build(scene, world, &args.settings(scene.render.seed), &|done, total| {
        bar.set_length(total as u64);
        bar.set_position(done as u64);
    })
    .map_err(|e| Failure::input(e.to_string()))?;
    bar.finish_and_clear();
    if map.photons().is_empty() && !quiet {
        eprintln!(
            "note: no photon reached a diffuse surface through a mirror or glass (no specular objects, or no light that shoots photons: the sky does not): the image is the path tracer's"
        );
    }
    Ok(map)
}
