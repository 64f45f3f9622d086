//! Safe to kill, safe to repeat: `kill -9` at any moment of a `sortsim run` or a `sortsim
//! sweep` never leaves a half-written report file (every file is written to a temporary name
//! and renamed), and a sweep killed part way and run again into the same folder finishes with
//! the table an uninterrupted sweep writes.

use crate::common;

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

fn spawn(args: &[&str]) -> Child {
    Command::new(env!("CARGO_BIN_EXE_sortsim"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("sortsim starts")
}

/// Lets `child` run for `after`, then SIGKILLs it (if it has not finished); true if it was
/// killed while still running.
fn kill_after(mut child: Child, after: Duration) -> bool {
    let start = Instant::now();
    while start.elapsed() < after {
        if let Some(status) = child.try_wait().unwrap() {
            assert!(
                status.success(),
                "sortsim failed before it was killed: {status}"
            );
            return false;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    let killed = child.try_wait().unwrap().is_none();
    child.kill().unwrap();
    child.wait().unwrap();
    killed
}

/// Temporary files (a killed writer's) anywhere under `dir`.
fn temporaries(dir: &Path) -> Vec<String> {
    let mut found = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let path = e.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else if path.to_string_lossy().contains(".tmp") {
                found.push(path.display().to_string());
            }
        }
    }
    found
}

/// Every report file under `dir` (hidden temporary files aside) is whole: JSON parses, a PNG
/// decodes, an SVG and an HTML page end as they must, a CSV ends with a newline.
fn assert_whole(dir: &Path) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries {
        let path = e.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        if name.starts_with('.') {
            continue; // a temporary name, never read as a report
        }
        if path.is_dir() {
            assert_whole(&path);
            continue;
        }
        let bytes = std::fs::read(&path).unwrap();
        let what = path.display();
        match path.extension().and_then(|x| x.to_str()) {
            Some("json") => {
                serde_json::from_slice::<serde_json::Value>(&bytes)
                    .unwrap_or_else(|e| panic!("{what} is not whole JSON: {e}"));
            }
            Some("png") => {
                let mut reader = png::Decoder::new(&bytes[..])
                    .read_info()
                    .unwrap_or_else(|e| panic!("{what}: {e}"));
                let mut buf = vec![0; reader.output_buffer_size()];
                reader
                    .next_frame(&mut buf)
                    .unwrap_or_else(|e| panic!("{what} is not a whole PNG: {e}"));
            }
            Some("svg") => assert!(bytes.trim_ascii_end().ends_with(b"</svg>"), "{what}"),
            Some("html") => assert!(bytes.trim_ascii_end().ends_with(b"</html>"), "{what}"),
            Some("csv") | Some("md") => assert!(bytes.ends_with(b"\n"), "{what}"),
            _ => {}
        }
    }
}

/// A 40-frame run on 64 processors takes a few seconds; it is killed at moments spread over
/// its whole life, writing of the report included. The folder never holds a partial file;
/// summary.json is whole or absent; a run to the end in a killed run's folder leaves no
/// temporary file behind.
#[test]
fn a_run_killed_at_any_moment_leaves_whole_files_or_none() {
    let mut delays_ms: Vec<u64> = (0..8).map(|k| 100 + 300 * k).collect();
    delays_ms.push(u64::MAX); // and one that finishes
    let mut killed = 0;
    let mut dir = common::scratch("run-0");
    for (k, ms) in delays_ms.into_iter().enumerate() {
        // The run that finishes writes into the last killed run's folder.
        if ms != u64::MAX {
            dir = common::scratch(&format!("run-{k}"));
        }
        let child = spawn(&[
            "run",
            "--machine",
            "machines/delta.json",
            "--scene",
            "scenes/plb-head-standin.json",
            "--algo",
            "sort-middle/ellsworth",
            "--procs",
            "64",
            "--frames",
            "0..40",
            "-o",
            dir.to_str().unwrap(),
        ]);
        let after = Duration::from_millis(ms.min(120_000));
        killed += usize::from(kill_after(child, after));
        assert_whole(&dir);
        if ms == u64::MAX {
            assert!(
                dir.join("summary.json").exists(),
                "the unkilled run finished"
            );
            assert_eq!(temporaries(&dir), Vec::<String>::new(), "and cleaned up");
        }
    }
    assert!(
        killed >= 3,
        "only {killed} runs were still running when killed"
    );
}

/// A sweep killed part way, then run again into the same folder, finishes with the table,
/// the JSON and the page an uninterrupted sweep writes.
#[test]
fn a_sweep_killed_part_way_resumes_to_the_uninterrupted_table() {
    let root = env!("CARGO_MANIFEST_DIR");
    let specs = common::scratch("spec");
    std::fs::create_dir_all(&*specs).unwrap();
    let spec = specs.join("long.json");
    std::fs::write(
        &spec,
        format!(
            r#"{{"machine": "{root}/machines/delta.json", "scene": "{root}/scenes/plb-head-standin.json",
                "algos": ["sort-middle/static", "sort-middle/ellsworth"], "procs": [1, 2, 4, 8, 16, 32],
                "frames": "0..12", "seed": 1}}"#
        ),
    )
    .unwrap();
    let spec = spec.to_str().unwrap();
    let whole = common::scratch("whole");
    let started = Instant::now();
    let done = Command::new(env!("CARGO_BIN_EXE_sortsim"))
        .args(["sweep", spec, "-o", whole.to_str().unwrap(), "--jobs", "2"])
        .output()
        .unwrap();
    // The kills land at shares of the sweep's own time on this host, early to late, so that
    // a faster simulator or a slower host still has them land part way.
    let uninterrupted = started.elapsed();
    assert!(
        done.status.success(),
        "{}",
        String::from_utf8_lossy(&done.stderr)
    );
    let mut part_way = 0;
    for (k, share) in [0.15, 0.45, 0.8].into_iter().enumerate() {
        let dir = common::scratch(&format!("killed-{k}"));
        let out = dir.to_str().unwrap();
        let child = spawn(&["sweep", spec, "-o", out, "--jobs", "2"]);
        let killed = kill_after(child, uninterrupted.mul_f64(share));
        assert_whole(&dir);
        if killed {
            // A table there was written whole before the kill: the uninterrupted one.
            if let Ok(table) = std::fs::read(dir.join("sweep.csv")) {
                assert_eq!(
                    table,
                    std::fs::read(whole.join("sweep.csv")).unwrap(),
                    "a killed sweep left a table that is not the whole one"
                );
            }
            part_way += usize::from(dir.join("points").exists());
        }
        let again = Command::new(env!("CARGO_BIN_EXE_sortsim"))
            .args(["sweep", spec, "-o", out, "--jobs", "2"])
            .output()
            .unwrap();
        assert!(
            again.status.success(),
            "{}",
            String::from_utf8_lossy(&again.stderr)
        );
        assert_eq!(
            temporaries(&dir),
            Vec::<String>::new(),
            "the rerun cleaned up"
        );
        for file in ["sweep.csv", "sweep.json", "index.html"] {
            assert_eq!(
                std::fs::read(dir.join(file)).unwrap(),
                std::fs::read(whole.join(file)).unwrap(),
                "{file} after a kill at {share} of the sweep's time and a rerun"
            );
        }
    }
    assert!(
        part_way >= 1,
        "no kill landed while points were being written"
    );
}
