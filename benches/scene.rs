//! Scene benchmarks: building the largest stand-in (paper 002's 806,640-triangle polio shell)
//! and producing one of its frames (transform, project, light), plus the geometric
//! statistics pass. The design budget is well under 1 s for build plus one frame.
//!
//! Must stay under about half a minute in total.

use std::path::Path;

use criterion::{criterion_group, criterion_main, Criterion};
use sortsim::scene::stats::geometric;
use sortsim::scene::Scene;

fn polio() -> &'static Path {
    Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenes/polio-standin.json"
    ))
}

fn build_polio(c: &mut Criterion) {
    let mut g = c.benchmark_group("scene");
    g.sample_size(10);
    g.bench_function("polio load (generate 800,000 + refine to 806,640)", |b| {
        b.iter(|| Scene::load(polio()).unwrap())
    });
    let scene = Scene::load(polio()).unwrap();
    g.bench_function("polio frame (transform, project, light)", |b| {
        b.iter(|| scene.frame(37).unwrap())
    });
    let frame = scene.frame(37).unwrap();
    g.bench_function("polio geometric stats", |b| b.iter(|| geometric(&frame)));
    g.finish();
}

criterion_group!(benches, build_polio);
criterion_main!(benches);
