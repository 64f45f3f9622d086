//! Benchmarks reachable from the command line (`sortsim bench ...`): PHOLD on the engine,
//! measured against a bare binary-heap PHOLD loop and the leanest executor of the engine's
//! design (`floor.rs`) in the same run; trace replay (paper 003)
//! against one pass over the fragments; how the simulator's cost grows (`scale.rs`); and the
//! instruction counts of the same comparisons, which the host's noise does not move
//! (`instructions.rs`).
//!
//! Owns workload definitions and wall-clock measurement. Wall-clock time is read here and in
//! `report::cost` only, never inside a simulation.

pub mod floor;
pub mod instructions;
pub mod scale;

use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::time::Instant;

use rand::Rng;
use rand_chacha::ChaCha12Rng;
use serde::Serialize;

use crate::engine::{rng_stream, Filter, Payload, Sim, SimError};
use crate::output::cost::ratio_or_zero;
use crate::units::SimTime;

/// The PHOLD synthetic workload (Fujimoto): `lps` logical processes start with
/// `events_per_lp` events each; every event schedules one new event, at a random other LP
/// with probability `remote`, after `lookahead` plus an exponential delay of mean `mean`.
#[derive(Clone, Debug, Serialize)]
pub struct PholdConfig {
    pub lps: u32,
    pub events_per_lp: u32,
    pub remote: f64,
    #[serde(skip)]
    pub mean: SimTime,
    #[serde(skip)]
    pub lookahead: SimTime,
    #[serde(skip)]
    pub end: SimTime,
    pub seed: u64,
}

impl PholdConfig {
    /// Events in flight at any instant (PHOLD keeps the population constant).
    pub fn in_flight(&self) -> u64 {
        self.lps as u64 * self.events_per_lp as u64
    }

    /// The `sortsim` command line that runs this workload (`bench phold`, every parameter
    /// given exactly: times in picoseconds, the probability in the shortest form that parses
    /// back to it).
    pub fn command_line(&self) -> Vec<String> {
        let time = |t: SimTime| format!("{}ps", t.ps());
        [
            "bench",
            "phold",
            "--lps",
            &self.lps.to_string(),
            "--events-per-lp",
            &self.events_per_lp.to_string(),
            "--remote",
            &self.remote.to_string(),
            "--mean",
            &time(self.mean),
            "--lookahead",
            &time(self.lookahead),
            "--end",
            &time(self.end),
            "--seed",
            &self.seed.to_string(),
        ]
        .map(String::from)
        .to_vec()
    }
}

/// What one PHOLD run produced.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct PholdOutcome {
    /// Events processed with time <= end.
    pub events: u64,
    /// Time of the last event processed, in picoseconds.
    pub last_event_ps: u64,
    /// Order-sensitive hash of (time, LP) of every processed event.
    pub trace_hash: u64,
}

/// The PHOLD event: carries nothing; the receiving LP is the event's place.
#[derive(Clone, Copy, Debug)]
struct Phold;
impl Payload for Phold {}

struct Draw {
    rng: ChaCha12Rng,
}

impl Draw {
    fn new(cfg: &PholdConfig, lp: u32) -> Draw {
        Draw {
            rng: rng_stream(cfg.seed, &format!("phold/{lp}")),
        }
    }
    /// (destination, delay) of the event an event at `lp` schedules. The exponential draw is
    /// f64, floored to whole picoseconds: deterministic on every IEEE-754 platform.
    fn next(&mut self, cfg: &PholdConfig, lp: u32) -> (u32, SimTime) {
        let dst = if cfg.lps > 1 && self.rng.gen_bool(cfg.remote) {
            let other = self.rng.gen_range(0..cfg.lps - 1);
            if other >= lp {
                other + 1
            } else {
                other
            }
        } else {
            lp
        };
        let u: f64 = 1.0 - self.rng.gen::<f64>(); // (0, 1]
        let exp_ps = (-(cfg.mean.ps() as f64) * u.ln()) as u64;
        (dst, cfg.lookahead + SimTime::from_ps(exp_ps))
    }
}

fn mix(hash: u64, t: SimTime, lp: u32) -> u64 {
    (hash ^ t.ps().rotate_left(17) ^ lp as u64).wrapping_mul(0x0000_0100_0000_01b3)
}

