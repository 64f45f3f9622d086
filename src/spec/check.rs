//! `sortsim check`: validate any spec file, detecting its kind, and describe it in one line.
//!
//! Must never run a simulation.

use std::path::Path;

use super::run::{RunSpec, RunSpecError};
use super::{load_json, machine::load_machine, SpecError, SpecKind};
use crate::scene::{Scene, SceneError};
use crate::units::SimTime;

/// Why a spec did not check out.
#[derive(Debug, thiserror::Error)]
pub enum CheckError {
    #[error(transparent)]
    Spec(#[from] SpecError),
    #[error(transparent)]
    Scene(#[from] SceneError),
    #[error("{}: {source}", file.display())]
    Run {
        source: RunSpecError,
        file: std::path::PathBuf,
    },
}

/// Validates the spec at `path`; on success, a one-line description of what it holds.
pub fn check(path: &Path) -> Result<String, CheckError> {
    match SpecKind::detect(path)? {
        SpecKind::Machine => {
            let m = load_machine(path)?;
            // An operation the file does not price is charged at zero wherever an algorithm
            // uses it: say which, so a file older than an operation is not silently faster.
            let unpriced: Vec<&str> = crate::machine::Op::ALL
                .iter()
                .filter(|&&op| !m.cpu.costs.is_priced(op))
                .map(|op| op.name())
                .collect();
            let nodes = match m.network.node {
                Some(n) => format!(
                    "{} processors in nodes of {}{} with {} on {} links with {} per hop, joined by a",
                    m.nodes,
                    n.processors,
                    match n.placement {
                        crate::net::topology::Placement::Block => "",
                        crate::net::topology::Placement::Cyclic => " (placed cyclically)",
                    },
                    crate::units::count(n.nics, "NIC"),
                    n.links.bandwidth,
                    n.links.hop_latency
                ),
                None => format!("{} nodes,", m.nodes),
            };
            let gap = match m.network.message_gap {
                SimTime::ZERO => String::new(),
                gap => format!(" and {gap} a message at each interface"),
            };
            Ok(format!(
                "machine '{}': {nodes} {} {}, links {} with {} per hop{gap}, {} switching, fidelity {}{}",
                m.name,
                m.network.topology.name(),
                crate::net::shape_text(m.network.topology, &m.network.dims),
                m.network.link_bandwidth,
                m.network.hop_latency,
                m.network.switching.name(),
                m.network.fidelity.name(),
                if unpriced.is_empty() {
                    String::new()
                } else {
                    format!("; charged at zero (not priced): {}", unpriced.join(", "))
                }
            ))
        }
        SpecKind::Scene => Ok(Scene::load(path)?.describe()),
        SpecKind::Run => {
            let mut spec: RunSpec = load_json(path)?;
            spec.machine = super::run::relative_to(path, &spec.machine);
            spec.scene = super::run::relative_to(path, &spec.scene);
            let run_error = |source| CheckError::Run {
                source,
                file: path.to_path_buf(),
            };
            let cfg = spec.resolve_file(None).map_err(run_error)?;
            crate::algo::check_options(&cfg).map_err(|e| {
                let message = match &e {
                    crate::algo::RunError::Option(o) => super::run::file_option_error(o),
                    e => e.to_string(),
                };
                run_error(RunSpecError::Invalid(message))
            })?;
            Ok(format!(
                "run: {} on {} processors of '{}', frames {}..{}",
                cfg.algo.id(),
                cfg.machine.nodes,
                cfg.machine.name,
                cfg.frames.start,
                cfg.frames.end
            ))
        }
        SpecKind::Sweep => {
            let sweep = crate::sweep::spec::load_sweep(path)?;
            // Every point set up as `sweep` would, short of simulating.
            crate::sweep::check(&sweep)?;
            let listed = sweep.listed().count();
            Ok(format!(
                "sweep: {listed} points, {} runs with the implicit 1-processor baselines",
                sweep.points.len()
            ))
        }
        SpecKind::Calibration => Err(SpecError::invalid(
            path,
            "",
            "a calibration spec: `sortsim check` checks it through `calibrate::check`",
        )
        .into()),
        SpecKind::Paper => Err(SpecError::invalid(
            path,
            "",
            "a paper's rows: `sortsim check` checks them through `paper::data::load_file`",
        )
        .into()),
        SpecKind::Pattern => {
            let _: crate::net::pattern::Pattern = load_json(path)?;
            Ok("network pattern (run it with `sortsim netsim MACHINE PATTERN`)".into())
        }
    }
}
