//! `sort-last/2-3-swap` (Yu, Wang, Ma 2008) as one node's program: binary swap for any N,
//! by groups of two or three.
//!
//! ```text
//! render my share into my full frame
//! groups = the N nodes alone, each holding the whole screen
//! round after round, until one group remains:
//!   join consecutive groups in twos (the first three together when their number is odd)
//!   my new group of M cuts the screen into M parts, handed out in the order of the
//!     pieces its members hold now (so a new part lies in, or overlaps, its holder's piece)
//!   send every other member the part of my piece that falls in its new part
//!   keep what falls in mine; receive from every member whose piece overlaps my new part,
//!     and z-merge it
//! gather: every node sends its part (A/N positions, as merged) to node 0
//! ```
//!
//! Every group of a round joins two or three groups, so a node talks to two or three
//! partners a round where binary swap talks to one: with N = 2^a 3^b and groups that join
//! equals, each node sends A (1 - 1/N) positions before the gather, as binary swap does for
//! powers of two (for which the two are the same exchange). Otherwise parts straddle the
//! pieces they come from and a node sends a little more.
//!
//! Must never hold full frames on the host: pieces travel as their active pixels, charged as
//! every position of the piece.

use std::rc::Rc;

use super::composite::{self, cut, receive_and_merge, Sender};
use super::full_frame::{self, Msg};
use super::interlace::Interlace;
use super::pixel::ShippedPixel;
use super::Ctx;
use crate::engine::{Node, SimError};

/// One round: the groups it forms, each listing its members in the order their parts run.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Round {
    pub groups: Vec<Vec<u32>>,
    /// Per node: (its group, its place in that group).
    pub place: Vec<(u32, u32)>,
}

impl Round {
    /// `node`'s group (members in part order) and its place in it.
    pub fn group_of(&self, node: u32) -> (&[u32], u32) {
        let (g, i) = self.place[node as usize];
        (&self.groups[g as usize], i)
    }
}

/// The rounds of 2-3 swap on `n` nodes (none for one node). Parts are fractions of the
/// screen, so the schedule does not depend on its size.
pub fn schedule(n: u32) -> Vec<Round> {
    // The groups as they stand, each member with its part (index, of how many).
    let mut groups: Vec<Vec<(u32, u32, u32)>> = (0..n).map(|i| vec![(i, 0, 1)]).collect();
    let mut rounds = Vec::new();
    while groups.len() > 1 {
        let sizes = join_sizes(groups.len());
        let mut joined = Vec::with_capacity(sizes.len());
        let mut rest = groups.into_iter();
        for size in sizes {
            let subgroups: Vec<_> = rest.by_ref().take(size).collect();
            joined.push(join(subgroups));
        }
        groups = joined;
        let mut place = vec![(0, 0); n as usize];
        for (g, members) in groups.iter().enumerate() {
            for (i, &(node, _, _)) in members.iter().enumerate() {
                place[node as usize] = (g as u32, i as u32);
            }
        }
        rounds.push(Round {
            groups: groups
                .iter()
                .map(|m| m.iter().map(|&(node, _, _)| node).collect())
                .collect(),
            place,
        });
    }
    rounds
}

/// How many consecutive groups each new group joins: twos, with the first three together
/// when the count is odd.
fn join_sizes(count: usize) -> Vec<usize> {
    let mut sizes = vec![2; count / 2];
    if count % 2 == 1 {
        sizes[0] = 3;
    }
    sizes
}

/// Joins subgroups into one: members ordered by where their current part starts (an exact
/// fraction; ties by subgroup), then each takes the next of the new group's equal parts.
fn join(subgroups: Vec<Vec<(u32, u32, u32)>>) -> Vec<(u32, u32, u32)> {
    let mut members: Vec<(usize, (u32, u32, u32))> = subgroups
        .into_iter()
        .enumerate()
        .flat_map(|(s, m)| m.into_iter().map(move |member| (s, member)))
        .collect();
    members.sort_by(|(s1, (_, j1, m1)), (s2, (_, j2, m2))| {
        (u64::from(*j1) * u64::from(*m2))
            .cmp(&(u64::from(*j2) * u64::from(*m1)))
            .then(s1.cmp(s2))
    });
    let size = members.len() as u32;
    members
        .into_iter()
        .enumerate()
        .map(|(i, (_, (node, _, _)))| (node, i as u32, size))
        .collect()
}

/// Part `j` of `m` of the screen's `area` positions.
pub fn part(area: u32, j: u32, m: u32) -> (u32, u32) {
    let cut = |j: u32| ((u64::from(area) * u64::from(j)) / u64::from(m)) as u32;
    (cut(j), cut(j + 1))
}

/// The positions two ranges share, if any.
pub fn overlap(a: (u32, u32), b: (u32, u32)) -> Option<(u32, u32)> {
    let (lo, hi) = (a.0.max(b.0), a.1.min(b.1));
    (lo < hi).then_some((lo, hi))
}

