//! The command line end to end: bundled specs validate, outputs are byte-identical across
//! runs of the same inputs.

use crate::common;

use std::path::PathBuf;
use std::process::{Command, Output};

fn sortsim(args: &[&str]) -> Output {
    let out = Command::new(env!("CARGO_BIN_EXE_sortsim"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("sortsim runs");
    assert!(
        out.status.success(),
        "{args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

fn temp_dir(name: &str) -> common::Scratch {
    common::scratch(name)
}

#[test]
fn every_bundled_machine_checks_ok() {
    let mut machines: Vec<String> = std::fs::read_dir("machines")
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .map(|p| p.to_string_lossy().into_owned())
        .collect();
    machines.sort();
    assert!(machines.len() >= 9, "{machines:?}");
    let args: Vec<&str> = std::iter::once("check")
        .chain(machines.iter().map(String::as_str))
        .collect();
    let stdout = String::from_utf8(sortsim(&args).stdout).unwrap();
    assert_eq!(
        stdout.lines().filter(|l| l.starts_with("OK ")).count(),
        machines.len(),
        "{stdout}"
    );
    assert!(
        stdout.contains("machine 'delta': 512 nodes, mesh 16x32, links 17MB/s with 80ns per hop and 168.66us a message at each interface, wormhole switching"),
        "{stdout}"
    );
    // Issue 32: today's machines, with nodes of several processors.
    assert!(
        stdout.contains("machine 'bgp-intrepid-8k': 32768 processors in nodes of 4 (placed cyclically) with 1 NIC on 3400MB/s links with 100ns per hop, joined by a torus 16x16x32, links 425MB/s"),
        "{stdout}"
    );
    assert!(
        stdout.contains("machine 'gpu-cluster-a100': 256 processors in nodes of 8 with 8 NICs on 300GB/s links with 500ns per hop, joined by a fat-tree down [16,16] up [1,16] parallel [1,1], links 25GB/s"),
        "{stdout}"
    );
}

#[test]
fn netsim_twice_gives_byte_identical_json_at_every_fidelity() {
    for fidelity in ["ideal", "hops", "flow", "packet"] {
        let (a, b) = (
            temp_dir(&format!("netsim-a-{fidelity}")),
            temp_dir(&format!("netsim-b-{fidelity}")),
        );
        let run = |dir: &PathBuf| {
            sortsim(&[
                "netsim",
                "machines/multicluster-torus.json",
                "tests/patterns/all-to-all-4x4.json",
                "--fidelity",
                fidelity,
                "-o",
                dir.to_str().unwrap(),
            ])
            .stdout
        };
        let (out_a, out_b) = (run(&a), run(&b));
        assert_eq!(out_a, out_b, "{fidelity}: stdout differs");
        let summary_a = std::fs::read(a.join("summary.json")).unwrap();
        assert_eq!(summary_a, std::fs::read(b.join("summary.json")).unwrap());
        assert_eq!(summary_a, out_a, "summary.json is what was printed");
        assert!(a.join("cost.json").exists());
        let report: serde_json::Value = serde_json::from_slice(&summary_a).unwrap();
        assert_eq!(report["messages"].as_array().unwrap().len(), 240);
        assert_eq!(report["fidelity"], fidelity);
    }
}

/// A PHOLD run whose end comes before its first event measured nothing, and says so rather
/// than print a ratio of zero over zero as if it were one.
#[test]
fn phold_with_no_event_before_its_end_says_nothing_was_measured() {
    let run = |end: &str| {
        let out = sortsim(&[
            "bench",
            "phold",
            "--lps",
            "1",
            "--events-per-lp",
            "1",
            "--end",
            end,
        ]);
        String::from_utf8(out.stdout).unwrap()
    };
    // The lookahead alone is 100ns: nothing can happen by 50ns.
    let empty = run("50ns");
    assert!(empty.contains("engine                0"), "{empty}");
    assert!(
        empty.contains("no event fell at or before --end"),
        "{empty}"
    );
    let some = run("100us");
    assert!(!some.contains("no event fell"), "{some}");
}

#[test]
fn phold_twice_gives_byte_identical_summary() {
    let (a, b) = (temp_dir("phold-a"), temp_dir("phold-b"));
    for dir in [&a, &b] {
        sortsim(&[
            "bench",
            "phold",
            "--lps",
            "64",
            "--events-per-lp",
            "8",
            "--end",
            "200us",
            "--seed",
            "9",
            "-o",
            dir.to_str().unwrap(),
        ]);
    }
    let summary = std::fs::read_to_string(a.join("summary.json")).unwrap();
    assert_eq!(
        summary,
        std::fs::read_to_string(b.join("summary.json")).unwrap()
    );
    let v: serde_json::Value = serde_json::from_str(&summary).unwrap();
    assert_eq!(v["baseline_agrees"], true);
    assert_eq!(v["floor_agrees"], true);
    assert_eq!(v["in_flight"], 512);
    // 512 events in flight for 200us at a mean spacing of 1.1us: about 93,000 events.
    let events = v["events"].as_u64().unwrap();
    assert!((80_000..110_000).contains(&events), "{events}");
}

#[test]
fn compare_prints_one_row_per_fidelity() {
    let out = sortsim(&[
        "netsim",
        "machines/snooping-bus.json",
        "tests/patterns/bus-broadcasts-8.json",
        "--compare",
    ]);
    let stdout = String::from_utf8(out.stdout).unwrap();
    let rows: Vec<&str> = stdout
        .lines()
        .skip(1)
        .map(|l| l.split_whitespace().next().unwrap())
        .collect();
    assert_eq!(rows, ["ideal", "hops", "flow", "packet"], "{stdout}");
    // With -o the same table is written too.
    let dir = tempfile::tempdir().unwrap();
    let out = sortsim(&[
        "netsim",
        "machines/snooping-bus.json",
        "tests/patterns/bus-broadcasts-8.json",
        "--compare",
        "-o",
        dir.path().to_str().unwrap(),
    ]);
    assert!(out.status.success());
    let md = std::fs::read_to_string(dir.path().join("fidelities.md")).unwrap();
    for fidelity in ["ideal", "hops", "flow", "packet"] {
        assert!(md.lines().any(|l| l.starts_with(fidelity)), "{md}");
    }
}

#[test]
fn completion_scripts_name_every_command_for_each_shell() {
    for (shell, marker) in [
        ("bash", "_sortsim()"),
        ("zsh", "#compdef sortsim"),
        ("fish", "complete -c sortsim"),
    ] {
        let out = sortsim(&["completions", shell]);
        let script = String::from_utf8(out.stdout).expect("a completion script is text");
        assert!(script.contains(marker), "{shell}: no {marker:?}");
        for command in [
            "netsim",
            "sweep",
            "accuracy",
            "utilization",
            "replay",
            "scale",
        ] {
            assert!(script.contains(command), "{shell}: {command} not completed");
        }
    }
}

#[test]
fn an_unknown_shell_is_refused_with_the_valid_ones() {
    let out = Command::new(env!("CARGO_BIN_EXE_sortsim"))
        .args(["completions", "tcsh"])
        .output()
        .expect("sortsim runs");
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("tcsh") && stderr.contains("bash") && stderr.contains("fish"),
        "{stderr}"
    );
}

#[test]
fn schema_prints_each_shipped_schema_and_refuses_an_unknown_kind() {
    let out = sortsim(&["schema", "machine"]);
    let shipped = std::fs::read(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("schemas/machine.schema.json"),
    )
    .unwrap();
    assert_eq!(out.stdout, shipped);
    let out = Command::new(env!("CARGO_BIN_EXE_sortsim"))
        .args(["schema", "shader"])
        .output()
        .expect("sortsim runs");
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("shader") && stderr.contains("pattern"),
        "{stderr}"
    );
}

#[test]
fn a_run_spec_may_name_its_schema() {
    let dir = temp_dir("run-schema");
    std::fs::create_dir_all(&dir).unwrap();
    let root = env!("CARGO_MANIFEST_DIR");
    let file = dir.join("run.json");
    std::fs::write(
        &file,
        format!(
            r#"{{"$schema": "{root}/schemas/run.schema.json", "machine": "{root}/machines/power-challenge.json",
                "scene": "{root}/scenes/p000-tetra-500.json", "algo": "sort-middle/static", "procs": 4}}"#
        ),
    )
    .unwrap();
    let out = sortsim(&["check", file.to_str().unwrap()]);
    assert!(String::from_utf8_lossy(&out.stdout).starts_with("OK"));
}

