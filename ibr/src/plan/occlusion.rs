//! What the last frame hid: the surface drawn in each cell of the finished frame, so that
//! the frame scope counts an object's error only over the part of it that still shows. An
//! object behind others (most of a dense world's, seen low over it) shows none of its
//! error, whatever draws it.
//!
//! **The test.** An object's predicted error is a mean over its screen rectangle, with the
//! object alone in front of the background, and lies on its silhouette. In the last
//! frame, seen from its camera, each cell of the object's rectangle there holds one
//! surface point, which is
//! - *in front* of the object's bounding sphere (nearer than its nearest point, by more
//!   than an image of it may be pulled forward, [`SLACK`]): the object is hidden there, if
//!   it reaches there;
//! - *within* the sphere's depth: the object itself, its image, or what lies beside it at
//!   its depth (the ground it stands on, a neighbour), showing;
//! - *behind* the sphere, or nothing drawn: the object does not reach there, and says
//!   nothing.
//!
//! The object's error lies where it shows, and just beside that, where an image that
//! misses part of its object shows what lies behind instead. Its share is (in + behind
//! beside in) / (in + behind beside in + in front): the part of where its error may lie
//! that shows. Where it shows nowhere although something of it is not hidden (an image
//! that missed it all, or an object too thin for the cells), the share is the part of its
//! cells not hidden; 1 when no cell says.
//!
//! Its weight in the frame's error is its rectangle's area this frame times its share: an
//! object in the open weighs its whole rectangle, one half behind a wall half of it, one in
//! a crowd the part of it that shows between its neighbours, whatever lies beyond it.
//! Neighbours at its depth count as it (the share errs high there).
//!
//! **The next frame.** The object is looked up where it was (its bounds of the last
//! frame) under the last frame's camera, so neither the eye's nor the object's move
//! slides the cells; the share then stands for this frame unless the eye moved more than
//! [`MAX_MOVE`] of the object's distance, or the target changed size, or the object was
//! not wholly in front of the last camera's near plane, or was not in view: then its
//! share is 1, as if nothing hid it. The cells are point samples (one pixel each); an
//! object's rectangle is read with a stride that keeps at most [`SAMPLES`] of them.

use crate::core::RectProjector;
use engine::{Camera, Sphere, Target};
use glam::Vec3;
use rayon::prelude::*;

/// Pixels a side of a cell: small, as most of a crowd's objects are tens of pixels across.
pub const CELL: u32 = 2;

/// The eye's largest move between the grid's frame and this one, as a fraction of an
/// object's distance, for which the grid still says what hides the object.
pub const MAX_MOVE: f32 = 0.1;

/// How far in front of an object's bounding sphere a surface may lie, in radii, and still
/// count as the object: an image's quad is drawn through the nearest corner of its box
/// ([`crate::core::Subject::corners`]), which lies within the cube around the sphere,
/// up to `sqrt(3) - 1` radii in front of it; and depth is stored in 32 bits.
pub const SLACK: f32 = 0.75;

/// The most cells read for one object: a larger rectangle is read with a stride.
pub const SAMPLES: u32 = 256;

/// The surface point of each cell of the last finished frame, and its camera.
#[derive(Clone, Debug, Default)]
pub struct Occlusion {
    camera: Option<Camera>,
    /// `camera`'s eye (taken once: inverting the view per object is a cost in a world).
    eye: Vec3,
    /// Screen rectangles under `camera`.
    project: Option<RectProjector>,
    size: (u32, u32),
    cols: usize,
    rows: usize,
    /// Per cell, row-major: the view-space `z` (negative ahead) of the point drawn at its
    /// first pixel; `NEG_INFINITY` where nothing was drawn.
    points: Vec<f32>,
    row: (Vec<u32>, Vec<f32>),
}

