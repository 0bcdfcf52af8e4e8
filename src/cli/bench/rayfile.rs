//! The ray file shared with `bench/embree/embree_trace.c` (one triangle mesh and named ray
//! batches) and the hit file it writes back (one `t` per ray). Little endian throughout.
//!
//! Ray file, version 1:
//! ```text
//! "CNDLRAY1", u32 vertices, u32 triangles, u32 batches, u32 reserved (0)
//! f32 positions[3·vertices], u32 indices[3·triangles]
//! per batch: u32 kind (0 closest hit, 1 any hit), u32 count, name: 16 bytes (UTF-8, NUL padded),
//!            count × {f32 ox, oy, oz, tnear, dx, dy, dz, tfar}
//! ```
//! Hit file, version 1:
//! ```text
//! "CNDLHIT1", u32 batches, u32 reserved, per batch: u32 count, f32 t[count]
//! ```
//! `t` is the hit distance or +∞ for a miss; for any-hit batches 0 means occluded, +∞ not.

use anyhow::{bail, Context, Result};
use candela::geometry::TriangleMesh;
use glam::Vec3;
use std::path::Path;

const RAY_MAGIC: &[u8; 8] = b"CNDLRAY1";
const HIT_MAGIC: &[u8; 8] = b"CNDLHIT1";
const NAME_LEN: usize = 16;

/// Largest ray or hit file read: the largest export (50 M triangles, three batches of 8192²
/// rays) is about 7.5 GB.
pub const MAX_RAY_FILE_BYTES: u64 = 16 << 30;

/// Which query a batch is traced with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RayKind {
    /// Closest hit (`SceneGeometry::intersect`, `rtcIntersect1`).
    Closest,
    /// Any hit (`SceneGeometry::occluded`, `rtcOccluded1`).
    Occluded,
}

/// One ray: `p = origin + t·dir` for `t` in `(tnear, tfar)`; `dir` need not be unit length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BenchRay {
    pub origin: Vec3,
    pub tnear: f32,
    pub dir: Vec3,
    pub tfar: f32,
}

/// A named batch of rays of one kind.
#[derive(Clone, Debug, PartialEq)]
pub struct RayBatch {
    /// At most 16 bytes of UTF-8, no spaces (it is a command argument for embree_trace).
    pub name: String,
    pub kind: RayKind,
    pub rays: Vec<BenchRay>,
}

/// A mesh and the ray batches to trace against it.
#[derive(Clone, Debug, Default)]
pub struct RayFile {
    pub mesh: TriangleMesh,
    pub batches: Vec<RayBatch>,
}

fn put_u32(out: &mut Vec<u8>, v: u32) {
    out.extend_from_slice(&v.to_le_bytes());
}

fn put_f32(out: &mut Vec<u8>, v: f32) {
    out.extend_from_slice(&v.to_le_bytes());
}

fn count_u32(n: usize, what: &str) -> Result<u32> {
    u32::try_from(n).with_context(|| format!("too many {what} for the ray file format ({n})"))
}

impl RayFile {
    /// The file's bytes.
    pub fn to_bytes(&self) -> Result<Vec<u8>> {
        let rays: usize = self.batches.iter().map(|b| b.rays.len()).sum();
        let mut out = Vec::with_capacity(
            24 + self.mesh.positions.len() * 12
                + self.mesh.indices.len() * 12
                + self.batches.len() * 24
                + rays * 32,
        );
        out.extend_from_slice(RAY_MAGIC);
        put_u32(&mut out, count_u32(self.mesh.positions.len(), "vertices")?);
        put_u32(&mut out, count_u32(self.mesh.indices.len(), "triangles")?);
        put_u32(&mut out, count_u32(self.batches.len(), "batches")?);
        put_u32(&mut out, 0);
        for p in &self.mesh.positions {
            p.to_array().iter().for_each(|&c| put_f32(&mut out, c));
        }
        for t in &self.mesh.indices {
            t.iter().for_each(|&i| put_u32(&mut out, i));
        }
        for b in &self.batches {
            if b.name.len() > NAME_LEN || b.name.is_empty() || b.name.contains(char::is_whitespace)
            {
                bail!(
                    "ray batch name {:?} must be 1 to {NAME_LEN} bytes without spaces",
                    b.name
                );
            }
            put_u32(
                &mut out,
                match b.kind {
                    RayKind::Closest => 0,
                    RayKind::Occluded => 1,
                },
            );
            put_u32(&mut out, count_u32(b.rays.len(), "rays")?);
            let mut name = [0u8; NAME_LEN];
            name[..b.name.len()].copy_from_slice(b.name.as_bytes());
            out.extend_from_slice(&name);
            for r in &b.rays {
                for v in [
                    r.origin.x, r.origin.y, r.origin.z, r.tnear, r.dir.x, r.dir.y, r.dir.z, r.tfar,
                ] {
                    put_f32(&mut out, v);
                }
            }
        }
        Ok(out)
    }

