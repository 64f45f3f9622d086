//! `sortsim calibrate`: fit a machine's free cost parameters, or a stand-in scene's free
//! shape parameters, to every numeric target of a paper at once. A calibration spec names
//! the file it fits (`machine` or `scene`), the paper, the rows of `papers/NNN.json` to fit
//! and the parameters (groups of the file's fields scaled by one factor each); the fit runs
//! the paper's experiments (`paper::run_paper`) on candidate files and minimises the sum of
//! squared deviations, each measured in units of its row's tolerance, with Nelder-Mead
//! (argmin) over the logarithms of the factors.
//!
//! ```text
//! spec ─> start file ─> Nelder-Mead: factors ─> candidate machine or scene ─> run_paper ─> cost
//!                                 best factors ─> fitted file (source updated) + residual table
//! ```
//!
//! A target must be a row the data file marks `fitted` (a refit) or, when told
//! (`--allow-predicted`), `predicted`; inputs and definitions are never targets. The fitted
//! file's `fitted_to` gains a record of the rows the fit saw, which `sortsim paper` checks
//! against the rows' roles. `--hold-out` leaves targets out of the fit and reports how the
//! fitted file does on them: a prediction of the fit, not a target of it.
//!
//! Owns the objective and the scaling of spec fields. Must never change how a run
//! simulates, nor invent a target: targets are the paper's rows, with their own tolerances.
//! Deterministic: the same spec gives the same fit and the same files.

use std::path::{Path, PathBuf};
use std::sync::Mutex;

use argmin::core::{CostFunction, Executor, State};
use argmin::solver::neldermead::NelderMead;
use serde::{Deserialize, Serialize};

use crate::paper::data::{Reference, Relation, Role, Tolerance};
use crate::paper::{run_paper, PaperId, PaperOptions, PaperReport, Verdict};
use crate::spec::machine::FitRecord;
use crate::units::{Bandwidth, SimTime};

/// A calibration spec file.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CalibrationSpec {
    #[serde(rename = "$schema", default)]
    pub schema: Option<String>,
    #[serde(default)]
    pub note: Option<String>,
    /// The machine file to fit, relative to the spec's folder (or give `scene`).
    #[serde(default)]
    pub machine: Option<PathBuf>,
    /// The scene file to fit, relative to the spec's folder (or give `machine`): a stand-in
    /// whose shape the paper does not give, pinned down by the rows it moves.
    #[serde(default)]
    pub scene: Option<PathBuf>,
    /// The bundled file (in `machines/` or `scenes/`) the candidates stand in for in the
    /// paper's experiments; the fitted file's own name when absent.
    #[serde(default)]
    pub replaces: Option<String>,
    /// The paper whose rows are the targets: "000" .. "003".
    pub paper: String,
    /// Row ids of papers/NNN.json; each must have a number (value or range).
    pub targets: Vec<String>,
    pub parameters: Vec<Parameter>,
    /// Run the paper's experiments with `--quick` frame counts.
    #[serde(default)]
    pub quick: bool,
    /// The most runs of the paper's experiments the search may spend (the start is one of
    /// them; the final run of the fitted machine comes on top).
    #[serde(default = "default_evaluations")]
    pub max_evaluations: u32,
}

fn default_evaluations() -> u32 {
    24
}

/// What a calibration fits: the bundled machines or the bundled scenes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Subject {
    Machine,
    Scene,
}

impl Subject {
    /// The repository folder its bundled files live in.
    pub fn folder(self) -> &'static str {
        match self {
            Subject::Machine => "machines",
            Subject::Scene => "scenes",
        }
    }

    fn noun(self) -> &'static str {
        match self {
            Subject::Machine => "machine",
            Subject::Scene => "scene",
        }
    }

    /// The free-text field a fit appends its summary to.
    fn source_field(self) -> &'static str {
        match self {
            Subject::Machine => "source",
            Subject::Scene => "description",
        }
    }
}

impl CalibrationSpec {
    /// What the spec fits and the file, relative to the working folder; `None` unless it
    /// names exactly one of `machine` and `scene` (`load_spec` refuses such a spec).
    pub fn subject(&self) -> Option<(Subject, &Path)> {
        match (&self.machine, &self.scene) {
            (None, Some(scene)) => Some((Subject::Scene, scene)),
            (Some(machine), None) => Some((Subject::Machine, machine)),
            _ => None,
        }
    }
}

