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
}

/// The mesh's leg along one dimension: straight to the target's coordinate.
fn mesh_leg(c: u32, target: u32, _k: u32) -> (u32, bool) {
    (c.abs_diff(target), c < target)
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
        self.grid.route_into(src, dst, mesh_leg, out);
        true
    }
    fn routes_in_place(&self) -> bool {
        true
    }
    fn line_tally(&self) -> Option<LineTally> {
        Some(self.grid.line_tally())
    }
    fn tally_route(&self, src: NodeId, dst: NodeId, tally: &mut LineTally, amount: Amount) -> u32 {
        self.grid.tally_route(src, dst, mesh_leg, tally, amount)
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
