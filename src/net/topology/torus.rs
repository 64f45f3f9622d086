//! A k-ary n-cube (torus) with wrap-around links and dimension-order (e-cube) routing:
//! lowest dimension first, the shortest way round each ring, a tie going `+`.
//!
//! A dimension of extent 1 has no links; one of extent 2 has only the `+` link per node
//! (its `+` and `-` neighbours coincide, and a tie never takes `-`). Must never route a
//! higher dimension before a lower one.

use super::grid::{Grid, LineTally};
use super::ring::ring_steps;
use super::{Amount, Link, Topology};
use crate::net::{LinkId, NodeId, TopologyKind};

pub struct Torus {
    grid: Grid,
}

impl Torus {
    pub fn new(dims: &[u32]) -> Torus {
        let grid = Grid::new(dims, |g, node, d, plus| {
            let k = g.dims[d];
            let c = g.coord(node, d);
            match (k, plus) {
                (1, _) | (2, false) => None,
                (_, true) => Some(g.with_coord(node, d, (c + 1) % k)),
                (_, false) => Some(g.with_coord(node, d, (c + k - 1) % k)),
            }
        });
        Torus { grid }
    }
}

impl Topology for Torus {
    fn kind(&self) -> TopologyKind {
        TopologyKind::Torus
    }
    fn nodes(&self) -> u32 {
        self.grid.nodes()
    }
    fn links(&self) -> &[Link] {
        &self.grid.links
    }
    fn route_into(&self, src: NodeId, dst: NodeId, out: &mut Vec<LinkId>) -> bool {
        self.grid.route_into(src, dst, ring_steps, out);
        true
    }
    fn routes_in_place(&self) -> bool {
        true
    }
    fn line_tally(&self) -> Option<LineTally> {
        Some(self.grid.line_tally())
    }
    fn tally_route(&self, src: NodeId, dst: NodeId, tally: &mut LineTally, amount: Amount) -> u32 {
        self.grid.tally_route(src, dst, ring_steps, tally, amount)
    }
    fn tallied(&self, tally: &LineTally) -> Vec<Amount> {
        self.grid.tallied(tally)
    }
    /// The cut across the longest dimension k: each of the N/k rings along it is crossed
    /// twice (2N/k links one way); for k = 2 each ring has one link each way (N/2).
    fn bisection_width(&self) -> u32 {
        let n = self.nodes();
        self.grid
            .dims
            .iter()
            .filter(|&&k| k >= 2)
            .map(|&k| if k == 2 { n / 2 } else { 2 * (n / k) })
            .min()
            .unwrap_or(0)
    }
}
