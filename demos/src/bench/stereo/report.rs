//! The stereo sweep as the CLI runs it ([`StereoSweep`]: its flags, its rows printed) and
//! its charts: bad-2 error against time for every matcher and pair, and each matcher's
//! bad-2 error pair by pair.

use super::Peer;
use super::Row;
use crate::bench::{Progress, RunFlags, Sweep};
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

/// The `stereo` sweep's flags.
#[derive(clap::Args, Clone, Debug)]
pub struct StereoFlags {
    #[command(flatten)]
    pub run: RunFlags,
    /// Leave OpenCV out (otherwise it runs when `python3 -c "import cv2"` works; `pip
    /// install opencv-python-headless` to get it).
    #[arg(long)]
    pub no_opencv: bool,
}

impl AsRef<RunFlags> for StereoFlags {
    fn as_ref(&self) -> &RunFlags {
        &self.run
    }
}

/// The `stereo` sweep (the module docs of [`super`]).
#[derive(Clone, Copy, Debug)]
pub struct StereoSweep;

impl Sweep for StereoSweep {
    const NAME: &'static str = "stereo";
    const ABOUT: &'static str =
        "Stereo matchers against OpenCV's StereoSGBM on rendered pairs: Middlebury error and time";
    type Flags = StereoFlags;
    /// The settings and OpenCV's script when it runs.
    type Settings = (super::Settings, Option<Peer>);
    type Row = Row;

    fn settings(&self, flags: &StereoFlags) -> Result<Self::Settings, String> {
        let settings = flags.run.pick(
            super::Settings::tiny,
            super::Settings::quick,
            super::Settings::full,
        );
        let peer = Peer::bundled();
        let peer = if flags.no_opencv {
            None
        } else if peer.available() {
            Some(peer)
        } else {
            println!(
                "bench: OpenCV is not installed for python3 (pip install opencv-python-headless); its rows are left out"
            );
            None
        };
        Ok((settings, peer))
    }

    fn rows(
        &self,
        (settings, peer): &Self::Settings,
        flags: &StereoFlags,
        progress: Progress,
    ) -> Result<Vec<Row>, String> {
        super::run(settings, &flags.run.out, peer.as_ref(), progress)
    }

    fn line(&self, r: &Row) -> Option<String> {
        let (n, a) = (&r.error.nonocc, &r.error.all);
        Some(format!(
            "{:<12} {:<15} {}x{} 0..{:<3} median {:>8.2} ms  non-occluded bad 1 {:>5.1}% bad 2 {:>5.1}% RMS {:>5.2} unknown {:>5.1}%  all bad 2 {:>5.1}%",
            r.pair,
            r.method,
            r.width,
            r.height,
            r.max_disparity,
            r.time.median_ms,
            100.0 * n.bad1,
            100.0 * n.bad2,
            n.rms,
            100.0 * n.unknown,
            100.0 * a.bad2,
        ))
    }

    fn charts(&self, rows: &[Row]) -> Vec<(&'static str, Chart)> {
        charts(rows)
    }
}
