//! Scan conversion: walk a set-up triangle row by row inside one target rectangle, find each
//! row's span of covered pixel centres exactly (integer DDAs on the edge functions for
//! large triangles, direct tests of the few centres of small ones; both exact, so they
//! agree), and interpolate depth and colour along the span.
//!
//! Must never decide where pixels go (that is the target) and never evaluate anything that
//! depends on the traversal: a span's pixels, depths and colours are pure functions of the
//! triangle and the pixel, so a region, a scanline or the whole screen see the same bits.

use super::fixed::{FloorDda, SUBPIXEL_ONE};
use super::screen::ScreenRect;
use super::setup::RasterTriangle;

/// Which pixels a walk generates.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Sampling {
    /// Pixels whose centre is covered under the top-left rule (every target but an
    /// anti-aliasing one): a mesh covers each pixel exactly once.
    #[default]
    Centre,
    /// Every pixel whose square touches the triangle, plus possibly a few near its corners
    /// that do not: for coverage-mask targets, which evaluate the samples of each pixel with
    /// `RasterTriangle::coverage_mask` and drop pixels whose mask is empty.
    Conservative,
}

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

/// How a walk finds each row's span. Both give identical spans (both are exact); they
/// differ only in cost.
#[derive(Clone, Copy, Debug)]
enum Mode {
    /// Wide or tall triangles: span ends from division-free DDAs (six divisions at start).
    Dda([Bound; 3]),
    /// Small triangles: test the few pixel centres of each row directly, which is cheaper
    /// than the divisions a DDA needs to start. `k` holds each biased edge function at the
    /// row's first column; it grows by `row_step` per row and `x_step` per column.
    Probe {
        k: [i64; 3],
        row_step: [i64; 3],
        x_step: [i64; 3],
    },
}

/// Triangles whose clipped extent is at most this many columns and rows use `Mode::Probe`.
const PROBE_MAX_COLS: i64 = 8;
const PROBE_MAX_ROWS: i64 = 16;

/// Walks the rows of one triangle inside one rectangle, top to bottom.
#[derive(Clone, Debug)]
pub struct RowWalker<'a> {
    tri: &'a RasterTriangle,
    state: RowState,
}

/// The position of a walk without the triangle it walks, so that a renderer can keep many
/// walks next to the triangles they belong to (the scanline renderer's active list).
#[derive(Clone, Copy, Debug)]
pub struct RowState {
    mode: Mode,
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
        Self::sampled(tri, rect, Sampling::Centre)
    }

    /// A walk with the given sampling.
    pub fn sampled(
        tri: &'a RasterTriangle,
        rect: ScreenRect,
        sampling: Sampling,
    ) -> Option<RowWalker<'a>> {
        let state = RowState::new(tri, rect, sampling, true)?;
        Some(RowWalker { tri, state })
    }

    /// The next row of the walk, or `None` after the last row.
    #[inline]
    pub fn next_row(&mut self) -> Option<Row<'a>> {
        self.state.next_row(self.tri)
    }

    /// Row the next call to [`RowWalker::next_row`] returns.
    pub fn next_y(&self) -> i64 {
        self.state.y
    }

    /// Last row of the walk.
    pub fn last_y(&self) -> i64 {
        self.state.y_last
    }
}

impl RowState {
    /// `None` when no sampled pixel of the rectangle lies within the triangle's extent.
    /// `allow_probe = false` forces the DDA, so tests can check both modes agree.
    #[inline]
    pub fn new(
        tri: &RasterTriangle,
        rect: ScreenRect,
        sampling: Sampling,
        allow_probe: bool,
    ) -> Option<RowState> {
        let (rows, cols) = match sampling {
            Sampling::Centre => (tri.rows, tri.cols),
            Sampling::Conservative => (tri.touched_rows, tri.touched_cols),
        };
        let row_constant = |e: &super::fixed::Edge, y: i64| match sampling {
            Sampling::Centre => e.row_constant(y),
            Sampling::Conservative => e.row_constant_conservative(y),
        };
        let y = rows.0.max(i64::from(rect.y0()));
        let y_last = rows.1.min(i64::from(rect.y1()) - 1);
        let x_lo = cols.0.max(i64::from(rect.x0()));
        let x_hi = cols.1.min(i64::from(rect.x1()) - 1);
        if y > y_last || x_lo > x_hi {
            return None;
        }
        let e = &tri.edges;
        let mode = if allow_probe && x_hi - x_lo < PROBE_MAX_COLS && y_last - y < PROBE_MAX_ROWS {
            let at = |i: usize| row_constant(&e[i], y) - SUBPIXEL_ONE * e[i].dy * x_lo;
            Mode::Probe {
                k: [at(0), at(1), at(2)],
                row_step: [
                    SUBPIXEL_ONE * e[0].dx,
                    SUBPIXEL_ONE * e[1].dx,
                    SUBPIXEL_ONE * e[2].dx,
                ],
                x_step: [
                    -SUBPIXEL_ONE * e[0].dy,
                    -SUBPIXEL_ONE * e[1].dy,
                    -SUBPIXEL_ONE * e[2].dy,
                ],
            }
        } else {
            let bound = |e: &super::fixed::Edge| {
                let k = row_constant(e, y);
                let step = SUBPIXEL_ONE * e.dx;
                let d = SUBPIXEL_ONE * e.dy.abs();
                match e.dy.signum() {
                    -1 => Bound::Left(FloorDda::new(k, step, d)),
                    1 => Bound::Right(FloorDda::new(k, step, d)),
                    _ => Bound::Flat { k, step },
                }
            };
            Mode::Dda([bound(&e[0]), bound(&e[1]), bound(&e[2])])
        };
        Some(RowState {
            mode,
            y,
            y_last,
            x_lo,
            x_hi,
        })
    }

