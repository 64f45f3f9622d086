//! The sweep spec: a run spec in which any of `machine`, `scene`, `algo`, `procs` and `seed`
//! may be a list, plus `vary`, a map from run option (or `machine.` field) to a list of
//! values. Its points are the cartesian product of every list, in one fixed order (outermost
//! first): machine, scene, algo, the `vary` keys in alphabetical order, seed, procs. Lists
//! keep the order they are written in, so procs is innermost and each plotted line is a run of
//! consecutive points.
//!
//! Paths are relative to the sweep file's folder. Owns parsing and validation of sweeps (errors
//! name the file and the field path); must never run a simulation or touch the report folder.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::algo::AlgorithmId;
use crate::spec::run::{relative_to, RunSpec};
use crate::spec::{load_json, parse_json, SpecError};

/// A sweep as a person writes it. `machines`, `scenes`, `algos`, `seeds` are accepted as
/// spellings of the same keys.
#[derive(Clone, Debug, Deserialize, PartialEq, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
#[schemars(transform = plural_spellings)]
pub struct SweepSpec {
    /// The JSON Schema this file follows, for editors (`schemas/`); sortsim ignores it.
    #[serde(rename = "$schema", default, skip_serializing)]
    pub schema: Option<String>,
    /// Free text for people: what the sweep reproduces and how long it takes.
    #[serde(default)]
    pub note: Option<String>,
    #[serde(alias = "machines")]
    pub machine: OneOrMany<PathBuf>,
    #[serde(alias = "scenes")]
    pub scene: OneOrMany<PathBuf>,
    #[serde(alias = "algos")]
    pub algo: OneOrMany<String>,
    pub procs: OneOrMany<u32>,
    /// Frames: "A..B" (B excluded), "A..=B" (B included) or "A"; all frames when absent.
    #[serde(default)]
    pub frames: Option<String>,
    #[serde(default = "default_seed", alias = "seeds")]
    pub seed: OneOrMany<u64>,
    /// Options every point shares, as `sortsim run --set`.
    #[serde(default)]
    pub set: BTreeMap<String, Scalar>,
    /// Options swept: each key takes every value of its list.
    #[serde(default)]
    pub vary: BTreeMap<String, OneOrMany<Scalar>>,
    /// Speedups divide by this scene's one-processor rate instead of each point's own scene
    /// (paper 002's Figure 10 divides every model by the single-processor PLB head).
    #[serde(default)]
    pub speedup_scene: Option<PathBuf>,
    /// Frames at the start of every run left out of the table's means (the runs and their
    /// summary.json keep them): the first frame of a frame-coherent algorithm waits for no
    /// region assignment, which in a run of a few frames would weigh far more than in a
    /// viewing sequence. Needs `frames` with more frames than this.
    #[serde(default)]
    pub warmup_frames: u32,
}

/// The keys a sweep may also spell in the plural (serde aliases), and whether one of the two
/// spellings is required.
const PLURALS: [(&str, &str, bool); 4] = [
    ("machine", "machines", true),
    ("scene", "scenes", true),
    ("algo", "algos", true),
    ("seed", "seeds", false),
];

/// Adds the plural spellings to the sweep's schema: the same value under either key, and a
/// required key satisfied by either (the derive knows nothing of serde aliases).
fn plural_spellings(schema: &mut schemars::Schema) {
    let Some(object) = schema.as_object_mut() else {
        return;
    };
    let mut either = Vec::new();
    for (one, many, required) in PLURALS {
        if let Some(properties) = object.get_mut("properties").and_then(|p| p.as_object_mut()) {
            if let Some(value) = properties.get(one).cloned() {
                properties.insert(many.to_string(), value);
            }
        }
        if required {
            if let Some(list) = object.get_mut("required").and_then(|r| r.as_array_mut()) {
                list.retain(|k| k != one);
            }
            either.push(serde_json::json!({"oneOf": [{"required": [one]}, {"required": [many]}]}));
        }
    }
    object.insert("allOf".to_string(), serde_json::Value::Array(either));
}

