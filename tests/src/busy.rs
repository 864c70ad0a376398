//! A busy scene for whole-pipeline tests (determinism, allocations): a few thousand
//! triangles with opaque, alpha-tested, alpha-blended and additive materials, textures
//! (trilinear and nearest), vertex colours, lighting, and geometry crossing the near plane
//! and the guard band.

use crate::scenes::Rng;
use engine::{
    AlphaMode, BlendMode, Camera, Filter, Material, Mesh, Rgba, Sampler, Scene, Texture, Wrap,
};
use glam::{Mat4, Vec2, Vec3};
use std::sync::Arc;

/// A ground grid reaching behind the eye, with uvs.
fn ground(n: u32, half: f32) -> Mesh {
    let mut m = Mesh::default();
    for j in 0..=n {
        for i in 0..=n {
            let x = -half + 2.0 * half * i as f32 / n as f32;
            let z = -half + 2.0 * half * j as f32 / n as f32;
            m.positions.push(Vec3::new(x, 0.0, z));
            m.normals.push(Vec3::Y);
            m.uvs.push(Vec2::new(x / 4.0, z / 4.0));
        }
    }
    for j in 0..n {
        for i in 0..n {
            let a = j * (n + 1) + i;
            // Counter-clockwise seen from above (+Y).
            m.indices
                .extend([a, a + n + 1, a + n + 2, a, a + n + 2, a + 1]);
        }
    }
    m
}

/// `count` random triangles in a box, with vertex colours (alpha varying) and uvs.
fn confetti(rng: &mut Rng, count: usize, lo: Vec3, hi: Vec3, size: f32) -> Mesh {
    let mut m = Mesh::default();
    let r = |rng: &mut Rng, a: f32, b: f32| rng.range(a as f64, b as f64) as f32;
    for t in 0..count {
        let c = Vec3::new(r(rng, lo.x, hi.x), r(rng, lo.y, hi.y), r(rng, lo.z, hi.z));
        for _ in 0..3 {
            let d = Vec3::new(
                r(rng, -size, size),
                r(rng, -size, size),
                r(rng, -size, size),
            );
            m.positions.push(c + d);
            m.uvs.push(Vec2::new(r(rng, -1.0, 2.0), r(rng, -1.0, 2.0)));
            m.colors.push(Rgba::new(
                r(rng, 0.0, 1.0),
                r(rng, 0.0, 1.0),
                r(rng, 0.0, 1.0),
                r(rng, 0.2, 1.0),
            ));
        }
        let b = 3 * t as u32;
        m.indices.extend([b, b + 1, b + 2]);
    }
    m.compute_normals();
    m
}

/// The scene and a camera standing in it, low over the ground.
pub fn busy_scene(width: u32, height: u32) -> (Scene, Camera) {
    let mut rng = Rng(0x5eed);
    let mut scene = Scene::default();
    let checker = Arc::new(Texture::checker(
        64,
        8,
        Rgba::new(0.9, 0.8, 0.2, 1.0),
        Rgba::new(0.1, 0.2, 0.6, 1.0),
    ));
    let mut mask_texels = Vec::new();
    for y in 0..16u32 {
        for x in 0..16u32 {
            let on = (x * x + y * y) % 7 < 4;
            mask_texels.extend([
                200,
                (x * 16) as u8,
                (y * 16) as u8,
                if on { 255 } else { 30 },
            ]);
        }
    }
    let mask =
        Arc::new(Texture::from_rgba8(16, 16, &mask_texels, engine::Encoding::Srgb).expect("16x16"));

    scene.add(
        ground(40, 60.0),
        Material::lit(Rgba::WHITE).with_texture(checker.clone()),
        Mat4::IDENTITY,
    );
    scene.add(
        confetti(
            &mut rng,
            1200,
            Vec3::new(-6.0, 0.0, -25.0),
            Vec3::new(6.0, 4.0, -2.0),
            0.8,
        ),
        Material::lit(Rgba::new(0.8, 0.8, 0.8, 1.0)).double_sided(true),
        Mat4::IDENTITY,
    );
    scene.add(
        confetti(
            &mut rng,
            600,
            Vec3::new(-4.0, 0.0, -15.0),
            Vec3::new(4.0, 3.0, -1.0),
            0.6,
        ),
        Material {
            alpha_mode: AlphaMode::Mask { cutoff: 0.5 },
            sampler: Sampler {
                filter: Filter::Nearest,
                wrap_u: Wrap::Mirror,
                wrap_v: Wrap::Clamp,
            },
            ..Material::unlit(Rgba::WHITE)
                .with_texture(mask)
                .double_sided(true)
        },
        Mat4::from_rotation_y(0.3),
    );
    scene.add(
        confetti(
            &mut rng,
            700,
            Vec3::new(-5.0, 0.2, -20.0),
            Vec3::new(5.0, 3.5, 0.5),
            1.2,
        ),
        Material::unlit(Rgba::new(1.0, 1.0, 1.0, 0.6))
            .blended(BlendMode::Alpha)
            .double_sided(true),
        Mat4::IDENTITY,
    );
    scene.add(
        confetti(
            &mut rng,
            400,
            Vec3::new(-5.0, 0.2, -20.0),
            Vec3::new(5.0, 3.5, 0.5),
            1.0,
        ),
        Material {
            soft_distance: 0.3,
            ..Material::unlit(Rgba::new(0.3, 0.2, 0.1, 0.5))
                .with_texture(checker)
                .blended(BlendMode::Additive)
                .double_sided(true)
        },
        Mat4::from_translation(Vec3::new(0.5, 0.0, 0.0)),
    );
    // Huge triangles: one past the guard band, one through the near plane.
    scene.add(
        crate::scenes::soup(&[
            [
                Vec3::new(-1e5, 30.0, -90.0),
                Vec3::new(1e5, 30.0, -90.0),
                Vec3::new(0.0, 1e5, -90.0),
            ],
            [
                Vec3::new(-0.5, 0.3, 5.0),
                Vec3::new(0.8, 0.1, -3.0),
                Vec3::new(-0.3, 1.5, -2.0),
            ],
        ]),
        Material::lit(Rgba::new(0.4, 0.6, 0.9, 1.0)).double_sided(true),
        Mat4::IDENTITY,
    );
    let camera = Camera::look_at(
        Vec3::new(0.2, 1.0, 3.0),
        Vec3::new(0.0, 0.8, -10.0),
        Vec3::Y,
        1.1,
        1.0,
    )
    .with_aspect(width, height)
    .with_depth_range(0.1, 100.0);
    (scene, camera)
}
