//! The `sortsim` command line: parse, dispatch, print errors. No simulation logic here.
//!
//! Exit codes: 0 success, 2 bad input (one message naming file, field path or line, and what
//! is valid), 1 internal error (a bug).

mod cli;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::Parser;
use cli::{
    AccuracyArgs, BenchCommand, Cli, Command, FidelityArg, NetsimArgs, PholdArgs, RunArgs,
    SweepArgs,
};
use sortsim::algo::{reference, RunError};
use sortsim::bench::{phold_report, PholdConfig};
use sortsim::engine::SimError;
use sortsim::net::fidelity::{fidelity_table, format_table};
use sortsim::net::pattern::{run_pattern, Pattern};
use sortsim::net::Fidelity;
use sortsim::raster::encode_png;
use sortsim::report::{cost::Stopwatch, to_json, write_atomic};
use sortsim::scene::Scene;
use sortsim::spec::run::{parse_frames, RunSpec, RunSpecError};
use sortsim::spec::{check::check, load_json, machine::load_machine, SpecError, SpecKind};

/// What went wrong, sorted by whose fault it is.
enum Failure {
    BadInput(String),
    Internal(String),
}

impl From<sortsim::spec::check::CheckError> for Failure {
    fn from(e: sortsim::spec::check::CheckError) -> Failure {
        Failure::BadInput(e.to_string())
    }
}

/// A report that could not be written is the user's folder's fault; a chart that could not be
/// drawn is a bug.
impl From<sortsim::report::plot::PlotError> for Failure {
    fn from(e: sortsim::report::plot::PlotError) -> Failure {
        match e {
            sortsim::report::plot::PlotError::Io { .. } => Failure::BadInput(e.to_string()),
            _ => Failure::Internal(e.to_string()),
        }
    }
}

impl From<SpecError> for Failure {
    fn from(e: SpecError) -> Failure {
        Failure::BadInput(e.to_string())
    }
}

impl From<sortsim::scene::SceneError> for Failure {
    fn from(e: sortsim::scene::SceneError) -> Failure {
        Failure::BadInput(e.to_string())
    }
}

