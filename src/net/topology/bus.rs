//! A bus: one shared medium that every message uses, and the only topology with broadcast
//! (one transmission reaches every other node).
//!
//! Its single link is reported as `bus` with `from` = `to` = 0. Must never give a message
//! more than one link.

use super::{Link, LinkKind, Topology};
use crate::net::{LinkId, NodeId, TopologyKind};

pub struct Bus {
    nodes: u32,
    links: [Link; 1],
}

impl Bus {
    pub fn new(nodes: u32) -> Bus {
        let medium = Link {
            from: 0,
            to: 0,
            kind: LinkKind::Bus,
        };
        Bus {
            nodes,
            links: [medium],
        }
    }
}

impl Topology for Bus {
    fn kind(&self) -> TopologyKind {
        TopologyKind::Bus
    }
    fn nodes(&self) -> u32 {
        self.nodes
    }
    fn links(&self) -> &[Link] {
        &self.links
    }
    fn route_into(&self, src: NodeId, dst: NodeId, out: &mut Vec<LinkId>) -> bool {
        if src != dst {
            out.push(0);
        }
        true
    }
    /// Any cut crosses the one medium.
    fn bisection_width(&self) -> u32 {
        1
    }
    fn broadcast_link(&self) -> Option<LinkId> {
        Some(0)
    }
}
