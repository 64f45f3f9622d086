//! Sweeps end to end through `sweep::run_sweep` on a small scene: the table and plots are
//! byte-identical whatever the thread count, an interrupted sweep resumes without touching
//! finished points, and speedup is the triangles/s ratio to the one-processor point (run
//! implicitly when the sweep does not list it).

use crate::common;

use std::path::{Path, PathBuf};

use sortsim::sweep::spec::{parse_sweep, Sweep};
use sortsim::sweep::{run_sweep, SweepOptions, SweepOutcome};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn out_dir(name: &str) -> common::Scratch {
    common::scratch(name)
}
/// Both sort-middle algorithms on the Delta, PLB head stand-in, two frames. The cpu costs are
/// set here so that the test does not depend on the Delta's calibration (and a one-processor
/// run takes time).
fn spec(procs: &str) -> Sweep {
    let json = format!(
        r#"{{"machine": "machines/delta.json", "scene": "scenes/plb-head-standin.json",
            "algos": ["sort-middle/static", "sort-middle/ellsworth"], "procs": {procs}, "frames": "0..2",
            "set": {{"machine.cpu.costs": "{{\"transform_vertex\": \"1us\", \"setup_triangle\": \"3us\", \"pixel_write\": \"80ns\"}}"}}}}"#
    );
    parse_sweep(&root().join("test-sweep.json"), &json).unwrap_or_else(|e| panic!("{e}"))
}

fn run(sweep: &Sweep, dir: &Path, jobs: usize) -> SweepOutcome {
    run_sweep(
        sweep,
        dir,
        SweepOptions {
            jobs,
            progress: false,
        },
    )
    .unwrap_or_else(|e| panic!("{e}"))
}

fn read(path: &Path) -> Vec<u8> {
    std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The summary.json of the point under `dir` whose folder name contains `fragment`.
fn point_summary(dir: &Path, fragment: &str) -> serde_json::Value {
    let point = std::fs::read_dir(dir.join("points"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.to_str().unwrap().contains(fragment))
        .unwrap_or_else(|| panic!("no point named like {fragment} ran"));
    serde_json::from_slice(&read(&point.join("summary.json"))).unwrap()
}

/// Every file under `dir` except the host-dependent cost files, by relative path.
fn deterministic_files(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.file_name().unwrap() != "cost.json" {
                out.push((p.strip_prefix(dir).unwrap().to_path_buf(), read(&p)));
            }
        }
    }
    out.sort();
    out
}

#[test]
fn thread_count_does_not_change_a_byte() {
    let sweep = spec("[1, 4, 16]");
    let (a, b) = (out_dir("jobs1"), out_dir("jobs2"));
    let one = run(&sweep, &a, 1);
    let two = run(&sweep, &b, 2);
    assert_eq!((one.ran, two.ran), (6, 6));
    assert_eq!(one.rows, two.rows);
    let (fa, fb) = (deterministic_files(&a), deterministic_files(&b));
    let names: Vec<_> = fa.iter().map(|(p, _)| p.clone()).collect();
    assert!(
        names.contains(&PathBuf::from("sweep.csv")) && names.contains(&PathBuf::from("sweep.json"))
    );
    for stem in [
        "triangles-per-s",
        "speedup",
        "efficiency",
        "traffic-per-frame",
        "load-imbalance",
        "memory-per-node",
    ] {
        for ext in ["svg", "png"] {
            let p = PathBuf::from(format!("plots/{stem}.{ext}"));
            assert!(names.contains(&p), "{} written", p.display());
        }
    }
    assert_eq!(
        fa.len(),
        2 + 12 + 6 + 1,
        "table, plots, one summary.json per point, the page: {names:?}"
    );
    for ((pa, ba), (pb, bb)) in fa.iter().zip(&fb) {
        assert_eq!(pa, pb);
        assert!(ba == bb, "{} differs between 1 and 2 threads", pa.display());
    }
    let csv = String::from_utf8(read(&a.join("sweep.csv"))).unwrap();
    assert_eq!(
        csv.lines().count(),
        7,
        "a header and one line per point:\n{csv}"
    );
    assert!(
        !csv.contains(a.to_str().unwrap()),
        "no output path in the table"
    );
}

#[test]
fn resume_keeps_finished_points_and_runs_the_rest() {
    let sweep = spec("[1, 4]");
    let dir = out_dir("resume");
    let first = run(&sweep, &dir, 2);
    assert_eq!((first.ran, first.skipped), (4, 0));
    let points = dir.join("points");
    let mut folders: Vec<PathBuf> = std::fs::read_dir(&points)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    folders.sort();
    // Tamper with one finished point, and "interrupt" another by removing its summary.
    let kept = folders[0].join("summary.json");
    let text = String::from_utf8(read(&kept)).unwrap();
    let line = text
        .lines()
        .find(|l| l.contains("\"mean_triangles_per_s\""))
        .unwrap();
    let tampered = text.replacen(line, "  \"mean_triangles_per_s\": 12345.5,", 1);
    std::fs::write(&kept, &tampered).unwrap();
    std::fs::remove_file(folders[1].join("summary.json")).unwrap();
    let second = run(&sweep, &dir, 2);
    assert_eq!((second.ran, second.skipped), (1, 3));
    assert_eq!(
        read(&kept),
        tampered.as_bytes(),
        "a finished point is never rewritten"
    );
    assert!(folders[1].join("summary.json").exists());
    let name = folders[0].file_name().unwrap().to_str().unwrap();
    let row = second.rows.iter().find(|r| r.point == name).unwrap();
    assert_eq!(
        row.mean_triangles_per_s,
        Some(12345.5),
        "the table is read from the kept summary"
    );
    let csv = String::from_utf8(read(&dir.join("sweep.csv"))).unwrap();
    assert!(
        csv.lines()
            .any(|l| l.starts_with(name) && l.contains(",12345.5,")),
        "{csv}"
    );
}

