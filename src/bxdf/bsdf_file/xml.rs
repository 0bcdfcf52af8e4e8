//! Reading an LBNL WINDOW / Radiance BSDF XML file (schema BSDF-v1.4, as Radiance's
//! `bsdf_m.c` and `bsdf_t.c` read it): `WindowElement > Optical > Layer` (the first layer),
//! its `DataDefinition` (`IncidentDataStructure` and any custom `AngleBasis`) and each
//! `WavelengthData > WavelengthDataBlock`. Every error names the file, the line and the
//! element.

use super::klems::KlemsBasis;
use std::path::Path;

/// Largest BSDF file read, in bytes (a 4-D tensor tree of fine resolution is tens of MB).
pub const MAX_BSDF_BYTES: u64 = 256 << 20;

/// Most XML nodes a file may have (each costs the parser about 100 bytes).
const MAX_NODES: u32 = 4_000_000;

/// How the file's scattering data are laid out.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layout {
    /// Klems matrices, one text row per outgoing patch (`Columns`).
    Columns,
    /// Klems matrices, one text row per incident patch (`Rows`).
    Rows,
    /// Tensor trees of 3 (isotropic) or 4 (anisotropic) dimensions.
    Tree(u8),
}

/// Which of the four scattering blocks, named by the sides of the surface as candela sees
/// it: +z is the side the surface normal points to (the room; WINDOW's *back*).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Block {
    /// Light from the −z side leaving on +z (WINDOW "Transmission Front").
    TransToPos,
    /// Light from +z leaving on −z (WINDOW "Transmission Back").
    TransToNeg,
    /// Light from +z reflected on +z (WINDOW "Reflection Back").
    ReflPos,
    /// Light from −z reflected on −z (WINDOW "Reflection Front").
    ReflNeg,
}

impl Block {
    /// The block's name in the file.
    pub fn window_name(self) -> &'static str {
        match self {
            Block::TransToPos => "Transmission Front",
            Block::TransToNeg => "Transmission Back",
            Block::ReflPos => "Reflection Back",
            Block::ReflNeg => "Reflection Front",
        }
    }

    /// The position of the block in arrays of four.
    pub fn slot(self) -> usize {
        self as usize
    }
}

/// One block of photopic (`Visible`) data.
#[derive(Debug)]
pub struct DataBlock {
    pub block: Block,
    /// Line of the `WavelengthDataBlock` element.
    pub line: u32,
    /// Klems: the incident (column) and outgoing (row) bases.
    pub bases: Option<(KlemsBasis, KlemsBasis)>,
    /// The numbers of `ScatteringData` (Klems; negative values already 0) or its text (trees).
    pub values: Vec<f32>,
    pub tree_text: Option<String>,
    /// Line where `ScatteringData` starts.
    pub data_line: u32,
}

/// What a file holds that candela uses, with notes on what it leaves out.
#[derive(Debug)]
pub struct ParsedFile {
    pub layout: Layout,
    pub blocks: Vec<DataBlock>,
    /// Wavelength sets other than `Visible` that the file holds (`Solar`, `CIE-X`, …).
    pub skipped: Vec<String>,
}

/// A message for an error at `node` of the file at `path`.
fn at(path: &Path, doc: &roxmltree::Document, node: roxmltree::Node, msg: &str) -> String {
    let pos = doc.text_pos_at(node.range().start);
    format!(
        "BSDF file '{}' line {} (<{}>): {msg}",
        path.display(),
        pos.row,
        node.tag_name().name()
    )
}

fn child<'a, 'i>(n: roxmltree::Node<'a, 'i>, name: &str) -> Option<roxmltree::Node<'a, 'i>> {
    n.children()
        .find(|c| c.is_element() && c.tag_name().name() == name)
}

fn children<'a, 'i: 'a>(
    n: roxmltree::Node<'a, 'i>,
    name: &'a str,
) -> impl Iterator<Item = roxmltree::Node<'a, 'i>> + 'a {
    n.children()
        .filter(move |c| c.is_element() && c.tag_name().name() == name)
}

fn text<'a>(n: roxmltree::Node<'a, '_>) -> &'a str {
    n.text().unwrap_or("").trim()
}

/// Read and parse the file at `path`.
pub fn read(path: &Path) -> Result<ParsedFile, String> {
    let text = crate::limits::read_text(path, MAX_BSDF_BYTES)
        .map_err(|e| format!("cannot read BSDF file '{}': {e}", path.display()))?;
    parse(path, &text)
}

