//! sort-last/tree (IceT's reduce tree): the image equals the sequential renderer's at every
//! node count (powers of two or not) on several topologies, and a frame moves exactly N - 1
//! full frames.

use crate::common;

use std::sync::Arc;

use common::{run_frame0, scene};
use sortsim::algo::{reference, RunError, RunResult};
use sortsim::scene::Scene;

/// Bytes of a full-frame pixel when frames are merged: rgb and a 32-bit z.
const FULL_FRAME_PIXEL_BYTES: u64 = 7;

fn simulate(
    machine: &str,
    scene: &Arc<Scene>,
    procs: u32,
    set: &[(&str, &str)],
) -> Result<RunResult, RunError> {
    run_frame0(machine, scene, "sort-last/tree", procs, set)
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
        for procs in [1, 2, 3, 5, 8, 13, 16] {
            let r = simulate("denali-crossbar.json", &s, procs, &[]).unwrap();
            assert_eq!(r.image.hash(), expected.hash(), "{name} n={procs}");
            assert_eq!(r.frames.len(), 1, "frame 0 only");
        }
    }
}

#[test]
fn every_topology_that_routes_the_pairs_runs_it() {
    let s = scene("spd-teapot.json");
    let (expected, _) = reference::render(&s.frame(0).unwrap());
    for (machine, set) in [
        (
            "multicluster-torus.json",
            vec![("machine.memory.capacity_per_node", "64MB")],
        ),
        ("delta.json", vec![]),
        ("snooping-bus.json", vec![]),
    ] {
        for procs in [6, 16] {
            let r = simulate(machine, &s, procs, &set).unwrap();
            assert_eq!(r.image.hash(), expected.hash(), "{machine} n={procs}");
        }
    }
}

#[test]
fn a_frame_moves_n_minus_one_full_frames() {
    let s = scene("spd-teapot.json");
    let frame = s.frame(0).unwrap();
    let area = u64::from(frame.width) * u64::from(frame.height);
    for procs in [2, 3, 7, 16] {
        let r = simulate("denali-crossbar.json", &s, procs, &[]).unwrap();
        let f = &r.frames[0];
        // Every merge receives one whole frame (A pixels of rgb + z, however few are
        // active) in one message: (N - 1) A pixels and N - 1 messages in all.
        let n = u64::from(procs);
        assert_eq!(f.messages, n - 1, "n={procs}");
        assert_eq!(
            f.bytes.get(),
            (n - 1) * area * FULL_FRAME_PIXEL_BYTES,
            "n={procs}"
        );
    }
}

#[test]
fn a_pipeline_cannot_send_frames_back_up_the_tree() {
    let s = scene("spd-teapot.json");
    match simulate("pixelflow-pipeline.json", &s, 4, &[]) {
        Err(e) => {
            let msg = e.to_string();
            assert!(
                msg.contains("sort-last/tree") && msg.contains("route"),
                "{msg}"
            );
        }
        Ok(_) => panic!("a one-way pipeline ran the tree"),
    }
}
