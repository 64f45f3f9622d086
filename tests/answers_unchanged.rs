//! Simulated answers that a change to the simulator's speed must not move: summary.json and
//! the image of a few runs of every algorithm family at every network fidelity, and netsim
//! reports of contended patterns, each hashed (FNV-1a 64) and compared with the hash the
//! code gave before the flow model, routing and engine were made faster.
//!
//! summary.json is hashed with its count of engine events set to zero: that count measures the
//! engine's work (a wake-up that does nothing is one), not the simulated machine.
//!
//! A mismatch means a simulated picosecond, byte or pixel changed. If a change is meant to
//! move answers (a model fix, not a speed-up), the new hashes are printed for the commit
//! that says why.

use crate::common;

use std::collections::BTreeMap;
use std::path::PathBuf;

use sortsim::algo::run;
use sortsim::metrics::run::RunSummary;
use sortsim::net::pattern::{all_to_all, hot_spot, random_staggered, run_pattern, Pattern};
use sortsim::net::{Fidelity, NetworkConfig, TopologyKind};
use sortsim::output::to_json;
use sortsim::spec::run::RunSpec;
use sortsim::trace::format::fnv1a64;
use sortsim::units::{Bytes, SimTime};

const FIDELITIES: [&str; 4] = ["ideal", "hops", "flow", "packet"];

/// The shipped Delta's interfaces' gap (machines/delta.json), set on cases whose hashes hold
/// the order of the messages the interfaces hold.
const DELTA_GAP: (&str, &str) = ("machine.network.message_gap", "168.66us");

