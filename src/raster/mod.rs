//! The rasterizer every algorithm drives: clip, snap to fixed point, set up, scan, write to a
//! target, and count the operations the machine's cost table charges for.
//!
//! Must never read the simulation clock or know about nodes: it turns triangles into pixels
//! and counts, nothing else.
//!
//! The modules are the pipeline, in order:
//! * `clip`: homogeneous clipping (near, far, guard band), shared edges cut identically;
//! * `fixed`: every fixed-point format, the edge functions and the top-left fill rule;
//! * `setup`: project, snap, cull, fan into [`ScreenTriangle`]s (the sort-middle message),
//!   then edge and plane equations ([`RasterTriangle`]);
//! * `scan`: exact spans per row and fragments along them;
//! * `target`: the [`Target`] trait and the buffers fragments land in;
//! * `scanline`: the scanline z-buffer renderer over the same spans;
//! * `counters`, `screen`, `image`: counts, screen coordinate types, PNG and image hash;
//! * `aa`: anti-aliasing targets (paper 000's adaptive supersampling with its bitmask table
//!   and Subpixel pool, and k x k supersampling), resolved to region images.
//!
//! Entry points, by the stage an algorithm runs on a node:
//! * whole pipeline: [`draw_mesh`], [`draw_subset`] (the triangles one node owns);
//! * geometry stage only (sort-middle senders): [`setup_mesh`], [`setup_subset`] produce
//!   [`ScreenTriangle`]s, shipped as [`ScreenTriangle::PAYLOAD_BYTES`]-byte messages
//!   ([`ScreenTriangle::to_bytes`] / [`ScreenTriangle::from_bytes`]);
//! * rasterization stage only (sort-middle receivers): [`draw_screen_triangles`];
//! * scanline z-buffer: [`render_scanlines`] (one finished scanline at a time).
//!
//! Every call returns [`Counters`] for the machine's cost model. Winding: triangles running
//! counter-clockwise on screen are front-facing ([`CullMode::Back`] drops the others).
//!
//! **Invariant:** the same triangles give the same pixels, bit for bit, whichever route
//! they take (whole screen, regions, scanlines, setup on one node and scan on another):
//! coverage, depth and colour are pure integer functions of the snapped triangle and the
//! pixel.
//!
//! **Invariant:** nothing here reads a clock, knows about nodes, or iterates a hash map.
//!
//! ```
//! use glam::{Vec3, Vec4};
//! use sortsim::raster::{draw_mesh, Framebuffer, RasterOptions, Vertex, Viewport};
//! let v = |x: f32, y: f32| Vertex { clip: Vec4::new(x, y, 0.5, 1.0), color: Vec3::new(1.0, 0.0, 0.0) };
//! let verts = [v(-1.0, -1.0), v(1.0, -1.0), v(-1.0, 1.0)];
//! let vp = Viewport::new(8, 8).unwrap();
//! let mut fb = Framebuffer::new(vp);
//! let c = draw_mesh(&verts, &[[0, 1, 2]], vp, &RasterOptions::default(), &mut fb);
//! assert_eq!(c.pixels_written, 28); // below the diagonal; the diagonal is a right edge
//! assert_eq!(fb.color(0, 7), Some([255, 0, 0]));
//! ```

pub mod aa;
mod clip;
pub mod counters;
pub mod fixed;
pub mod image;
pub mod scan;
pub mod scanline;
pub mod screen;
pub mod setup;
pub mod target;

pub use counters::Counters;
pub use fixed::{Depth, Sub};
pub use image::{encode_png, image_hash, write_png, PngError};
pub use scan::{Fragment, RowWalker, Sampling, Span};
pub use scanline::{render_scanlines, render_scanlines_counted, render_scanlines_into};
pub use screen::{ScreenRect, Viewport};
pub use setup::{
    CullMode, RasterOptions, RasterTriangle, ScreenTriangle, ScreenVertex, VertexCache,
};
pub use target::{
    ActivePixel, CountingTarget, FragmentRecord, Framebuffer, PixelBuffer, RegionError, RegionSet,
    ScanlineBuffer, SparseBuffer, Target, ACTIVE_PIXEL_BYTES, BYTES_PER_PIXEL,
};

