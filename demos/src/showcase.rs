//! The showcase's built-in scene, its animation, its deterministic camera path and the fly
//! camera: everything the `showcase` binary shows, without the window, so it can be tested.
//!
//! The scene needs no download: a noise terrain with a flat plaza in the middle, a
//! vertex-coloured spinning torus on a pedestal, lit spheres, crates with a generated wood
//! texture, a checker-textured plaza, an alpha-tested lattice fence (`AlphaMode::Mask`),
//! blended glass (`AlphaMode::Blend`), a house, trees and rocks, lit by a sun and two point
//! lights (one orbiting the torus, marked by a glowing lamp). Its image-based layer
//! ([`crate::showcase_ibr`]) adds a billboard forest, a laser exchange with explosions,
//! the sun's lens flare, and a sky of clouds and a city district drawn through runtime
//! impostors ([`crate::showcase_impostors`]).

use crate::showcase_ibr::IbrLayer;
use crate::showcase_impostors::{self, CITY_CENTER};
use engine::procedural::{self, Terrain, TreeKind, XorShift};
use engine::{
    AlphaMode, Camera, Encoding, FrameOptions, FrameStats, Instance, Light, Lighting, Material,
    Mesh, Renderer, Rgba, Scene, Shading, Target, Texture,
};
use glam::{Mat4, Quat, Vec3};
use std::sync::Arc;

/// Clear colour of the showcase (a pale sky).
pub const SKY: Rgba = Rgba::new(0.42, 0.62, 0.86, 1.0);
/// Vertical field of view of the showcase cameras, radians.
pub const FOV_Y: f32 = 1.05;
/// Far plane of the showcase cameras.
pub const FAR: f32 = 250.0;

/// The scene plus the handles its animation needs.
#[derive(Debug)]
pub struct Showcase {
    pub scene: Scene,
    pub terrain: Terrain,
    /// Billboards, lasers, effects and the lens flare.
    pub ibr: IbrLayer,
    torus: usize,
    lamp: usize,
    lamp_light: usize,
}

impl Showcase {
    /// Builds the scene (deterministic: same triangles and pixels every time).
    pub fn new() -> Showcase {
        build()
    }

    /// Poses the animated parts at time `t` seconds: the torus spins, the lamp orbits, the
    /// lasers fire and the effects advance.
    pub fn animate(&mut self, t: f32) {
        self.ibr.pose(t);
        let s = &mut self.scene;
        s.instances[self.torus].transform = Mat4::from_translation(Vec3::new(0.0, 2.1, 0.0))
            * Mat4::from_rotation_y(t * 0.7)
            * Mat4::from_rotation_x(1.1 + 0.25 * (t * 0.9).sin());
        let p = lamp_position(t);
        s.instances[self.lamp].transform = Mat4::from_translation(p);
        if let Some(Light::Point { position, .. }) = s.lighting.lights.get_mut(self.lamp_light) {
            *position = p;
        }
    }
}

impl Showcase {
    /// The headless camera path, `(eye, target)` at frame `i` of `n`. The first third
    /// circles the plaza once, bobbing up and down; the rest rises over the billboard
    /// forest (looking down on the trees, past their fade to top-down sprites), comes back
    /// to look along the laser from just behind turret B, turns up toward the sun (lens
    /// flare), flies over the city district, climbs into a cloud and through it, and
    /// returns to the start. The eye stays 2.5 units above the ground.
    pub fn path(&self, i: usize, n: usize) -> (Vec3, Vec3) {
        const CIRCLE: f32 = 1.0 / 3.0;
        let f = (i % n.max(1)) as f32 / n.max(1) as f32;
        let (eye, target) = if f < CIRCLE {
            self.circle(f / CIRCLE)
        } else {
            let keys = self.flight_keys();
            let u = (f - CIRCLE) / (1.0 - CIRCLE) * (keys.len() - 1) as f32;
            let k = (u.floor() as usize).min(keys.len() - 2);
            let t = u - k as f32;
            let at = |j: isize| keys[j.clamp(0, keys.len() as isize - 1) as usize];
            let k = k as isize;
            let (p0, p1, p2, p3) = (at(k - 1), at(k), at(k + 1), at(k + 2));
            (
                catmull_rom(p0.0, p1.0, p2.0, p3.0, t),
                catmull_rom(p0.1, p1.1, p2.1, p3.1, t),
            )
        };
        let ground = self.terrain.height_at(eye.x, eye.z) + 2.5;
        (Vec3::new(eye.x, eye.y.max(ground), eye.z), target)
    }

