//! Parallel rendering algorithms, one module per family, each reading like its paper's
//! pseudocode: node programs that compute, send and receive through the engine's `Node`.
//!
//! Owns the algorithm ids of the command line, their options (`--set key=value`), and the
//! record of what each frame took. Must never name a concrete topology (an algorithm states
//! what it needs, e.g. a broadcast medium, and asks the network), never read the clock except
//! through `Node::now`, and never invent a time: every duration is charged from counts.

pub mod aa;
pub mod charge;
mod frames;
pub mod options;
pub mod primitives;
pub mod reference;
pub mod sort_first;
pub mod sort_last;
pub mod sort_middle;

use std::ops::Range;
use std::sync::Arc;

use crate::engine::RunStats;
use crate::machine::MachineConfig;
use crate::raster::aa::AaStats;
use crate::raster::Framebuffer;
use crate::scene::Scene;
use crate::units::{Bytes, SimTime};

pub use options::{OptionError, Options};

/// The algorithms, by command-line id.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum AlgorithmId {
    /// Paper 000: static interleaved 64x64 regions, a root collects the image.
    SortMiddleStatic,
    /// Paper 002: Ellsworth's frame-coherent load balancing.
    SortMiddleEllsworth,
    /// Paper 001: SLML-full, distributed frame buffer over a torus.
    SortLastDf,
    /// Paper 001: SLML-full, pipeline composition by scanline chunks.
    SortLastPc,
    /// Paper 001: SLMF-full, the scanline z-buffer in a pipeline.
    SortLastScanlineFlow,
    /// Paper 003: SLML-full, whole frames streamed down a pipeline.
    SortLastPixelFlow,
    /// Paper 003: sparse, each pixel to the node owning its screen location.
    SortLastDirectSend,
    /// Paper 003: sparse, distributed snooping on a broadcast bus.
    SortLastSnooping,
    /// IceT's reduce tree: whole frames merged in pairs up a binary tree.
    SortLastTree,
    /// Binary swap (Ma et al. 1994): halves of the image exchanged with partners.
    SortLastBinarySwap,
    /// Radix-k (Peterka et al. 2009): direct send of image parts within groups of k.
    SortLastRadixK,
    /// 2-3 swap (Yu, Wang, Ma 2008): binary swap for any N, by groups of two or three.
    SortLastTwoThreeSwap,
    /// Sort-first (Mueller 1995): processors keep the primitives of their screen regions
    /// from frame to frame; only those crossing into other regions move.
    SortFirstMueller,
}

impl AlgorithmId {
    pub const ALL: [AlgorithmId; 13] = [
        AlgorithmId::SortMiddleStatic,
        AlgorithmId::SortMiddleEllsworth,
        AlgorithmId::SortLastDf,
        AlgorithmId::SortLastPc,
        AlgorithmId::SortLastScanlineFlow,
        AlgorithmId::SortLastPixelFlow,
        AlgorithmId::SortLastDirectSend,
        AlgorithmId::SortLastSnooping,
        AlgorithmId::SortLastTree,
        AlgorithmId::SortLastBinarySwap,
        AlgorithmId::SortLastRadixK,
        AlgorithmId::SortLastTwoThreeSwap,
        AlgorithmId::SortFirstMueller,
    ];

