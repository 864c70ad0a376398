//! Which holes the new view should see: free-space carving by the references.
//!
//! A reference pixel says what lies along its ray: empty space up to its sample, its
//! sample's surface, then the unknown behind it (or, for an empty pixel, empty space all
//! the way). A hole of the warped view is **seen** (a pixel the new view should see but no
//! sample covers, to be filled) when its ray, inside the box of everything the references
//! saw ([`sample_bounds`]), passes through a point that some reference has on or behind
//! a surface (within the edge tolerance, or farther) and that no reference has in empty
//! space: the ray enters a surface's footprint or its shadow, where something may stand
//! (a crack in a surface, a disocclusion behind an edge), or meets sky a reference saw. A
//! hole whose ray stays in space the references saw empty, or that no reference saw at
//! all (outside every reference's frame or the box), is **unseen**: it stays empty (alpha
//! 0, infinite depth) and is counted apart, so fills never reach past the warped
//! surfaces' footprint into the background beyond the references' coverage.
//!
//! Each hole's ray is marched from where it enters the box to where it leaves, in steps
//! of about one reference pixel (the segment's longest projection into a reference, at
//! most [`MAX_STEPS`] steps), each point looked up at the nearest reference pixel; for a
//! layered reference the nearest layer decides. Rows run on the thread pool.

use super::super::prepared::Prepared;
use super::super::warped::{Warped, HOLE};
use glam::{Mat4, Vec3, Vec4};
use rayon::prelude::*;

/// The most points marched along one hole's ray.
pub const MAX_STEPS: usize = 1024;

/// A world-space box: least and greatest corner.
pub type Bounds = [Vec3; 2];

/// The box around a reference's finite samples (sky and empty pixels left out); `None`
/// when it has none or its camera is not perspective.
pub fn sample_bounds(p: &Prepared) -> Option<Bounds> {
    let camera = p.camera();
    if !camera.projection.is_perspective() {
        return None;
    }
    let (w, h) = p.size();
    let inv_proj = camera.projection.reversed_z_matrix().inverse();
    let inv_view = camera.view.inverse();
    let single = p.single();
    (0..h)
        .into_par_iter()
        .filter_map(|y| {
            let mut b: Option<Bounds> = None;
            for x in 0..w {
                let i = (y * w + x) as usize;
                let range = if single {
                    i..i + 1
                } else {
                    p.first[i] as usize..p.first[i + 1] as usize
                };
                for &d in &p.disparity[range] {
                    if d.is_nan() || d <= 0.0 {
                        continue;
                    }
                    let ndc_x = 2.0 * (x as f32 + 0.5) / w as f32 - 1.0;
                    let ndc_y = 1.0 - 2.0 * (y as f32 + 0.5) / h as f32;
                    let f = inv_proj * Vec4::new(ndc_x, ndc_y, 0.0, 1.0);
                    let f = f.truncate() / f.w;
                    let world = inv_view.transform_point3(f * (1.0 / (d * -f.z)));
                    if world.is_finite() {
                        b = Some(
                            b.map_or([world, world], |[lo, hi]| [lo.min(world), hi.max(world)]),
                        );
                    }
                }
            }
            b
        })
        .reduce_with(|[a, b], [c, d]| [a.min(c), b.max(d)])
}

/// References carved with kept on the stack.
const STACK: usize = 16;

/// The references carving: on the stack, then any more.
#[derive(Clone, Copy)]
struct Carvers<'s, 'a> {
    stack: &'s [Option<Carver<'a>>; STACK],
    heap: &'s [Carver<'a>],
}

impl<'s, 'a> Carvers<'s, 'a> {
    fn iter(self) -> impl Iterator<Item = &'s Carver<'a>> {
        self.stack.iter().flatten().chain(self.heap)
    }
}

/// What one reference says of a world point.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Says {
    /// Outside its frame or behind its eye.
    Nothing,
    /// In empty space (an empty pixel, or nearer than its sample).
    Empty,
    /// On its sample's surface or behind it.
    Occupied,
}

/// A reference as the carving reads it.
struct Carver<'a> {
    p: &'a Prepared,
    clip: Mat4,
    w: u32,
    h: u32,
}

impl Carver<'_> {
    /// The disparity of the nearest sample at pixel `(x, y)`; [`HOLE`] when empty.
    fn nearest(&self, x: u32, y: u32) -> f32 {
        let i = (y * self.w + x) as usize;
        if self.p.single() {
            self.p.disparity[i]
        } else {
            let r = self.p.first[i] as usize..self.p.first[i + 1] as usize;
            self.p.disparity[r].iter().fold(HOLE, |a, &d| a.max(d))
        }
    }

    /// Where homogeneous point `q` (w = 0: a direction) projects, pixels (y down), and its
    /// clip `w` (the depth along the reference's axis); `None` behind the eye.
    fn project(&self, q: Vec4) -> Option<(f32, f32, f32)> {
        let c = self.clip * q;
        if c.w.is_nan() || c.w <= 0.0 {
            return None;
        }
        let u = (c.x / c.w + 1.0) * 0.5 * self.w as f32;
        let v = (1.0 - c.y / c.w) * 0.5 * self.h as f32;
        Some((u, v, c.w))
    }

    /// The pixel `q` lands in, and its depth; `None` outside the frame or behind the eye.
    fn pixel(&self, q: Vec4) -> Option<(u32, u32, f32)> {
        let (u, v, z) = self.project(q)?;
        (u >= 0.0 && v >= 0.0 && u < self.w as f32 && v < self.h as f32)
            .then_some((u as u32, v as u32, z))
    }

    fn says(&self, point: Vec3, keep: f32) -> Says {
        let Some((x, y, z)) = self.pixel(point.extend(1.0)) else {
            return Says::Nothing;
        };
        let d = self.nearest(x, y);
        // Empty pixel, or nearer than the sample by more than the tolerance:
        // `z < z_s (1 - edge)` is `d < (1 - edge) / z`.
        if d < 0.0 || d < keep / z {
            Says::Empty
        } else {
            Says::Occupied
        }
    }

    /// Whether the reference saw sky (a sample at infinity) along direction `dir`.
    fn sky(&self, dir: Vec3) -> bool {
        self.pixel(dir.extend(0.0))
            .is_some_and(|(x, y, _)| self.nearest(x, y) == 0.0)
    }
}

