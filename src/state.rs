//! Render state files (`NAME.state`): per-pixel sums, sums of squares, batch sums and sample
//! counts (both buffers in adaptive mode; illuminance sums when the render estimates it; the
//! light-and-health sums when the render keeps them), the scene's hash and the settings that determine the random
//! sequence, so a render can be resumed exactly or merged with independent renders.
//!
//! A file is the little-endian [postcard](https://docs.rs/postcard) encoding of [`RenderState`]
//! followed by the 8-byte little-endian [`checksum`] of those bytes; written atomically.
//! Reading checks, in this order, before a pixel is used: a regular file of at most
//! [`MAX_STATE_BYTES`]; the checksum (so a flipped bit, a truncation or an extension is refused);
//! the signature and format version; the sizes the file claims (film size, buffer lengths, seed
//! list) against the limits, the bytes present and the memory available, before anything is
//! allocated for them; then the values ([`Film::check`]).

use crate::film::{Film, HealthChannels, HealthFilm, IlluminanceSums, PixelSums};
use crate::meter::MeterSums;
use crate::output::write_atomic;
use crate::sampling::mix64;
use crate::scene::build::MAX_PIXELS;
use crate::world::World;
use serde::{Deserialize, Serialize};
use std::path::Path;

pub const MAGIC: &str = "candela-render-state";
/// Format version: 4 added the checksum, 12 the per-pixel batch sums with the illuminance sums
/// in buffers of their own (12 because no single flipped bit turns it into one of the
/// unchecked versions 1–3, see [`RenderState::decode`]), 13 the shard a state renders
/// ([`ShardInfo`]; no single flipped bit turns 13 into 1–3 either), 14 the light-and-health
/// sums (likewise), 15 the number of independent sample batches per pixel (likewise); other
/// versions are refused with a message.
pub const VERSION: u32 = 15;

/// Bytes of the checksum at the end of the file.
const CHECKSUM_BYTES: usize = 8;
/// Encoded size of one [`PixelSums`]: 8 f64 and 16 f64 of batch sums of 8 bytes, and 2 u64
/// varints of 1 to 10 bytes; of one [`IlluminanceSums`]: 4 f64, 16 batch sums and 1 varint.
const PIXEL_FLOATS: u64 = 8 + crate::film::PIXEL_BATCHES as u64;
const E_FLOATS: u64 = 4 + crate::film::PIXEL_BATCHES as u64;
const MIN_PIXEL_BYTES: u64 = PIXEL_FLOATS * 8 + 2;
const MIN_E_BYTES: u64 = E_FLOATS * 8 + 1;
/// Encoded size of one [`MeterSums`] at least: its 16 batch sums of 8 bytes, the name's length,
/// the grid tag, the luminance flag and two varints.
const MIN_METER_BYTES: u64 = crate::meter::BATCHES as u64 * 8 + 5;
/// Most bytes of a pixel of one buffer with its illuminance sums.
const MAX_PIXEL_BYTES: u64 = (PIXEL_FLOATS + E_FLOATS) * 8 + 3 * 10;
/// Longest scene name (the path the state was rendered from) and longest merged-seed list a
/// state may hold; the seed list is checked against itself when merging.
pub const MAX_SCENE_NAME_BYTES: u64 = 64 << 10;
pub const MAX_MERGED_SEEDS: u64 = 1 << 20;
/// Most bytes of a pixel's light-and-health sums: three batched quantities and the most bands.
const MAX_HEALTH_BYTES: u64 =
    (3 * crate::film::PIXEL_BATCHES as u64 + crate::film::MAX_SPECTRAL_BANDS as u64) * 8;
/// Largest state file read: that of the largest film allowed ([`MAX_PIXELS`], adaptive: two
/// buffers, and every light-and-health channel), with the longest name and seed list, the
/// fixed fields and the checksum.
pub const MAX_STATE_BYTES: u64 = 2 * MAX_PIXELS * MAX_PIXEL_BYTES
    + MAX_PIXELS * MAX_HEALTH_BYTES
    + MAX_SCENE_NAME_BYTES
    + 10 * MAX_MERGED_SEEDS
    + MAX_METERS * 256
    + 1024;
