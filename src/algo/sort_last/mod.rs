//! Sort-last rendering: every processor renders whole primitives of its own share of the
//! database into a local frame, and the frames are merged by depth over the network.
//!
//! Ten variants, one module each, reading like their papers:
//! * full-frame, merging after rendering (paper 001's SLML-full): `df` (distributed frame
//!   buffer over a torus), `pc` (pipeline composition by scanline chunks);
//! * full-frame, merging during rendering (SLMF-full): `scanline_flow`;
//! * paper 003's merges: `pixelflow` (whole frames down a pipeline), `direct_send` (each
//!   pixel to the node owning its screen location), `snooping` (broadcast on a bus, listeners
//!   delete what the broadcast hides);
//! * beyond the papers, the compositing IceT uses: `tree` (whole frames merged in pairs up a
//!   binary tree), `binary_swap` (halves of the image exchanged with partners, then
//!   gathered), `radix_k` (direct send of image parts within groups of k, round by round),
//!   `two_three_swap` (binary swap for any N, by groups of two or three).
//!
//! The mechanisms they share live beside them: `pixel` (the pixel a merge ships: an ordinary
//! active pixel, or with `aa=adaptive` a pixel of paper 000's adaptive buffer carrying its
//! Subpixels), `local` (a node renders its share into that pixel's buffer, charged as the
//! machine would be), `aa` (each node's Subpixel pool and the frame's grid), primitive
//! assignment in [`crate::algo::primitives`], request-based load balancing in `request`.
//!
//! Full frames are charged, not held: a node's simulated memory holds a 512x512 colour and
//! z frame, and merges are charged for every pixel they move, but the host keeps only each
//! node's active pixels, so a 64-node run does not need 64 full frame buffers.
//!
//! Must never name a topology: a variant states what it needs (node i linked to node i+1, a
//! broadcast medium) and `requirements` asks the network.

mod aa;
mod binary_swap;
mod bounds;
mod composite;
mod df;
mod direct_send;
mod full_frame;
mod image;
mod interlace;
mod local;
pub mod options;
mod pc;
mod pixel;
mod pixelflow;
mod radix_k;
mod request;
mod scanline_flow;
mod snooping;
mod sparse;
mod tree;
mod two_three_swap;

use std::cell::RefCell;
use std::rc::Rc;

use super::aa::{aa_settings, check_prices, AaSettings};
use super::frames::FrameBook;
use super::options::parse;
use super::primitives::{deal, shares, Deal};
use super::{bad_option as bad, simulate, RunConfig, RunError, RunResult};
use crate::engine::{Node, Payload, SimError};
use crate::machine::{Counts, Op};
use crate::raster::aa::{downsample, AaMethod, PIXEL_BYTES};
use crate::raster::{Framebuffer, RasterOptions, ScreenRect, VertexCache, Viewport};
use crate::scene::FrameGeometry;
use crate::units::Bytes;
use options::{AssignRule, Primitives, SplitFactor};
pub use options::{
    CompositeOptions, DealOptions, DfOptions, DirectSendOptions, PcOptions, RadixKOptions,
    SwapOptions,
};
use pixel::{AaPx, Px, ShippedPixel};

/// The ten sort-last algorithms.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Variant {
    Df,
    Pc,
    ScanlineFlow,
    PixelFlow,
    DirectSend,
    Snooping,
    Tree,
    BinarySwap,
    RadixK,
    TwoThreeSwap,
}

impl Variant {
    /// Whether the merge streams frames from node i to node i+1.
    fn needs_pipeline(self) -> bool {
        matches!(
            self,
            Variant::Pc | Variant::ScanlineFlow | Variant::PixelFlow
        )
    }

    /// Whether request-based load balancing applies: it runs at the end of the rendering
    /// phase, so only where rendering and merging are consecutive (paper 001, section 4.1).
    fn balances_on_request(self) -> bool {
        matches!(
            self,
            Variant::Df
                | Variant::Pc
                | Variant::Tree
                | Variant::BinarySwap
                | Variant::RadixK
                | Variant::TwoThreeSwap
        )
    }
}

/// How primitives reach processors.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Assignment {
    /// A fixed deal before rendering.
    Static(Deal),
    /// Object-space blocks of each frame's geometry (`primitives::blocks`).
    Blocks,
    /// Scatter, then idle nodes ask around the ring for work packets (paper 001): a busy
    /// neighbour answers with `1/split` of its remaining queue, if that is at least
    /// `min_packet` primitives.
    Request { split: u32, min_packet: u32 },
}