/// `check` names the operations a machine file leaves unpriced (charged at zero wherever an
/// algorithm uses them): a Delta file written before `count_sum` existed says so.
#[test]
fn check_names_the_operations_a_machine_leaves_unpriced() {
    let dir = tempfile::tempdir().unwrap();
    let mut delta: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("machines/delta.json"),
        )
        .unwrap(),
    )
    .unwrap();
    let file = dir.path().join("old-delta.json");
    let check = |v: &serde_json::Value| {
        std::fs::write(&file, v.to_string()).unwrap();
        let out = sortsim(&["check", file.to_str().unwrap()]);
        assert!(out.status.success());
        String::from_utf8(out.stdout).unwrap()
    };
    let before = check(&delta);
    assert!(!before.contains("count_sum"), "{before}");
    delta["cpu"]["costs"]
        .as_object_mut()
        .unwrap()
        .remove("count_sum");
    let after = check(&delta);
    assert!(after.contains("charged at zero (not priced):"), "{after}");
    assert!(after.contains("count_sum"), "{after}");

    // A run on that file names count_sum as charged at zero (Ellsworth's summing tree uses
    // it); an explicit zero is a price, and an unused unpriced operation is not named.
    let run = |v: &serde_json::Value| {
        std::fs::write(&file, v.to_string()).unwrap();
        let out_dir = dir.path().join("run");
        let out = sortsim(&[
            "run",
            "--machine",
            file.to_str().unwrap(),
            "--scene",
            "scenes/plb-head-standin.json",
            "--algo",
            "sort-middle/ellsworth",
            "--procs",
            "8",
            "--frames",
            "0..2",
            "--no-timeline",
            "-o",
            out_dir.to_str().unwrap(),
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out_dir.join("summary.json")).unwrap())
                .unwrap();
        (String::from_utf8(out.stdout).unwrap(), summary)
    };
    let (text, summary) = run(&delta);
    assert_eq!(summary["unpriced_ops"], serde_json::json!(["count_sum"]));
    assert!(
        text.contains("Charged at zero:** the run used count_sum"),
        "{text}"
    );
    delta["cpu"]["costs"]["count_sum"] = "0ns".into();
    let (text, summary) = run(&delta);
    assert!(summary.get("unpriced_ops").is_none(), "{summary}");
    assert!(!text.contains("Charged at zero"), "{text}");
}

