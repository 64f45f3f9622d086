//! Parameter sweeps: many independent runs of `algo::run` on a rayon thread pool, one report
//! folder per point, then one table (sweep.csv, sweep.json) and the plots over them.
//!
//! ```text
//! sweep.json ─> spec::Sweep (points in product order) ─> pending points (no summary.json yet)
//!     ─> thread pool: resolve, run, write points/<name>/summary.json + cost.json
//!     ─> every point's summary.json ─> table::Row (speedup against the 1-processor point)
//!     ─> sweep.csv, sweep.json, plots/*.svg|png, index.html, cost.json
//! ```
//!
//! Determinism: a point's result depends only on its run spec; results are collected by
//! point index and every row is read back from the summary.json text, so the table is
//! byte-identical whatever the thread count, and whether a point ran now or in an earlier,
//! interrupted sweep. Wall time goes only to the cost files.
//!
//! Owns scheduling, resuming and the report folder of a sweep. Must never change how a single
//! run simulates (that is `algo`), and never write a file except through `write_atomic`.

pub mod page;
pub mod plots;
pub mod shard;
pub mod slurm;
pub mod spec;
pub mod table;

use std::collections::BTreeMap;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::algo::{RunConfig, RunError};
use crate::engine::SimError;
use crate::metrics::run::RunSummary;
use crate::output::cost::{Cost, Stopwatch};
use crate::output::plot::PlotError;
use crate::output::{to_json, write_atomic};
use crate::scene::Scene;
use crate::spec::run::parse_frames;
use crate::spec::SpecError;
pub use shard::Shard;
use spec::{Point, Sweep};
use table::{PointMetrics, Row};

/// How to run a sweep (not what: that is the spec).
#[derive(Debug, Clone, Copy)]
pub struct SweepOptions {
    /// Simulations at a time (threads of the pool); at least 1.
    pub jobs: usize,
    /// Draw a progress bar on stderr (only ever drawn when stderr is a terminal).
    pub progress: bool,
}

/// What a finished sweep did.
#[derive(Debug)]
pub struct SweepOutcome {
    /// One row per listed point, in product order.
    pub rows: Vec<Row>,
    /// Points simulated now, and points whose summary.json an earlier sweep had written.
    pub ran: usize,
    pub skipped: usize,
    /// Points that failed: (point name, message, whether it is a simulator bug).
    pub failures: Vec<PointFailure>,
    pub cost: Cost,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct PointFailure {
    pub point: String,
    pub message: String,
    pub kind: FailureKind,
}

/// Whose a failed point is to fix.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum FailureKind {
    /// The machine cannot hold the run (memory): a result in itself, recorded in the row, as
    /// paper 002 records the partitions too small for the large models.
    Machine,
    /// A bad option value or an unsupported combination: the sweep is refused as bad input.
    BadInput,
    /// A deadlock or other engine failure: a bug, recorded in the row and reported.
    Internal,
}

