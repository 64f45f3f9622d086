//! Network benchmarks: flow-model throughput on a 512-node 16x32 torus (every node sends
//! 64 KiB to 8 random nodes at once: 4096 messages), and the fidelity table (the same
//! pattern at every level: predicted makespan next to the simulator's wall time).
//!
//! Prints its figures to stdout; must stay under about a minute in total, and must never
//! feed wall time into a simulated result.

use std::time::Instant;

use criterion::{criterion_group, criterion_main, Criterion};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use sortsim::net::fidelity::{fidelity_table, format_table};
use sortsim::net::pattern::{random_pairs, run_pattern, Pattern};
use sortsim::net::{Fidelity, NetworkConfig, Switching, TopologyKind};
use sortsim::units::{Bytes, SimTime};

fn torus_512(fidelity: Fidelity) -> NetworkConfig {
    NetworkConfig {
        topology: TopologyKind::Torus,
        dims: vec![16, 32],
        link_bandwidth: "17MB/s".parse().unwrap(),
        hop_latency: SimTime::from_us(1),
        switching: Switching::Wormhole,
        packet_size: Bytes::new(1024),
        fidelity,
        message_gap: SimTime::ZERO,
        node: None,
    }
}

fn pattern() -> Pattern {
    random_pairs(512, 8, Bytes::new(64 * 1024), 2024)
}

fn flow_throughput(c: &mut Criterion) {
    let cfg = torus_512(Fidelity::Flow);
    let p = pattern();
    let clock = Instant::now();
    let report = run_pattern(&cfg, &p).unwrap();
    let wall = clock.elapsed().as_secs_f64();
    println!(
        "flow 16x32 torus, {} messages of 64 KiB: {:.3} s wall, {:.0} messages simulated/s, makespan {:.3} ms",
        p.messages.len(),
        wall,
        p.messages.len() as f64 / wall,
        report.makespan_s * 1e3
    );
    // The same messages with starts spread over 100 ms: every start is a recomputation
    // from level 0 (the shortcut only applies to departures), the harder case.
    let staggered = staggered(&p);
    let clock = Instant::now();
    let report = run_pattern(&cfg, &staggered).unwrap();
    let wall = clock.elapsed().as_secs_f64();
    println!(
        "flow 16x32 torus, same messages, starts spread over 100 ms: {:.3} s wall, {:.0} messages simulated/s, makespan {:.3} ms",
        wall,
        p.messages.len() as f64 / wall,
        report.makespan_s * 1e3
    );
    let mut group = c.benchmark_group("net");
    group.sample_size(10);
    group.bench_function("flow_torus16x32_4096x64KiB", |b| {
        b.iter(|| run_pattern(&cfg, &p).unwrap().makespan_ps)
    });
    group.finish();
}

fn staggered(p: &Pattern) -> Pattern {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut out = p.clone();
    for m in &mut out.messages {
        m.start = format!("{}ps", rng.gen_range(0..100_000_000_000u64));
    }
    out
}

fn fidelity(_c: &mut Criterion) {
    let rows = fidelity_table(&torus_512(Fidelity::Flow), &pattern()).unwrap();
    println!("fidelity table, 16x32 torus, 4096 x 64 KiB random pairs, wormhole:");
    print!("{}", format_table(&rows));
}

criterion_group!(benches, flow_throughput, fidelity);
criterion_main!(benches);
