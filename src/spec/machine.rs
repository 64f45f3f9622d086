//! The machine spec file (machines/*.json) and its validation into a `MachineConfig`.
//!
//! Owns the JSON shape of a machine and every rule a machine must satisfy, each reported
//! with its field path. Must never build simulation state.

use std::collections::BTreeMap;
use std::path::Path;

use serde::Deserialize;

use super::{load_json, SpecError};
use crate::machine::{CostTable, CpuConfig, MachineConfig, Op};
use crate::net::{Fidelity, Network, NetworkConfig, Switching, TopologyKind};
use crate::units::{Bandwidth, Bytes, SimTime};

#[derive(Deserialize, Debug, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MachineSpec {
    /// The JSON Schema this file follows, for editors (`schemas/`); sortsim ignores it.
    #[serde(rename = "$schema", default, skip_serializing)]
    pub schema: Option<String>,
    pub name: String,
    pub source: String,
    #[schemars(range(min = 1, max = crate::limits::MAX_NODES))]
    pub nodes: u32,
    pub cpu: CpuSpec,
    pub memory: MemorySpec,
    pub network: NetworkSpec,
    /// The paper rows this machine's numbers were fitted to, one record per fit in its
    /// history (`sortsim calibrate` appends one to the machine it writes). `papers/NNN.json`
    /// marks exactly these rows `fitted`; `sortsim paper` refuses the two when they disagree.
    #[serde(default)]
    pub fitted_to: Vec<FitRecord>,
}

/// One fit a machine (or a stand-in scene) went through.
#[derive(Deserialize, serde::Serialize, Debug, Clone, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct FitRecord {
    /// "000" .. "003".
    pub paper: String,
    /// Row ids of `papers/NNN.json` the fit's cost included.
    pub rows: Vec<String>,
    /// The calibration spec that reproduces the fit, relative to `machines/` (a scene's:
    /// `scenes/`); absent for a value chosen by hand, which `source` explains.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spec: Option<String>,
}

#[derive(Deserialize, Debug, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CpuSpec {
    /// Time per operation, by operation name (see `Op`).
    #[serde(default)]
    pub costs: BTreeMap<String, SimTime>,
    pub send_overhead: SimTime,
    #[serde(default)]
    pub send_per_byte: SimTime,
    pub recv_overhead: SimTime,
    #[serde(default)]
    pub recv_per_byte: SimTime,
    pub overlap: bool,
    /// Round-robin time slicing between the programs on a node (a transputer's scheduler
    /// deschedules a low-priority process after two 1,024 us timeslices when another is
    /// ready): work is queued on the cpu a slice at a time, so a program that becomes ready
    /// waits at most one slice behind a long computation. Omitted: each computation holds the
    /// cpu until it ends.
    #[serde(default)]
    pub timeslice: Option<SimTime>,
}

#[derive(Deserialize, Debug, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MemorySpec {
    pub capacity_per_node: Bytes,
}

#[derive(Deserialize, Debug, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct NetworkSpec {
    pub topology: TopologySpec,
    /// Extent per dimension; may be omitted for ring, pipeline, bus and crossbar.
    #[serde(default)]
    pub dims: Option<Vec<u32>>,
    pub link_bandwidth: Bandwidth,
    pub hop_latency: SimTime,
    pub switching: SwitchingSpec,
    pub packet_size: Bytes,
    pub fidelity: FidelitySpec,
    /// Time each node's network interface spends on a message before its first byte leaves,
    /// sending one message at a time (LogGP's gap): a stream of messages from one node runs
    /// at `bytes / (message_gap + bytes / link_bandwidth)`. Omitted: no gap.
    #[serde(default)]
    pub message_gap: SimTime,
    /// A reconfigurable network (the MultiCluster's) wires a torus of any size a run asks
    /// for; a fixed torus must be used whole.
    #[serde(default)]
    pub reconfigurable: bool,
    /// The levels of a `fat-tree` (required for one, refused for any other topology).
    #[serde(default)]
    pub fat_tree: Option<FatTreeSpec>,
    /// The parts of a `dragonfly` (required for one, refused for any other topology).
    #[serde(default)]
    pub dragonfly: Option<DragonflySpec>,
    /// Nodes of several processors: the topology above joins their NICs. Omitted: each
    /// processor is a host of the topology.
    #[serde(default)]
    pub node: Option<NodeSpec>,
}

