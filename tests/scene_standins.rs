//! Stand-in scenes against the papers' numbers: every scenes/*.json loads, triangle counts
//! are exact, and mean triangle area / depth complexity match the published values within
//! the tolerance written next to each assertion (the table is `sortsim::scene::paper`).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, OnceLock};

use sortsim::scene::paper::{reference, REFERENCES};
use sortsim::scene::stats::{geometric, GeometricStats};
use sortsim::scene::Scene;

fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes")
}

/// Loads a scene under scenes/ once per test binary: several tests measure the same large
/// stand-ins (the polio shell has 806,640 triangles).
fn load(name: &str) -> Arc<Scene> {
    static CACHE: OnceLock<Mutex<BTreeMap<String, Arc<Scene>>>> = OnceLock::new();
    let cache = CACHE.get_or_init(Default::default);
    if let Some(s) = cache.lock().unwrap().get(name) {
        return s.clone();
    }
    let scene = Scene::load(&scenes_dir().join(format!("{name}.json")))
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    let scene = Arc::new(scene);
    cache
        .lock()
        .unwrap()
        .insert(name.to_string(), scene.clone());
    scene
}

fn stats_of(name: &str) -> (Arc<Scene>, GeometricStats) {
    let scene = load(name);
    let frame = scene.frame(0).unwrap();
    let stats = geometric(&frame);
    (scene, stats)
}

fn within(achieved: f64, paper: f64, tolerance: f64) -> bool {
    ((achieved - paper) / paper).abs() <= tolerance
}

#[test]
fn every_scene_file_loads_and_draws_its_first_and_last_frame() {
    let mut names: Vec<PathBuf> = std::fs::read_dir(scenes_dir())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .collect();
    names.sort();
    assert!(
        names.len() >= 22,
        "expected all stand-ins under scenes/, found {}",
        names.len()
    );
    for path in names {
        let scene = load(&path.file_stem().unwrap().to_string_lossy());
        let first = scene.frame(0).unwrap();
        let last = scene.frame(scene.frame_count() - 1).unwrap();
        assert_eq!(
            first.triangles.len(),
            last.triangles.len(),
            "{}",
            path.display()
        );
        assert!(
            first
                .vertices
                .iter()
                .all(|v| v.clip.is_finite() && v.color.is_finite()),
            "{}",
            path.display()
        );
    }
}

/// Paper 000 Fig. 8 (triangle counts; "about 800" for the letter B), paper 001's table (exact
/// triangle counts) and paper 002 Figs. 3 and 8 (exact counts).
#[test]
fn triangle_counts_match_the_papers() {
    for r in REFERENCES {
        let (scene, _) = stats_of(r.scene);
        let n = scene.triangle_count() as f64;
        if r.exact {
            assert_eq!(
                scene.triangle_count() as u64,
                r.triangles,
                "{} ({} {})",
                r.scene,
                r.paper,
                r.source
            );
        } else {
            // Paper 000 says "about 800": held to 5%.
            assert!(
                within(n, r.triangles as f64, 0.05),
                "{}: {n} triangles vs about {}",
                r.scene,
                r.triangles
            );
        }
    }
}

