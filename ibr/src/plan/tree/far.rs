//! The far field: every object whose centre lies beyond a distance from an eye, drawn as
//! one image mesh with depth (Sillion, Drettakis and Bodelet 97; Shade et al. 96's far
//! nodes as a few cached images). The image is captured from the field's eye through a
//! frustum a margin wider than the view's, in tiles (crops of it, a tile over the budget
//! split in four) spread over frames within a per-frame budget of captured triangles, and
//! drawn as a mesh of small quads at the pixels' depths with their colours, one per run of
//! pixels along a row that a quad's interpolation reproduces ([`super::far_mesh`]; grown a
//! fraction of a pixel so neighbours on a surface leave no cracks as the eye moves): opaque, depth written, seen from any nearby eye with the parallax of its
//! depths, so near geometry and the far field occlude each other. (A mesh joining pixel
//! centres, [`crate::warp::mesh`], shrinks every silhouette by half a pixel and drops
//! features a pixel wide: the far field's objects are a few pixels wide.)
//!
//! Tiles are swapped in one by one (Shade et al. 96 re-cache per node, not per scene): a
//! new field starts when the eye has moved far enough from the last field's eye that its
//! parallax at the field's distance passes [`FarConfig::parallax`] pixels, or when the
//! view leaves the last field's frustum (a field being captured that the view leaves is
//! given up, its tiles shown so far kept). Its slots are taken in the order the view needs
//! them, those it sees first, nearest its centre ([`super::far_field`]), and each slot's
//! tile is shown as soon as it is captured. Each object is in at most one tile, the one
//! whose slot holds its box centre, captured over all the pixels its box covers; a tile
//! swapped in takes down every older tile holding any of its objects (their other objects
//! the cut's until their own new tiles come), and a completed field takes down every older
//! tile. So every object is drawn exactly once: by the one shown tile standing for it, or
//! by the cut ([`FarField::owns`], [`FarField::side`]; `plan::tree::far_tests`). An object
//! that moves is the cut's from then on ([`FarField::release`]). [`Split`] is the rule a
//! field's objects follow (centre beyond the distance from the field's eye, whole box
//! inside its frustum).

use super::bvh::Tree;
use super::far_field::{take_slots, Field, Work};
use super::far_mesh::span_mesh;
use crate::core::{Capturer, DepthImage, Frustum, Subject};
use crate::warp::mesh::depth_mesh_material;
use engine::{Camera, Draw, Material, Mesh, Sphere};
use glam::{Mat4, Vec3};
use rayon::prelude::*;

/// Settings of a [`FarField`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FarConfig {
    /// Objects whose centre is farther than this from the field's eye are the far field's.
    pub distance: f32,
    /// The capture frustum's half-extents over the view's (>= 1: room to turn and move).
    pub margin: f32,
    /// Tiles a side of the capture grid.
    pub tiles: u32,
    /// Triangles captured per frame, at most (a tile over it alone is still taken, one a
    /// frame),
    pub triangles: u64,
    /// and during the hierarchy's loading frames ([`super::TreeConfig::loading`]) or while
    /// no field has been shown yet.
    pub loading_triangles: u64,
    /// Pixels of parallax at [`FarConfig::distance`], as the eye moves from the shown
    /// field's eye, past which a new field is captured.
    pub parallax: f32,
    /// Pixels each quad of the mesh is grown by on every side.
    pub grow: f32,
    /// Objects are captured at their coarsest level of detail whose geometric deviation
    /// projects within this many of the field's pixels ([`Subject::draws_seen`]; 0: full
    /// meshes), and the per-frame budget counts the triangles so captured.
    pub lod_px: f32,
}

impl Default for FarConfig {
    fn default() -> Self {
        FarConfig {
            distance: 80.0,
            margin: 1.25,
            tiles: 8,
            triangles: 150_000,
            loading_triangles: 4_000_000,
            parallax: 24.0,
            grow: 0.25,
            lod_px: 0.5,
        }
    }
}

