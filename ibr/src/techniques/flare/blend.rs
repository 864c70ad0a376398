//! The flare's sprites blended straight into a finished frame: an image pass over the pixels
//! each sprite's shape can reach (a disc, or a ring for the halo and ring shapes), instead of
//! a second render pass that loads and resolves every tile of the target.
//!
//! Each pixel adds `tint.rgb * tint.a * visibility * alpha` of every sprite over it, `alpha`
//! sampled from the flare [`atlas`](super::atlas) as the renderer would sample it for the
//! sprite's quad (bilinear on the full-size level where the sprite magnifies its cell,
//! trilinear through the mip chain where it shrinks it), then stores the sum added to what
//! is there; pixels every sprite leaves at zero are not touched.

use super::{region, FlareElement, FlareShape, ATLAS_COLS, CELL_PX, GUTTER};
use crate::core::UvRect;
use engine::{
    run_pass, Filter, Fragment, FrameStats, PassMode, PixelPass, PixelRect, Premul, Sampler,
    Target, Texture, Wrap,
};
use glam::Vec2;

/// Where one shape's alpha is not zero, in units of its sprite's half side: between
/// `inner` and `outer` from the centre, widened by the bilinear footprint.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reach {
    /// No pixel nearer the centre than this has alpha (0 for filled shapes).
    pub inner: f32,
    /// No pixel farther than this has alpha.
    pub outer: f32,
}

/// The atlas's full-size level as alphas, and each shape's [`Reach`], read from it once.
#[derive(Clone, Debug, PartialEq)]
pub struct AtlasAlpha {
    width: u32,
    height: u32,
    alpha: Vec<f32>,
    reach: [Reach; FlareShape::ALL.len()],
}

impl AtlasAlpha {
    /// Reads `atlas` (built by [`super::atlas`] with cells of [`CELL_PX`]).
    pub fn new(atlas: &Texture) -> Self {
        let level = &atlas.levels()[0];
        let (width, height) = (level.width, level.height);
        let alpha: Vec<f32> = level
            .texels
            .iter()
            .map(|&t| (t >> 24) as f32 / 255.0)
            .collect();
        let cell = width / ATLAS_COLS;
        let half = (cell - 2 * GUTTER) as f32 * 0.5;
        // A bilinear tap reaches texels up to a texel's diagonal away.
        let slack = std::f32::consts::SQRT_2 / half;
        let reach = FlareShape::ALL.map(|shape| {
            let (cx, cy) = (
                shape.index() % ATLAS_COLS * cell,
                shape.index() / ATLAS_COLS * cell,
            );
            let (mut inner, mut outer) = (f32::INFINITY, 0.0f32);
            for y in 0..cell {
                for x in 0..cell {
                    if alpha[((cy + y) * width + cx + x) as usize] > 0.0 {
                        let p = (Vec2::new(x as f32, y as f32) + 0.5 - cell as f32 * 0.5) / half;
                        inner = inner.min(p.length());
                        outer = outer.max(p.length());
                    }
                }
            }
            if outer == 0.0 {
                return Reach {
                    inner: 0.0,
                    outer: 0.0,
                };
            }
            Reach {
                inner: (inner - slack).max(0.0),
                outer: outer + slack,
            }
        });
        AtlasAlpha {
            width,
            height,
            alpha,
            reach,
        }
    }

    /// Where `shape`'s alpha is not zero.
    pub fn reach(&self, shape: FlareShape) -> Reach {
        self.reach[shape.index() as usize]
    }

    /// The two rows (their first texels) a bilinear lookup at `v` reads, and the lower
    /// one's weight: the same for a whole row of pixels of a sprite.
    #[inline]
    fn rows(&self, v: f32) -> (usize, usize, f32) {
        let fy = v * self.height as f32 - 0.5;
        let y0 = fy.floor();
        let clamp = |i: f32| (i.max(0.0) as usize).min(self.height as usize - 1);
        let w = self.width as usize;
        (clamp(y0) * w, clamp(y0 + 1.0) * w, fy - y0)
    }

