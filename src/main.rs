//! The `sortsim` command line: parse, dispatch, print errors. No simulation logic here.
//!
//! Exit codes: 0 success, 2 bad input (one message naming file, field path or line, and what
//! is valid), 1 internal error (a bug).

mod cli;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::Parser;
use cli::{BenchCommand, Cli, Command, FidelityArg, NetsimArgs, PholdArgs};
use sortsim::bench::{phold_report, PholdConfig};
use sortsim::net::fidelity::{fidelity_table, format_table};
use sortsim::net::pattern::{run_pattern, Pattern};
use sortsim::net::Fidelity;
use sortsim::report::{cost::Stopwatch, to_json, write_atomic};
use sortsim::spec::{check::check, load_json, machine::load_machine, SpecError};

/// What went wrong, sorted by whose fault it is.
enum Failure {
    BadInput(String),
    Internal(String),
}

impl From<SpecError> for Failure {
    fn from(e: SpecError) -> Failure {
        Failure::BadInput(e.to_string())
    }
}

impl From<sortsim::engine::SimError> for Failure {
    fn from(e: sortsim::engine::SimError) -> Failure {
        Failure::Internal(e.to_string())
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let outcome = match cli.command {
        None => default_job(),
        Some(Command::Check { files }) => check_files(&files),
        Some(Command::Netsim(args)) => netsim(&args),
        Some(Command::Bench(BenchCommand::Phold(args))) => bench_phold(&args),
    };
    match outcome {
        Ok(()) => ExitCode::SUCCESS,
        Err(Failure::BadInput(msg)) => {
            eprintln!("error: {msg}");
            ExitCode::from(2)
        }
        Err(Failure::Internal(msg)) => {
            eprintln!("internal error (please report it): {msg}");
            ExitCode::from(1)
        }
    }
}

fn check_files(files: &[PathBuf]) -> Result<(), Failure> {
    let mut first_error = None;
    for file in files {
        match check(file) {
            Ok(summary) => println!("OK   {}: {summary}", file.display()),
            Err(e) => {
                println!("FAIL {}", file.display());
                first_error.get_or_insert(e);
            }
        }
    }
    first_error.map_or(Ok(()), |e| Err(e.into()))
}

fn netsim(args: &NetsimArgs) -> Result<(), Failure> {
    let machine = load_machine(&args.machine)?;
    let pattern: Pattern = load_json(&args.pattern)?;
    let in_pattern =
        |e: sortsim::net::NetError| Failure::BadInput(format!("{}: {e}", args.pattern.display()));
    let mut network = machine.network.clone();
    if args.compare {
        let rows = fidelity_table(&network, &pattern).map_err(in_pattern)?;
        print!("{}", format_table(&rows));
        return Ok(());
    }
    if let Some(f) = args.fidelity {
        network.fidelity = match f {
            FidelityArg::Ideal => Fidelity::Ideal,
            FidelityArg::Hops => Fidelity::Hops,
            FidelityArg::Flow => Fidelity::Flow,
            FidelityArg::Packet => Fidelity::Packet,
        };
    }
    let clock = Stopwatch::start();
    let report = run_pattern(&network, &pattern).map_err(in_pattern)?;
    let cost = clock.cost(report.messages.len() as u64);
    let json = to_json(&report);
    if let Some(dir) = &args.out {
        write_file(dir, "summary.json", &json)?;
        write_file(dir, "cost.json", &to_json(&cost))?;
    }
    print!("{json}");
    Ok(())
}

fn write_file(dir: &Path, name: &str, text: &str) -> Result<(), Failure> {
    let path = dir.join(name);
    write_atomic(&path, text.as_bytes())
        .map_err(|e| Failure::BadInput(format!("{}: cannot write: {e}", path.display())))
}

fn bench_phold(args: &PholdArgs) -> Result<(), Failure> {
    let cfg = PholdConfig {
        lps: args.lps,
        events_per_lp: args.events_per_lp,
        remote: args.remote,
        mean: args.mean,
        lookahead: args.lookahead,
        end: args.end,
        seed: args.seed,
    };
    let (summary, cost) = phold_report(&cfg)?;
    if let Some(dir) = &args.out {
        write_file(dir, "summary.json", &to_json(&summary))?;
        write_file(dir, "cost.json", &to_json(&cost))?;
    }
    print!("{}{}", to_json(&summary), to_json(&cost));
    Ok(())
}

/// The main job on the built-in default: validate the bundled machines, run PHOLD on the
/// engine against its baseline, and show what network fidelity costs on the Delta; the report
/// goes to reports/default/.
fn default_job() -> Result<(), Failure> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let machines = root.join("machines");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&machines)
        .map_err(|e| Failure::Internal(format!("{}: {e}", machines.display())))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .collect();
    files.sort();
    check_files(&files)?;
    let out = root.join("reports/default");
    println!("\nPHOLD, 16,384 events in flight, engine against a bare binary-heap loop:");
    bench_phold(&PholdArgs {
        lps: 1024,
        events_per_lp: 16,
        remote: 0.9,
        mean: sortsim::units::SimTime::from_us(1),
        lookahead: sortsim::units::SimTime::from_ns(100),
        end: sortsim::units::SimTime::from_us(500),
        seed: 1,
        out: Some(out.join("phold")),
    })?;
    println!(
        "\nThe Delta's 16x32 mesh, every node sends 64 KiB to its mirror node (bit complement):"
    );
    let delta = load_machine(&machines.join("delta.json"))?;
    let pattern: Pattern = load_json(&root.join("tests/patterns/complement-16x32.json"))?;
    let rows =
        fidelity_table(&delta.network, &pattern).map_err(|e| Failure::Internal(e.to_string()))?;
    let table = format_table(&rows);
    print!("{table}");
    write_file(&out, "fidelity.txt", &table)?;
    println!("\nreport written to {}", out.display());
    Ok(())
}
