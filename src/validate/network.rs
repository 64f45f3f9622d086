//! `flow` against SimGrid: the same message patterns on the same networks through sortsim's
//! exact max-min solver and through SimGrid's CM02 model (every refinement off, zero
//! latency); every message's completion compared. Meshes and tori are handed to SimGrid with
//! sortsim's dimension-order routes spelled out; fat-trees and dragonflies are built by
//! SimGrid's own cluster zones, which route by their own rules, and every pair's route is
//! compared link for link before the times are.
//!
//! Owns the cases (what each pattern exercises), the platform description handed to SimGrid
//! and the comparison. Must never give SimGrid a route sortsim did not compute, nor let a
//! native zone's differing route pass unreported.

use std::collections::BTreeSet;
use std::ffi::OsStr;
use std::path::Path;
use std::time::Instant;

use serde::{Deserialize, Serialize};

use super::python::{self, ToolError, SIMGRID_FLOW};
use crate::net::pattern::{self, run_pattern, Pattern};
use crate::net::{Fidelity, Network, NetworkConfig, Switching, TopologyKind};
use crate::units::{Bytes, SimTime};

/// The largest relative difference allowed between sortsim's and SimGrid's transfer time of
/// any message: 0.1%. Not 0 because SimGrid solves in f64 (its max-min precision set to 1e-9
/// here) while sortsim rounds rates down to whole bits per second and completions up to the
/// picosecond; on these patterns both errors stay far below 1e-6.
pub const TOLERANCE: f64 = 1e-3;

/// One pattern on one network.
pub struct Case {
    pub name: String,
    pub what: &'static str,
    pub topology: TopologyKind,
    pub dims: Vec<u32>,
    pub pattern: Pattern,
    pub simgrid: Platform,
}

/// How SimGrid gets the network.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Platform {
    /// A full zone with sortsim's route for every pair.
    Routes,
    /// SimGrid's own cluster zone (fat-tree, dragonfly): its routes compared with sortsim's
    /// for every pair, the times measured on it.
    Native,
    /// SimGrid's own zone for the route comparison, sortsim's routes for the times: for a
    /// network where SimGrid's rule gives some pairs a route that is not a path (a
    /// dragonfly's intra-group route from a chassis other than 0).
    NativeRoutesOnly,
}

/// What one case showed.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CaseResult {
    pub name: String,
    pub what: &'static str,
    pub topology: &'static str,
    pub dims: Vec<u32>,
    /// The shape as people write it (`8x8`, a fat-tree's levels, a dragonfly's parts).
    pub shape: String,
    pub messages: usize,
    /// Messages that took at least 1% longer than alone on the network: how much sharing
    /// the case puts to the test.
    pub contended: usize,
    /// Ordered pairs whose route SimGrid's own zone gave (0 when SimGrid was handed
    /// sortsim's routes), how many of them differ from sortsim's, and how many of SimGrid's
    /// are not a path from source to destination (those are not counted as differing).
    pub routes_compared: usize,
    pub routes_differing: usize,
    pub simgrid_routes_not_paths: usize,
    pub makespan_s: f64,
    pub max_rel_diff: f64,
    pub mean_rel_diff: f64,
    /// The message with the largest difference: its index, sortsim's and SimGrid's transfer
    /// time in seconds.
    pub worst: (usize, f64, f64),
}

