//! The stereo sweep's charts: bad-2 error against time for every matcher and pair, and
//! each matcher's bad-2 error pair by pair.

use super::Row;
use crate::chart::{Chart, Line, Lines};

/// The matchers in the rows, in order of first appearance.
fn methods(rows: &[Row]) -> Vec<&str> {
    let mut out: Vec<&str> = Vec::new();
    for r in rows {
        if !out.contains(&r.method.as_str()) {
            out.push(&r.method);
        }
    }
    out
}

/// The rows of one matcher.
fn of<'a>(rows: &'a [Row], method: &'a str) -> impl Iterator<Item = &'a Row> + 'a {
    rows.iter().filter(move |r| r.method == method)
}

/// `(file, chart)` for every chart of the sweep.
pub fn charts(rows: &[Row]) -> Vec<(&'static str, Chart)> {
    let mut pairs: Vec<&str> = Vec::new();
    for r in rows {
        if !pairs.contains(&r.pair.as_str()) {
            pairs.push(&r.pair);
        }
    }
    let scatter = methods(rows)
        .into_iter()
        .map(|m| {
            let points = of(rows, m)
                .map(|r| (r.time.median_ms, 100.0 * r.error.nonocc.bad2))
                .collect();
            let mut line = Line::new(m, points);
            line.labels = of(rows, m).map(|r| r.pair.clone()).collect();
            line
        })
        .collect();
    let by_pair = methods(rows)
        .into_iter()
        .map(|m| {
            let points = of(rows, m)
                .filter_map(|r| {
                    let k = pairs.iter().position(|p| *p == r.pair)?;
                    Some(((k + 1) as f64, 100.0 * r.error.nonocc.bad2))
                })
                .collect();
            Line::new(m, points)
        })
        .collect();
    let size = rows.first().map_or(String::new(), |r| {
        format!(
            ", {}x{}, disparities 0..{}",
            r.width, r.height, r.max_disparity
        )
    });
    vec![
        (
            "stereo_time_error.png",
            Chart::Scatter(
                Lines::new(
                    format!("Stereo matchers: error against time, each pair{size}"),
                    "median time (ms)",
                    "bad 2 over non-occluded pixels (%, unknown counts as bad)",
                    scatter,
                )
                .log(true, false),
            ),
        ),
        (
            "stereo_pairs.png",
            Chart::Lines(Lines::new(
                format!("Bad 2 by pair: {}", pairs.join(", ")),
                "pair (in the order of the title)",
                "bad 2 over non-occluded pixels (%)",
                by_pair,
            )),
        ),
    ]
}
