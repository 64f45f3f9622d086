//! Sweep specs through `sweep::spec::parse_sweep`: the cartesian product and its documented
//! order, aliases and scalar values, implicit one-processor baselines, paths relative to the
//! sweep file, stable point names, and errors that name the file and the field.

use std::path::Path;

use sortsim::sweep::point_name;
use sortsim::sweep::spec::{parse_sweep, Sweep};

fn sweep(json: &str) -> Sweep {
    parse_sweep(Path::new("sweeps/test.json"), json).unwrap_or_else(|e| panic!("{e}"))
}

/// The error message for `json`, which must be refused.
fn refusal(json: &str) -> String {
    match parse_sweep(Path::new("sweeps/bad.json"), json) {
        Ok(_) => panic!("accepted: {json}"),
        Err(e) => e.to_string(),
    }
}

fn check_refusal(json: &str, fragment: &str) {
    let msg = refusal(json);
    assert!(msg.starts_with("sweeps/bad.json"), "names the file: {msg}");
    assert!(msg.contains(fragment), "expected {fragment:?} in {msg}");
}

#[test]
fn product_order_is_machine_scene_algo_vary_seed_procs() {
    let s = sweep(
        r#"{"machines": ["a.json", "b.json"], "scene": "s.json",
            "algos": ["sort-middle/static", "sort-middle/ellsworth"],
            "procs": [1, 4], "seeds": [7, 8],
            "vary": {"two-step": ["on", "off"], "granularity": [4, 8]}}"#,
    );
    let keys: Vec<&str> = s.dims.iter().map(|d| d.key.as_str()).collect();
    assert_eq!(
        keys,
        [
            "machine",
            "scene",
            "algo",
            "vary.granularity",
            "vary.two-step",
            "seed",
            "procs"
        ]
    );
    assert_eq!(s.points.len(), 2 * 2 * 2 * 2 * 2 * 2);
    assert!(
        s.points.iter().all(|p| p.listed),
        "1 is listed: no implicit baselines"
    );
    let values = |i: usize| s.points[i].values.join(" ");
    assert_eq!(values(0), "a.json s.json sort-middle/static 4 on 7 1");
    assert_eq!(values(1), "a.json s.json sort-middle/static 4 on 7 4");
    assert_eq!(values(2), "a.json s.json sort-middle/static 4 on 8 1");
    assert_eq!(values(4), "a.json s.json sort-middle/static 4 off 7 1");
    assert_eq!(values(8), "a.json s.json sort-middle/static 8 on 7 1");
    assert_eq!(values(16), "a.json s.json sort-middle/ellsworth 4 on 7 1");
    assert_eq!(values(63), "b.json s.json sort-middle/ellsworth 8 off 8 4");
    let p = &s.points[63].run;
    assert_eq!(p.algo, "sort-middle/ellsworth");
    assert_eq!((p.procs, p.seed), (4, 8));
    assert_eq!(p.set.get("granularity").map(String::as_str), Some("8"));
    assert_eq!(p.set.get("two-step").map(String::as_str), Some("off"));
}

#[test]
fn single_values_lists_and_scalars() {
    let s = sweep(
        r#"{"machine": "../machines/delta.json", "scene": "../scenes/x.json", "algo": "sort-middle/static",
            "procs": 16, "frames": "0..2", "set": {"granularity": 8, "two-step": "on", "flag": true, "x": 0.5}}"#,
    );
    // procs 16 needs a 1-processor baseline the spec does not list.
    assert_eq!(s.points.len(), 2);
    assert!(s.points[0].listed && !s.points[1].listed);
    assert_eq!(s.points[1].run.procs, 1);
    let run = &s.points[0].run;
    assert_eq!(
        run.machine,
        Path::new("sweeps/../machines/delta.json"),
        "relative to the sweep file"
    );
    assert_eq!(run.frames.as_deref(), Some("0..2"));
    assert_eq!(run.seed, 1, "default seed");
    let set: Vec<String> = run.set.iter().map(|(k, v)| format!("{k}={v}")).collect();
    assert_eq!(set, ["flag=true", "granularity=8", "two-step=on", "x=0.5"]);
}

