//! Paper 000's sort-middle renderer as one processor's program: polygons are distributed
//! evenly for transformation, back-face culling and clipping; only screen coordinates and
//! colours are sent; the screen is cut into 64x64 regions assigned in a fixed interleaved
//! pattern; a root process (processor 0) collects the regional images.
//!
//! ```text
//! wait for the frame to start (root)
//! for (each of my polygons) { transform, cull, clip; send to the owners of its regions }
//! flush buffers
//! rasterize my regions
//! send my regional image to the root; the root waits for every region
//! ```
//!
//! Must never reach into the mechanisms' state: it only calls them.

use std::cell::RefCell;
use std::rc::Rc;

use crate::algo::image_space::assign::Assignment;
use crate::algo::image_space::redistribute::{self, Redistributor};
use crate::algo::image_space::{
    collect_image, finish_frame, rasterize_redistributed, start_frame, transform, Ctx, Msg,
};
use crate::engine::{Node, SimError};
use crate::units::Bytes;

pub(super) async fn processor(node: Node<Msg>, ctx: Rc<Ctx>) -> Result<(), SimError> {
    let me = node.id();
    let grid = &ctx.settings.grid;
    let assignment =
        ctx.first_assignment(|| Assignment::interleaved_2d(grid.cols(), grid.rows(), ctx.n));
    let buffers = ctx.settings.polygon_buffer_memory(me, ctx.n);
    node.alloc("polygon buffers", buffers)?;
    let database = ctx.database_memory(me);
    node.alloc("database", database)?;
    let image_bytes = Bytes::new(ctx.viewport.pixels() as u64 * 3);
    if me == 0 {
        node.alloc("image", image_bytes)?;
    }
    for frame in ctx.frames() {
        node.phase("synchronize");
        start_frame(&node, &ctx, frame, None).await;

        let polygons = Rc::new(RefCell::new(Redistributor::new(
            &ctx,
            me,
            frame,
            assignment.clone(),
        )));
        transform(&node, &ctx, frame, |tris, work| {
            polygons.borrow_mut().place(&ctx, tris, work)
        })
        .await?;
        let out = polygons.borrow_mut().own_transform_done();
        redistribute::send_all(&node, &ctx, out).await;

        let regions = rasterize_redistributed(&node, &ctx, frame, &assignment, &polygons).await?;
        collect_image(&node, &ctx, frame, &regions).await;
        if ctx.is_last(frame) {
            ctx.images.borrow_mut()[me as usize] = Some(regions);
        }

        node.phase("synchronize");
        finish_frame(&node, &ctx, frame).await;
    }
    if me == 0 {
        node.free("image", image_bytes)?;
    }
    node.free("polygon buffers", buffers)?;
    node.free("database", database)?;
    Ok(())
}
