//! Shards of a render (`candela render --shard I/N`): which shard a process renders, from the
//! command line or a cluster's array-job variables, and what a set of shard states holds when
//! they are merged.
//!
//! Shard I of N (0-based) renders samples I·S … (I+1)·S − 1 of every pixel's sample sequence,
//! S being the samples per pixel it is asked for, so the N shards together take exactly the
//! samples of one render at N·S samples per pixel, each exactly once.

use super::invalid_option;
use crate::meter::MeterSums;
use crate::state::{RenderState, ShardInfo, MAX_SHARDS};
use anyhow::{bail, Context, Result};
use std::path::{Path, PathBuf};

/// What the shards of a merged render were: written to OUT.report.json and printed.
#[derive(Clone, Debug, serde::Serialize)]
pub struct ShardSummary {
    /// Shards of the render (N).
    pub count: u32,
    /// Samples per pixel of each finished shard.
    pub spp_per_shard: u32,
    /// Indices (0-based) of the shards merged.
    pub merged: Vec<u32>,
    /// Indices of the shards not given.
    pub missing: Vec<u32>,
    /// Indices of the merged shards that had not finished (a checkpoint).
    pub unfinished: Vec<u32>,
    /// Whether the estimate lacks samples of the render (missing or unfinished shards).
    pub partial: bool,
    /// Indices of the merged shards that measured their share of the meters and grid points
    /// (finished shards): the merged meters hold their samples.
    pub meter_shards: Vec<u32>,
}

/// A shard of a render: `index` of `count`, 0-based.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    pub index: u32,
    pub count: u32,
}

/// Index of each shard's first caustic light path in the light-path stream: far apart, so the
/// shards' light paths never overlap (a shard traces far fewer than 2⁴⁰).
pub const LIGHT_PATHS_PER_SHARD: u64 = 1 << 40;

impl Shard {
    /// The state file's record of this shard at `spp` samples per pixel.
    pub fn info(&self, spp: u32) -> ShardInfo {
        ShardInfo {
            index: self.index,
            count: self.count,
            spp,
        }
    }
    /// The suffix of the shard's output names: `.shard-I-of-N` (NAME.shard-2-of-8.state, …).
    pub fn suffix(&self) -> String {
        format!(".shard-{}-of-{}", self.index, self.count)
    }
}

/// The array-job variables read by `--shard auto`, in the order they are looked for.
pub const SLURM_ID: &str = "SLURM_ARRAY_TASK_ID";
pub const SLURM_MIN: &str = "SLURM_ARRAY_TASK_MIN";
pub const SLURM_MAX: &str = "SLURM_ARRAY_TASK_MAX";
pub const SLURM_COUNT: &str = "SLURM_ARRAY_TASK_COUNT";
pub const AWS_INDEX: &str = "AWS_BATCH_JOB_ARRAY_INDEX";
pub const K8S_INDEX: &str = "JOB_COMPLETION_INDEX";

/// A whole number of at most `max` from `text`, or an error naming `what`.
fn number(text: &str, what: &str, max: u64) -> Result<u64> {
    let t = text.trim();
    let v: u64 = t.parse().map_err(|_| {
        invalid_option(format!(
            "{what} must be a whole number, got {:?}",
            crate::limits::printable(text, 40)
        ))
    })?;
    if v > max {
        return Err(invalid_option(format!(
            "{what} is {v}, more than the limit of {max}"
        )));
    }
    Ok(v)
}

