//! Dealing a sweep's points to shards (`--shard I/T`, one Slurm array task each): every task
//! computes the same deal from the spec alone, so no task needs to hear from another.
//!
//! The deal is greedy longest-first over an estimate of each point's cost (processors x
//! triangles x frames): points in decreasing estimate (ties by product order) each go to the
//! shard with the least estimated work so far (ties to the lowest shard). That is Graham's
//! LPT rule, within 4/3 of the best makespan for the estimate.
//!
//! Owns the deal. Must never run a point or read a point's results.

use std::fmt;
use std::path::{Path, PathBuf};
use std::str::FromStr;

use serde::{Deserialize, Serialize};

/// Which points each shard holds, written beside the Slurm scripts (`slurm/shards.json`) so
/// that a person, and `--collect`'s message, can tell which array task to rerun.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct ShardPlan {
    pub tasks: u32,
    /// Point names of each shard, in product order.
    pub shards: Vec<Vec<String>>,
}

impl ShardPlan {
    pub fn new(dealt: &[(String, u32)], tasks: u32) -> ShardPlan {
        let mut shards = vec![Vec::new(); tasks as usize];
        for (name, shard) in dealt {
            shards[*shard as usize].push(name.clone());
        }
        ShardPlan { tasks, shards }
    }

    pub fn path(out: &Path) -> PathBuf {
        out.join("slurm").join("shards.json")
    }

    /// The plan in `out`, if there is a readable one.
    pub fn read(out: &Path) -> Option<ShardPlan> {
        let text = std::fs::read_to_string(ShardPlan::path(out)).ok()?;
        serde_json::from_str(&text).ok()
    }
}

/// Shard `index` of `of` (0-based, as Slurm numbers array tasks).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    pub index: u32,
    pub of: u32,
}

impl FromStr for Shard {
    type Err = String;

    fn from_str(s: &str) -> Result<Shard, String> {
        let invalid = || {
            format!("{s}: expected I/T with 0 <= I < T, e.g. 0/3 (shards are numbered from 0, as Slurm's array tasks)")
        };
        let (i, t) = s.split_once('/').ok_or_else(invalid)?;
        let (index, of): (u32, u32) = (
            i.trim().parse().map_err(|_| invalid())?,
            t.trim().parse().map_err(|_| invalid())?,
        );
        if of == 0 || index >= of {
            return Err(invalid());
        }
        Ok(Shard { index, of })
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.of)
    }
}

/// The estimated cost of a point: processors x triangles x frames (at least 1).
pub fn estimate(procs: u32, triangles: usize, frames: usize) -> u64 {
    (u64::from(procs) * triangles as u64 * frames as u64).max(1)
}

/// The shard of each point, from the points' estimates, over `tasks` shards.
pub fn deal(estimates: &[u64], tasks: u32) -> Vec<u32> {
    assert!(tasks > 0, "at least one shard");
    let mut order: Vec<usize> = (0..estimates.len()).collect();
    order.sort_by_key(|&i| (std::cmp::Reverse(estimates[i]), i));
    let mut load = vec![0u64; tasks as usize];
    let mut shard_of = vec![0u32; estimates.len()];
    for i in order {
        let lightest = (0..tasks as usize)
            .min_by_key(|&s| (load[s], s))
            .expect("at least one shard");
        load[lightest] += estimates[i];
        shard_of[i] = lightest as u32;
    }
    shard_of
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_parse_from_zero_and_refuse_indices_past_the_count() {
        assert_eq!("2/3".parse(), Ok(Shard { index: 2, of: 3 }));
        for bad in ["3/3", "4/3", "0/0", "1", "a/3", "-1/3", ""] {
            let e = bad.parse::<Shard>().unwrap_err();
            assert!(e.contains("0 <= I < T"), "{bad}: {e}");
        }
    }

    #[test]
    fn the_deal_balances_the_estimates_and_covers_every_point() {
        let estimates = [8, 1, 1, 4, 4, 2, 2, 2];
        let shard_of = deal(&estimates, 3);
        let mut load = [0u64; 3];
        for (i, &s) in shard_of.iter().enumerate() {
            load[s as usize] += estimates[i];
        }
        // 24 units over 3 shards: LPT gives 8 / 8 / 8 here.
        assert_eq!(load, [8, 8, 8]);
        // More shards than points: each point alone, the rest empty.
        assert_eq!(deal(&[5, 3], 4), vec![0, 1]);
        // The same input always gives the same deal.
        assert_eq!(deal(&estimates, 3), shard_of);
    }
}
