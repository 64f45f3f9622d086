//! Paper 000 (adaptive supersampling with fixed memory pools): the memory arithmetic of the
//! Pixel and Subpixel cells, what the 2 x 2-for-all pool holds at each resolution, memory
//! adaptation, Figure 6's memory and shares on the stand-in scenes, Figure 7's memory per
//! processor and Table 1's phase times on the Power Challenge.
//!
//! Owns which renders and runs answer which row of papers/000.json. Must never hold a paper
//! value.

use crate::algo::reference::render_adaptive_sequence;
use crate::algo::RunResult;
use crate::output::plot::{ChartOptions, Series};
use crate::raster::aa::cases::{every_pixel_an_edge, shared_edge_in_one_pixel};
use crate::raster::aa::{
    AaStats, AdaptiveConfig, AdaptiveTarget, Grid, SupersampleTarget, PIXEL_BYTES, RECLAIM_SPREAD,
    SUBPIXEL_BYTES,
};
use crate::raster::{draw_screen_triangles, Viewport};
use crate::scene::{FrameGeometry, Scene};

use super::runs::{mean, run_jobs, triangles_per_s, Job};
use super::{paper_value, Chart, Measured, Measurements, PaperData, PaperOptions};

const MB: f64 = 1e6;

pub fn measure(options: &PaperOptions, data: &PaperData) -> Result<Measurements, String> {
    let mut m = Measurements::default();
    memory_layout_rows(&mut m)?;
    pool_share_rows(&mut m)?;
    reclaim_rule_row(&mut m);
    figure_6_rows(options, data, &mut m)?;
    parallel_rows(options, data, &mut m)?;
    Ok(m)
}

fn memory_layout_rows(m: &mut Measurements) -> Result<(), String> {
    let vp = Viewport::new(512, 512).ok_or("a 512 x 512 viewport")?;
    let pixels = vp.pixels() as u64;
    m.put(
        "pixel-bytes",
        Measured::value(PIXEL_BYTES as f64, "raster::aa::PIXEL_BYTES"),
    );
    m.put(
        "subpixel-bytes",
        Measured::value(SUBPIXEL_BYTES as f64, "raster::aa::SUBPIXEL_BYTES"),
    );
    let t = AdaptiveTarget::full_screen(vp, AdaptiveConfig::for_pixels(pixels), [0; 3]);
    let array = t.stats().memory_used().get();
    m.put(
        "pixel-array-mb",
        Measured::value(
            array as f64 / MB,
            format!("{array} B charged by an empty 512 x 512 adaptive target"),
        ),
    );
    let ss = SupersampleTarget::full_screen(vp, 4, [0; 3]).bytes().get();
    m.put(
        "supersample-4x4-mb",
        Measured::value(
            ss as f64 / MB,
            format!("{ss} B: a 512 x 512 4 x 4 supersampling target"),
        ),
    );
    let pool = AdaptiveConfig::default_pool(pixels).get();
    m.put(
        "pool-2x2-mb",
        Measured::value(
            (array + pool) as f64 / MB,
            format!("{array} B Pixel array + {pool} B default pool"),
        ),
    );
    Ok(())
}

fn pool_share_rows(m: &mut Measurements) -> Result<(), String> {
    let (vp, tris) = every_pixel_an_edge(512);
    for (grid, key) in [(Grid::X4, "4x4"), (Grid::X3, "3x3"), (Grid::X2, "2x2")] {
        let mut config = AdaptiveConfig::for_pixels(vp.pixels() as u64);
        config.grid = grid;
        let mut t = AdaptiveTarget::full_screen(vp, config, [0; 3]);
        draw_screen_triangles(&tris, &mut t);
        let s = t.stats();
        m.put(
            &format!("pool-share-{key}"),
            Measured::value(
                100.0 * s.live_super_pixels as f64 / s.pixels as f64,
                format!(
                    "{} of {} pixels supersampled, {} overflowed",
                    s.live_super_pixels, s.pixels, s.overflowed_pixels
                ),
            ),
        );
    }
    Ok(())
}

