//! The routes an algorithm's messages need, checked before it runs: an algorithm names the
//! (sender, receiver) pairs it may use, or all of them, and a machine whose network cannot
//! carry one is refused with the first pair it lacks, instead of failing mid-run.
//!
//! Owns the check and its message. Must never decide which pairs an algorithm uses (each
//! family says that) and never simulate.

use super::{RunConfig, RunError};
use crate::net::Network;

/// The machine's network, built to be asked about routes.
pub fn network(cfg: &RunConfig) -> Result<Network, RunError> {
    Network::new(&cfg.machine.network).map_err(|e| RunError::Unsupported(e.to_string()))
}

/// Refuses the run when `net` cannot route one of `pairs`.
pub fn require(
    cfg: &RunConfig,
    net: &Network,
    pairs: impl IntoIterator<Item = (u32, u32)>,
) -> Result<(), RunError> {
    match pairs.into_iter().find(|&(a, b)| !net.can_route(a, b)) {
        None => Ok(()),
        Some((from, to)) => Err(RunError::Unsupported(format!(
            "{} sends from node {from} to node {to}, but machine '{}' ({}) has no route \
             between them; use a torus, mesh, hypercube, crossbar, bus or ring",
            cfg.algo.id(),
            cfg.machine.name,
            cfg.machine.network.topology.name()
        ))),
    }
}

/// Refuses the run unless every processor can send to every other (an algorithm whose
/// senders and receivers depend on the scene: region owners, pixel owners).
pub fn require_all_pairs(cfg: &RunConfig, net: &Network) -> Result<(), RunError> {
    if net.routes_every_pair() {
        return Ok(());
    }
    let n = cfg.machine.nodes;
    require(
        cfg,
        net,
        (0..n).flat_map(|a| (0..n).filter(move |&b| b != a).map(move |b| (a, b))),
    )
}
