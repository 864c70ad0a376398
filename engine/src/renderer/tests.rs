//! Draw order: opaque draws sorted near to far shade each covered pixel about once, give
//! the pixels of submission order, and keep them at any thread count; an opaque draw
//! without depth test keeps its place.

use super::order::permute;
use super::*;
use crate::material::{AlphaMode, Material};
use crate::testing::on_threads;
use glam::Mat4;

const SIZE: u32 = 64;

/// A quad facing the camera at view distance `d`, large enough to cover the whole view.
fn wall(d: f32) -> Mat4 {
    Mat4::from_translation(Vec3::new(0.0, 0.0, 5.0 - d)) * Mat4::from_scale(Vec3::splat(d))
}

/// A unit quad facing +z (the camera sits at z = 5 looking down -z).
pub(super) fn quad() -> Mesh {
    Mesh {
        positions: vec![
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(-1.0, 1.0, 0.0),
        ],
        indices: vec![0, 1, 2, 0, 2, 3],
        ..Default::default()
    }
}

/// Renders the walls `(distance, material)` in the order given on `threads` threads.
fn check(walls: &[(f32, &Material)], threads: usize) -> (Target, FrameStats) {
    let mesh = quad();
    let draws: Vec<Draw<'_>> = walls
        .iter()
        .map(|&(d, material)| Draw {
            mesh: &mesh,
            material,
            transform: wall(d),
        })
        .collect();
    render_with(&mut Renderer::new(), draws, threads)
}

/// Renders `draws` with `renderer` on `threads` threads into a `SIZE` square, seen from 5
/// units along +z looking at the origin (the walls' camera; the pre-pass tests' too).
pub(super) fn render_with(
    renderer: &mut Renderer,
    draws: Vec<Draw<'_>>,
    threads: usize,
) -> (Target, FrameStats) {
    render_sized(renderer, draws, threads, (SIZE, SIZE))
}

/// [`render_with`] into a target of `size`.
pub(super) fn render_sized(
    renderer: &mut Renderer,
    draws: Vec<Draw<'_>>,
    threads: usize,
    size: (u32, u32),
) -> (Target, FrameStats) {
    let camera = Camera::look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 1.0, 1.0);
    let mut target = Target::new(size.0, size.1);
    let opts = FrameOptions::default();
    let stats = on_threads(threads, || {
        renderer.render(draws, &camera, &Lighting::default(), &mut target, &opts)
    });
    (target, stats)
}

fn colour(k: usize) -> Material {
    Material::unlit(Rgba::new(k as f32 / 8.0, 1.0 - k as f32 / 8.0, 0.5, 1.0))
}

#[test]
fn walls_drawn_back_to_front_shade_one_screen() {
    let mats: Vec<Material> = (0..6).map(colour).collect();
    // Submitted far to near: in submission order every wall would be shaded whole.
    let walls: Vec<(f32, &Material)> = (0..6).rev().map(|k| (4.0 + k as f32, &mats[k])).collect();
    let pixels = (SIZE * SIZE) as u64;
    let (target, stats) = check(&walls, 2);
    assert_eq!(stats.fragments_shaded, pixels, "{stats:?}");
    assert_eq!(stats.fragments_written, pixels, "{stats:?}");
    // The nearest wall everywhere, as the depth test gives in any order.
    let (near, _) = check(&walls[5..], 1);
    assert_eq!(target.to_rgba8(), near.to_rgba8());
    // Any submission order, any thread count: the same pixels and counters.
    let mut shuffled = walls.clone();
    shuffled.swap(0, 3);
    shuffled.swap(1, 5);
    for threads in [1, 2] {
        let (t, s) = check(&shuffled, threads);
        assert_eq!(t.to_rgba8(), target.to_rgba8(), "{threads} threads");
        assert_eq!(s, stats, "{threads} threads");
    }
}

