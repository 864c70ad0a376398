//! Reduced-resolution blended draws (after Cantlay, "High-Speed, Off-Screen Particles",
//! GPU Gems 3, ch. 23): draws whose material is [`Material::low_res`](crate::Material)
//! are shaded into a target `scale` times smaller each way and composited over the frame.
//!
//! A frame with such draws runs in three passes over the same target:
//! 1. `first`: opaque and alpha-tested draws, and blended ones that write depth (images
//!    standing in for opaque objects), as one ordinary frame;
//! 2. `low`: the low-resolution draws into the small target, whose depth is the nearest of
//!    the frame's depths under each small pixel (`downsample_depth`: a small pixel with any
//!    occluder in it hides what lies behind that occluder), over transparent black; then
//!    [`composite`]: each full pixel takes the small target's colour, upsampled bilinearly
//!    from the taps whose depth is like its own (a pixel of an occluder does not take the
//!    sky's cloud beside it, nor a sky pixel the occluded block's emptiness, where another
//!    tap is alike), and blends it over itself (`dst = src + dst (1 - src.a)`: the over
//!    operator is associative, so the small target's one layer stands for all its draws);
//! 3. `late`: the other blended draws (smoke, lasers, glass), over the result.
//!
//! So the passes' order replaces depth order among blended draws: a low-resolution draw is
//! drawn after every depth-writing blended draw of the first pass (an impostor's image: a
//! cloud behind it shows over the image's fringe, where its alpha is under the depth it
//! writes from) and before every blended draw of the third, whatever their depths (a laser
//! behind a cloud shows over it). Only alpha-blended draws that write no depth take the
//! small target (additive ones and those writing depth stay in their full-resolution pass).
//! Besides the upsampling, the composite differs from shading the same draws at full
//! resolution by the small target's rounding (the frame's encoding, 8 bits a channel) and by
//! the small target's depth being the nearest under each of its pixels: a fragment is tested,
//! and a soft particle fades, against that nearest surface, so beside an occluder's outline
//! a band of one small pixel loses what lies behind the occluder's depth (the composite
//! then takes the colour from a tap beyond, where one is alike in depth).
//!
//! The pixels are the same at any thread count (every pass is), and a frame without such
//! draws, or with a scale of 1, is the single ordinary pass.

use super::Renderer;
use crate::camera::Camera;
use crate::light::Lighting;
use crate::material::{BlendMode, Material};
use crate::renderer::FrameOptions;
use crate::scene::Draw;
use crate::stats::{DrawCost, FrameStats};
use crate::target::{offset_in_tile, Target, TILE, TILE_PIXELS};
use rayon::prelude::*;
use std::time::Instant;

/// Two stored depths are alike when they differ by at most this share of the larger. The
/// stored depth of a perspective camera is about its near distance over the view depth
/// while the far plane lies well beyond (view depths within a third of each other are
/// alike); toward the far plane, where it falls to 0, and for orthographic cameras (linear
/// depth), the test is stricter, and more pixels take `composite`'s fallback.
const ALIKE: f32 = 0.25;

/// The scratch memory of the low-resolution pass, kept frame to frame.
#[derive(Debug, Default)]
pub(super) struct LowRes {
    /// The small target.
    small: Target,
    /// The small target as the composite reads it.
    read: composite::Small,
    /// The frame's draws, and which pass each goes to.
    draws: Vec<Draw<'static>>,
    passes: [Vec<u32>; 3],
    /// Each draw's cost over the three passes, in submission order.
    costs: Vec<DrawCost>,
    /// The small pixels' full-resolution spans (columns, rows), for the depth.
    spans: [Vec<(u32, u32)>; 2],
}

/// The pass a draw goes to: 0 `first`, 1 `low`, 2 `late` (module docs).
fn pass_of(m: &Material) -> usize {
    match (m.is_blended(), m.blend_depth.is_some()) {
        (true, false) if m.low_res && m.blend == BlendMode::Alpha => 1,
        (true, false) => 2,
        _ => 0,
    }
}

/// An emptied draw list with another lifetime, keeping its allocation.
fn recycle<'b>(mut v: Vec<Draw<'_>>) -> Vec<Draw<'b>> {
    v.clear();
    v.into_iter().map(|_| unreachable!("empty")).collect()
}

impl Renderer {
    /// Shades the blended draws whose material is [`Material::low_res`] at `1 / scale` of
    /// the target's resolution each way and composites them over the frame (see the
    /// `lowres` module: a frame with such draws renders in three passes); 1 (the default)
    /// or 0 shades them as every other draw. Counted in the frame's stats like any draw
    /// (their fragments are the small target's); [`Renderer::stage_times`] sums the three
    /// passes', the depth reduction and the composite counted in `tiles`.
    pub fn set_low_res_scale(&mut self, scale: u32) {
        self.low_res_scale = scale;
    }

    /// The scale set with [`Renderer::set_low_res_scale`] (1 when off).
    pub fn low_res_scale(&self) -> u32 {
        self.low_res_scale.max(1)
    }