/// The validated options of one run.
#[derive(Clone, Debug)]
pub struct Settings {
    pub variant: Variant,
    pub assignment: Assignment,
    /// Direct send: z-buffer locally first and send only active pixels (paper 003).
    pub local_zbuffer: bool,
    /// Pipeline composition: scanlines per chunk.
    pub chunk_rows: u32,
    /// Radix-k: the group size of each round (product: the processors).
    pub radices: Vec<u32>,
    /// 2-3 swap: its rounds on this many processors.
    pub swap_rounds: Rc<[two_three_swap::Round]>,
    /// Tree, binary swap, radix-k, 2-3 swap, direct send with a local z-buffer: how image
    /// pieces travel.
    pub image: options::ImageEncoding,
    /// Binary swap, radix-k, 2-3 swap: how the image is cut into pieces.
    pub pieces: options::Pieces,
    /// Tree, binary swap, radix-k, 2-3 swap: IceT's bounding boxes (`bounds=on`).
    pub bounds: bool,
    /// Binary swap, radix-k, 2-3 swap: the frame ends with the pieces at node 0 (`gather=on`)
    /// or left where they were composited (`gather=off`).
    pub gather: bool,
    /// Samples per pixel side (`aa=supersample:N`: sqrt N; 1 otherwise). Nodes render and
    /// merge samples, so every pixel the algorithm moves is a sample.
    pub side: u32,
    /// The anti-aliasing options (`aa=adaptive`: nodes render into paper 000's adaptive
    /// buffer and merges move super pixels with their Subpixels).
    pub aa: AaSettings,
}

/// Bytes of one full-frame pixel as a node holds and ships it: rgb and a 32-bit z (with
/// adaptive anti-aliasing, paper 000's 12-byte Pixel instead).
pub const FULL_FRAME_PIXEL_BYTES: u64 = 3 + 4;

/// What all processors of one run share on the host.
pub(crate) struct Ctx {
    pub settings: Settings,
    pub n: u32,
    pub cfg: RunConfig,
    /// The grid merges address: the screen, or with `aa=supersample:N` the grid sqrt N times
    /// finer in each direction, one location per sample.
    pub viewport: Viewport,
    /// The screen in pixels, where nodes rasterize (a supersampled node draws each pixel's
    /// samples with the sequential supersampling buffer's rule, then ships them as
    /// locations of `viewport`).
    pub screen: Viewport,
    /// With `aa=supersample:N`, each pixel's sample positions (`raster::aa::sample_positions`),
    /// built once for every untested fragment a node ships; empty otherwise.
    pub sample_positions: Vec<(u8, u8)>,
    pub background: [u8; 3],
    pub raster: RasterOptions,
    /// Adaptive anti-aliasing: pools, the frame's grid, statistics.
    pub aa: aa::AaState,
    book: FrameBook,
    /// The final image, set by whichever node holds it when the last frame is merged.
    image: RefCell<Option<Framebuffer>>,
    /// The latest frame's deal, every node's share.
    shares: RefCell<Option<(u32, Vec<Vec<u32>>)>>,
    /// With `bounds=on`, each node's rectangle and frame buffer.
    pub(super) bounds: bounds::Bounds,
    /// With `gather=off`, the composited pixels left at the nodes, resolved: (position, rgb,
    /// z), put together into the report's image after the run.
    left_in_pieces: RefCell<Vec<(u32, [u8; 3], u32)>>,
}

impl Ctx {
    pub fn frames(&self) -> std::ops::Range<u32> {
        self.cfg.frames.clone()
    }

    pub fn is_last(&self, frame: u32) -> bool {
        frame + 1 == self.cfg.frames.end
    }

    pub fn geometry<M: Payload>(
        &self,
        node: &Node<M>,
        frame: u32,
    ) -> Result<Rc<FrameGeometry>, SimError> {
        self.book.geometry(node, frame)
    }

    /// `frame`'s vertices prepared once for every processor (see `FrameBook::vertices`).
    pub fn vertices<M: Payload>(
        &self,
        node: &Node<M>,
        frame: u32,
    ) -> Result<Rc<RefCell<VertexCache>>, SimError> {
        self.book.vertices(node, frame)
    }

