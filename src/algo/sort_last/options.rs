//! The options of the sort-last algorithms, one struct per algorithm (three share one: they
//! take only the primitive assignment). The doc comment of a field is its help, its serde
//! default the default.
//!
//! Owns the option names, types and defaults. Must never check them against a machine (that
//! is `settings`).

use crate::algo::options::{choice_option, count_option, string_option, OnOff};

choice_option!(
    /// How primitives are dealt to processors.
    AssignRule {
        /// Round-robin in database order (paper 001's scattering).
        Scatter = "scatter",
        /// Each primitive to a processor drawn from a seeded stream.
        Random = "random",
        /// Scatter, but the largest primitive last (paper 003's advice for backgrounds).
        BackgroundLast = "background-last",
        /// Object-space blocks by recursive bisection of the primitives' centroids, as a
        /// volume renderer deals its data: each processor draws one compact part of the scene.
        Blocks = "blocks",
        /// Paper 001's request-based dynamic load balancing (sort-last/df and pc only).
        Request = "request",
    }
);

choice_option!(
    /// How the compositing variants ship image pieces.
    ImageEncoding {
        /// Every position of a piece, rgb and z.
        Dense = "dense",
        /// IceT's sparse image: runs of inactive and active positions, active pixels only.
        Rle = "rle",
    }
);

choice_option!(
    /// How the swapping composites cut the image into pieces.
    Pieces {
        /// Contiguous ranges of positions in raster order.
        Contiguous = "contiguous",
        /// IceT's interlaced images, by rows: piece j of K gets rows y = j mod K.
        Interleaved = "interleaved",
    }
);

count_option!(
    /// Request balancing's splitting factor.
    SplitFactor,
    min = 2,
    what = "a splitting factor of at least 2"
);

count_option!(
    /// A packet of primitives.
    Primitives,
    min = 1,
    what = "a whole number of primitives, at least 1"
);

count_option!(
    /// Scanlines per pipeline message.
    Scanlines,
    min = 1,
    what = "a whole number of scanlines, at least 1"
);

/// Radix-k's group sizes, one per round: `auto`, or a list such as `4,4,2` (each at least 2)
/// whose product must be the number of processors.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Radices {
    /// Rounds of 8 where possible (see `radix_k::default_radices`).
    Auto,
    Given(Vec<u32>),
}

impl std::str::FromStr for Radices {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        if s == "auto" {
            return Ok(Radices::Auto);
        }
        s.split(',')
            .map(|k| k.trim().parse::<u32>().ok().filter(|&k| k >= 2))
            .collect::<Option<Vec<u32>>>()
            .map(Radices::Given)
            .ok_or_else(|| "expected auto or group sizes of at least 2, e.g. 4,4,2".to_string())
    }
}

impl std::fmt::Display for Radices {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Radices::Auto => write!(f, "auto"),
            Radices::Given(k) => {
                let k: Vec<String> = k.iter().map(u32::to_string).collect();
                write!(f, "{}", k.join(","))
            }
        }
    }
}

string_option!(Radices);

impl schemars::JsonSchema for Radices {
    fn schema_name() -> std::borrow::Cow<'static, str> {
        "Radices".into()
    }
    fn json_schema(_: &mut schemars::SchemaGenerator) -> schemars::Schema {
        schemars::json_schema!({
            "type": "string",
            "pattern": "^(auto|[0-9]+(,[0-9]+)*)$",
            "description": "auto, or group sizes of at least 2 whose product is the number of processors, e.g. 4,4,2",
        })
    }
}

fn scatter() -> AssignRule {
    AssignRule::Scatter
}
/// Paper 001 names a splitting factor but not its value. Against Table 1's Gears and Mountain
/// imbalances with balancing on (2 to 16 nodes, `sweeps/p001-table1-split.json`), 4 deviates
/// least of 2, 3, 4, 6 and 8: the node left holding a large primitive's leftovers hands out
/// quarters, which reach idle nodes sooner over the slow links than halves.
fn split_in_four() -> SplitFactor {
    SplitFactor(4)
}
fn sixteen() -> Primitives {
    Primitives(16)
}
fn one_row() -> Scanlines {
    Scanlines(1)
}
fn off() -> OnOff {
    OnOff::Off
}

fn on() -> OnOff {
    OnOff::On
}

/// sort-last/pc (paper 001's Pipeline Composition).
#[derive(Clone, Debug, serde::Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub struct PcOptions {
    /// How primitives are dealt: scatter, random, background-last, blocks or request (paper 001's
    /// request-based dynamic load balancing).
    #[serde(default = "scatter")]
    pub assign: AssignRule,
    /// Request balancing: a donor splits its remaining work into this many parts.
    #[serde(default = "split_in_four")]
    pub split: SplitFactor,
    /// Request balancing: the smallest packet of primitives worth giving away.
    #[serde(default = "sixteen")]
    pub min_packet: Primitives,
    /// Scanlines per message through the pipeline.
    #[serde(default = "one_row")]
    pub chunk_rows: Scanlines,
}

/// sort-last/df (paper 001's Distributed Framebuffer).
#[derive(Clone, Debug, serde::Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub struct DfOptions {
    /// How primitives are dealt: scatter, random, background-last, blocks or request (paper 001's
    /// request-based dynamic load balancing).
    #[serde(default = "scatter")]
    pub assign: AssignRule,
    /// Request balancing: a donor splits its remaining work into this many parts.
    #[serde(default = "split_in_four")]
    pub split: SplitFactor,
    /// Request balancing: the smallest packet of primitives worth giving away.
    #[serde(default = "sixteen")]
    pub min_packet: Primitives,
}

