//! The run spec: machine, scene, algorithm, processors, frames, seed and `set` options, as
//! given by `sortsim run` flags or a JSON file (a sweep is a run spec with lists), and its
//! resolution into a validated `algo::RunConfig`.
//!
//! `set` keys that start with `machine.` edit the machine spec before it is validated (so
//! `machine.network.fidelity=packet` is checked like the file itself); every other key is an
//! option of the algorithm. Must never run anything.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use serde::{Deserialize, Serialize};

use super::machine::{validate, MachineSpec};
use super::SpecError;
use crate::algo::{AlgorithmId, OptionError, Options, RunConfig};
use crate::scene::{Scene, SceneError};

/// One run, as a person writes it.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RunSpec {
    /// The JSON Schema this file follows, for editors (`schemas/`); sortsim ignores it.
    #[serde(rename = "$schema", default, skip_serializing_if = "Option::is_none")]
    pub schema: Option<String>,
    pub machine: PathBuf,
    pub scene: PathBuf,
    pub algo: String,
    #[schemars(range(min = 1))]
    pub procs: u32,
    /// Frames: "A..B" (B excluded), "A..=B" (B included) or a single frame "A"; all frames
    /// when absent.
    #[serde(default)]
    pub frames: Option<String>,
    #[serde(default = "default_seed")]
    pub seed: u64,
    /// key = value options; values are strings as on the command line.
    #[serde(default)]
    pub set: BTreeMap<String, String>,
}

fn default_seed() -> u64 {
    1
}