    pub fn record<R>(&self, frame: u32, f: impl FnOnce(&mut super::FrameRecord) -> R) -> R {
        self.book.record(frame, f)
    }

    /// Sends `msg` of `bytes`, counting it against `frame`.
    pub async fn send<M: Payload>(
        &self,
        node: &Node<M>,
        frame: u32,
        dst: u32,
        bytes: Bytes,
        msg: M,
    ) {
        self.book.count_message(frame, bytes);
        node.send(dst, bytes, msg).await;
    }

    /// Broadcasts `msg` of `bytes` on the bus, counting it once against `frame`.
    pub async fn broadcast<M: Payload>(
        &self,
        node: &Node<M>,
        frame: u32,
        bytes: Bytes,
        msg: M,
    ) -> Result<(), SimError> {
        self.book.count_message(frame, bytes);
        node.broadcast(bytes, msg).await
    }

    /// Bytes of one full-frame pixel record.
    pub fn record_bytes(&self) -> u64 {
        if self.aa.adaptive {
            PIXEL_BYTES
        } else {
            FULL_FRAME_PIXEL_BYTES
        }
    }

    /// Positions of the piece `range` node `node` looks at to encode it: every one, or with
    /// `bounds=on` those inside its rectangle.
    pub fn scanned(&self, node: u32, range: (u32, u32)) -> u64 {
        self.positions_within(self.bounds.rect(node), range)
    }

    /// Positions of `range` a node holding nothing outside `rect` must cover: every one, or
    /// with `bounds=on` those inside `rect` (none without one).
    pub fn positions_within(&self, rect: Option<ScreenRect>, range: (u32, u32)) -> u64 {
        if !self.settings.bounds {
            return u64::from(range.1 - range.0);
        }
        rect.map_or(0, |r| {
            bounds::positions_inside(r, range, self.viewport.width())
        })
    }

    /// The bytes of a full frame, as a node's memory holds it (the Subpixel pool apart).
    pub fn full_frame_bytes(&self) -> Bytes {
        Bytes::new(self.viewport.pixels() as u64 * self.record_bytes())
    }

    /// The bytes of `rows` full scanlines as a buffer holds them.
    pub fn rows_bytes(&self, rows: u32) -> Bytes {
        Bytes::new(u64::from(rows) * u64::from(self.viewport.width()) * self.record_bytes())
    }

    /// The bytes of `rows` full scanlines shipped with `pixels` active in them: every
    /// record, and the Subpixels of the super pixels among them.
    pub fn chunk_bytes<P: ShippedPixel>(&self, rows: u32, pixels: &[P]) -> Bytes {
        let extra: u64 = pixels.iter().map(P::extra_bytes).sum();
        Bytes::new(self.rows_bytes(rows).get() + extra)
    }

    /// Depth-merges `incoming` into this node's raster-ordered `own` pixels, charging
    /// `composite_pixel` for `charged` pixels and the subpixel work super pixels caused.
    pub async fn merge_rows<P: ShippedPixel, M: Payload>(
        &self,
        node: &Node<M>,
        incoming: &[P],
        own: &[P],
        charged: u64,
    ) -> Vec<P> {
        let (merged, work) = self.aa.with_blocks(node.id(), |blocks| {
            let merged = sparse::merge_sorted(incoming, own, blocks);
            (merged, blocks.take_work())
        });
        let mut counts = Counts::of(Op::CompositePixel, charged);
        counts += &super::charge::back_end(&work);
        node.compute(&counts).await;
        merged
    }

    /// Resolves the super pixels among `pixels` (`resolve_pixel` each) before they leave
    /// for a node that only shows them.
    pub async fn resolve_rows<P: ShippedPixel, M: Payload>(
        &self,
        node: &Node<M>,
        pixels: Vec<P>,
    ) -> Vec<P> {
        let filtered = pixels.iter().filter(|p| p.samples() > 0).count() as u64;
        node.compute(&Counts::of(Op::ResolvePixel, filtered)).await;
        pixels.iter().map(P::resolved).collect()
    }

