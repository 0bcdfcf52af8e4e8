//! The world's lights, once the BVH exists: area emitters, the lights models bring, the
//! scene's lights and suns, and last its one sky (its ground reflects the suns).

use super::objects::Objects;
use crate::description::context::{Context, SceneError};
use crate::description::schema::*;
use crate::geometry::SceneGeometry;
use crate::light::{AreaLight, Light, LightFlags};

/// The lights in the order the world numbers them, and which of them are infinite.
#[derive(Default)]
pub(super) struct Lights {
    pub(super) lights: Vec<Light>,
    pub(super) infinite: Vec<u32>,
}

impl Lights {
    fn push(&mut self, light: Light) {
        if light.flags().contains(LightFlags::INFINITE) {
            self.infinite.push(self.lights.len() as u32);
        }
        self.lights.push(light);
    }
}

/// Every light of the scene: the area emitters `objects` holds (each object is told its
/// light), the lights its models bring, then `scene.lights` with the sky last.
pub(super) fn build_lights(
    ctx: &Context,
    scene: &SceneFile,
    objects: &mut Objects,
    geometry: &SceneGeometry,
) -> Result<Lights, SceneError> {
    let mut out = Lights::default();
    for (object, field, e, s) in std::mem::take(&mut objects.pending_area) {
        let light = AreaLight::build(ctx, &field, object, &e, &s, geometry)?;
        objects.objects[object as usize].light = Some(out.lights.len() as u32);
        out.lights.push(Light::Area(light));
    }
    let frame = site_frame(ctx, &scene.site)?;
    for (field, l) in &objects.model_lights {
        out.push(build_light(ctx, field, l)?);
    }
    let mut sky = None;
    let mut suns_horizontal = crate::spectrum::DenseSpectrum::constant(0.0);
    for (i, l) in scene.lights.iter().enumerate() {
        let field = format!("lights[{i}]");
        let light = match l {
            LightDesc::Sky { .. } | LightDesc::Weather { .. } => {
                if let Some((j, _)) = sky {
                    return Err(ctx.err(
                        &field,
                        format!("a scene has one sky, and lights[{j}] is one already"),
                    ));
                }
                sky = Some((i, l));
                continue;
            }
            LightDesc::Sun {
                sun,
                amount,
                spectrum,
            } => {
                let (s, _) = crate::light::SunLight::build(
                    ctx,
                    &field,
                    sun,
                    *amount,
                    spectrum.as_ref(),
                    &frame,
                )?;
                let h = s.horizontal_irradiance(&frame);
                for (a, b) in suns_horizontal.values.iter_mut().zip(h.values.iter()) {
                    *a += *b;
                }
                Light::Sun(s)
            }
            _ => build_light(ctx, &field, l)?,
        };
        out.push(light);
    }
    if let Some((i, l)) = sky {
        add_sky(ctx, i, l, &frame, &suns_horizontal, &mut out)?;
    }
    Ok(out)
}

/// The sky `lights[i]` (a `Sky`, or a `Weather` hour), and the sun of its Perez model.
fn add_sky(
    ctx: &Context,
    i: usize,
    l: &LightDesc,
    frame: &crate::light::SiteFrame,
    suns_horizontal: &crate::spectrum::DenseSpectrum,
    out: &mut Lights,
) -> Result<(), SceneError> {
    let field = format!("lights[{i}]");
    let weather;
    let desc = match l {
        LightDesc::Sky {
            model,
            sun,
            amount,
            spectrum,
            ground_reflectance,
            portals,
            sun_disk,
        } => crate::light::sky::SkyDesc {
            model,
            sun: sun.as_ref(),
            amount: *amount,
            spectrum: spectrum.as_ref(),
            ground_reflectance: *ground_reflectance,
            portals,
            sun_disk: *sun_disk,
        },
        LightDesc::Weather {
            file,
            time,
            spectrum,
            ground_reflectance,
            portals,
            sun_disk,
        } => {
            weather = crate::light::sky::weather_sky(ctx, &field, file, time)?;
            crate::light::sky::SkyDesc {
                model: &weather.0,
                sun: Some(&weather.1),
                amount: None,
                spectrum: spectrum.as_ref(),
                ground_reflectance: *ground_reflectance,
                portals,
                sun_disk: *sun_disk,
            }
        }
        _ => unreachable!("only a Sky or a Weather light is a sky"),
    };
    let (s, perez_sun) = crate::light::SkyLight::build(ctx, &field, &desc, frame, suns_horizontal)?;
    out.push(Light::Sky(Box::new(s)));
    if let Some(sun) = perez_sun {
        out.push(Light::Sun(sun));
    }
    Ok(())
}

/// The site's frame from `site`.
fn site_frame(ctx: &Context, site: &SiteDesc) -> Result<crate::light::SiteFrame, SceneError> {
    let up = ctx.unit("site.up", site.up)?.as_dvec3();
    let north = ctx.unit("site.north", site.north)?.as_dvec3();
    if up.normalize().cross(north.normalize()).length() < 1e-3 {
        return Err(ctx.err("site.north", "north is parallel to up"));
    }
    crate::light::SiteFrame::new(up, north)
        .ok_or_else(|| ctx.err("site.north", "north is parallel to up"))
}

fn build_light(ctx: &Context, field: &str, l: &LightDesc) -> Result<Light, SceneError> {
    use crate::light::*;
    Ok(match l {
        LightDesc::Point {
            position,
            spectrum,
            amount,
        } => Light::Point(PointLight::build(ctx, field, *position, spectrum, *amount)?),
        LightDesc::Spot {
            position,
            look_at,
            inner_deg,
            outer_deg,
            spectrum,
            amount,
        } => Light::Spot(SpotLight::build(
            ctx, field, *position, *look_at, *inner_deg, *outer_deg, spectrum, *amount,
        )?),
        LightDesc::Distant {
            direction,
            spectrum,
            amount,
        } => Light::Distant(DistantLight::build(
            ctx, field, *direction, spectrum, *amount,
        )?),
        LightDesc::Environment {
            spectrum,
            amount,
            portals,
        } => Light::Environment(EnvironmentLight::build(
            ctx, field, spectrum, *amount, portals,
        )?),
        LightDesc::Goniometric {
            file,
            position,
            rotate_deg,
            spectrum,
            lumens,
            multiplier,
        } => Light::Goniometric(Box::new(GoniometricLight::build(
            ctx,
            field,
            &goniometric::GoniometricDesc {
                file,
                position: *position,
                rotate_deg: *rotate_deg,
                spectrum,
                lumens: *lumens,
                multiplier: *multiplier,
            },
        )?)),
        LightDesc::Sky { .. } | LightDesc::Weather { .. } | LightDesc::Sun { .. } => {
            unreachable!("skies and suns are built beside the site's frame")
        }
    })
}
