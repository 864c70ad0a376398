//! Billboard batches through the frame seam: faced to the camera in `prepare`, one draw.

use crate::core::{quads, BillboardBatch, Counters, FrameView, Technique};
use engine::Draw;

impl Technique for BillboardBatch {
    fn name(&self) -> &str {
        "billboards"
    }
    fn prepare(&mut self, view: &FrameView<'_>) {
        self.build(&view.billboard_view());
    }
    fn draws<'a>(&'a self, out: &mut Vec<Draw<'a>>) {
        out.push(self.draw());
    }
    /// Quads of the last build (an item may make none, or several).
    fn counters(&self) -> Counters {
        Counters {
            quads: quads(self.mesh()),
            ..Counters::default()
        }
    }
}