    /// Depth-merges `pixels` into the dense `image` (slot of each from `slot`), charging
    /// `op` per pixel and the subpixel work super pixels caused.
    pub async fn merge_into<P: ShippedPixel, M: Payload>(
        &self,
        node: &Node<M>,
        image: &mut sparse::Image<P>,
        slot: impl Fn(u32) -> usize,
        pixels: &[P],
        op: Op,
    ) {
        let work = self.aa.with_blocks(node.id(), |blocks| {
            for p in pixels {
                image.merge(slot(p.loc()), p, blocks);
            }
            blocks.take_work()
        });
        let mut counts = Counts::of(op, pixels.len() as u64);
        counts += &super::charge::back_end(&work);
        node.compute(&counts).await;
    }

    /// The static share of this node in `frame`: database indices, ascending. With request
    /// balancing this is the initial scatter. The deal is made once per frame, for all nodes.
    pub fn share<M: Payload>(&self, node: &Node<M>, frame: u32) -> Result<Vec<u32>, SimError> {
        let mut cache = self.shares.borrow_mut();
        if cache.as_ref().is_none_or(|(f, _)| *f != frame) {
            let geometry = self.geometry(node, frame)?;
            let dealt = match self.settings.assignment {
                Assignment::Static(rule) => {
                    static_assignment(&geometry, frame, rule, self.n, self.cfg.seed)
                }
                Assignment::Request { .. } => {
                    static_assignment(&geometry, frame, Deal::Scatter, self.n, self.cfg.seed)
                }
                Assignment::Blocks => block_assignment(&geometry, self.n),
            };
            *cache = Some((frame, shares(&dealt, self.n)));
        }
        let (_, shares) = cache.as_ref().expect("filled above");
        Ok(shares[node.id() as usize].clone())
    }

    /// Shows `frame`'s merged pixels on the node holding the frame buffer: charges
    /// resolving them every frame (super pixels' box filters, or with `supersample:N` every
    /// pixel's samples), and keeps the image after the run's last frame.
    pub async fn show<P: ShippedPixel, M: Payload>(
        &self,
        node: &Node<M>,
        frame: u32,
        pixels: &[P],
    ) {
        let side = self.settings.side;
        let resolved = if side > 1 {
            self.viewport.pixels() as u64 / u64::from(side * side)
        } else {
            pixels.iter().filter(|p| p.samples() > 0).count() as u64
        };
        node.compute(&Counts::of(Op::ResolvePixel, resolved)).await;
        if self.is_last(frame) {
            let image = self.image_of(pixels.iter().map(|p| {
                let (rgb, z) = p.resolve();
                (p.loc(), rgb, z)
            }));
            *self.image.borrow_mut() = Some(image);
        }
    }

    /// Keeps a piece composited at a node that does not send it on (`gather=off`), for the
    /// report's image.
    pub fn leave_piece<P: ShippedPixel>(&self, pixels: &[P]) {
        let mut left = self.left_in_pieces.borrow_mut();
        left.extend(pixels.iter().map(|p| {
            let (rgb, z) = p.resolve();
            (p.loc(), rgb, z)
        }));
    }

    /// The image of resolved pixels on the run's grid (downsampled to the screen when
    /// supersampled).
    fn image_of(&self, pixels: impl Iterator<Item = (u32, [u8; 3], u32)>) -> Framebuffer {
        let image = sparse::framebuffer_of(self.viewport, self.background, pixels);
        match self.settings.side {
            1 => image,
            side => downsample(&image, side),
        }
    }

    /// Starts `frame`'s anti-aliasing state on `node` (its Subpixel pool).
    pub fn begin_aa<M: Payload>(&self, node: &Node<M>, frame: u32) -> Result<(), SimError> {
        self.aa.begin(node, frame)
    }

    /// Ends `frame` on `node`: records its anti-aliasing statistics, frees its pool.
    pub fn end_aa<M: Payload>(&self, node: &Node<M>, frame: u32) -> Result<(), SimError> {
        self.aa.end(node, frame, &self.book, self.n)
    }
}

/// The processor of every triangle of `geometry` (frame `frame`) under a static deal, as a
/// run gives them: database order, screen area for `background-last`, the random stream
/// `sort-last/assign/frame=<frame>`. Tests hand it to trace replay (`Replay::pass`) to
/// replay exactly the assignment a run used.
pub fn static_assignment(
    geometry: &FrameGeometry,
    frame: u32,
    rule: Deal,
    n: u32,
    seed: u64,
) -> Vec<u32> {
    let count = geometry.triangles.len();
    let area = |k: usize| screen_area(geometry, k);
    let stream = format!("sort-last/assign/frame={frame}");
    deal(rule, count, area, n, seed, &stream)
}

