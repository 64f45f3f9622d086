//! A bidirectional ring: shortest direction, a tie (exactly opposite) goes clockwise.
//!
//! Link `2i` is `i -> i+1` (clockwise), link `2i+1` is `i -> i-1` (counter-clockwise). A
//! one-node ring has no links. Must never route the long way round.

use super::{Link, Topology};
use crate::net::{LinkId, NodeId, TopologyKind};

pub struct Ring {
    nodes: u32,
    links: Vec<Link>,
}

impl Ring {
    pub fn new(nodes: u32) -> Ring {
        let mut links = Vec::new();
        if nodes > 1 {
            for i in 0..nodes {
                links.push(Link::wire(i, (i + 1) % nodes));
                links.push(Link::wire(i, (i + nodes - 1) % nodes));
            }
        }
        Ring { nodes, links }
    }
}

/// Steps from `src` to `dst` on a ring of `k`, as (count, clockwise). Ties go clockwise.
pub(super) fn ring_steps(src: u32, dst: u32, k: u32) -> (u32, bool) {
    let clockwise = (dst + k - src) % k;
    let counter = (k - clockwise) % k;
    if clockwise <= counter {
        (clockwise, true)
    } else {
        (counter, false)
    }
}

impl Topology for Ring {
    fn kind(&self) -> TopologyKind {
        TopologyKind::Ring
    }
    fn nodes(&self) -> u32 {
        self.nodes
    }
    fn links(&self) -> &[Link] {
        &self.links
    }
    fn route_into(&self, src: NodeId, dst: NodeId, out: &mut Vec<LinkId>) -> bool {
        let n = self.nodes;
        let (steps, clockwise) = ring_steps(src, dst, n);
        let mut at = src;
        for _ in 0..steps {
            if clockwise {
                out.push(2 * at);
                at = (at + 1) % n;
            } else {
                out.push(2 * at + 1);
                at = (at + n - 1) % n;
            }
        }
        true
    }
    /// A balanced cut crosses the ring twice; one direction of each crossing counts. (Two
    /// nodes: both links 0->1 cross, still 2.)
    fn bisection_width(&self) -> u32 {
        if self.nodes > 1 {
            2
        } else {
            0
        }
    }
}
