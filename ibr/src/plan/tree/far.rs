//! The far field: every leaf of objects lying beyond a distance from an eye, drawn as
//! one image mesh with depth (Sillion, Drettakis and Bodelet 97; Shade et al. 96's far
//! nodes as a few cached images). The image is captured from the field's eye through a
//! frustum a margin wider than the view's, in tiles (crops of it, a tile over the budget
//! split in four) spread over frames within a per-frame budget of captured triangles, and
//! drawn as a mesh of quads at the pixels' depths, one per rectangle of pixels on one plane
//! of depth, textured with the tile's image ([`super::far_mesh`]; grown a fraction of a
//! pixel so neighbours on a surface leave no cracks as the eye moves): cut out where
//! uncovered, depth written, seen from any nearby eye with the parallax of its depths, so
//! near geometry and the far field occlude each other. (A mesh joining pixel
//! centres, [`crate::warp::mesh`], shrinks every silhouette by half a pixel and drops
//! features a pixel wide: the far field's objects are a few pixels wide.)
//!
//! Two fields are held: the one shown and the one being captured. A new capture starts
//! when the eye has moved far enough from the shown field's eye that its parallax at the
//! field's distance passes [`FarConfig::parallax`] pixels, or when the view leaves the
//! shown field's frustum; the shown field stays (stale but whole) until every tile of the
//! new one is taken, then they swap. Each object is in exactly one of the shown field or
//! the cut: [`Split`] is the rule both follow (an object is the field's when the box of its
//! leaf of the hierarchy lies wholly beyond the distance from the field's eye and inside the
//! field's frustum), so a view that turns past the field sees the rest drawn by the cut. A
//! leaf across the distance is the cut's whole, so the cut may draw it as one image.

use super::bvh::Tree;
use super::far_mesh::{image_texture, span_mesh, tile_material, Rect};
use crate::core::frame::recycle;
use crate::core::{Capturer, DepthImage, Frustum, Subject};
use engine::{Camera, Draw, Material, Mesh, Projection, Sphere};
use glam::{Mat4, Vec2, Vec3};
use rayon::prelude::*;
use std::sync::Arc;

/// Settings of a [`FarField`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FarConfig {
    /// Leaves of objects wholly farther than this from the field's eye are the far field's.
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
    /// Tiles captured,
    pub tiles: usize,
    /// the triangles they drew,
    pub triangles: u64,
    /// and objects.
    pub objects: usize,
    /// Whether a field is shown (the cut then leaves its objects to it).
    pub shown: bool,
    /// Fields completed and swapped in so far.
    pub swaps: usize,
    /// Triangles of the shown field's meshes drawn.
    pub mesh_triangles: usize,
    /// Tiles of the field being captured still to take.
    pub pending: usize,
    /// Pixels of parallax at the shown field's distance as the eye moved from its eye
    /// (0 with none shown): a re-capture starts only past [`FarConfig::parallax`] (or when
    /// the view leaves the field).
    pub parallax: f32,
}

/// One tile of a field: its pixel rectangle of the field's image and that as a mesh.
#[derive(Clone, Debug)]
struct Tile {
    min: (u32, u32),
    max: (u32, u32),
    mesh: Mesh,
    /// The mesh's material, its image as a texture (`None`: empty).
    material: Option<Material>,
    /// Bounds of the mesh's points (`None`: empty).
    sphere: Option<Sphere>,
    /// The objects captured into it.
    objects: Vec<u32>,
}

/// One capture of the far field: its eye, frustum and tiles (the first `taken` captured).
#[derive(Clone, Debug)]
struct Field {
    eye: Vec3,
    camera: Camera,
    size: (u32, u32),
    distance: f32,
    tiles: Vec<Tile>,
    taken: usize,
}

impl Tile {
    fn new(min: (u32, u32), max: (u32, u32)) -> Tile {
        Tile {
            min,
            max,
            mesh: Mesh::default(),
            material: None,
            sphere: None,
            objects: Vec::new(),
        }
    }

    /// Its camera, a crop of the field's.
    fn camera(&self, field: &Camera, (w, h): (u32, u32)) -> Camera {
        let min = Vec2::new(self.min.0 as f32, self.min.1 as f32);
        let max = Vec2::new(self.max.0 as f32, self.max.1 as f32);
        field.crop(min, max, w, h)
    }

    fn size(&self) -> (u32, u32) {
        (self.max.0 - self.min.0, self.max.1 - self.min.1)
    }

