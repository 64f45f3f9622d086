//! `sortsim paper`: each paper's `--quick` report, as a user gets it from the command line,
//! keeps its verdicts from silently getting worse. The counts below are those measured when
//! the rows were written (release build, seed 1); a change that makes a row worse fails here
//! and must either be fixed or be recorded here with its reason. Key rows are held to their
//! own verdicts. The data files are checked against the papers' text.
//!
//! The papers' runs are the slowest part of the suite, so `sortsim paper all --quick` runs
//! once for every test here that reads a quick report (`quick`), and the seed papers once each
//! in full for the comparison of the two (paper 004 has no quick mode: it runs its single
//! frames either way); one paper also runs alone, as `sortsim paper ID --quick`.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

use serde_json::Value;

fn sortsim(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sortsim"))
        .args(args)
        .output()
        .expect("sortsim runs")
}

/// Runs `sortsim paper ID --quick` into a fresh folder; returns its paper.json and the folder.
fn quick_report(id: &str) -> (Value, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let stdout = paper_ok(&["paper", id, "--quick", "--jobs", "2", "-o", out]);
    assert!(stdout.contains(&format!("paper {id}: ")), "{stdout}");
    (checked_report(&dir.path().join(id)), dir)
}

/// Paper `id`'s quick report, from the one `sortsim paper all --quick` of this test run (its
/// folder checked, then removed).
fn quick(id: &str) -> Value {
    static QUICK: OnceLock<Vec<(String, Value)>> = OnceLock::new();
    let reports = QUICK.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        all_reports(dir.path())
    });
    reports
        .iter()
        .find(|(paper, _)| paper == id)
        .unwrap_or_else(|| panic!("no paper {id} in `paper all`"))
        .1
        .clone()
}

/// Every file the report names exists: the plots the page shows, the markdown tables.
fn check_folder(folder: &Path, json: &Value) {
    let html = std::fs::read_to_string(folder.join("index.html")).unwrap();
    let md = std::fs::read_to_string(folder.join("paper.md")).unwrap();
    assert!(html.starts_with("<!DOCTYPE html>"));
    assert!(
        !html.contains("http://") && !html.contains("https://"),
        "self-contained"
    );
    for src in html.split("src=\"").skip(1) {
        let file = &src[..src.find('"').unwrap()];
        assert!(folder.join(file).is_file(), "{file} is missing");
    }
    let rows = json["rows"].as_array().unwrap();
    for row in rows {
        let figure = row["figure"].as_str().unwrap();
        assert!(md.contains(&format!("## {figure}")), "{figure}");
        assert!(html.contains(&format!("<h2>{figure}</h2>")), "{figure}");
    }
    let predicted = rows.iter().filter(|r| r["role"] == "predicted").count();
    let headline = |t: &Value| {
        format!(
            "predicted: {} rows: {} exact, {} within tolerance, {} shape holds, {} differ",
            predicted, t["exact"], t["within_tolerance"], t["shape_holds"], t["differs"]
        )
    };
    assert!(md.contains(&headline(&json["tally"])), "{md}");
    // The per-role tallies add up to every row, and a fitted row names its machine.
    let by_role: u64 = json["by_role"]
        .as_object()
        .unwrap()
        .values()
        .map(|t| {
            ["exact", "within_tolerance", "shape_holds", "differs"]
                .iter()
                .map(|k| t[k].as_u64().unwrap())
                .sum::<u64>()
        })
        .sum();
    assert_eq!(by_role as usize, rows.len());
    for row in rows {
        assert_eq!(row["role"] == "fitted", row["fit"].is_string(), "{row}");
    }
}

fn verdict_rank(v: &str) -> u8 {
    match v {
        "exact" => 0,
        "within-tolerance" => 1,
        "shape-holds" => 2,
        "differs" => 3,
        other => panic!("unknown verdict {other}"),
    }
}

