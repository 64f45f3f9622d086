//! sort-last/binary-swap (Ma, Painter, Hansen, Krogh 1994): the image equals the sequential
//! renderer's at every node count (with the fold of the extra nodes when N is not a power of
//! two) on several topologies, and a frame moves exactly the closed form's bytes.

use crate::common;

use std::sync::Arc;

use common::{run_frame0, scene};
use sortsim::algo::{reference, RunResult};
use sortsim::scene::Scene;

/// Bytes of a full-frame pixel when frames are merged: rgb and a 32-bit z.
const FULL_FRAME_PIXEL_BYTES: u64 = 7;

fn simulate(machine: &str, scene: &Arc<Scene>, procs: u32, set: &[(&str, &str)]) -> RunResult {
    run_frame0(machine, scene, "sort-last/binary-swap", procs, set)
        .unwrap_or_else(|e| panic!("{machine} n={procs} {set:?}: {e}"))
}

#[test]
fn images_equal_the_sequential_image_at_any_node_count() {
    for name in [
        "p003-roses.json",
        "spd-teapot.json",
        "plb-head-standin.json",
    ] {
        let s = scene(name);
        let (expected, _) = reference::render(&s.frame(0).unwrap());
        for procs in [1, 2, 3, 5, 8, 13, 16, 32] {
            let r = simulate("denali-crossbar.json", &s, procs, &[]);
            assert_eq!(r.image.hash(), expected.hash(), "{name} n={procs}");
        }
    }
}

#[test]
fn every_topology_that_routes_the_partners_runs_it() {
    let s = scene("spd-teapot.json");
    let (expected, _) = reference::render(&s.frame(0).unwrap());
    for (machine, set) in [
        (
            "multicluster-torus.json",
            vec![("machine.memory.capacity_per_node", "64MB")],
        ),
        ("delta.json", vec![]),
        ("snooping-bus.json", vec![]),
        (
            "multicluster-pipeline.json",
            vec![("machine.memory.capacity_per_node", "64MB")],
        ),
    ] {
        for procs in [6, 16] {
            let r = simulate(machine, &s, procs, &set);
            assert_eq!(r.image.hash(), expected.hash(), "{machine} n={procs}");
        }
    }
}

#[test]
fn a_frame_moves_the_closed_form() {
    let s = scene("spd-teapot.json");
    let frame = s.frame(0).unwrap();
    let area = u64::from(frame.width) * u64::from(frame.height);
    for procs in [2u64, 3, 8, 12, 16] {
        let r = simulate("denali-crossbar.json", &s, procs as u32, &[]);
        let f = &r.frames[0];
        let k = 1u64 << procs.ilog2();
        let rounds = u64::from(k.ilog2());
        // Fold: each of the N - k extra nodes sends its whole frame (A positions). Swap: each
        // of the k nodes sends half its piece per round, A/2 + A/4 + ... + A/k = A (1 - 1/k),
        // in log2 k messages. Gather: k - 1 pieces of A/k to node 0. A = 512^2 divides by k.
        let positions = (procs - k) * area + k * (area - area / k) + (k - 1) * (area / k);
        assert_eq!(
            f.bytes.get(),
            positions * FULL_FRAME_PIXEL_BYTES,
            "n={procs}"
        );
        assert_eq!(f.messages, (procs - k) + k * rounds + (k - 1), "n={procs}");
    }
}

#[test]
fn a_one_way_pipeline_cannot_carry_the_swaps() {
    let s = scene("spd-teapot.json");
    let Err(e) = run_frame0(
        "pixelflow-pipeline.json",
        &s,
        "sort-last/binary-swap",
        4,
        &[],
    ) else {
        panic!("a one-way pipeline ran binary swap");
    };
    let msg = e.to_string();
    assert!(
        msg.contains("sort-last/binary-swap") && msg.contains("no route"),
        "{msg}"
    );
}

/// The frame time of binary swap on the Delta at `fidelity`.
fn delta_frame_s(procs: u32, fidelity: &str) -> f64 {
    let s = scene("plb-head-standin.json");
    let r = simulate(
        "delta.json",
        &s,
        procs,
        &[("machine.network.fidelity", fidelity)],
    );
    r.frames[0].time().as_secs_f64()
}

#[test]
fn contention_shows_where_partners_routes_share_links() {
    // Two nodes on the Delta's mesh are neighbours: the one swap round sends 0 -> 1 and
    // 1 -> 0 on the two directions of one link, and the gather is one message, so no two
    // messages ever share a link and `flow` predicts exactly what `hops` does.
    assert_eq!(delta_frame_s(2, "flow"), delta_frame_s(2, "hops"));
    // Sixteen nodes form a 4x4 mesh. Round 1 pairs i with i xor 2, two columns apart in the
    // same row: 0 -> 2 crosses links 0->1 and 1->2, and 1 -> 3 crosses 1->2 and 2->3, so
    // both halves of every row share a link and `flow` halves their rates where `hops`
    // does not see it.
    let (flow, hops) = (delta_frame_s(16, "flow"), delta_frame_s(16, "hops"));
    assert!(flow > hops, "flow {flow} s, hops {hops} s");
}
