//! [`Lines`] charts: named series of points, drawn joined or as loose dots ([`Series`]),
//! each series with its own colour, marker and dash; reference lines (identity, tolerance)
//! grey and dashed; "exact" values (a PSNR of identical images) as arrows at the top of the
//! y axis instead of a made-up number.

use super::plot::{Axes, Body, Map, Mark, Polyline};
use super::style::{Marker, Style};

/// One named series of a [`Lines`] chart: points joined by a line, optionally labelled
/// (`labels` empty, or one per point). Points with a non-finite coordinate (or, on a log
/// axis, one at or below zero) are left out.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Line {
    pub name: String,
    pub points: Vec<(f64, f64)>,
    pub labels: Vec<String>,
    /// A reference line (identity, tolerance): always joined, grey and dashed, no markers
    /// or labels, even on a [`super::Chart::Scatter`].
    pub reference: bool,
    /// On the right y axis (see [`Lines::right_axis`]).
    pub right: bool,
}

impl Line {
    /// A named line without labels.
    pub fn new(name: impl Into<String>, points: Vec<(f64, f64)>) -> Line {
        Line {
            name: name.into(),
            points,
            labels: Vec::new(),
            reference: false,
            right: false,
        }
    }

    /// A named reference line (see [`Line::reference`]).
    pub fn reference(name: impl Into<String>, points: Vec<(f64, f64)>) -> Line {
        Line {
            reference: true,
            ..Line::new(name, points)
        }
    }

    /// On the right y axis.
    pub fn on_right(self) -> Line {
        Line {
            right: true,
            ..self
        }
    }

    /// With one label per point.
    pub fn labelled(self, labels: Vec<String>) -> Line {
        Line { labels, ..self }
    }
}

/// A chart of several lines sharing two axes (colours in order, repeating after fourteen;
/// markers after six; dashes after three). The legend, when there are two or more named
/// lines, is drawn beside the plot, never over the data.
#[derive(Clone, Debug)]
pub struct Lines {
    pub title: String,
    pub x_desc: String,
    pub y_desc: String,
    pub lines: Vec<Line>,
    pub log_x: bool,
    pub log_y: bool,
    /// Y values at or above this are "exact" (a PSNR of identical images): drawn on a dotted
    /// line near the top of the y axis (in the legend as "exact: identical images"), the
    /// axis range coming from the other values.
    pub exact_at: Option<f64>,
    /// The right y axis' description (linear, from zero), for lines [`Line::on_right`]: a
    /// second quantity gets its own axis.
    pub y2_desc: Option<String>,
}

impl Lines {
    /// Linear axes, no "exact" values.
    pub fn new(title: impl Into<String>, x_desc: &str, y_desc: &str, lines: Vec<Line>) -> Lines {
        Lines {
            title: title.into(),
            x_desc: x_desc.into(),
            y_desc: y_desc.into(),
            lines,
            log_x: false,
            log_y: false,
            exact_at: None,
            y2_desc: None,
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

    /// With a right y axis described by `desc`, for the lines [`Line::on_right`].
    pub fn right_axis(self, desc: &str) -> Lines {
        Lines {
            y2_desc: Some(desc.into()),
            ..self
        }
    }

    /// With y values at or above `cap` drawn as "exact" (see [`Lines::exact_at`]).
    pub fn exact_at(self, cap: f64) -> Lines {
        Lines {
            exact_at: Some(cap),
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
            y2_desc: self.y2_desc.as_deref(),
        }
    }

    /// Whether a point can be drawn on the chart's axes.
    fn keeps(&self, (x, y): (f64, f64)) -> bool {
        let keep = |v: f64, log: bool| v.is_finite() && (!log || v > 0.0);
        keep(x, self.log_x) && (self.exact(y) || keep(y, self.log_y))
    }

    /// Whether `y` is "exact".
    fn exact(&self, y: f64) -> bool {
        self.exact_at.is_some_and(|cap| y >= cap)
    }
}

/// A point and its label.
type Labelled<'a> = ((f64, f64), &'a str);

/// A [`Lines`] chart's lines with the points (and their labels) it can draw, joined or as
/// loose dots.
pub(super) struct Series<'a> {
    spec: &'a Lines,
    joined: bool,
    /// Each line, its style, and its drawable points with their labels.
    lines: Vec<(&'a Line, Style, Vec<Labelled<'a>>)>,
}

