//! Interconnection networks: topologies, routing and the transport models behind
//! `network.fidelity`.
//!
//! Owns where a message goes (the exact list of links) and when it arrives. The engine hands
//! a message in with [`Network::inject`] and asks for deliveries with
//! [`Network::next_event_time`] / [`Network::advance`]; this module is a plain discrete-event
//! state machine and knows nothing about async programs, cpus or payloads.
//!
//! Layout: `topology/` says which links a message crosses (one file per topology behind the
//! [`topology::Topology`] trait); `transport/` says when it arrives (one file per fidelity
//! level); `timing.rs` holds the one contention-free formula every level agrees with; `routes.rs`
//! keeps each (source, destination) pair's route once computed;
//! `pattern.rs` drives a network from a list of messages without the engine.
//!
//! Contract with the caller (the engine, or [`pattern::run_pattern`]):
//! 1. `inject(now, ..)` is called at the message's start instant, never for an instant earlier
//!    than the last `advance`.
//! 2. After every `inject` or `advance`, the caller re-reads `next_event_time()` and calls
//!    `advance(t)` at that `t` before injecting anything later than `t`.
//! 3. `advance(now)` processes every internal event at or before `now`; afterwards
//!    `next_event_time()` is either `None` or strictly later than `now` (until the next
//!    `inject`: the flow level asks for an `advance` at the injection instant, so that
//!    messages starting together share one rate computation; advancing between them gives
//!    the same times, only slower).
//!
//! Must never iterate a hash map on a path that affects timing or output, and never use
//! floating point for a time.

pub mod fidelity;
mod interface;
mod occupancy;
pub mod pattern;
mod routes;
pub mod timing;
pub mod topology;
pub mod transport;

use crate::units::{Bandwidth, Bytes, SimTime};
pub use timing::NodeLinks;
use timing::{Hops, Timing};
use topology::{LineTally, Link, Topology};
use transport::Transport;

/// A simulated node (processor) index, `0..nodes`.
pub type NodeId = u32;

/// A message's identity, assigned by whoever injects it (the engine uses its sequence).
pub type MsgId = u64;

/// Index of a link in [`Network::link_stats`] and in routes.
pub type LinkId = u32;

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum TopologyKind {
    Ring,
    Pipeline,
    Torus,
    Mesh,
    Hypercube,
    Bus,
    Crossbar,
    FatTree,
    Dragonfly,
}