    /// [`Renderer::render`] with a low-resolution scale above 1 (module docs).
    pub(super) fn render_low_res<'a>(
        &mut self,
        draws: impl IntoIterator<Item = Draw<'a>>,
        camera: &Camera,
        lighting: &Lighting,
        target: &mut Target,
        opts: &FrameOptions,
    ) -> FrameStats {
        let mut low = std::mem::take(&mut self.low);
        let mut list: Vec<Draw<'a>> = recycle(std::mem::take(&mut low.draws));
        list.extend(draws);
        low.passes.iter_mut().for_each(Vec::clear);
        for (i, d) in list.iter().enumerate() {
            low.passes[pass_of(d.material)].push(i as u32);
        }
        let stats = if low.passes[1].is_empty() {
            self.frame(list.iter().copied(), camera, lighting, target, opts, None)
        } else {
            self.three_passes(&mut low, &list, camera, lighting, target, opts)
        };
        low.draws = recycle(list);
        self.low = low;
        stats
    }

    fn three_passes(
        &mut self,
        low: &mut LowRes,
        list: &[Draw<'_>],
        camera: &Camera,
        lighting: &Lighting,
        target: &mut Target,
        opts: &FrameOptions,
    ) -> FrameStats {
        let over = FrameOptions {
            clear: None,
            ..*opts
        };
        let scale = self.low_res_scale.max(1);
        let (w, h) = (target.width(), target.height());
        let (sw, sh) = (w.div_ceil(scale), h.div_ceil(scale));
        low.costs.clear();
        low.costs.resize(list.len(), DrawCost::default());
        let mut total = FrameStats::default();
        let mut times = super::StageTimes::default();
        for pass in 0..3 {
            let picked = low.passes[pass].iter().map(|&i| list[i as usize]);
            let stats = match pass {
                0 => self.frame(picked, camera, lighting, target, opts, None),
                1 => {
                    let t0 = Instant::now();
                    if (low.small.width(), low.small.height()) != (sw, sh) {
                        low.small.resize(sw, sh);
                    }
                    low.small.set_encoding(target.encoding());
                    downsample_depth(target, &mut low.small, &mut low.spans);
                    times.tiles += t0.elapsed();
                    let small = &mut low.small;
                    let s = self.frame(picked, camera, lighting, small, &over, None);
                    let t1 = Instant::now();
                    composite::composite(low, target);
                    times.tiles += t1.elapsed();
                    s
                }
                _ => self.frame(picked, camera, lighting, target, &over, None),
            };
            total += stats;
            let t = self.times;
            times.vertex += t.vertex;
            times.front += t.front;
            times.tiles += t.tiles;
            times.raster += t.raster;
            times.resolve += t.resolve;
            for (k, c) in self.costs.iter().enumerate() {
                if let Some(&i) = low.passes[pass].get(k) {
                    low.costs[i as usize] += *c;
                }
            }
        }
        if self.count_costs {
            self.costs.clone_from(&low.costs);
        }
        self.times = times;
        self.last = total;
        total
    }
}

/// The full-resolution span `[a, b)` small pixel `i` of `small` covers out of `full`.
fn span(i: u32, full: u32, small: u32) -> (u32, u32) {
    let small = small.max(1) as u64;
    let a = (i as u64 * full as u64 / small) as u32;
    let b = ((i as u64 + 1) * full as u64).div_ceil(small) as u32;
    (a.min(full), b.min(full).max(a.saturating_add(1).min(full)))
}

/// Sets `small`'s depth to the nearest (largest reversed) depth of `full` under each of its
/// pixels ([`span`]s worked out once a frame into `spans`), and its colour to transparent
/// black.
fn downsample_depth(full: &Target, small: &mut Target, spans: &mut [Vec<(u32, u32)>; 2]) {
    let (w, h) = (full.width(), full.height());
    let (sw, sh) = (small.width(), small.height());
    let [xs, ys] = spans;
    xs.clear();
    xs.extend((0..sw).map(|i| span(i, w, sw)));
    ys.clear();
    ys.extend((0..sh).map(|j| span(j, h, sh)));
    let (xs, ys) = (&xs[..], &ys[..]);
    let tiles_x = small.tiles_x() as usize;
    let (colors, depths) = small.storage_mut();
    colors
        .par_chunks_mut(TILE_PIXELS)
        .zip(depths.par_chunks_mut(TILE_PIXELS))
        .enumerate()
        .with_max_len(1)
        .for_each(|(t, (color, depth))| {
            color.fill(0);
            depth.fill(0.0);
            let (ox, oy) = (t % tiles_x * TILE, t / tiles_x * TILE);
            for y in oy..(oy + TILE).min(sh as usize) {
                let (y0, y1) = ys[y];
                for x in ox..(ox + TILE).min(sw as usize) {
                    let (x0, x1) = xs[x];
                    let mut nearest = 0.0f32;
                    for fy in y0..y1 {
                        for fx in x0..x1 {
                            nearest = nearest.max(full.depth[full.index(fx, fy)]);
                        }
                    }
                    depth[offset_in_tile(x - ox, y - oy)] = nearest;
                }
            }
        });
}

mod composite;
#[cfg(test)]
mod tests;