/// What the far field did in the last frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FarReport {
    /// Tiles captured (each swapped in as it completed),
    pub tiles: usize,
    /// the triangles they drew,
    pub triangles: u64,
    /// and objects.
    pub objects: usize,
    /// Of the tiles captured, those the view saw.
    pub in_view: usize,
    /// Tiles of older fields taken down because a new tile took some of their objects
    /// (theirs left to the cut until their own new tiles come).
    pub dropped: usize,
    /// Whether any tile is shown (the cut then leaves its objects to it).
    pub shown: bool,
    /// Tiles shown.
    pub shown_tiles: usize,
    /// Objects the shown tiles stand for.
    pub owned: usize,
    /// Fields completed so far.
    pub swaps: usize,
    /// Triangles of the shown meshes drawn.
    pub mesh_triangles: usize,
    /// Tiles of the field being captured still to take.
    pub pending: usize,
}

/// One captured tile: its pixel rectangle of its field's image, that as a mesh, and the
/// objects it stands for (each object in one tile at most: the one holding its centre).
#[derive(Clone, Debug)]
struct Tile {
    mesh: Mesh,
    /// Bounds of the mesh's points (`None`: empty).
    sphere: Option<Sphere>,
    /// The objects captured into it.
    objects: Vec<u32>,
    /// Its field's number and rule.
    field: u32,
    split: Split,
}

/// Which objects a shown field stands for (module docs): the field's eye, distance and
/// frustum.
#[derive(Clone, Copy, Debug)]
pub struct Split {
    /// The eye the field was captured from,
    pub eye: Vec3,
    /// the distance beyond which (of a box's centre) objects are its,
    pub distance: f32,
    /// and the frustum it was captured through (an object's whole box inside).
    pub frustum: Frustum,
}

/// Where a box of objects lies against a [`Split`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    /// Every object in it is the far field's,
    Far,
    /// none is,
    Near,
    /// or some may be.
    Across,
}

impl Split {
    /// Whether the object of box `lo..hi` is the far field's.
    pub fn is_far(&self, (lo, hi): (Vec3, Vec3)) -> bool {
        (lo + hi).distance(self.eye * 2.0) > 2.0 * self.distance
            && crate::core::box_corners(lo, hi)
                .iter()
                .all(|&c| self.frustum.contains(c))
    }

    /// Where the node box `lo..hi` lies (its objects' boxes inside it).
    pub fn side(&self, lo: Vec3, hi: Vec3) -> Side {
        let (near, far) = box_range(self.eye, lo, hi);
        let (c, r) = ((lo + hi) * 0.5, (hi - lo).length() * 0.5);
        if far <= self.distance || !self.frustum.sees(c, r) {
            return Side::Near;
        }
        let inside = crate::core::box_corners(lo, hi)
            .iter()
            .all(|&c| self.frustum.contains(c));
        if near > self.distance && inside {
            Side::Far
        } else {
            Side::Across
        }
    }
}

/// The nearest and farthest distances from `p` to the box `lo..hi`.
pub(super) fn box_range(p: Vec3, lo: Vec3, hi: Vec3) -> (f32, f32) {
    let near = p.clamp(lo, hi).distance(p);
    let far = (p - lo).abs().max((p - hi).abs()).length();
    (near, far)
}

/// No tile: an object the cut draws.
const NO_TILE: u32 = u32::MAX;

/// The far field of a hierarchy's objects (module docs).
#[derive(Debug)]
pub struct FarField {
    /// Settings; may be changed between frames (a new distance applies from the next field).
    pub config: FarConfig,
    /// The tiles shown (`None`: a free place), from the field being captured or older ones.
    tiles: Vec<Option<Tile>>,
    /// Per object, the tile that stands for it ([`NO_TILE`]: the cut's).
    owner: Vec<u32>,
    /// Per place of the tree's object order, how many before it are a tile's (for
    /// [`FarField::side`]), and whether that needs recounting.
    owned_before: Vec<u32>,
    recount: bool,
    /// The field being captured, and the last one begun (whose eye and frustum say when the
    /// next one is due).
    building: Option<Field>,
    newest: Option<Field>,
    fields: u32,
    material: Material,
    /// What the last [`FarField::step`] did.
    pub report: FarReport,
}

