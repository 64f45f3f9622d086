//! sort-last/radix-k (Peterka, Goodell, Ross, Shen, Thakur 2009): the image equals the
//! sequential renderer's for any node count and any factorization, a frame moves exactly the
//! closed form's bytes and messages, and a factorization that does not multiply to the node
//! count is refused with what would be valid.

mod common;

use std::process::Command;
use std::sync::Arc;

use common::{root, run_frame0, scene};
use sortsim::algo::{reference, RunResult};
use sortsim::scene::Scene;

/// Bytes of a full-frame pixel when frames are merged: rgb and a 32-bit z.
const FULL_FRAME_PIXEL_BYTES: u64 = 7;

fn simulate(machine: &str, scene: &Arc<Scene>, procs: u32, set: &[(&str, &str)]) -> RunResult {
    run_frame0(machine, scene, "sort-last/radix-k", procs, set)
        .unwrap_or_else(|e| panic!("{machine} n={procs} {set:?}: {e}"))
}

#[test]
fn images_equal_the_sequential_image_for_any_factorization() {
    for name in [
        "p003-roses.json",
        "spd-teapot.json",
        "plb-head-standin.json",
    ] {
        let s = scene(name);
        let (expected, _) = reference::render(&s.frame(0).unwrap());
        for (procs, k) in [
            (1, "auto"),
            (2, "auto"),
            (3, "auto"),
            (12, "auto"),
            (12, "2,3,2"),
            (13, "auto"),
            (16, "2,2,2,2"),
            (16, "16"),
            (32, "auto"),
            (32, "4,4,2"),
        ] {
            let r = simulate("denali-crossbar.json", &s, procs, &[("k", k)]);
            assert_eq!(r.image.hash(), expected.hash(), "{name} n={procs} k={k}");
        }
    }
    let s = scene("spd-teapot.json");
    let (expected, _) = reference::render(&s.frame(0).unwrap());
    let r = simulate("delta.json", &s, 24, &[]);
    assert_eq!(r.image.hash(), expected.hash(), "delta n=24");
}

#[test]
fn a_frame_moves_the_closed_form() {
    let s = scene("spd-teapot.json");
    let frame = s.frame(0).unwrap();
    let area = u64::from(frame.width) * u64::from(frame.height);
    for (procs, radices) in [
        (8u64, vec![8u64]),
        (16, vec![4, 4]),
        (32, vec![4, 4, 2]),
        (64, vec![8, 8]),
    ] {
        let k: Vec<String> = radices.iter().map(u64::to_string).collect();
        let r = simulate(
            "denali-crossbar.json",
            &s,
            procs as u32,
            &[("k", &k.join(","))],
        );
        let f = &r.frames[0];
        // Before the gather every node sends A (1 - 1/N) positions in sum(k_i - 1)
        // messages; the gather sends N - 1 pieces of A/N. A = 512^2 divides by every N here.
        let positions = procs * (area - area / procs) + (procs - 1) * (area / procs);
        assert_eq!(
            f.bytes.get(),
            positions * FULL_FRAME_PIXEL_BYTES,
            "n={procs}"
        );
        let per_node: u64 = radices.iter().map(|k| k - 1).sum();
        assert_eq!(f.messages, procs * per_node + procs - 1, "n={procs}");
    }
}

#[test]
fn group_sizes_that_do_not_multiply_to_the_node_count_are_refused() {
    let out = Command::new(env!("CARGO_BIN_EXE_sortsim"))
        .args([
            "run",
            "--machine",
            root()
                .join("machines/denali-crossbar.json")
                .to_str()
                .unwrap(),
            "--scene",
            root().join("scenes/spd-teapot.json").to_str().unwrap(),
            "--algo",
            "sort-last/radix-k",
            "--procs",
            "12",
            "--set",
            "k=4,4",
            "--no-timeline",
        ])
        .output()
        .unwrap();
    common::assert_refused(
        &out,
        "k=4,4 on 12",
        "product is the number of processors, 12",
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("4,4 multiply to 16") && stderr.contains("6,2"),
        "{stderr}"
    );
}
