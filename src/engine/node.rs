//! The handle a node program acts through: compute, send, receive, broadcast, post, sleep,
//! allocate, spawn helpers, label phases, draw random numbers.
//!
//! Every awaitable here is a small leaf future that re-checks its condition when polled, so a
//! spurious wake-up is harmless. Must never poll another program or hold the state borrow
//! across an `.await`.

use std::cell::RefCell;
use std::fmt;
use std::future::Future;
use std::pin::Pin;
use std::rc::Rc;
use std::task::{Context, Poll};

use rand_chacha::ChaCha12Rng;

use super::executor::{Event, SimError, State, Wait};
use super::rng::rng_stream;
use crate::machine::Counts;
use crate::net::NodeId;
use crate::units::{Bytes, SimTime};

/// What programs send. The tag is what `recv` can match on besides the source.
pub trait Payload: Clone + 'static {
    fn tag(&self) -> u32 {
        0
    }
}

impl Payload for () {}
impl Payload for u32 {}
impl Payload for u64 {}

/// A delivered message.
#[derive(Clone, Debug)]
pub struct Envelope<M> {
    pub src: NodeId,
    pub dst: NodeId,
    pub tag: u32,
    /// The size the machine was charged for (the payload itself may be smaller or larger).
    pub bytes: Bytes,
    pub payload: M,
    pub arrived: SimTime,
}

impl<M: Clone> Envelope<M> {
    pub(super) fn clone_for_broadcast(&self) -> Envelope<M> {
        self.clone()
    }
}

/// Which messages a `recv` accepts: one tag or any, one source or any.
///
/// One word (the tag in the low 32 bits, bit 32 set when a tag is asked for, the source plus
/// one above it, 0 for any), so that a `Receive`, a node handle and a filter, is two words
/// and moves in registers: built in memory and copied whole, as a larger one was, the copy's
/// wide loads waited for the narrow stores that built it, on every `recv`.
#[derive(Clone, Copy, Default, PartialEq, Eq)]
pub struct Filter(u64);

const TAG_GIVEN: u64 = 1 << 32;
const SOURCE_SHIFT: u32 = 33;

impl Filter {
    pub const ANY: Filter = Filter(0);

    pub fn tag(tag: u32) -> Filter {
        Filter(TAG_GIVEN | tag as u64)
    }
    pub fn source(src: NodeId) -> Filter {
        Filter::ANY.and_source(src)
    }
    pub fn and_source(self, src: NodeId) -> Filter {
        // A simulation has at most `MAX_NODE_ID` nodes (checked when it is built).
        assert!(
            src < MAX_NODE_ID,
            "node {src}: no simulation has such a node"
        );
        let tag_part = self.0 & (TAG_GIVEN | u32::MAX as u64);
        Filter(tag_part | ((src as u64 + 1) << SOURCE_SHIFT))
    }
    fn tag_of(self) -> Option<u32> {
        (self.0 & TAG_GIVEN != 0).then_some(self.0 as u32)
    }
    fn src_of(self) -> Option<NodeId> {
        match self.0 >> SOURCE_SHIFT {
            0 => None,
            s => Some((s - 1) as NodeId),
        }
    }
    #[inline]
    pub fn matches<M>(&self, env: &Envelope<M>) -> bool {
        self.accepts(env.tag, env.src)
    }
    /// Whether a message with `tag` from `src` passes.
    #[inline]
    pub fn accepts(&self, tag: u32, src: NodeId) -> bool {
        self.tag_of().is_none_or(|t| t == tag) && self.src_of().is_none_or(|s| s == src)
    }
}

/// Node ids a [`Filter`] can name: those below 2^31 - 1 (a machine has at most
/// `limits::MAX_NODES`, and PHOLD at most one logical process per event in flight).
pub(super) const MAX_NODE_ID: NodeId = (1 << 31) - 1;

impl fmt::Debug for Filter {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Filter")
            .field("tag", &self.tag_of())
            .field("src", &self.src_of())
            .finish()
    }
}

impl fmt::Display for Filter {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match (self.tag_of(), self.src_of()) {
            (None, None) => write!(f, "of any kind from anyone"),
            (Some(t), None) => write!(f, "with tag {t} from anyone"),
            (None, Some(s)) => write!(f, "of any kind from node {s}"),
            (Some(t), Some(s)) => write!(f, "with tag {t} from node {s}"),
        }
    }
}

