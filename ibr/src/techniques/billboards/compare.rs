//! Test support: an atlas's sprite against its mesh from one eye, counted in pixels.

use super::ViewAtlas;
use crate::core::{Billboard, Facing, View};
use engine::{
    Camera, Draw, FrameOptions, Light, Lighting, Material, Mesh, Renderer, Rgba, Shading, Target,
};
use glam::{Mat4, Vec2, Vec3};

/// The atlas's sprite ([`ViewAtlas::relief`], or its nailboard when switched on) of the
/// object at the origin, seen by `cam` from `eye` on a target `h` pixels tall.
pub(super) fn centred_sprite(atlas: &ViewAtlas, eye: Vec3, cam: &Camera, h: u32) -> Mesh {
    let item = Billboard {
        region: atlas.region(eye),
        ..Billboard::new(
            Vec3::ZERO,
            Facing::World { up: Vec3::Y },
            Vec2::splat(2.0 * atlas.bounds.radius),
        )
    };
    let mut mesh = Mesh::default();
    assert_eq!(atlas.relief(&[item], &View::new(cam, h), &mut mesh), 1);
    mesh
}

/// `atlas`'s sprite of `draw` (framed by the atlas's sphere at the origin) and `draw`
/// itself, lit by `lighting`, rendered from `eye` looking at the origin (160 x 120, field of view
/// `fov`): the pixels both cover, those one covers and the other not, and the mean
/// level difference (RGB) over the first.
pub(super) fn against_mesh(
    atlas: &ViewAtlas,
    draw: Draw<'_>,
    lighting: &Lighting,
    eye: Vec3,
    fov: f32,
) -> (u32, u32, f32) {
    let (w, h) = (160u32, 120u32);
    let cam = Camera::look_at(eye, Vec3::ZERO, Vec3::Y, fov, w as f32 / h as f32);
    let mesh = centred_sprite(atlas, eye, &cam, h);
    let sprite = atlas.material().double_sided(true);
    let render = |d: Draw<'_>| {
        let mut t = Target::new(w, h);
        Renderer::new().render(
            [d],
            &cam,
            lighting,
            &mut t,
            &FrameOptions {
                clear: Some(Rgba::TRANSPARENT),
                ..FrameOptions::default()
            },
        );
        t.to_rgba8_premultiplied()
    };
    let image = render(Draw {
        mesh: &mesh,
        material: &sprite,
        transform: Mat4::IDENTITY,
    });
    let truth = render(draw);
    let (mut both, mut one, mut off) = (0u32, 0u32, 0u32);
    for (p, q) in image.chunks(4).zip(truth.chunks(4)) {
        match (p[3] > 0, q[3] > 0) {
            (true, true) => {
                both += 1;
                off += (0..3).map(|c| p[c].abs_diff(q[c]) as u32).sum::<u32>();
            }
            (false, false) => {}
            _ => one += 1,
        }
    }
    (both, one, off as f32 / (3 * both.max(1)) as f32)
}

/// A matte green material (no highlight: a view carries the light that left toward its
/// bake direction).
pub(super) fn matte() -> Material {
    Material {
        shading: Shading::Lit {
            specular: 0.0,
            shininess: 32.0,
        },
        ..Material::lit(Rgba::new(0.3, 0.7, 0.2, 1.0))
    }
}

/// An ambient light and one sun from up and to the side.
pub(super) fn sun() -> Lighting {
    Lighting {
        ambient: Rgba::new(0.2, 0.2, 0.25, 1.0),
        lights: vec![Light::Directional {
            direction: Vec3::new(-0.45, -0.75, -0.5).normalize(),
            color: Rgba::WHITE,
        }],
    }
}