/// A vertex as the scene hands it over: clip-space position as produced by glam's
/// `Mat4::perspective_rh` (visible when 0 <= z <= w, |x|,|y| <= w), and a linear colour in
/// 0..=1 per channel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vertex {
    pub clip: glam::Vec4,
    pub color: glam::Vec3,
}

/// Draws every triangle of an indexed mesh, in order, into `target`. Triangle `i` of
/// `triangles` has primitive id `i`. Out-of-range indices and non-finite vertices drop the
/// triangle (counted as `culled_invalid`); nothing panics.
pub fn draw_mesh<T: Target + ?Sized>(
    vertices: &[Vertex],
    triangles: &[[u32; 3]],
    viewport: Viewport,
    options: &RasterOptions,
    target: &mut T,
) -> Counters {
    let mut own = new_cache(triangles.len(), vertices.len(), viewport);
    draw_indices(
        vertices,
        triangles,
        0..triangles.len() as u32,
        viewport,
        options,
        own.as_mut(),
        target,
    )
}

/// Draws the triangles whose indices are listed in `subset` (in that order): the triangles
/// one node owns. Primitive ids stay the indices into `triangles`. Vertices are prepared in
/// `cache` (made for `vertices`; its viewport is the one drawn to), which other subsets of
/// the same mesh may share.
pub fn draw_subset<T: Target + ?Sized>(
    vertices: &[Vertex],
    triangles: &[[u32; 3]],
    subset: &[u32],
    cache: &mut VertexCache,
    options: &RasterOptions,
    target: &mut T,
) -> Counters {
    let viewport = cache.viewport();
    draw_indices(
        vertices,
        triangles,
        subset.iter().copied(),
        viewport,
        options,
        Some(cache),
        target,
    )
}

/// Front end only: clips, projects, snaps and culls the listed triangles and appends the
/// resulting screen triangles to `out` (the sort-middle geometry stage), preparing vertices
/// in `cache` as [`draw_subset`] does.
pub fn setup_subset(
    vertices: &[Vertex],
    triangles: &[[u32; 3]],
    subset: &[u32],
    cache: &mut VertexCache,
    options: &RasterOptions,
    out: &mut Vec<ScreenTriangle>,
) -> Counters {
    let mut c = Counters::default();
    setup_subset_into(vertices, triangles, subset, cache, options, out, &mut c);
    c
}

/// [`setup_subset`], its counts added to `c`. Inlined: dealing calls it for one triangle at
/// a time, into its batch's counts (a fresh set of counts per triangle, zeroed and added,
/// cost as much as the triangle's own setup).
#[inline]
pub fn setup_subset_into(
    vertices: &[Vertex],
    triangles: &[[u32; 3]],
    subset: &[u32],
    cache: &mut VertexCache,
    options: &RasterOptions,
    out: &mut Vec<ScreenTriangle>,
    c: &mut Counters,
) {
    let viewport = cache.viewport();
    front_end(
        vertices,
        triangles,
        subset.iter().copied(),
        viewport,
        options,
        Some(cache),
        c,
        |t| out.push(t),
    );
}

/// [`setup_subset`] over the whole mesh, with a cache of its own when it pays.
pub fn setup_mesh(
    vertices: &[Vertex],
    triangles: &[[u32; 3]],
    viewport: Viewport,
    options: &RasterOptions,
    out: &mut Vec<ScreenTriangle>,
) -> Counters {
    let mut own = new_cache(triangles.len(), vertices.len(), viewport);
    let mut c = Counters::default();
    front_end(
        vertices,
        triangles,
        0..triangles.len() as u32,
        viewport,
        options,
        own.as_mut(),
        &mut c,
        |t| out.push(t),
    );
    c
}

/// The front-end loop every entry point shares: clips, projects and snaps the listed
/// triangles (vertices prepared once in `cache` when there is one), handing each screen
/// triangle to `sink` in order. Inlined: dealing calls it for one triangle at a time.
#[allow(clippy::too_many_arguments)]
#[inline]
fn front_end(
    vertices: &[Vertex],
    triangles: &[[u32; 3]],
    indices: impl Iterator<Item = u32>,
    viewport: Viewport,
    options: &RasterOptions,
    mut cache: Option<&mut VertexCache>,
    counters: &mut Counters,
    mut sink: impl FnMut(ScreenTriangle),
) {
    for prim in indices {
        setup_one(
            vertices,
            triangles,
            prim,
            viewport,
            options,
            cache.as_deref_mut(),
            counters,
            &mut sink,
        );
    }
}