impl TopologyKind {
    pub const ALL: [TopologyKind; 9] = [
        TopologyKind::Ring,
        TopologyKind::Pipeline,
        TopologyKind::Torus,
        TopologyKind::Mesh,
        TopologyKind::Hypercube,
        TopologyKind::Bus,
        TopologyKind::Crossbar,
        TopologyKind::FatTree,
        TopologyKind::Dragonfly,
    ];
    pub fn name(self) -> &'static str {
        match self {
            TopologyKind::Ring => "ring",
            TopologyKind::Pipeline => "pipeline",
            TopologyKind::Torus => "torus",
            TopologyKind::Mesh => "mesh",
            TopologyKind::Hypercube => "hypercube",
            TopologyKind::Bus => "bus",
            TopologyKind::Crossbar => "crossbar",
            TopologyKind::FatTree => "fat-tree",
            TopologyKind::Dragonfly => "dragonfly",
        }
    }
    /// The kind called `name` in specs (`ring`, `torus`, ...), or an error listing them.
    pub fn from_name(name: &str) -> Result<TopologyKind, NetError> {
        by_name(&Self::ALL, name, Self::name, "topology")
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Switching {
    StoreAndForward,
    Wormhole,
}

impl Switching {
    pub const ALL: [Switching; 2] = [Switching::StoreAndForward, Switching::Wormhole];
    pub fn name(self) -> &'static str {
        match self {
            Switching::StoreAndForward => "store-and-forward",
            Switching::Wormhole => "wormhole",
        }
    }
    /// `store-and-forward` or `wormhole`, or an error listing them.
    pub fn from_name(name: &str) -> Result<Switching, NetError> {
        by_name(&Self::ALL, name, Self::name, "switching")
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Fidelity {
    Ideal,
    Hops,
    Flow,
    Packet,
}

impl Fidelity {
    pub const ALL: [Fidelity; 4] = [
        Fidelity::Ideal,
        Fidelity::Hops,
        Fidelity::Flow,
        Fidelity::Packet,
    ];
    pub fn name(self) -> &'static str {
        match self {
            Fidelity::Ideal => "ideal",
            Fidelity::Hops => "hops",
            Fidelity::Flow => "flow",
            Fidelity::Packet => "packet",
        }
    }
    /// `ideal`, `hops`, `flow` or `packet`, or an error listing them.
    pub fn from_name(name: &str) -> Result<Fidelity, NetError> {
        by_name(&Self::ALL, name, Self::name, "fidelity")
    }
}

/// A network's extent per dimension as people write it: `16x32`.
pub fn dims_text(dims: &[u32]) -> String {
    dims.iter()
        .map(u32::to_string)
        .collect::<Vec<_>>()
        .join("x")
}

/// A network's shape as people write it: `16x32` for a grid, the levels of a fat-tree, the
/// parts of a dragonfly (`dims` as [`NetworkConfig::dims`] holds them).
pub fn shape_text(topology: TopologyKind, dims: &[u32]) -> String {
    let list = |d: &[u32]| d.iter().map(u32::to_string).collect::<Vec<_>>().join(",");
    match (topology, dims) {
        (TopologyKind::FatTree, _) => {
            let h = dims.len() / 3;
            format!(
                "down [{}] up [{}] parallel [{}]",
                list(&dims[..h]),
                list(&dims[h..2 * h]),
                list(&dims[2 * h..])
            )
        }
        (TopologyKind::Dragonfly, &[g, c, r, n]) => {
            format!("{g} groups x {c} chassis x {r} routers x {n} hosts")
        }
        (TopologyKind::Dragonfly, &[g, c, r, n, _]) => {
            format!("{g} groups x {c} chassis x {r} routers x {n} hosts, Valiant routing")
        }
        _ => dims_text(dims),
    }
}

/// Users read these enums by the names specs spell them with (`mesh`, `wormhole`, `flow`),
/// never by their Rust names.
macro_rules! display_by_name {
    ($($kind:ty),*) => {$(
        impl std::fmt::Display for $kind {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str(self.name())
            }
        }
    )*};
}
display_by_name!(TopologyKind, Switching, Fidelity);

/// The variant whose `name` is `wanted` (names come from each enum's exhaustive `name`).
fn by_name<T: Copy>(
    all: &[T],
    wanted: &str,
    name: fn(T) -> &'static str,
    what: &str,
) -> Result<T, NetError> {
    all.iter()
        .copied()
        .find(|&v| name(v) == wanted)
        .ok_or_else(|| {
            let valid: Vec<&str> = all.iter().map(|&v| name(v)).collect();
            NetError::Config(format!(
                "unknown {what} '{wanted}'; valid: {}",
                valid.join(", ")
            ))
        })
}

/// A network description (built by `spec`; validated by [`Network::new`]).
#[derive(Clone, Debug)]
pub struct NetworkConfig {
    pub topology: TopologyKind,
    /// Extent per dimension (torus, mesh); `[nodes]` for the one-dimensional topologies and
    /// the hypercube; a fat-tree's `down ++ up ++ parallel` (one entry each per level,
    /// SimGrid's parameters); a dragonfly's `[groups, chassis, routers, nodes per router]`,
    /// with a fifth entry 1 for Valiant routing.
    pub dims: Vec<u32>,
    pub link_bandwidth: Bandwidth,
    pub hop_latency: SimTime,
    pub switching: Switching,
    pub packet_size: Bytes,
    pub fidelity: Fidelity,
    /// Time a node's network interface spends on each message before its first byte leaves,
    /// sending one message at a time (LogGP's gap; `interface.rs`). Zero: a message leaves
    /// at its send.
    pub message_gap: SimTime,
    /// Nodes of several processors: each node's processors and NICs on a switch of their
    /// own, the NICs being the hosts of the topology above (`None`: one processor a host).
    pub node: Option<NodeConfig>,
}

/// A node of several processors (GPUs, cores): `processors` on one switch with `nics`
/// network interfaces, every link inside the node at `links`' rate and latency.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NodeConfig {
    pub processors: u32,
    pub nics: u32,
    pub links: NodeLinks,
    /// Which node each processor sits on.
    pub placement: topology::Placement,
}

/// Where a message goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dest {
    Node(NodeId),
    /// Every other node, in one transmission (bus only).
    Broadcast,
}

/// A message that has arrived.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Delivered {
    pub msg: MsgId,
    pub at: SimTime,
}

