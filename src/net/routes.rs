//! Routes computed once per (source, destination) pair: the first message between two nodes
//! asks the topology, every later one reads the stored list of links. A topology whose
//! routes cost a load a hop (`Topology::routes_in_place`: the mesh and the torus) is asked
//! every time instead, into one list reused, as that is cheaper than the store's cache misses.
//!
//! Owns the store only (rows per source, begun when that source first sends, and one arena
//! of links). A row starts as a short sorted list of the destinations the source has sent
//! to and becomes a table over every destination once the source has talked to many: a
//! compositing round talks to a few partners, an all-to-all to everyone, and a table per
//! source would take `nodes^2` entries (8.6 GB at 32,768 nodes). Must never decide a route
//! itself (that is the topology's), and never hand out a route different from what
//! `Topology::route_into` gives for the pair.

use super::topology::Topology;
use super::{LinkId, NodeId};

/// Not asked yet.
const UNKNOWN: (u32, u32) = (u32::MAX, 0);
/// The topology has no route (a pipeline run backwards).
const NO_ROUTE: (u32, u32) = (u32::MAX, 1);

/// A source's routes: `(start, len)` in `Routes::links`, or a marker above.
enum Row {
    /// The destinations asked so far, sorted, each with its entry.
    Few(Vec<(NodeId, (u32, u32))>),
    /// Every destination's entry.
    All(Box<[(u32, u32)]>),
}

/// Destinations a row lists before it becomes a table: a table costs 8 bytes per node, a
/// listed destination 12, and a lookup in a list a binary search.
fn table_after(nodes: usize) -> usize {
    (nodes / 16).max(64)
}

#[derive(Default)]
pub struct Routes {
    /// Per source, begun when it first sends.
    rows: Vec<Option<Row>>,
    links: Vec<LinkId>,
    /// The last route computed in place.
    in_place: Vec<LinkId>,
}

impl Routes {
    pub fn new(nodes: u32) -> Routes {
        Routes {
            rows: (0..nodes).map(|_| None).collect(),
            links: Vec::new(),
            in_place: Vec::new(),
        }
    }

    /// The links from `src` to `dst` (both `< nodes`), in order; `None` when the topology has
    /// no route.
    pub fn get(&mut self, topology: &dyn Topology, src: NodeId, dst: NodeId) -> Option<&[LinkId]> {
        if topology.routes_in_place() {
            self.in_place.clear();
            return topology
                .route_into(src, dst, &mut self.in_place)
                .then_some(&self.in_place[..]);
        }
        let nodes = self.rows.len();
        let row = self.rows[src as usize].get_or_insert_with(|| Row::Few(Vec::new()));
        let known = match row {
            Row::All(all) => all[dst as usize],
            Row::Few(few) => match few.binary_search_by_key(&dst, |e| e.0) {
                Ok(i) => few[i].1,
                Err(_) => UNKNOWN,
            },
        };
        let entry = if known != UNKNOWN {
            known
        } else {
            let start = self.links.len();
            let entry = if topology.route_into(src, dst, &mut self.links) {
                (start as u32, (self.links.len() - start) as u32)
            } else {
                self.links.truncate(start);
                NO_ROUTE
            };
            match row {
                Row::All(all) => all[dst as usize] = entry,
                Row::Few(few) => {
                    let at = few.partition_point(|e| e.0 < dst);
                    few.insert(at, (dst, entry));
                    if few.len() > table_after(nodes) {
                        let mut all = vec![UNKNOWN; nodes].into_boxed_slice();
                        for &(d, e) in few.iter() {
                            all[d as usize] = e;
                        }
                        *row = Row::All(all);
                    }
                }
            }
            entry
        };
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
            // Enough destinations per source for its list to become a table midway (a store:
            // a ring's routes are not computed in place).
            (TopologyKind::Ring, vec![144]),
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
