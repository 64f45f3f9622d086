//! `sortsim calibrate` end to end on paper 001's uniprocessor times (the cheapest paper to
//! run): the fit never ends worse than it started, stays inside its ranges, writes a machine
//! that `sortsim check` accepts with its source updated, lists every target, and is
//! reproducible. A spec naming a row the paper does not have is bad input.

mod common;

use std::path::Path;
use std::process::{Command, Output};

use serde_json::Value;

fn sortsim(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sortsim"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("sortsim runs")
}

fn pipeline() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("machines/multicluster-pipeline.json")
}

/// A spec fitting the pipeline's cpu costs to `targets` of paper 001.
fn spec(dir: &Path, targets: &[&str], max_evaluations: u32) -> String {
    spec_of(dir, &pipeline(), None, targets, max_evaluations)
}

/// A spec fitting `machine` (standing in for `replaces`, if given).
fn spec_of(
    dir: &Path,
    machine: &Path,
    replaces: Option<&str>,
    targets: &[&str],
    max_evaluations: u32,
) -> String {
    let mut text = serde_json::json!({
        "machine": machine,
        "paper": "001",
        "targets": targets,
        "parameters": [{"name": "cpu costs", "fields": ["cpu.costs.*"], "range": [0.5, 2.0]}],
        "max_evaluations": max_evaluations
    });
    if let Some(name) = replaces {
        text["replaces"] = name.into();
    }
    let file = dir.join("fit.json");
    std::fs::write(&file, text.to_string()).unwrap();
    file.to_str().unwrap().to_string()
}

fn fit(dir: &Path, out: &str) -> Value {
    let file = spec(
        dir,
        &[
            "uni-zbuffer-teapot",
            "uni-zbuffer-misc3",
            "uni-scanline-tetra",
        ],
        4,
    );
    let run = sortsim(&["calibrate", &file, "--jobs", "2", "-o", out]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    serde_json::from_str(&std::fs::read_to_string(Path::new(out).join("calibration.json")).unwrap())
        .unwrap()
}

#[test]
fn a_fit_improves_or_keeps_its_start_and_writes_a_valid_machine() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    let c = fit(dir.path(), a.to_str().unwrap());
    let (start, fitted) = (
        c["start_cost"].as_f64().unwrap(),
        c["fitted_cost"].as_f64().unwrap(),
    );
    assert!(fitted <= start, "fitted {fitted} > start {start}");
    let factor = c["factors"][0][1].as_f64().unwrap();
    assert!((0.5..=2.0).contains(&factor), "{factor}");
    assert_eq!(c["rows"].as_array().unwrap().len(), 3);
    let machine = a.join("multicluster-pipeline.json");
    let check = sortsim(&["check", machine.to_str().unwrap()]);
    assert!(
        check.status.success(),
        "{}",
        String::from_utf8_lossy(&check.stderr)
    );
    let text = std::fs::read_to_string(&machine).unwrap();
    assert!(
        text.contains("Fitted by sortsim calibrate to paper 001"),
        "{text}"
    );
    // The same spec gives the same files.
    fit(dir.path(), b.to_str().unwrap());
    for name in [
        "calibration.json",
        "calibration.md",
        "multicluster-pipeline.json",
        "index.html",
    ] {
        assert_eq!(
            std::fs::read(a.join(name)).unwrap(),
            std::fs::read(b.join(name)).unwrap(),
            "{name}"
        );
    }
}

#[test]
fn a_target_the_paper_does_not_have_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let file = spec(dir.path(), &["uni-zbuffer-teapot", "uni-zbuffer-quake"], 4);
    let out = sortsim(&[
        "calibrate",
        &file,
        "-o",
        dir.path().join("o").to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("uni-zbuffer-quake") && err.contains("papers/001.json"),
        "{err}"
    );
    let file = spec(dir.path(), &["pc-beats-df"], 4);
    let out = sortsim(&["calibrate", &file]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("a claim without a number"));
}

#[test]
fn a_machine_the_papers_do_not_use_is_refused_unless_it_names_the_one_it_replaces() {
    let dir = tempfile::tempdir().unwrap();
    let renamed = dir.path().join("pipeline-start.json");
    std::fs::copy(pipeline(), &renamed).unwrap();
    let out_dir = dir.path().join("o");
    let out = out_dir.to_str().unwrap();
    let targets = ["uni-zbuffer-teapot"];
    // Under its own name the candidates would never be run: the fit would search a flat cost.
    let file = spec_of(dir.path(), &renamed, None, &targets, 2);
    let refused = sortsim(&["calibrate", &file, "-o", out]);
    common::assert_refused(&refused, "a renamed machine", "pipeline-start.json");
    common::assert_refused(&refused, "a renamed machine", "replaces");
    let file = spec_of(
        dir.path(),
        &renamed,
        Some("multicluster-pipeline.json"),
        &targets,
        2,
    );
    let run = sortsim(&["calibrate", &file, "--jobs", "1", "-o", out]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let c: Value =
        serde_json::from_str(&std::fs::read_to_string(out_dir.join("calibration.json")).unwrap())
            .unwrap();
    // The candidates stood in for the bundled machine the paper's experiments use.
    assert_eq!(c["machine"], "multicluster-pipeline.json", "{c}");
}
