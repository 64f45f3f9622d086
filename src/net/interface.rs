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
//!
//! A level that knows a message's arrival from the instant it leaves alone (no contention)
//! needs no stop at that instant: the leaving is known at the send too, so such a message
//! is held from its send straight to its arrival ([`Interfaces::depart`] and
//! [`Interfaces::arrive_known`]), in the same order among arrivals as when held at its
//! leaving (`held_from_the_send_arrive_as_held_from_the_leaving`, below).

use std::cmp::Reverse;
use std::collections::VecDeque;

use dary_heap::QuaternaryHeap;

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

/// Where a held event sits in the one order they all come out in: its instant, then the order
/// it was held in, so that same-instant events keep the order they were made in.
type Key = (SimTime, u64);

/// Where an arrival sits among the held events: its instant, then the instant its message
/// left and the order it was sent in ([`Interfaces::arrive_known`]); an arrival held at its
/// leaving ([`Interfaces::arrive_at`]) has no leaving instant of its own (zero) and the
/// order of its leaving in the last place.
type ArrivalKey = (SimTime, SimTime, u64);

/// A message waiting for its sender's interface.
#[derive(Clone, Copy, Debug)]
struct Waiting {
    key: Key,
    msg: MsgId,
    dst: Dest,
    bytes: Bytes,
}

pub(super) struct Interfaces {
    gap: SimTime,
    /// Per node: the instant its interface can start on another message.
    free_at: Vec<SimTime>,
    /// Per node: its messages waiting to leave, in the order they leave. A node's messages
    /// leave one at a time, each at least a gap after the last, so each queue's keys rise and
    /// only its first can be the next to leave.
    waiting: Vec<VecDeque<Waiting>>,
    /// The key of each non-empty queue's first message, with its node. Both heaps are 4-ary,
    /// as the engine's event queue is: half a binary heap's depth, so a node's next message
    /// put on top after its last one leaves sinks in fewer steps.
    heads: QuaternaryHeap<Reverse<(Key, NodeId)>>,
    /// Messages whose transport told their arrival, until then.
    arriving: QuaternaryHeap<Reverse<(ArrivalKey, MsgId)>>,
    seq: u64,
}

