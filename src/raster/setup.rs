//! Front end and triangle setup: project clipped vertices to the screen, snap them to fixed
//! point, cull (invalid, outside, back-facing, zero area), fan clipped polygons into
//! [`ScreenTriangle`]s, and turn a screen triangle into the edge and plane equations that
//! `scan` walks ([`RasterTriangle`]).
//!
//! Must never touch a target or generate pixels. Everything after snapping is integer, so a
//! `ScreenTriangle` shipped to another node as bytes rasterizes to identical pixels there.
//!
//! Winding: a triangle is *front-facing* when its vertices run counter-clockwise as seen on
//! the screen (x right, y down), which is counter-clockwise in normalized device coordinates
//! (y up), the OpenGL convention that glam's `perspective_rh` preserves.

use super::clip::{
    clip_classified, guard, outcode, plane_mask, ClipResult, ClipVertex, MAX_POLYGON,
};
use super::counters::Counters;
use super::fixed::{channel_to_u8, ColorPlane, Depth, DepthPlane, Edge, PlaneBasis, Sub};
use super::screen::Viewport;
use super::Vertex;

/// Which faces the front end drops.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum CullMode {
    /// Draw both windings.
    #[default]
    None,
    /// Drop triangles that run clockwise on screen.
    Back,
}

/// Front-end options.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RasterOptions {
    pub cull: CullMode,
}

/// A projected, snapped vertex: position in 1/256 pixel, depth, 8-bit linear colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ScreenVertex {
    pub x: Sub,
    pub y: Sub,
    pub z: Depth,
    pub rgb: [u8; 3],
}

impl ScreenVertex {
    /// A vertex given directly in screen space (the `screen` camera of scene files): pixel
    /// x right, pixel y down, depth in 0..=1 (0 nearest), linear colour in 0..=1. Snaps to
    /// 1/256 px with no float round trip through clip space, so pixel-exact input stays
    /// pixel-exact. `None` for NaN. Coordinates beyond +-2^21 px are clamped (there is no
    /// clipping on this path): give such geometry in clip space instead.
    pub fn from_pixels(x: f64, y: f64, z: f64, rgb: [f64; 3]) -> Option<ScreenVertex> {
        if rgb.iter().any(|c| c.is_nan()) {
            return None;
        }
        Some(ScreenVertex {
            x: Sub::snap(x)?,
            y: Sub::snap(y)?,
            z: Depth::from_unit(z)?,
            rgb: rgb.map(channel_to_u8),
        })
    }
}

/// A snapped screen-space triangle with non-zero area, ready to ship between nodes and to
/// rasterize anywhere with identical results.
///
/// Invariant: the vertices are stored in the canonical orientation (`area2 > 0`, see
/// `fixed`), which for a front-facing input means v1 and v2 were swapped; coverage does not
/// depend on the order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ScreenTriangle {
    v: [ScreenVertex; 3],
    prim: u32,
    /// `signed_area2` of `v`, cached (> 0); derived, never serialized.
    area2: i64,
}

/// Twice the signed area of the snapped triangle, `(b - a) x (c - a)` in y-down
/// coordinates: negative for counter-clockwise on screen (front-facing).
#[inline]
pub fn signed_area2(a: &ScreenVertex, b: &ScreenVertex, c: &ScreenVertex) -> i64 {
    let (ax, ay) = (a.x.wide(), a.y.wide());
    (b.x.wide() - ax) * (c.y.wide() - ay) - (b.y.wide() - ay) * (c.x.wide() - ax)
}

impl ScreenTriangle {
    /// Bytes of a serialized screen triangle: per vertex x, y (i32), z (u32), r, g, b (u8),
    /// then the primitive id (u32), little endian. This is the message payload per
    /// triangle for sort-middle redistribution.
    pub const PAYLOAD_BYTES: usize = 3 * (4 + 4 + 4 + 3) + 4;

    /// `None` when the snapped area is zero. `prim` is the triangle's index in its mesh,
    /// which fragment records carry and depth ties are ordered by.
    pub fn new(v: [ScreenVertex; 3], prim: u32) -> Option<ScreenTriangle> {
        Self::with_signed_area(v, prim, signed_area2(&v[0], &v[1], &v[2]))
    }

