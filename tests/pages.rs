//! Every kind of report page, as a person sees it: each report folder's index.html opened in
//! headless Chromium (installed by the test through `common::installed` when missing). Every
//! image must load (complete, naturalWidth > 0), the browser must log no console message,
//! and a screenshot must not be blank.
//!
//! The images are checked from a small harness page that loads the report in an iframe
//! (`--allow-file-access-from-files` lets it read the frame's document) and prints its
//! verdict into the DOM that `--dump-dom` returns.

use crate::common;

use std::path::Path;
use std::process::{Command, Output};

fn sortsim(args: &[&str]) -> Output {
    let out = Command::new(env!("CARGO_BIN_EXE_sortsim"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("sortsim runs");
    assert!(
        out.status.success(),
        "sortsim {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

fn chromium(profile: &Path, extra: &[&str]) -> Output {
    let browser = common::installed("chromium", &["chromium"]);
    Command::new(browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--no-first-run",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .args(extra)
        .output()
        .expect("chromium starts")
}

const HARNESS: &str = r#"<!DOCTYPE html><html><body><pre id="verdict">pending</pre>
<iframe id="page" src="PAGE" style="width:1280px;height:900px"></iframe>
<script>
document.getElementById('page').addEventListener('load', () => {
  const doc = document.getElementById('page').contentDocument;
  const images = Array.from(doc.images);
  const broken = images.filter(i => !(i.complete && i.naturalWidth > 0)).map(i => i.getAttribute('src'));
  const shown = images.map(i => [i.getAttribute('src'), i.width / Math.max(i.naturalWidth, 1)]);
  document.getElementById('verdict').textContent =
    'images=' + images.length + ' broken=' + JSON.stringify(broken) + ' h1=' + (doc.querySelector('h1') !== null)
    + ' shown=' + JSON.stringify(shown);
});
</script></body></html>"#;

/// Opens `dir/index.html`; returns the number of images it shows.
fn check_page(dir: &Path) -> usize {
    let page = dir.join("index.html");
    assert!(page.is_file(), "{} was not written", page.display());
    let html = std::fs::read_to_string(&page).unwrap();
    assert!(!html.contains("<script"), "a report page needs no script");
    assert!(!html.contains("<link"), "CSS is inline");
    let work = tempfile::tempdir().unwrap();
    let harness = work.path().join("harness.html");
    std::fs::write(
        &harness,
        HARNESS.replace("PAGE", &format!("file://{}", page.display())),
    )
    .unwrap();
    let out = chromium(
        &work.path().join("profile"),
        &[
            "--allow-file-access-from-files",
            "--virtual-time-budget=10000",
            "--enable-logging=stderr",
            "--v=1",
            "--dump-dom",
            &format!("file://{}", harness.display()),
        ],
    );
    let dom = String::from_utf8_lossy(&out.stdout);
    let log = String::from_utf8_lossy(&out.stderr);
    let verdict = dom
        .split("<pre id=\"verdict\">")
        .nth(1)
        .and_then(|s| s.split('<').next())
        .unwrap_or_else(|| panic!("{}: no verdict; browser said:\n{log}", page.display()));
    assert!(
        verdict.contains("broken=[]"),
        "{}: {verdict}",
        page.display()
    );
    assert!(verdict.contains("h1=true"), "{}: {verdict}", page.display());
    let console: Vec<&str> = log.lines().filter(|l| l.contains(":CONSOLE")).collect();
    assert!(console.is_empty(), "{}: {console:?}", page.display());
    let images: usize = verdict
        .split("images=")
        .nth(1)
        .and_then(|s| s.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap();
    assert_plot_text_readable(dir, verdict);
    assert_not_blank(&page, work.path());
    images
}

/// Every chart's text is at least 16 px as the page shows it: the smallest font-size in the
/// chart's SVG (the PNG is drawn from the same layout) times the scale the page draws it at.
fn assert_plot_text_readable(dir: &Path, verdict: &str) {
    let shown: Vec<(String, f64)> = verdict
        .split(" shown=")
        .nth(1)
        .and_then(|json| serde_json::from_str(json).ok())
        .unwrap_or_else(|| panic!("{}: no image scales in {verdict}", dir.display()));
    for (src, scale) in shown {
        let svg = dir.join(&src).with_extension("svg");
        let Ok(text) = std::fs::read_to_string(&svg) else {
            continue; // not a chart (a rendered frame)
        };
        let smallest = text
            .split("font-size=\"")
            .skip(1)
            .filter_map(|s| s.split('"').next()?.parse::<f64>().ok())
            .fold(f64::INFINITY, f64::min);
        assert!(
            smallest.is_finite() && smallest * scale >= 16.0,
            "{}: {src} shows text at {:.1} px ({smallest:.1} px drawn, shown at {scale:.2} of its size)",
            dir.display(),
            smallest * scale
        );
    }
}

/// A screenshot of the page has ink: at least 1% of its pixels are not the background.
fn assert_not_blank(page: &Path, work: &Path) {
    let shot = work.join("shot.png");
    let out = chromium(
        &work.join("profile-shot"),
        &[
            "--window-size=1280,1600",
            &format!("--screenshot={}", shot.display()),
            &format!("file://{}", page.display()),
        ],
    );
    assert!(
        shot.is_file(),
        "no screenshot: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&shot).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    let channels = info.color_type.samples();
    let pixels = &buf[..info.buffer_size()];
    let background = &pixels[..channels];
    let inked = pixels
        .chunks(channels)
        .filter(|p| p[..3] != background[..3])
        .count();
    let total = pixels.len() / channels;
    assert!(
        inked * 100 > total,
        "{}: only {inked} of {total} pixels differ from the background",
        page.display()
    );
}

#[test]
fn a_run_page_shows_its_tables_bars_and_image() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    sortsim(&[
        "run",
        "--machine",
        "machines/delta.json",
        "--scene",
        "scenes/plb-head-standin.json",
        "--algo",
        "sort-middle/ellsworth",
        "--procs",
        "16",
        "--frames",
        "0..2",
        "-o",
        out,
    ]);
    let html = std::fs::read_to_string(dir.path().join("index.html")).unwrap();
    assert!(html.contains("Time by phase, per node") && html.contains("timeline.json"));
    assert_eq!(
        html.matches("class=\"bar\"").count(),
        16,
        "one bar per node"
    );
    assert_eq!(check_page(dir.path()), 1, "the frame's image");
}

#[test]
fn a_sweep_page_shows_its_table_and_plots() {
    let dir = tempfile::tempdir().unwrap();
    sortsim(&[
        "sweep",
        "sweeps/default.json",
        "--jobs",
        "2",
        "-o",
        dir.path().to_str().unwrap(),
    ]);
    assert!(check_page(dir.path()) >= 3, "the sweep's plots");
}

#[test]
fn an_accuracy_page_shows_its_images_and_charts() {
    let dir = tempfile::tempdir().unwrap();
    sortsim(&[
        "accuracy",
        "scenes/screen-demo.json",
        "--machine",
        "machines/delta.json",
        "--algo",
        "sort-middle/static",
        "--procs",
        "4",
        "--modes",
        "none,adaptive",
        "--fidelities",
        "ideal,flow",
        "-o",
        dir.path().to_str().unwrap(),
    ]);
    assert!(check_page(dir.path()) >= 4, "reference, frames and charts");
}

#[test]
fn a_trace_replay_page_shows_its_table_and_charts() {
    let dir = tempfile::tempdir().unwrap();
    sortsim(&[
        "trace",
        "replay",
        "traces/p003-zinnia.trace",
        "-o",
        dir.path().to_str().unwrap(),
    ]);
    assert_eq!(check_page(dir.path()), 2, "traffic over max and over min");
}

#[test]
fn a_utilization_page_shows_its_tables_and_figures() {
    let dir = tempfile::tempdir().unwrap();
    sortsim(&[
        "utilization",
        "scenes/plb-head-standin.json",
        "--procs",
        "2,4,...,16",
        "--granularity",
        "1,4",
        "--frames",
        "3..7",
        "--frame-step",
        "2",
        "-o",
        dir.path().to_str().unwrap(),
    ]);
    assert_eq!(check_page(dir.path()), 2, "Figures 4 and 5");
}

#[test]
fn paper_pages_show_the_verdicts_and_plots() {
    let dir = tempfile::tempdir().unwrap();
    sortsim(&[
        "paper",
        "003",
        "--quick",
        "-o",
        dir.path().to_str().unwrap(),
    ]);
    assert!(check_page(&dir.path().join("003")) >= 1);
    check_page(dir.path());
}

#[test]
fn the_default_job_page_shows_its_tables_as_tables() {
    let dir = tempfile::tempdir().unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_sortsim"))
        .current_dir(dir.path())
        .env("SORTSIM_ROOT", env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("sortsim runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let page = dir.path().join("reports/default");
    let html = std::fs::read_to_string(page.join("index.html")).unwrap();
    assert!(html.contains("href=\"phold/summary.json\""));
    // The sweep, PHOLD and the fidelities as HTML tables, not monospace text.
    assert!(html.matches("<table>").count() >= 3, "{html}");
    assert!(!html.contains("<pre>"), "{html}");
    check_page(&page);
}
