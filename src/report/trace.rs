//! The trace replay report (`sortsim trace replay -o DIR`, paper 003): replay.csv and
//! replay.json (every algorithm and n), and the Figures 5 and 6 style charts, traffic over
//! d*A and over the minimum against n, as SVG and PNG; and the line `trace record` prints.
//!
//! Owns the files of this report kind. Must never replay (it is handed the report) and never
//! write except through `write_atomic`.

use std::path::Path;

use crate::output::plot::{line_chart, ChartOptions, PlotError};
use crate::output::{to_json, write_text};
use crate::trace::replay::{Baseline, Report};
use crate::trace::Trace;

/// The line `sortsim trace record` prints: what was recorded from which scene frame, and the
/// file's size per fragment.
pub fn recorded_line(trace: &Trace, scene: &Path, out: &Path, bytes: u64) -> String {
    let m = trace.meta();
    format!(
        "{}: frame {}, {}x{}, {} primitives, {} fragments -> {} ({bytes} bytes, {:.2} bytes per fragment)\n",
        scene.display(),
        m.frame,
        m.width,
        m.height,
        m.primitives,
        trace.len(),
        out.display(),
        bytes as f64 / trace.len().max(1) as f64
    )
}

/// Writes the report of `report` under `dir`; `trace` names the trace file in replay.json.
pub fn write(dir: &Path, report: &Report, trace: &str) -> Result<(), PlotError> {
    write_text(dir, "replay.csv", &report.csv())?;
    write_text(dir, "replay.json", &to_json(&report.json(trace)))?;
    let assign = report.config.assign.name();
    for (stem, baseline, y_label) in [
        ("traffic-over-max", Baseline::Maximum, "traffic / (d*A)"),
        (
            "traffic-over-min",
            Baseline::Minimum,
            "traffic / active pixels",
        ),
    ] {
        line_chart(
            &dir.join(stem),
            &format!("Distributed snooping traffic, {assign} (paper 003, Figs. 5-6)"),
            "processors n",
            y_label,
            &report.figure_series(baseline),
            ChartOptions {
                log_x: true,
                y_from_zero: true,
            },
        )?;
    }
    crate::output::page::Page::new(format!("Trace replay: {trace}"))
        .section(crate::output::page::text_block("Traffic", &report.table()))
        .images_of(dir)
        .files(&["replay.csv", "replay.json"])
        .write(dir)
}
