//! Merging independent renders of one scene (different seeds) from their state files into one
//! estimate: the sums add, so the merged film is the render with all their samples. Shards of
//! one render (`render --shard`) are merged in the order of their index whatever the order they
//! are given in, so the merged sums, and every output, are the same bit for bit. Light-and-health
//! sums (`--alpha-opic`, `--mesopic`, `--spectral-bands`) merge with the film; inputs must keep
//! the same channels, and OUT.spectral.exr is written when they keep spectral bands.

use super::files::{check_exposure, check_output_dir, film_layers, output_stem, write_png};
use super::shard::ShardSummary;
use crate::output::{self, with_suffix};
use crate::state::RenderState;
use anyhow::{bail, Context, Result};
use std::collections::HashSet;
use std::path::{Path, PathBuf};

/// How to merge.
#[derive(Clone, Debug, Default)]
pub struct MergeOptions {
    /// Exposure of the PNG in EV (None: automatic).
    pub exposure_ev: Option<f64>,
    /// Merge the shards present even if some are missing or unfinished (the estimate of the
    /// samples they hold); without it such a merge is refused.
    pub partial: bool,
}

/// What a merge wrote.
#[derive(Clone, Debug)]
pub struct MergeOutputs {
    pub exr_path: PathBuf,
    pub png_path: PathBuf,
    /// OUT.hdr, written when an input state has its render's NAME.hdr beside it.
    pub hdr_path: Option<PathBuf>,
    /// The merged state (not written for a partial merge of shards).
    pub state_path: PathBuf,
    /// Number of state files merged.
    pub renders: usize,
    /// Every seed in the merged estimate.
    pub seeds: Vec<u64>,
    /// Image samples per pixel of the merged film.
    pub samples_per_pixel: f64,
    /// For shards: which were merged, and OUT.report.json with the merged meters.
    pub shards: Option<ShardSummary>,
    pub report_path: Option<PathBuf>,
    /// The merged meters' and grid points' sums (shards that measured them).
    pub meters: Vec<crate::meter::MeterSums>,
}

/// The light-and-health channels a film keeps (none: the default).
fn health(film: &crate::film::Film) -> crate::film::HealthChannels {
    film.health.as_ref().map(|h| h.channels).unwrap_or_default()
}

/// Merges `states` into OUT.exr, OUT.png, OUT.state and, when an input's render wrote a
/// Radiance picture beside its state, OUT.hdr (`out` names a stem, or an existing
/// directory for `DIR/merged.*`); refuses to overwrite an input, to mix scenes or settings,
/// and to count a seed twice. `exposure_ev` sets the PNG's exposure (None: automatic).
pub fn merge(states: &[PathBuf], out: &Path, exposure_ev: Option<f64>) -> Result<MergeOutputs> {
    merge_with(
        states,
        out,
        &MergeOptions {
            exposure_ev,
            partial: false,
        },
    )
}

