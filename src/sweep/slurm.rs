//! A sweep handed to Slurm (`sortsim sweep SPEC -o DIR --slurm`): an array job whose task I
//! runs `sortsim sweep SPEC -o DIR --shard I/T`, and a collect job that runs `--collect` once
//! every task has succeeded. Slurm schedules; sortsim only deals points and writes scripts.
//!
//! DIR, SPEC (with the machines and scenes it names) and the folder the command runs in must
//! be on a filesystem every node sees at the same path: the tasks start in that folder and
//! name SPEC and DIR as they were given.
//!
//! Owns the scripts and their submission. Must never run a point (the tasks do that through
//! the same `run_shard` a person can call), and never write a script before every point of
//! the sweep has been checked.

use std::path::{Path, PathBuf};
use std::process::Command;

use super::shard::ShardPlan;
use super::spec::Sweep;
use super::{deal, write, SweepError};
use crate::output::to_json;

/// How the array job asks Slurm for resources.
#[derive(Debug, Clone, Default)]
pub struct SlurmOptions {
    /// Array tasks (shards).
    pub tasks: u32,
    pub partition: Option<String>,
    /// Wall-clock limit per task, as Slurm writes it (`HH:MM:SS`, `D-HH:MM:SS`, minutes).
    pub time: Option<String>,
    /// Memory per task, as Slurm writes it (`4G`, `500M`).
    pub mem: Option<String>,
    /// Simulations at a time in each task (its `--cpus-per-task`).
    pub jobs: u32,
}

/// The files `--slurm` wrote.
#[derive(Debug, Clone)]
pub struct Scripts {
    pub sweep: PathBuf,
    pub collect: PathBuf,
    pub plan: PathBuf,
    pub logs: PathBuf,
}

/// `DIR/slurm/sweep.sbatch`.
pub fn sweep_script(out: &Path) -> PathBuf {
    out.join("slurm").join("sweep.sbatch")
}

/// Deals the points of `sweep` to `options.tasks` shards and writes the array script, the
/// collect script and the shard plan under `out/slurm`. `exe` is the sortsim the tasks run.
pub fn write_scripts(
    sweep: &Sweep,
    out: &Path,
    exe: &Path,
    options: &SlurmOptions,
) -> Result<Scripts, SweepError> {
    let plan = ShardPlan::new(&deal(sweep, options.tasks)?, options.tasks);
    let absolute = |p: &Path, what: &str| {
        std::path::absolute(p).map_err(|e| SweepError::Write {
            path: p.to_path_buf(),
            source: std::io::Error::new(e.kind(), format!("{what}: {e}")),
        })
    };
    // The tasks run where the sweep was written from and name the spec and the folder as they
    // were given: a point's summary.json records its scene path as resolved from the spec's,
    // so the same words give the same bytes as a local run.
    let (cwd, dir, exe) = (
        absolute(Path::new("."), "the working folder")?,
        absolute(out, "the report folder")?,
        absolute(exe, "sortsim")?,
    );
    check_dir(&cwd).map_err(SweepError::Slurm)?;
    let logs = dir.join("slurm").join("logs");
    std::fs::create_dir_all(&logs).map_err(|source| SweepError::Write {
        path: logs.clone(),
        source,
    })?;
    let name = sweep
        .file
        .file_stem()
        .map_or("sweep".into(), |s| s.to_string_lossy().into_owned());
    let run = |args: &str| {
        format!(
            "exec {} sweep {} -o {} {args}\n",
            quote(&exe),
            quote(&sweep.file),
            quote(out)
        )
    };
    let header = |job: &str, log: &str| {
        format!(
            "#!/bin/bash\n# Written by `sortsim sweep --slurm`; submit with `sbatch`, or let `--submit` do it.\n#SBATCH --job-name={job}\n#SBATCH --chdir={}\n#SBATCH --output={}\n",
            cwd.display(),
            logs.join(log).display()
        )
    };
    let mut array = header(&format!("sortsim-{name}"), "shard-%a.out");
    array += &format!("#SBATCH --array=0-{}\n", options.tasks - 1);
    array += &format!("#SBATCH --cpus-per-task={}\n", options.jobs);
    for (flag, value) in [
        ("partition", &options.partition),
        ("time", &options.time),
        ("mem", &options.mem),
    ] {
        if let Some(v) = value {
            array += &format!("#SBATCH --{flag}={v}\n");
        }
    }
    array += "set -euo pipefail\n";
    array += &run(&format!(
        "--shard \"${{SLURM_ARRAY_TASK_ID}}/{}\" --jobs {}",
        options.tasks, options.jobs
    ));
    let mut collect = header(&format!("sortsim-{name}-collect"), "collect.out");
    if let Some(p) = &options.partition {
        collect += &format!("#SBATCH --partition={p}\n");
    }
    collect += "set -euo pipefail\n";
    collect += &run("--collect");
    let scripts = Scripts {
        sweep: sweep_script(&dir),
        collect: dir.join("slurm").join("collect.sbatch"),
        plan: ShardPlan::path(&dir),
        logs,
    };
    write(&scripts.plan, to_json(&plan).as_bytes())?;
    write(&scripts.collect, collect.as_bytes())?;
    write(&scripts.sweep, array.as_bytes())?;
    Ok(scripts)
}

