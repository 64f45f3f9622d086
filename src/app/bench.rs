//! `sortsim bench`: benchmarks of the simulator itself, each against a baseline measured in
//! the same run.

use std::path::Path;
use std::sync::Arc;

use super::cli::{BenchCommand, FidelityArg, PholdArgs};
use super::{writable_folder, Context, Failure};
use crate::bench::instructions::{available, needs_valgrind};
use crate::bench::{phold_report, PholdConfig};
use crate::net::Fidelity;
use crate::output::to_json;
use crate::scene::Scene;
use crate::units::SimTime;

pub(super) fn run(ctx: &Context, cmd: &BenchCommand) -> Result<(), Failure> {
    match cmd {
        BenchCommand::Phold(args) => bench_phold(args).map(|_| {
            if let Some(dir) = &args.out {
                print!("{}", crate::output::closing_line(dir, ""));
            }
        }),
        BenchCommand::Overhead {
            machine,
            scene,
            procs,
            frame,
            fidelity,
            instructions,
        } => bench_overhead(
            ctx,
            &ctx.input(machine),
            &ctx.input(scene),
            (*procs, *frame),
            fidelity,
            *instructions,
        ),
        BenchCommand::Scale {
            quick,
            frames,
            out,
            instructions,
        } => bench_scale(ctx, *quick, *frames, out, *instructions),
        BenchCommand::Replay {
            scene,
            frame,
            procs,
            assign,
            seed,
        } => bench_replay(&ctx.input(scene), *frame, procs, assign, *seed),
    }
}

/// `--instructions` asked for on a machine without valgrind: refused before anything runs.
fn valgrind_if(instructions: bool) -> Result<(), Failure> {
    if instructions && !available() {
        return Err(Failure::BadInput(needs_valgrind()));
    }
    Ok(())
}

fn bench_overhead(
    ctx: &Context,
    machine: &Path,
    scene_file: &Path,
    (procs, frame): (u32, u32),
    fidelities: &[FidelityArg],
    instructions: bool,
) -> Result<(), Failure> {
    valgrind_if(instructions)?;
    let scene = Arc::new(Scene::load(scene_file)?);
    let levels: Vec<Option<&str>> = if fidelities.is_empty() {
        vec![None]
    } else {
        fidelities
            .iter()
            .map(|&f| Some(Fidelity::from(f).name()))
            .collect()
    };
    for level in levels {
        let set = level
            .map(|l| ("machine.network.fidelity".to_string(), l.to_string()))
            .into_iter()
            .collect();
        let mut report = crate::bench::overhead(machine, scene.clone(), procs, frame, set)
            .map_err(Failure::BadInput)?;
        if instructions {
            let line = crate::bench::overhead_command_line(
                &ctx.root.path,
                machine,
                scene_file,
                procs,
                frame,
                level,
            );
            report
                .count_instructions(&line)
                .map_err(Failure::Internal)?;
        }
        print!("{}", to_json(&report));
    }
    Ok(())
}

fn bench_scale(
    ctx: &Context,
    quick: bool,
    frames: Option<u32>,
    out: &Path,
    instructions: bool,
) -> Result<(), Failure> {
    use crate::bench::scale::{scale, table, ScaleConfig};
    valgrind_if(instructions)?;
    writable_folder(out)?;
    let root = &ctx.root.path;
    let mut cfg = if quick {
        ScaleConfig::quick(root)
    } else {
        ScaleConfig::full(root)
    };
    if let Some(f) = frames {
        cfg.frames = f;
    }
    cfg.instructions = instructions;
    let report =
        scale(&cfg, &mut |step| eprintln!("measuring: {step}")).map_err(Failure::Internal)?;
    let text = table(&report);
    crate::report::bench::write_scale(out, &report, &text)?;
    print!("{text}");
    Ok(())
}

fn bench_replay(
    scene: &Path,
    frame: u32,
    procs: &str,
    assign: &str,
    seed: u64,
) -> Result<(), Failure> {
    let procs: Vec<u32> = match procs {
        "pow2" => (0..=6).map(|k| 1 << k).collect(),
        _ => (1..=64).collect(),
    };
    let rule = crate::algo::primitives::Deal::from_name(assign)
        .ok_or_else(|| Failure::BadInput(format!("--assign {assign}: unknown rule")))?;
    let report =
        crate::bench::replay_bench(scene, frame, procs, rule, seed).map_err(Failure::BadInput)?;
    print!("{}", to_json(&report));
    Ok(())
}

/// Runs PHOLD and prints its summary and cost as JSON; returns what it printed.
pub(super) fn bench_phold(
    args: &PholdArgs,
) -> Result<(crate::bench::PholdSummary, crate::bench::PholdCost), Failure> {
    valgrind_if(args.instructions)?;
    let pending = u64::from(args.lps) * u64::from(args.events_per_lp);
    if pending > crate::limits::MAX_PENDING_EVENTS {
        return Err(Failure::BadInput(format!(
            "--lps {} x --events-per-lp {} is {pending} events in flight; the engine holds at most \
             {} pending at once (crate::limits::MAX_PENDING_EVENTS)",
            args.lps,
            args.events_per_lp,
            crate::limits::MAX_PENDING_EVENTS
        )));
    }
    if args.mean == SimTime::ZERO && args.lookahead == SimTime::ZERO {
        // Every event would schedule the next at its own instant: the clock never moves.
        return Err(Failure::BadInput(
            "--mean 0 and --lookahead 0: every event would schedule the next at the same \
             instant, so simulated time would never reach --end; give either a positive \
             duration (e.g. --lookahead 100ns)"
                .to_string(),
        ));
    }
    let cfg = PholdConfig {
        lps: args.lps,
        events_per_lp: args.events_per_lp,
        remote: args.remote,
        mean: args.mean,
        lookahead: args.lookahead,
        end: args.end,
        seed: args.seed,
    };
    let (summary, mut cost) = phold_report(&cfg)?;
    if args.instructions {
        cost.count_instructions(&cfg).map_err(Failure::Internal)?;
    }
    if let Some(dir) = &args.out {
        crate::report::bench::write_phold(dir, &summary, &cost)?;
    }
    print!("{}", crate::report::bench::phold_text(&summary, &cost));
    Ok((summary, cost))
}
