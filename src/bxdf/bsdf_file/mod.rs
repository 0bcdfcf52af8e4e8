//! A surface whose scattering is read from an LBNL WINDOW / Radiance BSDF XML file: a blind,
//! fabric, diffuser or any fenestration system measured or computed as a BSDF (Klems
//! matrices; docs/fenestration.md).
//!
//! Orientation as Radiance's `BSDF` primitive: the file's +Z is the surface normal, which
//! points into the room (WINDOW's *back*; its *front* is the exterior); its X axis is
//! up × normal, so azimuth 0 of the file lies along the surface, perpendicular to `up`.
//! WINDOW's "Transmission Front" is light from outside into the room.
//!
//! `eval` reads the matrix entry of the incident and outgoing patches, looked up as Radiance
//! looks them up, so f is what Radiance's `SDevalBSDF` returns (without its ±0.03 %
//! position hash). `sample` draws an incident patch in proportion to f Λ over the reflection
//! and transmission rows of the outgoing patch and a direction uniform in projected solid
//! angle within it: the density is f |cos θi| / Σ f Λ exactly, so every sample weighs the
//! row's albedo and multiple importance sampling with light sampling is exact. Light sampling
//! at the surface evaluates the file at the light's exact direction, so the sun through a
//! blind keeps its direction and is spread only over the file's own outgoing patch.
//!
//! The data are photopic (`Visible`): f applies at every wavelength (a grey system). Other
//! wavelength sets in the file (`Solar`, `CIE-X`, `CIE-Z`) are reported and not used.

pub mod klems;
pub mod xml;

use super::{BsdfSample, Frame, MaterialFlags};
use crate::description::context::{Context, SceneError};
use crate::description::schema::MaterialDesc;
use crate::spectrum::SampledSpectrum;
use glam::{Vec2, Vec3};
use klems::KlemsMatrix;
use std::path::{Path, PathBuf};
use xml::Block;

/// Hemispherical sums above this are refused (measured and Monte Carlo files reach 1.004).
pub const MAX_HEMISPHERICAL: f64 = 1.01;

/// A BSDF read from a file.
#[derive(Debug)]
pub struct BsdfFile {
    /// The file it was read from, for messages and the report.
    pub path: PathBuf,
    /// The up direction in scene coordinates: the file's X axis is up × normal.
    pub up: Vec3,
    /// The four blocks by [`Block::slot`]: transmission to +z, to −z, reflection on +z, on −z.
    blocks: [Option<KlemsMatrix>; 4],
    /// What reading the file noted (data left out, a direction made by reciprocity).
    pub notes: Vec<String>,
}

impl BsdfFile {
    /// The file at `path`, oriented by `up` (scene coordinates, unit).
    pub fn load(path: &Path, up: Vec3) -> Result<Self, String> {
        let parsed = xml::read(path)?;
        Self::from_parsed(path, up, parsed)
    }

    fn from_parsed(path: &Path, up: Vec3, parsed: xml::ParsedFile) -> Result<Self, String> {
        if let xml::Layout::Tree(k) = parsed.layout {
            return Err(format!(
                "BSDF file '{}' holds a {k}-D tensor tree; candela reads Klems matrices \
                 (LBNL/Klems Full, Half, Quarter or a custom basis). Convert the tree with \
                 Radiance's bsdf2klems.",
                path.display()
            ));
        }
        let mut blocks: [Option<KlemsMatrix>; 4] = Default::default();
        let mut notes = Vec::new();
        if !parsed.skipped.is_empty() {
            notes.push(format!(
                "uses the Visible data; the file's {} data are not used",
                parsed.skipped.join(", ")
            ));
        }
        for b in parsed.blocks {
            let (inc, out) = b.bases.expect("Klems blocks have bases");
            let m = KlemsMatrix::new(inc, out, b.values);
            let (sum, i) = m.max_hemispherical();
            if sum > MAX_HEMISPHERICAL {
                let (theta, phi) = m.incident_angles_deg(i);
                return Err(format!(
                    "BSDF file '{}' line {} ('{}'): light arriving from θ = {theta:.1}°, φ = \
                     {phi:.1}° (patch {}) is scattered {:.1} % (Σ f Λ over the outgoing \
                     patches), more than 100 %: the data do not conserve energy",
                    path.display(),
                    b.data_line,
                    b.block.window_name(),
                    i + 1,
                    100.0 * sum
                ));
            }
            blocks[b.block.slot()] = Some(m);
        }
        // A missing transmission direction follows from the other by reciprocity (as
        // Radiance and dctimestep use it).
        for (have, missing) in [
            (Block::TransToPos, Block::TransToNeg),
            (Block::TransToNeg, Block::TransToPos),
        ] {
            if blocks[missing.slot()].is_none() {
                if let Some(m) = &blocks[have.slot()] {
                    let r = m
                        .reciprocal()
                        .map_err(|e| format!("BSDF file '{}': {e}", path.display()))?;
                    blocks[missing.slot()] = Some(r);
                    notes.push(format!(
                        "'{}' made from '{}' by reciprocity",
                        missing.window_name(),
                        have.window_name()
                    ));
                }
            }
        }
        // Together with the reflection on the side light arrives from, transmission may not
        // exceed 1 either.
        for (refl, trans) in [
            (Block::ReflPos, Block::TransToNeg),
            (Block::ReflNeg, Block::TransToPos),
        ] {
            if let (Some(r), Some(t)) = (&blocks[refl.slot()], &blocks[trans.slot()]) {
                if r.inc.name == t.inc.name {
                    let worst = (0..r.inc.len())
                        .map(|i| r.hemispherical(i) + t.hemispherical(i))
                        .fold(0.0f64, f64::max);
                    if worst > MAX_HEMISPHERICAL {
                        return Err(format!(
                            "BSDF file '{}': '{}' and '{}' together scatter {:.1} % of the light \
                             arriving from one direction, more than 100 %",
                            path.display(),
                            refl.window_name(),
                            trans.window_name(),
                            100.0 * worst
                        ));
                    }
                }
            }
        }
        Ok(Self {
            path: path.to_path_buf(),
            up,
            blocks,
            notes,
        })
    }

