//! Scale: 32,768 simulated processes of the Blue Gene/P partition composite a 64-megapixel
//! image (issue 32: a run at the scale of Kendall et al.'s, in minutes and under 8 GB on a
//! 2-core machine; the wall time and memory are measured by hand and quoted in
//! docs/sweeps.md, not asserted here). What is asserted: the composited image is the
//! sequential renderer's, bit for bit, and binary swap sent exactly its messages.

mod common;

use common::{run_frame0, scene};
use sortsim::algo::reference;

#[test]
fn thirty_two_thousand_processes_composite_64_megapixels_to_the_sequential_image() {
    let s = scene("plb-head-64mp.json");
    let procs = 32_768u64;
    // A 64-megapixel frame buffer per process does not fit the quarter of a 2 GB node each
    // of four processes has; the run gives each 1 GiB (paper 004's bounding boxes are what
    // let the real runs fit).
    let r = run_frame0(
        "bgp-intrepid-8k.json",
        &s,
        "sort-last/binary-swap",
        procs as u32,
        &[
            ("image", "rle"),
            ("machine.memory.capacity_per_node", "1GiB"),
        ],
    )
    .expect("the run completes");
    let (expected, _) = reference::render(&s.frame(0).unwrap());
    assert_eq!(r.image.hash(), expected.hash(), "the composited image");
    // 15 swap rounds of one message each, then every process but 0 sends its piece to 0.
    let messages: u64 = r.stats.nodes.iter().map(|n| n.messages_sent).sum();
    assert_eq!(messages, procs * 15 + procs - 1);
}
