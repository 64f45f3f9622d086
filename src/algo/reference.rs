//! The sequential reference renderer: one processor, one z-buffer, triangles in scene order.
//! `sortsim render` draws with it, and every parallel algorithm's image must equal its
//! image bit for bit (ties in depth go to the lower primitive id in both).
//!
//! Must never charge time: it is the host's renderer, not a simulated one.

use crate::raster::aa::{
    adapt, AaMethod, AaStats, AdaptiveConfig, AdaptiveTarget, Grid, SupersampleTarget,
};
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

/// Draws `frame` with `method`'s anti-aliasing on one full-screen buffer: the image an
/// algorithm run with `aa=<method>` reproduces at any processor count. `supersample:N`: every
/// pixel's N samples at the same positions, depths and colour as sort-middle's regions, box
/// filtered. `adaptive`: paper 000's buffer at 4 x 4 with its default pool (2 x 2 for every
/// pixel), as a run's first frame on one processor; a run whose per-processor pool runs out
/// samples some edge pixels once (its summary counts them as overflowed).
pub fn render_aa(frame: &FrameGeometry, method: AaMethod) -> (Framebuffer, Counters) {
    let vp = viewport(frame);
    let mut fb = Framebuffer::with_clear(vp, frame.background);
    let options = raster_options(frame);
    let mut counters = match method {
        AaMethod::None => return render(frame),
        AaMethod::Supersample { side } => {
            let mut target = SupersampleTarget::full_screen(vp, side, frame.background);
            let mut c = draw_mesh(&frame.vertices, &frame.triangles, vp, &options, &mut target);
            target.resolve_into(&mut fb, &mut c);
            return (fb, c);
        }
        AaMethod::Adaptive => Counters::default(),
    };
    let config = AdaptiveConfig::for_pixels(vp.pixels() as u64);
    let mut target = AdaptiveTarget::full_screen(vp, config, frame.background);
    counters += draw_mesh(&frame.vertices, &frame.triangles, vp, &options, &mut target);
    target.resolve_into(&mut fb, &mut counters);
    (fb, counters)
}

/// Draws each frame on one full-screen adaptive target (paper 000), adapting the subpixel
/// resolution between frames as the algorithms do; each frame's statistics. Without
/// `reclaim`, no pixel gives its block back.
pub fn render_adaptive_sequence<'a>(
    frames: impl IntoIterator<Item = &'a FrameGeometry>,
    reclaim: bool,
) -> Vec<AaStats> {
    let mut grid = Grid::X4;
    frames
        .into_iter()
        .map(|frame| {
            let vp = viewport(frame);
            let mut config = AdaptiveConfig::for_pixels(vp.pixels() as u64);
            config.grid = grid;
            if !reclaim {
                config.reclaim_spread = None;
            }
            let mut target = AdaptiveTarget::full_screen(vp, config, frame.background);
            draw_mesh(
                &frame.vertices,
                &frame.triangles,
                vp,
                &raster_options(frame),
                &mut target,
            );
            let stats = target.stats();
            grid = adapt(&stats);
            stats
        })
        .collect()
}
