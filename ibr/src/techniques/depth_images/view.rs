//! The warp as a technique: each frame the references nearest the eye are warped to the
//! frame's camera, holes are filled, and an image pass writes the result into the target,
//! depth-tested against the geometry drawn there (warped samples write depth, so geometry
//! in front hides them and they hide geometry behind). Pixels no warped reference saw
//! anything at stay empty ([`super::holes::seen`]): only holes are counted and filled.
//! References are prepared for the warp once, when they change.

use crate::core::{Counters, FrameView, Technique};
use crate::core::{DepthImage, LayeredDepthImage};
use crate::warp::holes::seen::{mark_unseen, sample_bounds, Bounds};
use crate::warp::holes::{classify_seen, Fill, Filler, HoleStats};
use crate::warp::predict::{depth_range, parallax_px};
use crate::warp::{ImagePass, Prepared, WarpOptions, WarpStats, Warped, Warper};
use engine::{run_packed_pass, Camera, Draw, FrameStats, PassMode, PixelRect, Target};

/// Depth images standing in for a scene from any nearby view.
#[derive(Debug)]
pub struct WarpedView {
    name: String,
    /// The references (after replacing some in place, call [`WarpedView::references_changed`]).
    pub references: Vec<DepthImage>,
    /// Layered depth images, warped (all of them) before the nearest references.
    pub layered: Vec<LayeredDepthImage>,
    /// How each reference is warped into the view.
    pub options: WarpOptions,
    /// How the warped image's holes are filled.
    pub fill: Fill,
    /// How many references, the nearest to the eye first, are warped each frame (after the
    /// layered images).
    pub nearest: usize,
    /// Whether holes are classified each frame (for counters and charts; a full pass over
    /// the image).
    pub count_holes: bool,
    /// Whether pixels no warped reference saw anything at are told from holes and left
    /// empty (`super::holes::seen`); when not, every pixel nothing landed on is a hole.
    pub carve: bool,
    warper: Warper,
    /// Per output pixel: nothing landed and no reference saw anything there.
    unseen: Vec<bool>,
    /// The box around each reference's samples, and each layered image's.
    bounds: Vec<Option<Bounds>>,
    bounds_layered: Vec<Option<Bounds>>,
    filler: Filler,
    order: Vec<(f32, usize)>,
    /// Each reference's median depth and depth range, and the references and layered
    /// images prepared for the warp, computed when they change.
    reach: Vec<f32>,
    ranges: Vec<Option<(f32, f32)>>,
    prepared: Vec<Prepared>,
    prepared_layered: Vec<Prepared>,
    last: WarpFrame,
}

/// What the last frame's warp did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WarpFrame {
    /// The warp's work, summed over the references warped.
    pub stats: WarpStats,
    /// Holes before filling (zero when not counted).
    pub holes: HoleStats,
    /// Hole pixels the fill gave a colour.
    pub filled: u64,
    /// Pixels the image pass offers the target (filled output pixels).
    pub pixels: u64,
    /// References warped: every layered image and the nearest `nearest` depth images.
    pub references: u64,
    /// The predicted parallax spread of the nearest reference, pixels
    /// (`super::predict::parallax_px`): the widest a disocclusion can open.
    pub predicted_px: f32,
}

impl WarpedView {
    /// A warped view named `name` of `references`: default [`WarpOptions`], pull-push
    /// fill, the 2 nearest references a frame, holes counted and unseen pixels carved.
    pub fn new(name: impl Into<String>, references: Vec<DepthImage>) -> Self {
        WarpedView {
            name: name.into(),
            references,
            layered: Vec::new(),
            options: WarpOptions::default(),
            fill: Fill::PullPush,
            nearest: 2,
            count_holes: true,
            carve: true,
            warper: Warper::new(),
            unseen: Vec::new(),
            bounds: Vec::new(),
            bounds_layered: Vec::new(),
            filler: Filler::default(),
            order: Vec::new(),
            reach: Vec::new(),
            ranges: Vec::new(),
            prepared: Vec::new(),
            prepared_layered: Vec::new(),
            last: WarpFrame::default(),
        }
    }

