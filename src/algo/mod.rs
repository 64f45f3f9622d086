//! Parallel rendering algorithms, one module per family, each reading like its paper's
//! pseudocode: node programs that compute, send and receive through the engine's `Node`.
//!
//! Owns the algorithm ids of the command line, their options (`--set key=value`), and the
//! record of what each frame took. Must never name a concrete topology (an algorithm states
//! what it needs, e.g. a broadcast medium, and asks the network), never read the clock except
//! through `Node::now`, and never invent a time: every duration is charged from counts.

pub mod aa;
mod ahead;
pub mod charge;
mod frames;
pub mod image_space;
pub mod options;
pub mod primitives;
pub mod reference;
mod routes;
pub mod sort_first;
pub mod sort_last;
pub mod sort_middle;

use std::ops::Range;
use std::sync::Arc;

use schemars::JsonSchema;
use serde::de::DeserializeOwned;

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

/// Something done with an algorithm's options struct, whichever it is
/// ([`AlgorithmId::with_options_struct`]): parsing, documenting, describing as a schema.
trait OptionsUse {
    type Out;
    fn with<T: DeserializeOwned + JsonSchema>(self) -> Self::Out;
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
            AlgorithmId::SortMiddleStatic => Family::Middle(M::Static),
            AlgorithmId::SortMiddleEllsworth => Family::Middle(M::Ellsworth),
            AlgorithmId::SortLastDf => Family::Last(L::Df),
            AlgorithmId::SortLastPc => Family::Last(L::Pc),
            AlgorithmId::SortLastScanlineFlow => Family::Last(L::ScanlineFlow),
            AlgorithmId::SortLastPixelFlow => Family::Last(L::PixelFlow),
            AlgorithmId::SortLastDirectSend => Family::Last(L::DirectSend),
            AlgorithmId::SortLastSnooping => Family::Last(L::Snooping),
            AlgorithmId::SortLastTree => Family::Last(L::Tree),
            AlgorithmId::SortLastBinarySwap => Family::Last(L::BinarySwap),
            AlgorithmId::SortLastRadixK => Family::Last(L::RadixK),
            AlgorithmId::SortLastTwoThreeSwap => Family::Last(L::TwoThreeSwap),
            AlgorithmId::SortFirstMueller => Family::First,
        }
    }

    pub fn from_id(id: &str) -> Option<AlgorithmId> {
        AlgorithmId::ALL.into_iter().find(|a| a.id() == id)
    }

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
        struct Check<'a>(&'a Options, &'static str);
        impl OptionsUse for Check<'_> {
            type Out = Result<(), OptionError>;
            fn with<T: DeserializeOwned + JsonSchema>(self) -> Self::Out {
                options::parse::<T>(self.0, self.1).map(drop)
            }
        }
        self.with_options_struct(Check(o, self.id()))
    }

    /// The options of this algorithm's own struct, without the anti-aliasing ones.
    fn own_option_docs(self) -> Vec<options::OptionDoc> {
        struct Docs;
        impl OptionsUse for Docs {
            type Out = Vec<options::OptionDoc>;
            fn with<T: DeserializeOwned + JsonSchema>(self) -> Self::Out {
                options::docs::<T>()
            }
        }
        self.with_options_struct(Docs)
    }

    /// `what`, done with this algorithm's options struct: the one place that says which
    /// struct an algorithm reads its options into.
    fn with_options_struct<U: OptionsUse>(self, what: U) -> U::Out {
        match self {
            AlgorithmId::SortMiddleStatic => what.with::<sort_middle::StaticOptions>(),
            AlgorithmId::SortMiddleEllsworth => what.with::<sort_middle::EllsworthOptions>(),
            AlgorithmId::SortFirstMueller => what.with::<sort_first::SortFirstOptions>(),
            AlgorithmId::SortLastDf => what.with::<sort_last::DfOptions>(),
            AlgorithmId::SortLastTree => what.with::<sort_last::CompositeOptions>(),
            AlgorithmId::SortLastBinarySwap | AlgorithmId::SortLastTwoThreeSwap => {
                what.with::<sort_last::SwapOptions>()
            }
            AlgorithmId::SortLastRadixK => what.with::<sort_last::RadixKOptions>(),
            AlgorithmId::SortLastPc => what.with::<sort_last::PcOptions>(),
            AlgorithmId::SortLastDirectSend => what.with::<sort_last::DirectSendOptions>(),
            AlgorithmId::SortLastScanlineFlow
            | AlgorithmId::SortLastPixelFlow
            | AlgorithmId::SortLastSnooping => what.with::<sort_last::DealOptions>(),
        }
    }

    /// The JSON Schema of this algorithm's options (its struct's properties and the
    /// anti-aliasing ones).
    pub fn options_schema(self) -> serde_json::Value {
        use schemars::schema_for;
        struct Schema;
        impl OptionsUse for Schema {
            type Out = serde_json::Value;
            fn with<T: DeserializeOwned + JsonSchema>(self) -> Self::Out {
                schema_for!(T).to_value()
            }
        }
        let mut own = self.with_options_struct(Schema);
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

    /// The valid ids as `--help` prints them (a test keeps this equal to [`AlgorithmId::ALL`]).
    pub const IDS_HELP: &'static str = "Algorithm id: sort-middle/static, sort-middle/ellsworth, \
        sort-last/df, sort-last/pc, sort-last/scanline-flow, sort-last/pixelflow, \
        sort-last/direct-send, sort-last/snooping, sort-last/tree, sort-last/binary-swap, \
        sort-last/radix-k, sort-last/2-3-swap, sort-first/mueller";

    /// The valid ids, for error messages.
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
    /// Record the timeline only from the start of the first of these frames to the start of
    /// the frame after the last (all of the run when `None`), so that a long run's timeline
    /// costs the memory of a few frames.
    pub timeline_frames: Option<Range<u32>>,
    /// Make the later frames' front end (geometry, prepared vertices, sort-middle's dealt
    /// shares) on a second host thread while the simulation runs (`ahead`). It changes no
    /// answer, only the run's wall time; off, the simulation's thread makes every frame.
    pub front_end_ahead: bool,
    /// Queue a wake-up for the end of every slice of a time-sliced cpu and poll its program
    /// there, instead of letting the executor reserve a lone computation's slices
    /// (`engine::Sim::wake_every_slice`): the plain way, kept as the oracle of the tests. It
    /// changes no answer, only the run's wall time.
    pub wake_every_slice: bool,
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
    /// Per node, how long its rasterizer waited for polygon messages to arrive (paper 002's
    /// "waiting for polygons to arrive"): the time from asking for the next message to its
    /// arrival, summed; zero for algorithms that do not rasterize streams of polygons.
    pub polygon_wait: Vec<SimTime>,
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
    if cfg.wake_every_slice {
        sim.wake_every_slice();
    }
    if cfg.timeline {
        sim.record_timeline();
        // A timeline of later frames starts paused; the frames' beginnings resume it.
        if let Some(covered) = &cfg.timeline_frames {
            sim.pause_timeline(covered.start > cfg.frames.start);
        }
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
    Middle(sort_middle::Variant),
    Last(sort_last::Variant),
    First,
}

/// Checks `cfg`'s options (and that the machine offers what the algorithm needs) as a run
/// would, without running it.
pub fn check_options(cfg: &RunConfig) -> Result<(), RunError> {
    match cfg.algo.family() {
        Family::Middle(v) => sort_middle::check(cfg, v),
        Family::Last(v) => sort_last::check(cfg, v),
        Family::First => sort_first::check(cfg),
    }
}

/// Runs `cfg` to the end of its last frame.
pub fn run(cfg: &RunConfig) -> Result<RunResult, RunError> {
    match cfg.algo.family() {
        Family::Middle(v) => sort_middle::run(cfg, v),
        Family::Last(v) => sort_last::run(cfg, v),
        Family::First => sort_first::run(cfg),
    }
}

#[cfg(test)]
mod ids_help_tests {
    #[test]
    fn the_help_lists_every_algorithm_id() {
        let listed = super::AlgorithmId::IDS_HELP
            .trim_start_matches("Algorithm id: ")
            .replace(char::is_whitespace, "");
        assert_eq!(listed, super::AlgorithmId::valid_ids().replace(' ', ""));
    }
}
