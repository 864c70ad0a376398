//! The `bench objects` sweep: frame time and measured error against the number of objects
//! (1k to 100k) at a fixed mix of objects (so triangles per object, on average) and a fixed
//! resolution: the budget sweep's world grown to that many lots, flown over the same way,
//! its geometry beside the per-node planner ([`ibr::plan::tree`], cluster images of the
//! hierarchy's nodes) at a few error budgets. Every frame is measured against a render of
//! all the geometry from the same eye, as `bench budget` does (`measured_mean`: the mean
//! absolute error over the pixels the visible objects' rectangles cover).
//!
//! Equal pixels: every world fills the same square of ground, the 1k world's
//! ([`FOOTPRINT`] lots a side), its lots and objects shrunk to fit ([`World::in_footprint`]),
//! and is flown along the same eye path ([`flight`]): the ground, the sky and the part of
//! the frame the objects stand in are the same at every count (the CSV's `covered` and
//! `sky`), and only the number of objects in them grows, with the geometry's triangles.
//! (Until session 19 the larger worlds were larger squares of full-size lots, whose far
//! part filled pixels that are sky in the 1k world.)

use crate::bench::budget::{by_count, Row, Settings};
use crate::bench::{Progress, RunFlags, Sweep};
use crate::chart::{Chart, Line, Lines};
use crate::world::World;
#[cfg(doc)]
use crate::world::LOT;
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

/// Lots of [`LOT`] a side of the ground every world of the sweep fills (32 x 32, the
/// sweep's 1k objects at full size).
pub const FOOTPRINT: u32 = 32;

/// The sweep's world of `side` x `side` objects: [`FOOTPRINT`]'s square of ground.
pub fn world(side: u32) -> World {
    World::in_footprint(side, 11, FOOTPRINT)
}

/// The sweep's flight over `world` at frame `f` of `n`: [`World::camera`]'s eye path
/// (its first quarter, the same for every world of the sweep: they share their footprint),
/// looking down at 41.7 degrees ([`LOOK`]), so that every corner of the frame meets the
/// ground inside the lots: no sky in any frame, every pixel the footprint's ground or
/// what stands on it.
pub fn flight(world: &World, f: usize, n: usize, (w, h): (u32, u32)) -> Camera {
    let along = world.camera(f as f32 / n.max(2) as f32 * 0.25, (w, h));
    let eye = along.eye();
    Camera::look_at(
        eye,
        eye + LOOK,
        glam::Vec3::Y,
        1.0,
        w as f32 / h.max(1) as f32,
    )
    .with_depth_range(0.5, world.half_extent * 2.2)
}

/// The sweep's view direction ([`flight`]). The fly-over's own, 17.6 degrees down, sees
/// past the footprint's far edge: the sky and the far objects' silhouettes against it
/// then differ with the objects' size (a first run of this sweep at that view: sky 0.23,
/// 0.29 and 0.31 of the frame at 1k, 4k and 16k objects).
pub const LOOK: glam::Vec3 = glam::Vec3::new(0.15, -0.9, -1.0);

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
            (world, flight),
            progress,
        ))
    }

    fn report(&self, rows: &[Row]) {
        for r in rows {
            println!(
                "{:>7} objects {:>10} tris {}x{}  {:<12} {:>4}  median {:>8.2} ms  measured {:>6.3} (p99 {:>6.3})  geometry {:>7.1} images {:>6.1}  rebuilds {:>5.1}  planning {:>5.2} ms  covered {:.3} sky {:.3}",
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
                r.covered,
                r.sky,
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
    use ibr::subject::Subject;

    /// Every world of the sweep stands on the 1k world's ground and is flown the same way:
    /// the same eyes, the 1k world at full size.
    #[test]
    fn every_world_fills_the_1k_worlds_ground_and_is_flown_alike() {
        let size = (640, 360);
        let full = World::new(FOOTPRINT, 11);
        let small = world(FOOTPRINT);
        assert_eq!(small.triangle_count(), full.triangle_count());
        let large = world(FOOTPRINT * 4);
        assert_eq!(large.objects.len(), 16 * full.objects.len());
        assert_eq!(large.half_extent, full.half_extent);
        for f in [0, 12, 24] {
            let own = full.camera(f as f32 / 24.0 * 0.25, size);
            for w in [&small, &large] {
                let eye = flight(w, f, 24, size).eye();
                assert!(own.eye().distance(eye) < 1e-4, "{f}");
            }
        }
        // Every object inside the footprint, at a sixteenth of the area each.
        let inside = |w: &World| {
            w.objects.iter().all(|o| {
                let s = o.bounds();
                s.center.x.abs() <= w.half_extent + s.radius
                    && s.center.z.abs() <= w.half_extent + s.radius
            })
        };
        assert!(inside(&small) && inside(&large));
        let radii = |w: &World| w.objects.iter().map(|o| o.bounds().radius).sum::<f32>();
        let ratio = radii(&large) / radii(&small);
        assert!((ratio - 4.0).abs() < 0.6, "{ratio}");
    }

    /// Rendered at 160 x 90 along the flight, the sweep's worlds of 256 and 4,096 objects
    /// leave no pixel to the sky (every pixel the footprint's ground or an object on it),
    /// while the larger draws more than eight times the triangles: the sweep changes the
    /// number of objects, not the pixels.
    #[test]
    fn the_sweeps_worlds_cover_the_same_pixels() {
        let (w, h) = (160, 90);
        let cover = |side: u32, f: usize| {
            let world = world(side);
            let camera = flight(&world, f, 24, (w, h));
            let (target, stats) = world.render_geometry(&world.ground, &camera, (w, h));
            let sky = (0..h)
                .flat_map(|y| (0..w).map(move |x| (x, y)))
                .filter(|&(x, y)| target.depth_reversed(x, y) == Some(0.0))
                .count();
            (sky as f32 / (w * h) as f32, stats.triangles_in)
        };
        for f in [0, 24] {
            let (sky_a, _) = cover(16, f);
            let (sky_b, _) = cover(64, f);
            assert_eq!((sky_a, sky_b), (0.0, 0.0), "frame {f}");
        }
        let (_, tris_a) = cover(16, 12);
        let (_, tris_b) = cover(64, 12);
        assert!(tris_b > 8 * tris_a, "triangles in {tris_a} -> {tris_b}");
    }
}
