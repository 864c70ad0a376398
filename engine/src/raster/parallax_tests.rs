//! A nailboard's parallax search ([`crate::material::DepthOffset::parallax`]) against the
//! mesh it stands for: a sphere whose colour tells where on it a pixel looks, imaged
//! orthographically (as a billboard's views are baked) and seen in perspective from near.

use super::nailboard_tests::nailboard;
use crate::material::{AlphaMode, DepthOffset, Material};
use crate::testing::on_threads;
use crate::texture::Texture;
use crate::{
    procedural, Camera, Draw, Encoding, FrameOptions, Lighting, Mesh, Renderer, Rgba, Target,
};
use glam::{Mat4, Vec3};
use std::sync::Arc;

const SIZE: u32 = 96;
const TEXELS: u32 = 128;
/// The eye on +z, the unit sphere at the origin: its front stands a fifth of the eye's
/// distance nearer than its centre, where an orthographic image is right.
const EYE: f32 = 5.0;
/// The quad's half side: it frames the sphere's orthographic image.
const HALF: f32 = 1.05;

/// The colour of the sphere's point `p`: its x and y as red and green.
fn tint(p: Vec3) -> Rgba {
    Rgba::new((p.x + 1.0) * 0.5, (p.y + 1.0) * 0.5, 0.5, 1.0)
}

/// The sphere seen along -z, orthographically, over the square of side `2 HALF` at the
/// plane `z = 0`: each texel's colour ([`tint`] of the point it sees) and its depth behind
/// the plane `z = 1` (the sphere's front, where the quad stands), in units of the side.
fn images() -> (Texture, Texture) {
    let n = TEXELS as usize;
    let (mut colour, mut depth) = (vec![0u32; n * n], vec![0u32; n * n]);
    let byte = |v: f32| (v.clamp(0.0, 1.0) * 255.0).round() as u32;
    for j in 0..n {
        for i in 0..n {
            let x = -HALF + (i as f32 + 0.5) / n as f32 * 2.0 * HALF;
            let y = HALF - (j as f32 + 0.5) / n as f32 * 2.0 * HALF;
            let r2 = x * x + y * y;
            if r2 >= 1.0 {
                continue;
            }
            let z = (1.0 - r2).sqrt();
            let c = tint(Vec3::new(x, y, z));
            colour[j * n + i] = byte(c.r) | byte(c.g) << 8 | byte(c.b) << 16 | 255 << 24;
            depth[j * n + i] = byte((1.0 - z) / (2.0 * HALF)) | 255 << 24;
        }
    }
    let tex = |t| Texture::from_packed(TEXELS, TEXELS, t, Encoding::Unorm, true).expect("image");
    (tex(colour), tex(depth))
}

fn board_material(parallax: Option<f32>) -> Material {
    let (colour, depth) = images();
    // The quad at z = 1, the image right at z = 0.
    nailboard(colour, Some((depth, 1.0 / (2.0 * HALF))), parallax)
}

/// The sphere's colours (`[r, g]` bytes) and the board's, where each covers, rendered on
/// `threads` threads.
fn render(draw: Draw<'_>, threads: usize) -> Vec<Option<[u8; 2]>> {
    let mut target = Target::new(SIZE, SIZE);
    let opts = FrameOptions {
        clear: Some(Rgba::TRANSPARENT),
        ..FrameOptions::default()
    };
    let cam = Camera::look_at(Vec3::new(0.0, 0.0, EYE), Vec3::ZERO, Vec3::Y, 0.6, 1.0);
    on_threads(threads, || {
        Renderer::new().render([draw], &cam, &Lighting::default(), &mut target, &opts)
    });
    target
        .to_rgba8_premultiplied()
        .chunks(4)
        .map(|p| (p[3] > 0).then_some([p[0], p[1]]))
        .collect()
}

/// The pixels one of `a` and `b` covers and the other not, and the mean level
/// difference (red and green) where both do.
fn compare(a: &[Option<[u8; 2]>], b: &[Option<[u8; 2]>]) -> (usize, usize, f32) {
    let (mut both, mut one, mut off) = (0, 0, 0u32);
    for (p, q) in a.iter().zip(b) {
        match (p, q) {
            (Some(p), Some(q)) => {
                both += 1;
                off += (0..2).map(|c| p[c].abs_diff(q[c]) as u32).sum::<u32>();
            }
            (None, None) => {}
            _ => one += 1,
        }
    }
    (both, one, off as f32 / (2 * both.max(1)) as f32)
}

#[test]
fn with_parallax_a_nailboard_shows_the_surface_each_ray_meets() {
    let mut sphere = procedural::uv_sphere(1.0, 64, 128);
    sphere.colors = sphere.positions.iter().map(|&p| tint(p)).collect();
    let white = Material::unlit(Rgba::WHITE);
    let quad: Mesh = procedural::quad(2.0 * HALF, 2.0 * HALF);
    // The image's square at z = 0 scaled about the eye into the plane z = 1.
    let eye = Vec3::new(0.0, 0.0, EYE);
    let s = (EYE - 1.0) / EYE;
    let board = |m| Draw {
        mesh: &quad,
        material: m,
        transform: Mat4::from_translation(eye)
            * Mat4::from_scale(Vec3::splat(s))
            * Mat4::from_translation(-eye),
    };
    let mesh = render(
        Draw {
            mesh: &sphere,
            material: &white,
            transform: Mat4::IDENTITY,
        },
        2,
    );
    let (flat, searched) = (board_material(None), board_material(Some(0.03)));
    let (both, flat_one, flat_off) = compare(&mesh, &render(board(&flat), 2));
    let with = render(board(&searched), 2);
    let (_, one, off) = compare(&mesh, &with);
    // Measured: 3,016 pixels both cover; the colours 6.63 levels off flat (each pixel
    // shows the point straight behind it, up to a fifth of the radius away), 0.79 with the
    // search; the outline off on 140 and 108 pixels (the search does not dilate it).
    assert!(both > 2000, "{both}");
    assert!(
        off < 1.5 && off * 4.0 < flat_off,
        "colours off by {off} levels with the search, {flat_off} flat"
    );
    assert!(
        one <= flat_one && one * 100 < both * 5,
        "outline off on {one} with the search, {flat_one} flat, of {both}"
    );
    assert_eq!(with, render(board(&searched), 1), "one thread and two");
}

