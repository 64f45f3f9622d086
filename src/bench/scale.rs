//! `sortsim bench scale`: how the simulator's own cost grows with the size of what it
//! simulates, measured in one process, each figure printed beside its target.
//!
//! Figures: a whole viewing sequence of the polio stand-in on 512 Delta nodes at `flow`, and
//! at `hops` as its floor (the same engine and rendering work without a contention model);
//! one polio frame simulated against drawing it sequentially; staggered traffic on a 16x32
//! torus at `hops` and `flow`; PHOLD against its bare-heap loop (populations of 16 events a
//! process, and one of a single event a process, where every event's process is a cache
//! miss); and three growth curves (wall
//! time against messages, processors and triangles).
//!
//! Owns the workload definitions and the wall-clock measurements of this benchmark. Must
//! never assert a time (targets are printed, not tested) and never let a wall time reach a
//! simulated result.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use serde::Serialize;

use super::instructions::{self, Counts, Stretch};
use super::{overhead, overhead_command_line, phold_report, PholdConfig};
use crate::net::pattern::{random_staggered, run_pattern_counted, Pattern};
use crate::net::transport::SolveCounters;
use crate::net::{Fidelity, NetworkConfig, TopologyKind};
use crate::output::cost::peak_host_memory;
use crate::scene::Scene;
use crate::spec::run::RunSpec;
use crate::units::{Bytes, SimTime};

/// What to measure; the defaults are the targets' own sizes.
#[derive(Clone, Debug)]
pub struct ScaleConfig {
    /// The repository root (machines/, scenes/).
    pub root: PathBuf,
    /// Frames of the polio sequence for the headline run (the seeds' 80 to 110).
    pub frames: u32,
    /// Message counts of the torus figures and the messages curve.
    pub messages: Vec<usize>,
    /// Processor counts of the processors curve.
    pub procs: Vec<u32>,
    /// PHOLD populations.
    pub phold: Vec<Population>,
    /// Runs of each short figure (the one-frame ratios, the torus patterns up to 16,384
    /// messages, PHOLD), reported as their median: the host's noise moves a single run by
    /// 15 to 40%.
    pub repeats: usize,
    /// Also count instructions (callgrind) of PHOLD up to 16,384 in flight and of one polio
    /// frame at `hops` against drawing it: those comparisons without the noise.
    pub instructions: bool,
}

/// A PHOLD population: how many logical processes, each starting with how many events.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Population {
    pub lps: u32,
    pub events_per_lp: u32,
}

impl Population {
    /// `in_flight` events, 16 a process.
    const fn in_flight(in_flight: u32) -> Population {
        Population {
            lps: in_flight / 16,
            events_per_lp: 16,
        }
    }

    /// One event a process: each event reaches a process of its own as a rule, so every
    /// event's process state is a cache miss.
    const fn lone(lps: u32) -> Population {
        Population {
            lps,
            events_per_lp: 1,
        }
    }

    fn events(self) -> u64 {
        u64::from(self.lps) * u64::from(self.events_per_lp)
    }

    /// How its figures name it.
    fn label(self) -> String {
        match self.events_per_lp {
            16 => format!("{} in flight", self.events()),
            1 => format!("{} processes of one event", self.lps),
            e => format!("{} processes of {e} events", self.lps),
        }
    }
}

impl ScaleConfig {
    pub fn full(root: &Path) -> ScaleConfig {
        ScaleConfig {
            root: root.to_path_buf(),
            frames: 110,
            messages: vec![1024, 4096, 16384, 65536],
            procs: vec![16, 32, 64, 128, 256, 512],
            phold: vec![
                Population::in_flight(1024),
                Population::in_flight(16384),
                Population::in_flight(1 << 20),
                Population::lone(16384),
            ],
            repeats: 3,
            instructions: false,
        }
    }

    /// A few minutes in all: 3 frames, up to 16,384 messages, PHOLD up to 16,384 in flight.
    pub fn quick(root: &Path) -> ScaleConfig {
        ScaleConfig {
            frames: 3,
            messages: vec![1024, 4096, 16384],
            phold: vec![
                Population::in_flight(1024),
                Population::in_flight(16384),
                Population::lone(16384),
            ],
            ..ScaleConfig::full(root)
        }
    }
}

