//! IES LM-63 photometric files: 1986 (no version line), 1991 (`IESNA91`), 1995
//! (`IESNA:LM-63-1995`), 2002 (`IESNA:LM-63-2002`) and 2019 (`IES:LM-63-2019`);
//! `TILT=NONE` and `TILT=INCLUDE`; photometric types A, B and C with every symmetry.
//!
//! Candela are multiplied by the candela multiplier, the ballast factor, the ballast-lamp
//! photometric factor (1991/1995 only; the field is "future use" in 2002 and the file
//! generation type in 2019) and, with a tilt table, the tilt factor at 0° (the luminaire as
//! photometered).

use super::{Format, Kind, ParseError, Photometry, Symmetry};
use std::fmt::Write as _;
use std::path::Path;

/// Largest table accepted (planes × angles), so a corrupt count cannot exhaust memory.
pub const MAX_VALUES: usize = 4_000_000;

struct Tokens<'a> {
    toks: Vec<(usize, &'a str)>,
    pos: usize,
    file: &'a Path,
    last_line: usize,
}

impl<'a> Tokens<'a> {
    fn err(&self, line: usize, field: &str, message: impl Into<String>) -> ParseError {
        ParseError {
            file: self.file.to_path_buf(),
            line,
            field: field.to_string(),
            message: message.into(),
        }
    }
    fn next_raw(&mut self, field: &str) -> Result<(usize, &'a str), ParseError> {
        match self.toks.get(self.pos) {
            Some(&t) => {
                self.pos += 1;
                Ok(t)
            }
            None => Err(self.err(
                self.last_line,
                field,
                "unexpected end of file (the table is truncated or a count is too large)",
            )),
        }
    }
    fn num(&mut self, field: &str) -> Result<(usize, f64), ParseError> {
        let (line, s) = self.next_raw(field)?;
        match s.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok((line, v)),
            Ok(v) => Err(self.err(line, field, format!("{v} is not a finite number"))),
            Err(_) => Err(self.err(line, field, format!("{s:?} is not a number"))),
        }
    }
    fn count(&mut self, field: &str) -> Result<(usize, usize), ParseError> {
        let (line, v) = self.num(field)?;
        if v < 1.0 || v.fract() != 0.0 || v > MAX_VALUES as f64 {
            return Err(self.err(
                line,
                field,
                format!("{v} is not a positive whole number (at most {MAX_VALUES})"),
            ));
        }
        Ok((line, v as usize))
    }
    fn int_in(&mut self, field: &str, allowed: &[i64]) -> Result<(usize, i64), ParseError> {
        let (line, v) = self.num(field)?;
        match allowed.iter().find(|&&a| a as f64 == v) {
            Some(&a) => Ok((line, a)),
            None => Err(self.err(line, field, format!("{v} is not one of {allowed:?}"))),
        }
    }
    /// Room for `n` values, but no more than the file has left: a corrupt count then ends in
    /// "unexpected end of file", not in a large allocation.
    fn capacity(&self, n: usize) -> usize {
        n.min(self.toks.len().saturating_sub(self.pos))
    }
    fn angles(&mut self, n: usize, what: &str) -> Result<Vec<(usize, f64)>, ParseError> {
        let mut out: Vec<(usize, f64)> = Vec::with_capacity(self.capacity(n));
        for k in 0..n {
            let field = format!("{what} angle {}", k + 1);
            let (line, v) = self.num(&field)?;
            if let Some(&(_, prev)) = out.last() {
                if v <= prev {
                    return Err(self.err(
                        line,
                        &field,
                        format!("angles out of order: {v}° does not follow {prev}° (angles must increase)"),
                    ));
                }
            }
            out.push((line, v));
        }
        Ok(out)
    }
}

