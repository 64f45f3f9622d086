//! Where sortsim finds its bundled data and the files named on its command line. Owns the
//! data-root rule and the copy of the data carried inside the binary; never parses a spec and
//! never decides where a report goes (reports go under the current folder).
//!
//! The data root (machines/, scenes/, sweeps/, papers/, schemas/, traces/, tests/patterns/)
//! is, first match wins:
//! 1. `--root DIR`, or the environment variable `SORTSIM_ROOT`;
//! 2. the current folder, when it holds `machines/` and `scenes/` (a checkout of sortsim);
//! 3. the data bundled in the binary, unpacked once per build into the user's data folder
//!    (`$XDG_DATA_HOME/sortsim/<version>-<digest>`, `~/.local/share/...` on Linux).
//!
//! A relative file named on the command line is read from the current folder when it exists
//! there, else from the data root; so `sortsim run --machine machines/delta.json ...` works
//! from any folder.

use std::hash::{Hash, Hasher};
use std::path::{Path, PathBuf};

use include_dir::{include_dir, Dir};

/// The folders a data root holds, bundled as they are in the source tree.
static BUNDLE: [(&str, Dir<'static>); 7] = [
    ("machines", include_dir!("$CARGO_MANIFEST_DIR/machines")),
    ("scenes", include_dir!("$CARGO_MANIFEST_DIR/scenes")),
    ("sweeps", include_dir!("$CARGO_MANIFEST_DIR/sweeps")),
    ("papers", include_dir!("$CARGO_MANIFEST_DIR/papers")),
    ("schemas", include_dir!("$CARGO_MANIFEST_DIR/schemas")),
    ("traces", include_dir!("$CARGO_MANIFEST_DIR/traces")),
    (
        "tests/patterns",
        include_dir!("$CARGO_MANIFEST_DIR/tests/patterns"),
    ),
];

/// The environment variable naming a data root.
pub const ROOT_VAR: &str = "SORTSIM_ROOT";

/// The folder bundled files are read from, and how it was chosen.
#[derive(Clone, Debug)]
pub struct DataRoot {
    pub path: PathBuf,
}

impl DataRoot {
    /// Applies the rule above; `given` is `--root` (or `SORTSIM_ROOT`, which clap reads).
    pub fn find(given: Option<&Path>) -> Result<DataRoot, String> {
        if let Some(dir) = given {
            if !dir.join("machines").is_dir() {
                return Err(format!(
                    "{}: not a sortsim data root (--root or {ROOT_VAR}): it has no machines/ \
                     folder; valid: a sortsim checkout or a folder holding machines/, scenes/ \
                     and sweeps/",
                    dir.display()
                ));
            }
            return Ok(DataRoot {
                path: dir.to_path_buf(),
            });
        }
        if is_checkout(Path::new(".")) {
            return Ok(DataRoot {
                path: PathBuf::from("."),
            });
        }
        unpack_bundle().map(|path| DataRoot { path })
    }

    /// A bundled file or folder, by its path relative to the root.
    pub fn join(&self, relative: impl AsRef<Path>) -> PathBuf {
        if self.path == Path::new(".") {
            relative.as_ref().to_path_buf()
        } else {
            self.path.join(relative)
        }
    }

    /// A file named on the command line: as given when it exists (or is absolute), else the
    /// same relative path under the data root when it exists there, else as given (so the
    /// error names what the user typed).
    pub fn input(&self, given: &Path) -> PathBuf {
        if given.is_absolute() || given.exists() {
            return given.to_path_buf();
        }
        let bundled = self.join(given);
        if bundled.exists() {
            bundled
        } else {
            given.to_path_buf()
        }
    }
}

fn is_checkout(dir: &Path) -> bool {
    dir.join("machines").is_dir() && dir.join("scenes").is_dir()
}

/// Unpacks the bundled data once per build: into a fresh folder beside the destination, then
/// renamed into place, so a reader never sees half of it and two first runs do not collide.
fn unpack_bundle() -> Result<PathBuf, String> {
    let base = dirs::data_dir()
        .unwrap_or_else(std::env::temp_dir)
        .join("sortsim");
    let dest = base.join(format!("{}-{:016x}", env!("CARGO_PKG_VERSION"), digest()));
    if is_checkout(&dest) {
        return Ok(dest);
    }
    let fail = |e: std::io::Error| {
        format!(
            "{}: cannot unpack sortsim's bundled machines and scenes: {e}; give a data root \
             with --root DIR or {ROOT_VAR}",
            base.display()
        )
    };
    std::fs::create_dir_all(&base).map_err(fail)?;
    let staging = tempfile::Builder::new()
        .prefix(".unpacking-")
        .tempdir_in(&base)
        .map_err(fail)?;
    for (folder, dir) in &BUNDLE {
        let target = staging.path().join(folder);
        std::fs::create_dir_all(&target).map_err(fail)?;
        dir.extract(&target).map_err(fail)?;
    }
    let staged = staging.keep();
    if let Err(e) = std::fs::rename(&staged, &dest) {
        // Another sortsim unpacked it first: use theirs.
        let _ = std::fs::remove_dir_all(&staged);
        if !is_checkout(&dest) {
            return Err(fail(e));
        }
    }
    Ok(dest)
}

/// A digest of every bundled file's path and bytes, so that a rebuilt binary with changed data
/// unpacks afresh instead of reading an older copy.
fn digest() -> u64 {
    let mut hasher = std::hash::DefaultHasher::new();
    for (folder, dir) in &BUNDLE {
        folder.hash(&mut hasher);
        hash_dir(dir, &mut hasher);
    }
    hasher.finish()
}

fn hash_dir(dir: &Dir<'_>, hasher: &mut impl Hasher) {
    for file in dir.files() {
        file.path().hash(hasher);
        file.contents().hash(hasher);
    }
    for sub in dir.dirs() {
        hash_dir(sub, hasher);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_bundle_holds_the_default_jobs_inputs() {
        let has = |folder: &str, file: &str| {
            BUNDLE
                .iter()
                .any(|(f, d)| *f == folder && d.get_file(file).is_some())
        };
        assert!(has("machines", "delta.json"));
        assert!(has("sweeps", "default.json"));
        assert!(has("tests/patterns", "complement-16x32.json"));
        assert!(has("scenes", "plb-head-standin.json"));
    }

    #[test]
    fn an_input_that_exists_here_is_read_as_given() {
        let root = DataRoot {
            path: PathBuf::from("/nonexistent-root"),
        };
        assert_eq!(root.input(Path::new("Cargo.toml")), Path::new("Cargo.toml"));
        assert_eq!(
            root.input(Path::new("missing.json")),
            Path::new("missing.json")
        );
    }
}
