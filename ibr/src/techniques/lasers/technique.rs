//! Laser batches through the frame seam: beams and caps rebuilt for the camera, two draws.

use super::LaserBatch;
use crate::core::{quads, Counters, FrameView, Technique};
use engine::Draw;

impl Technique for LaserBatch {
    fn name(&self) -> &str {
        "lasers"
    }
    fn prepare(&mut self, view: &FrameView<'_>) {
        self.build(&view.billboard_view());
    }
    fn draws<'a>(&'a self, out: &mut Vec<Draw<'a>>) {
        out.extend(LaserBatch::draws(self));
    }
    /// Beam and cap quads of the last build.
    fn counters(&self) -> Counters {
        Counters {
            quads: quads(self.beam_mesh()) + quads(self.cap_mesh()),
            ..Counters::default()
        }
    }
}
