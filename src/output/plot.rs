//! Line charts for reports (plotters): one chart is written twice, as `STEM.svg` and
//! `STEM.png`, from the same drawing code. Text is laid out with DejaVu Sans, embedded in the
//! binary (`fonts/DejaVuSans.ttf`, license beside it), so a PNG has the same labels on every
//! machine and the SVG's layout does not depend on the host's fonts.
//!
//! Owns chart layout: axis ranges, ticks, colours, the legend. Must never compute a metric
//! (callers hand it finished points), never read the clock or the environment, and never
//! write a file except through `write_atomic`: both images are rendered in memory first, so
//! a failed chart leaves no file behind. The same input gives the same SVG bytes.
//!
//! ```no_run
//! use sortsim::output::plot::{line_chart, ChartOptions, Series};
//! let series = [Series::new("static", vec![(1.0, 1.0), (2.0, 1.9), (4.0, 3.5)])];
//! let options = ChartOptions { log_x: true, y_from_zero: true };
//! line_chart("out/speedup".as_ref(), "Speedup", "processors", "speedup", &series, options).unwrap();
//! ```

use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::{register_font, FontStyle};

use super::write_atomic;

/// One line of a chart: its legend label and its points in drawing order.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    pub label: String,
    pub points: Vec<(f64, f64)>,
    /// Points without a line between them, drawn as large crosses: published values drawn
    /// over simulated curves.
    pub marks_only: bool,
}

/// How the axes are scaled.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ChartOptions {
    /// Base-2 logarithmic x axis (processor counts); points with x <= 0 are left out.
    pub log_x: bool,
    /// The y axis starts at zero (or below, for negative data) instead of at the data.
    pub y_from_zero: bool,
}

/// A chart ready to render: borrowed labels and series.
#[derive(Debug, Clone, Copy)]
pub struct LineChart<'a> {
    pub title: &'a str,
    pub x_label: &'a str,
    pub y_label: &'a str,
    pub series: &'a [Series],
    pub options: ChartOptions,
}

#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    #[error("the embedded plot font could not be loaded")]
    Font,
    #[error("drawing the chart failed: {0}")]
    Draw(String),
    #[error("{}: cannot write: {source}", path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
}

/// Renders a line chart and writes `STEM.svg` and `STEM.png` (the stem gets the extension
/// appended, so a stem containing dots keeps them).
pub fn line_chart(
    path_stem: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    options: ChartOptions,
) -> Result<(), PlotError> {
    LineChart {
        title,
        x_label,
        y_label,
        series,
        options,
    }
    .write(path_stem)
}

impl Series {
    pub fn new(label: impl Into<String>, points: Vec<(f64, f64)>) -> Series {
        Series {
            label: label.into(),
            points,
            marks_only: false,
        }
    }

    /// A series of separate marks (no line), e.g. a paper's published values.
    pub fn marks(label: impl Into<String>, points: Vec<(f64, f64)>) -> Series {
        Series {
            marks_only: true,
            ..Series::new(label, points)
        }
    }
}

