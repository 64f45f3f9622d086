//! The simulation state and the executor loop: pops events in (time, sequence) order, turns
//! them into wake-ups, and polls node programs until they wait again.
//!
//! Owns the clock, the queue, program bookkeeping and message hand-off between the network
//! model and mailboxes. Must never expose the queue or the clock to programs except through
//! `Node`, and never poll a program while holding the state borrow.

use std::cell::RefCell;
use std::collections::VecDeque;
use std::fmt;
use std::future::Future;
use std::pin::Pin;
use std::ptr::NonNull;
use std::rc::Rc;
use std::task::{Context, Poll, Waker};

use smallvec::SmallVec;

use super::node::{Envelope, Filter, Node, Payload};
use super::queue::{EventQueue, LookAhead, Place};
use super::slices::{Chain, Slices};
use super::stats::{CpuSpan, CpuTimeline, NodeStats, RunStats};
use super::wakes::NetWakes;
use crate::machine::{CpuConfig, MachineConfig, MemError, MemoryPool};
use crate::net::{Delivered, Dest, MsgId, Network, NodeId};
use crate::units::{Bytes, SimTime};

/// A program's index in the simulation, in spawn order.
pub type ProgramId = u32;

type Program = Pin<Box<dyn Future<Output = Result<(), SimError>>>>;

/// Why a run stopped without finishing.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    #[error("deadlock at {at} (seed {seed}): the event queue is empty but {} program(s) still wait:\n{}", waiting.len(), list(waiting))]
    Deadlock {
        at: SimTime,
        seed: u64,
        waiting: Vec<WaitingProgram>,
    },
    #[error("program '{program}' on node {node} failed at {at} (seed {seed}): {source}")]
    Memory {
        program: String,
        node: NodeId,
        at: SimTime,
        seed: u64,
        source: MemError,
    },
    /// A charge past the largest simulated time: the machine's costs are too large for the
    /// run (the user's to fix, like a memory pool too small).
    #[error("program '{program}' on node {node} at {at} (seed {seed}): {message}")]
    TimeOverflow {
        program: String,
        node: NodeId,
        at: SimTime,
        seed: u64,
        message: String,
    },
    #[error("program '{program}' on node {node} failed at {at} (seed {seed}): {message}")]
    Program {
        program: String,
        node: NodeId,
        at: SimTime,
        seed: u64,
        message: String,
    },
}

/// A program left waiting when the queue emptied.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct WaitingProgram {
    pub name: String,
    pub node: NodeId,
    pub waits_for: String,
}

