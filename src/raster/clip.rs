//! Clipping in homogeneous clip space: trivial rejection against the view volume, then
//! Sutherland-Hodgman against the near plane (z >= 0), the far plane (z <= w) and, only when
//! a vertex lies outside it, the guard band (|x|, |y| <= g * w, [`guard`]) that keeps
//! projected coordinates inside the fixed-point range. The band lies 2^20 px from the
//! viewport's centre: a clipped edge is cut at a snapped new vertex, which moves it, so the
//! band sits where that can no longer move an edge by a visible amount (a vertex moved by
//! 1/512 px a million pixels away shifts the edge on screen by under 2^-16 px); everything
//! nearer is drawn with its own edges.
//!
//! Must never project, snap or decide coverage (that is `setup` and `fixed`), and must never
//! compute a shared edge's intersection in an order that depends on which triangle asks:
//! [`intersect`] always runs from the lexicographically smaller vertex to the larger one, so
//! two triangles sharing an edge get bit-identical new vertices and stay watertight.

use std::cmp::Ordering;

use super::Vertex;

/// Distance of the guard band from the viewport's centre, in pixels along its longer side:
/// with the centre at most 8192 px from the origin, projected coordinates stay below
/// 2^20 + 8192 < 2^21 px (`fixed::MAX_COORD_PX`).
pub const GUARD_PX: f64 = (1u64 << 20) as f64;

/// The guard band's half-size for `viewport` in units of w (normalized device coordinates).
pub fn guard(viewport: super::Viewport) -> f64 {
    let half = f64::from(viewport.width().max(viewport.height())) / 2.0;
    GUARD_PX / half
}

/// Most vertices a triangle can have after clipping against six planes.
pub const MAX_POLYGON: usize = 9;

/// A clip-space vertex widened to f64 for clipping arithmetic.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClipVertex {
    /// x, y, z, w.
    pub pos: [f64; 4],
    /// Linear colour, clamped to 0..=1.
    pub color: [f64; 3],
}

impl ClipVertex {
    /// `None` when any position or colour component is NaN or infinite.
    #[inline]
    pub fn new(v: &Vertex) -> Option<ClipVertex> {
        let p = v.clip.to_array();
        let c = v.color.to_array();
        if !p.iter().chain(c.iter()).all(|x| x.is_finite()) {
            return None;
        }
        Some(ClipVertex {
            pos: p.map(f64::from),
            color: c.map(|x| f64::from(x).clamp(0.0, 1.0)),
        })
    }

    fn components(&self) -> [f64; 7] {
        let [x, y, z, w] = self.pos;
        let [r, g, b] = self.color;
        [x, y, z, w, r, g, b]
    }

    /// A total order on vertices (IEEE total order, component by component): the fixed
    /// direction in which every shared edge is intersected.
    fn key_cmp(&self, other: &ClipVertex) -> Ordering {
        let (a, b) = (self.components(), other.components());
        a.iter()
            .zip(b.iter())
            .map(|(x, y)| x.total_cmp(y))
            .find(|o| o.is_ne())
            .unwrap_or(Ordering::Equal)
    }
}

/// The planes a triangle is clipped against, in the fixed order they are applied.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Plane {
    Near,
    Far,
    GuardLeft,
    GuardRight,
    GuardBottom,
    GuardTop,
}

const PLANES: [Plane; 6] = [
    Plane::Near,
    Plane::Far,
    Plane::GuardLeft,
    Plane::GuardRight,
    Plane::GuardBottom,
    Plane::GuardTop,
];

impl Plane {
    /// Signed distance, >= 0 inside, for a guard band of half-size `g`.
    #[inline]
    fn distance(self, v: &ClipVertex, g: f64) -> f64 {
        let [x, y, z, w] = v.pos;
        match self {
            Plane::Near => z,
            Plane::Far => w - z,
            Plane::GuardLeft => x + g * w,
            Plane::GuardRight => g * w - x,
            Plane::GuardBottom => y + g * w,
            Plane::GuardTop => g * w - y,
        }
    }

