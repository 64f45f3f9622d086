//! A crossbar: every node has an output port (link `i`, `out{i}`) and an input port (link
//! `N + i`, `in{i}`); a message `src -> dst` uses `[out(src), in(dst)]`, acquired together as
//! ONE hop (one switch traversal), so only endpoint contention exists.
//!
//! Must never add internal links: the switch itself is non-blocking.

use super::{Link, LinkKind, Topology};
use crate::net::{LinkId, NodeId, TopologyKind};

pub struct Crossbar {
    nodes: u32,
    links: Vec<Link>,
}

impl Crossbar {
    pub fn new(nodes: u32) -> Crossbar {
        let port = |i, kind| Link {
            from: i,
            to: i,
            kind,
        };
        let outs = (0..nodes).map(|i| port(i, LinkKind::Out));
        let ins = (0..nodes).map(|i| port(i, LinkKind::In));
        Crossbar {
            nodes,
            links: outs.chain(ins).collect(),
        }
    }
}

impl Topology for Crossbar {
    fn kind(&self) -> TopologyKind {
        TopologyKind::Crossbar
    }
    fn nodes(&self) -> u32 {
        self.nodes
    }
    fn links(&self) -> &[Link] {
        &self.links
    }
    fn route_into(&self, src: NodeId, dst: NodeId, out: &mut Vec<LinkId>) -> bool {
        if src != dst {
            out.push(src);
            out.push(self.nodes + dst);
        }
        true
    }
    fn links_per_hop(&self) -> u32 {
        2
    }
    /// The switch never blocks, so a balanced cut is limited by the ports: the floor(N/2)
    /// output ports of one half, counted one way.
    fn bisection_width(&self) -> u32 {
        self.nodes / 2
    }
}
