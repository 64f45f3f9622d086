//! The papers' numbers, one data file per paper (`papers/NNN.json`): each row a quantity the
//! paper prints or a claim it makes, with its figure or table, where in the text it stands,
//! the words it is quoted from, the tolerance sortsim is held to and, where sortsim is known
//! to differ, why.
//!
//! Every row says what it is (`role`): an `input` read back, a `definition` true by
//! construction, a `fitted` calibration target naming the machine (or stand-in scene) fitted
//! to it, or a `predicted` number nothing was tuned to. The fitted rows are exactly those
//! that the bundled machines' and scenes' `fitted_to` records list, checked at load, so roles
//! cannot drift from the fits.
//!
//! Owns the file format, the roles' consistency with the fits, and how a row prints its
//! claim and deviation. Must never hold a measured value.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::{PaperError, PaperId};
use crate::spec::machine::FitRecord;

/// A paper's data file.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PaperData {
    #[serde(rename = "$schema", default)]
    pub schema: Option<String>,
    pub paper: String,
    pub title: String,
    pub rows: Vec<Reference>,
}

/// One number or claim of a paper.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Reference {
    /// Stable key: the tests and the experiments name rows by it.
    pub id: String,
    /// The figure or table the row belongs to ("Table 1", "Figure 9"); rows are grouped by it.
    pub figure: String,
    /// Where the number stands: the section (the plain-text copies carry no page numbers).
    pub location: String,
    pub quantity: String,
    /// What kind of evidence the row is: only `predicted` rows make a paper's headline.
    pub role: Role,
    /// For a `fitted` row: the bundled machine file (in `machines/`, by its name:
    /// `delta.json`) or stand-in scene (`scenes/p003-brooks.json`) whose `fitted_to`
    /// records list it. Only fitted rows name one.
    #[serde(default)]
    pub fit: Option<String>,
    #[serde(default)]
    pub unit: String,
    /// The paper's number, in `unit`, with the digits the paper prints.
    #[serde(default)]
    pub value: Option<f64>,
    /// Decimals the paper prints when the JSON number drops trailing zeros ("2.0", "0.0120").
    #[serde(default)]
    pub decimals: Option<u32>,
    /// How `value` is meant: equal to it (default), or a bound.
    #[serde(default)]
    pub relation: Relation,
    /// The paper gives a range instead of one number.
    #[serde(default)]
    pub range: Option<[f64; 2]>,
    #[serde(default)]
    pub tolerance: Option<Tolerance>,
    /// The paper's words the value or claim is taken from.
    #[serde(default)]
    pub quote: Option<String>,
    /// Why `--quick`'s value of this row is not within the row's tolerance of the full
    /// run's (fewer frames or sampled frames); the quick report marks the row approximate.
    /// `tests/paper.rs` runs both and holds every other row to its tolerance.
    #[serde(default)]
    pub approximate_when_quick: Option<String>,
    /// Why sortsim's number can differ (stand-in scene, a cost the paper does not give, a
    /// model difference); printed when the row holds only in shape or differs.
    #[serde(default)]
    pub why: Option<String>,
}

/// What a row's agreement is evidence of.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Deserialize, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Role {
    /// Nothing was tuned to it: the only rows that test the model.
    Predicted,
    /// A target a machine's costs were fitted to (by `sortsim calibrate` or by hand).
    Fitted,
    /// A parameter read back: a machine or scene was built to this number.
    Input,
    /// True by construction: arithmetic of inputs, or the algorithm doing what it is.
    Definition,
}

impl Role {
    pub const ALL: [Role; 4] = [Role::Predicted, Role::Fitted, Role::Input, Role::Definition];

    pub fn label(self) -> &'static str {
        match self {
            Role::Predicted => "predicted",
            Role::Fitted => "fitted",
            Role::Input => "input",
            Role::Definition => "definition",
        }
    }
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Relation {
    #[default]
    Equals,
    /// "under 5%": sortsim's number must be below the value.
    Below,
    /// "at least": sortsim's number must be above the value.
    Above,
}

/// How far sortsim's number may be from the paper's.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "kebab-case")]
pub enum Tolerance {
    /// In percent of the paper's value.
    RelativePct(f64),
    /// In the row's unit (percentage points for a percentage).
    Absolute(f64),
}