/// `path` in single quotes for bash.
fn quote(path: &Path) -> String {
    format!("'{}'", path.display().to_string().replace('\'', r"'\''"))
}

/// Why a submission failed.
#[derive(Debug, thiserror::Error)]
pub enum SubmitError {
    #[error("--submit: `sbatch` is not on the PATH; install Slurm's client (Debian: slurm-client), or leave out --submit and submit the scripts yourself")]
    NoSbatch,
    #[error("sbatch {}: {message}", script.display())]
    Sbatch { script: PathBuf, message: String },
}

/// Job ids of a submitted sweep.
#[derive(Debug, Clone)]
pub struct Submitted {
    pub array: String,
    pub collect: String,
}

/// `sbatch` on the PATH, if there is one.
pub fn find_sbatch() -> Option<PathBuf> {
    crate::host::on_path("sbatch")
}

/// Submits the array job, then the collect job with `afterok` on the whole array.
pub fn submit(scripts: &Scripts) -> Result<Submitted, SubmitError> {
    let sbatch = find_sbatch().ok_or(SubmitError::NoSbatch)?;
    let array = sbatch_run(&sbatch, &[], &scripts.sweep)?;
    let dependency = format!("--dependency=afterok:{array}");
    let collect = sbatch_run(&sbatch, &[&dependency], &scripts.collect)?;
    Ok(Submitted { array, collect })
}

/// Runs `sbatch --parsable ARGS SCRIPT`; returns the job id.
fn sbatch_run(sbatch: &Path, args: &[&str], script: &Path) -> Result<String, SubmitError> {
    let failed = |message: String| SubmitError::Sbatch {
        script: script.to_path_buf(),
        message,
    };
    let out = Command::new(sbatch)
        .arg("--parsable")
        .args(args)
        .arg(script)
        .output()
        .map_err(|e| failed(e.to_string()))?;
    if !out.status.success() {
        return Err(failed(
            String::from_utf8_lossy(&out.stderr).trim().to_string(),
        ));
    }
    // `--parsable` prints "id" or "id;cluster".
    let text = String::from_utf8_lossy(&out.stdout);
    let id = text
        .trim()
        .split(';')
        .next()
        .unwrap_or_default()
        .to_string();
    if id.is_empty() || !id.bytes().all(|b| b.is_ascii_digit()) {
        return Err(failed(format!("unexpected output {:?}", text.trim())));
    }
    Ok(id)
}