/// One free parameter: every listed field multiplied by the same factor.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Parameter {
    pub name: String,
    /// Dotted paths into the spec holding a time, a bandwidth or a number
    /// ("cpu.send_overhead", "geometry.0.generator.footprint": a number indexes a list);
    /// `path.*` scales every entry of the object at `path` ("cpu.costs.*").
    pub fields: Vec<String>,
    /// The smallest and largest factor allowed.
    pub range: [f64; 2],
}

#[derive(Debug, thiserror::Error)]
pub enum CalibrationError {
    /// The spec, the machine or a target is not usable: bad input.
    #[error("{}: {message}", file.display())]
    Spec { file: PathBuf, message: String },
    /// An experiment or the optimiser failed.
    #[error("calibration failed: {0}")]
    Failed(String),
}

/// How to fit, beside the spec.
#[derive(Clone, Debug, Default)]
pub struct FitOptions {
    /// Simulations at a time.
    pub jobs: usize,
    /// Targets of the spec left out of the fit; their residuals are reported afterwards.
    pub hold_out: Vec<String>,
    /// Fit rows the data file marks `predicted` (they become fitted: relabel them after).
    pub allow_predicted: bool,
}

/// The outcome: the factors found, the fitted file's JSON text, and the targets' rows at
/// the start and at the fit.
#[derive(Debug, Serialize)]
pub struct Calibration {
    pub paper: String,
    /// The fitted file's name (a machine or a scene, as `subject` says).
    pub file: String,
    pub subject: &'static str,
    pub factors: Vec<(String, f64)>,
    pub evaluations: u32,
    pub start_cost: f64,
    pub fitted_cost: f64,
    pub rows: Vec<Residual>,
    /// The held-out targets: not in the cost, measured on the start and the fitted machine.
    pub held_out: Vec<Residual>,
    #[serde(skip)]
    pub fitted_text: String,
}

/// One target before and after the fit.
#[derive(Debug, Serialize)]
pub struct Residual {
    pub id: String,
    pub quantity: String,
    pub unit: String,
    pub paper: String,
    pub start: Option<f64>,
    pub fitted: Option<f64>,
    pub fitted_deviation_pct: Option<f64>,
    pub tolerance: String,
    pub fitted_verdict: Verdict,
}

/// Reads and checks the calibration spec at `path`.
pub fn load_spec(path: &Path) -> Result<CalibrationSpec, CalibrationError> {
    let text = crate::spec::read_input(path).map_err(|e| CalibrationError::Spec {
        file: path.to_path_buf(),
        message: e.to_string(),
    })?;
    parse_spec(path, &text)
}

/// Reads and checks a calibration spec from `text`, the contents of `path` (which errors name,
/// and beside which its machine or scene file is found).
pub fn parse_spec(path: &Path, text: &str) -> Result<CalibrationSpec, CalibrationError> {
    let fail = |message: String| CalibrationError::Spec {
        file: path.to_path_buf(),
        message,
    };
    let de = &mut serde_json::Deserializer::from_str(text);
    let mut spec: CalibrationSpec = serde_path_to_error::deserialize(de)
        .map_err(|e| fail(format!("at {}: {}", e.path(), e.inner())))?;
    match (&mut spec.machine, &mut spec.scene) {
        (Some(file), None) | (None, Some(file)) => {
            *file = crate::spec::run::relative_to(path, file)
        }
        (Some(_), Some(_)) => {
            return Err(fail(
                "give \"machine\" or \"scene\" (the file the fit changes), not both".into(),
            ))
        }
        (None, None) => {
            return Err(fail(
                "give \"machine\" or \"scene\": the file the fit changes".into(),
            ))
        }
    }
    if spec.parameters.is_empty() || spec.targets.is_empty() {
        return Err(fail("give at least one target and one parameter".into()));
    }
    for p in &spec.parameters {
        let [lo, hi] = p.range;
        if !(lo > 0.0 && lo <= 1.0 && hi >= 1.0 && hi.is_finite()) {
            return Err(fail(format!(
                "parameter {:?}: range [{lo}, {hi}] must hold the factor 1 and be positive",
                p.name
            )));
        }
    }
    if spec.max_evaluations < 2 {
        return Err(fail("max_evaluations must be at least 2".into()));
    }
    Ok(spec)
}

