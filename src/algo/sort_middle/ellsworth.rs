//! Ellsworth's algorithm (paper 002, Figure 6) as one processor's program.
//!
//! ```text
//! if (processor 0) { compute region assignments; broadcast region assignments }
//! else read region assignments
//! synchronize                                   /* ensure prev. frame finished */
//! for (each polygon) { transform to screen space; place in buffer(s) for processor(s);
//!                      send buffer if full }
//! flush polygon buffers
//! initialize color- and z-buffer for my regions
//! while (there are more polygons to process) { get a buffer full of polygons; render each }
//! ```
//!
//! Incoming polygons wait in the mailbox (the paper's interrupt-driven handler saves them for
//! later); the per-region counts go up a summing tree concurrently with rasterization, and
//! processor 0 assigns the next frame's regions while the others render. With `counts =
//! current` the counts are summed and the regions assigned before any polygon is sent.
//!
//! Must never reach into the mechanisms' state: it only calls them.

use std::cell::RefCell;
use std::rc::Rc;

use crate::algo::image_space::assign::Assignment;
use crate::algo::image_space::redistribute::{self, Redistributor};
use crate::algo::image_space::{
    compute_assignment, finish_frame, rasterize_redistributed, region_counts, start_frame,
    sum_counts, transform, CountsFrom, Ctx, Msg,
};
use crate::engine::{Filter, Node, SimError};
use crate::machine::Counts;
use crate::units::SimTime;

pub(super) async fn processor(node: Node<Msg>, ctx: Rc<Ctx>) -> Result<(), SimError> {
    let me = node.id();
    // The first frame's load balancing: region r goes to processor r mod N.
    let mut assignment =
        ctx.first_assignment(|| Assignment::interleaved(ctx.settings.grid.count(), ctx.n));
    let buffers = ctx.settings.polygon_buffer_memory(me, ctx.n);
    node.alloc("polygon buffers", buffers)?;
    let database = ctx.database_memory(me);
    node.alloc("database", database)?;
    for frame in ctx.frames() {
        node.phase("synchronize");
        let update = if me == 0 {
            ctx.begin_frame(&node, frame);
            ctx.next_assignment.borrow_mut().take()
        } else {
            None
        };
        if let Some(new) = start_frame(&node, &ctx, frame, update).await {
            assignment = new;
        }

        let polygons = match ctx.settings.counts {
            CountsFrom::Previous => {
                let polygons = redistributor(&node, &ctx, frame, &assignment);
                transform(&node, &ctx, frame, |tris, work| {
                    polygons.borrow_mut().place(&ctx, tris, work)
                })
                .await?;
                flush(&node, &ctx, &polygons).await;
                let counts = std::mem::take(&mut polygons.borrow_mut().counts);
                node.spawn(
                    format!("summing tree {me}"),
                    assign_next_frame(node.clone(), ctx.clone(), frame, counts),
                );
                polygons
            }
            CountsFrom::Current => {
                let mut screen = Vec::new();
                transform(&node, &ctx, frame, |tris, _| {
                    screen.extend_from_slice(tris);
                    Vec::new()
                })
                .await?;
                node.phase("load balance");
                let total = sum_counts(&node, &ctx, frame, region_counts(&ctx, &screen)).await;
                let new = match total {
                    Some(total) => Some(Rc::new(compute_assignment(&node, &ctx, &total).await)),
                    None => None,
                };
                node.phase("synchronize");
                if let Some(new) = start_frame(&node, &ctx, frame, new).await {
                    assignment = new;
                }
                node.phase("transform");
                let polygons = redistributor(&node, &ctx, frame, &assignment);
                let mut work = Counts::new();
                let out = polygons.borrow_mut().place(&ctx, &screen, &mut work);
                node.compute(&work).await;
                redistribute::send_all(&node, &ctx, out).await;
                flush(&node, &ctx, &polygons).await;
                polygons
            }
        };

        let regions = rasterize_redistributed(&node, &ctx, frame, &assignment, &polygons).await?;
        if ctx.is_last(frame) {
            ctx.images.borrow_mut()[me as usize] = Some(regions);
        }

        node.phase("synchronize");
        finish_frame(&node, &ctx, frame).await;
        if me == 0 && ctx.settings.counts == CountsFrom::Previous && !ctx.is_last(frame) {
            // Figure 6's loop starts with the assignment, so waiting for the summing tree
            // and processor 0's packing is the next frame's time, as in a frame rate.
            ctx.begin_frame(&node, frame + 1);
            node.recv(Filter::tag(crate::algo::image_space::TAG_ASSIGNED))
                .await;
        }
    }
    node.free("polygon buffers", buffers)?;
    node.free("database", database)?;
    Ok(())
}

/// This frame's redistribution state, with the two-step forwarding handler running when this
/// processor forwards for other groups.
fn redistributor(
    node: &Node<Msg>,
    ctx: &Rc<Ctx>,
    frame: u32,
    assignment: &Rc<Assignment>,
) -> Rc<RefCell<Redistributor>> {
    let polygons = Rc::new(RefCell::new(Redistributor::new(
        ctx,
        node.id(),
        frame,
        assignment.clone(),
    )));
    if polygons.borrow().forwards() {
        node.spawn(
            format!("forwarder {}", node.id()),
            redistribute::forward(node.clone(), ctx.clone(), polygons.clone()),
        );
    }
    polygons
}

/// Ends this processor's own polygon streams.
async fn flush(node: &Node<Msg>, ctx: &Ctx, polygons: &Rc<RefCell<Redistributor>>) {
    let out = polygons.borrow_mut().own_transform_done();
    redistribute::send_all(node, ctx, out).await;
}

/// The summing tree's handler for one frame: passes this subtree's counts up; processor 0
/// then assigns the next frame's regions and tells its own main program.
async fn assign_next_frame(
    node: Node<Msg>,
    ctx: Rc<Ctx>,
    frame: u32,
    counts: Vec<u32>,
) -> Result<(), SimError> {
    node.phase("load balance");
    let total = sum_counts(&node, &ctx, frame, counts).await;
    if let (Some(total), false) = (total, ctx.is_last(frame)) {
        let next = compute_assignment(&node, &ctx, &total).await;
        *ctx.next_assignment.borrow_mut() = Some(Rc::new(next));
        node.post(0, SimTime::ZERO, Msg::Assigned { frame });
    }
    Ok(())
}
