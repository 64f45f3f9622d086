//! The image-space stages that sort-middle and sort-first share: screen regions (`regions`)
//! and their assignment to processors (`assign`), per-region counts summed up a tree of
//! processors, polygon buffers (`buffers`) and redistribution (`redistribute`, `two_step`),
//! the frame barriers, the rasterization stage (`canvas` and `rasterize` here), and sort-first's
//! book of who holds which primitive (`holders`). The node programs that use them live with
//! their algorithms: `sort_middle::{ellsworth, static_regions}`, `sort_first::mueller`.
//!
//! Must never name a topology (groups and trees are over processor ids), and never import an
//! algorithm: they import this.

pub mod assign;
pub mod buffers;
pub mod canvas;
pub(crate) mod dealing;
pub mod holders;
pub mod options;
pub(crate) mod redistribute;
pub mod regions;
pub mod two_step;

use std::cell::RefCell;
use std::rc::Rc;

use super::aa::{aa_settings, AaSettings};
use assign::Assignment;
use canvas::Canvas;
pub use holders::{FirstSettings, HolderBook};
pub use options::CountsFrom;
use options::TwoStep;
pub use options::DEFAULT_BUFFER;
use regions::RegionGrid;
use two_step::Groups;

use super::ahead::Deal;
use super::charge;
use super::frames::FrameBook;
use super::{bad_option as bad, simulate, FrameRecord, RunConfig, RunError, RunResult};
use crate::engine::{Filter, Node, Payload, SimError};
use crate::machine::{Counts, Op};
use crate::raster::aa::{adapt, AaMethod, Grid};
use crate::raster::{
    draw_screen_triangles, setup_subset, Framebuffer, RasterOptions, RegionSet, ScreenTriangle,
    VertexCache, Viewport,
};
use crate::scene::FrameGeometry;
use crate::units::{Bytes, SimTime};

/// How a variant lays out its regions.
#[derive(Clone, Copy, Debug)]
pub enum RegionChoice {
    /// Square regions of this side in pixels (paper 000).
    Side(u32),
    /// This many regions per processor (paper 002's granularity ratio).
    PerProcessor(u32),
}

/// What a variant's options chose, before they are checked against the machine and the screen.
#[derive(Clone, Debug)]
pub struct Choice {
    pub regions: RegionChoice,
    pub buffer: Bytes,
    pub counts: CountsFrom,
    pub two_step: TwoStep,
    /// The load balancer's estimate of one polygon's rasterization time; none: set-up plus 3
    /// spans plus 6 pixels at the machine's costs.
    pub polygon_estimate: Option<SimTime>,
    pub aa: super::aa::AaOptions,
    pub first: FirstSettings,
    /// The smallest record a buffer must hold: a routed triangle, or a database record.
    pub record_bytes: u64,
}

/// The validated options of one run.
#[derive(Clone, Debug)]
pub struct Settings {
    pub grid: RegionGrid,
    pub buffer: Bytes,
    pub counts: CountsFrom,
    pub groups: Option<Groups>,
    /// The load balancer's estimate of one polygon's rasterization time.
    pub polygon_estimate: SimTime,
    /// Anti-aliasing (`aa`, `aa-pool`, `aa-start`, `aa-reclaim`).
    pub aa: AaSettings,
    /// Sort-first: how regions are assigned and how records travel.
    pub first: FirstSettings,
}

pub(crate) const TAG_POLYGONS: u32 = 1;
pub(crate) const TAG_FORWARD: u32 = 2;
pub(crate) const TAG_COUNTS: u32 = 3;
pub(crate) const TAG_START: u32 = 4;
pub(crate) const TAG_DONE: u32 = 5;
pub(crate) const TAG_PIXELS: u32 = 6;
pub(crate) const TAG_ASSIGNED: u32 = 7;
pub(crate) const TAG_RECORDS: u32 = 8;
pub(crate) const TAG_EXPECT_UP: u32 = 9;
pub(crate) const TAG_EXPECT_DOWN: u32 = 10;