impl LineChart<'_> {
    /// The chart as SVG text (deterministic).
    pub fn svg(&self) -> Result<String, PlotError> {
        ensure_font()?;
        let size = self.size();
        let mut text = String::new();
        {
            let root = SVGBackend::with_string(&mut text, size).into_drawing_area();
            self.draw(&root)?;
            root.present().map_err(draw_error)?;
        }
        Ok(text)
    }

    /// The chart as PNG bytes (RGB, 8 bits per channel).
    pub fn png(&self) -> Result<Vec<u8>, PlotError> {
        ensure_font()?;
        let (w, h) = self.size();
        let mut rgb = vec![255u8; w as usize * h as usize * 3];
        {
            let root = BitMapBackend::with_buffer(&mut rgb, (w, h)).into_drawing_area();
            self.draw(&root)?;
            root.present().map_err(draw_error)?;
        }
        encode_rgb_png(&rgb, w, h, &self.caption())
    }

    /// What the chart shows, in words: its title, and which quantity against which.
    pub fn caption(&self) -> String {
        format!("{}: {} against {}", self.title, self.y_label, self.x_label)
    }

    /// Renders both images, then writes `STEM.svg` and `STEM.png`.
    pub fn write(&self, path_stem: &Path) -> Result<(), PlotError> {
        let svg = self.svg()?;
        let png = self.png()?;
        for (ext, bytes) in [("svg", svg.as_bytes()), ("png", png.as_slice())] {
            let path = with_suffix(path_stem, ext);
            write_atomic(&path, bytes).map_err(|source| PlotError::Io { path, source })?;
        }
        Ok(())
    }

    /// Plot area plus a legend column wide enough for the longest label; taller when the
    /// legend has many entries, so no entry falls off the image.
    fn size(&self) -> (u32, u32) {
        let h = (LEGEND_TOP + LEGEND_ROW * self.series.len() as i32 + 20).max(PLOT_H as i32);
        (PLOT_W + self.legend_width(), h as u32)
    }

    fn legend_width(&self) -> u32 {
        let chars = self
            .series
            .iter()
            .map(|s| legend_label(&s.label).chars().count())
            .max()
            .unwrap_or(0) as u32;
        // ~11 px per character at 20 px DejaVu Sans, plus the swatch and margins.
        (chars * 11 + 56).clamp(140, 540)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
        root.fill(&WHITE).map_err(draw_error)?;
        let (plot, legend) = root.split_horizontally(PLOT_W);
        let lines = self.transformed();
        let (xr, yr) = (self.x_range(&lines), self.y_range(&lines));
        let x_desc = if self.options.log_x {
            format!("{} (log scale, base 2)", self.x_label)
        } else {
            self.x_label.to_string()
        };
        let mut chart = ChartBuilder::on(&plot)
            .caption(self.title, (FONT_NAME, 26))
            .margin(12)
            .x_label_area_size(60)
            .y_label_area_size(100)
            .build_cartesian_2d(xr.0..xr.1, yr.0..yr.1)
            .map_err(draw_error)?;
        let log_x = self.options.log_x;
        let x_fmt = move |v: &f64| x_tick(*v, log_x);
        let y_fmt = |v: &f64| format_number(*v);
        let x_ticks = if log_x {
            (xr.1 - xr.0).ceil() as usize + 1
        } else {
            10
        };
        chart
            .configure_mesh()
            .x_desc(x_desc)
            .y_desc(self.y_label)
            .x_labels(x_ticks.clamp(2, 24))
            .y_labels(8)
            .x_label_formatter(&x_fmt)
            .y_label_formatter(&y_fmt)
            .label_style((FONT_NAME, TEXT_PX))
            .axis_desc_style((FONT_NAME, TEXT_PX))
            .max_light_lines(1)
            .light_line_style(RGBColor(242, 242, 242))
            .bold_line_style(RGBColor(215, 215, 215))
            .draw()
            .map_err(draw_error)?;
        for (i, points) in lines.iter().enumerate() {
            let colour = palette(i);
            if self.series[i].marks_only {
                chart
                    .draw_series(
                        points
                            .iter()
                            .map(|&p| Cross::new(p, 7, colour.stroke_width(3))),
                    )
                    .map_err(draw_error)?;
                continue;
            }
            chart
                .draw_series(LineSeries::new(
                    points.iter().copied(),
                    colour.stroke_width(2),
                ))
                .map_err(draw_error)?;
            chart
                .draw_series(points.iter().map(|&p| Circle::new(p, 3, colour.filled())))
                .map_err(draw_error)?;
        }
        self.draw_legend(&legend)
    }

    /// The legend as its own column right of the plot, so it never hides a line.
    fn draw_legend<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
    ) -> Result<(), PlotError> {
        for (i, s) in self.series.iter().enumerate() {
            let colour = palette(i);
            let y = LEGEND_TOP + LEGEND_ROW * i as i32;
            if s.marks_only {
                area.draw(&Cross::new((17, y), 6, colour.stroke_width(3)))
                    .map_err(draw_error)?;
            } else {
                area.draw(&PathElement::new(
                    vec![(4, y), (30, y)],
                    colour.stroke_width(2),
                ))
                .map_err(draw_error)?;
                area.draw(&Circle::new((17, y), 3, colour.filled()))
                    .map_err(draw_error)?;
            }
            let style = TextStyle::from((FONT_NAME, TEXT_PX).into_font()).color(&BLACK);
            area.draw(&Text::new(legend_label(&s.label), (38, y - 9), style))
                .map_err(draw_error)?;
        }
        Ok(())
    }

    /// Points in axis coordinates: log2 of x on a log axis; non-finite points dropped (a
    /// missing value is a gap in the data, not a reason to fail the report).
    fn transformed(&self) -> Vec<Vec<(f64, f64)>> {
        let log_x = self.options.log_x;
        self.series
            .iter()
            .map(|s| {
                s.points
                    .iter()
                    .filter(|(x, _)| !log_x || *x > 0.0)
                    .map(|&(x, y)| (if log_x { x.log2() } else { x }, y))
                    .filter(|(x, y)| x.is_finite() && y.is_finite())
                    .collect()
            })
            .collect()
    }

    fn x_range(&self, lines: &[Vec<(f64, f64)>]) -> (f64, f64) {
        let (lo, hi) = bounds(lines.iter().flatten().map(|p| p.0)).unwrap_or((0.0, 1.0));
        if self.options.log_x {
            // Whole powers of two at both ends, a quarter step of air so end markers show.
            let (lo, hi) = (lo.floor(), hi.ceil().max(lo.floor() + 1.0));
            return (lo - 0.25, hi + 0.25);
        }
        padded(lo, hi, 0.03)
    }

    fn y_range(&self, lines: &[Vec<(f64, f64)>]) -> (f64, f64) {
        let (lo, hi) = bounds(lines.iter().flatten().map(|p| p.1)).unwrap_or((0.0, 1.0));
        if self.options.y_from_zero {
            let (lo, hi) = (lo.min(0.0), hi.max(0.0));
            let span = if hi > lo { hi - lo } else { 1.0 };
            return (
                lo - if lo < 0.0 { span * 0.05 } else { 0.0 },
                hi + span * 0.05,
            );
        }
        padded(lo, hi, 0.05)
    }
}

