//! PNG charts of benchmark rows, drawn with plotters' bitmap backend.
//!
//! Text is drawn by plotters' pure-Rust `ab_glyph` renderer, from a TrueType font found at
//! run time ([`font_file`]: `$PARALLAX_FONT`, else DejaVu Sans, Liberation Sans or any
//! `.ttf` under the usual font folders), so building needs no font libraries. When no font
//! can be found or read, the chart is drawn without any text (axes, grid, series and
//! points only) rather than failing, and the caller is told so it can say it.

use crate::bench::Row;
use plotters::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

type Error = Box<dyn std::error::Error>;

/// Whether a chart got its text.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Drawn {
    WithText,
    /// No usable font: drawn without captions, labels or legends.
    WithoutText,
}

const SIZE: (u32, u32) = (960, 600);
const SERIES: [RGBColor; 4] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
];

/// Axis labels: 1.5, 20, 300, 4k, 2.5M.
fn short(v: f64) -> String {
    let a = v.abs();
    let trim = |s: String| {
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    };
    if a >= 1e6 {
        format!("{}M", trim(format!("{:.2}", v / 1e6)))
    } else if a >= 1e3 {
        format!("{}k", trim(format!("{:.1}", v / 1e3)))
    } else if a >= 10.0 {
        format!("{v:.0}")
    } else {
        trim(format!("{v:.2}"))
    }
}

/// A labelled point.
struct Point {
    x: f64,
    y: f64,
    label: String,
}

/// One chart: a line through `line`, loose labelled `dots`, log or linear axes.
struct Spec<'a> {
    title: &'a str,
    x_desc: &'a str,
    y_desc: &'a str,
    line_name: &'a str,
    line: Vec<Point>,
    dots_name: &'a str,
    dots: Vec<Point>,
    log_x: bool,
    log_y: bool,
}

fn range(values: impl Iterator<Item = f64> + Clone, log: bool) -> (f64, f64) {
    let lo = values.clone().fold(f64::INFINITY, f64::min);
    let hi = values.fold(f64::NEG_INFINITY, f64::max);
    if !lo.is_finite() || !hi.is_finite() {
        return (if log { 0.1 } else { 0.0 }, 1.0);
    }
    if log {
        // Whole decades, so every log axis has labelled ticks.
        let lo = lo.max(1e-3);
        let decade = |v: f64, up: bool| {
            let e = v.log10();
            10f64.powf(if up { e.ceil() } else { e.floor() })
        };
        (decade(lo * 0.8, false), decade(hi.max(lo) * 1.25, true))
    } else {
        (0.0, hi.max(1e-3) * 1.15)
    }
}

fn draw(path: &Path, spec: &Spec, text: bool) -> Result<(), Error> {
    let root = BitMapBackend::new(path, SIZE).into_drawing_area();
    root.fill(&WHITE)?;
    let all = spec.line.iter().chain(&spec.dots);
    let (x0, x1) = range(all.clone().map(|p| p.x), spec.log_x);
    let (y0, y1) = range(all.map(|p| p.y), spec.log_y);
    let mut builder = ChartBuilder::on(&root);
    builder.margin(16);
    if text {
        builder
            .caption(spec.title, ("sans-serif", 24))
            .x_label_area_size(48)
            .y_label_area_size(64);
    }
    // One body for the four axis kinds (their coordinate types differ).
    macro_rules! body {
        ($chart:expr) => {{
            let mut chart = $chart;
            let mut mesh = chart.configure_mesh();
            if text {
                mesh.x_desc(spec.x_desc)
                    .y_desc(spec.y_desc)
                    .x_label_formatter(&|x: &f64| short(*x))
                    .y_label_formatter(&|y: &f64| short(*y));
            } else {
                mesh.x_labels(0).y_labels(0);
            }
            mesh.draw()?;
            let c = SERIES[0];
            let line: Vec<(f64, f64)> = spec.line.iter().map(|p| (p.x, p.y)).collect();
            let s = chart.draw_series(LineSeries::new(line.clone(), c.stroke_width(2)))?;
            if text {
                s.label(spec.line_name).legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2))
                });
            }
            chart.draw_series(line.iter().map(|&p| Circle::new(p, 4, c.filled())))?;
            if text {
                chart.draw_series(spec.line.iter().map(|p| {
                    Text::new(p.label.clone(), (p.x, p.y), ("sans-serif", 14).into_font())
                }))?;
            }
            let d = SERIES[1];
            let s = chart.draw_series(
                spec.dots
                    .iter()
                    .map(|p| Circle::new((p.x, p.y), 5, d.filled())),
            )?;
            if text && !spec.dots.is_empty() {
                s.label(spec.dots_name)
                    .legend(move |(x, y)| Circle::new((x + 10, y), 5, d.filled()));
                chart.draw_series(spec.dots.iter().map(|p| {
                    Text::new(p.label.clone(), (p.x, p.y), ("sans-serif", 14).into_font())
                }))?;
            }
            if text {
                chart
                    .configure_series_labels()
                    .position(SeriesLabelPosition::UpperLeft)
                    .background_style(WHITE.mix(0.85))
                    .border_style(BLACK)
                    .draw()?;
            }
        }};
    }
    match (spec.log_x, spec.log_y) {
        (true, true) => {
            body!(builder.build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())?)
        }
        (true, false) => body!(builder.build_cartesian_2d((x0..x1).log_scale(), y0..y1)?),
        (false, true) => body!(builder.build_cartesian_2d(x0..x1, (y0..y1).log_scale())?),
        (false, false) => body!(builder.build_cartesian_2d(x0..x1, y0..y1)?),
    }
    root.present()?;
    Ok(())
}

