//! The bad-input corpus: every file under tests/bad_input/<kind>/ must be refused by the real
//! binary with exit code 2, one message containing the fragment listed for it in that
//! folder's EXPECTED.txt, no panic, and no output files written.

use crate::common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use common::sortsim;

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
        .filter(|p| p.is_file() && p.file_name().unwrap() != "EXPECTED.txt")
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

/// Runs `command FILE -o OUT` and checks the refusal of [`check_refusal`] and that `out` was
/// not created.
fn refused_writing_nothing(command: &str, file: &Path, fragment: &str, out_dir: &Path) {
    let out = sortsim(&[
        command,
        file.to_str().unwrap(),
        "-o",
        out_dir.to_str().unwrap(),
    ]);
    check_refusal(&out, file, fragment);
    assert!(
        !out_dir.exists(),
        "{}: a refused {command} wrote output",
        file.display()
    );
}

#[test]
fn every_bad_machine_is_refused_with_its_message() {
    let out_dir = common::scratch("bad-machine-run");
    for (file, fragment) in corpus("machine") {
        let out = sortsim(&["check", file.to_str().unwrap()]);
        check_refusal(&out, &file, &fragment);
        if fragment.contains("kind of spec") {
            continue; // `check` guesses the kind; `run` is told it is a machine
        }
        // `run` loads the machine as `check` does: the same message, the file named.
        let out = sortsim(&[
            "run",
            "--machine",
            file.to_str().unwrap(),
            "--scene",
            "scenes/spd-teapot.json",
            "--algo",
            "sort-middle/static",
            "--procs",
            "1",
            "-o",
            out_dir.to_str().unwrap(),
        ]);
        check_refusal(&out, &file, &fragment);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            stderr.contains(file.file_name().unwrap().to_str().unwrap()),
            "{}: run names the file: {stderr}",
            file.display()
        );
        assert!(!out_dir.exists(), "{}: nothing written", file.display());
    }
}

#[test]
fn every_bad_scene_is_refused_with_its_message() {
    for (file, fragment) in corpus("scene") {
        let out = sortsim(&["check", file.to_str().unwrap()]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{}: {stderr}", file.display());
        assert!(
            stderr.contains(&fragment),
            "{}: expected {fragment:?} in: {stderr}",
            file.display()
        );
        assert!(!stderr.contains("panicked"), "{stderr}");
    }
}

#[test]
fn every_bad_run_spec_is_refused_naming_its_field() {
    for (file, fragment) in corpus("run") {
        let out = sortsim(&["check", file.to_str().unwrap()]);
        check_refusal(&out, &file, &fragment);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            !stderr.contains("--procs")
                && !stderr.contains("--frames")
                && !stderr.contains("--set"),
            "{}: a file's mistake is not worded as a flag: {stderr}",
            file.display()
        );
    }
}

#[test]
fn every_bad_paper_file_is_refused_by_check_naming_its_row() {
    for (file, fragment) in corpus("paper") {
        let out = sortsim(&["check", file.to_str().unwrap()]);
        check_refusal(&out, &file, &fragment);
    }
    // And every shipped paper file checks out, with its rows counted by role.
    for id in ["000", "001", "002", "003", "004"] {
        let file = format!("papers/{id}.json");
        let out = sortsim(&["check", &file]);
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success() && stdout.contains(" predicted, "),
            "{file}: {stdout}"
        );
    }
}

#[test]
fn every_bad_calibration_spec_is_refused_by_check_and_calibrate_alike() {
    let out_dir = common::scratch("bad-calibration");
    for (file, fragment) in corpus("calibration") {
        let out = sortsim(&["check", file.to_str().unwrap()]);
        check_refusal(&out, &file, &fragment);
        refused_writing_nothing("calibrate", &file, &fragment, &out_dir);
    }
    // And every shipped calibration spec checks out, as what it is (beside the machines and
    // scenes the fits start from).
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let fits = ["machines/fits", "scenes/fits"].map(|f| root.join(f));
    for e in fits.iter().flat_map(|dir| std::fs::read_dir(dir).unwrap()) {
        let path = e.unwrap().path();
        let out = sortsim(&["check", path.to_str().unwrap()]);
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(out.status.success(), "{}: {stdout}", path.display());
        let is_fit = path.file_name().unwrap().to_string_lossy().contains("-to-");
        assert_eq!(
            stdout.contains(": calibration of "),
            is_fit,
            "{}: {stdout}",
            path.display()
        );
    }
}