    pub fn id(self) -> &'static str {
        match self {
            AlgorithmId::SortMiddleStatic => "sort-middle/static",
            AlgorithmId::SortMiddleEllsworth => "sort-middle/ellsworth",
            AlgorithmId::SortLastDf => "sort-last/df",
            AlgorithmId::SortLastPc => "sort-last/pc",
            AlgorithmId::SortLastScanlineFlow => "sort-last/scanline-flow",
            AlgorithmId::SortLastPixelFlow => "sort-last/pixelflow",
            AlgorithmId::SortLastDirectSend => "sort-last/direct-send",
            AlgorithmId::SortLastSnooping => "sort-last/snooping",
            AlgorithmId::SortLastTree => "sort-last/tree",
            AlgorithmId::SortLastBinarySwap => "sort-last/binary-swap",
            AlgorithmId::SortLastRadixK => "sort-last/radix-k",
            AlgorithmId::SortLastTwoThreeSwap => "sort-last/2-3-swap",
            AlgorithmId::SortFirstMueller => "sort-first/mueller",
        }
    }

    /// The family and variant that run this id.
    fn family(self) -> Family {
        use sort_last::Variant as L;
        use sort_middle::Variant as M;
        match self {
            AlgorithmId::SortMiddleStatic => Family::SortMiddle(M::Static),
            AlgorithmId::SortMiddleEllsworth => Family::SortMiddle(M::Ellsworth),
            AlgorithmId::SortLastDf => Family::SortLast(L::Df),
            AlgorithmId::SortLastPc => Family::SortLast(L::Pc),
            AlgorithmId::SortLastScanlineFlow => Family::SortLast(L::ScanlineFlow),
            AlgorithmId::SortLastPixelFlow => Family::SortLast(L::PixelFlow),
            AlgorithmId::SortLastDirectSend => Family::SortLast(L::DirectSend),
            AlgorithmId::SortLastSnooping => Family::SortLast(L::Snooping),
            AlgorithmId::SortLastTree => Family::SortLast(L::Tree),
            AlgorithmId::SortLastBinarySwap => Family::SortLast(L::BinarySwap),
            AlgorithmId::SortLastRadixK => Family::SortLast(L::RadixK),
            AlgorithmId::SortLastTwoThreeSwap => Family::SortLast(L::TwoThreeSwap),
            // Sort-first runs on the sort-middle family's regions and rasterization stage.
            AlgorithmId::SortFirstMueller => Family::SortMiddle(M::SortFirst),
        }
    }

    pub fn from_id(id: &str) -> Option<AlgorithmId> {
        AlgorithmId::ALL.into_iter().find(|a| a.id() == id)
    }

    /// The valid ids, for error messages.
    /// The options this algorithm takes (its own, then the anti-aliasing ones), read from
    /// their structs: the same source as parsing, the schema and `--help`.
    pub fn option_docs(self) -> Vec<options::OptionDoc> {
        let mut all = self.own_option_docs();
        all.extend(options::docs::<aa::AaOptions>());
        all
    }

    /// Parses `o` as a run of this algorithm will (names and values, anti-aliasing ones
    /// included), needing neither machine nor scene, so a mistyped `--set` is reported before
    /// a large scene is built. What depends on the machine or the scene is checked later.
    pub fn check_option_values(self, o: &Options) -> Result<(), OptionError> {
        use options::parse;
        let id = self.id();
        match self {
            AlgorithmId::SortMiddleStatic => parse::<sort_middle::StaticOptions>(o, id).map(drop),
            AlgorithmId::SortMiddleEllsworth => {
                parse::<sort_middle::EllsworthOptions>(o, id).map(drop)
            }
            AlgorithmId::SortFirstMueller => parse::<sort_first::SortFirstOptions>(o, id).map(drop),
            AlgorithmId::SortLastDf => parse::<sort_last::DfOptions>(o, id).map(drop),
            AlgorithmId::SortLastTree => parse::<sort_last::CompositeOptions>(o, id).map(drop),
            AlgorithmId::SortLastBinarySwap | AlgorithmId::SortLastTwoThreeSwap => {
                parse::<sort_last::SwapOptions>(o, id).map(drop)
            }
            AlgorithmId::SortLastRadixK => parse::<sort_last::RadixKOptions>(o, id).map(drop),
            AlgorithmId::SortLastPc => parse::<sort_last::PcOptions>(o, id).map(drop),
            AlgorithmId::SortLastDirectSend => {
                parse::<sort_last::DirectSendOptions>(o, id).map(drop)
            }
            AlgorithmId::SortLastScanlineFlow
            | AlgorithmId::SortLastPixelFlow
            | AlgorithmId::SortLastSnooping => parse::<sort_last::DealOptions>(o, id).map(drop),
        }
    }

    /// The options of this algorithm's own struct, without the anti-aliasing ones.
    fn own_option_docs(self) -> Vec<options::OptionDoc> {
        use options::docs;
        match self {
            AlgorithmId::SortMiddleStatic => docs::<sort_middle::StaticOptions>(),
            AlgorithmId::SortMiddleEllsworth => docs::<sort_middle::EllsworthOptions>(),
            AlgorithmId::SortFirstMueller => docs::<sort_first::SortFirstOptions>(),
            AlgorithmId::SortLastDf => docs::<sort_last::DfOptions>(),
            AlgorithmId::SortLastTree => docs::<sort_last::CompositeOptions>(),
            AlgorithmId::SortLastBinarySwap | AlgorithmId::SortLastTwoThreeSwap => {
                docs::<sort_last::SwapOptions>()
            }
            AlgorithmId::SortLastRadixK => docs::<sort_last::RadixKOptions>(),
            AlgorithmId::SortLastPc => docs::<sort_last::PcOptions>(),
            AlgorithmId::SortLastDirectSend => docs::<sort_last::DirectSendOptions>(),
            AlgorithmId::SortLastScanlineFlow
            | AlgorithmId::SortLastPixelFlow
            | AlgorithmId::SortLastSnooping => docs::<sort_last::DealOptions>(),
        }
    }

    /// The JSON Schema of this algorithm's options (its struct's properties and the
    /// anti-aliasing ones).
    pub fn options_schema(self) -> serde_json::Value {
        use schemars::schema_for;
        let own = match self {
            AlgorithmId::SortMiddleStatic => schema_for!(sort_middle::StaticOptions),
            AlgorithmId::SortMiddleEllsworth => schema_for!(sort_middle::EllsworthOptions),
            AlgorithmId::SortFirstMueller => schema_for!(sort_first::SortFirstOptions),
            AlgorithmId::SortLastDf => schema_for!(sort_last::DfOptions),
            AlgorithmId::SortLastTree => schema_for!(sort_last::CompositeOptions),
            AlgorithmId::SortLastBinarySwap | AlgorithmId::SortLastTwoThreeSwap => {
                schema_for!(sort_last::SwapOptions)
            }
            AlgorithmId::SortLastRadixK => schema_for!(sort_last::RadixKOptions),
            AlgorithmId::SortLastPc => schema_for!(sort_last::PcOptions),
            AlgorithmId::SortLastDirectSend => schema_for!(sort_last::DirectSendOptions),
            AlgorithmId::SortLastScanlineFlow
            | AlgorithmId::SortLastPixelFlow
            | AlgorithmId::SortLastSnooping => schema_for!(sort_last::DealOptions),
        };
        let mut own = own.to_value();
        let aa = schema_for!(aa::AaOptions).to_value();
        for key in ["properties", "$defs"] {
            if let (Some(into), Some(from)) = (
                own.get_mut(key).and_then(|v| v.as_object_mut()),
                aa.get(key).and_then(|v| v.as_object()),
            ) {
                into.extend(from.clone());
            } else if let Some(from) = aa.get(key) {
                own[key] = from.clone();
            }
        }
        own["title"] = self.id().into();
        own["additionalProperties"] = false.into();
        own
    }

    /// Every algorithm's options as `--help` prints them.
    pub fn options_help() -> String {
        let mut text = String::from(
            "Algorithm options (--set KEY=VALUE, or a run spec's \"set\"), with their defaults:\n",
        );
        for a in AlgorithmId::ALL {
            text.push_str(&format!("  {}\n", a.id()));
            text.push_str(&options::help_lines(&a.own_option_docs()));
        }
        text.push_str("  every algorithm (anti-aliasing)\n");
        text.push_str(&options::help_lines(&options::docs::<aa::AaOptions>()));
        text
    }

    pub fn valid_ids() -> String {
        AlgorithmId::ALL
            .iter()
            .map(|a| a.id())
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// Everything one simulated run needs, validated.
#[derive(Clone)]
pub struct RunConfig {
    /// The machine, already sized to the number of processors the run uses.
    pub machine: MachineConfig,
    pub scene: Arc<Scene>,
    pub algo: AlgorithmId,
    pub frames: Range<u32>,
    pub options: Options,
    pub seed: u64,
    /// Record every cpu span for a timeline (costs host memory).
    pub timeline: bool,
}

/// What one frame took.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct FrameRecord {
    pub frame: u32,
    pub start: SimTime,
    /// `start` is set: the frame has begun at the node that times frames.
    pub begun: bool,
    pub end: SimTime,
    /// Triangles that survived culling and clipping (the papers' "triangles in view").
    pub triangles_in_view: u64,
    /// Bytes and messages that crossed the network during the frame.
    pub bytes: Bytes,
    pub messages: u64,
    /// When each node finished rasterizing (paper 001's load imbalance uses these).
    pub raster_finish: Vec<SimTime>,
    /// Sort-first: database records sent to processors that did not hold them.
    pub records_moved: Option<u64>,
    /// Per node, what anti-aliasing did this frame (supersampled, reclaimed and overflowed
    /// pixels, the subpixel resolution used, memory); empty when anti-aliasing is off.
    pub aa: Vec<AaStats>,
}