/// [`merge`] with options. Shards of one render (see [`super::shard`]) are checked to be of
/// the same render (scene, settings, seed, shard count, samples per shard), taken in the order
/// of their index, and the missing or unfinished ones named (refused unless
/// `options.partial`); OUT.report.json then says which shards the estimate holds and gives the
/// merged meters and grid points.
pub fn merge_with(states: &[PathBuf], out: &Path, options: &MergeOptions) -> Result<MergeOutputs> {
    check_exposure(options.exposure_ev)?;
    let paths = MergePaths::new(states, out)?;
    let (loaded, shards) = load_states(states, options.partial)?;
    let first = &loaded[0].1;
    let (film, seeds) = merge_films(&loaded, shards.is_some())?;
    let meters = match &shards {
        Some(_) => super::shard::merge_meters(&loaded)?,
        _ => Vec::new(),
    };
    let mut layers = merged_layers(first, &film, &seeds, shards.as_ref());
    let view = find_view(&loaded, &film);
    if let Some(v) = &view {
        add_view(&mut layers, v);
    }
    // Every output is attempted whether or not an earlier one failed (on a nearly full disk
    // the small ones still get written); the error lists each that failed.
    let mut writes = super::Writes::default();
    let hdr_path = paths.write_images(&film, &layers, view.as_ref(), first, options, &mut writes);
    let merged = RenderState {
        seed: seeds[0],
        merged_seeds: seeds[1..].to_vec(),
        film,
        shard: None,
        meters: Vec::new(),
        ..first.clone()
    };
    let report_path = match &shards {
        Some(s) => {
            let path = with_suffix(&paths.stem, ".report.json");
            writes.attempt(&path, || {
                super::shard::write_report(&path, s, &merged, &meters)
            });
            Some(path)
        }
        None => None,
    };
    // A partial estimate's state would resume past samples of shards it lacks and repeat
    // them: it gets none (merge the shards again once they are all done).
    if !shards.as_ref().is_some_and(|s| s.partial) {
        writes.attempt(&paths.state, || {
            merged
                .save(&paths.state)
                .context("cannot write the merged state")
        });
    }
    writes.finish()?;
    Ok(MergeOutputs {
        exr_path: paths.exr,
        png_path: paths.png,
        hdr_path,
        state_path: paths.state,
        renders: loaded.len(),
        samples_per_pixel: merged.film.samples_per_pixel(),
        seeds,
        shards,
        report_path,
        meters,
    })
}

/// The files of a merge, named after its output stem.
struct MergePaths {
    stem: PathBuf,
    exr: PathBuf,
    png: PathBuf,
    hdr: PathBuf,
    state: PathBuf,
}

impl MergePaths {
    /// The merge's file names; refuses an output directory that does not exist and an output
    /// that would replace an input.
    fn new(states: &[PathBuf], out: &Path) -> Result<Self> {
        // Like `render --out`, a directory gets files named `merged.*`.
        let stem = output_stem(Some(out), "merged", &["exr", "hdr", "png", "state"]);
        let paths = MergePaths {
            exr: with_suffix(&stem, ".exr"),
            png: with_suffix(&stem, ".png"),
            hdr: with_suffix(&stem, ".hdr"),
            state: with_suffix(&stem, ".state"),
            stem,
        };
        check_output_dir(&paths.stem).with_context(|| format!("-o {}", out.display()))?;
        for output in [&paths.exr, &paths.png, &paths.hdr, &paths.state] {
            if let Some(input) = states.iter().find(|s| super::would_replace(output, s)) {
                bail!(
                    "-o {}: refusing to overwrite the input state file {} with the merged {}; choose another output name",
                    out.display(),
                    input.display(),
                    output.display()
                );
            }
        }
        Ok(paths)
    }

    /// OUT.exr, OUT.spectral.exr when the film keeps spectral bands, OUT.png, and OUT.hdr
    /// when an input's render wrote the `view` (its path then returned).
    fn write_images(
        &self,
        film: &crate::film::Film,
        layers: &output::Layers,
        view: Option<&output::HdrImage>,
        first: &RenderState,
        options: &MergeOptions,
        writes: &mut super::Writes,
    ) -> Option<PathBuf> {
        writes.attempt(&self.exr, || {
            output::write_exr(&self.exr, layers).context("cannot write the EXR")
        });
        if let Some(spectral) = crate::film::spectral_layers(film, &first.scene) {
            let path = with_suffix(&self.stem, ".spectral.exr");
            writes.attempt(&path, || {
                output::write_exr(&path, &spectral).context("cannot write the spectral EXR")
            });
        }
        writes.attempt(&self.png, || {
            write_png(film, &self.png, options.exposure_ev)
        });
        let v = view?;
        let extra: Vec<String> = v
            .projection
            .iter()
            .map(|p| format!("CANDELA_PROJECTION={p}"))
            .collect();
        writes.attempt(&self.hdr, || {
            output::write_hdr(
                &self.hdr,
                film.width,
                film.height,
                &film.xyz_image(),
                v.view.as_deref(),
                &extra,
            )
            .context("cannot write the HDR")
        });
        Some(self.hdr.clone())
    }
}

