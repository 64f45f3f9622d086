//! The verdict on one row: `exact` when sortsim prints the paper's digits, `within tolerance`
//! when it is inside the stated tolerance or bound, `shape holds` when the number misses but
//! the paper's qualitative claim around it holds, `differs` otherwise.
//!
//! Owns these rules. Must never soften them per row: a row that should pass more easily says
//! so in its tolerance, in the data file, where a reader sees it.

use serde::Serialize;

use super::data::{Reference, Relation, Tolerance};
use super::Measured;

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Verdict {
    Exact,
    WithinTolerance,
    ShapeHolds,
    Differs,
}

impl Verdict {
    pub fn label(self) -> &'static str {
        match self {
            Verdict::Exact => "exact",
            Verdict::WithinTolerance => "within tolerance",
            Verdict::ShapeHolds => "shape holds",
            Verdict::Differs => "differs",
        }
    }
}

/// How many rows got each verdict.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Tally {
    pub exact: usize,
    pub within_tolerance: usize,
    pub shape_holds: usize,
    pub differs: usize,
}

impl Tally {
    pub fn of(verdicts: impl Iterator<Item = Verdict>) -> Tally {
        let mut t = Tally::default();
        for v in verdicts {
            *match v {
                Verdict::Exact => &mut t.exact,
                Verdict::WithinTolerance => &mut t.within_tolerance,
                Verdict::ShapeHolds => &mut t.shape_holds,
                Verdict::Differs => &mut t.differs,
            } += 1;
        }
        t
    }

    pub fn total(&self) -> usize {
        self.exact + self.within_tolerance + self.shape_holds + self.differs
    }

    /// "12 rows: 3 exact, 5 within tolerance, 2 shape holds, 2 differ".
    pub fn headline(&self) -> String {
        format!(
            "{} rows: {} exact, {} within tolerance, {} shape holds, {} differ",
            self.total(),
            self.exact,
            self.within_tolerance,
            self.shape_holds,
            self.differs
        )
    }
}

pub fn judge(reference: &Reference, measured: &Measured) -> Verdict {
    let numeric = measured.value.and_then(|m| numeric_verdict(reference, m));
    match numeric {
        Some(v) => v,
        None if measured.shape == Some(true) => Verdict::ShapeHolds,
        None => Verdict::Differs,
    }
}

/// Exact or within tolerance, or None when the number does not match (or there is none).
fn numeric_verdict(reference: &Reference, m: f64) -> Option<Verdict> {
    if !m.is_finite() {
        return None;
    }
    if let Some([lo, hi]) = reference.range {
        return (lo..=hi).contains(&m).then_some(Verdict::WithinTolerance);
    }
    let v = reference.value?;
    match reference.relation {
        Relation::Below => (m < v).then_some(Verdict::WithinTolerance),
        Relation::Above => (m > v).then_some(Verdict::WithinTolerance),
        Relation::Equals if (m - v).abs() <= half_last_digit(v, reference.decimals) => {
            Some(Verdict::Exact)
        }
        Relation::Equals => {
            let inside = match reference.tolerance? {
                Tolerance::RelativePct(p) => v != 0.0 && ((m - v) / v).abs() * 100.0 <= p,
                Tolerance::Absolute(a) => (m - v).abs() <= a,
            };
            inside.then_some(Verdict::WithinTolerance)
        }
    }
}

/// Half a unit in the last digit the paper prints: 10.44 -> 0.005, 12 -> 0.5, 2.0 (one
/// decimal given) -> 0.05.
fn half_last_digit(v: f64, decimals: Option<u32>) -> f64 {
    let text = format!("{v}");
    let decimals = decimals
        .map(|d| d as usize)
        .unwrap_or_else(|| text.split_once('.').map_or(0, |(_, f)| f.len()));
    0.5 * 10f64.powi(-(decimals as i32))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reference(value: f64, tolerance: Option<Tolerance>, relation: Relation) -> Reference {
        Reference {
            id: "x".into(),
            figure: "Table 1".into(),
            location: "Section 1".into(),
            quantity: "q".into(),
            unit: "MB".into(),
            role: crate::paper::Role::Predicted,
            fit: None,
            value: Some(value),
            relation,
            range: None,
            tolerance,
            decimals: None,
            quote: None,
            approximate_when_quick: None,
            why: None,
        }
    }

    #[test]
    fn the_papers_digits_decide_exact() {
        let r = reference(29.4, None, Relation::Equals);
        assert_eq!(judge(&r, &Measured::value(29.36, "")), Verdict::Exact);
        assert_eq!(judge(&r, &Measured::value(29.46, "")), Verdict::Differs);
        let r = reference(10.44, Some(Tolerance::RelativePct(0.6)), Relation::Equals);
        assert_eq!(
            judge(&r, &Measured::value(10.49, "")),
            Verdict::WithinTolerance
        );
        assert_eq!(judge(&r, &Measured::value(10.6, "")), Verdict::Differs);
        let mut r = reference(2.0, None, Relation::Equals);
        assert_eq!(judge(&r, &Measured::value(1.85, "")), Verdict::Exact);
        r.decimals = Some(1);
        assert_eq!(judge(&r, &Measured::value(1.85, "")), Verdict::Differs);
        assert_eq!(r.claim(), "2.0");
    }

    #[test]
    fn a_miss_with_its_claim_holding_is_shape_only() {
        let r = reference(2.8, Some(Tolerance::RelativePct(20.0)), Relation::Equals);
        let m = Measured::value_and_shape(5.0, true, "");
        assert_eq!(judge(&r, &m), Verdict::ShapeHolds);
        let m = Measured::value_and_shape(5.0, false, "");
        assert_eq!(judge(&r, &m), Verdict::Differs);
        assert_eq!(judge(&r, &Measured::value(f64::NAN, "")), Verdict::Differs);
    }

    #[test]
    fn bounds_and_ranges() {
        let r = reference(5.0, None, Relation::Below);
        assert_eq!(
            judge(&r, &Measured::value(4.9, "")),
            Verdict::WithinTolerance
        );
        assert_eq!(judge(&r, &Measured::value(5.0, "")), Verdict::Differs);
        let mut r = reference(0.0, None, Relation::Equals);
        r.value = None;
        r.range = Some([0.017, 0.030]);
        assert_eq!(
            judge(&r, &Measured::value(0.02, "")),
            Verdict::WithinTolerance
        );
        assert_eq!(r.deviation_pct(0.02), Some(0.0));
        assert_eq!(judge(&r, &Measured::value(0.04, "")), Verdict::Differs);
    }
}