/// (case, hash of summary.json without its event count, hash of the image), recorded at
/// d25ffe7, where the hashes of the whole summary.json recorded before the speed-up still held;
/// the cases with the interfaces' message gap at 66f8e72, where the gap came in.
const RUNS: &[(&str, u64, u64)] = &[
    ("sort-middle/ellsworth delta.json plb-head-standin.json n=64 frames=0..2 two-step=on ideal", 0x2f8e692975a4c6fc, 0x8c3aa80857f938f7),
    ("sort-middle/ellsworth delta.json plb-head-standin.json n=64 frames=0..2 two-step=on hops", 0x943e2d430415bb15, 0x8c3aa80857f938f7),
    ("sort-middle/ellsworth delta.json plb-head-standin.json n=64 frames=0..2 two-step=on flow", 0x914432dd521ae6ad, 0x8c3aa80857f938f7),
    ("sort-middle/ellsworth delta.json plb-head-standin.json n=64 frames=0..2 two-step=on packet", 0x31c8c7847f4cdf65, 0x8c3aa80857f938f7),
    ("sort-middle/ellsworth delta.json plb-head-standin.json n=64 frames=0..2 two-step=on machine.network.message_gap=168.66us ideal", 0xb2879d41fb688ed0, 0x8c3aa80857f938f7),
    ("sort-middle/ellsworth delta.json plb-head-standin.json n=64 frames=0..2 two-step=on machine.network.message_gap=168.66us hops", 0x735c8e92ed011663, 0x8c3aa80857f938f7),
    ("sort-middle/ellsworth delta.json plb-head-standin.json n=64 frames=0..2 two-step=on machine.network.message_gap=168.66us flow", 0xa6f9d0182e4d9eda, 0x8c3aa80857f938f7),
    ("sort-middle/ellsworth delta.json plb-head-standin.json n=64 frames=0..2 two-step=on machine.network.message_gap=168.66us packet", 0xa4c89499f99ff3c1, 0x8c3aa80857f938f7),
    ("sort-middle/ellsworth delta.json polio-standin.json n=512 frames=0 ideal", 0xae15d5ceffd7fb70, 0x0681af2dce78a65e),
    ("sort-middle/ellsworth delta.json polio-standin.json n=512 frames=0 hops", 0xdd6d581230f76d25, 0x0681af2dce78a65e),
    ("sort-middle/ellsworth delta.json polio-standin.json n=512 frames=0 flow", 0x5e46e1fcb09a430d, 0x0681af2dce78a65e),
    ("sort-middle/ellsworth delta.json polio-standin.json n=512 frames=0 packet", 0xdf2fd08eac8d92d7, 0x0681af2dce78a65e),
    ("sort-middle/ellsworth delta.json polio-standin.json n=512 frames=0 machine.network.message_gap=168.66us ideal", 0xce3186ceca2f9f9d, 0x0681af2dce78a65e),
    ("sort-middle/ellsworth delta.json polio-standin.json n=512 frames=0 machine.network.message_gap=168.66us hops", 0x13dafb4403e1b3f0, 0x0681af2dce78a65e),
    ("sort-middle/ellsworth delta.json polio-standin.json n=512 frames=0 machine.network.message_gap=168.66us flow", 0x88e8f7f561d13c83, 0x0681af2dce78a65e),
    ("sort-middle/ellsworth delta.json polio-standin.json n=512 frames=0 machine.network.message_gap=168.66us packet", 0xeaf0413e1c809455, 0x0681af2dce78a65e),
    ("sort-middle/static power-challenge.json p000-tetra-500.json n=8 frames=0..2 ideal", 0x22e7c5fa3af0078d, 0x0346fc8a424f6732),
    ("sort-middle/static power-challenge.json p000-tetra-500.json n=8 frames=0..2 hops", 0xcfd48abfcd604a4c, 0x0346fc8a424f6732),
    ("sort-middle/static power-challenge.json p000-tetra-500.json n=8 frames=0..2 flow", 0xb7b9184211cc7303, 0x0346fc8a424f6732),
    ("sort-middle/static power-challenge.json p000-tetra-500.json n=8 frames=0..2 packet", 0x341461fd6a22b5f3, 0x0346fc8a424f6732),
    ("sort-last/df multicluster-torus.json spd-teapot.json n=16 frames=0 assign=request ideal", 0x6b5c6d2fc686228e, 0xf308eb1ba10fe0d3),
    ("sort-last/df multicluster-torus.json spd-teapot.json n=16 frames=0 assign=request hops", 0x40edca026f8996d3, 0xf308eb1ba10fe0d3),
    ("sort-last/df multicluster-torus.json spd-teapot.json n=16 frames=0 assign=request flow", 0x451d512a71d618d5, 0xf308eb1ba10fe0d3),
    ("sort-last/df multicluster-torus.json spd-teapot.json n=16 frames=0 assign=request packet", 0x0919a0fbfeb37005, 0xf308eb1ba10fe0d3),
    ("sort-last/pc multicluster-pipeline.json spd-teapot.json n=8 frames=0 ideal", 0xc34289b2305cf6d3, 0xf308eb1ba10fe0d3),
    ("sort-last/pc multicluster-pipeline.json spd-teapot.json n=8 frames=0 hops", 0x518ff2bca167284c, 0xf308eb1ba10fe0d3),
    ("sort-last/pc multicluster-pipeline.json spd-teapot.json n=8 frames=0 flow", 0xeb964091ec75ad29, 0xf308eb1ba10fe0d3),
    ("sort-last/pc multicluster-pipeline.json spd-teapot.json n=8 frames=0 packet", 0xeb38147a1e292247, 0xf308eb1ba10fe0d3),
    ("sort-last/direct-send denali-crossbar.json p003-cube.json n=16 frames=0 local-zbuffer=on ideal", 0x061f2e3eeb697a19, 0xcc93046f41923d57),
    ("sort-last/direct-send denali-crossbar.json p003-cube.json n=16 frames=0 local-zbuffer=on hops", 0xad495ddf0c7bf8ac, 0xcc93046f41923d57),
    ("sort-last/direct-send denali-crossbar.json p003-cube.json n=16 frames=0 local-zbuffer=on flow", 0x60d194b5e3933715, 0xcc93046f41923d57),
    ("sort-last/direct-send denali-crossbar.json p003-cube.json n=16 frames=0 local-zbuffer=on packet", 0x02bfd913ea6db34d, 0xcc93046f41923d57),
    ("sort-last/snooping snooping-bus.json p003-cube.json n=16 frames=0 assign=random ideal", 0x0e2a3356d850f765, 0xcc93046f41923d57),
    ("sort-last/snooping snooping-bus.json p003-cube.json n=16 frames=0 assign=random hops", 0xe4fc0e04d5ee3a1c, 0xcc93046f41923d57),
    ("sort-last/snooping snooping-bus.json p003-cube.json n=16 frames=0 assign=random flow", 0x18a8cb5032aa0635, 0xcc93046f41923d57),
    ("sort-last/snooping snooping-bus.json p003-cube.json n=16 frames=0 assign=random packet", 0x99c50feeeea6ca32, 0xcc93046f41923d57),
];

