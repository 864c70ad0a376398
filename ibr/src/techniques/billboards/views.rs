//! A billboard baked from many directions ([`ViewAtlas`]): an object's orthographic images
//! from a grid of azimuths and elevations around its bounding sphere, in one atlas, and
//! the cell to show on a quad facing the eye ([`ViewAtlas::region`]).
//!
//! One image baked from one side shows that side (its lit face, its outline) from
//! everywhere; an upright quad seen from above is squashed. Here the quad faces the eye
//! through the sphere's centre (a world-facing billboard, up as near +Y as it can be,
//! framing the sphere's `2r x 2r` square) and shows the image baked from the direction
//! nearest the eye's, so it shows the side seen, lit as the object is, at any elevation
//! the grid covers. The cost is memory: one `px` square per direction.
//!
//! Drawn as cutouts ([`ViewAtlas::material`], [`ViewAtlas::order`]): alpha-tested, opaque
//! where a view's alpha is at least `CUTOFF` (0.5), writing depth, the quads near to far, so
//! the fragments of a sprite hidden behind a nearer one (or any opaque surface) fail the
//! depth test and are never shaded; blended, every sprite shades its whole quad.
//!
//! With depth ([`ViewAtlas::relief`], a coarse nailboard after Schaufler 97): each view
//! also keeps the object's depth from its bake on a `RELIEF` x `RELIEF` grid of nodes over
//! its square, and the quad is drawn as that grid with every node moved toward the eye
//! along its own ray by the surface's offset from the image's plane (so the image does not
//! move on screen; the plane faces the view's bake direction through the object's
//! [`ViewAtlas::pivot`], [`super::mount`]). Sprites then hide one another, and meshes hide them, about where the
//! objects' surfaces do, not at their centres' depth: two crowns overlapping on screen
//! are ordered by their fronts, and a crown behind a near tree's mesh is cut along it.
//! A sprite small on screen ([`ViewAtlas::coarse_px`]) takes every 2nd column of the
//! grid's nodes (16 triangles, not 32), all of its rows: its outline stays the trim's.
//!
//! Trimmed ([`ViewAtlas::trims`], [`Trim`]): the grid's nodes are spread over the texels a
//! view covers (its rows, and per node row its columns, grown a screen pixel), not the
//! whole square, so the clear texels around a tall tree or a round crown, which an
//! alpha-tested sprite samples and discards like any other, are not drawn.
//!
//! As nailboards proper ([`ViewAtlas::nailboard`], [`ViewAtlas::nailboards`]): each view's
//! depth kept per texel in an offset image beside the atlas ([`ViewAtlas::depth_texture`]),
//! and each sprite drawn flat (its trim's outline, 8 triangles) at its view's nearest
//! surface, its fragments' depth moved back per texel by the engine
//! ([`engine::DepthOffset`]). Off in the showcase: measured slower there (BENCHMARKS.md).

use super::bake::{bake_bounds, bake_camera};
use super::mount::Mount;
use super::nailboard::{offset_image, remeasure, DEPTH_SPAN};
use super::trim::{surface, Trim};
use crate::core::{orient, Basis, Billboard, Capturer, Facing, Size, UvRect, View};
use engine::{
    AlphaMode, DepthOffset, Draw, Encoding, Lighting, Material, Mesh, Rgba, Sphere, Texture,
};
use glam::{Vec2, Vec3};
use std::f32::consts::{PI, TAU};
use std::sync::Arc;

/// Texels of transparent margin framed around the sphere in every cell, so the mipmaps
/// of one cell blend no neighbour's texels in at the levels a quad of its size uses.
const MARGIN: f32 = 0.04;

/// The alpha at which a view's texel is kept ([`ViewAtlas::material`]): the mip-filtered
/// alpha of a pixel is about the share of it the object covers, so a pixel is drawn where
/// the object covers at least half of it, as a rasterised mesh covers the pixels whose
/// centres it holds.
const CUTOFF: f32 = 0.5;

