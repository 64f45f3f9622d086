//! Instruction counts of one stretch of a benchmark, for the comparisons a shared machine's
//! noise hides (its wall times move 15 to 40% from run to run; an instruction count does not
//! move at all): this binary runs the same benchmark again under valgrind's callgrind, with
//! collection on only from the entry of one function to its return, and the count is
//! callgrind's total.
//!
//! Owns finding valgrind, running it and reading the count. Must never run a workload in its
//! own process, nor count outside the function it names: each [`Stretch`]'s function is
//! `#[inline(never)]`, so that it keeps a symbol to toggle on.
//!
//! An instruction count leaves out what a cache miss costs, so it is the noise-free side of a
//! comparison, not a replacement for the wall time.

use std::path::Path;
use std::process::{Command, Stdio};

use serde::Serialize;

/// A function whose instructions can be counted, everything it calls included.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stretch {
    /// [`super::phold_engine`]: PHOLD on the engine.
    PholdEngine,
    /// [`super::phold_baseline`]: the bare binary-heap loop.
    PholdBaseline,
    /// [`super::floor::phold_floor`]: the floor of the engine's design.
    PholdFloor,
    /// [`super::simulate_frame`]: one frame simulated (`bench overhead`).
    Simulate,
    /// [`super::render_frame`]: the same frame drawn sequentially.
    Render,
}

impl Stretch {
    /// The function's name as callgrind shows it (demangled, without the hash).
    fn symbol(self) -> &'static str {
        match self {
            Stretch::PholdEngine => "sortsim::bench::phold_engine",
            Stretch::PholdBaseline => "sortsim::bench::phold_baseline",
            Stretch::PholdFloor => "sortsim::bench::floor::phold_floor",
            Stretch::Simulate => "sortsim::bench::simulate_frame",
            Stretch::Render => "sortsim::bench::render_frame",
        }
    }
}

/// The instructions of a measured stretch and of its baseline, from the same command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Counts {
    pub measured: u64,
    pub baseline: u64,
}

impl Counts {
    /// PHOLD's two loops on `cfg`: the engine (measured) and the bare heap (baseline).
    pub fn phold(cfg: &super::PholdConfig) -> Result<Counts, String> {
        Counts::of(
            &cfg.command_line(),
            Stretch::PholdEngine,
            Stretch::PholdBaseline,
        )
    }

    /// The frame of a `bench overhead` command line (see [`super::overhead_command_line`]):
    /// simulated (measured) and drawn sequentially (baseline).
    pub fn frame(command_line: &[String]) -> Result<Counts, String> {
        Counts::of(command_line, Stretch::Simulate, Stretch::Render)
    }

    /// Counts both stretches of `args` (a `sortsim` command line without the program name).
    fn of(args: &[String], measured: Stretch, baseline: Stretch) -> Result<Counts, String> {
        Ok(Counts {
            measured: count(args, measured)?,
            baseline: count(args, baseline)?,
        })
    }

    /// Measured over baseline: how many times the baseline's instructions the stretch took.
    pub fn ratio(&self) -> f64 {
        self.measured as f64 / self.baseline.max(1) as f64
    }

    /// Baseline over measured: the share of the stretch's instructions that the baseline's
    /// would be (an event-rate ratio's counterpart).
    pub fn baseline_over_measured(&self) -> f64 {
        self.baseline as f64 / self.measured.max(1) as f64
    }
}

/// Why a count needs valgrind, in the words every command that offers one uses.
pub fn needs_valgrind() -> String {
    "--instructions counts instructions under valgrind's callgrind, and valgrind is not on the \
     PATH: install it (Debian: apt-get install valgrind) or leave out --instructions"
        .into()
}

/// Whether a count can be made here.
pub fn available() -> bool {
    crate::host::on_path("valgrind").is_some()
}

/// Instructions `stretch` executes when this binary runs `args`.
pub fn count(args: &[String], stretch: Stretch) -> Result<u64, String> {
    let valgrind = crate::host::on_path("valgrind").ok_or_else(needs_valgrind)?;
    let exe = std::env::current_exe().map_err(|e| format!("cannot find this binary: {e}"))?;
    let folder = tempfile::tempdir().map_err(|e| format!("a temporary folder: {e}"))?;
    let out_file = folder.path().join("callgrind.out");
    let run = Command::new(&valgrind)
        .arg("--tool=callgrind")
        .arg(format!("--callgrind-out-file={}", out_file.display()))
        .arg(format!("--toggle-collect={}", stretch.symbol()))
        .arg(&exe)
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .output()
        .map_err(|e| format!("{}: {e}", valgrind.display()))?;
    if !run.status.success() {
        let stderr = String::from_utf8_lossy(&run.stderr);
        let tail: Vec<&str> = stderr.lines().rev().take(8).collect();
        return Err(format!(
            "valgrind --tool=callgrind {} {} failed ({}):\n{}",
            exe.display(),
            args.join(" "),
            run.status,
            tail.into_iter().rev().collect::<Vec<_>>().join("\n")
        ));
    }
    let total = totals(&out_file)?;
    if total == 0 {
        // A name that no longer matches a symbol (renamed or inlined) counts nothing.
        return Err(format!(
            "callgrind counted no instruction in {}: the function is not in this binary \
             under that name",
            stretch.symbol()
        ));
    }
    Ok(total)
}

/// The `totals:` line of a callgrind output file (its first event, instructions).
fn totals(file: &Path) -> Result<u64, String> {
    let text = std::fs::read_to_string(file)
        .map_err(|e| format!("callgrind's output {}: {e}", file.display()))?;
    text.lines()
        .find_map(|line| line.strip_prefix("totals:"))
        .and_then(|rest| rest.split_whitespace().next())
        .and_then(|n| n.parse().ok())
        .ok_or_else(|| format!("{} has no totals line", file.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_the_first_event_of_the_totals_line() {
        let folder = tempfile::tempdir().unwrap();
        let file = folder.path().join("callgrind.out");
        std::fs::write(
            &file,
            "version: 1\nevents: Ir Dr\nfn=(1) main\n3 5 2\nsummary: 5 2\ntotals: 5 2\n",
        )
        .unwrap();
        assert_eq!(totals(&file), Ok(5));
        std::fs::write(&file, "version: 1\nevents: Ir\n").unwrap();
        assert!(totals(&file).unwrap_err().contains("no totals line"));
    }
}
