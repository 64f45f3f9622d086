//! Paper 001 (full-frame sort-last merging on the Parsytec MultiCluster): the uniprocessor
//! times, Table 1 (request balancing on and off) and the shapes of Figures 1 to 4, on the
//! stand-in scenes and the calibrated MultiCluster machines, one frame each.
//!
//! Owns which runs answer which row of papers/001.json. Must never hold a paper value.

use crate::algo::RunResult;
use crate::output::plot::{ChartOptions, Series};

use super::runs::{after_raster_s, run_jobs, Job};
use super::{paper_value, Chart, Measured, Measurements, PaperData, PaperOptions};

/// (row key, scene file, paper name), in the paper's order.
const SCENES: [(&str, &str, &str); 7] = [
    ("teapot", "spd-teapot.json", "Teapot"),
    ("gears", "spd-gears.json", "Gears"),
    ("misc1", "p001-misc1.json", "Misc_I"),
    ("misc2", "p001-misc2.json", "Misc_II"),
    ("tetra", "spd-tetra.json", "Tetra"),
    ("misc3", "p001-misc3.json", "Misc_III"),
    ("mountain", "spd-mountain.json", "Mountain"),
];
const TABLE_1: [&str; 4] = ["gears", "misc1", "misc3", "mountain"];
const NODES: [u32; 4] = [2, 4, 8, 16];
const PIPELINE: &str = "multicluster-pipeline.json";

fn scene_file(key: &str) -> &'static str {
    SCENES
        .iter()
        .find(|s| s.0 == key)
        .map(|s| s.1)
        .unwrap_or("")
}

fn pc(key: &str, procs: u32, assign: &str) -> Job {
    Job::new(PIPELINE, scene_file(key), "sort-last/pc", procs).set("assign", assign)
}

fn scanline_flow(key: &str, procs: u32) -> Job {
    Job::new(PIPELINE, scene_file(key), "sort-last/scanline-flow", procs)
}

/// DF on the torus machine rewired for the node count, as Figure 2 ran it.
fn df(key: &str, procs: u32) -> Job {
    let dims = match procs {
        1 => "[1,1]",
        2 => "[2,1]",
        4 => "[2,2]",
        8 => "[4,2]",
        _ => "[4,4]",
    };
    Job::new(
        "multicluster-torus.json",
        scene_file(key),
        "sort-last/df",
        procs,
    )
    .set("machine.nodes", &procs.to_string())
    .set("machine.network.dims", dims)
}

fn secs(r: &RunResult) -> f64 {
    r.frames[0].time().as_secs_f64()
}

fn throughput(r: &RunResult) -> f64 {
    r.frames[0].triangles_in_view as f64 / secs(r)
}

