//! The event queue: pending events keyed by (time, insertion sequence), earliest first.
//!
//! Keys are 16 bytes: time (64 bits), sequence (40 bits) and the event's slot in a side slab
//! (24 bits) packed into one u128, so every key is distinct and their order is the events'.
//! They are held in one of two structures, chosen by how many are pending:
//! - up to tens of thousands, a 4-ary heap (dary_heap crate: half the depth of a binary heap,
//!   so fewer cache lines touched per pop), which is fastest while it fits in cache;
//! - beyond that, a radix heap: a simulation never schedules before the last event it took,
//!   so the keys taken out only rise, a push is an append to a bucket and a key moves a few
//!   times at most instead of sifting through a heap of a million.
//!
//! Both give the same order (the keys'), so the switch is invisible to the simulation, and
//! both have the next key at hand, so the next event can be looked at before it is taken.
//! A [`Place`] in that order can also be reserved without queueing anything, for events kept
//! elsewhere that must still run exactly where a queued one would (the network's wake-ups).
//! Event bodies stay put in a side slab, whose freed slots are reused first (warm in cache);
//! beside each slot the queue keeps a word its pusher may attach (a hint), handed back for a
//! look ahead at the next two events without their bodies read.
//! Owns ordering only; must never look at what an event means, and never accepts a key below
//! the last one taken (that would break the radix heap's order; it panics instead).

use std::cmp::Reverse;

use dary_heap::QuaternaryHeap;

use crate::units::SimTime;

const SLOT_BITS: u32 = 24;
const _: () = assert!(1 << SLOT_BITS == crate::limits::MAX_PENDING_EVENTS);
const SEQ_BITS: u32 = 64 - SLOT_BITS;

/// A place in the queue's order: a time and an insertion sequence number (a reserved place,
/// or a queued event's).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct Place(u128);

impl Place {
    /// The first place at `at`, before every event at that time.
    pub fn first_at(at: SimTime) -> Place {
        Place((at.ps() as u128) << 64)
    }

    pub fn time(self) -> SimTime {
        SimTime::from_ps((self.0 >> 64) as u64)
    }
}

/// The slot of the side slab a key's event body is in.
fn slot_of(key: u128) -> usize {
    (key as u64 & ((1 << SLOT_BITS) - 1)) as usize
}

/// Pending events, earliest first, FIFO among equal times.
pub struct EventQueue<E> {
    keys: Keys,
    slots: Vec<Option<E>>,
    /// A word the caller attached to each slot's event, for its look ahead
    /// ([`EventQueue::push_hinted`]); kept apart from the bodies, so that it stays in cache.
    hints: Vec<u32>,
    free: Vec<u32>,
    next_seq: u64,
}

/// The hint of an event pushed without one.
const NO_HINT: u32 = u32::MAX;

/// The next two events as a look ahead sees them ([`EventQueue::look_ahead`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LookAhead {
    /// The hint of the earliest event.
    pub next: Option<u32>,
    /// The hint of the event after it, when it was cheap to find.
    pub after: Option<u32>,
    /// Where that event's body is kept.
    pub after_body: Option<*const u8>,
}

impl<E> Default for EventQueue<E> {
    fn default() -> Self {
        EventQueue {
            keys: Keys::default(),
            slots: Vec::new(),
            hints: Vec::new(),
            free: Vec::new(),
            next_seq: 0,
        }
    }
}

impl<E> EventQueue<E> {
    /// A queue that moves its keys into a radix heap past `to_radix` pending and back below
    /// `to_heap` (tests use small numbers to cross both often).
    #[cfg(test)]
    fn with_thresholds(to_radix: usize, to_heap: usize) -> Self {
        EventQueue {
            keys: Keys::with_thresholds(to_radix, to_heap),
            ..EventQueue::default()
        }
    }

