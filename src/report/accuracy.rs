//! The report of `sortsim accuracy`: accuracy.json (image error, simulated frame time and
//! memory per anti-aliasing mode; predicted frame time per network fidelity; byte-identical
//! for identical inputs), cost.json (the simulator's wall time for the reference, every mode
//! and every fidelity), accuracy.md (both tables with wall times beside them), fidelity.txt,
//! the charts (error against simulated frame time, against memory and against wall time,
//! one point per mode; predicted frame time against wall time, one point per fidelity) and
//! the images (reference.png, frame-<mode>.png).
//!
//! Must never run a simulation, and never put a wall time or host measurement into
//! accuracy.json.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::accuracy::{base_options, FidelityResult, ModeResult, RunMeasure, Study};
use crate::metrics::run::RunHeader;
use crate::output::cost::Cost;
use crate::output::plot::{line_chart, ChartOptions, PlotError, Series};
use crate::output::{to_json, write_atomic};
use crate::raster::{encode_png, Framebuffer};

/// accuracy.json.
#[derive(Serialize, Debug, Clone, PartialEq)]
pub struct AccuracySummary {
    /// The study's run spec (its fidelity is what the modes ran at; `aa` is left out of
    /// its options, the modes set it).
    #[serde(flatten)]
    pub run: RunHeader,
    pub reference: ReferenceSummary,
    pub modes: Vec<ModeSummary>,
    pub fidelities: Vec<FidelitySummary>,
}

#[derive(Serialize, Debug, Clone, PartialEq)]
pub struct ReferenceSummary {
    pub frame: u32,
    pub width: u32,
    pub height: u32,
    pub samples_per_pixel: u32,
    /// FNV-1a of the reference rounded to 8 bits per channel (reference.png).
    pub image_hash: String,
}

#[derive(Serialize, Debug, Clone, PartialEq)]
pub struct ModeSummary {
    pub mode: String,
    /// The `aa` option passed, if any.
    pub aa_option: Option<String>,
    pub mae_levels: f64,
    pub max_abs_levels: f64,
    pub off_by_more_than_one_pct: f64,
    pub mean_frame_s: f64,
    pub last_frame_s: f64,
    pub memory_high_water_max_bytes: u64,
    pub memory_high_water_mean_bytes: u64,
    pub events: u64,
    pub image_hash: String,
}

#[derive(Serialize, Debug, Clone, PartialEq)]
pub struct FidelitySummary {
    pub fidelity: &'static str,
    pub mean_frame_s: f64,
    pub last_frame_s: f64,
    pub events: u64,
}

/// cost.json: wall times, in the same order as accuracy.json's lists.
#[derive(Serialize, Debug, Clone)]
pub struct AccuracyCost {
    pub reference: Cost,
    pub modes: Vec<NamedCost>,
    pub fidelities: Vec<NamedCost>,
}

#[derive(Serialize, Debug, Clone)]
pub struct NamedCost {
    pub name: String,
    #[serde(flatten)]
    pub cost: Cost,
}

#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    #[error("{}: cannot write: {source}", path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error(transparent)]
    Plot(#[from] PlotError),
    #[error("PNG encoding failed: {0}")]
    Png(String),
}

fn hash(fb: &Framebuffer) -> String {
    format!("{:016x}", fb.hash())
}

fn mode_summary(m: &ModeResult) -> ModeSummary {
    ModeSummary {
        mode: m.mode.name(),
        aa_option: m.mode.option_value(),
        mae_levels: m.error.mae_levels,
        max_abs_levels: m.error.max_abs_levels,
        off_by_more_than_one_pct: 100.0 * m.error.off_by_more_than_one_share,
        mean_frame_s: m.measure.mean_frame.as_secs_f64(),
        last_frame_s: m.measure.last_frame.as_secs_f64(),
        memory_high_water_max_bytes: m.measure.memory_max.get(),
        memory_high_water_mean_bytes: m.measure.memory_mean.get(),
        events: m.measure.events,
        image_hash: hash(&m.image),
    }
}