/// Marks the holes of `image` no reference saw: `unseen[i]` for pixel `i`, true where it
/// is a hole whose ray stays in space the `references` saw empty, or saw not at all;
/// `bounds` is the box of their samples ([`sample_bounds`], joined). Returns how many.
pub fn mark_unseen<'a>(
    image: &Warped,
    references: impl Iterator<Item = &'a Prepared> + Clone,
    bounds: Option<Bounds>,
    edge: f32,
    unseen: &mut Vec<bool>,
) -> u64 {
    let (w, h) = (image.width(), image.height());
    unseen.clear();
    unseen.resize(image.disparity.len(), false);
    if w == 0 || h == 0 || !image.camera.projection.is_perspective() {
        return 0;
    }
    // The first [`STACK`] references on the stack, any more on the heap: frame after frame
    // nothing is allocated.
    let mut stack: [Option<Carver>; STACK] = std::array::from_fn(|_| None);
    let mut heap: Vec<Carver> = Vec::new();
    let usable = references
        .clone()
        .filter(|p| p.camera().projection.is_perspective() && p.size().0 > 0 && p.size().1 > 0);
    for (k, p) in usable.enumerate() {
        let c = Carver {
            p,
            clip: p.camera().clip_from_world(),
            w: p.size().0,
            h: p.size().1,
        };
        match stack.get_mut(k) {
            Some(slot) => *slot = Some(c),
            None => heap.push(c),
        }
    }
    let carvers = Carvers {
        stack: &stack,
        heap: &heap,
    };
    let references = references.clone();
    let any_sky = references.clone().any(|p| p.disparity.contains(&0.0));
    let keep = 1.0 - edge;
    // The box, grown a little so a flat surface's box has depth.
    let bounds = bounds.map(|[lo, hi]| {
        let pad = (hi - lo).length() * 1e-3 + 1e-4 * (lo.abs().max(hi.abs())).max_element();
        [lo - Vec3::splat(pad), hi + Vec3::splat(pad)]
    });
    let inv = image.camera.gl_view_proj().inverse();
    let eye = image.camera.eye();
    unseen
        .par_chunks_mut(w as usize)
        .zip(image.disparity.par_chunks(w as usize))
        .enumerate()
        .map(|(y, (marks, row))| {
            let mut count = 0u64;
            for (x, (mark, &d)) in marks.iter_mut().zip(row).enumerate() {
                if d >= 0.0 {
                    continue;
                }
                let ndc_x = 2.0 * (x as f32 + 0.5) / w as f32 - 1.0;
                let ndc_y = 1.0 - 2.0 * (y as f32 + 0.5) / h as f32;
                let far = inv * Vec4::new(ndc_x, ndc_y, 1.0, 1.0);
                let dir = (far.truncate() / far.w - eye).normalize_or_zero();
                let seen = (any_sky && carvers.iter().any(|c| c.sky(dir)))
                    || bounds.is_some_and(|b| seen_along(carvers, eye, dir, b, keep));
                if !seen {
                    *mark = true;
                    count += 1;
                }
            }
            count
        })
        .sum()
}

/// Whether the ray from `eye` along `dir` meets, inside box `b`, a point some reference
/// has occupied and none has empty.
fn seen_along(carvers: Carvers, eye: Vec3, dir: Vec3, b: Bounds, keep: f32) -> bool {
    // Slab test: the parameters where the ray enters and leaves the box.
    let (mut t0, mut t1) = (0.0f32, f32::INFINITY);
    for k in 0..3 {
        let inv = 1.0 / dir[k];
        let (a, c) = ((b[0][k] - eye[k]) * inv, (b[1][k] - eye[k]) * inv);
        let (a, c) = if a <= c { (a, c) } else { (c, a) };
        // NaN (a ray in the slab's plane) leaves the bound as it is.
        t0 = t0.max(a);
        t1 = t1.min(c);
    }
    if t0 > t1 || !t1.is_finite() {
        return false;
    }
    let (p0, p1) = (eye + dir * t0, eye + dir * t1);
    // Steps: about one reference pixel each, along the longest projection (no finer
    // than the frame's larger side, which a segment partly behind the eye takes).
    let mut span = 1.0f32;
    for c in carvers.iter() {
        let side = c.w.max(c.h) as f32;
        span = span.max(
            match (c.project(p0.extend(1.0)), c.project(p1.extend(1.0))) {
                (Some(a), Some(b)) => (a.0 - b.0).abs().max((a.1 - b.1).abs()).min(side),
                _ => side,
            },
        );
    }
    let steps = (span.ceil() as usize + 1).min(MAX_STEPS);
    (0..=steps).any(|k| {
        let point = p0 + (p1 - p0) * (k as f32 / steps as f32);
        let mut occupied = false;
        for c in carvers.iter() {
            match c.says(point, keep) {
                Says::Empty => return false,
                Says::Occupied => occupied = true,
                Says::Nothing => {}
            }
        }
        occupied
    })
}