/// Why a run cannot be set up.
#[derive(Debug, thiserror::Error)]
pub enum RunSpecError {
    #[error(transparent)]
    Spec(#[from] SpecError),
    #[error(transparent)]
    Scene(#[from] SceneError),
    #[error("{0}")]
    Invalid(String),
}

impl RunSpec {
    /// Loads the machine and scene and checks everything a run needs before it starts.
    /// `scene_cache` lets sweeps share one loaded scene between runs.
    pub fn resolve(&self, scene: Option<Arc<Scene>>) -> Result<RunConfig, RunSpecError> {
        self.resolve_as(scene, Written::Flags)
    }

    /// As `resolve`, for a run spec file: mistakes are named by field (`frames`,
    /// `set.granularity`), not by flag.
    pub fn resolve_file(&self, scene: Option<Arc<Scene>>) -> Result<RunConfig, RunSpecError> {
        self.resolve_as(scene, Written::File)
    }

    /// As `resolve_file`, for one point of a sweep, whose options come from `set` or `vary`.
    pub fn resolve_sweep_point(
        &self,
        scene: Option<Arc<Scene>>,
    ) -> Result<RunConfig, RunSpecError> {
        self.resolve_as(scene, Written::SweepPoint)
    }

    fn resolve_as(
        &self,
        scene: Option<Arc<Scene>>,
        written: Written,
    ) -> Result<RunConfig, RunSpecError> {
        let algo = AlgorithmId::from_id(&self.algo).ok_or_else(|| {
            RunSpecError::Invalid(format!(
                "{}: unknown algorithm; valid ids: {}",
                written.name("algo", &self.algo),
                AlgorithmId::valid_ids()
            ))
        })?;
        let machine = self.machine_with_overrides(written)?;
        if self.procs == 0 {
            return Err(RunSpecError::Invalid(format!(
                "{}: a run needs at least 1 processor",
                written.name("procs", "0")
            )));
        }
        let machine = machine.with_nodes(self.procs).map_err(|e| {
            let procs = written.name("procs", &self.procs.to_string());
            RunSpecError::Invalid(format!("{procs}: {e}"))
        })?;
        let options = Options::new(
            self.set
                .iter()
                .filter(|(k, _)| !k.starts_with("machine."))
                .map(|(k, v)| (k.clone(), v.clone()))
                .collect(),
        );
        algo.check_option_values(&options)
            .map_err(|e| RunSpecError::Invalid(written.option_error(&e)))?;
        let scene = match scene {
            Some(s) => s,
            None => Arc::new(Scene::load(&self.scene)?),
        };
        let frames = parse_frames(self.frames.as_deref(), scene.frame_count()).map_err(|e| {
            RunSpecError::Invalid(format!(
                "{}: {e}",
                written.name("frames", self.frames.as_deref().unwrap_or(""))
            ))
        })?;
        Ok(RunConfig {
            machine,
            scene,
            algo,
            frames,
            options,
            seed: self.seed,
            timeline: false,
            timeline_frames: None,
            front_end_ahead: true,
            wake_every_slice: false,
        })
    }

    /// The machine spec with every `machine.` key of `set` applied, validated. The file is
    /// first read as `check` reads it (field paths, duplicate keys), so a mistake in the file
    /// is named in the file; what only the overrides break is named with their keys.
    fn machine_with_overrides(
        &self,
        written: Written,
    ) -> Result<crate::machine::MachineConfig, RunSpecError> {
        let text = super::read_input(&self.machine).map_err(|source| SpecError::Io {
            file: self.machine.clone(),
            source,
        })?;
        let as_written: MachineSpec = super::parse_json(&self.machine, &text)?;
        let overrides: Vec<(&String, &String)> = self
            .set
            .iter()
            .filter(|(k, _)| k.starts_with("machine."))
            .collect();
        if overrides.is_empty() {
            return Ok(validate(&self.machine, as_written)?);
        }
        let mut value: serde_json::Value = super::parse_json(&self.machine, &text)?;
        for (key, raw) in &overrides {
            let path: Vec<&str> = key["machine.".len()..].split('.').collect();
            set_path(&mut value, &path, raw)
                .map_err(|e| RunSpecError::Invalid(format!("{}: {e}", written.set(key, raw))))?;
        }
        let spec: MachineSpec = serde_path_to_error::deserialize(value).map_err(|e| {
            let keys: Vec<String> = overrides
                .iter()
                .map(|(k, v)| written.set_with(k, v))
                .collect();
            RunSpecError::Invalid(format!(
                "{}: at `{}` with {}: {}",
                self.machine.display(),
                e.path(),
                keys.join(", "),
                e.inner()
            ))
        })?;
        Ok(validate(&self.machine, spec)?)
    }
}

/// An algorithm option's error in a run spec file, worded by the field written
/// (`at `set.key` (value)`), not by the flag.
pub fn file_option_error(e: &OptionError) -> String {
    Written::File.option_error(e)
}

/// Where a run spec came from, which decides how its messages name a value: by the flag a
/// person typed or by the field they wrote.
#[derive(Clone, Copy)]
enum Written {
    Flags,
    File,
    SweepPoint,
}

impl Written {
    /// `--frames 0..=2` or `at `frames` (0..=2)`.
    fn name(self, field: &str, value: &str) -> String {
        match self {
            Written::Flags => format!("--{field} {value}"),
            Written::File | Written::SweepPoint => format!("at `{field}` ({value})"),
        }
    }

    /// `--set key`, `at `set.key`` or `option `key``, leading a message.
    fn option(self, key: &str) -> String {
        match self {
            Written::Flags => format!("--set {key}"),
            Written::File => format!("at `set.{key}`"),
            Written::SweepPoint => format!("option `{key}`"),
        }
    }

    /// `--set key=value`, `at `set.key` (value)` or `option `key` = value`, leading a message.
    fn set(self, key: &str, value: &str) -> String {
        match self {
            Written::Flags => format!("--set {key}={value}"),
            Written::File => format!("at `set.{key}` ({value})"),
            Written::SweepPoint => format!("option `{key}` = {value}"),
        }
    }

    /// As `set`, after "with".
    fn set_with(self, key: &str, value: &str) -> String {
        match self {
            Written::Flags => format!("--set {key}={value}"),
            Written::File => format!("`set.{key}` = {value}"),
            Written::SweepPoint => format!("option `{key}` = {value}"),
        }
    }

    /// An algorithm option's error, worded for where the option was written.
    fn option_error(self, e: &OptionError) -> String {
        match (self, e) {
            (Written::Flags, e) => e.to_string(),
            (
                _,
                OptionError::Invalid {
                    key,
                    value,
                    message,
                },
            ) => {
                format!("{}: {message}", self.set(key, value))
            }
            (_, OptionError::Unknown { key, algo, valid }) => format!(
                "{}: {algo} has no option '{key}'; valid options: {valid}",
                self.option(key)
            ),
        }
    }
}

/// Sets `path` inside `value` to `raw`, read as JSON when it is a number, boolean, list or
/// object, and as a string otherwise. The objects on the way must be in the file; the last
/// field may be one the file leaves out, if the machine spec allows it there (an optional
/// field, such as `network.node.placement`).
fn set_path(value: &mut serde_json::Value, path: &[&str], raw: &str) -> Result<(), String> {
    let mut here = value;
    for (i, key) in path.iter().enumerate() {
        let obj = here
            .as_object_mut()
            .ok_or_else(|| format!("`{}` is not an object", path[..i].join(".")))?;
        if !obj.contains_key(*key) {
            let allowed = super::schema::machine_fields_at(&path[..i]).unwrap_or_default();
            let in_spec = allowed.iter().any(|f| f == key);
            if in_spec && i + 1 < path.len() {
                return Err(format!(
                    "the machine file has no `{}` to set `{}` in; write that object in the file",
                    path[..=i].join("."),
                    path[i + 1..].join(".")
                ));
            }
            if !in_spec {
                let valid = if allowed.is_empty() {
                    obj.keys().cloned().collect::<Vec<_>>()
                } else {
                    allowed
                };
                return Err(format!(
                    "the machine spec has no field `{}`; valid fields there: {}",
                    path[..=i].join("."),
                    valid.join(", ")
                ));
            }
        }
        here = obj
            .entry(key.to_string())
            .or_insert(serde_json::Value::Null);
    }
    *here = match serde_json::from_str::<serde_json::Value>(raw) {
        Ok(v) if !v.is_string() => v,
        _ => serde_json::Value::String(raw.to_string()),
    };
    Ok(())
}

/// `A..B`, `A..=B` (see `spec::range`), `A`, or all frames. A malformed range is blamed on
/// its syntax, a well-formed one outside the scene on the scene's frames.
pub fn parse_frames(text: Option<&str>, count: u32) -> Result<std::ops::Range<u32>, String> {
    let range = match text {
        None => 0..count,
        Some(t) => match super::range::parse(t) {
            Some(r) => {
                let r = r?;
                *r.start()..r.end().saturating_add(1)
            }
            None => {
                let a = t.trim().parse::<u32>().map_err(|_| {
                    format!(
                        "'{t}' is not a frame range: write {}, or a single frame A",
                        super::range::SYNTAX
                    )
                })?;
                a..a.saturating_add(1)
            }
        },
    };
    if range.is_empty() {
        return Err(format!(
            "the scene has no frames (0..{count}); there is nothing to run"
        ));
    }
    if range.end > count {
        return Err(format!(
            "the scene has frames 0..{count} (0 to {}), not {}..{}",
            count.saturating_sub(1),
            range.start,
            range.end
        ));
    }
    Ok(range)
}

/// Resolves a path given relative to a spec file's folder.
pub fn relative_to(spec_file: &Path, path: &Path) -> PathBuf {
    if path.is_absolute() {
        path.to_path_buf()
    } else {
        spec_file.parent().unwrap_or(Path::new(".")).join(path)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_ranges() {
        assert_eq!(parse_frames(None, 80), Ok(0..80));
        assert_eq!(parse_frames(Some("3..7"), 80), Ok(3..7));
        assert_eq!(parse_frames(Some("5"), 80), Ok(5..6));
        // Past the scene: blamed on the scene's frames.
        for bad in ["0..81", "80"] {
            let e = parse_frames(Some(bad), 80).unwrap_err();
            assert!(e.contains("the scene has frames 0..80"), "{bad}: {e}");
        }
        // Empty: blamed on the order.
        for bad in ["7..3", "3..3"] {
            let e = parse_frames(Some(bad), 80).unwrap_err();
            assert!(e.contains("is an empty range"), "{bad}: {e}");
        }
        // Malformed: blamed on the syntax, whatever the scene.
        for bad in ["x", "0..=x", "0-3", "-1", "1..2..3", ""] {
            let e = parse_frames(Some(bad), 80).unwrap_err();
            assert!(
                e.contains("A..B (A to B-1) or A..=B (A to B)"),
                "{bad}: {e}"
            );
        }
        // Both of Rust's forms.
        assert_eq!(parse_frames(Some("2..5"), 80), Ok(2..5));
        assert_eq!(parse_frames(Some("2..=5"), 80), Ok(2..6));
        assert_eq!(parse_frames(Some("79..=79"), 80), Ok(79..80));
    }

    #[test]
    fn machine_paths_must_be_the_specs() {
        let mut v: serde_json::Value = serde_json::json!({"network": {"fidelity": "flow", "node": {"processors": 4}}, "nodes": 4});
        set_path(&mut v, &["network", "fidelity"], "packet").unwrap();
        set_path(&mut v, &["nodes"], "8").unwrap();
        // An optional field the file leaves out.
        set_path(&mut v, &["network", "node", "placement"], "cyclic").unwrap();
        assert_eq!(
            v,
            serde_json::json!({"network": {"fidelity": "packet",
                "node": {"processors": 4, "placement": "cyclic"}}, "nodes": 8})
        );
        // A field the spec does not have, named with the ones it has there.
        let err = set_path(&mut v, &["network", "colour"], "red").unwrap_err();
        assert!(
            err.contains("no field `network.colour`; valid fields there: ")
                && err.contains("dims, dragonfly, fat_tree, fidelity, hop_latency"),
            "{err}"
        );
        let err = set_path(&mut v, &["network", "node", "placment"], "cyclic").unwrap_err();
        assert!(
            err.contains("hop_latency, link_bandwidth, nics, placement, processors"),
            "{err}"
        );
        // The objects on the way must be written: a node's fields without a node.
        let mut flat = serde_json::json!({"network": {"fidelity": "flow"}});
        let err = set_path(&mut flat, &["network", "node", "placement"], "cyclic").unwrap_err();
        assert!(
            err.contains("no `network.node` to set `placement` in; write that object"),
            "{err}"
        );
    }
}
