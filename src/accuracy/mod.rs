//! What accuracy costs in time (`sortsim accuracy`): one run spec simulated under several
//! anti-aliasing modes and several network fidelities, each result set beside what it cost.
//!
//! * `reference.rs`: the band-rendered 16x16-samples-per-pixel reference image;
//! * `error.rs`: image error against it (mean absolute error, share of pixels off);
//! * this file: the study. Every run goes through `spec::run::RunSpec::resolve` and
//!   `algo::run`, exactly as `sortsim run` does: an anti-aliasing mode other than `none` adds
//!   the option `aa=<mode>` to the run's options, a fidelity sets
//!   `machine.network.fidelity`. Every run is resolved and its options checked before the
//!   first one starts, so a mode the algorithm does not know fails at once.
//!
//! Must never write a file or format a report (that is `report::accuracy`), and never let a
//! wall time feed into a simulated number: wall times are kept apart in [`Cost`]s.

pub mod error;
pub mod reference;

use std::collections::BTreeMap;
use std::str::FromStr;
use std::sync::Arc;

use crate::algo::{check_options, RunConfig, RunError, RunResult};
use crate::net::Fidelity;
use crate::output::cost::{Cost, Stopwatch};
use crate::raster::Framebuffer;
use crate::scene::{Scene, SceneError};
use crate::spec::run::{RunSpec, RunSpecError};
use crate::units::{Bytes, SimTime};

pub use error::{image_error, ImageError, SizeMismatch};
pub use reference::{render_reference, Reference, ReferenceError};

/// The option key an anti-aliasing mode is passed under.
pub const AA_OPTION: &str = "aa";
/// The machine field a fidelity is set through (as `--set machine.network.fidelity=...`).
pub const FIDELITY_KEY: &str = "machine.network.fidelity";
/// Samples per pixel side of the default reference.
pub const DEFAULT_REFERENCE_SCALE: u32 = 16;

/// An anti-aliasing mode as the algorithms' `aa` option spells it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum AaMode {
    /// One sample per pixel centre; no option is passed.
    None,
    /// Paper 000's adaptive supersampling.
    Adaptive,
    /// N samples per pixel.
    Supersample(u32),
}

impl AaMode {
    /// `none`, `adaptive`, `supersample:N`.
    pub fn name(self) -> String {
        match self {
            AaMode::None => "none".into(),
            AaMode::Adaptive => "adaptive".into(),
            AaMode::Supersample(n) => format!("supersample:{n}"),
        }
    }

    /// The value of the `aa` option, or `None` when no option is passed.
    pub fn option_value(self) -> Option<String> {
        match self {
            AaMode::None => None,
            other => Some(other.name()),
        }
    }
}

impl FromStr for AaMode {
    type Err = String;
    fn from_str(s: &str) -> Result<AaMode, String> {
        let bad = || {
            format!("unknown anti-aliasing mode '{s}'; valid: none, adaptive, supersample:N (N samples per pixel, 1..=256)")
        };
        match s.trim() {
            "none" => Ok(AaMode::None),
            "adaptive" => Ok(AaMode::Adaptive),
            t => {
                let n: u32 = t
                    .strip_prefix("supersample:")
                    .ok_or_else(bad)?
                    .parse()
                    .map_err(|_| bad())?;
                (1..=256)
                    .contains(&n)
                    .then_some(AaMode::Supersample(n))
                    .ok_or_else(bad)
            }
        }
    }
}

/// What to study.
#[derive(Clone, Debug)]
pub struct StudyConfig {
    /// The run every mode and fidelity starts from.
    pub run: RunSpec,
    pub modes: Vec<AaMode>,
    pub fidelities: Vec<Fidelity>,
    /// Samples per pixel side of the reference.
    pub reference_scale: u32,
}

/// Frame times and memory of one simulated run.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RunMeasure {
    /// Mean over the frames, floored to a picosecond.
    pub mean_frame: SimTime,
    pub last_frame: SimTime,
    /// Memory high-water mark of the busiest node, and the mean over nodes (floored).
    pub memory_max: Bytes,
    pub memory_mean: Bytes,
    pub events: u64,
}

