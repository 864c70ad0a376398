//! The `bench objects` sweep: frame time and measured error against the number of objects
//! (1k to 100k) at a fixed mix of objects (so triangles per object, on average) and a fixed
//! resolution: the budget sweep's world grown to that many lots, flown over the same way,
//! its geometry beside the per-node planner ([`ibr::plan::tree`], cluster images of the
//! hierarchy's nodes) at a few error budgets. Every frame is measured against a render of
//! all the geometry from the same eye, as `bench budget` does (`measured_mean`: the mean
//! absolute error over the pixels the visible objects' rectangles cover).
//!
//! Equal pixels: every world is flown along the same eye path in world units ([`flight`]),
//! the 1k world's fly-over held at the same distance from the near edge, so the view's
//! near part (the cut's geometry and node images) shows comparable content at every count
//! and only its far part fills with more objects as the world grows (the far field).

use crate::bench::budget::{by_count, Row, Settings};
use crate::bench::{Progress, RunFlags, Sweep};
use crate::chart::{Chart, Line, Lines};
use crate::world::{World, LOT};
use clap::Args;
use engine::Camera;

/// `bench objects`'s flags.
#[derive(Args, Clone, Debug)]
pub struct ObjectsFlags {
    #[command(flatten)]
    pub run: RunFlags,
    /// Only these object counts (repeat the option; each the world of the nearest square
    /// number of lots); default: the sweep's.
    #[arg(long, value_name = "N")]
    pub objects: Vec<usize>,
    /// Print each measured frame's stage times (ms) and work counters to stderr, one line
    /// a frame starting `stages`.
    #[arg(long)]
    pub stages: bool,
}

impl AsRef<RunFlags> for ObjectsFlags {
    fn as_ref(&self) -> &RunFlags {
        &self.run
    }
}

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

/// Lots a side of the world whose fly-over every larger world is flown along (32 x 32,
/// the sweep's 1k objects).
pub const FLIGHT_SIDE: u32 = 32;

/// The sweep's flight over `world` at frame `f` of `n`: [`World::camera`]'s first quarter
/// for a world up to [`FLIGHT_SIDE`] lots a side; a larger world is flown along that
/// world's eye path, the same distance in from its near edge, looking the same way, its far
/// plane past its own far edge. (Each world's own fly-over crosses a fifth of the world:
/// 9.6 units in the 24 frames at 1k, 95 at 100k, ten times as fast, so the far field's
/// parallax, and its re-capture, would follow the number of objects.)
pub fn flight(world: &World, f: usize, n: usize, (w, h): (u32, u32)) -> Camera {
    let t = f as f32 / n.max(2) as f32 * 0.25;
    let e = world.half_extent;
    let path = e.min(FLIGHT_SIDE as f32 * LOT * 0.5);
    let eye = glam::Vec3::new(path * (0.4 * t - 0.2), 20.0, e - 0.1 * path);
    let target = eye + glam::Vec3::new(0.15, -0.32, -1.0);
    Camera::look_at(eye, target, glam::Vec3::Y, 1.0, w as f32 / h.max(1) as f32)
        .with_depth_range(0.5, e * 2.2)
}

/// Frame time and error against the number of objects.
#[derive(Clone, Copy, Debug)]
pub struct ObjectsSweep;

impl Sweep for ObjectsSweep {
    const NAME: &'static str = "objects";
    const ABOUT: &'static str = "Frame time and measured error against the number of objects (1k to 100k) at a fixed mix of objects and resolution: geometry beside the per-node planner";
    type Flags = ObjectsFlags;
    type Settings = Counts;
    type Row = Row;

    fn settings(&self, flags: &ObjectsFlags) -> Result<Counts, String> {
        let mut c = flags.run.pick(Counts::tiny, Counts::quick, Counts::full);
        if let Some(&n) = flags.objects.iter().find(|&&n| n == 0) {
            return Err(format!("--objects {n}: a world needs at least one object"));
        }
        if !flags.objects.is_empty() {
            c.counts.clone_from(&flags.objects);
        }
        c.run.stages = flags.stages;
        Ok(c)
    }

    fn rows(&self, c: &Counts, _: &ObjectsFlags, progress: Progress) -> Result<Vec<Row>, String> {
        Ok(by_count(
            &c.run,
            (&c.counts, c.geometry_up_to),
            flight,
            progress,
        ))
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_world_is_flown_along_the_1k_worlds_path() {
        let size = (640, 360);
        let small = World::new(FLIGHT_SIDE, 11);
        let large = World::new(FLIGHT_SIDE * 4, 11);
        for f in [0, 12, 24] {
            // At 1k, the world's own fly-over.
            let own = small.camera(f as f32 / 24.0 * 0.25, size);
            let flown = flight(&small, f, 24, size);
            assert!(own.eye().distance(flown.eye()) < 1e-3, "{f}");
            // Larger: the same eye path, the same distance from its near edge.
            let (a, b) = (flown.eye(), flight(&large, f, 24, size).eye());
            assert!((a.x - b.x).abs() < 1e-3 && (a.y - b.y).abs() < 1e-3, "{f}");
            let edge = |w: &World, z: f32| w.half_extent - z;
            assert!((edge(&small, a.z) - edge(&large, b.z)).abs() < 1e-3, "{f}");
        }
        // 24 frames cross the same 9.6 units in both.
        let path = |w: &World| flight(w, 24, 24, size).eye() - flight(w, 0, 24, size).eye();
        assert!((path(&small).length() - 9.6).abs() < 1e-3);
        assert!((path(&large).length() - 9.6).abs() < 1e-3);
    }
}