/// What sort-middle processors send each other.
#[derive(Clone, Debug)]
pub(crate) enum Msg {
    /// Screen triangles for the receiver's regions. The last message of a sender's stream
    /// says how many messages the stream had (`end`), since a network may deliver two
    /// messages of one pair out of order (the flow model shares bandwidth between them).
    Polygons {
        frame: u32,
        tris: Vec<ScreenTriangle>,
        end: Option<u32>,
    },
    /// First step of two-step redistribution: triangles with their final destination.
    Forward {
        frame: u32,
        tris: Vec<(u32, ScreenTriangle)>,
        end: Option<u32>,
    },
    /// Per-region polygon counts on their way up the summing tree.
    Counts { frame: u32, counts: Vec<u32> },
    /// The start of a frame, down the tree from processor 0, with the region assignment when
    /// it changed.
    Start {
        frame: u32,
        assignment: Option<Rc<Assignment>>,
    },
    /// A subtree has finished rasterizing `frame`.
    Done { frame: u32 },
    /// A processor's regional image for the root (paper 000).
    Pixels { frame: u32, pixels: u64 },
    /// Processor 0's assignment for the next frame is ready (a local event).
    Assigned { frame: u32 },
    /// Sort-first: database records of primitives (indices on the host) for the receiver's
    /// regions, which it transforms itself.
    Records { frame: u32, prims: Vec<u32> },
    /// Sort-first: record messages per destination, summed up the tree (partial sums) and
    /// sent back down (the totals).
    Expect {
        frame: u32,
        up: bool,
        counts: Rc<Vec<u32>>,
    },
}

impl Payload for Msg {
    fn tag(&self) -> u32 {
        match self {
            Msg::Polygons { .. } => TAG_POLYGONS,
            Msg::Forward { .. } => TAG_FORWARD,
            Msg::Counts { .. } => TAG_COUNTS,
            Msg::Start { .. } => TAG_START,
            Msg::Done { .. } => TAG_DONE,
            Msg::Pixels { .. } => TAG_PIXELS,
            Msg::Assigned { .. } => TAG_ASSIGNED,
            Msg::Records { .. } => TAG_RECORDS,
            Msg::Expect { up: true, .. } => TAG_EXPECT_UP,
            Msg::Expect { up: false, .. } => TAG_EXPECT_DOWN,
        }
    }
}

impl Msg {
    pub(crate) fn frame(&self) -> u32 {
        match *self {
            Msg::Polygons { frame, .. }
            | Msg::Forward { frame, .. }
            | Msg::Counts { frame, .. }
            | Msg::Start { frame, .. }
            | Msg::Done { frame }
            | Msg::Pixels { frame, .. }
            | Msg::Records { frame, .. }
            | Msg::Expect { frame, .. }
            | Msg::Assigned { frame } => frame,
        }
    }

    /// What the machine is charged for moving this message.
    pub(crate) fn bytes(&self) -> Bytes {
        let header = buffers::HEADER_BYTES;
        match self {
            Msg::Polygons { .. } | Msg::Forward { .. } => redistribute::polygon_bytes(self),
            Msg::Counts { counts, .. } => Bytes::new(header + 4 * counts.len() as u64),
            Msg::Start { assignment, .. } => {
                Bytes::new(header + assignment.as_ref().map_or(0, |a| 2 * a.owner.len() as u64))
            }
            Msg::Done { .. } | Msg::Assigned { .. } => Bytes::new(header),
            Msg::Pixels { pixels, .. } => Bytes::new(header + 3 * pixels),
            Msg::Records { prims, .. } => {
                Bytes::new(header + DATABASE_BYTES_PER_TRIANGLE * prims.len() as u64)
            }
            Msg::Expect { counts, .. } => Bytes::new(header + 4 * counts.len() as u64),
        }
    }
}

/// Bytes of one triangle of the retained database a processor stores: three vertices with
/// position and normal as 32-bit floats, and a colour (paper 002: "the database can be broken
/// up and stored in the processors' memories").
pub const DATABASE_BYTES_PER_TRIANGLE: u64 = 3 * (12 + 12) + 4;

impl Ctx {
    /// The memory processor `me` holds for its share (every n-th triangle) of the model.
    pub(crate) fn database_memory(&self, me: u32) -> Bytes {
        let triangles = self.cfg.scene.triangle_count() as u64;
        let share = triangles / self.n as u64 + u64::from((me as u64) < triangles % self.n as u64);
        Bytes::new(share * DATABASE_BYTES_PER_TRIANGLE)
    }
}

impl Settings {
    /// The memory processor `me` keeps for its fixed-size polygon buffers: one per other
    /// processor, or with two-step redistribution one per other group and one per other
    /// member of its own group (paper 002).
    pub fn polygon_buffer_memory(&self, me: u32, n: u32) -> Bytes {
        let buffers = match &self.groups {
            None => n - 1,
            Some(g) => (g.count() - 1) + (g.members(g.group_of(me)).len() as u32 - 1),
        };
        self.buffer * buffers as u64
    }
}

