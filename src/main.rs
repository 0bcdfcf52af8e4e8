//! The `candela` command line.

use candela::colour::tables::Observer;
use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

/// `println!` / `print!` that ignore a closed standard output (e.g. `candela … | head -1`): the
/// outputs are files, and a reader that stopped early must not make the command fail or panic.
/// Text from input files (names, headers) may hold control characters: every line is printed
/// through [`cli::printable_lines`].
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let text = $crate::cli::printable_lines(&format!($($arg)*));
        let _ = writeln!(std::io::stdout(), "{text}");
    }};
}
macro_rules! say_raw {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let text = $crate::cli::printable_lines(&format!($($arg)*));
        let _ = write!(std::io::stdout(), "{text}");
    }};
}
/// [`say_raw!`] for JSON, which must stay valid (see [`cli::printable_json`]).
macro_rules! say_json {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let text = $crate::cli::printable_json(&format!($($arg)*));
        let _ = write!(std::io::stdout(), "{text}");
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
    /// Combine independent renders of the same scene (different seeds), or the shards of one render (render --shard), from their state files into one estimate.
    Merge(cli::render::MergeOpts),
    /// Colorimetry of a spectrum: XYZ, xy, u′v′, CCT, Duv, efficacy, S/P, sRGB, CRI, α-opic (CIE S 026), TM-30 Rf/Rg.
    Spectrum {
        /// A CSV file (nm,value), a named spectrum (D65, FL2, LED-B3, …) or blackbody:3000K.
        source: String,
        /// Standard observer.
        #[arg(long, default_value = "1931", value_parser = ["1931", "1964"])]
        observer: String,
        /// Print JSON instead of a table.
        #[arg(long)]
        json: bool,
        /// Also print XYZ and xy exactly as colour-science's sd_to_XYZ with this method.
        #[arg(long, value_parser = ["integration", "astm-e308"])]
        method: Option<String>,
        /// Also print the luminous efficacy of radiation by this rule (trapezoid = colour-science).
        #[arg(long, value_parser = ["sum", "trapezoid"])]
        efficacy_rule: Option<String>,
        /// Write the TM-30 colour vector graphic of a light source to this PNG.
        #[arg(long)]
        cvg: Option<PathBuf>,
        /// How a CSV file is resampled to 1 nm: cie167 (Sprague / cubic spline, as colour-science) or linear.
        #[arg(long, value_parser = ["cie167", "linear"], default_value = "cie167")]
        interpolation: String,
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
    /// Self-contained HTML report of a render (NAME.html): the image with a pixel probe, false colour, grids, meters; see docs/report-html.md.
    Report(cli::report::ReportArgs),
    /// Glare of a fisheye luminance image (DGP, UGR, DGI, VCP, CGI, E_v with 95 % intervals, the glare sources), as evalglare computes them; see docs/glare.md.
    Glare(cli::glare::GlareArgs),
    /// A year of daylight on the scene's grids from an EPW weather file: DA, cDA, UDI, sDA, ASE, EN 17037 with 95 % intervals, hourly illuminance (NAME.annual.json, NAME.annual.csv); see docs/annual.md.
    Annual(cli::annual::AnnualArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render(opts) => cli::render::render(&opts),
        Command::Merge(opts) => cli::render::merge(&opts),
        Command::Spectrum {
            source,
            observer,
            json,
            method,
            efficacy_rule,
            cvg,
            interpolation,
        } => {
            let obs = if observer == "1964" {
                Observer::Cie1964_10
            } else {
                Observer::Cie1931_2
            };
            // clap has checked the values: parsing cannot fail.
            let opts = cli::colour::health::SpectrumOptions {
                method: method.map(|m| cli::colour::health::parse_method(&m).expect("clap value")),
                efficacy_rule: efficacy_rule
                    .map(|r| cli::colour::health::parse_efficacy_rule(&r).expect("clap value")),
                cvg,
                interpolation: candela::colour::sd::Interpolation::parse(&interpolation)
                    .expect("clap value"),
            };
            cli::colour::spectrum_command_with(&source, obs, json, &opts).map(|s| {
                if json {
                    say_json!("{s}")
                } else {
                    say_raw!("{s}")
                }
            })
        }
        // Every value of `convert` comes from the command line: any error is a usage error.
        Command::Convert { value, from, to } => cli::colour::convert_command(value, &from, &to)
            .map(|s| say_raw!("{s}"))
            .map_err(|e| cli::usage(format!("{e:#}"))),
        Command::Luminaire { file, diagram } => {
            cli::luminaire::run(&file, diagram.as_deref()).map(|s| say_raw!("{s}"))
        }
        Command::Bench(args) => cli::bench::main(&args),
        Command::Probe(args) => cli::probe::run(&args).map(|s| {
            if args.json {
                say_json!("{s}")
            } else {
                say_raw!("{s}")
            }
        }),
        Command::Falsecolour(args) => cli::falsecolour::run(&args).map(|s| say_raw!("{s}")),
        Command::Report(args) => cli::report::run(&args).map(|s| say_raw!("{s}")),
        Command::Annual(args) => cli::annual::run(&args).map(|s| say_raw!("{s}")),
        Command::Glare(args) => cli::glare::run(&args).map(|s| {
            if args.json {
                say_json!("{s}")
            } else {
                say_raw!("{s}")
            }
        }),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!(
                "error: {}",
                cli::printable_lines(&candela::job::error_text(&e))
            );
            exit_code(&e)
        }
    }
}

/// Exit code of a failed command (docs/guarantees.md): 2 when the command line is wrong (clap
/// exits with 2 for its own errors), 1 when an input file, an output or the run failed. An
/// interrupted render exits with 130 (`cli::render`).
fn exit_code(e: &anyhow::Error) -> ExitCode {
    if e.chain().any(|c| c.is::<candela::job::InvalidOption>()) {
        ExitCode::from(2)
    } else {
        ExitCode::FAILURE
    }
}
