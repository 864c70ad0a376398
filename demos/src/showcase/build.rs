//! Construction of the showcase scene: terrain and plaza, props, house, vegetation, the
//! lights, and the image-based layer on top.

use super::lod::TourLod;
use super::textures::{crate_texture, lattice_texture};
use super::{lamp_position, Showcase};
use crate::showcase::ibr_layer::IbrLayer;
use crate::showcase::impostors;
use engine::procedural::{self, Terrain, TreeKind, XorShift};
use engine::{AlphaMode, Instance, Light, Lighting, Material, Mesh, Rgba, Scene, Shading, Texture};
use glam::{Mat4, Quat, Vec3};
use std::sync::Arc;

/// Adds a mesh and a material without an instance; returns their indices.
fn push(scene: &mut Scene, mesh: Mesh, material: Material) -> (usize, usize) {
    scene.meshes.push(mesh);
    scene.materials.push(material);
    (scene.meshes.len() - 1, scene.materials.len() - 1)
}

/// Adds one instance of an existing mesh and material.
fn instance(scene: &mut Scene, mesh: usize, material: usize, transform: Mat4) -> usize {
    scene.instances.push(Instance {
        mesh,
        material,
        transform,
    });
    scene.instances.len() - 1
}

/// A lit material of `color` with a specular highlight.
fn lit(color: Rgba, specular: f32, shininess: f32) -> Material {
    Material {
        shading: Shading::Lit {
            specular,
            shininess,
        },
        ..Material::lit(color)
    }
}

/// A lit material with almost no highlight.
fn matte(c: Rgba) -> Material {
    lit(c, 0.05, 8.0)
}

/// The showcase scene, built step by step (each step adds its meshes, materials and
/// instances in turn; the order is the scene's), then animated to time 0.
pub(super) fn build() -> Showcase {
    let mut s = Scene::default();
    let terrain = Terrain {
        size: 120.0,
        cells: 120,
        height: 12.0,
        feature: 22.0,
        flat_radius: 12.0,
        seed: 7,
    };
    let ground_at = ground(&mut s, &terrain);
    let torus = centre_piece(&mut s);
    let sphere = procedural::uv_sphere(1.0, 24, 48);
    let mut balls = spheres(&mut s, &sphere);
    crates(&mut s);
    fence(&mut s);
    balls.push(glass(&mut s, &sphere));
    let lamp = lamp(&mut s);
    let house_at = house(&mut s);
    vegetation(&mut s, &terrain);
    s.lighting = lighting(house_at);
    let ibr = IbrLayer::new(&mut s, &terrain);
    let lod = TourLod::new(terrain.cells, ground_at, (torus, TORUS.0, TORUS.1), balls);
    let mut show = Showcase {
        scene: s,
        terrain,
        ibr,
        lod,
        torus,
        lamp,
        lamp_light: 1,
        draws: None,
        low_res_scale: super::CLOUD_LOW_RES,
    };
    show.animate(0.0);
    show
}

/// The torus's major and minor radii.
const TORUS: (f32, f32) = (1.1, 0.38);

/// Ground: vertex-coloured terrain and a checker-textured plaza; the terrain's instance.
fn ground(s: &mut Scene, terrain: &Terrain) -> usize {
    let at = s.add(terrain.mesh(), matte(Rgba::WHITE), Mat4::IDENTITY);
    let stone = Texture::checker(
        256,
        8,
        Rgba::from_srgb8(200, 196, 186),
        Rgba::from_srgb8(120, 118, 112),
    );
    let mut plaza = procedural::plane(14.0, 14.0, 4, 4);
    plaza.colors.clear();
    s.add(
        plaza,
        matte(Rgba::WHITE).with_texture(Arc::new(stone)),
        Mat4::from_translation(Vec3::new(0.0, 0.02, 0.0)),
    );
    at
}

/// Centre piece: a vertex-coloured torus over a stone pedestal; the torus's instance.
fn centre_piece(s: &mut Scene) -> usize {
    let mut pedestal = procedural::cylinder(0.7, 0.6, 24);
    pedestal.colors.clear();
    s.add(
        pedestal,
        matte(Rgba::from_srgb8(150, 146, 140)),
        Mat4::IDENTITY,
    );
    s.add(
        procedural::torus(TORUS.0, TORUS.1, 96, 48),
        lit(Rgba::WHITE, 0.5, 48.0),
        Mat4::IDENTITY,
    )
}