/// Where an object's cells say it shows, and where they say it is hidden.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Cells {
    /// Cells where the object shows (within its bounding sphere's depth).
    pub shows: u32,
    /// Cells where something in front of the object hides it.
    pub hidden: u32,
    /// Cells behind the object beside one where it shows: where an image that misses part
    /// of its object errs.
    pub edge: u32,
    /// Every cell read.
    pub read: u32,
}

/// What one cell says of an object.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Class {
    Hidden,
    Shows,
    Behind,
}

impl Occlusion {
    /// Takes the finished frame's depth, seen from `camera`.
    pub fn observe(&mut self, target: &Target, camera: &Camera) {
        let (w, h) = (target.width(), target.height());
        self.size = (w, h);
        (self.cols, self.rows) = (w.div_ceil(CELL) as usize, h.div_ceil(CELL) as usize);
        self.points.clear();
        self.points.reserve(self.cols * self.rows);
        let (colors, depth) = (&mut self.row.0, &mut self.row.1);
        for y in (0..h).step_by(CELL as usize) {
            target.read_row(y, colors, depth);
            let drawn = depth.iter().step_by(CELL as usize).map(|&d| {
                let z = -camera.view_depth_from_reversed(d);
                if d > 0.0 && z.is_finite() {
                    z
                } else {
                    f32::NEG_INFINITY
                }
            });
            self.points.extend(drawn);
        }
        self.camera = Some(*camera);
        self.eye = camera.eye();
        self.project = Some(RectProjector::new(camera, w, h));
    }

    /// Forgets the last frame: every object may show.
    pub fn clear(&mut self) {
        self.camera = None;
    }

    /// What the last frame's cells say of an object with bounds `then` in it, seen from
    /// `now` on a `width` x `height` target (`None`: nothing known; see the module docs).
    pub fn cells(&self, then: Sphere, now: &Camera, width: u32, height: u32) -> Option<Cells> {
        self.cells_from(then, now.eye(), width, height)
    }

    /// [`Occlusion::cells`] seen from the eye `now`.
    fn cells_from(&self, then: Sphere, now: Vec3, width: u32, height: u32) -> Option<Cells> {
        let old = self.camera.as_ref()?;
        if (width, height) != self.size || !(then.center.is_finite() && then.radius.is_finite()) {
            return None;
        }
        let c = old.view.transform_point3(then.center);
        if -c.z - then.radius <= old.near_far().0 {
            return None;
        }
        let moved = now.distance(self.eye);
        let within = moved <= MAX_MOVE * now.distance(then.center);
        if !within {
            return None;
        }
        let r = self
            .project?
            .rect(then.center, then.radius)?
            .clip(width, height);
        if r.is_empty() {
            return None;
        }
        let (x0, y0) = (r.x / CELL, r.y / CELL);
        let (x1, y1) = (
            (r.x + r.width).div_ceil(CELL),
            (r.y + r.height).div_ceil(CELL),
        );
        // The least stride that keeps the cells read within SAMPLES.
        let mut stride = 1;
        let sampled = |s: u32| ((x1 - x0).div_ceil(s), (y1 - y0).div_ceil(s));
        while sampled(stride).0 * sampled(stride).1 > SAMPLES {
            stride += 1;
        }
        let (nx, ny) = (sampled(stride).0 as usize, sampled(stride).1 as usize);
        // View z (negative ahead) of the sphere's nearest point, less what an image's quad
        // may be pulled forward, and of its farthest.
        let near = c.z + then.radius * (1.0 + SLACK);
        let far = c.z - then.radius;
        let mut class = [Class::Behind; SAMPLES as usize];
        for (j, cy) in (y0..y1).step_by(stride as usize).enumerate() {
            let row = &self.points[cy as usize * self.cols..][..self.cols];
            for (i, cx) in (x0..x1).step_by(stride as usize).enumerate() {
                let z = row[cx as usize];
                class[j * nx + i] = if z > near {
                    Class::Hidden
                } else if z >= far {
                    Class::Shows
                } else {
                    Class::Behind
                };
            }
        }
        let mut out = Cells {
            read: (nx * ny) as u32,
            ..Cells::default()
        };
        let class = &class[..nx * ny];
        for &c in class {
            match c {
                Class::Hidden => out.hidden += 1,
                Class::Shows => out.shows += 1,
                Class::Behind => {}
            }
        }
        // Edges only where cells show and others lie behind.
        if out.shows == 0 || out.shows + out.hidden == out.read {
            return Some(out);
        }
        for (k, &c) in class.iter().enumerate() {
            match c {
                Class::Hidden | Class::Shows => {}
                Class::Behind => {
                    let (i, j) = (k % nx, k / nx);
                    let shows = |i: usize, j: usize| class[j * nx + i] == Class::Shows;
                    let edge = (i > 0 && shows(i - 1, j))
                        || (i + 1 < nx && shows(i + 1, j))
                        || (j > 0 && shows(i, j - 1))
                        || (j + 1 < ny && shows(i, j + 1));
                    out.edge += u32::from(edge);
                }
            }
        }
        Some(out)
    }