impl FrameRecord {
    pub fn time(&self) -> SimTime {
        self.end - self.start
    }

    /// (longest finishing time - mean) / longest, in percent (paper 001's definition), with
    /// times measured from the frame's start.
    pub fn load_imbalance_pct(&self) -> f64 {
        let times: Vec<f64> = self
            .raster_finish
            .iter()
            .map(|&t| t.saturating_sub(self.start).as_secs_f64())
            .collect();
        load_imbalance_pct(&times)
    }
}

/// Paper 001's load imbalance of some finishing times: (longest - mean) / longest, in
/// percent; 0 when nothing took any time.
pub fn load_imbalance_pct(finishes: &[f64]) -> f64 {
    let longest = finishes.iter().cloned().fold(0.0, f64::max);
    if longest <= 0.0 {
        return 0.0;
    }
    let mean = finishes.iter().sum::<f64>() / finishes.len() as f64;
    100.0 * (longest - mean) / longest
}

/// What a run produced: the machine's statistics, per-frame records, the last frame's image.
pub struct RunResult {
    pub stats: RunStats,
    pub frames: Vec<FrameRecord>,
    pub image: Framebuffer,
}

#[derive(Debug, thiserror::Error)]
pub enum RunError {
    #[error(transparent)]
    Option(#[from] OptionError),
    #[error(transparent)]
    Sim(#[from] crate::engine::SimError),
    #[error(transparent)]
    Scene(#[from] crate::scene::SceneError),
    #[error("{0}")]
    Unsupported(String),
}

/// The error for option `key` whose value is not `what` the algorithm expects.
pub(crate) fn bad_option(o: &Options, key: &str, what: &str) -> RunError {
    let value = o
        .pairs()
        .find(|(k, _)| *k == key)
        .map(|(_, v)| v.clone())
        .unwrap_or_default();
    RunError::Option(OptionError::Invalid {
        key: key.into(),
        value,
        message: format!("expected {what}"),
    })
}

/// Runs one program per processor, `program(node, ctx)`, on a fresh simulation of `cfg`'s
/// machine, to the end.
pub(crate) fn simulate<M, C, F, Fut>(
    cfg: &RunConfig,
    ctx: &std::rc::Rc<C>,
    program: F,
) -> Result<RunStats, RunError>
where
    M: crate::engine::Payload,
    F: Fn(crate::engine::Node<M>, std::rc::Rc<C>) -> Fut,
    Fut: std::future::Future<Output = Result<(), crate::engine::SimError>> + 'static,
{
    let mut sim: crate::engine::Sim<M> = crate::engine::Sim::new(&cfg.machine, cfg.seed)
        .map_err(|e| RunError::Unsupported(e.to_string()))?;
    if cfg.timeline {
        sim.record_timeline();
    }
    for p in 0..cfg.machine.nodes {
        sim.spawn(
            p,
            format!("processor {p}"),
            program(sim.node(p), ctx.clone()),
        );
    }
    Ok(sim.run()?)
}

/// Where an algorithm sorts, and which of its family's variants it is.
enum Family {
    SortMiddle(sort_middle::Variant),
    SortLast(sort_last::Variant),
}

/// Checks `cfg`'s options (and that the machine offers what the algorithm needs) as a run
/// would, without running it.
pub fn check_options(cfg: &RunConfig) -> Result<(), RunError> {
    match cfg.algo.family() {
        Family::SortMiddle(v) => sort_middle::check(cfg, v),
        Family::SortLast(v) => sort_last::check(cfg, v),
    }
}

/// Runs `cfg` to the end of its last frame.
pub fn run(cfg: &RunConfig) -> Result<RunResult, RunError> {
    match cfg.algo.family() {
        Family::SortMiddle(v) => sort_middle::run(cfg, v),
        Family::SortLast(v) => sort_last::run(cfg, v),
    }
}
