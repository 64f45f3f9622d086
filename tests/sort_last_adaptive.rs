//! Adaptive anti-aliasing in the sort-last family (`aa=adaptive`, paper 000's buffer on every
//! node): merges move super pixels with their Subpixels and combine them sample by sample,
//! so images follow the sequential adaptive render, traffic grows with the super pixels
//! moved, and the nodes' fixed pools bound what a frame may supersample.

use crate::common;

use std::sync::Arc;

use common::{root, run_sort_last};
use sortsim::algo::{reference, run};
use sortsim::raster::aa::{AdaptiveConfig, AdaptiveTarget, Grid, PIXEL_BYTES, SUBPIXEL_BYTES};
use sortsim::raster::{draw_mesh, Framebuffer};
use sortsim::scene::Scene;
use sortsim::spec::run::RunSpec;

fn scene(name: &str) -> Arc<Scene> {
    Arc::new(Scene::load(&root().join("scenes").join(name)).unwrap())
}

/// Frame `frame` rendered sequentially into one adaptive buffer (4x4, default pool,
/// reclaiming off), resolved.
fn sequential_adaptive(scene: &Scene, frame: u32) -> Framebuffer {
    let g = scene.frame(frame).unwrap();
    let vp = reference::viewport(&g);
    let config = AdaptiveConfig {
        reclaim_spread: None,
        ..AdaptiveConfig::for_pixels(vp.pixels() as u64)
    };
    let mut target = AdaptiveTarget::full_screen(vp, config, g.background);
    draw_mesh(
        &g.vertices,
        &g.triangles,
        vp,
        &reference::raster_options(&g),
        &mut target,
    );
    let mut fb = Framebuffer::with_clear(vp, g.background);
    target.resolve_into(&mut fb, &mut Default::default());
    fb
}

/// Pixels whose colour differs by more than `levels` in some channel.
fn differing(a: &Framebuffer, b: &Framebuffer, levels: u8) -> usize {
    a.colors()
        .iter()
        .zip(b.colors())
        .filter(|(p, q)| (0..3).any(|c| p[c].abs_diff(q[c]) > levels))
        .count()
}

/// Every (algorithm, options) pair that merges adaptive pixels.
const RUNS: [(&str, &[(&str, &str)]); 10] = [
    ("sort-last/df", &[]),
    ("sort-last/pc", &[]),
    ("sort-last/scanline-flow", &[]),
    ("sort-last/pixelflow", &[]),
    ("sort-last/direct-send", &[]),
    ("sort-last/direct-send", &[("local-zbuffer", "on")]),
    ("sort-last/snooping", &[]),
    ("sort-last/tree", &[]),
    ("sort-last/binary-swap", &[]),
    ("sort-last/radix-k", &[]),
];

/// Without reclaiming (which depends on the order triangles arrive) and with blocks to
/// spare, merging the nodes' adaptive buffers sample by sample gives the sequential adaptive
/// image: exactly on one node, and on several nodes up to the one thing a merge cannot know,
/// the exact plane depth of a plain pixel. The shipped Pixel holds z rounded to a raw unit,
/// so a pixel expanded at the receiver can put a sample one raw unit away from where one
/// buffer would; that decides near-ties only, where two faces of a tetrahedron meet at a
/// silhouette edge (measured: teapot and letter B exact at 3 and 8 nodes; 500 tetrahedra at
/// most 25 of 262,144 pixels).
#[test]
fn merged_adaptive_images_follow_the_sequential_adaptive_render() {
    for name in [
        "spd-teapot.json",
        "p000-tetra-500.json",
        "p000-letter-b.json",
    ] {
        let scene = scene(name);
        let expected = sequential_adaptive(&scene, 0);
        let pixels = expected.colors().len();
        for (algo, opts) in RUNS {
            for procs in [1, 3, 8] {
                let mut set = vec![("aa", "adaptive"), ("aa-reclaim", "off")];
                set.extend_from_slice(opts);
                let r = run_sort_last(&scene, algo, procs, Some("0"), &set).unwrap();
                let what = format!("{name} {algo} {opts:?} n={procs}");
                let overflowed: u64 = r.frames[0].aa.iter().map(|a| a.overflowed_pixels).sum();
                assert_eq!(overflowed, 0, "{what}: blocks to spare");
                let off = differing(&r.image, &expected, 0);
                if procs == 1 || name != "p000-tetra-500.json" {
                    assert_eq!(off, 0, "{what}");
                } else {
                    // Tolerance: 0.02% of the pixels (measured at most 0.0095%).
                    assert!(off * 5_000 <= pixels, "{what}: {off} pixels differ");
                }
            }
        }
    }
}

