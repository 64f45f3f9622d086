//! What this machine offers a command beyond sortsim itself: programs on the PATH (Slurm's
//! `sbatch`, valgrind). Owns looking them up; must never run them or decide what their
//! absence means (each caller says that in its own words).

use std::path::PathBuf;

/// `program` in the first folder of the PATH that has it, if any does.
pub fn on_path(program: &str) -> Option<PathBuf> {
    std::env::split_paths(&std::env::var_os("PATH")?)
        .map(|dir| dir.join(program))
        .find(|path| path.is_file())
}
