//! Node programs talking through each transport model: the engine hands messages to the
//! network and back without adding or losing time.

use crate::common;

use std::cell::RefCell;
use std::rc::Rc;

use sortsim::engine::{Filter, Sim};
use sortsim::metrics::machine::Summary;
use sortsim::output::to_json;
use sortsim::units::{Bandwidth, Bytes, SimTime};

fn torus(fidelity: &str, switching: &str) -> sortsim::machine::MachineConfig {
    common::machine(&format!(
        r#"{{"name": "t", "source": "test", "nodes": 16,
            "cpu": {{"send_overhead": "3us", "recv_overhead": "2us", "overlap": true}},
            "memory": {{"capacity_per_node": "4MB"}},
            "network": {{"topology": "torus", "dims": [4, 4], "link_bandwidth": "1.7MB/s", "hop_latency": "5us",
                         "switching": "{switching}", "packet_size": "1KiB", "fidelity": "{fidelity}"}}}}"#
    ))
}

/// Sends `bytes` from `src` to `dst` at time zero and returns when the receiver got it.
fn lone_message(m: &sortsim::machine::MachineConfig, src: u32, dst: u32, bytes: u64) -> SimTime {
    let mut sim: Sim<()> = Sim::new(m, 1).unwrap();
    let n = sim.node(src);
    sim.spawn(src, "sender", async move {
        n.send(dst, Bytes::new(bytes), ()).await;
        Ok(())
    });
    let got = Rc::new(RefCell::new(SimTime::ZERO));
    let (n, g) = (sim.node(dst), got.clone());
    sim.spawn(dst, "receiver", async move {
        n.recv(Filter::ANY).await;
        *g.borrow_mut() = n.now();
        Ok(())
    });
    sim.run().unwrap();
    let t = *got.borrow();
    t
}

#[test]
fn a_lone_message_costs_overheads_plus_the_formula_at_every_fidelity() {
    let bw: Bandwidth = "1.7MB/s".parse().unwrap();
    let (l, h) = (SimTime::from_us(5), 4); // node 0 to node 10 = (2,2): two hops in x, two in y
    for bytes in [1u64, 1024, 1025, 10_000] {
        let wormhole = l.times(h) + bw.transfer_time(Bytes::new(bytes));
        let saf = wormhole + bw.transfer_time(Bytes::new(bytes.min(1024))).times(h - 1);
        let overheads = SimTime::from_us(3 + 2);
        for fidelity in ["ideal", "hops", "flow", "packet"] {
            assert_eq!(
                lone_message(&torus(fidelity, "wormhole"), 0, 10, bytes),
                overheads + wormhole,
                "{fidelity} {bytes}B"
            );
            // `ideal` ignores switching: the store-and-forward pipeline term is the price of `hops` and above.
            let expect = if fidelity == "ideal" { wormhole } else { saf };
            assert_eq!(
                lone_message(&torus(fidelity, "store-and-forward"), 0, 10, bytes),
                overheads + expect,
                "{fidelity} SAF {bytes}B"
            );
        }
    }
}

/// Two senders whose routes share the link 1 -> 2 (node 0 -> 2 and node 1 -> 2 on a 4x4
/// torus, e-cube routing): returns both arrival times.
fn shared_link(fidelity: &str) -> Vec<SimTime> {
    let m = torus(fidelity, "wormhole");
    let mut sim: Sim<()> = Sim::new(&m, 1).unwrap();
    for src in [0, 1] {
        let n = sim.node(src);
        sim.spawn(src, "sender", async move {
            n.send(2, Bytes::new(17_000), ()).await;
            Ok(())
        });
    }
    let got = Rc::new(RefCell::new(Vec::new()));
    let (n, g) = (sim.node(2), got.clone());
    sim.spawn(2, "receiver", async move {
        for _ in 0..2 {
            let env = n.recv(Filter::ANY).await;
            g.borrow_mut().push(env.arrived);
        }
        Ok(())
    });
    sim.run().unwrap();
    let v = got.borrow().clone();
    v
}

#[test]
fn sharing_a_link_under_flow_doubles_the_transfer() {
    // 17,000 B at 1.7 MB/s = 10ms alone; shared fairly on link 1->2 while both are active.
    let ideal = shared_link("ideal");
    let flow = shared_link("flow");
    assert_eq!(
        ideal[1] - SimTime::from_us(3 + 5 + 5),
        SimTime::from_ms(10),
        "no contention modelled"
    );
    assert!(flow[1] > ideal[1]);
    // Both transfers start together (same overhead): each gets half the link for 20ms.
    let transfer_part = flow[1] - SimTime::from_us(3);
    assert!(transfer_part >= SimTime::from_ms(20), "{transfer_part}");
    assert!(
        transfer_part <= SimTime::from_ms(20) + SimTime::from_us(10) + SimTime::from_ps(2),
        "{transfer_part}"
    );
}

#[test]
fn the_summary_of_a_run_is_byte_identical_across_runs() {
    let summary = || {
        let m = torus("flow", "wormhole");
        let mut sim: Sim<u32> = Sim::new(&m, 3).unwrap();
        for id in 0..16 {
            let n = sim.node(id);
            sim.spawn(id, "all-to-all", async move {
                n.phase("exchange");
                for k in 1..16 {
                    n.send((id + k) % 16, Bytes::new(2048 + 100 * k as u64), k)
                        .await;
                }
                n.phase("drain");
                for _ in 1..16 {
                    n.recv(Filter::ANY).await;
                }
                n.alloc("inbox", Bytes::new(15 * 4096)).unwrap();
                Ok(())
            });
        }
        to_json(&Summary::from_stats(&sim.run().unwrap()))
    };
    let a = summary();
    assert_eq!(a, summary());
    let v: serde_json::Value = serde_json::from_str(&a).unwrap();
    assert_eq!(v["totals"]["sent_messages"], 240);
    assert_eq!(
        v["nodes"][0]["memory_high_water_by_tag_bytes"]["inbox"],
        61440
    );
    assert!(v["links"]
        .as_array()
        .unwrap()
        .iter()
        .any(|l| l["peak_queue"].as_u64().unwrap() >= 2));
}
