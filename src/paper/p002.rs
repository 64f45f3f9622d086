//! Paper 002 (Ellsworth's sort-middle on the Touchstone Delta): the machine's parameters,
//! the test models, two-step redistribution's message count, the utilization simulator and
//! performance model (Figures 4 and 5), and Figure 9's peaks, gains and shares, from runs of
//! `sort-middle/ellsworth` on machines/delta.json at its default fidelity.
//!
//! Owns which runs answer which row of papers/002.json. Must never hold a paper value.

use crate::algo::image_space::assign::Assignment;
use crate::algo::image_space::regions::RegionGrid;
use crate::algo::image_space::two_step::Groups;
use crate::algo::image_space::DEFAULT_BUFFER;
use crate::algo::reference::viewport;
use crate::algo::sort_middle::utilization::{self, CountsMode};
use crate::algo::{FrameRecord, RunResult};
use crate::machine::{MachineConfig, Op};
use crate::net::Fidelity;
use crate::output::plot::{ChartOptions, Series};
use crate::scene::summary::summary;
use crate::scene::Scene;
use crate::spec::machine::load_machine;
use crate::units::SimTime;

use super::runs::{mean, run_jobs, triangles_per_s_over, Job};
use super::{paper_value, Chart, Measured, Measurements, PaperData, PaperOptions};

const DELTA: &str = "delta.json";
const POLIO: &str = "polio-standin.json";
const PLB: &str = "plb-head-standin.json";
const PROCS: [u32; 6] = [16, 32, 64, 128, 256, 512];
const MODES: [&str; 2] = ["off", "on"];
const AA: (&str, &str) = ("aa", "supersample:16");
/// Where sortsim's anti-aliased polio curve is drawn beside the paper's anti-aliased peak.
const AA_CURVE_PROCS: [u32; 4] = [64, 128, 256, 512];

/// The frames of a run that stand for the paper's viewing sequences: all but the first, which
/// deals regions r mod N and waits for no assignment. In the paper's averages over 80 and 110
/// frames the first weighs about 1%; in a run of a few frames it would weigh a third or a half.
fn sequence_frames(r: &RunResult) -> &[FrameRecord] {
    if r.frames.len() > 1 {
        &r.frames[1..]
    } else {
        &r.frames
    }
}

/// Triangles in view over frame time, averaged over frames (the paper's measure).
fn triangles_per_s(r: &RunResult) -> f64 {
    triangles_per_s_over(sequence_frames(r))
}

/// Mean frame time in seconds.
fn frame_s(r: &RunResult) -> f64 {
    mean(sequence_frames(r).iter().map(|f| f.time().as_secs_f64()))
}

fn ellsworth(scene: &str, procs: u32, two_step: &str, frames: &str) -> Job {
    Job::new(DELTA, scene, "sort-middle/ellsworth", procs)
        .frames(frames)
        .set("granularity", "8")
        .set("two-step", two_step)
}

pub fn measure(options: &PaperOptions, data: &PaperData) -> Result<Measurements, String> {
    let machine = load_machine(&options.machine(DELTA)).map_err(|e| e.to_string())?;
    let mut m = Measurements::default();
    delta_rows(&machine, options, &mut m)?;
    model_rows(options, &mut m)?;
    two_step_rows(&mut m);
    assignment_rows(&machine, options, &mut m)?;
    utilization_rows(options, &machine, &mut m)?;
    figure_9_rows(options, &machine, data, &mut m)?;
    Ok(m)
}

/// Buffers in the stream `buffer-stream-rate` times: enough that the first buffer's latency
/// is a small part of the whole.
const STREAM_BUFFERS: u32 = 64;