#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    /// Bad input: the spec, a machine, a scene, or a point that cannot be set up.
    #[error(transparent)]
    Spec(#[from] SpecError),
    #[error("{}: cannot write: {source}", path.display())]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{}: {message}; delete it to run the point again", path.display())]
    BadSummary { path: PathBuf, message: String },
    #[error(transparent)]
    Plot(#[from] PlotError),
    #[error("cannot start {jobs} worker threads: {message}")]
    Pool { jobs: usize, message: String },
    /// A Slurm option or path that cannot go into a batch script (bad input).
    #[error("{0}")]
    Slurm(String),
    /// `--collect` before every point has a result.
    #[error("{}", missing_message(dir, missing, *foreign, rerun))]
    Missing {
        dir: PathBuf,
        missing: Vec<String>,
        /// The command that runs just the missing points.
        rerun: String,
        /// Point folders that belong to no point of this sweep.
        foreign: usize,
    },
}

fn missing_message(dir: &Path, missing: &[String], foreign: usize, rerun: &str) -> String {
    let mut text = format!(
        "{}: {} point(s) of this sweep have no result (no summary.json or failure.json): {}",
        dir.display(),
        missing.len(),
        missing.join(", ")
    );
    if foreign > 0 {
        text += &format!(
            "; {} folder(s) under points/ belong to no point of this sweep: the folder holds \
             another sweep, or this one from before its spec, machine or scene changed",
            foreign
        );
    }
    text + "; to run just the missing points: " + rerun
}

/// Runs every point of `sweep` whose `out/points/<name>/summary.json` does not exist yet,
/// then writes the table and plots over all points.
pub fn run_sweep(
    sweep: &Sweep,
    out: &Path,
    options: SweepOptions,
) -> Result<SweepOutcome, SweepError> {
    let clock = Stopwatch::start();
    let names = point_names(sweep);
    let all: Vec<usize> = (0..sweep.points.len()).collect();
    let ran = run_points(sweep, out, &names, &all, options, &mut Scenes::default())?;
    let metrics = read_metrics(out, &names, &ran.failures)?;
    finish(sweep, out, &names, metrics, ran, clock, options.jobs)
}

/// Sets up every point of `sweep` (machine, scene, processors, frames, options) as `run_sweep`
/// would before it runs any, and runs none: what `sortsim check` does for a sweep.
pub fn check(sweep: &Sweep) -> Result<(), SpecError> {
    let names = point_names(sweep);
    let all: Vec<usize> = (0..sweep.points.len()).collect();
    resolve_pending(sweep, &names, &all, &mut Scenes::default()).map(|_| ())
}

/// Runs the points of one shard of `sweep` that have no summary.json yet (a Slurm array
/// task); writes only those points' folders. The table is `collect`'s to write.
pub fn run_shard(
    sweep: &Sweep,
    out: &Path,
    shard: Shard,
    options: SweepOptions,
) -> Result<ShardOutcome, SweepError> {
    let clock = Stopwatch::start();
    let names = point_names(sweep);
    let mut scenes = Scenes::default();
    let shard_of = shard::deal(&estimates(sweep, &mut scenes)?, shard.of);
    let mine: Vec<usize> = (0..sweep.points.len())
        .filter(|&i| shard_of[i] == shard.index)
        .collect();
    let mut ran = run_points(sweep, out, &names, &mine, options, &mut scenes)?;
    ran.failures.sort_by(|a, b| a.point.cmp(&b.point));
    Ok(ShardOutcome {
        shard,
        points: mine.len(),
        ran: ran.ran,
        failures: ran.failures,
        cost: clock.cost(0),
    })
}

/// Builds the table, plots and page of `sweep` from its points' files (summary.json, or
/// failure.json for a point whose run failed), as `run_sweep` would have written them. Fails
/// with the list of points that have neither.
pub fn collect(sweep: &Sweep, out: &Path) -> Result<SweepOutcome, SweepError> {
    let clock = Stopwatch::start();
    let names = point_names(sweep);
    let mut failures = Vec::new();
    let mut missing = Vec::new();
    for name in &names {
        if summary_path(out, name).exists() {
            continue;
        }
        match read_failure(out, name)? {
            Some(f) => failures.push(f),
            None => missing.push(name.clone()),
        }
    }
    if !missing.is_empty() {
        return Err(SweepError::Missing {
            dir: out.to_path_buf(),
            rerun: rerun_hint(sweep, out, &missing),
            foreign: foreign_points(out, &names),
            missing,
        });
    }
    let metrics = read_metrics(out, &names, &failures)?;
    let ran = Ran { ran: 0, failures };
    finish(sweep, out, &names, metrics, ran, clock, 1)
}

/// What running a selection of points did.
struct Ran {
    /// Points simulated now (the others of the selection were done already).
    ran: usize,
    failures: Vec<PointFailure>,
}

/// What a shard did.
#[derive(Debug)]
pub struct ShardOutcome {
    pub shard: Shard,
    /// The shard's points, and those of them simulated now.
    pub points: usize,
    pub ran: usize,
    pub failures: Vec<PointFailure>,
    pub cost: Cost,
}

fn point_names(sweep: &Sweep) -> Vec<String> {
    sweep.points.iter().map(|p| point_name(sweep, p)).collect()
}

/// Runs the points of `selection` that have no summary.json yet. Bad input (a point that
/// cannot be set up, a bad option) refuses the whole selection before anything is written.
fn run_points(
    sweep: &Sweep,
    out: &Path,
    names: &[String],
    selection: &[usize],
    options: SweepOptions,
    scenes: &mut Scenes,
) -> Result<Ran, SweepError> {
    let pending: Vec<usize> = selection
        .iter()
        .copied()
        .filter(|&i| !summary_path(out, &names[i]).exists())
        .collect();
    // Everything is resolved before anything runs: a bad point is bad input, and must not
    // leave half a sweep behind.
    let configs = resolve_pending(sweep, names, &pending, scenes)?;
    let results = run_pending(sweep, out, names, &pending, configs, options)?;
    let failures: Vec<PointFailure> = results.into_iter().filter_map(Result::err).collect();
    // Options are checked as a run starts; a bad one fails its points at once, before they
    // simulate anything, and refuses the sweep without a table.
    if let Some(f) = failures.iter().find(|f| f.kind == FailureKind::BadInput) {
        let message = format!("point {}: {}", f.point, f.message);
        return Err(SweepError::Spec(SpecError::invalid(
            &sweep.file,
            "",
            message,
        )));
    }
    Ok(Ran {
        ran: pending.len(),
        failures,
    })
}

/// The table, plots, page and cost.json over every point.
fn finish(
    sweep: &Sweep,
    out: &Path,
    names: &[String],
    metrics: Vec<Option<PointMetrics>>,
    ran: Ran,
    clock: Stopwatch,
    jobs: usize,
) -> Result<SweepOutcome, SweepError> {
    let Ran { ran, mut failures } = ran;
    let rows = table::rows(sweep, names, &metrics, &failures);
    write_reports(sweep, out, &rows)?;
    failures.sort_by(|a, b| a.point.cmp(&b.point));
    let outcome = SweepOutcome {
        rows,
        ran,
        skipped: sweep.points.len() - ran,
        failures,
        cost: clock.cost(0),
    };
    write(
        &out.join("cost.json"),
        to_json(&SweepCost::new(&outcome, jobs)).as_bytes(),
    )?;
    Ok(outcome)
}

/// Each point's estimated cost for dealing points to shards: processors x triangles x
/// frames, with each scene loaded once.
fn estimates(sweep: &Sweep, scenes: &mut Scenes) -> Result<Vec<u64>, SweepError> {
    sweep
        .points
        .iter()
        .map(|p| {
            let run = &p.run;
            let scene = scenes.get(sweep, &run.scene)?;
            let frames = parse_frames(run.frames.as_deref(), scene.frame_count())
                .map_err(|e| SpecError::invalid(&sweep.file, "frames", e))?;
            Ok(shard::estimate(
                run.procs,
                scene.triangle_count(),
                frames.len(),
            ))
        })
        .collect()
}

/// The shard of each point of `sweep` over `tasks` shards, as `run_shard` deals them.
pub fn deal(sweep: &Sweep, tasks: u32) -> Result<Vec<(String, u32)>, SweepError> {
    let shard_of = shard::deal(&estimates(sweep, &mut Scenes::default())?, tasks);
    Ok(point_names(sweep).into_iter().zip(shard_of).collect())
}

/// The command that runs just `missing`: the array tasks that hold them when the folder has a
/// shard plan (`--slurm` wrote one), else a local sweep into the same folder (which skips
/// every point already done).
fn rerun_hint(sweep: &Sweep, out: &Path, missing: &[String]) -> String {
    let local = format!(
        "sortsim sweep {} -o {}",
        sweep.file.display(),
        out.display()
    );
    let Some(plan) = shard::ShardPlan::read(out) else {
        return local;
    };
    let tasks: Vec<String> = plan
        .shards
        .iter()
        .enumerate()
        .filter(|(_, points)| points.iter().any(|p| missing.contains(p)))
        .map(|(i, _)| i.to_string())
        .collect();
    if tasks.is_empty() {
        return local;
    }
    format!(
        "sbatch --array={} {} (or locally: {local})",
        tasks.join(","),
        slurm::sweep_script(out).display()
    )
}

/// Folders under `out/points` that are not among `names`.
fn foreign_points(out: &Path, names: &[String]) -> usize {
    std::fs::read_dir(out.join("points")).map_or(0, |dir| {
        dir.filter_map(Result::ok)
            .filter(|e| !names.iter().any(|n| e.file_name() == n.as_str()))
            .count()
    })
}

/// The folder name of a point: its readable values and a hash of its whole run spec as
/// written and of the machine and scene files' text, so a point whose options or machine
/// change gets a new folder instead of a stale result. (A mesh a scene file refers to is not
/// hashed: after editing one, use a new report folder.)
pub fn point_name(sweep: &Sweep, point: &Point) -> String {
    let mut parts = Vec::new();
    for (d, v) in sweep.dims.iter().zip(&point.values) {
        let part = match d.key.as_str() {
            "machine" | "scene" => plots::stem(v),
            "algo" => v.clone(),
            "seed" => format!("s{v}"),
            "procs" => format!("p{:04}", v.parse::<u32>().unwrap_or(0)),
            key => format!("{}-{v}", key.trim_start_matches("vary.")),
        };
        parts.push(sanitize(&part));
    }
    let key = serde_json::json!({
        "dims": sweep.dims.iter().map(|d| &d.key).collect::<Vec<_>>(),
        "values": point.values,
        "frames": point.run.frames,
        "set": point.run.set,
        "machine_file": file_hash(&point.run.machine),
        "scene_file": file_hash(&point.run.scene),
    });
    let hash = fnv1a(key.to_string().as_bytes());
    format!("{}_{:08x}", parts.join("_"), hash >> 32)
}

/// Letters, digits, `.`, `-` and `=` stay; anything else (`/`, spaces) becomes `-`.
fn sanitize(s: &str) -> String {
    s.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '.' | '-' | '=') {
                c
            } else {
                '-'
            }
        })
        .collect()
}