/// The shard of `spec` (the value of `--shard`), reading array-job variables through `env`:
///
/// - `I/N`: shard I of N, I from 0 to N − 1;
/// - `auto`: a Slurm array task: I = `SLURM_ARRAY_TASK_ID` − `SLURM_ARRAY_TASK_MIN`,
///   N = `SLURM_ARRAY_TASK_COUNT` (an array of step 1, e.g. `--array=0-7` or `--array=1-8`);
/// - `auto/N`: N shards, I from the first variable set among `SLURM_ARRAY_TASK_ID` (less
///   `SLURM_ARRAY_TASK_MIN`), `AWS_BATCH_JOB_ARRAY_INDEX` (AWS Batch array jobs) and
///   `JOB_COMPLETION_INDEX` (Kubernetes indexed jobs).
///
/// Errors name the option or the variable at fault.
pub fn parse(spec: &str, env: &dyn Fn(&str) -> Option<String>) -> Result<Shard> {
    let max = MAX_SHARDS as u64;
    let (i_text, n_text) = match spec.split_once('/') {
        Some((i, n)) => (i.trim(), Some(n)),
        None => (spec.trim(), None),
    };
    let count = |n: u64, what: &str| -> Result<u32> {
        if n == 0 {
            return Err(invalid_option(format!(
                "{what} is 0: a render needs at least 1 shard"
            )));
        }
        Ok(n as u32)
    };
    let shard = if i_text == "auto" {
        let given = n_text
            .map(|n| number(n, "the shard count N of --shard auto/N", max))
            .transpose()?;
        let slurm = env(SLURM_ID);
        let (index, what) = if let Some(id) = slurm {
            let id = number(&id, SLURM_ID, u32::MAX as u64)?;
            let min = match env(SLURM_MIN) {
                Some(m) => number(&m, SLURM_MIN, u32::MAX as u64)?,
                None => 0,
            };
            if id < min {
                return Err(invalid_option(format!(
                    "{SLURM_ID} {id} is below {SLURM_MIN} {min}"
                )));
            }
            let slurm_count = env(SLURM_COUNT)
                .map(|c| number(&c, SLURM_COUNT, max))
                .transpose()?;
            if let (Some(c), Some(m)) = (slurm_count, env(SLURM_MAX)) {
                let m = number(&m, SLURM_MAX, u32::MAX as u64)?;
                if m < min || m - min + 1 != c {
                    return Err(invalid_option(format!(
                        "the Slurm array runs tasks {min} to {m} but {SLURM_ARRAY_TASK_COUNT} is {c}: --shard auto needs an array of consecutive task ids (e.g. --array=0-7, no step or list)",
                        SLURM_ARRAY_TASK_COUNT = SLURM_COUNT
                    )));
                }
            }
            match (given, slurm_count) {
                (Some(n), Some(c)) if n != c => {
                    return Err(invalid_option(format!(
                        "--shard auto/{n} gives {n} shards but the Slurm array has {c} tasks ({SLURM_COUNT})"
                    )))
                }
                (None, None) => {
                    return Err(invalid_option(format!(
                        "--shard auto: {SLURM_ID} is set but {SLURM_COUNT} is not; give the shard count as --shard auto/N"
                    )))
                }
                _ => {}
            }
            let n = given.or(slurm_count).expect("checked above");
            (
                (id - min, count(n, SLURM_COUNT)?),
                format!("{SLURM_ID} {id} − {SLURM_MIN} {min}"),
            )
        } else {
            let Some(n) = given else {
                return Err(invalid_option(format!(
                    "--shard auto takes the shard and the shard count from a Slurm array job ({SLURM_ID}, {SLURM_COUNT}), which is not set here; elsewhere give --shard auto/N (index from {AWS_INDEX} or {K8S_INDEX}) or --shard I/N"
                )));
            };
            let n = count(n, "the shard count N of --shard auto/N")?;
            let Some((var, v)) = [AWS_INDEX, K8S_INDEX]
                .into_iter()
                .find_map(|var| env(var).map(|v| (var, v)))
            else {
                return Err(invalid_option(format!(
                    "--shard auto/{n}: none of {SLURM_ID}, {AWS_INDEX} or {K8S_INDEX} is set, so the shard index is unknown; give --shard I/{n}"
                )));
            };
            let i = number(&v, var, u32::MAX as u64)?;
            ((i, n), var.to_string())
        };
        let (i, n) = index;
        if i >= n as u64 {
            return Err(invalid_option(format!(
                "--shard auto: the shard index from {what} is {i}, but there are only {n} shards (0 to {})",
                n - 1
            )));
        }
        Shard {
            index: i as u32,
            count: n,
        }
    } else {
        let Some(n_text) = n_text else {
            return Err(invalid_option(format!(
                "--shard takes I/N (shard I of N, 0-based), auto or auto/N, got {:?}",
                crate::limits::printable(spec, 40)
            )));
        };
        let i = number(i_text, "the shard index I of --shard I/N", u32::MAX as u64)?;
        let n = number(n_text, "the shard count N of --shard I/N", max)?;
        let n = count(n, "the shard count N of --shard I/N")?;
        if i >= n as u64 {
            return Err(invalid_option(format!(
                "--shard {i}/{n}: shards are numbered from 0 to {} (0-based)",
                n - 1
            )));
        }
        Shard {
            index: i as u32,
            count: n,
        }
    };
    Ok(shard)
}