/// Paper 002 Figs. 3 and 8: average triangle size of the PLB head (4.4 px), polio (6.7 px),
/// terrain (2.8 px) and CT head (4 px) at 640x512 over each model's viewing sequence, each
/// within 5%, both measured geometrically and as the rasterizer's pixels per set-up
/// triangle. The sequence is sampled at 14 to 16 evenly spaced frames to keep the test fast.
#[test]
fn paper_002_standins_match_mean_triangle_area_within_5_percent() {
    use sortsim::scene::stats::rasterized;
    let mut failures = Vec::new();
    for name in [
        "plb-head-standin",
        "polio-standin",
        "polio-whole-standin",
        "terrain-standin",
        "ct-head-standin",
    ] {
        let r = reference(name).unwrap();
        let scene = load(name);
        let n = scene.frame_count();
        let frames: Vec<u32> = (0..n).step_by((n as usize).div_ceil(16)).collect();
        let (mut geo, mut ras) = (0.0, 0.0);
        for f in &frames {
            let frame = scene.frame(*f).unwrap();
            geo += geometric(&frame).mean_area_px;
            ras += rasterized(&frame).mean_area_px;
        }
        let (geo, ras) = (geo / frames.len() as f64, ras / frames.len() as f64);
        let paper = r.mean_area_px.unwrap();
        eprintln!(
            "{name}: mean {geo:.3} px, rasterized {ras:.3} px (paper {paper}) over {} frames",
            frames.len()
        );
        if !within(geo, paper, 0.05) || !within(ras, paper, 0.05) {
            failures.push(format!(
                "{name}: mean {geo:.3} px (rasterized {ras:.3}) vs paper {paper} px ({})",
                r.source
            ));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Paper 003 Table 1: primitives, mean size and depth complexity within 10% (geometric depth
/// complexity: sum of on-screen areas / screen area).
#[test]
fn paper_003_standins_match_primitives_size_and_depth_within_10_percent() {
    for r in REFERENCES.iter().filter(|r| r.paper == "003") {
        let (_, s) = stats_of(r.scene);
        let (mean, d) = (r.mean_area_px.unwrap(), r.depth_complexity.unwrap());
        eprintln!(
            "{}: drawn {} mean {:.2} (paper {mean}) d {:.3} (paper {d})",
            r.scene, s.on_screen, s.mean_area_px, s.depth_complexity
        );
        assert!(
            within(s.on_screen as f64, r.triangles as f64, 0.10),
            "{}: {} primitives drawn",
            r.scene,
            s.on_screen
        );
        assert!(
            within(s.mean_area_px, mean, 0.10),
            "{}: mean {:.2} px vs {mean}",
            r.scene,
            s.mean_area_px
        );
        assert!(
            within(s.depth_complexity, d, 0.10),
            "{}: d {:.3} vs {d}",
            r.scene,
            s.depth_complexity
        );
    }
}

/// Paper 003 Table 1 again, now counted by the real rasterizer: pixels rendered per
/// primitive and depth complexity within 10%, and p_d sums to 1 with active pixels = A(1 - p_0).
#[test]
fn paper_003_standins_rasterized_depth_complexity_within_10_percent() {
    use sortsim::scene::stats::rasterized;
    let mut failures = Vec::new();
    for r in REFERENCES.iter().filter(|r| r.paper == "003") {
        let (scene, _) = stats_of(r.scene);
        let frame = scene.frame(0).unwrap();
        let s = rasterized(&frame);
        let (mean, d) = (r.mean_area_px.unwrap(), r.depth_complexity.unwrap());
        eprintln!(
            "{}: set up {} mean {:.2} (paper {mean}) d {:.3} (paper {d}) active {}",
            r.scene,
            s.counters.triangles_set_up,
            s.mean_area_px,
            s.depth_complexity,
            s.active_pixels
        );
        if !within(s.mean_area_px, mean, 0.10)
            || !within(s.depth_complexity, d, 0.10)
            || !within(s.counters.triangles_set_up as f64, r.triangles as f64, 0.10)
        {
            failures.push(format!(
                "{}: {} set up, mean {:.2} vs {mean}, d {:.3} vs {d}",
                r.scene, s.counters.triangles_set_up, s.mean_area_px, s.depth_complexity
            ));
        }
        let p = s.p_d(frame.width, frame.height);
        assert!(
            (p.iter().sum::<f64>() - 1.0).abs() < 1e-9,
            "{}: p_d sums to {}",
            r.scene,
            p.iter().sum::<f64>()
        );
        let a = (frame.width * frame.height) as f64;
        assert!(
            (s.active_pixels as f64 - a * (1.0 - p[0])).abs() < 0.5,
            "{}",
            r.scene
        );
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Paper 002: "overlap factor with 256 regions: 1.09 to 1.4" for its models; the stand-ins'
/// rasterized overlap factor for a 16 x 16 grid of 40 x 32 regions must fall in that range
/// widened by 10% on each side.
#[test]
fn paper_002_standins_overlap_factor_for_256_regions_in_published_range() {
    use sortsim::scene::stats::raster_overlap_factor;
    for name in [
        "plb-head-standin",
        "polio-standin",
        "polio-whole-standin",
        "terrain-standin",
        "ct-head-standin",
    ] {
        let (scene, _) = stats_of(name);
        let o = raster_overlap_factor(&scene.frame(0).unwrap(), 40, 32);
        eprintln!("{name}: overlap factor {o:.3}");
        assert!(
            (1.09 * 0.9..=1.4 * 1.1).contains(&o),
            "{name}: overlap factor {o:.3} outside 1.09..1.4 (paper 002)"
        );
    }
}

/// The `scene-stats` summary puts achieved and published numbers side by side.
#[test]
fn summary_prints_achieved_next_to_paper_numbers() {
    let scene = load("p003-cube");
    let s = sortsim::scene::summary::summary(&scene, 0).unwrap();
    let text = s.to_string();
    eprintln!("{text}");
    assert!(text.contains("stands in for paper 003"), "{text}");
    let d_line = text
        .lines()
        .find(|l| l.starts_with("depth complexity d (rasterized)"))
        .unwrap();
    assert!(
        d_line.contains("8.009") && d_line.trim_end().ends_with("8.01"),
        "{d_line}"
    );
    assert!(text.contains("depth histogram: p0="), "{text}");
}

/// Paper 000 (Fig. 8 scenes, 512x512): share of pixels supersampled, compared with the
/// pixels a visible polygon edge passes through, averaged over each animation. The letter B
/// must stay under the paper's 5%. The tetrahedra are held to 25% relative: the paper says
/// "about" and the estimate counts only edges that change a pixel centre's primitive, so it
/// reads low (the 3000-tetrahedra stand-in reaches 41% against "about 50%").
#[test]
fn paper_000_standins_have_the_published_share_of_edge_pixels() {
    use sortsim::scene::paper::EDGE_REFERENCES;
    use sortsim::scene::stats::edge_pixel_fraction;
    for r in EDGE_REFERENCES {
        let scene = load(r.scene);
        let n = scene.frame_count();
        let sum: f64 = (0..n)
            .map(|f| edge_pixel_fraction(&scene.frame(f).unwrap()))
            .sum();
        let fraction = sum / n as f64;
        eprintln!(
            "{}: edge pixels {:.3} (paper {}: {})",
            r.scene, fraction, r.fraction, r.source
        );
        if r.upper_bound {
            assert!(
                fraction < r.fraction,
                "{}: {fraction:.3} not under {} ({})",
                r.scene,
                r.fraction,
                r.source
            );
        } else {
            assert!(
                within(fraction, r.fraction, 0.25),
                "{}: {fraction:.3} vs {} ({})",
                r.scene,
                r.fraction,
                r.source
            );
        }
    }
}

/// Paper 001's table counts triangles of screen-space files "with backfaces culling
/// performed": every one of the stand-ins' exactly-N triangles faces the camera and lies on
/// screen, and the rasterizer culls almost none.
#[test]
fn paper_001_standins_draw_every_triangle_like_pre_culled_files() {
    use sortsim::scene::stats::rasterized;
    for r in REFERENCES.iter().filter(|r| r.paper == "001") {
        let (scene, s) = stats_of(r.scene);
        assert!(scene.spec().precull, "{}", r.scene);
        assert_eq!(s.front_facing as u64, r.triangles, "{}: {s:?}", r.scene);
        // Refinement may split a triangle on the screen's border so that one half lies
        // wholly outside: allow 0.5% of them.
        assert!(
            (r.triangles - s.on_screen as u64) * 200 <= r.triangles,
            "{}: {s:?}",
            r.scene
        );
        let c = rasterized(&scene.frame(0).unwrap()).counters;
        // Snapping to 1/256 pixel can flatten or flip a sliver on the silhouette that was
        // barely front-facing in floating point; allow 0.5% of them.
        let lost = c.culled_backface + c.culled_zero_area;
        assert!(lost * 200 <= r.triangles, "{}: {c:?}", r.scene);
    }
}

/// The two polio stand-ins share the paper's count (806,640) and mean size (6.7 px) but not
/// what a frame draws: the close-up's frustum holds the far side of the shell, so fewer than
/// a fifth of its in-frustum triangles face the eye, while the whole virus in view draws a
/// third of them (a closed shell seen from 3.2 radii), about six deep. The paper's
/// triangles per second count the frustum's triangles, so this share sets how much
/// rasterization and redistribution each counted triangle brings.
#[test]
fn the_two_polio_standins_draw_different_shares_of_their_frustum() {
    use sortsim::scene::stats::rasterized;
    let share = |name: &str| {
        let frame = load(name).frame(0).unwrap();
        let c = rasterized(&frame).counters;
        let in_frustum = c.triangles_in - c.culled_outside - c.culled_invalid;
        (
            c.triangles_set_up as f64 / in_frustum as f64,
            rasterized(&frame).depth_complexity,
        )
    };
    let (close, close_depth) = share("polio-standin");
    let (whole, whole_depth) = share("polio-whole-standin");
    eprintln!("drawn share of the frustum: close-up {close:.3} (depth {close_depth:.2}), whole {whole:.3} (depth {whole_depth:.2})");
    assert!(close < 0.2, "close-up: {close}");
    assert!((0.3..0.4).contains(&whole), "whole virus: {whole}");
    assert!(whole_depth > 5.0 && close_depth < 1.1);
}