/// Most meters and grid points whose sums a state file is read with (at most 256 bytes each
/// with a short name).
pub const MAX_METERS: u64 = 1 << 20;

/// The contents of a state file. Reading decodes the fields in this order by hand (see
/// [`RenderState::decode`]); a change here is a new [`VERSION`] and a change there.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RenderState {
    pub magic: String,
    pub version: u32,
    /// Hash of the scene file's bytes and the settings that change the estimator.
    pub scene_hash: u64,
    pub scene: String,
    pub seed: u64,
    /// Most scattering events per path, [`UNLIMITED_DEPTH`] for none.
    pub max_depth: u32,
    pub illuminance: bool,
    pub film: Film,
    /// The shard of a render this state holds (`candela render --shard`); None for a whole
    /// render or a merge.
    pub shard: Option<ShardInfo>,
    /// A finished shard's meter and grid-point batch sums (meters first, then each grid's
    /// points row by row), for `candela merge`; empty otherwise.
    pub meters: Vec<MeterSums>,
    /// The other seeds a merged state contains (`candela merge`; empty for one render), so a
    /// later merge can refuse a seed that is already in it.
    pub merged_seeds: Vec<u64>,
}

/// Which part of a sharded render a state holds: shard `index` of `count` (0-based) renders
/// samples `index·spp .. (index+1)·spp` of every pixel's sequence, so the `count` shards
/// together take the samples of one render at `count·spp`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct ShardInfo {
    pub index: u32,
    pub count: u32,
    /// Samples per pixel of a finished shard.
    pub spp: u32,
}

/// Most shards a render may be split into.
pub const MAX_SHARDS: u32 = 1 << 20;

/// The fields of a [`RenderState`] with everything borrowed: what is written, so that saving a
/// render's film needs no copy of it.
#[derive(Serialize)]
struct StateRef<'a> {
    magic: &'a str,
    version: u32,
    scene_hash: u64,
    scene: &'a str,
    seed: u64,
    max_depth: u32,
    illuminance: bool,
    film: &'a Film,
    shard: Option<ShardInfo>,
    meters: &'a [MeterSums],
    merged_seeds: &'a [u64],
    health: Option<HealthRef<'a>>,
    pixel_batches: u32,
}

/// The light-and-health sums of a film ([`HealthFilm`]) as written: the channels, whether the
/// melanopic channel has an m-EDI part, and the sums pixel after pixel.
#[derive(Serialize)]
struct HealthRef<'a> {
    melanopic: bool,
    mesopic: bool,
    spectral_bands: u64,
    illuminance: bool,
    sums: &'a [f64],
}

impl<'a> HealthRef<'a> {
    fn of(film: &'a Film) -> Option<Self> {
        film.health.as_ref().map(|h| HealthRef {
            melanopic: h.channels.melanopic,
            mesopic: h.channels.mesopic,
            spectral_bands: h.channels.spectral_bands as u64,
            illuminance: h.illuminance,
            sums: &h.sums,
        })
    }
}