/// What all processors of one run share on the host: the scene's frames (computed once per
/// frame, not once per processor), the settings, and the records being written.
pub(crate) struct Ctx {
    pub settings: Settings,
    pub n: u32,
    pub(crate) cfg: RunConfig,
    pub(crate) viewport: Viewport,
    background: [u8; 3],
    pub(crate) raster: RasterOptions,
    book: FrameBook,
    /// Each frame's front end, run once for every processor (`transform`).
    dealer: dealing::Dealer,
    /// The assignment every processor starts the run with, once the first has made it.
    first_assignment: RefCell<Option<Rc<Assignment>>>,
    /// Processor 0's assignment for the next frame, once computed.
    pub(crate) next_assignment: RefCell<Option<Rc<Assignment>>>,
    /// Each processor's regions after the last frame, for the output image.
    pub(crate) images: RefCell<Vec<Option<RegionSet>>>,
    /// Sort-first: who holds which primitive (host bookkeeping).
    pub(crate) holders: HolderBook,
    /// Each processor's subpixel resolution for its next frame (adaptive anti-aliasing).
    aa_grid: RefCell<Vec<Grid>>,
}

impl Ctx {
    /// The assignment every processor starts the run with (`make`, the same in each): made by
    /// the first to ask and shared, where each made its own (512 of them took a twentieth of a
    /// 512-processor frame's host time).
    pub(crate) fn first_assignment(&self, make: impl FnOnce() -> Assignment) -> Rc<Assignment> {
        self.first_assignment
            .borrow_mut()
            .get_or_insert_with(|| Rc::new(make()))
            .clone()
    }

    pub(crate) fn frames(&self) -> std::ops::Range<u32> {
        self.cfg.frames.clone()
    }

    pub(crate) fn is_last(&self, frame: u32) -> bool {
        frame + 1 == self.cfg.frames.end
    }

    pub(crate) fn geometry(
        &self,
        node: &Node<Msg>,
        frame: u32,
    ) -> Result<Rc<FrameGeometry>, SimError> {
        self.book.geometry(node, frame)
    }

    /// `frame`'s vertices prepared once for every processor (see `FrameBook::vertices`).
    pub(crate) fn vertices(
        &self,
        node: &Node<Msg>,
        frame: u32,
    ) -> Result<Rc<RefCell<VertexCache>>, SimError> {
        self.book.vertices(node, frame)
    }

    pub(crate) fn record<R>(&self, frame: u32, f: impl FnOnce(&mut FrameRecord) -> R) -> R {
        self.book.record(frame, f)
    }

    /// `frame` begins now at processor 0, unless it has begun already: a frame's time runs
    /// from its beginning to its end, whatever processor 0 waits for in between.
    pub(crate) fn begin_frame(&self, node: &Node<Msg>, frame: u32) {
        self.book.begin(node, frame);
    }

    pub(crate) fn count_message(&self, frame: u32, bytes: Bytes) {
        self.book.count_message(frame, bytes)
    }

    pub(crate) async fn send(&self, node: &Node<Msg>, dst: u32, msg: Msg) {
        let bytes = msg.bytes();
        self.count_message(msg.frame(), bytes);
        node.send(dst, bytes, msg).await;
    }

    /// Triangles per transformation batch: one buffer's worth, so compute is charged at the
    /// grain messages are sent (events grow with messages, not with pixels).
    pub(crate) fn batch(&self) -> usize {
        batch_of(&self.settings)
    }

    /// How this run deals each frame's front end out (`transform`), as the thread that makes
    /// the later frames ahead deals them.
    fn deal(&self) -> Deal {
        deal_of(&self.settings, self.n, self.raster)
    }
}

/// How many triangles one polygon buffer of `settings` holds.
fn batch_of(settings: &Settings) -> usize {
    ((settings.buffer.get().saturating_sub(buffers::HEADER_BYTES)) / buffers::TRIANGLE_BYTES).max(1)
        as usize
}

/// The dealing of a run of `settings` on `n` processors: one polygon buffer's worth a batch.
fn deal_of(settings: &Settings, n: u32, options: RasterOptions) -> Deal {
    Deal {
        n,
        batch: batch_of(settings),
        options,
    }
}

