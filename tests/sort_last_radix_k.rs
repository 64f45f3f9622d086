//! sort-last/radix-k (Peterka, Goodell, Ross, Shen, Thakur 2009): the image equals the
//! sequential renderer's for any node count and any factorization, a frame moves exactly the
//! closed form's bytes and messages, and a factorization that does not multiply to the node
//! count is refused with what would be valid.

use crate::common;

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

/// A round's pieces are merged as they arrive, as IceT's radix-k does with a wait-any, not
/// in the order of the group's members. Three processors in one round of 3: processor 0
/// draws a triangle over the whole screen at 1 us a pixel, 1 and 2 a pixel's worth each, so
/// 0's pieces arrive last. Processor 1 has 2's piece early and merges it while 0 still
/// draws; once 0's piece is in, one merge is left, where member order (0 before 2) would
/// leave two.
#[test]
fn a_round_merges_its_pieces_as_they_arrive() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("late.obj"),
        "v 0 0 0.5 1 0 0\nv 200 0 0.5 1 0 0\nv 0 200 0.5 1 0 0\n\
         v 1 1 0.2 0 1 0\nv 2 1 0.2 0 1 0\nv 1 2 0.2 0 1 0\n\
         v 5 5 0.2 0 0 1\nv 6 5 0.2 0 0 1\nv 5 6 0.2 0 0 1\n\
         f 1 2 3\nf 4 5 6\nf 7 8 9\n",
    )
    .unwrap();
    let scene_file = dir.path().join("late.json");
    std::fs::write(
        &scene_file,
        r#"{"resolution": [96, 96], "frames": 1, "camera": {"kind": "screen"},
            "cull_backfaces": false, "geometry": [{"obj": "late.obj"}]}"#,
    )
    .unwrap();
    let s = Arc::new(Scene::load(&scene_file).unwrap());
    let composite_pixel = 1_000_000u64; // ps
    let r = simulate(
        "denali-crossbar.json",
        &s,
        3,
        &[
            ("k", "3"),
            ("gather", "off"),
            ("machine.cpu.costs.pixel_write", "1us"),
            ("machine.cpu.costs.composite_pixel", "1us"),
        ],
    );
    let f = &r.frames[0];
    let drawn = |p: usize| f.raster_finish[p].ps();
    assert!(drawn(0) > drawn(1).max(drawn(2)), "processor 0 draws last");
    // Processor 1 keeps positions A/3..2A/3 of the raster order: 3,072 positions a merge.
    let merge = 96 * 96 / 3 * composite_pixel;
    assert!(
        drawn(0) - drawn(2) > 2 * merge,
        "2's piece arrives well before 0's is drawn"
    );
    let after_last = r.stats.nodes[1].finish.ps() - drawn(0);
    assert!(
        (merge..2 * merge).contains(&after_last),
        "processor 1 ends {after_last} ps after 0 has drawn; one merge is {merge} ps"
    );
}
