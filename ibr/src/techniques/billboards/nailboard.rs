//! A [`ViewAtlas`]'s sprites as nailboards proper (Schaufler 97): each sprite one flat
//! polygon (the trim's outline, 8 triangles) at its view's nearest surface, its fragments' depth taken per texel from a
//! baked offset image beside the colour atlas ([`engine::DepthOffset`]), not from a coarse
//! grid of moved nodes ([`ViewAtlas::relief`]).

use super::views::{Placed, ViewAtlas, RELIEF};
use crate::core::{Billboard, View};
use engine::Mesh;
use glam::Vec2;

/// The span of the bake's offsets (radii): its orthographic depth runs from 1.5 radii in
/// front of the centre to 1.5 behind. A texel's offset is stored as its depth behind its
/// view's nearest surface over this span, in a byte (1/85 of a radius a step).
pub(crate) const DEPTH_SPAN: f32 = 3.0;

/// One view's offset image into `out` (`px` square, row-major, premultiplied unorm texels
/// `red | alpha << 24`): `alpha` each texel's coverage, `offsets` its surface's offset
/// toward the viewer (radii; not finite where the bake drew nothing), `covered` whether
/// it passes the alpha test. Red over alpha is the texel's depth behind the view's nearest
/// covered surface over [`DEPTH_SPAN`] (a texel drawn but not covered, at the outline, as
/// far as its own offset says, or at the nearest where it has none). Returns that nearest
/// offset (0 for an empty view).
pub(crate) fn offset_image(
    alpha: &[u8],
    offsets: &[f32],
    covered: impl Fn(usize) -> bool,
    out: &mut [u32],
) -> f32 {
    let near = (0..offsets.len())
        .filter(|&i| covered(i) && offsets[i].is_finite())
        .map(|i| offsets[i])
        .fold(f32::NEG_INFINITY, f32::max);
    let near = if near.is_finite() { near } else { 0.0 };
    for (i, o) in out.iter_mut().enumerate() {
        let a = alpha[i] as f32;
        let off = if offsets[i].is_finite() {
            offsets[i]
        } else {
            near
        };
        let v = ((near - off) / DEPTH_SPAN).clamp(0.0, 1.0);
        *o = (v * a).round() as u32 | (alpha[i] as u32) << 24;
    }
    near
}

/// The views' offset images of `texels` (an atlas `w` texels wide of `px`-square views,
/// row-major, each measured back from its own nearest offset, `nearest` in the views'
/// order) measured back from `near` instead (at least every view's nearest).
pub(crate) fn remeasure(texels: &mut [u32], w: usize, px: usize, nearest: &[f32], near: f32) {
    let across = w / px;
    for (i, t) in texels.iter_mut().enumerate() {
        let (x, y) = (i % w, i / w);
        let view = (y / px) * across + x / px;
        let shift = (near - nearest[view]) / DEPTH_SPAN;
        let a = *t >> 24;
        let red = (*t & 0xff) + (shift * a as f32).round() as u32;
        *t = red.min(a) | a << 24;
    }
}

