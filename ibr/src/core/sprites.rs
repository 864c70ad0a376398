//! Sprite textures made at start-up: analytic glows and beam profiles, and sprites baked
//! from meshes through the capture service (the billboard trees' images).
//!
//! Nothing here reads a file. Generated textures are straight-alpha sRGB-encoded images
//! with mipmaps; baked sprites are the engine's own premultiplied render of the mesh.

use crate::core::Capturer;
use crate::core::UvRect;
use engine::{Camera, Draw, Encoding, Lighting, Material, Mesh, Projection, Texture};
use glam::{Mat4, Vec2, Vec3};
use std::sync::Arc;

/// A square `size` x `size` white texture whose alpha is `alpha(r)`, `r` the distance from
/// the centre in units of the half size (1 at the middle of each edge).
pub fn radial(size: u32, alpha: impl Fn(f32) -> f32) -> Texture {
    let size = size.max(1);
    let mut rgba = Vec::with_capacity(size as usize * size as usize * 4);
    let half = size as f32 * 0.5;
    for y in 0..size {
        for x in 0..size {
            let d = Vec2::new(x as f32 + 0.5 - half, y as f32 + 0.5 - half) / half;
            let a = alpha(d.length()).clamp(0.0, 1.0);
            rgba.extend_from_slice(&[255, 255, 255, (a * 255.0).round() as u8]);
        }
    }
    Texture::from_rgba8(size, size, &rgba, Encoding::Unorm).expect("size is valid")
}

/// A soft glow: a bright core and a wide falloff, zero at the edge.
pub fn glow(size: u32) -> Texture {
    radial(size, glow_profile)
}

/// The glow's alpha at distance `r` (half-size units) from the centre: a Gaussian core plus
/// a wider halo, faded to exactly zero at `r = 1` so quads show no edges.
pub fn glow_profile(r: f32) -> f32 {
    let edge = (1.0 - r).clamp(0.0, 1.0);
    ((-r * r * 18.0).exp() + 0.35 * (-r * r * 4.0).exp()) * edge * edge.sqrt()
}

/// A soft round puff (smoke, dust): a disc with a smooth rim.
pub fn puff(size: u32) -> Texture {
    radial(size, |r| {
        let t = (1.0 - r).clamp(0.0, 1.0);
        t * t * (3.0 - 2.0 * t)
    })
}

/// A beam's cross-section across `u` (white, alpha by the glow profile of `|2u - 1|`),
/// constant along `v`: the texture of a laser's quads.
pub fn beam(width: u32) -> Texture {
    let width = width.max(2);
    let height = 4;
    let mut rgba = Vec::with_capacity(width as usize * height * 4);
    for _ in 0..height {
        for x in 0..width {
            let r = ((x as f32 + 0.5) / width as f32 * 2.0 - 1.0).abs();
            let a = glow_profile(r).clamp(0.0, 1.0);
            rgba.extend_from_slice(&[255, 255, 255, (a * 255.0).round() as u8]);
        }
    }
    Texture::from_rgba8(width, height as u32, &rgba, Encoding::Unorm).expect("size is valid")
}

/// A sprite baked from a mesh for an axial (upright) billboard: the side view in the left
/// half of the texture, the view from above in the right half.
#[derive(Clone, Debug)]
pub struct BakedSprite {
    /// The baked texture: side view in the left half, top view in the right.
    pub texture: Arc<Texture>,
    /// Region of the side view (an upright billboard).
    pub side: UvRect,
    /// Region of the top view (the fallback of an upright billboard seen from above).
    pub top: UvRect,
    /// World width and height of the side view's quad.
    pub size: Vec2,
    /// Where the mesh's origin falls in the side quad (quad units: 0..1, bottom-left 0).
    pub pivot: Vec2,
}

