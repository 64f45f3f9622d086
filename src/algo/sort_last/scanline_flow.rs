//! ScanlineFlow rasterization (paper 001, section 4.2, SLMF-full) as one node's program.
//!
//! ```text
//! first pass: transform my share, bucket sort it by first scanline
//! second pass, for each scanline y (top to bottom):
//!   render y from my active polygon list into a scanline buffer
//!   receive scanline y from node i-1 (all its pixels, active or not), z-merge it with mine
//!   pass the merged scanline to node i+1; node N-1 holds the image
//! ```
//!
//! Node i works on scanline y while node i-1 is on y+1: a triple buffer (one scanline being
//! received, one merged, one sent) becomes a credit scheme of two scanlines in flight into
//! each node; a node sends scanline y itself right after merging it (the send costs the cpu
//! only its overhead, the link carries it while the next scanline is rendered). Rendering uses the scanline z-buffer renderer, so the image is the sequential
//! z-buffer's bit for bit.
//!
//! Costs per scanline: clearing it, setting up the triangles it activates, visiting every
//! active triangle, and inserting each newly active triangle into the active list by walking
//! it (a sorted linked list: `active_list_op` per element passed, half the list on average).
//! That insertion cost is what makes the sequential scanline renderer superlinear in the
//! triangles per scanline, as paper 001 says of its own implementation.
//!
//! Must never hold full frames on the host: scanlines carry active pixels only.

use std::collections::BTreeMap;
use std::rc::Rc;

use super::full_frame::{self, tag, Msg, CHUNK, CONTROL_BYTES, CREDIT};
use super::pixel::ShippedPixel;
use super::{local, Ctx};
use crate::algo::charge;
use crate::engine::{Filter, Node, SimError};
use crate::machine::{Counts, Op};
use crate::raster::{
    draw_screen_triangles, render_scanlines_counted, setup_subset, Counters, Sampling, ScreenRect,
    ScreenTriangle, Span, Target,
};
use crate::units::Bytes;

/// Scanlines that may be in flight into a node (with the one being merged: a triple buffer).
pub const IN_FLIGHT: u32 = 2;

/// Bytes of one bucket-sorted triangle as the first pass stores it.
pub const BUCKET_BYTES_PER_TRIANGLE: u64 = ScreenTriangle::PAYLOAD_BYTES as u64 + 4;

/// One rendered scanline of this node: what rendering it costs and its active pixels.
struct Line<P> {
    work: Counts,
    pixels: Vec<P>,
}

/// Renders `tris` scanline by scanline on the host and prices each scanline: the scanline
/// renderer's own work per line (clearing it, setting up and walking the active triangle
/// list, spans) from the scanline pass, and the pixels' work (depth tests and writes, and
/// with adaptive anti-aliasing coverage masks and subpixel work) from the run's buffer,
/// counted row by row. The pixels are that buffer's.
fn render_lines<P: ShippedPixel>(
    ctx: &Ctx,
    frame: u32,
    node: u32,
    tris: &[ScreenTriangle],
) -> (Vec<Line<P>>, Counters) {
    // Scanlines are the screen's; with supersampling each carries `side` rows of samples,
    // which travel as rows of the merge grid (the first of them charged the scanline's work).
    let side = ctx.settings.side;
    let width = ctx.viewport.width();
    let height = ctx.screen.height() as usize;
    let mut structure = Vec::with_capacity(height);
    let mut prev = Counters::default();
    let total = render_scanlines_counted(tris, ctx.screen, ctx.background, |_, c| {
        let inserts = c.active_inserts - prev.active_inserts;
        // The list while this scanline is drawn: everything inserted, minus what earlier
        // scanlines removed.
        let length = c.active_inserts - prev.active_removals;
        let mut work = Counts::new();
        work.add(Op::ClearPixel, u64::from(width * side))
            .add(
                Op::SetupTriangle,
                c.triangles_scanned - prev.triangles_scanned,
            )
            .add(Op::ActiveListOp, length + inserts * length / 2)
            .add(Op::Span, c.spans - prev.spans);
        structure.push(work);
        prev = *c;
    });
    let mut target = RowCounted {
        inner: P::buffer(ctx, frame),
        rows: vec![Counters::default(); height],
    };
    draw_screen_triangles(tris, &mut target);
    let mut pixels = P::collect(target.inner, ctx, node).into_iter().peekable();
    let mut lines = Vec::with_capacity(height * side as usize);
    for (mut work, row) in structure.into_iter().zip(&target.rows) {
        work += &charge::back_end(row);
        for _ in 0..side {
            let end = (lines.len() as u32 + 1) * width;
            let mut line = Vec::new();
            while let Some(p) = pixels.next_if(|p| p.loc() < end) {
                line.push(p);
            }
            lines.push(Line {
                work: std::mem::take(&mut work),
                pixels: line,
            });
        }
    }
    (lines, total)
}

