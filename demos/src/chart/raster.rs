//! The `bench raster` charts: one labelled line and loose labelled dots
//! ([`LineAndDots`]), for frame time against resolution and against triangle count.

use super::plot::{labels, legend, Axes, Axis, Body, Context};
use super::{Chart, Error, SERIES};
use crate::bench::Row;
use plotters::prelude::*;

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
