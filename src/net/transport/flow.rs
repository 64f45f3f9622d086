//! `flow`: max-min fair sharing of every link's bandwidth among the messages crossing it
//! (fluid model), recomputed incrementally.
//!
//! Owns the exact fluid arithmetic:
//! - a flow's remaining work is an exact integer in bit-picoseconds (`Bandwidth::work_of`);
//! - rates are whole bits per second from water-filling with floor division, so no link
//!   carries more than its capacity and a flow never finishes early; a rate is never 0 (a
//!   link shared by more flows than it has bits per second gives each 1 bit/s);
//! - progress over `dt` picoseconds is exactly `rate * dt`; a completion is at
//!   `now + ceil(remaining / rate)`, rounded once;
//! - a flow's delivery is its fluid end plus `Timing::fixed_part` (route latency and the
//!   store-and-forward pipeline term), so a lone message matches the formula exactly.
//!
//! Incremental: when flows start or end, only the connected component of flows that share
//! links with them (transitively) gets new rates; every other flow keeps its rate and its
//! progress is applied lazily. Starts at one instant are batched into one recomputation
//! (`next_event_time` asks for an `advance` at the start instant).
//!
//! Must never use floating point, never iterate a hash map, and never let a stale completion
//! entry (one computed under an old rate) deliver a message: entries carry the flow's version.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use super::{Transport, Usage};
use crate::net::timing::Timing;
use crate::net::{Delivered, LinkId, MsgId};
use crate::units::{ceil_div, Bandwidth, Bytes, SimTime};

pub struct Flow {
    timing: Timing,
    capacity: u64,
    clock: SimTime,
    seq: u64,
    flows: Vec<FlowState>,
    free_slots: Vec<u32>,
    links: Vec<LinkState>,
    /// (completion, seq, flow slot, flow version); entries of older versions are stale.
    completions: BinaryHeap<Reverse<(SimTime, u64, u32, u32)>>,
    /// (delivery, seq, message): fluid transfer done, fixed latency running.
    deliveries: BinaryHeap<Reverse<(SimTime, u64, MsgId)>>,
    /// Flows started and links vacated since the last recomputation, and when.
    dirty_flows: Vec<u32>,
    dirty_links: Vec<LinkId>,
    dirty_since: Option<SimTime>,
    /// A level below which no flow's rate changes in the next recomputation: the lowest
    /// rate among flows that ended, and for each flow that started the smallest initial share
    /// on its route (see `recompute`).
    dirty_floor: u64,
    /// Test switch: recompute from level 0 every time (the reference for the shortcut).
    always_full: bool,
    scratch: Scratch,
}

struct FlowState {
    msg: MsgId,
    route: Vec<LinkId>,
    /// Bit-picoseconds still to move, as of `since`.
    remaining: u128,
    /// Bits per second; 0 only before the first recomputation.
    rate: u64,
    since: SimTime,
    tail: SimTime,
    version: u32,
    active: bool,
}

#[derive(Default)]
struct LinkState {
    flows: Vec<u32>,
    busy: SimTime,
    busy_since: SimTime,
    peak: u32,
}

/// Reused buffers of the recomputation; `epoch` marks what the current one has visited.
#[derive(Default)]
struct Scratch {
    /// u64: never wraps back to a stale mark.
    epoch: u64,
    flow_epoch: Vec<u64>,
    link_epoch: Vec<u64>,
    component_flows: Vec<u32>,
    component_links: Vec<LinkId>,
    fixed: Vec<bool>,
    cap_left: Vec<u64>,
    unfixed: Vec<u32>,
    /// Rates of the component's flows before the recomputation, aligned with
    /// `component_flows`.
    old_rates: Vec<u64>,
    /// Trusted rates of one link's flows, sorted: see `start_floor`.
    rates: Vec<u64>,
    /// (share lower bound, link): see `water_fill`.
    /// Keys packed as `share << 32 | link` (one integer compare per heap step).
    bottlenecks: BinaryHeap<Reverse<u128>>,
}

