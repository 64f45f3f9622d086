//! `assign=blocks` (object-space blocks) and `bounds=on` (IceT's bounding boxes) for the
//! compositing variants: the image is the sequential renderer's whatever the deal and the
//! bounds; bounds change what is cleared, held and scanned, never what travels; and blocks
//! are what makes bounds pay (a node's rectangle is small only when its primitives are close
//! together in space).

use crate::common;

use std::sync::Arc;

use common::{run_frame0, scene};
use sortsim::algo::{reference, RunResult};
use sortsim::scene::Scene;
use sortsim::units::SimTime;

const COMPOSITES: [&str; 4] = [
    "sort-last/tree",
    "sort-last/binary-swap",
    "sort-last/radix-k",
    "sort-last/2-3-swap",
];

fn simulate(s: &Arc<Scene>, algo: &str, procs: u32, assign: &str, bounds: &str) -> RunResult {
    run_frame0(
        "bgp-intrepid-8k.json",
        s,
        algo,
        procs,
        &[("image", "rle"), ("assign", assign), ("bounds", bounds)],
    )
    .unwrap_or_else(|e| panic!("{algo} n={procs} assign={assign} bounds={bounds}: {e}"))
}

fn phase(r: &RunResult, node: usize, name: &str) -> SimTime {
    r.stats.nodes[node]
        .busy_by_phase
        .iter()
        .find(|(p, _)| *p == name)
        .map_or(SimTime::ZERO, |&(_, t)| t)
}

fn total(r: &RunResult, name: &str) -> SimTime {
    (0..r.stats.nodes.len()).map(|i| phase(r, i, name)).sum()
}

#[test]
fn blocks_and_bounds_give_the_sequential_image() {
    for name in ["spd-teapot.json", "plb-head-standin.json"] {
        let s = scene(name);
        let (expected, _) = reference::render(&s.frame(0).unwrap());
        for algo in COMPOSITES {
            for procs in [1, 3, 8, 13] {
                for (assign, bounds) in [("blocks", "off"), ("blocks", "on"), ("scatter", "on")] {
                    let r = simulate(&s, algo, procs, assign, bounds);
                    assert_eq!(
                        r.image.hash(),
                        expected.hash(),
                        "{name} {algo} n={procs} assign={assign} bounds={bounds}"
                    );
                }
            }
        }
    }
}

#[test]
fn bounds_cut_clearing_scanning_and_memory_but_not_traffic() {
    let s = scene("plb-head-standin.json");
    for algo in COMPOSITES {
        let (off, on) = (
            simulate(&s, algo, 16, "blocks", "off"),
            simulate(&s, algo, 16, "blocks", "on"),
        );
        // The same pixels travel in the same pieces.
        let (f_off, f_on) = (&off.frames[0], &on.frames[0]);
        assert_eq!(
            (f_off.bytes, f_off.messages),
            (f_on.bytes, f_on.messages),
            "{algo}"
        );
        for i in 0..16 {
            // Clearing a rectangle of the screen never costs more than clearing all of it,
            // and a node's frame buffer and input pieces never outgrow full ones.
            assert!(
                phase(&on, i, "clear") <= phase(&off, i, "clear"),
                "{algo} node {i}"
            );
            assert!(
                on.stats.memory[i].high_water <= off.stats.memory[i].high_water,
                "{algo} node {i}"
            );
        }
        // Sixteen blocks of the head each cover a small part of the 512 x 512 screen: all
        // clearing together stays under a quarter of sixteen full frames, and the merge
        // phase (scanning pieces to encode them, then merging) gets cheaper too.
        assert!(
            4 * total(&on, "clear").ps() < total(&off, "clear").ps(),
            "{algo}: clear {} against {}",
            total(&on, "clear"),
            total(&off, "clear")
        );
        assert!(total(&on, "merge") < total(&off, "merge"), "{algo}");
        let peak = |r: &RunResult| r.stats.memory.iter().map(|m| m.high_water).max().unwrap();
        assert!(peak(&on) < peak(&off), "{algo}");
    }
}

#[test]
fn blocks_keep_each_nodes_rectangle_small_where_scattering_spreads_it() {
    // With bounds, a node clears the rectangle around what it drew: a scattered share
    // reaches across the whole model, a block only across its part.
    let s = scene("plb-head-standin.json");
    let blocks = simulate(&s, "sort-last/binary-swap", 16, "blocks", "on");
    let scatter = simulate(&s, "sort-last/binary-swap", 16, "scatter", "on");
    assert!(
        3 * total(&blocks, "clear").ps() < total(&scatter, "clear").ps(),
        "blocks {} scatter {}",
        total(&blocks, "clear"),
        total(&scatter, "clear")
    );
}

#[test]
fn gather_off_leaves_the_image_in_pieces_and_ends_the_frame_sooner() {
    let s = scene("plb-head-standin.json");
    let (expected, _) = reference::render(&s.frame(0).unwrap());
    for algo in [
        "sort-last/binary-swap",
        "sort-last/radix-k",
        "sort-last/2-3-swap",
    ] {
        for procs in [1, 6, 16] {
            let run = |gather: &str| {
                run_frame0(
                    "bgp-intrepid-8k.json",
                    &s,
                    algo,
                    procs,
                    &[
                        ("image", "rle"),
                        ("assign", "blocks"),
                        ("bounds", "on"),
                        ("gather", gather),
                    ],
                )
                .unwrap_or_else(|e| panic!("{algo} n={procs} gather={gather}: {e}"))
            };
            let (on, off) = (run("on"), run("off"));
            assert_eq!(off.image.hash(), expected.hash(), "{algo} n={procs}");
            // Every node but 0 that ends holding a piece sends it to node 0 when gathering
            // (binary swap's folded nodes hand theirs on first; radix-k and 2-3 swap keep all).
            let holders = if algo == "sort-last/binary-swap" {
                1 << procs.ilog2()
            } else {
                procs
            };
            let (f_on, f_off) = (&on.frames[0], &off.frames[0]);
            assert_eq!(
                f_on.messages - f_off.messages,
                u64::from(holders - 1),
                "{algo} n={procs}"
            );
            let time = |f: &sortsim::algo::FrameRecord| f.end - f.start;
            if procs > 1 {
                assert!(time(f_off) < time(f_on), "{algo} n={procs}");
            } else {
                assert!(time(f_off) <= time(f_on), "{algo} n={procs}");
            }
        }
    }
}