fn list(waiting: &[WaitingProgram]) -> String {
    waiting
        .iter()
        .map(|w| {
            format!(
                "  - '{}' on node {} waits for {}",
                w.name, w.node, w.waits_for
            )
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// What a program is blocked on, for deadlock reports.
#[derive(Clone, Copy, Debug)]
pub(super) enum Wait {
    Nothing,
    Time(SimTime),
    Message(Filter),
    Delivery(NodeId),
}

impl fmt::Display for Wait {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Wait::Nothing => write!(f, "nothing (it never ran to completion)"),
            Wait::Time(t) => write!(f, "the clock to reach {t}"),
            Wait::Message(filter) => write!(f, "a message {filter}"),
            Wait::Delivery(dst) => write!(f, "its blocking send to node {dst} to be delivered"),
        }
    }
}

pub(super) enum Event<M> {
    Wake(ProgramId),
    /// A message whose arrival time the network knew at injection.
    Arrive(MsgId),
    /// The end of a slice of a chain (`slices.rs`): of its program's computation on a node.
    Slice(ProgramId, NodeId),
    /// A message posted directly into a mailbox, bypassing network and cpu (timers, PHOLD).
    /// Kept small: heap entries are moved on every push and pop.
    Post {
        src: NodeId,
        dst: NodeId,
        payload: M,
    },
}

pub(super) struct ProgramMeta {
    pub name: String,
    pub node: NodeId,
    /// Daemons (message handlers) may still be waiting when the run ends.
    pub daemon: bool,
    pub done: bool,
    pub phase: &'static str,
    /// Where `phase` sits among its node's busy times, once a charge has found it: a program
    /// charges one phase many times over, and finding it is a search of its node's phases.
    pub phase_slot: Option<u32>,
    pub wait: Wait,
    /// Set when a blocking send this program waits on has been delivered.
    pub delivered: bool,
    /// Whether the look ahead warms this program's state: it is its node's first
    /// (`State::first_program`).
    pub warmed: bool,
}

struct InFlight<M> {
    env: Envelope<M>,
    broadcast: bool,
    /// A program blocked until delivery (sends without communication overlap).
    notify: Option<ProgramId>,
}

/// A node's state. What a message's hand-over and the next `recv` touch fill the node's first
/// two cache lines (a run with many nodes takes most of its time missing in cache on them):
/// the waiters and the mailbox the first, the received counters and the message handed over
/// the second. With the counters among the other statistics, on a third line, a delivery
/// missed one line more (PHOLD, 16,384 logical processes: docs/performance.md).
#[repr(C, align(64))]
pub(super) struct NodeState<M> {
    /// Programs waiting for a message, one as a rule: kept inline, so handing a message over
    /// touches no memory beyond the node's own.
    pub waiters: SmallVec<[(ProgramId, Filter); 1]>,
    pub mailbox: VecDeque<Envelope<M>>,
    /// What every delivery counts; [`NodeStats`] takes them when a run's counters are read.
    pub received: Received,
    /// The message handed over to one of its programs, as a rule the only one ([`Handoffs`]).
    pub handoff: Handoff<M>,
    pub cpu_free_at: SimTime,
    pub stats: NodeStats,
    pub pool: MemoryPool,
}

/// The bytes and messages delivered to a node.
#[derive(Clone, Copy, Default)]
pub(super) struct Received {
    pub bytes: Bytes,
    pub messages: u64,
}

impl<M> NodeState<M> {
    /// The first program waiting for a message with `tag` from `src`, no longer waiting. The
    /// one waiter a node has as a rule leaves by a pop, which moves nothing.
    #[inline(always)]
    fn take_waiter(&mut self, tag: u32, src: NodeId) -> Option<ProgramId> {
        let i = self.waiters.iter().position(|(_, f)| f.accepts(tag, src))?;
        let (p, _) = if i + 1 == self.waiters.len() {
            self.waiters.pop()?
        } else {
            self.waiters.swap_remove(i)
        };
        Some(p)
    }

    /// Where the first message in the mailbox that `filter` accepts is. An empty mailbox,
    /// the rule when a program waits, is answered without walking it.
    #[inline]
    pub fn mailbox_position(&self, filter: Filter) -> Option<usize> {
        if self.mailbox.is_empty() {
            return None;
        }
        self.mailbox.iter().position(|e| filter.matches(e))
    }

    /// The node's statistics with the received counters in them.
    fn stats(&self) -> NodeStats {
        NodeStats {
            bytes_received: self.received.bytes,
            messages_received: self.received.messages,
            ..self.stats.clone()
        }
    }
}

/// Messages handed straight to programs that were waiting for them, until each runs, one per
/// program: a node's first on the node (`NodeState::handoff`), where a `recv` looks first;
/// the rest (several only when a node's programs are handed messages before any of them runs)
/// in one list of the run's, so that the node's second cache line holds the one it has as a
/// rule and nothing else.
pub(super) struct Handoffs<M> {
    more: Vec<(ProgramId, bool, Envelope<M>)>,
}

impl<M> Default for Handoffs<M> {
    fn default() -> Self {
        Handoffs { more: Vec::new() }
    }
}

/// The message handed over that a node keeps on itself: the program it is for, whether that
/// program has taken it and is paying its receive overhead (then it is ready when the
/// program's wait for the clock is over), and the message.
pub(super) type Handoff<M> = Option<(ProgramId, bool, Envelope<M>)>;

impl<M> Handoffs<M> {
    /// Hands `env` to program `p` of the node whose own hand-off slot is `first`.
    #[inline(always)]
    fn put(&mut self, first: &mut Handoff<M>, p: ProgramId, env: Envelope<M>) {
        self.put_as(first, p, false, env);
    }

    /// Gives `env` back to program `p`, which took it and now pays its receive overhead.
    pub fn put_paid(&mut self, first: &mut Handoff<M>, p: ProgramId, env: Envelope<M>) {
        self.put_as(first, p, true, env);
    }

    #[inline(always)]
    fn put_as(&mut self, first: &mut Handoff<M>, p: ProgramId, paid: bool, env: Envelope<M>) {
        match first {
            None => *first = Some((p, paid, env)),
            Some(_) => self.more.push((p, paid, env)),
        }
    }

    /// The message handed to program `p` of the node whose own slot is `first`, if one was,
    /// and whether it is one `p` took and is paying for.
    pub fn take(&mut self, first: &mut Handoff<M>, p: ProgramId) -> Option<(Envelope<M>, bool)> {
        if first.as_ref().is_some_and(|&(q, _, _)| q == p) {
            return first.take().map(|(_, paid, env)| (env, paid));
        }
        let i = self.more.iter().position(|&(q, _, _)| q == p)?;
        let (_, paid, env) = self.more.swap_remove(i);
        Some((env, paid))
    }
}

pub(super) struct State<M> {
    pub now: SimTime,
    pub seed: u64,
    pub queue: EventQueue<Event<M>>,
    pub ready: VecDeque<ProgramId>,
    pub current: ProgramId,
    pub programs: Vec<ProgramMeta>,
    pub spawned: Vec<Program>,
    pub nodes: Vec<NodeState<M>>,
    pub handoffs: Handoffs<M>,
    /// Where each node's first program keeps its state, while it runs, for the look ahead
    /// (`warm_for_next`): a word a node, so that with many nodes the table itself stays in
    /// cache (at 32 bytes a node, PHOLD's 16,384 processes missed on it).
    first_program: Vec<Option<Warm>>,
    /// Whether the look ahead runs: only with enough nodes that their records and programs
    /// miss in cache ([`LOOK_AHEAD_NODES`]); with fewer it is work that saves nothing.
    look_ahead: bool,
    pub cpu: CpuConfig,
    net: Option<Network>,
    net_wakes: NetWakes,
    /// Computations whose slices the executor reserves for their programs (`slices.rs`).
    pub slices: Slices,
    /// Every slice's end a wake-up and a poll of its program, as before chains: the plain
    /// way, kept as the oracle the tests compare chains against.
    every_slice_an_event: bool,
    in_flight: Vec<Option<InFlight<M>>>,
    free_slots: Vec<usize>,
    delivered: Vec<Delivered>,
    pub events: u64,
    /// Cpu spans, when the run records a timeline (off by default: it costs memory).
    timeline: Option<CpuTimeline>,
    /// The timeline is recorded but paused (outside the frames it covers).
    timeline_paused: bool,
    /// A charge that would end past the largest simulated time: the run stops with it at the
    /// next step (checked in the step's one borrow of the state), as the charging program
    /// cannot return an error from inside `compute`.
    overflow: Option<SimError>,
    /// What made the charge `compute` is about to reserve too long, when it was.
    pub overflow_cause: Option<String>,
    /// Operations charged that the machine does not price (bits over `Op`): they cost
    /// nothing, and the run's summary says so.
    pub unpriced_used: u32,
}

impl<M: Payload> State<M> {
    #[inline]
    pub fn schedule(&mut self, at: SimTime, event: Event<M>) {
        debug_assert!(at >= self.now, "an event was scheduled in the past");
        let node = if self.look_ahead {
            self.delivered_to(&event)
        } else {
            None
        };
        self.queue.push_hinted(at, event, node);
    }

    /// The node whose record the event's delivery reads first, for the look ahead.
    #[inline]
    fn delivered_to(&self, event: &Event<M>) -> Option<NodeId> {
        match *event {
            Event::Post { dst, .. } => Some(dst),
            Event::Arrive(id) => self.in_flight[id as usize]
                .as_ref()
                .filter(|f| !f.broadcast)
                .map(|f| f.env.dst),
            Event::Wake(_) | Event::Slice(..) => None,
        }
    }

    /// Pauses or resumes a recorded timeline: its cpu spans and its links' occupancy. No cpu
    /// span recorded before it is lengthened after it.
    pub fn pause_timeline(&mut self, paused: bool) {
        self.timeline_paused = paused;
        if let Some(timeline) = &mut self.timeline {
            timeline.cut();
        }
        if let Some(net) = self.net.as_mut() {
            net.pause_occupancy(paused);
        }
    }

    pub fn meta(&mut self) -> &mut ProgramMeta {
        &mut self.programs[self.current as usize]
    }

    /// Queues `t` of work on `node`'s cpu, first come first served; returns when it ends.
    pub fn reserve_cpu(&mut self, node: NodeId, t: SimTime, comm: bool) -> SimTime {
        self.slices.end_on(node);
        let meta = &self.programs[self.current as usize];
        // The program's own node keeps its phase's place (a charge to another node finds it).
        let own_node = meta.node == node;
        let (phase, slot) = (meta.phase, meta.phase_slot.filter(|_| own_node));
        let now = self.now;
        let start = self.nodes[node as usize].cpu_free_at.max(now);
        // SimTime::MAX is also what an overflowing cost-table charge saturates to.
        let Some(end) = start.checked_add(t).filter(|_| t < SimTime::MAX) else {
            if self.overflow.is_none() {
                let meta = &self.programs[self.current as usize];
                self.overflow = Some(SimError::TimeOverflow {
                    program: meta.name.clone(),
                    node: meta.node,
                    at: now,
                    seed: self.seed,
                    message: format!(
                    "a charge to the cpu in phase '{phase}' of {} ({}) would end past the \
                     largest simulated time, {} (u64 picoseconds); the machine's costs are too \
                     large for this run",
                    if t == SimTime::MAX { "more than that".to_string() } else { t.to_string() },
                    match (comm, self.overflow_cause.take()) {
                        (true, _) => "a message's cpu.send_overhead or cpu.recv_overhead and its per-byte cost".to_string(),
                        (false, Some(cause)) => cause,
                        (false, None) => "work on the cpu".to_string(),
                    },
                    SimTime::MAX
                ),
                });
            }
            return SimTime::MAX;
        };
        let n = &mut self.nodes[node as usize];
        n.cpu_free_at = end;
        match slot {
            Some(slot) => n.stats.charge_at(slot as usize, t),
            None => {
                let slot = n.stats.charge(phase, t) as u32;
                if own_node {
                    self.programs[self.current as usize].phase_slot = Some(slot);
                }
            }
        }
        if comm {
            n.stats.comm += t;
        }
        if let Some(timeline) = &mut self.timeline {
            if t > SimTime::ZERO && !self.timeline_paused {
                timeline.record(CpuSpan {
                    node,
                    phase,
                    start,
                    end,
                });
            }
        }
        end
    }

    /// Starts a chain (`slices.rs`) for program `p`, whose slice on `node` ends at `at` with
    /// `left` work after it; false where its wake-ups stay the program's: on the oracle's
    /// plain way, or for work that would end past the largest time (the plain way reports
    /// that when it gets there).
    pub fn chain_slices(&mut self, node: NodeId, p: ProgramId, at: SimTime, left: SimTime) -> bool {
        if self.every_slice_an_event || at.checked_add(left).is_none() {
            return false;
        }
        self.slices.start(node, p, left, at);
        self.schedule(at, Event::Slice(p, node));
        true
    }

    /// A slice of program `p`'s computation on `node` ends at `first`: if its chain still
    /// runs, the next slice is reserved, as the program would on waking (`Until`), and so
    /// is every slice after it that ends before anything else is due (a slice reserved now
    /// ends at a place after every one taken so far at its instant, so it comes before
    /// anything at a later instant and after everything at its own); then the next slice
    /// event is queued, or, after the last slice, the program's wake-up. If the chain has
    /// ended, the program wakes now (returned). Slices are not reserved past `horizon`, as a
    /// program's wake-ups would not be taken.
    #[cold]
    #[inline(never)]
    fn next_slices(
        &mut self,
        p: ProgramId,
        node: NodeId,
        first: SimTime,
        horizon: SimTime,
    ) -> Option<ProgramId> {
        let Some(mut chain) = self.slices.take(node, p) else {
            return Some(p);
        };
        let net = self.net_wakes.due(self.queue.last_taken()).map(Place::time);
        if net.is_none()
            && self.slices.running() > 0
            && self.queue.len() == self.slices.running()
            && self.chains_in_rounds((node, chain), horizon)
        {
            return None;
        }
        let bound = SimTime::earliest(self.queue.peek_time(), net).unwrap_or(SimTime::MAX);
        let slice = self.cpu.timeslice.expect("chains run on a sliced cpu");
        // Slice ends at `first`, `first + slice`, ... before `bound` and within `horizon`,
        // each reserving a slice, until the work is all reserved.
        let before_bound = bound.ps().saturating_sub(first.ps()).div_ceil(slice.ps());
        let within_horizon = ((horizon.ps() - first.ps()) / slice.ps()).saturating_add(1);
        let to_exhaust = chain.left.ps().div_ceil(slice.ps());
        let ends = before_bound.min(within_horizon).min(to_exhaust).max(1);
        let work = chain.left.min(slice.times(ends));
        // The slice event taken counted one of the ends.
        self.events += ends - 1;
        self.current = p;
        // One charge for every slice: on a timeline they are one span either way.
        let end = self.reserve_cpu(node, work, false);
        self.now = first + slice.times(ends - 1);
        chain.left = chain.left - work;
        if chain.left > SimTime::ZERO {
            self.slices.start(node, p, chain.left, end);
            self.schedule(end, Event::Slice(p, node));
        } else {
            self.slices.resume_with(p, SimTime::ZERO);
            self.schedule(end, Event::Wake(p));
        }
        self.programs[p as usize].wait = Wait::Time(end);
        None
    }

    /// Whole rounds of every chain at once, when the queue holds nothing but the chains'
    /// slice events (each running chain has exactly one queued) and no network wake-up is
    /// due: `first` (the chain whose event was just taken, on its node) and the others, in
    /// the queue's order. Each round takes every chain's slice end in that same order (a
    /// chain's next end is queued after the others' ends of the round, at most a slice
    /// later), and each end reserves the next slice of its chain on its own node, which no
    /// other end touches; so `R` rounds are `R` slices reserved on each node at once, and
    /// the chains' events queued again in the order they were taken. Rounds stop before any
    /// chain's last slice (its program wakes then) and at `horizon`. False, with nothing
    /// done, when not one whole round fits.
    fn chains_in_rounds(&mut self, first: (NodeId, Chain), horizon: SimTime) -> bool {
        let slice = self.cpu.timeslice.expect("chains run on a sliced cpu");
        // Every chain keeps work for a slice after the rounds, and the latest end taken in a
        // round (the last chain's) stays within the horizon: one pass over the chains.
        let rounds_left = |c: &Chain| c.left.ps().div_ceil(slice.ps()) - 1;
        let (mut rounds, latest) = self.slices.chains().fold(
            (rounds_left(&first.1), first.1.at),
            |(rounds, latest), c| (rounds.min(rounds_left(c)), latest.max(c.at)),
        );
        rounds = rounds.min(match horizon.ps().checked_sub(latest.ps()) {
            Some(room) => (room / slice.ps()).saturating_add(1),
            None => 0,
        });
        if rounds == 0 {
            return false;
        }
        let mut order = vec![first];
        while let Some((at, event)) = self.queue.pop() {
            let Event::Slice(p, node) = event else {
                unreachable!("only the chains' slice events are queued")
            };
            let chain = self.slices.take(node, p).expect("a running chain's event");
            debug_assert_eq!(chain.at, at, "a chain's event is queued where it says");
            order.push((node, chain));
        }
        let work = slice.times(rounds);
        for &(node, chain) in &order {
            (self.now, self.current) = (chain.at, chain.program);
            let end = self.reserve_cpu(node, work, false);
            self.slices
                .start(node, chain.program, chain.left - work, end);
            self.schedule(end, Event::Slice(chain.program, node));
            self.programs[chain.program as usize].wait = Wait::Time(end);
        }
        // The event taken counted the first end.
        self.events += rounds * order.len() as u64 - 1;
        self.now = latest + slice.times(rounds - 1);
        true
    }

    pub fn register_program(&mut self, node: NodeId, name: String, daemon: bool, program: Program) {
        let first = &mut self.first_program[node as usize];
        let warmed = first.is_none();
        if warmed {
            *first = Some(Warm::of(&program));
        }
        self.programs.push(ProgramMeta {
            name,
            node,
            daemon,
            done: false,
            phase: "run",
            phase_slot: None,
            wait: Wait::Nothing,
            delivered: false,
            warmed,
        });
        self.spawned.push(program);
    }

    /// Hands a message to the network at `now`, unless it could arrive past the largest
    /// simulated time (then the run stops with that error).
    pub fn inject(&mut self, env: Envelope<M>, broadcast: bool, notify: Option<ProgramId>) {
        let (src, dst, bytes) = (env.src, env.dst, env.bytes);
        let now = self.now;
        let net = self
            .net
            .as_mut()
            .expect("this simulation was built without a network; use Node::post");
        if let Err(bound) = net.admit(now, bytes) {
            self.refuse_past_the_horizon(bytes, bound);
            return;
        }
        let stats = &mut self.nodes[src as usize].stats;
        stats.bytes_sent += bytes;
        stats.messages_sent += 1;
        let slot = match self.free_slots.pop() {
            Some(i) => i,
            None => {
                self.in_flight.push(None);
                self.in_flight.len() - 1
            }
        };
        self.in_flight[slot] = Some(InFlight {
            env,
            broadcast,
            notify,
        });
        let id = slot as MsgId;
        let dest = if broadcast {
            Dest::Broadcast
        } else {
            Dest::Node(dst)
        };
        let net = self
            .net
            .as_mut()
            .expect("this simulation was built without a network; use Node::post");
        match net.inject(now, id, src, dest, bytes) {
            Some(at) => self.schedule(at, Event::Arrive(id)),
            None => self.arm_net_wake(),
        }
    }

    /// Stops the run at a message of `bytes` the network could deliver only past the largest
    /// simulated time, everything sent so far taking up to `bound` picoseconds.
    #[cold]
    fn refuse_past_the_horizon(&mut self, bytes: Bytes, bound: u128) {
        if self.overflow.is_some() {
            return;
        }
        let meta = &self.programs[self.current as usize];
        self.overflow = Some(SimError::TimeOverflow {
            program: meta.name.clone(),
            node: meta.node,
            at: self.now,
            seed: self.seed,
            message: format!(
                "a message of {bytes} could arrive past the largest simulated time, {} (u64 \
                 picoseconds): the messages sent so far, one after another over the slowest \
                 link, could take until {:.3e} s; the network's message_gap, hop latency or \
                 link bandwidth is too large for this run",
                SimTime::MAX,
                bound as f64 / 1e12
            ),
        });
    }

    fn arm_net_wake(&mut self) {
        if let Some(t) = self.net.as_ref().and_then(Network::next_event_time) {
            self.net_wakes.arm(t, &mut self.queue);
        }
    }

    /// The network's wake-up at the current instant (`NetWakes::take` has disarmed it).
    fn net_wake(&mut self) {
        let mut delivered = std::mem::take(&mut self.delivered);
        self.net
            .as_mut()
            .expect("network wake-up without a network")
            .advance(self.now, &mut delivered);
        for d in delivered.drain(..) {
            debug_assert_eq!(
                d.at, self.now,
                "the network delivered at another instant than asked"
            );
            self.arrive(d.msg);
        }
        self.delivered = delivered;
        self.arm_net_wake();
        self.warm_next_delivered();
    }

    /// Asks the cpu for the record of the message the network delivers next, when it knows
    /// which: written when the message was sent and read only on its arrival, that record is
    /// otherwise a cache miss per message, and the events until the wake-up hide it. Changes
    /// nothing.
    fn warm_next_delivered(&self) {
        let next = self.net.as_ref().and_then(Network::next_delivered);
        // Its address only: reading the slot here would wait for the very miss.
        if let Some(slot) = next.and_then(|m| self.in_flight.get(m as usize)) {
            let start = std::ptr::from_ref(slot).cast::<u8>();
            prefetch(start);
            prefetch(start.wrapping_add(size_of_val(slot) - 1));
        }
    }

    fn arrive(&mut self, id: MsgId) {
        let flight = self.in_flight[id as usize]
            .take()
            .expect("a message arrived twice");
        self.free_slots.push(id as usize);
        if let Some(p) = flight.notify {
            self.programs[p as usize].delivered = true;
            self.ready.push_back(p);
        }
        let mut env = flight.env;
        env.arrived = self.now;
        if flight.broadcast {
            for dst in 0..self.nodes.len() as NodeId {
                if dst != env.src {
                    let mut copy = env.clone_for_broadcast();
                    copy.dst = dst;
                    self.deliver(copy);
                }
            }
        } else {
            self.deliver(env);
        }
    }

    /// The message program `p` of node `node` took and is paying for, once the wait for its
    /// receive overhead is over; until then it stays where it was.
    pub fn paid(&mut self, node: NodeId, p: ProgramId, env: Envelope<M>) -> Poll<Envelope<M>> {
        match self.programs[p as usize].wait {
            Wait::Time(until) if self.now < until => {
                let slot = &mut self.nodes[node as usize].handoff;
                self.handoffs.put_paid(slot, p, env);
                Poll::Pending
            }
            _ => Poll::Ready(env),
        }
    }

    /// Hands a message to the first program on its destination waiting for one like it, or
    /// else puts it in the destination's mailbox.
    #[inline]
    pub fn deliver(&mut self, env: Envelope<M>) {
        let (src, dst, tag, bytes) = (env.src, env.dst, env.tag, env.bytes);
        if let Some(p) = self.deliver_made(src, dst, tag, bytes, move || env) {
            self.ready.push_back(p);
        }
    }

    /// [`State::deliver`] of the envelope `make` builds, from `src` to `dst` with `tag` and
    /// `bytes`: built where it goes (a program's hand-off or the mailbox), as built first and
    /// moved there, the move's wide loads would wait for the narrow stores that built it.
    /// Returns the program the message was handed to, which the caller makes ready.
    #[inline(always)]
    #[must_use]
    fn deliver_made(
        &mut self,
        src: NodeId,
        dst: NodeId,
        tag: u32,
        bytes: Bytes,
        make: impl FnOnce() -> Envelope<M>,
    ) -> Option<ProgramId> {
        let node = &mut self.nodes[dst as usize];
        node.received.bytes += bytes;
        node.received.messages += 1;
        match node.take_waiter(tag, src) {
            Some(p) => {
                self.handoffs.put(&mut node.handoff, p, make());
                Some(p)
            }
            None => {
                node.mailbox.push_back(make());
                None
            }
        }
    }
}

/// One simulation: a machine's nodes, their programs, and the network between them.
pub struct Sim<M: Payload> {
    state: Rc<RefCell<State<M>>>,
    programs: Vec<Option<Program>>,
}

impl<M: Payload> Sim<M> {
    /// A simulation of `machine`, with random streams derived from `seed`.
    pub fn new(machine: &MachineConfig, seed: u64) -> Result<Sim<M>, crate::net::NetError> {
        let net = Network::new(&machine.network)?;
        Ok(Sim::build(
            machine.nodes,
            machine.cpu.clone(),
            machine.memory_per_node,
            Some(net),
            seed,
        ))
    }

    /// A simulation without a network or cpu costs: programs exchange only `Node::post`
    /// messages (used by PHOLD and by engine tests).
    pub fn bare(nodes: u32, seed: u64) -> Sim<M> {
        Sim::build(
            nodes,
            CpuConfig::default(),
            Bytes::new(u64::MAX),
            None,
            seed,
        )
    }

    fn build(nodes: u32, cpu: CpuConfig, memory: Bytes, net: Option<Network>, seed: u64) -> Sim<M> {
        assert!(
            nodes <= super::node::MAX_NODE_ID,
            "{nodes} nodes: a filter names node ids below 2^31 - 1"
        );
        let nodes: Vec<NodeState<M>> = (0..nodes)
            .map(|i| NodeState {
                cpu_free_at: SimTime::ZERO,
                received: Received::default(),
                mailbox: VecDeque::new(),
                waiters: SmallVec::new(),
                handoff: None,
                pool: MemoryPool::new(i, memory),
                stats: NodeStats::default(),
            })
            .collect();
        let first_program = vec![None; nodes.len()];
        let slices = Slices::new(nodes.len());
        let state = State {
            now: SimTime::ZERO,
            seed,
            queue: EventQueue::with_capacity(1024),
            ready: VecDeque::new(),
            current: 0,
            programs: Vec::new(),
            spawned: Vec::new(),
            nodes,
            handoffs: Handoffs::default(),
            look_ahead: first_program.len() >= LOOK_AHEAD_NODES,
            first_program,
            cpu,
            net,
            net_wakes: NetWakes::default(),
            slices,
            every_slice_an_event: false,
            in_flight: Vec::new(),
            free_slots: Vec::new(),
            delivered: Vec::new(),
            events: 0,
            timeline: None,
            timeline_paused: false,
            overflow: None,
            overflow_cause: None,
            unpriced_used: 0,
        };
        Sim {
            state: Rc::new(RefCell::new(state)),
            programs: Vec::new(),
        }
    }

    pub fn nodes(&self) -> u32 {
        self.state.borrow().nodes.len() as u32
    }

    /// Records every stretch of cpu work for a timeline (see `RunStats::timeline`).
    pub fn record_timeline(&mut self) {
        let mut st = self.state.borrow_mut();
        st.timeline.get_or_insert_with(CpuTimeline::default);
        if let Some(net) = st.net.as_mut() {
            net.record_occupancy();
        }
    }

    /// Wakes a program at the end of every slice of a time-sliced cpu instead of running
    /// chains (`slices.rs`): the plain way, kept as the oracle the tests compare chains
    /// against. Changes no answer, only the run's wall time.
    pub fn wake_every_slice(&mut self) {
        self.state.borrow_mut().every_slice_an_event = true;
    }

    /// Pauses (or resumes) the recorded timeline from now on (see `Node::record_timeline`).
    pub fn pause_timeline(&mut self, paused: bool) {
        self.state.borrow_mut().pause_timeline(paused);
    }

    /// The handle through which programs on node `id` act.
    pub fn node(&self, id: NodeId) -> Node<M> {
        assert!(id < self.nodes(), "node {id} does not exist");
        Node::new(id, self.state.clone())
    }

    /// Starts `program` on node `id` at time zero (or now, if the run has started).
    pub fn spawn<F>(&mut self, id: NodeId, name: impl Into<String>, program: F)
    where
        F: Future<Output = Result<(), SimError>> + 'static,
    {
        self.state
            .borrow_mut()
            .register_program(id, name.into(), false, Box::pin(program));
    }

    /// Runs until no event is left. Fails if a program fails, or with a deadlock report if
    /// programs that must finish are still waiting.
    pub fn run(&mut self) -> Result<RunStats, SimError> {
        self.run_until(SimTime::MAX)?;
        let st = self.state.borrow();
        let waits = st.waits();
        let waiting: Vec<WaitingProgram> = st
            .programs
            .iter()
            .enumerate()
            .filter(|(_, p)| !p.done && !p.daemon)
            .map(|(id, p)| WaitingProgram {
                name: p.name.clone(),
                node: p.node,
                waits_for: waits[id].to_string(),
            })
            .collect();
        if !waiting.is_empty() {
            return Err(SimError::Deadlock {
                at: st.now,
                seed: st.seed,
                waiting,
            });
        }
        drop(st);
        // The run is over: its timeline is handed over, not copied (it can be gigabytes).
        let mut stats = self.counters();
        let mut st = self.state.borrow_mut();
        let st = &mut *st;
        stats.timeline = st.timeline.take().map(CpuTimeline::into_spans);
        stats.link_timeline = stats
            .timeline
            .as_ref()
            .and(st.net.as_mut())
            .map(Network::take_link_spans);
        Ok(stats)
    }

    /// Processes every event up to and including `horizon`; programs may still be waiting
    /// afterwards (a time-bounded run such as PHOLD).
    pub fn run_until(&mut self, horizon: SimTime) -> Result<(), SimError> {
        let mut cx = Context::from_waker(Waker::noop());
        loop {
            // One borrow per program polled: the events before it are taken in the same one.
            let p = {
                let mut st = self.state.borrow_mut();
                // A charge past the largest simulated time, made by the program polled last.
                if let Some(overflow) = st.overflow.take() {
                    return Err(overflow);
                }
                if !st.spawned.is_empty() {
                    drop(st);
                    self.adopt_spawned();
                    continue;
                }
                match st.next_ready(horizon) {
                    Some(p) => p,
                    None => return Ok(()),
                }
            };
            let Some(program) = self.programs[p as usize].as_mut() else {
                continue;
            };
            if let Poll::Ready(result) = program.as_mut().poll(&mut cx) {
                self.programs[p as usize] = None;
                self.finished(p);
                result?;
            }
        }
    }

    fn finished(&mut self, p: ProgramId) {
        let mut st = self.state.borrow_mut();
        let now = st.now;
        let meta = &mut st.programs[p as usize];
        meta.done = true;
        let (node, daemon, warmed) = (meta.node, meta.daemon, meta.warmed);
        if warmed {
            st.first_program[node as usize] = None;
        }
        if !daemon {
            let stats = &mut st.nodes[node as usize].stats;
            stats.finish = stats.finish.max(now);
        }
    }

    fn adopt_spawned(&mut self) {
        let mut st = self.state.borrow_mut();
        let first = self.programs.len() as ProgramId;
        let spawned: Vec<Program> = st.spawned.drain(..).collect();
        for (i, p) in spawned.into_iter().enumerate() {
            self.programs.push(Some(p));
            st.ready.push_back(first + i as ProgramId);
        }
    }

    /// What the run has measured so far, its timeline aside.
    fn counters(&self) -> RunStats {
        let st = self.state.borrow();
        RunStats {
            end: st.now,
            seed: st.seed,
            events: st.events,
            nodes: st.nodes.iter().map(NodeState::stats).collect(),
            links: st.net.as_ref().map(Network::link_stats).unwrap_or_default(),
            memory: st.nodes.iter().map(|n| n.pool.stats()).collect(),
            timeline: None,
            unpriced_ops: crate::machine::Op::from_bits(st.unpriced_used),
            link_timeline: None,
            flow_solves: st
                .net
                .as_ref()
                .map(Network::solve_counters)
                .unwrap_or_default(),
        }
    }

    pub fn now(&self) -> SimTime {
        self.state.borrow().now
    }
}

// Programs hold `Node` handles (and so the state) in their futures; break the cycle.
impl<M: Payload> Drop for Sim<M> {
    fn drop(&mut self) {
        self.programs.clear();
        if let Ok(mut st) = self.state.try_borrow_mut() {
            st.spawned.clear();
        }
    }
}

/// The fewest nodes at which the look ahead runs. PHOLD measured it paying at 16,384 logical
/// processes and not at 1,024 or below (docs/performance.md), where a node's record and its
/// program's state (about 0.5 KB together) stay in the cache of a 2-core host.
const LOOK_AHEAD_NODES: usize = 4096;

/// How much of a program's future the look ahead asks for: PHOLD's program is 448 bytes, and
/// fetching only its first four lines kept most of the misses.
const WARM_BYTES: usize = 8 * 64;

/// Where a program keeps its state (its future: where it waits, its locals, such as PHOLD's
/// random stream): the cache lines the look ahead asks the cpu for while the queue takes out
/// the event that will wake the program. With many programs that state is a cache miss per
/// event, which the program's poll would otherwise wait for. A hint only: it changes no
/// memory and no answer, and the future is pinned, so the lines stay its own while it runs.
///
/// One word: the address of the first line, whose low six bits are free, plus how many lines.
#[derive(Clone, Copy)]
struct Warm(NonNull<u8>);

impl Warm {
    fn of(future: &Program) -> Warm {
        let future = &**future;
        let start = std::ptr::from_ref(future).cast::<u8>();
        // A poll reads the future's state word, its locals and the receive it waits in,
        // spread over its lines; only a long future's tail is left cold.
        let len = std::mem::size_of_val(future).min(WARM_BYTES);
        let offset = start.addr() % 64;
        let lines = (offset + len).div_ceil(64).max(1);
        const _: () = assert!(
            WARM_BYTES / 64 + 1 < 64,
            "the lines fit below a line's address"
        );
        let word = start.wrapping_sub(offset).wrapping_add(lines);
        Warm(NonNull::new(word.cast_mut()).expect("a future's line is not at address zero"))
    }

    fn first_line(self) -> *const u8 {
        self.0.as_ptr().wrapping_sub(self.lines())
    }

    fn lines(self) -> usize {
        self.0.as_ptr().addr() % 64
    }

    #[inline]
    fn prefetch(self) {
        let first = self.first_line();
        for line in 0..self.lines() {
            prefetch(first.wrapping_add(line * 64));
        }
    }
}

#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn prefetch(at: *const u8) {
    use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
    // SAFETY: a prefetch is a hint that never faults and reads nothing the program sees, so
    // any address is sound; SSE, which it needs, is part of every x86_64 target.
    unsafe { _mm_prefetch::<_MM_HINT_T0>(at.cast::<i8>()) }
}

