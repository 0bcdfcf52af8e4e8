//! glTF materials and punctual lights as candela's (the rule is in docs/scene-format.md →
//! models): base colour → a smooth reflectance spectrum as for `Rgb`; metallic ≥ 0.5 → a
//! conductor whose normal-incidence reflectance is that spectrum; transmission ≥ 0.5 → a
//! dielectric of index `ior`; else roughness ≥ 0.5 → Lambertian, below → a clear-coated
//! Lambertian base. Emission: `emissiveFactor × emissive_strength` in cd/m² (luminance of its
//! Rec. 709 Y). Lights keep glTF's photometric units: cd for point and spot, lx for directional.

use crate::bxdf::diffuse::TexturedDiffuse;
use crate::bxdf::metal_rough::{BaseColour, MetalRough, MAX_METAL_REFLECTANCE};
use crate::bxdf::normal_map::NormalMapped;
use crate::bxdf::Material;
use crate::description::context::{Context, Role, SceneError};
use crate::description::schema::{
    Amount, DistributionDesc, EmissionDesc, IorDesc, LightDesc, MaskingDesc, MaterialDesc,
    SpectrumDesc,
};
use crate::geometry::gltf::{
    GltfImage, GltfLight, GltfLightKind, GltfMaterial, GltfModel, GltfTextureRef,
};
use crate::texture::bytes::ByteTexture;
use crate::texture::emission::EmissionTexture;
use crate::texture::{Texture, TextureError, Wrap};
use std::collections::HashMap;
use std::sync::Arc;

/// Rec. 709 luminance weights of linear sRGB.
fn luma(c: [f64; 3]) -> f64 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

/// Textures already decoded, so materials sharing an image share it: reflectance textures by
/// (image, tint bits), metallic-roughness and normal maps by image.
#[derive(Default)]
pub struct TextureCache {
    colour: HashMap<(usize, [u32; 3]), Arc<Texture>>,
    metal_rough: HashMap<usize, Arc<ByteTexture<2>>>,
    normal: HashMap<usize, Arc<ByteTexture<3>>>,
    emissive: HashMap<(usize, [u32; 3]), Arc<EmissionTexture>>,
}

impl TextureCache {
    pub fn new() -> Self {
        Self::default()
    }
}

/// Decodes image `image` of `model` with `decode(label, bytes)`.
fn with_image<T>(
    model: &GltfModel,
    image: usize,
    decode: impl Fn(&std::path::Path, &[u8]) -> Result<T, TextureError>,
) -> Result<T, String> {
    match model.images.get(image) {
        Some(GltfImage::File(p)) => crate::limits::read_file(p, 4 << 30)
            .map_err(|e| format!("cannot use texture image '{}': {e}.", p.display()))
            .and_then(|b| decode(p, &b).map_err(|e| e.to_string())),
        Some(GltfImage::Bytes { label, bytes }) => decode(label, bytes).map_err(|e| e.to_string()),
        None => Err(format!("image {image} does not exist")),
    }
}

/// `t`'s wrap mode and UV map on a copy of `texture`.
fn with_sampler<T: Clone>(
    texture: &T,
    t: &GltfTextureRef,
    set: impl Fn(&mut T, Wrap, glam::Affine2),
) -> T {
    let mut tex = texture.clone();
    set(
        &mut tex,
        if t.clamp { Wrap::Clamp } else { Wrap::Repeat },
        t.uv,
    );
    tex
}