/// Parse the text of an IES file; `file` is used in messages.
pub fn parse(text: &str, file: &Path) -> Result<Photometry, ParseError> {
    let lines: Vec<&str> = text.lines().collect();
    let version = version(&lines, file)?;
    let start = usize::from(version != "LM-63-1986");
    let (header, tilt_idx, tilt) = header_and_tilt(&lines, start, file)?;
    let mut t = Tokens {
        toks: tokens(&lines, tilt_idx + 1),
        pos: 0,
        file,
        last_line: lines.len().max(1),
    };
    let tilt_factor = tilt_factor(&mut t, &tilt, tilt_idx)?;
    let f = Fields::read(&mut t, &version)?;
    let vert = t.angles(f.nv, "vertical")?;
    let horiz = t.angles(f.nh, "horizontal")?;
    let kind = match f.ptype {
        1 => Kind::C,
        2 => Kind::B,
        _ => Kind::A,
    };
    let symmetry = symmetry(&t, kind, &vert, &horiz)?;
    let scale = f.multiplier * f.ballast * f.blpf * tilt_factor;
    let candela = candela_table(&mut t, &horiz, &vert, scale)?;
    let stated_lumens = (f.lumens_per_lamp > 0.0 && f.lamps > 0.0)
        .then_some(f.lamps * f.lumens_per_lamp * f.ballast * f.blpf * tilt_factor);
    let to_m = if f.units == 1 { 0.3048 } else { 1.0 };
    Ok(Photometry {
        format: Format::Ies(version),
        header,
        kind,
        symmetry,
        planes: horiz.iter().map(|a| a.1).collect(),
        angles: vert.iter().map(|a| a.1).collect(),
        candela,
        stated_lumens,
        size_m: [
            f.length.abs() * to_m,
            f.width.abs() * to_m,
            f.height.abs() * to_m,
        ],
    })
}

fn line_err(file: &Path, line: usize, field: &str, message: String) -> ParseError {
    ParseError {
        file: file.to_path_buf(),
        line,
        field: field.to_string(),
        message,
    }
}

/// The LM-63 version the first line names (`LM-63-1986` when it names none).
fn version(lines: &[&str], file: &Path) -> Result<String, ParseError> {
    let first = lines.first().map(|l| l.trim()).unwrap_or("");
    if !(first.starts_with("IESNA") || first.starts_with("IES:")) {
        return Ok("LM-63-1986".to_string());
    }
    let v = if first == "IESNA91" {
        "LM-63-1991".to_string()
    } else {
        first.split(':').nth(1).unwrap_or(first).trim().to_string()
    };
    let known = ["LM-63-1991", "LM-63-1995", "LM-63-2002", "LM-63-2019"];
    if !known.contains(&v.as_str()) {
        return Err(line_err(
            file,
            1,
            "format line",
            format!("unknown IES version {first:?} (known: IESNA91, IESNA:LM-63-1995, IESNA:LM-63-2002, IES:LM-63-2019, or none for 1986)"),
        ));
    }
    Ok(v)
}

/// The header's keyword lines (`[MORE]` joined to the one before) and free text from line
/// `start`, then the index of the `TILT=` line and its value.
#[allow(clippy::type_complexity)]
fn header_and_tilt(
    lines: &[&str],
    start: usize,
    file: &Path,
) -> Result<(Vec<(String, String)>, usize, String), ParseError> {
    let mut header: Vec<(String, String)> = Vec::new();
    for (k, raw) in lines.iter().enumerate().skip(start) {
        let l = raw.trim();
        if let Some(rest) = l.strip_prefix("TILT") {
            let rest = rest.trim_start();
            let Some(v) = rest.strip_prefix('=') else {
                return Err(line_err(
                    file,
                    k + 1,
                    "TILT",
                    format!("expected TILT=…, got {l:?}"),
                ));
            };
            return Ok((header, k, v.trim().to_string()));
        }
        if let Some(rest) = l.strip_prefix('[') {
            if let Some(end) = rest.find(']') {
                let key = rest[..end].trim().to_string();
                let value = rest[end + 1..].trim().to_string();
                if key == "MORE" {
                    if let Some(last) = header.last_mut() {
                        last.1.push('\n');
                        last.1.push_str(&value);
                        continue;
                    }
                }
                header.push((key, value));
                continue;
            }
        }
        if !l.is_empty() {
            header.push((String::new(), l.to_string()));
        }
    }
    Err(line_err(
        file,
        lines.len().max(1),
        "TILT",
        "no TILT= line: the file ends before the photometric data".into(),
    ))
}

/// The numbers from line index `from` on, each with its 1-based line (whitespace or commas
/// separate them).
fn tokens<'a>(lines: &[&'a str], from: usize) -> Vec<(usize, &'a str)> {
    lines
        .iter()
        .enumerate()
        .skip(from)
        .flat_map(|(k, l)| {
            l.split(|c: char| c.is_whitespace() || c == ',')
                .filter(|s| !s.is_empty())
                .map(move |s| (k + 1, s))
        })
        .collect()
}

