//! The default job's page (reports/default/index.html): the machines it checked, the default
//! sweep's table and plots, PHOLD against its baseline and what network fidelity costs on the
//! Delta, with links to every file it wrote.
//!
//! Must never run anything; the job (main.rs) hands it the texts it printed.

use std::path::{Path, PathBuf};

use maud::html;

use crate::output::page::{text_block, Page};
use crate::output::plot::PlotError;
use crate::output::write_text;

pub struct DefaultJob<'a> {
    pub machines: &'a [PathBuf],
    pub sweep_table: &'a str,
    pub phold: &'a str,
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
        .section(text_block("The default sweep", job.sweep_table))
        .images_of(dir)
        .section(html! {
            h2 { "PHOLD" }
            p { "16,384 events in flight, the engine against a bare binary-heap loop: "
                a href="phold/summary.json" { "phold/summary.json" } ", "
                a href="phold/cost.json" { "phold/cost.json" } "." }
            pre { (job.phold) }
        })
        .section(text_block(
            "The Delta's mesh at every network fidelity (bit complement, 64 KiB per node)",
            job.fidelity,
        ))
        .files(&["sweep.csv", "sweep.json", "fidelity.txt", "cost.json"])
        .write(dir)
}
