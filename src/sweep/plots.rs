//! The plots of a sweep, each against the processor count: triangles/s, speedup, efficiency,
//! traffic per frame, load imbalance, the largest node's memory. One line per combination of the other swept values, in
//! product order, labelled by the values that differ between lines.
//!
//! Owns which charts a sweep gets and how rows become series. Must never compute a metric
//! (the rows hold them) nor draw (that is `report::plot`).

use std::path::Path;

use super::spec::Sweep;
use super::table::Row;
use crate::output::plot::{line_chart, ChartOptions, PlotError, Series};

/// A chart of the sweep: file stem, title, y label, the metric, and whether y starts at zero.
struct Metric {
    stem: &'static str,
    title: &'static str,
    y_label: &'static str,
    get: fn(&Row) -> Option<f64>,
}

const METRICS: [Metric; 6] = [
    Metric {
        stem: "triangles-per-s",
        title: "Rendering rate",
        y_label: "triangles per second",
        get: |r| r.mean_triangles_per_s,
    },
    Metric {
        stem: "speedup",
        title: "Speedup over one processor",
        y_label: "speedup",
        get: |r| r.speedup,
    },
    Metric {
        stem: "efficiency",
        title: "Parallel efficiency",
        y_label: "speedup / processors",
        get: |r| r.efficiency,
    },
    Metric {
        stem: "traffic-per-frame",
        title: "Network traffic",
        y_label: "bytes per frame",
        get: |r| r.mean_bytes_per_frame,
    },
    Metric {
        stem: "load-imbalance",
        title: "Load imbalance",
        y_label: "load imbalance (%)",
        get: |r| r.mean_load_imbalance_pct,
    },
    Metric {
        stem: "memory-per-node",
        title: "Memory of the fullest node",
        y_label: "high-water mark (bytes)",
        get: |r| r.peak_node_memory_bytes,
    },
];

/// Writes `DIR/<metric>.svg` and `.png` for every metric; a sweep over several machines also
/// gets `DIR/<metric>-<machine>.svg|png` per machine, whose values can lie orders of
/// magnitude apart from the others' on one axis.
pub fn write_plots(sweep: &Sweep, rows: &[Row], dir: &Path) -> Result<(), PlotError> {
    let groups = groups(sweep, rows);
    let procs: Vec<u32> = rows.iter().map(|r| r.procs).collect();
    // The sweep's file name tells which report a plot belongs to once it is copied out.
    let name = sweep
        .file
        .file_stem()
        .map_or(String::new(), |s| s.to_string_lossy().into_owned());
    let options = ChartOptions {
        log_x: log_axis(&procs),
        y_from_zero: true,
    };
    let mut machines: Vec<&str> = Vec::new();
    for r in rows {
        if !machines.contains(&r.machine.as_str()) {
            machines.push(&r.machine);
        }
    }
    let mut charts = vec![(
        String::new(),
        name.clone(),
        groups.iter().collect::<Vec<_>>(),
    )];
    if machines.len() > 1 {
        for m in &machines {
            let mine = groups
                .iter()
                .filter(|(_, members)| members[0].machine == *m);
            charts.push((
                format!("-{}", stem(m)),
                format!("{name}, {}", stem(m)),
                mine.collect(),
            ));
        }
    }
    for (suffix, context, groups) in charts {
        for m in &METRICS {
            let series: Vec<Series> = groups
                .iter()
                .map(|(label, members)| {
                    let mut points: Vec<(f64, f64)> = members
                        .iter()
                        .filter_map(|r| Some((f64::from(r.procs), (m.get)(r)?)))
                        .collect();
                    points.sort_by(|a, b| a.0.total_cmp(&b.0));
                    Series::new(label.clone(), points)
                })
                .collect();
            let title = format!("{} ({context})", m.title);
            line_chart(
                &dir.join(format!("{}{suffix}", m.stem)),
                &title,
                "processors",
                m.y_label,
                &series,
                options,
            )?;
        }
    }
    Ok(())
}

/// Rows grouped by everything but procs, groups in order of first appearance (product
/// order), each labelled by the values that vary across the sweep.
fn groups<'r>(sweep: &Sweep, rows: &'r [Row]) -> Vec<(String, Vec<&'r Row>)> {
    let procs = sweep.dims.len() - 1;
    let swept: Vec<usize> = (0..procs)
        .filter(|&i| sweep.dims[i].values.len() > 1)
        .collect();
    let listed: Vec<_> = sweep.listed().collect();
    let mut out: Vec<(Vec<String>, String, Vec<&Row>)> = Vec::new();
    for (point, row) in listed.iter().zip(rows) {
        let key = point.values[..procs].to_vec();
        match out.iter_mut().find(|(k, _, _)| *k == key) {
            Some((_, _, members)) => members.push(row),
            None => out.push((key, label(sweep, &point.values, &swept, row), vec![row])),
        }
    }
    out.into_iter()
        .map(|(_, label, rows)| (label, rows))
        .collect()
}

fn label(sweep: &Sweep, values: &[String], swept: &[usize], row: &Row) -> String {
    if swept.is_empty() {
        return row.algo.clone();
    }
    let parts: Vec<String> = swept
        .iter()
        .map(|&i| {
            let (key, v) = (&sweep.dims[i].key, &values[i]);
            match key.as_str() {
                "algo" => v.clone(),
                "machine" | "scene" => Path::new(v)
                    .file_stem()
                    .map_or(v.clone(), |s| s.to_string_lossy().into_owned()),
                other => format!("{}={v}", other.trim_start_matches("vary.")),
            }
        })
        .collect();
    parts.join(", ")
}

/// A log axis when processor counts span a factor of 8 or more (powers of two, usually).
fn log_axis(procs: &[u32]) -> bool {
    let (lo, hi) = (
        procs.iter().min().copied().unwrap_or(1),
        procs.iter().max().copied().unwrap_or(1),
    );
    hi >= lo.saturating_mul(8)
}

/// A path's file stem, as legends and tables name machines and scenes.
pub(crate) fn stem(path: &str) -> String {
    Path::new(path)
        .file_stem()
        .map_or_else(|| path.to_string(), |s| s.to_string_lossy().into_owned())
}
