//! Area light: Lambertian emission from the primitives of one scene object (its `emission`),
//! given by the surface's luminance or the object's flux, the same everywhere on it or varying
//! over it by an emission texture ([`EmissionTexture`]).

use super::{EmissionPoint, LightFlags, LightSample};
use crate::description::context::{Context, Role, SceneError};
use crate::description::schema::{Amount, EmissionDesc};
use crate::geometry::{Hit, SceneGeometry, SurfacePoint};
use crate::photometry::luminous_integral;
use crate::sampling::pick_from_cdf;
use crate::spectrum::{DenseSpectrum, SampledSpectrum, SampledWavelengths};
use crate::texture::emission::EmissionTexture;
use glam::{Vec2, Vec3};
use std::sync::Arc;

/// The spectral shape of an emission: one spectrum for the whole surface, or an emission
/// texture (a shape and a luminance per texel).
#[derive(Clone, Debug)]
pub enum EmissionShape {
    Spectrum(DenseSpectrum),
    Texture(Arc<EmissionTexture>),
}

/// Most points per primitive at which a textured light's mean luminance is estimated.
const MEAN_POINTS_MAX: usize = 64 * 64;
/// Most points over all of a textured light's primitives.
const MEAN_POINTS_TOTAL: usize = 1 << 22;

#[derive(Clone, Debug)]
pub struct AreaLight {
    /// The scene object (index) that emits.
    pub object: u32,
    /// Its primitives.
    pub prims: Vec<u32>,
    /// Cumulative area fractions of `prims`, last = 1.
    pub cdf: Vec<f32>,
    /// Total area of `prims`, m².
    pub total_area: f32,
    radiance: Radiance,
    /// Emits from both faces (otherwise only from the front face).
    pub two_sided: bool,
    /// One per `prims` when all are flat (and, for a textured light, quads, whose texture
    /// coordinates are the sample numbers); otherwise empty, and the scene samples them.
    flat: Vec<FlatPrim>,
}

/// A flat primitive of a light as its samples need it, copied from the scene at build, so
/// that a sample skips the primitive's lookup and recomputing its area and normal: a quad's
/// origin and edges or a triangle's vertices, sampled by the scene's own
/// [`crate::geometry::flat_point`], so the points and densities equal the scene's bit for bit
/// (tests/area_light_prims.rs).
#[derive(Clone, Copy, Debug)]
struct FlatPrim {
    corners: [Vec3; 3],
    triangle: bool,
    /// Unit front-face normal.
    n: Vec3,
    /// Area, m².
    area: f32,
}

impl FlatPrim {
    fn new(geom: &SceneGeometry, prim: u32) -> Option<Self> {
        let (corners, triangle) = geom.prim_corners(prim)?;
        Some(FlatPrim {
            corners,
            triangle,
            n: geom.prim_bounds_normal(prim).1?,
            area: geom.prim_area(prim),
        })
    }

    /// The point uniform by area for `u` ∈ [0, 1)², as the scene samples it.
    #[inline(always)]
    fn point(&self, u: Vec2) -> Vec3 {
        crate::geometry::flat_point(self.corners, self.triangle, u)
    }
}

/// The flat primitives of `prims` (see [`AreaLight::flat`]).
fn flat_prims(geom: &SceneGeometry, prims: &[u32], textured: bool) -> Vec<FlatPrim> {
    prims
        .iter()
        .map(|&p| FlatPrim::new(geom, p).filter(|f| !(textured && f.triangle)))
        .collect::<Option<Vec<_>>>()
        .unwrap_or_default()
}

/// What an area light's surface emits.
#[derive(Clone, Debug)]
enum Radiance {
    /// L_e(λ), W·m⁻²·sr⁻¹·nm⁻¹, the same at every point and direction.
    Uniform(DenseSpectrum),
    /// `luminance` (cd/m²) times the emission texture's radiance per unit Y, and each
    /// primitive's (as `prims`) mean luminance, cd/m², estimated from points on it (for light
    /// selection and the flux only, never for radiance).
    Textured {
        texture: Arc<EmissionTexture>,
        luminance: f32,
        prim_luminance: Vec<f32>,
    },
}