    /// The share of an object with bounds `then` in the last frame that shows, seen from
    /// `now` on a `width` x `height` target ([module docs](self)): from 0 (hidden) to 1.
    pub fn share(&self, then: Sphere, now: &Camera, width: u32, height: u32) -> f32 {
        self.share_from(then, now.eye(), width, height)
    }

    /// [`Occlusion::share`] seen from the eye `now`.
    fn share_from(&self, then: Sphere, now: Vec3, width: u32, height: u32) -> f32 {
        match self.cells_from(then, now, width, height) {
            Some(c) if c.shows > 0 => {
                (c.shows + c.edge) as f32 / (c.shows + c.edge + c.hidden) as f32
            }
            Some(c) if c.read > 0 => 1.0 - c.hidden as f32 / c.read as f32,
            _ => 1.0,
        }
    }

    /// Each visible object's weight in the frame's error into `out`: its rectangle's area
    /// this frame, `areas(k)` (at least 1), times its share, from its bounds in the last
    /// frame, `then(k)` (`None`: not in it, share 1), seen from `now` on a `width` x
    /// `height` target. Side by side over the objects, gathered in order: the same at any
    /// thread count.
    pub fn weigh(
        &self,
        n: usize,
        then: impl Fn(usize) -> Option<Sphere> + Sync,
        areas: impl Fn(usize) -> f32 + Sync,
        now: &Camera,
        (width, height): (u32, u32),
        out: &mut Vec<f32>,
    ) {
        let eye = now.eye();
        (0..n)
            .into_par_iter()
            .map(|k| {
                let share = then(k).map_or(1.0, |b| self.share_from(b, eye, width, height));
                areas(k).max(1.0) * share
            })
            .collect_into_vec(out);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use engine::{procedural, Draw, FrameOptions, Lighting, Material, Renderer, Rgba};
    use glam::Mat4;

    const W: u32 = 160;
    const H: u32 = 96;

    fn camera(eye: Vec3) -> Camera {
        Camera::look_at(eye, Vec3::ZERO, Vec3::Y, 0.9, W as f32 / H as f32)
            .with_depth_range(0.05, 100.0)
    }

    fn ball(x: f32, z: f32) -> Sphere {
        Sphere {
            center: Vec3::new(x, 0.0, z),
            radius: 0.3,
        }
    }

    /// The grid of a 2 x 2 wall through the origin facing +Z, and balls of bounds `balls`
    /// (cubes inscribed in them), seen from `eye`.
    fn wall_from(eye: Vec3, balls: &[Sphere]) -> Occlusion {
        let wall = procedural::cuboid(Vec3::new(2.0, 2.0, 0.1));
        let cube = procedural::cuboid(Vec3::splat(0.3));
        let material = Material::unlit(Rgba::WHITE);
        let mut draws = vec![Draw {
            mesh: &wall,
            material: &material,
            transform: Mat4::IDENTITY,
        }];
        draws.extend(balls.iter().map(|b| Draw {
            mesh: &cube,
            material: &material,
            transform: Mat4::from_translation(b.center),
        }));
        let (cam, mut target) = (camera(eye), Target::new(W, H));
        let opts = FrameOptions::default();
        Renderer::new().render(draws, &cam, &Lighting::default(), &mut target, &opts);
        let mut o = Occlusion::default();
        o.observe(&target, &cam);
        o
    }

    #[test]
    fn behind_the_wall_nothing_shows_beside_or_in_front_all_of_it() {
        let eye = Vec3::new(0.0, 0.0, 5.0);
        let balls = [
            ball(0.0, -1.0),
            ball(0.0, 1.0),
            ball(2.5, -1.0),
            ball(1.2, -1.0),
        ];
        let o = wall_from(eye, &balls);
        let share = |b: Sphere, eye: Vec3| o.share(b, &camera(eye), W, H);
        assert_eq!(share(balls[0], eye), 0.0);
        assert_eq!(share(balls[1], eye), 1.0);
        assert_eq!(share(balls[2], eye), 1.0);
        // Straddling the wall's edge: some of it, counting the background beside the cube.
        let edge = share(balls[3], eye);
        assert!(edge > 0.1 && edge < 0.9, "{edge}");
        let c = o.cells(balls[3], &camera(eye), W, H).unwrap();
        assert!(c.edge > 0 && c.shows > 0 && c.hidden > 0, "{c:?}");
        // Straddling it but not drawn (an image that missed its object): the part of its
        // cells not hidden.
        let missed = ball(1.2, -1.5);
        let c = o.cells(missed, &camera(eye), W, H).unwrap();
        assert!(c.shows == 0 && c.hidden > 0 && c.hidden < c.read, "{c:?}");
        let want = 1.0 - c.hidden as f32 / c.read as f32;
        assert_eq!(share(missed, eye), want);
        // Where nothing reached (an object new to the frame, in front of the wall): nothing
        // hides it.
        assert_eq!(share(ball(-0.5, 1.0), eye), 1.0);
        // A small step of the eye: still hidden. A teleport behind the wall, a new size or
        // a forgotten frame: nothing known, all of it may show.
        assert_eq!(share(balls[0], Vec3::new(0.05, 0.0, 5.0)), 0.0);
        assert_eq!(share(balls[0], Vec3::new(0.0, 0.0, -8.0)), 1.0);
        assert_eq!(o.share(balls[0], &camera(eye), W / 2, H), 1.0);
        let mut forgot = o.clone();
        forgot.clear();
        assert_eq!(forgot.share(balls[0], &camera(eye), W, H), 1.0);
    }

    #[test]
    fn a_large_object_is_read_with_a_stride() {
        let eye = Vec3::new(0.0, 0.0, 5.0);
        let big = Sphere {
            center: Vec3::new(0.0, 0.0, -1.0),
            radius: 3.0,
        };
        let o = wall_from(eye, &[]);
        let c = o.cells(big, &camera(eye), W, H).unwrap();
        assert!(c.shows + c.hidden <= SAMPLES, "{c:?}");
        // The wall is in its sphere: it shows.
        assert!(c.shows > 0 && c.hidden == 0, "{c:?}");
    }

    #[test]
    fn odd_frames_and_bounds_give_a_share_between_zero_and_one() {
        let mut o = Occlusion::default();
        let cam = camera(Vec3::new(0.0, 0.0, 5.0));
        assert_eq!(o.share(ball(0.0, 0.0), &cam, W, H), 1.0);
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
                let s = o.share(b, &cam, w, h);
                assert!((0.0..=1.0).contains(&s), "{b:?} {w}x{h}: {s}");
            }
        }
        let o = wall_from(Vec3::new(0.0, 0.0, 5.0), &[]);
        for b in odd {
            let s = o.share(b, &cam, W, H);
            assert!((0.0..=1.0).contains(&s), "{b:?}: {s}");
        }
    }
}
