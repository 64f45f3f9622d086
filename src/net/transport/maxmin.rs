//! Exact integer max-min fair rates of flows sharing links, kept current as flows start and
//! end, at a cost that follows the rates that actually change.
//!
//! The allocation is defined by one procedure, progressive filling in whole bits per second:
//! repeatedly take the link with unfixed flows whose share `floor(capacity_left / unfixed)`
//! is smallest (ties to the lowest link index), fix its unfixed flows at `max(share, 1)`, and
//! take their rates from the capacity left on every link they cross (never below 0). Each
//! link that fixes flows does so at a *key* `(share, link)`; keys rise through the filling,
//! and a flow's key is its bottleneck link's. [`reference_rates`] runs that procedure plainly
//! over every link; it is the oracle the tests compare against.
//!
//! [`MaxMin::solve`] gives the same rates by replaying the filling only where it differs from
//! the last solve. A link's pop depends only on which of its flows are fixed before it and at
//! what rates, so a link none of whose flows changed pops at its old key and is not looked at.
//! The sweep walks keys upward through a heap of *dirty* links (their flow set changed, or a
//! flow on them got a new rate or key), each evaluated at the sweep's current key from its
//! flows: a flow settled in this sweep counts at its new rate, an untouched one at its old
//! rate if its old key has passed. Flows whose bottleneck turned dirty are *unsettled*: if
//! one is still unfixed when the sweep passes its old key, every link it crosses turns dirty
//! there (they would have counted it as fixed). Before any link's old key is passed, every
//! way its pop could differ has marked it dirty, so untouched links and flows keep their old
//! keys and rates exactly.
//!
//! Must never use floating point, never iterate a hash map, and never depend on anything but
//! the flows' routes and the link capacity (not on the order flows were added).

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use crate::net::LinkId;

/// `(share << 32) | link`: the order in which links fix their flows.
type Key = u128;

/// A link that fixed no flow (every flow on it was fixed before it), or a flow not yet rated.
const NONE: Key = Key::MAX;

fn key(share: u64, link: LinkId) -> Key {
    (share as Key) << 32 | link as Key
}

fn share_of(key: Key) -> u64 {
    (key >> 32) as u64
}

fn link_of(key: Key) -> LinkId {
    key as LinkId
}

/// Flows sharing links of one capacity, and their max-min fair rates as of the last
/// [`MaxMin::solve`].
pub struct MaxMin {
    capacity: u64,
    links: Vec<Link>,
    flows: Vec<Flow>,
    /// Links whose flow set changed since the last solve.
    touched: Vec<LinkId>,
    /// Flows added since the last solve.
    added: Vec<u32>,
    sweep: Sweep,
}

#[derive(Default)]
struct Link {
    flows: Vec<u32>,
    key: Key,
}

struct Flow {
    route: Vec<LinkId>,
    rate: u64,
    key: Key,
    live: bool,
}

/// Per-solve state; `epoch` stamps what belongs to the current solve.
#[derive(Default)]
struct Sweep {
    epoch: u64,
    flows: Vec<SweepFlow>,
    /// Epoch in which each link turned dirty, and its new key once evaluated.
    link_epoch: Vec<u64>,
    link_key: Vec<Key>,
    dirty: Vec<LinkId>,
    settled: Vec<u32>,
    /// Min-heap of `(key << 1 | kind, id)`: kind 0 evaluates link `id` (the key is a lower
    /// bound of its real one), kind 1 is the old key of unsettled flow `id`. At one key, a
    /// link is evaluated before a flow's old key counts as passed.
    heap: BinaryHeap<Reverse<(u128, u32)>>,
    /// The key of the last link that fixed flows or of the last flow key passed.
    now: Key,
}

#[derive(Clone, Copy, Default)]
struct SweepFlow {
    epoch: u64,
    settled: bool,
    rate: u64,
    key: Key,
}

const EVALUATE: u128 = 0;
const PASSED: u128 = 1;

impl MaxMin {
    /// `links` links of `capacity` bits per second each.
    pub fn new(capacity: u64, links: usize) -> MaxMin {
        MaxMin {
            capacity,
            links: (0..links)
                .map(|_| Link {
                    flows: Vec::new(),
                    key: NONE,
                })
                .collect(),
            flows: Vec::new(),
            touched: Vec::new(),
            added: Vec::new(),
            sweep: Sweep {
                link_epoch: vec![0; links],
                link_key: vec![NONE; links],
                ..Sweep::default()
            },
        }
    }

