//! EULUMDAT (`.ldt`): one field per line, luminous intensities in cd/klm of lamp flux,
//! type C photometry, symmetry indicator Isym 0 (none), 1 (rotational), 2 (C0–C180 plane),
//! 3 (C90–C270 plane), 4 (both planes). A decimal comma is accepted.
//!
//! Absolute candela = value × (Σ over lamp sets of the sets' total lamp flux) / 1000 ×
//! the conversion factor (line 24). The stated luminaire flux is that lamp flux × LOR.

use super::{Format, Kind, ParseError, Photometry, Symmetry};
use std::fmt::Write as _;
use std::path::Path;

const MAX_PLANES: usize = 3600;
const MAX_ANGLES: usize = 3600;

struct Lines<'a> {
    lines: Vec<&'a str>,
    pos: usize,
    file: &'a Path,
}

impl<'a> Lines<'a> {
    fn err(&self, line: usize, field: &str, message: impl Into<String>) -> ParseError {
        ParseError {
            file: self.file.to_path_buf(),
            line,
            field: field.to_string(),
            message: message.into(),
        }
    }
    fn text(&mut self, field: &str) -> Result<(usize, &'a str), ParseError> {
        match self.lines.get(self.pos) {
            Some(l) => {
                self.pos += 1;
                Ok((self.pos, l.trim()))
            }
            None => Err(self.err(
                self.lines.len().max(1),
                field,
                "unexpected end of file (the file is truncated or a count is too large)",
            )),
        }
    }
    fn num(&mut self, field: &str) -> Result<(usize, f64), ParseError> {
        let (line, s) = self.text(field)?;
        let cleaned = s.replace(',', ".");
        match cleaned.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok((line, v)),
            Ok(v) => Err(self.err(line, field, format!("{v} is not a finite number"))),
            Err(_) => Err(self.err(line, field, format!("{s:?} is not a number"))),
        }
    }
    fn int(&mut self, field: &str, lo: i64, hi: i64) -> Result<(usize, i64), ParseError> {
        let (line, v) = self.num(field)?;
        if v.fract() != 0.0 || v < lo as f64 || v > hi as f64 {
            return Err(self.err(
                line,
                field,
                format!("{v} is not a whole number in {lo}…{hi}"),
            ));
        }
        Ok((line, v as i64))
    }
}

/// Parse the text of a EULUMDAT file; `file` is used in messages.
pub fn parse(text: &str, file: &Path) -> Result<Photometry, ParseError> {
    let mut l = Lines {
        lines: text.lines().collect(),
        pos: 0,
        file,
    };
    let mut header = Vec::new();
    let h = Head::read(&mut l, &mut header)?;
    let (lamp_flux, lor, conversion) = read_lamps(&mut l, &mut header)?;
    let (mc, ng) = (h.mc as usize, h.ng as usize);
    let c_angles = read_angles(&mut l, mc, "C angle")?;
    let g_angles = read_angles(&mut l, ng, "gamma angle")?;
    if c_angles[0] < 0.0 || c_angles[mc - 1] >= 360.0 {
        return Err(l.err(h.mc_line, "C angles", "C angles must lie in 0…<360°"));
    }
    if g_angles[0] < 0.0 || g_angles[ng - 1] > 180.0 {
        return Err(l.err(h.mc_line, "gamma angles", "gamma angles must lie in 0…180°"));
    }
    let (symmetry, planes) = tabulated_planes(&l, &h, &c_angles)?;
    let scale = lamp_flux / 1000.0 * conversion;
    let candela = read_intensities(&mut l, &planes, &g_angles, scale)?;
    let stated = (lamp_flux > 0.0).then_some(lamp_flux * lor / 100.0 * conversion);
    Ok(Photometry {
        format: Format::Eulumdat,
        header,
        kind: Kind::C,
        symmetry,
        planes,
        angles: g_angles,
        candela,
        stated_lumens: stated,
        size_m: [h.dims[0] / 1000.0, h.dims[1] / 1000.0, h.dims[2] / 1000.0],
    })
}

/// The lines before the lamp sets: identification, symmetry, counts of planes and angles,
/// dimensions.
struct Head {
    isym_line: usize,
    isym: i64,
    mc_line: usize,
    mc: i64,
    ng: i64,
    /// Luminaire length, width, height, then the luminous area's, mm.
    dims: [f64; 9],
}