#[test]
fn every_bad_pattern_is_refused_and_writes_nothing() {
    let out_dir = common::scratch("bad-pattern");
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
        // Zero delays would never let the clock move: refused, not run forever.
        (
            &["bench", "phold", "--mean", "0ns", "--lookahead", "0ns", "--end", "1us"],
            "--mean 0 and --lookahead 0: every event would schedule the next at the same instant",
        ),
        // A data root without machines/ is named, with what would be valid.
        (
            &["--root", "/nonexistent-sortsim-root", "check", "machines/delta.json"],
            "/nonexistent-sortsim-root: not a sortsim data root (--root or SORTSIM_ROOT): it has no machines/ folder",
        ),
        (
            &["bench", "phold", "--lps", "1048576", "--events-per-lp", "4294967295"],
            "events in flight; the engine holds at most 16777216",
        ),
        // A negative number names its option; a malformed range is blamed on its syntax.
        (
            &["run", "--machine", "machines/delta.json", "--scene", "scenes/spd-teapot.json",
              "--algo", "sort-middle/static", "--procs", "4", "--seed", "-1"],
            "invalid value '-1' for '--seed <SEED>'",
        ),
        (
            &["run", "--machine", "machines/delta.json", "--scene", "scenes/spd-teapot.json",
              "--algo", "sort-middle/static", "--procs", "-4"],
            "invalid value '-4' for '--procs <PROCS>'",
        ),
        (
            &["run", "--machine", "machines/delta.json", "--scene", "scenes/spd-teapot.json",
              "--algo", "sort-middle/static", "--procs", "4", "--frames", "-1"],
            "--frames -1: '-1' is not a frame range: write A..B",
        ),
        (
            &["run", "--machine", "machines/delta.json", "--scene", "scenes/spd-teapot.json",
              "--algo", "sort-middle/static", "--procs", "4", "--frames", "0..=x"],
            "--frames 0..=x: '0..=x' is not a range: write A..B (A to B-1) or A..=B (A to B)",
        ),
        (
            &["run", "--machine", "machines/delta.json", "--scene", "scenes/spd-teapot.json",
              "--algo", "sort-middle/static", "--procs", "4", "--frames", "0-3"],
            "--frames 0-3: '0-3' is not a frame range",
        ),
        (
            &["run", "--machine", "machines/delta.json", "--scene", "scenes/spd-teapot.json",
              "--algo", "sort-middle/static", "--procs", "4", "--frames", "5..2"],
            "'5..2' is an empty range",
        ),
        // A timeline's frames lie within the run's, and there must be a timeline.
        (
            &["run", "--machine", "machines/delta.json", "--scene", "scenes/plb-head-standin.json",
              "--algo", "sort-middle/static", "--procs", "4", "--frames", "0..2", "--timeline-frames", "1..3"],
            "--timeline-frames 1..3: the run has frames 0..2 (--frames); the timeline can cover only frames within them",
        ),
        (
            &["run", "--machine", "machines/delta.json", "--scene", "scenes/spd-teapot.json",
              "--algo", "sort-middle/static", "--procs", "4", "--timeline-frames", "2..1"],
            "--timeline-frames 2..1: '2..1' is an empty range",
        ),
        (
            &["run", "--machine", "machines/delta.json", "--scene", "scenes/spd-teapot.json",
              "--algo", "sort-middle/static", "--procs", "4", "--timeline-frames", "x"],
            "--timeline-frames x: 'x' is not a frame range",
        ),
        (
            &["run", "--machine", "machines/delta.json", "--scene", "scenes/spd-teapot.json",
              "--algo", "sort-middle/static", "--procs", "4", "--no-timeline", "--timeline-frames", "0"],
            "the argument '--no-timeline' cannot be used with '--timeline-frames <FRAMES>'",
        ),
        // Slurm values are checked before they reach a batch script.
        (
            &["sweep", "sweeps/default.json", "--slurm", "--mem", "lots"],
            "--mem \"lots\": expected a Slurm memory size",
        ),
        (
            &["sweep", "sweeps/default.json", "--slurm", "--time", "abc"],
            "--time \"abc\": expected a Slurm time limit",
        ),
        (
            &["sweep", "sweeps/default.json", "--slurm", "--time", "1:30:00:00"],
            "expected a Slurm time limit",
        ),
        // Sizes refused before anything is allocated (sortsim::limits).
        (
            &["utilization", "scenes/plb-head-standin.json", "--procs", "1..=4294967295", "--frames", "0..2"],
            "--procs: '1..=4294967295' has 4294967295 values; the limit is 4096",
        ),
        (
            &["utilization", "scenes/plb-head-standin.json", "--procs", "1..100000000:7", "--frames", "0..1"],
            "has 14285715 values; the limit is 4096",
        ),
        (
            &["utilization", "scenes/plb-head-standin.json", "--procs", "1,2,...,1000000", "--frames", "0..1"],
            "has 1000000 values; the limit is 4096",
        ),
        (
            &["utilization", "scenes/plb-head-standin.json", "--procs", "4000000", "--frames", "0..1"],
            "4000000 processors; at most 1048576",
        ),
        (
            &["utilization", "scenes/plb-head-standin.json", "--procs", "8", "--granularity", "1..=99999"],
            "--granularity: '1..=99999' has 99999 values; the limit is 4096",
        ),
        (
            &[
                "run", "--machine", "machines/delta.json", "--scene", "scenes/spd-teapot.json",
                "--algo", "sort-first/mueller", "--procs", "4", "--set", "regions=random",
            ],
            "--set regions=random: expected one of static, adaptive",
        ),
        (
            &[
                "run", "--machine", "machines/delta.json", "--scene", "scenes/spd-teapot.json",
                "--algo", "sort-first/mueller", "--procs", "4", "--set", "migrate=later",
            ],
            "--set migrate=later: expected one of batched, immediate",
        ),
        (
            &[
                "run", "--machine", "machines/delta.json", "--scene", "scenes/spd-teapot.json",
                "--algo", "sort-first/mueller", "--procs", "4", "--set", "granularity=100000",
            ],
            "regions fit a 512x512 screen",
        ),
        (
            &[
                "run", "--machine", "machines/delta.json", "--scene", "scenes/spd-teapot.json",
                "--algo", "sort-first/mueller", "--procs", "4", "--set", "two-step=on",
            ],
            "sort-first/mueller has no option 'two-step'",
        ),
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
        (
            &[
                "run",
                "--machine",
                "machines/delta.json",
                "--scene",
                "scenes/spd-teapot.json",
                "--algo",
                "sort-middle/static",
                "--procs",
                "0",
            ],
            "--procs 0: a run needs at least 1 processor",
        ),
        (
            &[
                "run",
                "--machine",
                "machines/delta.json",
                "--scene",
                "scenes/spd-teapot.json",
                "--algo",
                "sort-middle/static",
                "--procs",
                "513",
            ],
            "has 512 nodes; ask for at most 512",
        ),
        (
            &[
                "run",
                "--machine",
                "machines/delta.json",
                "--scene",
                "scenes/spd-teapot.json",
                "--algo",
                "sort-middle/static",
                "--procs",
                "37",
            ],
            "no rectangular partition of 37 nodes fits",
        ),
        (
            &[
                "run",
                "--machine",
                "machines/multicluster-torus.json",
                "--scene",
                "scenes/spd-teapot.json",
                "--algo",
                "sort-middle/static",
                "--procs",
                "8",
                "--set",
                "machine.network.reconfigurable=false",
            ],
            "a torus cannot be partitioned, so ask for exactly 16",
        ),
        (
            &[
                "run",
                "--machine",
                "machines/delta.json",
                "--scene",
                "scenes/spd-teapot.json",
                "--algo",
                "sort-middle/magic",
                "--procs",
                "4",
            ],
            "unknown algorithm; valid ids: sort-middle/static, sort-middle/ellsworth",
        ),
        (
            &[
                "run",
                "--machine",
                "machines/delta.json",
                "--scene",
                "scenes/spd-teapot.json",
                "--algo",
                "sort-middle/ellsworth",
                "--procs",
                "4",
                "--set",
                "granularity=0",
            ],
            "--set granularity=0: expected a whole number of regions per processor, at least 1",
        ),
        (
            &[
                "run",
                "--machine",
                "machines/delta.json",
                "--scene",
                "scenes/spd-teapot.json",
                "--algo",
                "sort-middle/ellsworth",
                "--procs",
                "4",
                "--set",
                "granularity=lots",
            ],
            "--set granularity=lots: expected",
        ),
        (
            // 100,000 s a message at each interface: the queue of gaps overflowed the network's
            // u64 picoseconds, a panic.
            &[
                "run",
                "--machine",
                "machines/delta.json",
                "--scene",
                "scenes/spd-tetra.json",
                "--algo",
                "sort-last/scanline-flow",
                "--procs",
                "5",
                "--frames",
                "0",
                "--set",
                "machine.network.message_gap=100000s",
            ],
            "could arrive past the largest simulated time, 18446744.07371s (u64 picoseconds)",
        ),
        (
            // 268,435,457 x 16 processors is 16 regions in 32-bit arithmetic: was run as such.
            &[
                "run",
                "--machine",
                "machines/delta.json",
                "--scene",
                "scenes/spd-teapot.json",
                "--algo",
                "sort-middle/ellsworth",
                "--procs",
                "16",
                "--set",
                "granularity=268435457",
            ],
            "--set granularity=268435457: expected at most 262144 regions fit a 512x512 screen",
        ),
        (
            &[
                "run",
                "--machine",
                "machines/delta.json",
                "--scene",
                "scenes/spd-teapot.json",
                "--algo",
                "sort-middle/ellsworth",
                "--procs",
                "4",
                "--set",
                "colour=red",
            ],
            "has no option 'colour'; valid options:",
        ),
        (
            // Options are checked before the scene is read (or built: a large stand-in takes
            // a while), so a mistyped key is reported even when the scene would fail too.
            &[
                "run",
                "--machine",
                "machines/delta.json",
                "--scene",
                "scenes/no-such-scene.json",
                "--algo",
                "sort-middle/ellsworth",
                "--procs",
                "4",
                "--set",
                "colour=red",
            ],
            "sort-middle/ellsworth has no option 'colour'; valid options:",
        ),
        (
            &[
                "run",
                "--machine",
                "machines/delta.json",
                "--scene",
                "scenes/spd-teapot.json",
                "--algo",
                "sort-middle/static",
                "--procs",
                "4",
                "--set",
                "granularity=8",
            ],
            "sort-middle/static has no option 'granularity'",
        ),
        (
            &[
                "run",
                "--machine",
                "machines/delta.json",
                "--scene",
                "scenes/spd-teapot.json",
                "--algo",
                "sort-middle/static",
                "--procs",
                "4",
                "--set",
                "machine.network.colour=red",
            ],
            "no field `network.colour`",
        ),
        (
            &[
                "run",
                "--machine",
                "machines/delta.json",
                "--scene",
                "scenes/spd-teapot.json",
                "--algo",
                "sort-middle/static",
                "--procs",
                "4",
                "--set",
                "machine.network.fidelity=exact",
            ],
            "unknown variant `exact`",
        ),
        (
            &[
                "run",
                "--machine",
                "machines/delta.json",
                "--scene",
                "scenes/spd-teapot.json",
                "--algo",
                "sort-middle/static",
                "--procs",
                "4",
                "--set",
                "counts",
            ],
            "--set counts: expected KEY=VALUE",
        ),
        (
            &[
                "run",
                "--machine",
                "machines/delta.json",
                "--scene",
                "scenes/plb-head-standin.json",
                "--algo",
                "sort-middle/static",
                "--procs",
                "4",
                "--frames",
                "70..90",
            ],
            "the scene has frames 0..80",
        ),
        (
            &[
                "run",
                "--machine",
                "machines/delta.json",
                "--scene",
                "scenes/polio-standin.json",
                "--algo",
                "sort-middle/ellsworth",
                "--procs",
                "1",
                "--frames",
                "0",
            ],
            "exceeds its memory",
        ),
        (
            &[
                "run",
                "--machine",
                "machines/delta.json",
                "--scene",
                "scenes/spd-teapot.json",
                "--algo",
                "sort-middle/static",
                "--procs",
                "4",
                "--set",
                "buffer=10B",
            ],
            "--set buffer=10B: expected a buffer of at least",
        ),
        (
            &[
                "accuracy",
                "scenes/screen-demo.json",
                "--machine",
                "machines/delta.json",
                "--algo",
                "sort-middle/static",
                "--procs",
                "4",
                "--modes",
                "none,fxaa",
            ],
            "unknown anti-aliasing mode 'fxaa'; valid: none, adaptive, supersample:N",
        ),
        (
            &[
                "accuracy",
                "scenes/screen-demo.json",
                "--machine",
                "machines/delta.json",
                "--algo",
                "sort-middle/static",
                "--procs",
                "4",
                "--fidelities",
                "ideal,warp",
            ],
            "invalid value 'warp' for '--fidelities",
        ),
        (
            &[
                "accuracy",
                "scenes/screen-demo.json",
                "--machine",
                "machines/delta.json",
                "--algo",
                "sort-middle/static",
                "--procs",
                "4",
                "--reference-scale",
                "65",
            ],
            "--reference-scale",
        ),
        (
            &[
                "run",
                "--machine",
                "machines/multicluster-torus.json",
                "--scene",
                "scenes/p003-zinnia.json",
                "--algo",
                "sort-last/snooping",
                "--procs",
                "16",
            ],
            "sort-last/snooping needs a broadcast medium, but machine 'multicluster-torus' is a torus",
        ),
        (
            &[
                "run",
                "--machine",
                "machines/multicluster-torus.json",
                "--scene",
                "scenes/p003-zinnia.json",
                "--algo",
                "sort-last/pixelflow",
                "--procs",
                "16",
            ],
            "sort-last/pixelflow streams frames from node i to node i+1, but machine 'multicluster-torus' (torus) has no direct link",
        ),
        (
            &[
                "run",
                "--machine",
                "machines/denali-crossbar.json",
                "--scene",
                "scenes/p003-zinnia.json",
                "--algo",
                "sort-last/direct-send",
                "--procs",
                "4",
                "--set",
                "local-zbuffer=maybe",
            ],
            "--set local-zbuffer=maybe: expected one of on, off",
        ),
        (
            &[
                "run",
                "--machine",
                "machines/power-challenge.json",
                "--scene",
                "scenes/p000-letter-b.json",
                "--algo",
                "sort-middle/static",
                "--procs",
                "4",
                "--set",
                "aa=supersample:15",
            ],
            "--set aa=supersample:15: expected none, adaptive, or supersample:N with N a perfect square from 4 to 256",
        ),
        (
            &[
                "run",
                "--machine",
                "machines/snooping-bus.json",
                "--scene",
                "scenes/p003-zinnia.json",
                "--algo",
                "sort-last/snooping",
                "--procs",
                "4",
                "--set",
                "assign=request",
            ],
            "--set assign=request: expected scatter, random, background-last or blocks",
        ),
        (
            &[
                "run",
                "--machine",
                "machines/power-challenge.json",
                "--scene",
                "scenes/p000-letter-b.json",
                "--algo",
                "sort-middle/ellsworth",
                "--procs",
                "4",
                "--set",
                "aa=fxaa",
            ],
            "--set aa=fxaa: expected none, adaptive, or supersample:N",
        ),
        (
            &[
                "run",
                "--machine",
                "machines/power-challenge.json",
                "--scene",
                "scenes/p000-letter-b.json",
                "--algo",
                "sort-middle/static",
                "--procs",
                "4",
                "--set",
                "aa-start=5",
            ],
            "--set aa-start=5: expected one of 4, 3, 2",
        ),
        (
            &[
                "run",
                "--machine",
                "machines/power-challenge.json",
                "--scene",
                "scenes/p000-letter-b.json",
                "--algo",
                "sort-middle/static",
                "--procs",
                "4",
                "--set",
                "aa-pool=lots",
            ],
            "--set aa-pool=lots: expected a Subpixel pool size per processor",
        ),
        (
            &[
                "run",
                "--machine",
                "machines/power-challenge.json",
                "--scene",
                "scenes/p000-letter-b.json",
                "--algo",
                "sort-middle/static",
                "--procs",
                "4",
                "--set",
                "aa-reclaim=maybe",
            ],
            "--set aa-reclaim=maybe: expected one of on, off",
        ),
        (
            &[
                "run",
                "--machine",
                "machines/power-challenge.json",
                "--scene",
                "scenes/p000-letter-b.json",
                "--algo",
                "sort-middle/static",
                "--procs",
                "4",
                "--set",
                "aa=supersample:16",
                "--set",
                "aa-pool=10MB",
            ],
            "--set aa-pool=10MB: expected aa=adaptive with it",
        ),
        // A device would be read without end: only regular files are inputs.
        (&["check", "/dev/zero"], "/dev/zero: cannot read: not a regular file"),
        (
            &["trace", "replay", "/dev/zero"],
            "/dev/zero: cannot read: not a regular file",
        ),
        (
            &["netsim", "machines/delta.json", "/dev/zero"],
            "not a regular file",
        ),
        (
            &["sweep", "sweeps/cluster-demo.json", "--shard", "4/3"],
            "0 <= I < T",
        ),
        (
            &["sweep", "sweeps/cluster-demo.json", "--shard", "3/3"],
            "0 <= I < T",
        ),
        (
            &["sweep", "sweeps/cluster-demo.json", "--slurm", "--tasks", "0"],
            "--tasks",
        ),
        (
            &["sweep", "sweeps/cluster-demo.json", "--tasks", "2"],
            "--slurm",
        ),
        (
            &["sweep", "sweeps/cluster-demo.json", "--slurm", "--time", "1 day"],
            "--time",
        ),
    ];
    for (args, fragment) in cases {
        common::assert_refused(&sortsim(args), &format!("{args:?}"), fragment);
    }
}