    /// [`ScreenTriangle::new`] when the caller already holds `signed_area2(v)`.
    #[inline]
    fn with_signed_area(v: [ScreenVertex; 3], prim: u32, a: i64) -> Option<ScreenTriangle> {
        match a.signum() {
            0 => None,
            1 => Some(ScreenTriangle { v, prim, area2: a }),
            _ => Some(ScreenTriangle {
                v: [v[0], v[2], v[1]],
                prim,
                area2: -a,
            }),
        }
    }

    pub fn vertices(&self) -> &[ScreenVertex; 3] {
        &self.v
    }

    pub fn prim(&self) -> u32 {
        self.prim
    }

    /// Inclusive pixel rows and columns whose centres lie within the vertices' extent
    /// (empty when first > last). Cheap: no edge or plane setup.
    #[inline]
    pub fn centre_extent(&self) -> ((i64, i64), (i64, i64)) {
        let [a, b, c] = self.v;
        let (ymin, ymax) = (a.y.min(b.y).min(c.y), a.y.max(b.y).max(c.y));
        let (xmin, xmax) = (a.x.min(b.x).min(c.x), a.x.max(b.x).max(c.x));
        (
            (
                ymin.first_centre_at_or_after(),
                ymax.last_centre_at_or_before(),
            ),
            (
                xmin.first_centre_at_or_after(),
                xmax.last_centre_at_or_before(),
            ),
        )
    }

    /// Twice the area in square subpixel steps (> 0).
    #[inline]
    pub fn area2(&self) -> i64 {
        self.area2
    }

    pub fn to_bytes(&self) -> [u8; ScreenTriangle::PAYLOAD_BYTES] {
        let mut out = [0u8; ScreenTriangle::PAYLOAD_BYTES];
        for (i, v) in self.v.iter().enumerate() {
            let o = i * 15;
            out[o..o + 4].copy_from_slice(&v.x.raw().to_le_bytes());
            out[o + 4..o + 8].copy_from_slice(&v.y.raw().to_le_bytes());
            out[o + 8..o + 12].copy_from_slice(&v.z.raw().to_le_bytes());
            out[o + 12..o + 15].copy_from_slice(&v.rgb);
        }
        out[45..49].copy_from_slice(&self.prim.to_le_bytes());
        out
    }

    /// Inverse of [`ScreenTriangle::to_bytes`]; `None` for bytes no screen triangle
    /// produces (coordinates out of range, reserved depth, zero area).
    pub fn from_bytes(b: &[u8; ScreenTriangle::PAYLOAD_BYTES]) -> Option<ScreenTriangle> {
        let word = |o: usize| [b[o], b[o + 1], b[o + 2], b[o + 3]];
        let vertex = |i: usize| -> Option<ScreenVertex> {
            let o = i * 15;
            Some(ScreenVertex {
                x: Sub::from_raw(i32::from_le_bytes(word(o)))?,
                y: Sub::from_raw(i32::from_le_bytes(word(o + 4)))?,
                z: Depth::from_raw(u32::from_le_bytes(word(o + 8)))?,
                rgb: [b[o + 12], b[o + 13], b[o + 14]],
            })
        };
        let v = [vertex(0)?, vertex(1)?, vertex(2)?];
        let prim = u32::from_le_bytes(word(45));
        // Only the canonical orientation is ever serialized; reject anything else so that
        // a round trip is the identity.
        let area2 = signed_area2(&v[0], &v[1], &v[2]);
        (area2 > 0).then_some(ScreenTriangle { v, prim, area2 })
    }
}

/// Projects a clipped vertex to the screen and snaps it. `None` when w is not positive
/// (a vertex at the eye; only reachable through degenerate input).
#[inline]
fn project(v: &ClipVertex, viewport: Viewport) -> Option<ScreenVertex> {
    let [x, y, z, w] = v.pos;
    if w.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return None;
    }
    // One division per vertex; a shared vertex still projects to the same bits everywhere.
    let inv = 1.0 / w;
    let sx = (x * inv + 1.0) * 0.5 * f64::from(viewport.width());
    let sy = (1.0 - y * inv) * 0.5 * f64::from(viewport.height());
    Some(ScreenVertex {
        x: Sub::snap(sx)?,
        y: Sub::snap(sy)?,
        z: Depth::from_unit(z * inv)?,
        rgb: v.color.map(channel_to_u8),
    })
}