#[cfg(not(target_arch = "x86_64"))]
#[inline(always)]
fn prefetch(_at: *const u8) {}

impl<M: Payload> State<M> {
    /// What each program is blocked on: a message if a node lists it among its waiters (a
    /// `recv` registers there only, so handing a message over never touches the program's
    /// record), otherwise what it last said it waits for.
    fn waits(&self) -> Vec<Wait> {
        let mut waits: Vec<Wait> = self.programs.iter().map(|p| p.wait).collect();
        for node in &self.nodes {
            for &(p, filter) in &node.waiters {
                waits[p as usize] = Wait::Message(filter);
            }
        }
        waits
    }

    /// The next program to poll, made current: the first ready one, after taking events in
    /// order (up to `horizon`) until one is. `None` when no event is left by then. Events
    /// never run program code, so nothing a poll could change (an overflowing charge, a
    /// spawned program) arises while they are taken.
    fn next_ready(&mut self, horizon: SimTime) -> Option<ProgramId> {
        loop {
            if let Some(p) = self.ready.pop_front() {
                self.current = p;
                return Some(p);
            }
            if self.look_ahead {
                if let Some(warm) = self.warm_for_next() {
                    warm.prefetch();
                }
            }
            let last = self.queue.last_taken();
            let wake = self.net_wakes.due(last).filter(|w| w.time() <= horizon);
            let Some((at, event)) = self.queue.pop_before(horizon, wake) else {
                let wake = wake?;
                self.net_wakes.take(wake);
                self.now = wake.time();
                self.events += 1;
                self.net_wake();
                continue;
            };
            self.now = at;
            self.events += 1;
            // The program an event wakes alone runs next: the ready queue was empty (the loop
            // takes an event only then), so queueing it would only take it straight back out.
            let woken = match event {
                Event::Wake(p) => Some(p),
                Event::Slice(p, node) => self.next_slices(p, node, at, horizon),
                Event::Arrive(id) => {
                    self.arrive(id);
                    None
                }
                Event::Post { src, dst, payload } => {
                    let tag = payload.tag();
                    self.deliver_made(src, dst, tag, Bytes::ZERO, || Envelope {
                        src,
                        dst,
                        tag,
                        bytes: Bytes::ZERO,
                        payload,
                        arrived: at,
                    })
                }
            };
            if let Some(p) = woken {
                debug_assert!(self.ready.is_empty(), "an event taken with programs ready");
                self.current = p;
                return Some(p);
            }
        }
    }

