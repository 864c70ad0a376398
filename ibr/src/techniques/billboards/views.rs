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

use super::bake::{bake_bounds, bake_camera};
use crate::core::{Billboard, Capturer, UvRect};
use engine::{AlphaMode, Draw, Encoding, Lighting, Material, Rgba, Sphere, Texture};
use glam::{Vec2, Vec3};
use std::f32::consts::TAU;
use std::sync::Arc;

/// Texels of transparent margin framed around the sphere in every cell, so the mipmaps
/// of one cell blend no neighbour's texels in at the levels a quad of its size uses.
const MARGIN: f32 = 0.04;

/// The alpha at which a view's texel is kept ([`ViewAtlas::material`]): the mip-filtered
/// alpha of a pixel is about the share of it the object covers, so a pixel is drawn where
/// the object covers at least half of it, as a rasterised mesh covers the pixels whose
/// centres it holds.
const CUTOFF: f32 = 0.5;

/// An object's images from `azimuths` evenly spaced directions about +Y (the first along
/// +X, then toward +Z) at each of `elevations` (radians above the horizon), in one atlas:
/// row `j` holds elevation `j`, column `k` azimuth `k`.
#[derive(Clone, Debug)]
pub struct ViewAtlas {
    /// The atlas: premultiplied sRGB with mipmaps, `azimuths * px` by `elevations * px`.
    pub texture: Arc<Texture>,
    /// The sphere each image frames, enlarged by the cells' margin: a quad facing the eye
    /// through its centre, `2 * radius` square, shows a cell at the object's size.
    pub bounds: Sphere,
    /// Directions about the vertical axis.
    pub azimuths: usize,
    /// Elevations baked, radians, ascending.
    pub elevations: Vec<f32>,
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
        for (j, &e) in elevations.iter().enumerate() {
            for k in 0..azimuths {
                let camera = bake_camera(bounds, direction(azimuths, k, e));
                let t = capturer.render(
                    draws.iter().copied(),
                    &camera,
                    lighting,
                    px,
                    px,
                    Encoding::Srgb,
                );
                for y in 0..px {
                    t.read_row(y, &mut row, &mut z);
                    let at = (j * px as usize + y as usize) * w as usize + k * px as usize;
                    texels[at..at + px as usize].copy_from_slice(&row);
                }
            }
        }
        let texture =
            Texture::from_packed(w, h, texels, Encoding::Srgb, true).expect("a non-empty atlas");
        ViewAtlas {
            texture: Arc::new(texture),
            bounds,
            azimuths,
            elevations,
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
    pub fn region(&self, to_eye: Vec3) -> UvRect {
        let (k, j) = self.cell(to_eye);
        let size = Vec2::new(
            1.0 / self.azimuths as f32,
            1.0 / self.elevations.len() as f32,
        );
        let min = Vec2::new(k as f32, j as f32) * size;
        UvRect {
            min,
            max: min + size,
        }
    }

    /// The column (azimuth) and row (elevation) of [`ViewAtlas::region`].
    pub fn cell(&self, to_eye: Vec3) -> (usize, usize) {
        let d = to_eye.normalize_or_zero();
        if d == Vec3::ZERO {
            return (0, 0);
        }
        let a = d.z.atan2(d.x).rem_euclid(TAU);
        let k = (a / TAU * self.azimuths as f32).round() as usize % self.azimuths;
        let e = d.y.clamp(-1.0, 1.0).asin();
        let j = (0..self.elevations.len())
            .min_by(|&p, &q| {
                (self.elevations[p] - e)
                    .abs()
                    .total_cmp(&(self.elevations[q] - e).abs())
            })
            .unwrap_or(0);
        (k, j)
    }
}

/// The unit direction toward the viewer of column `k` of `azimuths` at elevation `e`.
fn direction(azimuths: usize, k: usize, e: f32) -> Vec3 {
    let a = k as f32 * TAU / azimuths as f32;
    Vec3::new(a.cos() * e.cos(), e.sin(), a.sin() * e.cos())
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
            // The ball covers the cell's centre, opaque red (shaded); its corners stay clear.
            let c = at(8, 8).to_le_bytes();
            assert!(
                c[0] > 100 && c[1] < 30 && c[3] == 255,
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
}