/// The processors' summing and broadcast tree: a binary heap over ids, rooted at 0.
pub(crate) fn children(me: u32, n: u32) -> impl Iterator<Item = u32> {
    [2 * me + 1, 2 * me + 2].into_iter().filter(move |&c| c < n)
}

pub(crate) fn parent(me: u32) -> u32 {
    (me - 1) / 2
}

/// Processor 0 starts `frame` by sending `Start` down the tree; every other processor waits
/// for it (this is also the barrier that ensures the previous frame finished) and passes it on.
pub(crate) async fn start_frame(
    node: &Node<Msg>,
    ctx: &Ctx,
    frame: u32,
    assignment: Option<Rc<Assignment>>,
) -> Option<Rc<Assignment>> {
    let me = node.id();
    let assignment = if me == 0 {
        assignment
    } else {
        let env = node
            .recv(Filter::tag(TAG_START).and_source(parent(me)))
            .await;
        let Msg::Start { assignment, .. } = env.payload else {
            unreachable!("filtered by tag")
        };
        assignment
    };
    for child in children(me, ctx.n) {
        ctx.send(
            node,
            child,
            Msg::Start {
                frame,
                assignment: assignment.clone(),
            },
        )
        .await;
    }
    if me == 0 {
        ctx.begin_frame(node, frame);
    }
    assignment
}

/// Waits until the whole subtree below this processor has finished `frame`, then tells the
/// parent; at processor 0 this is the end of the frame.
pub(crate) async fn finish_frame(node: &Node<Msg>, ctx: &Ctx, frame: u32) {
    let me = node.id();
    for child in children(me, ctx.n) {
        node.recv(Filter::tag(TAG_DONE).and_source(child)).await;
    }
    if me == 0 {
        let now = node.now();
        ctx.record(frame, |r| r.end = now);
    } else {
        ctx.send(node, parent(me), Msg::Done { frame }).await;
    }
}

/// Every processor's regional image goes to processor 0 (paper 000's root), which copies
/// them into the frame: rgb per pixel, its own included.
pub(crate) async fn collect_image(node: &Node<Msg>, ctx: &Ctx, frame: u32, regions: &RegionSet) {
    let pixels: u64 = regions
        .regions()
        .iter()
        .map(|b| b.rect().pixels() as u64)
        .sum();
    node.phase("collect");
    if node.id() == 0 {
        node.compute(&Counts::of(Op::ByteCopy, 3 * pixels)).await;
        for _ in 1..ctx.n {
            let env = node.recv(Filter::tag(TAG_PIXELS)).await;
            let Msg::Pixels { pixels, .. } = env.payload else {
                unreachable!("filtered by tag")
            };
            node.compute(&Counts::of(Op::ByteCopy, 3 * pixels)).await;
        }
    } else {
        ctx.send(node, 0, Msg::Pixels { frame, pixels }).await;
    }
}

/// Sums per-region counts up the tree: processor 0 ends with the total (`Some`); every other
/// processor hands its partial sum on to its parent, moved into the message (a 512-node
/// frame's counts are 16 KB, and a copy kept by a processor that never read it again cost
/// the frame 8 MB of copying).
pub(crate) async fn sum_counts(
    node: &Node<Msg>,
    ctx: &Ctx,
    frame: u32,
    mut counts: Vec<u32>,
) -> Option<Vec<u32>> {
    let me = node.id();
    for child in children(me, ctx.n) {
        let env = node.recv(Filter::tag(TAG_COUNTS).and_source(child)).await;
        let Msg::Counts { counts: theirs, .. } = env.payload else {
            unreachable!("filtered by tag")
        };
        for (a, b) in counts.iter_mut().zip(theirs) {
            *a += b;
        }
        node.compute(&Counts::of(Op::CountSum, counts.len() as u64))
            .await;
    }
    if me == 0 {
        return Some(counts);
    }
    ctx.send(node, parent(me), Msg::Counts { frame, counts })
        .await;
    None
}