/// True when no pixel centre of the viewport lies within the x/y extent of the vertices.
#[inline]
fn misses_viewport(vs: &[ScreenVertex], viewport: Viewport) -> bool {
    let xmin = vs.iter().map(|v| v.x).min();
    let xmax = vs.iter().map(|v| v.x).max();
    let ymin = vs.iter().map(|v| v.y).min();
    let ymax = vs.iter().map(|v| v.y).max();
    let (Some(xmin), Some(xmax), Some(ymin), Some(ymax)) = (xmin, xmax, ymin, ymax) else {
        return true;
    };
    xmax.last_centre_at_or_before() < 0
        || ymax.last_centre_at_or_before() < 0
        || xmin.first_centre_at_or_after() >= i64::from(viewport.width())
        || ymin.first_centre_at_or_after() >= i64::from(viewport.height())
}

/// Runs one input triangle through clip, project, snap and cull, handing each resulting
/// screen triangle to `emit` and counting what happened.
pub fn setup_triangle(
    vertices: &[Vertex],
    tri: [u32; 3],
    prim: u32,
    viewport: Viewport,
    options: &RasterOptions,
    counters: &mut Counters,
    mut emit: impl FnMut(ScreenTriangle),
) {
    let fetch = |i: u32| vertices.get(i as usize).and_then(|v| prepare(v, viewport));
    let prepared = [fetch(tri[0]), fetch(tri[1]), fetch(tri[2])];
    setup_prepared(
        vertices, tri, prepared, prim, viewport, options, counters, &mut emit,
    );
}

/// A vertex with the front-end work that depends only on the vertex done: validity,
/// classification against the clip planes, and its projection when no clipping can touch
/// it. Shared vertices are prepared once per draw ([`VertexCache`]); the result is the same
/// bits as preparing them per triangle, so caching never changes an image.
///
/// Small on purpose (the clip-space vertex is re-read only for the rare triangles that need
/// clipping), so a cache over a large unshared vertex array stays cheap.
#[derive(Clone, Copy, Debug)]
pub struct PreparedVertex {
    outcode: u8,
    planes: u8,
    screen: Option<ScreenVertex>,
}

/// `None` for a vertex with a NaN or infinite component.
#[inline]
pub fn prepare(v: &Vertex, viewport: Viewport) -> Option<PreparedVertex> {
    let clip = ClipVertex::new(v)?;
    let planes = plane_mask(&clip, guard(viewport));
    Some(PreparedVertex {
        outcode: outcode(&clip),
        planes,
        screen: if planes == 0 {
            project(&clip, viewport)
        } else {
            None
        },
    })
}

/// Prepared vertices of one mesh for one viewport, filled on first use. One cache can serve
/// every draw of that mesh and viewport (all processors of a simulated frame share one), so
/// each vertex is prepared once however the triangles are dealt.
#[derive(Clone, Debug)]
pub struct VertexCache {
    viewport: Viewport,
    slots: Vec<Slot>,
}

#[derive(Clone, Copy, Debug)]
enum Slot {
    Empty,
    Invalid,
    Ready(PreparedVertex),
}

impl Slot {
    /// `v` prepared for `viewport`: invalid when it is missing or not finite.
    fn of(v: Option<&Vertex>, viewport: Viewport) -> Slot {
        match v.and_then(|v| prepare(v, viewport)) {
            Some(p) => Slot::Ready(p),
            None => Slot::Invalid,
        }
    }
}

impl VertexCache {
    pub fn new(vertex_count: usize, viewport: Viewport) -> VertexCache {
        VertexCache {
            viewport,
            slots: vec![Slot::Empty; vertex_count],
        }
    }

    /// An empty cache like [`VertexCache::new`]'s, in this one's memory.
    pub fn emptied(mut self, vertex_count: usize, viewport: Viewport) -> VertexCache {
        self.slots.clear();
        self.slots.resize(vertex_count, Slot::Empty);
        self.viewport = viewport;
        self
    }

