//! A dragonfly in the Cray Cascade layout SimGrid's dragonfly cluster zone builds: `groups`
//! groups of `chassis` chassis of `routers` routers, each router serving `nodes` hosts. Dims
//! `[groups, chassis, routers, nodes]`; host id = ((group * chassis + chassis_index) *
//! routers + router) * nodes + slot.
//!
//! Links, each a pair (one per direction) at the network's one link rate: every host to its
//! router; "green" between every two routers of a chassis; "black" between the routers at the
//! same place in every two chassis of a group; one "blue" (global) link between every two
//! groups, joining router `j` of group `i` to router `i` of group `j` (routers counted
//! across the group's chassis), as SimGrid places them. Vertex ids: hosts `0..N`, then the
//! routers in the same order as their hosts.
//!
//! Minimal routing, deterministic: to another group, a green hop to the router that holds
//! the blue link to it (within the source chassis, then a black hop to chassis 0 where that
//! router sits), the blue hop, then inside the destination group a green hop to the
//! destination's router position and a black hop to its chassis. SimGrid takes the same
//! links except inside a group when the source is not in chassis 0: there it charges the
//! black link from chassis 0 (a route that is not a path), sortsim the one from the chassis
//! the message is in; `sortsim validate network` compares routes where the two rules agree.
//! Blue links sit on chassis 0, so `groups` may not exceed `routers` (the same bound as
//! SimGrid's).
//!
//! Valiant routing (dims `[groups, chassis, routers, nodes, 1]`), an option SimGrid's zone
//! does not have: a message between groups first goes minimally to an intermediate group
//! other than its two ends, then minimally on, spreading traffic over the global links. The
//! intermediate group is a fixed function of the pair (a SplitMix64 hash of source and
//! destination), so every run routes the same way; with fewer than three groups, or inside
//! a group, the route is minimal.
//!
//! Must never route a pair over a path that is not connected.

use super::{Link, Topology};
use crate::net::{LinkId, NodeId, TopologyKind};

pub struct Dragonfly {
    groups: u32,
    chassis: u32,
    routers: u32,
    per_router: u32,
    valiant: bool,
    links: Vec<Link>,
    /// Per router (index from 0): the up link of each host slot, then down.
    host_up: Vec<LinkId>,
    /// `green[router][other position in chassis]`, `black[router][other chassis]`,
    /// `blue[router]`: the link leaving `router`, or `NONE`.
    green: Vec<Vec<LinkId>>,
    black: Vec<Vec<LinkId>>,
    blue: Vec<LinkId>,
}

const NONE: LinkId = LinkId::MAX;

#[derive(Clone, Copy, PartialEq, Eq)]
struct Place {
    group: u32,
    chassis: u32,
    router: u32,
}

impl Dragonfly {
    /// `dims = [groups, chassis, routers, nodes]`, each at least 1 and `groups <= routers`,
    /// and a fifth entry 1 for Valiant routing (checked by the caller).
    pub fn new(dims: &[u32]) -> Dragonfly {
        let [groups, chassis, routers, per_router] = [dims[0], dims[1], dims[2], dims[3]];
        let valiant = dims.get(4) == Some(&1);
        let count = (groups * chassis * routers) as usize;
        let mut d = Dragonfly {
            groups,
            chassis,
            routers,
            per_router,
            valiant,
            links: Vec::new(),
            host_up: Vec::with_capacity(count * per_router as usize),
            green: vec![vec![NONE; routers as usize]; count],
            black: vec![vec![NONE; chassis as usize]; count],
            blue: vec![NONE; count],
        };
        d.wire();
        d
    }

    fn hosts(&self) -> u32 {
        self.groups * self.chassis * self.routers * self.per_router
    }

    fn index(&self, p: Place) -> u32 {
        (p.group * self.chassis + p.chassis) * self.routers + p.router
    }

    fn vertex(&self, p: Place) -> NodeId {
        self.hosts() + self.index(p)
    }

    fn place_of_host(&self, host: NodeId) -> Place {
        let r = host / self.per_router;
        Place {
            group: r / (self.chassis * self.routers),
            chassis: r / self.routers % self.chassis,
            router: r % self.routers,
        }
    }