    /// Puts an intersection exactly on the plane, so later tests never see it outside.
    fn project_onto(self, v: &mut ClipVertex, g: f64) {
        let w = v.pos[3];
        match self {
            Plane::Near => v.pos[2] = 0.0,
            Plane::Far => v.pos[2] = w,
            Plane::GuardLeft => v.pos[0] = -g * w,
            Plane::GuardRight => v.pos[0] = g * w,
            Plane::GuardBottom => v.pos[1] = -g * w,
            Plane::GuardTop => v.pos[1] = g * w,
        }
    }
}

/// A convex polygon of up to [`MAX_POLYGON`] vertices, in the input's winding order.
#[derive(Clone, Copy, Debug)]
pub struct Polygon {
    verts: [ClipVertex; MAX_POLYGON],
    len: usize,
}

impl Polygon {
    fn empty() -> Polygon {
        let zero = ClipVertex {
            pos: [0.0; 4],
            color: [0.0; 3],
        };
        Polygon {
            verts: [zero; MAX_POLYGON],
            len: 0,
        }
    }

    fn push(&mut self, v: ClipVertex) {
        // Each plane adds at most one vertex to a convex polygon, so this never overflows.
        if self.len < MAX_POLYGON {
            self.verts[self.len] = v;
            self.len += 1;
        }
    }

    pub fn vertices(&self) -> &[ClipVertex] {
        &self.verts[..self.len]
    }
}

/// What clipping did to a triangle. Kept on the stack on purpose (no boxing in the
/// per-triangle path), hence the size difference between variants.
#[derive(Clone, Copy, Debug)]
#[allow(clippy::large_enum_variant)]
pub enum ClipResult {
    /// Entirely inside the near/far planes and the guard band: the triangle unchanged.
    Inside([ClipVertex; 3]),
    /// Crossed at least one clip plane; the visible part as a convex polygon (>= 3 vertices).
    Polygon(Polygon),
    /// Nothing of it can be visible.
    Outside,
}

/// Bits of the view-volume outcode: a triangle whose three vertices share a bit is invisible.
#[inline]
pub fn outcode(v: &ClipVertex) -> u8 {
    let [x, y, z, w] = v.pos;
    (u8::from(x < -w))
        | (u8::from(x > w) << 1)
        | (u8::from(y < -w) << 2)
        | (u8::from(y > w) << 3)
        | (u8::from(z < 0.0) << 4)
        | (u8::from(z > w) << 5)
}

/// Bit i set when the vertex is outside clip plane i (near, far, then the guard band of
/// half-size `g`).
#[inline]
pub fn plane_mask(v: &ClipVertex, g: f64) -> u8 {
    PLANES
        .iter()
        .enumerate()
        .fold(0, |m, (i, p)| m | (u8::from(p.distance(v, g) < 0.0) << i))
}

/// Clips one triangle against a guard band of half-size `g`. Vertices must be finite (see
/// [`ClipVertex::new`]).
#[cfg(test)]
pub fn clip_triangle(tri: [ClipVertex; 3], g: f64) -> ClipResult {
    let outcodes = outcode(&tri[0]) & outcode(&tri[1]) & outcode(&tri[2]);
    let planes = plane_mask(&tri[0], g) | plane_mask(&tri[1], g) | plane_mask(&tri[2], g);
    clip_classified(tri, outcodes, planes, g)
}

/// [`clip_triangle`] given the AND of the vertices' outcodes and the OR of their plane
/// masks, for callers that computed them once per shared vertex.
pub fn clip_classified(
    tri: [ClipVertex; 3],
    outcodes_and: u8,
    planes_or: u8,
    g: f64,
) -> ClipResult {
    if outcodes_and != 0 {
        return ClipResult::Outside;
    }
    if planes_or == 0 {
        return ClipResult::Inside(tri);
    }
    let mut poly = Polygon::empty();
    for v in tri {
        poly.push(v);
    }
    for plane in PLANES {
        if poly.vertices().iter().any(|v| plane.distance(v, g) < 0.0) {
            poly = clip_against(&poly, plane, g);
            if poly.len < 3 {
                // Everything was clipped away.
                return ClipResult::Outside;
            }
        }
    }
    ClipResult::Polygon(poly)
}

