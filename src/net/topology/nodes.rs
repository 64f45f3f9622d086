//! Nodes of several processors: `G` processors (GPUs, cores) and `K` network interfaces on
//! one switch per node, the NICs being the hosts of any other topology (the network between
//! nodes). Where processor `p` sits is the [`Placement`]: slot `i` of node `m` with
//! `(m, i) = (p / G, p mod G)` (`block`: a node's processors numbered together, as a GPU
//! cluster numbers its ranks) or `(p mod M, p / M)` (`cyclic`: consecutive processors on
//! consecutive nodes, Blue Gene's default XYZT order). Slot `i` sends and receives through
//! its node's NIC `i mod K` (NIC `m * K + k` of the network between nodes), the way each GPU
//! of a multi-GPU node is paired with a NIC.
//!
//! Links: the network's own first (its vertices moved up by `M * G`), then per node, for each
//! processor its pair to the switch, for each NIC its pair from the switch; those node links
//! run at the node's rate. A route inside a node is processor, switch, processor; between
//! nodes, processor, switch, NIC, the network's route between the two NICs, NIC, switch,
//! processor.
//!
//! Must never route between nodes except through the network's own route, nor wrap a
//! topology whose hops take more than one link (a crossbar) or that broadcasts (a bus).

use super::{Link, Topology};
use crate::net::{LinkId, NetError, NodeId, TopologyKind};

/// Which node and slot each processor takes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Placement {
    /// Processor `p` in slot `p mod G` of node `p / G`.
    #[default]
    Block,
    /// Processor `p` in slot `p / M` of node `p mod M` (`M` nodes).
    Cyclic,
}

pub struct Nodes {
    network: Box<dyn Topology>,
    placement: Placement,
    processors: u32,
    nics: u32,
    nodes: u32,
    links: Vec<Link>,
    /// Id of the first node link: the network's links come before it.
    first_node_link: LinkId,
}

impl Nodes {
    pub fn new(
        network: Box<dyn Topology>,
        processors: u32,
        nics: u32,
        placement: Placement,
    ) -> Result<Nodes, NetError> {
        let kind = network.kind();
        let invalid = |what: String| Err(NetError::Config(format!("nodes on a {kind}: {what}")));
        if matches!(kind, TopologyKind::Crossbar | TopologyKind::Bus) {
            return invalid(
                "the network between nodes must be a point-to-point topology (not a crossbar \
                 or a bus)"
                    .to_string(),
            );
        }
        if processors == 0 || nics == 0 {
            return invalid("a node needs at least 1 processor and 1 NIC".to_string());
        }
        let hosts = network.nodes();
        if hosts % nics != 0 {
            return invalid(format!(
                "the network's {hosts} hosts are NICs, {nics} per node: {hosts} is not a \
                 multiple of {nics}"
            ));
        }
        let nodes = hosts / nics;
        let Some(processor_count) = nodes.checked_mul(processors) else {
            return invalid(format!(
                "{nodes} nodes of {processors} processors overflow u32"
            ));
        };
        // Vertex ids: processors, then the network's vertices, then the node switches.
        let shift = processor_count;
        let network_vertices = network
            .links()
            .iter()
            .map(|l| l.from.max(l.to) + 1)
            .max()
            .unwrap_or(0)
            .max(hosts);
        let first_switch = shift as u64 + network_vertices as u64;
        if first_switch + nodes as u64 > u32::MAX as u64 {
            return invalid(format!("more than {} vertices", u32::MAX));
        }
        let first_switch = first_switch as u32;
        let mut links: Vec<Link> = network
            .links()
            .iter()
            .map(|l| Link {
                from: l.from + shift,
                to: l.to + shift,
                kind: l.kind,
            })
            .collect();
        let first_node_link = links.len() as LinkId;
        let processor_at = |m: u32, i: u32| match placement {
            Placement::Block => m * processors + i,
            Placement::Cyclic => i * nodes + m,
        };
        for m in 0..nodes {
            let switch = first_switch + m;
            for i in 0..processors {
                let p = processor_at(m, i);
                links.push(Link::wire(p, switch));
                links.push(Link::wire(switch, p));
            }
            for k in 0..nics {
                let nic = shift + m * nics + k;
                links.push(Link::wire(switch, nic));
                links.push(Link::wire(nic, switch));
            }
        }
        Ok(Nodes {
            network,
            placement,
            processors,
            nics,
            nodes,
            links,
            first_node_link,
        })
    }

    /// The first link of node `m`'s block: its processors' pairs, then its NICs'.
    fn block(&self, m: u32) -> LinkId {
        self.first_node_link + 2 * m * (self.processors + self.nics)
    }

    /// Processor `p`'s node and slot in it.
    fn place(&self, p: NodeId) -> (u32, u32) {
        match self.placement {
            Placement::Block => (p / self.processors, p % self.processors),
            Placement::Cyclic => (p % self.nodes, p / self.nodes),
        }
    }

    fn processor_up(&self, p: NodeId) -> LinkId {
        let (m, i) = self.place(p);
        self.block(m) + 2 * i
    }

    /// The NIC processor `p` uses, as a host of the network between nodes.
    fn nic_of(&self, p: NodeId) -> NodeId {
        let (m, i) = self.place(p);
        m * self.nics + i % self.nics
    }

