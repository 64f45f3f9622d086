//! Runs one of the reference scripts with the system's Python 3.
//!
//! Owns finding the interpreter (`SORTSIM_PYTHON`, else Debian's `/usr/bin/python3`, whose
//! dist-packages hold python3-simgrid and python3-moderngl, else `python3` on the PATH) and
//! turning a missing interpreter or module into a message that says what to install. Must
//! never install anything itself.

use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::Command;

/// A reference script: its file name and text (built in, so the binary runs from anywhere).
pub struct Script {
    pub name: &'static str,
    pub text: &'static str,
    /// The Debian packages that provide what it imports, named in the missing-module message.
    pub packages: &'static str,
}

pub const SIMGRID_FLOW: Script = Script {
    name: "simgrid_flow.py",
    text: include_str!("../../scripts/validate/simgrid_flow.py"),
    packages: "python3-simgrid",
};

pub const LLVMPIPE_RASTER: Script = Script {
    name: "llvmpipe_raster.py",
    text: include_str!("../../scripts/validate/llvmpipe_raster.py"),
    packages: "python3-moderngl libegl1 libegl-mesa0 libgl1-mesa-dri",
};

/// Why a reference program could not give its answer.
#[derive(Debug, thiserror::Error)]
pub enum ToolError {
    /// The interpreter or a module is not installed: the user's to fix (exit 2).
    #[error("{what} is not installed: {hint}")]
    Missing { what: String, hint: String },
    /// The script ran and failed, or printed something unreadable: a bug here (exit 1).
    #[error("{script} failed: {detail}")]
    Failed {
        script: &'static str,
        detail: String,
    },
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
}

impl ToolError {
    pub fn is_missing_tool(&self) -> bool {
        matches!(self, ToolError::Missing { .. })
    }
}

fn interpreter() -> PathBuf {
    if let Some(p) = std::env::var_os("SORTSIM_PYTHON") {
        return PathBuf::from(p);
    }
    let debian = Path::new("/usr/bin/python3");
    if debian.is_file() {
        debian.to_path_buf()
    } else {
        PathBuf::from("python3")
    }
}

/// Writes `script` into `dir` and runs it with `args`; its standard output.
pub fn run(script: &Script, dir: &Path, args: &[&OsStr]) -> Result<String, ToolError> {
    let path = dir.join(script.name);
    std::fs::write(&path, script.text).map_err(|source| ToolError::Io {
        path: path.clone(),
        source,
    })?;
    let python = interpreter();
    let install = format!("apt-get install {}", script.packages);
    let out = Command::new(&python)
        .arg(&path)
        .args(args)
        .output()
        .map_err(|e| ToolError::Missing {
            what: format!("Python 3 ({}: {e})", python.display()),
            hint: format!("install it with `apt-get install python3`, then `{install}`"),
        })?;
    let stderr = String::from_utf8_lossy(&out.stderr);
    if out.status.code() == Some(3) {
        if let Some(module) = stderr
            .lines()
            .find_map(|l| l.strip_prefix("missing-module: "))
        {
            return Err(ToolError::Missing {
                what: format!("the Python module '{module}' (for {})", python.display()),
                hint: format!(
                    "`{install}` (Debian), or set SORTSIM_PYTHON to a Python 3 that has it"
                ),
            });
        }
    }
    if !out.status.success() {
        return Err(ToolError::Failed {
            script: script.name,
            detail: format!("{}: {}", out.status, stderr.trim()),
        });
    }
    String::from_utf8(out.stdout).map_err(|e| ToolError::Failed {
        script: script.name,
        detail: format!("output is not UTF-8: {e}"),
    })
}

/// The script's JSON answer.
pub fn parse<T: serde::de::DeserializeOwned>(
    script: &Script,
    stdout: &str,
) -> Result<T, ToolError> {
    serde_json::from_str(stdout).map_err(|e| ToolError::Failed {
        script: script.name,
        detail: format!(
            "unreadable answer ({e}): {}",
            stdout.chars().take(200).collect::<String>()
        ),
    })
}
