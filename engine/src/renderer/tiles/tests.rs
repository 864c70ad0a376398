//! The visibility pre-pass: opaque pixels shaded once, alpha-tested holes showing what lies
//! behind, blended draws over the same opaque result, and the pixels, depths and written
//! counts of the one-pass path at any thread count.

use crate::{AlphaMode, Draw, FrameStats, Material, Mesh, Renderer, Rgba, Target, Texture};
use glam::{Mat4, Vec2, Vec3};
use std::sync::Arc;

const SIZE: u32 = 64;

/// `n` walls facing the camera in one mesh (so the draw order cannot sort them), farthest
/// first, each covering the whole view, wall `k` at view distance `4 + n - 1 - k` in its own
/// vertex colour.
fn stack(n: usize) -> Mesh {
    let mut m = Mesh::default();
    for k in 0..n {
        let d = (4 + n - 1 - k) as f32;
        let z = 5.0 - d;
        let base = m.positions.len() as u32;
        for (x, y) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
            m.positions.push(Vec3::new(x * d, y * d, z));
            m.uvs.push(Vec2::new((x + 1.0) * 2.0, (y + 1.0) * 2.0));
            m.colors.push(Rgba::new(
                k as f32 / n as f32,
                1.0 - k as f32 / n as f32,
                0.5,
                1.0,
            ));
        }
        m.indices
            .extend([base, base + 1, base + 2, base, base + 2, base + 3]);
    }
    m
}

/// Renders `draws` with the pre-pass on or off, on `threads` threads (the renderer tests'
/// camera and target).
fn render(draws: &[Draw<'_>], prepass: bool, threads: usize) -> (Target, FrameStats) {
    let mut renderer = Renderer::new();
    renderer.set_visibility_prepass(prepass);
    crate::renderer::tests::render_with(&mut renderer, draws.to_vec(), threads)
}

/// The pre-pass against the one-pass reference: same colours and depths on 1 and 2 threads;
/// returns both runs' counters on 2 threads, (pre-pass, one pass).
fn same_as_one_pass(draws: &[Draw<'_>]) -> (FrameStats, FrameStats) {
    let (want, one) = render(draws, false, 1);
    let mut got = None;
    for threads in [1, 2] {
        let (t, s) = render(draws, true, threads);
        assert_eq!(t.to_rgba8(), want.to_rgba8(), "{threads} threads");
        assert_eq!(t.depth_storage(), want.depth_storage(), "{threads} threads");
        got = Some(s);
    }
    (got.expect("ran"), one)
}

fn lit() -> Material {
    Material {
        vertex_colors: true,
        ..Material::unlit(Rgba::WHITE)
    }
}

#[test]
fn a_stack_of_opaque_walls_shades_each_pixel_once() {
    let (mesh, mat) = (stack(6), lit());
    let draws = [Draw {
        mesh: &mesh,
        material: &mat,
        transform: Mat4::IDENTITY,
    }];
    let (pre, one) = same_as_one_pass(&draws);
    let pixels = (SIZE * SIZE) as u64;
    // One pass shades every wall whole (each is nearer than the last); the pre-pass shades
    // what is seen, once.
    assert_eq!(one.fragments_shaded, 6 * pixels, "{one:?}");
    assert_eq!(pre.fragments_shaded, pixels, "{pre:?}");
    assert_eq!(pre.fragments_written, pixels, "{pre:?}");
    assert_eq!(pre.fragments_tested, one.fragments_tested, "{pre:?}");
}

#[test]
fn alpha_tested_holes_show_what_lies_behind() {
    let (walls, mat) = (stack(3), lit());
    // A near wall whose texture is transparent in every other cell, and behind it the
    // stack; the stack first in submission order and the cutout nearest.
    let holes = Texture::checker(
        64,
        8,
        Rgba::new(1.0, 1.0, 0.0, 1.0),
        Rgba::new(0.0, 0.0, 0.0, 0.0),
    );
    let cutout = Material {
        base_texture: Some(Arc::new(holes)),
        alpha_mode: AlphaMode::Mask { cutoff: 0.5 },
        ..Material::unlit(Rgba::WHITE)
    };
    let screen = stack(1);
    let near =
        Mat4::from_translation(Vec3::new(0.0, 0.0, 2.0)) * Mat4::from_scale(Vec3::splat(0.5));
    let draws = [
        Draw {
            mesh: &walls,
            material: &mat,
            transform: Mat4::IDENTITY,
        },
        Draw {
            mesh: &screen,
            material: &cutout,
            transform: near,
        },
    ];
    let (pre, one) = same_as_one_pass(&draws);
    let (t, _) = render(&draws, true, 2);
    let (behind, _) = render(&draws[..1], false, 1);
    // Some pixels are the cutout's, others (its holes) the nearest wall of the stack.
    let (mut cut, mut through) = (0, 0);
    for y in 0..SIZE {
        for x in 0..SIZE {
            if t.pixel(x, y) == behind.pixel(x, y) {
                through += 1;
            } else {
                cut += 1;
            }
        }
    }
    assert!(cut > 1000 && through > 1000, "{cut} cut, {through} through");
    // The cutout is drawn first (it is nearer) and shaded whole in both; the stack behind
    // only where it shows with the pre-pass.
    let pixels = (SIZE * SIZE) as u64;
    assert!(
        pre.fragments_shaded < one.fragments_shaded,
        "{pre:?} {one:?}"
    );
    assert_eq!(pre.fragments_shaded, pixels + through, "{pre:?}");
}

#[test]
fn blended_and_barrier_draws_give_the_one_pass_pixels() {
    let (mesh, mat) = (stack(4), lit());
    let glass = Material {
        alpha_mode: AlphaMode::Blend,
        ..Material::unlit(Rgba::new(0.0, 0.0, 1.0, 0.5))
    };
    let screen = stack(1);
    let near =
        Mat4::from_translation(Vec3::new(0.0, 0.0, 2.0)) * Mat4::from_scale(Vec3::splat(0.3));
    let mut draws = vec![
        Draw {
            mesh: &screen,
            material: &glass,
            transform: near,
        },
        Draw {
            mesh: &mesh,
            material: &mat,
            transform: Mat4::IDENTITY,
        },
    ];
    let (pre, one) = same_as_one_pass(&draws);
    assert!(
        pre.fragments_shaded < one.fragments_shaded,
        "{pre:?} {one:?}"
    );
    assert_eq!(pre.fragments_shaded_blended, one.fragments_shaded_blended);
    // An opaque draw without depth test turns the pre-pass off for the frame: the same
    // pixels and counters as one pass.
    let mut over = mat.clone();
    over.depth_test = false;
    draws.push(Draw {
        mesh: &screen,
        material: &over,
        transform: near,
    });
    let (pre, one) = same_as_one_pass(&draws);
    assert_eq!(pre, one);
}