/// At least `matching` predicted rows exact or within tolerance, at most `differ` predicted
/// rows that differ; every key row at least as good as its verdict; every miss says why.
fn hold(json: &Value, matching: u64, differ: u64, key_rows: &[(&str, &str)]) {
    let t = &json["tally"];
    let good = t["exact"].as_u64().unwrap() + t["within_tolerance"].as_u64().unwrap();
    eprintln!("paper {}: tally {t}", json["paper"]);
    assert!(good >= matching, "{good} rows match, recorded {matching}");
    assert!(
        t["differs"].as_u64().unwrap() <= differ,
        "{} rows differ, recorded {differ}",
        t["differs"]
    );
    let rows = json["rows"].as_array().unwrap();
    for (id, verdict) in key_rows {
        let row = rows
            .iter()
            .find(|r| r["id"] == *id)
            .unwrap_or_else(|| panic!("no row {id}"));
        assert!(
            verdict_rank(row["verdict"].as_str().unwrap()) <= verdict_rank(verdict),
            "{id}: {} (sortsim {}, paper {}), held to {verdict}",
            row["verdict"],
            row["sortsim"],
            row["paper"]
        );
    }
    for row in rows {
        let v = row["verdict"].as_str().unwrap();
        let numeric = row["paper"] != "claim";
        if v == "differs" || (v == "shape-holds" && numeric) {
            let why = row["why"].as_str().unwrap();
            assert!(
                !why.is_empty() && !why.contains("no explanation"),
                "{}: a miss must say why",
                row["id"]
            );
        }
    }
}

#[test]
fn paper_000_memory_and_adaptation() {
    let json = quick("000");
    hold(
        &json,
        6,
        8,
        &[
            // Exact arithmetic (Section 4 and 7.1).
            ("pixel-bytes", "exact"),
            // Section 4.2's rule: below one unit of depth spread reclaimed, at one kept.
            ("reclaim-rule", "shape-holds"),
            ("subpixel-bytes", "exact"),
            ("supersample-4x4-mb", "exact"),
            ("pool-share-4x4", "exact"),
            ("pool-share-3x3", "exact"),
            ("pool-share-2x2", "exact"),
            // 10.49 MB exact against the paper's 10.44: 0.6%.
            ("pool-2x2-mb", "within-tolerance"),
            ("letter-b-supersampled", "within-tolerance"),
            ("per-processor-memory", "within-tolerance"),
            ("view-change-recovers", "shape-holds"),
        ],
    );
}

#[test]
fn paper_001_table_1_and_figures() {
    // Run alone, as `sortsim paper 001`, the one paper quick enough to run twice.
    let (json, _dir) = quick_report("001");
    hold(
        &json,
        10,
        17,
        &[
            // Section 5.1's definition, recomputed exactly from a run's finishing times.
            ("imbalance-definition", "shape-holds"),
            ("dlb-helps-big-primitives-only", "shape-holds"),
            ("pc-beats-df", "shape-holds"),
            ("df-merge-grows", "within-tolerance"),
            ("pc-merge-flat", "within-tolerance"),
            ("slmf-wins-from-8", "shape-holds"),
            ("sequential-scanline-slower", "shape-holds"),
        ],
    );
    // Table 1's throughputs, the targets of machines/fits/multicluster-to-001-table1.json:
    // each within the row's 10%, but for five misses held at today's values. Misc_III at 8
    // and 16 nodes is mostly merge time, which the one fitted link bandwidth makes 10-17%
    // slow while Gears and Mountain, whose stand-ins rasterize 10-18% faster than the paper's
    // uniprocessor times, run up to 10% fast (Mountain on at 4 nodes: +10.1%); Misc_I at 2
    // nodes is 11.3% slow.
    let misses = [
        ("t1-misc1-off-2-throughput", -13.0, -10.0),
        ("t1-mountain-on-4-throughput", 9.0, 12.0),
        ("t1-misc3-off-8-throughput", -12.0, -9.0),
        ("t1-misc3-on-16-throughput", -16.0, -12.0),
        ("t1-misc3-off-16-throughput", -18.0, -14.0),
    ];
    let rows = json["rows"].as_array().unwrap();
    let throughputs: Vec<&Value> = rows
        .iter()
        .filter(|r| {
            let id = r["id"].as_str().unwrap();
            id.starts_with("t1-") && id.ends_with("-throughput")
        })
        .collect();
    assert_eq!(throughputs.len(), 32);
    for row in throughputs {
        let id = row["id"].as_str().unwrap();
        let deviation = row["deviation_pct"].as_f64().unwrap();
        match misses.iter().find(|m| m.0 == id) {
            Some(&(_, low, high)) => assert!(
                (low..=high).contains(&deviation),
                "{id}: {deviation:+.1}%, held to {low}..{high}"
            ),
            None => assert!(
                deviation.abs() <= 10.0,
                "{id}: {deviation:+.1}% (Table 1, 10%)"
            ),
        }
    }
}

