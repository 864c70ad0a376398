//! The impostors over the showcase tour, as charts written beside the headless frames: the
//! largest predicted error shown per frame against the tolerance and twice it, and the
//! refreshes per frame beside the frame time.

use super::RunStats;
use crate::chart::{self, Chart, Line, Lines};
use std::path::Path;
use std::time::Duration;

/// Writes `path` (the error chart) and the refreshes chart beside it (`_refreshes` added
/// to the file stem).
pub fn tour_chart(
    run: &RunStats,
    times: &[Duration],
    path: &Path,
) -> Result<(), Box<dyn std::error::Error>> {
    let frames = run.per_frame.len();
    let at = |f: &dyn Fn(usize) -> f64| (0..frames).map(|i| (i as f64, f(i))).collect();
    let level = |v: f64| vec![(0.0, v), (frames.max(1) as f64 - 1.0, v)];
    let error = Lines::new(
        "Impostors over the tour: largest predicted error shown",
        "frame",
        "predicted error / tolerance",
        vec![
            Line::new("largest shown", at(&|i| run.per_frame[i].0 as f64)),
            Line::reference("tolerance", level(1.0)),
            Line::reference("twice the tolerance (never shown)", level(2.0)),
        ],
    );
    chart::draw(path, &Chart::Lines(error))?;
    let ms = |i: usize| times.get(i).map_or(f64::NAN, |t| t.as_secs_f64() * 1e3);
    // Two quantities, two axes: refreshes on the left, milliseconds on the right.
    let work = Lines::new(
        "Impostors over the tour: refreshes and frame time",
        "frame",
        "impostor refreshes per frame",
        vec![
            Line::new("refreshes", at(&|i| run.per_frame[i].1 as f64)),
            Line::new("frame time", at(&ms)).on_right(),
        ],
    )
    .right_axis("frame time (ms)");
    let stem = path
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("impostors");
    chart::draw(
        &path.with_file_name(format!("{stem}_refreshes.png")),
        &Chart::Lines(work),
    )?;
    Ok(())
}
