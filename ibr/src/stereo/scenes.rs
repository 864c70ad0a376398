//! Test scenes for the matchers: textured cards rendered as rectified pairs.

use super::pair::StereoPair;
use engine::procedural::{self, XorShift};
use engine::{Camera, Draw, Encoding, Lighting, Material, Mesh, Rgba, Texture};
use glam::{Mat4, Vec3};
use std::sync::Arc;

pub(crate) const W: u32 = 160;
pub(crate) const H: u32 = 120;
/// The baseline: a plane 5 units off has about 11.6 pixels of disparity.
pub(super) const BASELINE: f32 = 0.4;

/// A 128x128 texture of random grey levels (blocks of 2x2 texels): texture to match on.
fn noise() -> Arc<Texture> {
    let mut rng = XorShift::new(11);
    let cells: Vec<u8> = (0..64 * 64).map(|_| (rng.next_u64() % 256) as u8).collect();
    let mut px = Vec::with_capacity(128 * 128 * 4);
    for y in 0..128 {
        for x in 0..128 {
            let v = cells[(y / 2) * 64 + x / 2];
            px.extend_from_slice(&[v, v, v, 255]);
        }
    }
    Arc::new(Texture::from_rgba8(128, 128, &px, Encoding::Srgb).expect("a texture"))
}

/// A textured square of `size` facing +z, and its material.
fn card(size: f32) -> (Mesh, Material) {
    let mut mesh = procedural::quad(size, size);
    mesh.colors.clear();
    let material = Material::unlit(Rgba::WHITE)
        .with_texture(noise())
        .double_sided(true);
    (mesh, material)
}

/// The left camera: 5 units in front of the origin, looking at it.
pub(super) fn camera() -> Camera {
    Camera::look_at(
        Vec3::new(0.0, 0.0, 5.0),
        Vec3::ZERO,
        Vec3::Y,
        0.8,
        W as f32 / H as f32,
    )
    .with_depth_range(0.1, 50.0)
}

/// The slanted card and a small card in front of it, as meshes, materials and transforms
/// (to draw from any cameras).
pub(crate) fn scene_draws() -> (Vec<(Mesh, Material)>, Vec<Mat4>) {
    let transforms = vec![
        Mat4::from_rotation_y(0.6),
        Mat4::from_translation(Vec3::new(0.3, 0.2, 2.0)),
    ];
    (vec![card(12.0), card(1.0)], transforms)
}

/// [`scene_draws`] as draws, handed to `f`.
pub(crate) fn with_scene_draws<R>(f: impl FnOnce(&[Draw<'_>]) -> R) -> R {
    let (parts, transforms) = scene_draws();
    let draws: Vec<Draw<'_>> = parts
        .iter()
        .zip(&transforms)
        .map(|((mesh, material), &transform)| Draw {
            mesh,
            material,
            transform,
        })
        .collect();
    f(&draws)
}

/// A pair of the cards `(size, transform)`.
pub(super) fn pair(cards: &[(f32, Mat4)]) -> StereoPair {
    let made: Vec<(Mesh, Material)> = cards.iter().map(|&(s, _)| card(s)).collect();
    let draws: Vec<Draw<'_>> = made
        .iter()
        .zip(cards)
        .map(|((mesh, material), &(_, transform))| Draw {
            mesh,
            material,
            transform,
        })
        .collect();
    StereoPair::render(&draws, &Lighting::default(), &camera(), BASELINE, W, H)
}

/// A large card through the origin facing the cameras.
pub(super) fn plane() -> StereoPair {
    pair(&[(12.0, Mat4::IDENTITY)])
}

/// The large card, and a small one 2.5 units in front of it hiding part of it from the
/// right camera.
pub(super) fn occluded() -> StereoPair {
    pair(&[
        (12.0, Mat4::IDENTITY),
        (1.2, Mat4::from_translation(Vec3::new(0.0, 0.0, 2.5))),
    ])
}

/// A flat grey wall (no texture at all) through the origin, and a textured card 2.5 units
/// in front of it.
pub(super) fn textureless() -> StereoPair {
    let mut wall = procedural::quad(12.0, 12.0);
    wall.colors.clear();
    let grey = Material::unlit(Rgba::new(0.4, 0.4, 0.4, 1.0)).double_sided(true);
    let (card, textured) = card(1.2);
    let draws = [
        Draw {
            mesh: &wall,
            material: &grey,
            transform: Mat4::IDENTITY,
        },
        Draw {
            mesh: &card,
            material: &textured,
            transform: Mat4::from_translation(Vec3::new(0.0, 0.0, 2.5)),
        },
    ];
    StereoPair::render(&draws, &Lighting::default(), &camera(), BASELINE, W, H)
}

/// The large card turned 35 degrees about the vertical: disparity changing along rows.
pub(super) fn slanted() -> StereoPair {
    pair(&[(12.0, Mat4::from_rotation_y(0.6))])
}

/// The slanted card rendered from `camera` (colour and depth), the truth for a view of
/// [`slanted`]'s scene.
pub(super) fn slanted_truth(camera: &Camera) -> crate::core::DepthImage {
    let (mesh, material) = card(12.0);
    let draws = [Draw {
        mesh: &mesh,
        material: &material,
        transform: Mat4::from_rotation_y(0.6),
    }];
    let mut out = crate::core::capture_batch(&draws, &[*camera], &Lighting::default(), W, H);
    out.remove(0)
}

/// Left pixels the right view cannot see, away from the left image's edge strip.
pub(super) fn occluded_band(p: &StereoPair) -> Vec<usize> {
    let w = W as usize;
    (0..p.visible.len())
        .filter(|&i| !p.visible[i] && i % w > 40 && p.truth.known(i))
        .collect()
}