/// A nailboard's [`DepthOffset::max_lod`]: texels of scattered grey levels seen at a
/// quarter of their size read as the mean of 4 x 4 of them from the mip chain (level 2),
/// and as single texels, as scattered as the image, when the level is capped at 0.
#[test]
fn a_capped_level_of_detail_reads_the_finer_texels() {
    let n = 64u32;
    // Grey levels scattered by a hash of the texel's index.
    let noise = (0..n * n)
        .map(|i| ((i.wrapping_mul(2_654_435_761) >> 24) * 0x1_0101) | (255 << 24))
        .collect();
    let colour = Texture::from_packed(n, n, noise, Encoding::Unorm, true).expect("image");
    let flat = Texture::from_packed(
        n,
        n,
        vec![255 << 24; (n * n) as usize],
        Encoding::Unorm,
        true,
    )
    .expect("image");
    let (colour, flat) = (Arc::new(colour), Arc::new(flat));
    let quad = procedural::quad(1.0, 1.0);
    let spread = |max_lod: f32| {
        let material = Material {
            alpha_mode: AlphaMode::Mask { cutoff: 0.5 },
            depth_offset: Some(DepthOffset {
                texture: flat.clone(),
                scale: 1.0,
                lift: 0.0,
                parallax: None,
                max_lod,
            }),
            ..Material::unlit(Rgba::WHITE).with_texture(colour.clone())
        };
        // The unit quad 16 pixels wide: 4 texels a pixel.
        let d = 0.5 * (SIZE as f32 / 16.0) / 0.3f32.tan();
        let cam = Camera::look_at(Vec3::Z * d, Vec3::ZERO, Vec3::Y, 0.6, 1.0);
        let mut target = Target::new(SIZE, SIZE);
        let opts = FrameOptions {
            clear: Some(Rgba::TRANSPARENT),
            ..FrameOptions::default()
        };
        // Moved half a texel: the pixels' centres on the texels' (a texel's corner is
        // where 4 texels blend to grey on any level).
        let draw = Draw {
            mesh: &quad,
            material: &material,
            transform: Mat4::from_translation(Vec3::new(0.5, 0.5, 0.0) / n as f32),
        };
        Renderer::new().render([draw], &cam, &Lighting::default(), &mut target, &opts);
        let reds: Vec<f32> = target
            .to_rgba8_premultiplied()
            .chunks(4)
            .filter(|p| p[3] > 0)
            .map(|p| p[0] as f32)
            .collect();
        let mean = reds.iter().sum::<f32>() / reds.len().max(1) as f32;
        let var = reds.iter().map(|r| (r - mean) * (r - mean)).sum::<f32>();
        (reds.len(), (var / reds.len().max(1) as f32).sqrt())
    };
    let (n_mip, mip) = spread(f32::INFINITY);
    let (n_capped, capped) = spread(0.0);
    // Measured: standard deviations of 2.9 and 58.8 levels over the 256 pixels.
    assert_eq!((n_mip, n_capped), (256, 256));
    assert!(
        capped > 40.0 && mip < 15.0,
        "spread {capped} capped at level 0, {mip} from the mip chain"
    );
}

/// Odd triangles through the parallax search's setup (a zero-area one, one with a NaN
/// corner, one reaching behind the eye, one whose uvs are all the same point, so its
/// length per unit of `u` is infinite) draw without a panic, the same pixels on 1 and 2
/// threads, and the drawable ones draw.
#[test]
fn odd_triangles_through_the_parallax_search_neither_panic_nor_differ_by_threads() {
    use glam::Vec2;
    let material = board_material(Some(0.03)).double_sided(true);
    let p = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
    let mesh = Mesh {
        positions: vec![
            p(0.0, 0.0, 1.0),
            p(0.5, 0.5, 1.0),
            p(1.0, 1.0, 1.0),
            p(f32::NAN, 0.0, 1.0),
            p(0.5, 0.0, 1.0),
            p(0.0, 0.5, 1.0),
            p(-0.5, -0.5, 1.0),
            p(0.5, -0.5, 1.0),
            p(0.0, 0.5, 9.0),
            p(-0.5, 0.5, 0.5),
            p(0.5, 0.5, 0.5),
            p(0.0, -0.5, 0.5),
        ],
        uvs: [
            [0.0, 0.0],
            [0.5, 0.5],
            [1.0, 1.0],
            [0.0, 0.0],
            [1.0, 0.0],
            [0.0, 1.0],
            [0.0, 1.0],
            [1.0, 1.0],
            [0.5, 0.0],
            [0.5, 0.5],
            [0.5, 0.5],
            [0.5, 0.5],
        ]
        .iter()
        .map(|&[u, v]| Vec2::new(u, v))
        .collect(),
        indices: (0..12).collect(),
        ..Mesh::default()
    };
    let draw = Draw {
        mesh: &mesh,
        material: &material,
        transform: Mat4::IDENTITY,
    };
    let (one, two) = (render(draw, 1), render(draw, 2));
    assert_eq!(one, two, "one thread and two");
    let drawn = one.iter().filter(|p| p.is_some()).count();
    assert!(drawn > 0, "nothing drawn");
}