/// Parse the text of the file at `path` (named in messages).
pub fn parse(path: &Path, source: &str) -> Result<ParsedFile, String> {
    let opts = roxmltree::ParsingOptions {
        allow_dtd: false,
        nodes_limit: MAX_NODES,
    };
    let doc = roxmltree::Document::parse_with_options(source, opts)
        .map_err(|e| format!("BSDF file '{}' is not valid XML: {e}", path.display()))?;
    let root = doc.root_element();
    if root.tag_name().name() != "WindowElement" {
        return Err(at(
            path,
            &doc,
            root,
            "the root element is not <WindowElement>; this is not a WINDOW BSDF file",
        ));
    }
    let layer = child(root, "Optical")
        .and_then(|o| child(o, "Layer"))
        .ok_or_else(|| at(path, &doc, root, "no <Optical><Layer> element"))?;
    let def = child(layer, "DataDefinition")
        .ok_or_else(|| at(path, &doc, layer, "no <DataDefinition>"))?;
    let structure = child(def, "IncidentDataStructure")
        .ok_or_else(|| at(path, &doc, def, "no <IncidentDataStructure>"))?;
    let layout = match text(structure).to_ascii_lowercase().as_str() {
        "columns" => Layout::Columns,
        "rows" => Layout::Rows,
        "tensortree3" => Layout::Tree(3),
        "tensortree4" => Layout::Tree(4),
        other => {
            return Err(at(
                path,
                &doc,
                structure,
                &format!(
                    "{:?} is not a data structure candela reads (Columns, Rows, TensorTree3, \
                     TensorTree4)",
                    crate::limits::printable(other, 40)
                ),
            ))
        }
    };
    let mut custom = Vec::new();
    for ab in children(def, "AngleBasis") {
        custom.push(custom_basis(path, &doc, ab)?);
    }
    let mut out = ParsedFile {
        layout,
        blocks: Vec::new(),
        skipped: Vec::new(),
    };
    for wd in children(layer, "WavelengthData") {
        let wl = child(wd, "Wavelength").ok_or_else(|| at(path, &doc, wd, "no <Wavelength>"))?;
        let name = text(wl);
        if !name.eq_ignore_ascii_case("Visible") {
            let shown = crate::limits::printable(name, 40);
            if !out.skipped.contains(&shown) {
                out.skipped.push(shown);
            }
            continue;
        }
        for db in children(wd, "WavelengthDataBlock") {
            let block = data_block(path, &doc, db, layout, &custom)?;
            if out.blocks.iter().any(|b| b.block == block.block) {
                return Err(at(
                    path,
                    &doc,
                    db,
                    &format!(
                        "a second Visible '{}' block; each direction may be given once",
                        block.block.window_name()
                    ),
                ));
            }
            out.blocks.push(block);
        }
    }
    if out.blocks.is_empty() {
        let also = if out.skipped.is_empty() {
            String::new()
        } else {
            format!(" (it has {})", out.skipped.join(", "))
        };
        return Err(format!(
            "BSDF file '{}' has no Visible scattering data{also}; candela renders photopic \
             (Visible) data",
            path.display()
        ));
    }
    Ok(out)
}

/// A custom `AngleBasis`: its name and rings (`ThetaBounds` and `nPhis` per block).
fn custom_basis(
    path: &Path,
    doc: &roxmltree::Document,
    ab: roxmltree::Node,
) -> Result<KlemsBasis, String> {
    let name = child(ab, "AngleBasisName")
        .map(text)
        .filter(|n| !n.is_empty())
        .ok_or_else(|| at(path, doc, ab, "no <AngleBasisName>"))?;
    if let Some(std) = KlemsBasis::standard(name) {
        return Ok(std);
    }
    let mut rings = Vec::new();
    let mut last_upper: Option<f64> = None;
    for b in children(ab, "AngleBasisBlock") {
        let num = |n: Option<roxmltree::Node>, what: &str| -> Result<f64, String> {
            let n = n.ok_or_else(|| at(path, doc, b, &format!("no <{what}>")))?;
            text(n).parse::<f64>().map_err(|_| {
                at(
                    path,
                    doc,
                    n,
                    &format!(
                        "{:?} is not a number",
                        crate::limits::printable(text(n), 40)
                    ),
                )
            })
        };
        let bounds = child(b, "ThetaBounds");
        let lower = num(bounds.and_then(|t| child(t, "LowerTheta")), "LowerTheta")?;
        let upper = num(bounds.and_then(|t| child(t, "UpperTheta")), "UpperTheta")?;
        let nphi = num(child(b, "nPhis"), "nPhis")?;
        if let Some(u) = last_upper.filter(|u| (u - lower).abs() > 1e-6 * u.abs().max(1.0)) {
            return Err(at(
                path,
                doc,
                b,
                &format!("LowerTheta {lower}° does not continue the previous UpperTheta {u}°"),
            ));
        }
        if !(nphi >= 1.0 && nphi <= super::klems::MAX_PATCHES as f64 && nphi.fract() == 0.0) {
            return Err(at(path, doc, b, &format!("nPhis {nphi} is not a count")));
        }
        rings.push((lower, nphi as usize));
        last_upper = Some(upper);
    }
    if last_upper.is_some_and(|u| (u - 90.0).abs() > 1e-6) {
        return Err(at(
            path,
            doc,
            ab,
            &format!(
                "the last ring ends at {}°, not 90°",
                last_upper.unwrap_or(0.0)
            ),
        ));
    }
    KlemsBasis::from_rings(name, &rings)
        .map_err(|e| at(path, doc, ab, &format!("angle basis {name:?}: {e}")))
}

