//! summary.json: the simulated metrics of a run (per node busy time by phase, idle time,
//! traffic; per link traffic, busy time, peak queue; per node memory high-water marks).
//!
//! Must never contain anything that depends on the host (wall time, thread count, paths
//! beyond what the user gave): two runs of the same inputs give the same bytes.

use std::collections::BTreeMap;

use serde::Serialize;

use crate::engine::RunStats;

#[derive(Serialize, Debug, Clone, PartialEq)]
pub struct Summary {
    pub seed: u64,
    pub end_s: f64,
    pub end_ps: u64,
    pub events: u64,
    pub nodes: Vec<NodeSummary>,
    pub links: Vec<LinkSummary>,
    pub totals: Totals,
}

#[derive(Serialize, Debug, Clone, PartialEq)]
pub struct NodeSummary {
    pub node: u32,
    pub busy_s: f64,
    pub idle_s: f64,
    pub busy_pct: f64,
    pub comm_s: f64,
    pub finish_s: f64,
    /// Busy time per phase label (sorted by label).
    pub busy_by_phase_s: BTreeMap<String, f64>,
    pub sent_bytes: u64,
    pub sent_messages: u64,
    pub received_bytes: u64,
    pub received_messages: u64,
    pub memory_capacity_bytes: u64,
    pub memory_high_water_bytes: u64,
    pub memory_high_water_by_tag_bytes: BTreeMap<String, u64>,
}

#[derive(Serialize, Debug, Clone, PartialEq)]
pub struct LinkSummary {
    pub link: usize,
    pub from: u32,
    pub to: u32,
    pub bytes: u64,
    pub messages: u64,
    pub busy_s: f64,
    pub utilization_pct: f64,
    pub peak_queue: u32,
}

#[derive(Serialize, Debug, Clone, PartialEq)]
pub struct Totals {
    pub sent_bytes: u64,
    pub sent_messages: u64,
    pub busy_s: f64,
    pub comm_s: f64,
    /// (slowest node's finish - mean finish) / slowest finish, as paper 001 defines imbalance.
    pub load_imbalance_pct: f64,
    pub memory_high_water_max_bytes: u64,
}

fn pct(part: f64, whole: f64) -> f64 {
    if whole > 0.0 {
        100.0 * part / whole
    } else {
        0.0
    }
}

impl Summary {
    pub fn from_stats(stats: &RunStats) -> Summary {
        let end = stats.end.as_secs_f64();
        let nodes: Vec<NodeSummary> = stats
            .nodes
            .iter()
            .zip(&stats.memory)
            .enumerate()
            .map(|(i, (n, mem))| NodeSummary {
                node: i as u32,
                busy_s: n.busy().as_secs_f64(),
                idle_s: stats.idle(i).as_secs_f64(),
                busy_pct: pct(n.busy().as_secs_f64(), end),
                comm_s: n.comm.as_secs_f64(),
                finish_s: n.finish.as_secs_f64(),
                busy_by_phase_s: n
                    .busy_by_phase
                    .iter()
                    .map(|&(p, t)| (p.to_string(), t.as_secs_f64()))
                    .collect(),
                sent_bytes: n.bytes_sent.get(),
                sent_messages: n.messages_sent,
                received_bytes: n.bytes_received.get(),
                received_messages: n.messages_received,
                memory_capacity_bytes: mem.capacity.get(),
                memory_high_water_bytes: mem.high_water.get(),
                memory_high_water_by_tag_bytes: mem
                    .high_water_by_tag
                    .iter()
                    .map(|(t, b)| (t.to_string(), b.get()))
                    .collect(),
            })
            .collect();
        let links = stats
            .links
            .iter()
            .enumerate()
            .map(|(i, l)| LinkSummary {
                link: i,
                from: l.from,
                to: l.to,
                bytes: l.bytes.get(),
                messages: l.messages,
                busy_s: l.busy.as_secs_f64(),
                utilization_pct: pct(l.busy.as_secs_f64(), end),
                peak_queue: l.peak_queue,
            })
            .collect();
        let finishes: Vec<f64> = stats.nodes.iter().map(|n| n.finish.as_secs_f64()).collect();
        let totals = Totals {
            sent_bytes: stats.nodes.iter().map(|n| n.bytes_sent.get()).sum(),
            sent_messages: stats.nodes.iter().map(|n| n.messages_sent).sum(),
            busy_s: stats.nodes.iter().map(|n| n.busy().as_secs_f64()).sum(),
            comm_s: stats.nodes.iter().map(|n| n.comm.as_secs_f64()).sum(),
            load_imbalance_pct: crate::algo::load_imbalance_pct(&finishes),
            memory_high_water_max_bytes: stats
                .memory
                .iter()
                .map(|m| m.high_water.get())
                .max()
                .unwrap_or(0),
        };
        Summary {
            seed: stats.seed,
            end_s: end,
            end_ps: stats.end.ps(),
            events: stats.events,
            nodes,
            links,
            totals,
        }
    }
}