/// Checks a value meant for an `#SBATCH` line: letters, digits and `-:._` only, so that it
/// cannot break the script. Returns what is wrong.
pub fn check_value(flag: &str, value: &str, example: &str) -> Result<String, String> {
    if !value.is_empty()
        && value
            .bytes()
            .all(|b| b.is_ascii_alphanumeric() || b"-:._".contains(&b))
    {
        Ok(value.to_string())
    } else {
        Err(format!(
            "{flag} {value:?}: expected a Slurm value of letters, digits and - : . _ (e.g. {example})"
        ))
    }
}

/// A Slurm time limit: minutes, minutes:seconds, hours:minutes:seconds, days-hours,
/// days-hours:minutes or days-hours:minutes:seconds (whole numbers), or UNLIMITED.
pub fn check_time(value: &str) -> Result<String, String> {
    let fail = || {
        format!(
            "--time {value:?}: expected a Slurm time limit: minutes (30), minutes:seconds, \
             hours:minutes:seconds (1:30:00), days-hours (2-12), days-hours:minutes or \
             days-hours:minutes:seconds, or UNLIMITED"
        )
    };
    if value.eq_ignore_ascii_case("unlimited") || value.eq_ignore_ascii_case("infinite") {
        return Ok(value.to_string());
    }
    let number = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    let (days, clock) = match value.split_once('-') {
        Some((d, rest)) => (Some(d), rest),
        None => (None, value),
    };
    let parts: Vec<&str> = clock.split(':').collect();
    let fits = match days {
        Some(d) => number(d) && (1..=3).contains(&parts.len()),
        None => (1..=3).contains(&parts.len()),
    };
    if fits && parts.iter().all(|p| number(p)) && days.is_none_or(number) {
        Ok(value.to_string())
    } else {
        Err(fail())
    }
}

/// A Slurm memory size: a whole number with an optional unit K, M, G or T (megabytes when
/// absent), above zero.
pub fn check_mem(value: &str) -> Result<String, String> {
    let digits = value.trim_end_matches(['K', 'M', 'G', 'T', 'k', 'm', 'g', 't']);
    let unit_len = value.len() - digits.len();
    let ok = unit_len <= 1
        && !digits.is_empty()
        && digits.bytes().all(|b| b.is_ascii_digit())
        && digits.bytes().any(|b| b != b'0');
    if ok {
        Ok(value.to_string())
    } else {
        Err(format!(
            "--mem {value:?}: expected a Slurm memory size: a whole number above 0 with an \
             optional unit K, M, G or T (4G, 500M; megabytes when absent)"
        ))
    }
}

/// Checks that `dir` (absolute) can be named in an `#SBATCH` line (Slurm does not unquote).
fn check_dir(dir: &Path) -> Result<(), String> {
    let text = dir.display().to_string();
    if text.chars().any(|c| c.is_whitespace() || c == '%') {
        return Err(format!(
            "{text}: with --slurm, the report folder and the working folder must have no spaces or % in their paths (#SBATCH lines cannot quote them)"
        ));
    }
    Ok(())
}

#[cfg(test)]
mod value_tests {
    use super::*;

    #[test]
    fn slurm_times_and_sizes() {
        for ok in [
            "30",
            "30:00",
            "1:30:00",
            "2-12",
            "2-12:30",
            "2-00:00:00",
            "UNLIMITED",
        ] {
            assert!(check_time(ok).is_ok(), "{ok}");
        }
        for bad in [
            "abc",
            "",
            "1:2:3:4",
            "-5",
            "1-",
            "1h",
            "2-1:2:3:4",
            "1:30:",
            "lots",
        ] {
            assert!(check_time(bad).is_err(), "{bad}");
        }
        for ok in ["4G", "500M", "4000", "1T", "64k"] {
            assert!(check_mem(ok).is_ok(), "{ok}");
        }
        for bad in ["lots", "", "G", "0", "0G", "4GB", "1.5G", "-4G"] {
            assert!(check_mem(bad).is_err(), "{bad}");
        }
    }
}