/// Reads the light-and-health sums of a film of `n` pixels rendered with(out) illuminance,
/// checking the channels, the length against the bytes left and the memory before allocating,
/// and the values after.
fn take_health(bytes: &mut &[u8], n: u64, illuminance: bool) -> Result<HealthFilm, String> {
    let (melanopic, mesopic): (bool, bool) = take(bytes, "its light-and-health channels")?;
    let bands: u64 = take(bytes, "its number of spectral bands")?;
    let with_e: bool = take(bytes, "whether its melanopic channel has m-EDI")?;
    if bands > crate::film::MAX_SPECTRAL_BANDS as u64 {
        return Err(format!(
            "it claims {bands} spectral bands per pixel, more than the limit of {}",
            crate::film::MAX_SPECTRAL_BANDS
        ));
    }
    let channels = HealthChannels {
        melanopic,
        mesopic,
        spectral_bands: bands as usize,
    };
    if !channels.any() || with_e != (melanopic && illuminance) {
        return Err(
            "its light-and-health record names no channel, or an m-EDI part that does not match the illuminance setting"
                .into(),
        );
    }
    let len: u64 = take(bytes, "the length of its light-and-health sums")?;
    let want = n * channels.floats_per_pixel(illuminance) as u64;
    if len != want {
        return Err(format!(
            "its light-and-health sums number {len}, but its film and channels need {want}"
        ));
    }
    if (bytes.len() as u64) < len * 8 {
        return Err(format!(
            "its {len} light-and-health sums need {} bytes, but only {} remain (truncated?)",
            len * 8,
            bytes.len()
        ));
    }
    crate::limits::check_memory(len * 8, &format!("the light-and-health sums of {n} pixels"))?;
    let mut sums = Vec::with_capacity(len as usize);
    for k in 0..len {
        let v: f64 = take(bytes, "a light-and-health sum")?;
        if !(v.is_finite() && v >= 0.0) {
            return Err(format!(
                "light-and-health sum {k} is {v:e}, but sums of radiance are finite and ≥ 0"
            ));
        }
        sums.push(v);
    }
    Ok(HealthFilm {
        channels,
        illuminance,
        sums,
    })
}

impl StateRef<'_> {
    /// Writes the state with its checksum, atomically.
    fn save(&self, path: &Path) -> anyhow::Result<()> {
        let mut bytes = postcard::to_stdvec(self)?;
        let sum = checksum(&bytes);
        bytes.extend_from_slice(&sum.to_le_bytes());
        write_atomic(path, |w| w.write_all(&bytes))?;
        Ok(())
    }
}

/// [`RenderState::max_depth`] of a render without a depth limit (finite limits are at most
/// 10 000).
pub const UNLIMITED_DEPTH: u32 = u32::MAX;

/// The state file's code of a depth limit: the limit, or [`UNLIMITED_DEPTH`].
pub fn depth_code(max_depth: Option<u32>) -> u32 {
    max_depth.unwrap_or(UNLIMITED_DEPTH)
}

/// The leading fields of every version, read first so an old file gets a clear message.
#[derive(Deserialize)]
struct Header<'a> {
    magic: &'a str,
    version: u32,
}

/// The fields before the pixel buffers, read to check the sizes the file claims.
#[derive(Deserialize)]
struct Prefix<'a> {
    magic: &'a str,
    version: u32,
    scene_hash: u64,
    scene: &'a str,
    seed: u64,
    max_depth: u32,
    illuminance: bool,
    width: u64,
    height: u64,
}

/// 64-bit checksum of `bytes`: four interleaved chains `h ← mix64(h ⊕ word)` over the 8-byte
/// little-endian words (word k to chain k mod 4, the last word zero-padded), folded with the
/// length. Every step is a bijection of `h` ([`mix64`] is invertible), so a change confined to
/// one 8-byte word (any single flipped bit, any damaged byte) always changes the checksum;
/// other changes of the same length go unnoticed with a probability of about 2⁻⁶⁴. Four
/// independent chains run about four times as fast as one.
pub fn checksum(bytes: &[u8]) -> u64 {
    // Digits of π: the chains start apart.
    let mut lanes = [
        0x243f_6a88_85a3_08d3_u64,
        0x1319_8a2e_0370_7344,
        0xa409_3822_299f_31d0,
        0x082e_fa98_ec4e_6c89,
    ];
    let word = |b: &[u8]| {
        let mut w = [0u8; 8];
        w[..b.len()].copy_from_slice(b);
        u64::from_le_bytes(w)
    };
    let mut blocks = bytes.chunks_exact(32);
    for block in &mut blocks {
        for (lane, w) in lanes.iter_mut().zip(block.chunks_exact(8)) {
            *lane = mix64(*lane ^ word(w));
        }
    }
    for (lane, w) in lanes.iter_mut().zip(blocks.remainder().chunks(8)) {
        *lane = mix64(*lane ^ word(w));
    }
    lanes
        .iter()
        .fold(bytes.len() as u64, |h, &lane| mix64(h ^ lane))
}

