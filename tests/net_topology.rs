//! Topologies through the `Network` facade: exact routes (as link names), hop counts, link
//! lists and bisection widths, including wrap-around links and direction ties.

use sortsim::net::{Fidelity, Network, NetworkConfig, Switching, TopologyKind};
use sortsim::units::{Bytes, SimTime};

fn net(topology: TopologyKind, dims: &[u32]) -> Network {
    Network::new(&NetworkConfig {
        topology,
        dims: dims.to_vec(),
        link_bandwidth: "17MB/s".parse().unwrap(),
        hop_latency: SimTime::from_us(1),
        switching: Switching::Wormhole,
        packet_size: Bytes::new(1024),
        fidelity: Fidelity::Hops,
        message_gap: SimTime::ZERO,
        node: None,
    })
    .unwrap()
}

/// The route from `src` to `dst` must be exactly `expected` (link names) and its hop count
/// `hops`.
fn check(net: &Network, src: u32, dst: u32, expected: &[&str], hops: u32) {
    let route = net.route(src, dst).expect("routable");
    let names: Vec<String> = route
        .iter()
        .map(|&l| net.links()[l as usize].name(net.nodes()))
        .collect();
    assert_eq!(names, expected, "route {src} -> {dst}");
    assert_eq!(net.hops(src, dst).total(), hops, "hops {src} -> {dst}");
}

fn link_names(net: &Network) -> Vec<String> {
    net.links().iter().map(|l| l.name(net.nodes())).collect()
}

#[test]
fn ring_takes_the_short_way_and_ties_go_clockwise() {
    let ring = net(TopologyKind::Ring, &[8]);
    check(&ring, 0, 3, &["0->1", "1->2", "2->3"], 3);
    check(&ring, 0, 4, &["0->1", "1->2", "2->3", "3->4"], 4);
    check(&ring, 0, 5, &["0->7", "7->6", "6->5"], 3);
    check(&ring, 6, 1, &["6->7", "7->0", "0->1"], 3);
    check(&ring, 5, 5, &[], 0);
    assert_eq!(ring.bisection_width(), 2);
    let small = net(TopologyKind::Ring, &[4]);
    let expected = [
        "0->1", "0->3", "1->2", "1->0", "2->3", "2->1", "3->0", "3->2",
    ];
    assert_eq!(link_names(&small), expected);
    check(&small, 3, 1, &["3->0", "0->1"], 2);
    assert_eq!(net(TopologyKind::Ring, &[1]).link_count(), 0);
}

#[test]
fn pipeline_only_goes_forward() {
    let p = net(TopologyKind::Pipeline, &[4]);
    assert_eq!(link_names(&p), ["0->1", "1->2", "2->3"]);
    check(&p, 1, 3, &["1->2", "2->3"], 2);
    assert!(!p.can_route(3, 1));
    assert!(p.route(3, 1).is_none());
    assert!(p.can_route(2, 2));
    assert_eq!(p.bisection_width(), 1);
}

#[test]
fn torus_routes_lowest_dimension_first_with_wrap_around() {
    // Node id = x + 4y.
    let t = net(TopologyKind::Torus, &[4, 4]);
    assert_eq!(t.link_count(), 64);
    check(&t, 0, 10, &["0->1", "1->2", "2->6", "6->10"], 4);
    check(&t, 0, 3, &["0->3"], 1);
    check(&t, 15, 0, &["15->12", "12->0"], 2);
    check(&t, 5, 7, &["5->6", "6->7"], 2);
    check(&t, 1, 13, &["1->13"], 1);
    assert_eq!(t.bisection_width(), 8); // k^(n-1) * 2
    assert_eq!(net(TopologyKind::Torus, &[4, 4, 4]).bisection_width(), 32);
    assert_eq!(net(TopologyKind::Torus, &[16, 32]).bisection_width(), 32);
    // A dimension of 2 has one link each way per pair; a dimension of 1 none.
    let thin = net(TopologyKind::Torus, &[2, 3, 1]);
    assert_eq!(thin.link_count(), 6 + 12);
    check(&thin, 1, 0, &["1->0"], 1);
    assert_eq!(thin.bisection_width(), 3);
    let one_d = net(TopologyKind::Torus, &[5]);
    check(&one_d, 0, 3, &["0->4", "4->3"], 2);
}

#[test]
fn mesh_routes_x_then_y_then_z_without_wrap() {
    let m = net(TopologyKind::Mesh, &[4, 3]);
    check(&m, 0, 11, &["0->1", "1->2", "2->3", "3->7", "7->11"], 5);
    check(&m, 11, 0, &["11->10", "10->9", "9->8", "8->4", "4->0"], 5);
    check(&m, 3, 0, &["3->2", "2->1", "1->0"], 3);
    assert_eq!(m.link_count(), 2 * (3 * 3 + 4 * 2));
    assert_eq!(m.bisection_width(), 3);
    let cube = net(TopologyKind::Mesh, &[2, 2, 2]);
    check(&cube, 0, 7, &["0->1", "1->3", "3->7"], 3);
    check(&cube, 6, 1, &["6->7", "7->5", "5->1"], 3);
    let delta = net(TopologyKind::Mesh, &[16, 32]);
    assert_eq!(delta.nodes(), 512);
    assert_eq!(delta.link_count(), 2 * (15 * 32 + 16 * 31));
    assert_eq!(delta.hops(0, 511).total(), 15 + 31);
    assert_eq!(delta.bisection_width(), 16);
}

