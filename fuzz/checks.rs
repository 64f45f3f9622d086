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
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(spec) = parse_json::<MachineSpec>(file("machine"), text) {
        let _ = validate(file("machine"), spec);
    }
}

pub fn scene(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(spec) = parse_json::<SceneSpec>(file("scene"), text) {
        let _ = spec.validate(file("scene"));
    }
}

pub fn run(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(spec) = parse_json::<RunSpec>(file("run"), text) {
        let again = serde_json::to_string(&spec).expect("a run spec serializes");
        let back: RunSpec = parse_json(file("run"), &again).expect("a written run spec reads");
        assert_eq!(back, spec, "a run spec written and read back");
    }
}

pub fn sweep(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let _ = sortsim::sweep::spec::parse_sweep(file("sweep"), text);
}

pub fn obj(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
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
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(p) = parse_json::<Pattern>(file("pattern"), text) {
        let again = serde_json::to_string(&p).expect("a pattern serializes");
        let back: Pattern = parse_json(file("pattern"), &again).expect("a written pattern reads");
        assert_eq!(back, p, "a pattern written and read back");
    }
}