/// One `WavelengthDataBlock` of Visible data.
fn data_block(
    path: &Path,
    doc: &roxmltree::Document,
    db: roxmltree::Node,
    layout: Layout,
    custom: &[KlemsBasis],
) -> Result<DataBlock, String> {
    let dir = child(db, "WavelengthDataDirection")
        .ok_or_else(|| at(path, doc, db, "no <WavelengthDataDirection>"))?;
    let block = match text(dir).to_ascii_lowercase().as_str() {
        "transmission front" => Block::TransToPos,
        "transmission back" => Block::TransToNeg,
        "reflection back" => Block::ReflPos,
        "reflection front" => Block::ReflNeg,
        other => {
            return Err(at(
                path,
                doc,
                dir,
                &format!(
                    "{:?} is not a direction (Transmission Front, Transmission Back, \
                     Reflection Front, Reflection Back)",
                    crate::limits::printable(other, 40)
                ),
            ))
        }
    };
    let data =
        child(db, "ScatteringData").ok_or_else(|| at(path, doc, db, "no <ScatteringData>"))?;
    let data_line = doc.text_pos_at(data.range().start).row;
    let line = doc.text_pos_at(db.range().start).row;
    if let Layout::Tree(_) = layout {
        return Ok(DataBlock {
            block,
            line,
            bases: None,
            values: Vec::new(),
            tree_text: Some(text(data).to_string()),
            data_line,
        });
    }
    let basis = |name: &str| -> Result<KlemsBasis, String> {
        let n = child(db, name).ok_or_else(|| at(path, doc, db, &format!("no <{name}>")))?;
        let want = text(n);
        KlemsBasis::standard(want)
            .or_else(|| {
                custom
                    .iter()
                    .find(|b| b.name.eq_ignore_ascii_case(want))
                    .cloned()
            })
            .ok_or_else(|| {
                at(
                    path,
                    doc,
                    n,
                    &format!(
                        "angle basis {:?} is neither a standard Klems basis nor defined in the \
                         file's <DataDefinition>",
                        crate::limits::printable(want, 60)
                    ),
                )
            })
    };
    let inc = basis("ColumnAngleBasis")?;
    let out = basis("RowAngleBasis")?;
    let (ni, no) = (inc.len(), out.len());
    let raw = numbers(text(data), ni * no).map_err(|e| {
        at(
            path,
            doc,
            data,
            &format!("of '{}': {e}", block.window_name()),
        )
    })?;
    let mut values = vec![0.0f32; ni * no];
    for (k, v) in raw.into_iter().enumerate() {
        // Stored as f[o][i]; `Rows` lists one incident patch per text row.
        let (o, i) = match layout {
            Layout::Rows => (k % no, k / no),
            _ => (k / ni, k % ni),
        };
        values[o * ni + i] = v;
    }
    Ok(DataBlock {
        block,
        line,
        bases: Some((inc, out)),
        values,
        tree_text: None,
        data_line,
    })
}

/// Exactly `want` numbers separated by white space or commas; negative values become 0
/// (as Radiance reads them).
fn numbers(s: &str, want: usize) -> Result<Vec<f32>, String> {
    let mut out = Vec::with_capacity(want);
    for (k, tok) in s
        .split(|c: char| c.is_ascii_whitespace() || c == ',')
        .filter(|t| !t.is_empty())
        .enumerate()
    {
        if k == want {
            return Err(format!("has more than the {want} values the bases need"));
        }
        let v: f32 = tok.parse().map_err(|_| {
            format!(
                "value {} is {:?}, not a number",
                k + 1,
                crate::limits::printable(tok, 30)
            )
        })?;
        if !v.is_finite() {
            return Err(format!("value {} is {tok}, not a finite number", k + 1));
        }
        out.push(v.max(0.0));
    }
    if out.len() < want {
        return Err(format!(
            "has {} of the {want} values the bases need",
            out.len()
        ));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_counted_and_checked() {
        assert_eq!(numbers("1, 2\n3 -4", 4).unwrap(), vec![1.0, 2.0, 3.0, 0.0]);
        assert!(numbers("1 2 3", 4).unwrap_err().contains("has 3 of the 4"));
        assert!(numbers("1 2 3 4 5", 4).unwrap_err().contains("more than"));
        assert!(numbers("1 x 3 4", 4).unwrap_err().contains("value 2"));
        assert!(numbers("1 inf 3 4", 4).unwrap_err().contains("finite"));
    }
}
