//! `sortsim netsim`: a list of messages on a machine's network, at one fidelity or all.

use super::cli::NetsimArgs;
use super::{Context, Failure};
use crate::net::fidelity::{fidelity_table, format_table, levels_refused};
use crate::net::pattern::{run_pattern, Pattern};
use crate::net::Network;
use crate::output::{cost::Stopwatch, to_json};
use crate::spec::{load_json, machine::load_machine};

pub(super) fn run(ctx: &Context, args: &NetsimArgs) -> Result<(), Failure> {
    let machine = load_machine(&ctx.input(&args.machine))?;
    let pattern_file = ctx.input(&args.pattern);
    let pattern: Pattern = load_json(&pattern_file)?;
    let in_pattern =
        |e: crate::net::NetError| Failure::BadInput(format!("{}: {e}", pattern_file.display()));
    let mut network = machine.network.clone();
    if args.compare {
        let rows = fidelity_table(&network, &pattern).map_err(in_pattern)?;
        if let Some(dir) = &args.out {
            crate::report::netsim::write_comparison(dir, &rows)?;
        }
        print!("{}", format_table(&rows));
        for (fidelity, why) in levels_refused(&network) {
            println!("{fidelity}: not run on this network: {why}");
        }
        return Ok(());
    }
    if let Some(f) = args.fidelity {
        network.fidelity = f.into();
        Network::new(&network).map_err(|e| {
            Failure::BadInput(format!(
                "--fidelity {}: {}: {e}",
                network.fidelity,
                ctx.input(&args.machine).display()
            ))
        })?;
    }
    let clock = Stopwatch::start();
    let report = run_pattern(&network, &pattern).map_err(in_pattern)?;
    let cost = clock.cost(report.messages.len() as u64);
    if let Some(dir) = &args.out {
        crate::report::netsim::write(dir, &report, &cost)?;
    }
    print!("{}", to_json(&report));
    Ok(())
}