/// Per-link traffic over a run.
///
/// `busy` depends on the level: ideal/hops add the serialization time of every message that
/// crosses the link; flow counts the time with at least one active flow; packet counts the
/// time the link is transmitting (held by a packet). `peak_queue`: 0 for ideal/hops, the
/// largest number of concurrent flows for flow, the longest FIFO of waiting packets for
/// packet (a message's own packets waiting behind each other count).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct LinkStats {
    pub from: NodeId,
    pub to: NodeId,
    /// Human name: `3->4` for a wire (`3->s0` to a switch), `bus`, `out3` / `in3` for crossbar
    /// ports.
    pub name: String,
    pub bytes: Bytes,
    pub messages: u64,
    pub busy: SimTime,
    pub peak_queue: u32,
}

/// Why a network or a message was rejected. Every message says what would be valid.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum NetError {
    /// The configuration cannot describe a network.
    #[error("invalid network: {0}")]
    Config(String),
    /// A message cannot be sent on this network.
    #[error("{0}")]
    Message(String),
    /// A pattern file field is malformed (bad unit string, ...).
    #[error("{0}")]
    Pattern(String),
}

/// The network a machine owns: a topology plus the transport model its fidelity selects.
///
/// ```
/// use sortsim::net::{Dest, Fidelity, Network, NetworkConfig, Switching, TopologyKind};
/// use sortsim::units::{Bytes, SimTime};
///
/// let cfg = NetworkConfig {
///     topology: TopologyKind::Mesh,
///     dims: vec![4, 4],
///     link_bandwidth: "1MB/s".parse().unwrap(),
///     hop_latency: SimTime::from_us(1),
///     switching: Switching::Wormhole,
///     packet_size: Bytes::new(1024),
///     fidelity: Fidelity::Flow,
///     message_gap: SimTime::ZERO,
///     node: None,
/// };
/// let mut net = Network::new(&cfg).unwrap();
/// // Two messages from 0 and 4 to 8 at once share the link 4->8 ...
/// assert_eq!(net.inject(SimTime::ZERO, 1, 0, Dest::Node(8), Bytes::new(1000)), None);
/// assert_eq!(net.inject(SimTime::ZERO, 2, 4, Dest::Node(8), Bytes::new(1000)), None);
/// let mut delivered = Vec::new();
/// while let Some(t) = net.next_event_time() {
///     net.advance(t, &mut delivered);
/// }
/// // ... so each moves at half the link rate: 2 ms of transfer plus 2 and 1 hops of 1 us.
/// let at: Vec<u64> = delivered.iter().map(|d| d.at.ps()).collect();
/// assert_eq!(at, [2_001_000_000, 2_002_000_000]);
/// ```
pub struct Network {
    topology: Box<dyn Topology>,
    transport: Box<dyn Transport>,
    fidelity: Fidelity,
    timing: Timing,
    /// Per link: (bytes, messages) that crossed it, side by side (an injection updates both
    /// for every link of its route).
    carried: Vec<(Bytes, u64)>,
    /// Where a level times messages without their routes (`ideal` and `hops` on links of one
    /// rate) on a topology whose routes run along lines (the mesh and the torus): the bytes,
    /// messages and busy time routes carried, tallied by lines, and the level. A message
    /// then costs a few additions a dimension instead of a walk of its route and three
    /// passes over it; [`Network::link_stats`] sums the lines per link.
    lines: Option<(LineTally, transport::RouteFree)>,
    routes: routes::Routes,
    /// Per-message link occupancy, when a timeline is recorded.
    occupancy: Option<occupancy::Occupancy>,
    /// The nodes' interfaces, when they cost a gap per message.
    interfaces: Option<interface::Interfaces>,
    /// Whether the level knows a message's arrival from the instant it leaves alone (no
    /// contention) and every message takes time to arrive (so no arrival falls at its own
    /// leaving): then, unless a timeline records the links' occupancy from each message's
    /// start, a message held by its interface is started as it is sent
    /// ([`Network::arrival_known_at_send`]).
    arrival_follows_leaving: bool,
    /// The topology's node count, read at every message (asked of the topology, a product
    /// over its dimensions behind a virtual call).
    nodes: u32,
    /// The latest instant everything sent so far could end ([`Network::admit`]).
    horizon: u64,
    /// The terms of [`Network::worst_case_ps`], which every message sent pays.
    worst: WorstCase,
}

