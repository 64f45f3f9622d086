//! The bad-input corpus: every file under tests/bad_input/<kind>/ must be refused by the real
//! binary with exit code 2, one message containing the fragment listed for it in that
//! folder's EXPECTED.txt, no panic, and no output files written.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn sortsim(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sortsim"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("sortsim runs")
}

/// (file, expected fragment) pairs of one corpus folder; every .json file must be listed.
fn corpus(kind: &str) -> Vec<(PathBuf, String)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/bad_input")
        .join(kind);
    let expected = std::fs::read_to_string(dir.join("EXPECTED.txt")).expect("EXPECTED.txt exists");
    let cases: Vec<(PathBuf, String)> = expected
        .lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .map(|l| {
            let (file, fragment) = l
                .split_once(": ")
                .expect("EXPECTED.txt lines are `file: fragment`");
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
    assert_eq!(
        listed, present,
        "every corpus file has an expectation and every expectation a file"
    );
    cases
}

fn check_refusal(out: &Output, file: &Path, fragment: &str) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(
        out.status.code(),
        Some(2),
        "{}: exit code; stderr: {stderr}",
        file.display()
    );
    assert!(
        stderr.contains(fragment),
        "{}: expected {fragment:?} in: {stderr}",
        file.display()
    );
    assert!(
        stderr.contains(&*file.file_name().unwrap().to_string_lossy()),
        "the message names the file: {stderr}"
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(
        stderr.lines().filter(|l| l.starts_with("error")).count(),
        1,
        "one message: {stderr}"
    );
}

#[test]
fn every_bad_machine_is_refused_with_its_message() {
    for (file, fragment) in corpus("machine") {
        let out = sortsim(&["check", file.to_str().unwrap()]);
        check_refusal(&out, &file, &fragment);
    }
}

#[test]
fn every_bad_pattern_is_refused_and_writes_nothing() {
    let out_dir = std::env::temp_dir().join(format!("sortsim-bad-pattern-{}", std::process::id()));
    for (file, fragment) in corpus("pattern") {
        let out = sortsim(&[
            "netsim",
            "machines/multicluster-torus.json",
            file.to_str().unwrap(),
            "-o",
            out_dir.to_str().unwrap(),
        ]);
        check_refusal(&out, &file, &fragment);
        assert!(
            !out_dir.exists(),
            "{}: a refused run wrote output",
            file.display()
        );
    }
}

#[test]
fn bad_flags_are_refused_with_exit_code_2() {
    let cases: &[(&[&str], &str)] = &[
        (&["bench", "phold", "--remote", "1.5"], "not a probability"),
        (&["bench", "phold", "--lps", "0"], "--lps"),
        (&["bench", "phold", "--end", "5 fortnights"], "unknown unit"),
        (
            &[
                "netsim",
                "machines/delta.json",
                "tests/patterns/complement-16x32.json",
                "--fidelity",
                "warp",
            ],
            "warp",
        ),
        (
            &["check", "tests/bad_input/does-not-exist.json"],
            "does-not-exist.json: cannot read",
        ),
        (&["frobnicate"], "unrecognized subcommand"),
    ];
    for (args, fragment) in cases {
        let out = sortsim(args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(
            stderr.contains(fragment),
            "{args:?}: expected {fragment:?} in {stderr}"
        );
        assert!(!stderr.contains("panicked"), "{stderr}");
    }
}

#[test]
fn every_bad_sweep_is_refused_and_writes_nothing() {
    let out_dir = std::env::temp_dir().join(format!("sortsim-bad-sweep-{}", std::process::id()));
    for (file, fragment) in corpus("sweep") {
        let rel = file.strip_prefix(env!("CARGO_MANIFEST_DIR")).unwrap();
        let out = sortsim(&[
            "sweep",
            rel.to_str().unwrap(),
            "-o",
            out_dir.to_str().unwrap(),
        ]);
        check_refusal(&out, &file, &fragment);
        assert!(
            !out_dir.exists(),
            "{}: a refused sweep wrote output",
            file.display()
        );
    }
}
