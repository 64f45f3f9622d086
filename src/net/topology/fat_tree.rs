//! A generalized fat-tree (an XGFT): `h` levels of switches above the hosts, each switch of
//! level `l + 1` joined to `down[l]` children, each node of level `l` to `up[l]` parents,
//! every such pair by `parallel[l]` cables. SimGrid's fat-tree cluster zone has the same
//! parameters (`levels;down;up;parallel`) and the same construction, so sortsim and SimGrid
//! build the same links in the same order and route every pair over the same cables
//! (`sortsim validate network` compares them one for one).
//!
//! Labels: a node of level `l` has one digit per level; digit `i` counts `up[i]` parents
//! below level `l` (`i < l`) and `down[i]` children from it on; positions enumerate labels
//! with digit 0 fastest. A parent and a child are joined when their labels agree on every
//! digit except the child's level. Vertex ids: hosts `0..N`, then the switches level by
//! level, by position. Links are numbered in pairs, up (child to parent) then down, in the
//! order: child level, child position, parent position, cable.
//!
//! Routing, deterministic like InfiniBand's static tables ("destination mod k"): going up
//! from a node of level `l`, the port is `(dst / (up[0] * .. * up[l-1])) mod (up[l] *
//! parallel[l])` (port `t + j * up[l]` is cable `j` to parent `t`), until the node's subtree
//! holds the destination; going down, a switch of level `L` scans its child ports from
//! `(src mod parallel[L-1]) * down[L-1]` upwards and takes the first whose child is on the
//! destination's side, and the scan goes on from the next port at the switch it reached
//! (SimGrid's rule, kept so that the cables chosen among parallel ones agree).
//!
//! Must never route a pair over a path that is not connected, nor depend on anything but
//! the two endpoints.

use super::{Link, Topology};
use crate::net::{LinkId, NodeId, TopologyKind};

pub struct FatTree {
    down: Vec<u32>,
    up: Vec<u32>,
    parallel: Vec<u32>,
    /// First vertex id of each level (0 for the hosts), and one past the last.
    level_start: Vec<u32>,
    links: Vec<Link>,
    /// Per vertex, its up links by port `t + j * up[level]`.
    up_ports: Vec<Vec<LinkId>>,
    /// Per switch vertex, its down links by port `digit + j * down[level - 1]`.
    down_ports: Vec<Vec<LinkId>>,
}

impl FatTree {
    /// `dims` is `down ++ up ++ parallel`, one entry per level each (checked by the caller).
    pub fn new(dims: &[u32]) -> FatTree {
        let h = dims.len() / 3;
        let (down, up, parallel) = (
            dims[..h].to_vec(),
            dims[h..2 * h].to_vec(),
            dims[2 * h..].to_vec(),
        );
        let mut level_start = vec![0u32];
        for l in 0..=h {
            let size: u32 = (0..h)
                .map(|i| if i < l { up[i] } else { down[i] })
                .product();
            level_start.push(level_start[l] + size);
        }
        let vertices = level_start[h + 1] as usize;
        let mut tree = FatTree {
            down,
            up,
            parallel,
            level_start,
            links: Vec::new(),
            up_ports: vec![Vec::new(); vertices],
            down_ports: vec![Vec::new(); vertices],
        };
        tree.wire();
        tree
    }

    fn levels(&self) -> usize {
        self.down.len()
    }

    /// Digit `i`'s radix at level `l`.
    fn radix(&self, l: usize, i: usize) -> u32 {
        if i < l {
            self.up[i]
        } else {
            self.down[i]
        }
    }

    fn label(&self, l: usize, position: u32) -> Vec<u32> {
        let mut rest = position;
        (0..self.levels())
            .map(|i| {
                let r = self.radix(l, i);
                let digit = rest % r;
                rest /= r;
                digit
            })
            .collect()
    }

    fn vertex(&self, l: usize, label: &[u32]) -> NodeId {
        let position = (0..self.levels())
            .rev()
            .fold(0, |acc, i| acc * self.radix(l, i) + label[i]);
        self.level_start[l] + position
    }

    fn level_of(&self, v: NodeId) -> usize {
        self.level_start.partition_point(|&s| s <= v) - 1
    }