/// A message's worst case, in picoseconds: `2 * per_byte * bytes + per_packet * packets +
/// fixed`.
#[derive(Clone, Copy, Debug)]
struct WorstCase {
    per_byte: u128,
    per_packet: u128,
    fixed: u128,
    packet_size: u64,
}

impl WorstCase {
    fn of(timing: &Timing, nodes: u32, gap: SimTime) -> WorstCase {
        let hop = timing
            .hop_latency
            .max(timing.node_links.map_or(SimTime::ZERO, |n| n.hop_latency));
        WorstCase {
            per_byte: Bandwidth::work_of(Bytes::new(1))
                .div_ceil(u128::from(timing.slowest().bits_per_s())),
            per_packet: u128::from(hop.ps()) * u128::from(nodes),
            fixed: u128::from(gap.ps()) + 1,
            packet_size: timing.packet_size.get().max(1),
        }
    }
}

pub use occupancy::LinkSpan;

/// A route's hops by kind of link.
fn hops_of(topology: &dyn Topology, timing: Timing, route: &[LinkId]) -> Hops {
    let node = match timing.node_links {
        Some(_) => route.iter().filter(|&&l| topology.is_node_link(l)).count() as u32,
        None => 0,
    };
    let network = (route.len() as u32 - node) / topology.links_per_hop();
    Hops { network, node }
}

/// The links a message crosses: the bus, for a broadcast, or a pair's stored route.
enum Route<'a> {
    Bus(LinkId),
    Links(&'a [LinkId]),
}

impl Route<'_> {
    fn links(&self) -> &[LinkId] {
        match self {
            Route::Bus(link) => std::slice::from_ref(link),
            Route::Links(links) => links,
        }
    }
}

/// The route from `src` to `dst` (not to itself); `None` when there is none (a broadcast off
/// a bus, a node out of range, a pipeline run backwards).
fn route_of<'a>(
    topology: &dyn Topology,
    routes: &'a mut routes::Routes,
    src: NodeId,
    dst: Dest,
) -> Option<Route<'a>> {
    let n = topology.nodes();
    match dst {
        Dest::Broadcast => topology.broadcast_link().map(Route::Bus),
        Dest::Node(d) if src < n && d < n => routes.get(topology, src, d).map(Route::Links),
        Dest::Node(_) => None,
    }
}

impl Network {
    /// Builds the network, validating the configuration (dimensions and packet size).
    pub fn new(cfg: &NetworkConfig) -> Result<Network, NetError> {
        if cfg.packet_size.get() == 0 {
            return Err(NetError::Config(
                "packet_size must be at least 1 byte".to_string(),
            ));
        }
        let mut topology = topology::build(cfg.topology, &cfg.dims)?;
        if let Some(node) = cfg.node {
            topology = topology::in_nodes(topology, node.processors, node.nics, node.placement)?;
        }
        let nodes = topology.nodes();
        let timing = Timing {
            bandwidth: cfg.link_bandwidth,
            hop_latency: cfg.hop_latency,
            switching: cfg.switching,
            packet_size: cfg.packet_size,
            node_links: cfg.node.map(|n| n.links),
        };
        let links = topology.links().len();
        let node_link: Vec<bool> = match cfg.node {
            Some(_) => (0..links as LinkId)
                .map(|l| topology.is_node_link(l))
                .collect(),
            None => Vec::new(),
        };
        let transport = transport::build(
            cfg.fidelity,
            timing,
            links,
            topology.links_per_hop(),
            &node_link,
        )
        .map_err(NetError::Config)?;
        let route_free = transport::route_free(cfg.fidelity, timing);
        let lines = route_free.and_then(|level| Some((topology.line_tally()?, level)));
        Ok(Network {
            topology,
            transport,
            fidelity: cfg.fidelity,
            timing,
            carried: vec![(Bytes::ZERO, 0); links],
            lines,
            routes: routes::Routes::new(nodes),
            occupancy: None,
            interfaces: interface::Interfaces::new(cfg.message_gap, nodes),
            arrival_follows_leaving: route_free.is_some() && timing.hop_latency > SimTime::ZERO,
            nodes,
            horizon: 0,
            worst: WorstCase::of(&timing, nodes, cfg.message_gap),
        })
    }

    pub fn nodes(&self) -> u32 {
        self.nodes
    }

