//! The resource budgets every command checks before it allocates or loops, in one place, so
//! that a mistyped size gets a refusal naming the limit within a second instead of an abort
//! or an hour of work. Each limit is far above what the papers' experiments use.
//!
//! Owns the numbers and the wording of a refusal. Must never be bypassed by a command that
//! sizes something from input.

/// The most links a machine's network may have. A fat-tree's switches and cables, and a
/// dragonfly's all-to-all chassis, grow faster than its hosts, so a shape within
/// [`MAX_NODES`] hosts can still ask for billions of links: `parallel: [1, 300000]` on a
/// 256-host tree built 153 M links (9.2 GB, 19 s) before `check` answered. Each link is host
/// memory: a hypercube of `MAX_NODES` nodes, the most links any other topology reaches
/// (20.9 M), takes 0.8 GB to check at `hops` and 5.8 GB at `flow`.
pub const MAX_LINKS: u64 = 1 << 25;

/// The most nodes a machine may have, or a utilization run may simulate: every node and link
/// is host memory, allocated when the network is built (about 300 B a node).
pub const MAX_NODES: u32 = 1 << 20;

/// The most values a command-line list (`--procs 1..64`, `--granularity 2,4,...,12`,
/// `--frames`) may expand to.
pub const MAX_LIST_ITEMS: u64 = 4096;

/// Refuses a list of `count` values: "'1..4294967295' has 4294967295 values; the limit is
/// 4096".
pub fn check_list(text: &str, count: u64) -> Result<(), String> {
    if count > MAX_LIST_ITEMS {
        return Err(format!(
            "'{text}' has {count} values; the limit is {MAX_LIST_ITEMS} (sortsim::limits::MAX_LIST_ITEMS)"
        ));
    }
    Ok(())
}

/// The most points (simulations) a sweep may list.
pub const MAX_SWEEP_POINTS: u64 = 1_000_000;

/// The most packet hops (packets times the links each crosses) a `netsim` pattern may ask of
/// the `packet` transport, which simulates every one: about five seconds of host time on a
/// contended route. `flow` and `hops` take any size.
pub const MAX_PACKET_HOPS: u64 = 100_000_000;

/// The most events the engine's queue holds pending at once (its slot index has 24 bits):
/// `bench phold` refuses more logical processes times events per process than this.
pub const MAX_PENDING_EVENTS: u64 = 1 << 24;

/// The most triangles a scene may generate in all (its objects' generators, and the counts
/// their `triangles` fields refine them to), forty times the largest bundled scene: at the
/// limit a UV sphere takes 1.1 GB of host memory to build and check and 2.4 GB to draw.
/// Checked before any vertex is made, so that a generator's parameters, each within its own
/// range, cannot together ask for billions.
pub const MAX_SCENE_TRIANGLES: u64 = 1 << 25;
