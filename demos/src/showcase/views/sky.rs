//! The views moment's panorama sky: the showcase's scene beyond [`SPLIT`] units captured
//! from above the plaza into a cube map ([`ibr::panorama::Sky`]) and drawn behind the near
//! scene (drawn as geometry) while the eye walks away from the capture point; captured
//! again at the eye when the predicted parallax passes [`SKY_TOLERANCE_PX`]. Each frame is
//! measured against the whole geometry from the same eye, over the pixels the panorama
//! fills.

use super::{db, over_sky, Frame};
use crate::showcase::{self, attractions, FAR};
use engine::{Camera, Draw, Lighting};
use glam::{Quat, Vec3};
use ibr::capture::Capturer;
use ibr::images::DepthImage;
use ibr::metrics::{self, Image, ImageError, Options, Region};
use ibr::panorama::{trim_beyond, Sky};
use std::time::Instant;

/// The panorama holds what lies farther than this from where it was captured (along each
/// cube face's axis); nearer geometry is drawn.
pub const SPLIT: f32 = 10.0;
/// The panorama also holds the last this many units inside [`SPLIT`], drawn over by the
/// near scene where it is there: as the eye moves, a ray the near scene leaves empty just
/// past the split finds the panorama's copy instead of a hole.
const SEAM: f32 = 1.0;
/// Where the first panorama is captured: above the plaza's southern edge, looking north
/// over it (from its centre the eye would be inside the torus).
pub const SKY_CENTRE: Vec3 = Vec3::new(0.0, 3.0, 7.0);
/// The panorama is captured again when its predicted parallax passes this many pixels.
pub const SKY_TOLERANCE_PX: f32 = 6.0;
/// The eye's walk: as far as would make the first panorama this many tolerances wrong, so
/// every image size sees the same re-captures. Short enough that a step of the headless
/// run's few sky frames (four at 120 frames) stays under the tolerance: a re-capture
/// every other frame at most, not one every frame.
const SKY_WALK_TOLERANCES: f32 = 2.5;

/// What the sky part showed in one frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SkyFrame {
    /// The predicted parallax of the panorama drawn (pixels; 0 right after a capture).
    pub predicted_px: f32,
    /// The prediction for the panorama held before the frame, which decided re-capturing.
    pub before_px: f32,
    pub recaptured: bool,
    /// Captures so far (the first included).
    pub captures: u32,
    /// The share of the frame's pixels the panorama fills: what the near scene leaves and
    /// the far scene (in the panorama or the geometry) covers; open sky left out.
    pub far_share: f64,
    /// The error over those pixels against the whole geometry from the same eye.
    pub error: Option<ImageError>,
    /// Pixels the geometry covers that neither the near scene nor the panorama fills.
    pub unfilled: u64,
}

impl SkyFrame {
    /// The readout line (upper case, for the bitmap font): the parallax the re-capture
    /// decision acted on (the held panorama's, before the frame), and the one drawn after
    /// a re-capture.
    pub fn line(&self) -> String {
        let f = self;
        format!(
            "PANORAMA SKY  PARALLAX {:.1} PX (TOL {:.0})  FAR {:.0}% OF FRAME: {}, {:.0}% WRONG  \
             CAPTURES {}{}",
            f.before_px,
            SKY_TOLERANCE_PX,
            100.0 * f.far_share,
            db(f.error),
            100.0 * f.error.map_or(0.0, |e| e.frac_over),
            f.captures,
            if f.recaptured {
                format!("  RE-CAPTURED, NOW {:.1} PX", f.predicted_px)
            } else {
                String::new()
            }
        )
    }
}

/// Focal length in pixels of `camera` for an image `width` wide.
fn focal_px(camera: &Camera, width: u32) -> f32 {
    camera.projection.gl_matrix().x_axis.x * 0.5 * width as f32
}

/// The panorama sky, its walk and the images each frame reuses.
#[derive(Debug)]
pub(super) struct SkyPart {
    pub(super) sky: Sky,
    width: u32,
    height: u32,
    focal: f32,
    /// Length of the eye's walk from the first capture point.
    walk: f32,
    capturer: Capturer,
    /// The near scene, it with the panorama behind, and the whole geometry.
    near: DepthImage,
    image: DepthImage,
    truth: DepthImage,
    truth_rgba: Vec<u8>,
    mask: Vec<bool>,
}