/// One value or a list of them; a single value is a list of one.
#[derive(Clone, Debug, Deserialize, PartialEq, schemars::JsonSchema)]
#[serde(untagged, expecting = "a value or a list of values")]
pub enum OneOrMany<T> {
    One(T),
    Many(Vec<T>),
}

/// An option value: written as a string, a number or a boolean, used as its text.
#[derive(Clone, Debug, Deserialize, PartialEq, schemars::JsonSchema)]
#[serde(untagged, expecting = "a string, a number or a boolean")]
pub enum Scalar {
    Text(String),
    Int(i64),
    Float(f64),
    Bool(bool),
}

/// The dimensions of a sweep, in product order; each names the spec field it came from.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Dim {
    /// `machine`, `scene`, `algo`, `vary.KEY`, `seed` or `procs`.
    pub key: String,
    /// The values as written (paths as written in the sweep file).
    pub values: Vec<String>,
}

/// One simulation of the sweep: the values of every dimension, and the run spec with paths
/// resolved against the sweep file.
#[derive(Clone, Debug, PartialEq)]
pub struct Point {
    /// One value per dimension, in `Sweep::dims` order.
    pub values: Vec<String>,
    pub run: RunSpec,
    /// False for a one-processor point the sweep runs only as a speedup baseline.
    pub listed: bool,
}

/// A validated sweep, with its points in product order followed by the implicit baselines.
#[derive(Clone, Debug)]
pub struct Sweep {
    pub file: PathBuf,
    pub note: Option<String>,
    /// The scene speedups divide by, as written, when not each point's own.
    pub speedup_scene: Option<String>,
    /// Frames at the start of every run the table's means leave out.
    pub warmup_frames: u32,
    pub dims: Vec<Dim>,
    pub points: Vec<Point>,
}

fn default_seed() -> OneOrMany<u64> {
    OneOrMany::One(1)
}

impl<T: Clone> OneOrMany<T> {
    pub fn to_vec(&self) -> Vec<T> {
        match self {
            OneOrMany::One(v) => vec![v.clone()],
            OneOrMany::Many(v) => v.clone(),
        }
    }
}

impl Scalar {
    pub fn text(&self) -> String {
        match self {
            Scalar::Text(s) => s.clone(),
            Scalar::Int(i) => i.to_string(),
            Scalar::Float(f) => f.to_string(),
            Scalar::Bool(b) => b.to_string(),
        }
    }
}

/// Reads, parses and validates a sweep file.
pub fn load_sweep(path: &Path) -> Result<Sweep, SpecError> {
    let spec: SweepSpec = load_json(path)?;
    Sweep::new(path, spec)
}

/// As `load_sweep`, for text in memory; `path` names the file in messages and anchors
/// relative paths.
pub fn parse_sweep(path: &Path, text: &str) -> Result<Sweep, SpecError> {
    let spec: SweepSpec = parse_json(path, text)?;
    Sweep::new(path, spec)
}

impl Sweep {
    /// Checks the lists and expands the product. Runs nothing and loads no machine or scene.
    pub fn new(file: &Path, spec: SweepSpec) -> Result<Sweep, SpecError> {
        let dims = dims(file, &spec)?;
        validate_values(file, &spec)?;
        let count = dims
            .iter()
            .fold(1u128, |n, d| n.saturating_mul(d.values.len() as u128));
        if count > u128::from(crate::limits::MAX_SWEEP_POINTS) {
            return Err(SpecError::invalid(
                file,
                dims.iter()
                    .max_by_key(|d| d.values.len())
                    .map_or("".to_string(), |d| d.key.clone()),
                format!(
                    "this sweep has {count} points ({}); the limit is {} \
                     (sortsim::limits::MAX_SWEEP_POINTS)",
                    dims.iter()
                        .map(|d| format!("{} {}", d.values.len(), d.key))
                        .collect::<Vec<_>>()
                        .join(" x "),
                    crate::limits::MAX_SWEEP_POINTS
                ),
            ));
        }
        let mut points: Vec<Point> = product(&dims)
            .into_iter()
            .map(|values| point(file, &spec, &dims, values, true))
            .collect();
        let speedup_scene = spec.speedup_scene.as_ref().map(|p| p.display().to_string());
        let baselines = implicit_baselines(&dims, &points, speedup_scene.as_deref());
        points.extend(
            baselines
                .into_iter()
                .map(|values| point(file, &spec, &dims, values, false)),
        );
        Ok(Sweep {
            file: file.to_path_buf(),
            note: spec.note.clone(),
            speedup_scene,
            warmup_frames: spec.warmup_frames,
            dims,
            points,
        })
    }

