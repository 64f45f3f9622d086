//! The sweep table: one row per listed point with its swept values and the metrics read from
//! its summary.json, plus speedup and efficiency against the one-processor point with the
//! same other values. Written as sweep.csv and sweep.json.
//!
//! Owns the row layout and the speedup definition (triangles per second at p processors over
//! triangles per second at one). Must never read the clock or anything host-dependent: the
//! table is byte-identical for identical inputs.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::spec::Sweep;
use super::PointFailure;

/// The part of a run's summary.json the table uses.
#[derive(Debug, Clone, Deserialize)]
pub struct PointMetrics {
    pub mean_triangles_per_s: f64,
    pub mean_frame_s: f64,
    pub mean_load_imbalance_pct: f64,
    pub mean_bytes_per_frame: f64,
    pub mean_messages_per_frame: f64,
    pub machine_metrics: MachineMetrics,
    pub per_frame: Vec<FrameMetrics>,
}

/// One frame of a run's summary.json.
#[derive(Debug, Clone, Deserialize)]
pub struct FrameMetrics {
    pub time_s: f64,
    pub triangles_per_s: f64,
    pub load_imbalance_pct: f64,
    pub bytes: u64,
    pub messages: u64,
}

impl PointMetrics {
    /// The per-frame means over the frames after the first `warmup` (as the run summary
    /// computes them over all frames); unchanged when no frame would be left.
    fn after_warmup(&self, warmup: u32) -> PointMetrics {
        let frames = self.per_frame.get(warmup as usize..).unwrap_or_default();
        if frames.is_empty() {
            return self.clone();
        }
        let mean = |f: &dyn Fn(&FrameMetrics) -> f64| {
            frames.iter().map(f).sum::<f64>() / frames.len() as f64
        };
        PointMetrics {
            mean_triangles_per_s: mean(&|f| f.triangles_per_s),
            mean_frame_s: mean(&|f| f.time_s),
            mean_load_imbalance_pct: mean(&|f| f.load_imbalance_pct),
            mean_bytes_per_frame: mean(&|f| f.bytes as f64),
            mean_messages_per_frame: mean(&|f| f.messages as f64),
            ..self.clone()
        }
    }
}

#[derive(Debug, Clone, Deserialize)]
pub struct MachineMetrics {
    pub links: Vec<LinkMetrics>,
    pub nodes: Vec<NodeMetrics>,
}

#[derive(Debug, Clone, Deserialize)]
pub struct NodeMetrics {
    pub memory_high_water_bytes: u64,
}

#[derive(Debug, Clone, Deserialize)]
pub struct LinkMetrics {
    pub utilization_pct: f64,
}

/// One point of the sweep. Metrics are absent for a failed point; speedup also when the
/// one-processor point failed or rendered nothing.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Row {
    pub point: String,
    pub machine: String,
    pub scene: String,
    pub algo: String,
    /// The `vary` options of this point, by key.
    pub options: BTreeMap<String, String>,
    pub seed: u64,
    pub procs: u32,
    pub mean_triangles_per_s: Option<f64>,
    pub mean_frame_s: Option<f64>,
    pub speedup: Option<f64>,
    pub efficiency: Option<f64>,
    pub mean_bytes_per_frame: Option<f64>,
    pub mean_messages_per_frame: Option<f64>,
    pub mean_load_imbalance_pct: Option<f64>,
    pub busiest_link_utilization_pct: Option<f64>,
    /// The largest memory high-water mark of any node.
    pub peak_node_memory_bytes: Option<f64>,
    pub error: Option<String>,
}

/// sweep.json: the sweep's dimensions in product order, then the rows.
#[derive(Debug, Serialize)]
pub struct SweepTable<'a> {
    pub note: Option<&'a str>,
    pub frames: Option<&'a str>,
    /// Frames at the start of every run that the means leave out.
    #[serde(skip_serializing_if = "is_zero")]
    pub warmup_frames: u32,
    /// Product order, outermost first; the values as written in the spec.
    pub dims: &'a [super::spec::Dim],
    pub speedup: &'static str,
    pub rows: &'a [Row],
}

impl<'a> SweepTable<'a> {
    pub fn new(sweep: &'a Sweep, rows: &'a [Row]) -> SweepTable<'a> {
        SweepTable {
            note: sweep.note.as_deref(),
            frames: sweep.points.first().and_then(|p| p.run.frames.as_deref()),
            warmup_frames: sweep.warmup_frames,
            dims: &sweep.dims,
            speedup: "mean_triangles_per_s over that of the same machine, scene (or the sweep's speedup_scene), algorithm, options and seed on 1 processor; efficiency = speedup / procs",
            rows,
        }
    }
}

