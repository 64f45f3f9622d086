//! Scene statistics. `geometric` measures a frame in floating point without rasterizing:
//! each triangle is clipped in homogeneous space against the near and far planes, projected
//! to pixels, clipped to the screen rectangle, and its area taken. This is what stand-in
//! scenes are matched on (paper 002's mean triangle sizes, paper 003's depth complexity).
//!
//! `rasterized` measures what the real rasterizer does with the frame (after culling,
//! clipping and snapping): triangles set up, pixels rendered, depth complexity and its
//! histogram p_d, active pixels (paper 003's vocabulary), and `raster_overlap_factor` the
//! mean number of screen regions a set-up triangle's bounding box touches (paper 002).
//!
//! Owns measurement of frames. Must never change geometry or know about machines; it calls
//! the rasterizer only to count, never to produce an image anyone keeps.

use glam::{DVec2, DVec4};

use super::FrameGeometry;
use crate::raster::{
    self, Counters, CountingTarget, CullMode, RasterOptions, ScreenTriangle, Viewport,
};

/// What the rasterizer made of one frame (every fragment counted, before any depth test).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RasterStats {
    /// The rasterizer's own counts (culled, clipped, set up, spans, ...).
    pub counters: Counters,
    /// Fragments generated: pixels rendered before z-buffering (paper 003's "total pixels").
    pub pixels_rendered: u64,
    /// `pixels_rendered / triangles_set_up`: mean pixels per set-up triangle.
    pub mean_area_px: f64,
    /// `pixels_rendered / (width * height)`: depth complexity d.
    pub depth_complexity: f64,
    /// Pixel locations with at least one fragment.
    pub active_pixels: u64,
    /// `depth_histogram[k]` = number of pixel locations with exactly k fragments; divided by
    /// width * height this is paper 003's p_d.
    pub depth_histogram: Vec<u64>,
}

impl RasterStats {
    /// p_d for every d (sums to 1).
    pub fn p_d(&self, width: u32, height: u32) -> Vec<f64> {
        let a = width as f64 * height as f64;
        self.depth_histogram.iter().map(|n| *n as f64 / a).collect()
    }
}

/// Rasterizes `frame` into a fragment-counting target (no z-buffer) and measures it.
pub fn rasterized(frame: &FrameGeometry) -> RasterStats {
    let Some(viewport) = Viewport::new(frame.width, frame.height) else {
        return RasterStats::default();
    };
    let mut target = CountingTarget::new(viewport);
    let counters = raster::draw_mesh(
        &frame.vertices,
        &frame.triangles,
        viewport,
        &options(frame),
        &mut target,
    );
    let mut histogram: Vec<u64> = Vec::new();
    let mut pixels = 0u64;
    for &c in target.counts() {
        let c = c as usize;
        if histogram.len() <= c {
            histogram.resize(c + 1, 0);
        }
        histogram[c] += 1;
        pixels += c as u64;
    }
    let set_up = counters.triangles_set_up;
    RasterStats {
        counters,
        pixels_rendered: pixels,
        mean_area_px: if set_up > 0 {
            pixels as f64 / set_up as f64
        } else {
            0.0
        },
        depth_complexity: pixels as f64 / viewport.pixels() as f64,
        active_pixels: viewport.pixels() as u64 - histogram.first().copied().unwrap_or(0),
        depth_histogram: histogram,
    }
}

/// Mean number of `region_w` x `region_h` regions (a grid from the top-left corner) that the
/// snapped bounding box of each set-up triangle touches: paper 002's overlap factor, as a
/// sort-middle geometry stage that sends a triangle to every region its bounding box meets
/// would count it.
pub fn raster_overlap_factor(frame: &FrameGeometry, region_w: u32, region_h: u32) -> f64 {
    let Some(viewport) = Viewport::new(frame.width, frame.height) else {
        return 0.0;
    };
    let mut tris: Vec<ScreenTriangle> = Vec::new();
    raster::setup_mesh(
        &frame.vertices,
        &frame.triangles,
        viewport,
        &options(frame),
        &mut tris,
    );
    if tris.is_empty() {
        return 0.0;
    }
    let (rw, rh) = (region_w.max(1) as i64, region_h.max(1) as i64);
    let (maxx, maxy) = (frame.width as i64 - 1, frame.height as i64 - 1);
    let mut touched = 0u64;
    for t in &tris {
        let v = t.vertices();
        let px = |s: raster::Sub| s.pixel();
        let (x0, x1) = (
            v.iter().map(|p| px(p.x)).min().unwrap().clamp(0, maxx),
            v.iter().map(|p| px(p.x)).max().unwrap().clamp(0, maxx),
        );
        let (y0, y1) = (
            v.iter().map(|p| px(p.y)).min().unwrap().clamp(0, maxy),
            v.iter().map(|p| px(p.y)).max().unwrap().clamp(0, maxy),
        );
        touched += ((x1 / rw - x0 / rw + 1) * (y1 / rh - y0 / rh + 1)) as u64;
    }
    touched as f64 / tris.len() as f64
}