    /// The material of a `BsdfFile` description.
    pub fn from_desc(ctx: &Context, field: &str, desc: &MaterialDesc) -> Result<Self, SceneError> {
        let MaterialDesc::BsdfFile { file, up } = desc else {
            unreachable!("BsdfFile::from_desc is called with BsdfFile descriptions only")
        };
        let up = ctx.unit(&format!("{field}.up"), *up)?;
        Self::load(&ctx.resolve(file), up).map_err(|e| ctx.err(format!("{field}.file"), e))
    }

    /// No delta lobes: every direction is read from the tables.
    pub const FLAGS: MaterialFlags = MaterialFlags::NONE;

    /// The shading frame at a hit of unit normal `n`: x = up × n (Radiance's BSDF frame); a
    /// normal along `up` falls back to an arbitrary tangent.
    pub fn frame(&self, n: Vec3) -> Frame {
        let t = self.up.cross(n).normalize_or_zero();
        if t == Vec3::ZERO {
            return Frame::from_normal(n);
        }
        Frame {
            t,
            b: n.cross(t),
            n,
        }
    }

    fn block(&self, b: Block) -> Option<&KlemsMatrix> {
        self.blocks[b.slot()].as_ref()
    }

    /// f(wo, wi) in sr⁻¹ (grey).
    pub fn value(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z == 0.0 || wi.z == 0.0 {
            return 0.0;
        }
        let block = match (wi.z > 0.0, wo.z > 0.0) {
            (false, true) => Block::TransToPos,
            (true, false) => Block::TransToNeg,
            (true, true) => Block::ReflPos,
            (false, false) => Block::ReflNeg,
        };
        self.block(block).map_or(0.0, |m| {
            m.value(
                Vec3::new(-wi.x, -wi.y, wi.z.abs()),
                Vec3::new(wo.x, wo.y, wo.z.abs()),
            )
        })
    }

    /// The reflection and transmission blocks light reaching `wo` comes through, with the
    /// outgoing index vector.
    fn rows(&self, wo: Vec3) -> (Option<&KlemsMatrix>, Option<&KlemsMatrix>, Vec3) {
        let b = Vec3::new(wo.x, wo.y, wo.z.abs());
        if wo.z > 0.0 {
            (self.block(Block::ReflPos), self.block(Block::TransToPos), b)
        } else {
            (self.block(Block::ReflNeg), self.block(Block::TransToNeg), b)
        }
    }

    /// Σ f Λ of the reflection and the transmission rows toward `wo`.
    fn row_sums(&self, wo: Vec3) -> (f32, f32) {
        let (r, t, b) = self.rows(wo);
        (
            r.map_or(0.0, |m| m.row_sum(b)),
            t.map_or(0.0, |m| m.row_sum(b)),
        )
    }

    /// The fractions of light arriving from local direction `wi` (toward the light) that the
    /// file reflects and transmits: Σ_o f Λ_o over the outgoing patches of each block.
    pub fn reflected_transmitted(&self, wi: Vec3) -> (f64, f64) {
        let a = Vec3::new(-wi.x, -wi.y, wi.z.abs());
        let (refl, trans) = if wi.z > 0.0 {
            (Block::ReflPos, Block::TransToNeg)
        } else {
            (Block::ReflNeg, Block::TransToPos)
        };
        let sum = |b: Block| {
            self.block(b)
                .map_or(0.0, |m| m.hemispherical(m.inc.index(a)))
        };
        (sum(refl), sum(trans))
    }

    pub fn eval(&self, wo: Vec3, wi: Vec3) -> SampledSpectrum {
        SampledSpectrum::splat(self.value(wo, wi))
    }

    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z == 0.0 {
            return 0.0;
        }
        let (sr, st) = self.row_sums(wo);
        let total = sr + st;
        if total <= 0.0 {
            return 0.0;
        }
        self.value(wo, wi) * wi.z.abs() / total
    }

    pub fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BsdfSample> {
        if wo.z == 0.0 {
            return None;
        }
        let (r, t, b) = self.rows(wo);
        let (sr, st) = (
            r.map_or(0.0, |m| m.row_sum(b)),
            t.map_or(0.0, |m| m.row_sum(b)),
        );
        let total = sr + st;
        if total <= 0.0 {
            return None;
        }
        let p_refl = sr / total;
        let (a, reflect) = if uc < p_refl {
            (r?.sample(b, uc / p_refl, u)?, true)
        } else {
            let uc = ((uc - p_refl) / (1.0 - p_refl)).min(1.0 - f32::EPSILON / 2.0);
            (t?.sample(b, uc, u)?, false)
        };
        // Back from the index vector (x and y turned about the normal) to the side light
        // comes from.
        let z = if reflect == (wo.z > 0.0) { a.z } else { -a.z };
        let wi = Vec3::new(-a.x, -a.y, z);
        let f = self.value(wo, wi);
        let pdf = f * wi.z.abs() / total;
        (pdf > 0.0).then(|| BsdfSample {
            wi,
            f: SampledSpectrum::splat(f),
            pdf,
            specular: false,
        })
    }
}
