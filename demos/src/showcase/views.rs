//! The showcase's views moment (`showcase --views`, V in the window): views made from
//! images instead of all of their geometry, each beside its error against the geometry
//! drawn from the same eye. The moment plays its parts one after another ([`Part::ALL`]):
//! - [`Part::Layers`]: a layered background, the scene's objects beyond the plaza as image
//!   layers warped by the perspective map fitted to their corners and re-rendered past a
//!   pixel of error within a per-frame budget ([`ibr::layers`]), as the eye strolls across
//!   the plaza and turns;
//! - [`Part::Sky`]: a far land (a ring of mountains beyond [`SPLIT`] units, what a
//!   panorama carries) captured from above the plaza into a cube-map panorama
//!   ([`ibr::panorama::Sky`]) and drawn behind the plaza's scene, which is drawn as
//!   geometry, as the eye walks away from where it was captured; captured again, a few
//!   faces a frame, ahead of where the predicted parallax passes [`SKY_TOLERANCE_PX`];
//! - [`Part::Morph`]: two views of the plaza morphed into each other (view morphing with
//!   correspondences from depth, [`ibr::morph::ViewMorph`]), beside the plain morph without
//!   prewarp, which is not shape preserving.
//!
//! A part is a case of [`Part`] and a submodule (`layers`, `sky`, `morph`) holding its state, built
//! when the part is first shown (captures and prewarp happen once), its frame function and
//! its readout line; adding one is a new submodule, a case and its arms in
//! [`ViewsTour::render_part`], [`ViewsTour::readout`] and [`ViewsTour::summary`]. Frames
//! are opaque sRGB images over the showcase's sky colour.

mod layers;
mod morph;
mod sky;

pub use layers::{LayersFrame, LAYERS_BUDGET, LAYERS_TOLERANCE_PX};
pub use morph::{MorphFrame, MORPH_EYES, MORPH_TARGET};
pub use sky::{SkyFrame, SKY_CENTRE, SKY_TOLERANCE_PX, SPLIT};

use crate::showcase::SKY;
use crate::timing::Usage;
use engine::color::{Encoder, Encoding};
use engine::{Camera, Draw, Premul, Scene, Sphere};
use ibr::images::DepthImage;
use ibr::impostor::Frustum;
use ibr::metrics::ImageError;
use layers::LayersPart;
use morph::MorphPart;
use rayon::prelude::*;
use sky::SkyPart;
use std::time::Duration;

/// PSNR figures are capped here (a view identical to its geometry has an infinite one).
const PSNR_CAP: f64 = 99.0;

/// The parts of the moment, in the order they play.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Part {
    Layers,
    Sky,
    Morph,
}

impl Part {
    pub const ALL: [Part; 3] = [Part::Layers, Part::Sky, Part::Morph];

    /// The part frame `i` of `n` shows and how far along it (0 to 1): the frames shared
    /// out in order, a part of one frame shown halfway.
    pub fn at(i: usize, n: usize) -> (Part, f32) {
        let parts = Self::ALL.len();
        let n = n.max(parts);
        let i = i.min(n - 1);
        let p = i * parts / n;
        let (start, end) = ((p * n).div_ceil(parts), ((p + 1) * n).div_ceil(parts));
        let t = if end - start > 1 {
            (i - start) as f32 / (end - start - 1) as f32
        } else {
            0.5
        };
        (Self::ALL[p], t)
    }
}

/// One frame of the moment: opaque sRGB RGBA8, row-major, top row first.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Frame {
    pub width: u32,
    pub height: u32,
    pub rgba: Vec<u8>,
    /// Time this frame spent measuring itself: rendering the geometry it is compared with
    /// and comparing. Not part of showing it: the headless frame times leave it out.
    pub measure: Duration,
    /// What measuring cost the process ([`Usage`]: CPU time of all threads, page faults),
    /// so that the headless run can leave it out of the frame's own.
    pub measure_usage: Usage,
    /// Where the time of showing it went.
    pub stages: Stages,
}

