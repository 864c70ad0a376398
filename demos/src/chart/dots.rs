//! One labelled line and loose labelled dots ([`LineAndDots`]): the `bench raster` sweep's
//! frame time against resolution and against triangle count.

use super::plot::{Axes, Body, Map, Mark, Polyline};
use super::style::Style;

/// A labelled point.
#[derive(Clone, Debug)]
pub struct Point {
    pub x: f64,
    pub y: f64,
    pub label: String,
}

/// One chart: a line through `line`, loose labelled `dots`, log or linear axes.
#[derive(Clone, Debug)]
pub struct LineAndDots {
    pub title: String,
    pub x_desc: &'static str,
    pub y_desc: &'static str,
    pub line_name: String,
    pub line: Vec<Point>,
    pub dots_name: &'static str,
    pub dots: Vec<Point>,
    pub log_x: bool,
    pub log_y: bool,
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
