//! Message patterns: a list of messages read from JSON (or generated), driven through a
//! [`Network`] by a small (time, sequence) loop, without the engine. Backs `sortsim netsim`.
//!
//! Owns pattern validation (errors name the field, `messages[3].dst`, and the valid range),
//! the report with units in its key names, and the generators used by tests and benches
//! (all-to-all, hot spot, transpose, seeded random pairs, seeded staggered random traffic).
//!
//! Must never reorder messages in the report (input order), never use a HashMap, and never
//! take randomness from anywhere but the given seed.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use super::{Delivered, Dest, Fidelity, MsgId, NetError, Network, NetworkConfig, NodeId};
use crate::units::{Bytes, SimTime};

/// One message of a pattern file.
#[derive(Clone, Debug, PartialEq, Eq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PatternMessage {
    pub src: u32,
    /// Destination node; leave it out and set `broadcast: true` for a bus broadcast.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dst: Option<u32>,
    #[serde(default, skip_serializing_if = "is_false")]
    pub broadcast: bool,
    /// A size with its unit, e.g. "64KiB".
    pub bytes: String,
    /// The instant the message starts, e.g. "0us"; "0ps" if absent.
    #[serde(default = "zero_time")]
    pub start: String,
}

/// A pattern file: `{"messages": [{"src": 0, "dst": 3, "bytes": "4KiB", "start": "0us"}]}`.
#[derive(Clone, Debug, Default, PartialEq, Eq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Pattern {
    /// The JSON Schema this file follows, for editors (`schemas/`); sortsim ignores it.
    #[serde(rename = "$schema", default, skip_serializing_if = "Option::is_none")]
    pub schema: Option<String>,
    pub messages: Vec<PatternMessage>,
}