#[test]
fn an_opaque_draw_without_depth_test_keeps_its_place() {
    let (red, green) = (colour(0), colour(7));
    let mut over = green.clone();
    over.depth_test = false;
    let red_px = check(&[(4.0, &red)], 1).0.pixel(32, 32);
    let green_px = check(&[(9.0, &green)], 1).0.pixel(32, 32);
    // Drawn last, the far wall without depth test covers the near one...
    let (t, _) = check(&[(4.0, &red), (9.0, &over)], 2);
    assert_eq!(t.pixel(32, 32), green_px);
    // ...and drawn first it is covered, though it is farther.
    let (t, _) = check(&[(9.0, &over), (4.0, &red)], 2);
    assert_eq!(t.pixel(32, 32), red_px);
    // Walls on each side of it are still sorted among themselves.
    let (t, s) = check(&[(6.0, &green), (4.0, &red), (9.0, &over), (5.0, &red)], 2);
    assert_eq!(t.pixel(32, 32), red_px);
    assert_eq!(s.fragments_shaded, 3 * (SIZE * SIZE) as u64, "{s:?}");
}

#[test]
fn blended_draws_still_go_after_the_opaque_ones_far_to_near() {
    let opaque = colour(0);
    let glass = Material {
        alpha_mode: AlphaMode::Blend,
        ..Material::unlit(Rgba::new(0.0, 0.0, 1.0, 0.5))
    };
    // The glass is submitted first and nearest; the opaque wall behind it still shows
    // through, and the glass is shaded over it once per pixel.
    let (t, s) = check(&[(4.0, &glass), (8.0, &opaque)], 2);
    let (alone, _) = check(&[(8.0, &opaque)], 1);
    assert_ne!(t.pixel(32, 32), alone.pixel(32, 32));
    let (after, _) = check(&[(8.0, &opaque), (4.0, &glass)], 1);
    assert_eq!(t.to_rgba8(), after.to_rgba8());
    let pixels = (SIZE * SIZE) as u64;
    assert_eq!(s.fragments_shaded_blended, pixels, "{s:?}");
    assert_eq!(s.fragments_shaded, 2 * pixels, "{s:?}");
}

/// Each draw's cost, when counted: a wall shifted so that its corner sits on the view's
/// centre covers one quarter of the target (32 x 32 pixels), and the full wall behind it,
/// submitted first, shades the other three quarters; the costs come back in submission
/// order, sum to the frame's totals, and are the same on 1 and 2 threads.
#[test]
fn draw_costs_count_each_draw_in_submission_order() {
    let (far, near) = (colour(1), colour(2));
    let mesh = quad();
    let quarter = Mat4::from_translation(Vec3::new(4.0, 4.0, 0.0)) * wall(4.0);
    let draws = || {
        vec![
            Draw {
                mesh: &mesh,
                material: &far,
                transform: wall(6.0),
            },
            Draw {
                mesh: &mesh,
                material: &near,
                transform: quarter,
            },
        ]
    };
    let pixels = (SIZE * SIZE) as u64;
    let mut seen = Vec::new();
    for threads in [1, 2] {
        let mut renderer = Renderer::new();
        render_with(&mut renderer, draws(), threads);
        assert!(renderer.draw_costs().is_empty(), "not counted unless asked");
        renderer.set_draw_costs(true);
        let (_, stats) = render_with(&mut renderer, draws(), threads);
        let costs = renderer.draw_costs().to_vec();
        let shaded: Vec<u64> = costs.iter().map(|c| c.fragments_shaded).collect();
        assert_eq!(shaded, [pixels * 3 / 4, pixels / 4], "{costs:?}");
        let sum = |f: fn(&DrawCost) -> u64| costs.iter().map(f).sum::<u64>();
        assert_eq!(sum(|c| c.fragments_shaded), stats.fragments_shaded);
        assert_eq!(sum(|c| c.fragments_tested), stats.fragments_tested);
        assert_eq!(sum(|c| c.rows_shaded), stats.rows_shaded);
        seen.push(
            costs
                .iter()
                .map(|c| DrawCost {
                    raster: Duration::ZERO,
                    ..*c
                })
                .collect::<Vec<_>>(),
        );
    }
    assert_eq!(seen[0], seen[1], "the same counts on 1 and 2 threads");
}

/// A square of side 4 facing the camera, cut into `n x n` cells of two triangles, its
/// vertex colours a gradient across it.
fn gradient_grid(n: u32) -> Mesh {
    let mut mesh = Mesh::default();
    for j in 0..=n {
        for i in 0..=n {
            let (u, v) = (i as f32 / n as f32, j as f32 / n as f32);
            mesh.positions
                .push(Vec3::new(4.0 * u - 2.0, 4.0 * v - 2.0, 0.0));
            mesh.colors.push(Rgba::new(u, v, 0.5, 1.0));
        }
    }
    for j in 0..n {
        for i in 0..n {
            let k = j * (n + 1) + i;
            mesh.indices
                .extend_from_slice(&[k, k + 1, k + n + 2, k, k + n + 2, k + n + 1]);
        }
    }
    mesh
}

