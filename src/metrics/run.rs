//! summary.json of a run, as data: what the run was (`RunHeader`), per-frame figures, means
//! over frames, and the machine's per-node and per-link metrics. Built from a run's result;
//! must never format for a person (that is `report::run`) nor depend on the host.

use std::collections::BTreeMap;

use serde::Serialize;

use super::machine::Summary;
use crate::algo::{FrameRecord, RunConfig, RunResult};

/// What a run was: the fields every report of one run spec opens with (summary.json,
/// accuracy.json).
#[derive(Serialize, Debug, Clone, PartialEq)]
pub struct RunHeader {
    pub machine: String,
    pub scene: String,
    pub algo: &'static str,
    pub procs: u32,
    pub frames: Vec<u32>,
    pub seed: u64,
    /// The machine's network fidelity.
    pub fidelity: &'static str,
    pub options: BTreeMap<String, String>,
}

impl RunHeader {
    /// The header of `cfg`, reporting `options` as its options.
    pub fn new(cfg: &RunConfig, options: BTreeMap<String, String>) -> RunHeader {
        RunHeader {
            machine: cfg.machine.name.clone(),
            scene: cfg.scene.file().display().to_string(),
            algo: cfg.algo.id(),
            procs: cfg.machine.nodes,
            frames: cfg.frames.clone().collect(),
            seed: cfg.seed,
            fidelity: cfg.machine.network.fidelity.name(),
            options,
        }
    }

    /// The run's context for a markdown report: scene, frames, seed, fidelity.
    pub fn context(&self) -> String {
        format!(
            "scene `{}`, frames {}, seed {}, network fidelity `{}`",
            self.scene,
            frame_list(&self.frames),
            self.seed,
            self.fidelity
        )
    }
}

/// summary.json of a run.
#[derive(Serialize, Debug, Clone, PartialEq)]
pub struct RunSummary {
    #[serde(flatten)]
    pub run: RunHeader,
    pub mean_frame_s: f64,
    pub mean_triangles_per_s: f64,
    pub mean_load_imbalance_pct: f64,
    pub mean_bytes_per_frame: f64,
    pub mean_messages_per_frame: f64,
    pub per_frame: Vec<FrameSummary>,
    pub machine_metrics: Summary,
    /// Operations the run charged that the machine file does not price (each cost nothing).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub unpriced_ops: Vec<&'static str>,
}

#[derive(Serialize, Debug, Clone, PartialEq)]
pub struct FrameSummary {
    pub frame: u32,
    pub time_s: f64,
    pub triangles_in_view: u64,
    pub triangles_per_s: f64,
    pub load_imbalance_pct: f64,
    pub bytes: u64,
    pub messages: u64,
    /// Sort-first: primitives' database records sent to processors that did not hold them.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub records_moved: Option<u64>,
    /// Anti-aliasing this frame, when the run used it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub aa: Option<AaFrameSummary>,
}

/// One frame's anti-aliasing over all nodes (paper 000's memory figures).
#[derive(Serialize, Debug, Clone, PartialEq)]
pub struct AaFrameSummary {
    /// Samples per side each node used (4 = 4x4).
    pub grid_side_per_node: Vec<u32>,
    pub supersampled_pixels: u64,
    pub reclaimed_pixels: u64,
    pub overflowed_pixels: u64,
    /// Super pixels left after reclaiming.
    pub live_super_pixels: u64,
    /// Pixels of the screen the nodes held.
    pub pixels: u64,
    /// Per node: Pixel array plus Subpixel cells in use at the end of the frame.
    pub memory_min_bytes: u64,
    pub memory_mean_bytes: f64,
    pub memory_max_bytes: u64,
}

fn aa_summary(r: &FrameRecord) -> Option<AaFrameSummary> {
    if r.aa.is_empty() {
        return None;
    }
    let sum = |f: fn(&crate::raster::aa::AaStats) -> u64| r.aa.iter().map(f).sum::<u64>();
    let memory: Vec<u64> = r.aa.iter().map(|a| a.memory_used().get()).collect();
    Some(AaFrameSummary {
        grid_side_per_node: r.aa.iter().map(|a| a.grid_side).collect(),
        supersampled_pixels: sum(|a| a.supersampled_pixels),
        reclaimed_pixels: sum(|a| a.reclaimed_pixels),
        overflowed_pixels: sum(|a| a.overflowed_pixels),
        live_super_pixels: sum(|a| a.live_super_pixels),
        pixels: sum(|a| a.pixels),
        memory_min_bytes: memory.iter().copied().min().unwrap_or(0),
        memory_mean_bytes: mean(memory.iter().map(|&m| m as f64)),
        memory_max_bytes: memory.iter().copied().max().unwrap_or(0),
    })
}

fn frame_summary(r: &FrameRecord) -> FrameSummary {
    let t = r.time().as_secs_f64();
    FrameSummary {
        frame: r.frame,
        time_s: t,
        triangles_in_view: r.triangles_in_view,
        triangles_per_s: if t > 0.0 {
            r.triangles_in_view as f64 / t
        } else {
            0.0
        },
        load_imbalance_pct: r.load_imbalance_pct(),
        bytes: r.bytes.get(),
        messages: r.messages,
        records_moved: r.records_moved,
        aa: aa_summary(r),
    }
}

fn mean(values: impl Iterator<Item = f64>) -> f64 {
    let (sum, n) = values.fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    if n == 0 {
        0.0
    } else {
        sum / n as f64
    }
}

impl RunSummary {
    pub fn new(cfg: &RunConfig, result: &RunResult) -> RunSummary {
        let per_frame: Vec<FrameSummary> = result.frames.iter().map(frame_summary).collect();
        let options = cfg.options.pairs().map(|(k, v)| (k.clone(), v.clone()));
        RunSummary {
            run: RunHeader::new(cfg, options.collect()),
            mean_frame_s: mean(per_frame.iter().map(|f| f.time_s)),
            // The papers average triangles/s over the frames (paper 002, Performance).
            mean_triangles_per_s: mean(per_frame.iter().map(|f| f.triangles_per_s)),
            mean_load_imbalance_pct: mean(per_frame.iter().map(|f| f.load_imbalance_pct)),
            mean_bytes_per_frame: mean(per_frame.iter().map(|f| f.bytes as f64)),
            mean_messages_per_frame: mean(per_frame.iter().map(|f| f.messages as f64)),
            per_frame,
            machine_metrics: Summary::from_stats(&result.stats),
            unpriced_ops: result
                .stats
                .unpriced_ops
                .iter()
                .map(|op| op.name())
                .collect(),
        }
    }
}

/// Frames as a person writes them: `0..20` (20 excluded, as `--frames` reads it) when they
/// run on without a gap, else listed.
fn frame_list(frames: &[u32]) -> String {
    match (frames.first(), frames.last()) {
        (Some(&a), Some(&b)) if b.checked_sub(a).map(|d| d as usize + 1) == Some(frames.len()) => {
            format!("{a}..{}", u64::from(b) + 1)
        }
        _ => frames
            .iter()
            .map(u32::to_string)
            .collect::<Vec<_>>()
            .join(", "),
    }
}
