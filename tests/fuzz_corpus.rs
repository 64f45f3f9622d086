//! Replays every fuzz target's corpus (fuzz/corpus/<target>/, seeded from tests/bad_input and
//! the bundled files, grown and minimised by `cargo fuzz`) through the same checks the targets
//! run (fuzz/checks.rs): no input may panic, and what is written back reads back equal. This is
//! how CI runs the fuzz targets: a quick replay, not a fuzzing campaign.

use std::path::Path;

#[path = "../fuzz/checks.rs"]
mod checks;

fn replay(target: &str, check: fn(&[u8])) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fuzz/corpus")
        .join(target);
    let mut inputs = 0;
    for e in std::fs::read_dir(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
        let path = e.unwrap().path();
        let bytes = std::fs::read(&path).unwrap();
        let outcome = std::panic::catch_unwind(|| check(&bytes));
        assert!(outcome.is_ok(), "{target}: {} panics", path.display());
        inputs += 1;
    }
    assert!(inputs >= 5, "{target}: only {inputs} corpus inputs");
}

#[test]
fn machine_specs() {
    replay("machine", checks::machine);
}

#[test]
fn scene_specs() {
    replay("scene", checks::scene);
}

#[test]
fn run_specs() {
    replay("run", checks::run);
}

#[test]
fn sweep_specs() {
    replay("sweep", checks::sweep);
}

#[test]
fn obj_files() {
    replay("obj", checks::obj);
}

#[test]
fn traces() {
    replay("trace", checks::trace);
}

#[test]
fn patterns() {
    replay("pattern", checks::pattern);
}

#[test]
fn option_values() {
    replay("options", checks::options);
}

#[test]
fn calibration_specs() {
    replay("calibration", checks::calibration);
}

#[test]
fn paper_files() {
    replay("paper", checks::paper);
}

#[test]
fn simulated_runs() {
    replay("simulate", checks::simulate);
}
