//! `cargo install` gives a sortsim that works from any folder: it finds its bundled machines,
//! scenes and sweeps by the data-root rule (src/app/data.rs) and writes its reports under the
//! current folder, never into the source tree.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn manifest_dir() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// Installs sortsim into `root` with cargo, as a user would. The build goes to a target folder
/// of its own, kept between runs so that a second install only links: in the tests' folder it
/// would rebuild sortsim anyway (the dev-dependencies turn on features of some shared crates,
/// which changes their hashes) and relink `target/release/sortsim` while other tests run it.
fn install(root: &Path) -> PathBuf {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = Command::new(cargo)
        .args(["install", "--quiet", "--locked", "--offline", "--path"])
        .arg(manifest_dir())
        .arg("--root")
        .arg(root)
        .arg("--target-dir")
        .arg(manifest_dir().join("target/install"))
        .output()
        .expect("cargo runs");
    assert!(
        out.status.success(),
        "cargo install failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    root.join("bin")
        .join(format!("sortsim{}", std::env::consts::EXE_SUFFIX))
}

/// The installed binary in `folder`, with a home and data folder of its own and no data root
/// from the environment.
fn run_in(bin: &Path, folder: &Path, home: &Path, args: &[&str]) -> Output {
    let out = Command::new(bin)
        .args(args)
        .current_dir(folder)
        .env("HOME", home)
        .env("XDG_DATA_HOME", home.join("data"))
        .env_remove("SORTSIM_ROOT")
        .output()
        .expect("the installed sortsim runs");
    assert!(
        out.status.success(),
        "sortsim {args:?} in {} failed: {}",
        folder.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

fn summary_per_frame(dir: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(dir.join("summary.json")).expect("summary.json written");
    let summary: serde_json::Value = serde_json::from_str(&text).expect("summary.json is JSON");
    summary["per_frame"].clone()
}

#[test]
fn an_installed_sortsim_runs_the_default_job_and_a_run_from_another_folder() {
    let scratch = tempfile::tempdir().expect("temporary folder");
    let bin = install(&scratch.path().join("install"));
    let (work, home) = (scratch.path().join("work"), scratch.path().join("home"));
    std::fs::create_dir_all(&work).unwrap();
    std::fs::create_dir_all(&home).unwrap();

    let job = run_in(&bin, &work, &home, &[]);
    let printed = String::from_utf8_lossy(&job.stdout);
    assert!(
        work.join("reports/default/index.html").is_file(),
        "the default job writes under the current folder; it printed:\n{printed}"
    );
    assert!(
        printed.contains("OK   "),
        "machines were checked:\n{printed}"
    );
    let unpacked = std::fs::read_dir(home.join("data/sortsim"))
        .expect("the bundled data is unpacked under the data folder")
        .count();
    assert_eq!(unpacked, 1, "one unpacked copy per build");

    let run = [
        "run",
        "--machine",
        "machines/delta.json",
        "--scene",
        "scenes/plb-head-standin.json",
        "--algo",
        "sort-middle/static",
        "--procs",
        "8",
        "--frames",
        "0..2",
        "-o",
    ];
    let installed: Vec<&str> = run.iter().copied().chain(["installed"]).collect();
    run_in(&bin, &work, &home, &installed);

    // The same run from the checkout, by the binary the tests built: same simulated answers.
    let checkout = scratch.path().join("checkout-run");
    let checkout_arg = checkout.to_str().expect("UTF-8 path");
    let from_checkout: Vec<&str> = run.iter().copied().chain([checkout_arg]).collect();
    let out = Command::new(env!("CARGO_BIN_EXE_sortsim"))
        .args(&from_checkout)
        .current_dir(manifest_dir())
        .output()
        .expect("sortsim runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(
        summary_per_frame(&work.join("installed")),
        summary_per_frame(&checkout)
    );

    // --root names a data root explicitly, from a folder that has none.
    let root_arg = manifest_dir().to_str().expect("UTF-8 path");
    let check = run_in(
        &bin,
        &work,
        &home,
        &["--root", root_arg, "check", "sweeps/default.json"],
    );
    assert!(String::from_utf8_lossy(&check.stdout).starts_with("OK   sweeps/default.json"));
}
