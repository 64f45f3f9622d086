//! Routes computed once per (source, destination) pair: the first message between two nodes
//! asks the topology, every later one reads the stored list of links.
//!
//! Owns the store only (rows per source, allocated when that source first sends, and one
//! arena of links). Must never decide a route itself (that is the topology's), and never
//! hand out a route different from what `Topology::route_into` gives for the pair.

use super::topology::Topology;
use super::{LinkId, NodeId};

/// Not asked yet.
const UNKNOWN: (u32, u32) = (u32::MAX, 0);
/// The topology has no route (a pipeline run backwards).
const NO_ROUTE: (u32, u32) = (u32::MAX, 1);

/// Per destination: `(start, len)` in `Routes::links`, or a marker above.
type Row = Box<[(u32, u32)]>;

#[derive(Default)]
pub struct Routes {
    /// Per source, allocated when it first sends.
    rows: Vec<Option<Row>>,
    links: Vec<LinkId>,
}

impl Routes {
    pub fn new(nodes: u32) -> Routes {
        Routes {
            rows: (0..nodes).map(|_| None).collect(),
            links: Vec::new(),
        }
    }

    /// The links from `src` to `dst` (both `< nodes`), in order; `None` when the topology has
    /// no route.
    pub fn get(&mut self, topology: &dyn Topology, src: NodeId, dst: NodeId) -> Option<&[LinkId]> {
        let nodes = self.rows.len();
        let row = self.rows[src as usize].get_or_insert_with(|| vec![UNKNOWN; nodes].into());
        let mut entry = row[dst as usize];
        if entry == UNKNOWN {
            let start = self.links.len();
            entry = if topology.route_into(src, dst, &mut self.links) {
                (start as u32, (self.links.len() - start) as u32)
            } else {
                self.links.truncate(start);
                NO_ROUTE
            };
            row[dst as usize] = entry;
        }
        (entry != NO_ROUTE).then(|| &self.links[entry.0 as usize..(entry.0 + entry.1) as usize])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::net::topology::build;
    use crate::net::TopologyKind;

    #[test]
    fn stored_routes_equal_the_topologys_for_every_pair_asked_twice() {
        for (kind, dims) in [
            (TopologyKind::Torus, vec![4, 4]),
            (TopologyKind::Mesh, vec![3, 5]),
            (TopologyKind::Pipeline, vec![6]),
            (TopologyKind::Ring, vec![5]),
            (TopologyKind::Crossbar, vec![4]),
        ] {
            let topology = build(kind, &dims).unwrap();
            let n = topology.nodes();
            let mut routes = Routes::new(n);
            for pass in 0..2 {
                for src in 0..n {
                    for dst in 0..n {
                        let mut direct = Vec::new();
                        let ok = topology.route_into(src, dst, &mut direct);
                        let stored = routes.get(topology.as_ref(), src, dst).map(|r| r.to_vec());
                        assert_eq!(
                            stored,
                            ok.then_some(direct),
                            "{kind:?} {src}->{dst} pass {pass}"
                        );
                    }
                }
            }
        }
    }
}
