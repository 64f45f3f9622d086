//! What every fuzz target checks, shared by the targets under fuzz_targets/ and by
//! tests/fuzz_corpus.rs, which replays each target's corpus in the ordinary test run.
//!
//! Each check feeds bytes to one of the library's public readers: it must return (a value or
//! an error), never panic; where a format is written back (traces, run specs, patterns), a value
//! read must come back equal after writing and reading it again.

use std::path::Path;

use sortsim::net::pattern::Pattern;
use sortsim::spec::machine::{validate, MachineSpec};
use sortsim::spec::parse_json;
use sortsim::spec::run::RunSpec;
use sortsim::spec::scene::SceneSpec;

/// A check of one target: bytes in, a panic only for a bug.
type Check = fn(&[u8]);

/// Spec and OBJ readers take text: other bytes are not a case for them.
fn utf8(data: &[u8]) -> Option<&str> {
    std::str::from_utf8(data).ok()
}

/// Reads `text` as a `T`; if it reads, writes it back and asserts it reads back equal.
fn round_trip<T>(name: &str, text: &str)
where
    T: serde::de::DeserializeOwned + serde::Serialize + PartialEq + std::fmt::Debug,
{
    if let Ok(value) = parse_json::<T>(file(name), text) {
        let again = serde_json::to_string(&value).expect("what was read serializes");
        let back: T = parse_json(file(name), &again).expect("what was written reads");
        assert_eq!(back, value, "{name}: written and read back");
    }
}

/// The file name errors carry; relative paths inside a spec resolve beside it (nothing there).
fn file(name: &str) -> &'static Path {
    match name {
        "machine" => Path::new("fuzz-input/machine.json"),
        "scene" => Path::new("fuzz-input/scene.json"),
        "run" => Path::new("fuzz-input/run.json"),
        "sweep" => Path::new("fuzz-input/sweep.json"),
        "obj" => Path::new("fuzz-input/mesh.obj"),
        "calibration" => Path::new("fuzz-input/calibration.json"),
        "paper" => Path::new("fuzz-input/paper.json"),
        _ => Path::new("fuzz-input/pattern.json"),
    }
}

pub fn machine(data: &[u8]) {
    let Some(text) = utf8(data) else {
        return;
    };
    if let Ok(spec) = parse_json::<MachineSpec>(file("machine"), text) {
        let _ = validate(file("machine"), spec);
    }
}

pub fn scene(data: &[u8]) {
    let Some(text) = utf8(data) else {
        return;
    };
    if let Ok(spec) = parse_json::<SceneSpec>(file("scene"), text) {
        let _ = spec.validate(file("scene"));
    }
}

pub fn run(data: &[u8]) {
    let Some(text) = utf8(data) else {
        return;
    };
    round_trip::<RunSpec>("run", text);
}

pub fn sweep(data: &[u8]) {
    let Some(text) = utf8(data) else {
        return;
    };
    let _ = sortsim::sweep::spec::parse_sweep(file("sweep"), text);
}

pub fn obj(data: &[u8]) {
    let Some(text) = utf8(data) else {
        return;
    };
    let _ = sortsim::scene::obj::parse(file("obj"), text);
}

pub fn trace(data: &[u8]) {
    if let Ok(trace) = sortsim::trace::decode(data) {
        let again = sortsim::trace::encode(&trace);
        let back = sortsim::trace::decode(&again).expect("an encoded trace decodes");
        assert_eq!(back, trace, "a trace encoded and decoded back");
    }
}

pub fn pattern(data: &[u8]) {
    let Some(text) = utf8(data) else {
        return;
    };
    round_trip::<Pattern>("pattern", text);
}