/// The candela material of glTF material `m` of `model`; errors at `field` name the material.
pub fn material(
    ctx: &Context,
    field: &str,
    model: &GltfModel,
    m: &GltfMaterial,
    cache: &mut TextureCache,
) -> Result<Material, SceneError> {
    let at = format!(
        "{field} (material {:?} of '{}')",
        m.name,
        model.path.display()
    );
    let unit = |what: &str, v: f64| -> Result<f64, SceneError> {
        if !(v.is_finite() && (0.0..=1.0).contains(&v)) {
            return Err(ctx.err(&at, format!("{what} {v} is outside [0, 1]")));
        }
        Ok(v)
    };
    let c = m.base_colour;
    let rgb = [
        unit("baseColorFactor", c[0])?,
        unit("baseColorFactor", c[1])?,
        unit("baseColorFactor", c[2])?,
    ];
    let metallic = unit("metallicFactor", m.metallic)?;
    let roughness = unit("roughnessFactor", m.roughness)?;
    let transmission = unit("transmissionFactor", m.transmission)?;
    let inner =
        if transmission < 0.5 && (m.base_texture.is_some() || m.metal_rough_texture.is_some()) {
            textured(ctx, &at, model, m, cache, rgb, (metallic, roughness))?
        } else {
            untextured(ctx, &at, m, rgb, (metallic, roughness, transmission))?
        };
    let Some((t, scale)) = &m.normal_texture else {
        return Ok(inner);
    };
    let map = match cache.normal.get(&t.image) {
        Some(map) => map.clone(),
        None => {
            let map = with_image(model, t.image, |p, b| ByteTexture::decode(p, b, [0, 1, 2]))
                .map_err(|e| ctx.err(&at, format!("normalTexture: {e}")))?;
            let map = Arc::new(map);
            cache.normal.insert(t.image, map.clone());
            map
        }
    };
    Ok(Material::NormalMapped(Arc::new(NormalMapped {
        inner,
        map: with_sampler(&*map, t, |m, w, uv| {
            m.wrap = w;
            m.uv = uv;
        }),
        scale: *scale,
    })))
}

/// A material with a base-colour or metallic-roughness texture (not transmissive): a textured
/// Lambertian where the factors make it one everywhere and only the base colour is textured,
/// else [`MetalRough`], which applies the rule per hit.
fn textured(
    ctx: &Context,
    at: &str,
    model: &GltfModel,
    m: &GltfMaterial,
    cache: &mut TextureCache,
    rgb: [f64; 3],
    (metallic, roughness): (f64, f64),
) -> Result<Material, SceneError> {
    let base = match &m.base_texture {
        Some(t) => {
            let tint = rgb.map(|v| v as f32);
            let key = (t.image, tint.map(f32::to_bits));
            let texture = match cache.colour.get(&key) {
                Some(tex) => tex.clone(),
                None => {
                    let tex = with_image(model, t.image, |p, b| Texture::decode(p, b, tint))
                        .map_err(|e| ctx.err(at, e))?;
                    let tex = Arc::new(tex);
                    cache.colour.insert(key, tex.clone());
                    tex
                }
            };
            let tex = with_sampler(&*texture, t, |x, w, uv| {
                x.wrap = w;
                x.uv = uv;
            });
            if m.metal_rough_texture.is_none() && metallic < 0.5 && roughness >= 0.5 {
                return Ok(Material::TexturedDiffuse(TexturedDiffuse {
                    texture: Arc::new(tex),
                }));
            }
            BaseColour::Texture(Arc::new(tex))
        }
        None => BaseColour::Spectrum(ctx.spectrum(
            at,
            &SpectrumDesc::Rgb(rgb[0], rgb[1], rgb[2]),
            Role::Reflectance,
        )?),
    };
    let mr = match &m.metal_rough_texture {
        Some(t) => {
            let map = match cache.metal_rough.get(&t.image) {
                Some(map) => map.clone(),
                None => {
                    let map = with_image(model, t.image, |p, b| ByteTexture::decode(p, b, [1, 2]))
                        .map_err(|e| ctx.err(at, format!("metallicRoughnessTexture: {e}")))?;
                    let map = Arc::new(map);
                    cache.metal_rough.insert(t.image, map.clone());
                    map
                }
            };
            Some(with_sampler(&*map, t, |x, w, uv| {
                x.wrap = w;
                x.uv = uv;
            }))
        }
        None => None,
    };
    if !(m.ior.is_finite() && m.ior >= 1.0) {
        return Err(ctx.err(at, format!("ior {} must be ≥ 1", m.ior)));
    }
    let mr = MetalRough::build(ctx, at, base, (metallic, roughness), mr, m.ior)?;
    Ok(Material::MetalRough(Arc::new(mr)))
}

