//! The papers side by side: for each of the four seed papers, every number and claim of
//! PAPER-TARGETS.md (the paper's value from `papers/NNN.json`) next to what sortsim measures
//! for it, with the deviation, the tolerance and a verdict; and a fifth, radix-k on Blue
//! Gene/P, whose published claims nothing in sortsim was tuned to.
//!
//! ```text
//! papers/NNN.json (References) ─┐
//! pNNN::measure (runs, replays) ┴─> judge each row ─> PaperReport ─> report::paper (md, json, html, plots)
//! ```
//!
//! Owns the verdict rules and which experiment answers which row. Must never write a file
//! (that is `report::paper`), never invent a paper value (every one comes from the data file,
//! which names its figure or table and quotes the text), and never drop a row that differs.

pub mod data;
mod p000;
mod p001;
mod p002;
mod p003;
mod p004;
mod runs;
pub mod verdict;

use std::collections::BTreeMap;
use std::path::PathBuf;

use serde::Serialize;

use crate::output::plot::{ChartOptions, Series};
pub use data::{PaperData, Reference, Role};
pub use verdict::{judge, Tally, Verdict};

/// One of the papers sortsim is held against.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum PaperId {
    /// Adaptive supersampling with fixed memory pools (SGI Power Challenge).
    P000,
    /// Full-frame sort-last merging (Parsytec MultiCluster).
    P001,
    /// Sort-middle with frame-coherent load balancing (Intel Touchstone Delta).
    P002,
    /// Pixel merging and distributed snooping.
    P003,
    /// Radix-k compositing on Blue Gene/P (Peterka et al. 2009, Kendall et al. 2010).
    P004,
}

impl PaperId {
    pub const ALL: [PaperId; 5] = [
        PaperId::P000,
        PaperId::P001,
        PaperId::P002,
        PaperId::P003,
        PaperId::P004,
    ];

    /// The paper's number as the command line and the data files spell it.
    pub fn id(self) -> &'static str {
        match self {
            PaperId::P000 => "000",
            PaperId::P001 => "001",
            PaperId::P002 => "002",
            PaperId::P003 => "003",
            PaperId::P004 => "004",
        }
    }

    pub fn from_id(id: &str) -> Option<PaperId> {
        PaperId::ALL.into_iter().find(|p| p.id() == id)
    }
}

/// How to run the experiments (not which: that is the paper).
#[derive(Clone, Debug)]
pub struct PaperOptions {
    /// Fewer frames per run, so that all the papers take minutes, not tens of minutes.
    pub quick: bool,
    /// Simulations at a time.
    pub jobs: usize,
    /// The repository root: machines/, scenes/ and papers/ are read from here.
    pub root: PathBuf,
    /// Where machine files are read from instead of `root/machines` (a calibration's
    /// candidate machines).
    pub machines: Option<PathBuf>,
    /// Where scene files are read from instead of `root/scenes` (a calibration's candidate
    /// scenes).
    pub scenes: Option<PathBuf>,
}

impl PaperOptions {
    /// The machine file `name` (e.g. `delta.json`).
    pub fn machine(&self, name: &str) -> PathBuf {
        self.machines
            .clone()
            .unwrap_or_else(|| self.root.join("machines"))
            .join(name)
    }

    /// The scene file `name` (e.g. `polio-standin.json`).
    pub fn scene(&self, name: &str) -> PathBuf {
        self.scenes
            .clone()
            .unwrap_or_else(|| self.root.join("scenes"))
            .join(name)
    }
}

/// What sortsim measured for one row: a number in the row's unit, whether the paper's
/// qualitative claim holds, or both; `detail` says how it was measured.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Measured {
    pub value: Option<f64>,
    pub shape: Option<bool>,
    pub detail: String,
}

impl Measured {
    pub fn value(value: f64, detail: impl Into<String>) -> Measured {
        Measured {
            value: Some(value),
            shape: None,
            detail: detail.into(),
        }
    }

    pub fn shape(holds: bool, detail: impl Into<String>) -> Measured {
        Measured {
            value: None,
            shape: Some(holds),
            detail: detail.into(),
        }
    }

    /// A number that may miss the paper's digits while the claim around it still holds.
    pub fn value_and_shape(value: f64, holds: bool, detail: impl Into<String>) -> Measured {
        Measured {
            value: Some(value),
            shape: Some(holds),
            detail: detail.into(),
        }
    }
}

/// A chart of a paper's report: sortsim's curves with the paper's values drawn over them.
#[derive(Clone, Debug)]
pub struct Chart {
    /// File stem under `plots/`.
    pub stem: String,
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub series: Vec<Series>,
    pub options: ChartOptions,
}

/// Everything one paper's experiments produced, keyed by row id.
#[derive(Debug, Default)]
pub struct Measurements {
    pub rows: BTreeMap<String, Measured>,
    pub charts: Vec<Chart>,
}

impl Measurements {
    pub fn put(&mut self, id: &str, m: Measured) {
        let previous = self.rows.insert(id.to_string(), m);
        debug_assert!(previous.is_none(), "row {id} measured twice");
    }
}

/// One row of a paper's report.
#[derive(Clone, Debug, Serialize)]
pub struct RowReport {
    pub id: String,
    pub figure: String,
    pub location: String,
    pub quantity: String,
    pub unit: String,
    pub role: Role,
    /// The machine a fitted row was fitted to.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fit: Option<String>,
    /// The paper's number or claim as printed ("2.8", "< 5", "0.017 .. 0.030", "shape").
    pub paper: String,
    pub sortsim: Option<f64>,
    pub deviation_pct: Option<f64>,
    pub tolerance: String,
    pub verdict: Verdict,
    /// Why a row holds only in shape or differs; empty when it matches.
    pub why: String,
    pub detail: String,
    /// Under `--quick`, why this row's value is only approximately the full run's.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub approximate: Option<String>,
}