    /// The viewport every vertex here is prepared for.
    pub fn viewport(&self) -> Viewport {
        self.viewport
    }

    /// Prepares every vertex now, in order: what [`VertexCache::get`] would fill in on first
    /// use, so it changes no result. Triangles dealt out scattered (sort-last's processors) reach
    /// their vertices far apart, and preparing each on first use there read a vertex and its
    /// slot out of cache; one pass in order streams both.
    pub fn prepare_all(&mut self, vertices: &[Vertex]) {
        for (slot, v) in self.slots.iter_mut().zip(vertices) {
            if let Slot::Empty = slot {
                *slot = Slot::of(Some(v), self.viewport);
            }
        }
    }

    fn get(&mut self, vertices: &[Vertex], i: u32) -> Option<PreparedVertex> {
        let slot = self.slots.get_mut(i as usize)?;
        if let Slot::Empty = slot {
            *slot = Slot::of(vertices.get(i as usize), self.viewport);
        }
        match slot {
            Slot::Ready(p) => Some(*p),
            _ => None,
        }
    }
}

/// [`setup_triangle`] with shared vertices prepared once in `cache` (which must have been
/// made for `vertices`), in the cache's viewport.
pub fn setup_triangle_cached(
    vertices: &[Vertex],
    cache: &mut VertexCache,
    tri: [u32; 3],
    prim: u32,
    options: &RasterOptions,
    counters: &mut Counters,
    mut emit: impl FnMut(ScreenTriangle),
) {
    let prepared = tri.map(|i| cache.get(vertices, i));
    setup_prepared(
        vertices,
        tri,
        prepared,
        prim,
        cache.viewport,
        options,
        counters,
        &mut emit,
    );
}

#[allow(clippy::too_many_arguments)]
fn setup_prepared(
    vertices: &[Vertex],
    tri: [u32; 3],
    prepared: [Option<PreparedVertex>; 3],
    prim: u32,
    viewport: Viewport,
    options: &RasterOptions,
    counters: &mut Counters,
    emit: &mut impl FnMut(ScreenTriangle),
) {
    counters.triangles_in += 1;
    let [Some(a), Some(b), Some(c)] = prepared else {
        counters.culled_invalid += 1;
        return;
    };
    let outcodes = a.outcode & b.outcode & c.outcode;
    let planes = a.planes | b.planes | c.planes;
    if outcodes == 0 && planes == 0 {
        // The common case: nothing to clip, vertices already projected.
        let (Some(sa), Some(sb), Some(sc)) = (a.screen, b.screen, c.screen) else {
            // A vertex at w == 0 on the eye: nothing visible.
            counters.culled_outside += 1;
            return;
        };
        finish_projected(&[sa, sb, sc], prim, viewport, options, counters, emit);
        return;
    }
    // Prepared vertices are valid, so re-reading them always succeeds.
    let fetch = |i: u32| vertices.get(i as usize).and_then(ClipVertex::new);
    let (Some(ca), Some(cb), Some(cc)) = (fetch(tri[0]), fetch(tri[1]), fetch(tri[2])) else {
        counters.culled_invalid += 1;
        return;
    };
    match clip_classified([ca, cb, cc], outcodes, planes, guard(viewport)) {
        ClipResult::Outside => counters.culled_outside += 1,
        ClipResult::Inside(t) => finish_polygon(&t, prim, viewport, options, counters, emit),
        ClipResult::Polygon(p) => {
            counters.clipped += 1;
            finish_polygon(p.vertices(), prim, viewport, options, counters, emit);
        }
    }
}

/// Projects a (clipped) convex polygon, culls it as a whole, and fans it into triangles.
fn finish_polygon(
    clipped: &[ClipVertex],
    prim: u32,
    viewport: Viewport,
    options: &RasterOptions,
    counters: &mut Counters,
    emit: &mut impl FnMut(ScreenTriangle),
) {
    let n = clipped.len();
    let mut poly = [ScreenVertex {
        x: Sub::default(),
        y: Sub::default(),
        z: Depth::NEAR,
        rgb: [0; 3],
    }; MAX_POLYGON];
    for (dst, v) in poly.iter_mut().zip(clipped) {
        match project(v, viewport) {
            Some(s) => *dst = s,
            None => {
                counters.culled_outside += 1;
                return;
            }
        }
    }
    finish_projected(&poly[..n], prim, viewport, options, counters, emit);
}

