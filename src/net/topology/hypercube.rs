//! A binary hypercube of 2^n nodes with e-cube routing: fix the lowest differing bit first.
//!
//! Link `i * n + b` is `i -> i ^ (1 << b)`. Must never fix a higher bit before a lower one.

use super::{Link, Topology};
use crate::net::{LinkId, NodeId, TopologyKind};

pub struct Hypercube {
    nodes: u32,
    bits: u32,
    links: Vec<Link>,
}

impl Hypercube {
    /// `nodes` is a power of two (checked by `topology::build`).
    pub fn new(nodes: u32) -> Hypercube {
        let bits = nodes.trailing_zeros();
        let links = (0..nodes)
            .flat_map(|i| (0..bits).map(move |b| Link::wire(i, i ^ (1 << b))))
            .collect();
        Hypercube { nodes, bits, links }
    }
}

impl Topology for Hypercube {
    fn kind(&self) -> TopologyKind {
        TopologyKind::Hypercube
    }
    fn nodes(&self) -> u32 {
        self.nodes
    }
    fn links(&self) -> &[Link] {
        &self.links
    }
    fn route_into(&self, src: NodeId, dst: NodeId, out: &mut Vec<LinkId>) -> bool {
        let mut at = src;
        for b in 0..self.bits {
            if (at ^ dst) & (1 << b) != 0 {
                out.push(at * self.bits + b);
                at ^= 1 << b;
            }
        }
        true
    }
    /// Cutting along one bit crosses N/2 links one way.
    fn bisection_width(&self) -> u32 {
        self.nodes / 2
    }
}
