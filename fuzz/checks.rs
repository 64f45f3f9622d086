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
