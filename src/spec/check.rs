//! `sortsim check`: validate any spec file, detecting its kind, and describe it in one line.
//!
//! Must never run a simulation.

use std::path::Path;

use super::{machine::load_machine, SpecError, SpecKind};

/// Validates the spec at `path`; on success, a one-line description of what it holds.
pub fn check(path: &Path) -> Result<String, SpecError> {
    match SpecKind::detect(path)? {
        SpecKind::Machine => {
            let m = load_machine(path)?;
            Ok(format!(
                "machine '{}': {} nodes, {:?} {:?}, links {} with {} per hop, {:?} switching, fidelity {}",
                m.name,
                m.nodes,
                m.network.topology,
                m.network.dims,
                m.network.link_bandwidth,
                m.network.hop_latency,
                m.network.switching,
                m.network.fidelity.name()
            ))
        }
        SpecKind::Scene => Err(SpecError::invalid(
            path,
            "",
            "scene specs are checked once scenes are supported",
        )),
        SpecKind::Pattern => Err(SpecError::invalid(
            path,
            "",
            "network patterns are checked by `sortsim netsim`",
        )),
    }
}