/// The spec (a machine's or a scene's JSON) with each parameter's fields multiplied by its
/// factor.
pub fn scaled_spec(
    spec: &serde_json::Value,
    parameters: &[Parameter],
    factors: &[f64],
) -> Result<serde_json::Value, String> {
    let mut m = spec.clone();
    for (p, &f) in parameters.iter().zip(factors) {
        for field in &p.fields {
            let (path, all) = match field.strip_suffix(".*") {
                Some(path) => (path, true),
                None => (field.as_str(), false),
            };
            let mut here = &mut m;
            for key in path.split('.') {
                here = field_mut(here, key).ok_or_else(|| format!("there is no field `{path}`"))?;
            }
            if all {
                let obj = here
                    .as_object_mut()
                    .ok_or_else(|| format!("`{path}` is not an object"))?;
                for v in obj.values_mut() {
                    *v = scale_quantity(v, f).map_err(|e| format!("{field}: {e}"))?;
                }
            } else {
                *here = scale_quantity(here, f).map_err(|e| format!("{field}: {e}"))?;
            }
        }
    }
    Ok(m)
}

/// The field `key` of an object, or the entry of a list a number names.
fn field_mut<'v>(v: &'v mut serde_json::Value, key: &str) -> Option<&'v mut serde_json::Value> {
    match v {
        serde_json::Value::Array(items) => items.get_mut(key.parse::<usize>().ok()?),
        _ => v.get_mut(key),
    }
}

/// A time or bandwidth string times `factor`, in integer picoseconds or bytes per second; a
/// number times `factor`, rounded when the number was a whole one (a count stays a count).
fn scale_quantity(v: &serde_json::Value, factor: f64) -> Result<serde_json::Value, String> {
    if let Some(n) = v.as_u64() {
        return Ok(((n as f64 * factor).round() as u64).into());
    }
    if let Some(x) = v.as_f64() {
        return serde_json::Number::from_f64(x * factor)
            .map(serde_json::Value::Number)
            .ok_or_else(|| format!("{x} x {factor} is not a finite number"));
    }
    let text = v
        .as_str()
        .ok_or_else(|| format!("{v} is not a time, a bandwidth or a number"))?;
    if let Ok(t) = text.parse::<SimTime>() {
        let ps = (t.ps() as f64 * factor).round() as u64;
        return Ok(format!("{ps}ps").into());
    }
    if let Ok(b) = text.parse::<Bandwidth>() {
        let bps = (b.bytes_per_s_f64() * factor).round().max(1.0) as u64;
        return Ok(format!("{bps}B/s").into());
    }
    Err(format!("{text:?} is not a time, a bandwidth or a number"))
}

/// How far a row is from its paper value, in units of its tolerance (0 inside a bound or
/// range); a row without a number costs as much as ten tolerances.
pub fn row_cost(reference: &Reference, measured: Option<f64>) -> f64 {
    let Some(m) = measured.filter(|m| m.is_finite()) else {
        return 100.0;
    };
    let Some(dev) = reference.deviation_pct(m) else {
        // A bound: free inside, 10% of the bound per unit outside.
        let v = reference.value.unwrap_or(0.0);
        let outside = match reference.relation {
            Relation::Below if m >= v => (m - v) / v.abs().max(1e-12),
            Relation::Above if m <= v => (v - m) / v.abs().max(1e-12),
            _ => 0.0,
        };
        return (outside / 0.10).powi(2);
    };
    let unit_pct = match (reference.tolerance, reference.value) {
        (Some(Tolerance::RelativePct(p)), _) => p,
        (Some(Tolerance::Absolute(a)), Some(v)) if v != 0.0 => 100.0 * a / v.abs(),
        _ => 10.0,
    };
    (dev / unit_pct).powi(2)
}