    /// Forgets what was computed from the references and layered images (their depths'
    /// median and range, their prepared forms).
    pub fn references_changed(&mut self) {
        self.reach.clear();
        self.prepared_layered.clear();
    }

    /// The last frame's warped and filled image.
    pub fn image(&self) -> &Warped {
        self.warper.output()
    }

    /// The last frame's unseen pixels (row-major; empty when not carved): nothing landed
    /// there and no warped reference saw anything there, so no fill writes them.
    pub fn unseen(&self) -> &[bool] {
        &self.unseen
    }

    /// What the last frame's warp did (all zero before the first frame).
    pub fn last(&self) -> WarpFrame {
        self.last
    }

    /// Warps the nearest references to `camera` at `width` x `height` and fills the holes.
    pub fn warp_to(&mut self, camera: &Camera, width: u32, height: u32) -> WarpFrame {
        crate::warp::on_pool(|| self.warp_on_pool(camera, width, height))
    }

    fn warp_on_pool(&mut self, camera: &Camera, width: u32, height: u32) -> WarpFrame {
        let eye = camera.eye();
        let forward = camera.forward();
        let edge = self.options.edge;
        let stale = |p: &[Prepared], n: usize| p.len() != n || p.iter().any(|p| p.edge() != edge);
        if self.reach.len() != self.references.len() || stale(&self.prepared, self.reach.len()) {
            self.reach = self.references.iter().map(median_depth).collect();
            self.ranges = self.references.iter().map(depth_range).collect();
            let prepare = |r: &DepthImage| Prepared::from_image(r, edge);
            self.prepared = self.references.iter().map(prepare).collect();
            self.bounds = self.prepared.iter().map(sample_bounds).collect();
        }
        if stale(&self.prepared_layered, self.layered.len()) {
            let prepare = |l: &LayeredDepthImage| Prepared::from_ldi(l, edge);
            self.prepared_layered = self.layered.iter().map(prepare).collect();
            self.bounds_layered = self.prepared_layered.iter().map(sample_bounds).collect();
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
        for ldi in &self.prepared_layered {
            frame.stats += self.warper.add_prepared(ldi, &self.options);
            frame.references += 1;
        }
        if let Some(&(_, i)) = self.order.first().filter(|_| self.nearest > 0) {
            let r = &self.references[i];
            frame.predicted_px = self.ranges[i].map_or(0.0, |range| {
                parallax_px(range, &r.camera, camera, width, height)
            });
        }
        for &(_, i) in self.order.iter().take(self.nearest) {
            frame.stats += self.warper.add_prepared(&self.prepared[i], &self.options);
            frame.references += 1;
        }
        self.unseen.clear();
        if self.carve && (self.count_holes || self.fill != Fill::None) {
            let nearest = &self.order[..self.nearest.min(self.order.len())];
            let prepared = &self.prepared;
            let refs = (self.prepared_layered.iter())
                .chain(nearest.iter().map(move |&(_, i)| &prepared[i]));
            let bounds = (self.bounds_layered.iter().copied())
                .chain(nearest.iter().map(|&(_, i)| self.bounds[i]))
                .flatten()
                .reduce(|[a, b], [c, d]| [a.min(c), b.max(d)]);
            let out = self.warper.output();
            mark_unseen(out, refs, bounds, edge, &mut self.unseen);
        }
        if self.count_holes {
            frame.holes = classify_seen(self.warper.output(), edge, &self.unseen);
        }
        let fill = self
            .filler
            .fill_seen(self.warper.output_mut(), self.fill, edge, &self.unseen);
        frame.filled = fill.filled;
        frame.pixels = self.warper.output().disparity.len() as u64 - fill.left;
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
        run_packed_pass(target, rect, &ImagePass::new(image), PassMode::default())
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
