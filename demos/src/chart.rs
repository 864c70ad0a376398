//! PNG charts of benchmark rows, drawn with plotters' bitmap backend.
//!
//! Text is drawn by plotters' pure-Rust `ab_glyph` renderer, from a TrueType font found at
//! run time ([`font_file`]: `$PARALLAX_FONT`, else DejaVu Sans, Liberation Sans or any
//! `.ttf` under the usual font folders), so building needs no font libraries. When no font
//! can be found or read, the chart is drawn without any text (axes, grid, series and
//! points only) rather than failing, and the caller is told so it can say it.

use crate::bench::Row;
use plotters::coord::ranged1d::{Ranged, ValueFormatter};
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

/// Axis range of `values`: from zero, or whole decades on a log axis.
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

/// A chart ready to draw with [`draw`].
#[derive(Clone, Debug)]
pub enum Chart {
    /// Each line's points joined.
    Lines(Lines),
    /// Each line's points as dots, not joined (a scatter: one colour per line, repeating
    /// after four).
    Scatter(Lines),
    /// One labelled line and loose labelled dots.
    LineAndDots(LineAndDots),
}

/// Draws a chart as a PNG, with text when a font is usable (see the module docs). Points
/// with a non-finite coordinate (or, on a log axis, one at or below zero) of a
/// [`Chart::Lines`] or [`Chart::Scatter`] are left out.
pub fn draw(path: &Path, chart: &Chart) -> Result<Drawn, Error> {
    match chart {
        Chart::Lines(spec) => {
            with_fallback(|text| plot(path, &spec.axes(), &Joined::of(spec), text))
        }
        Chart::Scatter(spec) => {
            with_fallback(|text| plot(path, &spec.axes(), &Dots::of(spec), text))
        }
        Chart::LineAndDots(spec) => with_fallback(|text| plot(path, &spec.axes(), spec, text)),
    }
}

/// Draws with text when a font is usable; without when none is, or when drawing with text
/// fails.
fn with_fallback(mut draw: impl FnMut(bool) -> Result<(), Error>) -> Result<Drawn, Error> {
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

/// A chart's title, axis descriptions and scales.
struct Axes<'a> {
    title: &'a str,
    x_desc: &'a str,
    y_desc: &'a str,
    log_x: bool,
    log_y: bool,
}

/// An axis of plotted values (linear or logarithmic).
trait Axis: Ranged<ValueType = f64> + ValueFormatter<f64> {}
impl<T: Ranged<ValueType = f64> + ValueFormatter<f64>> Axis for T {}

type Context<'a, 'b, X, Y> = ChartContext<'a, BitMapBackend<'b>, Cartesian2d<X, Y>>;

/// What a chart draws inside its axes.
trait Body {
    /// Every drawn point (they set the axis ranges).
    fn points(&self) -> Vec<(f64, f64)>;
    fn draw<'a, 'b: 'a, X: Axis, Y: Axis>(
        &self,
        chart: &mut Context<'a, 'b, X, Y>,
        text: bool,
    ) -> Result<(), Error>;
}

/// Draws `body` on `axes` (ranges fitted to its points) into a PNG at `path`.
fn plot(path: &Path, axes: &Axes, body: &impl Body, text: bool) -> Result<(), Error> {
    let points = body.points();
    let (x0, x1) = range(points.iter().map(|p| p.0), axes.log_x);
    let (y0, y1) = range(points.iter().map(|p| p.1), axes.log_y);
    let root = BitMapBackend::new(path, SIZE).into_drawing_area();
    root.fill(&WHITE)?;
    let mut builder = ChartBuilder::on(&root);
    builder.margin(16);
    if text {
        builder
            .caption(axes.title, ("sans-serif", 24))
            .x_label_area_size(48)
            .y_label_area_size(64);
    }
    // The four axis kinds have different coordinate types.
    match (axes.log_x, axes.log_y) {
        (true, true) => inside(
            builder.build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())?,
            axes,
            body,
            text,
        )?,
        (true, false) => inside(
            builder.build_cartesian_2d((x0..x1).log_scale(), y0..y1)?,
            axes,
            body,
            text,
        )?,
        (false, true) => inside(
            builder.build_cartesian_2d(x0..x1, (y0..y1).log_scale())?,
            axes,
            body,
            text,
        )?,
        (false, false) => inside(
            builder.build_cartesian_2d(x0..x1, y0..y1)?,
            axes,
            body,
            text,
        )?,
    }
    root.present()?;
    Ok(())
}

/// The grid, tick labels and axis descriptions, then the body.
fn inside<'a, 'b: 'a, X: Axis, Y: Axis>(
    mut chart: Context<'a, 'b, X, Y>,
    axes: &Axes,
    body: &impl Body,
    text: bool,
) -> Result<(), Error> {
    let mut mesh = chart.configure_mesh();
    if text {
        mesh.x_desc(axes.x_desc)
            .y_desc(axes.y_desc)
            .x_label_formatter(&|x: &f64| short(*x))
            .y_label_formatter(&|y: &f64| short(*y));
    } else {
        mesh.x_labels(0).y_labels(0);
    }
    mesh.draw()?;
    body.draw(&mut chart, text)
}

