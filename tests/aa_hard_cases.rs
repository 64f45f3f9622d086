//! Hard cases of the anti-aliasing targets: samples exactly on edges, shared edges inside one
//! pixel, many edges in one pixel, the reclaim threshold itself, an empty pool, and a pool
//! that runs out on one node only. Each test goes through the public targets (or a whole
//! run) and checks what a user would see; none may panic.

use std::path::Path;
use std::sync::Arc;

use sortsim::algo::reference::{raster_options, render, viewport};
use sortsim::algo::{run, RunResult};
use sortsim::raster::aa::cases::shared_edge_in_one_pixel;
use sortsim::raster::aa::{
    AdaptiveConfig, AdaptiveTarget, Grid, SupersampleTarget, RECLAIM_SPREAD, SUBPIXEL_BYTES,
};
use sortsim::raster::{
    draw_mesh, draw_screen_triangles, Counters, Depth, ScreenTriangle, ScreenVertex, Sub, Viewport,
};
use sortsim::scene::Scene;
use sortsim::spec::run::RunSpec;

const RED: [u8; 3] = [255, 0, 0];
const BLUE: [u8; 3] = [0, 0, 255];

/// A vertex at pixel coordinates `(x, y)` with raw depth `z`.
fn v(x: f64, y: f64, z: u32, rgb: [u8; 3]) -> ScreenVertex {
    ScreenVertex {
        x: Sub::snap(x).unwrap(),
        y: Sub::snap(y).unwrap(),
        z: Depth::from_raw(z).unwrap(),
        rgb,
    }
}

/// An adaptive target whose pool holds a block for every pixel (these screens are tiny,
/// and the cases here are not about running out).
fn adaptive(vp: Viewport, grid: Grid, reclaim: bool) -> AdaptiveTarget {
    let mut config = AdaptiveConfig::for_pixels(vp.pixels() as u64);
    config.grid = grid;
    config.pool = sortsim::units::Bytes::new(vp.pixels() as u64 * 16 * SUBPIXEL_BYTES);
    if !reclaim {
        config.reclaim_spread = None;
    }
    AdaptiveTarget::full_screen(vp, config, [0; 3])
}

/// Two tall rectangles meet on x = 1.5, the middle sample column of a 3x3 grid (and of no
/// other grid); their diagonals stay out of pixel (1, 1). Every sample of that pixel must be
/// covered exactly once (red or blue, never background, never both), for every grid and
/// for 3x3 supersampling, whose middle column is also exactly on the edge.
#[test]
fn edges_exactly_on_sample_positions_cover_each_sample_once() {
    let (vp, tris) = shared_edge_in_one_pixel(0, RED, BLUE);
    for grid in Grid::FINEST_FIRST {
        let mut t = adaptive(vp, grid, false);
        draw_screen_triangles(&tris, &mut t);
        let samples = t.samples(1, 1).expect("pixel (1, 1) is an edge pixel");
        let red = samples.iter().filter(|s| s.1 == RED).count();
        let blue = samples.iter().filter(|s| s.1 == BLUE).count();
        assert_eq!(red + blue, grid.samples() as usize, "{grid}: {samples:?}");
        // Left of x = 1/2 is red, right is blue; the tie column goes wholly to one side.
        let n = grid.side() as usize;
        assert!(
            red >= n * (n / 2) && blue >= n * (n / 2),
            "{grid}: {red} red {blue} blue"
        );
    }
    let mut ss = SupersampleTarget::full_screen(vp, 3, [0; 3]);
    draw_screen_triangles(&tris, &mut ss);
    let image = ss.resolve(&mut Counters::default());
    let rgb = image.regions()[0].color(1, 1).unwrap();
    // 3 or 6 of 9 samples red, the rest blue: red + blue channels add up to 255 (+-1).
    assert!(
        rgb[1] == 0 && (254..=256).contains(&(u32::from(rgb[0]) + u32::from(rgb[2]))),
        "{rgb:?}"
    );
    assert!(rgb[0] == 85 || rgb[0] == 170, "{rgb:?}");
}

