//! The `sortsim paper` report: per paper, `paper.md` and `paper.json` (one table per figure
//! or table of the paper, with the verdict counts as a headline), `plots/` (the paper's
//! values drawn over sortsim's curves) and `index.html`; over all papers asked for, an
//! `index.html` and `papers.md` with each paper's headline.
//!
//! Owns the layout of these files. Must never judge a row (that is `paper::verdict`) or run
//! anything; every file goes through `write_atomic`, and the text is byte-identical for
//! identical inputs.

use std::fmt::Write as _;
use std::path::Path;

use maud::{html, Markup};

use crate::output::page::shell;
use crate::output::plot::{LineChart, PlotError};
use crate::output::{to_json, write_text};
use crate::paper::{PaperReport, Role, RowReport, Verdict};

/// Writes one paper's folder: plots, paper.md, paper.json, index.html.
pub fn write_paper(report: &PaperReport, dir: &Path) -> Result<(), PlotError> {
    for c in &report.charts {
        LineChart {
            title: &c.title,
            x_label: &c.x_label,
            y_label: &c.y_label,
            series: &c.series,
            options: c.options,
        }
        .write(&dir.join("plots").join(&c.stem))?;
    }
    write_text(dir, "paper.md", &markdown(report))?;
    write_text(dir, "paper.json", &to_json(report))?;
    write_text(dir, "index.html", &page(report).into_string())
}

/// Writes the overview of several papers (each in its own folder `dir/NNN/`).
pub fn write_overview(reports: &[PaperReport], dir: &Path) -> Result<(), PlotError> {
    let mut md = String::from("# sortsim and the papers\n\n");
    for r in reports {
        let _ = writeln!(
            md,
            "- [Paper {}]({}/paper.md): {}. {}",
            r.paper,
            r.paper,
            r.title,
            r.headline()
        );
    }
    write_text(dir, "papers.md", &md)?;
    let body = html! {
        h1 { "sortsim and the papers" }
        p { "Each paper's numbers and claims next to what sortsim measures for them. "
            "Verdicts: exact (the paper's digits), within tolerance, shape holds (the number misses, the claim holds), differs. "
            "The verdict columns count the predicted rows, the only ones nothing was tuned to; "
            "fitted rows (calibration targets), inputs read back and definitions are counted beside them, not as agreement." }
        table {
            thead { tr { th { "paper" } th { "title" } th { "exact" } th { "within tolerance" } th { "shape holds" } th { "differs" }
                th { "fitted" } th { "input" } th { "definition" } } }
            tbody {
                @for r in reports {
                    tr {
                        td { a href={ (r.paper) "/index.html" } { "Paper " (r.paper) } }
                        td { (r.title) }
                        td.num { (r.tally.exact) }
                        td.num { (r.tally.within_tolerance) }
                        td.num { (r.tally.shape_holds) }
                        td.num { (r.tally.differs) }
                        td.num { (role_total(r, Role::Fitted)) }
                        td.num { (role_total(r, Role::Input)) }
                        td.num { (role_total(r, Role::Definition)) }
                    }
                }
            }
        }
    };
    write_text(
        dir,
        "index.html",
        &shell("sortsim and the papers", body).into_string(),
    )
}

fn role_total(r: &PaperReport, role: Role) -> usize {
    r.by_role.get(&role).map_or(0, |t| t.total())
}

/// What each role's rows are, for the reader of a report.
const ROLES_TEXT: &str =
    "Roles: predicted (nothing was tuned to the row: the headline counts only these), \
fitted (a target a machine's costs were fitted to; it names the machine), \
input (a parameter of a machine or scene read back) and definition (true by construction).";

/// Each role's verdicts, one line each, predicted first.
fn role_lines(r: &PaperReport) -> Vec<String> {
    r.by_role
        .iter()
        .map(|(role, t)| format!("{}: {}", role.label(), t.headline()))
        .collect()
}

/// The fitted rows grouped by the machine fitted to them.
fn fitted_rows(r: &PaperReport) -> Vec<(&str, Vec<&RowReport>)> {
    let mut by_machine: Vec<(&str, Vec<&RowReport>)> = Vec::new();
    for row in r.rows.iter().filter(|row| row.role == Role::Fitted) {
        let machine = row.fit.as_deref().unwrap_or("");
        match by_machine.iter_mut().find(|(m, _)| *m == machine) {
            Some((_, rows)) => rows.push(row),
            None => by_machine.push((machine, vec![row])),
        }
    }
    by_machine
}