impl ViewAtlas {
    /// Writes `items` (as [`ViewAtlas::relief`] takes them) into `mesh` (cleared) as seen
    /// from `view`, each as one flat polygon: its view's trim's outline (the 5 node rows'
    /// first and last columns, as [`ViewAtlas::relief`] draws it: 8 triangles) on its
    /// [`super::mount::Mount`]'s plane, moved toward the eye by a scaling about the eye (so it covers
    /// the same pixels with the same texels) until it stands at the nearest surface of
    /// every view ([`ViewAtlas::depth_near`], less the pivot's part on the mount's plane,
    /// so the texels' surfaces stand where [`ViewAtlas::relief`] puts them). Drawn with
    /// [`ViewAtlas::material`] (its [`engine::DepthOffset`]), each fragment's depth is its
    /// texel's surface behind that plane. Returns the sprites written.
    pub fn nailboards(&self, items: &[Billboard], view: &View, mesh: &mut Mesh) -> usize {
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
            let scale = 0.5 * size.x;
            let trim = self.trims[view_index];
            let flip = b.region.max.x < b.region.min.x;
            let lo = Vec2::new(b.region.min.x.min(b.region.max.x), b.region.min.y);
            let span = (b.region.max - b.region.min).abs();
            // The nearest surface's offset in front of the mount's plane, and the scaling
            // about the eye that carries the plane there.
            let (_, near) = mount.place(0.0, self.depth_near * scale, pivot);
            let base = mesh.positions.len() as u32;
            let mut s = 1.0;
            for gy in 0..RELIEF {
                for col in 0..2 {
                    let gx = if flip { 1 - col } else { col };
                    let t = trim.node(gx * (RELIEF - 1), gy);
                    let x = if flip { 1.0 - t.x } else { t.x };
                    let (up, _) = mount.place((0.5 - t.y) * size.y, 0.0, pivot);
                    let flat = b.position + basis.right * ((x - 0.5) * size.x) + up;
                    if gy == 0 && col == 0 {
                        let d = (view.eye - flat).dot(mount.toward);
                        s = (1.0 - near / d).clamp(0.01, 1.0e3);
                        if !s.is_finite() {
                            s = 1.0;
                        }
                    }
                    mesh.positions.push(view.eye + (flat - view.eye) * s);
                    mesh.uvs.push(lo + t * span);
                    mesh.colors.push(b.tint);
                }
            }
            crate::core::grid_triangles(1, RELIEF as u32 - 1, base, &mut mesh.indices);
            n += 1;
        }
        n
    }
}

#[cfg(test)]
mod tests {
    use super::super::compare::{against_mesh, centred_sprite, matte, sun};
    use super::*;
    use engine::{
        procedural, Camera, Draw, FrameOptions, Lighting, Material, Renderer, Rgba, Sphere, Target,
    };
    use glam::{Mat4, Vec3};

    /// A ball of radius 0.5, unlit red, in a sphere of 0.6, baked 64 texels a view.
    fn ball() -> (Mesh, Material) {
        (
            procedural::uv_sphere(0.5, 24, 48),
            Material::unlit(Rgba::new(1.0, 0.0, 0.0, 1.0)),
        )
    }

    fn atlas(mesh: &Mesh, material: &Material) -> ViewAtlas {
        let draw = Draw {
            mesh,
            material,
            transform: Mat4::IDENTITY,
        };
        let bounds = Sphere {
            center: Vec3::ZERO,
            radius: 0.6,
        };
        ViewAtlas::bake(&[draw], &Lighting::default(), bounds, 6, &[0.0, 0.5], 64)
    }

