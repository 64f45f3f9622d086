//! The bad-trace corpus (paper 003's pixel traces): every file under tests/bad_input/trace/
//! must be refused by `sortsim trace replay` with exit code 2, one message naming the file
//! and containing the fragment EXPECTED.txt lists for it, no panic and no report written.
//! Bad command lines for `trace record` and `trace replay` get the same treatment.

use crate::common;

use std::path::{Path, PathBuf};
use std::process::Output;

use common::sortsim;

/// (file, fragment) pairs; every file in the folder must be listed and every listed file exist.
fn corpus() -> Vec<(PathBuf, String)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/bad_input/trace");
    let expected = std::fs::read_to_string(dir.join("EXPECTED.txt")).unwrap();
    let cases: Vec<(PathBuf, String)> = expected
        .lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .map(|l| {
            let (file, fragment) = l.split_once(": ").expect("`file: fragment` lines");
            (dir.join(file), fragment.to_string())
        })
        .collect();
    let mut listed: Vec<_> = cases.iter().map(|(f, _)| f.clone()).collect();
    let mut present: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.file_name().unwrap() != "EXPECTED.txt")
        .collect();
    listed.sort();
    present.sort();
    assert_eq!(listed, present, "every corpus file has an expectation");
    cases
}

fn check_refusal(out: &Output, name: &str, fragment: &str) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(
        out.status.code(),
        Some(2),
        "{name}: exit code; stderr: {stderr}"
    );
    assert!(
        stderr.contains(fragment),
        "{name}: expected {fragment:?} in: {stderr}"
    );
    assert!(stderr.contains(name), "the message names {name}: {stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "one message: {stderr}");
}

#[test]
fn every_bad_trace_is_refused_with_its_message() {
    let cases = corpus();
    assert!(cases.len() >= 13);
    let out_dir = common::scratch("trace-corpus");
    for (file, fragment) in cases {
        let out = sortsim(&[
            "trace",
            "replay",
            file.to_str().unwrap(),
            "-o",
            out_dir.to_str().unwrap(),
        ]);
        let name = file.file_name().unwrap().to_string_lossy();
        check_refusal(&out, &name, &fragment);
        assert!(!out_dir.exists(), "{name}: no report for a refused trace");
        // `check` knows a trace by its magic bytes and reads it the same way.
        if std::fs::read(&file).unwrap().starts_with(b"SORTTRC\n") {
            check_refusal(
                &sortsim(&["check", file.to_str().unwrap()]),
                &name,
                &fragment,
            );
        }
    }
    let good = sortsim(&["check", "traces/p003-zinnia.trace"]);
    assert!(good.status.success());
    assert!(String::from_utf8_lossy(&good.stdout).contains("trace of frame 0 (1024x768"));
}

#[test]
fn missing_trace_and_bad_flags_are_refused() {
    let out = sortsim(&["trace", "replay", "traces/does-not-exist.trace"]);
    check_refusal(&out, "does-not-exist.trace", "cannot read");
    let out = sortsim(&[
        "trace",
        "replay",
        "traces/p003-zinnia.trace",
        "--procs",
        "0,4",
    ]);
    check_refusal(
        &out,
        "--procs",
        "0 processors is out of range (valid: 1..=65536)",
    );
    let out = sortsim(&[
        "trace",
        "replay",
        "traces/p003-zinnia.trace",
        "--procs",
        "two",
    ]);
    check_refusal(&out, "--procs", "'two'");
    let out = sortsim(&[
        "trace",
        "replay",
        "traces/p003-zinnia.trace",
        "--algo",
        "binary-swap",
    ]);
    assert_eq!(
        out.status.code(),
        Some(2),
        "clap refuses unknown algorithms"
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains("snooping"));
}

#[test]
fn recording_a_bad_scene_or_frame_is_refused() {
    let out_file = common::scratch("recorded.trace");
    let out = sortsim(&[
        "trace",
        "record",
        "scenes/p003-zinnia.json",
        "--frame",
        "5",
        "-o",
        out_file.to_str().unwrap(),
    ]);
    check_refusal(&out, "p003-zinnia.json", "frame 5 is out of range");
    assert!(!out_file.exists());
    let out = sortsim(&[
        "trace",
        "record",
        "tests/bad_input/scene/unknown-generator.json",
        "-o",
        out_file.to_str().unwrap(),
    ]);
    check_refusal(&out, "unknown-generator.json", "klein-bottle");
    assert!(!out_file.exists());
}
