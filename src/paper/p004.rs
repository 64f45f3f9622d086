//! Paper 004 (radix-k compositing on Blue Gene/P: Peterka et al., SC09, and Kendall et al.,
//! EGPGV 2010): radix-k's lead over binary swap from 32 to 4,096 processes, what bounding
//! boxes and run-length encoding add, and 64 megapixels composited by 32,768 processes, all
//! on machines/bgp-intrepid-8k.json, which was built from the machine's published figures and
//! fitted to nothing, so every row is a prediction.
//!
//! Each process count runs on a partition of its own size (Blue Gene/P runs a job on a block
//! of nodes shaped for it: a 3-D mesh below 512 nodes, a torus from 512), the image left in pieces as compositing benchmarks time it
//! (`gather=off`), and the time compared is the composite's: the frame's end minus the last
//! process's rasterization finish.
//!
//! Owns which runs answer which row of papers/004.json. Must never hold a paper value.

use crate::output::plot::{ChartOptions, Series};

use super::runs::{after_raster_s, run_jobs_keeping, Job};
use super::{paper_value, Chart, Measured, Measurements, PaperData, PaperOptions};

const BGP: &str = "bgp-intrepid-8k.json";
/// Dense frames of 16 megapixels fit a process's 512 MiB; 64 megapixels need bounding boxes.
const DENSE: &str = "plb-head-16mp.json";
const LARGE: &str = "plb-head-64mp.json";
const PROCS: [u32; 3] = [32, 512, 4096];
const LARGEST: u32 = 32768;

/// The Blue Gene/P block a job of `procs` processes (four a node) runs on: a mesh below 512
/// nodes, a torus from there (the machine file's note).
fn partition(procs: u32) -> (&'static str, &'static str) {
    match procs {
        32 => ("mesh", "[2,2,2]"),
        512 => ("mesh", "[4,4,8]"),
        4096 => ("torus", "[8,8,16]"),
        _ => ("torus", "[16,16,32]"),
    }
}

/// What a run composites: full frames, or IceT's bounding boxes around run-length pieces.
#[derive(Clone, Copy, PartialEq)]
enum Pixels {
    Dense,
    BoundedRle,
}

fn composite(algo: &str, scene: &str, procs: u32, pixels: Pixels) -> Job {
    let (topology, dims) = partition(procs);
    let job = Job::new(BGP, scene, &format!("sort-last/{algo}"), procs)
        .frames("0")
        .set("machine.nodes", &procs.to_string())
        .set("machine.network.topology", topology)
        .set("machine.network.dims", dims)
        .set("assign", "blocks")
        .set("gather", "off");
    match pixels {
        Pixels::Dense => job,
        Pixels::BoundedRle => job.set("image", "rle").set("bounds", "on"),
    }
}

pub fn measure(options: &PaperOptions, data: &PaperData) -> Result<Measurements, String> {
    let mut jobs = Vec::new();
    for n in PROCS {
        jobs.push(composite("radix-k", DENSE, n, Pixels::Dense));
        jobs.push(composite("binary-swap", DENSE, n, Pixels::Dense));
    }
    for n in PROCS.into_iter().chain([LARGEST]) {
        jobs.push(composite("radix-k", LARGE, n, Pixels::BoundedRle));
        jobs.push(composite("binary-swap", LARGE, n, Pixels::BoundedRle));
    }
    let composites = run_jobs_keeping(options, &jobs, |r| after_raster_s(&r))?;
    let time = |algo: &str, scene: &str, n: u32, pixels: Pixels| -> f64 {
        let i = jobs
            .iter()
            .position(|j| *j == composite(algo, scene, n, pixels))
            .expect("every job asked for was run");
        composites[i]
    };

    let mut m = Measurements::default();
    let mut gains = Vec::new();
    for n in PROCS {
        let rk = time("radix-k", DENSE, n, Pixels::Dense);
        let bs = time("binary-swap", DENSE, n, Pixels::Dense);
        let gain = 100.0 * (bs - rk) / bs;
        m.put(
            &format!("rk-gain-{n}"),
            Measured::value(
                gain,
                format!(
                    "radix-k (k=auto) {} against binary swap {}, {n} processes, {DENSE}, \
                     assign=blocks, gather=off, composite after the last rasterization",
                    ms(rk),
                    ms(bs)
                ),
            ),
        );
        gains.push((n as f64, gain));
    }
    let ratios: Vec<(u32, f64, f64, f64)> = PROCS
        .into_iter()
        .chain([LARGEST])
        .map(|n| {
            let rk = time("radix-k", LARGE, n, Pixels::BoundedRle);
            let bs = time("binary-swap", LARGE, n, Pixels::BoundedRle);
            (n, bs / rk, rk, bs)
        })
        .collect();
    let best = ratios
        .iter()
        .copied()
        .fold(ratios[0], |a, r| if r.1 > a.1 { r } else { a });
    m.put(
        "bounds-rle-up-to-5x",
        Measured::value(
            best.1,
            format!(
                "largest at {} processes; binary swap / radix-k, both with image=rle, \
                 bounds=on, {LARGE}, assign=blocks, gather=off: {}",
                best.0,
                ratios
                    .iter()
                    .map(|(n, r, rk, bs)| format!("{n} {r:.2}x ({} / {})", ms(*bs), ms(*rk)))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        ),
    );
    let large = time("radix-k", LARGE, LARGEST, Pixels::BoundedRle);
    m.put(
        "t-64mp-32k",
        Measured::value(
            large,
            format!(
                "radix-k (k=auto) on {LARGEST} processes, {LARGE}, assign=blocks, image=rle, \
                 bounds=on, gather=off: composite after the last rasterization"
            ),
        ),
    );
    m.charts.push(gain_chart(&gains, data));
    Ok(m)
}

fn ms(s: f64) -> String {
    format!("{:.1} ms", 1e3 * s)
}

/// sortsim's lead by process count, the paper's "about 40%" marked at each.
fn gain_chart(gains: &[(f64, f64)], data: &PaperData) -> Chart {
    let paper: Vec<(f64, f64)> = gains
        .iter()
        .filter_map(|&(n, _)| Some((n, paper_value(data, &format!("rk-gain-{n}"))?)))
        .collect();
    Chart {
        stem: "radix-k-gain".into(),
        title: "Radix-k's lead over binary swap on Blue Gene/P (dense 16-megapixel images)".into(),
        x_label: "processes".into(),
        y_label: "binary swap's time saved (%)".into(),
        series: vec![
            Series {
                label: "sortsim".into(),
                points: gains.to_vec(),
                marks_only: false,
            },
            Series {
                label: "paper (32 to 35,000 processes)".into(),
                points: paper,
                marks_only: true,
            },
        ],
        options: ChartOptions {
            log_x: true,
            y_from_zero: true,
        },
    }
}