    /// Parses a ray file's bytes; every inconsistency is an error (never a panic).
    pub fn from_bytes(bytes: &[u8]) -> Result<RayFile> {
        let mut c = Cursor { bytes, pos: 0 };
        if c.take(8, "the header")? != RAY_MAGIC {
            bail!("it is not a candela ray file (version 1): the magic bytes are wrong");
        }
        let nv = c.u32("the header")? as usize;
        let nt = c.u32("the header")? as usize;
        let nb = c.u32("the header")? as usize;
        c.u32("the header")?;
        // Check sizes before allocating, so a corrupt count cannot exhaust memory.
        c.need(nv.saturating_mul(12), "the vertices")?;
        let positions: Vec<Vec3> = (0..nv)
            .map(|_| Ok(Vec3::new(c.f32("")?, c.f32("")?, c.f32("")?)))
            .collect::<Result<_>>()?;
        if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
            bail!("vertex {i} is not finite");
        }
        c.need(nt.saturating_mul(12), "the triangles")?;
        let mut indices = Vec::with_capacity(nt);
        for f in 0..nt {
            let t = [c.u32("")?, c.u32("")?, c.u32("")?];
            if let Some(&bad) = t.iter().find(|&&i| i as usize >= nv) {
                bail!("triangle {f} refers to vertex {bad}, but there are only {nv} vertices");
            }
            indices.push(t);
        }
        let mut batches = Vec::new();
        for b in 0..nb {
            let what = format!("the header of ray batch {b}");
            let kind = match c.u32(&what)? {
                0 => RayKind::Closest,
                1 => RayKind::Occluded,
                k => bail!("ray batch {b} has an unknown kind {k} (0 closest hit, 1 any hit)"),
            };
            let n = c.u32(&what)? as usize;
            let raw = c.take(NAME_LEN, &what)?;
            let end = raw.iter().position(|&x| x == 0).unwrap_or(NAME_LEN);
            let name = std::str::from_utf8(&raw[..end])
                .ok()
                .filter(|s| !s.is_empty())
                .with_context(|| format!("ray batch {b} has an invalid name"))?
                .to_string();
            c.need(n.saturating_mul(32), &format!("the rays of batch '{name}'"))?;
            let mut rays = Vec::with_capacity(n);
            for i in 0..n {
                let v: [f32; 8] = std::array::from_fn(|_| c.f32("").unwrap_or(f32::NAN));
                let r = BenchRay {
                    origin: Vec3::new(v[0], v[1], v[2]),
                    tnear: v[3],
                    dir: Vec3::new(v[4], v[5], v[6]),
                    tfar: v[7],
                };
                if !(r.origin.is_finite() && r.dir.is_finite() && r.tnear.is_finite())
                    || r.tfar.is_nan()
                {
                    bail!("ray {i} of batch '{name}' is not finite");
                }
                rays.push(r);
            }
            batches.push(RayBatch { name, kind, rays });
        }
        if c.pos != bytes.len() {
            bail!(
                "{} unexpected bytes after the last ray batch",
                bytes.len() - c.pos
            );
        }
        Ok(RayFile {
            mesh: TriangleMesh {
                positions,
                normals: None,
                indices,
            },
            batches,
        })
    }

    pub fn write(&self, path: &Path) -> Result<()> {
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)
                .with_context(|| format!("cannot create the directory '{}'", dir.display()))?;
        }
        let bytes = self.to_bytes()?;
        candela::output::write_atomic(path, |w| w.write_all(&bytes))
            .with_context(|| format!("cannot write the ray file '{}'", path.display()))
    }

    pub fn read(path: &Path) -> Result<RayFile> {
        let bytes = candela::limits::read_file(path, MAX_RAY_FILE_BYTES).with_context(|| {
            format!(
                "cannot read the ray file '{}' (create it with `candela bench traversal --export {}`)",
                path.display(),
                path.display()
            )
        })?;
        // The mesh and rays take about as much memory as their bytes.
        candela::limits::check_memory(
            bytes.len() as u64,
            &format!("the mesh and rays of '{}'", path.display()),
        )
        .map_err(anyhow::Error::msg)?;
        Self::from_bytes(&bytes).with_context(|| {
            format!(
                "the ray file '{}' is corrupt or truncated; export it again with `candela bench traversal --export`",
                path.display()
            )
        })
    }
}

/// Reads a hit file: one `t` array per batch.
pub fn read_hits(path: &Path) -> Result<Vec<Vec<f32>>> {
    let bytes = candela::limits::read_file(path, MAX_RAY_FILE_BYTES)
        .with_context(|| format!("cannot read the hit file '{}'", path.display()))?;
    hits_from_bytes(&bytes)
        .with_context(|| format!("the hit file '{}' is corrupt or truncated", path.display()))
}