impl Head {
    fn read(l: &mut Lines, header: &mut Vec<(String, String)>) -> Result<Self, ParseError> {
        let (_, company) = l.text("company identification")?;
        header.push(("company".to_string(), company.to_string()));
        let (_, ityp) = l.int("type indicator Ityp", 0, 3)?;
        let (isym_line, isym) = l.int("symmetry indicator Isym", 0, 4)?;
        let (mc_line, mc) = l.int("number of C planes Mc", 1, MAX_PLANES as i64)?;
        let _ = l.num("distance between C planes Dc")?;
        let (_, ng) = l.int("number of intensities per plane Ng", 1, MAX_ANGLES as i64)?;
        let _ = l.num("distance between angles Dg")?;
        for name in [
            "measurement report number",
            "luminaire name",
            "luminaire number",
            "file name",
            "date/user",
        ] {
            let (_, v) = l.text(name)?;
            header.push((name.to_string(), v.to_string()));
        }
        header.push(("type indicator".into(), ityp.to_string()));
        let mut dims = [0.0; 9];
        for (k, name) in [
            "length/diameter of luminaire (mm)",
            "width of luminaire (mm)",
            "height of luminaire (mm)",
            "length/diameter of luminous area (mm)",
            "width of luminous area (mm)",
            "height of luminous area C0 (mm)",
            "height of luminous area C90 (mm)",
            "height of luminous area C180 (mm)",
            "height of luminous area C270 (mm)",
        ]
        .iter()
        .enumerate()
        {
            dims[k] = l.num(name)?.1;
        }
        Ok(Self {
            isym_line,
            isym,
            mc_line,
            mc,
            ng,
            dims,
        })
    }
}

/// From the downward flux fraction to the direct ratios: the lamps' total flux (lm), the light
/// output ratio (%) and the conversion factor of the intensities.
fn read_lamps(
    l: &mut Lines,
    header: &mut Vec<(String, String)>,
) -> Result<(f64, f64, f64), ParseError> {
    let _ = l.num("downward flux fraction DFF (%)")?;
    let (lor_line, lor) = l.num("light output ratio LORL (%)")?;
    if lor < 0.0 {
        return Err(l.err(
            lor_line,
            "light output ratio LORL (%)",
            format!("{lor} is negative"),
        ));
    }
    let (cf_line, conversion) = l.num("conversion factor for luminous intensities")?;
    if conversion <= 0.0 {
        return Err(l.err(
            cf_line,
            "conversion factor for luminous intensities",
            format!("{conversion} is not positive"),
        ));
    }
    let _ = l.num("tilt of luminaire during measurement")?;
    let (_, nsets) = l.int("number of standard sets of lamps n", 0, 20)?;
    let mut lamp_flux = 0.0;
    for k in 1..=nsets {
        let _ = l.text(&format!("number of lamps (set {k})"))?;
        let (_, ty) = l.text(&format!("type of lamps (set {k})"))?;
        header.push((format!("lamp type (set {k})"), ty.to_string()));
        let field = format!("total luminous flux of lamps (set {k}) (lm)");
        let (line, f) = l.num(&field)?;
        if f < 0.0 {
            return Err(l.err(line, &field, format!("{f} is negative")));
        }
        lamp_flux += f;
        let (_, cct) = l.text(&format!("colour temperature (set {k})"))?;
        header.push((format!("colour appearance (set {k})"), cct.to_string()));
        let _ = l.text(&format!("colour rendering (set {k})"))?;
        let _ = l.text(&format!("wattage including ballast (set {k}) (W)"))?;
    }
    for k in 1..=10 {
        let _ = l.num(&format!("direct ratio {k}"))?;
    }
    Ok((lamp_flux, lor, conversion))
}

/// `n` strictly increasing angles, one a line, named `what` and their number in messages.
fn read_angles(l: &mut Lines, n: usize, what: &str) -> Result<Vec<f64>, ParseError> {
    let mut out: Vec<f64> = Vec::with_capacity(n);
    for k in 0..n {
        let field = format!("{what} {}", k + 1);
        let (line, v) = l.num(&field)?;
        if let Some(&prev) = out.last() {
            if v <= prev {
                return Err(l.err(
                    line,
                    &field,
                    format!(
                        "angles out of order: {v}° does not follow {prev}° (angles must increase)"
                    ),
                ));
            }
        }
        out.push(v);
    }
    Ok(out)
}

/// The symmetry of Isym and the C planes whose intensities the file holds, which must include
/// the planes that symmetry needs.
fn tabulated_planes(
    l: &Lines,
    h: &Head,
    c_angles: &[f64],
) -> Result<(Symmetry, Vec<f64>), ParseError> {
    let pick = |lo: f64, hi: f64| -> Vec<f64> {
        c_angles
            .iter()
            .copied()
            .filter(|&c| c >= lo - 1e-6 && c <= hi + 1e-6)
            .collect()
    };
    let (symmetry, planes) = match h.isym {
        0 => (Symmetry::None, c_angles.to_vec()),
        1 => (Symmetry::Rotational, vec![0.0]),
        2 => (Symmetry::C0C180, pick(0.0, 180.0)),
        3 => (Symmetry::C90C270, pick(90.0, 270.0)),
        _ => (Symmetry::Quadrant, pick(0.0, 90.0)),
    };
    let need_ends = |a: f64, b: f64| {
        planes.first().is_some_and(|&p| (p - a).abs() < 1e-6)
            && planes.last().is_some_and(|&p| (p - b).abs() < 1e-6)
    };
    let ok = match symmetry {
        Symmetry::C0C180 => need_ends(0.0, 180.0),
        Symmetry::C90C270 => need_ends(90.0, 270.0),
        Symmetry::Quadrant => need_ends(0.0, 90.0),
        Symmetry::None => c_angles[0].abs() < 1e-6,
        _ => true,
    };
    if !ok {
        return Err(l.err(
            h.isym_line,
            "symmetry indicator Isym",
            format!(
                "the C angles {}…{}° do not contain the planes Isym {} needs",
                c_angles[0],
                c_angles[c_angles.len() - 1],
                h.isym
            ),
        ));
    }
    Ok((symmetry, planes))
}