struct Objective<'a> {
    spec: &'a CalibrationSpec,
    /// The targets in the cost: the spec's, less the held-out ones.
    fitting: Vec<String>,
    held_out: Vec<String>,
    /// The spec as the fitted file's record names it (relative to its folder when under it).
    spec_name: String,
    subject: Subject,
    /// The file being fitted, as JSON.
    start: serde_json::Value,
    id: PaperId,
    options: PaperOptions,
    work: PathBuf,
    file_name: String,
    evaluations: Mutex<u32>,
    /// The first experiment failure during the search.
    failure: Mutex<Option<String>>,
}

impl Objective<'_> {
    fn factors(&self, x: &[f64]) -> Vec<f64> {
        x.iter()
            .zip(&self.spec.parameters)
            .map(|(&x, p)| x.exp().clamp(p.range[0], p.range[1]))
            .collect()
    }

    fn report(&self, factors: &[f64]) -> Result<PaperReport, String> {
        let candidate = scaled_spec(&self.start, &self.spec.parameters, factors)?;
        let text = serde_json::to_string_pretty(&candidate).map_err(|e| e.to_string())?;
        std::fs::write(self.work.join(&self.file_name), text).map_err(|e| e.to_string())?;
        *self.evaluations.lock().unwrap_or_else(|e| e.into_inner()) += 1;
        run_paper(self.id, &self.options).map_err(|e| e.to_string())
    }

    fn cost_of(&self, report: &PaperReport, data: &crate::paper::PaperData) -> f64 {
        self.fitting
            .iter()
            .map(|id| {
                let reference = data.rows.iter().find(|r| &r.id == id).expect("checked");
                let row = report.row(id).expect("every row is reported");
                row_cost(reference, row.sortsim)
            })
            .sum()
    }
}

/// The objective as argmin sees it (a borrow, so the fit keeps the objective afterwards).
struct Problem<'a, 'b> {
    objective: &'a Objective<'b>,
    data: &'a crate::paper::PaperData,
}

impl CostFunction for Problem<'_, '_> {
    type Param = Vec<f64>;
    type Output = f64;

    fn cost(&self, x: &Vec<f64>) -> Result<f64, argmin::core::Error> {
        let o = self.objective;
        // The budget is hard: past it a point costs nothing to evaluate and is never better,
        // so the remaining steps end at once and the best point so far stands.
        if *o.evaluations.lock().unwrap_or_else(|e| e.into_inner()) >= o.spec.max_evaluations {
            return Ok(f64::INFINITY);
        }
        // An experiment that fails ends the fit with its message; argmin's Nelder-Mead
        // unwraps the cost of some steps, so the failure is kept here and reported after.
        match o.report(&o.factors(x)) {
            Ok(report) => Ok(o.cost_of(&report, self.data)),
            Err(e) => {
                let mut failure = o.failure.lock().unwrap_or_else(|e| e.into_inner());
                failure.get_or_insert(e);
                Ok(f64::INFINITY)
            }
        }
    }
}

/// What a spec fits, checked against the paper's data and the fitted file before any run.
struct Prepared {
    id: PaperId,
    data: crate::paper::PaperData,
    subject: Subject,
    start: serde_json::Value,
    /// The bundled file the candidates stand in for.
    file_name: String,
}

/// Checks a calibration spec as `sortsim calibrate` would (its targets against the paper's
/// rows and roles, its machine and parameter fields), short of running anything: the line
/// `sortsim check` prints for it.
pub fn check(spec_file: &Path, root: &Path) -> Result<String, CalibrationError> {
    let spec = load_spec(spec_file)?;
    let options = FitOptions {
        jobs: 1,
        hold_out: Vec::new(),
        allow_predicted: false,
    };
    let prepared = prepare(&spec, spec_file, root, &options)?;
    Ok(format!(
        "calibration of {} to paper {}: {} targets, parameters {}",
        prepared.file_name,
        spec.paper,
        spec.targets.len(),
        spec.parameters
            .iter()
            .map(|p| format!("{:?} {:?}", p.name, p.range))
            .collect::<Vec<_>>()
            .join(", ")
    ))
}

/// Checks `spec` as [`calibrate`] will, with these options, before anything is written or run.
pub fn validate(
    spec: &CalibrationSpec,
    spec_file: &Path,
    root: &Path,
    fit_options: &FitOptions,
) -> Result<(), CalibrationError> {
    prepare(spec, spec_file, root, fit_options).map(|_| ())
}