/// MB/s one link carries for a stream of full polygon buffers from node 0 to node 1 (their
/// neighbour on the mesh), neither doing anything else: each buffer pays the sender's
/// overhead, its interface's gap, the wire and the receiver's overhead, as the machine's cpu
/// and interfaces overlap them.
fn buffer_stream_mb_per_s(machine: &MachineConfig) -> Result<f64, String> {
    use crate::engine::{Filter, Sim};
    let mut sim: Sim<()> = Sim::new(machine, 1).map_err(|e| e.to_string())?;
    let sender = sim.node(0);
    sim.spawn(0, "sender", async move {
        for _ in 0..STREAM_BUFFERS {
            sender.send(1, DEFAULT_BUFFER, ()).await;
        }
        Ok(())
    });
    let receiver = sim.node(1);
    sim.spawn(1, "receiver", async move {
        for _ in 0..STREAM_BUFFERS {
            receiver.recv(Filter::ANY).await;
        }
        Ok(())
    });
    let stats = sim.run().map_err(|e| e.to_string())?;
    let bytes = DEFAULT_BUFFER.get() as f64 * f64::from(STREAM_BUFFERS);
    Ok(bytes / stats.end.as_secs_f64() / 1e6)
}

fn delta_rows(
    machine: &MachineConfig,
    options: &PaperOptions,
    m: &mut Measurements,
) -> Result<(), String> {
    let net = &machine.network;
    m.put(
        "delta-nodes",
        Measured::value(machine.nodes as f64, "machines/delta.json: nodes"),
    );
    m.put(
        "delta-mesh",
        Measured::shape(
            net.topology == crate::net::TopologyKind::Mesh && net.dims == [16, 32],
            format!(
                "machines/delta.json: {} {}",
                net.topology,
                crate::net::dims_text(&net.dims)
            ),
        ),
    );
    m.put(
        "delta-link",
        Measured::value(
            net.link_bandwidth.bytes_per_s_f64() / 1e6,
            "machines/delta.json: network.link_bandwidth",
        ),
    );
    m.put(
        "delta-buffer",
        Measured::value(
            DEFAULT_BUFFER.get() as f64 / 1024.0,
            "sort-middle's default option buffer",
        ),
    );
    let cpu = &machine.cpu;
    let overhead = (cpu.send_overhead + cpu.recv_overhead).as_secs_f64();
    let copy = cpu
        .costs
        .get(Op::ByteCopy)
        .times(DEFAULT_BUFFER.get())
        .as_secs_f64()
        + (cpu.send_per_byte + cpu.recv_per_byte)
            .times(DEFAULT_BUFFER.get())
            .as_secs_f64();
    let wire = net
        .link_bandwidth
        .transfer_time(DEFAULT_BUFFER)
        .as_secs_f64();
    m.put(
        "delta-overhead-share",
        Measured::value(
            100.0 * overhead / (overhead + copy + wire),
            format!(
                "overheads {:.0} us / (overheads + copying {:.0} us + wire {:.0} us)",
                overhead * 1e6,
                copy * 1e6,
                wire * 1e6
            ),
        ),
    );
    let at = |fidelity: Fidelity, overlap: bool| {
        let mut variant = machine.clone();
        variant.network.fidelity = fidelity;
        variant.cpu.overlap = overlap;
        buffer_stream_mb_per_s(&variant)
    };
    let (packets, flows, blocking) = (
        at(Fidelity::Packet, machine.cpu.overlap)?,
        at(Fidelity::Flow, machine.cpu.overlap)?,
        at(Fidelity::Packet, false)?,
    );
    m.put(
        "buffer-stream-rate",
        Measured::value(
            packets,
            format!(
                "{STREAM_BUFFERS} full buffers from node 0 to its neighbour, node 1, at packet fidelity (the Delta's wormhole packets, first come first served on the link); {flows:.1} MB/s at flow fidelity, whose flows share the link and so arrive together; {blocking:.1} MB/s if each send waited for its delivery (cpu.overlap false)"
            ),
        ),
    );
    let mut screens = Vec::new();
    for name in [PLB, POLIO, "terrain-standin.json", "ct-head-standin.json"] {
        let scene = Scene::load(&options.scene(name)).map_err(|e| e.to_string())?;
        let s = summary(&scene, 0).map_err(|e| e.to_string())?;
        screens.push((name, s.width, s.height));
    }
    m.put(
        "delta-screen",
        Measured::shape(
            screens.iter().all(|s| (s.1, s.2) == (640, 512)),
            screens
                .iter()
                .map(|(n, w, h)| format!("{n} {w}x{h}"))
                .collect::<Vec<_>>()
                .join(", "),
        ),
    );
    Ok(())
}

