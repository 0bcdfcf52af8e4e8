//! `candela report`: the self-contained HTML report of an existing render, written by
//! [`candela::report::html::write_html_report`]; see docs/report-html.md.

use std::path::{Path, PathBuf};

use candela::report::html::{read_glare_json, write_html_report};

/// Arguments of `candela report`.
#[derive(clap::Args, Debug, Clone)]
pub struct ReportArgs {
    /// EXR written by `candela render` (or a Radiance HDR picture: luminance and colour, no intervals).
    pub exr: PathBuf,
    /// The render's report JSON (default: NAME.report.json beside NAME.exr, if it exists); refused if it belongs to another render.
    pub report: Option<PathBuf>,
    /// Output page (default: NAME.html beside the EXR).
    #[arg(short = 'o', long = "out")]
    pub out: Option<PathBuf>,
    /// A glare evaluation of the image (`candela glare NAME.exr --json > NAME.glare.json`): the page shows its indices and sources.
    #[arg(long)]
    pub glare: Option<PathBuf>,
}

/// NAME for NAME.exr, NAME.hdr or NAME.
fn stem(exr: &Path) -> PathBuf {
    let name = exr.file_name().and_then(|n| n.to_str()).unwrap_or("");
    match name
        .strip_suffix(".exr")
        .or_else(|| name.strip_suffix(".hdr"))
    {
        Some(s) if !s.is_empty() => exr.with_file_name(s),
        _ => exr.to_path_buf(),
    }
}

/// `candela report`: returns the line to print.
pub fn run(a: &ReportArgs) -> anyhow::Result<String> {
    let base = stem(&a.exr);
    let report = a.report.clone().or_else(|| {
        let p = candela::output::with_suffix(&base, ".report.json");
        p.is_file().then_some(p)
    });
    let out = a
        .out
        .clone()
        .unwrap_or_else(|| candela::output::with_suffix(&base, ".html"));
    if let Some(g) = a
        .glare
        .as_deref()
        .filter(|g| candela::output::would_replace(&out, g))
    {
        anyhow::bail!(
            "{}: refusing to overwrite the input {} (--glare) with the HTML report; choose another output",
            out.display(),
            g.display()
        );
    }
    let glare = a.glare.as_deref().map(read_glare_json).transpose()?;
    let r = write_html_report(&a.exr, report.as_deref(), glare.as_ref(), &out)?;
    Ok(format!(
        "wrote {} ({:.2} MB; channels {}{}{})\n",
        r.path.display(),
        r.bytes as f64 / 1e6,
        r.channels.join(", "),
        match &report {
            Some(p) => format!("; report {}", p.display()),
            None => "; no report JSON: no settings, meters or grids".into(),
        },
        match &a.glare {
            Some(p) => format!("; glare {}", p.display()),
            None => String::new(),
        }
    ))
}
