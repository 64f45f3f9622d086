//! Shared machinery of the k-ary n-cube (torus) and the mesh: coordinates and the table
//! from (node, dimension, direction) to link index.
//!
//! Node id = x + dims[0] * (y + dims[1] * z). Links are numbered by node, then dimension,
//! then `+` before `-`, skipping links that do not exist. Must never decide a route: the
//! torus and the mesh each own their routing rule.

use super::Link;
use crate::net::{LinkId, NodeId};

const NO_LINK: LinkId = LinkId::MAX;

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

    /// Appends the links of `steps` hops from `node` along dimension `d` in direction `plus`
    /// (wrapping at the ends, which only a torus's routes reach) and returns where they end.
    /// One division per call, not per hop: routes are computed for every pair that talks.
    pub fn walk(
        &self,
        node: NodeId,
        d: usize,
        steps: u32,
        plus: bool,
        out: &mut Vec<LinkId>,
    ) -> NodeId {
        let (k, stride) = (self.dims[d], self.strides[d]);
        let mut c = self.coord(node, d);
        let row = node - c * stride;
        // A range's map has a known length: one reservation, no capacity check per hop.
        out.extend((0..steps).map(|_| {
            let link = self.link(row + c * stride, d, plus);
            c = match (plus, c) {
                (true, c) if c + 1 == k => 0,
                (true, c) => c + 1,
                (false, 0) => k - 1,
                (false, c) => c - 1,
            };
            link
        }));
        row + c * stride
    }

    /// The link leaving `node` along dimension `d` in direction `plus`.
    pub fn link(&self, node: NodeId, d: usize, plus: bool) -> LinkId {
        let id = self.ports[self.port(node, d, usize::from(!plus))];
        debug_assert_ne!(id, NO_LINK, "routing used a missing link");
        id
    }
}
