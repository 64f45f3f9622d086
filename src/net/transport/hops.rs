//! `hops`: the switching-aware contention-free formula (`Timing::contention_free`).
//!
//! Must never model contention: messages never see each other.

use super::{SerializationBusy, Transport, Usage};
use crate::net::timing::Timing;
use crate::net::{Delivered, LinkId, MsgId};
use crate::units::{Bytes, SimTime};

pub struct Hops {
    timing: Timing,
    busy: SerializationBusy,
}

impl Hops {
    pub fn new(timing: Timing, links: usize) -> Hops {
        Hops {
            timing,
            busy: SerializationBusy::new(links),
        }
    }
}

impl Transport for Hops {
    fn inject(
        &mut self,
        now: SimTime,
        _msg: MsgId,
        route: &[LinkId],
        hops: u32,
        bytes: Bytes,
    ) -> Option<SimTime> {
        self.busy.charge(&self.timing, route, bytes);
        Some(now + self.timing.contention_free(hops, bytes))
    }
    fn next_event_time(&self) -> Option<SimTime> {
        None
    }
    fn advance(&mut self, _now: SimTime, _delivered: &mut Vec<Delivered>) {}
    fn usage(&self, link: LinkId) -> Usage {
        self.busy.usage(link)
    }
}