/// Section 4.2's rule on Figure 3's case: two flat rectangles meet on x = 1.5 inside pixel
/// (1, 1). Reclaimed when they share a colour and their depths differ by less than one unit
/// (`RECLAIM_SPREAD` raw steps); kept at exactly one unit, or when the colours differ.
fn reclaim_rule_row(m: &mut Measurements) {
    let (red, blue) = ([255, 0, 0], [0, 0, 255]);
    let mut holds = true;
    let mut seen = Vec::new();
    for (gap, right, reclaim) in [
        (RECLAIM_SPREAD - 1, red, true),
        (RECLAIM_SPREAD, red, false),
        (0, blue, false),
    ] {
        let (vp, tris) = shared_edge_in_one_pixel(gap, red, right);
        let mut config = AdaptiveConfig::for_pixels(vp.pixels() as u64);
        config.grid = Grid::X4;
        let mut t = AdaptiveTarget::full_screen(vp, config, [0; 3]);
        draw_screen_triangles(&tris, &mut t);
        let reclaimed = !t.is_super(1, 1);
        holds &= reclaimed == reclaim;
        seen.push(format!(
            "depth gap {gap}/{RECLAIM_SPREAD}, {}: {}",
            if right == red {
                "one colour"
            } else {
                "two colours"
            },
            if reclaimed { "reclaimed" } else { "kept" }
        ));
    }
    m.put(
        "reclaim-rule",
        Measured::shape(
            holds,
            format!("4x4 adaptive target, pixel (1, 1): {}", seen.join("; ")),
        ),
    );
}

fn frames_of(options: &PaperOptions, name: &str) -> Result<Vec<FrameGeometry>, String> {
    let scene = Scene::load(&options.scene(name)).map_err(|e| e.to_string())?;
    (0..scene.frame_count())
        .map(|f| scene.frame(f).map_err(|e| e.to_string()))
        .collect()
}

fn pct(n: u64, s: &AaStats) -> f64 {
    100.0 * n as f64 / s.pixels as f64
}

fn mb(s: &AaStats) -> f64 {
    s.memory_used().get() as f64 / MB
}

