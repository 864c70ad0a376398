//! The headless showcase's summary, for a user and a script: each part's frame times
//! (median, p90, p99, max and the frame that took it) and each attraction's figures
//! ([`crate::showcase::attractions`]), as text lines and as `summary.json`:
//!
//! ```json
//! {"parts": {"tour": {"frames": 120, "ms": {"median": 0, "p90": 0, "p99": 0, "max": 0, "max_frame": 0},
//!                     "error_levels": null},
//!            "building": {...}, "views": {...}, "world": {...}},
//!  "attractions": [{"name": "statue", "technique": "light field", "part": "tour", "frames": 66,
//!                   "psnr_db": {"mean": 0, "worst": 0}, "flicker": 0}]}
//! ```
//!
//! Every part has the same five `ms` keys (all 0 for a part not rendered, with `frames` 0)
//! and `error_levels` (`{"mean": 0, "worst": 0}`, the world moment's error measured against
//! all its geometry; `null` for the other parts);
//! a figure not measured is `null`. Percentiles are nearest-rank; `max_frame` is the
//! index of the slowest frame within its part (its PNG's number). Written by hand: demos
//! has no JSON dependency and the shape is small.

use crate::showcase::attractions::Figures;
use std::fmt::Write as _;
use std::time::Duration;

/// The parts of the headless tour, in the order they play.
pub const PARTS: [&str; 4] = ["tour", "building", "views", "world"];

/// One part's frame times, in milliseconds.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PartTimes {
    pub frames: usize,
    pub median: f64,
    pub p90: f64,
    pub p99: f64,
    pub max: f64,
    /// The index of the slowest frame (the first of equals).
    pub max_frame: usize,
    /// Measured error against all the geometry, levels: the mean and the worst over the
    /// frames (the world moment's; `None` where not measured).
    pub error: Option<[f64; 2]>,
}

impl PartTimes {
    /// The figures of `times`, one per frame in order (all 0 when empty).
    pub fn of(times: &[Duration]) -> PartTimes {
        let ms: Vec<f64> = times.iter().map(|t| t.as_secs_f64() * 1e3).collect();
        let mut sorted = ms.clone();
        sorted.sort_by(f64::total_cmp);
        let (max_frame, max) =
            ms.iter()
                .copied()
                .enumerate()
                .fold((0, 0.0), |b, (i, v)| if v > b.1 { (i, v) } else { b });
        PartTimes {
            frames: ms.len(),
            median: percentile(&sorted, 0.5),
            p90: percentile(&sorted, 0.9),
            p99: percentile(&sorted, 0.99),
            max,
            max_frame,
            error: None,
        }
    }

    /// `median 12.30 ms  p90 ...  max 40.10 ms (frame 17)`.
    pub fn line(&self) -> String {
        let error = self.error.map_or(String::new(), |[mean, worst]| {
            format!("  measured error mean {mean:.2} worst {worst:.2} levels")
        });
        format!(
            "{} frames: median {:.2} ms  p90 {:.2} ms  p99 {:.2} ms  max {:.2} ms (frame {}){error}",
            self.frames, self.median, self.p90, self.p99, self.max, self.max_frame
        )
    }
}

/// Nearest-rank percentile `q` in [0, 1] of sorted samples (0 when empty).
fn percentile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return 0.0;
    }
    let rank = (q * sorted.len() as f64).ceil() as usize;
    sorted[rank.clamp(1, sorted.len()) - 1]
}

/// The whole summary: a part's times per name of [`PARTS`], and the attractions.
#[derive(Clone, Debug, Default)]
pub struct Summary {
    pub parts: [PartTimes; PARTS.len()],
    pub attractions: Vec<Figures>,
}

