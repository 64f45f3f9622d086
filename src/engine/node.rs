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

/// Which messages a `recv` accepts.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Filter {
    tag: Option<u32>,
    src: Option<NodeId>,
}

impl Filter {
    pub const ANY: Filter = Filter {
        tag: None,
        src: None,
    };

    pub fn tag(tag: u32) -> Filter {
        Filter {
            tag: Some(tag),
            src: None,
        }
    }
    pub fn source(src: NodeId) -> Filter {
        Filter {
            tag: None,
            src: Some(src),
        }
    }
    pub fn and_source(self, src: NodeId) -> Filter {
        Filter {
            src: Some(src),
            ..self
        }
    }
    pub fn matches<M>(&self, env: &Envelope<M>) -> bool {
        self.tag.is_none_or(|t| t == env.tag) && self.src.is_none_or(|s| s == env.src)
    }
}

impl fmt::Display for Filter {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match (self.tag, self.src) {
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
        self.st.borrow_mut().meta().phase = label;
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
        Receive {
            node: self,
            filter,
            registered: false,
            paying: None,
        }
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
}

impl<M: Payload> Future for Until<'_, M> {
    type Output = ();
    fn poll(mut self: Pin<&mut Self>, _cx: &mut Context<'_>) -> Poll<()> {
        let node = self.node;
        let mut st = node.st.borrow_mut();
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
            st.schedule(self.at, Event::Wake(p));
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
    registered: bool,
    /// The message taken, and when its receive overhead will have been paid.
    paying: Option<(Envelope<M>, SimTime)>,
}

// Nothing in a `Receive` is ever pinned in place: the envelope is moved out by value.
impl<M: Payload> Unpin for Receive<'_, M> {}

impl<M: Payload> Future for Receive<'_, M> {
    type Output = Envelope<M>;
    fn poll(mut self: Pin<&mut Self>, _cx: &mut Context<'_>) -> Poll<Envelope<M>> {
        let this = &mut *self;
        let mut st = this.node.st.borrow_mut();
        if let Some((_, until)) = &this.paying {
            return if st.now >= *until {
                Poll::Ready(this.paying.take().expect("checked").0)
            } else {
                Poll::Pending
            };
        }
        let p = st.current;
        let filter = this.filter;
        let st = &mut *st;
        let node = &mut st.nodes[this.node.id as usize];
        let env = match st.handoffs.take(&mut node.handoff, p) {
            Some(env) => env,
            None => match node.mailbox.iter().position(|e| filter.matches(e)) {
                Some(i) => node.mailbox.remove(i).expect("position is in range"),
                None => {
                    // Not registered yet, or woken for a message another program took.
                    if !this.registered || !node.waiters.iter().any(|&(w, _)| w == p) {
                        node.waiters.push((p, filter));
                        this.registered = true;
                    }
                    return Poll::Pending;
                }
            },
        };
        let cost = st.cpu.recv_cost(env.bytes);
        if cost == SimTime::ZERO {
            return Poll::Ready(env);
        }
        let until = st.reserve_cpu(this.node.id, cost, true);
        let p = st.current;
        st.schedule(until, Event::Wake(p));
        st.meta().wait = Wait::Time(until);
        this.paying = Some((env, until));
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