    pub fn with_capacity(n: usize) -> Self {
        EventQueue {
            keys: Keys::default(),
            slots: Vec::with_capacity(n),
            hints: Vec::with_capacity(n),
            free: Vec::new(),
            next_seq: 0,
        }
    }

    /// Schedules `event` at `at`, after every event already scheduled at `at`; `at` must not
    /// be earlier than the last event taken.
    ///
    /// Inlined, and the event written in one place only, so that the caller stores its fields
    /// straight into its slot: built apart and copied in, the copy's wide loads would wait for
    /// the narrow stores that built it.
    #[inline]
    pub fn push(&mut self, at: SimTime, event: E) {
        self.push_hinted(at, event, None);
    }

    /// [`EventQueue::push`], with a word the queue keeps beside the event and hands back to a
    /// look ahead ([`EventQueue::look_ahead`]) without reading the event's body; the queue
    /// never reads it itself.
    #[inline]
    pub fn push_hinted(&mut self, at: SimTime, event: E, hint: Option<u32>) {
        if self.free.is_empty() {
            self.add_slot();
        }
        let slot = self.free.pop().expect("a free slot was just made");
        self.slots[slot as usize] = Some(event);
        self.hints[slot as usize] = hint.unwrap_or(NO_HINT);
        self.file(at, slot);
    }

    /// A free slot at the slab's end (a run's first events, then only past its most pending).
    #[cold]
    #[inline(never)]
    fn add_slot(&mut self) {
        let s = self.slots.len() as u32;
        assert!(s < 1 << SLOT_BITS, "more than 2^24 events pending at once");
        self.slots.push(None);
        self.hints.push(NO_HINT);
        self.free.push(s);
    }

    /// Queues the key of the event in `slot`, at `at`.
    #[inline(never)]
    fn file(&mut self, at: SimTime, slot: u32) {
        let Place(key) = self.reserve(at);
        self.keys.push(key | slot as u128);
    }

    /// The place an event pushed at `at` now would take, taken so that no later event can
    /// have it; nothing is queued.
    pub fn reserve(&mut self, at: SimTime) -> Place {
        assert!(
            self.next_seq < 1 << SEQ_BITS,
            "a run scheduled more than 2^40 events"
        );
        let low = self.next_seq << SLOT_BITS;
        self.next_seq += 1;
        Place(((at.ps() as u128) << 64) | low as u128)
    }

    /// The place of the last event taken (the start of the order before any).
    pub fn last_taken(&self) -> Place {
        Place(self.keys.last)
    }

    pub fn pop(&mut self) -> Option<(SimTime, E)> {
        self.pop_until(SimTime::MAX)
    }

    /// Takes the earliest event if it is due at or before `horizon`.
    pub fn pop_until(&mut self, horizon: SimTime) -> Option<(SimTime, E)> {
        self.pop_before(horizon, None)
    }

    /// The earliest event (the look ahead reads hints instead: [`EventQueue::look_ahead`]).
    #[cfg(test)]
    pub fn peek(&self) -> Option<&E> {
        let key = self.keys.peek()?;
        self.slots[slot_of(key)].as_ref()
    }

    /// What a look ahead needs of the next two events, found with no event's body read:
    /// the hint of the earliest, and, when finding it is cheap (the keys in the heap: the
    /// least of the root's children), the hint of the event after it and where its body is
    /// kept, so that it can be fetched while the earliest is taken. Pushes before the next pop
    /// may come earlier than that second event; it is a guess, never an order.
    #[inline]
    pub fn look_ahead(&self) -> LookAhead {
        let hint = |key: u128| Some(self.hints[slot_of(key)]).filter(|&h| h != NO_HINT);
        let Store::Heap(h) = &self.keys.store else {
            return LookAhead {
                next: self.keys.peek().and_then(hint),
                ..LookAhead::default()
            };
        };
        let heap = h.as_slice();
        let Some(&Reverse(first)) = heap.first() else {
            return LookAhead::default();
        };
        let second = heap.get(1..5.min(heap.len())).and_then(|c| c.iter().max());
        LookAhead {
            next: hint(first),
            after: second.and_then(|&Reverse(key)| hint(key)),
            after_body: second
                .map(|&Reverse(key)| std::ptr::from_ref(&self.slots[slot_of(key)]).cast()),
        }
    }

