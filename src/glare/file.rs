//! A luminance image file as a [`GlareImage`]: candela's EXR (luminance `Y`, its standard
//! error `stderr.Y`, the camera's `projection` attribute) or a Radiance picture (`.hdr`, no
//! standard errors, the projection from its `VIEW=` line). Pixel directions and solid angles
//! come from the camera's projection ([`crate::camera::projection`]), in the view frame
//! (x right, y up, z the line of sight).

use super::image::radiance_view_pixels;
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

/// A Radiance view as the glare evaluation reads it: the options of a `VIEW=` line in order
/// (a later one overrides an earlier one), Radiance's defaults for those not given
/// (`-vd 0 1 0 -vu 0 0 1 -vh 45 -vv 45 -vs 0 -vl 0`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RadianceView {
    /// The view type letter: `a`, `h`, `s` or `v` (`-vta` …).
    pub kind: char,
    /// Full horizontal and vertical view angles, degrees.
    pub vh: f64,
    pub vv: f64,
    /// View direction and up vector as given.
    pub vd: [f64; 3],
    pub vu: [f64; 3],
    /// View shift and lift, in image widths and heights.
    pub vs: f64,
    pub vl: f64,
}

impl RadianceView {
    /// The up vector in the image's frame (x right, y up, z the line of sight), as given:
    /// `-vu`'s components across and along `-vd`.
    pub fn up_in_view_frame(&self) -> [f64; 3] {
        let n = |a: [f64; 3]| {
            let l = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
            a.map(|v| v / l)
        };
        let (d, u) = (n(self.vd), n(self.vu));
        let along = d[0] * u[0] + d[1] * u[1] + d[2] * u[2];
        [0.0, (1.0 - along * along).max(0.0).sqrt(), along]
    }
}

/// What each view type accepts: its name and the largest full angle (inclusive or not).
fn view_type(kind: char) -> Option<(&'static str, f64, bool)> {
    match kind {
        'a' => Some(("an angular fisheye (-vta)", 360.0, true)),
        'h' => Some(("a hemispherical fisheye (-vth)", 180.0, true)),
        's' => Some(("a stereographic fisheye (-vts)", 360.0, false)),
        'v' => Some(("a perspective view (-vtv)", 180.0, false)),
        _ => None,
    }
}