fn model_rows(options: &PaperOptions, m: &mut Measurements) -> Result<(), String> {
    for (key, file) in [
        ("plb", PLB),
        ("polio", POLIO),
        ("terrain", "terrain-standin.json"),
        ("ct", "ct-head-standin.json"),
    ] {
        let scene = Scene::load(&options.scene(file)).map_err(|e| e.to_string())?;
        let s = summary(&scene, 0).map_err(|e| e.to_string())?;
        let where_ = format!("scenes/{file}, frame 0");
        m.put(
            &format!("model-{key}-triangles"),
            Measured::value(s.raster.counters.triangles_in as f64, where_.clone()),
        );
        m.put(
            &format!("model-{key}-mean-px"),
            Measured::value(s.raster.mean_area_px, where_.clone()),
        );
        m.put(
            &format!("model-{key}-overlap"),
            Measured::value(
                s.overlap_256,
                format!(
                    "{where_}, 16 x 16 regions of {}x{} px",
                    s.width / 16,
                    s.height / 16
                ),
            ),
        );
    }
    Ok(())
}

/// The load-balancing rules of the Implementation section, checked on the grids Figure 9's
/// runs use (ratio 8) and, for the greedy packing, on a real frame's polygon counts.
fn assignment_rows(
    machine: &MachineConfig,
    options: &PaperOptions,
    m: &mut Measurements,
) -> Result<(), String> {
    const RATIO: u32 = 8;
    let scene = Scene::load(&options.scene(PLB)).map_err(|e| e.to_string())?;
    let vp = viewport(&scene.frame(1).map_err(|e| e.to_string())?);
    let grid = |n: u32| {
        RegionGrid::with_count(vp, n * RATIO).ok_or(format!("{} regions on the screen", n * RATIO))
    };
    let mut interleaved = true;
    for n in PROCS {
        let a = Assignment::interleaved(grid(n)?.count(), n);
        interleaved &= a.owner.iter().enumerate().all(|(r, &p)| p == r as u32 % n);
    }
    m.put(
        "first-frame-interleaved",
        Measured::shape(
            interleaved,
            format!("Assignment::interleaved on {PROCS:?} processors x {RATIO} regions"),
        ),
    );
    let prices = utilization::Prices::of(machine);
    let profile = utilization::FrameProfile::new(&scene, 1, &prices).map_err(|e| e.to_string())?;
    let mut greedy = true;
    for n in PROCS {
        let counts = profile.counts(&grid(n)?);
        let costs: Vec<SimTime> = counts.iter().map(|&c| SimTime::from_ps(c as u64)).collect();
        let owner = Assignment::greedy(&costs, &vec![SimTime::ZERO; n as usize]).owner;
        greedy &= packs_largest_first_to_lightest(&costs, &owner, n);
    }
    m.put(
        "greedy-largest-first",
        Measured::shape(
            greedy,
            format!(
                "Assignment::greedy on the PLB head stand-in's frame 1 counts, {PROCS:?} processors x {RATIO} regions: each region, taken in decreasing count, went to a processor with the least load so far"
            ),
        ),
    );
    Ok(())
}

/// Whether `owner` is what assigning regions in decreasing cost, each to a least-loaded
/// processor, gives: replays the order and checks every choice against the loads so far.
fn packs_largest_first_to_lightest(costs: &[SimTime], owner: &[u32], n: u32) -> bool {
    let mut order: Vec<usize> = (0..costs.len()).collect();
    order.sort_by_key(|&r| (std::cmp::Reverse(costs[r]), r));
    let mut loads = vec![SimTime::ZERO; n as usize];
    order.into_iter().all(|r| {
        let p = owner[r] as usize;
        let lightest = loads.iter().all(|&l| loads[p] <= l);
        loads[p] += costs[r];
        lightest
    })
}