fn figure_6_rows(
    options: &PaperOptions,
    data: &PaperData,
    m: &mut Measurements,
) -> Result<(), String> {
    let b = frames_of(options, "p000-letter-b.json")?;
    let (b_plain, b_reclaimed) = (
        render_adaptive_sequence(&b, false),
        render_adaptive_sequence(&b, true),
    );
    let (plain, reclaimed) = (&b_plain, &b_reclaimed);
    let note = format!(
        "scenes/p000-letter-b.json, {} frames, full-screen adaptive target",
        b.len()
    );
    let worst = plain
        .iter()
        .map(|s| pct(s.supersampled_pixels, s))
        .fold(0.0, f64::max);
    m.put(
        "letter-b-supersampled",
        Measured::value(worst, note.clone()),
    );
    m.put(
        "letter-b-memory",
        Measured::value(mean(plain.iter().map(mb)), note.clone()),
    );
    let live = mean(reclaimed.iter().map(|s| pct(s.live_super_pixels, s)));
    m.put(
        "letter-b-reclaimed-share",
        Measured::value(
            live,
            format!(
                "{note}; without reclaiming {:.2}%",
                mean(plain.iter().map(|s| pct(s.supersampled_pixels, s)))
            ),
        ),
    );
    m.put(
        "letter-b-reclaimed-memory",
        Measured::value(mean(reclaimed.iter().map(mb)), note.clone()),
    );
    let most = reclaimed
        .iter()
        .map(|s| 100.0 * s.reclaimed_pixels as f64 / s.supersampled_pixels.max(1) as f64)
        .fold(0.0, f64::max);
    m.put("letter-b-most-reclaimed", Measured::value(most, note));

    let t = frames_of(options, "p000-tetra-500.json")?;
    let (plain, reclaimed) = (
        render_adaptive_sequence(&t, false),
        render_adaptive_sequence(&t, true),
    );
    let note = format!("scenes/p000-tetra-500.json, {} frames", t.len());
    m.put(
        "tetra-500-memory",
        Measured::value(mean(plain.iter().map(mb)), note.clone()),
    );
    m.put(
        "tetra-500-supersampled",
        Measured::value(
            mean(plain.iter().map(|s| pct(s.supersampled_pixels, s))),
            note.clone(),
        ),
    );
    let removed =
        mean(reclaimed.iter().map(|s| {
            100.0 * (1.0 - s.live_super_pixels as f64 / s.supersampled_pixels.max(1) as f64)
        }));
    m.put("tetra-500-removed", Measured::value(removed, note.clone()));
    m.put(
        "tetra-500-left",
        Measured::value(
            mean(reclaimed.iter().map(|s| pct(s.live_super_pixels, s))),
            note,
        ),
    );
    m.charts.push(Chart {
        stem: "figure6-memory".into(),
        title: "Figure 6: memory per frame, before and after reclaiming".into(),
        x_label: "frame".into(),
        y_label: "MB".into(),
        series: vec![
            Series::new("sortsim, letter B", frame_series(&b_plain)),
            Series::new("sortsim, letter B, reclaiming", frame_series(&b_reclaimed)),
            Series::new("sortsim, 500 tetrahedra", frame_series(&plain)),
            Series::new(
                "sortsim, 500 tetrahedra, reclaiming",
                frame_series(&reclaimed),
            ),
            // The text gives one number per case, not per frame: drawn over the middle frame.
            Series::marks(
                "paper, letter B",
                text_mark(data, "letter-b-memory", b.len()),
            ),
            Series::marks(
                "paper, letter B, reclaiming",
                text_mark(data, "letter-b-reclaimed-memory", b.len()),
            ),
            Series::marks(
                "paper, 500 tetrahedra",
                text_mark(data, "tetra-500-memory", t.len()),
            ),
        ],
        options: ChartOptions {
            log_x: false,
            y_from_zero: true,
        },
    });

    let many = frames_of(options, "p000-tetra-3000.json")?;
    let mut most = 0.0f64;
    let mut runs = Vec::new();
    for reclaim in [false, true] {
        let s = render_adaptive_sequence(&many, reclaim);
        most = most.max(
            s[1..]
                .iter()
                .map(|f| pct(f.supersampled_pixels, f))
                .fold(0.0, f64::max),
        );
        runs.push(s);
    }
    // Section 7.1 renders the 3000 tetrahedra with reclaiming and finds 2 x 2 set: the claim
    // is checked on that run, the one without reclaiming shown beside it.
    let with_reclaiming = &runs[1];
    let steps_ok = with_reclaiming[0].grid_side == 4
        && with_reclaiming[0].overflowed_pixels > 0
        && with_reclaiming[1..]
            .iter()
            .all(|f| f.grid_side == 2 && f.overflowed_pixels == 0);
    let details: Vec<String> = runs
        .iter()
        .zip([false, true])
        .map(|(s, reclaim)| {
            let sides: Vec<u32> = s.iter().map(|f| f.grid_side).collect();
            let demand = s
                .iter()
                .map(|f| pct(f.demand_pixels(), f))
                .fold(0.0, f64::max);
            format!("reclaiming {reclaim}: grids {sides:?}, largest demand {demand:.1}% of pixels")
        })
        .collect();
    m.put(
        "adaptation-steps-down",
        Measured::shape(steps_ok, details.join("; ")),
    );
    m.put(
        "tetra-3000-supersampled",
        Measured::value(
            most,
            format!("scenes/p000-tetra-3000.json, {} frames", many.len()),
        ),
    );
    let changed =
        render_adaptive_sequence(&[b[0].clone(), many[0].clone(), many[0].clone()], false);
    let overflowed: Vec<u64> = changed.iter().map(|s| s.overflowed_pixels).collect();
    m.put(
        "view-change-recovers",
        Measured::shape(
            overflowed[0] == 0 && overflowed[1] > 0 && overflowed[2] == 0,
            format!("overflowed pixels per frame: {overflowed:?}"),
        ),
    );
    Ok(())
}

fn frame_series(stats: &[AaStats]) -> Vec<(f64, f64)> {
    stats
        .iter()
        .enumerate()
        .map(|(i, s)| (i as f64, mb(s)))
        .collect()
}

fn text_mark(data: &PaperData, id: &str, frames: usize) -> Vec<(f64, f64)> {
    paper_value(data, id)
        .map(|v| ((frames / 2) as f64, v))
        .into_iter()
        .collect()
}

fn phase_per_frame(r: &RunResult, phase: &str) -> Vec<f64> {
    let frames = r.frames.len() as f64;
    r.stats
        .nodes
        .iter()
        .map(|n| {
            n.busy_by_phase
                .iter()
                .filter(|(p, _)| *p == phase)
                .map(|(_, t)| t.as_secs_f64())
                .sum::<f64>()
                / frames
        })
        .collect()
}

fn min_max(v: &[f64]) -> (f64, f64) {
    v.iter()
        .fold((f64::MAX, f64::MIN), |(lo, hi), &x| (lo.min(x), hi.max(x)))
}

