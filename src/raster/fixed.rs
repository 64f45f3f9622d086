//! All fixed-point arithmetic of the rasterizer: the subpixel coordinate format, the edge
//! functions and the top-left fill rule, the depth and colour plane formats, and the exact
//! incremental floor division that walks span ends. Every conversion between floats and
//! fixed point happens here and nowhere else.
//!
//! Must never read a clock, allocate, or hold per-node state; must never use floating point
//! on a path that decides coverage. Floats appear only in snapping and in fitting the depth
//! and colour gradients, always as pure IEEE functions of integer inputs (no fused
//! operations), so every node computes the same bits.
//!
//! # Coordinates
//! Screen space is in pixels, x right, y down, origin at the top-left corner of the viewport.
//! Pixel `(px, py)` covers `[px, px+1) x [py, py+1)`; it is sampled at its centre
//! `(px + 0.5, py + 0.5)`. A snapped coordinate [`Sub`] counts 1/256 pixel
//! ([`SUBPIXEL_BITS`] = 8), so the centre of pixel `px` is `256 * px + 128`, exactly.
//!
//! # Edge functions and the fill rule
//! A triangle is stored in the orientation where `area2 = (b-a) x (c-a) > 0` with
//! `u x v = u.x * v.y - u.y * v.x` (in y-down coordinates that is clockwise as seen on
//! screen). For the directed edge `a -> b` the edge function is
//! `E(p) = (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x)`: positive inside, zero on
//! the edge line, and it is an exact 64-bit integer (coordinates are at most 2^29 in
//! magnitude, 2^21 px, so every product is below 2^60 and the function below 2^61).
//!
//! A pixel centre exactly on an edge line belongs to at most one of the two triangles that
//! share the edge: the top-left rule. In this orientation an edge is
//! * a *top* edge when it is horizontal and runs to the right (`dy == 0 && dx > 0`): the
//!   interior lies below it;
//! * a *left* edge when it runs upwards (`dy < 0`): the interior lies to its right.
//!
//! Centres on a top or left edge are inside (`E >= 0`), centres on any other edge are
//! outside (`E > 0`, written `E - 1 >= 0` because `E` is an integer): this `-1` is the only
//! bias in coverage. The neighbour across a shared edge sees the same edge reversed, which is
//! top-left exactly when the original is not, so each centre on the shared line is owned by
//! exactly one of them, and no centre is owned by neither: meshes are drawn without holes or
//! double hits.

/// Fractional bits of a snapped screen coordinate.
pub const SUBPIXEL_BITS: u32 = 8;
/// Subpixel steps per pixel (256).
pub const SUBPIXEL_ONE: i64 = 1 << SUBPIXEL_BITS;
/// Offset of a pixel centre from the pixel's top-left corner, in subpixel steps.
pub const PIXEL_CENTRE: i64 = SUBPIXEL_ONE / 2;
/// Largest magnitude of a snapped coordinate, in pixels. The guard band in `clip` keeps every
/// projected vertex inside this (at 2^20 px from the viewport's centre, so a triangle reaching
/// a million pixels off screen is drawn with its own edges, not clipped ones); snapping clamps
/// to it as a last line of defence so the edge-function products above can never overflow.
pub const MAX_COORD_PX: i64 = 1 << 21;

/// The coordinate range before the guard band moved out to a million pixels: a triangle
/// within it takes exactly the plane arithmetic it always took (see [`PlaneBasis::is_far`]).
const NEAR_LIMIT: i64 = (1 << 17) * SUBPIXEL_ONE;

/// A snapped screen coordinate in 1/256 pixel (the `s.8` format): |value| <= 2^29.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Sub(i32);

impl Sub {
    const LIMIT: i64 = MAX_COORD_PX * SUBPIXEL_ONE;

    /// Rounds a pixel coordinate to the nearest 1/256 pixel (ties away from zero), clamping
    /// to the representable range. `None` for NaN.
    #[inline]
    pub fn snap(pixels: f64) -> Option<Sub> {
        if pixels.is_nan() {
            return None;
        }
        let scaled = round_f64(pixels * SUBPIXEL_ONE as f64);
        Some(Sub(scaled.clamp(-Self::LIMIT, Self::LIMIT) as i32))
    }