impl FarField {
    /// A far field with nothing captured yet.
    pub fn new(config: FarConfig) -> Self {
        FarField {
            config,
            tiles: Vec::new(),
            owner: Vec::new(),
            owned_before: Vec::new(),
            recount: true,
            building: None,
            newest: None,
            fields: 0,
            material: depth_mesh_material(),
            report: FarReport::default(),
        }
    }

    /// Whether a whole field has been completed (before that, the hierarchy loads).
    pub fn completed(&self) -> bool {
        self.report.swaps > 0
    }

    /// Whether object `i` is a shown tile's.
    pub fn owns(&self, i: usize) -> bool {
        self.owner.get(i).is_some_and(|&t| t != NO_TILE)
    }

    /// The rule of the field whose tile stands for object `i`, if one does.
    pub fn split_of(&self, i: usize) -> Option<Split> {
        let t = *self.owner.get(i)?;
        self.tiles.get(t as usize)?.as_ref().map(|t| t.split)
    }

    /// Where the node over `order[first..first + count]` of `tree` lies: wholly the shown
    /// tiles' ([`Side::Far`]), none of it ([`Side::Near`]), or some ([`Side::Across`]).
    pub fn side(&self, first: u32, count: u32) -> Side {
        let (a, b) = (first as usize, (first + count) as usize);
        let n = match (self.owned_before.get(a), self.owned_before.get(b)) {
            (Some(x), Some(y)) => y - x,
            _ => 0,
        };
        if n == 0 {
            Side::Near
        } else if n == count {
            Side::Far
        } else {
            Side::Across
        }
    }

    /// Leaves the objects `moved` to the cut (a tile shows where they were).
    pub fn release(&mut self, moved: &[usize]) {
        for &i in moved {
            if let Some(t) = self.owner.get_mut(i) {
                self.recount |= *t != NO_TILE;
                *t = NO_TILE;
            }
        }
    }

    /// Recounts [`FarField::side`]'s table for `tree` if ownership changed.
    pub fn recount(&mut self, tree: &Tree) {
        if !self.recount && self.owned_before.len() == tree.order().len() + 1 {
            return;
        }
        self.owned_before.clear();
        let mut n = 0u32;
        self.owned_before.push(0);
        for &i in tree.order() {
            n += u32::from(self.owns(i as usize));
            self.owned_before.push(n);
        }
        self.recount = false;
    }

    /// Starts, continues or completes captures for the frame seen by `camera` at `size`:
    /// the slots the view needs first ([`Field::next`]) within `budget` triangles (one
    /// slot at least), each capturing the objects of `tree` beyond the distance whose box
    /// centre is in it, and swapped in as it completes (module docs).
    pub fn step<S: Subject + Sync>(
        &mut self,
        camera: &Camera,
        size: (u32, u32),
        lighting: &engine::Lighting,
        (tree, objects): (&Tree, &[S]),
        budget: u64,
    ) -> &FarReport {
        let cfg = self.config;
        let mut report = FarReport {
            swaps: self.report.swaps,
            ..FarReport::default()
        };
        if self.owner.len() != objects.len() {
            self.owner = vec![NO_TILE; objects.len()];
            self.tiles.clear();
            (self.building, self.newest) = (None, None);
        }
        // A field being captured that the view left is given up (its tiles stay shown).
        if self
            .building
            .as_ref()
            .is_some_and(|f| !f.covers(camera, size))
        {
            self.building = None;
        }
        let stale = self.newest.as_ref().is_none_or(|f| {
            let px_per_unit = px_per_radian(camera, size.1) / f.distance.max(1e-3);
            f.eye.distance(camera.eye()) * px_per_unit > cfg.parallax || !f.covers(camera, size)
        });
        if self.building.is_none() && stale {
            let field = Field::new(camera, size, &cfg, self.fields);
            if field.covers(camera, size) {
                self.fields = self.fields.wrapping_add(1);
                self.newest = Some(field.clone());
                self.building = Some(field);
            }
        }
        if let Some(mut field) = self.building.take() {
            let work = take_slots(&mut field, camera, (tree, objects), budget, &cfg);
            report.triangles = work.iter().map(|w| w.2).sum();
            report.objects = work.iter().map(|w| w.1.len()).sum();
            report.tiles = work.len();
            report.in_view = work.iter().filter(|w| w.3).count();
            let seen = field.seen(cfg.lod_px);
            for tile in capture_tiles(&field, &work, (objects, seen), lighting, cfg.grow) {
                report.dropped += self.swap_in(tile);
            }
            report.pending = field.pending.len();
            if field.pending.is_empty() {
                // Complete: older fields' tiles are taken down (their objects the cut's).
                let old: Vec<usize> = (0..self.tiles.len())
                    .filter(|&t| {
                        self.tiles[t]
                            .as_ref()
                            .is_some_and(|x| x.field != field.number)
                    })
                    .collect();
                old.iter().for_each(|&t| self.take_down(t));
                report.swaps += 1;
            } else {
                self.building = Some(field);
            }
        }
        self.recount(tree);
        report.shown_tiles = self.tiles.iter().flatten().count();
        report.shown = report.shown_tiles > 0;
        report.owned = self.owner.iter().filter(|&&t| t != NO_TILE).count();
        self.report = report;
        &self.report
    }

