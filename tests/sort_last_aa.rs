//! Anti-aliasing in the sort-last family (`aa=supersample:N`): nodes render and merge
//! samples, so every image equals the sequential render on the same sample grid resolved by
//! the box filter, and the traffic of the merges grows with the samples they move.

mod common;

use std::collections::BTreeMap;
use std::sync::Arc;

use common::root;

use sortsim::algo::{reference, run, RunError, RunResult};
use sortsim::raster::aa::downsample;
use sortsim::raster::{draw_mesh, Framebuffer, Viewport};
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

/// The sequential render of frame 0 on a grid `side` times finer, resolved.
fn supersampled_reference(scene: &Scene, side: u32) -> Framebuffer {
    let frame = scene.frame(0).unwrap();
    let screen = reference::viewport(&frame);
    let grid = Viewport::new(screen.width() * side, screen.height() * side).unwrap();
    let mut fb = Framebuffer::with_clear(grid, frame.background);
    draw_mesh(
        &frame.vertices,
        &frame.triangles,
        grid,
        &reference::raster_options(&frame),
        &mut fb,
    );
    downsample(&fb, side)
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
fn the_sample_grid_resolves_like_the_supersample_target() {
    // Both routes sample at the same positions ((i + 1/2) / k of a pixel): sort-last renders
    // a grid k times finer, sort-middle's SupersampleTarget keeps k x k cells per pixel. They
    // are not bit-identical: the fine grid snaps vertices to 1/256 of a sample instead of a
    // pixel (a few edge samples flip) and interpolates colour at every sample. Measured on
    // the teapot at 2x2: 0.68% of pixels more than one level apart, 0.016% more than eight.
    let name = "spd-teapot.json";
    let scene = Arc::new(Scene::load(&root().join("scenes").join(name)).unwrap());
    let frame = scene.frame(0).unwrap();
    let screen = reference::viewport(&frame);
    let mut target =
        sortsim::raster::aa::SupersampleTarget::full_screen(screen, 2, frame.background);
    draw_mesh(
        &frame.vertices,
        &frame.triangles,
        screen,
        &reference::raster_options(&frame),
        &mut target,
    );
    let mut fb = Framebuffer::new(screen);
    target.resolve_into(&mut fb, &mut Default::default());
    let grid = supersampled_reference(&scene, 2);
    let diff = |a: &[u8; 3], b: &[u8; 3]| (0..3).map(|c| a[c].abs_diff(b[c])).max().unwrap();
    let diffs: Vec<u8> = fb
        .colors()
        .iter()
        .zip(grid.colors())
        .map(|(a, b)| diff(a, b))
        .collect();
    let max = diffs.iter().copied().max().unwrap();
    let over1 = diffs.iter().filter(|&&d| d > 1).count();
    let over8 = diffs.iter().filter(|&&d| d > 8).count();
    let n = diffs.len() as f64;
    assert!(
        max > 0,
        "the routes differ somewhere (else this test should demand equality)"
    );
    // Tolerances: 1% of pixels beyond one level, 0.05% beyond eight (about 3x the measured).
    assert!(
        (over1 as f64) < 0.01 * n,
        "{over1} pixels more than one level apart"
    );
    assert!(
        (over8 as f64) < 0.0005 * n,
        "{over8} pixels more than eight levels apart"
    );
}
