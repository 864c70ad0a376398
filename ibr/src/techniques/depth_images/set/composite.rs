//! A warped reference made ready for the frame: holes filled only inside what the
//! reference saw, the debug tint, and the image pass over the object's rectangle.

use super::Reference;
use crate::core::unproject;
use crate::warp::holes::{Fill, Filler};
use crate::warp::ImagePass;
use crate::warp::{Warped, ENCODING, HOLE};
use engine::color::{unpack, Encoder};
use engine::{Camera, Encoding, PackedFragment, PackedPass, Rgba};

/// Fills the holes of a warped rectangle from the background side, keeping a fill only
/// where the reference saw something in front of it (a disocclusion: the hole's surface,
/// at the depth it was filled with, projects into the reference behind a nearer sample)
/// or where the hole is a crack between samples of one surface; the rest is the object's
/// surroundings (or parts the reference never saw) and stays empty.
pub(super) fn fill_inside(
    out: &mut Warped,
    filler: &mut Filler,
    holes: &mut Vec<bool>,
    r: &Reference,
    edge: f32,
) {
    holes.clear();
    holes.extend(out.disparity.iter().map(|&d| d < 0.0));
    if !holes.iter().any(|&h| h) {
        return;
    }
    filler.fill(out, Fill::Background, edge);
    let (w, h) = (out.width() as usize, out.height() as usize);
    let camera = out.camera;
    let similar = |a: f32, b: f32| (a - b).abs() <= edge * a.min(b);
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            if !holes[i] || out.disparity[i] < 0.0 {
                continue;
            }
            // Samples on two opposite sides, of one surface, as they were before the fill.
            let sample = |j: usize| (!holes[j]).then_some(out.disparity[j]);
            let across =
                |a: Option<usize>, b: Option<usize>| match (a.and_then(sample), b.and_then(sample))
                {
                    (Some(p), Some(q)) => similar(p, q),
                    _ => false,
                };
            let crack = across(
                x.checked_sub(1).map(|x| y * w + x),
                (x + 1 < w).then_some(i + 1),
            ) || across(i.checked_sub(w), (y + 1 < h).then_some(i + w));
            let d = out.disparity[i];
            let keep = crack || occluded(r, &camera, (x, y), 1.0 / d, (w, h), edge);
            if !keep {
                out.color[i] = 0;
                out.disparity[i] = HOLE;
            }
        }
    }
}

/// Whether the point seen at pixel `(x, y)` of a `size` image by `camera` at axial
/// `depth` lies behind a sample of the reference nearer by more than `edge` (relative).
fn occluded(
    r: &Reference,
    camera: &Camera,
    (x, y): (usize, usize),
    depth: f32,
    (w, h): (usize, usize),
    edge: f32,
) -> bool {
    let (sx, sy) = (x as f32 + 0.5, y as f32 + 0.5);
    let Some(world) = unproject(camera, sx, sy, depth, w as u32, h as u32) else {
        return false;
    };
    let from = r.prepared.camera();
    let c = from.clip_from_world() * world.extend(1.0);
    if c.w <= 1e-6 {
        return false;
    }
    let (rw, rh) = r.prepared.size();
    let u = (c.x / c.w + 1.0) * 0.5 * rw as f32;
    let v = (1.0 - c.y / c.w) * 0.5 * rh as f32;
    if u.is_nan() || v.is_nan() || u < 0.0 || v < 0.0 || u >= rw as f32 || v >= rh as f32 {
        return false;
    }
    let k = v as usize * rw as usize + u as usize;
    let p = &r.prepared;
    // The nearest sample of the pixel: a depth image's only one, an LDI's last (painted
    // back to front).
    let nearest = if p.first.is_empty() {
        p.disparity.get(k).copied()
    } else {
        match (p.first.get(k), p.first.get(k + 1)) {
            (Some(&a), Some(&b)) if b > a => Some(p.disparity[b as usize - 1]),
            _ => None,
        }
    };
    let z = -from.view.transform_point3(world).z;
    nearest.is_some_and(|d| d >= 0.0 && z > 0.0 && d * z > 1.0 + edge)
}

/// Multiplies every sample of `out` by `t` (premultiplied: colour by its colour and alpha,
/// alpha by its alpha).
pub(super) fn tint(out: &mut Warped, t: Rgba) {
    let enc = Encoder::new(ENCODING);
    for (c, &d) in out.color.iter_mut().zip(&out.disparity) {
        if d >= 0.0 {
            let p = unpack(ENCODING, *c);
            let a = t.a;
            *c = enc.pack(p.r * t.r * a, p.g * t.g * a, p.b * t.b * a, p.a * a);
        }
    }
}

/// An image pass over a crop of the frame: pixel `(x, y)` of the frame is pixel
/// `(x - x0, y - y0)` of the crop (as the light-field objects' own).
pub(super) struct Cropped<'a> {
    pub(super) pass: ImagePass<'a>,
    pub(super) x0: u32,
    pub(super) y0: u32,
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