/// The processor of every triangle of `geometry` dealt in object-space blocks: each
/// triangle's centroid in clip coordinates (x, y, z before the divide: within a frame, a
/// fixed affine image of the scene's space, so the cuts are planes through the scene).
pub fn block_assignment(geometry: &FrameGeometry, n: u32) -> Vec<u32> {
    let centroids: Vec<[f32; 3]> = geometry
        .triangles
        .iter()
        .map(|tri| {
            let sum = tri
                .iter()
                .map(|&v| geometry.vertices[v as usize].clip.truncate())
                .fold(glam::Vec3::ZERO, |a, b| a + b);
            (sum / 3.0).to_array()
        })
        .collect();
    crate::algo::primitives::blocks(&centroids, n)
}

/// Twice the clip-space-projected area of triangle `k` in NDC units: the size
/// `background-last` compares (the largest primitive is the background). Triangles behind
/// the eye count as zero.
fn screen_area(g: &FrameGeometry, k: usize) -> u64 {
    let [a, b, c] = g.triangles[k].map(|i| g.vertices[i as usize].clip);
    if a.w <= 0.0 || b.w <= 0.0 || c.w <= 0.0 {
        return 0;
    }
    let p = |v: glam::Vec4| glam::Vec2::new(v.x / v.w, v.y / v.w);
    let (a, b, c) = (p(a), p(b), p(c));
    let cross = (b - a).perp_dot(c - a).abs() as f64;
    // Fixed resolution so the comparison is an integer one.
    (cross * (1u64 << 20) as f64).min(u64::MAX as f64) as u64
}

/// Checks that the machine offers what `variant` needs.
/// The (sender, receiver) pairs a compositing variant's merge uses on `n` nodes (none for
/// the others, whose needs are stated below).
fn partners(variant: Variant, n: u32, radices: &[u32]) -> Vec<(u32, u32)> {
    match variant {
        // Node i sends its frame in round trailing_zeros(i), to i minus its lowest set bit.
        Variant::Tree => (1..n).map(|i| (i, i - (1 << i.trailing_zeros()))).collect(),
        // The fold to i - k, the swaps with i xor 2^r, the gather to node 0.
        Variant::BinarySwap => {
            let k = 1 << n.ilog2();
            let fold = (k..n).map(|i| (i, i - k));
            let swaps = (0..k).flat_map(|i| (0..k.ilog2()).map(move |r| (i, i ^ (1 << r))));
            let gather = (1..k).map(|i| (i, 0));
            fold.chain(swaps).chain(gather).collect()
        }
        // Every pair within a round's group, and the gather to node 0.
        Variant::RadixK => {
            let within = (0..n).flat_map(|i| {
                (0..radices.len()).flat_map(move |r| {
                    radix_k::group(i, radices, r)
                        .into_iter()
                        .filter(move |&j| j != i)
                        .map(move |j| (i, j))
                })
            });
            within.chain((1..n).map(|i| (i, 0))).collect()
        }
        // Every overlap of a piece with a new part, and the gather to node 0.
        Variant::TwoThreeSwap => {
            let mut pairs = two_three_swap::senders(n);
            pairs.extend((1..n).map(|i| (i, 0)));
            pairs
        }
        _ => Vec::new(),
    }
}

fn requirements(cfg: &RunConfig, settings: &Settings) -> Result<(), RunError> {
    let variant = settings.variant;
    let m = &cfg.machine;
    let net = super::routes::network(cfg)?;
    if variant.needs_pipeline() {
        if let Some(i) = (0..m.nodes.saturating_sub(1)).find(|&i| net.hops(i, i + 1).total() != 1) {
            return Err(RunError::Unsupported(format!(
                "{} streams frames from node i to node i+1, but machine '{}' ({}) has no \
                 direct link from node {i} to node {}; use a machine whose topology is a \
                 pipeline or a ring",
                cfg.algo.id(),
                m.name,
                m.network.topology.name(),
                i + 1
            )));
        }
    }
    let request = matches!(settings.assignment, Assignment::Request { .. });
    match variant {
        // Pixels go to the owners of their scanlines, band requests to every node, credits
        // back up the pipelines and each frame's start from the image holder to every node;
        // a work packet goes back to whichever node asked around the ring.
        Variant::DirectSend | Variant::Df | Variant::Pc | Variant::ScanlineFlow => {
            super::routes::require_all_pairs(cfg, &net)?
        }
        _ if request => super::routes::require_all_pairs(cfg, &net)?,
        _ => super::routes::require(cfg, &net, partners(variant, m.nodes, &settings.radices))?,
    }
    if variant == Variant::Snooping && !net.supports_broadcast() {
        return Err(RunError::Unsupported(format!(
            "sort-last/snooping needs a broadcast medium, but machine '{}' is a {}; use a \
             machine whose topology is a bus",
            m.name,
            m.network.topology.name()
        )));
    }
    Ok(())
}