/// A target that also counts what its inner target does, row by row.
struct RowCounted<T> {
    inner: T,
    rows: Vec<Counters>,
}

impl<T: Target> Target for RowCounted<T> {
    fn rects(&self) -> &[ScreenRect] {
        self.inner.rects()
    }
    fn sampling(&self) -> Sampling {
        self.inner.sampling()
    }
    fn span(&mut self, rect: usize, span: &Span<'_>, counters: &mut Counters) {
        let mut c = Counters::default();
        self.inner.span(rect, span, &mut c);
        self.rows[span.y() as usize] += c;
        *counters += c;
    }
}

pub(super) async fn processor<P: ShippedPixel>(
    node: Node<Msg<P>>,
    ctx: Rc<Ctx>,
) -> Result<(), SimError> {
    let me = node.id();
    let n = ctx.n;
    let h = ctx.viewport.height();
    let width = ctx.viewport.width() as u64;
    for frame in ctx.frames() {
        full_frame::start_frame(&node, &ctx, frame).await?;
        node.phase("bucket sort");
        let geometry = ctx.geometry(&node, frame)?;
        let share = ctx.share(&node, frame)?;
        let mut tris = Vec::new();
        let front = setup_subset(
            &geometry.vertices,
            &geometry.triangles,
            &share,
            &mut ctx.vertices(&node, frame)?.borrow_mut(),
            &ctx.raster,
            &mut tris,
        );
        ctx.record(frame, |r| {
            r.triangles_in_view += front.triangles_in - front.culled_outside - front.culled_invalid
        });
        let (lines, total) = render_lines::<P>(&ctx, frame, me, &tris);
        let buckets = Bytes::new(total.bucket_inserts * BUCKET_BYTES_PER_TRIANGLE);
        node.alloc("bucket-sorted triangles", buckets)?;
        let mut work = charge::front_end(&front);
        work.add(Op::BucketInsert, total.bucket_inserts);
        node.compute(&work).await;
        drop(tris);

        node.phase("scanlines");
        let line_bytes = ctx.rows_bytes(1);
        let buffers = Bytes::new(3 * line_bytes.get());
        node.alloc("scanline triple buffer", buffers)?;
        let mut image: Option<Vec<P>> = (me == n - 1).then(Vec::new);
        let mut early = BTreeMap::new();
        for (y, line) in lines.into_iter().enumerate() {
            let y = y as u32;
            node.compute(&line.work).await;
            if y + 1 == h {
                local::raster_finished(&node, &ctx, frame);
            }
            let merged = if me == 0 {
                line.pixels
            } else {
                let pixels = scanline(&node, frame, y, &mut early).await;
                let merged = ctx.merge_rows(&node, &pixels, &line.pixels, width).await;
                let credit = Msg::Credit { frame };
                ctx.send(&node, frame, me - 1, Bytes::new(CONTROL_BYTES), credit)
                    .await;
                merged
            };
            match &mut image {
                Some(image) => image.extend(merged),
                None => {
                    // The send costs the cpu its overhead; the link carries the scanline
                    // while the next one is rendered.
                    if y >= IN_FLIGHT {
                        node.recv(Filter::tag(tag(CREDIT, frame)).and_source(me + 1))
                            .await;
                    }
                    full_frame::send_chunk(&node, &ctx, frame, me + 1, (y, y + 1), merged).await;
                }
            }
        }
        node.free("scanline triple buffer", buffers)?;
        node.free("bucket-sorted triangles", buckets)?;
        ctx.end_aa(&node, frame)?;
        if let Some(image) = image {
            full_frame::end_frame(&node, &ctx, frame, &image).await?;
        }
    }
    Ok(())
}

/// Scanline `y` from node i-1. Scanlines carrying super pixels differ in size and may
/// overtake each other; one that arrives before its turn waits in `early`.
async fn scanline<P: ShippedPixel>(
    node: &Node<Msg<P>>,
    frame: u32,
    y: u32,
    early: &mut BTreeMap<u32, Vec<P>>,
) -> Vec<P> {
    if let Some(pixels) = early.remove(&y) {
        return pixels;
    }
    loop {
        let env = node
            .recv(Filter::tag(tag(CHUNK, frame)).and_source(node.id() - 1))
            .await;
        let Msg::Chunk { y0, pixels, .. } = env.payload else {
            unreachable!("filtered by tag")
        };
        if y0 == y {
            return pixels;
        }
        early.insert(y0, pixels);
    }
}
