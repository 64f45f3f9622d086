//! `--instructions` of `sortsim bench`: each side of a comparison counted by valgrind's
//! callgrind inside its own function (src/bench/instructions.rs), the figures a shared
//! machine's noise would hide. valgrind is installed by the tests' shared helper.

use crate::common;

use std::path::Path;
use std::process::Command;

use common::sortsim;

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).expect("written")).expect("JSON")
}

/// PHOLD of 16 x 16 events in flight up to `end`, with `--instructions`: (events, engine's
/// instructions, bare heap's, the printed ratio, the floor executor's).
fn phold_counted(end: &str) -> (u64, u64, u64, f64, u64) {
    let out_dir = common::scratch("phold");
    let out_arg = out_dir.to_str().unwrap();
    let out = sortsim(&[
        "bench",
        "phold",
        "--lps",
        "16",
        "--events-per-lp",
        "16",
        "--end",
        end,
        "--instructions",
        "-o",
        out_arg,
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let summary = json(&out_dir.join("summary.json"));
    let cost = json(&out_dir.join("cost.json"));
    let printed = String::from_utf8_lossy(&out.stdout);
    assert!(
        printed.contains("instructions (callgrind): engine "),
        "{printed}"
    );
    (
        summary["events"].as_u64().unwrap(),
        cost["instructions"]["measured"].as_u64().unwrap(),
        cost["instructions"]["baseline"].as_u64().unwrap(),
        cost["instruction_ratio"].as_f64().unwrap(),
        cost["floor_instructions"].as_u64().unwrap(),
    )
}

#[test]
fn phold_instructions_repeat_exactly_and_grow_with_the_events_alone() {
    common::installed("valgrind", &["valgrind"]);
    let (events, engine, bare, ratio, floor) = phold_counted("200us");
    // The same run counts the same instructions: what the noise cannot move.
    assert_eq!(
        phold_counted("200us"),
        (events, engine, bare, ratio, floor),
        "a second identical run"
    );
    assert_eq!(ratio, bare as f64 / engine as f64);
    // The engine does the bare loop's work (the same draws, a queue) and its own besides; the
    // floor of its design does the bare loop's work and polls a program per event, no more.
    assert!(
        engine > floor && floor > bare,
        "engine {engine}, floor {floor}, bare heap {bare}"
    );
    // Twice the simulated time is about twice the events; each count follows them within 5%
    // (a count that took in the process's start-up, the other loop or the set-up of the 256
    // initial events would not: they do not grow with the events).
    let (events2, engine2, bare2, _, floor2) = phold_counted("400us");
    let grew = events2 as f64 / events as f64;
    assert!(grew > 1.8, "{events} -> {events2} events");
    for (who, before, after) in [
        ("engine", engine, engine2),
        ("bare heap", bare, bare2),
        ("floor", floor, floor2),
    ] {
        let counted = after as f64 / before as f64;
        assert!(
            (counted / grew - 1.0).abs() < 0.05,
            "{who}: instructions grew {counted:.3}x for {grew:.3}x the events"
        );
    }
}

#[test]
fn overhead_counts_the_simulated_frame_and_the_drawing_of_it() {
    common::installed("valgrind", &["valgrind"]);
    let out = sortsim(&[
        "bench",
        "overhead",
        "--scene",
        "scenes/plb-head-standin.json",
        "--procs",
        "4",
        "--fidelity",
        "hops",
        "--instructions",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON report");
    let simulate = report["instructions"]["measured"].as_u64().unwrap();
    let render = report["instructions"]["baseline"].as_u64().unwrap();
    assert_eq!(
        report["instruction_ratio"].as_f64().unwrap(),
        simulate as f64 / render as f64
    );
    // The simulation rasterizes every triangle the sequential drawing does, on 4 processors,
    // and sends them and runs the events besides.
    assert!(simulate > render, "simulate {simulate}, render {render}");
}

#[test]
fn instructions_without_valgrind_are_refused_before_anything_runs() {
    let empty = common::scratch("bin");
    std::fs::create_dir_all(&*empty).unwrap();
    let report = common::scratch("phold");
    let out = Command::new(env!("CARGO_BIN_EXE_sortsim"))
        .args(["bench", "phold", "--instructions", "-o"])
        .arg(&*report)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env("PATH", &*empty)
        .output()
        .expect("sortsim runs");
    common::assert_refused(
        &out,
        "--instructions, no valgrind",
        "apt-get install valgrind",
    );
    assert!(!report.exists(), "nothing written");
    let scale_report = common::scratch("scale");
    for command in [
        &["bench", "overhead", "--procs", "4", "--instructions"][..],
        &[
            "bench",
            "scale",
            "--quick",
            "--instructions",
            "-o",
            scale_report.to_str().unwrap(),
        ][..],
    ] {
        let out = Command::new(env!("CARGO_BIN_EXE_sortsim"))
            .args(command)
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .env("PATH", &*empty)
            .output()
            .expect("sortsim runs");
        common::assert_refused(&out, &command.join(" "), "valgrind is not on the PATH");
    }
    assert!(!scale_report.exists(), "nothing written");
}