/// The options every sort-last algorithm reads, whatever its struct.
struct Common {
    assign: AssignRule,
    split: u32,
    min_packet: u32,
    local_zbuffer: bool,
    chunk_rows: u32,
    radices: Option<options::Radices>,
    image: options::ImageEncoding,
    pieces: options::Pieces,
    bounds: bool,
    gather: bool,
}

impl Common {
    /// A variant that takes only the assignment (request balancing's parameters unused).
    fn dealt(assign: AssignRule) -> Common {
        Common::balanced(assign, SplitFactor(4), Primitives(16))
    }

    /// A variant that may balance on request; dense pieces, one-row chunks, no radices.
    fn balanced(assign: AssignRule, split: SplitFactor, min_packet: Primitives) -> Common {
        Common {
            assign,
            split: split.0,
            min_packet: min_packet.0,
            local_zbuffer: false,
            chunk_rows: 1,
            radices: None,
            image: options::ImageEncoding::Dense,
            pieces: options::Pieces::Contiguous,
            bounds: false,
            gather: true,
        }
    }
}

/// `bounds=on` needs pieces that can skip what lies outside a rectangle: run-length images,
/// cut in raster order, drawn from a deal known before rendering.
fn check_bounds(
    o: &super::Options,
    common: &Common,
    assignment: &Assignment,
) -> Result<(), RunError> {
    if common.image != options::ImageEncoding::Rle {
        return Err(bad(
            o,
            "bounds",
            "off, or on together with image=rle: a dense piece carries every position, so \
             there is nothing outside the rectangle to skip",
        ));
    }
    if common.pieces != options::Pieces::Contiguous {
        return Err(bad(
            o,
            "bounds",
            "off, or on with pieces=contiguous: interleaved rows scatter a rectangle over \
             every piece",
        ));
    }
    if matches!(assignment, Assignment::Request { .. }) {
        return Err(bad(
            o,
            "bounds",
            "off, or on with a static assignment (scatter, random, background-last or \
             blocks): with request balancing a node does not know what it will draw",
        ));
    }
    Ok(())
}

/// `gather=off` times one frame's compositing and leaves its pieces where they are, so there
/// is no next frame to start and no interlaced order to undo at node 0.
fn check_no_gather(o: &super::Options, cfg: &RunConfig, common: &Common) -> Result<(), RunError> {
    if common.pieces != options::Pieces::Contiguous {
        return Err(bad(
            o,
            "gather",
            "on, or off with pieces=contiguous: interleaved pieces are put back in order at \
             node 0, which gather=off never reaches",
        ));
    }
    if cfg.frames.len() != 1 {
        return Err(bad(
            o,
            "gather",
            &format!(
                "on, or off with one frame (--frames A): with the image left in pieces no \
                 node knows when the frame ends, so a next frame cannot start (asked for {} \
                 frames)",
                cfg.frames.len()
            ),
        ));
    }
    Ok(())
}