/// The intensities of `planes` × `g_angles`, times `scale`; nothing but blank lines may follow.
fn read_intensities(
    l: &mut Lines,
    planes: &[f64],
    g_angles: &[f64],
    scale: f64,
) -> Result<Vec<Vec<f64>>, ParseError> {
    let ng = g_angles.len();
    let mut candela = Vec::with_capacity(planes.len());
    for (i, &c) in planes.iter().enumerate() {
        let mut row = Vec::with_capacity(ng);
        for (j, &g) in g_angles.iter().enumerate() {
            let field = format!("intensity {} (C {c}°, γ {g}°)", i * ng + j + 1);
            let (line, v) = l.num(&field)?;
            if v < 0.0 {
                return Err(l.err(line, &field, format!("negative intensity {v}")));
            }
            row.push(v * scale);
        }
        candela.push(row);
    }
    if let Some((k, extra)) = l.lines[l.pos..]
        .iter()
        .enumerate()
        .find(|(_, s)| !s.trim().is_empty())
    {
        return Err(l.err(
            l.pos + k + 1,
            "end of intensity table",
            format!(
                "unexpected extra line {:?} after the intensities (wrong Mc, Ng or Isym?)",
                extra.trim()
            ),
        ));
    }
    Ok(candela)
}

/// Write a type C photometry as EULUMDAT: one lamp set whose flux is the stated flux (or the
/// integrated flux), LOR 100 %, intensities in cd/klm of that flux, C planes as tabulated plus
/// their mirror images where Isym needs a full Mc.
pub fn write(p: &Photometry) -> Result<String, String> {
    if p.kind != Kind::C {
        return Err("EULUMDAT holds type C photometry only".into());
    }
    let flux = p
        .stated_lumens
        .unwrap_or_else(|| p.distribution().lumens())
        .max(1e-9);
    let isym = match p.symmetry {
        Symmetry::None => 0,
        Symmetry::Rotational => 1,
        Symmetry::C0C180 => 2,
        Symmetry::C90C270 => 3,
        Symmetry::Quadrant => 4,
        Symmetry::Lateral => return Err("lateral symmetry is type A/B only".into()),
    };
    // Full C-angle list (Mc planes over 0…<360).
    let full = p.distribution();
    let c_all: Vec<f64> = full
        .planes
        .iter()
        .copied()
        .filter(|&c| c < 360.0 - 1e-9)
        .collect();
    let c_all = if isym == 1 { vec![0.0] } else { c_all };
    let mc = c_all.len();
    let name = p
        .header
        .iter()
        .find(|(k, _)| k == "LUMINAIRE" || k == "luminaire name")
        .map(|(_, v)| v.as_str())
        .unwrap_or("candela luminaire");
    let mut s = String::new();
    let mut w = |v: String| {
        s.push_str(&v);
        s.push_str("\r\n");
    };
    w("candela (written by the project)".into());
    w("1".into());
    w(isym.to_string());
    w(mc.to_string());
    w("0".into());
    w(p.angles.len().to_string());
    w("0".into());
    w("".into());
    w(name.to_string());
    w("".into());
    w("".into());
    w("".into());
    let [length, width, height] = p.size_m;
    for v in [length, width, height, length, width, 0.0, 0.0, 0.0, 0.0] {
        w(format!("{}", v * 1000.0));
    }
    w("100".into());
    w("100".into());
    w("1".into());
    w("0".into());
    w("1".into());
    w("1".into());
    w("LED".into());
    w(format!("{flux}"));
    w("".into());
    w("".into());
    w("0".into());
    for _ in 0..10 {
        w("0".into());
    }
    for c in &c_all {
        w(format!("{c}"));
    }
    for g in &p.angles {
        w(format!("{g}"));
    }
    for (row, &c) in p.candela.iter().zip(&p.planes) {
        if isym == 0 && c >= 360.0 - 1e-9 {
            continue; // C360 is C0 again; EULUMDAT lists 0…<360
        }
        for v in row {
            w(format!("{}", v * 1000.0 / flux));
        }
    }
    let mut out = String::new();
    let _ = write!(out, "{s}");
    Ok(out)
}