    /// Adds flow `slot` (not present) on `route`; it has no rate until the next solve.
    pub fn add(&mut self, slot: u32, route: &[LinkId]) {
        let i = slot as usize;
        if i >= self.flows.len() {
            self.flows.resize_with(i + 1, || Flow {
                route: Vec::new(),
                rate: 0,
                key: NONE,
                live: false,
            });
            self.sweep.flows.resize(i + 1, SweepFlow::default());
        }
        let f = &mut self.flows[i];
        f.route.clear();
        f.route.extend_from_slice(route);
        f.rate = 0;
        f.key = NONE;
        f.live = true;
        for &l in route {
            self.links[l as usize].flows.push(slot);
        }
        self.touched.extend_from_slice(route);
        self.added.push(slot);
    }

    /// Removes flow `slot`; the others' rates change at the next solve.
    pub fn remove(&mut self, slot: u32) {
        let f = &mut self.flows[slot as usize];
        f.rate = 0;
        f.key = NONE;
        f.live = false;
        for &l in &f.route {
            let flows = &mut self.links[l as usize].flows;
            let pos = flows
                .iter()
                .position(|&x| x == slot)
                .expect("flow on its link");
            flows.swap_remove(pos);
        }
        self.touched.extend_from_slice(&f.route);
    }

    /// Flows on `link` now.
    pub fn flows_on(&self, link: LinkId) -> usize {
        self.links[link as usize].flows.len()
    }

    /// The links flow `slot` crosses.
    pub fn route(&self, slot: u32) -> &[LinkId] {
        &self.flows[slot as usize].route
    }

    /// The rate of flow `slot` as of the last solve (0 before its first).
    pub fn rate(&self, slot: u32) -> u64 {
        self.flows[slot as usize].rate
    }

    /// Brings every rate up to date with the adds and removes since the last solve; appends
    /// `(slot, old rate)` for every flow whose rate changed (0 for an added flow), in the
    /// order the filling fixed them.
    pub fn solve(&mut self, changed: &mut Vec<(u32, u64)>) {
        let s = &mut self.sweep;
        s.epoch += 1;
        s.now = 0;
        s.dirty.clear();
        s.settled.clear();
        s.heap.clear();
        for &slot in &self.added {
            s.flows[slot as usize] = SweepFlow {
                epoch: s.epoch,
                settled: false,
                rate: 0,
                key: NONE,
            };
        }
        self.added.clear();
        let touched = std::mem::take(&mut self.touched);
        for &l in &touched {
            self.mark_dirty(l);
        }
        self.touched = touched;
        self.touched.clear();
        while let Some(Reverse((entry, id))) = self.sweep.heap.pop() {
            let at = entry >> 1;
            if entry & 1 == EVALUATE {
                self.evaluate(id, at);
            } else {
                self.pass_flow_key(id, at);
            }
        }
        self.commit(changed);
    }

    /// Makes `link` part of the sweep (once): it will be evaluated, and the flows it fixed
    /// last time are unsettled until it fixes them again.
    fn mark_dirty(&mut self, link: LinkId) {
        let s = &mut self.sweep;
        let l = link as usize;
        if s.link_epoch[l] == s.epoch {
            return;
        }
        debug_assert!(
            self.links[l].key >= s.now,
            "link {link} turned dirty after its old key had passed"
        );
        s.link_epoch[l] = s.epoch;
        s.link_key[l] = NONE;
        s.dirty.push(link);
        // Every link not yet fixing has a real key above `now`, so (share of now, link) is a
        // lower bound of it.
        let bound = key(share_of(s.now), link);
        s.heap.push(Reverse((bound << 1 | EVALUATE, link)));
        for &slot in &self.links[l].flows {
            let sf = &mut s.flows[slot as usize];
            let f = &self.flows[slot as usize];
            if sf.epoch != s.epoch && link_of(f.key) == link && f.key != NONE {
                *sf = SweepFlow {
                    epoch: s.epoch,
                    settled: false,
                    rate: f.rate,
                    key: f.key,
                };
                s.heap.push(Reverse((f.key << 1 | PASSED, slot)));
            }
        }
    }

    /// Whether `slot` is fixed when the sweep stands at `at`: settled in this sweep, or
    /// untouched with an old key below `at`.
    fn fixed_rate(&self, slot: u32, at: Key) -> Option<u64> {
        let sf = &self.sweep.flows[slot as usize];
        if sf.epoch == self.sweep.epoch {
            return sf.settled.then_some(sf.rate);
        }
        let f = &self.flows[slot as usize];
        (f.key < at).then_some(f.rate)
    }

