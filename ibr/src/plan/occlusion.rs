//! What the last frame hid: the farthest depth in each cell of the finished frame, so that
//! the frame scope counts an object's error only over the part of its rectangle where it
//! may still show. An object behind others (most of a dense world's, seen low over it)
//! shows none of its error, whatever draws it.
//!
//! **The test.** Under the grid's camera, an object may show in a cell unless all drawn
//! there is nearer than the nearest point of its bounding sphere. Its share is the part of
//! its rectangle's cells where it may show. The sphere reaches nearer than the object, and
//! a cell shows the object wherever anything farther is drawn in it, so the share errs
//! high: the frame's predicted error adds up every object's error where it may show, as
//! if none of them hid another.
//!
//! **The next frame.** The eye has moved since: an object's cells are looked up where its
//! centre was on the grid's image, in a pyramid of grids of cells 1, 2, 4 and 8 times as
//! wide, each cell holding the farthest depth in it and its eight neighbours: the finest
//! whose neighbours reach as far as the eye's move slides an occluder at half the
//! object's distance across it. Where that is more, or the eye
//! moved more than [`MAX_MOVE`] of the object's distance, or the target changed size, or
//! the object was not wholly in front of the grid's camera, its share is 1: a teleport
//! weighs objects as if nothing hid them.

use crate::impostor::pixels_per_radian;
use crate::metrics::Rect;
use engine::{Camera, Sphere, Target};
use glam::Vec2;
use rayon::prelude::*;

/// Pixels a side of a cell: small, as most of a crowd's objects are tens of pixels across.
pub const CELL: u32 = 2;

/// The eye's largest move between the grid's frame and this one, as a fraction of an
/// object's distance, for which the grid still says what hides the object.
pub const MAX_MOVE: f32 = 0.1;

/// The pyramid's levels: level `k`'s cells are `2^k` cells wide and reach as far.
const LEVELS: usize = 4;

/// The farthest reversed depth per cell of the last finished frame, and its camera.
#[derive(Clone, Debug, Default)]
pub struct Occlusion {
    camera: Option<Camera>,
    size: (u32, u32),
    cols: usize,
    rows: usize,
    /// Per level, its columns and rows and per cell, row-major: the least reversed depth
    /// drawn in it and its neighbours (the farthest; 0: nothing drawn somewhere).
    dims: [(usize, usize); LEVELS],
    far: [Vec<f32>; LEVELS],
    /// Per level, per cell: the least reversed depth drawn in it.
    raw: [Vec<f32>; LEVELS],
    row: (Vec<u32>, Vec<f32>),
    scratch: Vec<f32>,
}

/// Where an object's cells are looked up on the grids, and the reversed depth of its
/// sphere's nearest point.
#[derive(Clone, Copy, Debug)]
struct Map {
    dx: i64,
    dy: i64,
    level: usize,
    near: f32,
}

impl Occlusion {
    /// Takes the finished frame's depth, seen from `camera`.
    pub fn observe(&mut self, target: &Target, camera: &Camera) {
        let (w, h) = (target.width(), target.height());
        self.size = (w, h);
        (self.cols, self.rows) = (w.div_ceil(CELL) as usize, h.div_ceil(CELL) as usize);
        let cols = self.cols;
        let raw = &mut self.raw[0];
        raw.clear();
        raw.resize(cols * self.rows, f32::INFINITY);
        let (colors, depth) = (&mut self.row.0, &mut self.row.1);
        for y in 0..h {
            target.read_row(y, colors, depth);
            let cells = &mut raw[(y / CELL) as usize * cols..];
            for (cell, run) in cells.iter_mut().zip(depth.chunks(CELL as usize)) {
                *cell = run.iter().fold(*cell, |m, &d| m.min(d));
            }
        }
        // Each level from the last, 2 x 2 cells to one; then each cell with its neighbours.
        self.dims[0] = (cols, self.rows);
        for k in 1..LEVELS {
            let (c, r) = self.dims[k - 1];
            let (nc, nr) = (c.div_ceil(2), r.div_ceil(2));
            let (done, rest) = self.raw.split_at_mut(k);
            let (fine, coarse) = (&done[k - 1], &mut rest[0]);
            coarse.clear();
            coarse.resize(nc * nr, f32::INFINITY);
            for (i, &d) in fine.iter().enumerate() {
                let at = (i / c.max(1)) / 2 * nc + (i % c.max(1)) / 2;
                coarse[at] = coarse[at].min(d);
            }
            self.dims[k] = (nc, nr);
        }
        for k in 0..LEVELS {
            spread_min(
                &self.raw[k],
                &mut self.scratch,
                &mut self.far[k],
                self.dims[k],
                1,
            );
        }
        self.camera = Some(*camera);
    }

    /// Forgets the last frame: every object may show.
    pub fn clear(&mut self) {
        self.camera = None;
    }

