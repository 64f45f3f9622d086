//! The network-alone report (`sortsim netsim -o DIR`): summary.json (every message's
//! completion and every link's traffic; byte-identical for identical inputs) and cost.json
//! (what the simulation took on this host).
//!
//! Owns the files of this report kind. Must never simulate (it is handed the report).

use std::path::Path;

use super::cost::Cost;
use super::plot::PlotError;
use super::{to_json, write_text};
use crate::net::pattern::PatternReport;

pub fn write(dir: &Path, report: &PatternReport, cost: &Cost) -> Result<(), PlotError> {
    write_text(dir, "summary.json", &to_json(report))?;
    write_text(dir, "cost.json", &to_json(cost))
}
