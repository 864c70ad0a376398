//! The low-resolution pass against the same draws shaded at full resolution (the slow,
//! plain path as reference): alike away from edges, occluders untouched, a quarter of the
//! fragments at scale 2, the same pixels at any thread count, and no change to a frame
//! without low-resolution draws.

use crate::camera::Camera;
use crate::color::Rgba;
use crate::light::Lighting;
use crate::material::{BlendMode, Material};
use crate::mesh::Mesh;
use crate::renderer::{FrameOptions, Renderer};
use crate::scene::Draw;
use crate::stats::FrameStats;
use crate::target::Target;
use glam::{Mat4, Vec3, Vec4};

/// Odd sides: the small target's pixels do not tile the frame evenly.
const W: u32 = 131;
const H: u32 = 75;

/// The renderer tests' unit quad facing +z, its vertex colours `colors` (corners
/// counter-clockwise from the bottom left).
fn quad(colors: [Vec4; 4]) -> Mesh {
    Mesh {
        colors: colors.map(|c| Rgba::new(c.x, c.y, c.z, c.w)).to_vec(),
        ..crate::renderer::tests::quad()
    }
}

/// A quad at view distance `d` (the camera at z = 5 looking down -z), scaled by `s` about
/// its centre at `(x, y)`.
fn at(d: f32, x: f32, y: f32, s: f32) -> Mat4 {
    Mat4::from_translation(Vec3::new(x, y, 5.0 - d)) * Mat4::from_scale(Vec3::splat(s))
}

/// A soft cloud: blended, its colour and coverage gradients across it.
fn cloud() -> Material {
    let mut m = Material::unlit(Rgba::WHITE).blended(BlendMode::Alpha);
    m.low_res = true;
    m
}

struct Scene {
    flat: Mesh,
    shaded: Mesh,
    sky: Material,
    wall: Material,
    cloud: Material,
    glass: Material,
}

impl Scene {
    fn new() -> Self {
        let white = Vec4::ONE;
        Scene {
            flat: quad([white; 4]),
            shaded: quad([
                Vec4::new(1.0, 0.9, 0.8, 0.2),
                Vec4::new(0.9, 1.0, 0.9, 0.7),
                Vec4::new(0.8, 0.8, 1.0, 0.9),
                Vec4::new(1.0, 1.0, 1.0, 0.4),
            ]),
            sky: Material::unlit(Rgba::new(0.3, 0.5, 0.9, 1.0)),
            wall: Material::unlit(Rgba::new(0.6, 0.2, 0.1, 1.0)),
            cloud: cloud(),
            glass: Material::unlit(Rgba::new(0.1, 0.9, 0.2, 0.5)).blended(BlendMode::Alpha),
        }
    }

    /// The sky far behind, the cloud before it, an opaque wall before the cloud over its
    /// lower right, and a glass pane (blended, full resolution) at the left edge.
    fn draws(&self) -> Vec<Draw<'_>> {
        vec![
            Draw {
                mesh: &self.flat,
                material: &self.sky,
                transform: at(20.0, 0.0, 0.0, 40.0),
            },
            Draw {
                mesh: &self.shaded,
                material: &self.cloud,
                transform: at(8.0, -0.5, 0.3, 3.0),
            },
            Draw {
                mesh: &self.flat,
                material: &self.wall,
                transform: at(4.0, 1.2, -0.9, 0.8),
            },
            Draw {
                mesh: &self.flat,
                material: &self.glass,
                transform: at(4.0, -2.6, 0.0, 0.4),
            },
        ]
    }
}