/// PixelFlow moves every pixel's 12-byte Pixel record down each link, and a super pixel's
/// n x n Subpixels (7 bytes each) with it: a link out of node i carries node i's merged
/// frame, whose super pixels are the blocks in use in node i's pool (no block is ever
/// given back within a frame without reclaiming). The sum is exact.
#[test]
fn pixelflow_traffic_is_every_pixel_record_plus_every_super_pixels_samples() {
    let teapot = scene("spd-teapot.json");
    for procs in [1, 4] {
        let set = [("aa", "adaptive"), ("aa-reclaim", "off")];
        let r = run_sort_last(&teapot, "sort-last/pixelflow", procs, Some("0"), &set).unwrap();
        let f = &r.frames[0];
        let expected: u64 =
            f.aa.iter()
                .map(|a| a.pixels * PIXEL_BYTES + a.live_cells * SUBPIXEL_BYTES)
                .sum();
        assert_eq!(f.bytes.get(), expected, "n={procs}");
        assert!(f.aa.iter().all(|a| a.live_super_pixels > 0), "n={procs}");
    }
}

/// Traffic grows with the samples merges move: aliased < adaptive < 16 samples everywhere,
/// and an adaptive frame costs more simulated time than an aliased one (its coverage masks,
/// subpixel tests and resolves are priced).
#[test]
fn traffic_and_time_grow_with_anti_aliasing() {
    let teapot = scene("spd-teapot.json");
    for (algo, opts) in RUNS {
        let run = |aa: &str| {
            let mut set = vec![("aa", aa)];
            set.extend_from_slice(opts);
            let r = run_sort_last(&teapot, algo, 4, Some("0"), &set).unwrap();
            (r.frames[0].bytes.get(), r.frames[0].end - r.frames[0].start)
        };
        let (none, adaptive, sixteen) = (run("none"), run("adaptive"), run("supersample:16"));
        let what = format!("{algo} {opts:?}");
        assert!(
            none.0 < adaptive.0 && adaptive.0 < sixteen.0,
            "{what}: bytes"
        );
        assert!(none.1 < adaptive.1, "{what}: time {none:?} {adaptive:?}");
        // A sparse merge ships each pixel's address with a 12-byte record instead of an
        // 11-byte active pixel: at least 16/11 of the aliased traffic.
        assert!(
            adaptive.0 * 11 >= none.0 * 16,
            "{what}: {none:?} {adaptive:?}"
        );
    }
}

/// One subpixel resolution per frame for the whole machine (merges combine samples
/// position by position); a pool too small for 4x4 overflows in the first frame, and the
/// next frame runs coarser on every node and overflows less.
#[test]
fn every_node_renders_a_frame_at_one_grid_and_a_small_pool_adapts_it() {
    let tetra = scene("p000-tetra-500.json");
    let set = [("aa", "adaptive"), ("aa-pool", "1MB")];
    let r = run_sort_last(&tetra, "sort-last/pixelflow", 4, Some("0..3"), &set).unwrap();
    let grids: Vec<Vec<u32>> = r
        .frames
        .iter()
        .map(|f| f.aa.iter().map(|a| a.grid_side).collect())
        .collect();
    for g in &grids {
        assert!(g.iter().all(|&s| s == g[0]), "{grids:?}");
    }
    let overflowed = |k: usize| -> u64 { r.frames[k].aa.iter().map(|a| a.overflowed_pixels).sum() };
    assert_eq!(grids[0][0], Grid::X4.side());
    assert!(
        overflowed(0) > 0,
        "a 1 MB pool cannot hold 4x4 blocks for every edge pixel"
    );
    assert!(grids[1][0] < 4, "{grids:?}");
    assert!(
        overflowed(1) < overflowed(0),
        "{} {}",
        overflowed(1),
        overflowed(0)
    );
}