/// A program's view of its node.
#[derive(Clone)]
pub struct Node<M: Payload> {
    id: NodeId,
    st: Rc<RefCell<State<M>>>,
}

impl<M: Payload> Node<M> {
    pub(super) fn new(id: NodeId, st: Rc<RefCell<State<M>>>) -> Node<M> {
        Node { id, st }
    }

    pub fn id(&self) -> NodeId {
        self.id
    }

    pub fn nodes(&self) -> u32 {
        self.st.borrow().nodes.len() as u32
    }

    pub fn now(&self) -> SimTime {
        self.st.borrow().now
    }

    /// Resumes (`true`) or pauses a recorded timeline from now on; nothing when the run
    /// records none. Changes what the run reports, never what it simulates.
    pub fn record_timeline(&self, on: bool) {
        self.st.borrow_mut().pause_timeline(!on);
    }

    /// Labels this program's following work for the per-phase busy-time report.
    pub fn phase(&self, label: &'static str) {
        let mut st = self.st.borrow_mut();
        let meta = st.meta();
        if !std::ptr::eq(meta.phase, label) {
            meta.phase = label;
            meta.phase_slot = None;
        }
    }

    /// Occupies this node's cpu for the cost of `counts` under the machine's cost table.
    pub fn compute(&self, counts: &Counts) -> Until<'_, M> {
        let t = {
            let mut st = self.st.borrow_mut();
            let t = st.cpu.costs.time(counts);
            st.unpriced_used |= st.cpu.costs.unpriced_in(counts);
            if t == SimTime::MAX {
                let cause = st.cpu.costs.largest_term(counts);
                st.overflow_cause = Some(cause);
            }
            t
        };
        self.compute_for(t)
    }

    /// Occupies this node's cpu for `t` (queued behind work already on it; on a time-sliced
    /// cpu a slice at a time, each queued when the one before ends).
    pub fn compute_for(&self, t: SimTime) -> Until<'_, M> {
        let mut st = self.st.borrow_mut();
        let (first, left) = match st.cpu.timeslice {
            Some(slice) if t > slice => (slice, t - slice),
            _ => (t, SimTime::ZERO),
        };
        let end = st.reserve_cpu(self.id, first, false);
        Until {
            node: self,
            at: end,
            armed: false,
            left,
            chained: false,
        }
    }

    /// Waits `t` without using the cpu.
    pub fn sleep(&self, t: SimTime) -> Until<'_, M> {
        let at = self.now() + t;
        Until {
            node: self,
            at,
            armed: false,
            left: SimTime::ZERO,
            chained: false,
        }
    }

    /// Sends `bytes` to `dst` through the network: the cpu pays the send overhead first; then
    /// the message travels; without communication overlap the program waits until delivery.
    pub async fn send(&self, dst: NodeId, bytes: Bytes, payload: M) {
        self.transmit(dst, false, bytes, payload).await
    }

    /// One transmission that reaches every other node (a bus's broadcast).
    pub async fn broadcast(&self, bytes: Bytes, payload: M) -> Result<(), SimError> {
        let supports = self
            .st
            .borrow()
            .net()
            .is_some_and(|n| n.supports_broadcast());
        if !supports {
            return Err(self
                .st
                .borrow()
                .fail("broadcast needs a bus network".into()));
        }
        self.transmit(self.id, true, bytes, payload).await;
        Ok(())
    }

    async fn transmit(&self, dst: NodeId, broadcast: bool, bytes: Bytes, payload: M) {
        let overhead = self.st.borrow().cpu.send_cost(bytes);
        if overhead > SimTime::ZERO {
            let end = self.st.borrow_mut().reserve_cpu(self.id, overhead, true);
            Until {
                node: self,
                at: end,
                armed: false,
                left: SimTime::ZERO,
                chained: false,
            }
            .await;
        }
        let blocking = !self.st.borrow().cpu.overlap;
        let injected = {
            let mut st = self.st.borrow_mut();
            let now = st.now;
            let tag = payload.tag();
            let env = Envelope {
                src: self.id,
                dst,
                tag,
                bytes,
                payload,
                arrived: now,
            };
            let notify = blocking.then_some(st.current);
            st.meta().delivered = false;
            st.inject(env, broadcast, notify);
            now
        };
        if blocking {
            Delivery { node: self, dst }.await;
            let mut st = self.st.borrow_mut();
            let waited = st.now - injected;
            let phase = st.meta().phase;
            let stats = &mut st.nodes[self.id as usize].stats;
            stats.charge(phase, waited);
            stats.comm += waited;
        }
    }

    /// Takes the first message in this node's mailbox that `filter` accepts (in arrival
    /// order), waiting for one if none is there, then pays the receive overhead.
    pub fn recv(&self, filter: Filter) -> Receive<'_, M> {
        Receive { node: self, filter }
    }

    /// Delivers `payload` to `dst`'s mailbox after `delay`, with no network or cpu cost: a
    /// timer, or an abstract event (PHOLD).
    pub fn post(&self, dst: NodeId, delay: SimTime, payload: M) {
        let mut st = self.st.borrow_mut();
        let at = st.now + delay;
        st.schedule(
            at,
            Event::Post {
                src: self.id,
                dst,
                payload,
            },
        );
    }

    /// Starts a helper program on this node that must finish before the run ends.
    pub fn spawn<F>(&self, name: impl Into<String>, program: F)
    where
        F: Future<Output = Result<(), SimError>> + 'static,
    {
        self.st
            .borrow_mut()
            .register_program(self.id, name.into(), false, Box::pin(program));
    }

    /// Starts a helper program (a message handler) that may still be waiting when the run
    /// ends without that being a deadlock.
    pub fn spawn_daemon<F>(&self, name: impl Into<String>, program: F)
    where
        F: Future<Output = Result<(), SimError>> + 'static,
    {
        self.st
            .borrow_mut()
            .register_program(self.id, name.into(), true, Box::pin(program));
    }

    /// Allocates from this node's memory pool; over capacity is an error naming node, tag,
    /// requested and available bytes.
    pub fn alloc(&self, tag: &'static str, bytes: Bytes) -> Result<(), SimError> {
        let mut st = self.st.borrow_mut();
        let result = st.nodes[self.id as usize].pool.alloc(tag, bytes);
        result.map_err(|e| st.memory_error(e))
    }

    pub fn free(&self, tag: &'static str, bytes: Bytes) -> Result<(), SimError> {
        let mut st = self.st.borrow_mut();
        let result = st.nodes[self.id as usize].pool.free(tag, bytes);
        result.map_err(|e| st.memory_error(e))
    }

    pub fn memory_available(&self) -> Bytes {
        self.st.borrow().nodes[self.id as usize].pool.available()
    }

    /// The random stream `name` of this run (derived from the run's seed).
    pub fn rng(&self, name: &str) -> ChaCha12Rng {
        rng_stream(self.st.borrow().seed, name)
    }

    /// An error that stops the run, naming this program, node, time and seed.
    pub fn error(&self, message: impl Into<String>) -> SimError {
        self.st.borrow().fail(message.into())
    }
}

