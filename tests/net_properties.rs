//! Property test: thousands of messages starting within a few picoseconds of each other on
//! small topologies, at the flow and packet levels under both switchings. Every message is
//! delivered exactly once (`drive` panics on a duplicate or a missing delivery, and on a
//! network that stops making progress, i.e. a stuck message), never earlier than the
//! contention-free formula, and every link carries exactly the bytes of the routes that
//! cross it.

use proptest::prelude::*;
use sortsim::net::pattern::{drive, ParsedMessage};
use sortsim::net::topology::Placement;
use sortsim::net::{
    Dest, Fidelity, Network, NetworkConfig, NodeConfig, NodeLinks, Switching, TopologyKind,
};
use sortsim::units::{Bytes, SimTime};

const SHAPES: [(TopologyKind, &[u32]); 8] = [
    (TopologyKind::Ring, &[6]),
    (TopologyKind::Torus, &[3, 3]),
    (TopologyKind::Mesh, &[3, 2]),
    (TopologyKind::Hypercube, &[8]),
    (TopologyKind::Bus, &[4]),
    (TopologyKind::Crossbar, &[4]),
    (TopologyKind::FatTree, &[3, 2, 1, 2, 2, 1]),
    (TopologyKind::Dragonfly, &[2, 2, 2, 1]),
];

fn config(shape: usize, packet: bool, wormhole: bool) -> NetworkConfig {
    let (topology, dims) = SHAPES[shape];
    NetworkConfig {
        topology,
        dims: dims.to_vec(),
        link_bandwidth: "17MB/s".parse().unwrap(),
        hop_latency: SimTime::from_ns(700),
        switching: if wormhole {
            Switching::Wormhole
        } else {
            Switching::StoreAndForward
        },
        // Large packets keep the debug-build packet count reasonable.
        packet_size: Bytes::new(16 * 1024),
        fidelity: if packet {
            Fidelity::Packet
        } else {
            Fidelity::Flow
        },
        message_gap: SimTime::ZERO,
        node: None,
    }
}

fn check(cfg: &NetworkConfig, raw: &[(u32, u32, u64, u64)]) {
    let mut net = Network::new(cfg).unwrap();
    let n = net.nodes();
    let messages: Vec<ParsedMessage> = raw
        .iter()
        .map(|&(s, d, bytes, start)| ParsedMessage {
            src: s % n,
            dest: Dest::Node(d % n),
            bytes: Bytes::new(bytes),
            start: SimTime::from_ps(start),
        })
        .collect();
    let done = drive(&mut net, &messages);
    let timing = net.timing();
    let mut expected = vec![0u64; net.link_count()];
    for (m, &at) in messages.iter().zip(&done) {
        let Dest::Node(d) = m.dest else {
            unreachable!()
        };
        let earliest = if m.src == d {
            m.start
        } else {
            m.start + cfg.message_gap + timing.contention_free(net.hops(m.src, d), m.bytes)
        };
        assert!(
            at >= earliest,
            "{m:?} delivered at {at}, formula says {earliest}"
        );
        for l in net.route(m.src, d).unwrap() {
            expected[l as usize] += m.bytes.get();
        }
    }
    let carried: Vec<u64> = net.link_stats().iter().map(|s| s.bytes.get()).collect();
    assert_eq!(carried, expected);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 16, ..ProptestConfig::default() })]
    #[test]
    fn many_nearly_simultaneous_messages_are_all_delivered_never_early(
        shape in 0..SHAPES.len(),
        packet in any::<bool>(),
        wormhole in any::<bool>(),
        raw in prop::collection::vec((0u32..64, 0u32..64, 1u64..1_000_000, 0u64..6), 1000..2500),
    ) {
        check(&config(shape, packet, wormhole), &raw);
    }

    /// With a gap of 1 ns to 5 ms a message at each node's interface, at flow and packet:
    /// every message is delivered, never before its send plus the gap plus the formula, and
    /// each link carries exactly its routes' bytes.
    #[test]
    fn messages_waiting_at_their_interfaces_are_all_delivered_never_early(
        shape in 0..SHAPES.len(),
        packet in any::<bool>(),
        wormhole in any::<bool>(),
        gap_ns in 1u64..5_000_000,
        raw in prop::collection::vec((0u32..64, 0u32..64, 1u64..1_000_000, 0u64..6), 200..800),
    ) {
        let cfg = NetworkConfig {
            message_gap: SimTime::from_ns(gap_ns),
            ..config(shape, packet, wormhole)
        };
        check(&cfg, &raw);
    }

    /// Nodes of 3 processors and 2 NICs on a 10x faster switch, at flow (packet takes one
    /// kind of link), the NICs on a ring, a fat-tree or a dragonfly, processors placed in
    /// blocks or cyclically.
    #[test]
    fn messages_between_nodes_of_several_processors_are_all_delivered_never_early(
        shape in prop_oneof![Just(0usize), Just(6), Just(7)],
        wormhole in any::<bool>(),
        cyclic in any::<bool>(),
        raw in prop::collection::vec((0u32..64, 0u32..64, 1u64..1_000_000, 0u64..6), 1000..2500),
    ) {
        let cfg = NetworkConfig {
            node: Some(NodeConfig {
                processors: 3,
                nics: 2,
                links: NodeLinks {
                    bandwidth: "170MB/s".parse().unwrap(),
                    hop_latency: SimTime::from_ns(100),
                },
                placement: if cyclic { Placement::Cyclic } else { Placement::Block },
            }),
            ..config(shape, false, wormhole)
        };
        check(&cfg, &raw);
    }
}