/// The material of an untextured (or transmissive) glTF material, by the rule in the module
/// docs.
fn untextured(
    ctx: &Context,
    at: &str,
    m: &GltfMaterial,
    rgb: [f64; 3],
    (metallic, roughness, transmission): (f64, f64, f64),
) -> Result<Material, SceneError> {
    // glTF's roughness is perceptual: the microfacet α is its square.
    let alpha = (roughness * roughness) as f32;
    let desc = if transmission >= 0.5 {
        if !(m.ior.is_finite() && m.ior >= 1.0) {
            return Err(ctx.err(at, format!("ior {} must be ≥ 1", m.ior)));
        }
        MaterialDesc::Dielectric {
            // KHR_materials_ior's 1.0 means "no refraction": the thinnest interface candela has.
            ior: IorDesc::Constant(m.ior.max(1.0 + 1e-4) as f32),
            roughness: alpha,
            roughness_v: None,
            distribution: DistributionDesc::Ggx,
        }
    } else if metallic >= 0.5 {
        let r = ctx.spectrum(
            at,
            &SpectrumDesc::Rgb(rgb[0], rgb[1], rgb[2]),
            Role::Reflectance,
        )?;
        // n = 1: F0 = k² / (4 + k²), so k = 2√(F0 / (1 − F0)) gives F0 the base colour.
        let k: Vec<(f64, f64)> = (r.values.iter().enumerate())
            .map(|(i, &f0)| {
                let f0 = (f0 as f64).clamp(0.0, MAX_METAL_REFLECTANCE);
                (360.0 + i as f64, 2.0 * (f0 / (1.0 - f0)).sqrt())
            })
            .collect();
        MaterialDesc::Conductor {
            metal: None,
            n: Some(SpectrumDesc::Constant(1.0)),
            k: Some(SpectrumDesc::Tabulated(k)),
            roughness: alpha,
            roughness_v: None,
            distribution: DistributionDesc::Ggx,
            masking: MaskingDesc::default(),
        }
    } else if roughness >= 0.5 {
        MaterialDesc::Diffuse {
            reflectance: SpectrumDesc::Rgb(rgb[0], rgb[1], rgb[2]),
        }
    } else {
        if !(m.ior.is_finite() && m.ior >= 1.0) {
            return Err(ctx.err(at, format!("ior {} must be ≥ 1", m.ior)));
        }
        MaterialDesc::Coated {
            base: SpectrumDesc::Rgb(rgb[0], rgb[1], rgb[2]),
            ior: m.ior as f32,
            roughness: alpha,
            distribution: DistributionDesc::Ggx,
        }
    };
    Material::build(ctx, at, &desc)
}

/// The emission of glTF material `m`: front faces of luminance `strength · Y(emissive)` cd/m²
/// with the colour of `emissive` (scaled to a peak of 1) as its spectral shape; with an
/// `emissiveTexture`, per texel `strength · Y(c)` with the shape of c = `emissive` × the
/// texel's linear colour. `None` when `emissive` is black.
pub fn emission(
    ctx: &Context,
    field: &str,
    model: &GltfModel,
    m: &GltfMaterial,
    cache: &mut TextureCache,
) -> Result<Option<EmissionDesc>, SceneError> {
    let e = m.emissive;
    let at = || {
        format!(
            "{field} (material {:?} of '{}')",
            m.name,
            model.path.display()
        )
    };
    if let Some(v) = e
        .iter()
        .find(|v| !(v.is_finite() && (0.0..=1.0).contains(*v)))
    {
        return Err(ctx.err(
            at(),
            format!("emissiveFactor component {v} is outside [0, 1]"),
        ));
    }
    let s = m.emissive_strength;
    if !(s.is_finite() && s >= 0.0) {
        return Err(ctx.err(at(), format!("emissive_strength {s} must be ≥ 0")));
    }
    let peak = e.iter().copied().fold(0.0, f64::max);
    if peak == 0.0 || s == 0.0 {
        return Ok(None);
    }
    let texture = match &m.emissive_texture {
        None => None,
        Some(t) => {
            let tint = e.map(|v| v as f32);
            let key = (t.image, tint.map(f32::to_bits));
            let texture = match cache.emissive.get(&key) {
                Some(tex) => tex.clone(),
                None => {
                    let tex =
                        with_image(model, t.image, |p, b| EmissionTexture::decode(p, b, tint))
                            .map_err(|err| ctx.err(at(), err))?;
                    let tex = Arc::new(tex);
                    cache.emissive.insert(key, tex.clone());
                    tex
                }
            };
            let wrap = if t.clamp { Wrap::Clamp } else { Wrap::Repeat };
            Some(if texture.wrap == wrap && texture.uv == t.uv {
                texture
            } else {
                Arc::new(with_sampler(&*texture, t, |x, w, uv| {
                    x.wrap = w;
                    x.uv = uv;
                }))
            })
        }
    };
    Ok(Some(match texture {
        None => EmissionDesc {
            spectrum: SpectrumDesc::Rgb(e[0] / peak, e[1] / peak, e[2] / peak),
            amount: Amount::Luminance(s * luma(e)),
            two_sided: false,
            texture: None,
        },
        Some(t) => EmissionDesc {
            spectrum: SpectrumDesc::Rgb(1.0, 1.0, 1.0),
            amount: Amount::Luminance(s),
            two_sided: false,
            texture: Some(t),
        },
    }))
}

