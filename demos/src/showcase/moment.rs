//! One technique's frame over a moment's plain geometry: the frame loop and the draw list
//! both moments of one technique (the building walk, the world) reuse frame to frame.

use engine::{Draw, FrameOptions, FrameStats, Renderer, Rgba, Target};
use ibr::technique::{FrameLoop, FrameView, Technique};

/// A moment's frame loop and its scene's draw list, kept between frames (no allocation
/// once warm).
#[derive(Debug, Default)]
pub struct MomentFrame {
    frame: FrameLoop,
    draws: Vec<Draw<'static>>,
}

impl MomentFrame {
    /// Draws the geometry `scene` pushes, then `technique` over it, on `target` cleared to
    /// `clear`.
    pub fn render<'s>(
        &mut self,
        renderer: &mut Renderer,
        scene: impl FnOnce(&mut Vec<Draw<'s>>),
        technique: &mut dyn Technique,
        view: &FrameView<'_>,
        target: &mut Target,
        clear: Rgba,
    ) -> FrameStats {
        let mut draws = ibr::technique::recycle(std::mem::take(&mut self.draws));
        scene(&mut draws);
        let opts = FrameOptions {
            clear: Some(clear),
            ..Default::default()
        };
        let mut list: [&mut dyn Technique; 1] = [technique];
        let stats = self.frame.render(
            renderer,
            draws.iter().copied(),
            &mut list,
            view,
            target,
            &opts,
        );
        self.draws = ibr::technique::recycle(draws);
        stats
    }
}
