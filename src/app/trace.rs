//! `sortsim trace record|replay`: paper 003's pixel traces.

use std::path::Path;

use super::cli::{AssignArg, MergeAlgoArg, TraceCommand, TraceReplayArgs};
use super::{Context, Failure};
use crate::output::cost::Stopwatch;
use crate::scene::Scene;

/// `sortsim trace record|replay` (paper 003's pixel traces).
pub(super) fn run(ctx: &Context, cmd: &TraceCommand) -> Result<(), Failure> {
    match cmd {
        TraceCommand::Record { scene, frame, out } => trace_record(&ctx.input(scene), *frame, out),
        TraceCommand::Replay(args) => trace_replay(ctx, args),
    }
}

fn trace_record(scene: &Path, frame: u32, out: &Path) -> Result<(), Failure> {
    let loaded = Scene::load(scene)?;
    let trace = crate::trace::record_scene(&loaded, frame)?;
    let bytes =
        crate::trace::write_trace(out, &trace).map_err(|e| Failure::BadInput(e.to_string()))?;
    print!(
        "{}",
        crate::report::trace::recorded_line(&trace, scene, out, bytes)
    );
    Ok(())
}

fn trace_replay(ctx: &Context, args: &TraceReplayArgs) -> Result<(), Failure> {
    use crate::trace::replay::{Algo, Assign, Replay, ReplayConfig};
    let procs = crate::algo::sort_middle::utilization::parse_list(&args.procs)
        .map_err(|e| Failure::BadInput(format!("--procs: {e}")))?;
    if let Some(&bad) = procs.iter().find(|&&n| !(1..=65_536).contains(&n)) {
        return Err(Failure::BadInput(format!(
            "--procs: {bad} processors is out of range (valid: 1..=65536)"
        )));
    }
    let mut algos: Vec<Algo> = args
        .algo
        .iter()
        .map(|a| match a {
            MergeAlgoArg::DirectSend => Algo::DirectSend,
            MergeAlgoArg::Pixelflow => Algo::PixelFlow,
            MergeAlgoArg::Snooping => Algo::Snooping,
        })
        .collect();
    algos.sort_unstable();
    algos.dedup();
    let assign = match args.assign {
        AssignArg::Scatter => Assign::Scatter,
        AssignArg::Random => Assign::Random,
        AssignArg::BackgroundLast => Assign::BackgroundLast,
    };
    let trace = crate::trace::read_trace(&ctx.input(&args.trace)).map_err(|e| match e.kind {
        crate::trace::format::TraceErrorKind::Format(_)
        | crate::trace::format::TraceErrorKind::Read(_) => Failure::BadInput(e.to_string()),
        _ => Failure::Internal(e.to_string()),
    })?;
    let config = ReplayConfig {
        algos,
        procs,
        assign,
        seed: args.seed,
        local_zbuffer: args.local_zbuffer,
    };
    let clock = Stopwatch::start();
    let report = Replay::new(&trace).run(&config);
    let wall = clock.cost(0).wall_s;
    println!("{}", args.trace.display());
    print!("{}", report.table());
    if let Some(dir) = &args.out {
        let trace = args.trace.display().to_string();
        crate::report::trace::write(dir, &report, &trace)?;
    }
    let detail = format!(" (replayed in {wall:.2} s wall)");
    match &args.out {
        Some(dir) => print!("{}", crate::output::closing_line(dir, &detail)),
        None => println!("replayed in {wall:.2} s wall"),
    }
    Ok(())
}
