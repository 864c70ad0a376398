//! The views moment's view morph: two views of the plaza, captured with depth from eyes
//! apart across the view, morphed into each other ([`ibr::morph::ViewMorph`], prewarped
//! once) and measured, beside the plain morph without prewarp, against the geometry drawn
//! from each in-between camera.

use super::{db, over_sky, Frame, Stages};
use crate::showcase;
use crate::timing::Usage;
use engine::{Draw, Lighting};
use glam::Vec3;
use ibr::capture::{capture_batch, Capturer};
use ibr::images::DepthImage;
use ibr::metrics::{compare_rgba8, compare_seen, Image, ImageError, Options, Region};
use ibr::morph::{plain_morph, Correspondence, MorphScratch, MorphStats, ViewMorph};
use std::time::Instant;

/// The morphed views' eyes, both looking at [`MORPH_TARGET`] (the "near" pair of
/// `bench morph`: 4 units apart across the view, not parallel).
pub const MORPH_EYES: [Vec3; 2] = [Vec3::new(-2.0, 3.0, 12.0), Vec3::new(2.0, 3.0, 12.0)];
pub const MORPH_TARGET: Vec3 = Vec3::new(0.0, 1.0, 0.0);

/// The morphed views are captured this much wider than the frame (a strip of a sixth of
/// the frame's width beyond each side): the in-between views turn between the two, and a
/// frame captured only as wide left a strip at the frame's edge that neither view saw
/// (beside the house, at s 0.33 and 0.67), filled along its rows from whatever each row's
/// first mapped pixel showed: grey and green streaks (issue 39).
pub const WIDER: f32 = 1.3;
/// The prewarped pair's size against the wide views' (at their focal length): as tall as
/// that, about twice the frame's width (the frame's 1.5 without the wider views).
const FRAMING: f32 = 1.3;

/// What the morph part showed in one frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MorphFrame {
    /// How far from the first view to the second.
    pub s: f32,
    /// The morph and the plain morph against the geometry from the in-between camera, over
    /// the pixels both cover, with the share of the geometry's pixels each covers.
    pub error: Option<(ImageError, f64)>,
    pub plain: Option<(ImageError, f64)>,
    pub stats: MorphStats,
    /// The morph against the geometry over every pixel the geometry covers, both over the
    /// sky colour as shown: holes and what the morph left empty count (issue 39).
    pub full: Option<ImageError>,
    /// Pixels where the geometry shows something (ground, trees) and the morph shows the
    /// sky colour (less than half covered): sky-coloured holes and corners.
    pub sky_on_ground: u64,
    /// Pixels of the frame, which the holes of `stats` are counted in.
    pub frame_px: u64,
    /// Pixels of the parallel canvas morphed for this frame (a work counter: the band
    /// the postwarp reads, of a canvas about twice the frame's pixels).
    pub canvas_px: u64,
    /// Pixels of the canvas's rows the postwarp reads, every column: what was morphed
    /// before the columns were cut (the reference of `canvas_px`).
    pub band_px: u64,
    /// Pixels of the two prewarped views the morph looked at (a work counter: those too
    /// far along their row to move into the columns morphed are skipped).
    pub source_px: u64,
}

impl MorphFrame {
    /// The readout line (upper case, for the bitmap font).
    pub fn line(&self) -> String {
        let seen = |e: Option<(ImageError, f64)>| {
            let share = e.map_or(0.0, |e| 100.0 * e.1);
            format!("{} ({share:.0}% SEEN)", db(e.map(|e| e.0)))
        };
        format!(
            "VIEW MORPH S {:.2}  {}  ALL {}  SKY ON GROUND {} PX  PLAIN {}  HOLES {:.0}%  \
             CANVAS {:.2} OF {:.2} MPX FROM {:.2} MPX",
            self.s,
            seen(self.error),
            db(self.full),
            self.sky_on_ground,
            seen(self.plain),
            100.0 * self.holes_share(),
            self.canvas_px as f64 * 1e-6,
            self.band_px as f64 * 1e-6,
            self.source_px as f64 * 1e-6
        )
    }

    /// The holes' share of the frame.
    pub fn holes_share(&self) -> f64 {
        self.stats.holes as f64 / self.frame_px.max(1) as f64
    }
}

/// The two views, prewarped for morphing, and the images each frame reuses.
#[derive(Debug)]
pub(super) struct MorphPart {
    views: Vec<DepthImage>,
    morph: ViewMorph,
    capturer: Capturer,
    truth: DepthImage,
    /// The morph's canvas and view, kept from frame to frame.
    scratch: MorphScratch,
}

