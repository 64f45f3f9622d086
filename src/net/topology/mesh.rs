//! A 2D or 3D mesh (no wrap-around) with dimension-order routing: X, then Y, then Z. The
//! Intel Delta is a 16x32 mesh.
//!
//! Must never route a higher dimension before a lower one, nor use a link off the edge.

use super::grid::{Grid, LineTally};
use super::{Amount, Link, Topology};
use crate::net::{LinkId, NodeId, TopologyKind};

pub struct Mesh {
    grid: Grid,
}

impl Mesh {
    pub fn new(dims: &[u32]) -> Mesh {
        let grid = Grid::new(dims, |g, node, d, plus| {
            let c = g.coord(node, d);
            match plus {
                true if c + 1 < g.dims[d] => Some(g.with_coord(node, d, c + 1)),
                false if c > 0 => Some(g.with_coord(node, d, c - 1)),
                _ => None,
            }
        });
        Mesh { grid }
    }

    /// The route's legs, lowest dimension first: `leg(node, (d, coordinate), steps, plus)`
    /// takes each from where the last ended and returns where it ends.
    #[inline]
    fn legs(
        &self,
        src: NodeId,
        dst: NodeId,
        mut leg: impl FnMut(NodeId, (usize, u32), u32, bool) -> NodeId,
    ) {
        let g = &self.grid;
        let mut at = src;
        for d in 0..g.dims.len() {
            let (c, target) = (g.coord(at, d), g.coord(dst, d));
            at = leg(at, (d, c), c.abs_diff(target), c < target);
        }
    }
}

impl Topology for Mesh {
    fn kind(&self) -> TopologyKind {
        TopologyKind::Mesh
    }
    fn nodes(&self) -> u32 {
        self.grid.nodes()
    }
    fn links(&self) -> &[Link] {
        &self.grid.links
    }
    fn route_into(&self, src: NodeId, dst: NodeId, out: &mut Vec<LinkId>) -> bool {
        self.legs(src, dst, |at, dc, steps, plus| {
            self.grid.walk(at, dc, steps, plus, out)
        });
        true
    }
    fn routes_in_place(&self) -> bool {
        true
    }
    fn line_tally(&self) -> Option<LineTally> {
        Some(self.grid.line_tally())
    }
    fn tally_route(&self, src: NodeId, dst: NodeId, tally: &mut LineTally, amount: Amount) -> u32 {
        let mut links = 0;
        self.legs(src, dst, |at, dc, steps, plus| {
            links += steps;
            self.grid.tally(at, dc, steps, plus, tally, amount)
        });
        links
    }
    fn tallied(&self, tally: &LineTally) -> Vec<Amount> {
        self.grid.tallied(tally)
    }
    /// The smallest cross-section: cutting the longest dimension k crosses N/k links one way.
    fn bisection_width(&self) -> u32 {
        let n = self.nodes();
        self.grid
            .dims
            .iter()
            .filter(|&&k| k >= 2)
            .map(|&k| n / k)
            .min()
            .unwrap_or(0)
    }
}
