//! The two contention-free levels: messages never see each other, so a message's arrival is
//! known when it is injected.
//! - `ideal`: route latency plus one serialization, `h*L + T(bytes)` (`Timing::ideal`). It
//!   ignores switching: under store-and-forward it is faster than the other levels by exactly
//!   the pipeline term `(h-1)*T(first packet)`.
//! - `hops`: the switching-aware formula (`Timing::contention_free`).
//!
//! Link busy time: every message charges its serialization time to every link it crosses.
//! Must never model contention.

use super::{Transport, Usage};
use crate::net::timing::Timing;
use crate::net::{Delivered, LinkId, MsgId};
use crate::units::{Bytes, SimTime};

pub struct ContentionFree {
    timing: Timing,
    /// The level's formula: time from injection to delivery for `hops` hops and `bytes`.
    delay: fn(&Timing, u32, Bytes) -> SimTime,
    busy: Vec<SimTime>,
}

impl ContentionFree {
    pub fn ideal(timing: Timing, links: usize) -> ContentionFree {
        ContentionFree {
            timing,
            delay: Timing::ideal,
            busy: vec![SimTime::ZERO; links],
        }
    }

    pub fn hops(timing: Timing, links: usize) -> ContentionFree {
        ContentionFree {
            timing,
            delay: Timing::contention_free,
            busy: vec![SimTime::ZERO; links],
        }
    }
}

impl Transport for ContentionFree {
    fn inject(
        &mut self,
        now: SimTime,
        _msg: MsgId,
        route: &[LinkId],
        hops: u32,
        bytes: Bytes,
    ) -> Option<SimTime> {
        let t = self.timing.serialization(bytes);
        for &l in route {
            self.busy[l as usize] += t;
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