/// Fraction of the screen's pixels that a visible polygon edge passes through: pixels whose
/// frontmost primitive (or the background) differs from a 4-neighbour's, marked on both
/// sides. These are the pixels paper 000's adaptive supersampling stores subpixels for, so
/// this is how its "percent of pixels supersampled" compares (a pixel-level estimate: an edge
/// grazing a pixel without changing its centre's primitive is missed).
pub fn edge_pixel_fraction(frame: &FrameGeometry) -> f64 {
    let Some(viewport) = Viewport::new(frame.width, frame.height) else {
        return 0.0;
    };
    let mut target = VisibleTarget {
        rects: [viewport.rect()],
        depth: vec![u32::MAX; viewport.pixels()],
        prim: vec![u32::MAX; viewport.pixels()],
        width: frame.width as usize,
    };
    raster::draw_mesh(
        &frame.vertices,
        &frame.triangles,
        viewport,
        &options(frame),
        &mut target,
    );
    let (w, h) = (frame.width as usize, frame.height as usize);
    let mut edge = vec![false; w * h];
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            for j in [(x + 1 < w).then_some(i + 1), (y + 1 < h).then_some(i + w)]
                .into_iter()
                .flatten()
            {
                if target.prim[i] != target.prim[j] {
                    edge[i] = true;
                    edge[j] = true;
                }
            }
        }
    }
    edge.iter().filter(|e| **e).count() as f64 / (w * h) as f64
}

/// A z-buffer that keeps the frontmost primitive id per pixel (ties: first drawn stays, as in
/// the rasterizer's own targets).
struct VisibleTarget {
    rects: [raster::ScreenRect; 1],
    depth: Vec<u32>,
    prim: Vec<u32>,
    width: usize,
}

impl raster::Target for VisibleTarget {
    fn rects(&self) -> &[raster::ScreenRect] {
        &self.rects
    }
    fn span(&mut self, _rect: usize, span: &raster::Span<'_>, counters: &mut Counters) {
        let row = span.y() as usize * self.width;
        for f in span.fragments() {
            let i = row + f.x as usize;
            counters.pixels_tested += 1;
            if f.z < self.depth[i] {
                self.depth[i] = f.z;
                self.prim[i] = span.prim();
                counters.pixels_written += 1;
            }
        }
    }
}

fn options(frame: &FrameGeometry) -> RasterOptions {
    RasterOptions {
        cull: if frame.cull_backfaces {
            CullMode::Back
        } else {
            CullMode::None
        },
    }
}

/// Geometric statistics of one frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GeometricStats {
    /// Triangles handed to the rasterizer.
    pub triangles_in: usize,
    /// Triangles facing the viewer (of those not wholly outside the near/far planes).
    pub front_facing: usize,
    /// Triangles that would be drawn: with some area inside the screen, and front-facing
    /// when back-face culling is on.
    pub on_screen: usize,
    /// `sum_area_px / on_screen`: mean on-screen area of a drawn triangle, in pixels.
    pub mean_area_px: f64,
    /// Total on-screen area of the drawn triangles, in pixels.
    pub sum_area_px: f64,
    /// `sum_area_px / (width * height)`: the geometric depth complexity (paper 003's d).
    pub depth_complexity: f64,
    /// Median over drawn triangles of the shorter side of the on-screen bounding box, in
    /// pixels: a triangle "of over 50x50 pixels" (paper 000, section 7.2) has this at 50 or
    /// more.
    pub median_bbox_side_px: f64,
}

/// Measures `frame` geometrically (see the module doc).
pub fn geometric(frame: &FrameGeometry) -> GeometricStats {
    let (w, h) = (frame.width as f64, frame.height as f64);
    let mut s = GeometricStats {
        triangles_in: frame.triangles.len(),
        ..Default::default()
    };
    let mut sides = Vec::new();
    for t in &frame.triangles {
        let Some(m) = measure(frame, t) else { continue };
        if m.front {
            s.front_facing += 1;
        }
        if m.screen_area > 0.0 && (m.front || !frame.cull_backfaces) {
            s.on_screen += 1;
            s.sum_area_px += m.screen_area;
            let size = m.bbox.1 - m.bbox.0;
            sides.push(size.x.min(size.y));
        }
    }
    s.median_bbox_side_px = median(&mut sides);
    s.mean_area_px = if s.on_screen > 0 {
        s.sum_area_px / s.on_screen as f64
    } else {
        0.0
    };
    s.depth_complexity = s.sum_area_px / (w * h);
    s
}