    /// Its four quarters (a tile of a pixel a side stays whole).
    fn quarters(&self) -> Vec<Tile> {
        let (mx, my) = ((self.min.0 + self.max.0) / 2, (self.min.1 + self.max.1) / 2);
        if mx == self.min.0 || my == self.min.1 {
            return vec![self.clone()];
        }
        vec![
            Tile::new(self.min, (mx, my)),
            Tile::new((mx, self.min.1), (self.max.0, my)),
            Tile::new((self.min.0, my), (mx, self.max.1)),
            Tile::new((mx, my), self.max),
        ]
    }
}

impl Field {
    /// A field at `camera`'s eye, its frustum the view's widened on each side by a whole
    /// number of the view's pixels (at least `margin` times the view's extents), its image
    /// the view's `width` x `height` grown alike: seen from its own eye, the field's
    /// pixels are the view's (a margin of half a pixel, as 1.25 x 180 rows gave, put every
    /// texel half a pixel off the view's pixels), cut in `n` x `n` tiles.
    fn new(camera: &Camera, (width, height): (u32, u32), cfg: &FarConfig) -> Field {
        let m = cfg.margin.max(1.0);
        let [l, r, b, t] = camera.projection.extents();
        let (near, far) = camera.near_far();
        let (width, height) = (width.max(1), height.max(1));
        let (px, py) = ((r - l) / width as f32, (t - b) / height as f32);
        let side = |n: u32| (n as f32 * (m - 1.0) * 0.5).ceil() as u32;
        let (ex, ey) = (side(width), side(height));
        let whole = Camera {
            view: camera.view,
            projection: Projection::Frustum {
                left: l - ex as f32 * px,
                right: r + ex as f32 * px,
                bottom: b - ey as f32 * py,
                top: t + ey as f32 * py,
                near,
                far,
            },
        };
        let (w, h) = (width + 2 * ex, height + 2 * ey);
        let n = cfg.tiles.clamp(1, 64);
        let mut tiles = Vec::with_capacity((n * n) as usize);
        for ty in 0..n {
            for tx in 0..n {
                let (x0, x1) = (w * tx / n, w * (tx + 1) / n);
                let (y0, y1) = (h * ty / n, h * (ty + 1) / n);
                if x1 > x0 && y1 > y0 {
                    tiles.push(Tile::new((x0, y0), (x1, y1)));
                }
            }
        }
        Field {
            eye: camera.eye(),
            camera: whole,
            size: (w, h),
            distance: cfg.distance,
            tiles,
            taken: 0,
        }
    }

    /// How this field's captures draw objects, at `lod_px` pixels of deviation.
    fn seen(&self, lod_px: f32) -> Seen {
        Seen {
            eye: self.eye,
            px_per_radian: px_per_radian(&self.camera, self.size.1),
            lod_px,
        }
    }

    /// Whether everything `camera` sees beyond the field's distance lies in the field's
    /// frustum: the view's corner rays at that distance and at the far plane project
    /// inside it.
    fn covers(&self, camera: &Camera, (w, h): (u32, u32)) -> bool {
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

    fn split(&self) -> Split {
        Split {
            eye: self.eye,
            distance: self.distance,
            frustum: Frustum::new(self.camera.clip_from_world()),
        }
    }

    fn is_complete(&self) -> bool {
        self.taken == self.tiles.len()
    }
}

/// The far field of a hierarchy's objects (module docs).
#[derive(Debug)]
pub struct FarField {
    /// Settings; may be changed between frames (a new distance applies from the next field).
    pub config: FarConfig,
    shown: Option<Field>,
    building: Option<Field>,
    /// What the last [`FarField::step`] did.
    pub report: FarReport,
    /// Scratch: the tiles of this frame's capture and each one's objects.
    work: Vec<(usize, Vec<u32>)>,
    /// What the captures render with, kept frame to frame ([`capture_tiles`]).
    workers: Vec<Worker>,
}

/// One capturer of tiles and its scratch, reused frame to frame: a capturer made for each
/// frame's tile allocated its renderer's vertex buffers, targets and tile memory afresh,
/// and the fresh pages' faults and clearing were a third of the far field's capture time
/// (`perf record --call-graph dwarf` of `bench budget --scene world`, session 18).
#[derive(Debug, Default)]
struct Worker {
    capturer: Capturer,
    image: Option<DepthImage>,
    scratch: (Vec<bool>, Vec<Rect>),
    draws: Vec<Draw<'static>>,
}

/// Which objects a shown field stands for (module docs): the field's eye, distance and
/// frustum.
#[derive(Clone, Copy, Debug)]
pub struct Split {
    /// The eye the field was captured from,
    pub eye: Vec3,
    /// the distance beyond which (the whole box of their leaf) objects are its,
    pub distance: f32,
    /// and the frustum it was captured through (the leaf's whole box inside).
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
    /// Where the node box `lo..hi` lies (its objects' boxes inside it). A leaf's objects
    /// are the far field's when it is [`Side::Far`], else the cut's (a leaf is never split).
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

impl FarField {
    /// A far field with nothing captured yet.
    pub fn new(config: FarConfig) -> Self {
        FarField {
            config,
            shown: None,
            building: None,
            report: FarReport::default(),
            work: Vec::new(),
            workers: Vec::new(),
        }
    }

