//! The contention-free message time: the one formula every transport level agrees with
//! for a message alone on the network.
//!
//! Owns the arithmetic of latency, serialization and the store-and-forward pipeline term.
//! Must never model contention (that is the transports' job) nor round more than once per
//! term: every term is an exact `SimTime` from `Bandwidth::transfer_time`.

use super::Switching;
use crate::units::{Bandwidth, Bytes, SimTime};

/// The links of a second kind a network may have: those inside a node of several processors
/// (its switch, NVLink- or PCIe-like), at their own rate and latency.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NodeLinks {
    pub bandwidth: Bandwidth,
    pub hop_latency: SimTime,
}

/// A route's hops by kind: over the network's links and over node links. Converts from a
/// plain hop count (a network with one kind of link).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Hops {
    pub network: u32,
    pub node: u32,
}

impl From<u32> for Hops {
    fn from(network: u32) -> Hops {
        Hops { network, node: 0 }
    }
}

impl Hops {
    pub fn total(self) -> u32 {
        self.network + self.node
    }
}

/// The link parameters shared by every transport level.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Timing {
    /// The network's links.
    pub bandwidth: Bandwidth,
    pub hop_latency: SimTime,
    pub switching: Switching,
    pub packet_size: Bytes,
    /// Links inside nodes, when the network has nodes of several processors.
    pub node_links: Option<NodeLinks>,
}

impl Timing {
    /// Time for `bytes` to cross `hops` hops with no other traffic:
    /// - wormhole: `h*L + T(bytes)`;
    /// - store-and-forward: `h*L + T(bytes) + (h-1)*T(min(bytes, packet_size))`, the packets
    ///   pipelined so that only the first one pays the serialization at every extra hop.
    ///
    /// With node links, `h*L` is each hop's own latency, `T` the slowest link's on the route
    /// (the stream's pace), and the pipeline term the first packet's time on every other link.
    pub fn contention_free(&self, hops: impl Into<Hops>, bytes: Bytes) -> SimTime {
        let hops = hops.into();
        self.serialization_on(hops, bytes) + self.fixed_part(hops, bytes)
    }

    /// What `ideal` charges: `h*L + T(bytes)`, whatever the switching.
    pub fn ideal(&self, hops: impl Into<Hops>, bytes: Bytes) -> SimTime {
        let hops = hops.into();
        self.serialization_on(hops, bytes) + self.latency(hops)
    }

    /// `T(bytes)`: the time to push `bytes` through one of the network's links.
    pub fn serialization(&self, bytes: Bytes) -> SimTime {
        self.bandwidth.transfer_time(bytes)
    }

    /// `T(bytes)` on the slowest link of a route of `hops`.
    pub fn serialization_on(&self, hops: Hops, bytes: Bytes) -> SimTime {
        self.bottleneck(hops).transfer_time(bytes)
    }

    /// The slowest link rate on a route of `hops` (the network's rate for an empty route).
    pub fn bottleneck(&self, hops: Hops) -> Bandwidth {
        match self.node_links {
            Some(node)
                if hops.node > 0 && (hops.network == 0 || node.bandwidth < self.bandwidth) =>
            {
                node.bandwidth
            }
            _ => self.bandwidth,
        }
    }

    /// The slowest link rate of the whole network.
    pub fn slowest(&self) -> Bandwidth {
        match self.node_links {
            Some(node) if node.bandwidth < self.bandwidth => node.bandwidth,
            _ => self.bandwidth,
        }
    }

    /// Every hop's latency along a route of `hops`.
    pub fn latency(&self, hops: Hops) -> SimTime {
        let node = self.node_links.map_or(SimTime::ZERO, |n| n.hop_latency);
        self.hop_latency.times(hops.network as u64) + node.times(hops.node as u64)
    }

    /// The part of [`Timing::contention_free`] that does not occupy a link for the whole
    /// message: route latency plus, under store-and-forward, the pipeline fill. The flow
    /// model adds it after a flow's fluid transfer ends.
    pub fn fixed_part(&self, hops: impl Into<Hops>, bytes: Bytes) -> SimTime {
        let hops = hops.into();
        let latency = self.latency(hops);
        match self.switching {
            Switching::Wormhole => latency,
            Switching::StoreAndForward => {
                let first = self.first_packet(bytes);
                let on = |b: Bandwidth, n: u32| b.transfer_time(first).times(n as u64);
                let node = self.node_links.map_or(self.bandwidth, |n| n.bandwidth);
                // Every link but one of the slowest pays the first packet once more.
                let every = on(self.bandwidth, hops.network) + on(node, hops.node);
                let one_slowest = if hops.total() == 0 {
                    SimTime::ZERO
                } else {
                    self.bottleneck(hops).transfer_time(first)
                };
                latency + every.saturating_sub(one_slowest)
            }
        }
    }

    /// The size of a message's first packet.
    pub fn first_packet(&self, bytes: Bytes) -> Bytes {
        bytes.min(self.packet_size)
    }

    /// How many packets a message is cut into; a 0-byte message is one empty packet (a
    /// header that still pays the hop latency).
    pub fn packet_count(&self, bytes: Bytes) -> u64 {
        bytes.get().div_ceil(self.packet_size.get()).max(1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn timing(switching: Switching) -> Timing {
        Timing {
            bandwidth: "1MB/s".parse().unwrap(),
            hop_latency: SimTime::from_us(1),
            switching,
            packet_size: Bytes::new(100),
            node_links: None,
        }
    }

    #[test]
    fn wormhole_is_latency_plus_one_serialization() {
        let t = timing(Switching::Wormhole);
        // 1000 B at 1 MB/s = 1 ms; 3 hops of 1 us.
        assert_eq!(
            t.contention_free(3, Bytes::new(1000)),
            SimTime::from_us(1003)
        );
    }

    #[test]
    fn store_and_forward_pays_the_first_packet_at_every_extra_hop() {
        let t = timing(Switching::StoreAndForward);
        // 1000 + 3 + 2 * 100 us.
        assert_eq!(
            t.contention_free(3, Bytes::new(1000)),
            SimTime::from_us(1203)
        );
        // A message smaller than a packet pays its own size.
        assert_eq!(t.contention_free(3, Bytes::new(10)), SimTime::from_us(33));
        assert_eq!(t.ideal(3, Bytes::new(10)), SimTime::from_us(13));
        assert_eq!(t.packet_count(Bytes::new(1000)), 10);
        assert_eq!(t.packet_count(Bytes::new(1001)), 11);
        assert_eq!(t.packet_count(Bytes::ZERO), 1);
    }
}
