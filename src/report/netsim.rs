//! The network-alone report (`sortsim netsim -o DIR`): summary.json (every message's
//! completion and every link's traffic; byte-identical for identical inputs) and cost.json
//! (what the simulation took on this host); with `--compare`, fidelities.md, the table of
//! every transport model's makespan and mean completion beside its host time.
//!
//! Owns the files of this report kind. Must never simulate (it is handed the report).

use std::path::Path;

use crate::net::fidelity::{format_table, FidelityRow};
use crate::net::pattern::PatternReport;
use crate::output::cost::Cost;
use crate::output::plot::PlotError;
use crate::output::{to_json, write_text};

pub fn write(dir: &Path, report: &PatternReport, cost: &Cost) -> Result<(), PlotError> {
    write_text(dir, "summary.json", &to_json(report))?;
    write_text(dir, "cost.json", &to_json(cost))
}

/// `netsim --compare -o DIR`: the fidelity table as printed.
pub fn write_comparison(dir: &Path, rows: &[FidelityRow]) -> Result<(), PlotError> {
    write_text(
        dir,
        "fidelities.md",
        &format!("```text\n{}```\n", format_table(rows)),
    )
}