/// Host wall time of both programs on one case (kept apart: it varies from run to run).
#[derive(Clone, Debug, Serialize)]
pub struct CaseCost {
    pub name: String,
    pub messages: usize,
    pub sortsim_wall_s: f64,
    pub simgrid_wall_s: f64,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct NetworkValidation {
    pub model: &'static str,
    pub link_bandwidth: String,
    pub tolerance: f64,
    pub max_rel_diff: f64,
    /// Routes of SimGrid's own zones that differ from sortsim's (must be 0 to pass).
    pub routes_differing: usize,
    pub pass: bool,
    pub cases: Vec<CaseResult>,
}

/// The network every case runs on: the Delta's 17 MB/s links, zero latency, wormhole, flow.
fn config(topology: TopologyKind, dims: &[u32]) -> NetworkConfig {
    NetworkConfig {
        topology,
        dims: dims.to_vec(),
        link_bandwidth: "17MB/s".parse().expect("a valid bandwidth"),
        hop_latency: SimTime::ZERO,
        switching: Switching::Wormhole,
        packet_size: Bytes::new(4096),
        fidelity: Fidelity::Flow,
        message_gap: SimTime::ZERO,
        node: None,
    }
}

/// The patterns the issue of record names, on meshes and tori; `quick` keeps the smaller
/// half.
pub fn cases(quick: bool) -> Vec<Case> {
    let kib = |k: u64| Bytes::new(k * 1024);
    let mixed = [kib(4), kib(16), kib(64), kib(256), kib(1024)];
    let ms = SimTime::from_us(1000);
    let on = |name: &str, what, topology, dims: &[u32], pattern, simgrid| Case {
        name: name.to_string(),
        what,
        topology,
        dims: dims.to_vec(),
        pattern,
        simgrid,
    };
    let case = |name: &str, what, topology, dims: &[u32], pattern| {
        on(name, what, topology, dims, pattern, Platform::Routes)
    };
    use TopologyKind::{Dragonfly, FatTree, Mesh, Torus};
    let mut all = vec![
        case(
            "all-to-all-mesh-4x4",
            "every node to every other at once, 64 KiB",
            Mesh,
            &[4, 4],
            pattern::all_to_all(16, kib(64)),
        ),
        case(
            "hot-spot-mesh-8x8",
            "every node to node 27 at once, 256 KiB",
            Mesh,
            &[8, 8],
            pattern::hot_spot(64, 27, kib(256)),
        ),
        case(
            "complement-torus-8x8",
            "node i to node 63 - i at once, 128 KiB",
            Torus,
            &[8, 8],
            pattern::bit_complement(64, kib(128)),
        ),
        case(
            "permutations-mesh-8x8",
            "8 random permutations, staggered over 20 ms, 4 KiB to 1 MiB",
            Mesh,
            &[8, 8],
            pattern::random_permutations(64, 8, &mixed, ms.times(20), 1),
        ),
        on(
            "all-to-all-fat-tree-2-level",
            "every host to every other at once, 16 KiB, on 8 leaves of 8 hosts and 4 spines \
             (2:1 oversubscribed)",
            FatTree,
            &[8, 8, 1, 4, 1, 1],
            pattern::all_to_all(64, kib(16)),
            Platform::Native,
        ),
        on(
            "permutations-dragonfly-4x1x4x4",
            "8 random permutations, staggered over 20 ms, 4 KiB to 1 MiB, on 4 groups of 4 \
             routers of 4 hosts",
            Dragonfly,
            &[4, 1, 4, 4],
            pattern::random_permutations(64, 8, &mixed, ms.times(20), 5),
            Platform::Native,
        ),
    ];
    if !quick {
        all.extend([
            case(
                "all-to-all-subset-torus-8x8",
                "every node to 8 random others at once, 16 KiB",
                Torus,
                &[8, 8],
                pattern::random_pairs(64, 8, kib(16), 2),
            ),
            case(
                "transpose-mesh-16x16",
                "node (x, y) to node (y, x) at once, 1 MiB",
                Mesh,
                &[16, 16],
                pattern::transpose(&[16, 16], kib(1024)),
            ),
            case(
                "complement-mesh-16x32",
                "node i to node 511 - i at once on the Delta's mesh, 64 KiB",
                Mesh,
                &[16, 32],
                pattern::bit_complement(512, kib(64)),
            ),
            case(
                "permutations-torus-16x32",
                "4 random permutations, staggered over 40 ms, 4 KiB to 1 MiB",
                Torus,
                &[16, 32],
                pattern::random_permutations(512, 4, &mixed, ms.times(40), 3),
            ),
            case(
                "staggered-torus-16x16",
                "2,000 random pairs, staggered over 20 ms, 4 KiB to 1 MiB",
                Torus,
                &[16, 16],
                pattern::random_staggered(256, 2000, &mixed, ms.times(20), 4),
            ),
            on(
                "hot-spot-fat-tree-3-level-parallel",
                "every host to host 37 at once, 64 KiB, on a 3-level tree with 2 cables \
                 between leaves and their 2 parents",
                FatTree,
                &[4, 4, 4, 1, 2, 2, 2, 1, 1],
                pattern::hot_spot(64, 37, kib(64)),
                Platform::Native,
            ),
            on(
                "staggered-fat-tree-3-level",
                "2,000 random pairs, staggered over 20 ms, 4 KiB to 1 MiB, on a 3-level tree",
                FatTree,
                &[4, 4, 8, 1, 4, 2, 1, 1, 1],
                pattern::random_staggered(128, 2000, &mixed, ms.times(20), 6),
                Platform::Native,
            ),
            on(
                "all-to-all-dragonfly-3x2x3x2",
                "every host to every other at once, 16 KiB, on 3 groups of 2 chassis of 3 \
                 routers of 2 hosts",
                Dragonfly,
                &[3, 2, 3, 2],
                pattern::all_to_all(36, kib(16)),
                Platform::NativeRoutesOnly,
            ),
        ]);
    }
    all
}

/// What SimGrid is handed: the platform and the messages; with `native`, SimGrid builds the
/// zone and `routes` only names the pairs whose routes it reports.
#[derive(Serialize)]
struct SimgridInput {
    nodes: u32,
    bandwidth_bps: f64,
    links: usize,
    routes: Vec<(u32, u32, Vec<u32>)>,
    messages: Vec<(u32, u32, u64, f64)>,
    #[serde(skip_serializing_if = "Option::is_none")]
    native: Option<NativeZone>,
}

/// SimGrid's cluster-zone parameters for a fat-tree or a dragonfly.
#[derive(Serialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
enum NativeZone {
    FatTree {
        down: Vec<u32>,
        up: Vec<u32>,
        parallel: Vec<u32>,
    },
    Dragonfly {
        groups: u32,
        chassis: u32,
        routers: u32,
        nodes_per_router: u32,
    },
}

impl NativeZone {
    fn of(topology: TopologyKind, dims: &[u32]) -> Option<NativeZone> {
        let h = dims.len() / 3;
        match topology {
            TopologyKind::FatTree => Some(NativeZone::FatTree {
                down: dims[..h].to_vec(),
                up: dims[h..2 * h].to_vec(),
                parallel: dims[2 * h..].to_vec(),
            }),
            TopologyKind::Dragonfly => Some(NativeZone::Dragonfly {
                groups: dims[0],
                chassis: dims[1],
                routers: dims[2],
                nodes_per_router: dims[3],
            }),
            _ => None,
        }
    }
}

#[derive(Deserialize)]
struct SimgridAnswer {
    completion_s: Vec<f64>,
    wall_s: f64,
    #[serde(default)]
    routes: Vec<(u32, u32, Vec<u32>)>,
}

/// How SimGrid's own routes compare with sortsim's.
#[derive(Default)]
struct RouteCheck {
    compared: usize,
    differing: usize,
    not_paths: usize,
}

fn check_routes(net: &Network, theirs: &[(u32, u32, Vec<u32>)]) -> RouteCheck {
    let links = net.links();
    let is_path = |src: u32, dst: u32, route: &[u32]| {
        route.iter().all(|&l| (l as usize) < links.len()) && {
            let mut at = src;
            route.iter().all(|&l| {
                let link = links[l as usize];
                let joined = link.from == at;
                at = link.to;
                joined
            }) && at == dst
        }
    };
    let mut check = RouteCheck::default();
    for (src, dst, route) in theirs {
        check.compared += 1;
        if !is_path(*src, *dst, route) {
            check.not_paths += 1;
        } else if net.route(*src, *dst).as_deref() != Some(&route[..]) {
            check.differing += 1;
        }
    }
    check
}

/// Runs every case through both programs (SimGrid's script runs in `work`).
pub fn validate(
    cases: &[Case],
    work: &Path,
) -> Result<(NetworkValidation, Vec<CaseCost>), ToolError> {
    let mut results = Vec::new();
    let mut costs = Vec::new();
    for (i, case) in cases.iter().enumerate() {
        let (result, cost) = compare(case, &work.join(format!("case{i}.json")), work)?;
        results.push(result);
        costs.push(cost);
    }
    let max_rel_diff = results.iter().map(|r| r.max_rel_diff).fold(0.0, f64::max);
    let routes_differing = results.iter().map(|r| r.routes_differing).sum();
    let validation = NetworkValidation {
        model: "SimGrid CM02 (crosstraffic 0, TCP-gamma 0, weight-S 0, latency 0)",
        link_bandwidth: config(TopologyKind::Mesh, &[1]).link_bandwidth.to_string(),
        tolerance: TOLERANCE,
        max_rel_diff,
        routes_differing,
        pass: max_rel_diff <= TOLERANCE && routes_differing == 0,
        cases: results,
    };
    Ok((validation, costs))
}

fn compare(
    case: &Case,
    input_path: &Path,
    work: &Path,
) -> Result<(CaseResult, CaseCost), ToolError> {
    let cfg = config(case.topology, &case.dims);
    let began = Instant::now();
    let ours = run_pattern(&cfg, &case.pattern).expect("built-in validation cases are valid");
    let sortsim_wall_s = began.elapsed().as_secs_f64();

    let net = Network::new(&cfg).expect("built-in validation networks are valid");
    let route_of = |(s, d): (u32, u32)| (s, d, net.route(s, d).expect("every pair is routable"));
    let used: BTreeSet<(u32, u32)> = ours
        .messages
        .iter()
        .map(|m| (m.src, m.dst.expect("no broadcasts in validation patterns")))
        .collect();
    let messages: Vec<(u32, u32, u64, f64)> = ours
        .messages
        .iter()
        .map(|m| (m.src, m.dst.unwrap_or(0), m.bytes, seconds(m.start_ps)))
        .collect();
    let explicit = |messages| SimgridInput {
        nodes: net.nodes(),
        bandwidth_bps: cfg.link_bandwidth.bits_per_s() as f64 / 8.0,
        links: net.link_count(),
        routes: used.iter().copied().map(route_of).collect(),
        messages,
        native: None,
    };
    if case.simgrid == Platform::Routes {
        let answer = ask_simgrid(&explicit(messages), input_path, work)?;
        return finish(
            case,
            &net,
            &ours,
            sortsim_wall_s,
            answer,
            RouteCheck::default(),
        );
    }
    // SimGrid's own zone, asked for every ordered pair's route: the rule is compared whole.
    let n = net.nodes();
    let native = |messages| SimgridInput {
        routes: (0..n)
            .flat_map(|s| (0..n).filter(move |&d| d != s).map(move |d| (s, d)))
            .map(route_of)
            .collect(),
        native: NativeZone::of(case.topology, &case.dims),
        ..explicit(messages)
    };
    if case.simgrid == Platform::Native {
        let answer = ask_simgrid(&native(messages), input_path, work)?;
        let routes = check_routes(&net, &answer.routes);
        return finish(case, &net, &ours, sortsim_wall_s, answer, routes);
    }
    let routes = check_routes(
        &net,
        &ask_simgrid(&native(Vec::new()), input_path, work)?.routes,
    );
    let answer = ask_simgrid(&explicit(messages), input_path, work)?;
    finish(case, &net, &ours, sortsim_wall_s, answer, routes)
}

/// Writes `input`, runs SimGrid's script on it and reads its answer.
fn ask_simgrid(input: &SimgridInput, path: &Path, work: &Path) -> Result<SimgridAnswer, ToolError> {
    let text = serde_json::to_string(input).expect("plain data serializes");
    std::fs::write(path, text).map_err(|source| ToolError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let stdout = python::run(&SIMGRID_FLOW, work, &[OsStr::new(path)])?;
    python::parse(&SIMGRID_FLOW, &stdout)
}

/// Compares SimGrid's completions with sortsim's.
fn finish(
    case: &Case,
    net: &Network,
    ours: &pattern::PatternReport,
    sortsim_wall_s: f64,
    theirs: SimgridAnswer,
    routes: RouteCheck,
) -> Result<(CaseResult, CaseCost), ToolError> {
    if theirs.completion_s.len() != ours.messages.len() {
        return Err(ToolError::Failed {
            script: SIMGRID_FLOW.name,
            detail: format!(
                "{} completions for {} messages",
                theirs.completion_s.len(),
                ours.messages.len()
            ),
        });
    }

    let timing = net.timing();
    let mut worst = (0, 0.0, 0.0);
    let (mut max_rel_diff, mut sum, mut contended) = (0.0f64, 0.0, 0);
    for (i, (m, &done)) in ours.messages.iter().zip(&theirs.completion_s).enumerate() {
        let ours_s = seconds(m.latency_ps);
        let theirs_s = done - seconds(m.start_ps);
        let rel = (theirs_s - ours_s).abs() / ours_s;
        sum += rel;
        if rel > max_rel_diff || i == 0 {
            max_rel_diff = max_rel_diff.max(rel);
            worst = (i, ours_s, theirs_s);
        }
        let alone =
            timing.contention_free(net.hops(m.src, m.dst.unwrap_or(0)), Bytes::new(m.bytes));
        if m.latency_ps * 100 >= alone.ps() * 101 {
            contended += 1;
        }
    }
    let result = CaseResult {
        name: case.name.clone(),
        what: case.what,
        topology: case.topology.name(),
        dims: case.dims.clone(),
        shape: crate::net::shape_text(case.topology, &case.dims),
        messages: ours.messages.len(),
        contended,
        routes_compared: routes.compared,
        routes_differing: routes.differing,
        simgrid_routes_not_paths: routes.not_paths,
        makespan_s: ours.makespan_s,
        max_rel_diff,
        mean_rel_diff: sum / ours.messages.len().max(1) as f64,
        worst,
    };
    let cost = CaseCost {
        name: case.name.clone(),
        messages: ours.messages.len(),
        sortsim_wall_s,
        simgrid_wall_s: theirs.wall_s,
    };
    Ok((result, cost))
}

fn seconds(ps: u64) -> f64 {
    ps as f64 * 1e-12
}
