//! The light-and-health channels as EXR layers, and the spectral bands as a spectral OpenEXR
//! in the layout of Fichet, Pacanowski and Wilkie, "An OpenEXR Layout for Spectral Images"
//! (JCGT 10(3), 2021), which colour-science reads with `read_spectral_image_Fichet2021`.

use super::Film;
use crate::output::{Layers, ILLUMINANCE_SENTINEL};

/// m-EDL, cd/m² (CIE S 026 melanopic equivalent daylight (D65) luminance).
pub const CHANNEL_M_EDL: &str = "melanopic.EDL";
pub const CHANNEL_M_EDL_STDERR: &str = "stderr.melanopic.EDL";
/// m-EDI, lx, on the surface seen (as `E`), [`ILLUMINANCE_SENTINEL`] where undefined.
pub const CHANNEL_M_EDI: &str = "melanopic.EDI";
pub const CHANNEL_M_EDI_STDERR: &str = "stderr.melanopic.EDI";
/// Scotopic luminance L_s, scotopic cd/m² (K′_m = 1700 lm/W).
pub const CHANNEL_SCOTOPIC: &str = "scotopic.L";
pub const CHANNEL_SCOTOPIC_STDERR: &str = "stderr.scotopic.L";
/// CIE 191 mesopic luminance, cd/m², and its adaptation coefficient m.
pub const CHANNEL_MESOPIC: &str = "mesopic.L";
pub const CHANNEL_MESOPIC_STDERR: &str = "stderr.mesopic.L";
pub const CHANNEL_MESOPIC_M: &str = "mesopic.m";

/// Add the film's light-and-health channels (if it keeps any) to its EXR layers.
pub fn add_health_layers(film: &Film, layers: &mut Layers) {
    let Some(h) = &film.health else {
        return;
    };
    let n = film.pixels.len();
    let mut push = |name: &str, f: &dyn Fn(usize) -> f32| {
        layers
            .channels
            .push((name.to_string(), (0..n).map(f).collect()));
    };
    let mut notes = Vec::new();
    if h.channels.melanopic {
        let v = |i: usize| {
            h.melanopic_edl(i, &film.pixels[i], film.pixel_batches)
                .unwrap_or_default()
        };
        push(CHANNEL_M_EDL, &|i| v(i).mean as f32);
        push(CHANNEL_M_EDL_STDERR, &|i| v(i).stderr as f32);
        notes.push("melanopic.EDL: melanopic equivalent daylight (D65) luminance m-EDL in cd/m^2 (CIE S 026), stderr.melanopic.EDL its standard error".to_string());
        if let Some(e) = &film.e {
            let v =
                |i: usize| h.melanopic_edi(i, &film.pixels[i], e[i].count_e, film.pixel_batches);
            push(CHANNEL_M_EDI, &|i| {
                v(i).map_or(ILLUMINANCE_SENTINEL, |v| v.mean as f32)
            });
            push(CHANNEL_M_EDI_STDERR, &|i| {
                v(i).map_or(0.0, |v| v.stderr as f32)
            });
            notes.push(format!("melanopic.EDI: melanopic equivalent daylight (D65) illuminance m-EDI in lx on the surface seen, as E ({ILLUMINANCE_SENTINEL} where undefined), stderr.melanopic.EDI its standard error"));
        }
    }
    if h.channels.mesopic {
        let s = |i: usize| {
            h.scotopic(i, &film.pixels[i], film.pixel_batches)
                .unwrap_or_default()
        };
        push(CHANNEL_SCOTOPIC, &|i| s(i).mean as f32);
        push(CHANNEL_SCOTOPIC_STDERR, &|i| s(i).stderr as f32);
        let m = |i: usize| {
            h.mesopic(i, &film.pixels[i], film.pixel_batches)
                .unwrap_or_default()
        };
        push(CHANNEL_MESOPIC, &|i| m(i).mean as f32);
        push(CHANNEL_MESOPIC_STDERR, &|i| m(i).stderr as f32);
        push(CHANNEL_MESOPIC_M, &|i| {
            let p = &film.pixels[i];
            let (lp, ls) = (p.mean_xyz()[1], s(i).mean);
            if lp > 0.0 {
                crate::colour::mesopic::mesopic_luminance(lp, ls / lp).m as f32
            } else {
                0.0
            }
        });
        notes.push("scotopic.L: scotopic luminance in scotopic cd/m^2 (K'm = 1700 lm/W); mesopic.L: CIE 191:2010 mesopic luminance in cd/m^2 from Y and S/P = scotopic.L / Y, mesopic.m its adaptation coefficient, stderr.mesopic.L its jackknife standard error over the batches".to_string());
    }
    if !notes.is_empty() {
        layers
            .attributes
            .push(("light_and_health".to_string(), notes.join("; ")));
    }
}

/// The name of a Fichet 2021 emissive channel at `nm` nanometres: `S0.550,000000nm` (the
/// layout writes the decimal separator as a comma).
pub fn fichet_channel_name(nm: f64) -> String {
    format!("S0.{}nm", format!("{nm:.6}").replace('.', ","))
}

/// The film's spectral bands as a Fichet 2021 emissive spectral image (None if it keeps no
/// bands): one channel per band centre holding the band's mean spectral radiance in
/// W·m⁻²·sr⁻¹·nm⁻¹, with the layout's attributes.
pub fn spectral_layers(film: &Film, scene: &str) -> Option<Layers> {
    let h = film
        .health
        .as_ref()
        .filter(|h| h.channels.spectral_bands > 0)?;
    let mut layers = Layers::new(film.width, film.height);
    let bands: Vec<Vec<f64>> = (0..film.pixels.len())
        .map(|i| h.bands(i, &film.pixels[i]))
        .collect();
    for (k, nm) in h.band_centres_nm().into_iter().enumerate() {
        layers.channels.push((
            fichet_channel_name(nm),
            bands.iter().map(|b| b[k] as f32).collect(),
        ));
    }
    let width = (super::BANDS_END_NM - super::BANDS_START_NM) / h.channels.spectral_bands as f64;
    layers.attributes.extend([
        ("spectralLayoutVersion".to_string(), "1.0".to_string()),
        ("emissiveUnits".to_string(), "W.m^-2.sr^-1".to_string()),
        (
            "software".to_string(),
            format!("candela {}", env!("CARGO_PKG_VERSION")),
        ),
        ("scene".to_string(), scene.to_string()),
        (
            "spectral_bands".to_string(),
            format!(
                "{} bands of {width} nm from {} to {} nm; each channel holds the band's mean spectral radiance in W.m^-2.sr^-1.nm^-1 at its centre wavelength",
                h.channels.spectral_bands,
                super::BANDS_START_NM,
                super::BANDS_END_NM
            ),
        ),
    ]);
    Some(layers)
}

/// Read a spectral EXR written by [`spectral_layers`]: band centres (nm) and, per band, the
/// pixels' spectral radiance (W·m⁻²·sr⁻¹·nm⁻¹), sorted by wavelength.
pub fn read_spectral_bands(layers: &Layers) -> (Vec<f64>, Vec<Vec<f32>>) {
    let mut bands: Vec<(f64, Vec<f32>)> = layers
        .channels
        .iter()
        .filter_map(|(name, v)| {
            let nm = name.strip_prefix("S0.")?.strip_suffix("nm")?;
            let nm: f64 = nm.replace(',', ".").parse().ok()?;
            Some((nm, v.clone()))
        })
        .collect();
    bands.sort_by(|a, b| a.0.total_cmp(&b.0));
    bands.into_iter().unzip()
}