/// Culls a projected convex polygon as a whole and fans it into screen triangles.
fn finish_projected(
    poly: &[ScreenVertex],
    prim: u32,
    viewport: Viewport,
    options: &RasterOptions,
    counters: &mut Counters,
    emit: &mut impl FnMut(ScreenTriangle),
) {
    let n = poly.len();
    if misses_viewport(poly, viewport) {
        counters.culled_outside += 1;
        return;
    }
    // The polygon's orientation decides culling once for all its pieces, so snapping can
    // never make part of a clipped triangle face the other way.
    let total: i64 = (1..n - 1)
        .map(|i| signed_area2(&poly[0], &poly[i], &poly[i + 1]))
        .sum();
    if total == 0 {
        counters.culled_zero_area += 1;
        return;
    }
    if options.cull == CullMode::Back && total > 0 {
        counters.culled_backface += 1;
        return;
    }
    let mut produced = 0;
    for i in 1..n - 1 {
        let piece = [poly[0], poly[i], poly[i + 1]];
        let area = if n == 3 {
            total
        } else {
            signed_area2(&piece[0], &piece[1], &piece[2])
        };
        // A piece that snapping collapsed or flipped covers nothing of the polygon.
        if area.signum() != total.signum() {
            continue;
        }
        if let Some(t) = ScreenTriangle::with_signed_area(piece, prim, area) {
            emit(t);
            produced += 1;
        }
    }
    counters.triangles_set_up += produced;
    if produced == 0 {
        counters.culled_zero_area += 1;
    }
}

/// A screen triangle with its edge functions and interpolation planes, ready to scan.
#[derive(Clone, Copy, Debug)]
pub struct RasterTriangle {
    pub(crate) edges: [Edge; 3],
    pub(crate) depth: DepthPlane,
    pub(crate) color: [ColorPlane; 3],
    /// The pixel the planes are anchored at.
    pub(crate) anchor: (i64, i64),
    /// Inclusive pixel rows and columns whose centres lie within the vertices' extent.
    pub(crate) rows: (i64, i64),
    pub(crate) cols: (i64, i64),
    /// Inclusive pixel rows and columns whose squares overlap the vertices' extent (for
    /// conservative sampling).
    pub(crate) touched_rows: (i64, i64),
    pub(crate) touched_cols: (i64, i64),
    prim: u32,
}

/// Pixels whose half-open squares `[p, p+1)` overlap the closed extent `[lo, hi]`, as an
/// inclusive range.
fn touched(lo: Sub, hi: Sub) -> (i64, i64) {
    (lo.pixel(), hi.pixel())
}

impl RasterTriangle {
    #[inline]
    pub fn new(t: &ScreenTriangle) -> RasterTriangle {
        let [v0, v1, v2] = t.v;
        let edges = [
            Edge::new(v0.x, v0.y, v1.x, v1.y),
            Edge::new(v1.x, v1.y, v2.x, v2.y),
            Edge::new(v2.x, v2.y, v0.x, v0.y),
        ];
        let anchor = (v0.x.pixel(), v0.y.pixel());
        let basis = PlaneBasis {
            x0: v0.x.wide(),
            y0: v0.y.wide(),
            d1: (v1.x.wide() - v0.x.wide(), v1.y.wide() - v0.y.wide()),
            d2: (v2.x.wide() - v0.x.wide(), v2.y.wide() - v0.y.wide()),
            area2: t.area2,
            inv_area2: 1.0 / t.area2 as f64,
            ox: anchor.0,
            oy: anchor.1,
            far: PlaneBasis::is_far(&[v0.x, v0.y, v1.x, v1.y, v2.x, v2.y]),
        };
        let depth = DepthPlane::new(&basis, [v0.z.raw(), v1.z.raw(), v2.z.raw()]);
        let channel = |ch: usize| ColorPlane::new(&basis, [v0.rgb[ch], v1.rgb[ch], v2.rgb[ch]]);
        let color = [channel(0), channel(1), channel(2)];
        let xs = [v0.x, v1.x, v2.x];
        let ys = [v0.y, v1.y, v2.y];
        let min = |a: [Sub; 3]| a[0].min(a[1]).min(a[2]);
        let max = |a: [Sub; 3]| a[0].max(a[1]).max(a[2]);
        let (rows, cols) = t.centre_extent();
        RasterTriangle {
            edges,
            depth,
            color,
            anchor,
            rows,
            cols,
            touched_rows: touched(min(ys), max(ys)),
            touched_cols: touched(min(xs), max(xs)),
            prim: t.prim,
        }
    }