/// The legend box, at `position`.
fn legend<'a, 'b: 'a, X: Axis, Y: Axis>(
    chart: &mut Context<'a, 'b, X, Y>,
    position: SeriesLabelPosition,
) -> Result<(), Error> {
    chart
        .configure_series_labels()
        .position(position)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()?;
    Ok(())
}

/// Text labels at points.
fn labels<'a, X: Axis, Y: Axis>(
    chart: &mut Context<X, Y>,
    labelled: impl Iterator<Item = ((f64, f64), &'a str)>,
) -> Result<(), Error> {
    chart.draw_series(
        labelled
            .filter(|(_, l)| !l.is_empty())
            .map(|(p, l)| Text::new(l.to_string(), p, ("sans-serif", 14).into_font())),
    )?;
    Ok(())
}

/// A labelled point.
#[derive(Clone, Debug)]
struct Point {
    x: f64,
    y: f64,
    label: String,
}

/// One chart: a line through `line`, loose labelled `dots`, log or linear axes.
#[derive(Clone, Debug)]
pub struct LineAndDots {
    title: String,
    x_desc: &'static str,
    y_desc: &'static str,
    line_name: String,
    line: Vec<Point>,
    dots_name: &'static str,
    dots: Vec<Point>,
    log_x: bool,
    log_y: bool,
}

impl LineAndDots {
    fn axes(&self) -> Axes<'_> {
        Axes {
            title: &self.title,
            x_desc: self.x_desc,
            y_desc: self.y_desc,
            log_x: self.log_x,
            log_y: self.log_y,
        }
    }
}

impl Body for LineAndDots {
    fn points(&self) -> Vec<(f64, f64)> {
        self.line
            .iter()
            .chain(&self.dots)
            .map(|p| (p.x, p.y))
            .collect()
    }

    fn draw<'a, 'b: 'a, X: Axis, Y: Axis>(
        &self,
        chart: &mut Context<'a, 'b, X, Y>,
        text: bool,
    ) -> Result<(), Error> {
        let c = SERIES[0];
        let line: Vec<(f64, f64)> = self.line.iter().map(|p| (p.x, p.y)).collect();
        let s = chart.draw_series(LineSeries::new(line.clone(), c.stroke_width(2)))?;
        if text {
            s.label(self.line_name.as_str()).legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2))
            });
        }
        chart.draw_series(line.iter().map(|&p| Circle::new(p, 4, c.filled())))?;
        if text {
            labels(
                chart,
                self.line.iter().map(|p| ((p.x, p.y), p.label.as_str())),
            )?;
        }
        let d = SERIES[1];
        let s = chart.draw_series(
            self.dots
                .iter()
                .map(|p| Circle::new((p.x, p.y), 5, d.filled())),
        )?;
        if text && !self.dots.is_empty() {
            s.label(self.dots_name)
                .legend(move |(x, y)| Circle::new((x + 10, y), 5, d.filled()));
            labels(
                chart,
                self.dots.iter().map(|p| ((p.x, p.y), p.label.as_str())),
            )?;
        }
        if text {
            legend(chart, SeriesLabelPosition::UpperLeft)?;
        }
        Ok(())
    }
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

/// Median frame time against megapixels for the `resolution` rows.
pub fn resolution_chart(rows: &[Row]) -> Chart {
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
    Chart::LineAndDots(LineAndDots {
        title: format!("Frame time vs resolution ({mesh})"),
        x_desc: "megapixels",
        y_desc: "median frame time (ms)",
        line_name: mesh,
        line,
        dots_name: "",
        dots: Vec::new(),
        log_x: false,
        log_y: false,
    })
}

/// Median frame time against triangle count: the torus series as a line, the shared
/// models as labelled dots.
pub fn triangles_chart(rows: &[Row]) -> Chart {
    let points = |series: &str| -> Vec<Point> {
        rows.iter()
            .filter(|r| r.series == series)
            .map(|r| Point {
                x: r.triangles.max(1) as f64,
                y: r.time.median_ms,
                label: r.mesh.clone(),
            })
            .collect()
    };
    let size = rows
        .iter()
        .find(|r| r.series == "triangles")
        .map_or(String::new(), |r| format!(" at {}x{}", r.width, r.height));
    Chart::LineAndDots(LineAndDots {
        title: format!("Frame time vs triangles{size}"),
        x_desc: "triangles",
        y_desc: "median frame time (ms)",
        line_name: "procedural torus".into(),
        line: points("triangles"),
        dots_name: "shared models",
        dots: points("model"),
        log_x: true,
        log_y: true,
    })
}

/// One named series of a [`Lines`] chart: points joined by a line, optionally labelled
/// (`labels` empty, or one per point). Points with a non-finite coordinate (or, on a log
/// axis, one at or below zero) are left out.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Line {
    pub name: String,
    pub points: Vec<(f64, f64)>,
    pub labels: Vec<String>,
}

