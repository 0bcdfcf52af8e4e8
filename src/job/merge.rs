//! Merging independent renders of one scene (different seeds) from their state files into one
//! estimate: the sums add, so the merged film is the render with all their samples.

use super::files::{check_exposure, check_output_dir, film_layers, output_stem, write_png};
use crate::output::{self, with_suffix};
use crate::state::RenderState;
use anyhow::{bail, Context, Result};
use std::collections::HashSet;
use std::path::{Path, PathBuf};

/// What a merge wrote.
#[derive(Clone, Debug)]
pub struct MergeOutputs {
    pub exr_path: PathBuf,
    pub png_path: PathBuf,
    pub state_path: PathBuf,
    /// Number of state files merged.
    pub renders: usize,
    /// Every seed in the merged estimate.
    pub seeds: Vec<u64>,
    /// Image samples per pixel of the merged film.
    pub samples_per_pixel: f64,
}

/// Merges `states` into OUT.exr, OUT.png and OUT.state (`out` names a stem, or an existing
/// directory for `DIR/merged.*`); refuses to overwrite an input, to mix scenes or settings,
/// and to count a seed twice. `exposure_ev` sets the PNG's exposure (None: automatic).
pub fn merge(states: &[PathBuf], out: &Path, exposure_ev: Option<f64>) -> Result<MergeOutputs> {
    check_exposure(exposure_ev)?;
    // Like `render --out`, a directory gets files named `merged.*`.
    let stem = output_stem(Some(out), "merged", &["exr", "png", "state"]);
    let exr_path = with_suffix(&stem, ".exr");
    let png_path = with_suffix(&stem, ".png");
    let state_path = with_suffix(&stem, ".state");
    check_output_dir(&stem).with_context(|| format!("-o {}", out.display()))?;
    for output in [&exr_path, &png_path, &state_path] {
        if let Some(input) = states.iter().find(|s| super::would_replace(output, s)) {
            bail!(
                "-o {}: refusing to overwrite the input state file {} with the merged {}; choose another output name",
                out.display(),
                input.display(),
                output.display()
            );
        }
    }
    if states.is_empty() {
        bail!("nothing to merge: no state files given");
    }
    let mut loaded = Vec::new();
    for p in states {
        loaded.push((p, RenderState::load(p)?));
    }
    let (p0, first) = &loaded[0];
    let mut film = first.film.clone();
    let mut seeds = first.seeds();
    let mut seen: HashSet<u64> = seeds.iter().copied().collect();
    for (p, s) in &loaded[1..] {
        if s.scene_hash != first.scene_hash
            || s.max_depth != first.max_depth
            || s.illuminance != first.illuminance
            || s.film.width != film.width
            || s.film.height != film.height
            || s.film.decision.is_some() != film.decision.is_some()
        {
            bail!(
                "{} and {} are renders of different scenes or settings and cannot be merged",
                p0.display(),
                p.display()
            );
        }
        if let Some(seed) = s.seeds().into_iter().find(|x| seen.contains(x)) {
            bail!(
                "{} repeats seed {seed} of another input (directly or inside a merged state): renders with the same seed take the same samples, so merging them would count those samples twice; render with different --seed values",
                p.display()
            );
        }
        seen.extend(s.seeds());
        seeds.extend(s.seeds());
        film.merge(&s.film);
        // Each input is within the limits, so this sum cannot overflow; the next one might.
        film.check(first.illuminance).map_err(|e| {
            anyhow::anyhow!(
                "merging {} with the inputs before it: the merged film is out of range: {e}",
                p.display()
            )
        })?;
    }
    if seeds.len() as u64 > crate::state::MAX_MERGED_SEEDS + 1 {
        bail!(
            "the merged state would hold {} seeds, more than the limit of {}",
            seeds.len(),
            crate::state::MAX_MERGED_SEEDS + 1
        );
    }
    let mut layers = film_layers(&first.scene, &film, first.illuminance);
    layers
        .attributes
        .push(("merged_seeds".to_string(), format!("{seeds:?}")));
    output::write_exr(&exr_path, &layers).context("cannot write the EXR")?;
    write_png(&film, &png_path, exposure_ev)?;
    let merged = RenderState {
        seed: seeds[0],
        merged_seeds: seeds[1..].to_vec(),
        film,
        ..first.clone()
    };
    merged
        .save(&state_path)
        .context("cannot write the merged state")?;
    Ok(MergeOutputs {
        exr_path,
        png_path,
        state_path,
        renders: loaded.len(),
        samples_per_pixel: merged.film.samples_per_pixel(),
        seeds,
    })
}
