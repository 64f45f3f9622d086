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

pub use contention_free::RouteFree;

use super::timing::{Hops, Timing};
use super::{Delivered, Fidelity, LinkId, MsgId};
use crate::units::{Bytes, SimTime};

/// How much work the flow model's solves did, counted when built with the `counters`
/// feature or for the library's unit tests (zero otherwise): what the groups of `flow.rs`
/// save against flows, and what the sweep of `maxmin.rs` saves by counting a link's groups
/// instead of its flows.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct SolveCounters {
    pub solves: u64,
    /// Flows whose rate or bottleneck changed, summed over solves.
    pub flows_changed: u64,
    /// Groups whose rate or members changed (each one clock and one completion update).
    pub groups_changed: u64,
    /// Flows that moved from one group to another (new flows not counted).
    pub flows_switched: u64,
    /// Dirty links evaluated by the max-min sweep.
    pub link_evaluations: u64,
    /// Flows on the links evaluated, and the groups crossing the same links (what an
    /// evaluation walks).
    pub flows_on_links: u64,
    pub groups_crossing: u64,
    /// Flows drawn into a sweep (added, unsettled or fixed again), and the links their routes
    /// cross: each such visit updates that link's tallies of the flows drawn in.
    pub flows_swept: u64,
    pub swept_route_links: u64,
    /// Solves that ran the max-min sweep, and sweeps run again because a link left out of
    /// the first (a suspect) failed its check.
    pub sweeps: u64,
    pub reruns: u64,
    /// Flows added, and flows removed, with no sweep (the only change, and every other rate
    /// provably unchanged).
    pub added_alone: u64,
    pub removed_alone: u64,
    /// Over every sweep run: the links made dirty (evaluated and popped in key order), and
    /// the links left out and checked once it is done (suspects: their flows changed, but
    /// they fixed nothing last time, and more than one flow crosses them or the links'
    /// capacities differ).
    pub dirty_links: u64,
    pub left_out_links: u64,
}

/// What a transport knows about one link.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Usage {
    pub busy: SimTime,
    pub peak_queue: u32,
}

/// One fidelity level's state machine (see the contract in `net/mod.rs`); `Send` so a
/// network can move to a sweep's worker thread.
pub trait Transport: Send {
    /// Starts `msg` on `route` (non-empty; `hops` switch traversals, by kind of link).
    /// `Some(t)` when the arrival is already known; then it never comes out of `advance`.
    fn inject(
        &mut self,
        now: SimTime,
        msg: MsgId,
        route: &[LinkId],
        hops: Hops,
        bytes: Bytes,
    ) -> Option<SimTime>;
    fn next_event_time(&self) -> Option<SimTime>;
    fn advance(&mut self, now: SimTime, delivered: &mut Vec<Delivered>);
    /// The message `advance` will deliver first, when the level knows it ahead (a hint for
    /// the executor, which asks the cpu for that message's record; no answer depends on it).
    fn next_delivered(&self) -> Option<MsgId> {
        None
    }
    fn usage(&self, link: LinkId) -> Usage;
    /// The flow model's work counters; zero for the other levels.
    fn counters(&self) -> SolveCounters {
        SolveCounters::default()
    }
}

/// The level `fidelity` for `links` links, a network hop taking `links_per_hop` of them;
/// `node_link[l]` says link `l` is a node link (empty when the network has none). `Err`
/// says why the level cannot model these links.
pub fn build(
    fidelity: Fidelity,
    timing: Timing,
    links: usize,
    links_per_hop: u32,
    node_link: &[bool],
) -> Result<Box<dyn Transport>, String> {
    let rate = |l: usize| match timing.node_links {
        Some(node) if node_link.get(l) == Some(&true) => node.bandwidth,
        _ => timing.bandwidth,
    };
    Ok(match fidelity {
        Fidelity::Ideal => Box::new(contention_free::ContentionFree::new(
            RouteFree::ideal(timing),
            links,
            rate,
        )),
        Fidelity::Hops => Box::new(contention_free::ContentionFree::new(
            RouteFree::hops(timing),
            links,
            rate,
        )),
        Fidelity::Flow => {
            let capacities = if node_link.is_empty() {
                maxmin::Capacities::Uniform(timing.bandwidth.bits_per_s())
            } else {
                maxmin::Capacities::PerLink((0..links).map(|l| rate(l).bits_per_s()).collect())
            };
            maxmin::fastest_link(links, &capacities)
                .map_err(|limit| too_fast(timing, links, limit))?;
            Box::new(flow::Flow::new(timing, links, capacities))
        }
        Fidelity::Packet => Box::new(packet::Packet::new(timing, links, links_per_hop, node_link)),
    })
}

/// The level `fidelity` as a [`RouteFree`] when it needs no route to time a message and
/// charges every link the same (a contention-free level on links of one rate).
pub fn route_free(fidelity: Fidelity, timing: Timing) -> Option<RouteFree> {
    match (fidelity, timing.node_links) {
        (Fidelity::Ideal, None) => Some(RouteFree::ideal(timing)),
        (Fidelity::Hops, None) => Some(RouteFree::hops(timing)),
        _ => None,
    }
}

/// Why `flow` cannot rate links of `timing` on `links` links, the fastest it can being `limit`
/// bits per second: the field as a machine spec spells it, and what would do.
fn too_fast(timing: Timing, links: usize, limit: u64) -> String {
    let (field, bandwidth) = match timing.node_links {
        Some(node) if node.bandwidth > timing.bandwidth => ("node.link_bandwidth", node.bandwidth),
        _ => ("link_bandwidth", timing.bandwidth),
    };
    format!(
        "{field} {bandwidth} is too fast for the `flow` fidelity on {links} links: its exact rates \
         are whole bits per second, which on this many links must stay below 2^{} bit/s \
         ({:.3e} B/s); use a slower link, or the `hops` or `packet` fidelity",
        (limit + 1).trailing_zeros(),
        (limit + 1) as f64 / 8.0
    )
}