/// Fits the spec's parameters; `root` is the repository (scenes/, papers/, machines/).
pub fn calibrate(
    spec: &CalibrationSpec,
    spec_file: &Path,
    root: &Path,
    fit_options: &FitOptions,
) -> Result<Calibration, CalibrationError> {
    let Prepared {
        id,
        data,
        subject,
        start,
        file_name,
    } = prepare(spec, spec_file, root, fit_options)?;
    // The candidates live beside copies of every bundled file of their kind, since a paper's
    // experiments may use several.
    let dir =
        tempdir_for_candidates(&root.join(subject.folder())).map_err(CalibrationError::Failed)?;
    let work = dir.path().to_path_buf();
    let objective = Objective {
        spec,
        subject,
        start,
        id,
        fitting: spec
            .targets
            .iter()
            .filter(|t| !fit_options.hold_out.contains(t))
            .cloned()
            .collect(),
        held_out: fit_options.hold_out.clone(),
        spec_name: spec_name(spec_file, &root.join(subject.folder())),
        options: PaperOptions {
            quick: spec.quick,
            jobs: fit_options.jobs,
            root: root.to_path_buf(),
            machines: (subject == Subject::Machine).then(|| work.clone()),
            scenes: (subject == Subject::Scene).then(|| work.clone()),
        },
        work: work.clone(),
        file_name,
        evaluations: Mutex::new(0),
        failure: Mutex::new(None),
    };
    fit(&objective, &data)
}

fn prepare(
    spec: &CalibrationSpec,
    spec_file: &Path,
    root: &Path,
    fit_options: &FitOptions,
) -> Result<Prepared, CalibrationError> {
    let bad = |message: String| CalibrationError::Spec {
        file: spec_file.to_path_buf(),
        message,
    };
    let id = PaperId::from_id(&spec.paper).ok_or_else(|| {
        bad(format!(
            "paper {:?}: expected 000, 001, 002 or 003",
            spec.paper
        ))
    })?;
    let data = crate::paper::data::load(root, id).map_err(|e| bad(e.to_string()))?;
    for t in &spec.targets {
        match data.rows.iter().find(|r| &r.id == t) {
            None => {
                return Err(bad(format!(
                    "target {t:?} is not a row of papers/{}.json",
                    spec.paper
                )))
            }
            Some(r) if r.value.is_none() && r.range.is_none() => {
                return Err(bad(format!("target {t:?} is a claim without a number")))
            }
            Some(r) => check_target_role(r, &spec.paper, fit_options).map_err(&bad)?,
        }
    }
    for h in &fit_options.hold_out {
        if !spec.targets.contains(h) {
            return Err(bad(format!(
                "--hold-out {h:?} is not one of the spec's targets ({})",
                spec.targets.join(", ")
            )));
        }
    }
    if spec
        .targets
        .iter()
        .all(|t| fit_options.hold_out.contains(t))
    {
        return Err(bad(
            "--hold-out leaves no target to fit; hold out fewer rows".into(),
        ));
    }
    // The file as `check` reads it (field paths), then as the candidates are built from.
    let (subject, file) = spec.subject().ok_or_else(|| {
        bad("give \"machine\" or \"scene\": the file the fit changes, one of them".into())
    })?;
    match subject {
        Subject::Machine => crate::spec::machine::load_machine(file).map(|_| ()),
        Subject::Scene => crate::spec::scene::load(file).map(|_| ()),
    }
    .map_err(|e| bad(e.to_string()))?;
    let text =
        crate::spec::read_input(file).map_err(|e| bad(format!("{}: {e}", file.display())))?;
    let start: serde_json::Value =
        crate::spec::parse_json(file, &text).map_err(|e| bad(e.to_string()))?;
    scaled_spec(&start, &spec.parameters, &vec![1.0; spec.parameters.len()])
        .map_err(|e| bad(format!("{}: {e}", file.display())))?;
    let file_name = match &spec.replaces {
        Some(name) => name.clone(),
        None => file
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .ok_or_else(|| bad(format!("the {} has no file name", subject.noun())))?,
    };
    // A candidate under any other name would sit unused beside the bundled files, and the
    // fit would search a flat cost.
    let folder = subject.folder();
    if !root.join(folder).join(&file_name).is_file() {
        return Err(bad(format!(
            "{file_name} is not a {} in {folder}/, so the paper's experiments would not run on the candidates; \
             name the bundled {} the fitted one stands in for with \"replaces\" (e.g. \"{}\")",
            subject.noun(),
            subject.noun(),
            match subject {
                Subject::Machine => "delta.json",
                Subject::Scene => "p003-brooks.json",
            }
        )));
    }
    Ok(Prepared {
        id,
        data,
        subject,
        start,
        file_name,
    })
}

