//! Placeholder until the colour library's command-line functions land.
use crate::colour::tables::Observer;

pub fn spectrum_command(_source: &str, _observer: Observer, _json: bool) -> anyhow::Result<String> {
    anyhow::bail!("`candela spectrum` is not available yet")
}

pub fn convert_command(_value: f64, _from: &str, _to: &str) -> anyhow::Result<String> {
    anyhow::bail!("`candela convert` is not available yet")
}