/// Processor 0 assigns regions by greedy bin packing on estimated costs, charging its own
/// time for it (and counting that time as its own load, so that it takes no regions when the
/// assignment fills its frame).
pub(crate) async fn compute_assignment(node: &Node<Msg>, ctx: &Ctx, counts: &[u32]) -> Assignment {
    let s = &ctx.settings;
    let costs = &ctx.cfg.machine.cpu.costs;
    let work = Counts::of(Op::AssignRegion, counts.len() as u64);
    let own_time = costs.time(&work);
    let estimates: Vec<SimTime> = (0..counts.len() as u32)
        .map(|r| {
            let pixels = s.grid.rect(r).pixels() as u64;
            costs.get(Op::ClearPixel).times(pixels)
                + s.polygon_estimate.times(counts[r as usize] as u64)
        })
        .collect();
    let mut initial = vec![SimTime::ZERO; ctx.n as usize];
    initial[0] = own_time;
    node.phase("assign");
    node.compute(&work).await;
    Assignment::greedy(&estimates, &initial)
}

/// Per-region triangle counts of `tris` (the classification `Redistributor::place` also
/// does, which is where it is charged).
pub(crate) fn region_counts(ctx: &Ctx, tris: &[ScreenTriangle]) -> Vec<u32> {
    let mut counts = vec![0; ctx.settings.grid.count() as usize];
    let mut touched = Vec::new();
    for tri in tris {
        touched.clear();
        ctx.settings.grid.touched_by(tri, &mut touched);
        for &r in &touched {
            counts[r as usize] += 1;
        }
    }
    counts
}

/// Transforms this processor's share of the frame (every n-th polygon) one batch at a time,
/// handing each batch's screen triangles to `place`, which returns the messages to send.
pub(crate) async fn transform<P>(
    node: &Node<Msg>,
    ctx: &Ctx,
    frame: u32,
    mut place: P,
) -> Result<(), SimError>
where
    P: FnMut(&[ScreenTriangle], &mut Counts) -> Vec<redistribute::Outgoing>,
{
    node.phase("transform");
    let geometry = ctx.geometry(node, frame)?;
    let vertices = ctx.vertices(node, frame)?;
    // Triangles node.id(), node.id() + n, ... in batches of ctx.batch(), set up in one pass
    // for every processor (see `dealing`).
    let dealt = ctx.dealer.take(frame, node.id(), || {
        ctx.book
            .take_dealt(frame)
            .unwrap_or_else(|| ctx.deal().over(&geometry, &mut vertices.borrow_mut()))
    });
    drop((geometry, vertices));
    for (tris, c) in dealt.batches() {
        ctx.record(frame, |r| {
            r.triangles_in_view += c.triangles_in - c.culled_outside - c.culled_invalid
        });
        let mut work = charge::front_end(&c);
        let out = place(tris, &mut work);
        node.compute(&work).await;
        redistribute::send_all(node, ctx, out).await;
    }
    Ok(())
}

/// What a rasterizing processor waits for besides its own triangles.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Incoming {
    /// Screen triangles, until this many senders have ended their streams (sort-middle).
    Streams(u32),
    /// This many messages of database records, which it transforms itself (sort-first).
    Records(u32),
}

/// Rasterizes a sort-middle frame's polygons: those this processor kept for its own regions,
/// then every stream the redistribution `polygons` is sending it, as they arrive.
pub(crate) async fn rasterize_redistributed(
    node: &Node<Msg>,
    ctx: &Ctx,
    frame: u32,
    assignment: &Assignment,
    polygons: &RefCell<redistribute::Redistributor>,
) -> Result<RegionSet, SimError> {
    let (local, streams) = {
        let mut p = polygons.borrow_mut();
        (std::mem::take(&mut p.local), p.expected_streams())
    };
    let incoming = Incoming::Streams(streams);
    let (regions, _) = rasterize(node, ctx, frame, assignment, local, incoming).await?;
    Ok(regions)
}

