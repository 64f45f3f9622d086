//! The simulated machine: how many nodes, what each operation costs on a node's cpu, how much
//! memory each node has, and the network between them.
//!
//! Owns the validated `MachineConfig` that every run is built from. Must never hold
//! simulation state (that lives in `engine`) or know about any algorithm.

pub mod cpu;
pub mod memory;

pub use cpu::{CostTable, Counts, CpuConfig, Op};
pub use memory::{MemError, MemoryPool, PoolStats};

use crate::net::{NetworkConfig, TopologyKind};
use crate::units::Bytes;

/// A machine as a run sees it: validated, with every quantity in exact units.
#[derive(Clone, Debug)]
pub struct MachineConfig {
    pub name: String,
    /// Where the numbers come from (paper, table, datasheet).
    pub source: String,
    pub nodes: u32,
    pub cpu: CpuConfig,
    /// Memory capacity of each node's pool.
    pub memory_per_node: Bytes,
    pub network: NetworkConfig,
    /// Whether the network can be rewired for a run: a torus of fewer nodes is then the
    /// squarest two-dimensional torus of exactly that many (Helios mapping a torus onto the
    /// MultiCluster's reconfigurable links, paper 001).
    pub reconfigurable: bool,
}

impl MachineConfig {
    /// The same machine with `nodes` processors, as a run on a partition of it sees it: the
    /// one-dimensional topologies (ring, pipeline, bus, crossbar) take any count; a mesh
    /// becomes the squarest sub-mesh of `nodes` that fits in it (the Delta ran on rectangular
    /// partitions); a hypercube a sub-cube; a torus, whose wrap-around links a partition would
    /// not have, must be used whole unless the network is reconfigurable.
    pub fn with_nodes(&self, nodes: u32) -> Result<MachineConfig, String> {
        if nodes == 0 {
            return Err("the number of processors must be at least 1".into());
        }
        if nodes > self.nodes {
            return Err(format!(
                "machine '{}' has {} nodes; ask for at most {}",
                self.name, self.nodes, self.nodes
            ));
        }
        let mut m = self.clone();
        m.nodes = nodes;
        if self.network.node.is_some() {
            // Nodes of several processors are used whole: the run's processes sit on the
            // first processors, node by node.
            return Ok(m);
        }
        m.network.dims = match self.network.topology {
            TopologyKind::Ring | TopologyKind::Pipeline | TopologyKind::Bus | TopologyKind::Crossbar => vec![nodes],
            TopologyKind::Hypercube if nodes.is_power_of_two() => vec![nodes],
            TopologyKind::Hypercube => {
                return Err(format!("a hypercube partition has a power-of-two node count; {nodes} is not"))
            }
            // A switched network is used whole: the run's processes sit on its first hosts,
            // as a batch system hands out the first nodes of a partition.
            TopologyKind::FatTree | TopologyKind::Dragonfly => self.network.dims.clone(),
            TopologyKind::Torus if nodes == self.nodes => self.network.dims.clone(),
            TopologyKind::Torus if self.reconfigurable => squarest_torus(nodes),
            TopologyKind::Torus => {
                return Err(format!(
                    "machine '{}' is a {} torus of {} nodes; its network is not reconfigurable and a torus cannot be partitioned, so ask for exactly {}",
                    self.name, crate::net::dims_text(&self.network.dims), self.nodes, self.nodes
                ))
            }
            TopologyKind::Mesh => sub_mesh(&self.network.dims, nodes).ok_or_else(|| {
                format!("no rectangular partition of {nodes} nodes fits machine '{}' (a {} mesh)", self.name, crate::net::dims_text(&self.network.dims))
            })?,
        };
        Ok(m)
    }
}

/// The two-dimensional torus of exactly `nodes` nodes whose sides are closest, the longer
/// first (8 nodes: 4x2).
fn squarest_torus(nodes: u32) -> Vec<u32> {
    let short = (1..=nodes)
        .take_while(|d| d * d <= nodes)
        .filter(|d| nodes % d == 0)
        .last()
        .unwrap_or(1);
    vec![nodes / short, short]
}

/// The squarest box of exactly `nodes` nodes that fits in a mesh of `dims` (2D or 3D).
fn sub_mesh(dims: &[u32], nodes: u32) -> Option<Vec<u32>> {
    let divisors = |n: u32| (1..=n).filter(move |d| n % d == 0);
    let mut best: Option<Vec<u32>> = None;
    let spread = |b: &[u32]| b.iter().max().unwrap() - b.iter().min().unwrap();
    for a in divisors(nodes).filter(|&a| a <= dims[0]) {
        let rest = nodes / a;
        let candidates: Vec<Vec<u32>> = if dims.len() == 2 {
            vec![vec![a, rest]]
        } else {
            divisors(rest).map(|b| vec![a, b, rest / b]).collect()
        };
        for c in candidates
            .into_iter()
            .filter(|c| c.iter().zip(dims).all(|(x, d)| x <= d))
        {
            if best.as_ref().is_none_or(|b| spread(&c) < spread(b)) {
                best = Some(c);
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mesh_partitions_are_the_squarest_box_that_fits() {
        assert_eq!(sub_mesh(&[16, 32], 512), Some(vec![16, 32]));
        assert_eq!(sub_mesh(&[16, 32], 256), Some(vec![16, 16]));
        assert_eq!(sub_mesh(&[16, 32], 8), Some(vec![2, 4]));
        assert_eq!(sub_mesh(&[16, 32], 17), Some(vec![1, 17]));
        assert_eq!(sub_mesh(&[16, 32], 37), None);
        assert_eq!(sub_mesh(&[4, 4, 4], 8), Some(vec![2, 2, 2]));
    }

    #[test]
    fn a_rewired_torus_is_the_squarest_of_exactly_that_size() {
        assert_eq!(squarest_torus(16), [4, 4]);
        assert_eq!(squarest_torus(8), [4, 2]);
        assert_eq!(squarest_torus(2), [2, 1]);
        assert_eq!(squarest_torus(1), [1, 1]);
        assert_eq!(squarest_torus(7), [7, 1]);
    }
}
