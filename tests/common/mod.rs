//! Helpers shared by the integration tests: small machines built from JSON text through the
//! same validation the CLI uses.
#![allow(dead_code)]

use std::collections::BTreeMap;
use std::path::Path;
use std::process::Output;
use std::sync::Arc;

use sortsim::algo::{run, RunConfig, RunError, RunResult};
use sortsim::machine::MachineConfig;
use sortsim::scene::Scene;
use sortsim::spec::machine::{validate, MachineSpec};
use sortsim::spec::parse_json;
use sortsim::spec::run::RunSpec;

/// A machine from spec text (validated exactly as a file would be).
pub fn machine(json: &str) -> MachineConfig {
    let spec: MachineSpec =
        parse_json(Path::new("test-machine.json"), json).expect("test machine parses");
    validate(Path::new("test-machine.json"), spec).expect("test machine is valid")
}

/// A ring of `nodes` with the given cpu overheads and overlap flag, 1 MB/s links, 1us hops,
/// wormhole switching, ideal transport.
pub fn ring(nodes: u32, send_overhead: &str, recv_overhead: &str, overlap: bool) -> MachineConfig {
    machine(&format!(
        r#"{{"name": "test-ring", "source": "test", "nodes": {nodes},
            "cpu": {{"costs": {{"pixel_write": "10ns", "setup_triangle": "1us"}},
                     "send_overhead": "{send_overhead}", "recv_overhead": "{recv_overhead}", "overlap": {overlap}}},
            "memory": {{"capacity_per_node": "1MB"}},
            "network": {{"topology": "ring", "link_bandwidth": "1MB/s", "hop_latency": "1us",
                         "switching": "wormhole", "packet_size": "1KiB", "fidelity": "ideal"}}}}"#
    ))
}

/// The repository root (machines/, scenes/).
pub fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The real `sortsim` binary run with `args` in the checkout, its output captured (its exit
/// status is the caller's to check).
pub fn sortsim(args: &[&str]) -> Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_sortsim"))
        .args(args)
        .current_dir(root())
        .output()
        .expect("sortsim runs")
}

/// The machine each sort-last algorithm was built for, with the overrides its tests need:
/// the MultiCluster's T800s get 64 MB so that a frame of samples, or of Pixels with a
/// Subpixel pool, fits (4 MB does not; the tests that say so use the file as it is).
pub fn sort_last_machine(algo: &str) -> (&'static str, &'static [(&'static str, &'static str)]) {
    const BIG_T800: &[(&str, &str)] = &[("machine.memory.capacity_per_node", "64MB")];
    match algo {
        "sort-last/df" => ("multicluster-torus.json", BIG_T800),
        "sort-last/pc" | "sort-last/scanline-flow" => ("multicluster-pipeline.json", BIG_T800),
        "sort-last/pixelflow" => ("pixelflow-pipeline.json", &[]),
        "sort-last/direct-send" => ("denali-crossbar.json", &[]),
        _ => ("snooping-bus.json", &[]),
    }
}

/// A sort-last run of `scene` on its algorithm's machine, with `set` options (seed 1).
pub fn run_sort_last(
    scene: &Arc<Scene>,
    algo: &str,
    procs: u32,
    frames: Option<&str>,
    set: &[(&str, &str)],
) -> Result<RunResult, RunError> {
    let (machine, machine_set) = sort_last_machine(algo);
    let set: BTreeMap<String, String> = machine_set
        .iter()
        .chain(set)
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
    let spec = RunSpec {
        schema: None,
        machine: root().join("machines").join(machine),
        scene: scene.file().to_path_buf(),
        algo: algo.into(),
        procs,
        frames: frames.map(String::from),
        seed: 1,
        set,
    };
    run(&spec.resolve(Some(scene.clone())).expect("valid run"))
}

/// A scene of scenes/ by file name.
pub fn scene(name: &str) -> Arc<Scene> {
    Arc::new(Scene::load(&root().join("scenes").join(name)).expect("bundled scene loads"))
}

/// Frame 0 of `scene` run by `algo` on `procs` nodes of machines/`machine`, with `set`
/// options (seed 1).
pub fn run_frame0(
    machine: &str,
    scene: &Arc<Scene>,
    algo: &str,
    procs: u32,
    set: &[(&str, &str)],
) -> Result<RunResult, RunError> {
    run_frames(machine, scene, algo, procs, "0", set)
}

/// [`run_frame0`] over `frames` ("A..B" or "A").
pub fn run_frames(
    machine: &str,
    scene: &Arc<Scene>,
    algo: &str,
    procs: u32,
    frames: &str,
    set: &[(&str, &str)],
) -> Result<RunResult, RunError> {
    run(&frames_config(machine, scene, algo, procs, frames, set))
}

/// The resolved configuration [`run_frames`] runs.
pub fn frames_config(
    machine: &str,
    scene: &Arc<Scene>,
    algo: &str,
    procs: u32,
    frames: &str,
    set: &[(&str, &str)],
) -> RunConfig {
    let spec = RunSpec {
        schema: None,
        machine: root().join("machines").join(machine),
        scene: scene.file().to_path_buf(),
        algo: algo.into(),
        procs,
        frames: Some(frames.into()),
        seed: 1,
        set: set
            .iter()
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect(),
    };
    spec.resolve(Some(scene.clone())).expect("valid run spec")
}

