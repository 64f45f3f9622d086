//! What a run measured: per node busy time by phase, communication, traffic and finishing
//! time; per link traffic; per node memory high-water marks.
//!
//! Owns raw counters only. Must never format or write anything (that is `report`).

use crate::machine::PoolStats;
use crate::net::{LinkStats, NodeId};
use crate::units::{Bytes, SimTime};

/// A node's counters as a run reports them. The engine counts the received ones on the node's
/// record beside the message handed over, which every delivery touches, and copies them in
/// only when the run's counters are read: during a run these two fields stay zero.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct NodeStats {
    pub bytes_received: Bytes,
    pub messages_received: u64,
    /// Busy time per phase label, in the order the labels first appeared.
    pub busy_by_phase: Vec<(&'static str, SimTime)>,
    /// Part of the busy time spent on message overheads (and, without overlap, on waiting for
    /// a blocking send to be delivered).
    pub comm: SimTime,
    pub bytes_sent: Bytes,
    pub messages_sent: u64,
    /// When the node's last program that must finish did finish.
    pub finish: SimTime,
}

impl NodeStats {
    pub fn busy(&self) -> SimTime {
        self.busy_by_phase.iter().map(|&(_, t)| t).sum()
    }

    /// Adds `t` to `phase`'s busy time and returns where that phase sits among the node's
    /// (for [`NodeStats::charge_at`]).
    pub(crate) fn charge(&mut self, phase: &'static str, t: SimTime) -> usize {
        // A label is almost always the very literal it was first charged under, so its address
        // finds it without reading the text; the text decides only when no address matches
        // (the same words may sit at two addresses).
        let phases = &self.busy_by_phase;
        let slot = phases
            .iter()
            .position(|&(p, _)| std::ptr::eq(p, phase))
            .or_else(|| phases.iter().position(|&(p, _)| p == phase))
            .unwrap_or_else(|| {
                self.busy_by_phase.push((phase, SimTime::ZERO));
                self.busy_by_phase.len() - 1
            });
        self.charge_at(slot, t);
        slot
    }

    /// [`NodeStats::charge`] to the phase at `slot`, where an earlier charge found it.
    pub(crate) fn charge_at(&mut self, slot: usize, t: SimTime) {
        self.busy_by_phase[slot].1 += t;
    }
}

/// One stretch of cpu work of one phase on a node, for timelines.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CpuSpan {
    pub node: NodeId,
    pub phase: &'static str,
    pub start: SimTime,
    pub end: SimTime,
}

/// The cpu spans of a run being recorded. A charge that starts where its node's last span
/// ends, in the same phase, lengthens that span instead of adding one: the timeline shows
/// the same bars, and its size follows the changes of phase, not the charges (a sort-middle
/// frame charges each message's overheads apart; a time-sliced cpu charges each slice).
/// No span is lengthened across a [`CpuTimeline::cut`] (a frame's beginning), so that the
/// timeline of some frames is the whole run's cut there.
#[derive(Clone, Debug, Default)]
pub(crate) struct CpuTimeline {
    spans: Vec<CpuSpan>,
    /// `last[node]`: the index of the node's last span, `NO_SPAN` before its first.
    last: Vec<usize>,
}

const NO_SPAN: usize = usize::MAX;

impl CpuTimeline {
    pub fn record(&mut self, span: CpuSpan) {
        let node = span.node as usize;
        if node >= self.last.len() {
            self.last.resize(node + 1, NO_SPAN);
        }
        if let Some(last) = self.spans.get_mut(self.last[node]) {
            if last.end == span.start && last.phase == span.phase {
                last.end = span.end;
                return;
            }
        }
        self.last[node] = self.spans.len();
        self.spans.push(span);
    }

    /// Spans recorded from now on start afresh.
    pub fn cut(&mut self) {
        self.last.fill(NO_SPAN);
    }

    /// The spans, each where its first charge was made (so in the order they began on each
    /// node).
    pub fn into_spans(self) -> Vec<CpuSpan> {
        self.spans
    }
}

#[derive(Clone, Debug, Default)]
pub struct RunStats {
    /// The instant the last event was processed.
    pub end: SimTime,
    pub seed: u64,
    pub events: u64,
    pub nodes: Vec<NodeStats>,
    pub links: Vec<LinkStats>,
    pub memory: Vec<PoolStats>,
    /// Cpu spans in the order they began, if the run recorded a timeline; contiguous work of
    /// one phase on a node is one span ([`CpuTimeline`]).
    pub timeline: Option<Vec<CpuSpan>>,
    /// Link occupancy (messages in flight per link), if the run recorded a timeline.
    pub link_timeline: Option<Vec<crate::net::LinkSpan>>,
    /// Operations the programs charged that the machine does not price (charged at zero).
    pub unpriced_ops: Vec<crate::machine::Op>,
    /// The flow model's work (zero at other fidelities, and unless built with the `counters`
    /// feature).
    pub flow_solves: crate::net::transport::SolveCounters,
}

impl RunStats {
    /// Idle time of node `i`: the run's length minus its busy time.
    pub fn idle(&self, i: usize) -> SimTime {
        self.end.saturating_sub(self.nodes[i].busy())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_phase_is_charged_by_its_words_wherever_they_are_kept() {
        let mut stats = NodeStats::default();
        let owned = String::from("rasterize");
        // The same words at another address than the literal's.
        let elsewhere: &'static str = Box::leak(owned.into_boxed_str());
        stats.charge("rasterize", SimTime::from_ns(1));
        stats.charge("transform", SimTime::from_ns(2));
        stats.charge(elsewhere, SimTime::from_ns(4));
        stats.charge("rasterize", SimTime::from_ns(8));
        assert_eq!(
            stats.busy_by_phase,
            vec![
                ("rasterize", SimTime::from_ns(13)),
                ("transform", SimTime::from_ns(2))
            ]
        );
    }

    fn span(node: NodeId, phase: &'static str, start_ns: u64, end_ns: u64) -> CpuSpan {
        CpuSpan {
            node,
            phase,
            start: SimTime::from_ns(start_ns),
            end: SimTime::from_ns(end_ns),
        }
    }

    #[test]
    fn contiguous_work_of_one_phase_on_a_node_is_one_span() {
        let mut t = CpuTimeline::default();
        t.record(span(1, "transform", 0, 10));
        t.record(span(0, "transform", 10, 20)); // another node: its own span
        t.record(span(1, "transform", 10, 15)); // joins node 1's
        t.record(span(1, "rasterize", 15, 30)); // another phase
        t.record(span(1, "rasterize", 31, 40)); // a gap
        t.record(span(0, "transform", 20, 25)); // joins node 0's, after node 1's others
        t.cut();
        t.record(span(0, "transform", 25, 26)); // a frame began: its own span
        assert_eq!(
            t.into_spans(),
            vec![
                span(1, "transform", 0, 15),
                span(0, "transform", 10, 25),
                span(1, "rasterize", 15, 30),
                span(1, "rasterize", 31, 40),
                span(0, "transform", 25, 26),
            ]
        );
    }
}
