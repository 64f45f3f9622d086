//! Anti-aliasing across the families (`aa=supersample:N`): sort-last nodes render each
//! pixel's samples as the sequential supersampling buffer does and merge them sample by
//! sample, so every algorithm's image equals `sortsim render --aa supersample:N`, and the
//! traffic of the merges grows with the samples they move.

use crate::common;

use std::collections::BTreeMap;
use std::sync::Arc;

use common::root;

use sortsim::algo::{reference, run, RunError, RunResult};
use sortsim::raster::aa::AaMethod;
use sortsim::raster::Framebuffer;
use sortsim::scene::Scene;
use sortsim::spec::run::RunSpec;

fn simulate(
    scene: &Arc<Scene>,
    algo: &str,
    procs: u32,
    aa: Option<&str>,
    extra: &[(&str, &str)],
) -> Result<RunResult, RunError> {
    let mut set = extra.to_vec();
    if let Some(aa) = aa {
        set.push(("aa", aa));
    }
    common::run_sort_last(scene, algo, procs, None, &set)
}

/// The sequential supersampled render of frame 0 (`sortsim render --aa supersample:N`).
fn supersampled_reference(scene: &Scene, side: u32) -> Framebuffer {
    let frame = scene.frame(0).unwrap();
    reference::render_aa(&frame, AaMethod::Supersample { side }).0
}

const ALGOS: [&str; 9] = [
    "sort-last/df",
    "sort-last/pc",
    "sort-last/scanline-flow",
    "sort-last/pixelflow",
    "sort-last/direct-send",
    "sort-last/snooping",
    "sort-last/tree",
    "sort-last/binary-swap",
    "sort-last/radix-k",
];

#[test]
fn every_sort_last_algorithm_merges_samples_into_the_supersampled_image() {
    let name = "spd-teapot.json";
    let scene = Arc::new(Scene::load(&root().join("scenes").join(name)).unwrap());
    let expected = supersampled_reference(&scene, 2);
    let aliased = reference::render(&scene.frame(0).unwrap()).0;
    assert_ne!(
        expected.hash(),
        aliased.hash(),
        "anti-aliasing changes edge pixels"
    );
    for algo in ALGOS {
        for procs in [1, 4] {
            let r = simulate(&scene, algo, procs, Some("supersample:4"), &[])
                .unwrap_or_else(|e| panic!("{algo} n={procs}: {e}"));
            assert_eq!(r.image.width(), expected.width(), "{algo}: resolved size");
            assert_eq!(
                r.image.hash(),
                expected.hash(),
                "{algo} n={procs}: image differs from the supersampled sequential render"
            );
        }
    }
}

#[test]
fn merge_traffic_grows_with_the_samples_moved() {
    let name = "p003-cube.json";
    let scene = Arc::new(Scene::load(&root().join("scenes").join(name)).unwrap());
    let bytes = |algo: &str, aa: Option<&str>, extra: &[(&str, &str)]| -> u64 {
        let r = simulate(&scene, algo, 4, aa, extra).unwrap();
        r.frames.iter().map(|f| f.bytes.get()).sum()
    };
    // PixelFlow streams whole frames: every sample of every frame, so exactly N times the
    // aliased traffic (paper 003's n*A with A counted in samples).
    let plain = bytes("sort-last/pixelflow", None, &[]);
    let four = bytes("sort-last/pixelflow", Some("supersample:4"), &[]);
    assert_eq!(
        four,
        4 * plain,
        "pixelflow: 4 samples per pixel move 4x the bytes"
    );
    // Direct send without a local z-buffer moves every fragment, now every covered sample:
    // about N times as many (edges make it not exact); 3.5x to 4.5x for N = 4.
    let plain = bytes("sort-last/direct-send", None, &[]) as f64;
    let four = bytes("sort-last/direct-send", Some("supersample:4"), &[]) as f64;
    let ratio = four / plain;
    assert!((3.5..=4.5).contains(&ratio), "direct send: {ratio:.3}x");
}

