//! `flow`: max-min fair sharing of every link's bandwidth among the messages crossing it
//! (fluid model).
//!
//! Owns the exact fluid arithmetic:
//! - a flow's remaining work is an exact integer in bit-picoseconds (`Bandwidth::work_of`);
//! - rates are whole bits per second from integer progressive filling (`maxmin.rs`), so no
//!   link carries more than its capacity and a flow never finishes early; a rate is never 0
//!   (a link shared by more flows than it has bits per second gives each 1 bit/s);
//! - progress over `dt` picoseconds is exactly `rate * dt`, applied lazily when a flow's rate
//!   changes; a completion is at `now + ceil(remaining / rate)`, rounded once;
//! - a flow's delivery is its fluid end plus `Timing::fixed_part` (route latency and the
//!   store-and-forward pipeline term), so a lone message matches the formula exactly;
//! - flows completing at one instant finish in order of their `MsgId` (the id the caller gave).
//!
//! Starts and ends at one instant are batched into one solve (`next_event_time` asks for an
//! `advance` at the start instant); only flows whose rate changed get a new completion.
//!
//! Must never use floating point, never iterate a hash map, and never keep a completion
//! computed under an old rate: a flow has one entry in `completions`, moved when its rate
//! changes.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use super::completions::Completions;
use super::maxmin::{Capacities, MaxMin};
use super::{Transport, Usage};
use crate::net::timing::{Hops, Timing};
use crate::net::{Delivered, LinkId, MsgId};
use crate::units::{ceil_div, Bandwidth, Bytes, SimTime};

pub struct Flow {
    timing: Timing,
    clock: SimTime,
    seq: u64,
    flows: Vec<FlowState>,
    free_slots: Vec<u32>,
    links: Vec<LinkState>,
    shares: MaxMin,
    /// Each flow's completion at its current rate.
    completions: Completions,
    /// (delivery, seq, message): fluid transfer done, fixed latency running.
    deliveries: BinaryHeap<Reverse<(SimTime, u64, MsgId)>>,
    /// The earliest start or end not yet solved for.
    dirty_since: Option<SimTime>,
    /// Reused by every solve: (flow slot, old rate) of the flows whose rate changed.
    changed: Vec<(u32, u64)>,
    /// Test switch: every solve from scratch (the reference for the incremental one).
    #[cfg(test)]
    from_scratch: bool,
}

struct FlowState {
    msg: MsgId,
    /// Bit-picoseconds still to move, as of `since`.
    remaining: u128,
    /// Bits per second; 0 only before the first solve.
    rate: u64,
    since: SimTime,
    tail: SimTime,
}

#[derive(Default)]
struct LinkState {
    busy: SimTime,
    busy_since: SimTime,
    peak: u32,
}

impl Flow {
    pub fn new(timing: Timing, links: usize, capacities: Capacities) -> Flow {
        Flow {
            shares: MaxMin::new(capacities, links),
            timing,
            clock: SimTime::ZERO,
            seq: 0,
            flows: Vec::new(),
            free_slots: Vec::new(),
            links: (0..links).map(|_| LinkState::default()).collect(),
            completions: Completions::default(),
            deliveries: BinaryHeap::new(),
            dirty_since: None,
            changed: Vec::new(),
            #[cfg(test)]
            from_scratch: false,
        }
    }

    fn next_seq(&mut self) -> u64 {
        self.seq += 1;
        self.seq
    }

    fn schedule_delivery(&mut self, at: SimTime, msg: MsgId) {
        let seq = self.next_seq();
        self.deliveries.push(Reverse((at, seq, msg)));
    }

    fn mark_dirty(&mut self, now: SimTime) {
        self.dirty_since = Some(self.dirty_since.map_or(now, |t| t.min(now)));
    }

    fn start_flow(
        &mut self,
        now: SimTime,
        msg: MsgId,
        route: &[LinkId],
        tail: SimTime,
        bytes: Bytes,
    ) {
        let state = FlowState {
            msg,
            remaining: Bandwidth::work_of(bytes),
            rate: 0,
            since: now,
            tail,
        };
        let slot = match self.free_slots.pop() {
            Some(s) => {
                self.flows[s as usize] = state;
                s
            }
            None => {
                self.flows.push(state);
                (self.flows.len() - 1) as u32
            }
        };
        self.shares.add(slot, route);
        for &l in route {
            let flows = self.shares.flows_on(l) as u32;
            let link = &mut self.links[l as usize];
            if flows == 1 {
                link.busy_since = now;
            }
            link.peak = link.peak.max(flows);
        }
        self.mark_dirty(now);
    }

    /// Ends the flow in `slot` at `now` (its work is done) and schedules its delivery.
    fn finish_flow(&mut self, now: SimTime, slot: u32) {
        let f = &mut self.flows[slot as usize];
        let moved = f.rate as u128 * (now - f.since).ps() as u128;
        debug_assert!(
            moved >= f.remaining,
            "flow completed before its work was done"
        );
        f.remaining = 0;
        let (msg, at) = (f.msg, now + f.tail);
        // A link this flow leaves empty stops being busy.
        for &l in self.shares.route(slot) {
            if self.shares.flows_on(l) == 1 {
                let link = &mut self.links[l as usize];
                link.busy += now - link.busy_since;
            }
        }
        self.shares.remove(slot);
        self.free_slots.push(slot);
        self.schedule_delivery(at, msg);
        self.mark_dirty(now);
    }

