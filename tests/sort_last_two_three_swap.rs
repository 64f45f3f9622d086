//! sort-last/2-3-swap (Yu, Wang, Ma 2008): the image equals the sequential renderer's at any
//! node count, dense and rle, on several topologies; on N = 2^a 3^b a frame moves exactly the
//! closed form's bytes and messages; on powers of two it is binary swap's exchange.

use crate::common;

use std::sync::Arc;

use common::{run_frame0, scene};
use sortsim::algo::{reference, RunResult};
use sortsim::scene::Scene;

/// Bytes of a full-frame pixel when frames are merged: rgb and a 32-bit z.
const FULL_FRAME_PIXEL_BYTES: u64 = 7;

fn simulate(machine: &str, scene: &Arc<Scene>, procs: u32, set: &[(&str, &str)]) -> RunResult {
    run_frame0(machine, scene, "sort-last/2-3-swap", procs, set)
        .unwrap_or_else(|e| panic!("{machine} n={procs} {set:?}: {e}"))
}

#[test]
fn images_equal_the_sequential_image_at_any_node_count_dense_and_rle() {
    for name in [
        "p003-roses.json",
        "spd-teapot.json",
        "plb-head-standin.json",
    ] {
        let s = scene(name);
        let (expected, _) = reference::render(&s.frame(0).unwrap());
        for procs in [1, 2, 3, 5, 6, 7, 10, 12, 16, 27] {
            for image in ["dense", "rle"] {
                let r = simulate("denali-crossbar.json", &s, procs, &[("image", image)]);
                assert_eq!(r.image.hash(), expected.hash(), "{name} n={procs} {image}");
            }
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
        for procs in [6, 11] {
            let r = simulate(machine, &s, procs, &set);
            assert_eq!(r.image.hash(), expected.hash(), "{machine} n={procs}");
        }
    }
}

#[test]
fn a_frame_moves_the_closed_form_on_products_of_twos_and_threes() {
    let s = scene("spd-teapot.json");
    let frame = s.frame(0).unwrap();
    let area = u64::from(frame.width) * u64::from(frame.height);
    // (N, the group sizes its rounds join: pairs first, the first three together when the
    // number of groups is odd, so every join is of equal groups only for 2^a and 3 x 2^a).
    for (procs, joins) in [
        (2u64, vec![2u64]),
        (3, vec![3]),
        (6, vec![2, 3]),
        (8, vec![2, 2, 2]),
        (12, vec![2, 2, 3]),
        (24, vec![2, 2, 2, 3]),
    ] {
        let r = simulate("denali-crossbar.json", &s, procs as u32, &[]);
        let f = &r.frames[0];
        // A round joining j equal groups cuts every node's piece into j parts lying inside
        // it: the node keeps one and sends the other j - 1, one message each. So a node sends
        // everything but its final part, A - A/N positions, in sum(j - 1) messages, and the
        // N final parts tile the screen: (N - 1) A positions in all. Then N - 1 parts go to
        // node 0, which holds part 0 of A/N (rounded down).
        let swaps = (procs - 1) * area;
        let gather = area - area / procs;
        assert_eq!(
            f.bytes.get(),
            (swaps + gather) * FULL_FRAME_PIXEL_BYTES,
            "n={procs}"
        );
        let messages = procs * joins.iter().map(|j| j - 1).sum::<u64>() + (procs - 1);
        assert_eq!(f.messages, messages, "n={procs}");
    }
}

#[test]
fn any_node_count_sends_at_least_all_but_its_final_part() {
    let s = scene("spd-teapot.json");
    let frame = s.frame(0).unwrap();
    let area = u64::from(frame.width) * u64::from(frame.height);
    for procs in [5u64, 7, 9, 10, 18] {
        let r = simulate("denali-crossbar.json", &s, procs as u32, &[]);
        // Each node must hand on everything of the screen but its final part, whatever the
        // groups: (N - 1) A positions at least, then the gather.
        let least = (procs - 1) * area + (area - area / procs);
        let bytes = r.frames[0].bytes.get();
        assert!(
            bytes >= least * FULL_FRAME_PIXEL_BYTES,
            "n={procs}: {bytes} bytes"
        );
    }
}

#[test]
fn on_powers_of_two_it_moves_what_binary_swap_moves() {
    let s = scene("plb-head-standin.json");
    for procs in [2, 4, 8, 16] {
        let swap23 = simulate("denali-crossbar.json", &s, procs, &[]);
        let binary = run_frame0(
            "denali-crossbar.json",
            &s,
            "sort-last/binary-swap",
            procs,
            &[],
        )
        .unwrap();
        assert_eq!(swap23.frames[0].bytes, binary.frames[0].bytes, "n={procs}");
        assert_eq!(
            swap23.frames[0].messages, binary.frames[0].messages,
            "n={procs}"
        );
    }
}

#[test]
fn a_one_way_pipeline_cannot_carry_the_swaps() {
    let s = scene("spd-teapot.json");
    let Err(e) = run_frame0("pixelflow-pipeline.json", &s, "sort-last/2-3-swap", 5, &[]) else {
        panic!("a one-way pipeline ran 2-3 swap");
    };
    let msg = e.to_string();
    assert!(
        msg.contains("sort-last/2-3-swap") && msg.contains("no route"),
        "{msg}"
    );
}
