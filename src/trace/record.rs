//! Recording a pixel trace: draws one scene frame with the reference front end into a
//! recording sparse buffer, so every fragment is captured before the depth test, in the
//! order the rasterizer generates it (paper 003, section 2: "at the sites at which pixels are
//! generated, and before they are z-buffered").
//!
//! Must never filter, reorder or depth-test fragments: the trace is the rasterizer's output
//! as is.

use super::format::{Trace, TraceMeta};
use crate::algo::reference::{raster_options, viewport};
use crate::raster::{draw_mesh, SparseBuffer};
use crate::scene::{FrameGeometry, Scene, SceneError};

/// The trace of one frame's geometry (`frame` is the number stored in the header).
pub fn record_frame(geometry: &FrameGeometry, frame: u32) -> Trace {
    let vp = viewport(geometry);
    let mut buffer = SparseBuffer::recording(vp);
    draw_mesh(
        &geometry.vertices,
        &geometry.triangles,
        vp,
        &raster_options(geometry),
        &mut buffer,
    );
    let meta = TraceMeta {
        width: geometry.width,
        height: geometry.height,
        frame,
        primitives: geometry.triangles.len() as u32,
        culled: geometry.cull_backfaces,
    };
    let fragments = buffer.fragments().expect("a recording buffer records");
    Trace::new(meta, fragments)
        .expect("the rasterizer only emits fragments inside the viewport for listed triangles")
}

/// The trace of frame `frame` of `scene`.
pub fn record_scene(scene: &Scene, frame: u32) -> Result<Trace, SceneError> {
    Ok(record_frame(&scene.frame(frame)?, frame))
}