impl Line {
    /// A named line without labels.
    pub fn new(name: impl Into<String>, points: Vec<(f64, f64)>) -> Line {
        Line {
            name: name.into(),
            points,
            labels: Vec::new(),
        }
    }
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

impl Lines {
    /// Linear axes, the legend at the upper left.
    pub fn new(title: impl Into<String>, x_desc: &str, y_desc: &str, lines: Vec<Line>) -> Lines {
        Lines {
            title: title.into(),
            x_desc: x_desc.into(),
            y_desc: y_desc.into(),
            lines,
            log_x: false,
            log_y: false,
            legend: SeriesLabelPosition::UpperLeft,
        }
    }

    /// With log (or linear) axes.
    pub fn log(self, log_x: bool, log_y: bool) -> Lines {
        Lines {
            log_x,
            log_y,
            ..self
        }
    }

    /// With the legend at `position`.
    pub fn legend(self, position: SeriesLabelPosition) -> Lines {
        Lines {
            legend: position,
            ..self
        }
    }

    fn axes(&self) -> Axes<'_> {
        Axes {
            title: &self.title,
            x_desc: &self.x_desc,
            y_desc: &self.y_desc,
            log_x: self.log_x,
            log_y: self.log_y,
        }
    }

    /// Whether a point can be drawn on the chart's axes.
    fn keeps(&self, (x, y): (f64, f64)) -> bool {
        let keep = |v: f64, log: bool| v.is_finite() && (!log || v > 0.0);
        keep(x, self.log_x) && keep(y, self.log_y)
    }
}

/// A line with the points (and their labels) that can be drawn on the chart's axes.
type Drawable<'a> = (&'a Line, Vec<(f64, f64)>, Vec<&'a str>);

/// A [`Lines`] chart's lines with the points (and their labels) it can draw.
struct Joined<'a> {
    spec: &'a Lines,
    lines: Vec<Drawable<'a>>,
}

impl<'a> Joined<'a> {
    fn of(spec: &'a Lines) -> Joined<'a> {
        let lines = spec
            .lines
            .iter()
            .map(|l| {
                let mut pts = Vec::new();
                let mut labels = Vec::new();
                for (i, &p) in l.points.iter().enumerate() {
                    if spec.keeps(p) {
                        pts.push(p);
                        labels.push(l.labels.get(i).map_or("", |s| s.as_str()));
                    }
                }
                (l, pts, labels)
            })
            .collect();
        Joined { spec, lines }
    }
}

impl Body for Joined<'_> {
    fn points(&self) -> Vec<(f64, f64)> {
        self.lines
            .iter()
            .flat_map(|(_, p, _)| p.iter().copied())
            .collect()
    }

    fn draw<'a, 'b: 'a, X: Axis, Y: Axis>(
        &self,
        chart: &mut Context<'a, 'b, X, Y>,
        text: bool,
    ) -> Result<(), Error> {
        for (k, (line, pts, names)) in self.lines.iter().enumerate() {
            let c = SERIES[k % SERIES.len()];
            let s = chart.draw_series(LineSeries::new(pts.clone(), c.stroke_width(2)))?;
            if text && !line.name.is_empty() {
                s.label(line.name.as_str()).legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2))
                });
            }
            chart.draw_series(pts.iter().map(|&p| Circle::new(p, 4, c.filled())))?;
            if text {
                labels(chart, pts.iter().copied().zip(names.iter().copied()))?;
            }
        }
        if text && self.lines.iter().any(|(l, _, _)| !l.name.is_empty()) {
            legend(chart, self.spec.legend.clone())?;
        }
        Ok(())
    }
}

/// A [`Lines`] chart's points as loose dots, by line.
struct Dots<'a> {
    spec: &'a Lines,
    sets: Vec<(&'a str, Vec<(f64, f64)>)>,
}

impl<'a> Dots<'a> {
    fn of(spec: &'a Lines) -> Dots<'a> {
        let sets = spec
            .lines
            .iter()
            .map(|l| {
                let pts = l.points.iter().copied().filter(|&p| spec.keeps(p));
                (l.name.as_str(), pts.collect())
            })
            .collect();
        Dots { spec, sets }
    }
}

impl Body for Dots<'_> {
    fn points(&self) -> Vec<(f64, f64)> {
        self.sets
            .iter()
            .flat_map(|(_, p)| p.iter().copied())
            .collect()
    }

    fn draw<'a, 'b: 'a, X: Axis, Y: Axis>(
        &self,
        chart: &mut Context<'a, 'b, X, Y>,
        text: bool,
    ) -> Result<(), Error> {
        for (k, (name, pts)) in self.sets.iter().enumerate() {
            let c = SERIES[k % SERIES.len()];
            let s = chart.draw_series(pts.iter().map(|&p| Circle::new(p, 3, c.filled())))?;
            if text && !name.is_empty() {
                s.label(*name)
                    .legend(move |(x, y)| Circle::new((x + 10, y), 4, c.filled()));
            }
        }
        if text && self.sets.iter().any(|(n, _)| !n.is_empty()) {
            legend(chart, self.spec.legend.clone())?;
        }
        Ok(())
    }
}