    /// The values of the one-processor point that `values`' speedup divides by.
    pub fn baseline_of(&self, values: &[String]) -> Vec<String> {
        baseline_of(&self.dims, values, self.speedup_scene.as_deref())
    }

    /// Index of a dimension by key.
    pub fn dim(&self, key: &str) -> Option<usize> {
        self.dims.iter().position(|d| d.key == key)
    }

    /// Points the sweep lists (not the implicit baselines).
    pub fn listed(&self) -> impl Iterator<Item = &Point> {
        self.points.iter().filter(|p| p.listed)
    }
}

/// The dimension list in product order. A `vary` key becomes `vary.KEY`.
fn dims(file: &Path, spec: &SweepSpec) -> Result<Vec<Dim>, SpecError> {
    let paths =
        |l: &OneOrMany<PathBuf>| l.to_vec().iter().map(|p| p.display().to_string()).collect();
    let mut dims = vec![
        Dim {
            key: "machine".into(),
            values: paths(&spec.machine),
        },
        Dim {
            key: "scene".into(),
            values: paths(&spec.scene),
        },
        Dim {
            key: "algo".into(),
            values: spec.algo.to_vec(),
        },
    ];
    for (key, values) in &spec.vary {
        if spec.set.contains_key(key) {
            let msg = format!("`{key}` is both in `set` and in `vary`; give it in one place");
            return Err(SpecError::invalid(file, format!("vary.{key}"), msg));
        }
        let values = values.to_vec().iter().map(Scalar::text).collect();
        dims.push(Dim {
            key: format!("vary.{key}"),
            values,
        });
    }
    dims.push(Dim {
        key: "seed".into(),
        values: spec.seed.to_vec().iter().map(u64::to_string).collect(),
    });
    dims.push(Dim {
        key: "procs".into(),
        values: spec.procs.to_vec().iter().map(u32::to_string).collect(),
    });
    for d in &dims {
        check_list(file, d)?;
    }
    Ok(dims)
}

/// Every list has at least one value and no value twice (a repeated point would be run twice
/// and plotted on top of itself).
fn check_list(file: &Path, d: &Dim) -> Result<(), SpecError> {
    if d.values.is_empty() {
        return Err(SpecError::invalid(
            file,
            &d.key,
            "the list is empty; give at least one value",
        ));
    }
    for (i, v) in d.values.iter().enumerate() {
        if d.values[..i].contains(v) {
            return Err(SpecError::invalid(
                file,
                format!("{}[{i}]", d.key),
                format!("`{v}` is listed twice"),
            ));
        }
    }
    Ok(())
}

