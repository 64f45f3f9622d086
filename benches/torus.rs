//! The staggered torus pattern of `sortsim bench scale`, run once, alone in its process, so
//! that a profiler or callgrind sees nothing else: `cargo bench --bench torus -- [messages]
//! [hops|flow]` (16,384 messages at `flow` by default) prints the wall time and what the
//! pattern's report gives, to compare two builds' answers as well as their cost.
//!
//! Must never feed wall time into a simulated result, and never write a file.

use std::path::Path;
use std::time::Instant;

use sortsim::bench::scale::staggered_torus;
use sortsim::net::pattern::run_pattern;
use sortsim::net::Fidelity;

fn main() {
    // `cargo bench` passes `--bench`; the figures are the other arguments.
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| a != "--bench")
        .collect();
    let (count, fidelity) = match parse(&args) {
        Ok(figures) => figures,
        Err(why) => {
            eprintln!("error: {why}\nusage: cargo bench --bench torus -- [MESSAGES] [hops|flow]");
            std::process::exit(2);
        }
    };
    let machine = Path::new(env!("CARGO_MANIFEST_DIR")).join("machines/delta.json");
    let (network, pattern) = match staggered_torus(&machine, count, fidelity) {
        Ok(both) => both,
        Err(why) => {
            eprintln!("error: {why}");
            std::process::exit(2);
        }
    };
    let start = Instant::now();
    let report = run_pattern(&network, &pattern).expect("the pattern runs");
    let wall = start.elapsed().as_secs_f64();
    let completions: u128 = report
        .messages
        .iter()
        .map(|m| m.completion_ps as u128)
        .sum();
    println!(
        "{count} staggered messages, 16x32 torus, {fidelity:?}: {wall:.3} s wall; makespan {} ps, completions summing to {completions} ps",
        report.makespan_ps
    );
}

/// The count of messages (16,384 when absent, at least 1) and the fidelity (`flow` when absent).
fn parse(args: &[String]) -> Result<(usize, Fidelity), String> {
    let count = match args.first() {
        None => 16_384,
        Some(a) => match a.parse::<usize>() {
            Ok(n) if n > 0 => n,
            _ => return Err(format!("messages `{a}`: a whole number of at least 1")),
        },
    };
    let fidelity = match args.get(1).map(String::as_str) {
        None | Some("flow") => Fidelity::Flow,
        Some("hops") => Fidelity::Hops,
        Some(other) => return Err(format!("fidelity `{other}`: hops or flow")),
    };
    match args.get(2) {
        Some(extra) => Err(format!("unexpected `{extra}`")),
        None => Ok((count, fidelity)),
    }
}
