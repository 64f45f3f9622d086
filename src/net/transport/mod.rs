//! Transport models, one file per fidelity level: when does a routed message arrive?
//!
//! Owns the [`Transport`] trait and its exhaustive selection from [`Fidelity`]. Every level
//! agrees exactly with [`Timing::contention_free`] for a message alone on the network; they
//! differ in how they charge contention (none, max-min fair fluid sharing, per-link packet
//! queues). Must never see topologies (a transport receives a route as link indices and a hop
//! count) and never use floating point for time.

mod completions;
mod contention_free;
mod flow;
mod maxmin;
mod packet;

use super::timing::Timing;
use super::{Delivered, Fidelity, LinkId, MsgId};
use crate::units::{Bytes, SimTime};

/// What a transport knows about one link.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Usage {
    pub busy: SimTime,
    pub peak_queue: u32,
}

/// One fidelity level's state machine (see the contract in `net/mod.rs`); `Send` so a
/// network can move to a sweep's worker thread.
pub trait Transport: Send {
    /// Starts `msg` on `route` (non-empty; `hops` switch traversals). `Some(t)` when the
    /// arrival is already known; then it never comes out of `advance`.
    fn inject(
        &mut self,
        now: SimTime,
        msg: MsgId,
        route: &[LinkId],
        hops: u32,
        bytes: Bytes,
    ) -> Option<SimTime>;
    fn next_event_time(&self) -> Option<SimTime>;
    fn advance(&mut self, now: SimTime, delivered: &mut Vec<Delivered>);
    fn usage(&self, link: LinkId) -> Usage;
}

pub fn build(fidelity: Fidelity, timing: Timing, links: usize) -> Box<dyn Transport> {
    match fidelity {
        Fidelity::Ideal => Box::new(contention_free::ContentionFree::ideal(timing, links)),
        Fidelity::Hops => Box::new(contention_free::ContentionFree::hops(timing, links)),
        Fidelity::Flow => Box::new(flow::Flow::new(timing, links)),
        Fidelity::Packet => Box::new(packet::Packet::new(timing, links)),
    }
}