    fn wire(&mut self) {
        for l in 0..self.levels() {
            let (w, m, p) = (self.up[l], self.down[l], self.parallel[l]);
            for child in self.level_start[l]..self.level_start[l + 1] {
                let label = self.label(l, child - self.level_start[l]);
                self.up_ports[child as usize] = vec![0; (w * p) as usize];
                for t in 0..w {
                    let mut parent_label = label.clone();
                    parent_label[l] = t;
                    let parent = self.vertex(l + 1, &parent_label);
                    if self.down_ports[parent as usize].is_empty() {
                        self.down_ports[parent as usize] = vec![0; (m * p) as usize];
                    }
                    for j in 0..p {
                        let up = self.links.len() as LinkId;
                        self.links.push(Link::wire(child, parent));
                        self.links.push(Link::wire(parent, child));
                        self.up_ports[child as usize][(t + j * w) as usize] = up;
                        self.down_ports[parent as usize][(label[l] + j * m) as usize] = up + 1;
                    }
                }
            }
        }
    }

    /// Whether host `dst` lies below vertex `v` (a switch): their labels agree from `v`'s
    /// level up.
    fn holds(&self, v: NodeId, dst_label: &[u32]) -> bool {
        let l = self.level_of(v);
        l > 0 && {
            let label = self.label(l, v - self.level_start[l]);
            (l..self.levels()).all(|i| label[i] == dst_label[i])
        }
    }
}

impl Topology for FatTree {
    fn kind(&self) -> TopologyKind {
        TopologyKind::FatTree
    }
    fn nodes(&self) -> u32 {
        self.level_start[1]
    }
    fn links(&self) -> &[Link] {
        &self.links
    }
    fn route_into(&self, src: NodeId, dst: NodeId, out: &mut Vec<LinkId>) -> bool {
        if src == dst {
            return true;
        }
        let dst_label = self.label(0, dst);
        let mut at = src;
        while !self.holds(at, &dst_label) {
            let l = self.level_of(at);
            let below: u32 = self.up[..l].iter().product();
            let port = (dst / below) % (self.up[l] * self.parallel[l]);
            let link = self.up_ports[at as usize][port as usize];
            out.push(link);
            at = self.links[link as usize].to;
        }
        while at != dst {
            let l = self.level_of(at);
            let mut port = (src % self.parallel[l - 1]) * self.down[l - 1];
            while (port as usize) < self.down_ports[at as usize].len() {
                let l = self.level_of(at);
                if port % self.down[l - 1] == dst_label[l - 1] {
                    let link = self.down_ports[at as usize][port as usize];
                    out.push(link);
                    at = self.links[link as usize].to;
                }
                port += 1;
            }
        }
        true
    }
    /// Half the up links of the narrowest level, one way: a balanced cut that keeps every
    /// subtree of the level below whole (the halves exchange traffic only through the levels
    /// above it). A switch network's cut counts links, not hosts.
    fn bisection_width(&self) -> u32 {
        (0..self.levels())
            .map(|l| {
                let nodes = self.level_start[l + 1] - self.level_start[l];
                nodes * self.up[l] * self.parallel[l] / 2
            })
            .min()
            .unwrap_or(0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::net::topology::testing::path as route;

    #[test]
    fn two_level_tree_by_hand() {
        // 4 leaf switches of 4 hosts each, 2 spines: hosts 0..16, leaves 16..20, spines 20..22.
        let t = FatTree::new(&[4, 4, 1, 2, 1, 1]);
        assert_eq!(t.nodes(), 16);
        assert_eq!(t.level_start, [0, 16, 20, 22]);
        // 16 host cables + 4 x 2 leaf-spine cables, each a pair.
        assert_eq!(t.links.len(), 2 * (16 + 8));
        // Same leaf: up and down.
        assert_eq!(route(&t, 0, 3), [(0, 16), (16, 3)]);
        // Host 5 to host 9: leaf 17, spine chosen by 9 mod 2 = 1 (vertex 21), leaf 18.
        assert_eq!(route(&t, 5, 9), [(5, 17), (17, 21), (21, 18), (18, 9)]);
        // Host 8 to host 5: 5 mod 2 = 1, spine 21.
        assert_eq!(route(&t, 8, 5), [(8, 18), (18, 21), (21, 17), (17, 5)]);
        assert_eq!(route(&t, 7, 7), []);
        assert_eq!(t.bisection_width(), 4);
    }

    #[test]
    fn every_route_is_a_path_from_source_to_destination() {
        for dims in [
            vec![4, 4, 1, 2, 1, 1],
            vec![2, 3, 1, 2, 2, 1],
            vec![4, 4, 4, 1, 4, 4, 1, 1, 1],
            vec![3, 2, 2, 1, 2, 3, 1, 2, 2],
        ] {
            let t = FatTree::new(&dims);
            for s in 0..t.nodes() {
                for d in 0..t.nodes() {
                    let hops = route(&t, s, d);
                    // Up then down, never more than twice the tree's height.
                    assert!(hops.len() <= 2 * t.levels(), "{dims:?} {s}->{d}");
                }
            }
        }
    }
}
