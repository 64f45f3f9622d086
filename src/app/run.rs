//! `sortsim run` and `sortsim accuracy`: one simulated run (or one per anti-aliasing mode and
//! fidelity) and its report. The run itself lives in `algo`, the report in `report`.

use std::collections::BTreeMap;
use std::path::Path;

use super::cli::{AccuracyArgs, RunArgs};
use super::{is_internal, out_dir, Context, Failure};
use crate::net::Fidelity;
use crate::output::cost::Stopwatch;
use crate::spec::run::RunSpec;

pub(super) fn run(ctx: &Context, args: &RunArgs, verbose: bool) -> Result<(), Failure> {
    let spec = run_spec(
        ctx,
        (&args.machine, &args.scene, &args.algo),
        (args.procs, &args.frames, args.seed),
        &args.set,
    )?;
    let mut cfg = spec.resolve(None)?;
    cfg.timeline = !args.no_timeline;
    cfg.timeline_frames = args
        .timeline_frames
        .as_deref()
        .map(|text| timeline_frames(text, &cfg.frames, cfg.scene.frame_count()))
        .transpose()?;
    let clock = Stopwatch::start();
    let result = crate::algo::run(&cfg)?;
    let cost = clock.cost(result.stats.events);
    let summary = crate::report::run::write_report(&args.out, &cfg, &result, &cost)?;
    print!("{}", summary.terminal(verbose));
    print!("\n{}", crate::report::run::closing_line(&args.out, &cost));
    Ok(())
}

/// `--timeline-frames`: frames of the scene, and of the run's `--frames`.
fn timeline_frames(
    text: &str,
    run: &std::ops::Range<u32>,
    scene_frames: u32,
) -> Result<std::ops::Range<u32>, Failure> {
    let bad = |why: String| Failure::BadInput(format!("--timeline-frames {text}: {why}"));
    let covered = crate::spec::run::parse_frames(Some(text), scene_frames).map_err(bad)?;
    if covered.start < run.start || covered.end > run.end {
        return Err(bad(format!(
            "the run has frames {}..{} (--frames); the timeline can cover only frames within them",
            run.start, run.end
        )));
    }
    Ok(covered)
}

/// The run spec that `run`'s and `accuracy`'s flags spell: (machine, scene, algo), (procs,
/// frames, seed) and the `--set` pairs, files found by the data-root rule.
fn run_spec(
    ctx: &Context,
    (machine, scene, algo): (&Path, &Path, &str),
    (procs, frames, seed): (u32, &Option<String>, u64),
    set: &[String],
) -> Result<RunSpec, Failure> {
    Ok(RunSpec {
        schema: None,
        machine: ctx.input(machine),
        scene: ctx.input(scene),
        algo: algo.to_string(),
        procs,
        frames: frames.clone(),
        seed,
        set: parse_set(set)?,
    })
}

/// `--set KEY=VALUE` flags as a run spec's `set` map.
fn parse_set(pairs: &[String]) -> Result<BTreeMap<String, String>, Failure> {
    pairs
        .iter()
        .map(|kv| {
            kv.split_once('=')
                .map(|(k, v)| (k.trim().to_string(), v.trim().to_string()))
                .ok_or_else(|| Failure::BadInput(format!("--set {kv}: expected KEY=VALUE")))
        })
        .collect()
}

/// `sortsim accuracy`: every anti-aliasing mode and network fidelity of one run, against a
/// supersampled reference; the report goes to `-o` (reports/accuracy/<scene name>).
pub(super) fn accuracy(ctx: &Context, args: &AccuracyArgs) -> Result<(), Failure> {
    use crate::accuracy::{run_study, StudyConfig, StudyError};
    let out = out_dir(&args.out, &args.scene, "reports/accuracy/");
    let mut fidelities: Vec<Fidelity> = args.fidelities.iter().map(|&f| f.into()).collect();
    fidelities.sort_unstable();
    fidelities.dedup();
    let mut modes = Vec::new();
    for m in &args.modes {
        if !modes.contains(m) {
            modes.push(*m);
        }
    }
    let cfg = StudyConfig {
        run: run_spec(
            ctx,
            (&args.machine, &args.scene, &args.algo),
            (args.procs, &args.frames, args.seed),
            &args.set,
        )?,
        modes,
        fidelities,
        reference_scale: args.reference_scale,
    };
    let study = run_study(&cfg, &mut |line| println!("{line}")).map_err(|e| {
        let internal = matches!(e, StudyError::Size(_)) || e.run_error().is_some_and(is_internal);
        if internal {
            Failure::Internal(e.to_string())
        } else {
            Failure::BadInput(e.to_string())
        }
    })?;
    let markdown = crate::report::accuracy::write_report(&out, &study).map_err(|e| match e {
        crate::report::accuracy::ReportError::Io { .. } => Failure::BadInput(e.to_string()),
        _ => Failure::Internal(e.to_string()),
    })?;
    print!("\n{markdown}");
    print!("\n{}", crate::output::closing_line(&out, ""));
    Ok(())
}
