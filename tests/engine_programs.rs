//! The engine seen by node programs: cpu queueing, send/receive costs, matching, blocking
//! sends, deadlock reports, memory errors, broadcast, determinism.

use crate::common;

use std::cell::RefCell;
use std::rc::Rc;

use sortsim::engine::{Filter, Payload, Sim, SimError};
use sortsim::machine::{Counts, Op};
use sortsim::units::{Bytes, SimTime};

#[derive(Clone, Debug, PartialEq)]
enum Msg {
    Data(u32),
    Ack,
}

impl Payload for Msg {
    fn tag(&self) -> u32 {
        match self {
            Msg::Data(_) => 1,
            Msg::Ack => 2,
        }
    }
}

type Log = Rc<RefCell<Vec<(u64, String)>>>;

fn log(l: &Log, t: SimTime, what: impl Into<String>) {
    l.borrow_mut().push((t.ps(), what.into()));
}

#[test]
fn one_cpu_serves_compute_requests_first_come_first_served() {
    let m = common::ring(2, "0us", "0us", true);
    let mut sim: Sim<Msg> = Sim::new(&m, 1).unwrap();
    let l: Log = Default::default();
    for name in ["a", "b"] {
        let (node, l) = (sim.node(0), l.clone());
        sim.spawn(0, name, async move {
            node.phase(if name == "a" { "raster" } else { "transform" });
            // 1000 pixel writes at 10ns + 2 setups at 1us = 12us.
            node.compute(Counts::of(Op::PixelWrite, 1000).add(Op::SetupTriangle, 2))
                .await;
            log(&l, node.now(), name);
            Ok(())
        });
    }
    let stats = sim.run().unwrap();
    assert_eq!(
        *l.borrow(),
        vec![(12_000_000, "a".into()), (24_000_000, "b".into())]
    );
    assert_eq!(stats.nodes[0].busy(), SimTime::from_us(24));
    assert_eq!(
        stats.nodes[0].busy_by_phase,
        vec![
            ("raster", SimTime::from_us(12)),
            ("transform", SimTime::from_us(12))
        ]
    );
    assert_eq!(stats.idle(1), SimTime::from_us(24));
    assert_eq!(stats.end, SimTime::from_us(24));
}

