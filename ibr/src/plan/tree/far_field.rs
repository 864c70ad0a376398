//! The far field's fields: a capture's eye and frustum, cut in slots taken in the order
//! the view needs them ([`Field::next`]: slots the view sees first, nearest its centre),
//! each slot standing for the objects whose box centre it holds ([`Field::members`]).

use super::bvh::Tree;
use super::far::{far_objects, px_per_radian, FarConfig, Seen, Split};
use crate::core::{Frustum, Subject};
use engine::{Camera, Projection};
use glam::{Vec2, Vec3};

/// A tile's place in its field's image, before capture: objects whose box centre projects
/// into `min..max` are its.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Slot {
    pub(super) min: (u32, u32),
    pub(super) max: (u32, u32),
}

/// One capture of the far field: its eye, frustum and the slots still to capture.
#[derive(Clone, Debug)]
pub(super) struct Field {
    pub(super) number: u32,
    pub(super) eye: Vec3,
    pub(super) camera: Camera,
    pub(super) size: (u32, u32),
    pub(super) distance: f32,
    pub(super) pending: Vec<Slot>,
}

impl Slot {
    pub(super) fn size(&self) -> (u32, u32) {
        (self.max.0 - self.min.0, self.max.1 - self.min.1)
    }

    /// Its four quarters (a slot of a pixel a side stays whole).
    pub(super) fn quarters(&self) -> Vec<Slot> {
        let (mx, my) = ((self.min.0 + self.max.0) / 2, (self.min.1 + self.max.1) / 2);
        if mx == self.min.0 || my == self.min.1 {
            return vec![*self];
        }
        let slot = |min, max| Slot { min, max };
        vec![
            slot(self.min, (mx, my)),
            slot((mx, self.min.1), (self.max.0, my)),
            slot((self.min.0, my), (mx, self.max.1)),
            slot((mx, my), self.max),
        ]
    }

    pub(super) fn holds(&self, (x, y): (f32, f32)) -> bool {
        let (x0, y0) = (self.min.0 as f32, self.min.1 as f32);
        let (x1, y1) = (self.max.0 as f32, self.max.1 as f32);
        x >= x0 && x < x1 && y >= y0 && y < y1
    }
}

impl Field {
    /// A field at `camera`'s eye, its frustum `margin` times the view's, its image the
    /// view's `width` x `height` scaled alike, cut in `n` x `n` slots.
    pub(super) fn new(
        camera: &Camera,
        (width, height): (u32, u32),
        cfg: &FarConfig,
        number: u32,
    ) -> Field {
        let m = cfg.margin.max(1.0);
        let [l, r, b, t] = camera.projection.extents();
        let (near, far) = camera.near_far();
        let whole = Camera {
            view: camera.view,
            projection: Projection::Frustum {
                left: l * m,
                right: r * m,
                bottom: b * m,
                top: t * m,
                near,
                far,
            },
        };
        let (w, h) = (
            (width as f32 * m).ceil().max(1.0) as u32,
            (height as f32 * m).ceil().max(1.0) as u32,
        );
        let n = cfg.tiles.clamp(1, 64);
        let mut pending = Vec::with_capacity((n * n) as usize);
        for ty in 0..n {
            for tx in 0..n {
                let (x0, x1) = (w * tx / n, w * (tx + 1) / n);
                let (y0, y1) = (h * ty / n, h * (ty + 1) / n);
                if x1 > x0 && y1 > y0 {
                    pending.push(Slot {
                        min: (x0, y0),
                        max: (x1, y1),
                    });
                }
            }
        }
        Field {
            number,
            eye: camera.eye(),
            camera: whole,
            size: (w, h),
            distance: cfg.distance,
            pending,
        }
    }

    /// How this field's captures draw objects, at `lod_px` pixels of deviation.
    pub(super) fn seen(&self, lod_px: f32) -> Seen {
        Seen {
            eye: self.eye,
            px_per_radian: px_per_radian(&self.camera, self.size.1),
            lod_px,
        }
    }

    /// Whether everything `camera` sees beyond the field's distance lies in the field's
    /// frustum: the view's corner rays at that distance and at the far plane project
    /// inside it.
    pub(super) fn covers(&self, camera: &Camera, (w, h): (u32, u32)) -> bool {
        let clip = self.camera.clip_from_world();
        let far = camera.near_far().1;
        [
            (0.0, 0.0),
            (w as f32, 0.0),
            (0.0, h as f32),
            (w as f32, h as f32),
        ]
        .iter()
        .all(|&(x, y)| {
            let (o, d) = camera.pixel_ray(x, y, w, h);
            [self.distance, far].iter().all(|&s| {
                let p = clip * (o + d * s).extend(1.0);
                p.w > 0.0 && p.x.abs() <= p.w && p.y.abs() <= p.w
            })
        })
    }

    pub(super) fn split(&self) -> Split {
        Split {
            eye: self.eye,
            distance: self.distance,
            frustum: Frustum::new(self.camera.clip_from_world()),
        }
    }

    /// The field's pixel of world point `p` (in front of its eye).
    pub(super) fn pixel(&self, p: Vec3) -> (f32, f32) {
        let c = self.camera.clip_from_world() * p.extend(1.0);
        let (x, y) = (c.x / c.w, c.y / c.w);
        let (w, h) = (self.size.0 as f32, self.size.1 as f32);
        (
            ((x + 1.0) * 0.5 * w).clamp(0.0, w - 1e-3),
            ((1.0 - y) * 0.5 * h).clamp(0.0, h - 1e-3),
        )
    }

