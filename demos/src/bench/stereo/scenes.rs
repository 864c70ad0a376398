//! The stereo sweep's pairs, rendered with exact ground truth: the kinds of scene the
//! Middlebury sets hold and matchers fail on.

use crate::showcase::{self, Showcase};
use engine::procedural::{self, XorShift};
use engine::{Camera, Draw, Encoding, Lighting, Material, Mesh, Rgba, Texture};
use glam::{Mat4, Vec3};
use ibr::capture::capture_batch;
use ibr::stereo::{rectify, StereoPair};
use std::sync::Arc;

/// A named pair.
#[derive(Clone, Debug)]
pub struct Scene {
    pub name: String,
    pub pair: StereoPair,
}

/// The baseline of the card scenes: at 640x480 the nearest card (3 units from the
/// cameras) lies about 51 pixels apart, the wall behind (5 units) about 20.
const BASELINE: f32 = 0.18;

/// A 512x512 grey texture, `texel(x, y)` each.
fn texture(texel: impl Fn(u32, u32) -> u8) -> Arc<Texture> {
    let mut px = Vec::with_capacity(512 * 512 * 4);
    for y in 0..512 {
        for x in 0..512 {
            let v = texel(x, y);
            px.extend_from_slice(&[v, v, v, 255]);
        }
    }
    Arc::new(Texture::from_rgba8(512, 512, &px, Encoding::Srgb).expect("a texture"))
}

/// Random grey levels between `lo` and `hi`, in blocks of 2x2 texels.
fn noise(seed: u64, lo: u8, hi: u8) -> Arc<Texture> {
    let mut rng = XorShift::new(seed);
    let span = u64::from(hi - lo) + 1;
    let cells: Vec<u8> = (0..256 * 256)
        .map(|_| lo + (rng.next_u64() % span) as u8)
        .collect();
    texture(|x, y| cells[(y / 2 * 256 + x / 2) as usize])
}

/// A 16x16-texel tile of random grey blocks, repeated: textured everywhere, but the same
/// match every 16 texels (at 640x480 about 43 pixels on the wall, within the search).
fn repeated() -> Arc<Texture> {
    let mut rng = XorShift::new(23);
    let tile: Vec<u8> = (0..64).map(|_| (rng.next_u64() % 256) as u8).collect();
    texture(|x, y| tile[(y / 2 % 8 * 8 + x / 2 % 8) as usize])
}

/// A textured square of `size` facing +z.
fn card(size: f32, texture: &Arc<Texture>) -> (Mesh, Material) {
    let mut mesh = procedural::quad(size, size);
    mesh.colors.clear();
    let material = Material::unlit(Rgba::WHITE)
        .with_texture(texture.clone())
        .double_sided(true);
    (mesh, material)
}

/// The left camera of the card scenes: 5 units in front of the wall at the origin.
fn camera(w: u32, h: u32) -> Camera {
    Camera::look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 0.8, 1.0)
        .with_aspect(w, h)
        .with_depth_range(0.1, 50.0)
}

/// Meshes with materials and their transforms.
type Parts = Vec<((Mesh, Material), Mat4)>;

fn draws(parts: &Parts) -> Vec<Draw<'_>> {
    parts
        .iter()
        .map(|((mesh, material), transform)| Draw {
            mesh,
            material,
            transform: *transform,
        })
        .collect()
}

/// A wall of `texture` and two cards in front of it, 2.0 and 1.0 units out.
fn cards(texture: &Arc<Texture>) -> Parts {
    vec![
        (card(12.0, texture), Mat4::IDENTITY),
        (
            card(1.4, texture),
            Mat4::from_translation(Vec3::new(-0.6, 0.2, 1.0)),
        ),
        (
            card(0.8, texture),
            Mat4::from_translation(Vec3::new(0.7, -0.3, 2.0)),
        ),
    ]
}

/// The pairs, `w` x `h` each: plaza, cards, slanted, thin, low-texture, repeated,
/// unrectified.
pub fn scenes(w: u32, h: u32) -> Vec<Scene> {
    let lighting = Lighting::default();
    let rendered = |name: &str, parts: &Parts| Scene {
        name: name.into(),
        pair: StereoPair::render(&draws(parts), &lighting, &camera(w, h), BASELINE, w, h),
    };
    let textured = noise(11, 0, 255);
    let mut out = vec![plaza(w, h), rendered("cards", &cards(&textured))];
    out.push(rendered(
        "slanted",
        &vec![(card(14.0, &textured), Mat4::from_rotation_y(0.6))],
    ));
    let mut thin = vec![(card(12.0, &textured), Mat4::IDENTITY)];
    let mut bar = procedural::cuboid(Vec3::new(0.05, 3.0, 0.05));
    bar.colors.clear();
    let dark = Material::unlit(Rgba::new(0.15, 0.15, 0.15, 1.0));
    for k in 0..6 {
        let x = -1.5 + 0.6 * k as f32;
        thin.push((
            (bar.clone(), dark.clone()),
            Mat4::from_translation(Vec3::new(x, 0.0, 2.0)),
        ));
    }
    out.push(rendered("thin", &thin));
    out.push(rendered("low-texture", &cards(&noise(5, 120, 136))));
    out.push(repeated_pair(w, h));
    out.push(unrectified(w, h, &cards(&textured), &lighting));
    out
}

/// The `repeated` pair alone: the wall and cards of one repeated 16-texel tile.
pub fn repeated_pair(w: u32, h: u32) -> Scene {
    let parts = cards(&repeated());
    Scene {
        name: "repeated".into(),
        pair: StereoPair::render(
            &draws(&parts),
            &Lighting::default(),
            &camera(w, h),
            BASELINE,
            w,
            h,
        ),
    }
}

/// The showcase's plaza seen from its edge (a 0.3-unit baseline).
fn plaza(w: u32, h: u32) -> Scene {
    let show = Showcase::new();
    let draws: Vec<Draw<'_>> = show.scene.draws().collect();
    let camera = showcase::camera(Vec3::new(-3.0, 3.0, 12.0), Vec3::new(0.0, 1.0, 0.0), w, h);
    Scene {
        name: "plaza".into(),
        pair: StereoPair::render(&draws, &show.scene.lighting, &camera, 0.3, w, h),
    }
}

/// The cards seen by a right camera turned 3 degrees toward them and raised a little:
/// rectified from the known cameras, then matched; the truth is the scene rendered from
/// the rectified cameras.
fn unrectified(w: u32, h: u32, parts: &Parts, lighting: &Lighting) -> Scene {
    let left = camera(w, h);
    let eye = Vec3::new(BASELINE, 0.02, 5.0);
    let right = Camera::look_at(eye, Vec3::new(-0.26, 0.0, 0.0), Vec3::Y, 0.8, 1.0)
        .with_aspect(w, h)
        .with_depth_range(0.1, 50.0);
    let drawn = draws(parts);
    let [l, r]: [_; 2] = capture_batch(&drawn, &[left, right], lighting, w, h)
        .try_into()
        .expect("two views");
    let rect = rectify(&l, &r).expect("a sideways baseline");
    let truth = StereoPair::render(&drawn, lighting, &rect.left.camera, rect.baseline, w, h);
    Scene {
        name: "unrectified".into(),
        pair: StereoPair {
            left: rect.left,
            right: rect.right,
            ..truth
        },
    }
}