fn fidelity_summary(f: &FidelityResult) -> FidelitySummary {
    let RunMeasure {
        mean_frame,
        last_frame,
        events,
        ..
    } = f.measure;
    FidelitySummary {
        fidelity: f.fidelity.name(),
        mean_frame_s: mean_frame.as_secs_f64(),
        last_frame_s: last_frame.as_secs_f64(),
        events,
    }
}

impl AccuracySummary {
    pub fn new(study: &Study) -> AccuracySummary {
        let b = &study.base;
        AccuracySummary {
            run: RunHeader::new(b, base_options(study)),
            reference: ReferenceSummary {
                frame: study.reference_frame,
                width: study.reference.width(),
                height: study.reference.height(),
                samples_per_pixel: study.reference.samples_per_pixel(),
                image_hash: hash(&study.reference.to_framebuffer()),
            },
            modes: study.modes.iter().map(mode_summary).collect(),
            fidelities: study.fidelities.iter().map(fidelity_summary).collect(),
        }
    }
}

impl AccuracyCost {
    pub fn new(study: &Study) -> AccuracyCost {
        AccuracyCost {
            reference: study.reference_cost.clone(),
            modes: study
                .modes
                .iter()
                .map(|m| NamedCost {
                    name: m.mode.name(),
                    cost: m.cost.clone(),
                })
                .collect(),
            fidelities: study
                .fidelities
                .iter()
                .map(|f| NamedCost {
                    name: f.fidelity.name().to_string(),
                    cost: f.cost.clone(),
                })
                .collect(),
        }
    }
}

/// accuracy.md: the modes table and the fidelity table, wall times beside simulated ones.
pub fn markdown(s: &AccuracySummary, cost: &AccuracyCost) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "# What accuracy costs: {} on {} ({} processors)\n",
        s.run.algo, s.run.machine, s.run.procs
    );
    let _ = writeln!(
        out,
        "{}; images compared on frame {} against a {}-samples-per-pixel box-filtered \
reference (rendered in {:.2} s wall)\n",
        s.run.context(),
        s.reference.frame,
        s.reference.samples_per_pixel,
        cost.reference.wall_s
    );
    out += &modes_table(s, cost);
    out += "\n";
    out += &fidelity_table(s, cost);
    out
}

fn modes_table(s: &AccuracySummary, cost: &AccuracyCost) -> String {
    let mut out = String::from(
        "## Anti-aliasing modes\n\n| mode | MAE (levels) | pixels off > 1 level (%) | mean frame (ms) | last frame (ms) | memory high-water max / mean (KiB) | simulator wall (s) |\n| --- | ---: | ---: | ---: | ---: | ---: | ---: |\n",
    );
    for (m, c) in s.modes.iter().zip(&cost.modes) {
        let _ = writeln!(
            out,
            "| {} | {:.4} | {:.3} | {:.3} | {:.3} | {:.1} / {:.1} | {:.3} |",
            m.mode,
            m.mae_levels,
            m.off_by_more_than_one_pct,
            m.mean_frame_s * 1e3,
            m.last_frame_s * 1e3,
            m.memory_high_water_max_bytes as f64 / 1024.0,
            m.memory_high_water_mean_bytes as f64 / 1024.0,
            c.cost.wall_s
        );
    }
    out
}

fn fidelity_table(s: &AccuracySummary, cost: &AccuracyCost) -> String {
    let mut out = String::from(
        "## Network fidelity (anti-aliasing none)\n\n| fidelity | mean frame (ms) | last frame (ms) | events | simulator wall (s) |\n| --- | ---: | ---: | ---: | ---: |\n",
    );
    for (f, c) in s.fidelities.iter().zip(&cost.fidelities) {
        let _ = writeln!(
            out,
            "| {} | {:.3} | {:.3} | {} | {:.3} |",
            f.fidelity,
            f.mean_frame_s * 1e3,
            f.last_frame_s * 1e3,
            f.events,
            c.cost.wall_s
        );
    }
    out
}

