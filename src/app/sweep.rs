//! `sortsim sweep`: every point of a sweep spec, one shard of it, the collection of shards, or
//! the Slurm scripts that run them.

use std::path::Path;

use super::cli::SweepArgs;
use super::{jobs, out_dir, Context, Failure};
use crate::sweep::table::Row;

/// `sortsim sweep`: runs the points (all, or one shard's), or collects the shards' points, or
/// writes and submits Slurm scripts; prints the table and any failed point; returns the table
/// as printed. Bad input is refused before any point runs; a point that fails is a row with an
/// error.
pub(super) fn run(ctx: &Context, args: &SweepArgs) -> Result<Vec<Row>, Failure> {
    use crate::sweep::{collect, run_shard, run_sweep, spec::load_sweep, SweepOptions};
    let spec = load_sweep(&ctx.input(&args.spec))?;
    let out = out_dir(&args.out, &args.spec, "reports/sweep-");
    if args.slurm {
        return slurm(args, &spec, &out).map(|()| Vec::new());
    }
    // A folder that cannot be written is found before the first point is simulated.
    if out.exists() && !out.is_dir() {
        return Err(Failure::BadInput(format!(
            "{}: cannot write the sweep there: it is a file, not a folder",
            out.display()
        )));
    }
    let jobs = jobs(args.jobs);
    let options = SweepOptions {
        jobs,
        progress: true,
    };
    if let Some(shard) = args.shard {
        let outcome = run_shard(&spec, &out, shard, options).map_err(sweep_failure)?;
        print!(
            "{}",
            crate::report::sweep::shard_lines(&outcome, &out, jobs)
        );
        return internal_point(&outcome.failures).map(|()| Vec::new());
    }
    let outcome = if args.collect {
        collect(&spec, &out)
    } else {
        run_sweep(&spec, &out, options)
    }
    .map_err(sweep_failure)?;
    let table = crate::sweep::table::format_rows(&outcome.rows);
    print!("{table}");
    print!(
        "{}",
        crate::report::sweep::closing_lines(&outcome, &out, jobs)
    );
    internal_point(&outcome.failures).map(|()| outcome.rows)
}

fn sweep_failure(e: crate::sweep::SweepError) -> Failure {
    use crate::sweep::SweepError;
    match e {
        SweepError::Spec(_)
        | SweepError::BadSummary { .. }
        | SweepError::Write { .. }
        | SweepError::Slurm(_)
        | SweepError::Missing { .. } => Failure::BadInput(e.to_string()),
        SweepError::Plot(_) | SweepError::Pool { .. } => Failure::Internal(e.to_string()),
    }
}

/// A point that failed through a simulator bug makes the command fail (exit 1).
fn internal_point(failures: &[crate::sweep::PointFailure]) -> Result<(), Failure> {
    match failures
        .iter()
        .find(|f| f.kind == crate::sweep::FailureKind::Internal)
    {
        Some(f) => Err(Failure::Internal(format!(
            "point {}: {}",
            f.point, f.message
        ))),
        None => Ok(()),
    }
}

/// `sortsim sweep --slurm`: checks every point, writes the scripts, and with `--submit` hands
/// them to sbatch.
fn slurm(args: &SweepArgs, spec: &crate::sweep::spec::Sweep, out: &Path) -> Result<(), Failure> {
    use crate::sweep::slurm::{find_sbatch, submit, write_scripts, SlurmOptions};
    if args.submit && find_sbatch().is_none() {
        return Err(Failure::BadInput(
            crate::sweep::slurm::SubmitError::NoSbatch.to_string(),
        ));
    }
    let exe = std::env::current_exe()
        .map_err(|e| Failure::Internal(format!("cannot find the sortsim binary: {e}")))?;
    let options = SlurmOptions {
        tasks: args
            .tasks
            .unwrap_or_else(|| spec.points.len().clamp(1, 32) as u32),
        partition: args.partition.clone(),
        time: args.time.clone(),
        mem: args.mem.clone(),
        jobs: args.jobs.unwrap_or(1),
    };
    let scripts = write_scripts(spec, out, &exe, &options).map_err(sweep_failure)?;
    let submitted = if args.submit {
        Some(submit(&scripts).map_err(|e| Failure::BadInput(e.to_string()))?)
    } else {
        None
    };
    print!(
        "{}",
        crate::report::sweep::slurm_lines(&scripts, options.tasks, submitted.as_ref())
    );
    Ok(())
}