/// Per triangle: would it be drawn (front-facing, or culling off, and with some area on
/// screen)? The same rule `geometric` counts as `on_screen`.
pub(crate) fn drawn_mask(frame: &FrameGeometry) -> Vec<bool> {
    frame
        .triangles
        .iter()
        .map(|t| {
            measure(frame, t)
                .is_some_and(|m| m.screen_area > 0.0 && (m.front || !frame.cull_backfaces))
        })
        .collect()
}

/// Mean number of `region_w` x `region_h` pixel regions a drawn triangle's on-screen bounding
/// box touches (paper 002's overlap factor; a bounding-box estimate, exact for the regions
/// test most sort-middle implementations use).
pub fn overlap_factor(frame: &FrameGeometry, region_w: u32, region_h: u32) -> f64 {
    let (mut touched, mut drawn) = (0u64, 0u64);
    for t in &frame.triangles {
        let Some(m) = measure(frame, t) else { continue };
        if m.screen_area <= 0.0 || (frame.cull_backfaces && !m.front) {
            continue;
        }
        let (lo, hi) = m.bbox;
        let cols = (hi.x / region_w as f64).ceil().max(1.0) - (lo.x / region_w as f64).floor();
        let rows = (hi.y / region_h as f64).ceil().max(1.0) - (lo.y / region_h as f64).floor();
        touched += (cols.max(1.0) * rows.max(1.0)) as u64;
        drawn += 1;
    }
    if drawn == 0 {
        0.0
    } else {
        touched as f64 / drawn as f64
    }
}

/// The middle value (the mean of the two middle values for an even count); 0 when empty.
fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    match values.len() {
        0 => 0.0,
        n if n % 2 == 1 => values[n / 2],
        n => 0.5 * (values[n / 2 - 1] + values[n / 2]),
    }
}

struct Measured {
    front: bool,
    screen_area: f64,
    bbox: (DVec2, DVec2),
}

