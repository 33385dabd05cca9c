//! The `cellmd` executable: the command line of [`cellmd::cli`].

use std::process::ExitCode;

fn main() -> ExitCode {
    cellmd::cli::main(std::env::args_os())
}
