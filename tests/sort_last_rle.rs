//! `image=rle` (IceT's run-length sparse images) for the compositing variants: the image is
//! the sequential renderer's, as with dense pieces, and fewer bytes travel where frames are
//! sparse.

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;

use sortsim::algo::{reference, run, RunResult};
use sortsim::scene::Scene;
use sortsim::spec::run::RunSpec;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn scene(name: &str) -> Arc<Scene> {
    Arc::new(Scene::load(&root().join("scenes").join(name)).unwrap())
}

fn simulate(scene: &Arc<Scene>, algo: &str, procs: u32, image: &str) -> RunResult {
    let spec = RunSpec {
        schema: None,
        machine: root().join("machines/denali-crossbar.json"),
        scene: scene.file().to_path_buf(),
        algo: algo.into(),
        procs,
        frames: Some("0".into()),
        seed: 1,
        set: BTreeMap::from([("image".to_string(), image.to_string())]),
    };
    let cfg = spec.resolve(Some(scene.clone())).expect("valid run spec");
    run(&cfg).unwrap_or_else(|e| panic!("{algo} n={procs} image={image}: {e}"))
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