/// A node of several processors (GPUs, cores) on a switch of its own, with its NICs: the
/// topology's hosts are the NICs (`nics` per node), and `nodes` counts processors.
#[derive(Deserialize, Debug, Clone, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct NodeSpec {
    #[schemars(range(min = 1))]
    pub processors: u32,
    /// NICs per node (processor i uses NIC i mod nics); default 1.
    #[serde(default = "one")]
    #[schemars(range(min = 1))]
    pub nics: u32,
    /// Rate of every link inside the node (processor or NIC to the node's switch).
    pub link_bandwidth: Bandwidth,
    pub hop_latency: SimTime,
    /// Which node each processor sits on: `block` (default; processor p on node p / G, a
    /// node's processors numbered together) or `cyclic` (processor p on node p mod M,
    /// consecutive processors on consecutive nodes: Blue Gene's default XYZT order).
    #[serde(default)]
    pub placement: PlacementSpec,
}

/// `network.node.placement`.
#[derive(Deserialize, Debug, Clone, Copy, Default, PartialEq, Eq, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum PlacementSpec {
    #[default]
    Block,
    Cyclic,
}

fn one() -> u32 {
    1
}

/// A generalized fat-tree, level by level from the hosts up, in SimGrid's terms: `down[l]`
/// children per switch of level `l + 1`, `up[l]` parents per node of level `l`, and
/// `parallel[l]` cables between each such pair. Hosts: the product of `down`.
#[derive(Deserialize, Debug, Clone, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct FatTreeSpec {
    #[schemars(length(min = 1), inner(range(min = 1)))]
    pub down: Vec<u32>,
    #[schemars(length(min = 1), inner(range(min = 1)))]
    pub up: Vec<u32>,
    #[schemars(length(min = 1), inner(range(min = 1)))]
    pub parallel: Vec<u32>,
}

/// A dragonfly (Cray Cascade layout, as SimGrid's zone): groups of chassis of routers, each
/// router serving `nodes_per_router` hosts; one global link between every two groups.
#[derive(Deserialize, Debug, Clone, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DragonflySpec {
    /// At most `routers` (the global link to group g sits on router g of chassis 0).
    #[schemars(range(min = 1))]
    pub groups: u32,
    #[schemars(range(min = 1))]
    pub chassis: u32,
    /// Routers per chassis.
    #[schemars(range(min = 1))]
    pub routers: u32,
    #[schemars(range(min = 1))]
    pub nodes_per_router: u32,
    /// `minimal` (SimGrid's rule, the default) or `valiant` (through an intermediate group
    /// fixed per source and destination).
    #[serde(default)]
    pub routing: DragonflyRouting,
}

#[derive(Deserialize, Debug, Clone, Copy, Default, PartialEq, Eq, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum DragonflyRouting {
    #[default]
    Minimal,
    Valiant,
}

#[derive(Deserialize, Debug, Clone, Copy, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum TopologySpec {
    Ring,
    Pipeline,
    Torus,
    Mesh,
    Hypercube,
    Bus,
    Crossbar,
    FatTree,
    Dragonfly,
}

#[derive(Deserialize, Debug, Clone, Copy, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum SwitchingSpec {
    StoreAndForward,
    Wormhole,
}

#[derive(Deserialize, Debug, Clone, Copy, PartialEq, Eq, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum FidelitySpec {
    Ideal,
    Hops,
    Flow,
    Packet,
}

impl From<FidelitySpec> for Fidelity {
    fn from(f: FidelitySpec) -> Fidelity {
        match f {
            FidelitySpec::Ideal => Fidelity::Ideal,
            FidelitySpec::Hops => Fidelity::Hops,
            FidelitySpec::Flow => Fidelity::Flow,
            FidelitySpec::Packet => Fidelity::Packet,
        }
    }
}

