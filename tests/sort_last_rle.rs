//! `image=rle` (IceT's run-length sparse images) for the compositing variants: the image is
//! the sequential renderer's, as with dense pieces, and fewer bytes travel where frames are
//! sparse.

mod common;

use std::sync::Arc;

use common::{run_frame0, scene};
use sortsim::algo::{reference, RunResult};
use sortsim::scene::Scene;

fn simulate(scene: &Arc<Scene>, algo: &str, procs: u32, image: &str) -> RunResult {
    run_frame0(
        "denali-crossbar.json",
        scene,
        algo,
        procs,
        &[("image", image)],
    )
    .unwrap_or_else(|e| panic!("{algo} n={procs} image={image}: {e}"))
}

const COMPOSITES: [&str; 3] = [
    "sort-last/tree",
    "sort-last/binary-swap",
    "sort-last/radix-k",
];

#[test]
fn rle_pieces_give_the_sequential_image() {
    for name in [
        "p003-roses.json",
        "spd-teapot.json",
        "plb-head-standin.json",
    ] {
        let s = scene(name);
        let (expected, _) = reference::render(&s.frame(0).unwrap());
        for algo in COMPOSITES {
            for procs in [1, 3, 8, 13] {
                let r = simulate(&s, algo, procs, "rle");
                assert_eq!(r.image.hash(), expected.hash(), "{name} {algo} n={procs}");
            }
        }
    }
}

#[test]
fn rle_moves_fewer_bytes_in_as_many_messages_where_frames_are_sparse() {
    // The teapot covers about a third of the screen; each node's share far less.
    let s = scene("spd-teapot.json");
    for algo in COMPOSITES {
        let (dense, rle) = (simulate(&s, algo, 8, "dense"), simulate(&s, algo, 8, "rle"));
        let (d, r) = (&dense.frames[0], &rle.frames[0]);
        assert_eq!(d.messages, r.messages, "{algo}");
        assert!(
            2 * r.bytes.get() < d.bytes.get(),
            "{algo}: rle {} dense {}",
            r.bytes,
            d.bytes
        );
    }
}