    /// The link from node `m`'s switch to its NIC `k` (the way back is the next id).
    fn switch_to_nic(&self, m: u32, k: u32) -> LinkId {
        self.block(m) + 2 * self.processors + 2 * k
    }
}

impl Topology for Nodes {
    fn kind(&self) -> TopologyKind {
        self.network.kind()
    }
    fn nodes(&self) -> u32 {
        self.nodes * self.processors
    }
    fn links(&self) -> &[Link] {
        &self.links
    }
    fn route_into(&self, src: NodeId, dst: NodeId, out: &mut Vec<LinkId>) -> bool {
        if src == dst {
            return true;
        }
        let (m, m2) = (self.place(src).0, self.place(dst).0);
        out.push(self.processor_up(src));
        if m != m2 {
            let (a, b) = (self.nic_of(src), self.nic_of(dst));
            out.push(self.switch_to_nic(m, a % self.nics));
            if !self.network.route_into(a, b, out) {
                return false;
            }
            out.push(self.switch_to_nic(m2, b % self.nics) + 1);
        }
        out.push(self.processor_up(dst) + 1);
        true
    }
    fn is_node_link(&self, link: LinkId) -> bool {
        link >= self.first_node_link
    }
    /// The network's bisection, or, with one node, its NIC-side switch ports: a node's
    /// processors split in two halves share its switch, so half of them, one way.
    fn bisection_width(&self) -> u32 {
        if self.nodes > 1 {
            self.network.bisection_width()
        } else {
            self.processors / 2
        }
    }
    fn routes_every_pair(&self) -> bool {
        self.network.routes_every_pair()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::net::topology::build;

    fn names(t: &Nodes, s: u32, d: u32) -> Vec<String> {
        let mut out = Vec::new();
        assert!(t.route_into(s, d, &mut out));
        out.iter()
            .map(|&l| t.links[l as usize].name(t.nodes()))
            .collect()
    }

    #[test]
    fn four_nodes_of_four_gpus_and_two_nics_on_a_ring() {
        // A ring of 8 NICs: nodes 0..4 with NICs (0, 1), (2, 3), ...; 16 processors.
        let ring = build(TopologyKind::Ring, &[8]).unwrap();
        let t = Nodes::new(ring, 4, 2, Placement::Block).unwrap();
        assert_eq!(t.nodes(), 16);
        // Vertices: processors 0..16, NICs 16..24 (s0..s7 in names), node switches s8..s11.
        // Inside node 0: processor, switch, processor.
        assert_eq!(names(&t, 1, 3), ["1->s8", "s8->3"]);
        // Processor 1 (node 0) uses NIC 1 (s1); processor 6 (node 1, local 2) NIC 2 (s2).
        assert_eq!(
            names(&t, 1, 6),
            ["1->s8", "s8->s1", "s1->s2", "s2->s9", "s9->6"]
        );
        let mut route = Vec::new();
        t.route_into(1, 6, &mut route);
        let node: Vec<bool> = route.iter().map(|&l| t.is_node_link(l)).collect();
        assert_eq!(node, [true, true, false, true, true]);
        assert_eq!(t.bisection_width(), 2);
    }

    #[test]
    fn cyclic_placement_puts_consecutive_processors_on_consecutive_nodes() {
        // The same 16 processors on 4 nodes, now processor p on node p mod 4, slot p / 4:
        // processors 1 and 5 share node 1 (switch s9), 1 and 2 are a node apart.
        let ring = build(TopologyKind::Ring, &[8]).unwrap();
        let t = Nodes::new(ring, 4, 2, Placement::Cyclic).unwrap();
        assert_eq!(names(&t, 1, 5), ["1->s9", "s9->5"]);
        // Processor 1 is slot 0 of node 1 (NIC 2 = s2); processor 6 slot 1 of node 2 (NIC 5).
        assert_eq!(
            names(&t, 1, 6),
            ["1->s9", "s9->s2", "s2->s3", "s3->s4", "s4->s5", "s5->s10", "s10->6"]
        );
        // Every processor has its own pair of node links, and they are on its node's switch.
        for p in 0..16 {
            let mut route = Vec::new();
            assert!(t.route_into(p, (p + 4) % 16, &mut route));
            assert_eq!(
                route.len(),
                2,
                "processors {p} and {} share a node",
                (p + 4) % 16
            );
            let up = t.links[route[0] as usize];
            assert_eq!((up.from, up.to), (p, 24 + p % 4));
        }
    }

    #[test]
    fn a_crossbar_or_a_bus_cannot_join_nodes() {
        for kind in [TopologyKind::Crossbar, TopologyKind::Bus] {
            let e = Nodes::new(build(kind, &[4]).unwrap(), 2, 1, Placement::Block)
                .err()
                .unwrap();
            assert!(e.to_string().contains("point-to-point"), "{e}");
        }
        let e = Nodes::new(
            build(TopologyKind::Ring, &[6]).unwrap(),
            2,
            4,
            Placement::Block,
        )
        .err()
        .unwrap();
        assert!(e.to_string().contains("not a multiple of 4"), "{e}");
    }
}