    /// Adds the pair `a -> b`, `b -> a`; returns the first.
    fn pair(&mut self, a: NodeId, b: NodeId) -> LinkId {
        let id = self.links.len() as LinkId;
        self.links.push(Link::wire(a, b));
        self.links.push(Link::wire(b, a));
        id
    }

    fn wire(&mut self) {
        for host in 0..self.hosts() {
            let router = self.vertex(self.place_of_host(host));
            let up = self.pair(host, router);
            self.host_up.push(up);
        }
        for group in 0..self.groups {
            for chassis in 0..self.chassis {
                for a in 0..self.routers {
                    for b in a + 1..self.routers {
                        let pa = Place {
                            group,
                            chassis,
                            router: a,
                        };
                        let pb = Place {
                            group,
                            chassis,
                            router: b,
                        };
                        self.join_green(pa, pb);
                    }
                }
            }
        }
        for group in 0..self.groups {
            for a in 0..self.chassis {
                for b in a + 1..self.chassis {
                    for router in 0..self.routers {
                        let pa = Place {
                            group,
                            chassis: a,
                            router,
                        };
                        let pb = Place {
                            group,
                            chassis: b,
                            router,
                        };
                        let id = self.pair(self.vertex(pa), self.vertex(pb));
                        let (ia, ib) = (self.index(pa) as usize, self.index(pb) as usize);
                        self.black[ia][b as usize] = id;
                        self.black[ib][a as usize] = id + 1;
                    }
                }
            }
        }
        for i in 0..self.groups {
            for j in i + 1..self.groups {
                let pi = self.blue_router(i, j);
                let pj = self.blue_router(j, i);
                let id = self.pair(self.vertex(pi), self.vertex(pj));
                let (ii, ij) = (self.index(pi) as usize, self.index(pj) as usize);
                self.blue[ii] = id;
                self.blue[ij] = id + 1;
            }
        }
    }

    fn join_green(&mut self, a: Place, b: Place) {
        let id = self.pair(self.vertex(a), self.vertex(b));
        let (ia, ib) = (self.index(a) as usize, self.index(b) as usize);
        self.green[ia][b.router as usize] = id;
        self.green[ib][a.router as usize] = id + 1;
    }

    /// The router of `group` that holds its blue link to group `to`: router `to` of chassis 0.
    fn blue_router(&self, group: u32, to: u32) -> Place {
        Place {
            group,
            chassis: 0,
            router: to,
        }
    }

    /// Moves `at` across the blue link to `group`, from the router of its group that holds it.
    fn to_group(&self, at: &mut Place, group: u32, out: &mut Vec<LinkId>) {
        let exit = self.blue_router(at.group, group);
        self.within_group(at, exit.router, exit.chassis, out);
        out.push(self.blue[self.index(*at) as usize]);
        *at = self.blue_router(group, at.group);
    }

    /// Valiant's intermediate group for `src -> dst`: a group other than `from` and `to`,
    /// picked by a SplitMix64 hash of the pair.
    fn intermediate(&self, src: NodeId, dst: NodeId, from: u32, to: u32) -> u32 {
        let mut z = ((src as u64) << 32 | dst as u64).wrapping_add(0x9e37_79b9_7f4a_7c15);
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        let (lo, hi) = (from.min(to), from.max(to));
        let mut g = (z % (self.groups as u64 - 2)) as u32;
        // Skip the two ends, in order.
        if g >= lo {
            g += 1;
        }
        if g >= hi {
            g += 1;
        }
        g
    }

    /// Moves `at` to `router` within its chassis, then to `chassis` within its group.
    fn within_group(&self, at: &mut Place, router: u32, chassis: u32, out: &mut Vec<LinkId>) {
        if at.router != router {
            out.push(self.green[self.index(*at) as usize][router as usize]);
            at.router = router;
        }
        if at.chassis != chassis {
            out.push(self.black[self.index(*at) as usize][chassis as usize]);
            at.chassis = chassis;
        }
    }
}