/// [`parse`] with the process's environment.
pub fn parse_from_env(spec: &str) -> Result<Shard> {
    parse(spec, &|name| std::env::var(name).ok())
}

/// The per-pixel samples a shard's film holds (pixels outside a fisheye's circle hold none).
fn shard_samples(st: &RenderState) -> u64 {
    st.film.pixels.iter().map(|p| p.count).max().unwrap_or(0)
}

/// If the states are shards, checks that they are shards of one render, sorts them by index
/// and says which are missing or unfinished (an error unless `partial`); None if none is a
/// shard. A mix of shards and other states is refused.
pub fn order(
    loaded: &mut [(&PathBuf, RenderState)],
    partial: bool,
) -> Result<Option<ShardSummary>> {
    let Some(k) = loaded.iter().position(|(_, s)| s.shard.is_some()) else {
        return Ok(None);
    };
    if let Some((p, _)) = loaded.iter().find(|(_, s)| s.shard.is_none()) {
        bail!(
            "{} is a shard of a render (render --shard) and {} is not: merge the shards of a render on their own, then merge the result with other renders",
            loaded[k].0.display(),
            p.display()
        );
    }
    let info = |s: &RenderState| s.shard.expect("all are shards");
    let (p0, first) = (&loaded[k].0, &loaded[k].1);
    let i0 = info(first);
    for (p, s) in loaded.iter() {
        let i = info(s);
        let differs = if s.scene_hash != first.scene_hash
            || s.max_depth != first.max_depth
            || s.illuminance != first.illuminance
            || (s.film.width, s.film.height) != (first.film.width, first.film.height)
        {
            Some("renders of different scenes or settings (the scene file, a file it refers to, its resolution, max depth, illuminance or caustics differ)".to_string())
        } else if s.seed != first.seed {
            Some(format!(
                "rendered with different seeds ({} and {})",
                first.seed, s.seed
            ))
        } else if i.count != i0.count {
            Some(format!(
                "shards of renders split in {} and {} shards",
                i0.count, i.count
            ))
        } else if i.spp != i0.spp {
            Some(format!(
                "shards of {} and {} samples per pixel, so their sample ranges overlap",
                i0.spp, i.spp
            ))
        } else {
            None
        };
        if let Some(d) = differs {
            bail!(
                "{} and {} cannot be merged: they are {d}",
                p0.display(),
                p.display()
            );
        }
    }
    loaded.sort_by_key(|(_, s)| info(s).index);
    for w in loaded.windows(2) {
        if info(&w[0].1).index == info(&w[1].1).index {
            bail!(
                "shard {} of {} is given twice ({} and {}): its samples would count twice",
                info(&w[0].1).index,
                i0.count,
                w[0].0.display(),
                w[1].0.display()
            );
        }
    }
    let (n, spp) = (i0.count, i0.spp);
    let present: Vec<u32> = loaded.iter().map(|(_, s)| info(s).index).collect();
    let missing: Vec<u32> = (0..n)
        .filter(|i| present.binary_search(i).is_err())
        .collect();
    let mut unfinished = Vec::new();
    for (p, s) in loaded.iter() {
        let c = shard_samples(s);
        if c > spp as u64 {
            bail!(
                "{} is corrupt: it holds {c} samples per pixel, more than the {spp} of its shard",
                p.display()
            );
        }
        if c < spp as u64 {
            unfinished.push((info(s).index, c, p.display().to_string()));
        }
    }
    let list = |v: &[u32]| {
        v.iter()
            .map(|i| i.to_string())
            .collect::<Vec<_>>()
            .join(", ")
    };
    let complete = missing.is_empty() && unfinished.is_empty();
    if !partial && !complete {
        let mut why = Vec::new();
        if !missing.is_empty() {
            why.push(format!(
                "{} of the {n} shards {} missing: {} (0-based; their states are NAME.shard-I-of-{n}.state)",
                missing.len(),
                if missing.len() == 1 { "is" } else { "are" },
                list(&missing)
            ));
        }
        for (i, c, p) in &unfinished {
            why.push(format!(
                "shard {i} ({p}) is unfinished: {c} of its {spp} samples per pixel (rerun its command to finish it)"
            ));
        }
        bail!(
            "{}; merge the shards present with --partial for the estimate of the samples they hold",
            why.join("; ")
        );
    }
    // Shard I's pixel batches continue the sequences from sample I·spp: merged after
    // acc samples, its batch b lands in batch (b + acc) mod 16, which must be the batch its
    // samples' sequences feed in every other shard, (b + I·spp) mod 16.
    let k = crate::film::PIXEL_BATCHES as u64;
    let mut acc = 0u64;
    for (p, s) in loaded.iter() {
        let i = info(s).index as u64;
        if acc % k != (i * spp as u64) % k {
            bail!(
                "cannot give a partial estimate from these shards: with {spp} samples per pixel per shard (not a multiple of {k}) and the shards before {} missing or unfinished, its pixel batches would mix with the others' and the standard errors would be wrong; render the missing shards, or shard with a multiple of {k} samples per pixel",
                p.display()
            );
        }
        acc += shard_samples(s);
    }
    let meter_shards = loaded
        .iter()
        .filter(|(_, s)| !s.meters.is_empty())
        .map(|(_, s)| info(s).index)
        .collect();
    Ok(Some(ShardSummary {
        count: n,
        spp_per_shard: spp,
        merged: present,
        missing,
        partial: !(unfinished.is_empty() && loaded.len() == n as usize),
        unfinished: unfinished.into_iter().map(|(i, _, _)| i).collect(),
        meter_shards,
    }))
}