/// Nodes a side of each view's depth grid ([`ViewAtlas::relief`]): 5 x 5 vertices, 32
/// triangles a sprite. Each node stands at the nearest surface near it ([`NODE_REACH`]),
/// so the coarser the grid the farther a trunk's foot or a crown's rim is drawn in front
/// of where it is, over the nearer trees behind it: on the showcase's forest (640 x 360
/// tour, session 16) 3 x 3 measured 26.17 / 22.95 dB and 2.78 fragments tested a pixel,
/// 5 x 5 26.85 / 23.88 dB and 2.63 (session 9: 4 x 4 0.2 dB more than 3 x 3). Session 19,
/// with the nodes' reach: 5 x 5 27.33 / 24.33 dB, 7 x 7 27.82 / 24.86 dB and the tour's
/// fragments tested / shaded a pixel 2.30 / 1.90 -> 2.21 / 1.85, but 17,555 -> 39,498
/// forest triangles a frame, the `forest` step 0.46 -> 0.83 ms and the whole run's CPU
/// 3.5% more (load 14): not kept.
pub(crate) const RELIEF: usize = 5;

/// How far from a node (in node spacings, each way) the texels lie whose nearest surface
/// is its depth ([`grid`]). Half a spacing (every texel to its nearest node, as before
/// session 19) stood a node at a crown's front when its share only reached the crown's
/// flank, pulling rims and trunks' feet in front of the nearer trees beside them; too
/// little and a node misses the surface between nodes (on the 640 x 360 tour with the 5 x
/// 5 grid, PSNR mean / worst dB: 0.5 26.92 / 23.91, 0.425 27.09 / 24.21, 0.375 27.20 /
/// 24.46, 0.35 27.25 / 24.49, 0.3 27.33 / 24.33, 0.25 27.28 / 23.99, 0.125 26.83 / 23.14).
const NODE_REACH: f32 = 0.3;