    /// The plaza circle at fraction `f` of a turn.
    fn circle(&self, f: f32) -> (Vec3, Vec3) {
        let a = std::f32::consts::TAU * f + 0.6;
        let r = 17.0 + 1.5 * (2.0 * a).sin();
        let (x, z) = (r * a.cos(), r * a.sin());
        (
            Vec3::new(x, 4.8 + 1.4 * a.sin(), z),
            Vec3::new(0.0, 1.2, 0.0),
        )
    }

    /// Key poses of the flight: from the circle's end over the forest, along the laser,
    /// toward the sun, over the city, through a cloud and back to the circle's start.
    fn flight_keys(&self) -> Vec<(Vec3, Vec3)> {
        let [a, b] = self.ibr.turrets;
        let along = (b - a).normalize();
        let side = along.cross(Vec3::Y).normalize();
        let sun = self.scene.lighting.sun().map_or(Vec3::Y, |(d, _)| -d);
        let sun_eye = Vec3::new(-14.0, 9.0, -16.0);
        let start = self.circle(0.0);
        let city = Vec3::new(CITY_CENTER.x, 4.0, CITY_CENTER.y);
        // The cloud is entered from the south (over the city) at its centre's height and
        // left to the north: `2.2` radii out, so the approach starts outside the band in
        // which its impostor is refreshed every frame.
        let cloud = self.ibr.impostors.path_cloud();
        let (cc, reach) = (cloud.center, 2.2 * cloud.radius);
        vec![
            start,
            (Vec3::new(22.0, 13.0, 22.0), Vec3::new(34.0, 3.0, 32.0)),
            (Vec3::new(36.0, 24.0, 36.0), Vec3::new(41.0, 4.0, 40.0)),
            (Vec3::new(44.0, 22.0, 26.0), Vec3::new(48.0, 2.0, 20.0)),
            (Vec3::new(12.0, 14.0, 34.0), Vec3::new(-6.0, 4.0, 14.0)),
            // From behind turret B, down the beam toward A, where B's bolts explode.
            // (beside the turret's head, so the beam is seen nearly end-on).
            (b + along * 7.0 + side * 1.5 + Vec3::Y * 1.2, a),
            (b + along * 2.5 + side * 0.8 + Vec3::Y * 0.3, a + side * 0.3),
            // The sun about 20 degrees above the image centre, over the forest.
            (
                sun_eye,
                sun_eye + Vec3::new(sun.x, sun.y * 0.4, sun.z) * 10.0,
            ),
            // Over the city, looking down on its impostored buildings.
            (Vec3::new(-18.0, 12.0, -24.0), city),
            (
                city + Vec3::new(3.0, 15.0, -9.0),
                city + Vec3::new(-4.0, -2.0, 8.0),
            ),
            // Into the cloud and out of it.
            (cc - Vec3::Z * reach, cc),
            (cc, cc + Vec3::Z * reach),
            (
                cc + Vec3::new(0.0, 0.5, reach),
                cc + Vec3::new(6.0, -6.0, 2.0 * reach),
            ),
            (Vec3::new(-12.0, 14.0, 28.0), Vec3::new(0.0, 1.2, 0.0)),
            start,
        ]
    }

