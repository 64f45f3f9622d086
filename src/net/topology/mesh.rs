//! A 2D or 3D mesh (no wrap-around) with dimension-order routing: X, then Y, then Z. The
//! Intel Delta is a 16x32 mesh.
//!
//! Must never route a higher dimension before a lower one, nor use a link off the edge.

use super::grid::Grid;
use super::{Link, Topology};
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
        let g = &self.grid;
        let mut at = src;
        for d in 0..g.dims.len() {
            let (c, target) = (g.coord(at, d), g.coord(dst, d));
            at = g.walk(at, (d, c), c.abs_diff(target), c < target, out);
        }
        true
    }
    fn routes_in_place(&self) -> bool {
        true
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