/// What happened to a pattern: every message in input order, every link in index order.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PatternReport {
    pub topology: &'static str,
    pub fidelity: &'static str,
    pub switching: &'static str,
    pub nodes: u32,
    /// Last completion minus first start.
    pub makespan_ps: u64,
    pub makespan_s: f64,
    /// Mean of (completion - start) over messages, floored to a picosecond.
    pub mean_latency_ps: u64,
    pub mean_latency_s: f64,
    pub messages: Vec<MessageReport>,
    pub links: Vec<LinkReport>,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MessageReport {
    pub src: u32,
    /// `None` for a broadcast.
    pub dst: Option<u32>,
    pub bytes: u64,
    pub start_ps: u64,
    pub completion_ps: u64,
    pub completion_s: f64,
    pub latency_ps: u64,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LinkReport {
    pub link: u32,
    pub name: String,
    pub from: u32,
    pub to: u32,
    pub bytes: u64,
    pub messages: u64,
    pub busy_ps: u64,
    pub busy_s: f64,
    pub peak_queue: u32,
}

impl Pattern {
    pub fn new(messages: Vec<PatternMessage>) -> Pattern {
        Pattern {
            schema: None,
            messages,
        }
    }
}

impl PatternMessage {
    /// A point-to-point message.
    pub fn new(src: NodeId, dst: NodeId, bytes: Bytes, start: SimTime) -> PatternMessage {
        PatternMessage {
            src,
            dst: Some(dst),
            broadcast: false,
            bytes: format!("{}B", bytes.get()),
            start: format!("{}ps", start.ps()),
        }
    }

    /// A bus broadcast from `src`.
    pub fn broadcast(src: NodeId, bytes: Bytes, start: SimTime) -> PatternMessage {
        PatternMessage {
            dst: None,
            broadcast: true,
            ..PatternMessage::new(src, 0, bytes, start)
        }
    }
}

/// A pattern message checked against a network.
#[derive(Clone, Copy, Debug)]
pub struct ParsedMessage {
    pub src: NodeId,
    pub dest: Dest,
    pub bytes: Bytes,
    pub start: SimTime,
}

/// Checks every message against `net`; the first error names its field and what is valid.
pub fn parse_pattern(net: &Network, pattern: &Pattern) -> Result<Vec<ParsedMessage>, NetError> {
    let parsed: Vec<ParsedMessage> = pattern
        .messages
        .iter()
        .enumerate()
        .map(|(i, m)| parse_message(net, i, m))
        .collect::<Result<_, _>>()?;
    check_horizon(net, &parsed)?;
    check_packet_budget(net, &parsed)?;
    Ok(parsed)
}

/// At `packet` fidelity, refuses a pattern whose packets times hops pass
/// [`limits::MAX_PACKET_HOPS`](crate::limits::MAX_PACKET_HOPS), naming the message that
/// contributes most, before any packet is simulated.
fn check_packet_budget(net: &Network, messages: &[ParsedMessage]) -> Result<(), NetError> {
    if net.fidelity() != Fidelity::Packet {
        return Ok(());
    }
    let packet = net.timing().packet_size.get().max(1);
    let work = |m: &ParsedMessage| {
        let hops = match m.dest {
            Dest::Node(d) => u64::from(net.hops(m.src, d).total().max(1)),
            Dest::Broadcast => 1,
        };
        m.bytes.get().div_ceil(packet).max(1).saturating_mul(hops)
    };
    let total = messages.iter().fold(0u64, |t, m| t.saturating_add(work(m)));
    let limit = crate::limits::MAX_PACKET_HOPS;
    if total <= limit {
        return Ok(());
    }
    // The first of the largest (max_by_key keeps the last of equals).
    let i = (0..messages.len())
        .rev()
        .max_by_key(|&i| work(&messages[i]))
        .unwrap_or(0);
    Err(NetError::Pattern(format!(
        "messages[{i}].bytes: at packet fidelity the pattern is {total:.3e} packet hops ({} B \
         packets); the limit is {limit:.0e} (sortsim::limits::MAX_PACKET_HOPS): send fewer or \
         smaller messages, or use --fidelity flow, which takes any size",
        packet
    )))
}

/// Refuses a pattern that could end past the largest simulated time: its last start plus
/// every message sent one after another over one link, each paying its interface's gap, a
/// hop latency per node and a serialization per packet on the way (more than any transport can take), must fit in
/// u64 picoseconds. The message that contributes most is named.
fn check_horizon(net: &Network, messages: &[ParsedMessage]) -> Result<(), NetError> {
    let cost = |m: &ParsedMessage| net.worst_case_ps(m.bytes);
    let last_start = messages
        .iter()
        .map(|m| m.start)
        .max()
        .unwrap_or(SimTime::ZERO);
    let total = messages.iter().fold(u128::from(last_start.ps()), |t, m| {
        t.saturating_add(cost(m))
    });
    if total <= u128::from(SimTime::MAX.ps()) {
        return Ok(());
    }
    let (i, field) = match messages.iter().enumerate().max_by_key(|(_, m)| cost(m)) {
        Some((i, m)) if cost(m) > u128::from(last_start.ps()) => (i, "bytes"),
        _ => (
            messages
                .iter()
                .position(|m| m.start == last_start)
                .unwrap_or(0),
            "start",
        ),
    };
    Err(NetError::Pattern(format!(
        "messages[{i}].{field}: the pattern could run past the largest simulated time, {} \
         (u64 picoseconds): its last start is {last_start} and its messages take up to {:.3e} s \
         on one link; send fewer or smaller messages, or start them earlier",
        SimTime::MAX,
        (total - u128::from(last_start.ps())) as f64 / 1e12
    )))
}

/// Runs `pattern` on a fresh network built from `cfg`.
pub fn run_pattern(cfg: &NetworkConfig, pattern: &Pattern) -> Result<PatternReport, NetError> {
    run_pattern_counted(cfg, pattern).map(|(report, _)| report)
}

/// [`run_pattern`], with the flow model's work counters at the end (see
/// [`SolveCounters`](super::transport::SolveCounters)).
pub fn run_pattern_counted(
    cfg: &NetworkConfig,
    pattern: &Pattern,
) -> Result<(PatternReport, super::transport::SolveCounters), NetError> {
    let mut net = Network::new(cfg)?;
    let parsed = parse_pattern(&net, pattern)?;
    let completions = drive(&mut net, &parsed);
    let counters = net.solve_counters();
    Ok((report(cfg, &net, &parsed, &completions), counters))
}

/// Injects every message at its start and collects each one's delivery instant, indexed like
/// `messages`. At one instant, injections (in input order) come before the network's own
/// events, so messages starting together share one flow recomputation.
///
/// Panics if the network delivers a message twice, never, or stops making progress: those
/// are bugs in a transport, not bad input.
pub fn drive(net: &mut Network, messages: &[ParsedMessage]) -> Vec<SimTime> {
    let mut order: Vec<usize> = (0..messages.len()).collect();
    order.sort_by_key(|&i| (messages[i].start, i));
    let mut completion: Vec<Option<SimTime>> = vec![None; messages.len()];
    let mut record = |i: usize, at: SimTime| {
        assert!(completion[i].is_none(), "message {i} delivered twice");
        completion[i] = Some(at);
    };
    let mut delivered: Vec<Delivered> = Vec::new();
    let mut next = 0;
    loop {
        let next_start = order.get(next).map(|&i| messages[i].start);
        let Some(now) = SimTime::earliest(next_start, net.next_event_time()) else {
            break;
        };
        while let Some(&i) = order.get(next).filter(|&&i| messages[i].start == now) {
            let m = messages[i];
            if let Some(at) = net.inject(now, i as MsgId, m.src, m.dest, m.bytes) {
                record(i, at);
            }
            next += 1;
        }
        if net.next_event_time() == Some(now) {
            net.advance(now, &mut delivered);
            for d in delivered.drain(..) {
                record(d.msg as usize, d.at);
            }
        }
        if let Some(t) = net.next_event_time() {
            assert!(t > now, "network made no progress at {now}");
        }
    }
    completion
        .into_iter()
        .enumerate()
        .map(|(i, c)| c.unwrap_or_else(|| panic!("message {i} was never delivered")))
        .collect()
}

/// Every node sends `bytes` to every other node, all at time 0.
pub fn all_to_all(nodes: u32, bytes: Bytes) -> Pattern {
    let messages = (0..nodes)
        .flat_map(|s| (0..nodes).filter(move |&d| d != s).map(move |d| (s, d)))
        .map(|(s, d)| PatternMessage::new(s, d, bytes, SimTime::ZERO))
        .collect();
    Pattern::new(messages)
}

/// Every node but `dst` sends `bytes` to `dst`, all at time 0.
pub fn hot_spot(nodes: u32, dst: NodeId, bytes: Bytes) -> Pattern {
    let messages = (0..nodes)
        .filter(|&s| s != dst)
        .map(|s| PatternMessage::new(s, dst, bytes, SimTime::ZERO))
        .collect();
    Pattern::new(messages)
}

/// Matrix transpose on a 2D grid `[w, h]`: node `x + w*y` sends to node `y + h*x` (nodes on
/// the diagonal of a square grid send nothing). Panics unless `dims` has two entries.
pub fn transpose(dims: &[u32], bytes: Bytes) -> Pattern {
    let [w, h] = dims else {
        panic!("transpose needs a 2D grid, got dims {dims:?}");
    };
    let messages = (0..*h)
        .flat_map(|y| (0..*w).map(move |x| (x + w * y, y + h * x)))
        .filter(|(s, d)| s != d)
        .map(|(s, d)| PatternMessage::new(s, d, bytes, SimTime::ZERO))
        .collect();
    Pattern::new(messages)
}

/// Every node sends `bytes` to `k` distinct other nodes chosen with a ChaCha8 stream seeded
/// by `seed` (k is capped at `nodes - 1`), all at time 0.
pub fn random_pairs(nodes: u32, k: u32, bytes: Bytes, seed: u64) -> Pattern {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let others = nodes.saturating_sub(1) as usize;
    let mut messages = Vec::new();
    for src in 0..nodes {
        let picks = rand::seq::index::sample(&mut rng, others, (k as usize).min(others));
        for j in picks.into_iter() {
            let j = j as u32;
            let dst = if j >= src { j + 1 } else { j };
            messages.push(PatternMessage::new(src, dst, bytes, SimTime::ZERO));
        }
    }
    Pattern::new(messages)
}

/// Bit complement: node `i` sends to node `(nodes - 1) - i` (for a power-of-two node count
/// that is `i` with every bit flipped), all at time 0; a middle node of an odd count sends
/// nothing.
pub fn bit_complement(nodes: u32, bytes: Bytes) -> Pattern {
    let messages = (0..nodes)
        .map(|s| (s, nodes - 1 - s))
        .filter(|(s, d)| s != d)
        .map(|(s, d)| PatternMessage::new(s, d, bytes, SimTime::ZERO))
        .collect();
    Pattern::new(messages)
}

/// `rounds` random permutations without fixed points: in each, every node sends one message
/// and receives one. Sizes are drawn from `sizes` and start instants uniformly from
/// `[0, spread)` (whole nanoseconds), all from one ChaCha8 stream seeded by `seed`. Panics if
/// `nodes < 2` or `sizes` is empty.
pub fn random_permutations(
    nodes: u32,
    rounds: u32,
    sizes: &[Bytes],
    spread: SimTime,
    seed: u64,
) -> Pattern {
    use rand::seq::SliceRandom;
    let mut draw = Draw::new(nodes, sizes, spread, seed);
    let mut messages = Vec::new();
    for _ in 0..rounds {
        let mut dst: Vec<u32> = (0..nodes).collect();
        dst.shuffle(&mut draw.rng);
        // Rotating the fixed points among themselves leaves a permutation without any.
        let fixed: Vec<usize> = (0..nodes as usize)
            .filter(|&i| dst[i] == i as u32)
            .collect();
        match fixed.len() {
            0 => {}
            1 => dst.swap(fixed[0], (fixed[0] + 1) % nodes as usize),
            n => {
                for k in 0..n {
                    dst[fixed[k]] = fixed[(k + 1) % n] as u32;
                }
            }
        }
        for (src, &d) in dst.iter().enumerate() {
            let (bytes, start) = draw.size_and_start();
            messages.push(PatternMessage::new(src as u32, d, bytes, start));
        }
    }
    Pattern::new(messages)
}

/// `count` messages between random distinct nodes, each of a size drawn from `sizes`, with
/// start instants drawn uniformly from `[0, spread)` (whole nanoseconds), all from one
/// ChaCha8 stream seeded by `seed`: traffic that keeps flows starting and ending while others
/// run. Panics if `nodes < 2` or `sizes` is empty.
pub fn random_staggered(
    nodes: u32,
    count: usize,
    sizes: &[Bytes],
    spread: SimTime,
    seed: u64,
) -> Pattern {
    use rand::Rng;
    let mut draw = Draw::new(nodes, sizes, spread, seed);
    let messages = (0..count)
        .map(|_| {
            let src = draw.rng.gen_range(0..nodes);
            let other = draw.rng.gen_range(0..nodes - 1);
            let dst = if other >= src { other + 1 } else { other };
            let (bytes, start) = draw.size_and_start();
            PatternMessage::new(src, dst, bytes, start)
        })
        .collect();
    Pattern::new(messages)
}

/// The random stream of the staggered generators and what they draw from it.
struct Draw<'a> {
    rng: ChaCha8Rng,
    sizes: &'a [Bytes],
    spread_ns: u64,
}

