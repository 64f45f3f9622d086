//! Paper 003 (Cox and Hanrahan) as simulated runs on the stand-in scenes (scenes/p003-*.json):
//! direct send's d*A, PixelFlow's n*A and A per link, distributed snooping's expectation
//! A sum p_d H_d and the observed traffic around it, the background-first pathology, the
//! reductions against d*A, and the back-to-front worst case n*A.
//!
//! tests/trace_paper.rs asserts the paper's numbers on trace replay; this file checks that
//! the engine's runs (sort-last/direct-send, pixelflow, snooping) agree with it and with the
//! formulas. Every tolerance has the paper's figure or sentence beside it and the value
//! measured here (seed 1, release build).

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::{Arc, Mutex, OnceLock};

use sortsim::algo::{reference, run, RunResult};
use sortsim::raster::{draw_mesh, CountingTarget, ACTIVE_PIXEL_BYTES};
use sortsim::scene::planes::back_to_front_planes;
use sortsim::scene::Scene;
use sortsim::spec::run::RunSpec;
use sortsim::spec::scene::SceneSpec;
use sortsim::trace::record_scene;
use sortsim::trace::replay::{harmonic, Algo, Assign, DepthStats, Replay, ReplayConfig};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// A stand-in scene, its fragment count d*A and its depth statistics (once per binary).
struct Standin {
    scene: Arc<Scene>,
    fragments: u64,
    stats: DepthStats,
}

fn standin(name: &str) -> &'static Standin {
    static CACHE: OnceLock<Mutex<BTreeMap<String, &'static Standin>>> = OnceLock::new();
    let cache = CACHE.get_or_init(Default::default);
    if let Some(s) = cache.lock().unwrap().get(name) {
        return s;
    }
    let scene = Arc::new(Scene::load(&root().join(format!("scenes/p003-{name}.json"))).unwrap());
    let trace = record_scene(&scene, 0).unwrap();
    let stats = Replay::new(&trace).stats().clone();
    let s: &'static Standin = Box::leak(Box::new(Standin {
        scene,
        fragments: trace.len() as u64,
        stats,
    }));
    cache.lock().unwrap().insert(name.to_string(), s);
    s
}

fn simulate_scene(
    scene: &Arc<Scene>,
    file: &Path,
    algo: &str,
    procs: u32,
    set: &[(&str, &str)],
) -> RunResult {
    let machine = match algo {
        "sort-last/pixelflow" => "pixelflow-pipeline.json",
        "sort-last/direct-send" => "denali-crossbar.json",
        _ => "snooping-bus.json",
    };
    let spec = RunSpec {
        schema: None,
        machine: root().join("machines").join(machine),
        scene: file.to_path_buf(),
        algo: algo.into(),
        procs,
        frames: None,
        seed: 1,
        set: set
            .iter()
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect(),
    };
    run(&spec.resolve(Some(scene.clone())).unwrap()).unwrap()
}

fn simulate(name: &str, algo: &str, procs: u32, set: &[(&str, &str)]) -> RunResult {
    let file = root().join(format!("scenes/p003-{name}.json"));
    simulate_scene(&standin(name).scene, &file, algo, procs, set)
}

/// Pixels a snooping run broadcast (its frame bytes are broadcast pixels only).
fn snooped(name: &str, procs: u32, assign: &str) -> u64 {
    let r = simulate(name, "sort-last/snooping", procs, &[("assign", assign)]);
    r.frames[0].bytes.get() / ACTIVE_PIXEL_BYTES
}

const ALL: [&str; 8] = [
    "bike", "cube", "zinnia", "roses", "washht", "brooks", "capitol", "rad",
];

/// Section 4: "the straightforward algorithm ... sends d*A pixels": direct send without a
/// local z-buffer ships every fragment, exactly (16 processors, every stand-in; d*A is the
/// fragment count of a recording render).
#[test]
fn direct_send_traffic_is_d_times_a() {
    for name in ALL {
        let r = simulate(name, "sort-last/direct-send", 16, &[]);
        let s = standin(name);
        assert_eq!(
            r.frames[0].bytes.get(),
            s.fragments * ACTIVE_PIXEL_BYTES,
            "{name}"
        );
        assert_eq!(s.fragments, s.stats.fragments);
    }
}

/// Section 5: PixelFlow "requires n*A pixels" of traffic, A on every link, exactly, for
/// any scene (7 bytes a pixel: rgb and z).
#[test]
fn pixelflow_traffic_is_n_times_a_and_a_per_link() {
    for (name, procs) in [("zinnia", 64), ("rad", 16), ("cube", 5)] {
        let r = simulate(name, "sort-last/pixelflow", procs, &[]);
        let area = standin(name).stats.area;
        assert_eq!(r.frames[0].bytes.get(), procs as u64 * area * 7, "{name}");
        for node in &r.stats.nodes[..procs as usize - 1] {
            assert_eq!(node.bytes_sent.get(), area * 7, "{name}: A per link");
        }
    }
}

/// Equation 3: the expected snooping traffic is A sum_d p_d H_d. The depth histogram of an
/// independent counting render equals replay's, and the formula computed from it equals
/// replay's `expected` to rounding (relative 1e-12) on every stand-in.
#[test]
fn expected_traffic_is_the_formula() {
    for name in ALL {
        let s = standin(name);
        let g = s.scene.frame(0).unwrap();
        let vp = reference::viewport(&g);
        let mut counting = CountingTarget::new(vp);
        draw_mesh(
            &g.vertices,
            &g.triangles,
            vp,
            &reference::raster_options(&g),
            &mut counting,
        );
        let mut histogram = vec![0u64; 1];
        for &c in counting.counts() {
            let d = c as usize;
            if histogram.len() <= d {
                histogram.resize(d + 1, 0);
            }
            histogram[d] += 1;
        }
        assert_eq!(histogram, s.stats.histogram, "{name}");
        let area = counting.counts().len() as f64;
        let expected: f64 = histogram
            .iter()
            .enumerate()
            .map(|(d, &c)| (c as f64 / area) * harmonic(d as u64))
            .sum::<f64>()
            * area;
        assert!(
            ((expected - s.stats.expected) / expected).abs() < 1e-12,
            "{name}: {expected} vs {}",
            s.stats.expected
        );
    }
}

