//! Interconnection networks: topologies, routing and the transport models behind
//! `network.fidelity`.
//!
//! Owns where a message goes (the exact list of links) and when it arrives. The engine hands
//! a message in with `Network::inject` and asks for deliveries with `next_event_time` /
//! `advance`; this module is a plain discrete-event state machine and knows nothing about
//! async programs, cpus or payloads.
//!
//! Must never iterate a hash map on a path that affects timing or output, and never use
//! floating point for a time.

use crate::units::{Bandwidth, Bytes, SimTime};

/// A simulated node (processor) index, `0..nodes`.
pub type NodeId = u32;

/// A message's identity, assigned by whoever injects it (the engine uses its sequence).
pub type MsgId = u64;

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum TopologyKind {
    Ring,
    Pipeline,
    Torus,
    Mesh,
    Hypercube,
    Bus,
    Crossbar,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Switching {
    StoreAndForward,
    Wormhole,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Fidelity {
    Ideal,
    Hops,
    Flow,
    Packet,
}

impl Fidelity {
    pub const ALL: [Fidelity; 4] = [Fidelity::Ideal, Fidelity::Hops, Fidelity::Flow, Fidelity::Packet];
    pub fn name(self) -> &'static str {
        match self {
            Fidelity::Ideal => "ideal",
            Fidelity::Hops => "hops",
            Fidelity::Flow => "flow",
            Fidelity::Packet => "packet",
        }
    }
}

/// A validated network description (built by `spec`).
#[derive(Clone, Debug)]
pub struct NetworkConfig {
    pub topology: TopologyKind,
    /// Extent per dimension (torus, mesh); `[nodes]` for the one-dimensional topologies.
    pub dims: Vec<u32>,
    pub link_bandwidth: Bandwidth,
    pub hop_latency: SimTime,
    pub switching: Switching,
    pub packet_size: Bytes,
    pub fidelity: Fidelity,
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
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct LinkStats {
    pub from: NodeId,
    pub to: NodeId,
    pub bytes: Bytes,
    pub messages: u64,
    pub busy: SimTime,
    pub peak_queue: u32,
}

#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum NetError {
    #[error("{0}")]
    Invalid(String),
}

/// Placeholder facade: ideal transport only. Replaced by the full topology and transport
/// implementation.
pub struct Network {
    cfg: NetworkConfig,
    nodes: u32,
}

impl Network {
    pub fn new(cfg: &NetworkConfig) -> Result<Network, NetError> {
        let nodes = cfg.dims.iter().product();
        Ok(Network { cfg: cfg.clone(), nodes })
    }
    pub fn nodes(&self) -> u32 {
        self.nodes
    }
    pub fn supports_broadcast(&self) -> bool {
        self.cfg.topology == TopologyKind::Bus
    }
    /// Starts a message at `now`. Returns the delivery time when the model already knows it
    /// (contention-free models); otherwise the delivery comes out of `advance`.
    pub fn inject(&mut self, now: SimTime, _msg: MsgId, _src: NodeId, _dst: Dest, bytes: Bytes) -> Option<SimTime> {
        Some(now + self.cfg.hop_latency + self.cfg.link_bandwidth.transfer_time(bytes))
    }
    /// The earliest instant at which `advance` has something to do.
    pub fn next_event_time(&self) -> Option<SimTime> {
        None
    }
    /// Processes the model's internal events at `now`, appending messages delivered at `now`.
    pub fn advance(&mut self, _now: SimTime, _delivered: &mut Vec<Delivered>) {}
    pub fn link_stats(&self) -> Vec<LinkStats> {
        Vec::new()
    }
}
