//! The sequential reference renderer: one processor, one z-buffer, triangles in scene order.
//! `sortsim render` draws with it, and every parallel algorithm's image must equal its
//! image bit for bit (ties in depth go to the lower primitive id in both).
//!
//! Must never charge time: it is the host's renderer, not a simulated one.

use crate::raster::{draw_mesh, Counters, CullMode, Framebuffer, RasterOptions, Viewport};
use crate::scene::FrameGeometry;

/// Front-end options a frame asks for.
pub fn raster_options(frame: &FrameGeometry) -> RasterOptions {
    RasterOptions {
        cull: if frame.cull_backfaces {
            CullMode::Back
        } else {
            CullMode::None
        },
    }
}

pub fn viewport(frame: &FrameGeometry) -> Viewport {
    Viewport::new(frame.width, frame.height).expect("scene specs have a non-zero resolution")
}

/// Draws `frame` into a framebuffer cleared to its background.
pub fn render(frame: &FrameGeometry) -> (Framebuffer, Counters) {
    let vp = viewport(frame);
    let mut fb = Framebuffer::with_clear(vp, frame.background);
    let counters = draw_mesh(
        &frame.vertices,
        &frame.triangles,
        vp,
        &raster_options(frame),
        &mut fb,
    );
    (fb, counters)
}