/// Paper 000, Figure 3: two polygons of one colour sharing an edge cover a pixel together;
/// its Subpixel cells are reclaimed and the pixel resolves to that colour. The shared edge
/// is a diagonal through pixel centres, on a tilted plane (depth changes across the pixel).
#[test]
fn two_polygons_sharing_an_edge_inside_a_pixel_are_reclaimed() {
    let vp = Viewport::new(6, 6).unwrap();
    let z = |x: f64, y: f64| (1.0e9 + 2.0e7 * x + 1.3e7 * y) as u32;
    let p = |x: f64, y: f64, rgb| v(x, y, z(x, y), rgb);
    // The two triangles share the diagonal a-c; the second one's colour decides whether
    // they agree.
    let quad = |rgb2: [u8; 3]| {
        vec![
            ScreenTriangle::new([p(0.3, 0.3, RED), p(5.7, 0.3, RED), p(5.7, 5.7, RED)], 0).unwrap(),
            ScreenTriangle::new([p(0.3, 0.3, rgb2), p(5.7, 5.7, rgb2), p(0.3, 5.7, rgb2)], 1)
                .unwrap(),
        ]
    };
    let mut same = adaptive(vp, Grid::X4, true);
    draw_screen_triangles(&quad(RED), &mut same);
    let s = same.stats();
    assert!(s.reclaimed_pixels >= 4, "the diagonal's pixels: {s:?}");
    for k in 1..5 {
        assert!(!same.is_super(k, k), "({k}, {k}) reclaimed");
    }
    let image = same.resolve(&mut Counters::default());
    assert_eq!(image.regions()[0].color(2, 2), Some(RED));
    // Control: when the two polygons' colours differ, the diagonal keeps its blocks.
    let mut differ = adaptive(vp, Grid::X4, true);
    draw_screen_triangles(&quad([0, 255, 0]), &mut differ);
    assert!(differ.is_super(3, 3));
}

/// Paper 000, section 3: "there is at most one memory block allocated to a pixel no matter
/// how many polygon edges are found in the pixel". Twelve triangles fan around the centre
/// of pixel (2, 2); every one of them partially covers it.
#[test]
fn a_pixel_crossed_by_many_edges_holds_one_block() {
    let vp = Viewport::new(5, 5).unwrap();
    let (cx, cy) = (2.5, 2.5);
    let ring = |k: u32| {
        let a = std::f64::consts::TAU * f64::from(k) / 12.0;
        let c = [(k * 20) as u8, 255 - (k * 20) as u8, 7 * k as u8];
        v(cx + 1.7 * a.cos(), cy + 1.7 * a.sin(), 5_000 + 100 * k, c)
    };
    let tris: Vec<ScreenTriangle> = (0..12)
        .filter_map(|k| {
            let c = ring(k).rgb;
            ScreenTriangle::new([v(cx, cy, 5_000, c), ring(k), ring((k + 1) % 12)], k)
        })
        .collect();
    assert_eq!(tris.len(), 12);
    let mut t = adaptive(vp, Grid::X4, false);
    let c = draw_screen_triangles(&tris, &mut t);
    let s = t.stats();
    let super_pixels = (0..5)
        .flat_map(|y| (0..5).map(move |x| (x, y)))
        .filter(|&(x, y)| t.is_super(x, y))
        .count() as u64;
    // One block per supersampled pixel, however many triangles crossed it.
    assert_eq!(s.supersampled_pixels, super_pixels);
    assert_eq!(s.live_cells, 16 * super_pixels);
    assert!(t.is_super(2, 2));
    assert_eq!(t.samples(2, 2).unwrap().len(), 16);
    assert!(
        c.aa_coverage_masks >= 12,
        "each triangle formed a mask at (2, 2)"
    );
}

/// Paper 000, section 4.2: reclaiming needs a depth spread "smaller than 1 unit" (strictly).
/// Two flat polygons of one colour share the edge x = 1.5 in pixel (1, 1); their depths
/// differ by exactly the threshold (kept) or one less (reclaimed); two colours are never
/// reclaimed. The same screen as `sortsim paper 000`'s reclaim-rule row.
#[test]
fn depth_spread_exactly_at_the_reclaim_threshold_is_kept() {
    for (gap, right, reclaimed) in [
        (RECLAIM_SPREAD, RED, false),
        (RECLAIM_SPREAD - 1, RED, true),
        (0, RED, true),
        (0, BLUE, false),
    ] {
        let (vp, tris) = shared_edge_in_one_pixel(gap, RED, right);
        let mut t = adaptive(vp, Grid::X4, true);
        draw_screen_triangles(&tris, &mut t);
        assert_eq!(!t.is_super(1, 1), reclaimed, "gap {gap}, right {right:?}");
    }
}

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn scene(name: &str) -> Arc<Scene> {
    Arc::new(Scene::load(&root().join("scenes").join(name)).unwrap())
}