fn clip_against(poly: &Polygon, plane: Plane, g: f64) -> Polygon {
    let mut out = Polygon::empty();
    let vs = poly.vertices();
    for (i, cur) in vs.iter().enumerate() {
        let next = &vs[(i + 1) % vs.len()];
        let (dc, dn) = (plane.distance(cur, g), plane.distance(next, g));
        if dc >= 0.0 {
            out.push(*cur);
        }
        if (dc >= 0.0) != (dn >= 0.0) {
            out.push(intersect(cur, next, plane, g));
        }
    }
    out
}

/// The point where edge `a`-`b` crosses `plane`, computed from the smaller vertex to the
/// larger one so the result does not depend on the edge's direction.
fn intersect(a: &ClipVertex, b: &ClipVertex, plane: Plane, g: f64) -> ClipVertex {
    let (lo, hi) = if a.key_cmp(b).is_le() { (a, b) } else { (b, a) };
    let (dl, dh) = (plane.distance(lo, g), plane.distance(hi, g));
    // The caller only asks when the signs differ, so the denominator is non-zero.
    let t = dl / (dl - dh);
    let lerp = |p: f64, q: f64| p + t * (q - p);
    let mut v = ClipVertex {
        pos: [0, 1, 2, 3].map(|i| lerp(lo.pos[i], hi.pos[i])),
        color: [0, 1, 2].map(|i| lerp(lo.color[i], hi.color[i]).clamp(0.0, 1.0)),
    };
    plane.project_onto(&mut v, g);
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The band of a 16-pixel viewport side at 8 half-viewports, as these cases were written.
    const G: f64 = 8.0;

    fn cv(x: f64, y: f64, z: f64, w: f64) -> ClipVertex {
        ClipVertex {
            pos: [x, y, z, w],
            color: [0.5; 3],
        }
    }

    #[test]
    fn intersection_is_independent_of_edge_direction() {
        let a = cv(0.3, -0.7, -0.25, 1.3);
        let b = cv(-0.1, 0.9, 0.8, 2.1);
        for plane in PLANES {
            let (da, db) = (plane.distance(&a, G), plane.distance(&b, G));
            if (da >= 0.0) != (db >= 0.0) {
                assert_eq!(intersect(&a, &b, plane, G), intersect(&b, &a, plane, G));
            }
        }
        let p = intersect(&a, &b, Plane::Near, G);
        assert_eq!(p.pos[2], 0.0);
    }

    #[test]
    fn triangle_behind_the_eye_is_outside() {
        let t = [
            cv(0.0, 0.0, -1.0, -0.5),
            cv(1.0, 0.0, -1.0, -0.5),
            cv(0.0, 1.0, -2.0, -1.0),
        ];
        assert!(matches!(clip_triangle(t, G), ClipResult::Outside));
    }

    #[test]
    fn triangle_crossing_near_plane_becomes_quad() {
        let t = [
            cv(0.0, 0.0, -0.5, 1.0),
            cv(0.5, 0.0, 0.5, 1.0),
            cv(0.0, 0.5, 0.5, 1.0),
        ];
        match clip_triangle(t, G) {
            ClipResult::Polygon(p) => {
                assert_eq!(p.vertices().len(), 4);
                assert!(p.vertices().iter().all(|v| v.pos[2] >= 0.0));
            }
            other => panic!("expected a clipped polygon, got {other:?}"),
        }
    }

    #[test]
    fn guard_band_only_when_needed() {
        let inside = [
            cv(-5.0, 0.0, 0.5, 1.0),
            cv(5.0, 0.0, 0.5, 1.0),
            cv(0.0, 7.0, 0.5, 1.0),
        ];
        assert!(matches!(clip_triangle(inside, G), ClipResult::Inside(_)));
        let huge = [
            cv(-1e6, 0.0, 0.5, 1.0),
            cv(1e6, 0.0, 0.5, 1.0),
            cv(0.0, 1e6, 0.5, 1.0),
        ];
        match clip_triangle(huge, G) {
            ClipResult::Polygon(p) => {
                for v in p.vertices() {
                    assert!(v.pos[0].abs() <= G * v.pos[3]);
                    assert!(v.pos[1].abs() <= G * v.pos[3]);
                }
            }
            other => panic!("expected a clipped polygon, got {other:?}"),
        }
    }
}
