//! Paper 000's memory figures for adaptive supersampling (section 7.1, Figures 6 to 8) and
//! paper 002's anti-aliasing rate ratio, against the stand-in scenes. Each assertion names
//! its source and states its tolerance; the stand-ins are approximate (scenes/p000-*.json
//! are held to 25% of the paper's edge-pixel shares by tests/scene_standins.rs), so the
//! scene-dependent figures are held to tolerances of that order, not to the paper's digits.

use crate::common;

use common::scene;

use std::sync::Arc;

use sortsim::algo::reference::{raster_options, render, render_adaptive_sequence, viewport};
use sortsim::algo::RunResult;
use sortsim::raster::aa::cases::every_pixel_an_edge;
use sortsim::raster::aa::{
    AaStats, AdaptiveConfig, AdaptiveTarget, Grid, SupersampleTarget, PIXEL_BYTES, SUBPIXEL_BYTES,
};
use sortsim::raster::{draw_mesh, draw_screen_triangles, Viewport};
use sortsim::scene::Scene;

const MB: f64 = 1e6;

/// `frames` of `scene` on one full-screen adaptive target each, adapting between frames.
fn animate(scene: &Scene, frames: std::ops::Range<u32>, reclaim: bool) -> Vec<AaStats> {
    let frames: Vec<_> = frames.map(|f| scene.frame(f).unwrap()).collect();
    render_adaptive_sequence(&frames, reclaim)
}

fn share(n: u64, s: &AaStats) -> f64 {
    n as f64 / s.pixels as f64
}

fn mean(v: impl Iterator<Item = f64>) -> f64 {
    let v: Vec<f64> = v.collect();
    v.iter().sum::<f64>() / v.len() as f64
}

/// Paper 000, section 7.1: "the 2D array of Pixel cells consumes about 3.14MB"; "the
/// traditional supersampling method where 29.4MB of memory is needed"; "we need about
/// 10.44MB of memory for rendering an image of 512x512 pixels" with a 2x2-for-all pool.
#[test]
fn a_512_screen_needs_the_papers_memory() {
    let vp = Viewport::new(512, 512).unwrap();
    let pixels = vp.pixels() as u64;
    let t = AdaptiveTarget::full_screen(vp, AdaptiveConfig::for_pixels(pixels), [0; 3]);
    let stats = t.stats();
    // Exact: 512 * 512 * 12 = 3,145,728 B = 3.14 MB (decimal megabytes, as the paper).
    assert_eq!(stats.memory_used().get(), 3_145_728);
    assert_eq!(pixels * PIXEL_BYTES, 3_145_728);
    // Exact: 512 * 512 * 16 * 7 = 29,360,128 B = 29.4 MB.
    let ss = SupersampleTarget::full_screen(vp, 4, [0; 3]);
    assert_eq!(ss.bytes().get(), 29_360_128);
    // The pool: 512 * 512 * 4 * 7 = 7,340,032 B; with the Pixel array 10,485,760 B =
    // 10.49 MB (exactly 10 MiB). The paper's 10.44 MB is 3.14 + 7.30, the pool's 7.34 MB
    // cut to 7.30; exact arithmetic gives 10.49 MB, which is what we charge.
    let pool = AdaptiveConfig::default_pool(pixels).get();
    assert_eq!(pool, 7_340_032);
    assert_eq!(pixels * PIXEL_BYTES + pool, 10_485_760);
    assert!((((pixels * PIXEL_BYTES + pool) as f64 / MB) - 10.44).abs() < 0.06);
    assert_eq!(stats.pool_cells * SUBPIXEL_BYTES, pool);
}

/// Paper 000, section 4.1: the 2x2-for-all pool "can be used to supersample 25% of the
/// total number of pixels in the image at a subpixel resolution of 4x4", "up to 44%" at 3x3
/// and "100%" at 2x2. Exact: the pool holds 4 cells per pixel, so floor(4 / n^2) of them.
#[test]
fn the_pool_supersamples_25_44_and_100_percent_of_pixels() {
    let (vp, tris) = every_pixel_an_edge(512);
    let pixels = vp.pixels() as u64;
    for (grid, expected) in [(Grid::X4, 0.25), (Grid::X3, 4.0 / 9.0), (Grid::X2, 1.0)] {
        let mut config = AdaptiveConfig::for_pixels(pixels);
        config.grid = grid;
        let mut t = AdaptiveTarget::full_screen(vp, config, [0; 3]);
        draw_screen_triangles(&tris, &mut t);
        let s = t.stats();
        let got = share(s.live_super_pixels, &s);
        eprintln!(
            "{grid}: {got:.4} supersampled, {} overflowed",
            s.overflowed_pixels
        );
        // Exact up to the last block that fits (one pixel in 262,144).
        assert!((got - expected).abs() < 1e-5, "{grid}: {got} vs {expected}");
        // The rest were sampled once: overflow exactly when the pool is short.
        assert_eq!(s.overflowed_pixels > 0, grid != Grid::X2, "{grid}");
        assert_eq!(s.reclaimed_pixels, 0);
    }
}