    /// The lookup of an object with bounds `b` seen from `now` on a `width` x `height`
    /// target (`None`: nothing known, it may show everywhere).
    fn map(&self, b: Sphere, now: &Camera, width: u32, height: u32) -> Option<Map> {
        let old = self.camera.as_ref()?;
        if (width, height) != self.size || !(b.center.is_finite() && b.radius.is_finite()) {
            return None;
        }
        let depth = -old.view.transform_point3(b.center).z;
        if depth - b.radius <= old.near_far().0 {
            return None;
        }
        let then = pixel(old, b, width, height)?;
        let here = pixel(now, b, width, height)?;
        let moved = now.eye().distance(old.eye());
        let distance = now.eye().distance(b.center).max(1e-6);
        if moved > MAX_MOVE * distance {
            return None;
        }
        let parallax = 2.0 * moved / distance * pixels_per_radian(now, height);
        // Rounding to a cell slides by up to half of one.
        let reach = parallax / CELL as f32 + 0.5;
        let level = (0..LEVELS).find(|&k| reach <= (1 << k) as f32)?;
        let shift = (then - here) / CELL as f32;
        if !shift.is_finite() || shift.abs().max_element() > (self.cols + self.rows) as f32 {
            return None;
        }
        Some(Map {
            dx: shift.x.round() as i64,
            dy: shift.y.round() as i64,
            level,
            near: old.reversed_from_view_depth(depth - b.radius),
        })
    }

    /// Whether an object looked up by `m` may show in this frame's cell `(cx, cy)` (off
    /// the grid it may).
    fn shows(&self, m: Map, cx: i64, cy: i64) -> bool {
        let (x, y) = (cx + m.dx, cy + m.dy);
        if x < 0 || y < 0 || x >= self.cols as i64 || y >= self.rows as i64 {
            return true;
        }
        let (x, y) = ((x as usize) >> m.level, (y as usize) >> m.level);
        m.near >= self.far[m.level][y * self.dims[m.level].0 + x]
    }

    /// The share of the screen rectangle `r` of an object with bounds `b` where it may
    /// show, seen from `now` on a `width` x `height` target ([module docs](self)): from 0
    /// (hidden) to 1.
    pub fn share(&self, b: Sphere, r: Rect, now: &Camera, width: u32, height: u32) -> f32 {
        self.share_of(self.map(b, now, width, height), r, width, height)
    }

    fn share_of(&self, m: Option<Map>, r: Rect, width: u32, height: u32) -> f32 {
        let Some(m) = m else {
            return 1.0;
        };
        let (mut shows, mut all) = (0u64, 0u64);
        for_cells(r, width, height, |cx, cy, px| {
            all += px;
            if self.shows(m, cx, cy) {
                shows += px;
            }
        });
        if all == 0 {
            1.0
        } else {
            shows as f32 / all as f32
        }
    }

    /// Each visible object's weight in the frame's error into `out`: its rectangle's area
    /// (at least 1) times its share. The objects' bounds are `bounds(k)` and their screen
    /// rectangles `rects` this frame, seen from `now` on a `width` x `height` target. Side
    /// by side over the objects, gathered in order: the same at any thread count.
    pub fn weigh(
        &mut self,
        bounds: impl Fn(usize) -> Sphere + Sync,
        rects: &[Rect],
        now: &Camera,
        (width, height): (u32, u32),
        out: &mut Vec<f32>,
    ) {
        let this = &*self;
        rects
            .par_iter()
            .enumerate()
            .map(|(k, &r)| {
                let area = (r.width as f32 * r.height as f32).max(1.0);
                area * this.share(bounds(k), r, now, width, height)
            })
            .collect_into_vec(out);
    }
}

/// Calls `f(cx, cy, pixels)` for each cell the rectangle `r` (clipped to a `width` x
/// `height` image) touches, with the pixels of `r` in it.
fn for_cells(r: Rect, width: u32, height: u32, mut f: impl FnMut(i64, i64, u64)) {
    let r = r.clip(width, height);
    if r.is_empty() {
        return;
    }
    let (x0, y0, x1, y1) = (r.x, r.y, r.x + r.width, r.y + r.height);
    for cy in y0 / CELL..y1.div_ceil(CELL) {
        let h = (y1.min((cy + 1) * CELL) - y0.max(cy * CELL)) as u64;
        for cx in x0 / CELL..x1.div_ceil(CELL) {
            let w = (x1.min((cx + 1) * CELL) - x0.max(cx * CELL)) as u64;
            f(i64::from(cx), i64::from(cy), w * h);
        }
    }
}

/// The least of `source` within `by` cells (a square), into `out`; `scratch` holds the
/// rows' pass.
fn spread_min(
    source: &[f32],
    scratch: &mut Vec<f32>,
    out: &mut Vec<f32>,
    (cols, rows): (usize, usize),
    by: i64,
) {
    let by = by.max(0) as usize;
    scratch.clear();
    scratch.resize(source.len(), 0.0);
    for y in 0..rows {
        let row = &source[y * cols..(y + 1) * cols];
        for x in 0..cols {
            let (a, b) = (x.saturating_sub(by), (x + by + 1).min(cols));
            scratch[y * cols + x] = row[a..b].iter().fold(f32::INFINITY, |m, &d| m.min(d));
        }
    }
    out.clear();
    out.resize(source.len(), 0.0);
    for y in 0..rows {
        let (a, b) = (y.saturating_sub(by), (y + by + 1).min(rows));
        for x in 0..cols {
            let column = (a..b).map(|yy| scratch[yy * cols + x]);
            out[y * cols + x] = column.fold(f32::INFINITY, f32::min);
        }
    }
}