impl From<RunSpecError> for Failure {
    fn from(e: RunSpecError) -> Failure {
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

/// A machine too small for the run (memory) or too slow for simulated time to hold it is the
/// user's to fix; a deadlock is ours.
fn is_internal(e: &RunError) -> bool {
    matches!(e, RunError::Sim(s) if !matches!(s, SimError::Memory { .. } | SimError::TimeOverflow { .. }))
}

impl From<sortsim::engine::SimError> for Failure {
    fn from(e: sortsim::engine::SimError) -> Failure {
        Failure::Internal(e.to_string())
    }
}

fn main() -> ExitCode {
    restore_default_sigpipe();
    let cli = Cli::parse();
    let outcome = match cli.command {
        None => default_job(),
        Some(Command::Check { files }) => check_files(&files),
        Some(Command::Netsim(args)) => netsim(&args),
        Some(Command::Run(args)) => run(&args),
        Some(Command::Accuracy(args)) => accuracy(&args),
        Some(Command::Render {
            scene,
            frame,
            aa,
            out,
        }) => render(&scene, frame, aa, &out),
        Some(Command::SceneStats {
            scene,
            frames,
            regions,
            json,
        }) => scene_stats(&scene, frames.as_deref(), regions, json),
        Some(Command::Bench(BenchCommand::Phold(args))) => bench_phold(&args).map(|_| {
            if let Some(dir) = &args.out {
                print!("{}", sortsim::report::closing_line(dir, ""));
            }
        }),
        Some(Command::Bench(BenchCommand::Overhead {
            machine,
            scene,
            procs,
            frame,
            fidelity,
        })) => bench_overhead(&machine, &scene, procs, frame, &fidelity),
        Some(Command::Bench(BenchCommand::Scale { quick, frames, out })) => {
            bench_scale(quick, frames, &out)
        }
        Some(Command::Bench(BenchCommand::Replay {
            scene,
            frame,
            procs,
            assign,
            seed,
        })) => bench_replay(&scene, frame, &procs, &assign, seed),
        Some(Command::Utilization(args)) => utilization(&args),
        Some(Command::Schema { kind }) => match sortsim::spec::schema::schema_json(&kind) {
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
        Some(Command::Trace(cmd)) => trace_command(&cmd),
        Some(Command::Sweep(args)) => sweep(&args).map(|_| ()),
        Some(Command::Paper(args)) => paper(&args),
        Some(Command::Calibrate(args)) => calibrate(&args),
        Some(Command::Validate(args)) => validate(&args),
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

/// A closed pipe (`sortsim check ... | head`) ends the process quietly, as for any Unix tool,
/// instead of making a print fail.
fn restore_default_sigpipe() {
    #[cfg(unix)]
    // SAFETY: called first thing in main, before any thread exists; SIG_DFL is always valid.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

fn check_files(files: &[PathBuf]) -> Result<(), Failure> {
    let mut first_error = None;
    for file in files {
        match check_file(file) {
            Ok(summary) => println!("OK   {}: {summary}", file.display()),
            Err(e) => {
                println!("FAIL {}", file.display());
                first_error.get_or_insert(e);
            }
        }
    }
    first_error.map_or(Ok(()), Err)
}

/// One file for `check`: a trace (by its magic bytes), a calibration spec, or any other spec.
fn check_file(file: &Path) -> Result<String, Failure> {
    let head = std::fs::File::open(file).and_then(|mut f| {
        let mut head = [0u8; 8];
        std::io::Read::read(&mut f, &mut head).map(|n| head[..n].to_vec())
    });
    if head.is_ok_and(|h| h == sortsim::trace::format::MAGIC) {
        let trace =
            sortsim::trace::read_trace(file).map_err(|e| Failure::BadInput(e.to_string()))?;
        let m = trace.meta();
        return Ok(format!(
            "trace of frame {} ({}x{}, {} primitives{}): {} fragments",
            m.frame,
            m.width,
            m.height,
            m.primitives,
            if m.culled { ", back faces culled" } else { "" },
            trace.len()
        ));
    }
    if SpecKind::detect(file)? == SpecKind::Calibration {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        return sortsim::calibrate::check(file, root).map_err(|e| Failure::BadInput(e.to_string()));
    }
    Ok(check(file)?)
}

fn netsim(args: &NetsimArgs) -> Result<(), Failure> {
    let machine = load_machine(&args.machine)?;
    let pattern: Pattern = load_json(&args.pattern)?;
    let in_pattern =
        |e: sortsim::net::NetError| Failure::BadInput(format!("{}: {e}", args.pattern.display()));
    let mut network = machine.network.clone();
    if args.compare {
        let rows = fidelity_table(&network, &pattern).map_err(in_pattern)?;
        if let Some(dir) = &args.out {
            sortsim::report::netsim::write_comparison(dir, &rows)?;
        }
        print!("{}", format_table(&rows));
        return Ok(());
    }
    if let Some(f) = args.fidelity {
        network.fidelity = fidelity(f);
    }
    let clock = Stopwatch::start();
    let report = run_pattern(&network, &pattern).map_err(in_pattern)?;
    let cost = clock.cost(report.messages.len() as u64);
    if let Some(dir) = &args.out {
        sortsim::report::netsim::write(dir, &report, &cost)?;
    }
    print!("{}", to_json(&report));
    Ok(())
}

fn run(args: &RunArgs) -> Result<(), Failure> {
    let spec = RunSpec {
        schema: None,
        machine: args.machine.clone(),
        scene: args.scene.clone(),
        algo: args.algo.clone(),
        procs: args.procs,
        frames: args.frames.clone(),
        seed: args.seed,
        set: parse_set(&args.set)?,
    };
    let mut cfg = spec.resolve(None)?;
    cfg.timeline = !args.no_timeline;
    let clock = Stopwatch::start();
    let result = sortsim::algo::run(&cfg)?;
    let cost = clock.cost(result.stats.events);
    let summary = sortsim::report::run::write_report(&args.out, &cfg, &result, &cost)?;
    print!("{}", summary.markdown());
    print!("\n{}", sortsim::report::run::closing_line(&args.out, &cost));
    Ok(())
}

/// `--set KEY=VALUE` flags as a run spec's `set` map.
fn parse_set(pairs: &[String]) -> Result<std::collections::BTreeMap<String, String>, Failure> {
    pairs
        .iter()
        .map(|kv| {
            kv.split_once('=')
                .map(|(k, v)| (k.trim().to_string(), v.trim().to_string()))
                .ok_or_else(|| Failure::BadInput(format!("--set {kv}: expected KEY=VALUE")))
        })
        .collect()
}

/// The report folder: `-o` when given, else `prefix` followed by the input file's stem.
fn out_dir(given: &Option<PathBuf>, input: &Path, prefix: &str) -> PathBuf {
    given.clone().unwrap_or_else(|| {
        let stem = input
            .file_stem()
            .map_or("report".into(), |s| s.to_string_lossy().into_owned());
        PathBuf::from(format!("{prefix}{stem}"))
    })
}

/// `sortsim accuracy`: every anti-aliasing mode and network fidelity of one run, against a
/// supersampled reference; the report goes to `-o` (reports/accuracy/<scene name>).
fn accuracy(args: &AccuracyArgs) -> Result<(), Failure> {
    use sortsim::accuracy::{run_study, StudyConfig, StudyError};
    let out = out_dir(&args.out, &args.scene, "reports/accuracy/");
    let mut fidelities: Vec<Fidelity> = args.fidelities.iter().map(|&f| fidelity(f)).collect();
    fidelities.sort_unstable();
    fidelities.dedup();
    let mut modes = Vec::new();
    for m in &args.modes {
        if !modes.contains(m) {
            modes.push(*m);
        }
    }
    let cfg = StudyConfig {
        run: RunSpec {
            schema: None,
            machine: args.machine.clone(),
            scene: args.scene.clone(),
            algo: args.algo.clone(),
            procs: args.procs,
            frames: args.frames.clone(),
            seed: args.seed,
            set: parse_set(&args.set)?,
        },
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
    let markdown = sortsim::report::accuracy::write_report(&out, &study).map_err(|e| match e {
        sortsim::report::accuracy::ReportError::Io { .. } => Failure::BadInput(e.to_string()),
        _ => Failure::Internal(e.to_string()),
    })?;
    print!("\n{markdown}");
    print!("\n{}", sortsim::report::closing_line(&out, ""));
    Ok(())
}

fn render(
    scene: &Path,
    frame: u32,
    aa: sortsim::raster::aa::AaMethod,
    out: &Path,
) -> Result<(), Failure> {
    let scene = Scene::load(scene)?;
    let geometry = scene.frame(frame)?;
    let (image, counters) = reference::render_aa(&geometry, aa);
    let png = png_bytes(&image)?;
    write_bytes(out, &png)?;
    println!(
        "{}",
        to_json(&sortsim::scene::summary::counters_json(&counters)).trim_end()
    );
    println!(
        "wrote {} ({}x{})",
        out.display(),
        geometry.width,
        geometry.height
    );
    Ok(())
}

fn scene_stats(
    path: &Path,
    frames: Option<&str>,
    regions: Option<(u32, u32)>,
    json: bool,
) -> Result<(), Failure> {
    use sortsim::scene::stats::raster_overlap_factor;
    let scene = Scene::load(path)?;
    let frames = parse_frames(Some(frames.unwrap_or("0")), scene.frame_count())
        .map_err(|e| Failure::BadInput(format!("{}: --frames: {e}", path.display())))?;
    for frame in frames {
        let s = sortsim::scene::summary::summary(&scene, frame)?;
        let (rw, rh) = regions.unwrap_or((s.width.div_ceil(16), s.height.div_ceil(16)));
        let overlap = match regions {
            None => s.overlap_256,
            Some(_) => raster_overlap_factor(&scene.frame(frame)?, rw, rh),
        };
        if !json {
            print!("{s}");
            if regions.is_some() {
                println!("overlap factor for {rw}x{rh} regions: {overlap:.3}");
            }
            continue;
        }
        let value = s.to_json(overlap, (rw, rh));
        println!("{}", serde_json::to_string(&value).expect("JSON"));
    }
    Ok(())
}

fn png_bytes(image: &sortsim::raster::Framebuffer) -> Result<Vec<u8>, Failure> {
    let mut bytes = Vec::new();
    encode_png(image, &mut bytes).map_err(|e| Failure::Internal(e.to_string()))?;
    Ok(bytes)
}

fn write_bytes(path: &Path, bytes: &[u8]) -> Result<(), Failure> {
    write_atomic(path, bytes)
        .map_err(|e| Failure::BadInput(format!("{}: cannot write: {e}", path.display())))
}

/// `sortsim sweep`: runs the points (all, or one shard's), or collects the shards' points, or
/// writes and submits Slurm scripts; prints the table and any failed point; returns the table
/// as printed. Bad input is refused before any point runs; a point that fails is a row with an
/// error.
fn sweep(args: &SweepArgs) -> Result<String, Failure> {
    use sortsim::sweep::{collect, run_shard, run_sweep, spec::load_sweep, SweepOptions};
    let spec = load_sweep(&args.spec)?;
    let out = out_dir(&args.out, &args.spec, "reports/sweep-");
    if args.slurm {
        return slurm(args, &spec, &out).map(|()| String::new());
    }
    // A folder that cannot be written is found before the first point is simulated.
    if out.exists() && !out.is_dir() {
        return Err(Failure::BadInput(format!(
            "{}: cannot write the sweep there: it is a file, not a folder",
            out.display()
        )));
    }
    let jobs = jobs(args.jobs);
    let options = SweepOptions {
        jobs,
        progress: true,
    };
    if let Some(shard) = args.shard {
        let outcome = run_shard(&spec, &out, shard, options).map_err(sweep_failure)?;
        print!(
            "{}",
            sortsim::report::sweep::shard_lines(&outcome, &out, jobs)
        );
        return internal_point(&outcome.failures).map(|()| String::new());
    }
    let outcome = if args.collect {
        collect(&spec, &out)
    } else {
        run_sweep(&spec, &out, options)
    }
    .map_err(sweep_failure)?;
    let table = sortsim::sweep::table::format_rows(&outcome.rows);
    print!("{table}");
    print!(
        "{}",
        sortsim::report::sweep::closing_lines(&outcome, &out, jobs)
    );
    internal_point(&outcome.failures).map(|()| table)
}

fn sweep_failure(e: sortsim::sweep::SweepError) -> Failure {
    use sortsim::sweep::SweepError;
    match e {
        SweepError::Spec(_)
        | SweepError::BadSummary { .. }
        | SweepError::Write { .. }
        | SweepError::Slurm(_)
        | SweepError::Missing { .. } => Failure::BadInput(e.to_string()),
        SweepError::Plot(_) | SweepError::Pool { .. } => Failure::Internal(e.to_string()),
    }
}

/// A point that failed through a simulator bug makes the command fail (exit 1).
fn internal_point(failures: &[sortsim::sweep::PointFailure]) -> Result<(), Failure> {
    match failures
        .iter()
        .find(|f| f.kind == sortsim::sweep::FailureKind::Internal)
    {
        Some(f) => Err(Failure::Internal(format!(
            "point {}: {}",
            f.point, f.message
        ))),
        None => Ok(()),
    }
}

/// `sortsim sweep --slurm`: checks every point, writes the scripts, and with `--submit` hands
/// them to sbatch.
fn slurm(args: &SweepArgs, spec: &sortsim::sweep::spec::Sweep, out: &Path) -> Result<(), Failure> {
    use sortsim::sweep::slurm::{find_sbatch, submit, write_scripts, SlurmOptions};
    if args.submit && find_sbatch().is_none() {
        return Err(Failure::BadInput(
            sortsim::sweep::slurm::SubmitError::NoSbatch.to_string(),
        ));
    }
    let exe = std::env::current_exe()
        .map_err(|e| Failure::Internal(format!("cannot find the sortsim binary: {e}")))?;
    let options = SlurmOptions {
        tasks: args
            .tasks
            .unwrap_or_else(|| spec.points.len().clamp(1, 32) as u32),
        partition: args.partition.clone(),
        time: args.time.clone(),
        mem: args.mem.clone(),
        jobs: args.jobs.unwrap_or(1),
    };
    let scripts = write_scripts(spec, out, &exe, &options).map_err(sweep_failure)?;
    let submitted = if args.submit {
        Some(submit(&scripts).map_err(|e| Failure::BadInput(e.to_string()))?)
    } else {
        None
    };
    print!(
        "{}",
        sortsim::report::sweep::slurm_lines(&scripts, options.tasks, submitted.as_ref())
    );
    Ok(())
}

/// `sortsim paper`: runs each paper's experiments, writes its folder, prints its headline.
fn paper(args: &cli::PaperArgs) -> Result<(), Failure> {
    use sortsim::paper::{run_paper, PaperId, PaperOptions};
    use sortsim::report::paper::{write_overview, write_paper};
    let ids: Vec<PaperId> = match PaperId::from_id(&args.paper) {
        Some(id) => vec![id],
        None => PaperId::ALL.to_vec(),
    };
    writable_folder(&args.out)?;
    let options = PaperOptions {
        quick: args.quick,
        jobs: jobs(args.jobs),
        root: PathBuf::from(env!("CARGO_MANIFEST_DIR")),
        machines: None,
    };
    let mut reports = Vec::new();
    for id in ids {
        let clock = Stopwatch::start();
        let report = run_paper(id, &options).map_err(|e| match e {
            // A data file or machine the user edited into disagreement: bad input.
            sortsim::paper::PaperError::Data { .. } => Failure::BadInput(e.to_string()),
            _ => Failure::Internal(e.to_string()),
        })?;
        let dir = args.out.join(id.id());
        write_paper(&report, &dir)?;
        println!(
            "paper {}: {} ({:.1} s) -> {}",
            id.id(),
            report.headline(),
            clock.cost(0).wall_s,
            dir.join("index.html").display()
        );
        reports.push(report);
    }
    write_overview(&reports, &args.out)?;
    println!("overview: {}", args.out.join("index.html").display());
    Ok(())
}

/// `sortsim calibrate`: fits, writes the fitted machine and the residual table, prints it.
fn calibrate(args: &cli::CalibrateArgs) -> Result<(), Failure> {
    use sortsim::calibrate::{calibrate, load_spec, CalibrationError};
    let to_failure = |e: CalibrationError| match e {
        CalibrationError::Spec { .. } => Failure::BadInput(e.to_string()),
        CalibrationError::Failed(_) => Failure::Internal(e.to_string()),
    };
    let spec = load_spec(&args.spec).map_err(to_failure)?;
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let options = sortsim::calibrate::FitOptions {
        jobs: jobs(args.jobs),
        hold_out: args.hold_out.clone(),
        allow_predicted: args.allow_predicted,
    };
    sortsim::calibrate::validate(&spec, &args.spec, root, &options).map_err(to_failure)?;
    let out = out_dir(&args.out, &args.spec, "reports/calibrate-");
    writable_folder(&out)?;
    let result = calibrate(&spec, &args.spec, root, &options).map_err(to_failure)?;
    sortsim::report::calibration::write(&out, &result)?;
    print!("{}", sortsim::report::calibration::markdown(&result));
    println!(
        "\nfitted machine: {}; page: {}",
        out.join(&result.machine).display(),
        out.join("index.html").display()
    );
    Ok(())
}

fn validate(args: &cli::ValidateArgs) -> Result<(), Failure> {
    use sortsim::report::validate::{markdown, write, Validation};
    use sortsim::validate::{network, raster, ToolError};
    let to_failure = |e: ToolError| {
        if e.is_missing_tool() {
            Failure::BadInput(e.to_string())
        } else {
            Failure::Internal(e.to_string())
        }
    };
    writable_folder(&args.out)?;
    let work = tempfile::tempdir()
        .map_err(|e| Failure::Internal(format!("cannot make a temporary folder: {e}")))?;
    let mut result = Validation::default();
    if args.what != "raster" {
        let cases = network::cases(args.quick);
        result.network = Some(network::validate(&cases, work.path()).map_err(to_failure)?);
    }
    if args.what != "network" {
        let cases = raster::cases(args.quick);
        result.raster = Some(raster::validate(&cases, work.path()).map_err(to_failure)?);
    }
    write(&args.out, &result)?;
    print!("{}", markdown(&result));
    print!("{}", sortsim::report::closing_line(&args.out, ""));
    let agrees = result.network.as_ref().is_none_or(|(n, _)| n.pass)
        && result.raster.as_ref().is_none_or(|(r, _)| r.pass);
    if agrees {
        Ok(())
    } else {
        Err(Failure::Internal(
            "sortsim and a reference program disagree beyond the stated tolerance (see the report)"
                .into(),
        ))
    }
}

fn jobs(given: Option<u32>) -> usize {
    given.map_or_else(
        || std::thread::available_parallelism().map_or(1, |n| n.get()),
        |j| j as usize,
    )
}

fn bench_overhead(
    machine: &Path,
    scene: &Path,
    procs: u32,
    frame: u32,
    fidelities: &[FidelityArg],
) -> Result<(), Failure> {
    let scene = std::sync::Arc::new(Scene::load(scene)?);
    let levels: Vec<Option<&str>> = if fidelities.is_empty() {
        vec![None]
    } else {
        fidelities.iter().map(|f| Some(fidelity_name(*f))).collect()
    };
    for level in levels {
        let set = level
            .map(|l| ("machine.network.fidelity".to_string(), l.to_string()))
            .into_iter()
            .collect();
        let report = sortsim::bench::overhead(machine, scene.clone(), procs, frame, set)
            .map_err(Failure::BadInput)?;
        print!("{}", to_json(&report));
    }
    Ok(())
}

fn fidelity(f: FidelityArg) -> Fidelity {
    match f {
        FidelityArg::Ideal => Fidelity::Ideal,
        FidelityArg::Hops => Fidelity::Hops,
        FidelityArg::Flow => Fidelity::Flow,
        FidelityArg::Packet => Fidelity::Packet,
    }
}

/// Creates `dir` and proves a file can be written in it: an unwritable folder is bad input,
/// found before minutes of simulation rather than after.
fn writable_folder(dir: &Path) -> Result<(), Failure> {
    let probe = dir.join(".writable");
    std::fs::create_dir_all(dir)
        .and_then(|()| sortsim::report::write_atomic(&probe, b""))
        .and_then(|()| std::fs::remove_file(&probe))
        .map_err(|e| Failure::BadInput(format!("{}: cannot write: {e}", dir.display())))
}

fn bench_scale(quick: bool, frames: Option<u32>, out: &Path) -> Result<(), Failure> {
    use sortsim::bench::scale::{scale, table, ScaleConfig};
    writable_folder(out)?;
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut cfg = if quick {
        ScaleConfig::quick(root)
    } else {
        ScaleConfig::full(root)
    };
    if let Some(f) = frames {
        cfg.frames = f;
    }
    let report =
        scale(&cfg, &mut |step| eprintln!("measuring: {step}")).map_err(Failure::Internal)?;
    let text = table(&report);
    sortsim::report::bench::write_scale(out, &report, &text)?;
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
    let rule = sortsim::algo::primitives::Deal::from_name(assign)
        .ok_or_else(|| Failure::BadInput(format!("--assign {assign}: unknown rule")))?;
    let report =
        sortsim::bench::replay_bench(scene, frame, procs, rule, seed).map_err(Failure::BadInput)?;
    print!("{}", to_json(&report));
    Ok(())
}

fn fidelity_name(f: FidelityArg) -> &'static str {
    match f {
        FidelityArg::Ideal => "ideal",
        FidelityArg::Hops => "hops",
        FidelityArg::Flow => "flow",
        FidelityArg::Packet => "packet",
    }
}

/// Runs PHOLD and prints its summary and cost as JSON; returns what it printed.
fn bench_phold(args: &PholdArgs) -> Result<String, Failure> {
    let pending = u64::from(args.lps) * u64::from(args.events_per_lp);
    if pending > sortsim::limits::MAX_PENDING_EVENTS {
        return Err(Failure::BadInput(format!(
            "--lps {} x --events-per-lp {} is {pending} events in flight; the engine holds at most \
             {} pending at once (sortsim::limits::MAX_PENDING_EVENTS)",
            args.lps,
            args.events_per_lp,
            sortsim::limits::MAX_PENDING_EVENTS
        )));
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
    let (summary, cost) = phold_report(&cfg)?;
    if let Some(dir) = &args.out {
        sortsim::report::bench::write_phold(dir, &summary, &cost)?;
    }
    let text = sortsim::report::bench::phold_text(&summary, &cost);
    print!("{text}");
    Ok(text)
}

/// The main job on the built-in default: validate the bundled machines, run the default sweep
/// (sweeps/default.json: both sort-middle algorithms on the Delta, 1 to 64 processors) with
/// its table and plots, run PHOLD on the engine against its baseline, and show what network
/// fidelity costs on the Delta; the report goes to reports/default/.
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
    let sweep_table = default_sweep(root, &out)?;
    println!("\nPHOLD on the engine against a bare binary-heap loop:");
    let phold = bench_phold(&PholdArgs {
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
    sortsim::report::default_job::write_page(
        &out,
        &sortsim::report::default_job::DefaultJob {
            machines: &files,
            sweep_table: &sweep_table,
            phold: &phold,
            fidelity: &table,
        },
    )?;
    print!("\n{}", sortsim::report::closing_line(&out, ""));
    Ok(())
}

/// The default sweep, always simulated afresh (its points folder is cleared first, so a
/// changed simulator or machine never shows an old result), and its table printed.
fn default_sweep(root: &Path, out: &Path) -> Result<String, Failure> {
    let spec = root.join("sweeps/default.json");
    println!("\nThe default sweep ({}):", spec.display());
    match std::fs::remove_dir_all(out.join("points")) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
            return Err(Failure::BadInput(format!(
                "{}: cannot clear: {e}",
                out.join("points").display()
            )))
        }
        _ => {}
    }
    sweep(&SweepArgs {
        spec,
        out: Some(out.to_path_buf()),
        jobs: None,
        shard: None,
        collect: false,
        slurm: false,
        tasks: None,
        partition: None,
        time: None,
        mem: None,
        submit: false,
    })
}

/// Ellsworth's utilization simulator (paper 002, Figure 4) and performance model (Figure 5).
fn utilization(args: &cli::UtilizationArgs) -> Result<(), Failure> {
    use sortsim::algo::sort_middle::utilization::{
        parse_list, simulate, Config, CountsMode, UtilizationError,
    };
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let machine_path = args
        .machine
        .clone()
        .unwrap_or_else(|| root.join("machines/delta.json"));
    let machine = load_machine(&machine_path)?;
    let scene = Scene::load(&args.scene)?;
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
        cli::CountsArg::Current => vec![CountsMode::Current],
        cli::CountsArg::Previous => vec![CountsMode::Previous],
        cli::CountsArg::Both => vec![CountsMode::Current, CountsMode::Previous],
    };
    let clock = Stopwatch::start();
    let outcome = simulate(&scene, &machine, &cfg).map_err(|e| match e {
        UtilizationError::Invalid(m) => Failure::BadInput(m),
        UtilizationError::Scene(e) => e.into(),
    })?;
    let wall = clock.cost(0).wall_s;
    let shown = sortsim::report::utilization::FramesShown {
        step: args.frame_step,
        count: frames.len(),
        of: scene.frame_count(),
        range,
    };
    print!(
        "{}",
        sortsim::report::utilization::header(&outcome, &args.scene, &machine_path, &shown)
    );
    println!();
    print!("{}", sortsim::report::utilization::tables(&outcome, &modes));
    if let Some(dir) = &args.out {
        let (scene, machine) = (
            args.scene.display().to_string(),
            machine_path.display().to_string(),
        );
        let files = (scene.as_str(), machine.as_str());
        sortsim::report::utilization::write(dir, &outcome, &modes, files)?;
    }
    let detail = format!(" (simulated in {wall:.1} s wall)");
    match &args.out {
        Some(dir) => print!("{}", sortsim::report::closing_line(dir, &detail)),
        None => println!("simulated in {wall:.1} s wall"),
    }
    Ok(())
}

/// `sortsim trace record|replay` (paper 003's pixel traces).
fn trace_command(cmd: &cli::TraceCommand) -> Result<(), Failure> {
    match cmd {
        cli::TraceCommand::Record { scene, frame, out } => trace_record(scene, *frame, out),
        cli::TraceCommand::Replay(args) => trace_replay(args),
    }
}

fn trace_record(scene: &Path, frame: u32, out: &Path) -> Result<(), Failure> {
    let loaded = Scene::load(scene)?;
    let trace = sortsim::trace::record_scene(&loaded, frame)?;
    let bytes =
        sortsim::trace::write_trace(out, &trace).map_err(|e| Failure::BadInput(e.to_string()))?;
    print!(
        "{}",
        sortsim::report::trace::recorded_line(&trace, scene, out, bytes)
    );
    Ok(())
}

fn trace_replay(args: &cli::TraceReplayArgs) -> Result<(), Failure> {
    use sortsim::trace::replay::{Algo, Assign, Replay, ReplayConfig};
    let procs = sortsim::algo::sort_middle::utilization::parse_list(&args.procs)
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
            cli::MergeAlgoArg::DirectSend => Algo::DirectSend,
            cli::MergeAlgoArg::Pixelflow => Algo::PixelFlow,
            cli::MergeAlgoArg::Snooping => Algo::Snooping,
        })
        .collect();
    algos.sort_unstable();
    algos.dedup();
    let assign = match args.assign {
        cli::AssignArg::Scatter => Assign::Scatter,
        cli::AssignArg::Random => Assign::Random,
        cli::AssignArg::BackgroundLast => Assign::BackgroundLast,
    };
    let trace = sortsim::trace::read_trace(&args.trace).map_err(|e| match e.kind {
        sortsim::trace::format::TraceErrorKind::Format(_)
        | sortsim::trace::format::TraceErrorKind::Read(_) => Failure::BadInput(e.to_string()),
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
        sortsim::report::trace::write(dir, &report, &trace)?;
    }
    let detail = format!(" (replayed in {wall:.2} s wall)");
    match &args.out {
        Some(dir) => print!("{}", sortsim::report::closing_line(dir, &detail)),
        None => println!("replayed in {wall:.2} s wall"),
    }
    Ok(())
}
