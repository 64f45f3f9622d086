//! The application layer: one module per command, turning parsed flags into calls on the
//! library and its results into reports and terminal lines. Owns the data-root rule (`data`),
//! the mapping of every error to whose fault it is (`Failure`), and where reports go; never
//! simulates, rasterizes or formats a report itself (that is `algo`, `raster` and `report`).

pub mod cli;
pub mod data;

mod bench;
mod check;
mod default_job;
mod netsim;
mod paper;
mod run;
mod scene;
mod sweep;
mod trace;
mod utilization;
mod validate;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use crate::algo::RunError;
use crate::engine::SimError;
use crate::spec::SpecError;
use cli::{Cli, Command};
use data::DataRoot;

/// What went wrong, sorted by whose fault it is.
#[derive(Debug)]
pub enum Failure {
    /// The user's to fix: exit code 2, one message naming the file, field or flag.
    BadInput(String),
    /// A bug: exit code 1.
    Internal(String),
}

impl Failure {
    /// The process's exit code, after printing the message to stderr.
    pub fn report(self) -> ExitCode {
        match self {
            Failure::BadInput(msg) => {
                eprintln!("error: {msg}");
                ExitCode::from(2)
            }
            Failure::Internal(msg) => {
                eprintln!("internal error (please report it): {msg}");
                ExitCode::from(1)
            }
        }
    }
}

impl From<crate::spec::check::CheckError> for Failure {
    fn from(e: crate::spec::check::CheckError) -> Failure {
        Failure::BadInput(e.to_string())
    }
}

/// A report that could not be written is the user's folder's fault; a chart that could not be
/// drawn is a bug.
impl From<crate::output::plot::PlotError> for Failure {
    fn from(e: crate::output::plot::PlotError) -> Failure {
        match e {
            crate::output::plot::PlotError::Io { .. } => Failure::BadInput(e.to_string()),
            _ => Failure::Internal(e.to_string()),
        }
    }
}

impl From<SpecError> for Failure {
    fn from(e: SpecError) -> Failure {
        Failure::BadInput(e.to_string())
    }
}

impl From<crate::scene::SceneError> for Failure {
    fn from(e: crate::scene::SceneError) -> Failure {
        Failure::BadInput(e.to_string())
    }
}

impl From<crate::spec::run::RunSpecError> for Failure {
    fn from(e: crate::spec::run::RunSpecError) -> Failure {
        Failure::BadInput(e.to_string())
    }
}

impl From<RunError> for Failure {
    fn from(e: RunError) -> Failure {
        if is_internal(&e) {
            Failure::Internal(e.to_string())
        } else {
            Failure::BadInput(e.to_string())
        }
    }
}

impl From<SimError> for Failure {
    fn from(e: SimError) -> Failure {
        Failure::Internal(e.to_string())
    }
}

/// A machine too small for the run (memory) or too slow for simulated time to hold it is the
/// user's to fix; a deadlock is ours.
fn is_internal(e: &RunError) -> bool {
    matches!(e, RunError::Sim(s) if !matches!(s, SimError::Memory { .. } | SimError::TimeOverflow { .. }))
}

/// What every command is given besides its flags.
pub struct Context {
    /// Where bundled machines, scenes, sweeps and papers are read from.
    pub root: DataRoot,
}

impl Context {
    /// A file named on the command line, found by the data-root rule.
    fn input(&self, given: &Path) -> PathBuf {
        self.root.input(given)
    }
}

/// Runs the parsed command line.
pub fn dispatch(cli: Cli) -> Result<(), Failure> {
    let root = DataRoot::find(cli.root.as_deref()).map_err(Failure::BadInput)?;
    let ctx = Context { root };
    match cli.command {
        None => default_job::run(&ctx),
        Some(Command::Check { files }) => check::run(&ctx, &files),
        Some(Command::Netsim(args)) => netsim::run(&ctx, &args),
        Some(Command::Run(args)) => run::run(&ctx, &args, cli.verbose),
        Some(Command::Accuracy(args)) => run::accuracy(&ctx, &args),
        Some(Command::Render(args)) => scene::render(&ctx, &args),
        Some(Command::SceneStats(args)) => scene::stats(&ctx, &args),
        Some(Command::Bench(cmd)) => bench::run(&ctx, &cmd),
        Some(Command::Utilization(args)) => utilization::run(&ctx, &args),
        Some(Command::Schema { kind }) => match crate::spec::schema::schema_json(&kind) {
            Some(text) => {
                print!("{text}");
                Ok(())
            }
            None => Err(Failure::BadInput(format!("{kind}: unknown spec kind"))),
        },
        Some(Command::Completions { shell }) => {
            use clap::CommandFactory;
            let mut command = Cli::command();
            clap_complete::generate(shell, &mut command, "sortsim", &mut std::io::stdout());
            Ok(())
        }
        Some(Command::Trace(cmd)) => trace::run(&ctx, &cmd),
        Some(Command::Sweep(args)) => sweep::run(&ctx, &args).map(|_| ()),
        Some(Command::Paper(args)) => paper::paper(&ctx, &args),
        Some(Command::Calibrate(args)) => paper::calibrate(&ctx, &args),
        Some(Command::Validate(args)) => validate::run(&args),
    }
}

/// The report folder: `-o` when given, else `prefix` followed by the input file's stem, under
/// the current folder.
fn out_dir(given: &Option<PathBuf>, input: &Path, prefix: &str) -> PathBuf {
    given.clone().unwrap_or_else(|| {
        let stem = input
            .file_stem()
            .map_or("report".into(), |s| s.to_string_lossy().into_owned());
        PathBuf::from(format!("{prefix}{stem}"))
    })
}

/// Creates `dir` and proves a file can be written in it: an unwritable folder is bad input,
/// found before minutes of simulation rather than after.
fn writable_folder(dir: &Path) -> Result<(), Failure> {
    let probe = dir.join(".writable");
    std::fs::create_dir_all(dir)
        .and_then(|()| crate::output::write_atomic(&probe, b""))
        .and_then(|()| std::fs::remove_file(&probe))
        .map_err(|e| Failure::BadInput(format!("{}: cannot write: {e}", dir.display())))
}

fn write_bytes(path: &Path, bytes: &[u8]) -> Result<(), Failure> {
    crate::output::write_atomic(path, bytes)
        .map_err(|e| Failure::BadInput(format!("{}: cannot write: {e}", path.display())))
}

/// Simulations at a time: `--jobs`, else the number of cores.
fn jobs(given: Option<u32>) -> usize {
    given.map_or_else(
        || std::thread::available_parallelism().map_or(1, |n| n.get()),
        |j| j as usize,
    )
}