fn markdown(r: &PaperReport) -> String {
    let mut md = String::new();
    let _ = writeln!(md, "# Paper {}: {}\n", r.paper, r.title);
    let _ = writeln!(md, "**{}**\n", r.headline());
    for line in role_lines(r) {
        let _ = writeln!(md, "- {line}");
    }
    let _ = writeln!(md, "\n{ROLES_TEXT}");
    if r.quick {
        md.push_str("\nQuick run (`--quick`): fewer frames per run than the full report.\n");
    }
    let fitted = fitted_rows(r);
    if !fitted.is_empty() {
        md.push_str("\nFitted rows (agreement here is the fit, not a prediction):\n\n");
        for (machine, rows) in &fitted {
            let ids: Vec<&str> = rows.iter().map(|row| row.id.as_str()).collect();
            let _ = writeln!(md, "- machines/{machine}: {}", ids.join(", "));
        }
    }
    for figure in r.figures() {
        let _ = writeln!(md, "\n## {figure}\n");
        md.push_str(
            "| quantity | where | role | paper | sortsim | deviation | tolerance | verdict | why |\n",
        );
        md.push_str("| --- | --- | --- | ---: | ---: | ---: | --- | --- | --- |\n");
        for row in r.rows.iter().filter(|row| row.figure == figure) {
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {} | {} | {} | {} | {} |",
                cell(&row.quantity),
                row.location,
                row.role.label(),
                with_unit(&row.paper, &row.unit),
                measured(row),
                deviation(row),
                row.tolerance,
                row.verdict.label(),
                cell(&match &row.approximate {
                    Some(why) => format!("{} (approximate under --quick: {why})", row.why)
                        .trim_start()
                        .to_string(),
                    None => row.why.clone(),
                })
            );
        }
    }
    if !r.charts.is_empty() {
        md.push_str("\n## Plots\n\n");
        for c in &r.charts {
            let _ = writeln!(md, "![{}](plots/{}.png)", c.title, c.stem);
        }
    }
    md
}

fn cell(text: &str) -> String {
    text.replace('|', "\\|")
}

fn with_unit(value: &str, unit: &str) -> String {
    if unit.is_empty() || value == "claim" {
        value.to_string()
    } else {
        format!("{value} {unit}")
    }
}

/// sortsim's side of a row: its number, or whether the claim holds; "≈" when the quick run
/// only approximates the full one.
fn measured(row: &RowReport) -> String {
    let mark = if row.approximate.is_some() {
        "≈ "
    } else {
        ""
    };
    let value = match row.sortsim {
        Some(v) => with_unit(&significant(v), &row.unit),
        None => match row.verdict {
            Verdict::Differs => "does not hold".to_string(),
            _ => "holds".to_string(),
        },
    };
    format!("{mark}{value}")
}

/// The row's detail, led by the reason when the quick run only approximates the full one.
fn detail(row: &RowReport) -> String {
    match &row.approximate {
        Some(why) => format!("approximate under --quick ({why}); {}", row.detail),
        None => row.detail.clone(),
    }
}

fn deviation(row: &RowReport) -> String {
    row.deviation_pct
        .map_or(String::new(), |d| format!("{d:+.1}%"))
}

/// Four significant digits, without an exponent for everyday magnitudes.
fn significant(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let digits = 4 - 1 - v.abs().log10().floor() as i32;
    if digits <= 0 {
        format!("{}", v.round())
    } else {
        let s = format!("{v:.*}", digits.min(9) as usize);
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

fn page(r: &PaperReport) -> Markup {
    let title = format!("Paper {}: {}", r.paper, r.title);
    let body = html! {
        p { a href="../index.html" { "all papers" } }
        h1 { (title) }
        p.headline { (r.headline()) }
        ul { @for line in role_lines(r) { li { (line) } } }
        p { (ROLES_TEXT) }
        @if r.quick { p { "Quick run (--quick): fewer frames per run than the full report." } }
        @let fitted = fitted_rows(r);
        @if !fitted.is_empty() {
            p { "Fitted rows (agreement here is the fit, not a prediction):" }
            ul { @for (machine, rows) in &fitted {
                li { "machines/" (machine) ": "
                    (rows.iter().map(|row| row.id.as_str()).collect::<Vec<_>>().join(", ")) }
            } }
        }
        @for figure in r.figures() {
            h2 { (figure) }
            table {
                thead { tr {
                    th { "quantity" } th { "where" } th { "role" } th { "paper" } th { "sortsim" }
                    th { "deviation" } th { "tolerance" } th { "verdict" } th { "why / how measured" }
                } }
                tbody {
                    @for row in r.rows.iter().filter(|row| row.figure == figure) {
                        tr class=(verdict_class(row.verdict)) {
                            td { (row.quantity) }
                            td { (row.location) }
                            td { (row.role.label()) }
                            td.num { (with_unit(&row.paper, &row.unit)) }
                            td.num { (measured(row)) }
                            td.num { (deviation(row)) }
                            td { (row.tolerance) }
                            td.verdict { (row.verdict.label()) }
                            td {
                                @if !row.why.is_empty() { (row.why) br; }
                                span.detail { (detail(row)) }
                            }
                        }
                    }
                }
            }
        }
        @if !r.charts.is_empty() {
            h2 { "Plots" }
            p { "Lines: sortsim. Crosses: the paper's values (only those its text or tables state)." }
            @for c in &r.charts {
                figure {
                    img src={ "plots/" (c.stem) ".png" } alt=(c.title);
                    figcaption { (c.title) }
                }
            }
        }
        p { "The same tables as " a href="paper.md" { "paper.md" } " and " a href="paper.json" { "paper.json" } "." }
    };
    shell(&title, body)
}

fn verdict_class(v: Verdict) -> &'static str {
    match v {
        Verdict::Exact => "exact",
        Verdict::WithinTolerance => "within",
        Verdict::ShapeHolds => "shape",
        Verdict::Differs => "differs",
    }
}
