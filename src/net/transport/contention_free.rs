//! The two contention-free levels: messages never see each other, so a message's arrival is
//! known when it is injected.
//! - `ideal`: route latency plus one serialization, `h*L + T(bytes)` (`Timing::ideal`). It
//!   ignores switching: under store-and-forward it is faster than the other levels by exactly
//!   the pipeline term `(h-1)*T(first packet)`.
//! - `hops`: the switching-aware formula (`Timing::contention_free`).
//!
//! Link busy time: every message charges its serialization time on each link to that link.
//! Must never model contention.

use super::{Transport, Usage};
use crate::net::timing::{Hops, Timing};
use crate::net::{Delivered, LinkId, MsgId};
use crate::units::Bandwidth;
use crate::units::{Bytes, SimTime};

pub struct ContentionFree {
    timing: Timing,
    /// The level's formula: time from injection to delivery for `hops` hops and `bytes`.
    delay: fn(&Timing, Hops, Bytes) -> SimTime,
    busy: Vec<SimTime>,
    /// Each link's rate, when they differ (empty when every link runs at `timing.bandwidth`).
    rates: Vec<Bandwidth>,
}

impl ContentionFree {
    pub fn ideal(
        timing: Timing,
        links: usize,
        rate: impl Fn(usize) -> Bandwidth,
    ) -> ContentionFree {
        Self::new(timing, links, rate, |t, h, b| t.ideal(h, b))
    }

    pub fn hops(timing: Timing, links: usize, rate: impl Fn(usize) -> Bandwidth) -> ContentionFree {
        Self::new(timing, links, rate, |t, h, b| t.contention_free(h, b))
    }

    fn new(
        timing: Timing,
        links: usize,
        rate: impl Fn(usize) -> Bandwidth,
        delay: fn(&Timing, Hops, Bytes) -> SimTime,
    ) -> ContentionFree {
        ContentionFree {
            timing,
            delay,
            busy: vec![SimTime::ZERO; links],
            rates: match timing.node_links {
                Some(_) => (0..links).map(rate).collect(),
                None => Vec::new(),
            },
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
            let t = self.timing.serialization(bytes);
            for &l in route {
                self.busy[l as usize] += t;
            }
        } else {
            for &l in route {
                self.busy[l as usize] += self.rates[l as usize].transfer_time(bytes);
            }
        }
        Some(now + (self.delay)(&self.timing, hops, bytes))
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