const FONT_NAME: &str = "sans-serif";
const FONT_BYTES: &[u8] = include_bytes!("fonts/DejaVuSans.ttf");
const PLOT_W: u32 = 700;
const PLOT_H: u32 = 520;
const LEGEND_TOP: i32 = 56;
const LEGEND_ROW: i32 = 26;
const LEGEND_MAX_CHARS: usize = 44;
/// Tick labels, axis names and legend entries: readable on a slide at the image's own size
/// (plotters writes 0.806 of this as the SVG's font-size, so 20 gives 16 px; a page shows a
/// chart at its drawn size: the widest, 700 + 540 px, fits the page; `tests/pages.rs` checks
/// both).
pub const TEXT_PX: u32 = 20;

/// plotters looks fonts up by family name in a process-wide table; register ours once.
fn ensure_font() -> Result<(), PlotError> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok =
        *REGISTERED.get_or_init(|| register_font(FONT_NAME, FontStyle::Normal, FONT_BYTES).is_ok());
    if ok {
        Ok(())
    } else {
        Err(PlotError::Font)
    }
}

fn draw_error<E: std::fmt::Debug>(e: E) -> PlotError {
    PlotError::Draw(format!("{e:?}"))
}

fn with_suffix(stem: &Path, ext: &str) -> PathBuf {
    let mut name = OsString::from(stem.as_os_str());
    name.push(".");
    name.push(ext);
    PathBuf::from(name)
}

/// The chart's caption goes into the PNG as its standard `Title` text, where a page (and any
/// image viewer) finds it.
fn encode_rgb_png(rgb: &[u8], w: u32, h: u32, title: &str) -> Result<Vec<u8>, PlotError> {
    let mut bytes = Vec::new();
    let mut enc = png::Encoder::new(&mut bytes, w, h);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    let png_error = |e: png::EncodingError| PlotError::Draw(format!("PNG encoding: {e}"));
    enc.add_itxt_chunk("Title".to_string(), title.to_string())
        .map_err(png_error)?;
    let mut writer = enc.write_header().map_err(png_error)?;
    writer.write_image_data(rgb).map_err(png_error)?;
    writer.finish().map_err(png_error)?;
    Ok(bytes)
}

/// The `Title` text of the PNG at `path` (a chart's caption), if it has one.
pub fn png_title(path: &Path) -> Option<String> {
    let file = std::fs::File::open(path).ok()?;
    let reader = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .ok()?;
    let info = reader.info();
    info.utf8_text
        .iter()
        .find(|t| t.keyword == "Title")
        .and_then(|t| t.get_text().ok())
        .or_else(|| {
            info.uncompressed_latin1_text
                .iter()
                .find(|t| t.keyword == "Title")
                .map(|t| t.text.clone())
        })
}

