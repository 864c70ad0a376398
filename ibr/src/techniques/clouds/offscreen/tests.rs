//! The off-screen particles against the same particles drawn in the frame: close in colour,
//! never over nearer geometry, a quarter of the blended fragments, the same pixels at any
//! thread count, and the estimate an upper bound of the fragments.

use super::*;
use crate::core::Subject;
use crate::techniques::clouds::Cloud;
use engine::{Material, Mesh};
use glam::{Mat4, Vec3};

const W: u32 = 320;
const H: u32 = 180;
const SKY: Rgba = Rgba::new(0.3, 0.5, 0.9, 1.0);

fn camera() -> Camera {
    Camera::look_at(
        Vec3::ZERO,
        Vec3::new(0.0, 0.0, -1.0),
        Vec3::Y,
        1.0,
        W as f32 / H as f32,
    )
}

/// An opaque wall nearer than the cloud over the left of the view, `x < WALL_X` pixels.
fn wall() -> (Mesh, Material) {
    let mesh = Mesh {
        positions: vec![
            Vec3::new(-8.0, -5.0, -6.0),
            Vec3::new(-2.0, -5.0, -6.0),
            Vec3::new(-2.0, 5.0, -6.0),
            Vec3::new(-8.0, 5.0, -6.0),
        ],
        indices: vec![0, 1, 2, 0, 2, 3],
        ..Default::default()
    };
    (mesh, Material::unlit(Rgba::new(0.8, 0.2, 0.1, 1.0)))
}

/// The wall's right edge in pixels: x = -2 at depth 6, `tan(0.5) * 6` the half height.
fn wall_x() -> u32 {
    let half_w = (0.5f32).tan() * 6.0 * W as f32 / H as f32;
    ((1.0 + -2.0 / half_w) * 0.5 * W as f32) as u32
}

fn cloud() -> Cloud {
    let mut c = Cloud::cumulus(
        Vec3::new(0.0, 0.0, -25.0),
        Vec3::new(40.0, 16.0, 24.0),
        300,
        7,
    );
    c.prepare(&camera(), H);
    c
}

/// The wall over the sky, then the cloud: in the frame (`off` false) or off-screen.
fn render(off: bool) -> (Target, FrameStats) {
    let (mesh, material) = wall();
    let cloud = cloud();
    let mut draws = Vec::new();
    cloud.draws(&mut draws);
    let (cam, light) = (camera(), Lighting::default());
    let mut renderer = Renderer::new();
    let mut target = Target::new(W, H);
    let opts = FrameOptions {
        clear: Some(SKY),
        ..FrameOptions::default()
    };
    let wall = Draw {
        mesh: &mesh,
        material: &material,
        transform: Mat4::IDENTITY,
    };
    if off {
        renderer.render([wall], &cam, &light, &mut target, &opts);
        let stats = Offscreen::new().draw(draws, &cam, &light, &mut target);
        (target, stats)
    } else {
        let all = std::iter::once(wall).chain(draws);
        let stats = renderer.render(all, &cam, &light, &mut target, &opts);
        (target, stats)
    }
}

#[test]
fn half_size_particles_match_the_frames_closely_and_blend_a_quarter() {
    let (full, fs) = render(false);
    let (half, hs) = render(true);
    let (a, b) = (full.to_rgba8(), half.to_rgba8());
    let diff: Vec<f64> = a
        .iter()
        .zip(&b)
        .map(|(x, y)| *x as f64 - *y as f64)
        .collect();
    let mse = diff.iter().map(|d| d * d).sum::<f64>() / diff.len() as f64;
    let psnr = 10.0 * (255.0 * 255.0 / mse.max(1e-9)).log10();
    assert!(psnr > 30.0, "PSNR {psnr:.2} dB");
    // The cloud covers most of the view: many blended fragments in full.
    let screen = (W * H) as u64;
    assert!(fs.fragments_shaded_blended > 2 * screen, "{fs:?}");
    // Off-screen: a quarter of them at half size, plus at most one screen composited.
    let (all, quarter) = (fs.fragments_shaded_blended, hs.fragments_shaded_blended);
    assert!(quarter >= all / 5, "{quarter} of {all}");
    assert!(quarter <= all * 3 / 10 + screen, "{quarter} of {all}");
    // No cloud over the nearer wall, but for its edge's two columns.
    for y in 0..H {
        for x in 0..wall_x().saturating_sub(2) {
            assert_eq!(half.pixel(x, y), full.pixel(x, y), "({x}, {y})");
        }
    }
}

#[test]
fn off_screen_particles_are_the_same_at_any_thread_count() {
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| render(true).0)
    };
    let one = run(1);
    assert!(run(2) == one);
    assert!(run(3) == one);
}

#[test]
fn the_estimate_bounds_the_fragments_and_decides() {
    let cloud = cloud();
    let mut draws = Vec::new();
    cloud.draws(&mut draws);
    let (_, fs) = render(false);
    let est = Offscreen::estimate(&draws, &camera(), W, H);
    let blended = fs.fragments_shaded_blended as f64;
    assert!(est >= blended && est < 3.0 * blended, "{est} {blended}");
    // Odd sides and small frames draw in the frame.
    assert!(!Offscreen::worth(&draws, &camera(), W + 1, H));
    assert_eq!(
        Offscreen::worth(&draws, &camera(), W, H),
        est > MIN_FRAGMENTS
    );
    let mut odd = Target::new(W + 1, H);
    let light = Lighting::default();
    let stats = Offscreen::new().draw(draws, &camera(), &light, &mut odd);
    assert_eq!(stats, FrameStats::default());
}