/// Where one frame's time went, by stage (zero where its part has no such stage); with
/// [`Frame::measure`] (the readout's reference renders and comparisons) the columns of
/// the headless run's `views_times.csv`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Stages {
    /// The image layers' re-renders (the layers' `prepare`).
    pub layers: Duration,
    /// The panorama's update (its spread re-capture).
    pub sky: Duration,
    /// The morph to the parallel in-between canvas, and its postwarp to the view.
    pub canvas: Duration,
    pub postwarp: Duration,
    /// The frame made into the shown sRGB bytes (over the sky colour); for the sky part,
    /// with the panorama looked up behind the near scene in the same pass (session 18:
    /// until then its lookup was in `sky`, and the near scene's read-back to floats in
    /// `geometry`).
    pub over_sky: Duration,
    /// The engine's render of what is drawn as geometry (and, for the layers, composited).
    pub geometry: Duration,
}

impl Stages {
    /// The columns of [`Stages::row`] and the readout's measure, as the CSV names them.
    pub const COLUMNS: [&'static str; 7] = [
        "layers",
        "sky",
        "morph_canvas",
        "postwarp",
        "over_sky",
        "geometry_render",
        "readout",
    ];

    /// The stages in [`Stages::COLUMNS`]'s order, `measure` last.
    pub fn row(&self, measure: Duration) -> [Duration; 7] {
        [
            self.layers,
            self.sky,
            self.canvas,
            self.postwarp,
            self.over_sky,
            self.geometry,
            measure,
        ]
    }
}

impl Frame {
    /// The frame as `0x00RRGGBB` pixels of a `width` x `height` window (nearest pixel).
    pub fn write_rgb_u32(&self, out: &mut Vec<u32>, width: u32, height: u32) {
        out.clear();
        let (fw, fh) = (self.width.max(1) as u64, self.height.max(1) as u64);
        for y in 0..height as u64 {
            let sy = (y * fh / height.max(1) as u64) as usize;
            out.extend((0..width as u64).map(|x| {
                let i = (sy * fw as usize + (x * fw / width.max(1) as u64) as usize) * 4;
                match self.rgba.get(i..i + 3) {
                    Some(p) => u32::from_be_bytes([0, p[0], p[1], p[2]]),
                    None => 0,
                }
            }));
        }
    }
}

/// What the last frame showed.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Shown {
    #[default]
    Nothing,
    Layers(LayersFrame),
    Sky(SkyFrame),
    Morph(MorphFrame),
}

/// The moment: the scene, each part's state once shown, the last frame and running totals.
#[derive(Debug)]
pub struct ViewsTour {
    scene: Scene,
    width: u32,
    height: u32,
    layers: Option<LayersPart>,
    sky: Option<SkyPart>,
    morph: Option<Result<MorphPart, String>>,
    frame: Frame,
    last: Shown,
    layers_totals: Totals,
    sky_totals: Totals,
    morph_totals: Totals,
}

/// Sums over the frames of one part, for the summary.
#[derive(Clone, Copy, Debug, Default)]
struct Totals {
    frames: usize,
    /// Frames measured, and the sums of their PSNRs (capped) and shares of wrong pixels:
    /// the morph's frames between its ends only (the ends are the views, resampled).
    measured: usize,
    psnr: f64,
    wrong: f64,
    /// The plain morph's PSNR sum over the same frames.
    plain_psnr: f64,
    /// The largest predicted parallax before a frame (sky), or geometric error (layers).
    peak_px: f32,
    /// The sum of the holes' (filled) shares of the frame (morph), or of the layers
    /// re-rendered (layers).
    holes: f64,
    /// The morph's PSNR sum over every pixel the geometry covers (holes count), and its
    /// pixels shown as sky where the geometry shows a surface, over the measured frames.
    full_psnr: f64,
    sky_on_ground: u64,
}

impl Totals {
    fn add(&mut self, e: ImageError) {
        self.measured += 1;
        self.psnr += e.psnr_capped(PSNR_CAP);
        self.wrong += e.frac_over;
    }

    fn mean(&self, sum: f64) -> f64 {
        sum / self.measured.max(1) as f64
    }
}