/// Issue 32: a machine whose nodes' links differ from its network's runs at every level,
/// `packet` included: on a hot spot, where the sink's links bound the pattern, packets and
/// the fluid model finish it within 1% of each other (packets take turns where flows share).
#[test]
fn netsim_compares_every_level_on_a_network_of_two_link_kinds() {
    let out = sortsim(&[
        "netsim",
        "machines/gpu-cluster-a100.json",
        "tests/patterns/hot-spot-4x4.json",
        "--compare",
    ]);
    let stdout = String::from_utf8(out.stdout).unwrap();
    let makespan = |level: &str| -> f64 {
        let line = stdout
            .lines()
            .find(|l| l.split_whitespace().next() == Some(level))
            .unwrap_or_else(|| panic!("no {level} row: {stdout}"));
        line.split_whitespace().nth(1).unwrap().parse().unwrap()
    };
    let (flow, packet) = (makespan("flow"), makespan("packet"));
    assert!((packet / flow - 1.0).abs() < 0.01, "{stdout}");
    assert!(makespan("hops") < flow, "{stdout}");
}

/// A sweep over several machines names the machine in its table and draws each machine's
/// curves on charts of their own besides the shared ones (their values can lie orders of
/// magnitude apart).
#[test]
fn a_sweep_over_two_machines_charts_each_machine_apart() {
    let dir = temp_dir("two-machine-sweep");
    std::fs::create_dir_all(&dir).unwrap();
    let root = env!("CARGO_MANIFEST_DIR");
    let spec = dir.join("two.json");
    std::fs::write(
        &spec,
        format!(
            r#"{{"machines": ["{root}/machines/delta.json", "{root}/machines/gpu-cluster-a100.json"],
                "scene": "{root}/scenes/spd-tetra.json", "algo": "sort-last/binary-swap",
                "procs": [2, 4], "frames": "0..1"}}"#
        ),
    )
    .unwrap();
    let out = dir.join("report");
    let run = sortsim(&["sweep", spec.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    let stdout = String::from_utf8(run.stdout).unwrap();
    assert!(
        stdout.starts_with("machine, algo, scene, options"),
        "{stdout}"
    );
    assert!(
        stdout.contains("gpu-cluster-a100, sort-last/binary-swap, spd-tetra"),
        "{stdout}"
    );
    for chart in [
        "triangles-per-s.svg",
        "triangles-per-s-delta.svg",
        "triangles-per-s-gpu-cluster-a100.png",
    ] {
        assert!(out.join("plots").join(chart).is_file(), "{chart}");
    }
    // Legend labels are text lines of their own in the SVG.
    let legend = |chart: &str| -> Vec<String> {
        std::fs::read_to_string(out.join("plots").join(chart))
            .unwrap()
            .lines()
            .map(|l| l.trim().to_string())
            .filter(|l| l == "delta" || l == "gpu-cluster-a100")
            .collect()
    };
    assert_eq!(legend("speedup.svg"), ["delta", "gpu-cluster-a100"]);
    assert_eq!(legend("speedup-delta.svg"), ["delta"]);
    assert_eq!(legend("speedup-gpu-cluster-a100.svg"), ["gpu-cluster-a100"]);
}
