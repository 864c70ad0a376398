//! Depth peeling: each layer, rendered strictly behind the previous one, holds the k-th
//! surface along every pixel's ray, as the analytic ray cast counts them, on scenes with a
//! known number of surfaces per ray (nested boxes: up to six along a ray through the
//! middle, fewer toward the edges).

use engine::{procedural, Camera, Cull, Draw, FrameOptions, Lighting, Material, Renderer};
use engine::{Mesh, Rgba, Target};
use glam::{DVec3, Mat4, Vec3};
use tests::reference::RayCast;

const W: u32 = 96;
const H: u32 = 72;

fn camera() -> Camera {
    Camera::look_at(Vec3::new(0.9, 1.3, 6.0), Vec3::ZERO, Vec3::Y, 0.8, 1.0)
        .with_aspect(W, H)
        .with_depth_range(0.5, 30.0)
}

/// Three nested boxes, slightly turned so no face is parallel to the image.
fn boxes() -> Vec<(Mesh, Mat4)> {
    [1.0f32, 2.0, 3.2]
        .iter()
        .enumerate()
        .map(|(i, &s)| {
            let mut m = procedural::cuboid(Vec3::new(s, s * 0.8, s * 1.1));
            m.colors.clear();
            let at = Mat4::from_rotation_y(0.3 + 0.2 * i as f32) * Mat4::from_rotation_x(0.15);
            (m, at)
        })
        .collect()
}

fn world_tris(meshes: &[(Mesh, Mat4)]) -> Vec<[DVec3; 3]> {
    let mut out = Vec::new();
    for (m, at) in meshes {
        for t in m.indices.chunks_exact(3) {
            out.push(std::array::from_fn(|k| {
                at.transform_point3(m.positions[t[k] as usize]).as_dvec3()
            }));
        }
    }
    out
}

/// Peels `layers` layers; returns their targets and the fragments each wrote.
fn peel(meshes: &[(Mesh, Mat4)], layers: usize) -> Vec<(Target, u64)> {
    let cam = camera();
    let material = Material::unlit(Rgba::new(0.8, 0.3, 0.2, 1.0));
    let draws = || {
        meshes.iter().map(|(mesh, at)| Draw {
            mesh,
            material: &material,
            transform: *at,
        })
    };
    let opts = FrameOptions {
        clear: Some(Rgba::TRANSPARENT),
        cull: Cull::None,
    };
    let (mut renderer, lighting) = (Renderer::new(), Lighting::default());
    let mut out: Vec<(Target, u64)> = Vec::new();
    for k in 0..layers {
        let mut t = Target::new(W, H);
        let stats = match out.last() {
            None => renderer.render(draws(), &cam, &lighting, &mut t, &opts),
            Some((prev, _)) => {
                renderer.render_behind(draws(), &cam, &lighting, &mut t, &opts, prev)
            }
        };
        assert_eq!(stats.triangles_rejected, 0, "layer {k}");
        out.push((t, stats.fragments_written));
    }
    out
}

#[test]
fn each_layer_is_the_next_surface_along_the_ray() {
    let meshes = boxes();
    let tris = world_tris(&meshes);
    let cam = camera();
    let rc = RayCast::new(&cam, W, H);
    let layers = peel(&meshes, 8);
    let (mut checked, mut deep) = (0, 0);
    for y in 0..H {
        for x in 0..W {
            let (cx, cy) = (x as f64 + 0.5, y as f64 + 0.5);
            let hits = rc.cast_all(cx, cy, &tris, 1e-6);
            // Near an edge of any surface the count changes within a fraction of a pixel:
            // snapping decides there, not visibility.
            let eps = 0.02;
            let stable = (0..8).all(|k| {
                let a = k as f64 * std::f64::consts::FRAC_PI_4;
                let ring = rc.cast_all(cx + eps * a.cos(), cy + eps * a.sin(), &tris, 1e-6);
                ring.len() == hits.len()
            });
            if !stable {
                continue;
            }
            checked += 1;
            if hits.len() >= 6 {
                deep += 1;
            }
            for (k, (layer, _)) in layers.iter().enumerate() {
                let d = layer.depth_reversed(x, y).unwrap() as f64;
                match hits.get(k) {
                    Some(&dist) => {
                        let want = rc.reversed_depth(dist);
                        assert!(
                            (d - want).abs() < 1e-5,
                            "pixel ({x}, {y}) layer {k}: depth {d}, surface {k} at {want}"
                        );
                        let a = layer.color_linear(x, y).unwrap().a;
                        assert!(a > 0.99, "pixel ({x}, {y}) layer {k} drawn");
                    }
                    None => {
                        assert_eq!(
                            d,
                            0.0,
                            "pixel ({x}, {y}) layer {k}: only {} surfaces",
                            hits.len()
                        );
                        assert_eq!(layer.color_linear(x, y).unwrap().a, 0.0);
                    }
                }
            }
        }
    }
    assert!(checked > (W * H) as usize / 2, "{checked} pixels checked");
    assert!(deep > 200, "rays through all six surfaces: {deep}");
    // Six surfaces at most: the seventh and eighth layers are empty, so a peeling loop ends.
    assert!(layers[5].1 > 0);
    assert_eq!(layers[6].1, 0);
    assert_eq!(layers[7].1, 0);
}

#[test]
fn peeling_behind_a_target_of_another_size_draws_nothing() {
    let meshes = boxes();
    let cam = camera();
    let material = Material::unlit(Rgba::WHITE);
    let draws = meshes.iter().map(|(mesh, at)| Draw {
        mesh,
        material: &material,
        transform: *at,
    });
    let mut t = Target::new(W, H);
    let other = Target::new(W + 1, H);
    let stats = Renderer::new().render_behind(
        draws,
        &cam,
        &Lighting::default(),
        &mut t,
        &FrameOptions::default(),
        &other,
    );
    assert_eq!(stats.fragments_written, 0);
    assert!(stats.triangles_set_up > 0, "the frame ran");
}

#[test]
fn peeling_gives_the_same_pixels_at_any_thread_count() {
    let meshes = boxes();
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool")
            .install(|| peel(&meshes, 4))
    };
    let (a, b) = (run(1), run(3));
    for ((ta, _), (tb, _)) in a.iter().zip(&b) {
        assert_eq!(ta.to_rgba8(), tb.to_rgba8());
        assert_eq!(ta.depth_gl_image(), tb.depth_gl_image());
    }
}