/// The tilt factor at 0° of `TILT=tilt` (line index `tilt_idx`): 1 without a table.
fn tilt_factor(t: &mut Tokens, tilt: &str, tilt_idx: usize) -> Result<f64, ParseError> {
    match tilt.to_ascii_uppercase().as_str() {
        "NONE" => Ok(1.0),
        "INCLUDE" => {
            t.int_in("lamp-to-luminaire geometry", &[1, 2, 3])?;
            let (_, n) = t.count("number of tilt angles")?;
            let angles = t.angles(n, "tilt")?;
            let mut factors = Vec::with_capacity(t.capacity(n));
            for k in 0..n {
                let field = format!("tilt multiplying factor {}", k + 1);
                let (line, v) = t.num(&field)?;
                if v < 0.0 {
                    return Err(t.err(line, &field, format!("{v} is negative")));
                }
                factors.push(v);
            }
            let xs: Vec<f64> = angles.iter().map(|a| a.1).collect();
            match super::bracket(&xs, 0.0) {
                Some((i, s)) if i + 1 < n => Ok(factors[i] * (1.0 - s) + factors[i + 1] * s),
                Some((i, _)) => Ok(factors[i]),
                None => Err(t.err(
                    angles[0].0,
                    "tilt angle 1",
                    "the tilt table does not cover 0° (the luminaire as photometered)",
                )),
            }
        }
        other => Err(t.err(
            tilt_idx + 1,
            "TILT",
            format!("TILT={other}: tilt data in a separate file is not supported; use TILT=NONE or TILT=INCLUDE"),
        )),
    }
}

/// The numbers between the tilt data and the angles.
struct Fields {
    lamps: f64,
    lumens_per_lamp: f64,
    multiplier: f64,
    nv: usize,
    nh: usize,
    ptype: i64,
    units: i64,
    width: f64,
    length: f64,
    height: f64,
    ballast: f64,
    /// The ballast-lamp photometric factor (1 where the version gives the field another use).
    blpf: f64,
}

impl Fields {
    fn read(t: &mut Tokens, version: &str) -> Result<Self, ParseError> {
        let non_negative = |t: &Tokens, (line, v): (usize, f64), field: &str| {
            if v < 0.0 {
                return Err(t.err(line, field, format!("{v} is negative")));
            }
            Ok(v)
        };
        let (_, lamps) = t.num("number of lamps")?;
        let (_, lumens_per_lamp) = t.num("lumens per lamp")?;
        let m = t.num("candela multiplier")?;
        let multiplier = non_negative(t, m, "candela multiplier")?;
        let (_, nv) = t.count("number of vertical angles")?;
        let (nhl, nh) = t.count("number of horizontal angles")?;
        if nv.saturating_mul(nh) > MAX_VALUES {
            return Err(t.err(
                nhl,
                "number of horizontal angles",
                format!("{nh} × {nv} values exceed the limit of {MAX_VALUES}"),
            ));
        }
        let (_, ptype) = t.int_in("photometric type", &[1, 2, 3])?;
        let (_, units) = t.int_in("units type", &[1, 2])?;
        let (_, width) = t.num("width")?;
        let (_, length) = t.num("length")?;
        let (_, height) = t.num("height")?;
        let b = t.num("ballast factor")?;
        let ballast = non_negative(t, b, "ballast factor")?;
        let future = t.num(if version == "LM-63-2019" {
            "file generation type"
        } else {
            "ballast-lamp photometric factor"
        })?;
        let blpf = if ["LM-63-1991", "LM-63-1995", "LM-63-1986"].contains(&version) {
            non_negative(t, future, "ballast-lamp photometric factor")?
        } else {
            1.0
        };
        let (_, _watts) = t.num("input watts")?;
        Ok(Self {
            lamps,
            lumens_per_lamp,
            multiplier,
            nv,
            nh,
            ptype,
            units,
            width,
            length,
            height,
            ballast,
            blpf,
        })
    }
}

