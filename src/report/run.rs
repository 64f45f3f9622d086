//! The report of one run: summary.json (every metric with its unit, deterministic),
//! summary.md (the tables a person reads), cost.json (what it cost the host), timeline.json
//! (Chrome trace events, one track per node cpu; opens in Perfetto or chrome://tracing), the
//! last frame's image and index.html (all of it on one page).
//!
//! Must never run a simulation; it only formats what a run measured.

use std::fmt::Write as _;
use std::io::{self, Write};
use std::path::Path;

use crate::algo::{RunConfig, RunResult};
use crate::engine::CpuSpan;
use crate::metrics::machine::NodeSummary;
use crate::metrics::run::RunSummary;
use crate::output::cost::Cost;
use crate::output::page::{Page, PALETTE};
use crate::output::plot::PlotError;
use crate::output::{to_json, write_atomic, write_atomic_with, write_text};
use crate::raster::encode_png;
use maud::{html, Markup};

/// The line `sortsim run` prints after the summary: where the report went and what the
/// simulation cost.
pub fn closing_line(dir: &Path, cost: &Cost) -> String {
    crate::output::closing_line(
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
    let timeline = result.stats.timeline.as_deref();
    if let Some(spans) = timeline {
        let path = dir.join("timeline.json");
        write_atomic_with(&path, |out| write_timeline(out, result, spans))
            .map_err(|source| PlotError::Io { path, source })?;
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
    // The bars first: where each node's time went is what a run page is opened for; then the
    // frames and the per-node digest; every node's row last.
    let mut page = Page::new(title)
        .markdown(&summary.headline())
        .section(phase_bars(
            &summary.machine_metrics.nodes,
            summary.machine_metrics.end_s,
        ))
        .markdown(&summary.tables_with(false, "Every node's row is in the table below."));
    let mut every_node = String::new();
    summary.node_table(&mut every_node);
    page = page.markdown(&every_node);
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

impl RunSummary {
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
        self.headline() + &self.tables(nodes_in_full)
    }

    /// The title, what ran and the means over frames.
    fn headline(&self) -> String {
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
        s
    }

    /// The frames table, anti-aliasing, the nodes (every row, or the digest and where to find
    /// every row) and the links.
    fn tables(&self, nodes_in_full: bool) -> String {
        self.tables_with(
            nodes_in_full,
            "Every node's row: summary.md in the report folder, or --verbose.",
        )
    }

    fn tables_with(&self, nodes_in_full: bool, rows_are: &str) -> String {
        let mut s = String::new();
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
            self.node_digest(&mut s, rows_are);
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
    fn node_digest(&self, s: &mut String, rows_are: &str) {
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
        type Column = (&'static str, fn(&NodeSummary) -> f64, usize);
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
        let _ = writeln!(s, "\n{rows_are}");
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
/// it). Times in microseconds. Written event by event: a large run's timeline is gigabytes of
/// text, which must not be built in memory first.
fn write_timeline(out: &mut dyn Write, result: &RunResult, spans: &[CpuSpan]) -> io::Result<()> {
    out.write_all(b"{\"displayTimeUnit\":\"ns\",\"traceEvents\":[\n")?;
    let mut first = true;
    let mut event = |out: &mut dyn Write, event: std::fmt::Arguments| {
        if !std::mem::take(&mut first) {
            out.write_all(b",\n")?;
        }
        out.write_fmt(event)
    };
    event(out, format_args!("{{\"name\":\"process_name\",\"ph\":\"M\",\"pid\":0,\"args\":{{\"name\":\"node cpus\"}}}}"))?;
    event(out, format_args!("{{\"name\":\"process_name\",\"ph\":\"M\",\"pid\":1,\"args\":{{\"name\":\"busy links (messages in flight)\"}}}}"))?;
    for n in 0..result.stats.nodes.len() {
        event(out, format_args!("{{\"name\":\"thread_name\",\"ph\":\"M\",\"pid\":0,\"tid\":{n},\"args\":{{\"name\":\"node {n} cpu\"}}}}"))?;
    }
    for sp in spans {
        event(
            out,
            format_args!(
                "{{\"name\":\"{}\",\"ph\":\"X\",\"pid\":0,\"tid\":{},\"ts\":{:.6},\"dur\":{:.6}}}",
                sp.phase,
                sp.node,
                sp.start.as_us_f64(),
                (sp.end - sp.start).as_us_f64()
            ),
        )?;
    }
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
    for l in named {
        event(out, format_args!("{{\"name\":\"thread_name\",\"ph\":\"M\",\"pid\":1,\"tid\":{l},\"args\":{{\"name\":\"{}\"}}}}", link_name(l)))?;
    }
    for sp in links {
        event(
            out,
            format_args!(
                "{{\"name\":\"in flight\",\"ph\":\"X\",\"pid\":1,\"tid\":{},\"ts\":{:.6},\"dur\":{:.6}}}",
                sp.link,
                sp.start.as_us_f64(),
                (sp.end - sp.start).as_us_f64()
            ),
        )?;
    }
    out.write_all(b"\n]}\n")
}

/// One horizontal bar per node: its busy time split by phase, then idle, to the run's end.
pub fn phase_bars(nodes: &[NodeSummary], end_s: f64) -> Markup {
    let mut phases: Vec<&str> = nodes
        .iter()
        .flat_map(|n| n.busy_by_phase_s.keys().map(String::as_str))
        .collect();
    phases.sort_unstable();
    phases.dedup();
    let colour =
        |p: &str| PALETTE[phases.iter().position(|q| *q == p).unwrap_or(0) % PALETTE.len()];
    let width = |s: f64| {
        if end_s > 0.0 {
            100.0 * s / end_s
        } else {
            0.0
        }
    };
    // Up to 64 bars get a label each; more are drawn thin, with every k-th node labelled.
    let dense = nodes.len() > 64;
    let every = nodes.len().div_ceil(32).max(1);
    let ticks: Vec<(f64, String)> = (0..=4)
        .map(|i| {
            let t = end_s * i as f64 / 4.0;
            (25.0 * i as f64, seconds_label(t, end_s))
        })
        .collect();
    html! {
        h2 { "Time by phase, per node" }
        p { "Each bar is one node from the start of the run to its end, on the time axis below; grey is idle." }
        div.legend {
            @for p in &phases {
                span { i style={ "background:" (colour(p)) } {} (p) }
            }
            span { i style="background:#e6e6e6" {} "idle" }
        }
        div class=(if dense { "bars dense" } else { "bars" }) {
            @for (k, n) in nodes.iter().enumerate() {
                div.bar title={ "node " (n.node) } {
                    span.label { @if !dense || k % every == 0 { "node " (n.node) } }
                    div.track {
                        @for (p, s) in &n.busy_by_phase_s {
                            div.seg style={ "width:" (format!("{:.3}", width(*s))) "%;background:" (colour(p)) }
                                title={ (p) ": " (format!("{s:.6}")) " s" } {}
                        }
                    }
                }
            }
        }
        div.axis {
            @for (i, (at, label)) in ticks.iter().enumerate() {
                span class=(match i { 0 => "first", 4 => "last", _ => "" }) style={ "left:" (format!("{at:.0}")) "%" } { (label) }
            }
        }
    }
}

/// A time on the bars' axis, in the unit that suits the run's length.
fn seconds_label(t: f64, end_s: f64) -> String {
    if end_s >= 1.0 {
        format!("{t:.2} s")
    } else if end_s >= 1e-3 {
        format!("{:.1} ms", t * 1e3)
    } else {
        format!("{:.1} us", t * 1e6)
    }
}

/// How to look at a run's timeline.json.
pub fn timeline_note() -> Markup {
    html! {
        h2 { "Timeline" }
        p {
            a href="timeline.json" { "timeline.json" }
            ": open ui.perfetto.dev in a browser, choose \"Open trace file\" and pick this file \
             (or chrome://tracing, Load): one track per node's cpu, one slice per stretch of work, \
             named after its phase."
        }
    }
}