/// The rows of small triangles are shaded several to a vector (`raster`'s packs), and each
/// pixel keeps its own colour: the gradient cut into 3-pixel triangles (most rows packed)
/// gives the pixels of the same gradient drawn as two large triangles (hardly any packs),
/// within a level of rounding, on 1 and 2 threads alike.
#[test]
fn packed_rows_give_each_pixel_its_own_colour() {
    let material = Material {
        vertex_colors: true,
        ..Material::unlit(Rgba::new(1.0, 1.0, 1.0, 1.0))
    };
    let draw = |mesh| {
        let (target, stats) = render_with(
            &mut Renderer::new(),
            vec![Draw {
                mesh,
                material: &material,
                transform: Mat4::IDENTITY,
            }],
            1,
        );
        let (two, _) = render_with(
            &mut Renderer::new(),
            vec![Draw {
                mesh,
                material: &material,
                transform: Mat4::IDENTITY,
            }],
            2,
        );
        let px = |t: &Target| -> Vec<u32> {
            (0..SIZE * SIZE)
                .map(|i| t.pixel(i % SIZE, i / SIZE).expect("inside"))
                .collect()
        };
        assert_eq!(px(&target), px(&two), "the same pixels on 1 and 2 threads");
        (px(&target), stats)
    };
    let (coarse_mesh, fine_mesh) = (gradient_grid(1), gradient_grid(16));
    let (coarse, coarse_stats) = draw(&coarse_mesh);
    let (fine, fine_stats) = draw(&fine_mesh);
    assert_eq!(coarse_stats.fragments_shaded, fine_stats.fragments_shaded);
    assert!(
        fine_stats.rows_paired * 4 > fine_stats.rows_shaded,
        "small triangles pack most rows: {fine_stats:?}"
    );
    assert!(
        coarse_stats.rows_paired * 10 < coarse_stats.rows_shaded,
        "{coarse_stats:?}"
    );
    let mut compared = 0;
    for (i, (&a, &b)) in coarse.iter().zip(&fine).enumerate() {
        if a >> 24 == 0 || b >> 24 == 0 {
            continue;
        }
        compared += 1;
        for c in 0..4 {
            let (x, y) = ((a >> (8 * c)) & 0xff, (b >> (8 * c)) & 0xff);
            assert!(x.abs_diff(y) <= 1, "pixel {i} channel {c}: {x} against {y}");
        }
    }
    assert!(compared > 1500, "{compared} pixels compared");
}

/// Small triangles (set up as coverage masks) wholly behind a nearer wall are rejected by
/// block against the farthest depth stored there: not one of their fragments is tested or
/// shaded, the pixels are the wall's alone, the same on 1 and 2 threads. Before the small
/// triangles had this test, each of their covered pixels was depth-tested.
#[test]
fn small_triangles_behind_a_wall_test_no_fragments() {
    // A grid of quads 0.4 units wide at view distance 10: about 2.3 pixels a side.
    let mut grid = Mesh::default();
    for j in 0..12 {
        for i in 0..12 {
            let (x, y) = (-3.3 + 0.6 * i as f32, -3.3 + 0.6 * j as f32);
            let k = grid.positions.len() as u32;
            for (dx, dy) in [(0.0, 0.0), (0.4, 0.0), (0.4, 0.4), (0.0, 0.4)] {
                grid.positions.push(Vec3::new(x + dx, y + dy, -5.0));
            }
            grid.indices.extend([k, k + 1, k + 2, k, k + 2, k + 3]);
        }
    }
    let (near, specks) = (colour(3), colour(6));
    let wall_mesh = quad();
    let draws = || {
        vec![
            Draw {
                mesh: &grid,
                material: &specks,
                transform: Mat4::IDENTITY,
            },
            Draw {
                mesh: &wall_mesh,
                material: &near,
                transform: wall(3.0),
            },
        ]
    };
    let pixels = (SIZE * SIZE) as u64;
    let (alone, wall_stats) = check(&[(3.0, &near)], 1);
    // The grid alone is drawn, as small triangles, and tests its pixels.
    let (_, grid_alone) = render_with(&mut Renderer::new(), draws()[..1].to_vec(), 1);
    assert!(grid_alone.fragments_shaded > 200, "{grid_alone:?}");
    for threads in [1, 2] {
        // Cluster occlusion off: the grid's clusters would be skipped before their blocks
        // are tested (`a_mesh_behind_a_wall_is_skipped_by_clusters`).
        let mut renderer = Renderer::new();
        renderer.set_cluster_occlusion(false);
        let (t, s) = render_with(&mut renderer, draws(), threads);
        assert_eq!(t.to_rgba8(), alone.to_rgba8(), "{threads} threads");
        assert_eq!(s.fragments_tested, pixels, "{s:?}");
        assert_eq!(s.fragments_shaded, pixels, "{s:?}");
        // Every block a small triangle reaches is rejected (the wall, drawn first, none).
        assert_eq!(
            s.blocks_hiz_rejected, grid_alone.blocks_partial,
            "{s:?} against {grid_alone:?}"
        );
    }
    assert_eq!(wall_stats.blocks_hiz_rejected, 0);
}

