//! Sort-first (Mueller 1995) as one processor's program.
//!
//! ```text
//! my primitives = every N-th of the database (before the first frame)
//! for (each frame) {
//!   synchronize; take the region assignment (fixed, or packed from last frame's counts)
//!   for (each primitive I hold) {
//!     transform it; find the processors whose regions it touches now
//!     if it touches mine: keep it, and its screen triangles for rasterizing
//!     if I am its first holder: send its database record to each of them that does not
//!       hold it (buffered per destination, or at once)
//!   }
//!   learn how many record messages are coming (counts summed up the tree and sent back down)
//!   rasterize my regions: my kept triangles, then each arriving record, transformed here
//!   send my regions' pixels to processor 0; with adaptive regions, sum per-region counts
//!   up the tree and let processor 0 pack the next frame's assignment
//! }
//! ```
//!
//! What moves is the primitive's database record (`DATABASE_BYTES_PER_TRIANGLE`), not its
//! screen-space form: the receiver transforms it again. The first frame is a full
//! distribution (the deal knows nothing of the screen); after it only primitives that cross
//! into regions of processors that did not hold them move, so a still camera moves nothing.
//! A primitive that touches no region (off screen, culled) stays with its first holder.
//! Each processor's pool holds the records it keeps ("database"), so the per-node memory
//! shows sort-first's imbalance when geometry gathers on a few regions.
//!
//! Must never reach into the mechanisms' state: it only calls them.

use std::rc::Rc;

use crate::algo::charge;
use crate::algo::image_space::assign::Assignment;
use crate::algo::image_space::buffers::HEADER_BYTES;
use crate::algo::image_space::{
    children, collect_image, compute_assignment, finish_frame, parent, rasterize, start_frame,
    sum_counts, Ctx, Incoming, Msg, DATABASE_BYTES_PER_TRIANGLE, TAG_EXPECT_DOWN, TAG_EXPECT_UP,
};
use crate::engine::{Filter, Node, SimError};
use crate::machine::{Counts, Op};
use crate::raster::{setup_subset, ScreenTriangle};
use crate::units::Bytes;

use crate::algo::image_space::options::{Migrate, RegionRule};

pub(crate) async fn processor(node: Node<Msg>, ctx: Rc<Ctx>) -> Result<(), SimError> {
    let me = node.id();
    let n = ctx.n;
    let regions = ctx.settings.grid.count();
    let mut assignment = ctx.first_assignment(|| Assignment::interleaved(regions, n));
    let buffers = ctx.settings.buffer * u64::from(n - 1);
    node.alloc("record buffers", buffers)?;
    let prims = ctx.cfg.scene.triangle_count() as u32;
    let mut held: Vec<u32> = (me..prims).step_by(n as usize).collect();
    let mut database = records(held.len());
    node.alloc("database", database)?;
    for frame in ctx.frames() {
        node.phase("synchronize");
        let update = if me == 0 {
            ctx.next_assignment.borrow_mut().take()
        } else {
            None
        };
        if let Some(new) = start_frame(&node, &ctx, frame, update).await {
            assignment = new;
        }

        let sorted = transform(&node, &ctx, frame, &assignment, &held).await?;
        node.phase("exchange counts");
        let expected = expect(&node, &ctx, frame, &sorted.sent).await;
        let (image, received) = rasterize(
            &node,
            &ctx,
            frame,
            &assignment,
            sorted.local,
            Incoming::Records(expected),
        )
        .await?;
        let mut keep = sorted.keep;
        keep.extend(received);
        keep.sort_unstable();
        keep.dedup();
        node.free("database", database)?;
        database = records(keep.len());
        node.alloc("database", database)?;
        ctx.holders.keep(frame, me, &keep);
        held = keep;

        collect_image(&node, &ctx, frame, &image).await;
        if ctx.is_last(frame) {
            ctx.images.borrow_mut()[me as usize] = Some(image);
        }
        if ctx.settings.first.regions == RegionRule::Adaptive && !ctx.is_last(frame) {
            node.phase("load balance");
            if let Some(total) = sum_counts(&node, &ctx, frame, sorted.counts).await {
                let next = compute_assignment(&node, &ctx, &total).await;
                *ctx.next_assignment.borrow_mut() = Some(Rc::new(next));
            }
        }
        node.phase("synchronize");
        finish_frame(&node, &ctx, frame).await;
    }
    node.free("record buffers", buffers)?;
    node.free("database", database)?;
    Ok(())
}