/// Where the centre of `b` lands on a `width` x `height` image from `camera`, pixels
/// (`None` at or behind the eye).
fn pixel(camera: &Camera, b: Sphere, width: u32, height: u32) -> Option<Vec2> {
    let c = camera.clip_from_world() * b.center.extend(1.0);
    if c.w <= 1e-6 || !c.is_finite() {
        return None;
    }
    let ndc = Vec2::new(c.x, c.y) / c.w;
    Some(Vec2::new(
        (ndc.x * 0.5 + 0.5) * width as f32,
        (0.5 - ndc.y * 0.5) * height as f32,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::impostor::screen_rect;
    use engine::{procedural, Draw, FrameOptions, Lighting, Material, Renderer, Rgba};
    use glam::{Mat4, Vec3};

    const W: u32 = 160;
    const H: u32 = 96;

    fn camera(eye: Vec3) -> Camera {
        Camera::look_at(eye, Vec3::ZERO, Vec3::Y, 0.9, W as f32 / H as f32)
            .with_depth_range(0.05, 100.0)
    }

    /// The grid of a 2 x 2 wall through the origin facing +Z, seen from `eye`.
    fn wall_from(eye: Vec3) -> Occlusion {
        let mesh = procedural::cuboid(Vec3::new(2.0, 2.0, 0.1));
        let material = Material::unlit(Rgba::WHITE);
        let draw = Draw {
            mesh: &mesh,
            material: &material,
            transform: Mat4::IDENTITY,
        };
        let (cam, mut target) = (camera(eye), Target::new(W, H));
        let opts = FrameOptions::default();
        Renderer::new().render([draw], &cam, &Lighting::default(), &mut target, &opts);
        let mut o = Occlusion::default();
        o.observe(&target, &cam);
        o
    }

    fn ball(x: f32, z: f32) -> Sphere {
        Sphere {
            center: Vec3::new(x, 0.0, z),
            radius: 0.3,
        }
    }

    #[test]
    fn behind_the_wall_nothing_shows_beside_or_in_front_all_of_it() {
        let eye = Vec3::new(0.0, 0.0, 5.0);
        let o = wall_from(eye);
        let share = |b: Sphere, eye: Vec3| {
            let cam = camera(eye);
            let r = screen_rect(&cam, b.center, b.radius, W, H).unwrap();
            o.share(b, r, &cam, W, H)
        };
        assert_eq!(share(ball(0.0, -1.0), eye), 0.0);
        assert_eq!(share(ball(0.0, 1.0), eye), 1.0);
        assert_eq!(share(ball(2.5, -1.0), eye), 1.0);
        // Straddling the wall's edge: some of it.
        let edge = share(ball(1.2, -1.0), eye);
        assert!(edge > 0.1 && edge < 0.9, "{edge}");
        // A small step of the eye: still hidden. A teleport behind the wall, a new size or
        // a forgotten frame: nothing known, all of it may show.
        assert_eq!(share(ball(0.0, -1.0), Vec3::new(0.05, 0.0, 5.0)), 0.0);
        assert_eq!(share(ball(0.0, -1.0), Vec3::new(0.0, 0.0, -8.0)), 1.0);
        let whole = Rect::new(0, 0, W, H);
        assert_eq!(o.share(ball(0.0, -1.0), whole, &camera(eye), W / 2, H), 1.0);
        let mut forgot = o.clone();
        forgot.clear();
        assert_eq!(
            forgot.share(ball(0.0, -1.0), whole, &camera(eye), W, H),
            1.0
        );
    }

    #[test]
    fn odd_frames_and_bounds_give_a_share_between_zero_and_one() {
        let mut o = Occlusion::default();
        let cam = camera(Vec3::new(0.0, 0.0, 5.0));
        let whole = Rect::new(0, 0, W, H);
        assert_eq!(o.share(ball(0.0, 0.0), whole, &cam, W, H), 1.0);
        o.observe(&Target::new(0, 0), &cam);
        let odd = [
            ball(0.0, 0.0),
            ball(f32::NAN, 0.0),
            ball(0.0, 5.0),
            ball(0.0, 1e30),
            Sphere {
                center: Vec3::ZERO,
                radius: 1e30,
            },
        ];
        for b in odd {
            for (w, h) in [(0, 0), (W, H)] {
                let s = o.share(b, whole, &cam, w, h);
                assert!((0.0..=1.0).contains(&s), "{b:?} {w}x{h}: {s}");
            }
        }
    }
}