/// `node`'s piece after round `r` (`None`: before the first, the whole screen).
fn piece(rounds: &[Round], r: Option<usize>, node: u32, area: u32) -> (u32, u32) {
    match r {
        None => (0, area),
        Some(r) => {
            let (members, i) = rounds[r].group_of(node);
            part(area, i, members.len() as u32)
        }
    }
}

/// The (sender, receiver) pairs of every round on `n` nodes, for screens of any size (the
/// parts' fractions overlap).
pub fn senders(n: u32) -> Vec<(u32, u32)> {
    let rounds = schedule(n);
    // A fine stand-in screen: parts of at most n nodes never round to empty on it.
    let area = n.saturating_mul(n).max(1);
    let mut pairs = Vec::new();
    for (r, round) in rounds.iter().enumerate() {
        for p in 0..n {
            let mine = piece(&rounds, r.checked_sub(1), p, area);
            let (members, _) = round.group_of(p);
            for (j, &q) in members.iter().enumerate() {
                let theirs = part(area, j as u32, members.len() as u32);
                if q != p && overlap(mine, theirs).is_some() {
                    pairs.push((p, q));
                }
            }
        }
    }
    pairs
}

pub(super) async fn processor<P: ShippedPixel>(
    node: Node<Msg<P>>,
    ctx: Rc<Ctx>,
) -> Result<(), SimError> {
    let me = node.id();
    let rounds = ctx.settings.swap_rounds.clone();
    let area = ctx.viewport.width() * ctx.viewport.height();
    let interlace = Interlace::for_run(&ctx, ctx.n);
    for frame in ctx.frames() {
        let mut pixels = composite::render(&node, &ctx, frame, interlace.as_ref()).await?;
        let mut held = (0, area);
        for (r, round) in rounds.iter().enumerate() {
            let at = (frame, r as u32);
            let (members, i) = round.group_of(me);
            let m = members.len() as u32;
            let new = part(area, i, m);
            // The parts of the new group tile the screen, so their overlaps tile my piece.
            let overlaps: Vec<(u32, (u32, u32))> = (0..m)
                .filter_map(|j| Some((members[j as usize], overlap(held, part(area, j, m))?)))
                .collect();
            let shares = cut(pixels, overlaps.iter().map(|&(_, (_, hi))| hi));
            let mut keep = Vec::new();
            for (&(q, range), share) in overlaps.iter().zip(shares) {
                if q == me {
                    keep = share;
                } else {
                    full_frame::send_piece(&node, &ctx, at, q, range, share).await;
                }
            }
            for &q in members.iter().filter(|&&q| q != me) {
                let theirs = piece(&rounds, r.checked_sub(1), q, area);
                if let Some(range) = overlap(theirs, new) {
                    keep = receive_and_merge(&node, &ctx, at, Sender::Node(q), range, keep).await?;
                }
            }
            pixels = keep;
            held = new;
        }
        let mine = Some((held, pixels));
        composite::finish(&node, &ctx, frame, ctx.n, mine, interlace.as_ref()).await?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every round's groups cover every node once, and each group's parts tile the screen.
    #[test]
    fn every_round_partitions_nodes_and_screen() {
        for n in 1..=40 {
            let rounds = schedule(n);
            for round in &rounds {
                let mut seen = vec![false; n as usize];
                for members in &round.groups {
                    assert!(members.len() >= 2, "n={n}: groups join two or more");
                    for (i, &node) in members.iter().enumerate() {
                        assert!(!seen[node as usize]);
                        seen[node as usize] = true;
                        assert_eq!(round.group_of(node), (members.as_slice(), i as u32));
                    }
                }
                assert!(seen.iter().all(|&s| s), "n={n}");
            }
            let last = rounds.last().map_or(1, |r| r.groups[0].len() as u32);
            assert_eq!(last, n, "the last round's group holds every node");
        }
    }

    #[test]
    fn groups_join_in_twos_and_threes() {
        assert_eq!(join_sizes(2), [2]);
        assert_eq!(join_sizes(3), [3]);
        assert_eq!(join_sizes(7), [3, 2, 2]);
        // 6 = 2 x 3: pairs, then the three pairs together.
        let six = schedule(6);
        assert_eq!(six[0].groups, [[0, 1], [2, 3], [4, 5]]);
        assert_eq!(six[1].groups, [vec![0, 2, 4, 1, 3, 5]]);
    }

    /// On a power of two the new part of every node lies in its piece and its one partner
    /// holds the same piece: binary swap's exchange of halves.
    #[test]
    fn powers_of_two_swap_halves_with_one_partner() {
        let area = 1 << 18;
        for n in [2u32, 4, 8, 16, 64] {
            let rounds = schedule(n);
            assert_eq!(rounds.len() as u32, n.ilog2());
            for (r, round) in rounds.iter().enumerate() {
                for p in 0..n {
                    let held = piece(&rounds, r.checked_sub(1), p, area);
                    let (members, i) = round.group_of(p);
                    let new = part(area, i, members.len() as u32);
                    assert_eq!(overlap(held, new), Some(new));
                    assert_eq!(new.1 - new.0, (held.1 - held.0) / 2);
                }
            }
        }
        assert_eq!(senders(8).len(), 8 * 3);
    }
}
