//! The command line's own modules: argument parsing (clap), progress bars and printing. Each
//! subcommand parses its arguments, calls one library function and prints what it returns.

pub mod bench;
pub mod colour;
pub mod falsecolour;
pub mod luminaire;
pub mod probe;
pub mod render;