fn simulate(scene: &Arc<Scene>, procs: u32, frames: &str, set: &[(&str, String)]) -> RunResult {
    let spec = RunSpec {
        schema: None,
        machine: root().join("machines/power-challenge.json"),
        scene: scene.file().to_path_buf(),
        algo: "sort-middle/static".into(),
        procs,
        frames: Some(frames.into()),
        seed: 1,
        set: set
            .iter()
            .map(|(k, v)| (k.to_string(), v.clone()))
            .collect(),
    };
    run(&spec.resolve(Some(scene.clone())).unwrap()).unwrap()
}

/// A pool of zero bytes must not panic: every edge pixel is sampled once and counted, and
/// the image is exactly the aliased one (on one target and through a whole run).
#[test]
fn a_pool_of_zero_bytes_samples_everything_once() {
    let b = scene("p000-letter-b.json");
    let g = b.frame(3).unwrap();
    let vp = viewport(&g);
    let config = AdaptiveConfig {
        pool: sortsim::units::Bytes::new(0),
        ..AdaptiveConfig::for_pixels(vp.pixels() as u64)
    };
    let mut t = AdaptiveTarget::full_screen(vp, config, g.background);
    draw_mesh(&g.vertices, &g.triangles, vp, &raster_options(&g), &mut t);
    let s = t.stats();
    assert_eq!(
        (s.supersampled_pixels, s.live_cells, s.pool_cells),
        (0, 0, 0)
    );
    assert!(s.overflowed_pixels > 1000, "{s:?}");
    let (reference, _) = render(&g);
    let image = t.resolve(&mut Counters::default());
    assert_eq!(image.regions()[0].colors(), reference.colors());

    let r = simulate(
        &b,
        4,
        "3",
        &[("aa", "adaptive".into()), ("aa-pool", "0B".into())],
    );
    assert_eq!(r.image.colors(), reference.colors());
    assert!(r.frames[0].aa.iter().all(|a| a.supersampled_pixels == 0));
}

/// A pool just big enough for every node but the neediest runs out on that node only,
/// partway through the frame (it supersampled pixels before overflowing); that node, and
/// only it, drops below 4x4 for the next frame.
#[test]
fn a_pool_exhausted_mid_frame_on_one_node_only() {
    let t = scene("p000-tetra-500.json");
    let free = simulate(&t, 8, "0", &[("aa", "adaptive".into())]);
    let peaks: Vec<u64> = free.frames[0].aa.iter().map(|a| a.peak_cells).collect();
    let mut sorted = peaks.clone();
    sorted.sort_unstable();
    let (second, most) = (sorted[6], sorted[7]);
    assert!(second < most, "one node needs the most: {peaks:?}");
    let needy = peaks.iter().position(|&p| p == most).unwrap();
    // Enough cells for the second neediest node (a whole number of 4x4 blocks).
    let pool = format!("{}B", second * SUBPIXEL_BYTES);
    let r = simulate(
        &t,
        8,
        "0..2",
        &[("aa", "adaptive".into()), ("aa-pool", pool)],
    );
    let (first, next) = (&r.frames[0].aa, &r.frames[1].aa);
    for (node, a) in first.iter().enumerate() {
        if node == needy {
            assert!(a.overflowed_pixels > 0, "node {node}: {a:?}");
            assert!(
                a.supersampled_pixels > 0 && a.peak_cells <= second,
                "mid-frame: {a:?}"
            );
            assert!(next[node].grid_side < 4, "node {node} adapts");
        } else {
            assert_eq!(a.overflowed_pixels, 0, "node {node}: {a:?}");
            assert_eq!(next[node].grid_side, 4, "node {node} keeps 4x4");
        }
    }
}