/// Resolves once the clock reaches `at` and no cpu work is `left` to queue.
pub struct Until<'a, M: Payload> {
    node: &'a Node<M>,
    at: SimTime,
    armed: bool,
    /// Computation still to queue, a slice at a time, once the slice ending at `at` is done.
    left: SimTime,
    /// The executor reserves the slices (a chain, `slices.rs`) until the program wakes.
    chained: bool,
}

impl<M: Payload> Future for Until<'_, M> {
    type Output = ();
    fn poll(mut self: Pin<&mut Self>, _cx: &mut Context<'_>) -> Poll<()> {
        let node = self.node;
        let mut st = node.st.borrow_mut();
        if self.chained {
            let p = st.current;
            let Some(left) = st.slices.resume(p) else {
                return Poll::Pending;
            };
            // Woken at the end of a slice, as the plain way wakes it.
            (self.at, self.left, self.chained) = (st.now, left, false);
        }
        if st.now >= self.at && self.left > SimTime::ZERO {
            // Behind whatever other programs queued during the slice just ended.
            let slice = st.cpu.timeslice.expect("work is left only on a sliced cpu");
            let next = self.left.min(slice);
            self.at = st.reserve_cpu(node.id, next, false);
            self.left = self.left - next;
            self.armed = false;
        }
        if st.now >= self.at {
            return Poll::Ready(());
        }
        if !self.armed {
            let p = st.current;
            // With work left on a sliced cpu, the executor reserves the slices until the last
            // one ends or another program reserves this cpu (`slices.rs`).
            self.chained =
                self.left > SimTime::ZERO && st.chain_slices(node.id, p, self.at, self.left);
            if !self.chained {
                st.schedule(self.at, Event::Wake(p));
            }
            st.meta().wait = Wait::Time(self.at);
            drop(st);
            self.armed = true;
        }
        Poll::Pending
    }
}