/// Paper 000, section 7.1 and Figure 6 (letter B, about 800 large polygons, rotating,
/// 512x512 at 4x4): "less than 5%" supersampled, Pixel array 3.14 MB plus Subpixel cells
/// 1.47 MB = 4.61 MB; with reclaiming 1.3% and 3.52 MB, "up to a maximum of 74%" of the
/// supersampled pixels reclaimed.
#[test]
fn letter_b_supersamples_under_5_percent_and_reclaims_most() {
    let b = scene("p000-letter-b.json");
    let frames = 0..b.frame_count();
    let plain = animate(&b, frames.clone(), false);
    let reclaimed = animate(&b, frames, true);
    let worst = plain
        .iter()
        .map(|s| share(s.supersampled_pixels, s))
        .fold(0.0, f64::max);
    let memory = mean(plain.iter().map(|s| s.memory_used().get() as f64 / MB));
    let live = mean(reclaimed.iter().map(|s| share(s.live_super_pixels, s)));
    let memory_reclaimed = mean(reclaimed.iter().map(|s| s.memory_used().get() as f64 / MB));
    let most_reclaimed = reclaimed
        .iter()
        .map(|s| s.reclaimed_pixels as f64 / s.supersampled_pixels as f64)
        .fold(0.0, f64::max);
    eprintln!(
        "letter B: worst {worst:.4} supersampled, {memory:.3} MB; reclaiming: {live:.4} live, \
         {memory_reclaimed:.3} MB, at most {most_reclaimed:.3} reclaimed"
    );
    assert!(plain
        .iter()
        .all(|s| s.grid_side == 4 && s.overflowed_pixels == 0));
    // "less than 5%": a bound, held exactly.
    assert!(worst < 0.05, "{worst}");
    // 4.61 MB is 3.14 MB + 5% of pixels at 4x4; under 5% must stay under it.
    let pixel_array = 3_145_728.0 / MB;
    assert!(memory > pixel_array && memory < 4.61, "{memory}");
    // 1.3% after reclaiming: the stand-in keeps about 2.1% over the 20 frames (its tumbling
    // B shows more silhouette, which no reclaiming removes); held to within a factor of 2
    // (0.65% .. 2.6%).
    assert!((0.0065..0.026).contains(&live), "{live}");
    // 3.52 MB: within 10% (the Pixel array's exact 3.14 MB dominates it; about 3.75 MB).
    assert!(
        (memory_reclaimed / 3.52 - 1.0).abs() < 0.10,
        "{memory_reclaimed}"
    );
    // "up to a maximum of 74%": the best frame reclaims 55% .. 90%.
    assert!((0.55..0.90).contains(&most_reclaimed), "{most_reclaimed}");
}