impl Flow {
    pub fn new(timing: Timing, links: usize) -> Flow {
        let scratch = Scratch {
            link_epoch: vec![0; links],
            cap_left: vec![0; links],
            unfixed: vec![0; links],
            ..Scratch::default()
        };
        Flow {
            capacity: timing.bandwidth.bits_per_s(),
            timing,
            clock: SimTime::ZERO,
            seq: 0,
            flows: Vec::new(),
            free_slots: Vec::new(),
            links: (0..links).map(|_| LinkState::default()).collect(),
            completions: BinaryHeap::new(),
            deliveries: BinaryHeap::new(),
            dirty_flows: Vec::new(),
            dirty_links: Vec::new(),
            dirty_since: None,
            dirty_floor: u64::MAX,
            always_full: false,
            scratch,
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
        let slot = match self.free_slots.pop() {
            Some(s) => s,
            None => {
                self.flows.push(FlowState {
                    msg: 0,
                    route: Vec::new(),
                    remaining: 0,
                    rate: 0,
                    since: now,
                    tail: SimTime::ZERO,
                    version: 0,
                    active: false,
                });
                self.scratch.flow_epoch.push(0);
                self.scratch.fixed.push(false);
                (self.flows.len() - 1) as u32
            }
        };
        let f = &mut self.flows[slot as usize];
        f.msg = msg;
        f.route.clear();
        f.route.extend_from_slice(route);
        f.remaining = Bandwidth::work_of(bytes);
        f.rate = 0;
        f.since = now;
        f.tail = tail;
        f.active = true;
        for &l in route {
            let link = &mut self.links[l as usize];
            if link.flows.is_empty() {
                link.busy_since = now;
            }
            link.flows.push(slot);
            link.peak = link.peak.max(link.flows.len() as u32);
        }
        self.dirty_flows.push(slot);
        let below = self.start_floor(route);
        self.dirty_floor = self.dirty_floor.min(below);
        self.mark_dirty(now);
    }

    /// A rate that a flow just started on `route` (already in the links' lists, with rate 0)
    /// is certain to exceed, capped at the current floor: see `recompute`.
    ///
    /// On the started flow's bottleneck link `l`, its new rate `r` satisfies
    /// `sum(min(old_i, r)) + r > capacity - flows(l)` over the other flows `i` on `l` (the
    /// link is saturated up to the floors, every other flow there ends at most at `r`, and a
    /// flow below `r` keeps its old rate). So any `x` with `sum(min(old_i, x)) + x <=
    /// capacity - flows(l)` on every link of the route is below `r`. Rates are trusted only
    /// below the current floor (they cannot have changed yet in this batch); above it, and
    /// for flows not yet rated, `min(old_i, x)` is replaced by its upper bound `x`.
    ///
    /// That bound costs a sort of each link's flows, worth it for a start alone at its
    /// instant (the common case once a run is under way). When other flows started in the
    /// same batch, or a link carries more than `SORTED_BOUND_MAX_FLOWS` flows, the link's
    /// initial share `capacity / flows` is used instead: also below the new rate, since the
    /// filling's shares only grow.
    fn start_floor(&mut self, route: &[LinkId]) -> u64 {
        let floor = self.dirty_floor;
        let mut result = floor;
        let batched = self.dirty_flows.len() > 1;
        let rates = &mut self.scratch.rates;
        for &l in route {
            let flows = &self.links[l as usize].flows;
            if batched || flows.len() > SORTED_BOUND_MAX_FLOWS {
                result = result.min(self.capacity / flows.len() as u64);
                continue;
            }
            let budget = self.capacity.saturating_sub(flows.len() as u64);
            rates.clear();
            rates.extend(
                flows
                    .iter()
                    .map(|&f| self.flows[f as usize].rate)
                    .filter(|&r| r != 0 && r < floor),
            );
            rates.sort_unstable();
            // Flows counted at x: the untrusted others and the started flow itself.
            let at_x = (flows.len() - rates.len()) as u64;
            let mut fixed_sum: u64 = 0;
            let mut best = 0;
            for k in 0..=rates.len() {
                if k > 0 {
                    fixed_sum += rates[k - 1];
                }
                let counted = at_x + (rates.len() - k) as u64;
                if fixed_sum > budget || counted == 0 {
                    break;
                }
                let x = (budget - fixed_sum) / counted;
                best = x;
                if k == rates.len() || x <= rates[k] {
                    break;
                }
            }
            result = result.min(best);
        }
        result
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
        f.active = false;
        self.dirty_floor = self.dirty_floor.min(f.rate);
        f.version = f.version.wrapping_add(1);
        let (msg, at) = (f.msg, now + f.tail);
        let route = std::mem::take(&mut f.route);
        for &l in &route {
            let link = &mut self.links[l as usize];
            let pos = link
                .flows
                .iter()
                .position(|&x| x == slot)
                .expect("flow on its link");
            link.flows.swap_remove(pos);
            if link.flows.is_empty() {
                link.busy += now - link.busy_since;
            }
            self.dirty_links.push(l);
        }
        self.flows[slot as usize].route = route;
        self.free_slots.push(slot);
        self.schedule_delivery(at, msg);
        self.mark_dirty(now);
    }

    /// Collects into the scratch lists every active flow of rate >= `floor` connected to the
    /// dirty flows and links through such flows, and the links they cross.
    fn collect_component(&mut self, floor: u64) {
        let s = &mut self.scratch;
        s.epoch += 1;
        s.component_flows.clear();
        s.component_links.clear();
        let epoch = s.epoch;
        let mut frontier: Vec<LinkId> = Vec::new();
        for &slot in &self.dirty_flows {
            if self.flows[slot as usize].active && s.flow_epoch[slot as usize] != epoch {
                s.flow_epoch[slot as usize] = epoch;
                s.component_flows.push(slot);
            }
        }
        frontier.extend(self.dirty_links.iter().copied());
        let mut next_flow = 0;
        loop {
            while let Some(l) = frontier.pop() {
                if s.link_epoch[l as usize] == epoch {
                    continue;
                }
                s.link_epoch[l as usize] = epoch;
                s.component_links.push(l);
                for &slot in &self.links[l as usize].flows {
                    if s.flow_epoch[slot as usize] != epoch
                        && self.flows[slot as usize].rate >= floor
                    {
                        s.flow_epoch[slot as usize] = epoch;
                        s.component_flows.push(slot);
                    }
                }
            }
            if next_flow == s.component_flows.len() {
                break;
            }
            let slot = s.component_flows[next_flow];
            next_flow += 1;
            frontier.extend(
                self.flows[slot as usize]
                    .route
                    .iter()
                    .filter(|&&l| s.link_epoch[l as usize] != epoch),
            );
        }
        self.dirty_flows.clear();
        self.dirty_links.clear();
    }

    /// New max-min fair rates for the dirty component at `now`, and new completions.
    ///
    /// A flow whose rate did not change keeps its completion entry: with the same rate,
    /// `since + ceil(remaining / rate)` is the same instant whenever it is computed.
    ///
    /// Flows whose rate is below a floor keep their rates, so the filling restarts at the
    /// floor with their rates subtracted and gives exactly the full recomputation's result.
    /// Why: adding or removing a flow `f` of rate `r` (with it present) cannot change any
    /// level below `r` of the filling, because no link `f` crosses is a bottleneck below
    /// `r` (it would have fixed `f` there), and without `f` those links' shares are only
    /// higher. An ended flow's `r` is its current rate; a started flow's `r` is at least the
    /// smallest `capacity / flows` on its route, since the filling's shares only grow. Over a
    /// batch of changes the floor is the minimum of theirs (by induction, no flow's rate at an
    /// intermediate step drops below it).
    fn recompute(&mut self, now: SimTime) {
        let mut floor = std::mem::replace(&mut self.dirty_floor, u64::MAX);
        if self.always_full {
            floor = 0;
        }
        self.collect_component(floor);
        let comp = std::mem::take(&mut self.scratch.component_flows);
        let mut old_rates = std::mem::take(&mut self.scratch.old_rates);
        old_rates.clear();
        for &slot in &comp {
            let f = &mut self.flows[slot as usize];
            let moved = f.rate as u128 * (now - f.since).ps() as u128;
            f.remaining = f.remaining.saturating_sub(moved);
            f.since = now;
            old_rates.push(f.rate);
            self.scratch.fixed[slot as usize] = false;
        }
        self.water_fill();
        for (&slot, &old_rate) in comp.iter().zip(&old_rates) {
            let f = &mut self.flows[slot as usize];
            if f.rate == old_rate {
                continue;
            }
            f.version = f.version.wrapping_add(1);
            let left = ceil_div(f.remaining, f.rate as u128);
            let (at, version) = (now + SimTime::from_ps(left), f.version);
            let seq = self.next_seq();
            self.completions.push(Reverse((at, seq, slot, version)));
        }
        self.scratch.component_flows = comp;
        self.scratch.old_rates = old_rates;
        self.compact_completions();
    }

    /// Progressive filling: repeatedly take the link whose remaining capacity gives its
    /// unfixed flows the smallest (floored) share, fix those flows at that share.
    ///
    /// Fixing flows at the current minimum share never lowers another link's share (it had
    /// at least that much per flow), so the heap keys are lazy lower bounds: a popped link
    /// whose real share has grown is pushed back with it, and no key is touched when a flow
    /// is fixed. Ties go to the lowest link index.
    fn water_fill(&mut self) {
        let s = &mut self.scratch;
        let mut keys = std::mem::take(&mut s.bottlenecks).into_vec();
        keys.clear();
        for &l in &s.component_links {
            let li = l as usize;
            let mut cap = self.capacity;
            let mut unfixed = 0;
            for &slot in &self.links[li].flows {
                let rate = self.flows[slot as usize].rate;
                // Outside the component means below the floor (collect_component took every
                // flow at or above it on these links, and every started flow).
                let below = s.flow_epoch[slot as usize] != s.epoch;
                s.fixed[slot as usize] = below;
                if below {
                    cap = cap.saturating_sub(rate);
                } else {
                    unfixed += 1;
                }
            }
            s.cap_left[li] = cap;
            s.unfixed[li] = unfixed;
            if unfixed > 0 {
                keys.push(Reverse(bottleneck_key(cap / unfixed as u64, l)));
            }
        }
        s.bottlenecks = BinaryHeap::from(keys);
        while let Some(Reverse(packed)) = s.bottlenecks.pop() {
            let (key, l) = ((packed >> 32) as u64, packed as u32);
            let li = l as usize;
            if s.unfixed[li] == 0 {
                continue;
            }
            let share = s.cap_left[li] / s.unfixed[li] as u64;
            if share > key {
                s.bottlenecks.push(Reverse(bottleneck_key(share, l)));
                continue;
            }
            let rate = share.max(1);
            for &slot in &self.links[li].flows {
                if s.fixed[slot as usize] {
                    continue;
                }
                s.fixed[slot as usize] = true;
                let f = &mut self.flows[slot as usize];
                f.rate = rate;
                for &l2 in &f.route {
                    let i = l2 as usize;
                    s.cap_left[i] = s.cap_left[i].saturating_sub(rate);
                    s.unfixed[i] -= 1;
                }
            }
        }
    }

    /// Rebuilds the completion heap when stale entries outnumber live ones, so it stays
    /// proportional to the active flows.
    fn compact_completions(&mut self) {
        let live = self.flows.len() - self.free_slots.len();
        if self.completions.len() <= 2 * live + 64 {
            return;
        }
        let flows = &self.flows;
        let mut entries = std::mem::take(&mut self.completions).into_vec();
        entries.retain(|Reverse((_, _, slot, version))| {
            let f = &flows[*slot as usize];
            f.active && f.version == *version
        });
        self.completions = BinaryHeap::from(entries);
    }

    fn drop_stale_completions(&mut self) {
        while let Some(&Reverse((_, _, slot, version))) = self.completions.peek() {
            let f = &self.flows[slot as usize];
            if f.active && f.version == version {
                break;
            }
            self.completions.pop();
        }
    }
}

impl Transport for Flow {
    fn inject(
        &mut self,
        now: SimTime,
        msg: MsgId,
        route: &[LinkId],
        hops: u32,
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
        let completion = self.completions.peek().map(|Reverse(e)| e.0);
        let delivery = self.deliveries.peek().map(|Reverse(e)| e.0);
        [self.dirty_since, completion, delivery]
            .into_iter()
            .flatten()
            .min()
    }