    /// Evaluates dirty `link` at lower bound `bound`: fixes its flows if its real key is the
    /// bound, otherwise pushes it back at its real key.
    fn evaluate(&mut self, link: LinkId, bound: Key) {
        let at = bound.max(self.sweep.now);
        let mut left = self.capacity;
        let mut unfixed = 0u64;
        for &slot in &self.links[link as usize].flows {
            match self.fixed_rate(slot, at) {
                Some(rate) => left = left.saturating_sub(rate),
                None => unfixed += 1,
            }
        }
        if unfixed == 0 {
            return;
        }
        let share = left / unfixed;
        let real = key(share, link);
        debug_assert!(real >= at, "link {link}'s share fell below the sweep");
        if real > at {
            self.sweep.heap.push(Reverse((real << 1 | EVALUATE, link)));
            return;
        }
        self.sweep.now = real;
        self.sweep.link_key[link as usize] = real;
        let rate = share.max(1);
        for i in 0..self.links[link as usize].flows.len() {
            let slot = self.links[link as usize].flows[i];
            if self.fixed_rate(slot, at).is_none() {
                self.settle(slot, rate, real);
            }
        }
    }

    /// Flow `slot` is fixed at `rate` by the link of key `at`. Links that counted it
    /// differently last time turn dirty.
    fn settle(&mut self, slot: u32, rate: u64, at: Key) {
        let s = &mut self.sweep;
        let sf = &mut s.flows[slot as usize];
        let (old_rate, old_key) = if sf.epoch == s.epoch {
            (sf.rate, sf.key)
        } else {
            let f = &self.flows[slot as usize];
            (f.rate, f.key)
        };
        *sf = SweepFlow {
            epoch: s.epoch,
            settled: true,
            rate,
            key: at,
        };
        s.settled.push(slot);
        if old_key == NONE || (old_rate == rate && old_key == at) {
            // An added flow's links are all dirty already.
            return;
        }
        for i in 0..self.flows[slot as usize].route.len() {
            let l = self.flows[slot as usize].route[i];
            self.mark_dirty(l);
        }
    }

    /// The sweep passes the old key of flow `slot`: if nothing fixed it yet, every link it
    /// crosses counted it as fixed from here on, and must be evaluated.
    fn pass_flow_key(&mut self, slot: u32, at: Key) {
        self.sweep.now = self.sweep.now.max(at);
        if self.sweep.flows[slot as usize].settled {
            return;
        }
        for i in 0..self.flows[slot as usize].route.len() {
            let l = self.flows[slot as usize].route[i];
            self.mark_dirty(l);
        }
    }

    fn commit(&mut self, changed: &mut Vec<(u32, u64)>) {
        let s = &mut self.sweep;
        for &l in &s.dirty {
            self.links[l as usize].key = s.link_key[l as usize];
        }
        for &slot in &s.settled {
            let sf = s.flows[slot as usize];
            let f = &mut self.flows[slot as usize];
            if f.rate != sf.rate {
                changed.push((slot, f.rate));
            }
            f.rate = sf.rate;
            f.key = sf.key;
        }
    }
}

#[cfg(test)]
impl MaxMin {
    /// What [`MaxMin::solve`] must do, done plainly: every rate from [`reference_rates`].
    pub fn solve_from_scratch(&mut self, changed: &mut Vec<(u32, u64)>) {
        self.added.clear();
        self.touched.clear();
        let live: Vec<u32> = (0..self.flows.len() as u32)
            .filter(|&s| self.flows[s as usize].live)
            .collect();
        let routes: Vec<Vec<LinkId>> = live
            .iter()
            .map(|&s| self.flows[s as usize].route.clone())
            .collect();
        let rates = reference_rates(self.capacity, self.links.len(), &routes);
        for (&slot, rate) in live.iter().zip(rates) {
            let f = &mut self.flows[slot as usize];
            if f.rate != rate {
                changed.push((slot, f.rate));
                f.rate = rate;
            }
        }
    }
}

