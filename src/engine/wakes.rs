//! The network model's wake-ups, kept beside the event queue so that one superseded by an
//! earlier wake-up costs nothing when its time comes.
//!
//! Whenever the network's next instant of work moves earlier, a wake-up is armed at it and
//! takes its place in the queue's order (time, then sequence) exactly as a queued event
//! would. Only a wake-up at the armed instant does work, and of those the first in that
//! order; the others would do nothing when reached and are dropped unrun. One not yet
//! reached stays, because the armed instant may come back to its time before then (after a
//! wake-up runs, the next instant is armed afresh), and then it is the first at that instant.
//! So the network's work runs at the very place in the order a queue of every wake-up gave
//! it, and the events around it keep their order.
//!
//! Owns the armed instant and the pending places; must never run the network itself or
//! decide what a wake-up does.

use super::queue::{EventQueue, Place};
use crate::units::SimTime;

#[derive(Default)]
pub(super) struct NetWakes {
    /// The instant the network next has work, while a wake-up for it is pending.
    armed: Option<SimTime>,
    /// Places of the wake-ups armed and not yet reached, latest first: a handful as a rule,
    /// most armed before the ones pending (an earlier instant), so each goes in at or near
    /// the end of a sorted list, and those passed come off the end.
    pending: Vec<Place>,
    /// The first pending place at the armed instant: the wake-up that does the work. Fixed
    /// from one arming to the next, since the events taken meanwhile all come before it; so
    /// the executor's question before every event is a field read, not a search.
    due: Option<Place>,
}

impl NetWakes {
    /// Arms a wake-up at `at` unless one at or before it is armed.
    pub fn arm<E>(&mut self, at: SimTime, queue: &mut EventQueue<E>) {
        if self.armed.is_none_or(|armed| at < armed) {
            // Places already passed can never be due; one of them may be at `at` itself.
            let passed = queue.last_taken();
            while self.pending.last().is_some_and(|&p| p < passed) {
                self.pending.pop();
            }
            self.armed = Some(at);
            let place = queue.reserve(at);
            let i = self.insert(place);
            // The due one is the first at `at`: this one, or one armed there before it (after
            // it in the list, which runs latest first).
            let first_at = self.pending[i..]
                .iter()
                .take_while(|p| p.time() == at)
                .last();
            self.due = first_at.copied();
        }
    }

    /// Puts `place` in the list, latest first, moving the few earlier places up by one (a
    /// loop, not a block move: it is one or two as a rule); returns its index.
    fn insert(&mut self, place: Place) -> usize {
        self.pending.push(place);
        let mut i = self.pending.len() - 1;
        while i > 0 && self.pending[i - 1] < place {
            self.pending[i] = self.pending[i - 1];
            i -= 1;
        }
        self.pending[i] = place;
        i
    }

    /// The wake-up that does the network's work next: the first pending at the armed
    /// instant. `passed` (the last event taken) never passes it: the queue hands out no
    /// event after it until it is taken.
    #[inline]
    pub fn due(&self, passed: Place) -> Option<Place> {
        debug_assert!(
            self.due.is_none_or(|d| d >= passed),
            "a due wake-up was passed"
        );
        self.due
    }

    /// Takes the wake-up at `place` (the one `due` gave) and disarms: its work is being done.
    pub fn take(&mut self, place: Place) {
        while self.pending.last().is_some_and(|&p| p <= place) {
            self.pending.pop();
        }
        self.armed = None;
        self.due = None;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Clone, Copy, Debug, PartialEq)]
    enum Item {
        Other(u32),
        Wake,
    }

    /// What the n-th item processed does, as programs and the network would: events pushed
    /// after the given delays, and a wake-up armed after a delay (0 is the same instant).
    type Action = (Vec<u64>, Option<u64>);

    /// Pushes the action's events; returns the instant it arms a wake-up at, if any.
    fn push_events(
        action: &Action,
        now: u64,
        q: &mut EventQueue<Item>,
        next: &mut u32,
    ) -> Option<SimTime> {
        for &delay in &action.0 {
            q.push(SimTime::from_ps(now + delay), Item::Other(*next));
            *next += 1;
        }
        action.1.map(|delay| SimTime::from_ps(now + delay))
    }

    /// The plain way: every wake-up armed is queued, and one reached at another instant than
    /// the armed one does nothing.
    fn queued(actions: &[Action]) -> Vec<(u64, Item)> {
        let mut q = EventQueue::default();
        let mut armed: Option<SimTime> = None;
        let (mut trace, mut next) = (Vec::new(), 0);
        let mut now = 0;
        loop {
            if let Some(t) = push_events(&actions[trace.len()], now, &mut q, &mut next) {
                if armed.is_none_or(|a| t < a) {
                    armed = Some(t);
                    q.push(t, Item::Wake);
                }
            }
            let item = loop {
                match q.pop() {
                    Some((t, Item::Wake)) if armed != Some(t) => continue,
                    Some((t, item)) => {
                        if item == Item::Wake {
                            armed = None;
                        }
                        break Some((t.ps(), item));
                    }
                    None => break None,
                }
            };
            let Some((t, item)) = item else { return trace };
            trace.push((t, item));
            now = t;
            if trace.len() == actions.len() {
                return trace;
            }
        }
    }

    /// The same with the wake-ups kept in `NetWakes`.
    fn kept_apart(actions: &[Action]) -> Vec<(u64, Item)> {
        let mut q = EventQueue::default();
        let mut wakes = NetWakes::default();
        let (mut trace, mut next) = (Vec::new(), 0);
        let mut now = 0;
        loop {
            if let Some(t) = push_events(&actions[trace.len()], now, &mut q, &mut next) {
                wakes.arm(t, &mut q);
            }
            let wake = wakes.due(q.last_taken());
            let (t, item) = match q.pop_before(SimTime::MAX, wake) {
                Some((t, item)) => (t, item),
                None => match wake {
                    Some(place) => {
                        wakes.take(place);
                        (place.time(), Item::Wake)
                    }
                    None => return trace,
                },
            };
            trace.push((t.ps(), item));
            now = t.ps();
            if trace.len() == actions.len() {
                return trace;
            }
        }
    }

    proptest::proptest! {
        /// The network's work runs at the same places among the same events as when every
        /// wake-up is queued: many ties, wake-ups superseded, armed again at an instant whose
        /// superseded wake-up is still pending, and armed at the very instant just served.
        #[test]
        fn runs_the_work_where_queued_wake_ups_did(
            actions in proptest::collection::vec(
                (proptest::collection::vec(0u64..4, 0..3), proptest::option::of(0u64..6)),
                1..300,
            )
        ) {
            proptest::prop_assert_eq!(kept_apart(&actions), queued(&actions));
        }
    }
}