    /// The full-size level's bilinear alpha at `u` on `rows` ([`AtlasAlpha::rows`]),
    /// clamped at the edges: the texture's own bilinear filter, texel for texel.
    #[inline]
    fn along(&self, (ya, yb, ty): (usize, usize, f32), u: f32) -> f32 {
        let fx = u * self.width as f32 - 0.5;
        let x0 = fx.floor();
        let tx = fx - x0;
        let clamp = |i: f32| (i.max(0.0) as usize).min(self.width as usize - 1);
        let (xa, xb) = (clamp(x0), clamp(x0 + 1.0));
        let a = &self.alpha;
        let top = a[ya + xa] + (a[ya + xb] - a[ya + xa]) * tx;
        let bottom = a[yb + xa] + (a[yb + xb] - a[yb + xa]) * tx;
        top + (bottom - top) * ty
    }
}

/// One sprite as placed on the screen for a frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placed {
    /// Centre, pixels.
    pub centre: Vec2,
    /// Half the side, pixels.
    pub half: f32,
    /// Linear colour added at alpha 1: `tint.rgb * tint.a * visibility`.
    pub add: [f32; 3],
    /// Its atlas cell minus the gutter.
    pub region: UvRect,
    /// Where its alpha is not zero.
    pub reach: Reach,
    /// Texels of its cell per pixel, as log2 (above 0: the cell is shrunk).
    pub lod: f32,
}

impl Placed {
    /// `e` placed at `centre`, `half` pixels across each way, at `visibility`.
    pub fn new(
        e: &FlareElement,
        centre: Vec2,
        half: f32,
        visibility: f32,
        alpha: &AtlasAlpha,
    ) -> Self {
        let k = e.tint.a * visibility;
        let texels = (CELL_PX - 2 * GUTTER) as f32;
        let shrunk = (texels / (2.0 * half)).log2();
        let reach = if shrunk > 0.0 {
            // Coarser levels spread every shape over its whole square.
            Reach {
                inner: 0.0,
                outer: std::f32::consts::SQRT_2,
            }
        } else {
            alpha.reach(e.shape)
        };
        Placed {
            centre,
            half,
            add: [e.tint.r * k, e.tint.g * k, e.tint.b * k],
            region: region(e.shape, CELL_PX),
            reach,
            lod: shrunk,
        }
    }

    /// The pixels `[lo, hi)` of row `y` (centres `+ 0.5`) nearer the centre than `radius`
    /// half sides, clipped to the sprite's square.
    fn row(&self, y: u32, radius: f32) -> Option<(i64, i64)> {
        let dy = (y as f32 + 0.5 - self.centre.y) / self.half;
        let r = radius.min(std::f32::consts::SQRT_2);
        let across = r * r - dy * dy;
        if across <= 0.0 || dy.abs() >= 1.0 {
            return None;
        }
        let dx = across.sqrt().min(1.0) * self.half;
        // Pixel centres x + 0.5 with |x + 0.5 - c| < dx.
        let lo = (self.centre.x - dx - 0.5).ceil() as i64;
        let hi = (self.centre.x + dx - 0.5).floor() as i64 + 1;
        (lo < hi).then_some((lo, hi))
    }

    /// The pixels of a `width` x `height` image within its reach: what [`blend`] looks at
    /// for it.
    pub fn reach_pixels(&self, width: u32, height: u32) -> u64 {
        let rows = self.rect(width, height);
        (rows.y0..rows.y1)
            .map(|y| {
                let Some((lo, hi)) = self.row(y, self.reach.outer) else {
                    return 0;
                };
                let inside = |(a, b): (i64, i64)| (b.min(width as i64) - a.max(0)).max(0) as u64;
                let hole = (self.reach.inner > 0.0)
                    .then(|| self.row(y, self.reach.inner))
                    .flatten()
                    .map_or(0, inside);
                inside((lo, hi)) - hole
            })
            .sum()
    }

