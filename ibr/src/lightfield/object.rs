//! A light field standing in a rasterized scene, like an impostor: each frame it is
//! rendered into the screen rectangle its focal plane covers (a crop of the frame's
//! camera, so the cost follows the covered pixels), then composited by an image pass that
//! depth-tests against the geometry, blends its edges "over" and writes the depth of its
//! proxy (the focal plane).

use super::render::{render, LightFieldFrame, Lookup};
use super::LightField;
use crate::subject::{MeshGroup, Subject};
use crate::technique::{Counters, FrameView, Technique};
use crate::warp::technique::ImagePass;
use crate::warp::Warped;
use engine::{
    run_packed_pass, Camera, Draw, Encoding, FrameStats, PackedFragment, PackedPass, PassMode,
    PixelRect, Target,
};
use glam::Vec2;

/// A light field in a scene, and the geometry it stands for (for error measurement).
#[derive(Debug)]
pub struct LightFieldObject {
    pub name: String,
    pub field: LightField,
    pub lookup: Lookup,
    /// The geometry captured into the light field, if kept.
    pub reference: Option<MeshGroup>,
    image: Warped,
    rect: Option<PixelRect>,
    last: LightFieldFrame,
}

impl LightFieldObject {
    pub fn new(name: impl Into<String>, field: LightField) -> Self {
        let camera = field.slab.camera(0, 0);
        LightFieldObject {
            name: name.into(),
            field,
            lookup: Lookup::default(),
            reference: None,
            image: Warped::new(0, 0, camera),
            rect: None,
            last: LightFieldFrame::default(),
        }
    }

    /// The last frame's work.
    pub fn last(&self) -> LightFieldFrame {
        self.last
    }

    /// The pixels of a `width` x `height` view the focal plane can cover: the bounds of its
    /// corners on screen, or the whole view when a corner is behind the eye; `None` when
    /// off screen.
    fn screen_rect(&self, camera: &Camera, width: u32, height: u32) -> Option<PixelRect> {
        let m = camera.clip_from_world();
        let (mut lo, mut hi) = (Vec2::splat(f32::INFINITY), Vec2::NEG_INFINITY);
        let st = &self.field.slab.st;
        for p in [
            st.at(0.0, 0.0),
            st.at(1.0, 0.0),
            st.at(1.0, 1.0),
            st.at(0.0, 1.0),
        ] {
            let c = m * p.extend(1.0);
            if c.w.is_nan() || c.w <= 1e-6 {
                return Some(PixelRect::full(width, height));
            }
            let px = Vec2::new(
                (c.x / c.w + 1.0) * 0.5 * width as f32,
                (1.0 - c.y / c.w) * 0.5 * height as f32,
            );
            lo = lo.min(px);
            hi = hi.max(px);
        }
        let clamp = |v: f32, n: u32| v.clamp(0.0, n as f32);
        let (x0, y0) = (clamp(lo.x.floor(), width), clamp(lo.y.floor(), height));
        let (x1, y1) = (clamp(hi.x.ceil(), width), clamp(hi.y.ceil(), height));
        (x0 < x1 && y0 < y1).then_some(PixelRect {
            x0: x0 as u32,
            y0: y0 as u32,
            x1: x1 as u32,
            y1: y1 as u32,
        })
    }
}

/// An image pass over a crop of the frame: pixel `(x, y)` of the frame is pixel
/// `(x - x0, y - y0)` of the crop.
struct Cropped<'a> {
    pass: ImagePass<'a>,
    x0: u32,
    y0: u32,
}

impl PackedPass for Cropped<'_> {
    fn encoding(&self) -> Encoding {
        self.pass.encoding()
    }

    fn shade_span(&self, x0: u32, y: u32, out: &mut [Option<PackedFragment>]) {
        if x0 >= self.x0 && y >= self.y0 {
            self.pass.shade_span(x0 - self.x0, y - self.y0, out);
        }
    }
}

impl Technique for LightFieldObject {
    fn name(&self) -> &str {
        &self.name
    }

    fn prepare(&mut self, view: &FrameView<'_>) {
        self.rect = self.screen_rect(view.camera, view.width, view.height);
        self.last = LightFieldFrame::default();
        if let Some(r) = self.rect {
            let lo = Vec2::new(r.x0 as f32, r.y0 as f32);
            let hi = Vec2::new(r.x1 as f32, r.y1 as f32);
            let crop = view.camera.crop(lo, hi, view.width, view.height);
            let (w, h) = (r.x1 - r.x0, r.y1 - r.y0);
            self.last = render(&self.field, &crop, w, h, self.lookup, &mut self.image);
        }
    }

    fn draws<'a>(&'a self, _out: &mut Vec<Draw<'a>>) {}

    fn passes(&self, _view: &FrameView<'_>, target: &mut Target) -> FrameStats {
        let Some(rect) = self.rect else {
            return FrameStats::default();
        };
        let pass = Cropped {
            pass: ImagePass::new(&self.image),
            x0: rect.x0,
            y0: rect.y0,
        };
        let mode = PassMode {
            blend: true,
            ..PassMode::default()
        };
        run_packed_pass(target, rect, &pass, mode)
    }

    fn counters(&self) -> Counters {
        Counters {
            images: self.rect.is_some() as u64,
            pixels: self.last.pixels,
            samples: self.last.taps,
            ..Counters::default()
        }
    }

    fn reference<'a>(&'a self, out: &mut Vec<Draw<'a>>) {
        if let Some(g) = &self.reference {
            g.draws(out);
        }
    }
}