    /// The rule the cut and the field share while a field is shown ([`Split`]).
    pub fn split(&self) -> Option<Split> {
        self.shown.as_ref().map(Field::split)
    }

    /// Starts, continues or swaps in captures for the frame seen by `camera` at `size`,
    /// taking tiles in order within `budget` triangles (one at least), each capturing the
    /// objects of `tree` beyond the distance in its frustum. Shows no field while the shown
    /// one does not cover the view.
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
        let parallax = self.shown.as_ref().map_or(0.0, |f| {
            let px_per_unit = px_per_radian(camera, size.1) / f.distance.max(1e-3);
            f.eye.distance(camera.eye()) * px_per_unit
        });
        report.parallax = parallax;
        let stale = self
            .shown
            .as_ref()
            .is_none_or(|f| parallax > cfg.parallax || !f.covers(camera, size));
        if self.building.is_none() && stale {
            let field = Field::new(camera, size, &cfg);
            self.building = field.covers(camera, size).then_some(field);
        }
        if let Some(field) = &mut self.building {
            self.work.clear();
            let mut spent = 0u64;
            let split = field.split();
            let seen = field.seen(cfg.lod_px);
            let mut scratch = Vec::new();
            while field.taken + self.work.len() < field.tiles.len() {
                let k = field.taken + self.work.len();
                let mut members = Vec::new();
                let tile = &field.tiles[k];
                let camera = tile.camera(&field.camera, field.size);
                far_objects(tree, objects, &split, &camera, &mut members);
                let tris: u64 = members
                    .iter()
                    .map(|&i| seen.triangles(&objects[i as usize], &mut scratch))
                    .sum();
                if tris > budget {
                    let quarters = tile.quarters();
                    if quarters.len() > 1 {
                        field.tiles.splice(k..=k, quarters);
                        continue;
                    }
                }
                if !self.work.is_empty() && spent + tris > budget {
                    break;
                }
                spent += tris;
                report.objects += members.len();
                self.work.push((k, members));
            }
            let workers = &mut self.workers;
            capture_tiles(
                field,
                &self.work,
                workers,
                (objects, seen),
                lighting,
                cfg.grow,
            );
            field.taken += self.work.len();
            report.tiles = self.work.len();
            report.triangles = spent;
            report.pending = field.tiles.len() - field.taken;
            if field.is_complete() {
                self.shown = self.building.take();
                report.swaps += 1;
                report.pending = 0;
            }
        }
        report.shown = self.shown.is_some();
        self.report = report;
        &self.report
    }

    /// The objects the shown field's tiles captured (an object once per tile it shows in).
    pub fn captured(&self) -> impl Iterator<Item = u32> + '_ {
        let tiles = self.shown.as_ref().map_or(&[][..], |f| &f.tiles[..]);
        tiles.iter().flat_map(|t| t.objects.iter().copied())
    }

    /// The shown field's tiles with something in them that `frustum` sees.
    fn seen(&self, frustum: Frustum) -> impl Iterator<Item = &Tile> {
        let tiles = self.shown.as_ref().map_or(&[][..], |f| &f.tiles[..]);
        tiles
            .iter()
            .filter(move |t| t.sphere.is_some_and(|s| frustum.sees(s.center, s.radius)))
    }

    /// Triangles of the shown field's meshes that `frustum` sees.
    pub fn triangles_seen(&self, frustum: &Frustum) -> usize {
        self.seen(*frustum).map(|t| t.mesh.indices.len() / 3).sum()
    }

