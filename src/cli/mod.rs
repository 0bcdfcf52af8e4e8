//! The command line's own modules: argument parsing (clap), progress bars and printing. Each
//! subcommand parses its arguments, calls one library function and prints what it returns.

pub mod annual;
pub mod bench;
pub mod colour;
pub mod falsecolour;
pub mod glare;
pub mod luminaire;
pub mod probe;
pub mod render;
pub mod report;

/// Longest line printed, in characters: a message quoting a huge input field stays readable.
const MAX_LINE_CHARS: usize = 4096;

/// `text` safe to print on a terminal: each line with its control characters (CR, NUL, escape
/// sequences from an input file) shown as `\u{..}` escapes and cut at [`MAX_LINE_CHARS`]; the
/// newlines between lines are kept.
pub fn printable_lines(text: &str) -> String {
    text.split('\n')
        .map(|line| candela::limits::printable(line, MAX_LINE_CHARS))
        .collect::<Vec<_>>()
        .join("\n")
}

/// JSON text safe to print: serde_json already escapes the control characters below U+0020;
/// DEL and the C1 controls (U+007F–U+009F) become `\u00XX` escapes, which keep the JSON valid
/// (outside strings JSON text holds none).
pub fn printable_json(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        if ('\u{7f}'..='\u{9f}').contains(&c) {
            out.push_str(&format!("\\u{:04x}", c as u32));
        } else {
            out.push(c);
        }
    }
    out
}

/// `--draws` of the commands that draw replicates for their intervals: 0 (no intervals) or
/// 2 … 100 000.
pub fn check_draws(draws: usize) -> anyhow::Result<()> {
    if draws == 1 || draws > 100_000 {
        return Err(usage(format!(
            "--draws must be 0 (no intervals) or 2 … 100 000, got {draws}"
        )));
    }
    Ok(())
}

/// An error in the command line found after clap parsed it (an option's value that no input
/// can make valid, options that exclude each other): exit code 2, as clap's own.
pub fn usage(message: impl Into<String>) -> anyhow::Error {
    candela::job::invalid_option(message)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn printable_lines_keeps_newlines_and_escapes_the_rest() {
        assert_eq!(
            printable_lines("a\r\nb\u{1b}[31m\0\nc"),
            "a\\u{d}\nb\\u{1b}[31m\\u{0}\nc"
        );
        let json = printable_json("{\"a\": \"x\u{7f}\u{85}y\"}");
        assert_eq!(json, "{\"a\": \"x\\u007f\\u0085y\"}");
        let v: serde_json::Value = serde_json::from_str(&json).unwrap();
        assert_eq!(v["a"], "x\u{7f}\u{85}y");
    }
}