pub fn hits_from_bytes(bytes: &[u8]) -> Result<Vec<Vec<f32>>> {
    let mut c = Cursor { bytes, pos: 0 };
    if c.take(8, "the header")? != HIT_MAGIC {
        bail!("it is not a candela hit file (version 1): the magic bytes are wrong");
    }
    let nb = c.u32("the header")? as usize;
    c.u32("the header")?;
    let mut out = Vec::new();
    for b in 0..nb {
        let n = c.u32(&format!("the header of batch {b}"))? as usize;
        c.need(n.saturating_mul(4), &format!("the hits of batch {b}"))?;
        out.push((0..n).map(|_| c.f32("").unwrap_or(f32::NAN)).collect());
    }
    if c.pos != bytes.len() {
        bail!(
            "{} unexpected bytes after the last batch",
            bytes.len() - c.pos
        );
    }
    Ok(out)
}

/// A hit file's bytes (the format `embree_trace --hits` writes).
pub fn hits_to_bytes(hits: &[Vec<f32>]) -> Vec<u8> {
    let mut out = Vec::new();
    out.extend_from_slice(HIT_MAGIC);
    put_u32(&mut out, hits.len() as u32);
    put_u32(&mut out, 0);
    for h in hits {
        put_u32(&mut out, h.len() as u32);
        h.iter().for_each(|&t| put_f32(&mut out, t));
    }
    out
}

struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
}

impl<'a> Cursor<'a> {
    fn need(&self, n: usize, what: &str) -> Result<()> {
        if self.bytes.len() - self.pos < n {
            bail!(
                "the file ends early (while reading {what}: {n} bytes needed, {} left)",
                self.bytes.len() - self.pos
            );
        }
        Ok(())
    }
    fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8]> {
        self.need(n, what)?;
        let s = &self.bytes[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }
    fn u32(&mut self, what: &str) -> Result<u32> {
        Ok(u32::from_le_bytes(self.take(4, what)?.try_into()?))
    }
    fn f32(&mut self, what: &str) -> Result<f32> {
        Ok(f32::from_le_bytes(self.take(4, what)?.try_into()?))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> RayFile {
        RayFile {
            mesh: TriangleMesh {
                positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
                normals: None,
                indices: vec![[0, 1, 2]],
            },
            batches: vec![
                RayBatch {
                    name: "primary".into(),
                    kind: RayKind::Closest,
                    rays: vec![BenchRay {
                        origin: Vec3::new(0.2, 0.2, 1.0),
                        tnear: 0.0,
                        dir: -Vec3::Z,
                        tfar: f32::INFINITY,
                    }],
                },
                RayBatch {
                    name: "shadow".into(),
                    kind: RayKind::Occluded,
                    rays: vec![
                        BenchRay {
                            origin: Vec3::new(0.2, 0.2, -1.0),
                            tnear: 0.0,
                            dir: Vec3::Z,
                            tfar: 0.5,
                        };
                        3
                    ],
                },
            ],
        }
    }

    #[test]
    fn ray_file_round_trips() {
        let f = sample();
        let bytes = f.to_bytes().unwrap();
        let g = RayFile::from_bytes(&bytes).unwrap();
        assert_eq!(g.mesh.positions, f.mesh.positions);
        assert_eq!(g.mesh.indices, f.mesh.indices);
        assert_eq!(g.batches, f.batches);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("sub/rays.bin");
        f.write(&path).unwrap();
        assert_eq!(RayFile::read(&path).unwrap().batches, f.batches);
    }

    #[test]
    fn corrupt_ray_files_are_errors() {
        let bytes = sample().to_bytes().unwrap();
        for cut in [0, 7, 12, 30, bytes.len() - 1] {
            let e = RayFile::from_bytes(&bytes[..cut]).unwrap_err().to_string();
            assert!(e.contains("ends early") || e.contains("magic"), "{e}");
        }
        let mut extra = bytes.clone();
        extra.push(0);
        assert!(RayFile::from_bytes(&extra).is_err());
        let mut bad_index = bytes.clone();
        bad_index[24 + 36..24 + 40].copy_from_slice(&7u32.to_le_bytes());
        let e = RayFile::from_bytes(&bad_index).unwrap_err().to_string();
        assert!(e.contains("refers to vertex 7"), "{e}");
        let mut huge = bytes.clone();
        huge[8..12].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(RayFile::from_bytes(&huge).is_err());
        let missing = RayFile::read(Path::new("/nonexistent/rays.bin")).unwrap_err();
        assert!(format!("{missing:#}").contains("cannot read the ray file"));
    }

    #[test]
    fn hit_file_round_trips() {
        let h = vec![vec![1.0, f32::INFINITY], vec![], vec![0.0]];
        let bytes = hits_to_bytes(&h);
        assert_eq!(hits_from_bytes(&bytes).unwrap(), h);
        assert!(hits_from_bytes(&bytes[..bytes.len() - 2]).is_err());
    }
}
