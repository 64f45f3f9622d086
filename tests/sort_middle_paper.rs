//! Sort-middle against the papers' figures, in shape: paper 002 (Ellsworth on the Touchstone
//! Delta, Figure 9) and paper 000 (static regions on the Power Challenge, Table 1). Each
//! assertion names its figure and states its tolerance.

use crate::common;

use common::scene;

use std::sync::Arc;

use sortsim::algo::RunResult;
use sortsim::scene::Scene;

fn simulate(
    machine: &str,
    scene: &Arc<Scene>,
    algo: &str,
    procs: u32,
    frames: &str,
    set: &[(&str, &str)],
) -> RunResult {
    common::run_frames(machine, scene, algo, procs, frames, set).unwrap()
}

/// Paper 002's measures over a viewing sequence use the frames after the first (which deals
/// regions r mod N and waits for no assignment; it is 1 of the paper's 80 or 110 frames).
fn later_frames(r: &RunResult) -> &[sortsim::algo::FrameRecord] {
    &r.frames[1..]
}

fn triangles_per_s(r: &RunResult) -> f64 {
    let rates: Vec<f64> = later_frames(r)
        .iter()
        .map(|f| f.triangles_in_view as f64 / f.time().as_secs_f64())
        .collect();
    rates.iter().sum::<f64>() / rates.len() as f64
}

fn mean_frame_s(r: &RunResult) -> f64 {
    let frames = later_frames(r);
    frames.iter().map(|f| f.time().as_secs_f64()).sum::<f64>() / frames.len() as f64
}

/// `hops` keeps these runs fast; on the polio stand-in at 512 processors, `flow` (link
/// contention) changed the first frame's time by 1.4% at 14 times the simulator's cost.
const FAST_NETWORK: (&str, &str) = ("machine.network.fidelity", "hops");

#[test]
fn polio_triangles_per_second_peak_then_fall_on_the_delta() {
    // Paper 002, Figure 9: the polio model peaks at 2.8 M triangles/s on 256 processors and
    // falls at 512. Frames 0..3: frames 1 and 2 are balanced on the previous frame's counts.
    // Two-step on, the faster mode from 128 processors on (the paper's curve is the better of
    // the two; with two-step off alone the peak is at 128: 2.01 M against 1.91 M at 256).
    let polio = scene("polio-standin.json");
    let rate = |n| {
        triangles_per_s(&simulate(
            "delta.json",
            &polio,
            "sort-middle/ellsworth",
            n,
            "0..3",
            &[FAST_NETWORK, ("two-step", "on")],
        ))
    };
    let curve: Vec<(u32, f64)> = [64, 128, 256, 512]
        .into_iter()
        .map(|n| (n, rate(n)))
        .collect();
    eprintln!("polio triangles/s: {curve:?}");
    let (peak_n, peak) = curve
        .iter()
        .cloned()
        .fold((0, 0.0), |a, b| if b.1 > a.1 { b } else { a });
    // The peak lies at 256 processors, as in the paper: waiting for the summing tree of the
    // per-region counts, whose messages grow with N, is what falls at 512.
    assert_eq!(peak_n, 256, "peak at {peak_n}: {curve:?}");
    // Its height misses the paper's 2.8 M (tolerance 10%): the Delta's fit to all of paper
    // 002 (three steps, machines/delta.json's source) lands it 10% low even with the PLB
    // head's frame rate held out (papers/002.json's peak-polio says why). Held here is today's
    // value, 2.61 M at `hops` over these three frames, so a change that moves it is seen.
    assert!((2.4e6..=2.8e6).contains(&peak), "peak {peak:.0}");
    // It falls by at least 15% from the peak to 512 processors.
    assert!(curve[3].1 <= 0.85 * peak, "{curve:?}");
    assert!(curve[0].1 < peak, "rises before the peak: {curve:?}");
}