#[test]
fn every_bad_sweep_is_refused_and_writes_nothing() {
    let out_dir = common::scratch("bad-sweep");
    for (file, fragment) in corpus("sweep") {
        let rel = file.strip_prefix(env!("CARGO_MANIFEST_DIR")).unwrap();
        refused_writing_nothing("sweep", rel, &fragment, &out_dir);
        // `check` sets every point up as `sweep` would: refused too, nothing simulated. (It
        // guesses a file's kind, so a sweep whose lists are all single values may be read as
        // the run spec it also is, and be refused with that kind's words for the same field.)
        let out = sortsim(&["check", rel.to_str().unwrap()]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{}: {stderr}", file.display());
        assert!(!stderr.contains("panicked"), "{stderr}");
        let field = fragment.split('`').nth(1).unwrap_or(&fragment);
        assert!(
            stderr.contains(&fragment) || stderr.contains(&format!("`{field}`")),
            "{}: check: expected {fragment:?} in: {stderr}",
            file.display()
        );
    }
}

/// Sort-last runs the machine cannot carry or whose options make no sense (paper 001's
/// algorithms): exit 2, the message, and no report folder.
#[test]
fn sort_last_runs_refuse_what_the_machine_or_options_cannot_do() {
    let out_dir = common::scratch("bad-sort-last");
    let cases: &[(&str, &str, &str, &[&str], &str)] = &[
        (
            "machines/multicluster-torus.json",
            "sort-last/pc",
            "16",
            &[],
            "no direct link from node 3 to node 4; use a machine whose topology is a pipeline or a ring",
        ),
        (
            "machines/multicluster-torus.json",
            "sort-last/scanline-flow",
            "16",
            &[],
            "pipeline or a ring",
        ),
        (
            "machines/multicluster-torus.json",
            "sort-last/df",
            "8",
            &["machine.network.reconfigurable=false"],
            "a torus cannot be partitioned, so ask for exactly 16",
        ),
        (
            "machines/multicluster-pipeline.json",
            "sort-last/scanline-flow",
            "4",
            &["assign=request"],
            "only sort-last/df, sort-last/pc and the compositing variants (tree, binary-swap, radix-k, 2-3-swap) use it",
        ),
        (
            "machines/multicluster-pipeline.json",
            "sort-last/pc",
            "4",
            &["assign=request", "split=1"],
            "a splitting factor of at least 2",
        ),
        (
            "machines/multicluster-pipeline.json",
            "sort-last/pc",
            "4",
            &["assign=request", "min-packet=0"],
            "a whole number of primitives, at least 1",
        ),
        (
            "machines/multicluster-pipeline.json",
            "sort-last/pc",
            "4",
            &["assign=round-robin"],
            "round-robin",
        ),
        (
            "machines/multicluster-pipeline.json",
            "sort-last/pc",
            "4",
            &["chunk-rows=0"],
            "a whole number of scanlines, at least 1",
        ),
        (
            "machines/snooping-bus.json",
            "sort-last/snooping",
            "4",
            &[
                "aa=adaptive",
                "machine.cpu.costs.coverage_mask=0ns",
                "machine.cpu.costs.subpixel_test=0ns",
                "machine.cpu.costs.subpixel_write=0ns",
                "machine.cpu.costs.reclaim_check=0ns",
                "machine.cpu.costs.resolve_pixel=0ns",
            ],
            "prices none of the anti-aliasing operations, so --set aa=adaptive would cost no time",
        ),
        (
            "machines/snooping-bus.json",
            "sort-last/pixelflow",
            "4",
            &["aa=supersample:4", "aa-start=3"],
            "--set aa-start=3: expected aa=adaptive with it",
        ),
        (
            "machines/snooping-bus.json",
            "sort-last/pixelflow",
            "4",
            &["aa=supersample:15"],
            "expected none, adaptive, or supersample:N with N a perfect square from 4 to 256",
        ),
        (
            "machines/denali-crossbar.json",
            "sort-last/direct-send",
            "4",
            &["image=rle"],
            "--set image=rle: expected dense, or rle together with local-zbuffer=on",
        ),
        (
            "machines/denali-crossbar.json",
            "sort-last/binary-swap",
            "4",
            &["pieces=diagonal"],
            "contiguous",
        ),
        (
            "machines/denali-crossbar.json",
            "sort-last/tree",
            "4",
            &["pieces=interleaved"],
            "pieces",
        ),
        (
            "machines/denali-crossbar.json",
            "sort-last/2-3-swap",
            "4",
            &["k=2,2"],
            "k",
        ),
        (
            "machines/denali-crossbar.json",
            "sort-last/binary-swap",
            "4",
            &["bounds=on"],
            "--set bounds=on: expected off, or on together with image=rle",
        ),
        (
            "machines/denali-crossbar.json",
            "sort-last/radix-k",
            "4",
            &["bounds=on", "image=rle", "pieces=interleaved"],
            "--set bounds=on: expected off, or on with pieces=contiguous",
        ),
        (
            "machines/denali-crossbar.json",
            "sort-last/tree",
            "4",
            &["bounds=on", "image=rle", "assign=request"],
            "--set bounds=on: expected off, or on with a static assignment",
        ),
        (
            "machines/denali-crossbar.json",
            "sort-last/direct-send",
            "4",
            &["bounds=on"],
            "bounds",
        ),
        (
            "machines/denali-crossbar.json",
            "sort-last/binary-swap",
            "4",
            &["gather=off", "pieces=interleaved"],
            "--set gather=off: expected on, or off with pieces=contiguous",
        ),
        (
            "machines/denali-crossbar.json",
            "sort-last/tree",
            "4",
            &["gather=off"],
            "sort-last/tree has no option 'gather'",
        ),
    ];
    // A run of several frames with the image left in pieces.
    let out = sortsim(&[
        "run",
        "--machine",
        "machines/bgp-intrepid-8k.json",
        "--scene",
        "scenes/plb-head-standin.json",
        "--algo",
        "sort-last/radix-k",
        "--procs",
        "4",
        "--frames",
        "0..2",
        "--set",
        "gather=off",
        "-o",
        out_dir.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("--set gather=off: expected on, or off with one frame (--frames A)"),
        "{stderr}"
    );
    assert!(!out_dir.exists(), "a refused run wrote output");
    for (machine, algo, procs, sets, fragment) in cases {
        let mut args = vec![
            "run",
            "--machine",
            machine,
            "--scene",
            "scenes/spd-teapot.json",
            "--algo",
            algo,
            "--procs",
            procs,
            "-o",
            out_dir.to_str().unwrap(),
        ];
        for s in *sets {
            args.extend(["--set", s]);
        }
        let out = sortsim(&args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(
            stderr.contains(fragment),
            "{args:?}: expected {fragment:?} in {stderr}"
        );
        assert!(!stderr.contains("panicked"), "{stderr}");
        assert!(!out_dir.exists(), "{args:?}: a refused run wrote output");
    }
}

/// A sample grid past the rasterizer's viewport limit is refused before anything runs.
/// A `supersample:N` grid past 16384 samples a side is refused before anything is allocated,
/// in both families, however much memory the simulated machine has: the host holds every
/// sample (here about 2.6 GB; 16x16 on a 16384^2 screen would be 481 GB).
#[test]
fn a_sample_grid_too_large_is_refused_before_allocating() {
    for (machine, algo) in [
        ("machines/snooping-bus.json", "sort-last/snooping"),
        ("machines/delta.json", "sort-middle/static"),
    ] {
        let out = sortsim(&[
            "run",
            "--machine",
            machine,
            "--scene",
            "scenes/p003-brooks.json",
            "--algo",
            algo,
            "--procs",
            "4",
            "--set",
            "aa=supersample:256",
            "--set",
            "machine.memory.capacity_per_node=100000GB",
        ]);
        common::assert_refused(
            &out,
            algo,
            &format!(
                "1204x1204 pixels at 16x16 samples is a 19264x19264 sample grid (about 2.6 GB of host memory); {algo} works on sample grids of at most 16384 per side"
            ),
        );
    }
}

/// The long benchmark and calibration commands find an unwritable report folder before they
/// run anything (a plain file stands where a folder should be made).
#[test]
fn an_unwritable_report_folder_is_refused_before_the_benchmark_runs() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("a-file");
    std::fs::write(&file, "").unwrap();
    let out = file.join("report");
    let out = out.to_str().unwrap();
    for args in [
        &["bench", "scale", "--quick", "-o", out][..],
        &[
            "calibrate",
            "machines/fits/multicluster-to-001-table1.json",
            "-o",
            out,
        ][..],
    ] {
        let result = sortsim(args);
        common::assert_refused(&result, &format!("{args:?}"), "a-file/report: cannot write");
        let err = String::from_utf8_lossy(&result.stderr);
        assert!(
            !err.contains("measuring:"),
            "{args:?} ran before refusing: {err}"
        );
        assert!(result.stdout.is_empty(), "{args:?} printed a report");
    }
}

/// Every algorithm names the routes its messages need and is refused before the run on a
/// machine that cannot carry them (a one-way pipeline has no route back), with the first
/// pair it lacks; only PixelFlow, which streams one way, runs there.
#[test]
fn every_algorithm_is_refused_on_a_network_that_cannot_route_its_messages() {
    let out_dir = common::scratch("bad-routes");
    let help = sortsim(&["run", "--help"]);
    let text = String::from_utf8_lossy(&help.stdout);
    let mut algos: Vec<&str> = text
        .split(|c: char| c.is_whitespace() || c == ',' || c == '`')
        .filter(|w| w.starts_with("sort-") && w.contains('/'))
        .collect();
    algos.sort_unstable();
    algos.dedup();
    assert!(algos.len() >= 13, "{algos:?}");
    for algo in algos {
        let out = sortsim(&[
            "run",
            "--machine",
            "machines/pixelflow-pipeline.json",
            "--scene",
            "scenes/spd-teapot.json",
            "--algo",
            algo,
            "--procs",
            "8",
            "--no-timeline",
            "-o",
            out_dir.to_str().unwrap(),
        ]);
        if algo == "sort-last/pixelflow" {
            assert!(out.status.success(), "{algo}");
            std::fs::remove_dir_all(&*out_dir).unwrap();
            continue;
        }
        let fragment = if algo == "sort-last/snooping" {
            "needs a broadcast medium"
        } else {
            "sends from node 1 to node 0, but machine 'pixelflow-pipeline' (pipeline) has no route"
        };
        common::assert_refused(&out, algo, fragment);
        assert!(!out_dir.exists(), "{algo}: nothing written");
    }
}

/// Costs so large that simulated time would pass u64 picoseconds (213 days) are refused
/// where the charge is made, naming the phase and the cost behind it: exit 2, nothing
/// written, no panic.
#[test]
fn a_charge_past_the_largest_simulated_time_is_refused_naming_its_cost() {
    let out_dir = common::scratch("bad-overflow");
    let cases = [
        (
            "machine.cpu.send_overhead=18000000s",
            "(a message's cpu.send_overhead or cpu.recv_overhead and its per-byte cost) would end past the largest simulated time",
        ),
        (
            "machine.cpu.costs.pixel_test=100000s",
            "x pixel_test at 100000s each) would end past the largest simulated time",
        ),
        (
            "machine.cpu.costs.transform_vertex=18000000s",
            "x transform_vertex at 18000000s each) would end past the largest simulated time",
        ),
    ];
    for (set, fragment) in cases {
        let out = sortsim(&[
            "run",
            "--machine",
            "machines/delta.json",
            "--scene",
            "scenes/plb-head-standin.json",
            "--algo",
            "sort-middle/ellsworth",
            "--procs",
            "8",
            "--frames",
            "0..1",
            "--set",
            set,
            "-o",
            out_dir.to_str().unwrap(),
        ]);
        common::assert_refused(&out, set, fragment);
        assert!(!out_dir.exists(), "{set}: nothing written");
    }
}

/// A file output given as an existing folder is refused with exit 2, and nothing (no
/// half-written temporary) is left beside it.
#[test]
fn an_output_file_that_is_a_folder_is_refused_and_leaves_nothing() {
    let parent = tempfile::tempdir().unwrap();
    let folder = parent.path().join("existing");
    std::fs::create_dir(&folder).unwrap();
    for args in [
        &["render", "scenes/spd-teapot.json", "-o"][..],
        &["trace", "record", "scenes/spd-teapot.json", "-o"][..],
    ] {
        let mut args = args.to_vec();
        args.push(folder.to_str().unwrap());
        let out = sortsim(&args);
        common::assert_refused(
            &out,
            &format!("{args:?}"),
            "is a folder; give the name of a file",
        );
        let left: Vec<_> = std::fs::read_dir(parent.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(left, ["existing"], "{args:?}: {left:?}");
        assert_eq!(std::fs::read_dir(&folder).unwrap().count(), 0);
    }
}

/// A sweep whose report folder is an existing file is refused before any point runs.
#[test]
fn a_sweep_into_a_file_is_refused_before_it_simulates() {
    let parent = tempfile::tempdir().unwrap();
    let file = parent.path().join("a-file");
    std::fs::write(&file, "").unwrap();
    let out = sortsim(&["sweep", "sweeps/default.json", "-o", file.to_str().unwrap()]);
    common::assert_refused(&out, "sweep into a file", "it is a file, not a folder");
    assert!(
        !String::from_utf8_lossy(&out.stderr).contains("points/"),
        "refused before any point was written"
    );
}

#[test]
fn a_pattern_past_the_packet_budget_is_refused_at_packet_fidelity_only() {
    // Two 100 GB messages sharing links: 2.4e7 4 KiB packets each over five hops, which
    // the packet transport would simulate one by one; flow takes them whole.
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("huge.json");
    std::fs::write(
        &file,
        r#"{"messages": [{"src": 0, "dst": 5, "bytes": "100GB", "start": "0us"},
                         {"src": 1, "dst": 6, "bytes": "100GB", "start": "0us"}]}"#,
    )
    .unwrap();
    let run = |fidelity: &str| {
        sortsim(&[
            "netsim",
            "machines/delta.json",
            file.to_str().unwrap(),
            "--fidelity",
            fidelity,
        ])
    };
    check_refusal(
        &run("packet"),
        &file,
        "messages[0].bytes: at packet fidelity the pattern is",
    );
    let flow = run("flow");
    assert!(
        flow.status.success(),
        "{}",
        String::from_utf8_lossy(&flow.stderr)
    );
}

/// A network too fast for `flow`'s one-word keys (tests/bad_input/machine/too-fast-for-flow.json
/// at `hops`): `netsim --fidelity flow` refuses it naming the flag and `link_bandwidth`, and
/// `--compare` runs the other levels and says why `flow` was not run.
#[test]
fn a_network_too_fast_for_flow_is_refused_at_flow_only() {
    let dir = tempfile::tempdir().unwrap();
    let corpus = std::fs::read_to_string("tests/bad_input/machine/too-fast-for-flow.json").unwrap();
    let machine = dir.path().join("too-fast-at-hops.json");
    std::fs::write(
        &machine,
        corpus.replace(r#""fidelity": "flow""#, r#""fidelity": "hops""#),
    )
    .unwrap();
    let pattern = dir.path().join("one.json");
    std::fs::write(
        &pattern,
        r#"{"messages": [{"src": 0, "dst": 2, "bytes": "64KiB", "start": "0us"}]}"#,
    )
    .unwrap();
    let netsim = |extra: &[&str]| {
        let mut args = vec![
            "netsim",
            machine.to_str().unwrap(),
            pattern.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        sortsim(&args)
    };
    let refused = netsim(&["--fidelity", "flow"]);
    check_refusal(&refused, &machine, "--fidelity flow: ");
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert!(
        stderr.contains(
            "link_bandwidth 500000000GB/s is too fast for the `flow` fidelity on 8 links"
        ),
        "{stderr}"
    );
    let compare = netsim(&["--compare"]);
    let stdout = String::from_utf8_lossy(&compare.stdout);
    assert!(
        compare.status.success(),
        "{}",
        String::from_utf8_lossy(&compare.stderr)
    );
    assert!(
        stdout.contains("flow: not run on this network: invalid network: link_bandwidth"),
        "{stdout}"
    );
    assert!(stdout.lines().any(|l| l.starts_with("packet ")), "{stdout}");
}

/// Outside a checkout, with no data root given and a data folder that cannot be written, the
/// bundled machines cannot be unpacked: one message saying so and how to give a root, exit 2,
/// nothing written.
#[test]
fn an_unwritable_data_folder_is_refused_with_a_way_out() {
    let work = tempfile::tempdir().unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_sortsim"))
        .args(["check", "machines/delta.json"])
        .current_dir(work.path())
        .env_remove("SORTSIM_ROOT")
        .env("XDG_DATA_HOME", "/dev/null/not-a-folder")
        .output()
        .expect("sortsim runs");
    common::assert_refused(
        &out,
        "unwritable data folder",
        "cannot unpack sortsim's bundled machines and scenes",
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains("--root DIR or SORTSIM_ROOT"));
    assert_eq!(std::fs::read_dir(work.path()).unwrap().count(), 0);
}
