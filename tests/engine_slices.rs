//! Chains of slices on a time-sliced cpu (`engine/slices.rs`) against the plain way
//! (`Sim::wake_every_slice`: the program wakes at the end of every slice): programs that
//! compute, sleep and send on nodes whose cpus other programs and message handlers keep
//! taking, with slices and work in whole microseconds so that slice ends fall on the same
//! instants as other events. Every program's steps happen at the same instants in the same
//! order, and the run's statistics (busy time by phase, events, timeline spans) are the same
//! to the last counter, both when the run goes to its end at once and when it stops at a
//! horizon first.

use crate::common;

use std::cell::{Cell, RefCell};
use std::future::Future;
use std::pin::Pin;
use std::rc::Rc;
use std::task::{Context, Poll};

use proptest::prelude::*;
use sortsim::engine::{Filter, Payload, Sim};
use sortsim::units::{Bytes, SimTime};

#[derive(Clone, Debug)]
struct Note;

impl Payload for Note {}

#[derive(Clone, Copy, Debug)]
enum Step {
    Compute(u64),
    Sleep(u64),
    Send(u32),
}

/// What a run did, in the order it happened: (time in ps, program, step).
type Log = Rc<RefCell<Vec<(u64, String, usize)>>>;

#[derive(Clone, Debug)]
struct Workload {
    timeslice_us: u64,
    recv_us: u64,
    /// Each program: its node and its steps.
    programs: Vec<(u32, Vec<Step>)>,
    /// Work each node's message handler does per message, in microseconds.
    handler_us: Vec<u64>,
    timeline: bool,
    /// Where the run stops first, in microseconds, before it goes on to the end.
    horizon_us: Option<u64>,
}

fn step() -> impl Strategy<Value = Step> {
    prop_oneof![
        4 => (0u64..60).prop_map(Step::Compute),
        2 => (0u64..15).prop_map(Step::Sleep),
        1 => (0u32..3).prop_map(Step::Send),
    ]
}

fn workload() -> impl Strategy<Value = Workload> {
    (1u32..=3, 1u64..=7, 0u64..3).prop_flat_map(|(nodes, timeslice_us, recv_us)| {
        (
            prop::collection::vec((0..nodes, prop::collection::vec(step(), 1..8)), 1..6),
            prop::collection::vec(0u64..12, nodes as usize),
            any::<bool>(),
            prop::option::of(0u64..200),
        )
            .prop_map(
                move |(programs, handler_us, timeline, horizon_us)| Workload {
                    timeslice_us,
                    recv_us,
                    programs,
                    handler_us,
                    timeline,
                    horizon_us,
                },
            )
    })
}

/// Runs `w`, chained or the plain way; returns everything it did and measured, as text.
fn run(w: &Workload, plain: bool) -> String {
    let mut machine = common::ring(3, "1us", &format!("{}us", w.recv_us), true);
    machine.cpu.timeslice = Some(SimTime::from_us(w.timeslice_us));
    let mut sim: Sim<Note> = Sim::new(&machine, 1).unwrap();
    if plain {
        sim.wake_every_slice();
    }
    if w.timeline {
        sim.record_timeline();
    }
    let log: Log = Default::default();
    for (i, (at, steps)) in w.programs.iter().enumerate() {
        let (node, log, steps) = (sim.node(*at), log.clone(), steps.clone());
        let name = format!("p{i}");
        sim.spawn(*at, name.clone(), async move {
            node.phase(if i % 2 == 0 { "even" } else { "odd" });
            for (k, s) in steps.into_iter().enumerate() {
                match s {
                    Step::Compute(us) => node.compute_for(SimTime::from_us(us)).await,
                    Step::Sleep(us) => node.sleep(SimTime::from_us(us)).await,
                    Step::Send(dst) => node.send(dst % 3, Bytes::new(4), Note).await,
                }
                log.borrow_mut().push((node.now().ps(), name.clone(), k));
            }
            Ok(())
        });
    }
    for n in 0..3 {
        let (node, log) = (sim.node(n), log.clone());
        let work = SimTime::from_us(w.handler_us.get(n as usize).copied().unwrap_or(1));
        let name = format!("handler{n}");
        sim.node(n).spawn_daemon(name.clone(), async move {
            for k in 0.. {
                node.recv(Filter::ANY).await;
                node.phase("handler");
                node.compute_for(work).await;
                log.borrow_mut().push((node.now().ps(), name.clone(), k));
            }
            Ok(())
        });
    }
    let mut out = String::new();
    if let Some(h) = w.horizon_us {
        sim.run_until(SimTime::from_us(h)).unwrap();
        out += &format!("at the horizon: {} {:?}\n", sim.now(), log.borrow());
    }
    let stats = sim.run().unwrap();
    out += &format!("{:?}\n{:?}", log.borrow(), stats);
    out
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]
    #[test]
    fn chains_do_what_a_wake_up_every_slice_does(w in workload()) {
        prop_assert_eq!(run(&w, false), run(&w, true), "{:?}", w);
    }
}

