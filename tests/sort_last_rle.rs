//! `image=rle` (IceT's run-length sparse images) for the compositing variants: the image is
//! the sequential renderer's, as with dense pieces, and fewer bytes travel where frames are
//! sparse.

use crate::common;

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

fn direct_send(scene: &Arc<Scene>, procs: u32, image: &str) -> RunResult {
    run_frame0(
        "denali-crossbar.json",
        scene,
        "sort-last/direct-send",
        procs,
        &[("local-zbuffer", "on"), ("image", image)],
    )
    .unwrap_or_else(|e| panic!("direct send n={procs} image={image}: {e}"))
}

#[test]
fn direct_send_with_rle_gives_the_sequential_image() {
    for name in [
        "p003-roses.json",
        "spd-teapot.json",
        "plb-head-standin.json",
    ] {
        let s = scene(name);
        let (expected, _) = reference::render(&s.frame(0).unwrap());
        for procs in [1, 3, 8, 13] {
            let r = direct_send(&s, procs, "rle");
            assert_eq!(r.image.hash(), expected.hash(), "{name} n={procs}");
        }
    }
}

#[test]
fn direct_send_with_rle_trades_addresses_for_run_headers() {
    // Dense: every shipped pixel carries x and y (2 + 2 bytes) with its 7-byte record (11).
    // Rle: the same pixels as 7-byte records, plus an 8-byte header per run of consecutive
    // positions of the owner's rows, in as many messages. A header pays for itself when its
    // run is longer than two pixels (8 bytes against 4 of address each); each node z-buffers
    // a scattered quarter (or sixteenth) of the teapot, whose pixels measured 3.5 to a run at
    // 4 nodes.
    const DENSE: u64 = 11;
    const RECORD: u64 = 7;
    let s = scene("spd-teapot.json");
    for procs in [4, 16] {
        let (dense, rle) = (
            direct_send(&s, procs, "dense"),
            direct_send(&s, procs, "rle"),
        );
        let (d, r) = (&dense.frames[0], &rle.frames[0]);
        assert_eq!(d.messages, r.messages, "n={procs}");
        assert_eq!(d.bytes.get() % DENSE, 0);
        let shipped = d.bytes.get() / DENSE;
        let headers = r.bytes.get() - shipped * RECORD;
        assert_eq!(headers % 8, 0, "n={procs}: whole run headers");
        let runs = headers / 8;
        assert!(
            runs > 0 && runs * 2 < shipped,
            "n={procs}: {runs} runs for {shipped} pixels"
        );
        assert!(r.bytes < d.bytes, "n={procs}");
    }
}
