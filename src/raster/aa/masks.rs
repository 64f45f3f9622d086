//! Paper 000's precomputed bitmask table: the coverage of an n x n subpixel grid by the
//! half-plane of one polygon edge, looked up by where the edge's line enters and leaves the
//! pixel square. A triangle's mask in a pixel is the AND of its three edges' masks.
//!
//! Must never evaluate a sample against the exact edge function: the table is the paper's
//! cheap approximation (crossings quantized to 1/24 of a pixel side), and it must stay a
//! pure function of the edge line and the pixel so that the masks of two triangles sharing
//! an edge are exact complements (a shared edge never drops or doubles a sample).
//!
//! # Positions
//! The pixel's perimeter is cut into 24 steps per side (24 is divisible by 2n for n = 2, 3,
//! 4, so every sample centre `(2i + 1) / 2n` is on the 1/24 lattice too). Perimeter index
//! `p` in 0..96 walks clockwise in y-down screen space from the top-left corner: top side
//! 0..24, right 24..48, bottom 48..72, left 72..96.
//!
//! # Ties
//! A sample exactly on the quantized line (`cross == 0`) belongs to the entry `(from, to)`
//! with `from < to`. The neighbour across a shared edge looks up `(to, from)`, so the tie
//! goes to exactly one of the two.

use std::sync::OnceLock;

use crate::raster::fixed::{Edge, SUBPIXEL_ONE};
use crate::raster::setup::RasterTriangle;

/// Steps per pixel side of the perimeter lattice and the sample lattice.
pub const STEPS: i64 = 24;
/// Perimeter positions of one pixel.
const POSITIONS: usize = 4 * STEPS as usize;

/// A subpixel resolution of an adaptive target: n x n samples per super pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Grid {
    X2,
    X3,
    X4,
}

impl Grid {
    /// Finest first: the order memory adaptation tries them in.
    pub const FINEST_FIRST: [Grid; 3] = [Grid::X4, Grid::X3, Grid::X2];

    /// Samples per side (n).
    pub fn side(self) -> u32 {
        match self {
            Grid::X2 => 2,
            Grid::X3 => 3,
            Grid::X4 => 4,
        }
    }

    /// Samples (and Subpixel cells) per super pixel, n * n.
    pub fn samples(self) -> u32 {
        self.side() * self.side()
    }

    /// `None` unless `side` is 2, 3 or 4.
    pub fn from_side(side: u32) -> Option<Grid> {
        Grid::FINEST_FIRST.into_iter().find(|g| g.side() == side)
    }

    /// Every sample covered.
    pub fn full_mask(self) -> u16 {
        ((1u32 << self.samples()) - 1) as u16
    }

    /// Sample `i` (row-major, bit `i` of a mask) in 1/24 pixel units from the pixel's
    /// top-left corner.
    pub fn sample(self, i: u32) -> (i64, i64) {
        let n = self.side();
        let at = |k: u32| 12 * (2 * i64::from(k) + 1) / i64::from(n);
        (at(i % n), at(i / n))
    }

    fn slot(self) -> usize {
        self as usize
    }
}

impl std::fmt::Display for Grid {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{0}x{0}", self.side())
    }
}

/// The masks of every (from, to) perimeter pair, for each grid.
pub struct MaskTable {
    masks: [Vec<u16>; 3],
}

impl MaskTable {
    fn build() -> MaskTable {
        let one = |g: Grid| {
            let mut v = vec![0u16; POSITIONS * POSITIONS];
            for from in 0..POSITIONS {
                for to in 0..POSITIONS {
                    v[from * POSITIONS + to] = half_plane_mask(g, from, to);
                }
            }
            v
        };
        MaskTable {
            masks: [one(Grid::X2), one(Grid::X3), one(Grid::X4)],
        }
    }

    /// Samples on the inside (left in y-down coordinates, `cross > 0`) of the directed
    /// line `from -> to`.
    pub fn lookup(&self, grid: Grid, from: u8, to: u8) -> u16 {
        self.masks[grid.slot()][usize::from(from) * POSITIONS + usize::from(to)]
    }
}

/// The table, built on first use (a few tens of kilobytes).
pub fn table() -> &'static MaskTable {
    static TABLE: OnceLock<MaskTable> = OnceLock::new();
    TABLE.get_or_init(MaskTable::build)
}

/// A perimeter index as a point in 1/24 pixel units.
fn point(p: usize) -> (i64, i64) {
    let q = (p % STEPS as usize) as i64;
    match p / STEPS as usize {
        0 => (q, 0),
        1 => (STEPS, q),
        2 => (STEPS - q, STEPS),
        _ => (0, STEPS - q),
    }
}

fn half_plane_mask(g: Grid, from: usize, to: usize) -> u16 {
    let (a, b) = (point(from), point(to));
    let mut mask = 0u16;
    for i in 0..g.samples() {
        let s = g.sample(i);
        let cross = (b.0 - a.0) * (s.1 - a.1) - (b.1 - a.1) * (s.0 - a.0);
        if cross > 0 || (cross == 0 && from < to) {
            mask |= 1 << i;
        }
    }
    mask
}

