//! Topologies: which links exist and which ones a message crosses.
//!
//! Owns the [`Topology`] trait (one implementation per file, BookSim's `networks/` folder)
//! and the exhaustive selection from [`TopologyKind`]. Routing is deterministic and fixed per
//! pair (no adaptive routing): ties always go the "increasing id" way.
//!
//! Vertices: nodes (hosts) are `0..nodes`; a switched network (fat-tree, dragonfly) numbers
//! its switches from `nodes` on, so a link's ends may be switches.
//!
//! Bisection width convention, shared by every topology: the number of links that cross
//! the best balanced cut, counted in ONE direction (a bidirectional pair counts once, a
//! one-way link counts once). A ring has 2, a k-ary n-cube `2 * N / k` for the cut across its
//! longest dimension, a hypercube `N / 2`.
//!
//! Must never know about time, bandwidth or transport models.

mod bus;
mod crossbar;
mod dragonfly;
mod fat_tree;
mod grid;
mod hypercube;
mod mesh;
mod nodes;
mod pipeline;
mod ring;
mod torus;

pub use grid::LineTally;
pub use nodes::Placement;

use super::{LinkId, NetError, NodeId, TopologyKind};

/// What a route adds to each link it crosses, as counts the caller names (the network's:
/// bytes, messages, busy picoseconds).
pub type Amount = [u64; 3];

/// One directed link (or the shared medium of a bus, or a crossbar port).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Link {
    pub from: NodeId,
    pub to: NodeId,
    pub kind: LinkKind,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LinkKind {
    /// A point-to-point wire `from -> to`.
    Wire,
    /// The single shared medium of a bus (`from` = `to` = 0).
    Bus,
    /// A crossbar's output port of node `from` (= `to`).
    Out,
    /// A crossbar's input port of node `to` (= `from`).
    In,
}

impl Link {
    pub fn wire(from: NodeId, to: NodeId) -> Link {
        Link {
            from,
            to,
            kind: LinkKind::Wire,
        }
    }

    /// `3->4`, `3->s0` (to the first switch of a network of `nodes` hosts), `bus`, `out3`,
    /// `in3`.
    pub fn name(&self, nodes: u32) -> String {
        let vertex = |v: NodeId| {
            if v < nodes {
                v.to_string()
            } else {
                format!("s{}", v - nodes)
            }
        };
        match self.kind {
            LinkKind::Wire => format!("{}->{}", vertex(self.from), vertex(self.to)),
            LinkKind::Bus => "bus".to_string(),
            LinkKind::Out => format!("out{}", self.from),
            LinkKind::In => format!("in{}", self.to),
        }
    }
}

/// A network shape with its routing function (`Send + Sync` so that sweeps can build and
/// move networks across threads).
pub trait Topology: Send + Sync {
    fn kind(&self) -> TopologyKind;
    fn nodes(&self) -> u32;
    /// Every link, in link-index order.
    fn links(&self) -> &[Link];
    /// Appends the links from `src` to `dst` (both `< nodes`) to `out`; false when the pair
    /// has no route. A message to itself has an empty route.
    fn route_into(&self, src: NodeId, dst: NodeId, out: &mut Vec<LinkId>) -> bool;
    /// Whether `route_into` costs about a load a hop (no search, no allocation), so that a
    /// message's route is computed as it starts rather than read from a store of every pair
    /// that talked: on 512 nodes talking all to all that store is megabytes, and reading a
    /// route from it misses in cache where computing it does not.
    fn routes_in_place(&self) -> bool {
        false
    }
    /// Links that one hop acquires together (2 on a crossbar: the source's output port and
    /// the destination's input port are one switch traversal).
    fn links_per_hop(&self) -> u32 {
        1
    }
    fn bisection_width(&self) -> u32;
    /// Whether every ordered pair of nodes has a route (only a pipeline of two or more
    /// nodes lacks some: it runs one way).
    fn routes_every_pair(&self) -> bool {
        true
    }
    /// The link a broadcast uses, if the topology has one.
    fn broadcast_link(&self) -> Option<LinkId> {
        None
    }
    /// Whether `link` lies inside a node of several processors (and runs at the node's rate).
    fn is_node_link(&self, _link: LinkId) -> bool {
        false
    }
    /// An empty [`LineTally`] when routes run along lines of nodes (the mesh and the torus),
    /// so that [`Topology::tally_route`] can stand for `route_into` where only what routes
    /// carry per link is kept, not the routes.
    fn line_tally(&self) -> Option<LineTally> {
        None
    }
    /// Adds `amount` to every link of the route from `src` to `dst` (both `< nodes`) in
    /// `tally` (made by [`Topology::line_tally`]) and returns how many links the route has.
    fn tally_route(&self, _src: NodeId, _dst: NodeId, _tally: &mut LineTally, _: Amount) -> u32 {
        unreachable!("only a topology with a line tally tallies routes by lines")
    }
    /// Every link's total in `tally`, in link index order.
    fn tallied(&self, _tally: &LineTally) -> Vec<Amount> {
        unreachable!("only a topology with a line tally tallies routes by lines")
    }
}

