//! Flow (fluid max-min) against packet (queues) on contention patterns: all-to-all, hot
//! spot and transpose on a 4x4 torus and an 8x8 mesh, and all-to-all on a bus.
//!
//! The two levels answer the same question differently, so they agree only within a
//! tolerance, measured rather than hoped for (17 MB/s links, 1 us per hop, 1 KiB packets;
//! ratios packet/flow measured when this test was written):
//!
//! | case | makespan WH | mean WH | makespan SAF | mean SAF |
//! | --- | --- | --- | --- | --- |
//! | torus4x4 all-to-all 16 KiB | 1.005 | 0.906 | 0.995 | 0.901 |
//! | torus4x4 hot-spot | 1.000 | 0.741 | 0.977 | 0.745 |
//! | torus4x4 transpose | 1.000 | 0.937 | 0.971 | 0.921 |
//! | mesh8x8 all-to-all 2 KiB | 1.050 | 0.620 | 1.011 | 0.611 |
//! | mesh8x8 hot-spot | 1.000 | 0.665 | 0.986 | 0.671 |
//! | mesh8x8 transpose | 0.998 | 0.864 | 0.911 | 0.870 |
//! | bus8 all-to-all | 1.000 | 0.968 | 1.000 | 0.968 |
//!
//! So the makespans agree within 10% (asserted: 0.88..=1.10), but packet's mean completion
//! is up to 40% lower (asserted: 0.55..=1.02). Why packet differs:
//! - head-of-line blocking: a packet waiting for a busy link holds its FIFO place (and on a
//!   crossbar its output port) while fluid flows never block each other;
//! - discreteness: packets transmit one at a time in FIFO order, so who finishes first
//!   depends on arrival order, whereas max-min sharing finishes equal flows together;
//! - parking-lot unfairness: where FIFOs merge, each input gets about an equal share of
//!   packets, so sources close to a hot spot finish early (lower mean), while max-min gives
//!   every flow through the bottleneck the same rate and they all finish near the end;
//! - fluid flows are bounded by one bottleneck rate along the whole route at once, while
//!   packets pipeline hop by hop and can use idle links early; and under store-and-forward
//!   the flow model adds the pipeline-fill term after the fluid transfer, although under
//!   contention packets fill the pipeline while they wait (packet makespan up to 9% lower).

use sortsim::net::pattern::{all_to_all, hot_spot, run_pattern, transpose, Pattern};
use sortsim::net::{Fidelity, NetworkConfig, Switching, TopologyKind};
use sortsim::units::{Bytes, SimTime};

fn cfg(
    topology: TopologyKind,
    dims: &[u32],
    fidelity: Fidelity,
    switching: Switching,
) -> NetworkConfig {
    NetworkConfig {
        topology,
        dims: dims.to_vec(),
        link_bandwidth: "17MB/s".parse().unwrap(),
        hop_latency: SimTime::from_us(1),
        switching,
        packet_size: Bytes::new(1024),
        fidelity,
        message_gap: SimTime::ZERO,
        node: None,
    }
}

/// (makespan ratio packet/flow, mean-latency ratio packet/flow).
fn ratios(
    topology: TopologyKind,
    dims: &[u32],
    switching: Switching,
    pattern: &Pattern,
) -> (f64, f64) {
    let flow = run_pattern(&cfg(topology, dims, Fidelity::Flow, switching), pattern).unwrap();
    let packet = run_pattern(&cfg(topology, dims, Fidelity::Packet, switching), pattern).unwrap();
    (
        packet.makespan_ps as f64 / flow.makespan_ps as f64,
        packet.mean_latency_ps as f64 / flow.mean_latency_ps as f64,
    )
}

fn cases() -> Vec<(&'static str, TopologyKind, Vec<u32>, Pattern)> {
    let b = Bytes::new(16 * 1024);
    vec![
        (
            "torus4x4 all-to-all",
            TopologyKind::Torus,
            vec![4, 4],
            all_to_all(16, b),
        ),
        (
            "torus4x4 hot-spot",
            TopologyKind::Torus,
            vec![4, 4],
            hot_spot(16, 5, b),
        ),
        (
            "torus4x4 transpose",
            TopologyKind::Torus,
            vec![4, 4],
            transpose(&[4, 4], b),
        ),
        (
            "mesh8x8 all-to-all",
            TopologyKind::Mesh,
            vec![8, 8],
            all_to_all(64, Bytes::new(2048)),
        ),
        (
            "mesh8x8 hot-spot",
            TopologyKind::Mesh,
            vec![8, 8],
            hot_spot(64, 27, b),
        ),
        (
            "mesh8x8 transpose",
            TopologyKind::Mesh,
            vec![8, 8],
            transpose(&[8, 8], b),
        ),
        (
            "bus8 all-to-all",
            TopologyKind::Bus,
            vec![8],
            all_to_all(8, b),
        ),
    ]
}

#[test]
fn flow_and_packet_agree_within_the_measured_tolerance() {
    for switching in [Switching::Wormhole, Switching::StoreAndForward] {
        for (name, topology, dims, pattern) in cases() {
            let (makespan, mean) = ratios(topology, &dims, switching, &pattern);
            println!(
                "{name:<22} {switching:?}: makespan packet/flow {makespan:.4}, mean {mean:.4}"
            );
            assert!(
                (0.88..=1.10).contains(&makespan),
                "{name} {switching:?}: makespan {makespan}"
            );
            assert!(
                (0.55..=1.02).contains(&mean),
                "{name} {switching:?}: mean {mean}"
            );
        }
    }
}