    /// Asks the cpu for the two lines of the node record a delivery reads first, for the
    /// event after the next and again for the next, before the queue takes them out: in a run
    /// of many nodes that record is a cache miss, and one event's work did not hide it all.
    /// The nodes come from the queue's hints (`State::schedule`), which stay in cache, so
    /// finding them waits for no event's body, and nothing here waits for a node; the body
    /// of the event after the next is asked for too, which its pop reads. Returns
    /// where the next event's node's first program keeps its state (`Warm`): that program is
    /// the one a delivery wakes as a rule, and its state is the next miss; it is taken from a
    /// small table rather than from the node's waiters, so the misses overlap instead of one
    /// waiting for another. Changes nothing.
    fn warm_for_next(&self) -> Option<Warm> {
        let LookAhead {
            next,
            after,
            after_body,
        } = self.queue.look_ahead();
        if let Some(body) = after_body {
            prefetch(body);
        }
        let warm_node = |dst: u32| {
            let node = std::ptr::from_ref(&self.nodes[dst as usize]).cast::<u8>();
            prefetch(node);
            prefetch(node.wrapping_add(64));
        };
        if let Some(after) = after {
            warm_node(after);
            prefetch(std::ptr::from_ref(&self.first_program[after as usize]).cast());
        }
        let next = next?;
        warm_node(next);
        self.first_program[next as usize]
    }