/// The font file charts use: `$PARALLAX_FONT` when set, else the first of DejaVu Sans,
/// Liberation Sans, or any `.ttf` file found under the usual font folders.
pub fn font_file() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("PARALLAX_FONT") {
        return Some(PathBuf::from(p));
    }
    fn walk(dir: &Path, depth: u32, out: &mut Vec<PathBuf>) {
        let Ok(entries) = std::fs::read_dir(dir) else {
            return;
        };
        let mut entries: Vec<PathBuf> = entries.flatten().map(|e| e.path()).collect();
        entries.sort();
        for p in entries {
            if p.is_dir() && depth < 4 {
                walk(&p, depth + 1, out);
            } else if p.extension().is_some_and(|e| e.eq_ignore_ascii_case("ttf")) {
                out.push(p);
            }
        }
    }
    let mut found = Vec::new();
    for dir in [
        "/usr/share/fonts",
        "/usr/local/share/fonts",
        "/Library/Fonts",
        "C:\\Windows\\Fonts",
    ] {
        walk(Path::new(dir), 0, &mut found);
    }
    let named = |name: &str| {
        found
            .iter()
            .find(|p| p.file_name().is_some_and(|f| f.eq_ignore_ascii_case(name)))
            .cloned()
    };
    named("DejaVuSans.ttf")
        .or_else(|| named("LiberationSans-Regular.ttf"))
        .or_else(|| named("Arial.ttf"))
        .or_else(|| found.into_iter().next())
}

/// Registers [`font_file`] as plotters' "sans-serif" once; whether text can be drawn.
fn font_ready() -> bool {
    static READY: OnceLock<bool> = OnceLock::new();
    *READY.get_or_init(|| {
        let Some(bytes) = font_file().and_then(|p| std::fs::read(p).ok()) else {
            return false;
        };
        // plotters keeps fonts for the life of the program; this runs once.
        let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
        plotters::style::register_font("sans-serif", FontStyle::Normal, bytes).is_ok()
    })
}

fn draw_with_fallback(path: &Path, spec: &Spec) -> Result<Drawn, Error> {
    if !font_ready() {
        draw(path, spec, false)?;
        return Ok(Drawn::WithoutText);
    }
    match draw(path, spec, true) {
        Ok(()) => Ok(Drawn::WithText),
        Err(_) => {
            draw(path, spec, false)?;
            Ok(Drawn::WithoutText)
        }
    }
}

/// Median frame time against megapixels for the `resolution` rows.
pub fn resolution_chart(path: &Path, rows: &[Row]) -> Result<Drawn, Error> {
    let line: Vec<Point> = rows
        .iter()
        .filter(|r| r.series == "resolution")
        .map(|r| Point {
            x: r.width as f64 * r.height as f64 / 1e6,
            y: r.time.median_ms,
            label: format!("{}x{}", r.width, r.height),
        })
        .collect();
    let mesh = rows
        .iter()
        .find(|r| r.series == "resolution")
        .map_or(String::new(), |r| r.mesh.clone());
    let title = format!("Frame time vs resolution ({mesh})");
    draw_with_fallback(
        path,
        &Spec {
            title: &title,
            x_desc: "megapixels",
            y_desc: "median frame time (ms)",
            line_name: &mesh,
            line,
            dots_name: "",
            dots: Vec::new(),
            log_x: false,
            log_y: false,
        },
    )
}