pub fn measure(options: &PaperOptions, data: &PaperData) -> Result<Measurements, String> {
    // One list of jobs, run together; `at` finds a job's result again.
    let mut jobs = Vec::new();
    for (key, ..) in SCENES {
        jobs.push(pc(key, 1, "scatter"));
        if key != "mountain" {
            jobs.push(scanline_flow(key, 1));
        }
        for n in NODES {
            jobs.push(pc(key, n, "scatter"));
            jobs.push(df(key, n));
        }
    }
    for key in TABLE_1 {
        for n in NODES {
            jobs.push(pc(key, n, "request"));
        }
    }
    for key in ["tetra", "misc3"] {
        for n in NODES {
            jobs.push(scanline_flow(key, n));
        }
    }
    let results = run_jobs(options, &jobs)?;
    let at = |job: Job| -> &RunResult {
        let i = jobs
            .iter()
            .position(|j| {
                j.algo == job.algo
                    && j.scene == job.scene
                    && j.procs == job.procs
                    && j.set == job.set
            })
            .expect("every job asked for was run");
        &results[i]
    };

    let mut m = Measurements::default();
    let mut scanline_slower = Vec::new();
    for (key, _, name) in SCENES {
        let z = secs(at(pc(key, 1, "scatter")));
        m.put(
            &format!("uni-zbuffer-{key}"),
            Measured::value(z, "sort-last/pc on 1 node, frame 0"),
        );
        if key != "mountain" {
            let s = secs(at(scanline_flow(key, 1)));
            m.put(
                &format!("uni-scanline-{key}"),
                Measured::value(s, "sort-last/scanline-flow on 1 node, frame 0"),
            );
            scanline_slower.push((name, s > z, s / z));
        }
    }
    m.put(
        "sequential-scanline-slower",
        Measured::shape(
            scanline_slower.iter().all(|s| s.1),
            format!(
                "scanline / z-buffer time: {}",
                scanline_slower
                    .iter()
                    .map(|(n, _, r)| format!("{n} {r:.2}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        ),
    );

    for key in TABLE_1 {
        for n in NODES {
            for (mode, assign) in [("on", "request"), ("off", "scatter")] {
                let r = at(pc(key, n, assign));
                let detail = format!("sort-last/pc, assign={assign}, {n} nodes, frame 0");
                m.put(
                    &format!("t1-{key}-{mode}-{n}-imbalance"),
                    Measured::value(r.frames[0].load_imbalance_pct(), detail.clone()),
                );
                m.put(
                    &format!("t1-{key}-{mode}-{n}-throughput"),
                    Measured::value(throughput(r), detail),
                );
            }
        }
    }
    let gears = at(pc("gears", 16, "request"));
    m.put(
        "imbalance-definition",
        imbalance_is_the_papers(&gears.frames[0], 16),
    );
    let mut balancing = Vec::new();
    for key in ["gears", "mountain"] {
        for n in [4, 8, 16] {
            let on = at(pc(key, n, "request")).frames[0].load_imbalance_pct();
            let off = at(pc(key, n, "scatter")).frames[0].load_imbalance_pct();
            balancing.push((
                format!("{key} {n}: imbalance {off:.1}% -> {on:.1}%"),
                on < off,
            ));
        }
    }
    for n in NODES {
        let on = throughput(at(pc("misc3", n, "request")));
        let off = throughput(at(pc("misc3", n, "scatter")));
        balancing.push((
            format!("misc3 {n}: throughput {off:.0} -> {on:.0}"),
            on <= 1.01 * off,
        ));
    }
    m.put(
        "dlb-helps-big-primitives-only",
        Measured::shape(
            balancing.iter().all(|b| b.1),
            join(balancing.iter().map(|b| b.0.clone())),
        ),
    );

    let mut rising = Vec::new();
    let mut pc_wins = Vec::new();
    for (key, _, name) in SCENES {
        let t1 = secs(at(pc(key, 1, "scatter")));
        let mut speedups = vec![1.0];
        for n in NODES {
            let t = secs(at(pc(key, n, "scatter")));
            speedups.push(t1 / t);
            pc_wins.push(t < secs(at(df(key, n))));
        }
        let ok = speedups.windows(2).all(|w| w[1] > w[0]);
        rising.push((
            format!(
                "{name} {}",
                join(speedups.iter().map(|s| format!("{s:.2}"))).replace("; ", " ")
            ),
            ok,
        ));
    }
    m.put(
        "pc-speedup-rises",
        Measured::shape(
            rising.iter().all(|r| r.1),
            format!(
                "PC speedup at 1, 2, 4, 8, 16 nodes: {}",
                join(rising.iter().map(|r| r.0.clone()))
            ),
        ),
    );
    m.put(
        "pc-beats-df",
        Measured::shape(
            pc_wins.iter().all(|&w| w),
            format!(
                "PC faster in {} of {} (scene, nodes) pairs",
                pc_wins.iter().filter(|&&w| w).count(),
                pc_wins.len()
            ),
        ),
    );
    let df_merge: Vec<f64> = NODES
        .iter()
        .map(|&n| after_raster_s(at(df("misc3", n))))
        .collect();
    let pc_merge: Vec<f64> = NODES
        .iter()
        .map(|&n| after_raster_s(at(pc("misc3", n, "scatter"))))
        .collect();
    m.put(
        "df-merge-grows",
        Measured::value(
            df_merge[3] / df_merge[0],
            format!("DF merge, 2..16 nodes: {}", seconds_list(&df_merge)),
        ),
    );
    let (lo, hi) = pc_merge
        .iter()
        .fold((f64::MAX, 0.0f64), |(lo, hi), &x| (lo.min(x), hi.max(x)));
    m.put(
        "pc-merge-flat",
        Measured::value(
            hi / lo,
            format!("PC merge, 2..16 nodes: {}", seconds_list(&pc_merge)),
        ),
    );

    let mut superlinear = Vec::new();
    let mut wins = Vec::new();
    for key in ["tetra", "misc3"] {
        let t1 = secs(at(scanline_flow(key, 1)));
        for n in [2, 4] {
            let eff = t1 / (n as f64 * secs(at(scanline_flow(key, n))));
            superlinear.push((format!("{key} {n}: {:.0}%", 100.0 * eff), eff > 1.0));
        }
        for n in [8, 16] {
            let sf = secs(at(scanline_flow(key, n)));
            let (p, d) = (secs(at(pc(key, n, "scatter"))), secs(at(df(key, n))));
            wins.push((
                format!("{key} {n}: SF {sf:.2} s, PC {p:.2} s, DF {d:.2} s"),
                sf < p && sf < d,
            ));
        }
    }
    m.put(
        "slmf-superlinear-early",
        Measured::shape(
            superlinear.iter().all(|s| s.1),
            format!(
                "ScanlineFlow efficiency: {}",
                join(superlinear.iter().map(|s| s.0.clone()))
            ),
        ),
    );
    m.put(
        "slmf-wins-from-8",
        Measured::shape(
            wins.iter().all(|w| w.1),
            join(wins.iter().map(|w| w.0.clone())),
        ),
    );

    for (key, _, name) in SCENES.iter().filter(|s| TABLE_1.contains(&s.0)) {
        let curve = |assign: &str| -> Vec<(f64, f64)> {
            NODES
                .iter()
                .map(|&n| (n as f64, throughput(at(pc(key, n, assign)))))
                .collect()
        };
        let paper = |mode: &str| -> Vec<(f64, f64)> {
            NODES
                .iter()
                .filter_map(|&n| {
                    paper_value(data, &format!("t1-{key}-{mode}-{n}-throughput"))
                        .map(|v| (n as f64, v))
                })
                .collect()
        };
        m.charts.push(Chart {
            stem: format!("table1-{key}-throughput"),
            title: format!("Table 1, {name}: Pipeline Composition throughput"),
            x_label: "nodes".into(),
            y_label: "polygons/s".into(),
            series: vec![
                Series::new("sortsim, request balancing on", curve("request")),
                Series::new("sortsim, off (scattering)", curve("scatter")),
                Series::marks("paper, on", paper("on")),
                Series::marks("paper, off", paper("off")),
            ],
            options: ChartOptions {
                log_x: true,
                y_from_zero: true,
            },
        });
    }
    Ok(m)
}

fn join(parts: impl Iterator<Item = String>) -> String {
    parts.collect::<Vec<_>>().join("; ")
}

fn seconds_list(v: &[f64]) -> String {
    join(v.iter().map(|s| format!("{s:.3} s")))
}

/// Whether `frame`'s reported load imbalance is Section 5.1's definition over the `nodes`
/// nodes' pixel-rendering finishing times: recomputed here in exact integer picoseconds.
fn imbalance_is_the_papers(frame: &crate::algo::FrameRecord, nodes: u32) -> Measured {
    let times: Vec<u128> = frame
        .raster_finish
        .iter()
        .map(|&t| t.saturating_sub(frame.start).ps() as u128)
        .collect();
    let longest = times.iter().copied().max().unwrap_or(0);
    let (n, sum) = (times.len() as u128, times.iter().sum::<u128>());
    let exact = if longest == 0 {
        0.0
    } else {
        100.0 * (n * longest - sum) as f64 / (n * longest) as f64
    };
    let reported = frame.load_imbalance_pct();
    Measured::shape(
        times.len() == nodes as usize && (exact - reported).abs() <= 1e-9 * exact.max(1.0),
        format!(
            "Gears, sort-last/pc with request balancing, 16 nodes: longest {:.3} ms, mean {:.3} ms over {} finishing times, (longest - mean) / longest = {exact:.4}%, reported {reported:.4}%",
            longest as f64 / 1e9,
            sum as f64 / n.max(1) as f64 / 1e9,
            times.len()
        ),
    )
}
