//! Sweeps on a cluster: `sortsim sweep --slurm --submit` on a real one-node Slurm cluster
//! (started by the test through scripts/slurm-test-cluster.sh) gives, after the collect job,
//! exactly the report a local sweep writes; a resubmission after one shard's output is lost
//! redoes only that shard's points. Also `--shard` and `--collect` by hand, and what they
//! refuse (the flags' own bad values are in tests/bad_input.rs).

use crate::common;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

use common::SlurmCluster;
use sortsim::sweep::shard::ShardPlan;

const SPEC: &str = "sweeps/cluster-demo.json";

fn sortsim(args: &[&str], env: &[(&str, &Path)]) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_sortsim"));
    cmd.args(args).current_dir(env!("CARGO_MANIFEST_DIR"));
    for (k, v) in env {
        cmd.env(k, v);
    }
    cmd.output().expect("sortsim runs")
}

fn ok(out: Output) -> String {
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    text
}

/// The report's files that must not depend on where or how the points ran: everything but
/// the host's cost files, the Slurm folder and the failure records' absence.
fn report_files(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut files = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                if p.file_name().unwrap() != "slurm" {
                    stack.push(p);
                }
            } else if p.file_name().unwrap() != "cost.json" {
                files.insert(
                    p.strip_prefix(dir).unwrap().to_path_buf(),
                    std::fs::read(&p).unwrap(),
                );
            }
        }
    }
    files
}

/// Asserts that `dir` holds exactly `expected`, naming the files that differ.
fn same_report(dir: &Path, expected: &BTreeMap<PathBuf, Vec<u8>>, what: &str) {
    let got = report_files(dir);
    let differ: Vec<_> = expected
        .keys()
        .chain(got.keys())
        .filter(|k| expected.get(*k) != got.get(*k))
        .collect();
    assert!(differ.is_empty(), "{what}: these files differ: {differ:?}");
}

