//! Link occupancy for timelines: for every message, every link of its route counts as
//! occupied from the message's injection to its delivery; per link the intervals are merged.
//! This is what a timeline's link tracks show (a message in flight over the link), the same
//! at every fidelity level; the transports' own busy time stays in `LinkStats`.
//!
//! Opt-in (it keeps a record per message). Must never influence a delivery time.

use std::collections::BTreeMap;

use super::{LinkId, MsgId};
use crate::units::SimTime;

/// A stretch of time during which a link carried at least one message.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LinkSpan {
    pub link: LinkId,
    pub start: SimTime,
    pub end: SimTime,
}

#[derive(Default)]
pub(super) struct Occupancy {
    /// Messages whose delivery comes later, with their injection time and route.
    pending: BTreeMap<MsgId, (SimTime, Vec<LinkId>)>,
    /// Per link, the intervals recorded so far (merged when read).
    intervals: BTreeMap<LinkId, Vec<(SimTime, SimTime)>>,
    /// Messages injected now are not recorded.
    pub paused: bool,
}

impl Occupancy {
    pub fn injected(
        &mut self,
        msg: MsgId,
        now: SimTime,
        route: &[LinkId],
        arrival: Option<SimTime>,
    ) {
        if self.paused {
            return;
        }
        match arrival {
            Some(at) => self.occupy(route, now, at),
            None => {
                self.pending.insert(msg, (now, route.to_vec()));
            }
        }
    }

    pub fn delivered(&mut self, msg: MsgId, at: SimTime) {
        if let Some((start, route)) = self.pending.remove(&msg) {
            self.occupy(&route, start, at);
        }
    }

    fn occupy(&mut self, route: &[LinkId], start: SimTime, end: SimTime) {
        if end > start {
            for &l in route {
                let intervals = self.intervals.entry(l).or_default();
                // An interval that overlaps or touches the link's last one joins it: the
                // merge when read would join them anyway (a busy link's messages mostly
                // overlap), and the record stays about half the size.
                match intervals.last_mut() {
                    Some(last) if start <= last.1 && end >= last.0 => {
                        *last = (last.0.min(start), last.1.max(end));
                    }
                    _ => intervals.push((start, end)),
                }
            }
        }
    }

    /// Merged spans, by link and then by time, freeing each link's intervals as soon as they
    /// are merged, so that the raw record and the merged spans are not both held whole.
    pub fn into_spans(self) -> Vec<LinkSpan> {
        let mut out = Vec::new();
        for (link, intervals) in self.intervals {
            merge_into(&mut out, link, intervals);
        }
        out
    }
}

/// Appends `link`'s intervals, sorted and with overlapping ones merged, to `out`.
fn merge_into(out: &mut Vec<LinkSpan>, link: LinkId, mut intervals: Vec<(SimTime, SimTime)>) {
    intervals.sort_unstable();
    let mut current: Option<(SimTime, SimTime)> = None;
    for (s, e) in intervals {
        current = match current {
            Some((cs, ce)) if s <= ce => Some((cs, ce.max(e))),
            Some((cs, ce)) => {
                out.push(LinkSpan {
                    link,
                    start: cs,
                    end: ce,
                });
                Some((s, e))
            }
            None => Some((s, e)),
        };
    }
    if let Some((start, end)) = current {
        out.push(LinkSpan { link, start, end });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// Joining an interval to its link's last one as it is recorded gives the spans of
        /// recording every interval and merging them only when read.
        #[test]
        fn joining_as_recorded_gives_the_spans_of_merging_when_read(
            messages in proptest::collection::vec((0u32..4, 0u64..60, 0u64..12, 0u32..2), 0..80)
        ) {
            let mut o = Occupancy::default();
            let mut raw: BTreeMap<LinkId, Vec<(SimTime, SimTime)>> = BTreeMap::new();
            for (i, &(link, start, len, hops)) in messages.iter().enumerate() {
                let route: Vec<LinkId> = (0..=hops).map(|h| (link + h) % 4).collect();
                let (s, e) = (t(start), t(start + len));
                o.injected(i as MsgId, s, &route, Some(e));
                if e > s {
                    for &l in &route {
                        raw.entry(l).or_default().push((s, e));
                    }
                }
            }
            let mut plain = Vec::new();
            for (link, intervals) in raw {
                merge_into(&mut plain, link, intervals);
            }
            prop_assert_eq!(o.into_spans(), plain);
        }
    }

    fn t(us: u64) -> SimTime {
        SimTime::from_us(us)
    }

    #[test]
    fn overlapping_messages_merge_and_gaps_stay() {
        let mut o = Occupancy::default();
        o.injected(1, t(0), &[3, 4], Some(t(10)));
        o.injected(2, t(5), &[4], None);
        o.injected(3, t(30), &[4], Some(t(40)));
        o.delivered(2, t(20));
        let expected = vec![
            LinkSpan {
                link: 3,
                start: t(0),
                end: t(10),
            },
            LinkSpan {
                link: 4,
                start: t(0),
                end: t(20),
            },
            LinkSpan {
                link: 4,
                start: t(30),
                end: t(40),
            },
        ];
        assert_eq!(o.into_spans(), expected);
    }
}