fn fit(
    objective: &Objective,
    data: &crate::paper::PaperData,
) -> Result<Calibration, CalibrationError> {
    let failed = |e: String| CalibrationError::Failed(e);
    let spec = objective.spec;
    let n = spec.parameters.len();
    let start_factors = vec![1.0; n];
    let start = objective.report(&start_factors).map_err(failed)?;
    let start_cost = objective.cost_of(&start, data);
    // The simplex: the start and one point per parameter, a factor 1.5 away (toward the
    // larger end of its range when 1.5 is outside it).
    let mut simplex = vec![vec![0.0; n]];
    for (i, p) in spec.parameters.iter().enumerate() {
        let mut x = vec![0.0; n];
        x[i] = if p.range[1] >= 1.5 {
            1.5f64.ln()
        } else {
            (1.0 / 1.5f64).ln()
        };
        simplex.push(x);
    }
    let solver = NelderMead::new(simplex)
        .with_sd_tolerance(1e-3)
        .map_err(|e| failed(e.to_string()))?;
    // The simplex costs n + 1 runs, each later step one or two (a shrink n + 1); `cost`
    // stops running once max_evaluations is spent, so the step count only bounds the loop.
    let iterations = u64::from(spec.max_evaluations).max(1);
    let run = Executor::new(Problem { objective, data }, solver)
        .configure(|state| state.max_iters(iterations))
        .run()
        .map_err(|e| failed(e.to_string()))?;
    if let Some(e) = objective
        .failure
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .take()
    {
        return Err(failed(e));
    }
    let best = run
        .state()
        .get_best_param()
        .cloned()
        .unwrap_or_else(|| vec![0.0; n]);
    let factors = objective.factors(&best);
    let fitted = objective.report(&factors).map_err(failed)?;
    let fitted_cost = objective.cost_of(&fitted, data);
    let evaluations = *objective
        .evaluations
        .lock()
        .unwrap_or_else(|e| e.into_inner());
    let residuals = |ids: &[String]| -> Vec<Residual> {
        ids.iter()
            .map(|id| {
                let (s, f) = (
                    start.row(id).expect("reported"),
                    fitted.row(id).expect("reported"),
                );
                Residual {
                    id: id.clone(),
                    quantity: f.quantity.clone(),
                    unit: f.unit.clone(),
                    paper: f.paper.clone(),
                    start: s.sortsim,
                    fitted: f.sortsim,
                    fitted_deviation_pct: f.deviation_pct,
                    tolerance: f.tolerance.clone(),
                    fitted_verdict: f.verdict,
                }
            })
            .collect()
    };
    let rows = residuals(&objective.fitting);
    let held_out = residuals(&objective.held_out);
    let named: Vec<(String, f64)> = spec
        .parameters
        .iter()
        .zip(&factors)
        .map(|(p, &f)| (p.name.clone(), f))
        .collect();
    let mut fitted_spec =
        scaled_spec(&objective.start, &spec.parameters, &factors).map_err(failed)?;
    let source_field = objective.subject.source_field();
    let source = fitted_spec
        .get(source_field)
        .and_then(|s| s.as_str())
        .unwrap_or("")
        .to_string();
    let held_out_text = if held_out.is_empty() {
        String::new()
    } else {
        format!(
            " Held out of this fit: {}.",
            held_out
                .iter()
                .map(|r| format!(
                    "{} {} ({})",
                    r.id,
                    r.fitted_deviation_pct
                        .map_or("no number".to_string(), |d| format!("{d:+.1}%")),
                    r.fitted_verdict.label()
                ))
                .collect::<Vec<_>>()
                .join(", ")
        )
    };
    let mut records: Vec<FitRecord> = match fitted_spec.get("fitted_to") {
        Some(v) => serde_json::from_value(v.clone())
            .map_err(|e| failed(format!("the fitted file's fitted_to: {e}")))?,
        None => Vec::new(),
    };
    // A refit from its own output replaces its record rather than repeating it.
    records.retain(|r| r.spec.as_deref() != Some(objective.spec_name.as_str()));
    records.push(FitRecord {
        paper: spec.paper.clone(),
        rows: objective.fitting.clone(),
        spec: Some(objective.spec_name.clone()),
    });
    fitted_spec["fitted_to"] = serde_json::to_value(&records).map_err(|e| failed(e.to_string()))?;
    // The fitted file stands in for a bundled one (in machines/ or scenes/), so it names its
    // schema from there, wherever the start lay.
    if fitted_spec.get("$schema").is_some() {
        fitted_spec["$schema"] =
            format!("../schemas/{}.schema.json", objective.subject.noun()).into();
    }
    fitted_spec[source_field] = format!(
        "{source} Fitted by sortsim calibrate to paper {} ({}): {}; cost {:.3} (start {:.3}) over {} runs.{held_out_text}",
        spec.paper,
        objective.fitting.join(", "),
        named
            .iter()
            .map(|(n, f)| format!("{n} x{f:.4}"))
            .collect::<Vec<_>>()
            .join(", "),
        fitted_cost,
        start_cost,
        evaluations
    )
    .trim()
    .into();
    let mut fitted_text =
        serde_json::to_string_pretty(&fitted_spec).map_err(|e| failed(e.to_string()))?;
    fitted_text.push('\n');
    Ok(Calibration {
        paper: spec.paper.clone(),
        file: objective.file_name.clone(),
        subject: objective.subject.noun(),
        factors: named,
        evaluations,
        start_cost,
        fitted_cost,
        rows,
        held_out,
        fitted_text,
    })
}

