//! The simulations a paper's experiments need, run side by side on a thread pool of
//! `--jobs` threads; each scene is loaded once and shared.
//!
//! Owns only scheduling. Must never change a run: each is `algo::run` on its own spec, so
//! results do not depend on the thread count, and they come back in the order asked.

use std::collections::BTreeMap;
use std::sync::Arc;

use rayon::prelude::*;

use crate::algo::{run, FrameRecord, RunResult};
use crate::scene::Scene;
use crate::spec::run::RunSpec;

use super::PaperOptions;

/// One simulation: files named relative to machines/ and scenes/.
#[derive(Clone, Debug, PartialEq)]
pub struct Job {
    pub machine: String,
    pub scene: String,
    pub algo: String,
    pub procs: u32,
    pub frames: Option<String>,
    pub set: Vec<(String, String)>,
}

impl Job {
    pub fn new(machine: &str, scene: &str, algo: &str, procs: u32) -> Job {
        Job {
            machine: machine.into(),
            scene: scene.into(),
            algo: algo.into(),
            procs,
            frames: None,
            set: Vec::new(),
        }
    }

    pub fn frames(mut self, frames: &str) -> Job {
        self.frames = Some(frames.into());
        self
    }

    pub fn set(mut self, key: &str, value: &str) -> Job {
        self.set.push((key.into(), value.into()));
        self
    }
}

/// Runs `jobs` on a pool of `options.jobs` threads; results in the order of `jobs`.
pub fn run_jobs(options: &PaperOptions, jobs: &[Job]) -> Result<Vec<RunResult>, String> {
    run_jobs_keeping(options, jobs, |r| r)
}

/// As [`run_jobs`], keeping only `keep` of each result as soon as its run ends (a run's image
/// and per-node statistics can be larger than the figure wanted from it).
pub fn run_jobs_keeping<T: Send>(
    options: &PaperOptions,
    jobs: &[Job],
    keep: impl Fn(RunResult) -> T + Sync,
) -> Result<Vec<T>, String> {
    let threads = options.jobs;
    let mut scenes: BTreeMap<&str, Arc<Scene>> = BTreeMap::new();
    for job in jobs {
        if !scenes.contains_key(job.scene.as_str()) {
            let scene = Scene::load(&options.scene(&job.scene)).map_err(|e| e.to_string())?;
            scenes.insert(&job.scene, Arc::new(scene));
        }
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.max(1))
        .build()
        .map_err(|e| format!("cannot start {threads} threads: {e}"))?;
    pool.install(|| {
        jobs.par_iter()
            .map(|job| {
                let spec = RunSpec {
                    schema: None,
                    machine: options.machine(&job.machine),
                    scene: options.scene(&job.scene),
                    algo: job.algo.clone(),
                    procs: job.procs,
                    frames: job.frames.clone(),
                    seed: 1,
                    set: job.set.iter().cloned().collect(),
                };
                let config = spec
                    .resolve(Some(scenes[job.scene.as_str()].clone()))
                    .map_err(|e| format!("{job:?}: {e}"))?;
                run(&config).map(&keep).map_err(|e| format!("{job:?}: {e}"))
            })
            .collect()
    })
}

/// Frame 0's merge or composite: its end minus the last node's rasterization finish.
pub fn after_raster_s(r: &RunResult) -> f64 {
    let f = &r.frames[0];
    let last = f.raster_finish.iter().max().copied().unwrap_or(f.start);
    (f.end - last).as_secs_f64()
}

/// Mean over frames of triangles in view per simulated second.
pub fn triangles_per_s(r: &RunResult) -> f64 {
    triangles_per_s_over(&r.frames)
}

/// Mean over `frames` of triangles in view per simulated second.
pub fn triangles_per_s_over(frames: &[FrameRecord]) -> f64 {
    mean(
        frames
            .iter()
            .map(|f| f.triangles_in_view as f64 / f.time().as_secs_f64()),
    )
}

pub fn mean(v: impl Iterator<Item = f64>) -> f64 {
    let (sum, n) = v.fold((0.0, 0usize), |(s, n), x| (s + x, n + 1));
    if n == 0 {
        f64::NAN
    } else {
        sum / n as f64
    }
}
