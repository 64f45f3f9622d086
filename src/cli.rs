//! Command-line arguments (clap): structure and validation of flags only. Turning them into a
//! run, and printing, happens in `main.rs`; the work itself in the library.

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand, ValueEnum};

#[derive(Parser, Debug)]
#[command(
    name = "sortsim",
    version,
    about = "Deterministic simulator of parallel polygon-rendering machines",
    long_about = "Deterministic discrete-event simulator of parallel polygon-rendering machines \
(sort-middle, sort-last, pixel merging, adaptive supersampling). With no command it runs the \
built-in default job and writes its report under reports/.",
    after_help = "Examples:\n  sortsim check machines/*.json\n  sortsim netsim machines/delta.json tests/patterns/complement-16x32.json --fidelity packet\n  sortsim bench phold --lps 1024 --events-per-lp 16"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Validate machine, scene, run and sweep specs (the kind is detected).
    #[command(after_help = "Example:\n  sortsim check machines/*.json")]
    Check {
        /// Spec files to validate.
        #[arg(required = true)]
        files: Vec<PathBuf>,
    },
    /// Simulate a list of messages on a machine's network and print each completion time.
    #[command(
        after_help = "Example:\n  sortsim netsim machines/multicluster-torus.json tests/patterns/hot-spot-4x4.json --fidelity flow\n  sortsim netsim machines/delta.json tests/patterns/complement-16x32.json --compare"
    )]
    Netsim(NetsimArgs),
    /// Benchmarks of the simulator itself.
    #[command(subcommand)]
    Bench(BenchCommand),
}

#[derive(Args, Debug)]
pub struct NetsimArgs {
    /// Machine spec (its network is used).
    pub machine: PathBuf,
    /// Pattern file: {"messages": [{"src": 0, "dst": 5, "bytes": "64KiB", "start": "0us"}, ...]}.
    pub pattern: PathBuf,
    /// Override the machine's network.fidelity.
    #[arg(long, value_enum)]
    pub fidelity: Option<FidelityArg>,
    /// Run the pattern at every fidelity and print predicted time against simulator wall time.
    #[arg(long, conflicts_with = "fidelity")]
    pub compare: bool,
    /// Also write DIR/summary.json (the printed report) and DIR/cost.json (wall time).
    #[arg(short, long, value_name = "DIR")]
    pub out: Option<PathBuf>,
}

#[derive(ValueEnum, Clone, Copy, Debug)]
pub enum FidelityArg {
    Ideal,
    Hops,
    Flow,
    Packet,
}

#[derive(Subcommand, Debug)]
pub enum BenchCommand {
    /// PHOLD on the engine against a bare binary-heap loop, in the same run.
    #[command(
        after_help = "Example:\n  sortsim bench phold --lps 1024 --events-per-lp 16 --end 2ms"
    )]
    Phold(PholdArgs),
}

#[derive(Args, Debug)]
pub struct PholdArgs {
    /// Logical processes.
    #[arg(long, default_value_t = 1024, value_parser = clap::value_parser!(u32).range(1..))]
    pub lps: u32,
    /// Initial events per LP (events in flight = lps x this).
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u32).range(1..))]
    pub events_per_lp: u32,
    /// Probability that an event is scheduled at another LP.
    #[arg(long, default_value_t = 0.9, value_parser = probability)]
    pub remote: f64,
    /// Mean of the exponential part of the delay.
    #[arg(long, default_value = "1us")]
    pub mean: sortsim::units::SimTime,
    /// Fixed part of the delay (the lookahead).
    #[arg(long, default_value = "100ns")]
    pub lookahead: sortsim::units::SimTime,
    /// Simulated end time.
    #[arg(long, default_value = "1ms")]
    pub end: sortsim::units::SimTime,
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Also write DIR/summary.json (deterministic) and DIR/cost.json (wall times).
    #[arg(short, long, value_name = "DIR")]
    pub out: Option<PathBuf>,
}

fn probability(s: &str) -> Result<f64, String> {
    let p: f64 = s
        .parse()
        .map_err(|_| format!("'{s}' is not a number; expected a probability in 0..=1"))?;
    if (0.0..=1.0).contains(&p) {
        Ok(p)
    } else {
        Err(format!(
            "{p} is not a probability; expected a number in 0..=1"
        ))
    }
}