/// Reads one postcard value from the front of `bytes`.
fn take<'a, T: Deserialize<'a>>(bytes: &mut &'a [u8], what: &str) -> Result<T, String> {
    let (v, rest) =
        postcard::take_from_bytes(bytes).map_err(|e| format!("cannot read {what}: {e}"))?;
    *bytes = rest;
    Ok(v)
}

/// Reads a buffer of `n` pixels of at least `min_bytes` each after checking the length the file
/// gives it against `n`, the bytes left and the memory available, so a false length allocates
/// nothing.
fn take_pixels<T: serde::de::DeserializeOwned>(
    bytes: &mut &[u8],
    n: u64,
    min_bytes: u64,
    buffer: &str,
) -> Result<Vec<T>, String> {
    let len: u64 = take(bytes, &format!("the length of the {buffer} buffer"))?;
    if len != n {
        return Err(format!(
            "its {buffer} buffer claims {len} pixels, but its film has {n}"
        ));
    }
    if (bytes.len() as u64) < n * min_bytes {
        return Err(format!(
            "its {buffer} buffer of {n} pixels needs at least {} bytes, but only {} remain (truncated?)",
            n * min_bytes,
            bytes.len()
        ));
    }
    let size = n * std::mem::size_of::<T>() as u64;
    crate::limits::check_memory(size, &format!("the {buffer} buffer of {n} pixels"))?;
    let mut pixels = Vec::with_capacity(n as usize);
    for i in 0..n {
        let (p, rest) = postcard::take_from_bytes(bytes)
            .map_err(|e| format!("cannot read pixel {i} of the {buffer} buffer: {e}"))?;
        pixels.push(p);
        *bytes = rest;
    }
    Ok(pixels)
}