    /// The transport model this network runs.
    pub fn fidelity(&self) -> Fidelity {
        self.fidelity
    }

    /// The flow model's work counters so far (zero at other levels, and without the
    /// `counters` feature).
    pub fn solve_counters(&self) -> transport::SolveCounters {
        self.transport.counters()
    }

    /// Whether every ordered pair of nodes has a route (see [`Network::can_route`]).
    pub fn routes_every_pair(&self) -> bool {
        self.topology.routes_every_pair()
    }

    /// Only a bus reaches every node with one transmission.
    pub fn supports_broadcast(&self) -> bool {
        self.topology.broadcast_link().is_some()
    }

    pub fn timing(&self) -> Timing {
        self.timing
    }

    /// The most picoseconds a message of `bytes` can add to the network's work: its
    /// interface's gap, a serialization over the slowest link twice (rounded up per byte), and
    /// the longest hop's latency times the node count for each of its packets (more than any
    /// transport can take). Sent one after another, messages end within the sum of theirs.
    pub fn worst_case_ps(&self, bytes: Bytes) -> u128 {
        let w = self.worst;
        let packets = bytes
            .get()
            .div_ceil(w.packet_size)
            .clamp(1, u32::MAX as u64);
        2 * w.per_byte * u128::from(bytes.get()) + w.per_packet * u128::from(packets) + w.fixed
    }

    /// Takes a message of `bytes` sent at `now` into the network's worst case, everything sent
    /// so far one after another ([`Network::worst_case_ps`]); refused, with that bound in
    /// picoseconds, when it could end past the largest simulated time. The network's own
    /// arithmetic then never overflows (an interface's queue of long gaps did).
    pub fn admit(&mut self, now: SimTime, bytes: Bytes) -> Result<(), u128> {
        let end = u128::from(self.horizon.max(now.ps())) + self.worst_case_ps(bytes);
        match u64::try_from(end) {
            Ok(end) if end <= SimTime::MAX.ps() => {
                self.horizon = end;
                Ok(())
            }
            _ => Err(end),
        }
    }

    /// The time each node's interface spends on a message before its first byte leaves.
    pub fn message_gap(&self) -> SimTime {
        self.interfaces.as_ref().map_or(SimTime::ZERO, |i| i.gap())
    }

    /// Whether a message from `src` to `dst` has a route (false only for a pipeline run
    /// backwards, or nodes out of range).
    pub fn can_route(&self, src: NodeId, dst: NodeId) -> bool {
        let n = self.nodes();
        src < n && dst < n && self.topology.route_into(src, dst, &mut Vec::new())
    }

    /// The links a message crosses, in order; `None` when [`Network::can_route`] is false.
    /// On a crossbar a route is `[out(src), in(dst)]`.
    pub fn route(&self, src: NodeId, dst: NodeId) -> Option<Vec<LinkId>> {
        let mut links = Vec::new();
        let n = self.nodes();
        (src < n && dst < n && self.topology.route_into(src, dst, &mut links)).then_some(links)
    }

    /// Switch traversals from `src` to `dst`: the `h` of the latency formula (the number of
    /// links, except on a crossbar where both ports count as one hop), over node links and
    /// the network's.
    ///
    /// Panics when the pair cannot be routed (check [`Network::can_route`] first).
    pub fn hops(&self, src: NodeId, dst: NodeId) -> Hops {
        let route = self
            .route(src, dst)
            .unwrap_or_else(|| panic!("no route from node {src} to node {dst}"));
        self.hops_of(&route)
    }

    fn hops_of(&self, route: &[LinkId]) -> Hops {
        hops_of(self.topology.as_ref(), self.timing, route)
    }

    /// Links cut by the best balanced bisection, counted in one direction (a bidirectional
    /// pair counts once); see each topology's file for its case.
    pub fn bisection_width(&self) -> u32 {
        self.topology.bisection_width()
    }

    pub fn link_count(&self) -> usize {
        self.topology.links().len()
    }

    pub fn links(&self) -> &[Link] {
        self.topology.links()
    }