#[test]
fn paper_002_delta() {
    let json = quick("002");
    hold(
        &json,
        8,
        // util-previous-drop-other-512 (the 12% on another model), the PLB head's peak
        // location, the centre's longer wait and the two Figure 9 rows checked below.
        5,
        &[
            ("delta-nodes", "exact"),
            // Figure 9's peak: the summing tree's wait counted in the next frame puts it at 256.
            ("peak-polio-procs", "exact"),
            ("peaks-then-falls", "shape-holds"),
            // The Delta's fit to paper 002 (machines/fits/delta-to-002-fig9.json, then
            // delta-to-002-split.json): each target within the paper row's tolerance (Figure 9,
            // Discussion, Implementation) but the polio peak, checked below.
            ("plb-fps-128", "within-tolerance"),
            ("two-step-largest-gain", "within-tolerance"),
            ("peak-polio-aa", "within-tolerance"),
            ("aa-ratio-8", "within-tolerance"),
            ("delta-overhead-share", "within-tolerance"),
            ("first-frame-interleaved", "shape-holds"),
            ("greedy-largest-first", "shape-holds"),
            ("delta-link", "exact"),
            ("delta-buffer", "exact"),
            ("model-polio-triangles", "exact"),
            ("model-plb-overlap", "within-tolerance"),
            ("two-step-messages-256", "exact"),
            ("two-step-messages-min", "shape-holds"),
            ("util-rises-with-g", "shape-holds"),
            ("util-falls-with-n", "shape-holds"),
            ("util-previous-drop-512", "within-tolerance"),
            ("two-step-helps-small-many", "shape-holds"),
            ("aa-ratio-512", "within-tolerance"),
            ("aa-ratio-256", "shape-holds"),
        ],
    );
    // The misses, held at today's values so that a change moving them is seen.
    let value = |id: &str| -> f64 {
        let rows = json["rows"].as_array().unwrap();
        let row = rows.iter().find(|r| r["id"] == id).unwrap();
        row["sortsim"].as_f64().unwrap()
    };
    // Figure 9's polio peak (2.8 M, tolerance 10%) and the PLB head's 19 frames/s at 128
    // (tolerance 10%) pull against each other on the stand-ins; with the cpu costs split
    // into per-triangle and per-pixel factors, and refitted with the interfaces' message gap,
    // the fit lands at 2.49 M (-11%) and 20.2 frames/s (+6.4%, within).
    let peak = value("peak-polio");
    assert!((2.3..=2.52).contains(&peak), "polio peak {peak} M");
    let fps = value("plb-fps-128");
    assert!(
        (19.0..=20.9).contains(&fps),
        "PLB head at 128: {fps} frames/s"
    );
    // The bisection links' 2.5 MB/s (tolerance 25%): sortsim's screen triangles carry about
    // a quarter of the bytes per triangle the paper's figure implies; 0.74 MB/s today.
    let bisection = value("bisection-link-rate");
    assert!(
        (0.5..=0.9).contains(&bisection),
        "bisection {bisection} MB/s"
    );
    // 40% of cpu time in communication (tolerance 5 points): sortsim counts the message
    // overheads alone; 6.6% today.
    let comm = value("comm-share-128");
    assert!((3.0..=7.0).contains(&comm), "communication {comm}%");
    // "A quarter of the maximum rate for 4-Kbyte messages": 10 MB/s, the rate the Delta's
    // interface gap (network.message_gap, 168.66 us) is computed from, so this checks the
    // engine and network together: 64 buffers at 409.6 us each, plus the last buffer's
    // receive overhead, 9.9 MB/s.
    let stream = value("buffer-stream-rate");
    assert!(
        (9.7..=10.1).contains(&stream),
        "buffer stream {stream} MB/s"
    );
}