/// Back end only: sets up and scans screen triangles (in order) into `target` (the
/// sort-middle rasterization stage).
pub fn draw_screen_triangles<T: Target + ?Sized>(
    tris: &[ScreenTriangle],
    target: &mut T,
) -> Counters {
    let mut c = Counters::default();
    for t in tris {
        draw_screen_triangle(t, target, &mut c);
    }
    c
}

/// Sets up and scans one screen triangle into every rectangle of `target`.
#[inline]
pub fn draw_screen_triangle<T: Target + ?Sized>(
    tri: &ScreenTriangle,
    target: &mut T,
    c: &mut Counters,
) {
    let rt = RasterTriangle::new(tri);
    c.triangles_scanned += 1;
    let sampling = target.sampling();
    for i in 0..target.rects().len() {
        let rect = target.rects()[i];
        let Some(mut walker) = RowWalker::sampled(&rt, rect, sampling) else {
            continue;
        };
        while let Some(row) = walker.next_row() {
            if let Some(span) = row.span {
                c.spans += 1;
                target.span(i, &span, c);
            }
        }
    }
}

#[allow(clippy::too_many_arguments)]
fn draw_indices<T: Target + ?Sized>(
    vertices: &[Vertex],
    triangles: &[[u32; 3]],
    indices: impl Iterator<Item = u32>,
    viewport: Viewport,
    options: &RasterOptions,
    cache: Option<&mut VertexCache>,
    target: &mut T,
) -> Counters {
    let mut front = Counters::default();
    let mut back = Counters::default();
    front_end(
        vertices,
        triangles,
        indices,
        viewport,
        options,
        cache,
        &mut front,
        |t| draw_screen_triangle(&t, target, &mut back),
    );
    front + back
}

#[allow(clippy::too_many_arguments)]
fn setup_one(
    vertices: &[Vertex],
    triangles: &[[u32; 3]],
    prim: u32,
    viewport: Viewport,
    options: &RasterOptions,
    cache: Option<&mut VertexCache>,
    c: &mut Counters,
    emit: impl FnMut(ScreenTriangle),
) {
    match (triangles.get(prim as usize), cache) {
        (Some(&tri), Some(cache)) => {
            setup::setup_triangle_cached(vertices, cache, tri, prim, options, c, emit)
        }
        (Some(&tri), None) => {
            setup::setup_triangle(vertices, tri, prim, viewport, options, c, emit)
        }
        (None, _) => {
            c.triangles_in += 1;
            c.culled_invalid += 1;
        }
    }
}

/// A vertex cache when the triangles drawn are many relative to the vertex array, so that
/// preparing shared vertices once (in a cache the size of the vertex array) pays off.
/// Caching never changes results, only cost.
fn new_cache(
    triangle_count: usize,
    vertex_count: usize,
    viewport: Viewport,
) -> Option<VertexCache> {
    (4 * 3 * triangle_count >= vertex_count).then(|| VertexCache::new(vertex_count, viewport))
}

#[cfg(test)]
mod tests {
    /// Every file of the rasterizer says what it owns and what it must never do.
    #[test]
    fn every_file_states_what_it_owns_and_must_never_do() {
        let files = [
            ("mod.rs", include_str!("mod.rs")),
            ("clip.rs", include_str!("clip.rs")),
            ("fixed.rs", include_str!("fixed.rs")),
            ("setup.rs", include_str!("setup.rs")),
            ("scan.rs", include_str!("scan.rs")),
            ("target.rs", include_str!("target.rs")),
            ("scanline.rs", include_str!("scanline.rs")),
            ("counters.rs", include_str!("counters.rs")),
            ("screen.rs", include_str!("screen.rs")),
            ("image.rs", include_str!("image.rs")),
            ("aa/mod.rs", include_str!("aa/mod.rs")),
            ("aa/masks.rs", include_str!("aa/masks.rs")),
            ("aa/adaptive.rs", include_str!("aa/adaptive.rs")),
            ("aa/supersample.rs", include_str!("aa/supersample.rs")),
        ];
        for (name, src) in files {
            assert!(src.starts_with("//!"), "{name} must start with a //! doc");
            let head: String = src.lines().take_while(|l| l.starts_with("//!")).collect();
            assert!(
                head.to_lowercase().contains("must never"),
                "{name}: say what it must never do"
            );
        }
    }
}
