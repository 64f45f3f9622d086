//! Two-step redistribution (paper 002, Figure 7): processors split into g groups of
//! consecutive ids; each processor has one forwarding processor in every other group and
//! sends polygons for that group there, which copies them into its buffers for the group's
//! members. Messages per frame, when every stream fits in one message:
//! N(g-1) + N^2/g - N, smallest near g = sqrt(N).
//!
//! Owns group arithmetic only. Must never send anything.

/// The processors cut into groups of consecutive ids, sizes as equal as possible.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Groups {
    /// `starts[k]..starts[k + 1]` are the members of group k.
    starts: Vec<u32>,
}

impl Groups {
    /// `g` groups over `n` processors (1 <= g <= n).
    pub fn new(n: u32, g: u32) -> Groups {
        let g = g.clamp(1, n.max(1));
        Groups {
            starts: (0..=g)
                .map(|k| (k as u64 * n as u64 / g as u64) as u32)
                .collect(),
        }
    }

    /// g = round(sqrt(n)), the message-count minimum.
    pub fn near_sqrt(n: u32) -> Groups {
        Groups::new(n, (n as f64).sqrt().round().max(1.0) as u32)
    }

    pub fn count(&self) -> u32 {
        self.starts.len() as u32 - 1
    }

    pub fn group_of(&self, p: u32) -> u32 {
        (self.starts.partition_point(|&s| s <= p) - 1) as u32
    }

    pub fn members(&self, group: u32) -> std::ops::Range<u32> {
        self.starts[group as usize]..self.starts[group as usize + 1]
    }

    /// The processor in `group` that forwards `src`'s polygons for that group: the member at
    /// `src`'s position within its own group, modulo the group's size.
    pub fn forwarder(&self, src: u32, group: u32) -> u32 {
        let own = self.members(self.group_of(src));
        let target = self.members(group);
        target.start + (src - own.start) % target.len() as u32
    }

    /// How many processors outside `p`'s group use `p` as their forwarder.
    pub fn forwarded_sources(&self, p: u32) -> u32 {
        let mine = self.group_of(p);
        (0..self.count())
            .filter(|&k| k != mine)
            .flat_map(|k| self.members(k))
            .filter(|&s| self.forwarder(s, mine) == p)
            .count() as u32
    }

    /// The minimum number of messages one frame needs (each non-empty stream one message).
    pub fn min_messages(&self) -> u64 {
        let n: u64 = self.starts.last().copied().unwrap_or(0) as u64;
        let first: u64 = (0..self.count())
            .map(|k| self.members(k).len() as u64 * (self.count() as u64 - 1))
            .sum();
        let second: u64 = (0..self.count())
            .map(|k| {
                let m = self.members(k).len() as u64;
                m * (m - 1)
            })
            .sum();
        debug_assert!(n > 0 || first + second == 0);
        first + second
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sixteen_processors_in_four_groups_like_figure_7() {
        let g = Groups::new(16, 4);
        assert_eq!(g.members(2), 8..12);
        assert_eq!(g.group_of(11), 2);
        assert_eq!(g.forwarder(1, 3), 13);
        assert_eq!(g.forwarder(6, 0), 2);
        assert!(
            (0..16).all(|p| g.forwarded_sources(p) == 3),
            "every processor forwards for one per other group"
        );
    }

    #[test]
    fn message_count_is_ellsworths_formula_and_least_near_sqrt_n() {
        for n in [16u32, 64, 256, 512] {
            let best = (1..=n)
                .filter(|g| n % g == 0)
                .min_by_key(|&g| Groups::new(n, g).min_messages())
                .unwrap();
            for g in (1..=n).filter(|g| n % g == 0) {
                let (n64, g64) = (n as u64, g as u64);
                assert_eq!(
                    Groups::new(n, g).min_messages(),
                    n64 * (g64 - 1) + n64 * n64 / g64 - n64,
                    "n={n} g={g}"
                );
            }
            let sqrt = (n as f64).sqrt();
            assert!(
                (best as f64 / sqrt - 1.0).abs() <= 0.5,
                "n={n}: best g={best}, sqrt={sqrt}"
            );
        }
    }
}
