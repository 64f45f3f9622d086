//! `sortsim calibrate`'s report: the fitted machine file, calibration.json, calibration.md
//! (the factors and the residual table: every target, the paper's value, sortsim's before and
//! after the fit, the deviation and the verdict) and index.html.
//!
//! Must never fit anything; it lays out what `calibrate` found.

use std::fmt::Write as _;
use std::path::Path;

use crate::calibrate::{Calibration, Residual};
use crate::output::page::Page;
use crate::output::plot::PlotError;
use crate::output::{to_json, write_text};

pub fn markdown(c: &Calibration) -> String {
    let mut md = format!("# Calibration of {} to paper {}\n\n", c.file, c.paper);
    let _ = writeln!(
        md,
        "Cost (squared deviations in tolerances, summed): {:.3} at the start, {:.3} fitted, after {} runs of the paper's experiments.\n",
        c.start_cost, c.fitted_cost, c.evaluations
    );
    md.push_str("| parameter | factor |\n| --- | ---: |\n");
    for (name, f) in &c.factors {
        let _ = writeln!(md, "| {name} | {f:.4} |");
    }
    residual_table(&mut md, "target", &c.rows);
    if !c.held_out.is_empty() {
        md.push_str("\nHeld out (not in the cost; how the fitted machine predicts them):\n");
        residual_table(&mut md, "held out", &c.held_out);
    }
    md
}

fn residual_table(md: &mut String, first: &str, rows: &[Residual]) {
    let _ = writeln!(
        md,
        "\n| {first} | quantity | paper | start | fitted | deviation | tolerance | verdict |"
    );
    md.push_str("| --- | --- | ---: | ---: | ---: | ---: | --- | --- |\n");
    let num = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.4}"));
    for r in rows {
        let _ = writeln!(
            md,
            "| {} | {} | {} {} | {} | {} | {} | {} | {} |",
            r.id,
            r.quantity.replace('|', "\\|"),
            r.paper,
            r.unit,
            num(r.start),
            num(r.fitted),
            r.fitted_deviation_pct
                .map_or(String::new(), |d| format!("{d:+.1}%")),
            r.tolerance,
            r.fitted_verdict.label()
        );
    }
}

pub fn write(dir: &Path, c: &Calibration) -> Result<(), PlotError> {
    write_text(dir, &c.file, &c.fitted_text)?;
    write_text(dir, "calibration.json", &to_json(c))?;
    let md = markdown(c);
    write_text(dir, "calibration.md", &md)?;
    Page::new(format!("Calibration of {}", c.file))
        .markdown(&md)
        .files(&[c.file.as_str(), "calibration.json", "calibration.md"])
        .write(dir)
}