/// The candela light of glTF light `l`, its colour's luminance scaling the intensity (white
/// (1, 1, 1) keeps it): point → `Point`, spot → `Spot` (the look-at point 1 m along its axis),
/// directional → `Distant`. `None` for a black or zero-intensity light.
pub fn light(ctx: &Context, field: &str, l: &GltfLight) -> Result<Option<LightDesc>, SceneError> {
    let c = l.colour;
    let at = || format!("{field} (light {:?})", l.name);
    if let Some(v) = c
        .iter()
        .find(|v| !(v.is_finite() && (0.0..=1.0).contains(*v)))
    {
        return Err(ctx.err(at(), format!("color component {v} is outside [0, 1]")));
    }
    if !(l.intensity.is_finite() && l.intensity >= 0.0) {
        return Err(ctx.err(at(), format!("intensity {} must be ≥ 0", l.intensity)));
    }
    let peak = c.iter().copied().fold(0.0, f64::max);
    let amount = l.intensity * luma(c);
    if peak == 0.0 || amount == 0.0 {
        return Ok(None);
    }
    let spectrum = SpectrumDesc::Rgb(c[0] / peak, c[1] / peak, c[2] / peak);
    let p = l.position.to_array();
    Ok(Some(match l.kind {
        GltfLightKind::Point => LightDesc::Point {
            position: p,
            spectrum,
            amount: Amount::Intensity(amount),
        },
        GltfLightKind::Spot {
            inner_rad,
            outer_rad,
        } => LightDesc::Spot {
            position: p,
            look_at: (l.position + l.direction).to_array(),
            inner_deg: inner_rad.to_degrees() as f32,
            outer_deg: outer_rad.to_degrees() as f32,
            spectrum,
            amount: Amount::Intensity(amount),
        },
        GltfLightKind::Directional => LightDesc::Distant {
            direction: l.direction.to_array(),
            spectrum,
            amount: Amount::Illuminance(amount),
        },
    }))
}

/// `l` moved by the object's transform `t` (its direction renormalised).
pub fn placed(l: &GltfLight, t: Option<&crate::geometry::Transform>) -> GltfLight {
    let mut l = l.clone();
    if let Some(t) = t {
        l.position = t.matrix.transform_point3(l.position);
        l.direction = t.matrix.transform_vector3(l.direction).normalize_or_zero();
    }
    l
}

/// One world object made from a glTF model: a primitive placed by one node (in the model's
/// space, before the object's transform), or in its mesh's own space when the mesh is
/// instanced; its texture coordinates, material and emission.
pub struct GltfPart {
    pub shape: crate::geometry::Shape,
    pub uvs: Option<Vec<glam::Vec2>>,
    pub material: u32,
    pub emission: Option<EmissionDesc>,
}

