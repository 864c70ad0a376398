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

use super::bake::{bake_bounds, bake_camera};
use crate::core::{Capturer, UvRect};
use engine::{Draw, Encoding, Lighting, Sphere, Texture};
use glam::{Vec2, Vec3};
use std::f32::consts::TAU;
use std::sync::Arc;

/// Texels of transparent margin framed around the sphere in every cell, so the mipmaps
/// of one cell blend no neighbour's texels in at the levels a quad of its size uses.
const MARGIN: f32 = 0.04;

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
    use engine::{procedural, Material, Rgba};
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
}