impl Summary {
    /// The text summary: one line per part, one per attraction.
    pub fn lines(&self) -> Vec<String> {
        let parts = PARTS.iter().zip(&self.parts);
        let mut out: Vec<String> = parts.map(|(n, p)| format!("{n}: {}", p.line())).collect();
        for a in &self.attractions {
            let f = |v: Option<f64>, d: usize| v.map_or("-".to_string(), |v| format!("{v:.d$}"));
            out.push(format!(
                "{} ({}, {}): {} frames  PSNR mean {} dB, worst {} dB  flicker {}",
                a.name,
                a.technique,
                a.part,
                a.frames,
                f(a.psnr_mean, 1),
                f(a.psnr_worst, 1),
                f(a.flicker, 2)
            ));
        }
        out
    }

    /// The JSON text (module docs), one part or attraction per line.
    pub fn json(&self) -> String {
        let mut s = String::from("{\"parts\": {");
        for (k, (name, p)) in PARTS.iter().zip(&self.parts).enumerate() {
            let sep = if k > 0 { ",\n          " } else { "" };
            let _ = write!(
                s,
                "{sep}{}: {{\"frames\": {}, \"ms\": {{\"median\": {}, \"p90\": {}, \"p99\": {}, \
                 \"max\": {}, \"max_frame\": {}}}, \"error_levels\": {}}}",
                string(name),
                p.frames,
                number(Some(p.median)),
                number(Some(p.p90)),
                number(Some(p.p99)),
                number(Some(p.max)),
                p.max_frame,
                p.error.map_or("null".to_string(), |[mean, worst]| format!(
                    "{{\"mean\": {}, \"worst\": {}}}",
                    number(Some(mean)),
                    number(Some(worst))
                ))
            );
        }
        s.push_str("},\n \"attractions\": [");
        for (k, a) in self.attractions.iter().enumerate() {
            let sep = if k > 0 { ",\n   " } else { "\n   " };
            let _ = write!(
                s,
                "{sep}{{\"name\": {}, \"technique\": {}, \"part\": {}, \"frames\": {}, \
                 \"psnr_db\": {{\"mean\": {}, \"worst\": {}}}, \"flicker\": {}}}",
                string(a.name),
                string(a.technique),
                string(a.part),
                a.frames,
                number(a.psnr_mean),
                number(a.psnr_worst),
                number(a.flicker)
            );
        }
        s.push_str("]}\n");
        s
    }
}

/// Where each frame of a part spent its time, in named columns (a technique's `prepare`,
/// an engine stage, ...), one row per frame: its median per column, the slowest frame's
/// row, and a CSV of every row. The columns need not add up to the frame (stage times
/// summed over workers overlap the wall clock); `frame` is the frame's own time.
#[derive(Clone, Debug, Default)]
pub struct Breakdown {
    columns: Vec<String>,
    frames: Vec<Duration>,
    rows: Vec<Vec<Duration>>,
}

impl Breakdown {
    /// An empty breakdown with these columns.
    pub fn new(columns: &[&str]) -> Breakdown {
        Breakdown {
            columns: columns.iter().map(|c| c.to_string()).collect(),
            ..Default::default()
        }
    }

    /// Adds one frame: its own time and one time per column (missing columns count 0).
    pub fn push(&mut self, frame: Duration, row: &[Duration]) {
        let mut row = row.to_vec();
        row.resize(self.columns.len(), Duration::ZERO);
        self.frames.push(frame);
        self.rows.push(row);
    }

    /// Each column's median over the frames, ms, in column order.
    pub fn medians(&self) -> Vec<f64> {
        (0..self.columns.len())
            .map(|c| {
                let mut v: Vec<f64> = self.rows.iter().map(|r| ms(r[c])).collect();
                v.sort_by(f64::total_cmp);
                percentile(&v, 0.5)
            })
            .collect()
    }

