//! Plots through their public API (`report::plot`): both files are written, the SVG is
//! byte-identical for identical input, a PNG is a real PNG of the stated size, and odd data
//! (empty series, one point, NaN, x <= 0 on a log axis) draws without failing.

use crate::common;

use sortsim::output::plot::{line_chart, ChartOptions, LineChart, Series};

fn out_dir(name: &str) -> common::Scratch {
    common::scratch(name)
}

/// The text content of every `<text>` element.
fn svg_texts(svg: &str) -> Vec<String> {
    svg.split("<text")
        .skip(1)
        .filter_map(|t| {
            let body = t.split_once('>')?.1;
            Some(body.split_once("</text>")?.0.trim().to_string())
        })
        .collect()
}

fn speedup_series() -> Vec<Series> {
    let procs: [f64; 10] = [1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0, 128.0, 256.0, 512.0];
    let line = |eff: f64| procs.iter().map(|&p| (p, p * eff.powf(p.log2()))).collect();
    vec![
        Series::new("sort-middle/static", line(0.9)),
        Series::new("sort-middle/ellsworth two-step=on", line(0.95)),
    ]
}

fn chart(series: &[Series]) -> LineChart<'_> {
    LineChart {
        title: "Speedup",
        x_label: "processors",
        y_label: "speedup",
        series,
        options: ChartOptions {
            log_x: true,
            y_from_zero: true,
        },
    }
}

#[test]
fn writes_svg_and_png_side_by_side() {
    let dir = out_dir("plot-both");
    let series = speedup_series();
    let stem = dir.join("speedup");
    line_chart(
        &stem,
        "Speedup",
        "processors",
        "speedup",
        &series,
        ChartOptions {
            log_x: true,
            y_from_zero: true,
        },
    )
    .unwrap();
    let svg = std::fs::read_to_string(dir.join("speedup.svg")).unwrap();
    assert!(svg.starts_with("<svg"), "{}", &svg[..60.min(svg.len())]);
    let texts = svg_texts(&svg);
    assert!(
        texts
            .iter()
            .any(|t| t == "sort-middle/ellsworth two-step=on"),
        "{texts:?}"
    );
    assert!(
        texts.iter().any(|t| t == "512"),
        "log axis labels whole powers of two: {texts:?}"
    );
    assert!(
        !texts.iter().any(|t| t == "2.83" || t == "1.41"),
        "no fractional powers: {texts:?}"
    );
    let png = std::fs::read(dir.join("speedup.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    let decoder = png::Decoder::new(png.as_slice());
    let reader = decoder.read_info().unwrap();
    let (w, h) = (reader.info().width, reader.info().height);
    assert!(w > 720 && h >= 480, "{w}x{h}");
}

#[test]
fn svg_and_png_are_deterministic() {
    let series = speedup_series();
    assert_eq!(chart(&series).svg().unwrap(), chart(&series).svg().unwrap());
    assert_eq!(chart(&series).png().unwrap(), chart(&series).png().unwrap());
}

#[test]
fn odd_data_still_draws() {
    let cases = [
        vec![],
        vec![Series::new("empty", vec![])],
        vec![Series::new("one point", vec![(4.0, 2.0)])],
        vec![Series::new("flat", vec![(1.0, 3.0), (2.0, 3.0)])],
        vec![Series::new(
            "gaps",
            vec![
                (0.0, 1.0),
                (1.0, f64::NAN),
                (2.0, 2.0),
                (4.0, f64::INFINITY),
            ],
        )],
    ];
    for series in &cases {
        for log_x in [false, true] {
            for y_from_zero in [false, true] {
                let c = LineChart {
                    options: ChartOptions { log_x, y_from_zero },
                    ..chart(series)
                };
                c.svg()
                    .unwrap_or_else(|e| panic!("{series:?} {log_x} {y_from_zero}: {e}"));
                c.png()
                    .unwrap_or_else(|e| panic!("{series:?} {log_x} {y_from_zero}: {e}"));
            }
        }
    }
}