/// Paper 000, section 7.1 (Figure 8(b), 500 tetrahedra): 10.14 MB, about 24% of pixels
/// supersampled, reclaiming removes about 28% of them (to about 17%).
#[test]
fn five_hundred_tetrahedra_supersample_about_a_quarter() {
    let t = scene("p000-tetra-500.json");
    let plain = animate(&t, 0..t.frame_count(), false);
    let reclaimed = animate(&t, 0..t.frame_count(), true);
    let supersampled = mean(plain.iter().map(|s| share(s.supersampled_pixels, s)));
    let memory = mean(plain.iter().map(|s| s.memory_used().get() as f64 / MB));
    let removed = mean(
        reclaimed
            .iter()
            .map(|s| 1.0 - s.live_super_pixels as f64 / s.supersampled_pixels as f64),
    );
    let live = mean(reclaimed.iter().map(|s| share(s.live_super_pixels, s)));
    eprintln!(
        "500 tetrahedra: {supersampled:.4} supersampled, {memory:.3} MB; reclaiming removes \
         {removed:.3}, leaving {live:.4}"
    );
    assert!(plain
        .iter()
        .all(|s| s.grid_side == 4 && s.overflowed_pixels == 0));
    // About 24%: within 25% relative, the stand-in's own tolerance.
    assert!((supersampled / 0.24 - 1.0).abs() < 0.25, "{supersampled}");
    // 10.14 MB: within 20% (3.14 MB of it is exact; the rest follows the share above).
    assert!((memory / 10.14 - 1.0).abs() < 0.20, "{memory}");
    // About 28% removed: the stand-in is held to 14% .. 42% (50% relative).
    assert!((0.14..0.42).contains(&removed), "{removed}");
    // About 17% left: within 25% relative.
    assert!((live / 0.17 - 1.0).abs() < 0.25, "{live}");
}

/// Paper 000, section 7.1 (Figure 8(d), 3000 tetrahedra): "about 50%" supersampled, "the
/// subpixel resolution has been set to 2x2", and the run stays within the pool. The first
/// frame at 4x4 can only supersample 25% and overflows. Without reclaiming its demand
/// forces 2x2 next; with reclaiming the stand-in's peak fits 3x3 (its 46% supersampled
/// leave 33% in use at the end), so the run settles there. Either way: below 4x4 after the
/// first frame and never past the pool's end again.
#[test]
fn three_thousand_tetrahedra_adapt_down_and_stay_in_the_pool() {
    let t = scene("p000-tetra-3000.json");
    for reclaim in [false, true] {
        let frames = animate(&t, 0..t.frame_count(), reclaim);
        let sides: Vec<u32> = frames.iter().map(|s| s.grid_side).collect();
        eprintln!(
            "3000 tetrahedra, reclaiming {reclaim}: grids {sides:?}, supersampled {:?}",
            frames
                .iter()
                .map(|s| (100.0 * share(s.supersampled_pixels, s)).round())
                .collect::<Vec<_>>()
        );
        assert_eq!(frames[0].grid_side, 4);
        assert!(
            frames[0].overflowed_pixels > 0,
            "4x4 cannot hold this scene"
        );
        if !reclaim {
            assert_eq!(frames[1].grid_side, 2, "the overflowing frame forces 2x2");
        }
        assert!(frames[1..].iter().all(|s| s.grid_side < 4));
        assert!(
            frames[1..].iter().all(|s| s.overflowed_pixels == 0),
            "{reclaim}"
        );
        assert!(frames[1..].iter().all(|s| s.peak_cells <= s.pool_cells));
        // About 50% edge pixels: the most any frame supersampled, within 25% relative.
        let most = frames[1..]
            .iter()
            .map(|s| share(s.supersampled_pixels, s))
            .fold(0.0, f64::max);
        assert!((most / 0.5 - 1.0).abs() < 0.25, "{most}");
    }
}

/// Paper 000, section 7.1: "a rapid change of the viewing direction" makes adaptation
/// predict wrong: "some edge pixels may not be supersampled ... our adaptive algorithm will
/// correct the situation in the next frame". A letter-B frame (few edges) is followed by
/// the 3000 tetrahedra twice.
#[test]
fn a_sudden_view_change_overflows_one_frame_and_recovers_in_the_next() {
    let b = scene("p000-letter-b.json").frame(0).unwrap();
    let t = scene("p000-tetra-3000.json").frame(0).unwrap();
    let overflowed: Vec<u64> = render_adaptive_sequence([&b, &t, &t], true)
        .iter()
        .map(|s| s.overflowed_pixels)
        .collect();
    assert_eq!(overflowed[0], 0, "the letter B fits at 4x4");
    assert!(
        overflowed[1] > 0,
        "the change overflows the frame it happens in"
    );
    assert_eq!(
        overflowed[2], 0,
        "and the next frame is within the pool: {overflowed:?}"
    );
}

fn simulate(
    machine: &str,
    scene: &Arc<Scene>,
    algo: &str,
    procs: u32,
    frames: &str,
    set: &[(&str, &str)],
) -> RunResult {
    common::run_frames(machine, scene, algo, procs, frames, set).unwrap()
}