/// Median frame time against triangle count: the torus series as a line, the shared
/// models as labelled dots.
pub fn triangles_chart(path: &Path, rows: &[Row]) -> Result<Drawn, Error> {
    let point = |r: &Row, label: String| Point {
        x: r.triangles.max(1) as f64,
        y: r.time.median_ms,
        label,
    };
    let line: Vec<Point> = rows
        .iter()
        .filter(|r| r.series == "triangles")
        .map(|r| point(r, r.mesh.clone()))
        .collect();
    let dots: Vec<Point> = rows
        .iter()
        .filter(|r| r.series == "model")
        .map(|r| point(r, r.mesh.clone()))
        .collect();
    let size = rows
        .iter()
        .find(|r| r.series == "triangles")
        .map_or(String::new(), |r| format!(" at {}x{}", r.width, r.height));
    let title = format!("Frame time vs triangles{size}");
    draw_with_fallback(
        path,
        &Spec {
            title: &title,
            x_desc: "triangles",
            y_desc: "median frame time (ms)",
            line_name: "procedural torus",
            line,
            dots_name: "shared models",
            dots,
            log_x: true,
            log_y: true,
        },
    )
}

/// One named series of a [`lines_chart`]: points joined by a line, optionally labelled
/// (`labels` empty, or one per point). Points with a non-finite coordinate (or, on a log
/// axis, one at or below zero) are left out.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Line {
    pub name: String,
    pub points: Vec<(f64, f64)>,
    pub labels: Vec<String>,
}

/// A chart of several lines sharing two axes (colours in order, repeating after four).
#[derive(Clone, Debug)]
pub struct Lines {
    pub title: String,
    pub x_desc: String,
    pub y_desc: String,
    pub lines: Vec<Line>,
    pub log_x: bool,
    pub log_y: bool,
    /// Where the legend goes.
    pub legend: SeriesLabelPosition,
}

/// A line with the points (and their labels) that can be drawn on the chart's axes.
type Drawable<'a> = (&'a Line, Vec<(f64, f64)>, Vec<&'a str>);

fn draw_lines(path: &Path, spec: &Lines, text: bool) -> Result<(), Error> {
    let keep = |x: f64, log: bool| x.is_finite() && (!log || x > 0.0);
    let lines: Vec<Drawable> = spec
        .lines
        .iter()
        .map(|l| {
            let mut pts = Vec::new();
            let mut labels = Vec::new();
            for (i, &(x, y)) in l.points.iter().enumerate() {
                if keep(x, spec.log_x) && keep(y, spec.log_y) {
                    pts.push((x, y));
                    labels.push(l.labels.get(i).map_or("", |s| s.as_str()));
                }
            }
            (l, pts, labels)
        })
        .collect();
    let all = lines.iter().flat_map(|(_, p, _)| p.iter().copied());
    let (x0, x1) = range(all.clone().map(|p| p.0), spec.log_x);
    let (y0, y1) = range(all.map(|p| p.1), spec.log_y);
    let root = BitMapBackend::new(path, SIZE).into_drawing_area();
    root.fill(&WHITE)?;
    let mut builder = ChartBuilder::on(&root);
    builder.margin(16);
    if text {
        builder
            .caption(spec.title.as_str(), ("sans-serif", 24))
            .x_label_area_size(48)
            .y_label_area_size(64);
    }
    macro_rules! body {
        ($chart:expr) => {{
            let mut chart = $chart;
            let mut mesh = chart.configure_mesh();
            if text {
                mesh.x_desc(spec.x_desc.as_str())
                    .y_desc(spec.y_desc.as_str())
                    .x_label_formatter(&|x: &f64| short(*x))
                    .y_label_formatter(&|y: &f64| short(*y));
            } else {
                mesh.x_labels(0).y_labels(0);
            }
            mesh.draw()?;
            for (k, (line, pts, labels)) in lines.iter().enumerate() {
                let c = SERIES[k % SERIES.len()];
                let s = chart.draw_series(LineSeries::new(pts.clone(), c.stroke_width(2)))?;
                if text && !line.name.is_empty() {
                    s.label(line.name.as_str()).legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2))
                    });
                }
                chart.draw_series(pts.iter().map(|&p| Circle::new(p, 4, c.filled())))?;
                if text {
                    chart.draw_series(
                        pts.iter()
                            .zip(labels)
                            .filter(|(_, l)| !l.is_empty())
                            .map(|(&p, l)| {
                                Text::new(l.to_string(), p, ("sans-serif", 14).into_font())
                            }),
                    )?;
                }
            }
            if text && lines.iter().any(|(l, _, _)| !l.name.is_empty()) {
                chart
                    .configure_series_labels()
                    .position(spec.legend.clone())
                    .background_style(WHITE.mix(0.85))
                    .border_style(BLACK)
                    .draw()?;
            }
        }};
    }
    match (spec.log_x, spec.log_y) {
        (true, true) => {
            body!(builder.build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())?)
        }
        (true, false) => body!(builder.build_cartesian_2d((x0..x1).log_scale(), y0..y1)?),
        (false, true) => body!(builder.build_cartesian_2d(x0..x1, (y0..y1).log_scale())?),
        (false, false) => body!(builder.build_cartesian_2d(x0..x1, y0..y1)?),
    }
    root.present()?;
    Ok(())
}

