//! The report of one run: summary.json (every metric with its unit, deterministic),
//! summary.md (the tables a person reads), cost.json (what it cost the host), timeline.json
//! (Chrome trace events, one track per node cpu; opens in Perfetto or chrome://tracing), the
//! last frame's image and index.html (all of it on one page).
//!
//! Must never run a simulation; it only formats what a run measured.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use serde::Serialize;

use super::cost::Cost;
use super::page::{phase_bars, timeline_note, Page};
use super::plot::PlotError;
use super::summary::Summary;
use super::{to_json, write_atomic, write_text};
use crate::algo::{FrameRecord, RunConfig, RunResult};
use crate::raster::encode_png;

/// The line `sortsim run` prints after the summary: where the report went and what the
/// simulation cost.
pub fn closing_line(dir: &Path, cost: &Cost) -> String {
    super::closing_line(
        dir,
        &format!(
            " (simulated in {:.2} s wall, {} events)",
            cost.wall_s, cost.events
        ),
    )
}

/// Writes a run's report folder; returns its summary (for printing).
pub fn write_report(
    dir: &Path,
    cfg: &RunConfig,
    result: &RunResult,
    cost: &Cost,
) -> Result<RunSummary, PlotError> {
    let summary = RunSummary::new(cfg, result);
    let last = result.frames.last().map_or(0, |f| f.frame);
    let mut png = Vec::new();
    encode_png(&result.image, &mut png).map_err(|e| PlotError::Draw(e.to_string()))?;
    write_text(dir, "summary.json", &to_json(&summary))?;
    write_text(dir, "summary.md", &summary.markdown())?;
    write_text(dir, "cost.json", &to_json(cost))?;
    let timeline = timeline_json(result);
    if let Some(timeline) = &timeline {
        write_text(dir, "timeline.json", timeline)?;
    }
    let image = dir.join(format!("frame-{last:04}.png"));
    write_atomic(&image, &png).map_err(|source| PlotError::Io {
        path: image.clone(),
        source,
    })?;
    let title = format!(
        "{} on {} ({} processors)",
        summary.run.algo, summary.run.machine, summary.run.procs
    );
    let mut page = Page::new(title)
        .markdown(&summary.markdown())
        .section(phase_bars(
            &summary.machine_metrics.nodes,
            summary.machine_metrics.end_s,
        ));
    if timeline.is_some() {
        page = page.section(timeline_note());
    }
    let mut files = vec!["summary.json", "summary.md", "cost.json"];
    if timeline.is_some() {
        files.push("timeline.json");
    }
    page.images_of(dir).files(&files).write(dir)?;
    Ok(summary)
}

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

    /// summary.md: per-frame table, then per-node time by phase and traffic.
    pub fn markdown(&self) -> String {
        self.markdown_with(true)
    }

    /// What `sortsim run` prints: summary.md with its per-node table folded into one line per
    /// quantity (min, mean, max and the node that has the max) unless `verbose`.
    pub fn terminal(&self, verbose: bool) -> String {
        self.markdown_with(verbose)
    }

    fn markdown_with(&self, nodes_in_full: bool) -> String {
        let mut s = String::new();
        let run = &self.run;
        let _ = writeln!(
            s,
            "# {} on {} ({} processors)\n",
            run.algo, run.machine, run.procs
        );
        let _ = writeln!(s, "{}", run.context());
        if !run.options.is_empty() {
            let opts: Vec<String> = run
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
        if !self.unpriced_ops.is_empty() {
            let _ = writeln!(
                s,
                "**Charged at zero:** the run used {}, which {} does not price (give each a cost in \
                 its `cpu.costs`).\n",
                self.unpriced_ops.join(", "),
                run.machine
            );
        }
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
        self.aa_markdown(&mut s);
        if nodes_in_full {
            self.node_table(&mut s);
        } else {
            self.node_digest(&mut s);
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

impl RunSummary {
    /// The per-node table of summary.md: time per phase, busy, comm, idle, traffic, memory.
    fn node_table(&self, s: &mut String) {
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
    }

    /// The per-node table in a few lines: each column's min, mean and max over the nodes.
    fn node_digest(&self, s: &mut String) {
        let nodes = &self.machine_metrics.nodes;
        if nodes.is_empty() {
            return;
        }
        let _ = writeln!(
            s,
            "\n## Per node ({} nodes; min / mean / max, busiest node)\n",
            nodes.len()
        );
        let _ = writeln!(s, "| quantity | min | mean | max | at node |");
        let _ = writeln!(s, "|---|---:|---:|---:|---:|");
        type Column = (&'static str, fn(&super::summary::NodeSummary) -> f64, usize);
        let columns: [Column; 6] = [
            ("busy (s)", |n| n.busy_s, 6),
            ("comm (s)", |n| n.comm_s, 6),
            ("idle (s)", |n| n.idle_s, 6),
            ("sent bytes", |n| n.sent_bytes as f64, 0),
            ("sent messages", |n| n.sent_messages as f64, 0),
            (
                "memory high-water (bytes)",
                |n| n.memory_high_water_bytes as f64,
                0,
            ),
        ];
        for (name, value, digits) in columns {
            let values: Vec<f64> = nodes.iter().map(value).collect();
            let (mut at, mut max, mut min) = (0, f64::MIN, f64::MAX);
            for (i, &v) in values.iter().enumerate() {
                if v > max {
                    (at, max) = (i, v);
                }
                min = min.min(v);
            }
            let mean = values.iter().sum::<f64>() / values.len() as f64;
            let _ = writeln!(
                s,
                "| {name} | {min:.digits$} | {mean:.digits$} | {max:.digits$} | {} |",
                nodes[at].node
            );
        }
        let _ = writeln!(
            s,
            "\nEvery node's row: summary.md in the report folder, or --verbose."
        );
    }

    /// The anti-aliasing table of summary.md, when the run anti-aliased.
    fn aa_markdown(&self, s: &mut String) {
        if self.per_frame.iter().all(|f| f.aa.is_none()) {
            return;
        }
        let _ = writeln!(s, "\n## Anti-aliasing\n\n| frame | grid per node | supersampled (%) | reclaimed | overflowed | after reclaiming (%) | memory per node min / mean / max (bytes) |");
        let _ = writeln!(s, "|---:|---|---:|---:|---:|---:|---|");
        for f in &self.per_frame {
            let Some(a) = &f.aa else { continue };
            let pct = |n: u64| 100.0 * n as f64 / a.pixels.max(1) as f64;
            let grids: Vec<String> = a
                .grid_side_per_node
                .iter()
                .map(|g| format!("{g}x{g}"))
                .collect();
            let _ = writeln!(
                s,
                "| {} | {} | {:.2} | {} | {} | {:.2} | {} / {:.0} / {} |",
                f.frame,
                grids.join(" "),
                pct(a.supersampled_pixels),
                a.reclaimed_pixels,
                a.overflowed_pixels,
                pct(a.live_super_pixels),
                a.memory_min_bytes,
                a.memory_mean_bytes,
                a.memory_max_bytes
            );
        }
    }
}

/// timeline.json in Chrome trace-event format: a process of node cpus (one track per node, a
/// complete event per stretch of cpu work, named after its phase) and a process of links (one
/// track per link that carried traffic, a span while at least one message was in flight over
/// it). Times in microseconds.
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
    let links = result.stats.link_timeline.as_deref().unwrap_or_default();
    let link_name = |l: u32| {
        result
            .stats
            .links
            .get(l as usize)
            .map_or(format!("link {l}"), |s| format!("link {}", s.name))
    };
    let mut named: Vec<u32> = links.iter().map(|s| s.link).collect();
    named.dedup();
    let link_names = named.into_iter().map(|l| {
        format!("{{\"name\":\"thread_name\",\"ph\":\"M\",\"pid\":1,\"tid\":{l},\"args\":{{\"name\":\"{}\"}}}}", link_name(l))
    });
    let link_work = links.iter().map(|sp| {
        format!(
            "{{\"name\":\"in flight\",\"ph\":\"X\",\"pid\":1,\"tid\":{},\"ts\":{:.6},\"dur\":{:.6}}}",
            sp.link,
            sp.start.as_us_f64(),
            (sp.end - sp.start).as_us_f64()
        )
    });
    let processes = [
        "{\"name\":\"process_name\",\"ph\":\"M\",\"pid\":0,\"args\":{\"name\":\"node cpus\"}}".to_string(),
        "{\"name\":\"process_name\",\"ph\":\"M\",\"pid\":1,\"args\":{\"name\":\"busy links (messages in flight)\"}}".to_string(),
    ];
    let events: Vec<String> = processes
        .into_iter()
        .chain(names)
        .chain(work)
        .chain(link_names)
        .chain(link_work)
        .collect();
    let out = format!(
        "{{\"displayTimeUnit\":\"ns\",\"traceEvents\":[\n{}\n]}}\n",
        events.join(",\n")
    );
    Some(out)
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
