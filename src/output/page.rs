//! The `index.html` every report folder gets: a self-contained page (CSS inline, no script,
//! images by relative path, nothing fetched from the network) built with maud from parts each
//! report writer picks: its markdown summary, CSV tables, per-node time-by-phase bars, the
//! images it wrote, links to its data files and, for a run, how to open its timeline.
//!
//! Owns page layout and the shared stylesheet. Must never compute a metric (writers hand it
//! finished text and numbers) nor write a file except through `write_text`.

use std::path::Path;

use maud::{html, Markup, PreEscaped, DOCTYPE};

use super::plot::PlotError;
use super::write_text;

/// A page under construction: sections in the order they are added.
pub struct Page {
    title: String,
    sections: Vec<Markup>,
}

impl Page {
    pub fn new(title: impl Into<String>) -> Page {
        Page {
            title: title.into(),
            sections: Vec::new(),
        }
    }

    pub fn section(mut self, markup: Markup) -> Page {
        self.sections.push(markup);
        self
    }

    /// Markdown (GitHub tables) rendered to HTML.
    pub fn markdown(self, text: &str) -> Page {
        self.section(markdown(text))
    }

    /// Every PNG image in `dir` and `dir/plots`, by file name order, each captioned with what
    /// it shows (a chart's title, kept in its PNG) and its file name.
    pub fn images_of(self, dir: &Path) -> Page {
        let mut images = Vec::new();
        for sub in ["", "plots"] {
            let folder = dir.join(sub);
            let Ok(entries) = std::fs::read_dir(&folder) else {
                continue;
            };
            let mut names: Vec<String> = entries
                .filter_map(|e| e.ok())
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .filter(|n| n.ends_with(".png"))
                .collect();
            names.sort();
            for n in names {
                let src = if sub.is_empty() {
                    n.clone()
                } else {
                    format!("{sub}/{n}")
                };
                images.push(src);
            }
        }
        if images.is_empty() {
            return self;
        }
        let captions: Vec<String> = images
            .iter()
            .map(|src| super::plot::png_title(&dir.join(src)).unwrap_or_else(|| src.clone()))
            .collect();
        self.section(html! {
            h2 { "Images" }
            @for (src, caption) in images.iter().zip(&captions) {
                figure {
                    img src=(src) alt=(caption);
                    figcaption { (caption) " (" a href=(src) { (src) } ")" }
                }
            }
        })
    }

    /// Links to the data files the writer wrote beside the page (named, not listed from the
    /// folder, so the page does not depend on what an earlier run left there).
    pub fn files(self, names: &[&str]) -> Page {
        self.section(html! {
            h2 { "Files" }
            ul { @for n in names { li { a href=(n) { (n) } } } }
        })
    }

    /// Writes `dir/index.html`. A page whose first section opens with its own heading (a
    /// report's markdown) keeps that one instead of repeating the title.
    pub fn write(self, dir: &Path) -> Result<(), PlotError> {
        let headed = self
            .sections
            .first()
            .is_some_and(|s| s.0.trim_start().starts_with("<h1>"));
        let body = html! {
            @if !headed { h1 { (self.title) } }
            @for s in &self.sections { (s) }
        };
        write_text(dir, "index.html", &shell(&self.title, body).into_string())
    }
}

pub fn markdown(text: &str) -> Markup {
    let parser = pulldown_cmark::Parser::new_ext(text, pulldown_cmark::Options::ENABLE_TABLES);
    let mut out = String::new();
    pulldown_cmark::html::push_html(&mut out, parser);
    PreEscaped(out)
}

/// A table: a header row and rows of cells, numbers right-aligned.
pub fn table(title: &str, header: &[&str], rows: &[Vec<String>]) -> Markup {
    let numeric = |c: &str| c.parse::<f64>().is_ok();
    html! {
        h2 { (title) }
        table {
            thead { tr { @for h in header { th { (h) } } } }
            tbody { @for row in rows { tr { @for c in row {
                @if numeric(c) { td.num { (c) } } @else { td { (c) } }
            } } } }
        }
    }
}

/// A CSV text (as sortsim writes it: a header line, no quoted commas) as a table.
pub fn csv_table(title: &str, text: &str) -> Markup {
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
    html! {
        h2 { (title) }
        table {
            thead { tr { @for h in &header { th { (h) } } } }
            tbody { @for line in lines { tr { @for c in line.split(',') { td { (c) } } } } }
        }
    }
}

/// Preformatted text (a table sortsim prints on the terminal).
pub fn text_block(title: &str, text: &str) -> Markup {
    html! { h2 { (title) } pre { (text) } }
}

/// A self-contained page: inline CSS, no script, images by relative path.
pub fn shell(title: &str, body: Markup) -> Markup {
    html! {
        (DOCTYPE)
        html lang="en" {
            head {
                meta charset="utf-8";
                meta name="viewport" content="width=device-width, initial-scale=1";
                title { (title) }
                style { (PreEscaped(CSS)) }
            }
            body { (body) }
        }
    }
}

/// The colours of phases and series, in order, on every page.
pub const PALETTE: [&str; 8] = [
    "#4e79a7", "#f28e2b", "#59a14f", "#e15759", "#76b7b2", "#edc948", "#b07aa1", "#9c755f",
];

const CSS: &str = "body{font-family:system-ui,sans-serif;margin:2em auto;max-width:80em;padding:0 1em;color:#222}\
table{border-collapse:collapse;margin:1em 0}\
th,td{border:1px solid #ddd;padding:.3em .5em;vertical-align:top;text-align:left;font-size:.92em}\
th{background:#f4f4f4}td.num{text-align:right;white-space:nowrap}\
pre{background:#f8f8f8;padding:.8em;overflow-x:auto}\
tr.exact td.verdict{background:#d9f2d9}tr.within td.verdict{background:#e8f5e0}\
tr.shape td.verdict{background:#fff3c4}tr.differs td.verdict{background:#f8d0d0}\
.detail{color:#666;font-size:.9em}.headline{font-size:1.15em;font-weight:600}\
figure{display:block;margin:1em 0;max-width:100%}figcaption{color:#444;margin-top:.3em}img{max-width:100%;border:1px solid #eee}\
.legend span{margin-right:1em;white-space:nowrap}.legend i{display:inline-block;width:.9em;height:.9em;margin-right:.3em;vertical-align:middle}\
.bars{margin:.5em 0}.bar{display:flex;align-items:center;height:16px;margin:1px 0}.bars.dense .bar{height:4px;margin:0}\
.bar .label{width:4.5em;font-size:13px;color:#555;text-align:right;padding-right:.5em;white-space:nowrap}\
.track{flex:1;display:flex;height:100%;background:#e6e6e6}.seg{height:100%}\
.axis{display:flex;margin-left:5em;position:relative;height:2.2em;border-top:1px solid #888}\
.axis span{position:absolute;transform:translateX(-50%);font-size:13px;color:#444;padding-top:.2em}\
.axis span.first{transform:none}.axis span.last{transform:translateX(-100%)}";