/// PHOLD on the engine: one program per LP, events as posted messages. Never inlined: its
/// instructions are counted by name ([`instructions::Stretch::PholdEngine`]).
#[inline(never)]
pub fn phold_engine(cfg: &PholdConfig) -> Result<PholdOutcome, SimError> {
    use std::cell::Cell;
    use std::rc::Rc;
    let mut sim: Sim<Phold> = Sim::bare(cfg.lps, cfg.seed);
    // Events, last time, hash.
    let log = Rc::new(Cell::new((0u64, 0u64, 0u64)));
    // One configuration read by every LP, as the baseline reads its one.
    let shared = Rc::new(cfg.clone());
    for lp in 0..cfg.lps {
        let node = sim.node(lp);
        let (cfg, log) = (shared.clone(), log.clone());
        sim.spawn(lp, format!("lp{lp}"), async move {
            let mut draw = Draw::new(&cfg, lp);
            for _ in 0..cfg.events_per_lp {
                let (dst, delay) = draw.next(&cfg, lp);
                node.post(dst, delay, Phold);
            }
            loop {
                node.recv(Filter::ANY).await;
                let now = node.now();
                let (n, _, h) = log.get();
                log.set((n + 1, now.ps(), mix(h, now, lp)));
                let (dst, delay) = draw.next(&cfg, lp);
                node.post(dst, delay, Phold);
            }
        });
    }
    sim.run_until(cfg.end)?;
    let (events, last, hash) = log.get();
    Ok(PholdOutcome {
        events,
        last_event_ps: last,
        trace_hash: hash,
    })
}

/// PHOLD as a bare loop over a `BinaryHeap` of (time, sequence, lp): the baseline the
/// engine's overhead is measured against. Draws the same random numbers in the same order,
/// so it must produce the same outcome. Never inlined, as [`phold_engine`].
#[inline(never)]
pub fn phold_baseline(cfg: &PholdConfig) -> PholdOutcome {
    let mut draws: Vec<Draw> = (0..cfg.lps).map(|lp| Draw::new(cfg, lp)).collect();
    let mut heap = BinaryHeap::with_capacity(cfg.in_flight() as usize);
    let mut seq = 0u64;
    for lp in 0..cfg.lps {
        for _ in 0..cfg.events_per_lp {
            let (dst, delay) = draws[lp as usize].next(cfg, lp);
            heap.push(Reverse((delay.ps(), seq, dst)));
            seq += 1;
        }
    }
    let (mut events, mut last, mut hash) = (0u64, 0u64, 0u64);
    while let Some(Reverse((t, _, lp))) = heap.pop() {
        if t > cfg.end.ps() {
            break;
        }
        let now = SimTime::from_ps(t);
        events += 1;
        last = t;
        hash = mix(hash, now, lp);
        let (dst, delay) = draws[lp as usize].next(cfg, lp);
        heap.push(Reverse(((now + delay).ps(), seq, dst)));
        seq += 1;
    }
    PholdOutcome {
        events,
        last_event_ps: last,
        trace_hash: hash,
    }
}

/// The deterministic part of a PHOLD run: the workload and what the engine computed.
/// Byte-identical for identical inputs.
#[derive(Clone, Debug, Serialize)]
pub struct PholdSummary {
    pub lps: u32,
    pub events_per_lp: u32,
    pub in_flight: u64,
    pub remote: f64,
    pub mean_s: f64,
    pub lookahead_s: f64,
    pub end_s: f64,
    pub seed: u64,
    pub events: u64,
    pub simulated_end_s: f64,
    pub trace_hash: String,
    /// Whether the bare loop processed the same events in the same order.
    pub baseline_agrees: bool,
    /// Whether the floor executor (`floor.rs`) did.
    pub floor_agrees: bool,
}

