//! Sort-first's state on the shared image-space stages: its validated settings (how regions
//! are assigned, how records travel) and the host's book of who holds which primitive.
//!
//! Host bookkeeping only; must never decide anything a processor could not know: a holder of
//! a primitive knows where it fell last frame, so it knows the other holders.

use std::cell::RefCell;

use super::options::{Migrate, RegionRule};

/// The validated sort-first options (defaults for the sort-middle variants, which ignore them).
#[derive(Clone, Copy, Debug)]
pub struct FirstSettings {
    pub regions: RegionRule,
    pub migrate: Migrate,
}

impl Default for FirstSettings {
    fn default() -> FirstSettings {
        FirstSettings {
            regions: RegionRule::Static,
            migrate: Migrate::Batched,
        }
    }
}

/// Who holds each primitive's record during a frame: the processors whose regions it touched
/// last frame (or, where it touched none, the one that held it first), sorted. Before the
/// first frame primitive p is with processor p mod N (the even deal sort-middle also uses).
///
/// Host bookkeeping only: every holder of a primitive transformed it last frame and so knows
/// this list itself.
#[derive(Default)]
pub struct HolderBook {
    inner: RefCell<Book>,
}

#[derive(Default)]
struct Book {
    /// The frame `start`/`holders` describe; `None` before the first.
    frame: Option<u32>,
    /// Per primitive, `holders[start[p]..start[p + 1]]`.
    start: Vec<u32>,
    holders: Vec<u32>,
    /// (primitive, processor) pairs kept for the next frame, as processors finish.
    next: Vec<(u32, u32)>,
}

impl HolderBook {
    /// The holders of primitive `prim` in `frame` (call with frames in order), `n`
    /// processors, `prims` primitives.
    pub fn holders(&self, frame: u32, prim: u32, n: u32, prims: usize) -> Vec<u32> {
        let mut book = self.inner.borrow_mut();
        book.settle(frame, prims);
        if book.start.is_empty() {
            return vec![prim % n];
        }
        let (a, b) = (book.start[prim as usize], book.start[prim as usize + 1]);
        book.holders[a as usize..b as usize].to_vec()
    }

    /// Processor `me` keeps `prims` for the frame after `frame`.
    pub fn keep(&self, frame: u32, me: u32, prims: &[u32]) {
        let mut book = self.inner.borrow_mut();
        book.settle(frame, 0);
        book.next.extend(prims.iter().map(|&p| (p, me)));
    }
}

impl Book {
    /// Turns the pairs kept during the frame before `frame` into `frame`'s lists.
    fn settle(&mut self, frame: u32, prims: usize) {
        if self.frame == Some(frame) {
            return;
        }
        if self.frame.is_some() {
            let mut next = std::mem::take(&mut self.next);
            next.sort_unstable();
            next.dedup();
            let count = prims.max(next.last().map_or(0, |&(p, _)| p as usize + 1));
            self.start = vec![0; count + 1];
            for &(p, _) in &next {
                self.start[p as usize + 1] += 1;
            }
            for i in 0..count {
                self.start[i + 1] += self.start[i];
            }
            self.holders = next.into_iter().map(|(_, q)| q).collect();
        }
        self.frame = Some(frame);
    }
}
