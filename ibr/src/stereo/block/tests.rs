//! The block matcher on rendered pairs with exact ground truth.

use super::*;
use crate::stereo::measure::measure;
use crate::stereo::pair::StereoPair;
use engine::procedural::{self, XorShift};
use engine::{Camera, Draw, Encoding, Lighting, Material, Mesh, Rgba, Texture};
use glam::{Mat4, Vec3};
use std::sync::Arc;

const W: u32 = 160;
const H: u32 = 120;

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

/// A textured square of `size`, facing +z, at `at`.
fn card(size: f32, texture: &Arc<Texture>) -> (Mesh, Material) {
    let mut mesh = procedural::quad(size, size);
    mesh.colors.clear();
    let material = Material::unlit(Rgba::WHITE)
        .with_texture(texture.clone())
        .double_sided(true);
    (mesh, material)
}

fn camera() -> Camera {
    Camera::look_at(
        Vec3::new(0.0, 0.0, 5.0),
        Vec3::ZERO,
        Vec3::Y,
        0.8,
        W as f32 / H as f32,
    )
    .with_depth_range(0.1, 50.0)
}

fn matcher() -> BlockMatch {
    BlockMatch {
        max_disparity: 32,
        ..BlockMatch::default()
    }
}

#[test]
fn a_textured_plane_facing_the_cameras_is_matched_to_a_fraction_of_a_pixel() {
    let texture = noise();
    let (mesh, material) = card(12.0, &texture);
    let draws = [Draw {
        mesh: &mesh,
        material: &material,
        transform: Mat4::IDENTITY,
    }];
    let pair = StereoPair::render(&draws, &Lighting::default(), &camera(), 0.4, W, H);
    // Disparity fx b / z, the same everywhere: about 11.6 pixels.
    let want = pair.focal_px * 0.4 / 5.0;
    let mid = (H / 2 * W + W / 2) as usize;
    assert!(
        (pair.truth.data[mid] - want).abs() < 1e-3 && want > 8.0,
        "{want}"
    );
    let (l, r) = (luminance(&pair.left), luminance(&pair.right));
    let est = matcher().run(&l, &r, W, H);
    let m = measure(&est, &pair.truth, Some(&pair.visible)).unwrap();
    assert!(m.nonocc.pixels > 15_000, "{m:?}");
    // (Measured: 4.2% off, all of them the image border no window fits; RMS 0.15 pixels.)
    assert!(m.nonocc.bad1 < 0.08, "{m:?}");
    assert!(m.nonocc.rms < 0.3, "{m:?}");
    // Only the strip the right camera cannot see (the left image's left edge) is occluded.
    let occluded = pair.visible.iter().filter(|v| !**v).count();
    assert!(occluded as f32 <= (want + 2.0) * H as f32, "{occluded}");
}

#[test]
fn the_left_right_check_leaves_occluded_pixels_unknown() {
    let texture = noise();
    let (back, back_material) = card(12.0, &texture);
    let (front, front_material) = card(1.2, &texture);
    let draws = [
        Draw {
            mesh: &back,
            material: &back_material,
            transform: Mat4::IDENTITY,
        },
        Draw {
            mesh: &front,
            material: &front_material,
            transform: Mat4::from_translation(Vec3::new(0.0, 0.0, 2.5)),
        },
    ];
    let pair = StereoPair::render(&draws, &Lighting::default(), &camera(), 0.4, W, H);
    let (l, r) = (luminance(&pair.left), luminance(&pair.right));
    let est = matcher().run(&l, &r, W, H);
    let m = measure(&est, &pair.truth, Some(&pair.visible)).unwrap();
    // (Measured: 7.5%, the borders and the card's edges.)
    assert!(m.nonocc.bad2 < 0.12, "{m:?}");
    // The band of the back plane left of the front card that the right camera cannot see
    // (the card hides it there): mostly left unknown, not matched to something wrong.
    let w = W as usize;
    let band: Vec<usize> = (0..pair.visible.len())
        .filter(|&i| !pair.visible[i] && i % w > 40 && pair.truth.known(i))
        .collect();
    assert!(band.len() > 100, "{} occluded pixels", band.len());
    let unknown = band.iter().filter(|&&i| !est.known(i)).count();
    assert!(
        unknown * 2 > band.len(),
        "{unknown} of {} occluded pixels unknown",
        band.len()
    );
}