/// Ten colours that stay distinguishable in print (the Tableau 10 hues); series past the
/// tenth reuse them in order.
fn palette(i: usize) -> RGBColor {
    const COLOURS: [(u8, u8, u8); 10] = [
        (31, 119, 180),
        (255, 127, 14),
        (44, 160, 44),
        (214, 39, 40),
        (148, 103, 189),
        (140, 86, 75),
        (227, 119, 194),
        (127, 127, 127),
        (188, 189, 34),
        (23, 190, 207),
    ];
    let (r, g, b) = COLOURS[i % COLOURS.len()];
    RGBColor(r, g, b)
}

fn legend_label(label: &str) -> String {
    if label.chars().count() <= LEGEND_MAX_CHARS {
        return label.to_string();
    }
    let mut s: String = label.chars().take(LEGEND_MAX_CHARS - 1).collect();
    s.push('…');
    s
}

fn bounds(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    values.fold(None, |acc, v| match acc {
        None => Some((v, v)),
        Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
    })
}

/// `lo..hi` widened by `frac` of its span on each side; a single value gets a span of its
/// own size (or 1), so a flat line sits in the middle of the chart.
fn padded(lo: f64, hi: f64, frac: f64) -> (f64, f64) {
    let span = hi - lo;
    if span > 0.0 {
        return (lo - span * frac, hi + span * frac);
    }
    let half = if lo != 0.0 { lo.abs() * 0.5 } else { 1.0 };
    (lo - half, hi + half)
}

/// A tick on the x axis: on a log axis only whole powers of two get a label (2^v), the
/// others stay blank rather than show 2.83.
fn x_tick(v: f64, log_x: bool) -> String {
    if !log_x {
        return format_number(v);
    }
    let k = v.round();
    if (v - k).abs() > 1e-9 {
        return String::new();
    }
    format_number(k.exp2())
}

/// Short tick labels with SI prefixes: 2.5 M rather than 2500000, 200 µ rather than 0.0002;
/// between 0.001 and 10,000 plain numbers (integers as integers, at most three decimals).
pub fn format_number(v: f64) -> String {
    const LARGE: [(f64, &str); 5] = [(1e15, "P"), (1e12, "T"), (1e9, "G"), (1e6, "M"), (1e3, "k")];
    const SMALL: [(f64, &str); 4] = [(1e-3, "m"), (1e-6, "µ"), (1e-9, "n"), (1e-12, "p")];
    let a = v.abs();
    if v == 0.0 || !v.is_finite() {
        return if v == 0.0 { "0".into() } else { format!("{v}") };
    }
    if a >= 1e4 {
        let (scale, prefix) = LARGE
            .iter()
            .find(|(s, _)| a >= *s)
            .expect("a >= 1e4 >= 1e3");
        return format!("{} {prefix}", three_significant(v / scale));
    }
    if a < 1e-3 {
        let (scale, prefix) = SMALL
            .iter()
            .find(|(s, _)| a >= *s)
            .unwrap_or(&SMALL[SMALL.len() - 1]);
        return format!("{} {prefix}", three_significant(v / scale));
    }
    if (v - v.round()).abs() < 1e-9 {
        return format!("{}", v.round() as i64);
    }
    let s = format!("{v:.3}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// At most three significant digits, trailing zeros dropped: 2.5, 65.5, 512.
fn three_significant(v: f64) -> String {
    let decimals = match v.abs() {
        a if a >= 100.0 => 0,
        a if a >= 10.0 => 1,
        _ => 2,
    };
    let s = format!("{v:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_short() {
        assert_eq!(format_number(0.0), "0");
        assert_eq!(format_number(512.0), "512");
        assert_eq!(format_number(2.5), "2.5");
        assert_eq!(format_number(0.12345), "0.123");
        assert_eq!(format_number(15_000_000.0), "15 M");
        assert_eq!(format_number(2_500_000.0), "2.5 M");
        assert_eq!(format_number(65_536.0), "65.5 k");
        assert_eq!(format_number(9_999.0), "9999");
        assert_eq!(format_number(-0.0002), "-200 µ");
        assert_eq!(format_number(3.2e-7), "320 n");
    }

    #[test]
    fn log_ticks_label_only_powers_of_two() {
        assert_eq!(x_tick(9.0, true), "512");
        assert_eq!(x_tick(0.0, true), "1");
        assert_eq!(x_tick(1.5, true), "");
        assert_eq!(x_tick(1.5, false), "1.5");
    }

    #[test]
    fn stems_keep_their_dots() {
        assert_eq!(
            with_suffix(Path::new("a/p0.5"), "svg"),
            PathBuf::from("a/p0.5.svg")
        );
    }
}
