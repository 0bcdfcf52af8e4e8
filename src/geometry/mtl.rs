//! Wavefront MTL material libraries: the statements candela maps to materials (`Kd`, `Ks`,
//! `Ns`, `d`/`Tr`, `Ni`, `Ke`, `map_Kd`, `map_Ke` and the tangent-space normal map `norm`, with their
//! `-s`, `-o`, `-clamp` options and `norm`'s `-bm`), read with the
//! file and line of every error. Other statements (`Ka`, `illum`, `Tf`, other maps, PBR
//! extensions) are skipped; how the kept ones become materials is in `scene::build` and
//! docs/scene-format.md.

use super::GeometryError;
use std::path::{Path, PathBuf};

/// A texture map (`map_Kd`, `norm`) with its options.
#[derive(Clone, Debug, PartialEq)]
pub struct MtlMap {
    /// The image file, relative to the MTL file's directory as written.
    pub file: String,
    /// `-s u v`: texture coordinates are multiplied by this (default 1, 1).
    pub scale: [f32; 2],
    /// `-o u v`: then offset by this (default 0, 0).
    pub offset: [f32; 2],
    /// `-clamp on`: clamp instead of repeating.
    pub clamp: bool,
    /// `-bm f`: a normal map's scale of x and y (default 1).
    pub bump: f32,
}

/// One `newmtl` block: the statements candela uses, as written (not yet checked for range).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MtlMaterial {
    pub name: String,
    /// The MTL file and the line of its `newmtl`, for messages.
    pub file: PathBuf,
    pub line: usize,
    pub kd: Option<[f64; 3]>,
    pub ks: Option<[f64; 3]>,
    pub ns: Option<f64>,
    /// Dissolve (opacity); `Tr t` is read as `d = 1 − t`.
    pub d: Option<f64>,
    pub ni: Option<f64>,
    pub ke: Option<[f64; 3]>,
    pub map_kd: Option<MtlMap>,
    /// An emission colour map, multiplying `ke`.
    pub map_ke: Option<MtlMap>,
    /// A tangent-space normal map.
    pub norm: Option<MtlMap>,
}

fn syntax(path: &Path, line: usize, message: String) -> GeometryError {
    GeometryError::MaterialSyntax {
        mtl: path.to_path_buf(),
        line,
        message,
    }
}

fn number(path: &Path, line: usize, stmt: &str, w: &str) -> Result<f64, GeometryError> {
    match w.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(syntax(
            path,
            line,
            format!("`{stmt}` expects numbers, found {w:?}"),
        )),
    }
}

/// `Kd r [g b]` (one value is a grey); the `spectral` and `xyz` forms are refused.
fn colour(path: &Path, line: usize, stmt: &str, args: &[&str]) -> Result<[f64; 3], GeometryError> {
    if args
        .first()
        .is_some_and(|a| *a == "spectral" || *a == "xyz")
    {
        return Err(syntax(
            path,
            line,
            format!("`{stmt} {}` is not supported; give an RGB colour `{stmt} r g b` (and a spectral material in the scene's `materials_from_file` if needed)", args[0]),
        ));
    }
    match args.len() {
        1 => {
            let v = number(path, line, stmt, args[0])?;
            Ok([v; 3])
        }
        3 => Ok([
            number(path, line, stmt, args[0])?,
            number(path, line, stmt, args[1])?,
            number(path, line, stmt, args[2])?,
        ]),
        n => Err(syntax(
            path,
            line,
            format!("`{stmt}` expects 3 numbers (r g b) or 1 (a grey), found {n}"),
        )),
    }
}

fn scalar(path: &Path, line: usize, stmt: &str, args: &[&str]) -> Result<f64, GeometryError> {
    match args {
        [v] => number(path, line, stmt, v),
        _ => Err(syntax(
            path,
            line,
            format!("`{stmt}` expects one number, found {} values", args.len()),
        )),
    }
}

/// `map_Kd [options] file` (or `norm`, named by `stmt`): `-s`, `-o` (1 to 3 numbers; the first
/// two are used), `-clamp on|off`, `-bm f`; other options are skipped with their arguments.
fn map(path: &Path, line: usize, stmt: &str, args: &[&str]) -> Result<MtlMap, GeometryError> {
    let mut m = MtlMap {
        file: String::new(),
        scale: [1.0, 1.0],
        offset: [0.0, 0.0],
        clamp: false,
        bump: 1.0,
    };
    let mut i = 0;
    let numbers = |i: &mut usize, max: usize| -> Vec<f64> {
        let mut v = Vec::new();
        while v.len() < max {
            match args.get(*i).and_then(|w| w.parse::<f64>().ok()) {
                Some(x) if x.is_finite() => {
                    v.push(x);
                    *i += 1;
                }
                _ => break,
            }
        }
        v
    };
    while i < args.len() && args[i].starts_with('-') {
        let opt = args[i];
        i += 1;
        match opt {
            "-s" | "-o" => {
                let v = numbers(&mut i, 3);
                if v.is_empty() {
                    return Err(syntax(
                        path,
                        line,
                        format!("`{stmt} {opt}` expects 1 to 3 numbers"),
                    ));
                }
                let uv = [v[0] as f32, *v.get(1).unwrap_or(&v[0]) as f32];
                if opt == "-s" {
                    m.scale = uv;
                } else {
                    m.offset = uv;
                }
            }
            "-t" => {
                numbers(&mut i, 3);
            }
            "-clamp" | "-blendu" | "-blendv" | "-cc" => {
                let on = match args.get(i) {
                    Some(&"on") => true,
                    Some(&"off") => false,
                    _ => {
                        return Err(syntax(
                            path,
                            line,
                            format!("`{stmt} {opt}` expects on or off"),
                        ))
                    }
                };
                i += 1;
                if opt == "-clamp" {
                    m.clamp = on;
                }
            }
            "-mm" => {
                numbers(&mut i, 2);
            }
            "-bm" => match numbers(&mut i, 1).first() {
                Some(&b) => m.bump = b as f32,
                None => return Err(syntax(path, line, format!("`{stmt} -bm` expects a number"))),
            },
            "-boost" | "-texres" => {
                numbers(&mut i, 1);
            }
            "-imfchan" => i += 1,
            _ => {
                return Err(syntax(
                    path,
                    line,
                    format!("unknown `{stmt}` option {opt:?}"),
                ))
            }
        }
    }
    m.file = args[i.min(args.len())..].join(" ");
    if m.file.is_empty() {
        return Err(syntax(path, line, format!("`{stmt}` names no image file")));
    }
    Ok(m)
}