    fn advance(&mut self, now: SimTime, delivered: &mut Vec<Delivered>) {
        self.clock = self.clock.max(now);
        while let Some(&Reverse((at, _, slot, _))) = self.completions.peek() {
            if at > now {
                break;
            }
            self.completions.pop();
            self.finish_flow(at, slot);
            self.drop_stale_completions();
        }
        if self.dirty_since.take().is_some() {
            self.recompute(now);
            self.drop_stale_completions();
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
        let running = if l.flows.is_empty() {
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

/// Above this many flows on a link, `start_floor` uses the cheap bound for it.
const SORTED_BOUND_MAX_FLOWS: usize = 256;

/// Orders by share, then by link index.
fn bottleneck_key(share: u64, link: LinkId) -> u128 {
    (share as u128) << 32 | link as u128
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
        }
    }

    /// Runs random overlapping flows on 12 links, starting at multiples of `grain` ps (a
    /// coarse grain makes starts coincide with each other and with completions); returns
    /// every delivery in order.
    fn run(always_full: bool, seed: u64, grain: u64) -> Vec<Delivered> {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let mut flow = Flow::new(timing(), 12);
        flow.always_full = always_full;
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
                flow.inject(*at, next as MsgId, route, route.len() as u32, *bytes);
                next += 1;
            }
            if flow.next_event_time() == Some(now) {
                flow.advance(now, &mut out);
            }
        }
        out
    }

    #[test]
    fn restarting_the_filling_at_the_ended_rate_equals_a_full_recomputation() {
        for seed in 0..8 {
            for grain in [1, 1_000_000_000, 5_000_000_000] {
                let full = run(true, seed, grain);
                assert_eq!(full.len(), 300);
                assert_eq!(run(false, seed, grain), full, "seed {seed} grain {grain}");
            }
        }
    }
}