/// The hash of a file's bytes; 0 for a file that cannot be read (resolving the point will
/// then report it).
fn file_hash(path: &Path) -> u64 {
    crate::spec::read_input_bytes(path).map_or(0, |b| fnv1a(&b))
}

fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

fn summary_path(out: &Path, name: &str) -> PathBuf {
    out.join("points").join(name).join("summary.json")
}

/// The scenes a sweep's points use, each loaded once (a stand-in's geometry can take a second
/// to build), shared by the shard deal and the points' resolution.
#[derive(Default)]
struct Scenes(BTreeMap<PathBuf, Arc<Scene>>);

impl Scenes {
    fn get(&mut self, sweep: &Sweep, path: &Path) -> Result<Arc<Scene>, SpecError> {
        if let Some(s) = self.0.get(path) {
            return Ok(s.clone());
        }
        let s = Arc::new(
            Scene::load(path)
                .map_err(|e| SpecError::invalid(&sweep.file, "scene", e.to_string()))?,
        );
        self.0.insert(path.to_path_buf(), s.clone());
        Ok(s)
    }
}

/// Resolves every pending point, loading each scene once.
fn resolve_pending(
    sweep: &Sweep,
    names: &[String],
    pending: &[usize],
    scenes: &mut Scenes,
) -> Result<Vec<RunConfig>, SpecError> {
    let mut configs = Vec::with_capacity(pending.len());
    for &i in pending {
        let run = &sweep.points[i].run;
        let scene = scenes.get(sweep, &run.scene)?;
        let cfg = run
            .resolve_sweep_point(Some(scene))
            .map_err(|e| SpecError::invalid(&sweep.file, "", format!("point {}: {e}", names[i])))?;
        configs.push(cfg);
    }
    Ok(configs)
}