    /// Takes the earliest event if it is due at or before `horizon` and comes before `place`
    /// (a reserved place whose event is kept elsewhere) when there is one.
    /// Inlined: it runs once per event, and its caller's loop is where its tests fold away.
    /// Always: with a second caller (`pop`, which chains in rounds use) the compiler kept it
    /// and `Keys::pop_if` out of line, 3% more instructions a polio frame at `hops`.
    #[inline(always)]
    pub fn pop_before(&mut self, horizon: SimTime, place: Option<Place>) -> Option<(SimTime, E)> {
        let key = self.keys.pop_if(|key| {
            (key >> 64) as u64 <= horizon.ps() && place.is_none_or(|Place(first)| key < first)
        })?;
        let slot = slot_of(key);
        let event = self.slots[slot]
            .take()
            .expect("a queued slot holds its event");
        self.free.push(slot as u32);
        Some((SimTime::from_ps((key >> 64) as u64), event))
    }

    /// The time of the earliest event queued.
    pub fn peek_time(&self) -> Option<SimTime> {
        self.keys
            .peek()
            .map(|key| SimTime::from_ps((key >> 64) as u64))
    }

    pub fn len(&self) -> usize {
        self.keys.len()
    }

    pub fn is_empty(&self) -> bool {
        self.keys.len() == 0
    }
}

/// Pending keys in a 4-ary heap while they are few, in a radix heap while they are many (the
/// thresholds apart, so a queue hovering near one does not flip back and forth).
struct Keys {
    store: Store,
    /// The last key taken: the radix heap's floor when the keys move into one.
    last: u128,
    to_radix: usize,
    to_heap: usize,
}

enum Store {
    Heap(QuaternaryHeap<Reverse<u128>>),
    Radix(RadixHeap),
}

impl Default for Keys {
    fn default() -> Self {
        Keys::with_thresholds(1 << 16, 1 << 12)
    }
}

impl Keys {
    fn with_thresholds(to_radix: usize, to_heap: usize) -> Keys {
        Keys {
            store: Store::Heap(QuaternaryHeap::new()),
            last: 0,
            to_radix,
            to_heap,
        }
    }

    fn len(&self) -> usize {
        match &self.store {
            Store::Heap(h) => h.len(),
            Store::Radix(r) => r.len,
        }
    }

    #[inline]
    fn push(&mut self, key: u128) {
        match &mut self.store {
            Store::Heap(h) => {
                assert!(
                    key >= self.last,
                    "an event scheduled before the last one taken"
                );
                h.push(Reverse(key));
                if h.len() > self.to_radix {
                    self.move_to_radix();
                }
            }
            Store::Radix(r) => r.push(key),
        }
    }

    /// Past `to_radix` pending keys: the heap's keys go into a radix heap (rare, and kept
    /// out of line so that a push stays small enough to inline).
    #[cold]
    #[inline(never)]
    fn move_to_radix(&mut self) {
        if let Store::Heap(h) = &mut self.store {
            let mut radix = RadixHeap::starting_at(self.last);
            for Reverse(k) in std::mem::take(h).into_vec() {
                radix.push(k);
            }
            self.store = Store::Radix(radix);
        }
    }

    #[inline]
    fn peek(&self) -> Option<u128> {
        match &self.store {
            Store::Heap(h) => h.peek().map(|Reverse(k)| *k),
            Store::Radix(r) => r.peek(),
        }
    }