    /// The pixel rectangle of its square, clipped to `width` x `height`.
    pub fn rect(&self, width: u32, height: u32) -> PixelRect {
        let clip = |x: f32, n: u32| x.clamp(0.0, n as f32) as u32;
        let (c, h) = (self.centre, self.half * self.reach.outer.min(1.0));
        PixelRect {
            x0: clip((c.x - h).floor(), width),
            y0: clip((c.y - h).floor(), height),
            x1: clip((c.x + h).ceil() + 1.0, width),
            y1: clip((c.y + h).ceil() + 1.0, height),
        }
    }
}

/// The pass over a frame's placed sprites.
struct Sprites<'a> {
    placed: &'a [Placed],
    alpha: &'a AtlasAlpha,
    atlas: &'a Texture,
}

impl PixelPass for Sprites<'_> {
    fn shade_span(&self, x0: u32, y: u32, out: &mut [Option<Fragment>]) {
        let mut sum = [[0.0f32; 3]; engine::target::TILE];
        let span = (x0 as i64, x0 as i64 + out.len() as i64);
        let sampler = Sampler {
            wrap_u: Wrap::Clamp,
            wrap_v: Wrap::Clamp,
            filter: Filter::Trilinear,
        };
        let mut any = false;
        for s in self.placed {
            let Some((lo, hi)) = s.row(y, s.reach.outer) else {
                continue;
            };
            let hole = (s.reach.inner > 0.0)
                .then(|| s.row(y, s.reach.inner))
                .flatten()
                .unwrap_or((hi, hi));
            let size = s.region.max - s.region.min;
            let v =
                s.region.min.y + (y as f32 + 0.5 - (s.centre.y - s.half)) / (2.0 * s.half) * size.y;
            let du = size.x / (2.0 * s.half);
            let u0 = s.region.min.x + (0.5 - (s.centre.x - s.half)) * du;
            let rows = self.alpha.rows(v);
            for (a, b) in [(lo, hole.0), (hole.1, hi)] {
                let a = a.clamp(span.0, span.1);
                let b = b.clamp(a, span.1);
                any |= a < b;
                let sums = &mut sum[(a - span.0) as usize..(b - span.0) as usize];
                let at = |x: i64| u0 + x as f32 * du;
                if s.lod > 0.0 {
                    for (acc, x) in sums.iter_mut().zip(a..b) {
                        let alpha = self.atlas.sample(&sampler, at(x), v, s.lod).a;
                        add(acc, s.add, alpha);
                    }
                } else {
                    for (acc, x) in sums.iter_mut().zip(a..b) {
                        add(acc, s.add, self.alpha.along(rows, at(x)));
                    }
                }
            }
        }
        if !any {
            return;
        }
        for (o, [r, g, b]) in out.iter_mut().zip(sum) {
            if r > 0.0 || g > 0.0 || b > 0.0 {
                // Alpha 0 over what is there: the colour is added, the target's alpha kept.
                *o = Some(Fragment {
                    color: Premul { r, g, b, a: 0.0 },
                    depth: 0.0,
                });
            }
        }
    }
}

/// `acc += add * alpha`.
#[inline]
fn add(acc: &mut [f32; 3], add: [f32; 3], alpha: f32) {
    for c in 0..3 {
        acc[c] += add[c] * alpha;
    }
}

/// Adds `placed` sprites to `target` (see the module docs). Counts the pixels looked at
/// (`fragments_tested`, the rectangle round the sprites' reach) and the pixels given light
/// (`fragments_shaded`, `fragments_written`).
pub(super) fn blend(
    placed: &[Placed],
    alpha: &AtlasAlpha,
    atlas: &Texture,
    target: &mut Target,
) -> FrameStats {
    let (w, h) = (target.width(), target.height());
    let Some(rect) = placed
        .iter()
        .map(|p| p.rect(w, h))
        .reduce(|a, b| PixelRect {
            x0: a.x0.min(b.x0),
            y0: a.y0.min(b.y0),
            x1: a.x1.max(b.x1),
            y1: a.y1.max(b.y1),
        })
    else {
        return FrameStats::default();
    };
    let mode = PassMode {
        depth_test: false,
        depth_write: false,
        blend: true,
    };
    run_pass(
        target,
        rect,
        &Sprites {
            placed,
            alpha,
            atlas,
        },
        mode,
    )
}