#[test]
fn two_step_redistribution_helps_a_small_model_on_many_processors() {
    // Paper 002, Figure 9 and Discussion: two-step gains with small data sets and many
    // processors, "the largest performance increase is 50 percent" (the paper row's tolerance
    // is 10 points).
    let plb = scene("plb-head-standin.json");
    let frame = |n, two_step| {
        mean_frame_s(&simulate(
            "delta.json",
            &plb,
            "sort-middle/ellsworth",
            n,
            "0..3",
            &[FAST_NETWORK, ("two-step", two_step)],
        ))
    };
    let gain = |n| frame(n, "off") / frame(n, "on");
    let (g16, g256, g512) = (gain(16), gain(256), gain(512));
    eprintln!("two-step speedup of the frame: 16 -> {g16:.2}, 256 -> {g256:.2}, 512 -> {g512:.2}");
    assert!(g256 > 1.1 && g512 > 1.1, "256: {g256}, 512: {g512}");
    assert!(g16 < g256.min(g512), "few processors gain less: 16: {g16}");
    assert!(
        g256.max(g512) <= 1.6,
        "at most 50% (+10 points): {g256}, {g512}"
    );
    // Auto decides like the model: on at 512 processors, off at 4.
    let auto_512 = simulate(
        "delta.json",
        &plb,
        "sort-middle/ellsworth",
        512,
        "0..1",
        &[FAST_NETWORK, ("two-step", "auto")],
    );
    let on_512 = simulate(
        "delta.json",
        &plb,
        "sort-middle/ellsworth",
        512,
        "0..1",
        &[FAST_NETWORK, ("two-step", "on")],
    );
    assert_eq!(auto_512.frames[0].messages, on_512.frames[0].messages);
    let auto_4 = simulate(
        "delta.json",
        &plb,
        "sort-middle/ellsworth",
        4,
        "0..1",
        &[FAST_NETWORK, ("two-step", "auto")],
    );
    let off_4 = simulate(
        "delta.json",
        &plb,
        "sort-middle/ellsworth",
        4,
        "0..1",
        &[FAST_NETWORK],
    );
    assert_eq!(auto_4.frames[0].messages, off_4.frames[0].messages);
}

#[test]
fn previous_frame_counts_balance_the_rasterization() {
    // Paper 002, Load balancing: the first frame assigns region r to processor r mod N; later
    // frames use the previous frame's counts with greedy bin packing, which must balance the
    // rasterization better than the fixed pattern did.
    let plb = scene("plb-head-standin.json");
    let r = simulate(
        "delta.json",
        &plb,
        "sort-middle/ellsworth",
        32,
        "0..4",
        &[FAST_NETWORK],
    );
    let first = r.frames[0].load_imbalance_pct();
    let later: f64 = r.frames[1..]
        .iter()
        .map(|f| f.load_imbalance_pct())
        .sum::<f64>()
        / 3.0;
    eprintln!("load imbalance: frame 0 {first:.1}%, frames 1..4 {later:.1}%");
    assert!(later < first, "{first} -> {later}");
}

#[test]
fn letter_b_on_eight_processors_like_table_1() {
    // Paper 000, Table 1 (letter B, 8 processors, 20 frames): transformation time is the same
    // on every processor; rasterization times spread from 0.017 to 0.030 s (max/min 1.76).
    let b = scene("p000-letter-b.json");
    let r = simulate(
        "power-challenge.json",
        &b,
        "sort-middle/static",
        8,
        "0..20",
        &[],
    );
    let phase = |p: &str| -> Vec<f64> {
        r.stats
            .nodes
            .iter()
            .map(|n| {
                n.busy_by_phase
                    .iter()
                    .find(|(q, _)| *q == p)
                    .map_or(0.0, |(_, t)| t.as_secs_f64())
            })
            .collect()
    };
    let spread = |v: &[f64]| {
        v.iter().cloned().fold(0.0, f64::max) / v.iter().cloned().fold(f64::MAX, f64::min)
    };
    let (transform, raster) = (phase("transform"), phase("rasterize"));
    eprintln!("transform {transform:?}\nrasterize {raster:?}");
    // Even: every processor transforms 101 of the 808 polygons; only region classification,
    // which depends on polygon sizes, differs (6% here, with the transform cost fitted to
    // Table 1). Table 1 prints least and greatest as 0.0002 s at four decimals, which bounds
    // the spread at 1.67 only; 10% holds the mechanism (equal work per processor) to account.
    assert!(spread(&transform) <= 1.10, "{transform:?}");
    // Same order as Table 1's 1.76: between 1.3 and 2.5.
    let s = spread(&raster);
    assert!((1.3..=2.5).contains(&s), "rasterization max/min {s:.2}");
}