/// Reads the options of `variant` and checks them.
fn settings(cfg: &RunConfig, variant: Variant) -> Result<Settings, RunError> {
    let o = &cfg.options;
    let algo = cfg.algo.id();
    let (common, aa) = match variant {
        Variant::Pc => {
            let (p, aa) = parse::<PcOptions>(o, algo)?;
            let c = Common {
                chunk_rows: p.chunk_rows.0,
                ..Common::balanced(p.assign, p.split, p.min_packet)
            };
            (c, aa)
        }
        Variant::Df => {
            let (d, aa) = parse::<DfOptions>(o, algo)?;
            (Common::balanced(d.assign, d.split, d.min_packet), aa)
        }
        Variant::Tree => {
            let (d, aa) = parse::<CompositeOptions>(o, algo)?;
            let c = Common {
                image: d.image,
                bounds: d.bounds.is_on(),
                ..Common::balanced(d.assign, d.split, d.min_packet)
            };
            (c, aa)
        }
        Variant::BinarySwap | Variant::TwoThreeSwap => {
            let (d, aa) = parse::<SwapOptions>(o, algo)?;
            let c = Common {
                image: d.image,
                pieces: d.pieces,
                bounds: d.bounds.is_on(),
                gather: d.gather.is_on(),
                ..Common::balanced(d.assign, d.split, d.min_packet)
            };
            (c, aa)
        }
        Variant::RadixK => {
            let (r, aa) = parse::<RadixKOptions>(o, algo)?;
            let c = Common {
                radices: Some(r.k),
                image: r.image,
                pieces: r.pieces,
                bounds: r.bounds.is_on(),
                gather: r.gather.is_on(),
                ..Common::balanced(r.assign, r.split, r.min_packet)
            };
            (c, aa)
        }
        Variant::DirectSend => {
            let (d, aa) = parse::<DirectSendOptions>(o, algo)?;
            if d.image == options::ImageEncoding::Rle && !d.local_zbuffer.is_on() {
                return Err(bad(
                    o,
                    "image",
                    "dense, or rle together with local-zbuffer=on: without a local z-buffer \
                     direct send ships every fragment as it is drawn, not an image to \
                     run-length encode",
                ));
            }
            let c = Common {
                local_zbuffer: d.local_zbuffer.is_on(),
                image: d.image,
                ..Common::dealt(d.assign)
            };
            (c, aa)
        }
        Variant::ScanlineFlow | Variant::PixelFlow | Variant::Snooping => {
            let (d, aa) = parse::<DealOptions>(o, algo)?;
            (Common::dealt(d.assign), aa)
        }
    };
    let assignment =
        match common.assign {
            AssignRule::Scatter => Assignment::Static(Deal::Scatter),
            AssignRule::Random => Assignment::Static(Deal::Random),
            AssignRule::BackgroundLast => Assignment::Static(Deal::BackgroundLast),
            AssignRule::Blocks => Assignment::Blocks,
            AssignRule::Request if !variant.balances_on_request() => return Err(bad(
                o,
                "assign",
                "scatter, random, background-last or blocks: request balancing runs at the end \
                 of rendering, so only sort-last/df, sort-last/pc and the compositing \
                 variants (tree, binary-swap, radix-k, 2-3-swap) use it (paper 001)",
            )),
            AssignRule::Request => Assignment::Request {
                split: common.split,
                min_packet: common.min_packet,
            },
        };
    if common.assign != AssignRule::Request {
        if let Some(k) = ["split", "min-packet"].iter().find(|k| o.is_given(k)) {
            return Err(bad(
                o,
                k,
                "assign=request with it (it applies to request balancing only)",
            ));
        }
    }
    if common.bounds {
        check_bounds(o, &common, &assignment)?;
    }
    if !common.gather {
        check_no_gather(o, cfg, &common)?;
    }
    let (local_zbuffer, chunk_rows) = (common.local_zbuffer, common.chunk_rows);
    let n = cfg.machine.nodes;
    let radices = match common.radices {
        None => Vec::new(),
        Some(options::Radices::Auto) => radix_k::default_radices(n),
        Some(options::Radices::Given(k)) => {
            let product = k.iter().try_fold(1u32, |p, &k| p.checked_mul(k));
            if product != Some(n) {
                let what = format!(
                    "group sizes whose product is the number of processors, {n} (e.g. {}), \
                     or auto; {} multiply to {}",
                    options::Radices::Given(radix_k::default_radices(n)),
                    options::Radices::Given(k.clone()),
                    product.map_or("more than 2^32".to_string(), |p| p.to_string())
                );
                return Err(bad(o, "k", &what));
            }
            k
        }
    };
    let aa = aa_settings(o, &aa)?;
    check_prices(cfg, &aa)?;
    let side = match aa.method {
        AaMethod::None | AaMethod::Adaptive => 1,
        AaMethod::Supersample { side } => side,
    };
    Ok(Settings {
        variant,
        assignment,
        local_zbuffer,
        chunk_rows,
        radices,
        swap_rounds: if variant == Variant::TwoThreeSwap {
            two_three_swap::schedule(n).into()
        } else {
            Rc::from([])
        },
        image: common.image,
        pieces: common.pieces,
        bounds: common.bounds,
        gather: common.gather,
        side,
        aa,
    })
}