#[test]
fn speedup_is_the_triangle_rate_ratio_to_one_processor() {
    let sweep = spec("[4, 16]");
    let dir = out_dir("speedup");
    let outcome = run(&sweep, &dir, 2);
    assert_eq!(
        outcome.ran, 6,
        "4 listed points and 2 implicit one-processor baselines"
    );
    assert_eq!(outcome.rows.len(), 4, "baselines are not rows");
    let baselines: Vec<PathBuf> = std::fs::read_dir(dir.join("points"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.to_str().unwrap().contains("_p0001_"))
        .collect();
    assert_eq!(baselines.len(), 2);
    for row in &outcome.rows {
        let base_dir = baselines
            .iter()
            .find(|p| p.to_str().unwrap().contains(&row.algo.replace('/', "-")))
            .unwrap();
        let base: serde_json::Value =
            serde_json::from_slice(&read(&base_dir.join("summary.json"))).unwrap();
        let base_tps = base["mean_triangles_per_s"].as_f64().unwrap();
        assert!(base_tps > 0.0);
        let tps = row.mean_triangles_per_s.unwrap();
        assert_eq!(row.speedup, Some(tps / base_tps), "{row:?}");
        assert_eq!(row.efficiency, Some(tps / base_tps / f64::from(row.procs)));
        assert!(row.busiest_link_utilization_pct.unwrap() > 0.0);
        assert!(row.peak_node_memory_bytes.unwrap() > 0.0);
        assert!(row.mean_bytes_per_frame.unwrap() > 0.0 && row.error.is_none());
    }
}

#[test]
fn a_speedup_scene_is_the_baseline_of_every_point() {
    // Paper 002, Figure 10: speedups are every model's rate over the single-processor PLB head.
    let json = r#"{"machine": "machines/delta.json", "scene": "scenes/spd-teapot.json",
        "algo": "sort-middle/ellsworth", "procs": [4], "speedup_scene": "scenes/plb-head-standin.json", "frames": "0..1",
        "set": {"machine.cpu.costs": "{\"transform_vertex\": \"1us\", \"setup_triangle\": \"3us\", \"pixel_write\": \"80ns\"}"}}"#;
    let sweep =
        parse_sweep(&root().join("test-sweep.json"), json).unwrap_or_else(|e| panic!("{e}"));
    let dir = out_dir("speedup-scene");
    let outcome = run(&sweep, &dir, 2);
    assert_eq!(
        outcome.ran, 2,
        "the teapot point and the PLB head's one-processor baseline"
    );
    let base = point_summary(&dir, "plb-head");
    let base_tps = base["mean_triangles_per_s"].as_f64().unwrap();
    let row = &outcome.rows[0];
    assert_eq!(
        row.speedup,
        Some(row.mean_triangles_per_s.unwrap() / base_tps)
    );
}

#[test]
fn warm_up_frames_are_left_out_of_the_means() {
    // Ellsworth's first frame deals regions r mod N and waits for no assignment; a sweep with
    // `warmup_frames` averages the frames after it (paper 002's 80-frame averages nearly do).
    let json = r#"{"machine": "machines/delta.json", "scene": "scenes/plb-head-standin.json",
        "algo": "sort-middle/ellsworth", "procs": [16], "frames": "0..3", "warmup_frames": 1,
        "set": {"machine.cpu.costs": "{\"transform_vertex\": \"1us\", \"setup_triangle\": \"3us\", \"pixel_write\": \"80ns\"}"}}"#;
    let sweep =
        parse_sweep(&root().join("test-sweep.json"), json).unwrap_or_else(|e| panic!("{e}"));
    let dir = out_dir("warmup");
    let outcome = run(&sweep, &dir, 2);
    let summary = point_summary(&dir, "_p0016_");
    let frames = summary["per_frame"].as_array().unwrap();
    assert_eq!(frames.len(), 3, "the runs keep every frame");
    let mean = |key: &str| {
        frames[1..]
            .iter()
            .map(|f| f[key].as_f64().unwrap())
            .sum::<f64>()
            / 2.0
    };
    let row = outcome.rows.iter().find(|r| r.procs == 16).unwrap();
    assert_eq!(row.mean_triangles_per_s, Some(mean("triangles_per_s")));
    assert_eq!(row.mean_frame_s, Some(mean("time_s")));
    assert_eq!(row.mean_bytes_per_frame, Some(mean("bytes")));
    assert_ne!(
        row.mean_triangles_per_s,
        summary["mean_triangles_per_s"].as_f64(),
        "the first frame differs from the others, so leaving it out shows"
    );
    let table: serde_json::Value = serde_json::from_slice(&read(&dir.join("sweep.json"))).unwrap();
    assert_eq!(table["warmup_frames"], 1);
}
