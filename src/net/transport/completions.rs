//! The fluid transfers' next completion instants, one entry per slot (a group of flows
//! sharing a rate in `flow`, a single flow in the tests' per-flow account), kept in order.
//!
//! Owns a binary min-heap of `(completion, message, slot)` with each slot's position kept
//! beside it, so a slot whose rate or first member changes moves its one entry in place (or
//! drops it) instead of leaving a stale entry behind. Entries order by completion, then by
//! message id.
//!
//! Must never hold two entries for one slot, and never order by anything but the entry.

use crate::net::MsgId;
use crate::units::SimTime;

/// Where a slot with no entry stands in `position`.
const ABSENT: u32 = u32::MAX;

#[derive(Default)]
pub struct Completions {
    heap: Vec<(SimTime, MsgId, u32)>,
    /// `position[slot]`: the slot's index in `heap`, or `ABSENT`.
    position: Vec<u32>,
}

impl Completions {
    /// The earliest completion: (instant, message, slot).
    pub fn first(&self) -> Option<(SimTime, MsgId, u32)> {
        self.heap.first().copied()
    }

    /// Slot `slot` (its first message `msg`) completes at `at`, replacing any entry of its own.
    pub fn set(&mut self, slot: u32, msg: MsgId, at: SimTime) {
        let s = slot as usize;
        if s >= self.position.len() {
            self.position.resize(s + 1, ABSENT);
        }
        let entry = (at, msg, slot);
        match self.position[s] {
            ABSENT => {
                self.heap.push(entry);
                self.sift_up(self.heap.len() - 1);
            }
            i => {
                let i = i as usize;
                let earlier = entry < self.heap[i];
                self.heap[i] = entry;
                if earlier {
                    self.sift_up(i);
                } else {
                    self.sift_down(i);
                }
            }
        }
    }

    /// Drops `slot`'s entry, if it has one.
    pub fn remove(&mut self, slot: u32) {
        let Some(&i) = self.position.get(slot as usize) else {
            return;
        };
        if i == ABSENT {
            return;
        }
        let i = i as usize;
        self.position[slot as usize] = ABSENT;
        let last = self.heap.pop().expect("an entry is in the heap");
        if i < self.heap.len() {
            // The last entry takes the freed place and moves whichever way it must.
            let earlier = last < self.heap[i];
            self.place(i, last);
            if earlier {
                self.sift_up(i);
            } else {
                self.sift_down(i);
            }
        }
    }

    /// Takes the earliest entry out (the tests' per-flow account).
    #[cfg(test)]
    pub fn pop(&mut self) -> Option<(SimTime, MsgId, u32)> {
        let first = *self.heap.first()?;
        let last = self.heap.pop().expect("not empty");
        self.position[first.2 as usize] = ABSENT;
        if !self.heap.is_empty() {
            self.heap[0] = last;
            self.sift_down(0);
        }
        Some(first)
    }

    fn place(&mut self, i: usize, entry: (SimTime, MsgId, u32)) {
        self.heap[i] = entry;
        self.position[entry.2 as usize] = i as u32;
    }

    fn sift_up(&mut self, mut i: usize) {
        let entry = self.heap[i];
        while i > 0 {
            let parent = (i - 1) / 2;
            if self.heap[parent] <= entry {
                break;
            }
            self.place(i, self.heap[parent]);
            i = parent;
        }
        self.place(i, entry);
    }

    fn sift_down(&mut self, mut i: usize) {
        let entry = self.heap[i];
        let n = self.heap.len();
        loop {
            let left = 2 * i + 1;
            if left >= n {
                break;
            }
            let right = left + 1;
            let child = if right < n && self.heap[right] < self.heap[left] {
                right
            } else {
                left
            };
            if entry <= self.heap[child] {
                break;
            }
            self.place(i, self.heap[child]);
            i = child;
        }
        self.place(i, entry);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use std::collections::BTreeMap;

    proptest! {
        /// Against a plain map from slot to entry: every `first` and `pop` agrees, with entries
        /// set, moved and removed at random.
        #[test]
        fn keeps_the_order_of_a_plain_map(ops in proptest::collection::vec(
            (0u32..24, 0u64..50, 0u8..3), 1..300)
        ) {
            let mut heap = Completions::default();
            let mut plain: BTreeMap<u32, (SimTime, MsgId)> = BTreeMap::new();
            for (slot, at, op) in ops {
                if op == 2 {
                    heap.remove(slot);
                    plain.remove(&slot);
                } else if op == 1 {
                    let want = plain
                        .iter()
                        .map(|(&s, &(t, m))| (t, m, s))
                        .min();
                    prop_assert_eq!(heap.pop(), want);
                    if let Some((_, _, s)) = want {
                        plain.remove(&s);
                    }
                } else {
                    // A slot's message id is fixed while it has an entry; ties in time
                    // are common (at < 50).
                    let msg = plain.get(&slot).map_or(slot as MsgId * 7 % 24, |e| e.1);
                    heap.set(slot, msg, SimTime::from_ps(at));
                    plain.insert(slot, (SimTime::from_ps(at), msg));
                }
                let want = plain.iter().map(|(&s, &(t, m))| (t, m, s)).min();
                prop_assert_eq!(heap.first(), want);
            }
        }
    }
}