/// Checks a variant's options and machine against `cfg` without running it.
pub fn check(cfg: &RunConfig, variant: Variant) -> Result<(), RunError> {
    let settings = settings(cfg, variant)?;
    requirements(cfg, &settings)?;
    let first = cfg.scene.frame(cfg.frames.start)?;
    super::aa::sample_grid(cfg, super::reference::viewport(&first), settings.side).map(|_| ())
}

/// Runs a sort-last variant.
pub fn run(cfg: &RunConfig, variant: Variant) -> Result<RunResult, RunError> {
    let settings = settings(cfg, variant)?;
    requirements(cfg, &settings)?;
    let first = cfg.scene.frame(cfg.frames.start)?;
    let screen = super::reference::viewport(&first);
    let viewport = super::aa::sample_grid(cfg, screen, settings.side)?;
    let n = cfg.machine.nodes;
    let sample_positions = match settings.side {
        1 => Vec::new(),
        side => crate::raster::aa::sample_positions(side),
    };
    let ctx = Rc::new(Ctx {
        aa: aa::AaState::new(&settings.aa, n, viewport.pixels() as u64, first.background),
        settings,
        n,
        cfg: cfg.clone(),
        viewport,
        screen,
        sample_positions,
        background: first.background,
        raster: super::reference::raster_options(&first),
        book: FrameBook::new(cfg, screen, Rc::new(first), None),
        image: RefCell::default(),
        shares: RefCell::default(),
        bounds: bounds::Bounds::new(n),
        left_in_pieces: RefCell::default(),
    });
    let stats = if ctx.aa.adaptive {
        simulate_variant::<AaPx>(cfg, &ctx, variant)?
    } else {
        simulate_variant::<Px>(cfg, &ctx, variant)?
    };
    finish(ctx, stats)
}

/// Runs `variant` with nodes that ship pixels of type `P`.
fn simulate_variant<P: ShippedPixel>(
    cfg: &RunConfig,
    ctx: &Rc<Ctx>,
    variant: Variant,
) -> Result<crate::engine::RunStats, RunError> {
    Ok(match variant {
        Variant::Df => simulate(cfg, ctx, df::processor::<P>)?,
        Variant::Pc => simulate(cfg, ctx, pc::processor::<P>)?,
        Variant::ScanlineFlow => simulate(cfg, ctx, scanline_flow::processor::<P>)?,
        Variant::PixelFlow => simulate(cfg, ctx, pixelflow::processor::<P>)?,
        Variant::DirectSend => simulate(cfg, ctx, direct_send::processor::<P>)?,
        Variant::Tree => simulate(cfg, ctx, tree::processor::<P>)?,
        Variant::BinarySwap => simulate(cfg, ctx, binary_swap::processor::<P>)?,
        Variant::RadixK => simulate(cfg, ctx, radix_k::processor::<P>)?,
        Variant::TwoThreeSwap => simulate(cfg, ctx, two_three_swap::processor::<P>)?,
        Variant::Snooping => {
            let shared = Rc::new(snooping::Shared::default());
            simulate(cfg, ctx, move |node, ctx| {
                snooping::processor::<P>(node, ctx, shared.clone())
            })?
        }
    })
}

fn finish(ctx: Rc<Ctx>, stats: crate::engine::RunStats) -> Result<RunResult, RunError> {
    if !ctx.settings.gather {
        let left = std::mem::take(&mut *ctx.left_in_pieces.borrow_mut());
        *ctx.image.borrow_mut() = Some(ctx.image_of(left.into_iter()));
    }
    let image = ctx.image.borrow_mut().take().unwrap_or_else(|| {
        let side = ctx.settings.side;
        let screen = Viewport::new(ctx.viewport.width() / side, ctx.viewport.height() / side);
        Framebuffer::with_clear(screen.unwrap_or(ctx.viewport), ctx.background)
    });
    Ok(RunResult {
        stats,
        frames: ctx.book.records(),
        image,
    })
}