    /// A slot's camera, a crop of the field's.
    pub(super) fn crop(&self, min: (u32, u32), max: (u32, u32)) -> Camera {
        let v = |p: (u32, u32)| Vec2::new(p.0 as f32, p.1 as f32);
        self.camera.crop(v(min), v(max), self.size.0, self.size.1)
    }

    /// How much the view `view` needs slot `s` (less: sooner): 0 for a slot it sees, then
    /// the distance of the slot's centre from the view's centre, in the view's half-widths.
    pub(super) fn need(&self, s: &Slot, view: &Camera) -> (u8, f32) {
        let (cx, cy) = (
            (s.min.0 + s.max.0) as f32 * 0.5,
            (s.min.1 + s.max.1) as f32 * 0.5,
        );
        let (o, d) = self.camera.pixel_ray(cx, cy, self.size.0, self.size.1);
        let c = view.clip_from_world() * (o + d * self.distance).extend(1.0);
        let off = if c.w > 0.0 {
            Vec2::new(c.x, c.y).abs().max_element() / c.w
        } else {
            f32::MAX
        };
        let clip = view.clip_from_world();
        let (mut lo, mut hi) = (Vec2::splat(f32::MAX), Vec2::splat(f32::MIN));
        for (x, y) in [s.min, (s.max.0, s.min.1), (s.min.0, s.max.1), s.max] {
            let (o, d) = self
                .camera
                .pixel_ray(x as f32, y as f32, self.size.0, self.size.1);
            let c = clip * (o + d * self.distance).extend(1.0);
            if c.w <= 0.0 {
                return (1, off);
            }
            let p = Vec2::new(c.x, c.y) / c.w;
            (lo, hi) = (lo.min(p), hi.max(p));
        }
        let sees = lo.x <= 1.0 && lo.y <= 1.0 && hi.x >= -1.0 && hi.y >= -1.0;
        (u8::from(!sees), off)
    }

    /// The index in `pending` of the slot the view needs most (ties: the least corner).
    pub(super) fn next(&self, view: &Camera) -> Option<usize> {
        (0..self.pending.len()).min_by(|&a, &b| {
            let (sa, sb) = (&self.pending[a], &self.pending[b]);
            let (na, nb) = (self.need(sa, view), self.need(sb, view));
            na.0.cmp(&nb.0)
                .then(na.1.total_cmp(&nb.1))
                .then((sa.min.1, sa.min.0).cmp(&(sb.min.1, sb.min.0)))
        })
    }

    /// The far objects of `tree` whose box centre is in slot `s` (pushed to `out`) and the
    /// pixel rectangle their boxes cover, `s`'s own at least.
    pub(super) fn members<S: Subject>(
        &self,
        s: &Slot,
        (tree, objects): (&Tree, &[S]),
        out: &mut Vec<u32>,
    ) -> Slot {
        let split = self.split();
        let camera = self.crop(s.min, s.max);
        far_objects(tree, objects, &split, &camera, out);
        out.retain(|&i| {
            let b = tree.box_of(i as usize).unwrap_or_default();
            s.holds(self.pixel((b.0 + b.1) * 0.5))
        });
        let (mut lo, mut hi) = (
            Vec2::new(s.min.0 as f32, s.min.1 as f32),
            Vec2::new(s.max.0 as f32, s.max.1 as f32),
        );
        for &i in out.iter() {
            let (a, b) = tree.box_of(i as usize).unwrap_or_default();
            for c in crate::core::box_corners(a, b) {
                let (x, y) = self.pixel(c);
                lo = lo.min(Vec2::new(x, y));
                hi = hi.max(Vec2::new(x, y));
            }
        }
        Slot {
            min: (lo.x.floor() as u32, lo.y.floor() as u32),
            max: (
                (hi.x.ceil() as u32).clamp(1, self.size.0),
                (hi.y.ceil() as u32).clamp(1, self.size.1),
            ),
        }
    }
}

/// A slot to capture: where it lies, its objects, their triangles and whether the view saw
/// it.
pub(super) type Work = (Slot, Vec<u32>, u64, bool);

/// Takes `field`'s slots the view `camera` needs most within `budget` triangles (one at
/// least; a slot over the budget split in four first).
pub(super) fn take_slots<S: Subject>(
    field: &mut Field,
    camera: &Camera,
    (tree, objects): (&Tree, &[S]),
    budget: u64,
    cfg: &FarConfig,
) -> Vec<Work> {
    let seen = field.seen(cfg.lod_px);
    let (mut work, mut spent, mut scratch) = (Vec::new(), 0u64, Vec::new());
    while let Some(k) = field.next(camera) {
        let slot = field.pending[k];
        let mut members = Vec::new();
        let rect = field.members(&slot, (tree, objects), &mut members);
        let tris: u64 = members
            .iter()
            .map(|&i| seen.triangles(&objects[i as usize], &mut scratch))
            .sum();
        if tris > budget {
            let quarters = slot.quarters();
            if quarters.len() > 1 {
                field.pending.swap_remove(k);
                field.pending.extend(quarters);
                continue;
            }
        }
        if !work.is_empty() && spent + tris > budget {
            break;
        }
        let in_view = field.need(&slot, camera).0 == 0;
        field.pending.swap_remove(k);
        spent += tris;
        work.push((rect, members, tris, in_view));
    }
    work
}