    /// Always inlined, as [`EventQueue::pop_before`].
    #[inline(always)]
    fn pop_if(&mut self, take: impl FnOnce(u128) -> bool) -> Option<u128> {
        let key = match &mut self.store {
            Store::Heap(h) => {
                let Reverse(min) = *h.peek()?;
                if !take(min) {
                    return None;
                }
                h.pop();
                min
            }
            Store::Radix(r) => {
                let min = r.pop_if(take)?;
                if r.len < self.to_heap {
                    self.store = Store::Heap(r.drain().map(Reverse).collect());
                }
                min
            }
        };
        self.last = key;
        Some(key)
    }
}

/// A monotone min-queue of distinct u128 keys, a radix heap in base 16: a key other than
/// `last` (the last key taken) lives in bucket (level, digit), where level is the highest hex
/// digit in which it differs from `last` and digit its value there. Buckets in (level, digit)
/// order hold ever larger keys, and taking the smallest key of the first bucket moves that
/// bucket's other keys to lower levels only, so a key moves at most once per level its
/// distance from the front spans (five times for a microsecond in picoseconds). (The
/// radix-heap crate has no peek and is binary, which moves a key once per bit.)
struct RadixHeap {
    last: u128,
    /// `LEVELS * 16` buckets, level-major.
    buckets: Vec<Vec<u128>>,
    /// Bit `d` of `digits[level]` set when bucket (level, d) is not empty.
    digits: [u16; LEVELS],
    /// Bit `level` set when some bucket of that level is not empty.
    levels: u32,
    /// The key equal to `last`: only ever the first key pushed, when it is 0.
    at_last: Option<u128>,
    /// The smallest key, kept as keys come and go (a compare per push, and a pop's scan of
    /// the next first bucket done as it ends rather than as the next pop begins), so that the
    /// look ahead can read the next event's state with a million pending too.
    front: Option<u128>,
    len: usize,
}

const LEVELS: usize = 32;

impl RadixHeap {
    /// An empty heap that takes keys from `last` up.
    fn starting_at(last: u128) -> Self {
        RadixHeap {
            last,
            buckets: (0..LEVELS * 16).map(|_| Vec::new()).collect(),
            digits: [0; LEVELS],
            levels: 0,
            at_last: None,
            front: None,
            len: 0,
        }
    }

