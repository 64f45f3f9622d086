//! The contention-free message time: the one formula every transport level agrees with
//! for a message alone on the network.
//!
//! Owns the arithmetic of latency, serialization and the store-and-forward pipeline term.
//! Must never model contention (that is the transports' job) nor round more than once per
//! term: every term is an exact `SimTime` from `Bandwidth::transfer_time`.

use super::Switching;
use crate::units::{Bandwidth, Bytes, SimTime};

/// The link parameters shared by every transport level.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Timing {
    pub bandwidth: Bandwidth,
    pub hop_latency: SimTime,
    pub switching: Switching,
    pub packet_size: Bytes,
}

impl Timing {
    /// Time for `bytes` to cross `hops` hops with no other traffic:
    /// - wormhole: `h*L + T(bytes)`;
    /// - store-and-forward: `h*L + T(bytes) + (h-1)*T(min(bytes, packet_size))`, the packets
    ///   pipelined so that only the first one pays the serialization at every extra hop.
    pub fn contention_free(&self, hops: u32, bytes: Bytes) -> SimTime {
        self.serialization(bytes) + self.fixed_part(hops, bytes)
    }

    /// What `ideal` charges: `h*L + T(bytes)`, whatever the switching.
    pub fn ideal(&self, hops: u32, bytes: Bytes) -> SimTime {
        self.serialization(bytes) + self.hop_latency.times(hops as u64)
    }

    /// `T(bytes)`: the time to push `bytes` through one link.
    pub fn serialization(&self, bytes: Bytes) -> SimTime {
        self.bandwidth.transfer_time(bytes)
    }

    /// The part of [`Timing::contention_free`] that does not occupy a link for the whole
    /// message: route latency plus, under store-and-forward, the pipeline fill. The flow
    /// model adds it after a flow's fluid transfer ends.
    pub fn fixed_part(&self, hops: u32, bytes: Bytes) -> SimTime {
        let latency = self.hop_latency.times(hops as u64);
        match self.switching {
            Switching::Wormhole => latency,
            Switching::StoreAndForward => {
                let first = self.serialization(self.first_packet(bytes));
                latency + first.times(hops.saturating_sub(1) as u64)
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