#[cfg(test)]
/// Progressive filling from scratch over every link: the plain procedure [`MaxMin`] must
/// agree with. `routes[i]` is flow i's route; returns its rate.
pub fn reference_rates(capacity: u64, links: usize, routes: &[Vec<LinkId>]) -> Vec<u64> {
    let mut on_link: Vec<Vec<usize>> = vec![Vec::new(); links];
    for (i, route) in routes.iter().enumerate() {
        for &l in route {
            on_link[l as usize].push(i);
        }
    }
    let mut left = vec![capacity; links];
    let mut unfixed: Vec<u64> = on_link.iter().map(|f| f.len() as u64).collect();
    let mut rate: Vec<Option<u64>> = vec![None; routes.len()];
    loop {
        let Some((share, l)) = (0..links)
            .filter(|&l| unfixed[l] > 0)
            .map(|l| (left[l] / unfixed[l], l))
            .min()
        else {
            break;
        };
        for &i in &on_link[l] {
            if rate[i].is_some() {
                continue;
            }
            let r = share.max(1);
            rate[i] = Some(r);
            for &l2 in &routes[i] {
                left[l2 as usize] = left[l2 as usize].saturating_sub(r);
                unfixed[l2 as usize] -= 1;
            }
        }
    }
    rate.into_iter()
        .map(|r| r.expect("every flow fixed"))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// One step of a pattern: flows added (routes) and flows removed (indices into the live
    /// list, taken modulo its length), then a solve.
    #[derive(Clone, Debug)]
    struct Step {
        add: Vec<Vec<LinkId>>,
        remove: Vec<usize>,
    }

    fn route(links: u32) -> impl Strategy<Value = Vec<LinkId>> {
        // A path on a ring of links (what e-cube and ring routes look like), sometimes a
        // scattered set (a torus route crosses two dimensions).
        prop_oneof![
            (0..links, 1..6u32)
                .prop_map(move |(first, len)| (first..first + len).map(|l| l % links).collect()),
            proptest::collection::btree_set(0..links, 1..5).prop_map(|s| s.into_iter().collect()),
        ]
    }

    fn steps(links: u32) -> impl Strategy<Value = Vec<Step>> {
        let step = (
            proptest::collection::vec(route(links), 0..6),
            proptest::collection::vec(any::<usize>(), 0..4),
        )
            .prop_map(|(add, remove)| Step { add, remove });
        proptest::collection::vec(step, 1..40)
    }

    /// Applies `steps` to a `MaxMin` and checks every flow's rate against the reference
    /// after every solve, and that `changed` lists exactly the flows whose rate moved.
    fn check(capacity: u64, links: u32, steps: &[Step]) -> Result<(), TestCaseError> {
        let mut mm = MaxMin::new(capacity, links as usize);
        let mut live: Vec<(u32, Vec<LinkId>)> = Vec::new();
        let mut free: Vec<u32> = Vec::new();
        let mut next = 0u32;
        let mut before: Vec<u64> = Vec::new();
        for step in steps {
            for &r in &step.remove {
                if live.is_empty() {
                    break;
                }
                let (slot, _) = live.swap_remove(r % live.len());
                mm.remove(slot);
                free.push(slot);
                before[slot as usize] = 0;
            }
            for route in &step.add {
                let slot = free.pop().unwrap_or_else(|| {
                    next += 1;
                    next - 1
                });
                mm.add(slot, route);
                live.push((slot, route.clone()));
            }
            let mut changed = Vec::new();
            mm.solve(&mut changed);
            let routes: Vec<Vec<LinkId>> = live.iter().map(|(_, r)| r.clone()).collect();
            let expected = reference_rates(capacity, links as usize, &routes);
            before.resize(next as usize, 0);
            for ((slot, _), want) in live.iter().zip(&expected) {
                prop_assert_eq!(mm.rate(*slot), *want, "flow in slot {}", slot);
            }
            let mut moved: Vec<u32> = live
                .iter()
                .filter(|(slot, _)| before[*slot as usize] != mm.rate(*slot))
                .map(|(slot, _)| *slot)
                .collect();
            let mut listed: Vec<u32> = changed.iter().map(|c| c.0).collect();
            moved.sort_unstable();
            listed.sort_unstable();
            prop_assert_eq!(listed, moved);
            for &(slot, old) in &changed {
                prop_assert_eq!(old, before[slot as usize]);
            }
            for (slot, _) in &live {
                before[*slot as usize] = mm.rate(*slot);
            }
        }
        Ok(())
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(3000))]

        /// Small capacities make floors, ties and shares of 0 (rate 1) common.
        #[test]
        fn equals_progressive_filling_from_scratch_small_capacity(
            capacity in 1u64..40, s in steps(10)
        ) {
            check(capacity, 10, &s)?;
        }

        #[test]
        fn equals_progressive_filling_from_scratch_real_capacity(s in steps(24)) {
            check(136_000_000, 24, &s)?;
        }
    }

    #[test]
    fn equals_progressive_filling_on_a_long_random_pattern() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let links = 64u32;
        let steps: Vec<Step> = (0..400)
            .map(|_| Step {
                add: (0..rng.gen_range(0..8))
                    .map(|_| {
                        let first = rng.gen_range(0..links);
                        (first..first + rng.gen_range(1..9))
                            .map(|l| l % links)
                            .collect()
                    })
                    .collect(),
                remove: (0..rng.gen_range(0..7)).map(|_| rng.gen()).collect(),
            })
            .collect();
        check(1_000_003, links, &steps).unwrap();
    }
}