/// Loaded states, each with the file it came from.
type Loaded<'a> = Vec<(&'a PathBuf, RenderState)>;

/// The states to merge, loaded, in the order of their shard index when they are the shards
/// of one render (with which shards they are); refuses fewer than two states that are not
/// shards.
fn load_states(states: &[PathBuf], partial: bool) -> Result<(Loaded<'_>, Option<ShardSummary>)> {
    if states.is_empty() {
        bail!("nothing to merge: no state files given");
    }
    let mut loaded = Vec::new();
    for p in states {
        loaded.push((p, RenderState::load(p)?));
    }
    let shards = match super::shard::order(&mut loaded, partial)? {
        Some(s) => Some(s),
        None if loaded.len() < 2 => {
            bail!("nothing to merge: give two state files or more (or the shards of a render)")
        }
        None => None,
    };
    Ok((loaded, shards))
}

/// The sum of the states' films, in their order, and every seed it holds. Refuses states of
/// different scenes or settings, a seed counted twice (unless they are `shards` of one
/// render, which share its seed and take disjoint samples of its sequences), and a sum out of
/// range.
fn merge_films(
    loaded: &[(&PathBuf, RenderState)],
    shards: bool,
) -> Result<(crate::film::Film, Vec<u64>)> {
    let (p0, first) = &loaded[0];
    let mut film = first.film.clone();
    let mut seeds = first.seeds();
    let mut seen: HashSet<u64> = seeds.iter().copied().collect();
    for (p, s) in &loaded[1..] {
        if !same_render(first, s, &film) {
            bail!(
                "{} and {} are renders of different scenes or settings and cannot be merged",
                p0.display(),
                p.display()
            );
        }
        if shards {
            film.merge(&s.film);
            film.check(first.illuminance).map_err(|e| {
                anyhow::anyhow!(
                    "merging {}: the merged film is out of range: {e}",
                    p.display()
                )
            })?;
            continue;
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
    Ok((film, seeds))
}

/// Whether state `s` is of the render of `first` (scene, settings, the size, adaptive mode
/// and kept channels of `film`, the sum so far).
fn same_render(first: &RenderState, s: &RenderState, film: &crate::film::Film) -> bool {
    s.scene_hash == first.scene_hash
        && s.max_depth == first.max_depth
        && s.illuminance == first.illuminance
        && s.film.width == film.width
        && s.film.height == film.height
        && s.film.decision.is_some() == film.decision.is_some()
        && health(&s.film) == health(&first.film)
}

/// The EXR channels and attributes of the merged `film`, with the seeds and shards it holds.
fn merged_layers(
    first: &RenderState,
    film: &crate::film::Film,
    seeds: &[u64],
    shards: Option<&ShardSummary>,
) -> output::Layers {
    let mut layers = film_layers(&first.scene, film, first.illuminance);
    layers
        .attributes
        .push(("merged_seeds".to_string(), format!("{seeds:?}")));
    if let Some(s) = shards {
        layers.attributes.push((
            "merged_shards".to_string(),
            format!("{:?} of {}", s.merged, s.count),
        ));
    }
    layers
}

/// The camera is not in the state: its view comes from the Radiance picture a render writes
/// beside its state (NAME.hdr beside NAME.state), the first of the size of `film`.
fn find_view(
    loaded: &[(&PathBuf, RenderState)],
    film: &crate::film::Film,
) -> Option<output::HdrImage> {
    loaded
        .iter()
        .filter_map(|(p, _)| output::read_hdr(&p.with_extension("hdr")).ok())
        .find(|h| h.width == film.width && h.height == film.height)
}

/// The view's VIEW= and projection lines, which the merged picture and EXR repeat.
fn add_view(layers: &mut output::Layers, v: &output::HdrImage) {
    for (key, value) in [
        (output::ATTRIBUTE_PROJECTION, &v.projection),
        (output::ATTRIBUTE_VIEW, &v.view),
    ] {
        if let Some(value) = value {
            layers.attributes.push((key.to_string(), value.clone()));
        }
    }
}