/// One paper's side-by-side report.
#[derive(Debug, Serialize)]
pub struct PaperReport {
    pub paper: String,
    pub title: String,
    pub quick: bool,
    /// The headline: the verdicts of the predicted rows, the only ones that test the model.
    pub tally: Tally,
    /// Every role's verdicts (predicted, fitted, input, definition; roles without rows left out).
    pub by_role: BTreeMap<Role, Tally>,
    pub rows: Vec<RowReport>,
    #[serde(skip)]
    pub charts: Vec<Chart>,
}

impl PaperReport {
    /// The figures and tables in the order the data file first names them.
    pub fn figures(&self) -> Vec<&str> {
        let mut seen: Vec<&str> = Vec::new();
        for r in &self.rows {
            if !seen.contains(&r.figure.as_str()) {
                seen.push(&r.figure);
            }
        }
        seen
    }

    /// "predicted: 12 rows: 3 exact, 5 within tolerance, 2 shape holds, 2 differ; not
    /// evidence: 7 fitted, 10 input, 4 definition".
    pub fn headline(&self) -> String {
        let others: Vec<String> = self
            .by_role
            .iter()
            .filter(|(role, _)| **role != Role::Predicted)
            .map(|(role, t)| format!("{} {}", t.total(), role.label()))
            .collect();
        let mut line = format!("predicted: {}", self.tally.headline());
        if !others.is_empty() {
            line.push_str(&format!("; not evidence: {}", others.join(", ")));
        }
        line
    }

    pub fn row(&self, id: &str) -> Option<&RowReport> {
        self.rows.iter().find(|r| r.id == id)
    }
}

#[derive(Debug, thiserror::Error)]
pub enum PaperError {
    #[error("{}: {message}", path.display())]
    Data { path: PathBuf, message: String },
    #[error("paper {paper}: {message}")]
    Experiment {
        paper: &'static str,
        message: String,
    },
    #[error("paper {paper}: row {id} is in the data file but no experiment measures it")]
    Unmeasured { paper: &'static str, id: String },
    #[error("paper {paper}: the experiments measure {id}, which the data file does not list")]
    Unlisted { paper: &'static str, id: String },
}

/// Runs one paper's experiments and judges every row of its data file.
pub fn run_paper(id: PaperId, options: &PaperOptions) -> Result<PaperReport, PaperError> {
    let data = data::load(&options.root, id)?;
    let measured = match id {
        PaperId::P000 => p000::measure(options, &data),
        PaperId::P001 => p001::measure(options, &data),
        PaperId::P002 => p002::measure(options, &data),
        PaperId::P003 => p003::measure(options, &data),
        PaperId::P004 => p004::measure(options, &data),
    }
    .map_err(|message| PaperError::Experiment {
        paper: id.id(),
        message,
    })?;
    let mut report = assemble(id, &data, measured)?;
    report.quick = options.quick;
    if options.quick {
        for (row, reference) in report.rows.iter_mut().zip(&data.rows) {
            row.approximate = reference.approximate_when_quick.clone();
        }
    }
    Ok(report)
}

fn assemble(
    id: PaperId,
    data: &PaperData,
    mut measured: Measurements,
) -> Result<PaperReport, PaperError> {
    let mut rows = Vec::with_capacity(data.rows.len());
    for reference in &data.rows {
        let m = measured
            .rows
            .remove(&reference.id)
            .ok_or_else(|| PaperError::Unmeasured {
                paper: id.id(),
                id: reference.id.clone(),
            })?;
        rows.push(row_report(reference, m));
    }
    if let Some(extra) = measured.rows.keys().next() {
        return Err(PaperError::Unlisted {
            paper: id.id(),
            id: extra.clone(),
        });
    }
    Ok(PaperReport {
        paper: id.id().to_string(),
        title: data.title.clone(),
        quick: false,
        tally: tally_of(&rows, Role::Predicted),
        by_role: Role::ALL
            .into_iter()
            .map(|role| (role, tally_of(&rows, role)))
            .filter(|(_, t)| t.total() > 0)
            .collect(),
        rows,
        charts: measured.charts,
    })
}

fn tally_of(rows: &[RowReport], role: Role) -> Tally {
    Tally::of(rows.iter().filter(|r| r.role == role).map(|r| r.verdict))
}

fn row_report(reference: &Reference, m: Measured) -> RowReport {
    let verdict = judge(reference, &m);
    let claim_only = reference.value.is_none() && reference.range.is_none();
    let why = match verdict {
        Verdict::Exact | Verdict::WithinTolerance => String::new(),
        Verdict::ShapeHolds if claim_only => String::new(),
        Verdict::ShapeHolds | Verdict::Differs => reference
            .why
            .clone()
            .unwrap_or_else(|| "(no explanation recorded)".to_string()),
    };
    RowReport {
        id: reference.id.clone(),
        figure: reference.figure.clone(),
        location: reference.location.clone(),
        quantity: reference.quantity.clone(),
        unit: reference.unit.clone(),
        role: reference.role,
        fit: reference.fit.clone(),
        paper: reference.claim(),
        sortsim: m.value,
        deviation_pct: m.value.and_then(|v| reference.deviation_pct(v)),
        tolerance: reference.tolerance_text(),
        verdict,
        why,
        detail: m.detail,
        approximate: None,
    }
}

/// The paper's value of a row, for drawing it over a curve; `None` for a row without one (a
/// claim) or an id the data file does not list.
pub(crate) fn paper_value(data: &PaperData, id: &str) -> Option<f64> {
    data.rows.iter().find(|r| r.id == id).and_then(|r| r.value)
}
