//! `sortsim utilization` end to end: a small run prints the Figure 4 table and writes its
//! files; bad flags get one clear message and exit code 2.
//!
//! Must never check numbers (tests/utilization_paper.rs does): only the command's contract.

use crate::common;

use std::process::{Command, Output};

fn sortsim(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sortsim"))
        .arg("utilization")
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("sortsim runs")
}

fn temp_dir(name: &str) -> common::Scratch {
    common::scratch(name)
}

const SCENE: &str = "scenes/plb-head-standin.json";

#[test]
fn a_small_run_prints_the_table_and_writes_its_files() {
    let dir = temp_dir("utilization");
    let out = sortsim(&[
        SCENE,
        "--procs",
        "2,4,...,16",
        "--granularity",
        "1,4",
        "--frames",
        "3..7",
        "--frame-step",
        "2",
        "-o",
        dir.to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("2 of 80 frames"), "{stdout}");
    assert!(
        stdout.contains(
            "Expected rasterization utilization (%), bin packing on the current frame's counts"
        ),
        "{stdout}"
    );
    assert!(stdout.contains("previous frame's counts"), "{stdout}");
    assert!(stdout.contains("Relative execution time"), "{stdout}");
    let csv = std::fs::read_to_string(dir.join("utilization.csv")).unwrap();
    // Header plus 3 modes x 4 processor counts x 2 ratios.
    assert_eq!(csv.lines().count(), 1 + 3 * 4 * 2, "{csv}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("utilization.json")).unwrap())
            .unwrap();
    assert_eq!(json["frames"], serde_json::json!([3, 5]));
    // Identical inputs, identical files.
    let again = temp_dir("utilization-again");
    assert!(sortsim(&[
        SCENE,
        "--procs",
        "2,4,...,16",
        "--granularity",
        "1,4",
        "--frames",
        "3..7",
        "--frame-step",
        "2",
        "-o",
        again.to_str().unwrap()
    ])
    .status
    .success());
    assert_eq!(
        csv,
        std::fs::read_to_string(again.join("utilization.csv")).unwrap()
    );
}

#[test]
fn bad_flags_exit_2_with_one_clear_message() {
    let cases: [(&[&str], &str); 7] = [
        (&["--granularity", "0,4"], "--granularity: 0 is not allowed"),
        (&["--procs", "0"], "--procs: 0 is not allowed"),
        (&["--procs", ""], "--procs"),
        (&["--granularity", "4..1"], "is an empty range"),
        (&["--procs", "2,4,...,101"], "never reaches 101"),
        (&["--frames", "70..99"], "--frames"),
        (
            &["--procs", "4096", "--granularity", "100"],
            "do not fit a 640x512 screen",
        ),
    ];
    for (args, message) in cases {
        let mut all = vec![SCENE];
        if !args.contains(&"--frames") {
            all.extend(["--frames", "0..1"]);
        }
        all.extend_from_slice(args);
        let out = sortsim(&all);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(message), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    }
}
