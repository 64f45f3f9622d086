//! A one-way pipeline: link `i` is `i -> i+1`, no wrap-around.
//!
//! Owns the rule that only higher node ids are reachable; a message backwards has no route
//! and must never be invented one.

use super::{Link, Topology};
use crate::net::{LinkId, NodeId, TopologyKind};

pub struct Pipeline {
    nodes: u32,
    links: Vec<Link>,
}

impl Pipeline {
    pub fn new(nodes: u32) -> Pipeline {
        let links = (1..nodes).map(|i| Link::wire(i - 1, i)).collect();
        Pipeline { nodes, links }
    }
}

impl Topology for Pipeline {
    fn kind(&self) -> TopologyKind {
        TopologyKind::Pipeline
    }
    fn routes_every_pair(&self) -> bool {
        self.nodes <= 1
    }
    fn nodes(&self) -> u32 {
        self.nodes
    }
    fn links(&self) -> &[Link] {
        &self.links
    }
    fn route_into(&self, src: NodeId, dst: NodeId, out: &mut Vec<LinkId>) -> bool {
        if dst < src {
            return false;
        }
        out.extend(src..dst);
        true
    }
    /// Cutting the pipeline in the middle crosses one link.
    fn bisection_width(&self) -> u32 {
        u32::from(self.nodes > 1)
    }
}
