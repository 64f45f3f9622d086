//! Sort-middle runs end to end: the parallel image equals the sequential one, message counts
//! are what the algorithm's structure dictates, outputs are deterministic, and the event
//! count follows messages, not pixels.

use crate::common;

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;

use sortsim::algo::{reference, run, RunResult};
use sortsim::scene::Scene;
use sortsim::spec::run::RunSpec;

fn spec(machine: &str, scene: &str, algo: &str, procs: u32, set: &[(&str, &str)]) -> RunSpec {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    RunSpec {
        schema: None,
        machine: root.join("machines").join(machine),
        scene: root.join("scenes").join(scene),
        algo: algo.into(),
        procs,
        frames: None,
        seed: 1,
        set: set
            .iter()
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect::<BTreeMap<_, _>>(),
    }
}

fn simulate(spec: &RunSpec) -> RunResult {
    run(&spec.resolve(None).expect("valid run")).expect("the run completes")
}

#[test]
fn parallel_images_equal_the_sequential_image() {
    let scene = Arc::new(
        Scene::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/spd-gears.json")).unwrap(),
    );
    let (expected, _) = reference::render(&scene.frame(0).unwrap());
    type Case<'a> = (&'a str, u32, &'a [(&'a str, &'a str)]);
    let cases: &[Case] = &[
        ("sort-middle/static", 1, &[]),
        ("sort-middle/static", 3, &[]),
        ("sort-middle/static", 7, &[]),
        ("sort-middle/ellsworth", 2, &[]),
        ("sort-middle/ellsworth", 5, &[("granularity", "3")]),
        ("sort-middle/ellsworth", 16, &[("two-step", "on")]),
        (
            "sort-middle/ellsworth",
            9,
            &[("counts", "current"), ("buffer", "1KiB")],
        ),
    ];
    for (algo, procs, set) in cases {
        let mut s = spec("delta.json", "spd-gears.json", algo, *procs, set);
        s.set
            .insert("machine.network.fidelity".into(), "flow".into());
        let cfg = s.resolve(Some(scene.clone())).unwrap();
        let result = run(&cfg).unwrap();
        assert_eq!(
            result.image.hash(),
            expected.hash(),
            "{algo} on {procs} processors with {set:?}"
        );
    }
}

/// Polygon messages of one frame: everything but the tree messages (one Start and one Done
/// per tree edge, plus one Counts per edge for Ellsworth's summing tree).
fn polygon_messages(result: &RunResult, procs: u64, trees: u64) -> u64 {
    result.frames[0].messages - trees * (procs - 1)
}

#[test]
fn with_buffers_large_enough_every_stream_is_one_message() {
    // Paper 002, Two-step redistribution: N(g-1) + N^2/g - N messages per frame, exactly,
    // when each stream fits one message; one-step needs N(N-1).
    for (n, g) in [(16u64, 4u64), (36, 6), (64, 8)] {
        let one = simulate(&spec(
            "delta.json",
            "spd-teapot.json",
            "sort-middle/ellsworth",
            n as u32,
            &[
                ("buffer", "1MiB"),
                ("machine.memory.capacity_per_node", "256MiB"),
            ],
        ));
        assert_eq!(polygon_messages(&one, n, 3), n * (n - 1), "one-step, N={n}");
        let two = simulate(&spec(
            "delta.json",
            "spd-teapot.json",
            "sort-middle/ellsworth",
            n as u32,
            &[
                ("buffer", "1MiB"),
                ("machine.memory.capacity_per_node", "256MiB"),
                ("two-step", "on"),
            ],
        ));
        assert_eq!(
            polygon_messages(&two, n, 3),
            n * (g - 1) + n * n / g - n,
            "two-step, N={n}, g={g}"
        );
    }
}