#[test]
fn baselines_are_one_per_combination_in_product_order() {
    let s = sweep(
        r#"{"machine": "m.json", "scene": "s.json", "algos": ["sort-middle/static", "sort-middle/ellsworth"],
            "procs": [4, 16], "vary": {"machine.network.fidelity": ["flow", "packet"]}}"#,
    );
    let listed = s.points.iter().filter(|p| p.listed).count();
    let baselines: Vec<String> = s.points[listed..]
        .iter()
        .map(|p| p.values.join(" "))
        .collect();
    assert_eq!(listed, 8);
    assert_eq!(
        baselines,
        [
            "m.json s.json sort-middle/static flow 1 1",
            "m.json s.json sort-middle/static packet 1 1",
            "m.json s.json sort-middle/ellsworth flow 1 1",
            "m.json s.json sort-middle/ellsworth packet 1 1",
        ]
    );
}

#[test]
fn point_names_are_stable_readable_and_distinct() {
    let json = r#"{"machine": "m.json", "scene": "dir/plb.json", "algo": "sort-middle/ellsworth",
                   "procs": [1, 2], "vary": {"two-step": ["on", "off"]}}"#;
    let (a, b) = (sweep(json), sweep(json));
    let names: Vec<String> = a.points.iter().map(|p| point_name(&a, p)).collect();
    assert_eq!(
        names,
        b.points
            .iter()
            .map(|p| point_name(&b, p))
            .collect::<Vec<_>>()
    );
    assert!(
        names[0].starts_with("m_plb_sort-middle-ellsworth_two-step-on_s1_p0001_"),
        "{}",
        names[0]
    );
    let mut unique = names.clone();
    unique.sort();
    unique.dedup();
    assert_eq!(unique.len(), names.len());
    // A shared option changes every name: an old result is never taken for a new point.
    let other = sweep(&json.replace("\"procs\"", "\"set\": {\"granularity\": 4}, \"procs\""));
    assert_ne!(point_name(&other, &other.points[0]), names[0]);
}

#[test]
fn errors_name_file_and_field() {
    let base = r#""machine": "m.json", "scene": "s.json", "algo": "sort-middle/static""#;
    let cases = [
        (format!("{{{base}, \"procs\": [1], \"colour\": 1}}"), "at `colour`: unknown field `colour`"),
        (format!("{{{base}}}"), "missing field `procs`"),
        (format!("{{{base}, \"procs\": []}}"), "at `procs`: the list is empty"),
        (format!("{{{base}, \"procs\": [2, 0]}}"), "at `procs[1]`: a run needs at least 1 processor"),
        (format!("{{{base}, \"procs\": [2, 2]}}"), "at `procs[1]`: `2` is listed twice"),
        (format!("{{{base}, \"procs\": [-1]}}"), "at `procs`"),
        (format!("{{{base}, \"procs\": 1, \"frames\": \"3-4\"}}"), "at `frames`: `3-4`: write A..B"),
        (format!("{{{base}, \"procs\": 1, \"vary\": {{\"g\": [[1]]}}}}"), "at `vary.g`"),
        (format!("{{{base}, \"procs\": 1, \"set\": {{\"g\": 1}}, \"vary\": {{\"g\": [2]}}}}"), "at `vary.g`: `g` is both in `set` and in `vary`"),
        (format!("{{{base}, \"machines\": \"n.json\", \"procs\": 1}}"), "duplicate field `machine`"),
        (
            r#"{"machine": "m.json", "scene": "s.json", "algo": ["sort-middle/static", "sort-last/x"], "procs": 1}"#.to_string(),
            "at `algo[1]`: unknown algorithm `sort-last/x`; valid ids: sort-middle/static",
        ),
        ("{\"machine\": ".to_string(), "sweeps/bad.json:1:12: malformed JSON"),
    ];
    for (json, fragment) in &cases {
        check_refusal(json, fragment);
    }
}

#[test]
fn bundled_sweeps_parse_and_name_existing_files() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("sweeps");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .collect();
    files.sort();
    assert!(
        files.iter().any(|f| f.ends_with("default.json")),
        "{files:?}"
    );
    for file in &files {
        let s = sortsim::sweep::spec::load_sweep(file).unwrap_or_else(|e| panic!("{e}"));
        assert!(
            s.note.is_some(),
            "{}: says what it is and how long it takes",
            file.display()
        );
        for p in &s.points {
            assert!(
                p.run.machine.exists(),
                "{}: {}",
                file.display(),
                p.run.machine.display()
            );
            assert!(
                p.run.scene.exists(),
                "{}: {}",
                file.display(),
                p.run.scene.display()
            );
        }
    }
}