/// One measured figure with its target.
#[derive(Clone, Debug, Serialize)]
pub struct Figure {
    pub name: String,
    pub measured: f64,
    pub unit: &'static str,
    /// The target, as "<= 60" or ">= 0.8" in `unit`.
    pub target: String,
    /// `None` when the run was smaller than the one the target is for.
    pub met: Option<bool>,
    pub detail: String,
}

/// A point of a growth curve: wall seconds at one size, per fidelity.
#[derive(Clone, Debug, Serialize)]
pub struct CurvePoint {
    pub x: f64,
    pub label: String,
    pub fidelity: &'static str,
    pub wall_s: f64,
    pub events: u64,
}

#[derive(Clone, Debug, Serialize)]
pub struct ScaleReport {
    pub figures: Vec<Figure>,
    pub wall_against_messages: Vec<CurvePoint>,
    pub wall_against_procs: Vec<CurvePoint>,
    pub wall_against_triangles: Vec<CurvePoint>,
    /// The flow model's work on one polio frame and on each torus pattern (empty unless built
    /// with the `counters` feature).
    pub flow_solves: Vec<(String, SolveCounters)>,
}

/// The fidelities each growth curve compares.
pub const CURVE_FIDELITIES: [Fidelity; 2] = [Fidelity::Hops, Fidelity::Flow];
/// The scenes of the triangles curve, smallest first.
const TRIANGLE_SCENES: [&str; 4] = [
    "plb-head-standin.json",
    "terrain-standin.json",
    "ct-head-standin.json",
    "polio-standin.json",
];
/// One message starts every 2 us on average across the machine (each node about every 1 ms):
/// 278 kbit on average over 12 links on average, about six times what the torus's 2,048 links
/// carry, so flows pile up and every start and end changes many rates (the hard case for
/// `flow`).
const STAGGER_PER_MESSAGE: SimTime = SimTime::from_us(2);

