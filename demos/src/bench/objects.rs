//! The `bench objects` sweep: frame time and measured error against the number of objects
//! (1k to 100k) at a fixed mix of objects (so triangles per object, on average) and a fixed
//! resolution: the budget sweep's world grown to that many lots, flown over the same way,
//! its geometry beside the per-node planner ([`ibr::plan::tree`], cluster images of the
//! hierarchy's nodes) at a few error budgets. Every frame is measured against a render of
//! all the geometry from the same eye, as `bench budget` does (`measured_mean`: the mean
//! absolute error over the pixels the visible objects' rectangles cover).

use crate::bench::budget::{by_count, Row, Settings};
use crate::bench::{Progress, RunFlags, Sweep};
use crate::chart::{Chart, Line, Lines};

/// What the sweep measures.
#[derive(Clone, Debug)]
pub struct Counts {
    /// The budget sweep's settings (size, frames, budgets).
    pub run: Settings,
    /// Object counts.
    pub counts: Vec<usize>,
    /// The geometry is drawn up to this many objects (beyond, a frame takes seconds).
    pub geometry_up_to: usize,
}

impl Counts {
    /// 1k to 100k objects, 24 frames each, budgets 8 and 16.
    fn full() -> Counts {
        Counts {
            run: Settings {
                budgets: vec![8.0, 16.0],
                ..Settings::full()
            },
            counts: vec![1_024, 4_096, 16_384, 65_536, 100_489],
            geometry_up_to: 100_489,
        }
    }

    /// 1k, 4k and 16k objects, 8 frames each, budget 16: a few minutes.
    fn quick() -> Counts {
        Counts {
            run: Settings {
                budgets: vec![16.0],
                ..Settings::quick()
            },
            counts: vec![1_024, 4_096, 16_384],
            geometry_up_to: 16_384,
        }
    }

    /// A seconds-long smoke run (tests).
    fn tiny() -> Counts {
        Counts {
            run: Settings {
                budgets: vec![16.0],
                ..Settings::tiny()
            },
            counts: vec![16, 64],
            geometry_up_to: 64,
        }
    }
}

/// Frame time and error against the number of objects.
#[derive(Clone, Copy, Debug)]
pub struct ObjectsSweep;

impl Sweep for ObjectsSweep {
    const NAME: &'static str = "objects";
    const ABOUT: &'static str = "Frame time and measured error against the number of objects (1k to 100k) at a fixed mix of objects and resolution: geometry beside the per-node planner";
    type Flags = RunFlags;
    type Settings = Counts;
    type Row = Row;

    fn settings(&self, flags: &RunFlags) -> Result<Counts, String> {
        Ok(flags.pick(Counts::tiny, Counts::quick, Counts::full))
    }

    fn rows(&self, c: &Counts, _: &RunFlags, progress: Progress) -> Result<Vec<Row>, String> {
        Ok(by_count(&c.run, &c.counts, c.geometry_up_to, progress))
    }

    fn report(&self, rows: &[Row]) {
        for r in rows {
            println!(
                "{:>7} objects {:>10} tris {}x{}  {:<12} {:>4}  median {:>8.2} ms  measured {:>6.3} (p99 {:>6.3})  geometry {:>7.1} images {:>6.1}  rebuilds {:>5.1}  planning {:>5.2} ms",
                r.objects,
                r.triangles,
                r.width,
                r.height,
                r.method,
                r.budget,
                r.time.median_ms,
                r.measured_mean,
                r.measured_p99,
                r.geometry_per_frame,
                r.images_per_frame,
                r.rebuilds_per_frame,
                r.planning_ms,
            );
        }
    }

    fn charts(&self, rows: &[Row]) -> Vec<(&'static str, Chart)> {
        // One line per method and budget.
        let mut keys: Vec<(&str, f32)> = Vec::new();
        for r in rows {
            if !keys.contains(&(r.method, r.budget)) {
                keys.push((r.method, r.budget));
            }
        }
        let lines = |f: &dyn Fn(&Row) -> (f64, f64), labels: bool| -> Vec<Line> {
            keys.iter()
                .map(|&(m, b)| {
                    let of: Vec<&Row> = rows
                        .iter()
                        .filter(|r| r.method == m && r.budget == b)
                        .collect();
                    let name = match m {
                        "geometry" => m.to_string(),
                        _ => format!("{m} b{b}"),
                    };
                    let line = Line::new(name, of.iter().map(|r| f(r)).collect());
                    if labels {
                        line.labelled(
                            of.iter()
                                .map(|r| format!("{}k", r.objects / 1000))
                                .collect(),
                        )
                    } else {
                        line
                    }
                })
                .collect()
        };
        let thousands = |r: &Row| r.objects as f64 / 1000.0;
        vec![
            (
                "objects_time.png",
                Chart::Lines(Lines::new(
                    "Frame time against the number of objects",
                    "objects (thousands)",
                    "median frame time (ms)",
                    lines(&|r| (thousands(r), r.time.median_ms), false),
                )),
            ),
            (
                "objects_error.png",
                Chart::Lines(Lines::new(
                    "Measured error against the number of objects",
                    "objects (thousands)",
                    "mean abs error over objects (8-bit levels)",
                    lines(&|r| (thousands(r), r.measured_mean), false),
                )),
            ),
            (
                "objects_time_error.png",
                Chart::Lines(Lines::new(
                    "Measured error against frame time (labels: objects)",
                    "median frame time (ms)",
                    "mean abs error over objects (8-bit levels)",
                    lines(&|r| (r.time.median_ms, r.measured_mean), true),
                )),
            ),
        ]
    }
}