#[test]
fn paper_003_snooping() {
    let json = quick("003");
    hold(
        &json,
        5,
        2,
        &[
            // Fitted rows: Brooks' and Cube's footprints (scenes/fits/) still give the
            // reductions they were fitted to.
            ("reduction-brooks", "within-tolerance"),
            ("reduction-cube", "within-tolerance"),
            ("t1-bike-area", "exact"),
            ("t1-roses-depth", "exact"),
            ("direct-send-is-dA", "shape-holds"),
            ("pixelflow-is-nA", "shape-holds"),
            ("expected-is-formula", "shape-holds"),
            ("even-bound-holds", "shape-holds"),
            ("worst-case-nA", "shape-holds"),
            ("zbuffer-writes-expected", "shape-holds"),
            // Roses 2.3 and Wash.ht 2.0 at the paper's digits or within 10%.
            ("reduction-roses", "within-tolerance"),
            ("reduction-washht", "within-tolerance"),
            ("reduction-bike", "within-tolerance"),
            ("rises-then-plateaus", "shape-holds"),
            ("zinnia-background-first", "shape-holds"),
            ("zinnia-fixed", "shape-holds"),
        ],
    );
}

/// Paper 004: radix-k on Blue Gene/P, all predicted (the machine is fitted to nothing). The
/// rows come from the papers' summaries (their abstracts and the first author's page), so none
/// quotes text that ../shared/papers could check.
#[test]
fn paper_004_radix_k_on_blue_gene() {
    let json = quick("004");
    hold(
        &json,
        2,
        3,
        &[
            // Peterka's page: radix-k ahead of binary swap by 40%; 40 +- 15 points at 32.
            ("rk-gain-32", "within-tolerance"),
            // Up to 5x with bounding boxes and run-length encoding; 5 +- 50%.
            ("bounds-rle-up-to-5x", "within-tolerance"),
        ],
    );
    let rows = json["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 5);
    for row in rows {
        assert_eq!(row["role"], "predicted", "{}", row["id"]);
        assert!(!row["location"].as_str().unwrap().is_empty());
    }
    // Radix-k is ahead of binary swap at every process count, dense or bounded.
    for id in ["rk-gain-32", "rk-gain-512", "rk-gain-4096"] {
        let gain = rows.iter().find(|r| r["id"] == id).unwrap()["sortsim"]
            .as_f64()
            .unwrap();
        assert!(gain > 0.0, "{id}: {gain}");
    }
    let bounded = rows
        .iter()
        .find(|r| r["id"] == "bounds-rle-up-to-5x")
        .unwrap();
    assert!(bounded["sortsim"].as_f64().unwrap() > 1.0);
}

/// The papers' text, beside the repository as CI has it.
fn paper_text(id: &str) -> String {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/papers");
    let file: PathBuf = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .find(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with(&format!("{id}_")))
        })
        .unwrap_or_else(|| panic!("no text of paper {id} in {}", dir.display()));
    std::fs::read_to_string(file).unwrap()
}

fn words(text: &str) -> String {
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// Every quote in papers/NNN.json stands in the paper's text (whitespace aside), so a value
/// cannot drift from its source unnoticed; every row names its figure and location.
#[test]
fn every_quote_is_the_papers_words() {
    for id in ["000", "001", "002", "003"] {
        let text = words(&paper_text(id));
        let data: Value = serde_json::from_str(
            &std::fs::read_to_string(
                Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("papers/{id}.json")),
            )
            .unwrap(),
        )
        .unwrap();
        let rows = data["rows"].as_array().unwrap();
        assert!(rows.len() >= 25, "{id}: {} rows", rows.len());
        let mut quoted = 0;
        for row in rows {
            assert!(!row["figure"].as_str().unwrap().is_empty());
            assert!(!row["location"].as_str().unwrap().is_empty());
            if let Some(q) = row["quote"].as_str() {
                assert!(text.contains(&words(q)), "{id} {}: {q:?}", row["id"]);
                quoted += 1;
            }
        }
        assert!(quoted >= 5, "{id}: only {quoted} quotes");
    }
}

