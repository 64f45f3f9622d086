//! The price of accuracy: one pattern at every fidelity level, predicted times next to the
//! simulator's own wall time (DESIGN.md principle 4).
//!
//! Owns [`fidelity_table`] and its text rendering. Wall time is the only non-deterministic
//! number here; it must never feed back into a simulated time.

use std::time::{Duration, Instant};

use super::pattern::{drive, parse_pattern, Pattern};
use super::{Fidelity, NetError, Network, NetworkConfig};
use crate::units::SimTime;

/// One level's prediction for a pattern and what it cost to compute.
#[derive(Clone, Debug)]
pub struct FidelityRow {
    pub fidelity: Fidelity,
    /// Last completion minus first start.
    pub makespan: SimTime,
    /// Mean over messages of (completion - start), floored to a picosecond.
    pub mean_completion: SimTime,
    pub messages: usize,
    /// Wall time of building the network and driving the pattern (not of parsing it).
    pub wall: Duration,
}

/// The levels of [`Fidelity::ALL`] that cannot model `cfg`'s network (`packet` on a network
/// with node links of their own rate), each with the reason.
pub fn levels_refused(cfg: &NetworkConfig) -> Vec<(Fidelity, NetError)> {
    Fidelity::ALL
        .iter()
        .filter_map(|&fidelity| {
            Network::new(&NetworkConfig {
                fidelity,
                ..cfg.clone()
            })
            .err()
            .map(|e| (fidelity, e))
        })
        .collect()
}

/// Runs `pattern` at every level of [`Fidelity::ALL`] on `cfg` (its own fidelity ignored),
/// leaving out the [`levels_refused`].
pub fn fidelity_table(
    cfg: &NetworkConfig,
    pattern: &Pattern,
) -> Result<Vec<FidelityRow>, NetError> {
    let parsed = parse_pattern(&Network::new(cfg)?, pattern)?;
    let first_start = parsed
        .iter()
        .map(|m| m.start)
        .min()
        .unwrap_or(SimTime::ZERO);
    let refused = levels_refused(cfg);
    Fidelity::ALL
        .iter()
        .filter(|&&f| refused.iter().all(|(r, _)| *r != f))
        .map(|&fidelity| {
            let cfg = NetworkConfig {
                fidelity,
                ..cfg.clone()
            };
            let clock = Instant::now();
            let mut net = Network::new(&cfg)?;
            let done = drive(&mut net, &parsed);
            let wall = clock.elapsed();
            let last = done.iter().copied().max().unwrap_or(SimTime::ZERO);
            let total: u128 = done
                .iter()
                .zip(&parsed)
                .map(|(&d, m)| (d - m.start).ps() as u128)
                .sum();
            Ok(FidelityRow {
                fidelity,
                makespan: last.saturating_sub(first_start),
                mean_completion: SimTime::from_ps((total / done.len().max(1) as u128) as u64),
                messages: done.len(),
                wall,
            })
        })
        .collect()
}

/// A plain-text table: level, makespan, mean completion, wall time, messages per second.
pub fn format_table(rows: &[FidelityRow]) -> String {
    let mut out = format!(
        "{:<8} {:>16} {:>18} {:>12} {:>14}\n",
        "fidelity", "makespan_us", "mean_completion_us", "wall_ms", "messages/s"
    );
    for r in rows {
        let wall_s = r.wall.as_secs_f64();
        let rate = if wall_s > 0.0 {
            r.messages as f64 / wall_s
        } else {
            f64::INFINITY
        };
        out += &format!(
            "{:<8} {:>16.3} {:>18.3} {:>12.3} {:>14.0}\n",
            r.fidelity.name(),
            r.makespan.as_us_f64(),
            r.mean_completion.as_us_f64(),
            wall_s * 1e3,
            rate
        );
    }
    out
}