/// The meter and grid-point sums of the shards that measured them, added in the order given
/// (that of the shard index).
pub fn merge_meters(loaded: &[(&PathBuf, RenderState)]) -> Result<Vec<MeterSums>> {
    let mut with = loaded.iter().filter(|(_, s)| !s.meters.is_empty());
    let Some((p0, first)) = with.next() else {
        return Ok(Vec::new());
    };
    let mut merged = first.meters.clone();
    for (p, s) in with {
        let same = s.meters.len() == merged.len()
            && s.meters.iter().zip(&first.meters).all(|(a, b)| {
                a.name == b.name
                    && a.grid == b.grid
                    && a.luminance == b.luminance
                    && a.per_batch == b.per_batch
            });
        if !same {
            bail!(
                "{} and {} hold different meters or grid points (or shares of them) and cannot be merged",
                p0.display(),
                p.display()
            );
        }
        for (a, b) in merged.iter_mut().zip(&s.meters) {
            a.merge(b);
        }
    }
    Ok(merged)
}

/// One meter's estimate as JSON, in its SI unit.
fn estimate_json(e: &crate::meter::Estimate) -> serde_json::Value {
    serde_json::json!({
        "mean": e.mean,
        "stderr": e.stderr,
        "ci95_half_width": e.ci95(),
        "samples": e.samples,
        "non_finite_samples": e.non_finite,
    })
}

