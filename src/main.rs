//! The `candela` command line.

use candela::colour::tables::Observer;
use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

/// `println!` / `print!` that ignore a closed standard output (e.g. `candela … | head -1`): the
/// outputs are files, and a reader that stopped early must not make the command fail or panic.
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($arg)*);
    }};
}
macro_rules! say_raw {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = write!(std::io::stdout(), $($arg)*);
    }};
}

mod cli;

#[derive(Parser)]
#[command(
    name = "candela",
    version,
    about = "A spectral path tracer whose output is measured light (cd/m², lux)."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene to NAME.exr (absolute XYZ, Y = luminance in cd/m², plus its standard error) and NAME.png (sRGB).
    Render(Box<cli::render::RenderOpts>),
    /// Combine independent renders of the same scene (different seeds) from their state files into one estimate.
    Merge {
        /// State files written with --save-state (or checkpoints).
        #[arg(required = true, num_args = 2..)]
        states: Vec<PathBuf>,
        /// Output name: writes OUT.exr, OUT.png and OUT.state; an existing directory (or a path ending in `/`) writes DIR/merged.exr, .png and .state. Refused if an output would replace an input.
        #[arg(short, long)]
        out: PathBuf,
        /// Exposure of the PNG in EV, between -100 and 100 (default: automatic).
        #[arg(long, allow_hyphen_values = true)]
        exposure: Option<f64>,
    },
    /// Colorimetry of a spectrum: XYZ, xy, u′v′, CCT, Duv, efficacy, S/P, sRGB, CRI.
    Spectrum {
        /// A CSV file (nm,value), a named spectrum (D65, FL2, LED-B3, …) or blackbody:3000K.
        source: String,
        /// Standard observer.
        #[arg(long, default_value = "1931", value_parser = ["1931", "1964"])]
        observer: String,
        /// Print JSON instead of a table.
        #[arg(long)]
        json: bool,
    },
    /// Convert a photometric value between units, e.g. `candela convert 100 lx fc`.
    Convert {
        #[arg(allow_hyphen_values = true)]
        value: f64,
        from: String,
        to: String,
    },
    /// Summary of an IES/EULUMDAT photometric file (flux, peak, beam and field angles) and a polar candela diagram (PNG).
    Luminaire {
        /// Photometric file: IES LM-63 (.ies) or EULUMDAT (.ldt).
        file: PathBuf,
        /// Where to write the polar diagram (default: FILE-STEM-polar.png in the current directory); refused if it is FILE itself.
        #[arg(long)]
        diagram: Option<PathBuf>,
    },
    /// Benchmark: samples/s and rays/s on the Cornell box and on a generated 1 M-triangle scene; `bench traversal` (BVH vs Embree) and `bench scaling` (10 k … 5 M triangles).
    Bench(cli::bench::BenchArgs),
    /// Luminance, illuminance (95 % CI), XYZ, xy, u′v′, CCT, Duv and sRGB of a pixel or disc of an EXR; see docs/reports.md.
    Probe(cli::probe::ProbeArgs),
    /// False-colour PNG of luminance or illuminance with a legend; see docs/reports.md.
    Falsecolour(cli::falsecolour::FalsecolourArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render(opts) => cli::render::render(&opts),
        Command::Merge {
            states,
            out,
            exposure,
        } => cli::render::merge(&states, &out, exposure),
        Command::Spectrum {
            source,
            observer,
            json,
        } => {
            let obs = if observer == "1964" {
                Observer::Cie1964_10
            } else {
                Observer::Cie1931_2
            };
            cli::colour::spectrum_command(&source, obs, json).map(|s| say_raw!("{s}"))
        }
        Command::Convert { value, from, to } => {
            cli::colour::convert_command(value, &from, &to).map(|s| say_raw!("{s}"))
        }
        Command::Luminaire { file, diagram } => {
            cli::luminaire::run(&file, diagram.as_deref()).map(|s| say_raw!("{s}"))
        }
        Command::Bench(args) => cli::bench::main(&args),
        Command::Probe(args) => cli::probe::run(&args).map(|s| say_raw!("{s}")),
        Command::Falsecolour(args) => cli::falsecolour::run(&args).map(|s| say_raw!("{s}")),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", error_message(&e));
            ExitCode::FAILURE
        }
    }
}

/// The error and its causes joined by ": ", like `{:#}`, but a cause whose text an outer
/// message already contains (e.g. "cannot read scene file X: {source}" whose source is also
/// the next cause in the chain) is not repeated.
fn error_message(e: &anyhow::Error) -> String {
    let mut msg = String::new();
    for cause in e.chain() {
        let text = cause.to_string();
        if msg.is_empty() {
            msg = text;
        } else if !text.is_empty() && !msg.contains(&text) {
            msg.push_str(": ");
            msg.push_str(&text);
        }
    }
    msg
}