/// Runs the pending points on a pool of `options.jobs` threads. Larger processor counts
/// start first, so the longest runs do not end up alone at the tail.
fn run_pending(
    sweep: &Sweep,
    out: &Path,
    names: &[String],
    pending: &[usize],
    configs: Vec<RunConfig>,
    options: SweepOptions,
) -> Result<Vec<Result<(), PointFailure>>, SweepError> {
    let jobs = options.jobs.max(1);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(jobs)
        .thread_name(|i| format!("sweep-{i}"))
        .build()
        .map_err(|e| SweepError::Pool {
            jobs,
            message: e.to_string(),
        })?;
    // A config holds per-run interior state (which options were read), so each one moves to
    // the thread that runs it rather than being shared.
    let mut work: Vec<(usize, RunConfig)> = configs.into_iter().enumerate().collect();
    work.sort_by_key(|(k, _)| std::cmp::Reverse(sweep.points[pending[*k]].run.procs));
    let bar = progress_bar(pending.len(), options.progress);
    type Outcome = Result<Result<(), PointFailure>, SweepError>;
    let results: Vec<(usize, Outcome)> = pool.install(|| {
        work.into_par_iter()
            .map(|(k, cfg)| {
                let name = &names[pending[k]];
                let r = run_point(&cfg, &out.join("points").join(name), name);
                bar.inc(1);
                bar.set_message(name.clone());
                (k, r)
            })
            .collect()
    });
    bar.finish_and_clear();
    let mut by_index: Vec<Option<Outcome>> = (0..pending.len()).map(|_| None).collect();
    for (k, r) in results {
        by_index[k] = Some(r);
    }
    by_index
        .into_iter()
        .map(|r| r.expect("every pending point ran"))
        .collect()
}

/// A progress bar on stderr, hidden when stderr is not a terminal (logs, CI, tests).
fn progress_bar(len: usize, wanted: bool) -> ProgressBar {
    if !wanted || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::with_draw_target(Some(len as u64), ProgressDrawTarget::stderr());
    let style = ProgressStyle::with_template(
        "{bar:30} {pos}/{len} points, {elapsed} elapsed, ~{eta} left  {wide_msg}",
    )
    .unwrap_or_else(|_| ProgressStyle::default_bar());
    bar.set_style(style);
    bar
}

