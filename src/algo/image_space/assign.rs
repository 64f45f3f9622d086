//! Region-to-processor assignment: the fixed interleaved pattern (paper 000; paper 002's first
//! frame) and Ellsworth's greedy multiple-bin packing on estimated region costs (paper 002:
//! largest estimated cost first, each to the least-loaded processor).
//!
//! Owns the arithmetic of assignment. Must never charge time or send anything: the caller
//! charges the cpu for running it.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use crate::units::SimTime;

/// `owner[r]` is the processor that rasterizes region `r`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Assignment {
    pub owner: Vec<u32>,
    /// The regions again, processor by processor in index order (processor `p`'s are
    /// `by_processor[starts[p]..starts[p + 1]]`): listed once, where each processor of a
    /// 512-node frame used to filter every region's owner for its own.
    by_processor: Vec<u32>,
    starts: Vec<u32>,
}

impl Assignment {
    /// The assignment `owner` gives, over `processors` processors (each owner below it).
    fn from_owner(owner: Vec<u32>, processors: u32) -> Assignment {
        let mut starts = vec![0u32; processors as usize + 1];
        for &p in &owner {
            starts[p as usize + 1] += 1;
        }
        for p in 0..processors as usize {
            starts[p + 1] += starts[p];
        }
        let mut next = starts.clone();
        let mut by_processor = vec![0; owner.len()];
        for (r, &p) in owner.iter().enumerate() {
            by_processor[next[p as usize] as usize] = r as u32;
            next[p as usize] += 1;
        }
        Assignment {
            owner,
            by_processor,
            starts,
        }
    }

    /// Region `r` to processor `r mod n`.
    pub fn interleaved(regions: u32, processors: u32) -> Assignment {
        Assignment::from_owner((0..regions).map(|r| r % processors).collect(), processors)
    }

    /// A fixed interleaved pattern over a `cols x rows` grid that also shifts each row, so
    /// that no processor is left with whole screen columns when `cols` is a multiple of `n`:
    /// region (row, col) goes to (col + row * s) mod n, with s the smallest shift >= 2 coprime
    /// with n (a Latin-square pattern when cols = n).
    pub fn interleaved_2d(cols: u32, rows: u32, processors: u32) -> Assignment {
        let shift = (2..)
            .find(|&s| gcd(s, processors.max(1)) == 1)
            .expect("a coprime shift exists");
        let owner = (0..rows)
            .flat_map(|row| {
                (0..cols).map(move |col| {
                    ((col as u64 + row as u64 * shift as u64) % processors as u64) as u32
                })
            })
            .collect();
        Assignment::from_owner(owner, processors)
    }

    /// The regions processor `p` rasterizes, in index order.
    pub fn regions_of(&self, p: u32) -> &[u32] {
        let p = p as usize;
        match self.starts.get(p..p + 2) {
            Some(&[start, end]) => &self.by_processor[start as usize..end as usize],
            _ => &[],
        }
    }

    /// Greedy multiple-bin packing: regions in decreasing estimated cost (ties by index) go
    /// one by one to the processor with the least load so far (ties by lowest id).
    /// `initial_load[p]` is work a processor already has, such as processor 0's time spent
    /// computing this very assignment; a processor whose initial load exceeds what the others
    /// reach gets no regions at all.
    pub fn greedy(costs: &[SimTime], initial_load: &[SimTime]) -> Assignment {
        let mut order: Vec<u32> = (0..costs.len() as u32).collect();
        order.sort_by_key(|&r| (Reverse(costs[r as usize]), r));
        let mut loads: BinaryHeap<Reverse<(SimTime, u32)>> = initial_load
            .iter()
            .enumerate()
            .map(|(p, &l)| Reverse((l, p as u32)))
            .collect();
        let mut owner = vec![0; costs.len()];
        for r in order {
            let Reverse((load, p)) = loads.pop().expect("at least one processor");
            owner[r as usize] = p;
            loads.push(Reverse((load + costs[r as usize], p)));
        }
        Assignment::from_owner(owner, initial_load.len() as u32)
    }

