//! The default job's page (reports/default/index.html): the machines it checked, the default
//! sweep's table and plots, PHOLD against its baseline and what network fidelity costs on the
//! Delta, with links to every file it wrote.
//!
//! Must never run anything; the job (main.rs) hands it the texts it printed.

use std::path::{Path, PathBuf};

use maud::html;

use crate::bench::{PholdCost, PholdSummary};
use crate::net::fidelity::FidelityRow;
use crate::output::page::{table, Page};
use crate::output::plot::PlotError;
use crate::output::write_text;
use crate::sweep::page::table_html;
use crate::sweep::table::Row;

pub struct DefaultJob<'a> {
    pub machines: &'a [PathBuf],
    pub sweep_rows: &'a [Row],
    pub phold: &'a (PholdSummary, PholdCost),
    pub fidelity_rows: &'a [FidelityRow],
    /// The fidelity table as printed (fidelity.txt).
    pub fidelity: &'a str,
}

/// Writes fidelity.txt and the page.
pub fn write_page(dir: &Path, job: &DefaultJob) -> Result<(), PlotError> {
    write_text(dir, "fidelity.txt", job.fidelity)?;
    Page::new("sortsim: the default job")
        .section(html! {
            p { "What " code { "cargo run --release" } " ran: the bundled machines checked, the default sweep "
                "(sweeps/default.json: sort-middle/static and sort-middle/ellsworth on the Touchstone Delta, "
                "PLB head stand-in, 1 to 64 processors), the engine's PHOLD benchmark and the Delta's network "
                "at every fidelity." }
            h2 { "Machines checked" }
            ul { @for m in job.machines { li { (m.file_name().map_or_else(String::new, |n| n.to_string_lossy().into_owned())) } } }
        })
        .section(table_html("The default sweep", job.sweep_rows))
        .images_of(dir)
        .section(html! {
            h2 { "PHOLD" }
            p { "16,384 events in flight, the engine against a bare binary-heap loop: "
                a href="phold/summary.json" { "phold/summary.json" } ", "
                a href="phold/cost.json" { "phold/cost.json" } "." }
        })
        .section(phold_table(&job.phold.0, &job.phold.1))
        .section(fidelity_table(job.fidelity_rows))
        .files(&["sweep.csv", "sweep.json", "fidelity.txt", "cost.json"])
        .write(dir)
}

/// PHOLD's three runs side by side.
fn phold_table(summary: &PholdSummary, cost: &PholdCost) -> maud::Markup {
    let row = |who: &str, wall: f64, rate: f64| {
        vec![
            who.to_string(),
            summary.events.to_string(),
            format!("{wall:.3}"),
            format!("{:.2}", rate / 1e6),
        ]
    };
    let rows = [
        row("engine", cost.engine_wall_s, cost.engine_events_per_s),
        row("floor", cost.floor_wall_s, cost.floor_events_per_s),
        row(
            "bare heap",
            cost.baseline_wall_s,
            cost.baseline_events_per_s,
        ),
    ];
    html! {
        (table("Engine against the floor of its design and the bare heap", &["loop", "events", "wall (s)", "M events/s"], &rows))
        p { "Ratio " (format!("{:.2}", cost.ratio_to_baseline)) "x; same events in the same order: "
            (if summary.baseline_agrees && summary.floor_agrees { "yes" } else { "no" }) ". "
            "Against the floor (one async program per logical process and nothing else): "
            (format!("{:.2}", cost.ratio_to_floor)) "x." }
    }
}

/// Each fidelity's prediction beside what it cost to simulate.
fn fidelity_table(rows: &[FidelityRow]) -> maud::Markup {
    let cells: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            let wall_s = r.wall.as_secs_f64();
            vec![
                r.fidelity.to_string(),
                format!("{:.3}", r.makespan.as_us_f64()),
                format!("{:.3}", r.mean_completion.as_us_f64()),
                format!("{:.3}", wall_s * 1e3),
            ]
        })
        .collect();
    table(
        "The Delta's mesh at every network fidelity (bit complement, 64 KiB per node)",
        &[
            "fidelity",
            "makespan (us)",
            "mean completion (us)",
            "simulator wall (ms)",
        ],
        &cells,
    )
}