    /// From raw subpixel steps; `None` outside the representable range.
    pub fn from_raw(raw: i32) -> Option<Sub> {
        (i64::from(raw).abs() <= Self::LIMIT).then_some(Sub(raw))
    }

    #[inline]
    pub fn raw(self) -> i32 {
        self.0
    }

    #[inline]
    pub(crate) fn wide(self) -> i64 {
        i64::from(self.0)
    }

    /// The first pixel index whose centre is at or after this coordinate.
    #[inline]
    pub fn first_centre_at_or_after(self) -> i64 {
        ceil_div(self.wide() - PIXEL_CENTRE, SUBPIXEL_ONE)
    }

    /// The last pixel index whose centre is at or before this coordinate.
    #[inline]
    pub fn last_centre_at_or_before(self) -> i64 {
        floor_div(self.wide() - PIXEL_CENTRE, SUBPIXEL_ONE)
    }

    /// The pixel containing this coordinate (a coordinate on a pixel border belongs to the
    /// pixel to its right / below).
    #[inline]
    pub fn pixel(self) -> i64 {
        floor_div(self.wide(), SUBPIXEL_ONE)
    }
}

/// Centre of pixel index `p`, in subpixel steps.
#[inline]
pub fn centre(p: i64) -> i64 {
    p * SUBPIXEL_ONE + PIXEL_CENTRE
}

/// Floor of `n / d` for `d > 0`.
#[inline]
pub fn floor_div(n: i64, d: i64) -> i64 {
    debug_assert!(d > 0);
    n.div_euclid(d)
}

/// Ceiling of `n / d` for `d > 0`.
#[inline]
pub fn ceil_div(n: i64, d: i64) -> i64 {
    -floor_div(-n, d)
}

/// One directed edge `a -> b` of a triangle in canonical orientation, as integer
/// coefficients of its edge function, with the fill-rule bias already applied.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Edge {
    /// `b.x - a.x` in subpixel steps.
    pub dx: i64,
    /// `b.y - a.y` in subpixel steps.
    pub dy: i64,
    /// Start vertex.
    pub ax: i64,
    pub ay: i64,
    /// 0 for a top or left edge, 1 otherwise: inside is `E(p) - bias >= 0`.
    pub bias: i64,
}

impl Edge {
    #[inline]
    pub fn new(ax: Sub, ay: Sub, bx: Sub, by: Sub) -> Edge {
        let dx = bx.wide() - ax.wide();
        let dy = by.wide() - ay.wide();
        let top_left = dy < 0 || (dy == 0 && dx > 0);
        Edge {
            dx,
            dy,
            ax: ax.wide(),
            ay: ay.wide(),
            bias: if top_left { 0 } else { 1 },
        }
    }

    /// The raw edge function at a point in subpixel steps (no bias).
    #[inline]
    pub fn eval(&self, x: i64, y: i64) -> i64 {
        self.dx * (y - self.ay) - self.dy * (x - self.ax)
    }

    /// True when the point is inside this edge's half-plane under the fill rule.
    #[inline]
    pub fn covers(&self, x: i64, y: i64) -> bool {
        self.eval(x, y) - self.bias >= 0
    }

    /// The biased edge function on row `py` at pixel `px = 0`, i.e. `K` in
    /// `E(px) - bias = K - 256 * dy * px`.
    #[inline]
    pub fn row_constant(&self, py: i64) -> i64 {
        self.eval(PIXEL_CENTRE, centre(py)) - self.bias
    }

    /// `K` for conservative sampling: a pixel's closed square reaches the edge's half-plane
    /// exactly when the edge function at its centre is at least `-128 * (|dx| + |dy|)`,
    /// the most the function can grow from the centre to a corner. No fill-rule bias: a
    /// pixel that only touches the edge is kept, and its coverage mask (which does obey the
    /// rule) then decides.
    #[inline]
    pub fn row_constant_conservative(&self, py: i64) -> i64 {
        self.eval(PIXEL_CENTRE, centre(py)) + PIXEL_CENTRE * (self.dx.abs() + self.dy.abs())
    }
}