/// (case, hash of the netsim report), recorded before the speed-up; those with a gap at 66f8e72.
const PATTERNS: &[(&str, u64)] = &[
    (
        "torus 16x32, 4096 staggered, 168.66us gap, hops",
        0x5dc7b4a25e51d2c6,
    ),
    (
        "torus 16x32, 4096 staggered, 168.66us gap, flow",
        0xb909fe382426868b,
    ),
    ("torus 16x32, 4096 staggered, flow", 0xfefedad2f36d95ba),
    ("mesh 16x32, 4096 staggered, flow", 0x32f075b4ce0d1d38),
    ("torus 4x4, all-to-all 64KiB, flow", 0x3bcbceee61ce98a3),
    ("mesh 8x8, hot spot 4KiB, flow", 0xca6639a17a590a2c),
    (
        "torus 16x32, 4096 staggered, 168.66us gap, packet",
        0x1f99757ef4908d21,
    ),
    ("torus 16x32, 4096 staggered, packet", 0x669673c4460ec0e8),
    ("mesh 16x32, 4096 staggered, packet", 0x498271c47f49fa39),
    ("torus 4x4, all-to-all 64KiB, packet", 0x6a0e8a7331f4ae95),
    ("mesh 8x8, hot spot 4KiB, packet", 0x86c39444152de75e),
];

struct Case {
    name: String,
    spec: RunSpec,
    /// The scene as the hashes name it: its shipped path, also where a frozen copy stands in.
    scene: String,
}

/// The machine or scene a case runs on: the copy frozen under tests/answers_unchanged/ when
/// there is one (the Delta as it was before its costs were fitted to all of paper 002, the
/// Cube stand-in before its footprint was fitted to paper 003: a fit moves answers on
/// purpose, and these hashes prove only that speed-ups do not), else the shipped file in
/// `folder`.
fn frozen_or_shipped(folder: &str, file: &str) -> PathBuf {
    let frozen = PathBuf::from("tests/answers_unchanged").join(file);
    if frozen.is_file() {
        frozen
    } else {
        PathBuf::from(folder).join(file)
    }
}

fn case(
    machine: &str,
    scene: &str,
    algo: &str,
    procs: u32,
    frames: &str,
    set: &[(&str, &str)],
) -> Vec<Case> {
    FIDELITIES
        .iter()
        .map(|fidelity| {
            let mut options: BTreeMap<String, String> = set
                .iter()
                .map(|(k, v)| (k.to_string(), v.to_string()))
                .collect();
            options.insert("machine.network.fidelity".into(), fidelity.to_string());
            let label: String = set.iter().map(|(k, v)| format!(" {k}={v}")).collect();
            Case {
                name: format!(
                    "{algo} {machine} {scene} n={procs} frames={frames}{label} {fidelity}"
                ),
                spec: RunSpec {
                    schema: None,
                    machine: frozen_or_shipped("machines", machine),
                    scene: frozen_or_shipped("scenes", scene),
                    algo: algo.into(),
                    procs,
                    frames: Some(frames.into()),
                    seed: 1,
                    set: options,
                },
                scene: format!("scenes/{scene}"),
            }
        })
        .collect()
}

fn run_cases() -> Vec<Case> {
    [
        case(
            "delta.json",
            "plb-head-standin.json",
            "sort-middle/ellsworth",
            64,
            "0..2",
            &[("two-step", "on")],
        ),
        // The frozen Delta with the shipped Delta's interface gap (the held messages' order).
        case(
            "delta.json",
            "plb-head-standin.json",
            "sort-middle/ellsworth",
            64,
            "0..2",
            &[("two-step", "on"), DELTA_GAP],
        ),
        case(
            "delta.json",
            "polio-standin.json",
            "sort-middle/ellsworth",
            512,
            "0",
            &[],
        ),
        case(
            "delta.json",
            "polio-standin.json",
            "sort-middle/ellsworth",
            512,
            "0",
            &[DELTA_GAP],
        ),
        case(
            "power-challenge.json",
            "p000-tetra-500.json",
            "sort-middle/static",
            8,
            "0..2",
            &[],
        ),
        case(
            "multicluster-torus.json",
            "spd-teapot.json",
            "sort-last/df",
            16,
            "0",
            &[("assign", "request")],
        ),
        case(
            "multicluster-pipeline.json",
            "spd-teapot.json",
            "sort-last/pc",
            8,
            "0",
            &[],
        ),
        case(
            "denali-crossbar.json",
            "p003-cube.json",
            "sort-last/direct-send",
            16,
            "0",
            &[("local-zbuffer", "on")],
        ),
        case(
            "snooping-bus.json",
            "p003-cube.json",
            "sort-last/snooping",
            16,
            "0",
            &[("assign", "random")],
        ),
    ]
    .into_iter()
    .flatten()
    .collect()
}