/// Feeds the bytes of the regular file `path` to `eat` as one slice would be, reading it in
/// blocks (a mesh of gigabytes is not held twice), and returns its length. What is not a
/// regular file (a FIFO or device put in a model's place) is an error, found without blocking.
fn hash_file(
    h: &mut u64,
    path: &std::path::Path,
    eat: impl Fn(&mut u64, &[u8]),
) -> std::io::Result<u64> {
    use std::io::Read;
    let not_regular =
        || std::io::Error::new(std::io::ErrorKind::InvalidInput, "not a regular file");
    if !std::fs::metadata(path)?.is_file() {
        return Err(not_regular());
    }
    let mut open = std::fs::OpenOptions::new();
    open.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        // A file swapped for a FIFO since the check opens at once instead of waiting.
        open.custom_flags(libc::O_NONBLOCK);
    }
    let mut file = open.open(path)?;
    if !file.metadata()?.is_file() {
        return Err(not_regular());
    }
    // Whole blocks are a multiple of 8 bytes, so `eat`'s 8-byte words fall as over one slice.
    let mut block = vec![0u8; 1 << 16];
    let mut len = 0u64;
    loop {
        let mut filled = 0;
        while filled < block.len() {
            match file.read(&mut block[filled..]) {
                Ok(0) => break,
                Ok(n) => filled += n,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => return Err(e),
            }
        }
        eat(h, &block[..filled]);
        len += filled as u64;
        if filled < block.len() {
            return Ok(len);
        }
    }
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
        match hash_file(&mut h, source, eat) {
            Ok(len) => h = mix64(h ^ len),
            Err(_) => h = mix64(h ^ 0xdead),
        }
    }
    h = mix64(h ^ depth_code(world.settings.max_depth) as u64);
    h = mix64(h ^ world.settings.rr_depth as u64);
    h = mix64(h ^ world.settings.illuminance as u64);
    h = mix64(h ^ world.caustics.is_some() as u64);
    h = mix64(h ^ world.settings.light_paths_per_sample.to_bits() as u64);
    h = mix64(h ^ world.settings.light_sampler as u64);
    h = mix64(h ^ world.settings.pixel_batches as u64);
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
            max_depth: depth_code(world.settings.max_depth),
            illuminance: world.settings.illuminance,
            film,
            merged_seeds: Vec::new(),
            shard: None,
            meters: Vec::new(),
        }
    }

    /// Every seed whose samples this state holds.
    pub fn seeds(&self) -> Vec<u64> {
        std::iter::once(self.seed)
            .chain(self.merged_seeds.iter().copied())
            .collect()
    }

    /// Writes the state with its checksum, atomically.
    pub fn save(&self, path: &Path) -> anyhow::Result<()> {
        StateRef {
            magic: &self.magic,
            version: self.version,
            scene_hash: self.scene_hash,
            scene: &self.scene,
            seed: self.seed,
            max_depth: self.max_depth,
            illuminance: self.illuminance,
            film: &self.film,
            merged_seeds: &self.merged_seeds,
            shard: self.shard,
            meters: &self.meters,
            health: HealthRef::of(&self.film),
            pixel_batches: self.film.pixel_batches,
        }
        .save(path)
    }

    /// Writes the state [`Self::new`] would make of `film` (of shard `shard`, if any, with its
    /// meter sums), without copying the film.
    pub fn save_film(
        scene: &Path,
        scene_hash: u64,
        world: &World,
        film: &Film,
        shard: Option<ShardInfo>,
        meters: &[MeterSums],
        path: &Path,
    ) -> anyhow::Result<()> {
        StateRef {
            magic: MAGIC,
            version: VERSION,
            scene_hash,
            scene: &scene.display().to_string(),
            seed: world.settings.seed,
            max_depth: depth_code(world.settings.max_depth),
            illuminance: world.settings.illuminance,
            film,
            merged_seeds: &[],
            shard,
            meters,
            health: HealthRef::of(film),
            pixel_batches: film.pixel_batches,
        }
        .save(path)
    }

    /// Reads and checks a state file (see the module's description); errors name the file and
    /// what is wrong with it.
    pub fn load(path: &Path) -> anyhow::Result<Self> {
        let bytes = crate::limits::read_file(path, MAX_STATE_BYTES)
            .map_err(|e| anyhow::anyhow!("cannot read state file {}: {e}", path.display()))?;
        Self::decode(&bytes, path)
    }

    /// Checks and decodes the bytes of a state file; `path` names it in errors.
    pub fn decode(bytes: &[u8], path: &Path) -> anyhow::Result<Self> {
        let name = path.display();
        let header = postcard::take_from_bytes::<Header>(bytes)
            .ok()
            .map(|(h, _)| h);
        let signed = header.as_ref().filter(|h| h.magic == MAGIC);
        let intact = bytes.len() >= CHECKSUM_BYTES && {
            let (payload, stored) = bytes.split_at(bytes.len() - CHECKSUM_BYTES);
            stored == checksum(payload).to_le_bytes()
        };
        match signed {
            None if bytes.is_empty() => {
                anyhow::bail!("{name} is empty, not a candela render state")
            }
            None if postcard::to_stdvec(MAGIC).is_ok_and(|sig| sig.starts_with(bytes)) => {
                anyhow::bail!(
                    "{name} is corrupt or truncated: it ends within the signature of a candela render state"
                )
            }
            None => anyhow::bail!(
                "{name} is not a candela render state (it does not begin with one's signature)"
            ),
            // Versions before the checksum: their last bytes are no checksum, so the version
            // is read unchecked (a damaged current file cannot read as one of these: its
            // version byte is 8, and no single flipped bit makes it 1, 2 or 3).
            Some(h) if (1..4).contains(&h.version) && !intact => anyhow::bail!(
                "{name} is a candela render state of format version {}; this candela reads version {VERSION} only (which carries a checksum): finish or merge it with the candela that wrote it, or render again",
                h.version
            ),
            Some(_) if !intact => anyhow::bail!(
                "{name} is corrupt or truncated: its checksum does not match its contents (a changed, missing or added byte)"
            ),
            Some(h) if h.version == 4 => anyhow::bail!(
                "{name} is a candela render state of format version 4, which has no per-pixel batch sums: this candela (format version {VERSION}) estimates pixel standard errors from them and cannot resume or merge it; finish or merge it with the candela that wrote it, or render again"
            ),
            Some(h) if h.version != VERSION => anyhow::bail!(
                "{name} is a candela render state of format version {}; this candela reads version {VERSION} (read it with the candela that wrote it)",
                h.version
            ),
            Some(_) => {}
        }
        let payload = &bytes[..bytes.len() - CHECKSUM_BYTES];
        Self::decode_payload(payload).map_err(|e| anyhow::anyhow!("{name} is corrupt: {e}"))
    }

    /// The fields of an intact, current file, with the sizes it claims checked before they are
    /// allocated and the film's values checked after.
    fn decode_payload(mut bytes: &[u8]) -> Result<Self, String> {
        let p: Prefix = take(&mut bytes, "its header")?;
        if p.scene.len() as u64 > MAX_SCENE_NAME_BYTES {
            return Err(format!(
                "its scene name is {} bytes long, more than the limit of {MAX_SCENE_NAME_BYTES}",
                p.scene.len()
            ));
        }
        let n = p.width as u128 * p.height as u128;
        if n == 0 || n > MAX_PIXELS as u128 {
            return Err(format!(
                "its film is {}×{} pixels{}",
                p.width,
                p.height,
                if n == 0 {
                    String::new()
                } else {
                    format!(", more than the limit of {MAX_PIXELS}")
                }
            ));
        }
        let n = n as u64;
        let pixels = take_pixels::<PixelSums>(&mut bytes, n, MIN_PIXEL_BYTES, "image")?;
        let decision = match take::<u8>(&mut bytes, "whether it has a decision buffer")? {
            0 => None,
            1 => Some(take_pixels(&mut bytes, n, MIN_PIXEL_BYTES, "decision")?),
            t => return Err(format!("its decision-buffer tag is {t}, not 0 or 1")),
        };
        let light_paths: [u64; 2] = take(&mut bytes, "its light-path counts")?;
        // Illuminance sums, for the image and the decision buffer: present exactly when the
        // render estimated illuminance (checked with the film).
        let mut e_buffers = [None, None];
        for (e, buffer) in e_buffers.iter_mut().zip(["image", "decision"]) {
            let what = format!("whether it has {buffer} illuminance sums");
            *e = match take::<u8>(&mut bytes, &what)? {
                0 => None,
                1 => Some(take_pixels::<IlluminanceSums>(
                    &mut bytes,
                    n,
                    MIN_E_BYTES,
                    &format!("{buffer} illuminance"),
                )?),
                t => return Err(format!("its {buffer} illuminance tag is {t}, not 0 or 1")),
            };
        }
        let [e, decision_e] = e_buffers;
        let shard: Option<ShardInfo> = take(&mut bytes, "its shard")?;
        if let Some(s) = shard {
            if s.count == 0 || s.count > MAX_SHARDS || s.index >= s.count || s.spp == 0 {
                return Err(format!(
                    "it claims to be shard {} of {} at {} samples per pixel (shards are 0 … count − 1, at most {MAX_SHARDS}, with at least 1 sample per pixel)",
                    s.index, s.count, s.spp
                ));
            }
        }
        let n_meters: u64 = take(&mut bytes, "the length of its meter list")?;
        if n_meters > bytes.len() as u64 / MIN_METER_BYTES {
            return Err(format!(
                "its meter list claims {n_meters} meters ({MIN_METER_BYTES} bytes or more each), but only {} bytes remain",
                bytes.len()
            ));
        }
        let mut meters = Vec::with_capacity(n_meters as usize);
        for k in 0..n_meters {
            let m: MeterSums = take(&mut bytes, "a meter's sums")?;
            if m.name.len() as u64 > MAX_SCENE_NAME_BYTES
                || m.per_batch > crate::film::MAX_SAMPLES
                || m.non_finite > m.per_batch * crate::meter::BATCHES as u64
                || m.sums.iter().any(|v| !(v.is_finite() && *v >= 0.0))
                || (m.per_batch == 0 && m.sums.iter().any(|&v| v != 0.0))
            {
                return Err(format!(
                    "meter {k} ({:?}) holds sums that no render gives (sums finite and ≥ 0, at most as many non-finite samples as samples)",
                    crate::limits::printable(&m.name, 60)
                ));
            }
            meters.push(m);
        }
        let seeds: u64 = take(&mut bytes, "the length of its merged-seed list")?;
        if seeds > MAX_MERGED_SEEDS || seeds > bytes.len() as u64 {
            return Err(format!(
                "its merged-seed list claims {seeds} seeds (at most {MAX_MERGED_SEEDS}, one byte or more each, and {} bytes remain)",
                bytes.len()
            ));
        }
        let mut merged_seeds = Vec::with_capacity(seeds as usize);
        for _ in 0..seeds {
            merged_seeds.push(take(&mut bytes, "a merged seed")?);
        }
        let health = match take::<u8>(&mut bytes, "whether it has light-and-health sums")? {
            0 => None,
            1 => Some(take_health(&mut bytes, n, p.illuminance)?),
            t => return Err(format!("its light-and-health tag is {t}, not 0 or 1")),
        };
        let pixel_batches: u32 = take(&mut bytes, "its batches per pixel")?;
        if !crate::film::PIXEL_BATCH_CHOICES.contains(&pixel_batches) {
            return Err(format!(
                "it claims {pixel_batches} independent sample batches per pixel, not 2, 4, 8 or 16"
            ));
        }
        if !bytes.is_empty() {
            return Err(format!("{} bytes follow its last field", bytes.len()));
        }
        let mut seen = std::collections::HashSet::from([p.seed]);
        if let Some(s) = merged_seeds.iter().find(|&&s| !seen.insert(s)) {
            return Err(format!("it lists seed {s} twice"));
        }
        let film = Film {
            width: p.width as usize,
            height: p.height as usize,
            pixels,
            decision,
            light_paths,
            e,
            decision_e,
            health,
            pixel_batches,
        };
        film.check(p.illuminance)?;
        Ok(Self {
            magic: p.magic.into(),
            version: p.version,
            scene_hash: p.scene_hash,
            scene: p.scene.into(),
            seed: p.seed,
            max_depth: p.max_depth,
            illuminance: p.illuminance,
            film,
            merged_seeds,
            shard,
            meters,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A file hashed in blocks gives what hashing its bytes as one slice gave, at lengths
    /// around the word and block sizes; a FIFO is refused without blocking.
    #[test]
    fn file_hash_in_blocks_equals_one_slice() {
        let eat = |h: &mut u64, bytes: &[u8]| {
            for chunk in bytes.chunks(8) {
                let mut b = [0u8; 8];
                b[..chunk.len()].copy_from_slice(chunk);
                *h = mix64(*h ^ u64::from_le_bytes(b));
            }
        };
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("f.bin");
        for len in [0usize, 1, 7, 8, 9, 65_535, 65_536, 65_537, 200_003] {
            let bytes: Vec<u8> = (0..len).map(|i| (i * 31 % 251) as u8).collect();
            std::fs::write(&path, &bytes).unwrap();
            let (mut a, mut b) = (7u64, 7u64);
            eat(&mut a, &bytes);
            assert_eq!(hash_file(&mut b, &path, eat).unwrap(), len as u64);
            assert_eq!(a, b, "length {len}");
        }
        #[cfg(unix)]
        {
            let fifo = dir.path().join("fifo");
            let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
            assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
            assert!(hash_file(&mut 0, &fifo, eat).is_err());
        }
    }

    /// A 3 × 2 film with one sample per pixel and melanopic and 4-band sums, as a state.
    fn health_state() -> RenderState {
        let mut film = Film::new(3, 2);
        for p in &mut film.pixels {
            p.add([1.0, 2.0, 3.0]);
        }
        let channels = HealthChannels {
            melanopic: true,
            mesopic: false,
            spectral_bands: 4,
        };
        let mut h = HealthFilm::new(channels, false, 6).unwrap();
        for (k, v) in h.sums.iter_mut().enumerate() {
            *v = k as f64 * 0.25;
        }
        film.health = Some(h);
        RenderState {
            magic: MAGIC.into(),
            version: VERSION,
            scene_hash: 7,
            scene: "s.ron".into(),
            seed: 1,
            max_depth: UNLIMITED_DEPTH,
            illuminance: false,
            film,
            shard: None,
            meters: Vec::new(),
            merged_seeds: Vec::new(),
        }
    }

    #[test]
    fn batches_per_pixel_round_trip_and_bad_ones_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("k.state");
        let mut st = health_state();
        st.film.pixel_batches = 4;
        st.save(&path).unwrap();
        assert_eq!(RenderState::load(&path).unwrap().film.pixel_batches, 4);
        st.film.pixel_batches = 3;
        st.save(&path).unwrap();
        let e = RenderState::load(&path).unwrap_err().to_string();
        assert!(e.contains("3 independent sample batches per pixel"), "{e}");
    }

    #[test]
    fn health_sums_round_trip_and_bad_ones_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("h.state");
        let st = health_state();
        st.save(&path).unwrap();
        assert_eq!(RenderState::load(&path).unwrap(), st);
        // A negative sum, then sums that the channels do not account for, with valid checksums.
        let mut bad = health_state();
        bad.film.health.as_mut().unwrap().sums[5] = -1.0;
        bad.save(&path).unwrap();
        let e = RenderState::load(&path).unwrap_err().to_string();
        assert!(e.contains("light-and-health sum 5"), "{e}");
        let mut bad = health_state();
        bad.film.health.as_mut().unwrap().sums.pop();
        bad.save(&path).unwrap();
        let e = RenderState::load(&path).unwrap_err().to_string();
        assert!(e.contains("light-and-health sums number 119"), "{e}");
    }

    #[test]
    fn checksum_sees_every_change_within_one_word() {
        // Lengths around the 32-byte blocks; every word, 64 changes each (single bits and
        // random masks) and a byte appended or removed.
        for len in [0usize, 1, 7, 8, 31, 32, 33, 100] {
            let bytes: Vec<u8> = (0..len as u64).map(|i| mix64(i) as u8).collect();
            let sum = checksum(&bytes);
            for w in 0..len.div_ceil(8) {
                for k in 0..64u64 {
                    let mask = if k % 2 == 0 { 1u64 << k } else { mix64(k) | 1 };
                    let mut b = bytes.clone();
                    for (i, m) in mask.to_le_bytes().iter().enumerate() {
                        if let Some(x) = b.get_mut(8 * w + i) {
                            *x ^= m;
                        }
                    }
                    assert!(
                        b == bytes || checksum(&b) != sum,
                        "len {len} word {w} mask {mask:x}"
                    );
                }
            }
            let mut longer = bytes.clone();
            longer.push(0);
            assert_ne!(checksum(&longer), sum);
            if len > 0 {
                assert_ne!(checksum(&bytes[..len - 1]), sum);
            }
        }
    }
}