impl<'a> Draw<'a> {
    /// Panics if `nodes < 2` or `sizes` is empty.
    fn new(nodes: u32, sizes: &'a [Bytes], spread: SimTime, seed: u64) -> Draw<'a> {
        assert!(
            nodes >= 2 && !sizes.is_empty(),
            "staggered patterns need 2 nodes and a size"
        );
        Draw {
            rng: ChaCha8Rng::seed_from_u64(seed),
            sizes,
            spread_ns: (spread.ps() / 1000).max(1),
        }
    }

    /// A size from the list, then a start in `[0, spread)` whole nanoseconds.
    fn size_and_start(&mut self) -> (Bytes, SimTime) {
        use rand::Rng;
        let bytes = self.sizes[self.rng.gen_range(0..self.sizes.len())];
        let start = SimTime::from_ns(self.rng.gen_range(0..self.spread_ns));
        (bytes, start)
    }
}

fn zero_time() -> String {
    "0ps".to_string()
}

fn is_false(b: &bool) -> bool {
    !*b
}

fn parse_message(net: &Network, i: usize, m: &PatternMessage) -> Result<ParsedMessage, NetError> {
    let field = |name: &str, why: String| NetError::Pattern(format!("messages[{i}].{name}: {why}"));
    let last = net.nodes() - 1;
    if m.src > last {
        return Err(field(
            "src",
            format!("node {} does not exist; valid nodes are 0..={last}", m.src),
        ));
    }
    let dest = match (m.dst, m.broadcast) {
        (Some(_), true) => {
            return Err(field(
                "dst",
                "give either dst or broadcast: true, not both".to_string(),
            ))
        }
        (None, false) => {
            return Err(field(
                "dst",
                format!("missing; give a node 0..={last}, or broadcast: true on a bus"),
            ))
        }
        (None, true) if !net.supports_broadcast() => {
            return Err(field(
                "broadcast",
                "broadcast needs a bus topology; send to each node instead".to_string(),
            ))
        }
        (None, true) => Dest::Broadcast,
        (Some(d), false) if d > last => {
            return Err(field(
                "dst",
                format!("node {d} does not exist; valid nodes are 0..={last}"),
            ))
        }
        (Some(d), false) if !net.can_route(m.src, d) => {
            return Err(field(
                "dst",
                format!(
                    "no route from node {} to node {d}: a pipeline only sends to nodes {}..={last}",
                    m.src, m.src
                ),
            ))
        }
        (Some(d), false) => Dest::Node(d),
    };
    let bytes = m
        .bytes
        .parse::<Bytes>()
        .map_err(|e| field("bytes", e.to_string()))?;
    let start = m
        .start
        .parse::<SimTime>()
        .map_err(|e| field("start", e.to_string()))?;
    Ok(ParsedMessage {
        src: m.src,
        dest,
        bytes,
        start,
    })
}

fn report(
    cfg: &NetworkConfig,
    net: &Network,
    parsed: &[ParsedMessage],
    completions: &[SimTime],
) -> PatternReport {
    let messages: Vec<MessageReport> = parsed
        .iter()
        .zip(completions)
        .map(|(m, &done)| MessageReport {
            src: m.src,
            dst: match m.dest {
                Dest::Node(d) => Some(d),
                Dest::Broadcast => None,
            },
            bytes: m.bytes.get(),
            start_ps: m.start.ps(),
            completion_ps: done.ps(),
            completion_s: done.as_secs_f64(),
            latency_ps: (done - m.start).ps(),
        })
        .collect();
    let first_start = parsed
        .iter()
        .map(|m| m.start)
        .min()
        .unwrap_or(SimTime::ZERO);
    let last_done = completions.iter().copied().max().unwrap_or(SimTime::ZERO);
    let makespan = last_done.saturating_sub(first_start);
    let total: u128 = messages.iter().map(|m| m.latency_ps as u128).sum();
    let mean = SimTime::from_ps((total / messages.len().max(1) as u128) as u64);
    let links = net
        .link_stats()
        .into_iter()
        .enumerate()
        .map(|(i, s)| LinkReport {
            link: i as u32,
            name: s.name,
            from: s.from,
            to: s.to,
            bytes: s.bytes.get(),
            messages: s.messages,
            busy_ps: s.busy.ps(),
            busy_s: s.busy.as_secs_f64(),
            peak_queue: s.peak_queue,
        })
        .collect();
    PatternReport {
        topology: cfg.topology.name(),
        fidelity: cfg.fidelity.name(),
        switching: cfg.switching.name(),
        nodes: net.nodes(),
        makespan_ps: makespan.ps(),
        makespan_s: makespan.as_secs_f64(),
        mean_latency_ps: mean.ps(),
        mean_latency_s: mean.as_secs_f64(),
        messages,
        links,
    }
}
