//! The main job on the built-in default (`sortsim` with no command).

use std::path::{Path, PathBuf};

use super::cli::{PholdArgs, SweepArgs};
use super::{Context, Failure};
use crate::net::fidelity::{fidelity_table, format_table};
use crate::net::pattern::Pattern;
use crate::spec::{load_json, machine::load_machine};
use crate::sweep::table::Row;

/// The main job on the built-in default: validate the bundled machines, run the default sweep
/// (sweeps/default.json: both sort-middle algorithms on the Delta, 1 to 64 processors) with
/// its table and plots, run PHOLD on the engine against its baseline, and show what network
/// fidelity costs on the Delta; the report goes to reports/default/.
pub(super) fn run(ctx: &Context) -> Result<(), Failure> {
    let machines = ctx.root.join("machines");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&machines)
        .map_err(|e| Failure::Internal(format!("{}: {e}", machines.display())))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .collect();
    files.sort();
    super::check::run(ctx, &files)?;
    let out = PathBuf::from("reports/default");
    let sweep_rows = default_sweep(ctx, &out)?;
    println!("\nPHOLD on the engine against a bare binary-heap loop:");
    let phold = super::bench::bench_phold(&PholdArgs {
        lps: 1024,
        events_per_lp: 16,
        remote: 0.9,
        mean: crate::units::SimTime::from_us(1),
        lookahead: crate::units::SimTime::from_ns(100),
        end: crate::units::SimTime::from_us(500),
        seed: 1,
        out: Some(out.join("phold")),
        instructions: false,
    })?;
    println!(
        "\nThe Delta's 16x32 mesh, every node sends 64 KiB to its mirror node (bit complement):"
    );
    let delta = load_machine(&machines.join("delta.json"))?;
    let pattern: Pattern = load_json(&ctx.root.join("tests/patterns/complement-16x32.json"))?;
    let rows =
        fidelity_table(&delta.network, &pattern).map_err(|e| Failure::Internal(e.to_string()))?;
    let table = format_table(&rows);
    print!("{table}");
    crate::report::default_job::write_page(
        &out,
        &crate::report::default_job::DefaultJob {
            machines: &files,
            sweep_rows: &sweep_rows,
            phold: &phold,
            fidelity_rows: &rows,
            fidelity: &table,
        },
    )?;
    print!("\n{}", crate::output::closing_line(&out, ""));
    Ok(())
}

/// The default sweep, always simulated afresh (its points folder is cleared first, so a
/// changed simulator or machine never shows an old result), and its table printed.
fn default_sweep(ctx: &Context, out: &Path) -> Result<Vec<Row>, Failure> {
    let spec = ctx.root.join("sweeps/default.json");
    println!("\nThe default sweep ({}):", spec.display());
    match std::fs::remove_dir_all(out.join("points")) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
            return Err(Failure::BadInput(format!(
                "{}: cannot clear: {e}",
                out.join("points").display()
            )))
        }
        _ => {}
    }
    super::sweep::run(
        ctx,
        &SweepArgs {
            spec,
            out: Some(out.to_path_buf()),
            jobs: None,
            shard: None,
            collect: false,
            slurm: false,
            tasks: None,
            partition: None,
            time: None,
            mem: None,
            submit: false,
        },
    )
}
