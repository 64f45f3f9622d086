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
}

impl MachineConfig {
    /// The same machine with `nodes` processors, where the topology allows it: the
    /// one-dimensional topologies (ring, pipeline, bus, crossbar) take any count; a torus,
    /// mesh or hypercube keeps its shape, so `nodes` must not exceed it (a run may use a
    /// subset of the nodes, as the Delta's partitions did).
    pub fn with_nodes(&self, nodes: u32) -> Result<MachineConfig, String> {
        if nodes == 0 {
            return Err("the number of processors must be at least 1".into());
        }
        let mut m = self.clone();
        match self.network.topology {
            TopologyKind::Ring
            | TopologyKind::Pipeline
            | TopologyKind::Bus
            | TopologyKind::Crossbar => {
                m.nodes = nodes;
                m.network.dims = vec![nodes];
            }
            TopologyKind::Torus | TopologyKind::Mesh | TopologyKind::Hypercube => {
                if nodes > self.nodes {
                    return Err(format!(
                        "machine '{}' has {} nodes ({:?} of {:?}); ask for at most {}",
                        self.name, self.nodes, self.network.topology, self.network.dims, self.nodes
                    ));
                }
            }
        }
        Ok(m)
    }
}
