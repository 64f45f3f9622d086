//! `sortsim utilization`: Ellsworth's utilization simulator and performance model.

use super::cli::{CountsArg, UtilizationArgs};
use super::{Context, Failure};
use crate::output::cost::Stopwatch;
use crate::scene::Scene;
use crate::spec::machine::load_machine;
use crate::spec::run::parse_frames;

/// Ellsworth's utilization simulator (paper 002, Figure 4) and performance model (Figure 5).
pub(super) fn run(ctx: &Context, args: &UtilizationArgs) -> Result<(), Failure> {
    use crate::algo::sort_middle::utilization::{
        parse_list, simulate, Config, CountsMode, UtilizationError,
    };
    let machine_path = ctx.input(
        args.machine
            .as_deref()
            .unwrap_or("machines/delta.json".as_ref()),
    );
    let machine = load_machine(&machine_path)?;
    let scene = Scene::load(&ctx.input(&args.scene))?;
    let list = |flag: &str, text: &str| {
        parse_list(text).map_err(|e| Failure::BadInput(format!("{flag}: {e}")))
    };
    let (procs, granularities) = (
        list("--procs", &args.procs)?,
        list("--granularity", &args.granularity)?,
    );
    let range = parse_frames(args.frames.as_deref(), scene.frame_count())
        .map_err(|e| Failure::BadInput(format!("{}: --frames: {e}", args.scene.display())))?;
    let frames: Vec<u32> = range.clone().step_by(args.frame_step as usize).collect();
    let cfg = Config::new(&procs, &granularities, &frames)
        .map_err(|e| Failure::BadInput(e.to_string()))?;
    let modes: Vec<CountsMode> = match args.counts {
        CountsArg::Current => vec![CountsMode::Current],
        CountsArg::Previous => vec![CountsMode::Previous],
        CountsArg::Both => vec![CountsMode::Current, CountsMode::Previous],
    };
    let clock = Stopwatch::start();
    let outcome = simulate(&scene, &machine, &cfg).map_err(|e| match e {
        UtilizationError::Invalid(m) => Failure::BadInput(m),
        UtilizationError::Scene(e) => e.into(),
    })?;
    let wall = clock.cost(0).wall_s;
    let shown = crate::report::utilization::FramesShown {
        step: args.frame_step,
        count: frames.len(),
        of: scene.frame_count(),
        range,
    };
    print!(
        "{}",
        crate::report::utilization::header(&outcome, &args.scene, &machine_path, &shown)
    );
    println!();
    print!("{}", crate::report::utilization::tables(&outcome, &modes));
    if let Some(dir) = &args.out {
        let (scene, machine) = (
            args.scene.display().to_string(),
            machine_path.display().to_string(),
        );
        let files = (scene.as_str(), machine.as_str());
        crate::report::utilization::write(dir, &outcome, &modes, files)?;
    }
    let detail = format!(" (simulated in {wall:.1} s wall)");
    match &args.out {
        Some(dir) => print!("{}", crate::output::closing_line(dir, &detail)),
        None => println!("simulated in {wall:.1} s wall"),
    }
    Ok(())
}