    /// Renders the scene and its image-based layer for `camera` (two passes: the scene
    /// with billboards, lasers and effects, then the lens flare).
    pub fn render(
        &mut self,
        renderer: &mut Renderer,
        camera: &Camera,
        target: &mut Target,
        opts: &FrameOptions,
    ) -> FrameStats {
        self.ibr.render(&self.scene, renderer, camera, target, opts)
    }
}

/// Uniform Catmull-Rom interpolation between `p1` and `p2`.
fn catmull_rom(p0: Vec3, p1: Vec3, p2: Vec3, p3: Vec3, t: f32) -> Vec3 {
    let (t2, t3) = (t * t, t * t * t);
    0.5 * ((2.0 * p1)
        + (p2 - p0) * t
        + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * t2
        + (3.0 * p1 - p0 - 3.0 * p2 + p3) * t3)
}

impl Default for Showcase {
    fn default() -> Self {
        Self::new()
    }
}

fn lamp_position(t: f32) -> Vec3 {
    let a = t * 0.8;
    Vec3::new(3.2 * a.cos(), 1.6 + 0.4 * (t * 1.3).sin(), 3.2 * a.sin())
}

/// A camera for the showcase at `eye` looking at `target`, for a `width` x `height` image.
pub fn camera(eye: Vec3, target: Vec3, width: u32, height: u32) -> Camera {
    Camera::look_at(eye, target, Vec3::Y, FOV_Y, 1.0)
        .with_aspect(width, height)
        .with_depth_range(0.1, FAR)
}

/// Builds a texture from a per-texel function returning straight sRGB bytes.
fn texture(size: u32, f: impl Fn(u32, u32) -> [u8; 4]) -> Arc<Texture> {
    let mut bytes = Vec::with_capacity((size * size * 4) as usize);
    for y in 0..size {
        for x in 0..size {
            bytes.extend_from_slice(&f(x, y));
        }
    }
    Arc::new(Texture::from_rgba8(size, size, &bytes, Encoding::Srgb).expect("valid size"))
}

/// Wooden crate: planks with grain, a darker frame and diagonal brace.
pub fn crate_texture() -> Arc<Texture> {
    const N: u32 = 128;
    texture(N, |x, y| {
        let (u, v) = (x as f32 / N as f32, y as f32 / N as f32);
        let grain = procedural::value_noise(u * 3.0, v * 40.0, 11);
        let plank = ((v * 4.0).fract() < 0.04) as u8 as f32;
        let frame = !(0.1..=0.9).contains(&u) || !(0.1..=0.9).contains(&v);
        let brace = ((u - v).abs() < 0.07) && !frame;
        let mut c = [
            168.0 + 40.0 * grain,
            118.0 + 30.0 * grain,
            66.0 + 16.0 * grain,
        ];
        if frame || brace {
            c = [c[0] * 0.72, c[1] * 0.7, c[2] * 0.66];
        }
        if plank > 0.0 && !frame {
            c = [c[0] * 0.5, c[1] * 0.5, c[2] * 0.5];
        }
        [c[0] as u8, c[1] as u8, c[2] as u8, 255]
    })
}

/// Fence panel: a diagonal lattice inside a frame; the holes are transparent (alpha 0).
pub fn lattice_texture() -> Arc<Texture> {
    const N: u32 = 128;
    texture(N, |x, y| {
        let (u, v) = (x as f32 / N as f32, y as f32 / N as f32);
        let frame = !(0.06..=0.94).contains(&u) || !(0.08..=0.92).contains(&v);
        let d1 = ((u + v) * 5.0).fract();
        let d2 = ((u - v + 4.0) * 5.0).fract();
        let bar = d1 < 0.16 || d2 < 0.16;
        if frame || bar {
            let shade = 0.85 + 0.15 * procedural::value_noise(u * 20.0, v * 20.0, 3);
            let s = |c: f32| (c * shade) as u8;
            [s(205.0), s(200.0), s(185.0), 255]
        } else {
            [0, 0, 0, 0]
        }
    })
}

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

