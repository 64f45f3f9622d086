//! The papers' numbers, one data file per paper (`papers/NNN.json`): each row a quantity the
//! paper prints or a claim it makes, with its figure or table, where in the text it stands,
//! the words it is quoted from, the tolerance sortsim is held to and, where sortsim is known
//! to differ, why.
//!
//! Owns the file format and how a row prints its claim and deviation. Must never hold a
//! measured value.

use std::path::Path;

use serde::Deserialize;

use super::{PaperError, PaperId};

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
    /// Why sortsim's number can differ (stand-in scene, a cost the paper does not give, a
    /// model difference); printed when the row holds only in shape or differs.
    #[serde(default)]
    pub why: Option<String>,
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

/// Reads and checks `papers/NNN.json` under `root`.
pub fn load(root: &Path, id: PaperId) -> Result<PaperData, PaperError> {
    let path = root.join("papers").join(format!("{}.json", id.id()));
    let fail = |message: String| PaperError::Data {
        path: path.clone(),
        message,
    };
    let text = std::fs::read_to_string(&path).map_err(|e| fail(e.to_string()))?;
    let de = &mut serde_json::Deserializer::from_str(&text);
    let data: PaperData = serde_path_to_error::deserialize(de)
        .map_err(|e| fail(format!("at {}: {}", e.path(), e.inner())))?;
    if data.paper != id.id() {
        return Err(fail(format!(
            "\"paper\" is {:?}, expected {:?}",
            data.paper,
            id.id()
        )));
    }
    let mut ids: Vec<&str> = data.rows.iter().map(|r| r.id.as_str()).collect();
    ids.sort_unstable();
    if let Some(w) = ids.windows(2).find(|w| w[0] == w[1]) {
        return Err(fail(format!("row id {:?} appears twice", w[0])));
    }
    for r in &data.rows {
        if r.value.is_some() && r.range.is_some() {
            return Err(fail(format!(
                "row {}: give a value or a range, not both",
                r.id
            )));
        }
    }
    Ok(data)
}