/// `floor(n / d)` tracked exactly while `n` grows by a constant step: the end of a span on
/// successive rows. Holds `n = q * d + r` with `0 <= r < d`; no division after `new`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FloorDda {
    q: i64,
    r: i64,
    q_step: i64,
    r_step: i64,
    d: i64,
}

impl FloorDda {
    /// `d > 0` is the caller's guarantee (edges with `dy == 0` never get a DDA).
    #[inline]
    pub fn new(n: i64, step: i64, d: i64) -> FloorDda {
        debug_assert!(d > 0);
        // One division each; the remainder follows by multiplication.
        let q = n.div_euclid(d);
        let q_step = step.div_euclid(d);
        FloorDda {
            q,
            r: n - q * d,
            q_step,
            r_step: step - q_step * d,
            d,
        }
    }

    #[inline]
    pub fn value(&self) -> i64 {
        self.q
    }

    #[inline]
    pub fn step(&mut self) {
        self.q += self.q_step;
        self.r += self.r_step;
        if self.r >= self.d {
            self.r -= self.d;
            self.q += 1;
        }
    }
}

/// A depth value: 0 at the near plane, `Depth::FAR` at the far plane; smaller is nearer.
/// `u32::MAX` is never produced, so it serves as the cleared value of every depth buffer and
/// a fragment on the far plane still passes a fresh buffer.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Depth(u32);

impl Depth {
    pub const NEAR: Depth = Depth(0);
    pub const FAR: Depth = Depth(u32::MAX - 1);
    pub const CLEARED: u32 = u32::MAX;

    /// From normalized depth z/w (clamped to 0..=1, rounded to nearest). `None` for NaN.
    #[inline]
    pub fn from_unit(z: f64) -> Option<Depth> {
        if z.is_nan() {
            return None;
        }
        let scaled = round_f64(z.clamp(0.0, 1.0) * Depth::FAR.0 as f64);
        Some(Depth(scaled as u32))
    }

    /// From raw bits; `None` for the reserved cleared value.
    pub fn from_raw(raw: u32) -> Option<Depth> {
        (raw != Depth::CLEARED).then_some(Depth(raw))
    }

    #[inline]
    pub fn raw(self) -> u32 {
        self.0
    }
}

/// Converts a linear colour channel (clamped to 0..=1) to 8 bits, rounding to nearest.
/// NaN has been rejected before this point; it maps to 0 to stay total.
#[inline]
pub fn channel_to_u8(c: f64) -> u8 {
    if c.is_nan() {
        return 0;
    }
    round_f64(c.clamp(0.0, 1.0) * 255.0) as u8
}

/// Fractional bits of the depth plane (`i128`): the error of a rounded gradient over the
/// whole coordinate range stays below 2^-14 depth units, so the plane rounds to the exact
/// vertex depth at a vertex and varies monotonically along any line.
pub const DEPTH_FRAC: u32 = 32;
/// Fractional bits of a colour plane (`i64`, 8-bit channel units).
pub const COLOR_FRAC: u32 = 20;
/// Colour gradients saturate here (2^22 channel units per pixel, far beyond any visible
/// gradient) so the `i64` plane can never overflow on degenerate slivers; the result is then
/// clamped to the triangle's colour range anyway.
const COLOR_GRADIENT_LIMIT: i64 = 1 << 42;
/// The same for a far triangle, whose pixels lie up to 2^22 px from its anchor: 2^39 x 2^22
/// x 2 stays inside `i64`.
const COLOR_GRADIENT_LIMIT_FAR: i64 = 1 << 39;

/// Rounds to the nearest integer, halves away from zero, saturating (NaN gives 0). Inline
/// arithmetic instead of `f64::round`, which is a library call on baseline x86-64.
#[inline]
pub fn round_f64(v: f64) -> i64 {
    (v + 0.5f64.copysign(v)) as i64
}