#[test]
fn hypercube_fixes_the_lowest_bit_first() {
    let h = net(TopologyKind::Hypercube, &[8]);
    assert_eq!(h.link_count(), 24);
    check(&h, 5, 2, &["5->4", "4->6", "6->2"], 3);
    check(&h, 0, 4, &["0->4"], 1);
    assert_eq!(h.bisection_width(), 4);
    assert_eq!(net(TopologyKind::Hypercube, &[64]).bisection_width(), 32);
}

#[test]
fn bus_is_one_shared_link_with_broadcast() {
    let b = net(TopologyKind::Bus, &[4]);
    assert_eq!(link_names(&b), ["bus"]);
    check(&b, 1, 3, &["bus"], 1);
    assert!(b.supports_broadcast());
    assert!(!net(TopologyKind::Ring, &[4]).supports_broadcast());
    assert_eq!(b.bisection_width(), 1);
}

#[test]
fn crossbar_uses_both_endpoint_ports_as_one_hop() {
    let x = net(TopologyKind::Crossbar, &[4]);
    assert_eq!(
        link_names(&x),
        ["out0", "out1", "out2", "out3", "in0", "in1", "in2", "in3"]
    );
    check(&x, 1, 3, &["out1", "in3"], 1);
    check(&x, 3, 1, &["out3", "in1"], 1);
    assert_eq!(x.bisection_width(), 2);
}

#[test]
fn invalid_configs_are_rejected_with_what_is_valid() {
    let base = NetworkConfig {
        topology: TopologyKind::Torus,
        dims: vec![4, 4],
        link_bandwidth: "17MB/s".parse().unwrap(),
        hop_latency: SimTime::from_us(1),
        switching: Switching::Wormhole,
        packet_size: Bytes::new(1024),
        fidelity: Fidelity::Flow,
        message_gap: SimTime::ZERO,
        node: None,
    };
    let reject = |cfg: NetworkConfig, needle: &str| {
        let e = Network::new(&cfg).err().expect("rejected").to_string();
        assert!(e.contains(needle), "{e}");
    };
    reject(
        NetworkConfig {
            packet_size: Bytes::ZERO,
            ..base.clone()
        },
        "packet_size must be at least 1 byte",
    );
    reject(
        NetworkConfig {
            dims: vec![],
            ..base.clone()
        },
        "must not be empty",
    );
    reject(
        NetworkConfig {
            dims: vec![4, 0],
            ..base.clone()
        },
        "at least 1",
    );
    reject(
        NetworkConfig {
            topology: TopologyKind::Hypercube,
            dims: vec![6],
            ..base.clone()
        },
        "power of two",
    );
    reject(
        NetworkConfig {
            topology: TopologyKind::Mesh,
            dims: vec![6],
            ..base.clone()
        },
        "2D or 3D",
    );
    reject(
        NetworkConfig {
            topology: TopologyKind::Bus,
            dims: vec![2, 2],
            ..base.clone()
        },
        "exactly one dim",
    );
}

#[test]
fn names_round_trip_and_unknown_names_list_the_valid_ones() {
    for kind in TopologyKind::ALL {
        assert_eq!(TopologyKind::from_name(kind.name()), Ok(kind));
    }
    for f in Fidelity::ALL {
        assert_eq!(Fidelity::from_name(f.name()), Ok(f));
    }
    for s in Switching::ALL {
        assert_eq!(Switching::from_name(s.name()), Ok(s));
    }
    let e = TopologyKind::from_name("butterfly")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("ring, pipeline, torus, mesh, hypercube, bus, crossbar, fat-tree, dragonfly"),
        "{e}"
    );
    let e = Switching::from_name("cut-through").unwrap_err().to_string();
    assert!(e.contains("store-and-forward, wormhole"), "{e}");
}

#[test]
fn a_network_can_move_to_another_thread() {
    fn assert_send<T: Send>(_: &T) {}
    assert_send(&net(TopologyKind::Mesh, &[4, 4]));
}