/// What the PHOLD run cost on this host, engine against baseline in the same process.
#[derive(Clone, Debug, Serialize)]
pub struct PholdCost {
    pub engine_wall_s: f64,
    pub engine_events_per_s: f64,
    pub baseline_wall_s: f64,
    pub baseline_events_per_s: f64,
    /// Engine events/s over baseline events/s (1.0 = no overhead).
    pub ratio_to_baseline: f64,
    /// The floor executor's (`floor.rs`): one async program per LP and nothing else.
    pub floor_wall_s: f64,
    pub floor_events_per_s: f64,
    /// Engine events/s over the floor's: what the engine's features cost beyond its design.
    pub ratio_to_floor: f64,
    /// With `--instructions`: the engine's instructions (`measured`) and the bare heap's
    /// (`baseline`), counted by callgrind.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub instructions: Option<instructions::Counts>,
    /// The bare heap's instructions over the engine's: the event-rate ratio's counterpart
    /// without the host's noise (and without what cache misses cost).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub instruction_ratio: Option<f64>,
    /// With `--instructions`: the floor executor's instructions.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub floor_instructions: Option<u64>,
}

impl PholdCost {
    /// The floor executor's event rate over the bare heap's: what the engine's design costs
    /// before its features.
    pub fn floor_over_baseline(&self) -> f64 {
        ratio_or_zero(self.floor_events_per_s, self.baseline_events_per_s)
    }

    /// Adds the instruction counts of `cfg`'s engine, floor and bare heap (valgrind; this
    /// binary run three times more under callgrind).
    pub fn count_instructions(&mut self, cfg: &PholdConfig) -> Result<(), String> {
        let counts = instructions::Counts::phold(cfg)?;
        self.instruction_ratio = Some(counts.baseline_over_measured());
        self.instructions = Some(counts);
        self.floor_instructions = Some(instructions::count(
            &cfg.command_line(),
            instructions::Stretch::PholdFloor,
        )?);
        Ok(())
    }
}

/// Runs PHOLD on the engine, the floor executor and the baseline, and reports all three.
pub fn phold_report(cfg: &PholdConfig) -> Result<(PholdSummary, PholdCost), SimError> {
    let (engine, engine_wall) = timed(|| phold_engine(cfg));
    let engine = engine?;
    let (floor, floor_wall) = timed(|| floor::phold_floor(cfg));
    let (baseline, baseline_wall) = timed(|| phold_baseline(cfg));
    let rate = |events: u64, wall: f64| ratio_or_zero(events as f64, wall);
    let engine_rate = rate(engine.events, engine_wall);
    let floor_rate = rate(floor.events, floor_wall);
    let baseline_rate = rate(baseline.events, baseline_wall);
    let summary = PholdSummary {
        lps: cfg.lps,
        events_per_lp: cfg.events_per_lp,
        in_flight: cfg.in_flight(),
        remote: cfg.remote,
        mean_s: cfg.mean.as_secs_f64(),
        lookahead_s: cfg.lookahead.as_secs_f64(),
        end_s: cfg.end.as_secs_f64(),
        seed: cfg.seed,
        events: engine.events,
        simulated_end_s: SimTime::from_ps(engine.last_event_ps).as_secs_f64(),
        trace_hash: format!("{:016x}", engine.trace_hash),
        baseline_agrees: engine == baseline,
        floor_agrees: engine == floor,
    };
    let cost = PholdCost {
        engine_wall_s: engine_wall,
        engine_events_per_s: engine_rate,
        baseline_wall_s: baseline_wall,
        baseline_events_per_s: baseline_rate,
        ratio_to_baseline: ratio_or_zero(engine_rate, baseline_rate),
        floor_wall_s: floor_wall,
        floor_events_per_s: floor_rate,
        ratio_to_floor: ratio_or_zero(engine_rate, floor_rate),
        instructions: None,
        instruction_ratio: None,
        floor_instructions: None,
    };
    Ok((summary, cost))
}

/// `f`'s result and its wall time in seconds.
fn timed<T>(f: impl FnOnce() -> T) -> (T, f64) {
    let start = Instant::now();
    let out = f();
    (out, start.elapsed().as_secs_f64())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn small(seed: u64) -> PholdConfig {
        PholdConfig {
            lps: 16,
            events_per_lp: 4,
            remote: 0.75,
            mean: SimTime::from_us(1),
            lookahead: SimTime::from_ns(100),
            end: SimTime::from_us(200),
            seed,
        }
    }

    #[test]
    fn engine_processes_exactly_the_baselines_events_in_order() {
        let cfg = small(42);
        let engine = phold_engine(&cfg).unwrap();
        let baseline = phold_baseline(&cfg);
        // Expected ~ lps*events_per_lp*end/(mean+lookahead) = 64*200/1.1 ≈ 11,600 events.
        assert!(engine.events > 5_000, "{engine:?}");
        assert_eq!(engine, baseline);
        assert_eq!(floor::phold_floor(&cfg), baseline);
        assert!(engine.last_event_ps <= cfg.end.ps());
    }

    #[test]
    fn seeds_change_the_trace_and_repeat_it() {
        assert_eq!(
            phold_engine(&small(1)).unwrap(),
            phold_engine(&small(1)).unwrap()
        );
        assert_ne!(
            phold_engine(&small(1)).unwrap().trace_hash,
            phold_engine(&small(2)).unwrap().trace_hash
        );
    }
}