fn two_step_rows(m: &mut Measurements) {
    m.put(
        "two-step-messages-256",
        Measured::value(
            Groups::new(256, 16).min_messages() as f64,
            "two_step::Groups::new(256, 16): every processor one message to a forwarder in each other group, each forwarder one to each other member of its group",
        ),
    );
    let best = (1..=256u32)
        .min_by_key(|&g| (Groups::new(256, g).min_messages(), g))
        .unwrap_or(1);
    m.put(
        "two-step-messages-min",
        Measured::shape(
            best == 16 && Groups::near_sqrt(256).count() == 16,
            format!(
                "fewest messages at g = {best} ({}); two-step on uses g = {}",
                Groups::new(256, best).min_messages(),
                Groups::near_sqrt(256).count()
            ),
        ),
    );
}

fn utilization_rows(
    options: &PaperOptions,
    machine: &MachineConfig,
    m: &mut Measurements,
) -> Result<(), String> {
    const UPROCS: [u32; 10] = [1, 2, 4, 8, 16, 32, 64, 128, 256, 512];
    const GRANULARITIES: [u32; 6] = [1, 2, 4, 6, 8, 12];
    let step = if options.quick { 16 } else { 4 };
    let plb_frames: Vec<u32> = (1..80).step_by(step).collect();
    let polio_frames: Vec<u32> = if options.quick {
        vec![1]
    } else {
        vec![1, 28, 55, 82]
    };
    let simulate = |file: &str,
                    procs: &[u32],
                    granularities: &[u32],
                    frames: &[u32]|
     -> Result<utilization::Outcome, String> {
        let scene = Scene::load(&options.scene(file)).map_err(|e| e.to_string())?;
        let cfg =
            utilization::Config::new(procs, granularities, frames).map_err(|e| e.to_string())?;
        utilization::simulate(&scene, machine, &cfg).map_err(|e| e.to_string())
    };
    let plb = simulate(PLB, &UPROCS, &GRANULARITIES, &plb_frames)?;
    let u =
        |n: u32, g: u32, mode: CountsMode| plb.cell(n, g, mode).map_or(f64::NAN, |c| c.utilization);
    let balanced = [CountsMode::Current, CountsMode::Previous];
    let mut rises = true;
    let mut falls = true;
    for mode in balanced {
        for n in UPROCS.into_iter().filter(|&n| n >= 8) {
            rises &= GRANULARITIES
                .windows(2)
                .all(|w| u(n, w[1], mode) >= u(n, w[0], mode) - 0.03);
            rises &= u(n, 12, mode) > u(n, 1, mode);
        }
        for g in GRANULARITIES {
            falls &= u(512, g, mode) <= u(8, g, mode) - 0.05;
        }
    }
    let frames_note = format!("PLB head stand-in, frames {plb_frames:?}");
    m.put(
        "util-rises-with-g",
        Measured::shape(
            rises,
            format!(
                "{frames_note}; previous counts, 512 processors: {}",
                GRANULARITIES
                    .iter()
                    .map(|&g| format!("g={g} {:.2}", u(512, g, CountsMode::Previous)))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        ),
    );
    m.put(
        "util-falls-with-n",
        Measured::shape(
            falls,
            format!(
                "{frames_note}; g=8 previous counts: 8 processors {:.2}, 512 processors {:.2}",
                u(8, 8, CountsMode::Previous),
                u(512, 8, CountsMode::Previous)
            ),
        ),
    );
    const DROP_RATIOS: [u32; 3] = [4, 8, 12];
    let drop = DROP_RATIOS
        .iter()
        .map(|&g| 100.0 * (u(512, g, CountsMode::Current) - u(512, g, CountsMode::Previous)))
        .fold(f64::MIN, f64::max);
    m.put(
        "util-previous-drop-512",
        Measured::value(drop, frames_note.clone()),
    );
    let other_frames: Vec<u32> = if options.quick {
        vec![1]
    } else {
        vec![1, 20, 39]
    };
    let mut other = Vec::new();
    for file in ["terrain-standin.json", "ct-head-standin.json"] {
        // Only the cells the row reads: 512 processors at its three ratios.
        let outcome = simulate(file, &[512], &DROP_RATIOS, &other_frames)?;
        let u = |g: u32, mode| {
            outcome
                .cell(512, g, mode)
                .map_or(f64::NAN, |c| c.utilization)
        };
        let drop = DROP_RATIOS
            .iter()
            .map(|&g| 100.0 * (u(g, CountsMode::Current) - u(g, CountsMode::Previous)))
            .fold(f64::MIN, f64::max);
        other.push((file, drop));
    }
    m.put(
        "util-previous-drop-other-512",
        Measured::value(
            other.iter().map(|o| o.1).fold(f64::MIN, f64::max),
            format!(
                "frames {other_frames:?}: {}",
                other
                    .iter()
                    .map(|(f, d)| format!("{f} {d:.1}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        ),
    );
    let polio = simulate(POLIO, &UPROCS, &GRANULARITIES, &polio_frames)?;
    for (id, outcome, note) in [
        ("best-g-head", &plb, frames_note.clone()),
        (
            "best-g-polio",
            &polio,
            format!("polio stand-in, frames {polio_frames:?}"),
        ),
    ] {
        // Figure 5's ratios (2 to 12): the mean relative time over 2..512 processors.
        let score = |g: u32| {
            mean(
                outcome
                    .cells
                    .iter()
                    .filter(|c| {
                        c.granularity == g && c.procs >= 2 && c.counts == CountsMode::Previous
                    })
                    .map(|c| c.relative_time),
            )
        };
        let best = GRANULARITIES[1..]
            .iter()
            .copied()
            .min_by(|&a, &b| score(a).total_cmp(&score(b)))
            .unwrap_or(8);
        let scores = GRANULARITIES[1..]
            .iter()
            .map(|&g| format!("{g}: {:.3}", score(g)))
            .collect::<Vec<_>>()
            .join(", ");
        m.put(
            id,
            Measured::value(
                best as f64,
                format!("{note}; mean relative time by ratio: {scores}"),
            ),
        );
    }
    Ok(())
}

/// The best of two-step off and on at each processor count, by triangles per second.
struct Curve<'a> {
    runs: Vec<(u32, [&'a RunResult; 2])>,
}

impl<'a> Curve<'a> {
    fn best(&self, procs: u32) -> (&'a RunResult, &'static str) {
        let [off, on] = self
            .runs
            .iter()
            .find(|r| r.0 == procs)
            .expect("a listed count")
            .1;
        if triangles_per_s(on) > triangles_per_s(off) {
            (on, "on")
        } else {
            (off, "off")
        }
    }

    fn rates(&self, pick: impl Fn(&[&'a RunResult; 2]) -> f64) -> Vec<(f64, f64)> {
        self.runs
            .iter()
            .map(|(n, r)| (*n as f64, pick(r)))
            .collect()
    }

    fn best_rates(&self) -> Vec<(u32, f64)> {
        self.runs
            .iter()
            .map(|(n, _)| (*n, triangles_per_s(self.best(*n).0)))
            .collect()
    }
}

fn figure_9_rows(
    options: &PaperOptions,
    machine: &MachineConfig,
    data: &PaperData,
    m: &mut Measurements,
) -> Result<(), String> {
    let (polio_frames, plb_frames) = if options.quick {
        ("0..2", "0..3")
    } else {
        ("0..4", "0..16")
    };
    let mut jobs = Vec::new();
    for n in PROCS {
        for mode in MODES {
            jobs.push(ellsworth(POLIO, n, mode, polio_frames));
            jobs.push(ellsworth(PLB, n, mode, plb_frames));
        }
    }
    for mode in MODES {
        jobs.push(ellsworth(POLIO, 256, mode, polio_frames).set(AA.0, AA.1));
    }
    // Figure 9's anti-aliased curve around its peak (two-step on, the faster mode there).
    for n in AA_CURVE_PROCS.into_iter().filter(|&n| n != 256) {
        jobs.push(ellsworth(POLIO, n, "on", polio_frames).set(AA.0, AA.1));
    }
    for n in [8, 256, 512] {
        jobs.push(ellsworth(PLB, n, "off", plb_frames));
        jobs.push(ellsworth(PLB, n, "off", plb_frames).set(AA.0, AA.1));
    }
    let results = run_jobs(options, &jobs)?;
    let at = |job: Job| -> &RunResult {
        let i = jobs
            .iter()
            .position(|j| j.scene == job.scene && j.procs == job.procs && j.set == job.set)
            .expect("every job asked for was run");
        &results[i]
    };
    let curve = |scene: &str, frames: &str| Curve {
        runs: PROCS
            .iter()
            .map(|&n| {
                (
                    n,
                    [
                        at(ellsworth(scene, n, "off", frames)),
                        at(ellsworth(scene, n, "on", frames)),
                    ],
                )
            })
            .collect(),
    };
    let polio = curve(POLIO, polio_frames);
    let plb = curve(PLB, plb_frames);
    let fidelity = machine.network.fidelity.to_string();
    let note = |scene: &str, frames: &str| {
        format!(
            "sort-middle/ellsworth, granularity 8, {scene}, frames {frames}, fidelity {fidelity}"
        )
    };

    let (best_256, mode_256) = polio.best(256);
    m.put(
        "peak-polio",
        Measured::value(
            triangles_per_s(best_256) / 1e6,
            format!("{}, two-step {mode_256}", note("polio", polio_frames)),
        ),
    );
    let polio_best = polio.best_rates();
    let peak_at = |rates: &[(u32, f64)]| {
        rates
            .iter()
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .map_or(0, |r| r.0)
    };
    m.put(
        "peak-polio-procs",
        Measured::value(
            peak_at(&polio_best) as f64,
            format!(
                "best-of-modes M triangles/s: {}",
                rate_list(&polio_best, 1e6)
            ),
        ),
    );
    let plb_best = plb.best_rates();
    m.put(
        "peak-plb-procs",
        Measured::value(
            peak_at(&plb_best) as f64,
            format!(
                "best-of-modes frames/s: {}",
                plb.runs
                    .iter()
                    .map(|(n, _)| format!("{n}: {:.1}", 1.0 / frame_s(plb.best(*n).0)))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        ),
    );
    let falls_after_peak = |rates: &[(u32, f64)]| {
        let top = peak_at(rates);
        top < 512 && rates.iter().any(|r| r.0 < top)
    };
    m.put(
        "peaks-then-falls",
        Measured::shape(
            falls_after_peak(&polio_best) && falls_after_peak(&plb_best),
            format!(
                "polio peaks at {} processors, PLB head at {}",
                peak_at(&polio_best),
                peak_at(&plb_best)
            ),
        ),
    );
    let (plb_128, plb_mode) = plb.best(128);
    m.put(
        "plb-fps-128",
        Measured::value(
            1.0 / frame_s(plb_128),
            format!("{}, two-step {plb_mode}", note("PLB head", plb_frames)),
        ),
    );
    let gains: Vec<(String, f64)> = [("polio", &polio), ("PLB head", &plb)]
        .iter()
        .flat_map(|(name, c)| {
            c.runs.iter().map(move |(n, [off, on])| {
                (
                    format!("{name} {n}"),
                    100.0 * (triangles_per_s(on) / triangles_per_s(off) - 1.0),
                )
            })
        })
        .collect();
    let largest = gains
        .iter()
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .cloned()
        .unwrap_or_default();
    m.put(
        "two-step-largest-gain",
        Measured::value(largest.1, format!("largest at {}", largest.0)),
    );
    let gain = |name: &str| gains.iter().find(|g| g.0 == name).map_or(f64::NAN, |g| g.1);
    let (g16, g32) = (gain("PLB head 16"), gain("PLB head 32"));
    let (g256, g512) = (gain("PLB head 256"), gain("PLB head 512"));
    m.put(
        "two-step-helps-small-many",
        Measured::shape(
            g256.min(g512) > 0.0 && g256.min(g512) > g16.max(g32),
            format!(
                "PLB head gain: {g16:+.0}% at 16, {g32:+.0}% at 32, {g256:+.0}% at 256, {g512:+.0}% at 512"
            ),
        ),
    );
    m.put(
        "bisection-link-rate",
        Measured::value(
            bisection_rate(machine, best_256)? / 1e6,
            format!("polio, 256 processors, two-step {mode_256}: bytes over the run's time, mean over links crossing the middle of the longest side"),
        ),
    );
    let (centre, edge) = centre_and_edge_wait(machine, best_256)?;
    m.put(
        "centre-waits-longer",
        Measured::shape(
            centre > 1.1 * edge,
            format!(
                "polio, 256 processors, two-step {mode_256}: mean wait a frame for polygon messages to arrive while rasterizing {:.2} ms in the central quarter, {:.2} ms on the border",
                centre * 1e3,
                edge * 1e3
            ),
        ),
    );
    let (best_128, mode_128) = polio.best(128);
    let (comm, busy) = best_128.stats.nodes.iter().fold((0.0, 0.0), |(c, b), n| {
        let busy: f64 = n.busy_by_phase.iter().map(|(_, t)| t.as_secs_f64()).sum();
        (c + n.comm.as_secs_f64(), b + busy)
    });
    m.put(
        "comm-share-128",
        Measured::value(
            100.0 * comm / busy,
            format!("polio, 128 processors, two-step {mode_128}: message overheads over busy time, all nodes"),
        ),
    );

    let polio_aa = MODES
        .iter()
        .map(|&mode| {
            (
                mode,
                triangles_per_s(at(ellsworth(POLIO, 256, mode, polio_frames).set(AA.0, AA.1))),
            )
        })
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap_or(("off", f64::NAN));
    m.put(
        "peak-polio-aa",
        Measured::value(
            polio_aa.1 / 1e6,
            format!(
                "{}, aa={}, two-step {}",
                note("polio", polio_frames),
                AA.1,
                polio_aa.0
            ),
        ),
    );
    let plb_ratio = |n: u32| {
        triangles_per_s(at(ellsworth(PLB, n, "off", plb_frames).set(AA.0, AA.1)))
            / triangles_per_s(at(ellsworth(PLB, n, "off", plb_frames)))
    };
    let aa_note = format!(
        "{}, two-step off, aa={} against none",
        note("PLB head", plb_frames),
        AA.1
    );
    m.put(
        "aa-ratio-8",
        Measured::value(100.0 * plb_ratio(8), aa_note.clone()),
    );
    m.put(
        "aa-ratio-512",
        Measured::value(100.0 * plb_ratio(512), aa_note),
    );
    let polio_ratio = triangles_per_s(at(
        ellsworth(POLIO, 256, "off", polio_frames).set(AA.0, AA.1)
    )) / triangles_per_s(at(ellsworth(POLIO, 256, "off", polio_frames)));
    let head_256 = plb_ratio(256);
    m.put(
        "aa-ratio-256",
        Measured::shape(
            head_256 >= 0.9 && polio_ratio < head_256,
            format!(
                "anti-aliased / aliased at 256, two-step off: PLB head {:.0}%, polio {:.0}%",
                100.0 * head_256,
                100.0 * polio_ratio
            ),
        ),
    );

    let paper_point =
        |id: &str, x: f64| paper_value(data, id).map(|v| (x, v)).into_iter().collect();
    let mtris = |r: &RunResult| triangles_per_s(r) / 1e6;
    m.charts.push(Chart {
        stem: "figure9-polio".into(),
        title: "Figure 9, polio: triangles per second on the Delta".into(),
        x_label: "processors".into(),
        y_label: "M triangles/s".into(),
        series: vec![
            Series::new("sortsim, two-step off", polio.rates(|r| mtris(r[0]))),
            Series::new("sortsim, two-step on", polio.rates(|r| mtris(r[1]))),
            Series::marks(
                "paper, point-sampled peak",
                paper_point("peak-polio", 256.0),
            ),
            Series::new(
                "sortsim, anti-aliased, two-step on",
                AA_CURVE_PROCS
                    .iter()
                    .map(|&n| {
                        let r = at(ellsworth(POLIO, n, "on", polio_frames).set(AA.0, AA.1));
                        (n as f64, mtris(r))
                    })
                    .collect(),
            ),
            Series::marks(
                "paper, anti-aliased peak",
                paper_point("peak-polio-aa", 256.0),
            ),
        ],
        options: ChartOptions {
            log_x: true,
            y_from_zero: true,
        },
    });
    m.charts.push(Chart {
        stem: "figure9-plb-head".into(),
        title: "Figure 9, PLB head: frames per second on the Delta".into(),
        x_label: "processors".into(),
        y_label: "frames/s".into(),
        series: vec![
            Series::new("sortsim, two-step off", plb.rates(|r| 1.0 / frame_s(r[0]))),
            Series::new("sortsim, two-step on", plb.rates(|r| 1.0 / frame_s(r[1]))),
            Series::marks("paper, peak", paper_point("plb-fps-128", 128.0)),
        ],
        options: ChartOptions {
            log_x: true,
            y_from_zero: true,
        },
    });
    Ok(())
}

fn rate_list(rates: &[(u32, f64)], scale: f64) -> String {
    rates
        .iter()
        .map(|(n, r)| format!("{n}: {:.2}", r / scale))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Mean seconds a frame that the nodes in the central quarter of the mesh (within a quarter
/// of each side from its middle), and those on its border, waited for polygon messages to
/// arrive while rasterizing.
fn centre_and_edge_wait(machine: &MachineConfig, r: &RunResult) -> Result<(f64, f64), String> {
    let procs = r.stats.nodes.len() as u32;
    let dims = machine.with_nodes(procs)?.network.dims;
    let coords = |node: u32| {
        let mut rest = node;
        dims.iter().map(move |&k| {
            let c = rest % k;
            rest /= k;
            (c, k)
        })
    };
    let central = |node: u32| coords(node).all(|(c, k)| (2 * c + 1).abs_diff(k) <= k / 2);
    let border = |node: u32| coords(node).any(|(c, k)| c == 0 || c + 1 == k);
    let waited = |node: usize| -> f64 {
        r.frames
            .iter()
            .map(|f| f.polygon_wait[node].as_secs_f64())
            .sum()
    };
    let mean_wait = |keep: &dyn Fn(u32) -> bool| {
        mean(
            (0..procs)
                .filter(|&i| keep(i))
                .map(|i| waited(i as usize) / r.frames.len().max(1) as f64),
        )
    };
    Ok((mean_wait(&central), mean_wait(&border)))
}

/// Mean bytes per second over the links that cross the middle of the partition's longest
/// side (both directions), over the whole run.
fn bisection_rate(machine: &MachineConfig, r: &RunResult) -> Result<f64, String> {
    let procs = r.stats.nodes.len() as u32;
    let dims = machine.with_nodes(procs)?.network.dims;
    let (d, &side) = dims
        .iter()
        .enumerate()
        .max_by_key(|(i, &k)| (k, std::cmp::Reverse(*i)))
        .ok_or("a mesh without dimensions")?;
    let stride: u32 = dims[..d].iter().product();
    let half = |node: u32| (node / stride) % side < side / 2;
    let crossing: Vec<f64> = r
        .stats
        .links
        .iter()
        .filter(|l| half(l.from) != half(l.to))
        .map(|l| l.bytes.get() as f64)
        .collect();
    let seconds = r.stats.end.as_secs_f64();
    Ok(mean(crossing.into_iter()) / seconds)
}
