//! cost.json: what a simulation cost the host: wall time, events processed, events per
//! second, peak resident memory. The other half of "accuracy costs time".
//!
//! The only place besides `bench` that reads the wall clock; never feeds back into a result.

use std::time::Instant;

use serde::Serialize;

#[derive(Serialize, Debug, Clone)]
pub struct Cost {
    pub wall_s: f64,
    pub events: u64,
    pub events_per_s: f64,
    /// Peak resident set of this process so far (Linux VmHWM), if the platform tells.
    pub peak_host_memory_bytes: Option<u64>,
}

/// Measures wall time from its creation.
pub struct Stopwatch(Instant);

impl Stopwatch {
    pub fn start() -> Stopwatch {
        Stopwatch(Instant::now())
    }

    pub fn cost(&self, events: u64) -> Cost {
        let wall = self.0.elapsed().as_secs_f64();
        Cost {
            wall_s: wall,
            events,
            events_per_s: ratio_or_zero(events as f64, wall),
            peak_host_memory_bytes: peak_host_memory(),
        }
    }
}

/// `of / to`, or 0 when `to` is 0 (nothing was measured): events over wall seconds, or one
/// event rate over another.
pub fn ratio_or_zero(of: f64, to: f64) -> f64 {
    if to > 0.0 {
        of / to
    } else {
        0.0
    }
}

/// VmHWM from /proc/self/status, in bytes.
pub fn peak_host_memory() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}