/// Bakes `mesh` (standing on its origin, +Y up) seen from the horizontal direction `side`
/// and from above, `px` pixels tall, with orthographic cameras fitted to its bounds.
pub fn bake_upright(
    mesh: &Mesh,
    material: &Material,
    lighting: &Lighting,
    side: Vec3,
    px: u32,
) -> BakedSprite {
    let (lo, hi) = bounds(mesh);
    // Radius about the vertical axis through the origin, so every side view fits.
    let radius = mesh
        .positions
        .iter()
        .filter(|p| p.is_finite())
        .map(|p| Vec2::new(p.x, p.z).length())
        .fold(1e-3f32, f32::max);
    let height = (hi.y - lo.y).max(1e-3);
    let px = px.max(2);
    let w = ((px as f32) * 2.0 * radius / height).ceil().max(2.0) as u32;
    let side = Vec3::new(side.x, 0.0, side.z).normalize_or(Vec3::Z);
    let mid = Vec3::new(0.0, (lo.y + hi.y) * 0.5, 0.0);
    let dist = radius + height + 1.0;
    let ortho = |half_w: f32, half_h: f32| Projection::Orthographic {
        left: -half_w,
        right: half_w,
        bottom: -half_h,
        top: half_h,
        near: 0.01,
        far: 2.0 * dist + height,
    };
    let mut capturer = Capturer::new();
    let draw = Draw {
        mesh,
        material,
        transform: Mat4::IDENTITY,
    };
    // Left half: the side view (w x px pixels); right half: the top view (w x w pixels).
    let side_cam = Camera {
        view: Mat4::look_at_rh(mid + side * dist, mid, Vec3::Y),
        projection: ortho(radius, height * 0.5),
    };
    let side_img = capturer.render([draw], &side_cam, lighting, w, px, Encoding::Srgb);
    let side_tex = side_img.to_texture().expect("not empty");
    let top_cam = Camera {
        view: Mat4::look_at_rh(
            Vec3::new(0.0, hi.y + dist, 0.0),
            Vec3::new(0.0, lo.y, 0.0),
            Vec3::NEG_Z,
        ),
        projection: ortho(radius, radius * w.min(px) as f32 / w as f32),
    };
    let top_img = capturer.render([draw], &top_cam, lighting, w, w.min(px), Encoding::Srgb);
    let top_tex = top_img.to_texture().expect("not empty");
    // Assemble the atlas with a 2-pixel transparent gutter between the halves.
    let (aw, ah) = (w * 2 + 2, px);
    let mut texels = vec![0u32; aw as usize * ah as usize];
    blit(
        &mut texels,
        aw,
        side_tex.levels()[0].texels.as_slice(),
        w,
        0,
    );
    blit(
        &mut texels,
        aw,
        top_tex.levels()[0].texels.as_slice(),
        w,
        w + 2,
    );
    let texture = Texture::from_packed(aw, ah, texels, Encoding::Srgb, true).expect("valid");
    let u = |x: u32| x as f32 / aw as f32;
    BakedSprite {
        texture: Arc::new(texture),
        side: UvRect {
            min: Vec2::ZERO,
            max: Vec2::new(u(w), 1.0),
        },
        top: UvRect {
            min: Vec2::new(u(w + 2), 0.0),
            max: Vec2::new(u(2 * w + 2), w.min(px) as f32 / ah as f32),
        },
        size: Vec2::new(2.0 * radius, height),
        pivot: Vec2::new(0.5, (0.0 - lo.y) / height),
    }
}

fn blit(dst: &mut [u32], dst_w: u32, src: &[u32], src_w: u32, x0: u32) {
    for (y, row) in src.chunks_exact(src_w as usize).enumerate() {
        let start = y * dst_w as usize + x0 as usize;
        dst[start..start + src_w as usize].copy_from_slice(row);
    }
}

/// Axis-aligned bounds of the finite positions (a unit box around the origin if none).
fn bounds(mesh: &Mesh) -> (Vec3, Vec3) {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    for p in mesh.positions.iter().filter(|p| p.is_finite()) {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    if lo.x > hi.x {
        return (Vec3::splat(-0.5), Vec3::splat(0.5));
    }
    (lo, hi)
}
