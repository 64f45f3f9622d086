//! The anti-aliasing options every algorithm reads (`--set aa=none|adaptive|supersample:N`,
//! `aa-pool`, `aa-start`, `aa-reclaim`): one parser, one settings type, for both families.
//!
//! Must never build a target or charge anything: a family decides what its nodes render into.

use super::{bad_option as bad, Options, RunConfig, RunError};
use crate::machine::Op;
use crate::raster::aa::{AaMethod, Grid};
use crate::units::{Bytes, SimTime};

/// The anti-aliasing options of a run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AaSettings {
    pub method: AaMethod,
    /// Subpixel pool per processor (`aa-pool`); `None`: 2x2 for all of its pixels.
    pub pool: Option<Bytes>,
    /// First frame's resolution (`aa-start`, paper 000: 4x4).
    pub start: Grid,
    /// Reclaiming on (`aa-reclaim`).
    pub reclaim: bool,
}

impl Default for AaSettings {
    fn default() -> AaSettings {
        AaSettings {
            method: AaMethod::None,
            pool: None,
            start: Grid::X4,
            reclaim: true,
        }
    }
}

/// Reads the anti-aliasing options (`aa`, `aa-pool`, `aa-start`, `aa-reclaim`).
pub(crate) fn aa_settings(o: &Options) -> Result<AaSettings, RunError> {
    let method: String = o.get("aa", "none".to_string(), AaMethod::VALID)?;
    let method = AaMethod::parse(&method).ok_or_else(|| bad(o, "aa", AaMethod::VALID))?;
    let pool_given = o.pairs().any(|(k, _)| k == "aa-pool");
    let pool: Bytes = o.get(
        "aa-pool",
        Bytes::new(0),
        "a Subpixel pool size per processor such as 10MB",
    )?;
    let pool = pool_given.then_some(pool);
    let start = match o.choice("aa-start", "4", &["4", "3", "2"])? {
        "3" => Grid::X3,
        "2" => Grid::X2,
        _ => Grid::X4,
    };
    let reclaim = o.choice("aa-reclaim", "on", &["on", "off"])? == "on";
    let adaptive_only = ["aa-pool", "aa-start", "aa-reclaim"];
    if method != AaMethod::Adaptive {
        if let Some((k, _)) = o.pairs().find(|(k, _)| adaptive_only.contains(&k.as_str())) {
            return Err(bad(
                o,
                k,
                "aa=adaptive with it (it applies to adaptive supersampling only)",
            ));
        }
    }
    Ok(AaSettings {
        method,
        pool,
        start,
        reclaim,
    })
}

/// The operations anti-aliasing charges beyond the aliased renderer's.
const AA_OPS: [Op; 5] = [
    Op::CoverageMask,
    Op::SubpixelTest,
    Op::SubpixelWrite,
    Op::ReclaimCheck,
    Op::ResolvePixel,
];

/// Refuses an anti-aliased run on a machine that prices none of the anti-aliasing
/// operations: its samples would cost nothing, and the run would claim accuracy for free.
pub(crate) fn check_prices(cfg: &RunConfig, aa: &AaSettings) -> Result<(), RunError> {
    let costs = &cfg.machine.cpu.costs;
    if aa.method == AaMethod::None || AA_OPS.iter().any(|&op| costs.get(op) > SimTime::ZERO) {
        return Ok(());
    }
    let names: Vec<&str> = AA_OPS.iter().map(|op| op.name()).collect();
    Err(RunError::Unsupported(format!(
        "machine '{}' prices none of the anti-aliasing operations, so --set aa={} would cost \
         no time; add cpu.costs for {} to the machine file (machines/power-challenge.json \
         states estimates relative to pixel_test)",
        cfg.machine.name,
        aa.method.name(),
        names.join(", ")
    )))
}