proptest::proptest! {
    /// A program's charges land on the phase it named last, however it switches between
    /// labels (the same words at another address are the same phase), summed per node in the
    /// order the phases were first charged: the plain sum over every charge. (The engine keeps
    /// where a program's phase sits among its node's phases between charges.)
    #[test]
    fn charges_are_summed_by_the_phase_named_last(
        scripts in proptest::collection::vec(
            proptest::collection::vec((0usize..4, 0u64..4), 0..30),
            2..=2,
        )
    ) {
        // "a" a second time at an address of its own.
        let labels: [&'static str; 4] = ["a", "b", Box::leak(String::from("a").into_boxed_str()), "c"];
        let m = common::ring(2, "0us", "0us", true);
        let mut sim: Sim<Msg> = Sim::new(&m, 1).unwrap();
        for (id, script) in scripts.iter().enumerate() {
            let (node, script) = (sim.node(id as u32), script.clone());
            sim.spawn(id as u32, "charges", async move {
                for (label, ns) in script {
                    node.phase(labels[label]);
                    node.compute_for(SimTime::from_ns(ns)).await;
                }
                Ok(())
            });
        }
        let stats = sim.run().unwrap();
        for (id, script) in scripts.iter().enumerate() {
            let mut expected: Vec<(&str, SimTime)> = Vec::new();
            for &(label, ns) in script {
                let t = SimTime::from_ns(ns);
                match expected.iter_mut().find(|(p, _)| *p == labels[label]) {
                    Some((_, sum)) => *sum += t,
                    None => expected.push((labels[label], t)),
                }
            }
            let got: Vec<(&str, SimTime)> = stats.nodes[id].busy_by_phase.clone();
            proptest::prop_assert_eq!(got, expected, "node {}", id);
        }
    }
}

/// A ring node whose cpu slices work into `timeslice` pieces.
fn sliced_ring(timeslice: &str) -> sortsim::machine::MachineConfig {
    let mut m = common::ring(2, "0us", "0us", true);
    m.cpu.timeslice = Some(timeslice.parse().unwrap());
    m
}

#[test]
fn a_time_sliced_cpu_lets_a_short_job_in_after_one_slice_of_a_long_one() {
    for (timeslice, short_ends, long_ends) in [
        // 100us of work against 1us that arrives at 5us: without slicing the short job waits
        // for all of the long one; with 10us slices it runs after the first slice, and the
        // long one ends 1us later than alone.
        (None, 101, 100),
        (Some("10us"), 11, 101),
        // A slice longer than the work changes nothing.
        (Some("1ms"), 101, 100),
    ] {
        let m = match timeslice {
            Some(t) => sliced_ring(t),
            None => common::ring(2, "0us", "0us", true),
        };
        let mut sim: Sim<Msg> = Sim::new(&m, 1).unwrap();
        let l: Log = Default::default();
        let (node, log_long) = (sim.node(0), l.clone());
        sim.spawn(0, "long", async move {
            node.compute_for(SimTime::from_us(100)).await;
            log(&log_long, node.now(), "long");
            Ok(())
        });
        let (node, log_short) = (sim.node(0), l.clone());
        sim.spawn(0, "short", async move {
            node.sleep(SimTime::from_us(5)).await;
            node.compute_for(SimTime::from_us(1)).await;
            log(&log_short, node.now(), "short");
            Ok(())
        });
        let stats = sim.run().unwrap();
        let mut want = vec![
            (short_ends * 1_000_000, "short".to_string()),
            (long_ends * 1_000_000, "long".to_string()),
        ];
        want.sort();
        assert_eq!(*l.borrow(), want, "timeslice {timeslice:?}");
        // Slicing moves work in time, never adds or drops any.
        assert_eq!(stats.nodes[0].busy(), SimTime::from_us(101));
    }
}

#[test]
fn alone_on_its_cpu_a_sliced_computation_ends_when_an_unsliced_one_would() {
    for timeslice in ["1us", "7us", "10us", "33us"] {
        let mut sim: Sim<Msg> = Sim::new(&sliced_ring(timeslice), 1).unwrap();
        let l: Log = Default::default();
        let (node, l2) = (sim.node(0), l.clone());
        sim.spawn(0, "alone", async move {
            node.compute(Counts::of(Op::PixelWrite, 1000).add(Op::SetupTriangle, 90))
                .await;
            log(&l2, node.now(), "alone");
            Ok(())
        });
        sim.run().unwrap();
        assert_eq!(
            *l.borrow(),
            vec![(100_000_000, "alone".into())],
            "{timeslice}"
        );
    }
}

#[test]
fn a_message_costs_send_overhead_transfer_and_receive_overhead() {
    // 1000 B at 1 MB/s = 1ms; one hop of 1us; 5us to send, 7us to receive.
    let m = common::ring(2, "5us", "7us", true);
    let mut sim: Sim<Msg> = Sim::new(&m, 1).unwrap();
    let l: Log = Default::default();
    let (n0, l0) = (sim.node(0), l.clone());
    sim.spawn(0, "sender", async move {
        n0.send(1, Bytes::new(1000), Msg::Data(9)).await;
        log(&l0, n0.now(), "sent");
        Ok(())
    });
    let (n1, l1) = (sim.node(1), l.clone());
    sim.spawn(1, "receiver", async move {
        let env = n1.recv(Filter::ANY).await;
        assert_eq!(
            (env.src, env.payload, env.bytes),
            (0, Msg::Data(9), Bytes::new(1000))
        );
        assert_eq!(env.arrived, SimTime::from_us(5 + 1 + 1000));
        log(&l1, n1.now(), "received");
        Ok(())
    });
    let stats = sim.run().unwrap();
    assert_eq!(
        *l.borrow(),
        vec![
            (5_000_000, "sent".into()),
            (1_013_000_000, "received".into())
        ]
    );
    assert_eq!(stats.nodes[0].comm, SimTime::from_us(5));
    assert_eq!(stats.nodes[1].comm, SimTime::from_us(7));
    assert_eq!(
        (stats.nodes[0].bytes_sent, stats.nodes[0].messages_sent),
        (Bytes::new(1000), 1)
    );
    assert_eq!(
        (
            stats.nodes[1].bytes_received,
            stats.nodes[1].messages_received
        ),
        (Bytes::new(1000), 1)
    );
}

#[test]
fn without_overlap_the_sender_waits_for_delivery() {
    let m = common::ring(2, "5us", "0us", false);
    let mut sim: Sim<Msg> = Sim::new(&m, 1).unwrap();
    let l: Log = Default::default();
    let (n0, l0) = (sim.node(0), l.clone());
    sim.spawn(0, "sender", async move {
        n0.send(1, Bytes::new(1000), Msg::Data(1)).await;
        log(&l0, n0.now(), "sent");
        Ok(())
    });
    let n1 = sim.node(1);
    sim.spawn(1, "receiver", async move {
        n1.recv(Filter::ANY).await;
        Ok(())
    });
    let stats = sim.run().unwrap();
    assert_eq!(*l.borrow(), vec![(1_006_000_000, "sent".into())]);
    assert_eq!(
        stats.nodes[0].comm,
        SimTime::from_us(1006),
        "overhead plus the blocked transfer"
    );
}

#[test]
fn receive_matches_tag_and_source_in_arrival_order() {
    let m = common::ring(3, "0us", "0us", true);
    let mut sim: Sim<Msg> = Sim::new(&m, 1).unwrap();
    let got: Rc<RefCell<Vec<(u32, Msg)>>> = Default::default();
    for src in [1, 2] {
        let n = sim.node(src);
        sim.spawn(src, format!("sender{src}"), async move {
            n.send(0, Bytes::new(10), Msg::Data(src)).await;
            n.sleep(SimTime::from_ms(1)).await;
            n.send(0, Bytes::new(10), Msg::Ack).await;
            Ok(())
        });
    }
    let (n0, g) = (sim.node(0), got.clone());
    sim.spawn(0, "receiver", async move {
        n0.sleep(SimTime::from_ms(5)).await; // everything has arrived by now
        for filter in [
            Filter::tag(2).and_source(2),
            Filter::tag(1),
            Filter::source(1),
            Filter::ANY,
        ] {
            let env = n0.recv(filter).await;
            g.borrow_mut().push((env.src, env.payload));
        }
        Ok(())
    });
    sim.run().unwrap();
    assert_eq!(
        *got.borrow(),
        vec![
            (2, Msg::Ack),
            (1, Msg::Data(1)),
            (1, Msg::Ack),
            (2, Msg::Data(2))
        ]
    );
}

#[test]
fn a_deadlock_names_every_waiting_program_and_what_it_waits_for() {
    let m = common::ring(2, "0us", "0us", true);
    let mut sim: Sim<Msg> = Sim::new(&m, 77).unwrap();
    let n0 = sim.node(0);
    sim.spawn(0, "collector", async move {
        n0.recv(Filter::tag(2).and_source(1)).await;
        Ok(())
    });
    let n1 = sim.node(1);
    sim.spawn(1, "worker", async move {
        n1.recv(Filter::ANY).await;
        Ok(())
    });
    let n1 = sim.node(1);
    sim.node(1).spawn_daemon("handler", async move {
        loop {
            n1.recv(Filter::tag(7)).await;
        }
    });
    let err = sim.run().unwrap_err();
    let SimError::Deadlock { waiting, seed, .. } = &err else {
        panic!("expected a deadlock, got {err}")
    };
    assert_eq!(*seed, 77);
    let names: Vec<_> = waiting
        .iter()
        .map(|w| (w.name.as_str(), w.node, w.waits_for.as_str()))
        .collect();
    assert_eq!(
        names,
        vec![
            ("collector", 0, "a message with tag 2 from node 1"),
            ("worker", 1, "a message of any kind from anyone"),
        ],
        "the daemon handler is not reported"
    );
    assert!(err
        .to_string()
        .contains("'collector' on node 0 waits for a message with tag 2 from node 1"));
}

#[test]
fn memory_over_capacity_stops_the_run_naming_node_tag_and_bytes() {
    let m = common::ring(2, "0us", "0us", true);
    let mut sim: Sim<Msg> = Sim::new(&m, 1).unwrap();
    let n = sim.node(1);
    sim.spawn(1, "renderer", async move {
        n.alloc("framebuffer", Bytes::new(600_000))?;
        n.compute_for(SimTime::from_us(3)).await;
        n.alloc("zbuffer", Bytes::new(500_000))?;
        Ok(())
    });
    let err = sim.run().unwrap_err().to_string();
    assert!(
        err.contains("program 'renderer' on node 1 failed at 3us"),
        "{err}"
    );
    assert!(
        err.contains(
            "allocating 500000B for 'zbuffer' exceeds its memory: 400000B of 1000000B available"
        ),
        "{err}"
    );
}

#[test]
fn broadcast_needs_a_bus() {
    let m = common::ring(2, "0us", "0us", true);
    let mut sim: Sim<Msg> = Sim::new(&m, 1).unwrap();
    let n = sim.node(0);
    sim.spawn(0, "talker", async move {
        n.broadcast(Bytes::new(4), Msg::Ack).await
    });
    let err = sim.run().unwrap_err().to_string();
    assert!(err.contains("broadcast needs a bus network"), "{err}");
}

#[test]
fn timers_and_posts_cost_nothing_and_keep_fifo_order_on_ties() {
    let mut sim: Sim<u64> = Sim::bare(1, 1);
    let n = sim.node(0);
    let got: Rc<RefCell<Vec<u64>>> = Default::default();
    let g = got.clone();
    sim.spawn(0, "timers", async move {
        for i in 0..5 {
            n.post(0, SimTime::from_us(10), i);
        }
        n.post(0, SimTime::from_us(5), 99);
        for _ in 0..6 {
            let payload = n.recv(Filter::ANY).await.payload;
            g.borrow_mut().push(payload);
        }
        assert_eq!(n.now(), SimTime::from_us(10));
        Ok(())
    });
    let stats = sim.run().unwrap();
    assert_eq!(*got.borrow(), vec![99, 0, 1, 2, 3, 4]);
    assert_eq!(stats.nodes[0].busy(), SimTime::ZERO);
}

/// A run whose every event is logged with its time: the same seed must give the same log.
fn chatty_run(seed: u64) -> Vec<(u64, String)> {
    use rand::Rng;
    let m = common::ring(8, "3us", "2us", true);
    let mut sim: Sim<Msg> = Sim::new(&m, seed).unwrap();
    let l: Log = Default::default();
    for id in 0..8 {
        let (n, lp) = (sim.node(id), l.clone());
        sim.spawn(id, format!("p{id}"), async move {
            let mut rng = n.rng(&format!("chatty/{id}"));
            for round in 0..20 {
                let dst = rng.gen_range(0..8);
                n.send(dst, Bytes::new(rng.gen_range(1..5000)), Msg::Data(round))
                    .await;
                n.compute_for(SimTime::from_ns(rng.gen_range(0..5000)))
                    .await;
                log(&lp, n.now(), format!("{id} sent {round} to {dst}"));
            }
            Ok(())
        });
        let (n, li) = (sim.node(id), l.clone());
        sim.node(id).spawn_daemon(format!("inbox{id}"), async move {
            loop {
                let env = n.recv(Filter::ANY).await;
                log(
                    &li,
                    n.now(),
                    format!("{id} got {:?} from {}", env.payload, env.src),
                );
            }
        });
    }
    sim.run().unwrap();
    let out = l.borrow().clone();
    out
}

#[test]
fn same_seed_same_event_log_other_seed_other_log() {
    let a = chatty_run(5);
    assert_eq!(a.len(), 8 * 20 * 2);
    assert_eq!(a, chatty_run(5));
    assert_ne!(a, chatty_run(6));
}