    /// Shows `tile`, taking down every tile holding one of its objects; returns how many.
    fn swap_in(&mut self, tile: Tile) -> usize {
        let mut old: Vec<usize> = tile
            .objects
            .iter()
            .map(|&i| self.owner[i as usize])
            .filter(|&t| t != NO_TILE)
            .map(|t| t as usize)
            .collect();
        old.sort_unstable();
        old.dedup();
        old.iter().for_each(|&t| self.take_down(t));
        let place = match self.tiles.iter().position(Option::is_none) {
            Some(p) => p,
            None => {
                self.tiles.push(None);
                self.tiles.len() - 1
            }
        };
        for &i in &tile.objects {
            self.owner[i as usize] = place as u32;
        }
        self.tiles[place] = Some(tile);
        self.recount = true;
        old.len()
    }

    /// Takes down tile `t`: its objects are the cut's.
    fn take_down(&mut self, t: usize) {
        if let Some(tile) = self.tiles.get_mut(t).and_then(Option::take) {
            for &i in &tile.objects {
                if self.owner[i as usize] == t as u32 {
                    self.owner[i as usize] = NO_TILE;
                }
            }
            self.recount = true;
        }
    }

    /// The objects the shown tiles stand for (each once).
    pub fn captured(&self) -> impl Iterator<Item = u32> + '_ {
        (0..self.owner.len() as u32).filter(|&i| self.owns(i as usize))
    }

    /// The shown tiles with something in them that `frustum` sees.
    fn seen(&self, frustum: Frustum) -> impl Iterator<Item = &Tile> {
        self.tiles
            .iter()
            .flatten()
            .filter(move |t| t.sphere.is_some_and(|s| frustum.sees(s.center, s.radius)))
    }

    /// Triangles of the shown meshes that `frustum` sees.
    pub fn triangles_seen(&self, frustum: &Frustum) -> usize {
        self.seen(*frustum).map(|t| t.mesh.indices.len() / 3).sum()
    }

    /// The shown tiles seen by `frustum`, as draws (opaque, depth written).
    pub fn draws<'a>(&'a self, frustum: &Frustum, out: &mut Vec<Draw<'a>>) {
        for t in self.seen(*frustum) {
            out.push(Draw {
                mesh: &t.mesh,
                material: &self.material,
                transform: Mat4::IDENTITY,
            });
        }
    }

    /// Bytes the tiles' meshes hold.
    pub fn memory(&self) -> usize {
        self.tiles
            .iter()
            .flatten()
            .map(|t| {
                let m = &t.mesh;
                m.positions.capacity() * 12 + m.colors.capacity() * 16 + m.indices.capacity() * 4
            })
            .sum::<usize>()
            + self.owner.capacity() * 4
    }
}