/// Draws a [`Lines`] chart as a PNG, with text when a font is usable (see the module docs).
pub fn lines_chart(path: &Path, spec: &Lines) -> Result<Drawn, Error> {
    if !font_ready() {
        draw_lines(path, spec, false)?;
        return Ok(Drawn::WithoutText);
    }
    match draw_lines(path, spec, true) {
        Ok(()) => Ok(Drawn::WithText),
        Err(_) => {
            draw_lines(path, spec, false)?;
            Ok(Drawn::WithoutText)
        }
    }
}

/// Draws a [`Lines`] chart's points as dots, not joined (a scatter: one colour per line,
/// repeating after four), as a PNG with text when a font is usable (see the module docs).
/// Points with a non-finite coordinate (or, on a log axis, one at or below zero) are left
/// out.
pub fn scatter_chart(path: &Path, spec: &Lines) -> Result<Drawn, Error> {
    let draw = |text: bool| -> Result<(), Error> {
        let keep = |x: f64, log: bool| x.is_finite() && (!log || x > 0.0);
        let sets: Vec<(&str, Vec<(f64, f64)>)> = spec
            .lines
            .iter()
            .map(|l| {
                let pts = l.points.iter().copied();
                let pts = pts.filter(|&(x, y)| keep(x, spec.log_x) && keep(y, spec.log_y));
                (l.name.as_str(), pts.collect())
            })
            .collect();
        let all = sets.iter().flat_map(|(_, p)| p.iter().copied());
        let (x0, x1) = range(all.clone().map(|p| p.0), spec.log_x);
        let (y0, y1) = range(all.map(|p| p.1), spec.log_y);
        let root = BitMapBackend::new(path, SIZE).into_drawing_area();
        root.fill(&WHITE)?;
        let mut builder = ChartBuilder::on(&root);
        builder.margin(16);
        if text {
            builder
                .caption(spec.title.as_str(), ("sans-serif", 24))
                .x_label_area_size(48)
                .y_label_area_size(64);
        }
        macro_rules! body {
            ($chart:expr) => {{
                let mut chart = $chart;
                let mut mesh = chart.configure_mesh();
                if text {
                    mesh.x_desc(spec.x_desc.as_str())
                        .y_desc(spec.y_desc.as_str())
                        .x_label_formatter(&|x: &f64| short(*x))
                        .y_label_formatter(&|y: &f64| short(*y));
                } else {
                    mesh.x_labels(0).y_labels(0);
                }
                mesh.draw()?;
                for (k, (name, pts)) in sets.iter().enumerate() {
                    let c = SERIES[k % SERIES.len()];
                    let s =
                        chart.draw_series(pts.iter().map(|&p| Circle::new(p, 3, c.filled())))?;
                    if text && !name.is_empty() {
                        s.label(*name)
                            .legend(move |(x, y)| Circle::new((x + 10, y), 4, c.filled()));
                    }
                }
                if text && sets.iter().any(|(n, _)| !n.is_empty()) {
                    chart
                        .configure_series_labels()
                        .position(spec.legend.clone())
                        .background_style(WHITE.mix(0.85))
                        .border_style(BLACK)
                        .draw()?;
                }
            }};
        }
        match (spec.log_x, spec.log_y) {
            (true, true) => {
                body!(builder.build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())?)
            }
            (true, false) => body!(builder.build_cartesian_2d((x0..x1).log_scale(), y0..y1)?),
            (false, true) => body!(builder.build_cartesian_2d(x0..x1, (y0..y1).log_scale())?),
            (false, false) => body!(builder.build_cartesian_2d(x0..x1, y0..y1)?),
        }
        root.present()?;
        Ok(())
    };
    if !font_ready() {
        draw(false)?;
        return Ok(Drawn::WithoutText);
    }
    match draw(true) {
        Ok(()) => Ok(Drawn::WithText),
        Err(_) => {
            draw(false)?;
            Ok(Drawn::WithoutText)
        }
    }
}