fn cost_files(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    std::fs::read_dir(dir.join("points"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter_map(|p| {
            let cost = std::fs::read(p.join("cost.json")).ok()?;
            Some((p.file_name().unwrap().to_string_lossy().into_owned(), cost))
        })
        .collect()
}

/// Submits the sweep to the cluster and waits (at most two minutes) for both jobs to leave
/// the queue.
fn submit_and_wait(cluster: &SlurmCluster, out: &Path) -> String {
    let conf = cluster.conf();
    let printed = ok(sortsim(
        &[
            "sweep",
            SPEC,
            "-o",
            out.to_str().unwrap(),
            "--slurm",
            "--tasks",
            "3",
            "--submit",
        ],
        &[("SLURM_CONF", &conf)],
    ));
    let line = printed
        .lines()
        .find(|l| l.starts_with("submitted: array job "))
        .unwrap_or_else(|| panic!("no job ids in: {printed}"));
    let words: Vec<&str> = line.split_whitespace().collect();
    let (array, collect) = (words[3].trim_end_matches(','), words[6]);
    let deadline = Instant::now() + Duration::from_secs(120);
    while cluster.job_active(array) || cluster.job_active(collect) {
        assert!(
            Instant::now() < deadline,
            "jobs {array} and {collect} still queued or running after 120 s"
        );
        std::thread::sleep(Duration::from_millis(300));
    }
    printed
}

fn log(out: &Path, name: &str) -> String {
    let path = out.join("slurm/logs").join(name);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[test]
fn a_sweep_submitted_to_slurm_collects_the_local_report_and_resumes_one_lost_shard() {
    let cluster = SlurmCluster::start();
    let tmp = tempfile::tempdir().unwrap();
    let (local, remote) = (tmp.path().join("local"), tmp.path().join("remote"));
    ok(sortsim(
        &["sweep", SPEC, "-o", local.to_str().unwrap()],
        &[],
    ));
    submit_and_wait(&cluster, &remote);
    let collected = log(&remote, "collect.out");
    assert!(
        collected.contains("12 points (0 simulated now, 12 already done)"),
        "{collected}"
    );
    let expected = report_files(&local);
    assert!(expected.keys().any(|p| p.ends_with("sweep.csv")));
    assert!(expected.keys().any(|p| p.ends_with("index.html")));
    assert_eq!(
        report_files(&remote),
        expected,
        "the collected report is the local one"
    );

    // Lose shard 1's results; resubmitting reruns just its points.
    let plan = ShardPlan::read(&remote).expect("the shard plan");
    assert_eq!(plan.shards.iter().map(Vec::len).sum::<usize>(), 12);
    let lost = &plan.shards[1];
    assert!(!lost.is_empty());
    for name in lost {
        std::fs::remove_dir_all(remote.join("points").join(name)).unwrap();
    }
    let before = cost_files(&remote);
    submit_and_wait(&cluster, &remote);
    let after = cost_files(&remote);
    for (name, cost) in &before {
        assert_eq!(after.get(name), Some(cost), "{name} was not run again");
    }
    assert_eq!(after.len(), 12);
    for (i, points) in plan.shards.iter().enumerate() {
        let redone = if i == 1 { points.len() } else { 0 };
        let text = log(&remote, &format!("shard-{i}.out"));
        let expect = format!(
            "({redone} simulated now, {} already done)",
            points.len() - redone
        );
        assert!(text.contains(&expect), "shard {i}: {text}");
    }
    assert_eq!(
        report_files(&remote),
        expected,
        "and the report is the same again"
    );
}

/// Shards by hand, without a cluster: every shard, then `--collect`, equals the local sweep;
/// `--collect` with a shard missing names its points and the command that reruns them.
#[test]
fn shards_run_by_hand_collect_the_local_report() {
    let tmp = tempfile::tempdir().unwrap();
    let (local, sharded) = (tmp.path().join("local"), tmp.path().join("sharded"));
    let out = sharded.to_str().unwrap();
    ok(sortsim(
        &["sweep", SPEC, "-o", local.to_str().unwrap(), "--jobs", "2"],
        &[],
    ));
    for i in [0, 2] {
        let printed = ok(sortsim(
            &["sweep", SPEC, "-o", out, "--shard", &format!("{i}/3")],
            &[],
        ));
        assert!(printed.starts_with(&format!("shard {i}/3: ")), "{printed}");
    }
    let missing = sortsim(&["sweep", SPEC, "-o", out, "--collect"], &[]);
    let stderr = String::from_utf8_lossy(&missing.stderr);
    assert_eq!(missing.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("have no result"), "{stderr}");
    assert!(
        stderr.contains(&format!(
            "sortsim sweep {} -o {out}",
            Path::new(SPEC).display()
        )),
        "{stderr}"
    );
    assert!(!sharded.join("sweep.csv").exists(), "nothing written");
    ok(sortsim(&["sweep", SPEC, "-o", out, "--shard", "1/3"], &[]));
    ok(sortsim(&["sweep", SPEC, "-o", out, "--collect"], &[]));
    same_report(&sharded, &report_files(&local), "sharded by hand");
}

fn refused(args: &[&str], env: &[(&str, &Path)], fragment: &str) {
    common::assert_refused(&sortsim(args, env), &format!("{args:?}"), fragment);
}

#[test]
fn a_submission_without_sbatch_and_a_foreign_folder_are_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("r");
    let o = out.to_str().unwrap();
    let empty = tmp.path().join("no-sbatch-here");
    std::fs::create_dir(&empty).unwrap();
    refused(
        &["sweep", SPEC, "-o", o, "--slurm", "--submit"],
        &[("PATH", &empty)],
        "`sbatch` is not on the PATH",
    );
    assert!(!out.exists(), "a refused submission writes nothing");
    // A folder that holds another sweep's points.
    ok(sortsim(&["sweep", "sweeps/default.json", "-o", o], &[]));
    refused(
        &["sweep", SPEC, "-o", o, "--collect"],
        &[],
        "belong to no point of this sweep",
    );
}

/// A point whose machine cannot hold the run is a row with its error in a local sweep; run in
/// a shard, it leaves failure.json, and `--collect` gives the same table.
#[test]
fn a_point_too_big_for_its_machine_collects_as_its_local_row() {
    use sortsim::sweep::spec::parse_sweep;
    use sortsim::sweep::{collect, run_shard, run_sweep, FailureKind, Shard, SweepOptions};
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let json = r#"{"machine": "machines/delta.json", "scene": "scenes/plb-head-standin.json",
        "algo": "sort-middle/ellsworth", "procs": [1, 4], "frames": "0..1",
        "vary": {"machine.memory.capacity_per_node": ["64KB", "16MB"]}}"#;
    let sweep = parse_sweep(&root.join("test-sweep.json"), json).unwrap_or_else(|e| panic!("{e}"));
    let tmp = tempfile::tempdir().unwrap();
    let (local, sharded) = (tmp.path().join("local"), tmp.path().join("sharded"));
    let options = SweepOptions {
        jobs: 1,
        progress: false,
    };
    let outcome = run_sweep(&sweep, &local, options).unwrap();
    assert!(
        outcome
            .failures
            .iter()
            .any(|f| f.kind == FailureKind::Machine),
        "the 64 KB points do not fit: {:?}",
        outcome.failures
    );
    for index in 0..2 {
        run_shard(&sweep, &sharded, Shard { index, of: 2 }, options).unwrap();
    }
    let collected = collect(&sweep, &sharded).unwrap();
    assert_eq!(collected.failures.len(), outcome.failures.len());
    same_report(&sharded, &report_files(&local), "with failed points");
}