/// The path of `binary`, installing the Debian `packages` (apt-get, as root) when it is not on
/// the PATH. A failed install fails the calling test with apt-get's output: a test never
/// passes because a tool was missing.
pub fn installed(binary: &str, packages: &[&str]) -> std::path::PathBuf {
    let find = || {
        std::env::var_os("PATH").and_then(|paths| {
            std::env::split_paths(&paths)
                .map(|d| d.join(binary))
                .find(|p| p.is_file())
        })
    };
    ensure(binary, packages, || find().is_some());
    find().unwrap_or_else(|| panic!("{packages:?} installed, yet {binary} is not on the PATH"))
}

/// Makes sure Debian's Python 3 (`/usr/bin/python3`, the interpreter `sortsim validate` uses)
/// can import `module`, installing the Debian `packages` when it cannot; as [`installed`].
pub fn python_module(module: &str, packages: &[&str]) {
    let python = installed("python3", &["python3"]);
    let debian = std::path::Path::new("/usr/bin/python3");
    let python = if debian.is_file() {
        debian.to_path_buf()
    } else {
        python
    };
    let imports = || {
        std::process::Command::new(&python)
            .args(["-c", &format!("import {module}")])
            .output()
            .is_ok_and(|o| o.status.success())
    };
    ensure(&format!("Python module {module}"), packages, imports);
    assert!(
        imports(),
        "{packages:?} installed, yet {} cannot import {module}",
        python.display()
    );
}

/// Runs apt-get to install `packages` unless `present` already holds (one install at a time).
fn ensure(what: &str, packages: &[&str], present: impl Fn() -> bool) {
    static INSTALL: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _one_at_a_time = INSTALL.lock().unwrap_or_else(|e| e.into_inner());
    if present() {
        return;
    }
    let apt = |args: &[&str]| {
        let out = std::process::Command::new("apt-get")
            .args(args)
            .env("DEBIAN_FRONTEND", "noninteractive")
            .output()
            .unwrap_or_else(|e| panic!("{what} is missing and apt-get cannot run: {e}"));
        assert!(
            out.status.success(),
            "{what} is missing and `apt-get {}` failed:\n{}{}",
            args.join(" "),
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
    };
    apt(&["update"]);
    let mut install = vec!["install", "-y", "--no-install-recommends"];
    install.extend(packages);
    apt(&install);
}

/// A one-node Slurm cluster started by scripts/slurm-test-cluster.sh (Debian's slurm-wlm and
/// munge, installed through [`installed`] when missing), stopped when dropped, also when the
/// test fails. Its state lives in a fresh temporary folder.
pub struct SlurmCluster {
    dir: tempfile::TempDir,
}

impl SlurmCluster {
    pub fn start() -> SlurmCluster {
        installed("slurmctld", &["slurm-wlm", "munge"]);
        installed("munged", &["munge"]);
        let dir = tempfile::Builder::new()
            .prefix("sortsim-slurm-")
            .tempdir()
            .expect("a temporary folder");
        let cluster = SlurmCluster { dir };
        let out = cluster.script("start");
        assert!(
            out.status.success(),
            "the test cluster did not start:\n{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
        cluster
    }

    /// SLURM_CONF for the cluster's clients (sbatch, squeue, sortsim --submit).
    pub fn conf(&self) -> std::path::PathBuf {
        self.dir.path().join("slurm.conf")
    }

    /// True while `job` is queued or running.
    pub fn job_active(&self, job: &str) -> bool {
        let out = std::process::Command::new("squeue")
            .args(["-h", "-j", job, "-o", "%T"])
            .env("SLURM_CONF", self.conf())
            .output()
            .expect("squeue runs");
        out.status.success() && !String::from_utf8_lossy(&out.stdout).trim().is_empty()
    }

    fn script(&self, verb: &str) -> Output {
        std::process::Command::new(root().join("scripts/slurm-test-cluster.sh"))
            .arg(verb)
            .env("SORTSIM_SLURM_DIR", self.dir.path())
            .output()
            .expect("the cluster script runs")
    }
}

impl Drop for SlurmCluster {
    fn drop(&mut self) {
        let _ = self.script("stop");
    }
}

/// Asserts that a command was refused as bad input: exit code 2, `fragment` in its message,
/// no panic. `what` names the case in a failure.
pub fn assert_refused(out: &Output, what: &str, fragment: &str) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{what}: {stderr}");
    assert!(
        stderr.contains(fragment),
        "{what}: expected {fragment:?} in {stderr}"
    );
    assert!(!stderr.contains("panicked"), "{what}: {stderr}");
}

/// A path `name` inside a fresh temporary folder that is deleted, with everything under it,
/// when this value is dropped (also when the test fails). The path itself does not exist yet,
/// so a command can be asked to create it.
pub struct Scratch {
    _dir: tempfile::TempDir,
    path: std::path::PathBuf,
}

pub fn scratch(name: &str) -> Scratch {
    let dir = tempfile::Builder::new()
        .prefix("sortsim-test-")
        .tempdir()
        .expect("a temporary folder");
    let path = dir.path().join(name);
    Scratch { _dir: dir, path }
}

impl std::ops::Deref for Scratch {
    type Target = std::path::PathBuf;
    fn deref(&self) -> &std::path::PathBuf {
        &self.path
    }
}

impl AsRef<Path> for Scratch {
    fn as_ref(&self) -> &Path {
        &self.path
    }
}
