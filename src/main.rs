//! The `sortsim` binary: parses the command line, hands it to the application layer and turns
//! the outcome into an exit code. Nothing else lives here.
//!
//! Exit codes: 0 success, 2 bad input (one message naming file, field path or line, and what
//! is valid), 1 internal error (a bug).

use std::process::ExitCode;

use clap::Parser;
use sortsim::app::{cli::Cli, dispatch};

fn main() -> ExitCode {
    restore_default_sigpipe();
    match dispatch(Cli::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(failure) => failure.report(),
    }
}

/// A closed pipe (`sortsim check ... | head`) ends the process quietly, as for any Unix tool,
/// instead of making a print fail.
fn restore_default_sigpipe() {
    #[cfg(unix)]
    // SAFETY: called first thing in main, before any thread exists; SIG_DFL is always valid.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}