/// A textured light's mean luminance on each of `prims` (cd/m²), `luminance_at` giving it at
/// texture coordinates: the mean over a grid of stratified points (up to [`MEAN_POINTS_MAX`]
/// per primitive, [`MEAN_POINTS_TOTAL`] in all).
fn mean_luminances(
    prims: &[u32],
    geom: &SceneGeometry,
    luminance_at: impl Fn(Vec2) -> f64 + Sync,
) -> Vec<f32> {
    let side = ((MEAN_POINTS_TOTAL / prims.len().max(1)).min(MEAN_POINTS_MAX) as f64)
        .sqrt()
        .max(1.0) as usize;
    use rayon::prelude::*;
    prims
        .par_iter()
        .map(|&prim| {
            let mut sum = 0.0f64;
            for j in 0..side {
                for k in 0..side {
                    let u = Vec2::new(
                        (j as f32 + 0.5) / side as f32,
                        (k as f32 + 0.5) / side as f32,
                    );
                    sum += luminance_at(geom.sample_prim(prim, u).tex);
                }
            }
            (sum / (side * side) as f64) as f32
        })
        .collect()
}

/// Luminous flux (lm) of a Lambertian emitter of `luminance` cd/m² and `area` m² emitting from
/// `sides` faces: Φ = π L A per face.
pub fn flux_lm(luminance: f64, area: f64, sides: f64) -> f64 {
    std::f64::consts::PI * luminance * area * sides
}

fn sides(two_sided: bool) -> f64 {
    if two_sided {
        2.0
    } else {
        1.0
    }
}

impl AreaLight {
    pub const FLAGS: LightFlags = LightFlags::AREA;

    /// The spectral shape of object `field`'s emission (checked while the objects are read,
    /// before the geometry is built).
    pub fn spectrum(
        ctx: &Context,
        field: &str,
        e: &EmissionDesc,
    ) -> Result<EmissionShape, SceneError> {
        let sfield = format!("{field}.emission.spectrum");
        if let Some(t) = &e.texture {
            return Ok(EmissionShape::Texture(t.clone()));
        }
        if let crate::description::schema::SpectrumDesc::Texture {
            file,
            uv_scale,
            uv_offset,
            wrap,
        } = &e.spectrum
        {
            if !(uv_scale.iter().chain(uv_offset)).all(|v| v.is_finite()) {
                return Err(ctx.err(
                    sfield,
                    format!("uv_scale {uv_scale:?} and uv_offset {uv_offset:?} must be finite"),
                ));
            }
            let mut t = EmissionTexture::load(&ctx.resolve(file), [1.0; 3])
                .map_err(|err| ctx.err(&sfield, err.to_string()))?;
            t.uv = crate::texture::scale_offset(*uv_scale, *uv_offset);
            t.wrap = *wrap;
            return Ok(EmissionShape::Texture(Arc::new(t)));
        }
        Ok(EmissionShape::Spectrum(ctx.spectrum(
            &sfield,
            &e.spectrum,
            Role::Emission,
        )?))
    }

    /// The light of scene object `object` (`field` names it, e.g. `objects[3] "lamp"`) from its
    /// `emission` and spectral shape `s` ([`AreaLight::spectrum`]), once the geometry is built:
    /// amount `Luminance(cd/m²)` or `Flux(lm)` of the whole object; with a texture,
    /// `Luminance(cd/m²)` of a texel of Y = 1.
    pub fn build(
        ctx: &Context,
        field: &str,
        object: u32,
        e: &EmissionDesc,
        s: &EmissionShape,
        geometry: &SceneGeometry,
    ) -> Result<Self, SceneError> {
        let two_sided = e.two_sided;
        let prims = geometry.primitives_of_object(object).to_vec();
        let areas: Vec<f64> = prims
            .iter()
            .map(|&p| geometry.prim_area(p) as f64)
            .collect();
        let total: f64 = areas.iter().sum();
        if total.is_nan() || total <= 0.0 {
            return Err(ctx.err(
                format!("{field}.emission"),
                "the emitting shape has zero area",
            ));
        }
        let afield = format!("{field}.emission.amount");
        let cdf = crate::sampling::cdf_from_weights(&areas);
        let s = match s {
            EmissionShape::Spectrum(s) => s,
            EmissionShape::Texture(t) => {
                let l = match e.amount {
                    Amount::Luminance(l) => ctx.nonneg(&afield, l)?,
                    other => {
                        return Err(ctx.err(
                            afield,
                            format!("{other:?} is not an amount for a textured emission; use Luminance(cd/m²), the luminance of a white texel"),
                        ))
                    }
                };
                let peak = l * t.max_luminance();
                if !(peak as f32).is_finite() {
                    return Err(ctx.err(
                        afield,
                        format!("{l} cd/m² makes the brightest texel {peak:e} cd/m², beyond single precision"),
                    ));
                }
                // A white texel's radiance is D65 at this luminance: the same checks of the
                // amount as an untextured emitter's (not so small that it rounds to 0).
                let d65 = crate::colour::tables::named_spectrum("D65").expect("D65 ships");
                let d65 = DenseSpectrum::from_fn(|nm| d65.value(nm));
                ctx.scaled_emission(&format!("{field}.emission.spectrum"), &afield, &d65, l)?;
                let prim_luminance =
                    mean_luminances(&prims, geometry, |tex| t.luminance(tex) * l as f32 as f64);
                let flat = flat_prims(geometry, &prims, true);
                return Ok(Self {
                    object,
                    prims,
                    cdf,
                    total_area: total as f32,
                    radiance: Radiance::Textured {
                        texture: t.clone(),
                        luminance: l as f32,
                        prim_luminance,
                    },
                    two_sided,
                    flat,
                });
            }
        };
        let luminance = match e.amount {
            Amount::Luminance(l) => ctx.nonneg(&afield, l)?,
            Amount::Flux(phi) => ctx.nonneg(&afield, phi)? / flux_lm(1.0, total, sides(two_sided)),
            other => {
                return Err(ctx.err(
                    afield,
                    format!("{other:?} is not an amount for surface emission; use Luminance(cd/m²) or Flux(lm)"),
                ))
            }
        };
        let radiance =
            ctx.scaled_emission(&format!("{field}.emission.spectrum"), &afield, s, luminance)?;
        let flat = flat_prims(geometry, &prims, false);
        Ok(Self {
            object,
            prims,
            cdf,
            total_area: total as f32,
            radiance: Radiance::Uniform(radiance),
            two_sided,
            flat,
        })
    }