/// The checks that need no file: algorithm ids and processor counts.
fn validate_values(file: &Path, spec: &SweepSpec) -> Result<(), SpecError> {
    let field = |key: &str, i: usize, many: bool| {
        if many {
            format!("{key}[{i}]")
        } else {
            key.to_string()
        }
    };
    for (i, id) in spec.algo.to_vec().iter().enumerate() {
        if AlgorithmId::from_id(id).is_none() {
            let msg = format!(
                "unknown algorithm `{id}`; valid ids: {}",
                AlgorithmId::valid_ids()
            );
            return Err(SpecError::invalid(
                file,
                field("algo", i, is_many(&spec.algo)),
                msg,
            ));
        }
    }
    let procs = spec.procs.to_vec();
    if let Some(i) = procs.iter().position(|&p| p == 0) {
        let msg = "a run needs at least 1 processor";
        return Err(SpecError::invalid(
            file,
            field("procs", i, is_many(&spec.procs)),
            msg,
        ));
    }
    let mut frame_count = None;
    if let Some(frames) = &spec.frames {
        // The scene's frame count is checked when the scene is loaded; here only the form.
        match crate::spec::run::parse_frames(Some(frames), u32::MAX) {
            Ok(range) => frame_count = Some(range.len() as u32),
            Err(_) => {
                return Err(SpecError::invalid(
                    file,
                    "frames",
                    format!("`{frames}`: write A..B (B excluded) or A"),
                ))
            }
        }
    }
    let warmup = spec.warmup_frames;
    if warmup > 0 && frame_count.is_none_or(|n| n <= warmup) {
        let msg = format!(
            "{warmup} warm-up frames leave no frame to average; give `frames` a range of more than {warmup} frames, or set warmup_frames below the frames run"
        );
        return Err(SpecError::invalid(file, "warmup_frames", msg));
    }
    Ok(())
}

fn is_many<T>(l: &OneOrMany<T>) -> bool {
    matches!(l, OneOrMany::Many(_))
}

/// Every combination of one value per dimension, the last dimension varying fastest.
fn product(dims: &[Dim]) -> Vec<Vec<String>> {
    let mut out: Vec<Vec<String>> = vec![Vec::new()];
    for d in dims {
        out = out
            .into_iter()
            .flat_map(|prefix| {
                d.values.iter().map(move |v| {
                    let mut p = prefix.clone();
                    p.push(v.clone());
                    p
                })
            })
            .collect();
    }
    out
}

/// The one-processor point a speedup divides by: the same values on one processor, with the
/// speedup scene instead of the point's own when the sweep names one.
fn baseline_of(dims: &[Dim], values: &[String], speedup_scene: Option<&str>) -> Vec<String> {
    let mut base = values.to_vec();
    base[dims.len() - 1] = "1".to_string();
    if let (Some(scene), Some(i)) = (speedup_scene, dims.iter().position(|d| d.key == "scene")) {
        base[i] = scene.to_string();
    }
    base
}

/// One-processor points that speedups need but the sweep does not list: one per combination
/// of the other values, in product order.
fn implicit_baselines(
    dims: &[Dim],
    points: &[Point],
    speedup_scene: Option<&str>,
) -> Vec<Vec<String>> {
    let listed: BTreeSet<&[String]> = points.iter().map(|p| p.values.as_slice()).collect();
    let mut added: BTreeSet<Vec<String>> = BTreeSet::new();
    let mut out: Vec<Vec<String>> = Vec::new();
    for p in points {
        let base = baseline_of(dims, &p.values, speedup_scene);
        if !listed.contains(base.as_slice()) && added.insert(base.clone()) {
            out.push(base);
        }
    }
    out
}

fn point(file: &Path, spec: &SweepSpec, dims: &[Dim], values: Vec<String>, listed: bool) -> Point {
    let value = |key: &str| {
        let i = dims
            .iter()
            .position(|d| d.key == key)
            .expect("fixed dimensions exist");
        values[i].clone()
    };
    let mut set: BTreeMap<String, String> = spec
        .set
        .iter()
        .map(|(k, v)| (k.clone(), v.text()))
        .collect();
    for (d, v) in dims.iter().zip(&values) {
        if let Some(key) = d.key.strip_prefix("vary.") {
            set.insert(key.to_string(), v.clone());
        }
    }
    let run = RunSpec {
        schema: None,
        machine: relative_to(file, Path::new(&value("machine"))),
        scene: relative_to(file, Path::new(&value("scene"))),
        algo: value("algo"),
        procs: value("procs").parse().expect("procs values come from u32"),
        frames: spec.frames.clone(),
        seed: value("seed").parse().expect("seed values come from u64"),
        set,
    };
    Point {
        values,
        run,
        listed,
    }
}