    /// Each processor's total estimated cost under this assignment.
    pub fn loads(&self, costs: &[SimTime], processors: u32) -> Vec<SimTime> {
        let mut loads = vec![SimTime::ZERO; processors as usize];
        for (r, &p) in self.owner.iter().enumerate() {
            loads[p as usize] += costs[r];
        }
        loads
    }
}

fn gcd(a: u32, b: u32) -> u32 {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn us(v: &[u64]) -> Vec<SimTime> {
        v.iter().map(|&x| SimTime::from_us(x)).collect()
    }

    #[test]
    fn largest_first_to_the_least_loaded() {
        let a = Assignment::greedy(&us(&[5, 9, 2, 7, 1]), &us(&[0, 0]));
        // 9 -> p0, 7 -> p1, 5 -> p1 (7 < 9), 2 -> p0 (9 < 12), 1 -> p0 (11 < 12).
        assert_eq!(a.owner, vec![1, 0, 0, 1, 0]);
        assert_eq!(a.loads(&us(&[5, 9, 2, 7, 1]), 2), us(&[12, 12]));
    }

    #[test]
    fn a_processor_busy_assigning_gets_no_regions_when_that_fills_its_frame() {
        let a = Assignment::greedy(&us(&[3, 3, 3, 3]), &us(&[20, 0, 0]));
        assert!(a.regions_of(0).is_empty(), "{a:?}");
        let b = Assignment::greedy(&us(&[3, 3, 3, 3]), &us(&[2, 0, 0]));
        assert!(!b.regions_of(0).is_empty(), "{b:?}");
    }

    #[test]
    fn interleaving_in_2d_spreads_every_processor_over_all_columns() {
        let a = Assignment::interleaved_2d(8, 8, 8);
        for p in 0..8 {
            let mut cols: Vec<u32> = a.regions_of(p).iter().map(|r| r % 8).collect();
            cols.sort();
            assert_eq!(cols, (0..8).collect::<Vec<_>>(), "processor {p}");
        }
        assert_eq!(Assignment::interleaved_2d(4, 1, 2).owner, vec![0, 1, 0, 1]);
        assert_eq!(
            Assignment::interleaved_2d(2, 2, 2).owner,
            vec![0, 1, 1, 0],
            "a checkerboard"
        );
    }

    /// Each processor's list is exactly the regions it owns, in index order, for every way
    /// an assignment is made, including processors left with none.
    #[test]
    fn regions_of_lists_what_each_processor_owns() {
        let costs: Vec<SimTime> = (0..40u64).map(|r| SimTime::from_ns(r * 7 % 13)).collect();
        let mut loads = vec![SimTime::ZERO; 6];
        loads[2] = SimTime::from_us(1);
        for a in [
            Assignment::interleaved(23, 5),
            Assignment::interleaved(3, 5),
            Assignment::interleaved_2d(8, 5, 6),
            Assignment::greedy(&costs, &loads),
        ] {
            let processors = a.starts.len() as u32 - 1;
            let mut listed = 0;
            for p in 0..processors + 2 {
                let own: Vec<u32> = (0..a.owner.len() as u32)
                    .filter(|&r| a.owner[r as usize] == p)
                    .collect();
                assert_eq!(a.regions_of(p), own, "processor {p} of {a:?}");
                listed += own.len();
            }
            assert_eq!(listed, a.owner.len());
        }
        assert!(Assignment::greedy(&costs, &loads).regions_of(2).is_empty());
    }

    #[test]
    fn interleaved_is_r_mod_n() {
        assert_eq!(
            Assignment::interleaved(7, 3).owner,
            vec![0, 1, 2, 0, 1, 2, 0]
        );
        assert_eq!(Assignment::interleaved(7, 3).regions_of(1), vec![1, 4]);
    }
}
