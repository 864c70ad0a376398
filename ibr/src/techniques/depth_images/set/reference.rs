//! Capturing a depth image set's references: each object alone from the eye, as a depth
//! image or an LDI by depth peeling, prepared for the warp, with the gradients its error
//! predictions read.

use super::{Config, Job, Reference};
use crate::core::Capturer;
use crate::core::DepthImage;
use crate::core::Subject;
use crate::warp::predict::depth_range;
use crate::warp::{Prepared, ENCODING};
use engine::color::Encoder;
use engine::Lighting;

/// Captures `job`'s subject (prepared for the capture camera) alone: a depth image, or an
/// LDI by depth peeling; returns the prepared reference and the renders it took.
pub(super) fn capture<S: Subject>(
    job: &Job,
    subject: &mut S,
    capturer: &mut Capturer,
    lighting: &Lighting,
    cfg: &Config,
) -> (Reference, u64) {
    let (camera, side, edge) = (job.camera, job.side, cfg.options.edge);
    subject.prepare(&camera, side);
    let subject = &*subject;
    let draws = || {
        let mut out = Vec::new();
        subject.draws(&mut out);
        out
    };
    let (front, prepared, renders) = if cfg.layers <= 1 {
        let mut image = DepthImage::new(0, 0, camera);
        capturer.capture(draws(), &camera, lighting, side, side, &mut image);
        let prepared = Prepared::from_image(&image, edge);
        (image, prepared, 1)
    } else {
        let ldi = capturer.capture_layers(draws, &camera, lighting, side, side, cfg.layers);
        // Peeling stops after the first empty layer (rendered too) or at the most layers.
        let renders = (ldi.depth_complexity().max(1) + 1).min(cfg.layers) as u64;
        (ldi.layer(0), Prepared::from_ldi(&ldi, edge), renders)
    };
    let (gradient, edge_gradient) = gradients(&front, edge);
    let reference = Reference {
        prepared,
        eye: job.eye,
        bounds: job.bounds,
        version: job.version,
        side,
        range: depth_range(&front),
        gradient,
        edge_gradient,
    };
    (reference, renders)
}

/// The mean absolute difference between horizontally and vertically neighbouring pixels
/// of `image` over RGB of their stored 8-bit values (levels per texel, as the impostors
/// measure theirs), and the same counting only pairs across a depth edge or a silhouette
/// (depths apart by more than a relative `edge`, or one empty).
fn gradients(image: &DepthImage, edge: f32) -> (f32, f32) {
    let (w, h) = (image.width() as usize, image.height() as usize);
    let enc = Encoder::new(ENCODING);
    let px: Vec<[u8; 4]> = image
        .color
        .iter()
        .map(|c| enc.pack(c.r, c.g, c.b, c.a).to_le_bytes())
        .collect();
    let z = &image.depth;
    let split = |a: usize, b: usize| match (z[a].is_finite(), z[b].is_finite()) {
        (true, true) => (z[a] - z[b]).abs() > edge * z[a].min(z[b]),
        (fa, fb) => fa != fb,
    };
    let (mut sum, mut at_edges, mut n) = (0u64, 0u64, 0u64);
    let mut pair = |a: usize, b: usize| {
        let d: u64 = (0..3).map(|k| u64::from(px[a][k].abs_diff(px[b][k]))).sum();
        sum += d;
        if split(a, b) {
            at_edges += d;
        }
        n += 3;
    };
    for y in 0..h {
        for x in 0..w {
            let a = y * w + x;
            if x + 1 < w {
                pair(a, a + 1);
            }
            if y + 1 < h {
                pair(a, a + w);
            }
        }
    }
    let n = n.max(1) as f32;
    (sum as f32 / n, at_edges as f32 / n)
}
