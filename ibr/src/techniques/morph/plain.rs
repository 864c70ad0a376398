//! The plain morph, the baseline the view morph is compared with: points moved on straight
//! lines between the two views, without the prewarp.

use super::between;
use crate::core::DepthImage;
use glam::Vec4;

/// The largest side (pixels) of a plain morph's splat: a wider stretch is left open.
const MAX_SPLAT: f32 = 8.0;

/// The morph without the prewarp, for comparison: each pixel of `a` with depth moved on
/// the straight line from where `a` sees its point to where `b` does, a fraction `s` of
/// the way, nearer points painted last; colours from `a` alone. Not shape preserving
/// unless the views are parallel. Each pixel covers its footprint, so no crack opens
/// where the morph stretches the image: the box around the pixel's centre moved, spanning
/// half the way to where its neighbours on the same surface (depths within 5%) move (at
/// most `MAX_SPLAT` (8) pixels a side); across a depth edge, one pixel's step. Unfilled
/// pixels are transparent.
pub fn plain_morph(a: &DepthImage, b: &DepthImage, s: f32) -> DepthImage {
    let (w, h) = (a.width(), a.height());
    let camera = between(&a.camera, &b.camera, s);
    let mut out = DepthImage::new(w, h, camera);
    let to_b = b.camera.gl_view_proj();
    let pixel = |c: Vec4| {
        (
            (c.x / c.w + 1.0) * 0.5 * w as f32,
            (1.0 - c.y / c.w) * 0.5 * h as f32,
        )
    };
    // Where pixel (x, y) of `a` moves, and its depth there; `None` without depth or behind
    // `b`'s eye.
    let moved = |x: u32, y: u32| -> Option<(f32, f32, f32, f32)> {
        let point = a.world_point(x, y)?;
        let (_, z) = a.get(x, y)?;
        let c = to_b * point.extend(1.0);
        if c.w <= 0.0 {
            return None;
        }
        let (bx, by) = pixel(c);
        Some((
            (x as f32 + 0.5) * (1.0 - s) + bx * s,
            (y as f32 + 0.5) * (1.0 - s) + by * s,
            z * (1.0 - s) + c.w * s,
            z,
        ))
    };
    // The step to a neighbour on the same surface, from either side; one pixel otherwise.
    let step = |here: (f32, f32, f32, f32), x: u32, y: u32, dx: i32, dy: i32| -> (f32, f32) {
        let same = |n: Option<(f32, f32, f32, f32)>| {
            n.filter(|n| (n.3 - here.3).abs() <= 0.05 * here.3.min(n.3))
        };
        let at = |k: i32| {
            let (nx, ny) = (x as i32 + k * dx, y as i32 + k * dy);
            (nx >= 0 && ny >= 0 && nx < w as i32 && ny < h as i32)
                .then(|| moved(nx as u32, ny as u32))
                .flatten()
        };
        if let Some(n) = same(at(1)) {
            (n.0 - here.0, n.1 - here.1)
        } else if let Some(n) = same(at(-1)) {
            (here.0 - n.0, here.1 - n.1)
        } else {
            (dx as f32, dy as f32)
        }
    };
    for y in 0..h {
        for x in 0..w {
            let Some(here) = moved(x, y) else {
                continue;
            };
            let color = a.color[(y * w + x) as usize];
            let (ex, ey) = (step(here, x, y, 1, 0), step(here, x, y, 0, 1));
            // Half the steps either way, at least a pixel's box, at most the largest splat.
            let rx = ((ex.0.abs() + ey.0.abs()) * 0.5).clamp(0.5, MAX_SPLAT * 0.5);
            let ry = ((ex.1.abs() + ey.1.abs()) * 0.5).clamp(0.5, MAX_SPLAT * 0.5);
            let (px, py, depth) = (here.0, here.1, here.2);
            if !(px.is_finite() && py.is_finite()) {
                continue;
            }
            // The pixels whose centres lie in the box (the centre's own at least).
            let span = |p: f32, r: f32, n: u32| {
                let lo = (p - r - 0.5).ceil().max(0.0);
                let hi = (p + r - 0.5).floor().min(n as f32 - 1.0);
                let own = p.floor();
                (lo.min(own).max(0.0) as i64, hi.max(own) as i64)
            };
            let ((x0, x1), (y0, y1)) = (span(px, rx, w), span(py, ry, h));
            for ty in y0.max(0)..=y1.min(h as i64 - 1) {
                for tx in x0.max(0)..=x1.min(w as i64 - 1) {
                    let (tx, ty) = (tx as u32, ty as u32);
                    if out.get(tx, ty).is_some_and(|(_, d)| d <= depth) {
                        continue;
                    }
                    out.set(tx, ty, color, depth);
                }
            }
        }
    }
    out
}