/// How a field's captures draw its objects: from its eye at its pixels per radian, each at
/// its coarsest level of detail within `lod_px` pixels ([`Subject::draws_seen`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct Seen {
    pub(super) eye: Vec3,
    pub(super) px_per_radian: f32,
    pub(super) lod_px: f32,
}

impl Seen {
    pub(super) fn draws<'s, S: Subject>(&self, s: &'s S, out: &mut Vec<Draw<'s>>) {
        if self.lod_px > 0.0 {
            s.draws_seen(self.eye, self.px_per_radian, self.lod_px, out);
        } else {
            s.draws(out);
        }
    }

    /// Triangles `s` is captured with (`scratch`: a reused draw list).
    pub(super) fn triangles<'s, S: Subject>(&self, s: &'s S, scratch: &mut Vec<Draw<'s>>) -> u64 {
        scratch.clear();
        self.draws(s, scratch);
        scratch.iter().map(|d| d.mesh.triangle_count() as u64).sum()
    }
}

/// Pixels per radian of `camera`'s image `height` pixels high, at its centre.
pub(super) fn px_per_radian(camera: &Camera, height: u32) -> f32 {
    let [_, _, b, t] = camera.projection.extents();
    let near = camera.near_far().0;
    let half = ((t - b) * 0.5 / near.max(1e-6)).atan().max(1e-6);
    height as f32 * 0.5 / half
}

/// The objects of `tree` that are the far field's by `split` and whose bounds `camera`
/// sees, in the tree's order (pushed to `out`).
pub(super) fn far_objects<S: Subject>(
    tree: &Tree,
    objects: &[S],
    split: &Split,
    camera: &Camera,
    out: &mut Vec<u32>,
) {
    let nodes = tree.nodes();
    if nodes.is_empty() {
        return;
    }
    let frustum = Frustum::new(camera.clip_from_world());
    let mut stack = vec![0u32];
    while let Some(k) = stack.pop() {
        let node = nodes[k as usize];
        let s = node.sphere();
        if !frustum.sees(s.center, s.radius) || split.side(node.lo, node.hi) == Side::Near {
            continue;
        }
        if node.is_leaf() {
            for &i in tree.objects_of(k as usize) {
                let b = objects[i as usize].bounds();
                let far = tree.box_of(i as usize).is_some_and(|x| split.is_far(x));
                if far && frustum.sees(b.center, b.radius) {
                    out.push(i);
                }
            }
            continue;
        }
        stack.push(node.children[1]);
        stack.push(node.children[0]);
    }
}

/// Captures the slots `work` of `field` side by side on the pool, each its objects alone,
/// over the pixels their boxes cover, as a mesh of quads (same meshes at any thread count:
/// each tile is its own capture); returns them in `work`'s order.
fn capture_tiles<S: Subject + Sync>(
    field: &Field,
    work: &[Work],
    (objects, seen): (&[S], Seen),
    lighting: &engine::Lighting,
    grow: f32,
) -> Vec<Tile> {
    let split = field.split();
    work.par_iter()
        .map_init(
            || (Capturer::new(), DepthImage::new(0, 0, field.camera)),
            |(cap, image), (rect, members, _, _)| {
                let mut tile = Tile {
                    mesh: Mesh::default(),
                    sphere: None,
                    objects: members.clone(),
                    field: field.number,
                    split,
                };
                if members.is_empty() {
                    return tile;
                }
                let mut draws = Vec::new();
                for &i in members {
                    seen.draws(&objects[i as usize], &mut draws);
                }
                let camera = field.crop(rect.min, rect.max);
                let (w, h) = rect.size();
                cap.capture(draws, &camera, lighting, w, h, image);
                span_mesh(image, grow, &mut tile.mesh);
                tile.sphere = bounds_of(&tile.mesh.positions);
                tile
            },
        )
        .collect()
}

/// A sphere around `points` (their box's), `None` when there are none.
fn bounds_of(points: &[Vec3]) -> Option<Sphere> {
    let first = *points.first()?;
    let (lo, hi) = points
        .iter()
        .fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    Some(Sphere {
        center: (lo + hi) * 0.5,
        radius: (hi - lo).length() * 0.5,
    })
}