    /// The next row of the walk over `tri` (the triangle this state was made for).
    #[inline]
    pub fn next_row<'a>(&mut self, tri: &'a RasterTriangle) -> Option<Row<'a>> {
        if self.y > self.y_last {
            return None;
        }
        let (lo, hi) = match &mut self.mode {
            Mode::Dda(bounds) => dda_row(bounds, self.x_lo, self.x_hi),
            Mode::Probe {
                k,
                row_step,
                x_step,
            } => {
                let r = probe_row(k, x_step, self.x_lo, self.x_hi);
                for i in 0..3 {
                    k[i] += row_step[i];
                }
                r
            }
        };
        let y = self.y as u32;
        self.y += 1;
        let span = (lo <= hi).then(|| Span {
            tri,
            y,
            x0: lo as u32,
            x1: hi as u32 + 1,
        });
        Some(Row { y, span })
    }

    /// True once every row has been returned.
    pub fn is_done(&self) -> bool {
        self.y > self.y_last
    }

    /// Row the next call to [`RowState::next_row`] returns.
    pub fn next_y(&self) -> i64 {
        self.y
    }
}

/// Span ends of one row from the DDAs, then steps them to the next row.
#[inline]
fn dda_row(bounds: &mut [Bound; 3], x_lo: i64, x_hi: i64) -> (i64, i64) {
    let (mut lo, mut hi) = (x_lo, x_hi);
    for b in bounds {
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
    (lo, hi)
}

/// Span ends of one row by testing each centre; the covered centres of a row of a convex
/// triangle are contiguous, so the first run is the span. Empty is `lo > hi`.
#[inline]
fn probe_row(k: &[i64; 3], x_step: &[i64; 3], x_lo: i64, x_hi: i64) -> (i64, i64) {
    let mut e = *k;
    let (mut lo, mut hi) = (x_hi + 1, x_hi);
    let mut x = x_lo;
    while x <= x_hi {
        let inside = e[0] >= 0 && e[1] >= 0 && e[2] >= 0;
        if inside && lo > x_hi {
            lo = x;
        } else if !inside && lo <= x_hi {
            hi = x - 1;
            break;
        }
        for i in 0..3 {
            e[i] += x_step[i];
        }
        x += 1;
    }
    (lo, hi)
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
            c: [
                t.color[0].at(dx, dy),
                t.color[1].at(dx, dy),
                t.color[2].at(dx, dy),
            ],
            c_step: [
                t.color[0].step_x(),
                t.color[1].step_x(),
                t.color[2].step_x(),
            ],
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::raster::fixed::{Depth, Sub};
    use crate::raster::setup::{ScreenTriangle, ScreenVertex};

    fn spans(
        t: &RasterTriangle,
        rect: ScreenRect,
        sampling: Sampling,
        probe: bool,
    ) -> Vec<(u32, u32, u32)> {
        let mut out = Vec::new();
        if let Some(mut w) = RowState::new(t, rect, sampling, probe) {
            while let Some(row) = w.next_row(t) {
                if let Some(s) = row.span {
                    out.push((s.y(), s.x0(), s.x1()));
                }
            }
        }
        out
    }

    #[test]
    fn probe_and_dda_find_identical_spans() {
        // A small deterministic generator (xorshift) over subpixel coordinates.
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = |m: i32| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state % m as u64) as i32
        };
        let rect = ScreenRect::new(0, 0, 64, 64).unwrap();
        let mut compared = 0;
        for _ in 0..20_000 {
            let base = (next(50 * 256), next(50 * 256));
            let v = |dx: i32, dy: i32| ScreenVertex {
                x: Sub::from_raw(base.0 + dx).unwrap(),
                y: Sub::from_raw(base.1 + dy).unwrap(),
                z: Depth::NEAR,
                rgb: [0; 3],
            };
            let size = 1 + next(12 * 256);
            let (a, b, c) = (
                v(0, 0),
                v(next(size) - size / 2, next(size)),
                v(next(size), next(size) - size / 2),
            );
            let Some(t) = ScreenTriangle::new([a, b, c], 0) else {
                continue;
            };
            let rt = RasterTriangle::new(&t);
            for sampling in [Sampling::Centre, Sampling::Conservative] {
                let probe = spans(&rt, rect, sampling, true);
                let dda = spans(&rt, rect, sampling, false);
                assert_eq!(probe, dda, "{sampling:?} {t:?}");
            }
            compared += 1;
        }
        assert!(compared > 15_000);
    }
}
