//! The per-message gap at each node's network interface (`network.message_gap`): a lone
//! message arrives a gap after the contention-free formula at every level, a node's messages
//! leave one at a time (a stream runs at `bytes / (gap + bytes / rate)`), nodes' interfaces
//! do not wait for each other, and a message to self pays nothing.

use sortsim::net::pattern::{drive, ParsedMessage};
use sortsim::net::{Dest, Fidelity, Network, NetworkConfig, Switching, TopologyKind};
use sortsim::units::{Bandwidth, Bytes, SimTime};

const GAP: SimTime = SimTime::from_ps(168_660_000);

fn cfg(fidelity: Fidelity, switching: Switching, gap: SimTime) -> NetworkConfig {
    NetworkConfig {
        topology: TopologyKind::Mesh,
        dims: vec![4, 4],
        link_bandwidth: "17MB/s".parse().unwrap(),
        hop_latency: SimTime::from_ns(80),
        switching,
        packet_size: Bytes::new(1024),
        fidelity,
        message_gap: gap,
        node: None,
    }
}

fn msg(src: u32, dst: u32, bytes: u64, start: SimTime) -> ParsedMessage {
    ParsedMessage {
        src,
        dest: Dest::Node(dst),
        bytes: Bytes::new(bytes),
        start,
    }
}

fn run(cfg: &NetworkConfig, messages: &[ParsedMessage]) -> Vec<SimTime> {
    drive(&mut Network::new(cfg).unwrap(), messages)
}

fn every_level() -> impl Iterator<Item = (Fidelity, Switching)> {
    Fidelity::ALL.into_iter().flat_map(|f| {
        [Switching::Wormhole, Switching::StoreAndForward]
            .into_iter()
            .map(move |s| (f, s))
    })
}

#[test]
fn a_lone_message_arrives_one_gap_after_the_formula() {
    for (fidelity, switching) in every_level() {
        let start = SimTime::from_ps(1_234_567);
        for bytes in [0, 1, 1023, 4096, 65_536] {
            let m = [msg(0, 15, bytes, start)];
            let without = run(&cfg(fidelity, switching, SimTime::ZERO), &m)[0];
            let with = run(&cfg(fidelity, switching, GAP), &m)[0];
            assert_eq!(with - without, GAP, "{fidelity} {switching} {bytes} B");
        }
    }
}

/// Paper 002's sentence in numbers: full 4 KB buffers sent back to back to a neighbour over
/// 17 MB/s links arrive 409.6 us apart with a 168.66 us gap, 10 MB/s.
#[test]
fn a_stream_from_one_node_runs_at_gap_plus_serialization_per_message() {
    let rate: Bandwidth = "17MB/s".parse().unwrap();
    let bytes = Bytes::new(4096);
    let period = GAP + rate.transfer_time(bytes);
    let stream: Vec<_> = (0..32).map(|_| msg(0, 1, 4096, SimTime::ZERO)).collect();
    for (fidelity, switching) in every_level() {
        let at = run(&cfg(fidelity, switching, GAP), &stream);
        let lone = run(&cfg(fidelity, switching, GAP), &stream[..1])[0];
        for (i, t) in at.iter().enumerate() {
            assert_eq!(
                *t,
                lone + period.times(i as u64),
                "{fidelity} {switching} #{i}"
            );
        }
        let mb_per_s = 4096.0 / period.as_secs_f64() / 1e6;
        assert!(
            (mb_per_s - 10.0).abs() < 0.01,
            "{mb_per_s} MB/s, paper 002's 'maximum rate for 4-Kbyte messages' is 10"
        );
    }
}

#[test]
fn a_message_sent_after_the_interface_is_free_waits_only_its_gap() {
    let rate: Bandwidth = "17MB/s".parse().unwrap();
    let free = GAP + rate.transfer_time(Bytes::new(4096));
    for (fidelity, switching) in every_level() {
        let c = cfg(fidelity, switching, GAP);
        let late = free + SimTime::from_us(7);
        let at = run(&c, &[msg(0, 1, 4096, SimTime::ZERO), msg(0, 1, 100, late)]);
        let alone = run(&c, &[msg(0, 1, 100, late)])[0];
        assert_eq!(at[1], alone, "{fidelity} {switching}");
    }
}

#[test]
fn interfaces_of_different_nodes_do_not_wait_for_each_other() {
    // Node 0 to 1 and node 5 to 6 share no link and no interface.
    for (fidelity, switching) in every_level() {
        let c = cfg(fidelity, switching, GAP);
        let a = [msg(0, 1, 4096, SimTime::ZERO)];
        let b = [msg(5, 6, 4096, SimTime::from_us(3))];
        let both = run(&c, &[a[0], b[0]]);
        assert_eq!(
            both,
            [run(&c, &a)[0], run(&c, &b)[0]],
            "{fidelity} {switching}"
        );
    }
}

#[test]
fn a_message_to_itself_pays_no_gap() {
    for (fidelity, switching) in every_level() {
        let start = SimTime::from_us(5);
        let at = run(&cfg(fidelity, switching, GAP), &[msg(3, 3, 4096, start)]);
        assert_eq!(at, [start], "{fidelity} {switching}");
    }
}

/// A message with no route is the caller's bug whether or not it waits for an interface: the
/// panic names what would be valid, as `Network::check_message` does.
#[test]
#[should_panic(expected = "a pipeline only sends to higher node ids")]
fn a_message_with_no_route_is_refused_at_the_interface_too() {
    let pipeline = NetworkConfig {
        topology: TopologyKind::Pipeline,
        dims: vec![4],
        ..cfg(Fidelity::Hops, Switching::Wormhole, GAP)
    };
    Network::new(&pipeline)
        .unwrap()
        .inject(SimTime::ZERO, 1, 3, Dest::Node(0), Bytes::new(64));
}