#[test]
fn small_grids_list_their_links_by_node_then_dimension_then_plus_before_minus() {
    let torus = net(TopologyKind::Torus, &[3, 2]);
    let expected = [
        "0->1", "0->2", "0->3", "1->2", "1->0", "1->4", "2->0", "2->1", "2->5", "3->4", "3->5",
        "3->0", "4->5", "4->3", "4->1", "5->3", "5->4", "5->2",
    ];
    assert_eq!(link_names(&torus), expected);
    let mesh = net(TopologyKind::Mesh, &[2, 2]);
    let expected = [
        "0->1", "0->2", "1->0", "1->3", "2->3", "2->0", "3->2", "3->1",
    ];
    assert_eq!(link_names(&mesh), expected);
    let cube = net(TopologyKind::Hypercube, &[4]);
    let expected = [
        "0->1", "0->2", "1->0", "1->3", "2->3", "2->0", "3->2", "3->1",
    ];
    assert_eq!(link_names(&cube), expected);
}

/// Every route on meshes and tori, against dimension-order routing worked out one hop at a
/// time from coordinates: correct each dimension in turn, lowest first, by the shorter way
/// round (a torus; ties go `+`) or straight (a mesh), each hop the link from the node reached
/// so far to its neighbour.
#[test]
fn grid_routes_follow_dimension_order_hop_by_hop() {
    for (kind, dims) in [
        (TopologyKind::Mesh, vec![4, 3, 2]),
        (TopologyKind::Mesh, vec![16, 32]),
        (TopologyKind::Torus, vec![5, 4, 3]),
        (TopologyKind::Torus, vec![2, 6]),
        (TopologyKind::Torus, vec![7]),
    ] {
        let n = net(kind, &dims);
        let coords = |mut node: u32| -> Vec<u32> {
            dims.iter()
                .map(|&k| {
                    let c = node % k;
                    node /= k;
                    c
                })
                .collect()
        };
        let node_of = |c: &[u32]| -> u32 {
            c.iter()
                .zip(&dims)
                .rev()
                .fold(0, |acc, (&x, &k)| acc * k + x)
        };
        for src in 0..n.nodes() {
            for dst in 0..n.nodes() {
                let mut at = coords(src);
                let target = coords(dst);
                let mut expected = Vec::new();
                for d in 0..dims.len() {
                    let k = dims[d];
                    while at[d] != target[d] {
                        let up = (target[d] + k - at[d]) % k;
                        let plus = match kind {
                            TopologyKind::Torus => up <= k - up,
                            _ => at[d] < target[d],
                        };
                        let from = node_of(&at);
                        at[d] = if plus {
                            (at[d] + 1) % k
                        } else {
                            (at[d] + k - 1) % k
                        };
                        expected.push(format!("{from}->{}", node_of(&at)));
                    }
                }
                let route: Vec<String> = n
                    .route(src, dst)
                    .expect("routable")
                    .iter()
                    .map(|&l| n.links()[l as usize].name(n.nodes()))
                    .collect();
                assert_eq!(route, expected, "{kind:?} {dims:?}: {src} -> {dst}");
            }
        }
    }
}

#[test]
fn fat_tree_goes_up_by_destination_mod_k_and_down_to_the_destination() {
    // Two levels: 4 leaves of 4 hosts, 2 spines (s4, s5), one cable per pair.
    let n = net(TopologyKind::FatTree, &[4, 4, 1, 2, 1, 1]);
    assert_eq!(n.nodes(), 16);
    check(&n, 0, 3, &["0->s0", "s0->3"], 2);
    // Host 9 is odd: spine s5; host 8 even: spine s4.
    check(&n, 5, 9, &["5->s1", "s1->s5", "s5->s2", "s2->9"], 4);
    check(&n, 5, 8, &["5->s1", "s1->s4", "s4->s2", "s2->8"], 4);
    assert_eq!(n.bisection_width(), 4);
}

#[test]
fn dragonfly_routes_minimally_through_the_one_global_link() {
    // 3 groups of 1 chassis of 3 routers (s0..s8), 2 hosts each.
    let n = net(TopologyKind::Dragonfly, &[3, 1, 3, 2]);
    assert_eq!(n.nodes(), 18);
    check(
        &n,
        0,
        17,
        &["0->s0", "s0->s2", "s2->s6", "s6->s8", "s8->17"],
        5,
    );
    // The global link from group 1 to group 0 sits on router 0 of group 1 (s3): no green hop
    // at the source; then router 1 of group 0 (s1) is where it lands.
    check(&n, 6, 2, &["6->s3", "s3->s1", "s1->2"], 3);
    assert_eq!(n.bisection_width(), 2);
    // Two chassis: green within the chassis the message is in, then black; the global link
    // from group 0 to group 1 sits on router 1 of chassis 0 (s1).
    let n = net(TopologyKind::Dragonfly, &[2, 2, 2, 1]);
    check(&n, 3, 4, &["3->s3", "s3->s1", "s1->s4", "s4->4"], 4);
    check(
        &n,
        2,
        5,
        &["2->s2", "s2->s3", "s3->s1", "s1->s4", "s4->s5", "s5->5"],
        6,
    );
    check(&n, 2, 1, &["2->s2", "s2->s3", "s3->s1", "s1->1"], 4);
}