/// The symmetry the angles' ranges give a photometry of `kind`.
fn symmetry(
    t: &Tokens,
    kind: Kind,
    vert: &[(usize, f64)],
    horiz: &[(usize, f64)],
) -> Result<Symmetry, ParseError> {
    let (nh, v0, v1) = (horiz.len(), vert[0].1, vert[vert.len() - 1].1);
    let (h0, h1) = (horiz[0].1, horiz[nh - 1].1);
    let bad_v = |msg: &str| Err(t.err(vert[0].0, "vertical angle 1", msg));
    let bad_h = |msg: String| Err(t.err(horiz[0].0, "horizontal angle 1", msg));
    match kind {
        Kind::C => {
            if v0 < -ANGLE_TOL || v1 > 180.0 + ANGLE_TOL {
                return bad_v("type C vertical angles must lie in 0…180°");
            }
            let near = |a: f64, b: f64| (a - b).abs() < ANGLE_TOL;
            if nh == 1 {
                Ok(Symmetry::Rotational)
            } else if near(h0, 0.0) && near(h1, 90.0) {
                Ok(Symmetry::Quadrant)
            } else if near(h0, 0.0) && near(h1, 180.0) {
                Ok(Symmetry::C0C180)
            } else if near(h0, 90.0) && near(h1, 270.0) {
                Ok(Symmetry::C90C270)
            } else if near(h0, 0.0) && h1 > 180.0 && h1 <= 360.0 + ANGLE_TOL {
                Ok(Symmetry::None)
            } else {
                bad_h(format!(
                    "type C horizontal angles {h0}…{h1}° are not one of 0 (rotational), 0…90, 0…180, 90…270 or 0…360"
                ))
            }
        }
        Kind::A | Kind::B => {
            if v0 < -90.0 - ANGLE_TOL || v1 > 90.0 + ANGLE_TOL {
                return bad_v("type A/B vertical angles must lie in −90…90°");
            }
            if h0 < -90.0 - ANGLE_TOL || h1 > 90.0 + ANGLE_TOL {
                return bad_h("type A/B horizontal angles must lie in −90…90°".into());
            }
            if h0.abs() < ANGLE_TOL && nh > 1 {
                Ok(Symmetry::Lateral)
            } else if nh == 1 {
                bad_h("type A/B photometry needs at least two horizontal angles".into())
            } else {
                Ok(Symmetry::None)
            }
        }
    }
}

/// The candela table, a row per horizontal angle, times `scale`; nothing may follow it.
fn candela_table(
    t: &mut Tokens,
    horiz: &[(usize, f64)],
    vert: &[(usize, f64)],
    scale: f64,
) -> Result<Vec<Vec<f64>>, ParseError> {
    let nv = vert.len();
    let mut candela = Vec::with_capacity(horiz.len());
    for (i, &(_, h)) in horiz.iter().enumerate() {
        let mut row = Vec::with_capacity(t.capacity(nv));
        for (j, &(_, v)) in vert.iter().enumerate() {
            let field = format!(
                "candela value {} of horizontal angle {} ({h}°), vertical angle {v}°",
                i * nv + j + 1,
                i + 1
            );
            let (line, c) = t.num(&field)?;
            if c < 0.0 {
                return Err(t.err(line, &field, format!("negative candela {c}")));
            }
            row.push(c * scale);
        }
        candela.push(row);
    }
    if let Some(&(line, s)) = t.toks.get(t.pos) {
        return Err(t.err(
            line,
            "end of candela table",
            format!(
                "unexpected extra value {s:?} after the {} candela values (wrong count of angles?)",
                horiz.len() * nv
            ),
        ));
    }
    Ok(candela)
}

const ANGLE_TOL: f64 = 1e-6;

/// Write a photometry as IES LM-63-2002 (`TILT=NONE`, metres). Relative photometry with one
/// lamp of `stated_lumens` when the photometry states a flux, absolute (−1) otherwise. Numbers
/// are written with Rust's shortest round-trip representation, so reading the file back gives
/// the same candela exactly.
pub fn write(p: &Photometry) -> String {
    let mut s = String::from("IESNA:LM-63-2002\n");
    for (k, v) in &p.header {
        if k.is_empty() {
            continue;
        }
        for (n, part) in v.split('\n').enumerate() {
            let key = if n == 0 { k.as_str() } else { "MORE" };
            let _ = writeln!(s, "[{key}] {part}");
        }
    }
    s.push_str("TILT=NONE\n");
    let (lamps, lumens) = match p.stated_lumens {
        Some(l) => (1, l),
        None => (1, -1.0),
    };
    let ptype = match p.kind {
        Kind::C => 1,
        Kind::B => 2,
        Kind::A => 3,
    };
    let [length, width, height] = p.size_m;
    let _ = writeln!(
        s,
        "{lamps} {lumens} 1 {} {} {ptype} 2 {width} {length} {height}",
        p.angles.len(),
        p.planes.len()
    );
    s.push_str("1 1 0\n");
    let line = |vals: &[f64]| -> String {
        let mut out = String::new();
        for chunk in vals.chunks(10) {
            let parts: Vec<String> = chunk.iter().map(|v| format!("{v}")).collect();
            out.push_str(&parts.join(" "));
            out.push('\n');
        }
        out
    };
    s.push_str(&line(&p.angles));
    s.push_str(&line(&p.planes));
    for row in &p.candela {
        s.push_str(&line(row));
    }
    s
}
