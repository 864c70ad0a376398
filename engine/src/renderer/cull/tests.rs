//! Draw culling: draws behind the camera or beside the view cost no vertex, draws that
//! reach into the view are kept, and the pixels are those of a frame without culling at
//! any thread count.

use super::super::tests::{quad, render_with};
use crate::material::Material;
use crate::scene::Draw;
use crate::{Renderer, Rgba};
use glam::{Mat4, Vec3};

fn at(x: f32, y: f32, z: f32) -> Mat4 {
    Mat4::from_translation(Vec3::new(x, y, z))
}

#[test]
fn draws_behind_or_beside_the_view_transform_no_vertex() {
    let mesh = quad();
    let red = Material::unlit(Rgba::new(1.0, 0.0, 0.0, 1.0));
    let draws = |transforms: &[Mat4]| -> Vec<Draw<'_>> {
        transforms
            .iter()
            .map(|&transform| Draw {
                mesh: &mesh,
                material: &red,
                transform,
            })
            .collect()
    };
    // In view; behind the camera; far beside the view (x = 40 at distance 5, fov 1 rad).
    let scene = [at(0.0, 0.0, 0.0), at(0.0, 0.0, 9.0), at(40.0, 0.0, 0.0)];
    for threads in [1, 2] {
        let (on, s_on) = render_with(&mut Renderer::new(), draws(&scene), threads);
        let mut off_renderer = Renderer::new();
        off_renderer.set_draw_culling(false);
        let (off, s_off) = render_with(&mut off_renderer, draws(&scene), threads);
        assert_eq!(on.to_rgba8(), off.to_rgba8(), "{threads} threads");
        assert_eq!((s_on.draws, s_on.draws_culled), (3, 2), "{s_on:?}");
        assert_eq!((s_on.triangles_in, s_on.triangles_draw_culled), (6, 4));
        assert_eq!(s_on.vertices_transformed, 4, "only the quad in view");
        assert_eq!((s_off.draws_culled, s_off.vertices_transformed), (0, 12));
        assert_eq!(s_on.triangles_rejected, s_off.triangles_rejected);
        assert_eq!(s_on.fragments_written, s_off.fragments_written);
        assert!(s_on.fragments_written > 0);
        // Alone, each culled draw costs nothing.
        for &t in &scene[1..] {
            let (_, s) = render_with(&mut Renderer::new(), draws(&[t]), threads);
            assert_eq!((s.draws_culled, s.vertices_transformed), (1, 0), "{s:?}");
            assert_eq!(s.triangles_set_up + s.triangles_clipped, 0, "{s:?}");
        }
    }
}

#[test]
fn draws_reaching_into_the_view_are_kept() {
    let mesh = quad();
    let red = Material::unlit(Rgba::new(1.0, 0.0, 0.0, 1.0));
    // Straddling the image's right side and its top (half the view is 5 tan 0.5 = 2.73
    // wide at the quad's distance); reaching from in front of the eye to behind it.
    for transform in [
        at(2.6, 0.0, 0.0),
        at(0.0, 2.6, 0.0),
        at(0.0, 0.0, 4.0) * Mat4::from_rotation_x(1.2) * Mat4::from_scale(Vec3::splat(3.0)),
    ] {
        let draw = Draw {
            mesh: &mesh,
            material: &red,
            transform,
        };
        let (_, s) = render_with(&mut Renderer::new(), vec![draw], 1);
        assert_eq!(s.draws_culled, 0, "{transform:?}: {s:?}");
        assert_eq!(s.vertices_transformed, 4);
    }
}

/// A small deterministic generator (the pixels must not depend on a seed's library).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
}

#[test]
fn a_scattered_scene_gives_the_same_pixels_with_culling_off() {
    let mesh = quad();
    let materials: Vec<Material> = (0..6)
        .map(|k| {
            let c = Rgba::new(0.15 * k as f32, 1.0 - 0.1 * k as f32, 0.5, 1.0);
            let m = Material::unlit(c);
            if k == 5 {
                m.double_sided(true)
            } else {
                m
            }
        })
        .collect();
    let mut rng = Lcg(7);
    let transforms: Vec<Mat4> = (0..400)
        .map(|_| {
            let p = Vec3::new(rng.next(), rng.next(), rng.next()) * 30.0 - 15.0;
            let turn = Mat4::from_rotation_y(6.3 * rng.next()) * Mat4::from_rotation_x(rng.next());
            Mat4::from_translation(p) * turn * Mat4::from_scale(Vec3::splat(0.2 + rng.next()))
        })
        .collect();
    let draws = || -> Vec<Draw<'_>> {
        transforms
            .iter()
            .enumerate()
            .map(|(k, &transform)| Draw {
                mesh: &mesh,
                material: &materials[k % materials.len()],
                transform,
            })
            .collect()
    };
    for threads in [1, 2] {
        let (on, s_on) = render_with(&mut Renderer::new(), draws(), threads);
        let mut off_renderer = Renderer::new();
        off_renderer.set_draw_culling(false);
        let (off, s_off) = render_with(&mut off_renderer, draws(), threads);
        assert_eq!(on.to_rgba8(), off.to_rgba8(), "{threads} threads");
        assert_eq!(on.depth_storage(), off.depth_storage(), "{threads} threads");
        assert!(
            s_on.draws_culled > 200 && s_on.draws_culled < 400,
            "{s_on:?}"
        );
        assert_eq!(
            s_on.vertices_transformed,
            4 * (400 - s_on.draws_culled),
            "{s_on:?}"
        );
        for s in [s_on, s_off] {
            assert!(s.fragments_written > 500, "{s:?}");
        }
        assert_eq!(
            (s_on.triangles_set_up, s_on.fragments_written),
            (s_off.triangles_set_up, s_off.fragments_written)
        );
    }
}