/// sort-last/tree (IceT's reduce tree).
#[derive(Clone, Debug, serde::Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub struct CompositeOptions {
    /// How primitives are dealt: scatter, random, background-last, blocks or request (paper 001's
    /// request-based dynamic load balancing).
    #[serde(default = "scatter")]
    pub assign: AssignRule,
    /// Request balancing: a donor splits its remaining work into this many parts.
    #[serde(default = "split_in_four")]
    pub split: SplitFactor,
    /// Request balancing: the smallest packet of primitives worth giving away.
    #[serde(default = "sixteen")]
    pub min_packet: Primitives,
    /// How image pieces travel: dense (every position) or rle (IceT's run-length sparse
    /// image, charged per position scanned and per run).
    #[serde(default = "dense")]
    pub image: ImageEncoding,
    /// IceT's bounding boxes (with image=rle): a node clears, holds and scans only the
    /// rectangle of the screen it drew (after merging, the rectangle around what it holds);
    /// positions outside it go as one inactive run, never looked at.
    #[serde(default = "off")]
    pub bounds: OnOff,
}

fn dense() -> ImageEncoding {
    ImageEncoding::Dense
}

fn contiguous() -> Pieces {
    Pieces::Contiguous
}

/// sort-last/binary-swap (Ma et al. 1994) and sort-last/2-3-swap (Yu, Wang, Ma 2008).
#[derive(Clone, Debug, serde::Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub struct SwapOptions {
    /// How primitives are dealt: scatter, random, background-last, blocks or request (paper 001's
    /// request-based dynamic load balancing).
    #[serde(default = "scatter")]
    pub assign: AssignRule,
    /// Request balancing: a donor splits its remaining work into this many parts.
    #[serde(default = "split_in_four")]
    pub split: SplitFactor,
    /// Request balancing: the smallest packet of primitives worth giving away.
    #[serde(default = "sixteen")]
    pub min_packet: Primitives,
    /// How image pieces travel: dense (every position) or rle (IceT's run-length sparse
    /// image, charged per position scanned and per run).
    #[serde(default = "dense")]
    pub image: ImageEncoding,
    /// IceT's bounding boxes (with image=rle): a node clears, holds and scans only the
    /// rectangle of the screen it drew (after merging, the rectangle around what it holds);
    /// positions outside it go as one inactive run, never looked at.
    #[serde(default = "off")]
    pub bounds: OnOff,
    /// How the image is cut: contiguous ranges in raster order, or interleaved rows (IceT's
    /// interlaced images: each piece gets rows from the whole screen, for balance).
    #[serde(default = "contiguous")]
    pub pieces: Pieces,
    /// Whether the frame ends with every piece sent to node 0 (on), or with the composited
    /// image left in pieces, one per node, as compositing benchmarks time it (off: one frame,
    /// contiguous pieces; the report's image is put together outside the simulation).
    #[serde(default = "on")]
    pub gather: OnOff,
}

/// sort-last/radix-k (Peterka, Goodell, Ross, Shen, Thakur 2009).
#[derive(Clone, Debug, serde::Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub struct RadixKOptions {
    /// How primitives are dealt: scatter, random, background-last, blocks or request (paper 001's
    /// request-based dynamic load balancing).
    #[serde(default = "scatter")]
    pub assign: AssignRule,
    /// Request balancing: a donor splits its remaining work into this many parts.
    #[serde(default = "split_in_four")]
    pub split: SplitFactor,
    /// Request balancing: the smallest packet of primitives worth giving away.
    #[serde(default = "sixteen")]
    pub min_packet: Primitives,
    /// Group size of each round; their product is the number of processors. `auto`: rounds
    /// of 8 while 8 divides what is left, then the largest divisor up to 8.
    #[serde(default = "auto_radices")]
    pub k: Radices,
    /// How image pieces travel: dense (every position) or rle (IceT's run-length sparse
    /// image, charged per position scanned and per run).
    #[serde(default = "dense")]
    pub image: ImageEncoding,
    /// IceT's bounding boxes (with image=rle): a node clears, holds and scans only the
    /// rectangle of the screen it drew (after merging, the rectangle around what it holds);
    /// positions outside it go as one inactive run, never looked at.
    #[serde(default = "off")]
    pub bounds: OnOff,
    /// How the image is cut: contiguous ranges in raster order, or interleaved rows (IceT's
    /// interlaced images: each piece gets rows from the whole screen, for balance).
    #[serde(default = "contiguous")]
    pub pieces: Pieces,
    /// Whether the frame ends with every piece sent to node 0 (on), or with the composited
    /// image left in pieces, one per node, as compositing benchmarks time it (off: one frame,
    /// contiguous pieces; the report's image is put together outside the simulation).
    #[serde(default = "on")]
    pub gather: OnOff,
}

fn auto_radices() -> Radices {
    Radices::Auto
}

/// sort-last/direct-send (paper 003).
#[derive(Clone, Debug, serde::Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub struct DirectSendOptions {
    /// How primitives are dealt: scatter, random, background-last or blocks.
    #[serde(default = "scatter")]
    pub assign: AssignRule,
    /// Z-buffer locally first and send only the active pixels.
    #[serde(default = "off")]
    pub local_zbuffer: OnOff,
    /// With a local z-buffer, how a node's pixels for an owner travel: dense (each with its
    /// address) or rle (runs of the owner's rows, one header per run, no addresses).
    #[serde(default = "dense")]
    pub image: ImageEncoding,
}

/// sort-last/scanline-flow (paper 001), sort-last/pixelflow and sort-last/snooping (paper
/// 003): only the assignment.
#[derive(Clone, Debug, serde::Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub struct DealOptions {
    /// How primitives are dealt: scatter, random, background-last or blocks.
    #[serde(default = "scatter")]
    pub assign: AssignRule,
}