/// OUT.report.json of a merge of shards: which shards the estimate holds and whether it is
/// partial, the image's samples and mean luminance, and the merged meters and grids (SI units:
/// lx, cd/m²).
pub fn write_report(
    path: &Path,
    summary: &ShardSummary,
    merged: &RenderState,
    meters: &[MeterSums],
) -> Result<()> {
    let mut meter_json = Vec::new();
    let mut grids: Vec<(String, u32, u32, Vec<crate::meter::Estimate>)> = Vec::new();
    for m in meters {
        let e = m.estimate();
        match m.grid {
            None => {
                let mut v = estimate_json(&e);
                v["name"] = m.name.clone().into();
                v["unit"] = if m.luminance { "cd/m²" } else { "lx" }.into();
                meter_json.push(v);
            }
            Some([i, j, nx, ny]) => {
                if i == 0 && j == 0 {
                    grids.push((m.name.clone(), nx, ny, Vec::new()));
                }
                if let Some(g) = grids.last_mut() {
                    g.3.push(e);
                }
            }
        }
    }
    let grid_json: Vec<serde_json::Value> = grids
        .iter()
        .map(|(name, nx, ny, points)| {
            let s = crate::meter::grid_stats(points);
            serde_json::json!({
                "name": name,
                "nx": nx,
                "ny": ny,
                "e_min_lx": s.min,
                "e_avg_lx": s.avg,
                "e_max_lx": s.max,
                "u0": s.u0,
                "max_stderr_lx": s.max_stderr,
                "points_lx": points.iter().map(|e| e.mean).collect::<Vec<_>>(),
                "points_stderr_lx": points.iter().map(|e| e.stderr).collect::<Vec<_>>(),
            })
        })
        .collect();
    let report = serde_json::json!({
        "scene": merged.scene,
        "seed": merged.seed,
        "shards": summary,
        "image": {
            "width": merged.film.width,
            "height": merged.film.height,
            "samples_per_pixel": merged.film.samples_per_pixel(),
            "mean_luminance_cd_m2": merged.film.mean_luminance_cd_m2(),
        },
        "meters": meter_json,
        "grids": grid_json,
    });
    crate::report::json::write_text(path, &serde_json::to_string_pretty(&report)?)
        .with_context(|| format!("cannot write {}", path.display()))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn with(vars: &[(&str, &str)], spec: &str) -> Result<Shard, String> {
        let vars: Vec<(String, String)> = vars
            .iter()
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect();
        parse(spec, &|name| {
            vars.iter().find(|(k, _)| k == name).map(|(_, v)| v.clone())
        })
        .map_err(|e| e.to_string())
    }

    fn shard(index: u32, count: u32) -> Result<Shard, String> {
        Ok(Shard { index, count })
    }

    #[test]
    fn explicit_shards() {
        assert_eq!(with(&[], "0/4"), shard(0, 4));
        assert_eq!(with(&[], "3/4"), shard(3, 4));
        assert_eq!(with(&[], " 2 / 5 "), shard(2, 5));
        for (spec, part) in [
            ("4/4", "numbered from 0 to 3"),
            ("0/0", "is 0"),
            ("x/4", "shard index I"),
            ("1/y", "shard count N"),
            ("-1/4", "shard index I"),
            ("3", "takes I/N"),
            ("1/99999999", "more than the limit"),
        ] {
            let e = with(&[], spec).unwrap_err();
            assert!(e.contains(part), "{spec}: {e}");
        }
    }

    #[test]
    fn slurm_arrays_from_any_first_id() {
        let zero = [
            (SLURM_ID, "2"),
            (SLURM_MIN, "0"),
            (SLURM_MAX, "3"),
            (SLURM_COUNT, "4"),
        ];
        assert_eq!(with(&zero, "auto"), shard(2, 4));
        assert_eq!(with(&zero, "auto/4"), shard(2, 4));
        let one = [
            (SLURM_ID, "4"),
            (SLURM_MIN, "1"),
            (SLURM_MAX, "4"),
            (SLURM_COUNT, "4"),
        ];
        assert_eq!(with(&one, "auto"), shard(3, 4));
        let e = with(&zero, "auto/5").unwrap_err();
        assert!(e.contains("4 tasks"), "{e}");
        let step = [
            (SLURM_ID, "2"),
            (SLURM_MIN, "0"),
            (SLURM_MAX, "6"),
            (SLURM_COUNT, "4"),
        ];
        let e = with(&step, "auto").unwrap_err();
        assert!(e.contains("consecutive"), "{e}");
        let e = with(&[(SLURM_ID, "1x"), (SLURM_COUNT, "4")], "auto").unwrap_err();
        assert!(e.contains(SLURM_ID) && e.contains("whole number"), "{e}");
        let e = with(&[(SLURM_ID, "5"), (SLURM_COUNT, "4")], "auto").unwrap_err();
        assert!(e.contains("only 4 shards"), "{e}");
        let e = with(&[(SLURM_ID, "1"), (SLURM_COUNT, "")], "auto").unwrap_err();
        assert!(e.contains(SLURM_COUNT), "{e}");
        let e = with(&[(SLURM_ID, "1")], "auto").unwrap_err();
        assert!(e.contains("auto/N"), "{e}");
        assert_eq!(with(&[(SLURM_ID, "1")], "auto/3"), shard(1, 3));
    }

    #[test]
    fn aws_batch_and_kubernetes_indices() {
        assert_eq!(with(&[(AWS_INDEX, "7")], "auto/8"), shard(7, 8));
        assert_eq!(with(&[(K8S_INDEX, "0")], "auto/2"), shard(0, 2));
        let e = with(&[(AWS_INDEX, "8")], "auto/8").unwrap_err();
        assert!(e.contains(AWS_INDEX) && e.contains("only 8 shards"), "{e}");
        let e = with(&[(K8S_INDEX, "garbage")], "auto/8").unwrap_err();
        assert!(e.contains(K8S_INDEX), "{e}");
        let e = with(&[(AWS_INDEX, "1")], "auto").unwrap_err();
        assert!(e.contains("auto/N"), "{e}");
        let e = with(&[], "auto/4").unwrap_err();
        assert!(e.contains("none of"), "{e}");
        let e = with(&[(AWS_INDEX, "1")], "auto/0").unwrap_err();
        assert!(e.contains("is 0"), "{e}");
    }
}
