//! The lines `sortsim sweep` prints after its table: where the points and report went, what
//! failed, and the Slurm scripts and job ids.
//!
//! Must never compute a row (that is `sweep::table`) nor write a sweep's files (that is
//! `sweep`, which writes its table, plots and page).

use std::path::Path;

use crate::sweep::slurm::{Scripts, Submitted};
use crate::sweep::{ShardOutcome, SweepOutcome};

/// What `sortsim sweep --shard I/T` prints: the shard's points run and skipped, and each
/// failed point.
pub fn shard_lines(outcome: &ShardOutcome, out: &Path, jobs: usize) -> String {
    let mut text = format!(
        "shard {}: {} points ({} simulated now, {} already done) in {:.1} s on {jobs} threads, under {}\n",
        outcome.shard,
        outcome.points,
        outcome.ran,
        outcome.points - outcome.ran,
        outcome.cost.wall_s,
        out.join("points").display()
    );
    for f in &outcome.failures {
        text += &format!("point {} failed: {}\n", f.point, f.message);
    }
    text
}

/// What `sortsim sweep --slurm` prints: the scripts, and the job ids or how to submit.
pub fn slurm_lines(scripts: &Scripts, tasks: u32, submitted: Option<&Submitted>) -> String {
    let mut text = format!(
        "wrote {} ({tasks} array tasks), {} and {}\n",
        scripts.sweep.display(),
        scripts.collect.display(),
        scripts.plan.display()
    );
    match submitted {
        Some(s) => {
            text += &format!(
                "submitted: array job {}, collect job {} (runs after every task succeeds); logs in {}\n",
                s.array,
                s.collect,
                scripts.logs.display()
            );
        }
        None => {
            text += &format!(
                "submit with:\n  id=$(sbatch --parsable {})\n  sbatch --dependency=afterok:$id {}\n",
                scripts.sweep.display(),
                scripts.collect.display()
            );
        }
    }
    text
}

/// What `sortsim sweep` prints after its table: points run and skipped, wall time, each failed
/// point, and where the report went.
pub fn closing_lines(outcome: &SweepOutcome, out: &Path, jobs: usize) -> String {
    let threads = if outcome.ran > 0 {
        format!(" on {}", crate::units::count(jobs as u64, "thread"))
    } else {
        String::new()
    };
    let mut text = format!(
        "{} points ({} simulated now, {} already done) in {:.1} s{threads}\n",
        outcome.ran + outcome.skipped,
        outcome.ran,
        outcome.skipped,
        outcome.cost.wall_s
    );
    for f in &outcome.failures {
        text += &format!("point {} failed: {}\n", f.point, f.message);
    }
    text += &format!(
        "report written to {} (sweep.csv, sweep.json, plots/); page: {}\n",
        out.display(),
        out.join("index.html").display()
    );
    text
}
