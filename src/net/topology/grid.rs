//! Shared machinery of the k-ary n-cube (torus) and the mesh: coordinates and the table
//! from (node, dimension, direction) to link index.
//!
//! Node id = x + dims[0] * (y + dims[1] * z). Links are numbered by node, then dimension,
//! then `+` before `-`, skipping links that do not exist. A route is a leg along each
//! dimension, and a leg one or two runs of links along a line of nodes; so what routes carry
//! can be tallied by lines ([`LineTally`]) and summed per link only when asked. Must never
//! decide a route: the torus and the mesh each own their routing rule (a [`Leg`]).

use super::{Amount, Link};
use crate::net::{LinkId, NodeId};

const NO_LINK: LinkId = LinkId::MAX;

/// A routing rule along one dimension: from coordinate `c` to `target` on a line of `k` nodes,
/// how many steps and whether in the `+` direction.
pub trait Leg: Fn(u32, u32, u32) -> (u32, bool) {}
impl<F: Fn(u32, u32, u32) -> (u32, bool)> Leg for F {}

pub struct Grid {
    pub dims: Vec<u32>,
    strides: Vec<u32>,
    /// `ports[(node * ndims + d) * 2 + dir]`, dir 0 = `+`, 1 = `-`.
    ports: Vec<LinkId>,
    pub links: Vec<Link>,
}

impl Grid {
    /// `neighbour(node, d, plus)` gives the far end of a link, or `None` where there is none.
    pub fn new(
        dims: &[u32],
        neighbour: impl Fn(&Grid, NodeId, usize, bool) -> Option<NodeId>,
    ) -> Grid {
        let mut strides = Vec::with_capacity(dims.len());
        let mut stride = 1;
        for &k in dims {
            strides.push(stride);
            stride *= k;
        }
        let nodes = stride;
        let mut grid = Grid {
            dims: dims.to_vec(),
            strides,
            ports: vec![NO_LINK; nodes as usize * dims.len() * 2],
            links: Vec::new(),
        };
        for node in 0..nodes {
            for d in 0..dims.len() {
                for (dir, plus) in [(0, true), (1, false)] {
                    if let Some(to) = neighbour(&grid, node, d, plus) {
                        let id = grid.links.len() as LinkId;
                        let port = grid.port(node, d, dir);
                        grid.ports[port] = id;
                        grid.links.push(Link::wire(node, to));
                    }
                }
            }
        }
        grid
    }

    pub fn nodes(&self) -> u32 {
        self.dims.iter().product()
    }

    pub fn coord(&self, node: NodeId, d: usize) -> u32 {
        (node / self.strides[d]) % self.dims[d]
    }

    /// `node` with its coordinate in dimension `d` replaced by `c`.
    pub fn with_coord(&self, node: NodeId, d: usize, c: u32) -> NodeId {
        node - self.coord(node, d) * self.strides[d] + c * self.strides[d]
    }

    fn port(&self, node: NodeId, d: usize, dir: usize) -> usize {
        (node as usize * self.dims.len() + d) * 2 + dir
    }

    /// Appends the links from `src` to `dst` (a route leg by leg, lowest dimension first,
    /// each leg as the routing rule `leg` gives it: see [`Grid::legs`]).
    #[inline]
    pub fn route_into(&self, src: NodeId, dst: NodeId, leg: impl Leg, out: &mut Vec<LinkId>) {
        self.legs(src, dst, leg, |at, dc, steps, plus| {
            self.walk(at, dc, steps, plus, out)
        });
    }

    /// Adds `amount` to every link from `src` to `dst` under the routing rule `leg` in
    /// `tally`, and returns how many links the route has.
    #[inline]
    pub fn tally_route(
        &self,
        src: NodeId,
        dst: NodeId,
        leg: impl Leg,
        tally: &mut LineTally,
        amount: Amount,
    ) -> u32 {
        let mut links = 0;
        self.legs(src, dst, leg, |at, dc, steps, plus| {
            links += steps;
            self.tally(at, dc, steps, plus, tally, amount)
        });
        links
    }

