//! Engine benchmarks: PHOLD on the engine against a bare binary-heap PHOLD loop, at 1,024 and
//! 16,384 events in flight. The ratio engine/baseline is what counts (aim: 0.8 or better).

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use sortsim::bench::{phold_baseline, phold_engine, PholdConfig};
use sortsim::units::SimTime;

fn config(lps: u32, events_per_lp: u32) -> PholdConfig {
    PholdConfig {
        lps,
        events_per_lp,
        remote: 0.9,
        mean: SimTime::from_us(1),
        lookahead: SimTime::from_ns(100),
        end: SimTime::from_us(50),
        seed: 1,
    }
}

fn phold(c: &mut Criterion) {
    let mut group = c.benchmark_group("phold");
    group.sample_size(10);
    for (lps, per_lp) in [(1024, 1), (1024, 16)] {
        let cfg = config(lps, per_lp);
        let events = phold_baseline(&cfg).events;
        group.throughput(Throughput::Elements(events));
        let in_flight = cfg.in_flight();
        group.bench_with_input(BenchmarkId::new("engine", in_flight), &cfg, |b, cfg| {
            b.iter(|| phold_engine(cfg).expect("PHOLD runs"))
        });
        group.bench_with_input(BenchmarkId::new("baseline", in_flight), &cfg, |b, cfg| {
            b.iter(|| phold_baseline(cfg))
        });
    }
    group.finish();
}

criterion_group!(benches, phold);
criterion_main!(benches);
