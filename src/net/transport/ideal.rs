//! `ideal`: route latency plus one serialization, `h*L + T(bytes)`.
//!
//! Ideal ignores switching: under store-and-forward it is faster than the other levels by
//! exactly the pipeline term `(h-1)*T(first packet)`. Must never model contention.

use super::{SerializationBusy, Transport, Usage};
use crate::net::timing::Timing;
use crate::net::{Delivered, LinkId, MsgId};
use crate::units::{Bytes, SimTime};

pub struct Ideal {
    timing: Timing,
    busy: SerializationBusy,
}

impl Ideal {
    pub fn new(timing: Timing, links: usize) -> Ideal {
        Ideal {
            timing,
            busy: SerializationBusy::new(links),
        }
    }
}

impl Transport for Ideal {
    fn inject(
        &mut self,
        now: SimTime,
        _msg: MsgId,
        route: &[LinkId],
        hops: u32,
        bytes: Bytes,
    ) -> Option<SimTime> {
        self.busy.charge(&self.timing, route, bytes);
        Some(now + self.timing.ideal(hops, bytes))
    }
    fn next_event_time(&self) -> Option<SimTime> {
        None
    }
    fn advance(&mut self, _now: SimTime, _delivered: &mut Vec<Delivered>) {}
    fn usage(&self, link: LinkId) -> Usage {
        self.busy.usage(link)
    }
}