impl From<TopologySpec> for TopologyKind {
    fn from(t: TopologySpec) -> TopologyKind {
        match t {
            TopologySpec::Ring => TopologyKind::Ring,
            TopologySpec::Pipeline => TopologyKind::Pipeline,
            TopologySpec::Torus => TopologyKind::Torus,
            TopologySpec::Mesh => TopologyKind::Mesh,
            TopologySpec::Hypercube => TopologyKind::Hypercube,
            TopologySpec::Bus => TopologyKind::Bus,
            TopologySpec::Crossbar => TopologyKind::Crossbar,
            TopologySpec::FatTree => TopologyKind::FatTree,
            TopologySpec::Dragonfly => TopologyKind::Dragonfly,
        }
    }
}

/// Reads, parses and validates a machine spec.
pub fn load_machine(path: &Path) -> Result<MachineConfig, SpecError> {
    let spec: MachineSpec = load_json(path)?;
    validate(path, spec)
}

pub use crate::limits::MAX_NODES;

/// Host memory of a node's network state, as measured (`sortsim check` on a 2^20-node ring:
/// 310 MB); for the refusal's estimate only.
const HOST_BYTES_PER_NODE: u64 = 300;

/// Checks every rule a machine must satisfy and builds its `MachineConfig`.
pub fn validate(path: &Path, spec: MachineSpec) -> Result<MachineConfig, SpecError> {
    let invalid = |field: &str, msg: String| SpecError::invalid(path, field, msg);
    if spec.nodes == 0 {
        return Err(invalid("nodes", "a machine needs at least 1 node".into()));
    }
    if spec.nodes > MAX_NODES {
        return Err(invalid(
            "nodes",
            format!(
                "at most {MAX_NODES} nodes, got {} (its network alone would take about {:.0} GB \
                 of host memory, at about {HOST_BYTES_PER_NODE} B per node)",
                spec.nodes,
                spec.nodes as f64 * HOST_BYTES_PER_NODE as f64 / 1e9
            ),
        ));
    }
    let mut costs = CostTable::default();
    for (name, &cost) in &spec.cpu.costs {
        let op = Op::from_name(name).ok_or_else(|| {
            invalid(
                &format!("cpu.costs.{name}"),
                format!("unknown operation; valid operations: {}", Op::valid_names()),
            )
        })?;
        costs.set(op, cost);
    }
    if spec.cpu.timeslice == Some(SimTime::ZERO) {
        return Err(invalid(
            "cpu.timeslice",
            "must be greater than 0ns (omit it for no time slicing)".into(),
        ));
    }
    if spec.memory.capacity_per_node == Bytes::ZERO {
        return Err(invalid(
            "memory.capacity_per_node",
            "must be greater than 0B".into(),
        ));
    }
    let network = network_config(path, spec.nodes, &spec.network)?;
    Network::new(&network).map_err(|e| invalid("network", e.to_string()))?;
    Ok(MachineConfig {
        name: spec.name,
        source: spec.source,
        nodes: spec.nodes,
        cpu: CpuConfig {
            costs,
            send_overhead: spec.cpu.send_overhead,
            send_per_byte: spec.cpu.send_per_byte,
            recv_overhead: spec.cpu.recv_overhead,
            recv_per_byte: spec.cpu.recv_per_byte,
            overlap: spec.cpu.overlap,
            timeslice: spec.cpu.timeslice,
        },
        memory_per_node: spec.memory.capacity_per_node,
        reconfigurable: spec.network.reconfigurable,
        network,
    })
}

