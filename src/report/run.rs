//! The report of one run: summary.json (every metric with its unit, deterministic),
//! summary.md (the tables a person reads), timeline.json (Chrome trace events, one track per
//! node cpu; opens in Perfetto or chrome://tracing) and the last frame's image.
//!
//! Must never run a simulation; it only formats what a run measured.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use serde::Serialize;

use super::summary::Summary;
use crate::algo::{FrameRecord, RunConfig, RunResult};

/// summary.json of a run.
#[derive(Serialize, Debug, Clone, PartialEq)]
pub struct RunSummary {
    pub machine: String,
    pub scene: String,
    pub algo: &'static str,
    pub procs: u32,
    pub frames: Vec<u32>,
    pub seed: u64,
    pub fidelity: &'static str,
    pub options: BTreeMap<String, String>,
    pub mean_frame_s: f64,
    pub mean_triangles_per_s: f64,
    pub mean_load_imbalance_pct: f64,
    pub mean_bytes_per_frame: f64,
    pub mean_messages_per_frame: f64,
    pub per_frame: Vec<FrameSummary>,
    pub machine_metrics: Summary,
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
        RunSummary {
            machine: cfg.machine.name.clone(),
            scene: cfg.scene.file().display().to_string(),
            algo: cfg.algo.id(),
            procs: cfg.machine.nodes,
            frames: per_frame.iter().map(|f| f.frame).collect(),
            seed: cfg.seed,
            fidelity: cfg.machine.network.fidelity.name(),
            options: cfg
                .options
                .pairs()
                .map(|(k, v)| (k.clone(), v.clone()))
                .collect(),
            mean_frame_s: mean(per_frame.iter().map(|f| f.time_s)),
            // The papers average triangles/s over the frames (paper 002, Performance).
            mean_triangles_per_s: mean(per_frame.iter().map(|f| f.triangles_per_s)),
            mean_load_imbalance_pct: mean(per_frame.iter().map(|f| f.load_imbalance_pct)),
            mean_bytes_per_frame: mean(per_frame.iter().map(|f| f.bytes as f64)),
            mean_messages_per_frame: mean(per_frame.iter().map(|f| f.messages as f64)),
            per_frame,
            machine_metrics: Summary::from_stats(&result.stats),
        }
    }

    /// summary.md: per-frame table, then per-node time by phase and traffic.
    pub fn markdown(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "# {} on {} ({} processors)\n",
            self.algo, self.machine, self.procs
        );
        let _ = writeln!(
            s,
            "scene `{}`, frames {:?}, seed {}, network fidelity `{}`",
            self.scene, self.frames, self.seed, self.fidelity
        );
        if !self.options.is_empty() {
            let opts: Vec<String> = self
                .options
                .iter()
                .map(|(k, v)| format!("{k}={v}"))
                .collect();
            let _ = writeln!(s, "options: {}", opts.join(", "));
        }
        let _ = writeln!(
            s,
            "\nmean frame time {:.6} s, {:.0} triangles/s, load imbalance {:.1} %, {:.0} bytes and {:.0} messages per frame\n",
            self.mean_frame_s, self.mean_triangles_per_s, self.mean_load_imbalance_pct, self.mean_bytes_per_frame, self.mean_messages_per_frame
        );
        let _ = writeln!(s, "## Frames\n\n| frame | time (s) | triangles in view | triangles/s | load imbalance (%) | bytes | messages |");
        let _ = writeln!(s, "|---:|---:|---:|---:|---:|---:|---:|");
        for f in &self.per_frame {
            let _ = writeln!(
                s,
                "| {} | {:.6} | {} | {:.0} | {:.1} | {} | {} |",
                f.frame,
                f.time_s,
                f.triangles_in_view,
                f.triangles_per_s,
                f.load_imbalance_pct,
                f.bytes,
                f.messages
            );
        }
        let phases: Vec<&String> = {
            let mut all: Vec<&String> = self
                .machine_metrics
                .nodes
                .iter()
                .flat_map(|n| n.busy_by_phase_s.keys())
                .collect();
            all.sort();
            all.dedup();
            all
        };
        let _ = write!(s, "\n## Time per node (s)\n\n| node |");
        for p in &phases {
            let _ = write!(s, " {p} |");
        }
        let _ = writeln!(
            s,
            " busy | comm | idle | sent bytes | sent messages | memory high-water (bytes) |"
        );
        let _ = writeln!(
            s,
            "|---:|{}---:|---:|---:|---:|---:|---:|",
            "---:|".repeat(phases.len())
        );
        for n in &self.machine_metrics.nodes {
            let _ = write!(s, "| {} |", n.node);
            for p in &phases {
                let _ = write!(
                    s,
                    " {:.6} |",
                    n.busy_by_phase_s.get(*p).copied().unwrap_or(0.0)
                );
            }
            let _ = writeln!(
                s,
                " {:.6} | {:.6} | {:.6} | {} | {} | {} |",
                n.busy_s,
                n.comm_s,
                n.idle_s,
                n.sent_bytes,
                n.sent_messages,
                n.memory_high_water_bytes
            );
        }
        let busiest = self
            .machine_metrics
            .links
            .iter()
            .filter(|l| l.bytes > 0)
            .count();
        let _ = writeln!(
            s,
            "\n{} of {} links carried traffic.",
            busiest,
            self.machine_metrics.links.len()
        );
        s
    }
}

/// timeline.json in Chrome trace-event format: one process, one thread (track) per node,
/// a complete event per stretch of cpu work, named after its phase. Times in microseconds.
pub fn timeline_json(result: &RunResult) -> Option<String> {
    let spans = result.stats.timeline.as_ref()?;
    let nodes = result.stats.nodes.len();
    let names = (0..nodes).map(|n| format!("{{\"name\":\"thread_name\",\"ph\":\"M\",\"pid\":0,\"tid\":{n},\"args\":{{\"name\":\"node {n} cpu\"}}}}"));
    let work = spans.iter().map(|sp| {
        format!(
            "{{\"name\":\"{}\",\"ph\":\"X\",\"pid\":0,\"tid\":{},\"ts\":{:.6},\"dur\":{:.6}}}",
            sp.phase,
            sp.node,
            sp.start.as_us_f64(),
            (sp.end - sp.start).as_us_f64()
        )
    });
    let events: Vec<String> = names.chain(work).collect();
    let out = format!(
        "{{\"displayTimeUnit\":\"ns\",\"traceEvents\":[\n{}\n]}}\n",
        events.join(",\n")
    );
    Some(out)
}
