//! The warp as a technique: each frame the references nearest the eye are warped to the
//! frame's camera, holes are filled, and an image pass writes the result into the target,
//! depth-tested against the geometry drawn there (warped samples write depth, so geometry
//! in front hides them and they hide geometry behind).

use super::holes::{classify, Fill, Filler, HoleStats};
use super::predict::{depth_range, parallax_px};
use super::{is_filled, WarpOptions, WarpStats, Warper};
use crate::images::{DepthImage, LayeredDepthImage};
use crate::technique::{Counters, FrameView, Technique};
use engine::{
    run_pass, Camera, Draw, Fragment, FrameStats, PassMode, PixelPass, PixelRect, Target,
};

/// Depth images standing in for a scene from any nearby view.
#[derive(Debug)]
pub struct WarpedView {
    name: String,
    /// The references (after replacing some in place, call [`WarpedView::references_changed`]).
    pub references: Vec<DepthImage>,
    /// Layered depth images, warped (all of them) before the nearest references.
    pub layered: Vec<LayeredDepthImage>,
    pub options: WarpOptions,
    pub fill: Fill,
    /// How many references, the nearest to the eye first, are warped each frame (after the
    /// layered images).
    pub nearest: usize,
    /// Whether holes are classified each frame (for counters and charts; a full pass over
    /// the image).
    pub count_holes: bool,
    warper: Warper,
    filler: Filler,
    order: Vec<(f32, usize)>,
    /// Each reference's median depth and depth range, computed when the references change.
    reach: Vec<f32>,
    ranges: Vec<Option<(f32, f32)>>,
    last: WarpFrame,
}

/// What the last frame's warp did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WarpFrame {
    pub stats: WarpStats,
    /// Holes before filling (zero when not counted).
    pub holes: HoleStats,
    pub filled: u64,
    /// Pixels the image pass offers the target (filled output pixels).
    pub pixels: u64,
    pub references: u64,
    /// The predicted parallax spread of the nearest reference, pixels
    /// ([`super::predict::parallax_px`]): the widest a disocclusion can open.
    pub predicted_px: f32,
}

impl WarpedView {
    pub fn new(name: impl Into<String>, references: Vec<DepthImage>) -> Self {
        WarpedView {
            name: name.into(),
            references,
            layered: Vec::new(),
            options: WarpOptions::default(),
            fill: Fill::PullPush,
            nearest: 2,
            count_holes: true,
            warper: Warper::new(),
            filler: Filler::default(),
            order: Vec::new(),
            reach: Vec::new(),
            ranges: Vec::new(),
            last: WarpFrame::default(),
        }
    }

    /// Forgets what was computed from the references (their depths' median and range).
    pub fn references_changed(&mut self) {
        self.reach.clear();
    }

    /// The last frame's warped and filled image.
    pub fn image(&self) -> &DepthImage {
        self.warper.output()
    }

    pub fn last(&self) -> WarpFrame {
        self.last
    }

    /// Warps the nearest references to `camera` at `width` x `height` and fills the holes.
    pub fn warp_to(&mut self, camera: &Camera, width: u32, height: u32) -> WarpFrame {
        let eye = camera.eye();
        let forward = camera.forward();
        if self.reach.len() != self.references.len() {
            self.reach = self.references.iter().map(median_depth).collect();
            self.ranges = self.references.iter().map(depth_range).collect();
        }
        self.order.clear();
        let reach = &self.reach;
        self.order
            .extend(self.references.iter().enumerate().map(|(i, r)| {
                // Distance between the eyes, plus the turn between the view directions scaled
                // by how far the reference sees (a turn moves far samples most).
                let reach = reach[i];
                let turn = 1.0 - forward.dot(r.camera.forward()).clamp(-1.0, 1.0);
                ((eye - r.camera.eye()).length() + turn * reach, i)
            }));
        self.order
            .sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        self.warper.begin(camera, width, height);
        let mut frame = WarpFrame::default();
        for ldi in &self.layered {
            frame.stats += self.warper.add_layered(ldi, &self.options);
            frame.references += 1;
        }
        if let Some(&(_, i)) = self.order.first().filter(|_| self.nearest > 0) {
            let r = &self.references[i];
            frame.predicted_px = self.ranges[i].map_or(0.0, |range| {
                parallax_px(range, &r.camera, camera, width, height)
            });
        }
        for &(_, i) in self.order.iter().take(self.nearest) {
            frame.stats += self.warper.add(&self.references[i], &self.options);
            frame.references += 1;
        }
        if self.count_holes {
            frame.holes = classify(self.warper.output(), self.options.edge);
        }
        frame.filled = self
            .filler
            .fill(self.warper.output_mut(), self.fill, self.options.edge);
        frame.pixels = self
            .warper
            .output()
            .color
            .iter()
            .filter(|c| is_filled(**c))
            .count() as u64;
        self.last = frame;
        frame
    }
}

/// A reference's median finite depth (a sample of 257 pixels), 1 when it has none.
fn median_depth(r: &DepthImage) -> f32 {
    let step = (r.depth.len() / 257).max(1);
    let mut d: Vec<f32> = r
        .depth
        .iter()
        .step_by(step)
        .copied()
        .filter(|d| d.is_finite())
        .collect();
    if d.is_empty() {
        return 1.0;
    }
    let mid = d.len() / 2;
    *d.select_nth_unstable_by(mid, f32::total_cmp).1
}

/// Writes a depth image taken by the target's camera into the target: its colour, and its
/// depth turned into the target's reversed depth. Holes write nothing.
#[derive(Debug)]
pub struct ImagePass<'a> {
    pub image: &'a DepthImage,
}

impl PixelPass for ImagePass<'_> {
    fn shade_span(&self, x0: u32, y: u32, out: &mut [Option<Fragment>]) {
        let w = self.image.width();
        if y >= self.image.height() {
            return;
        }
        for (i, o) in out.iter_mut().enumerate() {
            let x = x0 + i as u32;
            if x >= w {
                break;
            }
            let k = (y * w + x) as usize;
            let c = self.image.color[k];
            if is_filled(c) {
                *o = Some(Fragment {
                    color: c,
                    depth: self
                        .image
                        .camera
                        .reversed_from_view_depth(self.image.depth[k]),
                });
            }
        }
    }
}

impl Technique for WarpedView {
    fn name(&self) -> &str {
        &self.name
    }
    fn prepare(&mut self, view: &FrameView<'_>) {
        self.warp_to(view.camera, view.width, view.height);
    }
    fn draws<'a>(&'a self, _out: &mut Vec<Draw<'a>>) {}
    fn passes(&self, _view: &FrameView<'_>, target: &mut Target) -> FrameStats {
        let image = self.warper.output();
        let rect = PixelRect::full(image.width(), image.height());
        run_pass(target, rect, &ImagePass { image }, PassMode::default())
    }
    fn counters(&self) -> Counters {
        Counters {
            images: self.last.references,
            pixels: self.last.pixels,
            samples: self.last.stats.samples,
            holes: self.last.holes.total(),
            ..Counters::default()
        }
    }
}

#[cfg(test)]
mod tests;