/// The Delta's links and switches, wired as `topology` with `dims`; without its interfaces'
/// gap, which these transports' hashes predate (`tests/net_interface.rs` checks the gap).
fn delta_network(topology: TopologyKind, dims: &[u32], fidelity: Fidelity) -> NetworkConfig {
    let machine = common::machine(
        &std::fs::read_to_string(common::root().join("machines/delta.json")).unwrap(),
    );
    NetworkConfig {
        topology,
        dims: dims.to_vec(),
        fidelity,
        message_gap: SimTime::ZERO,
        ..machine.network
    }
}

fn pattern_cases() -> Vec<(String, NetworkConfig, Pattern)> {
    let sizes = [Bytes::new(4096), Bytes::new(65536)];
    let staggered = random_staggered(512, 4096, &sizes, SimTime::from_ms(8), 7);
    let mut cases = Vec::new();
    for fidelity in [Fidelity::Hops, Fidelity::Flow, Fidelity::Packet] {
        let name = fidelity.name();
        // The shipped Delta's interfaces, which hold every message until it leaves.
        cases.push((
            format!("torus 16x32, 4096 staggered, {} gap, {name}", DELTA_GAP.1),
            NetworkConfig {
                message_gap: DELTA_GAP.1.parse().unwrap(),
                ..delta_network(TopologyKind::Torus, &[16, 32], fidelity)
            },
            staggered.clone(),
        ));
        if fidelity == Fidelity::Hops {
            continue;
        }
        cases.push((
            format!("torus 16x32, 4096 staggered, {name}"),
            delta_network(TopologyKind::Torus, &[16, 32], fidelity),
            staggered.clone(),
        ));
        cases.push((
            format!("mesh 16x32, 4096 staggered, {name}"),
            delta_network(TopologyKind::Mesh, &[16, 32], fidelity),
            staggered.clone(),
        ));
        cases.push((
            format!("torus 4x4, all-to-all 64KiB, {name}"),
            delta_network(TopologyKind::Torus, &[4, 4], fidelity),
            all_to_all(16, Bytes::new(65536)),
        ));
        cases.push((
            format!("mesh 8x8, hot spot 4KiB, {name}"),
            delta_network(TopologyKind::Mesh, &[8, 8], fidelity),
            hot_spot(64, 27, Bytes::new(4096)),
        ));
    }
    cases
}

#[test]
fn runs_give_the_answers_recorded_before_the_speed_up() {
    let mut actual = Vec::new();
    for c in run_cases() {
        let cfg = c
            .spec
            .resolve(None)
            .unwrap_or_else(|e| panic!("{}: {e}", c.name));
        let result = run(&cfg).unwrap_or_else(|e| panic!("{}: {e}", c.name));
        let mut summary = RunSummary::new(&cfg, &result);
        // How many events the engine took is a count of its own work, not a simulated answer:
        // dropping wake-ups that do nothing lowers it and must move nothing else.
        summary.machine_metrics.events = 0;
        summary.run.scene = c.scene.clone();
        let summary = to_json(&summary);
        actual.push((c.name, fnv1a64(summary.as_bytes()), result.image.hash()));
    }
    let expected: Vec<(String, u64, u64)> = RUNS
        .iter()
        .map(|(n, s, i)| (n.to_string(), *s, *i))
        .collect();
    if actual != expected {
        for (name, s, i) in &actual {
            println!("    ({name:?}, {s:#018x}, {i:#018x}),");
        }
        panic!("simulated answers changed (actual hashes printed above)");
    }
}

#[test]
fn netsim_patterns_give_the_answers_recorded_before_the_speed_up() {
    let mut actual = Vec::new();
    for (name, cfg, pattern) in pattern_cases() {
        let report = run_pattern(&cfg, &pattern).unwrap_or_else(|e| panic!("{name}: {e}"));
        actual.push((name, fnv1a64(to_json(&report).as_bytes())));
    }
    let expected: Vec<(String, u64)> = PATTERNS.iter().map(|(n, h)| (n.to_string(), *h)).collect();
    if actual != expected {
        for (name, h) in &actual {
            println!("    ({name:?}, {h:#018x}),");
        }
        panic!("simulated answers changed (actual hashes printed above)");
    }
}