impl<'a> Series<'a> {
    pub(super) fn of(spec: &'a Lines, joined: bool) -> Series<'a> {
        let (mut data, mut refs) = (0, 0);
        let lines = spec
            .lines
            .iter()
            .map(|l| {
                let style = if l.reference {
                    refs += 1;
                    Style::reference(refs - 1)
                } else {
                    data += 1;
                    Style::series(data - 1, joined)
                };
                let pts = (l.points.iter().enumerate())
                    .filter(|(_, &p)| spec.keeps(p))
                    .map(|(i, &p)| (p, l.labels.get(i).map_or("", |s| s.as_str())))
                    .collect();
                (l, style, pts)
            })
            .collect();
        Series {
            spec,
            joined,
            lines,
        }
    }
}

impl Series<'_> {
    /// Whether `line` is drawn on the right y axis (there is one only when described).
    fn right(&self, line: &Line) -> bool {
        line.right && self.spec.y2_desc.is_some()
    }
}

impl Body for Series<'_> {
    fn points(&self) -> Vec<(f64, f64)> {
        (self.lines.iter().filter(|(l, _, _)| !self.right(l)))
            .flat_map(|(_, _, p)| p.iter())
            .map(|&(p, _)| p)
            .filter(|p| !self.spec.exact(p.1))
            .collect()
    }

    fn points_right(&self) -> Vec<(f64, f64)> {
        (self.lines.iter().filter(|(l, _, _)| self.right(l)))
            .flat_map(|(_, _, p)| p.iter().map(|&(p, _)| p))
            .collect()
    }

    fn has_exact(&self) -> bool {
        (self.lines.iter().flat_map(|(_, _, p)| p.iter())).any(|(p, _)| self.spec.exact(p.1))
    }

    fn legend(&self) -> Vec<(String, Style)> {
        let mut entries: Vec<(String, Style)> = (self.lines.iter())
            .filter(|(l, _, _)| !l.name.is_empty())
            .map(|(l, s, _)| match self.right(l) {
                true => (format!("{} (right axis)", l.name), *s),
                false => (l.name.clone(), *s),
            })
            .collect();
        if self.has_exact() {
            entries.push(("exact: identical images".into(), exact_style()));
        }
        entries
    }

    fn layout(&self, map: &Map) -> (Vec<Polyline>, Vec<Mark>) {
        let (mut lines, mut marks) = (Vec::new(), Vec::new());
        let exact_y = map.exact_y;
        for (line, style, pts) in &self.lines {
            let to_px = if self.right(line) {
                map.right
            } else {
                map.left
            };
            let px: Vec<(i32, i32)> = pts
                .iter()
                .map(|&((x, y), _)| to_px((x, if self.spec.exact(y) { exact_y } else { y })))
                .collect();
            if line.reference || self.joined {
                lines.push((px.clone(), *style));
            }
            if line.reference {
                continue;
            }
            for (&at, &(_, label)) in px.iter().zip(pts) {
                marks.push(Mark {
                    at,
                    marker: style.marker,
                    colour: style.colour,
                    label: label.to_string(),
                });
            }
        }
        if self.has_exact() {
            // One dashed line across the data at the "exact" height, in the legend.
            let xs = self
                .lines
                .iter()
                .flat_map(|(_, _, p)| p.iter().map(|(p, _)| p.0));
            let lo = xs.clone().fold(f64::INFINITY, f64::min);
            let hi = xs.fold(f64::NEG_INFINITY, f64::max);
            let ends = vec![(map.left)((lo, exact_y)), (map.left)((hi, exact_y))];
            marks.push(Mark {
                at: ends[1],
                marker: Marker::None,
                colour: exact_style().colour,
                label: "exact".into(),
            });
            lines.push((ends, exact_style()));
        }
        (lines, marks)
    }
}

/// The "exact" line's look.
fn exact_style() -> Style {
    Style {
        marker: Marker::None,
        ..Style::reference(1)
    }
}
