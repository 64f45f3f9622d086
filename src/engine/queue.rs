//! The event queue: pending events keyed by (time, insertion sequence), earliest first.
//!
//! Heap entries are 16 bytes: time (64 bits), sequence (40 bits) and the event's slot in a
//! side slab (24 bits) packed into one u128, in a 4-ary heap (dary_heap crate: half the depth
//! of a binary heap, so fewer cache lines touched per pop), so sifting moves little memory; event bodies stay
//! put in the slab, whose freed slots are reused first (they are warm in cache).
//! Owns ordering only; must never look at what an event means.

use dary_heap::QuaternaryHeap;
use std::cmp::Reverse;

use crate::units::SimTime;

const SLOT_BITS: u32 = 24;
const SEQ_BITS: u32 = 64 - SLOT_BITS;

/// Pending events, earliest first, FIFO among equal times.
pub struct EventQueue<E> {
    heap: QuaternaryHeap<Reverse<u128>>,
    slots: Vec<Option<E>>,
    free: Vec<u32>,
    next_seq: u64,
}

impl<E> Default for EventQueue<E> {
    fn default() -> Self {
        EventQueue {
            heap: QuaternaryHeap::new(),
            slots: Vec::new(),
            free: Vec::new(),
            next_seq: 0,
        }
    }
}

impl<E> EventQueue<E> {
    pub fn with_capacity(n: usize) -> Self {
        EventQueue {
            heap: QuaternaryHeap::with_capacity(n),
            slots: Vec::with_capacity(n),
            free: Vec::new(),
            next_seq: 0,
        }
    }

    /// Schedules `event` at `at`, after every event already scheduled at `at`.
    pub fn push(&mut self, at: SimTime, event: E) {
        let slot = match self.free.pop() {
            Some(s) => {
                self.slots[s as usize] = Some(event);
                s
            }
            None => {
                let s = self.slots.len() as u32;
                assert!(s < 1 << SLOT_BITS, "more than 2^24 events pending at once");
                self.slots.push(Some(event));
                s
            }
        };
        assert!(
            self.next_seq < 1 << SEQ_BITS,
            "a run scheduled more than 2^40 events"
        );
        let low = (self.next_seq << SLOT_BITS) | slot as u64;
        self.next_seq += 1;
        self.heap
            .push(Reverse(((at.ps() as u128) << 64) | low as u128));
    }

    pub fn pop(&mut self) -> Option<(SimTime, E)> {
        let Reverse(key) = self.heap.pop()?;
        let slot = (key as u64 & ((1 << SLOT_BITS) - 1)) as u32;
        let event = self.slots[slot as usize]
            .take()
            .expect("a queued slot holds its event");
        self.free.push(slot);
        Some((SimTime::from_ps((key >> 64) as u64), event))
    }

    pub fn peek_time(&self) -> Option<SimTime> {
        self.heap
            .peek()
            .map(|Reverse(key)| SimTime::from_ps((key >> 64) as u64))
    }

    pub fn len(&self) -> usize {
        self.heap.len()
    }

    pub fn is_empty(&self) -> bool {
        self.heap.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orders_by_time_then_insertion() {
        let mut q = EventQueue::default();
        q.push(SimTime::from_ps(5), 'a');
        q.push(SimTime::from_ps(3), 'b');
        q.push(SimTime::from_ps(5), 'c');
        q.push(SimTime::from_ps(3), 'd');
        q.push(SimTime::MAX, 'e');
        let order: Vec<char> = std::iter::from_fn(|| q.pop().map(|(_, e)| e)).collect();
        assert_eq!(order, ['b', 'd', 'a', 'c', 'e']);
    }

    #[test]
    fn slots_are_reused_without_disturbing_order() {
        let mut q = EventQueue::default();
        for i in 0..100u64 {
            q.push(SimTime::from_ps(1000 - i), i);
            if i % 3 == 0 {
                q.pop();
            }
        }
        let times: Vec<u64> = std::iter::from_fn(|| q.pop().map(|(t, _)| t.ps())).collect();
        assert!(times.windows(2).all(|w| w[0] <= w[1]));
        assert_eq!(times.len(), 100 - 34);
    }
}
