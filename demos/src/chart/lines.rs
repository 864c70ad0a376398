//! [`Lines`] charts: named series of points, drawn joined ([`Joined`]) or as loose dots
//! ([`Dots`]).

use super::plot::{labels, legend, Axes, Axis, Body, Context};
use super::{Error, SERIES};
use plotters::prelude::*;

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

/// A chart of several lines sharing two axes (colours in order, repeating after fourteen).
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

    pub(super) fn axes(&self) -> Axes<'_> {
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
pub(super) struct Joined<'a> {
    spec: &'a Lines,
    lines: Vec<Drawable<'a>>,
}

impl<'a> Joined<'a> {
    pub(super) fn of(spec: &'a Lines) -> Joined<'a> {
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
pub(super) struct Dots<'a> {
    spec: &'a Lines,
    sets: Vec<(&'a str, Vec<(f64, f64)>)>,
}

impl<'a> Dots<'a> {
    pub(super) fn of(spec: &'a Lines) -> Dots<'a> {
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