    /// Checks that a message may be injected; the error names what is valid.
    pub fn check_message(&self, src: NodeId, dst: Dest) -> Result<(), NetError> {
        let n = self.nodes();
        if src >= n {
            return Err(NetError::Message(format!(
                "source node {src} does not exist; valid nodes are 0..={}",
                n - 1
            )));
        }
        match dst {
            Dest::Broadcast if !self.supports_broadcast() => Err(NetError::Message(format!(
                "broadcast needs a bus; this network is a {}",
                self.topology.kind().name()
            ))),
            Dest::Broadcast => Ok(()),
            Dest::Node(d) if d >= n => Err(NetError::Message(format!(
                "destination node {d} does not exist; valid nodes are 0..={}",
                n - 1
            ))),
            Dest::Node(d) if !self.can_route(src, d) => Err(NetError::Message(format!(
                "no route from node {src} to node {d}: a pipeline only sends to higher \
                 node ids (destination must be >= {src})"
            ))),
            Dest::Node(_) => Ok(()),
        }
    }

    /// Sends a message at `now`. Returns the delivery time when the model already knows it
    /// (ideal, hops, and a message to self at every level, all without a message gap);
    /// otherwise the delivery comes out of [`Network::advance`]. With a message gap the
    /// message first waits for its sender's interface (`interface.rs`).
    ///
    /// Panics if [`Network::check_message`] would fail: that is the caller's bug.
    pub fn inject(
        &mut self,
        now: SimTime,
        msg: MsgId,
        src: NodeId,
        dst: Dest,
        bytes: Bytes,
    ) -> Option<SimTime> {
        if let Some(pending) = self.next_event_time() {
            // Skipping an `advance` would lose a rate change or a queue hand-over.
            assert!(
                pending >= now,
                "Network::inject at {now} before advancing to the pending event at {pending}"
            );
        }
        if dst == Dest::Node(src) && src < self.nodes() {
            return Some(now);
        }
        if self.interfaces.is_some() {
            let rate = self.first_link_rate(msg, src, dst);
            if self.arrival_known_at_send() {
                let interfaces = self.interfaces.as_mut().expect("checked above");
                let (leaves, seq) = interfaces.depart(now, src, bytes, rate);
                let arrival = self
                    .start(leaves, msg, src, dst, bytes)
                    .expect("a level without contention knows an arrival at the start");
                let interfaces = self.interfaces.as_mut().expect("checked above");
                interfaces.arrive_known(arrival, leaves, seq, msg);
                return None;
            }
            if let Some(interfaces) = &mut self.interfaces {
                interfaces.send(now, msg, src, dst, bytes, rate);
            }
            return None;
        }
        self.start(now, msg, src, dst, bytes)
    }

    /// Whether a message's arrival is told as it is sent rather than as it leaves its
    /// interface: when its leaving alone gives its arrival (`arrival_follows_leaving`), and no
    /// timeline records the links' occupancy from each message's start.
    fn arrival_known_at_send(&self) -> bool {
        self.arrival_follows_leaving && self.occupancy.is_none()
    }

    /// The rate of the first link `msg` crosses from `src` to `dst` (not to itself): the pace
    /// at which its bytes leave the sender's interface.
    ///
    /// Panics if [`Network::check_message`] would fail: that is the caller's bug.
    fn first_link_rate(&mut self, msg: MsgId, src: NodeId, dst: Dest) -> Bandwidth {
        // With one rate for every link the route is not needed until the message starts,
        // only that it has one.
        if self.timing.node_links.is_none() {
            let n = self.nodes();
            if matches!(dst, Dest::Node(d) if src < n && d < n && self.topology.routes_every_pair())
            {
                return self.timing.bandwidth;
            }
        }
        let Some(route) = route_of(self.topology.as_ref(), &mut self.routes, src, dst) else {
            self.unroutable(msg, src, dst)
        };
        let first = route.links()[0];
        match self.timing.node_links {
            Some(n) if self.topology.is_node_link(first) => n.bandwidth,
            _ => self.timing.bandwidth,
        }
    }

    fn unroutable(&self, msg: MsgId, src: NodeId, dst: Dest) -> ! {
        panic!(
            "Network::inject of message {msg}: {}",
            self.check_message(src, dst).unwrap_err()
        )
    }