/// A pool of zero bytes samples every pixel once on every node and at every merge: no
/// panic, no super pixel, and the image is the aliased run's.
#[test]
fn a_pool_of_zero_bytes_gives_the_aliased_image() {
    let teapot = scene("spd-teapot.json");
    for (algo, opts) in RUNS {
        let mut set = vec![("aa", "adaptive"), ("aa-pool", "0B")];
        set.extend_from_slice(opts);
        let adaptive = run_sort_last(&teapot, algo, 4, Some("0"), &set).unwrap();
        let aliased = run_sort_last(&teapot, algo, 4, Some("0"), opts).unwrap();
        assert_eq!(
            adaptive.image.colors(),
            aliased.image.colors(),
            "{algo} {opts:?}"
        );
        let f = &adaptive.frames[0];
        assert!(f.aa.iter().all(|a| a.live_cells == 0), "{algo} {opts:?}");
    }
}

/// A T800's 4 MB holds a 512x512 frame of 12-byte Pixels (3 MiB) but not with paper 000's
/// default pool (2x2 for every pixel, 7 MiB more): the run stops with a memory error; a
/// 512 KiB pool fits, and the frame then runs at a coarser grid or overflows, as counted.
#[test]
fn a_t800_holds_the_pixels_only_with_a_small_pool() {
    let teapot = scene("spd-teapot.json");
    let spec = |set: &[(&str, &str)]| RunSpec {
        schema: None,
        machine: root().join("machines/multicluster-pipeline.json"),
        scene: teapot.file().to_path_buf(),
        algo: "sort-last/pc".into(),
        procs: 4,
        frames: Some("0".into()),
        seed: 1,
        set: set
            .iter()
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect(),
    };
    let cfg = spec(&[("aa", "adaptive")])
        .resolve(Some(teapot.clone()))
        .unwrap();
    let Err(err) = run(&cfg) else {
        panic!("a default pool does not fit a T800")
    };
    let err = err.to_string();
    assert!(
        err.contains("subpixel pool") || err.contains("memory"),
        "{err}"
    );
    let cfg = spec(&[("aa", "adaptive"), ("aa-pool", "512KiB")])
        .resolve(Some(teapot.clone()))
        .unwrap();
    let r = run(&cfg).unwrap();
    assert!(r.frames[0]
        .aa
        .iter()
        .all(|a| a.pool_cells == 512 * 1024 / SUBPIXEL_BYTES));
}

/// Identical inputs give byte-identical reports: the merges' pools, the frame's grid and
/// the per-node statistics follow the (time, sequence) order only.
#[test]
fn adaptive_sort_last_reports_are_byte_identical() {
    let dirs = [common::scratch("a"), common::scratch("b")];
    let out = |k: u32| dirs[k as usize].to_path_buf();
    for k in 0..2 {
        let status = std::process::Command::new(env!("CARGO_BIN_EXE_sortsim"))
            .args([
                "run",
                "--machine",
                "machines/denali-crossbar.json",
                "--scene",
                "scenes/p000-tetra-500.json",
                "--algo",
                "sort-last/direct-send",
                "--procs",
                "6",
                "--frames",
                "0..3",
                "--set",
                "aa=adaptive",
                "--set",
                "aa-pool=2MB",
                "-o",
            ])
            .arg(out(k))
            .current_dir(root())
            .status()
            .unwrap();
        assert!(status.success());
    }
    for file in ["summary.json", "summary.md", "frame-0002.png"] {
        let a = std::fs::read(out(0).join(file)).unwrap();
        let b = std::fs::read(out(1).join(file)).unwrap();
        assert!(a == b, "{file} differs between identical runs");
    }
    let summary = std::fs::read_to_string(out(0).join("summary.json")).unwrap();
    assert!(
        summary.contains("\"aa\""),
        "the summary reports anti-aliasing"
    );
    for k in 0..2 {
        let _ = std::fs::remove_dir_all(out(k));
    }
}

/// The frame buffer's holder resolves every frame it shows, not only the run's last: frame
/// 0 takes as long when a frame follows it as when it ends the run (the frame ends once
/// its image is resolved; the next one starts after).
#[test]
fn every_frame_shown_is_resolved() {
    let tetra = scene("p000-tetra-500.json");
    for (algo, aa) in [
        ("sort-last/pc", "adaptive"),
        ("sort-last/pc", "supersample:4"),
        ("sort-last/pixelflow", "adaptive"),
        ("sort-last/snooping", "adaptive"),
    ] {
        let set = [("aa", aa)];
        let time0 = |frames: &str| {
            let r = run_sort_last(&tetra, algo, 4, Some(frames), &set).unwrap();
            r.frames[0].end - r.frames[0].start
        };
        assert_eq!(time0("0..2"), time0("0"), "{algo} {aa}");
    }
}