/// Paper 000, Figure 7: 8 processors, 20 frames of the 500 tetrahedra under the static
/// sort-middle renderer: per-processor memory "very close" between the minimum and the
/// maximum, "about 0.98MB" on average (each processor: its regions' Pixel array plus the
/// Subpixel cells in use).
#[test]
fn eight_processors_use_close_to_a_megabyte_each() {
    let t = scene("p000-tetra-500.json");
    let r = simulate(
        "power-challenge.json",
        &t,
        "sort-middle/static",
        8,
        "0..20",
        &[("aa", "adaptive")],
    );
    assert_eq!(r.frames.len(), 20);
    let mut all = Vec::new();
    for f in &r.frames {
        assert_eq!(f.aa.len(), 8);
        let m: Vec<f64> =
            f.aa.iter()
                .map(|a| a.memory_used().get() as f64 / MB)
                .collect();
        let (lo, hi) = (
            m.iter().cloned().fold(f64::MAX, f64::min),
            m.iter().cloned().fold(0.0, f64::max),
        );
        // "very close": the largest within 35% of the smallest in every frame (the
        // interleaved 64x64 regions split the scattered tetrahedra evenly, not exactly).
        assert!(hi / lo < 1.35, "frame {}: {lo:.3} .. {hi:.3} MB", f.frame);
        all.extend(m);
    }
    let avg = mean(all.into_iter());
    eprintln!("8 processors: {avg:.3} MB per processor on average");
    // About 0.98 MB: within 10%.
    assert!((avg / 0.98 - 1.0).abs() < 0.10, "{avg}");
    // What each node is charged for is the preallocated pool (2x2 for all its pixels) and
    // the Pixel array, whatever the cells in use: 32,768 pixels each.
    for m in &r.stats.memory {
        assert_eq!(
            m.high_water_by_tag["subpixel pool"].get(),
            32_768 * 4 * SUBPIXEL_BYTES
        );
        assert_eq!(
            m.high_water_by_tag["pixel array"].get(),
            32_768 * PIXEL_BYTES
        );
    }
}

/// Paper 002's measure over a viewing sequence: triangles in view over frame time, averaged
/// over the frames after the first (which deals regions r mod N and waits for no assignment;
/// it is 1 of the sequence's 80 frames).
fn triangles_per_s(r: &RunResult) -> f64 {
    mean(
        r.frames[1..]
            .iter()
            .map(|f| f.triangles_in_view as f64 / f.time().as_secs_f64()),
    )
}

/// Paper 002, Performance: "With small partitions (eight processors), the antialiased
/// triangles-per-second performance is 36 percent of the aliased performance ... With 512
/// processors, and with 256 processors for all models except polio, the antialiased
/// performance equals the aliased performance." 16 samples per pixel, PLB head stand-in on
/// the Delta, whose anti-aliasing costs are fitted to paper 002 with its other costs
/// (machines/fits/delta-to-002-fig9.json): 36% at 8 processors within the paper row's 10
/// points, and a cost that all but vanishes on many processors (at least 90% at 256 and 512),
/// where communication and the load-balancing tree dominate.
#[test]
fn anti_aliasing_costs_much_on_8_processors_and_little_on_256_and_512() {
    let head = scene("plb-head-standin.json");
    let ratio = |procs: u32| {
        let none = simulate(
            "delta.json",
            &head,
            "sort-middle/ellsworth",
            procs,
            "0..3",
            &[],
        );
        let aa = simulate(
            "delta.json",
            &head,
            "sort-middle/ellsworth",
            procs,
            "0..3",
            &[("aa", "supersample:16")],
        );
        let r = triangles_per_s(&aa) / triangles_per_s(&none);
        eprintln!("{procs} processors: anti-aliased / aliased = {r:.3}");
        r
    };
    let r8 = ratio(8);
    assert!((0.26..=0.46).contains(&r8), "{r8}");
    for procs in [256, 512] {
        let r = ratio(procs);
        assert!((0.90..=1.02).contains(&r), "{procs}: {r}");
    }
}

