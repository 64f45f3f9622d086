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

/// A contention-free level on links of one rate: a message's arrival and what it charges
/// each link of its route, known without the route.
#[derive(Clone, Copy)]
pub struct RouteFree {
    timing: Timing,
    /// The level's formula: time from injection to delivery for `hops` hops and `bytes`.
    delay: fn(&Timing, Hops, Bytes) -> SimTime,
}

impl RouteFree {
    pub fn ideal(timing: Timing) -> RouteFree {
        RouteFree {
            timing,
            delay: |t, h, b| t.ideal(h, b),
        }
    }

    pub fn hops(timing: Timing) -> RouteFree {
        RouteFree {
            timing,
            delay: |t, h, b| t.contention_free(h, b),
        }
    }

    /// When a message of `bytes` injected at `now` over `hops` hops arrives.
    pub fn arrival(&self, now: SimTime, hops: Hops, bytes: Bytes) -> SimTime {
        now + (self.delay)(&self.timing, hops, bytes)
    }

    /// The busy time a message of `bytes` charges each link of its route.
    pub fn busy_per_link(&self, bytes: Bytes) -> SimTime {
        self.timing.serialization(bytes)
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
        } else {
            for &l in route {
                self.busy[l as usize] += self.rates[l as usize].transfer_time(bytes);
            }
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
