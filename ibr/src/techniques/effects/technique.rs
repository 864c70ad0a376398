//! Effects through the frame seam: particles stepped by the frame's `dt`, three batches drawn.

use super::{Effects, Layer};
use crate::core::{quads, Counters, FrameView, Technique};
use engine::Draw;

impl Technique for Effects {
    fn name(&self) -> &str {
        "effects"
    }
    /// Steps the particles by the frame's `dt`, then faces them to the camera.
    fn prepare(&mut self, view: &FrameView<'_>) {
        self.update(view.dt);
        self.build(&view.billboard_view());
    }
    fn draws<'a>(&'a self, out: &mut Vec<Draw<'a>>) {
        out.extend(Effects::draws(self));
    }
    /// Particle quads of the last build.
    fn counters(&self) -> Counters {
        let layers = [Layer::Smoke, Layer::Fire, Layer::Sparks];
        Counters {
            quads: layers.iter().map(|&l| quads(self.batch(l).mesh())).sum(),
            ..Counters::default()
        }
    }
}