/// The resolved image of a run is the anti-aliased one: with aa=supersample:16 the picture
/// differs from the aliased reference only near edges, and without any edge it is equal.
#[test]
fn the_run_image_is_the_resolved_image() {
    let b = scene("p000-letter-b.json");
    let r = simulate(
        "power-challenge.json",
        &b,
        "sort-middle/static",
        4,
        "3",
        &[("aa", "supersample:16")],
    );
    let (reference, _) = render(&b.frame(3).unwrap());
    let differ = r
        .image
        .colors()
        .iter()
        .zip(reference.colors())
        .filter(|(a, b)| a != b)
        .count();
    let pixels = reference.colors().len();
    eprintln!("{differ} of {pixels} pixels differ from the aliased image");
    // Edge pixels are about 3% of the screen for the letter B: some differ, most do not.
    assert!(differ > 0 && differ < pixels / 10, "{differ}");
}

/// An accuracy reference must be possible: 16x16 = 256 samples per pixel on a 512x512
/// screen is 256 * 7 * 262,144 = 469,762,048 modelled bytes (the host holds a primitive id
/// per sample too, about 740 MB, once). Its image and 4x4 supersampling's agree closely.
#[test]
fn a_256_sample_reference_renders_a_512_screen() {
    let g = scene("p000-letter-b.json").frame(5).unwrap();
    let vp = viewport(&g);
    let draw = |side: u32| {
        let mut t = SupersampleTarget::full_screen(vp, side, g.background);
        draw_mesh(&g.vertices, &g.triangles, vp, &raster_options(&g), &mut t);
        let bytes = t.bytes().get();
        (t.resolve(&mut sortsim::raster::Counters::default()), bytes)
    };
    let (fine, bytes) = draw(16);
    assert_eq!(bytes, 469_762_048);
    let (coarse, _) = draw(4);
    let (a, b) = (fine.regions()[0].colors(), coarse.regions()[0].colors());
    let diff: u64 = a
        .iter()
        .zip(b)
        .flat_map(|(p, q)| (0..3).map(move |c| u64::from(p[c].abs_diff(q[c]))))
        .sum();
    let mean = diff as f64 / (3 * a.len()) as f64;
    eprintln!("16x16 vs 4x4: mean channel difference {mean:.4}");
    // Differences live on edge pixels only (about 3% of the screen), each at most one
    // sample's worth of 4x4 (1/16 of 255 = 16): the mean stays well under 1.
    assert!(mean > 0.0 && mean < 1.0, "{mean}");
}

/// Paper 000, Figure 1(c): the adaptive method's filtered image is the supersampled one's.
/// Against a 16x16 reference, adaptive 4x4 (bitmask-table coverage, reclaiming on) must be
/// about as accurate as traditional 4x4 supersampling (exact per-sample coverage): its
/// error at most 1.5 times supersampling's, and far below the aliased image's.
#[test]
fn adaptive_images_are_about_as_accurate_as_4x4_supersampling() {
    let b = scene("p000-letter-b.json");
    let g = b.frame(7).unwrap();
    let vp = viewport(&g);
    let err = |img: &[[u8; 3]], reference: &[[u8; 3]]| {
        let d: u64 = img
            .iter()
            .zip(reference)
            .flat_map(|(p, q)| (0..3).map(move |c| u64::from(p[c].abs_diff(q[c]))))
            .sum();
        d as f64 / (3 * img.len()) as f64
    };
    let supersampled = |side: u32| {
        let mut t = SupersampleTarget::full_screen(vp, side, g.background);
        draw_mesh(&g.vertices, &g.triangles, vp, &raster_options(&g), &mut t);
        let image = t.resolve(&mut sortsim::raster::Counters::default());
        image.regions()[0].colors().to_vec()
    };
    let reference = supersampled(16);
    let ss4 = supersampled(4);
    let mut t = AdaptiveTarget::full_screen(
        vp,
        AdaptiveConfig::for_pixels(vp.pixels() as u64),
        g.background,
    );
    draw_mesh(&g.vertices, &g.triangles, vp, &raster_options(&g), &mut t);
    let adaptive = t.resolve(&mut sortsim::raster::Counters::default());
    let (aliased, _) = render(&g);
    let (e_ss, e_ad, e_al) = (
        err(&ss4, &reference),
        err(adaptive.regions()[0].colors(), &reference),
        err(aliased.colors(), &reference),
    );
    eprintln!("mean error vs 16x16: 4x4 {e_ss:.4}, adaptive 4x4 {e_ad:.4}, aliased {e_al:.4}");
    assert!(e_ad <= 1.5 * e_ss, "{e_ad} vs {e_ss}");
    assert!(e_ad < 0.5 * e_al, "{e_ad} vs aliased {e_al}");
}