    /// Hands a message that leaves its sender at `now` to the transport.
    ///
    /// Panics if [`Network::check_message`] would fail: that is the caller's bug.
    fn start(
        &mut self,
        now: SimTime,
        msg: MsgId,
        src: NodeId,
        dst: Dest,
        bytes: Bytes,
    ) -> Option<SimTime> {
        if let (Some((lines, level)), Dest::Node(d), None) = (&mut self.lines, dst, &self.occupancy)
        {
            let n = self.nodes;
            if src < n && d < n {
                let busy = level.busy_per_link(bytes);
                let amount = [bytes.get(), 1, busy.ps()];
                let links = self.topology.tally_route(src, d, lines, amount);
                let hops = Hops {
                    network: links / self.topology.links_per_hop(),
                    node: 0,
                };
                return Some(level.arrival_after_busy(now, busy, hops, bytes));
            }
        }
        let Some(route) = route_of(self.topology.as_ref(), &mut self.routes, src, dst) else {
            self.unroutable(msg, src, dst)
        };
        let route = route.links();
        for &l in route {
            let carried = &mut self.carried[l as usize];
            carried.0 += bytes;
            carried.1 += 1;
        }
        let hops = hops_of(self.topology.as_ref(), self.timing, route);
        let arrival = self.transport.inject(now, msg, route, hops, bytes);
        if let Some(o) = &mut self.occupancy {
            o.injected(msg, now, route, arrival);
        }
        arrival
    }

    /// The message the network will deliver next, when its model knows it ahead: a hint.
    pub fn next_delivered(&self) -> Option<MsgId> {
        self.transport.next_delivered()
    }

    /// The earliest instant at which `advance` has something to do.
    pub fn next_event_time(&self) -> Option<SimTime> {
        let held = self.interfaces.as_ref().and_then(|i| i.next_time());
        SimTime::earliest(self.transport.next_event_time(), held)
    }

    /// Processes the model's internal events at `now`, appending messages delivered at `now`.
    pub fn advance(&mut self, now: SimTime, delivered: &mut Vec<Delivered>) {
        let before = delivered.len();
        self.release_held(now, delivered);
        self.transport.advance(now, delivered);
        if let Some(o) = &mut self.occupancy {
            for d in &delivered[before..] {
                o.delivered(d.msg, d.at);
            }
        }
    }

    /// Starts the messages that leave their interfaces at `now` (before the transport
    /// advances, so that they join the rate computation or queues of `now`) and delivers those
    /// whose known arrival is `now`.
    fn release_held(&mut self, now: SimTime, delivered: &mut Vec<Delivered>) {
        while let Some((at, due)) = self.interfaces.as_mut().and_then(|i| i.pop_due(now)) {
            match due {
                interface::Due::Start {
                    msg,
                    src,
                    dst,
                    bytes,
                } => match self.start(at, msg, src, dst, bytes) {
                    Some(arrival) if arrival <= now => delivered.push(Delivered { msg, at }),
                    Some(arrival) => self
                        .interfaces
                        .as_mut()
                        .expect("held messages come from interfaces")
                        .arrive_at(arrival, msg),
                    None => {}
                },
                interface::Due::Arrive { msg } => delivered.push(Delivered { msg, at }),
            }
        }
    }

    /// Starts recording which links carry messages when (see [`LinkSpan`]), for timelines.
    pub fn record_occupancy(&mut self) {
        self.occupancy.get_or_insert_with(Default::default);
    }

    /// Stops (or resumes) recording the occupancy of messages injected from now on; those
    /// already recorded are kept to their delivery.
    pub fn pause_occupancy(&mut self, paused: bool) {
        if let Some(o) = &mut self.occupancy {
            o.paused = paused;
        }
    }

    /// The recorded link occupancy, merged per link, handed over (recording stops); empty
    /// unless recording.
    pub fn take_link_spans(&mut self) -> Vec<LinkSpan> {
        self.occupancy
            .take()
            .map(occupancy::Occupancy::into_spans)
            .unwrap_or_default()
    }

    /// Traffic per link, in link index order.
    pub fn link_stats(&self) -> Vec<LinkStats> {
        let by_lines = match &self.lines {
            Some((lines, _)) => self.topology.tallied(lines),
            None => Vec::new(),
        };
        self.topology
            .links()
            .iter()
            .enumerate()
            .map(|(i, link)| {
                let usage = self.transport.usage(i as LinkId);
                let [bytes, messages, busy] = by_lines.get(i).copied().unwrap_or_default();
                LinkStats {
                    from: link.from,
                    to: link.to,
                    name: link.name(self.nodes),
                    bytes: self.carried[i].0 + Bytes::new(bytes),
                    messages: self.carried[i].1 + messages,
                    busy: usage.busy + SimTime::from_ps(busy),
                    peak_queue: usage.peak_queue,
                }
            })
            .collect()
    }
}
