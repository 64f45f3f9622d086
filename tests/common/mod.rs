//! Helpers shared by the integration tests: small machines built from JSON text through the
//! same validation the CLI uses.
#![allow(dead_code)]

use std::path::Path;

use sortsim::machine::MachineConfig;
use sortsim::spec::machine::{validate, MachineSpec};
use sortsim::spec::parse_json;

/// A machine from spec text (validated exactly as a file would be).
pub fn machine(json: &str) -> MachineConfig {
    let spec: MachineSpec =
        parse_json(Path::new("test-machine.json"), json).expect("test machine parses");
    validate(Path::new("test-machine.json"), spec).expect("test machine is valid")
}

/// A ring of `nodes` with the given cpu overheads and overlap flag, 1 MB/s links, 1us hops,
/// wormhole switching, ideal transport.
pub fn ring(nodes: u32, send_overhead: &str, recv_overhead: &str, overlap: bool) -> MachineConfig {
    machine(&format!(
        r#"{{"name": "test-ring", "source": "test", "nodes": {nodes},
            "cpu": {{"costs": {{"pixel_write": "10ns", "setup_triangle": "1us"}},
                     "send_overhead": "{send_overhead}", "recv_overhead": "{recv_overhead}", "overlap": {overlap}}},
            "memory": {{"capacity_per_node": "1MB"}},
            "network": {{"topology": "ring", "link_bandwidth": "1MB/s", "hop_latency": "1us",
                         "switching": "wormhole", "packet_size": "1KiB", "fidelity": "ideal"}}}}"#
    ))
}