/// Rasterizes this processor's regions: its own triangles, then what `incoming` says to wait
/// for. Returns the regional image (resolved from the samples when anti-aliasing) and the
/// primitives whose records arrived.
pub(crate) async fn rasterize(
    node: &Node<Msg>,
    ctx: &Ctx,
    frame: u32,
    assignment: &Assignment,
    local: Vec<ScreenTriangle>,
    incoming: Incoming,
) -> Result<(RegionSet, Vec<u32>), SimError> {
    node.phase("rasterize");
    let me = node.id();
    let rects: Vec<_> = assignment
        .regions_of(me)
        .iter()
        .map(|&r| ctx.settings.grid.rect(r))
        .collect();
    let grid = ctx.aa_grid.borrow()[me as usize];
    let mut canvas = Canvas::new(
        node,
        &ctx.settings.aa,
        grid,
        ctx.viewport,
        rects,
        ctx.background,
    )?;
    let charges = canvas.charges();
    for &(tag, bytes) in &charges {
        node.alloc(tag, bytes)?;
    }
    node.compute(&Counts::of(Op::ClearPixel, canvas.clear_count()))
        .await;
    for batch in local.chunks(ctx.batch()) {
        let c = draw_screen_triangles(batch, canvas.target());
        node.compute(&charge::back_end(&c)).await;
    }
    let mut received = Vec::new();
    match incoming {
        Incoming::Streams(streams) => {
            let mut arrivals = redistribute::Streams::new(ctx.n);
            let mut waited = SimTime::ZERO;
            while arrivals.ended() < streams {
                let asked = node.now();
                let env = node.recv(Filter::tag(TAG_POLYGONS)).await;
                waited += env.arrived.saturating_sub(asked);
                let Msg::Polygons {
                    frame: f,
                    tris,
                    end,
                } = env.payload
                else {
                    unreachable!("filtered by tag")
                };
                debug_assert_eq!(f, frame, "a polygon message crossed a frame boundary");
                let c = draw_screen_triangles(&tris, canvas.target());
                node.compute(&charge::back_end(&c)).await;
                arrivals.arrived(env.src, end);
            }
            ctx.record(frame, |r| r.polygon_wait[me as usize] = waited);
        }
        Incoming::Records(messages) => {
            let geometry = ctx.geometry(node, frame)?;
            let vertices = ctx.vertices(node, frame)?;
            let mut tris = Vec::new();
            for _ in 0..messages {
                let env = node.recv(Filter::tag(TAG_RECORDS)).await;
                let Msg::Records { prims, .. } = env.payload else {
                    unreachable!("filtered by tag")
                };
                tris.clear();
                let front = setup_subset(
                    &geometry.vertices,
                    &geometry.triangles,
                    &prims,
                    &mut vertices.borrow_mut(),
                    &ctx.raster,
                    &mut tris,
                );
                let back = draw_screen_triangles(&tris, canvas.target());
                let mut work = charge::front_end(&front);
                work += &charge::back_end(&back);
                node.compute(&work).await;
                received.extend_from_slice(&prims);
            }
        }
    }
    let (image, resolve, stats) = canvas.finish();
    node.compute(&charge::back_end(&resolve)).await;
    if let Some(stats) = stats {
        // Memory adaptation (paper 000): this frame's demand picks the next frame's grid.
        ctx.aa_grid.borrow_mut()[me as usize] = adapt(&stats);
        let n = ctx.n as usize;
        ctx.record(frame, |r| {
            r.aa.resize(n, Default::default());
            r.aa[me as usize] = stats;
        });
    }
    let now = node.now();
    ctx.record(frame, |r| r.raster_finish[me as usize] = now);
    for &(tag, bytes) in &charges {
        node.free(tag, bytes)?;
    }
    Ok((image, received))
}

/// Checks a variant's `choice` against the machine and the screen.
fn settings(cfg: &RunConfig, choice: Choice, viewport: Viewport) -> Result<Settings, RunError> {
    let o = &cfg.options;
    let n = cfg.machine.nodes;
    let costs = &cfg.machine.cpu.costs;
    let default_estimate = costs.get(Op::SetupTriangle)
        + costs.get(Op::Span).times(3)
        + (costs.get(Op::PixelTest) + costs.get(Op::PixelWrite)).times(6);
    let grid = match choice.regions {
        RegionChoice::Side(side) => RegionGrid::of_size(viewport, side),
        RegionChoice::PerProcessor(granularity) => {
            // A product past u32 is far more regions than pixels, refused as such.
            let count = granularity.checked_mul(n);
            count
                .and_then(|c| RegionGrid::with_count(viewport, c))
                .ok_or_else(|| {
                    bad(
                        o,
                        "granularity",
                        &format!(
                            "at most {} regions fit a {}x{} screen",
                            viewport.pixels(),
                            viewport.width(),
                            viewport.height()
                        ),
                    )
                })?
        }
    };
    let buffer = choice.buffer;
    if buffer.get() < buffers::HEADER_BYTES + choice.record_bytes {
        return Err(bad(
            o,
            "buffer",
            &format!(
                "a buffer of at least {}B (one triangle)",
                buffers::HEADER_BYTES + choice.record_bytes
            ),
        ));
    }
    let groups = match choice.two_step {
        TwoStep::On => Some(Groups::near_sqrt(n)),
        TwoStep::Auto => two_step_pays(cfg, buffer).then(|| Groups::near_sqrt(n)),
        TwoStep::Off => None,
    };
    let aa = aa_settings(o, &choice.aa)?;
    super::aa::check_prices(cfg, &aa)?;
    if let AaMethod::Supersample { side } = aa.method {
        super::aa::sample_grid(cfg, viewport, side)?;
    }
    // Samples away from pixel centres: a triangle reaches every region its bounds overlap.
    let grid = match aa.method {
        AaMethod::None => grid,
        AaMethod::Adaptive | AaMethod::Supersample { .. } => grid.sampling_whole_pixels(),
    };
    Ok(Settings {
        grid,
        buffer,
        counts: choice.counts,
        groups,
        polygon_estimate: choice.polygon_estimate.unwrap_or(default_estimate),
        aa,
        first: choice.first,
    })
}