/// A grid of `n` x `n` quads `side` wide, spaced `step`, in the plane z = `z`, centred.
fn grid_mesh(n: usize, side: f32, step: f32, z: f32) -> Mesh {
    let mut grid = Mesh::default();
    let half = step * (n as f32 - 1.0) / 2.0 + side / 2.0;
    for j in 0..n {
        for i in 0..n {
            let (x, y) = (-half + step * i as f32, -half + step * j as f32);
            let k = grid.positions.len() as u32;
            for (dx, dy) in [(0.0, 0.0), (side, 0.0), (side, side), (0.0, side)] {
                grid.positions.push(Vec3::new(x + dx, y + dy, z));
            }
            grid.indices.extend([k, k + 1, k + 2, k, k + 2, k + 3]);
        }
    }
    grid
}

/// Renders `draws` into a 192 x 128 target (3 x 2 tiles) from the walls' camera, cluster
/// occlusion on or off, on `threads` threads.
fn render_wide(draws: &[Draw<'_>], occlusion: bool, threads: usize) -> (Target, FrameStats) {
    let camera = Camera::look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 1.0, 1.5);
    let mut target = Target::new(192, 128);
    let mut renderer = Renderer::new();
    renderer.set_cluster_occlusion(occlusion);
    let opts = FrameOptions::default();
    let stats = on_threads(threads, || {
        renderer.render(
            draws.to_vec(),
            &camera,
            &Lighting::default(),
            &mut target,
            &opts,
        )
    });
    (target, stats)
}

/// A mesh of walked and small triangles wholly behind a nearer wall: with cluster occlusion
/// every one of its (triangle, tile) pairs is skipped, none of its blocks reaches the
/// hierarchical test, and the pixels and depths are those of the renderer without it (where
/// the same triangles are rasterized and rejected block by block), on 1 and 2 threads.
#[test]
fn a_mesh_behind_a_wall_is_skipped_by_clusters() {
    // 400 quads of about 11 pixels and 144 of about 2, at view distance 10; the wall at 3.
    let big = grid_mesh(20, 0.35, 0.4, -5.0);
    let small = grid_mesh(12, 0.08, 0.6, -5.0);
    let (near, far) = (colour(3), colour(6));
    let wall_mesh = quad();
    let draws = [
        Draw {
            mesh: &big,
            material: &far,
            transform: Mat4::IDENTITY,
        },
        Draw {
            mesh: &small,
            material: &far,
            transform: Mat4::IDENTITY,
        },
        Draw {
            mesh: &wall_mesh,
            material: &near,
            transform: wall(3.0) * Mat4::from_scale(Vec3::new(1.6, 1.0, 1.0)),
        },
    ];
    let (want, off) = render_wide(&draws, false, 1);
    let (_, wall_alone) = render_wide(&draws[2..], false, 1);
    assert_eq!(off.clusters_occluded, 0);
    assert!(off.blocks_hiz_rejected > 100, "{off:?}");
    let behind = off.triangles_binned - wall_alone.triangles_binned;
    assert!(behind > 800, "{off:?}");
    for threads in [1, 2] {
        let (t, s) = render_wide(&draws, true, threads);
        assert_eq!(t.to_rgba8(), want.to_rgba8(), "{threads} threads");
        assert_eq!(t.depth_storage(), want.depth_storage(), "{threads} threads");
        assert_eq!(s.triangles_occluded, behind, "{s:?}");
        assert!(s.clusters_occluded >= behind.div_ceil(32), "{s:?}");
        assert_eq!(s.blocks_hiz_rejected, 0, "{s:?}");
        assert_eq!(s.fragments_tested, wall_alone.fragments_tested, "{s:?}");
        assert_eq!(s.fragments_shaded, wall_alone.fragments_shaded, "{s:?}");
    }
}