/// The simulator's own overhead on a sort-middle run: simulating `frame` of `scene` on
/// `procs` processors of `machine` against drawing the same frame with the sequential
/// reference renderer, in the same process (ratio = simulation wall / render wall).
#[derive(Clone, Debug, Serialize)]
pub struct OverheadReport {
    pub scene: String,
    pub procs: u32,
    pub fidelity: &'static str,
    pub render_wall_s: f64,
    pub simulate_wall_s: f64,
    pub ratio: f64,
    pub events: u64,
    pub messages: u64,
    /// With `--instructions`: the simulation's instructions (`measured`) and the sequential
    /// render's (`baseline`), counted by callgrind.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub instructions: Option<instructions::Counts>,
    /// Simulate over render by instructions: `ratio` without the host's noise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub instruction_ratio: Option<f64>,
    /// The flow model's work on the frame (zero unless built with the `counters` feature;
    /// `bench scale` prints it).
    #[serde(skip)]
    pub flow_solves: crate::net::transport::SolveCounters,
}

impl OverheadReport {
    /// Adds the instruction counts of the same frame simulated and drawn, from `command_line`
    /// (the `bench overhead` command that measures this report's frame).
    pub fn count_instructions(&mut self, command_line: &[String]) -> Result<(), String> {
        let counts = instructions::Counts::frame(command_line)?;
        self.instruction_ratio = Some(counts.ratio());
        self.instructions = Some(counts);
        Ok(())
    }
}

/// The `sortsim` command line of one `bench overhead` measurement: the frame of `scene` on
/// `procs` processors of `machine`, at `fidelity` (the machine's own when `None`), with the
/// data root `root`.
pub fn overhead_command_line(
    root: &std::path::Path,
    machine: &std::path::Path,
    scene: &std::path::Path,
    procs: u32,
    frame: u32,
    fidelity: Option<&str>,
) -> Vec<String> {
    let mut line: Vec<String> = vec![
        "--root".into(),
        root.display().to_string(),
        "bench".into(),
        "overhead".into(),
        "--machine".into(),
        machine.display().to_string(),
        "--scene".into(),
        scene.display().to_string(),
        "--procs".into(),
        procs.to_string(),
        "--frame".into(),
        frame.to_string(),
    ];
    if let Some(f) = fidelity {
        line.extend(["--fidelity".into(), f.into()]);
    }
    line
}

/// The sequential reference renderer's drawing of `frame`, its geometry generated first.
/// Never inlined: its instructions are counted by name ([`instructions::Stretch::Render`]).
#[inline(never)]
pub fn render_frame(scene: &crate::scene::Scene, frame: u32) -> Result<(), String> {
    let geometry = scene.frame(frame).map_err(|e| e.to_string())?;
    let (image, _) = crate::algo::reference::render(&geometry);
    std::hint::black_box(&image);
    Ok(())
}

/// One simulated run. Never inlined, as [`render_frame`].
#[inline(never)]
pub fn simulate_frame(
    cfg: &crate::algo::RunConfig,
) -> Result<crate::algo::RunResult, crate::algo::RunError> {
    crate::algo::run(cfg)
}

