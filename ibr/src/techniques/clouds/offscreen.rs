//! Off-screen particles at half resolution (Cantlay, "High-Speed, Off-Screen Particles",
//! GPU Gems 3 ch. 23): a cloud drawn as its particles around the eye blends several
//! screens of fragments; drawn into a half-size target instead, a quarter of them, then
//! composited over the frame with one bilinear pass.
//!
//! Per frame ([`Offscreen::draw`]), after the frame's main pass:
//! 1. the frame's depth, read into a plain buffer, is reduced 2 x 2 to the half-size
//!    target's depth, keeping the *nearest* of each four (so a puff behind any of them is
//!    hidden: no cloud drawn over nearer geometry's edges, at the price of a thinner cloud
//!    within a pixel or two of them);
//! 2. the particles' draws are rendered into the half-size target, cleared to transparent,
//!    depth-tested (not written: they are blended) against that depth, premultiplied;
//! 3. the result is composited "over" the frame: each pixel blends the four nearest
//!    half-size pixels bilinearly, leaving out those whose four pixels all lie behind it
//!    (depth-aware, so a near edge does not pull in cloud drawn beyond it) and renormalising
//!    the rest.
//!
//! Whether it pays ([`Offscreen::worth`]) is decided per frame from the particles' quads'
//! screen area: only when they would blend more than [`MIN_SCREENS`] screens and
//! [`MIN_FRAGMENTS`] fragments, and on a frame of even sides (the half-size pixels then
//! cover two by two of the frame's exactly). Below that the draws stay in the frame.
//! Every step is a pure function of the pixel or the engine's deterministic raster: the
//! same pixels at any thread count. Buffers are kept and reused frame to frame.

use engine::color::unpack;
use engine::{
    run_pass, Camera, Draw, Fragment, FrameOptions, FrameStats, Lighting, PassMode, PixelPass,
    PixelRect, Premul, Renderer, Rgba, Target,
};

/// Fewest screens of the particles' quads (estimated, [`Offscreen::estimate`]) for which
/// they are drawn off-screen: the composite reads and blends one screen of taps.
pub const MIN_SCREENS: f64 = 1.0;

/// Fewest estimated fragments for which the particles are drawn off-screen: below this the
/// full-size particles keep their edges exact. At the showcase test's 240 x 136 it is 12
/// screens, twice the most the tour's clouds blend at any size (6.2 on frame 108): that
/// size always draws the particles in the frame (BENCHMARKS.md, session 21).
pub const MIN_FRAGMENTS: f64 = 400_000.0;

/// The off-screen target and its scratch memory, kept frame to frame.
#[derive(Debug)]
pub struct Offscreen {
    renderer: Renderer,
    half: Target,
    /// The frame's reversed depth, row-major.
    depth: Vec<f32>,
    /// The half-size target's colours (premultiplied linear) and depths, row-major.
    color: Vec<Premul>,
    near: Vec<f32>,
    row_c: Vec<u32>,
    row_d: Vec<f32>,
}

impl Default for Offscreen {
    fn default() -> Self {
        Offscreen {
            renderer: Renderer::new(),
            half: Target::new(0, 0),
            depth: Vec::new(),
            color: Vec::new(),
            near: Vec::new(),
            row_c: Vec::new(),
            row_d: Vec::new(),
        }
    }
}

impl Offscreen {
    /// An empty off-screen target (sized at the first [`Offscreen::draw`]).
    pub fn new() -> Self {
        Self::default()
    }

