//! The simulator's own benchmarks as report folders: `bench scale` (scale.json, scale.txt
//! and the three growth charts) and `bench phold` (summary.json, the deterministic part;
//! cost.json, what it took on this host).
//!
//! Owns the files of these report kinds. Must never measure anything (it is handed the
//! reports) and never write except through `write_text` and the plot writer.

use std::path::Path;

use crate::bench::scale::{ScaleReport, CURVE_FIDELITIES};
use crate::bench::{PholdCost, PholdSummary};
use crate::output::plot::{line_chart, ChartOptions, PlotError, Series};
use crate::output::{to_json, write_text};

/// Writes `bench scale`'s folder; `table` is the text it printed.
pub fn write_scale(dir: &Path, report: &ScaleReport, table: &str) -> Result<(), PlotError> {
    write_text(dir, "scale.json", &to_json(report))?;
    write_text(dir, "scale.txt", table)?;
    scale_plots(report, dir)
}

/// Writes `bench phold`'s folder.
pub fn write_phold(dir: &Path, summary: &PholdSummary, cost: &PholdCost) -> Result<(), PlotError> {
    write_text(dir, "summary.json", &to_json(summary))?;
    write_text(dir, "cost.json", &to_json(cost))
}

/// What `bench phold` prints: the workload, the three loops' event rates (the engine, the
/// floor executor of its design, the bare heap) and the engine's ratio to each, whether they
/// processed the same events, and with `--instructions` both loops' instruction counts
/// (summary.json and cost.json hold every number).
pub fn phold_text(summary: &PholdSummary, cost: &PholdCost) -> String {
    let counted = match (cost.instructions, cost.instruction_ratio) {
        (Some(counts), Some(ratio)) => format!(
            "instructions (callgrind): engine {}, floor {}, bare heap {}; bare heap / engine: \
             {ratio:.3}x (the event-rate ratio without the host's noise)\n",
            counts.measured,
            cost.floor_instructions
                .map_or_else(|| "not counted".to_string(), |n| n.to_string()),
            counts.baseline
        ),
        _ => String::new(),
    };
    let row = |who: &str, wall: f64, rate: f64| {
        format!(
            "{who:<10} {:>12} {:>10.3} {:>12.2}\n",
            summary.events,
            wall,
            rate / 1e6
        )
    };
    format!(
        "PHOLD: {} logical processes x {} events = {} in flight, {:.0}% remote, mean delay {:.3} us, \
         lookahead {:.3} us, simulated to {:.3} us (seed {})\n\
         {:<10} {:>12} {:>10} {:>12}\n{}{}{}\
         engine / bare heap: {:.2}x; same events in the same order: {} (trace {})\n\
         engine / floor: {:.2}x (the floor is one async program per LP and nothing else: what \
         the engine's features cost beyond its design); same events: {}\n{}",
        summary.lps,
        summary.events_per_lp,
        summary.in_flight,
        100.0 * summary.remote,
        summary.mean_s * 1e6,
        summary.lookahead_s * 1e6,
        summary.simulated_end_s * 1e6,
        summary.seed,
        "loop",
        "events",
        "wall (s)",
        "M events/s",
        row("engine", cost.engine_wall_s, cost.engine_events_per_s),
        row("floor", cost.floor_wall_s, cost.floor_events_per_s),
        row("bare heap", cost.baseline_wall_s, cost.baseline_events_per_s),
        cost.ratio_to_baseline,
        if summary.baseline_agrees { "yes" } else { "NO" },
        summary.trace_hash,
        cost.ratio_to_floor,
        if summary.floor_agrees { "yes" } else { "NO" },
        counted
    ) + if summary.events == 0 {
        "no event fell at or before --end, so nothing was measured and the ratio means \
         nothing: give a later --end\n"
    } else {
        ""
    }
}

/// The three growth charts, one line per fidelity, written under `dir`.
fn scale_plots(report: &ScaleReport, dir: &Path) -> Result<(), PlotError> {
    for (stem, title, x_label, curve) in [
        (
            "wall-vs-messages",
            "Wall time against messages (16x32 torus)",
            "messages",
            &report.wall_against_messages,
        ),
        (
            "wall-vs-procs",
            "Wall time against processors (one polio frame)",
            "processors",
            &report.wall_against_procs,
        ),
        (
            "wall-vs-triangles",
            "Wall time against triangles (one frame, 512 nodes)",
            "triangles",
            &report.wall_against_triangles,
        ),
    ] {
        let series: Vec<Series> = CURVE_FIDELITIES
            .iter()
            .map(|f| {
                let points = curve
                    .iter()
                    .filter(|p| p.fidelity == f.name())
                    .map(|p| (p.x, p.wall_s))
                    .collect();
                Series::new(f.name(), points)
            })
            .filter(|s| !s.points.is_empty())
            .collect();
        if series.is_empty() {
            continue;
        }
        let options = ChartOptions {
            log_x: true,
            y_from_zero: true,
        };
        line_chart(
            &dir.join(stem),
            title,
            x_label,
            "wall (s)",
            &series,
            options,
        )?;
    }
    Ok(())
}