impl ViewsTour {
    /// The moment over `scene` (as posed) at `width` x `height`; nothing is captured yet.
    pub fn new(scene: Scene, width: u32, height: u32) -> ViewsTour {
        ViewsTour {
            scene,
            width: width.max(1),
            height: height.max(1),
            layers: None,
            sky: None,
            morph: None,
            frame: Frame::default(),
            last: Shown::Nothing,
            layers_totals: Totals::default(),
            sky_totals: Totals::default(),
            morph_totals: Totals::default(),
        }
    }

    /// Builds every part now (its captures, prewarps and layers), so that no frame of the
    /// moment builds one: the work that cannot be spread over frames is done ahead, as the
    /// scene's loading is. Fails as [`ViewsTour::render_part`] does.
    pub fn prepare(&mut self) -> Result<(), String> {
        let draws: Vec<Draw<'_>> = self.scene.draws().collect();
        let lighting = &self.scene.lighting;
        let (w, h) = (self.width, self.height);
        self.layers
            .get_or_insert_with(|| LayersPart::new(&self.scene, w, h));
        self.sky
            .get_or_insert_with(|| SkyPart::new(&draws, lighting, w, h));
        let morph = self
            .morph
            .get_or_insert_with(|| MorphPart::new(&draws, lighting, w, h));
        // The shown frame's bytes, kept from frame to frame, made now too: in the first
        // frame they were 3.7 MB of page faults at 1280x720 (session 21).
        let bytes = w as usize * h as usize * 4;
        if self.frame.rgba.len() < bytes {
            self.frame.rgba.resize(bytes, 0);
        }
        morph.as_ref().map(|_| ()).map_err(|e| e.clone())
    }

    /// Frame `i` of `n` of the moment ([`Part::at`]).
    pub fn render(&mut self, i: usize, n: usize) -> Result<&Frame, String> {
        let (part, t) = Part::at(i, n);
        self.render_part(part, t)
    }

    /// `part` a fraction `t` of the way along; builds the part when first shown. Fails
    /// only when the views cannot be morphed (at a size too small to prewarp).
    pub fn render_part(&mut self, part: Part, t: f32) -> Result<&Frame, String> {
        let draws: Vec<Draw<'_>> = self.scene.draws().collect();
        let lighting = &self.scene.lighting;
        let (w, h) = (self.width, self.height);
        self.frame.measure = Duration::ZERO;
        self.frame.measure_usage = Usage::default();
        self.frame.stages = Stages::default();
        let t = if t.is_finite() {
            t.clamp(0.0, 1.0)
        } else {
            0.0
        };
        match part {
            Part::Layers => {
                let part = self
                    .layers
                    .get_or_insert_with(|| LayersPart::new(&self.scene, w, h));
                let f = part.frame(&self.scene, t, &mut self.frame);
                let totals = &mut self.layers_totals;
                totals.frames += 1;
                totals.peak_px = totals.peak_px.max(f.max_px);
                totals.holes += f.refreshes as f64;
                if let Some(e) = f.error {
                    totals.add(e);
                }
                self.last = Shown::Layers(f);
            }
            Part::Sky => {
                let sky = self
                    .sky
                    .get_or_insert_with(|| SkyPart::new(&draws, lighting, w, h));
                let f = sky.frame(&draws, lighting, t, &mut self.frame);
                let totals = &mut self.sky_totals;
                totals.frames += 1;
                totals.peak_px = totals.peak_px.max(f.before_px);
                if let Some(e) = f.error {
                    totals.add(e);
                }
                self.last = Shown::Sky(f);
            }
            Part::Morph => {
                let morph = self
                    .morph
                    .get_or_insert_with(|| MorphPart::new(&draws, lighting, w, h))
                    .as_mut()
                    .map_err(|e| e.clone())?;
                let f = morph.frame(&draws, lighting, t, &mut self.frame);
                let totals = &mut self.morph_totals;
                totals.frames += 1;
                totals.holes += f.holes_share();
                if let (Some((e, _)), Some((plain, _)), true) =
                    (f.error, f.plain, t > 0.0 && t < 1.0)
                {
                    totals.add(e);
                    totals.plain_psnr += plain.psnr_capped(PSNR_CAP);
                    totals.full_psnr += f.full.map_or(0.0, |e| e.psnr_capped(PSNR_CAP));
                    totals.sky_on_ground += f.sky_on_ground;
                }
                self.last = Shown::Morph(f);
            }
        }
        Ok(&self.frame)
    }