/// The memory of `count` database records.
fn records(count: usize) -> Bytes {
    Bytes::new(count as u64 * DATABASE_BYTES_PER_TRIANGLE)
}

/// What transforming this processor's primitives decided.
struct Sorted {
    /// Screen triangles for my regions.
    local: Vec<ScreenTriangle>,
    /// Primitives I keep for the next frame (besides those that arrive).
    keep: Vec<u32>,
    /// Record messages sent to each processor.
    sent: Vec<u32>,
    /// Per region, screen triangles touching it, of the primitives I am first holder of.
    counts: Vec<u32>,
}

/// Transforms the held primitives batch by batch, keeping what falls in my regions and
/// sending records to the processors that need them.
async fn transform(
    node: &Node<Msg>,
    ctx: &Ctx,
    frame: u32,
    assignment: &Assignment,
    held: &[u32],
) -> Result<Sorted, SimError> {
    node.phase("transform");
    let me = node.id();
    let n = ctx.n;
    let geometry = ctx.geometry(node, frame)?;
    let vertices = ctx.vertices(node, frame)?;
    let prims = geometry.triangles.len();
    let grid = &ctx.settings.grid;
    let mut sorted = Sorted {
        local: Vec::new(),
        keep: Vec::new(),
        sent: vec![0; n as usize],
        counts: vec![0; grid.count() as usize],
    };
    let mut out = Outbox::new(ctx);
    let mut moved = 0u64;
    let (mut tris, mut touched, mut owners) = (Vec::new(), Vec::new(), Vec::new());
    for batch in held.chunks(ctx.batch()) {
        let holders: Vec<Vec<u32>> = batch
            .iter()
            .map(|&p| ctx.holders.holders(frame, p, n, prims))
            .collect();
        // First holders count the primitive as in view; every holder transforms it.
        let (mut first, mut copies) = (Vec::new(), Vec::new());
        for (&p, h) in batch.iter().zip(&holders) {
            if h[0] == me {
                first.push((p, h.as_slice()));
            } else {
                copies.push((p, h.as_slice()));
            }
        }
        let mut work = Counts::new();
        for (entries, is_first) in [(&first, true), (&copies, false)] {
            let list: Vec<u32> = entries.iter().map(|&(p, _)| p).collect();
            tris.clear();
            let c = setup_subset(
                &geometry.vertices,
                &geometry.triangles,
                &list,
                &mut vertices.borrow_mut(),
                &ctx.raster,
                &mut tris,
            );
            work += &charge::front_end(&c);
            if is_first {
                ctx.record(frame, |r| {
                    r.triangles_in_view += c.triangles_in - c.culled_outside - c.culled_invalid
                });
            }
            let mut at = 0;
            for &(p, h) in entries.iter() {
                let end = at + tris[at..].iter().take_while(|t| t.prim() == p).count();
                let mine = &tris[at..end];
                at = end;
                owners.clear();
                for t in mine {
                    touched.clear();
                    grid.touched_by(t, &mut touched);
                    work.add(Op::RegionCount, touched.len() as u64);
                    for &r in &touched {
                        owners.push(assignment.owner[r as usize]);
                        if is_first {
                            sorted.counts[r as usize] += 1;
                        }
                    }
                }
                owners.sort_unstable();
                owners.dedup();
                if owners.binary_search(&me).is_ok() {
                    sorted.local.extend_from_slice(mine);
                    sorted.keep.push(p);
                }
                if is_first {
                    if owners.is_empty() {
                        sorted.keep.push(p);
                    }
                    for &q in owners.iter().filter(|&&q| q != me && !h.contains(&q)) {
                        out.add(q, p);
                        moved += 1;
                    }
                }
            }
        }
        work.add(Op::ByteCopy, out.added_bytes());
        node.compute(&work).await;
        let flush_all = ctx.settings.first.migrate == Migrate::Immediate;
        out.send(node, ctx, frame, flush_all, &mut sorted.sent)
            .await;
    }
    out.send(node, ctx, frame, true, &mut sorted.sent).await;
    ctx.record(frame, |r| {
        *r.records_moved.get_or_insert(0) += moved;
    });
    Ok(sorted)
}

