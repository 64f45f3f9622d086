//! The rasterizer every algorithm drives: clip, snap to fixed point, set up, scan, write to a
//! target, and count the operations the machine's cost table charges for.
//!
//! Must never read the simulation clock or know about nodes: it turns triangles into pixels
//! and counts, nothing else.

/// A vertex as the scene hands it over: clip-space position as produced by glam's
/// `Mat4::perspective_rh` (visible when 0 <= z <= w, |x|,|y| <= w), and a linear colour in
/// 0..=1 per channel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vertex {
    pub clip: glam::Vec4,
    pub color: glam::Vec3,
}