fn lit(color: Rgba, specular: f32, shininess: f32) -> Material {
    Material {
        shading: Shading::Lit {
            specular,
            shininess,
        },
        ..Material::lit(color)
    }
}

fn build() -> Showcase {
    let mut s = Scene::default();
    let terrain = Terrain {
        size: 120.0,
        cells: 120,
        height: 12.0,
        feature: 22.0,
        flat_radius: 12.0,
        seed: 7,
    };
    let matte = |c: Rgba| lit(c, 0.05, 8.0);

    // Ground: vertex-coloured terrain and a checker-textured plaza.
    s.add(terrain.mesh(), matte(Rgba::WHITE), Mat4::IDENTITY);
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

    // Centre piece: a vertex-coloured torus over a stone pedestal.
    let mut pedestal = procedural::cylinder(0.7, 0.6, 24);
    pedestal.colors.clear();
    s.add(
        pedestal,
        matte(Rgba::from_srgb8(150, 146, 140)),
        Mat4::IDENTITY,
    );
    let torus = s.add(
        procedural::torus(1.1, 0.38, 96, 48),
        lit(Rgba::WHITE, 0.5, 48.0),
        Mat4::IDENTITY,
    );

    // Lit spheres: red plastic, gold, chalk (one mesh, three materials).
    let sphere = procedural::uv_sphere(1.0, 24, 48);
    let mut plain_sphere = sphere.clone();
    plain_sphere.colors.clear();
    let (sphere_m, _) = push(&mut s, plain_sphere, Material::default());
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
        instance(&mut s, sphere_m, m, xf);
    }

    // Crates with a generated wood texture.
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
        &mut s,
        crate_m,
        crate_mat,
        Mat4::from_scale_rotation_translation(
            Vec3::splat(0.9),
            Quat::from_rotation_y(-0.2),
            Vec3::new(3.7, 1.85, 3.1),
        ),
    );
    instance(
        &mut s,
        crate_m,
        crate_mat,
        Mat4::from_scale_rotation_translation(
            Vec3::splat(1.0),
            Quat::from_rotation_y(0.9),
            Vec3::new(5.4, 0.5, 1.6),
        ),
    );

    // Alpha-tested lattice fence behind the plaza, with posts.
    let fence_mat = Material {
        alpha_mode: AlphaMode::Mask { cutoff: 0.5 },
        ..matte(Rgba::WHITE)
            .with_texture(lattice_texture())
            .double_sided(true)
    };
    let mut panel = procedural::quad(2.0, 1.3);
    panel.colors.clear();
    let (panel_m, panel_mat) = push(&mut s, panel, fence_mat);
    let mut post = procedural::cylinder(0.07, 1.5, 8);
    post.colors.clear();
    let (post_m, post_mat) = push(&mut s, post, matte(Rgba::from_srgb8(110, 90, 70)));
    let z = -6.5;
    for k in 0..7 {
        let x = -6.0 + 2.0 * k as f32;
        let at = Mat4::from_translation(Vec3::new(x, 0.0, z));
        instance(&mut s, post_m, post_mat, at);
        if k < 6 {
            let at = Mat4::from_translation(Vec3::new(x + 1.0, 0.75, z));
            instance(&mut s, panel_m, panel_mat, at);
        }
    }

    // Blended glass: a tinted cube by the fence and a sphere in front of the plaza.
    let mut glass_cube = procedural::cuboid(Vec3::new(1.8, 1.8, 1.8));
    glass_cube.colors.clear();
    s.add(
        glass_cube,
        Material {
            alpha_mode: AlphaMode::Blend,
            ..lit(Rgba::new(0.35, 0.6, 0.95, 0.35), 1.2, 96.0)
        },
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
        Material {
            alpha_mode: AlphaMode::Blend,
            ..lit(Rgba::new(0.5, 0.95, 0.6, 0.3), 1.2, 96.0)
        },
        Mat4::from_scale_rotation_translation(
            Vec3::splat(0.9),
            Quat::IDENTITY,
            Vec3::new(1.6, 0.92, 4.2),
        ),
    );

    // The lamp: an emissive ball marking the orbiting point light.
    let mut lamp_mesh = procedural::uv_sphere(0.15, 8, 16);
    lamp_mesh.colors.clear();
    let lamp = s.add(
        lamp_mesh,
        Material::unlit(Rgba::new(1.0, 0.75, 0.35, 1.0)),
        Mat4::IDENTITY,
    );

    // A house with its own blue door light.
    let house_at = Mat4::from_translation(Vec3::new(-9.5, 0.0, -1.5)) * Mat4::from_rotation_y(0.6);
    s.add(
        procedural::house(4.0, 3.2, 2.4, 1.6),
        matte(Rgba::WHITE),
        house_at,
    );

    // Trees and rocks on the hills around the plaza (instanced variants).
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
        if showcase_impostors::in_city(x, z, 2.0) {
            continue;
        }
        let y = terrain.height_at(x, z) - 0.1;
        let v = variants[(rng.next_u64() % variants.len() as u64) as usize];
        let xf = Mat4::from_scale_rotation_translation(
            Vec3::splat(h),
            Quat::from_rotation_y(rng.range(0.0, 6.0)),
            Vec3::new(x, y, z),
        );
        instance(&mut s, v, veg, xf);
        placed += 1;
    }
    for (k, (x, z, h)) in [(-12.0, -4.5, 5.0), (-7.5, -9.5, 4.2), (-4.0, -11.0, 4.6)]
        .into_iter()
        .enumerate()
    {
        instance(
            &mut s,
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
        if showcase_impostors::in_city(x, z, 1.0) {
            continue;
        }
        let xf = Mat4::from_scale_rotation_translation(
            Vec3::splat(size),
            Quat::from_rotation_y(rng.range(0.0, 6.0)),
            Vec3::new(x, terrain.height_at(x, z) + 0.1 * size, z),
        );
        instance(&mut s, rocks[k % rocks.len()], veg, xf);
    }

    s.lighting = Lighting {
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
    };
    let ibr = IbrLayer::new(&mut s, &terrain);
    let mut show = Showcase {
        scene: s,
        terrain,
        ibr,
        torus,
        lamp,
        lamp_light: 1,
    };
    show.animate(0.0);
    show
}