/// Meshes partly behind, partly beside a wall covering the middle of the view, at slants
/// (so clusters straddle tiles and blocks, some hidden, some not): the same pixels, depths
/// and shaded counts with cluster occlusion as without, on 1 and 2 threads, with some
/// clusters skipped.
#[test]
fn cluster_occlusion_keeps_the_pixels() {
    let big = grid_mesh(40, 0.1, 0.12, 0.0);
    let small = grid_mesh(40, 0.03, 0.12, 0.0);
    let (a, b, c) = (colour(1), colour(5), colour(7));
    let wall_mesh = quad();
    let slant = |ry: f32, z: f32| {
        Mat4::from_translation(Vec3::new(0.0, 0.0, z)) * Mat4::from_rotation_y(ry)
    };
    let draws = [
        Draw {
            mesh: &big,
            material: &a,
            transform: slant(0.7, -3.0),
        },
        Draw {
            mesh: &small,
            material: &b,
            transform: slant(-0.5, -1.0),
        },
        Draw {
            mesh: &wall_mesh,
            material: &c,
            transform: Mat4::from_translation(Vec3::new(0.3, -0.2, 1.5))
                * Mat4::from_scale(Vec3::new(1.5, 0.9, 1.0)),
        },
    ];
    let (want, off) = render_wide(&draws, false, 1);
    assert_eq!(off.triangles_occluded, 0);
    for threads in [1, 2] {
        let (t, s) = render_wide(&draws, true, threads);
        assert_eq!(t.to_rgba8(), want.to_rgba8(), "{threads} threads");
        assert_eq!(t.depth_storage(), want.depth_storage(), "{threads} threads");
        assert_eq!(s.fragments_shaded, off.fragments_shaded, "{s:?}");
        assert_eq!(s.fragments_written, off.fragments_written, "{s:?}");
        assert!(s.clusters_occluded > 0, "{s:?}");
        assert!(s.triangles_occluded < off.triangles_binned, "{s:?}");
    }
}

proptest::proptest! {
    /// Applying a sort's order to the draws puts at each position the draw the order
    /// names, for any permutation (the order a depth sort gives draws has long cycles).
    #[test]
    fn permute_puts_each_item_where_its_order_says(
        keys in proptest::collection::vec(proptest::prelude::any::<u16>(), 0..400)
    ) {
        let mut order: Vec<usize> = (0..keys.len()).collect();
        order.sort_by_key(|&i| (keys[i], i));
        let mut items: Vec<usize> = (0..keys.len()).map(|i| i * 7 + 1).collect();
        let original = items.clone();
        let mut placed = vec![true; 3];
        permute(&mut items, |i| order[i], &mut placed);
        for (i, &item) in items.iter().enumerate() {
            proptest::prop_assert_eq!(item, original[order[i]]);
        }
    }
}

/// A reversed order of many draws (one cycle pair after another) and a rotation (one long
/// cycle) are applied exactly.
#[test]
fn permute_handles_long_cycles_and_reversals() {
    let n = 100_000;
    let mut placed = Vec::new();
    let mut items: Vec<usize> = (0..n).collect();
    permute(&mut items, |i| n - 1 - i, &mut placed);
    assert!(items.iter().enumerate().all(|(i, &x)| x == n - 1 - i));
    let mut items: Vec<usize> = (0..n).collect();
    permute(&mut items, |i| (i + 1) % n, &mut placed);
    assert!(items.iter().enumerate().all(|(i, &x)| x == (i + 1) % n));
}
