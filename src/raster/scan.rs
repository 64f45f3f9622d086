//! Scan conversion: walk a set-up triangle row by row inside one target rectangle, find each
//! row's span of covered pixel centres exactly (integer DDAs on the edge functions, no
//! per-pixel edge test), and interpolate depth and colour along the span.
//!
//! Must never decide where pixels go (that is the target) and never evaluate anything that
//! depends on the traversal: a span's pixels, depths and colours are pure functions of the
//! triangle and the pixel, so a region, a scanline or the whole screen see the same bits.

use super::fixed::{centre, FloorDda, SUBPIXEL_ONE};
use super::screen::ScreenRect;
use super::setup::RasterTriangle;

/// How one edge bounds a row: as a lower bound on x (`E` grows to the right), an upper
/// bound (`E` shrinks to the right), or for a horizontal edge all-or-nothing per row.
#[derive(Clone, Copy, Debug)]
enum Bound {
    /// `px >= -floor(K / D)`.
    Left(FloorDda),
    /// `px <= floor(K / D)`.
    Right(FloorDda),
    /// The row is inside iff `K >= 0`; `K` grows by `step` per row.
    Flat { k: i64, step: i64 },
}

/// Walks the rows of one triangle inside one rectangle, top to bottom.
#[derive(Clone, Debug)]
pub struct RowWalker<'a> {
    tri: &'a RasterTriangle,
    bounds: [Bound; 3],
    y: i64,
    y_last: i64,
    x_lo: i64,
    x_hi: i64,
}

/// One row of a walk: its index and its span, if any pixel of it is covered.
#[derive(Clone, Copy, Debug)]
pub struct Row<'a> {
    pub y: u32,
    pub span: Option<Span<'a>>,
}

impl<'a> RowWalker<'a> {
    /// `None` when no pixel centre of the rectangle lies within the triangle's extent.
    pub fn new(tri: &'a RasterTriangle, rect: ScreenRect) -> Option<RowWalker<'a>> {
        let y = tri.rows.0.max(i64::from(rect.y0()));
        let y_last = tri.rows.1.min(i64::from(rect.y1()) - 1);
        let x_lo = tri.cols.0.max(i64::from(rect.x0()));
        let x_hi = tri.cols.1.min(i64::from(rect.x1()) - 1);
        if y > y_last || x_lo > x_hi {
            return None;
        }
        let bounds = tri.edges.map(|e| {
            let k = e.row_constant(y);
            let step = SUBPIXEL_ONE * e.dx;
            let d = SUBPIXEL_ONE * e.dy.abs();
            match e.dy.signum() {
                -1 => Bound::Left(FloorDda::new(k, step, d)),
                1 => Bound::Right(FloorDda::new(k, step, d)),
                _ => Bound::Flat { k, step },
            }
        });
        Some(RowWalker {
            tri,
            bounds,
            y,
            y_last,
            x_lo,
            x_hi,
        })
    }

    /// The next row of the walk, or `None` after the last row.
    #[inline]
    pub fn next_row(&mut self) -> Option<Row<'a>> {
        if self.y > self.y_last {
            return None;
        }
        let (mut lo, mut hi) = (self.x_lo, self.x_hi);
        for b in &mut self.bounds {
            match b {
                Bound::Left(d) => {
                    lo = lo.max(-d.value());
                    d.step();
                }
                Bound::Right(d) => {
                    hi = hi.min(d.value());
                    d.step();
                }
                Bound::Flat { k, step } => {
                    if *k < 0 {
                        hi = lo - 1;
                    }
                    *k += *step;
                }
            }
        }
        let y = self.y as u32;
        self.y += 1;
        let span = (lo <= hi).then(|| Span {
            tri: self.tri,
            y,
            x0: lo as u32,
            x1: hi as u32 + 1,
        });
        Some(Row { y, span })
    }

    /// Row the next call to [`RowWalker::next_row`] returns.
    pub fn next_y(&self) -> i64 {
        self.y
    }

    /// Last row of the walk.
    pub fn last_y(&self) -> i64 {
        self.y_last
    }
}

/// A run of covered pixels `[x0, x1)` on row `y`, in screen pixels, inside one target rect.
#[derive(Clone, Copy, Debug)]
pub struct Span<'a> {
    tri: &'a RasterTriangle,
    y: u32,
    x0: u32,
    x1: u32,
}

/// One covered pixel of a span: its column, depth and colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Fragment {
    pub x: u32,
    pub z: u32,
    pub rgb: [u8; 3],
}

impl<'a> Span<'a> {
    pub fn y(&self) -> u32 {
        self.y
    }
    pub fn x0(&self) -> u32 {
        self.x0
    }
    /// One past the last pixel.
    pub fn x1(&self) -> u32 {
        self.x1
    }
    pub fn len(&self) -> usize {
        (self.x1 - self.x0) as usize
    }
    pub fn is_empty(&self) -> bool {
        self.x1 == self.x0
    }
    /// The triangle, for edge queries (sample coverage) by anti-aliasing targets.
    pub fn triangle(&self) -> &'a RasterTriangle {
        self.tri
    }
    pub fn prim(&self) -> u32 {
        self.tri.prim()
    }

    /// The span's fragments left to right. Values are evaluated from the planes at the first
    /// pixel and stepped exactly in integers, so they equal a direct evaluation per pixel.
    #[inline]
    pub fn fragments(&self) -> Fragments<'a> {
        let t = self.tri;
        let dx = i64::from(self.x0) - t.anchor.0;
        let dy = i64::from(self.y) - t.anchor.1;
        Fragments {
            tri: t,
            x: self.x0,
            end: self.x1,
            z: t.depth.at(dx, dy),
            z_step: t.depth.step_x(),
            c: [0, 1, 2].map(|i| t.color[i].at(dx, dy)),
            c_step: [0, 1, 2].map(|i| t.color[i].step_x()),
        }
    }
}

/// Iterator over a span's fragments.
#[derive(Clone, Debug)]
pub struct Fragments<'a> {
    tri: &'a RasterTriangle,
    x: u32,
    end: u32,
    z: i128,
    z_step: i128,
    c: [i64; 3],
    c_step: [i64; 3],
}

impl Iterator for Fragments<'_> {
    type Item = Fragment;

    #[inline(always)]
    fn next(&mut self) -> Option<Fragment> {
        if self.x >= self.end {
            return None;
        }
        let t = self.tri;
        let f = Fragment {
            x: self.x,
            z: t.depth.resolve(self.z),
            rgb: [
                t.color[0].resolve(self.c[0]),
                t.color[1].resolve(self.c[1]),
                t.color[2].resolve(self.c[2]),
            ],
        };
        self.x += 1;
        self.z = self.z.wrapping_add(self.z_step);
        for i in 0..3 {
            self.c[i] = self.c[i].wrapping_add(self.c_step[i]);
        }
        Some(f)
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let n = self.end.saturating_sub(self.x) as usize;
        (n, Some(n))
    }
}

impl ExactSizeIterator for Fragments<'_> {}

/// Centre of pixel `(px, py)` in subpixel steps; for tests and coverage targets.
pub fn pixel_centre(px: i64, py: i64) -> (i64, i64) {
    (centre(px), centre(py))
}