#[test]
fn an_unknown_paper_is_refused() {
    let out = sortsim(&["paper", "005"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("005") && err.contains("004"), "{err}");
}

#[test]
fn an_unwritable_folder_is_refused_before_anything_runs() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("a-file");
    std::fs::write(&file, "").unwrap();
    let out = sortsim(&["paper", "001", "-o", file.join("report").to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("cannot write") && err.contains("a-file"),
        "{err}"
    );
    assert!(out.stdout.is_empty(), "nothing ran");
}

/// Runs `sortsim paper all --quick` into `dir`; each paper's paper.json by id, its folder
/// checked.
fn all_reports(dir: &Path) -> Vec<(String, Value)> {
    let stdout = paper_ok(&[
        "paper",
        "all",
        "--quick",
        "--jobs",
        "2",
        "-o",
        dir.to_str().unwrap(),
    ]);
    ["000", "001", "002", "003", "004"]
        .iter()
        .map(|id| {
            assert!(stdout.contains(&format!("paper {id}: ")), "{stdout}");
            (id.to_string(), checked_report(&dir.join(id)))
        })
        .collect()
}

/// Runs `sortsim paper ID` in full into `dir`; its paper.json, its folder checked.
fn full_report(dir: &Path, id: &str) -> Value {
    let stdout = paper_ok(&["paper", id, "--jobs", "2", "-o", dir.to_str().unwrap()]);
    assert!(stdout.contains(&format!("paper {id}: ")), "{stdout}");
    checked_report(&dir.join(id))
}

/// Runs a `sortsim paper` command that must succeed; what it printed.
fn paper_ok(args: &[&str]) -> String {
    let out = sortsim(args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// A paper's report folder: its paper.json, after checking that every file it names exists.
fn checked_report(folder: &Path) -> Value {
    let json: Value =
        serde_json::from_str(&std::fs::read_to_string(folder.join("paper.json")).unwrap()).unwrap();
    check_folder(folder, &json);
    json
}

/// `--quick` runs enough frames that each compared value lies within its row's tolerance of
/// the full run's (the tolerance's width in the row's unit; a range, half its width; a bound
/// or a claim, the same verdict), or the row says why it is approximate, and then it really
/// is (a stale mark would hide the next change that makes quick and full agree or part).
#[test]
fn quick_values_are_within_tolerance_of_the_full_runs() {
    let dir = tempfile::tempdir().unwrap();
    let full: Vec<(String, Value)> = ["000", "001", "002", "003"]
        .iter()
        .map(|id| (id.to_string(), full_report(dir.path(), id)))
        .collect();
    let mut compared = 0;
    for (id, full_json) in &full {
        let quick_json = quick(id);
        let quick_rows = quick_json["rows"].as_array().unwrap();
        let full_rows = full_json["rows"].as_array().unwrap();
        let data: Value = serde_json::from_str(
            &std::fs::read_to_string(
                Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("papers/{id}.json")),
            )
            .unwrap(),
        )
        .unwrap();
        for (q, f) in quick_rows.iter().zip(full_rows) {
            assert_eq!(q["id"], f["id"]);
            let reference = data["rows"]
                .as_array()
                .unwrap()
                .iter()
                .find(|r| r["id"] == q["id"])
                .unwrap();
            let allowed = match (
                &reference["tolerance"],
                reference["value"].as_f64(),
                reference["range"].as_array(),
            ) {
                (t, Some(v), None) if t["relative-pct"].is_f64() || t["relative-pct"].is_u64() => {
                    Some(t["relative-pct"].as_f64().unwrap() / 100.0 * v.abs())
                }
                (t, Some(_), None) if !t["absolute"].is_null() => t["absolute"].as_f64(),
                (_, None, Some(r)) => Some((r[1].as_f64().unwrap() - r[0].as_f64().unwrap()) / 2.0),
                _ => None,
            }
            .filter(|_| reference["relation"].is_null());
            let agrees = match (allowed, q["sortsim"].as_f64(), f["sortsim"].as_f64()) {
                (Some(a), Some(qv), Some(fv)) => (qv - fv).abs() <= a,
                _ => q["verdict"] == f["verdict"],
            };
            let marked = reference["approximate_when_quick"].is_string();
            assert!(
                agrees != marked,
                "paper {id} {}: quick {} ({}), full {} ({}), allowed {allowed:?}; {}",
                q["id"],
                q["sortsim"],
                q["verdict"],
                f["sortsim"],
                f["verdict"],
                if marked {
                    "marked approximate_when_quick, but they agree: remove the mark"
                } else {
                    "give the quick run more frames or mark the row approximate_when_quick"
                }
            );
            assert_eq!(q["approximate"].is_string(), marked, "{}", q["id"]);
            compared += 1;
        }
    }
    assert!(compared > 200, "{compared} rows compared");
}
