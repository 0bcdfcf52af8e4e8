//! A luminance image file as a [`GlareImage`]: candela's EXR (luminance `Y`, its standard
//! error `stderr.Y`, the camera's `projection` attribute) or a Radiance picture (`.hdr`, no
//! standard errors, the projection from its `VIEW=` line). Pixel directions and solid angles
//! come from the camera's projection ([`crate::camera::projection`]), in the view frame
//! (x right, y up, z the line of sight).

use super::GlareImage;
use crate::camera::projection::FilmMap;
use crate::camera::{FisheyeMapping, Projection};
use crate::description::schema::{FisheyeMappingDesc, ProjectionDesc};
use crate::output::{self, OutputError};
use std::path::{Path, PathBuf};

/// Why an image file cannot be evaluated for glare.
#[derive(Debug, thiserror::Error)]
pub enum GlareFileError {
    #[error(transparent)]
    Read(#[from] OutputError),
    #[error("{path}: {message}")]
    View { path: PathBuf, message: String },
}

/// The projection of a Radiance view (`-vta`, `-vth`, `-vts`, `-vtv` with `-vh`, `-vv`) on a
/// `width` × `height` picture, as candela's cameras write it (a fisheye's circle spans the
/// shorter side).
pub fn projection_of_radiance_view(
    view: &str,
    width: usize,
    height: usize,
) -> Result<Projection, String> {
    let words: Vec<&str> = view.split_whitespace().collect();
    let mut kind = None;
    let (mut vh, mut vv) = (None, None);
    let mut i = 0;
    while i < words.len() {
        let w = words[i];
        if let Some(t) = w.strip_prefix("-vt") {
            kind = t.chars().next();
        } else if w == "-vh" || w == "-vv" {
            let v: f64 = words
                .get(i + 1)
                .and_then(|s| s.parse().ok())
                .filter(|v: &f64| v.is_finite() && *v > 0.0)
                .ok_or_else(|| format!("{w} needs a positive angle in degrees"))?;
            if w == "-vh" {
                vh = Some(v);
            } else {
                vv = Some(v);
            }
            i += 1;
        }
        i += 1;
    }
    let (w, h) = (width as f64, height as f64);
    let m = w.min(h);
    // The angle across the shorter side, from the angle across the width or height.
    let across = |f: &dyn Fn(f64, f64) -> f64| -> Result<f64, String> {
        match (vh, vv) {
            (Some(a), _) => Ok(f(a, w / m)),
            (None, Some(a)) => Ok(f(a, h / m)),
            _ => Err("the view gives neither -vh nor -vv".into()),
        }
    };
    let half = |deg: f64| 0.5 * deg.to_radians();
    let p = match kind {
        Some('a') => Projection::Fisheye {
            mapping: FisheyeMapping::Equidistant,
            fov_deg: across(&|a, k| a / k)?,
        },
        Some('h') => Projection::Fisheye {
            mapping: FisheyeMapping::Orthographic,
            fov_deg: across(&|a, k| 2.0 * (half(a).sin() / k).asin().to_degrees())?,
        },
        Some('s') => Projection::Fisheye {
            mapping: FisheyeMapping::Stereographic,
            fov_deg: across(&|a, k| 4.0 * ((0.5 * half(a)).tan() / k).atan().to_degrees())?,
        },
        Some('v') => Projection::Perspective {
            vfov_deg: match (vv, vh) {
                (Some(a), _) => a,
                (None, Some(a)) => 2.0 * (half(a).tan() * h / w).atan().to_degrees(),
                _ => return Err("the view gives neither -vh nor -vv".into()),
            },
        },
        Some(t) => return Err(format!("view type -vt{t} is not supported for glare")),
        None => return Err("the view has no -vt type".into()),
    };
    Ok(p)
}

/// The projection a candela EXR names in its `projection` attribute (scene syntax).
fn projection_of_attribute(text: &str) -> Result<Projection, String> {
    let desc: ProjectionDesc =
        ron::from_str(text).map_err(|e| format!("projection attribute `{text}`: {e}"))?;
    Ok(match desc {
        ProjectionDesc::Perspective { vfov_deg } => Projection::Perspective {
            vfov_deg: vfov_deg as f64,
        },
        ProjectionDesc::Fisheye { mapping, fov_deg } => Projection::Fisheye {
            mapping: match mapping {
                FisheyeMappingDesc::Equidistant => FisheyeMapping::Equidistant,
                FisheyeMappingDesc::Orthographic => FisheyeMapping::Orthographic,
                FisheyeMappingDesc::Equisolid => FisheyeMapping::Equisolid,
                FisheyeMappingDesc::Stereographic => FisheyeMapping::Stereographic,
            },
            fov_deg: fov_deg as f64,
        },
        ProjectionDesc::Equirectangular => Projection::Equirectangular,
    })
}

impl GlareImage {
    /// The image of `projection` at `width` × `height` pixels in its own view frame (looking
    /// along +z, up +y): each pixel's direction through its centre, its solid angle and whether
    /// it sees the scene, with the given luminances (cd/m²) and standard errors.
    pub fn of_projection(
        projection: Projection,
        width: usize,
        height: usize,
        luminance_cd_m2: Vec<f64>,
        stderr_cd_m2: Option<Vec<f64>>,
    ) -> Self {
        let map = FilmMap::new(projection, width, height);
        let n = width * height;
        let (mut direction, mut solid_angle_sr, mut inside) = (
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
        );
        for y in 0..height {
            for x in 0..width {
                let d = map.direction(x as f64 + 0.5, y as f64 + 0.5);
                let ok = map.pixel_inside(x, y) && d.is_some();
                direction.push(d.unwrap_or([0.0, 0.0, 1.0]));
                solid_angle_sr.push(if ok { map.pixel_solid_angle(x, y) } else { 0.0 });
                inside.push(ok);
            }
        }
        GlareImage {
            width,
            height,
            luminance_cd_m2,
            stderr_cd_m2,
            direction,
            solid_angle_sr,
            inside,
            view_dir: [0.0, 0.0, 1.0],
            up: [0.0, 1.0, 0.0],
        }
    }
}

/// Reads `path` (EXR or Radiance HDR) as a glare image in its view frame.
pub fn read_glare_image(path: &Path) -> Result<GlareImage, GlareFileError> {
    let layers = output::read_image(path)?;
    let view_err = |message: String| GlareFileError::View {
        path: path.to_path_buf(),
        message,
    };
    let (w, h) = (layers.width, layers.height);
    let attr = |name: &str| {
        layers
            .attributes
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_str())
    };
    let projection = match (
        attr(output::ATTRIBUTE_PROJECTION),
        attr(output::ATTRIBUTE_VIEW),
    ) {
        (Some(p), _) => projection_of_attribute(p).map_err(view_err)?,
        (None, Some(v)) => projection_of_radiance_view(v, w, h).map_err(view_err)?,
        (None, None) => {
            return Err(view_err(
                "the image names no projection (a candela EXR's `projection` attribute or a \
                 Radiance `VIEW=` line): glare needs to know each pixel's direction"
                    .into(),
            ))
        }
    };
    let valid = match projection {
        Projection::Fisheye { mapping, fov_deg } => {
            fov_deg > 0.0 && fov_deg <= mapping.max_fov_deg()
        }
        Projection::Perspective { vfov_deg } => vfov_deg > 0.0 && vfov_deg < 180.0,
        Projection::Equirectangular => true,
    };
    if !valid {
        return Err(view_err(format!(
            "the projection {} is outside its range",
            crate::camera::describe(projection)
        )));
    }
    let channel = |name: &str| {
        layers
            .channels
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.iter().map(|&x| x as f64).collect::<Vec<f64>>())
    };
    let luminance = channel(output::CHANNEL_Y)
        .ok_or_else(|| view_err("the image has no luminance channel `Y`".into()))?;
    let stderr = channel(output::CHANNEL_Y_STDERR);
    Ok(GlareImage::of_projection(
        projection, w, h, luminance, stderr,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn radiance_views_round_trip() {
        for p in [
            Projection::Fisheye {
                mapping: FisheyeMapping::Equidistant,
                fov_deg: 180.0,
            },
            Projection::Fisheye {
                mapping: FisheyeMapping::Orthographic,
                fov_deg: 160.0,
            },
            Projection::Fisheye {
                mapping: FisheyeMapping::Stereographic,
                fov_deg: 170.0,
            },
            Projection::Perspective { vfov_deg: 50.0 },
        ] {
            for (w, h) in [(64, 64), (96, 64)] {
                let Some(v) = crate::camera::radiance_view(
                    p,
                    (w, h),
                    [0.0; 3],
                    [0.0, 0.0, -1.0],
                    [0.0, 1.0, 0.0],
                ) else {
                    // A hemispherical fisheye whose wider side would pass 180° has no view.
                    assert!(
                        matches!(
                            p,
                            Projection::Fisheye {
                                mapping: FisheyeMapping::Orthographic,
                                ..
                            }
                        ) && w != h
                    );
                    continue;
                };
                let q = projection_of_radiance_view(&v, w, h).unwrap();
                let (a, b) = match (p, q) {
                    (
                        Projection::Fisheye {
                            fov_deg: a,
                            mapping: m1,
                        },
                        Projection::Fisheye {
                            fov_deg: b,
                            mapping: m2,
                        },
                    ) => {
                        assert_eq!(m1, m2);
                        (a, b)
                    }
                    (
                        Projection::Perspective { vfov_deg: a },
                        Projection::Perspective { vfov_deg: b },
                    ) => (a, b),
                    _ => panic!("{v}: {q:?}"),
                };
                assert!((a - b).abs() < 1e-4, "{v}: {a} vs {b}");
            }
        }
        assert!(projection_of_radiance_view("-vtc -vh 180 -vv 90", 10, 10).is_err());
        assert!(projection_of_radiance_view("-vta -vh nan", 10, 10).is_err());
        assert!(projection_of_radiance_view("-vp 0 0 0", 10, 10).is_err());
    }
}