/// A glTF mesh placed by two or more nodes: its primitives that do not emit, stored once in the
/// mesh's space, and the nodes' world transforms (in the model's space).
pub struct GltfGroup {
    pub parts: Vec<GltfPart>,
    pub transforms: Vec<crate::geometry::Transform>,
}

impl GltfGroup {
    /// The group's copies, one per node, in the model's space.
    pub fn flatten(self, ctx: &Context, field: &str) -> Result<Vec<GltfPart>, SceneError> {
        let mut out = Vec::with_capacity(self.parts.len() * self.transforms.len());
        for t in &self.transforms {
            for p in &self.parts {
                out.push(GltfPart {
                    shape: p
                        .shape
                        .to_world(t)
                        .map_err(|e| ctx.err(field, e.to_string()))?,
                    uvs: p.uvs.clone(),
                    material: p.material,
                    emission: p.emission.clone(),
                });
            }
        }
        Ok(out)
    }
}

/// The parts of glTF `model` used as the `Model` shape at `field`. A mesh placed by one node is
/// flattened to the model's space; a mesh placed by two or more becomes a [`GltfGroup`] (an
/// instance per node), except its emitting primitives, flattened once per node so that each is
/// an area light. Materials come from the file by the rule above, or from `overrides` by glTF
/// material name; a primitive without a material takes the object's `fallback`. Materials made
/// here are appended to `materials`.
pub fn parts(
    ctx: &Context,
    field: &str,
    model: &GltfModel,
    overrides: &std::collections::BTreeMap<String, crate::description::schema::MaterialRefDesc>,
    fallback: &str,
    lookup: &dyn Fn(&str, &str) -> Result<u32, SceneError>,
    materials: &mut Vec<Material>,
) -> Result<(Vec<GltfPart>, Vec<GltfGroup>), SceneError> {
    use crate::description::schema::MaterialRefDesc;
    use crate::geometry::{Shape, Transform};
    let file = model.path.display();
    for name in overrides.keys() {
        if !model.materials.iter().any(|m| &m.name == name) {
            let mut names: Vec<&str> = model.materials.iter().map(|m| m.name.as_str()).collect();
            names.sort_unstable();
            return Err(ctx.err(
                format!("{field}.materials_from_file[{name:?}]"),
                format!(
                    "'{file}' has no material {name:?}; its materials: {}",
                    names.join(", ")
                ),
            ));
        }
    }
    let mut cache = TextureCache::new();
    let mut ids: Vec<Option<(u32, Option<EmissionDesc>)>> = vec![None; model.materials.len()];
    let mut fallback_id = None;
    let mut resolve = |p: &crate::geometry::gltf::GltfPrimitive,
                       materials: &mut Vec<Material>|
     -> Result<(u32, Option<EmissionDesc>), SceneError> {
        Ok(match p.material {
            None => {
                let id = match fallback_id {
                    Some(id) => id,
                    None => {
                        let id = lookup(&format!("{field}.material"), fallback).map_err(|e| {
                            ctx.err(
                                format!("{field}.material"),
                                format!("'{file}' has primitives without a material; they take the object's `material`: {e}"),
                            )
                        })?;
                        *fallback_id.insert(id)
                    }
                };
                (id, None)
            }
            Some(i) => {
                if ids[i].is_none() {
                    let m = &model.materials[i];
                    let over = format!("{field}.materials_from_file[{:?}]", m.name);
                    let id = match overrides.get(&m.name) {
                        Some(MaterialRefDesc::Named(n)) => lookup(&over, n)?,
                        Some(MaterialRefDesc::Material(desc)) => {
                            materials.push(Material::build(ctx, &over, desc)?);
                            materials.len() as u32 - 1
                        }
                        None => {
                            materials.push(material(ctx, field, model, m, &mut cache)?);
                            materials.len() as u32 - 1
                        }
                    };
                    ids[i] = Some((id, emission(ctx, field, model, m, &mut cache)?));
                }
                ids[i].clone().expect("set above")
            }
        })
    };
    let mut uses = vec![0usize; model.meshes.len()];
    for inst in &model.instances {
        uses[inst.mesh] += 1;
    }
    // Index into `groups` of each shared mesh's group, made at its first node.
    let mut group_of: Vec<Option<usize>> = vec![None; model.meshes.len()];
    let mut groups: Vec<GltfGroup> = Vec::new();
    let mut out = Vec::new();
    for inst in &model.instances {
        let t = Transform::from_affine(inst.world);
        let at_node = |e: crate::geometry::GeometryError| {
            ctx.err(field, format!("'{file}' node {}: {e}", inst.node))
        };
        let shared = uses[inst.mesh] >= 2;
        if shared {
            if !t.is_invertible() {
                return Err(ctx.err(
                    field,
                    format!(
                        "'{file}' node {}: its transform is singular (zero scale on some axis) or not finite",
                        inst.node
                    ),
                ));
            }
            if let Some(g) = group_of[inst.mesh] {
                groups[g].transforms.push(t);
            }
        }
        let first = shared && group_of[inst.mesh].is_none();
        let mut group_parts = Vec::new();
        for p in &model.meshes[inst.mesh].primitives {
            if p.mesh.indices.is_empty() {
                continue;
            }
            let (material, emission) = resolve(p, materials)?;
            let placed_once = !shared || emission.is_some();
            if placed_once {
                out.push(GltfPart {
                    shape: Shape::Mesh(p.mesh.clone()).to_world(&t).map_err(at_node)?,
                    uvs: p.uvs.clone(),
                    material,
                    emission,
                });
            } else if first {
                group_parts.push(GltfPart {
                    shape: Shape::Mesh(p.mesh.clone()),
                    uvs: p.uvs.clone(),
                    material,
                    emission: None,
                });
            }
        }
        if first {
            group_of[inst.mesh] = Some(groups.len());
            groups.push(GltfGroup {
                parts: group_parts,
                transforms: vec![t],
            });
        }
    }
    groups.retain(|g| !g.parts.is_empty());
    Ok((out, groups))
}