    /// Two lines: each column's median, and the slowest frame's row.
    pub fn lines(&self) -> Vec<String> {
        let cols = |vals: &[f64]| {
            let named = self.columns.iter().zip(vals);
            named
                .map(|(c, v)| format!("{c} {v:.2}"))
                .collect::<Vec<_>>()
                .join(", ")
        };
        let mut out = vec![format!("medians, ms: {}", cols(&self.medians()))];
        let times = PartTimes::of(&self.frames);
        if let Some(row) = self.rows.get(times.max_frame) {
            let row: Vec<f64> = row.iter().map(|&d| ms(d)).collect();
            out.push(format!(
                "slowest frame {} ({:.2} ms), ms: {}",
                times.max_frame,
                times.max,
                cols(&row)
            ));
        }
        out
    }

    /// `frame,ms,COLUMN...` then one line per frame, times in ms.
    pub fn csv(&self) -> String {
        let mut s = format!("frame,ms,{}\n", self.columns.join(","));
        for (i, (f, row)) in self.frames.iter().zip(&self.rows).enumerate() {
            let _ = write!(s, "{i},{:.3}", ms(*f));
            for d in row {
                let _ = write!(s, ",{:.3}", ms(*d));
            }
            s.push('\n');
        }
        s
    }
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// A JSON number with four decimals, or `null` for none or a non-finite value.
fn number(v: Option<f64>) -> String {
    match v {
        Some(v) if v.is_finite() => format!("{}", (v * 1e4).round() / 1e4),
        _ => "null".to_string(),
    }
}

/// A JSON string: quoted, with quotes, backslashes and control characters escaped.
pub fn string(v: &str) -> String {
    let mut s = String::with_capacity(v.len() + 2);
    s.push('"');
    for c in v.chars() {
        match c {
            '"' => s.push_str("\\\""),
            '\\' => s.push_str("\\\\"),
            c if (c as u32) < 0x20 => {
                let _ = write!(s, "\\u{:04x}", c as u32);
            }
            c => s.push(c),
        }
    }
    s.push('"');
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn part_times_find_the_slowest_frame_and_nearest_rank_percentiles() {
        let ms = [5u64, 9, 3, 40, 7, 6, 8, 4, 2, 1];
        let times: Vec<Duration> = ms.iter().map(|&m| Duration::from_millis(m)).collect();
        let p = PartTimes::of(&times);
        assert_eq!((p.frames, p.max_frame), (10, 3));
        // Sorted: 1 2 3 4 5 6 7 8 9 40; rank ceil(0.5 * 10) = 5, ceil(9) = 9, ceil(9.9) = 10.
        assert!((p.median - 5.0).abs() < 1e-9 && (p.p90 - 9.0).abs() < 1e-9);
        assert!((p.p99 - 40.0).abs() < 1e-9 && (p.max - 40.0).abs() < 1e-9);
        assert_eq!(PartTimes::of(&[]), PartTimes::default());
    }

    #[test]
    fn breakdown_medians_slowest_row_and_csv() {
        let d = Duration::from_millis;
        let mut b = Breakdown::new(&["a", "b"]);
        b.push(d(10), &[d(1), d(2)]);
        b.push(d(30), &[d(3), d(20)]);
        b.push(d(20), &[d(2)]);
        // Sorted a: 1 2 3 -> 2; b: 0 2 20 -> 2 (the missing column counts 0).
        assert_eq!(b.medians(), vec![2.0, 2.0]);
        let lines = b.lines();
        assert!(
            lines[1].starts_with("slowest frame 1 (30.00 ms)"),
            "{lines:?}"
        );
        assert!(lines[1].ends_with("a 3.00, b 20.00"), "{lines:?}");
        assert_eq!(
            b.csv().lines().collect::<Vec<_>>(),
            [
                "frame,ms,a,b",
                "0,10.000,1.000,2.000",
                "1,30.000,3.000,20.000",
                "2,20.000,2.000,0.000"
            ]
        );
    }

    #[test]
    fn strings_and_numbers_are_valid_json() {
        assert_eq!(string("a\"b\\c\nd"), "\"a\\\"b\\\\c\\u000ad\"");
        assert_eq!(number(Some(f64::INFINITY)), "null");
        assert_eq!(number(None), "null");
        assert_eq!(number(Some(1.23456)), "1.2346");
    }
}
