//! A glTF material as the file gives it: its factors, its texture references (checked: texture
//! coordinate set 0, finite `KHR_texture_transform`) and its images, kept for `scene::gltf`.

use super::data::{self, parse_err};
use super::{GeometryError, GltfImage, GltfMaterial, GltfTextureRef};
use std::path::{Path, PathBuf};

/// `KHR_texture_transform`'s (offset, rotation in rad, scale, texCoord) of a texture reference.
type Transform = ([f32; 2], f32, [f32; 2], Option<u32>);

/// A texture reference of material `m` (`what` names the texture in messages): its set of
/// texture coordinates must be 0, its transform finite.
fn texture_ref(
    path: &Path,
    what: &str,
    m: usize,
    (tex, tex_coord, transform): (gltf::Texture, u32, Option<Transform>),
) -> Result<GltfTextureRef, GeometryError> {
    if tex_coord != 0 {
        return Err(parse_err(
            path,
            format!("material {m}'s {what} uses TEXCOORD_{tex_coord}; candela reads set 0"),
        ));
    }
    let mut uv = glam::Affine2::IDENTITY;
    if let Some((offset, rotation, scale, set)) = transform {
        if set.is_some_and(|c| c != 0) {
            return Err(parse_err(
                path,
                format!("material {m}'s {what} transform selects another TEXCOORD set"),
            ));
        }
        uv = crate::texture::gltf_uv_map(offset, rotation, scale);
        if !uv.is_finite() {
            return Err(parse_err(
                path,
                format!("material {m}'s {what} transform is not finite"),
            ));
        }
    }
    use gltf::texture::WrappingMode::ClampToEdge;
    let s = tex.sampler();
    Ok(GltfTextureRef {
        image: tex.source().index(),
        uv,
        clamp: s.wrap_s() == ClampToEdge && s.wrap_t() == ClampToEdge,
    })
}

/// A `textureInfo`'s texture, set and transform.
fn info_parts(info: gltf::texture::Info) -> (gltf::Texture, u32, Option<Transform>) {
    let t = info
        .texture_transform()
        .map(|t| (t.offset(), t.rotation(), t.scale(), t.tex_coord()));
    (info.texture(), info.tex_coord(), t)
}

/// The `KHR_texture_transform` of a normal texture, which the `gltf` crate leaves as JSON.
fn normal_transform(
    path: &Path,
    m: usize,
    n: &gltf::material::NormalTexture,
) -> Result<Option<Transform>, GeometryError> {
    let Some(v) = n.extension_value("KHR_texture_transform") else {
        return Ok(None);
    };
    let bad = || {
        parse_err(
            path,
            format!("material {m}'s normal texture has a malformed KHR_texture_transform"),
        )
    };
    let pair = |key: &str, default: [f32; 2]| -> Result<[f32; 2], GeometryError> {
        match v.get(key) {
            None => Ok(default),
            Some(a) => {
                let a = a.as_array().filter(|a| a.len() == 2).ok_or_else(bad)?;
                let x = |i: usize| a[i].as_f64().map(|x| x as f32).ok_or_else(bad);
                Ok([x(0)?, x(1)?])
            }
        }
    };
    let rotation = match v.get("rotation") {
        None => 0.0,
        Some(r) => r.as_f64().ok_or_else(bad)? as f32,
    };
    let set = match v.get("texCoord") {
        None => None,
        Some(c) => Some(c.as_u64().ok_or_else(bad)? as u32),
    };
    Ok(Some((
        pair("offset", [0.0, 0.0])?,
        rotation,
        pair("scale", [1.0, 1.0])?,
        set,
    )))
}

pub(super) fn material(path: &Path, m: &gltf::Material) -> Result<GltfMaterial, GeometryError> {
    let i = m.index().unwrap_or(0);
    let pbr = m.pbr_metallic_roughness();
    let f = |v: f32| v as f64;
    let base_texture = match pbr.base_color_texture() {
        Some(t) => Some(texture_ref(path, "base colour texture", i, info_parts(t))?),
        None => None,
    };
    let metal_rough_texture = match pbr.metallic_roughness_texture() {
        Some(t) => Some(texture_ref(
            path,
            "metallic-roughness texture",
            i,
            info_parts(t),
        )?),
        None => None,
    };
    let emissive_texture = match m.emissive_texture() {
        Some(t) => Some(texture_ref(path, "emissive texture", i, info_parts(t))?),
        None => None,
    };
    let normal_texture = match m.normal_texture() {
        Some(n) => {
            let parts = (n.texture(), n.tex_coord(), normal_transform(path, i, &n)?);
            let scale = n.scale();
            if !scale.is_finite() {
                return Err(parse_err(
                    path,
                    format!("material {i}'s normal texture scale {scale} is not finite"),
                ));
            }
            Some((texture_ref(path, "normal texture", i, parts)?, scale))
        }
        None => None,
    };
    Ok(GltfMaterial {
        name: m.name().map_or_else(|| format!("#{i}"), str::to_string),
        index: i,
        base_colour: pbr.base_color_factor().map(f),
        base_texture,
        metal_rough_texture,
        normal_texture,
        metallic: f(pbr.metallic_factor()),
        roughness: f(pbr.roughness_factor()),
        transmission: m.transmission().map_or(0.0, |t| f(t.transmission_factor())),
        ior: m.ior().map_or(1.5, f),
        emissive: m.emissive_factor().map(f),
        emissive_texture,
        emissive_strength: m.emissive_strength().map_or(1.0, f),
    })
}

pub(super) fn image(
    path: &Path,
    im: &gltf::Image,
    buffers: &[Vec<u8>],
) -> Result<GltfImage, GeometryError> {
    let label =
        |what: &str| PathBuf::from(format!("{} (image {}, {what})", path.display(), im.index()));
    Ok(match im.source() {
        gltf::image::Source::View { view, .. } => GltfImage::Bytes {
            label: label("embedded"),
            bytes: data::view_bytes(path, &view, buffers)?.to_vec(),
        },
        gltf::image::Source::Uri { uri, .. } => {
            match data::resource(path, uri, &format!("image {}", im.index()))? {
                data::Resource::File(f) => GltfImage::File(f),
                data::Resource::Data(bytes) => GltfImage::Bytes {
                    label: label("data: URI"),
                    bytes,
                },
            }
        }
    })
}