    /// The last frame rendered.
    pub fn frame(&self) -> &Frame {
        &self.frame
    }

    /// What the last frame showed.
    pub fn last(&self) -> Shown {
        self.last
    }

    /// The last frame as shown and its geometry from the same eye (RGBA8, the frame's
    /// encoding), and the pixels its part is measured over; `None` before a frame.
    pub fn renders(&self) -> Option<(Vec<u8>, Vec<u8>, Vec<bool>)> {
        let image = self.frame.rgba.clone();
        let all = || vec![true; image.len() / 4];
        let (truth, mask) = match self.last {
            Shown::Nothing => return None,
            Shown::Layers(_) => (self.layers.as_ref()?.truth_rgba(), all()),
            Shown::Sky(_) => self.sky.as_ref()?.truth_and_mask(),
            Shown::Morph(_) => (self.morph.as_ref()?.as_ref().ok()?.truth_rgba(), all()),
        };
        (truth.len() == image.len() && mask.len() == image.len() / 4)
            .then_some((image, truth, mask))
    }

    /// Panorama captures so far (0 before the sky was shown).
    pub fn captures(&self) -> u32 {
        self.sky.as_ref().map_or(0, |s| s.sky.captures)
    }

    /// One line for the window and the console (upper case, for the bitmap font): the last
    /// frame's part and its measured error.
    pub fn readout(&self) -> String {
        match self.last {
            Shown::Nothing => "VIEWS".to_string(),
            Shown::Layers(f) => f.line(),
            Shown::Sky(f) => f.line(),
            Shown::Morph(f) => f.line(),
        }
    }

    /// One line per part shown so far: its frames and mean error.
    pub fn summary(&self) -> Vec<String> {
        let mut lines = Vec::new();
        let l = &self.layers_totals;
        if let (Some(part), true) = (&self.layers, l.frames > 0) {
            lines.push(format!(
                "layered background: {} frames, {} layers (the terrain and the plaza as \
                 geometry), tolerance {LAYERS_TOLERANCE_PX} px, at most {LAYERS_BUDGET} \
                 re-rendered a frame: {:.1} re-rendered a frame on average ({} in all), \
                 predicted error up to {:.2} px; the frame against the geometry: PSNR mean \
                 {:.1} dB, {:.1}% of pixels off by more than 8 levels",
                l.frames,
                part.layers.subjects.len(),
                l.holes / l.frames as f64,
                l.holes,
                l.peak_px,
                l.mean(l.psnr),
                100.0 * l.mean(l.wrong)
            ));
        }
        let s = &self.sky_totals;
        if let (Some(sky), true) = (&self.sky, s.frames > 0) {
            lines.push(format!(
                "panorama sky: {} frames, faces {} px, tolerance {SKY_TOLERANCE_PX} px: {} \
                 captures ({} re-captures), predicted parallax up to {:.1} px; against the \
                 geometry over the far scene's pixels: PSNR mean {:.1} dB, {:.1}% of pixels \
                 off by more than 8 levels",
                s.frames,
                sky.sky.size,
                sky.sky.captures,
                sky.sky.captures.saturating_sub(1),
                s.peak_px,
                s.mean(s.psnr),
                100.0 * s.mean(s.wrong)
            ));
        }
        let m = &self.morph_totals;
        if m.frames > 0 {
            let between = if m.measured > 0 {
                format!(
                    "between them ({} frames) PSNR mean {:.1} dB against the geometry, the plain \
                     morph's {:.1} dB; over every pixel the geometry covers {:.1} dB, {} pixels \
                     shown as sky where it shows a surface",
                    m.measured,
                    m.mean(m.psnr),
                    m.mean(m.plain_psnr),
                    m.mean(m.full_psnr),
                    m.sky_on_ground
                )
            } else {
                "no frame between them".to_string()
            };
            lines.push(format!(
                "view morph: {} frames from one view to the other; {between}; holes filled on \
                 {:.0}% of the frame on average",
                m.frames,
                100.0 * m.holes / m.frames as f64
            ));
        }
        lines
    }
}