/// `network` with each of its hosts taken as a NIC of a node of `processors` processors and
/// `nics` NICs (see `nodes.rs`).
pub fn in_nodes(
    network: Box<dyn Topology>,
    processors: u32,
    nics: u32,
    placement: Placement,
) -> Result<Box<dyn Topology>, NetError> {
    Ok(Box::new(nodes::Nodes::new(
        network, processors, nics, placement,
    )?))
}

/// Builds the topology `kind` with extents `dims`, or says what `dims` would be valid.
pub fn build(kind: TopologyKind, dims: &[u32]) -> Result<Box<dyn Topology>, NetError> {
    let nodes = validate_dims(kind, dims)?;
    Ok(match kind {
        TopologyKind::Ring => Box::new(ring::Ring::new(nodes)),
        TopologyKind::Pipeline => Box::new(pipeline::Pipeline::new(nodes)),
        TopologyKind::Torus => Box::new(torus::Torus::new(dims)),
        TopologyKind::Mesh => Box::new(mesh::Mesh::new(dims)),
        TopologyKind::Hypercube => Box::new(hypercube::Hypercube::new(nodes)),
        TopologyKind::Bus => Box::new(bus::Bus::new(nodes)),
        TopologyKind::Crossbar => Box::new(crossbar::Crossbar::new(nodes)),
        TopologyKind::FatTree => Box::new(fat_tree::FatTree::new(dims)),
        TopologyKind::Dragonfly => Box::new(dragonfly::Dragonfly::new(dims)),
    })
}

/// Checks the shape rules and returns the node count.
fn validate_dims(kind: TopologyKind, dims: &[u32]) -> Result<u32, NetError> {
    let name = kind.name();
    let err = |what: String| Err(NetError::Config(format!("{name} dims {dims:?}: {what}")));
    if dims.is_empty() {
        return err("dims must not be empty".to_string());
    }
    if dims.contains(&0) {
        return err("every dimension must be at least 1".to_string());
    }
    let extents = match kind {
        TopologyKind::FatTree if dims.len() % 3 != 0 => {
            return err(
                "a fat-tree takes down ++ up ++ parallel, one entry each per level, e.g. \
                 [4, 4, 1, 2, 1, 1] for two levels"
                    .to_string(),
            )
        }
        // The hosts are the product of the children per switch.
        TopologyKind::FatTree => &dims[..dims.len() / 3],
        // A fifth entry is the routing rule, not an extent.
        TopologyKind::Dragonfly => &dims[..dims.len().min(4)],
        _ => dims,
    };
    let Some(nodes) = extents.iter().try_fold(1u32, |acc, &d| acc.checked_mul(d)) else {
        return err(format!(
            "the node count (product of dims) must fit in {} nodes",
            u32::MAX
        ));
    };
    match kind {
        TopologyKind::Ring
        | TopologyKind::Pipeline
        | TopologyKind::Bus
        | TopologyKind::Crossbar
            if dims.len() != 1 =>
        {
            err(
                "a ring, pipeline, bus or crossbar takes exactly one dim, the node count, e.g. [8]"
                    .to_string(),
            )
        }
        TopologyKind::Hypercube if dims.len() != 1 || !nodes.is_power_of_two() => err(
            "a hypercube takes exactly one dim, the node count, which must be a power of two \
             (1, 2, 4, 8, ...)"
                .to_string(),
        ),
        TopologyKind::Mesh if !(2..=3).contains(&dims.len()) => {
            err("a mesh is 2D or 3D: dims [x, y] or [x, y, z], e.g. [16, 32]".to_string())
        }
        TopologyKind::FatTree => {
            let vertices = fat_tree_vertices(dims);
            if vertices > u32::MAX as u64 {
                return err(format!(
                    "the tree's hosts and switches ({vertices}) must fit in {} vertices",
                    u32::MAX
                ));
            }
            if let Err(why) = within_link_limit(fat_tree_links(dims)) {
                return err(why);
            }
            Ok(nodes)
        }
        TopologyKind::Dragonfly if !(4..=5).contains(&dims.len()) => err(
            "a dragonfly takes [groups, chassis, routers, nodes per router], e.g. [4, 2, 4, 2], \
             and a fifth entry 1 for Valiant routing"
                .to_string(),
        ),
        TopologyKind::Dragonfly if dims.len() == 5 && dims[4] != 1 => err(format!(
            "a dragonfly's fifth entry, when present, is 1 (Valiant routing); got {}",
            dims[4]
        )),
        TopologyKind::Dragonfly if dims[0] > dims[2] => err(format!(
            "{} groups need at least as many routers per chassis ({}): the global link to \
             group g sits on router g of chassis 0",
            dims[0], dims[2]
        )),
        TopologyKind::Dragonfly => {
            let routers = (nodes / dims[3]) as u64;
            if nodes as u64 + routers > u32::MAX as u64 {
                return err(format!(
                    "hosts and routers must fit in {} vertices",
                    u32::MAX
                ));
            }
            if let Err(why) = within_link_limit(dragonfly_links(dims)) {
                return err(why);
            }
            Ok(nodes)
        }
        _ => Ok(nodes),
    }
}