/// Measures one frame; both timings include generating the frame's geometry from the scene.
pub fn overhead(
    machine: &std::path::Path,
    scene: std::sync::Arc<crate::scene::Scene>,
    procs: u32,
    frame: u32,
    set: std::collections::BTreeMap<String, String>,
) -> Result<OverheadReport, String> {
    use crate::spec::run::RunSpec;
    let (rendered, render_wall) = timed(|| render_frame(&scene, frame));
    rendered?;
    let spec = RunSpec {
        schema: None,
        machine: machine.to_path_buf(),
        scene: scene.file().to_path_buf(),
        algo: "sort-middle/ellsworth".into(),
        procs,
        frames: Some(frame.to_string()),
        seed: 1,
        set,
    };
    let cfg = spec
        .resolve(Some(scene.clone()))
        .map_err(|e| e.to_string())?;
    let (result, simulate_wall) = timed(|| simulate_frame(&cfg));
    let result = result.map_err(|e| e.to_string())?;
    Ok(OverheadReport {
        scene: scene.file().display().to_string(),
        procs,
        fidelity: cfg.machine.network.fidelity.name(),
        render_wall_s: render_wall,
        simulate_wall_s: simulate_wall,
        ratio: simulate_wall / render_wall.max(1e-9),
        events: result.stats.events,
        messages: result.frames.iter().map(|f| f.messages).sum(),
        instructions: None,
        instruction_ratio: None,
        flow_solves: result.stats.flow_solves,
    })
}

/// Trace replay's speed (paper 003's trace-driven simulation; issue 5 asks for "a 6.5 M-pixel
/// trace for n = 1..64 in a few seconds"): records one frame of `scene` (the Cube stand-in
/// has 6.46 M fragments), then replays direct send, PixelFlow and snooping for every n of
/// `procs`, against a baseline measured in the same run: one pass over the fragments (a
/// sequential z-buffer on the trace's pixel indices).
#[derive(Clone, Debug, Serialize)]
pub struct ReplayBench {
    pub scene: String,
    pub fragments: u64,
    pub area_pixels: u64,
    pub procs: Vec<u32>,
    pub assign: &'static str,
    /// Rasterizing the frame into a trace (not part of replay).
    pub record_wall_s: f64,
    /// One pass over the fragments.
    pub baseline_wall_s: f64,
    /// Grouping the fragments by pixel, once per trace (`Replay::new`).
    pub prepare_wall_s: f64,
    /// Replaying the three algorithms for every n.
    pub replay_wall_s: f64,
    pub prepare_over_baseline: f64,
    pub replay_over_baseline: f64,
    /// Replay time per n, over the baseline.
    pub replay_per_n_over_baseline: f64,
    /// Sum of every row's traffic: the same for every run of the same inputs.
    pub traffic_checksum: u64,
}

pub fn replay_bench(
    scene: &std::path::Path,
    frame: u32,
    procs: Vec<u32>,
    assign: crate::algo::primitives::Deal,
    seed: u64,
) -> Result<ReplayBench, String> {
    use crate::trace::replay::{Algo, Replay, ReplayConfig};
    let scene_data = crate::scene::Scene::load(scene).map_err(|e| e.to_string())?;
    let (trace, record_wall) = timed(|| crate::trace::record_scene(&scene_data, frame));
    let trace = trace.map_err(|e| e.to_string())?;

    // Freed after the clock stops: the baseline times the pass over the fragments alone.
    let (zbuffer, baseline_wall) = timed(|| {
        let mut zbuffer = vec![u32::MAX; trace.area()];
        for (&p, &z) in trace.pixels().iter().zip(trace.depths()) {
            let slot = &mut zbuffer[p as usize];
            *slot = (*slot).min(z);
        }
        std::hint::black_box(zbuffer)
    });
    drop(zbuffer);
    let baseline_wall = baseline_wall.max(1e-9);

    let (replay, prepare_wall) = timed(|| Replay::new(&trace));
    let config = ReplayConfig {
        algos: Algo::ALL.to_vec(),
        procs: procs.clone(),
        assign,
        seed,
        local_zbuffer: false,
    };
    let (report, replay_wall) = timed(|| replay.run(&config));
    let traffic_checksum = report.rows.iter().map(|r| r.pixels).sum();
    Ok(ReplayBench {
        scene: scene.display().to_string(),
        fragments: trace.len() as u64,
        area_pixels: trace.area() as u64,
        assign: assign.name(),
        record_wall_s: record_wall,
        baseline_wall_s: baseline_wall,
        prepare_wall_s: prepare_wall,
        replay_wall_s: replay_wall,
        prepare_over_baseline: prepare_wall / baseline_wall,
        replay_over_baseline: replay_wall / baseline_wall,
        replay_per_n_over_baseline: replay_wall / baseline_wall / procs.len().max(1) as f64,
        procs,
        traffic_checksum,
    })
}
