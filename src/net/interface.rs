//! The nodes' network interfaces, when a machine gives them a per-message gap
//! (`network.message_gap`, LogGP's g): an interface sends one message at a time, spends the
//! gap on each before its first byte leaves, and stays busy while its bytes leave at the rate
//! of the sender's first link; a message sent meanwhile waits its turn. A stream of messages
//! from one node then runs at `bytes / (gap + bytes / rate)`, below the links' rate for small
//! messages, which is what "the maximum rate for 4-Kbyte messages" of paper 002 describes.
//!
//! Owns when each message leaves its sender and the messages held until then (and, for the
//! levels that know an arrival at injection, until they arrive). Must never decide when a
//! message arrives (the transport does) nor look at any link but the sender's first.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use super::{Dest, MsgId, NodeId};
use crate::units::{Bandwidth, Bytes, SimTime};

/// What happens to a held message at its instant.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Due {
    /// It leaves its sender's interface: the transport takes it now.
    Start {
        msg: MsgId,
        src: NodeId,
        dst: Dest,
        bytes: Bytes,
    },
    /// It arrives (its transport knew the arrival when it started).
    Arrive { msg: MsgId },
}

/// A held message, ordered by (instant, order of holding): same-instant events keep the order
/// they were made in, so the run is deterministic.
#[derive(Debug)]
struct Held {
    at: SimTime,
    seq: u64,
    due: Due,
}

impl PartialEq for Held {
    fn eq(&self, other: &Held) -> bool {
        (self.at, self.seq) == (other.at, other.seq)
    }
}
impl Eq for Held {}
impl PartialOrd for Held {
    fn partial_cmp(&self, other: &Held) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Held {
    fn cmp(&self, other: &Held) -> std::cmp::Ordering {
        (self.at, self.seq).cmp(&(other.at, other.seq))
    }
}

pub(super) struct Interfaces {
    gap: SimTime,
    /// Per node: the instant its interface can start on another message.
    free_at: Vec<SimTime>,
    held: BinaryHeap<Reverse<Held>>,
    seq: u64,
}

impl Interfaces {
    /// The interfaces of `nodes` nodes, or `None` when the gap is zero: then a message leaves
    /// at its send and nothing is held, exactly as without interfaces.
    pub(super) fn new(gap: SimTime, nodes: u32) -> Option<Interfaces> {
        (gap > SimTime::ZERO).then(|| Interfaces {
            gap,
            free_at: vec![SimTime::ZERO; nodes as usize],
            held: BinaryHeap::new(),
            seq: 0,
        })
    }

    pub(super) fn gap(&self) -> SimTime {
        self.gap
    }

    /// Queues a message sent at `now` behind its sender's interface, whose first link runs at
    /// `rate`; it leaves (comes out of [`Interfaces::pop_due`] as `Due::Start`) a gap after
    /// the interface is free.
    pub(super) fn send(
        &mut self,
        now: SimTime,
        msg: MsgId,
        src: NodeId,
        dst: Dest,
        bytes: Bytes,
        rate: Bandwidth,
    ) {
        let free_at = &mut self.free_at[src as usize];
        let leaves = now.max(*free_at) + self.gap;
        *free_at = leaves + rate.transfer_time(bytes);
        self.hold(
            leaves,
            Due::Start {
                msg,
                src,
                dst,
                bytes,
            },
        );
    }

    /// Holds a message whose transport told its arrival at `at` until then.
    pub(super) fn arrive_at(&mut self, at: SimTime, msg: MsgId) {
        self.hold(at, Due::Arrive { msg });
    }

    fn hold(&mut self, at: SimTime, due: Due) {
        self.held.push(Reverse(Held {
            at,
            seq: self.seq,
            due,
        }));
        self.seq += 1;
    }

    /// The earliest instant something held is due.
    pub(super) fn next_time(&self) -> Option<SimTime> {
        self.held.peek().map(|Reverse(h)| h.at)
    }

    /// The next held message due at or before `now`, with its instant.
    pub(super) fn pop_due(&mut self, now: SimTime) -> Option<(SimTime, Due)> {
        if self.next_time()? > now {
            return None;
        }
        self.held.pop().map(|Reverse(h)| (h.at, h.due))
    }
}