fn is_zero(n: &u32) -> bool {
    *n == 0
}

/// The rows of the listed points, in product order; the means over the frames after the
/// sweep's warm-up frames.
pub fn rows(
    sweep: &Sweep,
    names: &[String],
    metrics: &[Option<PointMetrics>],
    failures: &[PointFailure],
) -> Vec<Row> {
    let after_warmup: Vec<Option<PointMetrics>>;
    let metrics = if sweep.warmup_frames == 0 {
        metrics
    } else {
        after_warmup = metrics
            .iter()
            .map(|m| m.as_ref().map(|m| m.after_warmup(sweep.warmup_frames)))
            .collect();
        &after_warmup
    };
    let index: BTreeMap<&[String], usize> = sweep
        .points
        .iter()
        .enumerate()
        .map(|(i, p)| (p.values.as_slice(), i))
        .collect();
    let baseline = |values: &[String]| {
        let base = sweep.baseline_of(values);
        let &i = index.get(base.as_slice())?;
        metrics[i]
            .as_ref()
            .map(|m| m.mean_triangles_per_s)
            .filter(|&t| t > 0.0)
    };
    sweep
        .points
        .iter()
        .enumerate()
        .filter(|(_, p)| p.listed)
        .map(|(i, p)| {
            let m = metrics[i].as_ref();
            let speedup = m.and_then(|m| Some(m.mean_triangles_per_s / baseline(&p.values)?));
            let error = failures
                .iter()
                .find(|f| f.point == names[i])
                .map(|f| f.message.clone());
            Row {
                point: names[i].clone(),
                machine: value(sweep, &p.values, "machine"),
                scene: value(sweep, &p.values, "scene"),
                algo: p.run.algo.clone(),
                options: sweep
                    .dims
                    .iter()
                    .zip(&p.values)
                    .filter_map(|(d, v)| {
                        Some((d.key.strip_prefix("vary.")?.to_string(), v.clone()))
                    })
                    .collect(),
                seed: p.run.seed,
                procs: p.run.procs,
                mean_triangles_per_s: m.map(|m| m.mean_triangles_per_s),
                mean_frame_s: m.map(|m| m.mean_frame_s),
                speedup,
                efficiency: speedup.map(|s| s / f64::from(p.run.procs)),
                mean_bytes_per_frame: m.map(|m| m.mean_bytes_per_frame),
                mean_messages_per_frame: m.map(|m| m.mean_messages_per_frame),
                mean_load_imbalance_pct: m.map(|m| m.mean_load_imbalance_pct),
                busiest_link_utilization_pct: m.map(busiest_link),
                peak_node_memory_bytes: m.map(peak_node_memory),
                error,
            }
        })
        .collect()
}

fn value(sweep: &Sweep, values: &[String], key: &str) -> String {
    sweep
        .dim(key)
        .map(|i| values[i].clone())
        .unwrap_or_default()
}

/// The largest memory high-water mark of any node.
fn peak_node_memory(m: &PointMetrics) -> f64 {
    let peak = m
        .machine_metrics
        .nodes
        .iter()
        .map(|n| n.memory_high_water_bytes)
        .max();
    peak.unwrap_or(0) as f64
}

/// The highest utilization of any link; 0 for a machine without links (one processor).
fn busiest_link(m: &PointMetrics) -> f64 {
    m.machine_metrics
        .links
        .iter()
        .map(|l| l.utilization_pct)
        .fold(0.0, f64::max)
}

