//! Render state files (`NAME.state`): per-pixel sums, sums of squares and sample counts (both
//! buffers in adaptive mode), the scene's hash and the settings that determine the random
//! sequence, so a render can be resumed exactly or merged with independent renders.
//!
//! Binary, little-endian [postcard](https://docs.rs/postcard) encoding of [`RenderState`];
//! written atomically.

use crate::film::Film;
use crate::output::write_atomic;
use crate::sampling::mix64;
use crate::world::World;
use serde::{Deserialize, Serialize};
use std::path::Path;

pub const MAGIC: &str = "candela-render-state";
pub const VERSION: u32 = 3;

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RenderState {
    pub magic: String,
    pub version: u32,
    /// Hash of the scene file's bytes and the settings that change the estimator.
    pub scene_hash: u64,
    pub scene: String,
    pub seed: u64,
    pub max_depth: u32,
    pub illuminance: bool,
    pub film: Film,
    /// The other seeds a merged state contains (`candela merge`; empty for one render), so a
    /// later merge can refuse a seed that is already in it.
    pub merged_seeds: Vec<u64>,
}

/// The leading fields of every version, read first so an old file gets a clear message.
#[derive(Deserialize)]
struct Header {
    magic: String,
    version: u32,
}

/// Hash of the scene text, the contents of every file it refers to ([`World::sources`]) and the
/// estimator's settings (seed excluded: merging combines seeds). A referenced file that can no
/// longer be read hashes as its path alone, so the state then no longer matches.
pub fn scene_hash(scene_text: &[u8], world: &World) -> u64 {
    let eat = |h: &mut u64, bytes: &[u8]| {
        for chunk in bytes.chunks(8) {
            let mut b = [0u8; 8];
            b[..chunk.len()].copy_from_slice(chunk);
            *h = mix64(*h ^ u64::from_le_bytes(b));
        }
    };
    let mut h = 0x0063_616e_6465_6c61_u64;
    eat(&mut h, scene_text);
    // (A scene without referenced files hashes as before they were included.)
    for source in &world.sources {
        eat(&mut h, source.to_string_lossy().as_bytes());
        match std::fs::read(source) {
            Ok(bytes) => {
                eat(&mut h, &bytes);
                h = mix64(h ^ bytes.len() as u64);
            }
            Err(_) => h = mix64(h ^ 0xdead),
        }
    }
    h = mix64(h ^ world.settings.max_depth as u64);
    h = mix64(h ^ world.settings.rr_depth as u64);
    h = mix64(h ^ world.settings.illuminance as u64);
    h = mix64(h ^ world.caustics.is_some() as u64);
    h = mix64(h ^ world.settings.light_paths_per_sample.to_bits() as u64);
    mix64(h ^ ((world.camera.width as u64) << 32 | world.camera.height as u64))
}

impl RenderState {
    pub fn new(scene: &Path, scene_hash: u64, world: &World, film: Film) -> Self {
        Self {
            magic: MAGIC.into(),
            version: VERSION,
            scene_hash,
            scene: scene.display().to_string(),
            seed: world.settings.seed,
            max_depth: world.settings.max_depth,
            illuminance: world.settings.illuminance,
            film,
            merged_seeds: Vec::new(),
        }
    }

    /// Every seed whose samples this state holds.
    pub fn seeds(&self) -> Vec<u64> {
        std::iter::once(self.seed)
            .chain(self.merged_seeds.iter().copied())
            .collect()
    }

    pub fn save(&self, path: &Path) -> anyhow::Result<()> {
        let bytes = postcard::to_stdvec(self)?;
        write_atomic(path, |w| w.write_all(&bytes))?;
        Ok(())
    }

    pub fn load(path: &Path) -> anyhow::Result<Self> {
        let bytes = std::fs::read(path)
            .map_err(|e| anyhow::anyhow!("cannot read state file {}: {e}", path.display()))?;
        if let Ok((h, _)) = postcard::take_from_bytes::<Header>(&bytes) {
            anyhow::ensure!(
                h.magic != MAGIC || h.version == VERSION,
                "{} is a candela render state of format version {}; this candela reads version {VERSION} (finish or merge it with the candela that wrote it, or render again)",
                path.display(),
                h.version
            );
        }
        let s: RenderState = postcard::from_bytes(&bytes).map_err(|e| {
            anyhow::anyhow!(
                "{} is not a candela render state (or is corrupt or truncated): {e}",
                path.display()
            )
        })?;
        anyhow::ensure!(
            s.magic == MAGIC && s.version == VERSION,
            "{} is not a candela render state of version {VERSION}",
            path.display()
        );
        // checked: a corrupt size must not wrap to the length of the arrays.
        let n = s.film.width.checked_mul(s.film.height).unwrap_or(0);
        anyhow::ensure!(
            n > 0
                && s.film.pixels.len() == n
                && s.film.decision.as_ref().is_none_or(|d| d.len() == n),
            "{} is corrupt: its pixel arrays do not match its {}×{} size",
            path.display(),
            s.film.width,
            s.film.height
        );
        Ok(s)
    }
}