/// Polls of a future, counted.
struct Counted<F> {
    inner: F,
    polls: Rc<Cell<u32>>,
}

impl<F: Future + Unpin> Future for Counted<F> {
    type Output = F::Output;
    fn poll(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<F::Output> {
        self.polls.set(self.polls.get() + 1);
        Pin::new(&mut self.inner).poll(cx)
    }
}

/// How often a computation of 100 slices is polled, with another program taking the cpu
/// once at `cut_at` if given, chained or the plain way.
fn polls_of_100_slices(cut_at: Option<u64>, plain: bool) -> (u32, u64) {
    let (polls, stats) = run_100_slices(cut_at, plain);
    (polls, stats.events)
}

/// [`polls_of_100_slices`]'s run, with a timeline; the other program works in a phase of its
/// own.
fn run_100_slices(cut_at: Option<u64>, plain: bool) -> (u32, sortsim::engine::RunStats) {
    let mut machine = common::ring(1, "0us", "0us", true);
    machine.cpu.timeslice = Some(SimTime::from_us(1));
    let mut sim: Sim<Note> = Sim::new(&machine, 1).unwrap();
    sim.record_timeline();
    if plain {
        sim.wake_every_slice();
    }
    let polls = Rc::new(Cell::new(0));
    let (node, counted) = (sim.node(0), polls.clone());
    sim.spawn(0, "long", async move {
        let inner = node.compute_for(SimTime::from_us(100));
        Counted {
            inner,
            polls: counted,
        }
        .await;
        Ok(())
    });
    if let Some(at) = cut_at {
        let node = sim.node(0);
        sim.spawn(0, "short", async move {
            node.sleep(SimTime::from_us(at)).await;
            node.phase("cut in");
            node.compute_for(SimTime::from_us(1)).await;
            Ok(())
        });
    }
    let stats = sim.run().unwrap();
    (polls.get(), stats)
}

/// The chains are taken: a computation alone on its cpu is polled when it starts and when
/// its last slice ends, not at every slice, and one that another program cuts into once is
/// polled twice more; the run counts an event at every slice's end all the same.
#[test]
fn a_computation_alone_on_its_cpu_is_polled_twice_not_every_slice() {
    let (chained, events) = polls_of_100_slices(None, false);
    assert_eq!((chained, events), (2, 100));
    assert_eq!(polls_of_100_slices(None, true), (101, 100));
    let (cut, events_cut) = polls_of_100_slices(Some(30), false);
    assert_eq!(
        cut, 3,
        "woken where the other program cut in, then chained again"
    );
    assert_eq!(polls_of_100_slices(Some(30), true).1, events_cut);
}

/// A timeline shows a computation's slices as one span, however many charges made it, and
/// a program that cuts in as a span between two: the same spans chained or the plain way.
#[test]
fn a_computation_cut_into_slices_is_one_span_on_a_timeline() {
    let spans = |cut_at, plain| {
        let timeline = run_100_slices(cut_at, plain).1.timeline.unwrap();
        timeline
            .iter()
            .map(|s| (s.phase, s.start.as_us_f64(), s.end.as_us_f64()))
            .collect::<Vec<_>>()
    };
    for plain in [false, true] {
        assert_eq!(
            spans(None, plain),
            vec![("run", 0.0, 100.0)],
            "plain: {plain}"
        );
        assert_eq!(
            spans(Some(30), plain),
            vec![
                ("run", 0.0, 30.0),
                ("cut in", 30.0, 31.0),
                ("run", 31.0, 101.0)
            ],
            "plain: {plain}"
        );
    }
}

/// Whole frames on the MultiCluster's time-sliced T800s, where paper 001's request balancer
/// shares each cpu with the renderer: every frame record, the statistics to the last counter
/// (timeline included) and the image are the plain way's, at the machine's costs and at
/// costs 10,000 times a slice.
#[test]
fn sliced_runs_are_the_same_chained() {
    use sortsim::algo::run;
    for algo in ["sort-last/df", "sort-last/scanline-flow", "sort-last/pc"] {
        for set in [&[][..], &[("machine.cpu.costs.pixel_write", "20ms")][..]] {
            let mut cfg = common::frames_config(
                "multicluster-pipeline.json",
                &common::scene("spd-gears.json"),
                algo,
                6,
                "0..1",
                set,
            );
            cfg.timeline = true;
            let chained = run(&cfg).expect("the run completes");
            cfg.wake_every_slice = true;
            let plain = run(&cfg).expect("the run completes");
            let answers = |r: &sortsim::algo::RunResult| {
                format!("{:?}\n{:?}\n{:016x}", r.frames, r.stats, r.image.hash())
            };
            assert_eq!(answers(&chained), answers(&plain), "{algo} {set:?}");
        }
    }
}