/// The dims of a fat-tree (`down ++ up ++ parallel`) or dragonfly (`[groups, chassis,
/// routers, nodes]`) from its typed description; `None` for the other topologies, which may
/// not carry one.
fn switched_dims(
    path: &Path,
    topology: TopologyKind,
    net: &NetworkSpec,
) -> Result<Option<Vec<u32>>, SpecError> {
    let invalid = |field: &str, msg: String| SpecError::invalid(path, field, msg);
    // Each switched topology's description: required for it, refused for any other.
    let shapes = [
        (
            "network.fat_tree",
            TopologyKind::FatTree,
            net.fat_tree.is_some(),
            "a fat-tree needs its levels: {\"down\": [4, 4], \"up\": [1, 2], \"parallel\": [1, 1]}",
        ),
        (
            "network.dragonfly",
            TopologyKind::Dragonfly,
            net.dragonfly.is_some(),
            "a dragonfly needs its parts: {\"groups\": 4, \"chassis\": 2, \"routers\": 4, \"nodes_per_router\": 2}",
        ),
    ];
    for (field, kind, given, example) in shapes {
        match (given, topology == kind) {
            (false, true) => return Err(invalid(field, example.into())),
            (true, false) => {
                return Err(invalid(
                    field,
                    format!("only a {kind} takes `{field}`; this network is a {topology}"),
                ))
            }
            _ => {}
        }
    }
    match (&net.fat_tree, &net.dragonfly) {
        (Some(t), _) => {
            for (field, list) in [("down", &t.down), ("up", &t.up), ("parallel", &t.parallel)] {
                if list.len() != t.down.len() || list.is_empty() {
                    return Err(invalid(
                        &format!("network.fat_tree.{field}"),
                        format!(
                            "one entry per level: `down` has {}, `{field}` has {}",
                            t.down.len(),
                            list.len()
                        ),
                    ));
                }
                if let Some(i) = list.iter().position(|&v| v == 0) {
                    return Err(invalid(
                        &format!("network.fat_tree.{field}[{i}]"),
                        "must be at least 1".into(),
                    ));
                }
            }
            Ok(Some([&t.down[..], &t.up, &t.parallel].concat()))
        }
        (_, Some(d)) => {
            let parts = [d.groups, d.chassis, d.routers, d.nodes_per_router];
            let names = ["groups", "chassis", "routers", "nodes_per_router"];
            if let Some(i) = parts.iter().position(|&v| v == 0) {
                return Err(invalid(
                    &format!("network.dragonfly.{}", names[i]),
                    "must be at least 1".into(),
                ));
            }
            if d.groups > d.routers {
                return Err(invalid(
                    "network.dragonfly.groups",
                    format!(
                        "at most `routers` ({}): the global link to group g sits on router g of chassis 0",
                        d.routers
                    ),
                ));
            }
            let mut dims = parts.to_vec();
            if d.routing == DragonflyRouting::Valiant {
                dims.push(1);
            }
            Ok(Some(dims))
        }
        (None, None) => Ok(None),
    }
}