/// Whether a row may be a target: a refit of a fitted row, a predicted row when told, never
/// an input or a definition.
fn check_target_role(r: &Reference, paper: &str, options: &FitOptions) -> Result<(), String> {
    match r.role {
        Role::Fitted => Ok(()),
        Role::Predicted if options.allow_predicted => Ok(()),
        Role::Predicted => Err(format!(
            "target {:?} is a predicted row of papers/{paper}.json: fitting to it would turn the \
             evidence it gives into a fit. Hold it out (--hold-out {}) to see how the fit predicts \
             it, or pass --allow-predicted and then mark it \"role\": \"fitted\" with the machine \
             in \"fit\"",
            r.id, r.id
        )),
        Role::Input | Role::Definition => Err(format!(
            "target {:?} is {} row of papers/{paper}.json (no fit can move it); \
             fit fitted or predicted rows",
            r.id,
            if r.role == Role::Input {
                "an input"
            } else {
                "a definition"
            }
        )),
    }
}

/// The spec's path as a fit record names it: relative to `folder` (the fitted file's bundled
/// folder) when it lies there.
fn spec_name(spec_file: &Path, folder: &Path) -> String {
    let absolute = |p: &Path| std::fs::canonicalize(p).unwrap_or_else(|_| p.to_path_buf());
    let (file, folder) = (absolute(spec_file), absolute(folder));
    file.strip_prefix(&folder)
        .unwrap_or(&file)
        .to_string_lossy()
        .replace('\\', "/")
}