    pub fn net(&self) -> Option<&Network> {
        self.net.as_ref()
    }

    pub fn fail(&self, message: String) -> SimError {
        let meta = &self.programs[self.current as usize];
        SimError::Program {
            program: meta.name.clone(),
            node: meta.node,
            at: self.now,
            seed: self.seed,
            message,
        }
    }

    pub fn memory_error(&self, source: MemError) -> SimError {
        let meta = &self.programs[self.current as usize];
        SimError::Memory {
            program: meta.name.clone(),
            node: meta.node,
            at: self.now,
            seed: self.seed,
            source,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn envelope(src: NodeId) -> Envelope<u32> {
        Envelope {
            src,
            dst: 0,
            tag: 0,
            bytes: Bytes::ZERO,
            payload: src,
            arrived: SimTime::ZERO,
        }
    }

    /// The look ahead asks for every line of a short program's future and the first 512
    /// bytes of a long one, and for no line before the future starts; what it keeps of a
    /// program is one word.
    #[test]
    fn the_look_ahead_covers_a_programs_future() {
        fn lines_of(program: &Program) -> (usize, usize, Warm) {
            let future = &**program;
            let start = std::ptr::from_ref(future).cast::<u8>();
            (
                start as usize,
                std::mem::size_of_val(future),
                Warm::of(program),
            )
        }
        let short = [1u8; 300];
        let long = [2u8; 3000];
        let programs: [Program; 2] = [
            Box::pin(async move {
                std::hint::black_box(short);
                Ok(())
            }),
            Box::pin(async move {
                std::hint::black_box(long);
                Ok(())
            }),
        ];
        for program in &programs {
            let (start, len, warm) = lines_of(program);
            let first = warm.first_line() as usize;
            assert_eq!(first % 64, 0, "a line's start");
            assert!(
                first <= start && start - first < 64,
                "starts on the future's first line"
            );
            assert!(
                first + 64 * warm.lines() >= start + len.min(WARM_BYTES),
                "covers it"
            );
            assert!(
                64 * (warm.lines() - 1) < start - first + len.min(WARM_BYTES),
                "no more"
            );
        }
        assert!(lines_of(&programs[0]).1 >= 300 && lines_of(&programs[1]).1 >= 3000);
        assert_eq!(std::mem::size_of::<Option<Warm>>(), 8, "a word a node");
    }

    /// Each program takes the message handed to it and no other, whichever of a node's
    /// programs runs first, and a program nothing was handed to takes nothing.
    #[test]
    fn each_program_takes_its_own_handoff() {
        let mut h = Handoffs::default();
        let (mut a, mut b) = (None, None);
        h.put(&mut a, 7, envelope(1));
        h.put(&mut a, 3, envelope(2));
        h.put(&mut b, 9, envelope(5));
        h.put(&mut a, 5, envelope(3));
        h.put(&mut b, 8, envelope(6));
        assert!(h.take(&mut a, 4).is_none());
        assert_eq!(h.take(&mut a, 5).map(|(e, _)| e.payload), Some(3));
        assert_eq!(h.take(&mut b, 8).map(|(e, _)| e.payload), Some(6));
        assert_eq!(h.take(&mut a, 7).map(|(e, _)| e.payload), Some(1));
        h.put(&mut a, 4, envelope(4));
        assert_eq!(h.take(&mut a, 4).map(|(e, _)| e.payload), Some(4));
        assert_eq!(h.take(&mut a, 3).map(|(e, _)| e.payload), Some(2));
        assert!(h.take(&mut a, 3).is_none() && h.take(&mut a, 7).is_none());
        assert_eq!(h.take(&mut b, 9).map(|(e, _)| e.payload), Some(5));
        assert!(h.take(&mut b, 9).is_none() && h.more.is_empty());
        // A message given back to the program paying for it comes out marked paid, beside
        // one handed over that is not, wherever each waits.
        h.put(&mut b, 1, envelope(8));
        h.put_paid(&mut b, 2, envelope(9));
        let taken = |h: &mut Handoffs<u32>, b: &mut Handoff<u32>, p| {
            h.take(b, p).map(|(e, paid)| (e.payload, paid))
        };
        assert_eq!(taken(&mut h, &mut b, 2), Some((9, true)));
        h.put_paid(&mut b, 3, envelope(10));
        assert_eq!(taken(&mut h, &mut b, 1), Some((8, false)));
        assert_eq!(taken(&mut h, &mut b, 3), Some((10, true)));
        assert!(b.is_none() && h.more.is_empty());
    }

    /// A node's waiters leave in the order a swap-remove gives, whether the one that leaves
    /// is the last (a pop) or not; the mailbox is searched only when it holds messages.
    #[test]
    fn waiters_leave_as_a_swap_remove_would_take_them() {
        let mut node: NodeState<u32> = NodeState {
            waiters: SmallVec::new(),
            mailbox: VecDeque::new(),
            received: Received::default(),
            handoff: None,
            cpu_free_at: SimTime::ZERO,
            stats: NodeStats::default(),
            pool: MemoryPool::new(0, Bytes::new(0)),
        };
        let ids = |n: &NodeState<u32>| n.waiters.iter().map(|&(p, _)| p).collect::<Vec<_>>();
        node.waiters.extend([
            (1, Filter::tag(1)),
            (2, Filter::tag(2)),
            (3, Filter::tag(1)),
            (4, Filter::ANY),
        ]);
        assert_eq!(node.take_waiter(2, 0), Some(2));
        assert_eq!(ids(&node), [1, 4, 3]);
        assert_eq!(node.take_waiter(1, 0), Some(1));
        assert_eq!(ids(&node), [3, 4]);
        assert_eq!(node.take_waiter(5, 0), Some(4));
        assert_eq!(ids(&node), [3]);
        assert_eq!(node.take_waiter(2, 0), None);
        assert_eq!(node.take_waiter(1, 0), Some(3));
        assert!(node.waiters.is_empty() && node.take_waiter(1, 0).is_none());
        assert_eq!(node.mailbox_position(Filter::ANY), None);
        node.mailbox.extend([envelope(3), envelope(5)]);
        assert_eq!(node.mailbox_position(Filter::source(5)), Some(1));
        assert_eq!(node.mailbox_position(Filter::source(4)), None);
    }

    /// A delivery and the next `recv` of a node touch its first two cache lines only, for a
    /// payload as small as PHOLD's: the waiters and the mailbox in the first, the received
    /// counters and the message handed over in the second.
    #[test]
    fn a_handover_touches_two_lines_of_the_node() {
        use std::mem::{offset_of, size_of};
        type N = NodeState<u32>;
        let line = |start: usize, len: usize| (start / 64, (start + len - 1) / 64);
        let waiters = size_of::<SmallVec<[(ProgramId, Filter); 1]>>();
        assert_eq!(line(offset_of!(N, waiters), waiters), (0, 0));
        let mailbox = size_of::<VecDeque<Envelope<u32>>>();
        assert_eq!(line(offset_of!(N, mailbox), mailbox), (0, 0));
        let received = size_of::<Received>();
        assert_eq!(line(offset_of!(N, received), received), (1, 1));
        let handoff = size_of::<Handoff<u32>>();
        assert_eq!(line(offset_of!(N, handoff), handoff), (1, 1));
    }
}