/// An object's images from `azimuths` evenly spaced directions about +Y (the first along
/// +X, then toward +Z) at each of `elevations` (radians above the horizon), in one atlas:
/// row `j` holds elevation `j`, column `k` azimuth `k`.
#[derive(Clone, Debug)]
pub struct ViewAtlas {
    /// The atlas: premultiplied unorm (linear) bytes with mipmaps, `azimuths * px` by
    /// `elevations * px`, sampled from its bytes (4 a texel; an sRGB atlas is sampled from
    /// a 16-bit linear copy, 8 a texel: on the showcase's forest the unorm atlas measured
    /// the same PSNR within 0.02 dB and 200 MB less resident).
    pub texture: Arc<Texture>,
    /// The sphere each image frames, enlarged by the cells' margin: a quad facing the eye
    /// through its centre, `2 * radius` square, shows a cell at the object's size.
    pub bounds: Sphere,
    /// Directions about the vertical axis.
    pub azimuths: usize,
    /// Elevations baked, radians, ascending.
    pub elevations: Vec<f32>,
    /// Per view (row-major as the atlas: elevation `j`, azimuth `k` at `j * azimuths +
    /// k`), the surface's offset toward the viewer from the plane through the centre, in
    /// `bounds.radius`, at each node of a `RELIEF` x `RELIEF` grid over the view's square
    /// (row-major, top row first as the image): the nearest surface among the texels
    /// near the node ([`NODE_REACH`]), 0 (the centre plane, where a convex object's
    /// outline lies) where they are empty. A trimmed sprite's nodes
    /// ([`ViewAtlas::trims`]) take this surface where they lie ([`super::trim::surface`]).
    pub depth: Vec<[f32; RELIEF * RELIEF]>,
    /// Per view (in the same order), the part of its square a sprite is drawn over: the
    /// grid's nodes spread over its covered texels ([`Trim`]), not the whole square, so
    /// the clear texels around a tall tree or a round crown are neither sampled nor tested.
    pub trims: Vec<Trim>,
    /// For an object turned about the vertical and lit by one sun
    /// ([`ViewAtlas::bake_turned`]): the sun's azimuth (radians from +X toward +Z). The
    /// columns then span the half turn from it (column `k` at `k / (azimuths - 1)` of
    /// it), and the other half shows them mirrored: seen from `a` on one side of the sun
    /// such an object shows the image of `a` on the other, left for right.
    pub mirror: Option<f32>,
    /// Where each view's image stands ([`Mount`], [`ViewAtlas::relief`]): on the plane
    /// facing its bake direction through the point of the vertical axis `pivot` (in
    /// `bounds.radius`) above the centre, where the object's outline lies (0, as baked:
    /// through the centre).
    pub pivot: f32,
    /// `(top, from)`: the pivot of the views seen from straight above (`top`, in
    /// `bounds.radius`), reached linearly from `pivot` over the elevations above `from`
    /// (radians), for an object whose outline from above lies lower (a pine's lowest
    /// cone's rim); `None`: `pivot` at every elevation ([`ViewAtlas::pivot_at`]).
    pub pivot_steep: Option<(f32, f32)>,
    /// The height on screen (pixels) under which [`ViewAtlas::relief`] draws a sprite with
    /// every 2nd column of its grid's nodes, every row kept (3 x 5 nodes, 16 triangles,
    /// not 32; the same outline, its depth across interpolated between 3 nodes, not 5).
    /// 0 (as baked): every sprite the whole grid.
    pub coarse_px: f32,
    /// Per view, the offset image of its surface ([`super::nailboard::offset_image`]):
    /// premultiplied unorm bytes laid out as `texture`, red over alpha the texel's depth
    /// behind `depth_near` over [`super::nailboard::DEPTH_SPAN`] radii.
    pub depth_texture: Arc<Texture>,
    /// The nearest covered surface's offset toward the viewer over every view, in
    /// `bounds.radius`: where a nailboard's quad stands ([`ViewAtlas::nailboards`]), and
    /// what `depth_texture`'s offsets are measured back from.
    pub depth_near: f32,
    /// Draw sprites as nailboards ([`ViewAtlas::nailboards`], flat, with per-texel
    /// depth; [`ViewAtlas::material`] then carries the offset image) instead of as depth
    /// grids ([`ViewAtlas::relief`]). `false` as baked.
    pub nailboard: bool,
    /// With `nailboard`: each fragment shows the texel whose surface lies on its own ray
    /// ([`engine::DepthOffset::parallax`], this its tolerance), not the one straight
    /// behind it on the view's plane; the views then stand on the plane through the centre
    /// (`pivot` and `pivot_steep` are not read: they placed the plane where the outline's
    /// surface lies, which the search does texel by texel). `None` as baked.
    pub parallax: Option<f32>,
    /// With `nailboard`: the coarsest level of detail read ([`engine::DepthOffset::max_lod`]);
    /// `f32::INFINITY` as baked.
    pub max_lod: f32,
}

impl ViewAtlas {
    /// Bakes `draws` (in world space, under `lighting`) framed by `bounds` from every
    /// direction of the grid, each image `px` square. Elevations are clamped to +-89
    /// degrees (a bake needs a horizontal component to keep its up) and sorted.
    pub fn bake<'a>(
        draws: &[Draw<'a>],
        lighting: &Lighting,
        bounds: Sphere,
        azimuths: usize,
        elevations: &[f32],
        px: u32,
    ) -> ViewAtlas {
        Self::bake_from(draws, lighting, bounds, azimuths, elevations, px, None)
    }