    /// The legs of a route, lowest dimension first: `each(node, (d, coordinate), steps,
    /// plus)` takes each from where the last ended and returns where it ends.
    #[inline]
    fn legs(
        &self,
        src: NodeId,
        dst: NodeId,
        leg: impl Leg,
        mut each: impl FnMut(NodeId, (usize, u32), u32, bool) -> NodeId,
    ) {
        let mut at = src;
        for d in 0..self.dims.len() {
            let (c, target) = (self.coord(at, d), self.coord(dst, d));
            let (steps, plus) = leg(c, target, self.dims[d]);
            at = each(at, (d, c), steps, plus);
        }
    }

    /// Appends the links of `steps` hops from `node` along dimension `d` in direction `plus`
    /// (wrapping at the ends, which only a torus's routes reach) and returns where they end;
    /// `steps` is at most the dimension's extent. The ports of the nodes along a dimension
    /// lie a fixed distance apart in the table, so a hop is one load: a walk is two runs of
    /// them, up to the edge and on from the other end. `c` is `node`'s coordinate in `d`,
    /// which the caller has at hand (finding it takes a division).
    #[inline]
    fn walk(
        &self,
        node: NodeId,
        (d, c): (usize, u32),
        steps: u32,
        plus: bool,
        out: &mut Vec<LinkId>,
    ) -> NodeId {
        let (k, stride) = (self.dims[d], self.strides[d]);
        debug_assert!(steps <= k, "a walk round a dimension more than once");
        debug_assert_eq!(
            c,
            self.coord(node, d),
            "a walk from a coordinate not its node's"
        );
        let row = node - c * stride;
        let dir = usize::from(!plus);
        let (runs, end) = leg_runs(k, c, steps, plus);
        let apart = stride as usize * self.dims.len() * 2;
        let port_at = |x: u32| self.port(row + x * stride, d, dir);
        for (from, hops) in runs {
            let first = port_at(from);
            // A range's map has a known length: one reservation, no capacity check per hop.
            out.extend((0..hops as usize).map(|i| {
                let port = if plus {
                    first + i * apart
                } else {
                    first - i * apart
                };
                let id = self.ports[port];
                debug_assert_ne!(id, NO_LINK, "routing used a missing link");
                id
            }));
        }
        row + end * stride
    }

    /// What [`Grid::walk`] would append, added to `tally` instead: `amount` on each link of
    /// the leg, by a difference at each end of its runs. Returns where the leg ends. Always
    /// inlined into the route's tally: called apart, each leg's call cost as much as its
    /// additions.
    #[inline(always)]
    fn tally(
        &self,
        node: NodeId,
        (d, c): (usize, u32),
        steps: u32,
        plus: bool,
        tally: &mut LineTally,
        amount: Amount,
    ) -> NodeId {
        let (k, stride) = (self.dims[d], self.strides[d]);
        debug_assert!(steps <= k, "a walk round a dimension more than once");
        let row = node - c * stride;
        let dir = usize::from(!plus);
        let (runs, end) = leg_runs(k, c, steps, plus);
        for (from, hops) in runs.into_iter().filter(|&(_, hops)| hops > 0) {
            // The run's links lie at coordinates [lo, hi) of the line, in either direction.
            let (lo, hi) = match plus {
                true => (from, from + hops),
                false => (from + 1 - hops, from + 1),
            };
            tally.add(self.port(row + lo * stride, d, dir), amount);
            if hi < k {
                tally.take(self.port(row + hi * stride, d, dir), amount);
            }
        }
        row + end * stride
    }

    /// An empty tally of this grid's lines.
    pub fn line_tally(&self) -> LineTally {
        LineTally {
            differences: vec![[0; 3]; self.ports.len()],
        }
    }

    /// Every link's total in `tally`, in link index order: the prefix sums of the differences
    /// along each line, in each direction.
    pub fn tallied(&self, tally: &LineTally) -> Vec<Amount> {
        let mut totals = vec![[0; 3]; self.links.len()];
        for (d, (&k, &stride)) in self.dims.iter().zip(&self.strides).enumerate() {
            let line_starts = (0..self.nodes()).filter(|&node| self.coord(node, d) == 0);
            for start in line_starts {
                for dir in 0..2 {
                    let mut sum: Amount = [0; 3];
                    for x in 0..k {
                        let port = self.port(start + x * stride, d, dir);
                        sum = plus(sum, tally.differences[port]);
                        if self.ports[port] != NO_LINK {
                            totals[self.ports[port] as usize] = sum;
                        }
                    }
                }
            }
        }
        totals
    }