    /// Seen from 3 units along the first view's direction, the ball's nailboard (8
    /// triangles) and its 5 x 5 relief (32) against its mesh: the mean and largest view
    /// depth difference where both cover, and the pixels compared.
    fn depth_off(a: &ViewAtlas, mesh: &Mesh, red: &Material) -> (f32, f32, usize, usize) {
        let eye = Vec3::new(3.0, 0.0, 0.0);
        let cam = Camera::look_at(eye, Vec3::ZERO, Vec3::Y, 0.6, 160.0 / 120.0);
        let sprite = centred_sprite(a, eye, &cam, 120);
        let material = a.material().double_sided(true);
        let render = |draw: Draw<'_>| {
            let mut t = Target::new(160, 120);
            let opts = FrameOptions {
                clear: Some(Rgba::TRANSPARENT),
                ..FrameOptions::default()
            };
            Renderer::new().render([draw], &cam, &Lighting::default(), &mut t, &opts);
            t
        };
        let board = render(Draw {
            mesh: &sprite,
            material: &material,
            transform: Mat4::IDENTITY,
        });
        let truth = render(Draw {
            mesh,
            material: red,
            transform: Mat4::IDENTITY,
        });
        let (mut n, mut sum, mut worst) = (0, 0.0, 0.0f32);
        for y in 0..120 {
            for x in 0..160 {
                let (p, q) = (board.depth_reversed(x, y), truth.depth_reversed(x, y));
                let (Some(p), Some(q)) = (p, q) else { continue };
                if p > 0.0 && q > 0.0 {
                    let d = cam.view_depth_from_reversed(p) - cam.view_depth_from_reversed(q);
                    n += 1;
                    sum += d.abs();
                    worst = worst.max(d.abs());
                }
            }
        }
        (sum / n.max(1) as f32, worst, n, sprite.indices.len() / 3)
    }

    /// The ball's nailboard, 8 triangles, stands about where its mesh does, and has its
    /// outline. Seen from 6 radii its depth is farther than the mesh's by 0.044 on average
    /// (measured; the relief's 0.022): an orthographic view's offset moved along the
    /// perspective ray misses the rim's nearer intersection (0.055 at 0.4 from the
    /// centre), where the relief's nodes, each the nearest surface near it, err toward
    /// the eye.
    #[test]
    fn a_nailboard_has_the_balls_depth_on_one_flat_outline() {
        let (mesh, red) = ball();
        let mut a = atlas(&mesh, &red);
        let (relief, relief_worst, n_relief, t_relief) = depth_off(&a, &mesh, &red);
        a.nailboard = true;
        let (nail, nail_worst, n_nail, t_nail) = depth_off(&a, &mesh, &red);
        assert_eq!((t_relief, t_nail), (32, 8));
        assert!(n_nail > 2000 && n_relief > 2000, "{n_nail} {n_relief}");
        assert!(
            nail < 0.06 && relief < 0.06,
            "mean off: nailboard {nail}, relief {relief} (worst {nail_worst}, {relief_worst})"
        );
        let draw = Draw {
            mesh: &mesh,
            material: &red,
            transform: Mat4::IDENTITY,
        };
        let (both, one, mean) = against_mesh(&a, draw, &Lighting::default(), Vec3::X * 3.0, 0.6);
        assert!(
            both > 2000 && one * 100 < both * 4,
            "outline off on {one} of {both}"
        );
        assert!(mean < 3.0, "colour off by {mean} levels");
    }

    /// A wide cone whose rim lies below its sprite's centre (a pine's lowest cone), lit,
    /// seen from 20 degrees up at 5 of its sphere's radii (the views on the plane through
    /// the centre either way): drawn flat, the nailboard shows
    /// the rim (nearer the eye than the view's plane) where the orthographic view has it,
    /// not where the eye sees it; with parallax each fragment shows the texel whose surface
    /// lies on its ray, and both the outline and the colours come nearer the mesh's.
    #[test]
    fn with_parallax_a_nailboard_shows_its_surfaces_where_the_eye_sees_them() {
        let mut cone = procedural::cone(0.6, 0.9, 48);
        cone.colors.clear();
        let material = matte();
        let draw = Draw {
            mesh: &cone,
            material: &material,
            transform: Mat4::from_translation(Vec3::new(0.0, -0.35, 0.0)),
        };
        let lighting = sun();
        let bounds = Sphere {
            center: Vec3::ZERO,
            radius: 0.8,
        };
        let elevations: Vec<f32> = (0..18).map(|k| (5.0 * k as f32).to_radians()).collect();
        let mut a = ViewAtlas::bake(&[draw], &lighting, bounds, 8, &elevations, 128);
        a.nailboard = true;
        let e = 20f32.to_radians();
        let eye = Vec3::new(e.cos(), e.sin(), 0.0) * 4.0;
        let (both, flat, flat_level) = against_mesh(&a, draw, &lighting, eye, 0.45);
        a.parallax = Some(0.03);
        let (_, searched, level) = against_mesh(&a, draw, &lighting, eye, 0.45);
        // Measured: 3,014 pixels both cover; the outline off on 354 flat, 178 searched; the
        // colours 1.41 and 0.70 levels off.
        assert!(both > 2000, "{both}");
        assert!(
            searched * 3 < flat * 2,
            "outline off on {searched} with parallax, {flat} without"
        );
        assert!(
            level * 4.0 < flat_level * 3.0,
            "colour off by {level} levels with parallax, {flat_level} without"
        );
    }
}
