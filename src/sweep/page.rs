//! A sweep's page (index.html): its note, the table as the terminal prints it, the plots and
//! links to sweep.csv, sweep.json and cost.json.
//!
//! Must never compute a row (that is `table`); it only lays out what the sweep wrote.

use std::path::Path;

use maud::html;

use super::spec::Sweep;
use super::table::{shown_cells, shown_columns, Row};
use crate::output::page::{table, Page};
use crate::output::plot::PlotError;

pub fn write_page(dir: &Path, sweep: &Sweep, rows: &[Row]) -> Result<(), PlotError> {
    let name = sweep
        .file
        .file_name()
        .map_or_else(|| "sweep".to_string(), |n| n.to_string_lossy().into_owned());
    Page::new(format!("Sweep {name}"))
        .section(html! {
            @if let Some(note) = &sweep.note { p { (note) } }
            p { (rows.len()) " points; speedup is triangles/s over the one-processor point's. "
                "Each point's summary.json is under points/." }
        })
        .section(table_html("Table", rows))
        .images_of(dir)
        .files(&["sweep.csv", "sweep.json", "cost.json"])
        .write(dir)
}

/// The sweep's table as the terminal prints it, as an HTML table (a failed point's error in a
/// row of its own).
pub fn table_html(title: &str, rows: &[Row]) -> maud::Markup {
    let mut cells = Vec::new();
    for (row, error) in shown_cells(rows) {
        cells.push(row);
        if let Some(e) = error {
            cells.push(vec![format!("failed: {e}")]);
        }
    }
    table(title, &shown_columns(rows), &cells)
}