fn network_config(path: &Path, nodes: u32, net: &NetworkSpec) -> Result<NetworkConfig, SpecError> {
    let invalid = |field: &str, msg: String| SpecError::invalid(path, field, msg);
    let topology = TopologyKind::from(net.topology);
    let switched = switched_dims(path, topology, net)?;
    let dims = match (&net.dims, topology) {
        (Some(_), TopologyKind::FatTree | TopologyKind::Dragonfly) => {
            return Err(invalid(
                "network.dims",
                format!(
                    "a {topology} is described by `network.{}`; remove `dims`",
                    topology.name().replace('-', "_")
                ),
            ))
        }
        (None, TopologyKind::FatTree | TopologyKind::Dragonfly) => {
            switched.clone().expect("switched_dims requires the shape")
        }
        (Some(d), _) => d.clone(),
        (
            None,
            TopologyKind::Ring
            | TopologyKind::Pipeline
            | TopologyKind::Bus
            | TopologyKind::Crossbar,
        ) => {
            vec![nodes]
        }
        (None, TopologyKind::Hypercube) => vec![nodes],
        (None, _) => {
            return Err(invalid(
                "network.dims",
                format!("a {topology} needs its extent per dimension, e.g. [4, 4]"),
            ))
        }
    };
    if dims.is_empty() {
        return Err(invalid(
            "network.dims",
            "must list at least one dimension".into(),
        ));
    }
    if let Some(i) = dims.iter().position(|&d| d == 0) {
        return Err(invalid(
            &format!("network.dims[{i}]"),
            "a dimension must be at least 1".into(),
        ));
    }
    let (field, hosts) = match topology {
        TopologyKind::FatTree => ("network.fat_tree.down", &dims[..dims.len() / 3]),
        TopologyKind::Dragonfly => ("network.dragonfly", &dims[..4]),
        _ => ("network.dims", &dims[..]),
    };
    let product: u64 = hosts.iter().map(|&d| d as u64).product();
    let node = node_config(path, net)?;
    match node {
        None if product != nodes as u64 => {
            return Err(invalid(
                field,
                format!(
                    "the product of {hosts:?} is {product}, but `nodes` is {nodes}; they must be equal"
                ),
            ))
        }
        Some(n) if product % n.nics as u64 != 0 => {
            return Err(invalid(
                "network.node.nics",
                format!(
                    "the topology's {product} hosts are NICs, {} per node: {product} is not a multiple of {}",
                    n.nics, n.nics
                ),
            ))
        }
        Some(n) if product / n.nics as u64 * n.processors as u64 != nodes as u64 => {
            return Err(invalid(
                "nodes",
                format!(
                    "{} nodes ({product} NICs, {} each) of {} processors are {} processors, but `nodes` is {nodes}; they must be equal",
                    product / n.nics as u64,
                    n.nics,
                    n.processors,
                    product / n.nics as u64 * n.processors as u64
                ),
            ))
        }
        _ => {}
    }
    match topology {
        TopologyKind::Mesh if !(2..=3).contains(&dims.len()) => {
            return Err(invalid(
                "network.dims",
                format!("a mesh is 2D or 3D, got {} dimensions", dims.len()),
            ))
        }
        TopologyKind::Ring
        | TopologyKind::Pipeline
        | TopologyKind::Bus
        | TopologyKind::Crossbar
        | TopologyKind::Hypercube
            if dims.len() != 1 =>
        {
            return Err(invalid(
                "network.dims",
                format!("a {topology} has one dimension, [nodes]"),
            ))
        }
        TopologyKind::Hypercube if !nodes.is_power_of_two() => {
            return Err(invalid(
                "nodes",
                format!("a hypercube has a power-of-two node count, got {nodes}"),
            ))
        }
        _ => {}
    }
    if net.packet_size == Bytes::ZERO {
        return Err(invalid("network.packet_size", "must be at least 1B".into()));
    }
    Ok(NetworkConfig {
        topology,
        dims,
        link_bandwidth: net.link_bandwidth,
        hop_latency: net.hop_latency,
        switching: match net.switching {
            SwitchingSpec::StoreAndForward => Switching::StoreAndForward,
            SwitchingSpec::Wormhole => Switching::Wormhole,
        },
        packet_size: net.packet_size,
        fidelity: net.fidelity.into(),
        message_gap: net.message_gap,
        node,
    })
}

/// The node of several processors a network spec describes, checked.
fn node_config(
    path: &Path,
    net: &NetworkSpec,
) -> Result<Option<crate::net::NodeConfig>, SpecError> {
    let Some(n) = &net.node else {
        return Ok(None);
    };
    let invalid = |field: &str, msg: &str| Err(SpecError::invalid(path, field, msg.to_string()));
    if n.processors == 0 {
        return invalid("network.node.processors", "must be at least 1");
    }
    if n.nics == 0 {
        return invalid("network.node.nics", "must be at least 1");
    }
    if matches!(net.topology, TopologySpec::Crossbar | TopologySpec::Bus) {
        return invalid(
            "network.node",
            "the network between nodes must be point-to-point (not a crossbar or a bus)",
        );
    }
    Ok(Some(crate::net::NodeConfig {
        processors: n.processors,
        nics: n.nics,
        links: crate::net::NodeLinks {
            bandwidth: n.link_bandwidth,
            hop_latency: n.hop_latency,
        },
        placement: match n.placement {
            PlacementSpec::Block => crate::net::topology::Placement::Block,
            PlacementSpec::Cyclic => crate::net::topology::Placement::Cyclic,
        },
    }))
}