/// None when the triangle is wholly in front of the near plane or behind the far plane.
fn measure(frame: &FrameGeometry, t: &[u32; 3]) -> Option<Measured> {
    let (w, h) = (frame.width as f64, frame.height as f64);
    let mut clip = Poly::default();
    for &i in t {
        clip.push(frame.vertices[i as usize].clip.as_dvec4());
    }
    // Near: z >= 0; far: z <= w (glam's perspective_rh depth range).
    let poly = clip_generic(&clip, |v| v.z, lerp4);
    let poly = clip_generic(&poly, |v| v.w - v.z, lerp4);
    if poly.len() < 3 || poly.as_slice().iter().any(|v| v.w <= 0.0) {
        return None;
    }
    let mut px = Poly::default();
    for v in poly.as_slice() {
        px.push(DVec2::new(
            (v.x / v.w + 1.0) * 0.5 * w,
            (1.0 - v.y / v.w) * 0.5 * h,
        ));
    }
    let signed = shoelace(px.as_slice());
    let inside = clip_rect(&px, w, h);
    let bbox = inside.as_slice().iter().fold(
        (DVec2::splat(f64::MAX), DVec2::splat(f64::MIN)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    Some(Measured {
        front: signed < 0.0,
        screen_area: shoelace(inside.as_slice()).abs(),
        bbox,
    })
}

/// A convex polygon on the stack: a triangle clipped by at most six planes has at most nine
/// corners, and `measure` runs for every triangle of every frame, so no heap allocation.
#[derive(Clone, Copy, Default)]
struct Poly<T: Copy + Default> {
    n: usize,
    v: [T; 12],
}

impl<T: Copy + Default> Poly<T> {
    fn push(&mut self, p: T) {
        self.v[self.n] = p;
        self.n += 1;
    }
    fn len(&self) -> usize {
        self.n
    }
    fn as_slice(&self) -> &[T] {
        &self.v[..self.n]
    }
}

/// Signed area with y down: negative means counter-clockwise to the viewer.
fn shoelace(p: &[DVec2]) -> f64 {
    if p.len() < 3 {
        return 0.0;
    }
    let mut a = 0.0;
    for i in 0..p.len() {
        let (u, v) = (p[i], p[(i + 1) % p.len()]);
        a += u.x * v.y - v.x * u.y;
    }
    a * 0.5
}

fn lerp4(a: DVec4, b: DVec4, t: f64) -> DVec4 {
    a + (b - a) * t
}

fn lerp2(a: DVec2, b: DVec2, t: f64) -> DVec2 {
    a + (b - a) * t
}

fn clip_rect(poly: &Poly<DVec2>, w: f64, h: f64) -> Poly<DVec2> {
    // Most triangles lie wholly inside: skip the four passes.
    if poly
        .as_slice()
        .iter()
        .all(|p| p.x >= 0.0 && p.x <= w && p.y >= 0.0 && p.y <= h)
    {
        return *poly;
    }
    let p = clip_generic(poly, |v| v.x, lerp2);
    let p = clip_generic(&p, |v| w - v.x, lerp2);
    let p = clip_generic(&p, |v| v.y, lerp2);
    clip_generic(&p, |v| h - v.y, lerp2)
}

/// Sutherland-Hodgman against the half-space `dist(v) >= 0`.
fn clip_generic<T: Copy + Default>(
    poly: &Poly<T>,
    dist: impl Fn(T) -> f64,
    lerp: fn(T, T, f64) -> T,
) -> Poly<T> {
    let mut out = Poly::default();
    let p = poly.as_slice();
    for i in 0..p.len() {
        let (a, b) = (p[i], p[(i + 1) % p.len()]);
        let (da, db) = (dist(a), dist(b));
        if da >= 0.0 {
            out.push(a);
        }
        if (da >= 0.0) != (db >= 0.0) {
            out.push(lerp(a, b, da / (da - db)));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use glam::{Vec3, Vec4};

    use super::*;
    use crate::raster::Vertex;

    /// A frame of one triangle given in pixels (x right, y down) at depth 0.5, w = 1.
    fn frame(px: [[f32; 2]; 3], cull: bool) -> FrameGeometry {
        let (w, h) = (100.0, 50.0);
        let vertices = px
            .iter()
            .map(|p| Vertex {
                clip: Vec4::new(2.0 * p[0] / w - 1.0, 1.0 - 2.0 * p[1] / h, 0.5, 1.0),
                color: Vec3::ONE,
            })
            .collect();
        FrameGeometry {
            width: 100,
            height: 50,
            vertices,
            triangles: vec![[0, 1, 2]],
            cull_backfaces: cull,
            background: [0; 3],
        }
    }

    #[test]
    fn counter_clockwise_to_the_viewer_is_front_facing() {
        // (0,0) -> (0,10) -> (10,0): down then up-right, counter-clockwise on screen.
        let s = geometric(&frame([[0.0, 0.0], [0.0, 10.0], [10.0, 0.0]], true));
        assert_eq!((s.front_facing, s.on_screen), (1, 1));
        assert!((s.sum_area_px - 50.0).abs() < 1e-3);
        let back = geometric(&frame([[0.0, 0.0], [10.0, 0.0], [0.0, 10.0]], true));
        assert_eq!(
            (back.front_facing, back.on_screen),
            (0, 0),
            "a back face is not drawn with culling on"
        );
        let both = geometric(&frame([[0.0, 0.0], [10.0, 0.0], [0.0, 10.0]], false));
        assert_eq!(both.on_screen, 1, "and is drawn with culling off");
    }

    #[test]
    fn only_the_on_screen_part_counts() {
        // A right triangle with legs 40 touching the right edge keeps all of its 800 px; moved
        // 20 px further right, what stays inside is 40*40/2 - 20*20/2 = 600 px.
        let s = geometric(&frame(
            [[60.0, 0.0], [60.0, 40.0], [100.0 + 0.0, 0.0]],
            true,
        ));
        assert!((s.sum_area_px - 800.0).abs() < 1e-3, "{s:?}");
        let s = geometric(&frame([[80.0, 0.0], [80.0, 40.0], [120.0, 0.0]], true));
        assert!((s.sum_area_px - 600.0).abs() < 1e-3, "{s:?}");
        assert!(
            (s.median_bbox_side_px - 20.0).abs() < 1e-3,
            "the on-screen part is 20 px wide and 40 tall: {s:?}"
        );
        let off = geometric(&frame([[200.0, 0.0], [200.0, 40.0], [240.0, 0.0]], true));
        assert_eq!(off.on_screen, 0);
        assert_eq!(
            off.front_facing, 1,
            "facing is decided before the screen clip"
        );
    }

    #[test]
    fn triangles_behind_the_eye_are_clipped_not_counted() {
        let mut f = frame([[0.0, 0.0], [0.0, 10.0], [10.0, 0.0]], true);
        for v in &mut f.vertices {
            v.clip.z = -1.0; // in front of the near plane (z < 0): invisible
        }
        let s = geometric(&f);
        assert_eq!((s.front_facing, s.on_screen), (0, 0));
        assert!(s.mean_area_px == 0.0 && s.sum_area_px == 0.0);
    }

    #[test]
    fn overlap_factor_counts_regions_of_the_bounding_box() {
        let f = frame([[5.0, 5.0], [5.0, 28.0], [28.0, 5.0]], true);
        assert_eq!(overlap_factor(&f, 10, 10), 9.0);
        assert_eq!(raster_overlap_factor(&f, 10, 10), 9.0);
        assert_eq!(overlap_factor(&f, 100, 50), 1.0);
    }
}
