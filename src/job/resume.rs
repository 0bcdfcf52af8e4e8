//! The film a job renders into: a new one, or the one of NAME.state it continues, refused
//! when the scene, its settings, the shard or the kept channels changed since.

use super::RenderJob;
use crate::film::Film;
use crate::state::RenderState;
use crate::world::World;
use anyhow::{bail, Result};
use std::path::Path;

/// The film to render into: [`initial_film`] (continued from `state_path` when `resuming`),
/// with the light-and-health channels the job asks for when the film has none yet.
pub(super) fn start_film(
    job: &RenderJob,
    world: &World,
    hash: u64,
    shard: Option<crate::state::ShardInfo>,
    resuming: bool,
    state_path: &Path,
) -> Result<Film> {
    let resume_job = RenderJob {
        resume: resuming,
        ..job.clone()
    };
    let mut film = initial_film(&resume_job, world, hash, shard, state_path)?;
    let (w, h) = (world.camera.width, world.camera.height);
    if job.health.any() && film.health.is_none() {
        let h = crate::film::HealthFilm::new(job.health, world.settings.illuminance, w * h)
            .map_err(anyhow::Error::msg)?;
        film.health = Some(h);
    }
    Ok(film)
}

/// The film to continue: from NAME.state with `resume` (refused if the scene, its settings or
/// the adaptive mode changed), else a new one.
fn initial_film(
    job: &RenderJob,
    world: &World,
    hash: u64,
    shard: Option<crate::state::ShardInfo>,
    state_path: &Path,
) -> Result<Film> {
    let (w, h) = (world.camera.width, world.camera.height);
    if !job.resume {
        let mut film = if job.target.is_some() {
            Film::new_adaptive(w, h)
        } else {
            Film::new(w, h)
        };
        film.pixel_batches = world.settings.pixel_batches;
        return Ok(film);
    }
    let st = RenderState::load(state_path)?;

    if st.scene_hash != hash || st.seed != world.settings.seed {
        bail!(
            "cannot resume from {}: the scene file {}, a file it refers to (mesh, spectrum, luminaire data) or its settings (seed, max depth, resolution, illuminance, caustics) changed since the state was written",
            state_path.display(),
            job.scene.display()
        );
    }
    if st.shard != shard {
        let what = |s: Option<crate::state::ShardInfo>| match s {
            Some(s) => format!(
                "shard {} of {} at {} samples per pixel",
                s.index, s.count, s.spp
            ),
            None => "a whole render (no --shard)".to_string(),
        };
        bail!(
            "cannot resume from {}: it holds {}, but this run asks for {}; rerun it as it was started, or start it again with --overwrite",
            state_path.display(),
            what(st.shard),
            what(shard)
        );
    }
    if (st.film.width, st.film.height) != (w, h) {
        bail!(
            "{} is corrupt: its film is {}×{} but the scene it was rendered from (whose hash it carries) renders {w}×{h}",
            state_path.display(),
            st.film.width,
            st.film.height
        );
    }
    if st.film.decision.is_some() != job.target.is_some() {
        bail!(
            "cannot resume from {}: it was {} a --target-error; resume it the same way",
            state_path.display(),
            if st.film.decision.is_some() {
                "rendered with"
            } else {
                "rendered without"
            }
        );
    }
    let kept = st
        .film
        .health
        .as_ref()
        .map(|h| h.channels)
        .unwrap_or_default();
    if kept != job.health {
        bail!(
            "cannot resume from {}: it keeps the light-and-health channels {kept:?}, but this run asks for {:?}; resume it with the same --alpha-opic, --mesopic and --spectral-bands",
            state_path.display(),
            job.health
        );
    }
    Ok(st.film)
}