/// Resolves to a message once one that the filter accepts has arrived and the cpu has paid
/// the receive overhead for it.
pub struct Receive<'a, M: Payload> {
    node: &'a Node<M>,
    filter: Filter,
}

impl<M: Payload> Future for Receive<'_, M> {
    type Output = Envelope<M>;
    fn poll(self: Pin<&mut Self>, _cx: &mut Context<'_>) -> Poll<Envelope<M>> {
        let (id, filter) = (self.node.id, self.filter);
        let mut st = self.node.st.borrow_mut();
        let p = st.current;
        let st = &mut *st;
        let node = &mut st.nodes[id as usize];
        let env = match st.handoffs.take(&mut node.handoff, p) {
            Some((env, false)) => env,
            Some((env, true)) => return st.paid(id, p, env),
            None => match node.mailbox_position(filter) {
                Some(i) => node.mailbox.remove(i).expect("position is in range"),
                None => {
                    // Registered once: a program waits in one `recv` at a time, and it leaves
                    // the waiters only when a message is handed to it.
                    if !node.waiters.iter().any(|&(w, _)| w == p) {
                        node.waiters.push((p, filter));
                    }
                    return Poll::Pending;
                }
            },
        };
        let cost = st.cpu.recv_cost(env.bytes);
        if cost == SimTime::ZERO {
            return Poll::Ready(env);
        }
        // The message waits, handed to this program and marked paid, until its receive
        // overhead is: kept on the node rather than in this future, which stays two words.
        let until = st.reserve_cpu(id, cost, true);
        st.schedule(until, Event::Wake(p));
        st.meta().wait = Wait::Time(until);
        st.handoffs
            .put_paid(&mut st.nodes[id as usize].handoff, p, env);
        Poll::Pending
    }
}

struct Delivery<'a, M: Payload> {
    node: &'a Node<M>,
    dst: NodeId,
}

impl<M: Payload> Future for Delivery<'_, M> {
    type Output = ();
    fn poll(self: Pin<&mut Self>, _cx: &mut Context<'_>) -> Poll<()> {
        let mut st = self.node.st.borrow_mut();
        if st.meta().delivered {
            return Poll::Ready(());
        }
        st.meta().wait = Wait::Delivery(self.dst);
        Poll::Pending
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn envelope(tag: u32, src: NodeId) -> Envelope<()> {
        Envelope {
            src,
            dst: 0,
            tag,
            bytes: Bytes::ZERO,
            payload: (),
            arrived: SimTime::ZERO,
        }
    }

    proptest::proptest! {
        /// The one-word filter accepts exactly what a tag or any and a source or any accept,
        /// at the ends of both ranges too (a tag of 2^32 - 1, the largest node id).
        #[test]
        fn a_filter_in_one_word_accepts_what_its_tag_and_source_say(
            tag in proptest::option::of(proptest::prop_oneof![0..4u32, proptest::prelude::Just(u32::MAX)]),
            src in proptest::option::of(proptest::prop_oneof![0..4u32, proptest::prelude::Just(MAX_NODE_ID - 1)]),
            msg_tag in proptest::prop_oneof![0..4u32, proptest::prelude::Just(u32::MAX)],
            msg_src in proptest::prop_oneof![0..4u32, proptest::prelude::Just(MAX_NODE_ID - 1)],
        ) {
            let filter = match (tag, src) {
                (None, None) => Filter::ANY,
                (Some(t), None) => Filter::tag(t),
                (None, Some(s)) => Filter::source(s),
                (Some(t), Some(s)) => Filter::tag(t).and_source(s),
            };
            proptest::prop_assert_eq!((filter.tag_of(), filter.src_of()), (tag, src));
            let want = tag.is_none_or(|t| t == msg_tag) && src.is_none_or(|s| s == msg_src);
            proptest::prop_assert_eq!(filter.matches(&envelope(msg_tag, msg_src)), want);
        }
    }

    /// A `Receive` is a node handle and a filter, two words, so that it moves in registers.
    #[test]
    fn a_receive_is_two_words() {
        assert_eq!(std::mem::size_of::<Receive<'_, ()>>(), 16);
    }
}