    /// The link leaving `node` along dimension `d` in direction `plus`.
    #[cfg(test)]
    fn link(&self, node: NodeId, d: usize, plus: bool) -> LinkId {
        let id = self.ports[self.port(node, d, usize::from(!plus))];
        debug_assert_ne!(id, NO_LINK, "routing used a missing link");
        id
    }
}

/// A leg of `steps` hops from coordinate `c` of a line of `k` nodes, as two runs `(from,
/// hops)` (the second from the far end of the line, after wrapping round it; empty unless the
/// leg wraps), and the coordinate where it ends.
fn leg_runs(k: u32, c: u32, steps: u32, plus: bool) -> ([(u32, u32); 2], u32) {
    let (first_run, wrapped_from, end) = match plus {
        true => (steps.min(k - c), 0, (c + steps) % k),
        false => (steps.min(c + 1), k - 1, (c + k - steps) % k),
    };
    ([(c, first_run), (wrapped_from, steps - first_run)], end)
}

/// Amounts that routes carried, kept per port as differences along the port's line: a run of
/// links adds at its first port and takes off past its last, so a route costs a few additions
/// a leg whatever its length, and [`Grid::tallied`] sums them per link. The arithmetic wraps:
/// each link's total is exact whenever it fits in 64 bits, as a tally by links would need.
pub struct LineTally {
    differences: Vec<Amount>,
}

impl LineTally {
    fn add(&mut self, port: usize, amount: Amount) {
        self.differences[port] = plus(self.differences[port], amount);
    }

    fn take(&mut self, port: usize, amount: Amount) {
        self.add(port, amount.map(u64::wrapping_neg));
    }
}

fn plus(a: Amount, b: Amount) -> Amount {
    std::array::from_fn(|i| a[i].wrapping_add(b[i]))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The walk hop by hop: each link looked up from the node it leaves, which is then
    /// stepped one coordinate on (the plain definition `walk` must agree with).
    fn walk_hop_by_hop(
        g: &Grid,
        node: NodeId,
        d: usize,
        steps: u32,
        plus: bool,
    ) -> (Vec<LinkId>, NodeId) {
        let (k, mut at, mut links) = (g.dims[d], node, Vec::new());
        for _ in 0..steps {
            links.push(g.link(at, d, plus));
            let c = g.coord(at, d);
            at = g.with_coord(at, d, if plus { (c + 1) % k } else { (c + k - 1) % k });
        }
        (links, at)
    }

    #[test]
    fn a_walk_takes_the_links_it_would_hop_by_hop() {
        let wrapping = |g: &Grid, node, d: usize, plus: bool| {
            let (k, c) = (g.dims[d], g.coord(node, d));
            (k > 1).then(|| g.with_coord(node, d, if plus { (c + 1) % k } else { (c + k - 1) % k }))
        };
        let edged = |g: &Grid, node, d: usize, plus: bool| {
            let (k, c) = (g.dims[d], g.coord(node, d));
            match plus {
                true => (c + 1 < k).then(|| g.with_coord(node, d, c + 1)),
                false => (c > 0).then(|| g.with_coord(node, d, c - 1)),
            }
        };
        for dims in [vec![5], vec![4, 4], vec![3, 5], vec![16, 32], vec![2, 3, 4]] {
            for (wraps, g) in [
                (true, Grid::new(&dims, wrapping)),
                (false, Grid::new(&dims, edged)),
            ] {
                for node in 0..g.nodes() {
                    for d in 0..dims.len() {
                        let (k, c) = (dims[d], g.coord(node, d));
                        for plus in [true, false] {
                            // Off a mesh's edge there is no link to walk.
                            let most = match (wraps, plus) {
                                (true, _) => k,
                                (false, true) => k - 1 - c,
                                (false, false) => c,
                            };
                            for steps in 0..=most {
                                let mut links = vec![7];
                                let end = g.walk(node, (d, c), steps, plus, &mut links);
                                let (expected, expected_end) =
                                    walk_hop_by_hop(&g, node, d, steps, plus);
                                assert_eq!(
                                    links[1..],
                                    expected[..],
                                    "{dims:?} node {node} d {d} {plus} {steps}"
                                );
                                assert_eq!(
                                    end, expected_end,
                                    "{dims:?} node {node} d {d} {plus} {steps}"
                                );
                            }
                        }
                    }
                }
            }
        }
    }
}
