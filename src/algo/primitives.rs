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

/// Object-space blocks, as a volume renderer deals its data: primitive k (its centroid
/// `centroids[k]`) to one of `n` processors by recursive bisection. A set going to m
/// processors is ordered along the widest axis of its centroids' extent (ties by database
/// index) and cut where the lower part holds floor(m/2) processors' share (its count times
/// floor(m/2) / m, rounded down); each part recurses. Every processor gets a compact block,
/// the counts within a few primitives of each other, the same deal for the same centroids.
pub fn blocks(centroids: &[[f32; 3]], n: u32) -> Vec<u32> {
    assert!(n >= 1, "at least one processor");
    let mut out = vec![0; centroids.len()];
    let mut ids: Vec<u32> = (0..centroids.len() as u32).collect();
    bisect(&mut ids, 0, n, centroids, &mut out);
    out
}

fn bisect(ids: &mut [u32], first: u32, m: u32, centroids: &[[f32; 3]], out: &mut [u32]) {
    if m == 1 || ids.is_empty() {
        for &k in ids.iter() {
            out[k as usize] = first;
        }
        return;
    }
    let extent = |axis: usize| {
        let values = ids.iter().map(|&k| centroids[k as usize][axis]);
        let (lo, hi) = values.fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
        hi - lo
    };
    let axis = (0..3)
        .max_by(|&a, &b| extent(a).total_cmp(&extent(b)).then(b.cmp(&a)))
        .expect("three axes");
    let lower = m / 2;
    let cut = ids.len() * lower as usize / m as usize;
    if cut > 0 && cut < ids.len() {
        ids.select_nth_unstable_by(cut, |&a, &b| {
            let (ca, cb) = (centroids[a as usize][axis], centroids[b as usize][axis]);
            ca.total_cmp(&cb).then(a.cmp(&b))
        });
    }
    let (low, high) = ids.split_at_mut(cut);
    bisect(low, first, lower, centroids, out);
    bisect(high, first + lower, m - lower, centroids, out);
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
    fn blocks_cut_space_into_compact_balanced_parts() {
        // A 16 x 8 grid of centroids in x and y, dealt to 8: each processor gets one 4 x 4
        // square (x is wider, so it is cut first, then the halves' wider axis, and so on).
        let centroids: Vec<[f32; 3]> = (0..128)
            .map(|k| [(k % 16) as f32, (k / 16) as f32, 0.0])
            .collect();
        let dealt = blocks(&centroids, 8);
        for p in 0..8 {
            let mine: Vec<&[f32; 3]> = (0..128)
                .filter(|&k| dealt[k] == p)
                .map(|k| &centroids[k])
                .collect();
            assert_eq!(mine.len(), 16, "processor {p}");
            let span = |axis: usize| {
                let v = mine.iter().map(|c| c[axis] as i32);
                v.clone().max().unwrap() - v.min().unwrap()
            };
            assert_eq!(
                (span(0), span(1)),
                (3, 3),
                "processor {p} holds a 4 x 4 square"
            );
        }
        // Uneven: 10 primitives on 3 processors, every one dealt, counts 3, 3, 4.
        let line: Vec<[f32; 3]> = (0..10).map(|k| [k as f32, 0.0, 0.0]).collect();
        let dealt = blocks(&line, 3);
        assert_eq!(dealt, [0, 0, 0, 1, 1, 1, 2, 2, 2, 2]);
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