fn parallel_rows(
    options: &PaperOptions,
    data: &PaperData,
    m: &mut Measurements,
) -> Result<(), String> {
    // Table 1's 20 frames even under --quick: fewer moved the polygons per second by a fifth
    // (90 K over 5 frames, 74 K over 20), and all 20 take under a second more.
    let frames = "0..20";
    let job = |scene: &str| {
        Job::new("power-challenge.json", scene, "sort-middle/static", 8)
            .frames(frames)
            .set("aa", "adaptive")
    };
    let jobs = [
        job("p000-tetra-500.json"),
        job("p000-letter-b.json"),
        job("p000-letter-b-near.json"),
        job("p000-table1-polygons.json"),
    ];
    let results = run_jobs(options, &jobs)?;
    let (tetra, b) = (&results[0], &results[1]);
    table_1_bracket(data, &results[2], &results[3], m);

    let mut all = Vec::new();
    let mut close = true;
    let mut worst = 1.0f64;
    for f in &tetra.frames {
        let per: Vec<f64> = f.aa.iter().map(mb).collect();
        let (lo, hi) = min_max(&per);
        close &= hi / lo < 1.35;
        worst = worst.max(hi / lo);
        all.extend(per);
    }
    let note = format!("sort-middle/static, aa=adaptive, 8 processors, frames {frames}");
    m.put(
        "per-processor-memory",
        Measured::value(mean(all.into_iter()), format!("500 tetrahedra, {note}")),
    );
    m.put(
        "per-processor-memory-close",
        Measured::shape(
            close,
            format!("largest / smallest, worst frame: {worst:.2}"),
        ),
    );
    let note = format!("letter B, {note}");
    for (key, phase) in [("transform", "transform"), ("rasterize", "rasterize")] {
        let (lo, hi) = min_max(&phase_per_frame(b, phase));
        m.put(&format!("t1-{key}-min"), Measured::value(lo, note.clone()));
        m.put(&format!("t1-{key}-max"), Measured::value(hi, note.clone()));
    }
    let comm: Vec<f64> = b
        .stats
        .nodes
        .iter()
        .map(|n| n.comm.as_secs_f64() / b.frames.len() as f64)
        .collect();
    let (lo, hi) = min_max(&comm);
    m.put("t1-redistribute-min", Measured::value(lo, note.clone()));
    m.put("t1-redistribute-max", Measured::value(hi, note.clone()));
    let (lo, hi) = min_max(&phase_per_frame(b, "transform"));
    m.put(
        "t1-transform-even",
        Measured::shape(
            hi <= 1.10 * lo,
            format!("transform per frame {lo:.6} .. {hi:.6} s"),
        ),
    );
    m.put(
        "t1-polygons-per-s",
        Measured::value(triangles_per_s(b), note),
    );
    Ok(())
}

/// Table 1's image cannot be rebuilt from the text (see scenes/p000-table1-polygons.json), so
/// its times are checked against the two readings that bound it: the letter B at its largest
/// on screen must be faster than the paper, 800 scattered 50x50 polygons slower. Both ends
/// run on the same Power Challenge costs, so the rows fail if those costs are off by more
/// than the bracket is wide.
fn table_1_bracket(data: &PaperData, near: &RunResult, literal: &RunResult, m: &mut Measurements) {
    let (near_lo, near_hi) = min_max(&phase_per_frame(near, "rasterize"));
    let (lit_lo, lit_hi) = min_max(&phase_per_frame(literal, "rasterize"));
    let paper_lo = paper_value(data, "t1-rasterize-min").unwrap_or(f64::NAN);
    let paper_hi = paper_value(data, "t1-rasterize-max").unwrap_or(f64::NAN);
    m.put(
        "t1-rasterize-bracketed",
        Measured::shape(
            near_hi < paper_hi && lit_lo > paper_lo,
            format!(
                "rasterization per frame: letter B at its largest {near_lo:.4} .. {near_hi:.4} s, \
                 800 polygons of 50x50 px {lit_lo:.4} .. {lit_hi:.4} s"
            ),
        ),
    );
    let (near_rate, lit_rate) = (triangles_per_s(near), triangles_per_s(literal));
    let (fewest, most) = data
        .rows
        .iter()
        .find(|r| r.id == "t1-polygons-per-s")
        .and_then(|r| r.range)
        .map_or((f64::NAN, f64::NAN), |r| (r[0], r[1]));
    m.put(
        "t1-polygons-per-s-bracketed",
        Measured::shape(
            near_rate > most && lit_rate < fewest,
            format!(
                "polygons per second: letter B at its largest {near_rate:.0}, 800 polygons of \
                 50x50 px {lit_rate:.0}"
            ),
        ),
    );
}
