//! The later frames' front end made ahead on a second host thread (`RunConfig::front_end_ahead`)
//! changes nothing a run computes: every frame record, the machine's statistics to the last
//! counter, the event count and the last image are those of the same run with every frame
//! made on the simulation's thread, for each family that takes its frames from the host's book
//! (sort-middle with its dealt shares, sort-first and sort-last with geometry and prepared
//! vertices only).

use sortsim::algo::{run, RunResult};

use crate::common;

/// Everything a run computed, as text (the statistics have no equality of their own).
fn answers(result: &RunResult) -> String {
    format!(
        "{:?}\n{:?}\n{:016x}",
        result.frames,
        result.stats,
        result.image.hash()
    )
}

fn run_both(
    machine: &str,
    scene: &str,
    algo: &str,
    procs: u32,
    frames: &str,
    set: &[(&str, &str)],
) {
    let mut cfg = common::frames_config(machine, &common::scene(scene), algo, procs, frames, set);
    assert!(
        cfg.front_end_ahead,
        "a resolved run makes its later frames ahead"
    );
    let ahead = run(&cfg).expect("the run completes");
    cfg.front_end_ahead = false;
    let alone = run(&cfg).expect("the run completes");
    assert!(
        ahead.frames.len() > 1,
        "{algo}: the run has later frames to make ahead"
    );
    assert_eq!(
        answers(&ahead),
        answers(&alone),
        "{algo} on {procs} processors, frames {frames}"
    );
}

#[test]
fn sort_middle_runs_are_the_same_with_their_front_end_dealt_ahead() {
    // Frames that do not start at 0, two-step forwarding, and a buffer that splits batches.
    run_both(
        "delta.json",
        "plb-head-standin.json",
        "sort-middle/ellsworth",
        16,
        "3..7",
        &[],
    );
    run_both(
        "delta.json",
        "plb-head-standin.json",
        "sort-middle/ellsworth",
        16,
        "0..3",
        &[("two-step", "on"), ("buffer", "1KiB")],
    );
    run_both(
        "delta.json",
        "terrain-standin.json",
        "sort-middle/static",
        12,
        "0..4",
        &[],
    );
}

#[test]
fn sort_first_and_sort_last_runs_are_the_same_with_their_geometry_made_ahead() {
    run_both(
        "delta.json",
        "plb-head-standin.json",
        "sort-first/mueller",
        8,
        "0..4",
        &[],
    );
    let (machine, set) = common::sort_last_machine("sort-last/tree");
    run_both(
        machine,
        "plb-head-standin.json",
        "sort-last/tree",
        8,
        "0..4",
        set,
    );
}