/// The performance model's verdict on two-step redistribution (paper 002: "an implementation
/// can determine this automatically"): per processor, one-step pays N-1 message overheads at
/// least; two-step pays (g-1) + (N/g - 1) but copies and sends every polygon twice.
fn two_step_pays(cfg: &RunConfig, buffer: Bytes) -> bool {
    let n = cfg.machine.nodes as u64;
    if n < 4 {
        return false;
    }
    let cpu = &cfg.machine.cpu;
    let per_message = cpu.send_overhead + cpu.recv_overhead;
    let tris = cfg.scene.triangle_count() as u64 / n + 1;
    let bytes = tris * buffers::TRIANGLE_BYTES;
    let messages = |streams: u64, bytes: u64| streams.max(bytes.div_ceil(buffer.get()));
    let g = Groups::near_sqrt(cfg.machine.nodes);
    let one_step = per_message.times(messages(n - 1, bytes));
    let (groups, members) = (g.count() as u64, n / g.count() as u64);
    let two_step = per_message.times(messages(groups - 1, bytes) + messages(members - 1, bytes))
        + (cpu.send_per_byte + cpu.recv_per_byte + cpu.costs.get(Op::ByteCopy)).times(bytes);
    two_step < one_step
}

/// Checks a variant's `choice` against `cfg` without running it.
pub(crate) fn check(cfg: &RunConfig, choice: Choice) -> Result<(), RunError> {
    let first = cfg.scene.frame(cfg.frames.start)?;
    settings(cfg, choice, super::reference::viewport(&first)).map(|_| ())
}

/// Runs `program` on every processor with the settings of `choice`; `dealt` when its
/// processors take their front end from `transform` (sort-middle), which the run's later
/// frames then have made ahead.
pub(crate) fn run<F, Fut>(
    cfg: &RunConfig,
    choice: Choice,
    dealt: bool,
    program: F,
) -> Result<RunResult, RunError>
where
    F: Fn(Node<Msg>, Rc<Ctx>) -> Fut,
    Fut: std::future::Future<Output = Result<(), SimError>> + 'static,
{
    // Any processor may own a region any other one's triangles touch.
    super::routes::require_all_pairs(cfg, &super::routes::network(cfg)?)?;
    let first = cfg.scene.frame(cfg.frames.start)?;
    let viewport = super::reference::viewport(&first);
    let settings = settings(cfg, choice, viewport)?;
    let settings_start = settings.aa.start;
    let n = cfg.machine.nodes;
    let raster = super::reference::raster_options(&first);
    let deal = dealt.then(|| deal_of(&settings, n, raster));
    let ctx = Rc::new(Ctx {
        settings,
        n,
        cfg: cfg.clone(),
        viewport,
        background: first.background,
        raster,
        book: FrameBook::new(cfg, viewport, Rc::new(first), deal),
        dealer: dealing::Dealer::default(),
        first_assignment: RefCell::default(),
        next_assignment: RefCell::default(),
        images: RefCell::new(vec![None; n as usize]),
        holders: Default::default(),
        aa_grid: RefCell::new(vec![settings_start; n as usize]),
    });
    let stats = simulate(cfg, &ctx, program)?;
    let mut image = Framebuffer::with_clear(viewport, ctx.background);
    for regions in ctx.images.borrow().iter().flatten() {
        regions.copy_into(&mut image);
    }
    let frames = ctx.book.records();
    Ok(RunResult {
        stats,
        frames,
        image,
    })
}