    /// The radiance L_e(λ) (W·m⁻²·sr⁻¹·nm⁻¹) of an untextured light, the same everywhere on
    /// it; None for a textured one.
    pub fn uniform_radiance(&self) -> Option<&DenseSpectrum> {
        match &self.radiance {
            Radiance::Uniform(r) => Some(r),
            Radiance::Textured { .. } => None,
        }
    }

    /// Whether the emission varies over the surface by a texture.
    pub fn is_textured(&self) -> bool {
        matches!(self.radiance, Radiance::Textured { .. })
    }

    /// Radiance (W·m⁻²·sr⁻¹·nm⁻¹) leaving the surface where its texture coordinates are `tex`.
    #[inline(always)]
    pub fn radiance_at(&self, tex: Vec2, wl: &SampledWavelengths) -> SampledSpectrum {
        match &self.radiance {
            Radiance::Uniform(r) => r.sample(wl),
            Radiance::Textured {
                texture, luminance, ..
            } => texture.radiance(tex, wl) * *luminance,
        }
    }

    /// Luminance (cd/m²) of the surface where its texture coordinates are `tex`.
    pub fn luminance_at(&self, tex: Vec2) -> f64 {
        match &self.radiance {
            Radiance::Uniform(r) => luminous_integral(r),
            Radiance::Textured {
                texture, luminance, ..
            } => texture.luminance(tex) * *luminance as f64,
        }
    }

    /// Mean luminance (cd/m²) of the `k`-th of `prims` (estimated for a textured light).
    pub fn prim_mean_luminance(&self, k: usize) -> f64 {
        match &self.radiance {
            Radiance::Uniform(r) => luminous_integral(r),
            Radiance::Textured { prim_luminance, .. } => prim_luminance[k] as f64,
        }
    }

    /// A point uniform by area (`uc` chooses the primitive, `u` the point).
    pub fn sample_emission_point(&self, geom: &SceneGeometry, uc: f32, u: Vec2) -> EmissionPoint {
        let (k, _) = pick_from_cdf(&self.cdf, uc);
        let sp = geom.sample_prim(self.prims[k], u);
        EmissionPoint {
            p: sp.p,
            n: Some(sp.n),
            tex: sp.tex,
            inv_pdf: self.total_area,
        }
    }

    /// Radiance × |cos θ| (W·m⁻²·sr⁻¹·nm⁻¹) leaving `at` toward unit direction `dir`, zero
    /// behind a one-sided emitter.
    pub fn emission_toward(
        &self,
        at: &EmissionPoint,
        dir: Vec3,
        wl: &SampledWavelengths,
    ) -> SampledSpectrum {
        let cos = at.n.map_or(0.0, |n| n.dot(dir));
        if cos > 0.0 || (self.two_sided && cos < 0.0) {
            self.radiance_at(at.tex, wl) * cos.abs()
        } else {
            SampledSpectrum::ZERO
        }
    }

    /// A point on the light seen from `p`, by solid angle within the primitive chosen by area.
    pub fn sample_li(
        &self,
        geom: &SceneGeometry,
        p: Vec3,
        uc: f32,
        u: Vec2,
        wl: &SampledWavelengths,
    ) -> Option<LightSample> {
        let (k, p_prim) = pick_from_cdf(&self.cdf, uc);
        let mut ls = self.sample_li_prim(geom, p, self.prims[k], u, wl)?;
        ls.pdf *= p_prim;
        Some(ls)
    }