/// The renderer tests' camera and pool, at low-resolution `scale`.
fn render(
    draws: &[Draw<'_>],
    scale: u32,
    threads: usize,
    size: (u32, u32),
) -> (Target, FrameStats) {
    let mut renderer = Renderer::new();
    renderer.set_low_res_scale(scale);
    crate::renderer::tests::render_sized(&mut renderer, draws.to_vec(), threads, size)
}

/// The largest channel difference between two pixels, in levels.
fn diff(a: u32, b: u32) -> u32 {
    let (a, b) = (a.to_le_bytes(), b.to_le_bytes());
    (0..4)
        .map(|c| a[c].abs_diff(b[c]) as u32)
        .max()
        .unwrap_or(0)
}

#[test]
fn low_res_draws_match_full_resolution_but_for_a_band_at_edges() {
    let scene = Scene::new();
    let draws = scene.draws();
    let (full, _) = render(&draws, 1, 2, (W, H));
    let (low, _) = render(&draws, 2, 2, (W, H));
    let (mut sum, mut far_off) = (0u64, 0u32);
    for y in 0..H {
        for x in 0..W {
            let d = diff(full.pixel(x, y).unwrap(), low.pixel(x, y).unwrap());
            sum += d as u64;
            far_off += (d > 4) as u32;
        }
    }
    let mean = sum as f64 / (W * H) as f64;
    // The cloud quad's hard outline, about 290 pixels long, is a band of one small pixel
    // (two full ones) that differs more (measured: mean 1.10, 453 pixels over 4 levels;
    // 1.43 and 502 before a pixel beside the wall took the cloud beyond its mixed block).
    assert!(mean < 1.25, "mean difference {mean} levels");
    assert!(far_off < 600, "{far_off} pixels more than 4 levels off");
    // Inside the cloud, away from every edge, the gradient is upsampled to within a few
    // levels: the 8-bit small target and the bilinear filter.
    for (x, y) in [(30, 30), (45, 20), (25, 40), (50, 38)] {
        let d = diff(full.pixel(x, y).unwrap(), low.pixel(x, y).unwrap());
        assert!(d <= 4, "({x}, {y}): {d} levels");
    }
}

#[test]
fn an_occluder_in_front_keeps_its_own_pixels() {
    let scene = Scene::new();
    let draws = scene.draws();
    let (full, _) = render(&draws, 1, 1, (W, H));
    let (low, _) = render(&draws, 2, 1, (W, H));
    let wall = Rgba::new(0.6, 0.2, 0.1, 1.0).premultiply();
    let mut seen = 0;
    for y in 0..H {
        for x in 0..W {
            let p = full.pixel(x, y).unwrap();
            if full
                .color_linear(x, y)
                .is_some_and(|c| (c.r - wall.r).abs() < 0.01 && (c.g - wall.g).abs() < 0.01)
            {
                seen += 1;
                assert_eq!(
                    low.pixel(x, y),
                    Some(p),
                    "the wall at ({x}, {y}) took cloud"
                );
            }
        }
    }
    assert!(seen > 300, "the wall covers {seen} pixels");
}

#[test]
fn a_quarter_of_the_fragments_at_scale_two() {
    let scene = Scene::new();
    let cloud = &scene.draws()[..2];
    let (_, full) = render(cloud, 1, 2, (W, H));
    let (_, low) = render(cloud, 2, 2, (W, H));
    let ratio = low.fragments_shaded_blended as f64 / full.fragments_shaded_blended as f64;
    assert!(
        (0.2..0.32).contains(&ratio),
        "blended fragments {ratio} of full resolution"
    );
    assert_eq!(low.draws, 2);
}

#[test]
fn the_same_pixels_at_any_thread_count() {
    let scene = Scene::new();
    let draws = scene.draws();
    let (one, a) = render(&draws, 2, 1, (W, H));
    for threads in [2, 3] {
        let (t, b) = render(&draws, 2, threads, (W, H));
        assert_eq!(t, one, "{threads} threads");
        assert_eq!(a.fragments_shaded, b.fragments_shaded);
    }
}

#[test]
fn a_frame_without_low_res_draws_is_the_plain_one() {
    let scene = Scene::new();
    let mut draws = scene.draws();
    draws.remove(1);
    assert_eq!(
        render(&draws, 2, 2, (W, H)).0,
        render(&draws, 1, 2, (W, H)).0
    );
    // An additive low-resolution material, or one writing depth, stays at full resolution.
    let mut glow = cloud().blended(BlendMode::Additive);
    glow.base_color = Rgba::new(0.2, 0.1, 0.0, 1.0);
    let mut stand_in = cloud();
    stand_in.blend_depth = Some(0.5);
    for m in [&glow, &stand_in] {
        let mut d = draws.clone();
        d.push(Draw {
            material: m,
            ..scene.draws()[1]
        });
        assert_eq!(render(&d, 2, 2, (W, H)).0, render(&d, 1, 2, (W, H)).0);
    }
}

#[test]
fn pixels_the_small_target_leaves_clear_are_the_plain_ones() {
    // The cloud far in the upper left: the glass pane, the wall and the sky elsewhere are
    // drawn by the first and last passes exactly as by one.
    let scene = Scene::new();
    let mut draws = scene.draws();
    draws[1].transform = at(8.0, -3.0, 2.0, 0.5);
    let (full, _) = render(&draws, 1, 2, (W, H));
    let (low, _) = render(&draws, 2, 2, (W, H));
    let mut same = 0;
    for y in H / 2..H {
        for x in 0..W {
            assert_eq!(low.pixel(x, y), full.pixel(x, y), "({x}, {y})");
            same += 1;
        }
    }
    assert!(same > 4000);
}

#[test]
fn draw_costs_stay_in_submission_order() {
    let scene = Scene::new();
    let draws = scene.draws();
    let camera = Camera::look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 1.0, 1.0);
    let mut renderer = Renderer::new();
    renderer.set_low_res_scale(2);
    renderer.set_draw_costs(true);
    let mut target = Target::new(W, H);
    let stats = renderer.render(
        draws.iter().copied(),
        &camera,
        &Lighting::default(),
        &mut target,
        &FrameOptions::default(),
    );
    let costs = renderer.draw_costs();
    assert_eq!(costs.len(), draws.len());
    let shaded: u64 = costs.iter().map(|c| c.fragments_shaded).sum();
    assert_eq!(shaded, stats.fragments_shaded);
    // The cloud (second) shaded the small target's pixels only: about a quarter of its
    // full-resolution area, which the sky (first) covers whole.
    assert!(costs[1].fragments_shaded * 3 < costs[0].fragments_shaded);
    assert_eq!(
        costs[1].fragments_shaded,
        stats.fragments_shaded_blended - costs[3].fragments_shaded
    );
}

#[test]
fn odd_inputs_do_not_panic() {
    let scene = Scene::new();
    let mut draws = scene.draws();
    for size in [(0, 0), (1, 1), (1, 300), (3, 2)] {
        render(&draws, 2, 2, size);
        render(&draws, 7, 2, size);
    }
    draws[1].transform = Mat4::from_scale(Vec3::splat(f32::NAN));
    render(&draws, 2, 2, (W, H));
    draws[1].transform = at(8.0, 1e30, 0.0, 1e30);
    render(&draws, 2, 2, (W, H));
}