/// Runs every figure and curve of `cfg`, reporting progress on `progress`.
pub fn scale(cfg: &ScaleConfig, progress: &mut dyn FnMut(&str)) -> Result<ScaleReport, String> {
    let machine = cfg.root.join("machines/delta.json");
    let polio = Arc::new(load(&cfg.root, "polio-standin.json")?);
    let repeats = cfg.repeats.max(1);
    let mut figures = Vec::new();

    progress(&format!(
        "polio stand-in, {} frames, 512 nodes, flow",
        cfg.frames
    ));
    let (wall, events) = run_wall(&machine, &polio, 512, cfg.frames, Fidelity::Flow)?;
    let memory = peak_host_memory().unwrap_or(0) as f64 / 1e9;
    let mut headline = figure(
        &format!("polio, {} frames, 512 Delta nodes, flow: wall", cfg.frames),
        wall,
        "s",
        Target::AtMost(60.0),
        format!("{events} events"),
    );
    if cfg.frames < 110 {
        // Frame 0 (no earlier counts: every triangle redistributed) costs most, so a share
        // of the 60 s would not be a fair target for a shorter run.
        headline.met = None;
        headline.detail += "; the target is for 110 frames";
    }
    figures.push(headline);
    figures.push(figure(
        "same run: peak host memory",
        memory,
        "GB",
        Target::AtMost(0.5),
        "VmHWM of this process, which ran nothing bigger before".into(),
    ));

    progress(&format!(
        "polio stand-in, {} frames, 512 nodes, hops",
        cfg.frames
    ));
    let (floor_wall, floor_events) = run_wall(&machine, &polio, 512, cfg.frames, Fidelity::Hops)?;
    let mut floor = figure(
        &format!(
            "same {} frames at hops, the floor under flow: wall",
            cfg.frames
        ),
        floor_wall,
        "s",
        Target::AtMost(60.0),
        format!(
            "{floor_events} events; the engine and the rendering with no contention model, which \
             flow runs too, with its solves besides: {}",
            floor_leaves(floor_wall, 60.0)
        ),
    );
    if cfg.frames < 110 {
        floor.met = None;
    }
    figures.push(floor);

    // The `hops` frame's ratio: a floor under the `flow` frame's, which does the same work
    // and its solves besides.
    let mut hops_ratio = None;
    let mut flow_solves = Vec::new();
    for (fidelity, limit) in [(Fidelity::Hops, 2.0), (Fidelity::Flow, 3.0)] {
        progress(&format!("one polio frame, 512 nodes, {}", fidelity.name()));
        let set = [(
            "machine.network.fidelity".to_string(),
            fidelity.name().to_string(),
        )];
        let set: std::collections::BTreeMap<_, _> = set.into_iter().collect();
        let runs = (0..repeats)
            .map(|_| overhead(&machine, polio.clone(), 512, 1, set.clone()))
            .collect::<Result<Vec<_>, _>>()?;
        let ratio = median(runs.iter().map(|r| r.ratio).collect());
        let r = runs
            .iter()
            .find(|r| r.ratio == ratio)
            .expect("the median is one of the runs");
        figures.push(figure(
            &format!(
                "one polio frame on 512 nodes at {}: simulate / render",
                fidelity.name()
            ),
            ratio,
            "x",
            Target::AtMost(limit),
            format!(
                "simulate {:.3} s, render sequentially {:.3} s{}{}",
                r.simulate_wall_s,
                r.render_wall_s,
                runs_note(&runs.iter().map(|r| r.ratio).collect::<Vec<_>>()),
                match hops_ratio {
                    Some(h) => format!("; at hops, its floor: {h:.3}x"),
                    None => String::new(),
                }
            ),
        ));
        hops_ratio = Some(ratio);
        if r.flow_solves.solves > 0 {
            flow_solves.push(("polio frame, 512".into(), r.flow_solves));
        }
        if cfg.instructions && fidelity == Fidelity::Hops {
            progress("one polio frame, 512 nodes, hops, under callgrind");
            let line = overhead_command_line(
                &cfg.root,
                &machine,
                polio.file(),
                512,
                1,
                Some(fidelity.name()),
            );
            let counts = Counts::frame(&line)?;
            figures.push(figure(
                "same, by instructions (callgrind): simulate / render",
                counts.ratio(),
                "x",
                Target::AtMost(limit),
                format!(
                    "simulate {:.3} G, render sequentially {:.3} G instructions",
                    counts.measured as f64 / 1e9,
                    counts.baseline as f64 / 1e9
                ),
            ));
        }
    }

    let mut messages_curve = Vec::new();
    // The runs of the longest pattern at `flow`, for its figure's detail.
    let mut longest_runs = String::new();
    for &count in &cfg.messages {
        for fidelity in CURVE_FIDELITIES {
            progress(&format!(
                "{count} staggered messages, 16x32 torus, {}",
                fidelity.name()
            ));
            // Even the longest pattern, about 4 s at `flow` in a quiet hour, is short enough to
            // repeat, and its figure is the one nearest its target.
            let mut walls = Vec::new();
            let mut counters = SolveCounters::default();
            for _ in 0..repeats {
                let (wall, counted) = torus_wall(&machine, count, fidelity)?;
                walls.push(wall);
                counters = counted;
            }
            if count == 65536 && fidelity == Fidelity::Flow {
                longest_runs = runs_note(&walls).trim_start_matches("; ").to_string();
            }
            let wall = median(walls);
            if counters.solves > 0 {
                flow_solves.push((format!("torus, {count} msgs"), counters));
            }
            messages_curve.push(CurvePoint {
                x: count as f64,
                label: format!("{count} messages"),
                fidelity: fidelity.name(),
                wall_s: wall,
                events: count as u64,
            });
        }
    }
    let wall_at = |count: usize, f: Fidelity| {
        messages_curve
            .iter()
            .find(|p| p.x == count as f64 && p.fidelity == f.name())
            .map(|p| p.wall_s)
    };
    if let (Some(hops), Some(flow)) = (
        wall_at(16384, Fidelity::Hops),
        wall_at(16384, Fidelity::Flow),
    ) {
        figures.push(figure(
            "16,384 staggered messages, 16x32 torus: flow / hops",
            flow / hops.max(1e-9),
            "x",
            Target::AtMost(20.0),
            format!("flow {flow:.3} s, hops {hops:.3} s"),
        ));
    }
    if let Some(flow) = wall_at(65536, Fidelity::Flow) {
        figures.push(figure(
            "65,536 staggered messages, 16x32 torus, flow: wall",
            flow,
            "s",
            Target::AtMost(5.0),
            longest_runs,
        ));
    }

    for &population in &cfg.phold {
        let (in_flight, label) = (population.events(), population.label());
        progress(&format!("PHOLD, {label}"));
        let phold = PholdConfig {
            lps: population.lps,
            events_per_lp: population.events_per_lp,
            remote: 0.9,
            mean: SimTime::from_us(1),
            lookahead: SimTime::from_ns(100),
            end: SimTime::from_us(1000 * 16384 / in_flight.max(16384)),
            seed: 1,
        };
        let mut ratios = Vec::new();
        let mut floor_ratios = Vec::new();
        let mut events = 0;
        for _ in 0..repeats {
            let (summary, cost) = phold_report(&phold).map_err(|e| e.to_string())?;
            if !summary.baseline_agrees || !summary.floor_agrees {
                return Err(
                    "PHOLD: the engine, the floor and the bare heap processed different events"
                        .into(),
                );
            }
            ratios.push(cost.ratio_to_baseline);
            floor_ratios.push(cost.floor_over_baseline());
            events = summary.events;
        }
        figures.push(figure(
            &format!("PHOLD, {label}: engine / bare heap event rate"),
            median(ratios.clone()),
            "x",
            Target::AtLeast(if in_flight >= 1 << 20 { 1.0 } else { 0.8 }),
            format!(
                "{events} events{}; the floor of the engine's design / bare heap: {:.3}x",
                runs_note(&ratios),
                median(floor_ratios)
            ),
        ));
        // A million in flight is about cache misses, which instructions leave out.
        if cfg.instructions && in_flight <= 16384 {
            progress(&format!("PHOLD, {label}, under callgrind"));
            // About a million events, whatever the population: a count does not need the
            // long run that evens out the noise, and a run under callgrind is slow.
            let counted = PholdConfig {
                end: SimTime::from_ns(1100 * (1 << 20) / in_flight),
                ..phold.clone()
            };
            let counts = Counts::phold(&counted)?;
            let floor = instructions::count(&counted.command_line(), Stretch::PholdFloor)?;
            figures.push(figure(
                &format!("PHOLD, {label}, by instructions (callgrind): bare heap / engine"),
                counts.baseline_over_measured(),
                "x",
                Target::AtLeast(0.8),
                format!(
                    "engine {:.1} M, floor of its design {:.1} M ({:.3}x), bare heap {:.1} M \
                     instructions, simulated to {}",
                    counts.measured as f64 / 1e6,
                    floor as f64 / 1e6,
                    counts.baseline as f64 / floor.max(1) as f64,
                    counts.baseline as f64 / 1e6,
                    counted.end
                ),
            ));
        }
    }

    let mut procs_curve = Vec::new();
    for &procs in &cfg.procs {
        for fidelity in CURVE_FIDELITIES {
            progress(&format!(
                "one polio frame, {procs} nodes, {}",
                fidelity.name()
            ));
            let label = format!("{procs} processors");
            procs_curve.push(frame_point(
                &machine,
                &polio,
                procs,
                fidelity,
                procs as f64,
                label,
            )?);
        }
    }

    let mut triangles_curve = Vec::new();
    for name in TRIANGLE_SCENES {
        let scene = Arc::new(load(&cfg.root, name)?);
        for fidelity in CURVE_FIDELITIES {
            progress(&format!(
                "one frame of {name}, 512 nodes, {}",
                fidelity.name()
            ));
            let (x, label) = (
                scene.triangle_count() as f64,
                name.trim_end_matches(".json"),
            );
            triangles_curve.push(frame_point(
                &machine,
                &scene,
                512,
                fidelity,
                x,
                label.into(),
            )?);
        }
    }

    Ok(ScaleReport {
        figures,
        wall_against_messages: messages_curve,
        flow_solves,
        wall_against_procs: procs_curve,
        wall_against_triangles: triangles_curve,
    })
}