    /// As [`ViewAtlas::bake`], for an object turned about the vertical (alike from every
    /// azimuth but for its light) lit by `lighting`'s first directional light (the sun)
    /// and its ambient: `azimuths` (at least 2) columns over the half turn from the sun's
    /// azimuth, the other half mirrored ([`ViewAtlas::mirror`]), so the views are half as
    /// far apart as `bake`'s for the same memory. Objects not turned, or lit by more than
    /// one direction, show the wrong side on the mirrored half.
    pub fn bake_turned<'a>(
        draws: &[Draw<'a>],
        lighting: &Lighting,
        bounds: Sphere,
        azimuths: usize,
        elevations: &[f32],
        px: u32,
    ) -> ViewAtlas {
        let sun = lighting.lights.iter().find_map(|l| match l {
            engine::Light::Directional { direction, .. } => Some(-*direction),
            _ => None,
        });
        let sun = sun.unwrap_or(Vec3::X);
        let mirror = sun.z.atan2(sun.x);
        let mirror = if mirror.is_finite() { mirror } else { 0.0 };
        let azimuths = azimuths.max(2);
        Self::bake_from(
            draws,
            lighting,
            bounds,
            azimuths,
            elevations,
            px,
            Some(mirror),
        )
    }

    fn bake_from<'a>(
        draws: &[Draw<'a>],
        lighting: &Lighting,
        bounds: Sphere,
        azimuths: usize,
        elevations: &[f32],
        px: u32,
        mirror: Option<f32>,
    ) -> ViewAtlas {
        let px = px.max(4);
        let azimuths = azimuths.max(1);
        let limit = 89f32.to_radians();
        let mut elevations: Vec<f32> = elevations
            .iter()
            .filter(|e| e.is_finite())
            .map(|e| e.clamp(-limit, limit))
            .collect();
        if elevations.is_empty() {
            elevations.push(0.0);
        }
        elevations.sort_by(f32::total_cmp);
        let b = bake_bounds(bounds);
        let bounds = Sphere {
            center: b.center,
            radius: b.radius * (1.0 + MARGIN),
        };
        let (w, h) = (azimuths as u32 * px, elevations.len() as u32 * px);
        let mut texels = vec![0u32; w as usize * h as usize];
        let (mut capturer, mut row, mut z) = (Capturer::new(), Vec::new(), Vec::new());
        let mut depth = Vec::with_capacity(azimuths * elevations.len());
        let mut trims = Vec::with_capacity(azimuths * elevations.len());
        let mut offsets = vec![f32::NEG_INFINITY; (px * px) as usize];
        let mut alpha = vec![0u8; (px * px) as usize];
        let mut raw = vec![f32::NAN; (px * px) as usize];
        let mut view_offsets = vec![0u32; (px * px) as usize];
        let mut depth_texels = vec![0u32; w as usize * h as usize];
        let mut nearest = Vec::with_capacity(azimuths * elevations.len());
        for (j, &e) in elevations.iter().enumerate() {
            for k in 0..azimuths {
                let a = column_azimuth(azimuths, k, mirror);
                let to_viewer = Vec3::new(a.cos() * e.cos(), e.sin(), a.sin() * e.cos());
                let camera = bake_camera(bounds, to_viewer);
                let t = capturer.render(
                    draws.iter().copied(),
                    &camera,
                    lighting,
                    px,
                    px,
                    Encoding::Unorm,
                );
                for y in 0..px {
                    t.read_row(y, &mut row, &mut z);
                    let at = (j * px as usize + y as usize) * w as usize + k * px as usize;
                    texels[at..at + px as usize].copy_from_slice(&row);
                    for (x, (&c, &d)) in row.iter().zip(&z).enumerate() {
                        // Reversed orthographic depth, 1 at the near plane (`BAKE_DISTANCE
                        // - 1.5` radii from the centre) and 0 at the far one (+ 1.5): an
                        // offset toward the viewer of `3 d - 1.5` radii.
                        alpha[(y * px) as usize + x] = (c >> 24) as u8;
                        raw[(y * px) as usize + x] = if d > 0.0 { 3.0 * d - 1.5 } else { f32::NAN };
                        let covered = (c >> 24) as f32 >= CUTOFF * 255.0;
                        offsets[(y * px) as usize + x] = if covered {
                            3.0 * d - 1.5
                        } else {
                            f32::NEG_INFINITY
                        };
                    }
                }
                let trim = Trim::of(&alpha, px as usize);
                let covered = |i: usize| offsets[i].is_finite();
                nearest.push(offset_image(&alpha, &raw, covered, &mut view_offsets));
                for y in 0..px as usize {
                    let at = (j * px as usize + y) * w as usize + k * px as usize;
                    let row = &view_offsets[y * px as usize..(y + 1) * px as usize];
                    depth_texels[at..at + px as usize].copy_from_slice(row);
                }
                depth.push(grid(&offsets, px as usize));
                trims.push(trim);
            }
        }
        let texture =
            Texture::from_packed(w, h, texels, Encoding::Unorm, true).expect("a non-empty atlas");
        let depth_near = nearest.iter().copied().fold(f32::NEG_INFINITY, f32::max);
        let depth_near = if depth_near.is_finite() {
            depth_near
        } else {
            0.0
        };
        remeasure(
            &mut depth_texels,
            w as usize,
            px as usize,
            &nearest,
            depth_near,
        );
        let depth_texture = Texture::from_packed(w, h, depth_texels, Encoding::Unorm, true)
            .expect("a non-empty atlas");
        ViewAtlas {
            texture: Arc::new(texture),
            bounds,
            azimuths,
            elevations,
            depth,
            trims,
            mirror,
            pivot: 0.0,
            pivot_steep: None,
            coarse_px: 0.0,
            depth_texture: Arc::new(depth_texture),
            depth_near,
            nailboard: false,
            parallax: None,
            max_lod: f32::INFINITY,
        }
    }