#[test]
fn two_runs_write_byte_identical_summaries() {
    let (a, b) = (common::scratch("a"), common::scratch("b"));
    for dir in [&a, &b] {
        let status = std::process::Command::new(env!("CARGO_BIN_EXE_sortsim"))
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .args([
                "run",
                "--machine",
                "machines/delta.json",
                "--scene",
                "scenes/plb-head-standin.json",
            ])
            .args([
                "--algo",
                "sort-middle/ellsworth",
                "--procs",
                "12",
                "--frames",
                "0..3",
                "--set",
                "two-step=on",
            ])
            .args(["-o", dir.to_str().unwrap()])
            .output()
            .unwrap();
        assert!(
            status.status.success(),
            "{}",
            String::from_utf8_lossy(&status.stderr)
        );
    }
    let summary = std::fs::read(a.join("summary.json")).unwrap();
    assert_eq!(summary, std::fs::read(b.join("summary.json")).unwrap());
    for f in ["summary.md", "cost.json", "timeline.json", "frame-0002.png"] {
        assert!(a.join(f).exists(), "{f} written");
    }
    let timeline_bytes = std::fs::read(a.join("timeline.json")).unwrap();
    assert_eq!(
        timeline_bytes,
        std::fs::read(b.join("timeline.json")).unwrap()
    );
    let timeline: serde_json::Value = serde_json::from_slice(&timeline_bytes).unwrap();
    let events = timeline["traceEvents"].as_array().unwrap();
    assert!(events.len() > 12, "one track per node plus work");
    // Every stretch of cpu work is in the timeline: its spans add up to each node's busy time
    // in summary.json (microseconds printed to six decimals, so to a nanosecond a span).
    let summary: serde_json::Value = serde_json::from_slice(&summary).unwrap();
    for node in summary["machine_metrics"]["nodes"].as_array().unwrap() {
        let id = node["node"].as_u64().unwrap();
        let spans: Vec<f64> = events
            .iter()
            .filter(|e| e["ph"] == "X" && e["pid"] == 0 && e["tid"].as_u64() == Some(id))
            .map(|e| e["dur"].as_f64().unwrap())
            .collect();
        let busy_us = node["busy_s"].as_f64().unwrap() * 1e6;
        let tolerance_us = 1e-3 * spans.len() as f64 + 1e-6 * busy_us;
        assert!(
            (spans.iter().sum::<f64>() - busy_us).abs() <= tolerance_us,
            "node {id}: timeline spans {} us against busy {busy_us} us",
            spans.iter().sum::<f64>()
        );
    }
    // The final frame's image is what `sortsim render` draws.
    let scene =
        Scene::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/plb-head-standin.json"))
            .unwrap();
    let (image, _) = reference::render(&scene.frame(2).unwrap());
    let mut png = Vec::new();
    sortsim::raster::encode_png(&image, &mut png).unwrap();
    assert_eq!(png, std::fs::read(a.join("frame-0002.png")).unwrap());
}

#[test]
fn events_follow_messages_not_pixels() {
    // The same geometry at 4x the pixels: rasterization work quadruples, events must not.
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut scene: serde_json::Value =
        serde_json::from_slice(&std::fs::read(root.join("scenes/spd-teapot.json")).unwrap())
            .unwrap();
    scene["resolution"] = serde_json::json!([1024, 1024]);
    let big = common::scratch("teapot-1024.json");
    std::fs::write(&*big, serde_json::to_vec(&scene).unwrap()).unwrap();
    let small = simulate(&spec(
        "delta.json",
        "spd-teapot.json",
        "sort-middle/static",
        8,
        &[],
    ));
    let mut large_spec = spec(
        "delta.json",
        "spd-teapot.json",
        "sort-middle/static",
        8,
        &[],
    );
    large_spec.scene = big.to_path_buf();
    let large = simulate(&large_spec);
    let pixels = |r: &RunResult| {
        r.stats
            .nodes
            .iter()
            .map(|n| n.busy())
            .sum::<sortsim::units::SimTime>()
    };
    assert!(
        pixels(&large) > pixels(&small),
        "more pixels cost more simulated time"
    );
    let (e_small, e_large) = (small.stats.events as f64, large.stats.events as f64);
    let (m_small, m_large) = (
        small.frames[0].messages as f64,
        large.frames[0].messages as f64,
    );
    // 64x64 regions: 4x the regions at 1024^2, so messages grow too; events must grow no
    // faster than messages (within 20%: batches of triangles are per buffer, not per pixel).
    assert!(
        e_large / e_small <= 1.2 * (m_large / m_small),
        "events {e_small} -> {e_large}, messages {m_small} -> {m_large}"
    );
}

#[test]
fn recording_a_timeline_changes_no_result() {
    // DESIGN principle 3: an effect switched on for observation must not change what is
    // simulated (the timeline and link occupancy only watch).
    let spec = spec(
        "delta.json",
        "spd-teapot.json",
        "sort-middle/ellsworth",
        6,
        &[("two-step", "on")],
    );
    let mut cfg = spec.resolve(None).unwrap();
    let plain = run(&cfg).unwrap();
    cfg.timeline = true;
    let watched = run(&cfg).unwrap();
    assert!(
        plain.stats.timeline.is_none()
            && watched
                .stats
                .timeline
                .as_ref()
                .is_some_and(|t| !t.is_empty())
    );
    assert_eq!(plain.frames, watched.frames);
    assert_eq!(plain.stats.events, watched.stats.events);
    assert_eq!(plain.stats.nodes, watched.stats.nodes);
    assert_eq!(plain.stats.links, watched.stats.links);
    assert_eq!(plain.image.hash(), watched.image.hash());
}