impl MorphPart {
    pub(super) fn new(
        draws: &[Draw<'_>],
        lighting: &Lighting,
        w: u32,
        h: u32,
    ) -> Result<MorphPart, String> {
        let cameras = MORPH_EYES.map(|eye| showcase::camera(eye, MORPH_TARGET, w, h));
        let views = capture_batch(draws, &cameras, lighting, w, h);
        // The morphed views, wider than the frame at its focal length (the same vertical
        // field of view): the turned in-between views' corners lie within what they saw.
        let wide_w = (w as f32 * WIDER).round() as u32;
        let wide = MORPH_EYES.map(|eye| showcase::camera(eye, MORPH_TARGET, wide_w, h));
        let wide = capture_batch(draws, &wide, lighting, wide_w, h);
        let morph = ViewMorph::framed(&wide[0], &wide[1], Correspondence::Depth, FRAMING)
            .map_err(|e| format!("the views moment's morph at {w}x{h}: {e}"))?
            .shown_as(cameras[0].projection, w, h);
        let truth = DepthImage::new(0, 0, cameras[0]);
        // The canvas and the view made now, at loading (the first view drawn into them):
        // made in the first frame they were 58 MB of page faults, its time doubled. The
        // view is shown as colour over the sky and measured by colour: no depth is made
        // (the same colours; a nearest-depth lookup and two divisions a pixel fewer).
        let mut scratch = MorphScratch::default();
        scratch.depth = false;
        morph.view_into(0.0, &mut scratch);
        Ok(MorphPart {
            views,
            morph,
            capturer: Capturer::new(),
            truth,
            scratch,
        })
    }

    /// The in-between view a fraction `s` of the way, measured with the plain morph
    /// against the geometry from the in-between camera.
    /// The last frame's geometry as RGBA8 over the sky (for its flicker).
    pub(super) fn truth_rgba(&self) -> Vec<u8> {
        let mut out = Vec::new();
        over_sky(&self.truth, &mut out);
        out
    }

    pub(super) fn frame(
        &mut self,
        draws: &[Draw<'_>],
        lighting: &Lighting,
        s: f32,
        out: &mut Frame,
    ) -> MorphFrame {
        let labels = self.morph.view_into(s, &mut self.scratch);
        let view = &self.scratch.view;
        // Shown: the view over the sky.
        let start = Instant::now();
        over_sky(view, &mut out.rgba);
        out.stages = Stages {
            canvas: self.scratch.canvas_time,
            postwarp: self.scratch.postwarp_time,
            over_sky: start.elapsed(),
            ..Stages::default()
        };
        let camera = self.morph.camera_at(s);
        let (w, h) = (view.width(), view.height());
        let measure = Instant::now();
        let used = Usage::now();
        // What the view is made of (its holes' share) is a figure for the readout: measuring.
        let stats = self.morph.stats(&labels);
        self.capturer.capture(
            draws.iter().copied(),
            &camera,
            lighting,
            w,
            h,
            &mut self.truth,
        );
        // The plain cross-dissolve is only a figure to compare with: measuring too.
        let plain = plain_morph(&self.views[0], &self.views[1], s);
        let (error, plain) = (
            compare_seen(view, &self.truth).ok(),
            compare_seen(&plain, &self.truth).ok(),
        );
        let (full, sky_on_ground) = against_all(view, &out.rgba, &self.truth);
        // Both reads of the usage inside the measure's time, which the frame leaves out.
        out.measure_usage = Usage::now().since(used);
        out.measure = measure.elapsed();
        (out.width, out.height) = (w, h);
        MorphFrame {
            s,
            frame_px: w as u64 * h as u64,
            canvas_px: self.scratch.canvas_px,
            band_px: self.scratch.band_px,
            source_px: self.scratch.source_px,
            error,
            plain,
            stats,
            full,
            sky_on_ground,
        }
    }
}

/// The morphed `view` (shown as `shown`, RGBA8 over the sky) against `truth` over every
/// pixel `truth` covers, and the count of those where the view is less than half covered
/// (shows the sky colour).
fn against_all(view: &DepthImage, shown: &[u8], truth: &DepthImage) -> (Option<ImageError>, u64) {
    if view.color.len() != truth.color.len() {
        return (None, 0);
    }
    let covered: Vec<bool> = truth.color.iter().map(|c| c.a > 0.0).collect();
    let sky_on_ground = (view.color.iter().zip(&truth.color))
        .filter(|(v, t)| t.a >= 0.5 && v.a < 0.5)
        .count() as u64;
    let mut reference = Vec::new();
    over_sky(truth, &mut reference);
    let (w, h) = (view.width(), view.height());
    let options = Options {
        region: Region::Mask(&covered),
        ..Options::default()
    };
    let error = Image::new(w, h, shown)
        .and_then(|a| compare_rgba8(a, Image::new(w, h, &reference)?, &options))
        .ok();
    (error, sky_on_ground)
}