/// One simulation: run, then write summary.json last (its presence marks the point done).
/// The outer error (a file that cannot be written) stops the sweep; the inner one (a run
/// that fails) is recorded in the point's row.
fn run_point(
    cfg: &RunConfig,
    dir: &Path,
    name: &str,
) -> Result<Result<(), PointFailure>, SweepError> {
    let clock = Stopwatch::start();
    let result = match crate::algo::run(cfg) {
        Ok(r) => r,
        Err(e) => {
            let kind = match &e {
                RunError::Sim(SimError::Memory { .. } | SimError::TimeOverflow { .. }) => {
                    FailureKind::Machine
                }
                RunError::Sim(_) => FailureKind::Internal,
                RunError::Option(_) | RunError::Scene(_) | RunError::Unsupported(_) => {
                    FailureKind::BadInput
                }
            };
            let failure = PointFailure {
                point: name.to_string(),
                message: e.to_string(),
                kind,
            };
            // Bad input refuses the sweep and leaves nothing; a machine too small or a bug
            // is this point's result, kept for `--collect`.
            if kind != FailureKind::BadInput {
                write(&dir.join(FAILURE), to_json(&failure).as_bytes())?;
            }
            return Ok(Err(failure));
        }
    };
    let cost = clock.cost(result.stats.events);
    let summary = RunSummary::new(cfg, &result);
    write(&dir.join("cost.json"), to_json(&cost).as_bytes())?;
    write(&dir.join("summary.json"), to_json(&summary).as_bytes())?;
    match std::fs::remove_file(dir.join(FAILURE)) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(SweepError::Write {
            path: dir.join(FAILURE),
            source: e,
        }),
        _ => Ok(Ok(())),
    }
}

/// A failed point's record, read by `--collect`.
const FAILURE: &str = "failure.json";

/// The failure recorded for point `name`, if its run failed.
fn read_failure(out: &Path, name: &str) -> Result<Option<PointFailure>, SweepError> {
    let path = out.join("points").join(name).join(FAILURE);
    let text = match std::fs::read_to_string(&path) {
        Ok(text) => text,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => {
            return Err(SweepError::BadSummary {
                path,
                message: format!("cannot read: {e}"),
            })
        }
    };
    serde_json::from_str(&text)
        .map(Some)
        .map_err(|e| SweepError::BadSummary {
            path,
            message: format!("not a point failure record: {e}"),
        })
}

/// Every point's metrics, read back from its summary.json (or None for a failed point).
fn read_metrics(
    out: &Path,
    names: &[String],
    failures: &[PointFailure],
) -> Result<Vec<Option<PointMetrics>>, SweepError> {
    names
        .iter()
        .map(|name| {
            if failures.iter().any(|f| &f.point == name) {
                return Ok(None);
            }
            let path = summary_path(out, name);
            let text = std::fs::read_to_string(&path).map_err(|e| SweepError::BadSummary {
                path: path.clone(),
                message: format!("cannot read: {e}"),
            })?;
            let metrics: PointMetrics =
                serde_json::from_str(&text).map_err(|e| SweepError::BadSummary {
                    path: path.clone(),
                    message: format!("not a run summary: {e}"),
                })?;
            Ok(Some(metrics))
        })
        .collect()
}

fn write_reports(sweep: &Sweep, out: &Path, rows: &[Row]) -> Result<(), SweepError> {
    write(&out.join("sweep.csv"), table::csv(sweep, rows).as_bytes())?;
    write(
        &out.join("sweep.json"),
        to_json(&table::SweepTable::new(sweep, rows)).as_bytes(),
    )?;
    plots::write_plots(sweep, rows, &out.join("plots"))?;
    page::write_page(out, sweep, rows)?;
    Ok(())
}

fn write(path: &Path, bytes: &[u8]) -> Result<(), SweepError> {
    write_atomic(path, bytes).map_err(|source| SweepError::Write {
        path: path.to_path_buf(),
        source,
    })
}

/// cost.json of the whole sweep: host-dependent, so kept out of sweep.json.
#[derive(Serialize)]
struct SweepCost<'a> {
    wall_s: f64,
    jobs: usize,
    points_run: usize,
    points_skipped: usize,
    peak_host_memory_bytes: Option<u64>,
    failures: &'a [PointFailure],
}

impl<'a> SweepCost<'a> {
    fn new(o: &'a SweepOutcome, jobs: usize) -> SweepCost<'a> {
        SweepCost {
            wall_s: o.cost.wall_s,
            jobs: jobs.max(1),
            points_run: o.ran,
            points_skipped: o.skipped,
            peak_host_memory_bytes: o.cost.peak_host_memory_bytes,
            failures: &o.failures,
        }
    }
}