/// Hosts plus switches of a fat-tree with `dims = down ++ up ++ parallel` (saturating: a
/// count past `u64::MAX` is refused all the same).
fn fat_tree_vertices(dims: &[u32]) -> u64 {
    let h = dims.len() / 3;
    (0..=h)
        .map(|l| fat_tree_level(dims, l))
        .fold(0, u64::saturating_add)
}

/// The vertices of level `l` of a fat-tree (0: the hosts).
fn fat_tree_level(dims: &[u32], l: usize) -> u64 {
    let h = dims.len() / 3;
    (0..h)
        .map(|i| if i < l { dims[h + i] } else { dims[i] } as u64)
        .fold(1, u64::saturating_mul)
}

/// The links `FatTree::new` wires: both directions of `parallel[l]` cables from each vertex of
/// level `l` to each of its `up[l]` parents.
fn fat_tree_links(dims: &[u32]) -> u64 {
    let h = dims.len() / 3;
    (0..h)
        .map(|l| {
            [dims[h + l] as u64, dims[2 * h + l] as u64, 2]
                .into_iter()
                .fold(fat_tree_level(dims, l), u64::saturating_mul)
        })
        .fold(0, u64::saturating_add)
}

/// The links `Dragonfly::new` wires, both directions of each: a host's to its router, every
/// two routers of a chassis, the routers of one position in every two chassis of a group,
/// and every two groups.
fn dragonfly_links(dims: &[u32]) -> u64 {
    let [groups, chassis, routers, per_router] = [0, 1, 2, 3].map(|i| dims[i] as u64);
    let pairs = |n: u64| n.saturating_mul(n.saturating_sub(1));
    let hosts = groups * chassis * routers * per_router;
    [
        hosts.saturating_mul(2),
        (groups * chassis).saturating_mul(pairs(routers)),
        (groups * routers).saturating_mul(pairs(chassis)),
        pairs(groups),
    ]
    .into_iter()
    .fold(0, u64::saturating_add)
}

/// Refuses a shape of more than [`limits::MAX_LINKS`](crate::limits::MAX_LINKS) links.
fn within_link_limit(links: u64) -> Result<(), String> {
    let limit = crate::limits::MAX_LINKS;
    match links <= limit {
        true => Ok(()),
        false => Err(format!(
            "{links} links; the limit is {limit} (sortsim::limits::MAX_LINKS): every link is \
             host memory, allocated before the first message"
        )),
    }
}

/// What the topology tests share: a route as the vertex pairs it crosses.
#[cfg(test)]
pub(super) mod testing {
    use super::Topology;