impl Reference {
    /// The paper's side of the row as printed in a table.
    pub fn claim(&self) -> String {
        // The paper's own digits: 0.0002, 2.8, 730, 2.0.
        let n = |v: f64| match self.decimals {
            Some(d) => format!("{v:.*}", d as usize),
            None => format!("{v}"),
        };
        match (self.value, self.range) {
            (_, Some([lo, hi])) => format!("{} .. {}", n(lo), n(hi)),
            (Some(v), None) => match self.relation {
                Relation::Equals => n(v),
                Relation::Below => format!("< {}", n(v)),
                Relation::Above => format!("> {}", n(v)),
            },
            (None, None) => "claim".to_string(),
        }
    }

    /// (sortsim - paper) / paper in percent, against the nearer end of a range (0 inside it).
    pub fn deviation_pct(&self, measured: f64) -> Option<f64> {
        let reference = match (self.value, self.range) {
            (_, Some([lo, hi])) if (lo..=hi).contains(&measured) => return Some(0.0),
            (_, Some([lo, hi])) => {
                if measured < lo {
                    lo
                } else {
                    hi
                }
            }
            // A bound holds or not; a distance to it reads like an error where there is none.
            (Some(_), None) if self.relation != Relation::Equals => return None,
            (Some(v), None) => v,
            (None, None) => return None,
        };
        (reference != 0.0).then(|| 100.0 * (measured - reference) / reference)
    }

    pub fn tolerance_text(&self) -> String {
        match (self.tolerance, self.value, self.range, self.relation) {
            (Some(Tolerance::RelativePct(p)), ..) => format!("±{p}%"),
            (Some(Tolerance::Absolute(a)), ..) => format!("±{a} {}", self.unit),
            (None, _, Some(_), _) => "inside the range".to_string(),
            (None, Some(_), None, Relation::Below) => "the bound".to_string(),
            (None, Some(_), None, Relation::Above) => "the bound".to_string(),
            (None, Some(_), None, Relation::Equals) => "the paper's digits".to_string(),
            (None, None, None, _) => "the claim".to_string(),
        }
    }
}

/// The most digits after the point a row may say its paper prints (`decimals`): more than
/// any paper prints, and more than an f64 value carries, so more is a mistake in the file
/// (and would be printed digit by digit in every report).
pub const MAX_DECIMALS: u32 = 20;

/// Reads and checks `papers/NNN.json` under `root`.
pub fn load(root: &Path, id: PaperId) -> Result<PaperData, PaperError> {
    let path = root.join("papers").join(format!("{}.json", id.id()));
    load_file(root, &path, Some(id))
}