    /// The flat primitive of id `prim` (one of `prims`), if the light keeps them.
    #[inline]
    fn flat(&self, prim: u32) -> Option<&FlatPrim> {
        if self.flat.is_empty() {
            return None;
        }
        // `prims` ascend, and an object's primitives are usually consecutive ids.
        let k = prim.wrapping_sub(self.prims[0]) as usize;
        if self.prims.get(k) == Some(&prim) {
            return self.flat.get(k);
        }
        let k = self.prims.binary_search(&prim).ok()?;
        self.flat.get(k)
    }

    /// A point on primitive `prim` (one of `prims`) seen from `p`, by solid angle; `pdf` is
    /// the density within that primitive (its choice is the caller's).
    pub fn sample_li_prim(
        &self,
        geom: &SceneGeometry,
        p: Vec3,
        prim: u32,
        u: Vec2,
        wl: &SampledWavelengths,
    ) -> Option<LightSample> {
        let sp = match self.flat(prim) {
            Some(f) => {
                let q = f.point(u);
                let pdf = SceneGeometry::area_to_solid_angle(f.area, p, q, f.n);
                (pdf > 0.0 && pdf.is_finite()).then_some((
                    SurfacePoint {
                        p: q,
                        n: f.n,
                        tex: u,
                    },
                    pdf,
                ))
            }
            // The texture coordinates only matter to a textured emission.
            None => geom.sample_prim_solid_angle_with(prim, p, u, self.is_textured()),
        };
        let (sp, pdf_sa) = sp?;
        let d = sp.p - p;
        let dist = d.length();
        if dist == 0.0 || pdf_sa.is_nan() || pdf_sa <= 0.0 || !pdf_sa.is_finite() {
            return None;
        }
        let wi = d / dist;
        let facing = sp.n.dot(-wi) > 0.0;
        if !facing && !self.two_sided {
            return None;
        }
        Some(LightSample {
            wi,
            li: self.radiance_at(sp.tex, wl),
            pdf: pdf_sa,
            dist,
            point: Some((sp.p, sp.n)),
            delta: false,
        })
    }

    /// Density (solid angle) with which [`AreaLight::sample_li`] from `p` would have produced
    /// the ray that hit the light at `hit`.
    pub fn pdf_li_hit(&self, geom: &SceneGeometry, p: Vec3, hit: &Hit) -> f32 {
        let area = self
            .flat(hit.prim)
            .map_or_else(|| geom.prim_area(hit.prim), |f| f.area);
        area / self.total_area * self.pdf_li_hit_prim(geom, p, hit)
    }

    /// Density (solid angle) with which [`AreaLight::sample_li_prim`] from `p`, given the
    /// primitive hit, would have produced the ray that hit the light at `hit`.
    #[inline]
    pub fn pdf_li_hit_prim(&self, geom: &SceneGeometry, p: Vec3, hit: &Hit) -> f32 {
        match self.flat(hit.prim) {
            Some(f) => SceneGeometry::area_to_solid_angle(f.area, p, hit.p, hit.ng),
            None => geom.pdf_prim_solid_angle(hit.prim, p, hit),
        }
    }

    /// Radiance leaving the surface toward the viewer, given the hit.
    pub fn emitted(&self, hit: &Hit, wl: &SampledWavelengths) -> SampledSpectrum {
        if hit.front_face || self.two_sided {
            self.radiance_at(hit.tex, wl)
        } else {
            SampledSpectrum::ZERO
        }
    }

    /// Σ A·L over the primitives (cd/m² × m²; estimated for a textured light) and their
    /// area Σ A (m²).
    fn luminance_area(&self, geom: &SceneGeometry) -> (f64, f64) {
        let (mut la, mut area) = (0.0, 0.0);
        for (k, &prim) in self.prims.iter().enumerate() {
            let a = geom.prim_area(prim) as f64;
            la += a * self.prim_mean_luminance(k);
            area += a;
        }
        (la, area)
    }

    /// Mean luminance over the light's surface, cd/m² (estimated for a textured light).
    pub fn mean_luminance(&self, geom: &SceneGeometry) -> f64 {
        let (la, area) = self.luminance_area(geom);
        la / area.max(f64::MIN_POSITIVE)
    }

    /// Luminous flux, lm (estimated from points for a textured light).
    pub fn power_lm(&self, geom: &SceneGeometry) -> f64 {
        flux_lm(self.luminance_area(geom).0, 1.0, sides(self.two_sided))
    }
}