    /// New max-min fair rates at `now`, and new completions for the flows whose rate changed.
    ///
    /// A flow whose rate did not change keeps its completion entry: with the same rate,
    /// `since + ceil(remaining / rate)` is the same instant whenever it is computed.
    fn solve(&mut self, now: SimTime) {
        let mut changed = std::mem::take(&mut self.changed);
        changed.clear();
        #[cfg(test)]
        if self.from_scratch {
            self.shares.solve_from_scratch(&mut changed);
        } else {
            self.shares.solve(&mut changed);
        }
        #[cfg(not(test))]
        self.shares.solve(&mut changed);
        for &(slot, old_rate) in &changed {
            let new_rate = self.shares.rate(slot);
            let f = &mut self.flows[slot as usize];
            debug_assert_eq!(f.rate, old_rate);
            let moved = old_rate as u128 * (now - f.since).ps() as u128;
            f.remaining -= moved;
            f.since = now;
            f.rate = new_rate;
            let left = ceil_div(f.remaining, new_rate as u128);
            let at = now + SimTime::from_ps(left);
            self.completions.set(slot, f.msg, at);
        }
        self.changed = changed;
    }
}

impl Transport for Flow {
    fn inject(
        &mut self,
        now: SimTime,
        msg: MsgId,
        route: &[LinkId],
        hops: Hops,
        bytes: Bytes,
    ) -> Option<SimTime> {
        debug_assert!(now >= self.clock, "inject in the past");
        self.clock = self.clock.max(now);
        let tail = self.timing.fixed_part(hops, bytes);
        if bytes.get() == 0 {
            self.schedule_delivery(now + tail, msg);
        } else {
            self.start_flow(now, msg, route, tail, bytes);
        }
        None
    }

    fn next_event_time(&self) -> Option<SimTime> {
        let completion = self.completions.first().map(|e| e.0);
        let delivery = self.deliveries.peek().map(|Reverse(e)| e.0);
        [self.dirty_since, completion, delivery]
            .into_iter()
            .flatten()
            .min()
    }

    fn advance(&mut self, now: SimTime, delivered: &mut Vec<Delivered>) {
        self.clock = self.clock.max(now);
        while let Some((at, _, slot)) = self.completions.first() {
            if at > now {
                break;
            }
            self.completions.pop();
            self.finish_flow(at, slot);
        }
        if self.dirty_since.take().is_some() {
            self.solve(now);
        }
        while let Some(&Reverse((at, _, msg))) = self.deliveries.peek() {
            if at > now {
                break;
            }
            self.deliveries.pop();
            delivered.push(Delivered { msg, at });
        }
    }

    fn usage(&self, link: LinkId) -> Usage {
        let l = &self.links[link as usize];
        let running = if self.shares.flows_on(link) == 0 {
            SimTime::ZERO
        } else {
            self.clock.saturating_sub(l.busy_since)
        };
        Usage {
            busy: l.busy + running,
            peak_queue: l.peak,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::net::Switching;
    use rand::{Rng, SeedableRng};

    fn timing() -> Timing {
        Timing {
            bandwidth: "17MB/s".parse().unwrap(),
            hop_latency: SimTime::from_ns(300),
            switching: Switching::Wormhole,
            packet_size: Bytes::new(1024),
            node_links: None,
        }
    }

    /// Runs random overlapping flows on 12 links, starting at multiples of `grain` ps (a
    /// coarse grain makes starts coincide with each other and with completions); returns
    /// every delivery in order.
    fn run(from_scratch: bool, seed: u64, grain: u64) -> Vec<Delivered> {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let mut flow = Flow::new(
            timing(),
            12,
            Capacities::Uniform(timing().bandwidth.bits_per_s()),
        );
        flow.from_scratch = from_scratch;
        let mut starts: Vec<(SimTime, Vec<LinkId>, Bytes)> = (0..300)
            .map(|_| {
                let first = rng.gen_range(0..12u32);
                let len = rng.gen_range(1..5u32);
                let route = (first..first + len).map(|l| l % 12).collect();
                let at = SimTime::from_ps(rng.gen_range(0..50_000_000_000u64 / grain) * grain);
                (at, route, Bytes::new(rng.gen_range(1..200_000)))
            })
            .collect();
        starts.sort_by_key(|s| s.0);
        let mut out = Vec::new();
        let mut next = 0;
        loop {
            let start = starts.get(next).map(|s| s.0);
            let Some(now) = [start, flow.next_event_time()].into_iter().flatten().min() else {
                break;
            };
            while next < starts.len() && starts[next].0 == now {
                let (at, route, bytes) = &starts[next];
                flow.inject(
                    *at,
                    next as MsgId,
                    route,
                    (route.len() as u32).into(),
                    *bytes,
                );
                next += 1;
            }
            if flow.next_event_time() == Some(now) {
                flow.advance(now, &mut out);
            }
        }
        out
    }

    #[test]
    fn incremental_solves_deliver_exactly_as_filling_from_scratch() {
        for seed in 0..8 {
            for grain in [1, 1_000_000_000, 5_000_000_000] {
                let full = run(true, seed, grain);
                assert_eq!(full.len(), 300);
                assert_eq!(run(false, seed, grain), full, "seed {seed} grain {grain}");
            }
        }
    }
}