    pub fn prim(&self) -> u32 {
        self.prim
    }

    /// Depth of the triangle's plane at the centre of pixel `(px, py)`, clamped to the
    /// triangle's depth range, whether or not the centre is covered (a coverage-mask target
    /// needs it for edge pixels). Equals the depth of a fragment there.
    pub fn depth_at(&self, px: i64, py: i64) -> u32 {
        self.depth
            .resolve(self.depth.at(px - self.anchor.0, py - self.anchor.1))
    }

    /// Depth of the plane at the centre of pixel `(px, py)` in 1/256 depth units, neither
    /// rounded nor clamped to the triangle's range: where anti-aliasing targets extrapolate
    /// subpixel depths from (a clamped centre would bend the plane at edge pixels).
    pub(crate) fn depth_fine_at(&self, px: i64, py: i64) -> i64 {
        let raw = self.depth.at(px - self.anchor.0, py - self.anchor.1);
        (raw >> (super::fixed::DEPTH_FRAC - 8)).clamp(i128::from(i64::MIN), i128::from(i64::MAX))
            as i64
    }

    /// Colour of the triangle's planes at the centre of pixel `(px, py)`, clamped per
    /// channel to the vertices' range. Equals the colour of a fragment there.
    pub fn color_at(&self, px: i64, py: i64) -> [u8; 3] {
        let (dx, dy) = (px - self.anchor.0, py - self.anchor.1);
        self.color.map(|c| c.resolve(c.at(dx, dy)))
    }

    /// True when the centre of pixel `(px, py)` is covered under the fill rule.
    pub fn covers_pixel(&self, px: i64, py: i64) -> bool {
        let (x, y) = (super::fixed::centre(px), super::fixed::centre(py));
        self.edges.iter().all(|e| e.covers(x, y))
    }

    /// True when the sample at `(px * 256 + sx, py * 256 + sy)` subpixel steps (`sx`, `sy`
    /// in 0..256 within pixel `(px, py)`) is inside under the fill rule. Samples obey the
    /// same top-left rule as pixel centres, so per-sample coverage is watertight too: this
    /// is what a supersampling or coverage-mask target evaluates on edge pixels.
    pub fn covers_sample(&self, px: i64, py: i64, sx: u8, sy: u8) -> bool {
        let x = px * super::fixed::SUBPIXEL_ONE + i64::from(sx);
        let y = py * super::fixed::SUBPIXEL_ONE + i64::from(sy);
        self.edges.iter().all(|e| e.covers(x, y))
    }

    /// Coverage mask of pixel `(px, py)` for up to 64 sample positions (bit i = sample i).
    pub fn coverage_mask(&self, px: i64, py: i64, samples: &[(u8, u8)]) -> u64 {
        samples
            .iter()
            .take(64)
            .enumerate()
            .filter(|(_, &(sx, sy))| self.covers_sample(px, py, sx, sy))
            .fold(0u64, |m, (i, _)| m | (1 << i))
    }

    /// True when the whole closed pixel square lies strictly inside all three edges (so
    /// every sample of it is covered): an interior pixel for an anti-aliasing target.
    pub fn fully_covers_pixel(&self, px: i64, py: i64) -> bool {
        let one = super::fixed::SUBPIXEL_ONE;
        let corners = [(0, 0), (one, 0), (0, one), (one, one)];
        corners.iter().all(|&(cx, cy)| {
            let (x, y) = (px * one + cx, py * one + cy);
            self.edges.iter().all(|e| e.eval(x, y) > 0)
        })
    }
}
