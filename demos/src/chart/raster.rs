//! The `bench raster` charts: one labelled line and loose labelled dots
//! ([`LineAndDots`]), for frame time against resolution and against triangle count.

use super::plot::{Axes, Body, Map, Mark, Polyline};
use super::style::Style;
use super::Chart;
use crate::bench::raster::Row;

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
    pub(super) fn axes(&self) -> Axes<'_> {
        Axes {
            title: &self.title,
            x_desc: self.x_desc,
            y_desc: self.y_desc,
            log_x: self.log_x,
            log_y: self.log_y,
            y2_desc: None,
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

    fn legend(&self) -> Vec<(String, Style)> {
        let mut entries = vec![(self.line_name.clone(), Style::series(0, true))];
        if !self.dots.is_empty() {
            entries.push((self.dots_name.to_string(), Style::series(1, false)));
        }
        entries
    }

    fn layout(&self, map: &Map) -> (Vec<Polyline>, Vec<Mark>) {
        let to_px = map.left;
        let (line, dots) = (Style::series(0, true), Style::series(1, false));
        let px = |p: &Point| to_px((p.x, p.y));
        let lines = vec![(self.line.iter().map(px).collect(), line)];
        let mark = |p: &Point, s: Style| Mark {
            at: px(p),
            marker: s.marker,
            colour: s.colour,
            label: p.label.clone(),
        };
        let marks = (self.line.iter().map(|p| mark(p, line)))
            .chain(self.dots.iter().map(|p| mark(p, dots)))
            .collect();
        (lines, marks)
    }
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