enum Target {
    AtMost(f64),
    AtLeast(f64),
}

fn figure(name: &str, measured: f64, unit: &'static str, target: Target, detail: String) -> Figure {
    let (target, met) = match target {
        Target::AtMost(t) => (format!("<= {}", trim(t)), Some(measured <= t)),
        Target::AtLeast(t) => (format!(">= {}", trim(t)), Some(measured >= t)),
    };
    Figure {
        name: name.to_string(),
        measured,
        unit,
        target,
        met,
        detail,
    }
}

fn trim(v: f64) -> String {
    let s = format!("{v:.2}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

fn load(root: &Path, name: &str) -> Result<Scene, String> {
    Scene::load(&root.join("scenes").join(name)).map_err(|e| e.to_string())
}

/// Wall seconds and events of an Ellsworth run of `frames` frames (from frame 0).
fn run_wall(
    machine: &Path,
    scene: &Arc<Scene>,
    procs: u32,
    frames: u32,
    fidelity: Fidelity,
) -> Result<(f64, u64), String> {
    let spec = RunSpec {
        schema: None,
        machine: machine.to_path_buf(),
        scene: scene.file().to_path_buf(),
        algo: "sort-middle/ellsworth".into(),
        procs,
        frames: Some(format!("0..{}", frames.min(scene.frame_count()))),
        seed: 1,
        set: [(
            "machine.network.fidelity".to_string(),
            fidelity.name().to_string(),
        )]
        .into_iter()
        .collect(),
    };
    let cfg = spec
        .resolve(Some(scene.clone()))
        .map_err(|e| e.to_string())?;
    let start = Instant::now();
    let result = crate::algo::run(&cfg).map_err(|e| e.to_string())?;
    Ok((start.elapsed().as_secs_f64(), result.stats.events))
}

/// One point of a growth curve: one frame (frame 0) of `scene` on `procs` nodes.
fn frame_point(
    machine: &Path,
    scene: &Arc<Scene>,
    procs: u32,
    fidelity: Fidelity,
    x: f64,
    label: String,
) -> Result<CurvePoint, String> {
    let (wall_s, events) = run_wall(machine, scene, procs, 1, fidelity)?;
    Ok(CurvePoint {
        x,
        label,
        fidelity: fidelity.name(),
        wall_s,
        events,
    })
}

/// The median of `values` (the lower middle one of an even count); NaN when empty.
fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    match values.len() {
        0 => f64::NAN,
        n => values[(n - 1) / 2],
    }
}

/// "; median of 3: a, b, c" for a figure's detail, or nothing for a single run.
fn runs_note(values: &[f64]) -> String {
    if values.len() < 2 {
        return String::new();
    }
    let list: Vec<String> = values.iter().map(|v| format!("{v:.3}")).collect();
    format!("; median of {}: {}", values.len(), list.join(", "))
}

/// Wall seconds of `count` staggered messages (4 KiB or 64 KiB, random pairs) on the Delta's
/// links wired as a 16x32 torus.
fn torus_wall(
    machine: &Path,
    count: usize,
    fidelity: Fidelity,
) -> Result<(f64, SolveCounters), String> {
    let (network, pattern) = staggered_torus(machine, count, fidelity)?;
    let start = Instant::now();
    let (_, counters) = run_pattern_counted(&network, &pattern).map_err(|e| e.to_string())?;
    Ok((start.elapsed().as_secs_f64(), counters))
}

/// The network and pattern of the staggered torus figures: `count` messages (4 KiB or
/// 64 KiB, random pairs, one start every 2 us on average, seed 1) on the links of `machine`
/// (the Delta's) wired as a 16x32 torus at `fidelity`, without its interfaces' gap, so that
/// the transports alone are measured.
pub fn staggered_torus(
    machine: &Path,
    count: usize,
    fidelity: Fidelity,
) -> Result<(NetworkConfig, Pattern), String> {
    let delta = crate::spec::machine::load_machine(machine).map_err(|e| e.to_string())?;
    let network = NetworkConfig {
        topology: TopologyKind::Torus,
        dims: vec![16, 32],
        fidelity,
        message_gap: SimTime::ZERO,
        ..delta.network
    };
    let sizes = [Bytes::new(4096), Bytes::new(65536)];
    let spread = STAGGER_PER_MESSAGE.times(count as u64);
    Ok((network, random_staggered(512, count, &sizes, spread, 1)))
}

/// The report as a table: one line per figure, then the curves.
pub fn table(report: &ScaleReport) -> String {
    let mut s = format!(
        "{:<72} {:>12} {:>10}  {}\n",
        "figure", "measured", "target", "met"
    );
    for f in &report.figures {
        s += &format!(
            "{:<72} {:>10.3} {:<2}{:>9}  {}\n",
            f.name,
            f.measured,
            f.unit,
            f.target,
            match f.met {
                Some(true) => "yes",
                Some(false) => "NO",
                None => "-",
            }
        );
        if !f.detail.is_empty() {
            s += &format!("    {}\n", f.detail);
        }
    }
    for (title, curve) in [
        (
            "wall against messages (16x32 torus)",
            &report.wall_against_messages,
        ),
        (
            "wall against processors (one polio frame)",
            &report.wall_against_procs,
        ),
        (
            "wall against triangles (one frame, 512 nodes)",
            &report.wall_against_triangles,
        ),
    ] {
        s += &format!(
            "\n{title}\n{:<28} {:>10} {:>12} {:>10}\n",
            "", "fidelity", "events", "wall_s"
        );
        for p in curve {
            s += &format!(
                "{:<28} {:>10} {:>12} {:>10.3}\n",
                p.label, p.fidelity, p.events, p.wall_s
            );
        }
    }
    if !report.flow_solves.is_empty() {
        s += &format!(
            "\nflow solves (per solve, then how many solves swept, swept again, or added or \
             removed a flow with no sweep, then per sweep run the links made dirty and those left \
             out and checked after it)\n{:<20} {:>7} {:>7} {:>7} {:>8} {:>10} {:>11} {:>7} {:>11} {:>7} {:>7} {:>7} {:>7} {:>7} {:>8}\n",
            "", "solves", "flows", "groups", "switched", "flows/link", "groups/link", "swept",
            "swept-links", "sweeps", "again", "added", "removed", "dirty", "left-out"
        );
        for (label, c) in &report.flow_solves {
            let per = |n: u64, d: u64| n as f64 / d.max(1) as f64;
            s += &format!(
                "{:<20} {:>7} {:>7.1} {:>7.1} {:>8.2} {:>10.1} {:>11.1} {:>7.1} {:>11.1} {:>7} {:>7} {:>7} {:>7} {:>7.1} {:>8.1}\n",
                label,
                c.solves,
                per(c.flows_changed, c.solves),
                per(c.groups_changed, c.solves),
                per(c.flows_switched, c.solves),
                per(c.flows_on_links, c.link_evaluations),
                per(c.groups_crossing, c.link_evaluations),
                per(c.flows_swept, c.solves),
                per(c.swept_route_links, c.solves),
                c.sweeps,
                c.reruns,
                c.added_alone,
                c.removed_alone,
                per(c.dirty_links, c.sweeps + c.reruns),
                per(c.left_out_links, c.sweeps + c.reruns),
            );
        }
    }
    s
}

/// What the `hops` floor of the 110 frames leaves `flow`'s own work under the target of
/// `target` seconds.
fn floor_leaves(floor_wall: f64, target: f64) -> String {
    if floor_wall >= target {
        "at or above the target, no solver meets it".to_string()
    } else {
        format!(
            "{:.1} s of the target left for flow's solves",
            target - floor_wall
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The populations of 16 events a process keep the names their figures have always had
    /// (readers of scale.json find them by name); the others say how many processes.
    #[test]
    fn phold_figures_name_their_population() {
        assert_eq!(Population::in_flight(1 << 20).label(), "1048576 in flight");
        assert_eq!(Population::in_flight(1024).events(), 1024);
        assert_eq!(
            Population::lone(16384).label(),
            "16384 processes of one event"
        );
        let four = Population {
            lps: 8,
            events_per_lp: 4,
        };
        assert_eq!(
            (four.label().as_str(), four.events()),
            ("8 processes of 4 events", 32)
        );
    }

    #[test]
    fn the_floor_says_what_it_leaves_flow_only_below_the_target() {
        assert_eq!(
            floor_leaves(55.4, 60.0),
            "4.6 s of the target left for flow's solves"
        );
        assert_eq!(
            floor_leaves(60.0, 60.0),
            "at or above the target, no solver meets it"
        );
    }

    #[test]
    fn a_figure_is_met_only_on_its_side_of_the_target() {
        let at_most = |v| figure("f", v, "s", Target::AtMost(60.0), String::new());
        assert_eq!(at_most(60.0).met, Some(true));
        assert_eq!(at_most(60.001).met, Some(false));
        assert_eq!(at_most(1.0).target, "<= 60");
        let at_least = |v| figure("f", v, "x", Target::AtLeast(0.8), String::new());
        assert_eq!(at_least(0.8).met, Some(true));
        assert_eq!(at_least(0.79).met, Some(false));
        assert_eq!(at_least(1.0).target, ">= 0.8");
    }

    #[test]
    fn a_median_is_the_middle_run_and_the_note_lists_every_run() {
        assert_eq!(median(vec![3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(vec![4.0, 1.0, 3.0, 2.0]), 2.0);
        assert_eq!(median(vec![5.0]), 5.0);
        assert!(median(Vec::new()).is_nan());
        assert_eq!(
            runs_note(&[0.7, 0.81, 0.75]),
            "; median of 3: 0.700, 0.810, 0.750"
        );
        assert_eq!(runs_note(&[0.7]), "");
    }

    #[test]
    fn the_table_lists_every_figure_and_curve_point_with_its_verdict() {
        let report = ScaleReport {
            figures: vec![
                figure(
                    "fast enough",
                    1.0,
                    "s",
                    Target::AtMost(2.0),
                    "detail".into(),
                ),
                figure("too slow", 3.0, "x", Target::AtMost(2.0), String::new()),
            ],
            wall_against_messages: vec![CurvePoint {
                x: 1024.0,
                label: "1024 messages".into(),
                fidelity: "flow",
                wall_s: 0.5,
                events: 1024,
            }],
            wall_against_procs: Vec::new(),
            wall_against_triangles: Vec::new(),
            flow_solves: vec![(
                "1024 messages".into(),
                SolveCounters {
                    solves: 4,
                    flows_changed: 10,
                    groups_changed: 2,
                    flows_switched: 1,
                    link_evaluations: 8,
                    flows_on_links: 20,
                    groups_crossing: 12,
                    flows_swept: 6,
                    swept_route_links: 30,
                    sweeps: 2,
                    reruns: 1,
                    added_alone: 1,
                    removed_alone: 1,
                    dirty_links: 6,
                    left_out_links: 12,
                },
            )],
        };
        let text = table(&report);
        let line = |name: &str| {
            text.lines()
                .find(|l| l.starts_with(name))
                .unwrap()
                .to_string()
        };
        assert!(line("fast enough").ends_with("yes"));
        assert!(line("too slow").ends_with("NO"));
        assert!(text.contains("    detail\n"));
        assert!(line("1024 messages").contains("flow"));
        // Per solve: 2.5 flows and 0.5 groups changed, 0.25 switched; per evaluated link 2.5
        // flows walked against 1.5 groups crossing; per solve 1.5 flows swept, crossing 7.5
        // links; of the 4 solves, 2 swept (one of them twice), 1 added a flow alone and 1
        // removed one alone; the 3 sweep runs made 2 links dirty and left 4 out each.
        let solves = text.split("flow solves").nth(1).unwrap();
        let row: Vec<&str> = solves
            .lines()
            .find(|l| l.starts_with("1024 messages"))
            .unwrap()
            .split_whitespace()
            .collect();
        assert_eq!(
            row[2..],
            [
                "4", "2.5", "0.5", "0.25", "2.5", "1.5", "1.5", "7.5", "2", "1", "1", "1", "2.0",
                "4.0"
            ]
        );
    }
}