/// Records waiting per destination, sent a buffer at a time.
struct Outbox {
    pending: Vec<Vec<u32>>,
    /// Records per message: a buffer's worth.
    per_message: usize,
    added: u64,
}

impl Outbox {
    fn new(ctx: &Ctx) -> Outbox {
        let room = ctx.settings.buffer.get().saturating_sub(HEADER_BYTES);
        Outbox {
            pending: vec![Vec::new(); ctx.n as usize],
            per_message: (room / DATABASE_BYTES_PER_TRIANGLE).max(1) as usize,
            added: 0,
        }
    }

    fn add(&mut self, dst: u32, prim: u32) {
        self.pending[dst as usize].push(prim);
        self.added += 1;
    }

    /// Bytes copied into buffers since the last call.
    fn added_bytes(&mut self) -> u64 {
        std::mem::take(&mut self.added) * DATABASE_BYTES_PER_TRIANGLE
    }

    /// Sends every full buffer, and with `all` the partly filled ones too, destinations in
    /// order starting after this processor (so senders do not all start at processor 0).
    async fn send(&mut self, node: &Node<Msg>, ctx: &Ctx, frame: u32, all: bool, sent: &mut [u32]) {
        let (me, n) = (node.id(), ctx.n);
        for k in 1..n {
            let dst = (me + k) % n;
            let pending = &mut self.pending[dst as usize];
            while pending.len() >= self.per_message || (all && !pending.is_empty()) {
                let take = pending.len().min(self.per_message);
                let prims: Vec<u32> = pending.drain(..take).collect();
                ctx.send(node, dst, Msg::Records { frame, prims }).await;
                sent[dst as usize] += 1;
            }
        }
    }
}

/// Sums the record messages sent to each processor up the tree and sends the totals back
/// down; returns how many this processor will receive.
async fn expect(node: &Node<Msg>, ctx: &Ctx, frame: u32, sent: &[u32]) -> u32 {
    let me = node.id();
    let mut total = sent.to_vec();
    for child in children(me, ctx.n) {
        let env = node
            .recv(Filter::tag(TAG_EXPECT_UP).and_source(child))
            .await;
        let Msg::Expect { counts, .. } = env.payload else {
            unreachable!("filtered by tag")
        };
        for (a, b) in total.iter_mut().zip(counts.iter()) {
            *a += b;
        }
        node.compute(&Counts::of(Op::CountSum, total.len() as u64))
            .await;
    }
    let totals = if me == 0 {
        Rc::new(total)
    } else {
        let up = Msg::Expect {
            frame,
            up: true,
            counts: Rc::new(total),
        };
        ctx.send(node, parent(me), up).await;
        let env = node
            .recv(Filter::tag(TAG_EXPECT_DOWN).and_source(parent(me)))
            .await;
        let Msg::Expect { counts, .. } = env.payload else {
            unreachable!("filtered by tag")
        };
        counts
    };
    for child in children(me, ctx.n) {
        let down = Msg::Expect {
            frame,
            up: false,
            counts: totals.clone(),
        };
        ctx.send(node, child, down).await;
    }
    totals[me as usize]
}