/// Reads and checks a Radiance view for a `width` × `height` picture: a supported type, angles
/// within what the type can show (Radiance's own limits), a direction and an up vector that
/// are finite, non-zero and not parallel, and square pixels (the angles in proportion to the
/// picture's sides, as `rpict` makes them). Errors name the offending option.
pub fn parse_radiance_view(
    view: &str,
    width: usize,
    height: usize,
) -> Result<RadianceView, String> {
    let words: Vec<&str> = view.split_whitespace().collect();
    let mut v = RadianceView {
        kind: '?',
        vh: 45.0,
        vv: 45.0,
        vd: [0.0, 1.0, 0.0],
        vu: [0.0, 0.0, 1.0],
        vs: 0.0,
        vl: 0.0,
    };
    let mut typed = false;
    let nums = |i: usize, n: usize, opt: &str| -> Result<Vec<f64>, String> {
        let got: Option<Vec<f64>> = (1..=n)
            .map(|k| {
                words
                    .get(i + k)
                    .and_then(|s| s.parse::<f64>().ok())
                    .filter(|x| x.is_finite())
            })
            .collect();
        got.ok_or_else(|| format!("VIEW option {opt} needs {n} finite number(s)"))
    };
    let mut i = 0;
    while i < words.len() {
        let w = words[i];
        match w {
            "-vp" | "-vd" | "-vu" => {
                let x = nums(i, 3, w)?;
                let x = [x[0], x[1], x[2]];
                if w == "-vd" {
                    v.vd = x;
                } else if w == "-vu" {
                    v.vu = x;
                }
                i += 3;
            }
            "-vh" | "-vv" | "-vs" | "-vl" | "-vo" | "-va" => {
                let x = nums(i, 1, w)?[0];
                match w {
                    "-vh" => v.vh = x,
                    "-vv" => v.vv = x,
                    "-vs" => v.vs = x,
                    "-vl" => v.vl = x,
                    _ => {}
                }
                i += 1;
            }
            "-vf" => return Err("VIEW option -vf (a view file) is not supported for glare".into()),
            _ => {
                if let Some(t) = w.strip_prefix("-vt") {
                    let mut c = t.chars();
                    match (c.next(), c.next()) {
                        (Some(k), None) => v.kind = k,
                        _ => return Err(format!("VIEW option {w} is not a view type")),
                    }
                    typed = true;
                }
            }
        }
        i += 1;
    }
    if !typed {
        return Err("the VIEW has no -vt type".into());
    }
    let Some((name, max, inclusive)) = view_type(v.kind) else {
        return Err(format!(
            "VIEW option -vt{}: this view type is not supported for glare",
            v.kind
        ));
    };
    for (opt, a) in [("-vh", v.vh), ("-vv", v.vv)] {
        let fits = if inclusive { a <= max } else { a < max };
        if !(a > 0.0 && fits) {
            let bound = if inclusive { "at most" } else { "less than" };
            return Err(format!(
                "VIEW option {opt} {a}: {name} shows an angle above 0° and {bound} {max}°"
            ));
        }
    }
    let len = |a: [f64; 3]| (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    if len(v.vd) <= 0.0 {
        return Err("VIEW option -vd is the zero vector".into());
    }
    let c = [
        v.vd[1] * v.vu[2] - v.vd[2] * v.vu[1],
        v.vd[2] * v.vu[0] - v.vd[0] * v.vu[2],
        v.vd[0] * v.vu[1] - v.vd[1] * v.vu[0],
    ];
    if len(c) <= 1e-9 * len(v.vd) * len(v.vu) {
        return Err("VIEW option -vu is zero or parallel to -vd: the view has no up".into());
    }
    if v.vs != 0.0 || v.vl != 0.0 {
        // evalglare's E_v of a shifted view differs from the shifted viewray's: not matched.
        return Err(format!(
            "VIEW options -vs {} -vl {}: shifted views are not supported for glare",
            v.vs, v.vl
        ));
    }
    // Square pixels: the image extent of each angle in proportion to the picture's side.
    let half = |deg: f64| 0.5 * deg.to_radians();
    let extent = |a: f64| match v.kind {
        'a' => a,
        'h' => half(a).sin(),
        's' => (0.5 * half(a)).tan(),
        _ => half(a).tan(),
    };
    let (w, h) = (width as f64, height as f64);
    let ratio = (extent(v.vh) / w) / (extent(v.vv) / h);
    // rpict rounds the resolution to whole pixels: half a pixel on the shorter side.
    let tol = 1.0 / w.min(h) + 1e-6;
    if !ratio.is_finite() || (ratio - 1.0).abs() > tol {
        return Err(format!(
            "VIEW options -vh {} -vv {} do not fit the {width}×{height} picture with square pixels \
             (their extents differ by a factor {ratio:.4})",
            v.vh, v.vv
        ));
    }
    Ok(v)
}

/// The projection of a Radiance view (`-vta`, `-vth`, `-vts`, `-vtv` with `-vh`, `-vv`) on a
/// `width` × `height` picture, as candela's cameras write it (a fisheye's circle spans the
/// shorter side). The view is checked as [`parse_radiance_view`] does.
pub fn projection_of_radiance_view(
    view: &str,
    width: usize,
    height: usize,
) -> Result<Projection, String> {
    let v = parse_radiance_view(view, width, height)?;
    let (w, h) = (width as f64, height as f64);
    let m = w.min(h);
    let half = |deg: f64| 0.5 * deg.to_radians();
    // The angle across the shorter side, from the angle across the width.
    let (a, k) = (v.vh, w / m);
    let p = match v.kind {
        'a' => Projection::Fisheye {
            mapping: FisheyeMapping::Equidistant,
            fov_deg: a / k,
        },
        'h' => Projection::Fisheye {
            mapping: FisheyeMapping::Orthographic,
            fov_deg: 2.0 * (half(a).sin() / k).asin().to_degrees(),
        },
        's' => Projection::Fisheye {
            mapping: FisheyeMapping::Stereographic,
            fov_deg: 4.0 * ((0.5 * half(a)).tan() / k).atan().to_degrees(),
        },
        _ => Projection::Perspective { vfov_deg: v.vv },
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
                // What is behind the eye is not seen (evalglare's rule for -vta), whatever
                // the projection shows there.
                let ok = map.pixel_inside(x, y) && d.is_some_and(|d| d[2] >= 0.0);
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
    // Checked before decoding: luminance (and its error) as f64, direction, solid angle and
    // the inside flag per pixel (the measured peak: the channels and 41 bytes a pixel).
    let beside = |names: &[&str]| 41 + 16 + 8 * names.contains(&output::CHANNEL_Y_STDERR) as u64;
    let layers = output::read_image_with(path, &beside)?;
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
    let view_text = attr(output::ATTRIBUTE_VIEW);
    let view = view_text
        .map(|v| {
            parse_radiance_view(v, w, h).map_err(|m| view_err(format!("{m} (VIEW= {})", v.trim())))
        })
        .transpose()?;
    let projection = match attr(output::ATTRIBUTE_PROJECTION) {
        Some(p) => {
            let projection = projection_of_attribute(p).map_err(view_err)?;
            let valid = match projection {
                Projection::Fisheye { mapping, fov_deg } => {
                    fov_deg > 0.0 && fov_deg <= mapping.max_fov_deg()
                }
                Projection::Perspective { vfov_deg } => vfov_deg > 0.0 && vfov_deg < 180.0,
                Projection::Equirectangular => true,
            };
            if !valid {
                return Err(view_err(format!(
                    "the projection attribute {} is outside its range",
                    crate::camera::describe(projection)
                )));
            }
            Some(projection)
        }
        None if view.is_some() => None,
        None => {
            return Err(view_err(
                "the image names no projection (a candela EXR's `projection` attribute or a \
                 Radiance `VIEW=` line): glare needs to know each pixel's direction"
                    .into(),
            ))
        }
    };
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
    let mut img = match (projection, view) {
        (Some(p), _) => GlareImage::of_projection(p, w, h, luminance, stderr),
        (None, Some(v)) => {
            // A Radiance picture: its pixels as evalglare takes them.
            let (direction, solid_angle_sr, inside) =
                radiance_view_pixels(v.kind, w, h, v.vh, v.vv, (v.vs, v.vl));
            GlareImage {
                width: w,
                height: h,
                luminance_cd_m2: luminance,
                stderr_cd_m2: stderr,
                direction,
                solid_angle_sr,
                inside,
                view_dir: [0.0, 0.0, 1.0],
                up: [0.0, 1.0, 0.0],
            }
        }
        (None, None) => unreachable!("checked above"),
    };
    if let Some(v) = view {
        img.up = v.up_in_view_frame();
    }
    if !(0..img.len()).any(|i| img.valid(i)) {
        return Err(view_err(
            "no pixel of the image is in view (in front of the eye, inside the projection)".into(),
        ));
    }
    Ok(img)
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
        // Views no projection can have, and views that do not fit the picture.
        for bad in [
            "-vth -vh 300 -vv 300",
            "-vth -vh 180 -vv 181",
            "-vtv -vh 400 -vv 400",
            "-vtv -vh 180 -vv 180",
            "-vta -vh 361 -vv 361",
            "-vts -vh 360 -vv 360",
            "-vta -vh -180 -vv -180",
            "-vta -vh 0 -vv 0",
            "-vta -vh 180 -vv nan",
            "-vta -vh 180 -vv 180 -vd 0 0 0",
            "-vta -vh 180 -vv 180 -vd 0 0 1 -vu 0 0 2",
            "-vta -vh 180 -vv 180 -vs 0.1",
            "-vta -vh 180 -vv 90",
            "-vta -vh 180",
            "-vtc -vh 180 -vv 180",
            "-vta -vh 180 -vv 180 -vd 1 0",
        ] {
            let e = parse_radiance_view(bad, 100, 100).unwrap_err();
            assert!(e.contains("VIEW"), "{bad}: {e}");
        }
        for good in [
            "-vta -vh 360 -vv 360",
            "-vth -vh 180 -vv 180",
            "-vts -vh 359 -vv 359",
            "-vtv -vh 179 -vv 179",
            "-vta -vh 180 -vv 180 -vd 0 -2 -1 -vu 0 0 1",
        ] {
            assert!(parse_radiance_view(good, 100, 100).is_ok(), "{good}");
        }
        // -vu as given in the image frame: 26.6° down with -vu 0 0 1.
        let v = parse_radiance_view("-vta -vh 180 -vv 180 -vd 0 2 -1 -vu 0 0 1", 9, 9).unwrap();
        let u = v.up_in_view_frame();
        assert!(
            (u[1] - 2.0 / 5f64.sqrt()).abs() < 1e-12 && (u[2] + 1.0 / 5f64.sqrt()).abs() < 1e-12
        );
    }
}