/// Section 7.2: "in all but one of the simulations, expected traffic is close to observed
/// traffic". Random assignment on 64 processors: every evenly scattered stand-in's simulated
/// run is within 4% of A sum p_d H_d (trace_paper.rs allows 3% for replay's own random
/// stream; the run draws from its own stream; measured -1.7% Roses to +2.4% Zinnia). Brooks
/// and Cube, whose depth piles up over their fitted footprints, are below it (local
/// z-buffering on 64 processors, which the expectation ignores) by less than 6% (measured
/// -5.2% and -1.9%), as trace_paper.rs says.
#[test]
fn random_assignment_observed_is_close_to_expected() {
    for name in ALL {
        let expected = standin(name).stats.expected;
        let observed = snooped(name, 64, "random");
        let ratio = observed as f64 / expected;
        eprintln!("{name}: simulated observed/expected at n=64 (random) {ratio:.4}");
        if ["brooks", "cube"].contains(&name) {
            assert!((0.94..1.0).contains(&ratio), "{name}: {ratio:.4}");
        } else {
            assert!((ratio - 1.0).abs() <= 0.04, "{name}: {ratio:.4}");
        }
    }
}

/// Section 7.2: Zinnia's observed traffic exceeds expected because the background
/// primitive is first in the database, so round-robin gives it to processor 0, the first to
/// broadcast; assigning it last fixes it. Simulated: round-robin more than 4% above expected
/// at 16 and 64 (measured +5.1%, +6.4%; replay +5.0%, +6.3%), background-last within 1% at 64
/// (measured -0.01%).
#[test]
fn zinnia_background_first_exceeds_expected_and_is_fixed() {
    let expected = standin("zinnia").stats.expected;
    for procs in [16, 64] {
        let first = snooped("zinnia", procs, "scatter");
        eprintln!(
            "zinnia n={procs}: background first {:.4} x expected",
            first as f64 / expected
        );
        assert!(first as f64 > 1.04 * expected, "n = {procs}");
        let last = snooped("zinnia", procs, "background-last");
        assert!(last < first, "n = {procs}");
        if procs == 64 {
            let r = last as f64 / expected;
            eprintln!("zinnia n=64: background last {r:.4} x expected");
            assert!((r - 1.0).abs() <= 0.01, "{r:.4}");
        }
    }
}

/// Section 7.2: "traffic is reduced by factors of about 3.3, 4.0, 2.3 and 2.0" (Brooks,
/// Cube, Roses, Wash.ht) at 64 processors, round-robin, simulated on the bus: within 10%,
/// as trace_paper.rs allows replay (measured 3.29, 4.00, 2.31, 1.84; replay 3.29, 4.00,
/// 2.32, 1.85; Brooks' and Cube's are the targets their footprints were fitted to); Bike,
/// Capitol and Rad below 2 (measured 1.63, 1.22, 1.31).
#[test]
fn reductions_against_d_times_a_are_in_the_papers_ranges() {
    let reduction = |name: &str| {
        let s = standin(name);
        let r = s.stats.fragments as f64 / snooped(name, 64, "scatter") as f64;
        eprintln!("{name}: simulated reduction d*A/observed at n=64 = {r:.3}");
        r
    };
    for (name, paper) in [
        ("brooks", 3.3),
        ("cube", 4.0),
        ("roses", 2.3),
        ("washht", 2.0),
    ] {
        let r = reduction(name);
        assert!(((r - paper) / paper).abs() <= 0.10, "{name}: {r:.3}");
    }
    for name in ["bike", "capitol", "rad"] {
        assert!(reduction(name) < 2.0, "{name}");
    }
}

/// Section 7.1, the worst case: "planes ... sorted back to front, one per processor" make
/// every processor broadcast its whole screen: n*A. Big triangles covering a 64x48 screen,
/// triangle k on processor k (round-robin), each nearer the eye than the one before.
#[test]
fn back_to_front_planes_broadcast_n_times_a() {
    for n in [1u32, 4, 9] {
        let json = back_to_front_planes(n);
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join(format!("back-to-front-planes-{n}.json"));
        std::fs::write(&file, &json).unwrap();
        let spec: SceneSpec = serde_json::from_str(&json).unwrap();
        let scene = Arc::new(Scene::from_spec(&file, spec).unwrap());
        let r = simulate_scene(&scene, &file, "sort-last/snooping", n, &[]);
        let area = 64 * 48;
        let broadcast = r.frames[0].bytes.get() / ACTIVE_PIXEL_BYTES;
        assert_eq!(broadcast, n as u64 * area, "n = {n}");
        // Every primitive has fragments here, so replay's own round-robin deal is the run's:
        // `sortsim trace replay` on this scene's trace reports the same count.
        let trace = record_scene(&scene, 0).unwrap();
        let report = Replay::new(&trace).run(&ReplayConfig {
            algos: vec![Algo::Snooping],
            procs: vec![n],
            assign: Assign::Scatter,
            seed: 1,
            local_zbuffer: false,
        });
        assert_eq!(report.rows[0].pixels, broadcast, "n = {n}: replay agrees");
        let (expected, _) = reference::render(&scene.frame(0).unwrap());
        assert_eq!(r.image.hash(), expected.hash());
    }
}