impl SkyPart {
    pub(super) fn new(draws: &[Draw<'_>], lighting: &Lighting, w: u32, h: u32) -> SkyPart {
        let focal = focal_px(&showcase::camera(SKY_CENTRE, Vec3::NEG_Z, w, h), w);
        // Faces about as sharp as the view: half a face spans the focal length. (Twice as
        // sharp, up to 1024 texels, measured 24.1 / 19.9 dB mean / worst at 640x360
        // against 22.8 / 20.2, for four times the capture: the worst frames are the
        // parallax's, 5 px from the capture point, not the faces'.)
        let size = ((2.0 * focal) as u32).clamp(64, 512);
        let sky = Sky::new(
            draws,
            lighting,
            SKY_CENTRE,
            size,
            (SPLIT - SEAM, FAR),
            SKY_TOLERANCE_PX,
        );
        // The walk is set by the split (where the drawn geometry ends), not by the seam's
        // nearer points, which the near scene covers where they show.
        let walk = if sky.map.nearest().is_finite() {
            SKY_WALK_TOLERANCES * SKY_TOLERANCE_PX * SPLIT / focal.max(1.0)
        } else {
            1.0
        };
        let empty = DepthImage::new(0, 0, showcase::camera(SKY_CENTRE, Vec3::NEG_Z, w, h));
        SkyPart {
            sky,
            width: w,
            height: h,
            focal,
            walk: walk.clamp(0.1, 5.0),
            capturer: Capturer::new(),
            near: empty.clone(),
            image: empty.clone(),
            truth: empty,
            truth_rgba: Vec::new(),
            mask: Vec::new(),
        }
    }

    /// The eye and the point it looks at, a fraction `t` along the walk: sideways from the
    /// capture point, looking out over the plaza and turning a little.
    fn pose(&self, t: f32) -> (Vec3, Vec3) {
        let eye = SKY_CENTRE + Vec3::X * (self.walk * t);
        let dir = Quat::from_rotation_y(0.15 - 0.3 * t) * Vec3::new(0.3, -0.1, -1.0);
        (eye, eye + dir)
    }

    /// The near scene drawn, the panorama behind it (captured again first if needed), and
    /// the whole geometry from the same eye to measure it against.
    /// The last frame's geometry as RGBA8 over the sky, and the far scene's pixels it is
    /// measured over (for its flicker).
    pub(super) fn truth_and_mask(&self) -> (Vec<u8>, Vec<bool>) {
        (self.truth_rgba.clone(), self.mask.clone())
    }

    pub(super) fn frame(
        &mut self,
        draws: &[Draw<'_>],
        lighting: &Lighting,
        t: f32,
        out: &mut Frame,
    ) -> SkyFrame {
        let (w, h) = (self.width, self.height);
        let (eye, at) = self.pose(t);
        let camera = showcase::camera(eye, at, w, h);
        let before_px = self.sky.map.predicted_px(eye, self.focal);
        let recaptured = self.sky.update(draws, lighting, &camera, self.focal);
        // Everything in the panorama's cube (half side SPLIT round its centre) is nearer
        // than this: drawn, so nothing falls between the geometry and the panorama; what
        // is drawn outside the cube is cleared, the panorama's (each point drawn once: the
        // fence's copy in the panorama no longer shows through its drawn lattice's holes).
        let reach = SPLIT * 3f32.sqrt() + (eye - self.sky.map.centre()).length();
        let near = camera.with_depth_range(0.1, reach);
        let cap = &mut self.capturer;
        cap.capture(draws.iter().copied(), &near, lighting, w, h, &mut self.near);
        trim_beyond(&mut self.near, self.sky.map.centre(), SPLIT);
        let measure = Instant::now();
        cap.capture(
            draws.iter().copied(),
            &camera,
            lighting,
            w,
            h,
            &mut self.truth,
        );
        let truth = measure.elapsed();
        self.image.clone_from(&self.near);
        self.sky.map.behind(&mut self.image);
        self.mask.clear();
        let (mut far, mut unfilled) = (0usize, 0u64);
        for ((n, f), g) in self
            .near
            .color
            .iter()
            .zip(&self.image.color)
            .zip(&self.truth.color)
        {
            let sky = n.a <= 0.0 && (f.a > 0.0 || g.a > 0.0);
            far += sky as usize;
            unfilled += (g.a > 0.0 && f.a <= 0.0) as u64;
            self.mask.push(sky);
        }
        over_sky(&self.image, &mut out.rgba);
        let measure = Instant::now();
        over_sky(&self.truth, &mut self.truth_rgba);
        (out.width, out.height) = (w, h);
        let error = compare_masked(&out.rgba, &self.truth_rgba, (w, h), &self.mask);
        if let (Some(dir), Some(e)) = (std::env::var_os(attractions::DUMP), error) {
            let n = (t * 1000.0) as usize;
            let both = [out.rgba.as_slice(), self.truth_rgba.as_slice()];
            attractions::dump(dir.as_ref(), "sky", n, e, both, &self.mask, (w, h));
        }
        out.measure = truth + measure.elapsed();
        SkyFrame {
            predicted_px: self.sky.map.predicted_px(eye, self.focal),
            before_px,
            recaptured,
            captures: self.sky.captures,
            far_share: far as f64 / (w as f64 * h as f64),
            error,
            unfilled,
        }
    }
}

/// The error of RGBA8 image `a` against `b`, both `size`, over the pixels of `mask`;
/// `None` when there is none.
fn compare_masked(a: &[u8], b: &[u8], (w, h): (u32, u32), mask: &[bool]) -> Option<ImageError> {
    let options = Options {
        region: Region::Mask(mask),
        ..Options::default()
    };
    metrics::compare_rgba8(
        Image::new(w, h, a).ok()?,
        Image::new(w, h, b).ok()?,
        &options,
    )
    .ok()
}