/// Reads and checks a paper file at `path` (the paper `expected`, when given), its fitted rows
/// against the machines under `root`.
pub fn load_file(
    root: &Path,
    path: &Path,
    expected: Option<PaperId>,
) -> Result<PaperData, PaperError> {
    let text = std::fs::read_to_string(path).map_err(|e| PaperError::Data {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    let data = parse(path, &text, expected)?;
    let mut fits = bundled_fits(&root.join("machines"), "")?;
    fits.extend(bundled_fits(&root.join("scenes"), "scenes/")?);
    check_roles(&data, &fits).map_err(|message| PaperError::Data {
        path: path.to_path_buf(),
        message,
    })?;
    Ok(data)
}

/// Reads and checks a paper file from `text`, the contents of `path` (which errors name): all
/// but its fitted rows against the bundled machines and scenes ([`check_roles`]).
pub fn parse(path: &Path, text: &str, expected: Option<PaperId>) -> Result<PaperData, PaperError> {
    let fail = |message: String| PaperError::Data {
        path: path.to_path_buf(),
        message,
    };
    let de = &mut serde_json::Deserializer::from_str(text);
    let data: PaperData = serde_path_to_error::deserialize(de)
        .map_err(|e| fail(format!("at {}: {}", e.path(), e.inner())))?;
    match expected {
        Some(id) if data.paper != id.id() => {
            return Err(fail(format!(
                "\"paper\" is {:?}, expected {:?}",
                data.paper,
                id.id()
            )))
        }
        None if PaperId::from_id(&data.paper).is_none() => {
            return Err(fail(format!(
                "\"paper\" is {:?}; valid: {}",
                data.paper,
                PaperId::ALL.map(|p| p.id()).join(", ")
            )))
        }
        _ => {}
    }
    let mut ids: Vec<&str> = data.rows.iter().map(|r| r.id.as_str()).collect();
    ids.sort_unstable();
    if let Some(w) = ids.windows(2).find(|w| w[0] == w[1]) {
        return Err(fail(format!("row id {:?} appears twice", w[0])));
    }
    for r in &data.rows {
        if let Some(d) = r.decimals.filter(|&d| d > MAX_DECIMALS) {
            return Err(fail(format!(
                "row {}: \"decimals\" is {d}; a paper prints at most {MAX_DECIMALS} digits after the point",
                r.id
            )));
        }
        if r.value.is_some() && r.range.is_some() {
            return Err(fail(format!(
                "row {}: give a value or a range, not both",
                r.id
            )));
        }
        if let (Some(value), Some(tolerance)) = (r.value, r.tolerance) {
            let width = match tolerance {
                Tolerance::RelativePct(pct) => pct / 100.0 * value.abs(),
                Tolerance::Absolute(a) => a,
            };
            // A tolerance as wide as the value passes any answer from 0 to twice the value:
            // such a row cannot fail where it matters.
            if !(width > 0.0 && width < value.abs()) {
                return Err(fail(format!(
                    "row {}: its tolerance, {}, must be above 0 and narrower than the value {value} \
                     itself (a relative tolerance under 100%, an absolute one under {})",
                    r.id,
                    r.tolerance_text(),
                    value.abs()
                )));
            }
        }
        match (r.role, &r.fit) {
            (Role::Fitted, None) => {
                return Err(fail(format!(
                    "row {}: a fitted row names the machine fitted to it in \"fit\" (e.g. \"delta.json\")",
                    r.id
                )))
            }
            (role, Some(_)) if role != Role::Fitted => {
                return Err(fail(format!(
                    "row {}: only a fitted row names a \"fit\"; this one is {}",
                    r.id,
                    role.label()
                )))
            }
            _ => {}
        }
    }
    Ok(data)
}

/// (fitted file as a row's `fit` names it, paper, row) for every row a bundled machine or
/// scene says it was fitted to.
pub type FitList = Vec<(String, String, String)>;

/// Reads the `fitted_to` records of every spec in `dir` (not its subfolders: the
/// intermediate machines under `machines/fits/` are a fit's history, carried forward in the
/// records of the machine it produced), each named `prefix` + its file name.
pub fn bundled_fits(dir: &Path, prefix: &str) -> Result<FitList, PaperError> {
    #[derive(Deserialize)]
    struct Fits {
        #[serde(default)]
        fitted_to: Vec<FitRecord>,
    }
    let entries = std::fs::read_dir(dir).map_err(|e| PaperError::Data {
        path: dir.to_path_buf(),
        message: e.to_string(),
    })?;
    let mut files: Vec<_> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .collect();
    files.sort();
    let mut fits = FitList::new();
    for path in files {
        let spec: Fits = crate::spec::load_json(&path).map_err(|e| PaperError::Data {
            path: path.clone(),
            message: e.to_string(),
        })?;
        let name = path
            .file_name()
            .map(|n| format!("{prefix}{}", n.to_string_lossy()))
            .unwrap_or_default();
        for record in &spec.fitted_to {
            for row in &record.rows {
                fits.push((name.clone(), record.paper.clone(), row.clone()));
            }
        }
    }
    Ok(fits)
}

/// Where a fit's file lives, for messages: a machine under `machines/`, a scene as named.
fn bundled(file: &str) -> String {
    if file.starts_with("scenes/") {
        file.to_string()
    } else {
        format!("machines/{file}")
    }
}

/// A row is `fitted`, naming file M, exactly when M's `fitted_to` lists it: a fit that used a
/// row the data file calls predicted, or a fitted row nothing was fitted to, is a mistake in
/// one of the two files.
pub fn check_roles(data: &PaperData, fits: &FitList) -> Result<(), String> {
    let listed = |machine: &str, row: &str| {
        fits.iter()
            .any(|(m, p, r)| m == machine && p == &data.paper && r == row)
    };
    for r in &data.rows {
        if let (Role::Fitted, Some(machine)) = (r.role, &r.fit) {
            if !listed(machine, &r.id) {
                return Err(format!(
                    "row {} is marked fitted to {machine}, but {} lists no fit to it in \"fitted_to\"",
                    r.id,
                    bundled(machine)
                ));
            }
        }
    }
    for (machine, paper, row) in fits.iter().filter(|(_, p, _)| p == &data.paper) {
        let Some(r) = data.rows.iter().find(|r| &r.id == row) else {
            return Err(format!(
                "{} says it was fitted to paper {paper}'s row {row}, which the data file does not list",
                bundled(machine)
            ));
        };
        if r.role != Role::Fitted || r.fit.as_deref() != Some(machine) {
            return Err(format!(
                "row {row} is marked {}, but {} was fitted to it: mark it \"role\": \"fitted\", \"fit\": \"{machine}\"",
                r.role.label(),
                bundled(machine)
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn data(rows: serde_json::Value) -> PaperData {
        serde_json::from_value(serde_json::json!({"paper": "002", "title": "t", "rows": rows}))
            .unwrap()
    }

    fn row(id: &str, role: &str, fit: Option<&str>) -> serde_json::Value {
        let mut r = serde_json::json!({"id": id, "figure": "F", "location": "S",
                                       "quantity": "q", "role": role, "value": 1.0});
        if let Some(f) = fit {
            r["fit"] = f.into();
        }
        r
    }

    fn fits(list: &[(&str, &str, &str)]) -> FitList {
        list.iter()
            .map(|(m, p, r)| (m.to_string(), p.to_string(), r.to_string()))
            .collect()
    }

    #[test]
    fn roles_agree_with_the_machines_fits_or_the_data_is_refused() {
        let d = data(serde_json::json!([
            row("a", "fitted", Some("delta.json")),
            row("b", "predicted", None)
        ]));
        assert!(check_roles(&d, &fits(&[("delta.json", "002", "a")])).is_ok());
        // Another paper's fits do not concern this one.
        assert!(check_roles(
            &d,
            &fits(&[("delta.json", "002", "a"), ("x.json", "001", "b")])
        )
        .is_ok());
        // A machine fitted to a row the data calls predicted.
        let e = check_roles(
            &d,
            &fits(&[("delta.json", "002", "a"), ("delta.json", "002", "b")]),
        )
        .unwrap_err();
        assert!(e.contains("row b is marked predicted"), "{e}");
        // A fitted row no machine was fitted to, or fitted to another machine.
        let e = check_roles(&d, &fits(&[])).unwrap_err();
        assert!(e.contains("lists no fit to it"), "{e}");
        let e = check_roles(
            &d,
            &fits(&[("delta.json", "002", "a"), ("other.json", "002", "a")]),
        )
        .unwrap_err();
        assert!(e.contains("other.json"), "{e}");
        // A fit naming a row the paper does not have.
        let e = check_roles(
            &d,
            &fits(&[("delta.json", "002", "a"), ("delta.json", "002", "z")]),
        )
        .unwrap_err();
        assert!(e.contains("row z"), "{e}");
    }

    #[test]
    fn a_fitted_scene_is_named_by_its_path_under_the_repository() {
        let d = data(serde_json::json!([row(
            "a",
            "fitted",
            Some("scenes/p003-x.json")
        )]));
        assert!(check_roles(&d, &fits(&[("scenes/p003-x.json", "002", "a")])).is_ok());
        let e = check_roles(&d, &fits(&[])).unwrap_err();
        assert!(e.contains("but scenes/p003-x.json lists no fit"), "{e}");
        let e = check_roles(
            &d,
            &fits(&[
                ("scenes/p003-x.json", "002", "a"),
                ("delta.json", "002", "a"),
            ]),
        )
        .unwrap_err();
        assert!(
            e.contains("but machines/delta.json was fitted to it"),
            "{e}"
        );
    }
}
