//! PHOLD on the leanest executor of the engine's design: one async program per logical
//! process, polled when an event reaches it, events in a binary heap of (time, sequence, LP).
//! It has none of the engine's features (no envelopes, filters, mailboxes of messages, cpu,
//! network wake-ups or failure reports): what is left is what the design itself costs, so
//! `bench phold` can tell how much of the engine's overhead is the design and how much is
//! what the engine does with it.
//!
//! Owns this one loop. Must never be used to simulate anything but PHOLD, and must draw the
//! same random numbers in the same order as the engine's PHOLD and the bare heap (it is held
//! to their outcome).

use std::cell::{Cell, RefCell};
use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::future::Future;
use std::pin::Pin;
use std::rc::Rc;
use std::task::{Context, Poll, Waker};

use super::{mix, Draw, PholdConfig, PholdOutcome};
use crate::units::SimTime;

/// What the programs share: the clock, the pending events, and how many events each LP has
/// been handed and not yet taken (one at most: an LP is polled as soon as one reaches it).
struct Shared {
    now: SimTime,
    events: BinaryHeap<Reverse<(SimTime, u64, u32)>>,
    sequence: u64,
    handed: Vec<u32>,
}

impl Shared {
    fn schedule(&mut self, lp: u32, delay: SimTime) {
        let at = self.now + delay;
        self.events.push(Reverse((at, self.sequence, lp)));
        self.sequence += 1;
    }
}

/// Waits for the next event handed to `lp`.
struct NextEvent {
    shared: Rc<RefCell<Shared>>,
    lp: u32,
}

impl Future for NextEvent {
    type Output = ();
    fn poll(self: Pin<&mut Self>, _cx: &mut Context<'_>) -> Poll<()> {
        let mut shared = self.shared.borrow_mut();
        let handed = &mut shared.handed[self.lp as usize];
        if *handed > 0 {
            *handed -= 1;
            Poll::Ready(())
        } else {
            Poll::Pending
        }
    }
}

type Program = Pin<Box<dyn Future<Output = ()>>>;

/// PHOLD on the floor executor. Never inlined: its instructions are counted by name.
#[inline(never)]
pub fn phold_floor(cfg: &PholdConfig) -> PholdOutcome {
    let shared = Rc::new(RefCell::new(Shared {
        now: SimTime::ZERO,
        events: BinaryHeap::with_capacity(cfg.in_flight() as usize),
        sequence: 0,
        handed: vec![0; cfg.lps as usize],
    }));
    // Events, last time, hash.
    let log = Rc::new(Cell::new((0u64, 0u64, 0u64)));
    let config = Rc::new(cfg.clone());
    let mut programs: Vec<Program> = (0..cfg.lps)
        .map(|lp| {
            let (shared, log, cfg) = (shared.clone(), log.clone(), config.clone());
            Box::pin(async move {
                let mut draw = Draw::new(&cfg, lp);
                for _ in 0..cfg.events_per_lp {
                    let (dst, delay) = draw.next(&cfg, lp);
                    shared.borrow_mut().schedule(dst, delay);
                }
                loop {
                    NextEvent {
                        shared: shared.clone(),
                        lp,
                    }
                    .await;
                    let now = shared.borrow().now;
                    let (n, _, h) = log.get();
                    log.set((n + 1, now.ps(), mix(h, now, lp)));
                    let (dst, delay) = draw.next(&cfg, lp);
                    shared.borrow_mut().schedule(dst, delay);
                }
            }) as Program
        })
        .collect();
    let mut cx = Context::from_waker(Waker::noop());
    for program in &mut programs {
        let _ = program.as_mut().poll(&mut cx);
    }
    loop {
        let lp = {
            let mut shared = shared.borrow_mut();
            let Some(&Reverse((at, _, lp))) = shared.events.peek() else {
                break;
            };
            if at > cfg.end {
                break;
            }
            shared.events.pop();
            shared.now = at;
            shared.handed[lp as usize] += 1;
            lp
        };
        let _ = programs[lp as usize].as_mut().poll(&mut cx);
    }
    // The programs hold the shared state; drop them first.
    drop(programs);
    let (events, last_event_ps, trace_hash) = log.get();
    PholdOutcome {
        events,
        last_event_ps,
        trace_hash,
    }
}