/// A `Model` object at `field` whose file is glTF: `(file, materials_from_file, ke_luminance,
/// lights)` as the scene gives them, `(transform, fallback, lookup)` the object's transform, its
/// `material` and the scene's material names. Returns its parts and instanced meshes (see
/// [`parts`]) and, with `lights`, the file's lights placed by the transform (with the fields to
/// name them by).
#[allow(clippy::type_complexity)]
pub fn model_parts(
    ctx: &Context,
    field: &str,
    (file, overrides, ke_luminance, with_lights): (
        &str,
        &std::collections::BTreeMap<String, crate::description::schema::MaterialRefDesc>,
        Option<f64>,
        bool,
    ),
    (transform, fallback, lookup): (
        Option<&crate::geometry::Transform>,
        &str,
        &dyn Fn(&str, &str) -> Result<u32, SceneError>,
    ),
    materials: &mut Vec<Material>,
) -> Result<(Vec<GltfPart>, Vec<GltfGroup>, Vec<(String, LightDesc)>), SceneError> {
    if ke_luminance.is_some() {
        return Err(ctx.err(
            format!("{field}.ke_luminance"),
            "applies to OBJ models; a glTF material's emission is in cd/m² already (emissive_strength)",
        ));
    }
    let model = crate::geometry::gltf::load_gltf(&ctx.resolve(file))
        .map_err(|e| crate::geometry::mesh_err(ctx, field, file, e))?;
    {
        // A render refuses to overwrite them, and its state's hash covers them.
        let mut sources = ctx.sources.borrow_mut();
        for f in &model.files {
            if !sources.contains(f) {
                sources.push(f.clone());
            }
        }
    }
    let mut lights = Vec::new();
    if with_lights {
        for (k, l) in model.lights.iter().enumerate() {
            let at = format!("{field}.lights[{k}]");
            if let Some(d) = light(ctx, &at, &placed(l, transform))? {
                lights.push((at, d));
            }
        }
    }
    let (parts, groups) = parts(ctx, field, &model, overrides, fallback, lookup, materials)?;
    Ok((parts, groups, lights))
}
