//! The fluid transfers' completion instants, one entry per flow, kept in order.
//!
//! Owns a binary min-heap of `(completion, message, flow slot)` with each slot's position
//! kept beside it, so a flow whose rate changes moves its one entry in place instead of
//! leaving a stale entry behind (the heap stays as large as the flows carrying data).
//! Entries order by completion, then by message id: flows completing at one instant finish
//! in `MsgId` order.
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

    /// Flow `slot` (carrying `msg`) completes at `at`, replacing any earlier entry of its own.
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

    /// Takes the earliest entry out.
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
        /// Against a plain map from slot to entry: every `first` and `pop` agrees.
        #[test]
        fn keeps_the_order_of_a_plain_map(ops in proptest::collection::vec(
            (0u32..24, 0u64..50, any::<bool>()), 1..300)
        ) {
            let mut heap = Completions::default();
            let mut plain: BTreeMap<u32, (SimTime, MsgId)> = BTreeMap::new();
            for (slot, at, take) in ops {
                if take {
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
