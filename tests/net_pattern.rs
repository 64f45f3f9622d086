//! The pattern driver behind `sortsim netsim`: JSON input, validation errors that name the
//! field and the valid range, deterministic reports, and the pattern generators.

use sortsim::net::fidelity::{fidelity_table, format_table};
use sortsim::net::pattern::{
    all_to_all, hot_spot, random_pairs, run_pattern, transpose, Pattern, PatternMessage,
};
use sortsim::net::{Fidelity, NetworkConfig, Switching, TopologyKind};
use sortsim::units::{Bytes, SimTime};

fn cfg(topology: TopologyKind, dims: &[u32], fidelity: Fidelity) -> NetworkConfig {
    NetworkConfig {
        topology,
        dims: dims.to_vec(),
        link_bandwidth: "20Mbit/s".parse().unwrap(),
        hop_latency: SimTime::from_us(2),
        switching: Switching::StoreAndForward,
        packet_size: Bytes::new(512),
        fidelity,
        message_gap: SimTime::ZERO,
        node: None,
    }
}

fn pattern(json: &str) -> Pattern {
    serde_json::from_str(json).unwrap()
}

fn error(cfg: &NetworkConfig, json: &str) -> String {
    run_pattern(cfg, &pattern(json)).unwrap_err().to_string()
}

#[test]
fn reads_a_pattern_file_and_reports_in_input_order() {
    let p = pattern(
        r#"{"messages": [
            {"src": 0, "dst": 3, "bytes": "4KiB", "start": "10us"},
            {"src": 1, "dst": 2, "bytes": "100B"}
        ]}"#,
    );
    let r = run_pattern(&cfg(TopologyKind::Ring, &[4], Fidelity::Flow), &p).unwrap();
    assert_eq!(r.messages.len(), 2);
    assert_eq!(
        (r.messages[0].src, r.messages[0].dst, r.messages[0].bytes),
        (0, Some(3), 4096)
    );
    assert_eq!(r.messages[0].start_ps, 10_000_000);
    // 0 -> 3 on a ring of 4 is one hop counter-clockwise: 2 us + 4096 * 8 / 20e6 s.
    assert_eq!(
        r.messages[0].completion_ps,
        10_000_000 + 2_000_000 + 1_638_400_000
    );
    assert_eq!(r.messages[1].start_ps, 0);
    assert_eq!(r.makespan_ps, r.messages[0].completion_ps);
    let json = serde_json::to_string(&r).unwrap();
    for key in [
        "\"completion_s\"",
        "\"busy_s\"",
        "\"start_ps\"",
        "\"peak_queue\"",
        "\"makespan_ps\"",
    ] {
        assert!(json.contains(key), "{key} missing from {json}");
    }
}

