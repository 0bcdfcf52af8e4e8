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
    let err = |line: usize, field: &str, m: String| ParseError {
        file: file.to_path_buf(),
        line,
        field: field.to_string(),
        message: m,
    };
    let first = lines.first().map(|l| l.trim()).unwrap_or("");
    let version = if first.starts_with("IESNA") || first.starts_with("IES:") {
        let v = if first == "IESNA91" {
            "LM-63-1991".to_string()
        } else {
            first.split(':').nth(1).unwrap_or(first).trim().to_string()
        };
        let known = ["LM-63-1991", "LM-63-1995", "LM-63-2002", "LM-63-2019"];
        if !known.contains(&v.as_str()) {
            return Err(err(
                1,
                "format line",
                format!("unknown IES version {first:?} (known: IESNA91, IESNA:LM-63-1995, IESNA:LM-63-2002, IES:LM-63-2019, or none for 1986)"),
            ));
        }
        v
    } else {
        "LM-63-1986".to_string()
    };
    let start = usize::from(version != "LM-63-1986");
    let mut header: Vec<(String, String)> = Vec::new();
    let mut tilt_line = None;
    for (k, raw) in lines.iter().enumerate().skip(start) {
        let l = raw.trim();
        if let Some(rest) = l.strip_prefix("TILT") {
            let rest = rest.trim_start();
            let Some(v) = rest.strip_prefix('=') else {
                return Err(err(k + 1, "TILT", format!("expected TILT=…, got {l:?}")));
            };
            tilt_line = Some((k, v.trim().to_string()));
            break;
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
    let Some((tilt_idx, tilt)) = tilt_line else {
        return Err(err(
            lines.len().max(1),
            "TILT",
            "no TILT= line: the file ends before the photometric data".into(),
        ));
    };
    let toks: Vec<(usize, &str)> = lines
        .iter()
        .enumerate()
        .skip(tilt_idx + 1)
        .flat_map(|(k, l)| {
            l.split(|c: char| c.is_whitespace() || c == ',')
                .filter(|s| !s.is_empty())
                .map(move |s| (k + 1, s))
        })
        .collect();
    let mut t = Tokens {
        toks,
        pos: 0,
        file,
        last_line: lines.len().max(1),
    };
    let mut tilt_factor = 1.0;
    match tilt.to_ascii_uppercase().as_str() {
        "NONE" => {}
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
            tilt_factor = match super::bracket(&xs, 0.0) {
                Some((i, s)) if i + 1 < n => factors[i] * (1.0 - s) + factors[i + 1] * s,
                Some((i, _)) => factors[i],
                None => {
                    return Err(t.err(
                        angles[0].0,
                        "tilt angle 1",
                        "the tilt table does not cover 0° (the luminaire as photometered)",
                    ))
                }
            };
        }
        other => {
            return Err(err(
                tilt_idx + 1,
                "TILT",
                format!("TILT={other}: tilt data in a separate file is not supported; use TILT=NONE or TILT=INCLUDE"),
            ))
        }
    }
    let (_, lamps) = t.num("number of lamps")?;
    let (llm_line, lumens_per_lamp) = t.num("lumens per lamp")?;
    let (mline, multiplier) = t.num("candela multiplier")?;
    if multiplier < 0.0 {
        return Err(t.err(
            mline,
            "candela multiplier",
            format!("{multiplier} is negative"),
        ));
    }
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
    let to_m = if units == 1 { 0.3048 } else { 1.0 };
    let (_, width) = t.num("width")?;
    let (_, length) = t.num("length")?;
    let (_, height) = t.num("height")?;
    let (bline, ballast) = t.num("ballast factor")?;
    if ballast < 0.0 {
        return Err(t.err(bline, "ballast factor", format!("{ballast} is negative")));
    }
    let (fline, future) = t.num(if version == "LM-63-2019" {
        "file generation type"
    } else {
        "ballast-lamp photometric factor"
    })?;
    let blpf = if version == "LM-63-1991" || version == "LM-63-1995" || version == "LM-63-1986" {
        if future < 0.0 {
            return Err(t.err(
                fline,
                "ballast-lamp photometric factor",
                format!("{future} is negative"),
            ));
        }
        future
    } else {
        1.0
    };
    let (_, _watts) = t.num("input watts")?;
    let vert = t.angles(nv, "vertical")?;
    let horiz = t.angles(nh, "horizontal")?;
    let kind = match ptype {
        1 => Kind::C,
        2 => Kind::B,
        _ => Kind::A,
    };
    let (v0, v1) = (vert[0].1, vert[nv - 1].1);
    let (h0, h1) = (horiz[0].1, horiz[nh - 1].1);
    let bad_v = |msg: &str| Err(err(vert[0].0, "vertical angle 1", msg.to_string()));
    let bad_h = |msg: String| Err(err(horiz[0].0, "horizontal angle 1", msg));
    let symmetry = match kind {
        Kind::C => {
            if v0 < -ANGLE_TOL || v1 > 180.0 + ANGLE_TOL {
                return bad_v("type C vertical angles must lie in 0…180°");
            }
            let near = |a: f64, b: f64| (a - b).abs() < ANGLE_TOL;
            if nh == 1 {
                Symmetry::Rotational
            } else if near(h0, 0.0) && near(h1, 90.0) {
                Symmetry::Quadrant
            } else if near(h0, 0.0) && near(h1, 180.0) {
                Symmetry::C0C180
            } else if near(h0, 90.0) && near(h1, 270.0) {
                Symmetry::C90C270
            } else if near(h0, 0.0) && h1 > 180.0 && h1 <= 360.0 + ANGLE_TOL {
                Symmetry::None
            } else {
                return bad_h(format!(
                    "type C horizontal angles {h0}…{h1}° are not one of 0 (rotational), 0…90, 0…180, 90…270 or 0…360"
                ));
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
                Symmetry::Lateral
            } else if nh == 1 {
                return bad_h("type A/B photometry needs at least two horizontal angles".into());
            } else {
                Symmetry::None
            }
        }
    };
    let scale = multiplier * ballast * blpf * tilt_factor;
    let mut candela = Vec::with_capacity(nh);
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
                nh * nv
            ),
        ));
    }
    let _ = llm_line;
    let stated_lumens = (lumens_per_lamp > 0.0 && lamps > 0.0)
        .then_some(lamps * lumens_per_lamp * ballast * blpf * tilt_factor);
    Ok(Photometry {
        format: Format::Ies(version),
        header,
        kind,
        symmetry,
        planes: horiz.iter().map(|a| a.1).collect(),
        angles: vert.iter().map(|a| a.1).collect(),
        candela,
        stated_lumens,
        size_m: [length.abs() * to_m, width.abs() * to_m, height.abs() * to_m],
    })
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