/// Lit spheres: red plastic, gold, chalk (one mesh, three materials); their instances.
fn spheres(s: &mut Scene, sphere: &Mesh) -> Vec<usize> {
    let mut placed = Vec::new();
    let mut plain_sphere = sphere.clone();
    plain_sphere.colors.clear();
    let (sphere_m, _) = push(s, plain_sphere, Material::default());
    for (color, spec, shin, scale, at) in [
        (
            Rgba::from_srgb8(200, 30, 30),
            0.7,
            64.0,
            1.0,
            Vec3::new(-4.5, 1.0, 2.0),
        ),
        (
            Rgba::from_srgb8(230, 170, 60),
            0.9,
            24.0,
            0.8,
            Vec3::new(4.6, 0.8, -2.2),
        ),
        (
            Rgba::from_srgb8(235, 235, 228),
            0.05,
            8.0,
            0.5,
            Vec3::new(-2.0, 0.5, 4.5),
        ),
    ] {
        s.materials.push(lit(color, spec, shin));
        let m = s.materials.len() - 1;
        let xf = Mat4::from_scale_rotation_translation(Vec3::splat(scale), Quat::IDENTITY, at);
        placed.push(instance(s, sphere_m, m, xf));
    }
    placed
}

/// Crates with a generated wood texture.
fn crates(s: &mut Scene) {
    let mut crate_mesh = procedural::cuboid(Vec3::ONE);
    crate_mesh.colors.clear();
    s.add(
        crate_mesh,
        matte(Rgba::WHITE).with_texture(crate_texture()),
        Mat4::from_scale_rotation_translation(
            Vec3::splat(1.4),
            Quat::from_rotation_y(0.35),
            Vec3::new(3.8, 0.7, 3.0),
        ),
    );
    let (crate_m, crate_mat) = (s.meshes.len() - 1, s.materials.len() - 1);
    instance(
        s,
        crate_m,
        crate_mat,
        Mat4::from_scale_rotation_translation(
            Vec3::splat(0.9),
            Quat::from_rotation_y(-0.2),
            Vec3::new(3.7, 1.85, 3.1),
        ),
    );
    instance(
        s,
        crate_m,
        crate_mat,
        Mat4::from_scale_rotation_translation(
            Vec3::splat(1.0),
            Quat::from_rotation_y(0.9),
            Vec3::new(5.4, 0.5, 1.6),
        ),
    );
}

/// Alpha-tested lattice fence behind the plaza, with posts.
fn fence(s: &mut Scene) {
    let fence_mat = Material {
        alpha_mode: AlphaMode::Mask { cutoff: 0.5 },
        ..matte(Rgba::WHITE)
            .with_texture(lattice_texture())
            .double_sided(true)
    };
    let mut panel = procedural::quad(2.0, 1.3);
    panel.colors.clear();
    let (panel_m, panel_mat) = push(s, panel, fence_mat);
    let mut post = procedural::cylinder(0.07, 1.5, 8);
    post.colors.clear();
    let (post_m, post_mat) = push(s, post, matte(Rgba::from_srgb8(110, 90, 70)));
    let z = -6.5;
    for k in 0..7 {
        let x = -6.0 + 2.0 * k as f32;
        let at = Mat4::from_translation(Vec3::new(x, 0.0, z));
        instance(s, post_m, post_mat, at);
        if k < 6 {
            let at = Mat4::from_translation(Vec3::new(x + 1.0, 0.75, z));
            instance(s, panel_m, panel_mat, at);
        }
    }
}

/// Blended glass: a tinted cube by the fence and a sphere in front of the plaza; the
/// sphere's instance.
fn glass(s: &mut Scene, sphere: &Mesh) -> usize {
    let glass = |tint: Rgba| Material {
        alpha_mode: AlphaMode::Blend,
        ..lit(tint, 1.2, 96.0)
    };
    let mut glass_cube = procedural::cuboid(Vec3::new(1.8, 1.8, 1.8));
    glass_cube.colors.clear();
    s.add(
        glass_cube,
        glass(Rgba::new(0.35, 0.6, 0.95, 0.35)),
        Mat4::from_scale_rotation_translation(
            Vec3::ONE,
            Quat::from_rotation_y(0.5),
            Vec3::new(-2.6, 0.92, -3.4),
        ),
    );
    let mut glass_ball = sphere.clone();
    glass_ball.colors.clear();
    s.add(
        glass_ball,
        glass(Rgba::new(0.5, 0.95, 0.6, 0.3)),
        Mat4::from_scale_rotation_translation(
            Vec3::splat(0.9),
            Quat::IDENTITY,
            Vec3::new(1.6, 0.92, 4.2),
        ),
    )
}