/// sweep.csv: a header, then one line per row. Numbers are printed in Rust's shortest
/// round-trip form; an absent value is an empty field.
pub fn csv(sweep: &Sweep, rows: &[Row]) -> String {
    let option_keys: Vec<&str> = sweep
        .dims
        .iter()
        .filter_map(|d| d.key.strip_prefix("vary."))
        .collect();
    let mut header: Vec<String> = ["point", "machine", "scene", "algo"]
        .map(String::from)
        .to_vec();
    header.extend(option_keys.iter().map(|k| k.to_string()));
    header.extend(
        [
            "seed",
            "procs",
            "mean_triangles_per_s",
            "mean_frame_s",
            "speedup",
            "efficiency",
            "mean_bytes_per_frame",
            "mean_messages_per_frame",
            "mean_load_imbalance_pct",
            "busiest_link_utilization_pct",
            "peak_node_memory_bytes",
            "error",
        ]
        .map(String::from),
    );
    let mut out = line(&header);
    for r in rows {
        let mut fields = vec![
            r.point.clone(),
            r.machine.clone(),
            r.scene.clone(),
            r.algo.clone(),
        ];
        fields.extend(
            option_keys
                .iter()
                .map(|k| r.options.get(*k).cloned().unwrap_or_default()),
        );
        fields.push(r.seed.to_string());
        fields.push(r.procs.to_string());
        for v in [
            r.mean_triangles_per_s,
            r.mean_frame_s,
            r.speedup,
            r.efficiency,
            r.mean_bytes_per_frame,
            r.mean_messages_per_frame,
            r.mean_load_imbalance_pct,
            r.busiest_link_utilization_pct,
            r.peak_node_memory_bytes,
        ] {
            fields.push(v.map(|x| x.to_string()).unwrap_or_default());
        }
        fields.push(r.error.clone().unwrap_or_default());
        out.push_str(&line(&fields));
    }
    out
}

/// One CSV line (RFC 4180 quoting where a field needs it).
fn line(fields: &[String]) -> String {
    let quoted: Vec<String> = fields
        .iter()
        .map(|f| {
            if f.contains([',', '"', '\n', '\r']) {
                format!("\"{}\"", f.replace('"', "\"\""))
            } else {
                f.clone()
            }
        })
        .collect();
    quoted.join(",") + "\n"
}

/// The columns a person reads, in order (the first names the machine too when a sweep has
/// several: [`shown_columns`]).
pub const SHOWN_COLUMNS: [&str; 9] = [
    "algo, scene, options",
    "procs",
    "triangles/s",
    "frame ms",
    "speedup",
    "eff",
    "bytes/frame",
    "imbal %",
    "link %",
];

/// Whether the rows come from more than one machine.
fn several_machines(rows: &[Row]) -> bool {
    rows.iter().any(|r| r.machine != rows[0].machine)
}

/// The headers of [`shown_cells`]' columns.
pub fn shown_columns(rows: &[Row]) -> Vec<&'static str> {
    let mut columns = SHOWN_COLUMNS.to_vec();
    if several_machines(rows) {
        columns[0] = "machine, algo, scene, options";
    }
    columns
}

/// Each row's cells under [`shown_columns`] (a failed point's numbers are `-`), and its
/// error.
pub fn shown_cells(rows: &[Row]) -> Vec<(Vec<String>, Option<String>)> {
    let opt = |v: Option<f64>, prec: usize| v.map_or("-".to_string(), |x| format!("{x:.prec$}"));
    let machine = several_machines(rows);
    rows.iter()
        .map(|r| {
            let mut what = format!("{}, {}", r.algo, super::plots::stem(&r.scene));
            if machine {
                what = format!("{}, {what}", super::plots::stem(&r.machine));
            }
            for (k, v) in &r.options {
                what.push_str(&format!(", {k}={v}"));
            }
            let cells = vec![
                what,
                r.procs.to_string(),
                opt(r.mean_triangles_per_s, 0),
                opt(r.mean_frame_s.map(|s| s * 1e3), 3),
                opt(r.speedup, 2),
                opt(r.efficiency, 2),
                opt(r.mean_bytes_per_frame, 0),
                opt(r.mean_load_imbalance_pct, 1),
                opt(r.busiest_link_utilization_pct, 1),
            ];
            (cells, r.error.clone())
        })
        .collect()
}

/// The table `sortsim sweep` prints: [`shown_columns`], one line per point, a failed point's
/// error under it.
pub fn format_rows(rows: &[Row]) -> String {
    let width = if several_machines(rows) { 72 } else { 56 };
    let line = |c: &[String]| {
        format!(
            "{:<width$} {:>5} {:>12} {:>10} {:>8} {:>6} {:>12} {:>8} {:>8}\n",
            c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7], c[8]
        )
    };
    let header: Vec<String> = shown_columns(rows).iter().map(|h| h.to_string()).collect();
    let mut out = line(&header);
    for (cells, error) in shown_cells(rows) {
        out.push_str(&line(&cells));
        if let Some(e) = error {
            out.push_str(&format!("    failed: {e}\n"));
        }
    }
    out
}