/// How one edge's line meets a pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Crossing {
    /// The whole open pixel square is inside the edge's half-plane.
    Inside,
    /// None of it is.
    Outside,
    /// The line crosses the square, entering at perimeter index `from` and leaving at `to`
    /// (ordered along the edge's direction, so the inside is on the left).
    Through { from: u8, to: u8 },
}

/// Where the line of `edge` crosses pixel `(px, py)`, from the raw (unbiased) edge function
/// at the four corners. A line through two opposite triangles' shared edge gives negated
/// corner values, hence the same two points in the opposite order.
pub fn crossing(edge: &Edge, px: i64, py: i64) -> Crossing {
    let (x0, y0) = (px * SUBPIXEL_ONE, py * SUBPIXEL_ONE);
    let corner = [(0, 0), (1, 0), (1, 1), (0, 1)];
    let e = corner
        .map(|(cx, cy)| i128::from(edge.eval(x0 + cx * SUBPIXEL_ONE, y0 + cy * SUBPIXEL_ONE)));
    if e.iter().all(|&v| v >= 0) {
        return Crossing::Inside;
    }
    if e.iter().all(|&v| v <= 0) {
        return Crossing::Outside;
    }
    let mut points = [0usize; 2];
    let mut found = 0;
    for side in 0..4 {
        let (ea, eb) = (e[side], e[(side + 1) % 4]);
        let q = if ea == 0 {
            Some(0)
        } else if (ea > 0) != (eb > 0) && eb != 0 {
            Some(quantize(ea, eb))
        } else {
            None
        };
        if let (Some(q), true) = (q, found < 2) {
            points[found] = (side * STEPS as usize + q as usize) % POSITIONS;
            found += 1;
        }
    }
    let centre_inside = || {
        let half = SUBPIXEL_ONE / 2;
        edge.covers(x0 + half, y0 + half)
    };
    let (p, q) = (point(points[0]), point(points[1]));
    let along = (q.0 - p.0) * edge.dx + (q.1 - p.1) * edge.dy;
    if found < 2 || points[0] == points[1] || along == 0 {
        // The line only grazes a corner at this resolution: no sample lies between it and
        // the corner, so the whole pixel is on the centre's side.
        return if centre_inside() {
            Crossing::Inside
        } else {
            Crossing::Outside
        };
    }
    let (from, to) = if along > 0 {
        (points[0], points[1])
    } else {
        (points[1], points[0])
    };
    Crossing::Through {
        from: from as u8,
        to: to as u8,
    }
}

/// `round(24 * ea / (ea - eb))`, halves away from the start corner; a function of the
/// ratio only, so negating both values gives the same step.
fn quantize(ea: i128, eb: i128) -> i64 {
    let (mut num, mut den) = (i128::from(STEPS) * ea, ea - eb);
    if den < 0 {
        num = -num;
        den = -den;
    }
    (2 * num + den).div_euclid(2 * den) as i64
}

/// The coverage mask of pixel `(px, py)` by `tri` on `grid`: the AND of its edges' table
/// masks.
pub fn triangle_mask(tri: &RasterTriangle, px: i64, py: i64, grid: Grid) -> u16 {
    let t = table();
    let mut mask = grid.full_mask();
    for edge in &tri.edges {
        match crossing(edge, px, py) {
            Crossing::Inside => {}
            Crossing::Outside => return 0,
            Crossing::Through { from, to } => mask &= t.lookup(grid, from, to),
        }
    }
    mask
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_sit_on_the_lattice_at_cell_centres() {
        // n = 4: 1/8, 3/8, 5/8, 7/8 of a pixel = 3, 9, 15, 21 steps of 1/24.
        assert_eq!(Grid::X4.sample(0), (3, 3));
        assert_eq!(Grid::X4.sample(15), (21, 21));
        assert_eq!(Grid::X3.sample(4), (12, 12));
        assert_eq!(Grid::X2.sample(1), (18, 6));
    }

    #[test]
    fn opposite_directions_are_exact_complements() {
        let t = table();
        for g in Grid::FINEST_FIRST {
            for a in 0..POSITIONS as u8 {
                for b in 0..POSITIONS as u8 {
                    if a == b {
                        continue;
                    }
                    let (m, n) = (t.lookup(g, a, b), t.lookup(g, b, a));
                    assert_eq!(m & n, 0, "{g} {a}->{b}");
                    assert_eq!(m | n, g.full_mask(), "{g} {a}->{b}");
                }
            }
        }
    }

    #[test]
    fn a_vertical_line_through_the_middle_splits_the_grid_in_half() {
        // Top-centre (index 12) to bottom-centre (index 60): eight samples on one side.
        let m = table().lookup(Grid::X4, 12, 60);
        assert_eq!(m.count_ones(), 8);
        let n = table().lookup(Grid::X4, 60, 12);
        assert_eq!(m | n, 0xffff);
    }
}