    /// The material that draws the atlas's views on billboards: unlit (the views are baked
    /// lit), the billboard's tint times the texture, alpha-tested at `CUTOFF` (0.5) with depth
    /// writes, in the opaque pass (draw the quads in [`ViewAtlas::order`]). With
    /// [`ViewAtlas::nailboard`], its depth offset is the views' offset image, in the
    /// quads' normals' unit ([`ViewAtlas::nailboards`]).
    pub fn material(&self) -> Material {
        Material {
            alpha_mode: AlphaMode::Mask { cutoff: CUTOFF },
            vertex_colors: true,
            // In units of the quad's world width per unit of u: a cell (1 / azimuths of
            // u) spans 2 radii.
            depth_offset: self.nailboard.then(|| DepthOffset {
                texture: self.depth_texture.clone(),
                scale: DEPTH_SPAN * 0.5 / self.azimuths as f32,
                lift: self.depth_near * 0.5 / self.azimuths as f32,
                parallax: self.parallax,
                max_lod: self.max_lod,
            }),
            ..Material::unlit(Rgba::WHITE).with_texture(self.texture.clone())
        }
    }

    /// Each of `items` a sprite can show (a world size, a finite position) with where it
    /// stands: its world-facing basis, the view shown, that view's [`Mount`] and the pivot's
    /// height; shared by [`ViewAtlas::relief`] and [`ViewAtlas::nailboards`].
    pub(super) fn placed<'a>(
        &'a self,
        items: &'a [Billboard],
        view: &'a View,
    ) -> impl Iterator<Item = Placed<'a>> + 'a {
        items.iter().filter_map(move |b| {
            let Size::World(size) = b.size else {
                return None;
            };
            if !b.position.is_finite() {
                return None;
            }
            let basis = orient(Facing::World { up: Vec3::Y }, view, b.position);
            let view_index = self.view_of(b.region);
            let e = self.elevations[view_index / self.azimuths];
            Some(Placed {
                b,
                size,
                basis,
                view_index,
                mount: Mount::new(e, basis.normal, basis.right),
                pivot: match (self.nailboard, self.parallax) {
                    (true, Some(_)) => 0.0,
                    _ => self.pivot_at(e) * 0.5 * size.y,
                },
            })
        })
    }

    /// Puts `items` near to far from `eye` (by distance; ties by position, so the order is
    /// one at any thread count), the order in which cutouts hide the most before they are
    /// shaded: each sprite's hidden fragments then fail the depth test written by the
    /// nearer ones. Allocates nothing.
    pub fn order(items: &mut [Billboard], eye: Vec3) {
        items.sort_unstable_by(|a, b| {
            let (da, db) = (
                a.position.distance_squared(eye),
                b.position.distance_squared(eye),
            );
            da.total_cmp(&db)
                .then(a.position.x.total_cmp(&b.position.x))
                .then(a.position.z.total_cmp(&b.position.z))
                .then(a.position.y.total_cmp(&b.position.y))
        });
    }

    /// The cell baked from the direction nearest `to_eye` (from the object toward the eye,
    /// any length): the nearest azimuth, and the nearest elevation of the grid. A zero or
    /// non-finite direction gives the first cell.
    /// With [`ViewAtlas::mirror`], a cell shown mirrored (left for right) has its `min.x`
    /// and `max.x` swapped.
    pub fn region(&self, to_eye: Vec3) -> UvRect {
        let (k, j, flip) = self.cell_mirrored(to_eye);
        let size = Vec2::new(
            1.0 / self.azimuths as f32,
            1.0 / self.elevations.len() as f32,
        );
        let min = Vec2::new(k as f32, j as f32) * size;
        let max = min + size;
        if flip {
            UvRect {
                min: Vec2::new(max.x, min.y),
                max: Vec2::new(min.x, max.y),
            }
        } else {
            UvRect { min, max }
        }
    }

    /// Writes `items` (world-facing billboards showing this atlas's views: `region` one
    /// of [`ViewAtlas::region`]'s cells, `size` in world units; a mirrored cell drawn left
    /// for right) into `mesh` (cleared) as seen from `view`, each as its view's depth grid
    /// ([`ViewAtlas::depth`]): the view's square, as wide as the quad
    /// [`crate::core::corners`] would make, standing on its [`Mount`] (the plane facing
    /// the view's bake direction at the eye's azimuth through the axis point
    /// [`ViewAtlas::pivot`]), trimmed to the view's covered texels ([`ViewAtlas::trims`])
    /// and split into `RELIEF` x `RELIEF` vertices, each moved along its ray toward the
    /// eye until it stands the view's offset (scaled from the atlas's radius to the quad's
    /// half width) in front of that plane. On screen it covers the plane's pixels that
    /// show covered texels, with the same texels; its depth is the object's.
    /// Items with a non-finite position or not world-sized are left out. Returns the
    /// sprites written. With [`ViewAtlas::nailboard`], writes [`ViewAtlas::nailboards`]
    /// instead.
    pub fn relief(&self, items: &[Billboard], view: &View, mesh: &mut Mesh) -> usize {
        if self.nailboard {
            return self.nailboards(items, view, mesh);
        }
        mesh.clear();

        let mut n = 0;
        for Placed {
            b,
            size,
            basis,
            view_index,
            mount,
            pivot,
        } in self.placed(items, view)
        {
            let pixel = view.pixel_size_at(b.position).unwrap_or(0.0);
            // A sprite under `coarse_px` tall on screen: every 2nd column of nodes; every
            // row (the trim's outline, and so the fragments drawn, are the whole grid's).
            let step = if size.y < self.coarse_px * pixel {
                2
            } else {
                1
            };
            let cols = (RELIEF - 1) / step + 1;
            // The view's trim as baked (a texel beyond the covered ones), not grown on
            // screen. Session 13 grew it by a screen pixel (the covered texels, filtered
            // down to the level a pixel samples, reach about a pixel beyond them, and the
            // trim as baked lost crown outline pixels the whole quad drew). With the 5 x 5
            // grid, the pivots and the rows below the horizon since, the growth only drew
            // more (session 18, 640 x 360 tour, the forest's fragments shaded a frame and
            // PSNR mean / worst dB: grown a pixel 95,885, 26.83 / 23.88; half a pixel
            // 89,630, 26.88 / 23.90; as baked 83,218, 26.92 / 23.91; shrunk half a pixel
            // 77,378, 25.97 / 21.67).
            let trim = self.trims[view_index];
            let offsets = &self.depth[view_index];
            let scale = 0.5 * size.x;
            let base = mesh.positions.len() as u32;
            // A mirrored view: its texels drawn right to left (and its nodes taken right
            // to left, so the triangles keep their winding).
            let flip = b.region.max.x < b.region.min.x;
            let lo = Vec2::new(b.region.min.x.min(b.region.max.x), b.region.min.y);
            let span = (b.region.max - b.region.min).abs();
            for gy in 0..RELIEF {
                for col in 0..cols {
                    let gx = if flip { cols - 1 - col } else { col };
                    let t = trim.node(gx * step, gy);
                    let x = if flip { 1.0 - t.x } else { t.x };
                    let v = (0.5 - t.y) * size.y;
                    let (up, o) = mount.place(v, surface(offsets, t) * scale, pivot);
                    let flat = b.position + basis.right * ((x - 0.5) * size.x) + up;
                    let ray = (view.eye - flat).normalize_or(mount.toward);
                    let along = ray.dot(mount.toward).max(0.2);
                    mesh.positions.push(flat + ray * (o / along));
                    mesh.uvs.push(lo + t * span);
                    mesh.colors.push(b.tint);
                }
            }
            let (cells_x, cells_y) = (cols as u32 - 1, RELIEF as u32 - 1);
            crate::core::grid_triangles(cells_x, cells_y, base, &mut mesh.indices);
            n += 1;
        }
        n
    }

    /// The distance from a sprite's position (its sphere's centre) within which
    /// [`ViewAtlas::relief`] draws a sprite of `size` (world units): its quad's corners,
    /// moved by the [`Mount`]'s pivot (the nodes then move along their rays, not across
    /// the screen).
    pub fn reach(&self, size: Vec2) -> f32 {
        let steep = self.pivot_steep.map_or(0.0, |(p, _)| p.abs());
        0.5 * size.length() + 0.5 * size.y * self.pivot.abs().max(steep)
    }

    /// The pivot of the views baked at elevation `e` (radians), in `bounds.radius`
    /// ([`ViewAtlas::pivot`], [`ViewAtlas::pivot_steep`]).
    pub fn pivot_at(&self, e: f32) -> f32 {
        match self.pivot_steep {
            Some((top, from)) if e > from => {
                let t = ((e - from) / (std::f32::consts::FRAC_PI_2 - from)).min(1.0);
                self.pivot + (top - self.pivot) * t
            }
            _ => self.pivot,
        }
    }

    /// The index of the view shown by `region` (one of [`ViewAtlas::region`]'s) in
    /// [`ViewAtlas::depth`] and [`ViewAtlas::trims`].
    pub(super) fn view_of(&self, region: UvRect) -> usize {
        let k = (region.min.x.min(region.max.x) * self.azimuths as f32).round() as usize;
        let j = (region.min.y * self.elevations.len() as f32).round() as usize;
        let i = j.min(self.elevations.len() - 1) * self.azimuths + k.min(self.azimuths - 1);
        i.min(self.depth.len() - 1)
    }

    /// The column (azimuth) and row (elevation) of [`ViewAtlas::region`].
    pub fn cell(&self, to_eye: Vec3) -> (usize, usize) {
        let (k, j, _) = self.cell_mirrored(to_eye);
        (k, j)
    }

    /// [`ViewAtlas::cell`], and whether it is shown mirrored ([`ViewAtlas::mirror`]).
    fn cell_mirrored(&self, to_eye: Vec3) -> (usize, usize, bool) {
        let d = to_eye.normalize_or_zero();
        if d == Vec3::ZERO {
            return (0, 0, false);
        }
        let a = d.z.atan2(d.x);
        let (k, flip) = match self.mirror {
            None => {
                let a = a.rem_euclid(TAU);
                let k = (a / TAU * self.azimuths as f32).round() as usize % self.azimuths;
                (k, false)
            }
            Some(sun) => {
                let off = (a - sun).rem_euclid(TAU);
                let (off, flip) = if off > PI {
                    (TAU - off, true)
                } else {
                    (off, false)
                };
                let k = (off / PI * (self.azimuths - 1) as f32).round() as usize;
                (k.min(self.azimuths - 1), flip)
            }
        };
        let e = d.y.clamp(-1.0, 1.0).asin();
        let j = (0..self.elevations.len())
            .min_by(|&p, &q| {
                (self.elevations[p] - e)
                    .abs()
                    .total_cmp(&(self.elevations[q] - e).abs())
            })
            .unwrap_or(0);
        (k, j, flip)
    }
}

