//! The two contention-free levels: messages never see each other, so a message's arrival is
//! known when it is injected.
//! - `ideal`: route latency plus one serialization, `h*L + T(bytes)` (`Timing::ideal`). It
//!   ignores switching: under store-and-forward it is faster than the other levels by exactly
//!   the pipeline term `(h-1)*T(first packet)`.
//! - `hops`: the switching-aware formula (`Timing::contention_free`).
//!
//! Link busy time: every message charges its serialization time on each link to that link.
//! On links of one rate the charge is the same on every link, so [`RouteFree`] hands the
//! arrival and the charge to a caller that tallies its routes itself (`Network`, by lines).
//! Must never model contention.

use super::{Transport, Usage};
use crate::net::timing::{Hops, Timing};
use crate::net::{Delivered, LinkId, MsgId};
use crate::units::Bandwidth;
use crate::units::{Bytes, SimTime};

/// A contention-free level: a message's arrival from its hops and size alone, and, on links
/// of one rate, what it charges each link of its route (its serialization, which its arrival
/// includes), so that a caller may tally its routes itself.
#[derive(Clone, Copy)]
pub struct RouteFree {
    timing: Timing,
    /// What the level adds to a message's serialization on its slowest link: the route's
    /// latency (`ideal`) or [`Timing::fixed_part`] (`hops`), the sums of [`Timing::ideal`]
    /// and [`Timing::contention_free`].
    beyond_serialization: fn(&Timing, Hops, Bytes) -> SimTime,
}

impl RouteFree {
    pub fn ideal(timing: Timing) -> RouteFree {
        RouteFree {
            timing,
            beyond_serialization: |t, h, _| t.latency(h),
        }
    }

    pub fn hops(timing: Timing) -> RouteFree {
        RouteFree {
            timing,
            beyond_serialization: |t, h, b| t.fixed_part(h, b),
        }
    }

    /// When a message of `bytes` injected at `now` over `hops` hops arrives.
    pub fn arrival(&self, now: SimTime, hops: Hops, bytes: Bytes) -> SimTime {
        let serialization = self.timing.serialization_on(hops, bytes);
        self.arrival_after(now, serialization, hops, bytes)
    }

    /// On links of one rate: the busy time a message of `bytes` charges each link of its
    /// route, which is its serialization.
    pub fn busy_per_link(&self, bytes: Bytes) -> SimTime {
        debug_assert!(self.timing.node_links.is_none(), "links of several rates");
        self.timing.serialization(bytes)
    }

    /// [`RouteFree::arrival`] on links of one rate, of a message whose
    /// [`RouteFree::busy_per_link`] is `busy` (its serialization, not worked out again).
    pub fn arrival_after_busy(
        &self,
        now: SimTime,
        busy: SimTime,
        hops: Hops,
        bytes: Bytes,
    ) -> SimTime {
        debug_assert!(self.timing.node_links.is_none(), "links of several rates");
        self.arrival_after(now, busy, hops, bytes)
    }

    fn arrival_after(
        &self,
        now: SimTime,
        serialization: SimTime,
        hops: Hops,
        bytes: Bytes,
    ) -> SimTime {
        now + serialization + (self.beyond_serialization)(&self.timing, hops, bytes)
    }
}

pub struct ContentionFree {
    level: RouteFree,
    busy: Vec<SimTime>,
    /// Each link's rate, when they differ (empty when every link runs at `timing.bandwidth`).
    rates: Vec<Bandwidth>,
}

impl ContentionFree {
    /// `level` on `links` links, link `l` running at `rate(l)`.
    pub fn new(
        level: RouteFree,
        links: usize,
        rate: impl Fn(usize) -> Bandwidth,
    ) -> ContentionFree {
        ContentionFree {
            busy: vec![SimTime::ZERO; links],
            rates: match level.timing.node_links {
                Some(_) => (0..links).map(rate).collect(),
                None => Vec::new(),
            },
            level,
        }
    }
}

impl Transport for ContentionFree {
    fn inject(
        &mut self,
        now: SimTime,
        _msg: MsgId,
        route: &[LinkId],
        hops: Hops,
        bytes: Bytes,
    ) -> Option<SimTime> {
        if self.rates.is_empty() {
            let t = self.level.busy_per_link(bytes);
            for &l in route {
                self.busy[l as usize] += t;
            }
            return Some(self.level.arrival_after_busy(now, t, hops, bytes));
        }
        for &l in route {
            self.busy[l as usize] += self.rates[l as usize].transfer_time(bytes);
        }
        Some(self.level.arrival(now, hops, bytes))
    }
    fn next_event_time(&self) -> Option<SimTime> {
        None
    }
    fn advance(&mut self, _now: SimTime, _delivered: &mut Vec<Delivered>) {}
    fn usage(&self, link: LinkId) -> Usage {
        Usage {
            busy: self.busy[link as usize],
            peak_queue: 0,
        }
    }
}