/// fidelity.txt: the fidelity table as plain text, like `sortsim netsim --compare`.
pub fn fidelity_text(s: &AccuracySummary, cost: &AccuracyCost) -> String {
    let mut out = format!(
        "{:<8} {:>16} {:>16} {:>12} {:>10}\n",
        "fidelity", "mean_frame_ms", "last_frame_ms", "events", "wall_s"
    );
    for (f, c) in s.fidelities.iter().zip(&cost.fidelities) {
        out += &format!(
            "{:<8} {:>16.4} {:>16.4} {:>12} {:>10.3}\n",
            f.fidelity,
            f.mean_frame_s * 1e3,
            f.last_frame_s * 1e3,
            f.events,
            c.cost.wall_s
        );
    }
    out
}

/// Writes every file of the report into `dir`; returns accuracy.md's text.
pub fn write_report(dir: &Path, study: &Study) -> Result<String, ReportError> {
    let summary = AccuracySummary::new(study);
    let cost = AccuracyCost::new(study);
    let md = markdown(&summary, &cost);
    write(dir, "accuracy.json", to_json(&summary).as_bytes())?;
    write(dir, "cost.json", to_json(&cost).as_bytes())?;
    write(dir, "accuracy.md", md.as_bytes())?;
    write(
        dir,
        "fidelity.txt",
        fidelity_text(&summary, &cost).as_bytes(),
    )?;
    write(
        dir,
        "reference.png",
        &png(&study.reference.to_framebuffer())?,
    )?;
    for m in &study.modes {
        let name = format!("frame-{}.png", m.mode.name().replace(':', "-"));
        write(dir, &name, &png(&m.image)?)?;
    }
    charts(dir, &summary, &cost)?;
    crate::output::page::Page::new("Accuracy versus time")
        .markdown(&md)
        .images_of(dir)
        .files(&["accuracy.md", "accuracy.json", "fidelity.txt", "cost.json"])
        .write(dir)?;
    Ok(md)
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> Result<(), ReportError> {
    let path = dir.join(name);
    write_atomic(&path, bytes).map_err(|source| ReportError::Io { path, source })
}

fn png(fb: &Framebuffer) -> Result<Vec<u8>, ReportError> {
    let mut bytes = Vec::new();
    encode_png(fb, &mut bytes).map_err(|e| ReportError::Png(e.to_string()))?;
    Ok(bytes)
}

/// One single-point series per mode, labelled by the mode.
fn mode_points(s: &AccuracySummary, x: impl Fn(usize, &ModeSummary) -> f64) -> Vec<Series> {
    s.modes
        .iter()
        .enumerate()
        .map(|(i, m)| Series::new(m.mode.clone(), vec![(x(i, m), m.mae_levels)]))
        .collect()
}

fn charts(dir: &Path, s: &AccuracySummary, cost: &AccuracyCost) -> Result<(), ReportError> {
    let scatter = ChartOptions {
        log_x: false,
        y_from_zero: true,
    };
    let title = |what: &str| format!("{what} ({}, {} procs)", s.run.machine, s.run.procs);
    let y = "image error (MAE, levels)";
    line_chart(
        &dir.join("error-vs-frame-time"),
        &title("Image error vs frame time"),
        "mean simulated frame time (ms)",
        y,
        &mode_points(s, |_, m| m.mean_frame_s * 1e3),
        scatter,
    )?;
    line_chart(
        &dir.join("error-vs-memory"),
        &title("Image error vs memory"),
        "memory high-water, busiest node (KiB)",
        y,
        &mode_points(s, |_, m| m.memory_high_water_max_bytes as f64 / 1024.0),
        scatter,
    )?;
    line_chart(
        &dir.join("error-vs-wall"),
        &title("Image error vs wall time"),
        "simulator wall time (s)",
        y,
        &mode_points(s, |i, _| cost.modes[i].cost.wall_s),
        scatter,
    )?;
    let fidelities: Vec<Series> = s
        .fidelities
        .iter()
        .zip(&cost.fidelities)
        .map(|(f, c)| Series::new(f.fidelity, vec![(c.cost.wall_s, f.mean_frame_s * 1e3)]))
        .collect();
    line_chart(
        &dir.join("fidelity-vs-wall"),
        &title("Fidelity: frame time vs wall time"),
        "simulator wall time (s)",
        "mean simulated frame time (ms)",
        &fidelities,
        ChartOptions {
            log_x: false,
            y_from_zero: false,
        },
    )?;
    Ok(())
}