/// One anti-aliasing mode's result.
#[derive(Clone, Debug)]
pub struct ModeResult {
    pub mode: AaMode,
    pub fidelity: Fidelity,
    pub error: ImageError,
    pub measure: RunMeasure,
    /// The last frame's image.
    pub image: Framebuffer,
    pub cost: Cost,
}

/// One fidelity's result (anti-aliasing `none`).
#[derive(Clone, Debug)]
pub struct FidelityResult {
    pub fidelity: Fidelity,
    pub measure: RunMeasure,
    pub cost: Cost,
}

/// The whole study.
#[derive(Clone)]
pub struct Study {
    /// The base run, resolved (its options without `aa`).
    pub base: RunConfig,
    /// The frame the images are compared on: the run's last.
    pub reference_frame: u32,
    pub reference: Reference,
    pub reference_cost: Cost,
    pub modes: Vec<ModeResult>,
    pub fidelities: Vec<FidelityResult>,
}

#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    #[error(transparent)]
    Spec(#[from] RunSpecError),
    #[error(transparent)]
    Scene(#[from] SceneError),
    #[error(transparent)]
    Reference(#[from] ReferenceError),
    #[error("--modes {mode}: {source}")]
    Mode { mode: String, source: RunError },
    #[error("--fidelities {fidelity}: {source}")]
    Fidelity {
        fidelity: &'static str,
        source: RunError,
    },
    #[error("comparing with the reference: {0}")]
    Size(#[from] SizeMismatch),
}

impl StudyError {
    /// The run's own error, when a run failed (for the caller to sort bad input from bugs).
    pub fn run_error(&self) -> Option<&RunError> {
        match self {
            StudyError::Mode { source, .. } | StudyError::Fidelity { source, .. } => Some(source),
            _ => None,
        }
    }
}

/// Runs the study; `progress` hears one line per finished step.
pub fn run_study(cfg: &StudyConfig, progress: &mut dyn FnMut(&str)) -> Result<Study, StudyError> {
    let scene = Arc::new(Scene::load(&cfg.run.scene)?);
    let base = cfg.run.resolve(Some(scene.clone()))?;
    let modes = resolve_modes(cfg, &scene)?;
    let fidelities = resolve_fidelities(cfg, &scene)?;
    let reference_frame = base.frames.end - 1;
    let clock = Stopwatch::start();
    let reference = render_reference(&scene.frame(reference_frame)?, cfg.reference_scale)?;
    let reference_cost = clock.cost(0);
    progress(&format!(
        "reference: frame {reference_frame} at {0}x{0} samples per pixel in {1:.2} s",
        cfg.reference_scale, reference_cost.wall_s
    ));
    let levels = reference.levels();
    let mut mode_results = Vec::new();
    for (mode, run_cfg) in modes {
        let r = run_mode(mode, &run_cfg, &levels)?;
        progress(&format!(
            "mode {}: error {:.3} levels, frame {}, {:.2} s wall",
            mode.name(),
            r.error.mae_levels,
            r.measure.mean_frame,
            r.cost.wall_s
        ));
        mode_results.push(r);
    }
    let mut fidelity_results = Vec::new();
    for (fidelity, run_cfg) in fidelities {
        let r = run_fidelity(fidelity, &run_cfg, &mode_results)?;
        progress(&format!(
            "fidelity {}: frame {}, {:.2} s wall",
            fidelity.name(),
            r.measure.mean_frame,
            r.cost.wall_s
        ));
        fidelity_results.push(r);
    }
    Ok(Study {
        base,
        reference_frame,
        reference,
        reference_cost,
        modes: mode_results,
        fidelities: fidelity_results,
    })
}

/// Resolves and checks one config per mode, before anything runs. A mode's `aa` replaces
/// any `aa` the user set; `none` removes it.
fn resolve_modes(
    cfg: &StudyConfig,
    scene: &Arc<Scene>,
) -> Result<Vec<(AaMode, RunConfig)>, StudyError> {
    cfg.modes
        .iter()
        .map(|&mode| {
            let mut spec = cfg.run.clone();
            match mode.option_value() {
                Some(v) => spec.set.insert(AA_OPTION.to_string(), v),
                None => spec.set.remove(AA_OPTION),
            };
            let run_cfg = spec.resolve(Some(scene.clone()))?;
            check_options(&run_cfg).map_err(|source| StudyError::Mode {
                mode: mode.name(),
                source,
            })?;
            Ok((mode, run_cfg))
        })
        .collect()
}

/// Resolves and checks one config per fidelity (anti-aliasing `none`: any `aa` the user set
/// is removed), before anything runs.
fn resolve_fidelities(
    cfg: &StudyConfig,
    scene: &Arc<Scene>,
) -> Result<Vec<(Fidelity, RunConfig)>, StudyError> {
    cfg.fidelities
        .iter()
        .map(|&fidelity| {
            let mut spec = cfg.run.clone();
            spec.set
                .insert(FIDELITY_KEY.to_string(), fidelity.name().to_string());
            spec.set.remove(AA_OPTION);
            let run_cfg = spec.resolve(Some(scene.clone()))?;
            check_options(&run_cfg).map_err(|source| StudyError::Fidelity {
                fidelity: fidelity.name(),
                source,
            })?;
            Ok((fidelity, run_cfg))
        })
        .collect()
}

fn run_mode(
    mode: AaMode,
    cfg: &RunConfig,
    reference: &[[f64; 3]],
) -> Result<ModeResult, StudyError> {
    let clock = Stopwatch::start();
    let result = crate::algo::run(cfg).map_err(|source| StudyError::Mode {
        mode: mode.name(),
        source,
    })?;
    let cost = clock.cost(result.stats.events);
    let error = image_error(result.image.colors(), reference)?;
    Ok(ModeResult {
        mode,
        fidelity: cfg.machine.network.fidelity,
        error,
        measure: measure(&result),
        image: result.image,
        cost,
    })
}

/// A fidelity's run; the `none` mode's run is reused when it already ran at that fidelity
/// with the same options.
fn run_fidelity(
    fidelity: Fidelity,
    cfg: &RunConfig,
    modes: &[ModeResult],
) -> Result<FidelityResult, StudyError> {
    if let Some(m) = modes
        .iter()
        .find(|m| m.mode == AaMode::None && m.fidelity == fidelity)
    {
        return Ok(FidelityResult {
            fidelity,
            measure: m.measure.clone(),
            cost: m.cost.clone(),
        });
    }
    let clock = Stopwatch::start();
    let result = crate::algo::run(cfg).map_err(|source| StudyError::Fidelity {
        fidelity: fidelity.name(),
        source,
    })?;
    Ok(FidelityResult {
        fidelity,
        cost: clock.cost(result.stats.events),
        measure: measure(&result),
    })
}

/// Frame times and memory high-water marks of a finished run.
pub fn measure(result: &RunResult) -> RunMeasure {
    let frames = result.frames.len().max(1) as u64;
    let total: u128 = result.frames.iter().map(|f| f.time().ps() as u128).sum();
    let marks: Vec<u64> = result
        .stats
        .memory
        .iter()
        .map(|p| p.high_water.get())
        .collect();
    let nodes = marks.len().max(1) as u64;
    RunMeasure {
        mean_frame: SimTime::from_ps((total / frames as u128) as u64),
        last_frame: result.frames.last().map_or(SimTime::ZERO, |f| f.time()),
        memory_max: Bytes::new(marks.iter().copied().max().unwrap_or(0)),
        memory_mean: Bytes::new(marks.iter().sum::<u64>() / nodes),
        events: result.stats.events,
    }
}

/// The base run's options as a sorted map (for reports), without `aa`: each mode says its
/// own.
pub fn base_options(study: &Study) -> BTreeMap<String, String> {
    study
        .base
        .options
        .pairs()
        .filter(|(k, _)| k.as_str() != AA_OPTION)
        .map(|(k, v)| (k.clone(), v.clone()))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn modes_parse_and_print_the_same() {
        for text in ["none", "adaptive", "supersample:16", "supersample:4"] {
            let m: AaMode = text.parse().unwrap();
            assert_eq!(m.name(), text);
        }
        assert_eq!(AaMode::None.option_value(), None);
        assert_eq!(
            AaMode::Supersample(16).option_value().as_deref(),
            Some("supersample:16")
        );
        for bad in [
            "fxaa",
            "supersample:0",
            "supersample:x",
            "supersample:",
            "super",
        ] {
            let e = bad.parse::<AaMode>().unwrap_err();
            assert!(
                e.contains(bad) && e.contains("valid: none, adaptive"),
                "{e}"
            );
        }
    }
}
