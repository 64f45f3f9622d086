//! The utilization report (`sortsim utilization -o DIR`, paper 002's Figures 4 and 5):
//! utilization.csv and utilization.json (every cell), figure4.csv and figure5.csv (the
//! charts' points) and the two charts as SVG and PNG; and the tables the command prints.
//!
//! Owns the files of this report kind. Must never simulate (it is handed the outcome) and
//! never write except through `write_atomic`.

use std::path::Path;

use crate::algo::sort_middle::utilization::{CountsMode, Outcome};
use crate::output::plot::{line_chart, ChartOptions, PlotError, Series};
use crate::output::{to_json, write_text};

/// Figure 5's count mode among those asked for: the previous frame's counts when present (as
/// in the paper), else the current frame's.
pub fn figure_5_mode(modes: &[CountsMode]) -> CountsMode {
    if modes.contains(&CountsMode::Previous) {
        CountsMode::Previous
    } else {
        CountsMode::Current
    }
}

/// The line `sortsim utilization` prints before its tables: which frames of which scene, their
/// mean screen triangles and pixels tested, and where the costs came from.
pub fn header(outcome: &Outcome, scene: &Path, machine: &Path, frames: &FramesShown) -> String {
    format!(
        "{}: {} of {} frames (frames {}..{} every {}), {:.0} screen triangles and {:.0} pixels tested per frame; costs from {}{}\n",
        scene.display(),
        frames.count,
        frames.of,
        frames.range.start,
        frames.range.end,
        frames.step,
        outcome.mean_screen_triangles,
        outcome.mean_pixels_tested,
        machine.display(),
        if outcome.prices.fallback {
            " (it prices no rasterization operation: documented fallback costs used, see utilization.json)"
        } else {
            ""
        }
    )
}

/// Which of a scene's frames a utilization run looked at.
pub struct FramesShown {
    pub range: std::ops::Range<u32>,
    pub step: u32,
    pub count: usize,
    pub of: u32,
}

/// The tables `sortsim utilization` prints: utilization in each count mode asked for, the
/// performance model's relative times (Figure 5) and the interleaved baseline.
pub fn tables(outcome: &Outcome, modes: &[CountsMode]) -> String {
    let percent = |c: &crate::algo::sort_middle::utilization::Cell| 100.0 * c.utilization;
    [
        outcome.table(modes, "Expected rasterization utilization (%)", 1, percent),
        outcome.table(
            &[figure_5_mode(modes)],
            "Relative execution time (performance model)",
            3,
            |c| c.relative_time,
        ),
        outcome.table(
            &[CountsMode::Interleaved],
            "Baseline utilization (%)",
            1,
            percent,
        ),
    ]
    .concat()
}

/// Writes the report of `outcome` under `dir`: `modes` are the counts modes shown in Figure 4
/// (Figure 5 shows `figure_5_mode` of them); `files` = (scene, machine) as named in
/// utilization.json.
pub fn write(
    dir: &Path,
    outcome: &Outcome,
    modes: &[CountsMode],
    files: (&str, &str),
) -> Result<(), PlotError> {
    let figure5 = figure_5_mode(modes);
    write_text(dir, "utilization.csv", &outcome.csv())?;
    write_text(
        dir,
        "utilization.json",
        &to_json(&outcome.json(files.0, files.1)),
    )?;
    let mut fig4 = String::from("counts,granularity,procs,utilization_pct\n");
    let mut fig5 = String::from("procs,granularity,relative_time\n");
    let mut utilization: Vec<Series> = Vec::new();
    let mut relative: std::collections::BTreeMap<u32, Vec<(f64, f64)>> =
        std::collections::BTreeMap::new();
    let mut grans: Vec<u32> = outcome.cells.iter().map(|c| c.granularity).collect();
    grans.sort_unstable();
    grans.dedup();
    for &mode in modes {
        for &g in &grans {
            let points: Vec<(f64, f64)> = outcome
                .cells
                .iter()
                .filter(|c| c.counts == mode && c.granularity == g)
                .map(|c| (c.procs as f64, 100.0 * c.utilization))
                .collect();
            for (n, u) in &points {
                fig4.push_str(&format!("{},{g},{n},{u:.4}\n", mode.name()));
            }
            utilization.push(Series::new(format!("g={g} {}", mode.name()), points));
        }
    }
    for c in outcome.cells.iter().filter(|c| c.counts == figure5) {
        fig5.push_str(&format!(
            "{},{},{:.5}\n",
            c.procs, c.granularity, c.relative_time
        ));
        relative
            .entry(c.procs)
            .or_default()
            .push((c.granularity as f64, c.relative_time));
    }
    let relative: Vec<Series> = relative
        .into_iter()
        .map(|(n, points)| Series::new(format!("N={n}"), points))
        .collect();
    write_text(dir, "figure4.csv", &fig4)?;
    write_text(dir, "figure5.csv", &fig5)?;
    line_chart(
        &dir.join("figure4-utilization"),
        "Expected rasterization utilization (paper 002, Fig. 4)",
        "processors N",
        "utilization (%)",
        &utilization,
        ChartOptions {
            log_x: true,
            y_from_zero: true,
        },
    )?;
    line_chart(
        &dir.join("figure5-relative-time"),
        &format!(
            "Relative execution time, {} counts (paper 002, Fig. 5)",
            figure5.name()
        ),
        "granularity ratio (regions per processor)",
        "time / mean time for the same N",
        &relative,
        ChartOptions {
            log_x: false,
            y_from_zero: false,
        },
    )?;
    let utilization_table =
        outcome.table(modes, "Expected rasterization utilization (%)", 1, |c| {
            100.0 * c.utilization
        });
    let relative_table = outcome.table(
        &[figure5],
        "Relative execution time (performance model)",
        3,
        |c| c.relative_time,
    );
    crate::output::page::Page::new(format!("Utilization simulation: {}", files.0))
        .section(crate::output::page::text_block(
            "Utilization",
            &utilization_table,
        ))
        .section(crate::output::page::text_block(
            "Performance model",
            &relative_table,
        ))
        .images_of(dir)
        .files(&[
            "utilization.csv",
            "utilization.json",
            "figure4.csv",
            "figure5.csv",
        ])
        .write(dir)
}