impl Interfaces {
    /// The interfaces of `nodes` nodes, or `None` when the gap is zero: then a message leaves
    /// at its send and nothing is held, exactly as without interfaces.
    pub(super) fn new(gap: SimTime, nodes: u32) -> Option<Interfaces> {
        (gap > SimTime::ZERO).then(|| Interfaces {
            gap,
            free_at: vec![SimTime::ZERO; nodes as usize],
            waiting: vec![VecDeque::new(); nodes as usize],
            heads: QuaternaryHeap::new(),
            arriving: QuaternaryHeap::new(),
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
        let key = self.depart(now, src, bytes, rate);
        let queue = &mut self.waiting[src as usize];
        if queue.is_empty() {
            self.heads.push(Reverse((key, src)));
        }
        queue.push_back(Waiting {
            key,
            msg,
            dst,
            bytes,
        });
    }

    /// Holds a message whose transport told its arrival at `at`, as it left, until then.
    pub(super) fn arrive_at(&mut self, at: SimTime, msg: MsgId) {
        let (at, seq) = self.next_key(at);
        self.arriving.push(Reverse(((at, SimTime::ZERO, seq), msg)));
    }

    /// When a message of `bytes` sent at `now` by `src` leaves its interface, whose first
    /// link runs at `rate` (a gap after the interface is free, which it is again once the
    /// bytes have left), with its place among the messages sent: the key it waits by
    /// ([`Interfaces::send`]) or is held by to its arrival ([`Interfaces::arrive_known`]).
    /// This, `arrive_known` and `pop_due` run once a message: marked inline so that they stay
    /// inlined into `Network` whichever codegen unit the compiler puts them in.
    #[inline]
    pub(super) fn depart(
        &mut self,
        now: SimTime,
        src: NodeId,
        bytes: Bytes,
        rate: Bandwidth,
    ) -> (SimTime, u64) {
        let free_at = &mut self.free_at[src as usize];
        let leaves = now.max(*free_at) + self.gap;
        *free_at = leaves + rate.transfer_time(bytes);
        self.next_key(leaves)
    }

    /// Holds until `at` a message whose arrival its level knew as it was sent; it leaves at
    /// `leaves`, `seq` its place among the messages sent ([`Interfaces::depart`]).
    /// Held at its leaving instead, it would have come out among the arrivals at `at` in the
    /// order the messages left, which is the order of (leaving instant, place sent): so it
    /// does here. It must arrive after it leaves: one arriving as it left would have been
    /// delivered at its leaving, among the other events of that instant.
    #[inline]
    pub(super) fn arrive_known(&mut self, at: SimTime, leaves: SimTime, seq: u64, msg: MsgId) {
        assert!(
            at > leaves,
            "a message held from its send arrived as it left"
        );
        self.arriving.push(Reverse(((at, leaves, seq), msg)));
    }

    fn next_key(&mut self, at: SimTime) -> Key {
        self.seq += 1;
        (at, self.seq - 1)
    }

    fn next_start(&self) -> Option<(Key, NodeId)> {
        self.heads.peek().map(|&Reverse(head)| head)
    }

    fn next_arrival(&self) -> Option<ArrivalKey> {
        self.arriving.peek().map(|&Reverse((key, _))| key)
    }

    /// The earliest instant something held is due.
    pub(super) fn next_time(&self) -> Option<SimTime> {
        let start = self.next_start().map(|((at, _), _)| at);
        let arrival = self.next_arrival().map(|(at, _, _)| at);
        SimTime::earliest(start, arrival)
    }

    /// The next held message due at or before `now`, with its instant: of a leaving and an
    /// arrival at the same instant, the one held first.
    #[inline]
    pub(super) fn pop_due(&mut self, now: SimTime) -> Option<(SimTime, Due)> {
        let start = self.next_start().filter(|&((at, _), _)| at <= now);
        let arrival = self.next_arrival().filter(|&(at, _, _)| at <= now);
        let leaves_first = match (start, arrival) {
            (Some(((at, seq), _)), Some(other)) => (at, SimTime::ZERO, seq) < other,
            (Some(_), None) => true,
            (None, Some(_)) => false,
            (None, None) => return None,
        };
        if let (true, Some(((at, _), src))) = (leaves_first, start) {
            return Some((at, self.leave(src)));
        }
        let ((at, _, _), msg) = self.arriving.pop()?.0;
        Some((at, Due::Arrive { msg }))
    }

    /// Takes `src`'s first waiting message off its queue (it is the next to leave).
    fn leave(&mut self, src: NodeId) -> Due {
        let queue = &mut self.waiting[src as usize];
        let w = queue
            .pop_front()
            .expect("a head stands for a waiting message");
        // The node's next message takes its place at the top: one sift down, where a pop and
        // a push would sift twice. Keys are distinct, so the heap's order is the same.
        match queue.front() {
            Some(next) => {
                *self.heads.peek_mut().expect("the node's head is the top") =
                    Reverse((next.key, src));
            }
            None => {
                self.heads.pop();
            }
        }
        Due::Start {
            msg: w.msg,
            src,
            dst: w.dst,
            bytes: w.bytes,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// What the interfaces did before each node kept its own queue: every held event in one
    /// list, the least (instant, order held) taken first. The oracle of the queues above.
    #[derive(Default)]
    struct OneList {
        free_at: Vec<SimTime>,
        held: Vec<(SimTime, u64, Due)>,
        seq: u64,
    }

    impl OneList {
        fn hold(&mut self, at: SimTime, due: Due) {
            self.held.push((at, self.seq, due));
            self.seq += 1;
        }

        fn pop_due(&mut self, now: SimTime) -> Option<(SimTime, Due)> {
            let (i, _) = self
                .held
                .iter()
                .enumerate()
                .min_by_key(|(_, (at, seq, _))| (*at, *seq))?;
            (self.held[i].0 <= now).then(|| {
                let (at, _, due) = self.held.swap_remove(i);
                (at, due)
            })
        }
    }

    #[derive(Clone, Debug)]
    enum Op {
        Send { after: u64, src: u32, bytes: u64 },
        Arrive { after: u64, late: u64 },
        Pop { after: u64 },
    }

    fn op() -> impl Strategy<Value = Op> {
        // Small steps and few nodes, so that instants tie often.
        prop_oneof![
            (0..3u64, 0..4u32, 1..3u64).prop_map(|(after, src, bytes)| Op::Send {
                after,
                src,
                bytes: bytes * 1000
            }),
            (0..3u64, 0..4u64).prop_map(|(after, late)| Op::Arrive { after, late }),
            (0..4u64).prop_map(|after| Op::Pop { after }),
        ]
    }

    proptest! {
        /// Held messages come out at the same instants and in the same order as from one list
        /// ordered by (instant, order held), ties included.
        #[test]
        fn queues_per_node_keep_the_one_list_order(ops in proptest::collection::vec(op(), 1..200)) {
            let gap = SimTime::from_us(1);
            let rate = Bandwidth::from_bytes_per_s(1_000_000_000).unwrap();
            let mut fast = Interfaces::new(gap, 4).unwrap();
            let mut oracle = OneList { free_at: vec![SimTime::ZERO; 4], ..OneList::default() };
            let mut now = SimTime::ZERO;
            let mut msg = 0;
            let drain = |fast: &mut Interfaces, oracle: &mut OneList, now| loop {
                let got = fast.pop_due(now);
                prop_assert_eq!(got, oracle.pop_due(now));
                if got.is_none() {
                    return Ok(());
                }
            };
            for op in ops {
                match op {
                    Op::Send { after, src, bytes } => {
                        now += SimTime::from_us(after);
                        msg += 1;
                        let (dst, bytes) = (Dest::Node(9), Bytes::new(bytes));
                        fast.send(now, msg, src, dst, bytes, rate);
                        let free_at = &mut oracle.free_at[src as usize];
                        let leaves = now.max(*free_at) + gap;
                        *free_at = leaves + rate.transfer_time(bytes);
                        oracle.hold(leaves, Due::Start { msg, src, dst, bytes });
                    }
                    Op::Arrive { after, late } => {
                        now += SimTime::from_us(after);
                        msg += 1;
                        fast.arrive_at(now + SimTime::from_us(late), msg);
                        oracle.hold(now + SimTime::from_us(late), Due::Arrive { msg });
                    }
                    Op::Pop { after } => {
                        now += SimTime::from_us(after);
                        drain(&mut fast, &mut oracle, now)?;
                    }
                }
                prop_assert_eq!(
                    fast.next_time(),
                    oracle.held.iter().map(|h| h.0).min()
                );
            }
            drain(&mut fast, &mut oracle, SimTime::MAX)?;
        }

        /// Messages held from their send straight to their arrival (`depart`, `arrive_known`)
        /// arrive at the same instants and in the same order as the same messages held until
        /// they leave and then, their arrival told, until they arrive (`send`, `arrive_at`):
        /// sends at a few instants from four nodes so that leavings and arrivals tie often,
        /// and delays beyond the gap, so that a node's later message can arrive first.
        #[test]
        fn held_from_the_send_arrive_as_held_from_the_leaving(
            sends in proptest::collection::vec((0..3u64, 0..4u32, 0..3u64, 1..2500u64), 1..120)
        ) {
            let gap = SimTime::from_us(1);
            let rate = Bandwidth::from_bytes_per_s(1_000_000_000).unwrap();
            // (instant sent, sender, bytes, the delay after its bytes leave) per message.
            let mut at = SimTime::ZERO;
            let sends: Vec<(SimTime, NodeId, Bytes, SimTime)> = sends
                .into_iter()
                .map(|(after, src, kb, delay)| {
                    at += SimTime::from_us(after);
                    (at, src, Bytes::new(kb * 1000), SimTime::from_ns(delay))
                })
                .collect();
            let arrival = |leaves: SimTime, m: usize| {
                leaves + rate.transfer_time(sends[m].2) + sends[m].3
            };
            let run = |from_the_send: bool| {
                let mut ifs = Interfaces::new(gap, 4).unwrap();
                let (mut next, mut arrived) = (0, Vec::new());
                while let Some(now) =
                    SimTime::earliest(sends.get(next).map(|s| s.0), ifs.next_time())
                {
                    while next < sends.len() && sends[next].0 == now {
                        let (_, src, bytes, _) = sends[next];
                        let msg = next as MsgId;
                        if from_the_send {
                            let (leaves, seq) = ifs.depart(now, src, bytes, rate);
                            ifs.arrive_known(arrival(leaves, next), leaves, seq, msg);
                        } else {
                            ifs.send(now, msg, src, Dest::Node(9), bytes, rate);
                        }
                        next += 1;
                    }
                    while let Some((t, due)) = ifs.pop_due(now) {
                        match due {
                            Due::Start { msg, .. } => ifs.arrive_at(arrival(t, msg as usize), msg),
                            Due::Arrive { msg } => arrived.push((t, msg)),
                        }
                    }
                }
                arrived
            };
            let held_from_the_send = run(true);
            prop_assert_eq!(held_from_the_send.len(), sends.len());
            prop_assert_eq!(held_from_the_send, run(false));
        }
    }
}