/// The lamp: an emissive ball marking the orbiting point light; its instance.
fn lamp(s: &mut Scene) -> usize {
    let mut lamp_mesh = procedural::uv_sphere(0.15, 8, 16);
    lamp_mesh.colors.clear();
    s.add(
        lamp_mesh,
        Material::unlit(Rgba::new(1.0, 0.75, 0.35, 1.0)),
        Mat4::IDENTITY,
    )
}

/// A house (its own blue door light is in [`lighting`]); where it stands.
fn house(s: &mut Scene) -> Mat4 {
    let house_at = Mat4::from_translation(Vec3::new(-9.5, 0.0, -1.5)) * Mat4::from_rotation_y(0.6);
    s.add(
        procedural::house(4.0, 3.2, 2.4, 1.6),
        matte(Rgba::WHITE),
        house_at,
    );
    house_at
}

/// Trees and rocks on the hills around the plaza (instanced variants).
fn vegetation(s: &mut Scene, terrain: &Terrain) {
    let mut rng = XorShift::new(2024);
    let mut variants = Vec::new();
    for (k, kind) in [
        TreeKind::Pine,
        TreeKind::Pine,
        TreeKind::Broadleaf,
        TreeKind::Broadleaf,
    ]
    .into_iter()
    .enumerate()
    {
        s.meshes.push(procedural::tree(kind, 1.0, k as u64 + 1));
        variants.push(s.meshes.len() - 1);
    }
    s.materials.push(matte(Rgba::WHITE));
    let veg = s.materials.len() - 1;
    let mut placed = 0;
    while placed < 48 {
        let a = rng.range(0.0, std::f32::consts::TAU);
        let r = rng.range(21.0, 44.0);
        let (x, z) = (r * a.cos(), r * a.sin());
        let h = rng.range(3.5, 7.0);
        if impostors::in_city(x, z, 2.0) {
            continue;
        }
        let y = terrain.height_at(x, z) - 0.1;
        let v = variants[(rng.next_u64() % variants.len() as u64) as usize];
        let xf = Mat4::from_scale_rotation_translation(
            Vec3::splat(h),
            Quat::from_rotation_y(rng.range(0.0, 6.0)),
            Vec3::new(x, y, z),
        );
        instance(s, v, veg, xf);
        placed += 1;
    }
    for (k, (x, z, h)) in [(-12.0, -4.5, 5.0), (-7.5, -9.5, 4.2), (-4.0, -11.0, 4.6)]
        .into_iter()
        .enumerate()
    {
        instance(
            s,
            variants[k % variants.len()],
            veg,
            Mat4::from_scale_rotation_translation(
                Vec3::splat(h),
                Quat::IDENTITY,
                Vec3::new(x, terrain.height_at(x, z), z),
            ),
        );
    }
    let mut rocks = Vec::new();
    for k in 0..3 {
        s.meshes.push(procedural::rock(1.0, 40 + k));
        rocks.push(s.meshes.len() - 1);
    }
    for k in 0..28 {
        let a = rng.range(0.0, std::f32::consts::TAU);
        let r = if k < 6 {
            rng.range(7.6, 11.0)
        } else {
            rng.range(12.0, 34.0)
        };
        let (x, z) = (r * a.cos(), r * a.sin());
        let size = rng.range(0.3, 1.2);
        if impostors::in_city(x, z, 1.0) {
            continue;
        }
        let xf = Mat4::from_scale_rotation_translation(
            Vec3::splat(size),
            Quat::from_rotation_y(rng.range(0.0, 6.0)),
            Vec3::new(x, terrain.height_at(x, z) + 0.1 * size, z),
        );
        instance(s, rocks[k % rocks.len()], veg, xf);
    }
}

/// The sun, the orbiting lamp's light and the house's blue door light.
fn lighting(house_at: Mat4) -> Lighting {
    Lighting {
        ambient: Rgba::new(0.2, 0.23, 0.3, 1.0),
        lights: vec![
            Light::Directional {
                direction: Vec3::new(-0.45, -0.75, -0.5).normalize(),
                color: Rgba::new(1.05, 0.97, 0.86, 1.0),
            },
            Light::Point {
                position: lamp_position(0.0),
                color: Rgba::new(3.0, 1.8, 0.7, 1.0),
                range: 7.0,
            },
            Light::Point {
                position: house_at.transform_point3(Vec3::new(0.0, 1.9, 2.4)),
                color: Rgba::new(0.6, 1.0, 3.0, 1.0),
                range: 6.0,
            },
        ],
    }
}
