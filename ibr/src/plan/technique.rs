//! The planner as a technique of the frame loop: `prepare` plans, `draws` gives each
//! object's chosen representation, `reference` every object's geometry.

use super::Planner;
use crate::core::Subject;
use crate::core::{Counters, FrameView, Observed, Technique};
use engine::{Draw, FrameStats, Target};

impl<S: Subject + Send + Sync> Technique for Planner<S> {
    fn name(&self) -> &str {
        "planner"
    }
    fn prepare(&mut self, view: &FrameView<'_>) {
        self.plan(view);
    }
    fn draws<'a>(&'a self, out: &mut Vec<Draw<'a>>) {
        Planner::draws(self, out);
    }
    fn passes(&self, view: &FrameView<'_>, target: &mut Target) -> FrameStats {
        Planner::passes(self, view, target)
    }
    /// Takes what the finished frame hides, for the next frame's weights.
    fn observe(&self, seen: &mut Observed<'_, '_>) -> Option<f32> {
        self.observe_frame(seen.target, seen.camera);
        None
    }
    /// Objects drawn as their own geometry, as images (every other representation), and
    /// the frame's rebuilds.
    fn counters(&self) -> Counters {
        let (mut geometry, mut images) = (0, 0);
        for (r, &n) in self.report.counts.iter().enumerate() {
            match self.representation(r) {
                Some(rep) if rep.draws_subject() => geometry += n as u64,
                _ => images += n as u64,
            }
        }
        Counters {
            images,
            geometry,
            refreshes: self.report.rebuilds as u64,
            ..Counters::default()
        }
    }
    fn reference<'a>(&'a self, out: &mut Vec<Draw<'a>>) {
        self.objects.iter().for_each(|s| s.draws(out));
    }
}
