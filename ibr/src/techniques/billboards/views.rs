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
//!
//! Trimmed ([`ViewAtlas::trims`], [`Trim`]): the grid's nodes are spread over the texels a
//! view covers (its rows, and per node row its columns, grown a screen pixel), not the
//! whole square, so the clear texels around a tall tree or a round crown, which an
//! alpha-tested sprite samples and discards like any other, are not drawn.

use super::bake::{bake_bounds, bake_camera};
use super::mount::Mount;
use super::trim::{surface, Trim};
use crate::core::{orient, Billboard, Capturer, Facing, Size, UvRect, View};
use engine::{AlphaMode, Draw, Encoding, Lighting, Material, Mesh, Rgba, Sphere, Texture};
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

/// Nodes a side of each view's depth grid ([`ViewAtlas::relief`]): 3 x 3 vertices, 8
/// triangles a sprite (4 x 4 measured 0.2 dB more on the showcase's forest for 18).
pub(crate) const RELIEF: usize = 3;

/// Screen pixels a sprite's trim ([`ViewAtlas::trims`]) is grown by: the texels covered
/// in the bake, filtered down to the level a pixel samples, reach about a pixel beyond
/// them, and the mesh in perspective shows a little more than its orthographic bake (the
/// trim as baked, a texel beyond the covered ones, lost the last pixel of crown outlines
/// the whole quad drew: 24.8 / 19.1 dB on the 640 x 360 tour against 24.6 / 19.5).
const TRIM_PX: f32 = 1.0;

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
    /// (row-major, top row first as the image): the nearest surface within the node's
    /// share of the square, 0 (the centre plane, where a convex object's outline lies)
    /// where it is empty. A trimmed sprite's nodes ([`ViewAtlas::trims`]) take this
    /// surface where they lie ([`super::trim::surface`]).
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
                        let covered = (c >> 24) as f32 >= CUTOFF * 255.0;
                        offsets[(y * px) as usize + x] = if covered {
                            3.0 * d - 1.5
                        } else {
                            f32::NEG_INFINITY
                        };
                    }
                }
                let trim = Trim::of(&alpha, px as usize);
                depth.push(grid(&offsets, px as usize));
                trims.push(trim);
            }
        }
        let texture =
            Texture::from_packed(w, h, texels, Encoding::Unorm, true).expect("a non-empty atlas");
        ViewAtlas {
            texture: Arc::new(texture),
            bounds,
            azimuths,
            elevations,
            depth,
            trims,
            mirror,
            pivot: 0.0,
        }
    }

    /// The material that draws the atlas's views on billboards: unlit (the views are baked
    /// lit), the billboard's tint times the texture, alpha-tested at `CUTOFF` (0.5) with depth
    /// writes, in the opaque pass (draw the quads in [`ViewAtlas::order`]).
    pub fn material(&self) -> Material {
        Material {
            alpha_mode: AlphaMode::Mask { cutoff: CUTOFF },
            vertex_colors: true,
            ..Material::unlit(Rgba::WHITE).with_texture(self.texture.clone())
        }
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
    /// sprites written.
    pub fn relief(&self, items: &[Billboard], view: &View, mesh: &mut Mesh) -> usize {
        mesh.clear();

        let mut n = 0;
        for b in items {
            let Size::World(size) = b.size else {
                continue;
            };
            if !b.position.is_finite() {
                continue;
            }
            let basis = orient(Facing::World { up: Vec3::Y }, view, b.position);
            let view_index = self.view_of(b.region);
            let mount = Mount::new(
                self.elevations[view_index / self.azimuths],
                basis.normal,
                basis.right,
            );
            let pivot = self.pivot * 0.5 * size.y;
            // The view's trim grown by TRIM_PX screen pixels at the sprite's distance.
            let pixel = view.pixel_size_at(b.position).unwrap_or(0.0);
            let by = Vec2::new(pixel / size.x, pixel / size.y) * TRIM_PX;
            let trim = self.trims[view_index].grown(by);
            let offsets = &self.depth[view_index];
            let scale = 0.5 * size.x;
            let base = mesh.positions.len() as u32;
            // A mirrored view: its texels drawn right to left (and its nodes taken right
            // to left, so the triangles keep their winding).
            let flip = b.region.max.x < b.region.min.x;
            let lo = Vec2::new(b.region.min.x.min(b.region.max.x), b.region.min.y);
            let span = (b.region.max - b.region.min).abs();
            for gy in 0..RELIEF {
                for col in 0..RELIEF {
                    let gx = if flip { RELIEF - 1 - col } else { col };
                    let t = trim.node(gx, gy);
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
            let cells = RELIEF as u32 - 1;
            crate::core::grid_triangles(cells, cells, base, &mut mesh.indices);
            n += 1;
        }
        n
    }

    /// The distance from a sprite's position (its sphere's centre) within which
    /// [`ViewAtlas::relief`] draws a sprite of `size` (world units): its quad's corners,
    /// moved by the [`Mount`]'s pivot (the nodes then move along their rays, not across
    /// the screen).
    pub fn reach(&self, size: Vec2) -> f32 {
        0.5 * size.length() + 0.5 * size.y * self.pivot.abs()
    }

    /// The index of the view shown by `region` (one of [`ViewAtlas::region`]'s) in
    /// [`ViewAtlas::depth`] and [`ViewAtlas::trims`].
    fn view_of(&self, region: UvRect) -> usize {
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
/// among the texels nearer that node than any other, 0 where they are all empty.
fn grid(offsets: &[f32], px: usize) -> [f32; RELIEF * RELIEF] {
    let mut g = [f32::NEG_INFINITY; RELIEF * RELIEF];
    let node = |x: usize| ((x as f32 + 0.5) / px as f32 * (RELIEF - 1) as f32).round() as usize;
    for (i, &o) in offsets.iter().enumerate() {
        let at = node(i / px) * RELIEF + node(i % px);
        g[at] = g[at].max(o);
    }
    g.map(|o| if o.is_finite() { o } else { 0.0 })
}

/// The unit direction toward the viewer of column `k` of `azimuths` at elevation `e`.
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
mod tests {
    use super::*;
    use crate::core::{BillboardBatch, Facing, View};
    use engine::{procedural, Camera, FrameOptions, Renderer, Target};
    use glam::Mat4;

    /// A ball of radius 0.5, unlit red, in a sphere of 0.6: every cell shows it.
    fn atlas(azimuths: usize, elevations: &[f32]) -> ViewAtlas {
        let mesh = procedural::uv_sphere(0.5, 8, 16);
        let material = Material::unlit(Rgba::new(1.0, 0.0, 0.0, 1.0));
        let draw = Draw {
            mesh: &mesh,
            material: &material,
            transform: Mat4::IDENTITY,
        };
        let bounds = Sphere {
            center: Vec3::ZERO,
            radius: 0.6,
        };
        ViewAtlas::bake(
            &[draw],
            &Lighting::default(),
            bounds,
            azimuths,
            elevations,
            16,
        )
    }

    #[test]
    fn the_cell_is_the_nearest_baked_direction() {
        let a = atlas(4, &[0.0, 0.6, 1.2]);
        assert_eq!(a.cell(Vec3::X), (0, 0));
        assert_eq!(a.cell(Vec3::new(0.1, 0.0, 1.0)), (1, 0));
        assert_eq!(a.cell(Vec3::new(-1.0, 0.0, -0.1)), (2, 0));
        assert_eq!(a.cell(Vec3::new(0.0, 0.0, -1.0)), (3, 0));
        // 45 degrees up is nearest 0.6 rad (34 degrees); straight up, the last row.
        assert_eq!(a.cell(Vec3::new(1.0, 1.0, 0.0)), (0, 1));
        assert_eq!(a.cell(Vec3::new(0.01, 1.0, 0.0)).1, 2);
        assert_eq!(a.cell(Vec3::ZERO), (0, 0));
        assert_eq!(a.cell(Vec3::NAN), (0, 0));
        let r = a.region(Vec3::new(-1.0, 0.7, 0.0));
        assert_eq!(r.min, Vec2::new(0.5, 1.0 / 3.0));
        assert_eq!(r.max, Vec2::new(0.75, 2.0 / 3.0));
    }

    #[test]
    fn every_cell_holds_its_view_framed_with_a_clear_margin() {
        let a = atlas(3, &[0.0, 1.0]);
        let t = &a.texture.levels()[0];
        assert_eq!((a.texture.width(), a.texture.height()), (48, 32));
        for (cy, cx) in [(0, 0), (0, 1), (0, 2), (1, 0), (1, 1), (1, 2)] {
            let at = |x: u32, y: u32| t.texels[((cy * 16 + y) * 48 + cx * 16 + x) as usize];
            // The ball covers the cell's centre, opaque red (shaded; linear bytes, 32 is
            // sRGB 100); its corners stay clear.
            let c = at(8, 8).to_le_bytes();
            assert!(
                c[0] > 32 && c[1] < 8 && c[3] == 255,
                "cell {cx},{cy}: {c:?}"
            );
            for (x, y) in [(0, 0), (15, 0), (0, 15), (15, 15)] {
                assert_eq!(at(x, y), 0, "cell {cx},{cy} corner {x},{y}");
            }
        }
    }

    /// Fragments shaded drawing `items` (in the order given, with `material`) from `cam`.
    fn shaded(cam: &Camera, material: Material, items: &[Billboard]) -> (u64, Target) {
        let mut batch = BillboardBatch::new(material);
        batch.items.extend_from_slice(items);
        batch.build(&View::new(cam, 120));
        let mut target = Target::new(160, 120);
        let stats = Renderer::new().render(
            [batch.draw()],
            cam,
            &Lighting::default(),
            &mut target,
            &FrameOptions {
                clear: Some(Rgba::TRANSPARENT),
                ..FrameOptions::default()
            },
        );
        (stats.fragments_shaded, target)
    }

    #[test]
    fn a_row_of_cutouts_near_to_far_shades_about_one_sprite() {
        let a = atlas(4, &[0.0]);
        let (eye, side) = (Vec3::new(0.0, 0.0, 2.5), 2.0 * a.bounds.radius);
        let cam = Camera::look_at(eye, Vec3::ZERO, Vec3::Y, 0.8, 160.0 / 120.0);
        // Eight balls in a row straight away from the eye, 0.25 apart, pushed far to near.
        let row: Vec<Billboard> = (0..8)
            .map(|k| {
                let p = Vec3::new(0.0, 0.0, -0.25 * k as f32);
                Billboard {
                    region: a.region(eye - p),
                    ..Billboard::new(p, Facing::World { up: Vec3::Y }, Vec2::splat(side))
                }
            })
            .rev()
            .collect();
        let mut sorted = row.clone();
        ViewAtlas::order(&mut sorted, eye);
        assert_eq!(sorted[0].position, Vec3::ZERO, "nearest first");
        // The reference: the nearest sprite drawn alone.
        let (one, alone) = shaded(&cam, a.material(), &sorted[..1]);
        let solid = (0..120)
            .flat_map(|y| (0..160).map(move |x| (x, y)))
            .filter(|&(x, y)| alone.pixel(x, y).is_some_and(|c| c >> 24 == 255))
            .count() as u64;
        assert!(one > 2000 && solid * 2 > one, "{one} {solid}");
        let (cut, image) = shaded(&cam, a.material(), &sorted);
        let blended = Material {
            alpha_mode: AlphaMode::Blend,
            ..a.material()
        };
        let (blend, _) = shaded(&cam, blended, &row);
        let (far_first, _) = shaded(&cam, a.material(), &row);
        // Near to far, a farther sprite (smaller on screen, its ball inside the nearer
        // balls) shades at most the clear part of its quad, no more than the nearest's;
        // blended or far to near, every quad shades whole.
        assert!(cut <= one + 7 * (one - solid), "{cut}: {one} {solid}");
        assert!(
            cut * 2 < blend && cut * 2 < far_first,
            "{cut} {blend} {far_first}"
        );
        assert!(blend * 10 > one * 40, "{blend} vs {one}");
        // And the row looks as its nearest sprite does where that one is opaque.
        assert_eq!(image.pixel(80, 60), alone.pixel(80, 60));
    }

    /// Mean absolute reversed depth difference from `truth` over the pixels both cover,
    /// and how many.
    fn depth_error(a: &Target, truth: &Target) -> (f32, usize) {
        let (mut sum, mut n) = (0.0, 0);
        for y in 0..a.height() {
            for x in 0..a.width() {
                let (p, q) = (a.depth_reversed(x, y), truth.depth_reversed(x, y));
                if let (Some(p), Some(q)) = (p, q) {
                    if p > 0.0 && q > 0.0 {
                        sum += (p - q).abs();
                        n += 1;
                    }
                }
            }
        }
        (sum / n.max(1) as f32, n)
    }

    #[test]
    fn a_relief_sprite_stands_where_the_mesh_does() {
        let a = atlas(4, &[0.0, 0.6]);
        // The centre node: the ball's front, 0.5 in front of the centre plane, in radii of
        // the atlas's (margin-enlarged) sphere.
        let g = &a.depth[0];
        let inner = [g[RELIEF * RELIEF / 2]];
        let want = 0.5 / a.bounds.radius;
        for o in inner {
            assert!((o - want).abs() < 0.05, "{o} vs {want}: {g:?}");
        }
        // A corner's share only grazes the ball's outline, where its surface meets the
        // centre plane.
        assert!((0.0..0.15).contains(&g[0]), "corner {}", g[0]);
        // Seen from the first bake's direction, in perspective: the relief's depth is
        // the ball's, where the flat quad's is its centre's.
        let eye = Vec3::new(3.0, 0.0, 0.0);
        let cam = Camera::look_at(eye, Vec3::ZERO, Vec3::Y, 0.6, 160.0 / 120.0);
        let view = View::new(&cam, 120);
        let side = 2.0 * a.bounds.radius;
        let item = Billboard {
            region: a.region(eye),
            ..Billboard::new(Vec3::ZERO, Facing::World { up: Vec3::Y }, Vec2::splat(side))
        };
        let mut mesh = Mesh::default();
        assert_eq!(a.relief(&[item], &view, &mut mesh), 1);
        assert_eq!(mesh.positions.len(), RELIEF * RELIEF);
        let material = a.material().double_sided(true);
        let ball = procedural::uv_sphere(0.5, 8, 16);
        let red = Material::unlit(Rgba::new(1.0, 0.0, 0.0, 1.0));
        let render = |draw: Draw<'_>| {
            let mut t = Target::new(160, 120);
            Renderer::new().render(
                [draw],
                &cam,
                &Lighting::default(),
                &mut t,
                &FrameOptions {
                    clear: Some(Rgba::TRANSPARENT),
                    ..FrameOptions::default()
                },
            );
            t
        };
        let at = |mesh| Draw {
            mesh,
            material: &material,
            transform: Mat4::IDENTITY,
        };
        let relief = render(at(&mesh));
        let mut flat = BillboardBatch::new(material.clone());
        flat.push(item);
        flat.build(&view);
        let flat = render(flat.draw());
        let truth = render(Draw {
            mesh: &ball,
            material: &red,
            transform: Mat4::IDENTITY,
        });
        let (e_relief, n_relief) = depth_error(&relief, &truth);
        let (e_flat, n_flat) = depth_error(&flat, &truth);
        assert!(n_relief > 1000 && n_flat > 1000, "{n_relief} {n_flat}");
        assert!(e_relief * 3.0 < e_flat, "relief {e_relief}, flat {e_flat}");
        // The same texels on screen: the relief's colour is the flat quad's but for the
        // texture's interpolation across its tilted triangles (a fraction of a texel,
        // seen along the outline of this magnified 16-texel view: 5.8% measured).
        let off = (0..120)
            .flat_map(|y| (0..160).map(move |x| (x, y)))
            .filter(|&(x, y)| {
                let (p, q) = (relief.pixel(x, y), flat.pixel(x, y));
                let (p, q) = (p.unwrap_or(0).to_le_bytes(), q.unwrap_or(0).to_le_bytes());
                p.iter().zip(q).any(|(a, b)| a.abs_diff(b) > 24)
            })
            .count();
        assert!(off * 100 < n_flat * 8, "{off} of {n_flat} pixels differ");
    }

    /// A matte ball lit by a sun, baked 64 texels a view, its sprite seen in perspective
    /// from far along a baked direction (the quad about as many pixels across as the
    /// view's texels), against the ball's mesh from the same eye: the sprite reproduces
    /// the bake. Its colour is the mesh's (the light that left the ball toward the eye,
    /// baked in) and its outline too.
    #[test]
    fn a_sprite_seen_from_its_bake_direction_reproduces_the_mesh() {
        use engine::Light;
        let ball = procedural::uv_sphere(0.5, 24, 48);
        let matte = Material {
            shading: engine::Shading::Lit {
                specular: 0.0,
                shininess: 32.0,
            },
            ..Material::lit(Rgba::new(0.3, 0.7, 0.2, 1.0))
        };
        let draw = Draw {
            mesh: &ball,
            material: &matte,
            transform: Mat4::IDENTITY,
        };
        let lighting = Lighting {
            ambient: Rgba::new(0.2, 0.2, 0.25, 1.0),
            lights: vec![Light::Directional {
                direction: Vec3::new(-0.45, -0.75, -0.5).normalize(),
                color: Rgba::WHITE,
            }],
        };
        let bounds = Sphere {
            center: Vec3::ZERO,
            radius: 0.6,
        };
        let elevations = [0.0, 0.5];
        let a = ViewAtlas::bake(&[draw], &lighting, bounds, 6, &elevations, 64);
        let h = 120u32; // the compared renders' height
        for (k, e) in [(0, 0.0), (2, 0.0), (4, 0.5)] {
            let eye = direction(6, k, e) * 12.0;
            assert_eq!(a.cell(eye), (k, usize::from(e > 0.0)));
            // 64 texels over the quad's 2 * radius at 12 units.
            let side = 2.0 * a.bounds.radius;
            let fov = 2.0 * (0.5 * h as f32 * side / (64.0 * 12.0)).atan();
            let (both, one, mean) =
                super::super::compare::against_mesh(&a, draw, &lighting, eye, fov);
            assert!(both > 1500, "view {k}: {both} pixels");
            assert!(
                one * 100 < both * 4,
                "view {k}: outline off on {one} of {both}"
            );
            assert!(mean < 3.0, "view {k}: colour off by {mean} levels");
        }
    }
}