/// A fresh temporary folder holding a copy of every file of `bundled` (the machines or the
/// scenes, with the meshes scenes name beside them), deleted when dropped (also when the fit
/// fails).
fn tempdir_for_candidates(bundled: &Path) -> Result<tempfile::TempDir, String> {
    let dir = tempfile::Builder::new()
        .prefix("sortsim-calibrate-")
        .tempdir()
        .map_err(|e| format!("cannot make a temporary folder: {e}"))?;
    let entries = std::fs::read_dir(bundled).map_err(|e| format!("{}: {e}", bundled.display()))?;
    for e in entries.filter_map(|e| e.ok()) {
        if e.path().is_file() {
            std::fs::copy(e.path(), dir.path().join(e.file_name()))
                .map_err(|err| format!("{}: {err}", e.path().display()))?;
        }
    }
    Ok(dir)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_scale_by_their_factor_in_integer_units() {
        let m = serde_json::json!({"cpu": {"send_overhead": "122us", "costs": {"a": "2us", "b": "10ns"}},
                                   "network": {"link_bandwidth": "17MB/s"}});
        let params = vec![
            Parameter {
                name: "o".into(),
                fields: vec!["cpu.send_overhead".into()],
                range: [0.5, 2.0],
            },
            Parameter {
                name: "c".into(),
                fields: vec!["cpu.costs.*".into()],
                range: [0.5, 2.0],
            },
            Parameter {
                name: "b".into(),
                fields: vec!["network.link_bandwidth".into()],
                range: [0.5, 2.0],
            },
        ];
        let s = scaled_spec(&m, &params, &[0.5, 2.0, 0.25]).unwrap();
        assert_eq!(s["cpu"]["send_overhead"], "61000000ps");
        assert_eq!(s["cpu"]["costs"]["a"], "4000000ps");
        assert_eq!(s["cpu"]["costs"]["b"], "20000ps");
        assert_eq!(s["network"]["link_bandwidth"], "4250000B/s");
        assert!(scaled_spec(
            &m,
            &[Parameter {
                name: "x".into(),
                fields: vec!["cpu.nothing".into()],
                range: [0.5, 2.0]
            }],
            &[1.0]
        )
        .is_err());
    }

    #[test]
    fn numbers_scale_and_list_entries_are_named_by_their_index() {
        let scene = serde_json::json!({"geometry": [{"generator": {"footprint": 1.0}},
                                                   {"generator": {"footprint": 0.5}}]});
        let params = vec![Parameter {
            name: "f".into(),
            fields: vec!["geometry.1.generator.footprint".into()],
            range: [0.1, 1.0],
        }];
        let s = scaled_spec(&scene, &params, &[0.4]).unwrap();
        assert_eq!(s["geometry"][1]["generator"]["footprint"], 0.2);
        assert_eq!(s["geometry"][0]["generator"]["footprint"], 1.0);
        // A count stays a whole number.
        let counts = serde_json::json!({"count": 9345});
        let params = vec![Parameter {
            name: "n".into(),
            fields: vec!["count".into()],
            range: [0.5, 2.0],
        }];
        assert_eq!(
            scaled_spec(&counts, &params, &[0.5]).unwrap()["count"],
            4673
        );
        for bad in [
            "geometry.2.generator.footprint",
            "geometry.x.generator.footprint",
        ] {
            let params = vec![Parameter {
                name: "f".into(),
                fields: vec![bad.into()],
                range: [0.1, 1.0],
            }];
            let e = scaled_spec(&scene, &params, &[1.0]).unwrap_err();
            assert!(e.contains("no field"), "{bad}: {e}");
        }
    }

    fn reference(value: f64, tolerance: Option<Tolerance>, relation: Relation) -> Reference {
        serde_json::from_value::<Reference>(serde_json::json!({
            "id": "x", "figure": "F", "location": "S", "quantity": "q", "role": "fitted",
            "fit": "m.json", "value": value
        }))
        .map(|mut r| {
            r.tolerance = tolerance;
            r.relation = relation;
            r
        })
        .unwrap()
    }

    #[test]
    fn a_rows_cost_is_its_deviation_in_tolerances() {
        let r = reference(2.8, Some(Tolerance::RelativePct(10.0)), Relation::Equals);
        assert!((row_cost(&r, Some(2.8)) - 0.0).abs() < 1e-12);
        // 20% off with a 10% tolerance: two tolerances, cost 4.
        assert!((row_cost(&r, Some(3.36)) - 4.0).abs() < 1e-9);
        assert_eq!(row_cost(&r, None), 100.0);
        let r = reference(50.0, Some(Tolerance::Absolute(10.0)), Relation::Equals);
        // 50 points off with a 10-point tolerance on 50: 5 tolerances.
        assert!((row_cost(&r, Some(100.0)) - 25.0).abs() < 1e-9);
        let r = reference(7.0, None, Relation::Below);
        assert_eq!(row_cost(&r, Some(3.0)), 0.0);
        assert!(row_cost(&r, Some(7.7)) > 0.9);
    }
}