/// What the user asks the fly camera to do this frame (independent of the window library).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FlyInput {
    /// Move along the view direction (+1 forward, -1 back).
    pub forward: f32,
    /// Move sideways (+1 right).
    pub right: f32,
    /// Move along world +Y.
    pub up: f32,
    /// Turn, radians: yaw to the left, pitch up.
    pub yaw: f32,
    pub pitch: f32,
    /// Move faster.
    pub fast: bool,
}

/// A fly camera: a position and yaw / pitch angles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlyCamera {
    pub position: Vec3,
    /// Radians around +Y; 0 looks down -Z.
    pub yaw: f32,
    /// Radians; positive looks up.
    pub pitch: f32,
    /// World units per second.
    pub speed: f32,
}

impl Default for FlyCamera {
    fn default() -> Self {
        FlyCamera::looking_at(Vec3::new(10.0, 4.5, 13.0), Vec3::new(0.0, 1.2, 0.0))
    }
}

impl FlyCamera {
    pub fn looking_at(eye: Vec3, target: Vec3) -> Self {
        let d = (target - eye).normalize_or(Vec3::NEG_Z);
        FlyCamera {
            position: eye,
            yaw: (-d.x).atan2(-d.z),
            pitch: d.y.clamp(-1.0, 1.0).asin(),
            speed: 6.0,
        }
    }