    /// The route `s -> d` as (from, to) vertex pairs, asserting that it is a connected path
    /// from `s` to `d` (empty when `s == d`).
    pub fn path(t: &dyn Topology, s: u32, d: u32) -> Vec<(u32, u32)> {
        let mut route = Vec::new();
        assert!(t.route_into(s, d, &mut route), "{s}->{d} has a route");
        let hops: Vec<(u32, u32)> = route
            .iter()
            .map(|&l| (t.links()[l as usize].from, t.links()[l as usize].to))
            .collect();
        match (hops.first(), hops.last()) {
            (Some(first), Some(last)) => {
                assert_eq!((first.0, last.1), (s, d), "{s}->{d} ends");
                assert!(hops.windows(2).all(|w| w[0].1 == w[1].0), "{s}->{d} joined");
            }
            _ => assert_eq!(s, d, "only a message to itself has an empty route"),
        }
        hops
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rejects(kind: TopologyKind, dims: &[u32], needle: &str) {
        let e = build(kind, dims)
            .err()
            .expect("must be rejected")
            .to_string();
        assert!(e.contains(needle), "{kind:?} {dims:?}: {e}");
    }

    #[test]
    fn invalid_shapes_say_what_is_valid() {
        rejects(TopologyKind::Ring, &[], "must not be empty");
        rejects(TopologyKind::Torus, &[4, 0], "at least 1");
        rejects(TopologyKind::Ring, &[4, 4], "exactly one dim");
        rejects(TopologyKind::Hypercube, &[12], "power of two");
        rejects(TopologyKind::Mesh, &[16], "2D or 3D");
        rejects(TopologyKind::Mesh, &[2, 2, 2, 2], "2D or 3D");
        rejects(TopologyKind::Torus, &[65536, 65536], "must fit");
        rejects(
            TopologyKind::FatTree,
            &[4, 4, 1, 2],
            "down ++ up ++ parallel",
        );
        rejects(
            TopologyKind::Dragonfly,
            &[4, 2, 4],
            "[groups, chassis, routers",
        );
        rejects(
            TopologyKind::Dragonfly,
            &[5, 2, 4, 2],
            "at least as many routers",
        );
        rejects(
            TopologyKind::FatTree,
            &[16, 16, 1, 16, 1, 300_000],
            "the limit is",
        );
        rejects(
            TopologyKind::FatTree,
            &[16, 16, 65536, 65536, 1, 1],
            "must fit",
        );
        rejects(
            TopologyKind::FatTree,
            &[2, 2, 2, u32::MAX, u32::MAX, u32::MAX, 1, 1, 1],
            "must fit",
        );
        rejects(TopologyKind::Dragonfly, &[1, 1, 65536, 1], "the limit is");
        assert!(build(TopologyKind::FatTree, &[4, 4, 1, 2, 1, 1]).is_ok());
        assert!(build(TopologyKind::Dragonfly, &[4, 2, 4, 2]).is_ok());
        assert!(build(TopologyKind::Torus, &[3, 3, 3, 3]).is_ok());
        assert!(build(TopologyKind::Hypercube, &[1]).is_ok());
    }

    /// The link counts the limit is checked against are the counts the topologies wire.
    #[test]
    fn the_links_counted_beforehand_are_the_links_wired() {
        let trees: [&[u32]; 4] = [
            &[4, 4, 1, 2, 1, 1],
            &[2, 3, 4, 3, 2, 1, 1, 2, 3],
            &[5, 1, 1],
            &[16, 16, 1, 16, 1, 3],
        ];
        for dims in trees {
            let wired = build(TopologyKind::FatTree, dims).unwrap().links().len();
            assert_eq!(fat_tree_links(dims), wired as u64, "fat-tree {dims:?}");
        }
        let dragonflies: [&[u32]; 5] = [
            &[4, 2, 4, 2],
            &[1, 1, 1, 1],
            &[3, 3, 5, 1],
            &[2, 4, 3, 2, 1],
            &[1, 1, 7, 3],
        ];
        for dims in dragonflies {
            let wired = build(TopologyKind::Dragonfly, dims).unwrap().links().len();
            assert_eq!(dragonfly_links(dims), wired as u64, "dragonfly {dims:?}");
        }
    }

    /// A tally by lines gives every link the sum a walk of each route adds link by link, for
    /// every pair of meshes and tori with ends, wrap-arounds, extents of one and two, and
    /// amounts whose differences wrap round 64 bits; and it counts each route's links.
    #[test]
    fn a_tally_by_lines_equals_one_by_links_for_every_pair() {
        let shapes: [&[u32]; 8] = [
            &[5],
            &[2, 2],
            &[1, 4],
            &[4, 4],
            &[3, 5],
            &[6, 1, 3],
            &[2, 3, 4],
            &[16, 32],
        ];
        for kind in [TopologyKind::Mesh, TopologyKind::Torus] {
            for dims in shapes {
                let Ok(t) = build(kind, dims) else {
                    assert!(kind == TopologyKind::Mesh && dims.len() == 1, "{dims:?}");
                    continue;
                };
                let mut lines = t.line_tally().expect("a grid tallies by lines");
                let mut by_links = vec![[0u64; 3]; t.links().len()];
                let mut route = Vec::new();
                for s in 0..t.nodes() {
                    for d in 0..t.nodes() {
                        let amount = [
                            (1 << 40) + u64::from(s * 7 + d),
                            1,
                            u64::from(s + 1) * u64::from(d + 3),
                        ];
                        route.clear();
                        assert!(t.route_into(s, d, &mut route));
                        for &l in &route {
                            for (total, a) in by_links[l as usize].iter_mut().zip(amount) {
                                *total += a;
                            }
                        }
                        let links = t.tally_route(s, d, &mut lines, amount);
                        assert_eq!(links as usize, route.len(), "{kind:?} {dims:?} {s}->{d}");
                    }
                }
                assert_eq!(t.tallied(&lines), by_links, "{kind:?} {dims:?}");
            }
        }
    }
}