#[test]
fn t800_memory_cannot_hold_a_frame_of_samples() {
    // A 512x512 frame of 4 samples per pixel at 7 bytes a sample is 7.3 MB: more than a
    // MultiCluster node's 4 MB (paper 001), so the machine refuses it for lack of memory.
    let name = "spd-teapot.json";
    let scene = Arc::new(Scene::load(&root().join("scenes").join(name)).unwrap());
    let spec = RunSpec {
        schema: None,
        machine: root().join("machines/multicluster-pipeline.json"),
        scene: root().join("scenes").join(name),
        algo: "sort-last/pc".into(),
        procs: 2,
        frames: None,
        seed: 1,
        set: BTreeMap::from([("aa".to_string(), "supersample:4".to_string())]),
    };
    let cfg = spec.resolve(Some(scene)).unwrap();
    let err = run(&cfg).err().expect("a 7.3 MB frame does not fit 4 MB");
    assert!(
        matches!(err, RunError::Sim(sortsim::engine::SimError::Memory { .. })),
        "{err}"
    );
}

#[test]
fn every_algorithm_reproduces_the_sequential_supersampled_render() {
    // One meaning of supersample:N for every family: the N samples of each pixel at the same
    // positions, with the same depths and colour, box filtered (`sortsim render --aa`).
    // Sort-last nodes draw them with the sequential buffer's rule and merge them as samples.
    let scene = common::scene("spd-teapot.json");
    let frame = scene.frame(0).unwrap();
    let expected = reference::render_aa(&frame, AaMethod::Supersample { side: 2 }).0;
    let mut algos: Vec<(&str, &str, Vec<u32>)> = ALGOS
        .iter()
        .map(|&a| (a, common::sort_last_machine(a).0, vec![1, 3]))
        .collect();
    algos.push(("sort-last/2-3-swap", "snooping-bus.json", vec![1, 3]));
    for a in [
        "sort-middle/static",
        "sort-middle/ellsworth",
        "sort-first/mueller",
    ] {
        algos.push((a, "delta.json", vec![1, 3, 13]));
    }
    for (algo, machine, counts) in algos {
        for procs in counts {
            let r = if algo.starts_with("sort-last") {
                simulate(&scene, algo, procs, Some("supersample:4"), &[])
            } else {
                common::run_frame0(machine, &scene, algo, procs, &[("aa", "supersample:4")])
            }
            .unwrap_or_else(|e| panic!("{algo} n={procs}: {e}"));
            assert_eq!(
                r.image.hash(),
                expected.hash(),
                "{algo} n={procs}: image differs from sortsim render --aa supersample:4"
            );
        }
    }
}

#[test]
fn every_algorithm_reproduces_the_sequential_adaptive_render_unless_a_pool_runs_out() {
    // Paper 000's buffer with enough Subpixels is one image at any processor count; with each
    // processor's fixed pool (the default, 2 x 2 for its own pixels) an uneven split runs
    // some pools dry, and only then may a pixel differ: it is sampled once and counted.
    let scene = common::scene("plb-head-standin.json");
    let frame = scene.frame(0).unwrap();
    let expected = reference::render_aa(&frame, AaMethod::Adaptive).0;
    let overflowed = |r: &RunResult| -> u64 {
        r.frames
            .iter()
            .flat_map(|f| &f.aa)
            .map(|s| s.overflowed_pixels)
            .sum()
    };
    let mut algos: Vec<&str> = ALGOS.to_vec();
    algos.extend([
        "sort-last/2-3-swap",
        "sort-middle/static",
        "sort-middle/ellsworth",
        "sort-first/mueller",
    ]);
    let mut fell_back = 0;
    for algo in algos {
        for (pool, procs) in [("8MB", 3), ("8MB", 13), ("", 13)] {
            let mut set = vec![
                ("aa", "adaptive"),
                ("machine.memory.capacity_per_node", "64MB"),
            ];
            if !pool.is_empty() {
                set.push(("aa-pool", pool));
            }
            let r = if algo.starts_with("sort-last") {
                common::run_sort_last(&scene, algo, procs, Some("0"), &set)
            } else {
                common::run_frame0("delta.json", &scene, algo, procs, &set)
            }
            .unwrap_or_else(|e| panic!("{algo} n={procs} pool {pool:?}: {e}"));
            let lost = overflowed(&r);
            if lost == 0 {
                assert_eq!(
                    r.image.hash(),
                    expected.hash(),
                    "{algo} n={procs} pool {pool:?}: no pixel fell back, yet the image differs \
                     from sortsim render --aa adaptive"
                );
            } else {
                assert!(pool.is_empty(), "{algo} n={procs}: an 8 MB pool ran out");
                fell_back += 1;
            }
        }
    }
    assert!(
        fell_back > 0,
        "some default pool runs out at 13 processors (else this test no longer shows why runs differ)"
    );
}
