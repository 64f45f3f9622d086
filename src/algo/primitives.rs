//! How object-parallel (sort-last) renderers deal primitives to processors: the static rules
//! of papers 001 and 003. One function serves both the engine runs and trace replay, so a
//! replayed trace and a simulated run with the same rule, n and seed give every primitive the
//! same processor.
//!
//! Must never look at pixels or the clock: a deal is a pure function of the primitive ids,
//! their sizes (only `background-last` reads them), n and a seeded stream.

use rand::Rng;

use crate::engine::rng_stream;

/// A static primitive-assignment rule.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Deal {
    /// Round-robin in database order (Molnar's scattering, paper 001's default): the k-th
    /// primitive goes to processor k mod n.
    Scatter,
    /// Each primitive, in database order, draws its processor uniformly from a seeded stream.
    Random,
    /// Scatter over every primitive but the largest (ties: the first), which goes to
    /// processor n-1, the last to broadcast when snooping (paper 003's advice for background
    /// primitives).
    BackgroundLast,
}

impl Deal {
    pub const ALL: [Deal; 3] = [Deal::Scatter, Deal::Random, Deal::BackgroundLast];

    /// The command-line id.
    pub fn name(self) -> &'static str {
        match self {
            Deal::Scatter => "scatter",
            Deal::Random => "random",
            Deal::BackgroundLast => "background-last",
        }
    }

    pub fn from_name(name: &str) -> Option<Deal> {
        Deal::ALL.into_iter().find(|d| d.name() == name)
    }
}

/// The processor of each of `count` primitives in database order. `size(k)` is primitive
/// k's size (fragments or screen area; only `BackgroundLast` calls it); `stream` names the
/// seeded random stream, so different users of a seed draw independent numbers.
pub fn deal(
    rule: Deal,
    count: usize,
    mut size: impl FnMut(usize) -> u64,
    n: u32,
    seed: u64,
    stream: &str,
) -> Vec<u32> {
    assert!(n >= 1, "at least one processor");
    let scatter = |k: usize| (k % n as usize) as u32;
    match rule {
        Deal::Scatter => (0..count).map(scatter).collect(),
        Deal::Random => {
            let mut rng = rng_stream(seed, stream);
            (0..count).map(|_| rng.gen_range(0..n)).collect()
        }
        Deal::BackgroundLast => {
            let mut largest: Option<(u64, usize)> = None;
            for k in 0..count {
                let s = size(k);
                if largest.is_none_or(|(best, _)| s > best) {
                    largest = Some((s, k));
                }
            }
            let Some((_, big)) = largest else {
                return Vec::new();
            };
            let mut out = Vec::with_capacity(count);
            let mut dealt = 0;
            for k in 0..count {
                if k == big {
                    out.push(n - 1);
                } else {
                    out.push(scatter(dealt));
                    dealt += 1;
                }
            }
            out
        }
    }
}

/// Every processor's primitives (database indices, ascending) under `assignment`, in one
/// pass: `shares(a, n)[p]` is what `deal` gave processor p.
pub fn shares(assignment: &[u32], n: u32) -> Vec<Vec<u32>> {
    let mut out = vec![Vec::new(); n as usize];
    for (k, &p) in assignment.iter().enumerate() {
        out[p as usize].push(k as u32);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scatter_is_round_robin() {
        assert_eq!(deal(Deal::Scatter, 5, |_| 0, 2, 0, "s"), [0, 1, 0, 1, 0]);
    }

    #[test]
    fn background_last_skips_the_largest_in_the_round_robin() {
        let sizes = [1, 9, 2, 9, 3];
        let out = deal(Deal::BackgroundLast, 5, |k| sizes[k], 3, 0, "s");
        assert_eq!(out, [0, 2, 1, 2, 0]);
    }

    #[test]
    fn random_is_seeded_and_in_range() {
        let a = deal(Deal::Random, 1000, |_| 0, 7, 42, "s");
        assert_eq!(a, deal(Deal::Random, 1000, |_| 0, 7, 42, "s"));
        assert_ne!(a, deal(Deal::Random, 1000, |_| 0, 7, 43, "s"));
        assert!(a.iter().all(|&p| p < 7));
        assert!((0..7).all(|p| a.contains(&p)));
    }

    #[test]
    fn shares_partition_the_primitives() {
        let a = deal(Deal::Scatter, 7, |_| 0, 3, 0, "s");
        let shares = shares(&a, 3);
        let total: usize = shares.iter().map(Vec::len).sum();
        assert_eq!(total, 7);
        assert_eq!(shares[1], [1, 4]);
    }
}