/// Division of `n` by `d > 0` rounded to nearest (ties up), exact in `i128`.
fn round_div_i128(n: i128, d: i128) -> i128 {
    (2 * n + d).div_euclid(2 * d)
}

/// Depth as a linear function over pixel centres, `value = origin + gx * (px - ox) +
/// gy * (py - oy)` in fixed point with `(ox, oy)` the basis's anchor pixel, built so that it is a pure function of the triangle and
/// the pixel: any traversal order (spans clipped to regions, scanlines) gets identical bits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DepthPlane {
    origin: i128,
    gx: i128,
    gy: i128,
    min: u32,
    max: u32,
}

/// The geometry a plane is fitted to: vertex 0 and the offsets to vertices 1 and 2 in
/// subpixel steps, plus `area2 = d1 x d2 > 0`.
#[derive(Clone, Copy, Debug)]
pub struct PlaneBasis {
    pub x0: i64,
    pub y0: i64,
    pub d1: (i64, i64),
    pub d2: (i64, i64),
    pub area2: i64,
    /// `1 / area2`, computed once per triangle and shared by every plane.
    pub inv_area2: f64,
    /// The pixel whose centre anchors the plane (the pixel containing vertex 0).
    pub ox: i64,
    pub oy: i64,
    /// A vertex lies beyond 2^17 px ([`PlaneBasis::is_far`]), set once per triangle.
    pub far: bool,
}

impl PlaneBasis {
    /// True when a coordinate (subpixel steps) lies beyond 2^17 px, the range every triangle
    /// had while the guard band sat at 8 half-viewports: such a triangle's planes are evaluated
    /// up to 2^22 px from the anchor, so they take tighter limits. A triangle within the range
    /// keeps the arithmetic it always had, bit for bit.
    pub fn is_far(coordinates: &[Sub]) -> bool {
        coordinates.iter().any(|c| c.wide().abs() > NEAR_LIMIT)
    }

    /// Offset of the anchor pixel's centre from vertex 0, in subpixel steps (|.| <= 128).
    fn anchor_offset(&self) -> (i128, i128) {
        (
            i128::from(centre(self.ox) - self.x0),
            i128::from(centre(self.oy) - self.y0),
        )
    }
}

impl DepthPlane {
    /// Fits the depth plane. The gradient is computed in f64 when that is provably as good
    /// as exact rounding for this triangle, and with exact `i128` division otherwise.
    ///
    /// Why the f64 path is safe: with |G| < 2^62 (fixed-point units per pixel), the three
    /// f64 roundings (1/area, the numerator, the product) add at most |G| * 2^-51 < 2^11
    /// units per pixel; pixels lie within 2^18 px of the anchor, so that is < 2^29 units =
    /// 1/8 depth unit, plus 2^17 units from rounding G to an integer: the plane still
    /// rounds to the exact depth at a vertex. Steeper planes (slivers whose depth changes by more
    /// than 2^30 per pixel) take the exact path. A far triangle (pixels up to 2^22 px from the
    /// anchor) takes the f64 path only below |G| < 2^58, for the same bound. Either way the
    /// plane is an exactly linear integer function, so depth stays monotone along any line.
    #[inline]
    pub fn new(basis: &PlaneBasis, z: [u32; 3]) -> DepthPlane {
        let min = z[0].min(z[1]).min(z[2]);
        let max = z[0].max(z[1]).max(z[2]);
        let one = 1i128 << DEPTH_FRAC;
        let z0 = i64::from(z[0]);
        let base = (i128::from(z0) << DEPTH_FRAC) + one / 2;
        if min == max {
            return DepthPlane {
                origin: base,
                gx: 0,
                gy: 0,
                min,
                max,
            };
        }
        // |f| < 2^32 and |d| <= 2^30: the numerators stay below 2^63, exact in i128 (and
        // below 2^59 for a triangle that is not far).
        let (f1, f2) = (
            i128::from(z[1]) - i128::from(z0),
            i128::from(z[2]) - i128::from(z0),
        );
        let (dx1, dy1) = (i128::from(basis.d1.0), i128::from(basis.d1.1));
        let (dx2, dy2) = (i128::from(basis.d2.0), i128::from(basis.d2.1));
        let (nx, ny) = (f1 * dy2 - f2 * dy1, dx1 * f2 - dx2 * f1);
        let per_step = (one as f64) * basis.inv_area2;
        let per_pixel = per_step * SUBPIXEL_ONE as f64;
        let (gxf, gyf) = (nx as f64 * per_pixel, ny as f64 * per_pixel);
        let fast_limit = if basis.far {
            (1u64 << 58) as f64
        } else {
            (1u64 << 62) as f64
        };
        if gxf.abs() < fast_limit && gyf.abs() < fast_limit {
            let (cx, cy) = (centre(basis.ox) - basis.x0, centre(basis.oy) - basis.y0);
            let offset = (nx as f64 * cx as f64 + ny as f64 * cy as f64) * per_step;
            return DepthPlane {
                origin: base + i128::from(round_f64(offset)),
                gx: i128::from(round_f64(gxf)),
                gy: i128::from(round_f64(gyf)),
                min,
                max,
            };
        }
        let area = i128::from(basis.area2);
        let (cx, cy) = basis.anchor_offset();
        // Per-pixel gradients: one pixel is 256 subpixel steps. |n| < 2^63, so n << 40 fits.
        let gx = round_div_i128(nx * SUBPIXEL_ONE as i128 * one, area);
        let gy = round_div_i128(ny * SUBPIXEL_ONE as i128 * one, area);
        let origin = base + round_div_i128((nx * cx + ny * cy) * one, area);
        DepthPlane {
            origin,
            gx,
            gy,
            min,
            max,
        }
    }