/// A view's depth grid over its whole square from its per-texel offsets (`px` square,
/// row-major, `-inf` where empty): at each node the largest offset (the nearest surface)
/// among the texels within [`NODE_REACH`] of a node spacing of it each way, 0 where they
/// are all empty.
fn grid(offsets: &[f32], px: usize) -> [f32; RELIEF * RELIEF] {
    let mut g = [f32::NEG_INFINITY; RELIEF * RELIEF];
    let at = |x: usize| (x as f32 + 0.5) / px as f32 * (RELIEF - 1) as f32;
    // Per texel column (and row, the same), its node and whether it lies within reach.
    let node = |x: usize| {
        let f = at(x);
        let n = f.round();
        ((f - n).abs() <= NODE_REACH).then_some(n as usize)
    };
    let nodes: Vec<Option<usize>> = (0..px).map(node).collect();
    for (i, &o) in offsets.iter().enumerate() {
        if let (Some(y), Some(x)) = (nodes[i / px], nodes[i % px]) {
            let at = y * RELIEF + x;
            g[at] = g[at].max(o);
        }
    }
    g.map(|o| if o.is_finite() { o } else { 0.0 })
}

/// The unit direction toward the viewer of column `k` of `azimuths` at elevation `e`.
/// One sprite placed for drawing ([`ViewAtlas::placed`]).
pub(super) struct Placed<'a> {
    /// The sprite.
    pub b: &'a Billboard,
    /// Its world size.
    pub size: Vec2,
    /// Its world-facing basis toward the eye.
    pub basis: Basis,
    /// The atlas view it shows.
    pub view_index: usize,
    /// Where that view's image stands.
    pub mount: Mount,
    /// The pivot's height above the sprite's centre (world units).
    pub pivot: f32,
}

#[cfg(test)]
fn direction(azimuths: usize, k: usize, e: f32) -> Vec3 {
    let a = column_azimuth(azimuths, k, None);
    Vec3::new(a.cos() * e.cos(), e.sin(), a.sin() * e.cos())
}

/// The azimuth (radians from +X toward +Z) of column `k` of `azimuths`: evenly around, or
/// with `mirror` (the sun's azimuth) over the half turn from it, both ends included.
fn column_azimuth(azimuths: usize, k: usize, mirror: Option<f32>) -> f32 {
    match mirror {
        None => k as f32 * TAU / azimuths as f32,
        Some(sun) => sun + k as f32 * PI / (azimuths.max(2) - 1) as f32,
    }
}

#[cfg(test)]
mod tests;