#[test]
fn unknown_fields_are_rejected() {
    let e = serde_json::from_str::<Pattern>(
        r#"{"messages": [{"src": 0, "dst": 1, "bytes": "1B", "size": 3}]}"#,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("unknown field `size`"), "{e}");
}

#[test]
fn invalid_messages_name_their_field_and_the_valid_range() {
    let torus = cfg(TopologyKind::Torus, &[4, 4], Fidelity::Flow);
    let e = error(
        &torus,
        r#"{"messages": [{"src": 0, "dst": 1, "bytes": "1B"}, {"src": 0, "dst": 16, "bytes": "1B"}]}"#,
    );
    assert_eq!(
        e,
        "messages[1].dst: node 16 does not exist; valid nodes are 0..=15"
    );
    let e = error(
        &torus,
        r#"{"messages": [{"src": 99, "dst": 1, "bytes": "1B"}]}"#,
    );
    assert!(e.starts_with("messages[0].src: node 99"), "{e}");
    let e = error(
        &torus,
        r#"{"messages": [{"src": 0, "broadcast": true, "bytes": "1B"}]}"#,
    );
    assert!(
        e.starts_with("messages[0].broadcast: broadcast needs a bus"),
        "{e}"
    );
    let e = error(&torus, r#"{"messages": [{"src": 0, "bytes": "1B"}]}"#);
    assert!(e.starts_with("messages[0].dst: missing"), "{e}");
    let e = error(
        &torus,
        r#"{"messages": [{"src": 0, "dst": 2, "bytes": "12 parsecs"}]}"#,
    );
    assert!(
        e.starts_with("messages[0].bytes:") && e.contains("KiB"),
        "{e}"
    );
    let e = error(
        &torus,
        r#"{"messages": [{"src": 0, "dst": 2, "bytes": "1B", "start": "-3us"}]}"#,
    );
    assert!(e.starts_with("messages[0].start:"), "{e}");
    let pipe = cfg(TopologyKind::Pipeline, &[4], Fidelity::Packet);
    let e = error(
        &pipe,
        r#"{"messages": [{"src": 0, "dst": 1, "bytes": "1B"}, {"src": 0, "dst": 3, "bytes": "1B"}, {"src": 0, "dst": 3, "bytes": "1B"}, {"src": 3, "dst": 1, "bytes": "1B"}]}"#,
    );
    assert_eq!(
        e,
        "messages[3].dst: no route from node 3 to node 1: a pipeline only sends to nodes 3..=3"
    );
}

#[test]
fn broadcast_on_a_bus_reaches_everyone_in_one_transmission() {
    let bus = cfg(TopologyKind::Bus, &[5], Fidelity::Packet);
    let p = Pattern::new(vec![PatternMessage::broadcast(
        1,
        Bytes::new(2000),
        SimTime::ZERO,
    )]);
    let r = run_pattern(&bus, &p).unwrap();
    assert_eq!(r.messages[0].dst, None);
    assert_eq!((r.links[0].messages, r.links[0].bytes), (1, 2000));
}

#[test]
fn the_same_pattern_gives_byte_identical_reports() {
    for fidelity in Fidelity::ALL {
        let c = cfg(TopologyKind::Mesh, &[4, 4], fidelity);
        let p = random_pairs(16, 5, Bytes::new(3000), 7);
        let a = serde_json::to_string(&run_pattern(&c, &p).unwrap()).unwrap();
        let b = serde_json::to_string(&run_pattern(&c, &p).unwrap()).unwrap();
        assert_eq!(a, b, "{fidelity:?}");
    }
}

#[test]
fn generators_make_the_documented_patterns() {
    assert_eq!(all_to_all(5, Bytes::new(1)).messages.len(), 20);
    let hs = hot_spot(6, 2, Bytes::new(1));
    assert_eq!(hs.messages.len(), 5);
    assert!(hs.messages.iter().all(|m| m.dst == Some(2) && m.src != 2));
    let t = transpose(&[4, 4], Bytes::new(1));
    assert_eq!(t.messages.len(), 12);
    assert!(t
        .messages
        .contains(&PatternMessage::new(1, 4, Bytes::new(1), SimTime::ZERO)));
    let t = transpose(&[2, 3], Bytes::new(1));
    assert!(t
        .messages
        .contains(&PatternMessage::new(1, 3, Bytes::new(1), SimTime::ZERO)));
    let r = random_pairs(10, 4, Bytes::new(1), 42);
    assert_eq!(r, random_pairs(10, 4, Bytes::new(1), 42));
    assert_ne!(r, random_pairs(10, 4, Bytes::new(1), 43));
    assert_eq!(r.messages.len(), 40);
    for src in 0..10 {
        let mut dsts: Vec<u32> = r
            .messages
            .iter()
            .filter(|m| m.src == src)
            .map(|m| m.dst.unwrap())
            .collect();
        dsts.sort();
        dsts.dedup();
        assert_eq!(dsts.len(), 4, "distinct destinations for {src}");
        assert!(!dsts.contains(&src));
    }
}

#[test]
fn the_fidelity_table_has_one_row_per_level_and_contention_only_slows() {
    let c = cfg(TopologyKind::Torus, &[4, 4], Fidelity::Ideal);
    let rows = fidelity_table(&c, &all_to_all(16, Bytes::new(4096))).unwrap();
    let levels: Vec<Fidelity> = rows.iter().map(|r| r.fidelity).collect();
    assert_eq!(levels, Fidelity::ALL);
    // Ideal <= hops (switching term) <= flow (contention); packet measured elsewhere.
    assert!(rows[0].makespan <= rows[1].makespan);
    assert!(rows[1].makespan < rows[2].makespan);
    assert!(rows.iter().all(|r| r.messages == 240));
    let text = format_table(&rows);
    assert_eq!(text.lines().count(), 5, "{text}");
}

#[test]
fn bit_complement_and_random_permutations_send_once_and_receive_once() {
    use sortsim::net::pattern::{bit_complement, random_permutations};
    use sortsim::units::{Bytes, SimTime};
    let c = bit_complement(8, Bytes::new(64));
    let pairs: Vec<(u32, Option<u32>)> = c.messages.iter().map(|m| (m.src, m.dst)).collect();
    assert_eq!(pairs, (0..8).map(|s| (s, Some(7 - s))).collect::<Vec<_>>());
    // An odd count leaves the middle node out.
    assert_eq!(bit_complement(5, Bytes::new(64)).messages.len(), 4);

    let sizes = [Bytes::new(4096), Bytes::new(65536)];
    let p = random_permutations(16, 20, &sizes, SimTime::from_us(100), 9);
    assert_eq!(p.messages.len(), 16 * 20);
    for round in p.messages.chunks(16) {
        let mut received = [0; 16];
        for (src, m) in round.iter().enumerate() {
            assert_eq!(m.src, src as u32);
            let dst = m.dst.unwrap();
            assert_ne!(dst, m.src, "no fixed points");
            received[dst as usize] += 1;
        }
        assert!(received.iter().all(|&r| r == 1), "{received:?}");
    }
    assert_eq!(
        p,
        random_permutations(16, 20, &sizes, SimTime::from_us(100), 9)
    );
}