    /// Empties the heap, in no particular order.
    fn drain(&mut self) -> impl Iterator<Item = u128> + '_ {
        self.len = 0;
        self.front = None;
        self.digits = [0; LEVELS];
        self.levels = 0;
        self.at_last
            .take()
            .into_iter()
            .chain(self.buckets.iter_mut().flat_map(|b| b.drain(..)))
    }

    fn push(&mut self, key: u128) {
        assert!(
            key > self.last || key == self.last && self.at_last.is_none(),
            "an event scheduled before the last one taken"
        );
        self.len += 1;
        if key == self.last {
            self.at_last = Some(key);
        } else {
            self.file(key);
        }
        if self.front.is_none_or(|front| key < front) {
            self.front = Some(key);
        }
    }

    /// Puts `key` (above `last`) in its bucket.
    fn file(&mut self, key: u128) {
        let level = (127 - (key ^ self.last).leading_zeros()) as usize / 4;
        let digit = (key >> (4 * level)) as usize & 15;
        self.buckets[level * 16 + digit].push(key);
        self.digits[level] |= 1 << digit;
        self.levels |= 1 << level;
    }

    /// The first non-empty bucket: every key in it is below every key of later buckets.
    fn first_bucket(&self) -> Option<usize> {
        if self.levels == 0 {
            return None;
        }
        let level = self.levels.trailing_zeros() as usize;
        Some(level * 16 + self.digits[level].trailing_zeros() as usize)
    }

    /// The smallest key, the one the next pop takes.
    fn peek(&self) -> Option<u128> {
        self.front
    }

    /// The smallest key once `front` has been taken: `at_last`, or the least of the first
    /// bucket, every key of which is below every key of later buckets.
    fn find_front(&self) -> Option<u128> {
        if self.at_last.is_some() {
            return self.at_last;
        }
        let b = self.first_bucket()?;
        self.buckets[b].iter().min().copied()
    }

    /// Takes the smallest key if `take` accepts it.
    fn pop_if(&mut self, take: impl FnOnce(u128) -> bool) -> Option<u128> {
        let min = self.front?;
        if !take(min) {
            return None;
        }
        self.len -= 1;
        if self.at_last.take().is_none() {
            self.take_from_first_bucket(min);
        }
        self.front = self.find_front();
        Some(min)
    }

    /// Takes `min`, the smallest key, out of the first bucket, and files the bucket's other
    /// keys again below `min`, the new `last`.
    fn take_from_first_bucket(&mut self, min: u128) {
        let b = self
            .first_bucket()
            .expect("the smallest key is in a bucket");
        let mut keys = std::mem::take(&mut self.buckets[b]);
        let (level, digit) = (b / 16, b % 16);
        self.digits[level] &= !(1 << digit);
        if self.digits[level] == 0 {
            self.levels &= !(1 << level);
        }
        self.last = min;
        // The other keys of the bucket agree with `min` from its level up, so each moves to
        // a lower level.
        for &k in &keys {
            if k != min {
                self.file(k);
            }
        }
        keys.clear();
        self.buckets[b] = keys;
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
        let mut now = 0;
        for i in 0..100u64 {
            q.push(SimTime::from_ps(now + (i * 7919) % 100), i);
            if i % 3 == 0 {
                now = q.pop().expect("pushed").0.ps();
            }
        }
        let times: Vec<u64> = std::iter::from_fn(|| q.pop().map(|(t, _)| t.ps())).collect();
        assert!(times.windows(2).all(|w| w[0] <= w[1]));
        assert_eq!(times.len(), 100 - 34);
    }

    /// The look ahead shows the event the next pop takes, in the heap and in the radix heap,
    /// across pushes that come before the one shown and pops that move keys between buckets.
    #[test]
    fn a_peek_shows_the_event_taken_next() {
        let mut q = EventQueue::with_thresholds(8, 4);
        for (i, t) in [5u64, 3, 9, 3, 7].into_iter().enumerate() {
            q.push(SimTime::from_ps(t), i);
        }
        while let Some(&next) = q.peek() {
            assert_eq!(q.pop().map(|(_, e)| e), Some(next));
        }
        assert!(q.is_empty());
        for (i, t) in [40u64, 17, 300, 17, 4096, 18, 65, 20, 19]
            .into_iter()
            .enumerate()
        {
            q.push(SimTime::from_ps(t), i);
        }
        assert!(matches!(q.keys.store, Store::Radix(_)));
        assert_eq!(q.peek(), Some(&1));
        q.push(SimTime::from_ps(16), 9);
        let mut order = Vec::new();
        while let Some(&next) = q.peek() {
            assert_eq!(q.pop().map(|(_, e)| e), Some(next));
            order.push(next);
        }
        assert_eq!(order, [9, 1, 3, 5, 8, 7, 0, 6, 2, 4]);
    }

    /// The look ahead hands back the hints pushed with the earliest event and the one taken
    /// after it, and where that second one's body is, while the keys are in the heap and
    /// nothing is pushed in between; `None` for events pushed without a hint; and only the
    /// first once the keys are in the radix heap.
    #[test]
    fn the_look_ahead_names_the_next_two_events() {
        let mut q = EventQueue::with_thresholds(8, 4);
        for (i, t) in [5u64, 3, 9, 3, 7, 12, 4].into_iter().enumerate() {
            q.push_hinted(SimTime::from_ps(t), i, Some(100 + i as u32));
        }
        q.push(SimTime::from_ps(8), 7);
        let hint = |e: usize| (e < 7).then_some(100 + e as u32);
        while q.len() > 1 {
            let ahead = q.look_ahead();
            let (_, e) = q.pop().expect("queued");
            assert_eq!(ahead.next, hint(e));
            let second = q.keys.peek().expect("a second event is queued");
            assert_eq!(ahead.after, hint(q.slots[slot_of(second)].expect("queued")));
            let body = std::ptr::from_ref(&q.slots[slot_of(second)]).cast();
            assert_eq!(ahead.after_body, Some(body));
        }
        let last = LookAhead {
            next: Some(105),
            ..LookAhead::default()
        };
        assert_eq!(q.look_ahead(), last);
        for i in 0..9 {
            q.push_hinted(SimTime::from_ps(20 + i), i as usize, Some(7));
        }
        assert!(matches!(q.keys.store, Store::Radix(_)));
        assert_eq!(q.look_ahead(), last);
        while q.pop().is_some() {}
        assert_eq!(q.look_ahead(), LookAhead::default());
    }

    #[test]
    #[should_panic(expected = "before the last one taken")]
    fn refuses_an_event_before_the_last_one_taken() {
        let mut q = EventQueue::default();
        q.push(SimTime::from_ps(10), ());
        q.pop();
        q.push(SimTime::from_ps(9), ());
    }

    #[test]
    fn a_horizon_leaves_later_events_queued_and_earlier_ones_welcome() {
        let mut q = EventQueue::default();
        q.push(SimTime::from_ps(50), 'a');
        assert_eq!(q.pop_until(SimTime::from_ps(40)), None);
        // Nothing was taken, so an event before the one waiting is still in order.
        q.push(SimTime::from_ps(45), 'b');
        assert_eq!(
            q.pop_until(SimTime::from_ps(50)),
            Some((SimTime::from_ps(45), 'b'))
        );
        assert_eq!(q.pop(), Some((SimTime::from_ps(50), 'a')));
        assert!(q.is_empty());
    }

    use std::cmp::Reverse;

    proptest::proptest! {
        /// Any monotone schedule (each push at or after the last event taken, with many equal
        /// times), taken with horizons that are often too early, comes out exactly as from a
        /// binary heap of (time, insertion order), in whichever structure the keys are.
        #[test]
        fn equals_a_binary_heap_on_monotone_schedules(
            steps in proptest::collection::vec(
                (0u64..4, 0u64..1 << 40, 0usize..3, 0u64..1 << 30), 1..400),
            to_heap in 1usize..20,
            gap in 1usize..20,
        ) {
            let mut q = EventQueue::with_thresholds(to_heap + gap, to_heap);
            let mut reference = std::collections::BinaryHeap::new();
            let (mut now, mut seq) = (0u64, 0u64);
            for (i, &(spread, delay, pops, ahead)) in steps.iter().enumerate() {
                // Delays of every magnitude, and often none, so ties are common.
                let at = now + (delay >> (10 * spread));
                q.push(SimTime::from_ps(at), i);
                reference.push(Reverse((at, seq, i)));
                seq += 1;
                for _ in 0..pops {
                    let horizon = now + ahead;
                    let want = match reference.peek() {
                        Some(&Reverse((t, _, e))) if t <= horizon => {
                            reference.pop();
                            now = t;
                            Some((SimTime::from_ps(t), e))
                        }
                        _ => None,
                    };
                    proptest::prop_assert_eq!(q.pop_until(SimTime::from_ps(horizon)), want);
                }
                proptest::prop_assert_eq!(q.len(), reference.len());
                proptest::prop_assert_eq!(
                    q.peek_time(),
                    reference.peek().map(|Reverse((t, _, _))| SimTime::from_ps(*t))
                );
                proptest::prop_assert_eq!(
                    q.peek(),
                    reference.peek().map(|Reverse((_, _, e))| e)
                );
            }
            while let Some(Reverse((t, _, e))) = reference.pop() {
                proptest::prop_assert_eq!(q.pop(), Some((SimTime::from_ps(t), e)));
            }
            proptest::prop_assert!(q.pop().is_none());
        }
    }
}
