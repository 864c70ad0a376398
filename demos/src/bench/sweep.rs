//! What every benchmark sweep shares: CSV rows and their file, progress steps, and the
//! warm-up-then-timed-frames loop under a time limit.

use std::io::Write;
use std::path::Path;
use std::time::{Duration, Instant};

/// Fewest timed frames of a measurement, whatever the time limit.
pub const MIN_FRAMES: usize = 2;

/// A row of a sweep's CSV file.
pub trait CsvRow {
    /// The header row: column names, comma-separated.
    const HEADER: &'static str;
    /// The row's fields, comma-separated, in the header's order.
    fn csv(&self) -> String;
}

/// Writes rows as CSV with a header row.
pub fn write_csv<R: CsvRow>(path: &Path, rows: &[R]) -> std::io::Result<()> {
    let mut f = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(f, "{}", R::HEADER)?;
    for r in rows {
        writeln!(f, "{}", r.csv())?;
    }
    f.flush()
}

/// Numbers a sweep's progress steps: each call reports the step's 0-based index, the
/// total, and what it is to `progress`, then counts it.
pub fn ticker<'a>(
    total: usize,
    progress: &'a mut dyn FnMut(usize, usize, &str),
) -> impl FnMut(String) + 'a {
    let mut step = 0;
    move |what: String| {
        progress(step, total, &what);
        step += 1;
    }
}

/// How a measurement times its frames: `warmup` untimed frames, then timed frames until
/// there are `frames` of them (at least [`MIN_FRAMES`]) or, once there are `MIN_FRAMES`,
/// `time_limit` has passed since the first.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Timing {
    pub warmup: usize,
    /// Most timed frames per measurement.
    pub frames: usize,
    /// Time limit per measurement.
    pub time_limit: Duration,
}

impl Timing {
    /// `warmup` untimed frames, then up to `frames` timed ones within `limit_s` seconds.
    pub const fn new(warmup: usize, frames: usize, limit_s: u64) -> Timing {
        Timing {
            warmup,
            frames,
            time_limit: Duration::from_secs(limit_s),
        }
    }

    /// One timed frame and no warm-up ([`MIN_FRAMES`] still apply): smoke runs.
    pub const fn once() -> Timing {
        Timing::new(0, 1, 0)
    }

    /// Runs the frames; what each timed `frame` returned, in order.
    pub fn run<T>(&self, mut frame: impl FnMut() -> T) -> Vec<T> {
        for _ in 0..self.warmup {
            frame();
        }
        let mut out = Vec::with_capacity(self.frames);
        let start = Instant::now();
        while out.len() < self.frames.max(MIN_FRAMES) {
            out.push(frame());
            if out.len() >= MIN_FRAMES && start.elapsed() >= self.time_limit {
                break;
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn timed_frames_stop_at_the_count_or_after_the_time_limit() {
        let mut calls = 0;
        let timing = |warmup, frames, time_limit| Timing {
            warmup,
            frames,
            time_limit,
        };
        let out = timing(2, 5, Duration::from_secs(60)).run(|| {
            calls += 1;
            calls
        });
        assert_eq!(out, [3, 4, 5, 6, 7]);
        let out = timing(0, 50, Duration::ZERO).run(|| ());
        assert_eq!(out.len(), MIN_FRAMES);
    }

    #[test]
    fn the_ticker_counts_steps() {
        let mut seen = Vec::new();
        let mut progress = |i: usize, n: usize, what: &str| seen.push((i, n, what.to_string()));
        let mut tick = ticker(2, &mut progress);
        tick("a".into());
        tick("b".into());
        drop(tick);
        assert_eq!(seen, [(0, 2, "a".into()), (1, 2, "b".into())]);
    }
}
