//! Scene statistics. `geometric` measures a frame in floating point without rasterizing:
//! each triangle is clipped in homogeneous space against the near and far planes, projected
//! to pixels, clipped to the screen rectangle, and its area taken. This is what stand-in
//! scenes are matched on (paper 002's mean triangle sizes, paper 003's depth complexity).
//!
//! Owns measurement of frames. Must never change geometry or know about machines.

use glam::{DVec2, DVec4};

use super::FrameGeometry;

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
}

/// Measures `frame` geometrically (see the module doc).
pub fn geometric(frame: &FrameGeometry) -> GeometricStats {
    let (w, h) = (frame.width as f64, frame.height as f64);
    let mut s = GeometricStats { triangles_in: frame.triangles.len(), ..Default::default() };
    for t in &frame.triangles {
        let Some(m) = measure(frame, t) else { continue };
        if m.front {
            s.front_facing += 1;
        }
        if m.screen_area > 0.0 && (m.front || !frame.cull_backfaces) {
            s.on_screen += 1;
            s.sum_area_px += m.screen_area;
        }
    }
    s.mean_area_px = if s.on_screen > 0 { s.sum_area_px / s.on_screen as f64 } else { 0.0 };
    s.depth_complexity = s.sum_area_px / (w * h);
    s
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

struct Measured {
    front: bool,
    screen_area: f64,
    bbox: (DVec2, DVec2),
}

/// None when the triangle is wholly in front of the near plane or behind the far plane.
fn measure(frame: &FrameGeometry, t: &[u32; 3]) -> Option<Measured> {
    let (w, h) = (frame.width as f64, frame.height as f64);
    let clip: Vec<DVec4> = t.iter().map(|&i| frame.vertices[i as usize].clip.as_dvec4()).collect();
    // Near: z >= 0; far: z <= w (glam's perspective_rh depth range).
    let poly = clip_homogeneous(clip, |v| v.z);
    let poly = clip_homogeneous(poly, |v| v.w - v.z);
    if poly.len() < 3 || poly.iter().any(|v| v.w <= 0.0) {
        return None;
    }
    let px: Vec<DVec2> = poly.iter().map(|v| DVec2::new((v.x / v.w + 1.0) * 0.5 * w, (1.0 - v.y / v.w) * 0.5 * h)).collect();
    let signed = shoelace(&px);
    let inside = clip_rect(px, w, h);
    let bbox = inside.iter().fold((DVec2::splat(f64::MAX), DVec2::splat(f64::MIN)), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    Some(Measured { front: signed < 0.0, screen_area: shoelace(&inside).abs(), bbox })
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

/// Sutherland-Hodgman against `dist(v) >= 0`, in homogeneous coordinates.
fn clip_homogeneous(poly: Vec<DVec4>, dist: impl Fn(DVec4) -> f64) -> Vec<DVec4> {
    clip_generic(poly, dist, |a, b, t| a + (b - a) * t)
}

fn clip_rect(poly: Vec<DVec2>, w: f64, h: f64) -> Vec<DVec2> {
    let lerp = |a: DVec2, b: DVec2, t: f64| a + (b - a) * t;
    let p = clip_generic(poly, |v| v.x, lerp);
    let p = clip_generic(p, |v| w - v.x, lerp);
    let p = clip_generic(p, |v| v.y, lerp);
    clip_generic(p, |v| h - v.y, lerp)
}

fn clip_generic<T: Copy>(poly: Vec<T>, dist: impl Fn(T) -> f64, lerp: impl Fn(T, T, f64) -> T) -> Vec<T> {
    if poly.is_empty() {
        return poly;
    }
    let mut out = Vec::with_capacity(poly.len() + 2);
    for i in 0..poly.len() {
        let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
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