/// summary.json and summary.md show anti-aliasing only when a run used it, and the same
/// run twice records the same numbers (no host state leaks into them).
#[test]
fn summaries_show_anti_aliasing_only_when_on_and_deterministically() {
    use sortsim::metrics::run::RunSummary;
    let b = scene("p000-letter-b.json");
    let summarize = |set: &[(&str, &str)]| {
        let spec = RunSpec {
            schema: None,
            machine: root().join("machines/power-challenge.json"),
            scene: b.file().to_path_buf(),
            algo: "sort-middle/static".into(),
            procs: 4,
            frames: Some("0..2".into()),
            seed: 1,
            set: set
                .iter()
                .map(|(k, v)| (k.to_string(), v.to_string()))
                .collect(),
        };
        let cfg = spec.resolve(Some(b.clone())).unwrap();
        let result = run(&cfg).unwrap();
        let s = RunSummary::new(&cfg, &result);
        (
            serde_json::to_string(&s).unwrap(),
            s.markdown(),
            result.frames,
        )
    };
    let (json, md, _) = summarize(&[]);
    assert!(!json.contains("\"aa\"") && !md.contains("Anti-aliasing"));
    let (json, md, frames) = summarize(&[("aa", "adaptive")]);
    for key in [
        "grid_side_per_node",
        "supersampled_pixels",
        "reclaimed_pixels",
        "overflowed_pixels",
        "memory_mean_bytes",
    ] {
        assert!(json.contains(key), "{key}");
    }
    assert!(md.contains("## Anti-aliasing") && md.contains("4x4 4x4 4x4 4x4"));
    let (json_again, _, frames_again) = summarize(&[("aa", "adaptive")]);
    assert_eq!(json, json_again);
    assert_eq!(frames, frames_again);
}

/// An adaptive target over a node's regions gives, on those regions, the pixels a
/// full-screen target gives (same pool size, no overflow): regions only cut the screen.
#[test]
fn regions_see_the_pixels_of_the_whole_screen() {
    let g = scene("p000-tetra-500.json").frame(2).unwrap();
    let vp = viewport(&g);
    let config = AdaptiveConfig::for_pixels(vp.pixels() as u64);
    let mut whole = AdaptiveTarget::full_screen(vp, config, g.background);
    draw_mesh(
        &g.vertices,
        &g.triangles,
        vp,
        &raster_options(&g),
        &mut whole,
    );
    let rect = |x0, y0, x1, y1| sortsim::raster::ScreenRect::new(x0, y0, x1, y1).unwrap();
    let rects = vec![
        rect(0, 0, 200, 300),
        rect(200, 0, 512, 300),
        rect(0, 300, 512, 512),
    ];
    let mut parts = AdaptiveTarget::new(vp, rects, config, g.background).unwrap();
    draw_mesh(
        &g.vertices,
        &g.triangles,
        vp,
        &raster_options(&g),
        &mut parts,
    );
    assert_eq!(whole.stats(), parts.stats());
    let mut a = sortsim::raster::Framebuffer::new(vp);
    let mut b = sortsim::raster::Framebuffer::new(vp);
    whole.resolve_into(&mut a, &mut Counters::default());
    parts.resolve_into(&mut b, &mut Counters::default());
    assert_eq!(a.colors(), b.colors());
    assert!(matches!(
        AdaptiveTarget::new(vp, vec![rect(0, 0, 600, 10)], config, [0; 3]),
        Err(sortsim::raster::RegionError::OutsideViewport(0))
    ));
}

/// Design principle 3: anti-aliasing switched on for a scene that does not exercise it (one
/// polygon covering every pixel of the screen, no edge inside it) changes nothing: no super
/// pixel, no Subpixel in use, and the resolved image equals the aliased one.
#[test]
fn a_screen_without_edges_is_not_changed_by_anti_aliasing() {
    let vp = Viewport::new(16, 12).unwrap();
    // A triangle much larger than the screen: its edges lie outside every pixel.
    let tri: Vec<ScreenTriangle> = ScreenTriangle::new(
        [
            v(-40.0, -40.0, 7, RED),
            v(80.0, -40.0, 7, RED),
            v(-40.0, 80.0, 7, RED),
        ],
        0,
    )
    .into_iter()
    .collect();
    for grid in [Grid::X2, Grid::X3, Grid::X4] {
        let mut t = adaptive(vp, grid, true);
        draw_screen_triangles(&tri, &mut t);
        let s = t.stats();
        assert_eq!(
            (s.supersampled_pixels, s.live_cells),
            (0, 0),
            "{grid:?}: {s:?}"
        );
        let image = t.resolve(&mut Counters::default());
        assert!(
            image.regions()[0].colors().iter().all(|&c| c == RED),
            "{grid:?}: every pixel is the polygon's colour"
        );
    }
}