/// Every command-line value parser the library owns, fed the same text: times, sizes and
/// rates, frame ranges and processor lists, the anti-aliasing modes, sweep shards, Slurm's
/// time, memory and partition, and each algorithm's `--set KEY=VALUE` options. None may
/// panic; what they accept must keep their promises (a frame range non-empty and inside the
/// scene, a list within its limit, a time or size written back reads back equal).
pub fn options(data: &[u8]) {
    let Some(text) = utf8(data) else {
        return;
    };
    use sortsim::units::{Bandwidth, Bytes, SimTime};
    if let Ok(t) = text.parse::<SimTime>() {
        let back: SimTime = format!("{}ps", t.ps())
            .parse()
            .expect("picoseconds read back");
        assert_eq!(back, t, "{text:?}: a time written in ps reads back equal");
    }
    if let Ok(b) = text.parse::<Bytes>() {
        let back: Bytes = format!("{}B", b.get()).parse().expect("bytes read back");
        assert_eq!(back, b, "{text:?}: a size written in B reads back equal");
    }
    let _ = text.parse::<Bandwidth>();
    for count in [1, 80, u32::MAX] {
        if let Ok(range) = sortsim::spec::run::parse_frames(Some(text), count) {
            assert!(
                !range.is_empty() && range.end <= count,
                "{text:?}: frames {range:?} of {count}"
            );
        }
    }
    if let Ok(list) = sortsim::algo::sort_middle::utilization::parse_list(text) {
        assert!(
            list.len() as u64 <= sortsim::limits::MAX_LIST_ITEMS,
            "{text:?}: {} values",
            list.len()
        );
    }
    let _ = sortsim::raster::aa::AaMethod::parse(text);
    let _ = text.parse::<sortsim::accuracy::AaMode>();
    let _ = text.parse::<sortsim::sweep::shard::Shard>();
    let _ = sortsim::sweep::slurm::check_time(text);
    let _ = sortsim::sweep::slurm::check_mem(text);
    let _ = sortsim::sweep::slurm::check_value("--partition", text, "debug");
    let (key, value) = text.split_once('=').unwrap_or(("aa", text));
    let options = sortsim::algo::Options::new([(key.to_string(), value.to_string())].into());
    for algo in sortsim::algo::AlgorithmId::ALL {
        let _ = algo.check_option_values(&options);
    }
}

/// A calibration spec: when it reads, each parameter's fields are scaled at both ends of its
/// range in a bundled machine's and a bundled scene's JSON, as a fit's first candidates are. The
/// field paths are the spec's free text, so walking them must end in an error, never a panic,
/// and what is scaled must still be a spec the machine or scene reader answers.
pub fn calibration(data: &[u8]) {
    let Some(text) = utf8(data) else {
        return;
    };
    let Ok(spec) = sortsim::calibrate::parse_spec(file("calibration"), text) else {
        return;
    };
    // Each bundled file, read once for every input, beside the check that reads what is
    // scaled from it.
    static SUBJECTS: std::sync::OnceLock<[(serde_json::Value, Check); 2]> =
        std::sync::OnceLock::new();
    let subjects = SUBJECTS.get_or_init(|| {
        let read = |text: &str| serde_json::from_str(text).expect("a bundled spec");
        [
            (read(include_str!("../machines/delta.json")), machine),
            (read(include_str!("../scenes/p003-brooks.json")), scene),
        ]
    });
    for (subject, read_back) in subjects {
        for end in [0, 1] {
            let factors: Vec<f64> = spec.parameters.iter().map(|p| p.range[end]).collect();
            let scaled = sortsim::calibrate::scaled_spec(subject, &spec.parameters, &factors);
            if let Ok(scaled) = scaled {
                read_back(scaled.to_string().as_bytes());
            }
        }
    }
}

/// A paper's data file: when it reads, its roles are checked against a list of fits, and every
/// row is printed and judged as a paper's report does, against sortsim numbers near and far.
pub fn paper(data: &[u8]) {
    let Some(text) = utf8(data) else {
        return;
    };
    let Ok(paper) = sortsim::paper::data::parse(file("paper"), text, None) else {
        return;
    };
    let fits: Vec<(String, String, String)> = [
        ("delta.json", "002", "peak-polio"),
        ("scenes/p003-brooks.json", "003", "reduction-brooks"),
    ]
    .map(|(file, paper, row)| (file.into(), paper.into(), row.into()))
    .into();
    let _ = sortsim::paper::data::check_roles(&paper, &fits);
    for row in &paper.rows {
        let _ = (row.claim(), row.tolerance_text());
        let near = row.value.or(row.range.map(|[lo, _]| lo)).unwrap_or(1.0);
        for m in [near, near * 1.5, 0.0, -1.0, f64::MAX, f64::NAN] {
            let _ = row.deviation_pct(m);
            let measured = sortsim::paper::Measured::value(m, "");
            let _ = sortsim::paper::verdict::judge(row, &measured);
        }
    }
}
