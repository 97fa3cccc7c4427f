//! The `janus2d` command (see the `janus2d_cli` library for what each
//! command does). Errors are printed as `error: …` with exit code 1;
//! bad arguments get clap's message and code 2.

use clap::Parser;

fn main() -> std::process::ExitCode {
    let cli = janus2d_cli::cli::Cli::parse();
    let mut out = std::io::stdout();
    match janus2d_cli::cli::execute(&cli, &mut out) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            std::process::ExitCode::FAILURE
        }
    }
}