/// `--timeline-frames`: the timeline of some frames is the whole run's timeline cut where the
/// first of them begins and where the frame after them begins (cpu spans in the order they
/// began; none runs across a frame's beginning), and the run is the same run.
#[test]
fn a_timeline_of_some_frames_is_the_whole_timeline_cut_at_their_beginnings() {
    for (machine, algo, procs) in [
        ("delta.json", "sort-middle/ellsworth", 6),
        ("pixelflow-pipeline.json", "sort-last/pixelflow", 4),
    ] {
        let mut s = spec(machine, "plb-head-standin.json", algo, procs, &[]);
        s.frames = Some("0..3".into());
        let mut cfg = s.resolve(None).unwrap();
        cfg.timeline = true;
        let whole = run(&cfg).unwrap();
        cfg.timeline_frames = Some(1..2);
        let part = run(&cfg).unwrap();
        assert_eq!(whole.frames, part.frames, "{algo}");
        assert_eq!(whole.stats.nodes, part.stats.nodes, "{algo}");
        assert_eq!(whole.image.hash(), part.image.hash(), "{algo}");

        let (all, cut) = (
            whole.stats.timeline.as_deref().unwrap(),
            part.stats.timeline.as_deref().unwrap(),
        );
        assert!(
            !cut.is_empty() && cut.len() < all.len(),
            "{algo}: {} of {} spans",
            cut.len(),
            all.len()
        );
        let from = all
            .iter()
            .position(|s| *s == cut[0])
            .expect("the cut's first span is in the whole");
        let to = from + cut.len();
        assert_eq!(
            &all[from..to],
            cut,
            "{algo}: the cut is one stretch of the whole"
        );
        let (begins, next_begins) = (whole.frames[1].start, whole.frames[2].start);
        assert!(
            cut.iter().all(|s| s.start >= begins),
            "{algo}: a span of the cut starts before frame 1 begins at {begins}"
        );
        assert!(
            all[to..].iter().all(|s| s.start >= next_begins),
            "{algo}: a span left out after the cut starts before frame 2 begins at {next_begins}"
        );
        if let Some(links) = part.stats.link_timeline.as_deref() {
            assert!(
                links.iter().all(|l| l.start >= begins),
                "{algo}: link occupancy before frame 1"
            );
        }
    }
}

/// Paper 002 measures a frame rate over a viewing sequence, so whatever processor 0 waits for
/// between frames belongs to a frame: with the previous frame's counts each frame begins where
/// the one before ended, and a summing tree slower than a frame lengthens the next frame (it
/// once fell between frames and made the load balancing free).
#[test]
fn ellsworth_frames_follow_each_other_and_count_the_summing_tree() {
    let run = |count_sum: &str| {
        let mut s = spec(
            "delta.json",
            "plb-head-standin.json",
            "sort-middle/ellsworth",
            64,
            &[("machine.cpu.costs.count_sum", count_sum)],
        );
        s.frames = Some("0..3".into());
        simulate(&s)
    };
    let regions = 8 * 64u64; // the default granularity ratio 8, 64 processors
    for count_sum_us in [0.43f64, 100.0] {
        let r = run(&format!("{count_sum_us}us"));
        for pair in r.frames.windows(2) {
            assert_eq!(
                pair[1].start, pair[0].end,
                "frame {} begins where {} ends",
                pair[1].frame, pair[0].frame
            );
        }
        if count_sum_us == 100.0 {
            // Processor 0 sums at least one child's counts for every region before frame 1's
            // regions can be assigned.
            let floor = 100e-6 * regions as f64;
            let frame_1 = r.frames[1].time().as_secs_f64();
            assert!(
                frame_1 >= floor,
                "frame 1 took {frame_1} s, the summing alone {floor} s"
            );
        }
    }
}

#[test]
fn rasterizers_wait_longer_for_polygons_over_slower_links() {
    let run = |bandwidth: &str| {
        let mut s = spec(
            "delta.json",
            "plb-head-standin.json",
            "sort-middle/ellsworth",
            64,
            &[("machine.network.link_bandwidth", bandwidth)],
        );
        s.frames = Some("0..2".into());
        simulate(&s)
    };
    let total_wait = |r: &RunResult| -> f64 {
        r.frames
            .iter()
            .flat_map(|f| f.polygon_wait.iter())
            .map(|w| w.as_secs_f64())
            .sum()
    };
    // At the Delta's 17 MB/s every polygon of the PLB head is in before its rasterizer asks.
    let (fast, slow) = (run("1.7MB/s"), run("0.17MB/s"));
    for r in [&fast, &slow] {
        for f in &r.frames {
            for (node, (&wait, &finish)) in f.polygon_wait.iter().zip(&f.raster_finish).enumerate()
            {
                assert!(
                    wait <= finish - f.start,
                    "frame {}, node {node}: waited {wait} for polygons within a rasterization that ended {} after the frame began",
                    f.frame,
                    finish - f.start
                );
            }
        }
    }
    let (fast_wait, slow_wait) = (total_wait(&fast), total_wait(&slow));
    assert!(
        fast_wait > 0.0,
        "no rasterizer ever waited for a polygon message at 1.7 MB/s ({slow_wait} s at 0.17 MB/s)"
    );
    assert!(
        slow_wait > 2.0 * fast_wait,
        "links 10 times slower: the rasterizers waited {slow_wait} s against {fast_wait} s"
    );
}