    /// The raw fixed-point value at the centre of pixel `anchor + (dx, dy)`, before rounding
    /// and clamping.
    #[inline]
    pub fn at(&self, dx: i64, dy: i64) -> i128 {
        self.origin + self.gx * i128::from(dx) + self.gy * i128::from(dy)
    }

    #[inline]
    pub fn step_x(&self) -> i128 {
        self.gx
    }

    /// Change per pixel down, in the same fixed point as [`DepthPlane::step_x`].
    #[inline]
    pub fn step_y(&self) -> i128 {
        self.gy
    }

    /// Rounds and clamps a raw value to the triangle's depth range.
    #[inline]
    pub fn resolve(&self, raw: i128) -> u32 {
        let v = raw >> DEPTH_FRAC;
        v.clamp(i128::from(self.min), i128::from(self.max)) as u32
    }
}

/// One colour channel as a plane in 8-bit units with [`COLOR_FRAC`] fractional bits. A
/// triangle whose vertices agree on a channel gets zero gradients and an origin of exactly
/// that value, so it comes out exactly in that colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ColorPlane {
    origin: i64,
    gx: i64,
    gy: i64,
    min: u8,
    max: u8,
}

impl ColorPlane {
    /// Fits the plane through the three vertex values of one channel. The gradients are
    /// computed in f64 (IEEE, no fused operations, so every node gets the same bits) from
    /// exact integer numerators; only flatness needs to be exact, and a flat channel never
    /// reaches the float path.
    #[inline]
    pub fn new(basis: &PlaneBasis, c: [u8; 3]) -> ColorPlane {
        let min = c.iter().copied().min().unwrap_or(0);
        let max = c.iter().copied().max().unwrap_or(0);
        let half = 1i64 << (COLOR_FRAC - 1);
        let base = (i64::from(c[0]) << COLOR_FRAC) + half;
        if min == max {
            return ColorPlane {
                origin: base,
                gx: 0,
                gy: 0,
                min,
                max,
            };
        }
        // |f| <= 255 and |d| <= 2^30, so the numerators stay below 2^39.
        let (f1, f2) = (
            i64::from(c[1]) - i64::from(c[0]),
            i64::from(c[2]) - i64::from(c[0]),
        );
        let (dx1, dy1) = basis.d1;
        let (dx2, dy2) = basis.d2;
        let (nx, ny) = (f1 * dy2 - f2 * dy1, dx1 * f2 - dx2 * f1);
        let (cx, cy) = (centre(basis.ox) - basis.x0, centre(basis.oy) - basis.y0);
        let per_step = (1i64 << COLOR_FRAC) as f64 * basis.inv_area2;
        let per_pixel = per_step * SUBPIXEL_ONE as f64;
        let lim = if basis.far {
            COLOR_GRADIENT_LIMIT_FAR
        } else {
            COLOR_GRADIENT_LIMIT
        } as f64;
        let fix = |v: f64| round_f64(v.clamp(-lim, lim));
        ColorPlane {
            origin: base + fix((nx * cx + ny * cy) as f64 * per_step),
            gx: fix(nx as f64 * per_pixel),
            gy: fix(ny as f64 * per_pixel),
            min,
            max,
        }
    }