    /// The screen area, in pixels of a `width` x `height` frame, of the quads of `draws`
    /// (meshes of four vertices a quad, as the clouds' batches and fog are): each quad's
    /// projected bounding box clipped to the frame, a whole frame for a quad reaching
    /// behind the eye. An upper bound of the fragments they blend.
    pub fn estimate(draws: &[Draw<'_>], camera: &Camera, width: u32, height: u32) -> f64 {
        let clip = camera.clip_from_world();
        let (w, h) = (width as f64, height as f64);
        let mut sum = 0.0;
        for d in draws {
            let m = clip * d.transform;
            for quad in d.mesh.positions.chunks_exact(4) {
                let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
                let mut behind = false;
                for p in quad {
                    let c = m * p.extend(1.0);
                    if c.w <= 1e-6 || !c.is_finite() {
                        behind = true;
                        break;
                    }
                    let (x, y) = ((c.x / c.w) as f64, (c.y / c.w) as f64);
                    lo = [lo[0].min(x), lo[1].min(y)];
                    hi = [hi[0].max(x), hi[1].max(y)];
                }
                sum += if behind {
                    w * h
                } else {
                    let sx = (hi[0].min(1.0) - lo[0].max(-1.0)).max(0.0) * 0.5 * w;
                    let sy = (hi[1].min(1.0) - lo[1].max(-1.0)).max(0.0) * 0.5 * h;
                    sx * sy
                };
            }
        }
        sum
    }

    /// Whether `draws` are worth drawing off-screen in a `width` x `height` frame (module
    /// docs).
    pub fn worth(draws: &[Draw<'_>], camera: &Camera, width: u32, height: u32) -> bool {
        if width % 2 != 0 || height % 2 != 0 || width < 2 || height < 2 {
            return false;
        }
        let screen = width as f64 * height as f64;
        let est = Self::estimate(draws, camera, width, height);
        est > MIN_FRAGMENTS && est > MIN_SCREENS * screen
    }

    /// Renders `draws` at half size and composites them over `frame` (module docs). The
    /// half render's counters and the composite's (its pixels given a fragment counted as
    /// blended); nothing for a frame of odd or zero sides.
    pub fn draw<'a>(
        &mut self,
        draws: impl IntoIterator<Item = Draw<'a>>,
        camera: &Camera,
        lighting: &Lighting,
        frame: &mut Target,
    ) -> FrameStats {
        let (w, h) = (frame.width(), frame.height());
        if w % 2 != 0 || h % 2 != 0 || w < 2 || h < 2 {
            return FrameStats::default();
        }
        let (hw, hh) = (w / 2, h / 2);
        self.depth.clear();
        for y in 0..h {
            frame.read_row(y, &mut self.row_c, &mut self.row_d);
            self.depth.extend_from_slice(&self.row_d);
        }
        if self.half.width() != hw || self.half.height() != hh {
            self.half = Target::with_encoding(hw, hh, frame.encoding());
        }
        self.half.set_encoding(frame.encoding());
        self.half.clear(Rgba::TRANSPARENT);
        let down = Nearest {
            depth: &self.depth,
            width: w as usize,
        };
        let write_depth = PassMode {
            depth_test: false,
            depth_write: true,
            blend: false,
        };
        run_pass(&mut self.half, PixelRect::full(hw, hh), &down, write_depth);
        let opts = FrameOptions {
            clear: None,
            ..FrameOptions::default()
        };
        let mut stats = self
            .renderer
            .render(draws, camera, lighting, &mut self.half, &opts);
        let encoding = self.half.encoding();
        self.color.clear();
        self.near.clear();
        for y in 0..hh {
            self.half.read_row(y, &mut self.row_c, &mut self.row_d);
            self.color
                .extend(self.row_c.iter().map(|&c| unpack(encoding, c)));
            self.near.extend_from_slice(&self.row_d);
        }
        let up = Composite {
            color: &self.color,
            near: &self.near,
            depth: &self.depth,
            half: (hw as usize, hh as usize),
            width: w as usize,
        };
        let over = PassMode {
            depth_test: false,
            depth_write: false,
            blend: true,
        };
        let mut pass = run_pass(frame, PixelRect::full(w, h), &up, over);
        pass.fragments_shaded_blended = pass.fragments_shaded;
        stats += pass;
        stats
    }
}

/// Step 1: each half-size pixel's depth, the nearest (largest reversed) of its four.
struct Nearest<'a> {
    depth: &'a [f32],
    width: usize,
}

impl PixelPass for Nearest<'_> {
    fn shade_span(&self, x0: u32, y: u32, out: &mut [Option<Fragment>]) {
        let (r0, r1) = (
            2 * y as usize * self.width,
            (2 * y as usize + 1) * self.width,
        );
        for (i, o) in out.iter_mut().enumerate() {
            let x = 2 * (x0 as usize + i);
            let d = self.depth[r0 + x]
                .max(self.depth[r0 + x + 1])
                .max(self.depth[r1 + x])
                .max(self.depth[r1 + x + 1]);
            if d > 0.0 {
                *o = Some(Fragment {
                    color: Premul::TRANSPARENT,
                    depth: d,
                });
            }
        }
    }
}

/// Step 3: the half-size image over the frame, bilinear and depth-aware.
struct Composite<'a> {
    color: &'a [Premul],
    near: &'a [f32],
    depth: &'a [f32],
    half: (usize, usize),
    width: usize,
}

/// The two half-size pixels either side of full-size pixel `x` and the second's weight.
#[inline]
fn taps(x: usize, n: usize) -> (usize, usize, f32) {
    // Full-size pixel centre x + 0.5 is half-size x / 2 + 0.25, i.e. 0.25 past a centre
    // (x odd) or 0.25 before one (x even).
    let (i, f) = if x % 2 == 1 {
        (x / 2, 0.25)
    } else {
        ((x / 2).saturating_sub(1), if x == 0 { 0.0 } else { 0.75 })
    };
    (i, (i + 1).min(n - 1), f)
}

impl PixelPass for Composite<'_> {
    fn shade_span(&self, x0: u32, y: u32, out: &mut [Option<Fragment>]) {
        let (hw, hh) = self.half;
        let (y0, y1, fy) = taps(y as usize, hh);
        for (i, o) in out.iter_mut().enumerate() {
            let x = x0 as usize + i;
            let (xa, xb, fx) = taps(x, hw);
            let here = self.depth[y as usize * self.width + x];
            let four = [
                (y0 * hw + xa, (1.0 - fx) * (1.0 - fy)),
                (y0 * hw + xb, fx * (1.0 - fy)),
                (y1 * hw + xa, (1.0 - fx) * fy),
                (y1 * hw + xb, fx * fy),
            ];
            let (mut c, mut total) = (Premul::TRANSPARENT, 0.0);
            for (at, wgt) in four {
                // Left out: a tap whose four pixels all lie behind this one.
                if wgt <= 0.0 || here > self.near[at] {
                    continue;
                }
                let t = self.color[at];
                c = Premul {
                    r: c.r + t.r * wgt,
                    g: c.g + t.g * wgt,
                    b: c.b + t.b * wgt,
                    a: c.a + t.a * wgt,
                };
                total += wgt;
            }
            if total <= 0.0 || c.a <= 0.0 {
                continue;
            }
            let k = 1.0 / total;
            *o = Some(Fragment {
                color: Premul {
                    r: c.r * k,
                    g: c.g * k,
                    b: c.b * k,
                    a: (c.a * k).min(1.0),
                },
                depth: 0.0,
            });
        }
    }
}

#[cfg(test)]
mod tests;