    /// Unit view direction.
    pub fn forward(&self) -> Vec3 {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        Vec3::new(-sy * cp, sp, -cy * cp)
    }

    /// Applies one frame of input over `dt` seconds.
    pub fn update(&mut self, input: &FlyInput, dt: f32) {
        self.yaw += input.yaw;
        self.pitch = (self.pitch + input.pitch).clamp(-1.5, 1.5);
        let f = self.forward();
        let right = f.cross(Vec3::Y).normalize_or(Vec3::X);
        let speed = self.speed * if input.fast { 4.0 } else { 1.0 } * dt;
        self.position += (f * input.forward + right * input.right + Vec3::Y * input.up) * speed;
    }

    pub fn camera(&self, width: u32, height: u32) -> Camera {
        camera(self.position, self.position + self.forward(), width, height)
    }
}

/// Checks a mesh list: every mesh valid (used by tests and debug builds).
pub fn validate(scene: &Scene) -> Result<(), String> {
    scene
        .meshes
        .iter()
        .enumerate()
        .try_for_each(|(i, m): (usize, &Mesh)| m.validate().map_err(|e| format!("mesh {i}: {e}")))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scene_is_valid_and_has_every_feature() {
        let show = Showcase::new();
        let s = &show.scene;
        validate(s).unwrap();
        assert!(s.draws().count() == s.instances.len());
        let mats: Vec<&Material> = s.draws().map(|d| d.material).collect();
        assert!(mats
            .iter()
            .any(|m| matches!(m.alpha_mode, AlphaMode::Mask { .. })));
        assert!(mats.iter().any(|m| m.alpha_mode == AlphaMode::Blend));
        assert!(mats.iter().any(|m| m.base_texture.is_some()));
        assert!(s
            .draws()
            .any(|d| d.material.vertex_colors && !d.mesh.colors.is_empty()));
        assert!(s
            .lighting
            .lights
            .iter()
            .any(|l| matches!(l, Light::Point { .. })));
        assert!(s
            .lighting
            .lights
            .iter()
            .any(|l| matches!(l, Light::Directional { .. })));
    }

    #[test]
    fn animation_moves_the_lamp_and_is_deterministic() {
        let mut a = Showcase::new();
        let mut b = Showcase::new();
        a.animate(1.5);
        b.animate(1.5);
        assert_eq!(a.scene, b.scene);
        let before = a.scene.lighting.clone();
        a.animate(2.5);
        assert_ne!(before, a.scene.lighting);
    }

    #[test]
    fn fly_camera_moves_where_it_looks() {
        let mut c = FlyCamera::looking_at(Vec3::ZERO, Vec3::new(0.0, 0.0, -5.0));
        assert!((c.forward() - Vec3::NEG_Z).length() < 1e-5);
        c.update(
            &FlyInput {
                forward: 1.0,
                ..Default::default()
            },
            0.5,
        );
        assert!((c.position - Vec3::new(0.0, 0.0, -3.0)).length() < 1e-4);
        c.update(
            &FlyInput {
                right: 1.0,
                up: 1.0,
                ..Default::default()
            },
            1.0 / 6.0,
        );
        assert!((c.position - Vec3::new(1.0, 1.0, -3.0)).length() < 1e-4);
        let looking = FlyCamera::looking_at(Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0));
        assert!((looking.forward() - Vec3::new(1.0, 1.0, 0.0).normalize()).length() < 1e-5);
        c.update(
            &FlyInput {
                pitch: 10.0,
                ..Default::default()
            },
            0.0,
        );
        assert!(c.pitch <= 1.5);
    }

    #[test]
    fn path_stays_above_the_ground() {
        let show = Showcase::new();
        for i in 0..120 {
            let (eye, _) = show.path(i, 120);
            assert!(eye.y > show.terrain.height_at(eye.x, eye.z) + 1.0);
        }
    }
}