/// Parses an MTL library read from `path`. Every error names the file and line.
pub fn parse_mtl(path: &Path, bytes: &[u8]) -> Result<Vec<MtlMaterial>, GeometryError> {
    let text = String::from_utf8_lossy(bytes);
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
    let mut out: Vec<MtlMaterial> = Vec::new();
    for (n, raw) in text.lines().enumerate() {
        let line = n + 1;
        let content = raw.split('#').next().unwrap_or("");
        let words: Vec<&str> = content.split_whitespace().collect();
        let Some((&stmt, args)) = words.split_first() else {
            continue;
        };
        if stmt == "newmtl" {
            let name = content.trim().strip_prefix("newmtl").unwrap_or("").trim();
            if name.is_empty() {
                return Err(syntax(path, line, "`newmtl` names no material".into()));
            }
            if let Some(prev) = out.iter().find(|m| m.name == name) {
                return Err(syntax(
                    path,
                    line,
                    format!(
                        "material {name:?} is defined twice (first at line {})",
                        prev.line
                    ),
                ));
            }
            out.push(MtlMaterial {
                name: name.to_string(),
                file: path.to_path_buf(),
                line,
                ..Default::default()
            });
            continue;
        }
        let known = matches!(
            stmt,
            "Kd" | "Ks" | "Ke" | "Ns" | "Ni" | "d" | "Tr" | "map_Kd" | "map_Ke" | "norm"
        );
        let Some(m) = out.last_mut() else {
            if known {
                return Err(syntax(
                    path,
                    line,
                    format!("`{stmt}` comes before any `newmtl`"),
                ));
            }
            continue;
        };
        match stmt {
            "Kd" => m.kd = Some(colour(path, line, stmt, args)?),
            "Ks" => m.ks = Some(colour(path, line, stmt, args)?),
            "Ke" => m.ke = Some(colour(path, line, stmt, args)?),
            "Ns" => m.ns = Some(scalar(path, line, stmt, args)?),
            "Ni" => m.ni = Some(scalar(path, line, stmt, args)?),
            "d" => {
                // `d -halo f` is the halo form; the factor is what is used.
                let args = args.strip_prefix(&["-halo"]).unwrap_or(args);
                m.d = Some(scalar(path, line, stmt, args)?)
            }
            "Tr" => m.d = Some(1.0 - scalar(path, line, stmt, args)?),
            "map_Kd" => m.map_kd = Some(map(path, line, stmt, args)?),
            "map_Ke" => m.map_ke = Some(map(path, line, stmt, args)?),
            "norm" => m.norm = Some(map(path, line, stmt, args)?),
            _ => {}
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn statements_and_errors() {
        let p = Path::new("a.mtl");
        let m = parse_mtl(
            p,
            b"# c\nnewmtl Wall Paint\nKd 0.5 0.25 0.125\nKs 0.1\nNs 20\nTr 0.25\nNi 1.5\nKe 1 2 3\nmap_Kd -s 2 3 1 -clamp on my floor.png\nillum 2\n",
        )
        .unwrap();
        assert_eq!(m.len(), 1);
        let m = &m[0];
        assert_eq!(m.name, "Wall Paint");
        assert_eq!(m.kd, Some([0.5, 0.25, 0.125]));
        assert_eq!(m.ks, Some([0.1; 3]));
        assert_eq!((m.ns, m.d, m.ni), (Some(20.0), Some(0.75), Some(1.5)));
        let map = m.map_kd.as_ref().unwrap();
        assert_eq!(map.file, "my floor.png");
        assert_eq!(map.scale, [2.0, 3.0]);
        assert!(map.clamp);
        for (bad, want) in [
            ("Kd 1 1 1\n", "line 1: `Kd` comes before any `newmtl`"),
            ("newmtl a\nKd 1 x 1\n", "line 2: `Kd` expects numbers"),
            ("newmtl a\nKd 1 1\n", "line 2: `Kd` expects 3 numbers"),
            ("newmtl a\nNs\n", "line 2: `Ns` expects one number"),
            (
                "newmtl a\nnewmtl a\n",
                "line 2: material \"a\" is defined twice",
            ),
            ("newmtl a\nmap_Kd -s\n", "line 2: `map_Kd -s` expects"),
            (
                "newmtl a\nKd spectral x.spd\n",
                "line 2: `Kd spectral` is not",
            ),
        ] {
            let e = parse_mtl(p, bad.as_bytes()).unwrap_err().to_string();
            assert!(e.contains("a.mtl") && e.contains(want), "{bad:?}: {e}");
        }
    }
}
