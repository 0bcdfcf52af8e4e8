//! `candela luminaire FILE [--diagram PATH]`: a data-sheet summary of a photometric file.

use candela::luminaire::summary::summarise;
use candela::luminaire::{load, Format, Kind, Symmetry};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Default diagram path: `<file stem>-polar.png` in the current directory.
pub fn default_diagram_path(file: &Path) -> PathBuf {
    let stem = file
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "luminaire".into());
    PathBuf::from(format!("{stem}-polar.png"))
}

/// Run the command: returns the report text; writes the diagram (refused if the diagram path
/// is the input file).
pub fn run(file: &Path, diagram: Option<&Path>) -> anyhow::Result<String> {
    let path = diagram
        .map(Path::to_path_buf)
        .unwrap_or_else(|| default_diagram_path(file));
    if candela::job::would_replace(&path, file) {
        anyhow::bail!(
            "--diagram {}: refusing to overwrite the input photometric file {} with the PNG diagram; choose another --diagram path",
            path.display(),
            file.display()
        );
    }
    let p = load(file)?;
    let s = summarise(&p);
    let mut out = String::new();
    let fmt = match &p.format {
        Format::Ies(v) => format!("IES {v}"),
        Format::Eulumdat => "EULUMDAT".into(),
    };
    let _ = writeln!(out, "file: {}", file.display());
    let _ = writeln!(out, "format: {fmt}");
    for (k, v) in &p.header {
        let v = v.replace('\n', " ");
        if k.is_empty() {
            let _ = writeln!(out, "  {v}");
        } else {
            let _ = writeln!(out, "  {k}: {v}");
        }
    }
    let kind = match p.kind {
        Kind::C => "C",
        Kind::B => "B",
        Kind::A => "A",
    };
    let sym = match p.symmetry {
        Symmetry::None => "none (all planes given)",
        Symmetry::Rotational => "rotational",
        Symmetry::C0C180 => "about the C0-C180 plane",
        Symmetry::C90C270 => "about the C90-C270 plane",
        Symmetry::Quadrant => "quadrant (both planes)",
        Symmetry::Lateral => "lateral (H >= 0 given)",
    };
    let _ = writeln!(out, "photometry: type {kind}, symmetry {sym}");
    let _ = writeln!(
        out,
        "table: {} planes ({}…{}°) × {} angles ({}…{}°)",
        p.planes.len(),
        p.planes[0],
        p.planes[p.planes.len() - 1],
        p.angles.len(),
        p.angles[0],
        p.angles[p.angles.len() - 1]
    );
    let [l, w, h] = p.size_m;
    let _ = writeln!(out, "size: length {l} m, width {w} m, height {h} m");
    let _ = write!(
        out,
        "luminous flux: {:.2} lm integrated from the table",
        s.integrated_lumens
    );
    match s.stated_lumens {
        Some(st) => {
            let _ = writeln!(
                out,
                "; stated {st:.2} lm (ratio {:.4})",
                s.integrated_lumens / st
            );
        }
        None => {
            let _ = writeln!(out, "; no flux stated (absolute photometry)");
        }
    }
    let (pa, pb) = match p.kind {
        Kind::C => ("C", "γ"),
        _ => ("H", "V"),
    };
    let _ = writeln!(
        out,
        "maximum intensity: {:.2} cd at {pa} {}°, {pb} {}°",
        s.max_cd, s.max_at.0, s.max_at.1
    );
    let _ = writeln!(
        out,
        "beam angle (50 %): {:.1}° in C0-C180, {:.1}° in C90-C270",
        s.beam[0], s.beam[1]
    );
    let _ = writeln!(
        out,
        "field angle (10 %): {:.1}° in C0-C180, {:.1}° in C90-C270",
        s.field[0], s.field[1]
    );
    let title = file
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    candela::luminaire::diagram::write_png(&path, &p.distribution(), &title)
        .map_err(|e| anyhow::anyhow!("{}: {e}", file.display()))?;
    let _ = writeln!(out, "polar diagram: {}", path.display());
    Ok(out)
}
