//! The anti-aliasing options every algorithm reads (`--set aa=none|adaptive|supersample:N`,
//! `aa-pool`, `aa-start`, `aa-reclaim`): one parser, one settings type, for both families.
//!
//! Must never build a target or charge anything: a family decides what its nodes render into.

use super::options::{choice_option, quantity_option, string_option, OnOff};
use super::{bad_option as bad, Options, RunConfig, RunError};
use crate::machine::Op;
use crate::raster::aa::{AaMethod, Grid};
use crate::raster::screen::MAX_VIEWPORT;
use crate::raster::Viewport;
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

choice_option!(
    /// The first frame's subpixel resolution, n x n.
    AaStart { X4 = "4", X3 = "3", X2 = "2" }
);

quantity_option!(
    /// A Subpixel pool per processor.
    PoolSize(Bytes),
    what = "a Subpixel pool size per processor such as 10MB"
);

/// An anti-aliasing method as `--set aa=` spells it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Method(pub AaMethod);

impl std::str::FromStr for Method {
    type Err = String;
    fn from_str(s: &str) -> Result<Method, String> {
        AaMethod::parse(s)
            .map(Method)
            .ok_or_else(|| format!("expected {}", AaMethod::VALID))
    }
}

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0.name())
    }
}

string_option!(Method);

impl schemars::JsonSchema for Method {
    fn schema_name() -> std::borrow::Cow<'static, str> {
        "AaMethod".into()
    }
    fn json_schema(_: &mut schemars::SchemaGenerator) -> schemars::Schema {
        schemars::json_schema!({
            "type": "string",
            "pattern": "^(none|adaptive|supersample:[0-9]+)$",
            "description": AaMethod::VALID,
        })
    }
}

/// The anti-aliasing options every algorithm takes.
#[derive(Clone, Debug, serde::Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub struct AaOptions {
    /// Anti-aliasing: none, adaptive (paper 000's supersampling of edge pixels into a fixed
    /// Subpixel pool) or supersample:N (N samples per pixel, a perfect square from 4 to 256).
    #[serde(default = "no_aa")]
    pub aa: Method,
    /// Subpixel pool per processor, adaptive only; none: 2x2 samples for all of its pixels.
    #[serde(default)]
    pub aa_pool: Option<PoolSize>,
    /// First frame's subpixel resolution n (n x n samples), adaptive only; paper 000: 4.
    #[serde(default = "start_at_4x4")]
    pub aa_start: AaStart,
    /// Reclaim the cells of edge pixels whose samples agree, adaptive only.
    #[serde(default = "reclaiming")]
    pub aa_reclaim: OnOff,
}

fn no_aa() -> Method {
    Method(AaMethod::None)
}
fn start_at_4x4() -> AaStart {
    AaStart::X4
}
fn reclaiming() -> OnOff {
    OnOff::On
}

/// The anti-aliasing settings of parsed options; the adaptive-only keys are refused with
/// any other method.
pub(crate) fn aa_settings(o: &Options, a: &AaOptions) -> Result<AaSettings, RunError> {
    let method = a.aa.0;
    let adaptive_only = ["aa-pool", "aa-start", "aa-reclaim"];
    if method != AaMethod::Adaptive {
        if let Some(k) = adaptive_only.iter().find(|k| o.is_given(k)) {
            return Err(bad(
                o,
                k,
                "aa=adaptive with it (it applies to adaptive supersampling only)",
            ));
        }
    }
    Ok(AaSettings {
        method,
        pool: a.aa_pool.map(|p| p.0),
        start: match a.aa_start {
            AaStart::X4 => Grid::X4,
            AaStart::X3 => Grid::X3,
            AaStart::X2 => Grid::X2,
        },
        reclaim: a.aa_reclaim.is_on(),
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

/// The grid of samples a `supersample:N` run renders (or merges) on: the screen sqrt N times
/// finer in each direction. Refused, before anything is allocated, past `MAX_VIEWPORT` samples
/// per side: the host holds every sample (7 bytes each) whatever memory the simulated machine has.
pub fn sample_grid(cfg: &RunConfig, screen: Viewport, side: u32) -> Result<Viewport, RunError> {
    Viewport::new(screen.width() * side, screen.height() * side).ok_or_else(|| {
        let samples = u64::from(screen.width() * side) * u64::from(screen.height() * side);
        RunError::Unsupported(format!(
            "{}x{} pixels at {side}x{side} samples is a {}x{} sample grid (about {:.1} GB of \
             host memory); {} works on sample grids of at most {MAX_VIEWPORT} per side",
            screen.width(),
            screen.height(),
            screen.width() * side,
            screen.height() * side,
            samples as f64 * crate::raster::aa::SUBPIXEL_BYTES as f64 / 1e9,
            cfg.algo.id()
        ))
    })
}