/// Each draw's bounding sphere in world space (its mesh's, moved by its transform and
/// grown by its largest scale): made once for a part's draws, which do not move.
fn world_spheres(draws: &[Draw<'_>]) -> Vec<Sphere> {
    (draws.iter())
        .map(|d| {
            let s = d.mesh.bounding_sphere();
            let t = d.transform;
            let scale = (t.x_axis.truncate().length())
                .max(t.y_axis.truncate().length())
                .max(t.z_axis.truncate().length());
            Sphere {
                center: t.transform_point3(s.center),
                radius: s.radius * scale,
            }
        })
        .collect()
}

/// The draws of `draws` whose bounding sphere (`spheres`, one a draw, [`world_spheres`])
/// reaches into `camera`'s frustum, into `out`: the others cover no pixel of its view
/// (the same pixels without them; fewer triangles set up).
fn in_view<'a>(draws: &[Draw<'a>], spheres: &[Sphere], camera: &Camera, out: &mut Vec<Draw<'a>>) {
    let frustum = Frustum::new(camera.clip_from_world());
    out.clear();
    out.extend(
        (draws.iter().zip(spheres))
            .filter_map(|(d, s)| frustum.sees(s.center, s.radius).then_some(*d)),
    );
}

/// The triangles of `draws` (a work counter for the readouts).
fn triangles(draws: &[Draw<'_>]) -> usize {
    draws.iter().map(|d| d.mesh.triangle_count()).sum()
}

/// A PSNR for the readouts, capped; `-` when nothing was measured.
fn db(e: Option<ImageError>) -> String {
    match e {
        Some(e) => format!("{:.1} DB", e.psnr_capped(PSNR_CAP)),
        None => "-".to_string(),
    }
}

/// `image` over the showcase's sky colour, as opaque sRGB RGBA8 bytes into `out`. In
/// chunks on the pool (each pixel its own: the same bytes on any number of threads): one
/// thread took 9 to 14 ms of the morph's frame at 1280x720.
/// Eight pixels at a time through the encoder's 8-lane packing ([`Encoder::pack8`], bit for
/// bit its one-pixel [`Encoder::pack`], as [`over_sky_pixel`] packs the rest of a chunk):
/// the same bytes as [`engine::color::encode_srgb8`] a channel.
fn over_sky(image: &DepthImage, out: &mut Vec<u8>) {
    const CHUNK: usize = 4096;
    let sky = SKY.premultiply();
    let encoder = Encoder::new(Encoding::Srgb);
    out.clear();
    out.resize(image.color.len() * 4, 0);
    out.par_chunks_mut(CHUNK * 4)
        .zip(image.color.par_chunks(CHUNK))
        .for_each(|(bytes, colors)| {
            let mut blocks = bytes.chunks_exact_mut(32);
            let mut eights = colors.chunks_exact(8);
            for (block, eight) in (&mut blocks).zip(&mut eights) {
                let (mut r, mut g, mut b, mut words) =
                    ([0.0f32; 8], [0.0f32; 8], [0.0f32; 8], [0u32; 8]);
                for (l, c) in eight.iter().enumerate() {
                    let k = 1.0 - c.a.clamp(0.0, 1.0);
                    (r[l], g[l], b[l]) = (c.r + sky.r * k, c.g + sky.g * k, c.b + sky.b * k);
                }
                encoder.pack8(&r, &g, &b, &[1.0; 8], &mut words);
                for (p, w) in block.chunks_exact_mut(4).zip(words) {
                    p.copy_from_slice(&w.to_le_bytes());
                }
            }
            let rest = blocks.into_remainder().chunks_exact_mut(4);
            for (p, &c) in rest.zip(eights.remainder()) {
                p.copy_from_slice(&over_sky_pixel(&encoder, sky, c).to_le_bytes());
            }
        });
}

/// One pixel of [`over_sky`]: `c` over `sky`, packed.
fn over_sky_pixel(encoder: &Encoder, sky: Premul, c: Premul) -> u32 {
    let k = 1.0 - c.a.clamp(0.0, 1.0);
    encoder.pack(c.r + sky.r * k, c.g + sky.g * k, c.b + sky.b * k, 1.0)
}

#[cfg(test)]
mod tests;