    /// Raw value at the centre of pixel `anchor + (dx, dy)`.
    #[inline]
    pub fn at(&self, dx: i64, dy: i64) -> i64 {
        self.origin + self.gx * dx + self.gy * dy
    }

    #[inline]
    pub fn step_x(&self) -> i64 {
        self.gx
    }

    #[inline]
    pub fn resolve(&self, raw: i64) -> u8 {
        (raw >> COLOR_FRAC).clamp(i64::from(self.min), i64::from(self.max)) as u8
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn snap_rounds_to_nearest_subpixel() {
        assert_eq!(Sub::snap(1.0).unwrap().raw(), 256);
        assert_eq!(Sub::snap(0.5 / 256.0 + 1e-9).unwrap().raw(), 1);
        assert_eq!(Sub::snap(-1.0 / 256.0).unwrap().raw(), -1);
        assert_eq!(Sub::snap(1e30).unwrap().wide(), Sub::LIMIT);
        assert!(Sub::snap(f64::NAN).is_none());
    }

    #[test]
    fn pixel_centre_helpers_agree_with_definition() {
        let s = Sub::from_raw(128).unwrap(); // centre of pixel 0
        assert_eq!(s.first_centre_at_or_after(), 0);
        assert_eq!(s.last_centre_at_or_before(), 0);
        let s = Sub::from_raw(129).unwrap();
        assert_eq!(s.first_centre_at_or_after(), 1);
        assert_eq!(s.last_centre_at_or_before(), 0);
        let s = Sub::from_raw(-1).unwrap();
        assert_eq!(s.pixel(), -1);
    }

    #[test]
    fn floor_dda_matches_division() {
        for &(n, step, d) in &[
            (7i64, 3i64, 5i64),
            (-7, 3, 5),
            (100, -13, 7),
            (0, 0, 1),
            (-5, 256, 256),
        ] {
            let mut dda = FloorDda::new(n, step, d);
            for k in 0..50 {
                assert_eq!(
                    dda.value(),
                    floor_div(n + k * step, d),
                    "n={n} step={step} d={d} k={k}"
                );
                dda.step();
            }
        }
    }

    #[test]
    fn reversed_edge_is_top_left_exactly_when_original_is_not() {
        let p = |v: i32| Sub::from_raw(v).unwrap();
        for &(ax, ay, bx, by) in &[(0, 0, 10, 0), (0, 0, 0, 10), (0, 0, 10, 10), (5, 3, -2, 8)] {
            let e = Edge::new(p(ax), p(ay), p(bx), p(by));
            let r = Edge::new(p(bx), p(by), p(ax), p(ay));
            assert_eq!(e.bias + r.bias, 1);
            // On the line both raw functions vanish; exactly one of them covers.
            assert_eq!(e.eval(i64::from(ax), i64::from(ay)), 0);
            assert!(
                e.covers(i64::from(ax), i64::from(ay)) != r.covers(i64::from(ax), i64::from(ay))
            );
        }
    }

    #[test]
    fn depth_never_produces_the_cleared_value() {
        assert_eq!(Depth::from_unit(1.0).unwrap(), Depth::FAR);
        assert_eq!(Depth::from_unit(2.0).unwrap(), Depth::FAR);
        assert_eq!(Depth::from_unit(-1.0).unwrap(), Depth::NEAR);
        assert!(Depth::from_raw(u32::MAX).is_none());
    }
}