impl Topology for Dragonfly {
    fn kind(&self) -> TopologyKind {
        TopologyKind::Dragonfly
    }
    fn nodes(&self) -> u32 {
        self.hosts()
    }
    fn links(&self) -> &[Link] {
        &self.links
    }
    fn route_into(&self, src: NodeId, dst: NodeId, out: &mut Vec<LinkId>) -> bool {
        if src == dst {
            return true;
        }
        let target = self.place_of_host(dst);
        let mut at = self.place_of_host(src);
        out.push(self.host_up[src as usize]);
        if at.group != target.group {
            if self.valiant && self.groups >= 3 {
                let via = self.intermediate(src, dst, at.group, target.group);
                self.to_group(&mut at, via, out);
            }
            self.to_group(&mut at, target.group, out);
        }
        self.within_group(&mut at, target.router, target.chassis, out);
        out.push(self.host_up[dst as usize] + 1);
        true
    }
    /// The cut between two halves of the groups, one way: `floor(G/2) * ceil(G/2)` blue
    /// links; with one group, between halves of its chassis (black links, one per router
    /// position), then of a chassis's routers (green links), then of a router's hosts.
    fn bisection_width(&self) -> u32 {
        let halves = |n: u32| (n / 2) * n.div_ceil(2);
        if self.groups >= 2 {
            halves(self.groups)
        } else if self.chassis >= 2 {
            halves(self.chassis) * self.routers
        } else if self.routers >= 2 {
            halves(self.routers)
        } else {
            self.per_router / 2
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::net::topology::testing::path as route;

    #[test]
    fn small_dragonfly_by_hand() {
        // 3 groups, 1 chassis, 3 routers, 2 hosts each: hosts 0..18, routers 18..27.
        let t = Dragonfly::new(&[3, 1, 3, 2]);
        assert_eq!(t.nodes(), 18);
        // 18 host cables, 3 x 3 green, 3 blue.
        assert_eq!(t.links.len(), 2 * (18 + 9 + 3));
        // Host 0 (group 0, router 0) to host 17 (group 2, router 2): green to router 2 of
        // group 0 (vertex 20), blue to router 0 of group 2 (vertex 24), green to router 2
        // (vertex 26).
        assert_eq!(
            route(&t, 0, 17),
            [(0, 18), (18, 20), (20, 24), (24, 26), (26, 17)]
        );
        // Same router.
        assert_eq!(route(&t, 0, 1), [(0, 18), (18, 1)]);
        assert_eq!(t.bisection_width(), 2);
    }

    #[test]
    fn valiant_routes_cross_two_global_links_through_a_third_group() {
        let minimal = Dragonfly::new(&[5, 2, 5, 2]);
        let t = Dragonfly::new(&[5, 2, 5, 2, 1]);
        let blue = |t: &Dragonfly, l: LinkId| t.blue.contains(&l);
        let mut vias = std::collections::BTreeSet::new();
        for s in 0..t.nodes() {
            for d in 0..t.nodes() {
                let hops = route(&t, s, d);
                if s == d {
                    continue;
                }
                let mut out = Vec::new();
                t.route_into(s, d, &mut out);
                let (gs, gd) = (t.place_of_host(s).group, t.place_of_host(d).group);
                let blues = out.iter().filter(|&&l| blue(&t, l)).count();
                if gs == gd {
                    assert_eq!(hops, route(&minimal, s, d), "inside a group: minimal");
                } else {
                    assert_eq!(blues, 2, "{s}->{d}");
                    let via = t.intermediate(s, d, gs, gd);
                    assert!(via != gs && via != gd && via < 5);
                    vias.insert(via);
                }
            }
        }
        assert_eq!(vias.len(), 5, "every group serves as an intermediate");
    }

    #[test]
    fn every_route_is_a_minimal_path() {
        for dims in [
            [3, 1, 3, 2],
            [4, 2, 4, 1],
            [2, 3, 2, 2],
            [1, 3, 2, 1],
            [1, 1, 1, 3],
        ] {
            let t = Dragonfly::new(&dims);
            for s in 0..t.nodes() {
                for d in 0..t.nodes() {
                    let hops = route(&t, s, d);
                    // Host, at most green + black, blue, green + black, host.
                    assert!(hops.len() <= 7, "{dims:?} {s}->{d}");
                }
            }
        }
    }
}