    /// The shown field's tiles seen by `frustum`, as draws (opaque, depth written).
    pub fn draws<'a>(&'a self, frustum: &Frustum, out: &mut Vec<Draw<'a>>) {
        for t in self.seen(*frustum) {
            if let Some(material) = &t.material {
                out.push(Draw {
                    mesh: &t.mesh,
                    material,
                    transform: Mat4::IDENTITY,
                });
            }
        }
    }

    /// Bytes the fields' meshes hold.
    pub fn memory(&self) -> usize {
        let field = |f: &Option<Field>| {
            f.as_ref().map_or(0, |f| {
                f.tiles
                    .iter()
                    .map(|t| {
                        let m = &t.mesh;
                        // The texture: packed bytes and the sampler's 16-bit copy, 12 a texel.
                        let (w, h) = t.size();
                        let texels = if t.material.is_some() { w * h } else { 0 };
                        m.positions.capacity() * 12
                            + m.uvs.capacity() * 8
                            + m.indices.capacity() * 4
                            + texels as usize * 12
                    })
                    .sum()
            })
        };
        field(&self.shown) + field(&self.building)
    }
}

/// How a field's captures draw its objects: from its eye at its pixels per radian, each at
/// its coarsest level of detail within `lod_px` pixels ([`Subject::draws_seen`]).
#[derive(Clone, Copy, Debug)]
struct Seen {
    eye: Vec3,
    px_per_radian: f32,
    lod_px: f32,
}

impl Seen {
    fn draws<'s, S: Subject>(&self, s: &'s S, out: &mut Vec<Draw<'s>>) {
        if self.lod_px > 0.0 {
            s.draws_seen(self.eye, self.px_per_radian, self.lod_px, out);
        } else {
            s.draws(out);
        }
    }

    /// Triangles `s` is captured with (`scratch`: a reused draw list).
    fn triangles<'s, S: Subject>(&self, s: &'s S, scratch: &mut Vec<Draw<'s>>) -> u64 {
        scratch.clear();
        self.draws(s, scratch);
        scratch.iter().map(|d| d.mesh.triangle_count() as u64).sum()
    }
}

/// Pixels per radian of `camera`'s image `height` pixels high, at its centre.
fn px_per_radian(camera: &Camera, height: u32) -> f32 {
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
            if split.side(node.lo, node.hi) != Side::Far {
                continue;
            }
            for &i in tree.objects_of(k as usize) {
                let b = objects[i as usize].bounds();
                if frustum.sees(b.center, b.radius) {
                    out.push(i);
                }
            }
            continue;
        }
        stack.push(node.children[1]);
        stack.push(node.children[0]);
    }
}

/// Captures the tiles `work` (tile, its objects) of `field` side by side on the pool, each
/// as a mesh of quads (same meshes at any thread count: each tile is its own capture), in
/// one run of consecutive tiles per worker of `workers` (as many as the pool has threads,
/// kept frame to frame).
fn capture_tiles<S: Subject + Sync>(
    field: &mut Field,
    work: &[(usize, Vec<u32>)],
    workers: &mut Vec<Worker>,
    (objects, seen): (&[S], Seen),
    lighting: &engine::Lighting,
    grow: f32,
) {
    let Some(first) = work.first().map(|w| w.0) else {
        return;
    };
    let (whole, size) = (field.camera, field.size);
    let tiles = &mut field.tiles[first..first + work.len()];
    let n = rayon::current_num_threads().clamp(1, work.len());
    if workers.len() < n {
        workers.resize_with(n, Worker::default);
    }
    let run = work.len().div_ceil(n);
    tiles
        .par_chunks_mut(run)
        .zip(work.par_chunks(run))
        .zip(workers.par_iter_mut())
        .with_max_len(1)
        .for_each(|((tiles, work), w)| {
            let image = w.image.get_or_insert_with(|| DepthImage::new(0, 0, whole));
            for (tile, (_, members)) in tiles.iter_mut().zip(work) {
                tile.sphere = None;
                tile.material = None;
                tile.mesh.clear();
                tile.objects.clone_from(members);
                if members.is_empty() {
                    continue;
                }
                let mut draws = recycle(std::mem::take(&mut w.draws));
                for &i in members {
                    seen.draws(&objects[i as usize], &mut draws);
                }
                let camera = tile.camera(&whole, size);
                let (tw, th) = tile.size();
                w.capturer
                    .capture(draws.iter().copied(), &camera, lighting, tw, th, image);
                w.draws = recycle(draws);
                span_mesh(image, grow, &mut tile.mesh, &mut w.scratch);
                tile.sphere = bounds_of(&tile.mesh.positions);
                if tile.sphere.is_some() {
                    tile.material = image_texture(image).map(|t| tile_material(Arc::new(t)));
                }
            }
        });
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
