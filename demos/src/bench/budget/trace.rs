//! `bench budget --trace B`: the frame-scope planner at error budget `B`, frame by frame
//! and object by object, for finding which objects carry a frame over its budget. One row
//! per visible object per measured frame: its representation, its predicted error, its
//! measured error over its screen rectangle and the rectangle's area, beside the frame's
//! measured error and the planner's bound on it.

use super::{fly_with, planner, scenes, Settings, REPRESENTATIONS};
use crate::bench::sweep::CsvRow;
use ibr::plan::Scope;

/// One visible object in one frame.
#[derive(Clone, Debug)]
pub struct TraceRow {
    pub scene: &'static str,
    pub frame: usize,
    pub object: usize,
    pub representation: &'static str,
    pub predicted: f64,
    pub measured: f64,
    /// The object's screen rectangle, pixels.
    pub area: u32,
    /// The planner's weight of the object's error, pixels.
    pub weight: f64,
    /// The frame's measured error and the planner's bound on it.
    pub frame_measured: f64,
    pub frame_bound: f64,
}

impl CsvRow for TraceRow {
    const HEADER: &'static str =
        "scene,frame,object,representation,predicted,measured,area,weight,frame_measured,frame_bound";

    fn csv(&self) -> String {
        format!(
            "{},{},{},{},{:.4},{:.4},{},{:.1},{:.4},{:.4}",
            self.scene,
            self.frame,
            self.object,
            self.representation,
            self.predicted,
            self.measured,
            self.area,
            self.weight,
            self.frame_measured,
            self.frame_bound
        )
    }
}

/// Flies every scene of `settings` with the frame-scope planner at `budget`.
pub fn trace(settings: &Settings, budget: f32) -> Vec<TraceRow> {
    let mut rows = Vec::new();
    for scene in &scenes(settings) {
        let mut p = planner(scene, settings, budget, true);
        p.config.budgets.scope = Scope::Frame;
        let mut frame = 0;
        fly_with(scene, settings, budget, &mut p, &mut |p, seen| {
            let (sum, area) = seen.iter().fold((0.0, 0.0), |(s, a), &(_, m, r)| {
                let px = f64::from(r.width * r.height);
                (s + m * px, a + px)
            });
            let frame_measured = sum / f64::max(area, 1.0);
            let (visible, weights) = p.weights();
            for &(i, measured, r) in seen {
                let c = p.choices()[i];
                rows.push(TraceRow {
                    scene: scene.name,
                    frame,
                    object: i,
                    representation: c.rep.map_or("culled", |k| REPRESENTATIONS[k]),
                    predicted: f64::from(c.error),
                    measured,
                    area: r.width * r.height,
                    weight: visible
                        .binary_search(&i)
                        .map_or(0.0, |v| f64::from(weights[v])),
                    frame_measured,
                    frame_bound: f64::from(p.report.bound),
                });
            }
            frame += 1;
        });
    }
    rows
}
